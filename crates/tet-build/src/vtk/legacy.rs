//! The VTK legacy format (`.vtk`), `DATASET UNSTRUCTURED_GRID`, ASCII or
//! BINARY (big-endian), reading both the classic `CELLS n size` layout and
//! the `OFFSETS` / `CONNECTIVITY` layout of version 5.1; writing version 3.0
//! (read by every VTK since).
//!
//! Read: `POINTS`, `CELLS`, `CELL_TYPES`, `POINT_DATA` / `CELL_DATA` with
//! `SCALARS` (any component count, optional `LOOKUP_TABLE` line) and
//! `FIELD` arrays; `VECTORS`, `NORMALS`, `TENSORS`, `TEXTURE_COORDINATES`,
//! `COLOR_SCALARS`, `LOOKUP_TABLE` and `METADATA` blocks are read past.
//! A `FIELD` array `triangle_count` before the point and cell data sets
//! [`tet_core::TetMesh::triangle_count`].

use std::fmt::Write as _;
use std::path::Path;

use tet_core::TetMesh;

use super::model::{
    Array, DataType, Grid, KIND_ARRAY, TRIANGLE_ARRAY, TRIANGLE_COUNT_FIELD, step_array_name,
};
use super::{VTK_TETRA, VTK_TRIANGLE, VtkEncoding, VtkError};

/// A legacy data section's type name (`float`, `vtktypeint64`, …).
fn legacy_type(name: &str) -> Option<DataType> {
    Some(match name.to_ascii_lowercase().as_str() {
        "float" => DataType::F32,
        "double" => DataType::F64,
        "char" | "vtktypeint8" => DataType::I8,
        "unsigned_char" | "vtktypeuint8" => DataType::U8,
        "short" | "vtktypeint16" => DataType::I16,
        "unsigned_short" | "vtktypeuint16" => DataType::U16,
        "int" | "vtktypeint32" | "vtkidtype" => DataType::I32,
        "unsigned_int" | "vtktypeuint32" => DataType::U32,
        "long" | "vtktypeint64" => DataType::I64,
        "unsigned_long" | "vtktypeuint64" => DataType::U64,
        _ => return None,
    })
}

/// A position in the file: byte offset and 1-based line.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
    binary: bool,
    path: &'a Path,
}

