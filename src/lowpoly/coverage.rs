//! The input-plane fit's coverage check: no fit operation may uncover input.
//!
//! The fit (`fit.rs`) pulls the LOD onto the input's planes, which lowers the output→input
//! distance; on open or thin inputs (a sheet's rim, a beetle's leg) the QEM placement or a flip
//! can also pull the surface *off* part of the input, and the input→output side of the
//! Hausdorff distance grows (measured on the corpus: 0.0117 → 0.0317 l on the beetle at
//! n_p = 200). This module keeps it:
//!
//! - The input is sampled as the Hausdorff measurement samples it (`verify::hausdorff`, its
//!   referenced vertices plus a barycentric grid at [`SPACING`]` · d`).
//! - Each sample `s` at distance `x_s` from the LOD before the fit gets a **budget**: `floor`
//!   (`= d`) when `x_s ≤ floor` — input within `d` may end up to `d` away — else
//!   `max(x_s, min(x_s + σ_s, X))`, `X` the largest `x_s`, with a slack
//!   `σ_s = clamp(x_s − `[`BURIED_DEPTH`]` · floor, 0, `[`BURIED_SLACK`]` · floor)`: input
//!   already farther than `d` (hidden input, rims the offset rounded) may not get farther,
//!   except input buried deeper than `2 d`, which may get up to one `d` farther, but never
//!   farther than the farthest sample already is. Measured 2026-12-06: input buried a few `d` under
//!   a flat face held that face off the input's plane — thingi10k 42722 at n_p = 200, whose 4093 of
//!   20k samples the unchecked fit moved beyond their distance were 99.7 % buried (median 5.7 d,
//!   moved by at most 1.08 d, the farthest not moved farther): 28.41 dB with the strict budget,
//!   29.82 dB with this slack, 39.97 dB unchecked. A slack from any depth (`x_s > d`) gained more
//!   there (30.77 dB) but let the fit pull the bridge between two cubes sharing an edge (input 1–2
//!   `d` inside it) into a twist (dirty_synth_nonmanifold at n_p = 100: 25.49 → 22.84 dB). Measured
//!   2026-12-07 and not taken either: samples deeper than `2 d` free up to `X` (no one-`d` limit) —
//!   42722 31.69 dB, the 23-mesh mean +0.08 dB, but the tree's measured Hausdorff distance
//!   +0.0008 l (many samples at the cap, the measurement sampling between them);
//!   docs/design-notes-lod.md, "LOD loop and fit".
//! - Invariant: every sample is within its budget of the LOD. A vertex move or a flip replaces
//!   a patch of faces (the one-ring, the flip's two faces); a sample within its budget of the
//!   *old* patch may rely on it, so it must be within its budget of the *new* patch, or the
//!   operation is refused. Samples farther than their budget from the old patch are covered by
//!   faces the operation does not touch. This is conservative (a sample covered both by the
//!   patch and by another face is still required to stay covered by the patch).
//!
//! Then, over the samples, `in→out(fitted) ≤ max(in→out(loop), d)` still (the slack is capped
//! at the farthest sample's distance). Candidate samples come from
//! a box tree over the samples' budget boxes `s ± b_s`, queried with the old patch's box.
//! Deterministic: the check is a pure predicate of the mesh and the candidate positions.

use rayon::prelude::*;

use crate::geom::{normalized, tri_normal, Vec3};
use crate::mesh::halfedge::{HalfEdgeMesh, VertexId};
use crate::spatial::closest::point_triangle_distance;
use crate::spatial::{cube_meets, sort_in_tree_order, CubeTree, TriangleBvh};
use crate::verify::hausdorff::surface_samples;

use super::guard::InputModel;

/// Spacing of the input samples, in `d` (the Hausdorff measurement's is `l / 400`, `d / 2` at
/// n_p = 200). 1 since 2026-11-29 (was 0.5, changed for speed): a quarter of the samples, the
/// fit 1.5–2.5× faster (fandisk at n_p = 200: bake 0.70 → 0.44 s wall); measured with the
/// shared harness at n_p = 100 and 200 against QEM and meshoptimizer at equal faces
/// (docs/benchmarks/ lod.md): shading and Hausdorff distance unchanged within the
/// per-mesh noise. The final measurement (`verify::hausdorff`, at `l / 400`) and the fit's
/// safety revert still judge the fitted LOD.
pub const SPACING: f64 = 1.0;

