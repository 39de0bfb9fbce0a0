//! The lockstep walks where the public widths do not reach, against the
//! scalar walks ray by ray, bit for bit: 1, 3 and 5 portable lanes (odd
//! packs: refills and parking at every lane count), and gates (the
//! projected walk's and the Plücker walk's handover, walked on by the
//! scalar walk from the state handed over). `tests/lockstep.rs` and
//! `tests/lockstep_tet80.rs` cover the public widths.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};

use super::driver::{Gate, NoGate};
use super::plucker::Begun;
use super::portable::Portable;
use super::{Geometry, Handover, Planar, Plucker, Triple, Width, trace};
use crate::kernel::WalkTracer;
use crate::locate::locate;
use crate::ray::{Ray, TraceOutcome};
use crate::reference::{Aim, random_direction, random_point_inside, ray_from_feature};
use crate::sctp::SctpTracer;
use crate::tet16::Tet16Tracer;
use crate::tet20::Tet20Tracer;
use crate::tet32::Tet32Tracer;
use crate::tet80::Tet80Tracer;
use crate::walk::lanes::Batch;
use crate::walk::start::begin;
use crate::walk::step::{advance, finish_step};
use crate::walk::stop::Advance;
use crate::walk::{DuffF32, Projection, Start, Starts, Topology, TripleF32};

/// A validated jittered Kuhn grid with random constrained faces, or a
/// closed shell one cell in.
fn grid(cells: u32, jitter: f32, fraction: f64, shell: bool, seed: u64) -> TetMesh {
    let m = kuhn_grid(&GridSpec {
        cells: [cells; 3],
        jitter,
        constrained_fraction: fraction,
        shell: shell.then_some(([1; 3], [cells - 1; 3])),
        seed,
        ..Default::default()
    });
    m.validate().unwrap();
    m
}

/// Every bit of an outcome.
fn bits(o: &TraceOutcome) -> String {
    match *o {
        TraceOutcome::Hit(h) => format!(
            "hit {} {} {:x} {:x?} {} {} {}",
            h.triangle,
            h.face,
            h.t.to_bits(),
            h.barycentrics.map(f32::to_bits),
            h.tet,
            h.far_tet,
            h.tets_visited
        ),
        o => format!("{o:?}"),
    }
}

/// `n` rays from `origin`: random, at vertices, at face centroids, along
/// the axes, some with a `t_min`/`t_max` window, some invalid.
fn rays(mesh: &TetMesh, rng: &mut SplitMix64, origin: Vec3, n: usize) -> Vec<Ray> {
    (0..n)
        .map(|i| {
            let point = mesh.points[(rng.next_u64() % mesh.points.len() as u64) as usize];
            let dir = match i % 6 {
                0 | 1 => random_direction(rng),
                2 => point - origin,
                3 => {
                    let t = mesh.tets[(rng.next_u64() % mesh.tets.len() as u64) as usize];
                    let f = t.map(|v| mesh.points[v as usize]);
                    (f[0] + f[1] + f[2]) / 3.0 - origin
                }
                4 => Vec3::AXES[(rng.next_u64() % 3) as usize],
                _ if rng.next_u64().is_multiple_of(5) => Vec3::ZERO,
                _ => random_direction(rng),
            };
            let mut r = Ray::new(origin, dir);
            match rng.next_u64() % 4 {
                0 => r.t_min = rng.range_f32(0.0, 2.0),
                1 => r.t_max = rng.range_f32(0.0, 2.0),
                _ => {}
            }
            r
        })
        .collect()
}

/// Batches to check on `mesh`: rays from points inside, from vertices and
/// edge midpoints, and restarted on constrained faces, with their start.
fn cases(mesh: &TetMesh, seed: u64) -> Vec<(Vec<Ray>, Start)> {
    let mut rng = SplitMix64(seed);
    let mut out = Vec::new();
    for k in 0..6 {
        let (origin, hint) = match k % 3 {
            0 => random_point_inside(mesh, &mut rng),
            _ => {
                let aim = [Aim::Vertex, Aim::EdgeMidpoint][k % 2];
                (ray_from_feature(mesh, &mut rng, aim).origin, 0)
            }
        };
        let start = Start::Tet(locate(mesh, origin, hint).unwrap());
        out.push((rays(mesh, &mut rng, origin, 29), start));
    }
    for c in (0..mesh.constrained.len()).step_by(mesh.constrained.len() / 3 + 1) {
        let cf = &mesh.constrained[c];
        let v = cf.vertices.map(|i| mesh.points[i as usize]);
        for side in [cf.front, cf.back].into_iter().filter(|s| s.exists()) {
            let start = Start::Face {
                face: c as u32,
                tet: side.tet,
            };
            out.push((rays(mesh, &mut rng, (v[0] + v[1] + v[2]) / 3.0, 17), start));
        }
    }
    out
}

