//! The paper's recursive split with exact seams: perpendicular planes
//! (Erkoç et al. 2021, Algorithm 1 `TETRA`/`CLIP`/`MERGE`, §3.2–3.3).
//!
//! A [`CutTree`] splits the enclosing box recursively; every leaf box is one
//! TetGen run (`-pY`). Where seams meet, both sides must see the same
//! triangles, so the whole cut is built as one conforming complex before
//! any part runs:
//!
//! 1. **Clipping in tree order.** Every scene triangle is a convex polygon
//!    whose edges each lie on a *root* segment: a scene edge, or the cut
//!    segment of a polygon by a plane. The crossing of an edge with a plane
//!    is always computed from its root's endpoints
//!    ([`super::seam::crossing_point`], f64, rounded once to f32, exact on
//!    the plane), so the two sides of a seam, and the neighbours sharing a
//!    scene edge, compute bit-identical points whatever the clip order. Each
//!    crossing point is *registered* on its root with its exact parameter
//!    `t` along the root. Scene triangles lying in a plane are part of that
//!    plane's seam and are also clipped further down both sides (only to
//!    register their edges' crossings).
//! 2. **Walls.** Every split node's plane section of its box (a *seam*) and
//!    the six faces of the enclosing box are *walls*. A wall's constraints
//!    are: its boundary, the *traces* of all other seams whose rectangle has
//!    an edge on the wall (the deeper planes on either side), the cut
//!    segments and in-plane scene edges and vertices. Traces and boundaries
//!    lie on axis-parallel lines where two coordinates are exact plane
//!    values, so the points on them are found *exactly* (every point with
//!    those two coordinates); traces crossing each other get their exact
//!    crossing point. Every other segment is subdivided at the points
//!    registered on its root between its endpoints (ordered by `t`). One
//!    planar CDT (`spade`) per wall.
//! 3. **Parts.** A leaf's PLC is its scene pieces (outlines subdivided as
//!    above, triangulated by ear clipping in the triangle's dominant
//!    projection) plus, for each of its six faces, the triangles of the wall
//!    it lies on that lie inside the face. Adjacent leaves therefore receive
//!    the very same triangles on shared faces, and subdivide shared edges
//!    identically; TetGen `-pY` keeps every facet (checked), and the merge
//!    is exact: in memory (dedup + `assemble`, [`build_tree`]) or streamed
//!    through part files ([`build_tree_to_file`], [`super::stream`]).
//!
//! | paper (Erkoç et al. 2021)                       | code                              |
//! |----------------------------------------|-----------------------------------|
//! | recursion of `TETRA`                   | [`CutTree`], [`build_tree`]       |
//! | `CLIP` (clip triangles by the plane)   | tree-order clipping (item 1)      |
//! | repair of overlapping vertices/edges   | none: shared roots and walls      |
//! | `MERGE` by centroid hashing            | exact dedup + `TetMesh::assemble` |

use tet_core::TetMesh;

use self::clear::ClearPositions;
use self::clip::{Cut, run_clipping};
use self::leaf_parts::{LeafWalls, TreeWhole, leaf_faces, piece_facets};
use self::walls::{prepare_walls, triangulate_wall};
use super::error::SeamError;
use super::merge::{InMemory, Merge, PartInputs, finish_parts};
use super::part_cache::PartCache;
use super::parts::{SeamOptions, SeamReport};
use super::plane::{NEAR_PLANE, SplitPlane, key};
use super::prepare::{Prepared, prepare};
use super::split::SplitTree;
use super::split_parts::{PartTriangles, SplitParts};
use super::stream::{StreamOptions, StreamSummary, ToFile};
use crate::bbox::EnclosingBox;
use crate::clean::clean_scene;
use crate::scene::Scene;

pub use cut_tree::CutTree;

mod clear;
mod clip;
mod cut_tree;
mod geometry;
mod leaf_parts;
mod walls;

/// Builds the mesh of `scene` in its enclosing box split by `tree` (see
/// the module docs): every leaf is one TetGen run (concurrently with
/// `options.parallel_parts`), merged exactly. The result passes
/// [`TetMesh::validate`]; constrained faces carry the *input* scene
/// triangle ids. The report's seam fields list the split nodes' seams in
/// depth-first order (below before above); part fields list the leaves in
/// the same order.
pub fn build_tree(
    scene: &Scene,
    tree: &CutTree,
    options: &SeamOptions,
) -> Result<(TetMesh, SeamReport), SeamError> {
    build_tree_with(scene, tree, options, &InMemory)
}

