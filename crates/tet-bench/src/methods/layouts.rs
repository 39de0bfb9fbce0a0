//! What a mesh holds: counts, regions and exact bytes per layout, before
//! and after pruning what no ray can reach (the `info` document, also the
//! construction and memory tables of `tables`).

use anyhow::Result;
use serde::Serialize;
use tet_core::TetMesh;
use tet_core::memory::MemoryReport;
use tet_core::regions::{compute_regions, locate_brute, locate_seeds_brute, prune_unreachable};

use super::strips::StripsTracer;
use crate::load::{BuildSummary, Loaded};

/// Bytes of one layout (JSON `layouts[]`).
#[derive(Clone, Debug, Serialize)]
pub struct LayoutBytes {
    /// `baseline32`, `tet32`, `tet20`, `tet16`, `tet80` or, in the `info`
    /// document and the memory table, `ray-strips` (whose bytes are all
    /// hot: geometry, strip hierarchies and the BVH above them).
    pub name: &'static str,
    /// Hot data: tet records + point positions read by the walk.
    pub hot_bytes: usize,
    /// Cold data: constrained-face table, attributes, anchors, reconstruction data.
    pub cold_bytes: usize,
    /// hot + cold.
    pub total_bytes: usize,
    /// Tet records.
    pub tets_bytes: usize,
    /// Point positions.
    pub points_bytes: usize,
    /// Constrained-face table.
    pub constrained_bytes: usize,
    /// Optional attributes (normals, UVs, materials), only when present.
    pub attributes_bytes: usize,
    /// Start-tet anchors (Tet20/Tet16).
    pub anchors_bytes: usize,
    /// Data kept only to decode the layout back (Tet80 vertex ids).
    pub reconstruction_bytes: usize,
    /// Hot bytes per tet.
    pub hot_bytes_per_tet: f64,
    /// Total bytes per scene triangle (the unit Ray-Strips and BVHs are
    /// compared in).
    pub total_bytes_per_triangle: f64,
    /// Ray-Strips only: vertices, strip indices and per-triangle words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geometry_bytes: Option<usize>,
    /// Ray-Strips only: the strip hierarchies.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hierarchy_bytes: Option<usize>,
    /// Ray-Strips only: the BVH over the strips.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub top_level_bytes: Option<usize>,
}

/// Region summary (JSON `regions`).
#[derive(Clone, Debug, Serialize)]
pub struct RegionSummary {
    /// Regions bounded by constrained faces.
    pub count: usize,
    /// Tets in the largest region.
    pub largest: u32,
    /// Tets in the smallest region.
    pub smallest: u32,
    /// Single-tet regions.
    pub singletons: usize,
    /// Up to ten largest sizes.
    pub top_sizes: Vec<u32>,
}

/// Effect of pruning unreachable regions (JSON `pruned`).
#[derive(Clone, Debug, Serialize)]
pub struct PruneSummary {
    /// Regions kept.
    pub regions_kept: usize,
    /// Regions removed.
    pub regions_removed: usize,
    /// Tets removed.
    pub tets_removed: usize,
    /// Points removed.
    pub points_removed: usize,
    /// Constrained faces removed.
    pub constrained_removed: usize,
    /// Bytes per layout after pruning.
    pub layouts: Vec<LayoutBytes>,
}

/// The `info` document.
#[derive(Clone, Debug, Serialize)]
pub struct Info {
    /// Scene or file name.
    pub name: String,
    /// Scene triangles referenced by the mesh.
    pub triangles: u32,
    /// Points.
    pub points: usize,
    /// Tets.
    pub tets: usize,
    /// Constrained faces.
    pub constrained_faces: usize,
    /// Connected components (Tet20/Tet16 anchors).
    pub components: usize,
    /// Regions.
    pub regions: RegionSummary,
    /// Bytes per layout.
    pub layouts: Vec<LayoutBytes>,
    /// Construction report when built here.
    pub build: Option<BuildSummary>,
    /// Pruning report with `--prune`.
    pub pruned: Option<PruneSummary>,
}

