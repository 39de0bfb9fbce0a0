//! Exact seams: parallel cut planes, every slab tetrahedralized separately,
//! and a merge by exact vertex triples (replaces the paper's
//! `CLIP`/`MERGE` with its vertex/edge repairs and centroid hashing,
//! Erkoç et al. 2021, §3.2–3.3).
//!
//! 1. **Cut** ([`clip_polygon`], [`cut_triangle`]): a scene triangle
//!    (or the part of it left above the previous planes) crossing the plane
//!    `x[axis] = value` is clipped into a polygon per side (source winding
//!    kept) and fanned into triangles. The crossing point of an edge is
//!    computed in f64 from the edge's endpoints in a canonical order (so the
//!    two triangles sharing the edge compute the same bits), rounded once to
//!    f32, and its `axis` coordinate set to `value` exactly — it lies on the
//!    plane, and both halves use bit-identical coordinates. Vertices exactly
//!    on the plane are used as they are (no new point).
//! 2. **Seam** ([`seam_triangulation`]): one planar constrained Delaunay
//!    triangulation (`spade`) of the section of the box by the plane, with
//!    every cut segment, every scene edge lying in the plane and every
//!    scene vertex on the plane as constraints. Its triangles lying inside a
//!    scene triangle that lies in the plane carry that triangle; the others
//!    are seam-only faces.
//! 3. **Slabs**: each slab's PLC is its pieces + all triangles of the
//!    seams bounding it + the other faces of its slab box; every facet has its own marker, and
//!    TetGen with `-pY` keeps every seam facet as exactly one face
//!    (checked), so both slabs next to a seam have the very same seam
//!    faces; a scene piece it returns split inside the slab keeps its
//!    faces ([`super::facet_faces`]).
//! 4. **Merge**: points are deduplicated by their exact f32 bits, tets are
//!    concatenated, and [`TetMesh::assemble`] pairs the two slabs' seam
//!    faces by vertex triple (a seam face carrying an in-plane scene
//!    triangle comes from both slabs and is listed once). Seam-only faces become ordinary interior
//!    faces; pieces of a cut scene triangle are constrained faces carrying
//!    the source triangle id (a scene triangle may then be several faces).
//!    [`build_slabs_to_file`] streams the parts through part files instead
//!    ([`super::stream`]), with the same result.
//!
//! TetGen's Steiner points (never on a wall, with `-Y`) are rounded to
//! f32; tets flattened by that rounding are repaired as in the in-core
//! pipeline (snapping, then TetGen re-runs with the rounded points as
//! input), and what remains is [`SeamError::RoundingFlattens`].

use glam::Vec3;
use tet_core::TetMesh;

use super::merge::{InMemory, Merge, PartInputs, finish_parts};
use super::parts::FacetKind;
use super::plane::{SplitPlane, fan};
use super::prepare::{Prepared, prepare};
use super::split_parts::{PartTriangles, SplitParts, WholeTriangle};
use super::stream::{StreamOptions, StreamSummary, ToFile};
use crate::bbox::EnclosingBox;
use crate::clean::clean_scene;
use crate::procedural::BOX_TRIANGLES;
use crate::scene::Scene;

pub use super::error::SeamError;
pub use super::parts::{RELAXED_COPLANAR_TOLERANCE, SeamOptions, SeamReport, SurfaceMode};
pub use super::plane::{
    NEAR_PLANE, Piece, clip_polygon, crossing_point, cut_triangle, near_plane_vertex,
};
pub use super::section::{Seam, seam_triangulation};

/// Builds the mesh of `scene` in its enclosing box as two halves cut by
/// `plane` with an exact seam, merged ([`build_slabs`] with one plane).
pub fn build_split_once(
    scene: &Scene,
    plane: SplitPlane,
    options: &SeamOptions,
) -> Result<(TetMesh, SeamReport), SeamError> {
    build_slabs(scene, plane.axis, &[plane.value], options)
}

/// Builds the mesh of `scene` in its enclosing box as `values.len() + 1`
/// slabs cut by the parallel planes `x[axis] = values[i]` (strictly
/// increasing, strictly inside the box), each tetrahedralized separately,
/// with exact seams, merged (see the module docs). Parallel planes keep
/// every seam a plain rectangle whose boundary lies on the enclosing box,
/// so no seam meets another. The result passes [`TetMesh::validate`];
/// constrained faces carry the *input* scene triangle ids.
pub fn build_slabs(
    scene: &Scene,
    axis: usize,
    values: &[f32],
    options: &SeamOptions,
) -> Result<(TetMesh, SeamReport), SeamError> {
    build_slabs_with(scene, axis, values, options, &InMemory)
}

