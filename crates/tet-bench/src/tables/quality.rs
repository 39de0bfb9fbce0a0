//! Build trade: the surface-preserving `-pY` build against the quality
//! bound `-pYq5` of the papers, against a bound on slivers only
//! (`--min-dihedral 2`: TetGen refines tets whose smallest dihedral angle
//! is below 2°, no radius-edge bound), and against that bound capped at
//! 1 % of the scene's vertices with no mesh optimisation (the worst
//! slivers go first, so a few hundred points do most of the work), and
//! the default build, `-pY` in parts with walls between them (`--walls
//! auto`), against `-pY` in one piece (`--walls none`): tets, build time,
//! tets per ray and tet20 speed.

use std::fmt::Write as _;

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::{QualityTrade, TABLE_FLAGS, TablesDoc};
use super::plan::{MeshCache, Planned};
use crate::load::BuildSummary;
use crate::load::build_flags::{BuildFlags, MaxSteiner};
use crate::methods::method::Method;
use crate::timing::{Frames, time_method};

/// The papers' setting: `-q5`, at most 2 M Steiner points.
pub const QUALITY5: BuildFlags = BuildFlags {
    quality: Some(5.0),
    max_steiner: Some(MaxSteiner::Count(2_000_000)),
    ..TABLE_FLAGS
};

/// Slivers only: tets with a dihedral angle below 2° refined, at most 2 M
/// Steiner points.
pub const MIN_DIHEDRAL2: BuildFlags = BuildFlags {
    min_dihedral: Some(2.0),
    max_steiner: Some(MaxSteiner::Count(2_000_000)),
    ..TABLE_FLAGS
};

/// Slivers bounded cheaply: `--min-dihedral 2 --optimize 0/0
/// --max-steiner 1%` (1 % of the scene's vertices).
pub const CAPPED: BuildFlags = BuildFlags {
    optimize: Some(tet_build::tetgen_options::Optimization {
        level: 0,
        scheme: 0,
    }),
    max_steiner: Some(MaxSteiner::Percent(1.0)),
    ..MIN_DIHEDRAL2
};

/// The scene in one TetGen run, `-pY`, no walls.
pub const ONE_PIECE: BuildFlags = BuildFlags {
    walls: Some(crate::load::build_flags::Walls::None),
    ..TABLE_FLAGS
};

/// The scene built with `flags` (`label` names it in the progress line)
/// and tet20 on it.
pub fn measure(
    planned: &Planned,
    cache: &mut MeshCache,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
    flags: &BuildFlags,
    label: &str,
) -> Result<QualityTrade> {
    eprintln!("  {}: {label} build", planned.spec);
    let refined = cache.load(planned, flags, false)?.0;
    Ok(QualityTrade {
        tets: refined.mesh.tets.len(),
        build: refined.build.clone(),
        tet20: time_method(&refined, Method::Tet20, opts, frames, pool)?.0,
    })
}

/// The table (full mode only).
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    if !doc.scenes.iter().any(|sc| sc.quality5.is_some()) {
        return;
    }
    let _ = writeln!(
        m,
        "\n## Build trade: surface-preserving `-pY` in parts with walls between them (the default, `--walls auto`) and in one piece (`--walls none`), slivers bounded (`--min-dihedral 2`, also capped at 1 % of the vertices), quality `-pYq5`\n"
    );
    let _ = writeln!(
        m,
        "tet20 at the render table's size and frames; build s: the whole build (TetGen and our stages), one run.\n"
    );
    let _ = writeln!(
        m,
        "| scene | build | tets | build s | tets/ray | tet20 Mrays/s |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        let (Some(q), Some(i)) = (&sc.quality5, &sc.info) else {
            continue;
        };
        let secs = |b: &Option<BuildSummary>| b.as_ref().map_or(f64::NAN, |b| b.total_s);
        if let Some(base) = sc.renders.iter().find(|r| r.method == Method::Tet20) {
            let _ = writeln!(
                m,
                "| {} | -pY, --walls auto (default) | {} | {:.2} | {:.1} | {:.2} |",
                i.name,
                i.tets,
                secs(&i.build),
                base.tets_per_ray,
                base.mrays_per_s
            );
        }
        for (label, t) in [
            ("-pY, --walls none", sc.one_piece.as_ref()),
            (
                "--min-dihedral 2 --optimize 0/0 --max-steiner 1%",
                sc.min_dihedral2_capped.as_ref(),
            ),
            ("--min-dihedral 2", sc.min_dihedral2.as_ref()),
            ("-q5", Some(q)),
        ] {
            if let Some(t) = t {
                let _ = writeln!(
                    m,
                    "| {} | {label} | {} | {:.2} | {:.1} | {:.2} |",
                    i.name,
                    t.tets,
                    secs(&t.build),
                    t.tet20.tets_per_ray,
                    t.tet20.mrays_per_s
                );
            }
        }
    }
}
