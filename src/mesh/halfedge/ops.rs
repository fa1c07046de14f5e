//! Local operations: edge collapse and edge flip, each with a pure topological check, a record of
//! what changed, and an O(local) [`Undo`].

use std::fmt;

use super::{
    check_finite, fresh_stamp, EdgeId, FaceId, HalfEdge, HalfEdgeMesh, HalfedgeId, VertexId,
};
use crate::{Error, Result};

/// Why a local operation is topologically not allowed (returned by
/// [`HalfEdgeMesh::can_collapse`] and [`HalfEdgeMesh::can_flip`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// The half-edge has been deleted.
    Deleted,
    /// Collapse: the edge is interior but both endpoints are on the boundary; collapsing it would
    /// pinch the surface into a non-manifold vertex.
    BoundaryPinch,
    /// Collapse: the link condition fails: `vertex` is a common neighbour of both endpoints but
    /// not opposite the edge in one of its faces, so the collapse would fold two edges into one.
    LinkCondition {
        /// The extra common neighbour.
        vertex: VertexId,
    },
    /// Collapse: the edge belongs to a tetrahedron (a closed component of 4 faces), which cannot
    /// get smaller.
    Tetrahedron,
    /// Collapse: the edge's only face has all three edges on the boundary (a lone triangle),
    /// which cannot get smaller.
    IsolatedTriangle,
    /// A vertex would be left with fewer edges than a manifold needs (3 inside, 2 on the
    /// boundary).
    Valence {
        /// The vertex concerned.
        vertex: VertexId,
        /// Its valence after the operation.
        valence: usize,
    },
    /// Flip: the edge is on the boundary (only interior edges can be flipped).
    BoundaryEdge,
    /// Flip: the edge the flip would create already exists.
    EdgeExists {
        /// One end of the existing edge.
        a: VertexId,
        /// The other end.
        b: VertexId,
    },
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Refusal::Deleted => write!(f, "the half-edge is deleted"),
            Refusal::BoundaryPinch => write!(
                f,
                "the edge is interior but both endpoints are on the boundary (would pinch the surface)"
            ),
            Refusal::LinkCondition { vertex } => write!(
                f,
                "link condition fails: vertex {vertex} is a common neighbour not opposite the edge"
            ),
            Refusal::Tetrahedron => write!(f, "the edge belongs to a tetrahedron component"),
            Refusal::IsolatedTriangle => write!(f, "the edge's face is a lone triangle"),
            Refusal::Valence { vertex, valence } => {
                write!(f, "vertex {vertex} would be left with valence {valence}")
            }
            Refusal::BoundaryEdge => write!(f, "the edge is on the boundary"),
            Refusal::EdgeExists { a, b } => write!(f, "edge ({a}, {b}) already exists"),
        }
    }
}

impl std::error::Error for Refusal {}

/// One saved record, restored by [`HalfEdgeMesh::undo`].
#[derive(Debug, Clone, Copy)]
enum Saved {
    HalfEdge(HalfedgeId, HalfEdge),
    Face(FaceId, HalfedgeId),
    Vertex {
        id: VertexId,
        out: HalfedgeId,
        alive: bool,
    },
    Position(VertexId, [f64; 3]),
}

/// What [`HalfEdgeMesh::undo`] needs to revert one operation: the previous values of the records
/// the operation changed. Its size is O(valence), and undoing costs the same.
///
/// An undo record applies only to the exact state its operation produced: undo operations in
/// reverse order (last first). A record that no longer matches (another operation or a
/// [`garbage_collect`](HalfEdgeMesh::garbage_collect) happened since, or it came from another
/// mesh or a clone) is refused. Dropping a record just makes the operation permanent.
#[derive(Debug, Clone)]
pub struct Undo {
    saved: Vec<Saved>,
    counts: [usize; 3],
    stamp_before: u64,
    stamp_after: u64,
}

