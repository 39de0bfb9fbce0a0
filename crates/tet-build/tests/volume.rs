//! Volumes for isosurface tracing: split grids against independent counts
//! and exact volumes, the Kuhn split against tet-core's `kuhn_grid`, field
//! formulas at hand-computed points, C60's geometry, the named volumes'
//! sizes.

use std::collections::HashSet;

use glam::{DVec3, Vec3};
use tet_build::volume::{
    AnalyticField, GridVolume, Split, VolumeError, VolumeOptions, attach_field, attach_time_series,
    c60_vertices, grid_mesh, synthetic_volume, synthetic_volume_info, synthetic_volume_names,
};
use tet_core::predicates::orient3d;
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_core::{MeshError, TetMesh};

/// Checks what every split grid must satisfy: valid, counts, no constrained
/// faces, total volume = box volume (exact orient3d / 6), conforming
/// (boundary faces = 2 per boundary square: a mismatched diagonal would
/// leave unlinked interior faces).
fn check_grid(spec: &GridVolume) -> TetMesh {
    let m = grid_mesh(spec).unwrap();
    m.validate().unwrap();
    let [nx, ny, nz] = spec.cells.map(u64::from);
    assert_eq!(
        m.tets.len() as u64,
        nx * ny * nz * spec.split.tets_per_box()
    );
    assert_eq!(m.points.len() as u64, (nx + 1) * (ny + 1) * (nz + 1));
    assert!(m.constrained.is_empty());
    let volume: f64 = (0..m.tets.len() as u32)
        .map(|t| {
            let p = m.tet_points(t).map(|v| v.as_dvec3());
            orient3d(p[0], p[1], p[2], p[3]) / 6.0
        })
        .sum();
    let size = (spec.hi - spec.lo).as_dvec3();
    let expected = size.x * size.y * size.z;
    assert!(
        (volume - expected).abs() < 1e-9 * expected.max(1.0),
        "{volume} vs {expected}"
    );
    let boundary = m
        .neighbors
        .iter()
        .flatten()
        .filter(|l| l.is_boundary())
        .count() as u64;
    assert_eq!(boundary, 2 * 2 * (nx * ny + ny * nz + nx * nz));
    m
}

#[test]
fn five_and_six_splits_are_valid_conforming_and_fill_the_box() {
    for split in [Split::Five, Split::Six] {
        for cells in [[1, 1, 1], [2, 3, 4], [3, 3, 3]] {
            check_grid(&GridVolume::new(
                cells,
                Vec3::new(-1.0, 0.5, 2.0),
                Vec3::new(1.0, 0.75, 5.0),
                split,
            ));
        }
    }
}

#[test]
fn six_split_is_the_kuhn_grid_of_tet_core() {
    let cells = [3, 2, 4];
    let ours = check_grid(&GridVolume::new(
        cells,
        Vec3::ZERO,
        Vec3::new(3.0, 2.0, 4.0),
        Split::Six,
    ));
    let kuhn = kuhn_grid(&GridSpec {
        cells,
        jitter: 0.0,
        ..GridSpec::default()
    });
    assert_eq!(ours.points, kuhn.points);
    let sorted = |m: &TetMesh| {
        let mut t: Vec<[u32; 4]> = m
            .tets
            .iter()
            .map(|t| {
                let mut t = *t;
                t.sort_unstable();
                t
            })
            .collect();
        t.sort_unstable();
        t
    };
    assert_eq!(sorted(&ours), sorted(&kuhn));
}

#[test]
fn bad_grids_are_typed_errors() {
    let bad = |cells, lo, hi| grid_mesh(&GridVolume::new(cells, lo, hi, Split::Five));
    assert!(matches!(
        bad([0, 1, 1], Vec3::ZERO, Vec3::ONE),
        Err(VolumeError::BadParameter { what: "cells", .. })
    ));
    assert!(matches!(
        bad([1, 1, 1], Vec3::ONE, Vec3::ZERO),
        Err(VolumeError::BadParameter { what: "domain", .. })
    ));
    assert!(matches!(
        bad([2000, 2000, 2000], Vec3::ZERO, Vec3::ONE),
        Err(VolumeError::BadParameter { what: "cells", .. })
    ));
}

