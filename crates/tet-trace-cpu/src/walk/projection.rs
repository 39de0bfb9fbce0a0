//! The projections: how a ray maps mesh vertices to the quantities whose
//! signs steer the walk (the 2-D points of Aman et al. (2022) §4, in f32
//! or f64, with or without the projected origin of Eq. 4–5, or the 3-D
//! scalar triple products of Lagae & Dutré), and the tie rule that keeps
//! each edge test exactly antisymmetric.

use glam::{DVec2, DVec3, Vec2, Vec3, Vec4};

use crate::ray::Ray;

/// How a ray's vertices are mapped to the quantities whose signs steer the walk.
pub trait Projection: Copy + Send + Sync {
    /// A projected vertex.
    type P: Copy;
    /// Short name for reports.
    const NAME: &'static str;
    /// Builds the projection of a (valid) ray.
    fn setup(ray: &Ray) -> Self;
    /// [`Projection::setup`] with the projected coordinates multiplied by
    /// `scale`, a power of two chosen per ray by [`walk_scale`]. A power of
    /// two multiplies every product exactly, so every sign — hence every
    /// exit face — is the one `setup` gives, but the determinants of a
    /// scene at 1e-30 or 1e30 no longer underflow or overflow f32. The f32
    /// 2-D projections fold the factor into their basis (no cost per
    /// vertex); the others ignore it (f64 has the range; the papers' 3-D
    /// products have no multiplication to fold it into).
    fn setup_scaled(ray: &Ray, scale: f32) -> Self {
        let _ = scale;
        Self::setup(ray)
    }
    /// Projects one mesh vertex (must be a pure function of `p` and the ray).
    fn project(&self, p: Vec3) -> Self::P;
    /// True when the projected triangle `p` is flat up to rounding (its
    /// area below a millionth of its edges' product): the ray runs in, or
    /// within rounding of, the triangle's plane. Used off the hot path
    /// only (the boundary entry's choice among faces).
    fn flat(p: &[Self::P; 3]) -> bool {
        let _ = p;
        false
    }
    /// True when the ray passes to the left of the directed edge `a → b`,
    /// i.e. `det(pa, pb) > 0` with the tie rule of the module docs.
    /// Exactly antisymmetric: `left(a, b) == !left(b, a)`.
    fn left(&self, a: Self::P, ia: u32, b: Self::P, ib: u32) -> bool;

    /// The entry face's three projected points as the walk stores them
    /// (an array, or SoA vectors for the SIMD 2-D projections).
    type Face: Copy;
    /// Packs three projected points.
    fn face(p: [Self::P; 3]) -> Self::Face;
    /// Replaces point `slot` (0..=2) of a face.
    fn set_point(face: &mut Self::Face, slot: usize, p: Self::P);
    /// The three edge tests of a step as a bit mask:
    /// bit `i` = `left(pd, d, pᵢ, ids[i])` for the points `pᵢ` of `face`
    /// (the index of [`EXIT_SLOT`](crate::walk::EXIT_SLOT)). Implementations may only change how
    /// the bits are computed, never their values: the 2-D ones evaluate the
    /// three determinants at once, branch-free, and take the tie rule only
    /// when one of them is zero.
    fn left_mask(&self, pd: Self::P, d: u32, face: &Self::Face, ids: &[u32; 3]) -> usize;
}

/// [`Projection::Face`] for projections that store the face as an array:
/// the three `left` calls of Algorithm 1, as written.
macro_rules! array_face {
    ($P:ty) => {
        array_face!($P, no_mask);
        #[inline(always)]
        fn left_mask(&self, pd: $P, d: u32, f: &[$P; 3], ids: &[u32; 3]) -> usize {
            self.left(pd, d, f[0], ids[0]) as usize
                | (self.left(pd, d, f[1], ids[1]) as usize) << 1
                | (self.left(pd, d, f[2], ids[2]) as usize) << 2
        }
    };
    ($P:ty, no_mask) => {
        type Face = [$P; 3];
        #[inline(always)]
        fn face(p: [$P; 3]) -> [$P; 3] {
            p
        }
        #[inline(always)]
        fn set_point(face: &mut [$P; 3], slot: usize, p: $P) {
            face[slot] = p;
        }
    };
}

