//! Wrinkle animation (§3.4): the geodesic-like interpolant between two CWF keyframes of
//! eqs. 3.11–3.17 / B.31–B.47, computed on `N'` guide frames.
//!
//! # What is computed
//!
//! For keyframes `(ω⁰, a⁰, z̃⁰)` and `(ω¹, a¹, z̃¹)` on one base mesh:
//!
//! 1. **Incompatible keyframes (eq. 3.17).** Each `ω^i` is split as `ω^i_com + δω^i` with
//!    `δω ∈ [−π, π)` ([`Cwf::decompose_omega`]); the solve below uses the compatible parts and
//!    `δω(t)` is added back at the end.
//! 2. **Amplitude (B.35):** `a(t) = (1−t) a⁰ + t a¹` per vertex.
//! 3. **Frequency (B.34, B.36–B.46):** the explicit magnitude/angle path of
//!    `omega_path` (derivation there), applied to `ω_com` and to `δω`,
//!    with the linear fallback where an endpoint amplitude vanishes.
//! 4. **Phase (eq. 3.12, B.29, B.47):** `z̃` on the guide times `t_n = n/N'` minimizes
//!
//!    ```text
//!    F(z̃) = ½ Σ_j A_j g_bd,j Σ_{n<N'} |z̃_{n+1,j} − z̃_{n,j}|² / δt          (E_smooth, B.47)
//!         + c δt Σ_{0<n<N'} [ Σ_e A_e |z̃_{n,k} e^{iω_{n,kl}} − z̃_{n,l}|²     (E_compat, 3.5)
//!                           + Σ_j A_j (|z̃_{n,j}|² − 1)² ]                    (E_unit, 3.6)
//!    ```
//!
//!    with `z̃_0 = z̃⁰`, `z̃_{N'} = z̃¹` fixed, `δt = 1/N'`, `A` the barycentric areas,
//!    `c = c_scale · g_ave` (`c_scale` = 10³ by default, §3.4.1). The keyframe terms of
//!    `E_opt` are constant and dropped. The solver minimizes `F / (A_total · g_ave)`, which has
//!    the same minimizers and makes the gradient tolerance independent of the mesh's size and
//!    of the amplitude unit. When every amplitude is zero (`g_ave = 0`, no wrinkles anywhere)
//!    the weights `g_bd` are replaced by 1 and `g_ave` by 1, so the phase still moves smoothly.
//!
//! # Solver (chosen by measurement)
//!
//! All unknown frames at once, `2 V (N'−1)` reals. `E_smooth + c E_compat` is a constant
//! positive semi-definite quadratic `K`; `E_unit` contributes a 2×2 block per unknown vertex.
//!
//! **Default: [`HessianModel::TrustRegion`].** A trust-region Newton method on the *exact*
//! Hessian `K + D(z̃)`, never factorized as a whole: each subproblem is solved by Steihaug–Toint
//! conjugate gradients preconditioned with a symmetric red–black block Gauss–Seidel sweep over
//! the guide frames, whose per-frame blocks (`2V × 2V`, planar pattern) are factored with faer's
//! sparse Cholesky in parallel (details and the argument in `spacetime`).
//! Negative curvature near singularities is followed to the trust-region boundary instead of
//! being damped away; the radius is updated by the ratio of actual to predicted decrease
//! (Nocedal & Wright Alg. 4.1), and CG stops at the inexact-Newton forcing tolerance
//! `‖g‖·min(½, √‖g‖)`. The preconditioner is refactored every 5 iterations.
//!
//! Why: the spacetime graph (mesh × time) is 3-D-like, so one sparse Cholesky factorization of
//! the whole system has ~75× the matrix's nonzeros (knight, 50 frames: 30.7 M) and takes ~2 s,
//! and the direct damped Newton iteration below needed 24–60+ of them (minutes per pair). The
//! trust-region solver reaches the same minimizer (`tests/wrinkle_interp.rs` compares both to
//! 1e-8 in the objective) in tens of milliseconds per iteration: measured on the knight pairs
//! of `benches/wrinkle_interp.rs` it takes 1.4–3.7 s instead of 48–150 s.
//!
//! **Direct models** (kept for comparison and as references). Each iteration factors
//! `K + D(z̃) + μ I` with faer's sparse Cholesky (the symbolic analysis is done once and reused:
//! the pattern never changes) and takes an Armijo line-search step:
//!
//! - [`HessianModel::Exact`]: `D` is the exact Hessian of `E_unit`,
//!   `4w(|z|²−1) I + 8w zzᵀ`; where the sum is indefinite the Cholesky factorization fails and
//!   `μ` is raised until it succeeds;
//! - [`HessianModel::Projected`]: each 2×2 block's eigenvalues clamped at 0 (`4w(3|z|²−1)`
//!   along `z`, `4w(|z|²−1)` across) — always PSD, "projected Newton";
//! - [`HessianModel::GaussNewton`]: `D = 8w zzᵀ`, the Gauss–Newton matrix of the residual
//!   `|z|² − 1`.
//!
//! `μ` is a Levenberg–Marquardt damping (relative to the mean diagonal): divided by 10 after a
//! full step, multiplied by 10 when the factorization fails or the line search needs a step
//! below 1/16. Measured on a sphere with Knöppel keyframes (642 vertices, 20 guide frames,
//! tolerance 1e-6) the exact Hessian needed 7 iterations (8 factorizations), the projected one
//! 75 and Gauss–Newton 80: near phase singularities the minimizer has `|z|² < 1/3`, where both
//! PSD models throw away the negative curvature of `E_unit` that the compatibility term already
//! compensates, and lose Newton's quadratic convergence. That is also why the trust-region
//! solver uses the exact Hessian and lets CG meet the negative curvature.
//!
//! The initial guess is one projected Newton step from `z̃ = 0` (where `E_unit`'s projected
//! Hessian vanishes, so it is the minimizer of the quadratic part `E_smooth + c E_compat` alone;
//! the trust-region solver computes it with the same preconditioned CG, to 1e-6 relative),
//! normalized per vertex: a temporally smooth, compatible start without singular lines.
//!
//! Stops when `‖∇(F / (A_total g_ave))‖₂ ≤ gradient_tolerance` ([`StopReason::Converged`]), after
//! `max_iterations` ([`StopReason::IterationCap`]), or when no step decreases the objective any
//! more ([`StopReason::Stalled`], e.g. for a huge `c` where round-off dominates).
//! Identical keyframes give the constant path without iterating
//! ([`StopReason::IdenticalKeyframes`]).
//!
//! Deterministic: every sum is taken in a fixed order and the parallel parts (per-frame energy
//! and gradient evaluation, per-frame factorizations, solves and matrix products) write
//! disjoint outputs, so the result does not depend on the thread count.

use std::time::Instant;

use rayon::prelude::*;

use super::animation::{check_time, CwfAnimation};
use super::areas::barycentric_areas;
use super::complex::Complex;
use super::cwf::Cwf;
use super::omega_path::OmegaPath;
use super::report::InterpStage;
use super::spacetime::FrameBlocks;
use crate::report::{Progress, ProgressFn, StageTimes, StatEntries};
use crate::solve::{
    assemble, dot_n, entry_index, steihaug_with_stop, sym_matvec_lower_into, Cholesky,
    CholeskyAnalysis, Entry, Parallelism, SparseMatrix,
};
use crate::{Error, Result};