/// How much farther a sample buried deeper than [`BURIED_DEPTH`] floors may end, in floors (reached
/// at `BURIED_DEPTH + BURIED_SLACK`), capped at the farthest sample's distance before the fit
/// (module docs). 1 since 2026-12-06 (was 0): measured that day with the shared harness over the 23
/// corpus meshes, it changes only the four inputs with deeply buried parts at n_p = 200 (mean PSNR
/// 25.43 → 25.52 dB, normal difference 0.0477 → 0.0474, Hausdorff unchanged) and two at n_p = 100
/// (22.57 → 22.62 dB); docs/design-notes-lod.md, "LOD loop and fit".
pub const BURIED_SLACK: f64 = 1.0;

/// The depth, in floors, below which a sample gets no slack ([`BURIED_SLACK`]): input 1–2 `d`
/// inside the LOD lies in the bridges and fillets the offset spans, whose shape it holds.
pub const BURIED_DEPTH: f64 = 2.0;

/// Fewer samples than this are checked on the calling thread: a fit operation's patch is small, and
/// below this the thread pool's wake-ups cost more than the work (measured 2026-11-29:
/// `sched_yield` and futex calls were ≈ 20% of a chain's CPU). The answers do not depend on it.
const PARALLEL_MIN: usize = 2048;

/// Cap on the per-edge subdivisions of one input triangle's samples.
const MAX_SUBDIVISIONS: usize = 32;

/// The input samples, their budgets and the box tree over `s ± b_s` (module docs): 24 + 8 B a
/// sample and the compact [`CubeTree`]'s ≈ 7.5 B (parry's BVH took ≈ 400 B a sample, too much
/// for the memory budget).
pub(crate) struct Coverage {
    points: Vec<Vec3>,
    budget: Vec<f64>,
    tree: CubeTree,
    /// At least twice the largest [`box_cull_margin`] of any sample: the growth of a face's
    /// box that finds every sample the face's box test would not cull.
    grow: f64,
    /// Operations refused because they would uncover a sample.
    pub refused: u64,
}

/// The budgets of samples at distances `dist` from the LOD before the fit (module docs): `floor`
/// within it, else the distance plus its slack (from [`BURIED_DEPTH`] floors deep, up to
/// [`BURIED_SLACK`] floors), capped at the largest finite distance (never below its own).
fn budgets(dist: Vec<f64>, floor: f64) -> Vec<f64> {
    let farthest = dist
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(0.0, f64::max);
    dist.into_iter()
        .map(|x| {
            if x <= floor {
                floor
            } else {
                let slack = (x - BURIED_DEPTH * floor).clamp(0.0, BURIED_SLACK * floor);
                (x + slack).min(farthest).max(x)
            }
        })
        .collect()
}

impl Coverage {
    /// Samples `input` at [`SPACING`]` · d` and sets each sample's budget from its distance to
    /// `lod` (the LOD before the fit): [`budgets`].
    pub fn new(input: &InputModel, lod: &HalfEdgeMesh, d: f64, floor: f64) -> Coverage {
        let mut points =
            surface_samples(&input.positions, &input.tris, SPACING * d, MAX_SUBDIVISIONS);
        // stored in the box tree's order: its queries, and the budgets' closest-point queries
        // below, then read consecutive samples (the sample indices are internal)
        sort_in_tree_order(&mut points);
        let tm = lod.to_trimesh();
        let bvh = TriangleBvh::new(tm.positions(), tm.triangles());
        let dist: Vec<f64> = points
            .par_iter()
            .map(|p| {
                bvh.closest_point(tm.positions(), tm.triangles(), p.to_array(), f64::INFINITY)
                    .map_or(f64::INFINITY, |c| c.distance)
            })
            .collect();
        Coverage::from_samples(points, budgets(dist, floor))
    }

