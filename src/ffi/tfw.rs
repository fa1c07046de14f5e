//! Tension-field wrinkles in the C ABI (capability `tfw`, dissertation ch. 2; Rust API
//! [`crate::tfw::solve`]).
//!
//! - `PleatTfwScene`: a validated scene (panels, material, loads, Dirichlet conditions), from a
//!   JSON file ([`pleat_tfw_scene_read_file`]), a JSON string ([`pleat_tfw_scene_from_json`])
//!   or arrays describing one panel ([`pleat_tfw_scene_from_arrays`]).
//! - [`pleat_tfw_solve`]: base surface → wrinkle-free faces, initialization → SQP → a complex
//!   wrinkle field, as a `PleatTfwResult`.
//! - Getters: the base mesh and the wrinkle field as the existing `PleatMesh` / `PleatCwf`
//!   handles (so `pleat_mesh_*` copies them out and `pleat_cwf_*` evaluates them), the
//!   wrinkled mesh ([`pleat_tfw_result_evaluate`], with the in-plane v2 term of eq. 2.19),
//!   stats ([`PleatTfwStats`]) and the SQP iteration history.
//!
//! Every function exists in every build; without `tfw` those that can fail return
//! `PLEAT_STATUS_UNSUPPORTED` (counts return 0).

#![allow(clippy::too_many_arguments)]
// Builds without `tfw` compile only the UNSUPPORTED branches.
#![cfg_attr(not(feature = "tfw"), allow(unused_imports))]

use super::boundary::{destroy, full_size, guard_value, requires, versioned};
use super::common::{guard, PleatProgressFn, PleatStatus};
use super::mesh::PleatMesh;
use super::wrinkle::{PleatCwf, PleatWrinkleEvalParams};

/// Runs `$body` when built with `tfw`; otherwise `PLEAT_STATUS_UNSUPPORTED`.
macro_rules! tfw_only {
    ([$($arg:expr),*] $body:expr) => {
        requires!("tfw", [$($arg),*], $body)
    };
}

// ---------------------------------------------------------------------------------------------
// Constants

/// `PleatTfwStats::status`: the base solve and the SQP both met a convergence test.
pub const PLEAT_TFW_STATUS_CONVERGED: u32 = 0;
/// `PleatTfwStats::status`: a result was produced, but the base solve or the SQP stopped
/// before converging (see `base_status`, `sqp_status`).
pub const PLEAT_TFW_STATUS_NOT_CONVERGED: u32 = 1;
/// `PleatTfwStats::status`: no compression anywhere: amplitude ≡ 0, returned at once.
pub const PLEAT_TFW_STATUS_NO_COMPRESSION: u32 = 2;
/// `PleatTfwStats::status`: compressed in every direction over most of the surface: out of
/// the model's scope; the best-effort base surface with amplitude ≡ 0.
pub const PLEAT_TFW_STATUS_OUT_OF_SCOPE: u32 = 3;

/// `PleatTfwParams::w_rule`: the dissertation's rule for the wrinkle-free faces (default).
pub const PLEAT_TFW_W_RULE_TEXT: u32 = 0;
/// `PleatTfwParams::w_rule`: the reference code's rule (`λ_c ≥ 0`, then vertex fill).
pub const PLEAT_TFW_W_RULE_REFERENCE: u32 = 1;

/// `PleatTfwParams::curvature`: `κ_f` by quadric fitting on the 5-ring (the default; spec and
/// reference code, S:2276).
pub const PLEAT_TFW_CURVATURE_QUADRIC_FIT: u32 = 0;
/// `PleatTfwParams::curvature`: `κ_f` per face from area-weighted vertex normals.
pub const PLEAT_TFW_CURVATURE_VERTEX_NORMALS: u32 = 1;
/// `PleatTfwParams::qp`: each SQP step is a QP with the curl constraint, solved by clarabel
/// (interior point).
pub const PLEAT_TFW_QP_CLARABEL: u32 = 0;
/// `PleatTfwParams::qp`: the curl constraint eliminated (tree–cotree basis), each step a
/// projected Newton step on `a ≥ 0` with a sparse Cholesky.
pub const PLEAT_TFW_QP_PROJECTED_NEWTON: u32 = 1;

/// `PleatTfwObstacle::kind`: the half-space behind a plane (the surface stays on the side the
/// normal points to).
pub const PLEAT_TFW_OBSTACLE_PLANE: u32 = 0;
/// `PleatTfwObstacle::kind`: a solid ball (the surface stays outside).
pub const PLEAT_TFW_OBSTACLE_SPHERE: u32 = 1;

/// Doubles per iteration written by `pleat_tfw_result_copy_history`: energy (J), stationarity
/// residual (absolute), step `‖Δx‖∞`, wall seconds since the SQP started.
pub const PLEAT_TFW_HISTORY_COLUMNS: u32 = 4;

// ---------------------------------------------------------------------------------------------
// Handles and structs

/// A validated TFW scene (opaque): panels, material, loads, Dirichlet conditions. Created by
/// `pleat_tfw_scene_read_file`, `pleat_tfw_scene_from_json` or `pleat_tfw_scene_from_arrays`;
/// destroyed by `pleat_tfw_scene_destroy`. Immutable: may be solved from several threads.
pub struct PleatTfwScene {
    #[cfg(feature = "tfw")]
    scene: crate::tfw::Scene,
}

/// The result of `pleat_tfw_solve` (opaque): base surface, wrinkle field, stats and history.
/// Destroyed by `pleat_tfw_result_destroy`. Immutable.
pub struct PleatTfwResult {
    #[cfg(feature = "tfw")]
    result: crate::tfw::TfwResult,
}

/// Parameters of `pleat_tfw_solve`. Get the defaults from `pleat_tfw_params_default()`;
/// `struct_size` must stay `sizeof(PleatTfwParams)` (an older, shorter struct is accepted:
/// missing fields take their defaults).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatTfwParams {
    /// `sizeof(PleatTfwParams)`; at least 8.
    pub struct_size: u32,
    /// SQP iteration limit, 1 to 1,000,000; default 1000 (A.6.3).
    pub sqp_max_iterations: u32,
    /// Newton iterations of the base solve per load step, 1 to 1,000,000; default 200.
    pub base_max_iterations: u32,
    /// Load steps of the Dirichlet motions, 1 to 10,000; default 1.
    pub base_load_steps: u32,
    /// `PLEAT_TFW_W_RULE_TEXT` (default) or `PLEAT_TFW_W_RULE_REFERENCE`.
    pub w_rule: u32,
    /// Reserved, set to 0.
    pub reserved: u32,
    /// Base solve: stop when the relative gradient is at most this; finite, > 0; default 1e-8.
    pub base_gradient_tolerance: f64,
    /// Base solve: stop when a step changes E by at most this times |E|; finite, ≥ 0;
    /// default 1e-14.
    pub base_energy_tolerance: f64,
    /// Multiplier of the bending coefficient `α h³/24`; finite, ≥ 0; default 1.
    pub bending_scale: f64,
    /// Initial peak amplitude `k` of A.6.2 (m); 0 = automatic (`min(0.01 m, 0.1 · bbox
    /// diagonal)`, the default); else finite, > 0.
    pub initial_amplitude: f64,
    /// SQP: stop when `r ≤ tol · r₀`; finite, ≥ 0; default 1e-6.
    pub sqp_stationarity_tolerance: f64,
    /// SQP: stop when a step changes E by at most this times |E|; finite, ≥ 0; default 1e-10.
    pub sqp_energy_tolerance: f64,
    /// SQP: stop when the scaled step is at most this; finite, ≥ 0; default 1e-10.
    pub sqp_step_tolerance: f64,
    /// SQP Armijo constant, in (0, 1); default 0.2.
    pub sqp_armijo: f64,
    /// SQP initial relative Hessian shift; finite, > 0; default 1e-6.
    pub sqp_initial_shift: f64,
    /// SQP wall-time budget in seconds; 0 = unlimited (default); else finite, > 0.
    pub sqp_time_limit_seconds: f64,
    /// Rest-area fraction of slack faces above which the scene is out of scope, in [0, 1];
    /// default 0.5.
    pub out_of_scope_slack_fraction: f64,
    /// How the curvature along the tension direction is estimated:
    /// `PLEAT_TFW_CURVATURE_QUADRIC_FIT` (default) or `PLEAT_TFW_CURVATURE_VERTEX_NORMALS`.
    /// Appended 2026-11-27: a shorter struct (without it) gets the default.
    pub curvature: u32,
    /// Reserved, set to 0.
    pub reserved2: u32,
    /// The SQP step solver: `PLEAT_TFW_QP_CLARABEL` or `PLEAT_TFW_QP_PROJECTED_NEWTON`
    /// (the default is `pleat_tfw_params_default()`'s). Appended 2026-11-27: a shorter
    /// struct (without it) gets the default.
    pub qp: u32,
    /// Reserved, set to 0.
    pub reserved3: u32,
    /// 1: snap the periods of ω around the base's non-contractible loops (a cylinder's ring,
    /// a torus's generators) to multiples of 2π before the phase, so ω agrees with the
    /// phase's integer winding there (E^wf leaves the SQP's minimum: +1.25% on the 690-v
    /// twisted cylinder); 0 (default): off, the SQP's ω as it is. Appended 2026-11-29: a
    /// shorter struct (without it) gets the default.
    pub snap_periods: u32,
    /// Reserved, set to 0.
    pub reserved4: u32,
    /// 1 (default): the projected-Newton SQP's valley search near the optimum (a 1-D search
    /// along (a, ω) → (a/μ, μω), README "Thickness × 10⁻²"; what makes thin shells converge);
    /// 0: off, the plain projected Newton. Appended 2026-11-29: a shorter struct (without it)
    /// gets the default.
    pub valley_search: u32,
    /// Reserved, set to 0.
    pub reserved5: u32,
}

