//! The built strips, decoded: coverage, vertex order, hierarchy bounds and
//! the documented byte sizes.

mod common;

use glam::Vec3;
use ray_strips::{BuildOptions, RayStrips, layout};

fn meshes() -> Vec<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let heights: Vec<f32> = (0..21 * 13)
        .map(|i| ((i * 7919) % 13) as f32 * 0.1)
        .collect();
    vec![
        common::icosphere(3, Vec3::new(0.3, -1.2, 2.0), 1.7),
        common::torus(24, 12, 2.0, 0.6, Vec3::ZERO),
        common::grid(20, 12, &heights),
    ]
}

/// Independent count of inner nodes by the split rule of the layout docs
/// (first part takes ⌈L/2⌉ pairs and the odd triangle).
fn inner_nodes(m: usize) -> usize {
    if m <= 3 {
        return 0;
    }
    let pairs = m / 2;
    let first = 2 * pairs.div_ceil(2) + m % 2;
    1 + inner_nodes(first) + inner_nodes(m - first)
}

#[test]
fn node_count_and_block_size_follow_the_formulas() {
    for n in 1..2000usize {
        let k = (n / 2).saturating_sub(1);
        assert_eq!(inner_nodes(n), k, "n = {n}");
        assert_eq!(layout::hierarchy_nodes(n), k);
        // Header, 2 floats per node, flag bytes in words, n + 2 indices,
        // n per-triangle words.
        for bits in [4, 20, 21, 32] {
            let words = 1 + 2 * k + k.div_ceil(4) + (n + 2) + (n * bits).div_ceil(32);
            assert_eq!(layout::strip_words(n, bits as u32), words, "n = {n}");
        }
    }
}

