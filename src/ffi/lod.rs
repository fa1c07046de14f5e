//! LODs and cages: `pleat_lod_params_default`, `pleat_lod_generate`,
//! `pleat_lod_generate_chain`, `pleat_cage_generate`.
//!
//! The functions exist in every build; without the cargo feature `lod` (or `cage`) they return
//! `PLEAT_STATUS_UNSUPPORTED`.

#[cfg(feature = "lod")]
use super::boundary::{arg_out, arg_slice, check_flags, read_versioned, versioned_out};
use super::boundary::{full_size, requires, versioned};
#[cfg(feature = "lod")]
use super::common::guard_progress;
use super::common::{PleatProgressFn, PleatStatus};
use super::deform::PleatDeformation;
#[cfg(feature = "lod")]
use super::mesh::mesh_ref;
use super::mesh::PleatMesh;
#[cfg(feature = "lod")]
use crate::{Error, Result};

/// `PleatLodParams::flags` bit: skip the feature-alignment step (Alg. 6).
pub const PLEAT_LOD_NO_ALIGN: u32 = 1;

/// `PleatLodParams::flags` bit: also measure the error floor of the offset stage (stats
/// metric `hausdorff_floor_rel`, the input-to-offset-surface distance over `l`); one more
/// distance measurement per level.
pub const PLEAT_LOD_MEASURE_FLOOR: u32 = 2;

/// `PleatLodParams::flags` bit: `PleatLodParams::clearance` is a length in model units
/// instead of a fraction of the offset distance d.
pub const PLEAT_LOD_CLEARANCE_ABSOLUTE: u32 = 4;

/// `PleatLodParams::flags` bit: skip the final input-plane fit of LODs (QEM vertex placement
/// on the input's planes and normal-improving flips after the loop; ignored for cages).
pub const PLEAT_LOD_NO_FIT: u32 = 8;

/// Parameters of `pleat_lod_generate`, `pleat_lod_generate_chain` and `pleat_cage_generate`.
/// Get the defaults from `pleat_lod_params_default()` and change what you need; the defaults
/// are the dissertation's (n_p = 200, N = 50, r = 1/8, ε = 1e-4, θ0 = 120°, l0 = 4).
///
/// `struct_size` must be `sizeof(PleatLodParams)` as the caller knows it (the default sets
/// it): fields beyond it keep their defaults, so older callers keep working when fields are
/// appended.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct PleatLodParams {
    /// `sizeof(PleatLodParams)`; at least the offset of `target_faces` (16).
    pub struct_size: u32,
    /// Maximum number of optimization rounds N (default 50; 0 returns the offset surface). A
    /// LOD without a face target stops earlier after 5 rounds without a new smallest face
    /// count (since 2026-11-29: later rounds only moved vertices, and the 23-mesh benchmark
    /// kept or improved every aggregate).
    pub max_rounds: u32,
    /// Screen size n_p in pixels covered by the input's bounding-box diagonal l (default 200).
    /// The offset distance and error bound is d = l / n_p. Finite and > 0.
    pub screen_size: f64,
    /// Target triangle count n_F, or 0 for none (minimise the count). At least 4 when set.
    pub target_faces: u64,
    /// Flow fraction r in (0, 1] (default 0.125).
    pub flow_ratio: f64,
    /// Convergence threshold ε relative to l (default 1e-4), >= 0.
    pub epsilon: f64,
    /// Feature-curve dihedral threshold θ0 in degrees, (0, 180) (default 120).
    pub theta0_deg: f64,
    /// Minimum feature-curve length l0 in edges (default 4).
    pub l0: u32,
    /// Bitwise OR of `PLEAT_LOD_*` flags (default 0).
    pub flags: u32,
    /// Upper bound on the bake's memory in bytes (default 2 GiB); exceeding the estimate fails
    /// with `PLEAT_STATUS_LIMIT_EXCEEDED` before the expensive work.
    pub memory_budget_bytes: u64,
    /// Cages only: the distance the cage keeps from the input, as a fraction of d (default
    /// 0.05: a twentieth of a pixel at the cage's screen size, see docs/benchmarks/cage.md), or
    /// in model units with `PLEAT_LOD_CLEARANCE_ABSOLUTE`. Must be >= 0 and below d; 0 keeps
    /// only "no contact". Appended 2026-11-25; callers with an older `struct_size` get the
    /// default.
    pub clearance: f64,
    /// LODs only: the surface the loop starts from: 0 = auto (the welded input when it is
    /// clean — closed, manifold, consistently and outward oriented, no degenerate face,
    /// self-intersection-free — else the offset surface), 1 = the offset surface at d,
    /// 2 = the welded input (`PLEAT_STATUS_INVALID_ARGUMENT` naming the failing property when
    /// it is not clean). Other values are `PLEAT_STATUS_INVALID_ARGUMENT`. Cages always start
    /// from the offset surface. Appended 2026-11-27; callers with an older `struct_size`
    /// get 0 (auto).
    pub start: u32,
    /// Reserved, 0 (keeps the struct free of padding).
    pub reserved: u32,
    /// LODs only: the offset voxel the bake starts from, as a multiple of d/√3, in (0, 2];
    /// 0 (the default) = automatic (2 from n_p = 200 on, 1.25 from 100, 1 below; see
    /// docs/design-notes-lod.md, "Offset stage"). A coarser voxel is still taken when the memory
    /// estimate needs it. NaN, negative or > 2 is `PLEAT_STATUS_INVALID_ARGUMENT`. Appended
    /// 2026-11-27; callers with an older `struct_size` get automatic.
    pub offset_voxel_scale: f64,
    /// LODs only: the skin and morph targets the levels must follow when posed
    /// (`pleat_deformation_create`, made for this input), or NULL (the default) for a static
    /// mesh. The handle must stay alive during the call. Appended 2026-12-08; callers with an
    /// older `struct_size` get NULL.
    pub deformation: *const PleatDeformation,
}

