//! What each affected triangle is cut along, in rounded coordinates: its
//! boundary through every point on its edges, its inner points and its
//! split segments, all as vertices.
//!
//! Rounding may put a point that lies exactly inside a triangle on or
//! outside its boundary (as seen in the triangle's projection). Such a
//! point, or one closer to the boundary than the snap distance (it would
//! make a needle that the next rounding may fold), is moved onto the
//! nearest boundary edge instead, as in snap rounding: the edge is split
//! there, for every triangle that has it, so the triangle and its
//! neighbours stay watertight and the point's segments stay inside. Alike,
//! a triangle thinner than the snap distance (a needle that rounding may
//! fold) is dropped and its thin corner put onto the opposite edge for the
//! triangles across it.
//!
//! The projection axis is the triangle's dominant normal axis unless two of
//! its vertices project to one point there.

use glam::DVec3;
use rayon::prelude::*;

use super::arrangement::Arranged;
use super::points::{Edge, Geo, Key, PointDef, edge, orient2, project};
use super::retriangulate::{PieceInput, PiecePoint};
use super::table::{FxMap, PointTable};

/// Marks a point that is a corner not named in the table.
const CORNER: u32 = u32::MAX;

/// Everything the inputs are built from.
pub(crate) struct CutState<'a> {
    /// Geometry over all vertices, the round's new ones included.
    pub geo: Geo<'a>,
    /// Current triangles.
    pub tris: &'a [[u32; 3]],
    /// Input triangle of each.
    pub parent: &'a [u32],
    /// The input triangles (their vertex ids are the soup's first ones).
    pub input: &'a [[u32; 3]],
    /// The round's named points.
    pub table: &'a PointTable,
    /// Class representative of each table id.
    pub reps: &'a [u32],
    /// Vertex of each representative.
    pub vertex_of: &'a [u32],
    /// Arrangement of each triangle that has one.
    pub arranged: &'a FxMap<u32, Arranged>,
    /// Coplanar partners of each triangle.
    pub partners: &'a FxMap<u32, Vec<u32>>,
    /// Points closer than this to a triangle's boundary go onto it.
    pub snap: f64,
}

impl CutState<'_> {
    fn class_point(&self, id: u32) -> PiecePoint {
        let r = self.reps[id as usize];
        PiecePoint {
            id: r,
            vertex: self.vertex_of[r as usize],
            def: self.table.defs[r as usize],
        }
    }

    fn corner(&self, v: u32) -> PiecePoint {
        match self.table.get(&Key::Vertex(v)) {
            Some(id) => self.class_point(id),
            None => PiecePoint {
                id: CORNER,
                vertex: v,
                def: PointDef::Vertex(v),
            },
        }
    }

    /// The cut of triangle `t` with the edge points of `registry`.
    fn input(&self, registry: &FxMap<Edge, Vec<u32>>, t: u32) -> Option<PieceInput> {
        let tri = self.tris[t as usize];
        let mut input = PieceInput {
            tri,
            parent: self.input[self.parent[t as usize] as usize],
            ..PieceInput::default()
        };
        // One point per vertex: points that rounded or snapped to one
        // vertex are one vertex of the triangulation.
        let mut index: FxMap<u32, usize> = FxMap::default();
        let mut add = |input: &mut PieceInput, p: PiecePoint| {
            *index.entry(p.vertex).or_insert_with(|| {
                input.points.push(p);
                input.points.len() - 1
            })
        };
        for k in 0..3 {
            let (p, q) = (tri[k], tri[(k + 1) % 3]);
            let c = add(&mut input, self.corner(p));
            input.chain.push(c);
            input.chain_edge.push(k as u8);
            if let Some(on) = registry.get(&edge(p, q)) {
                let ids: Vec<u32> = if p < q {
                    on.clone()
                } else {
                    on.iter().rev().copied().collect()
                };
                for id in ids {
                    let i = add(&mut input, self.class_point(id));
                    input.chain.push(i);
                    input.chain_edge.push(k as u8);
                }
            }
        }
        // A vertex enters the boundary once (an edge point may have
        // rounded onto a corner or onto another edge's point).
        let mut chain = Vec::with_capacity(input.chain.len());
        let mut chain_edge = Vec::with_capacity(input.chain.len());
        for (&c, &e) in input.chain.iter().zip(&input.chain_edge) {
            if chain.last() == Some(&c) {
                // The boundary runs on from here along the later edge.
                *chain_edge.last_mut()? = e;
                continue;
            }
            if chain.contains(&c) {
                continue;
            }
            chain.push(c);
            chain_edge.push(e);
        }
        input.chain = chain;
        input.chain_edge = chain_edge;
        if let Some(a) = self.arranged.get(&t) {
            for &p in &a.points {
                add(&mut input, self.class_point(p));
            }
            let constraints: Vec<[usize; 2]> = a
                .constraints
                .iter()
                .map(|c| c.map(|id| add(&mut input, self.class_point(id))))
                .collect();
            input.constraints = constraints
                .into_iter()
                .filter(|c| input.points[c[0]].vertex != input.points[c[1]].vertex)
                .collect();
        }
        let me = (self.parent[t as usize], t);
        if let Some(ps) = self.partners.get(&t) {
            input.partners = ps
                .iter()
                .filter(|&&o| (self.parent[o as usize], o) < me)
                .map(|&o| self.tris[o as usize])
                .collect();
        }
        input.axis = pick_axis(&self.geo, &input)?;
        Some(input)
    }
}

