//! LODs that follow a skin and morph targets from C: `pleat_deformation_create` takes the
//! input's skin weights, joint pivots and morph displacements once
//! (`crate::lowpoly::DeformationField`); `PleatLodParams::deformation` points at the handle so
//! that `pleat_lod_generate` and `pleat_lod_generate_chain` keep the vertices a posed level needs;
//! `pleat_deformation_destroy` frees it.
//!
//! The functions exist in every build; without the cargo feature `lod` they return
//! `PLEAT_STATUS_UNSUPPORTED`.

use super::boundary::{destroy, full_size, requires, versioned};
use super::common::PleatStatus;

/// What `pleat_deformation_create` reads. Get the defaults (no skin, no morph, default limits)
/// from `pleat_deformation_desc_default()` and set what the input has.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct PleatDeformationDesc {
    /// `sizeof(PleatDeformationDesc)`.
    pub struct_size: u32,
    /// Influences per vertex k (0: no skin; at most 64).
    pub influences: u32,
    /// Vertices of the input mesh the LOD will be made from, in its vertex order.
    pub vertex_count: usize,
    /// `vertex_count × influences` joint indices (NULL when `influences` is 0).
    pub joints: *const u32,
    /// `vertex_count × influences` weights, finite and >= 0 (need not be normalised; zero
    /// weights are ignored; NULL when `influences` is 0).
    pub weights: *const f32,
    /// Joints with a pivot in `joint_pivots` (0: none given; the lever arm of a joint without
    /// a pivot is the input's bounding-box diagonal).
    pub joint_count: usize,
    /// `joint_count × 3` bind-pose pivot coordinates (the joints' world positions, e.g. the
    /// translation of each inverse bind matrix's inverse), finite; NULL when `joint_count` is 0.
    pub joint_pivots: *const f64,
    /// Morph targets.
    pub morph_count: usize,
    /// `morph_count × vertex_count × 3` displacements (target after target), finite; NULL when
    /// `morph_count` is 0.
    pub morph_deltas: *const f32,
    /// The largest joint rotation from the bind pose, in radians (0: 1 rad).
    pub max_rotation: f64,
    /// The largest error the skin may add when posed, in pixels at each level's screen size
    /// (0: 0.5).
    pub max_skin_error: f64,
}

// Smallest size: through `influences` (later fields keep their defaults: no arrays).
versioned!(PleatDeformationDesc, 8, pleat_deformation_desc_default);

/// The deformation of an input mesh (opaque), made by `pleat_deformation_create`, freed by
/// `pleat_deformation_destroy`. Immutable: one handle may serve any number of bakes, from any
/// threads, while it lives.
pub struct PleatDeformation {
    #[cfg(feature = "lod")]
    pub(crate) field: std::sync::Arc<crate::lowpoly::DeformationField>,
}

/// No skin, no morph target, the default limits (1 rad, half a pixel), `struct_size` set.
#[no_mangle]
pub extern "C" fn pleat_deformation_desc_default() -> PleatDeformationDesc {
    PleatDeformationDesc {
        struct_size: full_size::<PleatDeformationDesc>(),
        influences: 0,
        vertex_count: 0,
        joints: std::ptr::null(),
        weights: std::ptr::null(),
        joint_count: 0,
        joint_pivots: std::ptr::null(),
        morph_count: 0,
        morph_deltas: std::ptr::null(),
        max_rotation: 0.0,
        max_skin_error: 0.0,
    }
}

/// Most influences per vertex `pleat_deformation_create` takes.
pub const PLEAT_DEFORMATION_MAX_INFLUENCES: u32 = 64;

#[cfg(feature = "lod")]
pub(super) mod imp {
    use super::*;
    use crate::ffi::boundary::arg_slice;
    use crate::lowpoly::DeformationField;
    use crate::{Error, Result};

