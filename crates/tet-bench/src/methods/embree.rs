//! The Embree 3 baseline (cargo feature `embree`; needs the system library,
//! e.g. `apt-get install libembree-dev`, Embree 3.13): the reference the
//! papers compare against ("Embree 3 single rays" in neptun's table).
//!
//! One triangle geometry over the scene triangles (the constrained faces, in
//! their source winding, so Embree's primitive id is the constrained-face
//! index), default build quality and scene flags, as an application would
//! use it. Two methods:
//! * `embree`: one `rtcIntersect1` per ray (single rays; a batch of rays
//!   from one start, a camera tile, in a coherent context, other rays in an
//!   incoherent one);
//! * `embree8`: `rtcIntersect8` on packets of eight consecutive rays of a
//!   batch (the renderer's batches are 16×16 tiles, so packets are
//!   coherent), secondary rays included: a tile's AO rays and its shadow
//!   rays toward one light go in packets of eight too;
//! * `embree16`: `rtcIntersect16`, likewise on packets of sixteen (Embree
//!   runs those only with AVX-512: the method is refused on a CPU
//!   without it).
//!
//! Every query is `rtcIntersect` (closest hit), AO and shadow rays
//! included, as for every other method. `rtcOccluded` (any hit) would stop
//! an occluded ray at its first hit, but on the AO rays of these scenes
//! most find nothing within their length (82 % on Torus Knots), and an
//! open ray traverses the same nodes either way.
//!
//! Hits are returned through the same record as every other method
//! ([`super::bvh::input_hit`]: t from Embree, barycentrics and sides
//! recomputed from the mesh), so images and accuracy compare like for like.
//! A ray that starts on a face (secondary rays, [`Start::Face`]) must not
//! hit that face again: Embree has no per-ray skip, so a hit on it is
//! retraced from just beyond it (at most a few times).
//!
//! Flush-to-zero / denormals-are-zero (MXCSR), which Embree recommends, is
//! not set: on Torus Knots it changed nothing beyond noise, and setting it
//! needs `unsafe` and would leak into the other methods' threads.

use embree3::sys::{RTCRayHit8, RTCRayHit16};
use embree3::{
    BufferUsage, Device, Format, GeometryKind, Hit8, Hit16, IntersectContext, Ray as ERay, Ray8,
    Ray16, RayHit as ERayHit, Scene, ValidMask, ValidMaskN,
};
use tet_core::{InputTriangles, TetMesh};
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::ray::{Failure, Ray, TraceOutcome};
use tet_trace_cpu::walk::Start;

use super::bvh::input_hit;

/// Embree's "no hit" geometry id.
const INVALID_ID: u32 = u32::MAX;
/// Retraces allowed past the start face before giving up (reported as a miss).
const SKIP_RETRIES: usize = 8;

/// An Embree scene over the constrained faces of a mesh.
pub struct EmbreeTracer<'m> {
    /// The mesh whose input triangles Embree holds (its constrained faces
    /// merged back: [`InputTriangles`]).
    mesh: &'m TetMesh,
    /// The input triangles (Embree's primitive ids index them).
    inputs: InputTriangles,
    /// Embree's committed scene (one triangle geometry).
    scene: Scene<'static>,
    /// Rays per query: 1 (`embree`), 8 (`embree8`) or 16 (`embree16`).
    width: usize,
    /// The device, which must outlive the scene (Scene holds its own handle).
    _device: Device,
}

/// Why Embree could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum EmbreeError {
    /// The device or a buffer could not be created.
    #[error("Embree: {0}")]
    Embree(String),
    /// Embree indexes triangles with 32-bit ids.
    #[error("Embree: {0} triangles exceed its 32-bit primitive ids")]
    TooLarge(usize),
    /// Packets come in 1, 8 or 16 rays.
    #[error("Embree: no packets of {0} rays (1, 8 or 16)")]
    Width(usize),
    /// `rtcIntersect16` needs AVX-512.
    #[error("Embree: 16-wide packets need a CPU with AVX-512")]
    NoAvx512,
}