/// What [`HalfEdgeMesh::collapse_edge`] changed.
#[derive(Debug, Clone)]
pub struct CollapseRecord {
    /// The surviving vertex: the origin of the collapsed half-edge, now at the new position.
    pub kept_vertex: VertexId,
    /// The deleted vertex: the target of the collapsed half-edge.
    pub removed_vertex: VertexId,
    /// The deleted faces (the one or two faces of the edge).
    pub removed_faces: Vec<FaceId>,
    /// The deleted edges: the collapsed edge first, then one edge per deleted face.
    pub removed_edges: Vec<EdgeId>,
    /// For each deleted face, `[deleted edge, surviving edge]`: the two edges from the face's
    /// third vertex that were merged into one (the surviving one joins it to `kept_vertex`).
    pub merged_edges: Vec<[EdgeId; 2]>,
    /// Every face around `kept_vertex` after the collapse: exactly the live faces whose corners
    /// changed or moved (for BVH refits and error updates).
    pub modified_faces: Vec<FaceId>,
    /// Reverts the collapse (see [`HalfEdgeMesh::undo`]).
    pub undo: Undo,
}

/// What [`HalfEdgeMesh::flip_edge`] changed.
#[derive(Debug, Clone)]
pub struct FlipRecord {
    /// The flipped edge (same id before and after).
    pub edge: EdgeId,
    /// Its endpoints before the flip.
    pub old_vertices: [VertexId; 2],
    /// Its endpoints after the flip: the flipped half-edge now runs from `new_vertices[0]` to
    /// `new_vertices[1]`.
    pub new_vertices: [VertexId; 2],
    /// The two faces, both modified (same ids before and after).
    pub faces: [FaceId; 2],
    /// Reverts the flip (see [`HalfEdgeMesh::undo`]).
    pub undo: Undo,
}

/// Applies changes to a mesh while saving every record's previous value.
struct Editor<'a> {
    m: &'a mut HalfEdgeMesh,
    saved: Vec<Saved>,
    counts: [usize; 3],
}

impl<'a> Editor<'a> {
    fn new(m: &'a mut HalfEdgeMesh) -> Self {
        let counts = [m.n_vertices, m.n_edges, m.n_faces];
        Editor {
            m,
            saved: Vec::with_capacity(32),
            counts,
        }
    }

    fn he_mut(&mut self, h: HalfedgeId) -> &mut HalfEdge {
        let old = self.m.halfedges[h];
        self.saved.push(Saved::HalfEdge(h, old));
        &mut self.m.halfedges[h]
    }

    /// `next(a) = b`, `prev(b) = a`.
    fn link(&mut self, a: HalfedgeId, b: HalfedgeId) {
        self.he_mut(a).next = b;
        self.he_mut(b).prev = a;
    }

    fn set_face_halfedge(&mut self, f: FaceId, h: HalfedgeId) {
        let old = self.m.f_he[f];
        self.saved.push(Saved::Face(f, old));
        self.m.f_he[f] = h;
    }

    fn set_vertex(&mut self, v: VertexId, out: HalfedgeId, alive: bool) {
        let (old_out, old_alive) = (self.m.v_out[v], self.m.v_alive[v]);
        self.saved.push(Saved::Vertex {
            id: v,
            out: old_out,
            alive: old_alive,
        });
        self.m.v_out[v] = out;
        self.m.v_alive[v] = alive;
    }

    fn set_out(&mut self, v: VertexId, out: HalfedgeId) {
        self.set_vertex(v, out, true);
    }

    fn set_position(&mut self, v: VertexId, p: [f64; 3]) {
        let old = self.m.positions[v];
        self.saved.push(Saved::Position(v, old));
        self.m.positions[v] = p;
    }

    /// Puts `by` in the place of `t` in `t`'s loop (face or boundary), taking over its face.
    fn replace_in_loop(&mut self, t: HalfedgeId, by: HalfedgeId) {
        let x = self.m.halfedges[t];
        self.link(x.prev, by);
        self.link(by, x.next);
        self.he_mut(by).face = x.face;
        if x.face.is_valid() && self.m.f_he[x.face] == t {
            self.set_face_halfedge(x.face, by);
        }
    }