/// `PleatLodParams::start`: the welded input when clean, else the offset surface.
pub const PLEAT_LOD_START_AUTO: u32 = 0;
/// `PleatLodParams::start`: the offset surface at d.
pub const PLEAT_LOD_START_OFFSET: u32 = 1;
/// `PleatLodParams::start`: the welded input, which must be clean.
pub const PLEAT_LOD_START_INPUT: u32 = 2;

/// Statistics of one baked level, filled when a non-NULL pointer is passed. Set `struct_size`
/// to `sizeof(PleatLodStats)`; pleat fills only that many bytes. Yes/no fields are 0 or 1.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct PleatLodStats {
    /// In: `sizeof(PleatLodStats)` as the caller knows it. Out: the bytes pleat filled.
    pub struct_size: u32,
    /// Optimization rounds run.
    pub rounds: u32,
    /// Triangles of the result.
    pub face_count: u64,
    /// Vertices of the result.
    pub vertex_count: u64,
    /// Triangles of the start surface (offset surface, or the finer level in a chain).
    pub start_face_count: u64,
    /// Edge collapses performed.
    pub collapse_count: u64,
    /// Wall seconds, total.
    pub seconds_total: f64,
    /// Wall seconds of the offset stage.
    pub seconds_offset: f64,
    /// Wall seconds of simplification (Alg. 5), summed over rounds.
    pub seconds_simplify: f64,
    /// Wall seconds of the flow, summed over rounds.
    pub seconds_flow: f64,
    /// Wall seconds of the feature alignment, summed over rounds.
    pub seconds_align: f64,
    /// Wall seconds of the independent verification.
    pub seconds_verify: f64,
    /// Offset distance d = l / n_p, in model units.
    pub offset_distance: f64,
    /// Two-sided sampled Hausdorff distance between result and input, model units.
    pub hausdorff: f64,
    /// `hausdorff / l` (l = the input's bounding-box diagonal).
    pub hausdorff_relative: f64,
    /// 1: verified closed and manifold.
    pub watertight: u32,
    /// 1: verified manifold and consistently oriented.
    pub manifold: u32,
    /// 1: verified free of self-intersections (exact predicates).
    pub self_intersection_free: u32,
    /// Cages: 1 when verified to enclose every input vertex without touching the input.
    /// LODs: 0.
    pub encloses_input: u32,
    /// 1 when the result was recomputed with exact checks only (see docs/guide/lod.md).
    pub exact_rerun: u32,
    /// 1 when a target face count was given and met.
    pub target_met: u32,
    /// The one-sided parts of `hausdorff_relative`: input to result (input the result does
    /// not cover) ...
    pub hausdorff_in_to_out_relative: f64,
    /// ... and result to input.
    pub hausdorff_out_to_in_relative: f64,
    /// With `PLEAT_LOD_MEASURE_FLOOR`, on levels baked from the offset surface: the distance
    /// from the input to the offset surface over `l`, the floor of
    /// `hausdorff_in_to_out_relative` (input the offset hides). NaN otherwise. Its time is
    /// the stats stage `floor` and is included in `seconds_total`.
    pub hausdorff_floor_relative: f64,
    /// Cages: the exact minimum distance between the cage's and the input's triangles, in
    /// model units, measured independently of the guard (not sampled). NaN for LODs.
    pub min_clearance: f64,
    /// Cages: `min_clearance / l`. NaN for LODs.
    pub min_clearance_relative: f64,
    /// Cages: the clearance that was required, in model units. NaN for LODs.
    pub clearance_required: f64,
    /// Cages: 1 when `min_clearance >= clearance_required`; 0 when the cage could not keep
    /// the clearance (it still encloses without contact — see `encloses_input`). LODs: 0.
    pub clearance_kept: u32,
    /// 1 when the level's loop started from the welded input (`PleatLodParams::start`; in a
    /// chain only the finest level can), 0 when from the offset surface or a finer level.
    pub started_from_input: u32,
    /// When the level was admitted by measurement (its up-front memory estimate fitted no offset
    /// voxel scale, so the offset stage counted its surface before allocating it): the peak bytes
    /// estimated from those counts, which fitted the memory budget. NaN otherwise.
    pub measured_estimate_bytes: f64,
    /// In a chain: 1 when this coarser level started from the next finer level's loop output
    /// before its fit (its own offset surface had the finer level's topology), 0 when from its
    /// own offset surface, and for the finest level or a single bake.
    pub started_from_finer: u32,
    /// 1 when the loop ended because `STALL_ROUNDS` (5) rounds in a row made no new smallest
    /// face count (LODs without a face target).
    pub stalled: u32,
    /// 1 when the last round's convergence test passed (change below `epsilon · l`).
    pub converged: u32,
    /// 1 when the input-plane fit was reverted because the Hausdorff distance grew (the
    /// result is the loop's output).
    pub fit_reverted: u32,
    /// Wall seconds of the input-plane fit (with the measurement of its safety revert).
    pub seconds_fit: f64,
    /// Wall seconds of the Hausdorff measurement. With `seconds_offset`, `seconds_simplify`,
    /// `seconds_flow`, `seconds_align`, `seconds_fit`, `seconds_verify` and the stages not
    /// listed (convergence tests, the floor and, for cages, the clearance measurement), this
    /// makes up `seconds_total`.
    pub seconds_measure: f64,
    /// Rank of the level in a chain, 0 = finest (baked first); -1 for a single bake.
    pub chain_level: i64,
}

