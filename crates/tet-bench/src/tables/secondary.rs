//! Secondary rays (the Tray Racing benchmark's workload, with shadows):
//! per primary hit one ambient-occlusion ray and one shadow ray per point
//! light (`render --rays mixed`), each kind's speed for the tet walks and
//! the BVHs in the same run, alternating rounds.

use std::fmt::Write as _;

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::TablesDoc;
use crate::load::Loaded;
use crate::methods::method::Method;
use crate::timing::{Frames, RenderDoc, time_method};

/// Rounds of every method in turn; a method's row is its round with the
/// fastest frame.
const ROUNDS: usize = 2;

/// The methods of the table: the two compact walks, obvhs, and Embree's
/// single rays and packets where built with it.
fn methods() -> Vec<Method> {
    let mut m = vec![Method::Tet20, Method::Tet16, Method::Obvhs];
    m.extend(crate::methods::embree_methods());
    m
}

/// One row per method: primary, AO and shadow rays of `loaded`'s camera
/// and lights.
pub fn measure(
    spec: &str,
    loaded: &Loaded,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<Vec<RenderDoc>> {
    let mixed = RenderOptions {
        shadows: true,
        ambient_occlusion: true,
        ..opts.clone()
    };
    let mut best: Vec<Option<RenderDoc>> = vec![None; methods().len()];
    for _ in 0..ROUNDS {
        for (slot, m) in best.iter_mut().zip(methods()) {
            eprintln!("  {spec}: secondary rays with {}", m.name());
            let doc = time_method(loaded, m, &mixed, frames, pool)?.0;
            if slot.as_ref().is_none_or(|b| doc.best_ms < b.best_ms) {
                *slot = Some(doc);
            }
        }
    }
    Ok(best.into_iter().flatten().collect())
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    if doc.scenes.iter().all(|sc| sc.secondary.is_empty()) {
        return;
    }
    let _ = writeln!(m, "\n## Secondary rays: ambient occlusion and shadows\n");
    let _ = writeln!(
        m,
        "Per primary hit one ambient-occlusion ray (cosine-distributed, a tenth of the scene's diagonal long) and one shadow ray per point light in front of the surface (`render --rays mixed`); the tet walks start them in the hit's tet, the BVHs from the root. Mrays/s of each kind: its rays over the time the workers spent tracing them; ratio: tet20 ÷ the method. Methods timed in {ROUNDS} alternating rounds, the round with the fastest frame.\n"
    );
    let _ = writeln!(
        m,
        "| scene | method | primary Mrays/s | AO Mrays/s | shadow Mrays/s | AO tets/ray | frame ms | tet20 ÷ method (primary / AO / shadow) |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|---|");
    for sc in &doc.scenes {
        let Some(t20) = sc.secondary.iter().find(|r| r.method == Method::Tet20) else {
            continue;
        };
        for r in &sc.secondary {
            let k = &r.by_kind;
            let ratio = |a: f64, b: f64| {
                if b > 0.0 {
                    format!("{:.2}", a / b)
                } else {
                    "–".into()
                }
            };
            let t = &t20.by_kind;
            let _ = writeln!(
                m,
                "| {} | {} | {:.2} | {:.2} | {:.2} | {} | {:.1} | {} / {} / {} |",
                r.scene,
                r.tracer,
                k.primary.mrays_per_s,
                k.ao.mrays_per_s,
                k.shadow.mrays_per_s,
                k.ao.tets_per_ray
                    .map_or("–".to_string(), |v| format!("{v:.1}")),
                r.best_ms,
                ratio(t.primary.mrays_per_s, k.primary.mrays_per_s),
                ratio(t.ao.mrays_per_s, k.ao.mrays_per_s),
                ratio(t.shadow.mrays_per_s, k.shadow.mrays_per_s),
            );
        }
    }
}
