//! Memory model: TetGen's peak resident memory as a linear function of its
//! input size (Erkoç et al. 2021, §3: `CALCULATE_EXPECTED_MEMORY`,
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
    /// Bytes per *wall* element of a part (a seam-only or box facet, or a
    /// point used by no scene facet), see [`MemoryModel::predict_part`].
    pub bytes_per_wall_element: f64,
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
    /// refit): TetGen 1.5 built by `build.rs`, `-pYczQ`, the worker's
    /// `VmHWM`, on the knot grids of [`measurement_scenes`] in an enclosing
    /// box and on parts of slab and tree splits of them
    /// ([`MemoryModel::fit_parts`]; `measure_part_memory_model` in
    /// `tests/outofcore.rs`). Parts of a split cost less per element than a
    /// whole scene: their seam facets are a planar triangulation TetGen
    /// meshes cheaply, hence the separate wall rate. [`MemoryModel::predict`]
    /// (whole scenes, no walls) uses the scene rate for every element. The
    /// measurements behind the constants are in the README's results. For
    /// comparison, the paper's fit is 4.57 kB per input vertex (≈ 1.5 kB per
    /// element for closed meshes, on a different TetGen build and
    /// measurement).
    pub const FITTED: MemoryModel = MemoryModel {
        base_bytes: 3_386_656.9,
        bytes_per_element: 2_324.144,
        bytes_per_wall_element: 408.192,
        margin: 1.353,
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
            bytes_per_wall_element: slope,
            margin: 1.1 * (1.0 + worst),
        })
    }

    /// The fitted value (no margin) for a part whose PLC has
    /// `scene_elements` scene points + scene facets (pieces of scene
    /// triangles and the points they use) and `wall_elements` wall facets
    /// + wall-only points, bytes.
    pub fn fit_part_bytes(&self, scene_elements: usize, wall_elements: usize) -> f64 {
        self.base_bytes
            + self.bytes_per_element * scene_elements as f64
            + self.bytes_per_wall_element * wall_elements as f64
    }

    /// Predicted peak of a part with the safety margin, bytes (see
    /// [`MemoryModel::fit_part_bytes`]).
    pub fn predict_part(&self, scene_elements: usize, wall_elements: usize) -> u64 {
        (self.margin * self.fit_part_bytes(scene_elements, wall_elements)).ceil() as u64
    }

    /// Weighted least-squares fit (weights `1/peak²`) of
    /// `peak = base + a · scene + b · wall` to part samples, margin as in
    /// [`MemoryModel::fit`]. A negative wall coefficient is clamped to 0
    /// and the other two refitted. `None` when the system is singular.
    pub fn fit_parts(samples: &[PartSample]) -> Option<MemoryModel> {
        if samples.iter().any(|s| s.peak_bytes == 0) || samples.len() < 3 {
            return None;
        }
        let rows: Vec<([f64; 3], f64, f64)> = samples
            .iter()
            .map(|s| {
                let y = s.peak_bytes as f64;
                (
                    [1.0, s.scene_elements as f64, s.wall_elements as f64],
                    y,
                    1.0 / (y * y),
                )
            })
            .collect();
        let solve = |cols: &[usize]| -> Option<Vec<f64>> {
            let n = cols.len();
            let mut a = vec![vec![0.0f64; n + 1]; n];
            for (x, y, w) in &rows {
                for i in 0..n {
                    for j in 0..n {
                        a[i][j] += w * x[cols[i]] * x[cols[j]];
                    }
                    a[i][n] += w * x[cols[i]] * y;
                }
            }
            // Gaussian elimination with partial pivoting.
            for k in 0..n {
                let p = (k..n).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))?;
                a.swap(k, p);
                if a[k][k].abs() < 1e-300 {
                    return None;
                }
                let pivot = a[k].clone();
                for row in a.iter_mut().skip(k + 1) {
                    let f = row[k] / pivot[k];
                    for (x, p) in row.iter_mut().zip(&pivot).skip(k) {
                        *x -= f * p;
                    }
                }
            }
            let mut x = vec![0.0; n];
            for k in (0..n).rev() {
                let s: f64 = (k + 1..n).map(|j| a[k][j] * x[j]).sum();
                x[k] = (a[k][n] - s) / a[k][k];
            }
            Some(x)
        };
        let c = solve(&[0, 1, 2])?;
        let (base, scene, wall) = if c[2] >= 0.0 {
            (c[0], c[1], c[2])
        } else {
            let c = solve(&[0, 1])?;
            (c[0], c[1], 0.0)
        };
        let worst = rows
            .iter()
            .map(|(x, y, _)| {
                let f = base + scene * x[1] + wall * x[2];
                (y - f) / f
            })
            .fold(0.0f64, f64::max);
        Some(MemoryModel {
            base_bytes: base,
            bytes_per_element: scene,
            bytes_per_wall_element: wall,
            margin: 1.1 * (1.0 + worst),
        })
    }
}

/// One part measurement for [`MemoryModel::fit_parts`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartSample {
    /// Scene points + scene facets of the part's PLC.
    pub scene_elements: usize,
    /// Wall-only points + wall facets.
    pub wall_elements: usize,
    /// Measured peak (bytes).
    pub peak_bytes: u64,
}

/// Predicted peak memory (bytes, with safety margin) of a TetGen run on a
/// PLC of `points` points and `triangles` triangles ([`MemoryModel::FITTED`]).
pub fn predict_peak_memory(points: usize, triangles: usize) -> u64 {
    MemoryModel::FITTED.predict(points, triangles)
}

/// Predicted peak memory (bytes, with margin) of a TetGen run on one part
/// of a split ([`MemoryModel::FITTED`], [`MemoryModel::predict_part`]):
/// its scene points and facets count at the scene rate, its wall-only
/// points and wall facets (seam-only triangles, box faces) at the wall rate.
pub fn predict_part_peak_memory(
    scene_points: usize,
    scene_triangles: usize,
    wall_points: usize,
    wall_triangles: usize,
) -> u64 {
    MemoryModel::FITTED.predict_part(scene_points + scene_triangles, wall_points + wall_triangles)
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
