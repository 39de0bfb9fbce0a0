//! One mesh in every compact layout: exact bytes per layout (hot and cold),
//! a lossless round trip through each, and the on-disk format.
//!
//! ```sh
//! cargo run --release -p tet-core --example layouts            # a synthetic grid
//! cargo run --release -p tet-core --example layouts -- X.tmesh # a built mesh
//! ```

use std::error::Error;

use tet_core::layout::{Baseline32Mesh, Tet16Mesh, Tet20Mesh, Tet32Mesh, Tet80Mesh};
use tet_core::memory::MemoryReport;
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_core::{TetMesh, format};

fn main() -> Result<(), Box<dyn Error>> {
    let mesh: TetMesh = match std::env::args().nth(1) {
        // `load` checks magic, version, sizes, CRCs and the mesh itself.
        Some(path) => format::load(&path)?,
        None => kuhn_grid(&GridSpec {
            cells: [16, 16, 16],
            constrained_fraction: 0.05,
            ..GridSpec::default()
        }),
    };
    println!("{}", MemoryReport::for_mesh(&mesh));

    // Every layout decodes back to the canonical mesh (same tets up to the
    // layouts' canonical vertex order, same neighbours and constrained faces).
    let tets = mesh.tets.len();
    let decoded = [
        ("baseline32", Baseline32Mesh::from_mesh(&mesh)?.to_mesh()?),
        ("tet32", Tet32Mesh::from_mesh(&mesh)?.to_mesh()?),
        ("tet20", Tet20Mesh::from_mesh(&mesh)?.to_mesh()?),
        ("tet16", Tet16Mesh::from_mesh(&mesh)?.to_mesh()?),
        ("tet80", Tet80Mesh::from_mesh(&mesh)?.to_mesh()?),
    ];
    for (name, back) in decoded {
        assert_eq!(back.tets.len(), tets, "{name}");
        assert_eq!(back.constrained.len(), mesh.constrained.len(), "{name}");
        println!("{name:>10}: round trip of {tets} tets ok");
    }
    let bytes = format::to_bytes(&mesh);
    println!("on disk: {} bytes", bytes.len());
    Ok(())
}
