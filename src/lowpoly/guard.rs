//! The one guard of every local operation of the mesh-optimization loop (dissertation
//! §4.3.2 "checks", §4.3.3 self-intersection acceleration, §4.5.2 cages).
//!
//! [`Guard`] owns the working [`HalfEdgeMesh`] together with a BVH over its faces. Every
//! collapse (simplification, Alg. 5), vertex move (flow, Alg. 3–4; alignment, Alg. 6; the final
//! input-plane fit, `fit.rs`) and edge flip (the fit's flips) goes through
//! [`Guard::try_collapse`], [`Guard::try_move`] or [`Guard::try_flip`]: the operation is applied, the
//! modified faces `M_e` are checked, and the operation is undone when a check fails. After every
//! accepted operation the mesh therefore still is:
//!
//! 1. **Topologically the same** — manifold, watertight, same genus and component count: the
//!    collapse preconditions of [`HalfEdgeMesh::can_collapse`] (link condition, valence
//!    safeguards) keep the Euler characteristic and the boundary loops; moves don't touch
//!    connectivity.
//! 2. **Free of degenerate faces** — no face of `M_e` has exactly collinear corners (exact
//!    predicate).
//! 3. **Free of self-intersections** — by the decomposition of §4.3.3: with `M_1` the faces that
//!    share a vertex with `M_e` and `M_r` the rest, the mesh stays intersection-free iff `M_e`
//!    does not meet `M_r` and `M_1` is intersection-free (the rest was before). `M_e × M_r`
//!    candidates come from the BVH (Alg. 7) and are decided by the exact triangle–triangle test
//!    with CGAL's rules for faces sharing vertices. Inside `M_1`, pairs of faces that share a
//!    vertex (which no box test can cull) are skipped when the **normal cone** of `M_1` is
//!    narrow (surface-normal test of Volino & Thalmann 1994; see [`CONE_HALF_ANGLE`]) and tested
//!    exactly otherwise; all other pairs of `M_1` are always tested exactly. The normal-cone
//!    path is sufficient only in practice (the contour test is skipped, as in the
//!    dissertation), so the pipeline verifies its output independently and reruns with
//!    [`Guard::set_exact_only`] when that ever finds an intersection.
//! 4. **A cage** (cage mode, §4.5.2) — `M_e` neither touches nor intersects the input (exact
//!    tests against the input's BVH), and no input vertex changes side: the winding number of
//!    the closed mesh changes only through `M_e`, so for input vertices `q` in the box swept by
//!    the operation, `Δw(q) = (Σ_{new M_e} Ω_f(q) − Σ_{old M_e} Ω_f(q)) / 4π` (solid angles) must
//!    round to 0. Together with "no touching", every input point stays strictly inside.
//! 5. **A cage with clearance** (cage mode with a clearance `c > 0`) — the
//!    exact distance between `M_e` and the input (triangle–triangle distances of
//!    `spatial::closest::disjoint_triangle_distance` on the candidates of the input's BVH within
//!    `c` of each face) is at least `c`, or — where the start surface already was closer — at
//!    least the distance of the patch `M_e` replaces: no operation brings a cage face closer to
//!    the input than `c`, and none makes an existing shortfall worse.
//! 6. **Sheets kept apart** (LOD mode with a self-clearance `s > 0`, set by the input-plane fit,
//!    `fit.rs`) — the exact distance (`disjoint_triangle_distance`, as in check 5) between every
//!    face of `M_e` and every LOD face sharing no vertex with it whose normal points more than
//!    90° away from its own (two sides of a sheet) is at least `s`, or at least
//!    what it was for the patch `M_e` replaces: no operation brings two sheets of the surface
//!    that are not neighbours within `s` of each other (a thin sheet's two sides projected onto
//!    one plane, intersection-free only in floating point), and none makes a shortfall worse.

use super::report::GuardCounts;
use crate::geom::{bbox_of, normalized, tri_normal, Vec3};
use crate::mesh::halfedge::{CollapseRecord, FaceData, FaceId, HalfedgeId, VertexId};
use crate::mesh::HalfEdgeMesh;
use crate::spatial::closest::{disjoint_triangle_distance, plane_gap_lower_bound};
use crate::spatial::solid_angle;
use crate::spatial::{self as sp, TriangleBvh};

/// Half-angle of the normal cone of `M_1` below which pairs of faces sharing a vertex are not
/// tested exactly (§4.3.3). Volino & Thalmann's surface-normal test asks for a cone of
/// half-angle below π/2 (all normals in an open half-space) *plus* a contour test; we skip the
/// contour test like the dissertation and compensate with the stricter reading "cone angle
/// below π/2", i.e. half-angle below π/4.
pub const CONE_HALF_ANGLE: f64 = std::f64::consts::FRAC_PI_4;

/// The input mesh `M_i` with the acceleration structures the loop queries.
pub(crate) struct InputModel {
    pub positions: Vec<[f64; 3]>,
    pub tris: Vec<[u32; 3]>,
    /// BVH over `tris` (closest points for flow and distances; cage intersection tests).
    pub bvh: TriangleBvh,
    /// Per triangle: exactly degenerate (collinear corners).
    pub degenerate: Vec<bool>,
    /// BVH over the referenced vertices (as point "triangles" `[v, v, v]`), cage mode only.
    pub points: Option<(Vec<[u32; 3]>, TriangleBvh)>,
    /// Bounding-box diagonal `l`.
    pub diag: f64,
    /// The deformation the simplification must keep vertices for (`LodParams::deformation`;
    /// `super::deform`), when there is one.
    pub deformation: Option<std::sync::Arc<super::deform::DeformationField>>,
}

/// Input faces from which [`InputModel::new_with_stop`] builds its trees on a background thread
/// (below, on the calling thread: no extra thread for the small inputs of most calls).
const HELPER_THREAD_FACES: usize = 1 << 17;

/// How often [`InputModel::new_with_stop`] asks whether to go on while its background thread builds
/// the trees (a cancel must be answered within 0.5 s).
const TREE_POLL: std::time::Duration = std::time::Duration::from_millis(100);

/// The trees of an [`InputModel`]: the face BVH and the optional vertex index.
type InputTrees = (TriangleBvh, Option<(Vec<[u32; 3]>, TriangleBvh)>);

/// The face BVH of `tris` and, with `with_points`, the vertex index of cage mode (the referenced
/// vertices as point "triangles" `[v, v, v]` and their BVH).
fn build_input_trees(positions: &[[f64; 3]], tris: &[[u32; 3]], with_points: bool) -> InputTrees {
    let bvh = TriangleBvh::new(positions, tris);
    let points = with_points.then(|| {
        let mut used = vec![false; positions.len()];
        for t in tris {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let pts: Vec<[u32; 3]> = (0..positions.len() as u32)
            .filter(|&v| used[v as usize])
            .map(|v| [v, v, v])
            .collect();
        let bvh = TriangleBvh::new(positions, &pts);
        (pts, bvh)
    });
    (bvh, points)
}

/// Per triangle: exactly degenerate (collinear corners).
fn degeneracy_flags(positions: &[[f64; 3]], tris: &[[u32; 3]]) -> Vec<bool> {
    tris.iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            sp::is_collinear(a, b, c)
        })
        .collect()
}

