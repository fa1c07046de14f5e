//! Phase from frequency (Knöppel et al. 2015, as used by the dissertation §3.2.2 and §3.3):
//! `z̃` is the eigenvector of the smallest eigenvalue of the ω-connection Laplacian `L_ω`
//! against the lumped mass matrix `M`,
//!
//! ```text
//! z̃ = argmin  z^H L_ω z   subject to  z^H M z = 1,
//! z^H L_ω z = Σ_edges w_kl |z_l − e^{iω_kl} z_k|²,
//! ```
//!
//! i.e. the discrete `∫ |(d − iω) z|²` of eq. 3.2 with the unit constraint relaxed to a norm
//! constraint, then normalized per vertex (`|z̃_j| = 1`; a vertex whose eigenvector entry
//! vanishes — below `1e-12` of the largest — gets `z̃_j = 0`, a singularity on the vertex).
//!
//! `w_kl` are the cotangent weights `(cot α + cot β)/2` (Knöppel et al.; [`PhaseWeights::Cotan`],
//! clamped below at `1e-3` of their mean absolute value so the matrix stays positive
//! semi-definite on obtuse meshes) or the barycentric edge areas of eq. 3.5
//! ([`PhaseWeights::EdgeArea`]). `M` holds the barycentric vertex areas.
//!
//! The Hermitian problem is solved in its real `2n × 2n` form (`z_j = x_j + i y_j`, unknowns
//! interleaved `x_0, y_0, x_1, …`; a complex entry `a + ib` becomes the block `[[a, −b], [b, a]]`)
//! by inverse iteration `(L + σM) u_{k+1} = M u_k` with one cached faer sparse Cholesky
//! factorization. The shift `σ = shift · max_j(L_jj / M_j)` makes `L + σM` positive definite
//! (on a compatible ω the smallest eigenvalue is 0); when the factorization still fails, σ is
//! multiplied by 100, up to 4 times.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use super::complex::Complex;
use super::cwf::barycentric_areas;
use super::report::CwfStage;
use super::topology::{cross, dot, norm, sub, Topology};
use crate::report::StageTimes;
use crate::{Error, Result};

/// Edge weights of the connection Laplacian.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u32)]
pub enum PhaseWeights {
    /// Cotangent weights (Knöppel et al. 2015), clamped to stay positive.
    #[default]
    Cotan = 0,
    /// Barycentric edge areas `A_kl` (the weights of `E_compat`, eq. 3.5).
    EdgeArea = 1,
}

/// Parameters of the Knöppel phase solve ([`Cwf::from_one_form`](super::Cwf::from_one_form)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnoppelOptions {
    /// Edge weights; default cotangent.
    pub weights: PhaseWeights,
    /// Maximum inverse-iteration steps; default 200.
    pub max_iterations: usize,
    /// Stop when the relative change of the Rayleigh quotient and the M-norm residual
    /// `‖L u − λ M u‖_M / ‖u‖_M` (relative to the largest `L_jj/M_j`) fall below this; default 1e-12.
    pub tolerance: f64,
    /// Relative shift σ / max(L_jj / M_j); default 1e-9.
    pub shift: f64,
}

impl Default for KnoppelOptions {
    fn default() -> Self {
        KnoppelOptions {
            weights: PhaseWeights::Cotan,
            max_iterations: 200,
            tolerance: 1e-12,
            shift: 1e-9,
        }
    }
}

/// What the Knöppel phase solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct KnoppelReport {
    /// Smallest generalized eigenvalue `λ = z^H L z / z^H M z` found (the largest of these
    /// over the mesh's connected components, each of which is solved independently).
    pub eigenvalue: f64,
    /// Inverse-iteration steps taken.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// The shift σ used.
    pub shift: f64,
    /// Wall seconds of building the CWF (`validate`, `knoppel`), filled by
    /// [`Cwf::from_one_form`](super::Cwf::from_one_form).
    pub stages: StageTimes<CwfStage>,
}

