//! The explicit frequency path `ω(t)` of App. B.1.2–B.1.3 (eqs. B.32–B.46) and the temporal
//! weights `g_bd` (B.39–B.40) and `g_ave` (eq. 3.16) derived from the same per-corner data.
//!
//! # Derivation (the typeset equations were garbled; this is what the code implements)
//!
//! In every triangle `f = (j, k, l)` and at every corner `m`, the one-form `ω` defines a tangent
//! vector `u_{f,m}` (B.50–B.52): the unique vector in the triangle's plane with
//! `u · (x_k − x_m) = ω_{m→k}` and `u · (x_l − x_m) = ω_{m→l}` for the two edges leaving `m`, i.e.
//! `u = x e₁ + y e₂` with `[e₁·e₁ e₁·e₂; e₁·e₂ e₂·e₂] [x y]ᵀ = [ω_{m→k} ω_{m→l}]ᵀ`.
//!
//! With `v = √a u` (B.36), `f = |v|² = a |u|²` (B.37) is interpolated linearly (B.38) and so is the
//! angle `φ` of `v` against a reference direction in the face plane (B.43). The reference
//! direction cancels: `φ¹ − φ⁰` is the signed angle `Δ ∈ (−π, π]` from `u⁰` to `u¹` about the face
//! normal `n̂_f` (the shorter rotation), so
//!
//! ```text
//! u^t_{f,m} = √(f^t / a^t) · (cos(tΔ) û⁰ + sin(tΔ) n̂_f × û⁰),
//! f^t = (1−t) a⁰|u⁰|² + t a¹|u¹|²,   a^t = (1−t) a⁰ + t a¹,
//! ```
//!
//! and the contribution of corner `m` of face `f` to edge `jk` is `u^t · (x_k − x_j)`, which is
//! `|e_jk| √(f^t/a^t) cos φ^t` of B.44–B.45. B.46 averages the `2|N_jk|` contributions of the
//! edge's endpoints in its one or two faces. At `t = 0` each contribution is exactly `ω⁰_jk`
//! (both endpoints of an edge are corners whose `u` reproduces it), so the path starts and ends
//! at the keyframes whatever the curl of `ω`.
//!
//! Where the rotation is undefined — `a⁰_m = 0` or `a¹_m = 0` (B.34 ff.), a vanishing `u⁰` or
//! `u¹`, or a degenerate triangle — the contribution falls back to the linear
//! `(1−t) ω⁰_jk + t ω¹_jk`.
//!
//! `g_bd` per vertex (B.40) is `1/(2|N_j|) Σ_{f∋j} (f⁰_{f,j})² + (f¹_{f,j})²`. `g_ave` (eq. 3.16)
//! is the area-weighted spacetime *mean* of `a²|ω|⁴ = f²` — `∫₀¹ f(t)² dt = (f⁰² + f⁰f¹ + f¹²)/3`
//! exactly for linear `f` — divided by the total area, so that `c = 10³ g_ave` has the units of
//! `g_bd` (1/length²) and `c E_opt` the units of `E_smooth`, as §3.4.1 intends ("to make
//! `cE_opt` unit consistent"); the integral without the division would make `c` depend on the
//! mesh's size.

use super::topology::Topology;
use crate::geom::{tri_normal, Vec3};

/// Per face corner: how its tangent vector moves from keyframe 0 to keyframe 1.
#[derive(Debug, Clone, Copy)]
enum Corner {
    /// Magnitude/angle interpolation (B.38, B.43).
    Rotate {
        /// `û⁰`.
        u_hat: Vec3,
        /// `n̂_f × û⁰`.
        u_perp: Vec3,
        /// `Δ = φ¹ − φ⁰` in (−π, π].
        delta: f64,
        /// `a⁰|u⁰|²`, `a¹|u¹|²`.
        f: [f64; 2],
        /// `a⁰`, `a¹`.
        a: [f64; 2],
    },
    /// Linear fallback: the edge values `(1−t) ω⁰ + t ω¹` are used.
    Linear,
}

