//! One pass of guarded quadric edge collapses — dissertation Alg. 5 (§4.3.2 "Mesh
//! Simplification").
//!
//! Vertex quadrics are Garland & Heckbert's (1997) area-weighted face-plane quadrics plus one
//! *virtual plane* per edge: the plane through the edge perpendicular to its faces (normal
//! `n̄ × ê`, `n̄` the mean of the two face normals), weighted by [`VIRTUAL_PLANE_WEIGHT`]`·|e|²`.
//! In flat regions the face planes alone give a rank-1 quadric whose minimiser is a whole
//! plane; the virtual planes make it full rank and keep the optimum near the collapsed edge.
//!
//! Edges are popped by increasing cost. A collapse is **skipped** (Alg. 5 lines 9–22) when
//! - the half-edge preconditions refuse it (topology), or a new face's normal turns by more
//!   than 90° (a fold-over, cheap to detect before the exact tests);
//! - it would move the surface by more than `d`: the two-sided Hausdorff distance between the
//!   patch before (`M_e`, the faces around both endpoints) and after (`M'_e`) exceeds `d`
//!   (line 20; sampled as in Metro, see [`sample_resolution`]);
//! - it increases the one-sided distance from the local patch to the input (line 17):
//!   `D(M'_e) > max(D(M_e), slack)`, where `D` is the area-weighted mean over the patch of the
//!   sampled point-to-input distances (`slack` is 0 for Alg. 5 as written and `d` when a chain
//!   level starts from a finer result). The text does not say which one-sided distance; the
//!   maximum does not work: on an offset surface every vertex sits at distance `≈ d`, and the
//!   quadric optimum of a convex patch lies just outside it, so every convex collapse would
//!   "increase" the maximum by a rounding-level amount and nothing would ever simplify. The
//!   mean rejects what the check is for — collapses that push the surface away from the input
//!   (concave regions) — and accepts chords that bring it closer;
//! - the [`Guard`] refuses it (self-intersections; cage mode: touching or uncovering the input).
//!
//! Candidate positions are tried in order — the quadric optimum, the edge midpoint, the two
//! endpoints — and the first that passes every check is used: on convex parts of an offset
//! surface the quadric optimum lies slightly *outside* (farther from the input) while the
//! midpoint lies on the chord, closer to it. A guard refusal ends the list (moving along the
//! edge rarely cures a self-intersection, and retrying would double the cost of those
//! refusals), unless the pass is asked to retry (`SimplifyOptions::retry_guard`): the rounds
//! of a cage with a clearance after its first pass, where a refusal is mostly the clearance
//! or contact, which depend on where along the edge the vertex lands (see
//! `pipeline::retries_guard_refusals`).
//!
//! The pass stops when the queue is empty or the face count reaches the target `n_F`.
//!
//! On large meshes (the dense offset surface of the first pass) candidates are evaluated in
//! parallel, in batches of collapses with disjoint neighbourhoods taken in queue order and
//! applied in that order (see `Pass::run`); the batches never depend on the thread count, so
//! neither does the output. Alg. 5 is sequential; the batches reorder it only where collapses
//! are independent of each other, except that a collapse's re-queued neighbours wait for the
//! rest of its batch.

use rayon::prelude::*;

use super::deform::{label_at, DeformationField, Label, LabelInput, Lever};
use super::guard::{bbox, boxes_overlap, patches_intersect, Guard, GuardScratch, InputModel};
use super::report::{GuardCounts, SimplifyCounts};
use crate::geom::{normalized, tri_normal, Vec3};
use crate::mesh::halfedge::{EdgeData, EdgeId, FaceData, FaceId, HalfedgeId, VertexData, VertexId};
use crate::mesh::HalfEdgeMesh;
use crate::spatial::closest::{for_each_sample, point_triangle_distance, sample_resolution};
use crate::{Error, Result};

/// Weight of an edge's virtual plane relative to `|e|²` (face planes weigh their area).
pub const VIRTUAL_PLANE_WEIGHT: f64 = 0.01;

/// Largest sampling grid per triangle edge in the local Hausdorff check.
const MAX_SAMPLE_RES: usize = 4;

/// Drift cap, in units of `d`: a collapse may not leave a new face with a sample farther
/// than `DRIFT_CAP·d` from the input unless the old patch already had one that far (then the
/// farthest sample may not grow). See the module docs: the per-collapse checks are relative
/// to the current patch, so without an absolute bound many collapses in a row can walk a
/// concave patch away from the input, `d` at a time.
pub const DRIFT_CAP: f64 = 2.0;

/// Options of one simplification pass.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SimplifyOptions {
    /// Largest allowed local two-sided Hausdorff change per collapse (`d = l / n_p`).
    pub d: f64,
    /// Stop when the face count is at most this.
    pub target_faces: Option<usize>,
    /// One-sided distance allowance (0 = Alg. 5 exactly).
    pub slack: f64,
    /// Sample spacing of the distance checks.
    pub spacing: f64,
    /// Try the next candidate position after a guard refusal too (module docs; a cage with a
    /// clearance after its first pass).
    pub retry_guard: bool,
}

/// A symmetric quadric `Q(x) = xᵀAx + 2bᵀx + c`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Quadric {
    /// Upper triangle of `A`: `a00 a01 a02 a11 a12 a22`.
    a: [f64; 6],
    b: Vec3,
    c: f64,
}

impl Quadric {
    /// `w · (n · (x − p))²` for a unit normal `n`.
    pub fn plane(n: Vec3, p: Vec3, w: f64) -> Quadric {
        let d = -n.dot(p);
        Quadric {
            a: [
                w * n[0] * n[0],
                w * n[0] * n[1],
                w * n[0] * n[2],
                w * n[1] * n[1],
                w * n[1] * n[2],
                w * n[2] * n[2],
            ],
            b: n * (w * d),
            c: w * d * d,
        }
    }

    /// Sum of two quadrics.
    pub fn add(&self, o: &Quadric) -> Quadric {
        let mut a = self.a;
        for (x, y) in a.iter_mut().zip(o.a) {
            *x += y;
        }
        Quadric {
            a,
            b: self.b + o.b,
            c: self.c + o.c,
        }
    }