    /// The coverage of `points` with their `budget`s: the box tree over `s ± b_s`, no refusals.
    fn from_samples(points: Vec<Vec3>, budget: Vec<f64>) -> Coverage {
        let tree = CubeTree::new(&points, &budget);
        let largest = points
            .iter()
            .zip(&budget)
            .map(|(&p, &b)| box_cull_margin(p, b))
            .fold(0.0, f64::max);
        let grow = if (2.0 * largest).is_finite() {
            2.0 * largest
        } else {
            f64::INFINITY
        };
        Coverage {
            points,
            budget,
            tree,
            grow,
            refused: 0,
        }
    }

    /// The samples that may rely on the faces `old` (within their budget of them): the only
    /// ones a replacement of `old` must keep covered (module docs). Each comes with the index
    /// of the first `old` face within its budget and its spare, which [`Coverage::keeps`]
    /// uses; deterministic order (the box tree's), not sorted.
    ///
    /// Same answers as testing every sample whose cube `s ± b_s` meets the patch's box against
    /// the faces in order ([`Patch::face_within`]), found faster: one box
    /// tree query with the patch's box, then face `k` is tried on a candidate only when its
    /// cube meets face `k`'s box grown by [`Coverage::grow`] — every sample the face's box
    /// test would not cull — so a high-valence ring does not test every candidate against
    /// every face, and no part of the tree is walked once per face.
    pub fn relying_on(&mut self, old: &[[Vec3; 3]]) -> Vec<Relying> {
        self.relying_on_moved(old, None)
    }

    /// [`Coverage::relying_on`], leaving out, with `moved = Some(δ)`, the samples that
    /// [`Coverage::keeps_within`] keeps without a distance for any replacement of `old` whose
    /// points each move at most `δ` (`spare ≥ δ + box_cull_margin(s, b + δ)`, the margin
    /// increasing in `δ`): the answer of [`Coverage::keeps_within`] with any `moved ≤ δ` is
    /// the same as over the full set (faster: most samples stay well inside their budget, and
    /// are no longer listed and re-checked on every line-search trial).
    fn relying_on_moved(&mut self, old: &[[Vec3; 3]], moved: Option<f64>) -> Vec<Relying> {
        let Some((lo, hi)) = corners_box(old) else {
            return Vec::new();
        };
        let patch = Patch::new(old);
        let grow = Vec3::splat(self.grow);
        let grown: Vec<(Vec3, Vec3)> = patch
            .boxes
            .iter()
            .map(|&(flo, fhi)| (flo - grow, fhi + grow))
            .collect();
        let (points, budget) = (&self.points, &self.budget);
        let candidates = self.tree.overlapping(points, budget, lo, hi);
        let relying = |s: u32| {
            let (p, b) = (points[s as usize], budget[s as usize]);
            let (face, dist) = grown.iter().enumerate().find_map(|(k, &(flo, fhi))| {
                if !cube_meets(p, b, flo, fhi) {
                    return None;
                }
                patch.near_or_inside(k, p, b).map(|dist| (k, dist))
            })?;
            let spare = b - dist;
            // kept unseen by every trial (`keeps_within`'s shortcut): left out
            let unseen = moved.is_some_and(|m| spare >= m + box_cull_margin(p, b + m));
            (!unseen).then_some(Relying {
                sample: s,
                face: face as u32,
                spare,
            })
        };
        // in the candidates' order either way (`collect` keeps it)
        if candidates.len() >= PARALLEL_MIN {
            candidates
                .into_par_iter()
                .with_min_len(64)
                .filter_map(relying)
                .collect()
        } else {
            candidates.into_iter().filter_map(relying).collect()
        }
    }

    /// Whether the faces `new` keep every sample of `relying` (from [`Coverage::relying_on`])
    /// within its budget; counts a refusal.
    pub fn keeps(&mut self, relying: &[Relying], new: &[[Vec3; 3]]) -> bool {
        self.keeps_within(relying, new, None, &mut 0)
    }

