//! [`TetMesh::validate`](crate::TetMesh::validate): every invariant of the
//! canonical mesh, checked exactly, with the first violation reported by
//! element.
//!
//! [`TetMesh::validate_construction`] is the same validator for a mesh
//! whose tets are already known to be positively oriented (a builder that
//! decided orientation exactly on the final coordinates): every other
//! invariant, in linear time. Its per-element checks are public so that a
//! builder can run them in parallel ([`TetMesh::check_sizes`],
//! [`TetMesh::check_point`], [`TetMesh::check_tet_vertices`],
//! [`TetMesh::check_links_upward`], [`TetMesh::check_constrained_face`],
//! [`TetMesh::face_class_key`], [`TetMesh::check_attributes`]).

use crate::error::MeshError;
use crate::link::{LinkKind, MAX_TETS};
use crate::mesh::{FaceSide, TetMesh, face_key, same_cyclic_order, sorted_faces};
use crate::predicates::orient3d_f32;

pub(crate) fn validate(m: &TetMesh) -> Result<(), MeshError> {
    m.check_sizes()?;
    check_points(m)?;
    check_tets(m)?;
    check_links(m)?;
    check_constrained_table(m)?;
    check_face_manifold(m)?;
    m.check_attributes()
}

fn check_counts(m: &TetMesh) -> Result<(), MeshError> {
    for (what, count) in [
        ("tets", m.tets.len()),
        ("constrained faces", m.constrained.len()),
    ] {
        if count >= MAX_TETS as usize {
            return Err(MeshError::TooMany {
                what,
                count,
                limit: MAX_TETS as usize - 1,
            });
        }
    }
    if m.points.len() > u32::MAX as usize {
        return Err(MeshError::TooMany {
            what: "points",
            count: m.points.len(),
            limit: u32::MAX as usize,
        });
    }
    if m.neighbors.len() != m.tets.len() {
        return Err(MeshError::LengthMismatch {
            array: "neighbors",
            actual: m.neighbors.len(),
            expected: m.tets.len(),
        });
    }
    Ok(())
}

fn check_points(m: &TetMesh) -> Result<(), MeshError> {
    (0..m.points.len()).try_for_each(|i| m.check_point(i))
}

fn check_tets(m: &TetMesh) -> Result<(), MeshError> {
    for t in 0..m.tets.len() as u32 {
        m.check_tet_vertices(t)?;
        m.check_tet_orientation(t)?;
    }
    Ok(())
}

fn same_set(a: [u32; 3], b: [u32; 3]) -> bool {
    face_key(a) == face_key(b)
}

fn check_links(m: &TetMesh) -> Result<(), MeshError> {
    for (t, links) in m.neighbors.iter().enumerate() {
        let t = t as u32;
        for (k, link) in links.iter().enumerate() {
            let face = k as u8;
            match link.kind() {
                LinkKind::Boundary => {}
                LinkKind::Tet(n) => {
                    if n as usize >= m.tets.len() {
                        return Err(MeshError::NeighborOutOfBounds {
                            tet: t,
                            face,
                            neighbor: n,
                            tets: m.tets.len(),
                        });
                    }
                    if !same_set(m.face_vertices(t, k), shared_or_empty(m, n, t)) {
                        return Err(MeshError::SharedFaceMismatch {
                            tet: t,
                            face,
                            neighbor: n,
                        });
                    }
                    let j = m.face_towards(n, t).expect("checked by shared face");
                    if m.neighbors[n as usize][j].as_tet() != Some(t) {
                        return Err(MeshError::NeighborNotSymmetric {
                            tet: t,
                            face,
                            neighbor: n,
                        });
                    }
                }
                LinkKind::Constrained(c) => m.check_constrained_link(t, k, c)?,
            }
        }
    }
    Ok(())
}

/// The three vertices `n` shares with `t`, or an impossible triple.
fn shared_or_empty(m: &TetMesh, n: u32, t: u32) -> [u32; 3] {
    match m.face_towards(n, t) {
        Some(j) => m.face_vertices(n, j),
        None => [u32::MAX; 3],
    }
}

fn check_constrained_table(m: &TetMesh) -> Result<(), MeshError> {
    (0..m.constrained.len()).try_for_each(|c| m.check_constrained_face(c))
}

impl TetMesh {
    /// Checks every invariant; the error names the first offending element.
    pub fn validate(&self) -> Result<(), MeshError> {
        validate(self)
    }

    /// Checks the array sizes: fewer tets and constrained faces than
    /// [`MAX_TETS`], point ids that fit a `u32`, one link row per tet.
    pub fn check_sizes(&self) -> Result<(), MeshError> {
        check_counts(self)
    }