/// The defaults, with `struct_size = sizeof(PleatLodParams)`.
#[no_mangle]
pub extern "C" fn pleat_lod_params_default() -> PleatLodParams {
    #[cfg(feature = "lod")]
    return PleatLodParams::from(&crate::lowpoly::LodParams::default());
    #[cfg(not(feature = "lod"))]
    return defaults_without_lod();
}

// Smallest sizes: through `screen_size` (params), through `rounds` (stats).
versioned!(PleatLodParams, 16, pleat_lod_params_default);
versioned!(PleatLodStats, 8);

#[cfg(feature = "lod")]
use crate::lowpoly::{Clearance, LodStart};

#[cfg(feature = "lod")]
impl From<&crate::lowpoly::LodParams> for PleatLodParams {
    fn from(p: &crate::lowpoly::LodParams) -> Self {
        let flag = |on: bool, bit: u32| if on { bit } else { 0 };
        PleatLodParams {
            struct_size: full_size::<PleatLodParams>(),
            max_rounds: p.max_rounds,
            screen_size: p.screen_size,
            target_faces: p.target_faces.map_or(0, |n| n as u64),
            flow_ratio: p.flow_ratio,
            epsilon: p.epsilon,
            theta0_deg: p.theta0_deg,
            l0: p.l0,
            flags: flag(!p.align, PLEAT_LOD_NO_ALIGN)
                | flag(p.measure_floor, PLEAT_LOD_MEASURE_FLOOR)
                | flag(
                    matches!(p.clearance, Clearance::Absolute(_)),
                    PLEAT_LOD_CLEARANCE_ABSOLUTE,
                )
                | flag(!p.fit_to_input, PLEAT_LOD_NO_FIT),
            memory_budget_bytes: p.memory_budget_bytes,
            clearance: match p.clearance {
                Clearance::FractionOfD(c) | Clearance::Absolute(c) => c,
            },
            start: match p.start {
                LodStart::Auto => PLEAT_LOD_START_AUTO,
                LodStart::Offset => PLEAT_LOD_START_OFFSET,
                LodStart::Input => PLEAT_LOD_START_INPUT,
            },
            reserved: 0,
            offset_voxel_scale: p.offset_voxel_scale.unwrap_or(0.0),
            // A Rust field has no C handle: callers set the pointer themselves.
            deformation: std::ptr::null(),
        }
    }
}