/// The explicit path `ω(t)` between two one-forms on one mesh (see the [module docs](self)).
#[derive(Debug, Clone)]
pub(crate) struct OmegaPath {
    corners: Vec<[Corner; 3]>,
    omega: [Vec<f64>; 2],
    /// Edge vectors `x_max − x_min`, one per edge.
    edge_vec: Vec<Vec3>,
    /// `f⁰`, `f¹` per face corner (0 where undefined), for the weights.
    f_corner: Vec<[[f64; 2]; 3]>,
}

impl OmegaPath {
    /// Precomputes the per-corner data for keyframes `(ω⁰, a⁰)` and `(ω¹, a¹)` (EdgeList
    /// orientation) on the mesh `topo` with positions `x`.
    pub fn new(
        topo: &Topology,
        x: &[[f64; 3]],
        omega0: &[f64],
        omega1: &[f64],
        a0: &[f64],
        a1: &[f64],
    ) -> OmegaPath {
        let mut corners = Vec::with_capacity(topo.n_faces());
        let mut f_corner = Vec::with_capacity(topo.n_faces());
        for f in 0..topo.n_faces() {
            let mut cs = [Corner::Linear; 3];
            let mut fc = [[0.0; 2]; 3];
            let normal = face_unit_normal(topo, x, f);
            for c in 0..3 {
                let u0 = corner_vector(topo, x, omega0, f, c);
                let u1 = corner_vector(topo, x, omega1, f, c);
                let m = topo.faces[f][c] as usize;
                let (am0, am1) = (a0[m], a1[m]);
                fc[c] = [am0 * u0.dot(u0), am1 * u1.dot(u1)];
                cs[c] = corner_path(u0, u1, normal, [am0, am1]);
            }
            corners.push(cs);
            f_corner.push(fc);
        }
        let edge_vec = topo
            .edges
            .iter()
            .map(|&[a, b]| Vec3::from(x[b as usize]) - Vec3::from(x[a as usize]))
            .collect();
        OmegaPath {
            corners,
            omega: [omega0.to_vec(), omega1.to_vec()],
            edge_vec,
            f_corner,
        }
    }

    /// `ω(t)` per edge (B.46). `t = 0` and `t = 1` return the keyframes' one-forms exactly.
    pub fn at(&self, topo: &Topology, t: f64) -> Vec<f64> {
        if t == 0.0 {
            return self.omega[0].clone();
        }
        if t == 1.0 {
            return self.omega[1].clone();
        }
        let mut sum = vec![0.0; topo.n_edges()];
        let mut count = vec![0u32; topo.n_edges()];
        for (f, cs) in self.corners.iter().enumerate() {
            let u: [Option<Vec3>; 3] = std::array::from_fn(|c| corner_at(&cs[c], t));
            for s in 0..3 {
                let e = topo.face_edges[f][s] as usize;
                let lin = (1.0 - t) * self.omega[0][e] + t * self.omega[1][e];
                for c in [s, (s + 1) % 3] {
                    sum[e] += u[c].map_or(lin, |u| u.dot(self.edge_vec[e]));
                    count[e] += 1;
                }
            }
        }
        sum.iter()
            .zip(&count)
            .enumerate()
            .map(|(e, (s, &n))| {
                if n == 0 {
                    (1.0 - t) * self.omega[0][e] + t * self.omega[1][e]
                } else {
                    s / n as f64
                }
            })
            .collect()
    }

    /// `g_bd` per vertex (B.39–B.40); 0 for vertices in no triangle.
    pub fn g_bd(&self, topo: &Topology) -> Vec<f64> {
        let mut sum = vec![0.0; topo.n_vertices];
        let mut count = vec![0u32; topo.n_vertices];
        for (f, fc) in self.f_corner.iter().enumerate() {
            for (c, fm) in fc.iter().enumerate() {
                let m = topo.faces[f][c] as usize;
                sum[m] += fm[0] * fm[0] + fm[1] * fm[1];
                count[m] += 1;
            }
        }
        sum.iter()
            .zip(&count)
            .map(|(s, &n)| if n == 0 { 0.0 } else { s / (2.0 * n as f64) })
            .collect()
    }