/// Bytes per layout of a mesh.
pub fn layout_bytes(mesh: &TetMesh) -> (MemoryReport, Vec<LayoutBytes>) {
    let report = MemoryReport::for_mesh(mesh);
    let tets = mesh.tets.len().max(1) as f64;
    let triangles = mesh.constrained.len().max(1) as f64;
    let layouts = report
        .layouts
        .iter()
        .map(|l| LayoutBytes {
            name: l.name,
            hot_bytes: l.hot(),
            cold_bytes: l.cold(),
            total_bytes: l.total(),
            tets_bytes: l.tets,
            points_bytes: l.points,
            constrained_bytes: l.constrained,
            attributes_bytes: l.attributes,
            anchors_bytes: l.anchors,
            reconstruction_bytes: l.reconstruction,
            hot_bytes_per_tet: l.hot() as f64 / tets,
            total_bytes_per_triangle: l.total() as f64 / triangles,
            geometry_bytes: None,
            hierarchy_bytes: None,
            top_level_bytes: None,
        })
        .collect();
    (report, layouts)
}

/// The bytes of Ray-Strips built over the mesh's constrained faces, as a
/// layout entry (everything hot; no tet records).
pub fn strips_bytes(mesh: &TetMesh) -> Result<LayoutBytes> {
    let b = StripsTracer::new(mesh, false)?.strips().bytes();
    Ok(LayoutBytes {
        name: "ray-strips",
        hot_bytes: b.total,
        cold_bytes: 0,
        total_bytes: b.total,
        tets_bytes: 0,
        points_bytes: 0,
        constrained_bytes: 0,
        attributes_bytes: 0,
        anchors_bytes: 0,
        reconstruction_bytes: 0,
        hot_bytes_per_tet: b.total as f64 / mesh.tets.len().max(1) as f64,
        total_bytes_per_triangle: b.total as f64 / mesh.constrained.len().max(1) as f64,
        geometry_bytes: Some(b.geometry),
        hierarchy_bytes: Some(b.hierarchy),
        top_level_bytes: Some(b.top_level),
    })
}

/// Computes the `info` document of a loaded mesh.
pub fn info(loaded: &Loaded, prune: bool) -> Result<Info> {
    let mesh = &loaded.mesh;
    let (report, mut layouts) = layout_bytes(mesh);
    if !mesh.constrained.is_empty() {
        layouts.push(strips_bytes(mesh)?);
    }
    let r = compute_regions(mesh).report();
    let pruned = if prune {
        let mut copy = mesh.clone();
        let mut points = vec![loaded.camera.position];
        points.extend(loaded.lights.iter().map(|l| l.position));
        // A camera or light outside the mesh (tight enclosing box) sees it
        // through its boundary: every tet on the boundary seeds its region.
        let (inside, outside): (Vec<glam::Vec3>, Vec<glam::Vec3>) = points
            .iter()
            .partition(|p| !p.is_finite() || locate_brute(&copy, **p).is_some());
        let mut seeds = locate_seeds_brute(&copy, &inside)?;
        if !outside.is_empty() {
            seeds.extend(
                (0..copy.tets.len() as u32)
                    .filter(|&t| (0..4).any(|k| copy.is_boundary_face(t, k))),
            );
        }
        let p = prune_unreachable(&mut copy, &seeds)?;
        Some(PruneSummary {
            regions_kept: p.regions_kept,
            regions_removed: p.regions_removed,
            tets_removed: p.tets_removed,
            points_removed: p.points_removed,
            constrained_removed: p.constrained_removed,
            layouts: layout_bytes(&copy).1,
        })
    } else {
        None
    };
    Ok(Info {
        name: loaded.name.clone(),
        triangles: mesh.triangle_count,
        points: mesh.points.len(),
        tets: mesh.tets.len(),
        constrained_faces: mesh.constrained.len(),
        components: report.component_count,
        regions: RegionSummary {
            count: r.count,
            largest: r.largest,
            smallest: r.smallest,
            singletons: r.singletons,
            top_sizes: r.top_sizes,
        },
        layouts,
        build: loaded.build.clone(),
        pruned,
    })
}
