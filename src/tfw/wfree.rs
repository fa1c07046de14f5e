//! Wrinkle-free faces and the per-face wrinkle initialization (§2.5.1, A.6.2; spec steps 3–4,
//! first part).
//!
//! - [`face_strains`]: per face the generalized eigenpairs of `(I − Ī)w = λĪw` (eq. 2.29):
//!   `λ_c ≤ λ_t` and their directions in the face's barycentric frame, normalized `wᵀĪw = 1`.
//! - [`wrinkle_free_faces`]: the set W by the text's rule (S:648: `μ_f` = mean of `λ_c` over f
//!   and its edge neighbours, `f ∈ W ⇔ μ_f > 0`, then isolated W faces removed and non-W
//!   faces whose three neighbours are all in W added) or the reference code's rule
//!   (`λ_c ≥ 0`, then every face whose three vertices touch W faces added).
//! - [`initial_face_field`]: A.6.2 per face — `â_f = √(2|λ_c|)`, the one-form `ω̂_f = Ī_f ŵ`
//!   (`ŵ` the compression direction, unit in `Ī`, so `½ â² |ω̂|² = |λ_c|`, eq. 2.8), signs
//!   combed (not in the text; R `combField`): Kruskal over dual edges by descending
//!   `min(â_f, â_g)` with a union–find that keeps each face's flip parity, comparing the two
//!   faces' wave vectors embedded in 3D on the base surface; then the scale
//!   `c = k / max_f â_f` (`a = c â`, `ω = ω̂/c`), and vertex amplitudes (mean of incident
//!   faces, zero on W and clamped vertices, two smoothing passes).
//!
//! - [`helmholtz_projection`]: the edge one-form `ω = argmin Σ_f √det Ī_f (D_fω − ω_f)ᵀ Ī_f⁻¹
//!   (D_fω − ω_f) + reg‖ω‖²` subject to `curl ω = 0` on every non-W face (A.6.2, A.8),
//!   on pleat's edge numbering. Departure: the spec's one KKT/LDLT solve needs an indefinite
//!   factorization that `crate::solve` does not have; the method of multipliers (augmented
//!   Lagrangian) on one sparse Cholesky of `Q + μCᵀC` reaches the constraint to rounding in a
//!   few solves instead. Edges of W faces only are 0.

use super::dense::{dot, sub};
use crate::mesh::TriMesh;
use crate::solve::{assemble, CholeskyAnalysis, Entry, Parallelism};
use crate::tfw::material::{principal_strains, Form};
use crate::{Error, Result};

/// The generalized eigen-decomposition of a face's strain (eq. 2.29).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceStrain {
    /// The smaller eigenvalue (compression when negative).
    pub lambda_c: f64,
    /// The larger eigenvalue (tension when positive).
    pub lambda_t: f64,
    /// Eigenvector of `λ_c` in barycentric coordinates, `wᵀĪw = 1`: the wave-vector direction.
    pub compression_dir: [f64; 2],
    /// Eigenvector of `λ_t`, `tᵀĪt = 1`: the crest (tension) direction.
    pub tension_dir: [f64; 2],
}

/// Which rule decides the wrinkle-free faces W.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WRule {
    /// The dissertation's rule (S:648): neighbour mean of `λ_c` > 0, outlier filter.
    #[default]
    Text,
    /// The reference code's rule: `λ_c ≥ 0`, then vertex fill.
    Reference,
}

/// Per face of `base`, the eigen-decomposition of its strain against `rest_forms` (one per
/// face, positive determinant).
pub fn face_strains(rest_forms: &[Form], base: &TriMesh) -> Vec<FaceStrain> {
    base.triangles()
        .iter()
        .zip(rest_forms)
        .map(|(t, &rest)| {
            let p = t.map(|v| base.positions()[v as usize]);
            let e1 = sub(p[1], p[0]);
            let e2 = sub(p[2], p[0]);
            let cur = [dot(e1, e1), dot(e1, e2), dot(e2, e2)];
            let (lt, lc) = principal_strains(rest, cur);
            FaceStrain {
                lambda_c: lc,
                lambda_t: lt,
                compression_dir: eigvec(rest, cur, lc, [1.0, 0.0]),
                tension_dir: eigvec(rest, cur, lt, [0.0, 1.0]),
            }
        })
        .collect()
}

