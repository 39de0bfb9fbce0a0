//! Exact seams: parallel cut planes, every slab tetrahedralized separately,
//! and a merge by exact vertex triples (issue 8, item 3; replaces the paper's
//! `CLIP`/`MERGE` with its vertex/edge repairs and centroid hashing, seed
//! 003 §3.2–3.3).
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
//!    TetGen with `-pY` keeps every facet as exactly one face (checked), so
//!    both slabs next to a seam have the very same seam faces.
//! 4. **Merge**: points are deduplicated by their exact f32 bits, tets are
//!    concatenated, and [`TetMesh::assemble`] pairs the two slabs' seam
//!    faces by vertex triple (a seam face carrying an in-plane scene
//!    triangle comes from both slabs and is listed once). Seam-only faces become ordinary interior
//!    faces; pieces of a cut scene triangle are constrained faces carrying
//!    the source triangle id (a scene triangle may then be several faces).
//!    [`build_slabs_to_file`] streams the parts through part files instead
//!    ([`super::stream`]), with the same result.
//!
//! TetGen's Steiner points (interior only, with `-Y`) are rounded to f32;
//! a tet flattened by that rounding is reported as
//! [`SeamError::RoundingFlattens`] (the in-core pipeline's snapping repair
//! is not applied here yet).

use std::collections::HashMap;

use glam::{DVec2, DVec3, Vec3};
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use tet_core::{MeshError, TetMesh, face_key};
use thiserror::Error;

use super::split::SplitPlane;
use super::stream::{StreamOptions, StreamSummary, ToFile};
use crate::bbox::{BoxError, BoxSpec, EnclosingBox};
use crate::clean::{CleanError, clean_scene};
use crate::procedural::BOX_TRIANGLES;
use crate::scene::Scene;
use crate::tetgen::{Isolation, TetgenError, TetgenInput, TetgenOptions, tetrahedralize};

