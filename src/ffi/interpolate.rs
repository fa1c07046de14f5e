//! Wrinkle animation in the C ABI (capability `wrinkle`, dissertation §3.4).
//!
//! - [`pleat_cwf_interpolate`]: the interpolant between two `PleatCwf` keyframes on the same
//!   base mesh, as a `PleatCwfAnimation` of `N' + 1` guide frames with `k` linear sub-steps.
//! - [`pleat_cwf_animation_frame`]: the wrinkle field at any `t ∈ [0, 1]`, as a new `PleatCwf`
//!   to evaluate with `pleat_cwf_evaluate`.
//! - Save/load (`.cwfa` text, see `src/wrinkle/animation.rs`), frame counts, convergence
//!   history.
//!
//! Every function exists in every build; without `wrinkle` the fallible ones return
//! `PLEAT_STATUS_UNSUPPORTED` and the counts 0.

#[cfg(feature = "wrinkle")]
use super::boundary::{arg_out, arg_ref, guard_value};
use super::boundary::{destroy, full_size, requires, versioned};
#[cfg(feature = "wrinkle")]
use super::common::{c_str_arg, guard};
use super::common::{PleatProgressFn, PleatStatus};
use super::mesh::PleatMesh;
use super::wrinkle::{wrinkle_count, wrinkle_only, PleatCwf};
#[cfg(feature = "wrinkle")]
use crate::Error;
#[cfg(feature = "wrinkle")]
use crate::Result;

/// `PleatWrinkleInterpStats::stop_reason`: the gradient norm reached the tolerance.
pub const PLEAT_INTERP_STOP_CONVERGED: u32 = 0;
/// `PleatWrinkleInterpStats::stop_reason`: the iteration cap was reached first.
pub const PLEAT_INTERP_STOP_ITERATION_CAP: u32 = 1;
/// `PleatWrinkleInterpStats::stop_reason`: no step decreased the objective any more (round-off
/// bound; the result is usable, see `final_gradient_norm`).
pub const PLEAT_INTERP_STOP_STALLED: u32 = 2;
/// `PleatWrinkleInterpStats::stop_reason`: identical keyframes, the constant path (0 iterations).
pub const PLEAT_INTERP_STOP_IDENTICAL_KEYFRAMES: u32 = 3;
/// `PleatWrinkleInterpStats::stop_reason`: `guide_frames == 1`, linear interpolation, no solve.
pub const PLEAT_INTERP_STOP_NO_UNKNOWNS: u32 = 4;

/// `PleatWrinkleInterpParams::hessian`: projected Newton (PSD per-vertex blocks).
pub const PLEAT_INTERP_HESSIAN_PROJECTED: u32 = 0;
/// `PleatWrinkleInterpParams::hessian`: Gauss–Newton.
pub const PLEAT_INTERP_HESSIAN_GAUSS_NEWTON: u32 = 1;
/// `PleatWrinkleInterpParams::hessian`: exact Hessian, direct sparse Cholesky of the whole
/// spacetime system with Levenberg–Marquardt damping (seconds per iteration on 500+ vertices).
pub const PLEAT_INTERP_HESSIAN_EXACT: u32 = 2;
/// `PleatWrinkleInterpParams::hessian`: exact Hessian, matrix-free trust-region Newton–CG with
/// a per-frame block preconditioner (default; 10–30× faster than the direct solvers on the
/// coarse corpus, same minimizer).
pub const PLEAT_INTERP_HESSIAN_TRUST_REGION: u32 = 3;

/// A wrinkle animation (opaque): guide frames between two keyframes on one base mesh (a private
/// copy). Created by `pleat_cwf_interpolate` or `pleat_cwf_animation_read_file`, destroyed by
/// `pleat_cwf_animation_destroy`. Immutable: frames may be extracted from several threads at
/// once; destroying it while in use is undefined.
pub struct PleatCwfAnimation {
    #[cfg(feature = "wrinkle")]
    anim: crate::wrinkle::CwfAnimation,
    /// `(seconds, gradient norm)` after the initial guess and each iteration; empty when read
    /// from a file.
    #[cfg(feature = "wrinkle")]
    history: Vec<[f64; 2]>,
}

