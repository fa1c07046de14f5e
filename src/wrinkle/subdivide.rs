//! Loop subdivision of the base mesh, of one-forms (S1) and of the complex field z
//! (dissertation §3.5, eqs. 3.18–3.24, App. B.2–B.3).
//!
//! # Vertex rule S0 (Loop 1987)
//! - interior even vertex of valence n: `(1 − nα) v + α Σ neighbours`, with Loop's
//!   `α(n) = (5/8 − (3/8 + cos(2π/n)/4)²) / n` (the "traditional" weight the text names);
//! - interior odd vertex on edge `ab` with opposite vertices `c, d`: `3/8 (a + b) + 1/8 (c + d)`;
//! - boundary odd vertex: the edge midpoint `(a + b)/2`;
//! - boundary even vertex: depends on [`BoundaryRule`]. `Fixed` (the default, App. B.2's
//!   "boundary fixed Loop scheme") keeps every boundary vertex where it is, so the boundary
//!   polyline, and every corner on it, stays exactly sharp. `Smooth` applies the cubic B-spline
//!   rule `3/4 v + 1/8 (b₁ + b₂)` along the boundary, except at *corners*, which stay fixed:
//!   boundary vertices with a single triangle (valence-2 boundary vertices) and boundary
//!   vertices whose triangle angles sum to π ± more than [`SubdivisionOptions::corner_angle`].
//!   Corners are found on the base mesh and stay corners on every level.
//!
//! # One-form rule S1 (Wang et al. 2006, de Goes et al. 2016)
//! S1 must satisfy `S1 d = d S0`. Every fine edge's stencil is written as an *exact part*, fixed
//! by that identity, plus a *curl part*, a combination of coarse face circulations (which
//! vanishes on exact forms and so never disturbs the identity):
//!
//! - exact part: a fine edge runs between two fine vertices whose S0 rows `r_a`, `r_b` are
//!   supported in the closed one-ring of an *anchor* coarse vertex `o` (the coarse endpoint for
//!   the halves of a coarse edge, the shared corner `j` for an edge `m_ij → m_jk` inside a coarse
//!   triangle). Since the rows sum to one, `(S0 f)_b − (S0 f)_a = Σ_u (r_b − r_a)_u (f_u − f_o)`,
//!   and `f_u − f_o = ω(o→u)` along the one-ring edge, so the exact part is
//!   `Σ_u (r_b − r_a)_u ω(o→u)`;
//! - curl part of an even edge `v → m_e` (Wang et al. Fig. 6, read in this form):
//!   `β/8 (c(F₋₁) + c(F₋₂) − c(F₀) − c(F₁))`, where `F₀, F₁` are the two triangles around `v`
//!   on one side of `e`, `F₋₁, F₋₂` those on the other side, each circulation `c` taken in the
//!   fan direction (the expression does not depend on which side is called "0"), and `β(n) = 1/4`
//!   for `n ≥ 6`, `1/4 − sin²(2π/5)/16` for 5, `1/8` for 4, `1/12` for 3;
//! - curl part of an odd edge `m_ij → m_jk` inside triangle `ijk` (Wang et al. Fig. 4):
//!   `−3/16 c(i→j→k) − 1/32 (c(j→i→p) + c(k→j→q))` with `p, q` the flap vertices across `ij`
//!   and `jk`. Expanding gives the published stencil
//!   `3/16 ω_ik + 3/32 (ω_ij + ω_jk) + 3/32 (ω_pj + ω_jq) − 1/32 (ω_ip + ω_qk)`, which
//!   reproduces the uniform-curl one-form exactly on a regular planar mesh.
//!
//! Near the boundary (App. B.2; its figure B.1 was lost in the text conversion) pleat keeps the
//! same two parts: the exact part comes from the boundary S0 rows above, so `S1 d = d S0` holds
//! exactly for either [`BoundaryRule`], and circulation terms of triangles that do not exist are
//! dropped (boundary vertices use `β = 1/4`). Away from the boundary this is Wang et al.'s scheme;
//! next to it, it distributes curl slightly differently from the reference implementation's
//! hand-tabulated cases, but total curl is carried identically: any loop farther than one
//! stencil from a vortex keeps its circulation exactly.
//!
//! # z rule (eqs. 3.18–3.24)
//! - on a segment (3.18): `z(P) = (1−α) z₀ e^{iαω} + α z₁ e^{−i(1−α)ω}`, `ω = ω(0→1)` (the text
//!   prints `e^{+i(1−α)ω}` for the second vote; extrapolating from `v₁` back towards `v₀`
//!   decreases the phase, so the sign is `−`, as in the reference implementation);
//! - in a triangle (3.19): `z(P) = Σ_j α_j z_j exp(i(α_{j+1} ω(j→j+1) + α_{j+2} ω(j→j+2)))`;
//! - interior odd vertex (3.20–3.22): `P₀ = 1/4 c + 3/8 (a + b)` in triangle `abc`, `P₁` likewise
//!   in `abd`; `z' = ½ (z(P₀) e^{iω(P₀)(P₁* − P₀)/2} + z(P₁) e^{iω(P₁)(P₀* − P₁)/2})`, where `P₁*`
//!   is `P₁` after rigidly unfolding `abd` about `ab` into the plane of `abc` (and vice versa),
//!   and `ω(P)` is the cotangent vector of App. B.3 (eqs. B.48–B.52, per face corner; on
//!   degenerate faces a one-ring least-squares gradient replaces it);
//! - interior even vertex (3.23–3.24): `P_j = (1 − 2γ) v + γ (v_{j+1} + v_{j+2})` in each
//!   triangle of the fan, `γ = nα/2`; `z' = (1/n) Σ_j z(P_j) e^{iω(P_j)(v' − P_j)}`. Here the
//!   displacement `v' − P_j` is applied to the in-plane cotangent vector, i.e. projected onto the
//!   triangle's plane (the text gives no unfolding for the n-gon; this is what the reference
//!   implementation does);
//! - boundary odd vertex: (3.18) at `α = 1/2`; boundary even vertex: `z' = z` when the vertex is
//!   fixed, else `½ Σ_{k=1,2} z(P_k) e^{iω(P_k)(v' − P_k)}` with `P_k = 3/4 v + 1/4 b_k` on the two
//!   boundary edges.
//!
//! On a planar mesh with `ω = d(k·x)` and `z = e^{ik·x}` every step is exact, so the scheme
//! reproduces plane waves to round-off at any level (the Remark after Fig. 3.13).