/// A unit (in `Ī`) solution of `(I − Ī − λĪ) w = 0`; `fallback` (normalized) when the pencil
/// is isotropic.
fn eigvec(rest: Form, cur: Form, l: f64, fallback: [f64; 2]) -> [f64; 2] {
    let m = [
        cur[0] - rest[0] - l * rest[0],
        cur[1] - rest[1] - l * rest[1],
        cur[2] - rest[2] - l * rest[2],
    ];
    // null vector of [[m0, m1], [m1, m2]]: orthogonal to its larger row
    let r0 = [-m[1], m[0]];
    let r1 = [m[2], -m[1]];
    let n0 = r0[0].hypot(r0[1]);
    let n1 = r1[0].hypot(r1[1]);
    let scale = m.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let w = if n0.max(n1) <= 1e-12 * scale.max(f64::MIN_POSITIVE) || scale == 0.0 {
        fallback
    } else if n0 >= n1 {
        r0
    } else {
        r1
    };
    let q = rest[0] * w[0] * w[0] + 2.0 * rest[1] * w[0] * w[1] + rest[2] * w[1] * w[1];
    let s = 1.0 / q.sqrt();
    [w[0] * s, w[1] * s]
}

/// Per face, its edge neighbours (faces sharing an edge; at most 3 on a manifold mesh).
pub fn face_neighbours(triangles: &[[u32; 3]]) -> Vec<Vec<usize>> {
    let mut by_edge: Vec<((u32, u32), usize)> = Vec::with_capacity(3 * triangles.len());
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge.push(((a.min(b), a.max(b)), f));
        }
    }
    by_edge.sort_unstable();
    let mut nb = vec![Vec::new(); triangles.len()];
    for run in by_edge.chunk_by(|x, y| x.0 == y.0) {
        for &(_, f) in run {
            for &(_, g) in run {
                if f != g && !nb[f].contains(&g) {
                    nb[f].push(g);
                }
            }
        }
    }
    nb
}

/// The wrinkle-free faces W (true = in W) from the per-face `λ_c` by `rule` (module docs).
pub fn wrinkle_free_faces(triangles: &[[u32; 3]], lambda_c: &[f64], rule: WRule) -> Vec<bool> {
    let nb = face_neighbours(triangles);
    match rule {
        WRule::Text => {
            let mut w: Vec<bool> = (0..triangles.len())
                .map(|f| {
                    let s: f64 = lambda_c[f] + nb[f].iter().map(|&g| lambda_c[g]).sum::<f64>();
                    s / (1 + nb[f].len()) as f64 > 0.0
                })
                .collect();
            let isolated: Vec<usize> = (0..w.len())
                .filter(|&f| w[f] && !nb[f].iter().any(|&g| w[g]))
                .collect();
            for f in isolated {
                w[f] = false;
            }
            let enclosed: Vec<usize> = (0..w.len())
                .filter(|&f| !w[f] && nb[f].len() == 3 && nb[f].iter().all(|&g| w[g]))
                .collect();
            for f in enclosed {
                w[f] = true;
            }
            w
        }
        WRule::Reference => {
            let mut w: Vec<bool> = lambda_c.iter().map(|&l| l >= 0.0).collect();
            let nv = triangles
                .iter()
                .flatten()
                .map(|&v| v as usize + 1)
                .max()
                .unwrap_or(0);
            let mut touches = vec![false; nv];
            for (t, &inw) in triangles.iter().zip(&w) {
                if inw {
                    for &v in t {
                        touches[v as usize] = true;
                    }
                }
            }
            for (t, x) in triangles.iter().zip(w.iter_mut()) {
                if t.iter().all(|&v| touches[v as usize]) {
                    *x = true;
                }
            }
            w
        }
    }
}