/// Parameters of `pleat_cwf_interpolate`. Get the defaults from
/// `pleat_wrinkle_interp_params_default()`; `struct_size` versioned as
/// `PleatWrinkleEvalParams`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatWrinkleInterpParams {
    /// `sizeof(PleatWrinkleInterpParams)`; at least 8.
    pub struct_size: u32,
    /// `N'`, guide intervals (guide frames at t = n/N', n = 0..N'), 1 to 100000; default 50.
    /// 1 means plain linear interpolation. Cost grows about linearly with it.
    pub guide_frames: u32,
    /// `k`, linear sub-steps per guide interval, 1 to 100000; default 4. The animation has
    /// `N'·k + 1` playback frames.
    pub substeps: u32,
    /// Newton iteration cap, 0 to 1000000; default 200 (0 returns the initial guess).
    pub max_iterations: u32,
    /// `c = c_scale · g_ave` (penalty of E_compat + E_unit, eq. 3.12); finite, > 0; default 1000.
    pub c_scale: f64,
    /// Stop when the normalized gradient norm is ≤ this; finite, ≥ 0; default 1e-6.
    pub gradient_tolerance: f64,
    /// `PLEAT_INTERP_HESSIAN_*`; default `PLEAT_INTERP_HESSIAN_TRUST_REGION`.
    pub hessian: u32,
    /// Reserved, set to 0.
    pub reserved: u32,
    /// 1 (default): vertices whose star (amplitude, z̃ and ω on the incident edges) is the
    /// same bit for bit in both keyframes (the fixed part of an edit) are held at their
    /// keyframe phase on every frame, so an edit's animation moves only where it changed
    /// (docs/guide/wrinkle-animation.md); 0: every vertex is solved (the dissertation's
    /// literal problem). Appended 2026-11-27: an older, shorter struct gets 1.
    pub locality: u32,
    /// Reserved, set to 0.
    pub reserved2: u32,
}

/// What `pleat_cwf_interpolate` did. Set `struct_size = sizeof(PleatWrinkleInterpStats)`
/// before the call; pleat fills at most that many bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatWrinkleInterpStats {
    /// In: `sizeof(PleatWrinkleInterpStats)` as the caller knows it (≥ 8). Out: bytes filled.
    pub struct_size: u32,
    /// Newton iterations done.
    pub iterations: u32,
    /// `PLEAT_INTERP_STOP_*`.
    pub stop_reason: u32,
    /// Sparse Cholesky factorizations done (including failed, damped ones); for the trust-region
    /// solver, of the per-frame blocks.
    pub factorizations: u32,
    /// Wall seconds of the whole call.
    pub total_seconds: f64,
    /// Normalized gradient norm at the end (the stopping residual).
    pub final_gradient_norm: f64,
    /// Final E_smooth (eq. 3.13).
    pub smooth_energy: f64,
    /// Final time integral of E_compat over the guide frames.
    pub compat_energy: f64,
    /// Final time integral of E_unit over the guide frames.
    pub unit_energy: f64,
    /// g_ave (eq. 3.16, area-weighted mean of a²|ω|⁴; 0 when every amplitude is zero).
    pub g_ave: f64,
    /// The penalty c used.
    pub c: f64,
    /// Vertices held at their keyframe phase by `params->locality` (0 when off). Appended
    /// 2026-11-27: an older, shorter stats struct does not receive it.
    pub pinned_vertices: u64,
}

/// The default interpolation parameters (50 guide frames, 4 sub-steps, 200 iterations,
/// c_scale 1000, tolerance 1e-6, trust-region Newton–CG with the exact Hessian,
/// `PLEAT_INTERP_HESSIAN_TRUST_REGION`), with `struct_size` set. Available in every build.
#[no_mangle]
pub extern "C" fn pleat_wrinkle_interp_params_default() -> PleatWrinkleInterpParams {
    #[cfg(feature = "wrinkle")]
    return PleatWrinkleInterpParams::from(&crate::wrinkle::InterpOptions::default());
    #[cfg(not(feature = "wrinkle"))]
    return defaults_without_wrinkle();
}

#[cfg(feature = "wrinkle")]
impl From<&crate::wrinkle::InterpOptions> for PleatWrinkleInterpParams {
    fn from(o: &crate::wrinkle::InterpOptions) -> Self {
        use crate::wrinkle::HessianModel;
        let count = |n: usize| n.min(u32::MAX as usize) as u32;
        PleatWrinkleInterpParams {
            struct_size: full_size::<PleatWrinkleInterpParams>(),
            guide_frames: count(o.guide_frames),
            substeps: count(o.substeps),
            max_iterations: count(o.max_iterations),
            c_scale: o.c_scale,
            gradient_tolerance: o.gradient_tolerance,
            hessian: match o.hessian {
                HessianModel::Projected => PLEAT_INTERP_HESSIAN_PROJECTED,
                HessianModel::GaussNewton => PLEAT_INTERP_HESSIAN_GAUSS_NEWTON,
                HessianModel::Exact => PLEAT_INTERP_HESSIAN_EXACT,
                HessianModel::TrustRegion => PLEAT_INTERP_HESSIAN_TRUST_REGION,
            },
            reserved: 0,
            locality: o.locality as u32,
            reserved2: 0,
        }
    }
}