#[test]
fn every_triangle_is_in_exactly_one_strip_with_its_vertices_in_input_order() {
    for (chunk, strips_per_leaf, strip_swaps) in [
        (1, 1, false),
        (7, 1, true),
        (64, 3, false),
        (256, 1, false),
        (256, 8, true),
        (100_000, 1, true),
    ] {
        for (positions, triangles) in meshes() {
            let options = BuildOptions {
                chunk_triangles: chunk,
                strips_per_leaf,
                strip_swaps,
            };
            let rs = RayStrips::build(&positions, &triangles, &options).unwrap();
            let mut seen = vec![0u32; triangles.len()];
            for s in rs.strips() {
                assert_eq!(s.vertices.len(), s.triangles.len() + 2);
                let set = |j: usize| {
                    let mut a =
                        [s.vertices[j], s.vertices[j + 1], s.vertices[j + 2]].map(|p| p.to_array());
                    a.sort_by(|x, y| x.partial_cmp(y).unwrap());
                    a
                };
                for (j, &t) in s.triangles.iter().enumerate() {
                    let Some(t) = t else {
                        // A swap slot repeats a neighbouring triangle.
                        assert!(s.input_order[j].is_none());
                        let prev = j > 0 && set(j) == set(j - 1);
                        let next = j + 1 < s.triangles.len() && set(j) == set(j + 1);
                        assert!(prev || next, "swap slot {j} repeats no neighbour");
                        continue;
                    };
                    seen[t as usize] += 1;
                    let order = s.input_order[j].unwrap();
                    for k in 0..3 {
                        let input = positions[triangles[t as usize][k] as usize];
                        let stored = s.vertices[j + order[k] as usize];
                        assert_eq!(stored, input, "triangle {t} vertex {k} (chunk {chunk})");
                    }
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "chunk {chunk}: coverage");
            let stats = rs.stats();
            assert_eq!(stats.triangles, triangles.len());
            let slots: usize = rs.strips().iter().map(|s| s.triangles.len()).sum();
            assert_eq!(slots, stats.triangles + stats.swap_slots);
            assert!(stats.chunks >= triangles.len().div_ceil(chunk));
            let longest = rs
                .strips()
                .iter()
                .map(|s| s.triangles.iter().flatten().count())
                .max()
                .unwrap();
            assert!(longest <= chunk);
        }
    }
}

#[test]
fn hierarchy_planes_bound_their_children_and_the_leaf_box_bounds_the_strip() {
    for (positions, triangles) in meshes() {
        let rs = RayStrips::build(
            &positions,
            &triangles,
            &BuildOptions {
                chunk_triangles: 512,
                ..BuildOptions::default()
            },
        )
        .unwrap();
        for s in rs.strips() {
            let (lo, hi) = s.bounds;
            for p in &s.vertices {
                assert!(p.cmpge(lo).all() && p.cmple(hi).all());
            }
            // Vertices of triangles [t0, t0 + m) are [t0, t0 + m + 2).
            let coords = |(t0, m): (u32, u32), axis: usize| {
                s.vertices[t0 as usize..(t0 + m + 2) as usize]
                    .iter()
                    .map(move |p| p[axis])
            };
            let (slo, shi) = s.strip_bounds;
            assert!(
                slo.cmpge(lo).all() && shi.cmple(hi).all(),
                "strip box within the leaf"
            );
            for p in &s.vertices {
                assert!(
                    p.cmpge(slo).all() && p.cmple(shi).all(),
                    "strip box holds the strip"
                );
            }
            assert_eq!(s.nodes.len(), layout::hierarchy_nodes(s.triangles.len()));
            for node in &s.nodes {
                let (lower, upper) = if node.reverse {
                    (node.second, node.first)
                } else {
                    (node.first, node.second)
                };
                for c in coords(lower, node.axis) {
                    assert!(c <= node.lo, "lower child beyond lo");
                }
                for c in coords(upper, node.axis) {
                    assert!(c >= node.hi, "upper child below hi");
                }
                // The bounds are tight: some vertex lies on each plane.
                assert!(coords(lower, node.axis).any(|c| c == node.lo));
                assert!(coords(upper, node.axis).any(|c| c == node.hi));
                // The parts share the centre edge.
                assert_eq!(node.first.0 + node.first.1, node.second.0);
            }
        }
    }
}

#[test]
fn bytes_add_up_from_the_block_formula() {
    for (positions, triangles) in meshes() {
        for options in [
            BuildOptions::default(),
            BuildOptions {
                strips_per_leaf: 4,
                strip_swaps: true,
                ..BuildOptions::default()
            },
        ] {
            let rs = RayStrips::build(&positions, &triangles, &options).unwrap();
            let strips = rs.strips();
            let stats = rs.stats();
            let blocks: usize = strips
                .iter()
                .map(|s| 4 * layout::strip_words(s.triangles.len(), stats.triangle_word_bits))
                .sum();
            assert_eq!(strips.iter().map(|s| s.block_bytes).sum::<usize>(), blocks);
            let hierarchy: usize = strips
                .iter()
                .map(|s| {
                    let k = layout::hierarchy_nodes(s.triangles.len());
                    4 + 8 * k + 4 * k.div_ceil(4)
                })
                .sum();
            let b = rs.bytes();
            assert_eq!(b.hierarchy, hierarchy);
            assert_eq!(b.geometry, blocks - hierarchy + 12 * stats.vertices);
            assert_eq!(b.top_level, 32 * stats.top_level_nodes);
            assert_eq!(b.total, b.geometry + b.hierarchy + b.top_level);
            // A binary BVH over its leaves: 2 · leaves − 1 nodes; with one
            // strip per leaf, one leaf per strip.
            if options.strips_per_leaf == 1 {
                assert_eq!(stats.top_level_nodes, 2 * stats.strips - 1);
            } else {
                assert!(stats.top_level_nodes < 2 * stats.strips - 1);
            }
            assert_eq!(stats.vertices, positions.len());
        }
    }
}

/// The meshes moved and scaled to the extremes, plus a flat one (zero
/// extent on an axis).
fn extreme_meshes() -> Vec<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let mut out = Vec::new();
    for (positions, triangles) in meshes() {
        for (scale, offset) in [
            (1e-30f32, Vec3::ZERO),
            (1e30, Vec3::ZERO),
            (1e37, Vec3::ZERO),
            (1.0, Vec3::new(1e7, -3e6, 2e5)),
            (1e-3, Vec3::splat(1e4)),
        ] {
            let moved = positions.iter().map(|&p| p * scale + offset).collect();
            out.push((moved, triangles.clone()));
        }
    }
    let flat = vec![0.5f32; 13 * 9];
    out.push(common::grid(12, 8, &flat));
    out
}

