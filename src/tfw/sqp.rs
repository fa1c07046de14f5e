//! The wrinkle SQP (A.6.3, S:2290–2307; spec "Algorithm" steps 5–7): minimize `E^wf(a, ω)`
//! subject to `a ≥ 0` and `curl ω = 0` on every face outside W, with `a ≡ 0` on the vertices of
//! W faces and on clamped vertices, and `ω` eliminated (0) on edges with no face outside W.
//!
//! Each iteration solves the convex QP `min ½δᵀHδ + gᵀδ` (the text omits `gᵀδ`) subject to
//! `Cδ = −Cx_k` and `a_k + δ_a ≥ 0` with clarabel (`ZeroCone` + `NonnegativeCone`), then an
//! Armijo backtracking line search on `E^wf` (c = 0.2, ρ = ½, t₀ = 1) keeps every accepted
//! point feasible and lowers `E` monotonically. Duals are blended `y ← y + t(y_QP − y)`;
//! the stationarity residual is `r = ‖∇E + Cᵀy − z‖∞` over the free unknowns (A.5.2, S:2184).
//!
//! **Hessian convexification** (S:2302–2307): each face's exact 5×5 Hessian block (all terms
//! together, [`HessianMode::ProjectedPerFace`]) is eigen-clamped to ≥ 0 before assembly, plus
//! `δ·mean diag(H)·I` with `δ₀ = 1e-6`, halved after each accepted step (floor 1e-16) and
//! doubled when the QP fails. Departure: the spec's switch to the true Hessian once ΔE < 1e-8
//! is not made (the true Hessian is indefinite off the feasible cone and clarabel needs a PSD
//! `P`); convergence is then linear near the optimum, as the spec expects anyway (S:2192).
//!
//! **Feasibility to rounding:** the interior-point QP meets `Cδ = −Cx_k` and the bounds only to
//! its tolerance, so every candidate point of the line search is made exactly feasible: `a`
//! clamped at 0 and `ω` projected onto `ker C` by the minimum-norm correction
//! `ω ← ω − Cᵀ(CCᵀ)⁻¹Cω` (one sparse Cholesky of `CCᵀ`, factored once). The curl residual after
//! every step is therefore at rounding level (tested ≤ 1e-10).
//!
//! **Scaling:** the QP is solved in variables `y = D⁻¹δ` with `D = (E₀/diag H)^{1/2}` of the
//! first iteration (fixed afterwards) and its objective divided by `E₀`, so amplitudes (≈1e-4 m)
//! and one-form values (≈1 rad) are comparable and the QP data do not depend on Young's
//! modulus. **Termination** (A.6.3): relative stationarity `r ≤ stationarity_tolerance · r₀`,
//! relative energy change `|ΔE| ≤ energy_tolerance · |E|`, scaled step `‖D⁻¹Δx‖∞ ≤
//! step_tolerance`, or the iteration limit. Departure: the text's thresholds are absolute SI
//! values (1e-6, 1e-10, 1e-10), which depend on the units and on Young's modulus (the spec's
//! stiff-case note); relative ones make E × 10⁴ give the same iterates.

use crate::report::{Progress, ProgressFn};
use crate::solve::{assemble, CholeskyAnalysis, Entry, Parallelism};
use crate::tfw::energy::{HessianMode, WfEval, WfTerms, WrinkleEnergy};
use crate::{Error, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use std::time::Instant;

/// Options of [`run_sqp`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SqpOptions {
    /// Iteration limit (A.6.3: 1000).
    pub max_iterations: usize,
    /// Stop when `r ≤ stationarity_tolerance · r₀` (default 1e-6).
    pub stationarity_tolerance: f64,
    /// Stop when an accepted step changes `E` by at most this times `|E|` (default 1e-10).
    pub energy_tolerance: f64,
    /// Stop when the accepted scaled step `‖D⁻¹Δx‖∞` is at most this (default 1e-10).
    pub step_tolerance: f64,
    /// Armijo constant (default 0.2).
    pub armijo: f64,
    /// Initial relative Hessian shift δ₀ (default 1e-6).
    pub initial_shift: f64,
    /// Wall-time budget in seconds (default: unlimited); stops with [`SqpStatus::TimeLimit`].
    pub time_limit_seconds: f64,
    /// How each step is computed (default [`QpMethod::ProjectedNewton`] since 2026-11-27: it
    /// passes the same checks as clarabel, Y × 10⁴ included, and reaches the stable answer
    /// 2.5–9× sooner; docs/design-notes.md, "Wrinkle SQP").
    pub qp: QpMethod,
    /// Keep a copy of `x` in [`SqpResult::snapshots`] at the start and every this many
    /// iterations (0 = none; the last iterate is always [`SqpResult::x`]). For wave counts
    /// against time (`pleat bench tfw`); costs one vector per snapshot, no evaluation.
    pub snapshot_every: usize,
    /// Projected Newton only: the exact-Hessian CG refinement of the step near the optimum
    /// (default [`CgRefinement::DEFAULT`] since 2026-11-27; [`CgRefinement::OFF`] is the
    /// projected step alone; docs/design-notes.md, "Wrinkle SQP").
    pub cg_refinement: CgRefinement,
    /// Projected Newton only: after a full step near the optimum (the gate of
    /// [`CgRefinement`]), minimize `E` along the amplitude ↔ frequency valley
    /// `(a, ω) → (a/μ, μω)` over the scalar `μ` ([`crate::tfw::pnewton`], "Valley search";
    /// default true since 2026-11-29: the thickness × 10⁻² cylinders converge in 13 / 14
    /// iterations instead of not in 1000). Every iterate stays feasible and `E` non-increasing.
    pub valley_search: bool,
}

