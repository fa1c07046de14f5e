//! Complex wrinkle fields (dissertation ch. 3).

mod complex;
mod subdivide;
mod topology;

pub use complex::Complex;
pub use subdivide::{BoundaryRule, LoopHierarchy, SubdivisionOptions};
