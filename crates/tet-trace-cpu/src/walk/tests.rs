//! Unit tests of the edge test, the tie rule, Algorithm 1's table and the basis.

use glam::{DVec2, DVec3, Vec2, Vec3};

use super::*;
use crate::ray::Ray;
use tet_core::synthetic::SplitMix64;

fn rnd(rng: &mut SplitMix64) -> f32 {
    // Wide dynamic range, with exact repeats and zeros.
    match rng.next_u64() % 8 {
        0 => 0.0,
        1 => 1.0,
        _ => rng.range_f32(-1.0, 1.0) * 2f32.powi((rng.next_u64() % 20) as i32 - 10),
    }
}

#[test]
fn edge_test_is_exactly_antisymmetric_with_ties() {
    let mut rng = SplitMix64(3);
    let ray = Ray::new(Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.3, -0.5, 0.8));
    let p32 = DuffF32::setup(&ray);
    let p64 = DuffF64::setup(&ray);
    let pt = TripleF32::setup(&ray);
    for i in 0..20000u32 {
        let a = Vec2::new(rnd(&mut rng), rnd(&mut rng));
        let b = if i % 3 == 0 {
            a * 2.0
        } else {
            Vec2::new(rnd(&mut rng), rnd(&mut rng))
        };
        assert_ne!(p32.left(a, 1, b, 2), p32.left(b, 2, a, 1), "{a:?} {b:?}");
        let (ad, bd) = (a.as_dvec2(), b.as_dvec2());
        assert_ne!(p64.left(ad, 1, bd, 2), p64.left(bd, 2, ad, 1));
        let a3 = Vec3::new(a.x, a.y, rnd(&mut rng));
        let b3 = if i % 5 == 0 {
            a3
        } else {
            Vec3::new(b.x, b.y, rnd(&mut rng))
        };
        assert_ne!(pt.left(a3, 7, b3, 9), pt.left(b3, 9, a3, 7));
    }
}

#[test]
fn tie_rule_matches_a_perturbed_origin() {
    // det = 0 with a.y > b.y: the origin moved by (ε, ε²) is left of a→b.
    let p = DuffF32::setup(&Ray::new(Vec3::ZERO, Vec3::Z));
    let (a, b) = (Vec2::new(0.0, 1.0), Vec2::new(0.0, -1.0));
    let eps = 1e-3f64;
    let exact = (b.x as f64 - a.x as f64) * (eps * eps - a.y as f64)
        - (b.y as f64 - a.y as f64) * (eps - a.x as f64);
    assert_eq!(p.left(a, 5, b, 6), exact > 0.0);
}

#[test]
fn exit_table_is_algorithm_1() {
    for (i, &slot) in EXIT_SLOT.iter().enumerate() {
        let (sa, sb, sc) = (i & 1 != 0, i & 2 != 0, i & 4 != 0);
        let alg1 = if sa {
            if sb { 0 } else { 2 }
        } else if sc {
            1
        } else {
            0
        };
        assert_eq!(slot as usize, alg1, "case {i}");
    }
}

#[test]
fn basis_is_right_handed_around_the_direction() {
    let mut rng = SplitMix64(8);
    for _ in 0..1000 {
        let d = crate::reference::random_direction(&mut rng)
            .as_dvec3()
            .normalize();
        let (u, v) = duff_basis(d);
        assert!((u.cross(v) - d).length() < 1e-9);
        assert!(u.dot(d).abs() < 1e-12 && v.dot(d).abs() < 1e-12);
    }
    for d in [DVec3::Z, -DVec3::Z, DVec3::X, -DVec3::Y] {
        let (u, v) = duff_basis(d);
        assert!((u.cross(v) - d).length() < 1e-12);
    }
}

/// A zero rounded determinant that hides a non-zero exact one is decided
/// by the exact sign (the tie rule's first step), checked against integer
/// arithmetic: integer coordinates `B + δ` (B = 24,576, below 2²⁴, exact
/// in f32) have products near 2²⁹ that f32 rounds to multiples of 64,
/// and with `δ_ax + δ_by = δ_ay + δ_bx` the exact determinant is the
/// small `δ_ax·δ_by − δ_ay·δ_bx` (exact in i64).
#[test]
fn zero_rounded_determinants_take_the_exact_sign() {
    let p32 = DuffF32::setup(&Ray::new(Vec3::ZERO, Vec3::Z));
    let p64 = DuffF64::setup(&Ray::new(Vec3::ZERO, Vec3::Z));
    let mut rng = SplitMix64(11);
    let mut hidden = 0;
    for _ in 0..20_000 {
        let c = |rng: &mut SplitMix64| (rng.next_u64() % 8) as i64;
        let (dax, dby, day) = (c(&mut rng), c(&mut rng), c(&mut rng));
        let base = 24_576i64;
        let (ax, by, ay) = (base + dax, base + dby, base + day);
        let bx = base + dax + dby - day;
        let exact = ax * by - ay * bx;
        let (a, b) = (
            Vec2::new(ax as f32, ay as f32),
            Vec2::new(bx as f32, by as f32),
        );
        let rounded = a.x * b.y - a.y * b.x;
        if rounded != 0.0 || exact == 0 {
            continue;
        }
        hidden += 1;
        assert_eq!(p32.left(a, 1, b, 2), exact > 0, "{a:?} {b:?}");
        assert_eq!(p32.left(b, 2, a, 1), exact < 0, "{a:?} {b:?}");
    }
    assert!(hidden > 100, "only {hidden} hidden signs drawn");
    // f64: integers 2⁴⁰ + δ (exact), whose products (about 2⁸⁰) round to
    // multiples of 2²⁸; with δ_ax + δ_by = δ_ay + δ_bx the exact
    // determinant is δ_ax·δ_by − δ_ay·δ_bx (below 2²⁴), exact in i128.
    let mut hidden = 0;
    for _ in 0..20_000 {
        let c = |rng: &mut SplitMix64| (rng.next_u64() % 4096) as i64;
        let (dax, dby, day) = (c(&mut rng), c(&mut rng), c(&mut rng));
        let dbx = dax + dby - day;
        let base = 1i64 << 40;
        let (ax, by, ay, bx) = (base + dax, base + dby, base + day, base + dbx);
        let exact = ax as i128 * by as i128 - ay as i128 * bx as i128;
        let (a, b) = (
            DVec2::new(ax as f64, ay as f64),
            DVec2::new(bx as f64, by as f64),
        );
        if a.x * b.y - a.y * b.x != 0.0 || exact == 0 {
            continue;
        }
        hidden += 1;
        assert_eq!(p64.left(a, 1, b, 2), exact > 0, "{a:?} {b:?}");
        assert_eq!(p64.left(b, 2, a, 1), exact < 0, "{a:?} {b:?}");
    }
    assert!(hidden > 100, "only {hidden} hidden signs drawn");
}