/// The exact-Hessian refinement of the projected Newton step (docs/design-notes.md, "Wrinkle SQP":
/// the projected step alone converged only linearly): Steihaug–Toint CG on the exact reduced
/// Hessian `Bᵀ H B` (held amplitudes fixed), preconditioned by the factorization of `Bᵀ(H_proj +
/// σW)B`, in the region `‖s‖_M ≤ radius · ‖s₀‖_M` (s₀ the projected step), stopped at
/// `‖Hs + g‖ ≤ tolerance ‖g‖`. The analogue of the base solve's CG (`tfw::base`), whose pressure
/// projection made Newton linear the same way the per-face PSD projection of `E^wf` (S:2302–2307)
/// does here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CgRefinement {
    /// CG iterations per step (0 = the projected step alone).
    pub iterations: usize,
    /// Trust-region radius relative to the projected step's `M`-norm.
    pub radius: f64,
    /// Relative model-gradient tolerance.
    pub tolerance: f64,
    /// Refine only after a full step (`t = 1`) of the line search and while the relative
    /// shift σ is at most [`Self::max_shift`]: near the optimum, where the spec switches to
    /// the true Hessian (A.6.3). Far from it the exact-Hessian steps took other paths (the
    /// sheared rectangle: a higher stationary energy, docs/design-notes.md).
    pub after_full_step: bool,
    /// With `after_full_step`: the largest relative shift σ at which to refine.
    pub max_shift: f64,
}

impl CgRefinement {
    /// The projected step alone.
    pub const OFF: CgRefinement = CgRefinement {
        iterations: 0,
        radius: 1e3,
        tolerance: 1e-3,
        after_full_step: false,
        max_shift: f64::INFINITY,
    };

    /// The default since 2026-11-27: 50 CG iterations, region 10 ‖s₀‖_M,
    /// tolerance 1e-3, after full steps with σ ≤ 1e-8 only (docs/design-notes.md, "Wrinkle SQP":
    /// the cylinders' SQP from 526 / 487 to 77 / 76 iterations, the torus's from 396 to 136,
    /// the same or a lower final energy on every scene).
    pub const DEFAULT: CgRefinement = CgRefinement {
        iterations: 50,
        radius: 10.0,
        tolerance: 1e-3,
        after_full_step: true,
        max_shift: 1e-8,
    };
}

/// How [`run_sqp`] computes a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum QpMethod {
    /// The QP with the curl rows as equality constraints, by clarabel (interior point).
    Clarabel,
    /// The curl constraint eliminated (ω = exact part + cohomology part on the complex of
    /// faces outside W, tree–cotree basis), leaving only `a ≥ 0`: projected Newton on faer's
    /// sparse Cholesky ([`crate::tfw::pnewton`]). The default since 2026-11-27.
    #[default]
    ProjectedNewton,
}

impl Default for SqpOptions {
    /// 1000 iterations, r/r₀ 1e-6, ΔE/E 1e-10, step 1e-10, Armijo 0.2, δ₀ 1e-6, no time limit,
    /// projected Newton with the exact-Hessian refinement and the valley search near the
    /// optimum, no snapshots.
    fn default() -> Self {
        SqpOptions {
            max_iterations: 1000,
            stationarity_tolerance: 1e-6,
            energy_tolerance: 1e-10,
            step_tolerance: 1e-10,
            armijo: 0.2,
            initial_shift: 1e-6,
            time_limit_seconds: f64::INFINITY,
            qp: QpMethod::ProjectedNewton,
            snapshot_every: 0,
            cg_refinement: CgRefinement::DEFAULT,
            valley_search: true,
        }
    }
}

