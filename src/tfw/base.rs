//! The base surface (§2.4.1, appendix A.2): minimize
//! `E = E_TFT + E_b + E_p + E_g` over the free vertex positions by Newton's method with an
//! Armijo line search on the crate's sparse Cholesky ([`crate::solve`], symbolic analysis
//! computed once: the pattern never changes).
//!
//! - `E_TFT = Σ_f (h/4) A_f W̃(λ1, λ2)`, `W̃` the relaxed density of A.2
//!   ([`relaxed_density_in_form`]), exact gradient and Hessian by the chain rule through the
//!   first fundamental form `I_f = [e1·e1, e1·e2, e2·e2]`. Convex in x (spec); its Hessian is
//!   PSD face by face.
//! - `E_b = c_b Σ_i ‖(L x)_i‖² / Ā_i` (eq. 2.28), `L` the cotan Laplacian of the rest pattern
//!   with the Wang et al. 2015 free-boundary correction, `Ā_i` barycentric rest areas,
//!   `c_b = bending_scale · α h³/24` (the reference code's value; the text's `α h³/12` is
//!   reachable with `bending_scale = 2`, spec Risk 2). Quadratic, exact Hessian `2 c_b LᵀM⁻¹L`.
//! - `E_p = −p V`, `V = Σ_f x0·(x1×x2)/6`. Not convex: each face's 9×9 Hessian block is
//!   projected onto the PSD cone (cyclic Jacobi, `tfw::dense`) unless the exact Hessian is asked
//!   for (tests).
//! - `E_g = −Σ_i ρ h Ā_i g·x_i`.
//!
//! Dirichlet vertices are eliminated. Regularization: the assembled Hessian is factored as
//! `H + σI`, σ starting at `1e-10 · mean|H_ii|` (or a tenth of the last σ that was needed) and
//! growing ×10 until faer's Cholesky succeeds (slack faces contribute nothing, so H is
//! singular in plane there; with ν = 0 the bending vanishes too). A direction that is not a
//! descent direction is replaced by the scaled negative gradient.
//!
//! With pressure the Newton matrix is not the Hessian (the PSD projection of the pressure
//! blocks made the balloons converge linearly: the disk's gradient fell ×0.9 per full step,
//! 101 iterations to a stall at 1.1e-6), so there the step is refined by Steihaug–Toint CG
//! on the exact Hessian, preconditioned by the factorization of the membrane + bending part
//! plus the shift (`newton_step`, [`BaseOptions::cg_iterations`]); the pressure blocks are
//! then not projected at all, which also removed most of the per-iteration cost (the 9×9
//! Jacobi projections: 74 of 119 ms per disk iteration). Measured 2026-11-27 (1000-v disk:
//! 101 → 12 iterations, 12.0 → 0.58 s, relative gradient 7e-11; 1320-v torus: 200
//! unconverged iterations → 85, converged). Scenes without pressure take the plain shifted
//! step, as before (same iterates).
//!
//! Sheared rectangle (no pressure; measured 2026-11-29): the plain
//! Armijo Newton iteration stopped at its 200-iteration limit at a relative gradient of 4.4e-8.
//! Not the out-of-plane directions (the sheet starts flat and the load is in plane, so the z
//! gradient and the x–z, y–z Hessian blocks are exactly 0 at every iterate) and not the shift:
//! the floor 1e-10·mean|H_ii| (7.9e-6) factors at 1e-14 as well, and floors from 1e-14 to 1e-7
//! all end between 1.6e-7 and 4.4e-8 at 200. The iterates crawl along a curved valley:
//! consecutive updates are parallel (cosine 0.98–0.9997 from iteration ≈ 185), ‖t d‖ ≈ 3e-7 m
//! does not shrink, and the gradient after a step is the model's second-order error (∝ t²),
//! sitting at wrinkled faces with `λ1 ≈ 1e-7…1e-6` beside slack faces (61 of 1824), whose
//! stiff `cλ1²` sees the step's soft in-plane motion at second order. So the line search cuts
//! the straight Newton step. The fix is the classic second-order correction
//! ([`BaseOptions::second_order_correction`], `corrected_step`): `s = d − M⁻¹g(x + d)` with the
//! same factorization, tried first and accepted by the same Armijo test (slope `gᵀd`); if it
//! fails, the usual backtracking along d. One more gradient evaluation and solve per iteration
//! (≈ 15 % of one on the rectangle). And a backtracked step (t < 1) no longer stops the solve
//! as `EnergyStalled` (its small E change says nothing about the rounding floor). Rectangle:
//! **Converged in 89 iterations at 2.3e-9** (E 0.24518000641622 J, below the 200-iteration
//! 0.24518000645213), 27.5 wrinkles, peak 1.299 mm (unchanged). The sheet (8 iterations) and
//! the cylinders take it too (other iterates, same answers: docs/design-notes.md, "Base solve");
//! with pressure the Newton matrix is not the Hessian and the CG path above is unchanged.
//!
//! Termination (spec step 2): `‖g‖∞ ≤ tol · ‖g₀‖∞` ([`BaseStatus::Converged`]); an accepted step
//! changing E by less than `energy_tolerance · |E|` ([`BaseStatus::EnergyStalled`], the
//! rounding floor of E is reached first when the gradient tolerance is very small); the
//! iteration limit; or a failed line search. The Armijo test allows an increase of
//! 4 ulp·|E| so that steps whose predicted decrease is below the rounding of E are not
//! rejected spuriously; apart from that, E never increases, except that a full step whose
//! predicted decrease is below 64 ε|E| (E cannot judge it) is accepted when it lowers
//! `‖g‖∞`; and an E change below `energy_tolerance` stops the solve only when the step did
//! not halve `‖g‖∞` (a Newton step near the optimum makes progress E cannot show).

use std::time::Instant;

use rayon::prelude::*;

use super::dense::{cross, dot, scale, sub};
use crate::mesh::TriMesh;
use crate::report::{Progress, ProgressFn};
use crate::solve::{
    dot_n, steihaug, sym_matvec_lower_into, AssemblyPlan, Cholesky, CholeskyAnalysis, Entry,
    Parallelism, ShiftSchedule, SparseMatrix,
};
use crate::tfw::dense::project_psd;
use crate::tfw::material::{principal_strains, relaxed_density_in_form, Branch, Lame};
use crate::tfw::scene::{Model, Obstacle};
use crate::{Error, Result};

/// Which energy terms to evaluate (all by default).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Terms {
    /// Tension-field membrane energy.
    pub membrane: bool,
    /// Quadratic bending (2.28).
    pub bending: bool,
    /// Pressure `−pV`.
    pub pressure: bool,
    /// Gravity.
    pub gravity: bool,
    /// Obstacle penalties ([`crate::tfw::Obstacle`]).
    pub obstacles: bool,
}

