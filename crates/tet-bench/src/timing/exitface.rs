//! Exit-face search cost (Maria et al. 2017, Table 5): the time to choose the exit
//! face of a tet a ray has entered, per method, single-threaded.
//!
//! Maria et al. time "16,384 random rays stabbing 10,000 random
//! tetrahedra" per method; we time two things:
//!
//! * **stabs** ([`stab_rows`]): random tets of a jittered Kuhn grid, each
//!   stabbed by random lines through a random interior point. A stab is
//!   one decision as a walk makes it after entering a tet: the entry face
//!   and the per-ray setup (projection basis, projected entry face) are
//!   prepared untimed, as a walk carries them from the previous step; the
//!   timed part is what a step computes — for the 2-D projections
//!   (Aman et al.) projecting the new vertex `d` and the three edge signs
//!   ([`Projection::left_mask`] + [`EXIT_SLOT`]), for scalar triple
//!   products (Lagae & Dutré, [`TripleF32`]) the same with 3-D products,
//!   for the Plücker method of Maria et al. (2017) ([`tet80`](tet_trace_cpu::tet80))
//!   `m = d × (V_e − o)` and two side products looked up in
//!   [`tet_trace_cpu::tet80::EXIT`] (its walk loop is private; the same
//!   formulas are written here and checked against the f64 exit face).
//!   Every decision is checked against the exit face computed in f64
//!   (stabs closer than 1e-6 relative to an edge are not drawn).
//! * **walks** ([`walk_rows`]): the criterion bench of `tet-trace-cpu`
//!   (`benches/exit_face.rs`) as a timed harness: random rays from random
//!   interior points of the grid walked to their first constrained face
//!   by every CPU kernel (layout, memory and all), time per tet visited.
//!
//! | Maria et al. (2017) Table 5 | here |
//! |---|---|
//! | Ours (two Plücker side products) | `plucker (tet80)` |
//! | STP | `triple products (sctp)` |
//! | — (Aman et al. 2022) | `2-D projection` rows |

use std::hint::black_box;
use std::time::Instant;

use glam::{DVec3, Vec3};
use serde::Serialize;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_core::{FACE_VERTICES, TetMesh};
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::ray::Ray;
use tet_trace_cpu::reference::{Aim, random_direction, random_ray};
use tet_trace_cpu::walk::{EXIT_SLOT, Projection, Start};
use tet_trace_cpu::{DuffF32, DuffF64, OriginF32, TripleF32};

/// Maria et al. (2017) Table 5, CPU single thread: ms for 10,000 tets × 16,384 rays.
pub const PAPER_TABLE5_CPU_MS: [(&str, f64); 5] = [
    ("Ray/plane", 15_623.0),
    ("Plücker (Lagae & Dutré)", 10_101.0),
    ("STP", 4_876.0),
    ("MS06", 5_994.0),
    ("Ours (Maria et al.)", 2_663.0),
];

/// Stabs in Maria et al. (2017) Table 5.
pub const PAPER_STABS: f64 = 10_000.0 * 16_384.0;

/// Sizes of the exit-face harness.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ExitFaceSizes {
    /// Kuhn grid cells per axis (6 tets per cell).
    pub grid_cells: u32,
    /// Random tets stabbed.
    pub tets: usize,
    /// Random lines per tet.
    pub rays_per_tet: usize,
    /// Random rays walked.
    pub walk_rays: usize,
    /// Timed repetitions (best is reported).
    pub repetitions: u32,
}

impl ExitFaceSizes {
    /// `tables` full mode.
    pub const FULL: ExitFaceSizes = ExitFaceSizes {
        grid_cells: 24,
        tets: 10_000,
        rays_per_tet: 64,
        walk_rays: 16_384,
        repetitions: 5,
    };
    /// `tables --quick`.
    pub const QUICK: ExitFaceSizes = ExitFaceSizes {
        grid_cells: 16,
        tets: 2_000,
        rays_per_tet: 32,
        walk_rays: 4_096,
        repetitions: 3,
    };
}