/// Why [`run_sqp`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SqpStatus {
    /// Relative stationarity reached.
    Stationary,
    /// Relative energy change below tolerance.
    EnergyConverged,
    /// Step below tolerance.
    StepConverged,
    /// Iteration limit reached.
    MaxIterations,
    /// Wall-time budget used up.
    TimeLimit,
    /// The line search found no decrease along the QP step.
    LineSearchFailed,
    /// The QP failed even with a large Hessian shift.
    QpFailed,
    /// No free amplitude (every face wrinkle-free or clamped): `a ≡ 0` is the answer.
    NoFreeUnknowns,
}

impl SqpStatus {
    /// A one-line explanation.
    pub fn describe(&self) -> &'static str {
        match self {
            SqpStatus::Stationary => "converged: relative stationarity below tolerance",
            SqpStatus::EnergyConverged => "converged: relative energy change below tolerance",
            SqpStatus::StepConverged => "converged: step below tolerance",
            SqpStatus::MaxIterations => "stopped: iteration limit reached",
            SqpStatus::TimeLimit => "stopped: time limit reached",
            SqpStatus::LineSearchFailed => "stopped: line search found no decrease",
            SqpStatus::QpFailed => "stopped: the QP failed even with a large Hessian shift",
            SqpStatus::NoFreeUnknowns => "no free amplitude: nothing to solve",
        }
    }

    /// Whether the status is one of the convergence tests of A.6.3.
    pub fn converged(&self) -> bool {
        matches!(
            self,
            SqpStatus::Stationary | SqpStatus::EnergyConverged | SqpStatus::StepConverged
        )
    }
}

/// One SQP iteration (for energy/residual-against-time plots, Fig. 2.22).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SqpIteration {
    /// `E^wf` after the step (J).
    pub energy: f64,
    /// Stationarity residual `r` after the step (absolute).
    pub stationarity: f64,
    /// `‖Δx‖∞` of the accepted step (unscaled).
    pub step_norm: f64,
    /// Accepted line-search step length `t`.
    pub step_length: f64,
    /// Relative Hessian shift δ used.
    pub shift: f64,
    /// Clarabel interior-point iterations of the QP (projected Newton: Cholesky
    /// factorizations tried).
    pub qp_iterations: u32,
    /// Projected Newton with the exact-Hessian refinement ([`crate::tfw::pnewton`]): the
    /// Steihaug–Toint CG iterations of the step (0 otherwise).
    pub cg_iterations: u32,
    /// Projected Newton: amplitudes held at 0 in the step (at the bound with a positive
    /// gradient); 0 for clarabel.
    pub held: u32,
    /// Max curl residual over the faces outside W after the step.
    pub curl_residual: f64,
    /// Wall time since the SQP started (s).
    pub seconds: f64,
}

/// Result of [`run_sqp`].
#[derive(Debug, Clone, PartialEq)]
pub struct SqpResult {
    /// `[a | ω]` at the end (vertices then edges).
    pub x: Vec<f64>,
    /// Why it stopped.
    pub status: SqpStatus,
    /// `E^wf` at the start.
    pub initial_energy: f64,
    /// `r₀` (at the start, zero duals).
    pub initial_stationarity: f64,
    /// Every iteration.
    pub history: Vec<SqpIteration>,
    /// Seconds in the step solver (clarabel, or the projected Newton's assembly,
    /// factorization and solve).
    pub qp_seconds: f64,
    /// Total seconds.
    pub seconds: f64,
    /// `(iterations done, x)` at the start and every [`SqpOptions::snapshot_every`]
    /// iterations (empty unless asked for).
    pub snapshots: Vec<(usize, Vec<f64>)>,
    /// The iteration (0-based) whose step first found no decrease with the first iteration's
    /// scales and was retried with the rescue scales (`rescue_weights`), kept from then on;
    /// `None` when every step succeeded as planned.
    pub rescued_at: Option<usize>,
}

/// The constraint structure of the SQP: free unknowns and curl rows.
#[derive(Debug, Clone)]
pub struct SqpProblem {
    energy: WrinkleEnergy,
    /// Free unknowns (global indices, increasing).
    pub(super) free: Vec<usize>,
    /// Per global index, its free index or `usize::MAX`.
    pub(super) slot: Vec<usize>,
    /// Number of free amplitudes (they come first in `free`).
    pub(super) n_free_a: usize,
    /// Curl rows: three `(free index, sign)` per face outside W.
    pub(super) curl: Vec<[(usize, f64); 3]>,
    /// Per free edge (free index − `n_free_a`), its vertices `[tail, head]` (ω integrated
    /// tail → head, pleat's edge orientation).
    pub(super) edge_ends: Vec<[usize; 2]>,
}

