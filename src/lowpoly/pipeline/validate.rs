//! [`LodParams::validate`]: every parameter and the input's coordinate range are checked
//! before any work, so a bad request fails with `InvalidArgument`, `InvalidMesh` or
//! `LimitExceeded` (naming the bound) and never reaches the exact predicates or the offset
//! grid with numbers they cannot compute with.

use super::budget::MAX_LOD_VOXEL_SCALE;
use super::params::{LodParams, Mode};
use crate::mesh::TriMesh;
use crate::{Error, Result};

impl LodParams {
    /// Checks every parameter (and the memory estimate for `input`) before any work.
    pub fn validate(&self, input: &TriMesh) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidArgument(m));
        if !(self.screen_size.is_finite() && self.screen_size > 0.0) {
            return bad(format!(
                "screen size n_p must be finite and > 0, got {}",
                self.screen_size
            ));
        }
        if let Some(n) = self.target_faces {
            if n < 4 {
                return bad(format!("target face count must be at least 4, got {n}"));
            }
        }
        if !(self.flow_ratio > 0.0 && self.flow_ratio <= 1.0) {
            return bad(format!(
                "flow ratio r must be in (0, 1], got {}",
                self.flow_ratio
            ));
        }
        if !(self.epsilon.is_finite() && self.epsilon >= 0.0) {
            return bad(format!(
                "epsilon must be finite and >= 0, got {}",
                self.epsilon
            ));
        }
        if !(self.theta0_deg > 0.0 && self.theta0_deg <= 180.0) {
            return bad(format!(
                "theta0 must be in (0, 180] degrees, got {}",
                self.theta0_deg
            ));
        }
        if let Some(field) = &self.deformation {
            field.validate(input.vertex_count())?;
        }
        if self.memory_budget_bytes == 0 {
            return bad("memory budget must be > 0".into());
        }
        if let Some(v) = self.offset_voxel_scale {
            if !(v.is_finite() && v > 0.0 && v <= MAX_LOD_VOXEL_SCALE) {
                return bad(format!(
                    "offset_voxel_scale must be finite and in (0, {MAX_LOD_VOXEL_SCALE}], got {v}"
                ));
            }
        }
        check_coordinate_range(input, self.screen_size)?;
        let l = input.bbox_diagonal();
        if !(l > 0.0 && l.is_finite()) {
            return Err(Error::InvalidMesh(format!(
                "the input's bounding-box diagonal is {l}; nothing to approximate"
            )));
        }
        let d = l / self.screen_size;
        let c = self.clearance.resolve(d);
        if !(c.is_finite() && c >= 0.0 && c < d) {
            return bad(format!(
                "the cage clearance must be >= 0 and below the offset distance d = {d} (the cage \
                 starts from the offset surface at d), got {:?} = {c}",
                self.clearance
            ));
        }
        // The cheap estimates only: a request that fits neither start is refused before the
        // clean-input check (a self-intersection pass) runs; which start is taken, and so which
        // estimate binds, is known only after it (`run`, `choose_start`).
        if self.offset_voxel_scale(input, Mode::Lod).is_none()
            && !self.input_start_may_fit(input)
            && !self.measured_admission_may_fit(input)
        {
            return Err(self.offset_over_budget(input, None));
        }
        Ok(())
    }
}

/// Largest coordinate magnitude a bake computes with, input and offset box (`2^128`, the
/// largest `f32`): far below the overflow of the degree-3 products of the exact predicates
/// (`2^341`) and of the offset stage's band estimates.
const MAX_WORK_COORDINATE: f64 = 3.402_823_669_209_385e38;

/// Smallest bounding-box extent a bake accepts (`2^−126`, the smallest normal `f32`): below it
/// the predicates' degree-3 products of coordinate differences underflow.
const MIN_INPUT_EXTENT: f64 = 1.175_494_350_822_287_5e-38;

/// Largest ratio of the coordinates' magnitude to the offset grid's voxel edge `h = d/√3`
/// (`2^40`): f64 then still places a surface vertex within `2^−12` of a voxel. At `2^53` a
/// voxel edge is one unit in the last place and the offset surface folds (a unit tetrahedron
/// at `10^15` from the origin at `n_p = 8` failed the offset's own self-intersection check).
const MAX_COORDINATE_PER_VOXEL: f64 = 1_099_511_627_776.0;

/// Refuses, before any work, inputs whose coordinates the bake cannot compute with (found
/// by fuzzing a cage of a soup with one corner at `5·10⁵⁴`): coordinates or the offset
/// box (`|x| + 2d`, `d = l / n_p`) beyond ±[`MAX_WORK_COORDINATE`] and voxels finer than
/// [`MAX_COORDINATE_PER_VOXEL`] allows are `LimitExceeded`; an extent below
/// [`MIN_INPUT_EXTENT`] is `InvalidMesh`. A zero extent is left to the caller's "nothing to
/// approximate". The message says which bound and how to get within it.
fn check_coordinate_range(input: &TriMesh, screen_size: f64) -> Result<()> {
    // Coordinates are finite (a `TriMesh` invariant) and the screen size finite and > 0
    // (checked first), so `magnitude` is finite and `reach` at most +∞, never NaN.
    let (lo, hi) = input.bbox();
    let magnitude = lo.iter().chain(&hi).fold(0.0f64, |m, c| m.max(c.abs()));
    if magnitude > MAX_WORK_COORDINATE {
        return Err(Error::LimitExceeded(format!(
            "the input's coordinates reach {magnitude:e}, beyond the supported ±{:.1e} (2^128): \
             the bake's exact predicates and estimates would overflow; scale the input down",
            MAX_WORK_COORDINATE
        )));
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    if extent > 0.0 && extent < MIN_INPUT_EXTENT {
        return Err(Error::InvalidMesh(format!(
            "the input's bounding box is {extent:e} across, below the supported {:.1e} (2^-126): \
             products of its coordinate differences would underflow; scale the input up",
            MIN_INPUT_EXTENT
        )));
    }
    let d = input.bbox_diagonal() / screen_size;
    let reach = magnitude + 2.0 * d;
    if extent > 0.0 && reach > MAX_WORK_COORDINATE {
        return Err(Error::LimitExceeded(format!(
            "the offset distance d = l / n_p = {d:.3e} takes the offset box to ±{reach:.3e}, \
             beyond the supported ±{:.1e} (2^128); raise the screen size or scale the input down",
            MAX_WORK_COORDINATE
        )));
    }
    let h = d / 3f64.sqrt();
    if extent > 0.0 && reach / h > MAX_COORDINATE_PER_VOXEL {
        return Err(Error::LimitExceeded(format!(
            "the offset grid's voxel edge h = d/√3 = {h:.3e} is finer than 2^-40 of the \
             coordinates' magnitude {reach:.3e}: f64 cannot place the offset surface within a \
             voxel; move the input near the origin or lower the screen size"
        )));
    }
    Ok(())
}
