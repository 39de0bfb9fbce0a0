//! [`Lanes`] as plain arrays of `W` lanes, each operation a lane loop for
//! the auto-vectoriser: the portable fallback (4 lanes on the baseline
//! target, 8 compiled for AVX2 for layouts whose records the gathers
//! cannot read), with bounds-checked loads.

use std::array::from_fn;

use glam::Vec3;

use super::lanes::Lanes;

/// `W` lanes as arrays (`0 < W ≤ 32`: a mask's lanes are the bits of a
/// `u32`).
#[derive(Clone, Copy)]
pub(crate) struct Portable<const W: usize>;

/// `f` out of line.
#[cold]
#[inline(never)]
fn cold_portable<R>(f: impl FnOnce() -> R) -> R {
    f()
}

impl<const W: usize> Lanes for Portable<W> {
    const WIDTH: usize = W;
    const GATHERS: bool = false;
    type F = [f32; W];
    type I = [u32; W];
    type M = [bool; W];
    type Arr<T: Copy> = [T; W];

    #[inline(always)]
    fn arr<T: Copy>(v: T) -> [T; W] {
        [v; W]
    }
    #[inline(always)]
    fn f_lanes(x: [f32; W]) -> [f32; W] {
        x
    }
    #[inline(always)]
    fn i_lanes(x: [u32; W]) -> [u32; W] {
        x
    }
    #[inline(always)]
    fn cold<R>(self, f: impl FnOnce() -> R) -> R {
        cold_portable(f)
    }

