//! [`HalfEdgeMesh::check_invariants`]: a full O(mesh) consistency check.

use super::{FaceData, HalfEdge, HalfEdgeMesh, VertexData, VertexId};
use crate::{Error, Result};

fn bug(msg: String) -> Error {
    Error::Internal(format!("half-edge invariant violated: {msg}"))
}

macro_rules! ensure {
    ($cond:expr, $($t:tt)*) => {
        if !$cond {
            return Err(bug(format!($($t)*)));
        }
    };
}

impl HalfEdgeMesh {
    /// Verifies every invariant listed in the [module documentation](super): pointer
    /// consistency (twin of twin, `prev`/`next` inverse, `next³ = id` in faces, origins matching
    /// along loops), vertex outgoing half-edges valid and boundary first, each vertex's faces a
    /// single fan, no duplicate edges or faces, faces with three distinct corners, finite
    /// positions, and the live counts. O(n); meant for tests and debugging.
    ///
    /// Errors with [`Error::Internal`] describing the first violation found (which would be a bug
    /// in pleat: no public operation can produce one).
    pub fn check_invariants(&self) -> Result<()> {
        self.check_storage()?;
        self.check_halfedge_links()?;
        self.check_faces()?;
        self.check_vertices()?;
        self.check_no_duplicate_edges()?;
        self.check_counts()
    }

    fn check_storage(&self) -> Result<()> {
        let nv = self.v_out.len();
        ensure!(
            self.positions.len() == nv && self.v_alive.len() == nv,
            "vertex arrays have different lengths"
        );
        ensure!(
            self.halfedges.len() % 2 == 0,
            "odd number of half-edge slots"
        );
        ensure!(
            self.halfedges.len() < u32::MAX as usize && self.f_he.len() < u32::MAX as usize,
            "id range exceeded"
        );
        Ok(())
    }

    fn check_halfedge_links(&self) -> Result<()> {
        let (nh, nv, nf) = (self.halfedges.len(), self.v_out.len(), self.f_he.len());
        for h in self.halfedges.ids() {
            let x = self.halfedges[h];
            let t = self.halfedges[h.twin()];
            if !x.origin.is_valid() {
                ensure!(x == HalfEdge::DELETED, "deleted half-edge {h} has links");
                ensure!(
                    !t.origin.is_valid(),
                    "half-edge {h} is deleted but its twin is not"
                );
                continue;
            }
            ensure!(
                t.origin.is_valid(),
                "half-edge {h} is live but its twin is deleted"
            );
            ensure!(
                x.origin.index() < nv && self.v_alive[x.origin],
                "half-edge {h} leaves dead or out-of-range vertex {}",
                x.origin
            );
            ensure!(
                x.origin != t.origin,
                "half-edge {h} is a loop at vertex {}",
                x.origin
            );
            ensure!(
                x.next.index() < nh && x.prev.index() < nh,
                "half-edge {h} has next/prev out of range"
            );
            let (n, p) = (self.halfedges[x.next], self.halfedges[x.prev]);
            ensure!(n.prev == h, "prev(next({h})) != {h}");
            ensure!(p.next == h, "next(prev({h})) != {h}");
            ensure!(
                n.origin == t.origin,
                "origin(next({h})) = {} but target({h}) = {}",
                n.origin,
                t.origin
            );
            ensure!(n.face == x.face, "next({h}) lies in another face");
            if !x.face.is_valid() {
                ensure!(t.face.is_valid(), "edge {} has no face", h.edge());
            } else {
                ensure!(
                    x.face.index() < nf && self.f_he[x.face].is_valid(),
                    "half-edge {h} lies in dead or out-of-range face {}",
                    x.face
                );
                ensure!(
                    self.halfedges[n.next].next == h,
                    "face {} of half-edge {h} is not a triangle",
                    x.face
                );
            }
        }
        Ok(())
    }