#[test]
fn field_formulas_at_hand_computed_points() {
    let lin = AnalyticField::Linear {
        gradient: DVec3::new(1.0, 2.0, 3.0),
        offset: -1.0,
    };
    assert_eq!(lin.eval(DVec3::new(1.0, 1.0, 1.0), 0.0), 5.0);
    // Marschner–Lobb at the centre: r = 0, ρ_r = cos(12π) = 1:
    // (1 − sin 0 + 0.25 · 2) / 2.5 = 0.6; at (0, 0, 1): (1 − 1 + 0.5) / 2.5.
    let ml = AnalyticField::marschner_lobb(Vec3::splat(-1.0), Vec3::ONE);
    assert!((ml.eval(DVec3::ZERO, 0.0) - 0.6).abs() < 1e-12);
    assert!((ml.eval(DVec3::Z, 0.0) - 0.2).abs() < 1e-12);
    let ell = AnalyticField::Ellipsoid {
        center: DVec3::ZERO,
        radii: DVec3::new(2.0, 1.0, 0.5),
    };
    assert_eq!(ell.eval(DVec3::new(2.0, 0.0, 0.0), 0.0), 1.0);
    assert_eq!(ell.eval(DVec3::new(0.0, 0.0, 0.25), 0.0), 0.25);
    let g = AnalyticField::Gaussians {
        centers: vec![DVec3::ZERO],
        sigma: 0.5,
        weight: 2.0,
    };
    assert!((g.eval(DVec3::X * 0.5, 0.0) - 2.0 * (-0.5f64).exp()).abs() < 1e-12);
    let moving = AnalyticField::MovingGaussian {
        center: DVec3::ZERO,
        radius: 0.5,
        sigma: 0.1,
        wave: 0.0,
        wave_vector: DVec3::X,
    };
    // The blob is at (0.5, 0, 0) at t = 0 and at (0, 0.5, 0) at t = 1/4.
    assert!((moving.eval(DVec3::X * 0.5, 0.0) - 1.0).abs() < 1e-12);
    assert!((moving.eval(DVec3::Y * 0.5, 0.25) - 1.0).abs() < 1e-12);
    assert!(moving.eval(DVec3::Y * 0.5, 0.0) < 1e-5);
}

#[test]
fn c60_is_a_truncated_icosahedron() {
    let v = c60_vertices();
    assert_eq!(v.len(), 60);
    let distinct: HashSet<[u64; 3]> = v.iter().map(|p| p.to_array().map(f64::to_bits)).collect();
    assert_eq!(distinct.len(), 60);
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let r = (9.0 * phi + 10.0).sqrt(); // circumradius at edge length 2
    for (i, p) in v.iter().enumerate() {
        assert!((p.length() - r).abs() < 1e-12, "vertex {i}");
        let edges = v
            .iter()
            .filter(|q| (q.distance(*p) - 2.0).abs() < 1e-9)
            .count();
        assert_eq!(edges, 3, "vertex {i} has 3 neighbours at edge length 2");
    }
}

#[test]
fn attach_field_evaluates_every_point_and_rejects_non_finite() {
    let mut m = grid_mesh(&GridVolume::new(
        [2, 2, 2],
        Vec3::ZERO,
        Vec3::ONE,
        Split::Five,
    ))
    .unwrap();
    attach_field(&mut m, "x+2y", |p| p.x + 2.0 * p.y).unwrap();
    let f = m.attributes.scalars.as_ref().unwrap();
    assert_eq!(f.steps.len(), 1);
    for (p, v) in m.points.iter().zip(&f.steps[0]) {
        assert_eq!(*v, p.x + 2.0 * p.y);
    }
    m.validate().unwrap();
    attach_time_series(&mut m, "t", 3, |p, t| p.z * t as f32).unwrap();
    let f = m.attributes.scalars.as_ref().unwrap();
    assert_eq!(f.steps.len(), 3);
    assert_eq!(f.steps[2][m.points.len() - 1], 2.0);
    let before = m.clone();
    let err = attach_field(&mut m, "bad", |p| if p.x > 0.9 { f32::NAN } else { 0.0 });
    assert!(matches!(
        err,
        Err(VolumeError::NonFiniteValue { step: 0, .. })
    ));
    assert_eq!(m, before, "a failed attach leaves the mesh unchanged");
    assert!(matches!(
        attach_field(&mut m, &"n".repeat(65), |_| 0.0),
        Err(VolumeError::Mesh(MeshError::ScalarName { .. }))
    ));
}

