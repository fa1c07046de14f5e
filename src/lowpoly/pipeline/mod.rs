//! The LOD pipeline — dissertation Alg. 3 (§4.3.2) after the offset stage (§4.3.1):
//! `M_d ← offset surface at d = l / n_p`, then up to `N` rounds of
//! {simplify (Alg. 5) → flow (Alg. 3–4) → align (Alg. 6)}, stopping early when the sampled
//! Hausdorff distance between consecutive rounds falls below `ε·l` (line 17) or the face target
//! `n_F` is met; finally an independent verification of Pro.III (watertight, manifold,
//! intersection-free), with a rerun using exact checks only if the normal-cone shortcut ever
//! let an intersection through (§4.3.3, last paragraph).
//!
//! This module only declares its parts and re-exports their API; each file holds one concern,
//! and the files import each other without cycles, in this order from the bottom:
//! - `params.rs`: [`LodParams`], [`Clearance`], [`LodStart`] and the bake's `Mode`;
//! - `progress.rs`: the progress windows and cancellation (`Reporter`);
//! - `budget.rs`: voxel scales, memory estimates and the budget refusals;
//! - `validate.rs`: [`LodParams::validate`] and the input's coordinate range;
//! - `start.rs`: the clean-input check ([`check_clean`]) and the choice of a LOD's start;
//! - `optimize.rs`: the loop of Alg. 3 on one level and the input-plane fit after it;
//! - `level.rs`: one level from its start through the rounds and the fit;
//! - `offset_start.rs`: a level's offset surface, admitted up front or by measurement;
//! - `judge.rs`: a level's verification, measurement and report;
//! - `chain.rs`: which chain level starts from which surface, and which run side by side;
//! - `run.rs`: the entry points [`generate`] and [`generate_chain`].

mod budget;
mod chain;
mod judge;
mod level;
mod offset_start;
mod optimize;
mod params;
mod progress;
mod run;
mod start;
mod validate;

#[cfg(test)]
mod tests;

pub use budget::{
    LOD_COARSE_VOXEL_MIN_SCREEN_SIZE, LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE, LOD_MEDIUM_VOXEL_SCALE,
    LOD_VOXEL_SCALE, LOD_VOXEL_SCALES,
};
pub use optimize::STALL_ROUNDS;
#[cfg(feature = "cage")]
pub(crate) use params::Mode;
pub use params::{
    Clearance, LodParams, LodStart, AUTO_MAX_GENUS, DEFAULT_CLEARANCE_FRACTION, FIT_HAUSDORFF_SLACK,
};
pub use run::{generate, generate_chain};
#[cfg(feature = "cage")]
pub(crate) use run::{run, run_chain};
pub use start::check_clean;
