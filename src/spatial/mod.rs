//! Spatial queries: BVHs, closest points, exact triangle–triangle tests, self-intersections,
//! winding numbers. The only module that speaks parry's types: everything else passes
//! [`crate::geom::Vec3`] (arithmetic) or `[f64; 3]` (stored positions).
//!
//! May import: `crate::geom`, `crate::mesh`.

mod box_tree;
pub mod bvh;
pub mod closest;
mod cube_tree;
pub mod self_intersect;
mod tri_tree;
pub mod tritri;
pub mod winding;

pub use box_tree::BoxTree;
pub use bvh::{ClosestPoint, TriangleBvh};
pub use cube_tree::{cube_meets, CubeTree};
pub use self_intersect::{
    degenerate_faces, find_self_intersections, find_self_intersections_in, has_self_intersection,
    has_self_intersection_in, self_intersections, SelfIntersections,
};
pub use tri_tree::TriTree;
pub use tritri::{
    are_coplanar, coplanar_same_side, faces_intersect, faces_intersect_at, is_collinear, orient2d,
    orient3d, segment_triangle_intersect, sharing, triangles_intersect, Sharing,
};
pub use winding::{
    solid_angle, winding_number, winding_number_in, winding_numbers, FastWindingNumber,
};
