//! Normal curvature of the base surface along each face's tension (crest) direction, the `κ_f`
//! of eq. 2.22, by two estimators ([`CurvatureMethod`]):
//!
//! - **Quadric fitting** (the spec's default, S:2276; R: `igl::principal_curvature`, 5 rings):
//!   per vertex a graph `z = c0 x² + c1 xy + c2 y² + c3 x + c4 y` fitted by least squares to its
//!   5-ring in the frame of its normal ([`quadric_fit`]); per face the fitted normal curvature
//!   along `dr_b t` at its three corners, averaged ([`tension_curvature_quadric`]).
//! - **Vertex normals** ([`tension_curvature`]): per face the second fundamental form from
//!   area-weighted vertex normals, `II ≈ −½(dn dxᵀ + dx dnᵀ)` in the face's barycentric frame
//!   (`dn(e_i) = n_i − n_0`), and `κ_f = tᵀ II t / tᵀ I t`. Exact on a sampled cylinder or
//!   sphere whose vertex normals are exact; local (no neighbourhood search).
//!
//! Sign irrelevant (κ enters squared). Note (measured on the twisted cylinder,
//! docs/design-notes.md): on a converged tension-field base without pressure, `κ_f ≈ 0` wherever
//! there is tension, by the membrane's normal equilibrium `σ : II = p` with the uniaxial stress `σ
//! = T t tᵀ` (`T κ_t = p = 0`); both estimators find |κ| ≈ 0.02–0.03 m⁻¹ there, so W_s² is weak on
//! such bases.

use super::dense::{cross, dot, sub};
use crate::mesh::TriMesh;
use crate::tfw::wfree::FaceStrain;

/// Area-weighted unit vertex normals of `mesh` (zero for isolated vertices).
pub fn vertex_normals(mesh: &TriMesh) -> Vec<[f64; 3]> {
    let p = mesh.positions();
    let mut n = vec![[0.0; 3]; p.len()];
    for t in mesh.triangles() {
        let [a, b, c] = t.map(|v| p[v as usize]);
        let fnrm = cross(sub(b, a), sub(c, a));
        for &v in t {
            for k in 0..3 {
                n[v as usize][k] += fnrm[k];
            }
        }
    }
    for x in &mut n {
        let l = dot(*x, *x).sqrt();
        if l > 0.0 {
            *x = [x[0] / l, x[1] / l, x[2] / l];
        }
    }
    n
}

/// Per face, the normal curvature along its tension direction `strains[f].tension_dir`
/// (module docs). 0 on faces whose base form is degenerate.
pub fn tension_curvature(mesh: &TriMesh, strains: &[FaceStrain]) -> Vec<f64> {
    let n = vertex_normals(mesh);
    let p = mesh.positions();
    mesh.triangles()
        .iter()
        .zip(strains)
        .map(|(t, s)| {
            let [x0, x1, x2] = t.map(|v| p[v as usize]);
            let [n0, n1, n2] = t.map(|v| n[v as usize]);
            let (e1, e2) = (sub(x1, x0), sub(x2, x0));
            let (d1, d2) = (sub(n1, n0), sub(n2, n0));
            let ii = [
                -dot(d1, e1),
                -0.5 * (dot(d1, e2) + dot(d2, e1)),
                -dot(d2, e2),
            ];
            let i = [dot(e1, e1), dot(e1, e2), dot(e2, e2)];
            let w = s.tension_dir;
            let q =
                |m: [f64; 3]| m[0] * w[0] * w[0] + 2.0 * m[1] * w[0] * w[1] + m[2] * w[1] * w[1];
            let den = q(i);
            if den > 0.0 {
                q(ii) / den
            } else {
                0.0
            }
        })
        .collect()
}

/// How `κ_f` (the normal curvature along the tension direction, eq. 2.22) is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CurvatureMethod {
    /// Quadric fitting on the `rings`-ring of each vertex (Panozzo et al. 2010, S:2276; R:
    /// `igl::principal_curvature` with its default 5 rings), Euler's formula along the face's
    /// tension direction at its three corners, averaged (the spec's default).
    #[default]
    QuadricFit,
    /// Per face from area-weighted vertex normals ([`tension_curvature`]; local, exact on
    /// sampled cylinders and spheres with exact normals).
    VertexNormals,
}

/// Rings of the quadric fit (R: `igl::principal_curvature` default radius 5).
pub const QUADRIC_FIT_RINGS: usize = 5;

/// The second fundamental form of a surface at a vertex, from a fitted quadric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexShape {
    /// Unit normal (the area-weighted vertex normal the fit is made in).
    pub normal: [f64; 3],
    /// Orthonormal tangent frame `(e1, e2)` with `e1 × e2 = normal`.
    pub frame: [[f64; 3]; 2],
    /// The fitted graph `z = c0 x² + c1 xy + c2 y² + c3 x + c4 y` over the frame (vertex at
    /// the origin).
    pub quadric: [f64; 5],
}

