//! TetGen through the shim: good inputs, and bad inputs that must come back
//! as typed errors with the host process alive (crash-prone ones run in the
//! isolated worker).

#![cfg(feature = "tetgen")]

use std::path::{Path, PathBuf};
use std::time::Duration;

use tet_build::tetgen::{
    Isolation, TetgenError, TetgenInput, TetgenOptions, WorkerCommand, tetrahedralize,
};

fn worker(timeout_s: f64) -> Isolation {
    Isolation::Worker(WorkerCommand {
        program: env!("CARGO_BIN_EXE_tet-build-worker").into(),
        args: vec![],
        timeout: Some(Duration::from_secs_f64(timeout_s)),
    })
}

/// Unit cube surface: 8 corners, 12 triangles (outward winding).
fn cube(offset: [f64; 3], size: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut p = Vec::new();
    for i in 0..8u32 {
        p.push([
            offset[0] + size * (i & 1) as f64,
            offset[1] + size * ((i >> 1) & 1) as f64,
            offset[2] + size * ((i >> 2) & 1) as f64,
        ]);
    }
    let quads = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    let mut t = Vec::new();
    for q in quads {
        t.push([q[0], q[1], q[2]]);
        t.push([q[0], q[2], q[3]]);
    }
    (p, t)
}

/// Exact orientation in f64 (points here are small integers / halves).
fn orient(p: &[[f64; 3]], t: [u32; 4]) -> f64 {
    let [a, b, c, d] = t.map(|v| glam::DVec3::from_array(p[v as usize]));
    (b - a).cross(c - a).dot(d - a)
}

fn check_cube_mesh(out: &tet_build::tetgen::TetgenOutput, tris: &[[u32; 3]]) {
    assert_eq!(out.points.len(), 8, "-pY adds no Steiner point to a cube");
    // The tets fill the cube: |volumes| sum to 1, none flat.
    let total: f64 = out
        .tets
        .iter()
        .map(|&t| orient(&out.points, t).abs() / 6.0)
        .sum();
    assert!((total - 1.0).abs() < 1e-12, "volume {total}");
    let signs: Vec<bool> = out
        .tets
        .iter()
        .map(|&t| orient(&out.points, t) > 0.0)
        .collect();
    assert!(
        signs.iter().all(|&s| s == signs[0]),
        "one orientation convention"
    );
    // Every input triangle comes back as exactly one marked face.
    for (i, tri) in tris.iter().enumerate() {
        let mut key = *tri;
        key.sort_unstable();
        let hits: Vec<usize> = (0..out.faces.len())
            .filter(|&f| out.face_markers[f] == i as i32 + 1)
            .collect();
        assert_eq!(hits.len(), 1, "triangle {i}");
        let mut fk = out.faces[hits[0]];
        fk.sort_unstable();
        assert_eq!(fk, key);
    }
}

#[test]
fn cube_in_process_and_isolated_agree() {
    let (p, t) = cube([0.0; 3], 1.0);
    let input = TetgenInput::with_index_markers(p, t.clone());
    let options = TetgenOptions {
        neighbors: true,
        ..TetgenOptions::default()
    };
    let a = tetrahedralize(&input, &options, &Isolation::InProcess).unwrap();
    check_cube_mesh(&a, &t);
    let b = tetrahedralize(&input, &options, &worker(60.0)).unwrap();
    check_cube_mesh(&b, &t);
    assert_eq!(a.tets, b.tets);
    assert_eq!(a.neighbors, b.neighbors);
    assert!(b.worker_peak_kib.unwrap() > 0);
    // Neighbour k is opposite corner k: it shares the other three vertices.
    let n = a.neighbors.as_ref().unwrap();
    for (ti, tet) in a.tets.iter().enumerate() {
        for k in 0..4 {
            if n[ti][k] >= 0 {
                let other = a.tets[n[ti][k] as usize];
                for j in (0..4).filter(|&j| j != k) {
                    assert!(other.contains(&tet[j]));
                }
                assert!(!other.contains(&tet[k]));
            }
        }
    }
}

