//! [`HalfEdgeMesh::check_invariants`]: a full O(mesh) consistency check.

use super::{edge_of, halfedge_of, twin, HalfEdge, HalfEdgeMesh, INVALID};
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
            self.halfedges.len() < INVALID as usize && self.f_he.len() < INVALID as usize,
            "id range exceeded"
        );
        Ok(())
    }

    fn check_halfedge_links(&self) -> Result<()> {
        let (nh, nv, nf) = (self.halfedges.len(), self.v_out.len(), self.f_he.len());
        for h in 0..nh as u32 {
            let x = self.halfedges[h as usize];
            let t = self.halfedges[twin(h) as usize];
            if x.origin == INVALID {
                ensure!(x == HalfEdge::DELETED, "deleted half-edge {h} has links");
                ensure!(
                    t.origin == INVALID,
                    "half-edge {h} is deleted but its twin is not"
                );
                continue;
            }
            ensure!(
                t.origin != INVALID,
                "half-edge {h} is live but its twin is deleted"
            );
            ensure!(
                (x.origin as usize) < nv && self.v_alive[x.origin as usize],
                "half-edge {h} leaves dead or out-of-range vertex {}",
                x.origin
            );
            ensure!(
                x.origin != t.origin,
                "half-edge {h} is a loop at vertex {}",
                x.origin
            );
            ensure!(
                (x.next as usize) < nh && (x.prev as usize) < nh,
                "half-edge {h} has next/prev out of range"
            );
            let (n, p) = (
                self.halfedges[x.next as usize],
                self.halfedges[x.prev as usize],
            );
            ensure!(n.prev == h, "prev(next({h})) != {h}");
            ensure!(p.next == h, "next(prev({h})) != {h}");
            ensure!(
                n.origin == t.origin,
                "origin(next({h})) = {} but target({h}) = {}",
                n.origin,
                t.origin
            );
            ensure!(n.face == x.face, "next({h}) lies in another face");
            if x.face == INVALID {
                ensure!(t.face != INVALID, "edge {} has no face", edge_of(h));
            } else {
                ensure!(
                    (x.face as usize) < nf && self.f_he[x.face as usize] != INVALID,
                    "half-edge {h} lies in dead or out-of-range face {}",
                    x.face
                );
                ensure!(
                    self.halfedges[n.next as usize].next == h,
                    "face {} of half-edge {h} is not a triangle",
                    x.face
                );
            }
        }
        Ok(())
    }

    fn check_faces(&self) -> Result<()> {
        let mut per_face = vec![0u8; self.f_he.len()];
        for x in &self.halfedges {
            if x.origin != INVALID && x.face != INVALID {
                per_face[x.face as usize] = per_face[x.face as usize].saturating_add(1);
            }
        }
        for f in 0..self.f_he.len() as u32 {
            let h = self.f_he[f as usize];
            if h == INVALID {
                ensure!(
                    per_face[f as usize] == 0,
                    "deleted face {f} still has half-edges"
                );
                continue;
            }
            ensure!(
                (h as usize) < self.halfedges.len() && self.halfedges[h as usize].face == f,
                "face {f}'s half-edge {h} is not in it"
            );
            ensure!(
                per_face[f as usize] == 3,
                "face {f} has {} half-edges",
                per_face[f as usize]
            );
            let [a, b, c] = self.face_vertices(f);
            ensure!(
                a != b && b != c && a != c,
                "face {f} ({a}, {b}, {c}) repeats a vertex"
            );
        }
        for e in self.edges() {
            let h = halfedge_of(e);
            if let (Some(c), Some(d)) = (self.opposite_vertex(h), self.opposite_vertex(twin(h))) {
                ensure!(
                    c != d,
                    "the two faces of edge {e} have the same three vertices"
                );
            }
        }
        Ok(())
    }

    fn check_vertices(&self) -> Result<()> {
        let mut out_count = vec![0u32; self.v_out.len()];
        let mut boundary_out = vec![0u32; self.v_out.len()];
        for x in &self.halfedges {
            if x.origin != INVALID {
                out_count[x.origin as usize] += 1;
                boundary_out[x.origin as usize] += (x.face == INVALID) as u32;
            }
        }
        for v in 0..self.v_out.len() as u32 {
            let (out, i) = (self.v_out[v as usize], v as usize);
            ensure!(
                self.positions[i].iter().all(|c| c.is_finite()),
                "vertex {v} has a non-finite position"
            );
            if out == INVALID {
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
                (out as usize) < self.halfedges.len() && self.halfedges[out as usize].origin == v,
                "outgoing half-edge {out} of vertex {v} does not leave it"
            );
            ensure!(
                boundary_out[i] <= 1,
                "vertex {v} has {} boundary half-edges leaving it",
                boundary_out[i]
            );
            ensure!(
                boundary_out[i] == 0 || self.halfedges[out as usize].face == INVALID,
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
        let mut seen_from = vec![INVALID; self.v_out.len()];
        for v in self.vertices() {
            for h in self.outgoing(v) {
                let t = self.target(h) as usize;
                ensure!(
                    seen_from[t] != v,
                    "two edges join vertices {v} and {t} (one of them is edge {})",
                    edge_of(h)
                );
                seen_from[t] = v;
            }
        }
        Ok(())
    }

    fn check_counts(&self) -> Result<()> {
        let nv = self.v_alive.iter().filter(|&&a| a).count();
        let nf = self.f_he.iter().filter(|&&h| h != INVALID).count();
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
