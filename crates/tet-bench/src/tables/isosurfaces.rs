//! Isosurfaces of tetrahedral volumes (Wald et al. 2007, Tables 1–4)
//! on the synthetic stand-ins for the paper's data sets (same tet counts;
//! the originals are not public): IBVH build time BIH vs SAH and render
//! speed, 16×16 packets, and the iso walk over our compact layouts beside
//! them, every method on the same rays and camera. `--quick` measures
//! `ell32p` alone at 256²; the full run the four static sets at 1024².
//! Table 3, the model grown by replicating the bucky ball n³ times
//! (`buckycube --replications n`), runs 1 and 2³ balls at 256² in quick
//! mode, 1, 2³ and 4³ (11.3 M tets) at 1024² in full mode.

use std::fmt::Write as _;

use anyhow::Result;

use super::doc::{IsoRow, IsoScaleRow, TablesDoc};
use crate::iso::{
    IsoFrames, IsoMethod, IsoView, IsoVolume, load_iso_volume, load_iso_volume_with, measure,
};

/// The paper's figures per data set: tets (Table 1), BIH and SAH build
/// ms (Table 1, dual Core 2 Duo), laptop fps at 1024² (Table 2, 2 cores),
/// 16×16 ray-box and ray-isopolygon tests per ray (Table 4).
struct Paper {
    /// Data set.
    name: &'static str,
    /// Tets.
    tets: u64,
    /// BIH build, ms.
    bih_ms: f64,
    /// SAH build, ms.
    sah_ms: f64,
    /// Laptop fps (Core Duo 2.33 GHz, 2 cores).
    laptop_fps: f64,
    /// 16×16 packets: ray-box tests per ray.
    box_tests: f64,
    /// 16×16 packets: ray-isopolygon tests per ray.
    isopolygon_tests: f64,
}

/// The paper's four static data sets.
const PAPER: [Paper; 4] = [
    Paper {
        name: "ell32p",
        tets: 148_955,
        bih_ms: 46.0,
        sah_ms: 2432.0,
        laptop_fps: 14.2,
        box_tests: 1.11,
        isopolygon_tests: 3.39,
    },
    Paper {
        name: "feok",
        tets: 121_668,
        bih_ms: 42.0,
        sah_ms: 1854.0,
        laptop_fps: 12.6,
        box_tests: 1.10,
        isopolygon_tests: 3.86,
    },
    Paper {
        name: "bucky",
        tets: 224_874,
        bih_ms: 61.0,
        sah_ms: 2932.0,
        laptop_fps: 13.3,
        box_tests: 1.8,
        isopolygon_tests: 4.42,
    },
    Paper {
        name: "blunt",
        tets: 176_856,
        bih_ms: 87.0,
        sah_ms: 3887.0,
        laptop_fps: 18.9,
        box_tests: 0.94,
        isopolygon_tests: 3.19,
    },
];

/// `methods` on `volume` at its own isovalue, `side`² pixels, from its
/// default view: one `iso` document each.
fn measure_methods(
    volume: &IsoVolume,
    methods: &[IsoMethod],
    side: u32,
    frames: u32,
    pool: &rayon::ThreadPool,
) -> Result<Vec<crate::iso::IsoDoc>> {
    let iso = [volume.default_isovalue];
    let f = IsoFrames {
        width: side,
        height: side,
        frames,
        time_step: 0,
        view: IsoView::of(&volume.mesh),
        regions: true,
    };
    methods
        .iter()
        .map(|&m| measure(volume, &iso, m, f, pool).map(|x| x.0))
        .collect()
}

/// Every method on the stand-ins (`quick`: ell32p at 256²).
pub fn measure_all(quick: bool, pool: &rayon::ThreadPool) -> Vec<IsoRow> {
    let (names, side, frames): (&[&str], u32, u32) = if quick {
        (&["ell32p"], 256, 2)
    } else {
        (&["ell32p", "feok", "bucky", "blunt"], 1024, 3)
    };
    let mut rows = Vec::new();
    for name in names {
        eprintln!("isosurfaces: {name}, {side}², every method");
        let row = (|| -> Result<IsoRow> {
            let volume = load_iso_volume(name)?;
            let docs = measure_methods(&volume, &IsoMethod::ALL, side, frames, pool)?;
            Ok(IsoRow {
                volume: name.to_string(),
                docs,
                error: None,
            })
        })();
        rows.push(row.unwrap_or_else(|e| IsoRow {
            volume: name.to_string(),
            docs: Vec::new(),
            error: Some(format!("{e:#}")),
        }));
    }
    rows
}

