//! Closest points on segments and triangles, point–triangle distances and the barycentric
//! sampling of triangles (Metro-style), on [`Vec3`]: the one home of these helpers for the
//! offset's distance field, the simplifier's Hausdorff bound and the sampled measurements.
//!
//! Two closest-point-on-triangle variants exist because pleat's stages have always rounded the
//! face-interior case differently and their outputs depend on it bit for bit: both walk the
//! same Voronoi regions (Ericson, *Real-Time Collision Detection*, §5.1.5, `voronoi_walk`);
//! [`closest_on_triangle`] (any triangle, degenerate ones via their edges) scales the
//! barycentrics by the reciprocal of their sum, [`closest_on_nondegenerate_triangle`] (the
//! distance field's primitives, slivers already removed) divides by the sum.
//!
//! May import: `crate::geom`.

use crate::geom::{lerp, Vec3};

/// Where the closest point of a triangle to a query point lies.
enum Region {
    /// At a vertex or on an edge: the point itself.
    Boundary(Vec3),
    /// In the interior: the unnormalized barycentric weights `(va, vb, vc)` of Ericson's walk.
    Face { va: f64, vb: f64, vc: f64 },
}

/// Ericson's Voronoi-region walk for the point `p` and triangle `abc` (`ab = b − a`,
/// `ac = c − a`): the closest vertex or edge point, or the weights of the interior case.
#[inline]
fn voronoi_walk(p: Vec3, a: Vec3, b: Vec3, c: Vec3, ab: Vec3, ac: Vec3) -> Region {
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return Region::Boundary(a);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return Region::Boundary(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return Region::Boundary(lerp(a, b, d1 / (d1 - d3)));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return Region::Boundary(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return Region::Boundary(lerp(a, c, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return Region::Boundary(lerp(b, c, (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    Region::Face { va, vb, vc }
}

/// The point of the closed triangle `t` closest to `p`. Works for degenerate triangles too
/// (a triangle whose `|ab × ac|²` is at most `f64::MIN_POSITIVE` is treated as its three edges).
/// Interior points are `a + (ab·v + ac·w)` with `v, w` the barycentrics scaled by the
/// reciprocal of their sum.
pub fn closest_on_triangle(p: Vec3, t: &[Vec3; 3]) -> Vec3 {
    let [a, b, c] = *t;
    let ab = b - a;
    let ac = c - a;
    if ab.cross(ac).length_squared() <= f64::MIN_POSITIVE {
        return closest_on_edges(p, t);
    }
    match voronoi_walk(p, a, b, c, ab, ac) {
        Region::Boundary(q) => q,
        Region::Face { va, vb, vc } => {
            let denom = 1.0 / (va + vb + vc);
            let v = vb * denom;
            let w = vc * denom;
            a + (ab * v + ac * w)
        }
    }
}

/// The point of the triangle `abc` closest to `p`, for triangles known not to be slivers (the
/// distance field's primitives). Interior points are `a + (ab·v + ac·w)` with `v, w` the
/// barycentrics divided by their sum; when rounding makes that sum non-positive (slivers
/// only), the closest point of the three edges.
pub fn closest_on_nondegenerate_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    match voronoi_walk(p, a, b, c, ab, ac) {
        Region::Boundary(q) => q,
        Region::Face { va, vb, vc } => {
            let denom = va + vb + vc;
            if denom.is_nan() || denom <= 0.0 {
                return closest_on_edges(p, &[a, b, c]);
            }
            let v = vb / denom;
            let w = vc / denom;
            a + (ab * v + ac * w)
        }
    }
}

/// Closest point to `p` on the closed segment `[a, b]` (`a` when `a == b`).
pub fn closest_on_segment(p: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let ab = b - a;
    let l2 = ab.length_squared();
    if l2 <= 0.0 {
        return a;
    }
    let t = ((p - a).dot(ab) / l2).clamp(0.0, 1.0);
    lerp(a, b, t)
}

/// The closest point to `p` on the three edges of `t` (the first edge wins ties).
fn closest_on_edges(p: Vec3, t: &[Vec3; 3]) -> Vec3 {
    let mut best = t[0];
    let mut bd = f64::INFINITY;
    for i in 0..3 {
        let q = closest_on_segment(p, t[i], t[(i + 1) % 3]);
        let d = (p - q).length_squared();
        if d < bd {
            bd = d;
            best = q;
        }
    }
    best
}

/// Distance from `p` to the closed triangle `t` (via [`closest_on_triangle`]).
#[inline]
pub fn point_triangle_distance(p: Vec3, t: &[Vec3; 3]) -> f64 {
    p.distance(closest_on_triangle(p, t))
}

/// Closest points `(p, q)` of the closed segments `[p1, q1]` and `[p2, q2]`, `p` on the first
/// and `q` on the second (Ericson, *Real-Time Collision Detection*, §5.1.9,
/// `ClosestPtSegmentSegment`; zero-length segments are points). Parallel segments get one of
/// their closest pairs.
pub fn closest_segment_segment(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> (Vec3, Vec3) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    if a <= 0.0 && e <= 0.0 {
        return (p1, p2);
    }
    let (s, t) = if a <= 0.0 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= 0.0 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p1 + d1 * s, p2 + d2 * t)
}

/// Distance between the closed segments `[p1, q1]` and `[p2, q2]` (via
/// [`closest_segment_segment`]).
#[inline]
pub fn segment_segment_distance(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> f64 {
    let (p, q) = closest_segment_segment(p1, q1, p2, q2);
    p.distance(q)
}

/// Distance between two closed triangles **known not to intersect** (decide that first with
/// the exact `spatial::triangles_intersect`; intersecting triangles are at distance 0, which
/// this function does not see when one pierces the other). For disjoint triangles the closest
/// pair involves a corner of one and the other triangle, or two edges, so the distance is the
/// minimum of the 6 point–triangle distances ([`point_triangle_distance`]) and the 9
/// edge–edge distances ([`segment_segment_distance`]) — exact up to floating-point rounding
/// (no sampling). Degenerate triangles are handled (point–triangle falls back to edges).
/// Stops early and returns a value `< below` as soon as one is found (pass `0.0` for the
/// exact minimum).
pub fn disjoint_triangle_distance(a: &[Vec3; 3], b: &[Vec3; 3], below: f64) -> f64 {
    let mut best = f64::INFINITY;
    for (x, y) in [(a, b), (b, a)] {
        for &p in x {
            best = best.min(point_triangle_distance(p, y));
            if best < below {
                return best;
            }
        }
    }
    for i in 0..3 {
        for j in 0..3 {
            let (p1, q1) = (a[i], a[(i + 1) % 3]);
            let (p2, q2) = (b[j], b[(j + 1) % 3]);
            best = best.min(segment_segment_distance(p1, q1, p2, q2));
            if best < below {
                return best;
            }
        }
    }
    best
}

/// A lower bound of the distance between the triangle `t` and anything on the far side of
/// the plane of triangle `f`: when all corners of `t` lie on one side of that plane, the
/// smallest of their distances to it, else 0. Cheap (one normal, three dot products), it
/// discards most far candidates of a large triangle whose box is big; 0 for a degenerate `f`.
pub fn plane_gap_lower_bound(f: &[Vec3; 3], t: &[Vec3; 3]) -> f64 {
    let n = (f[1] - f[0]).cross(f[2] - f[0]);
    let len = n.length();
    if len.is_nan() || len <= 0.0 {
        return 0.0;
    }
    let s = t.map(|p| (p - f[0]).dot(n) / len);
    let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
    if lo > 0.0 {
        lo
    } else if hi < 0.0 {
        -hi
    } else {
        0.0
    }
}

/// Barycentric sample points of a triangle on a regular grid with `k` subdivisions per edge
/// (`k = 1`: the three corners; `k ≥ 2` adds edge and interior points; for `k < 3` the centroid
/// is added), without the corners when `skip_corners`. Calls `f` for each point, in a fixed
/// order.
pub fn for_each_sample(t: &[Vec3; 3], k: usize, skip_corners: bool, mut f: impl FnMut(Vec3)) {
    let k = k.max(1);
    for i in 0..=k {
        for j in 0..=(k - i) {
            if skip_corners && (i == k || j == k || i + j == 0) {
                continue;
            }
            let u = i as f64 / k as f64;
            let v = j as f64 / k as f64;
            let w = 1.0 - u - v;
            f(t[0] * w + t[1] * u + t[2] * v);
        }
    }
    if k < 3 {
        f((t[0] + t[1] + t[2]) * (1.0 / 3.0));
    }
}

/// Grid resolution for [`for_each_sample`] so that samples are at most about `spacing` apart
/// (`⌈longest edge / spacing⌉`), clamped to `1..=max_k` (1 for a non-positive or NaN spacing or
/// a non-finite edge).
pub fn sample_resolution(t: &[Vec3; 3], spacing: f64, max_k: usize) -> usize {
    let e = t[0]
        .distance(t[1])
        .max(t[1].distance(t[2]))
        .max(t[2].distance(t[0]));
    if spacing.is_nan() || spacing <= 0.0 || !e.is_finite() {
        return 1;
    }
    ((e / spacing).ceil() as usize).clamp(1, max_k.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn closest_point_regions() {
        let t = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
        assert!(closest_on_triangle(v(0.2, 0.2, 1.), &t).distance(v(0.2, 0.2, 0.)) < 1e-15);
        assert_eq!(closest_on_triangle(v(-1., -1., 0.), &t), t[0]);
        assert_eq!(closest_on_triangle(v(2., -1., 0.), &t), t[1]);
        let e = closest_on_triangle(v(0.5, -1., 3.), &t);
        assert!((e.x - 0.5).abs() < 1e-15 && e.y == 0.0);
        let h = closest_on_triangle(v(1., 1., 0.), &t);
        assert!((h.x - 0.5).abs() < 1e-15 && (h.y - 0.5).abs() < 1e-15);
        let deg = [v(0., 0., 0.), v(1., 0., 0.), v(2., 0., 0.)];
        assert_eq!(closest_on_triangle(v(1.5, 1., 0.), &deg), v(1.5, 0., 0.));
    }

    #[test]
    fn nondegenerate_variant_regions() {
        let (a, b, c) = (v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.));
        assert_eq!(
            closest_on_nondegenerate_triangle(v(-1., -1., 3.), a, b, c),
            a
        );
        assert_eq!(
            closest_on_nondegenerate_triangle(v(0.25, 0.25, 3.), a, b, c),
            v(0.25, 0.25, 0.)
        );
        assert_eq!(
            closest_on_nondegenerate_triangle(v(0.5, -1., 0.), a, b, c),
            v(0.5, 0., 0.)
        );
        let p = closest_on_nondegenerate_triangle(v(1., 1., 0.), a, b, c);
        assert!(p.distance(v(0.5, 0.5, 0.)) < 1e-15);
        assert_eq!(closest_on_segment(v(3., 1., 0.), a, a), a);
        assert_eq!(closest_on_segment(v(3., 1., 0.), a, b), b);
    }

    #[test]
    fn segment_segment_cases() {
        // Skew perpendicular segments one unit apart.
        let d =
            segment_segment_distance(v(-1., 0., 0.), v(1., 0., 0.), v(0., -1., 1.), v(0., 1., 1.));
        assert!((d - 1.0).abs() < 1e-15);
        // Parallel, overlapping: distance between the lines.
        let d =
            segment_segment_distance(v(0., 0., 0.), v(2., 0., 0.), v(1., 0.5, 0.), v(3., 0.5, 0.));
        assert!((d - 0.5).abs() < 1e-15);
        // Collinear, apart: endpoint to endpoint.
        let d =
            segment_segment_distance(v(0., 0., 0.), v(1., 0., 0.), v(3., 0., 0.), v(4., 0., 0.));
        assert!((d - 2.0).abs() < 1e-15);
        // Points.
        let d =
            segment_segment_distance(v(0., 0., 0.), v(0., 0., 0.), v(0., 3., 4.), v(0., 3., 4.));
        assert!((d - 5.0).abs() < 1e-15);
        // Closest to an endpoint of one, interior of the other.
        let d =
            segment_segment_distance(v(0., 0., 0.), v(1., 0., 0.), v(2., -1., 0.), v(2., 1., 0.));
        assert!((d - 1.0).abs() < 1e-15);
    }

    #[test]
    fn triangle_triangle_distances() {
        let t = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
        // Parallel copy above: the plane gap.
        let up = t.map(|p| p + v(0.1, 0.1, 0.3));
        assert!((disjoint_triangle_distance(&t, &up, 0.0) - 0.3).abs() < 1e-15);
        // Edge against edge, crossed: the segments' gap (Pythagoras on the x/z offsets).
        // Edge over edge (every corner is farther than 0.6): the gap 0.5 between the edge
        // x = 0.5, z = 0.5 and t's edge on the x axis.
        let e = [v(0.5, -1., 0.5), v(0.5, 1., 0.5), v(0.5, 0., 3.)];
        assert!((disjoint_triangle_distance(&t, &e, 0.0) - 0.5).abs() < 1e-15);
        // Vertex over the face interior.
        let p = [v(0.2, 0.2, 0.7), v(0.2, 0.2, 3.0), v(0.3, 0.4, 3.0)];
        assert!((disjoint_triangle_distance(&t, &p, 0.0) - 0.7).abs() < 1e-15);
        // Symmetric, and the early exit returns something below the threshold.
        assert_eq!(
            disjoint_triangle_distance(&p, &t, 0.0),
            disjoint_triangle_distance(&t, &p, 0.0)
        );
        assert!(disjoint_triangle_distance(&t, &p, 1.0) < 1.0);
        // A degenerate (segment) triangle.
        let seg = [v(0., 0., 2.), v(1., 1., 2.), v(2., 2., 2.)];
        assert!((disjoint_triangle_distance(&t, &seg, 0.0) - 2.0).abs() < 1e-15);
    }

    #[test]
    fn plane_gap_bounds_the_distance() {
        let f = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
        let above = [v(5., 5., 0.5), v(6., 5., 0.7), v(5., 6., 2.)];
        assert!((plane_gap_lower_bound(&f, &above) - 0.5).abs() < 1e-15);
        assert!(plane_gap_lower_bound(&f, &above) <= disjoint_triangle_distance(&f, &above, 0.0));
        let below = above.map(|p| v(p.x, p.y, -p.z));
        assert!((plane_gap_lower_bound(&f, &below) - 0.5).abs() < 1e-15);
        let across = [v(5., 5., -0.5), v(6., 5., 0.7), v(5., 6., 2.)];
        assert_eq!(plane_gap_lower_bound(&f, &across), 0.0);
    }

    #[test]
    fn samples_cover_the_triangle() {
        let t = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
        let mut n = 0;
        for_each_sample(&t, 4, false, |_| n += 1);
        assert_eq!(n, 15);
        let mut m = 0;
        for_each_sample(&t, 4, true, |_| m += 1);
        assert_eq!(m, 12);
        assert_eq!(sample_resolution(&t, 0.5, 8), 3);
    }
}
