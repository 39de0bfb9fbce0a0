//! Time series as ParaView collections (`.pvd`): one VTK file per time
//! step, listed by `<DataSet timestep=… file=…/>` elements. Reading joins
//! the files into one mesh whose field has every file's steps, in
//! `timestep` order (file order among equal or missing timesteps); all
//! files must hold the same mesh. Writing puts each step in its own
//! `.vtu` next to the `.pvd`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use roxmltree::Document;
use tet_core::{ScalarField, TetMesh};

use super::xml::to_vtu_bytes;
use super::{VtkEncoding, VtkError, atomic_write, read_bytes, read_vtk};

fn parse_err(path: &Path, line: usize, message: String) -> VtkError {
    VtkError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    }
}

/// Reads a `.pvd` collection and the files it lists (see the module docs).
pub fn read_pvd(path: &Path) -> Result<TetMesh, VtkError> {
    let bytes = read_bytes(path)?;
    let text =
        std::str::from_utf8(&bytes).map_err(|_| parse_err(path, 0, "not UTF-8 text".into()))?;
    let doc = Document::parse(text)
        .map_err(|e| parse_err(path, e.pos().row as usize, format!("XML: {e}")))?;
    let line = |n: roxmltree::Node| doc.text_pos_at(n.range().start).row as usize;
    let root = doc.root_element();
    if !root.has_tag_name("VTKFile") || root.attribute("type") != Some("Collection") {
        return Err(parse_err(
            path,
            line(root),
            "not a VTKFile of type Collection".into(),
        ));
    }
    let collection = root
        .children()
        .find(|n| n.has_tag_name("Collection"))
        .ok_or_else(|| parse_err(path, line(root), "no <Collection>".into()))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut entries: Vec<(f64, PathBuf, usize)> = Vec::new();
    for ds in collection.children().filter(|n| n.has_tag_name("DataSet")) {
        if ds.attribute("part").is_some_and(|p| p != "0") {
            return Err(parse_err(
                path,
                line(ds),
                "several parts per step are not supported".into(),
            ));
        }
        let file = ds
            .attribute("file")
            .ok_or_else(|| parse_err(path, line(ds), "<DataSet> without a file".into()))?;
        let t = match ds.attribute("timestep") {
            Some(t) => t
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite())
                .ok_or_else(|| {
                    parse_err(path, line(ds), format!("timestep {t:?} is not a number"))
                })?,
            None => 0.0,
        };
        entries.push((t, dir.join(file), line(ds)));
    }
    if entries.is_empty() {
        return Err(parse_err(
            path,
            line(collection),
            "the collection lists no data set".into(),
        ));
    }
    entries.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut mesh: Option<TetMesh> = None;
    let mut name = String::new();
    let mut steps = Vec::new();
    for (k, (_, file, at)) in entries.iter().enumerate() {
        let mut m = read_vtk(file)?;
        let Some(field) = m.attributes.scalars.take() else {
            return Err(parse_err(
                path,
                *at,
                format!("data set {k} ({}) has no point scalars", file.display()),
            ));
        };
        match &mesh {
            None => {
                name = field.name;
                mesh = Some(m);
            }
            Some(first) if *first != m => {
                return Err(parse_err(
                    path,
                    *at,
                    format!(
                        "data set {k} ({}) holds another mesh than data set 0",
                        file.display()
                    ),
                ));
            }
            Some(_) => {}
        }
        steps.extend(field.steps);
    }
    let mut mesh = mesh.expect("at least one data set");
    mesh.attributes.scalars = Some(ScalarField { name, steps });
    mesh.validate().map_err(|source| VtkError::Mesh {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(mesh)
}

/// Writes `mesh` as a `.pvd` collection at `path` and one `.vtu` per time
/// step of its field beside it (`<stem>_t0000.vtu`, …; timestep = step
/// index), each with that step alone. A mesh without a field is written as
/// one data set without point data (which [`read_pvd`] refuses).
pub fn write_pvd(path: &Path, mesh: &TetMesh, encoding: VtkEncoding) -> Result<(), VtkError> {
    let stem = path
        .file_stem()
        .map_or("series".into(), |s| s.to_string_lossy().into_owned());
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n",
    );
    let steps = mesh
        .attributes
        .scalars
        .as_ref()
        .map_or(1, |f| f.steps.len());
    for k in 0..steps {
        let file = format!("{stem}_t{k:04}.vtu");
        let mut one = TetMesh {
            attributes: Default::default(),
            ..mesh.clone()
        };
        one.attributes.scalars = mesh.attributes.scalars.as_ref().map(|f| ScalarField {
            name: f.name.clone(),
            steps: vec![f.steps[k].clone()],
        });
        atomic_write(&dir.join(&file), &to_vtu_bytes(&one, encoding))?;
        let _ = writeln!(
            pvd,
            "<DataSet timestep=\"{k}\" part=\"0\" file=\"{}\"/>",
            file.replace('&', "&amp;")
                .replace('"', "&quot;")
                .replace('<', "&lt;")
        );
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    atomic_write(path, pvd.as_bytes())
}
