//! Spatial queries: BVH, closest points, exact triangle–triangle tests, winding numbers.

pub mod tritri;

pub use tritri::{
    are_coplanar, coplanar_same_side, faces_intersect, is_collinear, orient2d, orient3d,
    segment_triangle_intersect, sharing, triangles_intersect, Point3, Sharing,
};