/// One stab row.
#[derive(Clone, Debug, Serialize)]
pub struct StabRow {
    /// Decision procedure.
    pub method: String,
    /// Which `--method`s use it.
    pub used_by: String,
    /// Stabs timed.
    pub stabs: u64,
    /// Best time per stab, ns.
    pub ns_per_stab: f64,
    /// Floating-point operations per decision (and comparisons), from the
    /// kernels' module docs.
    pub operations: String,
    /// Decisions that differ from the f64 exit face (0 expected).
    pub wrong: u64,
    /// The ns per stab of Maria et al. (2017) for the same method, when it has one.
    pub paper_ns_per_stab: Option<f64>,
}

/// One walk row.
#[derive(Clone, Debug, Serialize)]
pub struct WalkRow {
    /// Tracer name.
    pub tracer: String,
    /// Rays walked.
    pub rays: usize,
    /// Tets visited by all rays.
    pub tets_visited: u64,
    /// Best time per tet visited, ns.
    pub ns_per_tet: f64,
    /// Hot bytes per tet of the layout.
    pub record_bytes: usize,
}

/// The exit-face table.
#[derive(Clone, Debug, Serialize)]
pub struct ExitFaceTable {
    /// Sizes used.
    pub sizes: ExitFaceSizes,
    /// Tets of the grid.
    pub grid_tets: usize,
    /// Stab rows.
    pub stabs: Vec<StabRow>,
    /// Walk rows.
    pub walks: Vec<WalkRow>,
}

/// A stab: a line through tet `tet` entering through the face opposite
/// slot `entry`, with the entry face's ids in the walk's order (the ray
/// passes left of each directed edge) and the exit slot found in f64.
#[derive(Clone, Copy, Debug)]
pub struct Stab {
    /// The ray (origin inside the tet).
    pub ray: Ray,
    /// Tet.
    pub tet: u32,
    /// Slot of the vertex opposite the entry face.
    pub entry: usize,
    /// Entry face ids, counter-clockwise around the ray.
    pub face: [u32; 3],
    /// The vertex opposite the entry face (`d` of the walk).
    pub d: u32,
    /// Slot of the vertex opposite the exit face (f64).
    pub exit: usize,
}

/// The jittered Kuhn grid of the harness (5 % of faces constrained).
pub fn grid(cells: u32) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [cells; 3],
        jitter: 0.12,
        constrained_fraction: 0.05,
        seed: 42,
        ..Default::default()
    })
}

/// Random stabs: `tets` random tets × `per_tet` random lines through a
/// random interior point; lines passing within `1e-6` (relative) of an
/// edge are redrawn, so every decision has one right answer.
pub fn stabs(mesh: &TetMesh, tets: usize, per_tet: usize, seed: u64) -> Vec<Stab> {
    let mut rng = SplitMix64(seed);
    let mut out = Vec::with_capacity(tets * per_tet);
    for _ in 0..tets {
        let t = (rng.next_u64() % mesh.tets.len() as u64) as u32;
        let v = mesh.tets[t as usize];
        let p = v.map(|i| mesh.points[i as usize]);
        let mut made = 0;
        let mut tries = 0;
        while made < per_tet && tries < 100 * per_tet {
            tries += 1;
            let w: [f64; 4] = std::array::from_fn(|_| rng.next_f64() + 1e-3);
            let sum: f64 = w.iter().sum();
            let o = (0..4).fold(DVec3::ZERO, |acc, k| acc + p[k].as_dvec3() * (w[k] / sum));
            let o32 = o.as_vec3();
            let dir = random_direction(&mut rng);
            if let Some(s) = classify(p, v, o32, dir) {
                out.push(Stab {
                    ray: Ray::new(o32, dir),
                    tet: t,
                    ..s
                });
                made += 1;
            }
        }
    }
    out
}

