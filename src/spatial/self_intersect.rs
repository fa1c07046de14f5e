//! Self-intersections of a triangle soup, with the semantics of CGAL's
//! `Polygon_mesh_processing::self_intersections` / `does_self_intersect` as `meshcheck` applies
//! them to any soup:
//!
//! 1. exactly coincident points are welded first ([`ExactWeld`]), so unwelded seams are not
//!    intersections;
//! 2. degenerate faces (exactly collinear corners, including repeated indices after welding) are
//!    reported separately and take part in no pair;
//! 3. every other pair of faces whose closed bounding boxes meet is tested with
//!    [`faces_intersect`](super::faces_intersect()): shared vertex or edge is allowed, anything
//!    more (folded-over neighbours, duplicate faces, touching, crossing, coplanar overlap) is an
//!    intersection (dissertation §4.3.3: "a mesh has intersections when any of its two triangles
//!    overlaps, or any of its two non-adjacent triangles touch or intersect").
//!
//! Broad phase: the non-degenerate faces are cut into spatially coherent chunks (runs of the
//! Morton order of their box centres, about 32k faces each), one [`TriangleBvh`] per chunk is
//! built in parallel, and every chunk tree is traversed against itself and against every later
//! chunk whose bounds it touches, in parallel: each pair of faces with touching boxes is visited
//! exactly once. Narrow phase: each visited pair is tested with exact predicates right away (no
//! candidate list is stored). The hits are sorted, so the result does not depend on the number
//! of threads. [`has_self_intersection`] runs the same traversal but stops testing at the first
//! hit.
//!
//! Stacked copies: the counting pass behind `verify::MeshReport`
//! (`count_self_intersections_welded`) and [`has_self_intersection`] group exact duplicates
//! (the same welded vertex set) first and traverse one face per group, so `k` copies of a face
//! cost one test, not `k(k−1)/2`. The listing functions return every pair, so their output (and
//! time) stays quadratic in the copies.
//!
//! Piles of near-copies: faces that overlap without being exact copies need one
//! exact test per pair (330 ns each on a jittered pile, against 19 ns of traversal). The
//! counting pass therefore estimates each chunk pair's candidates from 64 sampled faces,
//! counts a large chunk pair face by face in rounds of about 2¹⁹ candidates with a progress
//! call after each, and stops counting once 2²² tests have found an intersection, reporting
//! the count as a lower bound (deterministic: cut at a fixed position of a fixed order).

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

use rayon::prelude::*;

use super::bvh::{corners_box, TriangleBvh};
use super::tritri::{faces_intersect, is_collinear};
use crate::mesh::{ExactWeld, TriMesh};

/// All self-intersections of a soup: intersecting face pairs and degenerate faces.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SelfIntersections {
    /// Intersecting pairs `(f, g)` with `f < g` (face indices of the input), sorted.
    pub pairs: Vec<(u32, u32)>,
    /// Faces whose corners are exactly collinear (zero area), sorted. They are excluded from
    /// `pairs`; CGAL's `does_self_intersect` counts each as a self-intersection.
    pub degenerate: Vec<u32>,
}

impl SelfIntersections {
    /// True when there is no intersecting pair and no degenerate face (meshcheck's
    /// `self_intersection_free`, CGAL's `!does_self_intersect`).
    pub fn is_free(&self) -> bool {
        self.pairs.is_empty() && self.degenerate.is_empty()
    }
}

/// The intersecting face pairs `(f, g)`, `f < g`, of `mesh`, sorted (degenerate faces excluded;
/// see [`find_self_intersections`] for those).
pub fn self_intersections(mesh: &TriMesh) -> Vec<(u32, u32)> {
    find_self_intersections(mesh).pairs
}

/// Intersecting pairs and degenerate faces of `mesh`. See the [module docs](self).
pub fn find_self_intersections(mesh: &TriMesh) -> SelfIntersections {
    find_self_intersections_in(mesh.positions(), mesh.triangles())
}

/// As [`find_self_intersections`], on raw buffers (indices must be in range).
pub fn find_self_intersections_in(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
) -> SelfIntersections {
    let weld = ExactWeld::compute(positions);
    find_self_intersections_welded(positions, triangles, &weld).0
}

/// Wall seconds of the phases of [`find_self_intersections_welded`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct SelfIntersectionTimes {
    /// Welded faces and degenerate faces.
    pub prepare: f64,
    /// Chunk trees.
    pub bvh: f64,
    /// Traversal with the exact test of each candidate pair.
    pub pairs_and_tests: f64,
}