    /// `Q(x)`.
    pub fn eval(&self, x: Vec3) -> f64 {
        let [a00, a01, a02, a11, a12, a22] = self.a;
        let ax = Vec3::new(
            a00 * x[0] + a01 * x[1] + a02 * x[2],
            a01 * x[0] + a11 * x[1] + a12 * x[2],
            a02 * x[0] + a12 * x[1] + a22 * x[2],
        );
        x.dot(ax) + 2.0 * self.b.dot(x) + self.c
    }

    /// The minimiser `−A⁻¹b`, or `None` when `A` is (nearly) singular.
    pub fn minimize(&self) -> Option<Vec3> {
        let [a00, a01, a02, a11, a12, a22] = self.a;
        let c00 = a11 * a22 - a12 * a12;
        let c01 = a02 * a12 - a01 * a22;
        let c02 = a01 * a12 - a02 * a11;
        let det = a00 * c00 + a01 * c01 + a02 * c02;
        let tr = (a00 + a11 + a22) / 3.0;
        if det.is_nan() || det.abs() <= 1e-12 * tr * tr * tr {
            return None;
        }
        let c11 = a00 * a22 - a02 * a02;
        let c12 = a01 * a02 - a00 * a12;
        let c22 = a00 * a11 - a01 * a01;
        let b = self.b;
        let x = Vec3::new(
            -(c00 * b[0] + c01 * b[1] + c02 * b[2]) / det,
            -(c01 * b[0] + c11 * b[1] + c12 * b[2]) / det,
            -(c02 * b[0] + c12 * b[1] + c22 * b[2]) / det,
        );
        x.is_finite().then_some(x)
    }
}

/// Vertex quadrics of the current mesh (indexed by vertex id): face planes weighted by area
/// plus the virtual edge planes.
fn vertex_quadrics(g: &Guard<'_>) -> VertexData<Quadric> {
    let m = g.mesh();
    let mut q = VertexData::filled(m.vertex_capacity(), Quadric::default());
    for f in m.faces() {
        let t = m.face_positions(f).map(Vec3::from);
        let nv = tri_normal(t[0], t[1], t[2]);
        let Some(n) = normalized(nv) else { continue };
        let fq = Quadric::plane(n, t[0], 0.5 * nv.length());
        for v in m.face_vertices(f) {
            q[v] = q[v].add(&fq);
        }
    }
    for e in m.edges() {
        let h = m.edge_halfedge(e);
        let (a, b) = (m.origin(h), m.target(h));
        let (pa, pb) = (Vec3::from(m.position(a)), Vec3::from(m.position(b)));
        let nsum = [m.face(h), m.face(m.twin(h))]
            .into_iter()
            .flatten()
            .fold(Vec3::ZERO, |s, f| s + m.face_normal(f));
        let Some(pn) = normalized(nsum.cross(pb - pa)) else {
            continue;
        };
        let l2 = (pb - pa).length_squared();
        let vq = Quadric::plane(pn, pa, VIRTUAL_PLANE_WEIGHT * l2);
        q[a] = q[a].add(&vq);
        q[b] = q[b].add(&vq);
    }
    q
}

/// Optimal position and cost of collapsing edge `a–b` with combined quadric `q`.
fn collapse_target(q: &Quadric, pa: Vec3, pb: Vec3) -> (Vec3, f64) {
    let mid = (pa + pb) * 0.5;
    let len = pa.distance(pb);
    let x = q
        .minimize()
        .filter(|x| x.distance(mid) <= 2.0 * len)
        .unwrap_or_else(|| {
            [pa, pb, mid]
                .into_iter()
                .min_by(|x, y| q.eval(*x).total_cmp(&q.eval(*y)))
                .expect("three candidates")
        });
    (x, q.eval(x).max(0.0))
}

/// A queue entry: cost and edge id (the target position is recomputed by
/// `Pass::edge_target`).
#[derive(Debug, Clone, Copy)]
struct Entry {
    cost: f64,
    edge: EdgeId,
}

impl Entry {
    /// Queue order: cheapest first, ties by smallest edge id.
    fn before(&self, o: &Entry) -> bool {
        self.cost
            .total_cmp(&o.cost)
            .then_with(|| self.edge.cmp(&o.edge))
            .is_lt()
    }
}

/// Edges per chunk of [`Pass::queue_all_edges`]: large enough to keep both cores busy, small
/// enough that the chunk's buffers (12 B per edge) stay below a MB.
const QUEUE_FILL_CHUNK: usize = 1 << 16;

/// Marks an edge that is not in the queue.
const NOT_QUEUED: u32 = u32::MAX;

/// The collapse queue: an indexed 4-ary min-heap in [`Entry::before`] order holding at most
/// one entry per edge. Pushing an edge that is already queued changes its cost in place
/// (decrease- or increase-key), so no stale entries pile up: a lazy-deletion heap popped
/// 1.7 M entries for 185k candidates on elephant's first pass. Four children per node halve
/// the depth of a binary heap and sit in one or two cache lines.
#[derive(Debug, Default)]
struct Queue {
    v: Vec<Entry>,
    /// Heap slot of each edge, or [`NOT_QUEUED`].
    slot: EdgeData<u32>,
}

impl Queue {
    /// A queue for edge ids below `edges`.
    #[cfg(test)]
    fn with_capacity(edges: usize) -> Queue {
        Queue {
            v: Vec::with_capacity(edges),
            slot: EdgeData::filled(edges, NOT_QUEUED),
        }
    }

    fn len(&self) -> usize {
        self.v.len()
    }

    /// A queue holding `entries` (one per edge, edge ids below `edges`), built bottom-up in
    /// linear time. Entries are totally ordered by [`Entry::before`], so the pops are the same
    /// as after pushing them one by one.
    fn from_entries(edges: usize, entries: Vec<Entry>) -> Queue {
        let mut q = Queue {
            v: entries,
            slot: EdgeData::filled(edges, NOT_QUEUED),
        };
        for (i, e) in q.v.iter().enumerate() {
            q.slot[e.edge] = i as u32;
        }
        for i in (0..q.v.len().div_ceil(4)).rev() {
            q.sift_down(i);
        }
        q
    }