/// The trees from the background thread, asking `keep_going()` every [`TREE_POLL`] meanwhile;
/// `None` when it answers `false`.
fn wait_for_trees(
    rx: &std::sync::mpsc::Receiver<InputTrees>,
    keep_going: &mut dyn FnMut() -> bool,
) -> Option<InputTrees> {
    loop {
        match rx.recv_timeout(TREE_POLL) {
            Ok(trees) => return Some(trees),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                if !keep_going() {
                    return None;
                }
            }
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                panic!("the input model's tree builder panicked")
            }
        }
    }
}

/// The buffer behind `a` (a copy if another owner is still alive).
fn unwrap_shared<T: Clone>(a: std::sync::Arc<Vec<T>>) -> Vec<T> {
    std::sync::Arc::try_unwrap(a).unwrap_or_else(|a| (*a).clone())
}

impl InputModel {
    /// Builds the model; `with_points` adds the vertex index needed by cage mode.
    #[cfg(test)]
    pub fn new(mesh: &crate::mesh::TriMesh, with_points: bool) -> InputModel {
        Self::new_with_stop(mesh, with_points, &mut || true).expect("never stopped")
    }

    /// As [`new`](Self::new), with `keep_going()` asked on the calling thread while the trees
    /// are built; `None` as soon as it answers `false` (the face BVH of parry is one
    /// sequential build, 1.4 s at 10⁶ faces on a loaded machine, which has no cancellation point
    /// inside). From [`HELPER_THREAD_FACES`] input faces on, the trees are built on a
    /// background thread while this thread computes the degeneracy flags and then asks
    /// `keep_going` every [`TREE_POLL`]; on a cancel it returns at once and the background
    /// thread finishes its build and drops it (its result has no receiver; nothing is kept).
    /// The trees are the same sequential builds on either thread, so the model does not depend
    /// on the path taken.
    pub fn new_with_stop(
        mesh: &crate::mesh::TriMesh,
        with_points: bool,
        keep_going: &mut dyn FnMut() -> bool,
    ) -> Option<InputModel> {
        Self::build(mesh, with_points, keep_going, HELPER_THREAD_FACES)
    }

    /// [`new_with_stop`](Self::new_with_stop) with the background thread from `helper_from` faces.
    fn build(
        mesh: &crate::mesh::TriMesh,
        with_points: bool,
        keep_going: &mut dyn FnMut() -> bool,
        helper_from: usize,
    ) -> Option<InputModel> {
        let positions = std::sync::Arc::new(mesh.positions().to_vec());
        let tris = std::sync::Arc::new(mesh.triangles().to_vec());
        let (bvh, degenerate, points) = if tris.len() < helper_from {
            let (bvh, points) = build_input_trees(&positions, &tris, with_points);
            (bvh, degeneracy_flags(&positions, &tris), points)
        } else {
            let (tx, rx) = std::sync::mpsc::channel::<InputTrees>();
            let (p, t) = (positions.clone(), tris.clone());
            std::thread::spawn(move || {
                let trees = build_input_trees(&p, &t, with_points);
                drop((p, t)); // before the send: the caller then owns the buffers alone
                let _ = tx.send(trees); // no receiver after a cancel: dropped here
            });
            let degenerate = degeneracy_flags(&positions, &tris);
            let (bvh, points) = wait_for_trees(&rx, keep_going)?;
            (bvh, degenerate, points)
        };
        Some(InputModel {
            diag: mesh.bbox_diagonal(),
            positions: unwrap_shared(positions),
            tris: unwrap_shared(tris),
            bvh,
            degenerate,
            points,
            deformation: None,
        })
    }

    /// Closest input point to `p` and its distance.
    pub fn closest(&self, p: [f64; 3]) -> ([f64; 3], f64) {
        match self
            .bvh
            .closest_point(&self.positions, &self.tris, p, f64::INFINITY)
        {
            Some(c) => (c.point, c.distance),
            None => (p, 0.0),
        }
    }

    /// Distance from `p` to the input.
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        self.closest(p).1
    }

    /// Distance from `p` to the input, given an upper bound `ub` on it (from the triangle
    /// inequality), which lets the BVH prune everything farther.
    pub fn distance_bounded(&self, p: [f64; 3], ub: f64) -> f64 {
        let max = ub * (1.0 + 1e-9) + f64::MIN_POSITIVE;
        match self.bvh.closest_point(&self.positions, &self.tris, p, max) {
            Some(c) => c.distance,
            None => self.distance(p),
        }
    }

    /// Input triangle `t`'s corners.
    pub fn triangle(&self, t: u32) -> [[f64; 3]; 3] {
        self.tris[t as usize].map(|v| self.positions[v as usize])
    }
}

/// Why the guard refused an operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Reject {
    /// The half-edge preconditions refuse the collapse or flip (topology would change).
    /// Collapses outside tests check them before the guard (see `simplify`).
    Topology,
    /// A modified face would be degenerate.
    Degenerate,
    /// The mesh would intersect itself.
    SelfIntersection,
    /// Cage mode: the mesh would touch or intersect the input.
    TouchesInput,
    /// Cage mode: an input vertex would leave the enclosed volume.
    Uncovers,
    /// Cage mode with a clearance: a modified face would come closer to the input than the
    /// clearance (and closer than the faces it replaces).
    Clearance,
    /// LOD mode with a self-clearance: a modified face would come closer than it to an opposed
    /// face sharing no vertex with it (and closer than the faces it replaces).
    SelfClearance,
}

/// The corners of face `f` as raw vertex indices (the BVH's triangle boundary).
fn raw_corners(mesh: &HalfEdgeMesh, f: FaceId) -> [u32; 3] {
    mesh.face_vertices(f).map(VertexId::raw)
}

/// One face of the neighbourhood of an operation as it is *after* the operation: id, vertex
/// ids and corner positions.
#[derive(Debug, Clone, Copy)]
struct NFace {
    id: FaceId,
    v: [VertexId; 3],
    t: [[f64; 3]; 3],
}

/// Reusable buffers of one guard check. Checks of collapses take them explicitly so that
/// several checks can run in parallel on the same (unchanged) mesh, one scratch per thread.
#[derive(Debug, Default)]
pub(crate) struct GuardScratch {
    /// `M_1` after the operation, `M_e` first (its first `n_e` entries).
    m_1: Vec<NFace>,
    n_e: usize,
    /// Sorted ids of `M_1` and of the faces the operation removes: never candidates of `M_r`.
    excluded: Vec<FaceId>,
    /// Vertices of `M_e` (after the operation).
    verts: Vec<VertexId>,
    /// Geometry that `M_e` replaced (cage mode and with a self-clearance only).
    old_patch: Vec<[[f64; 3]; 3]>,
    /// Vertex ids of `old_patch`'s faces (same order).
    old_ids: Vec<[VertexId; 3]>,
    normals: Vec<Vec3>,
    cand: Vec<FaceId>,
}

