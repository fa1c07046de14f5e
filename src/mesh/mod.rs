//! Mesh core: the indexed triangle mesh [`TriMesh`], file I/O, half-edge connectivity for local
//! operations, and [`MeshReport`] validation of any triangle soup.

pub mod halfedge;
pub mod io;
mod report;
mod trimesh;
mod weld;

pub use halfedge::HalfEdgeMesh;
pub use report::{MeshReport, ReportOptions};
pub use trimesh::{Edge, EdgeList, TriMesh};
pub use weld::ExactWeld;
