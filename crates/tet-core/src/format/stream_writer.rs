//! [`StreamWriter`]: a mesh file written section by section, a slice at a
//! time, so the whole mesh never has to be in memory (see the module docs
//! of [`crate::format`]).

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crc32fast::Hasher;
use glam::{Vec2, Vec3};

use super::error::FormatError;
use super::header::{HeaderFields, header_bytes};
use super::scalar_block::name_slot;
use super::scene_block::scene_records;
use super::spec::{
    ELEMENT_BYTES, FLAG_MATERIALS, FLAG_NORMALS, FLAG_SCALARS, FLAG_SCENE, FLAG_UVS, HEADER_FIELDS,
    HEADER_LEN, SECTION_NAMES,
};
use super::words::{hash_le_words, padding, write_le_words};
use crate::link::{Link, MAX_TETS};
use crate::mesh::{Attributes, ConstrainedFace};
use crate::scene::SceneInfo;

/// Which optional sections a file has (flag bits 0–2, and bit 4 for the
/// scalar block). A present section may be empty; an absent one takes no
/// bytes and no table entry. A present scalar block needs at least one step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OptionalSections {
    /// Per-point normals (flag bit 0).
    pub normals: bool,
    /// Per-point texture coordinates (flag bit 1).
    pub uvs: bool,
    /// Per-triangle materials (flag bit 2).
    pub materials: bool,
    /// A per-point scalar field (flag bit 4; see
    /// [`StreamWriter::append_scalar_step`]).
    pub scalars: bool,
}

impl OptionalSections {
    /// The optional sections a mesh with `attributes` has.
    pub fn of(attributes: &Attributes) -> OptionalSections {
        OptionalSections {
            normals: attributes.normals.is_some(),
            uvs: attributes.uvs.is_some(),
            materials: attributes.materials.is_some(),
            scalars: attributes.scalars.is_some(),
        }
    }

    /// Flag bits 0–2.
    fn flags(self) -> u32 {
        [
            (self.normals, FLAG_NORMALS),
            (self.uvs, FLAG_UVS),
            (self.materials, FLAG_MATERIALS),
            (self.scalars, FLAG_SCALARS),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .fold(0, |f, (_, bit)| f | bit)
    }

    /// Whether section `i` (table order) is in a file with these sections.
    pub(super) fn present(self, i: usize) -> bool {
        match i {
            0..=3 => true,
            4 => self.normals,
            5 => self.uvs,
            6 => self.materials,
            _ => self.scalars,
        }
    }
}

/// Writes a mesh file a slice at a time: append to the sections in table
/// order (points, tets, neighbors, constrained, normals, uvs, materials;
/// each any number of times, a section never reopened after a later one
/// was written), then [`StreamWriter::finish`]. The bytes go to a
/// temporary file in the target's directory; the header, written last,
/// takes its counts and section table from what was appended; `finish`
/// syncs the file and renames it over the target. Dropped unfinished (or
/// after an error), the writer removes its temporary file and the target is
/// untouched.
///
/// Element values are not checked (a mesh is validated where it is built
/// or loaded); `finish` checks what the header must agree on: as many
/// neighbour records as tets, attribute sections of their counts' length,
/// counts within the format's limits.
#[derive(Debug)]
pub struct StreamWriter {
    path: PathBuf,
    tmp: PathBuf,
    /// `None` once finished (the temporary file is then renamed away).
    out: Option<BufWriter<File>>,
    crc: Hasher,
    /// Bytes written so far, the header's placeholder included.
    end: u64,
    /// (offset, length) per section in table order, then the scalar block
    /// (index 7, name slot included).
    table: [(u64, u64); 8],
    /// Name and steps of the scalar block written so far.
    scalar_name: Option<String>,
    scalar_steps: u32,
    /// The section being written, if one was started.
    open: Option<usize>,
    optional: OptionalSections,
    triangle_count: u32,
}

impl StreamWriter {
    /// Starts a file that will replace `path` on [`StreamWriter::finish`]:
    /// `triangle_count` scene triangles, the `optional` sections.
    pub fn create(
        path: impl AsRef<Path>,
        triangle_count: u32,
        optional: OptionalSections,
    ) -> Result<StreamWriter, FormatError> {
        let path = path.as_ref().to_path_buf();
        let tmp = temp_path(&path)?;
        let io = |source| FormatError::Io {
            path: path.clone(),
            source,
        };
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(io)?;
        let mut w = StreamWriter {
            path: path.clone(),
            tmp,
            out: Some(BufWriter::with_capacity(1 << 16, file)),
            crc: Hasher::new(),
            end: 0,
            table: [(0, 0); 8],
            scalar_name: None,
            scalar_steps: 0,
            open: None,
            optional,
            triangle_count,
        };
        // The header's place; overwritten by `finish`.
        w.write_raw(&[0u8; HEADER_LEN])?;
        Ok(w)
    }

    /// The file this writer replaces.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Elements appended to the points section so far.
    pub fn points_written(&self) -> u64 {
        self.table[0].1 / ELEMENT_BYTES[0]
    }