/// As [`find_self_intersections_in`] with the exact weld of `positions` already computed, with
/// the wall time of each phase.
pub(crate) fn find_self_intersections_welded(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    weld: &ExactWeld,
) -> (SelfIntersections, SelfIntersectionTimes) {
    let ((welded, faces, degenerate), prepare) =
        timed(|| split_degenerate(positions, triangles, weld));
    let (chunks, bvh) = timed(|| ChunkedBvh::new(positions, &welded, &faces, CHUNK_FACES));
    let narrow = Narrow {
        positions,
        welded: &welded,
    };
    let (pairs, pairs_and_tests) = timed(|| chunks.pairs_where(|f, g| narrow.intersect(f, g)));
    let times = SelfIntersectionTimes {
        prepare,
        bvh,
        pairs_and_tests,
    };
    (SelfIntersections { pairs, degenerate }, times)
}

/// What [`count_self_intersections_welded`] finds: the counts of
/// [`find_self_intersections_welded`] without the list of pairs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct SelfIntersectionCounts {
    /// Intersecting pairs of non-degenerate faces (`pairs.len()` of the listing pass); a lower
    /// bound when [`pairs_is_lower_bound`](Self::pairs_is_lower_bound).
    pub pairs: u64,
    /// True when counting stopped at the cap on exact tests that found an intersection
    /// ([`MAX_COUNTED_HITS`]): `pairs` is then a lower bound (at least that many pairs
    /// intersect), never an overestimate. `pairs > 0` then, so "no intersecting pair" stays
    /// exact.
    pub pairs_is_lower_bound: bool,
    /// Degenerate faces (`degenerate.len()` of the listing pass).
    pub degenerate: usize,
}

/// Exact tests that found an intersection after which [`count_self_intersections_welded`]
/// stops counting: a pile of near-copies of one face (20 000 copies with corners
/// jittered by ±10⁻⁹: 1.5·10⁸ intersecting pairs, one exact test each, 63 CPU s) is then
/// answered with a lower bound in about a second; the largest corpus count is 342 834
/// (large_cycloidal_mid16), 12 times below the cap. Pairs of stacked exact copies are counted
/// per group (no test each) and do not use up the cap.
pub(crate) const MAX_COUNTED_HITS: u64 = 1 << 22;

/// The counts of [`find_self_intersections_welded`], in time linear in the number of stacked
/// copies of a face rather than quadratic: the non-degenerate faces are grouped by
/// their welded vertex set (exact duplicates, in any corner order or orientation); the `k(k−1)/2`
/// pairs inside a group of `k` are classified once, by the exact test of its first two faces
/// (two faces on the same three welded vertices always intersect: CGAL counts duplicate faces),
/// and only one representative per group enters the broad phase, a hit between the groups of
/// sizes `k` and `m` counting `k·m` pairs. Faces of one group have the same corners and share
/// the same vertices with any other face, so every one of those pairs gets the representatives'
/// answer: the counts equal the listing pass's exactly, unless more than `max_hits` exact tests
/// of the broad phase find an intersection: counting then stops after the first query face (in
/// the chunks' fixed order) at which the tests that found one reach `max_hits`, and the count
/// is a lower bound ([`SelfIntersectionCounts::pairs_is_lower_bound`]; the same for any number
/// of threads).
///
/// `keep_going(fraction)` is called on the calling thread after the grouping, after the trees
/// and after each round of the traversal (about [`CANDIDATES_PER_ROUND`] candidate pairs, so
/// also inside one pile of overlapping faces); `None` as soon as it returns `false`.
pub(crate) fn count_self_intersections_welded(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    weld: &ExactWeld,
    max_hits: u64,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Option<(SelfIntersectionCounts, SelfIntersectionTimes)> {
    let t0 = std::time::Instant::now();
    let (welded, faces, degenerate) = split_degenerate(positions, triangles, weld);
    let groups = DuplicateGroups::of(&welded, &faces);
    let narrow = Narrow {
        positions,
        welded: &welded,
    };
    let inside = groups.pairs_inside(&narrow);
    let prepare = t0.elapsed().as_secs_f64();
    if !keep_going(0.1) {
        return None;
    }
    let t0 = std::time::Instant::now();
    let chunks =
        ChunkedBvh::new_with_stop(positions, &welded, &groups.reps, CHUNK_FACES, &mut |f| {
            keep_going(0.1 + 0.1 * f)
        })?;
    let bvh = t0.elapsed().as_secs_f64();
    let t0 = std::time::Instant::now();
    let across = chunks.weighted_count_where(
        |f, g| narrow.intersect(f, g),
        |f, g| u64::from(groups.size[f as usize]) * u64::from(groups.size[g as usize]),
        max_hits,
        CANDIDATES_PER_ROUND,
        &mut |f| keep_going(0.2 + 0.8 * f),
    )?;
    let times = SelfIntersectionTimes {
        prepare,
        bvh,
        pairs_and_tests: t0.elapsed().as_secs_f64(),
    };
    let counts = SelfIntersectionCounts {
        pairs: inside + across.total,
        pairs_is_lower_bound: across.capped,
        degenerate: degenerate.len(),
    };
    Some((counts, times))
}

/// Non-degenerate faces grouped by their welded vertex set (exact duplicates in any corner
/// order or orientation).
struct DuplicateGroups {
    /// The smallest face of each group, sorted.
    reps: Vec<u32>,
    /// Per face: the size of its group when it is a representative, else 0.
    size: Vec<u32>,
    /// Per group of two or more faces: its first two faces and its size.
    stacks: Vec<(u32, u32, u32)>,
}

impl DuplicateGroups {
    fn of(welded: &[[u32; 3]], faces: &[u32]) -> DuplicateGroups {
        let mut keyed: Vec<([u32; 3], u32)> = faces
            .par_iter()
            .map(|&f| {
                let mut k = welded[f as usize];
                k.sort_unstable();
                (k, f)
            })
            .collect();
        keyed.par_sort_unstable();
        let mut size = vec![0u32; welded.len()];
        let mut reps = Vec::new();
        let mut stacks = Vec::new();
        for run in keyed.chunk_by(|a, b| a.0 == b.0) {
            let rep = run[0].1;
            reps.push(rep);
            size[rep as usize] = run.len() as u32;
            if run.len() > 1 {
                stacks.push((rep, run[1].1, run.len() as u32));
            }
        }
        reps.par_sort_unstable();
        DuplicateGroups { reps, size, stacks }
    }

    /// Intersecting pairs inside the groups: `k(k−1)/2` per group of `k` whose first two faces
    /// intersect.
    fn pairs_inside(&self, narrow: &Narrow<'_>) -> u64 {
        self.stacks
            .iter()
            .filter(|&&(a, b, _)| narrow.intersect(a.min(b), a.max(b)))
            .map(|&(_, _, k)| u64::from(k) * (u64::from(k) - 1) / 2)
            .sum()
    }
}

/// `f()` and its wall seconds.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t0 = std::time::Instant::now();
    let r = f();
    (r, t0.elapsed().as_secs_f64())
}

