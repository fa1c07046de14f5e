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
pub use cube_tree::{cube_meets, sort_in_tree_order, CubeTree};
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

/// A deterministic xorshift64 stream of uniform numbers in `[0, 1)` from `seed` (non-zero), for
/// the trees' randomized tests (the same numbers on every platform).
#[cfg(test)]
pub(crate) fn test_uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}
