//! The layouts with a GPU kernel and the assembly of their WGSL sources:
//! `camera.wgsl` (camera rays) + `common.wgsl` (records, bindings, hit
//! point) + `walk.wgsl`
//! (projected walk) + the layout's `layout_vx` / `layout_exit`, or
//! `common.wgsl` + `tet80.wgsl` (Plücker walk). Decision tables are packed
//! from the CPU crate's constants, so the two cannot drift apart.

use tet_core::layout::{Tet16Mesh, Tet20Mesh, Tet32Mesh, Tet80Mesh};
use tet_core::{FACE_VERTICES, TetMesh};
use tet_trace_cpu::tet80::EXIT;
use tet_trace_cpu::walk::EXIT_SLOT;

use crate::error::GpuError;

/// WGSL source of the layout-independent walk.
const WALK: &str = include_str!("walk.wgsl");
/// WGSL shared by the kernels (records, bindings, hit point).
const COMMON: &str = include_str!("common.wgsl");
/// WGSL of the camera-ray generator, shared with the BVH kernel.
pub(crate) const CAMERA: &str = include_str!("camera.wgsl");
/// WGSL of the Tet80 Plücker walk.
const TET80: &str = include_str!("tet80.wgsl");

/// The compact layout a [`crate::GpuTracer`] uploads and walks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GpuLayout {
    /// Aman et al. (2022) Tet20: `VX` + four rank-ordered links (20 bytes, Algorithm 5).
    Tet20,
    /// Aman et al. (2022) Tet32: three ids, `VX`, four slot-ordered links (32 bytes,
    /// Algorithm 3).
    Tet32,
    /// Aman et al. (2022) Tet16: `VX` + three link xor-differences (16 bytes,
    /// Algorithm 7; the entry link is carried along the walk).
    Tet16,
    /// Maria et al. (2017) Tet80: four vertex positions + four faces (80 bytes), walked
    /// with Plücker side products (not watertight by construction).
    Tet80,
}

impl GpuLayout {
    /// All layouts with a GPU kernel.
    pub const ALL: [GpuLayout; 4] = [
        GpuLayout::Tet20,
        GpuLayout::Tet32,
        GpuLayout::Tet16,
        GpuLayout::Tet80,
    ];

