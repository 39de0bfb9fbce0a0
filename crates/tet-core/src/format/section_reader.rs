//! [`SectionReader`]: one section (or a range of it) of a mesh file at a
//! time, after the header checks of [`super::load`] (see the module docs of
//! [`crate::format`]).

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::ops::Range;
use std::path::{Path, PathBuf};

use bytemuck::Pod;
use crc32fast::Hasher;
use glam::{Vec2, Vec3};

use super::error::FormatError;
use super::header::{Header, parse_header};
use super::scalar_block::decode_name;
use super::scene_block::decode_scene;
use super::spec::{
    ELEMENT_BYTES, FLAG_MATERIALS, FLAG_NORMALS, FLAG_SCALARS, FLAG_SCENE, FLAG_UVS, HEADER_LEN,
    SCALAR_NAME_SLOT, SCENE_RECORD_BYTES, SECTION_NAMES,
};
use super::stream_writer::OptionalSections;
use super::words::from_le_words;
use crate::link::Link;
use crate::mesh::ConstrainedFace;
use crate::scene::SceneInfo;

/// Reads sections of a mesh file without loading the mesh.
///
/// [`SectionReader::open`] checks the header as [`super::load`] does
/// (magic, version, flags, counts and every section's bounds against the
/// real file length, header CRC), so every read is bounded by the file.
/// Reads return the elements as stored: vertex ids and links are not
/// checked against the counts, and the payload CRC only by
/// [`SectionReader::verify_payload`] (one streaming pass).
#[derive(Debug)]
pub struct SectionReader {
    path: PathBuf,
    file: File,
    header: Header,
}

impl SectionReader {
    /// Opens `path` and checks its header; the file is left positioned
    /// just after it.
    pub fn open(path: impl AsRef<Path>) -> Result<SectionReader, FormatError> {
        let path = path.as_ref().to_path_buf();
        let io = |source| FormatError::Io {
            path: path.clone(),
            source,
        };
        let mut file = File::open(&path).map_err(io)?;
        let actual = file.metadata().map_err(io)?.len();
        let mut head = Vec::with_capacity(HEADER_LEN);
        (&mut file)
            .take(HEADER_LEN as u64)
            .read_to_end(&mut head)
            .map_err(io)?;
        let header = parse_header(&head, actual, &path)?;
        Ok(SectionReader { path, file, header })
    }