/// [`build_tree`] with the parts written to part files as they finish and
/// streamed into the mesh file `stream.output` ([`super::stream`]): the
/// caller never holds the whole mesh. The parts follow each other in the
/// file in leaf order (depth first, below before above), each
/// Hilbert-sorted on its own with `stream.sort_parts`.
pub fn build_tree_to_file(
    scene: &Scene,
    tree: &CutTree,
    options: &SeamOptions,
    stream: &StreamOptions,
) -> Result<(StreamSummary, SeamReport), SeamError> {
    build_tree_with(scene, tree, options, &ToFile::new(stream)?)
}

/// [`build_tree`] with the parts finished and merged by `merge`.
fn build_tree_with<M: Merge>(
    scene: &Scene,
    tree: &CutTree,
    options: &SeamOptions,
    merge: &M,
) -> Result<(M::Output, SeamReport), SeamError> {
    let (inputs, report) = tree_part_inputs(scene, tree, options)?;
    finish_parts(inputs, report, options, merge, None)
}

/// Every leaf's PLC of `scene` split by `tree` (see the module docs), in
/// leaf order, and the report's seam fields; no TetGen run.
pub(in crate::outofcore) fn tree_part_inputs<'a>(
    scene: &'a Scene,
    tree: &CutTree,
    options: &SeamOptions,
) -> Result<(PartInputs<'a>, SeamReport), SeamError> {
    tree_part_inputs_of(scene, prepare(scene, options)?, tree, options)
}

/// [`tree_part_inputs`] prepared once: `prepared` is filled on the first
/// call and read on the next, so that an attempt after a moved plane does
/// not clean the scene and check it for self-intersections again (at 30 M
/// triangles, minutes each time). Filled on the first call, not before,
/// because a planner holds its own cleaned copy until its cut tree is made.
pub(in crate::outofcore) fn tree_part_inputs_once<'a, 's: 'a>(
    scene: &'s Scene,
    prepared: &'a std::cell::OnceCell<Prepared<'s>>,
    tree: &CutTree,
    options: &SeamOptions,
) -> Result<(PartInputs<'a>, SeamReport), SeamError> {
    let p = match prepared.get() {
        Some(p) => p,
        None => {
            let p = prepare(scene, options)?;
            prepared.get_or_init(|| p)
        }
    };
    tree_part_inputs_of(scene, p.again(), tree, options)
}

