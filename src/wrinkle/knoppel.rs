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

use super::areas::barycentric_areas;
use super::complex::Complex;
use super::report::CwfStage;
use super::topology::Topology;
use crate::geom::Vec3;
use crate::report::{StageTimes, StatEntries};
use crate::solve::{
    assemble, inverse_iteration_with_stop, run_stoppable, Cholesky, CholeskyAnalysis, Entry,
    InverseIterationInfo, InverseIterationParams, Parallelism, ShiftSchedule, ShiftedProblem,
};
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

impl KnoppelReport {
    /// Total wall seconds over the stages.
    pub fn total_seconds(&self) -> f64 {
        self.stages.total()
    }

    /// The report as named entries (metrics `knoppel eigenvalue`, `knoppel residual`; count
    /// `knoppel iterations`).
    pub fn entries(&self) -> StatEntries {
        let mut e = StatEntries::default();
        self.stages.write_entries(&mut e);
        e.metric_entry("knoppel eigenvalue", self.eigenvalue);
        e.metric_entry("knoppel residual", self.residual);
        e.count_entry("knoppel iterations", self.iterations as u64);
        e
    }
}

/// Knöppel et al. 2015 phase `z̃` (unit per vertex) for the one-form `omega` (EdgeList
/// orientation) on the mesh of `topo` with positions `x`. See the [module docs](self).
///
/// `tick` is a cancellation point, run after the factorization and before each
/// inverse iteration after the first; its error is returned as is. It does not change the
/// result.
pub(crate) fn knoppel_phase_with_tick(
    topo: &Topology,
    x: &[[f64; 3]],
    omega: &[f64],
    opts: &KnoppelOptions,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<(Vec<Complex>, KnoppelReport)> {
    let n = topo.n_vertices;
    let (edge_area, vertex_area) = barycentric_areas(topo, x);
    let w = match opts.weights {
        PhaseWeights::Cotan => cotan_weights(topo, x),
        PhaseWeights::EdgeArea => edge_area,
    };
    let mass = floored(&vertex_area);
    // the real form: both reals of vertex j carry its mass and its component
    let mass2: Vec<f64> = (0..2 * n).map(|i| mass[i / 2]).collect();
    let llt = factor_shifted(topo, &w, omega, &mass2, opts.shift, tick)?;
    tick()?;
    let sigma = llt.info().shift;
    let (comp, n_comp) = components(topo);
    let problem = ShiftedProblem {
        shifted: &llt,
        apply_a: |u: &[f64]| connection_laplacian_apply(topo, &w, omega, u),
        mass: &mass2,
        groups: &(0..2 * n).map(|i| comp[i / 2]).collect::<Vec<u32>>(),
        n_groups: n_comp,
        scale: max_ratio(topo, &w, &mass),
    };
    let start: Vec<f64> = (0..2 * n)
        .map(|i| if i % 2 == 0 { 1.0 } else { 0.5 })
        .collect();
    let params = InverseIterationParams {
        max_iterations: opts.max_iterations,
        tolerance: opts.tolerance,
    };
    let (u, info) = iterate_with_tick(&problem, start, &params, tick)?;
    let report = KnoppelReport {
        eigenvalue: info
            .eigenvalues
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max),
        iterations: info.iterations,
        residual: info.residual,
        shift: sigma,
        stages: StageTimes::default(),
    };
    Ok((normalize_per_vertex(&u), report))
}

