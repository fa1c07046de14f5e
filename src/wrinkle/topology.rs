//! Local connectivity for the wrinkle module: edges in the [`EdgeList`] numbering, edge → faces,
//! vertex → edges / faces, boundary flags, and the manifold checks a CWF base mesh must pass.
//!
//! The base level is built from a [`TriMesh`] and its [`EdgeList`]; every finer Loop level is
//! derived *structurally* from the coarser one in O(size) without sorting (see
//! [`Topology::refine`]), and its edge numbering is again exactly the [`EdgeList`] numbering of
//! the refined triangles (edges sorted by `(min, max)` vertex, oriented min → max). So a
//! one-form on any level follows the one documented edge convention of the C ABI.

use crate::geom::Vec3;
use crate::mesh::{EdgeList, TriMesh};
use crate::{Error, Result};

/// "No face" marker in [`Topology::edge_faces`].
pub(crate) const NONE: u32 = u32::MAX;

/// Compressed rows: row `i` is `items[offsets[i]..offsets[i + 1]]`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Csr {
    pub offsets: Vec<usize>,
    pub items: Vec<u32>,
}

impl Csr {
    /// Counting sort of `n_items` items into `n_rows` rows; item `i` goes to each row of
    /// `rows_of(i)`. Within a row, items appear in increasing item order.
    fn build<const K: usize>(
        n_rows: usize,
        n_items: usize,
        rows_of: impl Fn(usize) -> [u32; K],
    ) -> Csr {
        let mut offsets = vec![0usize; n_rows + 1];
        for i in 0..n_items {
            for r in rows_of(i) {
                offsets[r as usize + 1] += 1;
            }
        }
        for r in 0..n_rows {
            offsets[r + 1] += offsets[r];
        }
        let mut fill = offsets.clone();
        let mut items = vec![0u32; offsets[n_rows]];
        for i in 0..n_items {
            for r in rows_of(i) {
                items[fill[r as usize]] = i as u32;
                fill[r as usize] += 1;
            }
        }
        Csr { offsets, items }
    }

    /// Counting sort of `n_items` items into `n_rows` rows, item `i` going to row `row_of(i)`.
    fn build_items(n_rows: usize, n_items: usize, row_of: impl Fn(usize) -> u32) -> Csr {
        Csr::build(n_rows, n_items, |i| [row_of(i)])
    }

    /// Row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Length of row `i`.
    #[inline]
    pub fn len(&self, i: usize) -> usize {
        self.offsets[i + 1] - self.offsets[i]
    }
}

/// Connectivity of one subdivision level.
#[derive(Debug, Clone)]
pub(crate) struct Topology {
    pub n_vertices: usize,
    /// Triangles, corner order as in the mesh.
    pub faces: Vec<[u32; 3]>,
    /// Edges sorted by `(min, max)`, oriented `v[0] < v[1]` ([`EdgeList`] numbering).
    pub edges: Vec<[u32; 2]>,
    /// Per face, the edge from corner `t` to corner `t + 1`.
    pub face_edges: Vec<[u32; 3]>,
    /// Per edge, its one or two faces (`[f, NONE]` on the boundary).
    pub edge_faces: Vec<[u32; 2]>,
    /// Per edge, its slot in each of `edge_faces` (`face_edges[edge_faces[e][k]][slot] == e`).
    pub edge_face_slot: Vec<[u8; 2]>,
    /// Per vertex, incident edges in increasing edge order.
    pub vert_edges: Csr,
    /// Per vertex, its face corners `3f + c` (face `f`, corner `c`) in increasing order.
    pub vert_corners: Csr,
    /// Per edge, the rank of the edge in `vert_edges` of its endpoint 0 and endpoint 1.
    pub edge_rank: Vec<[u32; 2]>,
    /// True for vertices on a boundary edge.
    pub boundary_vertex: Vec<bool>,
    /// Sharp boundary corners (used by [`super::BoundaryRule::Smooth`]; inherited by even
    /// vertices on refinement).
    pub corner: Vec<bool>,
}

impl Topology {
    /// Builds and validates the base level: every triangle has three distinct vertices, every
    /// edge has one or two triangles, no two triangles share all three vertices, the two
    /// triangles of an interior edge traverse it in opposite directions (consistent
    /// orientation), and the triangles around each vertex form a single fan (disk or half-disk).
    /// Vertices referenced by no triangle are allowed (they are carried along unchanged).
    pub fn from_mesh(mesh: &TriMesh, el: &EdgeList) -> Result<Topology> {
        let faces = mesh.triangles().to_vec();
        check_distinct_corners(&faces)?;
        let edges: Vec<[u32; 2]> = el.edges.iter().map(|e| e.0).collect();
        let edge_faces = edge_faces_checked(&faces, &el.face_edges, &edges)?;
        let topo = Topology::from_parts(
            mesh.vertex_count(),
            faces,
            edges,
            el.face_edges.clone(),
            edge_faces,
            vec![false; mesh.vertex_count()],
        );
        topo.check_orientation_and_duplicates()?;
        topo.check_vertex_fans()?;
        Ok(topo)
    }

