//! [`BoxTree`]: a static bounding-volume hierarchy over caller-defined boxes (parry's
//! `partitioning::Bvh`, binned build), for primitives that are not mesh triangles: the distance
//! field's reduced input primitives, the interior-removal components. Callers pass and receive
//! [`Vec3`] only; parry's types stay inside `spatial/`.
//!
//! May import: `crate::geom`.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};

use crate::geom::Vec3;

/// A BVH whose leaf `k` is the `k`-th box it was built from. Queries take `&self` and may run
/// concurrently.
pub struct BoxTree {
    bvh: Bvh,
}

impl BoxTree {
    /// Builds the tree over the closed boxes `(min, max)` (leaf `k` is `boxes[k]`) with parry's
    /// binned strategy.
    pub fn new(boxes: impl IntoIterator<Item = (Vec3, Vec3)>) -> BoxTree {
        // streamed: the tree `from_leaves` builds, without a copy of the boxes alive
        let aabbs = boxes.into_iter().map(|(lo, hi)| Aabb::new(lo, hi));
        BoxTree {
            bvh: Bvh::from_iter(BvhBuildStrategy::Binned, aabbs.enumerate()),
        }
    }

    /// The leaves whose box meets the closed box `[lo, hi]` (touching counts), in tree order.
    pub fn overlapping(&self, lo: Vec3, hi: Vec3) -> Vec<u32> {
        self.bvh.intersect_aabb(&Aabb::new(lo, hi)).collect()
    }

    /// Best-first search for the leaf nearest to `p`: `leaf(k)` returns the exact distance from
    /// `p` to leaf `k`'s primitive and a payload (or `None` to skip it); subtrees whose box is
    /// not closer than the best distance so far (initially `bound`) are pruned. Returns the
    /// payload of the nearest leaf strictly closer than `bound`, ties broken by tree order.
    pub fn nearest<T>(
        &self,
        p: Vec3,
        bound: f64,
        leaf: impl Fn(u32) -> Option<(f64, T)>,
    ) -> Option<T> {
        self.bvh
            .find_best(
                bound,
                |node, _| box_distance(node.mins(), node.maxs(), p),
                |k, _| leaf(k),
            )
            .map(|(_, (_, t))| t)
    }
}

/// Euclidean distance from `p` to the closed box `[lo, hi]` (0 inside).
fn box_distance(lo: Vec3, hi: Vec3, p: Vec3) -> f64 {
    let dx = (lo.x - p.x).max(p.x - hi.x).max(0.0);
    let dy = (lo.y - p.y).max(p.y - hi.y).max(0.0);
    let dz = (lo.z - p.z).max(p.z - hi.z).max(0.0);
    (dx * dx + dy * dy + dz * dz).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_and_nearest() {
        let boxes: Vec<(Vec3, Vec3)> = (0..10)
            .map(|i| {
                let c = Vec3::new(2.0 * i as f64, 0.0, 0.0);
                (c - 0.5, c + 0.5)
            })
            .collect();
        let tree = BoxTree::new(boxes.iter().copied());
        let mut hit = tree.overlapping(Vec3::new(2.5, 0.0, 0.0), Vec3::new(4.0, 0.0, 0.0));
        hit.sort_unstable();
        assert_eq!(hit, vec![1, 2]);
        let p = Vec3::new(7.2, 3.0, 0.0);
        let near = tree.nearest(p, f64::INFINITY, |k| {
            let c = (boxes[k as usize].0 + boxes[k as usize].1) * 0.5;
            Some((c.distance(p), k))
        });
        assert_eq!(near, Some(4));
        assert_eq!(tree.nearest(p, 1.0, |k| Some((10.0, k))), None);
    }
}
