//! [`Lanes`] in AVX2 intrinsics: 8 lanes in 256-bit vectors, masks as
//! vectors (all ones in a set lane), the record words and points fetched
//! by `vpgatherdd`/`vgatherdps`.

use std::arch::x86_64::*;

use glam::Vec3;

use super::lanes::Lanes;

/// The AVX2 lanes: a token that exists only where the CPU has AVX2.
#[derive(Clone, Copy)]
pub(crate) struct Avx2(());

/// True when the CPU has every feature the AVX2 walks are compiled for
/// (their `#[target_feature]` lists): AVX2 and the scalar extensions that
/// come with it (FMA, BMI1/2, LZCNT, POPCNT). Compiling the walks for
/// these too, not AVX2 alone, gives the code a `-C target-cpu=native`
/// build gets.
pub(crate) fn has_avx2_set() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
        && std::arch::is_x86_feature_detected!("popcnt")
}

impl Avx2 {
    /// The token, when the CPU has [`has_avx2_set`] (detected at run time).
    pub(crate) fn detect() -> Option<Avx2> {
        has_avx2_set().then_some(Avx2(()))
    }
}

/// All ones in lane `l`, zeros elsewhere.
#[inline(always)]
fn lane_mask(_: Avx2, l: usize) -> __m256i {
    // SAFETY (every `unsafe` block of this file that only runs AVX2
    // intrinsics): an `Avx2` exists only where the CPU has AVX2.
    unsafe {
        _mm256_cmpeq_epi32(
            _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
            _mm256_set1_epi32(l as i32),
        )
    }
}

/// `f` out of line with AVX2 code generation.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn cold_avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}

impl Lanes for Avx2 {
    const WIDTH: usize = 8;
    const GATHERS: bool = true;
    type F = __m256;
    type I = __m256i;
    type M = __m256;
    type Arr<T: Copy> = [T; 8];

    #[inline(always)]
    fn arr<T: Copy>(v: T) -> [T; 8] {
        [v; 8]
    }
    #[inline(always)]
    fn f_lanes(x: __m256) -> [f32; 8] {
        bytemuck::cast(x)
    }
    #[inline(always)]
    fn i_lanes(x: __m256i) -> [u32; 8] {
        bytemuck::cast(x)
    }
    #[inline(always)]
    fn cold<R>(self, f: impl FnOnce() -> R) -> R {
        // SAFETY: as `lane_mask`.
        unsafe { cold_avx2(f) }
    }

