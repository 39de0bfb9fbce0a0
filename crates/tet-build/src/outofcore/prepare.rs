//! The whole scene before it is split: cleaned, and (unless
//! [`SeamOptions::resolve`] is off) with its self-intersections resolved,
//! exactly as the in-core build prepares it. Resolving before the split
//! matters: a crossing that a cut plane separates into two parts would
//! otherwise reach each part's TetGen run as half a crossing.

use std::borrow::Cow;

use super::error::SeamError;
use super::parts::SeamOptions;
use crate::clean::clean_scene;
use crate::pipeline::resolve_cleaned;
use crate::resolve::ResolveReport;
use crate::scene::Scene;

/// The scene the parts are cut from.
pub(super) struct Prepared<'a> {
    /// Cleaned (and resolved) scene: the input itself when cleaning and
    /// resolving changed nothing (the common case for generated scenes),
    /// so that a planner holds one copy of the scene, not two.
    pub scene: Cow<'a, Scene>,
    /// Input scene triangle of each cleaned one (pieces name their input
    /// triangle); the rest of the cleaning's map, a second copy of the
    /// scene, is not kept.
    pub triangle_source: Cow<'a, [u32]>,
    /// What the resolution did (`None` when off).
    pub resolve: Option<ResolveReport>,
}

impl Prepared<'_> {
    /// The same preparation, borrowed: what a retry of a build cuts its
    /// parts from, instead of cleaning the scene and checking it for
    /// self-intersections again (at 30 M triangles, minutes each time).
    pub fn again(&self) -> Prepared<'_> {
        Prepared {
            scene: Cow::Borrowed(&*self.scene),
            triangle_source: Cow::Borrowed(&*self.triangle_source),
            resolve: self.resolve.clone(),
        }
    }
}

/// Cleans `scene` and resolves its self-intersections when
/// `options.resolve` asks; [`SeamError::EmptyScene`] when nothing is left.
pub(super) fn prepare<'a>(
    scene: &'a Scene,
    options: &SeamOptions,
) -> Result<Prepared<'a>, SeamError> {
    let (cleaned, mut map) = clean_scene(scene)?;
    // Of the map, the resolution reads the triangles' sources only: the
    // vertex maps go now, before the self-intersection check.
    map.vertex_map = Vec::new();
    if cleaned.triangles.is_empty() {
        return Err(SeamError::EmptyScene);
    }
    let (prepared, triangle_source, resolve) = match &options.resolve {
        Some(o) => {
            let (scene, map, report) = resolve_cleaned(cleaned, map, o)?;
            (scene, map.triangle_source, Some(report))
        }
        None => (cleaned, map.triangle_source, None),
    };
    let unchanged = prepared.vertices == scene.vertices && prepared.triangles == scene.triangles;
    Ok(Prepared {
        scene: if unchanged {
            Cow::Borrowed(scene)
        } else {
            Cow::Owned(prepared)
        },
        triangle_source: Cow::Owned(triangle_source),
        resolve,
    })
}
