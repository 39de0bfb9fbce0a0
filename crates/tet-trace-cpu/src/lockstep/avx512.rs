//! [`Lanes`] in AVX-512F intrinsics: 16 lanes in 512-bit vectors, masks in
//! mask registers (`__mmask16`), the points' `(x, y)` fetched as 64-bit
//! pairs.

use std::arch::x86_64::*;

use glam::Vec3;

use super::lanes::Lanes;

/// The AVX-512 lanes: a token that exists only where the CPU has AVX-512F.
#[derive(Clone, Copy)]
pub(crate) struct Avx512(());

/// True when the CPU has every feature the AVX-512 walks are compiled for
/// (their `#[target_feature]` lists): AVX-512 F, VL, BW and DQ (mask and
/// 256-bit forms every AVX-512 CPU since Skylake-SP has) and the AVX2 set
/// ([`super::avx2::has_avx2_set`]).
pub(crate) fn has_avx512_set() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && super::avx2::has_avx2_set()
}

impl Avx512 {
    /// The token, when the CPU has [`has_avx512_set`] (detected at run time).
    pub(crate) fn detect() -> Option<Avx512> {
        has_avx512_set().then_some(Avx512(()))
    }
}

/// `f` out of line with AVX-512F code generation.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn cold_avx512<R>(f: impl FnOnce() -> R) -> R {
    f()
}

// SAFETY (every `unsafe` block below that only runs AVX-512F intrinsics):
// an `Avx512` exists only where the CPU has AVX-512F.
impl Lanes for Avx512 {
    const WIDTH: usize = 16;
    const GATHERS: bool = true;
    type F = __m512;
    type I = __m512i;
    type M = __mmask16;
    type Arr<T: Copy> = [T; 16];

    #[inline(always)]
    fn arr<T: Copy>(v: T) -> [T; 16] {
        [v; 16]
    }
    #[inline(always)]
    fn f_lanes(x: __m512) -> [f32; 16] {
        bytemuck::cast(x)
    }
    #[inline(always)]
    fn i_lanes(x: __m512i) -> [u32; 16] {
        bytemuck::cast(x)
    }
    #[inline(always)]
    fn cold<R>(self, f: impl FnOnce() -> R) -> R {
        // SAFETY: AVX-512F, see above.
        unsafe { cold_avx512(f) }
    }

