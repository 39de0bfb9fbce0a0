//! Code shared by the examples.

use glam::Vec3;

/// Minimal OBJ reader: `v x y z` and `f a b c …` (fans; `a/b/c` and
/// negative indices accepted).
pub fn load_obj(path: &str) -> Option<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut v = Vec::new();
    let mut f = Vec::new();
    for line in text.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("v") => {
                let c: Vec<f32> = w.take(3).filter_map(|s| s.parse().ok()).collect();
                v.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let idx: Vec<u32> = w
                    .filter_map(|s| s.split('/').next()?.parse::<i64>().ok())
                    .map(|i| if i < 0 { v.len() as i64 + i } else { i - 1 } as u32)
                    .collect();
                for k in 1..idx.len().saturating_sub(1) {
                    f.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Some((v, f))
}

/// Seconds this thread has run on a CPU (Linux `schedstat`), so that
/// timings on a loaded machine count only our own time.
pub fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}

/// The examples' camera framing a mesh: `(eye, centre)`, the eye outside
/// the mesh's box at 2.4 box radii, above and to the right.
pub fn framing(positions: &[Vec3]) -> (Vec3, Vec3) {
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    (
        centre + Vec3::new(0.3, 0.25, 1.0).normalize() * radius * 2.4,
        centre,
    )
}