/// `LodParams::default()` as C, for builds without `lod` (which have no `LodParams`); the
/// test `ffi::defaults` pins it to the conversion above.
#[cfg_attr(feature = "lod", allow(dead_code))]
pub(super) fn defaults_without_lod() -> PleatLodParams {
    PleatLodParams {
        struct_size: full_size::<PleatLodParams>(),
        max_rounds: 50,
        screen_size: 200.0,
        target_faces: 0,
        flow_ratio: 0.125,
        epsilon: 1e-4,
        theta0_deg: 120.0,
        l0: 4,
        flags: 0,
        memory_budget_bytes: 2 << 30,
        clearance: 0.05,
        start: PLEAT_LOD_START_AUTO,
        reserved: 0,
        offset_voxel_scale: 0.0,
        deformation: std::ptr::null(),
    }
}

#[cfg(feature = "lod")]
pub(super) mod imp {
    use super::*;
    use crate::lowpoly::{LodParams, LodReport, LodStage};
    use crate::mesh::TriMesh;

    /// The Rust parameters of C LOD parameters (flags and `target_faces` checked here, the
    /// rest by the pipeline).
    ///
    /// # Safety
    /// `p.deformation` is NULL or a live handle from `pleat_deformation_create`.
    pub(in crate::ffi) unsafe fn to_rust(p: &PleatLodParams) -> Result<LodParams> {
        let target = match p.target_faces {
            0 => None,
            n => Some(usize::try_from(n).map_err(|_| {
                Error::InvalidArgument(format!("target_faces {n} is out of range"))
            })?),
        };
        check_flags(
            p.flags,
            PLEAT_LOD_NO_ALIGN
                | PLEAT_LOD_MEASURE_FLOOR
                | PLEAT_LOD_CLEARANCE_ABSOLUTE
                | PLEAT_LOD_NO_FIT,
            "params->flags",
        )?;
        if p.reserved != 0 {
            return Err(Error::InvalidArgument(format!(
                "params->reserved must be 0, got {}",
                p.reserved
            )));
        }
        let start = match p.start {
            PLEAT_LOD_START_AUTO => LodStart::Auto,
            PLEAT_LOD_START_OFFSET => LodStart::Offset,
            PLEAT_LOD_START_INPUT => LodStart::Input,
            v => {
                return Err(Error::InvalidArgument(format!(
                    "params->start must be 0 (auto), 1 (offset) or 2 (input), got {v}"
                )))
            }
        };
        Ok(LodParams {
            start,
            screen_size: p.screen_size,
            target_faces: target,
            max_rounds: p.max_rounds,
            flow_ratio: p.flow_ratio,
            epsilon: p.epsilon,
            theta0_deg: p.theta0_deg,
            l0: p.l0,
            memory_budget_bytes: p.memory_budget_bytes,
            align: p.flags & PLEAT_LOD_NO_ALIGN == 0,
            measure_floor: p.flags & PLEAT_LOD_MEASURE_FLOOR != 0,
            fit_to_input: p.flags & PLEAT_LOD_NO_FIT == 0,
            clearance: if p.flags & PLEAT_LOD_CLEARANCE_ABSOLUTE != 0 {
                Clearance::Absolute(p.clearance)
            } else {
                Clearance::FractionOfD(p.clearance)
            },
            offset_voxel_scale: voxel_scale_to_rust(p.offset_voxel_scale)?,
            deformation: p.deformation.as_ref().map(|d| d.field.clone()),
        })
    }

