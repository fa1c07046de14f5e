//! TEMPORARY thin stand-in for `crate::spatial` (branch `report`), with the same names and
//! signatures, so the optimization stages compile before that branch lands on `main`. Replaced
//! by `pub(crate) use crate::spatial::...` as soon as it does; nothing here is public.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;

/// A point in 3D.
pub(crate) type Point3 = [f64; 3];

/// Closest point on a triangle set.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ClosestPoint {
    pub triangle: u32,
    pub point: Point3,
    pub distance: f64,
}

/// BVH over triangles keyed by triangle index.
#[derive(Clone, Default)]
pub(crate) struct TriangleBvh {
    bvh: Bvh,
}

fn aabb(positions: &[Point3], t: [u32; 3]) -> Aabb {
    let p = t.map(|v| positions[v as usize]);
    let (lo, hi) = corners_box(&p);
    Aabb::new(Vector::from(lo), Vector::from(hi))
}

pub(crate) fn corners_box(p: &[Point3; 3]) -> (Point3, Point3) {
    let mut lo = p[0];
    let mut hi = p[0];
    for q in &p[1..] {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (lo, hi)
}

impl TriangleBvh {
    pub(crate) fn new(positions: &[Point3], triangles: &[[u32; 3]]) -> Self {
        let all: Vec<u32> = (0..triangles.len() as u32).collect();
        Self::from_subset(positions, triangles, &all)
    }

    pub(crate) fn from_subset(
        positions: &[Point3],
        triangles: &[[u32; 3]],
        subset: &[u32],
    ) -> Self {
        let mut leaves = vec![Aabb::new_invalid(); triangles.len()];
        for &t in subset {
            leaves[t as usize] = aabb(positions, triangles[t as usize]);
        }
        let mut bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves);
        let keep: std::collections::HashSet<u32> = subset.iter().copied().collect();
        for t in 0..triangles.len() as u32 {
            if !keep.contains(&t) {
                bvh.remove(t);
            }
        }
        TriangleBvh { bvh }
    }

    pub(crate) fn update(&mut self, positions: &[Point3], triangles: &[[u32; 3]], changed: &[u32]) {
        for &t in changed {
            self.insert(positions, triangles, t);
        }
    }

    pub(crate) fn insert(&mut self, positions: &[Point3], triangles: &[[u32; 3]], t: u32) {
        self.bvh.remove(t);
        self.bvh.insert(aabb(positions, triangles[t as usize]), t);
    }

    pub(crate) fn remove(&mut self, t: u32) {
        self.bvh.remove(t);
    }

    pub(crate) fn query_box(&self, min: Point3, max: Point3) -> impl Iterator<Item = u32> + '_ {
        let q = Aabb::new(Vector::from(min), Vector::from(max));
        self.bvh.intersect_aabb(&q).collect::<Vec<_>>().into_iter()
    }

    pub(crate) fn query_triangle(&self, tri: &[Point3; 3]) -> impl Iterator<Item = u32> + '_ {
        let (lo, hi) = corners_box(tri);
        self.query_box(lo, hi)
    }

    pub(crate) fn closest_point(
        &self,
        positions: &[Point3],
        triangles: &[[u32; 3]],
        p: Point3,
        max_distance: f64,
    ) -> Option<ClosestPoint> {
        if self.bvh.is_empty() {
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

fn o3(a: Point3, b: Point3, c: Point3, d: Point3) -> i8 {
    let c3 = |p: Point3| robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    };
    let v = -robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    (v > 0.0) as i8 - (v < 0.0) as i8
}

fn o2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    let c2 = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
    let v = robust::orient2d(c2(a), c2(b), c2(c));
    (v > 0.0) as i8 - (v < 0.0) as i8
}

fn proj(p: Point3, drop: usize) -> [f64; 2] {
    match drop {
        0 => [p[1], p[2]],
        1 => [p[0], p[2]],
        _ => [p[0], p[1]],
    }
}

pub(crate) fn is_collinear(a: Point3, b: Point3, c: Point3) -> bool {
    (0..3).all(|k| o2(proj(a, k), proj(b, k), proj(c, k)) == 0)
}

fn axis(t: &[Point3; 3]) -> usize {
    (0..3)
        .find(|&k| o2(proj(t[0], k), proj(t[1], k), proj(t[2], k)) != 0)
        .unwrap_or(2)
}