    /// [`Coverage::keeps`]; with `moved = Some(δ)`, face `k` of `new` is face `k` of the
    /// patch `relying` was computed on with no point moved farther than `δ`, so a sample whose
    /// relied-on face had `spare ≥ δ` (plus [`box_cull_margin`], far beyond rounding) is kept
    /// without a distance: `dist(s, new_k) ≤ dist(s, old_k) + δ ≤ b` (the triangle
    /// inequality, each point of the face moving at most `δ`). The answer is the exact
    /// predicate's, as with the box test.
    ///
    /// `hint` indexes `relying`: that sample is tested first and, on a refusal, becomes a
    /// sample that failed. A line search's trials share `relying` and one hint, so a shorter
    /// step that fails on the same sample costs one test instead of a scan (up to
    /// `flow::MAX_HALVINGS` + 1 trials per move, most of them refused on large inputs). The
    /// answer is a conjunction, the same whatever the order.
    fn keeps_within(
        &mut self,
        relying: &[Relying],
        new: &[[Vec3; 3]],
        moved: Option<f64>,
        hint: &mut usize,
    ) -> bool {
        let patch = Patch::new(new);
        let kept = |r: &Relying| {
            let s = r.sample as usize;
            let (p, b) = (self.points[s], self.budget[s]);
            if moved.is_some_and(|m| r.spare >= m + box_cull_margin(p, b + m)) {
                return true;
            }
            patch.face_within(p, b, r.face as usize).is_some()
        };
        let failing = match relying.get(*hint) {
            Some(r) if !kept(r) => Some(*hint),
            // which failing sample a parallel scan reports varies; it only becomes the hint
            _ if relying.len() >= PARALLEL_MIN => relying
                .par_iter()
                .with_min_len(64)
                .position_any(|r| !kept(r)),
            _ => relying.iter().position(|r| !kept(r)),
        };
        match failing {
            Some(i) => {
                *hint = i;
                self.refused += 1;
                false
            }
            None => true,
        }
    }

    /// [`Coverage::relying_on`] the one-ring of `v`, for [`Coverage::keeps_move`] with moves of
    /// `v` no longer than `max_move` (the samples it would keep unseen left out:
    /// [`Coverage::relying_on_moved`]).
    pub fn relying_on_ring(
        &mut self,
        m: &HalfEdgeMesh,
        v: VertexId,
        max_move: f64,
    ) -> Vec<Relying> {
        let old: Vec<[Vec3; 3]> = m
            .vertex_faces(v)
            .map(|f| m.face_positions(f).map(Vec3::from))
            .collect();
        self.relying_on_moved(&old, Some(max_move))
    }

    /// [`Coverage::keeps`] for moving `v` of `m` to `q` (its one-ring after the move);
    /// `relying` from [`Coverage::relying_on_ring`] with a `max_move` of at least the move.
    /// `hint`: as for `keeps_within` (one per line search, starting at 0).
    pub fn keeps_move(
        &mut self,
        relying: &[Relying],
        m: &HalfEdgeMesh,
        v: VertexId,
        q: Vec3,
        hint: &mut usize,
    ) -> bool {
        let moved = q.distance(Vec3::from(m.position(v)));
        let new: Vec<[Vec3; 3]> = m
            .vertex_faces(v)
            .map(|f| {
                let vs = m.face_vertices(f);
                let mut t = m.face_positions(f).map(Vec3::from);
                for k in 0..3 {
                    if vs[k] == v {
                        t[k] = q;
                    }
                }
                t
            })
            .collect();
        // the one-ring in the order `relying_on_ring` saw it, only `v` moved (by `moved`)
        self.keeps_within(relying, &new, Some(moved), hint)
    }
}

/// A sample that relies on a patch ([`Coverage::relying_on`]): the sample's index and the index
/// of a patch face within its budget (where the replacement patch is checked first: a vertex
/// move keeps the one-ring's face order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Relying {
    /// Index of the sample.
    pub sample: u32,
    /// Index of the patch face found within the sample's budget.
    pub face: u32,
    /// At most the sample's budget less its distance to that face (`≥ 0`; exact, or lower by
    /// the rounding bounds of [`Patch::near_or_inside`]).
    pub spare: f64,
}

/// A patch of faces with their bounding boxes and prism bounds, for the coverage predicate.
struct Patch<'a> {
    tris: &'a [[Vec3; 3]],
    boxes: Vec<(Vec3, Vec3)>,
    prisms: Vec<Option<Prism>>,
}

