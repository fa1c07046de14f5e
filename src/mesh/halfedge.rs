//! [`HalfEdgeMesh`]: compact half-edge connectivity for manifold triangle meshes (closed or with
//! boundary), with the guarded local operations the simplifier needs (edge collapse and flip,
//! each with a pure `can_*` check and an O(local) undo record).
//!
//! # Representation
//!
//! Everything is index based: vertices, faces, edges and half-edges are typed `u32` ids
//! ([`VertexId`], [`FaceId`], [`EdgeId`], [`HalfedgeId`]) into per-element storage, so passing
//! one kind of id where another is expected is a type error; each id type's `INVALID`
//! (`u32::MAX`) means "none". Raw indices appear only at the boundary ([`HalfEdgeMesh::from_trimesh`],
//! [`HalfEdgeMesh::to_trimesh`], [`HalfEdgeMesh::positions`]). Half-edges come in pairs: the two halves of
//! edge `e` are `2e` and `2e + 1`; that arithmetic lives only in the typed ids ([`HalfedgeId::twin`],
//! [`HalfedgeId::edge`], [`EdgeId::halfedge`]), which also come with per-element containers
//! ([`VertexData`], [`FaceData`], [`EdgeData`], [`HalfedgeData`]) indexable only by their own id
//! type. A half-edge with no face is a *boundary* half-edge; boundary half-edges are linked by
//! `next`/`prev` into the boundary loops (a boundary loop runs clockwise seen from the front side
//! of the surface).
//!
//! Deleting elements (by a collapse) only marks them dead, so ids of the other elements stay
//! valid; [`HalfEdgeMesh::garbage_collect`] compacts the storage and says where everything went.
//!
//! # Invariants
//!
//! Every public operation keeps these (verified by [`HalfEdgeMesh::check_invariants`]):
//! - `twin(twin(h)) = h`, `prev(next(h)) = h`, `next(prev(h)) = h`, `origin(next(h)) = target(h)`,
//!   and `face(next(h)) = face(h)`; a face's loop has exactly 3 half-edges; each edge has at least
//!   one face; no edge joins a vertex to itself.
//! - Each live vertex that is not isolated has an outgoing half-edge, and when the vertex lies on
//!   the boundary that half-edge is its (unique) boundary half-edge ("boundary first"); all faces
//!   around a vertex form a single fan, so rotating around it visits every incident face once.
//! - There is at most one edge between two vertices, no two faces have the same three vertices
//!   (the mesh is a simplicial 2-manifold with boundary), and every position is finite.
//!
//! # Example
//!
//! ```
//! use pleat::mesh::halfedge::VertexId;
//! use pleat::mesh::{HalfEdgeMesh, TriMesh};
//! // A unit square split along the diagonal 0–2.
//! let quad = TriMesh::new(
//!     vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
//!     vec![[0, 1, 2], [0, 2, 3]],
//! )?;
//! let mut m = HalfEdgeMesh::from_trimesh(&quad)?;
//! assert_eq!((m.euler_characteristic(), m.boundary_loop_count()), (1, 1));
//!
//! // Collapse the boundary edge 0→1 (vertex 1 merges into 0), then revert it.
//! let v = |i| VertexId::new(i);
//! let h = m.find_halfedge(v(0), v(1)).unwrap();
//! assert!(m.can_collapse(h).is_ok());
//! let rec = m.collapse_edge(h, [0.5, 0., 0.])?;
//! assert_eq!((rec.kept_vertex, rec.removed_vertex, m.face_count()), (v(0), v(1), 1));
//! m.undo(rec.undo)?;
//! assert_eq!(m.to_trimesh(), quad);
//!
//! // Flip the diagonal: 0→2 lies in face (0, 2, 3), so it becomes 3→1.
//! let rec = m.flip_edge(m.find_halfedge(v(0), v(2)).unwrap())?;
//! assert_eq!(rec.new_vertices, [v(3), v(1)]);
//! m.check_invariants()?;
//! # Ok::<(), pleat::Error>(())
//! ```
//!
//! # Ids and panics
//!
//! Accessors take ids below the matching `*_capacity()`; an id at or beyond it panics with a
//! message naming the kind of id and the capacity. A *deleted* id never panics in the
//! connectivity accessors (they return an `INVALID` id, `None` or an empty iterator) and the
//! operations refuse it; only the face geometry helpers (`face_positions`, `face_normal`,
//! `face_area`, `face_area_vector`) need a live face and panic on a deleted one. The C ABI never
//! exposes half-edge ids.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::geom::{tri_normal, Vec3};
use crate::{Error, Result};

