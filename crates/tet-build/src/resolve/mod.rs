//! Resolving self-intersections: a triangle soup whose triangles cross,
//! touch or overlap becomes one whose triangles meet only in shared
//! vertices and shared edges, as TetGen's surface-preserving mode needs.
//!
//! ```
//! use glam::Vec3;
//! use tet_build::resolve::{ResolveOptions, resolve};
//!
//! // Two triangles crossing in an X.
//! let vertices = vec![
//!     Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 4.0, 0.0),
//!     Vec3::new(1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(3.0, 3.0, 0.0),
//! ];
//! let triangles = vec![[0, 1, 2], [3, 4, 5]];
//! let out = resolve(&vertices, &triangles, &ResolveOptions::default())?;
//! assert_eq!(out.report.pairs, 1);
//! assert_eq!(&out.vertices[..6], &vertices[..]);
//! assert!(tet_build::intersect::find_self_intersections(&out.vertices, &out.triangles).is_clean());
//! # Ok::<(), tet_build::resolve::ResolveError>(())
//! ```
//!
//! ## Algorithm
//!
//! One exact check ([`crate::intersect::find_self_intersections`]) finds
//! the intersecting pairs; a clean scene stops there and comes back
//! unchanged (`report.rounds == 0`). Otherwise rounds of:
//!
//! 1. **Pairs** (`pairs.rs`): each pair's intersection with exact
//!    predicates: a segment or a point, or for coplanar pairs each one's
//!    edges clipped to the other. Its ends are named symbolically
//!    (`points.rs`): a vertex, an edge crossing a triangle, two edges
//!    crossing, three planes meeting. A point exactly on a triangle's
//!    boundary gets the boundary's name, so every pair that meets it names
//!    it alike.
//! 2. **Edges** (`round.rs`): every point on a mesh edge is registered on
//!    that edge, sorted exactly along it, equal ones merged. Every triangle
//!    with that edge gets them, so no T-junction is left.
//! 3. **Arrangements** (`arrangement.rs`, per triangle, in parallel): the
//!    triangle's segments are split where they cross each other (two
//!    intersection lines meet where three planes do) and where points lie
//!    on them, exactly; equal points found in different ways are merged.
//! 4. **Rounding** (`round.rs`, `snap.rs`): each distinct point gets `f32`
//!    coordinates from a double evaluation whose error is far below an
//!    `f32` spacing (exact expansions where the error bound is too loose).
//!    A point at, or within [`SNAP_ULPS`](crate::resolve::SNAP_ULPS) spacings of, a vertex becomes
//!    that vertex, so rounds cannot breed clusters of almost equal points.
//! 5. **Cut lines** (`cutlines.rs`): per triangle, its boundary through
//!    its edges' points, its inner points and split segments, as vertices.
//!    A point that rounding put on, outside or within the snap distance of
//!    the boundary goes onto the nearest boundary edge (split for every
//!    triangle on it, as in snap rounding); a triangle thinner than the
//!    snap distance is dropped and its thin corner goes onto the opposite
//!    side, for the triangles across it.
//! 6. **Pieces** (`retriangulate.rs`, per triangle, in parallel): a
//!    constrained Delaunay triangulation (spade) of the rounded points in
//!    the triangle's projection, boundary and segments as constraints, the
//!    faces inside the boundary, lifted to the vertices and wound like the
//!    triangle (a sliver tilted by rounding is turned to agree with its
//!    input triangle's normal). Of two coplanar overlapping triangles the
//!    higher input index drops its pieces inside the lower (duplicates keep
//!    the lower); identical pieces collapse to one.
//! 7. **Re-check** (`recheck.rs`): rounding can create new contacts, so
//!    the new pieces are checked exactly against everything near them; what
//!    still meets goes into the next round (on the pieces, plain `f32`
//!    triangles again), up to [`ResolveOptions::max_rounds`](crate::resolve::ResolveOptions::max_rounds), else
//!    [`ResolveError::NotConverged`](crate::resolve::ResolveError::NotConverged) names the input triangles. A round
//!    that changed nothing is followed by one that snaps only equal
//!    positions.
//!
//! Two triangles within the snap distance of each other's plane are
//! treated as coplanar: where they cross is decided by rounding noise, and
//! cutting along such lines need not end.
//!
//! Input vertices are never moved or dropped; every piece records the input
//! triangle it came from and its normal agrees with that triangle's, but
//! for a piece flat within rounding (three points collinear before
//! rounding, e.g. a crossing point exactly on the triangle's edge rounded
//! just off it), whose normal is rounding noise. The
//! predicates run on `f64` with a forward error bound (`arith.rs`) and fall
//! back to exact expansion arithmetic (`expansion.rs`) when the bound cannot
//! decide. Exactly degenerate input triangles are an error (cleaning
//! removes them).