/// Hessian model of the phase solve (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u32)]
pub enum HessianModel {
    /// Exact Hessian with each vertex's 2×2 `E_unit` block projected to PSD.
    Projected = 0,
    /// Gauss–Newton matrix of `E_unit`.
    GaussNewton = 1,
    /// The exact Hessian; indefiniteness is handled by the damping `μ` alone (a failed
    /// Cholesky factorization raises it).
    Exact = 2,
    /// The default: the exact Hessian, never factorized — a trust-region Newton method whose
    /// subproblems are solved by Steihaug–Toint CG preconditioned by a symmetric block
    /// Gauss–Seidel sweep over the guide frames (see `spacetime`).
    /// Negative curvature is followed to the trust-region boundary, not damped.
    #[default]
    TrustRegion = 3,
}

/// Parameters of [`interpolate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterpOptions {
    /// `N'`: number of guide intervals; guide frames sit at `t = n/N'`, `n = 0..=N'`
    /// (`N' − 1` of them are solved for). `1` is plain linear interpolation. Default 50.
    pub guide_frames: usize,
    /// `k`: linear sub-steps per guide interval; the animation has `N'·k + 1` frames.
    /// Default 4.
    pub substeps: usize,
    /// `c = c_scale · g_ave` (eq. 3.16). Default 1e3 (§3.4.1).
    pub c_scale: f64,
    /// Stop when the normalized gradient norm is at most this. Default 1e-6.
    pub gradient_tolerance: f64,
    /// Iteration cap. Default 200.
    pub max_iterations: usize,
    /// Solver / Hessian model. Default [`HessianModel::TrustRegion`].
    pub hessian: HessianModel,
    /// Locality (spec check C10): hold `z̃(t) = z̃⁰` at every vertex whose *star* is the same in
    /// both keyframes (amplitude and `z̃` at the vertex, `ω` on every incident edge, bit for
    /// bit — what [`edit`](super::edit()) guarantees on its fixed region), so a local edit
    /// animates locally. Default `true`; `false` solves for every vertex (eq. 3.12 as printed).
    /// See [`unchanged_vertices`].
    pub locality: bool,
}

impl Default for InterpOptions {
    fn default() -> Self {
        InterpOptions {
            guide_frames: 50,
            substeps: 4,
            c_scale: 1e3,
            gradient_tolerance: 1e-6,
            max_iterations: 200,
            hessian: HessianModel::TrustRegion,
            locality: true,
        }
    }
}

/// Why the phase solve stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum StopReason {
    /// The gradient norm reached the tolerance.
    Converged = 0,
    /// `max_iterations` were done first.
    IterationCap = 1,
    /// No step along the (damped) Newton direction decreases the objective any more: the
    /// iterate is as good as round-off allows (reported with its gradient norm).
    Stalled = 2,
    /// The keyframes are identical: the constant path, no iteration.
    IdenticalKeyframes = 3,
    /// Nothing to solve: `guide_frames == 1` (linear interpolation).
    NoUnknowns = 4,
}

impl StopReason {
    /// A short lowercase name ("converged", "iteration cap", ...).
    pub fn name(self) -> &'static str {
        match self {
            StopReason::Converged => "converged",
            StopReason::IterationCap => "iteration cap",
            StopReason::Stalled => "stalled",
            StopReason::IdenticalKeyframes => "identical keyframes",
            StopReason::NoUnknowns => "no unknowns",
        }
    }
}

/// One point of the convergence history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationRecord {
    /// Iterations done (0 = the initial guess).
    pub iteration: usize,
    /// Wall seconds since the start of [`interpolate`].
    pub seconds: f64,
    /// Normalized gradient norm (the stopping residual).
    pub gradient_norm: f64,
    /// Normalized objective `F / (A_total g_ave)`.
    pub objective: f64,
}

/// What the phase solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct InterpReport {
    /// Newton iterations done (the initial-guess step not counted).
    pub iterations: usize,
    /// Why it stopped.
    pub stop: StopReason,
    /// Residual and wall time after the initial guess and after every iteration.
    pub history: Vec<IterationRecord>,
    /// Final `E_smooth` (eq. 3.13 discretized, unnormalized).
    pub smooth_energy: f64,
    /// Final `∫ E_compat dt` over the guide frames (unnormalized).
    pub compat_energy: f64,
    /// Final `∫ E_unit dt` over the guide frames (unnormalized).
    pub unit_energy: f64,
    /// `g_ave` (eq. 3.16, area-weighted mean; 0 when every amplitude is zero).
    pub g_ave: f64,
    /// The penalty `c` used (`c_scale · g_ave`, or `c_scale` when `g_ave = 0`).
    pub c: f64,
    /// Sparse Cholesky factorizations done: of the whole spacetime Hessian for the direct
    /// models, of the per-frame blocks (one per frame and iteration) for
    /// [`HessianModel::TrustRegion`].
    pub factorizations: usize,
    /// Conjugate-gradient iterations ([`HessianModel::TrustRegion`]; 0 for the direct models).
    pub cg_iterations: usize,
    /// Unknown reals (`2 V (N' − 1)`, pinned vertices included: they are held, not removed).
    pub unknowns: usize,
    /// Vertices held at their keyframe phase by [`InterpOptions::locality`] (0 when off).
    pub pinned_vertices: usize,
    /// Wall seconds per stage (`setup`, then `assemble` and `solve` when there was a solve).
    pub stages: StageTimes<InterpStage>,
}

impl InterpReport {
    /// Final normalized gradient norm (the last history entry).
    pub fn final_gradient_norm(&self) -> f64 {
        self.history.last().map_or(0.0, |r| r.gradient_norm)
    }
}

impl InterpReport {
    /// Total wall seconds over the stages.
    pub fn total_seconds(&self) -> f64 {
        self.stages.total()
    }

    /// The report as named entries (`g_ave`, `c`, `final gradient norm`, `E_smooth`,
    /// `E_compat`, `E_unit`; counts `iterations`, `factorizations`, `cg iterations`,
    /// `unknowns`).
    pub fn entries(&self) -> StatEntries {
        let mut e = StatEntries::default();
        self.stages.write_entries(&mut e);
        e.metric_entry("g_ave", self.g_ave);
        e.metric_entry("c", self.c);
        e.metric_entry("final gradient norm", self.final_gradient_norm());
        e.metric_entry("E_smooth", self.smooth_energy);
        e.metric_entry("E_compat", self.compat_energy);
        e.metric_entry("E_unit", self.unit_energy);
        e.count_entry("iterations", self.iterations as u64);
        e.count_entry("factorizations", self.factorizations as u64);
        e.count_entry("cg iterations", self.cg_iterations as u64);
        e.count_entry("unknowns", self.unknowns as u64);
        e.count_entry("pinned vertices", self.pinned_vertices as u64);
        e
    }
}

/// Interpolates between keyframes `a` (t = 0) and `b` (t = 1) on the same base mesh. See the
/// [module docs](self). Errors with [`Error::InvalidArgument`] when the keyframes' base meshes
/// differ (connectivity, or a position by more than 1e-9 of the bounding-box diagonal) or an
/// option is out of range, [`Error::Numerical`] if the factorization fails even with heavy
/// damping.
pub fn interpolate(a: &Cwf, b: &Cwf, opts: &InterpOptions) -> Result<(CwfAnimation, InterpReport)> {
    interpolate_with_progress(a, b, opts, &mut |_| true)
}

