//! [`CubeTree`]: a compact static tree over axis-aligned cubes `p ± b` (a point and a
//! half-width each), for millions of small boxes where parry's BVH costs ≈ 400 B a box (the
//! input-plane fit's coverage samples). It keeps no copy of the points: the
//! caller passes the same slices to every query.
//!
//! Layout: the cube indices in Morton order of their points (4 B a cube), and a pyramid of
//! `f32` boxes rounded outward — one per run of [`LEAF`] consecutive cubes, then one per
//! [`FANOUT`] boxes of the level below — ≈ 3.4 B a cube. Queries answer exactly the cubes
//! whose `f64` box `(p − b, p + b)` meets the query box (the test `BoxTree` makes), since the
//! outward-rounded `f32` boxes only ever cull what no member can meet.
//!
//! May import: `crate::geom`.

use rayon::prelude::*;

use crate::geom::Vec3;

/// Cubes per leaf box.
pub(super) const LEAF: usize = 8;
/// Boxes of a level per box of the level above.
pub(super) const FANOUT: usize = 8;
/// Bits of a Morton code per axis.
const MORTON_BITS: u32 = 21;

/// A box with `f32` corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct BoxF32 {
    pub(super) lo: [f32; 3],
    pub(super) hi: [f32; 3],
}

impl BoxF32 {
    /// The smallest `f32` box containing the `f64` box `[lo, hi]`.
    pub(super) fn outward(lo: Vec3, hi: Vec3) -> BoxF32 {
        BoxF32 {
            lo: [down(lo.x), down(lo.y), down(lo.z)],
            hi: [up(hi.x), up(hi.y), up(hi.z)],
        }
    }

    /// The union of `boxes` (non-empty).
    pub(super) fn union(boxes: &[BoxF32]) -> BoxF32 {
        boxes[1..].iter().fold(boxes[0], |a, b| BoxF32 {
            lo: [0, 1, 2].map(|k| a.lo[k].min(b.lo[k])),
            hi: [0, 1, 2].map(|k| a.hi[k].max(b.hi[k])),
        })
    }

    /// Whether this box meets the closed `f64` box `[lo, hi]` (touching counts).
    pub(super) fn meets(&self, lo: Vec3, hi: Vec3) -> bool {
        let (ql, qh) = (lo.to_array(), hi.to_array());
        (0..3).all(|k| f64::from(self.lo[k]) <= qh[k] && ql[k] <= f64::from(self.hi[k]))
    }
}

/// The largest `f32` not above `x` (`f32::MAX` for finite `x` beyond it).
fn down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        step_down(y)
    } else {
        y
    }
}

/// The smallest `f32` not below `x` (`-f32::MAX` for finite `x` below it).
fn up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x {
        -step_down(-y)
    } else {
        y
    }
}

/// The next `f32` below `y` (`f32::next_down`, stable only since Rust 1.86; the MSRV is 1.85).
fn step_down(y: f32) -> f32 {
    if y.is_nan() || y == f32::NEG_INFINITY {
        y
    } else if y == 0.0 {
        -f32::from_bits(1)
    } else if y > 0.0 {
        f32::from_bits(y.to_bits() - 1)
    } else {
        f32::from_bits(y.to_bits() + 1)
    }
}

/// Whether the cube `p ± b` — corners computed as `p − (b, b, b)` and `p + (b, b, b)` — meets
/// the closed box `[lo, hi]` (touching counts; `false` when a comparison involves NaN): the test
/// [`CubeTree::overlapping`] answers.
pub fn cube_meets(p: Vec3, b: f64, lo: Vec3, hi: Vec3) -> bool {
    let r = Vec3::new(b, b, b);
    let (cl, ch) = (p - r, p + r);
    cl.x <= hi.x && cl.y <= hi.y && cl.z <= hi.z && lo.x <= ch.x && lo.y <= ch.y && lo.z <= ch.z
}

/// Reorders `points` in place into the order a [`CubeTree`] over them visits its cubes (Morton
/// order in their bounding box, ties by index), so that a tree built afterwards has its leaves
/// over consecutive points and queries read memory in sequence (faster). Only the
/// indices change: a tree over the reordered points answers the same cubes, in the same order,
/// under their new indices. Deterministic; in place (one byte a point beyond the order).
pub fn sort_in_tree_order(points: &mut [Vec3]) {
    let order = morton_order(points);
    let mut done = vec![false; points.len()];
    for start in 0..points.len() {
        if done[start] {
            continue;
        }
        // the cycle of the permutation `new[i] = old[order[i]]` through `start`
        let first = points[start];
        let mut i = start;
        loop {
            done[i] = true;
            let k = order[i] as usize;
            if k == start {
                points[i] = first;
                break;
            }
            points[i] = points[k];
            i = k;
        }
    }
}