/// Wald et al. (2007) Table 3: balls, tets and fps at 1024² on four 2.4 GHz
/// Opteron cores, per replication of the bucky ball.
const PAPER_SCALING: [(u32, &str, f64); 5] = [
    (1, "177 k", 34.0),
    (8, "1.4 M", 13.5),
    (64, "11.3 M", 5.0),
    (512, "90.4 M", 1.8),
    (4096, "724 M", 0.66),
];

/// The bucky cube replicated n³ times (Wald et al. 2007, Table 3), with the
/// paper's packets (`ibvh-packets`) and the iso walk (`walk-tet20`).
/// 8³ (90 M tets) and beyond are left out: the volume alone would take
/// several GB and most of a run's time here.
pub fn measure_scaling(quick: bool, pool: &rayon::ThreadPool) -> Vec<IsoScaleRow> {
    let (sizes, side, frames): (&[u32], u32, u32) = if quick {
        (&[1, 2], 256, 2)
    } else {
        (&[1, 2, 4], 1024, 3)
    };
    sizes
        .iter()
        .map(|&n| {
            eprintln!("isosurfaces: buckycube, {}³ balls, {side}²", n);
            let docs = (|| -> Result<Vec<crate::iso::IsoDoc>> {
                let options = tet_build::volume::VolumeOptions {
                    replications: Some(n),
                    ..Default::default()
                };
                let volume = load_iso_volume_with("buckycube", &options)?;
                let methods = [IsoMethod::IbvhPackets, IsoMethod::WalkTet20];
                measure_methods(&volume, &methods, side, frames, pool)
            })();
            let (docs, error) = match docs {
                Ok(d) => (d, None),
                Err(e) => (Vec::new(), Some(format!("{e:#}"))),
            };
            IsoScaleRow {
                replications: n,
                balls: n * n * n,
                docs,
                error,
            }
        })
        .collect()
}

/// Table 3: fps as the model grows.
fn scaling_markdown(m: &mut String, doc: &TablesDoc) {
    if doc.iso_scaling.is_empty() {
        return;
    }
    let _ = writeln!(
        m,
        "\n### Isosurfaces as the model grows (Wald et al. 2007, Table 3)\n\nThe bucky ball replicated n³ times without instancing (`iso buckycube --replications n`), {} threads here; the paper's fps are at 1024² on four 2.4 GHz Opteron cores. Memory is the method's own structure beside the mesh. Last column: pixels whose hit differs from single rays through the BIH-built IBVH (`ibvh`, traced untimed on the same pixels): hit by one and missed by the other / hit at another crossing (another tet or isovalue, or for the packets another t).\n",
        doc.setup.threads
    );
    let _ = writeln!(
        m,
        "| balls | tets (paper) | method | pixels | build ms | fps | Mrays/s | MB | paper fps | hits | pixels ≠ ibvh: hit / crossing |"
    );
    let _ = writeln!(m, "|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for row in &doc.iso_scaling {
        let paper = PAPER_SCALING.iter().find(|p| p.0 == row.balls);
        let (paper_tets, paper_fps) = paper.map_or(("–".to_string(), "–".to_string()), |p| {
            (p.1.to_string(), format!("{}", p.2))
        });
        if let Some(e) = &row.error {
            let _ = writeln!(
                m,
                "| {} | ({paper_tets}) | failed: {e} | | | | | | {paper_fps} | | |",
                row.balls
            );
            continue;
        }
        for d in &row.docs {
            let _ = writeln!(
                m,
                "| {} | {} ({paper_tets}) | {} | {}² | {:.0} | {:.2} | {:.2} | {:.1} | {paper_fps} | {} | {} |",
                row.balls,
                d.tets,
                d.method.name(),
                d.width,
                d.build_ms,
                d.fps,
                d.mrays_per_s,
                d.bytes as f64 / 1e6,
                d.hits,
                differences(d),
            );
        }
    }
}

/// The table cell comparing a method's hits with single IBVH rays on the
/// same pixels: pixels hit by one and missed by the other / pixels hit at
/// another crossing; `ibvh` itself is the yardstick.
fn differences(d: &crate::iso::IsoDoc) -> String {
    if d.method == IsoMethod::Ibvh {
        "(yardstick)".to_string()
    } else {
        format!("{} / {}", d.hit_mismatches, d.crossing_mismatches)
    }
}