use rayon::prelude::*;

use super::complex::Complex;
use super::topology::{Topology, NONE};
use crate::geom::{normalized, tri_normal, Vec3};
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// How Loop subdivision treats boundary vertices (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u32)]
pub enum BoundaryRule {
    /// Boundary vertices never move; boundary edges are split at their midpoints (App. B.2).
    #[default]
    Fixed = 0,
    /// Cubic B-spline boundary curve with sharp corners kept fixed.
    Smooth = 1,
}

/// Options of the Loop refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubdivisionOptions {
    /// Boundary rule; default [`BoundaryRule::Fixed`].
    pub boundary: BoundaryRule,
    /// With [`BoundaryRule::Smooth`]: a boundary vertex whose triangle angles sum to a value
    /// differing from π by more than this (radians) is a corner and stays fixed. Default π/6.
    pub corner_angle: f64,
}

impl Default for SubdivisionOptions {
    fn default() -> Self {
        SubdivisionOptions {
            boundary: BoundaryRule::Fixed,
            corner_angle: std::f64::consts::FRAC_PI_6,
        }
    }
}

/// The even-vertex rule of one vertex on one level.
#[derive(Debug, Clone, Copy)]
pub(crate) enum VertexRule {
    /// The vertex keeps its value (fixed boundary, corner, or isolated vertex).
    Keep,
    /// Interior Loop rule with weight `alpha` for each of the `n` neighbours; `gamma = nα/2`
    /// is the z rule's weight (eq. 3.24).
    Interior { alpha: f64, gamma: f64 },
    /// B-spline boundary rule along the two boundary edges.
    Boundary { edges: [u32; 2] },
}

/// Loop's even weight `α(n) = (5/8 − (3/8 + cos(2π/n)/4)²) / n` (eq. 3.23).
pub(crate) fn loop_alpha(n: usize) -> f64 {
    let c = 0.375 + 0.25 * (2.0 * std::f64::consts::PI / n as f64).cos();
    (0.625 - c * c) / n as f64
}

/// Wang et al.'s curl weight `β(n)` of the even one-form rule (interior valence `n`).
fn wang_beta(n: usize) -> f64 {
    match n {
        0..=3 => 1.0 / 12.0,
        4 => 0.125,
        5 => 0.25 - 0.0625 * (0.4 * std::f64::consts::PI).sin().powi(2),
        _ => 0.25,
    }
}

/// The even-vertex rules of a level.
pub(crate) fn vertex_rules(topo: &Topology, boundary: BoundaryRule) -> Vec<VertexRule> {
    (0..topo.n_vertices)
        .map(|v| {
            let n = topo.vert_edges.len(v);
            if n == 0 || topo.corner[v] {
                VertexRule::Keep
            } else if !topo.boundary_vertex[v] {
                let alpha = loop_alpha(n);
                VertexRule::Interior {
                    alpha,
                    gamma: 0.5 * n as f64 * alpha,
                }
            } else if boundary == BoundaryRule::Fixed {
                VertexRule::Keep
            } else {
                let mut b = topo
                    .vert_edges
                    .row(v)
                    .iter()
                    .copied()
                    .filter(|&e| topo.is_boundary_edge(e as usize));
                let edges = [b.next().unwrap(), b.next().unwrap()];
                VertexRule::Boundary { edges }
            }
        })
        .collect()
}

/// A value S0 can average: `f64` (scalars, amplitude) or `[f64; 3]` (positions).
pub(crate) trait Blend: Copy + Send + Sync {
    /// `self + w·x`.
    fn axpy(self, w: f64, x: Self) -> Self;
    /// `w·self`.
    fn times(self, w: f64) -> Self;
}

impl Blend for f64 {
    #[inline]
    fn axpy(self, w: f64, x: f64) -> f64 {
        self + w * x
    }
    #[inline]
    fn times(self, w: f64) -> f64 {
        self * w
    }
}

impl Blend for [f64; 3] {
    #[inline]
    fn axpy(self, w: f64, x: [f64; 3]) -> [f64; 3] {
        (Vec3::from(self) + Vec3::from(x) * w).to_array()
    }
    #[inline]
    fn times(self, w: f64) -> [f64; 3] {
        (Vec3::from(self) * w).to_array()
    }
}

/// The two vertices opposite edge `e` (`NONE` for the missing one of a boundary edge).
#[inline]
pub(crate) fn opposite_vertices(topo: &Topology, e: usize) -> [u32; 2] {
    topo.edge_faces[e].map(|f| {
        if f == NONE {
            NONE
        } else {
            let s = topo.edge_slot(f as usize, e as u32);
            topo.faces[f as usize][(s + 2) % 3]
        }
    })
}

