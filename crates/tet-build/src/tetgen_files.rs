//! TetGen's file formats: `.node`, `.ele`, `.face`, `.neigh` (import and
//! export), so meshes made elsewhere (TetGen's command line, TetWild, …) can
//! be traced and ours inspected with other tools.
//!
//! Formats (TetGen manual §5.2): `#` starts a comment; the first data line is
//! a header; each record starts with its index, and the first record's index
//! (0 or 1) fixes the numbering of all vertex references.
//!
//! | file     | header                                    | record                           |
//! |----------|-------------------------------------------|----------------------------------|
//! | `.node`  | `#points 3 #attributes markers(0/1)`      | `i x y z [attributes] [marker]`  |
//! | `.ele`   | `#tets 4 region-attribute(0/1)`           | `i v0 v1 v2 v3 [attribute]`      |
//! | `.face`  | `#faces markers(0/1)`                     | `i v0 v1 v2 [marker]`            |
//! | `.neigh` | `#tets 4`                                 | `i n0 n1 n2 n3` (`-1` = none)    |
//!
//! Point attributes carry a scalar field: [`to_tet_mesh`] makes each
//! attribute column one time step of a field named [`ATTRIBUTE_FIELD`]
//! (TetGen files name no field), and [`from_tet_mesh`] writes each step of
//! a mesh's field as a column.
//!
//! Face markers name constrained faces: [`to_tet_mesh`] turns every face
//! with marker `m > 0` into a constrained face of scene triangle `m - 1`
//! (the convention of our shim), and [`from_tet_mesh`] writes them so.
//! Writes are atomic (temporary file, then rename).

use std::fmt::Write as _;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use tet_core::{LinkKind, MeshError, TetMesh};
use thiserror::Error;

/// The contents of a set of TetGen files, 0-based.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetgenFiles {
    /// `.node` coordinates.
    pub points: Vec<[f64; 3]>,
    /// `.node` point attributes: one column per attribute, each with one
    /// value per point (empty when the file has none).
    pub point_attributes: Vec<Vec<f64>>,
    /// `.ele` tets (any orientation).
    pub tets: Vec<[u32; 4]>,
    /// `.face` faces.
    pub faces: Vec<[u32; 3]>,
    /// `.face` markers (one per face), when the file has them.
    pub face_markers: Option<Vec<i32>>,
    /// `.neigh` neighbours (`-1` = none; `k`-th opposite corner `k`), when read or wanted.
    pub neighbors: Option<Vec<[i32; 4]>>,
}

/// A failure to read, write or convert TetGen files; names file and line.
#[derive(Debug, Error)]
pub enum FilesError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: io::Error,
    },
    /// A line could not be parsed or is inconsistent.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 = end of file).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The files do not form a valid mesh.
    #[error("{0}")]
    Mesh(#[from] MeshError),
    /// A tet is flat in the file's own f64 coordinates, or becomes flat or
    /// inverted when they are rounded to f32.
    #[error("tet {tet} (from {path}) is flat, or flat/inverted after rounding its points to f32")]
    RoundingFlattens {
        /// The `.ele` file.
        path: PathBuf,
        /// 0-based tet index.
        tet: u32,
    },
}

/// Name of the scalar field made of `.node` point attributes.
pub const ATTRIBUTE_FIELD: &str = "tetgen_attributes";

/// Most point attributes a `.node` file may declare (a bound checked before
/// any column is allocated).
pub const MAX_ATTRIBUTES: usize = 1 << 16;

/// Data lines of a file: (1-based line number, whitespace-separated fields).
fn data_lines(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, l)| {
        let l = l.split('#').next().unwrap_or("");
        let f: Vec<&str> = l.split_whitespace().collect();
        (!f.is_empty()).then_some((i + 1, f))
    })
}

struct Parser<'a> {
    path: &'a Path,
}

impl Parser<'_> {
    fn err(&self, line: usize, message: impl Into<String>) -> FilesError {
        FilesError::Parse {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }
    fn num<T: std::str::FromStr>(
        &self,
        line: usize,
        fields: &[&str],
        i: usize,
        what: &str,
    ) -> Result<T, FilesError> {
        let f = fields
            .get(i)
            .ok_or_else(|| self.err(line, format!("missing {what} (field {})", i + 1)))?;
        f.parse()
            .map_err(|_| self.err(line, format!("cannot parse {what} {f:?}")))
    }
}