impl VertexShape {
    /// Normal curvature of the fitted quadric at the vertex along the 3D direction `d`
    /// (projected onto the graph's tangent plane): `II(u, u) / I(u, u)`. 0 for a direction
    /// normal to the surface.
    pub fn normal_curvature(&self, d: [f64; 3]) -> f64 {
        let [a, b, c, p, q] = self.quadric;
        let w = (1.0 + p * p + q * q).sqrt();
        // first and second fundamental forms of the graph at the origin
        let (e, f, g) = (1.0 + p * p, p * q, 1.0 + q * q);
        let (l, m, n) = (2.0 * a / w, b / w, 2.0 * c / w);
        // d in graph parameters: the least-squares (u, v) with u X_x + v X_y ≈ d,
        // X_x = e1 + p n, X_y = e2 + q n
        let dl = [
            dot(d, self.frame[0]),
            dot(d, self.frame[1]),
            dot(d, self.normal),
        ];
        let r = [dl[0] + p * dl[2], dl[1] + q * dl[2]];
        let det = e * g - f * f;
        let (u, v) = ((g * r[0] - f * r[1]) / det, (e * r[1] - f * r[0]) / det);
        let den = e * u * u + 2.0 * f * u * v + g * v * v;
        if den > 0.0 {
            (l * u * u + 2.0 * m * u * v + n * v * v) / den
        } else {
            0.0
        }
    }
}

/// Per vertex, the quadric fitted by least squares to the vertices of its `rings`-ring (at
/// least 5 of them; with fewer, the fit is flat), in the frame of its area-weighted normal.
/// Coordinates are scaled by the neighbourhood's radius before the fit (conditioning).
pub fn quadric_fit(mesh: &TriMesh, rings: usize) -> Vec<VertexShape> {
    let p = mesh.positions();
    let normals = vertex_normals(mesh);
    let adj = vertex_adjacency(mesh);
    let mut mark = vec![usize::MAX; p.len()];
    (0..p.len())
        .map(|v| {
            let n = normals[v];
            let frame = tangent_frame(n);
            let hood = k_ring(&adj, v, rings, &mut mark);
            let local: Vec<[f64; 3]> = hood
                .iter()
                .map(|&u| {
                    let d = sub(p[u], p[v]);
                    [dot(d, frame[0]), dot(d, frame[1]), dot(d, n)]
                })
                .collect();
            VertexShape {
                normal: n,
                frame,
                quadric: fit_graph_quadric(&local),
            }
        })
        .collect()
}

/// Per face, the normal curvature along its tension direction by [`quadric_fit`] on `rings`
/// rings: Euler's formula (the fitted second fundamental form) along `dr_b t` at each corner,
/// averaged over the three corners (R). 0 on faces whose base form is degenerate.
pub fn tension_curvature_quadric(mesh: &TriMesh, strains: &[FaceStrain], rings: usize) -> Vec<f64> {
    let shapes = quadric_fit(mesh, rings);
    let p = mesh.positions();
    mesh.triangles()
        .iter()
        .zip(strains)
        .map(|(t, s)| {
            let [x0, x1, x2] = t.map(|v| p[v as usize]);
            let w = s.tension_dir;
            let (e1, e2) = (sub(x1, x0), sub(x2, x0));
            let d: [f64; 3] = std::array::from_fn(|k| e1[k] * w[0] + e2[k] * w[1]);
            if dot(d, d) <= 0.0 {
                return 0.0;
            }
            t.iter()
                .map(|&v| shapes[v as usize].normal_curvature(d))
                .sum::<f64>()
                / 3.0
        })
        .collect()
}

/// Per face, `κ_f` by `method` (see [`CurvatureMethod`]).
pub fn tension_curvature_by(
    mesh: &TriMesh,
    strains: &[FaceStrain],
    method: CurvatureMethod,
) -> Vec<f64> {
    match method {
        CurvatureMethod::QuadricFit => tension_curvature_quadric(mesh, strains, QUADRIC_FIT_RINGS),
        CurvatureMethod::VertexNormals => tension_curvature(mesh, strains),
    }
}

/// Sorted vertex neighbours over the edges of `mesh`.
fn vertex_adjacency(mesh: &TriMesh) -> Vec<Vec<usize>> {
    let mut adj = vec![Vec::new(); mesh.vertex_count()];
    for t in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            adj[a].push(b);
            adj[b].push(a);
        }
    }
    for a in &mut adj {
        a.sort_unstable();
        a.dedup();
    }
    adj
}