/// S0 at the even vertex `v` (eq. 3.23 and the boundary rules).
pub(crate) fn s0_even<T: Blend>(topo: &Topology, rules: &[VertexRule], v: usize, f: &[T]) -> T {
    match rules[v] {
        VertexRule::Keep => f[v],
        VertexRule::Interior { alpha, .. } => {
            let row = topo.vert_edges.row(v);
            let mut acc = f[v].times(1.0 - row.len() as f64 * alpha);
            for &e in row {
                acc = acc.axpy(alpha, f[topo.other_end(e as usize, v as u32) as usize]);
            }
            acc
        }
        VertexRule::Boundary { edges } => {
            let [b0, b1] = edges.map(|e| topo.other_end(e as usize, v as u32) as usize);
            f[v].times(0.75).axpy(0.125, f[b0]).axpy(0.125, f[b1])
        }
    }
}

/// S0 at the odd vertex of edge `e`.
pub(crate) fn s0_odd<T: Blend>(topo: &Topology, e: usize, f: &[T]) -> T {
    let [a, b] = topo.edges[e].map(|v| v as usize);
    let [c, d] = opposite_vertices(topo, e);
    if d == NONE {
        f[a].times(0.5).axpy(0.5, f[b])
    } else {
        f[a].times(0.375)
            .axpy(0.375, f[b])
            .axpy(0.125, f[c as usize])
            .axpy(0.125, f[d as usize])
    }
}

/// S0 on a whole level: even vertices `0..V`, then one odd vertex per edge.
pub(crate) fn apply_s0<T: Blend>(topo: &Topology, rules: &[VertexRule], f: &[T]) -> Vec<T> {
    let nv = topo.n_vertices;
    (0..nv + topo.n_edges())
        .into_par_iter()
        .map(|i| {
            if i < nv {
                s0_even(topo, rules, i, f)
            } else {
                s0_odd(topo, i - nv, f)
            }
        })
        .collect()
}

/// What S1 reads on the coarse level.
struct OneForm<'a> {
    topo: &'a Topology,
    rules: &'a [VertexRule],
    omega: &'a [f64],
    curl: Vec<f64>,
}

impl OneForm<'_> {
    /// `ω(from → opposite vertex of e in f)`, where `from` is an endpoint of `e`.
    fn toward_opposite(&self, f: usize, e: usize, from: u32) -> f64 {
        let s = self.topo.edge_slot(f, e as u32);
        let edge = if self.topo.faces[f][s] == from {
            self.topo.face_edges[f][(s + 2) % 3]
        } else {
            self.topo.face_edges[f][(s + 1) % 3]
        };
        self.topo.omega_from(self.omega, edge as usize, from)
    }

    /// `Σ_u r_u ω(o→u)` for the S0 row `r` of the odd vertex of `e`, anchored at its endpoint `o`.
    fn odd_row_from(&self, e: usize, o: u32) -> f64 {
        let to_other = self.topo.omega_from(self.omega, e, o);
        let [f0, f1] = self.topo.edge_faces[e];
        if f1 == NONE {
            return 0.5 * to_other;
        }
        0.375 * to_other
            + 0.125
                * (self.toward_opposite(f0 as usize, e, o)
                    + self.toward_opposite(f1 as usize, e, o))
    }

    /// `Σ_u r_u ω(v→u)` for the S0 row `r` of the even vertex `v`.
    fn even_row_from(&self, v: u32) -> f64 {
        let topo = self.topo;
        match self.rules[v as usize] {
            VertexRule::Keep => 0.0,
            VertexRule::Interior { alpha, .. } => {
                let row = topo.vert_edges.row(v as usize);
                alpha
                    * row
                        .iter()
                        .map(|&e| topo.omega_from(self.omega, e as usize, v))
                        .sum::<f64>()
            }
            VertexRule::Boundary { edges } => {
                0.125
                    * edges
                        .iter()
                        .map(|&e| topo.omega_from(self.omega, e as usize, v))
                        .sum::<f64>()
            }
        }
    }

    /// Circulation of face `f` traversed so that `from` is followed by `to` (0 for `NONE`).
    fn circulation(&self, f: u32, from: u32, to: u32) -> f64 {
        if f == NONE {
            return 0.0;
        }
        let t = self.topo.faces[f as usize];
        let c = self.topo.corner_of(f as usize, from);
        if t[(c + 1) % 3] == to {
            self.curl[f as usize]
        } else {
            -self.curl[f as usize]
        }
    }

    /// The face across the edge `(v, u)` of face `f` from `f`, and its vertex other than `v, u`.
    fn across(&self, f: u32, v: u32, u: u32) -> (u32, u32) {
        if f == NONE {
            return (NONE, NONE);
        }
        let fe = self.topo.face_edges[f as usize];
        let e = fe
            .iter()
            .copied()
            .find(|&e| {
                let [a, b] = self.topo.edges[e as usize];
                (a == v && b == u) || (a == u && b == v)
            })
            .unwrap();
        let g = self.topo.other_face(e as usize, f);
        if g == NONE {
            return (NONE, NONE);
        }
        let t = self.topo.faces[g as usize];
        let w = t.iter().copied().find(|&x| x != v && x != u).unwrap();
        (g, w)
    }

    fn opposite_in(&self, f: u32, e: usize) -> u32 {
        if f == NONE {
            return NONE;
        }
        let s = self.topo.edge_slot(f as usize, e as u32);
        self.topo.faces[f as usize][(s + 2) % 3]
    }

    /// Fine edge `v → m_e` (half of coarse edge `e` at its endpoint `v`).
    fn even_edge(&self, e: usize, v: u32) -> f64 {
        let exact = self.odd_row_from(e, v) - self.even_row_from(v);
        let w = self.topo.other_end(e, v);
        let [f0, f1] = self.topo.edge_faces[e];
        let (u1, um1) = (self.opposite_in(f0, e), self.opposite_in(f1, e));
        let (g1, _) = self.across(f0, v, u1);
        let (gm2, _) = self.across(f1, v, um1);
        let beta = match self.rules[v as usize] {
            VertexRule::Interior { .. } => wang_beta(self.topo.vert_edges.len(v as usize)),
            _ => 0.25,
        };
        let curl = self.circulation(f1, w, v) + self.circulation(gm2, um1, v)
            - self.circulation(f0, v, w)
            - self.circulation(g1, v, u1);
        exact + beta / 8.0 * curl
    }

    /// Fine edge `m_ij → m_jk` inside face `f`, where `ij` is the edge in slot `t`.
    fn odd_edge(&self, f: usize, t: usize) -> f64 {
        let tri = self.topo.faces[f];
        let (i, j, k) = (tri[t], tri[(t + 1) % 3], tri[(t + 2) % 3]);
        let ij = self.topo.face_edges[f][t] as usize;
        let jk = self.topo.face_edges[f][(t + 1) % 3] as usize;
        let exact = self.odd_row_from(jk, j) - self.odd_row_from(ij, j);
        let fp = self.topo.other_face(ij, f as u32);
        let fq = self.topo.other_face(jk, f as u32);
        let curl = -3.0 / 16.0 * self.curl[f]
            - 1.0 / 32.0 * (self.circulation(fp, j, i) + self.circulation(fq, k, j));
        exact + curl
    }
}