/// `InterpOptions::default()` as C, for builds without `wrinkle` (which have no
/// `InterpOptions`); the test `ffi::defaults` pins it to the conversion above.
#[cfg_attr(feature = "wrinkle", allow(dead_code))]
pub(super) fn defaults_without_wrinkle() -> PleatWrinkleInterpParams {
    PleatWrinkleInterpParams {
        struct_size: full_size::<PleatWrinkleInterpParams>(),
        guide_frames: 50,
        substeps: 4,
        max_iterations: 200,
        c_scale: 1e3,
        gradient_tolerance: 1e-6,
        hessian: PLEAT_INTERP_HESSIAN_TRUST_REGION,
        reserved: 0,
        locality: 1,
        reserved2: 0,
    }
}

versioned!(
    PleatWrinkleInterpParams,
    8,
    pleat_wrinkle_interp_params_default
);
versioned!(PleatWrinkleInterpStats, 8);

/// Interpolates between keyframe `a` (t = 0) and keyframe `b` (t = 1) (dissertation §3.4):
/// linear amplitude, the explicit magnitude/angle path of ω, and the phase z̃ on the guide frames
/// from a spacetime Newton solve; keyframes whose ω and z̃ disagree are split per eq. 3.17.
///
/// - `a`, `b`: non-NULL, on the same base mesh (same triangles, positions equal to 1e-9 of the
///   bounding-box diagonal), else `PLEAT_STATUS_INVALID_ARGUMENT` naming the difference.
/// - `params`: NULL = `pleat_wrinkle_interp_params_default()`; ranges in
///   `PleatWrinkleInterpParams`.
/// - `progress`: NULL or a callback, called on the calling thread after every Newton iteration;
///   non-zero cancels (`PLEAT_STATUS_CANCELLED`, no output).
/// - `user_data`: passed to `progress`; may be NULL.
/// - `out`: receives the animation (destroy with `pleat_cwf_animation_destroy`); non-NULL.
/// - `stats`: NULL or a `PleatWrinkleInterpStats` with `struct_size` set; filled on success.
///
/// Reaching the iteration cap or stalling is not an error (`stats->stop_reason` says so).
/// `PLEAT_STATUS_NUMERICAL` when the factorization fails even with heavy damping. Memory and
/// time grow with `vertices × guide_frames`. Output bytes do not depend on the thread count.
///
/// # Safety
/// Pointers are NULL or valid as described; `progress` is a valid function or NULL.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_interpolate(
    a: *const PleatCwf,
    b: *const PleatCwf,
    params: *const PleatWrinkleInterpParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatCwfAnimation,
    stats: *mut PleatWrinkleInterpStats,
) -> PleatStatus {
    wrinkle_only!([a, b, params, progress, user_data, out, stats]
        imp::interpolate(a, b, params, progress, user_data, out, stats))
}

/// The wrinkle field at time `t`: amplitude linear between the keyframes, ω and z̃ linear between
/// the two guide frames around `t`. `t = 0` and `t = 1` reproduce the keyframes exactly.
///
/// - `anim`: non-NULL.
/// - `t`: in [0, 1], not NaN, else `PLEAT_STATUS_INVALID_ARGUMENT`. Playback frame `i` is at
///   `t = i / (pleat_cwf_animation_frame_count(anim) - 1)`.
/// - `out`: receives a new `PleatCwf` (destroy with `pleat_cwf_destroy`); non-NULL.
///
/// Cost: O(vertices + edges) plus a copy of the base mesh.
///
/// # Safety
/// `anim` is NULL or live; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_frame(
    anim: *const PleatCwfAnimation,
    t: f64,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    wrinkle_only!([anim, t, out] guard(|| {
        let an = anim_ref(anim)?;
        let out = arg_out(out, "out")?;
        let cwf = an.anim.frame_at(t)?;
        out.put_boxed(PleatCwf {
            cwf,
            knoppel: None,
            edit: None,
        });
        Ok(())
    }))
}

