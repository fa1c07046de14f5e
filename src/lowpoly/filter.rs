//! Feature filtering (dissertation §4.3.1, "Feature Filtering"): the feature graph of the
//! flipped mesh consists of the edges whose dihedral angle is below θ0 (default 120°; 180° is
//! flat), chained into curves between vertices where the graph does not simply continue
//! (degree ≠ 2) — closed chains are curves too (Gao et al. 2019 use the same chaining). A curve
//! with more than l0 edges (default 4) is "real"; a feature vertex is kept only when it lies on
//! a real curve, every other patch reverts to its MC33 template.

use rayon::prelude::*;

use crate::geom::{normalized, Vec3};
use crate::mesh::halfedge::{EdgeData, EdgeId, FaceData, FaceId, HalfedgeId, VertexData, VertexId};
use crate::mesh::HalfEdgeMesh;

/// Marks the vertices lying on real feature curves (indexed by raw vertex index).
pub(crate) fn vertices_on_real_curves(mesh: &HalfEdgeMesh, theta0_deg: f64, l0: u32) -> Vec<bool> {
    let sharp = sharp_edges(mesh, theta0_deg);
    let nv = mesh.vertex_capacity();
    let mut degree = VertexData::filled(nv, 0u32);
    for e in mesh.edges().filter(|&e| sharp[e]) {
        let h = mesh.edge_halfedge(e);
        degree[mesh.origin(h)] += 1;
        degree[mesh.target(h)] += 1;
    }
    let mut used = EdgeData::filled(mesh.edge_capacity(), false);
    let mut on_real = VertexData::filled(nv, false);
    // Open curves start at vertices whose sharp degree is not 2; then closed loops remain.
    let starts: Vec<VertexId> = mesh.vertices().filter(|&v| degree[v] != 2).collect();
    let loops: Vec<VertexId> = mesh.vertices().filter(|&v| degree[v] == 2).collect();
    for &v in starts.iter().chain(&loops) {
        for h in mesh.outgoing(v).collect::<Vec<_>>() {
            let e = mesh.edge(h);
            if !sharp[e] || used[e] {
                continue;
            }
            let curve = walk_curve(mesh, &sharp, &degree, &mut used, h);
            if curve.len() as u32 > l0 + 1 {
                for &x in &curve {
                    on_real[x] = true;
                }
            }
        }
    }
    on_real.into_vec()
}

/// Follows sharp edges from half-edge `h` through degree-2 vertices; returns the vertices.
fn walk_curve(
    mesh: &HalfEdgeMesh,
    sharp: &EdgeData<bool>,
    degree: &VertexData<u32>,
    used: &mut EdgeData<bool>,
    mut h: HalfedgeId,
) -> Vec<VertexId> {
    let start = mesh.origin(h);
    let mut verts = vec![start];
    loop {
        used[mesh.edge(h)] = true;
        let v = mesh.target(h);
        verts.push(v);
        if v == start || degree[v] != 2 {
            break;
        }
        let Some(next) = mesh
            .outgoing(v)
            .find(|&g| sharp[mesh.edge(g)] && !used[mesh.edge(g)])
        else {
            break;
        };
        h = next;
    }
    verts
}

/// Per edge id: is its dihedral angle below `theta0_deg`? (Normals more than `180° − θ0`
/// apart.)
fn sharp_edges(mesh: &HalfEdgeMesh, theta0_deg: f64) -> EdgeData<bool> {
    let cos_limit = (180.0 - theta0_deg).to_radians().cos();
    let normals: FaceData<Option<Vec3>> = (0..mesh.face_capacity() as u32)
        .into_par_iter()
        .map(FaceId::new)
        .map(|f| {
            mesh.is_face_live(f)
                .then(|| normalized(mesh.face_area_vector(f)))
                .flatten()
        })
        .collect::<Vec<_>>()
        .into();
    let sharp: Vec<bool> = (0..mesh.edge_capacity() as u32)
        .into_par_iter()
        .map(EdgeId::new)
        .map(|e| {
            if !mesh.is_edge_live(e) {
                return false;
            }
            let h = mesh.edge_halfedge(e);
            let n = |h: HalfedgeId| mesh.face(h).and_then(|f| normals[f]);
            matches!((n(h), n(mesh.twin(h))), (Some(a), Some(b)) if a.dot(b) < cos_limit)
        })
        .collect();
    EdgeData::from_vec(sharp)
}