/// Material and loads of `pleat_tfw_scene_from_arrays` (SI units). Get the defaults from
/// `pleat_tfw_material_default()`; versioned like `PleatTfwParams`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatTfwMaterial {
    /// `sizeof(PleatTfwMaterial)`; at least 16.
    pub struct_size: u32,
    /// Reserved, set to 0.
    pub reserved: u32,
    /// Young's modulus (Pa), > 0; default 1e6.
    pub young: f64,
    /// Poisson's ratio, in (−1, 1); default 0.5.
    pub poisson: f64,
    /// Thickness (m), > 0; default 1e-4.
    pub thickness: f64,
    /// Density (kg/m³), ≥ 0; default 0.
    pub density: f64,
    /// Gravity acceleration (m/s²); default 0.
    pub gravity: [f64; 3],
    /// Internal pressure (Pa); default 0.
    pub pressure: f64,
}

/// What `pleat_tfw_solve` did (`pleat_tfw_result_get_stats`). Set `struct_size =
/// sizeof(PleatTfwStats)` before the call; pleat fills at most that many bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatTfwStats {
    /// In: `sizeof(PleatTfwStats)` as the caller knows it (≥ 8). Out: bytes filled.
    pub struct_size: u32,
    /// `PLEAT_TFW_STATUS_*`.
    pub status: u32,
    /// Why the base solve stopped: 0 converged, 1 energy stalled (at its rounding floor),
    /// 2 iteration limit, 3 line search failed, 4 factorization failed.
    pub base_status: u32,
    /// Why the SQP stopped: 0 stationary, 1 energy converged, 2 step converged, 3 iteration
    /// limit, 4 time limit, 5 line search failed, 6 QP failed, 7 no free unknowns, 8 did not
    /// run (no compression or out of scope).
    pub sqp_status: u32,
    /// Newton iterations of the base solve (all load steps).
    pub base_iterations: u32,
    /// SQP iterations (the length of the history).
    pub sqp_iterations: u32,
    /// Vertices of the base mesh.
    pub vertex_count: u64,
    /// Triangles of the base mesh.
    pub triangle_count: u64,
    /// Wrinkle-free faces (W).
    pub wrinkle_free_face_count: u64,
    /// `E^wf` at the result (J).
    pub energy: f64,
    /// `E^wf` at the start of the SQP (J); equals `energy` when the SQP did not run.
    pub initial_energy: f64,
    /// Stationarity residual at the end of the SQP (absolute); 0 when it did not run.
    pub residual: f64,
    /// Stationarity residual at the start of the SQP; 0 when it did not run.
    pub initial_residual: f64,
    /// `max |curl ω|` over the faces outside W at the result.
    pub curl_residual: f64,
    /// Largest vertex amplitude (m).
    pub peak_amplitude: f64,
    /// `‖g‖∞ / ‖g₀‖∞` of the base solve at the result.
    pub base_relative_gradient: f64,
    /// Wall seconds of the base solve.
    pub seconds_base: f64,
    /// Wall seconds of strains, W, curvature, initialization and Helmholtz projection.
    pub seconds_init: f64,
    /// Wall seconds of the SQP.
    pub seconds_sqp: f64,
    /// Wall seconds of the SQP spent in the QP solver.
    pub seconds_qp: f64,
    /// Wall seconds of the Knöppel phase.
    pub seconds_phase: f64,
    /// Loops whose period of ω was snapped to a multiple of 2π (`snap_periods`; 0 when off
    /// or none). Appended 2026-11-29, like every field below.
    pub snapped_loops: u32,
    /// Independent loops around wrinkle-free islands whose periods were kept.
    pub snap_kept_loops: u32,
    /// Largest `|period − 2π·waves|` over the snapped loops after snapping (rad); 0 when none.
    pub snap_max_period_error: f64,
    /// `max_e |δω_e|` of the snapping correction (rad); 0 when none.
    pub snap_max_correction: f64,
    /// `‖δω‖ / ‖ω‖` of the snapping correction (rest metric over the faces outside W); 0
    /// when none.
    pub snap_relative_correction: f64,
    /// The SQP iteration at which a step without decrease was retried with raised weights
    /// and kept them (README "SQP rescue"); −1 when no rescue was needed.
    pub sqp_rescue_iteration: i64,
}

/// A rigid obstacle of the base solve (`pleat_tfw_scene_add_obstacle`; the scene file's
/// `obstacles` entries): every vertex closer than `margin` to its surface pays the one-sided
/// cubic penalty `k Ā_i (margin − d_i)³`. Start from `pleat_tfw_obstacle_default()`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatTfwObstacle {
    /// `sizeof(PleatTfwObstacle)` as the caller knows it (≥ 8).
    pub struct_size: u32,
    /// `PLEAT_TFW_OBSTACLE_PLANE` or `PLEAT_TFW_OBSTACLE_SPHERE`; default plane.
    pub kind: u32,
    /// A point of the plane, or the sphere's centre (m); finite; default the origin.
    pub point: [f64; 3],
    /// The plane's normal, pointing to the allowed side (nonzero, any length; default +z);
    /// ignored for a sphere.
    pub normal: [f64; 3],
    /// The sphere's radius (m, > 0); ignored for a plane; default 0 (must be set for a sphere).
    pub radius: f64,
    /// Penalty stiffness (J/m⁵, > 0); default 1e9 (`DEFAULT_OBSTACLE_STIFFNESS`: a surface
    /// under a normal load q sinks in about `√(q/3k)`).
    pub stiffness: f64,
    /// Distance from the surface where the penalty starts (m, ≥ 0); default 0.
    pub margin: f64,
}

/// A wave count on the evaluated wrinkled surface (`pleat_tfw_result_count_waves`). Set
/// `struct_size = sizeof(PleatTfwWaveCount)` before the call; pleat fills at most that many
/// bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatTfwWaveCount {
    /// In: `sizeof(PleatTfwWaveCount)` as the caller knows it (≥ 8). Out: bytes filled.
    pub struct_size: u32,
    /// 1 when the section was counted as a closed ring (last and first samples compared).
    pub closed: u32,
    /// Waves: sign changes of `Re z` along the section / 2 (a half-integer on open lines).
    pub waves: f64,
    /// Peak `|Re z|` on the section (m): the wrinkle amplitude there.
    pub peak_amplitude: f64,
    /// Samples (edge crossings) on the section.
    pub samples: u64,
    /// A point of the section plane (m): the caller's, or the automatic choice.
    pub point: [f64; 3],
    /// The section plane's normal: the caller's, or the automatic choice.
    pub normal: [f64; 3],
    /// In (appended 2026-11-27; read only when `struct_size` covers it, else 0): samples
    /// closer than this (m, finite, ≥ 0) to the line through the section point along the
    /// normal are dropped — e.g. `0.5 ×` the outer radius keeps a balloon's outer half of its
    /// equator; 0 keeps all. Out: the value used.
    pub min_radius: f64,
}

versioned!(PleatTfwParams, 8, pleat_tfw_params_default);
versioned!(PleatTfwObstacle, 8, pleat_tfw_obstacle_default);
versioned!(PleatTfwWaveCount, 8);
versioned!(PleatTfwMaterial, 16, pleat_tfw_material_default);
versioned!(PleatTfwStats, 8);

/// The default solve parameters (those of the Rust `TfwParams::default()`), with
/// `struct_size` set. Available in every build.
#[no_mangle]
pub extern "C" fn pleat_tfw_params_default() -> PleatTfwParams {
    #[cfg(feature = "tfw")]
    return PleatTfwParams::from(&crate::tfw::TfwParams::default());
    #[cfg(not(feature = "tfw"))]
    return defaults_without_tfw();
}

/// The default material: Young 1 MPa, Poisson 0.5, thickness 0.1 mm, density 0, no gravity,
/// no pressure (the stretched sheet's), with `struct_size` set. Available in every build.
#[no_mangle]
pub extern "C" fn pleat_tfw_material_default() -> PleatTfwMaterial {
    PleatTfwMaterial {
        struct_size: full_size::<PleatTfwMaterial>(),
        reserved: 0,
        young: 1e6,
        poisson: 0.5,
        thickness: 1e-4,
        density: 0.0,
        gravity: [0.0; 3],
        pressure: 0.0,
    }
}

/// The default obstacle: a plane through the origin with normal +z, stiffness 1e9 J/m⁵,
/// margin 0, radius 0, with `struct_size` set. Available in every build.
#[no_mangle]
pub extern "C" fn pleat_tfw_obstacle_default() -> PleatTfwObstacle {
    PleatTfwObstacle {
        struct_size: full_size::<PleatTfwObstacle>(),
        kind: PLEAT_TFW_OBSTACLE_PLANE,
        point: [0.0; 3],
        normal: [0.0, 0.0, 1.0],
        radius: 0.0,
        // crate::tfw::DEFAULT_OBSTACLE_STIFFNESS (pinned by a test; the constant exists in
        // every build of the C ABI).
        stiffness: 1e9,
        margin: 0.0,
    }
}