    /// Elements appended to the tets section so far.
    pub fn tets_written(&self) -> u64 {
        self.table[1].1 / ELEMENT_BYTES[1]
    }

    /// Elements appended to the constrained section so far.
    pub fn constrained_written(&self) -> u64 {
        self.table[3].1 / ELEMENT_BYTES[3]
    }

    /// Appends points (`[f32; 3]`).
    pub fn append_points(&mut self, points: &[Vec3]) -> Result<(), FormatError> {
        self.append(0, bytemuck::cast_slice(points))
    }

    /// Appends tets (four vertex ids each).
    pub fn append_tets(&mut self, tets: &[[u32; 4]]) -> Result<(), FormatError> {
        self.append(1, bytemuck::cast_slice(tets))
    }

    /// Appends neighbour records (four links each, one per tet).
    pub fn append_neighbors(&mut self, neighbors: &[[Link; 4]]) -> Result<(), FormatError> {
        self.append(2, bytemuck::cast_slice(neighbors))
    }

    /// Appends constrained faces.
    pub fn append_constrained(&mut self, faces: &[ConstrainedFace]) -> Result<(), FormatError> {
        self.append(3, bytemuck::cast_slice(faces))
    }

    /// Appends normals (needs [`OptionalSections::normals`]).
    pub fn append_normals(&mut self, normals: &[Vec3]) -> Result<(), FormatError> {
        self.append(4, bytemuck::cast_slice(normals))
    }

    /// Appends texture coordinates (needs [`OptionalSections::uvs`]).
    pub fn append_uvs(&mut self, uvs: &[Vec2]) -> Result<(), FormatError> {
        self.append(5, bytemuck::cast_slice(uvs))
    }

    /// Appends materials (needs [`OptionalSections::materials`]).
    pub fn append_materials(&mut self, materials: &[u32]) -> Result<(), FormatError> {
        self.append(6, bytemuck::cast_slice(materials))
    }

    /// Appends one time step of the scalar field named `name` (needs
    /// [`OptionalSections::scalars`]): one value per point written, after
    /// every other section. Every step must carry the same name.
    pub fn append_scalar_step(&mut self, name: &str, values: &[f32]) -> Result<(), FormatError> {
        let refuse = |detail: String| FormatError::SectionOrder {
            path: self.path.clone(),
            section: "scalars",
            detail,
        };
        let Some(slot) = name_slot(name) else {
            return Err(refuse(format!(
                "field name {name:?} does not fit the {}-byte slot (or holds a control character)",
                slot_len()
            )));
        };
        let points = self.points_written();
        if values.len() as u64 != points {
            return Err(refuse(format!(
                "step {} has {} values, the file has {points} points",
                self.scalar_steps,
                values.len()
            )));
        }
        if self.scalar_steps == u32::MAX {
            return Err(refuse("too many steps".into()));
        }
        match &self.scalar_name {
            Some(first) if first != name => {
                return Err(refuse(format!(
                    "step {} is named {name:?}, the field {first:?}",
                    self.scalar_steps
                )));
            }
            Some(_) => {}
            None => {
                self.append_with(7, &slot, false)?;
                self.scalar_name = Some(name.to_string());
            }
        }
        self.append(7, bytemuck::cast_slice(values))?;
        self.scalar_steps += 1;
        Ok(())
    }

    fn io(&self, source: io::Error) -> FormatError {
        FormatError::Io {
            path: self.path.clone(),
            source,
        }
    }

    /// Writes bytes as they are (not hashed: the header's placeholder).
    fn write_raw(&mut self, bytes: &[u8]) -> Result<(), FormatError> {
        let out = self.out.as_mut().expect("an unfinished writer has a file");
        out.write_all(bytes).map_err(|e| FormatError::Io {
            path: self.path.clone(),
            source: e,
        })?;
        self.end += bytes.len() as u64;
        Ok(())
    }

    /// Writes and hashes payload bytes made of 4-byte words.
    fn write_payload(&mut self, bytes: &[u8]) -> Result<(), FormatError> {
        self.write_payload_with(bytes, true)
    }

    /// Writes and hashes payload bytes: 4-byte words (`words`) or plain
    /// bytes (the scalar name slot).
    fn write_payload_with(&mut self, bytes: &[u8], words: bool) -> Result<(), FormatError> {
        let out = self.out.as_mut().expect("an unfinished writer has a file");
        let written = if words {
            write_le_words(out, bytes)
        } else {
            out.write_all(bytes)
        };
        if let Err(e) = written {
            return Err(self.io(e));
        }
        if words {
            hash_le_words(&mut self.crc, bytes);
        } else {
            self.crc.update(bytes);
        }
        self.end += bytes.len() as u64;
        Ok(())
    }

    /// Ends the open section (its zero padding) and starts every present
    /// section before `next` as empty, so that `next` starts at `self.end`.
    fn advance_to(&mut self, next: usize) -> Result<(), FormatError> {
        let from = match self.open {
            Some(i) => {
                let pad = padding(self.table[i].1) as usize;
                self.write_payload(&[0u8; 8][..pad])?;
                i + 1
            }
            None => 0,
        };
        for k in from..next {
            if self.optional.present(k) {
                self.table[k] = (self.end, 0);
            }
        }
        Ok(())
    }

