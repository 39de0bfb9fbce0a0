//! What a VTK unstructured grid holds, as read from either format, and its
//! conversion to a validated [`TetMesh`] with its scalar field (and back,
//! for the writers).

use std::path::Path;

use glam::{DVec3, Vec3};
use tet_core::{ScalarField, TetMesh};

use super::{VTK_TETRA, VTK_TRIANGLE, VtkError};

/// Name of the cell-data array telling tets (0) from constrained faces (1).
pub const KIND_ARRAY: &str = "kind";
/// Name of the cell-data array with a constrained face's scene triangle.
pub const TRIANGLE_ARRAY: &str = "triangle";
/// Name of the field-data value holding [`TetMesh::triangle_count`].
pub const TRIANGLE_COUNT_FIELD: &str = "triangle_count";

/// A data array of a grid: its name, values as `f64` (every VTK numeric
/// type up to 32 bits is exact in it; 64-bit integers beyond 2⁵³ are not
/// indices we accept anyway), components per tuple, and where it was
/// (for errors).
#[derive(Clone, Debug, Default)]
pub(crate) struct Array {
    pub name: String,
    pub components: usize,
    pub values: Vec<f64>,
    /// Line of the array's header (legacy) or element (XML).
    pub line: usize,
}

/// An unstructured grid as parsed, before any check across sections.
#[derive(Clone, Debug, Default)]
pub(crate) struct Grid {
    pub points: Vec<[f64; 3]>,
    /// Flattened connectivity.
    pub connectivity: Vec<u64>,
    /// End offset of each cell in `connectivity`.
    pub offsets: Vec<u64>,
    pub types: Vec<u8>,
    pub point_data: Vec<Array>,
    pub cell_data: Vec<Array>,
    pub triangle_count: Option<u64>,
}

fn cell_error(path: &Path, cell: usize, message: String) -> VtkError {
    VtkError::Cell {
        path: path.to_path_buf(),
        cell,
        message,
    }
}

/// Splits `name_t0000`, `name_t0001`, … into (`name`, step index).
fn step_suffix(name: &str) -> Option<(&str, usize)> {
    let (base, digits) = name.rsplit_once("_t")?;
    (digits.len() == 4 && digits.bytes().all(|b| b.is_ascii_digit()))
        .then(|| (base, digits.parse().ok()))
        .and_then(|(b, d)| Some((b, d?)))
}

/// The name the writers give step `step` of `steps` of field `name`.
pub(crate) fn step_array_name(name: &str, step: usize, steps: usize) -> String {
    if steps == 1 {
        name.to_string()
    } else {
        format!("{name}_t{step:04}")
    }
}