#[cfg(feature = "tfw")]
impl From<&crate::tfw::TfwParams> for PleatTfwParams {
    fn from(p: &crate::tfw::TfwParams) -> Self {
        use crate::tfw::curvature::CurvatureMethod;
        use crate::tfw::wfree::WRule;
        let u32_of = |v: usize| v.min(u32::MAX as usize) as u32;
        let limit = p.sqp.time_limit_seconds;
        PleatTfwParams {
            struct_size: full_size::<PleatTfwParams>(),
            sqp_max_iterations: u32_of(p.sqp.max_iterations),
            base_max_iterations: u32_of(p.base.max_iterations),
            base_load_steps: u32_of(p.base.load_steps),
            w_rule: match p.w_rule {
                WRule::Text => PLEAT_TFW_W_RULE_TEXT,
                WRule::Reference => PLEAT_TFW_W_RULE_REFERENCE,
            },
            reserved: 0,
            base_gradient_tolerance: p.base.gradient_tolerance,
            base_energy_tolerance: p.base.energy_tolerance,
            bending_scale: p.base.bending_scale,
            initial_amplitude: p.initial_amplitude.unwrap_or(0.0),
            sqp_stationarity_tolerance: p.sqp.stationarity_tolerance,
            sqp_energy_tolerance: p.sqp.energy_tolerance,
            sqp_step_tolerance: p.sqp.step_tolerance,
            sqp_armijo: p.sqp.armijo,
            sqp_initial_shift: p.sqp.initial_shift,
            sqp_time_limit_seconds: if limit.is_finite() { limit } else { 0.0 },
            out_of_scope_slack_fraction: p.out_of_scope_slack_fraction,
            curvature: match p.curvature {
                CurvatureMethod::QuadricFit => PLEAT_TFW_CURVATURE_QUADRIC_FIT,
                CurvatureMethod::VertexNormals => PLEAT_TFW_CURVATURE_VERTEX_NORMALS,
            },
            reserved2: 0,
            qp: match p.sqp.qp {
                crate::tfw::QpMethod::Clarabel => PLEAT_TFW_QP_CLARABEL,
                crate::tfw::QpMethod::ProjectedNewton => PLEAT_TFW_QP_PROJECTED_NEWTON,
            },
            reserved3: 0,
            snap_periods: u32::from(p.snap_periods),
            reserved4: 0,
            valley_search: u32::from(p.sqp.valley_search),
            reserved5: 0,
        }
    }
}

/// `TfwParams::default()` as C, for builds without `tfw`; the test `ffi::defaults` pins it
/// to the conversion above.
#[cfg_attr(feature = "tfw", allow(dead_code))]
pub(super) fn defaults_without_tfw() -> PleatTfwParams {
    PleatTfwParams {
        struct_size: full_size::<PleatTfwParams>(),
        sqp_max_iterations: 1000,
        base_max_iterations: 200,
        base_load_steps: 1,
        w_rule: PLEAT_TFW_W_RULE_TEXT,
        reserved: 0,
        base_gradient_tolerance: 1e-8,
        base_energy_tolerance: 1e-14,
        bending_scale: 1.0,
        initial_amplitude: 0.0,
        sqp_stationarity_tolerance: 1e-6,
        sqp_energy_tolerance: 1e-10,
        sqp_step_tolerance: 1e-10,
        sqp_armijo: 0.2,
        sqp_initial_shift: 1e-6,
        sqp_time_limit_seconds: 0.0,
        out_of_scope_slack_fraction: 0.5,
        curvature: PLEAT_TFW_CURVATURE_QUADRIC_FIT,
        reserved2: 0,
        qp: PLEAT_TFW_QP_PROJECTED_NEWTON,
        reserved3: 0,
        snap_periods: 0,
        reserved4: 0,
        valley_search: 1,
        reserved5: 0,
    }
}

// ---------------------------------------------------------------------------------------------
// Scenes

/// Reads and validates a scene file (JSON; format in README "Tension-field wrinkles").
///
/// - `path`: NUL-terminated UTF-8 path; non-NULL.
/// - `out`: receives the new scene (destroy with `pleat_tfw_scene_destroy`); non-NULL.
///
/// Returns `PLEAT_STATUS_IO` when the file cannot be read, `PLEAT_STATUS_INVALID_ARGUMENT`
/// for malformed JSON or an invalid scene (the message names the field, e.g.
/// `scene: material.thickness: must be > 0`), `PLEAT_STATUS_UNSUPPORTED` without `tfw`.
///
/// # Safety
/// `path` is NULL or NUL-terminated; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_read_file(
    path: *const std::ffi::c_char,
    out: *mut *mut PleatTfwScene,
) -> PleatStatus {
    tfw_only!([path, out] guard(|| imp::read_file(path, out)))
}

/// Parses and validates a scene from JSON text (as `pleat_tfw_scene_read_file`).
///
/// - `json`: NUL-terminated UTF-8 text; non-NULL.
/// - `out`: receives the new scene; non-NULL.
///
/// # Safety
/// `json` is NULL or NUL-terminated; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_from_json(
    json: *const std::ffi::c_char,
    out: *mut *mut PleatTfwScene,
) -> PleatStatus {
    tfw_only!([json, out] guard(|| imp::from_json(json, out)))
}

/// Builds a scene of one flat panel from arrays.
///
/// - `rest`: `2 * vertex_count` doubles, the rest (pattern) coordinates `u, v` of each vertex
///   (m); finite; non-NULL.
/// - `vertex_count`: ≥ 3.
/// - `triangles`: `3 * triangle_count` vertex indices, each < `vertex_count`; every triangle
///   must have a positive rest area; non-NULL.
/// - `triangle_count`: ≥ 1.
/// - `positions`: NULL (the initial 3D position of vertex i is `(u_i, v_i, 0)`) or
///   `3 * vertex_count` finite doubles.
/// - `material`: NULL = `pleat_tfw_material_default()`, else a `PleatTfwMaterial` with
///   `struct_size` set.
/// - `clamped`: `clamped_count` vertex indices held by a Dirichlet condition (their target is
///   the initial position plus `translation`); NULL only when `clamped_count` is 0.
/// - `translation`: NULL (no motion) or 3 finite doubles (m).
/// - `out`: receives the new scene; non-NULL.
///
/// Returns `PLEAT_STATUS_INVALID_ARGUMENT` naming the bad argument or scene field.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_from_arrays(
    rest: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    positions: *const f64,
    material: *const PleatTfwMaterial,
    clamped: *const u32,
    clamped_count: usize,
    translation: *const f64,
    out: *mut *mut PleatTfwScene,
) -> PleatStatus {
    tfw_only!([rest, vertex_count, triangles, triangle_count, positions, material, clamped,
               clamped_count, translation, out]
    guard(|| imp::from_arrays(
        rest, vertex_count, triangles, triangle_count, positions, material, clamped,
        clamped_count, translation, out
    )))
}

/// Adds a rigid obstacle (plane or sphere) to a scene, kept out of by a penalty in the base
/// solve (the scene file's `obstacles`). The obstacle is validated first; on error the scene
/// is unchanged.
///
/// - `scene`: non-NULL; not being solved on another thread.
/// - `obstacle`: non-NULL, `struct_size` set (start from `pleat_tfw_obstacle_default()`);
///   `kind` one of `PLEAT_TFW_OBSTACLE_*`, finite fields, a nonzero plane normal, a sphere
///   radius > 0, stiffness > 0, margin ≥ 0 (the message names the field, e.g.
///   `scene: obstacles[0].radius: must be > 0`).
///
/// # Safety
/// `scene` is NULL or live; `obstacle` is NULL or valid for `obstacle->struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_add_obstacle(
    scene: *mut PleatTfwScene,
    obstacle: *const PleatTfwObstacle,
) -> PleatStatus {
    tfw_only!([scene, obstacle] guard(|| imp::add_obstacle(scene, obstacle)))
}

/// Destroys a scene. NULL is accepted and ignored.
///
/// # Safety
/// `scene` is NULL or a handle from pleat not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_destroy(scene: *mut PleatTfwScene) {
    destroy(scene)
}

// ---------------------------------------------------------------------------------------------
// Solve

/// Solves a scene: the tension-field base surface (§2.4.1), the wrinkle-free faces and the
/// initial field (A.6.2), the wrinkle SQP (A.6.3) and the Knöppel phase.
///
/// - `scene`: non-NULL.
/// - `params`: NULL = `pleat_tfw_params_default()`; see `PleatTfwParams` for the ranges.
/// - `progress`: NULL or a callback, called on the calling thread per Newton and SQP
///   iteration; returning non-zero cancels (`PLEAT_STATUS_CANCELLED`, no output).
/// - `user_data`: passed to `progress` unchanged; may be NULL.
/// - `out`: receives the result (destroy with `pleat_tfw_result_destroy`); non-NULL.
///
/// Non-convergence is not an error: it is `PleatTfwStats::status`. Errors:
/// `PLEAT_STATUS_INVALID_ARGUMENT` (parameters), `PLEAT_STATUS_NUMERICAL` (a factorization
/// that cannot be regularized), `PLEAT_STATUS_CANCELLED`, `PLEAT_STATUS_UNSUPPORTED`.
///
/// # Safety
/// Pointers are NULL or valid as described; `progress` is a valid function or NULL.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_solve(
    scene: *const PleatTfwScene,
    params: *const PleatTfwParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatTfwResult,
) -> PleatStatus {
    tfw_only!([scene, params, progress, user_data, out]
        imp::solve(scene, params, progress, user_data, out))
}