impl<'a> Cursor<'a> {
    fn err(&self, line: usize, message: impl Into<String>) -> VtkError {
        VtkError::Parse {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    /// The next line (without its end), or `None` at the end of the file.
    fn raw_line(&mut self) -> Option<(&'a [u8], usize)> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let line = self.line;
        self.pos += (end + 1).min(rest.len());
        self.line += 1;
        let text = &rest[..end];
        Some((text.strip_suffix(b"\r").unwrap_or(text), line))
    }

    /// The next non-blank line split into words, with its line number.
    fn words(&mut self) -> Result<Option<(Vec<&'a str>, usize)>, VtkError> {
        while let Some((text, line)) = self.raw_line() {
            let text = std::str::from_utf8(text)
                .map_err(|_| self.err(line, "keyword line is not UTF-8"))?;
            let words: Vec<&str> = text.split_whitespace().collect();
            if !words.is_empty() {
                return Ok(Some((words, line)));
            }
        }
        Ok(None)
    }

    /// Whether the next line starts with keyword `kw` (any case). In
    /// binary mode the keyword must follow at once (data may hold any
    /// byte); in ASCII mode blank space may come first.
    fn next_is(&self, kw: &str) -> bool {
        let mut at = self.pos;
        if !self.binary {
            while at < self.bytes.len() && self.bytes[at].is_ascii_whitespace() {
                at += 1;
            }
        }
        let rest = &self.bytes[at..];
        rest.len() >= kw.len()
            && rest[..kw.len()].eq_ignore_ascii_case(kw.as_bytes())
            && rest.get(kw.len()).is_none_or(u8::is_ascii_whitespace)
    }

    /// After a keyword line in ASCII mode the cursor sits at the start of
    /// the data; values are whitespace-separated tokens over any lines.
    fn token(&mut self) -> Option<(&'a [u8], usize)> {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            if self.bytes[self.pos] == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start).then(|| (&self.bytes[start..self.pos], self.line))
    }

    /// `count` values of type `ty` (`what` names them in errors). Values
    /// must be finite.
    fn values(&mut self, count: usize, ty: DataType, what: &str) -> Result<Vec<f64>, VtkError> {
        let start_line = self.line;
        if self.binary {
            let size = ty.size();
            let needed = count
                .checked_mul(size)
                .filter(|&n| n <= self.bytes.len() - self.pos);
            let Some(needed) = needed else {
                return Err(self.err(
                    start_line,
                    format!(
                        "{what}: {count} binary values of {size} bytes, only {} bytes left (truncated)",
                        self.bytes.len() - self.pos
                    ),
                ));
            };
            let data = &self.bytes[self.pos..self.pos + needed];
            self.pos += needed;
            self.line += data.iter().filter(|&&b| b == b'\n').count();
            let out: Vec<f64> = data
                .chunks_exact(size)
                .map(|c| ty.decode(c, true))
                .collect();
            if let Some(i) = out.iter().position(|v| !v.is_finite()) {
                return Err(self.err(start_line, format!("{what}: value {i} is {}", out[i])));
            }
            return Ok(out);
        }
        // Each ASCII value takes at least two bytes: never preallocate
        // beyond what the file can hold.
        let mut out = Vec::with_capacity(count.min((self.bytes.len() - self.pos) / 2 + 1));
        for i in 0..count {
            let Some((tok, line)) = self.token() else {
                return Err(self.err(
                    self.line,
                    format!("{what}: expected {count} values, the file ends after {i} (truncated)"),
                ));
            };
            let text = std::str::from_utf8(tok).unwrap_or("<not UTF-8>");
            let v: f64 = text
                .parse()
                .map_err(|_| self.err(line, format!("{what}: cannot parse value {i} {text:?}")))?;
            if !v.is_finite() {
                return Err(self.err(line, format!("{what}: value {i} is {text}, not finite")));
            }
            out.push(v);
        }
        Ok(out)
    }

    /// Word `i` of a keyword line as a count.
    fn count(&self, line: usize, words: &[&str], i: usize, what: &str) -> Result<usize, VtkError> {
        let w = words
            .get(i)
            .ok_or_else(|| self.err(line, format!("missing {what}")))?;
        w.parse()
            .map_err(|_| self.err(line, format!("{what} {w:?} is not a count")))
    }

    fn data_type(&self, line: usize, words: &[&str], i: usize) -> Result<DataType, VtkError> {
        let w = words
            .get(i)
            .ok_or_else(|| self.err(line, "missing data type"))?;
        legacy_type(w).ok_or_else(|| self.err(line, format!("unknown data type {w:?}")))
    }
}

/// Integers (connectivity, offsets, types) from values read as `f64`.
fn integers(c: &Cursor, line: usize, values: &[f64], what: &str) -> Result<Vec<u64>, VtkError> {
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            if v >= 0.0 && v.fract() == 0.0 && v < 2f64.powi(53) {
                Ok(v as u64)
            } else {
                Err(c.err(
                    line,
                    format!("{what}: value {i} ({v}) is not a non-negative integer"),
                ))
            }
        })
        .collect()
}

/// Which data section attributes go to.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Section {
    Dataset,
    Point(usize),
    Cell(usize),
}

/// Parses a legacy file image. `path` names the file in errors.
pub fn from_legacy_bytes(bytes: &[u8], path: &Path) -> Result<TetMesh, VtkError> {
    parse(bytes, path)?.into_mesh(path)
}