/// A static tree over the cubes `points[k] ± half[k]` (module docs). Queries take `&self` and
/// may run concurrently.
pub struct CubeTree {
    /// Cube indices in Morton order of their points (ties by index).
    order: Vec<u32>,
    /// `levels[0]`: a box per run of [`LEAF`] entries of `order`; `levels[i + 1]`: a box per
    /// run of [`FANOUT`] boxes of `levels[i]`; the last level has one box (none when empty).
    levels: Vec<Vec<BoxF32>>,
}

impl CubeTree {
    /// Builds the tree over the cubes `points[k] ± half[k]` (equal lengths, below 2³²).
    /// Deterministic.
    pub fn new(points: &[Vec3], half: &[f64]) -> CubeTree {
        assert_eq!(points.len(), half.len(), "a half-width per point");
        assert!(points.len() <= u32::MAX as usize, "at most 2^32 cubes");
        let order = morton_order(points);
        let leaves: Vec<BoxF32> = order
            .par_chunks(LEAF)
            .map(|run| leaf_box(run, points, half))
            .collect();
        let levels = pyramid(leaves);
        CubeTree { order, levels }
    }

    /// The cubes (indices into the slices the tree was built from, which must be passed again)
    /// that meet the closed box `[lo, hi]`, touching counts — the same set `BoxTree` gives
    /// over the boxes `(p − (b, b, b), p + (b, b, b))` — in tree order.
    pub fn overlapping(&self, points: &[Vec3], half: &[f64], lo: Vec3, hi: Vec3) -> Vec<u32> {
        let mut out = Vec::new();
        if let Some(top) = self.levels.len().checked_sub(1) {
            self.visit(top, 0, points, half, (lo, hi), &mut out);
        }
        out
    }

    /// Collects the cubes under box `i` of level `level` that meet `q`.
    fn visit(
        &self,
        level: usize,
        i: usize,
        points: &[Vec3],
        half: &[f64],
        q: (Vec3, Vec3),
        out: &mut Vec<u32>,
    ) {
        if !self.levels[level][i].meets(q.0, q.1) {
            return;
        }
        if level == 0 {
            let end = ((i + 1) * LEAF).min(self.order.len());
            for &k in &self.order[i * LEAF..end] {
                if cube_meets(points[k as usize], half[k as usize], q.0, q.1) {
                    out.push(k);
                }
            }
            return;
        }
        let end = ((i + 1) * FANOUT).min(self.levels[level - 1].len());
        for c in i * FANOUT..end {
            self.visit(level - 1, c, points, half, q, out);
        }
    }
}

/// The outward-rounded box of the cubes `run` (indices into `points`/`half`).
fn leaf_box(run: &[u32], points: &[Vec3], half: &[f64]) -> BoxF32 {
    let cube = |k: u32| {
        let (p, b) = (points[k as usize], half[k as usize]);
        let r = Vec3::new(b, b, b);
        (p - r, p + r)
    };
    let first = cube(run[0]);
    let (lo, hi) = run[1..].iter().fold(first, |(lo, hi), &k| {
        let (a, b) = cube(k);
        (lo.min(a), hi.max(b))
    });
    BoxF32::outward(lo, hi)
}

/// The indices of `points` sorted by the Morton code of the point in the points' bounding box
/// (ties by index): nearby points end up in the same leaf.
/// The levels of a box pyramid over `leaves`: `leaves` itself, then the union of every
/// [`FANOUT`] boxes of the level below, up to a single root (no level for no leaves).
pub(super) fn pyramid(leaves: Vec<BoxF32>) -> Vec<Vec<BoxF32>> {
    let mut levels = Vec::new();
    if !leaves.is_empty() {
        levels.push(leaves);
        while levels.last().is_some_and(|l| l.len() > 1) {
            let below = levels.last().expect("non-empty");
            let next: Vec<BoxF32> = below.chunks(FANOUT).map(BoxF32::union).collect();
            levels.push(next);
        }
    }
    levels
}

