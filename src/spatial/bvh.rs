//! [`TriangleBvh`]: a bounding-volume hierarchy over the triangles of a mesh (or a subset of
//! them), backed by parry's `partitioning::Bvh`.
//!
//! The tree stores only boxes; every query that needs geometry takes the mesh buffers
//! (`positions`, `triangles`), so one tree can follow a mesh whose vertices move (call
//! [`TriangleBvh::refit`] or [`TriangleBvh::update`]) and whose faces come and go
//! ([`TriangleBvh::insert`], [`TriangleBvh::remove`]). Leaves are keyed by triangle index.
//!
//! Boxes are the exact `min`/`max` of the corner coordinates and box tests are closed
//! (touching boxes overlap), so the candidate pairs are a superset of the pairs of triangles
//! that touch — the property exact intersection tests downstream rely on.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhNode, BvhWorkspace};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;

use super::Point3;

/// The point of a triangle set closest to a query point (see [`TriangleBvh::closest_point`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// Index of the triangle the closest point lies on.
    pub triangle: u32,
    /// The closest point.
    pub point: Point3,
    /// Euclidean distance from the query point to `point`.
    pub distance: f64,
}

/// A BVH over triangles of a mesh, keyed by triangle index. See the [module docs](self).
///
/// `Send + Sync`; queries take `&self` and may run concurrently.
#[derive(Clone, Default)]
pub struct TriangleBvh {
    bvh: Bvh,
    len: usize,
}

impl std::fmt::Debug for TriangleBvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TriangleBvh")
            .field("len", &self.len)
            .finish()
    }
}

impl TriangleBvh {
    /// Builds a tree over all `triangles` (leaf `i` is triangle `i`).
    pub fn new(positions: &[Point3], triangles: &[[u32; 3]]) -> Self {
        let leaves = (0..triangles.len()).map(|t| (t, triangle_aabb(positions, triangles[t])));
        Self::from_leaves(leaves, triangles.len())
    }

    /// Builds a tree over the listed triangles only (each index at most once).
    pub fn from_subset(positions: &[Point3], triangles: &[[u32; 3]], subset: &[u32]) -> Self {
        let leaves = subset
            .iter()
            .map(|&t| (t as usize, triangle_aabb(positions, triangles[t as usize])));
        Self::from_leaves(leaves, subset.len())
    }

    fn from_leaves(leaves: impl Iterator<Item = (usize, Aabb)>, len: usize) -> Self {
        let leaves: Vec<(usize, Aabb)> = leaves.collect();
        // parry's bulk build mis-keys trees of one or two leaves whose ids are not 0 and 1:
        // insert those one by one.
        let bvh = if leaves.len() <= 2 {
            let mut bvh = Bvh::new();
            for (id, aabb) in leaves {
                bvh.insert(aabb, id as u32);
            }
            bvh
        } else {
            Bvh::from_iter(BvhBuildStrategy::Binned, leaves)
        };
        TriangleBvh { bvh, len }
    }

    /// Number of triangles in the tree.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the tree holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// True when triangle `t` is in the tree.
    pub fn contains(&self, t: u32) -> bool {
        self.bvh.leaf_node(t).is_some()
    }

    /// The box stored for triangle `t`, as `(min, max)`, if it is in the tree.
    pub fn triangle_box(&self, t: u32) -> Option<(Point3, Point3)> {
        self.bvh
            .leaf_node(t)
            .map(|n| (n.mins().into(), n.maxs().into()))
    }

    /// Recomputes every leaf box from the current positions and refits the whole tree
    /// (O(n); the tree topology is kept, so quality degrades after large motions — rebuild then).
    pub fn refit(&mut self, positions: &[Point3], triangles: &[[u32; 3]]) {
        let ids: Vec<u32> = self.leaf_ids();
        for t in ids {
            let aabb = triangle_aabb(positions, triangles[t as usize]);
            self.bvh.update_partially_if_present(aabb, t, 0.0);
        }
        self.bvh.refit(&mut BvhWorkspace::default());
    }

    /// Recomputes the boxes of the listed triangles (which must be in the tree) and of their
    /// ancestors: O(k · height), for local edits.
    pub fn update(&mut self, positions: &[Point3], triangles: &[[u32; 3]], changed: &[u32]) {
        for &t in changed {
            let aabb = triangle_aabb(positions, triangles[t as usize]);
            self.bvh.update_partially_if_present(aabb, t, 0.0);
        }
        self.bvh.refit_partial(&[], changed);
    }