    /// Queues `e.edge` with cost `e.cost`, or moves it there when already queued.
    fn push(&mut self, e: Entry) {
        let k = e.edge;
        if k.index() >= self.slot.len() {
            self.slot.resize(k.index() + 1, NOT_QUEUED);
        }
        let i = self.slot[k];
        if i == NOT_QUEUED {
            self.v.push(e);
            self.sift_up(self.v.len() - 1);
            return;
        }
        let i = i as usize;
        let up = e.before(&self.v[i]);
        self.v[i] = e;
        if up {
            self.sift_up(i);
        } else {
            self.sift_down(i);
        }
    }

    fn pop(&mut self) -> Option<Entry> {
        let last = self.v.pop()?;
        self.slot[last.edge] = NOT_QUEUED;
        if self.v.is_empty() {
            return Some(last);
        }
        let top = self.v[0];
        self.slot[top.edge] = NOT_QUEUED;
        self.v[0] = last;
        self.sift_down(0);
        Some(top)
    }

    /// Places `v[i]` at slot `i` and records it.
    fn put(&mut self, i: usize, e: Entry) {
        self.v[i] = e;
        self.slot[e.edge] = i as u32;
    }

    fn sift_up(&mut self, mut i: usize) {
        let e = self.v[i];
        while i > 0 {
            let p = (i - 1) / 4;
            if !e.before(&self.v[p]) {
                break;
            }
            let pe = self.v[p];
            self.put(i, pe);
            i = p;
        }
        self.put(i, e);
    }

    fn sift_down(&mut self, mut i: usize) {
        let e = self.v[i];
        let n = self.v.len();
        loop {
            let c = 4 * i + 1;
            if c >= n {
                break;
            }
            let mut best = c;
            for j in c + 1..(c + 4).min(n) {
                if self.v[j].before(&self.v[best]) {
                    best = j;
                }
            }
            if !self.v[best].before(&e) {
                break;
            }
            let be = self.v[best];
            self.put(i, be);
            i = best;
        }
        self.put(i, e);
    }
}

/// An axis-aligned box `(min, max)`.
type Aabb = (Vec3, Vec3);

/// Largest number of candidate collapses evaluated together (see [`Pass::run`]).
const BATCH: usize = 64;

/// Batches are formed while the mesh has at least this many faces; below, candidates are
/// evaluated one at a time (a batch of one), in pure cost order.
const BATCH_MIN_FACES: usize = 2048;

/// The state of one pass.
struct Pass<'g, 'a> {
    g: &'g mut Guard<'a>,
    opt: SimplifyOptions,
    quadrics: VertexData<Quadric>,
    /// The queue and the batch formation.
    batcher: Batcher,
    /// Sampled distance to the input per face (NaN mean = not computed yet).
    face_dist: FaceData<FaceDist>,
    /// Distance to the input per vertex (NaN = not computed yet).
    vert_dist: VertexData<f64>,
    scratch: GuardScratch,
    report: SimplifyCounts,
    /// Per vertex, the input's deformation at its closest input point, when the input has one
    /// (`super::deform`): collapses keep the vertices it needs.
    labels: Option<VertexData<Label>>,
}

/// The collapse queue and the formation of batches from it (see [`Pass::run`]). Needs only
/// read access to the mesh, so a batch is formed while the guard's BVH catches up with the
/// previous one ([`Guard::flush_bvh_alongside`]).
struct Batcher {
    heap: Queue,
    /// Vertex marks of the batch being formed: `mark_w[v] == epoch` ⇔ `v` is written by a
    /// selected collapse (endpoint or one-ring), `mark_r[v] == epoch` ⇔ `v` is read by one (its
    /// two-ring, which holds the vertices of its `M_1`).
    mark_w: VertexData<u32>,
    mark_r: VertexData<u32>,
    epoch: u32,
    /// Scratch: the vertices `W` of a candidate's footprint.
    footprint: Vec<VertexId>,
    /// Entries popped so far (cancellation polling).
    pops: u64,
    /// Scratch: popped entries that overlap the batch.
    deferred: Vec<Entry>,
}

impl Batcher {
    /// Forms the next batch into `batch` (see [`Pass::run`]): pops entries in queue order,
    /// skips dead edges, keeps up to `cap` collapses with disjoint neighbourhoods (any one
    /// when `cap` is 1) and puts the overlapping ones (at most `cap`) back.
    fn form(&mut self, m: &HalfEdgeMesh, cap: usize, batch: &mut Vec<EdgeId>) {
        self.new_epoch();
        batch.clear();
        let mut deferred = std::mem::take(&mut self.deferred);
        while batch.len() < cap && deferred.len() < cap {
            let Some(entry) = self.heap.pop() else { break };
            self.pops += 1;
            let e = entry.edge;
            if !m.is_edge_live(e) {
                continue;
            }
            if cap > 1 && !self.reserve(m, e) {
                deferred.push(entry);
                continue;
            }
            batch.push(e);
        }
        for d in deferred.drain(..) {
            self.heap.push(d);
        }
        self.deferred = deferred;
    }

    /// Starts a new batch (clears the vertex marks).
    fn new_epoch(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.mark_w.fill(0);
            self.mark_r.fill(0);
            self.epoch = 1;
        }
    }

    /// Adds the collapse of edge `e` to the batch being formed if its neighbourhood is
    /// disjoint from the batch's: it writes its endpoints and their one-ring `W` (positions,
    /// connectivity, cached distances) and reads `W`'s one-ring `R` (the vertices of its guard
    /// neighbourhood `M_1`). It joins when `W ∩ R' = ∅` and `R ∩ W' = ∅` for the batch's `W'`,
    /// `R'`; then no collapse of the batch changes anything another one reads except through
    /// the BVH, which [`Pass::run`] handles.
    fn reserve(&mut self, m: &HalfEdgeMesh, e: EdgeId) -> bool {
        let h = m.edge_halfedge(e);
        let (a, b) = (m.origin(h), m.target(h));
        let ep = self.epoch;
        // W first, then the rest of R (with repeats).
        let mut fp = std::mem::take(&mut self.footprint);
        fp.clear();
        fp.extend([a, b]);
        fp.extend(m.vertex_neighbors(a));
        fp.extend(m.vertex_neighbors(b));
        let n_w = fp.len();
        let mut free = true;
        for i in 0..n_w {
            let v = fp[i];
            if self.mark_r[v] == ep {
                free = false;
                break;
            }
            fp.extend(m.vertex_neighbors(v));
        }
        free = free && fp[n_w..].iter().all(|&u| self.mark_w[u] != ep);
        if free {
            for &v in &fp[..n_w] {
                self.mark_w[v] = ep;
            }
            for &v in &fp {
                self.mark_r[v] = ep;
            }
        }
        self.footprint = fp;
        free
    }
}