/// An Embree failure, naming what was being created.
fn embree_err(what: &str, e: impl std::fmt::Debug) -> EmbreeError {
    EmbreeError::Embree(format!("{what}: {e:?}"))
}

impl<'m> EmbreeTracer<'m> {
    /// Builds the Embree scene; `width` (1, 8 or 16) selects single rays
    /// or `rtcIntersect8` / `rtcIntersect16` packets.
    pub fn new(mesh: &'m TetMesh, width: usize) -> Result<Self, EmbreeError> {
        if mesh.constrained.len() >= INVALID_ID as usize {
            return Err(EmbreeError::TooLarge(mesh.constrained.len()));
        }
        if !matches!(width, 1 | 8 | 16) {
            return Err(EmbreeError::Width(width));
        }
        if width == 16 && !has_avx512() {
            return Err(EmbreeError::NoAvx512);
        }
        let inputs = InputTriangles::of(mesh);
        let device = Device::new().map_err(|e| embree_err("device", e))?;
        let mut scene = device.create_scene().map_err(|e| embree_err("scene", e))?;
        if !inputs.is_empty() {
            let mut geom = device
                .create_geometry(GeometryKind::TRIANGLE)
                .map_err(|e| embree_err("geometry", e))?;
            geom.set_new_buffer::<[f32; 3]>(
                BufferUsage::VERTEX,
                0,
                Format::FLOAT3,
                12,
                mesh.points.len(),
            )
            .map_err(|e| embree_err("vertex buffer", e))?
            .iter_mut()
            .zip(&mesh.points)
            .for_each(|(dst, p)| *dst = p.to_array());
            geom.set_new_buffer::<[u32; 3]>(BufferUsage::INDEX, 0, Format::UINT3, 12, inputs.len())
                .map_err(|e| embree_err("index buffer", e))?
                .iter_mut()
                .zip(&inputs.corners)
                .for_each(|(dst, c)| *dst = *c);
            let geom = geom.commit();
            scene.attach_geometry(&geom);
        }
        scene.commit();
        Ok(EmbreeTracer {
            mesh,
            inputs,
            scene,
            width,
            _device: device,
        })
    }

    /// The ray as Embree's, from `t_near` to the ray's `t_max`.
    fn embree_ray(ray: &Ray, t_near: f32) -> ERay {
        ERay::segment(
            ray.origin.to_array(),
            ray.direction.to_array(),
            t_near,
            ray.t_max,
        )
    }

    /// The outcome of an Embree hit (`prim == INVALID_ID` for none).
    fn outcome(&self, ray: &Ray, prim: u32, t: f32) -> TraceOutcome {
        if prim == INVALID_ID {
            TraceOutcome::Miss { tets_visited: 0 }
        } else {
            TraceOutcome::Hit(input_hit(self.mesh, &self.inputs, ray, prim, t))
        }
    }

    /// A single ray from `start` traced in `ctx`: a ray that is not valid
    /// is a failure, and one from a face must not report that face.
    fn trace_in(&self, ctx: &mut IntersectContext, ray: &Ray, start: Start) -> TraceOutcome {
        if !ray.is_valid() {
            return TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            };
        }
        // A ray leaving a face skips the whole input triangle (its plane).
        let skip = start.on_face().and_then(|f| self.inputs.of_face(f));
        self.trace_one(ctx, ray, skip.unwrap_or(u32::MAX))
    }

    /// A single ray that must not report input triangle `skip` (u32::MAX:
    /// none),
    /// traced in `ctx` (coherent for the rays of a camera tile).
    fn trace_one(&self, ctx: &mut IntersectContext, ray: &Ray, skip: u32) -> TraceOutcome {
        let mut t_near = ray.t_min.max(0.0);
        for _ in 0..=SKIP_RETRIES {
            let mut rh = ERayHit::from(Self::embree_ray(ray, t_near));
            self.scene.intersect(ctx, &mut rh);
            let (geom, prim, t) = (rh.hit.geomID, rh.hit.primID, rh.ray.tfar);
            if geom == INVALID_ID {
                return self.outcome(ray, INVALID_ID, 0.0);
            }
            if prim != skip {
                return self.outcome(ray, prim, t);
            }
            t_near = t.next_up();
        }
        TraceOutcome::Miss { tets_visited: 0 }
    }
}