/// The projection axis: the triangle's dominant normal axis, unless two of
/// its distinct vertices project to one point there; then the next axis
/// (by normal component) where the triangle stays non-degenerate and the
/// vertices stay apart. `None` for a degenerate triangle.
fn pick_axis(geo: &Geo, input: &PieceInput) -> Option<usize> {
    let [a, b, c] = input.tri.map(|v| geo.pos(v));
    let n = (b - a).cross(c - a).abs();
    let mut order = [2usize, 1, 0];
    order.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
    let mut ids: Vec<u32> = input.points.iter().map(|p| p.vertex).collect();
    ids.sort_unstable();
    ids.dedup();
    let valid: Vec<usize> = order
        .into_iter()
        .filter(|&k| orient2(project(a, k), project(b, k), project(c, k)) != 0)
        .collect();
    for &k in &valid {
        let mut pts: Vec<(u64, u64)> = ids
            .iter()
            .map(|&v| {
                let (x, y) = project(geo.pos(v), k);
                ((x + 0.0).to_bits(), (y + 0.0).to_bits())
            })
            .collect();
        pts.sort_unstable();
        if pts.windows(2).all(|w| w[0] != w[1]) {
            return Some(k);
        }
    }
    valid.first().copied()
}

/// Is `q` strictly inside the closed polygon `poly` (any orientation)?
fn strictly_inside(q: (f64, f64), poly: &[(f64, f64)]) -> bool {
    let mut winding = 0i32;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let o = orient2(a, b, q);
        if o == 0
            && q.0 >= a.0.min(b.0)
            && q.0 <= a.0.max(b.0)
            && q.1 >= a.1.min(b.1)
            && q.1 <= a.1.max(b.1)
        {
            return false;
        }
        if a.1 <= q.1 {
            if b.1 > q.1 && o > 0 {
                winding += 1;
            }
        } else if b.1 <= q.1 && o < 0 {
            winding -= 1;
        }
    }
    winding != 0
}

fn segment_distance(q: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len = dx * dx + dy * dy;
    let s = if len > 0.0 {
        (((q.0 - a.0) * dx + (q.1 - a.1) * dy) / len).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (x, y) = (a.0 + s * dx - q.0, a.1 + s * dy - q.1);
    x * x + y * y
}

/// Distance from `p` to the segment `ab` in 3-D.
fn distance_3d(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let len = d.length_squared();
    let s = if len > 0.0 {
        ((p - a).dot(d) / len).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * s - p).length()
}

/// Inner points of `input` that rounding put on or outside its boundary,
/// or within `eps` of it, each with the triangle edge it goes onto.
fn stray_points(geo: &Geo, input: &PieceInput, eps: f64) -> Vec<(Edge, u32)> {
    let axis = input.axis;
    let at = |i: usize| project(geo.pos(input.points[i].vertex), axis);
    let poly: Vec<(f64, f64)> = input.chain.iter().map(|&c| at(c)).collect();
    let ring: Vec<DVec3> = input
        .chain
        .iter()
        .map(|&c| geo.pos(input.points[c].vertex))
        .collect();
    let mut on_chain = vec![false; input.points.len()];
    for &c in &input.chain {
        on_chain[c] = true;
    }
    let chain_vertices: Vec<u32> = input
        .chain
        .iter()
        .map(|&c| input.points[c].vertex)
        .collect();
    let mut out = Vec::new();
    for (i, p) in input.points.iter().enumerate() {
        if on_chain[i] || p.id == CORNER || chain_vertices.contains(&p.vertex) {
            continue;
        }
        let q = at(i);
        let p3 = geo.pos(p.vertex);
        let n = ring.len();
        let (near3, d3) = (0..n)
            .map(|x| (x, distance_3d(p3, ring[x], ring[(x + 1) % n])))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::INFINITY));
        let nearest = if d3 <= eps {
            near3
        } else if strictly_inside(q, &poly) {
            continue;
        } else {
            (0..poly.len())
                .min_by(|&x, &y| {
                    let dx = segment_distance(q, poly[x], poly[(x + 1) % poly.len()]);
                    let dy = segment_distance(q, poly[y], poly[(y + 1) % poly.len()]);
                    dx.total_cmp(&dy)
                })
                .unwrap_or(0)
        };
        let k = input.chain_edge[nearest] as usize;
        out.push((edge(input.tri[k], input.tri[(k + 1) % 3]), p.id));
    }
    out
}

