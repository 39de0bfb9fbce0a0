//! The normalised frame TetGen works in: the PLC is centred and scaled to
//! unit size before TetGen sees it, and TetGen's points are mapped back to
//! the user's coordinates, so a scene's scale and offset do not change what
//! TetGen does.
//!
//! TetGen's point `q` of a user point `x` (f32) is `q = (x − c)·2ᵏ` in f64,
//! per axis, with a centre `c` (an f32 value per axis) and one power-of-two
//! scale `2ᵏ` that brings the largest extent of the PLC's bounding box into
//! `[1, 2)`. The mesh keeps storing the user's f32 points; only TetGen sees
//! the frame.
//!
//! **Exactness.** Input points (and the rounded Steiner points fed back to
//! TetGen in repair rounds) must reach TetGen *exactly*, so that its exact
//! predicates decide on the very coordinates the mesh stores. Per axis, let
//! `[lo, hi]` be the PLC's interval widened by [`WIDEN`] f32 steps on each
//! side (room for snapped Steiner points), `m` the smallest magnitude in it
//! and `u` the f32 spacing at `m` (`2^(e(m)−23)`, or `2⁻¹⁴⁹` in the
//! subnormal range). Every f32 value of magnitude at least `m` is a multiple
//! of `u`; if `c` is a multiple of `u` too, `x − c = n·u` for an integer
//! `|n| ≤ max(hi − c, c − lo)/u`, which f64 holds exactly when
//! `|n| ≤ 2⁵³`. Then the f64 subtraction is exact, and the scaling by `2ᵏ`
//! is exact because the result stays far inside f64's normal range
//! (`|x − c|·2ᵏ ≤ 4`, nonzero values `≥ 2⁻¹⁴⁹·2⁻¹²⁹`). An axis that fails
//! this test (its interval reaches so close to zero that the f32 spacing
//! there is more than `2⁵³` times finer than the interval) gets `c = 0`:
//! `x·2ᵏ` is always exact, and centring would gain nothing there.
//!
//! **Invariance.** The centre is the interval's midpoint rounded to a
//! multiple of `g = 2^(⌊log₂ extent⌋ + 1)`, a grid coarser than the extent:
//! an interval that contains the origin has `|midpoint| < g/2`, so `c = 0`,
//! and a copy of the scene shifted by a multiple of `g` gets its centre
//! shifted by exactly as much. Its frame coordinates are then the same,
//! bit for bit, and so are TetGen's decisions and Steiner points; a copy
//! scaled by a power of two (without f32 underflow) likewise. The centre is
//! within `g/2` of the midpoint, so TetGen's coordinates stay below 4.
//!
//! **Back to f32.** `x = q·2⁻ᵏ + c`: the product is exact, the sum is
//! computed with its rounding error (TwoSum) and rounded once to the
//! nearest f32 ([`Frame::user_point`]), so the stored point is the f32 nearest
//! to TetGen's point, as without a frame; an input point comes back as
//! itself.
//!
//! [`check_range`] rejects scenes f32 cannot hold: an extent that overflows
//! f32, or every coordinate below the smallest normal f32 (subnormals keep
//! fewer than 24 significant bits).

use glam::{DVec3, Vec3};

use super::error::BuildError;

/// f32 steps the exactness test adds on each side of the PLC's interval
/// (snapping moves a rounded Steiner point at most 2 steps).
pub const WIDEN: usize = 4;

/// The map between the user's f32 coordinates and TetGen's f64 ones (see
/// the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The centre per axis (f32 values; 0 on an axis that is not centred).
    pub centre: [f32; 3],
    /// TetGen's coordinates are the user's minus the centre, times `2^exponent`.
    pub exponent: i32,
}

/// `2ⁿ` exactly, for `n` in f64's normal exponent range.
fn pow2(n: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&n));
    f64::from_bits(((n + 1023) as u64) << 52)
}

/// The exponent `e` with `2ᵉ ≤ x < 2ᵉ⁺¹`, for a positive normal f64.
fn exponent_of(x: f64) -> i32 {
    ((x.to_bits() >> 52) & 0x7ff) as i32 - 1023
}

