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

use std::collections::HashMap;
use std::sync::OnceLock;

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhNode, BvhWorkspace};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;

/// The point of a triangle set closest to a query point (see [`TriangleBvh::closest_point`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// Index of the triangle the closest point lies on.
    pub triangle: u32,
    /// The closest point.
    pub point: [f64; 3],
    /// Euclidean distance from the query point to `point`.
    pub distance: f64,
}

/// A BVH over triangles of a mesh, keyed by triangle index. See the [module docs](self).
///
/// `Send + Sync`; queries take `&self` and may run concurrently.
#[derive(Clone, Default)]
pub struct TriangleBvh {
    bvh: Bvh,
    keys: LeafKeys,
    len: usize,
}

/// How parry's leaf ids relate to triangle indices. parry keeps a table indexed by leaf id, so a
/// small subset of a big mesh gets dense leaf ids `0..k` and a map, not the triangle indices.
#[derive(Clone, Default)]
enum LeafKeys {
    /// Leaf id = triangle index.
    #[default]
    Identity,
    /// Leaf id `k` is triangle `tri_of_leaf[k]`; the inverse map is built on first use.
    Mapped {
        tri_of_leaf: Vec<u32>,
        leaf_of_tri: OnceLock<HashMap<u32, u32>>,
    },
}

impl LeafKeys {
    #[inline]
    fn tri(&self, leaf: u32) -> u32 {
        match self {
            LeafKeys::Identity => leaf,
            LeafKeys::Mapped { tri_of_leaf, .. } => tri_of_leaf[leaf as usize],
        }
    }

    #[inline]
    fn leaf(&self, tri: u32) -> Option<u32> {
        match self {
            LeafKeys::Identity => Some(tri),
            LeafKeys::Mapped {
                tri_of_leaf,
                leaf_of_tri,
            } => leaf_of_tri
                .get_or_init(|| inverse(tri_of_leaf))
                .get(&tri)
                .copied(),
        }
    }
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
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Self {
        let boxes = (0..triangles.len()).map(|t| triangle_aabb(positions, triangles[t]));
        TriangleBvh {
            bvh: build_tree(boxes),
            keys: LeafKeys::Identity,
            len: triangles.len(),
        }
    }

    /// Builds a tree over the listed triangles only (each index at most once). Memory is
    /// proportional to the subset, not to the mesh.
    pub fn from_subset(positions: &[[f64; 3]], triangles: &[[u32; 3]], subset: &[u32]) -> Self {
        let boxes = subset
            .iter()
            .map(|&t| triangle_aabb(positions, triangles[t as usize]));
        let keys = if subset.iter().enumerate().all(|(k, &t)| k as u32 == t) {
            LeafKeys::Identity
        } else {
            LeafKeys::Mapped {
                tri_of_leaf: subset.to_vec(),
                leaf_of_tri: OnceLock::new(),
            }
        };
        TriangleBvh {
            bvh: build_tree(boxes),
            keys,
            len: subset.len(),
        }
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
        self.keys
            .leaf(t)
            .is_some_and(|l| self.bvh.leaf_node(l).is_some())
    }

    /// The box stored for triangle `t`, as `(min, max)`, if it is in the tree.
    pub fn triangle_box(&self, t: u32) -> Option<([f64; 3], [f64; 3])> {
        let node = self.bvh.leaf_node(self.keys.leaf(t)?)?;
        Some((node.mins().into(), node.maxs().into()))
    }

    /// Recomputes every leaf box from the current positions and refits the whole tree
    /// (O(n); the tree topology is kept, so quality degrades after large motions — rebuild then).
    pub fn refit(&mut self, positions: &[[f64; 3]], triangles: &[[u32; 3]]) {
        let leaves: Vec<u32> = self.bvh.leaves(|_| true).collect();
        for leaf in leaves {
            let t = self.keys.tri(leaf);
            let aabb = triangle_aabb(positions, triangles[t as usize]);
            self.bvh.update_partially_if_present(aabb, leaf, 0.0);
        }
        self.bvh.refit(&mut BvhWorkspace::default());
    }

    /// Recomputes the boxes of the listed triangles and of their ancestors: O(k · height), for
    /// local edits. Triangles not in the tree are ignored.
    pub fn update(&mut self, positions: &[[f64; 3]], triangles: &[[u32; 3]], changed: &[u32]) {
        let mut leaves = Vec::with_capacity(changed.len());
        for &t in changed {
            if let Some(leaf) = self
                .keys
                .leaf(t)
                .filter(|&l| self.bvh.leaf_node(l).is_some())
            {
                let aabb = triangle_aabb(positions, triangles[t as usize]);
                self.bvh.update_partially_if_present(aabb, leaf, 0.0);
                leaves.push(leaf);
            }
        }
        self.bvh.refit_partial(&[], &leaves);
    }