/// Number of playback frames, `N'·k + 1`; 0 when `anim` is NULL or the build lacks `wrinkle`.
///
/// # Safety
/// `anim` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_frame_count(anim: *const PleatCwfAnimation) -> usize {
    wrinkle_count!(anim, |a| a.anim.frame_count())
}

/// Number of guide intervals `N'` (there are `N' + 1` guide frames); 0 when `anim` is NULL or
/// the build lacks `wrinkle`.
///
/// # Safety
/// `anim` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_guide_count(anim: *const PleatCwfAnimation) -> usize {
    wrinkle_count!(anim, |a| a.anim.guide_intervals())
}

/// Number of convergence-history records (the initial guess and each Newton iteration); 0 for
/// an animation read from a file, a NULL `anim` or a build without `wrinkle`.
///
/// # Safety
/// `anim` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_history_count(
    anim: *const PleatCwfAnimation,
) -> usize {
    wrinkle_count!(anim, |a| a.history.len())
}

/// Copies the convergence history: 2 doubles per record, `(wall seconds since the start of
/// the call, normalized gradient norm)` — error against run time.
///
/// - `anim`, `dst`: non-NULL.
/// - `record_capacity`: records `dst` holds (`2 * record_capacity` doubles);
///   ≥ `pleat_cwf_animation_history_count(anim)`, else `PLEAT_STATUS_LIMIT_EXCEEDED`.
///
/// # Safety
/// `anim` is NULL or live; `dst` is NULL or valid for `2 * record_capacity` doubles.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_copy_history(
    anim: *const PleatCwfAnimation,
    dst: *mut f64,
    record_capacity: usize,
) -> PleatStatus {
    wrinkle_only!([anim, dst, record_capacity] guard(|| {
        let an = anim_ref(anim)?;
        let dst = arg_out(dst, "dst")?;
        if record_capacity < an.history.len() {
            return Err(Error::LimitExceeded(format!(
                "dst holds {record_capacity} records, {} are needed",
                an.history.len()
            )));
        }
        for (i, &v) in an.history.iter().flatten().enumerate() {
            dst.add(i).put(v);
        }
        Ok(())
    }))
}

/// Writes the animation as a `.cwfa` text file (lossless; format in
/// docs/guide/wrinkle-animation.md). The base mesh is not written; store it separately.
///
/// - `anim`: non-NULL.
/// - `path`: NUL-terminated UTF-8 path; non-NULL. An existing file is replaced.
///
/// # Safety
/// `anim` is NULL or live; `path` is NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_write_file(
    anim: *const PleatCwfAnimation,
    path: *const std::ffi::c_char,
) -> PleatStatus {
    wrinkle_only!([anim, path] guard(|| {
        let an = anim_ref(anim)?;
        let path = c_str_arg(path, "path")?;
        crate::wrinkle::write_animation(path, &an.anim)
    }))
}

/// Reads a `.cwfa` file written for `base` (connectivity checked as for `.cwf` files).
///
/// - `base`: non-NULL; pleat keeps its own copy.
/// - `path`: NUL-terminated UTF-8 path; non-NULL.
/// - `out`: receives the animation; non-NULL.
///
/// `PLEAT_STATUS_IO` when unreadable, `PLEAT_STATUS_PARSE` when malformed (message with the
/// line), `PLEAT_STATUS_INVALID_ARGUMENT` for other connectivity or invalid values.
///
/// # Safety
/// `base` is NULL or live; `path` is NULL or NUL-terminated; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_read_file(
    base: *const PleatMesh,
    path: *const std::ffi::c_char,
    out: *mut *mut PleatCwfAnimation,
) -> PleatStatus {
    wrinkle_only!([base, path, out] guard(|| {
        let m = super::mesh::mesh_ref(base, "base")?;
        let path = c_str_arg(path, "path")?;
        let out = arg_out(out, "out")?;
        let anim = crate::wrinkle::read_animation(path, m.clone())?;
        out.put_boxed(PleatCwfAnimation { anim, history: Vec::new() });
        Ok(())
    }))
}

/// Destroys an animation. NULL is accepted and ignored. Destroying twice is undefined.
///
/// # Safety
/// `anim` is NULL or a handle from pleat not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_animation_destroy(anim: *mut PleatCwfAnimation) {
    destroy(anim)
}

