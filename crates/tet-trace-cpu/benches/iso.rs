//! Isosurface ray tracing throughput (Wald et al. 2007): IBVH builds (BIH, SAH),
//! refit, single rays, 16 × 16 packets and the iso walks (Tet32, Tet20,
//! Tet16) on a Kuhn grid with a sum-of-Gaussians field, primary rays of a
//! camera framing the box. A plain timing harness (not criterion): each
//! figure is the best of a few runs, printed as a table.
//!
//! `cargo bench -p tet-trace-cpu --bench iso -- [cells] [res] [threads]`
//! (defaults 32, 1024, 1: 196 608 tets, 1024² rays, one thread).

use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::iso::walk::IsoOutcome;
use tet_trace_cpu::iso::{BuildKind, Ibvh, IsoHit, IsoQuery, IsoStats, IsoWalk, WalkLayout};
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::walk::EntryHint;
use tet_trace_cpu::{DuffF32, Ray, Start, Starts, TraceOutcome, Tracer, Viewpoint};

fn gaussians(mesh: &TetMesh, n: f32) -> Vec<f32> {
    let mut r = SplitMix64(9);
    let bumps: Vec<(Vec3, f32)> = (0..12)
        .map(|_| {
            let c = Vec3::new(
                r.range_f32(0.2, 0.8),
                r.range_f32(0.2, 0.8),
                r.range_f32(0.2, 0.8),
            ) * n;
            (c, r.range_f32(0.06, 0.14) * n)
        })
        .collect();
    mesh.points
        .iter()
        .map(|p| {
            bumps
                .iter()
                .map(|&(c, s)| (-p.distance_squared(c) / (2.0 * s * s)).exp())
                .sum()
        })
        .collect()
}

/// Primary rays in 16 × 16 tiles (tile-major), from `eye` framing the box
/// `[0, n]³`.
fn camera(n: f32, res: usize) -> (Vec3, Vec<Ray>) {
    let centre = Vec3::splat(n * 0.5);
    let eye = centre + Vec3::new(1.3, -1.7, 1.1) * n;
    let fwd = (centre - eye).normalize();
    let right = fwd.cross(Vec3::Z).normalize();
    let up = right.cross(fwd);
    let half = 0.9 * (n * 0.5 * 3f32.sqrt()) / (centre - eye).length();
    let mut rays = Vec::with_capacity(res * res);
    for ty in (0..res).step_by(16) {
        for tx in (0..res).step_by(16) {
            for y in ty..(ty + 16).min(res) {
                for x in tx..(tx + 16).min(res) {
                    let u = ((x as f32 + 0.5) / res as f32 * 2.0 - 1.0) * half;
                    let v = ((y as f32 + 0.5) / res as f32 * 2.0 - 1.0) * half;
                    rays.push(Ray::new(eye, fwd + right * u + up * v));
                }
            }
        }
    }
    (eye, rays)
}

