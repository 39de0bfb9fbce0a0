//! Stage 5, assembly: neighbour links and the constrained-face table from
//! TetGen's tets ([`Assembly`]), then the vertex attributes.
//!
//! By default the neighbour links are TetGen's own (`-nn`: tet neighbours
//! and the two tets of every output face), so no face keys are sorted;
//! [`Assembly::SortFaceKeys`] runs [`TetMesh::assemble`] instead. Both give
//! the same mesh, field by field (tested on several scenes).
//!
//! **Normals at merged vertices**: the mesh stores one normal per point,
//! but a scene vertex merged from copies with different normals (a crease:
//! the corners of a flat-shaded box carry three face normals) has none that
//! is right for all its triangles, and keeping the first copy's normal would
//! bend the shading of every other face there. Such points get a zero
//! normal, which the tracers read as "no vertex normal": a triangle whose
//! three corners are all creases (a box face) is shaded with its geometric
//! normal, others interpolate only their smooth corners. Steiner points and
//! box corners also get zero normals. Exact per-corner shading needs
//! per-triangle corner normals in [`tet_core::mesh::Attributes`] (not there
//! yet); the conflicts are listed in
//! [`crate::clean::CleanReport::attribute_conflicts`].

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use tet_core::link::{Link, LinkKind, MAX_TETS};
use tet_core::mesh::{Attributes, ConstrainedFace, FaceSide, face_key};
use tet_core::{MeshError, TetMesh};

use super::faces::SceneFaces;
use super::options::Assembly;
use super::prepare::Cleaned;
use super::rounding::Rounded;
use crate::scene::Scene;

/// The mesh from TetGen's rounded output and the matched scene faces, by
/// `assembly`; `triangle_count` is the input scene's triangle count.
pub(super) fn assemble(
    rounded: Rounded,
    faces: &SceneFaces,
    assembly: Assembly,
    triangle_count: u32,
) -> Result<TetMesh, MeshError> {
    let Rounded {
        out, points, tets, ..
    } = rounded;
    let fast = match (assembly, &out.neighbors, &out.face_tets) {
        (Assembly::TetgenNeighbors, Some(neighbors), Some(face_tets)) => assemble_from_tetgen(
            points,
            tets,
            &TetgenAdjacency {
                tets: &out.tets,
                neighbors,
                face_tets,
            },
            &faces.face_of,
            &faces.triangles,
            triangle_count,
        )?,
        _ => Assembled::Unavailable(points, tets),
    };
    match fast {
        Assembled::Mesh(mesh) => Ok(mesh),
        Assembled::Unavailable(points, tets) => {
            TetMesh::assemble(points, tets, &faces.triangles, triangle_count)
        }
    }
}

/// Gives `mesh` the cleaned scene's normals and uvs: scene vertices are the
/// first points; box corners, Steiner points and creases (see the module
/// docs) get zero normals, and zero uvs. `scene` is the input scene.
pub(super) fn attach_attributes(mesh: &mut TetMesh, cleaned: &Cleaned, scene: &Scene) {
    let n_points = mesh.points.len();
    if let (Some(n), Some(input_normals)) = (&cleaned.scene.normals, &scene.normals) {
        let mut v = n.clone();
        v.resize(n_points, Vec3::ZERO);
        // A merged vertex whose copies carry different normals (a crease,
        // e.g. a flat-shaded box corner) has no single shading normal.
        for &(dropped, kept) in &cleaned.map.report.attribute_conflicts {
            if input_normals[dropped as usize] != input_normals[kept as usize] {
                let out = cleaned.map.vertex_map[kept as usize];
                if let Some(slot) = v.get_mut(out as usize) {
                    *slot = Vec3::ZERO;
                }
            }
        }
        mesh.attributes.normals = Some(v);
    }
    if let Some(uv) = &cleaned.scene.uvs {
        let mut v = uv.clone();
        v.resize(n_points, Vec2::ZERO);
        mesh.attributes.uvs = Some(v);
    }
}

/// What [`assemble_from_tetgen`] made.
enum Assembled {
    /// The mesh.
    Mesh(TetMesh),
    /// TetGen's adjacency cannot place some constrained face: the inputs,
    /// handed back for [`TetMesh::assemble`].
    Unavailable(Vec<Vec3>, Vec<[u32; 4]>),
}

/// TetGen's adjacency output (`-nn`), in TetGen's tet order and slot order.
struct TetgenAdjacency<'a> {
    /// TetGen's tets, before orientation.
    tets: &'a [[u32; 4]],
    /// Neighbour `k` of each tet (opposite TetGen slot `k`), `-1` = hull.
    neighbors: &'a [[i32; 4]],
    /// TetGen's `adjtetlist`: the two tets of each output face, `-1` = none
    /// (not trusted: see [`assemble_from_tetgen`]).
    face_tets: &'a [[i32; 2]],
}

