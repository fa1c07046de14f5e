//! Small `[f64; 3]` vector helpers shared by the low-poly stages.

/// A point or vector in 3D.
pub(crate) type V3 = [f64; 3];

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn norm2(a: V3) -> f64 {
    dot(a, a)
}

#[inline]
pub(crate) fn norm(a: V3) -> f64 {
    norm2(a).sqrt()
}

#[inline]
pub(crate) fn dist(a: V3, b: V3) -> f64 {
    norm(sub(a, b))
}

/// `a + t (b − a)`.
#[inline]
pub(crate) fn lerp(a: V3, b: V3, t: f64) -> V3 {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}

/// Unit vector along `a`, or `None` when `a` is (numerically) zero or not finite.
#[inline]
pub(crate) fn normalized(a: V3) -> Option<V3> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

/// Twice the area vector of triangle `abc` (`(b − a) × (c − a)`).
#[inline]
pub(crate) fn tri_normal(a: V3, b: V3, c: V3) -> V3 {
    cross(sub(b, a), sub(c, a))
}

/// Exact 2D orientation: positive when `a, b, c` are counter-clockwise.
#[inline]
pub(crate) fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let p = |v: [f64; 2]| robust::Coord { x: v[0], y: v[1] };
    robust::orient2d(p(a), p(b), p(c))
}
