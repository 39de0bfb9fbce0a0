//! The streaming merge (issue 8, item 4): every finished part goes to a
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
//! wall ([`SeamIndex::contains_point`]) can be shared by two parts (two
//! leaves' closed boxes meet only within the seam of their lowest common
//! split), so only those are deduplicated, by their exact bits, through a
//! map whose size is proportional to the seams' area, not the volume. The
//! sections are written in file order by passes over the part files
//! through [`SectionReader`]:
//!
//! 1. *points and seam faces*: each part's payload CRC is checked
//!    ([`SectionReader::verify_payload`]); its points get global ids (seam
//!    points through the map, the rest in order) and the new ones are
//!    appended; every open face of the part (a boundary face, or a scene
//!    face with one side) that lies in a seam ([`SeamIndex::contains_face`])
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

use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec3;
use tet_core::format::{FormatError, OptionalSections, SectionReader, StreamWriter};
use tet_core::reorder::PermutationError;
use tet_core::scene::SceneInfo;
use tet_core::{ConstrainedFace, FACE_VERTICES, FaceSide, Link, NO_TET, TetMesh, face_key};
use thiserror::Error;

use super::seam::{Merge, MergeContext, PartMesh, PartStats, SeamError, key};
use super::seam_index::SeamIndex;
use super::split::SplitPlane;

/// Where and how [`super::tree::build_tree_to_file`] and
/// [`super::seam::build_slabs_to_file`] write the merged mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamOptions {
    /// The mesh file (replaced atomically when the merge is done).
    pub output: PathBuf,
    /// Camera and lights stored with the mesh (the file's scene block).
    pub scene: SceneInfo,
    /// Hilbert-sort each part on its own before writing it.
    pub sort_parts: bool,
    /// Directory in which the part files' directory is made (and removed
    /// afterwards); `None`: the output's directory.
    pub work_dir: Option<PathBuf>,
}

impl StreamOptions {
    /// Writes `output`, parts sorted, no scene block, part files next to it.
    pub fn new(output: impl Into<PathBuf>) -> StreamOptions {
        StreamOptions {
            output: output.into(),
            scene: SceneInfo::default(),
            sort_parts: true,
            work_dir: None,
        }
    }
}

/// What the streaming merge wrote and held.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StreamSummary {
    /// Points of the merged mesh.
    pub points: u64,
    /// Tets.
    pub tets: u64,
    /// Constrained faces.
    pub constrained: u64,
    /// Bytes of the mesh file.
    pub file_bytes: u64,
    /// Bytes of all part files together.
    pub part_file_bytes: u64,
    /// Points on seams (deduplicated through the seam map).
    pub seam_points: usize,
    /// Seam-only faces linked across seams.
    pub seam_faces: usize,
    /// Scene faces lying on a cut plane, merged from their two parts.
    pub seam_constrained: usize,
    /// Largest number of bytes the merge held at once: one part's arrays
    /// (or chunks of them) plus the seam maps, by vector and hash-table
    /// capacity (see the module docs).
    pub max_resident_bytes: u64,
    /// Bytes of every part's arrays together (points and their global ids,
    /// tets, neighbours, constrained faces): what a merge holding all parts
    /// would need before any map of its own.
    pub all_parts_bytes: u64,
    /// Seconds of the merge (after the last part was written).
    pub merge_s: f64,
}

