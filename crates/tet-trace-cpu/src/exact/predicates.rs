//! The exact predicates of the reference walk ([`super`]): which side of a
//! directed edge the ray's line passes, and which side of a face plane the
//! ray's origin lies, each with a symbolic perturbation so that no answer
//! is ever zero.
//!
//! # Exactness
//!
//! Every input is an f32 (vertex positions, ray origin and direction). An
//! f32 is `m · 2^e` with an integer `m < 2^24` and `e ∈ [−149, 104]`, so a
//! product of at most three f32 is an integer below `2^72` (an `u128`)
//! times `2^e` with `e ∈ [−447, 312]`. Every predicate below is a sum of
//! such products, accumulated exactly in a 960-bit two's-complement fixed
//! point number ([`ExactSum`]: bit 0 weighs `2^−447`, the largest term
//! needs bit 831, and a sum of a few dozen terms stays below bit 840).
//! No rounding happens anywhere, so the sign is exact.
//!
//! The exact sum is the slow path. The fast path evaluates the side
//! product in f64 with a static per-edge error bound (see
//! [`side_filtered`]) and only falls back when the rounded value lies
//! within the bound.
//!
//! # The perturbation (simulation of simplicity)
//!
//! The ray's line is replaced by the line of origin
//! `o(ε) = o + ε·w + ε²·x̂ + ε⁴·ŷ + ε⁸·ẑ` and direction
//! `d(ε) = d + ε¹⁶·x̂ + ε³²·ŷ + ε⁶⁴·ẑ` for an infinitesimal `ε > 0`, where
//! `w = q₀ + q₁ + q₂ + q₃ − 4o` points from the origin to the centroid of
//! the walk's first tet (`qᵢ` its vertices): a real line for every small
//! `ε`, so every decision is the one of a real line in general position,
//! and decisions made in different tets can never contradict each other.
//! The first-order move towards the centroid puts `o(ε)` strictly inside
//! the first tet whenever `o` lies in it, even on its boundary: the start
//! tet the caller gave decides on which side of a face, edge or vertex the
//! ray starts.
//!
//! The side product of edge `a → b`,
//! `S = d·((a − o) × (b − o)) = d·(a × b) + (b − a)·(o × d)`, is linear in
//! the origin and in the direction, so the perturbed product is a
//! polynomial in `ε` whose coefficients, by increasing power, are
//! `S`; `w·c`, `c_x`, `c_y`, `c_z` with `c = d × (b − a)` (powers 1, 2, 4,
//! 8); `g_x` with `g = (a − o) × (b − o)` (16); `((b − a) × w)_x` (17);
//! `−(b−a)_z` (20); `(b−a)_y` (24); `g_y` (32); `((b − a) × w)_y` (33);
//! `(b−a)_z` (34); `−(b−a)_x` (40); …. Its sign is the sign of the first
//! nonzero one, and one of the last three is nonzero whenever `a ≠ b`.
//! Swapping `a` and `b` negates every coefficient, so the rule is exactly
//! antisymmetric and depends on the edge and the ray only, never on the
//! tet being walked.

use glam::Vec3;

/// Limbs of [`ExactSum`].
const LIMBS: usize = 15;
/// The bit that weighs `2^0` in [`ExactSum`]: three times the smallest f32
/// exponent (`2^−149`, the least subnormal).
const OFFSET: i32 = 3 * 149;

/// An exact sum of signed products of up to three f32: a 960-bit
/// two's-complement fixed-point number (see the module docs).
#[derive(Clone, Copy)]
pub(crate) struct ExactSum {
    limbs: [u64; LIMBS],
}

/// `x = m · 2^e` with an integer `m < 2^24` (exact for every finite f32).
fn split(x: f32) -> (u32, i32) {
    let bits = x.to_bits();
    let exp = ((bits >> 23) & 0xff) as i32;
    let frac = bits & 0x7f_ffff;
    if exp == 0 {
        (frac, -149)
    } else {
        (frac | 0x80_0000, exp - 150)
    }
}

impl ExactSum {
    /// Zero.
    pub(crate) fn new() -> Self {
        ExactSum { limbs: [0; LIMBS] }
    }