    /// Layout name (`"tet20"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            GpuLayout::Tet20 => "tet20",
            GpuLayout::Tet32 => "tet32",
            GpuLayout::Tet16 => "tet16",
            GpuLayout::Tet80 => "tet80",
        }
    }

    /// Method name for reports and `tet-bench` (`"gpu-tet20"`, ...).
    pub fn method(self) -> &'static str {
        match self {
            GpuLayout::Tet20 => "gpu-tet20",
            GpuLayout::Tet32 => "gpu-tet32",
            GpuLayout::Tet16 => "gpu-tet16",
            GpuLayout::Tet80 => "gpu-tet80",
        }
    }

    /// Bytes per tet record.
    pub fn record_bytes(self) -> usize {
        match self {
            GpuLayout::Tet20 => 20,
            GpuLayout::Tet32 => 32,
            GpuLayout::Tet16 => 16,
            GpuLayout::Tet80 => 80,
        }
    }

    /// The complete WGSL source of the layout's kernel.
    pub(crate) fn source(self, split: Split) -> String {
        let common = format!("{CAMERA}\n{COMMON}\n{}", split.wgsl());
        if self == GpuLayout::Tet80 {
            let [exit, second, first] = tet80_tables();
            format!(
                "{common}\nconst EXIT80: u32 = {exit}u;\nconst SECOND80: u32 = {second}u;\n\
                 const FIRST80: u32 = {first}u;\n{TET80}"
            )
        } else {
            let packed = exit_slot_table();
            format!(
                "{common}\nconst EXIT_SLOT_PACKED: u32 = {packed}u;\n{WALK}\n{}",
                self.snippet()
            )
        }
    }

    /// The WGSL of `layout_vx(t)` (paper `VX^t`) and `layout_exit(t, d,
    /// e)` (the raw link of tet `t` across the face opposite vertex `e`,
    /// with `s_ids` the entry face and `d` the fourth vertex): the ports of
    /// the CPU `Topology` implementations.
    fn snippet(self) -> &'static str {
        match self {
            GpuLayout::Tet80 => "",
            // Algorithm 5: links in the rank order of their opposite vertex.
            GpuLayout::Tet20 => {
                "fn layout_vx(t: u32) -> u32 { return tet_word(5u * t); }
fn layout_exit(t: u32, d: u32, e: u32) -> u32 {
    return tet_word(5u * t + 1u + rank_of(e, s_ids[0], s_ids[1], s_ids[2], d));
}
"
            }
            // Algorithm 3: v0 v1 v2 vx n0 n1 n2 n3, links in slot order.
            GpuLayout::Tet32 => {
                "fn layout_vx(t: u32) -> u32 { return tet_word(8u * t + 3u); }
fn layout_exit(t: u32, d: u32, e: u32) -> u32 {
    let b = 8u * t;
    if (e == tet_word(b)) { return tet_word(b + 4u); }
    if (e == tet_word(b + 1u)) { return tet_word(b + 5u); }
    if (e == tet_word(b + 2u)) { return tet_word(b + 6u); }
    return tet_word(b + 7u);
}
"
            }
            // Algorithm 7: N_want = N_entry ^ NX_rank(entry) ^ NX_rank(want),
            // NX_3 = 0; the entry face is opposite d.
            GpuLayout::Tet16 => {
                "fn layout_vx(t: u32) -> u32 { return tet_word(4u * t); }
fn tet16_nx(t: u32, r: u32) -> u32 { return select(tet_word(4u * t + 1u + min(r, 2u)), 0u, r == 3u); }
fn layout_exit(t: u32, d: u32, e: u32) -> u32 {
    let rd = rank_of(d, s_ids[0], s_ids[1], s_ids[2], d);
    let re = rank_of(e, s_ids[0], s_ids[1], s_ids[2], d);
    return s_entry ^ tet16_nx(t, rd) ^ tet16_nx(t, re);
}
"
            }
        }
    }

    /// The layout's tet records as 32-bit words (validates the mesh).
    pub(crate) fn encode(self, mesh: &TetMesh) -> Result<Vec<u32>, GpuError> {
        Ok(match self {
            GpuLayout::Tet20 => bytemuck::cast_slice(&Tet20Mesh::from_mesh(mesh)?.tets).to_vec(),
            GpuLayout::Tet32 => bytemuck::cast_slice(&Tet32Mesh::from_mesh(mesh)?.tets).to_vec(),
            GpuLayout::Tet16 => bytemuck::cast_slice(&Tet16Mesh::from_mesh(mesh)?.tets).to_vec(),
            GpuLayout::Tet80 => bytemuck::cast_slice(&Tet80Mesh::from_mesh(mesh)?.tets).to_vec(),
        })
    }
}
/// Most bindings the tet records may be split over.
pub(crate) const MAX_TET_BINDINGS: u32 = 4;

/// How the tet records are spread over storage bindings: `count` bindings of
/// `2^shift` words each (the last one shorter), so that word `i` lives in
/// binding `i >> shift` at `i & (2^shift − 1)`. One binding when the records
/// fit the binding limit; the single-binding shader has no extra cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Split {
    /// Number of bindings (1..=[`MAX_TET_BINDINGS`]).
    pub count: u32,
    /// log2 of the words per binding (only meaningful when `count > 1`).
    pub shift: u32,
}

impl Split {
    /// The split of `words` 32-bit words under a binding limit of
    /// `max_binding` bytes; `None` when more than `max_bindings` are needed.
    pub(crate) fn new(words: u64, max_binding: u64, max_bindings: u32) -> Option<Split> {
        if words * 4 <= max_binding {
            return Some(Split { count: 1, shift: 0 });
        }
        let per = max_binding / 4;
        if per == 0 {
            return None;
        }
        let shift = 63 - per.leading_zeros();
        let count = words.div_ceil(1u64 << shift);
        (count <= max_bindings.min(MAX_TET_BINDINGS) as u64).then_some(Split {
            count: count as u32,
            shift,
        })
    }

    /// Binding number of part `j`: 1, then 7, 8, 9.
    pub(crate) fn binding(j: u32) -> u32 {
        if j == 0 { 1 } else { 6 + j }
    }

    /// Words in part `j` of `words`.
    pub(crate) fn part(&self, j: u32, words: usize) -> std::ops::Range<usize> {
        if self.count == 1 {
            return 0..words;
        }
        let per = 1usize << self.shift;
        (j as usize * per).min(words)..((j as usize + 1) * per).min(words)
    }