/// [`tree_part_inputs`] of `scene` prepared as `prepared`.
fn tree_part_inputs_of<'a>(
    scene: &Scene,
    prepared: Prepared<'a>,
    tree: &CutTree,
    options: &SeamOptions,
) -> Result<(PartInputs<'a>, SeamReport), SeamError> {
    let Prepared {
        scene: cleaned,
        triangle_source,
        resolve,
    } = prepared;
    let b = EnclosingBox::new(cleaned.bounds(), options.enclosing_box)?;
    let mut cut = run_clipping(&cleaned.vertices, &cleaned.triangles, tree, b.min, b.max)?;
    prepare_walls(&mut cut, b.min, b.max);
    let mut report = SeamReport {
        resolve,
        triangles_cut: cut.triangles_cut.len(),
        triangles_in_plane: cut.triangles_in_plane.len(),
        ..SeamReport::default()
    };
    let triangulated: Vec<Result<_, SeamError>> = {
        let (walls, reg, lines) = (&cut.walls, &cut.registry, &cut.lines);
        use rayon::prelude::*;
        walls
            .par_iter()
            .map(|w| triangulate_wall(w, reg, lines))
            .collect()
    };
    for (w, t) in cut.walls.iter_mut().zip(triangulated) {
        w.triangles = t?;
        if w.seam {
            let mut vs: Vec<[u32; 3]> = w.triangles.iter().flat_map(|(t, _)| t.map(key)).collect();
            vs.sort_unstable();
            vs.dedup();
            report.seam_vertices.push(vs.len());
            report.seams.push((w.plane, w.lo, w.hi));
            report.seam_triangles.push(w.triangles.len());
        }
    }
    // Leaves in depth-first order (below first).
    let mut leaves = Vec::new();
    let mut stack = vec![0usize];
    while let Some(id) = stack.pop() {
        match cut.nodes[id].split {
            None => leaves.push(id),
            Some((_, _, below, above)) => {
                stack.push(above);
                stack.push(below);
            }
        }
    }
    let mut clipped = Vec::with_capacity(leaves.len());
    let mut walls = Vec::with_capacity(leaves.len());
    // Parts with a piece rounding left untriangulable (seen at 100 M
    // triangles): their walls move, as for a part TetGen fails on, so that
    // the planes cut the triangle elsewhere; all of them in one retry.
    let mut untriangulable = Vec::new();
    for (k, &id) in leaves.iter().enumerate() {
        // Each leaf's pieces are dropped as their facets are made, so the
        // two are not held whole at once.
        let polys = std::mem::take(&mut cut.pieces[id]);
        let mut pieces = Vec::with_capacity(polys.len());
        for poly in &polys {
            match piece_facets(poly, &cleaned, &cut.registry, &cut.lines) {
                Ok(facets) => pieces.push((poly.source, facets)),
                Err(e @ SeamError::PieceTriangulation { .. }) => {
                    untriangulable.push(SeamError::PartPiece {
                        part: k,
                        source: Box::new(e),
                    });
                    break;
                }
                Err(e) => return Err(e),
            }
        }
        clipped.push(pieces);
        walls.push(leaf_faces(&cut, id));
    }
    if let Some(e) = SeamError::parts_failed(untriangulable) {
        return Err(e);
    }
    let mut part_of_node = vec![None; cut.nodes.len()];
    for (k, &id) in leaves.iter().enumerate() {
        part_of_node[id] = Some(k);
    }
    let inside = PartTriangles::new(
        leaves.len(),
        |t| part_of_node.get(cut.leaf_of[t] as usize).copied().flatten(),
        cut.leaf_of.len(),
    );
    let Cut {
        registry,
        lines,
        walls: cut_walls,
        ..
    } = cut;
    let walls = LeafWalls::new(cut_walls.into_iter().map(|w| w.triangles).collect(), walls);
    let parts = SplitParts {
        whole: TreeWhole {
            scene: cleaned,
            registry,
            lines,
        },
        inside,
        clipped,
        box_faces: vec![Vec::new(); leaves.len()],
        walls,
    };
    let inputs = PartInputs {
        parts: Box::new(parts),
        triangle_source,
        triangle_count: scene.triangles.len() as u32,
    };
    Ok((inputs, report))
}

/// The plan [`build_tree_with_memory_limit`] built.
#[derive(Clone, Debug, PartialEq)]
pub struct TreePlan {
    /// The planner's tree (estimates per leaf, triangles cut per node),
    /// with the planes as planned; its leaves' triangle lists are dropped
    /// once the cut tree is made.
    pub plan: SplitTree,
    /// The planes as built (after any moves).
    pub cuts: CutTree,
    /// How many plane moves the build needed.
    pub plane_moves: usize,
    /// Each failure of TetGen on a part that a retry moved the part's
    /// walls for, in the order met (its message: the part and why).
    pub part_failures: Vec<String>,
    /// Parts built with the surface relaxed
    /// ([`SeamOptions::surface_relaxed_parts`]) after their walls moved
    /// [`MAX_PART_MOVES`] times and TetGen still failed on them.
    pub surface_relaxed_parts: Vec<usize>,
}

/// How many times [`build_tree_with_memory_limit`] moves planes that met
/// a degenerate configuration before giving up: each time, every plane
/// one clipping pass found near a point (at 100 M triangles, more than one
/// per pass).
pub const MAX_PLANE_MOVES: usize = 8;

/// How many times [`build_tree_with_memory_limit`] moves the walls of one
/// part TetGen failed or crashed on or ran past its time limit on before
/// it relaxes the part's surface (one last attempt, with `-Y/2`, else
/// without `-Y`: [`SeamOptions::surface_relaxed_parts`]) and then gives up.
pub const MAX_PART_MOVES: usize = 2;

/// How many attempts after the first [`build_tree_with_memory_limit`]
/// makes for parts TetGen failed on (each attempt moves the walls of
/// every part that failed in the one before, and runs TetGen on the parts
/// whose input changed) before giving up.
pub const MAX_PART_RETRIES: usize = 6;