/// True when `mesh` has a degenerate face or an intersecting face pair (CGAL's
/// `does_self_intersect`). Stops at the first hit found.
pub fn has_self_intersection(mesh: &TriMesh) -> bool {
    has_self_intersection_in(mesh.positions(), mesh.triangles())
}

/// As [`has_self_intersection`], on raw buffers (indices must be in range).
pub fn has_self_intersection_in(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> bool {
    let weld = ExactWeld::compute(positions);
    let (welded, faces, degenerate) = split_degenerate(positions, triangles, &weld);
    if !degenerate.is_empty() {
        return true;
    }
    // Stacked copies of a face are decided once per group, not pair by pair.
    let groups = DuplicateGroups::of(&welded, &faces);
    let narrow = Narrow {
        positions,
        welded: &welded,
    };
    if groups.pairs_inside(&narrow) > 0 {
        return true;
    }
    let chunks = ChunkedBvh::new(positions, &welded, &groups.reps, CHUNK_FACES);
    chunks.any_pair(|f, g| narrow.intersect(f, g))
}

/// Indices of the faces of `triangles` whose corners are exactly collinear, sorted.
pub fn degenerate_faces(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<u32> {
    (0..triangles.len() as u32)
        .into_par_iter()
        .filter(|&f| is_degenerate(positions, triangles[f as usize]))
        .collect()
}

#[inline]
fn is_degenerate(positions: &[[f64; 3]], t: [u32; 3]) -> bool {
    let [a, b, c] = t.map(|v| positions[v as usize]);
    is_collinear(a, b, c)
}

/// Exact narrow phase on welded faces.
struct Narrow<'a> {
    positions: &'a [[f64; 3]],
    welded: &'a [[u32; 3]],
}

impl Narrow<'_> {
    /// Whether faces `f` and `g` (both non-degenerate) intersect.
    fn intersect(&self, f: u32, g: u32) -> bool {
        faces_intersect(
            self.positions,
            self.welded[f as usize],
            self.welded[g as usize],
        )
    }
}

/// The welded faces, the non-degenerate ones and the degenerate ones (both sorted).
fn split_degenerate(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    weld: &ExactWeld,
) -> (Vec<[u32; 3]>, Vec<u32>, Vec<u32>) {
    let welded = if weld.is_identity() {
        triangles.to_vec()
    } else {
        weld.apply(triangles)
    };
    let flags: Vec<bool> = welded
        .par_iter()
        .map(|&t| is_degenerate(positions, t))
        .collect();
    let (degenerate, faces): (Vec<u32>, Vec<u32>) =
        (0..welded.len() as u32).partition(|&f| flags[f as usize]);
    (welded, faces, degenerate)
}