/// A failure of [`build_split_once`] and the other out-of-core builders.
#[derive(Debug, Error)]
pub enum SeamError {
    /// Cleaning rejected the scene.
    #[error("cleaning: {0}")]
    Clean(#[from] CleanError),
    /// The scene has no triangles after cleaning.
    #[error("the scene has no triangles")]
    EmptyScene,
    /// The enclosing box could not be built.
    #[error("enclosing box: {0}")]
    Box(#[from] BoxError),
    /// The plane does not cross the box's interior.
    #[error("plane {plane:?} does not cross the box {min:?}..{max:?}")]
    PlaneOutsideBox {
        /// The plane.
        plane: SplitPlane,
        /// Box lower corner.
        min: Vec3,
        /// Box upper corner.
        max: Vec3,
    },
    /// A scene vertex lies off the plane but closer to it than TetGen's
    /// tolerance (its crossing points would be merged with it by TetGen).
    #[error(
        "scene vertex {vertex} {point:?} is {distance:e} off the plane {plane:?}; move the plane"
    )]
    PlaneNearVertex {
        /// The plane.
        plane: SplitPlane,
        /// Input scene vertex index (after cleaning).
        vertex: u32,
        /// Its position.
        point: Vec3,
        /// Its distance to the plane.
        distance: f64,
    },
    /// A point made by an earlier cut (or a scene vertex) lies off the
    /// plane but closer to it than TetGen's tolerance.
    #[error("point {point:?} is {distance:e} off the plane {plane:?}; move the plane")]
    PlaneNearPoint {
        /// The plane.
        plane: SplitPlane,
        /// The point.
        point: Vec3,
        /// Its distance to the plane.
        distance: f64,
    },
    /// A cut met a nearly degenerate configuration (two planes crossing a
    /// segment at points closer than f32 rounding, or a clipped piece no
    /// longer convex after rounding).
    #[error("degenerate cut by {plane:?} near {point:?} (scene triangle {triangle}): {what}")]
    DegenerateCut {
        /// The plane.
        plane: SplitPlane,
        /// Where.
        point: Vec3,
        /// Cleaned scene triangle involved.
        triangle: u32,
        /// What went wrong.
        what: &'static str,
    },
    /// A clipped piece of a scene triangle could not be triangulated
    /// (rounding made its outline self-intersect).
    #[error("piece of scene triangle {triangle} with {vertices} vertices cannot be triangulated")]
    PieceTriangulation {
        /// Cleaned scene triangle.
        triangle: u32,
        /// Vertices of the piece's outline.
        vertices: usize,
    },
    /// No slab plan fits the memory limit.
    #[error("no slab plan keeps every part under {limit_bytes} bytes")]
    LimitTooSmall {
        /// The limit.
        limit_bytes: u64,
    },
    /// Two seam constraints cross (the scene self-intersects on the plane,
    /// or rounding of crossing points made two segments cross).
    #[error("seam constraint {from:?}–{to:?} crosses another seam constraint")]
    SeamConstraintsCross {
        /// Segment start.
        from: Vec3,
        /// Segment end.
        to: Vec3,
    },
    /// spade refused a seam point.
    #[error("seam triangulation: point {point:?}: {message}")]
    SeamPoint {
        /// The point.
        point: Vec3,
        /// spade's error.
        message: String,
    },
    /// TetGen failed on one part (slab).
    #[error("TetGen on part {part}: {source}")]
    Tetgen {
        /// Part index (0 = lowest slab).
        part: usize,
        /// TetGen's error.
        source: TetgenError,
    },
    /// TetGen found intersecting facets in a part's PLC; the first pair
    /// found by [`crate::intersect::find_self_intersections`] on the PLC.
    #[error("part {part}: facets {first:?} and {second:?} intersect ({kind:?}; {pairs} pairs)")]
    PartSelfIntersects {
        /// Part index.
        part: usize,
        /// One facet (vertices) and what it is (scene triangle or seam).
        first: ([Vec3; 3], Option<u32>),
        /// The other.
        second: ([Vec3; 3], Option<u32>),
        /// How they meet.
        kind: crate::intersect::IntersectionKind,
        /// Intersecting pairs in the part.
        pairs: usize,
    },
    /// A facet of a part did not come back as exactly one face.
    #[error("part {part}: facet {facet} came back as {faces} faces, expected exactly one")]
    FacetNotPreserved {
        /// Part index (0 = lowest slab).
        part: usize,
        /// Facet index in the part's PLC.
        facet: usize,
        /// Faces carrying its marker.
        faces: usize,
    },
    /// TetGen moved or dropped an input point.
    #[error("part {part}: TetGen moved or dropped input point {point}")]
    InputPointChanged {
        /// Part index (0 = lowest slab).
        part: usize,
        /// Point index.
        point: usize,
    },
    /// Rounding Steiner points to f32 flattened or inverted tets.
    #[error("part {part}: {count} tets are flat or inverted after rounding to f32")]
    RoundingFlattens {
        /// Part index (0 = lowest slab).
        part: usize,
        /// How many.
        count: usize,
    },
    /// Assembly or validation of the merged mesh failed.
    #[error("merged mesh: {0}")]
    Mesh(#[from] MeshError),
    /// Writing a part file or streaming the parts into the mesh file failed.
    #[error("streaming merge: {0}")]
    Stream(#[from] super::stream::StreamError),
}

/// What [`build_slabs`] (and [`build_split_once`]) did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeamReport {
    /// Scene triangles (after cleaning) strictly crossing at least one plane.
    pub triangles_cut: usize,
    /// Scene triangles lying in one of the planes.
    pub triangles_in_plane: usize,
    /// Vertices of each seam triangulation (including its 4 section corners).
    pub seam_vertices: Vec<usize>,
    /// Triangles of each seam triangulation.
    pub seam_triangles: Vec<usize>,
    /// Each seam: its plane and its rectangle (lower and upper corner; the
    /// plane's coordinate is the same in both), in the order of
    /// `seam_vertices`. Used by [`super::report::seam_quality`].
    pub seams: Vec<(SplitPlane, Vec3, Vec3)>,
    /// Input points of each part's PLC (part `k` lies between planes `k − 1` and `k`).
    pub part_points: Vec<usize>,
    /// Facets of each part's PLC.
    pub part_triangles: Vec<usize>,
    /// Points of each part's PLC used by no scene facet (wall corners,
    /// trace points): the part of `part_points` the memory model counts
    /// at the wall rate.
    pub part_wall_points: Vec<usize>,
    /// Facets of each part's PLC that are seam-only or box faces.
    pub part_wall_triangles: Vec<usize>,
    /// Tets of each part.
    pub part_tets: Vec<usize>,
    /// Peak memory of each part's worker (KiB), when isolated.
    pub part_peak_kib: Vec<Option<u64>>,
    /// Predicted peak memory of each part's TetGen run from its real input
    /// ([`super::memory_model::predict_part_peak_memory`], bytes, with margin).
    pub part_predicted_bytes: Vec<u64>,
}

/// Options of [`build_slabs`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeamOptions {
    /// Box around the scene (the whole mesh's boundary).
    pub enclosing_box: BoxSpec,
    /// TetGen switches (`-Y` is required and forced on).
    pub tetgen: TetgenOptions,
    /// Where TetGen runs.
    pub isolation: Isolation,
    /// Run the parts concurrently (one thread each, at most this many at a
    /// time; 0 or 1 = one after the other). Only worth it with
    /// [`Isolation::Worker`]: in-process TetGen runs are serialized.
    pub parallel_parts: usize,
}