/// Entry and exit faces of the line `o + s·dir` through the tet with
/// points `p` and ids `v`, in f64: the entry face is the one whose
/// outward-ordered edges all have negative triple products
/// `dir · ((a − o) × (b − o))`, the exit face the one whose products are
/// all positive. `None` when a product is near zero (grazing an edge).
fn classify(p: [Vec3; 4], v: [u32; 4], o: Vec3, dir: Vec3) -> Option<Stab> {
    let o = o.as_dvec3();
    let d = dir.as_dvec3();
    let q = p.map(|x| x.as_dvec3() - o);
    let scale = q.iter().map(|x| x.length()).fold(0.0, f64::max).powi(2) * d.length();
    let mut entry = None;
    let mut exit = None;
    for (k, f) in FACE_VERTICES.iter().enumerate() {
        let s = [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])].map(|(a, b)| d.dot(q[a].cross(q[b])));
        if s.iter().any(|x| x.abs() <= 1e-6 * scale) {
            if s.iter().all(|x| *x > 0.0) || s.iter().all(|x| *x < 0.0) {
                return None;
            }
            continue;
        }
        if s.iter().all(|x| *x < 0.0) {
            entry = Some(k);
        } else if s.iter().all(|x| *x > 0.0) {
            exit = Some(k);
        }
    }
    let (e, x) = (entry?, exit?);
    let [a, b, c] = FACE_VERTICES[e];
    Some(Stab {
        ray: Ray::new(Vec3::ZERO, Vec3::X),
        tet: 0,
        entry: e,
        face: [v[a], v[c], v[b]],
        d: v[e],
        exit: x,
    })
}

/// Times the decision of projection `P` on every stab (best of `reps`):
/// returns ns per stab and the number of decisions differing from f64.
fn time_projected<P: Projection>(mesh: &TetMesh, stabs: &[Stab], reps: u32) -> (f64, u64) {
    let pre: Vec<(P, P::Face)> = stabs
        .iter()
        .map(|s| {
            let proj = P::setup(&s.ray);
            let face = P::face(s.face.map(|i| proj.project(mesh.points[i as usize])));
            (proj, face)
        })
        .collect();
    let decide = |(proj, face): &(P, P::Face), s: &Stab| {
        let pd = proj.project(mesh.points[s.d as usize]);
        EXIT_SLOT[proj.left_mask(pd, s.d, face, &s.face) & 7]
    };
    let wrong = stabs
        .iter()
        .zip(&pre)
        .filter(|(s, x)| {
            // The exit face is the entry face with this slot replaced by d:
            // the vertex in the slot is the one opposite the exit face.
            let replaced = s.face[decide(x, s) as usize];
            mesh.tets[s.tet as usize][s.exit] != replaced
        })
        .count() as u64;
    let best = best_of(reps, || {
        let mut acc = 0u32;
        for (s, x) in stabs.iter().zip(&pre) {
            acc = acc.wrapping_add(decide(black_box(x), s) as u32);
        }
        acc
    });
    (best * 1e9 / stabs.len().max(1) as f64, wrong)
}

/// `SECOND[e][s₁]` of the Plücker kernel: the second edge's vertex slot.
fn second_slot(e: usize, left_of_a: bool) -> usize {
    let [_, b, c] = FACE_VERTICES[e];
    if left_of_a { c } else { b }
}

/// Times the Plücker decision of Maria et al. (2017), as in the Tet80 kernel:
/// two side products in the frame of the vertex opposite the entry face.
fn time_plucker(mesh: &TetMesh, stabs: &[Stab], reps: u32) -> (f64, u64) {
    // The Tet80 record holds the four positions inline.
    let records: Vec<[Vec3; 4]> = stabs
        .iter()
        .map(|s| mesh.tets[s.tet as usize].map(|i| mesh.points[i as usize]))
        .collect();
    let decide = |r: &[Vec3; 4], s: &Stab| {
        let (o, d) = (s.ray.origin, s.ray.direction);
        let e = s.entry;
        let apex = r[e];
        let m = d.cross(apex - o);
        let s1 = (r[FACE_VERTICES[e][0]] - apex).dot(m) > 0.0;
        let s2 = (r[second_slot(e, s1)] - apex).dot(m) > 0.0;
        tet_trace_cpu::tet80::EXIT[e][2 * s1 as usize + s2 as usize]
    };
    let wrong = stabs
        .iter()
        .zip(&records)
        .filter(|(s, r)| decide(r, s) as usize != s.exit)
        .count() as u64;
    let best = best_of(reps, || {
        let mut acc = 0u32;
        for (s, r) in stabs.iter().zip(&records) {
            acc = acc.wrapping_add(decide(black_box(r), s) as u32);
        }
        acc
    });
    (best * 1e9 / stabs.len().max(1) as f64, wrong)
}