impl Terms {
    /// Every term.
    pub const ALL: Terms = Terms {
        membrane: true,
        bending: true,
        pressure: true,
        gravity: true,
        obstacles: true,
    };
    /// No term (start from this and switch one on).
    pub const NONE: Terms = Terms {
        membrane: false,
        bending: false,
        pressure: false,
        gravity: false,
        obstacles: false,
    };
}

/// Options of [`solve_base`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseOptions {
    /// Newton iterations per load step.
    pub max_iterations: usize,
    /// Stop when `‖g‖∞ ≤ gradient_tolerance · ‖g₀‖∞` (g over free DOFs, g₀ at the start of the
    /// load step). Default 1e-8.
    pub gradient_tolerance: f64,
    /// Stop when an accepted step changes E by less than this times |E|. Default 1e-14.
    pub energy_tolerance: f64,
    /// Dirichlet motions are applied in this many equal increments (≥ 1; R `num_interpolation`).
    pub load_steps: usize,
    /// Multiplier of the bending coefficient `α h³/24` (spec Risk 2).
    pub bending_scale: f64,
    /// With pressure: conjugate-gradient iterations that refine each Newton step on the
    /// unshifted exact Hessian, preconditioned by the shifted factorization of the
    /// pressure-free part (Steihaug–Toint, [`crate::solve::steihaug`]; module docs); 0 = the
    /// shifted step with the pressure blocks PSD-projected. Scenes without pressure always
    /// take the plain shifted step. Default 50 (the balloons use 4–12).
    pub cg_iterations: usize,
    /// Without pressure: try the second-order-corrected step `d − M⁻¹g(x + d)` (M the factored
    /// Newton matrix) before backtracking along the Newton direction d, and let only full
    /// steps stop the solve as [`BaseStatus::EnergyStalled`] (module docs, "Sheared
    /// rectangle"). Default true; false is the plain Armijo Newton iteration of before.
    pub second_order_correction: bool,
}

impl Default for BaseOptions {
    /// 200 iterations, gradient 1e-8, energy 1e-14, one load step, bending scale 1, 50 CG
    /// iterations (with pressure), second-order correction on.
    fn default() -> Self {
        BaseOptions {
            max_iterations: 200,
            gradient_tolerance: 1e-8,
            energy_tolerance: 1e-14,
            load_steps: 1,
            bending_scale: 1.0,
            cg_iterations: 50,
            second_order_correction: true,
        }
    }
}

/// Why [`solve_base`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaseStatus {
    /// The relative gradient reached the tolerance.
    Converged,
    /// E stopped changing (relative change below `energy_tolerance`) before the gradient
    /// tolerance was met: E is at its rounding floor.
    EnergyStalled,
    /// The iteration limit was reached.
    MaxIterations,
    /// The line search found no decrease along the (Newton or gradient) direction.
    LineSearchFailed,
    /// Every Cholesky attempt failed (not even a large diagonal shift helped).
    FactorizationFailed,
}

impl BaseStatus {
    /// A one-line explanation.
    pub fn describe(&self) -> &'static str {
        match self {
            BaseStatus::Converged => "converged: relative gradient below tolerance",
            BaseStatus::EnergyStalled => {
                "stopped: energy change below its rounding floor before the gradient tolerance"
            }
            BaseStatus::MaxIterations => "stopped: iteration limit reached",
            BaseStatus::LineSearchFailed => "stopped: line search found no decrease",
            BaseStatus::FactorizationFailed => "stopped: Hessian factorization failed",
        }
    }
}

/// One Newton iteration of [`solve_base`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonIteration {
    /// Load step (1-based).
    pub load_step: usize,
    /// Energy after the step.
    pub energy: f64,
    /// `‖g‖∞` over free DOFs before the step.
    pub gradient_norm: f64,
    /// Accepted line-search step length t ∈ (0, 1].
    pub step: f64,
    /// `‖t d‖∞` of the accepted update (m).
    pub step_norm: f64,
    /// Diagonal shift σ used to factor the Hessian.
    pub shift: f64,
    /// True when the Newton direction was replaced by the negative gradient.
    pub gradient_step: bool,
    /// True when the accepted update was the second-order-corrected step
    /// ([`BaseOptions::second_order_correction`]; then `step` is 1).
    pub corrected: bool,
    /// Faces whose branch of the relaxed density (A.2: slack, tension, wrinkled) differs
    /// between the states before and after the step (where the Newton model, whose Hessian
    /// jumps at a branch switch, can stop being valid).
    pub branch_changes: usize,
    /// Wall-clock seconds since the start of [`solve_base`].
    pub seconds: f64,
    /// Where this iteration's time went ([`NewtonTimes`]).
    pub times: NewtonTimes,
}

/// The cost of one [`NewtonIteration`], by phase (wall-clock seconds and counts).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NewtonTimes {
    /// Energy, gradient and per-face Hessian blocks (pressure blocks PSD-projected).
    pub evaluate: f64,
    /// Scattering the free-DOF values into the fixed pattern and assembling the sparse
    /// matrix (and the exact pressure correction, when there is pressure); the first
    /// iteration also makes the assembly plan (one sort of the pattern).
    pub assemble: f64,
    /// Numeric Cholesky factorizations of `H + σI` (the symbolic analysis is made once per
    /// solve and reused: its time is in the first iteration's `assemble`).
    pub factor: f64,
    /// Factorizations tried (σ grown ×10 after each failure).
    pub factor_attempts: usize,
    /// Triangular solves and the conjugate-gradient refinement of the step.
    pub solve: f64,
    /// Conjugate-gradient iterations of the refinement ([`BaseOptions::cg_iterations`]).
    pub cg_iterations: usize,
    /// The Armijo line search (energy evaluations).
    pub line_search: f64,
    /// Energy evaluations of the line search.
    pub line_search_evaluations: usize,
}

/// The energy terms at one state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TermEnergies {
    /// Tension-field membrane energy (J).
    pub membrane: f64,
    /// Quadratic bending energy (J).
    pub bending: f64,
    /// Pressure energy `−pV` (J).
    pub pressure: f64,
    /// Gravity energy (J).
    pub gravity: f64,
    /// Obstacle penalty energy (J).
    pub obstacles: f64,
}

/// Per-face strain state of a base surface.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StrainSummary {
    /// Faces in pure tension.
    pub tension_faces: usize,
    /// Faces in tension with relaxed compression (wrinkle candidates).
    pub wrinkled_faces: usize,
    /// Faces compressed in every direction.
    pub slack_faces: usize,
    /// Faces with `det I ≤ 1e-12 det Ī` (collapsed in 3D; TFT does not see inversion).
    pub degenerate_faces: usize,
    /// Rest-area fraction of slack faces (the problem is out of scope, S:588, when large).
    pub slack_area_fraction: f64,
    /// Rest-area fraction of wrinkled faces.
    pub wrinkled_area_fraction: f64,
}