/// A candidate collapse that passed every check (see [`Pass::evaluate`]).
struct Accepted {
    h: HalfedgeId,
    a: VertexId,
    b: VertexId,
    x: Vec3,
    /// Distance of `x` to the input (becomes `a`'s cached distance).
    dx: f64,
    new: Patch,
    new_face_dist: Vec<FaceDist>,
    /// The deformation label of `x` (when the input has a deformation).
    label: Option<Label>,
}

/// A face's sampled distance to the input: mean and largest of its samples (corners, and
/// the centroid when the face is longer than the sample spacing).
#[derive(Debug, Clone, Copy)]
struct FaceDist {
    mean: f64,
    max: f64,
}

impl FaceDist {
    const UNKNOWN: FaceDist = FaceDist {
        mean: f64::NAN,
        max: f64::NAN,
    };
}

/// The result of evaluating one candidate collapse against an unchanged mesh, with the
/// distances computed on the way (cache fills, written when the result is applied) and the
/// guard's counters.
struct Eval {
    outcome: std::result::Result<Accepted, Rejection>,
    vert_dist: Vec<(VertexId, f64)>,
    face_dist: Vec<(FaceId, FaceDist)>,
    guard: GuardCounts,
}

/// Runs one pass of Alg. 5 on the guard's mesh. `keep_going` is polled now and then with the
/// fraction of the queue processed; returning `false` cancels with `Error::Cancelled`.
pub(crate) fn simplify_pass(
    g: &mut Guard<'_>,
    opt: &SimplifyOptions,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<SimplifyCounts> {
    let mut pass = Pass::new(g, *opt);
    pass.run(keep_going)?;
    Ok(pass.report)
}

impl<'g, 'a> Pass<'g, 'a> {
    fn new(g: &'g mut Guard<'a>, opt: SimplifyOptions) -> Self {
        let quadrics = vertex_quadrics(g);
        let labels = g
            .input()
            .deformation
            .as_deref()
            .map(|f| vertex_labels(g, f));
        let m = g.mesh();
        let mut pass = Pass {
            labels,
            face_dist: FaceData::filled(m.face_capacity(), FaceDist::UNKNOWN),
            vert_dist: VertexData::filled(m.vertex_capacity(), f64::NAN),
            batcher: Batcher {
                heap: Queue::default(),
                mark_w: VertexData::filled(m.vertex_capacity(), 0),
                mark_r: VertexData::filled(m.vertex_capacity(), 0),
                epoch: 0,
                footprint: Vec::new(),
                pops: 0,
                deferred: Vec::new(),
            },
            scratch: GuardScratch::default(),
            quadrics,
            opt,
            report: SimplifyCounts::default(),
            g,
        };
        pass.queue_all_edges();
        pass
    }

    /// Fills the queue with every edge: costs computed in parallel (each depends only on its
    /// edge), then one bottom-up heap build. The edges go through in chunks of
    /// [`QUEUE_FILL_CHUNK`], so the transient buffers are bounded instead of 36 B per edge of
    /// the dense offset surface; the entries are the same, in the same order,
    /// whatever the chunk or thread count.
    fn queue_all_edges(&mut self) {
        let mut entries = Vec::with_capacity(self.g.mesh().edge_count());
        let mut edges: Vec<EdgeId> = Vec::with_capacity(QUEUE_FILL_CHUNK);
        let mut all = self.g.mesh().edges().peekable();
        while all.peek().is_some() {
            edges.clear();
            edges.extend(all.by_ref().take(QUEUE_FILL_CHUNK));
            let this = &*self;
            let costs: Vec<f64> = edges
                .par_iter()
                .with_min_len(1024)
                .map(|&e| this.edge_target(e).1)
                .collect();
            entries.extend(
                edges
                    .iter()
                    .zip(costs)
                    .map(|(&edge, cost)| Entry { cost, edge }),
            );
        }
        self.batcher.heap = Queue::from_entries(self.g.mesh().edge_capacity(), entries);
    }

    fn target_reached(&self) -> bool {
        self.opt
            .target_faces
            .is_some_and(|n| self.g.mesh().face_count() <= n)
    }

    fn push(&mut self, e: EdgeId) {
        let (_, cost) = self.edge_target(e);
        self.batcher.heap.push(Entry { cost, edge: e });
    }

    /// The quadric optimum and cost of collapsing `e` ([`collapse_target`] of its endpoints'
    /// summed quadrics). Recomputed where needed instead of stored per edge (24 B per edge of
    /// the dense offset surface, a memory peak): within a pass only a commit changes a
    /// quadric or a position, and it re-queues every edge at the surviving vertex, so the
    /// value when an edge is popped is the one its queue cost was computed with.
    fn edge_target(&self, e: EdgeId) -> (Vec3, f64) {
        let m = self.g.mesh();
        let h = m.edge_halfedge(e);
        let (a, b) = (m.origin(h), m.target(h));
        let q = self.quadrics[a].add(&self.quadrics[b]);
        collapse_target(&q, m.position(a).into(), m.position(b).into())
    }

    /// The queue loop. Candidates are taken in cost order in **batches** of collapses whose
    /// neighbourhoods are disjoint (no vertex written by one is read by another; see
    /// [`reserve`](Self::reserve)); a candidate that overlaps the batch goes back to the queue
    /// for the next one. A batch is evaluated read-only — in parallel — against the mesh as it
    /// was before the batch, then applied sequentially in queue order. Disjointness makes each
    /// evaluation valid after the earlier collapses of its batch, except for one thing: the
    /// guard's `M_e`-against-the-rest test (§4.3.3) saw the *old* faces of the other collapses.
    /// So before a collapse is applied, its new faces are tested against the new faces of the
    /// collapses already applied from its batch ([`patches_intersect`]); if they meet, the
    /// candidate is evaluated again against the current mesh. The batches depend only on the
    /// queue and the mesh, never on the thread count, so the output is the same for any number
    /// of threads.
    ///
    /// The guard's BVH follows the collapses of a batch while the next batch is formed (the
    /// formation reads only the mesh and the queue), and before any re-evaluation.
    fn run(&mut self, keep_going: &mut dyn FnMut(f64) -> bool) -> Result<()> {
        let r = self.run_batches(keep_going);
        self.g.flush_bvh();
        r
    }

    /// The loop of [`run`](Self::run); the BVH may be stale when it returns.
    fn run_batches(&mut self, keep_going: &mut dyn FnMut(f64) -> bool) -> Result<()> {
        let total = self.batcher.heap.len().max(1) as f64;
        let mut polled = 0u64;
        let mut batch: Vec<EdgeId> = Vec::with_capacity(BATCH);
        let mut applied: Vec<(Vec<[[f64; 3]; 3]>, Aabb)> = Vec::with_capacity(BATCH);
        'pass: while !self.target_reached() {
            let cap = if self.g.mesh().face_count() >= BATCH_MIN_FACES {
                BATCH
            } else {
                1
            };
            let batcher = &mut self.batcher;
            let out = &mut batch;
            self.g.flush_bvh_alongside(|m| batcher.form(m, cap, out));
            let pops = self.batcher.pops;
            if pops / 512 > polled {
                polled = pops / 512;
                if !keep_going((pops as f64 / total).min(1.0)) {
                    return Err(Error::Cancelled);
                }
            }
            if batch.is_empty() {
                break;
            }
            let evals: Vec<Eval> = if batch.len() == 1 {
                let mut s = std::mem::take(&mut self.scratch);
                let ev = self.evaluate(batch[0], &mut s);
                self.scratch = s;
                vec![ev]
            } else {
                let this = &*self;
                batch
                    .par_iter()
                    .map_init(GuardScratch::default, |s, &e| this.evaluate(e, s))
                    .collect()
            };
            applied.clear();
            for (&e, mut ev) in batch.iter().zip(evals) {
                if self.target_reached() {
                    break 'pass;
                }
                self.report.candidates += 1;
                let meets = match &ev.outcome {
                    Ok(acc) if !applied.is_empty() => {
                        let st = &mut self.g.stats;
                        let abox = bbox(acc.new.tris.iter().flatten().copied());
                        applied.iter().any(|(p, pbox)| {
                            boxes_overlap(abox, *pbox) && patches_intersect(&acc.new.tris, p, st)
                        })
                    }
                    _ => false,
                };
                if meets {
                    self.report.rechecked += 1;
                    self.fill_caches(&mut ev);
                    self.g.flush_bvh();
                    let mut s = std::mem::take(&mut self.scratch);
                    ev = self.evaluate(e, &mut s);
                    self.scratch = s;
                }
                if let Ok(acc) = &ev.outcome {
                    let abox = bbox(acc.new.tris.iter().flatten().copied());
                    applied.push((acc.new.tris.clone(), abox));
                }
                self.apply(ev);
            }
        }
        Ok(())
    }

    /// Checks the collapse of edge `e` without changing anything, trying the quadric optimum
    /// first and then the edge midpoint and the two endpoints (see the module docs).
    fn evaluate(&self, e: EdgeId, s: &mut GuardScratch) -> Eval {
        let mut ev = Eval {
            outcome: Err(Rejection::Guard),
            vert_dist: Vec::new(),
            face_dist: Vec::new(),
            guard: GuardCounts::default(),
        };
        let m = self.g.mesh();
        let h0 = m.edge_halfedge(e);
        let Some(h) = [h0, m.twin(h0)]
            .into_iter()
            .find(|&h| m.can_collapse(h).is_ok())
        else {
            return ev;
        };
        let (a, b) = (m.origin(h), m.target(h));
        let (pa, pb) = (Vec3::from(m.position(a)), Vec3::from(m.position(b)));
        let mut candidates = [self.edge_target(e).0; 4];
        let mut n = 1;
        for c in [(pa + pb) * 0.5, pa, pb] {
            if !candidates[..n].contains(&c) {
                candidates[n] = c;
                n += 1;
            }
        }
        let retry_guard = self.opt.retry_guard;
        for &c in &candidates[..n] {
            match self.try_position(h, a, b, c, &mut ev, s) {
                Ok(acc) => {
                    ev.outcome = Ok(acc);
                    return ev;
                }
                // Another position can cure a fold-over or a patch farther from the input, and
                // in a cage with a clearance a guard refusal (when the pass retries them); a
                // too large change, or a guard refusal elsewhere, is rarely cured by moving
                // along the edge, and retrying would double the cost of those rejections.
                Err(r @ (Rejection::Fold | Rejection::Distance | Rejection::Deformation)) => {
                    ev.outcome = Err(r)
                }
                Err(r @ Rejection::Guard) if retry_guard => ev.outcome = Err(r),
                Err(r) => {
                    ev.outcome = Err(r);
                    break;
                }
            }
        }
        ev
    }

    /// All checks for collapsing `h = a→b` to `x`, cheapest first.
    fn try_position(
        &self,
        h: HalfedgeId,
        a: VertexId,
        b: VertexId,
        x: Vec3,
        ev: &mut Eval,
        s: &mut GuardScratch,
    ) -> std::result::Result<Accepted, Rejection> {
        let (old, new) = self.patches(h, x);
        if folds_over(&old, &new) {
            return Err(Rejection::Fold);
        }
        let label = self.follows_deformation(a, b, x, &old, &new)?;
        if !self.within_hausdorff(a, b, x, &old, &new) {
            return Err(Rejection::Hausdorff);
        }
        let Some((new_face_dist, dx)) = self.distance_not_increased(a, b, x, &old, &new, ev) else {
            return Err(Rejection::Distance);
        };
        self.g
            .check_collapse(h, x.to_array(), s, &mut ev.guard)
            .map_err(|_| Rejection::Guard)?;
        Ok(Accepted {
            h,
            a,
            b,
            x,
            dx,
            new,
            new_face_dist,
            label,
        })
    }

    /// The deformation check (`super::deform`): `x`'s label, when every edge of the new patch
    /// from `x` to a neighbour `n` keeps the posed error of its middle within bounds (or no
    /// larger than the edge from `a` or `b` to `n` it replaces) and the input's deformation at
    /// a quarter, half and three quarters of it is within bounds of the edge's linear blend.
    /// `Ok(None)` without a deformation.
    fn follows_deformation(
        &self,
        a: VertexId,
        b: VertexId,
        x: Vec3,
        old: &Patch,
        new: &Patch,
    ) -> std::result::Result<Option<Label>, Rejection> {
        let (Some(labels), Some(field)) = (&self.labels, self.g.input().deformation.as_deref())
        else {
            return Ok(None);
        };
        let input = self.g.input();
        let lever = Lever::new(field, input.diag);
        let model = label_input(input);
        let m = self.g.mesh();
        let at = |v: VertexId| Vec3::from(m.position(v));
        let lx = label_at(&model, field, x.to_array()).unwrap_or_default();
        let d = self.opt.d;
        let mut seen: Vec<VertexId> = Vec::with_capacity(16);
        for &n in new.verts.iter().flatten() {
            if n == a || seen.contains(&n) {
                continue;
            }
            seen.push(n);
            let pn = at(n);
            let replaced = old
                .verts
                .iter()
                .filter(|f| f.contains(&n))
                .flatten()
                .filter(|&&e| e == a || e == b)
                .map(|&e| labels[e].skin_gap(&labels[n], at(e).distance(pn), &lever, d))
                .fold(1.0, f64::max);
            if lx.skin_gap(&labels[n], x.distance(pn), &lever, d) > replaced {
                return Err(Rejection::Deformation);
            }
            for t in [0.25f32, 0.5, 0.75] {
                let p = x + (pn - x) * f64::from(t);
                let there = label_at(&model, field, p.to_array()).unwrap_or_default();
                if there.deviation(&lx, &labels[n], t, p, &lever, d) > 1.0 {
                    return Err(Rejection::Deformation);
                }
            }
        }
        Ok(Some(lx))
    }

    /// Writes the distances an evaluation computed into the caches.
    fn fill_caches(&mut self, ev: &mut Eval) {
        for (v, d) in ev.vert_dist.drain(..) {
            self.vert_dist[v] = d;
        }
        for (f, d) in ev.face_dist.drain(..) {
            self.face_dist[f] = d;
        }
    }

    /// Applies an evaluation: caches, counters and, when accepted, the collapse.
    fn apply(&mut self, mut ev: Eval) {
        self.fill_caches(&mut ev);
        self.g.stats.add(&ev.guard);
        match ev.outcome {
            Ok(acc) => {
                let rec = self.g.commit_collapse(acc.h, acc.x.to_array());
                self.commit(&acc, &rec.modified_faces);
            }
            Err(Rejection::Fold) => self.report.rejected_fold += 1,
            Err(Rejection::Hausdorff) => self.report.rejected_hausdorff += 1,
            Err(Rejection::Distance) => self.report.rejected_distance += 1,
            Err(Rejection::Guard) => self.report.rejected_guard += 1,
            Err(Rejection::Deformation) => self.report.rejected_deformation += 1,
        }
    }

    /// The patch before (faces around `a` and `b`) and after the collapse of `h = a→b` to `x`
    /// (the surviving faces with `a`, `b` replaced by `x`), each with its face ids.
    fn patches(&self, h: HalfedgeId, x: Vec3) -> (Patch, Patch) {
        let m = self.g.mesh();
        let (a, b) = (m.origin(h), m.target(h));
        let dying = [m.face(h), m.face(m.twin(h))];
        let mut old = Patch::default();
        let mut new = Patch::default();
        // The link condition (checked before) makes the edge's faces the only ones with both
        // endpoints.
        let faces_b = m
            .vertex_faces(b)
            .filter(|&f| !m.face_vertices(f).contains(&a));
        for f in m.vertex_faces(a).chain(faces_b) {
            let vs = m.face_vertices(f);
            let t = vs.map(|v| m.position(v));
            old.push(f, vs, t);
            if dying.contains(&Some(f)) {
                continue;
            }
            let nvs = vs.map(|v| if v == b { a } else { v });
            let nt = nvs.map(|v| if v == a { x.to_array() } else { m.position(v) });
            new.push(f, nvs, nt);
        }
        (old, new)
    }

    /// Alg. 5 line 20: the two-sided Hausdorff distance between the old and new patch is at
    /// most `d`.
    ///
    /// Exact shortcut first: `H(M_e, M'_e) ≤ max(|x − a|, |x − b|)`. (A point
    /// `αx + βr_i + γr_j` of a new face lies within `α|x − a|` (or `α|x − b|`) of the point
    /// `αa + βr_i + γr_j` of the old face it came from; a point `αa + βb + γc` of a deleted
    /// face lies within `(α + β) max(|x − a|, |x − b|)` of `(α + β)x + γc` on the new edge
    /// `x–c`.) Only when that bound exceeds `d` are both patches sampled (skipping the shared
    /// ring vertices, at distance 0 on both sides).
    fn within_hausdorff(
        &self,
        a: VertexId,
        b: VertexId,
        x: Vec3,
        old: &Patch,
        new: &Patch,
    ) -> bool {
        let d = self.opt.d;
        let s = self.opt.spacing;
        let m = self.g.mesh();
        if x.distance(m.position(a).into())
            .max(x.distance(m.position(b).into()))
            <= d
        {
            return true;
        }
        // Consecutive samples are close to each other, so the triangle that was near the last
        // one is tried first.
        let hint = std::cell::Cell::new(0usize);
        let near = |p: Vec3, other: &Patch| -> bool {
            let n = other.tris.len();
            let start = hint.get().min(n.saturating_sub(1));
            let found = (0..n)
                .map(|i| (start + i) % n)
                .find(|&i| point_triangle_distance(p, &other.tris[i].map(Vec3::from)) <= d);
            if let Some(i) = found {
                hint.set(i);
            }
            found.is_some()
        };
        let one_side = |from: &Patch, to: &Patch, moved: &[(VertexId, Vec3)]| -> bool {
            for &(_, p) in moved {
                if !near(p, to) {
                    return false;
                }
            }
            for t in &from.tris {
                let t = t.map(Vec3::from);
                let k = sample_resolution(&t, s, MAX_SAMPLE_RES);
                let mut ok = true;
                for_each_sample(&t, k, true, |p| ok = ok && near(p, to));
                if !ok {
                    return false;
                }
            }
            true
        };
        one_side(new, old, &[(a, x)])
            && one_side(
                old,
                new,
                &[(a, m.position(a).into()), (b, m.position(b).into())],
            )
    }

    /// Distance of vertex `v` to the input, from the cache or computed (and noted in `ev`).
    fn vertex_distance(&self, v: VertexId, ev: &mut Eval) -> f64 {
        let d = self.vert_dist[v];
        if !d.is_nan() {
            return d;
        }
        if let Some(&(_, d)) = ev.vert_dist.iter().find(|(u, _)| *u == v) {
            return d;
        }
        // A neighbour's known distance bounds this one (the distance field is 1-Lipschitz),
        // which lets the BVH prune everything farther.
        let m = self.g.mesh();
        let p = m.position(v);
        let ub = m
            .vertex_neighbors(v)
            .map(|u| self.vert_dist[u] + Vec3::from(p).distance(Vec3::from(m.position(u))))
            .filter(|b| !b.is_nan())
            .fold(f64::INFINITY, f64::min);
        let d = if ub.is_finite() {
            self.g.input().distance_bounded(p, ub)
        } else {
            self.g.input().distance(p)
        };
        ev.vert_dist.push((v, d));
        d
    }

    /// Distance of a triangle to the input, sampled at its corners (given) and, when it is
    /// longer than the sample spacing, at its centroid. Smaller triangles use their corners
    /// only: the distance field is 1-Lipschitz and, at the offset distance, smooth at that
    /// scale, so an interior sample adds little there.
    fn triangle_distance(&self, t: &[[f64; 3]; 3], corner: [f64; 3]) -> FaceDist {
        let t = &t.map(Vec3::from);
        let sum = corner[0] + corner[1] + corner[2];
        let cmax = corner[0].max(corner[1]).max(corner[2]);
        if sample_resolution(t, self.opt.spacing, 2) == 1 {
            return FaceDist {
                mean: sum / 3.0,
                max: cmax,
            };
        }
        let c = (t[0] + t[1] + t[2]) * (1.0 / 3.0);
        let ub = (0..3)
            .map(|i| corner[i] + c.distance(t[i]))
            .fold(f64::INFINITY, f64::min);
        let dc = self.g.input().distance_bounded(c.to_array(), ub);
        FaceDist {
            mean: (sum + dc) / 4.0,
            max: cmax.max(dc),
        }
    }

    /// Distance of face `f` (vertices `vs`, corners `t`) to the input, from the cache or
    /// computed (and noted in `ev`).
    fn face_distance(
        &self,
        f: FaceId,
        vs: [VertexId; 3],
        t: &[[f64; 3]; 3],
        ev: &mut Eval,
    ) -> FaceDist {
        let d = self.face_dist[f];
        if !d.mean.is_nan() {
            return d;
        }
        if let Some(&(_, d)) = ev.face_dist.iter().find(|(g, _)| *g == f) {
            return d;
        }
        let corner = vs.map(|v| self.vertex_distance(v, ev));
        let d = self.triangle_distance(t, corner);
        ev.face_dist.push((f, d));
        d
    }

    /// Alg. 5 line 17: the one-sided distance from the new patch to the input does not exceed
    /// the old patch's (or the slack). The patch distance is the area-weighted mean of the
    /// faces' sampled mean distances (see the module docs for why not the maximum). Also the
    /// drift cap: no new sample farther than `max(DRIFT_CAP·d, old patch's farthest sample)`.
    /// Returns the new faces' distances and the distance of `x` when both hold.
    fn distance_not_increased(
        &self,
        a: VertexId,
        b: VertexId,
        x: Vec3,
        old: &Patch,
        new: &Patch,
        ev: &mut Eval,
    ) -> Option<(Vec<FaceDist>, f64)> {
        let (mut old_sum, mut old_area, mut old_max) = (0.0, 0.0, 0.0f64);
        for i in 0..old.ids.len() {
            let w = area_vector(&old.tris[i]).length();
            let fd = self.face_distance(old.ids[i], old.verts[i], &old.tris[i], ev);
            old_sum += w * fd.mean;
            old_area += w;
            old_max = old_max.max(fd.max);
        }
        let cap = old_max.max(DRIFT_CAP * self.opt.d) * (1.0 + 1e-9);
        let old_mean = if old_area > 0.0 {
            old_sum / old_area
        } else {
            0.0
        };
        let limit = old_mean.max(self.opt.slack) * (1.0 + 1e-9);
        let m = self.g.mesh();
        let (pa, pb) = (Vec3::from(m.position(a)), Vec3::from(m.position(b)));
        let ub = (self.vertex_distance(a, ev) + x.distance(pa))
            .min(self.vertex_distance(b, ev) + x.distance(pb));
        let dx = self.g.input().distance_bounded(x.to_array(), ub);
        let (mut new_sum, mut new_area) = (0.0, 0.0);
        let mut out = Vec::with_capacity(new.ids.len());
        for i in 0..new.ids.len() {
            let vs = new.verts[i];
            let mut corner = [0.0; 3];
            for k in 0..3 {
                corner[k] = if vs[k] == a {
                    dx
                } else {
                    self.vertex_distance(vs[k], ev)
                };
            }
            let fd = self.triangle_distance(&new.tris[i], corner);
            if fd.max > cap {
                return None;
            }
            let w = area_vector(&new.tris[i]).length();
            new_sum += w * fd.mean;
            new_area += w;
            out.push(fd);
        }
        let new_mean = if new_area > 0.0 {
            new_sum / new_area
        } else {
            0.0
        };
        (new_mean <= limit).then_some((out, dx))
    }

    /// Book-keeping after the accepted collapse `acc` of `b` into `a`. The distance of `a`'s
    /// new position was computed by the check (`InputModel::distance_bounded` returns the
    /// exact distance whatever the bound), so it is cached rather than queried again.
    fn commit(&mut self, acc: &Accepted, modified: &[FaceId]) {
        let (a, b, new) = (acc.a, acc.b, &acc.new);
        self.report.collapses += 1;
        self.quadrics[a] = self.quadrics[a].add(&self.quadrics[b]);
        self.vert_dist[a] = acc.dx;
        if let (Some(labels), Some(l)) = (&mut self.labels, &acc.label) {
            labels[a] = l.clone();
        }
        for (i, &f) in new.ids.iter().enumerate() {
            self.face_dist[f] = acc.new_face_dist[i];
        }
        debug_assert!(modified.iter().all(|f| new.ids.contains(f)));
        let m = self.g.mesh();
        let edges: Vec<EdgeId> = m.outgoing(a).map(|h| m.edge(h)).collect();
        for e in edges {
            if e.is_valid() {
                self.push(e);
            }
        }
    }
}

