//! Loading a whole mesh: header checks, sections straight into typed
//! vectors, CRCs, then [`TetMesh::validate`].

use std::fs::File;
use std::io::{self, BufReader, Read};
use std::path::Path;

use bytemuck::Pod;
use crc32fast::Hasher;
use glam::{Vec2, Vec3};

use super::error::{FormatError, IN_MEMORY};
use super::header::{Header, parse_header};
use super::scalar_block::decode_name;
use super::scene_block::decode_scene;
use super::section_reader::SectionReader;
use super::spec::{
    FLAG_MATERIALS, FLAG_NORMALS, FLAG_SCALARS, FLAG_SCENE, FLAG_UVS, HEADER_LEN, SCALAR_NAME_SLOT,
};
use super::words::from_le_words;
use crate::fields::ScalarField;
use crate::link::Link;
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};
use crate::scene::SceneInfo;

/// A sequential byte source positioned just after the header.
trait Source {
    fn read_exact_into(&mut self, buf: &mut [u8]) -> io::Result<()>;
}

impl Source for &[u8] {
    fn read_exact_into(&mut self, buf: &mut [u8]) -> io::Result<()> {
        Read::read_exact(self, buf)
    }
}

struct FileSource(BufReader<File>);

impl Source for FileSource {
    fn read_exact_into(&mut self, buf: &mut [u8]) -> io::Result<()> {
        self.0.read_exact(buf)
    }
}

/// Reads the payload section by section into typed vectors, hashing every
/// byte (padding included) in file order.
struct PayloadReader<'a, S: Source> {
    src: S,
    pos: u64,
    crc: Hasher,
    path: &'a Path,
}

impl<S: Source> PayloadReader<'_, S> {
    fn io(&self, source: io::Error) -> FormatError {
        FormatError::Io {
            path: self.path.to_path_buf(),
            source,
        }
    }

    /// Consumes (and hashes) bytes up to absolute offset `to`.
    fn skip_to(&mut self, to: u64) -> Result<(), FormatError> {
        let mut buf = [0u8; 4096];
        while self.pos < to {
            let n = (to - self.pos).min(buf.len() as u64) as usize;
            self.src
                .read_exact_into(&mut buf[..n])
                .map_err(|e| self.io(e))?;
            self.crc.update(&buf[..n]);
            self.pos += n as u64;
        }
        Ok(())
    }

    /// Reads `N` plain bytes (not words) at absolute offset `offset`.
    fn raw<const N: usize>(&mut self, offset: u64) -> Result<[u8; N], FormatError> {
        self.skip_to(offset)?;
        let mut buf = [0u8; N];
        self.src.read_exact_into(&mut buf).map_err(|e| self.io(e))?;
        self.crc.update(&buf);
        self.pos += N as u64;
        Ok(buf)
    }

    /// Reads `count` elements at absolute offset `offset` straight into a
    /// `Vec<T>`. `count × size_of::<T>()` was checked against the file length.
    fn section<T: Pod>(&mut self, (offset, length): (u64, u64)) -> Result<Vec<T>, FormatError> {
        self.skip_to(offset)?;
        let count = (length / size_of::<T>() as u64) as usize;
        let mut v = vec![T::zeroed(); count];
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut v);
        self.src.read_exact_into(bytes).map_err(|e| self.io(e))?;
        self.crc.update(bytes);
        self.pos += length;
        from_le_words(bytes);
        Ok(v)
    }
}

fn decode<S: Source>(
    src: S,
    header: Header,
    path: &Path,
) -> Result<(TetMesh, SceneInfo), FormatError> {
    let mut r = PayloadReader {
        src,
        pos: HEADER_LEN as u64,
        crc: Hasher::new(),
        path,
    };
    let s = header.sections;
    let points: Vec<Vec3> = r.section(s[0])?;
    let tets: Vec<[u32; 4]> = r.section(s[1])?;
    let neighbors: Vec<[Link; 4]> = r.section(s[2])?;
    let constrained: Vec<ConstrainedFace> = r.section(s[3])?;
    let present = |bit| header.flags & bit != 0;
    let normals: Option<Vec<Vec3>> = if present(FLAG_NORMALS) {
        Some(r.section(s[4])?)
    } else {
        None
    };
    let uvs: Option<Vec<Vec2>> = if present(FLAG_UVS) {
        Some(r.section(s[5])?)
    } else {
        None
    };
    let materials: Option<Vec<u32>> = if present(FLAG_MATERIALS) {
        Some(r.section(s[6])?)
    } else {
        None
    };
    let scalars = if present(FLAG_SCALARS) {
        let (offset, _) = header.scalars;
        let slot: [u8; SCALAR_NAME_SLOT as usize] = r.raw(offset)?;
        let name = decode_name(&slot, path)?;
        let step_bytes = header.counts[0] * 4;
        let mut steps = Vec::with_capacity(header.scalar_steps as usize);
        for step in 0..u64::from(header.scalar_steps) {
            let at = offset + SCALAR_NAME_SLOT + step * step_bytes;
            steps.push(r.section::<f32>((at, step_bytes))?);
        }
        Some(ScalarField { name, steps })
    } else {
        None
    };
    let scene_records: Vec<[u32; 12]> = if present(FLAG_SCENE) {
        r.section(header.scene)?
    } else {
        Vec::new()
    };
    r.skip_to(header.file_length)?;
    let computed = r.crc.finalize();
    if computed != header.payload_crc {
        return Err(FormatError::ChecksumMismatch {
            path: path.to_path_buf(),
            part: "payload",
            stored: header.payload_crc,
            computed,
        });
    }
    debug_assert_eq!(points.len() as u64, header.counts[0]);
    let mesh = TetMesh {
        points,
        tets,
        neighbors,
        constrained,
        triangle_count: header.triangle_count,
        attributes: Attributes {
            normals,
            uvs,
            materials,
            scalars,
        },
    };
    let scene = decode_scene(&scene_records, path)?;
    mesh.validate().map_err(|source| FormatError::InvalidMesh {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((mesh, scene))
}

/// Decodes a mesh from an in-memory file image (checks as in [`load`];
/// errors name [`IN_MEMORY`] as the path). A scene block, if any, is checked
/// and dropped; [`from_bytes_with_scene`] returns it.
pub fn from_bytes(bytes: &[u8]) -> Result<TetMesh, FormatError> {
    from_bytes_with_scene(bytes).map(|(mesh, _)| mesh)
}

/// [`from_bytes`], also returning the scene block (empty when absent).
pub fn from_bytes_with_scene(bytes: &[u8]) -> Result<(TetMesh, SceneInfo), FormatError> {
    let path = Path::new(IN_MEMORY);
    let head = &bytes[..bytes.len().min(HEADER_LEN)];
    let header = parse_header(head, bytes.len() as u64, path)?;
    decode(&bytes[HEADER_LEN..], header, path)
}

/// Loads a mesh saved by [`super::save`]: header checks against the real file size,
/// sections read straight into typed vectors, CRCs, then [`TetMesh::validate`].
/// A scene block, if any, is checked and dropped; [`load_with_scene`]
/// returns it.
pub fn load(path: impl AsRef<Path>) -> Result<TetMesh, FormatError> {
    load_with_scene(path).map(|(mesh, _)| mesh)
}

/// [`load`], also returning the scene block (empty when absent).
pub fn load_with_scene(path: impl AsRef<Path>) -> Result<(TetMesh, SceneInfo), FormatError> {
    let path = path.as_ref();
    let (file, header) = SectionReader::open(path)?.into_parts();
    decode(
        FileSource(BufReader::with_capacity(1 << 16, file)),
        header,
        path,
    )
}
