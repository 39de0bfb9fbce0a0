//! Exact arithmetic on floating-point expansions (Shewchuk, "Adaptive
//! precision floating-point arithmetic and fast robust geometric
//! predicates", 1997): a value is a sum of non-overlapping doubles, sorted by
//! increasing magnitude, with zeros removed. Sums, differences and products
//! are exact as long as nothing overflows or underflows; the input range
//! check in [`super::resolve`] keeps every product of this module's
//! predicates far from both.

use super::arith::Ring;

/// An exact value: the sum of its components.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Expansion(Vec<f64>);

const SPLITTER: f64 = 134_217_729.0; // 2^27 + 1

fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    (x, b - (x - a))
}

fn split(a: f64) -> (f64, f64) {
    let c = SPLITTER * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    let (ahi, alo) = split(a);
    let (bhi, blo) = split(b);
    let err = x - ahi * bhi - alo * bhi - ahi * blo;
    (x, alo * blo - err)
}

impl Expansion {
    /// Adds one double (Shewchuk's GROW-EXPANSION with zero elimination).
    fn grow(&self, b: f64) -> Expansion {
        let mut out = Vec::with_capacity(self.0.len() + 1);
        let mut q = b;
        for &e in &self.0 {
            let (s, h) = two_sum(q, e);
            if h != 0.0 {
                out.push(h);
            }
            q = s;
        }
        if q != 0.0 {
            out.push(q);
        }
        Expansion(out)
    }

    /// `self * b` (SCALE-EXPANSION with zero elimination).
    fn scale(&self, b: f64) -> Expansion {
        let mut out = Vec::with_capacity(2 * self.0.len());
        let Some((&first, rest)) = self.0.split_first() else {
            return Expansion::default();
        };
        let (mut q, h) = two_product(first, b);
        if h != 0.0 {
            out.push(h);
        }
        for &e in rest {
            let (p1, p0) = two_product(e, b);
            let (sum, h) = two_sum(q, p0);
            if h != 0.0 {
                out.push(h);
            }
            let (nq, h) = fast_two_sum(p1, sum);
            if h != 0.0 {
                out.push(h);
            }
            q = nq;
        }
        if q != 0.0 {
            out.push(q);
        }
        Expansion(out)
    }

    /// Shortens the expansion to an equivalent one with as few components
    /// as the algorithm finds (Shewchuk's COMPRESS).
    fn compress(self) -> Expansion {
        let e = self.0;
        if e.len() < 3 {
            return Expansion(e);
        }
        let mut g = vec![0.0; e.len()];
        let mut bottom = e.len() - 1;
        let mut q = e[bottom];
        for i in (0..e.len() - 1).rev() {
            let (nq, small) = fast_two_sum(q, e[i]);
            if small != 0.0 {
                g[bottom] = nq;
                bottom -= 1;
                q = small;
            } else {
                q = nq;
            }
        }
        g[bottom] = q;
        let mut h = Vec::with_capacity(e.len() - bottom);
        for &now in &g[bottom + 1..] {
            let (nq, small) = fast_two_sum(now, q);
            q = nq;
            if small != 0.0 {
                h.push(small);
            }
        }
        if q != 0.0 {
            h.push(q);
        }
        Expansion(h)
    }

    fn negate(&self) -> Expansion {
        Expansion(self.0.iter().map(|x| -x).collect())
    }

    /// True when every component is finite (nothing overflowed).
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|x| x.is_finite())
    }
}

impl Ring for Expansion {
    fn from_f64(x: f64) -> Self {
        if x == 0.0 {
            Expansion::default()
        } else {
            Expansion(vec![x])
        }
    }
    fn diff(a: f64, b: f64) -> Self {
        let (x, y) = two_sum(a, -b);
        Expansion([y, x].into_iter().filter(|&c| c != 0.0).collect())
    }
    fn add(&self, o: &Self) -> Self {
        let (long, short) = if self.0.len() >= o.0.len() {
            (self, o)
        } else {
            (o, self)
        };
        let mut acc = long.clone();
        for &c in &short.0 {
            acc = acc.grow(c);
        }
        acc.compress()
    }
    fn sub(&self, o: &Self) -> Self {
        self.add(&o.negate())
    }
    fn mul(&self, o: &Self) -> Self {
        let (long, short) = if self.0.len() >= o.0.len() {
            (self, o)
        } else {
            (o, self)
        };
        let mut acc = Expansion::default();
        for &c in &short.0 {
            acc = acc.add(&long.scale(c));
        }
        acc
    }
    fn sign(&self) -> Option<i8> {
        if !self.is_finite() {
            return None;
        }
        // Components increase in magnitude and do not overlap: the largest decides.
        Some(match self.0.last() {
            None => 0,
            Some(&x) if x > 0.0 => 1,
            Some(_) => -1,
        })
    }
    fn estimate(&self) -> f64 {
        self.0.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(x: f64) -> Expansion {
        Expansion::from_f64(x)
    }

    #[test]
    fn cancellation_is_exact() {
        // (1 + 2^-40)^2 - 1 - 2^-39 = 2^-80 exactly.
        let a = e(1.0 + 2f64.powi(-40));
        let r = a.mul(&a).sub(&e(1.0)).sub(&e(2f64.powi(-39)));
        assert_eq!(r.sign(), Some(1));
        assert_eq!(r.estimate(), 2f64.powi(-80));
        // And the same value minus itself is exactly zero.
        let z = a.mul(&a).sub(&a.mul(&a));
        assert_eq!(z.sign(), Some(0));
    }

    #[test]
    fn products_match_integer_arithmetic() {
        // Products of 30-bit integers overflow f64's 53 bits but not i128.
        let xs = [1_073_741_789i64, -987_654_321, 123_456_789, 1_000_000_007];
        let mut exact = Expansion::from_f64(1.0);
        let mut int = 1i128;
        for &x in &xs {
            exact = exact.mul(&e(x as f64));
            int *= x as i128;
        }
        // Split the 120-bit integer into three exactly representable parts.
        let hi = int as f64;
        let rest = int - hi as i128;
        let mid = rest as f64;
        let lo = (rest - mid as i128) as f64;
        let zero = exact.sub(&e(hi)).sub(&e(mid)).sub(&e(lo));
        assert_eq!(zero.sign(), Some(0));
        let off_by_one = exact.sub(&e(hi)).sub(&e(mid)).sub(&e(lo + 1.0));
        assert_eq!(off_by_one.sign(), Some(-1));
    }

    #[test]
    fn diff_keeps_the_rounding_error() {
        let d = Expansion::diff(1e20, 1.0);
        assert_eq!(d.add(&e(1.0)).sub(&e(1e20)).sign(), Some(0));
    }
}
