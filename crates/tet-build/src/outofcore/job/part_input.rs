//! A part's input file: the facets one TetGen run receives (clipped scene
//! pieces and seam/wall triangles, and a slab's box faces), so that a part
//! can be built with nothing but this file.
//!
//! # Layout (version 1), little-endian
//!
//! | offset | size | field |
//! |-------:|-----:|-------|
//! | 0  | 8 | magic `TETPART\0` ([`MAGIC`]) |
//! | 8  | 4 | version `1` ([`VERSION`]) |
//! | 12 | 4 | part index |
//! | 16 | 4 | scene triangles (the ids below are `< ` this) |
//! | 20 | 4 | flags: bit 0 ([`FLAG_SURFACE_RELAXED`]) builds the part with its surface relaxed; other bits 0 |
//! | 24 | 8 | facets `F` |
//! | 32 | 8 | box faces `B` |
//! | 40 | 40·F | facets: 3 vertices × `[f32; 3]`, then `u32` the *input* scene triangle it is a piece of, or `0xFFFF_FFFF` for a seam-only triangle |
//! | … | 36·B | box faces: 3 vertices × `[f32; 3]` (unmarked facets of a slab's box) |
//! | end − 8 | 8 | XXH64 of every byte before it |
//!
//! [`decode`] checks the length before anything else (so a count in the
//! header never sizes an allocation beyond the file), then the magic, the
//! version, the flags (no unknown bit), the counts against the length, the
//! checksum, every id against the scene's triangles and every coordinate
//! for finiteness; each failure is an [`InputFault`]. The file's digest in
//! the plan is [`super::digest::format_digest`] of the checksum.

use glam::Vec3;

use super::digest::xxh64;
use super::error::InputFault;
use crate::outofcore::merge::PartInputs;
use crate::outofcore::parts::{FacetKind, PartFacetList};

/// The first 8 bytes of a part input file.
pub const MAGIC: [u8; 8] = *b"TETPART\0";
/// The format version written and read.
pub const VERSION: u32 = 1;
/// Header bytes.
pub const HEADER_BYTES: usize = 40;
/// Bytes of one facet record.
pub const FACET_BYTES: usize = 40;
/// Bytes of one box face record.
pub const BOX_FACE_BYTES: usize = 36;
/// The id of a seam-only facet.
pub const SEAM_FACET: u32 = u32::MAX;
/// Header flag: build the part with its surface relaxed (TetGen with
/// `-Y/2`, else without `-Y`; `SeamOptions::surface_relaxed_parts`), the planner's last resort
/// for a part TetGen failed on wherever its walls stood. Part of the
/// file, so of its digest: a relaxed input is another input than the one
/// that failed.
pub const FLAG_SURFACE_RELAXED: u32 = 1;

/// One part's TetGen input.
#[derive(Clone, Debug, PartialEq)]
pub struct PartInput {
    /// The part's index in the plan.
    pub part: u32,
    /// Triangles of the input scene.
    pub triangle_count: u32,
    /// Facets: vertices and the input scene triangle ([`SEAM_FACET`] for a
    /// seam-only triangle).
    pub facets: Vec<([Vec3; 3], u32)>,
    /// Unmarked box faces (a slab's outer walls).
    pub box_faces: Vec<[Vec3; 3]>,
    /// Build it with its surface relaxed ([`FLAG_SURFACE_RELAXED`]).
    pub surface_relaxed: bool,
}

impl PartInput {
    /// Part `k` of `inputs` as its input file holds it, made from its PLC
    /// `list`, relaxed when `relaxed` names it. Facets carry the *input*
    /// scene triangle, so that a part needs no map back from the cleaned
    /// scene.
    pub(super) fn of_part(
        inputs: &PartInputs,
        k: usize,
        list: &PartFacetList,
        relaxed: &[usize],
    ) -> PartInput {
        PartInput {
            part: k as u32,
            triangle_count: inputs.triangle_count,
            facets: list
                .facets
                .iter()
                .map(|(t, kind)| {
                    let id = match kind {
                        FacetKind::Scene(s) => inputs.triangle_source[*s as usize],
                        FacetKind::Seam => SEAM_FACET,
                    };
                    (*t, id)
                })
                .collect(),
            box_faces: list.box_faces.clone(),
            surface_relaxed: relaxed.contains(&k),
        }
    }

    /// The facets as the part builder takes them.
    pub(in crate::outofcore) fn facet_kinds(&self) -> Vec<([Vec3; 3], FacetKind)> {
        self.facets
            .iter()
            .map(|&(t, id)| {
                let kind = if id == SEAM_FACET {
                    FacetKind::Seam
                } else {
                    FacetKind::Scene(id)
                };
                (t, kind)
            })
            .collect()
    }
}