/// Destroys a result. NULL is accepted and ignored.
///
/// # Safety
/// `result` is NULL or a handle from pleat not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_destroy(result: *mut PleatTfwResult) {
    destroy(result)
}

// ---------------------------------------------------------------------------------------------
// Result getters

/// The base surface as a new mesh handle (destroy with `pleat_mesh_destroy`): copy it out with
/// `pleat_mesh_vertex_count` / `pleat_mesh_copy_positions_f64` / `pleat_mesh_copy_indices`.
/// Sewn panels share vertices; triangles keep the scene's orientation.
///
/// # Safety
/// `result` is NULL or live; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_base_mesh(
    result: *const PleatTfwResult,
    out: *mut *mut PleatMesh,
) -> PleatStatus {
    tfw_only!([result, out] guard(|| imp::base_mesh(result, out)))
}

/// The complex wrinkle field on the base mesh as a new `PleatCwf` (destroy with
/// `pleat_cwf_destroy`): amplitude per vertex (m), ω per edge in pleat's edge numbering,
/// phase by Knöppel's method. Evaluate it with `pleat_cwf_evaluate` (without the v2 term) or
/// use `pleat_tfw_result_evaluate`.
///
/// # Safety
/// `result` is NULL or live; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_cwf(
    result: *const PleatTfwResult,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    tfw_only!([result, out] guard(|| imp::cwf(result, out)))
}

/// The wrinkled surface: the field evaluated as `pleat_cwf_evaluate` does (`params->levels`
/// Loop refinements, displacement `Re(z) n̂`), plus, when `in_plane_v2` is 1, the in-plane
/// term of eq. 2.19 (`Δx += (Re z · Im z / 4) ∇φ`; `pleat tfw` uses it).
///
/// - `result`: non-NULL.
/// - `params`: NULL = `pleat_wrinkle_eval_params_default()` (3 levels); `flags` must be 0
///   here (no per-vertex fields).
/// - `in_plane_v2`: 0 or 1.
/// - `progress`, `user_data`: as `pleat_cwf_evaluate`.
/// - `out_mesh`: receives the wrinkled mesh (destroy with `pleat_mesh_destroy`); non-NULL.
///
/// # Safety
/// Pointers are NULL or valid as described; `progress` is a valid function or NULL.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_evaluate(
    result: *const PleatTfwResult,
    params: *const PleatWrinkleEvalParams,
    in_plane_v2: u32,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out_mesh: *mut *mut PleatMesh,
) -> PleatStatus {
    tfw_only!([result, params, in_plane_v2, progress, user_data, out_mesh]
        imp::evaluate(result, params, in_plane_v2, progress, user_data, out_mesh))
}

/// Fills `*out` with the stats of the solve.
///
/// - `result`: non-NULL.
/// - `out`: non-NULL, `out->struct_size = sizeof(PleatTfwStats)` (≥ 8).
///
/// # Safety
/// `result` is NULL or live; `out` is NULL or valid for `out->struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_get_stats(
    result: *const PleatTfwResult,
    out: *mut PleatTfwStats,
) -> PleatStatus {
    tfw_only!([result, out] guard(|| imp::get_stats(result, out)))
}

/// Counts the waves of the result's wrinkle field (the library's counter, `tfw::measure`):
/// the field is evaluated with `levels` Loop refinements, and the sign changes of `Re z` where
/// the smooth (unwrinkled) evaluated surface crosses a plane are counted, / 2.
///
/// - `result`: non-NULL.
/// - `levels`: 0 to 6 (2 or 3 resolve a wave of 3 base edges or more).
/// - `section_point`, `section_normal`: both NULL = automatic (of the three axis planes
///   through the base's bounding-box centre, the one crossing the most waves; closed when it
///   surrounds the centre), or both 3 finite doubles (normal nonzero) = that plane.
/// - `section_closed`: 1 = the section is a closed ring around `section_point` (the samples
///   ordered by angle, last and first compared: cylinders, balloons), 0 = an open line
///   (ordered along the samples' principal direction); ignored when automatic.
/// - `out`: non-NULL, `out->struct_size = sizeof(PleatTfwWaveCount)` (≥ 8); with the full
///   size, `out->min_radius` (finite, ≥ 0) is read first: samples closer than it to the line
///   through the section point along the normal are dropped (automatic sections too).
///
/// # Safety
/// Pointers are NULL or valid as described.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_count_waves(
    result: *const PleatTfwResult,
    levels: u32,
    section_point: *const f64,
    section_normal: *const f64,
    section_closed: u32,
    out: *mut PleatTfwWaveCount,
) -> PleatStatus {
    tfw_only!([result, levels, section_point, section_normal, section_closed, out]
        guard(|| imp::count_waves(result, levels, section_point, section_normal,
                                  section_closed, out)))
}

/// Number of SQP iterations recorded (0 when the SQP did not run, `result` is NULL or the
/// build lacks `tfw`).
///
/// # Safety
/// `result` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_history_count(result: *const PleatTfwResult) -> usize {
    #[cfg(feature = "tfw")]
    {
        guard_value(0, || {
            result
                .as_ref()
                .and_then(|r| r.result.sqp.as_ref())
                .map_or(0, |s| s.history.len())
        })
    }
    #[cfg(not(feature = "tfw"))]
    {
        let _ = result;
        0
    }
}

/// Copies the SQP history: `PLEAT_TFW_HISTORY_COLUMNS` (4) doubles per iteration, in order:
/// energy `E^wf` (J), stationarity residual, step `‖Δx‖∞`, wall seconds since the SQP started.
///
/// - `result`, `dst`: non-NULL.
/// - `iteration_capacity`: iterations `dst` holds (it holds `4 * iteration_capacity`
///   doubles); ≥ `pleat_tfw_result_history_count(result)`, else `PLEAT_STATUS_LIMIT_EXCEEDED`
///   and nothing is written.
///
/// # Safety
/// `result` is NULL or live; `dst` is NULL or valid for `4 * iteration_capacity` doubles.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_result_copy_history(
    result: *const PleatTfwResult,
    dst: *mut f64,
    iteration_capacity: usize,
) -> PleatStatus {
    tfw_only!([result, dst, iteration_capacity]
        guard(|| imp::copy_history(result, dst, iteration_capacity)))
}

// ---------------------------------------------------------------------------------------------
// Implementation (only with the `tfw` capability)

#[cfg(feature = "tfw")]
pub(super) mod imp {
    use super::*;
    use crate::ffi::boundary::{
        arg_out, arg_ref, arg_slice, bool_field, check_f64, check_range, finite_slice,
        read_versioned, required_versioned_out, Out,
    };
    use crate::ffi::common::{c_str_arg, guard_progress};
    use crate::ffi::wrinkle::imp::eval_options;
    use crate::tfw::curvature::CurvatureMethod;
    use crate::tfw::measure::Section;
    use crate::tfw::wfree::WRule;
    use crate::tfw::QpMethod;
    use crate::tfw::{
        BaseOptions, BaseStatus, Dirichlet, Material, Motion, Obstacle, ObstacleShape, Panel,
        Scene, SqpOptions, SqpStatus, TfwParams, TfwResult, TfwStatus,
    };
    use crate::wrinkle::KnoppelOptions;
    use crate::{Error, Result};

    unsafe fn scene_ref<'a>(s: *const PleatTfwScene) -> Result<&'a Scene> {
        arg_ref(s, "scene").map(|s| &s.scene)
    }

    unsafe fn result_ref<'a>(r: *const PleatTfwResult) -> Result<&'a TfwResult> {
        arg_ref(r, "result").map(|r| &r.result)
    }

    /// # Safety
    /// As `pleat_tfw_scene_read_file`.
    pub(super) unsafe fn read_file(
        path: *const std::ffi::c_char,
        out: *mut *mut PleatTfwScene,
    ) -> Result<()> {
        let path = c_str_arg(path, "path")?;
        let out = arg_out(out, "out")?;
        let scene = Scene::from_json_file(std::path::Path::new(path))?;
        out.put_boxed(PleatTfwScene { scene });
        Ok(())
    }

    /// # Safety
    /// As `pleat_tfw_scene_from_json`.
    pub(super) unsafe fn from_json(
        json: *const std::ffi::c_char,
        out: *mut *mut PleatTfwScene,
    ) -> Result<()> {
        let text = c_str_arg(json, "json")?;
        let out = arg_out(out, "out")?;
        let scene = Scene::from_json_str(text)?;
        out.put_boxed(PleatTfwScene { scene });
        Ok(())
    }

    /// `n` caller values at `p` (checked count, `n * k` elements), finite when doubles.
    ///
    /// # Safety
    /// `p` is NULL or valid for `n * k` values.
    unsafe fn doubles<'a>(p: *const f64, n: usize, k: usize, name: &str) -> Result<&'a [f64]> {
        let len = n
            .checked_mul(k)
            .ok_or_else(|| Error::InvalidArgument(format!("{name}: count overflows")))?;
        let s = arg_slice(p, len, name)?;
        finite_slice(s, name)?;
        Ok(s)
    }

    /// The Rust material of a C material (checked by `Scene::validate`, which names the
    /// field; only the gravity and pressure are checked here).
    fn material(m: &PleatTfwMaterial) -> Result<(Material, [f64; 3], f64)> {
        finite_slice(&m.gravity, "material->gravity")?;
        let p = m.pressure;
        check_f64(p, p.is_finite(), "material->pressure", "finite")?;
        let mat = Material {
            young: m.young,
            poisson: m.poisson,
            thickness: m.thickness,
            density: m.density,
        };
        Ok((mat, m.gravity, m.pressure))
    }