/// The initial wrinkle field per face and per vertex (A.6.2).
#[derive(Debug, Clone, PartialEq)]
pub struct InitialField {
    /// Per face, the amplitude `c â_f` (0 on W faces and faces with `λ_c ≥ 0`).
    pub face_amplitude: Vec<f64>,
    /// Per face, the one-form `ω̂_f / c` as `(ω(v0→v1), ω(v0→v2))` (0 where the amplitude is 0).
    pub face_omega: Vec<[f64; 2]>,
    /// Per face, whether combing flipped its sign.
    pub flipped: Vec<bool>,
    /// Per vertex, the initial amplitude (≥ 0; 0 on W and clamped vertices).
    pub vertex_amplitude: Vec<f64>,
    /// The scale `c = k / max_f â_f` (1 when no face is compressed).
    pub scale: f64,
}

/// A.6.2 without the Helmholtz projection (module docs): `k` is the target peak amplitude (the
/// spec's default `min(0.01 m, 0.1 · bbox diagonal)`), `w_faces` from
/// [`wrinkle_free_faces`], `clamped` per vertex.
pub fn initial_face_field(
    base: &TriMesh,
    rest_forms: &[Form],
    strains: &[FaceStrain],
    w_faces: &[bool],
    clamped: &[bool],
    k: f64,
) -> InitialField {
    let nf = strains.len();
    let active = |f: usize| !w_faces[f] && strains[f].lambda_c < 0.0;
    let a_hat: Vec<f64> = (0..nf)
        .map(|f| {
            if active(f) {
                (2.0 * strains[f].lambda_c.abs()).sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let omega_hat: Vec<[f64; 2]> = (0..nf)
        .map(|f| {
            if !active(f) {
                return [0.0; 2];
            }
            let (r, w) = (rest_forms[f], strains[f].compression_dir);
            [r[0] * w[0] + r[1] * w[1], r[1] * w[0] + r[2] * w[1]]
        })
        .collect();
    let flipped = comb_signs(base, &a_hat, &omega_hat);
    let max_a = a_hat.iter().fold(0.0f64, |m, &a| m.max(a));
    let scale = if max_a > 0.0 { k / max_a } else { 1.0 };
    let face_amplitude: Vec<f64> = a_hat.iter().map(|a| scale * a).collect();
    let face_omega: Vec<[f64; 2]> = omega_hat
        .iter()
        .zip(&flipped)
        .map(|(w, &fl)| {
            let s = if fl { -1.0 } else { 1.0 } / scale;
            [s * w[0], s * w[1]]
        })
        .collect();
    let vertex_amplitude = vertex_amplitudes(base, &face_amplitude, w_faces, clamped);
    InitialField {
        face_amplitude,
        face_omega,
        flipped,
        vertex_amplitude,
        scale,
    }
}

/// The 3D tangent vector `g` of face `f` with `g·E1 = ω1`, `g·E2 = ω2` (E the base edges).
pub fn embedded_wave_vector(base: &TriMesh, f: usize, omega: [f64; 2]) -> [f64; 3] {
    let p = base.triangles()[f].map(|v| base.positions()[v as usize]);
    let (e1, e2) = (sub(p[1], p[0]), sub(p[2], p[0]));
    let (i0, i1, i2) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
    let det = i0 * i2 - i1 * i1;
    if det <= 0.0 {
        return [0.0; 3];
    }
    let c1 = (i2 * omega[0] - i1 * omega[1]) / det;
    let c2 = (-i1 * omega[0] + i0 * omega[1]) / det;
    [
        c1 * e1[0] + c2 * e2[0],
        c1 * e1[1] + c2 * e2[1],
        c1 * e1[2] + c2 * e2[2],
    ]
}

/// Sign combing: per face, whether to flip `omega[f]` so that neighbouring wave vectors agree,
/// greedily along dual edges by descending `min(a_f, a_g)` (faces with `a = 0` do not take part).
fn comb_signs(base: &TriMesh, a: &[f64], omega: &[[f64; 2]]) -> Vec<bool> {
    let nf = a.len();
    let nb = face_neighbours(base.triangles());
    let g: Vec<[f64; 3]> = (0..nf)
        .map(|f| embedded_wave_vector(base, f, omega[f]))
        .collect();
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for f in 0..nf {
        for &h in &nb[f] {
            if f < h && a[f] > 0.0 && a[h] > 0.0 {
                pairs.push((a[f].min(a[h]), f, h));
            }
        }
    }
    pairs.sort_by(|x, y| y.0.total_cmp(&x.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    // union–find with parity: parity[f] = flip of f relative to its parent
    let mut parent: Vec<usize> = (0..nf).collect();
    let mut parity = vec![false; nf];
    fn find(parent: &mut [usize], parity: &mut [bool], f: usize) -> (usize, bool) {
        let mut path = Vec::new();
        let mut x = f;
        while parent[x] != x {
            path.push(x);
            x = parent[x];
        }
        // compress: parity to root accumulated from the top of the path down
        let root = x;
        let mut acc = false;
        for &y in path.iter().rev() {
            acc ^= parity[y];
            parity[y] = acc;
            parent[y] = root;
        }
        (root, if path.is_empty() { false } else { parity[f] })
    }
    for (_, f, h) in pairs {
        let (rf, pf) = find(&mut parent, &mut parity, f);
        let (rh, ph) = find(&mut parent, &mut parity, h);
        if rf == rh {
            continue;
        }
        let disagree = dot(g[f], g[h]) < 0.0;
        // want flip(f) xor flip(h) == disagree; flip(x) = parity(x) xor flip(root)
        parent[rh] = rf;
        parity[rh] = pf ^ ph ^ disagree;
    }
    (0..nf)
        .map(|f| find(&mut parent, &mut parity, f).1)
        .collect()
}

fn vertex_amplitudes(
    base: &TriMesh,
    face_amplitude: &[f64],
    w_faces: &[bool],
    clamped: &[bool],
) -> Vec<f64> {
    let n = base.vertex_count();
    let (mut sum, mut count) = (vec![0.0; n], vec![0usize; n]);
    let mut zero = clamped.to_vec();
    zero.resize(n, false);
    let mut ring: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (f, t) in base.triangles().iter().enumerate() {
        for k in 0..3 {
            let v = t[k] as usize;
            sum[v] += face_amplitude[f];
            count[v] += 1;
            if w_faces[f] {
                zero[v] = true;
            }
            for j in 1..3 {
                let u = t[(k + j) % 3];
                if !ring[v].contains(&u) {
                    ring[v].push(u);
                }
            }
        }
    }
    let mut a: Vec<f64> = (0..n)
        .map(|v| {
            if zero[v] || count[v] == 0 {
                0.0
            } else {
                sum[v] / count[v] as f64
            }
        })
        .collect();
    for _pass in 0..2 {
        let prev = a.clone();
        for v in 0..n {
            if prev[v] > 0.0 {
                let s: f64 = prev[v] + ring[v].iter().map(|&u| prev[u as usize]).sum::<f64>();
                a[v] = s / (1 + ring[v].len()) as f64;
            }
        }
    }
    a
}

/// The curl-free edge one-form of [`helmholtz_projection`].
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// One value per edge of [`TriMesh::edges`], integrated from the smaller to the larger
    /// vertex index.
    pub omega: Vec<f64>,
    /// `max_f |curl ω|` over non-W faces.
    pub curl_residual: f64,
    /// Cholesky solves used (augmented-Lagrangian iterations).
    pub solves: usize,
}

/// Projects the per-face one-forms `face_omega` (`(ω(v0→v1), ω(v0→v2))`) onto a one-form on
/// edges that is curl-free on every face not in `w_faces` (module docs). The regularization is
/// `1e-8 · mean diag(Q)`, the penalty `μ = 1e4 · mean diag(Q)`; stops when the curl residual is
/// below `1e-13 · max(1, max|ω|)` or after 50 solves. Errors ([`Error::Numerical`]) when the
/// factorization fails.
pub fn helmholtz_projection(
    base: &TriMesh,
    rest_forms: &[Form],
    face_omega: &[[f64; 2]],
    w_faces: &[bool],
) -> Result<Projection> {
    let el = base.edges();
    let ne = el.len();
    let mut q: Vec<Entry> = Vec::new();
    let mut b = vec![0.0; ne];
    let mut curl: Vec<[(usize, f64); 3]> = Vec::new();
    let mut used = vec![false; ne];
    for f in 0..base.triangle_count() {
        if w_faces[f] {
            continue;
        }
        let (fe, fs) = (el.face_edges[f], el.face_edge_sign[f]);
        if fs.contains(&0) {
            continue; // degenerate corner
        }
        let e = fe.map(|x| x as usize);
        let sg = fs.map(f64::from);
        for &x in &e {
            used[x] = true;
        }
        curl.push([(e[0], sg[0]), (e[1], sg[1]), (e[2], sg[2])]);
        let r = rest_forms[f];
        let det = r[0] * r[2] - r[1] * r[1];
        let w = det.sqrt();
        let inv = [r[2] / det, -r[1] / det, r[0] / det];
        // D_f ω = (s0 ω[e0], −s2 ω[e2])
        let (i0, c0, i1, c1) = (e[0], sg[0], e[2], -sg[2]);
        let push = |q: &mut Vec<Entry>, a: usize, bb: usize, v: f64| {
            q.push(Entry::new(a.max(bb), a.min(bb), v));
        };
        push(&mut q, i0, i0, w * c0 * c0 * inv[0]);
        push(&mut q, i1, i1, w * c1 * c1 * inv[2]);
        push(&mut q, i0, i1, w * c0 * c1 * inv[1]);
        let o = face_omega[f];
        let io = [inv[0] * o[0] + inv[1] * o[1], inv[1] * o[0] + inv[2] * o[1]];
        b[i0] += w * c0 * io[0];
        b[i1] += w * c1 * io[1];
    }
    let var: Vec<usize> = (0..ne).filter(|&x| used[x]).collect();
    let mut idx = vec![usize::MAX; ne];
    for (k, &x) in var.iter().enumerate() {
        idx[x] = k;
    }
    let nv = var.len();
    if nv == 0 {
        return Ok(Projection {
            omega: vec![0.0; ne],
            curl_residual: 0.0,
            solves: 0,
        });
    }
    let diag: f64 = q
        .iter()
        .filter(|t| t.row == t.col)
        .map(|t| t.val)
        .sum::<f64>()
        / nv as f64;
    let scale = if diag > 0.0 { diag } else { 1.0 };
    let (reg, mu) = (1e-8 * scale, 1e4 * scale);
    let mut entries: Vec<Entry> = q
        .iter()
        .map(|t| Entry::new(idx[t.row], idx[t.col], t.val))
        .collect();
    entries.extend((0..nv).map(|k| Entry::new(k, k, reg)));
    for row in &curl {
        for &(a, sa) in row {
            for &(c, sc) in row {
                let (ia, ic) = (idx[a], idx[c]);
                if ia >= ic {
                    entries.push(Entry::new(ia, ic, mu * sa * sc));
                }
            }
        }
    }
    let a = assemble(nv, &entries, "tfw Helmholtz projection")?;
    let chol = CholeskyAnalysis::new(&a)?
        .factor(&a, Parallelism::Global)
        .map_err(|e| Error::Numerical(format!("tfw Helmholtz projection: {e:?}")))?;
    let bv: Vec<f64> = var.iter().map(|&x| b[x]).collect();
    let mut y = vec![0.0; curl.len()];
    let mut omega = vec![0.0; ne];
    let mut solves = 0;
    let mut residual = f64::INFINITY;
    while solves < 50 {
        // (Q + reg I + μCᵀC) ω = b − Cᵀy
        let mut rhs = bv.clone();
        for (row, &yk) in curl.iter().zip(&y) {
            for &(e, s) in row {
                rhs[idx[e]] -= s * yk;
            }
        }
        let sol = chol.solve(&rhs);
        solves += 1;
        for (k, &x) in var.iter().enumerate() {
            omega[x] = sol[k];
        }
        residual = 0.0;
        for (row, yk) in curl.iter().zip(y.iter_mut()) {
            let r: f64 = row.iter().map(|&(e, s)| s * omega[e]).sum();
            residual = residual.max(r.abs());
            *yk += mu * r;
        }
        let big = omega.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        if residual <= 1e-13 * big {
            break;
        }
    }
    Ok(Projection {
        omega,
        curl_residual: residual,
        solves,
    })
}
