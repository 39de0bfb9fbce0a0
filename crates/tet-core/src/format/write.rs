//! Saving a whole mesh: [`write_to`] into any writer, [`save`] atomically
//! to a file through a [`StreamWriter`].

use std::io::{self, Write};
use std::path::Path;

use crc32fast::Hasher;

use super::error::FormatError;
use super::header::{HeaderFields, header_bytes};
use super::scalar_block::name_slot;
use super::scene_block::scene_records;
use super::spec::{
    FLAG_MATERIALS, FLAG_NORMALS, FLAG_SCALARS, FLAG_SCENE, FLAG_UVS, HEADER_LEN, SCALAR_NAME_SLOT,
};
use super::stream_writer::{OptionalSections, StreamWriter};
use super::words::{hash_le_words, padding, write_le_words};
use crate::fields::{ScalarField, check_name};
use crate::mesh::TetMesh;
use crate::scene::SceneInfo;

/// The sections of `mesh` in table order (`None` when absent), as raw bytes.
fn section_bytes(mesh: &TetMesh) -> [Option<&[u8]>; 7] {
    let a = &mesh.attributes;
    [
        Some(bytemuck::cast_slice(&mesh.points)),
        Some(bytemuck::cast_slice(&mesh.tets)),
        Some(bytemuck::cast_slice(&mesh.neighbors)),
        Some(bytemuck::cast_slice(&mesh.constrained)),
        a.normals.as_deref().map(bytemuck::cast_slice),
        a.uvs.as_deref().map(bytemuck::cast_slice),
        a.materials.as_deref().map(bytemuck::cast_slice),
    ]
}

/// Checks what the header needs of a scalar field: a storable name, at
/// least one step, every step of `points` values. (Values themselves are
/// checked on load.)
fn scalar_block_error(field: &ScalarField, points: usize) -> Option<String> {
    if let Err(e) = check_name(&field.name) {
        return Some(e.to_string());
    }
    if field.steps.is_empty() || field.steps.len() > u32::MAX as usize {
        return Some(format!(
            "scalar field has {} steps, expected 1..=2^32-1",
            field.steps.len()
        ));
    }
    field
        .steps
        .iter()
        .position(|s| s.len() != points)
        .map(|step| {
            format!(
                "scalar field step {step} has {} values, expected {points}",
                field.steps[step].len()
            )
        })
}

/// Serialises `mesh` into `w` (header first, then the sections).
///
/// The mesh is not validated: an invalid mesh is written as is and rejected
/// by [`super::load`] with [`FormatError::InvalidMesh`] (or a size mismatch when an
/// attribute array has the wrong length). A scalar field the header cannot
/// describe (name too long or with a NUL, no step, a step of the wrong
/// length) is refused with [`io::ErrorKind::InvalidInput`] instead of being
/// written wrong.
pub fn write_to(mesh: &TetMesh, w: &mut impl Write) -> io::Result<()> {
    write_to_with_scene(mesh, &SceneInfo::default(), w)
}