/// The meshes and step caps of every check.
fn meshes() -> Vec<(TetMesh, Option<u32>)> {
    vec![
        (grid(4, 0.12, 0.08, false, 7), None),
        (grid(5, 0.1, 0.05, true, 3), None),
        // Unjittered: axis rays run along faces and edges, many exact ties.
        (grid(4, 0.0, 0.1, false, 9), None),
        (grid(5, 0.1, 0.05, true, 4), Some(3)),
    ]
}

/// A fresh output buffer that no walk's outcome equals.
fn fresh(n: usize) -> Vec<TraceOutcome> {
    vec![
        TraceOutcome::Miss {
            tets_visited: u32::MAX
        };
        n
    ]
}

/// The lockstep walk of geometry `G` on `W` portable lanes.
fn portable<G: Geometry<T>, T, const W: usize>(batch: Batch<'_, T>) {
    let ran = G::walk::<Portable<W>, NoGate, 1>(Portable, batch, &mut NoGate);
    assert!(ran.is_ok(), "the portable lanes read any records");
}

/// `t`'s walk of geometry `G` on 1, 3 and 5 portable lanes equals its
/// scalar walk.
fn check_projected<G, L, P>(t: &WalkTracer<'_, L, P>, rays: &[Ray], start: Start)
where
    G: Geometry<L>,
    L: Topology,
    P: Projection,
{
    let (mesh, topo, cap) = (t.mesh, &t.layout, t.cap);
    let want: Vec<String> = rays
        .iter()
        .map(|r| bits(&crate::walk::trace::<P, L>(mesh, topo, r, start, cap)))
        .collect();
    let starts = Starts::Same(start);
    for lanes in [1, 3, 5] {
        let mut got = fresh(rays.len());
        let batch = t.batch(rays, starts, &mut got);
        match lanes {
            1 => portable::<G, L, 1>(batch),
            3 => portable::<G, L, 3>(batch),
            _ => portable::<G, L, 5>(batch),
        }
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(bits(&got[i]), want[i], "{} {lanes} lanes: {r:?}", t.name);
        }
    }
}

#[test]
fn odd_portable_lane_counts_equal_the_scalar_walks() {
    for (mesh, cap) in meshes() {
        let cap = cap.unwrap_or(crate::walk::step_cap(&mesh));
        let t20 = Tet20Tracer::<DuffF32>::new(&mesh)
            .unwrap()
            .with_step_cap(cap);
        let t16 = Tet16Tracer::<DuffF32>::new(&mesh)
            .unwrap()
            .with_step_cap(cap);
        let t32 = Tet32Tracer::<DuffF32>::new(&mesh)
            .unwrap()
            .with_step_cap(cap);
        let sctp = SctpTracer::<TripleF32>::new(&mesh)
            .unwrap()
            .with_step_cap(cap);
        let t80 = Tet80Tracer::new(&mesh).unwrap().with_step_cap(cap);
        let t80c = Tet80Tracer::consistent(&mesh).unwrap().with_step_cap(cap);
        for (rays, start) in cases(&mesh, 17) {
            check_projected::<Planar, _, _>(&t20, &rays, start);
            check_projected::<Planar, _, _>(&t16, &rays, start);
            check_projected::<Planar, _, _>(&t32, &rays, start);
            check_projected::<Triple, _, _>(&sctp, &rays, start);
            check_plucker(&t80, &rays, start);
            check_plucker(&t80c, &rays, start);
        }
    }
}

/// The Plücker walk of `t` on 1, 3 and 5 portable lanes equals its scalar
/// batch walk.
fn check_plucker<const C: bool>(t: &Tet80Tracer<'_, C>, rays: &[Ray], start: Start) {
    let starts = Starts::Same(start);
    let mut want = fresh(rays.len());
    t.trace_batch_from_scalar(rays, starts, &mut want);
    for lanes in [1, 3, 5] {
        let mut got = fresh(rays.len());
        let batch = t.batch(rays, starts, &mut got);
        match lanes {
            1 => portable::<Plucker, _, 1>(batch),
            3 => portable::<Plucker, _, 3>(batch),
            _ => portable::<Plucker, _, 5>(batch),
        }
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(
                bits(&got[i]),
                bits(&want[i]),
                "tet80 {C} {lanes} lanes: {r:?}"
            );
        }
    }
}

