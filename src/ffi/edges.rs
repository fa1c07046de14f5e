//! The edge numbering of the C ABI (wrinkle one-forms and any other per-edge data).
//!
//! Edges are those of `TriMesh::edges` ([`EdgeList`](crate::mesh::EdgeList)): the unique
//! undirected edges of the triangles, sorted by `(min vertex, max vertex)` and oriented from the
//! smaller to the larger vertex index. Available in every build.

use super::boundary::{arg_out, guard_value};
use super::common::{guard, PleatStatus};
use super::mesh::{mesh_ref, PleatMesh};
use crate::Error;

/// Number of unique undirected edges of `mesh` (0 when `mesh` is NULL). Degenerate corners
/// (a triangle repeating a vertex) contribute no edge.
///
/// This is the length of every per-edge array of the C API (e.g. wrinkle one-forms). The edge
/// list is rebuilt on each call (O(T log T) for T triangles): query it once.
///
/// # Safety
/// `mesh` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_edge_count(mesh: *const PleatMesh) -> usize {
    guard_value(0, || mesh.as_ref().map_or(0, |m| m.mesh.edges().len()))
}

/// Copies the edges of `mesh` in pleat's edge numbering: edge `e` is written as the two vertex
/// indices `dst[2e] < dst[2e + 1]`; edges are sorted by `(dst[2e], dst[2e + 1])`. A value on
/// edge `e` (such as a one-form ω) is integrated from `dst[2e]` to `dst[2e + 1]`; on the
/// opposite direction it is negated.
///
/// - `mesh`: non-NULL.
/// - `dst`: room for `edge_capacity` edges, i.e. `2 * edge_capacity` `uint32_t`; non-NULL.
/// - `edge_capacity`: number of edges `dst` holds; must be ≥ `pleat_mesh_edge_count(mesh)`,
///   else `PLEAT_STATUS_LIMIT_EXCEEDED` and nothing is written.
///
/// # Safety
/// `mesh` is NULL or live; `dst` is NULL or valid for `2 * edge_capacity` u32 writes.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_copy_edges(
    mesh: *const PleatMesh,
    dst: *mut u32,
    edge_capacity: usize,
) -> PleatStatus {
    guard(|| {
        let m = mesh_ref(mesh, "mesh")?;
        arg_out(dst, "dst")?;
        let edges = m.edges();
        let n = edges.len();
        if edge_capacity < n {
            return Err(Error::LimitExceeded(format!(
                "dst holds {edge_capacity} edges, the mesh has {n}"
            )));
        }
        let out = std::slice::from_raw_parts_mut(dst, 2 * n);
        for (o, e) in out.chunks_exact_mut(2).zip(&edges.edges) {
            o.copy_from_slice(&e.0);
        }
        Ok(())
    })
}
