//! Low-poly meshes by screen size (dissertation ch. 4).
//!
//! Stage 1, [`offset_surface`]: the robust, feature-preserving `d`-offset surface of any
//! triangle soup (§4.3.1): narrow-band unsigned distance (`distance`), Marching Cubes 33
//! topology (`mc33`), feature vertices (`features`), interior removal (`interior`).
//!
//! Stage 2, the mesh-optimization loop (§4.3.2–4.3.3, Alg. 3–7), then for LODs a final fit to
//! the input's planes (`fit`): [`generate`] bakes one LOD,
//! [`generate_chain`] several. Every local operation of the loop — edge collapses
//! (`simplify`, Alg. 5), the flow (Alg. 3–4) and the feature alignment (Alg. 6, eq. 4.5) —
//! goes through one guard (`guard.rs`) that keeps the mesh watertight, manifold, of the same
//! topology and free of self-intersections, and in cage mode (`crate::cage`) disjoint from the
//! input and enclosing it.
//!
//! Each bake returns a typed report ([`LodReport`], [`OffsetReport`]); the guarantees in it
//! are checked at the end by `crate::verify`, which shares no code with the guard.
//!
//! May import: `crate::mesh`, `crate::spatial`, `crate::verify`, `crate::geom`,
//! `crate::report`, `crate::error`.

mod align;
mod coverage;
mod deform;
pub(crate) mod distance;
mod extract;
pub(crate) mod features;
mod filter;
mod fit;
mod flips;
mod flow;
pub(crate) mod guard;
mod interior;
pub(crate) mod mc33;
mod measure;
mod offset;
mod pipeline;
mod report;
mod simplify;

pub use deform::{DeformationField, DEFAULT_MAX_ROTATION, MORPH_DEVIATION, SKIN_ERROR};
pub use fit::SELF_CLEARANCE as FIT_SELF_CLEARANCE;
pub use guard::CONE_HALF_ANGLE;
pub use offset::{offset_surface, offset_surface_with_progress, OffsetDistance, OffsetParams};
pub use pipeline::{
    check_clean, generate, generate_chain, Clearance, LodParams, LodStart, AUTO_MAX_GENUS,
    DEFAULT_CLEARANCE_FRACTION, FIT_HAUSDORFF_SLACK, LOD_COARSE_VOXEL_MIN_SCREEN_SIZE,
    LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE, LOD_MEDIUM_VOXEL_SCALE, LOD_VOXEL_SCALE, LOD_VOXEL_SCALES,
    STALL_ROUNDS,
};
#[cfg(feature = "cage")]
pub(crate) use pipeline::{run, run_chain, Mode};
pub use report::{
    ClearanceMeasure, ExtractionCounts, FeatureCounts, FloorMeasure, GuardCounts, InteriorCounts,
    LodReport, LodStage, OffsetReport, OffsetStage, OffsetVerification, SimplifyCounts,
};