/// One scene-triangle piece: three vertices in the source winding and the
/// (cleaned) source triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Vertices.
    pub v: [Vec3; 3],
    /// Cleaned scene triangle index.
    pub source: u32,
}

/// Exact bits of a point (−0 folded into +0).
pub(super) fn key(p: Vec3) -> [u32; 3] {
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// The crossing point of edge `p q` with the plane (endpoints strictly on
/// opposite sides), computed from the endpoints in canonical order.
pub fn crossing_point(p: Vec3, q: Vec3, plane: SplitPlane) -> Vec3 {
    let (p, q) = if key(p) <= key(q) { (p, q) } else { (q, p) };
    let (pd, qd) = (p.as_dvec3(), q.as_dvec3());
    let a = plane.axis;
    let t = (plane.value as f64 - pd[a]) / (qd[a] - pd[a]);
    let x = pd + t * (qd - pd);
    let mut r = Vec3::new(x.x as f32, x.y as f32, x.z as f32);
    // Rounding a value between two f32 values stays between them; clamp
    // anyway against t's own rounding.
    r = r.clamp(p.min(q), p.max(q));
    r[a] = plane.value;
    r
}

/// Exact: do three points span a proper triangle?
fn non_degenerate(t: [Vec3; 3]) -> bool {
    let proj = |p: Vec3, i: usize, j: usize| robust::Coord {
        x: p[i] as f64,
        y: p[j] as f64,
    };
    [(0, 1), (1, 2), (2, 0)].iter().any(|&(i, j)| {
        robust::orient2d(proj(t[0], i, j), proj(t[1], i, j), proj(t[2], i, j)) != 0.0
    })
}

/// Fans a convex polygon (3 or 4 vertices, source winding) into proper
/// triangles, trying each start vertex until no piece is degenerate.
fn fan(poly: &[Vec3]) -> Vec<[Vec3; 3]> {
    let n = poly.len();
    for s in 0..n {
        let tris: Vec<[Vec3; 3]> = (1..n - 1)
            .map(|i| [poly[s], poly[(s + i) % n], poly[(s + i + 1) % n]])
            .collect();
        if tris.iter().all(|&t| non_degenerate(t)) {
            return tris;
        }
    }
    // Some piece is degenerate whatever the start (rounding collapsed a
    // sliver): keep the proper ones.
    (1..n - 1)
        .map(|i| [poly[0], poly[i], poly[i + 1]])
        .filter(|&t| non_degenerate(t))
        .collect()
}

/// Clips a convex polygon (source winding) strictly crossing the plane
/// into its part below and its part above (both keep the winding) and the
/// two polygon points on the plane (the seam segment).
pub fn clip_polygon(poly: &[Vec3], plane: SplitPlane) -> (Vec<Vec3>, Vec<Vec3>, [Vec3; 2]) {
    let a = plane.axis;
    let side = |p: Vec3| {
        p[a].partial_cmp(&plane.value)
            .unwrap_or(std::cmp::Ordering::Equal)
    };
    let (mut lo, mut hi, mut on) = (Vec::new(), Vec::new(), Vec::new());
    let n = poly.len();
    for i in 0..n {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        let (sp, sq) = (side(p), side(q));
        if sp.is_le() {
            lo.push(p);
        }
        if sp.is_ge() {
            hi.push(p);
        }
        if sp.is_eq() {
            on.push(p);
        }
        if (sp.is_lt() && sq.is_gt()) || (sp.is_gt() && sq.is_lt()) {
            let x = crossing_point(p, q, plane);
            lo.push(x);
            hi.push(x);
            on.push(x);
        }
    }
    debug_assert_eq!(
        on.len(),
        2,
        "a convex polygon crossing a plane meets it twice"
    );
    (lo, hi, [on[0], on[1]])
}

/// Clips a triangle crossing the plane into (below pieces, above pieces,
/// the seam segment). Source winding is kept in every piece.
pub fn cut_triangle(
    tri: [Vec3; 3],
    plane: SplitPlane,
) -> (Vec<[Vec3; 3]>, Vec<[Vec3; 3]>, [Vec3; 2]) {
    let (lo, hi, seg) = clip_polygon(&tri, plane);
    (fan(&lo), fan(&hi), seg)
}

/// The seam: triangles in the plane, each with the in-plane scene triangle
/// it lies in (cleaned index), if any.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Seam {
    /// Triangles (oriented as their scene triangle where they have one).
    pub triangles: Vec<[Vec3; 3]>,
    /// Scene triangle each lies in.
    pub source: Vec<Option<u32>>,
    /// Number of distinct seam vertices.
    pub vertices: usize,
}