/// As [`interpolate`], reporting progress after each iteration (stage `"interpolate"`) and,
/// as cancellation points, inside it (trust region: every 4 CG iterations, between batches of
/// 8 frames of a preconditioner refactor, after each trial evaluation); the callback
/// returning `false` stops with [`Error::Cancelled`]. When not cancelled, the result is that of
/// [`interpolate`], bit for bit.
pub fn interpolate_with_progress(
    a: &Cwf,
    b: &Cwf,
    opts: &InterpOptions,
    progress: &mut ProgressFn<'_>,
) -> Result<(CwfAnimation, InterpReport)> {
    let start = Instant::now();
    check_options(opts)?;
    check_same_base(a, b)?;
    let mut stats = StageTimes::default();
    let setup = stats.time(InterpStage::Setup, || Setup::new(a, b, opts));
    // cancellation points around the solve's own per-iteration ones
    checkpoint(progress, "setup", 0.0)?;
    let n = opts.guide_frames;
    let omega_com: Vec<Vec<f64>> = (0..=n)
        .map(|i| setup.com.at(&a.topo, i as f64 / n as f64))
        .collect();
    let (zeta, mut report) = if identical(a, b) {
        let r = trivial_report(&setup, StopReason::IdenticalKeyframes, start);
        (vec![a.zeta().to_vec(); n + 1], r)
    } else if n == 1 {
        let r = trivial_report(&setup, StopReason::NoUnknowns, start);
        (vec![a.zeta().to_vec(), b.zeta().to_vec()], r)
    } else {
        let problem = stats.time(InterpStage::Assemble, || {
            Problem::new(a, b, &setup, &omega_com, opts)
        })?;
        checkpoint(progress, "assemble", 0.0)?;
        stats.time(InterpStage::Solve, || problem.solve(opts, start, progress))?
    };
    checkpoint(progress, "frames", 1.0)?;
    let omega = if identical(a, b) {
        vec![a.omega().to_vec(); n + 1]
    } else {
        full_omega(a, b, &setup, omega_com, n)
    };
    report.stages = stats;
    let anim = CwfAnimation::from_guides(
        a,
        [a.amplitude().to_vec(), b.amplitude().to_vec()],
        omega,
        zeta,
        opts.substeps,
    )?;
    Ok((anim, report))
}

/// One progress call; `Err(Cancelled)` when it answers `false`.
pub(super) fn checkpoint(progress: &mut ProgressFn<'_>, stage: &str, fraction: f64) -> Result<()> {
    if progress(Progress { stage, fraction }) {
        Ok(())
    } else {
        Err(Error::Cancelled)
    }
}

/// `ω(t)` of the explicit path (B.34/B.46) between the keyframes' full one-forms, without the
/// compatible/residual split: the frequency a per-frame baseline (e.g. Knöppel) would use.
/// `t` in [0, 1]; `t = 0, 1` give the keyframes exactly.
pub fn explicit_omega(a: &Cwf, b: &Cwf, t: f64) -> Result<Vec<f64>> {
    check_same_base(a, b)?;
    check_time(t)?;
    let path = OmegaPath::new(
        &a.topo,
        a.base().positions(),
        a.omega(),
        b.omega(),
        a.amplitude(),
        b.amplitude(),
    );
    Ok(path.at(&a.topo, t))
}

/// The plain linear interpolant of §3.4.3 (`a`, `ω` and `z̃` each `(1−t)·a + t·b`), the baseline
/// that shears rotating wrinkles into a singular line.
pub fn linear_interpolation(a: &Cwf, b: &Cwf, t: f64) -> Result<Cwf> {
    check_same_base(a, b)?;
    check_time(t)?;
    let lerp = |x: f64, y: f64| (1.0 - t) * x + t * y;
    let omega = a.omega().iter().zip(b.omega()).map(|(&x, &y)| lerp(x, y));
    let amp = a
        .amplitude()
        .iter()
        .zip(b.amplitude())
        .map(|(&x, &y)| lerp(x, y));
    let zeta = a
        .zeta()
        .iter()
        .zip(b.zeta())
        .map(|(&x, &y)| Complex::new(lerp(x.re, y.re), lerp(x.im, y.im)));
    Ok(a.with_fields(omega.collect(), amp.collect(), zeta.collect()))
}

fn check_options(o: &InterpOptions) -> Result<()> {
    if !(1..=100_000).contains(&o.guide_frames) {
        return crate::invalid_arg!("guide_frames = {}; allowed 1 to 100000", o.guide_frames);
    }
    if !(1..=100_000).contains(&o.substeps) {
        return crate::invalid_arg!("substeps = {}; allowed 1 to 100000", o.substeps);
    }
    if !(o.c_scale.is_finite() && o.c_scale > 0.0) {
        return crate::invalid_arg!("c_scale = {}; must be finite and > 0", o.c_scale);
    }
    if !(o.gradient_tolerance.is_finite() && o.gradient_tolerance >= 0.0) {
        return crate::invalid_arg!(
            "gradient_tolerance = {}; must be finite and ≥ 0",
            o.gradient_tolerance
        );
    }
    Ok(())
}

/// Rejects keyframes on different base meshes with a message naming the first difference.
pub(crate) fn check_same_base(a: &Cwf, b: &Cwf) -> Result<()> {
    let (ma, mb) = (a.base(), b.base());
    if ma.vertex_count() != mb.vertex_count() || ma.triangle_count() != mb.triangle_count() {
        return crate::invalid_arg!(
            "the keyframes are on different base meshes: {} vertices / {} triangles vs {} / {}",
            ma.vertex_count(),
            ma.triangle_count(),
            mb.vertex_count(),
            mb.triangle_count()
        );
    }
    if let Some(t) = (0..ma.triangle_count()).find(|&t| ma.triangles()[t] != mb.triangles()[t]) {
        return crate::invalid_arg!(
            "the keyframes are on different base meshes: triangle {t} is {:?} vs {:?}",
            ma.triangles()[t],
            mb.triangles()[t]
        );
    }
    let tol = 1e-9 * ma.bbox_diagonal().max(f64::MIN_POSITIVE);
    let far = |p: &[f64; 3], q: &[f64; 3]| {
        (0..3).any(|i| (p[i] - q[i]).abs() > tol || (p[i] - q[i]).is_nan())
    };
    if let Some(v) = (0..ma.vertex_count()).find(|&v| far(&ma.positions()[v], &mb.positions()[v])) {
        return crate::invalid_arg!(
            "the keyframes are on different base meshes: vertex {v} is at {:?} vs {:?} (the \
             interpolation needs one base geometry)",
            ma.positions()[v],
            mb.positions()[v]
        );
    }
    Ok(())
}

fn identical(a: &Cwf, b: &Cwf) -> bool {
    let bits = |s: &[f64], t: &[f64]| s.iter().zip(t).all(|(x, y)| x.to_bits() == y.to_bits());
    bits(a.omega(), b.omega())
        && bits(a.amplitude(), b.amplitude())
        && a.zeta()
            .iter()
            .zip(b.zeta())
            .all(|(x, y)| x.re.to_bits() == y.re.to_bits() && x.im.to_bits() == y.im.to_bits())
}

/// Per vertex: `true` when the keyframes agree on its whole star, bit for bit — amplitude and
/// `z̃` at the vertex and `ω` on every incident edge. These are the vertices
/// [`InterpOptions::locality`] holds at `z̃⁰`: an [`edit`](super::edit()) copies its fixed
/// region, so they are the fixed vertices not touching an interface edge. A vertex in no edge
/// is never pinned. Keyframes that share no star (a global edit, unrelated keyframes) pin
/// nothing, and the interpolation is eq. 3.12 unchanged.
///
/// Why pin rather than weight: the reference code multiplies the kinetic weight of a vertex at
/// distance `d` from the edit by `min(exp((d/σ)²), 1e10)` (spec C10), which freezes far vertices
/// only in the limit and makes the time coupling of the spacetime Hessian — and so the block
/// Gauss–Seidel preconditioner — badly conditioned; holding them is that limit taken exactly.
/// The minimizer stays the one of eq. 3.12 restricted to paths that leave unchanged stars alone.
pub fn unchanged_vertices(a: &Cwf, b: &Cwf) -> Vec<bool> {
    let same = |x: f64, y: f64| x.to_bits() == y.to_bits();
    let n = a.base().vertex_count().min(b.base().vertex_count());
    let mut keep: Vec<bool> = (0..n)
        .map(|j| {
            let (za, zb) = (a.zeta()[j], b.zeta()[j]);
            same(a.amplitude()[j], b.amplitude()[j]) && same(za.re, zb.re) && same(za.im, zb.im)
        })
        .collect();
    let mut has_edge = vec![false; n];
    for (e, &[k, l]) in a.edges().iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        has_edge[k] = true;
        has_edge[l] = true;
        if !same(a.omega()[e], b.omega()[e]) {
            keep[k] = false;
            keep[l] = false;
        }
    }
    keep.iter().zip(&has_edge).map(|(&k, &h)| k && h).collect()
}