/// [`build_slabs`] with the parts written to part files as they finish
/// and streamed into the mesh file `stream.output`
/// ([`super::stream`]): the caller never holds the whole mesh.
pub fn build_slabs_to_file(
    scene: &Scene,
    axis: usize,
    values: &[f32],
    options: &SeamOptions,
    stream: &StreamOptions,
) -> Result<(StreamSummary, SeamReport), SeamError> {
    build_slabs_with(scene, axis, values, options, &ToFile::new(stream)?)
}

/// [`build_slabs`] with the parts finished and merged by `merge`.
fn build_slabs_with<M: Merge>(
    scene: &Scene,
    axis: usize,
    values: &[f32],
    options: &SeamOptions,
    merge: &M,
) -> Result<(M::Output, SeamReport), SeamError> {
    let (inputs, report) = slab_part_inputs(scene, axis, values, options)?;
    finish_parts(inputs, report, options, merge, None)
}

/// Every slab's PLC of `scene` cut by the planes `x[axis] = values[i]`
/// (see [`build_slabs`]), in slab order, and the report's seam fields; no
/// TetGen run.
pub(super) fn slab_part_inputs<'a>(
    scene: &'a Scene,
    axis: usize,
    values: &[f32],
    options: &SeamOptions,
) -> Result<(PartInputs<'a>, SeamReport), SeamError> {
    let Prepared {
        scene: cleaned,
        triangle_source,
        resolve,
    } = prepare(scene, options)?;
    let b = EnclosingBox::new(cleaned.bounds(), options.enclosing_box)?;
    let a = axis;
    let planes: Vec<SplitPlane> = values
        .iter()
        .map(|&value| SplitPlane { axis, value })
        .collect();
    for (j, &plane) in planes.iter().enumerate() {
        let after_previous = j == 0 || plane.value > planes[j - 1].value;
        if axis > 2 || !(plane.value > b.min[a] && plane.value < b.max[a]) || !after_previous {
            return Err(SeamError::PlaneOutsideBox {
                plane,
                min: b.min,
                max: b.max,
            });
        }
        let tolerance = NEAR_PLANE * (b.max - b.min).max_element() as f64;
        if let Some(v) = near_plane_vertex(&cleaned.vertices, plane, tolerance) {
            let point = cleaned.vertices[v as usize];
            return Err(SeamError::PlaneNearVertex {
                plane,
                vertex: v,
                point,
                distance: (point[a] as f64 - plane.value as f64).abs(),
            });
        }
    }
    let n = planes.len();
    let mut report = SeamReport {
        resolve,
        ..SeamReport::default()
    };
    // Triangles inside one slab are listed, not copied: their facets are
    // made when their slab is taken up.
    let mut slab_of = vec![u32::MAX; cleaned.triangles.len()];
    let mut clipped: Vec<Vec<(u32, Vec<[Vec3; 3]>)>> = vec![Vec::new(); n + 1];
    let mut walls: Vec<Vec<([Vec3; 3], FacetKind)>> = vec![Vec::new(); n + 1];
    let mut segments: Vec<Vec<[Vec3; 2]>> = vec![Vec::new(); n];
    let mut seam_points: Vec<Vec<Vec3>> = vec![Vec::new(); n];
    let mut in_plane: Vec<Vec<([Vec3; 3], u32)>> = vec![Vec::new(); n];
    for (i, t) in cleaned.triangles.iter().enumerate() {
        let s = i as u32;
        let mut poly: Vec<Vec3> = t.map(|v| cleaned.vertices[v as usize]).to_vec();
        let mut slab = n;
        let mut cut = false;
        for (j, &plane) in planes.iter().enumerate() {
            let below = poly.iter().any(|p| p[a] < plane.value);
            let above = poly.iter().any(|p| p[a] > plane.value);
            let on: Vec<Vec3> = poly
                .iter()
                .copied()
                .filter(|p| p[a] == plane.value)
                .collect();
            if !below && !above {
                // The original triangle lies in this plane.
                in_plane[j].push((t.map(|v| cleaned.vertices[v as usize]), s));
                slab = usize::MAX;
                break;
            }
            if below && above {
                cut = true;
                let (lo, hi, seg) = clip_polygon(&poly, plane);
                clipped[j].push((s, fan(&lo)));
                segments[j].push(seg);
                poly = hi;
                continue;
            }
            match on.len() {
                1 => seam_points[j].push(on[0]),
                2 => segments[j].push([on[0], on[1]]),
                _ => {}
            }
            if below {
                slab = j;
                break;
            }
        }
        report.triangles_cut += usize::from(cut);
        if slab == usize::MAX {
            report.triangles_in_plane += 1;
        } else if cut {
            clipped[slab].push((s, fan(&poly)));
        } else {
            slab_of[i] = slab as u32;
        }
    }
    let corners_of = |lo: Vec3, hi: Vec3| -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 != 0 { hi.x } else { lo.x },
                if i & 2 != 0 { hi.y } else { lo.y },
                if i & 4 != 0 { hi.z } else { lo.z },
            )
        })
    };
    // Seams: one planar CDT per plane, given to both adjacent slabs.
    for (j, &plane) in planes.iter().enumerate() {
        let section: Vec<Vec3> = corners_of(b.min, b.max)
            .iter()
            .filter(|p| p[a] == b.min[a])
            .map(|&p| {
                let mut p = p;
                p[a] = plane.value;
                p
            })
            .collect();
        let section: [Vec3; 4] = section.try_into().expect("a box has 4 corners per face");
        let seam = seam_triangulation(plane, section, &segments[j], &seam_points[j], &in_plane[j])?;
        report.seam_vertices.push(seam.vertices);
        {
            let (mut lo, mut hi) = (b.min, b.max);
            lo[a] = plane.value;
            hi[a] = plane.value;
            report.seams.push((plane, lo, hi));
        }
        report.seam_triangles.push(seam.triangles.len());
        for (t, src) in seam.triangles.iter().zip(&seam.source) {
            let k = src.map_or(FacetKind::Seam, FacetKind::Scene);
            walls[j].push((*t, k));
            walls[j + 1].push((*t, k));
        }
    }
    // Box faces of each slab: BOX_TRIANGLES pairs are z-min, z-max, y-min,
    // y-max, x-min, x-max; a slab skips its faces on cut planes.
    let min_face = [8, 4, 0][a];
    let max_face = [10, 6, 2][a];
    let slab_faces = |k: usize| -> Vec<[Vec3; 3]> {
        let (mut lo, mut hi) = (b.min, b.max);
        if k > 0 {
            lo[a] = planes[k - 1].value;
        }
        if k < n {
            hi[a] = planes[k].value;
        }
        let corners = corners_of(lo, hi);
        BOX_TRIANGLES
            .iter()
            .enumerate()
            .filter(|(i, _)| {
                let face = i - i % 2;
                let on_cut = (k > 0 && face == min_face) || (k < n && face == max_face);
                !on_cut
            })
            .map(|(_, t)| t.map(|v| corners[v as usize]))
            .collect()
    };
    let box_faces: Vec<Vec<[Vec3; 3]>> = (0..=n).map(slab_faces).collect();
    let inside = PartTriangles::new(
        n + 1,
        |t| (slab_of[t] != u32::MAX).then_some(slab_of[t] as usize),
        slab_of.len(),
    );
    drop(slab_of);
    let parts = SplitParts {
        whole: SlabWhole { scene: cleaned },
        inside,
        clipped,
        walls,
        box_faces,
    };
    let inputs = PartInputs {
        parts: Box::new(parts),
        triangle_source,
        triangle_count: scene.triangles.len() as u32,
    };
    Ok((inputs, report))
}