    #[inline(always)]
    fn splat_f(self, v: f32) -> [f32; W] {
        [v; W]
    }
    #[inline(always)]
    fn splat_i(self, v: u32) -> [u32; W] {
        [v; W]
    }
    #[inline(always)]
    fn add_f(self, a: [f32; W], b: [f32; W]) -> [f32; W] {
        from_fn(|l| a[l] + b[l])
    }
    #[inline(always)]
    fn sub_f(self, a: [f32; W], b: [f32; W]) -> [f32; W] {
        from_fn(|l| a[l] - b[l])
    }
    #[inline(always)]
    fn mul_f(self, a: [f32; W], b: [f32; W]) -> [f32; W] {
        from_fn(|l| a[l] * b[l])
    }
    #[inline(always)]
    fn gt_f(self, a: [f32; W], b: [f32; W]) -> [bool; W] {
        from_fn(|l| a[l] > b[l])
    }
    #[inline(always)]
    fn eq_f(self, a: [f32; W], b: [f32; W]) -> [bool; W] {
        from_fn(|l| a[l] == b[l])
    }
    #[inline(always)]
    fn add_i(self, a: [u32; W], b: [u32; W]) -> [u32; W] {
        from_fn(|l| a[l].wrapping_add(b[l]))
    }
    #[inline(always)]
    fn mul_i(self, a: [u32; W], b: [u32; W]) -> [u32; W] {
        from_fn(|l| a[l].wrapping_mul(b[l]))
    }
    #[inline(always)]
    fn xor_i(self, a: [u32; W], b: [u32; W]) -> [u32; W] {
        from_fn(|l| a[l] ^ b[l])
    }
    #[inline(always)]
    fn and_i(self, a: [u32; W], b: [u32; W]) -> [u32; W] {
        from_fn(|l| a[l] & b[l])
    }
    #[inline(always)]
    fn permute_i(self, table: [u32; 8], idx: [u32; W]) -> [u32; W] {
        from_fn(|l| table[idx[l] as usize % 8])
    }
    #[inline(always)]
    fn min_u(self, a: [u32; W], b: [u32; W]) -> [u32; W] {
        from_fn(|l| a[l].min(b[l]))
    }
    #[inline(always)]
    fn inc(self, x: [u32; W], m: [bool; W]) -> [u32; W] {
        from_fn(|l| x[l].wrapping_add(m[l] as u32))
    }
    #[inline(always)]
    fn zero_unless(self, m: [bool; W], x: [u32; W]) -> [u32; W] {
        from_fn(|l| if m[l] { x[l] } else { 0 })
    }
    #[inline(always)]
    fn eq_i(self, a: [u32; W], b: [u32; W]) -> [bool; W] {
        from_fn(|l| a[l] == b[l])
    }
    #[inline(always)]
    fn ne_i(self, a: [u32; W], b: [u32; W]) -> [bool; W] {
        from_fn(|l| a[l] != b[l])
    }
    #[inline(always)]
    fn gt_i(self, a: [u32; W], b: [u32; W]) -> [bool; W] {
        from_fn(|l| (a[l] as i32) > (b[l] as i32))
    }
    #[inline(always)]
    fn ge_u(self, a: [u32; W], b: [u32; W]) -> [bool; W] {
        from_fn(|l| a[l] >= b[l])
    }
    #[inline(always)]
    fn lt_u(self, a: [u32; W], b: [u32; W]) -> [bool; W] {
        from_fn(|l| a[l] < b[l])
    }
    #[inline(always)]
    fn select_f(self, m: [bool; W], t: [f32; W], f: [f32; W]) -> [f32; W] {
        from_fn(|l| if m[l] { t[l] } else { f[l] })
    }
    #[inline(always)]
    fn select_i(self, m: [bool; W], t: [u32; W], f: [u32; W]) -> [u32; W] {
        from_fn(|l| if m[l] { t[l] } else { f[l] })
    }
    #[inline(always)]
    fn and_m(self, a: [bool; W], b: [bool; W]) -> [bool; W] {
        from_fn(|l| a[l] & b[l])
    }
    #[inline(always)]
    fn or_m(self, a: [bool; W], b: [bool; W]) -> [bool; W] {
        from_fn(|l| a[l] | b[l])
    }
    #[inline(always)]
    fn andnot_m(self, a: [bool; W], b: [bool; W]) -> [bool; W] {
        from_fn(|l| !a[l] & b[l])
    }
    #[inline(always)]
    fn not_m(self, a: [bool; W]) -> [bool; W] {
        a.map(|x| !x)
    }
    #[inline(always)]
    fn any(self, m: [bool; W]) -> bool {
        m.iter().any(|&x| x)
    }
    #[inline(always)]
    fn bits(self, m: [bool; W]) -> u32 {
        m.iter()
            .enumerate()
            .fold(0, |b, (l, &x)| b | (x as u32) << l)
    }
    #[inline(always)]
    fn mask_of_bits(self, b: u32) -> [bool; W] {
        from_fn(|l| b >> l & 1 != 0)
    }
    #[inline(always)]
    fn set_f(self, mut x: [f32; W], l: usize, v: f32) -> [f32; W] {
        x[l] = v;
        x
    }
    #[inline(always)]
    fn set_i(self, mut x: [u32; W], l: usize, v: u32) -> [u32; W] {
        x[l] = v;
        x
    }
    #[inline(always)]
    fn get_i(self, x: [u32; W], l: usize) -> u32 {
        x[l]
    }

    #[inline(always)]
    unsafe fn gather_words(self, words: &[u32], idx: [u32; W]) -> [u32; W] {
        from_fn(|l| words[idx[l] as usize])
    }
    #[inline(always)]
    unsafe fn gather_f(self, words: &[u32], idx: [u32; W]) -> [f32; W] {
        from_fn(|l| f32::from_bits(words[idx[l] as usize]))
    }
    #[inline(always)]
    unsafe fn gather_point(self, points: &[Vec3], i: [u32; W]) -> [[f32; W]; 3] {
        let p: [Vec3; W] = from_fn(|l| points[i[l] as usize]);
        [
            from_fn(|l| p[l].x),
            from_fn(|l| p[l].y),
            from_fn(|l| p[l].z),
        ]
    }
}
