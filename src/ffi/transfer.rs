//! Attribute transfer from C: `pleat_transfer_create` computes the LOD→input correspondence
//! once (`crate::transfer::Correspondence`); `pleat_transfer_f32`, `pleat_transfer_u32` and
//! `pleat_transfer_skin` apply it to any number of per-vertex arrays of the input (UVs,
//! colours, morph deltas, ids, skin weights); `pleat_transfer_destroy` frees it.
//!
//! The functions exist in every build; without the cargo feature `lod` they return
//! `PLEAT_STATUS_UNSUPPORTED`.

use super::boundary::{destroy, full_size, requires, versioned};
use super::common::PleatStatus;
use super::mesh::PleatMesh;

/// `pleat_transfer_f32` mode: interpolated with the barycentric coordinates of the LOD
/// vertex's corresponding input point (UVs, colours, morph deltas).
pub const PLEAT_TRANSFER_BARYCENTRIC: u32 = 0;
/// `pleat_transfer_f32` mode: the value of the input triangle's corner nearest to the
/// corresponding point (values that must not be mixed).
pub const PLEAT_TRANSFER_NEAREST: u32 = 1;

/// `PleatTransferParams::lookup`: cast along the LOD vertex normal within the envelope,
/// nearest hit, the closest input point when nothing is hit (the default).
pub const PLEAT_TRANSFER_LOOKUP_CAST: u32 = 0;
/// `PleatTransferParams::lookup`: the closest input point.
pub const PLEAT_TRANSFER_LOOKUP_CLOSEST: u32 = 1;

/// Most components per vertex `k` (and influences per input vertex `m`) the transfer calls
/// take.
pub const PLEAT_TRANSFER_MAX_COMPONENTS: usize = 1 << 16;

/// Parameters of `pleat_transfer_create`. Get the defaults from
/// `pleat_transfer_params_default()`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatTransferParams {
    /// `sizeof(PleatTransferParams)`.
    pub struct_size: u32,
    /// `PLEAT_TRANSFER_LOOKUP_CAST` (default) or `PLEAT_TRANSFER_LOOKUP_CLOSEST`.
    pub lookup: u32,
    /// Screen size n_p the LOD was made at (default 200; finite, > 0): d = l / n_p.
    pub screen_size: f64,
    /// Half-length of the cast along the normal, in d (default 3; finite, > 0).
    pub envelope_d: f64,
    /// Wrong-input bound, in d = l_lod / n_p (default 4; finite, > 0): every LOD vertex must
    /// lie within it of the input, and each side of the input's bounding box within it of
    /// the LOD's.
    pub max_distance_d: f64,
    /// Jacobi smoothing iterations of skin weights over the LOD's one-ring before the top-k
    /// (default 0, the measured rule; at most 64).
    pub skin_smoothing: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

versioned!(PleatTransferParams, 40, pleat_transfer_params_default);

/// A LOD→input correspondence (opaque), made by `pleat_transfer_create`, freed by
/// `pleat_transfer_destroy`. Immutable, so it may be used from several threads at once.
pub struct PleatTransfer {
    #[cfg(feature = "lod")]
    pub(crate) corr: crate::transfer::Correspondence,
    #[cfg(feature = "lod")]
    pub(crate) skin_smoothing: u32,
}

/// The transfer defaults (`pleat::transfer::TransferParams::default()`: n_p = 200, envelope
/// 3 d, wrong-input bound 4 d, cast lookup, no skin smoothing), with `struct_size` set.
#[no_mangle]
pub extern "C" fn pleat_transfer_params_default() -> PleatTransferParams {
    PleatTransferParams {
        struct_size: full_size::<PleatTransferParams>(),
        lookup: PLEAT_TRANSFER_LOOKUP_CAST,
        screen_size: 200.0,
        envelope_d: 3.0,
        max_distance_d: 4.0,
        skin_smoothing: 0,
        reserved: 0,
    }
}

