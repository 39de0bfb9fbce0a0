//! Secondary rays (Aman et al., seed 000 §6): shadow rays to point lights,
//! reflection and refraction rays.
//!
//! A hit reports the constrained face and the tets on both of its sides
//! ([`Hit::tet`], [`Hit::far_tet`]). A secondary ray starts *on* the hit face,
//! inside the tet on the side its direction points to ([`Start::Face`]), so
//! the walk never meets that face again and needs no epsilon offset.
//! `front`/`back` follow [`tet_core::ConstrainedFace`]: the front side is the
//! one the triangle's normal (right-hand rule on `vertices`) points to.

use glam::Vec3;
use tet_core::{NO_TET, TetMesh};

use crate::kernel::Tracer;
use crate::ray::{Hit, Ray, TraceOutcome};
use crate::walk::Start;

/// Unit geometric normal of a hit's face (from the source triangle winding).
pub fn face_normal(mesh: &TetMesh, face: u32) -> Vec3 {
    let v = mesh.constrained[face as usize]
        .vertices
        .map(|i| mesh.points[i as usize]);
    (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero()
}

/// The hit point of `hit` on `ray`, interpolated from the face's vertices
/// with the barycentrics (exactly on the face's plane up to rounding).
pub fn hit_point(mesh: &TetMesh, hit: &Hit) -> Vec3 {
    let v = mesh.constrained[hit.face as usize]
        .vertices
        .map(|i| mesh.points[i as usize]);
    v[0] * hit.barycentrics[0] + v[1] * hit.barycentrics[1] + v[2] * hit.barycentrics[2]
}

/// Where a ray leaving face `face` in direction `dir` starts: the tet on the
/// side `dir` points to, or `None` when no tet is there (mesh boundary) or
/// `dir` lies in the face's plane.
pub fn start_beyond(mesh: &TetMesh, face: u32, dir: Vec3) -> Option<Start> {
    let cf = &mesh.constrained[face as usize];
    let s = dir.dot(face_normal(mesh, face));
    let side = if s > 0.0 {
        cf.front
    } else if s < 0.0 {
        cf.back
    } else {
        return None;
    };
    (side.tet != NO_TET).then_some(Start::Face {
        face,
        tet: side.tet,
    })
}

/// A secondary ray and its outcome.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traced {
    /// The ray cast (origin on the hit face).
    pub ray: Ray,
    /// Its outcome; `None` when no tet lies on the side it leaves to (the ray
    /// leaves the mesh at once: a miss).
    pub outcome: Option<TraceOutcome>,
}

/// True when `light` is visible from the hit point of `hit` (no constrained
/// face strictly between them). The shadow ray runs from the hit face to the
/// light with `t_max = 1`; a light outside the mesh on the far side of a
/// boundary face counts as visible.
pub fn light_visible<T: Tracer + ?Sized>(tracer: &T, hit: &Hit, light: Vec3) -> bool {
    let mesh = tracer.mesh();
    let p = hit_point(mesh, hit);
    let dir = light - p;
    let Some(start) = start_beyond(mesh, hit.face, dir) else {
        // No tet on the light's side: the light is beyond the mesh boundary
        // (or exactly in the face's plane).
        return true;
    };
    let ray = Ray {
        origin: p,
        direction: dir,
        t_min: 0.0,
        t_max: 1.0,
    };
    !matches!(tracer.trace(&ray, start), TraceOutcome::Hit(_))
}

/// Mirror reflection of `ray` at `hit`, traced from the reflecting side.
pub fn reflect<T: Tracer + ?Sized>(tracer: &T, ray: &Ray, hit: &Hit) -> Traced {
    let mesh = tracer.mesh();
    let n = face_normal(mesh, hit.face);
    let d = ray.direction;
    let r = d - n * (2.0 * d.dot(n));
    cast(tracer, hit, r)
}

/// Refraction of `ray` at `hit` with relative index `eta = n_incident /
/// n_transmitted` (Snell's law), traced from the transmitting side; `None`
/// on total internal reflection.
pub fn refract<T: Tracer + ?Sized>(tracer: &T, ray: &Ray, hit: &Hit, eta: f32) -> Option<Traced> {
    let mesh = tracer.mesh();
    let mut n = face_normal(mesh, hit.face);
    let d = ray.direction.normalize();
    let mut cos_i = -d.dot(n);
    if cos_i < 0.0 {
        n = -n;
        cos_i = -cos_i;
    }
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    let t = d * eta + n * (eta * cos_i - k.sqrt());
    Some(cast(tracer, hit, t))
}

fn cast<T: Tracer + ?Sized>(tracer: &T, hit: &Hit, dir: Vec3) -> Traced {
    let mesh = tracer.mesh();
    let ray = Ray::new(hit_point(mesh, hit), dir);
    let outcome = start_beyond(mesh, hit.face, dir).map(|s| tracer.trace(&ray, s));
    Traced { ray, outcome }
}
