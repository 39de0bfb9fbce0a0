//! Helpers shared by the out-of-core test binaries.

use glam::Vec3;
use tet_core::TetMesh;

/// Exact bits of a point.
pub fn bits(p: Vec3) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}

/// A tet by its vertices' bits in slot order.
pub type TetKey = [[u32; 3]; 4];

/// A constrained face: triangle, vertices (bits, rotated to start at the
/// smallest, winding kept), front and back (tet, face).
pub type FaceKey = (
    u32,
    [[u32; 3]; 3],
    Option<(TetKey, u32)>,
    Option<(TetKey, u32)>,
);

/// Sorted points, tets with what lies across each face, constrained faces.
pub type Canonical = (Vec<[u32; 3]>, Vec<(TetKey, [String; 4])>, Vec<FaceKey>);

/// The mesh in a form independent of the order of points, tets and
/// constrained faces (two merges of the same parts must agree on it):
/// sorted points, tets with what lies across each face, constrained faces
/// with their sides.
pub fn canonical(m: &TetMesh) -> Canonical {
    let tet = |t: u32| m.tets[t as usize].map(|v| bits(m.points[v as usize]));
    let face = |v: [u32; 3]| {
        let k = v.map(|i| bits(m.points[i as usize]));
        let r = (0..3).min_by_key(|&i| k[i]).unwrap();
        [k[r], k[(r + 1) % 3], k[(r + 2) % 3]]
    };
    let side = |s: tet_core::FaceSide| s.exists().then(|| (tet(s.tet), s.face));
    let mut points: Vec<[u32; 3]> = m.points.iter().map(|&p| bits(p)).collect();
    points.sort_unstable();
    let mut tets: Vec<(TetKey, [String; 4])> = (0..m.tets.len())
        .map(|t| {
            let links = m.neighbors[t].map(|l| {
                if let Some(u) = l.as_tet() {
                    format!("tet {:?}", tet(u))
                } else if let Some(c) = l.as_constrained() {
                    let f = &m.constrained[c as usize];
                    format!("face {} {:?}", f.triangle, face(f.vertices))
                } else {
                    "boundary".to_string()
                }
            });
            (tet(t as u32), links)
        })
        .collect();
    tets.sort_unstable();
    let mut faces: Vec<FaceKey> = m
        .constrained
        .iter()
        .map(|f| (f.triangle, face(f.vertices), side(f.front), side(f.back)))
        .collect();
    faces.sort_unstable();
    (points, tets, faces)
}

/// A TetGen worker script in `dir` that crashes (SIGSEGV) on every request
/// whose switches keep the surface with plain `-Y` (read from the
/// request's first bytes: `pYc`, not `pY/2c`), as TetGen does on a part
/// no wall position cures, and is the real worker `worker` otherwise;
/// each run adds a line, `Y` or `relaxed`, to the file returned second.
#[cfg(unix)]
#[allow(dead_code)] // not every test binary uses it
pub fn crashing_on_plain_y(
    dir: &std::path::Path,
    worker: &str,
) -> (std::path::PathBuf, std::path::PathBuf) {
    use std::os::unix::fs::PermissionsExt;
    let (script, runs) = (dir.join("no-y.sh"), dir.join("runs"));
    std::fs::write(
        &script,
        format!(
            "#!/bin/sh\nreq=$(mktemp)\ncat > \"$req\"\n\
             if head -c 64 \"$req\" | grep -q -a pYc; then\n\
             echo Y >> '{runs}'; rm -f \"$req\"; kill -SEGV $$\nfi\n\
             echo relaxed >> '{runs}'\n\
             '{worker}' \"$@\" < \"$req\"; rc=$?; rm -f \"$req\"; exit $rc\n",
            runs = runs.display(),
        ),
    )
    .unwrap();
    std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
    (script, runs)
}
