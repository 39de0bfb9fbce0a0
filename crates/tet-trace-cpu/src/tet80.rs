//! Tet80 kernel: the Plücker traversal of Maria, Horna & Aveneau (seed 001
//! §3–4).
//!
//! Layout: [`tet_core::layout::Tet80`] = four vertex positions inline + four
//! 8-byte faces (`occlusion`, `neighbor = tet << 2 | face`), 80 bytes; the
//! walk reads no point array and no vertex ids.
//!
//! Entering tet `T` through face `e` (paper: `idV` gives the entry face's
//! vertices; its complement vertex is `V_e`), the ray leaves through one of
//! the three faces containing `V_e`. The Plücker side product of the ray
//! `(d, o)` with edge `V_e → V_x` is `d · ((V_e − o) × (V_x − V_e))`; in the
//! frame of the complement vertex it is `(V_x − V_e) · m` with
//! `m = d × (V_e − o)` computed once per tet (6 mul + 3 sub for `m`, then
//! 3 sub + 3 mul + 2 add per side product). Exactly two side products decide
//! the exit face, looked up in a 4 × 4 table ([`EXIT`]) indexed by the entry
//! face and the two signs (paper: 28 operations per tet). The start tet uses
//! the three-side-product test of the engine ([`crate::walk::start_exit_face`]).
//!
//! Not watertight by construction: the side product of one edge is computed
//! in the frame of a different vertex in each tet around it, so two tets can
//! disagree on a ray that grazes the edge, and zero is simply "right". Maria
//! et al. report no failures in f32; the tests measure it.

use tet_core::layout::{LayoutError, Tet80Face, Tet80Mesh};
use tet_core::{FACE_VERTICES, NO_TET, TetMesh};

use crate::kernel::Tracer;
use crate::ray::{Failure, Hit, Ray, TraceOutcome};
use crate::walk::{Start, TripleF32, degenerate_crossing, face_hit, start_exit_face, step_cap};

/// `EXIT[e][2·s₁ + s₂]`: the exit face of a tet entered through face `e`,
/// from the sign `s₁` of the side product with edge `V_e → A` and the sign
/// `s₂` with edge `V_e → B` (when `s₁`) or `V_e → C` (otherwise), where
/// `(A, B, C)` is face `e` in counter-clockwise order as seen along the ray,
/// i.e. slots `(FACE_VERTICES[e][0], FACE_VERTICES[e][2], FACE_VERTICES[e][1])`.
pub const EXIT: [[u8; 4]; 4] = {
    let mut t = [[0u8; 4]; 4];
    let mut e = 0;
    while e < 4 {
        let [a, b, c] = FACE_VERTICES[e];
        // (A, B, C) = (a, c, b): replace A → exit opposite a, B → c, C → b.
        t[e][0] = a as u8; // right of V→A, right of V→C: replace A
        t[e][1] = c as u8; // right of V→A, left of V→C: replace B
        t[e][2] = b as u8; // left of V→A, right of V→B: replace C
        t[e][3] = a as u8; // left of V→A, left of V→B: replace A
        e += 1;
    }
    t
};

/// The second edge's vertex slot: `B` after a left turn, `C` after a right one.
const SECOND: [[u8; 2]; 4] = {
    let mut t = [[0u8; 2]; 4];
    let mut e = 0;
    while e < 4 {
        let [_, b, c] = FACE_VERTICES[e];
        t[e][0] = b as u8; // C
        t[e][1] = c as u8; // B
        e += 1;
    }
    t
};

/// The Plücker (Tet80) tracer.
pub struct Tet80Tracer<'m> {
    mesh: &'m TetMesh,
    layout: Tet80Mesh,
    cap: u32,
}

impl<'m> Tet80Tracer<'m> {
    /// Encodes `mesh` (validated) in the Tet80 layout.
    pub fn new(mesh: &'m TetMesh) -> Result<Self, LayoutError> {
        Ok(Tet80Tracer {
            mesh,
            layout: Tet80Mesh::from_mesh(mesh)?,
            cap: step_cap(mesh),
        })
    }

