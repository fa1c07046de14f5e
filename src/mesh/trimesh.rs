//! [`TriMesh`]: the indexed triangle mesh every pleat operation takes and returns.

use crate::geom::{tri_normal, Vec3};
use crate::{Error, Result};

/// An indexed triangle mesh with `f64` positions and `u32` triangle indices.
///
/// Guarantees (checked by every constructor): at least one triangle, every coordinate finite,
/// every index `< positions.len()`. It promises nothing about topology: it may be any soup
/// (non-manifold, open, self-intersecting, degenerate faces, unreferenced vertices). Use
/// `MeshReport` to learn what it is.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Builds a mesh from positions and triangles, validating both.
    ///
    /// Errors with [`Error::InvalidMesh`] when there is no triangle, a coordinate is NaN or
    /// infinite, an index is out of range, or there are more than `u32::MAX` vertices.
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        validate(&positions, &triangles)?;
        Ok(TriMesh {
            positions,
            triangles,
        })
    }

    /// Builds a mesh from flat buffers: `positions` holds `3·n` coordinates (x, y, z per vertex),
    /// `indices` holds `3·m` vertex indices (one triangle per 3).
    ///
    /// Errors when `positions.len()` or `indices.len()` is not a multiple of 3, and as [`TriMesh::new`].
    pub fn from_flat(positions: &[f64], indices: &[u32]) -> Result<Self> {
        if positions.len() % 3 != 0 {
            return Err(Error::InvalidMesh(format!(
                "position count {} is not a multiple of 3",
                positions.len()
            )));
        }
        if indices.len() % 3 != 0 {
            return Err(Error::InvalidMesh(format!(
                "index count {} is not a multiple of 3",
                indices.len()
            )));
        }
        let p = positions
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let t = indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        TriMesh::new(p, t)
    }

    /// The vertex positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// The triangles, as three vertex indices each (counter-clockwise seen from outside when the
    /// mesh is consistently oriented).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of vertices (including unreferenced ones).
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Consumes the mesh and returns its buffers.
    pub fn into_parts(self) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (self.positions, self.triangles)
    }

    /// Position of vertex `i` (panics when out of range, like slice indexing).
    pub fn position(&self, i: u32) -> [f64; 3] {
        self.positions[i as usize]
    }

    /// The three corner positions of triangle `t`.
    pub fn triangle_positions(&self, t: usize) -> [[f64; 3]; 3] {
        let [a, b, c] = self.triangles[t];
        [self.position(a), self.position(b), self.position(c)]
    }

    /// Axis-aligned bounding box of the referenced vertices as `(min, max)`.
    pub fn bbox(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for t in &self.triangles {
            for &v in t {
                let p = self.positions[v as usize];
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        (lo, hi)
    }

    /// Length of the bounding-box diagonal of the referenced vertices (the dissertation's `l`).
    pub fn bbox_diagonal(&self) -> f64 {
        let (lo, hi) = self.bbox();
        let d: f64 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum();
        d.sqrt()
    }

    /// Area of triangle `t` (zero for degenerate triangles).
    pub fn triangle_area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangle_positions(t).map(Vec3::from);
        0.5 * tri_normal(a, b, c).length()
    }

    /// Total surface area.
    pub fn surface_area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| self.triangle_area(t))
            .sum()
    }

    /// The unique undirected edges of the mesh with a fixed, documented numbering (see
    /// [`EdgeList`]). Works on any soup; an edge shared by k faces appears once.
    pub fn edges(&self) -> EdgeList {
        EdgeList::build(&self.triangles)
    }
}

/// An undirected edge stored with its canonical orientation `v[0] < v[1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Edge(pub [u32; 2]);

/// The unique edges of a triangle mesh and, per face corner, which edge it starts.
///
/// Numbering (part of the C ABI for edge data such as wrinkle one-forms): edges are sorted
/// lexicographically by `(min vertex, max vertex)`, and each edge is oriented from its smaller
/// to its larger vertex index. `face_edges[f][i]` is the edge from corner `i` to corner
/// `(i + 1) % 3` of face `f`, and `face_edge_sign[f][i]` is `+1` when that corner order agrees
/// with the edge orientation and `-1` otherwise. Degenerate corners (`a == b`) get `u32::MAX`
/// and sign 0.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeList {
    /// The edges, sorted, oriented `v[0] < v[1]`.
    pub edges: Vec<Edge>,
    /// Per face, per corner `i`, the index into `edges` of edge `(i, i+1)`.
    pub face_edges: Vec<[u32; 3]>,
    /// Per face, per corner, `+1`/`-1` (orientation agreement) or `0` (degenerate corner).
    pub face_edge_sign: Vec<[i8; 3]>,
}