    /// Checks that point `i` is finite (`i` must be in range).
    pub fn check_point(&self, i: usize) -> Result<(), MeshError> {
        if self.points[i].is_finite() {
            Ok(())
        } else {
            Err(MeshError::NonFinitePoint { point: i as u32 })
        }
    }

    /// Checks that tet `t` names four distinct points in range (`t` must
    /// be in range).
    pub fn check_tet_vertices(&self, t: u32) -> Result<(), MeshError> {
        let tet = self.tets[t as usize];
        for (slot, &v) in tet.iter().enumerate() {
            if v as usize >= self.points.len() {
                return Err(MeshError::VertexOutOfBounds {
                    tet: t,
                    slot: slot as u8,
                    vertex: v,
                    points: self.points.len(),
                });
            }
            if tet[..slot].contains(&v) {
                return Err(MeshError::RepeatedVertex { tet: t, vertex: v });
            }
        }
        Ok(())
    }

    /// Checks that tet `t` is positively oriented, exactly, on the stored
    /// f32 points (its vertices must have passed
    /// [`TetMesh::check_tet_vertices`]).
    pub fn check_tet_orientation(&self, t: u32) -> Result<(), MeshError> {
        let [a, b, c, d] = self.tet_points(t);
        let o = orient3d_f32(a, b, c, d);
        if o <= 0.0 {
            return Err(MeshError::NotPositive {
                tet: t,
                orientation: o,
            });
        }
        Ok(())
    }

    /// Checks the links of tet `t` from its side: a tet link to `n > t`
    /// names a tet that has exactly the face's three vertices and links
    /// back through the face opposite its fourth; a constrained link names
    /// a table entry with `(t, face)` as one side. Returns (tet links of
    /// `t`, links to a higher tet checked). Links to a lower tet are
    /// checked from that tet's side: when the sums over all tets satisfy
    /// `tet links == 2 × checked`, every link is answered (the checked
    /// pairs use disjoint slots); otherwise [`TetMesh::unanswered_link`]
    /// names one that is not. Tet vertices must have been checked.
    pub fn check_links_upward(&self, t: u32) -> Result<(usize, usize), MeshError> {
        let m = self;
        let a = m.tets[t as usize];
        let (mut tet_links, mut pairs) = (0, 0);
        for (k, link) in m.neighbors[t as usize].iter().enumerate() {
            let face = k as u8;
            match link.kind() {
                LinkKind::Boundary => {}
                LinkKind::Tet(n) => {
                    tet_links += 1;
                    if n <= t {
                        if n == t {
                            return Err(MeshError::SharedFaceMismatch {
                                tet: t,
                                face,
                                neighbor: n,
                            });
                        }
                        // Answered by the check from n's side.
                        continue;
                    }
                    pairs += 1;
                    let Some(&b) = m.tets.get(n as usize) else {
                        return Err(MeshError::NeighborOutOfBounds {
                            tet: t,
                            face,
                            neighbor: n,
                            tets: m.tets.len(),
                        });
                    };
                    let shares = !b.contains(&a[k]) && (0..4).all(|i| i == k || b.contains(&a[i]));
                    let j = (0..4).find(|&j| !a.contains(&b[j]));
                    let Some(j) = j.filter(|_| shares) else {
                        return Err(MeshError::SharedFaceMismatch {
                            tet: t,
                            face,
                            neighbor: n,
                        });
                    };
                    if m.neighbors[n as usize][j].as_tet() != Some(t) {
                        return Err(MeshError::NeighborNotSymmetric {
                            tet: t,
                            face,
                            neighbor: n,
                        });
                    }
                }
                LinkKind::Constrained(c) => m.check_constrained_link(t, k, c)?,
            }
        }
        Ok((tet_links, pairs))
    }

    /// The error for a tet link `n → t` (`t < n`) that tet `t` does not
    /// answer, when [`TetMesh::check_links_upward`]'s counts say one exists.
    pub fn unanswered_link(&self) -> MeshError {
        let m = self;
        for (n, links) in m.neighbors.iter().enumerate() {
            for (j, l) in links.iter().enumerate() {
                if let Some(t) = l.as_tet()
                    && (t as usize) < n
                    && (m.tets[t as usize].contains(&m.tets[n][j])
                        || m.face_towards(t, n as u32)
                            .is_none_or(|k| m.neighbors[t as usize][k].as_tet() != Some(n as u32)))
                {
                    return MeshError::NeighborNotSymmetric {
                        tet: n as u32,
                        face: j as u8,
                        neighbor: t,
                    };
                }
            }
        }
        MeshError::NeighborNotSymmetric {
            tet: 0,
            face: 0,
            neighbor: 0,
        }
    }

