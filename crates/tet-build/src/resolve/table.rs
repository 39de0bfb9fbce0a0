//! One round's table of points: named points get dense ids, with their
//! construction and approximate coordinates; a union–find merges ids that
//! turned out to be the same point.

use glam::DVec3;

use super::points::{Geo, Key, PointDef};

/// The hash map of [`crate::clean`] (a multiply-rotate hash for small integer keys).
pub(crate) use crate::clean::FxMap;

/// Named points of one round.
#[derive(Default)]
pub(crate) struct PointTable {
    /// Construction of each point id.
    pub defs: Vec<PointDef>,
    /// Its approximate position.
    pub approx: Vec<DVec3>,
    /// Its name.
    pub keys: Vec<Key>,
    ids: FxMap<Key, u32>,
    parent: Vec<u32>,
}

impl PointTable {
    /// The id of the point named `key`, adding it if new.
    pub fn id(&mut self, geo: &Geo, key: Key) -> u32 {
        if let Some(&id) = self.ids.get(&key) {
            return id;
        }
        let def = geo.def_of(&key);
        self.insert(key, def, geo.approx(&def))
    }

    /// Adds a point with a known construction (its key must be new).
    pub fn insert(&mut self, key: Key, def: PointDef, approx: DVec3) -> u32 {
        let id = self.defs.len() as u32;
        self.defs.push(def);
        self.approx.push(approx);
        self.keys.push(key);
        self.parent.push(id);
        self.ids.insert(key, id);
        id
    }

    /// The id of `key`, if named already.
    pub fn get(&self, key: &Key) -> Option<u32> {
        self.ids.get(key).copied()
    }

    /// The soup vertex `id` is, if it is one (by construction).
    pub fn vertex_of_def(&self, id: u32) -> Option<u32> {
        match self.defs[id as usize] {
            PointDef::Vertex(v) => Some(v),
            _ => None,
        }
    }

    /// Number of ids.
    pub fn len(&self) -> usize {
        self.defs.len()
    }

    /// The representative of `id`'s class.
    pub fn find(&mut self, mut id: u32) -> u32 {
        while self.parent[id as usize] != id {
            let up = self.parent[self.parent[id as usize] as usize];
            self.parent[id as usize] = up;
            id = up;
        }
        id
    }

    /// Declares `a` and `b` the same point. A soup vertex, if the class has
    /// one, stays the representative; otherwise the lower id.
    pub fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return;
        }
        let vertex = |r: u32| matches!(self.defs[r as usize], PointDef::Vertex(_));
        let keep_a = match (vertex(ra), vertex(rb)) {
            (true, false) => true,
            (false, true) => false,
            _ => ra < rb,
        };
        if keep_a {
            self.parent[rb as usize] = ra;
        } else {
            self.parent[ra as usize] = rb;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn union_keeps_the_vertex_as_representative() {
        // Edge 0-1 and edge 2-3 cross at vertex 4; so does edge 2-3 with
        // the plane y = 0 of triangle 0-1-5.
        let verts = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let geo = Geo { verts: &verts };
        let mut t = PointTable::default();
        let e = t.id(&geo, Key::EdgeEdge([0, 1], [2, 3]));
        let v = t.id(&geo, Key::Vertex(4));
        let w = t.id(&geo, Key::EdgeTriangle([2, 3], [0, 1, 5]));
        assert_eq!(t.approx[e as usize], glam::DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(t.approx[w as usize], glam::DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(t.id(&geo, Key::Vertex(4)), v);
        t.union(e, w);
        t.union(w, v);
        assert_eq!(t.find(e), v);
        assert_eq!(t.find(w), v);
        assert_eq!(t.len(), 3);
    }
}