fn parse(bytes: &[u8], path: &Path) -> Result<Grid, VtkError> {
    let mut c = Cursor {
        bytes,
        pos: 0,
        line: 1,
        binary: false,
        path,
    };
    let (first, _) = c.raw_line().ok_or_else(|| c.err(1, "empty file"))?;
    // A legacy file has no length or end marker: a file cut inside a value
    // would still parse. Writers end every line, so a missing final line
    // break is taken as truncation.
    if !bytes.ends_with(b"\n") {
        let lines = 1 + bytes.iter().filter(|&&b| b == b'\n').count();
        return Err(c.err(lines, "the file does not end with a line break (truncated)"));
    }
    if !first
        .to_ascii_lowercase()
        .starts_with(b"# vtk datafile version")
    {
        return Err(c.err(
            1,
            "not a VTK legacy file (no \"# vtk DataFile Version\" line)",
        ));
    }
    c.raw_line()
        .ok_or_else(|| c.err(2, "missing title line (truncated)"))?;
    let (mode, line) = c
        .words()?
        .ok_or_else(|| c.err(3, "missing ASCII/BINARY line"))?;
    c.binary = match mode[0].to_ascii_uppercase().as_str() {
        "ASCII" => false,
        "BINARY" => true,
        other => return Err(c.err(line, format!("expected ASCII or BINARY, found {other:?}"))),
    };
    let mut grid = Grid::default();
    let mut section = Section::Dataset;
    let mut seen_dataset = false;
    let mut cells_declared = None;
    let (mut seen_points, mut seen_types) = (false, false);
    while let Some((words, line)) = c.words()? {
        let keyword = words[0].to_ascii_uppercase();
        if !seen_dataset && keyword != "DATASET" {
            return Err(c.err(line, format!("expected DATASET, found {:?}", words[0])));
        }
        match keyword.as_str() {
            "DATASET" => {
                let kind = words.get(1).copied().unwrap_or("");
                if !kind.eq_ignore_ascii_case("UNSTRUCTURED_GRID") {
                    return Err(c.err(line, format!("dataset {kind:?} is not UNSTRUCTURED_GRID")));
                }
                seen_dataset = true;
            }
            "POINTS" => {
                let n = c.count(line, &words, 1, "point count")?;
                let ty = c.data_type(line, &words, 2)?;
                let v = c.values(n.saturating_mul(3), ty, "POINTS")?;
                grid.points = v.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
                seen_points = true;
            }
            "CELLS" => {
                let a = c.count(line, &words, 1, "cell count")?;
                let b = c.count(line, &words, 2, "cell list size")?;
                let new_layout = c.next_is("OFFSETS");
                if new_layout {
                    let (w, l) = c.words()?.expect("peeked");
                    let ty = c.data_type(l, &w, 1)?;
                    let offsets = {
                        let v = c.values(a, ty, "OFFSETS")?;
                        integers(&c, l, &v, "OFFSETS")?
                    };
                    let (w, l) = c
                        .words()?
                        .ok_or_else(|| c.err(l, "missing CONNECTIVITY (truncated)"))?;
                    if !w[0].eq_ignore_ascii_case("CONNECTIVITY") {
                        return Err(c.err(l, format!("expected CONNECTIVITY, found {:?}", w[0])));
                    }
                    let ty = c.data_type(l, &w, 1)?;
                    grid.connectivity = {
                        let v = c.values(b, ty, "CONNECTIVITY")?;
                        integers(&c, l, &v, "CONNECTIVITY")?
                    };
                    if offsets.first().is_some_and(|&o| o != 0) {
                        return Err(c.err(l, "OFFSETS must start at 0"));
                    }
                    grid.offsets = offsets.iter().skip(1).copied().collect();
                    cells_declared = Some((a.saturating_sub(1), line));
                } else {
                    let list = {
                        let v = c.values(b, DataType::I32, "CELLS")?;
                        integers(&c, line, &v, "CELLS")?
                    };
                    let mut k = 0usize;
                    for cell in 0..a {
                        let Some(&count) = list.get(k) else {
                            return Err(c.err(
                                line,
                                format!("CELLS: the list of size {b} ends before cell {cell}"),
                            ));
                        };
                        let end = k + 1 + count as usize;
                        if end > list.len() {
                            return Err(c.err(
                                line,
                                format!(
                                    "CELLS: cell {cell} has {count} vertices past the list's end"
                                ),
                            ));
                        }
                        grid.connectivity.extend_from_slice(&list[k + 1..end]);
                        grid.offsets.push(grid.connectivity.len() as u64);
                        k = end;
                    }
                    if k != list.len() {
                        return Err(c.err(
                            line,
                            format!("CELLS: {a} cells use {k} of the list's {b} entries"),
                        ));
                    }
                    cells_declared = Some((a, line));
                }
            }
            "CELL_TYPES" => {
                let n = c.count(line, &words, 1, "cell type count")?;
                if let Some((a, cells_line)) = cells_declared
                    && a != n
                {
                    return Err(c.err(
                        line,
                        format!("CELL_TYPES has {n} cells, CELLS (line {cells_line}) {a}"),
                    ));
                }
                let types = {
                    let v = c.values(n, DataType::I32, "CELL_TYPES")?;
                    integers(&c, line, &v, "CELL_TYPES")?
                };
                grid.types = types.iter().map(|&t| t.min(255) as u8).collect();
                seen_types = true;
            }
            "POINT_DATA" => {
                section = Section::Point(c.count(line, &words, 1, "point data count")?)
            }
            "CELL_DATA" => section = Section::Cell(c.count(line, &words, 1, "cell data count")?),
            "SCALARS"
            | "VECTORS"
            | "NORMALS"
            | "TENSORS"
            | "TEXTURE_COORDINATES"
            | "COLOR_SCALARS" => {
                let n = match section {
                    Section::Point(n) | Section::Cell(n) => n,
                    Section::Dataset => {
                        return Err(
                            c.err(line, format!("{keyword} before POINT_DATA or CELL_DATA"))
                        );
                    }
                };
                let name = words
                    .get(1)
                    .ok_or_else(|| c.err(line, "missing array name"))?;
                let (components, ty) = match keyword.as_str() {
                    "SCALARS" => {
                        let comps = if words.len() > 3 {
                            c.count(line, &words, 3, "component count")?
                        } else {
                            1
                        };
                        (comps, c.data_type(line, &words, 2)?)
                    }
                    "VECTORS" | "NORMALS" => (3, c.data_type(line, &words, 2)?),
                    "TENSORS" => (9, c.data_type(line, &words, 2)?),
                    "TEXTURE_COORDINATES" => (
                        c.count(line, &words, 2, "dimension")?,
                        c.data_type(line, &words, 3)?,
                    ),
                    _ => (
                        c.count(line, &words, 2, "component count")?,
                        if c.binary {
                            DataType::U8
                        } else {
                            DataType::F32
                        },
                    ),
                };
                if keyword == "SCALARS" && c.next_is("LOOKUP_TABLE") {
                    c.words()?;
                }
                let values = c.values(n.saturating_mul(components), ty, name)?;
                let array = Array {
                    name: name.to_string(),
                    components,
                    values,
                    line,
                };
                match section {
                    Section::Point(_) => grid.point_data.push(array),
                    _ => grid.cell_data.push(array),
                }
            }
            "LOOKUP_TABLE" => {
                let n = c.count(line, &words, 2, "table size")?;
                let ty = if c.binary {
                    DataType::U8
                } else {
                    DataType::F32
                };
                c.values(n.saturating_mul(4), ty, "LOOKUP_TABLE")?;
            }
            "FIELD" => {
                let arrays = c.count(line, &words, 2, "array count")?;
                for _ in 0..arrays {
                    let (w, l) = c
                        .words()?
                        .ok_or_else(|| c.err(line, "FIELD: missing array (truncated)"))?;
                    let components = c.count(l, &w, 1, "component count")?;
                    let tuples = c.count(l, &w, 2, "tuple count")?;
                    let ty = c.data_type(l, &w, 3)?;
                    let values = c.values(components.saturating_mul(tuples), ty, w[0])?;
                    let array = Array {
                        name: w[0].to_string(),
                        components,
                        values,
                        line: l,
                    };
                    match section {
                        Section::Dataset if array.name == TRIANGLE_COUNT_FIELD => {
                            let v = array.values.first().copied().unwrap_or(-1.0);
                            let n = integers(&c, l, &[v], TRIANGLE_COUNT_FIELD)?;
                            grid.triangle_count = Some(n[0]);
                        }
                        Section::Dataset => {}
                        Section::Point(n) => {
                            if tuples != n {
                                return Err(
                                    c.err(l, format!("{}: {tuples} tuples, expected {n}", w[0]))
                                );
                            }
                            grid.point_data.push(array);
                        }
                        Section::Cell(_) => grid.cell_data.push(array),
                    }
                }
            }
            "METADATA" => {
                // Information blocks end at a blank line.
                while let Some((text, _)) = c.raw_line() {
                    if text.iter().all(u8::is_ascii_whitespace) {
                        break;
                    }
                }
            }
            _ => return Err(c.err(line, format!("unknown keyword {:?}", words[0]))),
        }
    }
    if !seen_dataset {
        return Err(c.err(c.line, "no DATASET (truncated)"));
    }
    for (keyword, seen) in [
        ("POINTS", seen_points),
        ("CELLS", cells_declared.is_some()),
        ("CELL_TYPES", seen_types),
    ] {
        if !seen {
            return Err(c.err(c.line, format!("no {keyword} section (truncated?)")));
        }
    }
    if let Section::Point(n) = section
        && n != grid.points.len()
    {
        return Err(c.err(
            0,
            format!("POINT_DATA {n} for {} points", grid.points.len()),
        ));
    }
    Ok(grid)
}

