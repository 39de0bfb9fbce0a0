//! Wavefront OBJ input through `tobj` (polygons fan-triangulated, CRLF
//! accepted), into a multi-index [`MeshData`].
//!
//! `tobj` does not report line numbers, so on a failure (or on a non-finite
//! coordinate, which `tobj` accepts) a small diagnostic scan of the text finds
//! the first offending line and the error names it.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::error::SceneError;

/// A mesh in its local frame, with separate index triples per attribute (as
/// in OBJ: a position can carry different normals on different faces).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Local positions.
    pub positions: Vec<Vec3>,
    /// Triangles as position indices (counter-clockwise = front).
    pub triangles: Vec<[u32; 3]>,
    /// Normals and their per-triangle index triples, when every face has them.
    pub normals: Option<(Vec<Vec3>, Vec<[u32; 3]>)>,
    /// Texture coordinates and their per-triangle index triples, when every face has them.
    pub uvs: Option<(Vec<Vec2>, Vec<[u32; 3]>)>,
}

/// A single-index mesh: one position (and optionally normal/uv) per vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlatMesh {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Normals (same length as `positions`), if requested and present.
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates (same length as `positions`), if requested and present.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

impl MeshData {
    /// A mesh whose normals (if any) share the position indices.
    pub fn single_index(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        normals: Option<Vec<Vec3>>,
    ) -> MeshData {
        let normals = normals.map(|n| (n, triangles.clone()));
        MeshData {
            positions,
            triangles,
            normals,
            uvs: None,
        }
    }

    /// Local axis-aligned bounds `(min, max)` of the referenced positions
    /// (`None` for an empty mesh).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.triangles.iter().flatten();
        let first = self.positions[*it.next()? as usize];
        Some(it.fold((first, first), |(lo, hi), &i| {
            let p = self.positions[i as usize];
            (lo.min(p), hi.max(p))
        }))
    }

    /// Convert to one index per vertex. Without attributes the positions keep
    /// their indices; with attributes every distinct (position, normal, uv)
    /// combination becomes a vertex, in order of first use.
    pub fn flatten(&self, keep_normals: bool, keep_uvs: bool) -> FlatMesh {
        let normals = self.normals.as_ref().filter(|_| keep_normals);
        let uvs = self.uvs.as_ref().filter(|_| keep_uvs);
        if normals.is_none() && uvs.is_none() {
            return FlatMesh {
                positions: self.positions.clone(),
                normals: None,
                uvs: None,
                triangles: self.triangles.clone(),
            };
        }
        let mut map = std::collections::HashMap::new();
        let mut out = FlatMesh {
            normals: normals.map(|_| Vec::new()),
            uvs: uvs.map(|_| Vec::new()),
            ..FlatMesh::default()
        };
        for (t, tri) in self.triangles.iter().enumerate() {
            let mut new_tri = [0u32; 3];
            for k in 0..3 {
                let p = tri[k];
                let n = normals.map_or(u32::MAX, |(_, idx)| idx[t][k]);
                let u = uvs.map_or(u32::MAX, |(_, idx)| idx[t][k]);
                let next = out.positions.len() as u32;
                let v = *map.entry((p, n, u)).or_insert_with(|| {
                    out.positions.push(self.positions[p as usize]);
                    if let (Some(list), Some((values, _))) = (out.normals.as_mut(), normals) {
                        list.push(values[n as usize]);
                    }
                    if let (Some(list), Some((values, _))) = (out.uvs.as_mut(), uvs) {
                        list.push(values[u as usize]);
                    }
                    next
                });
                new_tri[k] = v;
            }
            out.triangles.push(new_tri);
        }
        out
    }
}

/// Load an OBJ file: all its groups/objects are concatenated into one mesh.
pub fn load_obj(path: &Path) -> Result<MeshData, SceneError> {
    let bytes = std::fs::read(path).map_err(|e| SceneError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    parse_obj_bytes(&bytes, path)
}

/// Parse OBJ text already in memory; `path` is only used in error messages.
pub fn parse_obj_bytes(bytes: &[u8], path: &Path) -> Result<MeshData, SceneError> {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    if let Some(e) = find_error(bytes, path) {
        return Err(e);
    }
    let mut reader = Cursor::new(bytes);
    let result = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match result {
        Ok((models, _materials)) => models,
        Err(e) => return Err(diagnose(bytes, path, Some(e.to_string()))),
    };

    let mut mesh = MeshData::default();
    let mut normals: Option<(Vec<Vec3>, Vec<[u32; 3]>)> = Some(Default::default());
    let mut uvs: Option<(Vec<Vec2>, Vec<[u32; 3]>)> = Some(Default::default());
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        for p in m.positions.chunks_exact(3) {
            mesh.positions.push(Vec3::new(p[0], p[1], p[2]));
        }
        let tris = m.indices.len() / 3;
        for t in m.indices.chunks_exact(3) {
            mesh.triangles.push([base + t[0], base + t[1], base + t[2]]);
        }
        // Attributes are kept only when every face of every model has them.
        if m.normal_indices.len() == m.indices.len() && !m.normals.is_empty() {
            if let Some((values, idx)) = normals.as_mut() {
                let nb = values.len() as u32;
                values.extend(
                    m.normals
                        .chunks_exact(3)
                        .map(|n| Vec3::new(n[0], n[1], n[2])),
                );
                idx.extend(
                    m.normal_indices
                        .chunks_exact(3)
                        .map(|t| [nb + t[0], nb + t[1], nb + t[2]]),
                );
            }
        } else if tris > 0 {
            normals = None;
        }
        if m.texcoord_indices.len() == m.indices.len() && !m.texcoords.is_empty() {
            if let Some((values, idx)) = uvs.as_mut() {
                let ub = values.len() as u32;
                values.extend(m.texcoords.chunks_exact(2).map(|u| Vec2::new(u[0], u[1])));
                idx.extend(
                    m.texcoord_indices
                        .chunks_exact(3)
                        .map(|t| [ub + t[0], ub + t[1], ub + t[2]]),
                );
            }
        } else if tris > 0 {
            uvs = None;
        }
    }
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        return Err(diagnose(bytes, path, None));
    }
    if mesh.triangles.is_empty() {
        return Err(SceneError::ObjParse {
            path: path.to_path_buf(),
            line: None,
            message: "no triangles".into(),
        });
    }
    mesh.normals = normals.filter(|(v, _)| !v.is_empty());
    mesh.uvs = uvs.filter(|(v, _)| !v.is_empty());
    Ok(mesh)
}