    /// Replaces the step cap.
    pub fn with_step_cap(mut self, cap: u32) -> Self {
        self.cap = cap;
        self
    }

    /// The layout container.
    pub fn layout(&self) -> &Tet80Mesh {
        &self.layout
    }

    fn walk(&self, ray: &Ray, mut tet: u32, mut entry: usize, mut visited: u32) -> TraceOutcome {
        let tets = &self.layout.tets[..];
        let (o, d) = (ray.origin, ray.direction);
        loop {
            if visited >= self.cap {
                return TraceOutcome::Failed {
                    failure: Failure::StepCap,
                    tets_visited: visited,
                };
            }
            visited += 1;
            let rec = &tets[tet as usize];
            let apex = rec.vertex(entry);
            let m = d.cross(apex - o);
            let a = FACE_VERTICES[entry][0];
            let s1 = (rec.vertex(a) - apex).dot(m) > 0.0;
            let second = SECOND[entry][s1 as usize] as usize;
            let s2 = (rec.vertex(second) - apex).dot(m) > 0.0;
            let exit = EXIT[entry][2 * s1 as usize + s2 as usize] as usize;
            match self.leave(ray, tet, rec.f[exit], visited) {
                Ok((n, f)) => {
                    tet = n;
                    entry = f;
                }
                Err(out) => return out,
            }
        }
    }

    /// Crosses face `f` of `tet`: `Ok(next tet, its entry face)` or the outcome.
    #[inline(always)]
    fn leave(
        &self,
        ray: &Ray,
        tet: u32,
        f: Tet80Face,
        visited: u32,
    ) -> Result<(u32, usize), TraceOutcome> {
        if f.is_occlusive() {
            let cf = &self.mesh.constrained[f.occlusion as usize];
            let (t, w) = face_hit(self.mesh, ray, cf.vertices);
            if t >= ray.t_min as f64 {
                if t > ray.t_max as f64 {
                    return Err(TraceOutcome::Miss {
                        tets_visited: visited,
                    });
                }
                let barycentrics = w.map(|x| x as f32);
                if degenerate_crossing(t, &barycentrics) {
                    return Err(TraceOutcome::Failed {
                        failure: Failure::Lost,
                        tets_visited: visited,
                    });
                }
                return Err(TraceOutcome::Hit(Hit {
                    triangle: cf.triangle,
                    face: f.occlusion,
                    t: t as f32,
                    barycentrics,
                    tet,
                    far_tet: f.neighbor_tet().unwrap_or(NO_TET),
                    tets_visited: visited,
                }));
            }
        }
        match f.neighbor_tet() {
            Some(n) => Ok((n, f.neighbor_face())),
            None => Err(TraceOutcome::Miss {
                tets_visited: visited,
            }),
        }
    }
}

impl Tracer for Tet80Tracer<'_> {
    fn name(&self) -> String {
        "tet80/f32".into()
    }
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        if !ray.is_valid() {
            return TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            };
        }
        match start {
            Start::Tet(t) => {
                if t as usize >= self.layout.tets.len() {
                    return TraceOutcome::Failed {
                        failure: Failure::Lost,
                        tets_visited: 0,
                    };
                }
                let Some((t, k)) = start_exit_face::<TripleF32>(self.mesh, ray, t) else {
                    return TraceOutcome::Failed {
                        failure: Failure::Lost,
                        tets_visited: 1,
                    };
                };
                let f = self.layout.tets[t as usize].f[k];
                match self.leave(ray, t, f, 1) {
                    Ok((n, e)) => self.walk(ray, n, e, 1),
                    Err(out) => out,
                }
            }
            Start::Face { face, tet } => {
                let side = self
                    .mesh
                    .constrained
                    .get(face as usize)
                    .and_then(|cf| cf.side_of(tet));
                match side {
                    Some(s) => self.walk(ray, tet, s.face as usize, 0),
                    None => TraceOutcome::Failed {
                        failure: Failure::Lost,
                        tets_visited: 0,
                    },
                }
            }
        }
    }
}
