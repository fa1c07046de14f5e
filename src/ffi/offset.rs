//! `pleat_offset_surface`: stage 1 of the LOD pipeline as a standalone operation (ch. 4.5.1).

#[cfg(feature = "lod")]
use super::boundary::bool_field;
use super::boundary::{arg_out, full_size, read_versioned, requires, versioned};
#[cfg(feature = "lod")]
use super::common::guard_progress;
use super::common::{guard, PleatProgressFn, PleatStatus};
use super::mesh::{mesh_ref, PleatMesh};
#[cfg(feature = "lod")]
use super::stats::emit_stats;
use super::stats::PleatStats;
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
    #[cfg(feature = "lod")]
    return PleatOffsetParams::from(&crate::lowpoly::OffsetParams::default());
    #[cfg(not(feature = "lod"))]
    return defaults_without_lod();
}

// Smallest size: through `use_absolute_distance`.
versioned!(PleatOffsetParams, 8, pleat_offset_params_default);

#[cfg(feature = "lod")]
impl From<&crate::lowpoly::OffsetParams> for PleatOffsetParams {
    /// An absolute distance leaves `screen_size` 0; a screen size leaves `distance` 0.
    fn from(p: &crate::lowpoly::OffsetParams) -> Self {
        use crate::lowpoly::OffsetDistance;
        let (absolute, screen_size, distance) = match p.distance {
            OffsetDistance::ScreenSize(n_p) => (0, n_p, 0.0),
            OffsetDistance::Absolute(d) => (1, 0.0, d),
        };
        PleatOffsetParams {
            struct_size: full_size::<PleatOffsetParams>(),
            use_absolute_distance: absolute,
            screen_size,
            distance,
            voxel_scale: p.voxel_scale,
            theta0_deg: p.theta0_deg,
            l0: p.l0,
            features: p.features as u32,
            remove_interior: p.remove_interior as u32,
            iso_refinement_steps: p.iso_refinement_steps,
            memory_budget_bytes: p.memory_budget_bytes,
            verify: p.verify as u32,
            reserved: 0,
        }
    }
}

/// `OffsetParams::default()` as C, for builds without `lod` (which have no `OffsetParams`);
/// the test `ffi::defaults` pins it to the conversion above.
#[cfg_attr(feature = "lod", allow(dead_code))]
pub(super) fn defaults_without_lod() -> PleatOffsetParams {
    PleatOffsetParams {
        struct_size: full_size::<PleatOffsetParams>(),
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

/// The Rust parameters of a C struct (the `reserved` field is checked by the caller).
#[cfg(feature = "lod")]
pub(super) fn to_rust(p: &PleatOffsetParams) -> crate::Result<crate::lowpoly::OffsetParams> {
    use crate::lowpoly::{OffsetDistance, OffsetParams};
    Ok(OffsetParams {
        distance: if bool_field(p.use_absolute_distance, "use_absolute_distance")? {
            OffsetDistance::Absolute(p.distance)
        } else {
            OffsetDistance::ScreenSize(p.screen_size)
        },
        voxel_scale: p.voxel_scale,
        features: bool_field(p.features, "features")?,
        theta0_deg: p.theta0_deg,
        l0: p.l0,
        remove_interior: bool_field(p.remove_interior, "remove_interior")?,
        iso_refinement_steps: p.iso_refinement_steps,
        memory_budget_bytes: p.memory_budget_bytes,
        verify: bool_field(p.verify, "verify")?,
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
    // Argument errors come before "unsupported", as they always have for this function.
    let checked = guard(|| {
        mesh_ref(mesh, "mesh")?;
        arg_out(out, "out")?;
        reserved_zero(&read_versioned(params, "params")?)
    });
    if checked != PleatStatus::Ok {
        return checked;
    }
    requires!("lod", [progress, user_data, out_stats], {
        guard_progress(progress, user_data, |relay| {
            let m = mesh_ref(mesh, "mesh")?;
            let out = arg_out(out, "out")?;
            let p = to_rust(&read_versioned(params, "params")?)?;
            let (result, stats) = crate::lowpoly::offset_surface_with_progress(m, &p, relay)?;
            out.put_mesh(result);
            emit_stats(out_stats, stats.entries());
            Ok(())
        })
    })
}

fn reserved_zero(p: &PleatOffsetParams) -> crate::Result<()> {
    if p.reserved != 0 {
        return Err(Error::InvalidArgument("params->reserved must be 0".into()));
    }
    Ok(())
}