mod build;
mod check;
mod ids;
mod ops;
#[cfg(test)]
mod tests;

pub use build::Compaction;
pub use ids::{
    EdgeData, EdgeId, ElementId, FaceData, FaceId, HalfedgeData, HalfedgeId, IdVec, VertexData,
    VertexId,
};
pub use ops::{CollapseRecord, FlipRecord, Refusal, Undo};

/// One half-edge: its loop links, the vertex it leaves and the face on its left.
/// All four fields are `INVALID` for a deleted half-edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct HalfEdge {
    next: HalfedgeId,
    prev: HalfedgeId,
    origin: VertexId,
    face: FaceId,
}

impl HalfEdge {
    const DELETED: HalfEdge = HalfEdge {
        next: HalfedgeId::INVALID,
        prev: HalfedgeId::INVALID,
        origin: VertexId::INVALID,
        face: FaceId::INVALID,
    };
}

/// Half-edge connectivity of a manifold triangle mesh, possibly with boundary, with `f64`
/// positions.
///
/// Built by [`HalfEdgeMesh::from_trimesh`], which refuses anything that is not a consistently
/// oriented simplicial 2-manifold with boundary; converted back by
/// [`HalfEdgeMesh::to_trimesh`]. See the [module documentation](self) for the representation,
/// the invariants every operation keeps and the id rules.
#[derive(Debug, Clone)]
pub struct HalfEdgeMesh {
    positions: VertexData<[f64; 3]>,
    /// Outgoing half-edge per vertex (boundary first); `INVALID` when isolated or deleted.
    v_out: VertexData<HalfedgeId>,
    v_alive: VertexData<bool>,
    halfedges: HalfedgeData<HalfEdge>,
    /// One half-edge per face (the one starting at the face's first corner); `INVALID` when
    /// deleted.
    f_he: FaceData<HalfedgeId>,
    n_vertices: usize,
    n_edges: usize,
    n_faces: usize,
    /// Identifies the current topological state, so an [`Undo`] applies only to the state its
    /// operation produced (stamps come from [`fresh_stamp`] and are never reused, even across
    /// meshes and clones).
    stamp: u64,
}

/// A stamp never handed out before in this process.
fn fresh_stamp() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

#[cold]
#[inline(never)]
#[track_caller]
fn out_of_range(kind: &str, id: u32, capacity: usize) -> ! {
    panic!("{kind} id {id} is out of range (this HalfEdgeMesh has {capacity} {kind} slots)")
}

impl HalfEdgeMesh {
    // ----------------------------------------------------------------------------------------
    // Internal record access with clear out-of-range panics.

    #[inline]
    #[track_caller]
    fn he(&self, h: HalfedgeId) -> HalfEdge {
        match self.halfedges.get(h) {
            Some(x) => *x,
            None => out_of_range("half-edge", h.raw(), self.halfedges.len()),
        }
    }

    #[inline]
    #[track_caller]
    fn check_vertex(&self, v: VertexId) -> VertexId {
        if v.index() < self.v_out.len() {
            v
        } else {
            out_of_range("vertex", v.raw(), self.v_out.len())
        }
    }

    #[inline]
    #[track_caller]
    fn check_face(&self, f: FaceId) -> FaceId {
        if f.index() < self.f_he.len() {
            f
        } else {
            out_of_range("face", f.raw(), self.f_he.len())
        }
    }

    // ----------------------------------------------------------------------------------------
    // Counts and liveness.

    /// Number of live vertices, isolated ones included.
    pub fn vertex_count(&self) -> usize {
        self.n_vertices
    }

    /// Number of live faces.
    pub fn face_count(&self) -> usize {
        self.n_faces
    }

    /// Number of live edges (each is two half-edges).
    pub fn edge_count(&self) -> usize {
        self.n_edges
    }

    /// Number of live half-edges (`2 · edge_count()`).
    pub fn halfedge_count(&self) -> usize {
        2 * self.n_edges
    }

    /// Number of vertex slots, live or deleted: valid vertex ids are `0..vertex_capacity()`.
    pub fn vertex_capacity(&self) -> usize {
        self.v_out.len()
    }