impl SqpProblem {
    /// Free unknowns and constraints from the base mesh's faces: `w_faces` (true = W),
    /// `clamped` per vertex. A face takes part when it is outside W and its corners are not
    /// degenerate.
    pub fn new(
        energy: WrinkleEnergy,
        base: &crate::mesh::TriMesh,
        w_faces: &[bool],
        clamped: &[bool],
    ) -> SqpProblem {
        let nv = base.vertex_count();
        let el = base.edges();
        let mut a_free = vec![false; nv];
        let mut a_fixed = clamped.to_vec();
        let mut e_free = vec![false; el.len()];
        let mut rows = Vec::new();
        for (f, t) in base.triangles().iter().enumerate() {
            let active = !w_faces[f] && !el.face_edge_sign[f].contains(&0);
            for &v in t {
                if active {
                    a_free[v as usize] = true;
                } else {
                    a_fixed[v as usize] = true;
                }
            }
            if active {
                for &e in &el.face_edges[f] {
                    e_free[e as usize] = true;
                }
                rows.push(f);
            }
        }
        let mut free = Vec::new();
        for v in 0..nv {
            if a_free[v] && !a_fixed[v] {
                free.push(v);
            }
        }
        let n_free_a = free.len();
        for (e, &fr) in e_free.iter().enumerate() {
            if fr {
                free.push(nv + e);
            }
        }
        let mut slot = vec![usize::MAX; nv + el.len()];
        for (k, &g) in free.iter().enumerate() {
            slot[g] = k;
        }
        let curl = rows
            .iter()
            .map(|&f| {
                let (fe, fs) = (el.face_edges[f], el.face_edge_sign[f]);
                std::array::from_fn(|i| (slot[nv + fe[i] as usize], f64::from(fs[i])))
            })
            .collect();
        let edge_ends = free[n_free_a..]
            .iter()
            .map(|&g| el.edges[g - nv].0.map(|v| v as usize))
            .collect();
        SqpProblem {
            energy,
            free,
            slot,
            n_free_a,
            curl,
            edge_ends,
        }
    }

    /// The energy.
    pub fn energy(&self) -> &WrinkleEnergy {
        &self.energy
    }

    /// Number of free amplitudes.
    pub fn free_amplitudes(&self) -> usize {
        self.n_free_a
    }

    /// Number of curl constraints (faces outside W).
    pub fn curl_rows(&self) -> usize {
        self.curl.len()
    }

    /// `max |curl ω|` over the faces outside W at `x = [a | ω]`.
    pub fn curl_residual(&self, x: &[f64]) -> f64 {
        self.curl
            .iter()
            .map(|row| {
                row.iter()
                    .map(|&(k, s)| s * x[self.free[k]])
                    .sum::<f64>()
                    .abs()
            })
            .fold(0.0, f64::max)
    }
}

/// Exact feasibility: clamps amplitudes at 0, zeroes fixed unknowns, projects ω onto ker C.
pub(crate) struct Projector {
    chol: Option<crate::solve::Cholesky>,
}

impl Projector {
    fn new(p: &SqpProblem) -> Result<Projector> {
        if p.curl.is_empty() {
            return Ok(Projector { chol: None });
        }
        // CCᵀ: rows share an edge ⇒ off-diagonal ±1.
        let nr = p.curl.len();
        let mut by_var: Vec<Vec<(usize, f64)>> = vec![Vec::new(); p.free.len()];
        for (r, row) in p.curl.iter().enumerate() {
            for &(k, s) in row {
                by_var[k].push((r, s));
            }
        }
        let mut entries: Vec<Entry> = Vec::new();
        for list in &by_var {
            for &(r1, s1) in list {
                for &(r2, s2) in list {
                    if r1 >= r2 {
                        entries.push(Entry::new(r1, r2, s1 * s2));
                    }
                }
            }
        }
        // a tiny shift: CCᵀ is singular when the faces outside W close a surface; Cω has no
        // component in its kernel, so the shift does not bias the correction.
        entries.extend((0..nr).map(|r| Entry::new(r, r, 1e-12)));
        let a = assemble(nr, &entries, "tfw curl projection")?;
        let chol = CholeskyAnalysis::new(&a)?
            .factor(&a, Parallelism::Global)
            .map_err(|e| Error::Numerical(format!("tfw curl projection: {e:?}")))?;
        Ok(Projector { chol: Some(chol) })
    }

