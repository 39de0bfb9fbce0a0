//! The VTK XML unstructured-grid format (`.vtu`), one `Piece`, data arrays
//! `format="ascii"`, `"binary"` (base64, inline) or `"appended"`
//! (`AppendedData` with `encoding="raw"` or `"base64"`), either byte order,
//! `header_type` `UInt32` or `UInt64`; compressed data is refused with a
//! typed error.
//!
//! Read: `Points`, `Cells` (`connectivity`, `offsets`, `types`),
//! `PointData`, `CellData`, and a `FieldData` array `triangle_count`.

use std::fmt::Write as _;
use std::path::Path;

use roxmltree::{Document, Node};
use tet_core::TetMesh;

use super::base64;
use super::model::{
    Array, DataType, Grid, KIND_ARRAY, TRIANGLE_ARRAY, TRIANGLE_COUNT_FIELD, step_array_name,
};
use super::{VTK_TETRA, VTK_TRIANGLE, VtkEncoding, VtkError};

/// An XML data array's type name (`Float32`, `Int64`, …).
fn xml_type(name: &str) -> Option<DataType> {
    Some(match name {
        "Float32" => DataType::F32,
        "Float64" => DataType::F64,
        "Int8" => DataType::I8,
        "UInt8" => DataType::U8,
        "Int16" => DataType::I16,
        "UInt16" => DataType::U16,
        "Int32" => DataType::I32,
        "UInt32" => DataType::U32,
        "Int64" => DataType::I64,
        "UInt64" => DataType::U64,
        _ => return None,
    })
}

/// The file-wide settings and the appended data.
struct Context<'a> {
    path: &'a Path,
    doc: &'a Document<'a>,
    big_endian: bool,
    /// Bytes of the block-size header of binary data.
    header_bytes: usize,
    appended: Appended<'a>,
}

