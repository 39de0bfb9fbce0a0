//! The streaming merge of part files into the mesh file
//! ([`merge_part_files`]); see [`super`] for the passes and working set.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;
use tet_core::format::{OptionalSections, SectionReader, StreamWriter};
use tet_core::scene::SceneInfo;
use tet_core::{ConstrainedFace, FACE_VERTICES, FaceSide, Link, NO_TET, face_key};

use super::options::StreamSummary;
use crate::outofcore::error::StreamError;
use crate::outofcore::plane::{SplitPlane, key};
use crate::outofcore::seam_index::SeamIndex;

/// Elements read or written at a time by the passes that need no whole
/// section.
pub(crate) const CHUNK: u64 = 1 << 16;

/// Heap bytes of a vector (by capacity).
pub(crate) fn vec_bytes<T>(v: &[T], capacity: usize) -> u64 {
    debug_assert!(v.len() <= capacity);
    (capacity * size_of::<T>()) as u64
}

/// Heap bytes of a hash map (by capacity: one entry and one control byte
/// per slot).
pub(crate) fn map_bytes<K, V>(m: &HashMap<K, V>) -> u64 {
    (m.capacity() * (size_of::<(K, V)>() + 1)) as u64
}

/// A part as the merge sees it.
pub(crate) struct Part {
    pub(crate) path: PathBuf,
    pub(crate) points: u64,
    pub(crate) tets: u64,
    pub(crate) constrained: u64,
    /// Global id of the part's first new point.
    pub(crate) point_base: u32,
    /// Global index of the part's first tet.
    pub(crate) tet_base: u32,
    /// Global index of the part's first constrained face kept.
    pub(crate) constrained_base: u32,
    /// Local constrained faces that are a seam face's second copy (sorted).
    pub(crate) duplicates: Vec<u32>,
}

/// The first side offered for a seam face.
#[derive(Clone, Copy)]
pub(crate) struct OpenFace {
    pub(crate) part: u32,
    /// Global tet.
    pub(crate) tet: u32,
    pub(crate) face: u8,
    /// The local constrained face, for a scene face on the seam.
    pub(crate) constrained: Option<u32>,
}

/// The merge's state (see the module docs).
pub(crate) struct Merger<'a> {
    pub(crate) parts: Vec<Part>,
    pub(crate) seams: SeamIndex,
    pub(crate) scene: &'a SceneInfo,
    /// Seam point bits → global id.
    pub(crate) seam_points: HashMap<[u32; 3], u32>,
    /// Sorted global vertex triple → the side offered first.
    pub(crate) open: HashMap<[u32; 3], OpenFace>,
    /// (global tet, face) of a seam-only face → global tet on the other side.
    pub(crate) links: HashMap<(u32, u8), u32>,
    /// (part, local constrained face) of a seam scene face's first copy →
    /// the side the second part gives it (`true`: front).
    pub(crate) other_side: HashMap<(u32, u32), (bool, FaceSide)>,
    /// (part, local constrained face) of a second copy → global index.
    pub(crate) duplicate_of: HashMap<(u32, u32), u32>,
    pub(crate) triangle_count: u32,
    pub(crate) max_resident: u64,
}

impl Merger<'_> {
    pub(crate) fn maps_bytes(&self) -> u64 {
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
    pub(crate) fn note(&mut self, arrays: u64) {
        self.max_resident = self.max_resident.max(arrays + self.maps_bytes());
    }

    pub(crate) fn out_of_bounds(
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
    pub(crate) fn global_constrained(&self, p: usize, c: u32) -> u32 {
        let part = &self.parts[p];
        match part.duplicates.binary_search(&c) {
            Ok(_) => self.duplicate_of[&(p as u32, c)],
            Err(rank) => part.constrained_base + c - rank as u32,
        }
    }

    /// Global ids of part `p`'s points, as pass 1 gave them (seam points
    /// from the seam map, every other point the next id).
    pub(crate) fn global_points(&self, p: usize, points: &[Vec3]) -> Result<Vec<u32>, StreamError> {
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
    pub(crate) fn scan(&mut self, p: usize, w: &mut StreamWriter) -> Result<(), StreamError> {
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
    pub(crate) fn reopen(&mut self, p: usize) -> Result<(SectionReader, Vec<u32>), StreamError> {
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
    pub(crate) fn write_tets(&mut self, p: usize, w: &mut StreamWriter) -> Result<(), StreamError> {
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
    pub(crate) fn write_neighbors(
        &mut self,
        p: usize,
        w: &mut StreamWriter,
    ) -> Result<(), StreamError> {
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
    pub(crate) fn write_constrained(
        &mut self,
        p: usize,
        w: &mut StreamWriter,
    ) -> Result<(), StreamError> {
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