impl Tracer for EmbreeTracer<'_> {
    fn name(&self) -> String {
        match self.width {
            1 => "embree3-single/f32".into(),
            w => format!("embree3-packet{w}/f32"),
        }
    }

    fn mesh(&self) -> &TetMesh {
        self.mesh
    }

    fn walks_tets(&self) -> bool {
        false
    }

    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.trace_in(&mut IntersectContext::incoherent(), ray, start)
    }

    /// Packets also for rays from a viewpoint outside the tet mesh (their
    /// starts are ignored).
    fn trace_batch_from(
        &self,
        rays: &[Ray],
        starts: tet_trace_cpu::Starts<'_>,
        out: &mut [TraceOutcome],
    ) {
        match starts {
            tet_trace_cpu::Starts::Outside(_) => self.trace_batch(rays, Start::Tet(0), out),
            tet_trace_cpu::Starts::Same(s) => self.trace_batch(rays, s, out),
            tet_trace_cpu::Starts::Each(s) => self.trace_each(rays, s, out),
        }
    }

    /// A batch of shadow rays: Embree has no tets to stop at, so each runs
    /// to its `t_max` (the light's distance), in packets for `embree8`.
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        _stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        self.trace_each(rays, starts, out);
    }

    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        let from_face = matches!(start, Start::Face { .. });
        if self.width == 1 || from_face {
            // A batch from one start that is not a face is a tile of camera
            // rays: coherent, which is how an application would tell Embree.
            let mut ctx = if from_face {
                IntersectContext::incoherent()
            } else {
                IntersectContext::coherent()
            };
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = self.trace_in(&mut ctx, r, start);
            }
            return;
        }
        self.packets(IntersectContext::coherent(), rays, |_| u32::MAX, out);
    }
}

/// True where the CPU runs Embree's 16-wide packets (AVX-512F).
fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// An Embree ray packet (`RTCRayHit8`, `RTCRayHit16`): filled lane by lane,
/// traced by the matching `rtcIntersectN`, read back lane by lane.
trait Packet {
    /// Rays per packet.
    const N: usize;
    /// A packet of invalid lanes.
    fn empty() -> Self;
    /// Lane `i` traces `r` from `t_near`.
    fn set(&mut self, i: usize, r: &Ray, t_near: f32);
    /// `rtcIntersectN` on the lanes `valid` marks.
    fn intersect(&mut self, scene: &Scene, ctx: &mut IntersectContext, valid: &[ValidMask]);
    /// Lane `i`'s primitive and distance, `None` for no hit.
    fn hit(&self, i: usize) -> Option<(u32, f32)>;
}

/// [`Packet`] for one of Embree's packet types and its `rtcIntersectN`.
macro_rules! packet {
    ($t:ty, $ray:ty, $hit:ty, $n:literal, $intersect:ident) => {
        impl Packet for $t {
            const N: usize = $n;
            fn empty() -> Self {
                Self {
                    ray: <$ray>::empty(),
                    hit: <$hit>::new(),
                }
            }
            fn set(&mut self, i: usize, r: &Ray, t_near: f32) {
                let p = &mut self.ray;
                [p.org_x[i], p.org_y[i], p.org_z[i]] = r.origin.to_array();
                [p.dir_x[i], p.dir_y[i], p.dir_z[i]] = r.direction.to_array();
                p.tnear[i] = t_near;
                p.tfar[i] = r.t_max;
                p.mask[i] = u32::MAX;
                p.id[i] = i as u32;
            }
            fn intersect(
                &mut self,
                scene: &Scene,
                ctx: &mut IntersectContext,
                valid: &[ValidMask],
            ) {
                let mut v = [ValidMask::Invalid; $n];
                v.copy_from_slice(&valid[..$n]);
                scene.$intersect(ctx, self, &ValidMaskN::from(v));
            }
            fn hit(&self, i: usize) -> Option<(u32, f32)> {
                (self.hit.geomID[i] != INVALID_ID).then(|| (self.hit.primID[i], self.ray.tfar[i]))
            }
        }
    };
}

