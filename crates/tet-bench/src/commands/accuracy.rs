//! `tet-bench accuracy`: every method against an f64 reference, on the
//! scene as given and, with `--extremes`, scaled, translated and on slivers.

use anyhow::{Result, bail};
use serde::Serialize;

use crate::accuracy::{CaseAccuracy, RayPlan, all_cases};
use crate::cli::AccuracyArgs;
use crate::load::{load, require_tets};
use crate::methods::cpu_methods;
use crate::methods::method::Method;
use crate::output::{outln, print_json};

/// The `accuracy` document.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyDoc {
    /// Scene name.
    pub scene: String,
    /// Random seed.
    pub seed: u64,
    /// Side of the square camera image traced.
    pub image: u32,
    /// Random interior rays per case.
    pub random_rays: usize,
    /// Cases.
    pub cases: Vec<CaseAccuracy>,
}

/// Parses `--methods`.
pub fn parse_methods(s: &str) -> Result<Vec<Method>> {
    use clap::ValueEnum;
    if s == "all" {
        return Ok(cpu_methods());
    }
    s.split(',')
        .map(|m| {
            Method::from_str(m.trim(), true).map_err(|_| {
                anyhow::anyhow!("unknown method `{m}` (expected sctp, tet80, tet80-consistent, tet32, tet20, tet16, obvhs, embree, embree8, embree16, brute, exact or all)")
            })
        })
        .collect()
}

/// `tet-bench accuracy`.
pub fn run(args: &AccuracyArgs, json: bool) -> Result<()> {
    let methods = parse_methods(&args.methods)?;
    if methods.is_empty() {
        bail!("no methods given");
    }
    let mut loaded = load(&args.scene, &args.build, json)?;
    loaded.set_view(&args.view)?;
    require_tets(&loaded)?;
    let cases = all_cases(
        &loaded,
        &methods,
        args.precision,
        RayPlan {
            side: args.image,
            random: args.rays,
            seed: args.seed,
            min_time_s: args.min_time,
            adversarial: if args.adversarial { args.rays } else { 0 },
        },
        args.extremes.then_some(&args.build),
        json,
    )?;
    let doc = AccuracyDoc {
        scene: loaded.name.clone(),
        seed: args.seed,
        image: args.image,
        random_rays: args.rays,
        cases,
    };
    if json {
        print_json(&doc)?;
    } else {
        print_doc(&doc)?;
    }
    Ok(())
}

/// Prints the accuracy tables.
pub fn print_doc(doc: &AccuracyDoc) -> Result<()> {
    outln!(
        "{}: {}² camera rays + {} random interior rays per case, seed {}",
        doc.scene,
        doc.image,
        doc.random_rays,
        doc.seed
    )?;
    for c in &doc.cases {
        if let Some(why) = &c.skipped {
            outln!("\n[{}] skipped: {why}", c.case)?;
            continue;
        }
        outln!(
            "\n[{}] {} tets, tolerance {:.3e}, {} rays ({} grazing by the reference)",
            c.case,
            c.tets,
            c.tolerance,
            c.rays,
            c.reference_ambiguous
        )?;
        outln!(
            "  {:<18} {:>9} {:>9} {:>7} {:>7} {:>7} {:>7} {:>6} {:>6} {:>5} {:>9} {:>9}",
            "method",
            "agree",
            "grazing",
            "leaks",
            "wrong",
            "f.miss",
            "f.hit",
            "cap",
            "lost",
            "nan",
            "fail/1024²",
            "Mrays/s"
        )?;
        for m in &c.methods {
            outln!(
                "  {:<18} {:>9} {:>9} {:>7} {:>7} {:>7} {:>7} {:>6} {:>6} {:>5} {:>9.2} {:>9.2}",
                m.method,
                m.agree,
                m.ambiguous,
                m.leaks,
                m.wrong_triangle,
                m.false_misses,
                m.false_hits,
                m.step_cap,
                m.lost,
                m.nans,
                m.failures_per_1024_squared,
                m.mrays_per_s
            )?;
        }
        if !c.left_out.is_empty() {
            outln!(
                "  left out (f32 products out of range at this scale): {}",
                c.left_out.join(", ")
            )?;
        }
    }
    Ok(())
}
