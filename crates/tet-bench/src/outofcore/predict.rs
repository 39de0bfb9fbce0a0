//! The memory model's prediction for a scene (Erkoç et al. 2021,
//! §3.2: TetGen's peak memory as a linear function of its input size).

use anyhow::Result;
use tet_build::scene::Scene;

#[cfg(feature = "tetgen")]
use super::types::ModelDoc;
use super::types::Prediction;

/// Cleaned scene size as TetGen would receive it (with the box unless `no_box`).
#[cfg(feature = "tetgen")]
pub fn tetgen_input_size(scene: &Scene, no_box: bool) -> Result<(usize, usize)> {
    let (cleaned, _) = tet_build::clean::clean_scene(scene)
        .map_err(|e| anyhow::anyhow!("cannot clean `{}`: {e}", scene.name))?;
    let extra = if no_box { (0, 0) } else { (8, 12) };
    Ok((
        cleaned.vertices.len() + extra.0,
        cleaned.triangles.len() + extra.1,
    ))
}

/// The prediction for `scene`.
#[cfg(feature = "tetgen")]
pub fn predict(scene: &Scene, no_box: bool) -> Result<Prediction> {
    use tet_build::outofcore::memory_model::{MemoryModel, predict_peak_memory};
    let (points, triangles) = tetgen_input_size(scene, no_box)?;
    let m = MemoryModel::FITTED;
    Ok(Prediction {
        name: scene.name.clone(),
        points,
        triangles,
        predicted_peak_bytes: predict_peak_memory(points, triangles),
        model: ModelDoc {
            base_bytes: m.base_bytes,
            bytes_per_element: m.bytes_per_element,
            margin: m.margin,
        },
        builder_bytes: tet_build::outofcore::admission::builder_bytes(scene.triangles.len()),
    })
}

/// Without TetGen there is nothing to predict.
#[cfg(not(feature = "tetgen"))]
pub fn predict(scene: &Scene, _: bool) -> Result<Prediction> {
    anyhow::bail!(
        "`{}`: the memory model needs the `tetgen` feature",
        scene.name
    )
}