/// A failure of the part files or of the streaming merge; each names the
/// part (its index and file) and the element at fault.
#[derive(Debug, Error)]
pub enum StreamError {
    /// A part file or the mesh file could not be written or read, or is
    /// malformed.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The directory for the part files could not be made.
    #[error("{dir}: cannot make the part files' directory: {source}", dir = .dir.display())]
    WorkDir {
        /// The directory.
        dir: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
    /// A part could not be Hilbert-sorted.
    #[error("part {part}: Hilbert sort: {source}")]
    Sort {
        /// Part index.
        part: usize,
        /// The reorder's error.
        source: PermutationError,
    },
    /// Two part files disagree on the number of scene triangles.
    #[error("part {part} ({path}) has {found} scene triangles, part 0 has {expected}", path = .path.display())]
    TriangleCount {
        /// Part index.
        part: usize,
        /// Its file.
        path: PathBuf,
        /// Triangles it records.
        found: u32,
        /// Triangles part 0 records.
        expected: u32,
    },
    /// An element of a part file refers past the end of what it indexes.
    #[error("part {part} ({path}): {element} {index} refers to {value}, past the {count} it may index", path = .path.display())]
    OutOfBounds {
        /// Part index.
        part: usize,
        /// Its file.
        path: PathBuf,
        /// What refers (`"tet vertex"`, `"neighbour link"`, …).
        element: &'static str,
        /// Index of the referring element within the part.
        index: u64,
        /// The value found.
        value: u64,
        /// How many there are to refer to.
        count: u64,
    },
    /// A point on a seam occurs twice in one part (two points of the part
    /// rounded to the same f32 position).
    #[error("part {part}: seam point {point} at {position:?} repeats an earlier point of the part")]
    RepeatedSeamPoint {
        /// Part index.
        part: usize,
        /// Local point index.
        point: u32,
        /// Its position.
        position: Vec3,
    },
    /// A part file changed between the merge's passes.
    #[error("part {part} ({path}) changed during the merge", path = .path.display())]
    Changed {
        /// Part index.
        part: usize,
        /// Its file.
        path: PathBuf,
    },
    /// A face lying in a seam does not match across it.
    #[error(
        "part {part}: face {face} of tet {tet} (global vertices {vertices:?}) lies in a seam but {detail}"
    )]
    SeamFace {
        /// Part index.
        part: usize,
        /// Local tet index.
        tet: u32,
        /// Face of the tet.
        face: u8,
        /// Global vertex ids of the face.
        vertices: [u32; 3],
        /// What is wrong.
        detail: &'static str,
    },
}

/// One finished part: its file and report fields.
pub(super) struct PartFile {
    path: PathBuf,
    stats: PartStats,
}

/// A directory for part files, removed with everything in it on drop.
#[derive(Debug)]
struct PartDir(PathBuf);

impl PartDir {
    /// Makes a fresh directory inside `base`.
    fn create(base: &Path) -> Result<PartDir, StreamError> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let dir = base.join(format!(
            ".tet-parts-{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir(&dir).map_err(|source| StreamError::WorkDir {
            dir: dir.clone(),
            source,
        })?;
        Ok(PartDir(dir))
    }
}

impl Drop for PartDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

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

/// Elements read or written at a time by the passes that need no whole
/// section.
const CHUNK: u64 = 1 << 16;

/// Heap bytes of a vector (by capacity).
fn vec_bytes<T>(v: &[T], capacity: usize) -> u64 {
    debug_assert!(v.len() <= capacity);
    (capacity * size_of::<T>()) as u64
}

/// Heap bytes of a hash map (by capacity: one entry and one control byte
/// per slot).
fn map_bytes<K, V>(m: &HashMap<K, V>) -> u64 {
    (m.capacity() * (size_of::<(K, V)>() + 1)) as u64
}

/// A part as the merge sees it.
struct Part {
    path: PathBuf,
    points: u64,
    tets: u64,
    constrained: u64,
    /// Global id of the part's first new point.
    point_base: u32,
    /// Global index of the part's first tet.
    tet_base: u32,
    /// Global index of the part's first constrained face kept.
    constrained_base: u32,
    /// Local constrained faces that are a seam face's second copy (sorted).
    duplicates: Vec<u32>,
}

/// The first side offered for a seam face.
#[derive(Clone, Copy)]
struct OpenFace {
    part: u32,
    /// Global tet.
    tet: u32,
    face: u8,
    /// The local constrained face, for a scene face on the seam.
    constrained: Option<u32>,
}

/// The merge's state (see the module docs).
struct Merger<'a> {
    parts: Vec<Part>,
    seams: SeamIndex,
    scene: &'a SceneInfo,
    /// Seam point bits → global id.
    seam_points: HashMap<[u32; 3], u32>,
    /// Sorted global vertex triple → the side offered first.
    open: HashMap<[u32; 3], OpenFace>,
    /// (global tet, face) of a seam-only face → global tet on the other side.
    links: HashMap<(u32, u8), u32>,
    /// (part, local constrained face) of a seam scene face's first copy →
    /// the side the second part gives it (`true`: front).
    other_side: HashMap<(u32, u32), (bool, FaceSide)>,
    /// (part, local constrained face) of a second copy → global index.
    duplicate_of: HashMap<(u32, u32), u32>,
    triangle_count: u32,
    max_resident: u64,
}