#[cfg(feature = "lod")]
pub(super) mod imp {
    use super::*;
    use crate::ffi::boundary::{check_f64, check_range};
    use crate::transfer::{Correspondence, Lookup, TransferParams};
    use crate::{Error, Result};

    /// The Rust parameters of the C ones (checked).
    pub(in crate::ffi) fn to_rust(p: &PleatTransferParams) -> Result<TransferParams> {
        for (v, name) in [
            (p.screen_size, "params->screen_size"),
            (p.envelope_d, "params->envelope_d"),
            (p.max_distance_d, "params->max_distance_d"),
        ] {
            check_f64(v, v.is_finite() && v > 0.0, name, "finite and > 0")?;
        }
        check_range(p.skin_smoothing, 0, 64, "params->skin_smoothing")?;
        if p.reserved != 0 {
            return Err(Error::InvalidArgument(format!(
                "params->reserved must be 0, got {}",
                p.reserved
            )));
        }
        let lookup = match p.lookup {
            PLEAT_TRANSFER_LOOKUP_CAST => Lookup::Cast,
            PLEAT_TRANSFER_LOOKUP_CLOSEST => Lookup::ClosestPoint,
            v => {
                return Err(Error::InvalidArgument(format!(
                    "params->lookup must be 0 (cast) or 1 (closest), got {v}"
                )))
            }
        };
        Ok(TransferParams {
            screen_size: p.screen_size,
            envelope_factor: p.envelope_d,
            max_distance_factor: p.max_distance_d,
            lookup,
        })
    }

    /// Checks the counts a transfer call states against the handle's, before any array is
    /// read: `n_input` and `n_lod` exactly the vertex counts, `k` in 1..=65536.
    pub(in crate::ffi) fn check_counts(
        c: &Correspondence,
        n_input: usize,
        k: usize,
        k_name: &str,
        n_lod: usize,
    ) -> Result<(usize, usize)> {
        if n_input != c.input_vertex_count() {
            return Err(Error::InvalidArgument(format!(
                "n_input is {n_input}; the input has {} vertices",
                c.input_vertex_count()
            )));
        }
        if n_lod != c.lod_vertex_count() {
            return Err(Error::InvalidArgument(format!(
                "n_lod is {n_lod}; the LOD has {} vertices",
                c.lod_vertex_count()
            )));
        }
        if k == 0 || k > PLEAT_TRANSFER_MAX_COMPONENTS {
            return Err(Error::InvalidArgument(format!(
                "{k_name} is {k}; allowed 1 to {PLEAT_TRANSFER_MAX_COMPONENTS}"
            )));
        }
        // Both products fit: the vertex counts are those of meshes in memory.
        Ok((n_input * k, n_lod * k))
    }

    /// Copies `v` to the caller's array `out` (non-NULL, checked before).
    ///
    /// # Safety
    /// `out` holds `v.len()` writable values.
    pub(in crate::ffi) unsafe fn write<T: Copy>(v: &[T], out: *mut T) {
        std::ptr::copy_nonoverlapping(v.as_ptr(), out, v.len());
    }
}

#[cfg(feature = "lod")]
use super::boundary::{arg_out, arg_ref, arg_slice, guard_value, non_null, read_versioned};
#[cfg(feature = "lod")]
use super::common::guard;
#[cfg(feature = "lod")]
use super::mesh::mesh_ref;

