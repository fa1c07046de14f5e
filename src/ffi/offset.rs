//! `pleat_offset_surface`: stage 1 of the LOD pipeline as a standalone operation (ch. 4.5.1).

use super::common::{guard, guard_progress, null_arg, PleatProgressFn, PleatStatus};
use super::mesh::{emit_mesh, mesh_ref, PleatMesh};
use super::stats::{emit_stats, PleatStats};
use crate::Error;

/// Parameters of `pleat_offset_surface`. Get defaults from `pleat_offset_params_default()` and
/// change what you need; `struct_size` lets newer libraries accept older callers.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct PleatOffsetParams {
    /// `sizeof(PleatOffsetParams)` as the caller knows it (set by the default function).
    pub struct_size: u32,
    /// 0: `d = bbox diagonal / screen_size` (default); 1: `d = distance` in model units.
    pub use_absolute_distance: u32,
    /// Screen size n_p in pixels covered by the bounding-box diagonal; > 0. Default 200.
    pub screen_size: f64,
    /// Offset distance d in model units when `use_absolute_distance` is 1; > 0. Default 0.
    pub distance: f64,
    /// Voxel edge as a multiple of d/√3; > 0, at most 2 is sensible. Default 1.
    pub voxel_scale: f64,
    /// Feature-curve dihedral threshold θ0 in degrees, in (0, 180). Default 120.
    pub theta0_deg: f64,
    /// Minimum edges of a real feature curve l0. Default 4.
    pub l0: u32,
    /// 1: insert feature vertices to recover sharp creases (default); 0: plain MC33.
    pub features: u32,
    /// 1: drop components inside other components (default); 0: keep them.
    pub remove_interior: u32,
    /// Secant steps refining each iso-point against the exact distance, 0–64. Default 0.
    pub iso_refinement_steps: u32,
    /// Memory budget of the distance band and extraction in bytes; exceeding it fails with
    /// `PLEAT_STATUS_LIMIT_EXCEEDED` before the expensive work. Default 2 GiB.
    pub memory_budget_bytes: u64,
    /// 1: verify the output with independent checks, recorded in the stats (default); 0: skip.
    pub verify: u32,
    /// Reserved, must be 0.
    pub reserved: u32,
}

/// The default offset parameters (screen size 200, features on, θ0 = 120°, l0 = 4).
#[no_mangle]
pub extern "C" fn pleat_offset_params_default() -> PleatOffsetParams {
    PleatOffsetParams {
        struct_size: std::mem::size_of::<PleatOffsetParams>() as u32,
        use_absolute_distance: 0,
        screen_size: 200.0,
        distance: 0.0,
        voxel_scale: 1.0,
        theta0_deg: 120.0,
        l0: 4,
        features: 1,
        remove_interior: 1,
        iso_refinement_steps: 0,
        memory_budget_bytes: 2 << 30,
        verify: 1,
        reserved: 0,
    }
}

/// Reads a caller's params struct over the defaults, honouring a shorter `struct_size`.
///
/// # Safety
/// `p` is NULL or points to `p->struct_size` readable bytes.
unsafe fn read_params(p: *const PleatOffsetParams) -> crate::Result<PleatOffsetParams> {
    let mut out = pleat_offset_params_default();
    if p.is_null() {
        return Ok(out);
    }
    let size = std::ptr::read_unaligned(p as *const u32) as usize;
    if size < 8 {
        return Err(Error::InvalidArgument(format!(
            "params->struct_size is {size}; initialise params with pleat_offset_params_default()"
        )));
    }
    let n = size.min(std::mem::size_of::<PleatOffsetParams>());
    std::ptr::copy_nonoverlapping(p as *const u8, &mut out as *mut _ as *mut u8, n);
    Ok(out)
}

#[cfg(feature = "lod")]
fn to_rust(p: &PleatOffsetParams) -> crate::Result<crate::lowpoly::OffsetParams> {
    use crate::lowpoly::{OffsetDistance, OffsetParams};
    let flag = |v: u32, name: &str| match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(Error::InvalidArgument(format!(
            "{name} must be 0 or 1, got {v}"
        ))),
    };
    Ok(OffsetParams {
        distance: if flag(p.use_absolute_distance, "use_absolute_distance")? {
            OffsetDistance::Absolute(p.distance)
        } else {
            OffsetDistance::ScreenSize(p.screen_size)
        },
        voxel_scale: p.voxel_scale,
        features: flag(p.features, "features")?,
        theta0_deg: p.theta0_deg,
        l0: p.l0,
        remove_interior: flag(p.remove_interior, "remove_interior")?,
        iso_refinement_steps: p.iso_refinement_steps,
        memory_budget_bytes: p.memory_budget_bytes,
        verify: flag(p.verify, "verify")?,
    })
}

/// Computes the watertight, manifold, self-intersection-free, feature-preserving d-offset
/// surface of any triangle soup (stage 1 of the LOD pipeline, dissertation §4.3.1).
///
/// - `mesh`: the input, any soup; non-NULL.
/// - `params`: NULL for defaults, else initialised by `pleat_offset_params_default()`.
/// - `progress`, `user_data`: optional callback (NULL for none), called on this thread; a
///   non-zero return cancels with `PLEAT_STATUS_CANCELLED`.
/// - `out`: receives the new mesh on success; non-NULL.
/// - `out_stats`: receives a `PleatStats` (destroy with `pleat_stats_destroy`); NULL to skip.
///
/// Errors: `PLEAT_STATUS_INVALID_ARGUMENT` for NULL/NaN/out-of-range parameters,
/// `PLEAT_STATUS_LIMIT_EXCEEDED` when the grid would exceed `memory_budget_bytes`,
/// `PLEAT_STATUS_CANCELLED`, and `PLEAT_STATUS_UNSUPPORTED` in a build without feature `lod`.
///
/// # Safety
/// Pointers are NULL or valid as described.
#[no_mangle]
pub unsafe extern "C" fn pleat_offset_surface(
    mesh: *const PleatMesh,
    params: *const PleatOffsetParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatMesh,
    out_stats: *mut *mut PleatStats,
) -> PleatStatus {
    let checked = guard(|| {
        mesh_ref(mesh, "mesh")?;
        if out.is_null() {
            return Err(null_arg("out"));
        }
        let p = read_params(params)?;
        if p.reserved != 0 {
            return Err(Error::InvalidArgument("params->reserved must be 0".into()));
        }
        Ok(())
    });
    if checked != PleatStatus::Ok {
        return checked;
    }
    #[cfg(feature = "lod")]
    {
        guard_progress(progress, user_data, |relay| {
            let m = mesh_ref(mesh, "mesh")?;
            let p = to_rust(&read_params(params)?)?;
            let (result, stats) = crate::lowpoly::offset_surface_with_progress(m, &p, relay)?;
            emit_mesh(out, result);
            emit_stats(out_stats, stats.entries());
            Ok(())
        })
    }
    #[cfg(not(feature = "lod"))]
    {
        let _ = (progress, user_data, out_stats);
        guard(|| {
            Err(crate::Error::Unsupported(
                "pleat_offset_surface needs feature `lod`".into(),
            ))
        })
    }
}
