//! Mesh core: the indexed triangle mesh [`TriMesh`], file I/O and half-edge connectivity for
//! local operations (validation of any soup: `crate::verify::MeshReport`).
//!
//! May import: `crate::geom`, `crate::error` (the bottom layer).

pub mod halfedge;
pub mod io;
#[cfg(test)]
pub(crate) mod test_shapes;
mod trimesh;
mod weld;

pub use halfedge::HalfEdgeMesh;
pub use trimesh::{Edge, EdgeList, TriMesh};
pub use weld::ExactWeld;