/// An entry face of 2-D f32 points in SoA form: `xs = (x₀, x₁, x₂, 0)`,
/// `ys = (y₀, y₁, y₂, 0)`, so that the three determinants of a step
/// `det(pd, pᵢ) = pd.x·yᵢ − pd.y·xᵢ` are one SIMD multiply–multiply–subtract
/// (each lane computes exactly the scalar expression of `left_2d!`: same
/// operands, same operations, no fusion, hence bit-identical).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Face2 {
    // Plain arrays (16-byte aligned): a replacement is one scalar store per
    // array at a variable index, without branches; the determinants load
    // them as vectors.
    pub(crate) xs: [f32; 4],
    pub(crate) ys: [f32; 4],
}

impl Face2 {
    /// Packs three points.
    #[inline(always)]
    pub fn new(p: [Vec2; 3]) -> Face2 {
        Face2 {
            xs: [p[0].x, p[1].x, p[2].x, 0.0],
            ys: [p[0].y, p[1].y, p[2].y, 0.0],
        }
    }
    /// Point `i` (0..=2).
    #[inline(always)]
    pub fn point(&self, i: usize) -> Vec2 {
        Vec2::new(self.xs[i], self.ys[i])
    }
    /// Replaces point `slot` (0..=2; larger values panic).
    #[inline(always)]
    pub fn set(&mut self, slot: usize, p: Vec2) {
        self.xs[slot] = p.x;
        self.ys[slot] = p.y;
    }
    /// Bit `i` = `left_f32(pd, d, pᵢ, ids[i])`: the fast path when no
    /// determinant is zero, the full tie rule otherwise.
    #[inline(always)]
    pub fn left_mask(&self, pd: Vec2, d: u32, ids: &[u32; 3]) -> usize {
        let (xs, ys) = (Vec4::from_array(self.xs), Vec4::from_array(self.ys));
        let det = Vec4::splat(pd.x) * ys - Vec4::splat(pd.y) * xs;
        let nonzero = det.cmpne(Vec4::ZERO).bitmask() & 7;
        if nonzero == 7 {
            (det.cmpgt(Vec4::ZERO).bitmask() & 7) as usize
        } else {
            self.left_mask_ties(pd, d, ids)
        }
    }
    #[cold]
    #[inline(never)]
    pub(crate) fn left_mask_ties(&self, pd: Vec2, d: u32, ids: &[u32; 3]) -> usize {
        left_f32(pd, d, self.point(0), ids[0]) as usize
            | (left_f32(pd, d, self.point(1), ids[1]) as usize) << 1
            | (left_f32(pd, d, self.point(2), ids[2]) as usize) << 2
    }
}

/// [`Projection::Face`] = [`Face2`] for the 2-D f32 projections.
macro_rules! simd_face {
    () => {
        type Face = $crate::walk::projection::Face2;
        #[inline(always)]
        fn face(p: [Vec2; 3]) -> $crate::walk::projection::Face2 {
            $crate::walk::projection::Face2::new(p)
        }
        #[inline(always)]
        fn set_point(face: &mut $crate::walk::projection::Face2, slot: usize, p: Vec2) {
            face.set(slot, p);
        }
        #[inline(always)]
        fn left_mask(
            &self,
            pd: Vec2,
            d: u32,
            f: &$crate::walk::projection::Face2,
            ids: &[u32; 3],
        ) -> usize {
            f.left_mask(pd, d, ids)
        }
    };
}
pub(crate) use simd_face;