#[test]
fn named_volumes_have_the_documented_sizes() {
    let names: Vec<&str> = synthetic_volume_names().iter().map(|(n, _)| *n).collect();
    assert_eq!(
        names,
        [
            "ell32p",
            "feok",
            "bucky",
            "blunt",
            "buckycube",
            "fusion",
            "linear",
            "marschner-lobb"
        ]
    );
    let small = VolumeOptions::default();
    let full = VolumeOptions {
        full: true,
        ..VolumeOptions::default()
    };
    let tets = |name, o: &VolumeOptions| synthetic_volume_info(name, o).unwrap().tet_count();
    // Counts computed by hand from the documented grids.
    assert_eq!(tets("ell32p", &small), 5 * 31 * 31 * 31);
    assert_eq!(tets("ell32p", &small), 148_955); // the paper's count, exactly
    assert_eq!(tets("feok", &small), 6 * 26 * 26 * 30);
    assert_eq!(tets("bucky", &small), 224_874); // the paper's count, exactly
    assert_eq!(tets("blunt", &small), 6 * 27 * 33 * 33);
    assert_eq!(tets("buckycube", &small), 8 * 176_418);
    assert_eq!(tets("buckycube", &full), 64 * 176_418);
    // Table 3's replications: n³ balls, the paper's counts within 0.5 %.
    for (n, paper) in [(1, 177_000.0), (2, 1_400_000.0), (4, 11_300_000.0)] {
        let o = VolumeOptions {
            replications: Some(n),
            ..VolumeOptions::default()
        };
        let info = synthetic_volume_info("buckycube", &o).unwrap();
        assert_eq!(info.tet_count(), u64::from(n * n * n) * 176_418);
        assert_eq!(info.paper_tets, Some(paper as u64));
        assert!(
            (info.tet_count() as f64 - paper).abs() / paper < 0.01,
            "{n}"
        );
    }
    for n in [0, 9] {
        let o = VolumeOptions {
            replications: Some(n),
            ..VolumeOptions::default()
        };
        assert!(matches!(
            synthetic_volume_info("buckycube", &o),
            Err(VolumeError::BadParameter {
                what: "replications",
                ..
            })
        ));
    }
    assert_eq!(tets("fusion", &small), 300_000);
    assert_eq!(tets("fusion", &full), 3_000_000);
    assert_eq!(synthetic_volume_info("fusion", &small).unwrap().steps, 16);
    assert_eq!(synthetic_volume_info("fusion", &full).unwrap().steps, 116);
    // Within 0.5 % of the paper where it has a count.
    for name in ["ell32p", "feok", "bucky", "blunt"] {
        let info = synthetic_volume_info(name, &small).unwrap();
        let paper = info.paper_tets.unwrap() as f64;
        assert!(
            (info.tet_count() as f64 - paper).abs() / paper < 0.005,
            "{name}"
        );
    }
    assert!(matches!(
        synthetic_volume("nope", &small),
        Err(VolumeError::UnknownName { .. })
    ));
}

#[test]
fn linear_volume_is_built_with_its_field() {
    let m = synthetic_volume("linear", &VolumeOptions::default()).unwrap();
    m.validate().unwrap();
    assert_eq!(m.tets.len(), 24_576);
    let f = m.attributes.scalars.as_ref().unwrap();
    for (p, v) in m.points.iter().zip(&f.steps[0]) {
        let exact = 0.5 * f64::from(p.x) + 0.25 * f64::from(p.y) + 0.125 * f64::from(p.z);
        assert_eq!(*v, exact as f32);
    }
    // A time series with a chosen step count.
    let opts = VolumeOptions {
        steps: Some(3),
        ..VolumeOptions::default()
    };
    let info = synthetic_volume_info("fusion", &opts).unwrap();
    assert_eq!(info.steps, 3);
}

