//! Triangles in, constrained Delaunay tetrahedralization out.
//!
//! Builds the CDT of a hand-written triangle list (a unit cube, 12
//! triangles) inside an enclosing box with TetGen (the default `tetgen`
//! feature), prints its size, and writes it as a `.tmesh` file when given a
//! path:
//!
//! ```text
//! cargo run --release -p tet-build --example triangles_to_cdt -- cube.tmesh
//! ```

#[cfg(feature = "tetgen")]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    use glam::Vec3;
    use tet_build::bbox::BoxSpec;
    use tet_build::pipeline::{BuildOptions, build};
    use tet_build::scene::Scene;

    // Vertex i of the cube has x = 1 when bit 0 of i is set, y bit 1, z bit 2.
    let vertices = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
        .collect();
    // Two counter-clockwise (outward) triangles per face.
    #[rustfmt::skip]
    let triangles = vec![
        [0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], // z = 0, z = 1
        [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7], // y = 0, y = 1
        [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5], // x = 0, x = 1
    ];
    let scene = Scene {
        name: "cube".into(),
        vertices,
        triangles,
        ..Scene::default()
    };
    let options = BuildOptions {
        enclosing_box: Some(BoxSpec::default()),
        ..BuildOptions::default()
    };
    let (mesh, report) = build(&scene, &options)?;
    println!(
        "{} tets, {} points ({} Steiner), {} constrained faces",
        mesh.tets.len(),
        mesh.points.len(),
        report.steiner_points,
        mesh.constrained.len()
    );
    if let Some(path) = std::env::args_os().nth(1) {
        tet_core::format::save(&path, &mesh)?;
        println!("wrote {}", path.to_string_lossy());
    }
    Ok(())
}

#[cfg(not(feature = "tetgen"))]
fn main() {
    eprintln!("this example needs the default `tetgen` feature");
}
