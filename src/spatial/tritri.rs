//! Exact triangle–triangle and segment–triangle intersection tests on Shewchuk's adaptive
//! orientation predicates (the `robust` crate), and the classification of mesh face pairs that
//! share a vertex or an edge exactly as CGAL's `Polygon_mesh_processing::self_intersections`
//! (and the soup port in `meshcheck`) treat them.
//!
//! Every test here is on **closed** triangles and segments: touching at a single point counts as
//! intersecting. All decisions are made from signs of exact determinants, so the answers are
//! exact for any finite `f64` input (barring overflow/underflow of the predicates' expansions,
//! which needs coordinates beyond ~1e±150).
//!
//! Where the logic comes from:
//! - Orientation predicates: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and
//!   Fast Robust Geometric Predicates", DCG 18 (1997), via `robust::orient3d`/`orient2d`.
//! - Non-coplanar triangles: two closed triangles in different planes meet iff an edge of one
//!   meets the other. (Both meet the line `L` where their planes cross in a segment whose
//!   endpoints lie on their boundaries; if the two segments overlap, the larger of the two lower
//!   endpoints lies on an edge of one triangle and inside the other.) Early rejection by plane
//!   sides as in Guigue & Devillers, "Fast and robust triangle-triangle overlap test using
//!   orientation predicates", JGT 8(1), 2003 — the algorithm behind CGAL's
//!   `do_intersect(Triangle_3, Triangle_3)`.
//! - Segment crossing a triangle's plane: the crossing point is in the closed triangle iff the
//!   three signed volumes `[p, q, a, b]`, `[p, q, b, c]`, `[p, q, c, a]` have no two strictly
//!   opposite signs (each is the in-plane orientation of the crossing point against one edge,
//!   scaled by the same non-zero factor `n · (q − p)`).
//! - Coplanar configurations: projection to the coordinate plane in which the reference
//!   triangle's projection has non-zero exact area (an affine bijection of the common plane, so
//!   all 2D orientations keep their meaning), then the separating-axis theorem for convex
//!   polygons with `orient2d`: closed convex polygons are disjoint iff the line of some edge of
//!   either one strictly separates them.
//! - Face pairs of a mesh: CGAL 5.5 `internal::do_faces_intersect`
//!   (`Polygon_mesh_processing/self_intersections.h`) and `meshcheck.cpp`'s
//!   `soup_faces_intersect`: same three vertices ⇒ intersect; shared edge ⇒ intersect iff the
//!   four points are coplanar and both third vertices lie strictly on the same side of the edge
//!   (folded onto each other); one shared vertex ⇒ intersect iff the edge opposite the shared
//!   vertex in either face meets the other face; otherwise the closed triangle test.

use crate::geom::{tri_normal, Vec3};

/// Sign (`-1`, `0`, `+1`) of the orientation of `d` relative to the plane through `a, b, c`:
/// `+1` when `d` lies on the side the normal `(b − a) × (c − a)` points to, i.e. the sign of
/// `det[b − a, c − a, d − a]`. Exact (Shewchuk's adaptive `orient3d`).
#[inline]
pub fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> i8 {
    // Fast exact path for a plane normal to a coordinate axis k (common in CAD models, where
    // Shewchuk's adaptive stages are slow for exactly coplanar points): with (b − a)_k =
    // (c − a)_k = 0, det[b − a, c − a, d − a] = (d_k − a_k) · ((b − a) × (c − a))_k, and the
    // latter factor is the orientation of the projection dropping axis k.
    for k in 0..3 {
        if a[k] == b[k] && a[k] == c[k] {
            return match d[k].partial_cmp(&a[k]) {
                Some(std::cmp::Ordering::Greater) => orient2d(proj(a, k), proj(b, k), proj(c, k)),
                Some(std::cmp::Ordering::Less) => -orient2d(proj(a, k), proj(b, k), proj(c, k)),
                _ => 0,
            };
        }
    }
    // Shewchuk's orient3d(pa, pb, pc, pd) = det[pa − pd, pb − pd, pc − pd], which is positive when
    // pd lies *below* the plane (pa, pb, pc counter-clockwise seen from above): the opposite of
    // our convention.
    let v = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    -sign(v)
}

/// Sign of the 2D orientation of `(a, b, c)`: `+1` counter-clockwise, `-1` clockwise, `0`
/// collinear. Exact (Shewchuk's adaptive `orient2d`).
#[inline]
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    sign(crate::geom::orient2d(a, b, c))
}