#[test]
#[ignore = "builds the paper-sized volumes (seconds in release, longer in debug)"]
fn paper_sized_volumes_build_and_validate() {
    for name in [
        "ell32p",
        "feok",
        "bucky",
        "blunt",
        "fusion",
        "marschner-lobb",
        "buckycube",
    ] {
        let start = std::time::Instant::now();
        let m = synthetic_volume(name, &VolumeOptions::default()).unwrap();
        println!(
            "{name}: {} tets, {} points, built and validated in {:.2} s",
            m.tets.len(),
            m.points.len(),
            start.elapsed().as_secs_f64()
        );
        let info = synthetic_volume_info(name, &VolumeOptions::default()).unwrap();
        assert_eq!(m.tets.len() as u64, info.tet_count());
        let f = m.attributes.scalars.as_ref().unwrap();
        assert_eq!(f.steps.len(), info.steps);
        let (lo, hi) = f.range().unwrap();
        assert!(
            lo < info.isovalue && info.isovalue < hi,
            "{name}: isovalue inside the range"
        );
    }
}

#[test]
#[ignore = "builds the 11.3 M-tet bucky cube and the 3 M-tet x 116-step fusion volume (GBs of memory)"]
fn full_size_volumes_build() {
    let full = VolumeOptions {
        full: true,
        ..VolumeOptions::default()
    };
    for name in ["buckycube", "fusion"] {
        let start = std::time::Instant::now();
        let m = synthetic_volume(name, &full).unwrap();
        let info = synthetic_volume_info(name, &full).unwrap();
        assert_eq!(m.tets.len() as u64, info.tet_count());
        let f = m.attributes.scalars.as_ref().unwrap();
        assert_eq!(f.steps.len(), info.steps);
        println!(
            "{name} (full): {} tets, {} points, {} steps, built and validated in {:.1} s",
            m.tets.len(),
            m.points.len(),
            f.steps.len(),
            start.elapsed().as_secs_f64()
        );
    }
}

#[test]
fn load_volume_reads_every_format_and_the_names() {
    use tet_build::volume::load_volume;
    let opts = VolumeOptions::default();
    let mut m = grid_mesh(&GridVolume::new(
        [2, 1, 1],
        Vec3::ZERO,
        Vec3::ONE,
        Split::Five,
    ))
    .unwrap();
    attach_time_series(&mut m, "f", 2, |p, t| p.x + t as f32).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let vtu = dir.path().join("m.vtu");
    tet_build::vtk::write_vtu(&vtu, &m).unwrap();
    assert_eq!(load_volume(vtu.to_str().unwrap(), &opts).unwrap(), m);
    let vtk = dir.path().join("m.vtk");
    tet_build::vtk::write_vtk(&vtk, &m, tet_build::vtk::VtkEncoding::Binary).unwrap();
    assert_eq!(load_volume(vtk.to_str().unwrap(), &opts).unwrap(), m);
    let tmesh = dir.path().join("m.tmesh");
    tet_core::format::save(&tmesh, &m).unwrap();
    assert_eq!(load_volume(tmesh.to_str().unwrap(), &opts).unwrap(), m);
    let base = dir.path().join("t");
    tet_build::tetgen_files::write(&base, &tet_build::tetgen_files::from_tet_mesh(&m)).unwrap();
    let from_tetgen = load_volume(dir.path().join("t.node").to_str().unwrap(), &opts).unwrap();
    assert_eq!(from_tetgen.tets, m.tets);
    assert_eq!(
        from_tetgen.attributes.scalars.as_ref().unwrap().steps,
        m.attributes.scalars.as_ref().unwrap().steps
    );
    assert_eq!(load_volume("linear", &opts).unwrap().tets.len(), 24_576);
    assert!(matches!(
        load_volume("no-such-volume", &opts),
        Err(VolumeError::UnknownName { .. })
    ));
    assert!(matches!(
        load_volume(dir.path().join("gone.vtu").to_str().unwrap(), &opts),
        Err(VolumeError::Vtk(tet_build::vtk::VtkError::Io { .. }))
    ));
}