/// Builds the seam triangulation of the rectangle `corners` (on the plane)
/// with `segments` and `points` as constraints and the in-plane scene
/// triangles `in_plane` (vertices, cleaned index) as constraint edges and
/// face labels.
pub fn seam_triangulation(
    plane: SplitPlane,
    corners: [Vec3; 4],
    segments: &[[Vec3; 2]],
    points: &[Vec3],
    in_plane: &[([Vec3; 3], u32)],
) -> Result<Seam, SeamError> {
    let (u, v) = ((plane.axis + 1) % 3, (plane.axis + 2) % 3);
    let to2 = |p: Vec3| Point2::new(p[u] as f64, p[v] as f64);
    let to3 = |p: Point2<f64>| {
        let mut r = Vec3::ZERO;
        r[plane.axis] = plane.value;
        r[u] = p.x as f32;
        r[v] = p.y as f32;
        r
    };
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = HashMap::new();
    let mut insert = |cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>, p: Vec3| {
        if let Some(&h) = handles.get(&key(p)) {
            return Ok::<_, SeamError>(h);
        }
        let h = cdt.insert(to2(p)).map_err(|e| SeamError::SeamPoint {
            point: p,
            message: format!("{e:?}"),
        })?;
        handles.insert(key(p), h);
        Ok(h)
    };
    for &c in &corners {
        insert(&mut cdt, c)?;
    }
    for &p in points {
        insert(&mut cdt, p)?;
    }
    let mut edges: Vec<[Vec3; 2]> = segments.to_vec();
    for (t, _) in in_plane {
        for i in 0..3 {
            edges.push([t[i], t[(i + 1) % 3]]);
        }
    }
    for e in &edges {
        insert(&mut cdt, e[0])?;
        insert(&mut cdt, e[1])?;
    }
    for e in &edges {
        let (h0, h1) = (insert(&mut cdt, e[0])?, insert(&mut cdt, e[1])?);
        add_seam_constraint(&mut cdt, (e[0], h0), (e[1], h1))?;
    }
    let orient2 = |a: DVec2, b: DVec2, c: DVec2| {
        robust::orient2d(
            robust::Coord { x: a.x, y: a.y },
            robust::Coord { x: b.x, y: b.y },
            robust::Coord { x: c.x, y: c.y },
        )
    };
    let flat = |p: Vec3| DVec2::new(p[u] as f64, p[v] as f64);
    let mut seam = Seam {
        vertices: cdt.num_vertices(),
        ..Seam::default()
    };
    for f in cdt.inner_faces() {
        let [a, b, c] = f.vertices().map(|h| to3(h.position()));
        let mut t = [a, b, c];
        // Which in-plane scene triangle contains the centroid (strictly)?
        let g = (flat(a) + flat(b) + flat(c)) / 3.0;
        let mut source = None;
        for (s, id) in in_plane {
            let [p, q, r] = s.map(flat);
            let o = orient2(p, q, r);
            let inside = [(p, q), (q, r), (r, p)]
                .iter()
                .all(|&(x, y)| orient2(x, y, g) * o > 0.0);
            if inside {
                source = Some(*id);
                // Orient like the scene triangle.
                if orient2(flat(t[0]), flat(t[1]), flat(t[2])) * o < 0.0 {
                    t.swap(1, 2);
                }
                break;
            }
        }
        seam.triangles.push(t);
        seam.source.push(source);
    }
    Ok(seam)
}