/// The paper's `TETRA` under a memory limit: plans the recursive split of
/// `scene` ([`super::split::plan_split`], planes avoiding vertices within
/// TetGen's tolerance) so that every leaf's *predicted* TetGen peak fits
/// `split.limit_bytes`, then builds it ([`build_tree`]). A plane that
/// meets a degenerate configuration only the build can see (a point made
/// by an earlier cut within tolerance of it, [`SeamError::PlaneNearPoint`]
/// or [`SeamError::DegenerateCut`]) is moved, within half a step (1/4096
/// of the box's extent), to the value farthest from that point and the
/// scene's vertices in its box (module `clear`), and the build retried, at
/// most [`MAX_PLANE_MOVES`] times (each retry moves every plane the
/// clipping found near a point: [`SeamError::PlanesNearPoints`]); the walls of a part TetGen fails on or
/// runs past its time limit on are moved by about a step (likewise to
/// the clearest value within half a step of it), at most
/// [`MAX_PART_MOVES`] times per part and in at most [`MAX_PART_RETRIES`]
/// attempts; a part TetGen still fails on then has its surface relaxed
/// ([`SeamOptions::surface_relaxed_parts`]: `-Y/2`, else without `-Y`) for one
/// last attempt. An attempt goes on past such a part, so that one retry
/// moves the walls of every part that failed; it gives each part's TetGen
/// run a time limit scaled to the part's size (10 s and 2 ms per point
/// and triangle, under the worker's own limit), so that a stuck part
/// costs ten to thirty times what a part of its size takes, not the
/// limit of the largest. A retry runs TetGen only on the parts whose
/// input the moves changed: the others are kept from the attempt before
/// (see `part_cache`).
pub fn build_tree_with_memory_limit(
    scene: &Scene,
    split: &super::split::SplitOptions,
    options: &SeamOptions,
) -> Result<(TetMesh, SeamReport, TreePlan), SeamError> {
    build_tree_with_memory_limit_with(scene, split, options, &InMemory)
}

/// [`build_tree_with_memory_limit`] streaming the parts into the mesh file
/// `stream.output` ([`build_tree_to_file`]).
pub fn build_tree_with_memory_limit_to_file(
    scene: &Scene,
    split: &super::split::SplitOptions,
    options: &SeamOptions,
    stream: &StreamOptions,
) -> Result<(StreamSummary, SeamReport, TreePlan), SeamError> {
    build_tree_with_memory_limit_with(scene, split, options, &ToFile::new(stream)?)
}

/// [`build_tree_with_memory_limit`] with the parts merged by `merge`.
fn build_tree_with_memory_limit_with<M: Merge>(
    scene: &Scene,
    split: &super::split::SplitOptions,
    options: &SeamOptions,
    merge: &M,
) -> Result<(M::Output, SeamReport, TreePlan), SeamError> {
    let cache = PartCache::default();
    let prepared = std::cell::OnceCell::new();
    let ((output, report), plan) = plan_tree_with_moves(scene, split, options, |tree, relaxed| {
        let (inputs, report) = tree_part_inputs_once(scene, &prepared, tree, options)?;
        let options = SeamOptions {
            surface_relaxed_parts: relaxed.to_vec(),
            ..options.clone()
        };
        finish_parts(inputs, report, &options, merge, Some(&cache))
    })?;
    Ok((output, report, plan))
}