fn best_ms<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..runs {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        out = Some(r);
    }
    (best, out.expect("at least one run"))
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let cells = *args.first().unwrap_or(&32) as u32;
    let res = *args.get(1).unwrap_or(&1024);
    let threads = *args.get(2).unwrap_or(&1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mesh = kuhn_grid(&GridSpec {
        cells: [cells; 3],
        jitter: 0.1,
        seed: 1,
        ..Default::default()
    });
    let n = cells as f32;
    let values = gaussians(&mesh, n);
    let isos = [0.5f32];
    let q = IsoQuery::new(&isos);
    let (eye, rays) = camera(n, res);
    println!(
        "iso bench: {} tets, {} points, {}² rays, {} thread(s), isovalue {:?}",
        mesh.tets.len(),
        mesh.points.len(),
        res,
        threads,
        isos
    );
    pool.install(|| {
        let (bih_ms, bih) = best_ms(3, || Ibvh::build(&mesh, &values, BuildKind::Bih).unwrap());
        let (sah_ms, sah) = best_ms(3, || Ibvh::build(&mesh, &values, BuildKind::Sah).unwrap());
        let values2 = gaussians(&mesh, n * 0.97);
        let mut refit = bih.clone();
        let (refit_ms, _) = best_ms(3, || refit.refit(&values2).unwrap());
        println!("| structure | build ms | bytes | depth |");
        println!("|---|---|---|---|");
        println!("| IBVH BIH | {bih_ms:.1} | {} | {} |", bih.bytes(), bih.depth());
        println!("| IBVH SAH | {sah_ms:.1} | {} | {} |", sah.bytes(), sah.depth());
        println!("| IBVH refit (Schema II) | {refit_ms:.1} | | |");
        let walks: Vec<(WalkLayout, IsoWalk, f64)> = WalkLayout::ALL
            .iter()
            .map(|&l| {
                let (ms, w) = best_ms(1, || IsoWalk::new(&mesh, &values, l).unwrap());
                (l, w, ms)
            })
            .collect();
        for (l, w, ms) in &walks {
            println!("| walk {} | {ms:.1} (encode) | {} | |", l.name(), w.bytes());
        }
        let rays_m = rays.len() as f64 / 1e6;
        println!();
        println!("| method | ms | Mrays/s | hits | nodes/ray | isopoly tests/ray | tets/ray |");
        println!("|---|---|---|---|---|---|---|");
        let report = |name: &str, ms: f64, hits: &[Option<IsoHit>], st: &IsoStats| {
            let h = hits.iter().filter(|h| h.is_some()).count();
            let per = |x: u64| x as f64 / rays.len() as f64;
            println!(
                "| {name} | {ms:.1} | {:.2} | {h} | {:.1} | {:.1} | {:.1} |",
                rays_m / (ms / 1e3),
                per(st.nodes_visited),
                per(st.isopolygon_tests),
                per(st.range_tests)
            );
        };
        for (name, bvh) in [("ibvh-bih", &bih), ("ibvh-sah", &sah)] {
            let (ms, (hits, st)) = best_ms(3, || {
                let parts: Vec<(Vec<Option<IsoHit>>, IsoStats)> = rays
                    .par_chunks(256)
                    .map(|tile| {
                        let mut st = IsoStats::default();
                        let h = tile.iter().map(|r| bvh.trace_stats(r, &q, &mut st)).collect();
                        (h, st)
                    })
                    .collect();
                merge(parts)
            });
            report(&format!("{name} single"), ms, &hits, &st);
            let (ms, (phits, st)) = best_ms(3, || {
                let parts: Vec<(Vec<Option<IsoHit>>, IsoStats)> = rays
                    .par_chunks(256)
                    .map(|tile| {
                        let mut st = IsoStats::default();
                        let mut h = vec![None; tile.len()];
                        bvh.trace_packet_stats(tile, &q, &mut h, &mut st);
                        (h, st)
                    })
                    .collect();
                merge(parts)
            });
            assert_eq!(hits, phits, "packets differ from single rays");
            report(&format!("{name} packets 16×16"), ms, &phits, &st);
        }
        // Baseline: the plain Tet20 walk (no isosurface, SIMD lockstep
        // batches), every ray that enters the volume walked to its far side
        // from its entry face (found beforehand, untimed): its cost per tet
        // is the floor of the iso walk's.
        {
            let tracer = Tet20Tracer::<DuffF32>::new(&mesh).expect("tet20 layout");
            let vp = Viewpoint::locate(&mesh, eye).expect("viewpoint");
            let (entering, starts): (Vec<Ray>, Vec<Start>) = rays
                .par_iter()
                .filter_map(|r| vp.start(&tracer, r).ok().map(|s| (*r, s)))
                .unzip();
            let (ms, steps) = best_ms(3, || {
                entering
                    .par_chunks(256)
                    .zip(starts.par_chunks(256))
                    .map(|(tile, st)| {
                        let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; tile.len()];
                        tracer.trace_batch_from(tile, Starts::Each(st), &mut out);
                        out.iter().map(|o| o.tets_visited() as u64).sum::<u64>()
                    })
                    .sum::<u64>()
            });
            println!(
                "| plain tet20 walk through the volume ({} entering rays; baseline) | {ms:.1} | {:.2} | | | | {:.1} |",
                entering.len(),
                entering.len() as f64 / 1e6 / (ms / 1e3),
                steps as f64 / entering.len() as f64
            );
            println!("|   (ns per tet: {:.1}) | | | | | | |", ms * 1e6 / steps as f64);
            // The same walks one ray at a time (the scalar walk the iso
            // walk builds on).
            let (ms, steps) = best_ms(3, || {
                entering
                    .par_chunks(256)
                    .zip(starts.par_chunks(256))
                    .map(|(tile, st)| {
                        tile.iter()
                            .zip(st)
                            .map(|(r, s)| tracer.trace(r, *s).tets_visited() as u64)
                            .sum::<u64>()
                    })
                    .sum::<u64>()
            });
            println!(
                "| plain tet20 walk, single rays (baseline) | {ms:.1} | {:.2} | | | | {:.1} |",
                entering.len() as f64 / 1e6 / (ms / 1e3),
                steps as f64 / entering.len() as f64
            );
            println!("|   (ns per tet: {:.1}) | | | | | | |", ms * 1e6 / steps as f64);
        }
        let reference: Vec<Option<IsoHit>> = rays.iter().map(|r| bih.trace(r, &q)).collect();
        for (l, w, _) in &walks {
            let vp = w.viewpoint(eye).expect("camera viewpoint");
            let (ms, (hits, st, failed)) = best_ms(3, || {
                let parts: Vec<(Vec<Option<IsoHit>>, IsoStats, usize)> = rays
                    .par_chunks(256)
                    .map(|tile| {
                        let mut st = IsoStats::default();
                        let mut hint = EntryHint::default();
                        let mut failed = 0;
                        let h = tile
                            .iter()
                            .map(|r| match w.trace_from(&vp, r, &q, &mut hint, &mut st) {
                                IsoOutcome::Hit { hit, .. } => Some(hit),
                                IsoOutcome::Miss { .. } => None,
                                IsoOutcome::Failed { .. } => {
                                    failed += 1;
                                    None
                                }
                            })
                            .collect();
                        (h, st, failed)
                    })
                    .collect();
                let failed = parts.iter().map(|p| p.2).sum::<usize>();
                let (h, st) = merge(parts.into_iter().map(|p| (p.0, p.1)).collect());
                (h, st, failed)
            });
            report(&format!("walk {}", l.name()), ms, &hits, &st);
            println!("|   (ns per tet: {:.1}) | | | | | | |", ms * 1e6 / st.range_tests as f64);
            let (ms, (thits, st)) = best_ms(3, || {
                let parts: Vec<(Vec<Option<IsoHit>>, IsoStats)> = rays
                    .par_chunks(256)
                    .map(|tile| {
                        let mut st = IsoStats::default();
                        let mut out = vec![IsoOutcome::Miss { tets_visited: 0 }; tile.len()];
                        w.trace_tile(&vp, tile, &q, &mut out, &mut st);
                        (out.iter().map(|o| o.hit().copied()).collect(), st)
                    })
                    .collect();
                merge(parts)
            });
            assert_eq!(thits, hits, "interleaved walks differ from single walks");
            report(&format!("walk {} interleaved", l.name()), ms, &thits, &st);
            let same_tet = hits
                .iter()
                .zip(&reference)
                .filter(|(a, b)| a.map(|h| h.tet) == b.map(|h| h.tet))
                .count();
            println!(
                "|   (walk {}: {failed} failed; same hit tet as the IBVH on {same_tet} of {} rays) | | | | | | |",
                l.name(),
                rays.len()
            );
        }
    });
}

fn merge(parts: Vec<(Vec<Option<IsoHit>>, IsoStats)>) -> (Vec<Option<IsoHit>>, IsoStats) {
    let mut st = IsoStats::default();
    let mut h = Vec::new();
    for (p, s) in parts {
        h.extend(p);
        st.add(&s);
    }
    (h, st)
}