    fn check_faces(&self) -> Result<()> {
        let mut per_face = FaceData::filled(self.f_he.len(), 0u8);
        for x in self.halfedges.as_slice() {
            if x.origin.is_valid() && x.face.is_valid() {
                per_face[x.face] = per_face[x.face].saturating_add(1);
            }
        }
        for f in self.f_he.ids() {
            let h = self.f_he[f];
            if !h.is_valid() {
                ensure!(per_face[f] == 0, "deleted face {f} still has half-edges");
                continue;
            }
            ensure!(
                h.index() < self.halfedges.len() && self.halfedges[h].face == f,
                "face {f}'s half-edge {h} is not in it"
            );
            ensure!(per_face[f] == 3, "face {f} has {} half-edges", per_face[f]);
            let [a, b, c] = self.face_vertices(f);
            ensure!(
                a != b && b != c && a != c,
                "face {f} ({a}, {b}, {c}) repeats a vertex"
            );
        }
        for e in self.edges() {
            let h = e.halfedge();
            if let (Some(c), Some(d)) = (self.opposite_vertex(h), self.opposite_vertex(h.twin())) {
                ensure!(
                    c != d,
                    "the two faces of edge {e} have the same three vertices"
                );
            }
        }
        Ok(())
    }

    fn check_vertices(&self) -> Result<()> {
        let mut out_count = VertexData::filled(self.v_out.len(), 0u32);
        let mut boundary_out = VertexData::filled(self.v_out.len(), 0u32);
        for x in self.halfedges.as_slice() {
            if x.origin.is_valid() {
                out_count[x.origin] += 1;
                boundary_out[x.origin] += (!x.face.is_valid()) as u32;
            }
        }
        for v in self.v_out.ids() {
            let (out, i) = (self.v_out[v], v);
            ensure!(
                self.positions[i].iter().all(|c| c.is_finite()),
                "vertex {v} has a non-finite position"
            );
            if !out.is_valid() {
                ensure!(
                    out_count[i] == 0,
                    "vertex {v} has edges but no outgoing half-edge"
                );
                continue;
            }
            ensure!(
                self.v_alive[i],
                "deleted vertex {v} has an outgoing half-edge"
            );
            ensure!(
                out.index() < self.halfedges.len() && self.halfedges[out].origin == v,
                "outgoing half-edge {out} of vertex {v} does not leave it"
            );
            ensure!(
                boundary_out[i] <= 1,
                "vertex {v} has {} boundary half-edges leaving it",
                boundary_out[i]
            );
            ensure!(
                boundary_out[i] == 0 || !self.halfedges[out].face.is_valid(),
                "boundary vertex {v}'s outgoing half-edge {out} is not its boundary half-edge"
            );
            let fan = self.rotate(out).take(out_count[i] as usize + 1).count();
            ensure!(
                fan == out_count[i] as usize,
                "vertex {v}'s faces form more than one fan ({fan} of {} half-edges in the first)",
                out_count[i]
            );
        }
        Ok(())
    }

    /// Two edges joining the same vertices would give some vertex two half-edges to the same
    /// neighbour. Needs single fans (checked before), so rotation visits every half-edge. O(n).
    fn check_no_duplicate_edges(&self) -> Result<()> {
        let mut seen_from = VertexData::filled(self.v_out.len(), VertexId::INVALID);
        for v in self.vertices() {
            for h in self.outgoing(v) {
                let t = self.target(h);
                ensure!(
                    seen_from[t] != v,
                    "two edges join vertices {v} and {t} (one of them is edge {})",
                    h.edge()
                );
                seen_from[t] = v;
            }
        }
        Ok(())
    }

    fn check_counts(&self) -> Result<()> {
        let nv = self.v_alive.as_slice().iter().filter(|&&a| a).count();
        let nf = self.f_he.as_slice().iter().filter(|h| h.is_valid()).count();
        let ne = self.edges().count();
        ensure!(
            (nv, ne, nf) == (self.n_vertices, self.n_edges, self.n_faces),
            "live counts (V, E, F) = ({nv}, {ne}, {nf}) but recorded ({}, {}, {})",
            self.n_vertices,
            self.n_edges,
            self.n_faces
        );
        Ok(())
    }
}
