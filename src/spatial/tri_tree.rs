//! [`TriTree`]: a compact tree over a subset of a mesh's triangles with in-place leaf updates,
//! for the LOD guard's self-intersection queries on dense offset surfaces, where parry's BVH
//! costs ≈ 160 B a triangle and its rebuild a workspace of the same order (a memory peak).
//! It keeps no boxes of its own triangles: a leaf is tested with the triangle's current `f64`
//! box, computed from the positions and triangles the caller passes to every call.
//!
//! Layout (as [`CubeTree`](super::CubeTree)): the triangle indices in Morton order of their
//! centroids (4 B a triangle), the position of each in that order (4 B per triangle index), and
//! a pyramid of outward-rounded `f32` boxes — one per run of 8 consecutive triangles, then one
//! per 8 boxes of the level below (≈ 3.4 B a triangle). An update grows the boxes on the path
//! of a changed triangle to contain its new box (never shrinks them; a rebuild does), so every
//! box contains the current box of every triangle below it that was updated after its last
//! move. Queries then answer exactly the triangles of the tree whose current `f64` box meets
//! the query box, touching counts — the set [`TriangleBvh::query_box`](super::TriangleBvh)
//! gives over exact leaf boxes — in tree order.
//!
//! May import: `crate::geom`.

use rayon::prelude::*;

use super::cube_tree::{morton_order, pyramid, BoxF32, FANOUT, LEAF};
use crate::geom::Vec3;

/// Marks a triangle index that is not in the tree.
const ABSENT: u32 = u32::MAX;

/// A tree over a subset of triangles with leaf updates (module docs). Queries take `&self`.
#[derive(Debug, Default, Clone)]
pub struct TriTree {
    /// Triangle indices in Morton order of their centroids (ties by position in the subset).
    order: Vec<u32>,
    /// Per triangle index below the length at build time: its position in `order`, or
    /// [`ABSENT`].
    slot: Vec<u32>,
    /// `levels[0]`: a box per run of [`LEAF`] entries of `order`; `levels[i + 1]`: a box per
    /// run of [`FANOUT`] boxes of `levels[i]`; the last level has one box (none when empty).
    levels: Vec<Vec<BoxF32>>,
}

/// The `f64` box of triangle `t`, `(min, max)` coordinate-wise over its corners (the box
/// `spatial::bvh::triangle_aabb` stores).
fn tri_box(positions: &[[f64; 3]], t: [u32; 3]) -> (Vec3, Vec3) {
    let [a, b, c] = t.map(|v| Vec3::from(positions[v as usize]));
    (a.min(b).min(c), a.max(b).max(c))
}