#[test]
fn nested_cubes_keep_both_surfaces() {
    let (mut p, mut t) = cube([0.0; 3], 4.0);
    let (p2, t2) = cube([1.0, 1.5, 1.25], 1.0);
    t.extend(t2.iter().map(|tri| tri.map(|v| v + 8)));
    p.extend(p2);
    let input = TetgenInput::with_index_markers(p, t.clone());
    let out = tetrahedralize(&input, &TetgenOptions::default(), &Isolation::InProcess).unwrap();
    let total: f64 = out
        .tets
        .iter()
        .map(|&q| orient(&out.points, q).abs() / 6.0)
        .sum();
    assert!((total - 64.0).abs() < 1e-9, "volume {total}");
    for i in 0..t.len() {
        let n = out
            .face_markers
            .iter()
            .filter(|&&m| m == i as i32 + 1)
            .count();
        assert_eq!(n, 1, "triangle {i}");
    }
}

/// Two triangles crossing each other (plus a box so TetGen has a volume).
fn crossing_pair() -> TetgenInput {
    let (mut p, mut t) = cube([-2.0; 3], 4.0);
    let base = p.len() as u32;
    p.extend([
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -0.5, -1.0],
        [0.0, 0.5, -1.0],
        [0.0, 0.0, 1.0],
    ]);
    t.push([base, base + 1, base + 2]);
    t.push([base + 3, base + 4, base + 5]);
    TetgenInput::with_index_markers(p, t)
}

#[test]
fn crossing_triangles_are_a_self_intersection_isolated() {
    let r = tetrahedralize(&crossing_pair(), &TetgenOptions::default(), &worker(60.0));
    assert_eq!(r, Err(TetgenError::SelfIntersection));
}

#[test]
fn crossing_triangles_are_a_self_intersection_in_process() {
    // With assertions compiled out and exceptions caught, TetGen's code 3
    // reaches us and this process survives.
    let r = tetrahedralize(
        &crossing_pair(),
        &TetgenOptions::default(),
        &Isolation::InProcess,
    );
    assert_eq!(r, Err(TetgenError::SelfIntersection));
}

#[test]
fn rejected_before_tetgen() {
    let (p, t) = cube([0.0; 3], 1.0);
    let opts = TetgenOptions::default();
    let run = |p: Vec<[f64; 3]>, t: Vec<[u32; 3]>| {
        tetrahedralize(
            &TetgenInput::with_index_markers(p, t),
            &opts,
            &Isolation::InProcess,
        )
    };
    assert_eq!(
        run(vec![], vec![]),
        Err(TetgenError::EmptyInput {
            points: 0,
            triangles: 0
        })
    );
    let mut bad = p.clone();
    bad[3][1] = f64::NAN;
    assert!(matches!(
        run(bad, t.clone()),
        Err(TetgenError::NonFinitePoint { point: 3, .. })
    ));
    let mut bad = p.clone();
    bad[5][2] = f64::INFINITY;
    assert!(matches!(
        run(bad, t.clone()),
        Err(TetgenError::NonFinitePoint { point: 5, .. })
    ));
    // Duplicate facet (same three vertices, other winding).
    let mut dup = t.clone();
    dup.push([t[4][2], t[4][1], t[4][0]]);
    assert_eq!(
        run(p.clone(), dup),
        Err(TetgenError::DuplicateTriangle {
            first: 4,
            second: 12,
            vertices: {
                let mut k = t[4];
                k.sort_unstable();
                k
            }
        })
    );
    // Degenerate: the midpoint of an edge makes a collinear triangle.
    let mut p2 = p.clone();
    p2.push([0.5, 0.0, 0.0]);
    let mut t2 = t.clone();
    t2.push([0, 1, 8]);
    assert_eq!(
        run(p2, t2),
        Err(TetgenError::DegenerateTriangle {
            triangle: 12,
            vertices: [0, 1, 8]
        })
    );
    let mut t3 = t.clone();
    t3.push([0, 0, 1]);
    assert_eq!(
        run(p.clone(), t3),
        Err(TetgenError::RepeatedVertex {
            triangle: 12,
            vertex: 0
        })
    );
    let mut t4 = t.clone();
    t4.push([0, 1, 99]);
    assert!(matches!(
        run(p.clone(), t4),
        Err(TetgenError::VertexOutOfRange {
            triangle: 12,
            vertex: 99,
            ..
        })
    ));
    // Flat input: every point on z = 0.
    let flat = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    assert_eq!(
        run(flat, vec![[0, 1, 2], [1, 3, 2]]),
        Err(TetgenError::FlatInput)
    );
    // Tilted plane x + y + z = 1 (exactly representable points): also flat.
    let tilted = vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.25, 0.25, 0.5],
    ];
    assert_eq!(
        run(tilted, vec![[0, 1, 2], [0, 3, 1]]),
        Err(TetgenError::FlatInput)
    );
}

