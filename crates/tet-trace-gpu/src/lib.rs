//! # tet-trace-gpu
//!
//! Ray traversal through a constrained tetrahedralization as portable
//! [`wgpu`] compute shaders (WGSL): one invocation walks one ray from tet to
//! tet until it crosses a constrained face (a scene triangle) or leaves the
//! mesh. Runs on any adapter wgpu's Vulkan backend finds, including the
//! software rasteriser lavapipe (Debian package `mesa-vulkan-drivers`), which
//! is what the tests use on machines without a GPU.
//!
//! * [`GpuContext`]: adapter + device, with the adapter's highest limits and
//!   timestamp queries when available;
//! * [`GpuTracer`]: a mesh uploaded in one compact layout ([`GpuLayout`]:
//!   Tet20, Tet32, Tet16, Tet80) with its kernel; [`GpuTracer::trace_batch`] traces
//!   arbitrary rays (secondary rays from the CPU side), [`GpuTracer::render`]
//!   generates camera rays on the GPU;
//! * results are [`tet_trace_cpu::TraceOutcome`]s (the CPU hit records, same
//!   meaning field by field) plus [`DispatchStats`];
//! * walks that lost their way on the GPU are walked again on the host by
//!   the exact walk, as the CPU tracers do (see "Walks that lost their
//!   way" below);
//! * [`GpuBvh`]: the same-run GPU BVH baseline over the same triangles (see
//!   "The GPU BVH baseline" below).
//!
//! ## The kernels: a port of the CPU walk (Aman et al. 2022, Algorithms 1–7)
//!
//! `src/walk.wgsl` is a statement-by-statement port of the CPU walk's step
//! (`advance` in `tet-trace-cpu/src/walk/step.rs`) with the `DuffF32`
//! projection (see [`tet_trace_cpu::walk`] for the watertightness
//! argument); each layout appends its
//! `layout_vx` / `layout_exit` functions (ports of the CPU `Topology`
//! implementations: Tet32 Algorithm 3 compares the exit vertex with the three
//! stored ids, Tet20 Algorithm 5 indexes the rank-ordered links, Tet16
//! Algorithm 7 xors the carried entry link with two `NX` differences).
//!
//! `src/tet80.wgsl` ports `tet_trace_cpu::tet80::Tet80Tracer`, the Plücker
//! walk of Maria et al. (2017, §3–4): per tet the apex `V_e` opposite the
//! entry face `e`, `m = d × (V_e − o)`, two side products
//! `(V_x − V_e) · m` and the CPU's `EXIT` table (packed into `u32` constants
//! by the host, so the tables cannot drift apart). Like the CPU kernel it is
//! not watertight (zero counts as "right", and each tet computes an edge's
//! side product in its own frame), and its products are sums a driver may
//! contract into FMAs, so near-zero side products may differ from the CPU.
//!
//! | paper (Aman et al. 2022) | CPU (`tet-trace-cpu`) | WGSL |
//! |---|---|---|
//! | `idx_0..2`, `p_0..2` | `State::ids`, `State::p` | `s_ids`, `s_p` |
//! | `VX^next`, `idx_3 = idx_0 ⊕ idx_1 ⊕ idx_2 ⊕ VX` | `Topology::vx` | `layout_vx`, `d` |
//! | projection onto `(u, v)` ⊥ ray | `DuffF32::project` | `project` |
//! | Algorithm 1 (exit face) | `exit_slot`, `EXIT_SLOT` | `exit_slot` (table packed in a `u32`) |
//! | GETNEXTTET32/20/16 (Alg. 3, 5, 7) | `Topology::exit_link` | `layout_exit` |
//! | `order_a`, `order_b` | `rank_of` | `rank_of` |
//! | entry link (Tet16) | `Lane::entry_raw` | `s_entry` |
//! | exact sign of a zero determinant, tie rule (symbolic perturbation) | `ExactDet`, `left_2d!` | `product_error`, `left` |
//! | constrained-face crossing / hit | `resolve_face`, `face_hit` | `resolve` |
//!
//! GPU buffers: points (`12 B` each, `f32 x,y,z`), the layout's tet records
//! (Tet20 `20 B`: `VX` + four links in rank order; Tet32 `32 B`; Tet16
//! `16 B`; Tet80 `80 B` with the vertex positions inline, the point array
//! then only serves the hit computation), and a 24-byte constrained-face record
//! (`triangle, front tet, back tet, v0, v1, v2`) that the kernel needs to
//! report the triangle, to order the barycentrics like the CPU and to cross
//! faces before `t_min` (secondary rays). Normals and other attributes stay
//! on the host ([`GpuMemory`] reports the bytes).
//!
//! ## Where the GPU may differ from the CPU kernel
//!
//! * **Edge test.** The CPU computes `det = a.x·b.y − a.y·b.x` and tests its
//!   sign. WGSL gives no control over fused multiply-add contraction, and a
//!   fused `fma(a.x, b.y, −a.y·b.x)` is *not* exactly antisymmetric, which would
//!   break watertightness. The kernel therefore compares the two rounded
//!   products, `a.x·b.y > a.y·b.x`: for finite values `fl(l − r) > 0 ⇔ l > r`
//!   (gradual underflow), so this is the CPU decision bit for bit, and no
//!   contraction can apply (there is no addition). Equal rounded products
//!   are decided, as on the CPU (`ExactDet`), by the exact determinant: the
//!   difference of the two products' rounding errors, each exact by
//!   Dekker's two-product over halves split with a bit mask (every partial
//!   product is exact, so a fused multiply-add cannot change it); this is
//!   what ends rays lying in the plane of flat faces (see
//!   [`tet_trace_cpu::walk`], "Why the walk ends"). Differences only when a
//!   product overflows to ±∞ or underflows into a subnormal on an adapter that
//!   flushes subnormals to zero (coordinates beyond `~1e19` or below `~1e-19`
//!   relative to the ray origin).
//! * **Projection.** `u·(P − o)` is written as the CPU's left-to-right sum
//!   (`u.x q.x + u.y q.y + u.z q.z`), but a driver may contract it into FMAs.
//!   The walk stays watertight (every tet sees the same projected vertex,
//!   because it is the same pure function in the same shader), but the
//!   projected values, hence rare near-tie decisions, may differ from the CPU.
//!   The tests measure how often (`tests/walk.rs` prints the counts): on
//!   lavapipe (Mesa 22.3.6, LLVM 15) every walk of every test ray — random,
//!   aimed at vertices, edges and face centroids, axis-aligned through
//!   vertices on an unjittered grid, secondary rays, camera rays — equals the
//!   CPU walk (same faces, same tet counts) for Tet20, Tet32 and Tet16.
//! * **Projection basis.** For [`GpuTracer::trace_batch`] the host builds Duff
//!   et al.'s basis in f64 and rounds it to f32, exactly as the CPU does, and
//!   uploads it with the ray. Camera rays made on the GPU
//!   ([`GpuTracer::render`]) build it in f32 (no portable f64 in WGSL), and the
//!   ray directions themselves may differ in the last bit (Vulkan allows
//!   inexact `sqrt` and division); camera images therefore agree with the CPU
//!   renderer per triangle except on rays that graze an edge.
//! * **Hit point.** The CPU computes `t` and barycentrics once per ray in f64;
//!   the kernel does it in f32 (same formula). They agree to f32 rounding, and
//!   the decision `t < t_min` (cross a constrained face before the ray's start
//!   interval) can differ when `t` is within rounding of `t_min`. Where the
//!   ray runs along a face (within a millionth of a radian of its plane) or
//!   crosses its plane off the face at a grazing angle, the CPU reports the
//!   point of the face nearest the line and the kernel the plane's crossing
//!   (`tet_trace_cpu::walk::face_hit`): the same face, a different `t`.
//!   A ray re-walked on the host (see "Walks that lost their way") has the
//!   exact walk's hit, computed on the host as on the CPU.
//! * **Start.** For batch rays the host runs the CPU's exact start logic
//!   (`tet_trace_cpu::walk::start_exit_face`: start tet, the tets around an
//!   origin on a face/edge/vertex, last-resort fallback) and uploads the
//!   resulting exit face, so the GPU starts exactly where the CPU starts.
//!   Camera rays start on the GPU in the one start tet (`start_in_tet`); the
//!   few rays whose origin lies on that tet's boundary so that no face winds
//!   around it are re-traced through the batch path (CPU-generated rays).
//!   From outside the mesh ([`GpuTracer::render_view`]) the host chooses
//!   each ray's entry face and traces the rays through the batch path.
//!
//! ## Walks that lost their way: the exact walk, on the host
//!
//! A floating-point walk decides every step with the exact sign of its
//! rounded projection; in a tet thinner than that rounding (a near-flat
//! sliver) it can circle until its step cap, and the Plücker walk (Tet80,
//! not watertight) can leave the ray's line and circle too. The default
//! step cap ([`tet_trace_cpu::walk::step_cap`], twice the tets plus 1024)
//! is more than any line's walk takes, so reaching it proves the walk
//! lost; so does a start that finds no tet whose projection holds the
//! line (`Failure::Lost`). The CPU tracers then walk the ray again with
//! the exact walk ([`tet_trace_cpu::exact::ExactTracer`]: exact predicates,
//! symbolic perturbation) from the same start, and report that outcome
//! with the tets of both walks counted.
//!
//! WGSL has no exact arithmetic, so the GPU tracer does the same on the
//! host: after a dispatch's outcomes are read back, every walk that reached
//! the step cap or reported `Lost` is walked again by `ExactTracer` on the
//! CPU, from the same start, with the tets of both walks counted:
//!
//! * [`GpuTracer::trace_batch`]: from the ray's own [`tet_trace_cpu::Start`];
//! * [`GpuTracer::render`]: from the start tet, on the host's camera ray
//!   (`tet_trace_cpu::render::PinholeCamera`, the CPU renderer's ray; the
//!   GPU's own ray may differ in the last bit, see "Projection basis");
//!   rays whose GPU start failed are re-traced through the batch path, which
//!   re-walks them there if they lose their way again;
//! * [`GpuTracer::render_view`] from outside the mesh: through the batch
//!   path, from the entry face the host chose.
//!
//! So where the CPU walk was lost, the GPU tracer reports what the CPU
//! tracer reports (bit for bit for batch rays whose GPU walk was lost as
//! well). A caller's lower step cap ([`GpuTracer::with_step_cap`], to bound
//! the work per ray) keeps the `StepCap` failure, as on the CPU: below the
//! default cap it no longer proves a lost walk. [`DispatchStats`] counts
//! the re-walked rays ([`DispatchStats::host_rewalks`]) and their host time
//! ([`DispatchStats::host_rewalk_ms`]) apart from the GPU and wall times,
//! so those measure the GPU walk alone. The GPU's own walk has no such
//! fallback: a kernel that needs the exact outcome on the device (no host
//! round trip) would need an exact walk in WGSL.
//!
//! ## The GPU BVH baseline
//!
//! [`GpuBvh`] is the peer the GPU tet walks are measured against: a binary
//! BVH over the mesh's constrained faces (the scene triangles), built on the
//! CPU by obvhs (SAH, spatial pre-splits, reinsertion: the preset of the CPU
//! BVH baseline) and traversed by a WGSL kernel (`src/bvh.wgsl`: a stack of
//! postponed subtrees, the nearer child first, subtrees behind the closest
//! hit skipped, Möller–Trumbore triangles in f32). It runs on the same
//! [`GpuContext`], takes the same [`tet_trace_cpu::Ray`]s, generates camera
//! rays with the walks' own WGSL camera code ([`GpuBvh::render`], rays
//! bit-identical to [`GpuTracer::render`]'s) and reports the same
//! [`DispatchStats`], so a benchmark compares walk and BVH on the same rays,
//! in the same run, on the same device. Its hits report the scene triangle id
//! the walks report; the BVH's triangle test is not watertight, so the two may
//! differ on rays that graze an edge. Nodes of 32 bytes, leaf triangles of 48
//! bytes (`src/bvh.rs` has the layout); [`DispatchStats::tets_visited`] counts
//! the BVH boxes tested.
//!
//! ## Limits
//!
//! Every storage buffer must fit the device's `max_storage_buffer_binding_size`
//! and `max_buffer_size`. [`GpuContext`] requests the adapter's highest limits
//! (e.g. 128 MiB bindings on lavapipe, up to 2–4 GiB on hardware). The tet
//! records, the largest array, are split over up to four bindings of `2^k`
//! words when they do not fit one (the shader then picks the binding with a
//! shift and a mask; a mesh that fits one binding gets the plain accessor and
//! pays nothing): 512 MiB of records on lavapipe, i.e. ≈ 26 M Tet20 tets or
//! 6.7 M Tet80 tets. Points and the constrained-face table are not split,
//! nor are the BVH's nodes and triangles ([`GpuBvh`]). A
//! mesh that still does not fit gives [`GpuError::TooLarge`] naming the buffer
//! and the limit. Ray batches and camera frames are split into as many
//! dispatches as the limits (and the 65 535-workgroup dispatch limit)
//! require.
//!
//! A walk that loses its way spends its whole step cap on the GPU before
//! the host re-walks it (see "Walks that lost their way"); the re-walks run
//! on the calling thread, one exact walk per lost ray. They are rare (none
//! of the projected walks' test rays; a few per thousand of the Plücker
//! walk's rays aimed at vertices on a jittered grid), but a mesh full of
//! slivers makes them a host cost that [`DispatchStats::host_rewalk_ms`]
//! shows.
//!
//! ## Testing without a GPU
//!
//! `tests/walk.rs` runs on lavapipe (`apt-get install -y
//! --no-install-recommends mesa-vulkan-drivers`). Without an adapter the
//! tests print a skip message, unless [`REQUIRE_ADAPTER_ENV`]
//! (`TET_GPU_REQUIRED=1`) is set, which makes that a failure (CI). The
//! wgpu instance and adapter are looked up once per process and shared by
//! every [`GpuContext`]: on a machine without a Wayland session, Mesa's
//! window-system probe prints `error: XDG_RUNTIME_DIR is invalid or not set
//! in the environment.` at each lookup although nothing failed, so it
//! appears at most once per process (setting `XDG_RUNTIME_DIR`, e.g. to
//! `/tmp`, silences it).
//!
//! ## Timing
//!
//! With `Features::TIMESTAMP_QUERY` every dispatch is bracketed by timestamp
//! writes and [`DispatchStats::gpu_ms`] holds the summed GPU time; wall time
//! (submit to results on the host) is always in [`DispatchStats::wall_ms`].
//! The host re-walks of lost walks are in neither: their count and time are
//! [`DispatchStats::host_rewalks`] and [`DispatchStats::host_rewalk_ms`]
//! ([`DispatchStats::total_ms`] adds them to the wall time).

#![deny(missing_docs)]

mod bvh;
mod context;
mod dispatch;
mod error;
mod layout;
mod lost;
mod records;
mod starts;
mod stats;
mod tracer;

pub use bvh::{BvhHit, GpuBvh};
pub use context::{GpuContext, GpuOptions, REQUIRE_ADAPTER_ENV};
pub use error::GpuError;
pub use layout::GpuLayout;
pub use stats::{DispatchStats, GpuFrame, GpuMemory};
pub use tracer::GpuTracer;
