//! Triangulations of one cube's patches, each embedded by construction or checked exactly.
//!
//! Points of a patch are its loop's iso-points (on cube edges, strictly between corners) in
//! loop order, optionally followed by one extra vertex (index `n`). Triangles keep the loop
//! orientation, so their normals point to the outside (`f > d`) side.
//!
//! - [`fan`] around a point `x` strictly inside the cube is embedded: seen from `x`, each
//!   triangle `(a_i, a_{i+1}, x)` covers exactly the rays through the loop segment `a_i a_{i+1}`,
//!   which lies on the cube surface, and the loop is simple there (the radial projection from an
//!   interior point of a convex body onto its boundary is a bijection). It touches the cube
//!   surface only along its loop segments.
//! - [`plain_disk`] (the template triangulation, no extra vertex) projects the loop onto the
//!   coordinate plane most orthogonal to its Newell normal — dropping a coordinate, so exactly —
//!   and ear-clips it with exact predicates when the projection is a simple polygon. Disjoint
//!   projected triangles lift to triangles that meet only in their shared lifted edges and
//!   vertices (a height field), so the result is embedded. Chords between two iso-points on one
//!   cube face are refused (they would lie on the face shared with the neighbouring cube).
//! - [`strip`] zips two loops of a tunnel; it is kept only when exact tests find no
//!   intersection inside the strip or with the cube's other triangles.

use super::tables::edges_share_face;
use crate::geom::{orient2d, Vec3};
use crate::spatial::{faces_intersect, is_collinear, triangles_intersect};

/// A triangle as local point indices.
pub(crate) type LocalTri = [u8; 3];

/// Fan around the extra vertex `n`: `(i, i + 1, n)`.
pub(crate) fn fan(n: usize, out: &mut Vec<LocalTri>) {
    for i in 0..n {
        out.push([i as u8, ((i + 1) % n) as u8, n as u8]);
    }
}

/// Newell normal of a closed polygon.
pub(crate) fn newell_normal(pts: &[Vec3]) -> Vec3 {
    let mut n = Vec3::ZERO;
    for i in 0..pts.len() {
        let (u, v) = (pts[i], pts[(i + 1) % pts.len()]);
        n[0] += (u[1] - v[1]) * (u[2] + v[2]);
        n[1] += (u[2] - v[2]) * (u[0] + v[0]);
        n[2] += (u[0] - v[0]) * (u[1] + v[1]);
    }
    n
}

/// Ear-clipping triangulation without extra vertex (see module doc); `None` when the loop's
/// projection is not a simple polygon or no admissible ear exists.
pub(crate) fn plain_disk(pts: &[Vec3], edges: &[u8], out: &mut Vec<LocalTri>) -> bool {
    let n = pts.len();
    if !(3..=12).contains(&n) {
        return false;
    }
    let nn = newell_normal(pts);
    let ax = (0..3)
        .max_by(|&a, &b| nn[a].abs().total_cmp(&nn[b].abs()))
        .unwrap_or(2);
    if nn[ax] == 0.0 {
        return false;
    }
    let sign = if nn[ax] > 0.0 { 1.0 } else { -1.0 };
    let mut q = [[0.0f64; 2]; 12];
    for (i, p) in pts.iter().enumerate() {
        q[i] = [p[(ax + 1) % 3], p[(ax + 2) % 3]];
    }
    let q = &q[..n];
    if !is_simple(q) {
        return false;
    }
    let start = out.len();
    let mut rem: Vec<usize> = (0..n).collect();
    while rem.len() > 3 {
        let Some(k) = (0..rem.len()).find(|&k| is_ear(q, edges, &rem, k, sign)) else {
            out.truncate(start);
            return false;
        };
        let m = rem.len();
        out.push([
            rem[(k + m - 1) % m] as u8,
            rem[k] as u8,
            rem[(k + 1) % m] as u8,
        ]);
        rem.remove(k);
    }
    if orient2d(q[rem[0]], q[rem[1]], q[rem[2]]) * sign <= 0.0 {
        out.truncate(start);
        return false;
    }
    out.push([rem[0] as u8, rem[1] as u8, rem[2] as u8]);
    true
}

fn is_ear(q: &[[f64; 2]], edges: &[u8], rem: &[usize], k: usize, sign: f64) -> bool {
    let m = rem.len();
    let (a, b, c) = (rem[(k + m - 1) % m], rem[k], rem[(k + 1) % m]);
    if orient2d(q[a], q[b], q[c]) * sign <= 0.0 {
        return false;
    }
    if edges_share_face(edges[a], edges[c]) {
        return false;
    }
    rem.iter()
        .all(|&r| r == a || r == b || r == c || !inside_closed(q[r], [q[a], q[b], q[c]], sign))
}

fn inside_closed(p: [f64; 2], t: [[f64; 2]; 3], sign: f64) -> bool {
    (0..3).all(|i| orient2d(t[i], t[(i + 1) % 3], p) * sign >= 0.0)
}