/// The spacing of f32 values at magnitude `m` (`2⁻¹⁴⁹` for subnormals).
fn f32_spacing(m: f32) -> f64 {
    let e = ((m.abs().to_bits() >> 23) & 0xff) as i32;
    if e == 0 {
        pow2(-149)
    } else {
        pow2(e - 127 - 23)
    }
}

/// `x` moved `steps` f32 values down (or up); `None` past the finite range.
fn step(x: f32, steps: usize, up: bool) -> Option<f32> {
    let mut y = x;
    for _ in 0..steps {
        y = if up { y.next_up() } else { y.next_down() };
    }
    y.is_finite().then_some(y)
}

impl Frame {
    /// The identity frame (no centre, scale 1).
    pub const IDENTITY: Frame = Frame {
        centre: [0.0; 3],
        exponent: 0,
    };

    /// The frame of the PLC with these points (finite; see the module docs).
    pub fn new(points: &[Vec3]) -> Frame {
        let Some(&first) = points.first() else {
            return Frame::IDENTITY;
        };
        let (lo, hi) = points
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let extent = (hi.as_dvec3() - lo.as_dvec3()).max_element();
        if !(extent > 0.0 && extent.is_finite()) {
            return Frame::IDENTITY;
        }
        let e = exponent_of(extent);
        let grid = pow2(e + 1);
        let centre = std::array::from_fn(|axis| centre_of(lo[axis], hi[axis], grid).unwrap_or(0.0));
        Frame {
            centre,
            exponent: -e,
        }
    }

    /// TetGen's coordinates of a user point (exact for the points the
    /// frame was made for, see the module docs).
    pub fn tetgen_point(&self, p: Vec3) -> [f64; 3] {
        let s = pow2(self.exponent);
        std::array::from_fn(|i| (p[i] as f64 - self.centre[i] as f64) * s)
    }

    /// The user's f32 point nearest to TetGen's point `q`.
    pub fn user_point(&self, q: [f64; 3]) -> Vec3 {
        let s = pow2(-self.exponent);
        Vec3::from_array(std::array::from_fn(|i| {
            round_sum_to_f32(q[i] * s, self.centre[i] as f64)
        }))
    }

    /// TetGen's point `q` in user coordinates, in f64 (rounded once per
    /// coordinate): for distances, not for storing.
    pub fn user_point_f64(&self, q: [f64; 3]) -> DVec3 {
        let s = pow2(-self.exponent);
        DVec3::from_array(std::array::from_fn(|i| q[i] * s + self.centre[i] as f64))
    }
}

/// The centre of the axis interval `[lo, hi]`: its midpoint on `grid`, as
/// an f32, when every f32 of the widened interval minus it is exact in f64
/// (the test of the module docs); `None` otherwise.
fn centre_of(lo: f32, hi: f32, grid: f64) -> Option<f32> {
    let mid = (lo as f64 + hi as f64) * 0.5;
    let c = ((mid / grid).round() * grid) as f32;
    if c == 0.0 {
        return None;
    }
    let (wlo, whi) = (step(lo, WIDEN, false)?, step(hi, WIDEN, true)?);
    if wlo <= 0.0 && whi >= 0.0 {
        return None;
    }
    let u = f32_spacing(wlo.abs().min(whi.abs()));
    let c64 = c as f64;
    let multiple = (c64 / u).fract() == 0.0;
    let span = (whi as f64 - c64).max(c64 - wlo as f64);
    (multiple && span <= pow2(53) * u).then_some(c)
}

/// `a + c` rounded once to the nearest f32 (ties to even).
///
/// `s = a + c` in f64 with its exact error `err` (TwoSum). Rounding `s` to
/// f32 rounds `a + c` correctly unless `s` lies exactly halfway between two
/// f32 values while `err ≠ 0`: every f32 midpoint is an f64 value, so an
/// `a + c` strictly between two midpoints rounds to an `s` between them
/// too. In that case `err`'s sign says which neighbour is nearer.
fn round_sum_to_f32(a: f64, c: f64) -> f32 {
    let s = a + c;
    let bb = s - a;
    let err = (a - (s - bb)) + (c - bb);
    let r = s as f32;
    if err == 0.0 || !r.is_finite() || r as f64 == s {
        return r;
    }
    let other = if (r as f64) < s {
        r.next_up()
    } else {
        r.next_down()
    };
    if other as f64 - s != s - r as f64 {
        return r;
    }
    let (below, above) = if r < other { (r, other) } else { (other, r) };
    if err > 0.0 { above } else { below }
}

