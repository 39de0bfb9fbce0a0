//! The lots of a city block and the rectangles of their buildings: roofs,
//! outer walls, walls between lots of different heights, floor stripes.

use tet_core::synthetic::SplitMix64;

use super::faces::Rect;

/// A lot: one building's footprint, height and floor stripes (`floor`
/// units apart; 0 for none).
#[derive(Clone, Copy, Debug)]
pub(super) struct Lot {
    x: (i32, i32),
    z: (i32, i32),
    h: i32,
    floor: i32,
}

/// Column widths of a block (along x), in units.
const COLUMN: (i32, i32) = (3, 8);
/// Lot depths within a column (along z).
const LOT: (i32, i32) = (3, 8);

/// A random integer in `lo..=hi`.
pub(super) fn pick(rng: &mut SplitMix64, (lo, hi): (i32, i32)) -> i32 {
    lo + (rng.next_u64() % (hi - lo + 1) as u64) as i32
}

/// True with probability `p`.
fn chance(rng: &mut SplitMix64, p: f64) -> bool {
    rng.next_f64() < p
}

/// The lots of the block `x × z`, column by column: columns 3 to 8 units
/// wide, lots 3 to 8 deep, heights from a base of the block plus 0 to 7
/// (8 % towers 8 to 40 higher; 30 % as high as the lot before them),
/// half with floor stripes 2 to 4 units apart. A column's cuts avoid its
/// left neighbour's, so that no four lots share a corner.
pub(super) fn lots(rng: &mut SplitMix64, x: (i32, i32), z: (i32, i32)) -> Vec<Vec<Lot>> {
    let base = pick(rng, (2, 8));
    let mut columns: Vec<Vec<Lot>> = Vec::new();
    let mut x0 = x.0;
    while x0 < x.1 {
        let mut x1 = x0 + pick(rng, COLUMN);
        if x.1 - x1 < COLUMN.0 {
            x1 = x.1;
        }
        let previous: Vec<i32> = columns
            .last()
            .map(|c| c.iter().skip(1).map(|l| l.z.0).collect())
            .unwrap_or_default();
        let mut column: Vec<Lot> = Vec::new();
        let mut z0 = z.0;
        while z0 < z.1 {
            let mut z1 = z0 + pick(rng, LOT);
            if previous.contains(&z1) {
                z1 += 1;
            }
            if z.1 - z1 < LOT.0 {
                z1 = z.1;
            }
            let mut h = base + pick(rng, (0, 7));
            if chance(rng, 0.08) {
                h += pick(rng, (8, 40));
            }
            if let Some(prev) = column.last().filter(|_| chance(rng, 0.3)) {
                h = prev.h;
            }
            let floor = if chance(rng, 0.5) {
                pick(rng, (2, 4))
            } else {
                0
            };
            column.push(Lot {
                x: (x0, x1),
                z: (z0, z1),
                h,
                floor,
            });
            z0 = z1;
        }
        columns.push(column);
        x0 = x1;
    }
    columns
}

/// Walls in the plane `p[axis] = c` over `ranges`, cut into stripes at
/// the multiples of `floor` (none for 0) strictly inside its `y` range.
fn walls(
    rects: &mut Vec<Rect>,
    axis: usize,
    c: i32,
    ranges: [(i32, i32); 3],
    out: i32,
    floor: i32,
) {
    let (y0, y1) = ranges[1];
    let mut cuts = vec![y0];
    if floor > 0 {
        let mut y = (y0 / floor + 1) * floor;
        while y < y1 {
            cuts.push(y);
            y += floor;
        }
    }
    cuts.push(y1);
    for w in cuts.windows(2) {
        let mut r = ranges;
        r[1] = (w[0], w[1]);
        rects.push(Rect::new(axis, c, r, out));
    }
}

/// The wall between lot `a` (below `c` along `axis`) and lot `b` (above
/// it) over `ranges`: from the lower roof to the higher, facing the lower
/// lot, striped as the taller building is; none where they are equally
/// high.
fn party_wall(
    rects: &mut Vec<Rect>,
    axis: usize,
    c: i32,
    mut ranges: [(i32, i32); 3],
    a: &Lot,
    b: &Lot,
) {
    if a.h == b.h {
        return;
    }
    let (tall, low, out) = if a.h > b.h { (a, b, 1) } else { (b, a, -1) };
    ranges[1] = (low.h, tall.h);
    walls(rects, axis, c, ranges, out, tall.floor);
}

/// Every rectangle of the block `x × z` built on `columns`: roofs, the
/// outer walls from the ground up, the walls between lots.
pub(super) fn block_rects(
    columns: &[Vec<Lot>],
    x: (i32, i32),
    z: (i32, i32),
    rects: &mut Vec<Rect>,
) {
    for column in columns {
        for (k, lot) in column.iter().enumerate() {
            let up = (0, lot.h);
            rects.push(Rect::new(1, lot.h, [lot.x, up, lot.z], 1));
            if lot.x.0 == x.0 {
                walls(rects, 0, x.0, [up, up, lot.z], -1, lot.floor);
            }
            if lot.x.1 == x.1 {
                walls(rects, 0, x.1, [up, up, lot.z], 1, lot.floor);
            }
            if lot.z.0 == z.0 {
                walls(rects, 2, z.0, [lot.x, up, up], -1, lot.floor);
            }
            if lot.z.1 == z.1 {
                walls(rects, 2, z.1, [lot.x, up, up], 1, lot.floor);
            }
            if let Some(next) = column.get(k + 1) {
                party_wall(rects, 2, lot.z.1, [lot.x, up, up], lot, next);
            }
        }
    }
    for pair in columns.windows(2) {
        let c = pair[0][0].x.1;
        for a in &pair[0] {
            for b in &pair[1] {
                let (lo, hi) = (a.z.0.max(b.z.0), a.z.1.min(b.z.1));
                if lo < hi {
                    party_wall(rects, 0, c, [(c, c), (0, 0), (lo, hi)], a, b);
                }
            }
        }
    }
}