    /// Adds `sign · a · b · c` exactly.
    pub(crate) fn add(&mut self, positive: bool, a: f32, b: f32, c: f32) {
        if a == 0.0 || b == 0.0 || c == 0.0 {
            return;
        }
        let negative = !positive ^ (a < 0.0) ^ (b < 0.0) ^ (c < 0.0);
        let (ma, ea) = split(a.abs());
        let (mb, eb) = split(b.abs());
        let (mc, ec) = split(c.abs());
        let m = ma as u128 * mb as u128 * mc as u128;
        let shift = (ea + eb + ec + OFFSET) as usize;
        let (limb, bit) = (shift / 64, shift % 64);
        // `m < 2^72` shifted by `bit < 64` spans at most three limbs.
        let lo = m << bit;
        let hi = if bit == 0 { 0 } else { m >> (128 - bit) };
        let words = [lo as u64, (lo >> 64) as u64, hi as u64];
        if negative {
            self.sub_words(limb, words);
        } else {
            self.add_words(limb, words);
        }
    }

    /// Adds the product of two f32 (`sign · a · b`).
    pub(crate) fn add2(&mut self, positive: bool, a: f32, b: f32) {
        self.add(positive, a, b, 1.0);
    }

    fn add_words(&mut self, at: usize, words: [u64; 3]) {
        let mut carry = false;
        for i in at..LIMBS {
            let w = words.get(i - at).copied().unwrap_or(0);
            if w == 0 && !carry && i >= at + 3 {
                break;
            }
            let (s, c1) = self.limbs[i].overflowing_add(w);
            let (s, c2) = s.overflowing_add(carry as u64);
            self.limbs[i] = s;
            carry = c1 || c2;
        }
    }

    fn sub_words(&mut self, at: usize, words: [u64; 3]) {
        let mut borrow = false;
        for i in at..LIMBS {
            let w = words.get(i - at).copied().unwrap_or(0);
            if w == 0 && !borrow && i >= at + 3 {
                break;
            }
            let (s, b1) = self.limbs[i].overflowing_sub(w);
            let (s, b2) = s.overflowing_sub(borrow as u64);
            self.limbs[i] = s;
            borrow = b1 || b2;
        }
    }

    /// The sign: −1, 0 or 1.
    pub(crate) fn sign(&self) -> i32 {
        if self.limbs[LIMBS - 1] >> 63 == 1 {
            -1
        } else if self.limbs.iter().any(|&w| w != 0) {
            1
        } else {
            0
        }
    }
}

/// Adds `sign · det(x, y, z)` (the triple product `x · (y × z)`) exactly.
fn add_det(s: &mut ExactSum, positive: bool, x: Vec3, y: Vec3, z: Vec3) {
    let p = positive;
    s.add(p, x.x, y.y, z.z);
    s.add(!p, x.x, y.z, z.y);
    s.add(p, x.y, y.z, z.x);
    s.add(!p, x.y, y.x, z.z);
    s.add(p, x.z, y.x, z.y);
    s.add(!p, x.z, y.y, z.x);
}

/// Adds `sign · (a × b)_k` exactly.
fn add_cross(s: &mut ExactSum, positive: bool, a: Vec3, b: Vec3, k: usize) {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    s.add2(positive, a[i], b[j]);
    s.add2(!positive, a[j], b[i]);
}

/// Sign of `f32` comparison `b − a` (exact): 1, 0 or −1.
fn diff_sign(a: f32, b: f32) -> i32 {
    if b > a {
        1
    } else if b < a {
        -1
    } else {
        0
    }
}

/// Adds `sign · w·x` with `w = q₀ + q₁ + q₂ + q₃ − 4o` (see the module
/// docs), where `add_one(s, positive, p)` adds `sign · p·x` for one point.
fn add_w(s: &mut ExactSum, line: &Line, add_one: impl Fn(&mut ExactSum, bool, Vec3)) {
    for q in line.first {
        add_one(s, true, q);
    }
    for _ in 0..4 {
        add_one(s, false, line.o);
    }
}