    /// `g_ave` (eq. 3.16 as an area-weighted mean, see the [module docs](self)); 0 when the
    /// mesh has no area.
    pub fn g_ave(&self, topo: &Topology, vertex_area: &[f64]) -> f64 {
        let mut sum = vec![0.0; topo.n_vertices];
        let mut count = vec![0u32; topo.n_vertices];
        for (f, fc) in self.f_corner.iter().enumerate() {
            for (c, &[f0, f1]) in fc.iter().enumerate() {
                let m = topo.faces[f][c] as usize;
                sum[m] += (f0 * f0 + f0 * f1 + f1 * f1) / 3.0;
                count[m] += 1;
            }
        }
        let area: f64 = vertex_area.iter().sum();
        if area.is_nan() || area <= 0.0 {
            return 0.0;
        }
        let total: f64 = (0..topo.n_vertices)
            .filter(|&j| count[j] > 0)
            .map(|j| vertex_area[j] * sum[j] / count[j] as f64)
            .sum();
        total / area
    }
}

/// Unit normal of face `f` (zero for a degenerate face).
pub(crate) fn face_unit_normal(topo: &Topology, x: &[[f64; 3]], f: usize) -> Vec3 {
    let p = topo.faces[f].map(|v| Vec3::from(x[v as usize]));
    let n = tri_normal(p[0], p[1], p[2]);
    let l = n.length();
    // not `geom::normalized`: an infinite length is scaled (to zero or NaN) here, not rejected
    if l > 0.0 {
        n * (1.0 / l)
    } else {
        Vec3::ZERO
    }
}

/// The tangent vector `u_{f,c}` of B.51–B.52 at corner `c` of face `f` (zero when the triangle
/// is degenerate).
pub(crate) fn corner_vector(
    topo: &Topology,
    x: &[[f64; 3]],
    omega: &[f64],
    f: usize,
    c: usize,
) -> Vec3 {
    let t = topo.faces[f];
    let (m, k, l) = (t[c], t[(c + 1) % 3], t[(c + 2) % 3]);
    let xm = Vec3::from(x[m as usize]);
    let e1 = Vec3::from(x[k as usize]) - xm;
    let e2 = Vec3::from(x[l as usize]) - xm;
    // ω along m → k (slot c) and along m → l (slot c + 2 runs l → m, so negate it)
    let w1 = topo.omega_from(omega, topo.face_edges[f][c] as usize, m);
    let w2 = -topo.omega_from(omega, topo.face_edges[f][(c + 2) % 3] as usize, l);
    let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = g11 * g22 - g12 * g12;
    if det.is_nan() || det <= 1e-14 * g11 * g22 {
        return Vec3::ZERO;
    }
    let cx = (g22 * w1 - g12 * w2) / det;
    let cy = (g11 * w2 - g12 * w1) / det;
    e1 * cx + e2 * cy
}

/// Classifies one corner: rotation when both amplitudes and both vectors are non-zero and the
/// face has a normal, linear fallback otherwise.
fn corner_path(u0: Vec3, u1: Vec3, normal: Vec3, a: [f64; 2]) -> Corner {
    let (l0, l1) = (u0.length(), u1.length());
    let usable = a[0] > 0.0 && a[1] > 0.0 && l0 > 0.0 && l1 > 0.0 && normal.length() > 0.0;
    if !(usable && l0.is_finite() && l1.is_finite()) {
        return Corner::Linear;
    }
    let u_hat = u0 * (1.0 / l0);
    let u_perp = normal.cross(u_hat);
    let delta = u0.cross(u1).dot(normal).atan2(u0.dot(u1));
    Corner::Rotate {
        u_hat,
        u_perp,
        delta,
        f: [a[0] * l0 * l0, a[1] * l1 * l1],
        a,
    }
}

/// `u^t` of a corner, or `None` for the linear fallback.
#[inline]
fn corner_at(c: &Corner, t: f64) -> Option<Vec3> {
    match *c {
        Corner::Linear => None,
        Corner::Rotate {
            u_hat,
            u_perp,
            delta,
            f,
            a,
        } => {
            let ft = (1.0 - t) * f[0] + t * f[1];
            let at = (1.0 - t) * a[0] + t * a[1];
            let mag = (ft / at).sqrt();
            let (s, co) = (t * delta).sin_cos();
            Some((u_hat * co + u_perp * s) * mag)
        }
    }
}