/// Faces per broad-phase chunk (below this, one tree).
const CHUNK_FACES: usize = 1 << 15;

/// Chunk trees built between two cancellation points of [`ChunkedBvh::new_with_stop`]: 8 trees
/// of 32k faces are about 0.14 CPU s (0.52 CPU s for the 31 trees of 10⁶ faces, 2026-11-27).
const TREES_PER_BATCH: usize = 8;

/// Candidate pairs (touching boxes, each query's tree visit counted as one more) per round of a
/// large chunk pair in [`ChunkedBvh::weighted_count_where`] (and estimated per thread in a
/// batch of small ones), between two cancellation points: about 0.18 CPU s when every
/// candidate needs the full exact test (350 ns each on a pile of near-copies).
const CANDIDATES_PER_ROUND: u64 = 1 << 19;

/// Spatially coherent chunks of faces with one BVH each (parallel build and traversal).
struct ChunkedBvh<'a> {
    trees: Vec<TriangleBvh>,
    /// The faces in Morton order; chunk `i` is `order[i * size..]`, `size` faces at most.
    order: Vec<u32>,
    size: usize,
    positions: &'a [[f64; 3]],
    welded: &'a [[u32; 3]],
}

/// The result of [`ChunkedBvh::weighted_count_where`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct CappedCount {
    /// The weighted sum over the pairs counted.
    total: u64,
    /// True when counting stopped at the cap before the last query face.
    capped: bool,
}

/// A chunk pair of [`ChunkedBvh::weighted_count_where`]: query chunk `i`, tree `j` (`i ≤ j`),
/// and its estimated candidate pairs.
#[derive(Debug, Clone, Copy)]
struct PairTask {
    i: usize,
    j: usize,
    estimate: u64,
}

/// Faces of a chunk whose box queries estimate a chunk pair's candidates
/// ([`ChunkedBvh::pair_tasks`]).
const ESTIMATE_SAMPLES: usize = 64;

/// One thread's share of a round of [`ChunkedBvh::weighted_count_where`].
#[derive(Default)]
struct RoundPart {
    total: u64,
    hits: u64,
    /// `(query position, weighted sum, hits)` of its query faces with a hit.
    per_face: Vec<(usize, u64, u64)>,
}

impl<'a> ChunkedBvh<'a> {
    /// About `faces.len() / chunk_faces` chunks (at least 1, at most 64).
    fn new(
        positions: &'a [[f64; 3]],
        welded: &'a [[u32; 3]],
        faces: &[u32],
        chunk_faces: usize,
    ) -> Self {
        Self::new_with_stop(positions, welded, faces, chunk_faces, &mut |_| true)
            .expect("never stopped")
    }