    /// # Safety
    /// As `pleat_tfw_scene_from_arrays`.
    pub(super) unsafe fn from_arrays(
        rest: *const f64,
        vertex_count: usize,
        triangles: *const u32,
        triangle_count: usize,
        positions: *const f64,
        material_p: *const PleatTfwMaterial,
        clamped: *const u32,
        clamped_count: usize,
        translation: *const f64,
        out: *mut *mut PleatTfwScene,
    ) -> Result<()> {
        let out = arg_out(out, "out")?;
        if vertex_count < 3 || vertex_count > u32::MAX as usize {
            return Err(Error::InvalidArgument(format!(
                "vertex_count is {vertex_count}; must be 3 to 2^32 - 1"
            )));
        }
        if triangle_count == 0 {
            return Err(Error::InvalidArgument("triangle_count is 0".into()));
        }
        let uv = doubles(rest, vertex_count, 2, "rest")?;
        let tri_len = triangle_count
            .checked_mul(3)
            .ok_or_else(|| Error::InvalidArgument("triangle_count overflows".into()))?;
        let tris = arg_slice(triangles, tri_len, "triangles")?;
        if let Some(i) = tris.iter().position(|&v| v as usize >= vertex_count) {
            return Err(Error::InvalidArgument(format!(
                "triangles[{i}] is {}; must be < vertex_count {vertex_count}",
                tris[i]
            )));
        }
        let pos = if positions.is_null() {
            None
        } else {
            let p = doubles(positions, vertex_count, 3, "positions")?;
            Some(p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
        };
        let clamps: &[u32] = if clamped_count == 0 {
            &[]
        } else {
            arg_slice(clamped, clamped_count, "clamped")?
        };
        if let Some(i) = clamps.iter().position(|&v| v as usize >= vertex_count) {
            return Err(Error::InvalidArgument(format!(
                "clamped[{i}] is {}; must be < vertex_count {vertex_count}",
                clamps[i]
            )));
        }
        let shift = if translation.is_null() {
            [0.0; 3]
        } else {
            let t = doubles(translation, 1, 3, "translation")?;
            [t[0], t[1], t[2]]
        };
        let (mat, gravity, pressure) = material(&read_versioned(material_p, "material")?)?;
        let panel = Panel {
            rest: uv.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
            triangles: tris.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            positions: pos,
        };
        let dirichlet = if clamps.is_empty() {
            Vec::new()
        } else {
            vec![Dirichlet {
                panel: 0,
                vertices: clamps.to_vec(),
                motion: Motion {
                    translation: shift,
                    rotation: None,
                },
            }]
        };
        let scene = Scene {
            name: "arrays".into(),
            material: mat,
            panels: vec![panel],
            gravity,
            pressure,
            dirichlet,
            seam_tolerance: 1e-6,
            obstacles: Vec::new(),
        };
        scene.validate()?;
        out.put_boxed(PleatTfwScene { scene });
        Ok(())
    }

    /// The Rust obstacle of a C obstacle (validated by `Obstacle`'s scene check).
    fn obstacle(o: &PleatTfwObstacle) -> Result<Obstacle> {
        let shape = match o.kind {
            PLEAT_TFW_OBSTACLE_PLANE => ObstacleShape::Plane {
                point: o.point,
                normal: o.normal,
            },
            PLEAT_TFW_OBSTACLE_SPHERE => ObstacleShape::Sphere {
                centre: o.point,
                radius: o.radius,
            },
            k => {
                return Err(Error::InvalidArgument(format!(
                    "obstacle->kind is {k}; use PLEAT_TFW_OBSTACLE_PLANE or _SPHERE"
                )))
            }
        };
        Ok(Obstacle {
            shape,
            stiffness: o.stiffness,
            margin: o.margin,
        })
    }

    /// # Safety
    /// As `pleat_tfw_scene_add_obstacle`.
    pub(super) unsafe fn add_obstacle(
        scene: *mut PleatTfwScene,
        obstacle_p: *const PleatTfwObstacle,
    ) -> Result<()> {
        let s = scene
            .as_mut()
            .ok_or_else(|| crate::ffi::common::null_arg("scene"))?;
        crate::ffi::boundary::non_null(obstacle_p, "obstacle")?;
        let o = obstacle(&read_versioned(obstacle_p, "obstacle")?)?;
        let mut next = s.scene.clone();
        next.obstacles.push(o);
        next.validate()?;
        s.scene = next;
        Ok(())
    }

    /// A caller's 3-vector (finite).
    ///
    /// # Safety
    /// `p` is valid for 3 doubles.
    unsafe fn vec3(p: *const f64, name: &str) -> Result<[f64; 3]> {
        let v = doubles(p, 1, 3, name)?;
        Ok([v[0], v[1], v[2]])
    }

    /// The caller's section, or `None` for the automatic one.
    ///
    /// # Safety
    /// As `pleat_tfw_result_count_waves`.
    unsafe fn section(
        point: *const f64,
        normal: *const f64,
        closed: u32,
    ) -> Result<Option<Section>> {
        if point.is_null() && normal.is_null() {
            return Ok(None);
        }
        let p = vec3(point, "section_point")?;
        let n = vec3(normal, "section_normal")?;
        if n.iter().all(|&c| c == 0.0) {
            return Err(Error::InvalidArgument(
                "section_normal is zero; must be nonzero".into(),
            ));
        }
        Ok(Some(if bool_field(closed, "section_closed")? {
            Section::ring(p, n)
        } else {
            Section::line(p, n)
        }))
    }

    /// # Safety
    /// As `pleat_tfw_result_count_waves`.
    pub(super) unsafe fn count_waves(
        result: *const PleatTfwResult,
        levels: u32,
        point: *const f64,
        normal: *const f64,
        closed: u32,
        out: *mut PleatTfwWaveCount,
    ) -> Result<()> {
        let r = result_ref(result)?;
        check_range(levels, 0, 6, "levels")?;
        let section = section(point, normal, closed)?;
        let min_radius = wave_count_min_radius(out)?;
        let out = required_versioned_out(out, "out")?;
        let count = |s: &Section| crate::tfw::measure::count_waves(&r.cwf, levels as usize, s);
        let (s, c) = match section {
            Some(mut s) => {
                s.min_radius = min_radius;
                let c = count(&s)?;
                (s, c)
            }
            None => {
                let (mut s, c) = crate::tfw::measure::count_waves_auto(&r.cwf, levels as usize)?;
                if min_radius > 0.0 {
                    s.min_radius = min_radius;
                    (s, count(&s)?)
                } else {
                    (s, c)
                }
            }
        };
        out.write(PleatTfwWaveCount {
            struct_size: 0,
            closed: u32::from(s.closed),
            waves: c.waves,
            peak_amplitude: c.peak,
            samples: c.samples as u64,
            point: s.point,
            normal: s.normal,
            min_radius: s.min_radius,
        });
        Ok(())
    }

    /// `out->min_radius` when the caller's `struct_size` covers it (validated: finite,
    /// ≥ 0), else 0. `out` NULL or too small is left to `required_versioned_out`.
    ///
    /// # Safety
    /// `out` is NULL or valid for `out->struct_size` bytes.
    unsafe fn wave_count_min_radius(out: *const PleatTfwWaveCount) -> Result<f64> {
        if out.is_null() {
            return Ok(0.0);
        }
        let size = std::ptr::read_unaligned(out as *const u32) as usize;
        let end = std::mem::offset_of!(PleatTfwWaveCount, min_radius) + 8;
        if size < end {
            return Ok(0.0);
        }
        let v = std::ptr::read_unaligned(std::ptr::addr_of!((*out).min_radius));
        check_f64(
            v,
            v.is_finite() && v >= 0.0,
            "out->min_radius",
            "finite and ≥ 0",
        )?;
        Ok(v)
    }

    /// A non-negative finite tolerance field.
    fn tolerance(v: f64, name: &str) -> Result<f64> {
        check_f64(v, v.is_finite() && v >= 0.0, name, "finite and ≥ 0")?;
        Ok(v)
    }

    /// A positive finite field.
    fn positive(v: f64, name: &str) -> Result<f64> {
        check_f64(v, v.is_finite() && v > 0.0, name, "finite and > 0")?;
        Ok(v)
    }

    /// The Rust parameters of C solve parameters, every field checked.
    pub(in crate::ffi) fn params(p: &PleatTfwParams) -> Result<TfwParams> {
        check_range(
            p.sqp_max_iterations,
            1,
            1_000_000,
            "params->sqp_max_iterations",
        )?;
        check_range(
            p.base_max_iterations,
            1,
            1_000_000,
            "params->base_max_iterations",
        )?;
        check_range(p.base_load_steps, 1, 10_000, "params->base_load_steps")?;
        let w_rule = match p.w_rule {
            PLEAT_TFW_W_RULE_TEXT => WRule::Text,
            PLEAT_TFW_W_RULE_REFERENCE => WRule::Reference,
            w => {
                return Err(Error::InvalidArgument(format!(
                    "params->w_rule is {w}; use PLEAT_TFW_W_RULE_TEXT or _REFERENCE"
                )))
            }
        };
        let a = p.initial_amplitude;
        check_f64(
            a,
            a.is_finite() && a >= 0.0,
            "params->initial_amplitude",
            "0 (automatic) or finite and > 0",
        )?;
        let armijo = p.sqp_armijo;
        let armijo_ok = armijo > 0.0 && armijo < 1.0;
        check_f64(armijo, armijo_ok, "params->sqp_armijo", "in (0, 1)")?;
        let t = p.sqp_time_limit_seconds;
        check_f64(
            t,
            t.is_finite() && t >= 0.0,
            "params->sqp_time_limit_seconds",
            "0 (unlimited) or finite and > 0",
        )?;
        let curvature = match p.curvature {
            PLEAT_TFW_CURVATURE_QUADRIC_FIT => CurvatureMethod::QuadricFit,
            PLEAT_TFW_CURVATURE_VERTEX_NORMALS => CurvatureMethod::VertexNormals,
            c => {
                return Err(Error::InvalidArgument(format!(
                    "params->curvature is {c}; use PLEAT_TFW_CURVATURE_QUADRIC_FIT or \
                     _VERTEX_NORMALS"
                )))
            }
        };
        let qp = match p.qp {
            PLEAT_TFW_QP_CLARABEL => QpMethod::Clarabel,
            PLEAT_TFW_QP_PROJECTED_NEWTON => QpMethod::ProjectedNewton,
            q => {
                return Err(Error::InvalidArgument(format!(
                    "params->qp is {q}; use PLEAT_TFW_QP_CLARABEL or \
                     PLEAT_TFW_QP_PROJECTED_NEWTON"
                )))
            }
        };
        check_range(p.snap_periods, 0, 1, "params->snap_periods")?;
        check_range(p.valley_search, 0, 1, "params->valley_search")?;
        let f = p.out_of_scope_slack_fraction;
        let f_ok = (0.0..=1.0).contains(&f);
        check_f64(f, f_ok, "params->out_of_scope_slack_fraction", "in [0, 1]")?;
        Ok(TfwParams {
            base: BaseOptions {
                max_iterations: p.base_max_iterations as usize,
                gradient_tolerance: positive(
                    p.base_gradient_tolerance,
                    "params->base_gradient_tolerance",
                )?,
                energy_tolerance: tolerance(
                    p.base_energy_tolerance,
                    "params->base_energy_tolerance",
                )?,
                load_steps: p.base_load_steps as usize,
                bending_scale: tolerance(p.bending_scale, "params->bending_scale")?,
                ..BaseOptions::default()
            },
            w_rule,
            initial_amplitude: (a > 0.0).then_some(a),
            sqp: SqpOptions {
                max_iterations: p.sqp_max_iterations as usize,
                stationarity_tolerance: tolerance(
                    p.sqp_stationarity_tolerance,
                    "params->sqp_stationarity_tolerance",
                )?,
                energy_tolerance: tolerance(
                    p.sqp_energy_tolerance,
                    "params->sqp_energy_tolerance",
                )?,
                step_tolerance: tolerance(p.sqp_step_tolerance, "params->sqp_step_tolerance")?,
                armijo,
                initial_shift: positive(p.sqp_initial_shift, "params->sqp_initial_shift")?,
                time_limit_seconds: if t > 0.0 { t } else { f64::INFINITY },
                qp,
                snapshot_every: 0,
                valley_search: p.valley_search == 1,
                ..SqpOptions::default()
            },
            curvature,
            knoppel: KnoppelOptions::default(),
            out_of_scope_slack_fraction: f,
            snap_periods: p.snap_periods == 1,
        })
    }

    /// # Safety
    /// As `pleat_tfw_solve`.
    pub(super) unsafe fn solve(
        scene: *const PleatTfwScene,
        params_p: *const PleatTfwParams,
        progress: PleatProgressFn,
        user_data: *mut std::ffi::c_void,
        out: *mut *mut PleatTfwResult,
    ) -> PleatStatus {
        guard_progress(progress, user_data, |relay| {
            let s = scene_ref(scene)?;
            let out = arg_out(out, "out")?;
            let p = params(&read_versioned(params_p, "params")?)?;
            let result = crate::tfw::solve(s, &p, relay)?;
            out.put_boxed(PleatTfwResult { result });
            Ok(())
        })
    }

    /// # Safety
    /// As `pleat_tfw_result_base_mesh`.
    pub(super) unsafe fn base_mesh(
        result: *const PleatTfwResult,
        out: *mut *mut PleatMesh,
    ) -> Result<()> {
        let r = result_ref(result)?;
        let out = arg_out(out, "out")?;
        out.put_mesh(r.base.mesh.clone());
        Ok(())
    }

    /// # Safety
    /// As `pleat_tfw_result_cwf`.
    pub(super) unsafe fn cwf(result: *const PleatTfwResult, out: *mut *mut PleatCwf) -> Result<()> {
        let r = result_ref(result)?;
        let out: Out<*mut PleatCwf> = arg_out(out, "out")?;
        out.put_boxed(PleatCwf {
            cwf: r.cwf.clone(),
            knoppel: None,
            edit: None,
        });
        Ok(())
    }

    /// # Safety
    /// As `pleat_tfw_result_evaluate`.
    pub(super) unsafe fn evaluate(
        result: *const PleatTfwResult,
        params_p: *const PleatWrinkleEvalParams,
        in_plane_v2: u32,
        progress: PleatProgressFn,
        user_data: *mut std::ffi::c_void,
        out_mesh: *mut *mut PleatMesh,
    ) -> PleatStatus {
        guard_progress(progress, user_data, |relay| {
            let r = result_ref(result)?;
            let out_mesh = arg_out(out_mesh, "out_mesh")?;
            let p = read_versioned(params_p, "params")?;
            if p.flags != 0 {
                return Err(Error::InvalidArgument(format!(
                    "params->flags is {:#x}; must be 0 here (fields: pleat_tfw_result_cwf, \
                     then pleat_cwf_evaluate)",
                    p.flags
                )));
            }
            let mut opts = eval_options(&p, false)?;
            opts.in_plane_v2 = bool_field(in_plane_v2, "in_plane_v2")?;
            let (ev, _) = r
                .cwf
                .evaluate_with_progress(p.levels as usize, &opts, relay)?;
            out_mesh.put_mesh(ev.mesh);
            Ok(())
        })
    }

    fn status_code(s: TfwStatus) -> u32 {
        match s {
            TfwStatus::Converged => PLEAT_TFW_STATUS_CONVERGED,
            TfwStatus::NotConverged => PLEAT_TFW_STATUS_NOT_CONVERGED,
            TfwStatus::NoCompression => PLEAT_TFW_STATUS_NO_COMPRESSION,
            TfwStatus::OutOfScope => PLEAT_TFW_STATUS_OUT_OF_SCOPE,
        }
    }

    fn base_code(s: BaseStatus) -> u32 {
        match s {
            BaseStatus::Converged => 0,
            BaseStatus::EnergyStalled => 1,
            BaseStatus::MaxIterations => 2,
            BaseStatus::LineSearchFailed => 3,
            BaseStatus::FactorizationFailed => 4,
        }
    }

    fn sqp_code(s: Option<SqpStatus>) -> u32 {
        match s {
            Some(SqpStatus::Stationary) => 0,
            Some(SqpStatus::EnergyConverged) => 1,
            Some(SqpStatus::StepConverged) => 2,
            Some(SqpStatus::MaxIterations) => 3,
            Some(SqpStatus::TimeLimit) => 4,
            Some(SqpStatus::LineSearchFailed) => 5,
            Some(SqpStatus::QpFailed) => 6,
            Some(SqpStatus::NoFreeUnknowns) => 7,
            None => 8,
        }
    }

    /// The C stats of a result.
    pub(in crate::ffi) fn stats(r: &TfwResult) -> PleatTfwStats {
        let sqp = r.sqp.as_ref();
        let snap = r.snap.as_ref();
        let last = sqp.and_then(|s| s.history.last());
        let u32_of = |n: usize| n.min(u32::MAX as usize) as u32;
        PleatTfwStats {
            struct_size: 0,
            status: status_code(r.status),
            base_status: base_code(r.base.status),
            sqp_status: sqp_code(sqp.map(|s| s.status)),
            base_iterations: u32_of(r.base.history.len()),
            sqp_iterations: u32_of(sqp.map_or(0, |s| s.history.len())),
            vertex_count: r.base.mesh.vertex_count() as u64,
            triangle_count: r.base.mesh.triangle_count() as u64,
            wrinkle_free_face_count: r.w_faces.iter().filter(|&&w| w).count() as u64,
            energy: r.energy,
            initial_energy: sqp.map_or(r.energy, |s| s.initial_energy),
            residual: last.map_or(sqp.map_or(0.0, |s| s.initial_stationarity), |i| {
                i.stationarity
            }),
            initial_residual: sqp.map_or(0.0, |s| s.initial_stationarity),
            curl_residual: r.curl_residual,
            peak_amplitude: r.cwf.amplitude().iter().fold(0.0f64, |m, &a| m.max(a)),
            base_relative_gradient: r.base.relative_gradient,
            seconds_base: r.seconds.base,
            seconds_init: r.seconds.init,
            seconds_sqp: r.seconds.sqp,
            seconds_qp: sqp.map_or(0.0, |s| s.qp_seconds),
            seconds_phase: r.seconds.phase,
            snapped_loops: u32_of(snap.map_or(0, |s| s.loops.len())),
            snap_kept_loops: u32_of(snap.map_or(0, |s| s.kept_loops)),
            snap_max_period_error: snap.map_or(0.0, |s| s.max_period_error()),
            snap_max_correction: snap.map_or(0.0, |s| s.max_correction),
            snap_relative_correction: snap
                .filter(|s| s.omega_norm > 0.0)
                .map_or(0.0, |s| s.correction_norm / s.omega_norm),
            sqp_rescue_iteration: sqp
                .and_then(|s| s.rescued_at)
                .map_or(-1, |i| i.min(i64::MAX as usize) as i64),
        }
    }

    /// # Safety
    /// As `pleat_tfw_result_get_stats`.
    pub(super) unsafe fn get_stats(
        result: *const PleatTfwResult,
        out: *mut PleatTfwStats,
    ) -> Result<()> {
        let r = result_ref(result)?;
        let out = required_versioned_out(out, "out")?;
        out.write(stats(r));
        Ok(())
    }

    /// # Safety
    /// As `pleat_tfw_result_copy_history`.
    pub(super) unsafe fn copy_history(
        result: *const PleatTfwResult,
        dst: *mut f64,
        iteration_capacity: usize,
    ) -> Result<()> {
        let r = result_ref(result)?;
        let dst = arg_out(dst, "dst")?;
        let history = r.sqp.as_ref().map_or(&[][..], |s| &s.history[..]);
        if iteration_capacity < history.len() {
            return Err(Error::LimitExceeded(format!(
                "dst holds {iteration_capacity} iterations, {} were recorded",
                history.len()
            )));
        }
        for (i, it) in history.iter().enumerate() {
            let row = [it.energy, it.stationarity, it.step_norm, it.seconds];
            for (k, v) in row.into_iter().enumerate() {
                dst.add(4 * i + k).put(v);
            }
        }
        Ok(())
    }
}

#[cfg(all(test, feature = "tfw"))]
mod tests {
    use super::*;
    use crate::ffi::{
        pleat_cwf_copy_amplitude, pleat_cwf_destroy, pleat_mesh_copy_positions_f64,
        pleat_mesh_destroy, pleat_set_thread_count,
    };
    use std::ffi::CString;
    use std::ptr::null_mut;