/// Computes the correspondence of every vertex of `lod` on `input`, once, for any number of
/// `pleat_transfer_*` calls: per LOD vertex an input triangle and barycentric coordinates,
/// by a cast along the LOD's vertex normal within `envelope_d · d` (nearest hit), else the
/// closest input point. Deterministic, whatever the thread count.
///
/// - `input`: the mesh the LOD was made from; `lod`: a LOD or cage of it
///   (`pleat_lod_generate*`, `pleat_cage_generate`); non-NULL, with triangles.
/// - `params`: NULL for the defaults, else from `pleat_transfer_params_default()` with
///   `screen_size` set to the LOD's.
/// - `out`: non-NULL; receives the handle (destroy with `pleat_transfer_destroy`).
///
/// Returns `PLEAT_STATUS_INVALID_ARGUMENT` when `input` is not the mesh this LOD was made
/// from: some LOD vertex farther than `max_distance_d · l_lod / n_p` from the input, or a
/// side of the bounding boxes that far apart (the message names the vertex or the side);
/// or when `screen_size` is much larger than the LOD's.
///
/// # Safety
/// Handles are NULL or live; `params` is NULL or valid for `params->struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_transfer_create(
    input: *const PleatMesh,
    lod: *const PleatMesh,
    params: *const PleatTransferParams,
    out: *mut *mut PleatTransfer,
) -> PleatStatus {
    requires!("lod", [input, lod, params, out], {
        guard(|| {
            let input = mesh_ref(input, "input")?;
            let lod = mesh_ref(lod, "lod")?;
            let out = arg_out(out, "out")?;
            let p = read_versioned(params, "params")?;
            let rp = imp::to_rust(&p)?;
            let corr = crate::transfer::Correspondence::new(input, lod, &rp)?;
            out.put_boxed(PleatTransfer {
                corr,
                skin_smoothing: p.skin_smoothing,
            });
            Ok(())
        })
    })
}

/// Destroys a transfer handle. NULL is accepted and ignored.
///
/// # Safety
/// `transfer` is NULL or a handle from `pleat_transfer_create` not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_transfer_destroy(transfer: *mut PleatTransfer) {
    destroy(transfer)
}

/// Number of LOD vertices of `transfer` (the rows of every output; 0 when NULL or in a build
/// without `lod`).
///
/// # Safety
/// `transfer` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn pleat_transfer_lod_vertex_count(transfer: *const PleatTransfer) -> usize {
    #[cfg(feature = "lod")]
    {
        guard_value(0, || {
            transfer.as_ref().map_or(0, |t| t.corr.lod_vertex_count())
        })
    }
    #[cfg(not(feature = "lod"))]
    {
        let _ = transfer;
        0
    }
}

/// Number of input vertices of `transfer` (the rows every input array has; 0 when NULL or
/// in a build without `lod`).
///
/// # Safety
/// `transfer` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn pleat_transfer_input_vertex_count(
    transfer: *const PleatTransfer,
) -> usize {
    #[cfg(feature = "lod")]
    {
        guard_value(0, || {
            transfer.as_ref().map_or(0, |t| t.corr.input_vertex_count())
        })
    }
    #[cfg(not(feature = "lod"))]
    {
        let _ = transfer;
        0
    }
}

/// Real per-vertex attributes of the input on the LOD's vertices.
///
/// - `mode`: `PLEAT_TRANSFER_BARYCENTRIC` (interpolated on the corresponding input triangle:
///   each output is a convex combination of three input rows) or `PLEAT_TRANSFER_NEAREST`
///   (the row of the nearest corner).
/// - `values`: `n_input × k` floats, row per input vertex, all finite; non-NULL.
/// - `n_input`: the input's vertex count; `k`: components per vertex, 1 to 65536.
/// - `out_values`: `n_lod × k` floats, non-NULL; `n_lod` the LOD's vertex count.
///
/// `PLEAT_STATUS_INVALID_ARGUMENT` for NULL pointers, a count that is not the handle's, a
/// NaN or infinite value (named), an unknown mode. Nothing is written on failure.
/// Deterministic, whatever the thread count.
///
/// # Safety
/// `transfer` is NULL or live; arrays are NULL or hold the counts stated.
#[no_mangle]
pub unsafe extern "C" fn pleat_transfer_f32(
    transfer: *const PleatTransfer,
    mode: u32,
    values: *const f32,
    n_input: usize,
    k: usize,
    out_values: *mut f32,
    n_lod: usize,
) -> PleatStatus {
    requires!(
        "lod",
        [transfer, mode, values, n_input, k, out_values, n_lod],
        {
            guard(|| {
                use crate::transfer::TransferMode;
                let t = arg_ref(transfer, "transfer")?;
                let mode = match mode {
                    PLEAT_TRANSFER_BARYCENTRIC => TransferMode::Barycentric,
                    PLEAT_TRANSFER_NEAREST => TransferMode::Nearest,
                    v => {
                        return Err(crate::Error::InvalidArgument(format!(
                            "mode must be 0 (barycentric) or 1 (nearest), got {v}"
                        )))
                    }
                };
                let (n_in, n_out) = imp::check_counts(&t.corr, n_input, k, "k", n_lod)?;
                let values = arg_slice(values, n_in, "values")?;
                non_null(out_values, "out_values")?;
                let out = t.corr.transfer_f32(values, k, mode)?;
                debug_assert_eq!(out.len(), n_out);
                imp::write(&out, out_values);
                Ok(())
            })
        }
    )
}

