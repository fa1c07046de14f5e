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
//! Stacked copies (issue 15): the counting pass behind `verify::MeshReport`
//! (`count_self_intersections_welded`) and [`has_self_intersection`] group exact duplicates
//! (the same welded vertex set) first and traverse one face per group, so `k` copies of a face
//! cost one test, not `k(k−1)/2`. The listing functions return every pair, so their output (and
//! time) stays quadratic in the copies.

use std::sync::atomic::{AtomicBool, Ordering};

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
    /// Intersecting pairs of non-degenerate faces (`pairs.len()` of the listing pass).
    pub pairs: u64,
    /// Degenerate faces (`degenerate.len()` of the listing pass).
    pub degenerate: usize,
}

/// The counts of [`find_self_intersections_welded`], in time linear in the number of stacked
/// copies of a face rather than quadratic (issue 15): the non-degenerate faces are grouped by
/// their welded vertex set (exact duplicates, in any corner order or orientation); the `k(k−1)/2`
/// pairs inside a group of `k` are classified once, by the exact test of its first two faces
/// (two faces on the same three welded vertices always intersect: CGAL counts duplicate faces),
/// and only one representative per group enters the broad phase, a hit between the groups of
/// sizes `k` and `m` counting `k·m` pairs. Faces of one group have the same corners and share
/// the same vertices with any other face, so every one of those pairs gets the representatives'
/// answer: the counts equal the listing pass's exactly.
///
/// `keep_going(fraction)` is called on the calling thread after the grouping, after the trees
/// and after each batch of chunk pairs of the traversal; `None` as soon as it returns `false`.
pub(crate) fn count_self_intersections_welded(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    weld: &ExactWeld,
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
        &mut |f| keep_going(0.2 + 0.8 * f),
    )?;
    let times = SelfIntersectionTimes {
        prepare,
        bvh,
        pairs_and_tests: t0.elapsed().as_secs_f64(),
    };
    let counts = SelfIntersectionCounts {
        pairs: inside + across,
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
    // Stacked copies of a face are decided once per group (issue 15: not pair by pair).
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

/// Spatially coherent chunks of faces with one BVH each (parallel build and traversal).
struct ChunkedBvh {
    trees: Vec<TriangleBvh>,
}

impl ChunkedBvh {
    /// About `faces.len() / chunk_faces` chunks (at least 1, at most 64).
    fn new(positions: &[[f64; 3]], welded: &[[u32; 3]], faces: &[u32], chunk_faces: usize) -> Self {
        Self::new_with_stop(positions, welded, faces, chunk_faces, &mut |_| true)
            .expect("never stopped")
    }

    /// As [`new`](Self::new), building the chunk trees in parallel batches of
    /// [`TREES_PER_BATCH`] with `keep_going(fraction)` on the calling thread after the Morton
    /// order and after each batch (issue 15: a cancellation point every few 10⁵ faces instead
    /// of one piece of 0.5 CPU s at 10⁶ faces); `None` as soon as it returns `false`. The trees
    /// are those of one parallel build: each chunk's tree depends on its faces only.
    fn new_with_stop(
        positions: &[[f64; 3]],
        welded: &[[u32; 3]],
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
        Some(ChunkedBvh { trees })
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
    /// pass `test` (each visited once, as in [`pairs_where`](Self::pairs_where)). Chunk pairs
    /// are processed in parallel in batches, with `keep_going(fraction)` on the calling thread
    /// after each batch; `None` as soon as it returns `false`. An integer sum: the same
    /// whatever the number of threads.
    fn weighted_count_where(
        &self,
        test: impl Fn(u32, u32) -> bool + Sync,
        weight: impl Fn(u32, u32) -> u64 + Sync,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<u64> {
        let n = self.trees.len();
        let tasks: Vec<(usize, usize)> = (0..n).flat_map(|i| (i..n).map(move |j| (i, j))).collect();
        let mut total = 0u64;
        let mut done = 0;
        for batch in tasks.chunks(n.max(1)) {
            total += batch
                .par_iter()
                .map(|&(i, j)| {
                    let mut sum = 0u64;
                    self.for_each_pair(i, j, |f, g| {
                        if test(f, g) {
                            sum += weight(f, g);
                        }
                    });
                    sum
                })
                .sum::<u64>();
            done += batch.len();
            if !keep_going(done as f64 / tasks.len() as f64) {
                return None;
            }
        }
        Some(total)
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
            let count =
                chunked.weighted_count_where(|_, _| true, |f, g| u64::from(f + g), &mut |_| {
                    calls += 1;
                    true
                });
            let want: u64 = single.iter().map(|&(f, g)| u64::from(f + g)).sum();
            assert_eq!(count, Some(want), "chunk size {chunk_faces}");
            assert!(calls >= chunked.trees.len().div_ceil(2));
        }
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