/// Keyframe-derived data shared by the solve and the output.
struct Setup {
    /// Path of the compatible parts.
    com: OmegaPath,
    /// Path of the residuals δω.
    residual: OmegaPath,
    g_bd: Vec<f64>,
    g_ave: f64,
    edge_area: Vec<f64>,
    vertex_area: Vec<f64>,
}

impl Setup {
    fn new(a: &Cwf, b: &Cwf, _opts: &InterpOptions) -> Setup {
        let (da, db) = (a.decompose_omega(), b.decompose_omega());
        let x = a.base().positions();
        let (amp0, amp1) = (a.amplitude(), b.amplitude());
        let com = OmegaPath::new(&a.topo, x, &da.compatible, &db.compatible, amp0, amp1);
        let residual = OmegaPath::new(&a.topo, x, &da.residual, &db.residual, amp0, amp1);
        let (edge_area, vertex_area) = barycentric_areas(&a.topo, x);
        Setup {
            g_bd: com.g_bd(&a.topo),
            g_ave: com.g_ave(&a.topo, &vertex_area),
            com,
            residual,
            edge_area,
            vertex_area,
        }
    }

    /// `(g per vertex, g_ref)`: `g_bd` and `g_ave`, or all ones when `g_ave` is 0.
    fn weights(&self) -> (Vec<f64>, f64) {
        if self.g_ave > 0.0 && self.g_ave.is_finite() {
            (self.g_bd.clone(), self.g_ave)
        } else {
            (vec![1.0; self.g_bd.len()], 1.0)
        }
    }
}

fn trivial_report(setup: &Setup, stop: StopReason, start: Instant) -> InterpReport {
    let (_, g_ref) = setup.weights();
    InterpReport {
        iterations: 0,
        stop,
        history: vec![IterationRecord {
            iteration: 0,
            seconds: start.elapsed().as_secs_f64(),
            gradient_norm: 0.0,
            objective: 0.0,
        }],
        smooth_energy: 0.0,
        compat_energy: 0.0,
        unit_energy: 0.0,
        g_ave: setup.g_ave,
        c: 0.0f64.max(g_ref),
        factorizations: 0,
        cg_iterations: 0,
        unknowns: 0,
        pinned_vertices: 0,
        stages: StageTimes::default(),
    }
}