impl<'a> Patch<'a> {
    fn new(tris: &'a [[Vec3; 3]]) -> Self {
        let boxes = tris
            .iter()
            .map(|t| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])))
            .collect();
        let prisms = tris.iter().map(Prism::new).collect();
        Patch {
            tris,
            boxes,
            prisms,
        }
    }

    /// A face of the patch within `b` of `p` (`point_triangle_distance ≤ b`) and that distance,
    /// trying face `first` first, then the others in order; `None` when there is none. The
    /// answer (face and distance) is the exact predicate's: a face is skipped without its
    /// distance only when its box, or its [`Prism`] lower bound, is farther than `b` by more
    /// than [`box_cull_margin`] — far beyond the rounding of either distance — so speed is all
    /// the boxes and prisms change.
    fn face_within(&self, p: Vec3, b: f64, first: usize) -> Option<(usize, f64)> {
        let near = |k: usize| self.near(k, p, b).map(|dist| (k, dist));
        let n = self.tris.len();
        if first < n {
            if let Some(hit) = near(first) {
                return Some(hit);
            }
        }
        (0..n).filter(|&k| k != first).find_map(near)
    }

    /// [`Patch::near`], or an upper bound on the distance when the [`Prism`] shows `p` over
    /// face `k` within `b` by more than [`box_cull_margin`] (then the exact distance is `≤ b`
    /// too, so the same faces answer; the bound only lowers a [`Relying::spare`], which
    /// [`Coverage::keeps`] uses as a sufficient condition).
    fn near_or_inside(&self, k: usize, p: Vec3, b: f64) -> Option<f64> {
        let margin = box_cull_margin(p, b);
        match self.prisms[k].and_then(|pr| pr.over(p)) {
            Some(up) if up + margin <= b => Some(up + margin),
            _ => self.near(k, p, b),
        }
    }

    /// `point_triangle_distance(p, face k)` when it is `≤ b`, else `None`; the face's box and
    /// [`Prism`] skip the distance only when they are farther than `b` by more than
    /// [`box_cull_margin`], so the answer is the exact predicate's.
    fn near(&self, k: usize, p: Vec3, b: f64) -> Option<f64> {
        let margin = box_cull_margin(p, b);
        let (lo, hi) = self.boxes[k];
        if box_distance(lo, hi, p) > b + margin {
            return None;
        }
        if self.prisms[k].is_some_and(|pr| pr.farther_than(p, b + margin)) {
            return None;
        }
        let dist = point_triangle_distance(p, &self.tris[k]);
        (dist <= b).then_some(dist)
    }
}

/// A lower bound on the distance from a point to a well-shaped triangle `abc` (cheaper than the
/// exact distance): the triangle lies in its plane (unit normal `n`) and, within the plane, on the
/// inner side of each edge line (in-plane inward unit normals `m_e`, `n × (end − start)` for a
/// counter-clockwise `n = ab × ac`). For any `q` of the triangle, `p − q` has the component
/// `h = n · (p − a)` along `n` and, along the orthogonal `m_e`, a component at least
/// `−s_e = −m_e · (p − start_e)` when `s_e < 0`; so `dist(p, abc)² ≥ h² + min(0, min_e s_e)²`.
#[derive(Debug, Clone, Copy)]
struct Prism {
    a: Vec3,
    n: Vec3,
    /// Edge start points `a, b, c` and inward unit normals of `ab, bc, ca`.
    starts: [Vec3; 3],
    inward: [Vec3; 3],
    /// Added to the margin: bounds the rounding of `n`, `m_e` (well-shaped faces only) times
    /// the face's extent.
    slack: f64,
}

impl Prism {
    /// The bound of triangle `t`, or `None` when `t` is not well-shaped (`|ab × ac| <
    /// 10⁻² · longest edge²`, i.e. a smallest angle under ≈ 0.6°), where the unit vectors
    /// would be ill-conditioned and only the exact distance is used.
    fn new(t: &[Vec3; 3]) -> Option<Prism> {
        let [a, b, c] = *t;
        let cross = tri_normal(a, b, c);
        let longest = (b - a)
            .length_squared()
            .max((c - b).length_squared())
            .max((a - c).length_squared());
        let area2 = cross.length();
        if !(area2 >= 1e-2 * longest && longest.is_finite()) {
            return None;
        }
        let n = normalized(cross)?;
        let edge = |s: Vec3, e: Vec3| normalized(n.cross(e - s));
        Some(Prism {
            a,
            n,
            starts: [a, b, c],
            inward: [edge(a, b)?, edge(b, c)?, edge(c, a)?],
            slack: 1e-12 * longest.sqrt(),
        })
    }