    /// `PleatLodParams::offset_voxel_scale`: 0 is automatic (`None`), a value in (0, 2] is
    /// passed on, anything else (NaN, negative, infinite, > 2) is `InvalidArgument`.
    fn voxel_scale_to_rust(s: f64) -> Result<Option<f64>> {
        if s == 0.0 {
            return Ok(None);
        }
        if !(s.is_finite() && s > 0.0 && s <= 2.0) {
            return Err(Error::InvalidArgument(format!(
                "params->offset_voxel_scale must be 0 (automatic) or in (0, 2], got {s}"
            )));
        }
        Ok(Some(s))
    }

    /// One LOD or cage of `m` with the C parameters `p`.
    ///
    /// # Safety
    /// As [`to_rust`].
    pub(super) unsafe fn bake(
        m: &TriMesh,
        p: &PleatLodParams,
        cage: bool,
        prog: &mut crate::report::ProgressFn<'_>,
    ) -> Result<(TriMesh, LodReport)> {
        let rp = to_rust(p)?;
        if cage {
            #[cfg(feature = "cage")]
            return crate::cage::generate(m, &rp, prog);
        }
        crate::lowpoly::generate(m, &rp, prog)
    }

    /// The LOD chain of `m` at `sizes` with the C parameters `p`.
    ///
    /// # Safety
    /// As [`to_rust`].
    pub(super) unsafe fn bake_chain(
        m: &TriMesh,
        sizes: &[f64],
        p: &PleatLodParams,
        prog: &mut crate::report::ProgressFn<'_>,
    ) -> Result<Vec<(TriMesh, LodReport)>> {
        crate::lowpoly::generate_chain(m, sizes, &to_rust(p)?, prog)
    }

    /// 1 when the guarantee was checked and holds, else 0.
    fn flag(v: Option<bool>) -> u32 {
        (v == Some(true)) as u32
    }

    /// The C stats, field by field from the typed report.
    pub(in crate::ffi) fn to_c(mesh: &TriMesh, s: &LodReport) -> PleatLodStats {
        let v = &s.verified;
        PleatLodStats {
            struct_size: std::mem::size_of::<PleatLodStats>() as u32,
            rounds: s.rounds as u32,
            face_count: mesh.triangle_count() as u64,
            vertex_count: mesh.vertex_count() as u64,
            start_face_count: s.faces_offset,
            collapse_count: s.simplify.collapses,
            seconds_total: s.total_seconds(),
            seconds_offset: s.stages.seconds(LodStage::Offset),
            seconds_simplify: s.stages.seconds(LodStage::Simplify),
            seconds_flow: s.stages.seconds(LodStage::Flow),
            seconds_align: s.stages.seconds(LodStage::Align),
            seconds_verify: s.stages.seconds(LodStage::Verify),
            offset_distance: s.d,
            hausdorff: s.hausdorff,
            hausdorff_relative: s.hausdorff_rel,
            watertight: flag(v.watertight),
            manifold: flag(v.manifold),
            self_intersection_free: flag(v.self_intersection_free),
            encloses_input: flag(v.cage_encloses_without_touching),
            exact_rerun: (s.reruns_exact > 0) as u32,
            target_met: s.target_met as u32,
            hausdorff_in_to_out_relative: s.hausdorff_in_to_out_rel,
            hausdorff_out_to_in_relative: s.hausdorff_out_to_in_rel,
            hausdorff_floor_relative: s.floor.map_or(f64::NAN, |f| f.rel),
            min_clearance: s.clearance.map_or(f64::NAN, |c| c.min),
            min_clearance_relative: s.clearance.map_or(f64::NAN, |c| c.min_rel),
            clearance_required: s.clearance.map_or(f64::NAN, |c| c.required),
            clearance_kept: s.clearance.is_some_and(|c| c.kept) as u32,
            started_from_input: s.started_from_input as u32,
            measured_estimate_bytes: s.measured_estimate_bytes.unwrap_or(f64::NAN),
            started_from_finer: s.started_from_finer as u32,
            stalled: s.stalled as u32,
            converged: s.converged as u32,
            fit_reverted: s.fit_reverted as u32,
            seconds_fit: s.stages.seconds(LodStage::Fit),
            seconds_measure: s.stages.seconds(LodStage::Measure),
            chain_level: s.chain_level.map_or(-1, |r| r as i64),
        }
    }
}