/// [`inverse_iteration_with_stop`] with `tick` as its cancellation point: the error of `tick`
/// when it fails, the iteration's (as [`Error::Numerical`](crate::Error)) when a step is not
/// finite.
pub(crate) fn iterate_with_tick<F: Fn(&[f64]) -> Vec<f64>>(
    problem: &ShiftedProblem<'_, F>,
    start: Vec<f64>,
    params: &InverseIterationParams,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<(Vec<f64>, InverseIterationInfo)> {
    let mut stopped = None;
    let mut stop = |_| match tick() {
        Ok(()) => false,
        Err(e) => {
            stopped = Some(e);
            true
        }
    };
    match inverse_iteration_with_stop(problem, start, params, &mut stop) {
        Some(r) => Ok(r?),
        None => Err(stopped.unwrap_or(crate::Error::Cancelled)),
    }
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

/// Assembles `L_ω` (real form) and factors `L_ω + σM` with
/// `σ = shift · max_j(L_jj / M_j)`, multiplying σ by 100 (up to 4 times) while it is not
/// numerically positive definite. `mass2` is `M`'s diagonal in the real form. A large
/// factorization runs with `tick` as a cancellation point every 0.1 s
/// ([`run_stoppable`]); the factor is the same.
fn factor_shifted(
    topo: &Topology,
    w: &[f64],
    omega: &[f64],
    mass2: &[f64],
    shift: f64,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<Cholesky> {
    let n = topo.n_vertices;
    let mass: Vec<f64> = mass2.iter().step_by(2).copied().collect();
    let mut t = off_diagonal_triplets(topo, w, omega);
    let mut diag = vec![0.0; n];
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        diag[k as usize] += w[e];
        diag[l as usize] += w[e];
    }
    for (j, &d) in diag.iter().enumerate() {
        t.push(Entry::new(2 * j, 2 * j, d));
        t.push(Entry::new(2 * j + 1, 2 * j + 1, d));
    }
    let a = assemble(2 * n, &t, "the connection Laplacian")?;
    let schedule = ShiftSchedule {
        initial: shift.max(1e-15) * max_ratio(topo, w, &mass),
        growth: 100.0,
        max_attempts: 5,
    };
    let a = std::sync::Arc::new(a);
    let an = CholeskyAnalysis::new_stoppable(&a, tick)?;
    if an.is_heavy() {
        tick()?;
    }
    let mass2 = mass2.to_vec();
    run_stoppable(
        an.is_heavy(),
        move || an.factor_with_growing_shift(&a, &mass2, schedule, Parallelism::Global),
        tick,
    )?
    .map_err(|_| {
        Error::Numerical(
            "the shifted connection Laplacian is not positive definite (is the mesh \
                 degenerate?)"
                .into(),
        )
    })
}

/// Off-diagonal 2×2 blocks: `H_lk = −w e^{iω_kl}`, `H_kl = −w e^{−iω_kl}`.
fn off_diagonal_triplets(topo: &Topology, w: &[f64], omega: &[f64]) -> Vec<Entry> {
    let mut t = Vec::with_capacity(8 * topo.n_edges() + 2 * topo.n_vertices);
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        let (s, c) = omega[e].sin_cos();
        let (a, b) = (-w[e] * c, -w[e] * s);
        // block (l, k) of a + ib: [[a, −b], [b, a]]; block (k, l) is its transpose
        for (r, q, v) in [(0, 0, a), (0, 1, -b), (1, 0, b), (1, 1, a)] {
            t.push(Entry::new(2 * l + r, 2 * k + q, v));
            t.push(Entry::new(2 * k + q, 2 * l + r, v));
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
pub(crate) fn components(topo: &Topology) -> (Vec<u32>, usize) {
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
    clamp_cotan_weights(cotan_weights_raw(topo, x))
}

/// Unclamped cotangent weights `c_mn = (cot α + cot β)/2` (the FEM stiffness of the cotan
/// Laplacian, negative across obtuse angles; 0 for a degenerate triangle's corner).
pub(crate) fn cotan_weights_raw(topo: &Topology, x: &[[f64; 3]]) -> Vec<f64> {
    let mut w = vec![0.0; topo.n_edges()];
    for (f, t) in topo.faces.iter().enumerate() {
        for s in 0..3 {
            let o = Vec3::from(x[t[(s + 2) % 3] as usize]);
            let a = Vec3::from(x[t[s] as usize]) - o;
            let b = Vec3::from(x[t[(s + 1) % 3] as usize]) - o;
            let c = a.cross(b).length();
            let cot = if c > 0.0 { a.dot(b) / c } else { 0.0 };
            w[topo.face_edges[f][s] as usize] += 0.5 * cot;
        }
    }
    w
}

fn clamp_cotan_weights(w: Vec<f64>) -> Vec<f64> {
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