impl Merger<'_> {
    fn maps_bytes(&self) -> u64 {
        map_bytes(&self.seam_points)
            + map_bytes(&self.open)
            + map_bytes(&self.links)
            + map_bytes(&self.other_side)
            + map_bytes(&self.duplicate_of)
            + self
                .parts
                .iter()
                .map(|p| vec_bytes(&p.duplicates, p.duplicates.capacity()))
                .sum::<u64>()
    }

    /// Records that `arrays` bytes of part data are held besides the maps.
    fn note(&mut self, arrays: u64) {
        self.max_resident = self.max_resident.max(arrays + self.maps_bytes());
    }

    fn out_of_bounds(
        &self,
        part: usize,
        element: &'static str,
        index: u64,
        value: u64,
        count: u64,
    ) -> StreamError {
        StreamError::OutOfBounds {
            part,
            path: self.parts[part].path.clone(),
            element,
            index,
            value,
            count,
        }
    }

    /// Global index of part `p`'s constrained face `c`.
    fn global_constrained(&self, p: usize, c: u32) -> u32 {
        let part = &self.parts[p];
        match part.duplicates.binary_search(&c) {
            Ok(_) => self.duplicate_of[&(p as u32, c)],
            Err(rank) => part.constrained_base + c - rank as u32,
        }
    }

    /// Global ids of part `p`'s points, as pass 1 gave them (seam points
    /// from the seam map, every other point the next id).
    fn global_points(&self, p: usize, points: &[Vec3]) -> Result<Vec<u32>, StreamError> {
        let base = self.parts[p].point_base;
        let changed = || StreamError::Changed {
            part: p,
            path: self.parts[p].path.clone(),
        };
        let mut next = base;
        points
            .iter()
            .map(|&x| {
                if self.seams.contains_point(x) {
                    let g = *self.seam_points.get(&key(x)).ok_or_else(changed)?;
                    if g >= base {
                        if g != next {
                            return Err(changed());
                        }
                        next += 1;
                    }
                    Ok(g)
                } else {
                    next += 1;
                    Ok(next - 1)
                }
            })
            .collect()
    }

    /// Pass 1 on part `p`: global point ids (new points appended to `w`)
    /// and its open seam faces matched.
    fn scan(&mut self, p: usize, w: &mut StreamWriter) -> Result<(), StreamError> {
        let mut r = SectionReader::open(&self.parts[p].path)?;
        r.verify_payload()?;
        if p == 0 {
            self.triangle_count = r.triangle_count();
        } else if r.triangle_count() != self.triangle_count {
            return Err(StreamError::TriangleCount {
                part: p,
                path: self.parts[p].path.clone(),
                found: r.triangle_count(),
                expected: self.triangle_count,
            });
        }
        let (np, nt, nc) = (r.point_count(), r.tet_count(), r.constrained_count());
        let point_base = w.points_written() as u32;
        let (tet_base, constrained_base) = match p {
            0 => (0, 0),
            _ => {
                let q = &self.parts[p - 1];
                (
                    q.tet_base + q.tets as u32,
                    q.constrained_base + (q.constrained - q.duplicates.len() as u64) as u32,
                )
            }
        };
        {
            let part = &mut self.parts[p];
            (part.points, part.tets, part.constrained) = (np, nt, nc);
            (part.point_base, part.tet_base, part.constrained_base) =
                (point_base, tet_base, constrained_base);
        }
        let points = r.read_points(0..np)?;
        let mut global = Vec::with_capacity(points.len());
        let mut fresh = Vec::new();
        let mut next = point_base;
        for (i, &x) in points.iter().enumerate() {
            let g = if self.seams.contains_point(x) {
                match self.seam_points.get(&key(x)) {
                    Some(&g) if g >= point_base => {
                        return Err(StreamError::RepeatedSeamPoint {
                            part: p,
                            point: i as u32,
                            position: x,
                        });
                    }
                    Some(&g) => g,
                    None => {
                        self.seam_points.insert(key(x), next);
                        fresh.push(x);
                        next += 1;
                        next - 1
                    }
                }
            } else {
                fresh.push(x);
                next += 1;
                next - 1
            };
            global.push(g);
            if fresh.len() as u64 >= CHUNK {
                w.append_points(&fresh)?;
                fresh.clear();
            }
        }
        w.append_points(&fresh)?;
        let tets = r.read_tets(0..nt)?;
        let neighbors = r.read_neighbors(0..nt)?;
        let constrained = r.read_constrained(0..nc)?;
        self.note(
            vec_bytes(&points, points.capacity())
                + vec_bytes(&global, global.capacity())
                + vec_bytes(&fresh, fresh.capacity())
                + vec_bytes(&tets, tets.capacity())
                + vec_bytes(&neighbors, neighbors.capacity())
                + vec_bytes(&constrained, constrained.capacity()),
        );
        for (c, f) in constrained.iter().enumerate() {
            for side in [f.front, f.back] {
                if side.exists() && (u64::from(side.tet) >= nt || side.face >= 4) {
                    return Err(self.out_of_bounds(
                        p,
                        "constrained face side",
                        c as u64,
                        u64::from(side.tet),
                        nt,
                    ));
                }
            }
        }
        let mut duplicates = Vec::new();
        for (t, tet) in tets.iter().enumerate() {
            for (slot, &v) in tet.iter().enumerate() {
                if u64::from(v) >= np {
                    return Err(self.out_of_bounds(
                        p,
                        "tet vertex",
                        (4 * t + slot) as u64,
                        u64::from(v),
                        np,
                    ));
                }
            }
            for k in 0..4 {
                let link = neighbors[t][k];
                let open_constrained = match link.as_constrained() {
                    Some(c) => {
                        let f = constrained.get(c as usize).ok_or_else(|| {
                            self.out_of_bounds(
                                p,
                                "neighbour link",
                                (4 * t + k) as u64,
                                u64::from(c),
                                nc,
                            )
                        })?;
                        if f.front.exists() && f.back.exists() {
                            continue;
                        }
                        Some(c)
                    }
                    None if link.is_boundary() => None,
                    None => continue,
                };
                let local = FACE_VERTICES[k].map(|s| tet[s]);
                if !self.seams.contains_face(local.map(|v| points[v as usize])) {
                    continue;
                }
                let vertices = face_key(local.map(|v| global[v as usize]));
                let here = OpenFace {
                    part: p as u32,
                    tet: tet_base + t as u32,
                    face: k as u8,
                    constrained: open_constrained,
                };
                let Some(first) = self.open.remove(&vertices) else {
                    self.open.insert(vertices, here);
                    continue;
                };
                let fail = |detail| StreamError::SeamFace {
                    part: p,
                    tet: t as u32,
                    face: k as u8,
                    vertices,
                    detail,
                };
                if first.part == here.part {
                    return Err(fail("is open twice in its part"));
                }
                match (first.constrained, here.constrained) {
                    (None, None) => {
                        self.links.insert((first.tet, first.face), here.tet);
                        self.links.insert((here.tet, here.face), first.tet);
                    }
                    (Some(c0), Some(c)) => {
                        let global_c = self.global_constrained(first.part as usize, c0);
                        self.duplicate_of.insert((p as u32, c), global_c);
                        duplicates.push(c);
                        let f = &constrained[c as usize];
                        let (front, side) = if f.front.exists() {
                            (true, f.front)
                        } else {
                            (false, f.back)
                        };
                        let side = FaceSide {
                            tet: tet_base + side.tet,
                            face: side.face,
                        };
                        self.other_side.insert((first.part, c0), (front, side));
                    }
                    _ => {
                        return Err(fail(
                            "is a scene face on one side of the seam and not on the other",
                        ));
                    }
                }
            }
        }
        duplicates.sort_unstable();
        self.parts[p].duplicates = duplicates;
        self.note(
            vec_bytes(&points, points.capacity())
                + vec_bytes(&global, global.capacity())
                + vec_bytes(&tets, tets.capacity())
                + vec_bytes(&neighbors, neighbors.capacity())
                + vec_bytes(&constrained, constrained.capacity()),
        );
        Ok(())
    }

    /// Part `p`'s points and their global ids (passes 2 and 4).
    fn reopen(&mut self, p: usize) -> Result<(SectionReader, Vec<u32>), StreamError> {
        let mut r = SectionReader::open(&self.parts[p].path)?;
        let part = &self.parts[p];
        let counts = (r.point_count(), r.tet_count(), r.constrained_count());
        if counts != (part.points, part.tets, part.constrained) {
            return Err(StreamError::Changed {
                part: p,
                path: part.path.clone(),
            });
        }
        let points = r.read_points(0..part.points)?;
        let global = self.global_points(p, &points)?;
        self.note(vec_bytes(&points, points.capacity()) + vec_bytes(&global, global.capacity()));
        Ok((r, global))
    }

    /// Pass 2 on part `p`: tets with global vertex ids.
    fn write_tets(&mut self, p: usize, w: &mut StreamWriter) -> Result<(), StreamError> {
        let (mut r, global) = self.reopen(p)?;
        let n = self.parts[p].tets;
        for start in (0..n).step_by(CHUNK as usize) {
            let end = (start + CHUNK).min(n);
            let mut tets = r.read_tets(start..end)?;
            for (i, tet) in tets.iter_mut().enumerate() {
                for (slot, v) in tet.iter_mut().enumerate() {
                    *v = *global.get(*v as usize).ok_or_else(|| {
                        self.out_of_bounds(
                            p,
                            "tet vertex",
                            4 * (start + i as u64) + slot as u64,
                            u64::from(*v),
                            global.len() as u64,
                        )
                    })?;
                }
            }
            self.note(vec_bytes(&global, global.capacity()) + vec_bytes(&tets, tets.capacity()));
            w.append_tets(&tets)?;
        }
        Ok(())
    }

    /// Pass 3 on part `p`: neighbour links renumbered, seams linked.
    fn write_neighbors(&mut self, p: usize, w: &mut StreamWriter) -> Result<(), StreamError> {
        let mut r = SectionReader::open(&self.parts[p].path)?;
        if r.tet_count() != self.parts[p].tets || r.constrained_count() != self.parts[p].constrained
        {
            return Err(StreamError::Changed {
                part: p,
                path: self.parts[p].path.clone(),
            });
        }
        let (n, nc, base) = (
            self.parts[p].tets,
            self.parts[p].constrained,
            self.parts[p].tet_base,
        );
        for start in (0..n).step_by(CHUNK as usize) {
            let end = (start + CHUNK).min(n);
            let mut links = r.read_neighbors(start..end)?;
            for (i, record) in links.iter_mut().enumerate() {
                let t = base + (start + i as u64) as u32;
                for (k, link) in record.iter_mut().enumerate() {
                    let bad = |value: u64, count: u64| {
                        self.out_of_bounds(
                            p,
                            "neighbour link",
                            4 * (start + i as u64) + k as u64,
                            value,
                            count,
                        )
                    };
                    *link = if let Some(c) = link.as_constrained() {
                        if u64::from(c) >= nc {
                            return Err(bad(u64::from(c), nc));
                        }
                        Link::constrained(self.global_constrained(p, c))
                    } else if let Some(u) = link.as_tet() {
                        if u64::from(u) >= n {
                            return Err(bad(u64::from(u), n));
                        }
                        Link::tet(base + u)
                    } else {
                        self.links
                            .get(&(t, k as u8))
                            .map_or(Link::BOUNDARY, |&u| Link::tet(u))
                    };
                }
            }
            self.note(vec_bytes(&links, links.capacity()));
            w.append_neighbors(&links)?;
        }
        Ok(())
    }

    /// Pass 4 on part `p`: constrained faces with global vertices and
    /// sides, seam copies merged.
    fn write_constrained(&mut self, p: usize, w: &mut StreamWriter) -> Result<(), StreamError> {
        let (mut r, global) = self.reopen(p)?;
        let (n, base) = (self.parts[p].constrained, self.parts[p].tet_base);
        for start in (0..n).step_by(CHUNK as usize) {
            let end = (start + CHUNK).min(n);
            let faces = r.read_constrained(start..end)?;
            let mut kept: Vec<ConstrainedFace> = Vec::with_capacity(faces.len());
            for (i, f) in faces.iter().enumerate() {
                let c = (start + i as u64) as u32;
                if self.parts[p].duplicates.binary_search(&c).is_ok() {
                    continue;
                }
                let mut g = *f;
                for (slot, v) in g.vertices.iter_mut().enumerate() {
                    *v = *global.get(*v as usize).ok_or_else(|| {
                        self.out_of_bounds(
                            p,
                            "constrained face vertex",
                            3 * u64::from(c) + slot as u64,
                            u64::from(*v),
                            global.len() as u64,
                        )
                    })?;
                }
                for side in [&mut g.front, &mut g.back] {
                    if side.tet != NO_TET {
                        side.tet += base;
                    }
                }
                if let Some(&(front, side)) = self.other_side.get(&(p as u32, c)) {
                    let slot = if front { &mut g.front } else { &mut g.back };
                    if slot.exists() {
                        let t = [f.front, f.back]
                            .into_iter()
                            .find(|s| s.exists())
                            .map_or(0, |s| s.tet);
                        return Err(StreamError::SeamFace {
                            part: p,
                            tet: t,
                            face: 0,
                            vertices: face_key(g.vertices),
                            detail: "is a scene face whose two parts put their tets on the same side",
                        });
                    }
                    *slot = side;
                }
                kept.push(g);
            }
            self.note(
                vec_bytes(&global, global.capacity())
                    + vec_bytes(&faces, faces.capacity())
                    + vec_bytes(&kept, kept.capacity()),
            );
            w.append_constrained(&kept)?;
        }
        Ok(())
    }
}