/// The working mesh plus everything needed to check local operations. See the module docs.
pub(crate) struct Guard<'a> {
    mesh: HalfEdgeMesh,
    /// Triangles by face id (stale for deleted faces), mirrored for the BVH (raw vertex
    /// indices: the BVH's boundary).
    tris: FaceData<[u32; 3]>,
    /// The tree over the live faces' boxes (a compact [`sp::TriTree`]: parry's BVH cost
    /// ≈ 160 B a face plus a rebuild workspace of the same order, the first pass's peak on a
    /// dense offset surface). Its queries give the same face sets.
    bvh: sp::TriTree,
    input: &'a InputModel,
    cage: bool,
    /// Cage mode: the smallest distance to the input a modified face may have (model units;
    /// 0 = only "no contact").
    clearance: f64,
    /// LOD mode: the smallest distance a modified face may have to a face sharing no vertex
    /// with it (check 6; model units; 0 = off).
    self_clearance: f64,
    exact_only: bool,
    cone_cos: f64,
    scratch: GuardScratch,
    /// Leaf updates since the BVH was last built (it is rebuilt when they exceed the face
    /// count: incremental edits degrade the tree).
    edits: usize,
    /// Faces changed by committed collapses whose BVH leaves are not updated yet (see
    /// [`flush_bvh`](Self::flush_bvh)).
    pending: Vec<FaceId>,
    pub stats: GuardCounts,
}

impl<'a> Guard<'a> {
    /// Wraps `mesh` (which must be watertight, manifold and intersection-free — and, in cage
    /// mode, enclose the input without touching it; the pipeline checks this first).
    pub fn new(mesh: HalfEdgeMesh, input: &'a InputModel, cage: bool) -> Guard<'a> {
        let mut tris = FaceData::filled(mesh.face_capacity(), [0u32; 3]);
        let live: Vec<FaceId> = mesh.faces().collect();
        for &f in &live {
            tris[f] = raw_corners(&mesh, f);
        }
        let bvh =
            sp::TriTree::from_subset(mesh.positions(), tris.as_slice(), FaceId::raw_slice(&live));
        Guard {
            mesh,
            tris,
            bvh,
            input,
            cage,
            clearance: 0.0,
            self_clearance: 0.0,
            exact_only: false,
            cone_cos: CONE_HALF_ANGLE.cos(),
            scratch: GuardScratch::default(),
            edits: 0,
            pending: Vec::new(),
            stats: GuardCounts::default(),
        }
    }

    /// Disables the normal-cone fast path: every pair is tested exactly.
    pub fn set_exact_only(&mut self, on: bool) {
        self.exact_only = on;
    }

    /// Sets the clearance `c` (model units, `≥ 0`) kept in cage mode (check 5 of the module
    /// docs); 0, the initial value, only forbids contact.
    pub fn set_clearance(&mut self, c: f64) {
        self.clearance = c;
    }

    /// Sets the self-clearance `s` (model units, `≥ 0`) kept outside cage mode by every
    /// operation checked alone — moves, flips, `try_collapse` (check 6 of the module docs; the
    /// simplification's batched collapses are not re-checked against each other for it, so only
    /// the fit sets it); 0, the initial value, turns it off.
    pub fn set_self_clearance(&mut self, s: f64) {
        self.self_clearance = s;
    }

    /// Whether checks need the geometry an operation replaces (checks 4–6).
    fn keeps_old_patch(&self) -> bool {
        self.cage || self.self_clearance > 0.0
    }

    /// Records the faces `faces` as the patch an operation replaces (when a check needs it).
    fn save_old_patch(&self, faces: impl Iterator<Item = FaceId>, s: &mut GuardScratch) {
        s.old_patch.clear();
        s.old_ids.clear();
        if self.keeps_old_patch() {
            let m = &self.mesh;
            for f in faces {
                s.old_patch.push(m.face_positions(f));
                s.old_ids.push(m.face_vertices(f));
            }
        }
    }

    /// The clearance kept in cage mode (0 outside cage mode or when none was set).
    pub fn clearance(&self) -> f64 {
        if self.cage {
            self.clearance
        } else {
            0.0
        }
    }

    /// The working mesh (read-only: modify it through the guard).
    pub fn mesh(&self) -> &HalfEdgeMesh {
        &self.mesh
    }

    /// The input model.
    pub fn input(&self) -> &'a InputModel {
        self.input
    }

    /// Moves vertex `v` to `p` if the result passes every check; returns whether it did.
    pub fn try_move(&mut self, v: VertexId, p: [f64; 3]) -> Result<(), Reject> {
        self.flush_bvh();
        let old_p = self.mesh.position(v);
        let mut s = std::mem::take(&mut self.scratch);
        self.save_old_patch(self.mesh.vertex_faces(v), &mut s);
        if self.mesh.set_position(v, p).is_err() {
            self.scratch = s;
            return Err(Reject::Degenerate);
        }
        self.fill_move(v, &mut s);
        let mut st = GuardCounts::default();
        let r = self.check(&mut s, &mut st);
        self.stats.add(&st);
        match r {
            Ok(()) => {
                let faces: Vec<FaceId> = s.m_1[..s.n_e].iter().map(|f| f.id).collect();
                self.bvh.update(
                    self.mesh.positions(),
                    self.tris.as_slice(),
                    FaceId::raw_slice(&faces),
                );
            }
            Err(_) => {
                self.mesh
                    .set_position(v, old_p)
                    .expect("restoring a previous finite position");
            }
        }
        self.scratch = s;
        r
    }

    /// Collapses half-edge `h` (its target merges into its origin, which moves to `p`) if the
    /// result passes every check; the mesh is unchanged on `Err`. (The simplification pass
    /// uses [`check_collapse`](Self::check_collapse) and
    /// [`commit_collapse`](Self::commit_collapse), which this composes.)
    #[cfg(test)]
    pub fn try_collapse(&mut self, h: HalfedgeId, p: [f64; 3]) -> Result<CollapseRecord, Reject> {
        if self.mesh.can_collapse(h).is_err() {
            self.stats.checks += 1;
            self.stats.rejected_topology += 1;
            return Err(Reject::Topology);
        }
        let mut s = std::mem::take(&mut self.scratch);
        let mut st = GuardCounts::default();
        let r = self.check_collapse(h, p, &mut s, &mut st);
        self.stats.add(&st);
        self.scratch = s;
        r?;
        let rec = self.commit_collapse(h, p);
        self.flush_bvh();
        Ok(rec)
    }

    /// Checks 2–4 of the module docs for collapsing `h` to `p`, **without changing anything**:
    /// the state after the collapse is read through the unchanged mesh (faces around the
    /// endpoints with the target renamed to the origin, the origin at `p`), so checks of
    /// collapses with disjoint neighbourhoods can run in parallel. `h` must pass
    /// [`HalfEdgeMesh::can_collapse`], and the BVH must be current (no commit since the last
    /// [`flush_bvh`](Self::flush_bvh)). `st` counts the work.
    pub fn check_collapse(
        &self,
        h: HalfedgeId,
        p: [f64; 3],
        s: &mut GuardScratch,
        st: &mut GuardCounts,
    ) -> Result<(), Reject> {
        debug_assert!(self.pending.is_empty(), "check against a stale BVH");
        self.fill_collapse(h, p, s);
        self.check(s, st)
    }

