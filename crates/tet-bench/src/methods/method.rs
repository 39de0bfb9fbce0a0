//! The traversal methods (`--method`, `--methods`) and the precision of
//! their kernels (`--precision`): their names, the tet layout each walks,
//! and which of them walk tets or run on the GPU.

use clap::ValueEnum;

/// Traversal methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Scalar triple products (Lagae & Dutré 2008; 32-byte baseline layout).
    Sctp,
    /// Plücker traversal (Maria et al. 2017; Tet80 layout).
    Tet80,
    /// Tet80 with consistent side products: one per edge, the same in
    /// every tet around it (canonical edge orientation, one rule for zero).
    Tet80Consistent,
    /// 2-D projected traversal of Aman et al. (2022) on Tet32.
    Tet32,
    /// 2-D projected traversal of Aman et al. (2022) on Tet20.
    Tet20,
    /// 2-D projected traversal of Aman et al. (2022) on Tet16.
    Tet16,
    /// BVH baseline (obvhs, BVH2).
    Obvhs,
    /// Ray-Strips (Lauterbach et al. 2007): strip hierarchies under an SAH BVH,
    /// one ray at a time.
    Strips,
    /// Ray-Strips with 2×2 ray packets (groups of four consecutive rays).
    StripsPackets,
    /// Embree 3, one `rtcIntersect1` per ray (needs the `embree` feature).
    Embree,
    /// Embree 3, `rtcIntersect8` on packets of 8 rays (needs the `embree` feature).
    Embree8,
    /// Embree 3, `rtcIntersect16` on packets of 16 rays (needs the `embree`
    /// feature and a CPU with AVX-512).
    Embree16,
    /// f64 brute force over all triangles (reference; slow).
    Brute,
    /// The exact reference walk: exact side products with a symbolic tie
    /// rule (reference; not in the default comparisons).
    Exact,
    /// Tet20 walk as a wgpu compute shader (needs the `gpu` feature).
    GpuTet20,
    /// Tet32 on the GPU.
    GpuTet32,
    /// Tet16 on the GPU.
    GpuTet16,
    /// Tet80 (Plücker) on the GPU.
    GpuTet80,
}

impl Method {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Sctp => "sctp",
            Method::Tet80 => "tet80",
            Method::Tet80Consistent => "tet80-consistent",
            Method::Tet32 => "tet32",
            Method::Tet20 => "tet20",
            Method::Tet16 => "tet16",
            Method::Obvhs => "obvhs",
            Method::Strips => "strips",
            Method::StripsPackets => "strips-packets",
            Method::Embree => "embree",
            Method::Embree8 => "embree8",
            Method::Embree16 => "embree16",
            Method::Brute => "brute",
            Method::Exact => "exact",
            Method::GpuTet20 => "gpu-tet20",
            Method::GpuTet32 => "gpu-tet32",
            Method::GpuTet16 => "gpu-tet16",
            Method::GpuTet80 => "gpu-tet80",
        }
    }

    /// The tet layout the method walks (a name of
    /// `tet_core::memory::LAYOUT_NAMES`); `None` for the methods that walk
    /// no layout (BVHs, Ray-Strips, brute force, the exact walk).
    pub fn layout(self) -> Option<&'static str> {
        match self {
            Method::Sctp => Some("baseline32"),
            Method::Tet80 | Method::Tet80Consistent | Method::GpuTet80 => Some("tet80"),
            Method::Tet32 | Method::GpuTet32 => Some("tet32"),
            Method::Tet20 | Method::GpuTet20 => Some("tet20"),
            Method::Tet16 | Method::GpuTet16 => Some("tet16"),
            Method::Obvhs
            | Method::Strips
            | Method::StripsPackets
            | Method::Embree
            | Method::Embree8
            | Method::Embree16
            | Method::Brute
            | Method::Exact => None,
        }
    }

    /// True for the methods that walk tets (and so report tets per ray).
    pub fn walks_tets(self) -> bool {
        self.layout().is_some() || self == Method::Exact
    }

    /// True for the GPU methods.
    pub fn is_gpu(self) -> bool {
        matches!(
            self,
            Method::GpuTet20 | Method::GpuTet32 | Method::GpuTet16 | Method::GpuTet80
        )
    }
}

/// Floating-point precision of the kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Precision {
    /// f32 kernels.
    F32,
    /// f64 kernels.
    F64,
    /// Both.
    Both,
}