/// Best wall time (s) of `reps` runs of `f` (at least one).
fn best_of(reps: u32, mut f: impl FnMut() -> u32) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps.max(1) {
        let start = Instant::now();
        black_box(f());
        best = best.min(start.elapsed().as_secs_f64());
    }
    best
}

/// The paper's ns per stab for a row of Maria et al. (2017) Table 5.
fn paper_ns(name: &str) -> Option<f64> {
    PAPER_TABLE5_CPU_MS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, ms)| ms * 1e6 / PAPER_STABS)
}

/// The stab rows (single-threaded, on the calling thread).
pub fn stab_rows(mesh: &TetMesh, stabs: &[Stab], reps: u32) -> Vec<StabRow> {
    let n = stabs.len() as u64;
    let row = |method: &str, used_by: &str, (ns, wrong): (f64, u64), ops: &str, paper| StabRow {
        method: method.into(),
        used_by: used_by.into(),
        stabs: n,
        ns_per_stab: ns,
        operations: ops.into(),
        wrong,
        paper_ns_per_stab: paper,
    };
    vec![
        row(
            "2-D projection, f32 (Duff basis)",
            "tet20, tet16, tet32",
            time_projected::<DuffF32>(mesh, stabs, reps),
            "project d: 3 sub + 6 mul + 4 add; 3 det: 6 mul + 3 sub; 3 cmp + table",
            None,
        ),
        row(
            "2-D projection, f32, projected origin (Eq. 4-5)",
            "(variant)",
            time_projected::<OriginF32>(mesh, stabs, reps),
            "project d: 6 mul + 6 add/sub; 3 det: 6 mul + 3 sub; 3 cmp + table",
            None,
        ),
        row(
            "2-D projection, f64",
            "tet20/16/32 --precision f64",
            time_projected::<DuffF64>(mesh, stabs, reps),
            "as f32, in f64 (+ 3 conversions)",
            None,
        ),
        row(
            "scalar triple products, f32",
            "sctp",
            time_projected::<TripleF32>(mesh, stabs, reps),
            "3 sub; 3 × (cross 6 mul + 3 sub, dot 3 mul + 2 add); 3 cmp + table",
            paper_ns("STP"),
        ),
        row(
            "Plücker side products, f32 (Maria et al. 2017)",
            "tet80",
            time_plucker(mesh, stabs, reps),
            "m: 3 sub + 6 mul + 3 sub; 2 × (3 sub + 3 mul + 2 add); 2 cmp + table (paper: 28)",
            paper_ns("Ours (Maria et al.)"),
        ),
    ]
}