/// The result of [`solve_base`].
#[derive(Debug, Clone, PartialEq)]
pub struct BaseResult {
    /// The base surface (stitched mesh at the equilibrium positions).
    pub mesh: TriMesh,
    /// Why the last load step stopped.
    pub status: BaseStatus,
    /// Every Newton iteration of every load step.
    pub history: Vec<NewtonIteration>,
    /// The energy terms at the result.
    pub energies: TermEnergies,
    /// `‖g‖∞ / ‖g₀‖∞` at the result (last load step).
    pub relative_gradient: f64,
    /// The strain state at the result.
    pub strain: StrainSummary,
    /// Warnings from the scene and the solve.
    pub warnings: Vec<String>,
}

/// Energy, gradient and Hessian (lower triangle, full `3n` numbering, duplicates to be summed).
#[derive(Debug, Clone, PartialEq)]
pub struct BaseEval {
    /// The energy.
    pub energy: f64,
    /// The gradient, `3n` entries (x, y, z per vertex).
    pub gradient: Vec<f64>,
    /// Hessian entries `(row, col, value)` with `row ≥ col`; the pattern depends only on the
    /// mesh (zeros included), not on the state.
    pub hessian: Vec<(usize, usize, f64)>,
}

/// The assembled energy of a [`Model`] (precomputed rest quantities).
#[derive(Debug, Clone)]
pub struct BaseProblem {
    triangles: Vec<[u32; 3]>,
    rest_forms: Vec<[f64; 3]>,
    rest_areas: Vec<f64>,
    vertex_areas: Vec<f64>,
    lame: Lame,
    thickness: f64,
    density: f64,
    gravity: [f64; 3],
    pressure: f64,
    obstacles: Vec<Obstacle>,
    /// Rows of the corrected cotan Laplacian.
    laplacian: Vec<Vec<(u32, f64)>>,
    bending_coefficient: f64,
    /// `LᵀM⁻¹L`, lower triangle, merged.
    bending_matrix: Vec<(u32, u32, f64)>,
}

type Block9 = [[f64; 9]; 9];

impl BaseProblem {
    /// Precomputes rest areas, the corrected Laplacian and the bending matrix of `model`.
    pub fn new(model: &Model, bending_scale: f64) -> BaseProblem {
        let n = model.positions.len();
        let rest_areas: Vec<f64> = model
            .rest_forms
            .iter()
            .map(|f| 0.5 * (f[0] * f[2] - f[1] * f[1]).sqrt())
            .collect();
        let mut vertex_areas = vec![0.0; n];
        for (t, a) in model.triangles.iter().zip(&rest_areas) {
            for &v in t {
                vertex_areas[v as usize] += a / 3.0;
            }
        }
        let laplacian = corrected_laplacian(n, &model.triangles, &model.rest_corners);
        let lame = model.material.lame();
        let h = model.material.thickness;
        let bending_coefficient = bending_scale * lame.alpha * h * h * h / 24.0;
        let bending_matrix = normal_matrix(n, &laplacian, &vertex_areas);
        BaseProblem {
            triangles: model.triangles.clone(),
            rest_forms: model.rest_forms.clone(),
            rest_areas,
            vertex_areas,
            lame,
            thickness: h,
            density: model.material.density,
            gravity: model.gravity,
            pressure: model.pressure,
            obstacles: model.obstacles.clone(),
            laplacian,
            bending_coefficient,
            bending_matrix,
        }
    }

    /// The rows of the corrected cotan Laplacian `L` (`(Lx)_i = Σ_j L_ij x_j`); it annihilates
    /// functions that are affine on a flat panel, at interior and boundary vertices.
    pub fn laplacian(&self) -> &[Vec<(u32, f64)>] {
        &self.laplacian
    }

    /// The bending coefficient `c_b` (J·m⁻²·m² units: energy per squared Laplacian per area).
    pub fn bending_coefficient(&self) -> f64 {
        self.bending_coefficient
    }