/// A facet of a part's PLC and what it becomes in the merged mesh.
#[derive(Clone, Copy, Debug)]
pub(super) enum FacetKind {
    /// A scene-triangle piece (cleaned index).
    Scene(u32),
    /// A seam-only face.
    Seam,
}

/// What one part's TetGen run took and gave (the per-part report fields).
#[derive(Clone, Copy, Debug)]
pub(super) struct PartStats {
    input_points: usize,
    input_triangles: usize,
    /// Points used by no scene facet (seam and box corners, trace points).
    wall_points: usize,
    /// Facets that are not scene pieces (seam-only and box faces).
    wall_triangles: usize,
    tets: usize,
    peak_kib: Option<u64>,
}

/// One part after TetGen: f32 points, positive tets, constrained faces.
pub(super) struct PartMesh {
    pub(super) points: Vec<Vec3>,
    pub(super) tets: Vec<[u32; 4]>,
    /// (vertices, cleaned source) in the part's point indices.
    pub(super) constrained: Vec<([u32; 3], u32)>,
    pub(super) stats: PartStats,
}

fn run_part(
    part: usize,
    facets: &[([Vec3; 3], FacetKind)],
    box_faces: &[[Vec3; 3]],
    options: &SeamOptions,
) -> Result<PartMesh, SeamError> {
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut points: Vec<Vec3> = Vec::new();
    let mut id = |p: Vec3| {
        *index.entry(key(p)).or_insert_with(|| {
            points.push(p);
            points.len() as u32 - 1
        })
    };
    let mut triangles = Vec::new();
    let mut markers = Vec::new();
    for (i, (t, _)) in facets.iter().enumerate() {
        triangles.push(t.map(&mut id));
        markers.push(i as i32 + 1);
    }
    for t in box_faces {
        triangles.push(t.map(&mut id));
        markers.push(0);
    }
    let mut on_scene = vec![false; points.len()];
    for ((_, k), t) in facets.iter().zip(&triangles) {
        if matches!(k, FacetKind::Scene(_)) {
            for &v in t {
                on_scene[v as usize] = true;
            }
        }
    }
    let wall_points = on_scene.iter().filter(|&&s| !s).count();
    let wall_triangles = facets
        .iter()
        .filter(|(_, k)| matches!(k, FacetKind::Seam))
        .count()
        + box_faces.len();
    let input = TetgenInput {
        points: points.iter().map(|p| p.as_dvec3().to_array()).collect(),
        triangles,
        markers,
    };
    let mut topts = options.tetgen.clone();
    topts.preserve_surface = true;
    let out = match tetrahedralize(&input, &topts, &options.isolation) {
        Ok(out) => out,
        Err(TetgenError::SelfIntersection) => {
            return Err(self_intersection(part, facets, &points, &input.triangles));
        }
        Err(source) => return Err(SeamError::Tetgen { part, source }),
    };
    if let Some(i) = (0..input.points.len()).find(|&i| out.points.get(i) != Some(&input.points[i]))
    {
        return Err(SeamError::InputPointChanged { part, point: i });
    }
    // Every facet must be exactly one face with its own vertices.
    let mut count = vec![0usize; facets.len()];
    let mut same = vec![false; facets.len()];
    for (face, &m) in out.faces.iter().zip(&out.face_markers) {
        if m <= 0 || m as usize > facets.len() {
            continue;
        }
        let f = m as usize - 1;
        count[f] += 1;
        same[f] = face_key(*face) == face_key(input.triangles[f]);
    }
    if let Some(f) = (0..facets.len()).find(|&f| count[f] != 1 || !same[f]) {
        return Err(SeamError::FacetNotPreserved {
            part,
            facet: f,
            faces: count[f],
        });
    }
    let p32: Vec<Vec3> = out
        .points
        .iter()
        .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
        .collect();
    let mut tets = Vec::with_capacity(out.tets.len());
    let mut bad = 0;
    for &t in &out.tets {
        let [a, b, c, d] = t.map(|v| DVec3::from_array(out.points[v as usize]));
        let o = tet_core::predicates::orient3d(a, b, c, d);
        let t = if o < 0.0 { [t[1], t[0], t[2], t[3]] } else { t };
        let [a, b, c, d] = t.map(|v| p32[v as usize]);
        if o == 0.0 || tet_core::predicates::orient3d_f32(a, b, c, d) <= 0.0 {
            bad += 1;
        }
        tets.push(t);
    }
    if bad > 0 {
        return Err(SeamError::RoundingFlattens { part, count: bad });
    }
    let constrained = facets
        .iter()
        .zip(&input.triangles)
        .filter_map(|((_, k), &t)| match k {
            FacetKind::Scene(s) => Some((t, *s)),
            FacetKind::Seam => None,
        })
        .collect();
    Ok(PartMesh {
        stats: PartStats {
            input_points: input.points.len(),
            input_triangles: input.triangles.len(),
            wall_points,
            wall_triangles,
            tets: tets.len(),
            peak_kib: out.worker_peak_kib,
        },
        points: p32,
        tets,
        constrained,
    })
}