    /// Adds triangle `t` (or updates its box when already present).
    pub fn insert(&mut self, positions: &[[f64; 3]], triangles: &[[u32; 3]], t: u32) {
        if self.contains(t) {
            self.update(positions, triangles, &[t]);
            return;
        }
        let leaf = match &mut self.keys {
            LeafKeys::Identity => t,
            LeafKeys::Mapped {
                tri_of_leaf,
                leaf_of_tri,
            } => {
                leaf_of_tri.get_or_init(|| inverse(tri_of_leaf));
                let map = leaf_of_tri.get_mut().expect("initialized above");
                let leaf = *map.entry(t).or_insert(tri_of_leaf.len() as u32);
                if leaf as usize == tri_of_leaf.len() {
                    tri_of_leaf.push(t);
                }
                leaf
            }
        };
        self.bvh
            .insert(triangle_aabb(positions, triangles[t as usize]), leaf);
        self.len += 1;
    }

    /// Removes triangle `t` from the tree (no-op when absent).
    pub fn remove(&mut self, t: u32) {
        if let Some(leaf) = self
            .keys
            .leaf(t)
            .filter(|&l| self.bvh.leaf_node(l).is_some())
        {
            self.bvh.remove(leaf);
            self.len -= 1;
        }
    }

    /// The box enclosing every triangle in the tree, as `(min, max)`; `None` when empty.
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        if self.is_empty() {
            return None;
        }
        let aabb = self.bvh.root_aabb();
        Some((aabb.mins.into(), aabb.maxs.into()))
    }

    /// The triangle indices in the tree, in increasing order.
    pub fn leaf_ids(&self) -> Vec<u32> {
        let mut ids: Vec<u32> = self
            .bvh
            .leaves(|_| true)
            .map(|l| self.keys.tri(l))
            .collect();
        ids.sort_unstable();
        ids
    }

    /// Triangles whose box meets the closed box `[min, max]`, in tree order (unsorted).
    pub fn query_box(&self, min: [f64; 3], max: [f64; 3]) -> impl Iterator<Item = u32> + '_ {
        let query = BvhNode::leaf(Aabb::new(Vector::from(min), Vector::from(max)), 0);
        self.bvh
            .leaves(move |n: &BvhNode| n.intersects(&query))
            .map(|l| self.keys.tri(l))
    }

    /// Triangles that may lie within `pad` of the triangle `tri`: those whose box meets the
    /// box of `tri` grown by `pad` and, when `tri` has a normal, lies in the slab of points
    /// within `pad` (plus a rounding margin of `1e-9` of the coordinates) of `tri`'s plane. A
    /// superset of the triangles at distance `≤ pad` (a point that near `tri` is that near its
    /// plane), in tree order; for a large slanted `tri` the slab prunes most of its box.
    pub fn query_near_triangle(
        &self,
        tri: &[[f64; 3]; 3],
        pad: f64,
    ) -> impl Iterator<Item = u32> + '_ {
        let (lo, hi) = corners_box(tri);
        let lo = Vector::from(lo) - Vector::splat(pad);
        let hi = Vector::from(hi) + Vector::splat(pad);
        let query = BvhNode::leaf(Aabb::new(lo, hi), 0);
        let [a, b, c] = tri.map(Vector::from);
        let n = (b - a).cross(c - a).normalize_or_zero();
        let offset = n.dot(a);
        // Rounding of the dot products below stays far under 1e-9 of the magnitudes involved.
        let margin = 1e-9 * (lo.abs().max(hi.abs()).max_element() + (hi - lo).length());
        self.bvh
            .leaves(move |node: &BvhNode| {
                if !node.intersects(&query) {
                    return false;
                }
                if n == Vector::ZERO {
                    return true;
                }
                let (mins, maxs) = (node.mins(), node.maxs());
                let centre = n.dot((mins + maxs) * 0.5) - offset;
                let reach = n.abs().dot((maxs - mins) * 0.5);
                centre.abs() - reach <= pad + margin + 1e-9 * (reach + centre.abs())
            })
            .map(|l| self.keys.tri(l))
    }

    /// Triangles whose box meets the box of the triangle `tri` (given by its corners).
    pub fn query_triangle(&self, tri: &[[f64; 3]; 3]) -> impl Iterator<Item = u32> + '_ {
        let (lo, hi) = corners_box(tri);
        self.query_box(lo, hi)
    }

    /// All pairs `(a, b)`, `a < b`, of triangles in the tree whose boxes meet, sorted.
    /// Candidates for self-intersection tests (including pairs of neighbouring faces).
    pub fn self_pairs(&self) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        self.for_each_self_pair(|a, b| pairs.push((a, b)));
        pairs.sort_unstable();
        pairs
    }

    /// Calls `f(a, b)`, `a < b`, once for every pair of triangles in the tree whose boxes meet,
    /// in tree order (no allocation, no sorting).
    pub fn for_each_self_pair(&self, mut f: impl FnMut(u32, u32)) {
        if self.len >= 2 {
            self.bvh.traverse_bvtt_single_tree::<false>(
                &mut BvhWorkspace::default(),
                &mut |a, b| {
                    let (a, b) = (self.keys.tri(a), self.keys.tri(b));
                    f(a.min(b), a.max(b));
                },
            );
        }
    }

    /// All pairs `(a, b)` with `a` in `self` and `b` in `other` whose boxes meet, sorted.
    pub fn pairs_with(&self, other: &TriangleBvh) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        self.for_each_pair_with(other, |a, b| pairs.push((a, b)));
        pairs.sort_unstable();
        pairs
    }

    /// Calls `f(a, b)` once for every `a` in `self` and `b` in `other` whose boxes meet, in
    /// tree order.
    pub fn for_each_pair_with(&self, other: &TriangleBvh, mut f: impl FnMut(u32, u32)) {
        if self.is_empty() || other.is_empty() {
            return;
        }
        for (a, b) in self.bvh.leaf_pairs(&other.bvh, |a, b| a.intersects(b)) {
            // parry does not test the root-level pairs: re-check at the leaves.
            if let (Some(na), Some(nb)) = (self.bvh.leaf_node(a), other.bvh.leaf_node(b)) {
                if na.intersects(nb) {
                    f(self.keys.tri(a), other.keys.tri(b));
                }
            }
        }
    }

    /// The closest point to `p` on the triangles in the tree, if one lies strictly closer than
    /// `max_distance` (pass `f64::INFINITY` for no limit). Ties are broken by tree order.
    pub fn closest_point(
        &self,
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        p: [f64; 3],
        max_distance: f64,
    ) -> Option<ClosestPoint> {
        if self.is_empty() {
            return None;
        }
        let q = Vector::from(p);
        let (t, (distance, proj)) = self.bvh.project_point(q, max_distance, |leaf, _| {
            let tri = triangles[self.keys.tri(leaf) as usize];
            let [a, b, c] = tri.map(|v| Vector::from(positions[v as usize]));
            Some(Triangle::new(a, b, c).project_local_point(q, false))
        })?;
        Some(ClosestPoint {
            triangle: self.keys.tri(t),
            point: proj.point.into(),
            distance,
        })
    }
}

