//! Memory model: TetGen's peak resident memory as a linear function of its
//! input size (Erkoç et al., seed 003, §3: `CALCULATE_EXPECTED_MEMORY`,
//! their fit `y = 4.57e-3·X + 3.12` MB with `X` = input vertices).
//!
//! Our input size is `X = points + triangles` of the PLC given to TetGen
//! (scene vertices + box corners + any seam vertices; scene triangles + box
//! and seam facets). For closed meshes `points ≈ triangles / 2`, so the two
//! counts are nearly collinear and a two-coefficient fit would be
//! ill-conditioned; their sum is what the memory follows (TetGen's pools
//! scale with points, tets ∝ points, subfaces ∝ triangles).
//!
//! | paper                 | code                                   |
//! |-----------------------|----------------------------------------|
//! | `X`                   | [`MemoryModel::input_size`]            |
//! | expected memory `y`   | [`MemoryModel::fit_bytes`]             |
//! | memory_limit          | the caller's limit (bytes)             |
//! | CALCULATE_EXPECTED_MEMORY | [`predict_peak_memory`] (with margin) |
//!
//! ## Fitted constants ([`MemoryModel::FITTED`])
//! Measured with `-pYcz` in the isolated worker (`VmHWM` of the worker
//! process, i.e. including the worker's own start-up footprint), on the
//! procedural knot-grid scenes of [`measurement_scenes`] in an enclosing
//! box. See the table in [`MemoryModel::FITTED`]'s docs.
//!
//! ## How to refit
//! `cargo test -p tet-build --release --test outofcore -- --ignored
//! --nocapture measure_memory_model` prints one line per scene (points,
//! triangles, peak KiB) and the least-squares fit; copy the printed
//! constants into [`MemoryModel::FITTED`]. From code:
//! [`measure_peak_memory`] on any scenes, then [`MemoryModel::fit`].

use glam::DVec3;

use crate::bbox::{BoxSpec, EnclosingBox};
use crate::procedural::{TorusKnotParams, torus_knot};
use crate::scene::{ObjectPlacement, Scene, Transform};
use crate::tetgen::{Isolation, TetgenError, TetgenInput, TetgenOptions, tetrahedralize};

/// A linear model of TetGen's peak memory: `bytes = base + per_element · X`
/// with `X = points + triangles`, and a multiplicative safety margin for
/// predictions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemoryModel {
    /// Fixed part (bytes): process start-up, TetGen's initial pools.
    pub base_bytes: f64,
    /// Bytes per input element (point or triangle).
    pub bytes_per_element: f64,
    /// Predictions are `margin ×` the fitted value (≥ 1).
    pub margin: f64,
}

/// One measurement: input size and the measured peak.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemorySample {
    /// Points given to TetGen.
    pub points: usize,
    /// Triangles given to TetGen.
    pub triangles: usize,
    /// Tets TetGen produced.
    pub tets: usize,
    /// Peak resident memory of the worker (bytes).
    pub peak_bytes: u64,
    /// Seconds inside TetGen.
    pub seconds: f64,
}

impl MemoryModel {
    /// The constants fitted on this machine (see the module docs for how to
    /// refit). Measured 2026-11-22, TetGen 1.5 built by `build.rs`, `-pYczQ`,
    /// worker VmHWM, knot grids in an enclosing box:
    ///
    /// | scene (knots, segments×sides) | points | triangles | tets | peak MiB | TetGen s |
    /// |---|---:|---:|---:|---:|---:|
    /// | 1, 120×12  |   1,448 |   2,892 |    11,413 |   12.9 |  0.09 |
    /// | 1, 480×24  |  11,528 |  23,052 |   107,179 |   98.2 |  1.92 |
    /// | 8, 120×12  |  11,528 |  23,052 |    93,718 |   79.5 |  1.06 |
    /// | 27, 120×12 |  38,888 |  77,772 |   317,925 |  259.3 |  6.00 |
    /// | 8, 480×24  |  92,168 | 184,332 |   870,468 |  743.9 | 15.50 |
    /// | 27, 240×24 | 155,528 | 311,052 | 1,290,914 | 1188.0 | 25.16 |
    ///
    /// Fit: 2.35 MB + 2,565 B × (points + triangles); relative residuals
    /// −10 % … +13 % (the spread at equal size comes from the tet count,
    /// which depends on the geometry, not only on the input size); margin
    /// 1.1 × 1.131 = 1.244. Compare the paper's 4.57 kB per input vertex
    /// (≈ 1.5 kB per element for closed meshes, on a different TetGen build
    /// and measurement). Issue 8's figures (249 MB for 77k triangles, 1.1 GB
    /// for 360k, 9 GB for 2.88M, measured differently) are 17–21 % below
    /// this fit (301 MB, 1.39 GB, 11.1 GB), i.e. the fit is on the safe side.
    pub const FITTED: MemoryModel = MemoryModel {
        base_bytes: 2_350_988.6,
        bytes_per_element: 2_564.916,
        margin: 1.244,
    };

    /// Input size `X` of a PLC.
    pub fn input_size(points: usize, triangles: usize) -> f64 {
        points as f64 + triangles as f64
    }

    /// The fitted value (no margin), bytes.
    pub fn fit_bytes(&self, points: usize, triangles: usize) -> f64 {
        self.base_bytes + self.bytes_per_element * Self::input_size(points, triangles)
    }