/// Names the first intersecting pair of a part's PLC (TetGen only says
/// that there is one).
fn self_intersection(
    part: usize,
    facets: &[([Vec3; 3], FacetKind)],
    points: &[Vec3],
    triangles: &[[u32; 3]],
) -> SeamError {
    let r = crate::intersect::find_self_intersections(points, triangles);
    let what = |i: u32| {
        let t = triangles[i as usize].map(|v| points[v as usize]);
        let s = match facets.get(i as usize) {
            Some((_, FacetKind::Scene(s))) => Some(*s),
            _ => None,
        };
        (t, s)
    };
    match r.pairs.first() {
        Some(p) => SeamError::PartSelfIntersects {
            part,
            first: what(p.first),
            second: what(p.second),
            kind: p.kind,
            pairs: r.pairs.len(),
        },
        None => SeamError::Tetgen {
            part,
            source: TetgenError::SelfIntersection,
        },
    }
}

/// Vertices off a cut plane by less than this × the box's largest extent
/// make the plane unusable ([`SeamError::PlaneNearVertex`]): TetGen would
/// merge crossing points with them (its duplicate tolerance is relative).
pub const NEAR_PLANE: f64 = 1e-7;

/// The first vertex strictly off the plane but within `tolerance` of it.
pub fn near_plane_vertex(vertices: &[Vec3], plane: SplitPlane, tolerance: f64) -> Option<u32> {
    vertices
        .iter()
        .position(|p| {
            let d = (p[plane.axis] as f64 - plane.value as f64).abs();
            d > 0.0 && d < tolerance
        })
        .map(|i| i as u32)
}

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
    let (cleaned, cm) = clean_scene(scene)?;
    if cleaned.triangles.is_empty() {
        return Err(SeamError::EmptyScene);
    }
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
    let mut report = SeamReport::default();
    let mut parts: Vec<Vec<([Vec3; 3], FacetKind)>> = vec![Vec::new(); n + 1];
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
                parts[j].extend(fan(&lo).into_iter().map(|p| (p, FacetKind::Scene(s))));
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
        } else {
            parts[slab].extend(fan(&poly).into_iter().map(|p| (p, FacetKind::Scene(s))));
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
            parts[j].push((*t, k));
            parts[j + 1].push((*t, k));
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
    let faces: Vec<Vec<[Vec3; 3]>> = (0..=n).map(slab_faces).collect();
    let inputs = PartInputs {
        parts,
        faces,
        triangle_source: cm.triangle_source,
        triangle_count: scene.triangles.len() as u32,
    };
    finish_parts(inputs, report, options, merge)
}

