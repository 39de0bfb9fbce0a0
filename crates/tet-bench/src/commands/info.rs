//! `tet-bench info`: counts, regions and exact bytes per layout of a
//! scene or mesh file.

use anyhow::Result;

use super::text::print_build;
use crate::cli::InfoArgs;
use crate::load::load;
use crate::methods::layouts::{LayoutBytes, info};
use crate::output::{outln, print_json};

/// Bytes as MB (10⁶ bytes).
fn mb(b: usize) -> f64 {
    b as f64 / 1e6
}

/// `tet-bench info`.
pub fn run(args: &InfoArgs, json: bool) -> Result<()> {
    let loaded = load(&args.scene, &args.build, json)?;
    let info = info(&loaded, args.prune)?;
    if json {
        print_json(&info)?;
        return Ok(());
    }
    outln!("{}", info.name)?;
    outln!(
        "  triangles {}  points {}  tets {}  constrained faces {}  components {}",
        info.triangles,
        info.points,
        info.tets,
        info.constrained_faces,
        info.components
    )?;
    outln!(
        "  regions {} (largest {} tets, smallest {}, {} single-tet)",
        info.regions.count,
        info.regions.largest,
        info.regions.smallest,
        info.regions.singletons
    )?;
    if let Some(b) = &info.build {
        print_build(b)?;
    }
    print_layouts(&info.layouts)?;
    if let Some(p) = &info.pruned {
        outln!(
            "  pruned to the camera's and lights' regions: removed {} of {} regions, {} tets, {} points, {} constrained faces",
            p.regions_removed,
            p.regions_kept + p.regions_removed,
            p.tets_removed,
            p.points_removed,
            p.constrained_removed
        )?;
        print_layouts(&p.layouts)?;
    }
    Ok(())
}

/// The bytes-per-layout table.
fn print_layouts(layouts: &[LayoutBytes]) -> Result<()> {
    outln!(
        "  {:<11} {:>10} {:>10} {:>10} {:>10}",
        "layout",
        "hot MB",
        "cold MB",
        "total MB",
        "B/tet hot"
    )?;
    for l in layouts {
        outln!(
            "  {:<11} {:>10.3} {:>10.3} {:>10.3} {:>10.1}",
            l.name,
            mb(l.hot_bytes),
            mb(l.cold_bytes),
            mb(l.total_bytes),
            l.hot_bytes_per_tet
        )?;
    }
    Ok(())
}