    /// When `p` projects into the triangle (`s_e ≥ 0` for every edge), where its distance is
    /// `|h|`: `|h|` plus [`Prism::slack`], an upper bound on that distance; else `None`.
    fn over(&self, p: Vec3) -> Option<f64> {
        let inside = self
            .starts
            .iter()
            .zip(&self.inward)
            .all(|(s, m)| m.dot(p - *s) >= 0.0);
        inside.then(|| self.n.dot(p - self.a).abs() + self.slack)
    }

    /// Whether `p` is provably farther than `r` (plus the rounding [`Prism::slack`]) from the
    /// triangle: `h² + min(0, min_e s_e)² > (r + slack)²` (type docs).
    fn farther_than(&self, p: Vec3, r: f64) -> bool {
        let h = self.n.dot(p - self.a);
        let mut out = 0.0f64;
        for (s, m) in self.starts.iter().zip(&self.inward) {
            out = out.min(m.dot(p - *s));
        }
        let r = r + self.slack;
        h * h + out * out > r * r
    }
}

/// How much farther than `b` a face's box must be from `p` before the face is skipped unseen:
/// `10⁻⁹ (b + ‖p‖∞)`, some 10⁶ times the rounding error of the distances involved.
fn box_cull_margin(p: Vec3, b: f64) -> f64 {
    1e-9 * (b + p.x.abs().max(p.y.abs()).max(p.z.abs()))
}

/// Euclidean distance from `p` to the closed box `[lo, hi]` (0 inside).
fn box_distance(lo: Vec3, hi: Vec3, p: Vec3) -> f64 {
    let dx = (lo.x - p.x).max(p.x - hi.x).max(0.0);
    let dy = (lo.y - p.y).max(p.y - hi.y).max(0.0);
    let dz = (lo.z - p.z).max(p.z - hi.z).max(0.0);
    (dx * dx + dy * dy + dz * dz).sqrt()
}

/// The bounding box of the corners of `tris` (`None` when empty).
fn corners_box(tris: &[[Vec3; 3]]) -> Option<(Vec3, Vec3)> {
    let mut it = tris.iter().flatten();
    let first = *it.next()?;
    Some(it.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    /// A sample within the floor gets the floor; one buried less than two floors deep its own
    /// distance; deeper, a slack ramping up to one floor, but never more than the farthest
    /// sample's distance; an uncovered one (infinite distance) stays unbounded.
    #[test]
    fn deeply_buried_samples_get_slack_up_to_the_farthest() {
        let dist = vec![0.2, 1.0, 1.5, 2.0, 2.5, 3.5, 5.0, 5.5, f64::INFINITY];
        let b = budgets(dist, 1.0);
        assert_eq!(b, [1.0, 1.0, 1.5, 2.0, 3.0, 4.5, 5.5, 5.5, f64::INFINITY]);
    }

    fn coverage(points: Vec<Vec3>, budget: Vec<f64>) -> Coverage {
        Coverage::from_samples(points, budget)
    }

    /// A sample at the origin with budget 1 under a triangle at height 0.5: lifting the
    /// triangle to 0.9 keeps it, to 1.5 uncovers it; a sample the old patch did not cover
    /// (farther than its budget) does not constrain the patch.
    #[test]
    fn a_patch_may_not_move_off_a_sample_it_covers() {
        let tri = |z: f64| [v(-1.0, -1.0, z), v(2.0, -1.0, z), v(-1.0, 2.0, z)];
        let mut c = coverage(vec![v(0.0, 0.0, 0.0)], vec![1.0]);
        let relying = c.relying_on(&[tri(0.5)]);
        assert_eq!(relying.len(), 1);
        assert_eq!((relying[0].sample, relying[0].face), (0, 0));
        // over the face: the spare is `b − |h|` less the rounding bounds, far below 10⁻⁶
        assert!(relying[0].spare <= 0.5 && relying[0].spare > 0.5 - 1e-6);
        assert!(c.keeps(&relying, &[tri(0.9)]));
        assert!(!c.keeps(&relying, &[tri(1.5)]));
        assert_eq!(c.refused, 1);
        assert!(c.relying_on(&[tri(1.2)]).is_empty());
    }
}