    fn delete_edge(&mut self, e: EdgeId) {
        let h = e.halfedge();
        *self.he_mut(h) = HalfEdge::DELETED;
        *self.he_mut(h.twin()) = HalfEdge::DELETED;
        self.m.n_edges -= 1;
    }

    fn delete_face(&mut self, f: FaceId) {
        self.set_face_halfedge(f, HalfedgeId::INVALID);
        self.m.n_faces -= 1;
    }

    fn delete_vertex(&mut self, v: VertexId) {
        self.set_vertex(v, HalfedgeId::INVALID, false);
        self.m.n_vertices -= 1;
    }

    /// Makes `v`'s outgoing half-edge its boundary half-edge if it has one (rotating from `start`,
    /// a live half-edge leaving `v`), else keeps a live one.
    fn fix_outgoing(&mut self, v: VertexId, start: HalfedgeId) {
        let boundary = self
            .m
            .rotate(start)
            .find(|&h| self.m.is_boundary_halfedge(h));
        let cur = self.m.v_out[v];
        let want = match boundary {
            Some(b) => b,
            None if cur.is_valid() && self.m.halfedges[cur].origin == v => cur,
            None => start,
        };
        if want != cur {
            self.set_out(v, want);
        }
    }

    /// Ends the edit: gives the mesh a fresh state stamp and returns the undo record.
    fn finish(self) -> Undo {
        let stamp_before = self.m.stamp;
        self.m.stamp = fresh_stamp();
        Undo {
            saved: self.saved,
            counts: self.counts,
            stamp_before,
            stamp_after: self.m.stamp,
        }
    }
}

impl HalfEdgeMesh {
    /// The vertex opposite half-edge `h` in its face (`None` for a boundary half-edge).
    pub(super) fn opposite_vertex(&self, h: HalfedgeId) -> Option<VertexId> {
        self.face(h).map(|_| self.target(self.next(h)))
    }

    /// Minimum valence of a manifold vertex: 3 inside, 2 on the boundary.
    fn min_valence(&self, v: VertexId) -> usize {
        if self.is_boundary_vertex(v) {
            2
        } else {
            3
        }
    }

    /// Checks whether [`collapse_edge`](Self::collapse_edge)`(h, ..)` keeps the mesh a
    /// simplicial 2-manifold with the same topology (Euler characteristic and boundary loops).
    /// Pure; O(valence of both endpoints). Direction matters only for which vertex survives.
    ///
    /// Refuses (in this order) a deleted half-edge; an interior edge whose endpoints are both on
    /// the boundary; the link condition (Dey–Edelsbrunner, with a virtual vertex joined to the
    /// boundary): the common neighbours of the endpoints must be exactly the vertices opposite the
    /// edge, the edge must not belong to a tetrahedron, and a boundary edge's face must not be a
    /// lone triangle; and, as a safeguard, a vertex left below valence 3 (2 on the boundary).
    /// Panics if `h` is out of range.
    #[track_caller]
    pub fn can_collapse(&self, h: HalfedgeId) -> std::result::Result<(), Refusal> {
        if !self.is_halfedge_live(h) {
            return Err(Refusal::Deleted);
        }
        let o = h.twin();
        let (a, b) = (self.origin(h), self.origin(o));
        let (c, d) = (self.opposite_vertex(h), self.opposite_vertex(o));
        let interior = c.is_some() && d.is_some();
        if interior && self.is_boundary_vertex(a) && self.is_boundary_vertex(b) {
            return Err(Refusal::BoundaryPinch);
        }
        let valences = self.check_common_neighbours(a, b, c, d)?;
        match (c, d) {
            (Some(c), Some(d)) => self.check_not_tetrahedron(a, b, c, d)?,
            (Some(x), None) | (None, Some(x)) => self.check_not_lone_triangle(a, b, x)?,
            (None, None) => unreachable!("live edge {} has no face", h.edge()),
        }
        self.check_collapse_valences([a, b], valences, c, d, interior)
    }