    /// The vertex key of face `k` of tet `t` if that face represents its
    /// *class*, else `None`. Given checked links and constrained-face table,
    /// every face belongs to exactly one class — a linked pair of tets
    /// (represented from its lower tet), a constrained face (from its front
    /// side, or back when one-sided) or a one-sided mesh-boundary face —
    /// and the mesh is face-manifold iff no two classes have the same key.
    pub fn face_class_key(&self, t: usize, k: usize) -> Option<[u32; 3]> {
        let represents = match self.neighbors[t][k].kind() {
            LinkKind::Tet(n) => (t as u32) < n,
            LinkKind::Boundary => true,
            LinkKind::Constrained(c) => {
                let cf = &self.constrained[c as usize];
                let first = if cf.front.exists() { cf.front } else { cf.back };
                first.tet == t as u32 && first.face == k as u32
            }
        };
        represents.then(|| face_key(self.face_vertices(t as u32, k)))
    }

    /// The error for two face classes with the same vertex `key` (see
    /// [`TetMesh::face_class_key`]), naming one tet with that face.
    pub fn face_class_error(&self, key: [u32; 3]) -> MeshError {
        let (t, k) = (0..self.tets.len())
            .flat_map(|t| (0..4).map(move |k| (t, k)))
            .find(|&(t, k)| face_key(self.face_vertices(t as u32, k)) == key)
            .unwrap_or((0, 0));
        MeshError::FaceNotManifold {
            tet: t as u32,
            face: k as u8,
            vertices: key,
            detail: "shared by tets that are not linked across it",
        }
    }

    /// Checks the attribute arrays' lengths (normals and uvs per point,
    /// materials per scene triangle) and the scalar field
    /// ([`crate::fields::ScalarField::check`]).
    pub fn check_attributes(&self) -> Result<(), MeshError> {
        check_attributes(self)
    }

    /// Every invariant of [`TetMesh::validate`] except tet orientation, in
    /// linear time (plus a sort of one face key per face class): for a mesh
    /// whose orientation has been decided elsewhere, exactly on the stored
    /// points. A builder may run the same per-element checks in parallel.
    pub fn validate_construction(&self) -> Result<(), MeshError> {
        self.check_sizes()?;
        check_points(self)?;
        (0..self.tets.len() as u32).try_for_each(|t| self.check_tet_vertices(t))?;
        let (mut tet_links, mut pairs) = (0, 0);
        for t in 0..self.tets.len() as u32 {
            let (l, p) = self.check_links_upward(t)?;
            tet_links += l;
            pairs += p;
        }
        if tet_links != 2 * pairs {
            return Err(self.unanswered_link());
        }
        check_constrained_table(self)?;
        let mut keys: Vec<[u32; 3]> = (0..self.tets.len())
            .flat_map(|t| (0..4).filter_map(move |k| self.face_class_key(t, k)))
            .collect();
        keys.sort_unstable();
        if let Some(w) = keys.windows(2).find(|w| w[0] == w[1]) {
            return Err(self.face_class_error(w[0]));
        }
        self.check_attributes()
    }

    /// Checks that face `k` of tet `t`, linked to constrained face `c`,
    /// names an existing table entry that has `(t, k)` as one of its sides,
    /// as [`TetMesh::validate`] does; shared with builders that check links
    /// their own way.
    pub fn check_constrained_link(&self, t: u32, k: usize, c: u32) -> Result<(), MeshError> {
        let Some(cf) = self.constrained.get(c as usize) else {
            return Err(MeshError::ConstrainedOutOfBounds {
                tet: t,
                face: k as u8,
                index: c,
                count: self.constrained.len(),
            });
        };
        let me = FaceSide {
            tet: t,
            face: k as u32,
        };
        if cf.front != me && cf.back != me {
            return Err(MeshError::ConstrainedBackReference {
                index: c,
                detail: format!("tet {t} face {k} links to it but is neither side"),
            });
        }
        Ok(())
    }