/// `tri → k` for `tri_of_leaf[k] = tri`.
fn inverse(tri_of_leaf: &[u32]) -> HashMap<u32, u32> {
    tri_of_leaf
        .iter()
        .enumerate()
        .map(|(k, &t)| (t, k as u32))
        .collect()
}

/// A parry tree whose leaf `k` has the `k`-th box of `boxes`. The boxes stream into parry's
/// build (the tree `Bvh::from_leaves` builds from the same boxes, without a 48 B-a-leaf copy of
/// them alive during the build: a memory peak of the guard's rebuilds on a dense offset).
fn build_tree(boxes: impl ExactSizeIterator<Item = Aabb>) -> Bvh {
    if boxes.len() <= 2 {
        // parry's bulk build special-cases one and two leaves; insertion is just as good.
        let mut bvh = Bvh::new();
        for (k, aabb) in boxes.enumerate() {
            bvh.insert(aabb, k as u32);
        }
        bvh
    } else {
        Bvh::from_iter(BvhBuildStrategy::Binned, boxes.enumerate())
    }
}

/// The exact box of a triangle's corners.
pub fn triangle_aabb(positions: &[[f64; 3]], t: [u32; 3]) -> Aabb {
    let (lo, hi) = corners_box(&t.map(|v| positions[v as usize]));
    Aabb::new(Vector::from(lo), Vector::from(hi))
}