/// The walk rows: `rays` random rays walked by every CPU kernel
/// (single-threaded, on the calling thread), best of `reps`.
pub fn walk_rows(mesh: &TetMesh, rays: usize, reps: u32) -> anyhow::Result<Vec<WalkRow>> {
    use tet_trace_cpu::sctp::SctpTracer;
    use tet_trace_cpu::tet16::Tet16Tracer;
    use tet_trace_cpu::tet20::{Tet20Tracer, Tet20TracerF64};
    use tet_trace_cpu::tet32::Tet32Tracer;
    use tet_trace_cpu::tet80::Tet80Tracer;
    let mut rng = SplitMix64(7);
    let rays: Vec<(Ray, u32)> = (0..rays)
        .map(|_| random_ray(mesh, &mut rng, Aim::Random))
        .collect();
    let tracers: Vec<(Box<dyn Tracer + '_>, usize)> = vec![
        (Box::new(<Tet20Tracer<'_>>::new(mesh)?), 20),
        (
            Box::new(tet_trace_cpu::scaled::ScaledTracer::tet20(mesh)?),
            20,
        ),
        (Box::new(Tet20TracerF64::new(mesh)?), 20),
        (Box::new(<Tet16Tracer<'_>>::new(mesh)?), 16),
        (Box::new(<Tet32Tracer<'_>>::new(mesh)?), 32),
        (Box::new(<SctpTracer<'_>>::new(mesh)?), 32),
        (Box::new(Tet80Tracer::new(mesh)?), 80),
    ];
    let mut rows = Vec::new();
    for (t, record_bytes) in &tracers {
        let steps: u64 = rays
            .iter()
            .map(|(r, s)| t.trace(r, Start::Tet(*s)).tets_visited() as u64)
            .sum();
        let best = best_of(reps, || {
            let mut acc = 0u32;
            for (r, s) in &rays {
                acc = acc.wrapping_add(t.trace(black_box(r), Start::Tet(*s)).tets_visited());
            }
            acc
        });
        rows.push(WalkRow {
            tracer: t.name(),
            rays: rays.len(),
            tets_visited: steps,
            ns_per_tet: best * 1e9 / steps.max(1) as f64,
            record_bytes: *record_bytes,
        });
    }
    Ok(rows)
}

/// Runs the whole harness.
pub fn run(sizes: ExitFaceSizes) -> anyhow::Result<ExitFaceTable> {
    let mesh = grid(sizes.grid_cells);
    let stabs = stabs(&mesh, sizes.tets, sizes.rays_per_tet, 1);
    Ok(ExitFaceTable {
        sizes,
        grid_tets: mesh.tets.len(),
        stabs: stab_rows(&mesh, &stabs, sizes.repetitions),
        walks: walk_rows(&mesh, sizes.walk_rays, sizes.repetitions)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stabs' f64 entry and exit faces are right (checked by
    /// intersecting the line with the face planes independently), and
    /// every decision procedure picks the same exit face.
    #[test]
    fn every_method_finds_the_f64_exit_face() {
        let mesh = grid(4);
        let stabs = stabs(&mesh, 200, 8, 3);
        assert!(stabs.len() >= 1500, "few stabs were drawn: {}", stabs.len());
        for s in &stabs {
            let v = mesh.tets[s.tet as usize];
            let p = v.map(|i| mesh.points[i as usize].as_dvec3());
            let (o, d) = (s.ray.origin.as_dvec3(), s.ray.direction.as_dvec3());
            // Plane crossings: the exit face is the nearest plane ahead
            // (t > 0) that the line leaves through, the entry the nearest
            // behind.
            let cross = |k: usize| {
                let [a, b, c] = FACE_VERTICES[k].map(|i| p[i]);
                let n = (b - a).cross(c - a);
                (n.dot(a - o) / n.dot(d), n.dot(d))
            };
            let exit = (0..4)
                .filter(|&k| cross(k).1 > 0.0)
                .min_by(|&x, &y| cross(x).0.total_cmp(&cross(y).0))
                .unwrap();
            let entry = (0..4)
                .filter(|&k| cross(k).1 < 0.0)
                .max_by(|&x, &y| cross(x).0.total_cmp(&cross(y).0))
                .unwrap();
            assert_eq!(s.exit, exit);
            assert_eq!(s.entry, entry);
            assert_eq!(s.d, v[entry]);
        }
        for row in stab_rows(&mesh, &stabs, 1) {
            assert_eq!(row.wrong, 0, "{}", row.method);
            assert_eq!(row.stabs, stabs.len() as u64);
            assert!(row.ns_per_stab > 0.0 && row.ns_per_stab.is_finite());
        }
    }

    #[test]
    fn walk_rows_cover_every_kernel_with_the_same_steps() {
        let mesh = grid(4);
        let rows = walk_rows(&mesh, 64, 1).unwrap();
        assert_eq!(rows.len(), 7);
        // Every kernel walks the same rays to the same first constrained
        // face through the same tets (random directions do not graze).
        for r in &rows {
            assert_eq!(r.tets_visited, rows[0].tets_visited, "{}", r.tracer);
            assert!(r.ns_per_tet > 0.0);
        }
    }
}