/// Borrows an animation handle, failing with InvalidArgument on NULL.
///
/// # Safety
/// `a` is NULL or live.
#[cfg(feature = "wrinkle")]
unsafe fn anim_ref<'a>(a: *const PleatCwfAnimation) -> Result<&'a PleatCwfAnimation> {
    arg_ref(a, "anim")
}

#[cfg(feature = "wrinkle")]
pub(super) mod imp {
    use super::*;
    use crate::ffi::boundary::{bool_field, check_range, read_versioned, versioned_out};
    use crate::ffi::common::guard_progress;
    use crate::wrinkle::{interpolate_with_progress, HessianModel, InterpOptions, StopReason};

    /// The Rust options of C interpolation parameters; the enum and the iteration cap are
    /// checked here, the other ranges by `interpolate` with messages naming the field.
    pub(in crate::ffi) fn options(p: &PleatWrinkleInterpParams) -> Result<InterpOptions> {
        let hessian = match p.hessian {
            PLEAT_INTERP_HESSIAN_PROJECTED => HessianModel::Projected,
            PLEAT_INTERP_HESSIAN_GAUSS_NEWTON => HessianModel::GaussNewton,
            PLEAT_INTERP_HESSIAN_EXACT => HessianModel::Exact,
            PLEAT_INTERP_HESSIAN_TRUST_REGION => HessianModel::TrustRegion,
            h => {
                return Err(Error::InvalidArgument(format!(
                    "params->hessian is {h}; use a PLEAT_INTERP_HESSIAN_* value"
                )))
            }
        };
        check_range(p.max_iterations, 0, 1_000_000, "params->max_iterations")?;
        // the other ranges (guide_frames, substeps, c_scale, tolerance, NaN) are checked by
        // interpolate() with messages naming the field
        Ok(InterpOptions {
            guide_frames: p.guide_frames as usize,
            substeps: p.substeps as usize,
            c_scale: p.c_scale,
            gradient_tolerance: p.gradient_tolerance,
            max_iterations: p.max_iterations as usize,
            hessian,
            locality: bool_field(p.locality, "params->locality")?,
        })
    }

    fn stop_code(s: StopReason) -> u32 {
        match s {
            StopReason::Converged => PLEAT_INTERP_STOP_CONVERGED,
            StopReason::IterationCap => PLEAT_INTERP_STOP_ITERATION_CAP,
            StopReason::Stalled => PLEAT_INTERP_STOP_STALLED,
            StopReason::IdenticalKeyframes => PLEAT_INTERP_STOP_IDENTICAL_KEYFRAMES,
            StopReason::NoUnknowns => PLEAT_INTERP_STOP_NO_UNKNOWNS,
        }
    }

    /// # Safety
    /// As `pleat_cwf_interpolate`.
    pub(super) unsafe fn interpolate(
        a: *const PleatCwf,
        b: *const PleatCwf,
        params: *const PleatWrinkleInterpParams,
        progress: PleatProgressFn,
        user_data: *mut std::ffi::c_void,
        out: *mut *mut PleatCwfAnimation,
        stats: *mut PleatWrinkleInterpStats,
    ) -> PleatStatus {
        guard_progress(progress, user_data, |relay| {
            let ka = arg_ref(a, "a")?;
            let kb = arg_ref(b, "b")?;
            let out = arg_out(out, "out")?;
            let stats = versioned_out(stats, "stats")?;
            let p = read_versioned(params, "params")?;
            let opts = options(&p)?;
            let t0 = std::time::Instant::now();
            let (anim, report) = interpolate_with_progress(&ka.cwf, &kb.cwf, &opts, relay)?;
            let s = PleatWrinkleInterpStats {
                struct_size: 0,
                iterations: report.iterations.min(u32::MAX as usize) as u32,
                stop_reason: stop_code(report.stop),
                factorizations: report.factorizations.min(u32::MAX as usize) as u32,
                total_seconds: t0.elapsed().as_secs_f64(),
                final_gradient_norm: report.final_gradient_norm(),
                smooth_energy: report.smooth_energy,
                compat_energy: report.compat_energy,
                unit_energy: report.unit_energy,
                g_ave: report.g_ave,
                c: report.c,
                pinned_vertices: report.pinned_vertices as u64,
            };
            let history = report
                .history
                .iter()
                .map(|r| [r.seconds, r.gradient_norm])
                .collect();
            out.put_boxed(PleatCwfAnimation { anim, history });
            if let Some(stats) = stats {
                stats.write(s);
            }
            Ok(())
        })
    }
}
