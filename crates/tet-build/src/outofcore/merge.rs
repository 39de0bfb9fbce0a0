//! What becomes of finished parts ([`Merge`]): kept and merged in memory
//! ([`InMemory`]: exact point deduplication and [`tet_core::TetMesh::assemble`])
//! or streamed through part files ([`super::stream::ToFile`]); the
//! replacement of the paper's `MERGE` (Erkoç et al. 2021, §3.3).

use std::collections::HashMap;

use glam::Vec3;
use tet_core::{TetMesh, face_key};

use super::error::SeamError;
use super::part_cache::PartCache;
use super::parts::{PartFacets, PartMesh, PartStats, SeamOptions, SeamReport, run_parts};
use super::plane::{SplitPlane, key};

/// The parts of a split, ready for TetGen.
pub(super) struct PartInputs<'a> {
    /// Each part's PLC facets, made when the part is taken up.
    pub(super) parts: Box<dyn PartFacets + 'a>,
    /// Input scene triangle of each cleaned one.
    pub(super) triangle_source: std::borrow::Cow<'a, [u32]>,
    /// Input scene triangles.
    pub(super) triangle_count: u32,
}

/// What a [`Merge`] needs besides the parts.
pub(super) struct MergeContext<'a> {
    /// Input scene triangle of each cleaned one.
    pub(super) triangle_source: &'a [u32],
    /// Input scene triangles.
    pub(super) triangle_count: u32,
    /// The seams (plane and rectangle), as in [`SeamReport::seams`].
    pub(super) seams: &'a [(SplitPlane, Vec3, Vec3)],
}

impl MergeContext<'_> {
    /// A part's constrained faces with the *input* scene triangle ids.
    pub(super) fn scene_ids(&self, constrained: &[([u32; 3], u32)]) -> Vec<([u32; 3], u32)> {
        constrained
            .iter()
            .map(|&(t, s)| (t, self.triangle_source[s as usize]))
            .collect()
    }
}

/// What becomes of the parts once TetGen has run: [`InMemory`] keeps them
/// and merges them into one [`TetMesh`]; [`super::stream::ToFile`] writes
/// each to a part file and streams them into the mesh file.
pub(super) trait Merge: Sync {
    /// What is kept of a finished part until the merge.
    type Part: Send;
    /// The merged result.
    type Output;
    /// Called on the worker thread as soon as part `k`'s TetGen run returns.
    fn part(&self, k: usize, mesh: PartMesh, ctx: &MergeContext) -> Result<Self::Part, SeamError>;
    /// The report fields of a finished part.
    fn stats(part: &Self::Part) -> PartStats;
    /// Merges the parts (in part order).
    fn merge(&self, parts: Vec<Self::Part>, ctx: &MergeContext) -> Result<Self::Output, SeamError>;
}

/// Runs TetGen on every part ([`run_parts`]), hands each finished part to
/// `merge`, fills the per-part fields of `report` and merges. With a
/// `cache`, parts whose PLC it kept from an earlier attempt are not run
/// again, and on failure the finished parts are kept there.
pub(super) fn finish_parts<M: Merge>(
    inputs: PartInputs<'_>,
    mut report: SeamReport,
    options: &SeamOptions,
    merge: &M,
    cache: Option<&PartCache<M::Part>>,
) -> Result<(M::Output, SeamReport), SeamError> {
    let ctx = MergeContext {
        triangle_source: &inputs.triangle_source,
        triangle_count: inputs.triangle_count,
        seams: &report.seams,
    };
    let finish = |k, mesh| merge.part(k, mesh, &ctx);
    let parts = run_parts(inputs.parts.as_ref(), options, &finish, cache)?;
    report.parts_reused = cache.map_or(0, PartCache::reused);
    let stats: Vec<PartStats> = parts.iter().map(M::stats).collect();
    let output = merge.merge(parts, &ctx)?;
    for s in &stats {
        record_part(&mut report, s);
    }
    Ok((output, report))
}

/// The in-memory merge: parts kept as they come from TetGen, merged by
/// [`merge_parts`].
pub(super) struct InMemory;

impl Merge for InMemory {
    type Part = PartMesh;
    type Output = TetMesh;

    fn part(&self, _: usize, mesh: PartMesh, _: &MergeContext) -> Result<PartMesh, SeamError> {
        Ok(mesh)
    }

    fn stats(part: &PartMesh) -> PartStats {
        part.stats
    }

    fn merge(&self, parts: Vec<PartMesh>, ctx: &MergeContext) -> Result<TetMesh, SeamError> {
        merge_parts(&parts, ctx)
    }
}

/// Records a part's stats in the per-part fields of `report`.
pub(super) fn record_part(report: &mut SeamReport, s: &PartStats) {
    report.part_points.push(s.input_points);
    report.part_triangles.push(s.input_triangles);
    report.part_wall_points.push(s.wall_points);
    report.part_wall_triangles.push(s.wall_triangles);
    report.part_tets.push(s.tets);
    report.part_peak_kib.push(s.peak_kib);
    report.part_split_pieces.push(s.split_pieces);
    report.part_surface.push(s.surface);
    report
        .part_predicted_bytes
        .push(super::memory_model::predict_part_peak_memory(
            s.input_points - s.wall_points,
            s.input_triangles - s.wall_triangles,
            s.wall_points,
            s.wall_triangles,
        ));
}

/// Merges tetrahedralized parts in memory: points deduplicated by their
/// exact f32 bits, tets concatenated, constrained faces listed once each (a
/// face on a seam carrying an in-plane scene triangle comes from both
/// sides) with the *input* scene triangle id, then [`TetMesh::assemble`]
/// and [`TetMesh::validate`].
pub(super) fn merge_parts(meshes: &[PartMesh], ctx: &MergeContext) -> Result<TetMesh, SeamError> {
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut points = Vec::new();
    let mut tets = Vec::new();
    let mut tris: Vec<([u32; 3], u32)> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for m in meshes {
        let map: Vec<u32> = m
            .points
            .iter()
            .map(|&p| {
                *index.entry(key(p)).or_insert_with(|| {
                    points.push(p);
                    points.len() as u32 - 1
                })
            })
            .collect();
        tets.extend(m.tets.iter().map(|t| t.map(|v| map[v as usize])));
        for (t, s) in ctx.scene_ids(&m.constrained) {
            let g = t.map(|v| map[v as usize]);
            if seen.insert(face_key(g)) {
                tris.push((g, s));
            }
        }
    }
    let mesh = TetMesh::assemble(points, tets, &tris, ctx.triangle_count)?;
    mesh.validate()?;
    Ok(mesh)
}