/// Which check refused a candidate position.
#[derive(Debug, Clone, Copy)]
enum Rejection {
    Fold,
    Hausdorff,
    Distance,
    Guard,
    /// An edge would span too much change of the input's deformation (`super::deform`).
    Deformation,
}

/// The guard's input as the deformation labels query it.
fn label_input(input: &InputModel) -> LabelInput<'_> {
    LabelInput {
        positions: &input.positions,
        tris: &input.tris,
        bvh: &input.bvh,
    }
}

/// The label (`super::deform`) of every live vertex of the guard's mesh, in parallel (one
/// closest-point query each); dead slots get the empty label.
fn vertex_labels(g: &Guard<'_>, field: &DeformationField) -> VertexData<Label> {
    let (m, model) = (g.mesh(), label_input(g.input()));
    let labels: Vec<Label> = (0..m.vertex_capacity())
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let v = VertexId::new(i as u32);
            if m.is_vertex_live(v) {
                label_at(&model, field, m.position(v)).unwrap_or_default()
            } else {
                Label::default()
            }
        })
        .collect();
    VertexData::from_vec(labels)
}

/// Faces of a patch: ids, vertex ids and corner positions.
#[derive(Debug, Default)]
struct Patch {
    ids: Vec<FaceId>,
    verts: Vec<[VertexId; 3]>,
    tris: Vec<[[f64; 3]; 3]>,
}

