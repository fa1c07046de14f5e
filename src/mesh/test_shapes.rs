//! Meshes generated in code for the crate's unit tests (compiled only under `cfg(test)`).

use super::TriMesh;

/// Flat `nx × ny` grid of unit squares in the z = 0 plane, vertex `(i, j)` at index
/// `j (nx + 1) + i`, each square split along its `(i, j)–(i+1, j+1)` diagonal into
/// `[(i,j), (i+1,j), (i+1,j+1)]` and `[(i,j), (i+1,j+1), (i,j+1)]`: a disk with one boundary loop.
pub(crate) fn grid(nx: u32, ny: u32) -> TriMesh {
    let id = |i: u32, j: u32| j * (nx + 1) + i;
    let mut p = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            p.push([i as f64, j as f64, 0.0]);
        }
    }
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(p, t).expect("a grid is a valid mesh")
}