/// `(min, max)` of three points, coordinate-wise.
pub fn corners_box(p: &[[f64; 3]; 3]) -> ([f64; 3], [f64; 3]) {
    let lo = [0, 1, 2].map(|k| p[0][k].min(p[1][k]).min(p[2][k]));
    let hi = [0, 1, 2].map(|k| p[0][k].max(p[1][k]).max(p[2][k]));
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `query_near_triangle` returns every triangle within `pad` of the query (brute force
    /// over a noisy grid of small triangles against slanted queries) and, for a slanted query,
    /// far fewer than its box holds.
    #[test]
    fn near_triangle_query_is_a_superset_of_the_near_triangles() {
        use crate::geom::Vec3;
        use crate::spatial::closest::disjoint_triangle_distance;
        let mut p = Vec::new();
        let mut t = Vec::new();
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for i in 0..20 {
            for j in 0..20 {
                for k in 0..5 {
                    let c = [i as f64 * 0.1, j as f64 * 0.1, k as f64 * 0.1];
                    let base = p.len() as u32;
                    for _ in 0..3 {
                        p.push([
                            c[0] + 0.05 * rnd(),
                            c[1] + 0.05 * rnd(),
                            c[2] + 0.05 * rnd(),
                        ]);
                    }
                    t.push([base, base + 1, base + 2]);
                }
            }
        }
        let bvh = TriangleBvh::new(&p, &t);
        let queries = [
            [[0.0, 0.0, 0.0], [2.0, 0.1, 0.5], [0.3, 2.0, 0.2]],
            [[1.0, 1.0, -0.2], [1.9, 0.2, 0.7], [0.1, 1.8, 0.6]],
            [[0.5, 0.5, 0.25], [0.6, 0.5, 0.25], [0.5, 0.6, 0.25]],
        ];
        for q in &queries {
            let qv = q.map(Vec3::from);
            for pad in [0.0, 0.01, 0.05] {
                let got: std::collections::HashSet<u32> = bvh.query_near_triangle(q, pad).collect();
                let in_box: usize = {
                    let (lo, hi) = corners_box(q);
                    bvh.query_box(lo.map(|x| x - pad), hi.map(|x| x + pad))
                        .count()
                };
                for (i, tri) in t.iter().enumerate() {
                    let tv = tri.map(|v| Vec3::from(p[v as usize]));
                    // Intersecting pairs count as near (distance 0): the exact decision is
                    // the caller's; only far triangles may be left out.
                    let d = disjoint_triangle_distance(&qv, &tv, 0.0);
                    if d <= pad {
                        assert!(got.contains(&(i as u32)), "triangle {i} at {d} missed");
                    }
                }
                assert!(got.len() <= in_box);
            }
        }
        let slanted = bvh.query_near_triangle(&queries[0], 0.01).count();
        let (lo, hi) = corners_box(&queries[0]);
        let boxed = bvh.query_box(lo, hi).count();
        assert!(slanted * 2 < boxed, "{slanted} of {boxed}");
    }

    /// A strip of `n` unit right triangles along x, plus positions.
    fn strip(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for i in 0..=n {
            p.push([i as f64, 0., 0.]);
            p.push([i as f64, 1., 0.]);
        }
        let t = (0..n).map(|i| [2 * i, 2 * i + 2, 2 * i + 1]).collect();
        (p, t)
    }

    fn brute_pairs(p: &[[f64; 3]], t: &[[u32; 3]], ids: &[u32]) -> Vec<(u32, u32)> {
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
        assert_eq!(one.bounds(), Some(([0., 0., 0.], [1., 1., 0.])));
        assert_eq!(TriangleBvh::default().bounds(), None);
        assert_eq!(
            TriangleBvh::new(&p, &t).bounds(),
            Some(([0., 0., 0.], [20., 1., 0.]))
        );
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
    fn subset_tree_edits_keep_triangle_keys() {
        let (mut p, t) = strip(30);
        let mut bvh = TriangleBvh::from_subset(&p, &t, &[29, 3, 17, 5]);
        assert_eq!(bvh.leaf_ids(), vec![3, 5, 17, 29]);
        assert!(bvh.contains(17) && !bvh.contains(4));
        // Move triangle 29 (its free corner is vertex 60) onto triangle 3.
        p[60] = [3.5, 0.5, 0.];
        bvh.update(&p, &t, &[29, 4]); // 4 is not in the tree: ignored
        let hits: Vec<u32> = bvh.query_box([3.5, 0.5, 0.], [3.5, 0.5, 0.]).collect();
        assert!(hits.contains(&29) && hits.contains(&3), "{hits:?}");
        assert_eq!(bvh.self_pairs(), brute_pairs(&p, &t, &[3, 5, 17, 29]));
        bvh.remove(3);
        bvh.remove(3);
        assert_eq!((bvh.len(), bvh.contains(3)), (3, false));
        bvh.insert(&p, &t, 4);
        bvh.insert(&p, &t, 3);
        assert_eq!(bvh.leaf_ids(), vec![3, 4, 5, 17, 29]);
        assert_eq!(bvh.self_pairs(), brute_pairs(&p, &t, &[3, 4, 5, 17, 29]));
        let c = bvh.closest_point(&p, &t, [17.5, 0.2, 1.0], 5.0).unwrap();
        assert_eq!((c.triangle, c.distance), (17, 1.0));
        let all = TriangleBvh::new(&p, &t);
        let mut expected: Vec<(u32, u32)> = Vec::new();
        for s in [3u32, 4, 5, 17, 29] {
            for b in 0..30u32 {
                if s == b || brute_pairs(&p, &t, &[s.min(b), s.max(b)]).len() == 1 {
                    expected.push((s, b));
                }
            }
        }
        expected.sort_unstable();
        assert_eq!(bvh.pairs_with(&all), expected);
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