/// A gate at every tet `t` with `t % every == rest`, keeping what it
/// receives.
struct EveryNth<H> {
    every: u32,
    rest: u32,
    handed: Vec<(usize, H)>,
}

impl<H> Gate<H> for EveryNth<H> {
    const ON: bool = true;
    fn stops_before(&self, tet: u32) -> bool {
        tet % self.every == self.rest
    }
    fn hand_over(&mut self, ray: usize, h: H) {
        self.handed.push((ray, h));
    }
}

/// Runs `walk` (a gated walk of `n` rays into `out`) and checks it: the
/// walks it hands over are handed over once, before a tet the gate names,
/// and `resume` walks each on to the scalar outcome `want`; the others
/// end in lockstep with that outcome.
fn check_gated<H: Copy>(
    name: &str,
    want: &[String],
    gate: EveryNth<H>,
    got: &[TraceOutcome],
    tet_of: impl Fn(&H) -> u32,
    resume: impl Fn(usize, H) -> TraceOutcome,
) -> usize {
    let mut handed = vec![false; want.len()];
    for &(i, h) in &gate.handed {
        assert!(!handed[i], "{name}: ray {i} handed over twice");
        handed[i] = true;
        assert!(
            gate.stops_before(tet_of(&h)),
            "{name}: handed over elsewhere"
        );
        assert_eq!(bits(&resume(i, h)), want[i], "{name}: ray {i} resumed");
    }
    for (i, o) in got.iter().enumerate().filter(|(i, _)| !handed[*i]) {
        assert_eq!(bits(o), want[i], "{name}: ray {i} in lockstep");
    }
    gate.handed.len()
}

/// The gated walk of geometry `G` at `width`, or on 3 portable lanes
/// (`None`); false when the CPU lacks the width.
fn gated<G: Geometry<T>, T>(
    batch: Batch<'_, T>,
    width: Option<Width>,
    gate: &mut EveryNth<G::Handover>,
) -> bool {
    match width {
        Some(w) => trace::<G, T, _>(batch, w, gate).is_ok(),
        None => G::walk::<Portable<3>, _, 1>(Portable, batch, gate).is_ok(),
    }
}

#[test]
fn gated_walks_hand_over_exactly_where_the_gate_says() {
    let mut handed = 0;
    for (mesh, cap) in meshes() {
        let cap = cap.unwrap_or(crate::walk::step_cap(&mesh));
        let t20 = Tet20Tracer::<DuffF32>::new(&mesh)
            .unwrap()
            .with_step_cap(cap);
        let t80c = Tet80Tracer::consistent(&mesh).unwrap().with_step_cap(cap);
        let t80 = Tet80Tracer::new(&mesh).unwrap().with_step_cap(cap);
        for (rays, start) in cases(&mesh, 29) {
            let starts = Starts::Same(start);
            let widths = [
                None,
                Some(Width::Portable8),
                Some(Width::Avx2),
                Some(Width::Avx512),
            ];
            for (k, width) in widths.into_iter().enumerate() {
                let every = 3 + k as u32;
                // Projected (Tet20): the scalar walk from the same start,
                // resumed from the handover.
                let want: Vec<String> = rays
                    .iter()
                    .map(|r| {
                        bits(&crate::walk::trace::<DuffF32, _>(
                            &mesh,
                            &t20.layout,
                            r,
                            start,
                            cap,
                        ))
                    })
                    .collect();
                let mut gate = EveryNth::<Handover> {
                    every,
                    rest: 1,
                    handed: Vec::new(),
                };
                let mut got = fresh(rays.len());
                if gated::<Planar, _>(t20.batch(&rays, starts, &mut got), width, &mut gate) {
                    let resume = |i: usize, h: Handover| {
                        let mut lane = begin::<DuffF32>(&mesh, &rays[i], start).unwrap();
                        h.resume(&mut lane, &mesh.points);
                        loop {
                            let adv = advance(&mesh.points, &t20.layout, &mut lane, cap);
                            if adv != Advance::Go
                                && let Some(o) = finish_step(&mesh, &rays[i], &mut lane, adv)
                            {
                                return o;
                            }
                        }
                    };
                    handed += check_gated("tet20", &want, gate, &got, |h| h.next, resume);
                }
                // Plücker, both side rules: their scalar walk from the state
                // handed over.
                for consistent in [false, true] {
                    let mut want = fresh(rays.len());
                    let mut gate = EveryNth::<Begun> {
                        every,
                        rest: 2,
                        handed: Vec::new(),
                    };
                    let mut got = fresh(rays.len());
                    let ran = if consistent {
                        t80c.trace_batch_from_scalar(&rays, starts, &mut want);
                        gated::<Plucker, _>(t80c.batch(&rays, starts, &mut got), width, &mut gate)
                    } else {
                        t80.trace_batch_from_scalar(&rays, starts, &mut want);
                        gated::<Plucker, _>(t80.batch(&rays, starts, &mut got), width, &mut gate)
                    };
                    if !ran {
                        continue;
                    }
                    let want: Vec<String> = want.iter().map(bits).collect();
                    let resume = |i: usize, b: Begun| {
                        if consistent {
                            t80c.walk_from(&rays[i], b)
                        } else {
                            t80.walk_from(&rays[i], b)
                        }
                    };
                    handed += check_gated("tet80", &want, gate, &got, |b| b.tet, resume);
                }
            }
        }
    }
    assert!(handed > 100, "{handed} walks handed over");
}