    /// Applies the collapse of `h` to `p`; the BVH follows at the next
    /// [`flush_bvh`](Self::flush_bvh). Only for a collapse that
    /// `check_collapse` accepted on the current mesh — or on a mesh
    /// that differs from it only by operations outside the collapse's `M_1` whose new faces
    /// were then tested against its `M_e` (see [`patches_intersect`]).
    ///
    /// The two removed faces stay in the BVH as dead leaves until its next rebuild (they count
    /// as edits towards it): every query of the tree skips dead faces, and a parry removal
    /// (a tree restructuring on the sequential path of the pass) cost more than the skipped
    /// candidates do.
    pub fn commit_collapse(&mut self, h: HalfedgeId, p: [f64; 3]) -> CollapseRecord {
        let rec = self
            .mesh
            .collapse_edge(h, p)
            .expect("a collapse that passed the guard's checks");
        for &f in &rec.modified_faces {
            self.tris[f] = raw_corners(&self.mesh, f);
        }
        self.pending.extend_from_slice(&rec.modified_faces);
        self.edits += rec.modified_faces.len() + rec.removed_faces.len();
        rec
    }

    /// Brings the BVH up to date with the collapses committed since the last flush (leaf
    /// updates, or a rebuild when the edits exceed the face count). Every check of the guard
    /// needs it; `try_move` and `try_flip` flush first themselves.
    pub fn flush_bvh(&mut self) {
        if !self.pending.is_empty() || self.edits > rebuild_threshold(&self.mesh) {
            flush_bvh_parts(
                &self.mesh,
                &self.tris,
                &mut self.bvh,
                &mut self.pending,
                &mut self.edits,
            );
        }
    }

    /// [`flush_bvh`](Self::flush_bvh) on one thread of the pool while `work` runs on another
    /// with read access to the mesh (the simplification forms its next batch of collapses,
    /// which needs no BVH, meanwhile). Returns `work`'s result.
    pub fn flush_bvh_alongside<R: Send>(
        &mut self,
        work: impl FnOnce(&HalfEdgeMesh) -> R + Send,
    ) -> R {
        if self.pending.is_empty() && self.edits <= rebuild_threshold(&self.mesh) {
            return work(&self.mesh);
        }
        let Guard {
            mesh,
            tris,
            bvh,
            pending,
            edits,
            ..
        } = self;
        let mesh = &*mesh;
        rayon::join(
            || flush_bvh_parts(mesh, tris, bvh, pending, edits),
            || work(mesh),
        )
        .1
    }

    /// Counts leaf edits and rebuilds the BVH when they exceed the live face count.
    fn note_edits(&mut self, n: usize) {
        self.edits += n;
        if self.edits > rebuild_threshold(&self.mesh) {
            rebuild_bvh(&self.mesh, &self.tris, &mut self.bvh, &mut self.edits);
        }
    }

    /// Flips the edge of half-edge `h` (the fit's flips, `fit.rs`) if the result passes every
    /// check; the mesh is unchanged on `Err` (the flip is undone exactly).
    pub fn try_flip(&mut self, h: HalfedgeId) -> Result<(), Reject> {
        self.flush_bvh();
        if self.mesh.can_flip(h).is_err() {
            self.stats.checks += 1;
            self.stats.rejected_topology += 1;
            return Err(Reject::Topology);
        }
        let mut s = std::mem::take(&mut self.scratch);
        let m = &self.mesh;
        self.save_old_patch([m.face(h), m.face(h.twin())].into_iter().flatten(), &mut s);
        let rec = self.mesh.flip_edge(h).expect("a flip that passed can_flip");
        self.fill_patch(rec.faces.into_iter(), &mut s);
        let mut st = GuardCounts::default();
        let r = self.check(&mut s, &mut st);
        self.stats.add(&st);
        match r {
            Ok(()) => {
                for f in rec.faces {
                    self.tris[f] = raw_corners(&self.mesh, f);
                }
                self.bvh.update(
                    self.mesh.positions(),
                    self.tris.as_slice(),
                    FaceId::raw_slice(&rec.faces),
                );
                self.note_edits(2);
            }
            Err(_) => {
                self.mesh
                    .undo(rec.undo)
                    .expect("undoing the flip just made");
            }
        }
        self.scratch = s;
        r
    }

    /// Neighbourhood of a vertex that was just moved (the mesh holds the new position).
    fn fill_move(&self, v: VertexId, s: &mut GuardScratch) {
        self.fill_patch(self.mesh.vertex_faces(v), s);
    }

    /// Neighbourhood of an operation that just changed the faces `changed` (`M_e`; the mesh
    /// holds the new state).
    fn fill_patch(&self, changed: impl Iterator<Item = FaceId>, s: &mut GuardScratch) {
        let m = &self.mesh;
        s.m_1.clear();
        s.verts.clear();
        for f in changed {
            let fv = m.face_vertices(f);
            s.m_1.push(NFace {
                id: f,
                v: fv,
                t: fv.map(|u| m.position(u)),
            });
            s.verts.extend(fv);
        }
        s.n_e = s.m_1.len();
        s.verts.sort_unstable();
        s.verts.dedup();
        s.excluded.clear();
        for &u in &s.verts {
            s.excluded.extend(m.vertex_faces(u));
        }
        s.excluded.sort_unstable();
        s.excluded.dedup();
        for &g in &s.excluded {
            if s.m_1[..s.n_e].iter().any(|f| f.id == g) {
                continue;
            }
            let gv = m.face_vertices(g);
            s.m_1.push(NFace {
                id: g,
                v: gv,
                t: gv.map(|u| m.position(u)),
            });
        }
    }

    /// Neighbourhood after collapsing `h = a→b` to `p`, read from the unchanged mesh: faces
    /// keep their ids, `b` becomes `a`, `a` sits at `p`, the faces of the edge disappear.
    fn fill_collapse(&self, h: HalfedgeId, p: [f64; 3], s: &mut GuardScratch) {
        let m = &self.mesh;
        let (a, b) = (m.origin(h), m.target(h));
        let dying = [m.face(h), m.face(h.twin())];
        let map = |v: VertexId| if v == b { a } else { v };
        let pos = |v: VertexId| if v == a { p } else { m.position(v) };
        s.m_1.clear();
        s.verts.clear();
        s.old_patch.clear();
        s.old_ids.clear();
        s.excluded.clear();
        // M_e: the faces around a and b except the edge's own (the link condition makes those
        // the only faces with both endpoints).
        for f in m.vertex_faces(a).chain(
            m.vertex_faces(b)
                .filter(|&f| !m.face_vertices(f).contains(&a)),
        ) {
            let fv = m.face_vertices(f);
            s.excluded.push(f);
            if self.keeps_old_patch() {
                s.old_patch.push(fv.map(|u| m.position(u)));
                s.old_ids.push(fv);
            }
            if dying.contains(&Some(f)) {
                continue;
            }
            let nv = fv.map(map);
            s.m_1.push(NFace {
                id: f,
                v: nv,
                t: nv.map(pos),
            });
            s.verts.extend(nv);
        }
        s.n_e = s.m_1.len();
        s.verts.sort_unstable();
        s.verts.dedup();
        for &u in &s.verts {
            if u != a {
                s.excluded.extend(m.vertex_faces(u));
            }
        }
        s.excluded.sort_unstable();
        s.excluded.dedup();
        for i in 0..s.excluded.len() {
            let g = s.excluded[i];
            if dying.contains(&Some(g)) || s.m_1[..s.n_e].iter().any(|f| f.id == g) {
                continue;
            }
            let gv = m.face_vertices(g).map(map);
            s.m_1.push(NFace {
                id: g,
                v: gv,
                t: gv.map(pos),
            });
        }
    }