/// Knöppel et al. 2015 phase `z̃` (unit per vertex) for the one-form `omega` (EdgeList
/// orientation) on the mesh of `topo` with positions `x`. See the [module docs](self).
pub(crate) fn knoppel_phase(
    topo: &Topology,
    x: &[[f64; 3]],
    omega: &[f64],
    opts: &KnoppelOptions,
) -> Result<(Vec<Complex>, KnoppelReport)> {
    let n = topo.n_vertices;
    let (edge_area, vertex_area) = barycentric_areas(topo, x);
    let w = match opts.weights {
        PhaseWeights::Cotan => cotan_weights(topo, x),
        PhaseWeights::EdgeArea => edge_area,
    };
    let mass = floored(&vertex_area);
    let (llt, sigma) = factor_shifted(topo, &w, omega, &mass, opts.shift)?;
    let apply_l = |u: &[f64]| connection_laplacian_apply(topo, &w, omega, u);
    let (comp, n_comp) = components(topo);
    let mut u: Vec<f64> = (0..2 * n)
        .map(|i| if i % 2 == 0 { 1.0 } else { 0.5 })
        .collect();
    normalize_m(&mut u, &mass, &comp, n_comp);
    let scale = max_ratio(topo, &w, &mass);
    let mut lambda = vec![f64::INFINITY; n_comp];
    let mut report = KnoppelReport {
        eigenvalue: 0.0,
        iterations: 0,
        residual: f64::INFINITY,
        shift: sigma,
        stages: StageTimes::default(),
    };
    for it in 1..=opts.max_iterations.max(1) {
        let mut rhs = Mat::<f64>::from_fn(2 * n, 1, |i, _| mass[i / 2] * u[i]);
        llt.solve_in_place(&mut rhs);
        u = (0..2 * n).map(|i| rhs[(i, 0)]).collect();
        if !u.iter().all(|v| v.is_finite()) {
            return Err(Error::Numerical(
                "inverse iteration produced a non-finite vector".into(),
            ));
        }
        normalize_m(&mut u, &mass, &comp, n_comp);
        let lu = apply_l(&u);
        let new_lambda = rayleigh_quotients(&u, &lu, &comp, n_comp);
        let residual = residual_m(&lu, &u, &new_lambda, &mass, &comp) / scale;
        let change = new_lambda
            .iter()
            .zip(&lambda)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale;
        lambda = new_lambda;
        report = KnoppelReport {
            eigenvalue: lambda.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            iterations: it,
            residual,
            shift: sigma,
            stages: StageTimes::default(),
        };
        if residual < opts.tolerance || (change < opts.tolerance * 1e-3 && it > 2) {
            break;
        }
    }
    Ok((normalize_per_vertex(&u), report))
}

/// `L_ω u` in the interleaved real form.
fn connection_laplacian_apply(topo: &Topology, w: &[f64], omega: &[f64], u: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; u.len()];
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        let zk = Complex::new(u[2 * k], u[2 * k + 1]);
        let zl = Complex::new(u[2 * l], u[2 * l + 1]);
        let t = Complex::cis(omega[e]);
        // ∂/∂z̄ of w|z_l − t z_k|²: row l gets w(z_l − t z_k), row k gets w(z_k − t̄ z_l)
        let rl = (zl - t * zk).scale(w[e]);
        let rk = (zk - t.conj() * zl).scale(w[e]);
        out[2 * l] += rl.re;
        out[2 * l + 1] += rl.im;
        out[2 * k] += rk.re;
        out[2 * k + 1] += rk.im;
    }
    out
}

/// Assembles `L_ω + σM` (real form) and factors it, raising σ when it is not numerically PD.
fn factor_shifted(
    topo: &Topology,
    w: &[f64],
    omega: &[f64],
    mass: &[f64],
    shift: f64,
) -> Result<(Llt<usize, f64>, f64)> {
    let n = topo.n_vertices;
    let mut sigma = shift.max(1e-15) * max_ratio(topo, w, mass);
    let off = off_diagonal_triplets(topo, w, omega);
    let mut diag = vec![0.0; n];
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        diag[k as usize] += w[e];
        diag[l as usize] += w[e];
    }
    let mut symbolic: Option<SymbolicLlt<usize>> = None;
    for _ in 0..5 {
        let mut t = off.clone();
        for j in 0..n {
            let d = diag[j] + sigma * mass[j];
            t.push(Triplet::new(2 * j, 2 * j, d));
            t.push(Triplet::new(2 * j + 1, 2 * j + 1, d));
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(2 * n, 2 * n, &t)
            .map_err(|e| Error::Numerical(format!("assembling the connection Laplacian: {e:?}")))?;
        let sym = match &symbolic {
            Some(s) => s.clone(),
            None => {
                let s = SymbolicLlt::try_new(a.symbolic(), Side::Lower).map_err(|e| {
                    Error::Numerical(format!("symbolic Cholesky analysis failed: {e:?}"))
                })?;
                symbolic = Some(s.clone());
                s
            }
        };
        if let Ok(llt) = Llt::try_new_with_symbolic(sym, a.as_ref(), Side::Lower) {
            return Ok((llt, sigma));
        }
        sigma *= 100.0;
    }
    Err(Error::Numerical(
        "the shifted connection Laplacian is not positive definite (is the mesh degenerate?)"
            .into(),
    ))
}

/// Off-diagonal 2×2 blocks: `H_lk = −w e^{iω_kl}`, `H_kl = −w e^{−iω_kl}`.
fn off_diagonal_triplets(
    topo: &Topology,
    w: &[f64],
    omega: &[f64],
) -> Vec<Triplet<usize, usize, f64>> {
    let mut t = Vec::with_capacity(8 * topo.n_edges() + 2 * topo.n_vertices);
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        let (s, c) = omega[e].sin_cos();
        let (a, b) = (-w[e] * c, -w[e] * s);
        // block (l, k) of a + ib: [[a, −b], [b, a]]; block (k, l) is its transpose
        for (r, q, v) in [(0, 0, a), (0, 1, -b), (1, 0, b), (1, 1, a)] {
            t.push(Triplet::new(2 * l + r, 2 * k + q, v));
            t.push(Triplet::new(2 * k + q, 2 * l + r, v));
        }
    }
    t
}

