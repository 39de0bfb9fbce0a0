//! The traversal methods: what a `--method` names and its precision
//! ([`method`]), the tracers that are not in `tet-trace-cpu` — the BVH
//! baseline ([`bvh`]), Ray-Strips ([`strips`]), the f64 brute force
//! ([`brute`]) and Embree (`embree`, cargo feature `embree`) — and the
//! bytes of the layout each method walks ([`layouts`]).
//!
//! This module says which tracer implements each `--method` at each
//! precision ([`tracer`]).

pub mod brute;
pub mod bvh;
#[cfg(feature = "embree")]
pub mod embree;
pub mod layouts;
pub mod method;
pub mod strips;

use anyhow::{Result, bail};
use tet_core::TetMesh;
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::tet16::{Tet16Tracer, Tet16TracerF64};
use tet_trace_cpu::tet20::{Tet20Tracer, Tet20TracerF64};
use tet_trace_cpu::tet32::{Tet32Tracer, Tet32TracerF64};
use tet_trace_cpu::tet80::{Tet80ConsistentTracer, Tet80Tracer};

use bvh::BvhTracer;
use method::Method;
use strips::StripsTracer;

/// Builds the tracer of `method` over `mesh`, in f64 when `f64` is set.
pub fn tracer<'m>(method: Method, f64: bool, mesh: &'m TetMesh) -> Result<Box<dyn Tracer + 'm>> {
    tracer_capped(method, f64, mesh, None)
}

/// [`tracer`] with the tet walks' step cap replaced by `cap` (tets
/// visited before a walk reports [`tet_trace_cpu::ray::Failure::StepCap`];
/// the triangle structures have none).
pub fn tracer_capped<'m>(
    method: Method,
    f64: bool,
    mesh: &'m TetMesh,
    cap: Option<u32>,
) -> Result<Box<dyn Tracer + 'm>> {
    macro_rules! walk {
        ($t:expr) => {
            match cap {
                Some(c) => Box::new($t.with_step_cap(c)) as Box<dyn Tracer + 'm>,
                None => Box::new($t),
            }
        };
    }
    Ok(match (method, f64) {
        (Method::Sctp, false) => walk!(<SctpTracer<'_>>::new(mesh)?),
        (Method::Tet80, false) => walk!(Tet80Tracer::new(mesh)?),
        (Method::Tet80Consistent, false) => walk!(Tet80ConsistentTracer::consistent(mesh)?),
        (Method::Tet32, false) => walk!(<Tet32Tracer<'_>>::new(mesh)?),
        (Method::Tet32, true) => walk!(Tet32TracerF64::new(mesh)?),
        (Method::Tet20, false) => walk!(<Tet20Tracer<'_>>::new(mesh)?),
        (Method::Tet20, true) => walk!(Tet20TracerF64::new(mesh)?),
        (Method::Tet16, false) => walk!(<Tet16Tracer<'_>>::new(mesh)?),
        (Method::Tet16, true) => walk!(Tet16TracerF64::new(mesh)?),
        (Method::Obvhs, false) => Box::new(BvhTracer::new(mesh)),
        (Method::Strips, false) => Box::new(StripsTracer::new(mesh, false)?),
        (Method::StripsPackets, false) => Box::new(StripsTracer::new(mesh, true)?),
        #[cfg(feature = "embree")]
        (Method::Embree, false) => Box::new(embree::EmbreeTracer::new(mesh, 1)?),
        #[cfg(feature = "embree")]
        (Method::Embree8, false) => Box::new(embree::EmbreeTracer::new(mesh, 8)?),
        #[cfg(feature = "embree")]
        (Method::Embree16, false) => Box::new(embree::EmbreeTracer::new(mesh, 16)?),
        #[cfg(not(feature = "embree"))]
        (Method::Embree | Method::Embree8 | Method::Embree16, _) => bail!(
            "method {} needs tet-bench built with `--features embree` (and the system Embree 3 \
             library: `apt-get install libembree-dev`)",
            method.name()
        ),
        (Method::Brute, _) => Box::new(brute::BruteTracer { mesh }),
        (Method::Exact, false) => walk!(tet_trace_cpu::exact::ExactTracer::new(mesh)),
        (m, true) => bail!("method {} has no f64 variant", m.name()),
        (m, false) => bail!("{} runs on the GPU: only `render` supports it", m.name()),
    })
}

/// True when `method` has an f64 variant.
pub fn has_f64(method: Method) -> bool {
    matches!(
        method,
        Method::Tet32 | Method::Tet20 | Method::Tet16 | Method::Brute
    )
}

/// The CPU methods every comparison runs (`tables`, `accuracy --methods
/// all`): the tet walks, the obvhs BVH, Ray-Strips and, when built with
/// the `embree` feature, Embree's single rays and packets (of sixteen
/// where the CPU has AVX-512).
pub fn cpu_methods() -> Vec<Method> {
    let mut m = vec![
        Method::Tet20,
        Method::Tet16,
        Method::Tet32,
        Method::Tet80,
        Method::Tet80Consistent,
        Method::Sctp,
        Method::Obvhs,
        Method::Strips,
    ];
    m.extend(embree_methods());
    m
}

/// Embree's methods this build and CPU run: none without the `embree`
/// feature; single rays and packets of eight, and of sixteen where the
/// CPU has AVX-512.
pub fn embree_methods() -> Vec<Method> {
    let mut m = Vec::new();
    if cfg!(feature = "embree") {
        m.extend([Method::Embree, Method::Embree8]);
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            m.push(Method::Embree16);
        }
    }
    m
}