/// The vertices within `rings` edge hops of `v`, `v` excluded, in breadth-first order.
/// `mark` is scratch (one entry per vertex, any content; entries equal to `v` mean visited).
fn k_ring(adj: &[Vec<usize>], v: usize, rings: usize, mark: &mut [usize]) -> Vec<usize> {
    mark[v] = v;
    let mut out = Vec::new();
    let mut front = vec![v];
    for _ in 0..rings {
        let mut next = Vec::new();
        for &u in &front {
            for &w in &adj[u] {
                if mark[w] != v {
                    mark[w] = v;
                    next.push(w);
                }
            }
        }
        out.extend_from_slice(&next);
        front = next;
    }
    out
}

/// An orthonormal tangent pair `(e1, e2)` with `e1 × e2 = n` (n unit).
fn tangent_frame(n: [f64; 3]) -> [[f64; 3]; 2] {
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = cross(helper, n);
    let l = dot(e1, e1).sqrt();
    let e1 = [e1[0] / l, e1[1] / l, e1[2] / l];
    [e1, cross(n, e1)]
}

/// Least-squares `z = c0 x² + c1 xy + c2 y² + c3 x + c4 y` through `pts` (local frame, vertex
/// at the origin), coordinates scaled by the largest in-plane distance. Zero with fewer than 5
/// points or a singular system.
#[allow(clippy::needless_range_loop)] // the 5×5 elimination indexes rows and columns
fn fit_graph_quadric(pts: &[[f64; 3]]) -> [f64; 5] {
    if pts.len() < 5 {
        return [0.0; 5];
    }
    let s = pts
        .iter()
        .fold(0.0f64, |m, q| m.max(q[0].hypot(q[1])))
        .max(f64::MIN_POSITIVE);
    let mut ata = [[0.0; 5]; 5];
    let mut atb = [0.0; 5];
    for q in pts {
        let (x, y, z) = (q[0] / s, q[1] / s, q[2] / s);
        let row = [x * x, x * y, y * y, x, y];
        for i in 0..5 {
            atb[i] += row[i] * z;
            for j in 0..5 {
                ata[i][j] += row[i] * row[j];
            }
        }
    }
    // Gaussian elimination with partial pivoting on the 5×5 normal equations
    let scale = (0..5).map(|i| ata[i][i]).fold(0.0f64, f64::max);
    for c in 0..5 {
        let piv = (c..5)
            .max_by(|&a, &b| ata[a][c].abs().total_cmp(&ata[b][c].abs()))
            .unwrap_or(c);
        if ata[piv][c].abs() <= 1e-12 * scale {
            return [0.0; 5];
        }
        ata.swap(c, piv);
        atb.swap(c, piv);
        for r in c + 1..5 {
            let f = ata[r][c] / ata[c][c];
            for k in c..5 {
                ata[r][k] -= f * ata[c][k];
            }
            atb[r] -= f * atb[c];
        }
    }
    let mut x = [0.0; 5];
    for c in (0..5).rev() {
        let acc: f64 = (c + 1..5).map(|k| ata[c][k] * x[k]).sum();
        x[c] = (atb[c] - acc) / ata[c][c];
    }
    // back to unscaled coordinates: z/s = c (x/s)² … ⇒ quadratic terms / s, linear unchanged
    [x[0] / s, x[1] / s, x[2] / s, x[3], x[4]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A jittered grid patch of the sphere of radius `r` (polar angle ≤ 60°).
    fn sphere_patch(r: f64, n: usize) -> TriMesh {
        let mut p = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (u, v) = (
                    -1.0 + 2.0 * i as f64 / (n - 1) as f64,
                    -1.0 + 2.0 * j as f64 / (n - 1) as f64,
                );
                let (u, v) = (u + 0.01 * ((7 * i + 3 * j) % 5) as f64, v);
                let (th, ph) = (1.0 * u.hypot(v).min(1.0) * 60f64.to_radians(), v.atan2(u));
                p.push([
                    r * th.sin() * ph.cos(),
                    r * th.sin() * ph.sin(),
                    r * th.cos(),
                ]);
            }
        }
        let mut t = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let v = |a: usize, b: usize| (b * n + a) as u32;
                t.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                t.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
        TriMesh::new(p, t).unwrap()
    }

    #[test]
    fn quadric_fit_recovers_sphere_curvature_in_every_direction() {
        let mesh = sphere_patch(2.0, 21);
        let shapes = quadric_fit(&mesh, 2);
        for (v, s) in shapes.iter().enumerate() {
            let (i, j) = (v % 21, v / 21);
            if i < 4 || j < 4 || i > 16 || j > 16 {
                continue; // near the patch's rim
            }
            for d in [s.frame[0], s.frame[1], [1.0, 1.0, 0.0]] {
                let k = s.normal_curvature(d).abs();
                assert!((k - 0.5).abs() < 0.01, "vertex {v}: |κ| {k}, want 0.5");
            }
        }
    }
}