/// The tables: 1, 2 and 4, then 3.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    static_markdown(m, doc);
    scaling_markdown(m, doc);
}

/// Tables 1, 2 and 4 on the four static stand-ins.
fn static_markdown(m: &mut String, doc: &TablesDoc) {
    if doc.isosurfaces.is_empty() {
        return;
    }
    let _ = writeln!(
        m,
        "\n## Isosurfaces of tet volumes (Wald et al. 2007, Tables 1, 2, 4)\n"
    );
    let _ = writeln!(
        m,
        "Synthetic stand-ins with the paper's tet counts (`tet_build::volume`; the originals are not public), one isovalue, the same camera and rays for every method; {} threads here, {}² pixels (fps scale with the pixel count: compare with the paper's 1024² at the same size). `ibvh`/`ibvh-sah`: the implicit min-max BVH built BIH-style or by SAH, single rays; `ibvh-packets`: 16×16 packets; `walk-*`: the iso walk over our compact layouts, with a min-max tree over regions of up to 64 tets that culls the rays meeting no straddling region and starts the others there (no BVH over the tets). Paper: build ms on a dual Core 2 Duo (Table 1), fps at 1024² on a 2-core laptop (Table 2), 16×16 tests per ray (Table 4). Last column: every method's hits compared pixel by pixel with single `ibvh` rays (traced untimed on the same pixels): pixels hit by one and missed by the other / pixels both hit at another crossing (another tet or isovalue, or for the IBVH methods, which must give the same bits, another t); the walks may differ on rays grazing a silhouette.\n",
        doc.setup.threads,
        doc.isosurfaces
            .iter()
            .find_map(|r| r.docs.first())
            .map_or(0, |d| d.width)
    );
    let _ = writeln!(
        m,
        "| volume | tets (paper) | method | build ms | paper build ms | fps | Mrays/s | paper laptop fps | MB | box tests/ray | isopolygon tests/ray | paper 16×16 box / isopolygon tests | hits | pixels ≠ ibvh: hit / crossing |"
    );
    let _ = writeln!(
        m,
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for row in &doc.isosurfaces {
        if let Some(e) = &row.error {
            let _ = writeln!(
                m,
                "| {} | | failed: {e} | | | | | | | | | | | |",
                row.volume
            );
            continue;
        }
        let paper = PAPER.iter().find(|p| p.name == row.volume);
        for d in &row.docs {
            let dash = || "–".to_string();
            let build = paper.map_or_else(dash, |p| match d.method {
                IsoMethod::Ibvh | IsoMethod::IbvhPackets => format!("{:.0}", p.bih_ms),
                IsoMethod::IbvhSah => format!("{:.0}", p.sah_ms),
                _ => dash(),
            });
            let tests = paper
                .filter(|_| d.method == IsoMethod::IbvhPackets)
                .map_or_else(dash, |p| {
                    format!("{} / {}", p.box_tests, p.isopolygon_tests)
                });
            let _ = writeln!(
                m,
                "| {} | {} ({}) | {} | {:.1} | {build} | {:.1} | {:.2} | {} | {:.2} | {:.2} | {:.2} | {tests} | {} | {} |",
                row.volume,
                d.tets,
                paper.map_or_else(dash, |p| p.tets.to_string()),
                d.method.name(),
                d.build_ms,
                d.fps,
                d.mrays_per_s,
                paper.map_or_else(dash, |p| format!("{:.1}", p.laptop_fps)),
                d.bytes as f64 / 1e6,
                d.per_ray.box_tests,
                d.per_ray.isopolygon_tests,
                d.hits,
                differences(d),
            );
        }
        let speed = |m: IsoMethod| {
            row.docs
                .iter()
                .find(|d| d.method == m)
                .map(|d| d.mrays_per_s)
        };
        if let (Some(w), Some(b), Some(p)) = (
            speed(IsoMethod::WalkTet20),
            speed(IsoMethod::Ibvh),
            speed(IsoMethod::IbvhPackets),
        ) {
            let _ = writeln!(
                m,
                "| {} | | walk-tet20 ÷ ibvh = {:.2}, ÷ ibvh-packets = {:.2} | | | | | | | | | | | |",
                row.volume,
                w / b,
                w / p
            );
        }
    }
}