/// S1: the one-form `omega` on `topo` (EdgeList orientation) to the refined level `fine`
/// (which must be `topo.refine()`), again in EdgeList orientation. `S1 d = d S0` holds exactly.
pub(crate) fn apply_s1(
    topo: &Topology,
    fine: &Topology,
    rules: &[VertexRule],
    omega: &[f64],
) -> Vec<f64> {
    let ctx = OneForm {
        topo,
        rules,
        omega,
        curl: topo.face_curls(omega),
    };
    let nv = topo.n_vertices as u32;
    let n_even = 2 * topo.n_edges();
    (0..fine.n_edges())
        .into_par_iter()
        .map(|id| {
            let [a, b] = fine.edges[id];
            if id < n_even {
                ctx.even_edge((b - nv) as usize, a)
            } else {
                let (e1, e2) = (a - nv, b - nv);
                let f = (fine.edge_faces[id][0] / 4) as usize;
                let fe = topo.face_edges[f];
                let t1 = fe.iter().position(|&e| e == e1).unwrap();
                // The fine edge m_{fe[t]} → m_{fe[t+1]}; its EdgeList orientation is e1 → e2.
                if fe[(t1 + 1) % 3] == e2 {
                    ctx.odd_edge(f, t1)
                } else {
                    -ctx.odd_edge(f, (t1 + 2) % 3)
                }
            }
        })
        .collect()
}

/// Exterior derivative of a vertex function on the EdgeList orientation: `(df)_e = f_b − f_a`.
pub(crate) fn exterior_derivative(topo: &Topology, f: &[f64]) -> Vec<f64> {
    topo.edges
        .iter()
        .map(|&[a, b]| f[b as usize] - f[a as usize])
        .collect()
}

/// Per face and corner `t`, the tangent vector `g_t` of App. B.3 (eqs. B.50–B.52): the vector
/// in the face plane with `g_t·(x_{t+1} − x_t) = ω(t→t+1)` and `g_t·(x_{t+2} − x_t) = ω(t→t+2)`.
/// `ω(P)(d) = Σ_t α_t g_t·d` (B.49) is the cotangent vector at `P = Σ α_t x_t`.
///
/// A nearly degenerate face (Gram determinant below `1e-12` of its squared trace, i.e. height
/// below ~1e-6 of its length) cannot tell the component of ω across it; its corners use instead
/// the least-squares gradient of ω over the corner vertex's one-ring edges, in the tangent
/// plane of the vertex's area-weighted normal ([`ring_gradient`]). Both are exact for
/// `ω = d(k·x)` with `k` tangent, so plane waves stay exact.
pub(crate) fn face_gradients(topo: &Topology, x: &[[f64; 3]], omega: &[f64]) -> Vec<FaceField> {
    (0..topo.n_faces())
        .into_par_iter()
        .map(|f| {
            let t = topo.faces[f];
            let fe = topo.face_edges[f];
            let w = [0, 1, 2].map(|c| topo.omega_from(omega, fe[c] as usize, t[c]));
            let g = [0, 1, 2].map(|c| {
                let o = Vec3::from(x[t[c] as usize]);
                let e1 = Vec3::from(x[t[(c + 1) % 3] as usize]) - o;
                let e2 = Vec3::from(x[t[(c + 2) % 3] as usize]) - o;
                // ω(c→c+1) = w[c]; ω(c→c+2) = −ω(c+2→c) = −w[c+2]
                corner_gradient(e1, e2, w[c], -w[(c + 2) % 3])
                    .unwrap_or_else(|| ring_gradient(topo, x, omega, t[c]))
            });
            FaceField { w, g }
        })
        .collect()
}