mod arith;
mod arrangement;
mod cutlines;
pub mod error;
mod expansion;
mod pairs;
mod points;
mod recheck;
pub mod report;
mod retriangulate;
mod round;
mod snap;
mod table;

use glam::Vec3;

pub use error::{LISTED_PAIRS, ResolveError};
pub use report::ResolveReport;

use crate::intersect::{IntersectingPair, find_self_intersections};
use round::{Soup, run_round};

/// Largest coordinate magnitude accepted: the deepest predicate is a
/// polynomial of degree 13 in coordinate differences, which must stay far
/// from `f64` overflow.
pub const MAX_COORDINATE: f32 = 1.0e18;

/// The snap distance in units of the `f32` spacing at the largest input
/// coordinate: a new point this close (in every coordinate) to a vertex
/// becomes that vertex, a point this close to its triangle's boundary goes
/// onto it, a triangle this thin collapses, and two triangles this close
/// to each other's plane count as coplanar. Two spacings cover the
/// rounding of both points involved with room to spare, yet stay far below
/// any feature a scene can resolve in `f32`.
pub const SNAP_ULPS: f64 = 2.0;

/// Options of [`resolve`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ResolveOptions {
    /// Most rounds of cutting and re-checking before giving up.
    pub max_rounds: u32,
}

impl Default for ResolveOptions {
    fn default() -> Self {
        ResolveOptions { max_rounds: 8 }
    }
}

/// A soup without self-intersections.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Resolved {
    /// The input vertices, unchanged and in order, then the added points
    /// (only those some triangle uses).
    pub vertices: Vec<Vec3>,
    /// The pieces.
    pub triangles: Vec<[u32; 3]>,
    /// For each piece, the input triangle it lies in (index into the
    /// `triangles` argument of [`resolve`]).
    pub parent: Vec<u32>,
    /// What was done.
    pub report: ResolveReport,
}

fn validate(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), ResolveError> {
    for (i, p) in vertices.iter().enumerate() {
        if !p.is_finite() {
            return Err(ResolveError::NonFiniteVertex {
                vertex: i as u32,
                position: p.to_array(),
            });
        }
        if p.abs().max_element() > MAX_COORDINATE {
            return Err(ResolveError::CoordinateTooLarge {
                vertex: i as u32,
                position: p.to_array(),
                limit: MAX_COORDINATE,
            });
        }
    }
    for (t, tri) in triangles.iter().enumerate() {
        for (c, &v) in tri.iter().enumerate() {
            if v as usize >= vertices.len() {
                return Err(ResolveError::IndexOutOfRange {
                    triangle: t as u32,
                    corner: c as u8,
                    vertex: v,
                    count: vertices.len(),
                });
            }
        }
    }
    Ok(())
}