    /// Number of face slots, live or deleted: valid face ids are `0..face_capacity()`.
    pub fn face_capacity(&self) -> usize {
        self.f_he.len()
    }

    /// Number of edge slots, live or deleted: valid edge ids are `0..edge_capacity()`.
    pub fn edge_capacity(&self) -> usize {
        self.halfedges.len() / 2
    }

    /// Number of half-edge slots, live or deleted: valid ids are `0..halfedge_capacity()`.
    pub fn halfedge_capacity(&self) -> usize {
        self.halfedges.len()
    }

    /// True when vertex `v` has not been deleted (isolated vertices are live).
    #[track_caller]
    pub fn is_vertex_live(&self, v: VertexId) -> bool {
        self.v_alive[self.check_vertex(v)]
    }

    /// True when face `f` has not been deleted.
    #[track_caller]
    pub fn is_face_live(&self, f: FaceId) -> bool {
        self.f_he[self.check_face(f)].is_valid()
    }

    /// True when half-edge `h` (and so its twin and its edge) has not been deleted.
    #[inline]
    #[track_caller]
    pub fn is_halfedge_live(&self, h: HalfedgeId) -> bool {
        self.he(h).origin.is_valid()
    }

    /// True when edge `e` has not been deleted.
    #[track_caller]
    pub fn is_edge_live(&self, e: EdgeId) -> bool {
        self.is_halfedge_live(e.halfedge())
    }