/// Bounded walks ([`crate::walk::reach`]) in lockstep, on 3 portable lanes
/// and at every width the CPU has, equal the scalar bounded walk bit for
/// bit; each ends as the whole walk does (hit or miss; a step-cap failure
/// may become a miss) and visits no more tets. Rays with a short `t_max`
/// make the stop frequent.
#[test]
fn bounded_walks_in_lockstep_equal_the_scalar_bounded_walk() {
    let mut stopped_short = 0;
    for (mesh, cap) in meshes() {
        let cap = cap.unwrap_or(crate::walk::step_cap(&mesh));
        let t20 = Tet20Tracer::<DuffF32>::new(&mesh)
            .unwrap()
            .with_step_cap(cap);
        let sctp = SctpTracer::<TripleF32>::new(&mesh)
            .unwrap()
            .with_step_cap(cap);
        let mut rng = SplitMix64(41);
        for (mut rays, start) in cases(&mesh, 31) {
            for r in rays.iter_mut() {
                if !rng.next_u64().is_multiple_of(3) {
                    r.t_max = rng.range_f32(0.05, 1.5);
                }
            }
            let starts = Starts::Same(start);
            let within = |r: &Ray| {
                crate::walk::trace_within::<DuffF32, _>(&mesh, &t20.layout, r, start, cap)
            };
            let want: Vec<String> = rays.iter().map(|r| bits(&within(r))).collect();
            for (r, w) in rays.iter().zip(&want) {
                let whole = crate::walk::trace::<DuffF32, _>(&mesh, &t20.layout, r, start, cap);
                let bounded = within(r);
                if !matches!(whole, TraceOutcome::Failed { .. }) {
                    assert_eq!(bounded.hit(), whole.hit(), "{r:?}: {w} vs {whole:?}");
                }
                assert!(bounded.tets_visited() <= whole.tets_visited(), "{r:?}");
                stopped_short += (bounded.tets_visited() < whole.tets_visited()) as usize;
            }
            let widths = [None, Some(Width::Avx2), Some(Width::Avx512)];
            for width in widths {
                let mut got = fresh(rays.len());
                let batch = Batch {
                    bounded: true,
                    ..t20.batch(&rays, starts, &mut got)
                };
                let ran = match width {
                    None => <Planar as Geometry<_>>::walk::<Portable<3>, _, 1>(
                        Portable,
                        batch,
                        &mut NoGate,
                    )
                    .is_ok(),
                    Some(w) => trace::<Planar, _, _>(batch, w, &mut NoGate).is_ok(),
                };
                if !ran {
                    continue;
                }
                for (i, r) in rays.iter().enumerate() {
                    assert_eq!(bits(&got[i]), want[i], "tet20 {width:?}: {r:?}");
                }
            }
            // ScTP: its own projection, the same rule.
            let want: Vec<String> = rays
                .iter()
                .map(|r| {
                    bits(&crate::walk::trace_within::<TripleF32, _>(
                        &mesh,
                        &sctp.layout,
                        r,
                        start,
                        cap,
                    ))
                })
                .collect();
            let mut got = fresh(rays.len());
            let batch = Batch {
                bounded: true,
                ..sctp.batch(&rays, starts, &mut got)
            };
            portable::<Triple, _, 3>(batch);
            for (i, r) in rays.iter().enumerate() {
                assert_eq!(bits(&got[i]), want[i], "sctp: {r:?}");
            }
        }
    }
    assert!(stopped_short > 50, "{stopped_short} walks stopped short");
}