/// The shared body of `pleat_lod_generate` and `pleat_cage_generate`.
///
/// # Safety
/// As those functions.
unsafe fn generate_one(
    cage: bool,
    input: *const PleatMesh,
    params: *const PleatLodParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatMesh,
    stats: *mut PleatLodStats,
) -> PleatStatus {
    requires!(
        "lod",
        [cage, input, params, progress, user_data, out, stats],
        {
            if cage && !cfg!(feature = "cage") {
                return super::common::unsupported("cage");
            }
            guard_progress(progress, user_data, |prog| {
                let m = mesh_ref(input, "input")?;
                let out = arg_out(out, "out")?;
                let p = read_versioned(params, "params")?;
                let stats = versioned_out(stats, "stats")?;
                let (mesh, st) = imp::bake(m, &p, cage, prog)?;
                if let Some(s) = stats {
                    s.write(imp::to_c(&mesh, &st));
                }
                out.put_mesh(mesh);
                Ok(())
            })
        }
    )
}

/// Bakes one LOD of `input` (any triangle soup): a watertight, manifold,
/// self-intersection-free mesh within about d = l / n_p of the input, with as few triangles
/// as possible (or `params->target_faces`).
///
/// - `input`: non-NULL mesh handle.
/// - `params`: NULL for the defaults, else from `pleat_lod_params_default()` (checked:
///   `struct_size` >= 16, finite screen size > 0, flow ratio in (0, 1], ...).
/// - `progress`: NULL or a callback, called on the calling thread; non-zero cancels
///   (`PLEAT_STATUS_CANCELLED`). `user_data` is passed to it unchanged (may be NULL).
/// - `out`: non-NULL; receives a new mesh on success (destroy with `pleat_mesh_destroy`).
/// - `stats`: NULL, or a `PleatLodStats` with `struct_size` set, filled on success.
///
/// Returns `PLEAT_STATUS_UNSUPPORTED` when built without the `lod` feature.
///
/// # Safety
/// Pointers are NULL or valid for the sizes stated; `input` is a live handle.
#[no_mangle]
pub unsafe extern "C" fn pleat_lod_generate(
    input: *const PleatMesh,
    params: *const PleatLodParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatMesh,
    stats: *mut PleatLodStats,
) -> PleatStatus {
    generate_one(false, input, params, progress, user_data, out, stats)
}

/// Bakes a cage of `input` (any triangle soup): watertight, manifold, self-intersection-free,
/// enclosing every input vertex without touching the input, at offset d = l / n_p, and keeping
/// `params->clearance` from it. Parameters as `pleat_lod_generate`; `stats->encloses_input`
/// reports the verification, `stats->min_clearance` the exact measured clearance and
/// `stats->clearance_kept` whether the requested one was kept (0 when the start surface was
/// already closer: the call still succeeds — check the flag).
/// Returns `PLEAT_STATUS_UNSUPPORTED` when built without the `cage` feature.
///
/// # Safety
/// As `pleat_lod_generate`.
#[no_mangle]
pub unsafe extern "C" fn pleat_cage_generate(
    input: *const PleatMesh,
    params: *const PleatLodParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatMesh,
    stats: *mut PleatLodStats,
) -> PleatStatus {
    generate_one(true, input, params, progress, user_data, out, stats)
}