/// Builds exactly the mesh [`TetMesh::assemble`] would build from
/// `(points, tets, triangles)`, but from TetGen's own adjacency instead of
/// sorting face keys: tet links are TetGen's neighbours (slots 0 and 1
/// swapped where [`super::rounding::orient_tets`] flipped the tet), and constrained face `c`
/// (scene triangle `triangles[c]`, TetGen face `face_of[c]`) lies on a tet
/// TetGen lists for that face (checked to have the face) and on that tet's
/// neighbour across it. [`Assembled::Unavailable`] when TetGen names no tet with some face
/// (the caller then falls back to [`TetMesh::assemble`]). Where TetGen's
/// neighbour list disagrees with its faces the result is an error, never a
/// different mesh; face manifoldness (which makes the two identical) is
/// checked by either [`super::Validation`].
fn assemble_from_tetgen(
    points: Vec<Vec3>,
    tets: Vec<[u32; 4]>,
    adj: &TetgenAdjacency<'_>,
    face_of: &[u32],
    triangles: &[([u32; 3], u32)],
    triangle_count: u32,
) -> Result<Assembled, MeshError> {
    let nt = tets.len();
    for (what, count) in [("tets", nt), ("constrained faces", triangles.len())] {
        if count >= MAX_TETS as usize {
            return Err(MeshError::TooMany {
                what,
                count,
                limit: MAX_TETS as usize - 1,
            });
        }
    }
    for (array, actual) in [
        ("TetGen tets", adj.tets.len()),
        ("TetGen neighbours", adj.neighbors.len()),
    ] {
        if actual != nt {
            return Err(MeshError::LengthMismatch {
                array,
                actual,
                expected: nt,
            });
        }
    }
    if face_of.len() != triangles.len() {
        return Err(MeshError::LengthMismatch {
            array: "constrained faces",
            actual: face_of.len(),
            expected: triangles.len(),
        });
    }
    let np = points.len();
    let mut neighbors: Vec<[Link; 4]> = tets
        .par_iter()
        .zip(adj.tets.par_iter().zip(adj.neighbors.par_iter()))
        .enumerate()
        .with_min_len(4096)
        .map(|(t, (tet, (raw, n)))| {
            let t = t as u32;
            for (slot, &v) in tet.iter().enumerate() {
                if v as usize >= np {
                    return Err(MeshError::VertexOutOfBounds {
                        tet: t,
                        slot: slot as u8,
                        vertex: v,
                        points: np,
                    });
                }
            }
            let mut n = *n;
            if tet != raw {
                n.swap(0, 1);
            }
            let mut links = [Link::BOUNDARY; 4];
            for (k, (&v, link)) in n.iter().zip(&mut links).enumerate() {
                *link = match v {
                    -1 => Link::BOUNDARY,
                    v if v >= 0 && (v as usize) < nt => Link::tet(v as u32),
                    v => {
                        return Err(MeshError::NeighborOutOfBounds {
                            tet: t,
                            face: k as u8,
                            neighbor: v as u32,
                            tets: nt,
                        });
                    }
                };
            }
            Ok(links)
        })
        .collect::<Result<_, _>>()?;

    // The slot of `tet` opposite the face `vertices`, if `tet` has that face.
    let opposite = |tet: [u32; 4], vertices: [u32; 3]| {
        let mut outside = (0..4).filter(|&i| !vertices.contains(&tet[i]));
        match (outside.next(), outside.next()) {
            (Some(k), None) => Some(k),
            _ => None,
        }
    };
    let mut constrained: Vec<ConstrainedFace> = Vec::with_capacity(triangles.len());
    for (c, (&(vertices, triangle), &f)) in triangles.iter().zip(face_of).enumerate() {
        let key = face_key(vertices);
        // One tet with this face: TetGen's `adjtetlist` entry, used only
        // after checking that the tet has the face (for a face on the convex
        // hull TetGen may report its internal hull tet's unset index).
        let has_face = |s: i32| {
            let t = u32::try_from(s).ok().filter(|&t| (t as usize) < nt)?;
            opposite(tets[t as usize], vertices).map(|k| (t, k))
        };
        let sides = adj.face_tets.get(f as usize).copied().unwrap_or([-1, -1]);
        let Some((t0, k0)) = has_face(sides[0]).or_else(|| has_face(sides[1])) else {
            return Ok(Assembled::Unavailable(points, tets));
        };
        // The other side is t0's neighbour across the face.
        let second = match neighbors[t0 as usize][k0].kind() {
            LinkKind::Boundary => None,
            LinkKind::Tet(n) => match opposite(tets[n as usize], vertices) {
                Some(k) => Some((n, k)),
                None => {
                    return Err(MeshError::SharedFaceMismatch {
                        tet: t0,
                        face: k0 as u8,
                        neighbor: n,
                    });
                }
            },
            LinkKind::Constrained(prev) => {
                return Err(MeshError::DuplicateTriangle {
                    first: constrained[prev as usize].triangle,
                    second: triangle,
                    vertices: key,
                });
            }
        };
        let mut cf = ConstrainedFace {
            triangle,
            vertices,
            front: FaceSide::NONE,
            back: FaceSide::NONE,
        };
        for (t, k) in std::iter::once((t0, k0)).chain(second) {
            let link = &mut neighbors[t as usize][k];
            if let Some(prev) = link.as_constrained() {
                return Err(MeshError::DuplicateTriangle {
                    first: constrained[prev as usize].triangle,
                    second: triangle,
                    vertices: key,
                });
            }
            *link = Link::constrained(c as u32);
            cf.attach_side(tets[t as usize], t, k);
        }
        constrained.push(cf);
    }
    Ok(Assembled::Mesh(TetMesh {
        points,
        tets,
        neighbors,
        constrained,
        triangle_count,
        attributes: Attributes::default(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetgen_adjacency_tolerates_garbage_face_tets_and_falls_back() {
        // Two tets sharing face (0,1,2); TetGen's raw order has tet 1
        // negatively oriented (slots 0/1 swapped by orient_tets).
        let points = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(0.2, 0.2, 1.0),
            Vec3::new(0.2, 0.2, -1.0),
        ];
        let raw = vec![[0, 1, 2, 3], [0, 1, 2, 4]];
        let p64: Vec<[f64; 3]> = points.iter().map(|p| p.as_dvec3().to_array()).collect();
        let (tets, bad) = crate::pipeline::rounding::orient_tets(&p64, &points, &raw);
        assert!(bad.is_empty());
        assert_eq!(tets[1], [1, 0, 2, 4]);
        // TetGen's neighbour k is opposite its own slot k.
        let neighbors = vec![[-1, -1, -1, 1], [-1, -1, -1, 0]];
        // Triangle 0 = the shared face, triangle 1 = a hull face of tet 0.
        let tris = vec![([0, 1, 2], 5), ([0, 3, 1], 6)];
        let reference = TetMesh::assemble(points.clone(), tets.clone(), &tris, 7).unwrap();
        for face_tets in [
            vec![[1, 0], [0, -1]],
            vec![[-146_509_888, 1], [i32::MAX, 0]],
            vec![[0, 77], [-1, 0]],
        ] {
            let adj = TetgenAdjacency {
                tets: &raw,
                neighbors: &neighbors,
                face_tets: &face_tets,
            };
            match assemble_from_tetgen(points.clone(), tets.clone(), &adj, &[0, 1], &tris, 7) {
                Ok(Assembled::Mesh(m)) => {
                    assert_eq!(m, reference, "{face_tets:?}");
                    crate::pipeline::validate::check_construction(&m).unwrap();
                }
                _ => panic!("{face_tets:?}"),
            }
        }
        // No listed tet has face 1: hand the inputs back for the fallback.
        let face_tets = vec![[0, 1], [1, -1]];
        let adj = TetgenAdjacency {
            tets: &raw,
            neighbors: &neighbors,
            face_tets: &face_tets,
        };
        match assemble_from_tetgen(points.clone(), tets.clone(), &adj, &[0, 1], &tris, 7) {
            Ok(Assembled::Unavailable(p, t)) => assert!(p == points && t == tets),
            _ => panic!("expected a fallback"),
        }
        // A neighbour list that disagrees with the faces is an error.
        let wrong = vec![[-1, -1, -1, -1], [-1, -1, -1, 0]];
        let face_tets = vec![[0, 1], [0, -1]];
        let adj = TetgenAdjacency {
            tets: &raw,
            neighbors: &wrong,
            face_tets: &face_tets,
        };
        let m = match assemble_from_tetgen(points.clone(), tets.clone(), &adj, &[0, 1], &tris, 7) {
            Ok(Assembled::Mesh(m)) => m,
            _ => panic!(),
        };
        assert!(
            crate::pipeline::validate::check_construction(&m).is_err() && m.validate().is_err()
        );
    }
}