    /// WGSL declarations of the tet bindings and `tet_word`.
    fn wgsl(&self) -> String {
        let mut s = String::new();
        for j in 0..self.count {
            let name = if j == 0 {
                "tets".to_string()
            } else {
                format!("tets{j}")
            };
            s += &format!(
                "@group(0) @binding({}) var<storage, read> {name}: array<u32>;\n",
                Split::binding(j)
            );
        }
        if self.count == 1 {
            s += "fn tet_word(i: u32) -> u32 { return tets[i]; }\n";
        } else {
            let mask = (1u64 << self.shift) - 1;
            s += &format!(
                "fn tet_word(i: u32) -> u32 {{\n    let o = i & {mask}u;\n    switch (i >> {}u) {{\n",
                self.shift
            );
            for j in 0..self.count {
                let name = if j == 0 {
                    "tets".to_string()
                } else {
                    format!("tets{j}")
                };
                if j + 1 == self.count {
                    s += &format!("        default: {{ return {name}[o]; }}\n");
                } else {
                    s += &format!("        case {j}u: {{ return {name}[o]; }}\n");
                }
            }
            s += "    }\n}\n";
        }
        s
    }
}

/// The CPU's `EXIT_SLOT` (Algorithm 1) packed 4 bits per entry for the
/// walk shader.
fn exit_slot_table() -> u32 {
    EXIT_SLOT
        .iter()
        .enumerate()
        .fold(0u32, |acc, (i, &x)| acc | (x as u32) << (4 * i))
}

/// The Tet80 tables packed 2 bits per entry for `tet80.wgsl`: `EXIT80`
/// (index `4e + 2s₁ + s₂`, the CPU's `tet80::EXIT`), `SECOND80` (index
/// `2e + s₁`: `FACE_VERTICES[e][1]` after a right turn, `[2]` after a left
/// one) and `FIRST80` (index `e`: `FACE_VERTICES[e][0]`).
fn tet80_tables() -> [u32; 3] {
    let (mut exit, mut second, mut first) = (0u32, 0u32, 0u32);
    for (e, row) in EXIT.iter().enumerate() {
        for (j, &x) in row.iter().enumerate() {
            exit |= (x as u32) << (2 * (4 * e + j));
        }
        let [a, b, c] = FACE_VERTICES[e];
        second |= (b as u32) << (2 * (2 * e)) | (c as u32) << (2 * (2 * e + 1));
        first |= (a as u32) << (2 * e);
    }
    [exit, second, first]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_parts_cover_the_records_within_the_limit() {
        assert_eq!(Split::new(810, 4096, 4), Some(Split { count: 1, shift: 0 }));
        assert_eq!(Split::new(810, 256, 4), None);
        assert_eq!(Split::new(3240, 4096, 2), None);
        for (words, max) in [(3240u64, 4096u64), (3240, 8000), (1000, 2000), (5, 16)] {
            let s = Split::new(words, max, 4).unwrap();
            let mut next = 0;
            for j in 0..s.count {
                let r = s.part(j, words as usize);
                assert_eq!(r.start, next);
                assert!(!r.is_empty() && (r.len() * 4) as u64 <= max);
                // Word i of part j is global word (j << shift) + i.
                assert_eq!(r.start, (j as usize) << s.shift);
                next = r.end;
            }
            assert_eq!(next, words as usize);
        }
    }

    #[test]
    fn packed_exit_slot_decodes_to_algorithm_1() {
        // Algorithm 1 (Aman et al. 2022) written out independently of the CPU table.
        let packed = exit_slot_table();
        for i in 0..8u32 {
            let (sa, sb, sc) = (i & 1 != 0, i & 2 != 0, i & 4 != 0);
            let alg1 = if sa {
                if sb { 0 } else { 2 }
            } else if sc {
                1
            } else {
                0
            };
            assert_eq!((packed >> (4 * i)) & 0xF, alg1, "case {i}");
        }
    }

    #[test]
    fn packed_tet80_tables_decode_to_the_cpu_tables() {
        let [exit, second, first] = tet80_tables();
        let get = |t: u32, i: usize| ((t >> (2 * i)) & 3) as usize;
        for e in 0..4 {
            for (j, &x) in EXIT[e].iter().enumerate() {
                assert_eq!(get(exit, 4 * e + j), x as usize);
                // The exit face contains the apex (slot e): it is never the
                // entry face.
                assert_ne!(get(exit, 4 * e + j), e);
            }
            assert_eq!(get(first, e), FACE_VERTICES[e][0]);
            assert_eq!(get(second, 2 * e), FACE_VERTICES[e][1]);
            assert_eq!(get(second, 2 * e + 1), FACE_VERTICES[e][2]);
        }
    }
}
