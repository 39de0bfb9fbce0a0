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