    fn from_parts(
        n_vertices: usize,
        faces: Vec<[u32; 3]>,
        edges: Vec<[u32; 2]>,
        face_edges: Vec<[u32; 3]>,
        edge_faces: Vec<[u32; 2]>,
        corner: Vec<bool>,
    ) -> Topology {
        let vert_edges = Csr::build(n_vertices, edges.len(), |e| edges[e]);
        let vert_corners = Csr::build_items(n_vertices, 3 * faces.len(), |i| faces[i / 3][i % 3]);
        let edge_rank = edge_ranks(&vert_edges, &edges);
        let mut edge_face_slot = vec![[0u8; 2]; edges.len()];
        for (f, fe) in face_edges.iter().enumerate() {
            for (slot, &e) in fe.iter().enumerate() {
                let k = usize::from(edge_faces[e as usize][0] != f as u32);
                edge_face_slot[e as usize][k] = slot as u8;
            }
        }
        let mut boundary_vertex = vec![false; n_vertices];
        for (e, ef) in edge_faces.iter().enumerate() {
            if ef[1] == NONE {
                boundary_vertex[edges[e][0] as usize] = true;
                boundary_vertex[edges[e][1] as usize] = true;
            }
        }
        Topology {
            n_vertices,
            faces,
            edges,
            face_edges,
            edge_faces,
            edge_face_slot,
            vert_edges,
            vert_corners,
            edge_rank,
            boundary_vertex,
            corner,
        }
    }

    /// A topology with nothing in it (a placeholder for the last level, which needs none).
    pub fn empty() -> Topology {
        Topology::from_parts(
            0,
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
        )
    }

    /// Number of edges.
    #[inline]
    pub fn n_edges(&self) -> usize {
        self.edges.len()
    }