/// Puts `id` into the sorted point list of edge `e` by its position along
/// the edge (it lies within rounding of the edge, not exactly on it).
fn insert_on_edge(geo: &Geo, table: &PointTable, list: &mut Vec<u32>, e: Edge, id: u32) -> bool {
    if list.contains(&id) || table.vertex_of_def(id).is_some_and(|v| e.contains(&v)) {
        return false;
    }
    let (p, q) = (geo.pos(e[0]), geo.pos(e[1]));
    let d = q - p;
    let t = |i: u32| (table.approx[i as usize] - p).dot(d);
    let x = t(id);
    let at = list.partition_point(|&i| t(i) < x);
    list.insert(at, id);
    true
}

/// A triangle thinner than `eps`: a corner within `eps` of the opposite
/// edge. The corner goes onto that edge (for the triangles across it) and
/// the needle itself is dropped; what it covered lies within `eps` of the
/// edge.
fn needle(geo: &Geo, input: &PieceInput, eps: f64) -> Option<(Edge, u32)> {
    let corner = |v: u32| input.points.iter().find(|p| p.vertex == v);
    (0..3)
        .filter_map(|k| {
            let v = input.tri[k];
            let (a, b) = (input.tri[(k + 1) % 3], input.tri[(k + 2) % 3]);
            let d = distance_3d(geo.pos(v), geo.pos(a), geo.pos(b));
            let id = corner(v)?.id;
            (d <= eps && id != CORNER).then_some((d, edge(a, b), id))
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map(|(_, e, id)| (e, id))
}

/// Builds the cut of every triangle in `work`, routing stray points onto
/// boundary edges (which may bring in the triangles across those edges).
/// Returns `(triangle, input)` pairs sorted by triangle.
pub(crate) fn cut_inputs(
    st: &CutState,
    registry: &mut FxMap<Edge, Vec<u32>>,
    work: &[u32],
) -> Vec<(u32, PieceInput)> {
    let mut inputs: FxMap<u32, PieceInput> = FxMap::default();
    let mut collapsed: std::collections::HashSet<u32> = std::collections::HashSet::new();
    let mut todo: Vec<u32> = work.to_vec();
    for _pass in 0..4 {
        let built: Vec<(u32, Option<PieceInput>)> = todo
            .par_iter()
            .map(|&t| (t, st.input(registry, t)))
            .collect();
        let mut moved: Vec<(Edge, u32)> = Vec::new();
        for (t, input) in built {
            let Some(mut input) = input else {
                continue;
            };
            if collapsed.contains(&t) {
                input.collapsed = true;
            } else if let Some(m) = needle(&st.geo, &input, st.snap) {
                input.collapsed = true;
                collapsed.insert(t);
                moved.push(m);
            } else {
                moved.extend(stray_points(&st.geo, &input, st.snap));
            }
            inputs.insert(t, input);
        }
        moved.sort_unstable();
        moved.dedup();
        let mut edges: Vec<Edge> = Vec::new();
        for (e, id) in moved {
            let list = registry.entry(e).or_default();
            if insert_on_edge(&st.geo, st.table, list, e, id) {
                edges.push(e);
            }
        }
        if edges.is_empty() {
            break;
        }
        edges.dedup();
        let hot: std::collections::HashSet<Edge> = edges.into_iter().collect();
        todo = (0..st.tris.len() as u32)
            .into_par_iter()
            .filter(|&t| {
                let tri = st.tris[t as usize];
                (0..3).any(|k| hot.contains(&edge(tri[k], tri[(k + 1) % 3])))
            })
            .collect();
    }
    let mut out: Vec<(u32, PieceInput)> = inputs.into_iter().collect();
    out.sort_unstable_by_key(|(t, _)| *t);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_a_square_and_on_its_boundary() {
        let square = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)];
        assert!(strictly_inside((1.0, 1.0), &square));
        assert!(!strictly_inside((2.0, 1.0), &square));
        assert!(!strictly_inside((3.0, 1.0), &square));
        let reversed: Vec<(f64, f64)> = square.iter().rev().copied().collect();
        assert!(strictly_inside((0.5, 1.5), &reversed));
        assert!(!strictly_inside((0.0, 0.0), &reversed));
    }

    #[test]
    fn nearest_segment_distance() {
        assert_eq!(segment_distance((1.0, 1.0), (0.0, 0.0), (2.0, 0.0)), 1.0);
        assert_eq!(segment_distance((3.0, 0.0), (0.0, 0.0), (2.0, 0.0)), 1.0);
    }
}
