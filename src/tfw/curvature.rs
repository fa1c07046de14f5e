//! Normal curvature of the base surface along each face's tension (crest) direction, the `κ_f`
//! of eq. 2.22.
//!
//! Departure from the spec (quadric fitting on a 5-ring, Panozzo 2010, S:2276): per face the
//! second fundamental form is estimated from area-weighted vertex normals,
//! `II ≈ −½(dn dxᵀ + dx dnᵀ)` in the face's barycentric frame (`dn(e_i) = n_i − n_0`), and
//! `κ_f = tᵀ II t / tᵀ I t` with `t` the tension direction. It is exact on a sampled cylinder or
//! sphere whose vertex normals are exact, needs no neighbourhood search, and its sign is
//! irrelevant (κ enters squared). Quadric fitting remains the spec's default and is not written.

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