    fn append(&mut self, i: usize, bytes: &[u8]) -> Result<(), FormatError> {
        self.append_with(i, bytes, true)
    }

    fn append_with(&mut self, i: usize, bytes: &[u8], words: bool) -> Result<(), FormatError> {
        let refuse = |detail: String| FormatError::SectionOrder {
            path: self.path.clone(),
            section: section_name(i),
            detail,
        };
        if !self.optional.present(i) {
            return Err(refuse(
                "the file was created without this optional section".into(),
            ));
        }
        match self.open {
            Some(j) if j == i => {}
            Some(j) if j > i => {
                return Err(refuse(format!(
                    "section {} was already started (sections go in table order)",
                    section_name(j)
                )));
            }
            _ => {
                self.advance_to(i)?;
                self.table[i] = (self.end, 0);
                self.open = Some(i);
            }
        }
        self.write_payload_with(bytes, words)?;
        self.table[i].1 += bytes.len() as u64;
        Ok(())
    }

    /// [`StreamWriter::finish_with_scene`] without a scene block.
    pub fn finish(self) -> Result<u64, FormatError> {
        self.finish_with_scene(&SceneInfo::default())
    }

    /// Ends the file: sections never written are present and empty, a
    /// scene block holds `scene` (none when it is empty), the header is
    /// written, the file synced and renamed over the target. Returns the
    /// file's length. On error the temporary file is removed.
    pub fn finish_with_scene(mut self, scene: &SceneInfo) -> Result<u64, FormatError> {
        self.advance_to(8)?;
        if self.optional.scalars && self.scalar_steps == 0 {
            return Err(FormatError::BadField {
                path: self.path.clone(),
                field: "scalar_steps",
                detail: "the file was created with a scalar field but no step was appended".into(),
            });
        }
        let count = |i: usize| self.table[i].1 / ELEMENT_BYTES[i];
        let (points, tets, constrained) = (count(0), count(1), count(3));
        let mismatch = |i: usize, expected: u64| FormatError::SizeMismatch {
            path: self.path.clone(),
            field: HEADER_FIELDS[10 + 2 * i].0,
            expected: expected * ELEMENT_BYTES[i],
            found: self.table[i].1,
        };
        if count(2) != tets {
            return Err(mismatch(2, tets));
        }
        for (i, expected) in [
            (4, points),
            (5, points),
            (6, u64::from(self.triangle_count)),
        ] {
            if self.optional.present(i) && count(i) != expected {
                return Err(mismatch(i, expected));
            }
        }
        for (field, n, limit) in [
            ("point_count", points, u64::from(u32::MAX)),
            ("tet_count", tets, u64::from(MAX_TETS) - 1),
            ("constrained_count", constrained, u64::from(MAX_TETS) - 1),
        ] {
            if n > limit {
                return Err(FormatError::BadField {
                    path: self.path.clone(),
                    field,
                    detail: format!("{n} exceeds the limit {limit}"),
                });
            }
        }
        let records = scene_records(scene);
        self.write_payload(bytemuck::cast_slice(&records))?;
        let flags = self.optional.flags() | if records.is_empty() { 0 } else { FLAG_SCENE };
        let head = header_bytes(&HeaderFields {
            flags,
            file_length: self.end,
            triangle_count: self.triangle_count,
            scalar_steps: self.scalar_steps,
            counts: [points, tets, constrained],
            table: self.table[..7].try_into().expect("seven table entries"),
            payload_crc: self.crc.clone().finalize(),
        });
        let out = self.out.take().expect("an unfinished writer has a file");
        let file_length = self.end;
        let result = (|| -> io::Result<()> {
            let mut file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
            file.seek(SeekFrom::Start(0))?;
            file.write_all(&head)?;
            file.sync_all()?;
            drop(file);
            fs::rename(&self.tmp, &self.path)
        })();
        result.map_err(|e| self.io(e))?;
        Ok(file_length)
    }
}

impl Drop for StreamWriter {
    /// An unfinished writer (never finished, or finishing failed before the
    /// rename) removes its temporary file.
    fn drop(&mut self) {
        drop(self.out.take());
        if self.tmp.exists() {
            let _ = fs::remove_file(&self.tmp);
        }
    }
}

/// Name of section `i` in table order; 7 is the scalar block.
fn section_name(i: usize) -> &'static str {
    SECTION_NAMES.get(i).copied().unwrap_or("scalars")
}

/// Bytes of the scalar name slot.
fn slot_len() -> u64 {
    super::spec::SCALAR_NAME_SLOT
}

/// A fresh temporary path in `path`'s directory, named after it (so that
/// renaming it over `path` is atomic: same file system).
fn temp_path(path: &Path) -> Result<PathBuf, FormatError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| FormatError::Io {
        path: path.to_path_buf(),
        source: io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Ok(dir.join(format!(
        ".{}.tmp-{}-{}",
        name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )))
}
