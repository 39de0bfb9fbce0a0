//! One round of resolution over the current soup: every reported pair's
//! intersection, every mesh edge's points in exact order, every affected
//! triangle's arrangement, the new points rounded to `f32`, and the
//! affected triangles replaced by their pieces.

use glam::Vec3;
use rayon::prelude::*;

use super::arrangement::{Arranged, LOCAL, Seg, arrange};
use super::cutlines::{CutState, cut_inputs};
use super::error::ResolveError;
use super::pairs::{PairResult, Where, intersect_pair};
use super::points::{Edge, Geo, Key, PointDef, edge};
use super::retriangulate::{Pieces, retriangulate};
use super::snap::SnapGrid;
use super::table::{FxMap, PointTable};
use crate::intersect::IntersectingPair;

/// The triangle soup between rounds.
#[derive(Clone, Debug, Default)]
pub(crate) struct Soup {
    /// Input vertices first, then added points.
    pub vertices: Vec<Vec3>,
    /// Current triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Input triangle of each.
    pub parent: Vec<u32>,
    /// The input triangles.
    pub input: Vec<[u32; 3]>,
}

/// What a round changed.
#[derive(Clone, Debug, Default)]
pub(crate) struct RoundOutcome {
    /// Indices (in the new soup) of the pieces made this round.
    pub dirty: Vec<u32>,
    /// Pieces dropped (coplanar overlaps, duplicates).
    pub merged: usize,
}

/// Per-triangle inputs gathered from the pairs.
#[derive(Default)]
struct Gathered {
    table: PointTable,
    registry: FxMap<Edge, Vec<u32>>,
    interior: FxMap<u32, Vec<u32>>,
    segments: FxMap<u32, Vec<Seg>>,
    partners: FxMap<u32, Vec<u32>>,
}

fn gather(geo: &Geo, tris: &[[u32; 3]], pairs: &[IntersectingPair], eps: f64) -> Gathered {
    let results: Vec<PairResult> = pairs
        .par_iter()
        .map(|p| intersect_pair(geo, tris[p.first as usize], tris[p.second as usize], eps))
        .collect();
    let mut g = Gathered::default();
    for (p, r) in pairs.iter().zip(&results) {
        let ts = [p.first, p.second];
        for &(key, at) in &r.points {
            let id = g.table.id(geo, key);
            for (slot, w) in at.iter().enumerate() {
                match *w {
                    Where::Corner => {}
                    Where::Edge(e) => g.registry.entry(e).or_default().push(id),
                    Where::Interior => g.interior.entry(ts[slot]).or_default().push(id),
                }
            }
        }
        for &(slot, line, ka, kb) in &r.segments {
            let (a, b) = (g.table.id(geo, ka), g.table.id(geo, kb));
            g.segments
                .entry(ts[slot])
                .or_default()
                .push(Seg { line, a, b });
        }
        if r.coplanar {
            g.partners.entry(p.first).or_default().push(p.second);
            g.partners.entry(p.second).or_default().push(p.first);
        }
        // Triangles of a pair are affected even when nothing was added.
        g.interior.entry(p.first).or_default();
        g.interior.entry(p.second).or_default();
    }
    g
}

/// Sorts each edge's points from `e[0]` to `e[1]` exactly, merging equal
/// ones (recorded in the table's union–find).
fn order_edges(geo: &Geo, g: &mut Gathered, edges: &[Edge]) {
    let sorted: Vec<(Edge, Vec<u32>, Vec<[u32; 2]>)> = edges
        .par_iter()
        .map(|&e| {
            let mut ids = g.registry[&e].clone();
            ids.sort_unstable();
            ids.dedup();
            let (a, b) = (PointDef::Vertex(e[0]), PointDef::Vertex(e[1]));
            let axis = geo.line_axis(&a, &b).unwrap_or(0);
            let def = |i: u32| g.table.defs[i as usize];
            ids.sort_by(|&p, &q| geo.cmp_axis(&def(p), &def(q), axis));
            if geo.cmp_axis(&a, &b, axis).is_gt() {
                ids.reverse();
            }
            let mut unify = Vec::new();
            let mut out: Vec<u32> = Vec::with_capacity(ids.len());
            for &id in &ids {
                match out.last() {
                    Some(&last) if geo.cmp_axis(&def(last), &def(id), axis).is_eq() => {
                        unify.push([last, id]);
                    }
                    _ => out.push(id),
                }
            }
            (e, out, unify)
        })
        .collect();
    for (e, ids, unify) in sorted {
        for [a, b] in unify {
            g.table.union(a, b);
        }
        g.registry.insert(e, ids);
    }
}