    fn apply(&self, p: &SqpProblem, x: &mut [f64]) {
        for (g, xv) in x.iter_mut().enumerate() {
            if p.slot[g] == usize::MAX {
                *xv = 0.0;
            }
        }
        for &g in &p.free[..p.n_free_a] {
            x[g] = x[g].max(0.0);
        }
        let Some(chol) = &self.chol else { return };
        for _pass in 0..3 {
            let c: Vec<f64> = p
                .curl
                .iter()
                .map(|row| row.iter().map(|&(k, s)| s * x[p.free[k]]).sum())
                .collect();
            let big = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            if c.iter().all(|v| v.abs() <= 1e-15 * big) {
                break;
            }
            let lam = chol.solve(&c);
            for (row, l) in p.curl.iter().zip(&lam) {
                for &(k, s) in row {
                    x[p.free[k]] -= s * l;
                }
            }
        }
    }
}

/// The shift the rescue step starts from (relative to its weights): a damped step.
pub(super) const RESCUE_SHIFT: f64 = 1.0;

/// The step weights after a failed line search: each weight raised to the median of its
/// kind's (amplitudes `..na`, then ω). The first iteration's diagonal of `H` can be ~1e-8 of
/// the mean on unknowns the PSD projection left almost without curvature (the teabag at
/// 10 Pa: 55% of them below 1e-6 of the mean), where the shift `σ W` then allows steps of
/// 1e10 m; the median bounds them by the typical unknown's curvature. Only used once the
/// solve has failed a line search, so solves that never do are unchanged.
pub(super) fn rescue_weights(weights: &[f64], na: usize) -> Vec<f64> {
    let median = |w: &[f64]| -> f64 {
        let mut v: Vec<f64> = w
            .iter()
            .copied()
            .filter(|x| x.is_finite() && *x > 0.0)
            .collect();
        if v.is_empty() {
            return 0.0;
        }
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let na = na.min(weights.len());
    let (ma, mw) = (median(&weights[..na]), median(&weights[na..]));
    weights
        .iter()
        .enumerate()
        .map(|(i, &w)| w.max(if i < na { ma } else { mw }))
        .collect()
}

/// `shape` with the scales of [`rescue_weights`] (`D = (E₀/w)^{1/2}`): the clarabel step's
/// variables after a failed line search; the stop tests keep the first iteration's scales.
fn rescued_shape(shape: &QpShape, na: usize) -> QpShape {
    let weights: Vec<f64> = shape
        .scale
        .iter()
        .map(|d| shape.energy_scale / (d * d))
        .collect();
    QpShape {
        scale: rescue_weights(&weights, na)
            .iter()
            .map(|w| (shape.energy_scale / w).sqrt())
            .collect(),
        energy_scale: shape.energy_scale,
    }
}

/// Armijo backtracking on `E` from `x` along `delta` (free unknowns), every candidate made
/// exactly feasible by `projector`: the first `t = 1, ½, … ≥ 1e-10` with `E ≤ E₀ + c t slope`
/// and `E ≤ E₀`; returns the candidate, its energy and `t`.
fn line_search(
    problem: &SqpProblem,
    projector: &Projector,
    x: &[f64],
    delta: &[f64],
    g_free: &[f64],
    eval: &WfEval,
    c: f64,
) -> Option<(Vec<f64>, f64, f64)> {
    let e = problem.energy();
    let slope: f64 = delta.iter().zip(g_free).map(|(d, g)| d * g).sum();
    let mut t = 1.0;
    loop {
        let mut cand = x.to_vec();
        for (k, &gi) in problem.free.iter().enumerate() {
            cand[gi] += t * delta[k];
        }
        projector.apply(problem, &mut cand);
        let ec = e.energy(&cand, WfTerms::ALL);
        if ec <= eval.energy + c * t * slope.min(0.0) && ec <= eval.energy {
            return Some((cand, ec, t));
        }
        t *= 0.5;
        if t < 1e-10 {
            return None;
        }
    }
}

/// The QP data that does not change between iterations.
pub(super) struct QpShape {
    /// `D` per free unknown.
    pub(super) scale: Vec<f64>,
    /// The QP objective is divided by this (`E₀`), so the QP data do not depend on the units
    /// of energy (Young's modulus).
    pub(super) energy_scale: f64,
}

/// The largest change of a free unknown from `x` to `xn`, plain and divided by its scale in
/// `shape` (the step tests of both step solvers).
pub(super) fn step_sizes(
    problem: &SqpProblem,
    shape: &QpShape,
    x: &[f64],
    xn: &[f64],
) -> (f64, f64) {
    problem
        .free
        .iter()
        .enumerate()
        .fold((0.0f64, 0.0f64), |(m, s), (k, &gi)| {
            let d = (xn[gi] - x[gi]).abs();
            (m.max(d), s.max(d / shape.scale[k]))
        })
}

/// The QP scaling of the first iteration (module docs: `D = (E₀/diag H)^{1/2}`, objective
/// divided by `E₀`).
pub(super) fn qp_shape(problem: &SqpProblem, eval: &WfEval, initial_energy: f64) -> QpShape {
    let mut diag = vec![0.0; problem.free.len()];
    for &(r, c, v) in &eval.hessian {
        if r == c && problem.slot[r] != usize::MAX {
            diag[problem.slot[r]] += v;
        }
    }
    let pos: Vec<f64> = diag.iter().copied().filter(|&d| d > 0.0).collect();
    let mean = if pos.is_empty() {
        1.0
    } else {
        pos.iter().sum::<f64>() / pos.len() as f64
    };
    let energy_scale = if initial_energy > 0.0 && initial_energy.is_finite() {
        initial_energy
    } else {
        1.0
    };
    QpShape {
        scale: diag
            .iter()
            .map(|&d| (energy_scale / d.max(1e-8 * mean)).sqrt())
            .collect(),
        energy_scale,
    }
}

/// Upper-triangular CSC of a symmetric matrix given as lower triplets over `n` unknowns.
fn upper_csc(n: usize, lower: &[(usize, usize, f64)]) -> CscMatrix<f64> {
    // (col, row) of the upper triangle = (r, c) of the lower triplet (r ≥ c)
    let mut t: Vec<(usize, usize, f64)> = lower.iter().map(|&(r, c, v)| (r, c, v)).collect();
    t.sort_unstable_by_key(|&(col, row, _)| (col, row));
    let mut colptr = vec![0usize; n + 1];
    let mut rowval = Vec::with_capacity(t.len());
    let mut nzval: Vec<f64> = Vec::with_capacity(t.len());
    let mut last: Option<(usize, usize)> = None;
    for &(col, row, v) in &t {
        if last == Some((col, row)) {
            *nzval.last_mut().expect("merged entry exists") += v;
            continue;
        }
        last = Some((col, row));
        rowval.push(row);
        nzval.push(v);
        colptr[col + 1] += 1;
    }
    for c in 0..n {
        colptr[c + 1] += colptr[c];
    }
    CscMatrix::new(n, n, colptr, rowval, nzval)
}

/// Where both step solvers start: `x0` projected onto the curl constraint, its evaluation and
/// the clock; or the finished result when no amplitude is free.
pub(crate) enum FeasibleStart {
    /// Run the SQP from here.
    Run {
        /// The feasible start.
        x: Vec<f64>,
        /// Its evaluation (projected per-face Hessian).
        eval: WfEval,
        /// When the run started.
        start: Instant,
        /// The projector onto `C x = 0` (its `CCᵀ` factorization), for the line search.
        projector: Projector,
    },
    /// No free amplitude: `a ≡ 0` ([`SqpStatus::NoFreeUnknowns`]).
    Done(SqpResult),
}

/// The common start of [`run_sqp`] and the projected-Newton SQP (`tfw::pnewton`): projects
/// `x0` onto `C x = 0` and evaluates it. Errors on a failed factorization of `CCᵀ`.
pub(crate) fn feasible_start(problem: &SqpProblem, x0: &[f64]) -> Result<FeasibleStart> {
    let start = Instant::now();
    let projector = Projector::new(problem)?;
    let mut x = x0.to_vec();
    projector.apply(problem, &mut x);
    let eval = problem
        .energy
        .evaluate(&x, WfTerms::ALL, HessianMode::ProjectedPerFace);
    if problem.n_free_a == 0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return Ok(FeasibleStart::Done(SqpResult {
            x,
            status: SqpStatus::NoFreeUnknowns,
            initial_energy: eval.energy,
            initial_stationarity: 0.0,
            history: Vec::new(),
            qp_seconds: 0.0,
            seconds: start.elapsed().as_secs_f64(),
            snapshots: Vec::new(),
            rescued_at: None,
        }));
    }
    Ok(FeasibleStart::Run {
        x,
        eval,
        start,
        projector,
    })
}