    /// Adds triangle `t` (or updates its box when already present).
    pub fn insert(&mut self, positions: &[Point3], triangles: &[[u32; 3]], t: u32) {
        let aabb = triangle_aabb(positions, triangles[t as usize]);
        if self.contains(t) {
            self.update(positions, triangles, &[t]);
        } else {
            self.bvh.insert(aabb, t);
            self.len += 1;
        }
    }

    /// Removes triangle `t` from the tree (no-op when absent).
    pub fn remove(&mut self, t: u32) {
        if self.contains(t) {
            self.bvh.remove(t);
            self.len -= 1;
        }
    }

    /// The triangle indices in the tree, in increasing order.
    pub fn leaf_ids(&self) -> Vec<u32> {
        let mut ids: Vec<u32> = self.bvh.leaves(|_| true).collect();
        ids.sort_unstable();
        ids
    }

    /// Triangles whose box meets the closed box `[min, max]`, in tree order (unsorted).
    pub fn query_box(&self, min: Point3, max: Point3) -> impl Iterator<Item = u32> + '_ {
        let query = BvhNode::leaf(Aabb::new(Vector::from(min), Vector::from(max)), 0);
        self.bvh.leaves(move |n: &BvhNode| n.intersects(&query))
    }

    /// Triangles whose box meets the box of the triangle `tri` (given by its corners).
    pub fn query_triangle(&self, tri: &[Point3; 3]) -> impl Iterator<Item = u32> + '_ {
        let (lo, hi) = corners_box(tri);
        self.query_box(lo, hi)
    }

    /// All pairs `(a, b)`, `a < b`, of triangles in the tree whose boxes meet, sorted.
    /// Candidates for self-intersection tests (including pairs of neighbouring faces).
    pub fn self_pairs(&self) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        if self.len >= 2 {
            self.bvh.traverse_bvtt_single_tree::<false>(
                &mut BvhWorkspace::default(),
                &mut |a, b| {
                    pairs.push((a.min(b), a.max(b)));
                },
            );
        }
        pairs.sort_unstable();
        pairs
    }

    /// All pairs `(a, b)` with `a` in `self` and `b` in `other` whose boxes meet, sorted.
    pub fn pairs_with(&self, other: &TriangleBvh) -> Vec<(u32, u32)> {
        if self.is_empty() || other.is_empty() {
            return Vec::new();
        }
        let mut pairs: Vec<(u32, u32)> = self
            .bvh
            .leaf_pairs(&other.bvh, |a, b| a.intersects(b))
            // parry does not test the root-level pairs: re-check at the leaves.
            .filter(
                |&(a, b)| match (self.bvh.leaf_node(a), other.bvh.leaf_node(b)) {
                    (Some(na), Some(nb)) => na.intersects(nb),
                    _ => false,
                },
            )
            .collect();
        pairs.sort_unstable();
        pairs
    }

    /// The closest point to `p` on the triangles in the tree, if one lies strictly closer than
    /// `max_distance` (pass `f64::INFINITY` for no limit). Ties are broken by tree order.
    pub fn closest_point(
        &self,
        positions: &[Point3],
        triangles: &[[u32; 3]],
        p: Point3,
        max_distance: f64,
    ) -> Option<ClosestPoint> {
        if self.is_empty() {
            return None;
        }
        let q = Vector::from(p);
        let (t, (distance, proj)) = self.bvh.project_point(q, max_distance, |leaf, _| {
            let [a, b, c] = triangles[leaf as usize].map(|v| Vector::from(positions[v as usize]));
            Some(Triangle::new(a, b, c).project_local_point(q, false))
        })?;
        Some(ClosestPoint {
            triangle: t,
            point: proj.point.into(),
            distance,
        })
    }
}

/// The exact box of a triangle's corners.
pub fn triangle_aabb(positions: &[Point3], t: [u32; 3]) -> Aabb {
    let (lo, hi) = corners_box(&t.map(|v| positions[v as usize]));
    Aabb::new(Vector::from(lo), Vector::from(hi))
}

