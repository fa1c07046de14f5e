//! Mesh core: the indexed triangle mesh [`TriMesh`], file I/O, half-edge connectivity for local
//! operations, and [`MeshReport`] validation of any triangle soup.

pub mod halfedge;
pub mod io;
mod trimesh;

pub use halfedge::HalfEdgeMesh;
pub use trimesh::{Edge, EdgeList, TriMesh};