/// The legacy file (version 3.0) of `mesh`: tets then constrained faces
/// as triangles, cell data `kind` (0 tet, 1 constrained face) and
/// `triangle` (scene triangle, -1 for tets), field data `triangle_count`,
/// and the scalar field's steps as point data (`name`, or `name_t0000`, …
/// for several steps). Coordinates and values are written as `f32`
/// (exact: shortest round-trip decimals in ASCII).
pub fn to_legacy_bytes(mesh: &TetMesh, encoding: VtkEncoding) -> Vec<u8> {
    let binary = encoding != VtkEncoding::Ascii;
    let nt = mesh.tets.len();
    let nc = mesh.constrained.len();
    let mut out = Vec::with_capacity(32 * (mesh.points.len() + nt + nc) + 512);
    let text = |out: &mut Vec<u8>, s: &str| out.extend_from_slice(s.as_bytes());
    text(
        &mut out,
        &format!(
            "# vtk DataFile Version 3.0\ntetrays tetrahedral mesh\n{}\nDATASET UNSTRUCTURED_GRID\nFIELD FieldData 1\n{TRIANGLE_COUNT_FIELD} 1 1 unsigned_int\n",
            if binary { "BINARY" } else { "ASCII" }
        ),
    );
    let put_f32 = |out: &mut Vec<u8>, values: &mut dyn Iterator<Item = f32>, per_line: usize| {
        let mut s = String::new();
        for (i, v) in values.enumerate() {
            if binary {
                out.extend_from_slice(&v.to_be_bytes());
            } else {
                let _ = write!(s, "{v:?}");
                s.push(if (i + 1).is_multiple_of(per_line) {
                    '\n'
                } else {
                    ' '
                });
            }
        }
        out.extend_from_slice(s.as_bytes());
    };
    let put_i32 = |out: &mut Vec<u8>, rows: &mut dyn Iterator<Item = Vec<i64>>| {
        let mut s = String::new();
        for row in rows {
            for (k, v) in row.iter().enumerate() {
                if binary {
                    out.extend_from_slice(&(*v as i32).to_be_bytes());
                } else {
                    let _ = write!(s, "{}{v}", if k > 0 { " " } else { "" });
                }
            }
            if !binary {
                s.push('\n');
            }
        }
        out.extend_from_slice(s.as_bytes());
    };
    if binary {
        out.extend_from_slice(&mesh.triangle_count.to_be_bytes());
        out.push(b'\n');
    } else {
        text(&mut out, &format!("{}\n", mesh.triangle_count));
    }
    text(&mut out, &format!("POINTS {} float\n", mesh.points.len()));
    put_f32(
        &mut out,
        &mut mesh.points.iter().flat_map(|p| p.to_array()),
        3,
    );
    if binary {
        out.push(b'\n');
    }
    text(
        &mut out,
        &format!("CELLS {} {}\n", nt + nc, 5 * nt + 4 * nc),
    );
    put_i32(
        &mut out,
        &mut mesh
            .tets
            .iter()
            .map(|t| [4, t[0], t[1], t[2], t[3]].map(i64::from).to_vec())
            .chain(mesh.constrained.iter().map(|c| {
                let v = c.vertices;
                [3, v[0], v[1], v[2]].map(i64::from).to_vec()
            })),
    );
    if binary {
        out.push(b'\n');
    }
    text(&mut out, &format!("CELL_TYPES {}\n", nt + nc));
    put_i32(
        &mut out,
        &mut (0..nt)
            .map(|_| vec![i64::from(VTK_TETRA)])
            .chain((0..nc).map(|_| vec![i64::from(VTK_TRIANGLE)])),
    );
    if binary {
        out.push(b'\n');
    }
    text(
        &mut out,
        &format!(
            "CELL_DATA {}\nSCALARS {KIND_ARRAY} int 1\nLOOKUP_TABLE default\n",
            nt + nc
        ),
    );
    put_i32(
        &mut out,
        &mut (0..nt).map(|_| vec![0]).chain((0..nc).map(|_| vec![1])),
    );
    if binary {
        out.push(b'\n');
    }
    text(
        &mut out,
        &format!("SCALARS {TRIANGLE_ARRAY} int 1\nLOOKUP_TABLE default\n"),
    );
    put_i32(
        &mut out,
        &mut (0..nt)
            .map(|_| vec![-1])
            .chain(mesh.constrained.iter().map(|c| vec![i64::from(c.triangle)])),
    );
    if binary {
        out.push(b'\n');
    }
    if let Some(field) = &mesh.attributes.scalars {
        text(&mut out, &format!("POINT_DATA {}\n", mesh.points.len()));
        for (s, step) in field.steps.iter().enumerate() {
            let name = step_array_name(&field.name, s, field.steps.len());
            text(
                &mut out,
                &format!(
                    "SCALARS {} float 1\nLOOKUP_TABLE default\n",
                    legacy_name(&name)
                ),
            );
            put_f32(&mut out, &mut step.iter().copied(), 9);
            if binary || !step.len().is_multiple_of(9) {
                out.push(b'\n');
            }
        }
    }
    out
}

/// Legacy array names are single words: spaces become `_`.
fn legacy_name(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .collect();
    if s.is_empty() { "scalars".into() } else { s }
}
