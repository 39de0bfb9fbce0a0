//! The lane abstraction the lockstep walk is written over ([`Lanes`]): a
//! vector of `WIDTH` f32 lanes, one of `WIDTH` u32 lanes, a lane mask, and
//! the handful of operations the walk needs, each one instruction (or a
//! short fixed sequence) of the instruction set, like Embree's `vfloat<K>`.
//!
//! A value of a `Lanes` type is a token: the SIMD implementations can only
//! be made where the CPU has their instruction set (run-time detection), so
//! their safe methods may run its intrinsics. Every method is
//! `#[inline(always)]`: the generic walk, instantiated inside a
//! `#[target_feature]` entry point, inlines down to the intrinsics.

use glam::Vec3;

/// `WIDTH` SIMD lanes: the vector types and operations of one instruction
/// set. Comparisons of floats are ordered (false on NaN); arithmetic is
/// exactly the IEEE operation of each lane (no fused multiply-add), so a
/// lane computes what the scalar code computes.
pub trait Lanes: Copy {
    /// Lanes per vector.
    const WIDTH: usize;
    /// True for the SIMD lanes, whose gathers load a word per lane in one
    /// instruction: the projected walk gathers a layout's records with
    /// them, and reads them through [`Topology`](crate::walk::Topology)
    /// on the portable lanes, whose loads are lane by lane either way.
    const GATHERS: bool;
    /// `WIDTH` f32 lanes.
    type F: Copy;
    /// `WIDTH` u32 lanes.
    type I: Copy;
    /// `WIDTH` booleans.
    type M: Copy;
    /// `WIDTH` plain values, one per lane (the walk's per-lane cold state
    /// and the lanes of a vector read one by one).
    type Arr<T: Copy>: Copy + AsRef<[T]> + AsMut<[T]>;

    /// `v` in every lane.
    fn arr<T: Copy>(v: T) -> Self::Arr<T>;
    /// The lanes of `x` (a plain move: no instruction set needed).
    fn f_lanes(x: Self::F) -> Self::Arr<f32>;
    /// The lanes of `x` (a plain move: no instruction set needed).
    fn i_lanes(x: Self::I) -> Self::Arr<u32>;
    /// Runs the rare path `f` out of line, compiled for this instruction set
    /// (so that the lane operations inside it inline too).
    fn cold<R>(self, f: impl FnOnce() -> R) -> R;

    /// `v` in every lane.
    fn splat_f(self, v: f32) -> Self::F;
    /// `v` in every lane.
    fn splat_i(self, v: u32) -> Self::I;
    /// `a + b`.
    fn add_f(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a − b`.
    fn sub_f(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a · b`.
    fn mul_f(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a > b` (false on NaN).
    fn gt_f(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a == b` (false on NaN).
    fn eq_f(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a + b` (wrapping).
    fn add_i(self, a: Self::I, b: Self::I) -> Self::I;
    /// `a · b` (low 32 bits).
    fn mul_i(self, a: Self::I, b: Self::I) -> Self::I;
    /// `a ⊕ b`.
    fn xor_i(self, a: Self::I, b: Self::I) -> Self::I;
    /// `a ∧ b`, bitwise.
    fn and_i(self, a: Self::I, b: Self::I) -> Self::I;
    /// `table[idx mod 8]` per lane (one permute on AVX2 and AVX-512).
    fn permute_i(self, table: [u32; 8], idx: Self::I) -> Self::I;
    /// `min(a, b)`, unsigned.
    fn min_u(self, a: Self::I, b: Self::I) -> Self::I;
    /// `x + 1` in the lanes of `m`, `x` elsewhere.
    fn inc(self, x: Self::I, m: Self::M) -> Self::I;
    /// `x` in the lanes of `m`, 0 elsewhere.
    fn zero_unless(self, m: Self::M, x: Self::I) -> Self::I;
    /// `a == b`.
    fn eq_i(self, a: Self::I, b: Self::I) -> Self::M;
    /// `a != b`.
    fn ne_i(self, a: Self::I, b: Self::I) -> Self::M;
    /// `a > b` as signed integers.
    fn gt_i(self, a: Self::I, b: Self::I) -> Self::M;
    /// `a ≥ b`, unsigned.
    fn ge_u(self, a: Self::I, b: Self::I) -> Self::M;
    /// `a < b`, unsigned.
    fn lt_u(self, a: Self::I, b: Self::I) -> Self::M;
    /// `t` in the lanes of `m`, `f` elsewhere.
    fn select_f(self, m: Self::M, t: Self::F, f: Self::F) -> Self::F;
    /// `t` in the lanes of `m`, `f` elsewhere.
    fn select_i(self, m: Self::M, t: Self::I, f: Self::I) -> Self::I;
    /// `a ∧ b`.
    fn and_m(self, a: Self::M, b: Self::M) -> Self::M;
    /// `a ∨ b`.
    fn or_m(self, a: Self::M, b: Self::M) -> Self::M;
    /// `¬a ∧ b`.
    fn andnot_m(self, a: Self::M, b: Self::M) -> Self::M;
    /// `¬a`.
    fn not_m(self, a: Self::M) -> Self::M;
    /// True when some lane of `m` is set.
    fn any(self, m: Self::M) -> bool;
    /// Bit `l` set when lane `l` of `m` is.
    fn bits(self, m: Self::M) -> u32;
    /// The mask whose lane `l` is bit `l` of `b`.
    fn mask_of_bits(self, b: u32) -> Self::M;
    /// `x` with lane `l` replaced by `v`.
    fn set_f(self, x: Self::F, l: usize, v: f32) -> Self::F;
    /// `x` with lane `l` replaced by `v`.
    fn set_i(self, x: Self::I, l: usize, v: u32) -> Self::I;
    /// Lane `l` of `x`.
    fn get_i(self, x: Self::I, l: usize) -> u32;

    /// `words[idx]` per lane.
    ///
    /// # Safety
    ///
    /// Every lane of `idx` must be `< words.len()` (the SIMD
    /// implementations load without a bounds check).
    unsafe fn gather_words(self, words: &[u32], idx: Self::I) -> Self::I;
    /// `words[idx]` per lane, read as the bits of an f32.
    ///
    /// # Safety
    ///
    /// As [`Lanes::gather_words`].
    unsafe fn gather_f(self, words: &[u32], idx: Self::I) -> Self::F;
    /// `(x, y, z)` of `points[i]` per lane.
    ///
    /// # Safety
    ///
    /// Every lane of `i` must be `< points.len()`, and `3 · points.len()`
    /// must fit in an `i32` (the gathers' indices).
    unsafe fn gather_point(self, points: &[Vec3], i: Self::I) -> [Self::F; 3];
}
