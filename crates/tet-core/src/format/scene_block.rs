//! The scene block: one camera and point lights as 48-byte records (see
//! the module docs of [`crate::format`]).

use std::path::Path;

use glam::Vec3;

use super::error::FormatError;
use crate::scene::{Camera, PointLight, SceneInfo, SceneInfoError};

const SCENE_CAMERA: u32 = 1;
const SCENE_LIGHT: u32 = 2;

/// Parses and checks the scene block's records.
pub(super) fn decode_scene(records: &[[u32; 12]], path: &Path) -> Result<SceneInfo, FormatError> {
    let bad = |record: usize, detail: String| FormatError::BadScene {
        path: path.to_path_buf(),
        record,
        detail,
    };
    let mut scene = SceneInfo::default();
    for (i, rec) in records.iter().enumerate() {
        let f = |k: usize| f32::from_bits(rec[k]);
        let v = |k: usize| Vec3::new(f(k), f(k + 1), f(k + 2));
        let (used, single) = match rec[0] {
            SCENE_CAMERA => {
                if scene.camera.is_some() {
                    return Err(bad(i, "a second camera".into()));
                }
                let camera = Camera {
                    position: v(1),
                    target: v(4),
                    up: v(7),
                    vfov_deg: f(10),
                };
                scene.camera = Some(camera);
                (
                    11,
                    SceneInfo {
                        camera: Some(camera),
                        lights: Vec::new(),
                    },
                )
            }
            SCENE_LIGHT => {
                let light = PointLight {
                    position: v(1),
                    color: v(4),
                    intensity: f(7),
                };
                scene.lights.push(light);
                (
                    8,
                    SceneInfo {
                        camera: None,
                        lights: vec![light],
                    },
                )
            }
            kind => return Err(bad(i, format!("unknown kind {kind}"))),
        };
        if let Some(k) = (used..12).find(|&k| rec[k] != 0) {
            return Err(bad(
                i,
                format!("unused word {k} is {:#x}, expected 0", rec[k]),
            ));
        }
        // The record is checked alone, so a light error names "light 0":
        // the record index above is the position that matters.
        single
            .validate()
            .map_err(|e: SceneInfoError| bad(i, e.to_string().replace("light 0", "light")))?;
    }
    Ok(scene)
}

/// Encodes `scene` as scene-block records (camera first, then lights).
pub(super) fn scene_records(scene: &SceneInfo) -> Vec<[u32; 12]> {
    let mut out = Vec::with_capacity(scene.lights.len() + 1);
    let put = |kind: u32, words: &[f32]| {
        let mut rec = [0u32; 12];
        rec[0] = kind;
        for (k, w) in words.iter().enumerate() {
            rec[1 + k] = w.to_bits();
        }
        rec
    };
    if let Some(c) = &scene.camera {
        let (p, t, u) = (c.position, c.target, c.up);
        out.push(put(
            SCENE_CAMERA,
            &[p.x, p.y, p.z, t.x, t.y, t.z, u.x, u.y, u.z, c.vfov_deg],
        ));
    }
    for l in &scene.lights {
        let (p, c) = (l.position, l.color);
        out.push(put(
            SCENE_LIGHT,
            &[p.x, p.y, p.z, c.x, c.y, c.z, l.intensity],
        ));
    }
    out
}