/// Makes `triangles` over `vertices` free of self-intersections (see the
/// module docs). A scene without any comes back identical, with
/// `report.rounds == 0`.
pub fn resolve(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    options: &ResolveOptions,
) -> Result<Resolved, ResolveError> {
    validate(vertices, triangles)?;
    let check = find_self_intersections(vertices, triangles);
    if let Some(&t) = check.degenerate.first() {
        return Err(ResolveError::DegenerateTriangle { triangle: t });
    }
    if check.is_clean() {
        return Ok(Resolved {
            vertices: vertices.to_vec(),
            triangles: triangles.to_vec(),
            parent: (0..triangles.len() as u32).collect(),
            report: ResolveReport::default(),
        });
    }
    let mut soup = Soup {
        vertices: vertices.to_vec(),
        triangles: triangles.to_vec(),
        parent: (0..triangles.len() as u32).collect(),
        input: triangles.to_vec(),
    };
    let scale = vertices
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max) as f64;
    let snap = SNAP_ULPS * scale * 2f64.powi(-23);
    let mut report = ResolveReport {
        pairs: check.pairs.len(),
        ..ResolveReport::default()
    };
    let mut pairs = check.pairs;
    let signature = |soup: &Soup, pairs: &[IntersectingPair]| -> Vec<[[u32; 3]; 2]> {
        pairs
            .iter()
            .map(|p| {
                [
                    soup.triangles[p.first as usize],
                    soup.triangles[p.second as usize],
                ]
            })
            .collect()
    };
    let mut stuck = false;
    while !pairs.is_empty() {
        if report.rounds >= options.max_rounds {
            return Err(not_converged(report.rounds, &soup.parent, &pairs));
        }
        let before = signature(&soup, &pairs);
        let outcome = run_round(&mut soup, if stuck { 0.0 } else { snap }, &pairs)?;
        report.rounds += 1;
        report.merged_pieces += outcome.merged;
        pairs = recheck::recheck(&soup.vertices, &soup.triangles, &outcome.dirty);
        // A round that changed nothing snapped its points back onto the
        // vertices they came near: the next one snaps only equal positions.
        stuck = signature(&soup, &pairs) == before;
    }
    let (vertices_out, triangles_out) = drop_unused(vertices.len(), soup.vertices, soup.triangles);
    report.added_points = vertices_out.len() - vertices.len();
    report.split_triangles = count_changed(triangles, &triangles_out, &soup.parent);
    Ok(Resolved {
        vertices: vertices_out,
        triangles: triangles_out,
        parent: soup.parent,
        report,
    })
}

fn not_converged(rounds: u32, parent: &[u32], pairs: &[IntersectingPair]) -> ResolveError {
    let mut named: Vec<(u32, u32)> = pairs
        .iter()
        .map(|p| {
            let (a, b) = (parent[p.first as usize], parent[p.second as usize]);
            (a.min(b), a.max(b))
        })
        .collect();
    named.sort_unstable();
    named.dedup();
    let total = named.len();
    named.truncate(LISTED_PAIRS);
    ResolveError::NotConverged {
        rounds,
        pairs: named,
        total,
    }
}

/// Removes added points no triangle uses (input vertices all stay).
fn drop_unused(
    fixed: usize,
    mut vertices: Vec<Vec3>,
    mut triangles: Vec<[u32; 3]>,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut used = vec![false; vertices.len()];
    for t in &triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut map: Vec<u32> = (0..vertices.len() as u32).collect();
    let mut next = fixed;
    for v in fixed..vertices.len() {
        if used[v] {
            vertices[next] = vertices[v];
            map[v] = next as u32;
            next += 1;
        }
    }
    vertices.truncate(next);
    for t in &mut triangles {
        *t = t.map(|v| map[v as usize]);
    }
    (vertices, triangles)
}

/// Input triangles not output as exactly themselves, alone.
fn count_changed(input: &[[u32; 3]], output: &[[u32; 3]], parent: &[u32]) -> usize {
    let mut count = vec![0u32; input.len()];
    let mut same = vec![false; input.len()];
    for (t, &p) in output.iter().zip(parent) {
        count[p as usize] += 1;
        same[p as usize] = *t == input[p as usize];
    }
    (0..input.len())
        .filter(|&i| !(count[i] == 1 && same[i]))
        .count()
}
