//! The getters of a TFW result in the C ABI: the base mesh and wrinkle field as the existing
//! `PleatMesh` / `PleatCwf` handles, the wrinkled mesh, the stats, the wave count and the SQP
//! history. Every getter reads the result only; NULL or too small outputs are refused before
//! anything is written.

use super::types::*;
use crate::ffi::boundary::{guard_value, requires};
use crate::ffi::common::{guard, PleatProgressFn, PleatStatus};
use crate::ffi::mesh::PleatMesh;
use crate::ffi::wrinkle::{PleatCwf, PleatWrinkleEvalParams};

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
        arg_out, arg_ref, bool_field, check_f64, check_range, read_versioned,
        required_versioned_out, Out,
    };
    use crate::ffi::common::guard_progress;
    use crate::ffi::tfw::scene::imp::doubles;
    use crate::ffi::wrinkle::imp::eval_options;

    use crate::tfw::measure::Section;

    use crate::tfw::{BaseStatus, SqpStatus, TfwResult, TfwStatus};

    use crate::{Error, Result};

    unsafe fn result_ref<'a>(r: *const PleatTfwResult) -> Result<&'a TfwResult> {
        arg_ref(r, "result").map(|r| &r.result)
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