    /// Checks entry `c` of the constrained-face table exactly as
    /// [`TetMesh::validate`] does (triangle id, sides in bounds and linking
    /// back, same vertices, winding agreeing with front/back). Public so
    /// that a builder can check the table in parallel, entry by entry,
    /// without re-implementing the rules. `c` must be below
    /// `self.constrained.len()`.
    pub fn check_constrained_face(&self, c: usize) -> Result<(), MeshError> {
        let m = self;
        let cf = &m.constrained[c];
        let index = c as u32;
        let bad = |detail: String| Err(MeshError::ConstrainedBackReference { index, detail });
        if cf.triangle >= m.triangle_count {
            return bad(format!(
                "triangle id {} is not below the triangle count {}",
                cf.triangle, m.triangle_count
            ));
        }
        if !cf.front.exists() && !cf.back.exists() {
            return bad("has no tet on either side".into());
        }
        if cf.front.exists() && cf.front.tet == cf.back.tet {
            return bad(format!("tet {} is on both sides", cf.front.tet));
        }
        for (name, side, is_front) in [("front", cf.front, true), ("back", cf.back, false)] {
            if !side.exists() {
                continue;
            }
            if side.tet as usize >= m.tets.len() || side.face >= 4 {
                return bad(format!(
                    "{name} side (tet {}, face {}) is out of bounds",
                    side.tet, side.face
                ));
            }
            let link = m.neighbors[side.tet as usize][side.face as usize];
            if link.as_constrained() != Some(index) {
                return bad(format!(
                    "{name} tet {} face {} links to {link:?}, not back to it",
                    side.tet, side.face
                ));
            }
            let outward = m.face_vertices(side.tet, side.face as usize);
            if !same_set(outward, cf.vertices) {
                return bad(format!(
                    "vertices {:?} differ from {name} tet {} face {} {:?}",
                    cf.vertices, side.tet, side.face, outward
                ));
            }
            // The triangle normal points out of the back tet and into the front one.
            if same_cyclic_order(cf.vertices, outward) == is_front {
                return bad(format!(
                    "tet {} is recorded as the {name} side but lies on the other side of the triangle's winding",
                    side.tet
                ));
            }
        }
        Ok(())
    }
}

/// Each face key appears at most twice; twice only between linked tets (or
/// across one constrained face); once only on the boundary.
fn check_face_manifold(m: &TetMesh) -> Result<(), MeshError> {
    let faces = sorted_faces(&m.tets);
    for run in faces.chunk_by(|a, b| a.0 == b.0) {
        let (key, t, f) = run[0];
        let err = |detail| MeshError::FaceNotManifold {
            tet: t,
            face: f,
            vertices: key,
            detail,
        };
        let link = m.neighbors[t as usize][f as usize];
        match run.len() {
            1 => {
                let one_sided = match link.kind() {
                    LinkKind::Boundary => true,
                    LinkKind::Constrained(c) => {
                        let cf = &m.constrained[c as usize];
                        !(cf.front.exists() && cf.back.exists())
                    }
                    LinkKind::Tet(_) => false,
                };
                if !one_sided {
                    return Err(err("face of one tet only but linked as interior"));
                }
            }
            2 => {
                let (_, u, _) = run[1];
                let linked = match link.kind() {
                    LinkKind::Tet(n) => n == u,
                    LinkKind::Constrained(c) => m.constrained[c as usize]
                        .other_side(t)
                        .is_some_and(|s| s.tet == u),
                    LinkKind::Boundary => false,
                };
                if !linked {
                    return Err(err("shared by two tets that are not linked across it"));
                }
            }
            _ => return Err(err("shared by more than two tets")),
        }
    }
    Ok(())
}

fn check_attributes(m: &TetMesh) -> Result<(), MeshError> {
    let a = &m.attributes;
    let n = m.points.len();
    let checks = [
        ("normals", a.normals.as_ref().map(Vec::len), n),
        ("uvs", a.uvs.as_ref().map(Vec::len), n),
        (
            "materials",
            a.materials.as_ref().map(Vec::len),
            m.triangle_count as usize,
        ),
    ];
    for (name, len, expected) in checks {
        if let Some(actual) = len
            && actual != expected
        {
            return Err(MeshError::AttributeLength {
                name,
                actual,
                expected,
            });
        }
    }
    if let Some(field) = &a.scalars {
        field.check(n)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::Link;
    use crate::synthetic::{GridSpec, kuhn_grid};

    #[test]
    fn construction_checks_agree_with_validate() {
        let m = kuhn_grid(&GridSpec {
            cells: [3, 2, 2],
            constrained_fraction: 0.3,
            seed: 4,
            ..GridSpec::default()
        });
        m.validate().unwrap();
        m.validate_construction().unwrap();
        // A one-sided link.
        let mut a = m.clone();
        let t = (0..a.tets.len())
            .find(|&t| a.neighbors[t].iter().any(|l| l.as_tet().is_some()))
            .unwrap();
        let k = (0..4)
            .find(|&k| a.neighbors[t][k].as_tet().is_some())
            .unwrap();
        a.neighbors[t][k] = Link::BOUNDARY;
        assert!(a.validate().is_err() && a.validate_construction().is_err());
        // An unlinked copy of a tet: only face manifoldness sees it.
        let mut b = m.clone();
        b.tets.push(b.tets[0]);
        b.neighbors.push([Link::BOUNDARY; 4]);
        assert!(matches!(
            b.validate_construction(),
            Err(crate::MeshError::FaceNotManifold { .. })
        ));
        // Orientation is the one check left out.
        let mut c = m.clone();
        c.tets[0].swap(0, 1);
        assert!(matches!(
            c.validate(),
            Err(crate::MeshError::NotPositive { tet: 0, .. })
        ));
        assert!(c.check_tet_orientation(0).is_err());
    }
}