/// `(min, max)` of three points, coordinate-wise.
pub fn corners_box(p: &[Point3; 3]) -> (Point3, Point3) {
    let lo = [0, 1, 2].map(|k| p[0][k].min(p[1][k]).min(p[2][k]));
    let hi = [0, 1, 2].map(|k| p[0][k].max(p[1][k]).max(p[2][k]));
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of `n` unit right triangles along x, plus positions.
    fn strip(n: u32) -> (Vec<Point3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for i in 0..=n {
            p.push([i as f64, 0., 0.]);
            p.push([i as f64, 1., 0.]);
        }
        let t = (0..n).map(|i| [2 * i, 2 * i + 2, 2 * i + 1]).collect();
        (p, t)
    }

    fn brute_pairs(p: &[Point3], t: &[[u32; 3]], ids: &[u32]) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for (k, &a) in ids.iter().enumerate() {
            for &b in &ids[k + 1..] {
                let (ba, bb) = (
                    triangle_aabb(p, t[a as usize]),
                    triangle_aabb(p, t[b as usize]),
                );
                if ba.mins.cmple(bb.maxs).all() && bb.mins.cmple(ba.maxs).all() {
                    out.push((a.min(b), a.max(b)));
                }
            }
        }
        out.sort_unstable();
        out
    }

    #[test]
    fn self_pairs_match_brute_force_for_all_sizes() {
        for n in 0..12 {
            let (p, t) = strip(n);
            let bvh = TriangleBvh::new(&p, &t);
            assert_eq!(bvh.len(), n as usize);
            let ids: Vec<u32> = (0..n).collect();
            assert_eq!(bvh.self_pairs(), brute_pairs(&p, &t, &ids), "n = {n}");
            assert_eq!(bvh.leaf_ids(), ids);
        }
    }

    #[test]
    fn subsets_and_pairs_between_trees() {
        let (p, t) = strip(20);
        for subset in [vec![7u32], vec![3, 15], vec![2, 3, 4, 10, 11]] {
            let a = TriangleBvh::from_subset(&p, &t, &subset);
            assert_eq!(a.leaf_ids(), subset);
            assert_eq!(a.self_pairs(), brute_pairs(&p, &t, &subset));
            let all = TriangleBvh::new(&p, &t);
            let mut expected = Vec::new();
            for &s in &subset {
                for b in 0..20u32 {
                    if brute_pairs(&p, &t, &[s.min(b), s.max(b)]).len() == 1 || s == b {
                        expected.push((s, b));
                    }
                }
            }
            expected.sort_unstable();
            assert_eq!(a.pairs_with(&all), expected);
        }
        // Far-apart single leaves: the root-level pair must be filtered out.
        let one = TriangleBvh::from_subset(&p, &t, &[0]);
        let other = TriangleBvh::from_subset(&p, &t, &[19]);
        assert!(one.pairs_with(&other).is_empty());
    }

    #[test]
    fn refit_update_insert_remove() {
        let (mut p, t) = strip(10);
        let mut bvh = TriangleBvh::new(&p, &t);
        // Move triangle 9's free corner on top of triangle 0.
        p[20] = [0.5, 0.5, 0.];
        bvh.update(&p, &t, &[9]);
        let q: Vec<u32> = bvh.query_box([0.5, 0.5, 0.], [0.5, 0.5, 0.]).collect();
        assert!(q.contains(&9) && q.contains(&0), "{q:?}");
        let mut bvh2 = TriangleBvh::new(&strip(10).0, &t);
        bvh2.refit(&p, &t);
        assert_eq!(bvh2.self_pairs(), bvh.self_pairs());
        assert_eq!(bvh.self_pairs(), TriangleBvh::new(&p, &t).self_pairs());
        bvh.remove(9);
        assert!(!bvh.contains(9) && bvh.len() == 9);
        assert!(!bvh
            .query_box([0.5, 0.5, 0.], [0.5, 0.5, 0.])
            .any(|x| x == 9));
        bvh.insert(&p, &t, 9);
        assert!(bvh.contains(9) && bvh.len() == 10);
        assert_eq!(bvh.self_pairs(), TriangleBvh::new(&p, &t).self_pairs());
    }

    #[test]
    fn closest_point_with_max_distance() {
        let (p, t) = strip(10);
        let bvh = TriangleBvh::new(&p, &t);
        let c = bvh
            .closest_point(&p, &t, [3.25, 0.5, 2.0], f64::INFINITY)
            .unwrap();
        assert!((c.distance - 2.0).abs() < 1e-12);
        assert_eq!(c.point, [3.25, 0.5, 0.0]);
        assert!(c.triangle == 3 || c.triangle == 2 || c.triangle == 4);
        assert!(bvh.closest_point(&p, &t, [3.25, 0.5, 2.0], 1.5).is_none());
        let c = bvh.closest_point(&p, &t, [-1.0, 0.0, 0.0], 10.0).unwrap();
        assert_eq!((c.triangle, c.distance), (0, 1.0));
        assert!(TriangleBvh::default()
            .closest_point(&p, &t, [0.; 3], 1.0)
            .is_none());
    }
}