    /// Link condition on vertices: every common neighbour of `a` and `b` is `c` or `d`.
    /// Returns the valences of `a` and `b`.
    fn check_common_neighbours(
        &self,
        a: VertexId,
        b: VertexId,
        c: Option<VertexId>,
        d: Option<VertexId>,
    ) -> std::result::Result<[usize; 2], Refusal> {
        let mut around_a: Vec<VertexId> = self.vertex_neighbors(a).collect();
        around_a.sort_unstable();
        let mut valence_b = 0;
        for x in self.vertex_neighbors(b) {
            valence_b += 1;
            if Some(x) != c && Some(x) != d && around_a.binary_search(&x).is_ok() {
                return Err(Refusal::LinkCondition { vertex: x });
            }
        }
        Ok([around_a.len(), valence_b])
    }

    /// Link condition on edges: edge `c–d` must not have faces on both `a` and `b` (that makes
    /// `a, b, c, d` a tetrahedron).
    fn check_not_tetrahedron(
        &self,
        a: VertexId,
        b: VertexId,
        c: VertexId,
        d: VertexId,
    ) -> std::result::Result<(), Refusal> {
        if let Some(cd) = self.find_halfedge(c, d) {
            let (x, y) = (self.opposite_vertex(cd), self.opposite_vertex(cd.twin()));
            if (x == Some(a) && y == Some(b)) || (x == Some(b) && y == Some(a)) {
                return Err(Refusal::Tetrahedron);
            }
        }
        Ok(())
    }

    /// Link condition with the virtual boundary vertex: for boundary edge `a–b` with face
    /// `a, b, x`, edges `a–x` and `b–x` must not both be on the boundary.
    fn check_not_lone_triangle(
        &self,
        a: VertexId,
        b: VertexId,
        x: VertexId,
    ) -> std::result::Result<(), Refusal> {
        let on_boundary = |u: VertexId| {
            self.find_halfedge(u, x)
                .is_some_and(|h| self.is_boundary_edge(h.edge()))
        };
        if on_boundary(a) && on_boundary(b) {
            Err(Refusal::IsolatedTriangle)
        } else {
            Ok(())
        }
    }

    /// Valence safeguards: the merged vertex and the opposite vertices (which lose one edge each)
    /// keep a manifold valence.
    fn check_collapse_valences(
        &self,
        [a, b]: [VertexId; 2],
        [valence_a, valence_b]: [usize; 2],
        c: Option<VertexId>,
        d: Option<VertexId>,
        interior: bool,
    ) -> std::result::Result<(), Refusal> {
        let faces = 1 + interior as usize;
        let merged = (valence_a + valence_b).saturating_sub(2 + faces);
        let merged_min = self.min_valence(a).min(self.min_valence(b));
        if merged < merged_min {
            return Err(Refusal::Valence {
                vertex: a,
                valence: merged,
            });
        }
        for x in [c, d].into_iter().flatten() {
            let after = self.valence(x) - 1;
            if after < self.min_valence(x) {
                return Err(Refusal::Valence {
                    vertex: x,
                    valence: after,
                });
            }
        }
        Ok(())
    }

    /// Collapses the edge of half-edge `h = a→b`: vertex `b` merges into `a`, which moves to
    /// `new_position`; the one or two faces of the edge disappear, and in each of them the edge
    /// from the third vertex to `b` merges into the edge from that vertex to `a`. O(valence).
    ///
    /// Guarantees, when it succeeds: every invariant of the mesh still holds, the Euler
    /// characteristic and the number of boundary loops are unchanged, the ids of all other
    /// elements are unchanged, and the returned [`CollapseRecord`] lists what changed and carries
    /// the [`Undo`] that restores the exact previous state.
    ///
    /// Errors with [`Error::InvalidArgument`] (leaving the mesh untouched) when
    /// [`can_collapse`](Self::can_collapse) refuses or `new_position` is not finite. Panics if
    /// `h` is out of range.
    #[track_caller]
    pub fn collapse_edge(
        &mut self,
        h: HalfedgeId,
        new_position: [f64; 3],
    ) -> Result<CollapseRecord> {
        if let Err(r) = self.can_collapse(h) {
            return Err(Error::InvalidArgument(format!(
                "cannot collapse half-edge {h} ({}→{}): {r}",
                self.origin(h),
                self.target(h)
            )));
        }
        check_finite(new_position, || {
            format!("new position for collapsing half-edge {h}")
        })?;
        Ok(self.apply_collapse(h, new_position))
    }