#[test]
fn strip_boxes_hold_their_strips_at_any_scale_and_offset() {
    for (positions, triangles) in extreme_meshes() {
        for strips_per_leaf in [1, 4, 16] {
            let options = BuildOptions {
                strips_per_leaf,
                ..BuildOptions::default()
            };
            let rs = RayStrips::build(&positions, &triangles, &options).unwrap();
            let mut tighter = 0;
            for s in rs.strips() {
                let ((lo, hi), (slo, shi)) = (s.bounds, s.strip_bounds);
                assert!(slo.cmpge(lo).all() && shi.cmple(hi).all());
                for p in &s.vertices {
                    assert!(
                        p.cmpge(slo).all() && p.cmple(shi).all(),
                        "{p} outside the strip box {slo}..{shi}"
                    );
                }
                if strips_per_leaf == 1 {
                    assert_eq!((slo, shi), (lo, hi), "a leaf of one strip is its box");
                }
                tighter += usize::from((slo, shi) != (lo, hi));
            }
            if strips_per_leaf > 1 && rs.stats().strips > rs.stats().chunks {
                assert!(tighter > 0, "no strip box is tighter than its leaf");
            }
        }
    }
}

#[test]
fn strips_longer_than_a_header_can_name_are_cut() {
    // A 600 × 1 ribbon stripifies into one strip of 1200 triangles when
    // the chunk holds it all.
    let heights: Vec<f32> = (0..601 * 2).map(|i| (i % 7) as f32 * 0.01).collect();
    let (positions, triangles) = common::grid(600, 1, &heights);
    let rs = RayStrips::build(
        &positions,
        &triangles,
        &BuildOptions {
            chunk_triangles: 100_000,
            strips_per_leaf: 1,
            strip_swaps: false,
        },
    )
    .unwrap();
    let strips = rs.strips();
    assert!(
        strips
            .iter()
            .all(|s| s.triangles.len() <= layout::MAX_STRIP)
    );
    assert_eq!(rs.stats().max_strip_triangles, layout::MAX_STRIP);
    let mut seen = vec![0u32; triangles.len()];
    for s in &strips {
        for t in s.triangles.iter().flatten() {
            seen[*t as usize] += 1;
        }
    }
    assert!(seen.iter().all(|&c| c == 1));
    // Every cell is hit from above, in its own triangle.
    for x in 0..600 {
        let origin = Vec3::new(x as f32 + 0.7, 0.2, 5.0);
        let hit = rs
            .intersect(&ray_strips::Ray::new(origin, Vec3::NEG_Z))
            .unwrap();
        assert_eq!(hit.triangle, 2 * x, "cell {x}");
    }
}

#[test]
fn triangle_words_are_as_wide_as_the_largest_index_needs() {
    for (triangles, bits) in [
        (1, 4),
        (2, 4),
        (3, 5),
        (4, 5),
        (5, 6),
        (69_451, 20),
        (1 << 20, 23),
        ((1 << 20) + 1, 24),
    ] {
        assert_eq!(
            layout::triangle_word_bits(triangles),
            bits,
            "{triangles} triangles"
        );
    }
    for (positions, triangles) in meshes() {
        let rs = RayStrips::build(&positions, &triangles, &BuildOptions::default()).unwrap();
        assert_eq!(
            rs.stats().triangle_word_bits,
            layout::triangle_word_bits(triangles.len())
        );
    }
}
