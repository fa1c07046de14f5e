//! The TFW solve in the C ABI: [`pleat_tfw_solve`] with its parameters checked field by field
//! (`PLEAT_STATUS_INVALID_ARGUMENT` names the field), and the result's destruction.

use super::types::*;
use crate::ffi::boundary::{destroy, requires};
use crate::ffi::common::{PleatProgressFn, PleatStatus};

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
// Implementation (only with the `tfw` capability)

#[cfg(feature = "tfw")]
pub(in crate::ffi) mod imp {
    use super::*;
    use crate::ffi::boundary::{arg_out, check_f64, check_range, read_versioned};
    use crate::ffi::common::guard_progress;
    use crate::ffi::tfw::scene::imp::scene_ref;

    use crate::tfw::curvature::CurvatureMethod;

    use crate::tfw::wfree::WRule;
    use crate::tfw::QpMethod;
    use crate::tfw::{BaseOptions, SqpOptions, TfwParams};
    use crate::wrinkle::KnoppelOptions;
    use crate::{Error, Result};

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
}