pub(super) fn morton_order(points: &[Vec3]) -> Vec<u32> {
    let Some(&first) = points.first() else {
        return Vec::new();
    };
    let (lo, hi) = points
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let cells = f64::from((1u32 << MORTON_BITS) - 1);
    let ext = hi - lo;
    let scale = [ext.x, ext.y, ext.z].map(|e| if e > 0.0 { cells / e } else { 0.0 });
    let codes: Vec<u64> = points
        .par_iter()
        .map(|&p| {
            let q = p - lo;
            let c = [q.x, q.y, q.z]
                .into_iter()
                .zip(scale)
                .map(|(x, s)| (x * s).clamp(0.0, cells) as u64);
            c.enumerate().fold(0, |m, (k, c)| m | (spread(c) << k))
        })
        .collect();
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.par_sort_unstable_by_key(|&k| (codes[k as usize], k));
    order
}

/// The low [`MORTON_BITS`] bits of `x` spread to every third bit.
fn spread(x: u64) -> u64 {
    (0..MORTON_BITS).fold(0, |m, b| m | (((x >> b) & 1) << (3 * b)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// After [`sort_in_tree_order`] a tree visits the points in index order, and answers the
    /// same cubes as the tree over the unsorted points (mapped through the reordering).
    #[test]
    fn sorted_points_are_visited_in_index_order() {
        let mut rnd = crate::spatial::test_uniform(0x9e37_79b9_7f4a_7c15u64);
        let points: Vec<Vec3> = (0..2000)
            .map(|_| Vec3::new(rnd() * 4.0, rnd() * 2.0, (rnd() * 8.0).floor()))
            .collect();
        let half = vec![0.05; points.len()];
        let mut sorted = points.clone();
        sort_in_tree_order(&mut sorted);
        let tree = CubeTree::new(&sorted, &half);
        assert!(tree.order.iter().enumerate().all(|(i, &k)| i == k as usize));
        let old = CubeTree::new(&points, &half);
        for q in 0..50 {
            let c = Vec3::new(rnd() * 4.0, rnd() * 2.0, (q % 8) as f64);
            let (lo, hi) = (c - Vec3::splat(0.3), c + Vec3::splat(0.3));
            let a: Vec<Vec3> = old
                .overlapping(&points, &half, lo, hi)
                .iter()
                .map(|&k| points[k as usize])
                .collect();
            let b: Vec<Vec3> = tree
                .overlapping(&sorted, &half, lo, hi)
                .iter()
                .map(|&k| sorted[k as usize])
                .collect();
            assert_eq!(a, b);
        }
    }

    /// The tree answers exactly the brute-force set of meeting cubes, touching included, on a
    /// pseudo-random cloud with varied half-widths and boxes.
    #[test]
    fn overlapping_is_the_brute_force_set() {
        let mut rnd = crate::spatial::test_uniform(0x2545_f491_4f6c_dd1du64);
        let points: Vec<Vec3> = (0..3000)
            .map(|_| Vec3::new(rnd() * 10.0 - 5.0, rnd() * 3.0, rnd() * 0.1))
            .collect();
        let half: Vec<f64> = (0..3000)
            .map(|k| if k % 97 == 0 { 4.0 } else { rnd() * 0.3 })
            .collect();
        let tree = CubeTree::new(&points, &half);
        for q in 0..200 {
            let c = if q == 0 {
                // touching: the box's corner is exactly a cube's corner
                points[5] + Vec3::new(half[5], half[5], half[5])
            } else {
                Vec3::new(rnd() * 12.0 - 6.0, rnd() * 4.0 - 0.5, rnd() * 0.2 - 0.05)
            };
            let r = rnd() * 0.5;
            let (lo, hi) = if q == 0 {
                (c, c + Vec3::new(1.0, 1.0, 1.0))
            } else {
                (c - Vec3::new(r, r, r), c + Vec3::new(r, r, r))
            };
            let mut got = tree.overlapping(&points, &half, lo, hi);
            got.sort_unstable();
            let want: Vec<u32> = (0..points.len() as u32)
                .filter(|&k| cube_meets(points[k as usize], half[k as usize], lo, hi))
                .collect();
            assert_eq!(got, want, "query {q}");
            if q == 0 {
                assert!(want.contains(&5));
            }
        }
    }

    #[test]
    fn outward_rounding_contains_the_f64_value() {
        for x in [
            0.1, -0.1, 1e-40, -1e-40, 3.0e38, -3.0e38, 1e300, -1e300, 0.0,
        ] {
            assert!(f64::from(down(x)) <= x && x <= f64::from(up(x)), "{x}");
        }
        assert!(CubeTree::new(&[], &[])
            .overlapping(&[], &[], Vec3::ZERO, Vec3::ZERO)
            .is_empty());
    }
}
