//! Cube numbering used by pleat's MC33 (our own convention, not Lorensen's or Vega's).
//!
//! - Corner `c ∈ 0..8` sits at `(c & 1, (c >> 1) & 1, (c >> 2) & 1)`: bit `a` is coordinate `a`.
//! - Edge `e = 4·a + k` is parallel to axis `a`; `k` packs the two other coordinates `(u, v)`
//!   (the other axes in increasing order) as `u + 2v`. Its first corner has coordinate `a = 0`.
//! - Face `f = 2·a + s` is the face `coordinate a = s`. Its corners are listed counter-clockwise
//!   seen from outside the cube (right-handed about the outward normal), and `FACE_EDGES[f][i]`
//!   joins `FACE_CORNERS[f][i]` to `FACE_CORNERS[f][(i + 1) % 4]`.
//!
//! All tables are computed by `const fn`s from these rules, so they cannot disagree.

/// Position of each corner in the unit cube.
pub(crate) const CORNER_POS: [[u8; 3]; 8] = corner_pos();
/// The two corners of each edge, lower coordinate first.
pub(crate) const EDGE_CORNERS: [[u8; 2]; 12] = edge_corners();
/// Axis each edge is parallel to.
pub(crate) const EDGE_AXIS: [u8; 12] = [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2];
/// Corners of each face, counter-clockwise seen from outside.
pub(crate) const FACE_CORNERS: [[u8; 4]; 6] = face_corners();
/// Edges of each face; edge `i` joins corner `i` and corner `i + 1` (mod 4).
pub(crate) const FACE_EDGES: [[u8; 4]; 6] = face_edges();
/// The two faces containing each edge (lower face index first).
pub(crate) const EDGE_FACES: [[u8; 2]; 12] = edge_faces();

const fn corner_pos() -> [[u8; 3]; 8] {
    let mut out = [[0u8; 3]; 8];
    let mut c = 0;
    while c < 8 {
        out[c] = [(c & 1) as u8, ((c >> 1) & 1) as u8, ((c >> 2) & 1) as u8];
        c += 1;
    }
    out
}

/// The two axes other than `a`, in increasing order.
const fn others(a: usize) -> (usize, usize) {
    match a {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

const fn edge_corners() -> [[u8; 2]; 12] {
    let mut out = [[0u8; 2]; 12];
    let mut e = 0;
    while e < 12 {
        let a = e / 4;
        let k = e % 4;
        let (u, v) = others(a);
        let lo = ((k & 1) << u) | (((k >> 1) & 1) << v);
        out[e] = [lo as u8, (lo | (1 << a)) as u8];
        e += 1;
    }
    out
}

/// Edge joining corners `c0` and `c1` (which must differ in exactly one bit).
pub(crate) const fn edge_between(c0: u8, c1: u8) -> u8 {
    let diff = c0 ^ c1;
    let a = diff.trailing_zeros() as usize;
    let lo = (c0 & c1) as usize;
    let (u, v) = others(a);
    (4 * a + ((lo >> u) & 1) + 2 * ((lo >> v) & 1)) as u8
}

const fn face_corners() -> [[u8; 4]; 6] {
    let mut out = [[0u8; 4]; 6];
    let mut f = 0;
    while f < 6 {
        let a = f / 2;
        let s = f % 2;
        // (u, v) cyclic after a so that e_u × e_v = e_a.
        let u = (a + 1) % 3;
        let v = (a + 2) % 3;
        let uv: [(usize, usize); 4] = if s == 1 {
            [(0, 0), (1, 0), (1, 1), (0, 1)]
        } else {
            [(0, 0), (0, 1), (1, 1), (1, 0)]
        };
        let mut i = 0;
        while i < 4 {
            let c = (s << a) | (uv[i].0 << u) | (uv[i].1 << v);
            out[f][i] = c as u8;
            i += 1;
        }
        f += 1;
    }
    out
}

const fn face_edges() -> [[u8; 4]; 6] {
    let fc = face_corners();
    let mut out = [[0u8; 4]; 6];
    let mut f = 0;
    while f < 6 {
        let mut i = 0;
        while i < 4 {
            out[f][i] = edge_between(fc[f][i], fc[f][(i + 1) % 4]);
            i += 1;
        }
        f += 1;
    }
    out
}

const fn edge_faces() -> [[u8; 2]; 12] {
    let fe = face_edges();
    let mut out = [[u8::MAX; 2]; 12];
    let mut f = 0;
    while f < 6 {
        let mut i = 0;
        while i < 4 {
            let e = fe[f][i] as usize;
            if out[e][0] == u8::MAX {
                out[e][0] = f as u8;
            } else {
                out[e][1] = f as u8;
            }
            i += 1;
        }
        f += 1;
    }
    out
}

/// True when cube edges `e0` and `e1` lie on a common face.
pub(crate) const fn edges_share_face(e0: u8, e1: u8) -> bool {
    let a = EDGE_FACES[e0 as usize];
    let b = EDGE_FACES[e1 as usize];
    a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_are_consistent() {
        for (e, c) in EDGE_CORNERS.iter().enumerate() {
            let d = c[0] ^ c[1];
            assert_eq!(d.count_ones(), 1);
            assert_eq!(d.trailing_zeros() as u8, EDGE_AXIS[e]);
            assert_eq!(edge_between(c[0], c[1]) as usize, e);
            assert_eq!(edge_between(c[1], c[0]) as usize, e);
            assert!(EDGE_FACES[e][1] != u8::MAX && EDGE_FACES[e][0] < EDGE_FACES[e][1]);
        }
        for (f, fc) in FACE_CORNERS.iter().enumerate() {
            let (a, s) = (f / 2, f % 2);
            let p: Vec<[f64; 3]> = fc
                .iter()
                .map(|&c| CORNER_POS[c as usize].map(f64::from))
                .collect();
            for q in &p {
                assert_eq!(q[a], s as f64);
            }
            // Counter-clockwise about the outward normal: Newell normal along ±e_a.
            let mut n = [0.0; 3];
            for i in 0..4 {
                let (u, v) = (p[i], p[(i + 1) % 4]);
                n[0] += (u[1] - v[1]) * (u[2] + v[2]);
                n[1] += (u[2] - v[2]) * (u[0] + v[0]);
                n[2] += (u[0] - v[0]) * (u[1] + v[1]);
            }
            let sign = if s == 1 { 1.0 } else { -1.0 };
            assert!(n[a] * sign > 0.0, "face {f} is not counter-clockwise");
        }
        // Every edge is traversed in opposite directions by its two faces.
        for e in 0..12u8 {
            let dirs: Vec<(u8, u8)> = (0..6)
                .flat_map(|f| {
                    (0..4)
                        .filter(move |&i| FACE_EDGES[f][i] == e)
                        .map(move |i| (FACE_CORNERS[f][i], FACE_CORNERS[f][(i + 1) % 4]))
                })
                .collect();
            assert_eq!(dirs.len(), 2);
            assert_eq!(dirs[0], (dirs[1].1, dirs[1].0));
        }
    }
}
