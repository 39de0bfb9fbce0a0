//! Quality near the seams (Erkoç et al. 2021,
//! Table 3 compares tet quality of the merged mesh with TetGen's in-core
//! mesh, and notes it is worse near the cut).
//!
//! A tet *touches a seam* when one of its faces lies in a seam: its three
//! vertices have exactly the seam plane's coordinate and lie inside the
//! seam's rectangle ([`super::seam::SeamReport::seams`],
//! [`super::seam_index::SeamIndex`]). Exact: seam points carry the plane
//! coordinate bit for bit. [`seam_quality`]
//! measures those tets and the rest separately with
//! [`crate::quality`]'s aspect ratio and radius-edge ratio.

use glam::Vec3;
use tet_core::{FACE_VERTICES, TetMesh};

use super::plane::SplitPlane;
use super::seam_index::SeamIndex;
use crate::quality::{QualityReport, Stats, aspect_ratio, radius_edge_ratio};

/// Quality of the tets touching a seam and of the others.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeamQuality {
    /// Tets with a face on a seam (`None` when there are none).
    pub seam: Option<QualityReport>,
    /// All other tets (`None` when there are none).
    pub rest: Option<QualityReport>,
}

/// Which tets of `mesh` have a face in one of `seams` (plane, rectangle
/// lower and upper corner; [`SeamIndex::contains_face`]).
pub fn seam_tets(mesh: &TetMesh, seams: &[(SplitPlane, Vec3, Vec3)]) -> Vec<bool> {
    let index = SeamIndex::new(seams);
    (0..mesh.tets.len())
        .map(|t| {
            let p = mesh.tet_points(t as u32);
            FACE_VERTICES
                .iter()
                .any(|f| index.contains_face(f.map(|i| p[i])))
        })
        .collect()
}

fn report(mesh: &TetMesh, tets: &[usize]) -> Option<QualityReport> {
    let corners = |t: usize| mesh.tet_points(t as u32).map(|v| v.as_dvec3());
    Some(QualityReport {
        tets: tets.len(),
        aspect_ratio: Stats::of(tets.iter().map(|&t| aspect_ratio(corners(t))))?,
        radius_edge: Stats::of(tets.iter().map(|&t| radius_edge_ratio(corners(t))))?,
    })
}

/// Quality of the tets touching a seam vs the rest (see the module docs).
pub fn seam_quality(mesh: &TetMesh, seams: &[(SplitPlane, Vec3, Vec3)]) -> SeamQuality {
    let touch = seam_tets(mesh, seams);
    let (near, rest): (Vec<usize>, Vec<usize>) = (0..mesh.tets.len()).partition(|&t| touch[t]);
    SeamQuality {
        seam: report(mesh, &near),
        rest: report(mesh, &rest),
    }
}