/// Per face: `w[c] = ω(c → c+1)` in corner order and the corner tangent vectors `g[c]` (B.52).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FaceField {
    w: [f64; 3],
    g: [Vec3; 3],
}

impl FaceField {
    /// The corner tangent vectors `g[c]` (the gradient of the phase at corner `c`).
    pub(crate) fn corner_gradients(&self) -> [Vec3; 3] {
        self.g
    }
}

/// Solves `g·e1 = r1, g·e2 = r2` for `g = x e1 + y e2` (eq. B.52); `None` when the Gram
/// matrix is numerically singular.
fn corner_gradient(e1: Vec3, e2: Vec3, r1: f64, r2: f64) -> Option<Vec3> {
    let (a, b, c) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = a * c - b * b;
    let tr = a + c;
    if det.is_nan() || det <= 1e-12 * tr * tr {
        return None;
    }
    let x = (c * r1 - b * r2) / det;
    let y = (a * r2 - b * r1) / det;
    Some(e1 * x + e2 * y)
}

/// Least-squares tangent gradient of ω at vertex `v`: `g = argmin Σ_u (g·(x_u − x_v) − ω(v→u))²`
/// over the edges at `v`, with `g` in the plane orthogonal to the area-weighted vertex normal.
/// A rank-deficient system is solved along its dominant direction only; no value blows up.
fn ring_gradient(topo: &Topology, x: &[[f64; 3]], omega: &[f64], v: u32) -> Vec3 {
    let o = Vec3::from(x[v as usize]);
    let mut n = Vec3::ZERO;
    for &k in topo.vert_corners.row(v as usize) {
        let p = topo.faces[k as usize / 3].map(|u| Vec3::from(x[u as usize]));
        n += tri_normal(p[0], p[1], p[2]);
    }
    let (t1, t2) = tangent_basis(n);
    let (mut a, mut b, mut c, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &e in topo.vert_edges.row(v as usize) {
        let d = Vec3::from(x[topo.other_end(e as usize, v) as usize]) - o;
        let (p, q) = (d.dot(t1), d.dot(t2));
        let w = topo.omega_from(omega, e as usize, v);
        a += p * p;
        b += p * q;
        c += q * q;
        r1 += p * w;
        r2 += q * w;
    }
    let (s1, s2) = solve_sym2_robust(a, b, c, r1, r2);
    t1 * s1 + t2 * s2
}

/// An orthonormal pair spanning the plane orthogonal to `n` (any pair when `n = 0`).
fn tangent_basis(n: Vec3) -> (Vec3, Vec3) {
    let n = normalized(n).unwrap_or(Vec3::Z);
    let helper = if n.x.abs() < 0.6 { Vec3::X } else { Vec3::Y };
    let t1 = n.cross(helper);
    let t1 = t1 * (1.0 / t1.length());
    (t1, n.cross(t1))
}

/// Solves `[[a, b], [b, c]] s = r` for symmetric PSD input; along the dominant eigenvector only
/// when the matrix is numerically rank one, and `0` when it is zero.
fn solve_sym2_robust(a: f64, b: f64, c: f64, r1: f64, r2: f64) -> (f64, f64) {
    let tr = a + c;
    let det = a * c - b * b;
    if tr.is_nan() || tr <= 0.0 || !tr.is_finite() {
        return (0.0, 0.0);
    }
    if det > 1e-12 * tr * tr {
        return ((c * r1 - b * r2) / det, (a * r2 - b * r1) / det);
    }
    let lambda = 0.5 * (tr + ((a - c).powi(2) + 4.0 * b * b).sqrt());
    let (ux, uy) = if b != 0.0 {
        let (ux, uy) = (b, lambda - a);
        let l = ux.hypot(uy);
        (ux / l, uy / l)
    } else if a >= c {
        (1.0, 0.0)
    } else {
        (0.0, 1.0)
    };
    let s = (ux * r1 + uy * r2) / lambda;
    (s * ux, s * uy)
}

/// What the z rules read on the coarse level.
pub(crate) struct ZContext<'a> {
    pub topo: &'a Topology,
    pub rules: &'a [VertexRule],
    pub x: &'a [[f64; 3]],
    pub omega: &'a [f64],
    pub z: &'a [Complex],
    pub faces: Vec<FaceField>,
}