    /// Runs checks 2–4 of the module docs on the neighbourhood in `s`, counting in `st`.
    fn check(&self, s: &mut GuardScratch, st: &mut GuardCounts) -> Result<(), Reject> {
        st.checks += 1;
        let r = self.check_inner(s, st);
        match r {
            Ok(()) => st.accepted += 1,
            Err(Reject::Topology) => st.rejected_topology += 1,
            Err(Reject::Degenerate) => st.rejected_degenerate += 1,
            Err(Reject::SelfIntersection) => st.rejected_intersection += 1,
            Err(Reject::TouchesInput) => st.rejected_touch += 1,
            Err(Reject::Uncovers) => st.rejected_uncover += 1,
            Err(Reject::Clearance) => st.rejected_clearance += 1,
            Err(Reject::SelfClearance) => st.rejected_self_clearance += 1,
        }
        r
    }

    fn check_inner(&self, s: &mut GuardScratch, st: &mut GuardCounts) -> Result<(), Reject> {
        if s.m_1[..s.n_e]
            .iter()
            .any(|f| sp::is_collinear(f.t[0], f.t[1], f.t[2]))
        {
            return Err(Reject::Degenerate);
        }
        let cone_ok = !self.exact_only && self.normal_cone_is_narrow(s);
        if cone_ok {
            st.cone_fast_path += 1;
        }
        check_within_m1(s, cone_ok, st)?;
        self.check_against_rest(s, st)?;
        if !self.cage && self.self_clearance > 0.0 {
            self.check_self_clearance(s, st)?;
        }
        if self.cage {
            if self.clearance > 0.0 {
                self.check_clearance(s, st)?;
            } else {
                self.check_input_untouched(s, st)?;
            }
            self.check_enclosure(s)?;
        }
        Ok(())
    }

    /// Surface-normal test of §4.3.3 on `M_1`: all unit normals within [`CONE_HALF_ANGLE`] of
    /// their mean direction.
    fn normal_cone_is_narrow(&self, s: &mut GuardScratch) -> bool {
        s.normals.clear();
        let mut sum = Vec3::ZERO;
        for f in &s.m_1 {
            let [a, b, c] = f.t.map(Vec3::from);
            let Some(n) = normalized(tri_normal(a, b, c)) else {
                return false;
            };
            sum += n;
            s.normals.push(n);
        }
        let Some(axis) = normalized(sum) else {
            return false;
        };
        s.normals.iter().all(|&n| n.dot(axis) > self.cone_cos)
    }

    /// `M_e` does not meet `M_r` (Alg. 7 with exact tests on all BVH candidates): one BVH
    /// query with the box of `M_e`, then per-face box filtering. Faces outside `M_1` do not
    /// touch the operation's vertices, so their stored geometry is current.
    fn check_against_rest(&self, s: &mut GuardScratch, st: &mut GuardCounts) -> Result<(), Reject> {
        let m_e = &s.m_1[..s.n_e];
        let (lo, hi) = bbox(m_e.iter().flat_map(|f| f.t));
        s.cand.clear();
        let (mesh, excluded, cand) = (&self.mesh, &s.excluded, &mut s.cand);
        self.bvh.for_each_in_box(
            mesh.positions(),
            self.tris.as_slice(),
            lo.to_array(),
            hi.to_array(),
            &mut |t| {
                let g = FaceId::new(t);
                if excluded.binary_search(&g).is_err() && mesh.is_face_live(g) {
                    cand.push(g);
                }
            },
        );
        for &g in &s.cand {
            let gt = self.tris[g].map(|v| self.mesh.position(VertexId::new(v)));
            let gbox = bbox(gt);
            for f in m_e {
                if !boxes_overlap(bbox(f.t), gbox) {
                    continue;
                }
                st.exact_tests += 1;
                if sp::triangles_intersect(&f.t, &gt) {
                    return Err(Reject::SelfIntersection);
                }
            }
        }
        Ok(())
    }

    /// Cage mode: `M_e` does not touch the input.
    fn check_input_untouched(&self, s: &GuardScratch, st: &mut GuardCounts) -> Result<(), Reject> {
        let input = self.input;
        for f in &s.m_1[..s.n_e] {
            for t in input.bvh.query_triangle(&f.t) {
                st.exact_tests += 1;
                if touches_input_triangle(&f.t, &input.triangle(t), input.degenerate[t as usize]) {
                    return Err(Reject::TouchesInput);
                }
            }
        }
        Ok(())
    }

    /// Cage mode with clearance `c`: `M_e` does not touch the input, and its distance to the
    /// input is at least `c` or at least the distance of the patch it replaces — that is, at
    /// least `τ = min(c, old gap)`. `τ` comes first, so that the scan of the new patch stops at
    /// the first input triangle closer than it (most operations that reach this check are
    /// refused here).
    fn check_clearance(&self, s: &GuardScratch, st: &mut GuardCounts) -> Result<(), Reject> {
        let c = self.clearance;
        let tau = patch_gap(self.input, s.old_patch.iter().copied(), c, st);
        let new_patch = s.m_1[..s.n_e].iter().map(|f| f.t);
        patch_keeps_gap(self.input, new_patch, tau, st)
    }

    /// Check 6 (LOD mode with self-clearance `s`): the faces of `M_e` are at least `s` from
    /// every [`opposed`] face sharing no vertex with them — the rest of `M_1` and the faces of `M_r` the
    /// BVH finds within `s` of the old or new patch — or no closer than the patch they replace.
    /// Runs after checks 2–3, so the new patch meets none of those faces.
    fn check_self_clearance(&self, s: &GuardScratch, st: &mut GuardCounts) -> Result<(), Reject> {
        let c = self.self_clearance;
        let new: Vec<LodFace> = s.m_1[..s.n_e]
            .iter()
            .map(|f| (f.v, f.t.map(Vec3::from)))
            .collect();
        let old: Vec<LodFace> = s
            .old_ids
            .iter()
            .zip(&s.old_patch)
            .map(|(&v, t)| (v, t.map(Vec3::from)))
            .collect();
        let (lo, hi) = bbox(
            s.m_1[..s.n_e]
                .iter()
                .flat_map(|f| f.t)
                .chain(s.old_patch.iter().flatten().copied()),
        );
        let pad = Vec3::splat(c);
        let mut others: Vec<LodFace> = s.m_1[s.n_e..]
            .iter()
            .map(|f| (f.v, f.t.map(Vec3::from)))
            .collect();
        self.bvh.for_each_in_box(
            self.mesh.positions(),
            self.tris.as_slice(),
            (lo - pad).to_array(),
            (hi + pad).to_array(),
            &mut |t| {
                let g = FaceId::new(t);
                if s.excluded.binary_search(&g).is_err() && self.mesh.is_face_live(g) {
                    let v = self.tris[g].map(VertexId::new);
                    others.push((v, v.map(|u| Vec3::from(self.mesh.position(u)))));
                }
            },
        );
        let new_gap = self_gap(&new, &others, c, st);
        if new_gap >= c || new_gap >= self_gap(&old, &others, c, st) {
            Ok(())
        } else {
            Err(Reject::SelfClearance)
        }
    }

