//! The C types of the TFW API: status and option constants (`PLEAT_TFW_*`), the opaque scene
//! and result handles, and the versioned structs (parameters, material, obstacle, stats, wave
//! count) with their defaults, which are those of the Rust API (`ffi::defaults` checks every
//! one round-trips). Every item exists in every build.

use crate::ffi::boundary::{full_size, versioned};

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
    pub(super) scene: crate::tfw::Scene,
}

/// The result of `pleat_tfw_solve` (opaque): base surface, wrinkle field, stats and history.
/// Destroyed by `pleat_tfw_result_destroy`. Immutable.
pub struct PleatTfwResult {
    #[cfg(feature = "tfw")]
    pub(super) result: crate::tfw::TfwResult,
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
    /// along (a, ω) → (a/μ, μω), docs/design-notes.md, "Wrinkle SQP"; what makes thin shells
    /// converge); 0: off, the plain projected Newton. Appended 2026-11-29: a shorter struct
    /// (without it) gets the default.
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
    /// and kept them (docs/design-notes.md, "Wrinkle SQP"); −1 when no rescue was needed.
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
pub(in crate::ffi) fn defaults_without_tfw() -> PleatTfwParams {
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
