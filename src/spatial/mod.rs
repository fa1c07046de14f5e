//! Spatial queries: BVH, closest points, exact triangle–triangle tests, winding numbers.