impl ZContext<'_> {
    /// `z(P) e^{iψ}` with `z(P)` of eq. 3.19 at barycentric `b` in face `f`: each corner's vote
    /// `b_c z_c e^{i(b_{c+1} ω(c→c+1) + b_{c+2} ω(c→c+2))}` is rotated by the extrapolation
    /// phase `ψ` in the same `cis` (one transcendental per corner).
    fn vote_with_phase(&self, f: usize, b: [f64; 3], psi: f64) -> Complex {
        let t = self.topo.faces[f];
        let w = self.faces[f].w;
        let mut acc = Complex::ZERO;
        for c in 0..3 {
            let zc = self.z[t[c] as usize];
            if b[c] == 0.0 || zc == Complex::ZERO {
                continue;
            }
            let (n, p) = ((c + 1) % 3, (c + 2) % 3);
            let phase = b[n] * w[c] - b[p] * w[p] + psi;
            acc += zc * Complex::cis(phase) * b[c];
        }
        acc
    }

    /// Eq. B.49: `ω(P)(d)` at barycentric coordinates `b` in face `f`.
    fn omega_at(&self, f: usize, b: [f64; 3], d: Vec3) -> f64 {
        let g = &self.faces[f].g;
        b[0] * g[0].dot(d) + b[1] * g[1].dot(d) + b[2] * g[2].dot(d)
    }

    fn position(&self, f: usize, b: [f64; 3]) -> Vec3 {
        let t = self.topo.faces[f];
        let x = |c: usize| Vec3::from(self.x[t[c] as usize]);
        x(0) * b[0] + x(1) * b[1] + x(2) * b[2]
    }

    /// `z(P) e^{iω(P)(target − P)}` for `P` at barycentric `b` in `f` (projected displacement);
    /// exactly zero, and cheap, when the face's three `z` are zero.
    fn vote(&self, f: usize, b: [f64; 3], target: [f64; 3]) -> Complex {
        if self.topo.faces[f]
            .iter()
            .all(|&v| self.z[v as usize] == Complex::ZERO)
        {
            return Complex::ZERO;
        }
        let p = self.position(f, b);
        let psi = self.omega_at(f, b, Vec3::from(target) - p);
        self.vote_with_phase(f, b, psi)
    }

    /// The votes of face `f` for the next level: per corner, the interior even-rule vote
    /// (eq. 3.24) `z(P) e^{iω(P)(v' − P)}` with `P = (1 − 2γ) v + γ (u + w)` and `v'` the new
    /// position (zero unless the corner's vertex follows the interior rule); per edge slot, the
    /// interior odd-rule vote (eqs. 3.20–3.21) `z(P₀) e^{iω(P₀)(P₁* − P₀)/2}` with
    /// `P₀ = 3/8 (a + b) + 1/4 c` (zero on boundary edges). Computed face by face so the
    /// per-face data is read sequentially; zero (and cheap) where the face's `z` all vanish.
    fn face_votes(&self, f: usize, fine_x: &[[f64; 3]]) -> FaceVotes {
        let t = self.topo.faces[f];
        if t.iter().all(|&v| self.z[v as usize] == Complex::ZERO) {
            return FaceVotes::default();
        }
        let corner = [0, 1, 2].map(|c| match self.rules[t[c] as usize] {
            VertexRule::Interior { gamma, .. } => {
                let mut b = [gamma; 3];
                b[c] = 1.0 - 2.0 * gamma;
                self.vote(f, b, fine_x[t[c] as usize])
            }
            _ => Complex::ZERO,
        });
        let edge = [0, 1, 2].map(|s| self.edge_vote(f, s));
        FaceVotes { corner, edge }
    }

    /// The odd-rule vote of face `f` for its edge in slot `s` (eqs. 3.20–3.21).
    fn edge_vote(&self, f: usize, s: usize) -> Complex {
        let topo = self.topo;
        let e = topo.face_edges[f][s] as usize;
        let k = usize::from(topo.edge_faces[e][0] != f as u32);
        let g = topo.edge_faces[e][1 - k];
        if g == NONE {
            return Complex::ZERO;
        }
        let t = topo.faces[f];
        let d = topo.faces[g as usize][(topo.edge_face_slot[e][1 - k] as usize + 2) % 3];
        let [a, b, c] =
            [t[s], t[(s + 1) % 3], t[(s + 2) % 3]].map(|v| Vec3::from(self.x[v as usize]));
        let dc = unfold(a, b, c, Vec3::from(self.x[d as usize]));
        let mut bc = [0.375; 3];
        bc[(s + 2) % 3] = 0.25;
        // P₁* − P₀ = (d* − c)/4; the text's step is half of it.
        let psi = self.omega_at(f, bc, dc * 0.125);
        self.vote_with_phase(f, bc, psi)
    }

    /// Even vertex `v` moving to `target` (eqs. 3.23–3.24 and the boundary rules); `votes` are
    /// the [`ZContext::face_votes`] of every face.
    fn even(&self, v: usize, target: [f64; 3], votes: &[FaceVotes]) -> Complex {
        let topo = self.topo;
        match self.rules[v] {
            VertexRule::Keep => self.z[v],
            VertexRule::Interior { .. } => {
                let fan = topo.vert_corners.row(v);
                let mut acc = Complex::ZERO;
                for &k in fan {
                    acc += votes[k as usize / 3].corner[k as usize % 3];
                }
                acc.scale(1.0 / fan.len() as f64)
            }
            VertexRule::Boundary { edges } => {
                let mut acc = Complex::ZERO;
                for e in edges {
                    let f = topo.edge_faces[e as usize][0] as usize;
                    let u = topo.other_end(e as usize, v as u32);
                    let mut b = [0.0; 3];
                    b[topo.corner_of(f, v as u32)] = 0.75;
                    b[topo.corner_of(f, u)] = 0.25;
                    acc += self.vote(f, b, target);
                }
                acc.scale(0.5)
            }
        }
    }

    /// Odd vertex of edge `e` (eqs. 3.18, 3.22): the boundary rule, or the mean of the two
    /// faces' [`ZContext::edge_vote`]s.
    fn odd(&self, e: usize, votes: &[FaceVotes]) -> Complex {
        let topo = self.topo;
        let [f0, f1] = topo.edge_faces[e];
        if f1 == NONE {
            let [a, b] = topo.edges[e];
            let w = self.omega[e];
            return (self.z[a as usize] * Complex::cis(0.5 * w)
                + self.z[b as usize] * Complex::cis(-0.5 * w))
            .scale(0.5);
        }
        let [s0, s1] = topo.edge_face_slot[e].map(usize::from);
        (votes[f0 as usize].edge[s0] + votes[f1 as usize].edge[s1]).scale(0.5)
    }
}