    /// The energy terms at positions `x` (`3n`, flat).
    pub fn term_energies(&self, x: &[f64]) -> TermEnergies {
        let membrane = (0..self.triangles.len())
            .into_par_iter()
            .map(|f| self.membrane_value(f, x))
            .sum::<f64>();
        let bending = self.bending_value(x);
        let volume: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| vec3(x, v));
                dot(a, cross(b, c)) / 6.0
            })
            .sum();
        let gravity = -self.density
            * self.thickness
            * self
                .vertex_areas
                .iter()
                .enumerate()
                .map(|(i, a)| a * dot(self.gravity, vec3(x, i as u32)))
                .sum::<f64>();
        TermEnergies {
            membrane,
            bending,
            pressure: -self.pressure * volume,
            gravity,
            obstacles: self.obstacle_energy(x),
        }
    }

    /// The energy of the selected terms at `x`.
    pub fn energy(&self, x: &[f64], terms: Terms) -> f64 {
        let e = self.term_energies(x);
        let pick = |on: bool, v: f64| if on { v } else { 0.0 };
        pick(terms.membrane, e.membrane)
            + pick(terms.bending, e.bending)
            + pick(terms.pressure, e.pressure)
            + pick(terms.gravity, e.gravity)
            + pick(terms.obstacles, e.obstacles)
    }

    /// Energy, gradient and Hessian of the selected terms at `x`. The pressure Hessian is
    /// projected face by face onto the PSD cone unless `exact_pressure` (which also keeps the
    /// obstacle penalties' exact, indefinite Hessian; see `obstacle_terms`).
    pub fn evaluate(&self, x: &[f64], terms: Terms, exact_pressure: bool) -> BaseEval {
        self.evaluate_split(x, terms, exact_pressure, false, false)
            .0
    }

    /// [`evaluate`](Self::evaluate), and with `correction` (and a projected pressure Hessian)
    /// also the lower-triangle entries of `exact − projected` pressure Hessian, so that the
    /// exact Hessian is the sum of the two lists (the Newton step's CG operator). With
    /// `unprojected` too, the pressure Hessian is left out of the first list and the second
    /// holds all of it (no per-face projection).
    fn evaluate_split(
        &self,
        x: &[f64],
        terms: Terms,
        exact_pressure: bool,
        correction: bool,
        unprojected: bool,
    ) -> (BaseEval, Vec<(usize, usize, f64)>) {
        let n3 = x.len();
        let mut gradient = vec![0.0; n3];
        // 45 lower entries per face block, 3 per bending entry (one per coordinate)
        let mut hessian = Vec::with_capacity(
            45 * self.triangles.len()
                + 3 * self.bending_matrix.len()
                + 6 * self.obstacles.len() * self.vertex_areas.len(),
        );
        let with_pressure = terms.pressure && self.pressure != 0.0;
        let correction = correction && with_pressure && !exact_pressure;
        let blocks: Vec<(f64, [f64; 9], Block9, Option<Block9>)> = (0..self.triangles.len())
            .into_par_iter()
            .map(|f| {
                let mut e = 0.0;
                let mut g = [0.0; 9];
                let mut h = [[0.0; 9]; 9];
                let mut delta = correction.then_some([[0.0; 9]; 9]);
                if terms.membrane {
                    self.membrane_face(f, x, &mut e, &mut g, &mut h);
                }
                if with_pressure {
                    let split = (&mut delta, unprojected);
                    self.pressure_face(f, x, exact_pressure, &mut e, &mut g, &mut h, split);
                }
                (e, g, h, delta)
            })
            .collect();
        let mut energy = 0.0;
        let mut exact_minus_projected = Vec::with_capacity(if correction {
            45 * self.triangles.len()
        } else {
            0
        });
        for (t, (e, g, h, delta)) in self.triangles.iter().zip(&blocks) {
            energy += e;
            let dof = |k: usize| 3 * t[k / 3] as usize + k % 3;
            for (a, (ga, ha)) in g.iter().zip(h).enumerate() {
                gradient[dof(a)] += ga;
                for (b, hab) in ha.iter().enumerate() {
                    let (r, c) = (dof(a), dof(b));
                    if r >= c {
                        hessian.push((r, c, *hab));
                        if let Some(d) = delta {
                            exact_minus_projected.push((r, c, d[a][b]));
                        }
                    }
                }
            }
        }
        if terms.bending {
            energy += self.bending_value(x);
            let c2 = 2.0 * self.bending_coefficient;
            for &(j, k, v) in &self.bending_matrix {
                for d in 0..3 {
                    let (r, c) = (3 * j as usize + d, 3 * k as usize + d);
                    gradient[r] += c2 * v * x[c];
                    if r != c {
                        gradient[c] += c2 * v * x[r];
                    }
                    hessian.push((r, c, c2 * v));
                }
            }
        }
        if terms.gravity {
            let s = -self.density * self.thickness;
            for (i, a) in self.vertex_areas.iter().enumerate() {
                for d in 0..3 {
                    energy += s * a * self.gravity[d] * x[3 * i + d];
                    gradient[3 * i + d] += s * a * self.gravity[d];
                }
            }
        }
        if terms.obstacles {
            energy += self.obstacle_terms(x, exact_pressure, &mut gradient, &mut hessian);
        }
        let ev = BaseEval {
            energy,
            gradient,
            hessian,
        };
        (ev, exact_minus_projected)
    }

    /// The obstacle penalty `Σ_o Σ_i k_o Ā_i (m_o − d_o(x_i))³₊` ([`Obstacle`]).
    fn obstacle_energy(&self, x: &[f64]) -> f64 {
        let mut e = 0.0;
        for o in &self.obstacles {
            for (i, a) in self.vertex_areas.iter().enumerate() {
                let s = o.margin - o.distance(vec3(x, i as u32)).0;
                if s > 0.0 {
                    e += o.stiffness * a * s * s * s;
                }
            }
        }
        e
    }

    /// Adds the obstacle penalties' gradient and Hessian (lower 3×3 blocks) and returns their
    /// energy. With `s = m − d > 0`: `∇E = −3kĀs² ∇d`, `∇²E = 6kĀs ∇d∇dᵀ − 3kĀs² ∇²d`; the
    /// second part (negative semidefinite for a sphere: `∇²d = (I − uuᵀ)/ρ`) is dropped unless
    /// `exact`, so the Newton matrix stays PSD.
    fn obstacle_terms(
        &self,
        x: &[f64],
        exact: bool,
        gradient: &mut [f64],
        hessian: &mut Vec<(usize, usize, f64)>,
    ) -> f64 {
        let mut energy = 0.0;
        for o in &self.obstacles {
            for (i, a) in self.vertex_areas.iter().enumerate() {
                let (d, n, dd) = o.distance(vec3(x, i as u32));
                let s = o.margin - d;
                if s <= 0.0 {
                    continue;
                }
                let ka = o.stiffness * a;
                energy += ka * s * s * s;
                for r in 0..3 {
                    gradient[3 * i + r] -= 3.0 * ka * s * s * n[r];
                    for c in 0..=r {
                        let mut h = 6.0 * ka * s * n[r] * n[c];
                        if exact {
                            h -= 3.0 * ka * s * s * dd[r][c];
                        }
                        hessian.push((3 * i + r, 3 * i + c, h));
                    }
                }
            }
        }
        energy
    }

    /// Per-face branch counts and area fractions at `x`.
    pub fn strain_summary(&self, x: &[f64]) -> StrainSummary {
        let mut s = StrainSummary::default();
        let total: f64 = self.rest_areas.iter().sum();
        for (f, t) in self.triangles.iter().enumerate() {
            let cur = first_form(t.map(|v| vec3(x, v)));
            let rest = self.rest_forms[f];
            let det = cur[0] * cur[2] - cur[1] * cur[1];
            if det <= 1e-12 * (rest[0] * rest[2] - rest[1] * rest[1]) {
                s.degenerate_faces += 1;
            }
            let (l1, l2) = principal_strains(rest, cur);
            match self.lame.relaxed_density(l1, l2).1 {
                Branch::Tension => s.tension_faces += 1,
                Branch::Wrinkled => {
                    s.wrinkled_faces += 1;
                    s.wrinkled_area_fraction += self.rest_areas[f] / total;
                }
                Branch::Slack => {
                    s.slack_faces += 1;
                    s.slack_area_fraction += self.rest_areas[f] / total;
                }
            }
        }
        s
    }

    /// The branch of the relaxed density (A.2) of every face at `x`, in face order.
    pub fn branches(&self, x: &[f64]) -> Vec<Branch> {
        (0..self.triangles.len())
            .into_par_iter()
            .map(|f| {
                let cur = first_form(self.triangles[f].map(|v| vec3(x, v)));
                let (l1, l2) = principal_strains(self.rest_forms[f], cur);
                self.lame.relaxed_density(l1, l2).1
            })
            .collect()
    }

    fn membrane_value(&self, f: usize, x: &[f64]) -> f64 {
        let cur = first_form(self.triangles[f].map(|v| vec3(x, v)));
        let (l1, l2) = principal_strains(self.rest_forms[f], cur);
        0.25 * self.thickness * self.rest_areas[f] * self.lame.relaxed_density(l1, l2).0
    }

    fn bending_value(&self, x: &[f64]) -> f64 {
        if self.bending_coefficient == 0.0 {
            return 0.0;
        }
        let s: f64 = self
            .laplacian
            .iter()
            .zip(&self.vertex_areas)
            .map(|(row, a)| {
                let mut l = [0.0; 3];
                for &(j, w) in row {
                    let p = vec3(x, j);
                    for d in 0..3 {
                        l[d] += w * p[d];
                    }
                }
                dot(l, l) / a
            })
            .sum();
        self.bending_coefficient * s
    }

    /// Adds `(h/4) A_f W̃` of face `f` with its gradient and Hessian in the face's 9 DOFs.
    fn membrane_face(&self, f: usize, x: &[f64], e: &mut f64, g: &mut [f64; 9], h: &mut Block9) {
        let [x0, x1, x2] = self.triangles[f].map(|v| vec3(x, v));
        let (e1, e2) = (sub(x1, x0), sub(x2, x0));
        let cur = [dot(e1, e1), dot(e1, e2), dot(e2, e2)];
        let d = relaxed_density_in_form(&self.lame, self.rest_forms[f], cur);
        let k = 0.25 * self.thickness * self.rest_areas[f];
        *e += k * d.value;
        if d.branch == Branch::Slack {
            return;
        }
        // ∂p/∂(e1, e2): p0 = e1·e1, p1 = e1·e2, p2 = e2·e2.
        let zero = [0.0; 3];
        let dp: [[[f64; 3]; 2]; 3] = [[scale(e1, 2.0), zero], [e2, e1], [zero, scale(e2, 2.0)]];
        let mut ge = [[0.0; 3]; 2];
        let mut he = [[[[0.0; 3]; 3]; 2]; 2]; // he[i][j][a][b]: e_i component a, e_j comp. b
        for m in 0..3 {
            for i in 0..2 {
                for a in 0..3 {
                    ge[i][a] += k * d.grad[m] * dp[m][i][a];
                }
            }
            for n in 0..3 {
                let c = k * d.hess[m][n];
                for i in 0..2 {
                    for j in 0..2 {
                        for a in 0..3 {
                            for b in 0..3 {
                                he[i][j][a][b] += c * dp[m][i][a] * dp[n][j][b];
                            }
                        }
                    }
                }
            }
        }
        // Σ_m g_m ∇²p_m: ∇²p0 = 2I on (e1,e1), ∇²p1 = I on (e1,e2),(e2,e1), ∇²p2 = 2I on (e2,e2).
        #[allow(clippy::needless_range_loop)] // diagonal of four 3×3 blocks
        for a in 0..3 {
            he[0][0][a][a] += 2.0 * k * d.grad[0];
            he[0][1][a][a] += k * d.grad[1];
            he[1][0][a][a] += k * d.grad[1];
            he[1][1][a][a] += 2.0 * k * d.grad[2];
        }
        // e1 = x1 − x0, e2 = x2 − x0: coefficient of e_i in vertex v.
        const C: [[f64; 2]; 3] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
        for v in 0..3 {
            for a in 0..3 {
                g[3 * v + a] += C[v][0] * ge[0][a] + C[v][1] * ge[1][a];
                for w in 0..3 {
                    for b in 0..3 {
                        let mut s = 0.0;
                        for i in 0..2 {
                            for j in 0..2 {
                                s += C[v][i] * C[w][j] * he[i][j][a][b];
                            }
                        }
                        h[3 * v + a][3 * w + b] += s;
                    }
                }
            }
        }
    }

    /// Adds `−p x0·(x1×x2)/6` of face `f` with its gradient and (projected) Hessian; when the
    /// Hessian is projected and `delta` is `Some`, stores `exact − projected` there.
    #[allow(clippy::too_many_arguments)]
    fn pressure_face(
        &self,
        f: usize,
        x: &[f64],
        exact: bool,
        e: &mut f64,
        g: &mut [f64; 9],
        h: &mut Block9,
        (delta, unprojected): (&mut Option<Block9>, bool),
    ) {
        let p = self.triangles[f].map(|v| vec3(x, v));
        let k = -self.pressure / 6.0;
        *e += k * dot(p[0], cross(p[1], p[2]));
        let gv = [cross(p[1], p[2]), cross(p[2], p[0]), cross(p[0], p[1])];
        for v in 0..3 {
            for a in 0..3 {
                g[3 * v + a] += k * gv[v][a];
            }
        }
        // ∂²V/∂x_v∂x_w = ε-contraction with the third vertex u: skew(x_u) with sign of (v,w,u).
        let mut hp = [[0.0; 9]; 9];
        for (v, w, u) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
            // ∂(x_v-gradient)/∂x_w = ∂(x_w × x_u)/∂x_w = −skew(x_u)
            let s = skew(p[u]);
            for a in 0..3 {
                for b in 0..3 {
                    hp[3 * v + a][3 * w + b] = -k * s[a][b];
                    hp[3 * w + b][3 * v + a] = -k * s[a][b];
                }
            }
        }
        if let (Some(d), true, false) = (delta.as_mut(), unprojected, exact) {
            *d = hp;
            return;
        }
        if !exact {
            let before = hp;
            project_psd(&mut hp);
            if let Some(d) = delta {
                for a in 0..9 {
                    for b in 0..9 {
                        d[a][b] = before[a][b] - hp[a][b];
                    }
                }
            }
        }
        for a in 0..9 {
            for b in 0..9 {
                h[a][b] += hp[a][b];
            }
        }
    }
}

