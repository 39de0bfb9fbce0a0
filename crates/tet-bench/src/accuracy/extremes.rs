//! The adversarial cases of `accuracy --extremes`: the scene scaled by
//! 1e-4, 1e4, 1e-30 and 1e30 and translated by 1e5 (each rebuilt from the
//! transformed triangles, since rounding a built mesh's points can invert
//! tets; the builder works in a normalised frame, so every one of them
//! builds like the scene as given), and a sliver-heavy synthetic mesh.
//!
//! At 1e-30 and 1e30 a product of two projected coordinates under- or
//! overflows f32 (about 1e-60 and 1e60). The 2-D f32 walks (tet32, tet20,
//! tet16, tet80-consistent) scale their projection by a power of two per
//! ray and are scale-free; the papers' 3-D products (sctp, tet80 in f32)
//! are not, and would walk to their step cap on most rays there, so those
//! two cases leave them out ([`beyond_f32_products`]).

use anyhow::{Result, bail};
use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};
use tet_core::synthetic::{GridSpec, kuhn_grid};

use crate::load::build_flags::BuildFlags;
use crate::load::camera::framing_camera;
use crate::load::{Loaded, from_scene};

/// The transforms applied to the scene.
const TRANSFORMS: [(&str, f32, f32); 5] = [
    ("scale-1e-4", 1e-4, 0.0),
    ("scale-1e4", 1e4, 0.0),
    ("scale-1e-30", 1e-30, 0.0),
    ("scale-1e30", 1e30, 0.0),
    ("translate-1e5", 1.0, 1e5),
];

/// True for the cases whose products of coordinates leave f32's range:
/// there, kernels whose f32 products are not rescaled are left out.
pub fn beyond_f32_products(case: &str) -> bool {
    matches!(case, "scale-1e-30" | "scale-1e30")
}

/// `p` scaled, then shifted along every axis.
fn apply(p: Vec3, scale: f32, shift: f32) -> Vec3 {
    p * scale + Vec3::splat(shift)
}

/// Builds every extreme case (an error skips that case).
pub fn cases(loaded: &Loaded, flags: &BuildFlags, quiet: bool) -> Vec<(String, Result<Loaded>)> {
    let mut out: Vec<(String, Result<Loaded>)> = TRANSFORMS
        .iter()
        .map(|&(name, scale, shift)| {
            (
                name.to_string(),
                transformed(loaded, flags, quiet, scale, shift),
            )
        })
        .collect();
    out.push(("kuhn-slivers".into(), Ok(slivers())));
    out
}

/// The scene (rebuilt) or mesh file (points moved) scaled and shifted,
/// with its camera and lights.
fn transformed(
    loaded: &Loaded,
    flags: &BuildFlags,
    quiet: bool,
    scale: f32,
    shift: f32,
) -> Result<Loaded> {
    let camera = Camera {
        position: apply(loaded.camera.position, scale, shift),
        target: apply(loaded.camera.target, scale, shift),
        ..loaded.camera
    };
    let lights: Vec<PointLight> = loaded
        .lights
        .iter()
        .map(|l| PointLight {
            position: apply(l.position, scale, shift),
            ..*l
        })
        .collect();
    if let Some(scene) = &loaded.scene {
        let mut s = scene.clone();
        for v in &mut s.vertices {
            *v = apply(*v, scale, shift);
        }
        s.camera = Some(camera);
        s.lights = lights;
        s.name = format!("{} ({scale:e}x + {shift:e})", scene.name);
        return from_scene(s, flags, quiet);
    }
    let mut mesh: TetMesh = loaded.mesh.clone();
    for p in &mut mesh.points {
        *p = apply(*p, scale, shift);
    }
    if let Err(e) = mesh.validate() {
        bail!(
            "the transformed mesh file is invalid in f32 ({e}); pass a scene to rebuild it instead"
        );
    }
    Ok(Loaded {
        name: loaded.name.clone(),
        mesh,
        scene: None,
        camera,
        lights,
        build: None,
    })
}

/// A 12×12×12 Kuhn grid squashed 1000× along z (every tet a sliver), with
/// 30 % of its faces constrained; the camera sits at its centre.
fn slivers() -> Loaded {
    let mut mesh = kuhn_grid(&GridSpec {
        cells: [12, 12, 12],
        jitter: 0.15,
        constrained_fraction: 0.3,
        seed: 7,
        ..GridSpec::default()
    });
    for p in &mut mesh.points {
        p.z *= 1e-3;
    }
    if mesh.validate().is_err() {
        // Squashing rounded a tet flat: fall back to the unsquashed grid.
        for p in &mut mesh.points {
            p.z *= 1e3;
        }
    }
    let center = Vec3::new(6.01, 6.02, 6.03e-3);
    let camera = Camera {
        position: center,
        target: center + Vec3::new(1.0, 0.3, 0.0),
        ..framing_camera(&mesh)
    };
    Loaded {
        name: "kuhn-slivers".into(),
        mesh,
        scene: None,
        camera,
        lights: Vec::new(),
        build: None,
    }
}