/// Whether the closed boxes `a` and `b` meet (touching counts; parry's `Aabb::intersects`).
fn boxes_meet(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> bool {
    a.0.x <= b.1.x
        && a.0.y <= b.1.y
        && a.0.z <= b.1.z
        && b.0.x <= a.1.x
        && b.0.y <= a.1.y
        && b.0.z <= a.1.z
}

impl TriTree {
    /// Builds the tree over the triangles `subset` (indices into `triangles`, each at most
    /// once, below 2³² − 1). Deterministic.
    pub fn from_subset(positions: &[[f64; 3]], triangles: &[[u32; 3]], subset: &[u32]) -> Self {
        assert!(
            triangles.len() < ABSENT as usize,
            "fewer than 2^32 - 1 triangles"
        );
        let order: Vec<u32> = {
            let centroids: Vec<Vec3> = subset
                .par_iter()
                .map(|&t| {
                    let [a, b, c] =
                        triangles[t as usize].map(|v| Vec3::from(positions[v as usize]));
                    (a + b + c) / 3.0
                })
                .collect();
            let mut order = morton_order(&centroids);
            for k in &mut order {
                *k = subset[*k as usize];
            }
            order
        };
        let mut slot = vec![ABSENT; triangles.len()];
        for (i, &t) in order.iter().enumerate() {
            slot[t as usize] = i as u32;
        }
        let leaves: Vec<BoxF32> = order
            .par_chunks(LEAF)
            .map(|run| {
                let first = tri_box(positions, triangles[run[0] as usize]);
                let (lo, hi) = run[1..].iter().fold(first, |(lo, hi), &t| {
                    let (a, b) = tri_box(positions, triangles[t as usize]);
                    (lo.min(a), hi.max(b))
                });
                BoxF32::outward(lo, hi)
            })
            .collect();
        let levels = pyramid(leaves);
        TriTree {
            order,
            slot,
            levels,
        }
    }

    /// Number of triangles in the tree.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// True when the tree holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Grows the boxes above each listed triangle to contain its current box, so queries see
    /// it where it now is: O(k · height). Triangles not in the tree are ignored.
    pub fn update(&mut self, positions: &[[f64; 3]], triangles: &[[u32; 3]], changed: &[u32]) {
        for &t in changed {
            let Some(&s) = self.slot.get(t as usize).filter(|&&s| s != ABSENT) else {
                continue;
            };
            let (lo, hi) = tri_box(positions, triangles[t as usize]);
            let b = BoxF32::outward(lo, hi);
            let mut i = s as usize / LEAF;
            for level in &mut self.levels {
                let node = &mut level[i];
                let grown = BoxF32::union(&[*node, b]);
                if grown == *node {
                    // the boxes above contain this one
                    break;
                }
                *node = grown;
                i /= FANOUT;
            }
        }
    }

    /// Calls `f` with every triangle of the tree whose current box meets the closed box
    /// `[lo, hi]` (touching counts), in tree order; `positions` and `triangles` are the
    /// current ones (every triangle moved since the build must have been `update`d
    /// (Self::update)).
    pub fn for_each_in_box(
        &self,
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        lo: [f64; 3],
        hi: [f64; 3],
        f: &mut impl FnMut(u32),
    ) {
        let q = (Vec3::from(lo), Vec3::from(hi));
        let Some(top) = self.levels.len().checked_sub(1) else {
            return;
        };
        let mut stack = vec![(top, 0usize)];
        while let Some((level, i)) = stack.pop() {
            if !self.levels[level][i].meets(q.0, q.1) {
                continue;
            }
            if level == 0 {
                let end = ((i + 1) * LEAF).min(self.order.len());
                for &t in &self.order[i * LEAF..end] {
                    if boxes_meet(tri_box(positions, triangles[t as usize]), q) {
                        f(t);
                    }
                }
                continue;
            }
            let end = ((i + 1) * FANOUT).min(self.levels[level - 1].len());
            // pushed in reverse so that children are visited in order
            stack.extend((i * FANOUT..end).rev().map(|c| (level - 1, c)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// After random moves (each followed by an update) the tree answers exactly the
    /// brute-force set of triangles whose current box meets the query box, touching included.
    #[test]
    fn queries_after_updates_are_the_brute_force_set() {
        let mut rnd = crate::spatial::test_uniform(0x9e37_79b9_7f4a_7c15u64);
        let mut positions: Vec<[f64; 3]> = (0..2000)
            .map(|_| [rnd() * 10.0, rnd() * 4.0, rnd() * 0.5])
            .collect();
        let triangles: Vec<[u32; 3]> = (0..1500)
            .map(|k| [k as u32, (k + 1) as u32 % 2000, (k * 7 + 3) as u32 % 2000])
            .collect();
        // every third triangle is left out
        let subset: Vec<u32> = (0..1500u32).filter(|t| t % 3 != 0).collect();
        let mut tree = TriTree::from_subset(&positions, &triangles, &subset);
        assert_eq!(tree.len(), subset.len());
        for round in 0..30 {
            // move a few vertices and update the triangles using them
            for _ in 0..20 {
                let v = (rnd() * 2000.0) as usize % 2000;
                positions[v] = [rnd() * 12.0 - 1.0, rnd() * 5.0, rnd() * 0.5];
                let changed: Vec<u32> = (0..1500u32)
                    .filter(|&t| triangles[t as usize].contains(&(v as u32)))
                    .collect();
                tree.update(&positions, &triangles, &changed);
            }
            for q in 0..20 {
                let (lo, hi) = if q == 0 {
                    // touching: the query's corner is a tree triangle's box corner
                    let (a, _) = tri_box(&positions, triangles[1]);
                    (a.to_array().map(|x| x - 1.0), a.to_array())
                } else {
                    let c = [rnd() * 12.0 - 1.0, rnd() * 5.0, rnd() * 0.5];
                    let r = rnd();
                    (c.map(|x| x - r), c.map(|x| x + r))
                };
                let mut got = Vec::new();
                tree.for_each_in_box(&positions, &triangles, lo, hi, &mut |t| got.push(t));
                got.sort_unstable();
                let want: Vec<u32> = subset
                    .iter()
                    .copied()
                    .filter(|&t| {
                        boxes_meet(
                            tri_box(&positions, triangles[t as usize]),
                            (Vec3::from(lo), Vec3::from(hi)),
                        )
                    })
                    .collect();
                assert_eq!(got, want, "round {round} query {q}");
                if q == 0 {
                    assert!(want.contains(&1));
                }
            }
        }
        assert!(TriTree::default().is_empty());
    }
}