fn read_text(path: &Path) -> Result<String, FilesError> {
    fs::read_to_string(path).map_err(|source| FilesError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// A data line: its 1-based number and its fields.
type Record<'t> = (usize, Vec<&'t str>);

/// Parses records after the header: checks the count and consecutive
/// indices, returns the numbering base (index of the first record) and each
/// record's fields after the index.
fn records<'t>(
    p: &Parser,
    lines: &mut dyn Iterator<Item = (usize, Vec<&'t str>)>,
    count: usize,
    min_fields: usize,
) -> Result<(i64, Vec<Record<'t>>), FilesError> {
    let mut base = 0i64;
    // The header count is untrusted: never preallocate by it.
    let mut out = Vec::with_capacity(count.min(1 << 16));
    for k in 0..count {
        let (line, fields) = lines
            .next()
            .ok_or_else(|| p.err(0, format!("expected {count} records, found {k}")))?;
        let index: i64 = p.num(line, &fields, 0, "index")?;
        if k == 0 {
            if index != 0 && index != 1 {
                return Err(p.err(line, format!("first index must be 0 or 1, not {index}")));
            }
            base = index;
        } else if index != base + k as i64 {
            return Err(p.err(line, format!("index {index}, expected {}", base + k as i64)));
        }
        if fields.len() < 1 + min_fields {
            return Err(p.err(
                line,
                format!("expected at least {min_fields} values after the index"),
            ));
        }
        out.push((line, fields[1..].to_vec()));
    }
    if let Some((line, _)) = lines.next() {
        return Err(p.err(line, "more records than the header declares"));
    }
    Ok((base, out))
}

fn vertex(
    p: &Parser,
    line: usize,
    f: &[&str],
    i: usize,
    base: i64,
    n: usize,
) -> Result<u32, FilesError> {
    let v: i64 = p.num(line, f, i, "vertex")?;
    let z = v - base;
    if z < 0 || z as usize >= n {
        return Err(p.err(
            line,
            format!("vertex {v} out of range ({n} points, first index {base})"),
        ));
    }
    Ok(z as u32)
}

/// Reads `<base>.node` and `<base>.ele`, and `<base>.face` / `<base>.neigh` when present.
pub fn read(base: &Path) -> Result<TetgenFiles, FilesError> {
    let node_path = with_ext(base, "node");
    let text = read_text(&node_path)?;
    let p = Parser { path: &node_path };
    let mut lines = data_lines(&text);
    let (hl, h) = lines.next().ok_or_else(|| p.err(0, "empty file"))?;
    let n: usize = p.num(hl, &h, 0, "point count")?;
    let dim: usize = p.num(hl, &h, 1, "dimension")?;
    if dim != 3 {
        return Err(p.err(hl, format!("dimension {dim}, expected 3")));
    }
    let attributes: usize = match h.get(2) {
        Some(_) => p.num(hl, &h, 2, "attribute count")?,
        None => 0,
    };
    if attributes > MAX_ATTRIBUTES {
        return Err(p.err(
            hl,
            format!("{attributes} attributes, at most {MAX_ATTRIBUTES}"),
        ));
    }
    let (node_base, recs) = records(&p, &mut lines, n, 3 + attributes)?;
    let mut points = Vec::with_capacity(n);
    let mut point_attributes = vec![Vec::with_capacity(recs.len()); attributes];
    for (line, f) in &recs {
        let c = [
            p.num::<f64>(*line, f, 0, "x")?,
            p.num::<f64>(*line, f, 1, "y")?,
            p.num::<f64>(*line, f, 2, "z")?,
        ];
        if !c.iter().all(|x| x.is_finite()) {
            return Err(p.err(*line, "non-finite coordinate"));
        }
        points.push(c);
        for (k, column) in point_attributes.iter_mut().enumerate() {
            let v: f64 = p.num(*line, f, 3 + k, "attribute")?;
            if !v.is_finite() {
                return Err(p.err(*line, format!("attribute {k} is not finite")));
            }
            column.push(v);
        }
    }

    let ele_path = with_ext(base, "ele");
    let text = read_text(&ele_path)?;
    let p = Parser { path: &ele_path };
    let mut lines = data_lines(&text);
    let (hl, h) = lines.next().ok_or_else(|| p.err(0, "empty file"))?;
    let nt: usize = p.num(hl, &h, 0, "tet count")?;
    let corners: usize = p.num(hl, &h, 1, "nodes per tet")?;
    if corners != 4 {
        return Err(p.err(hl, format!("{corners} nodes per tet, only 4 is supported")));
    }
    let (_, recs) = records(&p, &mut lines, nt, 4)?;
    let mut tets = Vec::with_capacity(nt);
    for (line, f) in &recs {
        let mut t = [0u32; 4];
        for (k, v) in t.iter_mut().enumerate() {
            *v = vertex(&p, *line, f, k, node_base, n)?;
        }
        tets.push(t);
    }

    let mut files = TetgenFiles {
        points,
        point_attributes,
        tets,
        ..TetgenFiles::default()
    };
    let face_path = with_ext(base, "face");
    if face_path.exists() {
        let text = read_text(&face_path)?;
        let p = Parser { path: &face_path };
        let mut lines = data_lines(&text);
        let (hl, h) = lines.next().ok_or_else(|| p.err(0, "empty file"))?;
        let nf: usize = p.num(hl, &h, 0, "face count")?;
        let has_markers = h.get(1).map(|s| *s != "0").unwrap_or(false);
        let (_, recs) = records(&p, &mut lines, nf, if has_markers { 4 } else { 3 })?;
        let mut markers = Vec::new();
        for (line, f) in &recs {
            files.faces.push([
                vertex(&p, *line, f, 0, node_base, n)?,
                vertex(&p, *line, f, 1, node_base, n)?,
                vertex(&p, *line, f, 2, node_base, n)?,
            ]);
            if has_markers {
                markers.push(p.num(*line, f, 3, "marker")?);
            }
        }
        files.face_markers = has_markers.then_some(markers);
    }
    let neigh_path = with_ext(base, "neigh");
    if neigh_path.exists() {
        let text = read_text(&neigh_path)?;
        let p = Parser { path: &neigh_path };
        let mut lines = data_lines(&text);
        let (hl, h) = lines.next().ok_or_else(|| p.err(0, "empty file"))?;
        let count: usize = p.num(hl, &h, 0, "tet count")?;
        if count != nt {
            return Err(p.err(hl, format!("{count} tets, but the .ele file has {nt}")));
        }
        let (ele_base, recs) = records(&p, &mut lines, count, 4)?;
        let mut neigh = Vec::with_capacity(count);
        for (line, f) in &recs {
            let mut row = [0i32; 4];
            for (k, v) in row.iter_mut().enumerate() {
                let x: i64 = p.num(*line, f, k, "neighbour")?;
                *v = if x == -1 {
                    -1
                } else {
                    let z = x - ele_base;
                    if z < 0 || z as usize >= nt {
                        return Err(p.err(*line, format!("neighbour {x} out of range")));
                    }
                    z as i32
                };
            }
            neigh.push(row);
        }
        files.neighbors = Some(neigh);
    }
    Ok(files)
}

/// Writes `<base>.node` (with the point attributes), `<base>.ele`,
/// `<base>.face` (when there are faces) and `<base>.neigh` (when neighbours
/// are present), 0-based, atomically. An attribute column without one value
/// per point is refused ([`FilesError::Mesh`]).
pub fn write(base: &Path, files: &TetgenFiles) -> Result<(), FilesError> {
    let n = files.points.len();
    if let Some((step, c)) = files
        .point_attributes
        .iter()
        .enumerate()
        .find(|(_, c)| c.len() != n)
    {
        return Err(FilesError::Mesh(MeshError::ScalarLength {
            step,
            actual: c.len(),
            expected: n,
        }));
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# written by tet-build\n{} 3 {} 0",
        files.points.len(),
        files.point_attributes.len()
    );
    for (i, p) in files.points.iter().enumerate() {
        // `{:?}` prints the shortest string that parses back to the same f64.
        let _ = write!(s, "{i} {:?} {:?} {:?}", p[0], p[1], p[2]);
        for column in &files.point_attributes {
            let _ = write!(s, " {:?}", column.get(i).copied().unwrap_or(0.0));
        }
        s.push('\n');
    }
    atomic_write(&with_ext(base, "node"), s.as_bytes())?;
    let mut s = String::new();
    let _ = writeln!(s, "{} 4 0", files.tets.len());
    for (i, t) in files.tets.iter().enumerate() {
        let _ = writeln!(s, "{i} {} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    atomic_write(&with_ext(base, "ele"), s.as_bytes())?;
    if !files.faces.is_empty() || files.face_markers.is_some() {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} {}",
            files.faces.len(),
            files.face_markers.is_some() as u8
        );
        for (i, f) in files.faces.iter().enumerate() {
            let _ = write!(s, "{i} {} {} {}", f[0], f[1], f[2]);
            if let Some(m) = &files.face_markers {
                let _ = write!(s, " {}", m.get(i).copied().unwrap_or(0));
            }
            s.push('\n');
        }
        atomic_write(&with_ext(base, "face"), s.as_bytes())?;
    }
    if let Some(n) = &files.neighbors {
        let mut s = String::new();
        let _ = writeln!(s, "{} 4", n.len());
        for (i, r) in n.iter().enumerate() {
            let _ = writeln!(s, "{i} {} {} {} {}", r[0], r[1], r[2], r[3]);
        }
        atomic_write(&with_ext(base, "neigh"), s.as_bytes())?;
    }
    Ok(())
}

/// Converts files to a validated [`TetMesh`]: points rounded to f32, tets
/// oriented positively (by the exact f64 orientation of the file's
/// coordinates), faces with marker `m > 0` become constrained faces of
/// triangle `m - 1` (winding as in the file). `triangle_count` defaults to
/// the largest marker. Point attributes become the steps of the scalar field
/// [`ATTRIBUTE_FIELD`], rounded to f32 (a value beyond f32's range is a
/// [`FilesError::Mesh`]).
pub fn to_tet_mesh(
    files: &TetgenFiles,
    source: &Path,
    triangle_count: Option<u32>,
) -> Result<TetMesh, FilesError> {
    let points: Vec<Vec3> = files
        .points
        .iter()
        .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
        .collect();
    let mut tets = Vec::with_capacity(files.tets.len());
    for (i, &t) in files.tets.iter().enumerate() {
        let [a, b, c, d] = t.map(|v| DVec3::from_array(files.points[v as usize]));
        let o64 = tet_core::predicates::orient3d(a, b, c, d);
        let t = if o64 < 0.0 {
            [t[1], t[0], t[2], t[3]]
        } else {
            t
        };
        let [a, b, c, d] = t.map(|v| points[v as usize]);
        if o64 == 0.0 || tet_core::predicates::orient3d_f32(a, b, c, d) <= 0.0 {
            return Err(FilesError::RoundingFlattens {
                path: with_ext(source, "ele"),
                tet: i as u32,
            });
        }
        tets.push(t);
    }
    let mut tris = Vec::new();
    let mut max_marker = 0u32;
    if let Some(m) = &files.face_markers {
        for (f, &mk) in files.faces.iter().zip(m) {
            if mk > 0 {
                tris.push((*f, mk as u32 - 1));
                max_marker = max_marker.max(mk as u32);
            }
        }
    }
    let mut mesh = TetMesh::assemble(points, tets, &tris, triangle_count.unwrap_or(max_marker))?;
    if !files.point_attributes.is_empty() {
        mesh.attributes.scalars = Some(tet_core::ScalarField {
            name: ATTRIBUTE_FIELD.to_string(),
            steps: files
                .point_attributes
                .iter()
                .map(|c| c.iter().map(|&v| v as f32).collect())
                .collect(),
        });
    }
    mesh.validate()?;
    Ok(mesh)
}

/// The TetGen files of a mesh: constrained faces as faces with marker
/// `triangle + 1` (source winding), neighbours across every face (also
/// across constrained faces), `-1` on the boundary; the scalar field's
/// steps as point attributes (its name is not stored).
pub fn from_tet_mesh(mesh: &TetMesh) -> TetgenFiles {
    let neighbors = (0..mesh.tets.len())
        .map(|t| {
            let mut row = [-1i32; 4];
            for (k, r) in row.iter_mut().enumerate() {
                *r = match mesh.neighbors[t][k].kind() {
                    LinkKind::Tet(n) => n as i32,
                    LinkKind::Boundary => -1,
                    LinkKind::Constrained(_) => {
                        mesh.across(t as u32, k).map_or(-1, |s| s.tet as i32)
                    }
                };
            }
            row
        })
        .collect();
    TetgenFiles {
        points: mesh
            .points
            .iter()
            .map(|p| p.as_dvec3().to_array())
            .collect(),
        point_attributes: mesh.attributes.scalars.as_ref().map_or(Vec::new(), |f| {
            f.steps
                .iter()
                .map(|s| s.iter().map(|&v| f64::from(v)).collect())
                .collect()
        }),
        tets: mesh.tets.clone(),
        faces: mesh.constrained.iter().map(|c| c.vertices).collect(),
        face_markers: Some(
            mesh.constrained
                .iter()
                .map(|c| c.triangle as i32 + 1)
                .collect(),
        ),
        neighbors: Some(neighbors),
    }
}

fn with_ext(base: &Path, ext: &str) -> PathBuf {
    let mut s = base.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Writes `bytes` to `path` atomically: a temporary file in the same
/// directory, flushed, then renamed over `path`.
pub(crate) fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), FilesError> {
    let io_err = |source| FilesError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp{}", std::process::id()));
    let tmp = PathBuf::from(tmp);
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(io_err)
}