    /// `params` as `pleat_tfw_solve` reads them: versioned (a shorter `struct_size` gets the
    /// defaults beyond it), then validated.
    fn read(p: &PleatTfwParams) -> crate::Result<crate::tfw::TfwParams> {
        // SAFETY: `p` is a live struct of at least `p.struct_size` bytes.
        let v = unsafe { crate::ffi::boundary::read_versioned(p, "params") }?;
        imp::params(&v)
    }

    /// Base positions, amplitudes and the history of a small sheet solved through the C API
    /// on `threads` worker threads.
    fn solve_small(threads: u32, qp: u32) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let json =
            CString::new(crate::tfw::Scene::stretched_sheet(9, 4, 0.05).to_json_string()).unwrap();
        let mut params = pleat_tfw_params_default();
        params.sqp_max_iterations = 10;
        params.qp = qp;
        // SAFETY: valid pointers throughout; every handle is destroyed once.
        unsafe {
            assert_eq!(pleat_set_thread_count(threads), PleatStatus::Ok);
            let mut scene = null_mut();
            assert_eq!(
                pleat_tfw_scene_from_json(json.as_ptr(), &mut scene),
                PleatStatus::Ok
            );
            let mut result = null_mut();
            let st = pleat_tfw_solve(scene, &params, None, null_mut(), &mut result);
            assert_eq!(st, PleatStatus::Ok);
            let mut stats = PleatTfwStats {
                struct_size: full_size::<PleatTfwStats>(),
                ..Default::default()
            };
            assert_eq!(
                pleat_tfw_result_get_stats(result, &mut stats),
                PleatStatus::Ok
            );
            let (nv, n) = (stats.vertex_count as usize, stats.sqp_iterations as usize);
            assert_eq!(pleat_tfw_result_history_count(result), n);
            let mut history = vec![0.0; 4 * n];
            let st = pleat_tfw_result_copy_history(result, history.as_mut_ptr(), n);
            assert_eq!(st, PleatStatus::Ok);
            let (mut mesh, mut cwf) = (null_mut(), null_mut());
            assert_eq!(
                pleat_tfw_result_base_mesh(result, &mut mesh),
                PleatStatus::Ok
            );
            assert_eq!(pleat_tfw_result_cwf(result, &mut cwf), PleatStatus::Ok);
            let mut pos = vec![0.0; 3 * nv];
            let st = pleat_mesh_copy_positions_f64(mesh, pos.as_mut_ptr(), nv, 0);
            assert_eq!(st, PleatStatus::Ok);
            let mut amp = vec![0.0; nv];
            assert_eq!(
                pleat_cwf_copy_amplitude(cwf, amp.as_mut_ptr(), nv),
                PleatStatus::Ok
            );
            assert!(amp.iter().fold(0.0f64, |m, &a| m.max(a)) == stats.peak_amplitude);
            pleat_mesh_destroy(mesh);
            pleat_cwf_destroy(cwf);
            pleat_tfw_result_destroy(result);
            pleat_tfw_scene_destroy(scene);
            assert_eq!(pleat_set_thread_count(0), PleatStatus::Ok);
            (pos, amp, history)
        }
    }