/// `max_j L_jj / M_j`: the scale of the generalized eigenvalues.
fn max_ratio(topo: &Topology, w: &[f64], mass: &[f64]) -> f64 {
    let mut diag = vec![0.0; topo.n_vertices];
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        diag[k as usize] += w[e];
        diag[l as usize] += w[e];
    }
    let r = diag
        .iter()
        .zip(mass)
        .map(|(d, m)| d / m)
        .fold(0.0, f64::max);
    if r > 0.0 && r.is_finite() {
        r
    } else {
        1.0
    }
}

/// Connected components (union–find over edges): a label per vertex and their number. The
/// connection Laplacian is block-diagonal over components, so normalizing each component
/// separately runs independent inverse iterations: every component gets its own smallest
/// eigenvector instead of decaying towards the component with the smallest eigenvalue.
fn components(topo: &Topology) -> (Vec<u32>, usize) {
    let n = topo.n_vertices;
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(p: &mut [u32], mut v: u32) -> u32 {
        while p[v as usize] != v {
            p[v as usize] = p[p[v as usize] as usize];
            v = p[v as usize];
        }
        v
    }
    for &[a, b] in &topo.edges {
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    let mut label = vec![u32::MAX; n];
    let mut count = 0u32;
    let comp = (0..n as u32)
        .map(|v| {
            let r = find(&mut parent, v) as usize;
            if label[r] == u32::MAX {
                label[r] = count;
                count += 1;
            }
            label[r]
        })
        .collect();
    (comp, count as usize)
}

/// Scales each component of `u` to unit M-norm.
fn normalize_m(u: &mut [f64], mass: &[f64], comp: &[u32], n_comp: usize) {
    let mut n2 = vec![0.0; n_comp];
    for (i, v) in u.iter().enumerate() {
        n2[comp[i / 2] as usize] += mass[i / 2] * v * v;
    }
    let s: Vec<f64> = n2.iter().map(|x| 1.0 / x.sqrt()).collect();
    for (i, v) in u.iter_mut().enumerate() {
        let f = s[comp[i / 2] as usize];
        if f.is_finite() {
            *v *= f;
        }
    }
}

/// Per component, `u_cᵀ L u_c` (u is M-normalized per component).
fn rayleigh_quotients(u: &[f64], lu: &[f64], comp: &[u32], n_comp: usize) -> Vec<f64> {
    let mut q = vec![0.0; n_comp];
    for (i, (a, b)) in u.iter().zip(lu).enumerate() {
        q[comp[i / 2] as usize] += a * b;
    }
    q
}

/// `‖L u − λ M u‖_{M⁻¹}` with each component's own `λ`.
fn residual_m(lu: &[f64], u: &[f64], lambda: &[f64], mass: &[f64], comp: &[u32]) -> f64 {
    lu.iter()
        .zip(u)
        .enumerate()
        .map(|(i, (l, v))| {
            let r = l - lambda[comp[i / 2] as usize] * mass[i / 2] * v;
            r * r / mass[i / 2]
        })
        .sum::<f64>()
        .sqrt()
}

fn normalize_per_vertex(u: &[f64]) -> Vec<Complex> {
    let z: Vec<Complex> = u
        .chunks_exact(2)
        .map(|c| Complex::new(c[0], c[1]))
        .collect();
    let max = z.iter().map(|c| c.abs()).fold(0.0, f64::max);
    z.iter()
        .map(|&c| {
            let r = c.abs();
            if r > 1e-12 * max && r > 0.0 {
                c.scale(1.0 / r)
            } else {
                Complex::ZERO
            }
        })
        .collect()
}

/// Masses floored at `1e-12` of the mean, so zero-area vertices keep the matrix definite.
fn floored(m: &[f64]) -> Vec<f64> {
    let mean = m.iter().sum::<f64>() / m.len().max(1) as f64;
    let floor = if mean > 0.0 { 1e-12 * mean } else { 1.0 };
    m.iter().map(|&a| a.max(floor)).collect()
}

/// Cotangent weights `(cot α + cot β)/2`, clamped below at `1e-3` of their mean absolute value.
pub(crate) fn cotan_weights(topo: &Topology, x: &[[f64; 3]]) -> Vec<f64> {
    let mut w = vec![0.0; topo.n_edges()];
    for (f, t) in topo.faces.iter().enumerate() {
        for s in 0..3 {
            let o = x[t[(s + 2) % 3] as usize];
            let a = sub(x[t[s] as usize], o);
            let b = sub(x[t[(s + 1) % 3] as usize], o);
            let c = norm(cross(a, b));
            let cot = if c > 0.0 { dot(a, b) / c } else { 0.0 };
            w[topo.face_edges[f][s] as usize] += 0.5 * cot;
        }
    }
    let mean = w.iter().map(|v| v.abs()).sum::<f64>() / w.len().max(1) as f64;
    let floor = if mean > 0.0 && mean.is_finite() {
        1e-3 * mean
    } else {
        1.0
    };
    w.iter()
        .map(|&v| if v.is_finite() { v.max(floor) } else { floor })
        .collect()
}