    /// The checked Rust field of a description (every array read with its stated length,
    /// counts checked against overflow first).
    ///
    /// # Safety
    /// Every non-NULL pointer of `d` is valid for the length its counts state.
    pub(in crate::ffi) unsafe fn to_rust(d: &PleatDeformationDesc) -> Result<DeformationField> {
        if d.influences > PLEAT_DEFORMATION_MAX_INFLUENCES {
            return Err(Error::InvalidArgument(format!(
                "desc->influences is {}; at most {PLEAT_DEFORMATION_MAX_INFLUENCES}",
                d.influences
            )));
        }
        let k = d.influences as usize;
        let n = d.vertex_count;
        let count = |a: usize, b: usize, what: &str| {
            a.checked_mul(b).ok_or_else(|| {
                Error::InvalidArgument(format!("desc->{what}: {a} × {b} values overflow"))
            })
        };
        let (joints, weights) = if k == 0 {
            (Vec::new(), Vec::new())
        } else {
            let nk = count(n, k, "vertex_count × influences")?;
            (
                arg_slice(d.joints, nk, "desc->joints")?.to_vec(),
                arg_slice(d.weights, nk, "desc->weights")?.to_vec(),
            )
        };
        let joint_pivots = if d.joint_count == 0 {
            Vec::new()
        } else {
            let len = count(d.joint_count, 3, "joint_count × 3")?;
            let flat = arg_slice(d.joint_pivots, len, "desc->joint_pivots")?;
            flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        };
        let morph_deltas = if d.morph_count == 0 {
            Vec::new()
        } else {
            let per = count(n, 3, "vertex_count × 3")?;
            let len = count(d.morph_count, per, "morph_count × vertex_count × 3")?;
            let flat = arg_slice(d.morph_deltas, len, "desc->morph_deltas")?;
            flat.chunks_exact(per)
                .map(|t| t.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
                .collect()
        };
        let field = DeformationField {
            influences: k,
            joints,
            weights,
            morph_deltas,
            joint_pivots,
            max_rotation: d.max_rotation,
            max_skin_error: d.max_skin_error,
        };
        field.validate(n)?;
        Ok(field)
    }
}

#[cfg(feature = "lod")]
use super::boundary::{arg_out, non_null, read_versioned};
#[cfg(feature = "lod")]
use super::common::guard;

/// Reads the deformation a LOD of an input mesh must follow: its skin (joint indices and
/// weights per vertex, joint pivots) and its morph targets' displacements, in the input's
/// vertex order. Set `PleatLodParams::deformation` to the handle: the simplification then
/// refuses a collapse that would let the posed level leave the posed input by more than
/// `max_skin_error` pixels, or a morph displacement stray more than half a pixel from its
/// blend; the level is still made in the bind pose and is as valid as any other. Carry the
/// weights onto the level with `pleat_transfer_skin` and the displacements with
/// `pleat_transfer_f32`.
///
/// - `desc`: non-NULL, from `pleat_deformation_desc_default()` with the arrays set.
/// - `out`: non-NULL; receives the handle (destroy with `pleat_deformation_destroy`).
///
/// Returns `PLEAT_STATUS_INVALID_ARGUMENT` naming the field for a NULL array with a non-zero
/// count, counts that overflow, more than 64 influences, a negative or non-finite weight, a
/// non-finite pivot or displacement, or negative/non-finite limits. A bake whose input has
/// another vertex count than `vertex_count` fails with `PLEAT_STATUS_INVALID_ARGUMENT`.
///
/// # Safety
/// `desc` is NULL or valid for `desc->struct_size` bytes, and every array it points to is
/// valid for the length its counts state.
#[no_mangle]
pub unsafe extern "C" fn pleat_deformation_create(
    desc: *const PleatDeformationDesc,
    out: *mut *mut PleatDeformation,
) -> PleatStatus {
    requires!("lod", [desc, out], {
        guard(|| {
            let out = arg_out(out, "out")?;
            non_null(desc, "desc")?;
            let d = read_versioned(desc, "desc")?;
            let field = imp::to_rust(&d)?;
            out.put_boxed(PleatDeformation {
                field: std::sync::Arc::new(field),
            });
            Ok(())
        })
    })
}

/// Destroys a deformation handle. NULL is accepted and ignored. No bake may be using it.
///
/// # Safety
/// `deformation` is NULL or a handle from `pleat_deformation_create` not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_deformation_destroy(deformation: *mut PleatDeformation) {
    destroy(deformation)
}