/// Minimizes the base energy of `model` (module docs), applying the Dirichlet motions in
/// `options.load_steps` increments. `progress` may cancel ([`Error::Cancelled`]). Errors
/// ([`Error::InvalidArgument`]) on `load_steps == 0` or a non-finite or negative
/// `bending_scale`; numerical trouble is a [`BaseStatus`], not an error.
pub fn solve_base(
    model: &Model,
    options: &BaseOptions,
    progress: &mut ProgressFn<'_>,
) -> Result<BaseResult> {
    if options.load_steps == 0 {
        return Err(Error::InvalidArgument(
            "tfw: load_steps must be >= 1".into(),
        ));
    }
    if !(options.bending_scale >= 0.0 && options.bending_scale.is_finite()) {
        return Err(Error::InvalidArgument(
            "tfw: bending_scale must be finite and >= 0".into(),
        ));
    }
    let start = Instant::now();
    let problem = BaseProblem::new(model, options.bending_scale);
    let n = model.positions.len();
    let mut x: Vec<f64> = model.positions.iter().flatten().copied().collect();
    let mut free = vec![true; 3 * n];
    for &(v, _) in &model.clamps {
        for d in 0..3 {
            free[3 * v as usize + d] = false;
        }
    }
    let mut reduced = vec![usize::MAX; 3 * n];
    let mut nf = 0;
    for (i, r) in reduced.iter_mut().enumerate() {
        if free[i] {
            *r = nf;
            nf += 1;
        }
    }
    let mut warnings = model.warnings.clone();
    let mut history = Vec::new();
    let mut status = BaseStatus::Converged;
    let mut relative_gradient = 0.0;
    let mut analysis: Option<CholeskyAnalysis> = None;
    let mut hessian_plan: Option<ReducedAssembly> = None;
    let mut correction_plan: Option<ReducedAssembly> = None;
    let mut last_shift = 0.0;
    let step_cap = obstacle_step_cap(model);
    // The CG refinement (exact Newton steps) where the Newton matrix is not the Hessian:
    // with pressure; then the pressure Hessian enters only the CG operator, not the
    // preconditioner (no per-face PSD projection).
    let cg_iterations = if model.pressure != 0.0 {
        options.cg_iterations
    } else {
        0
    };
    let unprojected = cg_iterations > 0;
    // the second-order correction, where the Newton matrix is the Hessian (no pressure)
    let second_order = options.second_order_correction && cg_iterations == 0;
    for step in 1..=options.load_steps {
        let s = step as f64 / options.load_steps as f64;
        for &(v, m) in &model.clamps {
            let q = m.apply(model.positions[v as usize], s);
            x[3 * v as usize..3 * v as usize + 3].copy_from_slice(&q);
        }
        if nf == 0 {
            break;
        }
        let mut g0 = 0.0;
        status = BaseStatus::MaxIterations;
        for it in 0..options.max_iterations {
            let fraction = ((step - 1) as f64 + it as f64 / options.max_iterations as f64)
                / options.load_steps as f64;
            if !progress(Progress {
                stage: "tfw base surface",
                fraction,
            }) {
                return Err(Error::Cancelled);
            }
            let mut times = NewtonTimes::default();
            let clock = Instant::now();
            let (ev, correction) =
                problem.evaluate_split(&x, Terms::ALL, false, cg_iterations > 0, unprojected);
            times.evaluate = clock.elapsed().as_secs_f64();
            let g: Vec<f64> = (0..3 * n)
                .filter(|&i| free[i])
                .map(|i| ev.gradient[i])
                .collect();
            let gn = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if !gn.is_finite() || !ev.energy.is_finite() {
                return Err(Error::Numerical(
                    "tfw base surface: non-finite energy or gradient".into(),
                ));
            }
            if it == 0 {
                g0 = gn;
            }
            relative_gradient = if g0 > 0.0 { gn / g0 } else { 0.0 };
            if gn == 0.0 || gn <= options.gradient_tolerance * g0 {
                status = BaseStatus::Converged;
                break;
            }
            let clock = Instant::now();
            let (h, diag_sum) =
                ReducedAssembly::assemble(&mut hessian_plan, &ev.hessian, &reduced, nf)?;
            let exact_part = if correction.is_empty() {
                None
            } else {
                Some(ReducedAssembly::assemble(&mut correction_plan, &correction, &reduced, nf)?.0)
            };
            if analysis.is_none() {
                analysis = Some(CholeskyAnalysis::new(&h)?);
            }
            let an = analysis.as_ref().expect("set above");
            let diag_scale = (diag_sum / nf as f64).max(f64::MIN_POSITIVE);
            times.assemble = clock.elapsed().as_secs_f64();
            let schedule = ShiftSchedule {
                initial: (1e-10 * diag_scale).max(0.1 * last_shift),
                growth: 10.0,
                max_attempts: 24,
            };
            let weights = vec![1.0; nf];
            let clock = Instant::now();
            let factored =
                an.factor_with_growing_shift(&h, &weights, schedule, Parallelism::Global);
            times.factor = clock.elapsed().as_secs_f64();
            let Ok(ch) = factored else {
                status = BaseStatus::FactorizationFailed;
                break;
            };
            let shift = ch.info().shift;
            times.factor_attempts = ch.info().attempts;
            let clock = Instant::now();
            let (mut d, cg) = newton_step(&ch, &h, exact_part.as_ref(), &g, cg_iterations);
            times.cg_iterations = cg;
            times.solve = clock.elapsed().as_secs_f64();
            last_shift = shift;
            let mut slope: f64 = g.iter().zip(&d).map(|(a, b)| a * b).sum();
            let mut gradient_step = false;
            let descent = slope < 0.0 && d.iter().all(|v: &f64| v.is_finite());
            if !descent {
                d = g.iter().map(|v| -v / diag_scale).collect();
                slope = g.iter().zip(&d).map(|(a, b)| a * b).sum();
                gradient_step = true;
            }
            if let Some(cap) = step_cap {
                let scale = cap / max_vertex_move(&d, &reduced, n).max(f64::MIN_POSITIVE);
                if scale < 1.0 {
                    d.iter_mut().for_each(|v| *v *= scale);
                    slope *= scale;
                }
            }
            // Armijo backtracking (c = 0.2, ρ = 0.5; spec step 2).
            let clock = Instant::now();
            let slack = 4.0 * f64::EPSILON * ev.energy.abs();
            let mut t = 1.0;
            let mut trial = x.clone();
            let mut corrected_energy = None;
            if second_order {
                let s = corrected_step(&problem, &ch, &x, &d, &free, &reduced);
                set_trial(&mut trial, &x, 1.0, &s, &free, &reduced);
                let e = problem.energy(&trial, Terms::ALL);
                times.line_search_evaluations += 1;
                if e.is_finite() && e <= ev.energy + 0.2 * slope + slack {
                    corrected_energy = Some(e);
                    d = s;
                }
            }
            let corrected = corrected_energy.is_some();
            let accepted = if corrected {
                corrected_energy
            } else {
                loop {
                    set_trial(&mut trial, &x, t, &d, &free, &reduced);
                    let e = problem.energy(&trial, Terms::ALL);
                    times.line_search_evaluations += 1;
                    if e.is_finite() && e <= ev.energy + 0.2 * t * slope + slack {
                        break Some(e);
                    }
                    if t == 1.0 && e.is_finite() && -slope <= 64.0 * f64::EPSILON * ev.energy.abs()
                    {
                        // the predicted decrease is below the rounding of E: the energy cannot
                        // judge the step, the gradient can (a full Newton step near the optimum)
                        let g_trial = problem.evaluate_split(&trial, Terms::ALL, false, true, true);
                        if free_norm(&g_trial.0.gradient, &free) < gn {
                            break Some(e);
                        }
                    }
                    t *= 0.5;
                    if t < 1e-12 {
                        break None;
                    }
                }
            };
            times.line_search = clock.elapsed().as_secs_f64();
            let Some(e_new) = accepted else {
                status = BaseStatus::LineSearchFailed;
                break;
            };
            let step_norm = d.iter().fold(0.0f64, |m, v| m.max((t * v).abs()));
            let branch_changes = count_changes(&problem.branches(&x), &problem.branches(&trial));
            x = trial;
            history.push(NewtonIteration {
                load_step: step,
                energy: e_new,
                gradient_norm: gn,
                step: t,
                step_norm,
                shift,
                gradient_step,
                corrected,
                branch_changes,
                seconds: start.elapsed().as_secs_f64(),
                times,
            });
            // with the correction, a backtracked step's small E change says nothing about
            // the rounding floor (the valley crawl of the sheared rectangle): only full steps
            // may stop the solve here
            let judged = t == 1.0 || !second_order;
            if judged && (ev.energy - e_new).abs() <= options.energy_tolerance * ev.energy.abs() {
                // one more gradient check decides between Converged and EnergyStalled
                let g_new = problem.evaluate_split(&x, Terms::ALL, false, true, true);
                let gn_new = free_norm(&g_new.0.gradient, &free);
                relative_gradient = if g0 > 0.0 { gn_new / g0 } else { 0.0 };
                if gn_new <= options.gradient_tolerance * g0 {
                    status = BaseStatus::Converged;
                    break;
                }
                // a Newton step that still halved the gradient is progress E cannot show
                if gn_new > 0.5 * gn {
                    status = BaseStatus::EnergyStalled;
                    break;
                }
            }
        }
    }
    let strain = problem.strain_summary(&x);
    if strain.slack_area_fraction > 0.5 {
        warnings.push(format!(
            "{:.0}% of the rest area is compressed in every direction: the problem is not \
             tension-dominated (out of scope, S:588); the base surface is best effort",
            100.0 * strain.slack_area_fraction
        ));
    }
    if strain.degenerate_faces > 0 {
        warnings.push(format!(
            "{} base faces are collapsed (det I ≤ 1e-12 det Ī)",
            strain.degenerate_faces
        ));
    }
    let positions: Vec<[f64; 3]> = x.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let energies = problem.term_energies(&x);
    Ok(BaseResult {
        mesh: TriMesh::new(positions, model.triangles.clone())?,
        status,
        history,
        energies,
        relative_gradient,
        strain,
        warnings,
    })
}