/// The tie rule of the module docs for 2-D points: the rounded
/// determinant when it is not zero (its sign is exact, see
/// [`ExactDet`]), else the exact determinant's sign, else the symbolic
/// perturbation.
macro_rules! left_2d {
    ($a:expr, $ia:expr, $b:expr, $ib:expr) => {{
        let (a, b) = ($a, $b);
        let det = a.x * b.y - a.y * b.x;
        let exact;
        if det != 0.0 {
            det > 0.0
        } else if {
            exact = $crate::walk::projection::ExactDet::exact_det(a, b);
            exact != 0.0
        } {
            exact > 0.0
        } else if a.y != b.y {
            a.y > b.y
        } else if a.x != b.x {
            b.x > a.x
        } else {
            $ia < $ib
        }
    }};
}
pub(crate) use left_2d;

/// The determinant `det(a, b) = a.x·b.y − a.y·b.x` of two projected points
/// with its exact sign, for the tie rule (step 3 of the module docs), on
/// the cold path only: the walk reaches it when the rounded determinant is
/// zero.
///
/// Why the rounded determinant needs no check when it is not zero: the
/// products are rounded monotonically (`A ≤ B ⇒ fl(A) ≤ fl(B)`), so
/// `fl(A) ≠ fl(B)` already orders the exact products, and the subtraction
/// of two floats is zero only when they are equal. A zero, though, may hide
/// two different exact products that rounded to the same float; this is
/// what decides them.
pub(crate) trait ExactDet: Copy {
    /// A value with the sign of the exact `a.x·b.y − a.y·b.x` (zero only
    /// when it is exactly zero).
    fn exact_det(a: Self, b: Self) -> f64;
}

impl ExactDet for Vec2 {
    /// Products of two f32 are exact in f64 (24 + 24 bits < 53), and a
    /// rounded difference keeps the sign of the exact one.
    #[inline]
    fn exact_det(a: Vec2, b: Vec2) -> f64 {
        a.x as f64 * b.y as f64 - a.y as f64 * b.x as f64
    }
}

impl ExactDet for DVec2 {
    /// Called when `fl(fl(A) − fl(B)) = 0`, i.e. `fl(A) = fl(B)`: then
    /// `A − B = errA − errB`, each product's rounding error exact by a fused
    /// multiply-add (no overflow or underflow for the walk's magnitudes,
    /// see [`walk_scale`]); a rounded difference keeps the sign.
    #[inline]
    fn exact_det(a: DVec2, b: DVec2) -> f64 {
        let (pa, pb) = (a.x * b.y, a.y * b.x);
        if pa != pb {
            // Not reached from `left_2d!` (kept exact for any caller).
            return pa - pb;
        }
        a.x.mul_add(b.y, -pa) - a.y.mul_add(b.x, -pb)
    }
}

/// [`Projection::flat`] of the 2-D projections, in f64.
fn flat_2d(p: [DVec2; 3]) -> bool {
    let (e, f) = (p[1] - p[0], p[2] - p[0]);
    let area = e.perp_dot(f);
    area * area <= 1e-12 * e.length_squared() * f.length_squared()
}

/// The tie rule of the module docs on f32 2-D points (shared by every f32
/// 2-D projection).
#[inline(always)]
pub(crate) fn left_f32(a: Vec2, ia: u32, b: Vec2, ib: u32) -> bool {
    left_2d!(a, ia, b, ib)
}

/// The power of two [`Projection::setup_scaled`] multiplies a ray's
/// projected coordinates by, from `magnitude`, the largest coordinate of
/// the vertices around the start of its walk relative to its origin
/// (`|P − o|∞`): 1 for scenes of ordinary size (`magnitude` within
/// 2⁻¹⁶…2¹⁶, so their walks are bit for bit what they always were), else
/// `2⁻ᵉ` with `2ᵉ ≤ magnitude < 2ᵉ⁺¹`, which brings the projected
/// coordinates near 1 and their determinants far from f32's limits. Only
/// the walk's signs depend on the projection, and a power of two keeps
/// them, so any such factor gives the same walk.
#[inline]
pub fn walk_scale(magnitude: f64) -> f32 {
    // Two comparisons for ordinary scenes (every ray sets up its scale):
    // no logarithm on the hot path.
    if (1.0 / 65536.0..131072.0).contains(&magnitude) || !(magnitude.is_finite() && magnitude > 0.0)
    {
        return 1.0;
    }
    let e = magnitude.log2().floor() as i32;
    if (-16..=16).contains(&e) {
        1.0
    } else {
        (2.0f64).powi(-e.clamp(-126, 126)) as f32
    }
}

