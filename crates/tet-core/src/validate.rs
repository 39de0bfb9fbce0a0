//! [`TetMesh::validate`](crate::TetMesh::validate): every invariant of the
//! canonical mesh, checked exactly, with the first violation reported by
//! element.

use crate::error::MeshError;
use crate::link::{LinkKind, MAX_TETS};
use crate::mesh::{FaceSide, TetMesh, face_key, same_cyclic_order, sorted_faces};
use crate::predicates::orient3d_f32;

pub(crate) fn validate(m: &TetMesh) -> Result<(), MeshError> {
    check_counts(m)?;
    check_points(m)?;
    check_tets(m)?;
    check_links(m)?;
    check_constrained_table(m)?;
    check_face_manifold(m)?;
    check_attributes(m)
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
    match m.points.iter().position(|p| !p.is_finite()) {
        Some(i) => Err(MeshError::NonFinitePoint { point: i as u32 }),
        None => Ok(()),
    }
}

fn check_tets(m: &TetMesh) -> Result<(), MeshError> {
    for (t, tet) in m.tets.iter().enumerate() {
        let t = t as u32;
        for (slot, &v) in tet.iter().enumerate() {
            if v as usize >= m.points.len() {
                return Err(MeshError::VertexOutOfBounds {
                    tet: t,
                    slot: slot as u8,
                    vertex: v,
                    points: m.points.len(),
                });
            }
            if tet[..slot].contains(&v) {
                return Err(MeshError::RepeatedVertex { tet: t, vertex: v });
            }
        }
        let [a, b, c, d] = m.tet_points(t);
        let o = orient3d_f32(a, b, c, d);
        if o <= 0.0 {
            return Err(MeshError::NotPositive {
                tet: t,
                orientation: o,
            });
        }
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
    Ok(())
}