enum Appended<'a> {
    None,
    Raw(&'a [u8]),
    Base64(&'a str),
}

impl Context<'_> {
    fn line(&self, node: Node) -> usize {
        self.doc.text_pos_at(node.range().start).row as usize
    }

    fn err(&self, node: Node, message: impl Into<String>) -> VtkError {
        VtkError::Parse {
            path: self.path.to_path_buf(),
            line: self.line(node),
            message: format!("<{}>: {}", node.tag_name().name(), message.into()),
        }
    }

    fn count_attr(&self, node: Node, name: &str) -> Result<usize, VtkError> {
        let v = node
            .attribute(name)
            .ok_or_else(|| self.err(node, format!("missing attribute {name}")))?;
        v.parse()
            .map_err(|_| self.err(node, format!("{name}={v:?} is not a count")))
    }

    /// The block-size header at the start of `bytes`.
    fn block_len(&self, node: Node, bytes: &[u8]) -> Result<usize, VtkError> {
        let h = self.header_bytes;
        if bytes.len() < h {
            return Err(self.err(
                node,
                "binary block shorter than its size header (truncated)",
            ));
        }
        let ty = if h == 8 { DataType::U64 } else { DataType::U32 };
        Ok(ty.decode(&bytes[..h], self.big_endian) as usize)
    }

    /// A `DataArray`'s values, `expected` of them (tuples × components).
    fn values(&self, node: Node, expected: usize) -> Result<Array, VtkError> {
        let name = node.attribute("Name").unwrap_or("").to_string();
        let ty_name = node.attribute("type").unwrap_or("");
        let ty = xml_type(ty_name)
            .ok_or_else(|| self.err(node, format!("{name}: unknown type {ty_name:?}")))?;
        let components = match node.attribute("NumberOfComponents") {
            Some(_) => self.count_attr(node, "NumberOfComponents")?,
            None => 1,
        };
        let format = node.attribute("format").unwrap_or("ascii");
        let values: Vec<f64> = match format {
            "ascii" => {
                let text = node.text().unwrap_or("");
                let mut out = Vec::with_capacity(expected.min(text.len() / 2 + 1));
                for (i, w) in text.split_ascii_whitespace().enumerate() {
                    let v: f64 = w.parse().map_err(|_| {
                        self.err(node, format!("{name}: cannot parse value {i} {w:?}"))
                    })?;
                    out.push(v);
                }
                out
            }
            "binary" => {
                let bytes = base64::decode(node.text().unwrap_or(""))
                    .map_err(|e| self.err(node, format!("{name}: {e}")))?;
                self.binary_block(node, &name, &bytes, ty)?
            }
            "appended" => {
                let offset = self.count_attr(node, "offset")?;
                let bytes = match self.appended {
                    Appended::None => {
                        return Err(
                            self.err(node, format!("{name}: appended data but no <AppendedData>"))
                        );
                    }
                    Appended::Raw(raw) => raw
                        .get(offset..)
                        .ok_or_else(|| {
                            self.err(
                                node,
                                format!("{name}: offset {offset} past the appended data"),
                            )
                        })?
                        .to_vec(),
                    Appended::Base64(text) => self.appended_base64(node, &name, text, offset)?,
                };
                self.binary_block(node, &name, &bytes, ty)?
            }
            other => return Err(self.err(node, format!("{name}: unknown format {other:?}"))),
        };
        if values.len() != expected {
            return Err(self.err(
                node,
                format!("{name}: {} values, expected {expected}", values.len()),
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(self.err(
                node,
                format!("{name}: value {i} is {}, not finite", values[i]),
            ));
        }
        Ok(Array {
            name,
            components,
            values,
            line: self.line(node),
        })
    }

    /// Decodes one appended base64 block (header and data encoded as one
    /// stream) starting at character `offset`.
    fn appended_base64(
        &self,
        node: Node,
        name: &str,
        text: &str,
        offset: usize,
    ) -> Result<Vec<u8>, VtkError> {
        let rest = text.get(offset..).ok_or_else(|| {
            self.err(
                node,
                format!("{name}: offset {offset} past the appended data"),
            )
        })?;
        let head_chars = self.header_bytes.div_ceil(3) * 4;
        let head = base64::decode(rest.get(..head_chars).unwrap_or(rest))
            .map_err(|e| self.err(node, format!("{name}: {e}")))?;
        let len = self.block_len(node, &head)?;
        let chars = (self.header_bytes.saturating_add(len))
            .div_ceil(3)
            .saturating_mul(4);
        let block = rest.get(..chars).ok_or_else(|| {
            self.err(
                node,
                format!("{name}: block of {len} bytes runs past the appended data (truncated)"),
            )
        })?;
        base64::decode(block).map_err(|e| self.err(node, format!("{name}: {e}")))
    }

    /// The values of a binary block: size header, then the data.
    fn binary_block(
        &self,
        node: Node,
        name: &str,
        bytes: &[u8],
        ty: DataType,
    ) -> Result<Vec<f64>, VtkError> {
        let len = self.block_len(node, bytes)?;
        let data = bytes
            .get(self.header_bytes..self.header_bytes.saturating_add(len))
            .ok_or_else(|| {
                self.err(
                    node,
                    format!(
                        "{name}: block says {len} bytes, {} present (truncated)",
                        bytes.len() - self.header_bytes
                    ),
                )
            })?;
        if len % ty.size() != 0 {
            return Err(self.err(
                node,
                format!(
                    "{name}: {len} bytes is not a whole number of {}-byte values",
                    ty.size()
                ),
            ));
        }
        Ok(data
            .chunks_exact(ty.size())
            .map(|c| ty.decode(c, self.big_endian))
            .collect())
    }
}

fn child<'a, 'input>(node: Node<'a, 'input>, name: &str) -> Option<Node<'a, 'input>> {
    node.children().find(|n| n.has_tag_name(name))
}

fn arrays<'a, 'input>(node: Node<'a, 'input>) -> impl Iterator<Item = Node<'a, 'input>> {
    node.children().filter(|n| n.has_tag_name("DataArray"))
}

/// Splits raw appended data out of the file (it need not be text).
fn split_raw(bytes: &[u8]) -> (std::borrow::Cow<'_, [u8]>, Option<&[u8]>) {
    let find = |hay: &[u8], needle: &[u8], from: usize| {
        hay.get(from..)?
            .windows(needle.len())
            .position(|w| w == needle)
            .map(|p| p + from)
    };
    let Some(tag) = find(bytes, b"<AppendedData", 0) else {
        return (bytes.into(), None);
    };
    let Some(close) = find(bytes, b">", tag) else {
        return (bytes.into(), None);
    };
    let head = &bytes[tag..close];
    if find(head, b"raw", 0).is_none() {
        return (bytes.into(), None);
    }
    let Some(underscore) = find(bytes, b"_", close) else {
        return (bytes.into(), None);
    };
    let end = bytes
        .windows(b"</AppendedData>".len())
        .rposition(|w| w == b"</AppendedData>")
        .filter(|&e| e > underscore)
        .unwrap_or(bytes.len());
    let mut text = bytes[..=underscore].to_vec();
    text.extend_from_slice(&bytes[end..]);
    (text.into(), Some(&bytes[underscore + 1..end]))
}

/// Parses a `.vtu` file image. `path` names the file in errors.
pub fn from_vtu_bytes(bytes: &[u8], path: &Path) -> Result<TetMesh, VtkError> {
    let (xml, raw) = split_raw(bytes);
    let text = std::str::from_utf8(&xml).map_err(|e| VtkError::Parse {
        path: path.to_path_buf(),
        line: 1 + xml[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
        message: "not UTF-8 text".into(),
    })?;
    let doc = Document::parse(text).map_err(|e| VtkError::Parse {
        path: path.to_path_buf(),
        line: e.pos().row as usize,
        message: format!("XML: {e}"),
    })?;
    let root = doc.root_element();
    let mut ctx = Context {
        path,
        doc: &doc,
        big_endian: false,
        header_bytes: 4,
        appended: Appended::None,
    };
    if !root.has_tag_name("VTKFile") || root.attribute("type") != Some("UnstructuredGrid") {
        return Err(ctx.err(root, "not a VTKFile of type UnstructuredGrid"));
    }
    if let Some(c) = root.attribute("compressor") {
        return Err(ctx.err(root, format!("compressed data ({c}) is not supported")));
    }
    ctx.big_endian = match root.attribute("byte_order").unwrap_or("LittleEndian") {
        "LittleEndian" => false,
        "BigEndian" => true,
        other => return Err(ctx.err(root, format!("unknown byte_order {other:?}"))),
    };
    ctx.header_bytes = match root.attribute("header_type").unwrap_or("UInt32") {
        "UInt32" => 4,
        "UInt64" => 8,
        other => return Err(ctx.err(root, format!("unknown header_type {other:?}"))),
    };
    if let Some(app) = child(root, "AppendedData") {
        ctx.appended = match (app.attribute("encoding").unwrap_or("raw"), raw) {
            ("raw", Some(raw)) => Appended::Raw(raw),
            ("base64", _) => {
                let t = app.text().unwrap_or("").trim_start();
                Appended::Base64(t.strip_prefix('_').unwrap_or(t).trim_end())
            }
            (other, _) => return Err(ctx.err(app, format!("unknown encoding {other:?}"))),
        };
    }
    let ug =
        child(root, "UnstructuredGrid").ok_or_else(|| ctx.err(root, "no <UnstructuredGrid>"))?;
    let mut pieces = ug.children().filter(|n| n.has_tag_name("Piece"));
    let piece = pieces.next().ok_or_else(|| ctx.err(ug, "no <Piece>"))?;
    if let Some(p) = pieces.next() {
        return Err(ctx.err(p, "several pieces are not supported"));
    }
    let np = ctx.count_attr(piece, "NumberOfPoints")?;
    let nc = ctx.count_attr(piece, "NumberOfCells")?;
    let mut grid = Grid::default();
    if let Some(fd) = child(ug, "FieldData") {
        for a in arrays(fd).filter(|a| a.attribute("Name") == Some(TRIANGLE_COUNT_FIELD)) {
            let v = ctx.values(a, 1)?.values[0];
            if !(v >= 0.0 && v.fract() == 0.0 && v <= f64::from(u32::MAX)) {
                return Err(ctx.err(a, format!("{TRIANGLE_COUNT_FIELD} {v} is not a count")));
            }
            grid.triangle_count = Some(v as u64);
        }
    }
    let points = child(piece, "Points").ok_or_else(|| ctx.err(piece, "no <Points>"))?;
    let pa = arrays(points)
        .next()
        .ok_or_else(|| ctx.err(points, "no <DataArray>"))?;
    let p = ctx.values(pa, np.saturating_mul(3))?;
    if p.components != 3 {
        return Err(ctx.err(
            pa,
            format!("points have {} components, expected 3", p.components),
        ));
    }
    grid.points = p
        .values
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let cells = child(piece, "Cells").ok_or_else(|| ctx.err(piece, "no <Cells>"))?;
    let named = |name: &str| {
        arrays(cells)
            .find(|a| a.attribute("Name") == Some(name))
            .ok_or_else(|| ctx.err(cells, format!("no DataArray {name}")))
    };
    let ints = |node: Node, values: Vec<f64>| -> Result<Vec<u64>, VtkError> {
        values
            .into_iter()
            .enumerate()
            .map(|(i, v)| {
                if v >= 0.0 && v.fract() == 0.0 && v < 2f64.powi(53) {
                    Ok(v as u64)
                } else {
                    Err(ctx.err(
                        node,
                        format!("value {i} ({v}) is not a non-negative integer"),
                    ))
                }
            })
            .collect()
    };
    let offsets_node = named("offsets")?;
    grid.offsets = ints(offsets_node, ctx.values(offsets_node, nc)?.values)?;
    let conn_len = grid.offsets.last().copied().unwrap_or(0);
    let conn_node = named("connectivity")?;
    // The connectivity's length is what the offsets say; the array is
    // checked against it (no allocation from an unchecked count: values
    // are parsed first, then compared).
    let conn = ctx.values(conn_node, usize::try_from(conn_len).unwrap_or(usize::MAX))?;
    grid.connectivity = ints(conn_node, conn.values)?;
    let types_node = named("types")?;
    grid.types = ints(types_node, ctx.values(types_node, nc)?.values)?
        .into_iter()
        .map(|t| t.min(255) as u8)
        .collect();
    for (section, count, out) in [
        ("PointData", np, &mut grid.point_data),
        ("CellData", nc, &mut grid.cell_data),
    ] {
        if let Some(node) = child(piece, section) {
            for a in arrays(node) {
                let comps = match a.attribute("NumberOfComponents") {
                    Some(_) => ctx.count_attr(a, "NumberOfComponents")?,
                    None => 1,
                };
                out.push(ctx.values(a, count.saturating_mul(comps))?);
            }
        }
    }
    grid.into_mesh(path)
}

/// Escapes text for an XML attribute.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        // Attribute-value normalisation would turn these into spaces.
        .replace('\n', "&#10;")
        .replace('\r', "&#13;")
        .replace('\t', "&#9;")
}

/// Bytes of one array as stored (little-endian).
enum Data {
    F32(Vec<f32>),
    I64(Vec<i64>),
    U8(Vec<u8>),
}

impl Data {
    fn type_name(&self) -> &'static str {
        match self {
            Data::F32(_) => "Float32",
            Data::I64(_) => "Int64",
            Data::U8(_) => "UInt8",
        }
    }

    fn bytes(&self) -> Vec<u8> {
        match self {
            Data::F32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Data::I64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Data::U8(v) => v.clone(),
        }
    }

    fn ascii(&self, per_line: usize) -> String {
        let mut s = String::new();
        let mut put = |i: usize, t: std::fmt::Arguments| {
            let _ = s.write_fmt(t);
            s.push(if (i + 1).is_multiple_of(per_line) {
                '\n'
            } else {
                ' '
            });
        };
        match self {
            Data::F32(v) => v
                .iter()
                .enumerate()
                .for_each(|(i, x)| put(i, format_args!("{x:?}"))),
            Data::I64(v) => v
                .iter()
                .enumerate()
                .for_each(|(i, x)| put(i, format_args!("{x}"))),
            Data::U8(v) => v
                .iter()
                .enumerate()
                .for_each(|(i, x)| put(i, format_args!("{x}"))),
        }
        s
    }
}

/// The `.vtu` document of `mesh` (see [`super`] for what it holds).
pub fn to_vtu_bytes(mesh: &TetMesh, encoding: VtkEncoding) -> Vec<u8> {
    let nt = mesh.tets.len();
    let nc = mesh.constrained.len();
    let mut appended: Vec<u8> = Vec::new();
    let mut s = String::with_capacity(64 * (mesh.points.len() + nt + nc) + 1024);
    let mut array = |s: &mut String, name: &str, comps: usize, data: Data, per_line: usize| {
        let _ = write!(s, "<DataArray type=\"{}\"", data.type_name());
        if comps != 1 {
            let _ = write!(s, " NumberOfComponents=\"{comps}\"");
        }
        let _ = write!(s, " Name=\"{}\"", escape(name));
        match encoding {
            VtkEncoding::Ascii => {
                let _ = write!(s, " format=\"ascii\">\n{}", data.ascii(per_line));
            }
            VtkEncoding::Binary => {
                let bytes = data.bytes();
                let mut block = (bytes.len() as u64).to_le_bytes().to_vec();
                block.extend_from_slice(&bytes);
                let _ = write!(s, " format=\"binary\">\n{}\n", base64::encode(&block));
            }
            VtkEncoding::Appended => {
                let bytes = data.bytes();
                let _ = write!(s, " format=\"appended\" offset=\"{}\">", appended.len());
                appended.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
                appended.extend_from_slice(&bytes);
            }
        }
        s.push_str("</DataArray>\n");
    };
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<FieldData>\n");
    array(
        &mut s,
        TRIANGLE_COUNT_FIELD,
        1,
        Data::I64(vec![i64::from(mesh.triangle_count)]),
        1,
    );
    let _ = writeln!(
        s,
        "</FieldData>\n<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.points.len(),
        nt + nc
    );
    s.push_str("<Points>\n");
    array(
        &mut s,
        "Points",
        3,
        Data::F32(mesh.points.iter().flat_map(|p| p.to_array()).collect()),
        3,
    );
    s.push_str("</Points>\n<Cells>\n");
    let conn = mesh
        .tets
        .iter()
        .flat_map(|t| t.map(i64::from))
        .chain(
            mesh.constrained
                .iter()
                .flat_map(|c| c.vertices.map(i64::from)),
        )
        .collect();
    array(&mut s, "connectivity", 1, Data::I64(conn), 4);
    let offsets = (1..=nt as i64)
        .map(|i| 4 * i)
        .chain((1..=nc as i64).map(|i| 4 * nt as i64 + 3 * i))
        .collect();
    array(&mut s, "offsets", 1, Data::I64(offsets), 1);
    let types = std::iter::repeat_n(VTK_TETRA, nt)
        .chain(std::iter::repeat_n(VTK_TRIANGLE, nc))
        .collect();
    array(&mut s, "types", 1, Data::U8(types), 1);
    let _ = writeln!(s, "</Cells>\n<CellData Scalars=\"{KIND_ARRAY}\">");
    let kinds = std::iter::repeat_n(0, nt)
        .chain(std::iter::repeat_n(1, nc))
        .collect();
    array(&mut s, KIND_ARRAY, 1, Data::U8(kinds), 1);
    let ids = std::iter::repeat_n(-1, nt)
        .chain(mesh.constrained.iter().map(|c| i64::from(c.triangle)))
        .collect();
    array(&mut s, TRIANGLE_ARRAY, 1, Data::I64(ids), 1);
    s.push_str("</CellData>\n");
    if let Some(field) = &mesh.attributes.scalars {
        let first = step_array_name(&field.name, 0, field.steps.len());
        let _ = writeln!(s, "<PointData Scalars=\"{}\">", escape(&first));
        for (k, step) in field.steps.iter().enumerate() {
            let name = step_array_name(&field.name, k, field.steps.len());
            array(&mut s, &name, 1, Data::F32(step.clone()), 9);
        }
        s.push_str("</PointData>\n");
    }
    s.push_str("</Piece>\n</UnstructuredGrid>\n");
    let mut out = s.into_bytes();
    if encoding == VtkEncoding::Appended {
        out.extend_from_slice(b"<AppendedData encoding=\"raw\">\n_");
        out.extend_from_slice(&appended);
        out.extend_from_slice(b"\n</AppendedData>\n");
    }
    out.extend_from_slice(b"</VTKFile>\n");
    out
}
