//! The f64 brute-force reference as a [`Tracer`] (every constrained face per
//! ray): the ground truth of `accuracy`, usable in `render` on small scenes.

use tet_core::TetMesh;
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::ray::{Hit, Ray, TraceOutcome};
use tet_trace_cpu::reference::closest_hit;
use tet_trace_cpu::walk::Start;

/// Brute force over every constrained face, in f64.
pub struct BruteTracer<'m> {
    /// The mesh.
    pub mesh: &'m TetMesh,
}

impl Tracer for BruteTracer<'_> {
    fn name(&self) -> String {
        "brute/f64".into()
    }
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    fn walks_tets(&self) -> bool {
        false
    }

    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let _ = start;
        match closest_hit(self.mesh, ray) {
            Some(r) => {
                let cf = &self.mesh.constrained[r.face as usize];
                TraceOutcome::Hit(Hit {
                    triangle: cf.triangle,
                    face: r.face,
                    t: r.t as f32,
                    barycentrics: r.barycentrics.map(|b| b as f32),
                    tet: tet_core::NO_TET,
                    far_tet: tet_core::NO_TET,
                    tets_visited: 0,
                })
            }
            None => TraceOutcome::Miss { tets_visited: 0 },
        }
    }
}