#[test]
fn geometric_duplicate_facet_fails_cleanly_isolated() {
    // The same triangle twice through distinct (coincident) vertices: the
    // Rust pre-check cannot see it; TetGen must report an error, not crash.
    let (mut p, mut t) = cube([-2.0; 3], 4.0);
    let b = p.len() as u32;
    p.extend([[-1.0, -1.0, 0.1], [1.0, -1.0, 0.1], [0.0, 1.0, 0.1]]);
    p.extend([[-1.0, -1.0, 0.1], [1.0, -1.0, 0.1], [0.0, 1.0, 0.1]]);
    t.push([b, b + 1, b + 2]);
    t.push([b + 3, b + 4, b + 5]);
    let r = tetrahedralize(
        &TetgenInput::with_index_markers(p, t),
        &TetgenOptions::default(),
        &worker(60.0),
    );
    assert_eq!(r, Err(TetgenError::SelfIntersection));
}

fn near_parallel_pair(gap: f64) -> TetgenInput {
    let (mut p, mut t) = cube([-2.0; 3], 4.0);
    let b = p.len() as u32;
    p.extend([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]]);
    // The upper triangle is the lower one turned by 180°: their edges cross
    // in projection, so refinement squeezes tets between them.
    p.extend([[-1.0, 1.0, gap], [1.0, 1.0, gap], [0.0, -1.0, 2.0 * gap]]);
    t.push([b, b + 1, b + 2]);
    t.push([b + 3, b + 4, b + 5]);
    TetgenInput::with_index_markers(p, t)
}

#[test]
fn near_parallel_pair_with_quality_is_capped_by_steiner_limit() {
    // Two nearly parallel triangles 1e-6 apart inside a box: -q may refine
    // without end between them; -S caps the Steiner points.
    let options = TetgenOptions {
        quality: Some(1.1),
        max_steiner: Some(2000),
        preserve_surface: false,
        ..TetgenOptions::default()
    };
    // The cap counts the refinement's points only, not those the boundary
    // recovery adds (the same run without -q).
    let plain = TetgenOptions {
        quality: None,
        max_steiner: None,
        ..options.clone()
    };
    let recovered = tetrahedralize(&near_parallel_pair(1e-6), &plain, &Isolation::InProcess)
        .unwrap()
        .points
        .len();
    let start = std::time::Instant::now();
    let r = tetrahedralize(&near_parallel_pair(1e-6), &options, &worker(20.0));
    assert!(start.elapsed() < Duration::from_secs(25));
    match r {
        Ok(out) => assert!(
            out.points.len() <= recovered + 2000,
            "{} points, {recovered} before refinement",
            out.points.len()
        ),
        Err(e) => assert!(
            matches!(
                e,
                TetgenError::Timeout { .. } | TetgenError::CloseFacets | TetgenError::SmallFeature
            ),
            "{e}"
        ),
    }
}

#[test]
fn near_parallel_pair_with_uncapped_quality_returns_within_the_limit() {
    // Without -S (and without -Y, so TetGen may split the facets) -q keeps
    // refining between the two facets (observed: still running after 3 s,
    // while the capped run above takes milliseconds). The worker is killed
    // at the 3 s limit; a typed TetGen error would also be acceptable.
    let options = TetgenOptions {
        quality: Some(1.1),
        preserve_surface: false,
        ..TetgenOptions::default()
    };
    let start = std::time::Instant::now();
    let r = tetrahedralize(&near_parallel_pair(1e-7), &options, &worker(3.0));
    let took = start.elapsed();
    eprintln!(
        "uncapped -q: {:?} after {took:?}",
        r.as_ref().map(|o| o.points.len())
    );
    assert!(took < Duration::from_secs(8), "{took:?}");
    if let Err(e) = r {
        assert!(
            matches!(
                e,
                TetgenError::Timeout { .. } | TetgenError::CloseFacets | TetgenError::SmallFeature
            ),
            "{e}"
        );
    }
}

#[test]
fn hung_worker_is_killed_at_the_time_limit() {
    // A "worker" that never answers stands in for TetGen refining forever.
    let iso = Isolation::Worker(WorkerCommand {
        program: "sleep".into(),
        args: vec!["30".into()],
        timeout: Some(Duration::from_millis(300)),
    });
    let (p, t) = cube([0.0; 3], 1.0);
    let start = std::time::Instant::now();
    let r = tetrahedralize(
        &TetgenInput::with_index_markers(p, t),
        &TetgenOptions::default(),
        &iso,
    );
    assert!(matches!(r, Err(TetgenError::Timeout { .. })), "{r:?}");
    assert!(start.elapsed() < Duration::from_secs(5));
}