    /// `curvature` (appended 2026-11-27): read from a full struct, defaulted for an older,
    /// shorter one, and an unknown value is rejected with a message naming the field.
    #[test]
    fn curvature_field_is_versioned_and_checked() {
        use crate::tfw::curvature::CurvatureMethod;
        let mut p = pleat_tfw_params_default();
        assert_eq!(p.curvature, PLEAT_TFW_CURVATURE_QUADRIC_FIT);
        p.curvature = PLEAT_TFW_CURVATURE_VERTEX_NORMALS;
        let full = read(&p).unwrap();
        assert_eq!(full.curvature, CurvatureMethod::VertexNormals);
        p.struct_size = std::mem::offset_of!(PleatTfwParams, curvature) as u32;
        let old = read(&p).unwrap();
        assert_eq!(old.curvature, CurvatureMethod::QuadricFit);
        p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
        p.curvature = 7;
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("params->curvature"), "{e}");
    }

    /// `qp` (appended 2026-11-27): read from a full struct, defaulted for an older, shorter
    /// one, an unknown value rejected with a message naming the field.
    #[test]
    fn qp_field_is_versioned_and_checked() {
        use crate::tfw::QpMethod;
        let mut p = pleat_tfw_params_default();
        let default = crate::tfw::TfwParams::default().sqp.qp;
        assert_eq!(read(&p).unwrap().sqp.qp, default);
        p.qp = PLEAT_TFW_QP_PROJECTED_NEWTON;
        assert_eq!(read(&p).unwrap().sqp.qp, QpMethod::ProjectedNewton);
        p.qp = PLEAT_TFW_QP_CLARABEL;
        assert_eq!(read(&p).unwrap().sqp.qp, QpMethod::Clarabel);
        p.qp = if default == QpMethod::Clarabel {
            PLEAT_TFW_QP_PROJECTED_NEWTON
        } else {
            PLEAT_TFW_QP_CLARABEL
        };
        p.struct_size = std::mem::offset_of!(PleatTfwParams, qp) as u32;
        assert_eq!(read(&p).unwrap().sqp.qp, default);
        p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
        p.qp = 9;
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("params->qp"), "{e}");
    }

    /// `snap_periods` (appended 2026-11-29): read from a full struct, defaulted (off) for an
    /// older, shorter one, a value other than 0 or 1 rejected with a message naming the field.
    #[test]
    fn snap_periods_field_is_versioned_and_checked() {
        let mut p = pleat_tfw_params_default();
        assert_eq!(p.snap_periods, 0);
        assert!(!read(&p).unwrap().snap_periods);
        p.snap_periods = 1;
        assert!(read(&p).unwrap().snap_periods);
        p.struct_size = std::mem::offset_of!(PleatTfwParams, snap_periods) as u32;
        assert!(!read(&p).unwrap().snap_periods);
        p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
        p.snap_periods = 2;
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("params->snap_periods"), "{e}");
    }

    /// `valley_search` (appended 2026-11-29): on by default and for an older, shorter
    /// struct, off with 0, a value other than 0 or 1 rejected naming the field.
    #[test]
    fn valley_search_field_is_versioned_and_checked() {
        let mut p = pleat_tfw_params_default();
        assert_eq!(p.valley_search, 1);
        assert!(read(&p).unwrap().sqp.valley_search);
        p.valley_search = 0;
        assert!(!read(&p).unwrap().sqp.valley_search);
        p.struct_size = std::mem::offset_of!(PleatTfwParams, valley_search) as u32;
        assert!(read(&p).unwrap().sqp.valley_search);
        p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
        p.valley_search = 2;
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("params->valley_search"), "{e}");
    }

    /// `pleat_tfw_scene_add_obstacle` gives the scene a JSON `obstacles` entry gives, takes
    /// the defaults for an older (shorter) struct, and rejects bad fields naming them with the
    /// scene unchanged.
    #[test]
    fn obstacles_from_c_match_the_scene_file() {
        use crate::tfw::{Obstacle, ObstacleShape, DEFAULT_OBSTACLE_STIFFNESS};
        assert_eq!(
            pleat_tfw_obstacle_default().stiffness,
            DEFAULT_OBSTACLE_STIFFNESS
        );
        let json =
            CString::new(crate::tfw::Scene::stretched_sheet(5, 3, 0.05).to_json_string()).unwrap();
        // SAFETY: valid pointers throughout; the scene is destroyed once.
        unsafe {
            let mut scene = null_mut();
            assert_eq!(
                pleat_tfw_scene_from_json(json.as_ptr(), &mut scene),
                PleatStatus::Ok
            );
            let mut o = pleat_tfw_obstacle_default();
            o.kind = PLEAT_TFW_OBSTACLE_SPHERE;
            o.point = [0.1, 0.0, -0.3];
            o.radius = 0.25;
            o.margin = 1e-3;
            let st = pleat_tfw_scene_add_obstacle(scene, &o);
            assert_eq!(st, PleatStatus::Ok);
            let mut old = pleat_tfw_obstacle_default();
            old.normal = [0.0, 1.0, 0.0];
            old.stiffness = 5.0;
            old.struct_size = std::mem::offset_of!(PleatTfwObstacle, stiffness) as u32;
            assert_eq!(pleat_tfw_scene_add_obstacle(scene, &old), PleatStatus::Ok);
            let expected = vec![
                Obstacle {
                    shape: ObstacleShape::Sphere {
                        centre: [0.1, 0.0, -0.3],
                        radius: 0.25,
                    },
                    stiffness: DEFAULT_OBSTACLE_STIFFNESS,
                    margin: 1e-3,
                },
                Obstacle {
                    shape: ObstacleShape::Plane {
                        point: [0.0; 3],
                        normal: [0.0, 1.0, 0.0],
                    },
                    stiffness: DEFAULT_OBSTACLE_STIFFNESS,
                    margin: 0.0,
                },
            ];
            assert_eq!((*scene).scene.obstacles, expected);
            let bad = [
                (PleatTfwObstacle { kind: 5, ..o }, "obstacle->kind"),
                (PleatTfwObstacle { radius: 0.0, ..o }, "obstacles[2].radius"),
                (
                    PleatTfwObstacle {
                        point: [f64::NAN, 0.0, 0.0],
                        ..o
                    },
                    "obstacles[2].centre",
                ),
                (
                    PleatTfwObstacle {
                        kind: PLEAT_TFW_OBSTACLE_PLANE,
                        normal: [0.0; 3],
                        ..o
                    },
                    "obstacles[2].normal",
                ),
                (
                    PleatTfwObstacle { margin: -1.0, ..o },
                    "obstacles[2].margin",
                ),
                (
                    PleatTfwObstacle {
                        stiffness: 0.0,
                        ..o
                    },
                    "obstacles[2].stiffness",
                ),
                (
                    PleatTfwObstacle {
                        struct_size: 4,
                        ..o
                    },
                    "obstacle",
                ),
            ];
            for (b, field) in bad {
                let st = pleat_tfw_scene_add_obstacle(scene, &b);
                assert_eq!(st, PleatStatus::InvalidArgument, "{field}");
                let msg =
                    std::ffi::CStr::from_ptr(crate::ffi::pleat_last_error()).to_string_lossy();
                assert!(msg.contains(field), "{field}: {msg}");
            }
            let st = pleat_tfw_scene_add_obstacle(scene, std::ptr::null());
            assert_eq!(st, PleatStatus::InvalidArgument);
            let st = pleat_tfw_scene_add_obstacle(null_mut(), &o);
            assert_eq!(st, PleatStatus::InvalidArgument);
            assert_eq!((*scene).scene.obstacles, expected);
            pleat_tfw_scene_destroy(scene);
        }
    }

    /// `pleat_tfw_result_count_waves` is the library counter: automatic and given sections
    /// agree with `tfw::measure` on a solved sheet; bad arguments are named.
    #[test]
    fn wave_count_from_c_is_the_library_counter() {
        let json =
            CString::new(crate::tfw::Scene::stretched_sheet(13, 6, 0.05).to_json_string()).unwrap();
        // SAFETY: valid pointers throughout; every handle is destroyed once.
        unsafe {
            let mut scene = null_mut();
            assert_eq!(
                pleat_tfw_scene_from_json(json.as_ptr(), &mut scene),
                PleatStatus::Ok
            );
            let mut result = null_mut();
            let st = pleat_tfw_solve(scene, std::ptr::null(), None, null_mut(), &mut result);
            assert_eq!(st, PleatStatus::Ok);
            let mut w = PleatTfwWaveCount {
                struct_size: full_size::<PleatTfwWaveCount>(),
                ..Default::default()
            };
            let st = pleat_tfw_result_count_waves(
                result,
                2,
                std::ptr::null(),
                std::ptr::null(),
                0,
                &mut w,
            );
            assert_eq!(st, PleatStatus::Ok);
            let cwf = &(*result).result.cwf;
            let (s, c) = crate::tfw::measure::count_waves_auto(cwf, 2).unwrap();
            assert_eq!(
                (w.waves, w.peak_amplitude, w.samples),
                (c.waves, c.peak, c.samples as u64)
            );
            assert_eq!(
                (w.point, w.normal, w.closed),
                (s.point, s.normal, u32::from(s.closed))
            );
            assert!(w.waves >= 1.0 && w.peak_amplitude > 0.0, "{w:?}");
            let mut g = PleatTfwWaveCount {
                struct_size: full_size::<PleatTfwWaveCount>(),
                ..Default::default()
            };
            let st = pleat_tfw_result_count_waves(
                result,
                2,
                s.point.as_ptr(),
                s.normal.as_ptr(),
                0,
                &mut g,
            );
            assert_eq!(st, PleatStatus::Ok);
            assert_eq!((g.waves, g.peak_amplitude), (w.waves, w.peak_amplitude));
            // min_radius (appended): the library counter with that section; an older struct
            // size is not read (0); a bad value is named
            let mut m = PleatTfwWaveCount {
                struct_size: full_size::<PleatTfwWaveCount>(),
                min_radius: 0.02,
                ..Default::default()
            };
            let st = pleat_tfw_result_count_waves(
                result,
                2,
                s.point.as_ptr(),
                s.normal.as_ptr(),
                0,
                &mut m,
            );
            assert_eq!(st, PleatStatus::Ok);
            let cut = crate::tfw::measure::Section {
                min_radius: 0.02,
                ..s
            };
            let c2 = crate::tfw::measure::count_waves(cwf, 2, &cut).unwrap();
            assert_eq!(
                (m.waves, m.samples, m.min_radius),
                (c2.waves, c2.samples as u64, 0.02)
            );
            assert!(m.samples < w.samples, "{m:?} vs {w:?}");
            let mut old = PleatTfwWaveCount {
                struct_size: std::mem::offset_of!(PleatTfwWaveCount, min_radius) as u32,
                min_radius: -1.0,
                ..Default::default()
            };
            let st = pleat_tfw_result_count_waves(
                result,
                2,
                std::ptr::null(),
                std::ptr::null(),
                0,
                &mut old,
            );
            assert_eq!(st, PleatStatus::Ok);
            assert_eq!((old.waves, old.samples), (w.waves, w.samples));
            assert_eq!(old.min_radius, -1.0, "beyond struct_size: not written");
            m.min_radius = f64::NAN;
            let st = pleat_tfw_result_count_waves(
                result,
                2,
                std::ptr::null(),
                std::ptr::null(),
                0,
                &mut m,
            );
            assert_eq!(st, PleatStatus::InvalidArgument);
            let msg = std::ffi::CStr::from_ptr(crate::ffi::pleat_last_error()).to_string_lossy();
            assert!(msg.contains("out->min_radius"), "{msg}");
            let zero = [0.0; 3];
            let nan = [f64::NAN, 0.0, 1.0];
            let cases: [(u32, *const f64, *const f64, u32, &str); 5] = [
                (7, std::ptr::null(), std::ptr::null(), 0, "levels"),
                (2, s.point.as_ptr(), std::ptr::null(), 0, "section_normal"),
                (2, s.point.as_ptr(), zero.as_ptr(), 0, "section_normal"),
                (2, nan.as_ptr(), s.normal.as_ptr(), 0, "section_point"),
                (2, s.point.as_ptr(), s.normal.as_ptr(), 2, "section_closed"),
            ];
            for (levels, p, n, closed, field) in cases {
                let st = pleat_tfw_result_count_waves(result, levels, p, n, closed, &mut g);
                assert_eq!(st, PleatStatus::InvalidArgument, "{field}");
                let msg =
                    std::ffi::CStr::from_ptr(crate::ffi::pleat_last_error()).to_string_lossy();
                assert!(msg.contains(field), "{field}: {msg}");
            }
            let st = pleat_tfw_result_count_waves(
                result,
                2,
                std::ptr::null(),
                std::ptr::null(),
                0,
                null_mut(),
            );
            assert_eq!(st, PleatStatus::InvalidArgument);
            pleat_tfw_result_destroy(result);
            pleat_tfw_scene_destroy(scene);
        }
    }

    /// Same scene and parameters ⇒ the same bytes on 1 and 2 threads (the history's wall
    /// times aside).
    #[test]
    fn c_api_solve_is_thread_count_independent() {
        for qp in [PLEAT_TFW_QP_CLARABEL, PLEAT_TFW_QP_PROJECTED_NEWTON] {
            solve_is_thread_count_independent(qp);
        }
    }

    fn solve_is_thread_count_independent(qp: u32) {
        let (p1, a1, h1) = solve_small(1, qp);
        let (p2, a2, h2) = solve_small(2, qp);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&p1), bits(&p2));
        assert_eq!(bits(&a1), bits(&a2));
        let numbers = |h: &[f64]| {
            h.chunks_exact(4)
                .flat_map(|r| [r[0].to_bits(), r[1].to_bits(), r[2].to_bits()])
                .collect::<Vec<_>>()
        };
        assert!(!h1.is_empty());
        assert_eq!(numbers(&h1), numbers(&h2));
    }
}