/// Exact simplicity test of a closed 2D polygon (no repeated points, no touching edges).
fn is_simple(q: &[[f64; 2]]) -> bool {
    let n = q.len();
    for i in 0..n {
        for j in i + 1..n {
            if q[i] == q[j] {
                return false;
            }
        }
    }
    for i in 0..n {
        let (a, b) = (q[i], q[(i + 1) % n]);
        for j in i + 1..n {
            let (c, d) = (q[j], q[(j + 1) % n]);
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            if adjacent {
                // Sharing one endpoint: they must not overlap along a line.
                let (shared, other_ab, other_cd) = if j == i + 1 { (b, a, d) } else { (a, b, c) };
                if orient2d(shared, other_ab, other_cd) == 0.0
                    && (other_ab[0] - shared[0]) * (other_cd[0] - shared[0])
                        + (other_ab[1] - shared[1]) * (other_cd[1] - shared[1])
                        > 0.0
                {
                    return false;
                }
            } else if segs_touch(a, b, c, d) {
                return false;
            }
        }
    }
    true
}

fn segs_touch(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let s = |x: f64| (x > 0.0) as i8 - (x < 0.0) as i8;
    let o1 = s(orient2d(a, b, c));
    let o2 = s(orient2d(a, b, d));
    let o3 = s(orient2d(c, d, a));
    let o4 = s(orient2d(c, d, b));
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

/// Zips loop `a` (indices `0..n`) and loop `b` (indices `n..n + m`) into a tube: `a` is walked
/// forwards, `b` backwards (the two boundary loops of an oriented annulus turn in opposite
/// senses). Every start alignment is tried, shortest total first; a candidate is accepted when
/// no chord lies on a cube face and exact tests find no degenerate triangle and no intersection
/// within the strip or with `others` (the cube's remaining triangles, by position).
pub(crate) fn strip(
    a: &[Vec3],
    a_edges: &[u8],
    b: &[Vec3],
    b_edges: &[u8],
    others: &[[[f64; 3]; 3]],
    out: &mut Vec<LocalTri>,
) -> bool {
    let (n, m) = (a.len(), b.len());
    let mut cands: Vec<(f64, usize)> = (0..m).map(|s| (a[0].distance(b[s]), s)).collect();
    cands.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let pos = |i: usize| if i < n { a[i] } else { b[i - n] };
    let edge = |i: usize| if i < n { a_edges[i] } else { b_edges[i - n] };
    for &(_, s) in &cands {
        let start = out.len();
        zip(a, b, s, out);
        let tris = &out[start..];
        let chords_ok = tris.iter().all(|t| {
            (0..3).all(|k| {
                let (u, v) = (t[k] as usize, t[(k + 1) % 3] as usize);
                (u < n) == (v < n) || !edges_share_face(edge(u), edge(v))
            })
        });
        if chords_ok && strip_is_embedded(tris, &pos, others) {
            return true;
        }
        out.truncate(start);
    }
    false
}

fn zip(a: &[Vec3], b: &[Vec3], s: usize, out: &mut Vec<LocalTri>) {
    let (n, m) = (a.len(), b.len());
    let bi = |j: usize| (s + m * 2 - j % m) % m; // j-th step backwards from s
    let (mut i, mut j) = (0usize, 0usize);
    // Steps taken on one loop before the first step on the other. The diagonal (a_i, b_j) of
    // state (i, 0) reappears at (i, m), and that of (0, j) at (n, j): a loop may only be
    // finished once the other pointer has moved past its initial run.
    let (mut i_first, mut j_first) = (None::<usize>, None::<usize>);
    while i < n || j < m {
        let a_allowed = i < n && (i + 1 < n || j_first.is_some_and(|f| j > f));
        let b_allowed = j < m && (j + 1 < m || i_first.is_some_and(|f| i > f));
        let adv_a = match (a_allowed, b_allowed) {
            (true, false) => true,
            (false, true) => false,
            (false, false) => i < n,
            (true, true) => a[(i + 1) % n].distance(b[bi(j)]) <= a[i].distance(b[bi(j + 1)]),
        };
        if adv_a {
            out.push([i as u8, ((i + 1) % n) as u8, (n + bi(j)) as u8]);
            i += 1;
            j_first.get_or_insert(j);
        } else {
            out.push([(n + bi(j + 1)) as u8, (n + bi(j)) as u8, (i % n) as u8]);
            j += 1;
            i_first.get_or_insert(i);
        }
    }
}

fn strip_is_embedded(
    tris: &[LocalTri],
    pos: &dyn Fn(usize) -> Vec3,
    others: &[[[f64; 3]; 3]],
) -> bool {
    let n = tris
        .iter()
        .flat_map(|t| t.iter())
        .map(|&i| i as usize + 1)
        .max()
        .unwrap_or(0);
    let local: Vec<[f64; 3]> = (0..n).map(|i| pos(i).to_array()).collect();
    let ids = |t: &LocalTri| t.map(u32::from);
    let geo = |t: &LocalTri| t.map(|i| local[i as usize]);
    if tris.iter().any(|t| {
        let g = geo(t);
        is_collinear(g[0], g[1], g[2])
    }) {
        return false;
    }
    for (x, tx) in tris.iter().enumerate() {
        if tris[x + 1..]
            .iter()
            .any(|ty| faces_intersect(&local, ids(tx), ids(ty)))
        {
            return false;
        }
        if others.iter().any(|o| triangles_intersect(&geo(tx), o)) {
            return false;
        }
    }
    true
}
