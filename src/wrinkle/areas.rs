//! Barycentric area weights of a base mesh, shared by the CWF energies ([`cwf`](super::cwf)),
//! the Knöppel phase solve ([`knoppel`](super::knoppel)) and the interpolation
//! ([`interpolate`](mod@super::interpolate)). It sits below all three so none of them imports
//! another for it.
//!
//! May import: `super::topology`, `crate::geom`.

use super::topology::Topology;
use crate::geom::Vec3;

/// `(A_kl per edge, A_j per vertex)`: a third of each incident triangle's area.
pub(crate) fn barycentric_areas(topo: &Topology, x: &[[f64; 3]]) -> (Vec<f64>, Vec<f64>) {
    let mut edge = vec![0.0; topo.n_edges()];
    let mut vertex = vec![0.0; topo.n_vertices];
    for (f, t) in topo.faces.iter().enumerate() {
        let o = Vec3::from(x[t[0] as usize]);
        let (p1, p2) = (Vec3::from(x[t[1] as usize]), Vec3::from(x[t[2] as usize]));
        let third = (p1 - o).cross(p2 - o).length() / 6.0;
        for c in 0..3 {
            edge[topo.face_edges[f][c] as usize] += third;
            vertex[t[c] as usize] += third;
        }
    }
    (edge, vertex)
}
