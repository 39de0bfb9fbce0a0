//! Robustness (Maria et al. 2017, Table 4): rays with a wrong result
//! per 1024² rays per method against the f64 reference, beside each
//! method's render speed.

use std::fmt::Write as _;

use anyhow::Result;

use super::doc::TablesDoc;
use crate::accuracy::scale::run_streamed;
use crate::accuracy::{CaseAccuracy, RayPlan, run_case};
use crate::load::Loaded;
use crate::methods::method::{Method, Precision};

/// Every CPU method (`methods`) in f32 on the scene's camera image and
/// random interior rays (256² + 20,000 with `--quick`, else 1024² +
/// 100,000), each method timed for at least `min_time_s`; or, with
/// `streamed`, that many rays in batches (camera image, random and
/// adversarial rays: [`crate::accuracy::scale`]).
pub fn measure(
    spec: &str,
    loaded: &Loaded,
    methods: &[Method],
    quick: bool,
    min_time_s: f64,
    streamed: Option<u64>,
) -> Result<CaseAccuracy> {
    if let Some(total) = streamed {
        eprintln!("  {spec}: accuracy over {total} rays (camera, random and adversarial)");
        return run_streamed("as-is", loaded, methods, Precision::F32, total, 1, false);
    }
    let (side, rays) = if quick {
        (256, 20_000)
    } else {
        (1024, 100_000)
    };
    eprintln!("  {spec}: accuracy ({side}² camera rays + {rays} random rays)");
    let plan = RayPlan {
        side,
        random: rays,
        seed: 1,
        min_time_s,
        adversarial: 0,
    };
    run_case("as-is", loaded, methods, Precision::F32, plan)
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(
        m,
        "\n## Robustness (Maria et al. 2017, Table 4) and speed vs accuracy\n"
    );
    let _ = writeln!(
        m,
        "Failures = leaks + wrong triangle + false miss + false hit + step cap + lost + NaN, beyond the grazing tolerance, per 1024² rays, against an f64 reference. A leak is a ray that misses, or hits something farther along, where the reference hit grazes only closed edges (shared by two or more faces): it slipped through a watertight surface. Grazing rays (not failures) hit one of the triangles they graze, or graze an open edge. The paper column is Maria et al. (2017) Table 4: rays with a wrong result per 1024² on its GPU, averaged over about 1,300 viewpoints, on Banana / Bunny / Armadillo (its STP is our `sctp`, its own Plücker method our `tet80`; the 2-D walks of Aman et al. (2022) and the consistent Tet80 are not in it). Without `--quick` the first scene and the flat-faced Flat Parts are checked over 10⁸ rays each (`--robustness-rays`): the 1024² camera image, then random interior rays and adversarial rays (aimed at vertices, edges and faces of the tetrahedralization, along edges, started on faces, lying in the planes of faces) in equal parts; its Mrays/s column is the render's, the other scenes' 1024² + 100 k rays likewise.\n"
    );
    let _ = writeln!(
        m,
        "| scene | method | rays | grazing | leaks | wrong | false miss | false hit | cap | lost | failures per 1024² | paper per 1024² | Mrays/s (render) |"
    );
    let _ = writeln!(
        m,
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for sc in &doc.scenes {
        if let Some(a) = &sc.accuracy {
            for x in &a.methods {
                let speed = sc
                    .renders
                    .iter()
                    .find(|r| r.tracer == x.method)
                    .map_or(f64::NAN, |r| r.mrays_per_s);
                let _ = writeln!(
                    m,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {} | {:.2} |",
                    sc.info
                        .as_ref()
                        .map_or(sc.spec.as_str(), |i| i.name.as_str()),
                    x.method,
                    x.rays,
                    x.ambiguous,
                    x.leaks,
                    x.wrong_triangle,
                    x.false_misses,
                    x.false_hits,
                    x.step_cap,
                    x.lost,
                    x.failures_per_1024_squared,
                    paper_table4(&x.method).unwrap_or("–"),
                    speed
                );
            }
        }
    }
}

/// Maria et al. (2017) Table 4 for the method of tracer `name` (Banana / Bunny /
/// Armadillo, rays per 1024²): its STP is Lagae and Dutré's scalar triple
/// products (`sctp`), "Ours" its Plücker walk (`tet80`).
fn paper_table4(name: &str) -> Option<&'static str> {
    match name.split('/').next()? {
        "sctp" => Some("63.07 / 204.89 / 456.65"),
        "tet80" => Some("0 / 0 / 0"),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's figures go to the paper's methods only, whatever the
    /// precision suffix of the tracer's name.
    #[test]
    fn paper_figures_follow_the_method() {
        assert_eq!(paper_table4("tet80/f32"), Some("0 / 0 / 0"));
        assert_eq!(paper_table4("sctp/f32-stp"), paper_table4("sctp"));
        assert_eq!(paper_table4("tet80-consistent/f32"), None);
        assert_eq!(paper_table4("tet20/f32"), None);
    }
}