/// The exact, perturbed side of `line` with respect to the directed edge
/// `a → b`: true when the side product `d · ((a − o) × (b − o))` is
/// positive (after the perturbation of the module docs; never zero for
/// `a ≠ b`). `a == b` (a degenerate edge) gives false.
pub(crate) fn side_exact(line: &Line, a: Vec3, b: Vec3) -> bool {
    let (o, d) = (line.o, line.d);
    let decided = |s: ExactSum| match s.sign() {
        0 => None,
        x => Some(x > 0),
    };
    // S = det(d, a, b) + det(d, b, o) + det(d, o, a).
    let mut s = ExactSum::new();
    add_det(&mut s, true, d, a, b);
    add_det(&mut s, true, d, b, o);
    add_det(&mut s, true, d, o, a);
    if let Some(x) = decided(s) {
        return x;
    }
    // Power 1: w · (d × b − d × a) = Σ p · (d × b) − p · (d × a) over w's points.
    let mut s = ExactSum::new();
    add_w(&mut s, line, |s, pos, p| {
        add_det(s, pos, p, d, b);
        add_det(s, !pos, p, d, a);
    });
    if let Some(x) = decided(s) {
        return x;
    }
    // Powers 2, 4, 8: (d × (b − a))_k = (d × b)_k − (d × a)_k.
    for k in 0..3 {
        let mut c = ExactSum::new();
        add_cross(&mut c, true, d, b, k);
        add_cross(&mut c, false, d, a, k);
        if let Some(x) = decided(c) {
            return x;
        }
    }
    // ((a − o) × (b − o))_k = (a × b + b × o + o × a)_k.
    let g = |k: usize| {
        let mut c = ExactSum::new();
        add_cross(&mut c, true, a, b, k);
        add_cross(&mut c, true, b, o, k);
        add_cross(&mut c, true, o, a, k);
        c.sign()
    };
    // ((b − a) × w)_k = Σ (b × p)_k − (a × p)_k over w's points.
    let bw = |k: usize| {
        let mut c = ExactSum::new();
        add_w(&mut c, line, |s, pos, p| {
            add_cross(s, pos, b, p, k);
            add_cross(s, !pos, a, p, k);
        });
        c.sign()
    };
    // Powers 16, 17, 20, 24, 32, 33, 34, 40 (see the module docs).
    let steps: [&dyn Fn() -> i32; 8] = [
        &|| g(0),
        &|| bw(0),
        &|| -diff_sign(a.z, b.z),
        &|| diff_sign(a.y, b.y),
        &|| g(1),
        &|| bw(1),
        &|| diff_sign(a.z, b.z),
        &|| -diff_sign(a.x, b.x),
    ];
    for step in steps {
        match step() {
            0 => {}
            x => return x > 0,
        }
    }
    false
}

/// Relative error bound of the f64 side product (see [`side_filtered`]).
const SIDE_ERR: f64 = 4e-15;

/// One vertex seen from the ray's origin, for the filtered side product:
/// `p − o` in f64 and its largest absolute coordinate.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rel {
    /// The vertex (f32, for the exact fallback).
    pub(crate) p: Vec3,
    u: [f64; 3],
    max: f64,
}

impl Rel {
    /// `p` relative to origin `o`.
    #[inline(always)]
    pub(crate) fn new(p: Vec3, o: [f64; 3]) -> Rel {
        let u = [p.x as f64 - o[0], p.y as f64 - o[1], p.z as f64 - o[2]];
        let max = u[0].abs().max(u[1].abs()).max(u[2].abs());
        Rel { p, u, max }
    }
}

/// The ray as the side products need it: origin and direction (f32 and
/// f64) and `SIDE_ERR · ‖d‖₁`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Line {
    pub(crate) o: Vec3,
    pub(crate) d: Vec3,
    /// The first tet's vertices (the perturbation's `w`).
    first: [Vec3; 4],
    pub(crate) o64: [f64; 3],
    d64: [f64; 3],
    err: f64,
}

impl Line {
    /// The line of `origin + t · direction`, perturbed towards the
    /// centroid of the tet of vertices `first` (module docs).
    pub(crate) fn new(origin: Vec3, direction: Vec3, first: [Vec3; 4]) -> Line {
        let d64 = [direction.x as f64, direction.y as f64, direction.z as f64];
        Line {
            o: origin,
            d: direction,
            first,
            o64: [origin.x as f64, origin.y as f64, origin.z as f64],
            d64,
            err: SIDE_ERR * (d64[0].abs() + d64[1].abs() + d64[2].abs()),
        }
    }

    /// [`Rel::new`] from this line's origin.
    #[inline(always)]
    pub(crate) fn rel(&self, p: Vec3) -> Rel {
        Rel::new(p, self.o64)
    }
}