/// The six votes one face casts for the next level (see [`ZContext::face_votes`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FaceVotes {
    corner: [Complex; 3],
    edge: [Complex; 3],
}

/// Rigid unfolding across edge `ab` of the diamond `abc | abd` (eq. 3.21): returns `d* − c`,
/// where `d*` is `d` rotated about `ab` into the plane of `abc`, on the other side of `ab` from
/// `c`. With `ê` the unit vector along `ab`, `s_q = (q − a)·ê` and `h_q` the distance of `q` from
/// the line `ab`: `d* − c = (s_d − s_c) ê + (h_d + h_c) n̂`, `n̂` the unit in-plane normal of `ab`
/// pointing away from `c`. Degenerate pieces fall back gracefully: a zero-length `ab` gives
/// `d − c`, and a zero-height `abc` takes `n̂` towards `d`.
fn unfold(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> Vec3 {
    let ab = b - a;
    let len = ab.length();
    if len == 0.0 || !len.is_finite() {
        return d - c;
    }
    let axis = ab * (1.0 / len);
    let split = |q: Vec3| {
        let r = q - a;
        let s = r.dot(axis);
        let perp = r - axis * s;
        (s, perp, perp.length())
    };
    let (sc, pc, hc) = split(c);
    let (sd, pd, hd) = split(d);
    let tiny = 1e-300;
    let away_c = if hc > tiny {
        pc * (-1.0 / hc)
    } else if hd > tiny {
        pd * (1.0 / hd)
    } else {
        Vec3::ZERO
    };
    axis * (sd - sc) + away_c * (hd + hc)
}

/// All odd and even z values of the next level. `fine_x` are the S0 positions of the next level.
pub(crate) fn apply_z(ctx: &ZContext<'_>, fine_x: &[[f64; 3]]) -> Vec<Complex> {
    let votes: Vec<FaceVotes> = (0..ctx.topo.n_faces())
        .into_par_iter()
        .map(|f| ctx.face_votes(f, fine_x))
        .collect();
    let nv = ctx.topo.n_vertices;
    (0..nv + ctx.topo.n_edges())
        .into_par_iter()
        .map(|i| {
            if i < nv {
                ctx.even(i, fine_x[i], &votes)
            } else {
                ctx.odd(i - nv, &votes)
            }
        })
        .collect()
}

/// A mesh and `levels` Loop refinements of it, exposing the subdivision operators of §3.5 level
/// by level: S0 on vertex functions, S1 on one-forms, the z rule, and `d`. One-forms on every
/// level use the [`EdgeList`](crate::mesh::EdgeList) numbering and orientation of
/// [`LoopHierarchy::mesh`]`(level)`.
#[derive(Debug, Clone)]
pub struct LoopHierarchy {
    topo: Vec<Topology>,
    rules: Vec<Vec<VertexRule>>,
    positions: Vec<Vec<[f64; 3]>>,
}

impl LoopHierarchy {
    /// Validates `mesh` (manifold, possibly with boundary, consistently oriented; else
    /// [`Error::InvalidMesh`]) and refines it `levels` times.
    pub fn new(mesh: &TriMesh, levels: usize, opts: &SubdivisionOptions) -> Result<LoopHierarchy> {
        let mut base = Topology::from_mesh(mesh, &mesh.edges())?;
        if opts.boundary == BoundaryRule::Smooth {
            base.mark_corners(mesh.positions(), opts.corner_angle);
        }
        check_output_size(base.n_faces(), levels, usize::MAX)?;
        let mut h = LoopHierarchy {
            rules: vec![vertex_rules(&base, opts.boundary)],
            topo: vec![base],
            positions: vec![mesh.positions().to_vec()],
        };
        for l in 0..levels {
            let fine = h.topo[l].refine();
            let x = apply_s0(&h.topo[l], &h.rules[l], &h.positions[l]);
            h.rules.push(vertex_rules(&fine, opts.boundary));
            h.topo.push(fine);
            h.positions.push(x);
        }
        Ok(h)
    }

    /// Number of refinements (the finest level index).
    pub fn levels(&self) -> usize {
        self.topo.len() - 1
    }

    /// The mesh of `level` (0 = base). Panics when `level > levels()`.
    pub fn mesh(&self, level: usize) -> TriMesh {
        TriMesh::new(
            self.positions[level].clone(),
            self.topo[level].faces.clone(),
        )
        .expect("subdivided meshes are valid")
    }

    /// Number of edges of `level`.
    pub fn edge_count(&self, level: usize) -> usize {
        self.topo[level].n_edges()
    }

    /// S0: a vertex function on `level` to `level + 1` (eq. 3.23 and the odd/boundary rules).
    pub fn subdivide_scalar(&self, level: usize, f: &[f64]) -> Result<Vec<f64>> {
        self.check_level(level, f.len(), self.topo[level].n_vertices, "vertex values")?;
        Ok(apply_s0(&self.topo[level], &self.rules[level], f))
    }

    /// S1 (§3.5.1, App. B.2): a one-form on `level` (EdgeList orientation) to `level + 1`.
    pub fn subdivide_one_form(&self, level: usize, omega: &[f64]) -> Result<Vec<f64>> {
        self.check_level(
            level,
            omega.len(),
            self.topo[level].n_edges(),
            "edge values",
        )?;
        Ok(apply_s1(
            &self.topo[level],
            &self.topo[level + 1],
            &self.rules[level],
            omega,
        ))
    }

    /// The z rule (eqs. 3.18–3.24): per-vertex `z` on `level`, with the one-form `omega` of
    /// that level, to `level + 1`.
    pub fn subdivide_z(&self, level: usize, omega: &[f64], z: &[Complex]) -> Result<Vec<Complex>> {
        let topo = &self.topo[level];
        self.check_level(level, omega.len(), topo.n_edges(), "edge values")?;
        self.check_level(level, z.len(), topo.n_vertices, "vertex values")?;
        let x = &self.positions[level];
        let ctx = ZContext {
            topo,
            rules: &self.rules[level],
            x,
            omega,
            z,
            faces: face_gradients(topo, x, omega),
        };
        Ok(apply_z(&ctx, &self.positions[level + 1]))
    }

    /// The exterior derivative on `level`: `(df)_e = f[v1] − f[v0]` for edge `e = (v0, v1)`,
    /// `v0 < v1`.
    pub fn d(&self, level: usize, f: &[f64]) -> Result<Vec<f64>> {
        let topo = self
            .topo
            .get(level)
            .ok_or_else(|| Error::InvalidArgument(format!("level {level} does not exist")))?;
        if f.len() != topo.n_vertices {
            return crate::invalid_arg!(
                "{} vertex values given, level {level} has {} vertices",
                f.len(),
                topo.n_vertices
            );
        }
        Ok(exterior_derivative(topo, f))
    }

    fn check_level(&self, level: usize, got: usize, want: usize, what: &str) -> Result<()> {
        if level >= self.levels() {
            return crate::invalid_arg!(
                "level {level} has no finer level (the hierarchy has {} levels)",
                self.levels()
            );
        }
        if got != want {
            return crate::invalid_arg!("{got} {what} given, level {level} needs {want}");
        }
        Ok(())
    }
}

/// Errors with [`Error::LimitExceeded`] when `levels` refinements of `faces` triangles would
/// exceed `max_faces` or the u32 vertex index range.
pub(crate) fn check_output_size(faces: usize, levels: usize, max_faces: usize) -> Result<()> {
    // 4^32 · 2^64 < 2^128: no overflow below 33 levels, and 33 levels are absurd anyway
    let out = if levels <= 32 {
        (faces as u128) << (2 * levels)
    } else {
        u128::MAX
    };
    // 3F bounds V + E on any triangle mesh, and vertex indices are u32.
    if out > max_faces as u128 || 3 * out.min(u64::MAX as u128) > u32::MAX as u128 {
        let shown = if levels <= 32 {
            out.to_string()
        } else {
            "more than 2^64".into()
        };
        return Err(Error::LimitExceeded(format!(
            "{levels} subdivision levels of {faces} triangles give {shown} triangles, above the \
             limit of {} (or the u32 index range)",
            max_faces.min(u32::MAX as usize / 3)
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_size_limit() {
        assert!(check_output_size(1000, 5, 1 << 26).is_ok());
        assert!(check_output_size(1000, 12, 1 << 26).is_err());
        assert!(check_output_size(1024, 59, usize::MAX).is_err());
        assert!(check_output_size(1, 200, usize::MAX).is_err());
        assert!(check_output_size(1 << 20, 6, usize::MAX).is_err()); // > u32 indices
    }

    #[test]
    fn loop_weights() {
        assert!((loop_alpha(6) - 1.0 / 16.0).abs() < 1e-15);
        assert!((loop_alpha(3) - 3.0 / 16.0).abs() < 1e-15);
        for n in 3..40 {
            let na = n as f64 * loop_alpha(n);
            assert!(na > 0.2 && na <= 0.625);
        }
    }

    #[test]
    fn gradient_of_linear_function() {
        let k = Vec3::new(0.3, -1.7, 0.0);
        let e1 = Vec3::new(1.0, 0.2, 0.0);
        let e2 = Vec3::new(-0.4, 0.9, 0.0);
        let g = corner_gradient(e1, e2, k.dot(e1), k.dot(e2)).unwrap();
        assert!((g - k).length() < 1e-14);
        // degenerate: collinear edges are refused; the robust 2×2 solve stays finite
        assert!(corner_gradient(e1, e1 * 2.0, 1.0, 2.0).is_none());
        let (s1, s2) = solve_sym2_robust(1.0, 2.0, 4.0, 1.0, 2.0);
        assert!((s1 + 2.0 * s2 - 1.0).abs() < 1e-15 && (2.0 * s1 - s2).abs() < 1e-15);
    }

    #[test]
    fn unfolding_is_identity_on_flat_diamond() {
        let v = Vec3::from_array;
        let (a, b, c, d) = (
            Vec3::ZERO,
            v([1.0, 0.1, 0.0]),
            v([0.3, 0.8, 0.0]),
            v([0.6, -0.7, 0.0]),
        );
        assert!((unfold(a, b, c, d) - (d - c)).length() < 1e-15);
        assert!((unfold(b, a, d, c) - (c - d)).length() < 1e-15);
        // folded 90°: the unfolded distance is the intrinsic one
        let d = v([0.5, 0.0, -0.7]);
        let dc = unfold(a, v([1.0, 0.0, 0.0]), v([0.5, 0.7, 0.0]), d);
        assert!((dc - v([0.0, -1.4, 0.0])).length() < 1e-15);
    }
}