/// Streams the part files `parts` (in part order; each a mesh of its own
/// whose faces on `seams` are open, as the builders write them) into the
/// mesh file `output` with the scene block `scene` (see the module docs).
pub fn merge_part_files(
    parts: &[PathBuf],
    seams: &[(SplitPlane, Vec3, Vec3)],
    output: &Path,
    scene: &SceneInfo,
) -> Result<StreamSummary, StreamError> {
    let start = Instant::now();
    let mut m = Merger {
        parts: parts
            .iter()
            .map(|path| Part {
                path: path.clone(),
                points: 0,
                tets: 0,
                constrained: 0,
                point_base: 0,
                tet_base: 0,
                constrained_base: 0,
                duplicates: Vec::new(),
            })
            .collect(),
        seams: SeamIndex::new(seams),
        scene,
        seam_points: HashMap::new(),
        open: HashMap::new(),
        links: HashMap::new(),
        other_side: HashMap::new(),
        duplicate_of: HashMap::new(),
        triangle_count: 0,
        max_resident: 0,
    };
    // The triangle count goes in the header, which is written last; part
    // 0's is checked against every other part by pass 1.
    let triangle_count = match parts.first() {
        Some(p) => SectionReader::open(p)?.triangle_count(),
        None => 0,
    };
    let mut w = StreamWriter::create(output, triangle_count, OptionalSections::default())?;
    for p in 0..parts.len() {
        m.scan(p, &mut w)?;
    }
    if let Some((vertices, f)) = m.open.iter().next() {
        return Err(StreamError::SeamFace {
            part: f.part as usize,
            tet: f.tet - m.parts[f.part as usize].tet_base,
            face: f.face,
            vertices: *vertices,
            detail: "has no tet on the seam's other side",
        });
    }
    for p in 0..parts.len() {
        m.write_tets(p, &mut w)?;
    }
    for p in 0..parts.len() {
        m.write_neighbors(p, &mut w)?;
    }
    for p in 0..parts.len() {
        m.write_constrained(p, &mut w)?;
    }
    let summary = StreamSummary {
        points: w.points_written(),
        tets: w.tets_written(),
        constrained: w.constrained_written(),
        file_bytes: 0,
        part_file_bytes: parts
            .iter()
            .map(|p| std::fs::metadata(p).map_or(0, |m| m.len()))
            .sum(),
        seam_points: m.seam_points.len(),
        seam_faces: m.links.len() / 2,
        seam_constrained: m.duplicate_of.len(),
        max_resident_bytes: m.max_resident,
        all_parts_bytes: m
            .parts
            .iter()
            .map(|p| 16 * p.points + 32 * p.tets + 32 * p.constrained)
            .sum(),
        merge_s: 0.0,
    };
    let file_bytes = w.finish_with_scene(m.scene)?;
    Ok(StreamSummary {
        file_bytes,
        merge_s: start.elapsed().as_secs_f64(),
        ..summary
    })
}