    /// As [`new`](Self::new), building the chunk trees in parallel batches of
    /// [`TREES_PER_BATCH`] with `keep_going(fraction)` on the calling thread after the Morton
    /// order and after each batch (a cancellation point every few 10⁵ faces instead
    /// of one piece of 0.5 CPU s at 10⁶ faces); `None` as soon as it returns `false`. The trees
    /// are those of one parallel build: each chunk's tree depends on its faces only.
    fn new_with_stop(
        positions: &'a [[f64; 3]],
        welded: &'a [[u32; 3]],
        faces: &[u32],
        chunk_faces: usize,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<Self> {
        let chunks = (faces.len() / chunk_faces.max(1)).clamp(1, 64);
        let order = morton_order(positions, welded, faces);
        if !keep_going(0.0) {
            return None;
        }
        let size = order.len().div_ceil(chunks).max(1);
        let ids: Vec<&[u32]> = order.chunks(size).collect();
        let mut trees = Vec::with_capacity(ids.len());
        for batch in ids.chunks(TREES_PER_BATCH) {
            trees.par_extend(
                batch
                    .par_iter()
                    .map(|ids| TriangleBvh::from_subset(positions, welded, ids)),
            );
            if !keep_going(trees.len() as f64 / ids.len() as f64) {
                return None;
            }
        }
        Some(ChunkedBvh {
            trees,
            order,
            size,
            positions,
            welded,
        })
    }

    /// The pairs `(f, g)`, `f < g`, of faces with touching boxes that pass `test`, sorted. Each
    /// touching pair is visited exactly once; chunk pairs are processed in parallel.
    fn pairs_where(&self, test: impl Fn(u32, u32) -> bool + Sync) -> Vec<(u32, u32)> {
        let n = self.trees.len();
        let tasks: Vec<(usize, usize)> = (0..n).flat_map(|i| (i..n).map(move |j| (i, j))).collect();
        let mut pairs: Vec<(u32, u32)> = tasks
            .into_par_iter()
            .flat_map_iter(|(i, j)| {
                let mut hits = Vec::new();
                self.for_each_pair(i, j, |f, g| {
                    if test(f, g) {
                        hits.push((f, g));
                    }
                });
                hits
            })
            .collect();
        pairs.par_sort_unstable();
        pairs
    }

    /// `Σ weight(f, g)` over the pairs `(f, g)`, `f < g`, of faces with touching boxes that
    /// pass `test` (each counted once, as in [`pairs_where`](Self::pairs_where)), chunk pair
    /// by chunk pair in a fixed order ([`pair_tasks`](Self::pair_tasks)), with
    /// `keep_going(fraction)` on the calling thread between pieces of about
    /// `round_candidates` candidate pairs per thread; `None` as soon as it returns `false`.
    /// A chunk pair estimated at most `2 · round_candidates` candidates is traversed as one piece
    /// (tree against tree, consecutive such pairs in parallel); a larger one (a pile of
    /// overlapping faces) by one box query per face of its first chunk, in rounds
    /// of about `round_candidates` candidates ([`count_round`](Self::count_round)).
    ///
    /// Counting stops at the first chunk pair (or, inside a large one, query face) in that
    /// order at which the tests passed reach `max_hits`; the total then covers what came
    /// before it and it (`capped` when more remains). Every piece's contribution is an
    /// integer that does not depend on who computes it, so the result is the same whatever
    /// the number of threads.
    fn weighted_count_where(
        &self,
        test: impl Fn(u32, u32) -> bool + Sync,
        weight: impl Fn(u32, u32) -> u64 + Sync,
        max_hits: u64,
        round_candidates: u64,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<CappedCount> {
        let max_hits = max_hits.max(1);
        let tasks = self.pair_tasks();
        let light = |t: &PairTask| t.estimate <= 2 * round_candidates;
        let budget = round_candidates * rayon::current_num_threads() as u64;
        let (mut total, mut hits, mut k) = (0u64, 0u64, 0usize);
        while k < tasks.len() {
            if !light(&tasks[k]) {
                let t = tasks[k];
                let len = self.chunk(t.i).len();
                let mut start = 0;
                while start < len {
                    let (end, parts) = self.count_round(t, start, round_candidates, &test, &weight);
                    let round_hits: u64 = parts.iter().map(|p| p.hits).sum();
                    if hits + round_hits >= max_hits {
                        // Resolved at the first query face in order that reaches the cap.
                        let mut per_face: Vec<(usize, u64, u64)> =
                            parts.into_iter().flat_map(|p| p.per_face).collect();
                        per_face.sort_unstable();
                        for (q, w, h) in per_face {
                            total += w;
                            hits += h;
                            if hits >= max_hits {
                                let capped = q + 1 < len || k + 1 < tasks.len();
                                return Some(CappedCount { total, capped });
                            }
                        }
                        unreachable!("the round's hits reach the cap");
                    }
                    total += parts.iter().map(|p| p.total).sum::<u64>();
                    hits += round_hits;
                    start = end;
                    let done = (k as f64 + start as f64 / len as f64) / tasks.len() as f64;
                    if !keep_going(done) {
                        return None;
                    }
                }
                k += 1;
                continue;
            }
            let mut end = k + 1;
            let mut sum = tasks[k].estimate;
            while end < tasks.len() && light(&tasks[end]) && sum + tasks[end].estimate <= budget {
                sum += tasks[end].estimate;
                end += 1;
            }
            let per_task: Vec<(u64, u64)> = tasks[k..end]
                .par_iter()
                .map(|t| {
                    let (mut w, mut h) = (0u64, 0u64);
                    self.for_each_pair(t.i, t.j, |f, g| {
                        if test(f, g) {
                            w += weight(f, g);
                            h += 1;
                        }
                    });
                    (w, h)
                })
                .collect();
            for (idx, (w, h)) in per_task.into_iter().enumerate() {
                total += w;
                hits += h;
                if hits >= max_hits {
                    let capped = k + idx + 1 < tasks.len();
                    return Some(CappedCount { total, capped });
                }
            }
            k = end;
            if !keep_going(k as f64 / tasks.len() as f64) {
                return None;
            }
        }
        Some(CappedCount {
            total,
            capped: false,
        })
    }

    /// The faces of chunk `i` (Morton order).
    fn chunk(&self, i: usize) -> &[u32] {
        let lo = (i * self.size).min(self.order.len());
        &self.order[lo..(lo + self.size).min(self.order.len())]
    }

    /// The chunk pairs `(i, j)`, `i ≤ j`, whose bounds touch, in order, each with an estimate
    /// of its candidate pairs: the mean number of faces of tree `j` whose boxes touch one of
    /// [`ESTIMATE_SAMPLES`] evenly spaced faces of chunk `i`, times the faces of chunk `i`
    /// (pairs inside one chunk counted from both sides). Deterministic; a group of heavy
    /// faces that no sample meets is smaller than `1 / ESTIMATE_SAMPLES` of the chunk.
    fn pair_tasks(&self) -> Vec<PairTask> {
        let later = self.touching_later_chunks();
        let pairs: Vec<(usize, usize)> = (0..self.trees.len())
            .flat_map(|i| {
                std::iter::once(i)
                    .chain(later[i].iter().copied())
                    .map(move |j| (i, j))
            })
            .collect();
        pairs
            .into_par_iter()
            .map(|(i, j)| {
                let faces = self.chunk(i);
                let samples = faces.len().clamp(1, ESTIMATE_SAMPLES);
                let seen: u64 = (0..samples)
                    .map(|s| {
                        let (lo, hi) = self.face_box(faces[s * faces.len() / samples]);
                        self.trees[j].query_box(lo, hi).count() as u64
                    })
                    .sum();
                let estimate = (seen * faces.len() as u64).div_ceil(samples as u64);
                PairTask { i, j, estimate }
            })
            .collect()
    }

    /// The box of face `f`'s welded corners.
    fn face_box(&self, f: u32) -> ([f64; 3], [f64; 3]) {
        corners_box(&self.welded[f as usize].map(|v| self.positions[v as usize]))
    }

    /// One round of a large chunk pair `t` of [`weighted_count_where`](Self::weighted_count_where):
    /// the faces of chunk `t.i` from position `start`, claimed in order by the pool's threads
    /// until about `round_candidates` candidates are spent, each queried against tree `t.j`;
    /// the end of the claimed positions and each thread's share.
    fn count_round(
        &self,
        t: PairTask,
        start: usize,
        round_candidates: u64,
        test: &(impl Fn(u32, u32) -> bool + Sync),
        weight: &(impl Fn(u32, u32) -> u64 + Sync),
    ) -> (usize, Vec<RoundPart>) {
        let faces = self.chunk(t.i);
        let next = AtomicUsize::new(start);
        let spent = AtomicU64::new(0);
        let parts: Vec<RoundPart> = (0..rayon::current_num_threads())
            .into_par_iter()
            .map(|_| {
                let mut part = RoundPart::default();
                while spent.load(Ordering::Relaxed) < round_candidates {
                    let q = next.fetch_add(1, Ordering::Relaxed);
                    if q >= faces.len() {
                        break;
                    }
                    let (sum, h, candidates) = self.count_face(faces[q], t, test, weight);
                    spent.fetch_add(candidates, Ordering::Relaxed);
                    if h > 0 {
                        part.per_face.push((q, sum, h));
                        part.total += sum;
                        part.hits += h;
                    }
                }
                part
            })
            .collect();
        (next.load(Ordering::Relaxed).min(faces.len()), parts)
    }

    /// For face `f` of chunk `t.i`: `(Σ weight, tests passed, candidates visited + 1)` over
    /// its partners with touching boxes in tree `t.j` (only `g > f` when `t.j == t.i`).
    fn count_face(
        &self,
        f: u32,
        t: PairTask,
        test: &impl Fn(u32, u32) -> bool,
        weight: &impl Fn(u32, u32) -> u64,
    ) -> (u64, u64, u64) {
        let (lo, hi) = self.face_box(f);
        let (mut sum, mut hits, mut candidates) = (0u64, 0u64, 1u64);
        for g in self.trees[t.j].query_box(lo, hi) {
            if t.j == t.i && g <= f {
                continue;
            }
            candidates += 1;
            let (a, b) = (f.min(g), f.max(g));
            if test(a, b) {
                sum += weight(a, b);
                hits += 1;
            }
        }
        (sum, hits, candidates)
    }

    /// Per chunk `i`: the chunks `j > i` whose bounds touch its bounds.
    fn touching_later_chunks(&self) -> Vec<Vec<usize>> {
        let bounds: Vec<_> = self.trees.iter().map(TriangleBvh::bounds).collect();
        let touch = |i: usize, j: usize| match (bounds[i], bounds[j]) {
            (Some((alo, ahi)), Some((blo, bhi))) => {
                (0..3).all(|k| alo[k] <= bhi[k] && blo[k] <= ahi[k])
            }
            _ => false,
        };
        (0..self.trees.len())
            .map(|i| (i + 1..self.trees.len()).filter(|&j| touch(i, j)).collect())
            .collect()
    }

    /// Whether some pair of faces with touching boxes passes `test`. Chunk pairs are processed
    /// in parallel; once a hit is found no further test runs and no new chunk pair starts.
    fn any_pair(&self, test: impl Fn(u32, u32) -> bool + Sync) -> bool {
        let found = AtomicBool::new(false);
        let n = self.trees.len();
        let tasks: Vec<(usize, usize)> = (0..n).flat_map(|i| (i..n).map(move |j| (i, j))).collect();
        tasks.into_par_iter().any(|(i, j)| {
            self.for_each_pair(i, j, |f, g| {
                if !found.load(Ordering::Relaxed) && test(f, g) {
                    found.store(true, Ordering::Relaxed);
                }
            });
            found.load(Ordering::Relaxed)
        })
    }

    /// Calls `f(a, b)`, `a < b`, for the touching pairs between chunks `i` and `j` (`i ≤ j`).
    fn for_each_pair(&self, i: usize, j: usize, mut f: impl FnMut(u32, u32)) {
        let (a, b) = (&self.trees[i], &self.trees[j]);
        if i == j {
            return a.for_each_self_pair(f);
        }
        if let (Some((alo, ahi)), Some((blo, bhi))) = (a.bounds(), b.bounds()) {
            if (0..3).all(|k| alo[k] <= bhi[k] && blo[k] <= ahi[k]) {
                a.for_each_pair_with(b, |x, y| f(x.min(y), x.max(y)));
            }
        }
    }
}

/// `faces` sorted by the Morton code (21 bits per axis) of their box centres, ties by index.
fn morton_order(positions: &[[f64; 3]], welded: &[[u32; 3]], faces: &[u32]) -> Vec<u32> {
    let centre = |f: u32| {
        let (lo, hi) = corners_box(&welded[f as usize].map(|v| positions[v as usize]));
        [0, 1, 2].map(|k| 0.5 * lo[k] + 0.5 * hi[k])
    };
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &f in faces {
        let c = centre(f);
        for k in 0..3 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    let scale = [0, 1, 2].map(|k| {
        if hi[k] > lo[k] {
            2_097_151.0 / (hi[k] - lo[k])
        } else {
            0.0
        }
    });
    let mut keyed: Vec<(u64, u32)> = faces
        .par_iter()
        .map(|&f| {
            let c = centre(f);
            let q = [0, 1, 2].map(|k| ((c[k] - lo[k]) * scale[k]) as u64);
            (spread(q[0]) | spread(q[1]) << 1 | spread(q[2]) << 2, f)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, f)| f).collect()
}

/// Spreads the low 21 bits of `x` to every third bit.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(p: Vec<[f64; 3]>, t: Vec<[u32; 3]>) -> TriMesh {
        TriMesh::new(p, t).unwrap()
    }

    #[test]
    fn tetrahedron_is_free_and_crossing_pair_is_found() {
        let tet = mesh(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        );
        assert!(find_self_intersections(&tet).is_free());
        assert!(!has_self_intersection(&tet));
        // Two separate triangles crossing each other, plus a degenerate one.
        let m = mesh(
            vec![
                [0., 0., 0.],
                [4., 0., 0.],
                [0., 4., 0.],
                [1., 1., -1.],
                [1., 1., 1.],
                [2., 1., 0.],
                [9., 9., 9.],
            ],
            vec![[0, 1, 2], [3, 4, 5], [6, 6, 0]],
        );
        let si = find_self_intersections(&m);
        assert_eq!(si.pairs, vec![(0, 1)]);
        assert_eq!(si.degenerate, vec![2]);
        assert!(has_self_intersection(&m));
    }

    #[test]
    fn chunked_broad_phase_finds_every_touching_pair_once() {
        // A 40 × 40 grid of unit squares (3200 triangles), slightly wavy, plus a crossing sheet.
        let n = 40u32;
        let mut p = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                p.push([i as f64, j as f64, 0.1 * ((i * j) % 3) as f64]);
            }
        }
        let id = |i: u32, j: u32| i * (n + 1) + j;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let faces: Vec<u32> = (0..t.len() as u32).collect();
        let single = TriangleBvh::new(&p, &t).self_pairs();
        assert!(single.len() > 10_000);
        for chunk_faces in [1, 50, 333, 5000] {
            let chunked = ChunkedBvh::new(&p, &t, &faces, chunk_faces);
            assert_eq!(
                chunked.trees.len(),
                (faces.len() / chunk_faces).clamp(1, 64)
            );
            assert_eq!(
                chunked.pairs_where(|_, _| true),
                single,
                "chunk size {chunk_faces}"
            );
            let mut calls = 0;
            let weight = |f: u32, g: u32| u64::from(f + g);
            let count =
                chunked.weighted_count_where(|_, _| true, weight, u64::MAX, 1 << 10, &mut |_| {
                    calls += 1;
                    true
                });
            let want: u64 = single.iter().map(|&(f, g)| u64::from(f + g)).sum();
            let exact = CappedCount {
                total: want,
                capped: false,
            };
            assert_eq!(count, Some(exact), "chunk size {chunk_faces}");
            assert!(calls >= 1);
        }
    }

    /// `n` copies of one triangle, each corner moved independently by up to ±10⁻⁹: a pile of
    /// near-copies (no two faces share a vertex), one chunk, most pairs intersecting.
    fn jittered_pile(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut jitter = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 2001) as f64 * 1e-12 - 1e-9
        };
        let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let p = (0..n)
            .flat_map(|_| corners)
            .map(|c: [f64; 3]| c.map(|x| x + jitter()))
            .collect();
        let t = (0..n).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        (p, t)
    }

    #[test]
    fn a_pile_is_counted_in_rounds_and_capped_the_same_way_for_any_thread_count() {
        let (p, t) = jittered_pile(300);
        let listed = find_self_intersections_in(&p, &t).pairs.len() as u64;
        assert!(listed > 20_000, "{listed}");
        let faces: Vec<u32> = (0..t.len() as u32).collect();
        let narrow = Narrow {
            positions: &p,
            welded: &t,
        };
        let count = |max_hits: u64, round: u64, threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let chunks = ChunkedBvh::new(&p, &t, &faces, CHUNK_FACES);
                let mut calls = 0;
                let c = chunks.weighted_count_where(
                    |f, g| narrow.intersect(f, g),
                    |_, _| 1,
                    max_hits,
                    round,
                    &mut |_| {
                        calls += 1;
                        true
                    },
                );
                (c.expect("not cancelled"), calls)
            })
        };
        let exact = CappedCount {
            total: listed,
            capped: false,
        };
        // rounds of 64 and 4096: the chunk pair is large (estimated 9·10⁴ candidates), counted
        // face by face and capped at the first face reaching 5000 hits; rounds of 2¹⁹: one
        // small piece, counted whole (the cap is reached at its end: exact)
        let (capped, _) = count(5000, 64, 1);
        assert!(capped.capped && (5000..listed).contains(&capped.total));
        for threads in [1, 3] {
            for round in [64, 4096, 1 << 19] {
                let (c, calls) = count(u64::MAX, round, threads);
                assert_eq!(c, exact, "{threads} threads, rounds of {round}");
                if round == 64 {
                    // one chunk, yet many cancellation points
                    assert!(calls > 50, "{calls}");
                }
                let want = if round < 1 << 19 { capped } else { exact };
                assert_eq!(count(5000, round, threads).0, want);
                assert_eq!(count(listed, round, threads).0.total, listed);
            }
        }
        // a cancel inside the chunk's pairs is answered at the next round
        let chunks = ChunkedBvh::new(&p, &t, &faces, CHUNK_FACES);
        let mut calls = 0;
        let stopped = chunks.weighted_count_where(
            |f, g| narrow.intersect(f, g),
            |_, _| 1,
            u64::MAX,
            64,
            &mut |_| {
                calls += 1;
                calls < 3
            },
        );
        assert_eq!((stopped, calls), (None, 3));
        // through the counting pass: the exact count, or a lower bound at the cap
        let weld = ExactWeld::compute(&p);
        let run = |max_hits| {
            count_self_intersections_welded(&p, &t, &weld, max_hits, &mut |_| true)
                .unwrap()
                .0
        };
        let full = run(u64::MAX);
        assert_eq!((full.pairs, full.pairs_is_lower_bound), (listed, false));
        assert_eq!(run(5000), full, "one small piece, counted whole");
        // a pile estimated beyond 2²⁰ candidates is counted face by face and stops at the cap
        let (p, t) = jittered_pile(1500);
        let weld = ExactWeld::compute(&p);
        let low = count_self_intersections_welded(&p, &t, &weld, 5000, &mut |_| true)
            .unwrap()
            .0;
        assert!(
            low.pairs_is_lower_bound && (5000..7000).contains(&low.pairs),
            "{low:?}"
        );
    }

    #[test]
    fn unwelded_seams_do_not_count() {
        // Two triangles of a square, each with its own copy of the diagonal's vertices.
        let m = mesh(
            vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [0., 0., 0.],
                [1., 1., 0.],
                [0., 1., 0.],
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        );
        assert!(find_self_intersections(&m).is_free());
    }
}