packet!(RTCRayHit8, Ray8, Hit8, 8, intersect8);
packet!(RTCRayHit16, Ray16, Hit16, 16, intersect16);

impl EmbreeTracer<'_> {
    /// Rays with a start each (a tile's secondary rays), over the shortest
    /// of the three slices: single rays, or packets for `embree8`; a ray
    /// that starts on a face never reports that face's input triangle.
    fn trace_each(&self, rays: &[Ray], starts: &[Start], out: &mut [TraceOutcome]) {
        let n = tet_trace_cpu::Starts::Each(starts).batch_len(rays.len(), out.len());
        let (rays, starts, out) = (&rays[..n], &starts[..n], &mut out[..n]);
        let skip = |i: usize| {
            starts[i]
                .on_face()
                .and_then(|f| self.inputs.of_face(f))
                .unwrap_or(u32::MAX)
        };
        if self.width == 1 {
            let mut ctx = IntersectContext::incoherent();
            for (i, (r, o)) in rays.iter().zip(out.iter_mut()).enumerate() {
                *o = self.trace_in(&mut ctx, r, starts[i]);
            }
            return;
        }
        self.packets(IntersectContext::incoherent(), rays, skip, out);
    }

    /// `rtcIntersect8` or `rtcIntersect16` (the tracer's width) on
    /// packets of consecutive rays in `ctx`; ray `i` must not report input
    /// triangle `skip(i)` (`u32::MAX`: none): a lane that does is traced
    /// again alone, past it ([`Self::trace_one`]).
    fn packets(
        &self,
        ctx: IntersectContext,
        rays: &[Ray],
        skip: impl Fn(usize) -> u32,
        out: &mut [TraceOutcome],
    ) {
        if self.width == 16 {
            self.packets_of::<RTCRayHit16>(ctx, rays, skip, out)
        } else {
            self.packets_of::<RTCRayHit8>(ctx, rays, skip, out)
        }
    }

    /// [`Self::packets`] with packets of type `P`.
    fn packets_of<P: Packet>(
        &self,
        mut ctx: IntersectContext,
        rays: &[Ray],
        skip: impl Fn(usize) -> u32,
        out: &mut [TraceOutcome],
    ) {
        let mut valid = vec![ValidMask::Invalid; P::N];
        for (c, (chunk, outs)) in rays.chunks(P::N).zip(out.chunks_mut(P::N)).enumerate() {
            let mut packet = P::empty();
            valid.fill(ValidMask::Invalid);
            for (i, r) in chunk.iter().enumerate() {
                if r.is_valid() {
                    valid[i] = ValidMask::Valid;
                    packet.set(i, r, r.t_min.max(0.0));
                }
            }
            packet.intersect(&self.scene, &mut ctx, &valid);
            for (i, (r, o)) in chunk.iter().zip(outs.iter_mut()).enumerate() {
                *o = if valid[i] != ValidMask::Valid {
                    TraceOutcome::Failed {
                        failure: Failure::InvalidRay,
                        tets_visited: 0,
                    }
                } else {
                    match packet.hit(i) {
                        Some((prim, _)) if prim == skip(c * P::N + i) => {
                            self.trace_one(&mut ctx, r, prim)
                        }
                        Some((prim, t)) => self.outcome(r, prim, t),
                        None => TraceOutcome::Miss { tets_visited: 0 },
                    }
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
    use tet_trace_cpu::reference::{Aim, closest_hit, grazes_an_edge, random_ray};

    /// Single rays and packets hit the brute-force f64 reference's face on
    /// every ray that does not graze a triangle edge, and a secondary ray
    /// started on a face never reports that face again.
    #[test]
    fn single_rays_and_packets_match_the_brute_force() {
        let mesh = kuhn_grid(&GridSpec {
            cells: [5; 3],
            jitter: 0.12,
            constrained_fraction: 0.15,
            seed: 7,
            ..Default::default()
        });
        let single = EmbreeTracer::new(&mesh, 1).unwrap();
        let mut widths = vec![EmbreeTracer::new(&mesh, 8).unwrap()];
        // Sixteen-wide packets where the CPU has AVX-512 (refused elsewhere).
        match EmbreeTracer::new(&mesh, 16) {
            Ok(t) => widths.push(t),
            Err(e) => assert!(!has_avx512() && matches!(e, EmbreeError::NoAvx512)),
        }
        for packets in &widths {
            check_against_brute_force(&mesh, &single, packets);
        }
    }

    /// `single` and `packets` on camera-like batches and secondary rays.
    fn check_against_brute_force(mesh: &TetMesh, single: &EmbreeTracer, packets: &EmbreeTracer) {
        let mut rng = SplitMix64(3);
        let (mut checked, mut hits, mut secondary) = (0, 0, 0);
        let (mut conts, mut starts, mut singles) = (Vec::new(), Vec::new(), Vec::new());
        for aim in [Aim::Random, Aim::Vertex, Aim::EdgeMidpoint] {
            // Rays of one batch share a start tet, as in a render tile.
            let (r0, t0) = random_ray(mesh, &mut rng, aim);
            let mut rays = vec![r0];
            while rays.len() < 203 {
                let (r, _) = random_ray(mesh, &mut rng, aim);
                rays.push(Ray::new(r0.origin, r.direction));
            }
            let mut batch = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
            packets.trace_batch(&rays, Start::Tet(t0), &mut batch);
            for (ray, b) in rays.iter().zip(&batch) {
                let s = single.trace(ray, Start::Tet(t0));
                let want = closest_hit(mesh, ray);
                if grazes_an_edge(mesh, ray, 1e-4) {
                    continue;
                }
                checked += 1;
                for got in [&s, b] {
                    assert_eq!(got.hit().map(|h| h.face), want.map(|w| w.face), "{ray:?}");
                }
                let (Some(h), Some(w)) = (s.hit(), want) else {
                    continue;
                };
                hits += 1;
                assert!(
                    (h.t as f64 - w.t).abs() <= 1e-4 * w.t.max(1.0),
                    "{h:?} {w:?}"
                );
                // Continue through the face: never the same face again.
                let cont = Ray::new(ray.at(h.t), ray.direction);
                let start = Start::Face {
                    face: h.face,
                    tet: h.far_tet,
                };
                let out = single.trace(&cont, start);
                assert_ne!(out.hit().map(|x| x.face), Some(h.face));
                secondary += 1;
                conts.push(cont);
                starts.push(start);
                singles.push(out);
            }
        }
        // The same secondary rays in packets (a start each): the single
        // rays' faces, never the face a ray starts on.
        let mut packed = vec![TraceOutcome::Miss { tets_visited: 0 }; conts.len()];
        packets.trace_batch_from(&conts, tet_trace_cpu::Starts::Each(&starts), &mut packed);
        for ((p, s), start) in packed.iter().zip(&singles).zip(&starts) {
            assert_eq!(p.hit().map(|h| h.face), s.hit().map(|h| h.face));
            assert_ne!(p.hit().map(|h| h.face), start.on_face());
        }
        assert!(
            checked > 400 && hits > 200 && secondary > 200,
            "{checked} {hits}"
        );
        // Invalid rays are reported, not traced.
        let bad = Ray::new(Vec3::splat(1.0), Vec3::new(f32::NAN, 0.0, 1.0));
        assert!(matches!(
            single.trace(&bad, Start::Tet(0)),
            TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                ..
            }
        ));
    }
}