/// Duff et al.'s orthonormal basis for a unit vector `n`, ordered so that
/// `u × v` points along `n` (public so the GPU crate projects batch rays with
/// exactly the CPU's basis).
pub fn duff_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let u = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let v = DVec3::new(b, sign + n.y * n.y * a, -n.y);
    if u.cross(v).dot(n) >= 0.0 {
        (u, v)
    } else {
        (v, u)
    }
}

/// f32 projection `p = (u·(P−o), v·(P−o))` with Duff et al.'s basis
/// (6 multiplications, 4 additions, 3 subtractions per vertex). Both dot
/// products are evaluated at once in SIMD, column by column:
/// `(u·q, v·q) = (uₓ, vₓ)·qₓ + (u_y, v_y)·q_y + (u_z, v_z)·q_z`, which is the
/// scalar `(uₓqₓ + u_y q_y) + u_z q_z` lane by lane (bit-identical; any fixed
/// formula keeps the walk watertight, this one also matches the scalar
/// reference order).
#[derive(Clone, Copy, Debug, Default)]
pub struct DuffF32 {
    pub(crate) o: Vec3,
    pub(crate) cx: Vec4,
    pub(crate) cy: Vec4,
    pub(crate) cz: Vec4,
}

impl Projection for DuffF32 {
    type P = Vec2;
    simd_face!();
    const NAME: &'static str = "f32";
    fn flat(p: &[Vec2; 3]) -> bool {
        flat_2d(p.map(|q| q.as_dvec2()))
    }
    fn setup(ray: &Ray) -> Self {
        Self::setup_scaled(ray, 1.0)
    }
    fn setup_scaled(ray: &Ray, scale: f32) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        let (u, v) = (u.as_vec3() * scale, v.as_vec3() * scale);
        DuffF32 {
            o: ray.origin,
            cx: Vec4::new(u.x, v.x, 0.0, 0.0),
            cy: Vec4::new(u.y, v.y, 0.0, 0.0),
            cz: Vec4::new(u.z, v.z, 0.0, 0.0),
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> Vec2 {
        let q = p - self.o;
        let r =
            self.cx * Vec4::splat(q.x) + self.cy * Vec4::splat(q.y) + self.cz * Vec4::splat(q.z);
        Vec2::new(r.x, r.y)
    }
    #[inline(always)]
    fn left(&self, a: Vec2, ia: u32, b: Vec2, ib: u32) -> bool {
        left_2d!(a, ia, b, ib)
    }
}

/// f32 projection with the projected ray origin of Eq. 4–5:
/// `p = (u·P − po.x, v·P − po.y)`, `po = (u·o, v·o)` (one subtraction per
/// coordinate instead of three, less accurate far from the world origin).
#[derive(Clone, Copy, Debug)]
pub struct OriginF32 {
    po: Vec2,
    u: Vec3,
    v: Vec3,
}

impl Projection for OriginF32 {
    type P = Vec2;
    simd_face!();
    const NAME: &'static str = "f32-po";
    fn flat(p: &[Vec2; 3]) -> bool {
        flat_2d(p.map(|q| q.as_dvec2()))
    }
    fn setup(ray: &Ray) -> Self {
        Self::setup_scaled(ray, 1.0)
    }
    fn setup_scaled(ray: &Ray, scale: f32) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        let (u, v) = (u.as_vec3() * scale, v.as_vec3() * scale);
        OriginF32 {
            po: Vec2::new(u.dot(ray.origin), v.dot(ray.origin)),
            u,
            v,
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> Vec2 {
        Vec2::new(self.u.dot(p) - self.po.x, self.v.dot(p) - self.po.y)
    }
    #[inline(always)]
    fn left(&self, a: Vec2, ia: u32, b: Vec2, ib: u32) -> bool {
        left_2d!(a, ia, b, ib)
    }
}

/// f64 variant of [`DuffF32`] (points converted exactly to f64).
#[derive(Clone, Copy, Debug)]
pub struct DuffF64 {
    o: DVec3,
    u: DVec3,
    v: DVec3,
}

impl Projection for DuffF64 {
    type P = DVec2;
    array_face!(DVec2);
    const NAME: &'static str = "f64";
    fn flat(p: &[DVec2; 3]) -> bool {
        flat_2d(*p)
    }
    fn setup(ray: &Ray) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        DuffF64 {
            o: ray.origin.as_dvec3(),
            u,
            v,
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> DVec2 {
        let q = p.as_dvec3() - self.o;
        DVec2::new(self.u.dot(q), self.v.dot(q))
    }
    #[inline(always)]
    fn left(&self, a: DVec2, ia: u32, b: DVec2, ib: u32) -> bool {
        left_2d!(a, ia, b, ib)
    }
}

/// 3-D scalar triple products (Lagae & Dutré): a vertex maps to `q = P − o`
/// and the ray passes left of edge `a → b` when `d · (qa × qb) > 0`
/// (= `det(pa, pb)` up to a positive factor). `a × b = −(b × a)`
/// component-wise exactly, so the product is exactly antisymmetric. Zero is
/// decided as in 2-D by perturbing the origin by `ε u + ε² v` (`u, v` the
/// Duff basis): first `sign((qa − qb) · v)`, then `sign((qb − qa) · u)`, then
/// the vertex indices (`a < b` ⇒ left), each antisymmetric.
#[derive(Clone, Copy, Debug, Default)]
pub struct TripleF32 {
    o: Vec3,
    d: Vec3,
    u: Vec3,
    v: Vec3,
}

impl TripleF32 {
    /// The ray's origin and direction (for the SIMD lockstep walk).
    pub(crate) fn origin_direction(&self) -> (Vec3, Vec3) {
        (self.o, self.d)
    }