/// [`write_to`] followed by a scene block holding `scene` (none when it is
/// empty). The scene is not validated here either.
pub fn write_to_with_scene(
    mesh: &TetMesh,
    scene: &SceneInfo,
    w: &mut impl Write,
) -> io::Result<()> {
    let sections = section_bytes(mesh);
    let records = scene_records(scene);
    let scalars = mesh.attributes.scalars.as_ref();
    if let Some(detail) = scalars.and_then(|f| scalar_block_error(f, mesh.points.len())) {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, detail));
    }
    let mut flags = if records.is_empty() { 0 } else { FLAG_SCENE };
    if scalars.is_some() {
        flags |= FLAG_SCALARS;
    }
    for (bit, s) in [
        (FLAG_NORMALS, sections[4]),
        (FLAG_UVS, sections[5]),
        (FLAG_MATERIALS, sections[6]),
    ] {
        if s.is_some() {
            flags |= bit;
        }
    }
    let mut table = [(0u64, 0u64); 7];
    let mut crc = Hasher::new();
    let mut end = HEADER_LEN as u64;
    for (i, s) in sections.iter().enumerate() {
        if let Some(bytes) = s {
            let len = bytes.len() as u64;
            table[i] = (end, len);
            hash_le_words(&mut crc, bytes);
            crc.update(&[0u8; 8][..padding(len) as usize]);
            end += len + padding(len);
        }
    }
    let slot = scalars.and_then(|f| name_slot(&f.name));
    if let (Some(field), Some(slot)) = (scalars, &slot) {
        crc.update(slot);
        let mut len = SCALAR_NAME_SLOT;
        for step in &field.steps {
            hash_le_words(&mut crc, bytemuck::cast_slice(step));
            len += step.len() as u64 * 4;
        }
        crc.update(&[0u8; 8][..padding(len) as usize]);
        end += len + padding(len);
    }
    let scene_bytes: &[u8] = bytemuck::cast_slice(&records);
    hash_le_words(&mut crc, scene_bytes);
    end += scene_bytes.len() as u64;
    let head = header_bytes(&HeaderFields {
        flags,
        file_length: end,
        triangle_count: mesh.triangle_count,
        scalar_steps: scalars.map_or(0, |f| f.steps.len() as u32),
        counts: [
            mesh.points.len() as u64,
            mesh.tets.len() as u64,
            mesh.constrained.len() as u64,
        ],
        table,
        payload_crc: crc.finalize(),
    });
    w.write_all(&head)?;
    for bytes in sections.into_iter().flatten() {
        write_le_words(w, bytes)?;
        w.write_all(&[0u8; 8][..padding(bytes.len() as u64) as usize])?;
    }
    if let (Some(field), Some(slot)) = (scalars, &slot) {
        w.write_all(slot)?;
        let mut len = SCALAR_NAME_SLOT;
        for step in &field.steps {
            write_le_words(w, bytemuck::cast_slice(step))?;
            len += step.len() as u64 * 4;
        }
        w.write_all(&[0u8; 8][..padding(len) as usize])?;
    }
    write_le_words(w, scene_bytes)
}

/// Serialises `mesh` into a new byte vector (see [`write_to`]).
pub fn to_bytes(mesh: &TetMesh) -> Vec<u8> {
    to_bytes_with_scene(mesh, &SceneInfo::default())
}

/// Serialises `mesh` and `scene` into a new byte vector (see
/// [`write_to_with_scene`]).
pub fn to_bytes_with_scene(mesh: &TetMesh, scene: &SceneInfo) -> Vec<u8> {
    let mut out = Vec::new();
    write_to_with_scene(mesh, scene, &mut out).expect("writing to a Vec cannot fail");
    out
}

/// Saves `mesh` to `path` atomically: the bytes go to a fresh temporary file
/// in the same directory, which is synced and then renamed over `path`.
/// On error the temporary file is removed and `path` is untouched.
pub fn save(path: impl AsRef<Path>, mesh: &TetMesh) -> Result<(), FormatError> {
    save_with_scene(path, mesh, &SceneInfo::default())
}

/// [`save`] with a scene block holding `scene` (none when it is empty), so
/// the file remembers the camera and lights of the scene it was built from.
///
/// The sections go through a [`StreamWriter`], which checks on the way that
/// attribute arrays have their section's length
/// ([`FormatError::SizeMismatch`]); nothing else is validated.
pub fn save_with_scene(
    path: impl AsRef<Path>,
    mesh: &TetMesh,
    scene: &SceneInfo,
) -> Result<(), FormatError> {
    let a = &mesh.attributes;
    let mut w = StreamWriter::create(
        path,
        mesh.triangle_count,
        OptionalSections::of(&mesh.attributes),
    )?;
    w.append_points(&mesh.points)?;
    w.append_tets(&mesh.tets)?;
    w.append_neighbors(&mesh.neighbors)?;
    w.append_constrained(&mesh.constrained)?;
    if let Some(n) = &a.normals {
        w.append_normals(n)?;
    }
    if let Some(u) = &a.uvs {
        w.append_uvs(u)?;
    }
    if let Some(m) = &a.materials {
        w.append_materials(m)?;
    }
    if let Some(field) = &a.scalars {
        for step in &field.steps {
            w.append_scalar_step(&field.name, step)?;
        }
    }
    w.finish_with_scene(scene).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_mesh_round_trips() {
        let m = TetMesh::default();
        let b = to_bytes(&m);
        assert_eq!(b.len(), HEADER_LEN);
        assert_eq!(crate::format::from_bytes(&b).unwrap(), m);
    }
}