    /// The open file (positioned after the header when just opened) and
    /// its checked header, for [`super::load_with_scene`].
    pub(super) fn into_parts(self) -> (File, Header) {
        (self.file, self.header)
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of points.
    pub fn point_count(&self) -> u64 {
        self.header.counts[0]
    }

    /// Number of tets (and of neighbour records).
    pub fn tet_count(&self) -> u64 {
        self.header.counts[1]
    }

    /// Number of constrained faces.
    pub fn constrained_count(&self) -> u64 {
        self.header.counts[3]
    }

    /// Number of scene triangles the constrained faces refer to.
    pub fn triangle_count(&self) -> u32 {
        self.header.triangle_count
    }

    /// The optional sections present.
    pub fn optional(&self) -> OptionalSections {
        let on = |bit: u32| self.header.flags & bit != 0;
        OptionalSections {
            normals: on(FLAG_NORMALS),
            uvs: on(FLAG_UVS),
            materials: on(FLAG_MATERIALS),
            scalars: on(FLAG_SCALARS),
        }
    }

    /// The file's length in bytes (checked against the real length).
    pub fn file_length(&self) -> u64 {
        self.header.file_length
    }

    fn io(&self, source: io::Error) -> FormatError {
        FormatError::Io {
            path: self.path.clone(),
            source,
        }
    }

    /// Elements `range` of section `i` (table order).
    fn read<T: Pod>(&mut self, i: usize, range: Range<u64>) -> Result<Vec<T>, FormatError> {
        debug_assert_eq!(size_of::<T>() as u64, ELEMENT_BYTES[i]);
        let (offset, length) = self.header.sections[i];
        let count = if self.optional().present(i) {
            length / ELEMENT_BYTES[i]
        } else {
            0
        };
        if range.start > range.end || range.end > count {
            return Err(FormatError::SectionRange {
                path: self.path.clone(),
                section: SECTION_NAMES[i],
                start: range.start,
                end: range.end,
                count,
            });
        }
        let mut v = vec![T::zeroed(); (range.end - range.start) as usize];
        self.read_at(offset + range.start * ELEMENT_BYTES[i], &mut v)?;
        Ok(v)
    }

    /// Fills `v` from the 4-byte little-endian words at byte `offset`.
    fn read_at<T: Pod>(&mut self, offset: u64, v: &mut [T]) -> Result<(), FormatError> {
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(v);
        let r = self
            .file
            .seek(SeekFrom::Start(offset))
            .and_then(|_| self.file.read_exact(bytes));
        if let Err(e) = r {
            return Err(self.io(e));
        }
        from_le_words(bytes);
        Ok(())
    }

    /// Points `range`.
    pub fn read_points(&mut self, range: Range<u64>) -> Result<Vec<Vec3>, FormatError> {
        self.read(0, range)
    }

    /// Tets `range` (vertex ids as stored).
    pub fn read_tets(&mut self, range: Range<u64>) -> Result<Vec<[u32; 4]>, FormatError> {
        self.read(1, range)
    }

    /// Neighbour records of tets `range` (links as stored).
    pub fn read_neighbors(&mut self, range: Range<u64>) -> Result<Vec<[Link; 4]>, FormatError> {
        self.read(2, range)
    }

    /// Constrained faces `range` (as stored).
    pub fn read_constrained(
        &mut self,
        range: Range<u64>,
    ) -> Result<Vec<ConstrainedFace>, FormatError> {
        self.read(3, range)
    }

    /// Normals `range` (a [`FormatError::SectionRange`] with count 0 when
    /// the file has none).
    pub fn read_normals(&mut self, range: Range<u64>) -> Result<Vec<Vec3>, FormatError> {
        self.read(4, range)
    }

    /// Texture coordinates `range` (count 0 when absent).
    pub fn read_uvs(&mut self, range: Range<u64>) -> Result<Vec<Vec2>, FormatError> {
        self.read(5, range)
    }

    /// Materials `range` (count 0 when absent).
    pub fn read_materials(&mut self, range: Range<u64>) -> Result<Vec<u32>, FormatError> {
        self.read(6, range)
    }

    /// Time steps of the scalar field (0 when the file has none).
    pub fn scalar_steps(&self) -> u32 {
        self.header.scalar_steps
    }

    /// The scalar field's name (`None` when the file has no field); a slot
    /// that is not NUL-padded UTF-8 is a [`FormatError::BadField`].
    pub fn read_scalar_name(&mut self) -> Result<Option<String>, FormatError> {
        if self.header.flags & FLAG_SCALARS == 0 {
            return Ok(None);
        }
        let mut slot = [0u8; SCALAR_NAME_SLOT as usize];
        let r = self
            .file
            .seek(SeekFrom::Start(self.header.scalars.0))
            .and_then(|_| self.file.read_exact(&mut slot));
        if let Err(e) = r {
            return Err(self.io(e));
        }
        decode_name(&slot, &self.path).map(Some)
    }

    /// Values `range` (point indices) of time step `step` of the scalar
    /// field, as stored (finiteness is checked by [`super::load`] only). A
    /// step or range the file does not have is a
    /// [`FormatError::SectionRange`] (count 0 without a field).
    pub fn read_scalars(&mut self, step: u32, range: Range<u64>) -> Result<Vec<f32>, FormatError> {
        let points = self.point_count();
        let steps = u64::from(self.header.scalar_steps);
        let out_of = |start, end, count| FormatError::SectionRange {
            path: self.path.clone(),
            section: "scalars",
            start,
            end,
            count,
        };
        if u64::from(step) >= steps {
            return Err(out_of(u64::from(step), u64::from(step) + 1, steps));
        }
        if range.start > range.end || range.end > points {
            return Err(out_of(range.start, range.end, points));
        }
        let mut v = vec![0f32; (range.end - range.start) as usize];
        let at =
            self.header.scalars.0 + SCALAR_NAME_SLOT + (u64::from(step) * points + range.start) * 4;
        self.read_at(at, &mut v)?;
        Ok(v)
    }

    /// The scene block, checked as [`super::load_with_scene`] does (empty
    /// when the file has none).
    pub fn read_scene(&mut self) -> Result<SceneInfo, FormatError> {
        if self.header.flags & FLAG_SCENE == 0 {
            return Ok(SceneInfo::default());
        }
        let (offset, length) = self.header.scene;
        let mut records = vec![[0u32; 12]; (length / SCENE_RECORD_BYTES) as usize];
        self.read_at(offset, &mut records)?;
        decode_scene(&records, &self.path)
    }

    /// Reads the whole payload once (64 KiB at a time) and compares its
    /// CRC with the header's ([`FormatError::ChecksumMismatch`]).
    pub fn verify_payload(&mut self) -> Result<(), FormatError> {
        if let Err(e) = self.file.seek(SeekFrom::Start(HEADER_LEN as u64)) {
            return Err(self.io(e));
        }
        let mut crc = Hasher::new();
        let mut buf = vec![0u8; 1 << 16];
        let mut left = self.header.file_length - HEADER_LEN as u64;
        while left > 0 {
            let n = left.min(buf.len() as u64) as usize;
            if let Err(e) = self.file.read_exact(&mut buf[..n]) {
                return Err(self.io(e));
            }
            crc.update(&buf[..n]);
            left -= n as u64;
        }
        let computed = crc.finalize();
        if computed != self.header.payload_crc {
            return Err(FormatError::ChecksumMismatch {
                path: self.path.clone(),
                part: "payload",
                stored: self.header.payload_crc,
                computed,
            });
        }
        Ok(())
    }
}
