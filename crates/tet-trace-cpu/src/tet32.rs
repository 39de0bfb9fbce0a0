//! Tet32 kernel (Aman et al., seed 000 §3–4, Algorithms 1, 2, 3).
//!
//! Layout: [`tet_core::layout::Tet32`] = `V_0, V_1, V_2, VX, N_0..N_3`
//! (32 bytes). The new vertex comes from the xor field like Tet20; the exit
//! link is `N_k` for the slot `k` holding the exit vertex (Algorithm 3: three
//! id comparisons, written as a select chain rather than a variable-indexed
//! stack array, the compiler artefact that slowed the original). Per step:
//! 32-byte record, projection and Algorithm 1 as in [`crate::tet20`].

use tet_core::TetMesh;
use tet_core::layout::{LayoutError, Tet32Mesh};

use crate::kernel::WalkTracer;
use crate::walk::{DuffF32, DuffF64, Projection, Topology, prefetch_index};

impl Topology for Tet32Mesh {
    #[inline(always)]
    fn vx(&self, tet: u32) -> u32 {
        self.tets[tet as usize].vx
    }
    #[inline(always)]
    fn prefetch(&self, tet: u32) {
        prefetch_index(&self.tets, tet);
    }
    #[inline(always)]
    fn exit_link(&self, tet: u32, _f: [u32; 3], _d: u32, exiting: u32, _entry: u32) -> u32 {
        let r = &self.tets[tet as usize];
        let n = r.n;
        if exiting == r.v[0] {
            n[0].0
        } else if exiting == r.v[1] {
            n[1].0
        } else if exiting == r.v[2] {
            n[2].0
        } else {
            n[3].0
        }
    }
}

/// Tet32 tracer with projection `P`.
pub type Tet32Tracer<'m, P = DuffF32> = WalkTracer<'m, Tet32Mesh, P>;
/// Tet32 in f64.
pub type Tet32TracerF64<'m> = Tet32Tracer<'m, DuffF64>;

impl<'m, P: Projection> WalkTracer<'m, Tet32Mesh, P> {
    /// Encodes `mesh` (validated) in the Tet32 layout.
    pub fn new(mesh: &'m TetMesh) -> Result<Self, LayoutError> {
        Ok(Self::with_layout(
            mesh,
            Tet32Mesh::from_mesh(mesh)?,
            "tet32",
        ))
    }
}
