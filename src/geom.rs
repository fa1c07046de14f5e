//! The one small-vector vocabulary of pleat: [`Vec3`] for every point and vector in 3D, plus the
//! few helpers glam does not have with the exact semantics pleat's stages rely on.
//!
//! **Why glam's `DVec3` and not nalgebra's `Vector3<f64>`:** parry3d-f64 (pleat's BVH, closest
//! points and intersection tests) already speaks glam 0.33's `DVec3`, so the spatial layer
//! passes points to parry without conversions; `DVec3` is a plain `#[repr(C)]` triple of `f64`
//! with the layout of `[f64; 3]` (the storage and C layout of mesh positions), concrete
//! (non-generic) and fast in unoptimized test builds; and its `dot`, `cross`, `length` and
//! operators perform exactly the IEEE operations, in the same order, as the hand-written helpers
//! they replace, so outputs stay byte-identical. nalgebra's normalize divides by the length
//! where pleat multiplied by its reciprocal, which would have changed LOD outputs.
//!
//! Storage stays `[f64; 3]` where data crosses a boundary (mesh positions, file readers, the
//! C ABI); arithmetic is done on [`Vec3`] (`Vec3::from(p)`, `v.to_array()`).
//!
//! May import: nothing from the crate (this is the bottom layer).

/// A point or vector in 3D (glam's `DVec3`).
pub use glam::DVec3 as Vec3;

/// `a + t (b − a)` (not glam's `lerp`, which computes `a (1 − t) + b t` and rounds differently).
#[inline]
pub fn lerp(a: Vec3, b: Vec3, t: f64) -> Vec3 {
    a + (b - a) * t
}

/// Unit vector along `a` (`a` times the reciprocal of its length), or `None` when `a` is zero or
/// not finite.
#[inline]
pub fn normalized(a: Vec3) -> Option<Vec3> {
    let l = a.length();
    (l > 0.0 && l.is_finite()).then(|| a * (1.0 / l))
}

/// Barycentric coordinates of `q` (on or near the triangle's plane) with respect to `t`,
/// clamped to the triangle (non-negative, summing to 1).
pub fn barycentric(t: [Vec3; 3], q: Vec3) -> [f64; 3] {
    let v0 = t[1] - t[0];
    let v1 = t[2] - t[0];
    let v2 = q - t[0];
    let d00 = v0.dot(v0);
    let d01 = v0.dot(v1);
    let d11 = v1.dot(v1);
    let d20 = v2.dot(v0);
    let d21 = v2.dot(v1);
    let den = d00 * d11 - d01 * d01;
    if den == 0.0 || !den.is_finite() {
        // Degenerate triangle: the nearest corner.
        let d = t.map(|c| (c - q).length_squared());
        let k = (0..3).min_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap_or(0);
        let mut b = [0.0; 3];
        b[k] = 1.0;
        return b;
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    let b = [1.0 - v - w, v, w].map(|x| x.max(0.0));
    let s = b[0] + b[1] + b[2];
    b.map(|x| x / s)
}

/// `(b − a) × (c − a)`: the normal of triangle `abc` scaled by twice its area.
#[inline]
pub fn tri_normal(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    (b - a).cross(c - a)
}

/// Axis-aligned box `(min, max)` of a set of points (`(+∞, −∞)` when there are none).
pub fn bbox_of(points: impl IntoIterator<Item = Vec3>) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f64::INFINITY);
    let mut hi = Vec3::splat(f64::NEG_INFINITY);
    for p in points {
        lo = Vec3::new(lo.x.min(p.x), lo.y.min(p.y), lo.z.min(p.z));
        hi = Vec3::new(hi.x.max(p.x), hi.y.max(p.y), hi.z.max(p.z));
    }
    (lo, hi)
}

/// Exact 2D orientation (Shewchuk's predicate): positive when `a, b, c` are counter-clockwise,
/// zero when collinear.
#[inline]
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let p = |v: [f64; 2]| robust::Coord { x: v[0], y: v[1] };
    robust::orient2d(p(a), p(b), p(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The glam operations used across the crate round exactly like the hand-written helpers
    /// they replaced (same operations, same order), so outputs stay byte-identical.
    #[test]
    fn glam_rounds_like_the_old_helpers() {
        let a = [0.1, -2.7, 3.3e-5];
        let b = [1e10, 0.3, -7.1];
        let old_dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let old_cross = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let (va, vb) = (Vec3::from(a), Vec3::from(b));
        assert_eq!(va.dot(vb).to_bits(), old_dot.to_bits());
        assert_eq!(va.cross(vb).to_array(), old_cross);
        assert_eq!(
            va.length().to_bits(),
            (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt().to_bits()
        );
        let t = 0.37;
        let old_lerp = [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]));
        assert_eq!(lerp(va, vb, t).to_array(), old_lerp);
        assert_eq!(normalized(Vec3::ZERO), None);
        assert_eq!(bbox_of([va, vb]).0.to_array(), [0.1, -2.7, -7.1]);
        assert!(orient2d([0., 0.], [1., 0.], [0., 1.]) > 0.0);
    }
}