/// The free-DOF matrix of a `(row, col, value)` list in the full `3n` numbering (entries
/// touching a clamped coordinate dropped, a zero diagonal entry per free coordinate appended,
/// duplicates summed), assembled through a fixed pattern: the sort that orders the entries
/// is made once ([`AssemblyPlan`]) and reused while the list's indices stay the same (they
/// depend only on the mesh, except for obstacle contacts, which re-plan). The same matrix,
/// bit for bit, as `assemble` of the reduced triplets (the plan sums duplicates in the same
/// order), and the same `Σ|diagonal entries|` in list order.
struct ReducedAssembly {
    /// The list's `(row, col)` indices the plan was made for.
    indices: Vec<(usize, usize)>,
    /// Per list entry, its position among the reduced entries (`usize::MAX`: dropped).
    slots: Vec<usize>,
    /// Per reduced entry, whether it is on the diagonal.
    diagonal: Vec<bool>,
    plan: AssemblyPlan,
}

impl ReducedAssembly {
    /// The reduced matrix of `list` (`reduced[i]`: the free index of coordinate `i`, or
    /// `usize::MAX` when clamped) and the sum of the absolute diagonal entries in list order;
    /// `cache` holds the plan between calls.
    fn assemble(
        cache: &mut Option<ReducedAssembly>,
        list: &[(usize, usize, f64)],
        reduced: &[usize],
        nf: usize,
    ) -> Result<(SparseMatrix, f64)> {
        let same = cache.as_ref().is_some_and(|p| {
            p.indices.len() == list.len()
                && p.indices
                    .iter()
                    .zip(list)
                    .all(|(&(r, c), &(lr, lc, _))| r == lr && c == lc)
        });
        if !same {
            *cache = Some(ReducedAssembly::new(list, reduced, nf)?);
        }
        let plan = cache.as_ref().expect("made above");
        let mut values = vec![0.0; plan.diagonal.len()];
        for (&slot, &(_, _, v)) in plan.slots.iter().zip(list) {
            if slot != usize::MAX {
                values[slot] = v;
            }
        }
        let mut diag_sum = 0.0;
        for (v, &d) in values.iter().zip(&plan.diagonal) {
            if d {
                diag_sum += v.abs();
            }
        }
        Ok((plan.plan.assemble(&values)?, diag_sum))
    }