    #[cold]
    #[inline(never)]
    pub(crate) fn left_mask_ties(&self, pd: Vec3, d: u32, f: &[Vec3; 3], ids: &[u32; 3]) -> usize {
        self.left(pd, d, f[0], ids[0]) as usize
            | (self.left(pd, d, f[1], ids[1]) as usize) << 1
            | (self.left(pd, d, f[2], ids[2]) as usize) << 2
    }
}

impl Projection for TripleF32 {
    type P = Vec3;
    array_face!(Vec3, no_mask);
    /// The three triple products first, branch-free; the tie rule of
    /// [`TripleF32::left`] only when one of them is zero (same products, so
    /// the same bits as three `left` calls).
    #[inline(always)]
    fn left_mask(&self, pd: Vec3, d: u32, f: &[Vec3; 3], ids: &[u32; 3]) -> usize {
        let s = f.map(|p| self.d.dot(pd.cross(p)));
        if (s[0] != 0.0) & (s[1] != 0.0) & (s[2] != 0.0) {
            (s[0] > 0.0) as usize | ((s[1] > 0.0) as usize) << 1 | ((s[2] > 0.0) as usize) << 2
        } else {
            self.left_mask_ties(pd, d, f, ids)
        }
    }
    const NAME: &'static str = "f32-stp";
    fn setup(ray: &Ray) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        TripleF32 {
            o: ray.origin,
            d: ray.direction,
            u: u.as_vec3(),
            v: v.as_vec3(),
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> Vec3 {
        p - self.o
    }
    #[inline(always)]
    fn left(&self, a: Vec3, ia: u32, b: Vec3, ib: u32) -> bool {
        let s = self.d.dot(a.cross(b));
        if s != 0.0 {
            return s > 0.0;
        }
        let e = a - b;
        let y = e.dot(self.v);
        if y != 0.0 {
            return y > 0.0;
        }
        let x = e.dot(self.u);
        if x != 0.0 { x < 0.0 } else { ia < ib }
    }
}
