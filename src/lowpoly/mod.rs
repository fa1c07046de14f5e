//! Low-poly meshes by screen size (dissertation ch. 4).
//!
//! Stage 1, [`offset_surface`]: the robust, feature-preserving `d`-offset surface of any
//! triangle soup (§4.3.1): narrow-band unsigned distance (`distance`), Marching Cubes 33
//! topology (`mc33`), feature vertices (`features`), interior removal (`interior`).

pub(crate) mod distance;
mod extract;
pub(crate) mod features;
mod filter;
mod flips;
mod geom;
mod interior;
pub(crate) mod mc33;
mod offset;

pub use offset::{offset_surface, offset_surface_with_progress, OffsetDistance, OffsetParams};