    fn new(list: &[(usize, usize, f64)], reduced: &[usize], nf: usize) -> Result<Self> {
        let mut slots = Vec::with_capacity(list.len());
        let mut entries = Vec::with_capacity(list.len() + nf);
        for &(r, c, _) in list {
            let (i, j) = (reduced[r], reduced[c]);
            if i == usize::MAX || j == usize::MAX {
                slots.push(usize::MAX);
            } else {
                slots.push(entries.len());
                entries.push(Entry::new(i, j, 0.0));
            }
        }
        entries.extend((0..nf).map(|i| Entry::new(i, i, 0.0)));
        Ok(ReducedAssembly {
            indices: list.iter().map(|&(r, c, _)| (r, c)).collect(),
            slots,
            diagonal: entries.iter().map(|e| e.row == e.col).collect(),
            plan: AssemblyPlan::new(nf, &entries, "tfw base Hessian")?,
        })
    }
}

/// The second-order-corrected Newton step `s = d − M⁻¹g(x + d)` (reduced numbering): one
/// simplified-Newton iteration from the full step `x + d` with the factorization `ch` of this
/// iteration's Newton matrix M (no new factorization: one gradient evaluation and one pair of
/// triangular solves). Where the Newton step leaves a curved valley of E (a wrinkled face at
/// `λ1 ≈ 0` beside slack faces, the sheared rectangle: module docs), the correction brings the
/// stiff components back into it, so the full step's second-order error no longer forces the
/// line search to cut it.
fn corrected_step(
    problem: &BaseProblem,
    ch: &Cholesky,
    x: &[f64],
    d: &[f64],
    free: &[bool],
    reduced: &[usize],
) -> Vec<f64> {
    let mut y = x.to_vec();
    set_trial(&mut y, x, 1.0, d, free, reduced);
    let full = problem
        .evaluate_split(&y, Terms::ALL, false, true, true)
        .0
        .gradient;
    let g: Vec<f64> = full
        .iter()
        .zip(free)
        .filter(|(_, &f)| f)
        .map(|(v, _)| *v)
        .collect();
    let c = ch.solve(&g);
    d.iter().zip(&c).map(|(a, b)| a - b).collect()
}

/// `trial = x + t·d` on the free coordinates (`d` in the reduced numbering).
fn set_trial(trial: &mut [f64], x: &[f64], t: f64, d: &[f64], free: &[bool], reduced: &[usize]) {
    for i in 0..x.len() {
        if free[i] {
            trial[i] = x[i] + t * d[reduced[i]];
        }
    }
}

/// How many entries of `a` and `b` differ.
fn count_changes(a: &[Branch], b: &[Branch]) -> usize {
    a.iter().zip(b).filter(|(p, q)| p != q).count()
}

/// `‖g‖∞` over the free coordinates.
fn free_norm(g: &[f64], free: &[bool]) -> f64 {
    g.iter()
        .zip(free)
        .filter(|(_, &f)| f)
        .fold(0.0f64, |m, (v, _)| m.max(v.abs()))
}