/// Rejects a cleaned scene f32 cannot hold (`points` are its vertices,
/// `source` maps them to input vertex ids): an axis extent that overflows
/// f32 ([`BuildError::ExtentOverflows`]), or every coordinate below
/// `f32::MIN_POSITIVE` ([`BuildError::SubnormalScene`]).
pub fn check_range(points: &[Vec3], source: &[u32]) -> Result<(), BuildError> {
    let Some(&first) = points.first() else {
        return Ok(());
    };
    let input = |i: usize| source.get(i).copied().unwrap_or(i as u32);
    for axis in 0..3 {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in points.iter().enumerate() {
            if p[axis] < points[lo][axis] {
                lo = i;
            }
            if p[axis] > points[hi][axis] {
                hi = i;
            }
        }
        let (min, max) = (points[lo][axis], points[hi][axis]);
        if !(max - min).is_finite() {
            let vertex = if max.abs() >= min.abs() { hi } else { lo };
            return Err(BuildError::ExtentOverflows {
                axis: axis as u8,
                min,
                max,
                vertex: input(vertex),
            });
        }
    }
    let largest = points
        .iter()
        .enumerate()
        .map(|(i, p)| (i, p.abs().max_element()))
        .fold((0, first.abs().max_element()), |a, b| {
            if b.1 > a.1 { b } else { a }
        });
    if largest.1 < f32::MIN_POSITIVE {
        return Err(BuildError::SubnormalScene {
            largest: largest.1,
            vertex: input(largest.0),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use tet_core::synthetic::SplitMix64;

    /// Every f32 in the widened PLC interval maps to TetGen and back
    /// exactly, and the f64 difference is exact (checked with TwoSum).
    fn assert_exact_on(frame: &Frame, lo: Vec3, hi: Vec3, rng: &mut SplitMix64) {
        for _ in 0..2000 {
            let p = Vec3::from_array(std::array::from_fn(|i| {
                let (a, b) = (
                    step(lo[i], WIDEN, false).unwrap(),
                    step(hi[i], WIDEN, true).unwrap(),
                );
                // Random values, plus the interval's ends and near-zero values.
                match rng.next_u64() % 4 {
                    0 => a,
                    1 => b,
                    _ => a + (b - a) * rng.next_f64() as f32,
                }
            }));
            let q = frame.tetgen_point(p);
            assert_eq!(frame.user_point(q), p, "round trip of {p:?} in {frame:?}");
            for i in 0..3 {
                // Exact: q / 2ᵏ + c reproduces p[i] exactly in f64.
                let back = q[i] * pow2(-frame.exponent) + frame.centre[i] as f64;
                assert_eq!(back, p[i] as f64, "axis {i} of {p:?}");
            }
        }
    }

    #[test]
    fn frames_are_exact_and_unit_sized() {
        let mut rng = SplitMix64(5);
        for (lo, hi) in [
            (Vec3::splat(-1.0), Vec3::splat(1.0)),
            (Vec3::splat(1e5 - 2.0), Vec3::splat(1e5 + 2.0)),
            (Vec3::splat(-3e-30), Vec3::new(1e-30, 2e-30, 5e-31)),
            (Vec3::new(1e30, -1e30, 0.0), Vec3::new(3e30, 1e30, 1e29)),
            (Vec3::new(1e-20, 7.0, -1e6), Vec3::new(1e5, 7.5, -1e6 + 1.0)),
        ] {
            let frame = Frame::new(&[lo, hi]);
            assert_exact_on(&frame, lo, hi, &mut rng);
            let extent = frame.tetgen_point(hi)[0] - frame.tetgen_point(lo)[0];
            let widest = (0..3)
                .map(|i| frame.tetgen_point(hi)[i] - frame.tetgen_point(lo)[i])
                .fold(0.0, f64::max);
            assert!(
                (1.0..2.0).contains(&widest),
                "{widest} ({extent}) for {lo:?}"
            );
        }
    }

    #[test]
    fn far_offsets_are_centred_and_the_origin_is_not() {
        let f = Frame::new(&[Vec3::splat(1e5 - 1.0), Vec3::splat(1e5 + 1.0)]);
        assert_eq!(f.centre, [1e5; 3]);
        assert_eq!(f.exponent, -1);
        let g = Frame::new(&[Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.01)]);
        assert_eq!(g.centre, [0.0; 3]);
        // An interval from nearly zero to 1e5: no exact centre, so none.
        let h = Frame::new(&[Vec3::splat(1e-30), Vec3::splat(1e5)]);
        assert_eq!(h.centre, [0.0; 3]);
    }

    #[test]
    fn shifted_and_scaled_copies_get_the_same_frame_coordinates() {
        // Around the origin (c = 0), and away from it on every axis (centred).
        for points in [
            [Vec3::new(-1.5, 0.75, 3.0), Vec3::new(1.5, -0.75, -3.0)],
            [Vec3::new(10.5, 20.25, 3.0), Vec3::new(12.0, 21.75, 1.0)],
        ] {
            let base = Frame::new(&points);
            // Shift by a multiple of the centring grid, scale by a power of two.
            let shifted: Vec<Vec3> = points.iter().map(|&p| p + Vec3::splat(4096.0)).collect();
            let scaled: Vec<Vec3> = points.iter().map(|&p| p * pow2(-100) as f32).collect();
            for copy in [shifted, scaled] {
                let frame = Frame::new(&copy);
                for (p, q) in points.iter().zip(&copy) {
                    assert_eq!(frame.tetgen_point(*q), base.tetgen_point(*p), "{frame:?}");
                }
            }
        }
    }

    #[test]
    fn sums_round_once_to_the_nearest_f32() {
        // 1 + 2⁻²⁴ is halfway between 1 and the next f32: ties to even
        // give 1, but a tiny extra part decides the other way.
        let half = pow2(-24);
        assert_eq!(round_sum_to_f32(half, 1.0), 1.0);
        assert_eq!(round_sum_to_f32(half + pow2(-70), 1.0), 1.0f32.next_up());
        // The f64 sum of these rounds to the midpoint; the exact sum lies above it.
        assert_eq!(round_sum_to_f32(1.0 + half, pow2(-60)), 1.0f32.next_up());
        assert_eq!(round_sum_to_f32(1.0 + half, -pow2(-60)), 1.0);
        // Against an exact reference: the nearest of the f32 neighbours of
        // the f64 sum, compared with the exact error term.
        let mut rng = SplitMix64(9);
        for _ in 0..10_000 {
            let a = (rng.next_f64() - 0.5) * 1e3;
            let c = (rng.next_f64() * 100.0) as f32 as f64;
            if (a + c).abs() < 1.0 {
                continue;
            }
            let r = round_sum_to_f32(a, c);
            let exact_gap = |x: f32| {
                // |x − (a + c)|: with |a + c| ≥ 1 and |c| ≤ 100, `x − c` is
                // exact in f64 and close to `a`, so the second difference is
                // exact too (Sterbenz).
                ((x as f64 - c) - a).abs()
            };
            assert!(exact_gap(r) <= exact_gap(r.next_up()));
            assert!(exact_gap(r) <= exact_gap(r.next_down()));
        }
    }

    #[test]
    fn scenes_f32_cannot_hold_are_named() {
        let big = [Vec3::new(-3e38, 0.0, 0.0), Vec3::new(3e38, 1.0, 0.0)];
        assert_eq!(
            check_range(&big, &[4, 7]),
            Err(BuildError::ExtentOverflows {
                axis: 0,
                min: -3e38,
                max: 3e38,
                vertex: 7,
            })
        );
        let tiny = [Vec3::splat(1e-40), Vec3::new(0.0, -2e-39, 0.0)];
        assert_eq!(
            check_range(&tiny, &[2, 3]),
            Err(BuildError::SubnormalScene {
                largest: 2e-39,
                vertex: 3,
            })
        );
        assert_eq!(
            check_range(&[Vec3::splat(1e-37), Vec3::ZERO], &[0, 1]),
            Ok(())
        );
        assert_eq!(
            check_range(&[Vec3::splat(3e38), Vec3::ZERO], &[0, 1]),
            Ok(())
        );
    }
}