    pub(super) fn apply_collapse(&mut self, h: HalfedgeId, p: [f64; 3]) -> CollapseRecord {
        let o = h.twin();
        let (a, b) = (self.origin(h), self.origin(o));
        let around_b: Vec<HalfedgeId> = self.outgoing(b).collect();
        let (fl, fr) = (self.face(h), self.face(o));
        let mut removed_faces = Vec::with_capacity(2);
        let mut merged_edges = Vec::with_capacity(2);
        // A live half-edge leaving `a` after the collapse, to restore boundary-first from.
        let mut a_start = HalfedgeId::INVALID;
        let mut ed = Editor::new(self);
        if let Some(f) = fl {
            // Face a→b→c: edge b–c (h1 and its twin t1) goes, h2 = c→a takes t1's place.
            let (h1, h2) = (ed.m.next(h), ed.m.prev(h));
            let (t1, c) = (h1.twin(), ed.m.origin(h2));
            ed.replace_in_loop(t1, h2);
            if ed.m.v_out[c] == t1 {
                ed.set_out(c, h2);
            }
            removed_faces.push(f);
            merged_edges.push([h1.edge(), h2.edge()]);
            a_start = h2.twin();
        }
        if let Some(f) = fr {
            // Face b→a→d: edge d–b (o2 and its twin t2) goes, o1 = a→d takes t2's place.
            let (o1, o2) = (ed.m.next(o), ed.m.prev(o));
            let (t2, d) = (o2.twin(), ed.m.origin(o2));
            ed.replace_in_loop(t2, o1);
            if ed.m.v_out[d] == o2 {
                ed.set_out(d, o1.twin());
            }
            removed_faces.push(f);
            merged_edges.push([o2.edge(), o1.edge()]);
            a_start = o1;
        }
        // A boundary side of the edge: splice it out of its boundary loop.
        for x in [h, o] {
            if !ed.m.halfedges[x].face.is_valid() {
                let (p, n) = (ed.m.prev(x), ed.m.next(x));
                ed.link(p, n);
            }
        }
        for &x in &around_b {
            ed.he_mut(x).origin = a;
        }
        for &f in &removed_faces {
            ed.delete_face(f);
        }
        ed.delete_edge(h.edge());
        for &[gone, _] in &merged_edges {
            ed.delete_edge(gone);
        }
        ed.delete_vertex(b);
        ed.fix_outgoing(a, a_start);
        ed.set_position(a, p);
        let undo = ed.finish();
        let mut removed_edges = vec![h.edge()];
        removed_edges.extend(merged_edges.iter().map(|m| m[0]));
        CollapseRecord {
            kept_vertex: a,
            removed_vertex: b,
            removed_faces,
            removed_edges,
            merged_edges,
            modified_faces: self.vertex_faces(a).collect(),
            undo,
        }
    }

    /// Checks whether [`flip_edge`](Self::flip_edge)`(h)` is allowed. Pure; O(valence).
    ///
    /// Refuses a deleted half-edge, a boundary edge, a flip whose new edge (between the two
    /// vertices opposite the edge) already exists, and a flip that would leave an endpoint with
    /// valence 2 inside the surface (valence 3 before; a boundary endpoint may drop to 2).
    /// Panics if `h` is out of range.
    #[track_caller]
    pub fn can_flip(&self, h: HalfedgeId) -> std::result::Result<(), Refusal> {
        if !self.is_halfedge_live(h) {
            return Err(Refusal::Deleted);
        }
        let o = h.twin();
        let (Some(c), Some(d)) = (self.opposite_vertex(h), self.opposite_vertex(o)) else {
            return Err(Refusal::BoundaryEdge);
        };
        if c == d || self.find_halfedge(c, d).is_some() {
            return Err(Refusal::EdgeExists { a: c, b: d });
        }
        for v in [self.origin(h), self.origin(o)] {
            let after = self.valence(v) - 1;
            if after < self.min_valence(v) {
                return Err(Refusal::Valence {
                    vertex: v,
                    valence: after,
                });
            }
        }
        Ok(())
    }