/// Integer per-vertex attributes of the input (ids, flags, material or group indices) on the
/// LOD's vertices: each LOD vertex gets the row of the nearest corner of its input triangle.
/// Arguments as `pleat_transfer_f32` (no mode).
///
/// # Safety
/// As `pleat_transfer_f32`.
#[no_mangle]
pub unsafe extern "C" fn pleat_transfer_u32(
    transfer: *const PleatTransfer,
    values: *const u32,
    n_input: usize,
    k: usize,
    out_values: *mut u32,
    n_lod: usize,
) -> PleatStatus {
    requires!("lod", [transfer, values, n_input, k, out_values, n_lod], {
        guard(|| {
            let t = arg_ref(transfer, "transfer")?;
            let (n_in, _) = imp::check_counts(&t.corr, n_input, k, "k", n_lod)?;
            let values = arg_slice(values, n_in, "values")?;
            non_null(out_values, "out_values")?;
            let out = t.corr.transfer_u32(values, k)?;
            imp::write(&out, out_values);
            Ok(())
        })
    })
}

/// Skin weights of the input on the LOD's vertices: per LOD vertex, the influences of its
/// input triangle's corners (each normalised) blended per joint with the barycentric
/// coordinates, the `max_influences` largest kept (ties: lower joint first), sorted by weight
/// descending and renormalised so they sum to 1 within 1e-6; unused slots are joint 0,
/// weight 0. (The rule was chosen by measuring posed LODs of a skinned character; see the
/// `pleat::transfer` module docs.)
///
/// - `joints`, `weights`: `n_input × m` joint indices and weights (finite, >= 0; 0 marks an
///   unused slot; every input vertex used by a triangle needs a positive one); non-NULL.
/// - `max_influences`: 1 to 4, or up to 8 when `m` >= it.
/// - `out_joints`, `out_weights`: `n_lod × max_influences` values each; non-NULL.
///
/// # Safety
/// As `pleat_transfer_f32`.
#[no_mangle]
pub unsafe extern "C" fn pleat_transfer_skin(
    transfer: *const PleatTransfer,
    joints: *const u32,
    weights: *const f32,
    n_input: usize,
    m: usize,
    max_influences: u32,
    out_joints: *mut u32,
    out_weights: *mut f32,
    n_lod: usize,
) -> PleatStatus {
    requires!(
        "lod",
        [
            transfer,
            joints,
            weights,
            n_input,
            m,
            max_influences,
            out_joints,
            out_weights,
            n_lod
        ],
        {
            guard(|| {
                use crate::transfer::SkinParams;
                let t = arg_ref(transfer, "transfer")?;
                let (n_in, _) = imp::check_counts(&t.corr, n_input, m, "m", n_lod)?;
                let joints = arg_slice(joints, n_in, "joints")?;
                let weights = arg_slice(weights, n_in, "weights")?;
                non_null(out_joints, "out_joints")?;
                non_null(out_weights, "out_weights")?;
                let sp = SkinParams {
                    max_influences: max_influences as usize,
                    smoothing_iterations: t.skin_smoothing,
                    ..Default::default()
                };
                let sw = t.corr.transfer_skin(joints, weights, m, &sp)?;
                imp::write(&sw.joints, out_joints);
                imp::write(&sw.weights, out_weights);
                Ok(())
            })
        }
    )
}
