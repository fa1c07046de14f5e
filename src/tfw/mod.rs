//! Wrinkles from physics: tension-field wrinkle statics (TFW, dissertation ch. 2, appendix A;
//! implementable spec `shared/specs/tfw.md`). Feature `tfw`.
//!
//! **Implemented (this first part):**
//! - [`scene`]: problem setup — flat panels with initial 3D positions, sewn by merging vertices
//!   within a tolerance (each face keeps its own rest form `Ī_f`, S:2029–2033); material
//!   (Young, Poisson → Lamé α, β by eq. A.3), thickness, density, gravity, pressure, Dirichlet
//!   conditions (clamped vertices with a prescribed translation and rotation about an axis);
//!   a JSON scene format whose errors name the bad field; built-in scenes: the stretched sheet
//!   (S:714) and the twisted cylinder (S:682).
//! - [`material`]: `‖M‖²_SV` (eq. 2.4), the relaxed membrane density `W̃` of A.2 with its exact
//!   gradient and Hessian in the first fundamental form.
//! - [`base`]: the base surface of §2.4.1 — tension-field membrane + quadratic bending (2.28)
//!   with the free-boundary correction + pressure + gravity, exact gradients and Hessians,
//!   Newton with Armijo line search on [`crate::solve`]'s sparse Cholesky (symbolic analysis
//!   reused), Dirichlet by elimination and load steps; a [`BaseStatus`] says why it stopped.
//! - [`wfree`]: per-face strain eigenpairs (2.29), the wrinkle-free faces W (text and
//!   reference rules), and the initialization (A.6.2: amplitudes, face one-forms, sign
//!   combing, vertex amplitudes, Helmholtz projection to a one-form on pleat's edges that is
//!   curl-free on every non-W face).
//!
//! - [`curvature`]: the normal curvature `κ_f` along each face's tension direction (eq. 2.22),
//!   by quadric fitting on 5 rings (default) or from vertex normals.
//! - [`delaunay`]: irregular Delaunay meshing of a polygon panel (holes allowed) to a target
//!   vertex count (A.6.1): boundary samples (equal samples on equal edges, so seams match),
//!   Poisson-disk interior, spade's constrained Delaunay triangulation. Scene files ask for
//!   it with a `polygon` panel and `target_vertices` ([`scene`]).
//! - [`energy`]: the wrinkle energy `E^wf` (2.20–2.27, 3-point rule of A.7) on vertex
//!   amplitudes and the edge one-form, with its exact gradient and sparse Hessian.
//! - [`sqp`]: the wrinkle SQP of A.6.3 (clarabel QP per iteration, `a ≥ 0`, `curl ω = 0` off W,
//!   convexified Hessian, Armijo line search, termination tests, per-iteration history);
//!   [`pnewton`]: the same SQP with the curl eliminated, projected Newton steps
//!   ([`QpMethod::ProjectedNewton`]), refined on the exact Hessian and followed by a search
//!   along the amplitude ↔ frequency valley `(a, ω) → (a/μ, μω)` near the optimum (the
//!   thin-shell case: thickness × 10⁻² converges in 13 / 14 iterations).
//! - [`pipeline`]: [`solve`] — scene → base → W, init → SQP → period snapping →
//!   [`crate::wrinkle::Cwf`] (Knöppel phase), with a report; the wrinkled mesh comes from [`crate::wrinkle::Cwf::evaluate`]
//!   with [`crate::wrinkle::EvalOptions::in_plane_v2`] (the v2 term of eq. 2.19).
//!
//! - [`pnewton`]: the SQP step by projected Newton with the curl constraint eliminated
//!   (exact part + tree–cotree cohomology basis; [`sqp::QpMethod::ProjectedNewton`]).
//! - [`measure`]: wave counts of an evaluated field along a plane section (ring or line).
//! - Obstacles: planes and spheres by a one-sided cubic penalty in the base energy
//!   ([`scene::Obstacle`], [`base`]).
//!
//! - [`snap`]: period snapping (spec step 8's pre-step, Risk 9) — between the SQP and the
//!   phase, the periods of ω around the base's non-contractible loops (cylinder ring, torus
//!   generators, panel holes) go to the nearest multiple of 2π by the least-squares harmonic
//!   correction; loops around W islands keep theirs ([`TfwParams::snap_periods`], off by
//!   default; reported in [`TfwResult::snap`]).
//!
//! **Departures from the spec, and why:**
//! - The built-in stretched sheet and [`Scene::twisted_cylinder`] use structured grids with
//!   alternating diagonals and jittered interior vertices (±20% of the spacing);
//!   [`Scene::twisted_cylinder_delaunay`] and `polygon` panels in scene files are irregular
//!   Delaunay meshes ([`delaunay`]), as the spec asks.
//! - Hessian regularization: instead of `reg·I` doubled from 1e-8, the crate's
//!   `factor_with_growing_shift` adds `σI` with σ from `1e-10·mean|H_ii|` (or a tenth of the
//!   last σ needed) growing ×10: relative to the Hessian's scale, so the same for SI and
//!   rescaled units. The TFT and bending Hessians are exact (PSD face by face); only the
//!   pressure blocks are projected, as the spec says.
//! - The energy-change stop is relative, `|ΔE| ≤ 1e-14|E|` by default (the spec's 1e-12 stops
//!   Newton before its quadratic phase reaches the 1e-8 gradient), and reports
//!   [`BaseStatus::EnergyStalled`] unless the gradient test also holds.
//! - The stretched sheet's stretch is not given by the dissertation: it is a parameter.
//! - Helmholtz projection: the method of multipliers on one Cholesky factorization instead of
//!   a KKT/LDLT solve (`crate::solve` has no indefinite factorization); same minimizer, the
//!   curl constraint met to rounding (see [`wfree`]). Regularization `1e-8·mean diag` instead of
//!   an absolute 1e-8, so it does not depend on units.
//! - Sign combing compares the faces' wave vectors embedded in 3D on the base surface (the
//!   transport between neighbouring faces is the base embedding).
//! - SQP: the per-face PSD projection is applied to each face's whole 5×5 block (all terms
//!   together: closer to the true Hessian than projecting stretching and bending separately);
//!   no switch to the true Hessian near the optimum; candidates are made exactly feasible
//!   after the QP (curl ≤ rounding); the QP is nondimensionalized and the stop tests are
//!   relative, so Young's modulus does not change the iterates ([`sqp`]).

pub mod base;
pub mod curvature;
pub mod delaunay;
mod dense;
pub mod energy;
pub mod material;
pub mod measure;
pub mod pipeline;
pub mod pnewton;
pub mod scene;
pub mod snap;
pub mod sqp;
pub mod wfree;

pub use base::{
    solve_base, BaseEval, BaseOptions, BaseProblem, BaseResult, BaseStatus, NewtonIteration,
    NewtonTimes, StrainSummary, TermEnergies, Terms,
};
pub use material::{Branch, Lame};
pub use pipeline::{solve, TfwParams, TfwResult, TfwSeconds, TfwStatus};
pub use scene::{
    Dirichlet, Material, Model, Motion, Obstacle, ObstacleShape, Panel, Rotation, Scene,
    DEFAULT_OBSTACLE_STIFFNESS,
};
pub use snap::{snap_periods, PeriodSnap, SnappedLoop};
pub use sqp::{CgRefinement, QpMethod, SqpIteration, SqpOptions, SqpResult, SqpStatus};