    /// Flips the interior edge of `h = a→b` with faces `a, b, c` and `b, a, d` into the edge
    /// `c–d`, with faces `c, d, b` (which keeps the id of `h`'s face) and `d, c, a`; afterwards
    /// `h` runs `c→d`. Edge, face and half-edge ids are unchanged. O(1) plus the O(valence)
    /// check.
    ///
    /// Guarantees, when it succeeds: every invariant still holds and the returned [`FlipRecord`]
    /// carries the [`Undo`] that restores the exact previous state. Errors with
    /// [`Error::InvalidArgument`] (leaving the mesh untouched) when [`can_flip`](Self::can_flip)
    /// refuses. Panics if `h` is out of range.
    #[track_caller]
    pub fn flip_edge(&mut self, h: HalfedgeId) -> Result<FlipRecord> {
        if let Err(r) = self.can_flip(h) {
            return Err(Error::InvalidArgument(format!(
                "cannot flip half-edge {h} ({}→{}): {r}",
                self.origin(h),
                self.target(h)
            )));
        }
        Ok(self.apply_flip(h))
    }

    pub(super) fn apply_flip(&mut self, h: HalfedgeId) -> FlipRecord {
        let o = h.twin();
        let (h1, h2) = (self.next(h), self.prev(h)); // b→c, c→a
        let (o1, o2) = (self.next(o), self.prev(o)); // a→d, d→b
        let (a, b) = (self.origin(h), self.origin(o));
        let (c, d) = (self.origin(h2), self.origin(o2));
        let (fl, fr) = (self.halfedges[h].face, self.halfedges[o].face);
        let mut ed = Editor::new(self);
        // Face fl: c→d (h), d→b (o2), b→c (h1). Face fr: d→c (o), c→a (h2), a→d (o1).
        ed.he_mut(h).origin = c;
        ed.he_mut(o).origin = d;
        ed.link(h, o2);
        ed.link(o2, h1);
        ed.link(h1, h);
        ed.link(o, h2);
        ed.link(h2, o1);
        ed.link(o1, o);
        ed.he_mut(o2).face = fl;
        ed.he_mut(h2).face = fr;
        ed.set_face_halfedge(fl, h);
        ed.set_face_halfedge(fr, o);
        if ed.m.v_out[a] == h {
            ed.set_out(a, o1);
        }
        if ed.m.v_out[b] == o {
            ed.set_out(b, h1);
        }
        FlipRecord {
            edge: h.edge(),
            old_vertices: [a, b],
            new_vertices: [c, d],
            faces: [fl, fr],
            undo: ed.finish(),
        }
    }

    /// Reverts the operation that returned `undo`, restoring the exact previous state (every
    /// record, count and position it changed). O(size of the record).
    ///
    /// Errors with [`Error::InvalidArgument`] (changing nothing) when the mesh is not in the
    /// state that operation produced: undo in reverse order of the operations, and not across a
    /// [`garbage_collect`](Self::garbage_collect).
    pub fn undo(&mut self, undo: Undo) -> Result<()> {
        if undo.stamp_after != self.stamp {
            return Err(Error::InvalidArgument(
                "stale undo record: the mesh changed since that operation (undo the most recent operation first)".into(),
            ));
        }
        for s in undo.saved.iter().rev() {
            match *s {
                Saved::HalfEdge(h, x) => self.halfedges[h] = x,
                Saved::Face(f, h) => self.f_he[f] = h,
                Saved::Vertex { id, out, alive } => {
                    self.v_out[id] = out;
                    self.v_alive[id] = alive;
                }
                Saved::Position(v, p) => self.positions[v] = p,
            }
        }
        [self.n_vertices, self.n_edges, self.n_faces] = undo.counts;
        self.stamp = undo.stamp_before;
        Ok(())
    }
}