/// `ω(t_n) = ω_com(t_n) + δω(t_n)` per guide frame; the keyframes' own one-forms at the ends.
fn full_omega(a: &Cwf, b: &Cwf, setup: &Setup, com: Vec<Vec<f64>>, n: usize) -> Vec<Vec<f64>> {
    com.into_iter()
        .enumerate()
        .map(|(i, w)| {
            if i == 0 {
                a.omega().to_vec()
            } else if i == n {
                b.omega().to_vec()
            } else {
                let d = setup.residual.at(&a.topo, i as f64 / n as f64);
                w.iter().zip(&d).map(|(x, y)| x + y).collect()
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The phase problem

/// The discretized objective of eq. 3.12 over the unknown frames `1..N'`.
struct Problem {
    n_v: usize,
    /// `N'`.
    n_frames: usize,
    edges: Vec<[u32; 2]>,
    /// `e^{iω_n}` per guide frame `n` (interior ones used) and edge.
    rot: Vec<Vec<Complex>>,
    /// Normalized weights: `c_scale δt A_e / A_tot` per edge.
    w_compat: Vec<f64>,
    /// `c_scale δt A_j / A_tot` per vertex.
    w_unit: Vec<f64>,
    /// `½ A_j g_j / (δt A_tot g_ref)` per vertex.
    w_smooth: Vec<f64>,
    /// Keyframe phases (frames 0 and N').
    z_ends: [Vec<Complex>; 2],
    /// Per vertex: held at `z̃⁰` on every frame ([`InterpOptions::locality`]). A pinned vertex
    /// keeps its unknowns, but its gradient is zeroed and its rows and columns of `K` keep only
    /// the diagonal, so every step leaves it where it is.
    pinned: Vec<bool>,
    /// Unnormalization: `A_tot g_ref`, and `c`.
    scale: f64,
    c: f64,
    g_ave: f64,
}

/// Per-part values of the normalized objective.
#[derive(Debug, Clone, Copy, Default)]
struct Parts {
    smooth: f64,
    compat: f64,
    unit: f64,
}

impl Parts {
    fn total(&self) -> f64 {
        self.smooth + self.compat + self.unit
    }
}

impl Problem {
    fn new(
        a: &Cwf,
        b: &Cwf,
        setup: &Setup,
        omega_com: &[Vec<f64>],
        opts: &InterpOptions,
    ) -> Result<Problem> {
        let n_frames = opts.guide_frames;
        let dt = 1.0 / n_frames as f64;
        let area: f64 = setup.vertex_area.iter().sum();
        if !(area > 0.0 && area.is_finite()) {
            return crate::invalid_arg!("the base mesh has no area");
        }
        let (g, g_ref) = setup.weights();
        let cs = opts.c_scale;
        Ok(Problem {
            n_v: a.base().vertex_count(),
            n_frames,
            edges: a.edges().to_vec(),
            rot: omega_com
                .iter()
                .map(|w| w.iter().map(|&x| Complex::cis(x)).collect())
                .collect(),
            w_compat: setup
                .edge_area
                .iter()
                .map(|&ae| cs * dt * ae / area)
                .collect(),
            w_unit: setup
                .vertex_area
                .iter()
                .map(|&aj| cs * dt * aj / area)
                .collect(),
            w_smooth: setup
                .vertex_area
                .iter()
                .zip(&g)
                .map(|(&aj, &gj)| 0.5 * aj * gj / (dt * area * g_ref))
                .collect(),
            z_ends: [a.zeta().to_vec(), b.zeta().to_vec()],
            pinned: if opts.locality {
                unchanged_vertices(a, b)
            } else {
                vec![false; a.base().vertex_count()]
            },
            scale: area * g_ref,
            c: cs * g_ref,
            g_ave: setup.g_ave,
        })
    }

    /// Unknown count in complex entries.
    fn n_unknown(&self) -> usize {
        (self.n_frames - 1) * self.n_v
    }

    /// The phases of guide frame `n` (keyframes at 0 and N').
    fn frame<'a>(&'a self, x: &'a [Complex], n: usize) -> &'a [Complex] {
        if n == 0 {
            &self.z_ends[0]
        } else if n == self.n_frames {
            &self.z_ends[1]
        } else {
            &x[(n - 1) * self.n_v..n * self.n_v]
        }
    }

    /// Normalized objective parts and (optionally) its gradient (as complex `∂x + i∂y`).
    fn evaluate(&self, x: &[Complex], want_grad: bool) -> (Parts, Vec<Complex>) {
        let nv = self.n_v;
        let per_frame: Vec<(Parts, Vec<Complex>)> = (1..self.n_frames)
            .into_par_iter()
            .map(|n| self.frame_terms(x, n, want_grad))
            .collect();
        let mut parts = Parts::default();
        let mut grad = Vec::with_capacity(if want_grad { x.len() } else { 0 });
        for (p, g) in per_frame {
            parts.compat += p.compat;
            parts.unit += p.unit;
            parts.smooth += p.smooth;
            grad.extend(g);
        }
        // the last pair (N'−1, N') is not counted by frame_terms (each frame counts its
        // pair with the previous frame)
        let last = self.n_frames;
        let (zp, zq) = (self.frame(x, last - 1), self.frame(x, last));
        parts.smooth += (0..nv)
            .map(|j| self.w_smooth[j] * (zq[j] - zp[j]).norm_sqr())
            .sum::<f64>();
        (parts, grad)
    }

    /// Terms of unknown frame `n`: its compat and unit energies, the smooth energy of the pair
    /// `(n−1, n)`, and its gradient (all terms touching frame `n`).
    fn frame_terms(&self, x: &[Complex], n: usize, want_grad: bool) -> (Parts, Vec<Complex>) {
        let z = self.frame(x, n);
        let (zp, zn) = (self.frame(x, n - 1), self.frame(x, n + 1));
        let rot = &self.rot[n];
        let mut p = Parts::default();
        let mut g = if want_grad {
            vec![Complex::ZERO; self.n_v]
        } else {
            Vec::new()
        };
        for (e, &[k, l]) in self.edges.iter().enumerate() {
            let (k, l) = (k as usize, l as usize);
            let w = self.w_compat[e];
            let r = rot[e] * z[k] - z[l];
            p.compat += w * r.norm_sqr();
            if want_grad {
                g[k] += (rot[e].conj() * r).scale(2.0 * w);
                g[l] += r.scale(-2.0 * w);
            }
        }
        for j in 0..self.n_v {
            let m = z[j].norm_sqr() - 1.0;
            p.unit += self.w_unit[j] * m * m;
            let ws = self.w_smooth[j];
            p.smooth += ws * (z[j] - zp[j]).norm_sqr();
            if want_grad {
                g[j] += z[j].scale(4.0 * self.w_unit[j] * m);
                g[j] += (z[j] - zp[j] + z[j] - zn[j]).scale(2.0 * ws);
            }
        }
        if want_grad {
            self.mask(&mut g);
        }
        (p, g)
    }

    /// Zeroes the entries of pinned vertices in one frame's vector.
    fn mask(&self, g: &mut [Complex]) {
        for (gj, &p) in g.iter_mut().zip(&self.pinned) {
            if p {
                *gj = Complex::ZERO;
            }
        }
    }

    /// Every frame's pinned vertices set to the keyframe phase `z̃⁰` (the start of a solve).
    fn start_vector(&self) -> Vec<Complex> {
        let mut x = vec![Complex::ZERO; self.n_unknown()];
        for frame in x.chunks_exact_mut(self.n_v) {
            for (j, z) in frame.iter_mut().enumerate() {
                if self.pinned[j] {
                    *z = self.z_ends[0][j];
                }
            }
        }
        x
    }

    /// `E_unit`'s Hessian block of unknown `u` at `z` (zero for a pinned vertex).
    fn unit_block_at(&self, u: usize, z: Complex, model: HessianModel) -> [f64; 3] {
        let j = u % self.n_v;
        if self.pinned[j] {
            [0.0; 3]
        } else {
            unit_block(z, self.w_unit[j], model)
        }
    }

    /// The guide-frame phases and the report of a finished solve; `counts` are the iterations,
    /// factorizations and CG iterations done.
    fn finish(
        &self,
        x: &[Complex],
        stop: StopReason,
        history: Vec<IterationRecord>,
        counts: [usize; 3],
    ) -> (Vec<Vec<Complex>>, InterpReport) {
        let (parts, _) = self.evaluate(x, false);
        let (es, ec, eu) = self.energies(&parts);
        let frames = (0..=self.n_frames)
            .map(|n| self.frame(x, n).to_vec())
            .collect();
        let report = InterpReport {
            iterations: counts[0],
            stop,
            history,
            smooth_energy: es,
            compat_energy: ec,
            unit_energy: eu,
            g_ave: self.g_ave,
            c: self.c,
            factorizations: counts[1],
            cg_iterations: counts[2],
            unknowns: 2 * self.n_unknown(),
            pinned_vertices: self.pinned.iter().filter(|&&p| p).count(),
            stages: StageTimes::default(),
        };
        (frames, report)
    }

    /// Unnormalized energies: `(E_smooth, ∫E_compat dt, ∫E_unit dt)`.
    fn energies(&self, p: &Parts) -> (f64, f64, f64) {
        let s = self.scale;
        (p.smooth * s, p.compat * s / self.c, p.unit * s / self.c)
    }

    /// Runs the damped Newton iteration. Returns the guide-frame phases and the report.
    fn solve(
        &self,
        opts: &InterpOptions,
        start: Instant,
        progress: &mut ProgressFn<'_>,
    ) -> Result<(Vec<Vec<Complex>>, InterpReport)> {
        if opts.hessian == HessianModel::TrustRegion {
            return self.solve_trust_region(opts, start, progress);
        }
        let mut hess = Hessian::new(self)?;
        let mut x = self.start_vector();
        // initial guess: the quadratic part's minimizer (a projected Newton step from 0, pinned
        // vertices held; the step is zero on them)
        let (_, g0) = self.evaluate(&x, true);
        let mut mu = 1e-10;
        let d = hess.newton_direction(self, &x, &g0, &mut mu, HessianModel::Projected)?;
        x.iter_mut().zip(&d).for_each(|(xi, di)| *xi += *di);
        normalize_unknowns(&mut x);
        let mut log = IterationLog::new(start);
        let mut iterations = 0;
        let stop = loop {
            let (parts, grad) = self.evaluate(&x, true);
            if let Some(stop) = log.record(iterations, parts.total(), &grad, opts, progress)? {
                break stop;
            }
            // a cancellation point per damping trial: a stalling last step can try ~24
            let mut tick = || log.tick(progress);
            match self.step(
                &mut hess,
                &mut x,
                &grad,
                parts.total(),
                &mut mu,
                opts,
                &mut tick,
            )? {
                true => iterations += 1,
                false => break StopReason::Stalled,
            }
        };
        let counts = [iterations, hess.factorizations, 0];
        checkpoint(progress, "finish", log.best_fraction)?;
        Ok(self.finish(&x, stop, log.history, counts))
    }

    /// One damped Newton step with Armijo backtracking; `false` when no decrease is possible.
    /// `tick` (a cancellation point) runs before each factorization after the first and before
    /// each shortened trial.
    #[allow(clippy::too_many_arguments)]
    fn step(
        &self,
        hess: &mut Hessian,
        x: &mut Vec<Complex>,
        grad: &[Complex],
        f0: f64,
        mu: &mut f64,
        opts: &InterpOptions,
        tick: &mut dyn FnMut() -> Result<()>,
    ) -> Result<bool> {
        const MU_MAX: f64 = 1e12;
        const MU_MIN: f64 = 1e-12;
        let mut first = true;
        while *mu <= MU_MAX {
            if !std::mem::take(&mut first) {
                tick()?;
            }
            let d = hess.newton_direction(self, x, grad, mu, opts.hessian)?;
            let slope: f64 = grad
                .iter()
                .zip(&d)
                .map(|(g, d)| g.re * d.re + g.im * d.im)
                .sum();
            if slope.is_nan() || slope >= 0.0 {
                *mu = (*mu * 10.0).max(MU_MIN);
                continue;
            }
            let mut alpha = 1.0;
            while alpha >= 1.0 / 16.0 {
                if alpha < 1.0 {
                    tick()?;
                }
                let trial: Vec<Complex> = x
                    .iter()
                    .zip(&d)
                    .map(|(&xi, &di)| xi + di.scale(alpha))
                    .collect();
                let (p, _) = self.evaluate(&trial, false);
                if p.total() <= f0 + 1e-4 * alpha * slope {
                    *x = trial;
                    *mu = if alpha == 1.0 {
                        (*mu * 0.1).max(MU_MIN)
                    } else {
                        *mu
                    };
                    return Ok(true);
                }
                alpha *= 0.5;
            }
            *mu = (*mu * 10.0).max(MU_MIN);
        }
        Ok(false)
    }
}

/// Trust-region Newton–CG ([`HessianModel::TrustRegion`], see `spacetime`).
impl Problem {
    /// The frame blocks of `K` and the time coupling, for the preconditioner.
    fn frame_blocks(&self) -> Result<FrameBlocks> {
        let coupling = self
            .w_smooth
            .iter()
            .zip(&self.pinned)
            .map(|(w, &p)| if p { 0.0 } else { 2.0 * w })
            .collect();
        FrameBlocks::new(self.n_v, self.n_frames - 1, coupling, |n| {
            let mut t = Vec::new();
            push_frame_triplets(self, n, 0, false, &mut t);
            t
        })
    }

    /// `y = (K + D_exact(x)) v` on real vectors.
    fn hess_vec(&self, k: &FrameBlocks, x: &[Complex], v: &[f64], y: &mut [f64]) {
        k.k_matvec(v, y);
        for (u, z) in x.iter().enumerate() {
            let b = self.unit_block_at(u, *z, HessianModel::Exact);
            let (v0, v1) = (v[2 * u], v[2 * u + 1]);
            y[2 * u] += b[0] * v0 + b[1] * v1;
            y[2 * u + 1] += b[1] * v0 + b[2] * v1;
        }
    }

    /// Runs the trust-region iteration. Returns the guide-frame phases and the report.
    fn solve_trust_region(
        &self,
        opts: &InterpOptions,
        start: Instant,
        progress: &mut ProgressFn<'_>,
    ) -> Result<(Vec<Vec<Complex>>, InterpReport)> {
        const MAX_CG: usize = 2000;
        // measured on the knight and the torus (50 frames): refactoring every iteration,
        // every 5 and every 20 gave 6.4 / 4.5 / 5.8 s and 16.6 / 9.2 / 8.9 s
        const REFACTOR_EVERY: usize = 5;
        // CG iterations between two cancellation points: one took 22–30 ms at load
        // 7 on spot 1k × 50 frames, so 16 left gaps of 0.5 s; 4 keep them near 0.1 s
        const CG_PER_TICK: usize = 4;
        let blocks = self.frame_blocks()?;
        checkpoint(progress, "interpolate", 0.0)?;
        let (mut factorizations, mut cg_iterations) = (0usize, 0usize);
        // initial guess: the minimizer of the quadratic part K alone (E_unit's projected
        // Hessian vanishes at z = 0), normalized per vertex
        let mut x = self.start_vector();
        {
            let (_, g0) = self.evaluate(&x, true);
            checkpoint(progress, "interpolate", 0.0)?;
            let g = to_real(&g0);
            let pre = blocks.factor(|_, _| [0.0; 3], &mut || {
                checkpoint(progress, "interpolate", 0.0)
            })?;
            checkpoint(progress, "interpolate", 0.0)?;
            factorizations += self.n_frames - 1;
            let kv = |v: &[f64], y: &mut [f64]| blocks.k_matvec(v, y);
            let tol = 1e-6 * dot_n(&g, &g).sqrt();
            let st = steihaug_with_stop(
                &g,
                &kv,
                &|r| pre.apply(r),
                f64::INFINITY,
                tol,
                MAX_CG,
                &mut |it| {
                    it % CG_PER_TICK == 0 && checkpoint(progress, "interpolate", 0.0).is_err()
                },
            )
            .ok_or(Error::Cancelled)?;
            cg_iterations += st.iterations;
            x.iter_mut()
                .zip(to_complex(&st.step))
                .for_each(|(xi, di)| *xi += di);
            normalize_unknowns(&mut x);
        }
        let mut log = IterationLog::new(start);
        let mut iterations = 0;
        let (mut delta, mut first): (Option<f64>, Option<f64>) = (None, None);
        let mut pre = None;
        let (mut since_factor, mut last_cg) = (0usize, 0usize);

        let stop = 'outer: loop {
            let (parts, grad) = self.evaluate(&x, true);
            let f0 = parts.total();
            if let Some(stop) = log.record(iterations, f0, &grad, opts, progress)? {
                break stop;
            }
            let gnorm = log.last_gradient_norm();
            let g = to_real(&grad);
            // The preconditioner only shapes CG and the trust region: it is refactored when it is
            // `REFACTOR_EVERY` iterations old or CG needed many iterations with it.
            if pre.is_none() || since_factor >= REFACTOR_EVERY || last_cg > 20 {
                pre = Some(blocks.factor(
                    |n, j| {
                        let u = (n - 1) * self.n_v + j;
                        self.unit_block_at(u, x[u], HessianModel::Projected)
                    },
                    &mut || log.tick(progress),
                )?);
                factorizations += self.n_frames - 1;
                since_factor = 0;
                log.tick(progress)?;
            }
            since_factor += 1;
            let pre = pre.as_ref().expect("factored above");
            let apply = |r: &[f64]| pre.apply(r);
            let hv = |v: &[f64], y: &mut [f64]| self.hess_vec(&blocks, &x, v, y);
            // first radius: the M-norm of the preconditioned steepest-descent step
            let first_radius = *first.get_or_insert_with(|| dot_n(&g, &apply(&g)).sqrt());
            let mut radius = delta.unwrap_or(first_radius);
            // inexact Newton forcing term (superlinear near the solution)
            let tol = gnorm * gnorm.sqrt().min(0.5);
            let mut first_trial = true;
            loop {
                // a cancellation point per shrunk trial radius
                if !std::mem::take(&mut first_trial) {
                    log.tick(progress)?;
                }
                // and every `CG_PER_TICK` CG iterations (a last iteration can run hundreds)
                let st = steihaug_with_stop(&g, &hv, &apply, radius, tol, MAX_CG, &mut |it| {
                    it % CG_PER_TICK == 0 && log.tick(progress).is_err()
                })
                .ok_or(Error::Cancelled)?;
                cg_iterations += st.iterations;
                last_cg = st.iterations;
                let mut hs = vec![0.0; g.len()];
                hv(&st.step, &mut hs);
                let predicted = -(dot_n(&g, &st.step) + 0.5 * dot_n(&st.step, &hs));
                let trial: Vec<Complex> = x
                    .iter()
                    .zip(st.step.chunks_exact(2))
                    .map(|(&xi, d)| xi + Complex::new(d[0], d[1]))
                    .collect();
                let f1 = self.evaluate(&trial, false).0.total();
                // after the trial's evaluation: the next one (with gradient) follows
                log.tick(progress)?;
                let rho = if predicted > 0.0 {
                    (f0 - f1) / predicted
                } else {
                    -1.0
                };
                // radius update (Nocedal & Wright Alg. 4.1; halving measured slightly better than
                // quartering on the coarse corpus)
                if rho < 0.25 || !f1.is_finite() {
                    radius = 0.5 * st.m_norm.min(radius);
                } else if rho > 0.75 && st.on_boundary {
                    radius *= 2.0;
                }
                if f1.is_finite() && rho > 1e-4 {
                    x = trial;
                    iterations += 1;
                    delta = Some(radius);
                    break;
                }
                if radius <= 1e-12 * first_radius || predicted <= 0.0 {
                    break 'outer StopReason::Stalled;
                }
            }
        };
        let counts = [iterations, factorizations, cg_iterations];
        checkpoint(progress, "finish", log.best_fraction)?;
        Ok(self.finish(&x, stop, log.history, counts))
    }
}

fn to_real(z: &[Complex]) -> Vec<f64> {
    z.iter().flat_map(|c| [c.re, c.im]).collect()
}

/// The convergence history of a solve and the per-iteration checks both solvers share.
struct IterationLog {
    start: Instant,
    history: Vec<IterationRecord>,
    /// Largest progress fraction reported so far (reports never go backwards).
    best_fraction: f64,
}

impl IterationLog {
    fn new(start: Instant) -> IterationLog {
        IterationLog {
            start,
            history: Vec::new(),
            best_fraction: 0.0,
        }
    }

    /// Records iterate `iteration` (normalized objective, gradient) and decides: `Some` stop
    /// reason when converged or at the cap, an error when non-finite or cancelled by
    /// `progress`, `None` to go on.
    fn record(
        &mut self,
        iteration: usize,
        objective: f64,
        grad: &[Complex],
        opts: &InterpOptions,
        progress: &mut ProgressFn<'_>,
    ) -> Result<Option<StopReason>> {
        let gnorm = grad.iter().map(|g| g.norm_sqr()).sum::<f64>().sqrt();
        self.history.push(IterationRecord {
            iteration,
            seconds: self.start.elapsed().as_secs_f64(),
            gradient_norm: gnorm,
            objective,
        });
        if !gnorm.is_finite() || !objective.is_finite() {
            return Err(Error::Numerical(
                "the interpolation objective became non-finite".into(),
            ));
        }
        if gnorm <= opts.gradient_tolerance {
            return Ok(Some(StopReason::Converged));
        }
        if iteration >= opts.max_iterations {
            return Ok(Some(StopReason::IterationCap));
        }
        let g_first = self.history[0].gradient_norm.max(f64::MIN_POSITIVE);
        let frac = progress_fraction(g_first, gnorm, opts, iteration);
        self.best_fraction = self.best_fraction.max(frac);
        if !progress(Progress {
            stage: "interpolate",
            fraction: self.best_fraction,
        }) {
            return Err(Error::Cancelled);
        }
        Ok(None)
    }

    /// A progress call inside an iteration (stage `"interpolate"`, the fraction reported last):
    /// a cancellation point between the per-iteration ones; `Err(Cancelled)` on `false`.
    fn tick(&self, progress: &mut ProgressFn<'_>) -> Result<()> {
        if progress(Progress {
            stage: "interpolate",
            fraction: self.best_fraction,
        }) {
            Ok(())
        } else {
            Err(Error::Cancelled)
        }
    }

    /// Gradient norm of the last recorded iterate.
    fn last_gradient_norm(&self) -> f64 {
        self.history.last().map_or(0.0, |r| r.gradient_norm)
    }
}

/// Progress in [0, 1]: the larger of the iteration fraction and the log-gradient decrease.
fn progress_fraction(g_first: f64, g: f64, opts: &InterpOptions, it: usize) -> f64 {
    let by_it = it as f64 / opts.max_iterations.max(1) as f64;
    let tol = opts.gradient_tolerance.max(1e-300);
    let by_g = if g_first > tol {
        ((g_first / g).ln() / (g_first / tol).ln()).clamp(0.0, 1.0)
    } else {
        1.0
    };
    by_it.max(by_g).clamp(0.0, 0.999)
}

/// Scales every unknown to unit modulus (zeros stay zero).
fn normalize_unknowns(x: &mut [Complex]) {
    for z in x.iter_mut() {
        let r = z.abs();
        if r > 1e-12 {
            *z = z.scale(1.0 / r);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Hessian assembly and factorization

/// The constant quadratic part `K` (lower triangle, CSC), the slots of the 2×2 diagonal blocks
/// and the cached symbolic factorization.
struct Hessian {
    k: SparseMatrix,
    /// Per unknown vertex: value slots of `(2u,2u)`, `(2u+1,2u)`, `(2u+1,2u+1)`.
    diag_slots: Vec<[usize; 3]>,
    /// Mean of K's diagonal (the damping unit).
    diag_mean: f64,
    analysis: CholeskyAnalysis,
    factorizations: usize,
    /// The last successful factorization, reused as a preconditioner (see `lagged_solve`).
    last: Option<Cholesky>,
}

impl Hessian {
    fn new(p: &Problem) -> Result<Hessian> {
        let nu = p.n_unknown();
        let k = assemble_k(p)?;
        let slot = |r: usize, c: usize| -> usize {
            entry_index(&k, r, c).expect("diagonal block in pattern")
        };
        let diag_slots: Vec<[usize; 3]> = (0..nu)
            .map(|u| {
                [
                    slot(2 * u, 2 * u),
                    slot(2 * u + 1, 2 * u),
                    slot(2 * u + 1, 2 * u + 1),
                ]
            })
            .collect();
        let vals = k.val();
        let diag_mean = diag_slots
            .iter()
            .map(|s| vals[s[0]] + vals[s[2]])
            .sum::<f64>()
            / (2 * nu).max(1) as f64;
        let analysis = CholeskyAnalysis::new(&k)?;
        Ok(Hessian {
            k,
            diag_slots,
            diag_mean: if diag_mean > 0.0 { diag_mean } else { 1.0 },
            analysis,
            factorizations: 0,
            last: None,
        })
    }

    /// `K + D(x) + μ·mean(diag K)·I` (lower triangle).
    fn assemble(&self, p: &Problem, x: &[Complex], mu: f64, model: HessianModel) -> SparseMatrix {
        let mut h = self.k.clone();
        let vals = h.val_mut();
        for (u, s) in self.diag_slots.iter().enumerate() {
            let b = p.unit_block_at(u, x[u], model);
            vals[s[0]] += b[0] + mu * self.diag_mean;
            vals[s[1]] += b[1];
            vals[s[2]] += b[2] + mu * self.diag_mean;
        }
        h
    }

    /// Solves `(K + D(x) + μ·mean(diag K)·I) d = −g`. First by conjugate gradients
    /// preconditioned with the previous iteration's factorization (the Hessian changes only in
    /// its 2×2 diagonal blocks between iterations, so a few steps suffice), else by a fresh
    /// factorization, raising `μ` until it succeeds.
    fn newton_direction(
        &mut self,
        p: &Problem,
        x: &[Complex],
        g: &[Complex],
        mu: &mut f64,
        model: HessianModel,
    ) -> Result<Vec<Complex>> {
        let rhs: Vec<f64> = g.iter().flat_map(|c| [-c.re, -c.im]).collect();
        if let Some(llt) = &self.last {
            let h = self.assemble(p, x, *mu, model);
            if let Some(d) = lagged_solve(&h, llt, &rhs) {
                return Ok(to_complex(&d));
            }
        }
        for _ in 0..40 {
            let h = self.assemble(p, x, *mu, model);
            self.factorizations += 1;
            if let Ok(llt) = self.analysis.factor(&h, Parallelism::Global) {
                let d = llt.solve(&rhs);
                if d.iter().all(|v| v.is_finite()) {
                    self.last = Some(llt);
                    return Ok(to_complex(&d));
                }
            }
            *mu = (*mu * 100.0).max(1e-10);
        }
        Err(Error::Numerical(
            "the interpolation Hessian could not be factorized even with heavy damping".into(),
        ))
    }
}

/// The constant quadratic part `K` of the spacetime Hessian (lower triangle, CSC).
fn assemble_k(p: &Problem) -> Result<SparseMatrix> {
    let nu = p.n_unknown();
    let mut t: Vec<Entry> = Vec::new();
    for n in 1..p.n_frames {
        push_frame_triplets(p, n, (n - 1) * p.n_v, true, &mut t);
    }
    assemble(2 * nu, &t, "the interpolation Hessian")
}

/// Appends frame `n`'s entries of `K` (lower triangle) with its first unknown vertex at
/// `base`: the `E_smooth` diagonal `4 w_s,j`, the `c E_compat` connection Laplacian and, when
/// `time_coupling` and `n + 1 < N'`, the coupling `−2 w_s,j` to frame `n + 1`. Every frame
/// lists the same positions (explicit zeros included), so frame blocks share one pattern.
fn push_frame_triplets(
    p: &Problem,
    n: usize,
    base: usize,
    time_coupling: bool,
    t: &mut Vec<Entry>,
) {
    for j in 0..p.n_v {
        let u = base + j;
        let d = 4.0 * p.w_smooth[j];
        t.push(Entry::new(2 * u, 2 * u, d));
        t.push(Entry::new(2 * u + 1, 2 * u, 0.0));
        t.push(Entry::new(2 * u + 1, 2 * u + 1, d));
        if time_coupling && n + 1 < p.n_frames {
            let v = u + p.n_v;
            let o = if p.pinned[j] {
                0.0
            } else {
                -2.0 * p.w_smooth[j]
            };
            t.push(Entry::new(2 * v, 2 * u, o));
            t.push(Entry::new(2 * v + 1, 2 * u + 1, o));
        }
    }
    for (e, &[k, l]) in p.edges.iter().enumerate() {
        let (uk, ul) = (base + k as usize, base + l as usize);
        let w2 = 2.0 * p.w_compat[e];
        for uu in [uk, ul] {
            t.push(Entry::new(2 * uu, 2 * uu, w2));
            t.push(Entry::new(2 * uu + 1, 2 * uu + 1, w2));
        }
        // block (l, k) = −2w [t], [t] = [[c, −s], [s, c]]; l > k so it is lower. Dropped (kept
        // as explicit zeros, one pattern for every frame) when an end is pinned.
        let r = p.rot[n][e];
        let wo = if p.pinned[k as usize] || p.pinned[l as usize] {
            0.0
        } else {
            w2
        };
        for (a, q, v) in [(0, 0, r.re), (0, 1, -r.im), (1, 0, r.im), (1, 1, r.re)] {
            t.push(Entry::new(2 * ul + a, 2 * uk + q, -wo * v));
        }
    }
}

fn to_complex(d: &[f64]) -> Vec<Complex> {
    d.chunks_exact(2)
        .map(|c| Complex::new(c[0], c[1]))
        .collect()
}

/// `y = H v` for `H` stored as its lower triangle (CSC).
fn sym_matvec(h: &SparseMatrix, v: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; v.len()];
    sym_matvec_lower_into(h, v, &mut y);
    y
}

/// Preconditioned CG on `H d = b` with a stale factorization as preconditioner. `None` when it
/// does not reach a relative residual of 1e-8 within 12 steps or meets non-positive curvature
/// (`H` indefinite): the caller then factorizes.
fn lagged_solve(h: &SparseMatrix, pre: &Cholesky, b: &[f64]) -> Option<Vec<f64>> {
    let apply_pre = |r: &[f64]| -> Vec<f64> { pre.solve(r) };
    let dotv = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
    let bnorm = dotv(b, b).sqrt();
    if bnorm == 0.0 {
        return Some(vec![0.0; b.len()]);
    }
    let mut x = apply_pre(b);
    let hx = sym_matvec(h, &x);
    let mut r: Vec<f64> = b.iter().zip(&hx).map(|(bi, hi)| bi - hi).collect();
    let mut z = apply_pre(&r);
    let mut pdir = z.clone();
    let mut rz = dotv(&r, &z);
    for _ in 0..12 {
        if dotv(&r, &r).sqrt() <= 1e-8 * bnorm {
            return Some(x);
        }
        let hp = sym_matvec(h, &pdir);
        let php = dotv(&pdir, &hp);
        if php.is_nan() || php <= 0.0 {
            return None;
        }
        let alpha = rz / php;
        for i in 0..x.len() {
            x[i] += alpha * pdir[i];
            r[i] -= alpha * hp[i];
        }
        z = apply_pre(&r);
        let rz_new = dotv(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..x.len() {
            pdir[i] = z[i] + beta * pdir[i];
        }
    }
    (dotv(&r, &r).sqrt() <= 1e-8 * bnorm && x.iter().all(|v| v.is_finite())).then_some(x)
}

/// The PSD 2×2 Hessian block `(h00, h10, h11)` of `w (|z|² − 1)²` at `z`.
fn unit_block(z: Complex, w: f64, model: HessianModel) -> [f64; 3] {
    let r2 = z.norm_sqr();
    let (l_par, l_perp) = match model {
        // exact Hessian 4w(|z|²−1) I + 8w zzᵀ: eigenvalues along z and across, clamped at 0
        HessianModel::Projected => (
            (4.0 * w * (3.0 * r2 - 1.0)).max(0.0),
            (4.0 * w * (r2 - 1.0)).max(0.0),
        ),
        HessianModel::GaussNewton => (8.0 * w * r2, 0.0),
        HessianModel::Exact | HessianModel::TrustRegion => {
            (4.0 * w * (3.0 * r2 - 1.0), 4.0 * w * (r2 - 1.0))
        }
    };
    if r2 == 0.0 {
        return [l_perp, 0.0, l_perp];
    }
    // l_perp I + (l_par − l_perp) ẑẑᵀ
    let dl = (l_par - l_perp) / r2;
    [
        l_perp + dl * z.re * z.re,
        dl * z.re * z.im,
        l_perp + dl * z.im * z.im,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;

    /// The frame-block product used by the trust-region solver equals the assembled `K`.
    #[test]
    fn frame_block_matvec_equals_assembled_k() {
        let n = 6usize;
        let mut pos = Vec::new();
        for i in 0..n {
            for j in 0..n {
                pos.push([i as f64 + 0.1 * (j as f64).sin(), j as f64, 0.0]);
            }
        }
        let mut tris = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let v = (i * n + j) as u32;
                let w = n as u32;
                tris.push([v, v + w, v + w + 1]);
                tris.push([v, v + w + 1, v + 1]);
            }
        }
        let mesh = TriMesh::new(pos, tris).unwrap();
        let nv = mesh.vertex_count();
        let ne = mesh.edges().len();
        let omega_a: Vec<f64> = (0..ne).map(|e| 0.3 * (e as f64).cos()).collect();
        let omega_b: Vec<f64> = (0..ne).map(|e| 0.5 * (e as f64 * 0.7).sin()).collect();
        let zeta = |s: f64| {
            (0..nv)
                .map(|j| Complex::cis(s * j as f64))
                .collect::<Vec<_>>()
        };
        let a = Cwf::new(mesh.clone(), omega_a, vec![0.1; nv], zeta(0.2)).unwrap();
        let b = Cwf::new(mesh, omega_b, vec![0.2; nv], zeta(0.5)).unwrap();
        let opts = InterpOptions {
            guide_frames: 5,
            ..Default::default()
        };
        let setup = Setup::new(&a, &b, &opts);
        let omega: Vec<Vec<f64>> = (0..=5)
            .map(|i| setup.com.at(&a.topo, i as f64 / 5.0))
            .collect();
        let p = Problem::new(&a, &b, &setup, &omega, &opts).unwrap();
        let k = assemble_k(&p).unwrap();
        let blocks = p.frame_blocks().unwrap();
        let v: Vec<f64> = (0..2 * p.n_unknown())
            .map(|i| (i as f64 * 0.37).sin())
            .collect();
        let mut y1 = vec![0.0; v.len()];
        let mut y2 = vec![0.0; v.len()];
        sym_matvec_lower_into(&k, &v, &mut y1);
        blocks.k_matvec(&v, &mut y2);
        let err = y1
            .iter()
            .zip(&y2)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let scale = y1.iter().map(|a| a.abs()).fold(0.0, f64::max);
        assert!(err <= 1e-12 * scale, "max difference {err} (scale {scale})");
    }
}