/// True when `a, b, c` are exactly collinear (including coincident points): the triangle is
/// degenerate (zero area). Exact: `(b − a) × (c − a) = 0` iff its three components, which are
/// the orientations of the three coordinate-plane projections, all vanish.
pub fn is_collinear(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    (0..3).all(|drop| orient2d(proj(a, drop), proj(b, drop), proj(c, drop)) == 0)
}

/// True when the four points are exactly coplanar.
#[inline]
pub fn are_coplanar(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> bool {
    orient3d(a, b, c, d) == 0
}

/// For four coplanar points with `p, q, r` not collinear: true when `r` and `s` lie strictly on
/// the same side of the line `pq` inside their common plane. This is CGAL's
/// `coplanar_orientation(p, q, r, s) == POSITIVE`.
pub fn coplanar_same_side(p: [f64; 3], q: [f64; 3], r: [f64; 3], s: [f64; 3]) -> bool {
    let drop = projection_axis(&[p, q, r]);
    let (p2, q2) = (proj(p, drop), proj(q, drop));
    let or = orient2d(p2, q2, proj(r, drop));
    let os = orient2d(p2, q2, proj(s, drop));
    or != 0 && or == os
}

/// Exact test whether the closed segment `s` meets the closed triangle `t`.
///
/// `t` must not be degenerate (see [`is_collinear`]); `s` may be a single point.
pub fn segment_triangle_intersect(s: [[f64; 3]; 2], t: &[[f64; 3]; 3]) -> bool {
    let sp = orient3d(t[0], t[1], t[2], s[0]);
    let sq = orient3d(t[0], t[1], t[2], s[1]);
    segment_triangle_with_sides(s, t, sp, sq)
}

/// Exact test whether the closed triangles `a` and `b` intersect (share at least one point).
/// Coplanar overlap, touching at a vertex or along an edge all count.
///
/// Both triangles must be non-degenerate (see [`is_collinear`]); the answer is unspecified
/// otherwise. Symmetric in `a` and `b` and invariant under any permutation of either
/// triangle's vertices.
pub fn triangles_intersect(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> bool {
    let da = sides(b, a);
    if strictly_one_side(da) {
        return false;
    }
    if da == [0, 0, 0] {
        return coplanar_triangles_intersect(a, b);
    }
    let db = sides(a, b);
    if strictly_one_side(db) {
        return false;
    }
    // Non-coplanar: an edge of one triangle meets the other triangle.
    (0..3).any(|i| {
        let j = (i + 1) % 3;
        segment_triangle_with_sides([a[i], a[j]], b, da[i], da[j])
    }) || (0..3).any(|i| {
        let j = (i + 1) % 3;
        segment_triangle_with_sides([b[i], b[j]], a, db[i], db[j])
    })
}

/// How two faces given by vertex indices share vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sharing {
    /// No common vertex index.
    None,
    /// Exactly one common vertex: `a[ia] == b[ib]`.
    Vertex {
        /// Corner of the first face.
        ia: usize,
        /// Corner of the second face.
        ib: usize,
    },
    /// Exactly two common vertices (a common edge): `a[ia0] == b[ib0]`, `a[ia1] == b[ib1]`.
    Edge {
        /// Corners of the first face on the shared edge.
        ia: [usize; 2],
        /// The matching corners of the second face.
        ib: [usize; 2],
    },
    /// The same three vertices (a duplicate face, in either orientation).
    All,
}

/// Classifies how faces `a` and `b` share vertex indices. Faces are expected to have three
/// distinct indices each.
pub fn sharing(a: [u32; 3], b: [u32; 3]) -> Sharing {
    let mut sa = [0usize; 3];
    let mut sb = [0usize; 3];
    let mut n = 0;
    for (i, va) in a.iter().enumerate() {
        for (j, vb) in b.iter().enumerate() {
            if va == vb && n < 3 {
                sa[n] = i;
                sb[n] = j;
                n += 1;
            }
        }
    }
    match n {
        0 => Sharing::None,
        1 => Sharing::Vertex {
            ia: sa[0],
            ib: sb[0],
        },
        2 => Sharing::Edge {
            ia: [sa[0], sa[1]],
            ib: [sb[0], sb[1]],
        },
        _ => Sharing::All,
    }
}

/// Whether two faces of a mesh intersect in the sense of CGAL's self-intersection test (and
/// `meshcheck`): more than the vertices or edge they legitimately share.
///
/// `a` and `b` index `positions`; both faces must be non-degenerate, and faces are compared by
/// index, so exactly coincident points must be welded first (see
/// [`crate::mesh::ExactWeld`]). Rules (CGAL 5.5 `internal::do_faces_intersect`):
/// - same three vertices: intersect (a duplicate face overlaps itself);
/// - shared edge `pq`, third vertices `r` (of `a`) and `s` (of `b`): intersect iff the four points
///   are coplanar and `r`, `s` lie strictly on the same side of `pq` (the faces are folded onto
///   each other);
/// - one shared vertex: intersect iff the edge of `b` opposite the shared vertex meets `a`, or
///   the edge of `a` opposite it meets `b`;
/// - nothing shared: [`triangles_intersect`] (touching counts).
pub fn faces_intersect(positions: &[[f64; 3]], a: [u32; 3], b: [u32; 3]) -> bool {
    let p = |v: u32| positions[v as usize];
    faces_intersect_at(a, &a.map(p), b, &b.map(p))
}

/// [`faces_intersect`] with the corners given: faces `a` and `b` (vertex indices, which decide
/// what they share) with corner positions `ta` and `tb`. Used to test a hypothetical state
/// (a vertex at a new position) without writing it into a position buffer.
pub fn faces_intersect_at(
    a: [u32; 3],
    ta: &[[f64; 3]; 3],
    b: [u32; 3],
    tb: &[[f64; 3]; 3],
) -> bool {
    match sharing(a, b) {
        Sharing::All => true,
        Sharing::Edge { ia, ib } => {
            let ra = 3 - ia[0] - ia[1];
            let rb = 3 - ib[0] - ib[1];
            let (pp, pq, pr, ps) = (ta[ia[0]], ta[ia[1]], ta[ra], tb[rb]);
            are_coplanar(pp, pq, pr, ps) && coplanar_same_side(pp, pq, pr, ps)
        }
        Sharing::Vertex { ia, ib } => shared_vertex_faces_intersect(ta, tb, ia, ib),
        Sharing::None => triangles_intersect(ta, tb),
    }
}

// ---------------------------------------------------------------------------------------------
// internals

/// Faces sharing exactly the vertex `ta[ia] == tb[ib]`: intersect iff the edge of `tb` opposite
/// the shared vertex meets `ta` or the edge of `ta` opposite it meets `tb`. When `tb` lies in
/// `ta`'s plane both tests are planar and share one projection.
fn shared_vertex_faces_intersect(
    ta: &[[f64; 3]; 3],
    tb: &[[f64; 3]; 3],
    ia: usize,
    ib: usize,
) -> bool {
    let s_a = [ta[(ia + 1) % 3], ta[(ia + 2) % 3]];
    let s_b = [tb[(ib + 1) % 3], tb[(ib + 2) % 3]];
    let sp = orient3d(ta[0], ta[1], ta[2], s_b[0]);
    let sq = orient3d(ta[0], ta[1], ta[2], s_b[1]);
    if sp == sq && sp != 0 {
        // `tb` meets `ta`'s plane only at the shared vertex, so `ta ∩ tb` is that vertex: the
        // second test (edge of `ta` against `tb`) is false too, since that edge avoids it.
        return false;
    }
    if sp == 0 && sq == 0 {
        let d = projection_axis(ta);
        let ta2 = ta.map(|x| proj(x, d));
        let tb2 = tb.map(|x| proj(x, d));
        return segment_triangle_intersect_2d(s_b.map(|x| proj(x, d)), &ta2)
            || segment_triangle_intersect_2d(s_a.map(|x| proj(x, d)), &tb2);
    }
    segment_triangle_with_sides(s_b, ta, sp, sq) || segment_triangle_intersect(s_a, tb)
}

#[inline]
fn sign(v: f64) -> i8 {
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

#[inline]
fn c3(p: [f64; 3]) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Drops coordinate `drop` (0 = x, 1 = y, 2 = z), keeping the other two in cyclic order so the
/// projection's orientation equals the sign of the dropped normal component.
#[inline]
fn proj(p: [f64; 3], drop: usize) -> [f64; 2] {
    [p[(drop + 1) % 3], p[(drop + 2) % 3]]
}

/// A coordinate axis along which the projection of the non-degenerate triangle `t` keeps a
/// non-zero exact area. Tries the axis of the largest approximate normal component first.
fn projection_axis(t: &[[f64; 3]; 3]) -> usize {
    let [a, b, c] = t.map(Vec3::from);
    let n = tri_normal(a, b, c).abs();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
    order
        .into_iter()
        .find(|&d| orient2d(proj(t[0], d), proj(t[1], d), proj(t[2], d)) != 0)
        .unwrap_or(order[0])
}

/// Orientations of the three vertices of `t` against the plane of `plane`.
#[inline]
fn sides(plane: &[[f64; 3]; 3], t: &[[f64; 3]; 3]) -> [i8; 3] {
    [
        orient3d(plane[0], plane[1], plane[2], t[0]),
        orient3d(plane[0], plane[1], plane[2], t[1]),
        orient3d(plane[0], plane[1], plane[2], t[2]),
    ]
}

#[inline]
fn strictly_one_side(s: [i8; 3]) -> bool {
    (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0)
}

/// True when no two of the signs are strictly opposite.
#[inline]
fn no_opposite_signs(s: [i8; 3]) -> bool {
    !(s.contains(&1) && s.contains(&-1))
}

/// Segment–triangle test given the sides `sp`, `sq` of the endpoints against `t`'s plane.
fn segment_triangle_with_sides(s: [[f64; 3]; 2], t: &[[f64; 3]; 3], sp: i8, sq: i8) -> bool {
    if sp == sq && sp != 0 {
        return false; // both endpoints strictly on one side
    }
    if sp == 0 && sq == 0 {
        return coplanar_segment_triangle(s, t);
    }
    // The segment crosses (or touches) the plane in exactly one point X; X is in the closed
    // triangle iff the volumes against the three edge lines have no opposite signs.
    let [p, q] = s;
    no_opposite_signs([
        orient3d(p, q, t[0], t[1]),
        orient3d(p, q, t[1], t[2]),
        orient3d(p, q, t[2], t[0]),
    ])
}

fn coplanar_segment_triangle(s: [[f64; 3]; 2], t: &[[f64; 3]; 3]) -> bool {
    let d = projection_axis(t);
    let t2 = [proj(t[0], d), proj(t[1], d), proj(t[2], d)];
    segment_triangle_intersect_2d([proj(s[0], d), proj(s[1], d)], &t2)
}

fn coplanar_triangles_intersect(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> bool {
    let d = projection_axis(b);
    let a2 = [proj(a[0], d), proj(a[1], d), proj(a[2], d)];
    let b2 = [proj(b[0], d), proj(b[1], d), proj(b[2], d)];
    triangles_intersect_2d(&a2, &b2)
}

/// Closed 2D triangles (non-degenerate) are disjoint iff the line of some edge of either one
/// strictly separates them (separating-axis theorem for convex polygons: the candidate axes are
/// the edge normals).
fn triangles_intersect_2d(a: &[[f64; 2]; 3], b: &[[f64; 2]; 3]) -> bool {
    !(edge_separates(a, b) || edge_separates(b, a))
}

/// True when some edge line of `t` has all of `pts` strictly on its outer side.
fn edge_separates(t: &[[f64; 2]; 3], pts: &[[f64; 2]]) -> bool {
    let o = orient2d(t[0], t[1], t[2]);
    (0..3).any(|i| {
        let (p, q) = (t[i], t[(i + 1) % 3]);
        pts.iter().all(|&x| orient2d(p, q, x) * o < 0)
    })
}

/// Closed segment (possibly a point) against a closed non-degenerate triangle in 2D: disjoint
/// iff an edge line of the triangle or the segment's own line strictly separates them (the
/// edges of their Minkowski difference are parallel to those lines).
fn segment_triangle_intersect_2d(s: [[f64; 2]; 2], t: &[[f64; 2]; 3]) -> bool {
    if edge_separates(t, &s) {
        return false;
    }
    if s[0] == s[1] {
        return true;
    }
    let sides = t.map(|x| orient2d(s[0], s[1], x));
    !(sides.iter().all(|&o| o > 0) || sides.iter().all(|&o| o < 0))
}

#[cfg(test)]
#[path = "tritri_tests.rs"]
mod tests;
