//! Low-poly meshes by screen size (dissertation ch. 4).

pub(crate) mod distance;
mod exact;
pub(crate) mod features;
mod geom;
pub(crate) mod mc33;