impl Patch {
    fn push(&mut self, f: FaceId, vs: [VertexId; 3], t: [[f64; 3]; 3]) {
        self.ids.push(f);
        self.verts.push(vs);
        self.tris.push(t);
    }
}

/// True when a surviving face's normal turns by 90° or more (or degenerates).
fn folds_over(old: &Patch, new: &Patch) -> bool {
    new.ids.iter().enumerate().any(|(i, f)| {
        let j = old
            .ids
            .iter()
            .position(|g| g == f)
            .expect("new faces are old faces");
        let n0 = area_vector(&old.tris[j]);
        let n1 = area_vector(&new.tris[i]);
        n0.dot(n1) <= 0.0
    })
}

/// `(b − a) × (c − a)` of a stored triangle.
fn area_vector(t: &[[f64; 3]; 3]) -> Vec3 {
    let [a, b, c] = t.map(Vec3::from);
    tri_normal(a, b, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadric_of_three_planes_has_their_corner_as_minimiser() {
        let v = Vec3::new;
        let q = Quadric::plane(v(1., 0., 0.), v(1., 0., 0.), 1.0)
            .add(&Quadric::plane(v(0., 1., 0.), v(0., 2., 0.), 2.0))
            .add(&Quadric::plane(v(0., 0., 1.), v(0., 0., 3.), 0.5));
        let x = q.minimize().unwrap();
        assert!(x.distance(v(1., 2., 3.)) < 1e-12);
        assert!(q.eval(x).abs() < 1e-12);
        assert!((q.eval(v(0., 2., 3.)) - 1.0).abs() < 1e-12);
    }

    /// Against a sorted reference: one entry per edge, the last cost pushed wins (costs go
    /// both up and down), pops interleaved with pushes come out in cost-then-edge order.
    #[test]
    fn queue_pops_in_cost_then_edge_order() {
        let mut q = Queue::with_capacity(10);
        let mut live: std::collections::BTreeMap<EdgeId, f64> = Default::default();
        let mut x = 12345u64;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            x >> 33
        };
        let min_of = |live: &std::collections::BTreeMap<EdgeId, f64>| {
            live.iter()
                .map(|(&e, &c)| (c, e))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        };
        for i in 0..3000u32 {
            let edge = EdgeId::new((next() % 300) as u32);
            let cost = (next() % 50) as f64;
            q.push(Entry { cost, edge });
            live.insert(edge, cost);
            if i % 3 == 0 {
                let want = min_of(&live).unwrap();
                let got = q.pop().unwrap();
                assert_eq!((got.cost, got.edge), want);
                live.remove(&want.1);
            }
            assert_eq!(q.len(), live.len());
        }
        while let Some(got) = q.pop() {
            let want = min_of(&live).unwrap();
            assert_eq!((got.cost, got.edge), want);
            live.remove(&want.1);
        }
        assert!(live.is_empty());
    }

    /// The bottom-up build pops exactly what pushing the entries one by one pops.
    #[test]
    fn queue_built_at_once_pops_like_pushes() {
        let mut x = 777u64;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            x >> 33
        };
        for n in [0usize, 1, 2, 5, 17, 1000] {
            let entries: Vec<Entry> = (0..n as u32)
                .map(|i| Entry {
                    cost: (next() % 40) as f64,
                    edge: EdgeId::new(i),
                })
                .collect();
            let mut pushed = Queue::with_capacity(n);
            for &e in &entries {
                pushed.push(e);
            }
            let mut built = Queue::from_entries(n, entries);
            while let Some(want) = pushed.pop() {
                let got = built.pop().unwrap();
                assert_eq!((got.cost, got.edge), (want.cost, want.edge));
            }
            assert!(built.pop().is_none());
        }
    }

    #[test]
    fn rank_one_quadric_is_singular() {
        let q = Quadric::plane(Vec3::Z, Vec3::ZERO, 1.0);
        assert!(q.minimize().is_none());
        let (x, c) = collapse_target(&q, Vec3::ZERO, Vec3::X);
        assert_eq!(c, 0.0);
        assert_eq!(x[2], 0.0);
    }
}