/// A triangle inside one slab: itself (fanned as a cut piece would be).
struct SlabWhole<'a> {
    /// The cleaned (and resolved) scene.
    scene: std::borrow::Cow<'a, Scene>,
}

impl WholeTriangle for SlabWhole<'_> {
    fn facets(&self, t: u32) -> Result<Vec<[Vec3; 3]>, SeamError> {
        let v = self.scene.triangles[t as usize].map(|i| self.scene.vertices[i as usize]);
        Ok(fan(&v))
    }
}

/// Builds `scene` so that every TetGen run's *predicted* peak fits
/// `options.limit_bytes` ([`super::split::plan_slabs`], then
/// [`build_slabs`]); returns the plan with the mesh and report.
pub fn build_with_memory_limit(
    scene: &Scene,
    split: &super::split::SplitOptions,
    options: &SeamOptions,
) -> Result<(TetMesh, SeamReport, super::split::SlabPlan), SeamError> {
    let (cleaned, _) = clean_scene(scene)?;
    if cleaned.triangles.is_empty() {
        return Err(SeamError::EmptyScene);
    }
    let b = EnclosingBox::new(cleaned.bounds(), options.enclosing_box)?;
    let plan =
        super::split::plan_slabs(&cleaned.vertices, &cleaned.triangles, (b.min, b.max), split)
            .ok_or(SeamError::LimitTooSmall {
                limit_bytes: split.limit_bytes,
            })?;
    let (mesh, report) = build_slabs(scene, plan.axis, &plan.values, options)?;
    Ok((mesh, report, plan))
}
