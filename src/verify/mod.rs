//! Independent verification of any mesh: the checks behind every guarantee pleat reports,
//! written apart from the code that produces meshes (the design rule that guarantees are
//! verified by independent code, as CGAL's `does_self_intersect`/`is_closed` are).
//!
//! - [`validity`]: [`MeshReport`] — counts, manifoldness, watertightness, orientation,
//!   components, genus, self-intersections of any triangle soup (meshcheck's keys);
//! - [`cage`]: enclosure, contact and clearance of a cage against its input;
//! - [`hausdorff`]: sampled two-sided Hausdorff distance, its one-sided parts and the floor.
//!
//! The LOD, offset and cage pipelines call these at their end and record the outcome in their
//! reports (`Guarantees`, `hausdorff_rel`, ...).
//!
//! May import: `crate::mesh`, `crate::spatial`, `crate::geom`, `crate::report`,
//! `crate::error` — never a producer of meshes (`lowpoly`, `cage`, `wrinkle`).

pub mod cage;
pub mod hausdorff;
pub mod validity;

pub use cage::{check_cage, clearance, min_distance, CageCheck, CageInput};
pub use hausdorff::{
    hausdorff_sides, hausdorff_sides_unless, hausdorff_sides_with_progress, hausdorff_to_input,
    input_to_surface, HausdorffSides,
};
pub use validity::{MeshReport, ReportOptions, ValidityStage};