    /// The live vertex ids in increasing order (isolated vertices included).
    pub fn vertices(&self) -> impl Iterator<Item = VertexId> + '_ {
        self.v_alive.ids().filter(|&v| self.v_alive[v])
    }

    /// The live face ids in increasing order.
    pub fn faces(&self) -> impl Iterator<Item = FaceId> + '_ {
        self.f_he.ids().filter(|&f| self.f_he[f].is_valid())
    }

    /// The live edge ids in increasing order.
    pub fn edges(&self) -> impl Iterator<Item = EdgeId> + '_ {
        (0..self.edge_capacity() as u32)
            .map(EdgeId::new)
            .filter(|&e| self.halfedges[e.halfedge()].origin.is_valid())
    }

    /// The live half-edge ids in increasing order.
    pub fn halfedges(&self) -> impl Iterator<Item = HalfedgeId> + '_ {
        self.halfedges
            .ids()
            .filter(|&h| self.halfedges[h].origin.is_valid())
    }

    // ----------------------------------------------------------------------------------------
    // Half-edge navigation.

    /// The opposite half-edge of the same edge ([`HalfedgeId::twin`]). Never fails (no range
    /// check).
    #[inline]
    pub fn twin(&self, h: HalfedgeId) -> HalfedgeId {
        h.twin()
    }

    /// The edge of half-edge `h` ([`HalfedgeId::edge`]). Never fails (no range check).
    #[inline]
    pub fn edge(&self, h: HalfedgeId) -> EdgeId {
        h.edge()
    }

    /// The first half-edge `2e` of edge `e` (its twin is `2e + 1`). Never fails (no range check).
    #[inline]
    pub fn edge_halfedge(&self, e: EdgeId) -> HalfedgeId {
        e.halfedge()
    }

    /// The next half-edge in `h`'s face (or boundary loop); `INVALID` when `h` is deleted.
    #[inline]
    #[track_caller]
    pub fn next(&self, h: HalfedgeId) -> HalfedgeId {
        self.he(h).next
    }

    /// The previous half-edge in `h`'s face (or boundary loop); `INVALID` when `h` is deleted.
    #[inline]
    #[track_caller]
    pub fn prev(&self, h: HalfedgeId) -> HalfedgeId {
        self.he(h).prev
    }

    /// The vertex `h` leaves; `INVALID` when `h` is deleted.
    #[inline]
    #[track_caller]
    pub fn origin(&self, h: HalfedgeId) -> VertexId {
        self.he(h).origin
    }

    /// The vertex `h` points to (the origin of its twin); `INVALID` when `h` is deleted.
    #[inline]
    #[track_caller]
    pub fn target(&self, h: HalfedgeId) -> VertexId {
        self.he(h.twin()).origin
    }

    /// The face on the left of `h`, `None` for a boundary or deleted half-edge.
    #[inline]
    #[track_caller]
    pub fn face(&self, h: HalfedgeId) -> Option<FaceId> {
        let f = self.he(h).face;
        f.is_valid().then_some(f)
    }

    /// True when `h` is a live half-edge without a face (it lies in a boundary loop).
    #[inline]
    #[track_caller]
    pub fn is_boundary_halfedge(&self, h: HalfedgeId) -> bool {
        let x = self.he(h);
        x.origin.is_valid() && !x.face.is_valid()
    }

    /// True when live edge `e` has only one face (false for a deleted edge).
    #[track_caller]
    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        let h = e.halfedge();
        self.is_boundary_halfedge(h) || self.is_boundary_halfedge(h.twin())
    }

    /// The half-edge from `a` to `b`, if that edge exists. O(valence of `a`).
    #[track_caller]
    pub fn find_halfedge(&self, a: VertexId, b: VertexId) -> Option<HalfedgeId> {
        self.outgoing(a).find(|&h| self.target(h) == b)
    }

    // ----------------------------------------------------------------------------------------
    // Faces.

    /// The half-edge starting at the first corner of face `f`; `INVALID` when `f` is deleted.
    #[track_caller]
    pub fn face_halfedge(&self, f: FaceId) -> HalfedgeId {
        self.f_he[self.check_face(f)]
    }

    /// The three half-edges of face `f` in order, starting at its first corner;
    /// `[INVALID; 3]` when `f` is deleted.
    #[track_caller]
    pub fn face_halfedges(&self, f: FaceId) -> [HalfedgeId; 3] {
        let h0 = self.face_halfedge(f);
        if !h0.is_valid() {
            return [HalfedgeId::INVALID; 3];
        }
        let h1 = self.next(h0);
        [h0, h1, self.next(h1)]
    }

    /// The three corners of face `f`, counter-clockwise seen from the front; `[INVALID; 3]`
    /// when `f` is deleted.
    #[track_caller]
    pub fn face_vertices(&self, f: FaceId) -> [VertexId; 3] {
        self.face_halfedges(f).map(|h| {
            if h.is_valid() {
                self.origin(h)
            } else {
                VertexId::INVALID
            }
        })
    }

    /// The corner positions of live face `f` (panics on a deleted face).
    #[track_caller]
    pub fn face_positions(&self, f: FaceId) -> [[f64; 3]; 3] {
        let vs = self.face_vertices(f);
        assert!(vs[0].is_valid(), "face {f} is deleted");
        vs.map(|v| self.positions[v])
    }

    /// `(b − a) × (c − a)` of live face `f`: normal direction with length twice the area
    /// (panics on a deleted face).
    #[track_caller]
    pub fn face_area_vector(&self, f: FaceId) -> Vec3 {
        let [a, b, c] = self.face_positions(f).map(Vec3::from);
        tri_normal(a, b, c)
    }

    /// Unit normal of live face `f` (right-hand rule over its corners); `[0, 0, 0]` for a
    /// degenerate (zero-area) face. Panics on a deleted face.
    #[track_caller]
    pub fn face_normal(&self, f: FaceId) -> Vec3 {
        let n = self.face_area_vector(f);
        let l = n.length();
        if l > 0.0 {
            n / l
        } else {
            Vec3::ZERO
        }
    }

    /// Area of live face `f` (panics on a deleted face).
    #[track_caller]
    pub fn face_area(&self, f: FaceId) -> f64 {
        0.5 * self.face_area_vector(f).length()
    }

    // ----------------------------------------------------------------------------------------
    // Vertices.

    /// The outgoing half-edge stored for `v`: the boundary half-edge leaving `v` when `v` is on
    /// the boundary. `None` when `v` is isolated or deleted.
    #[inline]
    #[track_caller]
    pub fn vertex_halfedge(&self, v: VertexId) -> Option<HalfedgeId> {
        let h = self.v_out[self.check_vertex(v)];
        h.is_valid().then_some(h)
    }

    /// The half-edges leaving `v`, counter-clockwise seen from the front. When `v` is on the
    /// boundary the first one is its boundary half-edge (which has no face) and the others follow
    /// across the fan, so every incident face is the face of exactly one of them. Empty for an
    /// isolated or deleted vertex. O(valence).
    #[track_caller]
    pub fn outgoing(&self, v: VertexId) -> impl Iterator<Item = HalfedgeId> + '_ {
        self.rotate(self.vertex_halfedge(v).unwrap_or(HalfedgeId::INVALID))
    }

    /// The half-edges leaving `origin(start)`, counter-clockwise from live half-edge `start`
    /// (nothing when `start` is `INVALID`).
    fn rotate(&self, start: HalfedgeId) -> impl Iterator<Item = HalfedgeId> + '_ {
        let mut cur = start;
        std::iter::from_fn(move || {
            if !cur.is_valid() {
                return None;
            }
            let h = cur;
            // twin(prev(h)) also leaves origin(h): the next outgoing half-edge counter-clockwise.
            let n = self.halfedges[h].prev.twin();
            cur = if n == start { HalfedgeId::INVALID } else { n };
            Some(h)
        })
    }

    /// The faces around `v`, counter-clockwise seen from the front, each once (from the boundary
    /// edge across the fan for a boundary vertex). O(valence).
    #[track_caller]
    pub fn vertex_faces(&self, v: VertexId) -> impl Iterator<Item = FaceId> + '_ {
        self.outgoing(v).filter_map(|h| self.face(h))
    }

    /// The neighbours of `v` (the targets of [`outgoing`](Self::outgoing)), counter-clockwise,
    /// each once. O(valence).
    #[track_caller]
    pub fn vertex_neighbors(&self, v: VertexId) -> impl Iterator<Item = VertexId> + '_ {
        self.outgoing(v).map(|h| self.target(h))
    }

    /// Number of edges at `v` (0 for an isolated or deleted vertex). O(valence).
    #[track_caller]
    pub fn valence(&self, v: VertexId) -> usize {
        self.outgoing(v).count()
    }

    /// True when `v` lies on a boundary loop. O(1) thanks to the boundary-first rule; false for
    /// isolated and deleted vertices.
    #[inline]
    #[track_caller]
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.vertex_halfedge(v)
            .is_some_and(|h| !self.halfedges[h].face.is_valid())
    }

    /// True when `v` is live and has no edge (an unreferenced vertex of the input).
    #[track_caller]
    pub fn is_isolated_vertex(&self, v: VertexId) -> bool {
        self.is_vertex_live(v) && !self.v_out[v].is_valid()
    }

    /// Position of vertex `v` (a deleted vertex keeps its last position).
    #[inline]
    #[track_caller]
    pub fn position(&self, v: VertexId) -> [f64; 3] {
        self.positions[self.check_vertex(v)]
    }

    /// All position slots, indexed by raw vertex index ([`VertexId::index`]; deleted slots
    /// included).
    pub fn positions(&self) -> &[[f64; 3]] {
        self.positions.as_slice()
    }

    /// Moves live vertex `v` to `p`.
    ///
    /// Errors with [`Error::InvalidArgument`] when a coordinate is not finite or `v` is deleted.
    /// It does not touch topology, so it does not invalidate [`Undo`] records; undoing an
    /// operation restores only the positions that operation changed.
    #[track_caller]
    pub fn set_position(&mut self, v: VertexId, p: [f64; 3]) -> Result<()> {
        let i = self.check_vertex(v);
        if !self.v_alive[i] {
            return Err(Error::InvalidArgument(format!(
                "cannot move vertex {v}: it is deleted"
            )));
        }
        check_finite(p, || format!("position of vertex {v}"))?;
        self.positions[i] = p;
        Ok(())
    }

    // ----------------------------------------------------------------------------------------
    // Global topology.

    /// Euler characteristic `V − E + F` of the live elements (isolated vertices count). 2 for a
    /// closed genus-0 surface, 0 for a torus, 1 for a disk; every operation preserves it.
    pub fn euler_characteristic(&self) -> i64 {
        self.n_vertices as i64 - self.n_edges as i64 + self.n_faces as i64
    }

    /// Number of boundary loops (0 for a closed mesh). O(mesh).
    pub fn boundary_loop_count(&self) -> usize {
        let mut seen = HalfedgeData::filled(self.halfedges.len(), false);
        let mut loops = 0;
        for h in self.halfedges.ids() {
            if seen[h] || !self.is_boundary_halfedge(h) {
                continue;
            }
            loops += 1;
            let mut x = h;
            while !seen[x] {
                seen[x] = true;
                x = self.next(x);
            }
        }
        loops
    }
}

/// `Err(InvalidArgument)` naming `what` when a coordinate of `p` is NaN or infinite.
fn check_finite(p: [f64; 3], what: impl FnOnce() -> String) -> Result<()> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{} ({}, {}, {}) is not finite",
            what(),
            p[0],
            p[1],
            p[2]
        )))
    }
}