/// The sorted keys of a map, for a deterministic order.
fn sorted_keys<K: Copy + Ord, V>(m: &FxMap<K, V>) -> Vec<K> {
    let mut k: Vec<K> = m.keys().copied().collect();
    k.sort_unstable();
    k
}

/// Runs one round on `soup`, given the intersecting pairs of its current
/// triangles. A new point within `snap` (Chebyshev distance) of a vertex
/// becomes that vertex.
pub(crate) fn run_round(
    soup: &mut Soup,
    snap: f64,
    pairs: &[IntersectingPair],
) -> Result<RoundOutcome, ResolveError> {
    let n_vertices = soup.vertices.len() as u32;
    let tris = &soup.triangles;
    let geo = Geo {
        verts: &soup.vertices,
    };
    let mut g = gather(&geo, tris, pairs, snap);
    let edges = sorted_keys(&g.registry);
    order_edges(&geo, &mut g, &edges);

    // Affected: triangles of a pair, and every triangle with a split edge.
    let mut affected = vec![false; tris.len()];
    for &t in g.interior.keys() {
        affected[t as usize] = true;
    }
    let on_split_edge: Vec<u32> = (0..tris.len() as u32)
        .into_par_iter()
        .filter(|&t| {
            let tri = tris[t as usize];
            (0..3).any(|i| g.registry.contains_key(&edge(tri[i], tri[(i + 1) % 3])))
        })
        .collect();
    for t in on_split_edge {
        affected[t as usize] = true;
    }
    let mut work: Vec<u32> = (0..tris.len() as u32)
        .filter(|&t| affected[t as usize])
        .collect();
    let mut axes: Vec<Option<usize>> = work
        .par_iter()
        .map(|&t| geo.triangle_axis(tris[t as usize]))
        .collect();

    // Arrangements. A crossing that lies on a mesh edge was named by the
    // pair pass already (its pair meets there); should one be new all the
    // same, it is registered on its edges and the triangles on them are
    // arranged again, so no neighbour misses it.
    let empty_i: Vec<u32> = Vec::new();
    let empty_s: Vec<Seg> = Vec::new();
    let mut arranged: FxMap<u32, Arranged> = FxMap::default();
    let mut todo: Vec<usize> = (0..work.len()).collect();
    for _pass in 0..4 {
        let results: Vec<(usize, Arranged)> = todo
            .par_iter()
            .filter_map(|&w| {
                let t = work[w];
                let axis = axes[w]?;
                let interior = g.interior.get(&t).unwrap_or(&empty_i);
                let segments = g.segments.get(&t).unwrap_or(&empty_s);
                let a = arrange(
                    &geo,
                    &g.table,
                    &g.registry,
                    tris[t as usize],
                    axis,
                    interior,
                    segments,
                );
                Some((w, a))
            })
            .collect();
        let mut late: Vec<Edge> = Vec::new();
        for (w, mut a) in results {
            // Name the new points in the table, then rewrite local ids.
            let ids: Vec<u32> = a
                .new_points
                .iter()
                .map(|&(key, def, at)| {
                    if let Some(id) = g.table.get(&key) {
                        return id;
                    }
                    let id = g.table.insert(key, def, at);
                    let on: Vec<Edge> = match key {
                        Key::EdgeTriangle(e, _) => vec![e],
                        Key::EdgeEdge(e, f) => vec![e, f],
                        _ => Vec::new(),
                    };
                    for e in on {
                        g.registry.entry(e).or_default().push(id);
                        late.push(e);
                    }
                    id
                })
                .collect();
            let fix = |r: u32| {
                if r & LOCAL != 0 {
                    ids[(r & !LOCAL) as usize]
                } else {
                    r
                }
            };
            a.constraints.iter_mut().for_each(|c| *c = c.map(fix));
            a.points.iter_mut().for_each(|p| *p = fix(*p));
            a.unify.iter_mut().for_each(|u| *u = u.map(fix));
            a.new_points.clear();
            arranged.insert(work[w], a);
        }
        if late.is_empty() {
            break;
        }
        late.sort_unstable();
        late.dedup();
        order_edges(&geo, &mut g, &late);
        let late_set: std::collections::HashSet<Edge> = late.into_iter().collect();
        todo.clear();
        let slot: FxMap<u32, usize> = work.iter().enumerate().map(|(w, &t)| (t, w)).collect();
        for (t, tri) in tris.iter().enumerate() {
            if !(0..3).any(|i| late_set.contains(&edge(tri[i], tri[(i + 1) % 3]))) {
                continue;
            }
            let w = match slot.get(&(t as u32)) {
                Some(&w) => w,
                None => {
                    work.push(t as u32);
                    axes.push(geo.triangle_axis(*tri));
                    work.len() - 1
                }
            };
            todo.push(w);
        }
    }
    for t in sorted_keys(&arranged) {
        for [a, b] in arranged[&t].unify.clone() {
            g.table.union(a, b);
        }
    }
    // Every corner of a triangle being cut is named, so it can go onto an
    // edge when its triangle turns out to be a needle.
    for &t in &work {
        for v in tris[t as usize] {
            g.table.id(&geo, Key::Vertex(v));
        }
    }

    // Round every class representative to f32; bitwise-equal positions
    // are one vertex.
    let mut vertex_of: Vec<u32> = vec![u32::MAX; g.table.len()];
    let mut new_vertices: Vec<Vec3> = Vec::new();
    let reps: Vec<u32> = (0..g.table.len() as u32).map(|i| g.table.find(i)).collect();
    let mut need: Vec<u32> = reps.clone();
    need.sort_unstable();
    need.dedup();
    let rounded: Vec<Vec3> = need
        .par_iter()
        .map(|&r| geo.round(&g.table.defs[r as usize]))
        .collect();
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for (&r, &p) in need.iter().zip(&rounded) {
        if !matches!(g.table.defs[r as usize], PointDef::Vertex(_)) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let mut grid = SnapGrid::around(snap, &soup.vertices, lo, hi);
    for (&r, &p) in need.iter().zip(&rounded) {
        let v = match g.table.defs[r as usize] {
            PointDef::Vertex(v) => v,
            _ => {
                let pos = |v: u32| match v.checked_sub(n_vertices) {
                    Some(i) => new_vertices[i as usize],
                    None => soup.vertices[v as usize],
                };
                match grid.find(p, pos) {
                    Some(v) => v,
                    None => {
                        let v = n_vertices + new_vertices.len() as u32;
                        new_vertices.push(p);
                        grid.insert(v, p);
                        v
                    }
                }
            }
        };
        vertex_of[r as usize] = v;
    }
    soup.vertices.extend_from_slice(&new_vertices);
    let state = CutState {
        geo: Geo {
            verts: &soup.vertices,
        },
        tris,
        parent: &soup.parent,
        input: &soup.input,
        table: &g.table,
        reps: &reps,
        vertex_of: &vertex_of,
        arranged: &arranged,
        partners: &g.partners,
        snap,
    };
    let cuts = cut_inputs(&state, &mut g.registry, &work);
    let pieces: Vec<Pieces> = cuts
        .par_iter()
        .map(|(t, input)| {
            retriangulate(&state.geo, input).map_err(|e| ResolveError::Triangulation {
                triangle: soup.parent[*t as usize],
                message: format!("{e:?}"),
            })
        })
        .collect::<Result<_, _>>()?;
    let cut: Vec<u32> = cuts.iter().map(|(t, _)| *t).collect();

    // The new soup: untouched triangles as they were, the rest by pieces.
    let mut by_tri: FxMap<u32, &Pieces> = FxMap::default();
    for (&t, p) in cut.iter().zip(&pieces) {
        by_tri.insert(t, p);
    }
    let mut outcome = RoundOutcome::default();
    let mut triangles = Vec::with_capacity(soup.triangles.len() + pieces.len());
    let mut parent = Vec::with_capacity(triangles.capacity());
    let mut seen: std::collections::HashSet<[u32; 3]> = std::collections::HashSet::new();
    for (t, &tri) in soup.triangles.iter().enumerate() {
        let p = soup.parent[t];
        match by_tri.get(&(t as u32)) {
            None => {
                // A triangle of a pair that could not be cut (it would have
                // to be degenerate) stays, and is checked again.
                if g.interior.contains_key(&(t as u32)) {
                    outcome.dirty.push(triangles.len() as u32);
                }
                triangles.push(tri);
                parent.push(p);
            }
            Some(ps) => {
                outcome.merged += ps.dropped;
                for &piece in &ps.triangles {
                    let mut key = piece;
                    key.sort_unstable();
                    if !seen.insert(key) {
                        outcome.merged += 1;
                        continue;
                    }
                    outcome.dirty.push(triangles.len() as u32);
                    triangles.push(piece);
                    parent.push(p);
                }
            }
        }
    }
    soup.triangles = triangles;
    soup.parent = parent;
    Ok(outcome)
}
