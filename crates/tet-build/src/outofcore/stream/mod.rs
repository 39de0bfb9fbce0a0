//! The streaming merge: every finished part goes to a
//! part file in the mesh file format as soon as its TetGen worker returns,
//! and the part files are merged into the mesh file a part at a time, so
//! neither the builder nor the merge ever holds the whole mesh.
//!
//! **Part files.** On the worker thread that ran it, a part's
//! tets, points and constrained faces (with the *input* scene triangle ids)
//! are assembled into a [`TetMesh`] of their own ([`TetMesh::assemble`]:
//! neighbours within the part; faces on the part's walls are boundary
//! faces, and a scene face lying on a seam has one side), validated,
//! Hilbert-sorted on their own ([`tet_core::reorder::hilbert_reorder`],
//! with [`StreamOptions::sort_parts`]) and saved into a fresh directory
//! next to the output; the part's arrays are then dropped.
//!
//! **Merge** ([`merge_part_files`]). The parts follow each other in the
//! mesh file in part order (leaf order of the tree, depth first, below
//! before above; slab order for slabs): part `p`'s tets are
//! `tet_base[p]..`, its new points `point_base[p]..`. Only points on a seam
//! wall ([`SeamIndex::contains_point`](super::seam_index::SeamIndex::contains_point)) can be shared by two parts (two
//! leaves' closed boxes meet only within the seam of their lowest common
//! split), so only those are deduplicated, by their exact bits, through a
//! map whose size is proportional to the seams' area, not the volume. The
//! sections are written in file order by passes over the part files
//! through [`SectionReader`](tet_core::format::SectionReader):
//!
//! 1. *points and seam faces*: each part's payload CRC is checked
//!    ([`SectionReader::verify_payload`](tet_core::format::SectionReader::verify_payload)); its points get global ids (seam
//!    points through the map, the rest in order) and the new ones are
//!    appended; every open face of the part (a boundary face, or a scene
//!    face with one side) that lies in a seam ([`SeamIndex::contains_face`](super::seam_index::SeamIndex::contains_face))
//!    is keyed by its sorted global vertex triple. The first part to offer
//!    a key leaves it open; the second closes it: a seam-only face becomes a
//!    tet–tet link (both directions kept in a map keyed by (global tet,
//!    face)); a scene face lying on a cut plane becomes *one* constrained
//!    face, numbered in the first part, with the second part's tet as its
//!    other side (the second part's copy is dropped). A key left open, a key
//!    offered twice by one part, or a scene face on one side meeting a
//!    seam-only face on the other is a [`StreamError::SeamFace`].
//! 2. *tets*: vertex ids rewritten to global ids.
//! 3. *neighbours*: tet links offset by `tet_base`, constrained links
//!    renumbered, seam faces linked through the map.
//! 4. *constrained faces*: vertices and sides rewritten, seam duplicates
//!    dropped, the other side of each scene face on a seam filled in.
//!
//! The result is the mesh [`super::seam`]'s in-memory merge gives (the same
//! points, tets, links and constrained faces with both sides), up to the
//! order of points, tets and constrained faces: each part is Hilbert-sorted
//! on its own instead of the whole mesh (which needs the mesh in memory).
//! The merge checks every index it follows (typed errors naming the part
//! file and element) but does not run [`TetMesh::validate`] on the whole
//! mesh: each part was validated before it was written, and the seams are
//! matched exactly as above.
//!
//! **Working set.** At any time the merge holds one part's arrays (pass 1:
//! points and global ids, 16 bytes per point, tets and neighbours, 32 per
//! tet, constrained faces, 32 each; later passes one part's points and ids
//! and fixed-size chunks) plus the seam maps (seam points, open seam faces,
//! seam links, the other sides of seam scene faces): *the largest part plus
//! the seams' area*. [`StreamSummary::max_resident_bytes`] reports it
//! (vector and hash-table capacities), beside
//! [`StreamSummary::all_parts_bytes`], what holding every part at once
//! would take. A part is not a single slice of a big mesh: the builder's
//! own peak is one part (TetGen's output, then its [`TetMesh`]) per worker
//! thread on top of the planner's inputs.

use std::path::PathBuf;

use tet_core::TetMesh;

use self::part_file::{PartDir, PartFile};
use super::error::SeamError;
use super::merge::{Merge, MergeContext};
use super::parts::{PartMesh, PartStats};

pub use super::error::StreamError;
pub use merger::merge_part_files;
pub use options::{StreamOptions, StreamSummary};

mod merger;
mod options;
mod part_file;

/// The streaming [`Merge`]: part files, then [`merge_part_files`].
pub(super) struct ToFile<'a> {
    options: &'a StreamOptions,
    dir: PartDir,
}

impl<'a> ToFile<'a> {
    /// Makes the part files' directory.
    pub(super) fn new(options: &'a StreamOptions) -> Result<ToFile<'a>, StreamError> {
        let base = match &options.work_dir {
            Some(d) => d.clone(),
            None => match options.output.parent() {
                Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
                _ => PathBuf::from("."),
            },
        };
        Ok(ToFile {
            options,
            dir: PartDir::create(&base)?,
        })
    }
}

impl Merge for ToFile<'_> {
    type Part = PartFile;
    type Output = StreamSummary;

    fn part(&self, k: usize, mesh: PartMesh, ctx: &MergeContext) -> Result<PartFile, SeamError> {
        let tris = ctx.scene_ids(&mesh.constrained);
        let stats = mesh.stats;
        let mut local = TetMesh::assemble(mesh.points, mesh.tets, &tris, ctx.triangle_count)?;
        drop(tris);
        local.validate()?;
        if self.options.sort_parts {
            tet_core::reorder::hilbert_reorder(&mut local)
                .map_err(|source| StreamError::Sort { part: k, source })?;
        }
        let path = self.dir.0.join(format!("part-{k:05}.tmesh"));
        tet_core::format::save(&path, &local).map_err(StreamError::from)?;
        Ok(PartFile { path, stats })
    }

    fn stats(part: &PartFile) -> PartStats {
        part.stats
    }

    fn merge(&self, parts: Vec<PartFile>, ctx: &MergeContext) -> Result<StreamSummary, SeamError> {
        let paths: Vec<PathBuf> = parts.into_iter().map(|p| p.path).collect();
        Ok(merge_part_files(
            &paths,
            ctx.seams,
            &self.options.output,
            &self.options.scene,
        )?)
    }
}