fn put_triangle(out: &mut Vec<u8>, t: &[Vec3; 3]) {
    for p in t {
        for c in p.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
}

/// The file's bytes and its checksum.
pub fn encode(input: &PartInput) -> (Vec<u8>, u64) {
    let mut out = Vec::with_capacity(
        HEADER_BYTES
            + FACET_BYTES * input.facets.len()
            + BOX_FACE_BYTES * input.box_faces.len()
            + 8,
    );
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&input.part.to_le_bytes());
    out.extend_from_slice(&input.triangle_count.to_le_bytes());
    let flags = if input.surface_relaxed {
        FLAG_SURFACE_RELAXED
    } else {
        0
    };
    out.extend_from_slice(&flags.to_le_bytes());
    out.extend_from_slice(&(input.facets.len() as u64).to_le_bytes());
    out.extend_from_slice(&(input.box_faces.len() as u64).to_le_bytes());
    for (t, id) in &input.facets {
        put_triangle(&mut out, t);
        out.extend_from_slice(&id.to_le_bytes());
    }
    for t in &input.box_faces {
        put_triangle(&mut out, t);
    }
    let sum = xxh64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    (out, sum)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

fn triangle_at(b: &[u8], at: usize) -> [Vec3; 3] {
    std::array::from_fn(|v| {
        let f = |c: usize| f32::from_le_bytes(b[at + 12 * v + 4 * c..][..4].try_into().expect("4"));
        Vec3::new(f(0), f(1), f(2))
    })
}

/// Reads a part input file's bytes (see the module docs for the checks)
/// and returns it with its checksum.
pub fn decode(bytes: &[u8]) -> Result<(PartInput, u64), InputFault> {
    let len = bytes.len() as u64;
    let min = (HEADER_BYTES + 8) as u64;
    if len < min {
        return Err(InputFault::Short { len, min });
    }
    let magic: [u8; 8] = bytes[..8].try_into().expect("8 bytes");
    if magic != MAGIC {
        return Err(InputFault::Magic {
            found: magic,
            expected: MAGIC,
        });
    }
    let version = u32_at(bytes, 8);
    if version != VERSION {
        return Err(InputFault::Version {
            found: version,
            expected: VERSION,
        });
    }
    let flags = u32_at(bytes, 20);
    if flags & !FLAG_SURFACE_RELAXED != 0 {
        return Err(InputFault::Flags(flags));
    }
    let (part, triangle_count) = (u32_at(bytes, 12), u32_at(bytes, 16));
    let (facets, box_faces) = (u64_at(bytes, 24), u64_at(bytes, 32));
    let expected = facets
        .checked_mul(FACET_BYTES as u64)
        .zip(box_faces.checked_mul(BOX_FACE_BYTES as u64))
        .and_then(|(a, b)| a.checked_add(b))
        .and_then(|n| n.checked_add(min));
    if expected != Some(len) {
        return Err(InputFault::Length {
            facets,
            box_faces,
            expected: expected.unwrap_or(u64::MAX),
            len,
        });
    }
    let body = &bytes[..bytes.len() - 8];
    let (found, computed) = (u64_at(bytes, bytes.len() - 8), xxh64(body));
    if found != computed {
        return Err(InputFault::Checksum { found, computed });
    }
    let finite = |t: &[Vec3; 3]| t.iter().all(|p| p.is_finite());
    let mut out = PartInput {
        part,
        triangle_count,
        facets: Vec::with_capacity(facets as usize),
        box_faces: Vec::with_capacity(box_faces as usize),
        surface_relaxed: flags & FLAG_SURFACE_RELAXED != 0,
    };
    for i in 0..facets as usize {
        let at = HEADER_BYTES + FACET_BYTES * i;
        let t = triangle_at(bytes, at);
        let id = u32_at(bytes, at + 36);
        if !finite(&t) {
            return Err(InputFault::NonFinite {
                what: "facet",
                index: i as u64,
            });
        }
        if id != SEAM_FACET && id >= triangle_count {
            return Err(InputFault::Triangle {
                facet: i as u64,
                triangle: id,
                count: triangle_count,
            });
        }
        out.facets.push((t, id));
    }
    let base = HEADER_BYTES + FACET_BYTES * facets as usize;
    for i in 0..box_faces as usize {
        let t = triangle_at(bytes, base + BOX_FACE_BYTES * i);
        if !finite(&t) {
            return Err(InputFault::NonFinite {
                what: "box face",
                index: i as u64,
            });
        }
        out.box_faces.push(t);
    }
    Ok((out, computed))
}