    /// Number of faces.
    #[inline]
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }

    /// True when edge `e` has a single face.
    #[inline]
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_faces[e][1] == NONE
    }

    /// The slot `t` of face `f` whose edge (corner `t` → `t + 1`) is `e`.
    #[inline]
    pub fn edge_slot(&self, f: usize, e: u32) -> usize {
        let fe = self.face_edges[f];
        if fe[0] == e {
            0
        } else if fe[1] == e {
            1
        } else {
            debug_assert_eq!(fe[2], e);
            2
        }
    }

    /// The corner of face `f` that holds vertex `v`.
    #[inline]
    pub fn corner_of(&self, f: usize, v: u32) -> usize {
        let t = self.faces[f];
        if t[0] == v {
            0
        } else if t[1] == v {
            1
        } else {
            debug_assert_eq!(t[2], v);
            2
        }
    }

    /// The other face of edge `e` (or [`NONE`]).
    #[inline]
    pub fn other_face(&self, e: usize, f: u32) -> u32 {
        let ef = self.edge_faces[e];
        if ef[0] == f {
            ef[1]
        } else {
            ef[0]
        }
    }

    /// The endpoint of edge `e` that is not `v`.
    #[inline]
    pub fn other_end(&self, e: usize, v: u32) -> u32 {
        let [a, b] = self.edges[e];
        if a == v {
            b
        } else {
            a
        }
    }

    /// `ω` integrated along edge `e` starting at its endpoint `from` (edges are stored
    /// oriented min → max, so this is `±ω[e]`).
    #[inline]
    pub fn omega_from(&self, omega: &[f64], e: usize, from: u32) -> f64 {
        if self.edges[e][0] == from {
            omega[e]
        } else {
            -omega[e]
        }
    }

    /// Circulation of `ω` around each face in its corner order
    /// (`ω(c0→c1) + ω(c1→c2) + ω(c2→c0)`): the discrete curl `dω`.
    pub fn face_curls(&self, omega: &[f64]) -> Vec<f64> {
        (0..self.n_faces())
            .map(|f| {
                let t = self.faces[f];
                (0..3)
                    .map(|i| self.omega_from(omega, self.face_edges[f][i] as usize, t[i]))
                    .sum()
            })
            .collect()
    }

    /// Fine edge id of the half of coarse edge `e` at its endpoint `side` (0 or 1) after one
    /// refinement: the fine edge `(edges[e][side], V + e)`.
    #[inline]
    pub fn fine_even_edge(&self, e: usize, side: usize) -> usize {
        let v = self.edges[e][side] as usize;
        self.vert_edges.offsets[v] + self.edge_rank[e][side] as usize
    }

    /// Marks boundary corners kept sharp by [`super::BoundaryRule::Smooth`]: boundary vertices
    /// with a single incident triangle (valence 2), and boundary vertices whose triangle angles
    /// sum to a value differing from π by more than `angle_tolerance` radians.
    pub fn mark_corners(&mut self, positions: &[[f64; 3]], angle_tolerance: f64) {
        for v in 0..self.n_vertices {
            if !self.boundary_vertex[v] {
                continue;
            }
            let fan = self.vert_corners.row(v);
            let angle_sum: f64 = fan
                .iter()
                .map(|&k| corner_angle(positions, self.faces[k as usize / 3], v as u32))
                .sum();
            self.corner[v] =
                fan.len() == 1 || (angle_sum - std::f64::consts::PI).abs() > angle_tolerance;
        }
    }

    /// One level of 1-to-4 refinement: vertex `v` stays `v`, edge `e` gets the new vertex
    /// `V + e`, face `f` becomes faces `4f + t` (corner `t`: `(v_t, m_t, m_{t+2})`) and `4f + 3`
    /// (the middle `(m_0, m_1, m_2)`), where `m_t = V + face_edges[f][t]`. All orientations are
    /// inherited. The fine edges come out directly in [`EdgeList`] order:
    /// first `(v, V + e)` for `v` ascending and, per `v`, `e` ascending (these are the
    /// `vert_edges` rows, so edge `(v, V+e)` has id `vert_edges.offsets[v] + rank`), then
    /// `(V + e, V + e')` for `e < e'` ascending.
    pub fn refine(&self) -> Topology {
        let (faces, edges, face_edges, edge_faces) = self.refine_parts();
        let mut corner = self.corner.clone();
        corner.resize(self.n_vertices + self.n_edges(), false);
        Topology::from_parts(
            self.n_vertices + self.n_edges(),
            faces,
            edges,
            face_edges,
            edge_faces,
            corner,
        )
    }

    /// Only the fine triangles (what the last level needs).
    pub fn refine_faces(&self) -> Vec<[u32; 3]> {
        let v0 = self.n_vertices as u32;
        let mut out = Vec::with_capacity(4 * self.n_faces());
        for (f, t) in self.faces.iter().enumerate() {
            let m = self.face_edges[f].map(|e| v0 + e);
            for c in 0..3 {
                out.push([t[c], m[c], m[(c + 2) % 3]]);
            }
            out.push(m);
        }
        out
    }

    #[allow(clippy::type_complexity)]
    fn refine_parts(&self) -> (Vec<[u32; 3]>, Vec<[u32; 2]>, Vec<[u32; 3]>, Vec<[u32; 2]>) {
        let nv = self.n_vertices as u32;
        let ne = self.n_edges();
        let partners = self.interior_partners();
        let mut edges: Vec<[u32; 2]> = Vec::with_capacity(2 * ne + 3 * self.n_faces());
        for v in 0..self.n_vertices {
            for &e in self.vert_edges.row(v) {
                edges.push([v as u32, nv + e]);
            }
        }
        for e in 0..ne {
            for &p in partners.row(e) {
                edges.push([nv + e as u32, nv + p]);
            }
        }
        let interior_id = |a: u32, b: u32| -> u32 {
            let (lo, hi) = (a.min(b) as usize, a.max(b));
            let rank = partners.row(lo).iter().position(|&p| p == hi).unwrap();
            (2 * ne + partners.offsets[lo] + rank) as u32
        };
        let even_id = |v: u32, e: u32| -> u32 {
            let side = usize::from(self.edges[e as usize][0] != v);
            self.fine_even_edge(e as usize, side) as u32
        };
        let faces = self.refine_faces();
        let mut face_edges = Vec::with_capacity(faces.len());
        for (f, t) in self.faces.iter().enumerate() {
            let ce = self.face_edges[f];
            let mid = [0, 1, 2].map(|c| interior_id(ce[c], ce[(c + 1) % 3]));
            for c in 0..3 {
                let prev = (c + 2) % 3;
                face_edges.push([even_id(t[c], ce[c]), mid[prev], even_id(t[c], ce[prev])]);
            }
            face_edges.push(mid);
        }
        let edge_faces = edge_faces_unchecked(&face_edges, edges.len());
        (faces, edges, face_edges, edge_faces)
    }

    /// Per coarse edge `e`, the edges `e' > e` that share a face with it (ascending).
    fn interior_partners(&self) -> Csr {
        let pairs = |f: usize| {
            let fe = self.face_edges[f];
            [0, 1, 2].map(|c| (fe[c].min(fe[(c + 1) % 3]), fe[c].max(fe[(c + 1) % 3])))
        };
        let mut offsets = vec![0usize; self.n_edges() + 1];
        for f in 0..self.n_faces() {
            for (lo, _) in pairs(f) {
                offsets[lo as usize + 1] += 1;
            }
        }
        for e in 0..self.n_edges() {
            offsets[e + 1] += offsets[e];
        }
        let mut fill = offsets.clone();
        let mut items = vec![0u32; offsets[self.n_edges()]];
        for f in 0..self.n_faces() {
            for (lo, hi) in pairs(f) {
                items[fill[lo as usize]] = hi;
                fill[lo as usize] += 1;
            }
        }
        for e in 0..self.n_edges() {
            items[offsets[e]..offsets[e + 1]].sort_unstable();
        }
        Csr { offsets, items }
    }

    fn check_orientation_and_duplicates(&self) -> Result<()> {
        for e in 0..self.n_edges() {
            let [f, g] = self.edge_faces[e];
            if g == NONE {
                continue;
            }
            let (sf, sg) = (self.slot_sign(f as usize, e), self.slot_sign(g as usize, e));
            let [a, b] = self.edges[e];
            let opp =
                |h: u32| self.faces[h as usize][(self.edge_slot(h as usize, e as u32) + 2) % 3];
            if opp(f) == opp(g) {
                return Err(Error::InvalidMesh(format!(
                    "triangles {f} and {g} have the same three vertices; a wrinkle base mesh \
                     must not contain duplicated triangles"
                )));
            }
            if sf == sg {
                return Err(Error::InvalidMesh(format!(
                    "triangles {f} and {g} traverse edge ({a}, {b}) in the same direction: \
                     the mesh is not consistently oriented (or not orientable); wrinkle \
                     displacement needs consistent normals"
                )));
            }
        }
        Ok(())
    }

    /// +1 when face `f` traverses edge `e` from its smaller to its larger vertex.
    fn slot_sign(&self, f: usize, e: usize) -> i8 {
        let t = self.edge_slot(f, e as u32);
        if self.faces[f][t] < self.faces[f][(t + 1) % 3] {
            1
        } else {
            -1
        }
    }

    fn check_vertex_fans(&self) -> Result<()> {
        for v in 0..self.n_vertices {
            let n_faces = self.vert_corners.len(v);
            if n_faces == 0 {
                continue;
            }
            let bnd: Vec<u32> = self
                .vert_edges
                .row(v)
                .iter()
                .copied()
                .filter(|&e| self.is_boundary_edge(e as usize))
                .collect();
            let fan = if bnd.is_empty() || bnd.len() == 2 {
                self.walk_fan(v as u32, bnd.first().copied())
            } else {
                0
            };
            if fan != n_faces {
                return Err(Error::InvalidMesh(format!(
                    "vertex {v} is non-manifold: its {n_faces} triangles do not form a single \
                     fan (disk or half-disk); {} of its edges are boundary edges",
                    bnd.len()
                )));
            }
        }
        Ok(())
    }

    /// Number of faces reached by rotating around `v` across the edges at `v`, starting from
    /// the face of boundary edge `start_edge` (or from the first face of `v`).
    fn walk_fan(&self, v: u32, start_edge: Option<u32>) -> usize {
        let n = self.vert_corners.len(v as usize);
        let (start, mut came) = match start_edge {
            Some(e) => (self.edge_faces[e as usize][0], e),
            None => {
                let f = self.vert_corners.row(v as usize)[0] / 3;
                (
                    f,
                    self.face_edges[f as usize][self.corner_of(f as usize, v)],
                )
            }
        };
        let (mut cur, mut count) = (start, 1);
        while count <= n {
            let c = self.corner_of(cur as usize, v);
            let fe = self.face_edges[cur as usize];
            let out = if fe[c] == came {
                fe[(c + 2) % 3]
            } else {
                fe[c]
            };
            let next = self.other_face(out as usize, cur);
            if next == NONE || next == start {
                break;
            }
            count += 1;
            came = out;
            cur = next;
        }
        count
    }
}