    /// Cage mode: no input vertex in the swept box changes winding number.
    fn check_enclosure(&self, s: &GuardScratch) -> Result<(), Reject> {
        let Some((pts, pbvh)) = &self.input.points else {
            return Ok(());
        };
        let new_patch = &s.m_1[..s.n_e];
        let old_patch = &s.old_patch;
        let (lo, hi) = bbox(
            new_patch
                .iter()
                .flat_map(|f| f.t)
                .chain(old_patch.iter().flatten().copied()),
        );
        for i in pbvh.query_box(lo.to_array(), hi.to_array()) {
            let q = self.input.positions[pts[i as usize][0] as usize];
            let new_w: f64 = new_patch.iter().map(|f| solid_angle(f.t, q)).sum();
            let old_w: f64 = old_patch.iter().map(|t| solid_angle(*t, q)).sum();
            let dw = (new_w - old_w) / (4.0 * std::f64::consts::PI);
            if dw.abs() > 0.25 {
                return Err(Reject::Uncovers);
            }
        }
        Ok(())
    }
}

/// Leaf edits after which the guard's BVH is rebuilt rather than updated: the live face count
/// (at least 64).
fn rebuild_threshold(mesh: &HalfEdgeMesh) -> usize {
    mesh.face_count().max(64)
}

/// Rebuilds the guard's BVH over the live faces (dropping the dead leaves of removed faces).
/// The old tree is freed first, so the rebuild never holds two trees (to bound the peak memory:
/// on the first pass over a dense offset surface the old tree still has a leaf per offset face).
fn rebuild_bvh(
    mesh: &HalfEdgeMesh,
    tris: &FaceData<[u32; 3]>,
    bvh: &mut sp::TriTree,
    edits: &mut usize,
) {
    let live: Vec<FaceId> = mesh.faces().collect();
    *bvh = sp::TriTree::default();
    *bvh = sp::TriTree::from_subset(mesh.positions(), tris.as_slice(), FaceId::raw_slice(&live));
    *edits = 0;
}

/// The work of [`Guard::flush_bvh`] on the guard's parts: a rebuild when due, else the leaf
/// updates of the pending live faces.
fn flush_bvh_parts(
    mesh: &HalfEdgeMesh,
    tris: &FaceData<[u32; 3]>,
    bvh: &mut sp::TriTree,
    pending: &mut Vec<FaceId>,
    edits: &mut usize,
) {
    if *edits > rebuild_threshold(mesh) {
        rebuild_bvh(mesh, tris, bvh, edits);
    } else {
        pending.sort_unstable();
        pending.dedup();
        pending.retain(|&f| mesh.is_face_live(f));
        bvh.update(
            mesh.positions(),
            tris.as_slice(),
            FaceId::raw_slice(pending),
        );
    }
    pending.clear();
}

/// Plane separations below this fraction of `l` never skip a candidate of the clearance
/// check: there, rounding could hide a contact, which the exact test must decide.
const PLANE_SKIP_MIN: f64 = 1e-9;

/// The distance between the faces `patch` and the input, capped at `cap` (`> 0`): the exact
/// minimum triangle–triangle distance over the input triangles that may come within `cap` of
/// a face ([`crate::spatial::TriangleBvh::query_near_triangle`]), `cap` when there is none. The
/// patch must be known not to touch the input (the patch an operation replaces).
fn patch_gap(
    input: &InputModel,
    patch: impl Iterator<Item = [[f64; 3]; 3]>,
    cap: f64,
    st: &mut GuardCounts,
) -> f64 {
    let mut best = cap;
    for t in patch {
        let (lo, hi) = bbox(t);
        let tv = t.map(Vec3::from);
        for i in input.bvh.query_near_triangle(&t, best) {
            let it = input.triangle(i);
            if box_gap((lo, hi), bbox(it)) >= best {
                continue;
            }
            let itv = it.map(Vec3::from);
            // Far side of the face's plane by at least `best`.
            let plane = plane_gap_lower_bound(&tv, &itv);
            if plane >= best && plane > PLANE_SKIP_MIN * input.diag {
                continue;
            }
            st.exact_tests += 1;
            best = best.min(disjoint_triangle_distance(&tv, &itv, 0.0));
        }
    }
    best
}

/// `Ok` when no face of `patch` touches the input and every one is at least `tau` (`≥ 0`) from
/// it: `Err(TouchesInput)` at the first contact (exact test on every candidate whose box meets
/// the face's), `Err(Clearance)` at the first input triangle closer than `tau`. The decision
/// of [`patch_gap`]`(patch, cap ≥ tau, contact) ≥ tau`, without finishing the minimum.
fn patch_keeps_gap(
    input: &InputModel,
    patch: impl Iterator<Item = [[f64; 3]; 3]>,
    tau: f64,
    st: &mut GuardCounts,
) -> Result<(), Reject> {
    for t in patch {
        let (lo, hi) = bbox(t);
        let tv = t.map(Vec3::from);
        for i in input.bvh.query_near_triangle(&t, tau) {
            let it = input.triangle(i);
            let gap = box_gap((lo, hi), bbox(it));
            if gap >= tau && gap != 0.0 {
                continue;
            }
            let itv = it.map(Vec3::from);
            // Far side of the face's plane by at least `tau` (and clearly apart: no contact).
            let plane = plane_gap_lower_bound(&tv, &itv);
            if plane >= tau && plane > PLANE_SKIP_MIN * input.diag {
                continue;
            }
            st.exact_tests += 1;
            if touches_input_triangle(&t, &it, input.degenerate[i as usize]) {
                return Err(Reject::TouchesInput);
            }
            if tau > 0.0 && disjoint_triangle_distance(&tv, &itv, tau) < tau {
                return Err(Reject::Clearance);
            }
        }
    }
    Ok(())
}

/// Whether two faces' normals point more than 90° apart (`n_a · n_b < 0`): the two sides of a
/// sheet or of a crevice, which check 6 keeps apart; faces across a crease of 90° or more,
/// or on one side of a surface (a flat patch's slivers), are neighbours it leaves alone.
fn opposed(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    tri_normal(a[0], a[1], a[2]).dot(tri_normal(b[0], b[1], b[2])) < 0.0
}

/// A LOD face for check 6: vertex ids and corners.
type LodFace = ([VertexId; 3], [Vec3; 3]);