/// Plans the recursive split of `scene` under `split.limit_bytes` and
/// calls `build` on its cut tree and the parts to build with their
/// surface relaxed (in increasing order); a plane meeting a degenerate
/// configuration ([`SeamError::PlaneNearPoint`],
/// [`SeamError::DegenerateCut`]) is moved and `build` called again, and
/// so are a failed part's walls (see [`build_tree_with_memory_limit`]).
pub(in crate::outofcore) fn plan_tree_with_moves<T>(
    scene: &Scene,
    split: &super::split::SplitOptions,
    options: &SeamOptions,
    mut build: impl FnMut(&CutTree, &[usize]) -> Result<T, SeamError>,
) -> Result<(T, TreePlan), SeamError> {
    let (cleaned, _) = clean_scene(scene)?;
    if cleaned.triangles.is_empty() {
        return Err(SeamError::EmptyScene);
    }
    let b = EnclosingBox::new(cleaned.bounds(), options.enclosing_box)?;
    let (vertices, triangles) = (&cleaned.vertices, &cleaned.triangles);
    let plan = if split.best_effort {
        Some(super::split::plan_split(
            vertices,
            triangles,
            (b.min, b.max),
            split,
        ))
    } else {
        super::split::plan_split_within(vertices, triangles, (b.min, b.max), split)
    };
    let Some(mut plan) = plan else {
        return Err(SeamError::LimitTooSmall {
            limit_bytes: split.limit_bytes,
        });
    };
    let mut tree = CutTree::from_split_tree(&plan);
    plan.forget_triangles();
    drop(cleaned);
    // Planes moved off points, the attempts that moved them (at most
    // `MAX_PLANE_MOVES`), attempts after parts failed.
    let (mut plane_moves, mut plane_retries, mut retries) = (0, 0, 0);
    let mut part_failures = Vec::new();
    // Wall moves per part (by leaf index, which moves do not change).
    let mut part_moves = std::collections::HashMap::<usize, usize>::new();
    // Parts whose walls moved `MAX_PART_MOVES` times and still failed.
    let mut relaxed: Vec<usize> = Vec::new();
    let tolerance = NEAR_PLANE * (b.max - b.min).max_element() as f64;
    let mut clear = ClearPositions::new(&scene.vertices, tolerance);
    // A part's walls move by about this much (to the clearest value within
    // half of it; see `clear`).
    let step = (b.max - b.min).max_element() as f64 / 4096.0;
    loop {
        match build(&tree, &relaxed) {
            Ok(output) => {
                return Ok((
                    output,
                    TreePlan {
                        plan,
                        cuts: tree,
                        // One move per part failure besides.
                        plane_moves: plane_moves + part_moves.values().sum::<usize>(),
                        part_failures,
                        surface_relaxed_parts: relaxed,
                    },
                ));
            }
            // Every plane the clipping found near a point moves to the
            // value farthest from the points and every scene vertex in its
            // box, within half a step (each plane once).
            Err(e) if !e.planes_near_points().is_empty() => {
                let found = e.planes_near_points();
                if plane_retries >= MAX_PLANE_MOVES {
                    return Err(e);
                }
                for &(_, point) in &found {
                    clear.avoid(point);
                }
                // Where no gap is wide enough in the whole box (only the
                // pieces crossing the node are checked), the fixed step.
                let mut to = |p: SplitPlane, lo, hi| {
                    let v = clear.value(p, lo, hi, p.value as f64, step / 2.0);
                    v.or(Some((p.value as f64 + step) as f32))
                };
                let mut moved: Vec<SplitPlane> = Vec::new();
                for &(plane, _) in &found {
                    if !moved.contains(&plane) && tree.move_plane(plane, b.min, b.max, &mut to) {
                        moved.push(plane);
                    }
                }
                if moved.is_empty() {
                    return Err(e);
                }
                plane_retries += 1;
                plane_moves += moved.len();
            }
            // TetGen stuck or failing on parts: their walls met the
            // scene in a configuration TetGen's boundary recovery (`-Y`
            // adds no point on the walls) cannot take; seen on a city of
            // fan-triangulated streets, where a wall crossing a fan near
            // its apex leaves a row of crossings 0.002 apart and TetGen
            // ran until killed. Move those parts' walls (each plane once)
            // and build again. Likewise where a part's Steiner points
            // flatten tets when rounded to f32 (seen on Neptune), and
            // where TetGen crashes on a part (a segmentation fault in its
            // worker, seen in the 5,043 parts of 30 M triangles).
            Err(e) if !e.parts_to_retry().is_empty() => {
                let gave_up = |why: String, last: SeamError| SeamError::GaveUp {
                    why,
                    last: Box::new(last),
                };
                let failed = e.parts_to_retry();
                if retries >= MAX_PART_RETRIES {
                    return Err(gave_up(format!("{MAX_PART_RETRIES} retries"), e));
                }
                // Every failed part's walls, taken before any moves; a part
                // whose walls moved `MAX_PART_MOVES` times is built once
                // more where it stands, with its surface relaxed.
                let mut walls = Vec::with_capacity(failed.len());
                for &part in &failed {
                    if relaxed.contains(&part) {
                        let why =
                            format!("part {part} failed after {MAX_PART_MOVES} moves and relaxed");
                        return Err(gave_up(why, e));
                    }
                    let n = part_moves.entry(part).or_default();
                    if *n == MAX_PART_MOVES {
                        relaxed.push(part);
                        continue;
                    }
                    *n += 1;
                    walls.push((part, tree.leaf_walls(part).unwrap_or_default()));
                }
                // Each plane once: up by a step, else down (a thin
                // neighbour's planes may stand within a step), else a
                // quarter step either way.
                let mut moved: Vec<SplitPlane> = Vec::new();
                let mut stuck = Vec::new();
                for (part, planes) in walls {
                    let mut any = false;
                    for plane in planes {
                        if moved.contains(&plane) {
                            any = true;
                            continue;
                        }
                        for offset in [step, -step, step / 4.0, -step / 4.0] {
                            let mut to = |p: SplitPlane, lo, hi| {
                                let want = p.value as f64 + offset;
                                clear
                                    .value(p, lo, hi, want, offset.abs() / 2.0)
                                    .or(Some(want as f32))
                            };
                            if tree.move_plane(plane, b.min, b.max, &mut to) {
                                moved.push(plane);
                                any = true;
                                break;
                            }
                        }
                    }
                    if !any {
                        stuck.push(part);
                    }
                }
                // A part no wall of which can move is relaxed at once.
                relaxed.extend(stuck);
                relaxed.sort_unstable();
                retries += 1;
                match e {
                    SeamError::PartsFailed(all) => {
                        part_failures.extend(all.iter().map(ToString::to_string));
                    }
                    e => part_failures.push(e.to_string()),
                }
            }
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::geometry::triangulate_outline;
    use super::*;
    use glam::Vec3;

    /// A part with a clipped piece rounding left untriangulable has its
    /// walls moved and the build tried again, like a part TetGen fails on.
    #[test]
    fn an_untriangulable_piece_moves_its_parts_walls() {
        let scene = crate::outofcore::memory_model::knot_grid(1, 60, 8);
        let split = super::super::split::SplitOptions {
            limit_bytes: u64::MAX,
            min_depth: 2,
            ..Default::default()
        };
        let mut calls: Vec<CutTree> = Vec::new();
        let (_, plan) = plan_tree_with_moves(&scene, &split, &SeamOptions::default(), |tree, _| {
            calls.push(tree.clone());
            if calls.len() > 1 {
                return Ok(());
            }
            Err(SeamError::PartPiece {
                part: 1,
                source: Box::new(SeamError::PieceTriangulation {
                    triangle: 7,
                    vertices: 4,
                }),
            })
        })
        .unwrap();
        assert_eq!(calls.len(), 2, "one retry");
        assert_eq!(plan.part_failures.len(), 1, "{:?}", plan.part_failures);
        let before = calls[0].leaf_walls(1).unwrap();
        let after = calls[1].leaf_walls(1).unwrap();
        assert!(before.iter().zip(&after).any(|(b, a)| b.value != a.value));
    }

    /// A part TetGen fails on wherever its walls stand has them moved
    /// `MAX_PART_MOVES` times, is then built once more where they stand
    /// with its surface relaxed, and, failing that too, ends the build
    /// with the reason; a part that builds relaxed is reported so.
    #[test]
    fn a_part_failing_wherever_its_walls_stand_is_relaxed_then_given_up() {
        let scene = crate::outofcore::memory_model::knot_grid(1, 60, 8);
        let split = super::super::split::SplitOptions {
            limit_bytes: u64::MAX,
            min_depth: 2,
            ..Default::default()
        };
        let stuck = || SeamError::Tetgen {
            part: 1,
            source: crate::tetgen::TetgenError::Timeout { seconds: 10.0 },
        };
        for relaxed_builds in [true, false] {
            let mut calls: Vec<(CutTree, Vec<usize>)> = Vec::new();
            let r = plan_tree_with_moves(&scene, &split, &SeamOptions::default(), |tree, r| {
                calls.push((tree.clone(), r.to_vec()));
                if r.contains(&1) && relaxed_builds {
                    return Ok(());
                }
                Err(stuck())
            });
            let walls: Vec<_> = calls
                .iter()
                .map(|(t, _)| t.leaf_walls(1).unwrap())
                .collect();
            let relaxed: Vec<_> = calls.iter().map(|(_, r)| r.clone()).collect();
            assert_eq!(calls.len(), MAX_PART_MOVES + 2, "{relaxed:?}");
            // Moved each time but the last, which keeps the walls.
            for w in walls.windows(2).take(MAX_PART_MOVES) {
                assert_ne!(w[0], w[1]);
            }
            assert_eq!(walls[MAX_PART_MOVES], walls[MAX_PART_MOVES + 1]);
            assert!(relaxed[..=MAX_PART_MOVES].iter().all(Vec::is_empty));
            assert_eq!(relaxed[MAX_PART_MOVES + 1], vec![1]);
            match r {
                Ok((_, plan)) => {
                    assert!(relaxed_builds);
                    assert_eq!(plan.surface_relaxed_parts, vec![1]);
                    assert_eq!(plan.part_failures.len(), MAX_PART_MOVES + 1);
                }
                Err(e) => {
                    assert!(!relaxed_builds);
                    assert!(e.to_string().contains("and relaxed"), "{e}");
                }
            }
        }
    }

    /// One retry moves every plane a clipping pass found near a point (the
    /// build here reports every wall of the part with the most at once),
    /// and counts each.
    #[test]
    fn one_retry_moves_every_plane_found_near_a_point() {
        let scene = crate::outofcore::memory_model::knot_grid(1, 60, 8);
        let split = super::super::split::SplitOptions {
            limit_bytes: u64::MAX,
            min_depth: 3,
            ..Default::default()
        };
        let mut calls: Vec<CutTree> = Vec::new();
        let mut part = 0;
        let (_, plan) = plan_tree_with_moves(&scene, &split, &SeamOptions::default(), |tree, _| {
            calls.push(tree.clone());
            if calls.len() > 1 {
                return Ok(());
            }
            part = (0..tree.parts())
                .max_by_key(|&k| tree.leaf_walls(k).unwrap().len())
                .unwrap();
            let near = tree
                .leaf_walls(part)
                .unwrap()
                .into_iter()
                .map(|plane| SeamError::PlaneNearPoint {
                    plane,
                    point: Vec3::splat(plane.value),
                    distance: 1e-9,
                })
                .collect();
            Err(SeamError::PlanesNearPoints(near))
        })
        .unwrap();
        assert_eq!(calls.len(), 2, "one retry");
        let before = calls[0].leaf_walls(part).unwrap();
        let after = calls[1].leaf_walls(part).unwrap();
        assert!(before.len() >= 2, "{before:?}");
        assert_eq!(plan.plane_moves, before.len());
        for (b, a) in before.iter().zip(&after) {
            assert_eq!(b.axis, a.axis);
            assert_ne!(b.value, a.value, "{b:?} did not move");
        }
    }

    /// A piece nearly parallel to a wall (z = 0) whose chain A–D–C on the
    /// wall is not exactly straight: the ear at B would leave the sliver
    /// (A, C, D) lying in the wall, overlapping the wall's triangles.
    #[test]
    fn ear_clipping_leaves_no_sliver_in_a_wall() {
        let a = Vec3::new(0.0, 0.0, 0.0);
        let b = Vec3::new(0.9, -1.0, -0.01);
        let c = Vec3::new(2.0, 1.0, 0.0);
        let d = Vec3::new(1.0, 0.500_001, 0.0);
        let outline = [b, c, d, a];
        let normal = (c - a).as_dvec3().cross((b - a).as_dvec3()) * -1.0;
        assert!(normal.z > 0.0);
        let tris = triangulate_outline(&outline, normal, 0).unwrap();
        assert_eq!(tris.len(), 2);
        for t in &tris {
            assert!(!t.iter().all(|p| p.z == 0.0), "{t:?} lies in the wall");
        }
        // The triangles tile the outline (projected areas add up).
        let area = |p: &[Vec3]| {
            let n = p.len();
            (0..n)
                .map(|i| {
                    let (u, v) = (p[i].as_dvec3(), p[(i + 1) % n].as_dvec3());
                    u.x * v.y - v.x * u.y
                })
                .sum::<f64>()
                / 2.0
        };
        let sum: f64 = tris.iter().map(|t| area(t)).sum();
        assert!(
            (sum - area(&outline)).abs() < 1e-12,
            "{sum} vs {}",
            area(&outline)
        );
    }
}