/// Adds the segment between the already inserted seam points `a` and `b`
/// (with their CDT handles) as a constraint, unless it is degenerate or
/// already there. Two constraints that cross mean the seam cannot be
/// triangulated conformingly: an error naming the segment.
pub(super) fn add_seam_constraint(
    cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
    (a, h0): (Vec3, FixedVertexHandle),
    (b, h1): (Vec3, FixedVertexHandle),
) -> Result<(), SeamError> {
    if h0 == h1 || cdt.exists_constraint(h0, h1) {
        return Ok(());
    }
    if !cdt.can_add_constraint(h0, h1) {
        return Err(SeamError::SeamConstraintsCross { from: a, to: b });
    }
    cdt.add_constraint(h0, h1);
    Ok(())
}

/// The parts of a split, ready for TetGen.
pub(super) struct PartInputs {
    /// Each part's PLC facets (scene pieces and wall triangles).
    pub(super) parts: Vec<Vec<([Vec3; 3], FacetKind)>>,
    /// Each part's box faces (unmarked facets; empty for a tree, whose
    /// walls are among the facets).
    pub(super) faces: Vec<Vec<[Vec3; 3]>>,
    /// Input scene triangle of each cleaned one.
    pub(super) triangle_source: Vec<u32>,
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
/// `merge`, fills the per-part fields of `report` and merges.
pub(super) fn finish_parts<M: Merge>(
    inputs: PartInputs,
    mut report: SeamReport,
    options: &SeamOptions,
    merge: &M,
) -> Result<(M::Output, SeamReport), SeamError> {
    let ctx = MergeContext {
        triangle_source: &inputs.triangle_source,
        triangle_count: inputs.triangle_count,
        seams: &report.seams,
    };
    let parts = run_parts(&inputs.parts, &inputs.faces, options, &|k, mesh| {
        merge.part(k, mesh, &ctx)
    })?;
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
fn record_part(report: &mut SeamReport, s: &PartStats) {
    report.part_points.push(s.input_points);
    report.part_triangles.push(s.input_triangles);
    report.part_wall_points.push(s.wall_points);
    report.part_wall_triangles.push(s.wall_triangles);
    report.part_tets.push(s.tets);
    report.part_peak_kib.push(s.peak_kib);
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
fn merge_parts(meshes: &[PartMesh], ctx: &MergeContext) -> Result<TetMesh, SeamError> {
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

/// Runs TetGen on every part, at most `options.parallel_parts` at a time:
/// that many threads take the next part from a queue as soon as their
/// previous one finishes (largest input first, so a big part does not
/// start last), which keeps both threads busy when parts differ in size.
/// Each part is handed to `finish` on its thread as soon as its TetGen
/// run returns. Results are in part order; the first error (in part order)
/// is returned.
pub(super) fn run_parts<T: Send>(
    parts: &[Vec<([Vec3; 3], FacetKind)>],
    faces: &[Vec<[Vec3; 3]>],
    options: &SeamOptions,
    finish: &(dyn Fn(usize, PartMesh) -> Result<T, SeamError> + Sync),
) -> Result<Vec<T>, SeamError> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let width = options.parallel_parts.max(1).min(parts.len().max(1));
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse(parts[k].len() + faces[k].len()));
    let results: Vec<Mutex<Option<Result<T, SeamError>>>> =
        (0..parts.len()).map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let work = || {
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= order.len() || failed.load(Ordering::Relaxed) {
                break;
            }
            let k = order[i];
            let r = run_part(k, &parts[k], &faces[k], options).and_then(|m| finish(k, m));
            if r.is_err() {
                failed.store(true, Ordering::Relaxed);
            }
            *results[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
        }
    };
    if width == 1 {
        work();
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..width).map(|_| scope.spawn(work)).collect();
            for h in handles {
                h.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            }
        });
    }
    let mut out = Vec::with_capacity(parts.len());
    let mut first_error = None;
    for r in results {
        match r.into_inner().unwrap_or_else(|e| e.into_inner()) {
            Some(Ok(m)) => out.push(m),
            Some(Err(e)) => {
                first_error.get_or_insert(e);
            }
            None => {}
        }
    }
    match first_error {
        Some(e) => Err(e),
        None => Ok(out),
    }
}