fn check_distinct_corners(faces: &[[u32; 3]]) -> Result<()> {
    match faces
        .iter()
        .position(|t| t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
    {
        Some(f) => Err(Error::InvalidMesh(format!(
            "triangle {f} ({}, {}, {}) repeats a vertex",
            faces[f][0], faces[f][1], faces[f][2]
        ))),
        None => Ok(()),
    }
}

fn edge_faces_checked(
    faces: &[[u32; 3]],
    face_edges: &[[u32; 3]],
    edges: &[[u32; 2]],
) -> Result<Vec<[u32; 2]>> {
    let mut ef = vec![[NONE; 2]; edges.len()];
    for (f, fe) in face_edges.iter().enumerate() {
        for &e in fe {
            let slot = &mut ef[e as usize];
            if slot[0] == NONE {
                slot[0] = f as u32;
            } else if slot[1] == NONE {
                slot[1] = f as u32;
            } else {
                let [a, b] = edges[e as usize];
                return Err(Error::InvalidMesh(format!(
                    "edge ({a}, {b}) is shared by more than two triangles ({}, {} and {f}, \
                     triangle {f} = {:?}): the mesh is non-manifold",
                    slot[0], slot[1], faces[f]
                )));
            }
        }
    }
    Ok(ef)
}

fn edge_faces_unchecked(face_edges: &[[u32; 3]], n_edges: usize) -> Vec<[u32; 2]> {
    let mut ef = vec![[NONE; 2]; n_edges];
    for (f, fe) in face_edges.iter().enumerate() {
        for &e in fe {
            let slot = &mut ef[e as usize];
            if slot[0] == NONE {
                slot[0] = f as u32;
            } else {
                slot[1] = f as u32;
            }
        }
    }
    ef
}

fn edge_ranks(vert_edges: &Csr, edges: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let mut rank = vec![[0u32; 2]; edges.len()];
    for v in 0..vert_edges.offsets.len() - 1 {
        for (r, &e) in vert_edges.row(v).iter().enumerate() {
            let side = usize::from(edges[e as usize][0] != v as u32);
            rank[e as usize][side] = r as u32;
        }
    }
    rank
}

/// Interior angle of triangle `t` at its corner holding `v`.
fn corner_angle(p: &[[f64; 3]], t: [u32; 3], v: u32) -> f64 {
    let c = t.iter().position(|&x| x == v).unwrap_or(0);
    let o = Vec3::from(p[t[c] as usize]);
    let a = Vec3::from(p[t[(c + 1) % 3] as usize]) - o;
    let b = Vec3::from(p[t[(c + 2) % 3] as usize]) - o;
    a.cross(b).length().atan2(a.dot(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crate's test grid, `n × n` squares.
    fn grid(n: u32) -> TriMesh {
        crate::mesh::test_shapes::grid(n, n)
    }

    #[test]
    fn refinement_matches_edge_list_numbering() {
        let m = grid(3);
        let mut topo = Topology::from_mesh(&m, &m.edges()).unwrap();
        for _ in 0..3 {
            let fine = topo.refine();
            let pos = vec![[0.0; 3]; fine.n_vertices];
            let fm = TriMesh::new(pos, fine.faces.clone()).unwrap();
            let el = fm.edges();
            let want: Vec<[u32; 2]> = el.edges.iter().map(|e| e.0).collect();
            assert_eq!(want, fine.edges);
            assert_eq!(el.face_edges, fine.face_edges);
            let checked = Topology::from_mesh(&fm, &el).unwrap();
            assert_eq!(checked.edge_faces, fine.edge_faces);
            topo = fine;
        }
    }

    #[test]
    fn rejects_non_manifold() {
        // three triangles on one edge
        let p = vec![
            [0.; 3],
            [1., 0., 0.],
            [0., 1., 0.],
            [0., -1., 0.],
            [0., 0., 1.],
        ];
        let m = TriMesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap();
        let err = Topology::from_mesh(&m, &m.edges()).unwrap_err();
        assert!(err.to_string().contains("more than two triangles"), "{err}");
        // bow-tie vertex
        let p = vec![
            [0.; 3],
            [1., 0., 0.],
            [1., 1., 0.],
            [-1., 0., 0.],
            [-1., -1., 0.],
        ];
        let m = TriMesh::new(p, vec![[0, 1, 2], [0, 3, 4]]).unwrap();
        let err = Topology::from_mesh(&m, &m.edges()).unwrap_err();
        assert!(err.to_string().contains("non-manifold"), "{err}");
        // flipped neighbour
        let p = vec![[0.; 3], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]];
        let m = TriMesh::new(p, vec![[0, 1, 2], [1, 2, 3]]).unwrap();
        let err = Topology::from_mesh(&m, &m.edges()).unwrap_err();
        assert!(err.to_string().contains("consistently oriented"), "{err}");
    }
}