/// Runs the SQP with clarabel QP steps ([`QpMethod::Clarabel`]) from `x0 = [a | ω]` (made
/// feasible first), whatever `options.qp` says (`tfw::solve` dispatches on it; the
/// projected-Newton SQP is `tfw::pnewton::run_sqp_projected_newton`). `progress` may cancel
/// ([`Error::Cancelled`]). Errors on a failed factorization of `CCᵀ`.
pub fn run_sqp(
    problem: &SqpProblem,
    x0: &[f64],
    options: &SqpOptions,
    progress: &mut ProgressFn<'_>,
) -> Result<SqpResult> {
    let (mut x, mut eval, start, projector) = match feasible_start(problem, x0)? {
        FeasibleStart::Run {
            x,
            eval,
            start,
            projector,
        } => (x, eval, start, projector),
        FeasibleStart::Done(r) => return Ok(r),
    };
    let e = &problem.energy;
    let initial_energy = eval.energy;
    let done = |status, x, history, r0, qp_seconds, snapshots, rescued_at| SqpResult {
        x,
        status,
        initial_energy,
        initial_stationarity: r0,
        history,
        qp_seconds,
        seconds: start.elapsed().as_secs_f64(),
        snapshots,
        rescued_at,
    };
    let mut snapshots = Vec::new();
    if options.snapshot_every > 0 {
        snapshots.push((0, x.clone()));
    }
    let ncurl = problem.curl.len();
    let na = problem.n_free_a;
    // duals: curl rows then bound rows
    let mut duals = vec![0.0; ncurl + na];
    let stationarity = |g: &[f64], duals: &[f64]| -> f64 {
        let mut r: Vec<f64> = problem.free.iter().map(|&gi| g[gi]).collect();
        for (row, y) in problem.curl.iter().zip(duals) {
            for &(k, s) in row {
                r[k] += s * y;
            }
        }
        for (k, z) in duals[ncurl..].iter().enumerate() {
            r[k] -= z;
        }
        r.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let r0 = stationarity(&eval.gradient, &duals);
    let shape = qp_shape(problem, &eval, initial_energy);
    let mut shift = options.initial_shift;
    let mut rescue_shape: Option<QpShape> = None;
    let mut rescued_at = None;
    let mut history = Vec::new();
    let mut qp_seconds = 0.0;
    let mut status = SqpStatus::MaxIterations;
    for it in 0..options.max_iterations {
        if !progress(Progress {
            stage: "tfw wrinkle SQP",
            fraction: it as f64 / options.max_iterations as f64,
        }) {
            return Err(Error::Cancelled);
        }
        if start.elapsed().as_secs_f64() > options.time_limit_seconds {
            status = SqpStatus::TimeLimit;
            break;
        }
        let g_free: Vec<f64> = problem.free.iter().map(|&gi| eval.gradient[gi]).collect();
        let mut qp = None;
        let mut accepted = None;
        // one rescue (as the projected Newton's, `rescue_weights`): the step from the first
        // iteration's scales found no decrease, so retry it once with the rescue scales, kept
        for attempt in 0..2 {
            let t0 = Instant::now();
            let step_shape = rescue_shape.as_ref().unwrap_or(&shape);
            qp = solve_qp(problem, step_shape, &eval.hessian, &g_free, &x, &mut shift);
            qp_seconds += t0.elapsed().as_secs_f64();
            let Some((delta, _, _)) = &qp else { break };
            accepted = line_search(
                problem,
                &projector,
                &x,
                delta,
                &g_free,
                &eval,
                options.armijo,
            );
            if accepted.is_some() || attempt == 1 || rescue_shape.is_some() {
                break;
            }
            rescue_shape = Some(rescued_shape(&shape, problem.n_free_a));
            rescued_at = Some(history.len());
            shift = shift.max(RESCUE_SHIFT);
        }
        let Some((_, z, qp_iterations)) = qp else {
            status = SqpStatus::QpFailed;
            break;
        };
        let Some((xn, en, t)) = accepted else {
            status = SqpStatus::LineSearchFailed;
            break;
        };
        let (step_norm, scaled_step) = step_sizes(problem, &shape, &x, &xn);
        let de = eval.energy - en;
        x = xn;
        for (y, zq) in duals.iter_mut().zip(&z) {
            *y += t * (zq - *y);
        }
        eval = e.evaluate(&x, WfTerms::ALL, HessianMode::ProjectedPerFace);
        let r = stationarity(&eval.gradient, &duals);
        history.push(SqpIteration {
            energy: en,
            stationarity: r,
            step_norm,
            step_length: t,
            shift,
            qp_iterations,
            cg_iterations: 0,
            held: 0,
            curl_residual: problem.curl_residual(&x),
            seconds: start.elapsed().as_secs_f64(),
        });
        if options.snapshot_every > 0 && history.len() % options.snapshot_every == 0 {
            snapshots.push((history.len(), x.clone()));
        }
        shift = (shift * 0.5).max(1e-16);
        if r <= options.stationarity_tolerance * r0 {
            status = SqpStatus::Stationary;
            break;
        }
        if de.abs() <= options.energy_tolerance * en.abs() {
            status = SqpStatus::EnergyConverged;
            break;
        }
        if scaled_step <= options.step_tolerance {
            status = SqpStatus::StepConverged;
            break;
        }
    }
    Ok(done(
        status, x, history, r0, qp_seconds, snapshots, rescued_at,
    ))
}

/// One QP (module docs) in scaled variables; returns the step over the free unknowns, the
/// duals (curl rows, then bound rows) and clarabel's iteration count, or `None` when it fails
/// even after the shift has grown past 1e4.
fn solve_qp(
    p: &SqpProblem,
    shape: &QpShape,
    hessian: &[(usize, usize, f64)],
    g_free: &[f64],
    x: &[f64],
    shift: &mut f64,
) -> Option<(Vec<f64>, Vec<f64>, u32)> {
    let n = p.free.len();
    let d = &shape.scale;
    let mut lower: Vec<(usize, usize, f64)> = Vec::with_capacity(hessian.len() + n);
    for &(r, c, v) in hessian {
        let (sr, sc) = (p.slot[r], p.slot[c]);
        if sr != usize::MAX && sc != usize::MAX {
            let (a, b) = (sr.max(sc), sr.min(sc));
            lower.push((a, b, v * d[a] * d[b] / shape.energy_scale));
        }
    }
    let q: Vec<f64> = g_free
        .iter()
        .zip(d)
        .map(|(g, s)| g * s / shape.energy_scale)
        .collect();
    // constraints: curl rows (zero cone), then −y_a ≤ a_k / D (nonnegative cone)
    let ncurl = p.curl.len();
    let na = p.n_free_a;
    let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(3 * ncurl + na);
    let mut b = Vec::with_capacity(ncurl + na);
    for (r, row) in p.curl.iter().enumerate() {
        let mut cx = 0.0;
        for &(k, s) in row {
            trip.push((r, k, s * d[k]));
            cx += s * x[p.free[k]];
        }
        b.push(-cx);
    }
    for k in 0..na {
        trip.push((ncurl + k, k, -d[k]));
        b.push(x[p.free[k]]);
    }
    let a_mat = csc_from_triplets(ncurl + na, n, &mut trip);
    let mut cones = Vec::new();
    if ncurl > 0 {
        cones.push(SupportedConeT::ZeroConeT(ncurl));
    }
    cones.push(SupportedConeT::NonnegativeConeT(na));
    // mean diagonal of the scaled Hessian is ≈ 1 by construction of D at iteration 0
    loop {
        let mut l = lower.clone();
        l.extend((0..n).map(|k| (k, k, *shift)));
        let pm = upper_csc(n, &l);
        let settings = DefaultSettings {
            verbose: false,
            max_iter: 200,
            ..DefaultSettings::default()
        };
        let ok = DefaultSolver::new(&pm, &q, &a_mat, &b, &cones, settings)
            .ok()
            .and_then(|mut s| {
                s.solve();
                let sol = &s.solution;
                matches!(
                    sol.status,
                    SolverStatus::Solved | SolverStatus::AlmostSolved
                )
                .then(|| (sol.x.clone(), sol.z.clone(), sol.iterations))
            });
        if let Some((y, z, iters)) = ok {
            let delta: Vec<f64> = y.iter().zip(d).map(|(v, s)| v * s).collect();
            if delta.iter().all(|v| v.is_finite()) {
                let z = z.iter().map(|v| v * shape.energy_scale).collect();
                return Some((delta, z, iters));
            }
        }
        *shift *= 2.0;
        if *shift > 1e4 {
            return None;
        }
    }
}

/// CSC of an `m×n` matrix from triplets (no duplicates expected; sorted in place).
fn csc_from_triplets(m: usize, n: usize, trip: &mut [(usize, usize, f64)]) -> CscMatrix<f64> {
    trip.sort_unstable_by_key(|&(r, c, _)| (c, r));
    let mut colptr = vec![0usize; n + 1];
    for &(_, c, _) in trip.iter() {
        colptr[c + 1] += 1;
    }
    for c in 0..n {
        colptr[c + 1] += colptr[c];
    }
    CscMatrix::new(
        m,
        n,
        colptr,
        trip.iter().map(|t| t.0).collect(),
        trip.iter().map(|t| t.2).collect(),
    )
}