    /// Predicted peak with the safety margin, bytes.
    pub fn predict(&self, points: usize, triangles: usize) -> u64 {
        (self.margin * self.fit_bytes(points, triangles)).ceil() as u64
    }

    /// Weighted least-squares fit of `peak = base + slope · X` to
    /// `samples`, with weights `1/peak²` (it minimizes the *relative*
    /// error, so small parts are predicted as well as large ones), and
    /// margin `1.1 × (1 + largest relative under-prediction)` (at least
    /// 1.1). `None` with fewer than two distinct sizes or a zero peak.
    pub fn fit(samples: &[MemorySample]) -> Option<MemoryModel> {
        if samples.iter().any(|s| s.peak_bytes == 0) {
            return None;
        }
        let xs: Vec<f64> = samples
            .iter()
            .map(|s| Self::input_size(s.points, s.triangles))
            .collect();
        let ys: Vec<f64> = samples.iter().map(|s| s.peak_bytes as f64).collect();
        let ws: Vec<f64> = ys.iter().map(|y| 1.0 / (y * y)).collect();
        let sw: f64 = ws.iter().sum();
        if samples.is_empty() || sw <= 0.0 {
            return None;
        }
        let mx = xs.iter().zip(&ws).map(|(x, w)| w * x).sum::<f64>() / sw;
        let my = ys.iter().zip(&ws).map(|(y, w)| w * y).sum::<f64>() / sw;
        let sxx: f64 = xs
            .iter()
            .zip(&ws)
            .map(|(x, w)| w * (x - mx) * (x - mx))
            .sum();
        let sxy: f64 = (0..xs.len())
            .map(|i| ws[i] * (xs[i] - mx) * (ys[i] - my))
            .sum();
        if sxx <= 0.0 || xs.iter().all(|&x| x == xs[0]) {
            return None;
        }
        let slope = sxy / sxx;
        let base = my - slope * mx;
        let worst = xs
            .iter()
            .zip(&ys)
            .map(|(x, y)| (y - (base + slope * x)) / (base + slope * x))
            .fold(0.0f64, f64::max);
        Some(MemoryModel {
            base_bytes: base,
            bytes_per_element: slope,
            margin: 1.1 * (1.0 + worst),
        })
    }
}

/// Predicted peak memory (bytes, with safety margin) of a TetGen run on a
/// PLC of `points` points and `triangles` triangles ([`MemoryModel::FITTED`]).
pub fn predict_peak_memory(points: usize, triangles: usize) -> u64 {
    MemoryModel::FITTED.predict(points, triangles)
}

/// Runs TetGen (`-pYczQ`, in the given isolation, which should be a worker:
/// only a worker reports its own peak) on each scene inside an enclosing
/// box, and returns one sample per scene.
pub fn measure_peak_memory(
    scenes: &[Scene],
    isolation: &Isolation,
) -> Result<Vec<MemorySample>, TetgenError> {
    let mut out = Vec::new();
    for scene in scenes {
        let mut vertices = scene.vertices.clone();
        let mut triangles = scene.triangles.clone();
        let n = triangles.len();
        let b = EnclosingBox::new(scene.bounds(), BoxSpec::default()).map_err(|_| {
            TetgenError::EmptyInput {
                points: vertices.len(),
                triangles: n,
            }
        })?;
        b.append_to(&mut vertices, &mut triangles);
        let markers = (0..triangles.len())
            .map(|i| if i < n { i as i32 + 1 } else { 0 })
            .collect();
        let input = TetgenInput {
            points: vertices.iter().map(|v| v.as_dvec3().to_array()).collect(),
            triangles,
            markers,
        };
        let r = tetrahedralize(&input, &TetgenOptions::default(), isolation)?;
        let peak_kib = r
            .worker_peak_kib
            .or_else(crate::tetgen::worker::peak_memory_kib)
            .unwrap_or(0);
        out.push(MemorySample {
            points: input.points.len(),
            triangles: input.triangles.len(),
            tets: r.tets.len(),
            peak_bytes: peak_kib * 1024,
            seconds: r.seconds,
        });
    }
    Ok(out)
}

/// A grid of `n³` torus knots (spacing 5, as in "Torus Knots") with the
/// given tessellation.
pub fn knot_grid(n: u32, segments: u32, sides: u32) -> Scene {
    let knot = torus_knot(&TorusKnotParams {
        segments,
        sides,
        ..TorusKnotParams::default()
    });
    let mut placed = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                placed.push(ObjectPlacement {
                    name: "Torus Knot".into(),
                    mesh: &knot,
                    transform: Transform::translate(DVec3::new(
                        5.0 * i as f64,
                        5.0 * j as f64,
                        5.0 * k as f64,
                    )),
                    pre_transform: None,
                });
            }
        }
    }
    Scene::from_objects("knot grid", &placed, None, Vec::new())
        .expect("procedural meshes are small and finite")
}

/// The scenes the constants of [`MemoryModel::FITTED`] were measured on:
/// knot grids of 1, 8 and 27 knots at two tessellations (2.9k–311k triangles).
pub fn measurement_scenes() -> Vec<Scene> {
    vec![
        knot_grid(1, 120, 12),
        knot_grid(1, 480, 24),
        knot_grid(2, 120, 12),
        knot_grid(3, 120, 12),
        knot_grid(2, 480, 24),
        knot_grid(3, 240, 24),
    ]
}
