//! Exact (Shewchuk-predicate) segment/triangle and triangle/triangle tests on closed sets.
//!
//! Used where this stage must *know*, not estimate: validating tunnel strips inside one cube,
//! and the per-cube checks of the tests. Closed-set semantics: touching counts as intersecting.

use super::geom::{cross, orient2d, orient3d, sub, V3};

/// Projection of `p` dropping coordinate `axis` (exact: no arithmetic).
#[inline]
fn drop_axis(p: V3, axis: usize) -> [f64; 2] {
    [p[(axis + 1) % 3], p[(axis + 2) % 3]]
}

/// The axis along which triangle `t` has its largest normal component.
fn dominant_axis(t: &[V3; 3]) -> usize {
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let a = n.map(f64::abs);
    if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    }
}

/// True when the three points are collinear (exactly).
pub(crate) fn is_degenerate(t: &[V3; 3]) -> bool {
    (0..3).all(|axis| {
        orient2d(
            drop_axis(t[0], axis),
            drop_axis(t[1], axis),
            drop_axis(t[2], axis),
        ) == 0.0
    })
}

#[inline]
fn sgn(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Closed 2D segments `ab` and `cd` share a point.
fn segments_intersect_2d(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let o1 = sgn(orient2d(a, b, c));
    let o2 = sgn(orient2d(a, b, d));
    let o3 = sgn(orient2d(c, d, a));
    let o4 = sgn(orient2d(c, d, b));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    (o1 == 0 && on(a, b, c))
        || (o2 == 0 && on(a, b, d))
        || (o3 == 0 && on(c, d, a))
        || (o4 == 0 && on(c, d, b))
}

/// Closed 2D point-in-triangle (either orientation).
fn point_in_triangle_2d(p: [f64; 2], t: [[f64; 2]; 3]) -> bool {
    let s = [
        sgn(orient2d(t[0], t[1], p)),
        sgn(orient2d(t[1], t[2], p)),
        sgn(orient2d(t[2], t[0], p)),
    ];
    !(s.contains(&1) && s.contains(&-1))
}

fn coplanar_segment_triangle(s0: V3, s1: V3, t: &[V3; 3]) -> bool {
    let ax = dominant_axis(t);
    let q = t.map(|p| drop_axis(p, ax));
    let (a, b) = (drop_axis(s0, ax), drop_axis(s1, ax));
    point_in_triangle_2d(a, q)
        || point_in_triangle_2d(b, q)
        || (0..3).any(|i| segments_intersect_2d(a, b, q[i], q[(i + 1) % 3]))
}

/// The closed segment `s0 s1` and the closed non-degenerate triangle `t` share a point.
pub(crate) fn segment_hits_triangle(s0: V3, s1: V3, t: &[V3; 3]) -> bool {
    let o0 = sgn(orient3d(t[0], t[1], t[2], s0));
    let o1 = sgn(orient3d(t[0], t[1], t[2], s1));
    if o0 * o1 > 0 {
        return false;
    }
    if o0 == 0 && o1 == 0 {
        return coplanar_segment_triangle(s0, s1, t);
    }
    let e = [
        sgn(orient3d(s0, s1, t[0], t[1])),
        sgn(orient3d(s0, s1, t[1], t[2])),
        sgn(orient3d(s0, s1, t[2], t[0])),
    ];
    !(e.contains(&1) && e.contains(&-1))
}

/// Closed non-degenerate triangles share a point.
pub(crate) fn triangles_intersect(t1: &[V3; 3], t2: &[V3; 3]) -> bool {
    (0..3).any(|i| segment_hits_triangle(t1[i], t1[(i + 1) % 3], t2))
        || (0..3).any(|i| segment_hits_triangle(t2[i], t2[(i + 1) % 3], t1))
}

/// Two mesh triangles (vertex ids and positions) intersect anywhere other than in the vertices
/// or edge they share (or are duplicates).
pub(crate) fn triangles_conflict(i1: [u32; 3], t1: &[V3; 3], i2: [u32; 3], t2: &[V3; 3]) -> bool {
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|a| (0..3).map(move |b| (a, b)))
        .filter(|&(a, b)| i1[a] == i2[b])
        .collect();
    match shared.len() {
        0 => triangles_intersect(t1, t2),
        1 => {
            let (a, b) = shared[0];
            let o1 = [t1[(a + 1) % 3], t1[(a + 2) % 3]];
            let o2 = [t2[(b + 1) % 3], t2[(b + 2) % 3]];
            segment_hits_triangle(o1[0], o1[1], t2) || segment_hits_triangle(o2[0], o2[1], t1)
        }
        2 => {
            let x = t1[3 - shared[0].0 - shared[1].0];
            let y = t2[3 - shared[0].1 - shared[1].1];
            let (u, w) = (t1[shared[0].0], t1[shared[1].0]);
            if orient3d(u, w, x, y) != 0.0 {
                return false;
            }
            let ax = dominant_axis(t1);
            let p = |v: V3| drop_axis(v, ax);
            sgn(orient2d(p(u), p(w), p(x))) * sgn(orient2d(p(u), p(w), p(y))) >= 0
        }
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basic_configurations() {
        let t = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]];
        assert!(segment_hits_triangle([0.2, 0.2, -1.], [0.2, 0.2, 1.], &t));
        assert!(!segment_hits_triangle([0.8, 0.8, -1.], [0.8, 0.8, 1.], &t));
        assert!(segment_hits_triangle([0.5, 0.5, 0.], [0.5, 0.5, 1.], &t)); // touches edge
        assert!(segment_hits_triangle([-1., 0.1, 0.], [2., 0.1, 0.], &t)); // coplanar
        let u = [[0.2, 0.2, -1.], [0.2, 0.2, 1.], [3., 3., 0.]];
        assert!(triangles_intersect(&t, &u));
        let far = [[5., 5., 5.], [6., 5., 5.], [5., 6., 5.]];
        assert!(!triangles_intersect(&t, &far));
        // Shared edge, folded flat onto each other vs. properly hinged.
        let flat = [[0., 0., 0.], [1., 0., 0.], [0.3, 0.3, 0.]];
        assert!(triangles_conflict([0, 1, 2], &t, [0, 1, 3], &flat));
        let hinge = [[0., 0., 0.], [1., 0., 0.], [0.3, -0.3, 0.]];
        assert!(!triangles_conflict([0, 1, 2], &t, [0, 1, 3], &hinge));
        // Shared vertex only.
        let v = [[0., 0., 0.], [-1., 0., 0.], [0., -1., 0.2]];
        assert!(!triangles_conflict([0, 1, 2], &t, [0, 4, 5], &v));
        let w = [[0., 0., 0.], [0.5, 0.1, 0.], [0.1, 0.5, 0.]];
        assert!(triangles_conflict([0, 1, 2], &t, [0, 4, 5], &w));
        assert!(is_degenerate(&[[0., 0., 0.], [1., 1., 1.], [2., 2., 2.]]));
        assert!(!is_degenerate(&t));
    }
}
