//! Feature filtering (dissertation §4.3.1, "Feature Filtering"): the feature graph of the
//! flipped mesh consists of the edges whose dihedral angle is below θ0 (default 120°; 180° is
//! flat), chained into curves between vertices where the graph does not simply continue
//! (degree ≠ 2) — closed chains are curves too (Gao et al. 2019 use the same chaining). A curve
//! with more than l0 edges (default 4) is "real"; a feature vertex is kept only when it lies on
//! a real curve, every other patch reverts to its MC33 template.

use rayon::prelude::*;

use crate::geom::{normalized, Vec3};
use crate::mesh::HalfEdgeMesh;

/// Marks the vertices lying on real feature curves.
pub(crate) fn vertices_on_real_curves(mesh: &HalfEdgeMesh, theta0_deg: f64, l0: u32) -> Vec<bool> {
    let sharp = sharp_edges(mesh, theta0_deg);
    let nv = mesh.vertex_capacity();
    let mut degree = vec![0u32; nv];
    for e in mesh.edges().filter(|&e| sharp[e as usize]) {
        let h = mesh.edge_halfedge(e);
        degree[mesh.origin(h) as usize] += 1;
        degree[mesh.target(h) as usize] += 1;
    }
    let mut used = vec![false; mesh.edge_capacity()];
    let mut on_real = vec![false; nv];
    // Open curves start at vertices whose sharp degree is not 2; then closed loops remain.
    let starts: Vec<u32> = mesh
        .vertices()
        .filter(|&v| degree[v as usize] != 2)
        .collect();
    let loops: Vec<u32> = mesh
        .vertices()
        .filter(|&v| degree[v as usize] == 2)
        .collect();
    for &v in starts.iter().chain(&loops) {
        for h in mesh.outgoing(v).collect::<Vec<_>>() {
            let e = mesh.edge(h);
            if !sharp[e as usize] || used[e as usize] {
                continue;
            }
            let curve = walk_curve(mesh, &sharp, &degree, &mut used, h);
            if curve.len() as u32 > l0 + 1 {
                for &x in &curve {
                    on_real[x as usize] = true;
                }
            }
        }
    }
    on_real
}

/// Follows sharp edges from half-edge `h` through degree-2 vertices; returns the vertices.
fn walk_curve(
    mesh: &HalfEdgeMesh,
    sharp: &[bool],
    degree: &[u32],
    used: &mut [bool],
    mut h: u32,
) -> Vec<u32> {
    let start = mesh.origin(h);
    let mut verts = vec![start];
    loop {
        used[mesh.edge(h) as usize] = true;
        let v = mesh.target(h);
        verts.push(v);
        if v == start || degree[v as usize] != 2 {
            break;
        }
        let Some(next) = mesh
            .outgoing(v)
            .find(|&g| sharp[mesh.edge(g) as usize] && !used[mesh.edge(g) as usize])
        else {
            break;
        };
        h = next;
    }
    verts
}

/// Per edge id: is its dihedral angle below `theta0_deg`? (Normals more than `180° − θ0`
/// apart.)
fn sharp_edges(mesh: &HalfEdgeMesh, theta0_deg: f64) -> Vec<bool> {
    let cos_limit = (180.0 - theta0_deg).to_radians().cos();
    let normals: Vec<Option<Vec3>> = (0..mesh.face_capacity() as u32)
        .into_par_iter()
        .map(|f| {
            mesh.is_face_live(f)
                .then(|| normalized(mesh.face_area_vector(f)))
                .flatten()
        })
        .collect();
    (0..mesh.edge_capacity() as u32)
        .into_par_iter()
        .map(|e| {
            if !mesh.is_edge_live(e) {
                return false;
            }
            let h = mesh.edge_halfedge(e);
            let n = |h: u32| mesh.face(h).and_then(|f| normals[f as usize]);
            matches!((n(h), n(mesh.twin(h))), (Some(a), Some(b)) if a.dot(b) < cos_limit)
        })
        .collect()
}