    #[inline(always)]
    fn splat_f(self, v: f32) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_set1_ps(v) }
    }
    #[inline(always)]
    fn splat_i(self, v: u32) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_set1_epi32(v as i32) }
    }
    #[inline(always)]
    fn add_f(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_add_ps(a, b) }
    }
    #[inline(always)]
    fn sub_f(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_sub_ps(a, b) }
    }
    #[inline(always)]
    fn mul_f(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_mul_ps(a, b) }
    }
    #[inline(always)]
    fn gt_f(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(a, b) }
    }
    #[inline(always)]
    fn eq_f(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b) }
    }
    #[inline(always)]
    fn add_i(self, a: __m256i, b: __m256i) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_add_epi32(a, b) }
    }
    #[inline(always)]
    fn mul_i(self, a: __m256i, b: __m256i) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_mullo_epi32(a, b) }
    }
    #[inline(always)]
    fn xor_i(self, a: __m256i, b: __m256i) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_xor_si256(a, b) }
    }
    #[inline(always)]
    fn and_i(self, a: __m256i, b: __m256i) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_and_si256(a, b) }
    }
    #[inline(always)]
    fn permute_i(self, table: [u32; 8], idx: __m256i) -> __m256i {
        // `vpermd` reads the low 3 bits of each index: `idx mod 8`.
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_permutevar8x32_epi32(bytemuck::cast(table), idx) }
    }
    #[inline(always)]
    fn min_u(self, a: __m256i, b: __m256i) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_min_epu32(a, b) }
    }
    #[inline(always)]
    fn inc(self, x: __m256i, m: __m256) -> __m256i {
        // A set lane is −1: subtracting it adds one.
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_sub_epi32(x, _mm256_castps_si256(m)) }
    }
    #[inline(always)]
    fn zero_unless(self, m: __m256, x: __m256i) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_and_si256(x, _mm256_castps_si256(m)) }
    }
    #[inline(always)]
    fn eq_i(self, a: __m256i, b: __m256i) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_castsi256_ps(_mm256_cmpeq_epi32(a, b)) }
    }
    #[inline(always)]
    fn ne_i(self, a: __m256i, b: __m256i) -> __m256 {
        self.not_m(self.eq_i(a, b))
    }
    #[inline(always)]
    fn gt_i(self, a: __m256i, b: __m256i) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_castsi256_ps(_mm256_cmpgt_epi32(a, b)) }
    }
    #[inline(always)]
    fn ge_u(self, a: __m256i, b: __m256i) -> __m256 {
        // `a ≥ b` exactly when `min(a, b) = b`.
        self.eq_i(self.min_u(a, b), b)
    }
    #[inline(always)]
    fn lt_u(self, a: __m256i, b: __m256i) -> __m256 {
        self.not_m(self.ge_u(a, b))
    }
    #[inline(always)]
    fn select_f(self, m: __m256, t: __m256, f: __m256) -> __m256 {
        // A byte blend, not `vblendvps`: LLVM turns a float blend whose
        // result is stored where its old operand was loaded into a masked
        // store (`vmaskmovps`), slow on AMD and a store-forwarding stall
        // when the next round loads the field; no byte-masked store exists.
        // SAFETY: as `lane_mask`.
        unsafe {
            _mm256_castsi256_ps(_mm256_blendv_epi8(
                _mm256_castps_si256(f),
                _mm256_castps_si256(t),
                _mm256_castps_si256(m),
            ))
        }
    }
    #[inline(always)]
    fn select_i(self, m: __m256, t: __m256i, f: __m256i) -> __m256i {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_blendv_epi8(f, t, _mm256_castps_si256(m)) }
    }
    #[inline(always)]
    fn and_m(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_and_ps(a, b) }
    }
    #[inline(always)]
    fn or_m(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_or_ps(a, b) }
    }
    #[inline(always)]
    fn andnot_m(self, a: __m256, b: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_andnot_ps(a, b) }
    }
    #[inline(always)]
    fn not_m(self, a: __m256) -> __m256 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) }
    }
    #[inline(always)]
    fn any(self, m: __m256) -> bool {
        self.bits(m) != 0
    }
    #[inline(always)]
    fn bits(self, m: __m256) -> u32 {
        // SAFETY: as `lane_mask`.
        unsafe { _mm256_movemask_ps(m) as u32 }
    }
    #[inline(always)]
    fn mask_of_bits(self, b: u32) -> __m256 {
        // SAFETY: as `lane_mask`.
        let bit = unsafe { _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128) };
        // SAFETY: as `lane_mask`.
        let set = unsafe { _mm256_and_si256(self.splat_i(b), bit) };
        self.eq_i(set, bit)
    }
    #[inline(always)]
    fn set_f(self, x: __m256, l: usize, v: f32) -> __m256 {
        // SAFETY: as `lane_mask`.
        let m = unsafe { _mm256_castsi256_ps(lane_mask(self, l)) };
        self.select_f(m, self.splat_f(v), x)
    }
    #[inline(always)]
    fn set_i(self, x: __m256i, l: usize, v: u32) -> __m256i {
        // SAFETY: as `lane_mask`.
        let m = unsafe { _mm256_castsi256_ps(lane_mask(self, l)) };
        self.select_i(m, self.splat_i(v), x)
    }
    #[inline(always)]
    fn get_i(self, x: __m256i, l: usize) -> u32 {
        // SAFETY: as `lane_mask`.
        unsafe {
            _mm256_cvtsi256_si32(_mm256_permutevar8x32_epi32(x, _mm256_set1_epi32(l as i32))) as u32
        }
    }

    #[inline(always)]
    unsafe fn gather_words(self, words: &[u32], idx: __m256i) -> __m256i {
        // SAFETY: AVX2 as `lane_mask`; every lane of `idx` indexes `words`
        // (the caller's contract).
        unsafe { _mm256_i32gather_epi32::<4>(words.as_ptr() as *const i32, idx) }
    }
    #[inline(always)]
    unsafe fn gather_f(self, words: &[u32], idx: __m256i) -> __m256 {
        // SAFETY: AVX2 as `lane_mask`; every lane of `idx` indexes `words`
        // (the caller's contract).
        unsafe { _mm256_i32gather_ps::<4>(words.as_ptr() as *const f32, idx) }
    }
    #[inline(always)]
    unsafe fn gather_point(self, points: &[Vec3], i: __m256i) -> [__m256; 3] {
        // `Vec3` is `#[repr(C)]` `{x, y, z}`: 3 f32 words per point.
        let i3 = self.add_i(self.add_i(i, i), i);
        let base = points.as_ptr() as *const f32;
        // SAFETY: AVX2 as `lane_mask`; `i < points.len()` per lane (the
        // caller's contract), so word `3·i + axis` (axis ≤ 2) lies inside
        // `points` and `3·i` fits in an `i32`; `wrapping_add` only forms
        // the base address.
        unsafe {
            [
                _mm256_i32gather_ps::<4>(base, i3),
                _mm256_i32gather_ps::<4>(base.wrapping_add(1), i3),
                _mm256_i32gather_ps::<4>(base.wrapping_add(2), i3),
            ]
        }
    }
}
