//! Finished parts kept across the retries of one build, so that a retry
//! runs TetGen only on the parts whose input changed.
//!
//! A tree build whose plane moves (a cut too near a point, or TetGen
//! failing on a part: [`super::tree::build_tree_with_memory_limit`])
//! used to build every part again: at 30 M triangles, 25 minutes lost for
//! one part. Moving one plane changes the parts on either side of it and,
//! through the traces its seam leaves on other walls, some parts beyond;
//! which ones is a property of the whole cut, so the cache does not
//! predict it: it compares each part's PLC as made, and a part whose PLC
//! is the same as in the attempt before is taken as it was then (TetGen
//! is deterministic on the same input and options, which do not change
//! between attempts).
//!
//! A PLC is compared by a [`PlcPrint`]: its facet and box-face counts and
//! two salted 64-bit digests (std's `DefaultHasher`, SipHash) of its facets (the exact f32 bits of every
//! corner, the facet's kind and scene triangle) and box faces. Two
//! different PLCs of the same part with the same print would need a
//! collision of both digests and both counts.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::Vec3;

use super::facet_faces::FacetKind;

/// What identifies a part's PLC (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct PlcPrint {
    facets: usize,
    box_faces: usize,
    digests: [u64; 2],
}

impl PlcPrint {
    /// The print of one part's PLC: its facets and box faces.
    pub(super) fn of(facets: &[([Vec3; 3], FacetKind)], box_faces: &[[Vec3; 3]]) -> PlcPrint {
        let mut digests = [0u64; 2];
        for (salt, d) in digests.iter_mut().enumerate() {
            // Fixed keys (the same for every `new` in a run), salted.
            let mut h = std::hash::DefaultHasher::new();
            salt.hash(&mut h);
            for (t, kind) in facets {
                for p in t {
                    p.to_array().map(f32::to_bits).hash(&mut h);
                }
                match kind {
                    FacetKind::Scene(s) => (0u8, *s).hash(&mut h),
                    FacetKind::Seam => (1u8, 0u32).hash(&mut h),
                }
            }
            for t in box_faces {
                for p in t {
                    p.to_array().map(f32::to_bits).hash(&mut h);
                }
            }
            *d = h.finish();
        }
        PlcPrint {
            facets: facets.len(),
            box_faces: box_faces.len(),
            digests,
        }
    }
}

/// Finished parts (what a merge keeps of each, `T`) by part index, with
/// the print of the PLC they were built from.
pub(super) struct PartCache<T> {
    kept: Mutex<HashMap<usize, (PlcPrint, T)>>,
    reused: AtomicUsize,
}

impl<T> Default for PartCache<T> {
    fn default() -> Self {
        PartCache {
            kept: Mutex::new(HashMap::new()),
            reused: AtomicUsize::new(0),
        }
    }
}

impl<T> PartCache<T> {
    /// Part `k` as kept, if its PLC then had the print `print`; a part
    /// kept from another PLC is dropped.
    pub(super) fn take(&self, k: usize, print: PlcPrint) -> Option<T> {
        let kept = self.lock().remove(&k)?;
        (kept.0 == print).then(|| {
            self.reused.fetch_add(1, Ordering::Relaxed);
            kept.1
        })
    }

    /// Keeps part `k`, built from a PLC with the print `print`.
    pub(super) fn keep(&self, k: usize, print: PlcPrint, part: T) {
        self.lock().insert(k, (print, part));
    }

    /// How many parts [`PartCache::take`] has handed back so far.
    pub(super) fn reused(&self) -> usize {
        self.reused.load(Ordering::Relaxed)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<usize, (PlcPrint, T)>> {
        self.kept.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The print of a PLC of one facet.
    fn print(corner: f32, kind: FacetKind) -> PlcPrint {
        PlcPrint::of(
            &[([Vec3::ZERO, Vec3::X, Vec3::new(0.0, corner, 0.0)], kind)],
            &[],
        )
    }

    /// The same PLC gives the same print; a corner one ulp away, another
    /// scene triangle or a seam facet instead gives another; a part is
    /// handed back once, and only for its own print.
    #[test]
    fn a_part_comes_back_only_for_the_same_plc() {
        let a = print(1.0, FacetKind::Scene(3));
        assert_eq!(a, print(1.0, FacetKind::Scene(3)));
        assert_ne!(a, print(1.0f32.next_up(), FacetKind::Scene(3)));
        assert_ne!(a, print(1.0, FacetKind::Scene(4)));
        assert_ne!(a, print(1.0, FacetKind::Seam));
        let cache = PartCache::default();
        cache.keep(2, a, "part 2");
        assert_eq!(cache.take(1, a), None);
        assert_eq!(cache.take(2, a), Some("part 2"));
        assert_eq!(cache.take(2, a), None, "handed back once");
        cache.keep(2, a, "part 2");
        let b = print(2.0, FacetKind::Scene(3));
        assert_eq!(cache.take(2, b), None, "another PLC");
        assert_eq!(cache.take(2, a), None, "dropped by the miss");
        assert_eq!(cache.reused(), 1);
    }
}