/// The smallest distance, capped at `cap`, between a face of `patch` and an [`opposed`] face
/// of `others` sharing no vertex with it (exact triangle–triangle distances; the pairs must not
/// intersect, which checks 2–3 established for a new patch and the mesh's validity for an old
/// one).
fn self_gap(patch: &[LodFace], others: &[LodFace], cap: f64, st: &mut GuardCounts) -> f64 {
    let mut best = cap;
    for (pv, pt) in patch {
        let pbox = bbox_of(pt.iter().copied());
        for (ov, ot) in others {
            if pv.iter().any(|v| ov.contains(v)) || !opposed(pt, ot) {
                continue;
            }
            if box_gap(pbox, bbox_of(ot.iter().copied())) >= best {
                continue;
            }
            st.exact_tests += 1;
            best = best.min(disjoint_triangle_distance(pt, ot, 0.0));
        }
    }
    best
}

/// Euclidean distance between two axis-aligned boxes (0 when they overlap): a lower bound of
/// the distance between anything inside them.
pub(crate) fn box_gap(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> f64 {
    let gap = (b.0 - a.1).max(a.0 - b.1).max(Vec3::ZERO);
    gap.length()
}

/// `M_1` is intersection-free given it was before: pairs (f ∈ M_e, g ∈ M_1), each once. Pairs
/// sharing a vertex (which no box test can cull) are skipped when the normal cone is narrow.
fn check_within_m1(s: &GuardScratch, cone_ok: bool, st: &mut GuardCounts) -> Result<(), Reject> {
    for i in 0..s.n_e {
        let f = &s.m_1[i];
        let fbox = bbox(f.t);
        for g in &s.m_1[i + 1..] {
            let shares = g.v.iter().any(|v| f.v.contains(v));
            if shares && cone_ok {
                continue;
            }
            if !boxes_overlap(fbox, bbox(g.t)) {
                continue;
            }
            st.exact_tests += 1;
            if sp::faces_intersect_at(f.v.map(VertexId::raw), &f.t, g.v.map(VertexId::raw), &g.t) {
                return Err(Reject::SelfIntersection);
            }
        }
    }
    Ok(())
}

/// Whether two new patches `M_e` of collapses checked in the same batch meet. The collapses'
/// neighbourhoods `M_1` are disjoint, so the patches share no vertex and plain exact
/// triangle–triangle tests (touching counts) decide; each patch was checked against everything
/// else, so this is the only pair the batch's checks did not see (§4.3.3: `M_e` against the
/// rest, with part of the rest changed by the other collapse).
pub(crate) fn patches_intersect(
    a: &[[[f64; 3]; 3]],
    b: &[[[f64; 3]; 3]],
    st: &mut GuardCounts,
) -> bool {
    let (alo, ahi) = bbox(a.iter().flatten().copied());
    let (blo, bhi) = bbox(b.iter().flatten().copied());
    if !boxes_overlap((alo, ahi), (blo, bhi)) {
        return false;
    }
    a.iter().any(|ta| {
        let abox = bbox(*ta);
        b.iter().any(|tb| {
            if !boxes_overlap(abox, bbox(*tb)) {
                return false;
            }
            st.exact_tests += 1;
            sp::triangles_intersect(ta, tb)
        })
    })
}

/// Axis-aligned box `(min, max)` of stored positions (`geom::bbox_of`).
pub(crate) fn bbox(points: impl IntoIterator<Item = [f64; 3]>) -> (Vec3, Vec3) {
    bbox_of(points.into_iter().map(Vec3::from))
}

/// Closed box overlap test.
pub(crate) fn boxes_overlap(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// Exact: does the closed mesh triangle `tri` meet input triangle `t` (which may be
/// degenerate: then its edges — or its single point — are tested)?
pub(crate) fn touches_input_triangle(
    tri: &[[f64; 3]; 3],
    t: &[[f64; 3]; 3],
    degenerate: bool,
) -> bool {
    if !degenerate {
        return sp::triangles_intersect(tri, t);
    }
    (0..3).any(|i| sp::segment_triangle_intersect([t[i], t[(i + 1) % 3]], tri))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::mesh::TriMesh;

    /// Unit cube `[0,1]³` scaled by `s` and shifted by `o`, outward oriented.
    pub(crate) fn cube(s: f64, o: f64) -> TriMesh {
        let p = (0..8)
            .map(|i: u32| {
                [
                    o + s * (i & 1) as f64,
                    o + s * ((i >> 1) & 1) as f64,
                    o + s * ((i >> 2) & 1) as f64,
                ]
            })
            .collect();
        let f = vec![
            [0, 2, 3],
            [0, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
            [0, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
            [0, 4, 6],
            [0, 6, 2],
            [1, 3, 7],
            [1, 7, 5],
        ];
        TriMesh::new(p, f).unwrap()
    }

    fn guard_for<'a>(m: &TriMesh, input: &'a InputModel, cage: bool) -> Guard<'a> {
        Guard::new(HalfEdgeMesh::from_trimesh(m).unwrap(), input, cage)
    }

    /// Two unit cubes, `[0,1]³` (vertices 0–7) and `[2,3]³` (vertices 8–15).
    fn two_cubes() -> TriMesh {
        let a = cube(1.0, 0.0);
        let b = cube(1.0, 2.0);
        let mut p = a.positions().to_vec();
        p.extend_from_slice(b.positions());
        let mut t = a.triangles().to_vec();
        t.extend(b.triangles().iter().map(|f| f.map(|v| v + 8)));
        TriMesh::new(p, t).unwrap()
    }

    #[test]
    fn the_input_model_is_the_same_when_built_on_the_helper_thread() {
        let m = two_cubes();
        for with_points in [false, true] {
            let here = InputModel::new(&m, with_points);
            let mut polls = 0;
            let there = InputModel::build(
                &m,
                with_points,
                &mut || {
                    polls += 1;
                    true
                },
                0,
            )
            .expect("not cancelled");
            assert_eq!(
                (&here.positions, &here.tris),
                (&there.positions, &there.tris)
            );
            assert_eq!(here.degenerate, there.degenerate);
            assert_eq!(here.diag.to_bits(), there.diag.to_bits());
            assert_eq!(here.bvh.leaf_ids(), there.bvh.leaf_ids());
            for t in 0..m.triangle_count() as u32 {
                assert_eq!(here.bvh.triangle_box(t), there.bvh.triangle_box(t));
            }
            for p in [[0.5, 0.5, 1.5], [1.5, 2.5, 0.2], [-1.0, 4.0, 2.0]] {
                assert_eq!(here.closest(p), there.closest(p));
            }
            let pts = |x: &InputModel| x.points.as_ref().map(|(p, b)| (p.clone(), b.leaf_ids()));
            assert_eq!(pts(&here), pts(&there));
        }
    }

    #[test]
    fn moves_that_intersect_are_refused_and_undone() {
        let m = two_cubes();
        let input = InputModel::new(&m, false);
        let mut g = guard_for(&m, &input, false);
        // Vertex 7 = (1,1,1) pushed below the bottom face: its faces cross it (inside M_1).
        assert_eq!(
            g.try_move(VertexId::new(7), [0.5, 0.5, -0.5]),
            Err(Reject::SelfIntersection)
        );
        assert_eq!(g.mesh().position(VertexId::new(7)), [1., 1., 1.]);
        // Into the other cube: found through the BVH (M_r).
        assert_eq!(
            g.try_move(VertexId::new(7), [2.5, 2.5, 2.5]),
            Err(Reject::SelfIntersection)
        );
        assert!(g.try_move(VertexId::new(7), [1.2, 1.2, 1.2]).is_ok());
        assert_eq!(g.mesh().position(VertexId::new(7)), [1.2, 1.2, 1.2]);
        // The other cube's corner (2,2,2) comes closer; the BVH follows the move, so a later
        // check near its new position sees it.
        assert!(g.try_move(VertexId::new(8), [1.5, 1.5, 1.5]).is_ok());
        assert_eq!(
            g.try_move(VertexId::new(7), [1.6, 1.6, 1.6]),
            Err(Reject::SelfIntersection)
        );
        // Onto another vertex: degenerate faces.
        assert_eq!(
            g.try_move(VertexId::new(7), [1.0, 1.0, 0.0]),
            Err(Reject::Degenerate)
        );
        g.mesh().check_invariants().unwrap();
        assert_eq!(
            crate::verify::MeshReport::compute(&g.mesh().to_trimesh()).self_intersection_free,
            Some(true)
        );
    }

    #[test]
    fn exact_only_mode_agrees() {
        let m = cube(1.0, 0.0);
        let input = InputModel::new(&m, false);
        let mut g = guard_for(&m, &input, false);
        g.set_exact_only(true);
        assert_eq!(
            g.try_move(VertexId::new(7), [0.5, 0.5, -0.5]),
            Err(Reject::SelfIntersection)
        );
        assert!(g.try_move(VertexId::new(7), [1.2, 1.2, 1.2]).is_ok());
        assert_eq!(g.stats.cone_fast_path, 0);
    }

    #[test]
    fn collapses_are_checked_and_undone() {
        let m = cube(1.0, 0.0);
        let input = InputModel::new(&m, false);
        let mut g = guard_for(&m, &input, false);
        let h = g
            .mesh()
            .find_halfedge(VertexId::new(0), VertexId::new(3))
            .unwrap();
        // Collapsing the bottom diagonal to a point far above the cube folds it through.
        assert!(g.try_collapse(h, [0.5, 0.5, 5.0]).is_err());
        assert_eq!(g.mesh().face_count(), 12);
        g.mesh().check_invariants().unwrap();
        let rec = g.try_collapse(h, [0.5, 0.5, -0.1]).unwrap();
        assert_eq!(rec.removed_faces.len(), 2);
        assert_eq!(g.mesh().face_count(), 10);
        let out = g.mesh().to_trimesh();
        assert_eq!(
            crate::verify::MeshReport::compute(&out).self_intersection_free,
            Some(true)
        );
    }

    #[test]
    fn cage_refuses_touching_and_uncovering() {
        let big = cube(1.0, 0.0);
        // A tiny triangle soup near the (1,1,1) corner, inside the cage.
        let soup = TriMesh::new(
            vec![[0.9, 0.9, 0.85], [0.85, 0.9, 0.9], [0.9, 0.85, 0.9]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let input = InputModel::new(&soup, true);
        let mut g = guard_for(&big, &input, true);
        // Cutting the corner off beyond the triangle: no contact, but the soup ends outside.
        assert_eq!(
            g.try_move(VertexId::new(7), [0.5, 0.5, 0.5]),
            Err(Reject::Uncovers)
        );
        // Moving the corner onto an input vertex.
        assert_eq!(
            g.try_move(VertexId::new(7), [0.9, 0.9, 0.85]),
            Err(Reject::TouchesInput)
        );
        // Moving outward is fine.
        assert!(g.try_move(VertexId::new(7), [1.1, 1.1, 1.1]).is_ok());
        assert_eq!(g.stats.rejected_uncover, 1);
        assert_eq!(g.stats.rejected_touch, 1);
    }

    /// The guard's clearance decision agrees with the independent exact measurement
    /// (`verify::min_distance`) on the result: a move of the outer cube's corner along the
    /// diagonal is accepted iff the moved cage keeps the clearance.
    #[test]
    fn clearance_matches_the_independent_measurement() {
        let inner = cube(1.0, 0.0);
        let outer = cube(3.0, -1.0);
        let input = InputModel::new(&inner, true);
        let c = 0.5;
        for t in [2.5, 2.0, 1.8, 1.6, 1.4, 1.2, 1.1] {
            let mut g = guard_for(&outer, &input, true);
            g.set_clearance(c);
            let r = g.try_move(VertexId::new(7), [t, t, t]);
            let mut moved = outer.positions().to_vec();
            moved[7] = [t, t, t];
            let m = TriMesh::new(moved, outer.triangles().to_vec()).unwrap();
            let gap = crate::verify::min_distance(&m, &inner);
            assert_eq!(r.is_ok(), gap >= c, "t = {t}: guard {r:?}, exact gap {gap}");
        }
    }

    /// Where the start is already closer than the clearance, moves that do not lower the
    /// patch's distance are accepted and moves that lower it are refused.
    #[test]
    fn clearance_shortfall_is_never_made_worse() {
        let inner = cube(1.0, 0.0);
        let outer = cube(3.0, -1.0);
        let input = InputModel::new(&inner, true);
        let mut g = guard_for(&outer, &input, true);
        g.set_clearance(2.0);
        assert!(g.try_move(VertexId::new(7), [2.5, 2.5, 2.5]).is_ok());
        assert_eq!(
            g.try_move(VertexId::new(7), [1.5, 1.5, 1.5]),
            Err(Reject::Clearance)
        );
        assert_eq!(g.stats.rejected_clearance, 1);
    }

    /// Check 6: moving the unit cube's corner `(1, 1, 1)` down to `z = 0.2` brings face
    /// `[4, 5, 7]` within 0.2 of bottom face `[0, 2, 3]` (at corner 3, below the moved
    /// vertex), which shares no vertex with it: refused with a self-clearance of 0.3,
    /// accepted with 0.1 or without one; from there, with 0.3, a move that shrinks the shortfall
    /// (up to 0.25) is accepted and one that deepens it (down to 0.1) refused.
    #[test]
    fn self_clearance_keeps_sheets_apart() {
        let m = cube(1.0, 0.0);
        let input = InputModel::new(&m, false);
        let low = [1.0, 1.0, 0.2];
        for (c, ok) in [(0.0, true), (0.1, true), (0.3, false)] {
            let mut g = guard_for(&m, &input, false);
            g.set_self_clearance(c);
            let r = g.try_move(VertexId::new(7), low);
            assert_eq!(r.is_ok(), ok, "self-clearance {c}: {r:?}");
            assert_eq!(g.stats.rejected_self_clearance, u64::from(!ok));
        }
        let mut g = guard_for(&m, &input, false);
        assert!(g.try_move(VertexId::new(7), low).is_ok());
        g.set_self_clearance(0.3);
        assert!(g.try_move(VertexId::new(7), [1.0, 1.0, 0.25]).is_ok());
        assert_eq!(
            g.try_move(VertexId::new(7), [1.0, 1.0, 0.1]),
            Err(Reject::SelfClearance)
        );
    }
}
