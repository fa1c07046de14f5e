//! Small 3-vector helpers, the point–triangle closest point, solid angles and sampling used
//! by the mesh-optimization stages (dissertation §4.3.2–4.3.3).

/// A point or vector in 3D.
pub(crate) type P3 = [f64; 3];

#[inline]
pub(crate) fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn scale(a: P3, s: f64) -> P3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub(crate) fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn norm2(a: P3) -> f64 {
    dot(a, a)
}

#[inline]
pub(crate) fn norm(a: P3) -> f64 {
    norm2(a).sqrt()
}

#[inline]
pub(crate) fn dist(a: P3, b: P3) -> f64 {
    norm(sub(a, b))
}

/// `a + t (b − a)`.
#[inline]
pub(crate) fn lerp(a: P3, b: P3, t: f64) -> P3 {
    add(a, scale(sub(b, a), t))
}

/// Unit vector along `a`, or `None` for a zero (or non-finite) vector.
#[inline]
pub(crate) fn normalized(a: P3) -> Option<P3> {
    let l = norm(a);
    (l > 0.0 && l.is_finite()).then(|| scale(a, 1.0 / l))
}

/// `(b − a) × (c − a)`: the face normal scaled by twice the area.
#[inline]
pub(crate) fn tri_normal(t: &[P3; 3]) -> P3 {
    cross(sub(t[1], t[0]), sub(t[2], t[0]))
}

/// Axis-aligned box `(min, max)` of a set of points.
pub(crate) fn bbox_of(points: impl IntoIterator<Item = P3>) -> (P3, P3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The point of the closed triangle `t` closest to `p` (Ericson, *Real-Time Collision
/// Detection*, §5.1.5: Voronoi regions of the vertices, edges and face). Works for degenerate
/// triangles too (falls back to the closest point on the three edges).
pub(crate) fn closest_on_triangle(p: P3, t: &[P3; 3]) -> P3 {
    let [a, b, c] = *t;
    let ab = sub(b, a);
    let ac = sub(c, a);
    if norm2(cross(ab, ac)) <= f64::MIN_POSITIVE {
        return closest_on_degenerate(p, t);
    }
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return lerp(a, b, d1 / (d1 - d3));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return lerp(a, c, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return lerp(b, c, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    add(a, add(scale(ab, v), scale(ac, w)))
}

/// Closest point on the segment `[a, b]`.
pub(crate) fn closest_on_segment(p: P3, a: P3, b: P3) -> P3 {
    let ab = sub(b, a);
    let l2 = norm2(ab);
    if l2 <= 0.0 {
        return a;
    }
    let t = (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0);
    lerp(a, b, t)
}

fn closest_on_degenerate(p: P3, t: &[P3; 3]) -> P3 {
    let mut best = t[0];
    let mut bd = f64::INFINITY;
    for i in 0..3 {
        let q = closest_on_segment(p, t[i], t[(i + 1) % 3]);
        let d = norm2(sub(p, q));
        if d < bd {
            bd = d;
            best = q;
        }
    }
    best
}

/// Distance from `p` to the closed triangle `t`.
#[inline]
pub(crate) fn point_triangle_distance(p: P3, t: &[P3; 3]) -> f64 {
    dist(p, closest_on_triangle(p, t))
}

/// Barycentric sample points of a triangle on a regular grid with `k` subdivisions per edge
/// (`k = 1`: the three corners; `k ≥ 2` adds edge and interior points; the centroid is always
/// included), without the corners when `skip_corners`. Calls `f` for each point.
pub(crate) fn for_each_sample(t: &[P3; 3], k: usize, skip_corners: bool, mut f: impl FnMut(P3)) {
    let k = k.max(1);
    for i in 0..=k {
        for j in 0..=(k - i) {
            if skip_corners && (i == k || j == k || i + j == 0) {
                continue;
            }
            let u = i as f64 / k as f64;
            let v = j as f64 / k as f64;
            let w = 1.0 - u - v;
            f(add(add(scale(t[0], w), scale(t[1], u)), scale(t[2], v)));
        }
    }
    if k < 3 {
        f(scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0));
    }
}

/// Grid resolution for [`for_each_sample`] so that samples are at most about `spacing` apart,
/// capped at `max_k`.
pub(crate) fn sample_resolution(t: &[P3; 3], spacing: f64, max_k: usize) -> usize {
    let e = dist(t[0], t[1]).max(dist(t[1], t[2])).max(dist(t[2], t[0]));
    if spacing.is_nan() || spacing <= 0.0 || !e.is_finite() {
        return 1;
    }
    ((e / spacing).ceil() as usize).clamp(1, max_k.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let t = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]];
        assert!(dist(closest_on_triangle([0.2, 0.2, 1.], &t), [0.2, 0.2, 0.]) < 1e-15);
        assert_eq!(closest_on_triangle([-1., -1., 0.], &t), [0., 0., 0.]);
        assert_eq!(closest_on_triangle([2., -1., 0.], &t), [1., 0., 0.]);
        let e = closest_on_triangle([0.5, -1., 3.], &t);
        assert!((e[0] - 0.5).abs() < 1e-15 && e[1] == 0.0);
        let h = closest_on_triangle([1., 1., 0.], &t);
        assert!((h[0] - 0.5).abs() < 1e-15 && (h[1] - 0.5).abs() < 1e-15);
        let deg = [[0., 0., 0.], [1., 0., 0.], [2., 0., 0.]];
        assert_eq!(closest_on_triangle([1.5, 1., 0.], &deg), [1.5, 0., 0.]);
    }

    #[test]
    fn samples_cover_the_triangle() {
        let t = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]];
        let mut n = 0;
        for_each_sample(&t, 4, false, |_| n += 1);
        assert_eq!(n, 15);
        let mut m = 0;
        for_each_sample(&t, 4, true, |_| m += 1);
        assert_eq!(m, 12);
        assert_eq!(sample_resolution(&t, 0.5, 8), 3);
    }
}