impl EdgeList {
    fn build(tris: &[[u32; 3]]) -> EdgeList {
        let mut keys: Vec<(u32, u32)> = Vec::with_capacity(tris.len() * 3);
        for t in tris {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                if a != b {
                    keys.push((a.min(b), a.max(b)));
                }
            }
        }
        keys.sort_unstable();
        keys.dedup();
        let edges: Vec<Edge> = keys.iter().map(|&(a, b)| Edge([a, b])).collect();
        let mut face_edges = Vec::with_capacity(tris.len());
        let mut face_edge_sign = Vec::with_capacity(tris.len());
        for t in tris {
            let mut fe = [u32::MAX; 3];
            let mut fs = [0i8; 3];
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                if a != b {
                    let key = (a.min(b), a.max(b));
                    let e = keys.binary_search(&key).expect("edge was inserted");
                    fe[i] = e as u32;
                    fs[i] = if a < b { 1 } else { -1 };
                }
            }
            face_edges.push(fe);
            face_edge_sign.push(fs);
        }
        EdgeList {
            edges,
            face_edges,
            face_edge_sign,
        }
    }

    /// Number of unique edges.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// True when the mesh has no non-degenerate edge.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Index of the edge between `a` and `b` (either order), if the mesh has it. O(log E).
    pub fn find(&self, a: u32, b: u32) -> Option<usize> {
        let key = Edge([a.min(b), a.max(b)]);
        self.edges.binary_search(&key).ok()
    }
}

fn validate(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<()> {
    if triangles.is_empty() {
        return Err(Error::InvalidMesh("the mesh has no triangles".into()));
    }
    if positions.len() > u32::MAX as usize {
        return Err(Error::InvalidMesh(format!(
            "{} vertices exceed the u32 index range",
            positions.len()
        )));
    }
    if let Some((i, p)) = positions
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
    {
        return Err(Error::InvalidMesh(format!(
            "vertex {i} has a non-finite coordinate ({}, {}, {})",
            p[0], p[1], p[2]
        )));
    }
    let n = positions.len() as u32;
    if let Some((f, t)) = triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v >= n))
    {
        return Err(Error::InvalidMesh(format!(
            "triangle {f} ({}, {}, {}) references a vertex >= the vertex count {n}",
            t[0], t[1], t[2]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tet() -> TriMesh {
        TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
        .unwrap()
    }

    #[test]
    fn rejects_bad_input() {
        assert!(matches!(
            TriMesh::new(vec![[0.; 3]], vec![]),
            Err(Error::InvalidMesh(_))
        ));
        let nan = TriMesh::new(vec![[f64::NAN, 0., 0.], [1.; 3], [2.; 3]], vec![[0, 1, 2]]);
        assert!(nan.unwrap_err().to_string().contains("non-finite"));
        let oob = TriMesh::new(vec![[0.; 3]; 3], vec![[0, 1, 3]]);
        assert!(oob.unwrap_err().to_string().contains(">= the vertex count"));
        assert!(TriMesh::from_flat(&[0.; 9], &[0, 1]).is_err());
        assert!(TriMesh::from_flat(&[0.; 8], &[0, 1, 2]).is_err());
    }

    #[test]
    fn edges_of_tetrahedron() {
        let m = tet();
        let e = m.edges();
        assert_eq!(e.len(), 6);
        for (f, t) in m.triangles().iter().enumerate() {
            for i in 0..3 {
                let edge = e.edges[e.face_edges[f][i] as usize].0;
                let (a, b) = (t[i], t[(i + 1) % 3]);
                assert_eq!(edge, [a.min(b), a.max(b)]);
                assert_eq!(e.face_edge_sign[f][i], if a < b { 1 } else { -1 });
            }
        }
        assert_eq!(e.find(3, 0), Some(2));
        assert!((m.surface_area() - (1.5 + 3f64.sqrt() / 2.0)).abs() < 1e-12);
        assert!((m.bbox_diagonal() - 3f64.sqrt()).abs() < 1e-12);
    }
}