    #[inline(always)]
    fn splat_f(self, v: f32) -> __m512 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_set1_ps(v) }
    }
    #[inline(always)]
    fn splat_i(self, v: u32) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_set1_epi32(v as i32) }
    }
    #[inline(always)]
    fn add_f(self, a: __m512, b: __m512) -> __m512 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_add_ps(a, b) }
    }
    #[inline(always)]
    fn sub_f(self, a: __m512, b: __m512) -> __m512 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_sub_ps(a, b) }
    }
    #[inline(always)]
    fn mul_f(self, a: __m512, b: __m512) -> __m512 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_mul_ps(a, b) }
    }
    #[inline(always)]
    fn gt_f(self, a: __m512, b: __m512) -> __mmask16 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(a, b) }
    }
    #[inline(always)]
    fn eq_f(self, a: __m512, b: __m512) -> __mmask16 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(a, b) }
    }
    #[inline(always)]
    fn add_i(self, a: __m512i, b: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_add_epi32(a, b) }
    }
    #[inline(always)]
    fn mul_i(self, a: __m512i, b: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_mullo_epi32(a, b) }
    }
    #[inline(always)]
    fn xor_i(self, a: __m512i, b: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_xor_si512(a, b) }
    }
    #[inline(always)]
    fn and_i(self, a: __m512i, b: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_and_si512(a, b) }
    }
    #[inline(always)]
    fn permute_i(self, table: [u32; 8], idx: __m512i) -> __m512i {
        // `vpermd` reads the low 4 bits of each index; the table repeated
        // twice makes that `table[idx mod 8]`.
        let t: [u32; 16] = std::array::from_fn(|k| table[k % 8]);
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_permutexvar_epi32(idx, bytemuck::cast(t)) }
    }
    #[inline(always)]
    fn min_u(self, a: __m512i, b: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_min_epu32(a, b) }
    }
    #[inline(always)]
    fn inc(self, x: __m512i, m: __mmask16) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_mask_add_epi32(x, m, x, _mm512_set1_epi32(1)) }
    }
    #[inline(always)]
    fn zero_unless(self, m: __mmask16, x: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_maskz_mov_epi32(m, x) }
    }
    #[inline(always)]
    fn eq_i(self, a: __m512i, b: __m512i) -> __mmask16 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_cmpeq_epi32_mask(a, b) }
    }
    #[inline(always)]
    fn ne_i(self, a: __m512i, b: __m512i) -> __mmask16 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_cmpneq_epi32_mask(a, b) }
    }
    #[inline(always)]
    fn gt_i(self, a: __m512i, b: __m512i) -> __mmask16 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_cmpgt_epi32_mask(a, b) }
    }
    #[inline(always)]
    fn ge_u(self, a: __m512i, b: __m512i) -> __mmask16 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_cmpge_epu32_mask(a, b) }
    }
    #[inline(always)]
    fn lt_u(self, a: __m512i, b: __m512i) -> __mmask16 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_cmplt_epu32_mask(a, b) }
    }
    #[inline(always)]
    fn select_f(self, m: __mmask16, t: __m512, f: __m512) -> __m512 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_mask_blend_ps(m, f, t) }
    }
    #[inline(always)]
    fn select_i(self, m: __mmask16, t: __m512i, f: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_mask_blend_epi32(m, f, t) }
    }
    #[inline(always)]
    fn and_m(self, a: __mmask16, b: __mmask16) -> __mmask16 {
        a & b
    }
    #[inline(always)]
    fn or_m(self, a: __mmask16, b: __mmask16) -> __mmask16 {
        a | b
    }
    #[inline(always)]
    fn andnot_m(self, a: __mmask16, b: __mmask16) -> __mmask16 {
        !a & b
    }
    #[inline(always)]
    fn not_m(self, a: __mmask16) -> __mmask16 {
        !a
    }
    #[inline(always)]
    fn any(self, m: __mmask16) -> bool {
        m != 0
    }
    #[inline(always)]
    fn bits(self, m: __mmask16) -> u32 {
        m as u32
    }
    #[inline(always)]
    fn mask_of_bits(self, b: u32) -> __mmask16 {
        b as __mmask16
    }
    #[inline(always)]
    fn set_f(self, x: __m512, l: usize, v: f32) -> __m512 {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_mask_mov_ps(x, 1 << l, _mm512_set1_ps(v)) }
    }
    #[inline(always)]
    fn set_i(self, x: __m512i, l: usize, v: u32) -> __m512i {
        // SAFETY: AVX-512F, see above.
        unsafe { _mm512_mask_set1_epi32(x, 1 << l, v as i32) }
    }
    #[inline(always)]
    fn get_i(self, x: __m512i, l: usize) -> u32 {
        // One permute brings lane `l` to lane 0.
        // SAFETY: AVX-512F, see above.
        unsafe {
            let at = _mm512_set1_epi32(l as i32);
            _mm_cvtsi128_si32(_mm512_castsi512_si128(_mm512_permutexvar_epi32(at, x))) as u32
        }
    }

    #[inline(always)]
    unsafe fn gather_words(self, words: &[u32], idx: __m512i) -> __m512i {
        // SAFETY: AVX-512F, see above; every lane of `idx` indexes `words`
        // (the caller's contract).
        unsafe { _mm512_i32gather_epi32::<4>(idx, words.as_ptr() as *const i32) }
    }
    /// `(x, y)` as two 8-lane gathers of 64-bit pairs, deinterleaved (16
    /// loads instead of the 32 of two 16-lane gathers), then `z`.
    #[inline(always)]
    unsafe fn gather_f(self, words: &[u32], idx: __m512i) -> __m512 {
        // SAFETY: AVX-512F, see above; every lane of `idx` indexes `words`
        // (the caller's contract).
        unsafe { _mm512_i32gather_ps::<4>(idx, words.as_ptr() as *const f32) }
    }
    #[inline(always)]
    unsafe fn gather_point(self, points: &[Vec3], i: __m512i) -> [__m512; 3] {
        // `Vec3` is `#[repr(C)]` `{x, y, z}`: 3 f32 words per point.
        let i3 = self.add_i(self.add_i(i, i), i);
        // SAFETY: AVX-512F, see above; `i < points.len()` per lane (the
        // caller's contract), so `3·i` fits in an `i32`, the 8 bytes at
        // word `3·i` (x and y) and the word `3·i + 2` (z) lie inside
        // `points`; `wrapping_add` only forms the base address.
        unsafe {
            let pairs = points.as_ptr() as *const i64;
            let lo = _mm512_castsi512_si256(i3);
            let hi = _mm512_extracti64x4_epi64::<1>(i3);
            let a = _mm512_castsi512_ps(_mm512_i32gather_epi64::<4>(lo, pairs));
            let b = _mm512_castsi512_ps(_mm512_i32gather_epi64::<4>(hi, pairs));
            let even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
            let odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
            let z = (points.as_ptr() as *const f32).wrapping_add(2);
            [
                _mm512_permutex2var_ps(a, even, b),
                _mm512_permutex2var_ps(a, odd, b),
                _mm512_i32gather_ps::<4>(i3, z),
            ]
        }
    }
}
