//! The numbers the predicates are written over: one formula, two number
//! types. [`Tracked`] is an `f64` with a running bound on its error, cheap
//! and certain in the common case; [`super::expansion::Expansion`] is exact
//! (Shewchuk's floating-point expansions) and decides what the filter left
//! open.

/// The operations a predicate formula needs.
pub(crate) trait Ring: Sized {
    /// The number `x` (exact).
    fn from_f64(x: f64) -> Self;
    /// `a - b` for plain doubles (exact for [`super::expansion::Expansion`]).
    fn diff(a: f64, b: f64) -> Self;
    /// Sum.
    fn add(&self, other: &Self) -> Self;
    /// Difference.
    fn sub(&self, other: &Self) -> Self;
    /// Product.
    fn mul(&self, other: &Self) -> Self;
    /// The sign (−1, 0, +1), or `None` when the filter cannot be sure.
    fn sign(&self) -> Option<i8>;
    /// A double close to the value.
    fn estimate(&self) -> f64;
}

/// Unit roundoff of `f64`.
const U: f64 = f64::EPSILON * 0.5;
/// Inflation of every computed bound, covering the rounding of the bound's
/// own arithmetic.
const GROW: f64 = 1.0 + 8.0 * U;
/// Absolute slack per product: covers underflow.
const TINY: f64 = 1e-300;

/// A double `v` with `|exact - v| <= e`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tracked {
    /// The computed value.
    pub v: f64,
    /// A bound on its distance from the exact value.
    pub e: f64,
}

impl Ring for Tracked {
    fn from_f64(x: f64) -> Self {
        Tracked { v: x, e: 0.0 }
    }
    fn diff(a: f64, b: f64) -> Self {
        let v = a - b;
        Tracked {
            v,
            e: 2.0 * U * v.abs(),
        }
    }
    fn add(&self, o: &Self) -> Self {
        let v = self.v + o.v;
        Tracked {
            v,
            e: (self.e + o.e + 2.0 * U * v.abs()) * GROW,
        }
    }
    fn sub(&self, o: &Self) -> Self {
        let v = self.v - o.v;
        Tracked {
            v,
            e: (self.e + o.e + 2.0 * U * v.abs()) * GROW,
        }
    }
    fn mul(&self, o: &Self) -> Self {
        let v = self.v * o.v;
        let e = self.v.abs() * o.e + o.v.abs() * self.e + self.e * o.e + 2.0 * U * v.abs();
        Tracked {
            v,
            e: e * GROW + TINY,
        }
    }
    fn sign(&self) -> Option<i8> {
        if !(self.v.is_finite() && self.e.is_finite()) {
            return None;
        }
        if self.v.abs() > self.e {
            Some(if self.v > 0.0 { 1 } else { -1 })
        } else if self.v == 0.0 && self.e == 0.0 {
            Some(0)
        } else {
            None
        }
    }
    fn estimate(&self) -> f64 {
        self.v
    }
}

impl Tracked {
    /// Relative error bound (infinite when the value may be zero).
    pub fn relative_error(&self) -> f64 {
        if self.v == 0.0 {
            if self.e == 0.0 { 0.0 } else { f64::INFINITY }
        } else {
            self.e / self.v.abs()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_hold_for_a_cancelling_sum() {
        // (1 + 2^-40)^2 - 1 - 2^-39 = 2^-80, far below the rounding of the square.
        let a = Tracked::from_f64(1.0 + 2f64.powi(-40));
        let sq = a.mul(&a);
        let r = sq.sub(&Tracked::from_f64(1.0 + 2f64.powi(-39)));
        let exact = 2f64.powi(-80);
        assert!((r.v - exact).abs() <= r.e, "{r:?}");
        assert_ne!(r.sign(), Some(-1));
        assert_ne!(r.sign(), Some(0));
    }

    #[test]
    fn exact_zero_is_certain_only_without_error() {
        assert_eq!(Tracked::from_f64(0.0).sign(), Some(0));
        let z = Tracked::diff(0.5, 0.25).sub(&Tracked::from_f64(0.25));
        assert_eq!(z.v, 0.0);
        assert_eq!(z.sign(), None);
    }
}