fn seg_seg_2d(p: [[f64; 2]; 2], q: [[f64; 2]; 2]) -> bool {
    let d1 = o2(p[0], p[1], q[0]);
    let d2 = o2(p[0], p[1], q[1]);
    let d3 = o2(q[0], q[1], p[0]);
    let d4 = o2(q[0], q[1], p[1]);
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    let on = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (0..2).all(|k| a[k].min(b[k]) <= c[k] && c[k] <= a[k].max(b[k]))
    };
    (d1 == 0 && on(p[0], p[1], q[0]))
        || (d2 == 0 && on(p[0], p[1], q[1]))
        || (d3 == 0 && on(q[0], q[1], p[0]))
        || (d4 == 0 && on(q[0], q[1], p[1]))
}

fn point_in_tri_2d(p: [f64; 2], t: &[[f64; 2]; 3]) -> bool {
    let s = [o2(t[0], t[1], p), o2(t[1], t[2], p), o2(t[2], t[0], p)];
    !(s.contains(&1) && s.contains(&-1))
}

fn seg_tri_2d(s: [[f64; 2]; 2], t: &[[f64; 2]; 3]) -> bool {
    point_in_tri_2d(s[0], t)
        || point_in_tri_2d(s[1], t)
        || (0..3).any(|i| seg_seg_2d(s, [t[i], t[(i + 1) % 3]]))
}

pub(crate) fn segment_triangle_intersect(s: [Point3; 2], t: &[Point3; 3]) -> bool {
    let sp = o3(t[0], t[1], t[2], s[0]);
    let sq = o3(t[0], t[1], t[2], s[1]);
    if sp * sq > 0 {
        return false;
    }
    if sp == 0 && sq == 0 {
        let k = axis(t);
        return seg_tri_2d(s.map(|x| proj(x, k)), &t.map(|x| proj(x, k)));
    }
    let v = [
        o3(s[0], s[1], t[0], t[1]),
        o3(s[0], s[1], t[1], t[2]),
        o3(s[0], s[1], t[2], t[0]),
    ];
    !(v.contains(&1) && v.contains(&-1))
}

pub(crate) fn triangles_intersect(a: &[Point3; 3], b: &[Point3; 3]) -> bool {
    let sa = a.map(|p| o3(b[0], b[1], b[2], p));
    if sa.iter().all(|&s| s > 0) || sa.iter().all(|&s| s < 0) {
        return false;
    }
    if sa == [0, 0, 0] {
        let k = axis(b);
        let a2 = a.map(|x| proj(x, k));
        let b2 = b.map(|x| proj(x, k));
        return (0..3).any(|i| seg_tri_2d([a2[i], a2[(i + 1) % 3]], &b2))
            || point_in_tri_2d(b2[0], &a2);
    }
    let sb = b.map(|p| o3(a[0], a[1], a[2], p));
    if sb.iter().all(|&s| s > 0) || sb.iter().all(|&s| s < 0) {
        return false;
    }
    (0..3).any(|i| segment_triangle_intersect([a[i], a[(i + 1) % 3]], b))
        || (0..3).any(|i| segment_triangle_intersect([b[i], b[(i + 1) % 3]], a))
}

/// CGAL face-pair rules (see `report` branch docs).
pub(crate) fn faces_intersect(positions: &[Point3], a: [u32; 3], b: [u32; 3]) -> bool {
    let p = |v: u32| positions[v as usize];
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .filter(|&(i, j)| a[i] == b[j])
        .collect();
    let ta = a.map(p);
    let tb = b.map(p);
    match shared.len() {
        0 => triangles_intersect(&ta, &tb),
        1 => {
            let (ia, ib) = shared[0];
            let sa = [ta[(ia + 1) % 3], ta[(ia + 2) % 3]];
            let sb = [tb[(ib + 1) % 3], tb[(ib + 2) % 3]];
            segment_triangle_intersect(sb, &ta) || segment_triangle_intersect(sa, &tb)
        }
        2 => {
            let (ia0, _) = shared[0];
            let (ia1, _) = shared[1];
            let ra = 3 - ia0 - ia1;
            let rb = 3 - shared[0].1 - shared[1].1;
            let (pp, pq, pr, ps) = (ta[ia0], ta[ia1], ta[ra], tb[rb]);
            if o3(pp, pq, pr, ps) != 0 {
                return false;
            }
            let k = axis(&[pp, pq, pr]);
            let or = o2(proj(pp, k), proj(pq, k), proj(pr, k));
            let os = o2(proj(pp, k), proj(pq, k), proj(ps, k));
            or != 0 && or == os
        }
        _ => true,
    }
}