#[test]
fn crashed_worker_is_reported() {
    let iso = Isolation::Worker(WorkerCommand {
        program: "sh".into(),
        args: vec![
            "-c".into(),
            "cat >/dev/null; echo boom >&2; kill -SEGV $$".into(),
        ],
        timeout: Some(Duration::from_secs(10)),
    });
    let (p, t) = cube([0.0; 3], 1.0);
    let r = tetrahedralize(
        &TetgenInput::with_index_markers(p, t),
        &TetgenOptions::default(),
        &iso,
    );
    match r {
        Err(TetgenError::WorkerDied { status, stderr }) => {
            assert!(
                status.contains("signal") || status.contains("SIGSEGV"),
                "{status}"
            );
            assert!(stderr.contains("boom"));
        }
        other => panic!("{other:?}"),
    }
}

/// The build script's source locator, shared with `build.rs`.
#[path = "../build/locate.rs"]
mod locate;

/// The `cargo metadata` route of `build.rs` (used for vendored sources,
/// `[patch]`, or a registry outside `$CARGO_HOME`) finds the same TetGen
/// source as the registry route the normal build takes, and the version
/// pin it searches for is the workspace's.
#[test]
fn build_script_finds_tetgen_through_cargo_metadata_too() {
    let manifest_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let workspace = std::fs::read_to_string(manifest_dir.join("../../Cargo.toml")).unwrap();
    let pin = format!("tritet = {{ version = \"={}\"", locate::TRITET_VERSION);
    assert!(
        workspace.contains(&pin),
        "workspace Cargo.toml lacks `{pin}`"
    );
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let target = env!("TET_BUILD_TARGET");
    let via_metadata =
        locate::from_cargo_metadata(&cargo, &manifest_dir.join("Cargo.toml"), target).unwrap();
    assert!(locate::has_sources(&via_metadata), "{via_metadata:?}");
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
        .unwrap();
    if let Some(via_registry) = locate::from_registry(&home) {
        assert_eq!(
            via_registry.canonicalize().unwrap(),
            via_metadata.canonicalize().unwrap()
        );
    }
    // A manifest that does not exist is an error message, not a panic.
    let err = locate::from_cargo_metadata(&cargo, Path::new("/nonexistent/Cargo.toml"), target);
    assert!(err.unwrap_err().contains("cargo metadata failed"));
    // An empty registry directory finds nothing.
    let empty = tempfile::tempdir().unwrap();
    assert_eq!(locate::from_registry(empty.path()), None);
}

/// `-nn`: for every output face, one of the two tets TetGen lists has that
/// face (the other may be TetGen's unset hull-tet index on the convex hull),
/// and a face between two tets lists both, which are neighbours.
#[test]
fn face_tets_name_a_tet_with_the_face() {
    let (mut p, mut t) = cube([0.0; 3], 4.0);
    let (pi, ti) = cube([1.0, 1.5, 1.2], 1.0);
    let base = p.len() as u32;
    p.extend(pi);
    t.extend(ti.iter().map(|f| f.map(|v| v + base)));
    let input = TetgenInput::with_index_markers(p, t);
    let options = TetgenOptions {
        face_tets: true,
        ..TetgenOptions::default()
    };
    assert!(options.switches().contains("nn"));
    for isolation in [Isolation::InProcess, worker(60.0)] {
        let out = tetrahedralize(&input, &options, &isolation).unwrap();
        let face_tets = out.face_tets.as_ref().unwrap();
        let neighbors = out.neighbors.as_ref().unwrap();
        assert_eq!(face_tets.len(), out.faces.len());
        let has = |s: i32, f: [u32; 3]| {
            usize::try_from(s)
                .ok()
                .and_then(|s| out.tets.get(s))
                .is_some_and(|tet| f.iter().all(|v| tet.contains(v)))
        };
        let mut inner = 0;
        for (f, sides) in out.faces.iter().zip(face_tets) {
            assert!(has(sides[0], *f) || has(sides[1], *f), "{f:?} {sides:?}");
            if has(sides[0], *f) && has(sides[1], *f) {
                inner += 1;
                let (a, b) = (sides[0] as usize, sides[1] as usize);
                assert!(neighbors[a].contains(&(b as i32)) && neighbors[b].contains(&(a as i32)));
            }
        }
        // The inner cube's 12 triangles have tets on both sides.
        assert_eq!(inner, 12);
    }
}