/// Bakes one LOD per screen size. A coarser level starts from the next finer level's loop
/// output (before that level's input-plane fit) when its own offset surface has the finer
/// level's topology, else from that offset surface (then it is the level `pleat_lod_generate`
/// bakes). On a pool of more than one thread, independent levels
/// run at the same time, with the results of a one-thread run; the progress callback is still
/// called on the calling thread only, with fractions that never go back. A chain
/// {50, 100, 200} takes about 1.3x the wall time of its finest level alone (corpus median).
///
/// - `screen_sizes`: `count` screen sizes (any order; each finite and > 0), `count` >= 1.
/// - `params`: as `pleat_lod_generate`; `screen_size` and `target_faces` are ignored.
/// - `out_meshes`: array of `count` pointers; on success `out_meshes[i]` is the level of
///   `screen_sizes[i]` (destroy each with `pleat_mesh_destroy`). Nothing is written on failure.
/// - `stats`: NULL, or an array of `count` `PleatLodStats` whose first element's `struct_size`
///   gives the element size used for all.
///
/// # Safety
/// Pointers are NULL or valid for the sizes stated.
#[no_mangle]
pub unsafe extern "C" fn pleat_lod_generate_chain(
    input: *const PleatMesh,
    screen_sizes: *const f64,
    count: usize,
    params: *const PleatLodParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out_meshes: *mut *mut PleatMesh,
    stats: *mut PleatLodStats,
) -> PleatStatus {
    requires!(
        "lod",
        [
            input,
            screen_sizes,
            count,
            params,
            progress,
            user_data,
            out_meshes,
            stats
        ],
        {
            guard_progress(progress, user_data, |prog| {
                let m = mesh_ref(input, "input")?;
                let sizes = arg_slice(screen_sizes, count, "screen_sizes")?;
                let out = arg_out(out_meshes, "out_meshes")?;
                if count == 0 || count > 64 {
                    return Err(Error::InvalidArgument(format!(
                        "count is {count}; give 1 to 64 screen sizes"
                    )));
                }
                let p = read_versioned(params, "params")?;
                let stats = versioned_out(stats, "stats")?;
                let levels = imp::bake_chain(m, sizes, &p, prog)?;
                for (i, (mesh, st)) in levels.into_iter().enumerate() {
                    if let Some(s) = &stats {
                        s.write_at(i, imp::to_c(&mesh, &st));
                    }
                    out.add(i).put_mesh(mesh);
                }
                Ok(())
            })
        }
    )
}

#[cfg(all(test, feature = "lod"))]
mod tests {
    use super::imp::to_c;
    use crate::lowpoly::{LodReport, LodStage};
    use crate::mesh::test_shapes::grid;

    /// The fields appended 2026-11-29 carry the typed report's: the chain rank (-1 outside
    /// a chain), the loop's end flags and the fit and measure stage seconds.
    #[test]
    fn chain_and_loop_fields_come_from_the_report() {
        let mesh = grid(1, 1);
        let mut r = LodReport::default();
        let single = to_c(&mesh, &r);
        assert_eq!(single.chain_level, -1);
        assert_eq!(
            (single.started_from_finer, single.stalled, single.converged),
            (0, 0, 0)
        );
        r.chain_level = Some(2);
        r.started_from_finer = true;
        r.stalled = true;
        r.fit_reverted = true;
        r.stages.push(LodStage::Fit, 0.25);
        r.stages.push(LodStage::Measure, 0.5);
        let c = to_c(&mesh, &r);
        assert_eq!(c.chain_level, 2);
        assert_eq!(
            (c.started_from_finer, c.stalled, c.converged, c.fit_reverted),
            (1, 1, 0, 1)
        );
        assert_eq!((c.seconds_fit, c.seconds_measure), (0.25, 0.5));
        assert_eq!(c.seconds_total, 0.75);
    }
}
