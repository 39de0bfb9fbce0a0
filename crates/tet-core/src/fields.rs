//! Per-point scalar fields: the data an isosurface is extracted from
//! (Wald et al. 2007: a scalar value at every vertex of a tetrahedral
//! volume, interpolated linearly inside each tet, possibly one array per
//! time step).
//!
//! A mesh carries at most one named field ([`crate::Attributes::scalars`]),
//! with one or several time steps. Each step is its own `Vec<f32>` of one
//! value per point, so a tracer borrows one step as a plain `&[f32]`
//! (`field.steps[t].as_slice()`), a time series can be built or streamed one
//! step at a time, and a step can be replaced without touching the others.
//! The steps of one field share its name and the mesh's points (the paper's
//! time-varying data sets keep the mesh and vary only the values).

use crate::error::MeshError;

/// Most bytes of a field's name (UTF-8): the mesh file stores the name in a
/// fixed 64-byte slot, NUL-padded, so a name may not contain NUL either.
/// Names are labels: no control characters at all (which XML files, e.g.
/// VTK's, could not carry).
pub const SCALAR_NAME_BYTES: usize = 64;

/// One named per-point scalar field with one or more time steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScalarField {
    /// Name of the field (at most [`SCALAR_NAME_BYTES`] bytes of UTF-8, no
    /// control character), e.g. `"density"`.
    pub name: String,
    /// One array per time step, each with one finite value per mesh point.
    pub steps: Vec<Vec<f32>>,
}

impl ScalarField {
    /// A field with a single time step.
    pub fn single(name: impl Into<String>, values: Vec<f32>) -> ScalarField {
        ScalarField {
            name: name.into(),
            steps: vec![values],
        }
    }

    /// Number of time steps.
    pub fn step_count(&self) -> usize {
        self.steps.len()
    }

    /// The values of time step `step` (one per point), if it exists.
    pub fn step(&self, step: usize) -> Option<&[f32]> {
        self.steps.get(step).map(Vec::as_slice)
    }

    /// `(min, max)` over every value of every step; `None` when there are
    /// no values. (An isovalue outside this range crosses nothing.)
    pub fn range(&self) -> Option<(f32, f32)> {
        self.steps.iter().flatten().fold(None, |acc, &v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
    }

    /// `(min, max)` of one step (`None` when the step is absent or empty).
    pub fn step_range(&self, step: usize) -> Option<(f32, f32)> {
        let values = self.step(step)?;
        values.iter().fold(None, |acc, &v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
    }

    /// Exact heap bytes of the values and the name.
    pub fn bytes(&self) -> usize {
        self.steps.iter().map(|s| s.len() * 4).sum::<usize>() + self.name.len()
    }

    /// Checks the field against a mesh of `points` points: a valid name, at
    /// least one step, every step one value per point, every value finite.
    /// The first violation is reported by step and point.
    pub fn check(&self, points: usize) -> Result<(), MeshError> {
        check_name(&self.name)?;
        if self.steps.is_empty() {
            return Err(MeshError::ScalarNoSteps {
                name: self.name.clone(),
            });
        }
        for (step, values) in self.steps.iter().enumerate() {
            if values.len() != points {
                return Err(MeshError::ScalarLength {
                    step,
                    actual: values.len(),
                    expected: points,
                });
            }
            if let Some(point) = values.iter().position(|v| !v.is_finite()) {
                return Err(MeshError::ScalarNotFinite {
                    step,
                    point: point as u32,
                    value: values[point],
                });
            }
        }
        Ok(())
    }
}

/// Checks a field name: at most [`SCALAR_NAME_BYTES`] bytes, no control
/// character (NUL included).
pub fn check_name(name: &str) -> Result<(), MeshError> {
    let detail = if name.len() > SCALAR_NAME_BYTES {
        format!("{} bytes, at most {SCALAR_NAME_BYTES}", name.len())
    } else if let Some(c) = name.chars().find(|c| c.is_control()) {
        format!("contains the control character {c:?}")
    } else {
        return Ok(());
    };
    Err(MeshError::ScalarName {
        name: name.chars().take(80).collect(),
        detail,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_names_step_and_point() {
        let mut f = ScalarField {
            name: "rho".into(),
            steps: vec![vec![0.0, 1.0], vec![2.0, 3.0]],
        };
        assert_eq!(f.check(2), Ok(()));
        assert_eq!(f.range(), Some((0.0, 3.0)));
        assert_eq!(f.step_range(1), Some((2.0, 3.0)));
        assert_eq!(f.bytes(), 16 + 3);
        f.steps[1][1] = f32::NAN;
        assert!(matches!(
            f.check(2),
            Err(MeshError::ScalarNotFinite {
                step: 1,
                point: 1,
                ..
            })
        ));
        f.steps[1].pop();
        assert_eq!(
            f.check(2),
            Err(MeshError::ScalarLength {
                step: 1,
                actual: 1,
                expected: 2
            })
        );
        f.steps.clear();
        assert!(matches!(f.check(2), Err(MeshError::ScalarNoSteps { .. })));
        f.name = "x".repeat(65);
        assert!(matches!(f.check(2), Err(MeshError::ScalarName { .. })));
        for bad in ["a\0b", "a\nb", "\u{10}"] {
            f.name = bad.into();
            assert!(matches!(f.check(2), Err(MeshError::ScalarName { .. })));
        }
    }
}