/// Find the first offending line of an OBJ text; `fallback` is tobj's message.
/// The error to report for an OBJ text tobj rejected: the first problem the
/// text check finds, else tobj's own message.
fn diagnose(bytes: &[u8], path: &Path, fallback: Option<String>) -> SceneError {
    find_error(bytes, path).unwrap_or_else(|| SceneError::ObjParse {
        path: path.to_path_buf(),
        line: None,
        message: fallback.unwrap_or_else(|| "malformed OBJ".into()),
    })
}

/// Checks the OBJ text line by line (numbers parse and are finite, every
/// face index — absolute or relative — names an existing element) and
/// returns the first problem with its line. Run before tobj, which does not
/// check indices (an out-of-range relative index overflows inside it).
fn find_error(bytes: &[u8], path: &Path) -> Option<SceneError> {
    let text = String::from_utf8_lossy(bytes);
    let path: PathBuf = path.to_path_buf();
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    // Positive indices may legally point forward; check them at the end.
    let mut forward: Vec<(usize, &'static str, i64)> = Vec::new();
    for (no, raw) in text.lines().enumerate() {
        let line = no + 1;
        let mut words = raw.split_whitespace();
        let Some(tag) = words.next() else { continue };
        let want = match tag {
            "v" => 3,
            "vn" => 3,
            "vt" => 1,
            "f" => 0,
            _ => continue,
        };
        if want > 0 {
            let vals: Vec<&str> = words.collect();
            if vals.len() < want {
                return Some(SceneError::ObjParse {
                    path,
                    line: Some(line),
                    message: format!("`{tag}` needs {want} numbers, found {}", vals.len()),
                });
            }
            for s in vals.iter().take(if tag == "vt" { 1 } else { 3 }) {
                match s.parse::<f32>() {
                    Ok(x) if x.is_finite() => {}
                    Ok(_) if tag == "v" => {
                        return Some(SceneError::NonFiniteCoordinate {
                            path,
                            line,
                            vertex: nv as u32,
                        });
                    }
                    Ok(_) => {
                        return Some(SceneError::ObjParse {
                            path,
                            line: Some(line),
                            message: format!("non-finite `{tag}` value {s:?}"),
                        });
                    }
                    Err(_) => {
                        return Some(SceneError::ObjParse {
                            path,
                            line: Some(line),
                            message: format!("cannot parse {s:?} as a number"),
                        });
                    }
                }
            }
            match tag {
                "v" => nv += 1,
                "vt" => nt += 1,
                _ => nn += 1,
            }
            continue;
        }
        for corner in words {
            for (slot, part) in corner.split('/').enumerate() {
                if part.is_empty() && slot > 0 {
                    continue;
                }
                let (kind, count) = match slot {
                    0 => ("position", nv),
                    1 => ("texture coordinate", nt),
                    2 => ("normal", nn),
                    _ => {
                        return Some(SceneError::ObjParse {
                            path,
                            line: Some(line),
                            message: format!("bad face corner {corner:?}"),
                        });
                    }
                };
                let Ok(i) = part.parse::<i64>() else {
                    return Some(SceneError::ObjParse {
                        path,
                        line: Some(line),
                        message: format!("bad face corner {corner:?}"),
                    });
                };
                if i == 0 || (i < 0 && i.unsigned_abs() > count as u64) {
                    return Some(SceneError::IndexOutOfRange {
                        path,
                        line,
                        kind,
                        index: i,
                        count: count as usize,
                    });
                }
                if i > 0 {
                    forward.push((line, kind, i));
                }
            }
        }
    }
    for (line, kind, i) in forward {
        let count = match kind {
            "position" => nv,
            "texture coordinate" => nt,
            _ => nn,
        };
        if i > count {
            return Some(SceneError::IndexOutOfRange {
                path,
                line,
                kind,
                index: i,
                count: count as usize,
            });
        }
    }
    None
}