/// The Newton step `d ≈ −H⁻¹g` and the CG iterations spent. `ch` factors the Newton matrix
/// `H_p` (pressure blocks projected, or left out) plus the shift σI; `h` is `H_p` and
/// `exact_part` (when there is pressure) the rest of the exact Hessian. Without CG
/// (`cg_iterations == 0`) the shifted step `−(H_p + σI)⁻¹g`. With CG, Steihaug–Toint CG on
/// the unshifted exact Hessian preconditioned by `ch`: its first iterate is the shifted step
/// at its best length, later ones resolve the pressure part and the directions where the
/// shift dominates `H` (a free surface's rigid motions): exact Newton steps near the
/// optimum. The region `‖s‖_M ≤ 10³ ‖s₀‖_M` bounds the step along negative or
/// rounding-level curvature; the line search does the rest. CG stops at
/// `‖H s + g‖₂ ≤ 10⁻³ ‖g‖₂`. (On the sheared rectangle, without pressure, CG to 10⁻⁸
/// changed nothing: the shifted step already solves the model; its slow tail was the
/// model's second-order error, fixed by `corrected_step`, module docs.)
fn newton_step(
    ch: &Cholesky,
    h: &SparseMatrix,
    exact_part: Option<&SparseMatrix>,
    g: &[f64],
    cg_iterations: usize,
) -> (Vec<f64>, usize) {
    let d0: Vec<f64> = ch.solve(g).into_iter().map(|v| -v).collect();
    if cg_iterations == 0 {
        return (d0, 0);
    }
    let m_norm0 = (-dot_n(g, &d0)).max(0.0).sqrt(); // ‖s₀‖_M² = gᵀM⁻¹g
    let radius = 1e3;
    let z = std::cell::RefCell::new(vec![0.0; g.len()]);
    let hess = |v: &[f64], y: &mut [f64]| {
        sym_matvec_lower_into(h, v, y);
        if let Some(c) = exact_part {
            let mut z = z.borrow_mut();
            sym_matvec_lower_into(c, v, &mut z);
            y.iter_mut().zip(z.iter()).for_each(|(a, b)| *a += b);
        }
    };
    let precond = |r: &[f64]| ch.solve(r);
    let gnorm = dot_n(g, g).sqrt();
    let tol = 1e-3;
    let st = steihaug(
        g,
        &hess,
        &precond,
        radius * m_norm0,
        tol * gnorm,
        cg_iterations,
    );
    (st.step, st.iterations)
}

/// Rows of the cotan Laplacian of the rest pattern (weights from each face's own rest
/// corners), plus the Wang et al. 2015 free-boundary correction (spec "Energies"): for every
/// boundary edge (i, j) of face (i, j, k), rows i and j get `+½cot∠j` at i, `+½cot∠i` at j and
/// `−½(cot∠i + cot∠j)` at k.
fn corrected_laplacian(
    n: usize,
    tris: &[[u32; 3]],
    rest: &[[[f64; 2]; 3]],
) -> Vec<Vec<(u32, f64)>> {
    let mut entries: Vec<(u32, u32, f64)> = Vec::new();
    let mut edge_faces: std::collections::HashMap<(u32, u32), usize> = Default::default();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edge_faces.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    for (t, c) in tris.iter().zip(rest) {
        let cot = |k: usize| {
            let (p, q, r) = (c[k], c[(k + 1) % 3], c[(k + 2) % 3]);
            let u = [q[0] - p[0], q[1] - p[1]];
            let v = [r[0] - p[0], r[1] - p[1]];
            (u[0] * v[0] + u[1] * v[1]) / (u[0] * v[1] - u[1] * v[0]).abs()
        };
        let cots = [cot(0), cot(1), cot(2)];
        for k in 0..3 {
            // edge opposite corner k: (k+1, k+2)
            let (i, j) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            let w = 0.5 * cots[k];
            entries.extend([(i, j, w), (j, i, w), (i, i, -w), (j, j, -w)]);
        }
        for k in 0..3 {
            let (ci, cj, ck) = (k, (k + 1) % 3, (k + 2) % 3);
            let (i, j, o) = (t[ci], t[cj], t[ck]);
            if edge_faces[&(i.min(j), i.max(j))] != 1 {
                continue;
            }
            for r in [i, j] {
                entries.push((r, i, 0.5 * cots[cj]));
                entries.push((r, j, 0.5 * cots[ci]));
                entries.push((r, o, -0.5 * (cots[ci] + cots[cj])));
            }
        }
    }
    entries.sort_by_key(|a| (a.0, a.1));
    let mut rows = vec![Vec::new(); n];
    for (r, c, w) in entries {
        let row: &mut Vec<(u32, f64)> = &mut rows[r as usize];
        match row.last_mut() {
            Some(last) if last.0 == c => last.1 += w,
            _ => row.push((c, w)),
        }
    }
    rows
}

/// `K = Lᵀ diag(1/Ā) L`, lower triangle `(j, k, K_jk)`, `j ≥ k`, merged and sorted.
fn normal_matrix(n: usize, rows: &[Vec<(u32, f64)>], areas: &[f64]) -> Vec<(u32, u32, f64)> {
    let mut e: Vec<(u32, u32, f64)> = Vec::new();
    for (row, a) in rows.iter().zip(areas) {
        for &(j, wj) in row {
            for &(k, wk) in row {
                if j >= k {
                    e.push((j, k, wj * wk / a));
                }
            }
        }
    }
    e.sort_by_key(|a| (a.0, a.1));
    let mut out: Vec<(u32, u32, f64)> = Vec::with_capacity(e.len());
    for (j, k, v) in e {
        match out.last_mut() {
            Some(last) if last.0 == j && last.1 == k => last.2 += v,
            _ => out.push((j, k, v)),
        }
    }
    debug_assert!(out.iter().all(|&(j, _, _)| (j as usize) < n));
    out
}

/// With obstacles, the largest vertex displacement of one Newton step: a quarter of the
/// smallest sphere radius and of the initial bounding-box diagonal, so that no step can carry
/// a vertex through an obstacle (a free surface's rigid modes have a near-zero Hessian: its
/// first Newton steps are huge). `None` without obstacles (no cap: results unchanged).
fn obstacle_step_cap(model: &Model) -> Option<f64> {
    if model.obstacles.is_empty() {
        return None;
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &model.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let radius = model
        .obstacles
        .iter()
        .filter_map(|o| match o.shape {
            crate::tfw::scene::ObstacleShape::Sphere { radius, .. } => Some(radius),
            crate::tfw::scene::ObstacleShape::Plane { .. } => None,
        })
        .fold(diag, f64::min);
    Some(0.25 * radius)
}

/// The largest per-vertex displacement `|d_v|` of a reduced step `d` (free coordinates).
fn max_vertex_move(d: &[f64], reduced: &[usize], n: usize) -> f64 {
    (0..n)
        .map(|v| {
            (0..3)
                .map(|k| reduced[3 * v + k])
                .filter(|&r| r != usize::MAX)
                .map(|r| d[r] * d[r])
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
}

fn vec3(x: &[f64], v: u32) -> [f64; 3] {
    let i = 3 * v as usize;
    [x[i], x[i + 1], x[i + 2]]
}

/// `skew(v) w = v × w`.
fn skew(v: [f64; 3]) -> [[f64; 3]; 3] {
    [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]
}

/// `I = [e1·e1, e1·e2, e2·e2]` of a triangle (A.1).
fn first_form(p: [[f64; 3]; 3]) -> [f64; 3] {
    let (e1, e2) = (sub(p[1], p[0]), sub(p[2], p[0]));
    [dot(e1, e1), dot(e1, e2), dot(e2, e2)]
}