/// [`side_exact`] behind a floating-point filter: the side product
/// `d · (u_a × u_b)` with `u = p − o`, all in f64. Each term of the
/// expansion carries at most seven roundings (two differences, two
/// products, a subtraction, a product and two additions), so the
/// computed value is within `γ₇ · Σ|d_i|·(|u_aj·u_bk| + |u_ak·u_bj|)
/// ≤ 7.01u · 2‖d‖₁ · max|u_a| · max|u_b|` of the exact one (`u = 2⁻⁵³`;
/// f32 inputs keep every f64 intermediate far from underflow and
/// overflow: the smallest nonzero product is above `2⁻⁴⁴⁷`). The bound
/// used, `4·10⁻¹⁵ · ‖d‖₁ · max|u_a| · max|u_b|`, is over twice that; a
/// value within it goes to the exact sum.
#[inline(always)]
pub(crate) fn side_filtered(line: &Line, a: &Rel, b: &Rel) -> bool {
    let (d, u, v) = (&line.d64, &a.u, &b.u);
    let s = d[0] * (u[1] * v[2] - u[2] * v[1])
        + d[1] * (u[2] * v[0] - u[0] * v[2])
        + d[2] * (u[0] * v[1] - u[1] * v[0]);
    let bound = line.err * a.max * b.max;
    if s > bound {
        true
    } else if s < -bound {
        false
    } else {
        side_exact(line, a.p, b.p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact sum of `a·b·c` terms against integer arithmetic.
    #[test]
    fn exact_sum_matches_integers() {
        let mut s = ExactSum::new();
        s.add(true, 3.0, 5.0, 7.0);
        s.add(false, 105.0, 1.0, 1.0);
        assert_eq!(s.sign(), 0);
        s.add(true, 1e-40, 1e-40, 1e-40);
        assert_eq!(s.sign(), 1);
        s.add(false, 3e38, 3e38, 3e38);
        assert_eq!(s.sign(), -1);
        s.add(true, 3e38, 3e38, 3e38);
        assert_eq!(s.sign(), 1);
        s.add(false, 1e-40, 1e-40, 1e-40);
        assert_eq!(s.sign(), 0);
    }

    /// `1 + 2⁻⁶⁰ − 1` is positive exactly (f64 would lose it).
    #[test]
    fn exact_sum_keeps_tiny_differences() {
        let mut s = ExactSum::new();
        s.add(true, 1.0, 1.0, 1.0);
        s.add(true, 2f32.powi(-20), 2f32.powi(-20), 2f32.powi(-20));
        s.add(false, 1.0, 1.0, 1.0);
        assert_eq!(s.sign(), 1);
    }

    /// A tet around the origin for the perturbation's `w`.
    const AROUND: [Vec3; 4] = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(-1.0, -1.0, -1.0),
    ];

    fn side_exact4(o: Vec3, d: Vec3, a: Vec3, b: Vec3) -> bool {
        side_exact(&Line::new(o, d, AROUND), a, b)
    }

    /// Antisymmetry and agreement with a hand-computed product.
    #[test]
    fn side_is_antisymmetric_and_right() {
        let o = Vec3::ZERO;
        let d = Vec3::Z;
        // A triangle crossed by the z axis: all outward edges positive.
        let (p, q) = (Vec3::new(-1.0, -1.0, 1.0), Vec3::new(1.0, -1.0, 1.0));
        assert!(side_exact4(o, d, p, q));
        assert!(!side_exact4(o, d, q, p));
        // The line through an edge's end point, and along an edge.
        let a = Vec3::new(0.0, 0.0, 2.0);
        let b = Vec3::new(1.0, 0.0, 2.0);
        assert_ne!(side_exact4(o, d, a, b), side_exact4(o, d, b, a));
        let c = Vec3::new(0.0, 0.0, 5.0);
        assert_ne!(side_exact4(o, d, a, c), side_exact4(o, d, c, a));
        // Parallel to the ray but off its line.
        let e = Vec3::new(1.0, 1.0, 0.0);
        let f = Vec3::new(1.0, 1.0, 3.0);
        assert_ne!(side_exact4(o, d, e, f), side_exact4(o, d, f, e));
    }

    /// The filter agrees with the exact sign on near-degenerate products.
    #[test]
    fn filter_agrees_with_exact() {
        let o = Vec3::new(0.1, 0.2, 0.3);
        let line = Line::new(o, Vec3::new(1.0, 1e-7, -3e-8), AROUND.map(|p| p + o));
        for i in 0..200 {
            let t = i as f32 * 0.37;
            let a = o + Vec3::new(t, 1e-7 * t, -3e-8 * t + 1e-9 * (i % 3) as f32);
            let b = Vec3::new(2.0, 0.2 + (i as f32) * 1e-8, 0.3);
            let f = side_filtered(&line, &line.rel(a), &line.rel(b));
            assert_eq!(f, side_exact(&line, a, b));
        }
    }
}