impl Grid {
    /// Converts to a validated mesh (see [`super`] for the rules).
    pub(crate) fn into_mesh(self, path: &Path) -> Result<TetMesh, VtkError> {
        let n = self.points.len();
        let cells = self.types.len();
        if self.offsets.len() != cells {
            return Err(VtkError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: format!("{} cell offsets for {cells} cell types", self.offsets.len()),
            });
        }
        let cell_array = |name: &str| self.cell_data.iter().find(|a| a.name == name);
        for a in self
            .cell_data
            .iter()
            .filter(|a| a.name == KIND_ARRAY || a.name == TRIANGLE_ARRAY)
        {
            if a.values.len() != cells || a.components != 1 {
                return Err(VtkError::Parse {
                    path: path.to_path_buf(),
                    line: a.line,
                    message: format!(
                        "cell array {} has {} values of {} components, expected {cells} of 1",
                        a.name,
                        a.values.len(),
                        a.components
                    ),
                });
            }
        }
        if let Some(i) = self
            .points
            .iter()
            .position(|p| p.iter().any(|&x| !(x as f32).is_finite()))
        {
            return Err(VtkError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: format!("point {i} {:?} is not finite in f32", self.points[i]),
            });
        }
        let kind = cell_array(KIND_ARRAY);
        let triangle = cell_array(TRIANGLE_ARRAY);
        let points: Vec<Vec3> = self
            .points
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let mut tets = Vec::new();
        let mut tris = Vec::new();
        let mut max_triangle = None;
        let mut start = 0u64;
        for (c, (&ty, &end)) in self.types.iter().zip(&self.offsets).enumerate() {
            if end < start || end > self.connectivity.len() as u64 {
                return Err(cell_error(
                    path,
                    c,
                    format!(
                        "offset {end} is out of order or past the connectivity ({} entries)",
                        self.connectivity.len()
                    ),
                ));
            }
            let ids = &self.connectivity[start as usize..end as usize];
            start = end;
            let wanted = match ty {
                VTK_TETRA => 4,
                VTK_TRIANGLE => 3,
                _ => {
                    return Err(cell_error(
                        path,
                        c,
                        format!(
                            "VTK cell type {ty} is not a tetrahedron ({VTK_TETRA}) or a marked constrained triangle ({VTK_TRIANGLE})"
                        ),
                    ));
                }
            };
            if ids.len() != wanted {
                return Err(cell_error(
                    path,
                    c,
                    format!("type {ty} needs {wanted} vertices, has {}", ids.len()),
                ));
            }
            let mut v = [0u32; 4];
            for (slot, &id) in ids.iter().enumerate() {
                if id >= n as u64 {
                    return Err(cell_error(
                        path,
                        c,
                        format!("vertex {id} is out of range ({n} points)"),
                    ));
                }
                v[slot] = id as u32;
            }
            if ty == VTK_TETRA {
                if kind.is_some_and(|k| k.values[c] != 0.0) {
                    return Err(cell_error(
                        path,
                        c,
                        "a tetrahedron marked as a constrained face".into(),
                    ));
                }
                let [a, b, cc, d] = v.map(|i| DVec3::from_array(self.points[i as usize]));
                let o64 = tet_core::predicates::orient3d(a, b, cc, d);
                let t = if o64 < 0.0 {
                    [v[1], v[0], v[2], v[3]]
                } else {
                    v
                };
                let p = t.map(|i| points[i as usize]);
                if o64 == 0.0 || tet_core::predicates::orient3d_f32(p[0], p[1], p[2], p[3]) <= 0.0 {
                    return Err(cell_error(
                        path,
                        c,
                        "the tetrahedron is flat, or flat/inverted after rounding to f32".into(),
                    ));
                }
                tets.push(t);
            } else {
                if kind.is_none_or(|k| k.values[c] != 1.0) {
                    return Err(cell_error(
                        path,
                        c,
                        format!(
                            "a triangle without the constrained-face marker (cell data {KIND_ARRAY} = 1)"
                        ),
                    ));
                }
                let Some(triangle) = triangle else {
                    return Err(cell_error(
                        path,
                        c,
                        format!("a constrained face without the cell array {TRIANGLE_ARRAY}"),
                    ));
                };
                let id = triangle.values[c];
                if !(id >= 0.0 && id < f64::from(u32::MAX) && id.fract() == 0.0) {
                    return Err(cell_error(
                        path,
                        c,
                        format!("{TRIANGLE_ARRAY} id {id} is not a scene triangle index"),
                    ));
                }
                max_triangle = max_triangle.max(Some(id as u32));
                tris.push(([v[0], v[1], v[2]], id as u32));
            }
        }
        if start != self.connectivity.len() as u64 {
            return Err(VtkError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: format!(
                    "the cells use {start} connectivity entries, the file has {}",
                    self.connectivity.len()
                ),
            });
        }
        let implied = max_triangle.map_or(0, |m| u64::from(m) + 1);
        let triangle_count = self.triangle_count.unwrap_or(implied);
        if triangle_count < implied || triangle_count > u64::from(u32::MAX) {
            return Err(VtkError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: format!(
                    "{TRIANGLE_COUNT_FIELD} {triangle_count} does not cover triangle id {}",
                    implied.saturating_sub(1)
                ),
            });
        }
        let scalars = field_of(&self.point_data, n, path)?;
        let mut mesh =
            TetMesh::assemble(points, tets, &tris, triangle_count as u32).map_err(|source| {
                VtkError::Mesh {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        mesh.attributes.scalars = scalars;
        mesh.validate().map_err(|source| VtkError::Mesh {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(mesh)
    }
}

/// The scalar field of the point-data arrays: every one-component array is
/// a time step, in file order. The field is named after the first array;
/// when there are several and they are exactly `name_t0000`,
/// `name_t0001`, … (what the writers produce), the suffix is dropped.
fn field_of(arrays: &[Array], n: usize, path: &Path) -> Result<Option<ScalarField>, VtkError> {
    let scalars: Vec<&Array> = arrays.iter().filter(|a| a.components == 1).collect();
    let Some(first) = scalars.first() else {
        return Ok(None);
    };
    let mut steps = Vec::with_capacity(scalars.len());
    for a in &scalars {
        if a.values.len() != n {
            return Err(VtkError::Parse {
                path: path.to_path_buf(),
                line: a.line,
                message: format!(
                    "point array {} has {} values, expected {n}",
                    a.name,
                    a.values.len()
                ),
            });
        }
        let mut step = Vec::with_capacity(n);
        for (i, &v) in a.values.iter().enumerate() {
            let f = v as f32;
            if !f.is_finite() {
                return Err(VtkError::Parse {
                    path: path.to_path_buf(),
                    line: a.line,
                    message: format!("point array {} value {i} is {v}: not a finite f32", a.name),
                });
            }
            step.push(f);
        }
        steps.push(step);
    }
    let series = scalars.len() > 1
        && scalars.iter().enumerate().all(|(k, a)| {
            step_suffix(&a.name).is_some_and(|(base, s)| {
                s == k && Some(base) == step_suffix(&first.name).map(|b| b.0)
            })
        });
    let name = if series {
        step_suffix(&first.name).map_or(first.name.clone(), |(b, _)| b.to_string())
    } else {
        first.name.clone()
    };
    tet_core::fields::check_name(&name).map_err(|source| VtkError::Mesh {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(Some(ScalarField { name, steps }))
}

/// Element types of VTK data arrays (legacy and XML name them differently:
/// see each reader's `data_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum DataType {
    F32,
    F64,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
}

impl DataType {
    /// Bytes per value.
    pub(super) fn size(self) -> usize {
        match self {
            DataType::I8 | DataType::U8 => 1,
            DataType::I16 | DataType::U16 => 2,
            DataType::F32 | DataType::I32 | DataType::U32 => 4,
            DataType::F64 | DataType::I64 | DataType::U64 => 8,
        }
    }

    /// The value in `b` (`self.size()` bytes) in byte order `big`.
    pub(super) fn decode(self, b: &[u8], big: bool) -> f64 {
        let mut x = [0u8; 8];
        x[..b.len()].copy_from_slice(b);
        if big {
            x[..b.len()].reverse();
        }
        let w4 = [x[0], x[1], x[2], x[3]];
        match self {
            DataType::F32 => f64::from(f32::from_le_bytes(w4)),
            DataType::F64 => f64::from_le_bytes(x),
            DataType::I8 => f64::from(x[0] as i8),
            DataType::U8 => f64::from(x[0]),
            DataType::I16 => f64::from(i16::from_le_bytes([x[0], x[1]])),
            DataType::U16 => f64::from(u16::from_le_bytes([x[0], x[1]])),
            DataType::I32 => f64::from(i32::from_le_bytes(w4)),
            DataType::U32 => f64::from(u32::from_le_bytes(w4)),
            DataType::I64 => i64::from_le_bytes(x) as f64,
            DataType::U64 => u64::from_le_bytes(x) as f64,
        }
    }
}
