//! Cage checks of any mesh against any input soup: **contact** (exact triangle–triangle tests
//! on Shewchuk's predicates, BVH candidates), **enclosure** (hierarchical fast winding numbers,
//! Barill et al. 2018, of every referenced input vertex) and **clearance**: the exact minimum
//! distance between cage triangles and input triangles ([`CageInput::min_distance`]), and the
//! cheaper vertex-based upper bound [`clearance`].
//!
//! This is the verification of what the cage pipeline produces; it shares no code with the
//! guard that keeps those properties during the cage's construction.
//!
//! May import: `crate::mesh`, `crate::spatial`, `crate::geom` (never `lowpoly`, `cage` or
//! `wrinkle`).

use rayon::prelude::*;

use crate::geom::Vec3;
use crate::mesh::TriMesh;
use crate::spatial::bvh::corners_box;
use crate::spatial::closest::{disjoint_triangle_distance, plane_gap_lower_bound};
use crate::spatial::{
    is_collinear, segment_triangle_intersect, triangles_intersect, FastWindingNumber, TriangleBvh,
};

/// Result of [`check_cage`]: the two cage properties.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CageCheck {
    /// No cage triangle touches or intersects an input triangle (exact tests on BVH
    /// candidates; touching counts as contact).
    pub untouched: bool,
    /// Every referenced input vertex has winding number above 1/2 with respect to the cage
    /// (hierarchical fast winding numbers, Barill et al. 2018).
    pub encloses: bool,
}

impl CageCheck {
    /// Both properties hold.
    pub fn is_cage(&self) -> bool {
        self.untouched && self.encloses
    }
}

/// The input side of the cage checks, prepared once and reusable for several candidate cages
/// of the same input: its triangles with a BVH, which of them are degenerate, and its
/// referenced vertices.
pub struct CageInput<'a> {
    positions: &'a [[f64; 3]],
    tris: &'a [[u32; 3]],
    bvh: TriangleBvh,
    /// Per triangle: corners exactly collinear (tested by its edges).
    degenerate: Vec<bool>,
    /// Referenced vertices, in index order.
    points: Vec<[f64; 3]>,
}

impl<'a> CageInput<'a> {
    /// Prepares `input` (any soup).
    pub fn new(input: &'a TriMesh) -> CageInput<'a> {
        let positions = input.positions();
        let tris = input.triangles();
        let degenerate = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                is_collinear(a, b, c)
            })
            .collect();
        CageInput {
            positions,
            tris,
            bvh: TriangleBvh::new(positions, tris),
            degenerate,
            points: referenced_points(positions, tris),
        }
    }

    /// Contact and enclosure of `cage` (see [`CageCheck`]).
    pub fn check(&self, cage: &TriMesh) -> CageCheck {
        self.check_with_progress(cage, &mut |_| true)
            .expect("never cancelled")
    }

    /// [`CageInput::check`] with a progress callback, called on the calling thread between
    /// chunks of [`super::hausdorff::FACES_PER_CHUNK`] cage triangles (contact) and of
    /// `16 ×` that many input vertices (enclosure) with the fraction done; `None` as soon as it
    /// returns `false`. The result is the same as [`CageInput::check`]'s: each
    /// property is an "any" / "all" over independent tests, which the chunking does not change.
    pub fn check_with_progress(
        &self,
        cage: &TriMesh,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<CageCheck> {
        let touches = self.touches_with_progress(cage, &mut |f| keep_going(0.5 * f))?;
        let encloses = self.enclosed_by_with_progress(cage, &mut |f| keep_going(0.5 + 0.5 * f))?;
        Some(CageCheck {
            untouched: !touches,
            encloses,
        })
    }

    /// True when some triangle of `cage` touches or intersects an input triangle (exact).
    pub fn touches(&self, cage: &TriMesh) -> bool {
        self.touches_with_progress(cage, &mut |_| true)
            .expect("never cancelled")
    }

    /// [`CageInput::touches`], in chunks of cage triangles with `keep_going(fraction)` after
    /// each (stops at the first chunk with a contact).
    fn touches_with_progress(
        &self,
        cage: &TriMesh,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<bool> {
        let pos = cage.positions();
        let tris = cage.triangles();
        let chunk = super::hausdorff::FACES_PER_CHUNK;
        for (i, ts) in tris.chunks(chunk).enumerate() {
            let hit = ts.par_iter().any(|t| {
                let tri = t.map(|v| pos[v as usize]);
                self.bvh
                    .query_triangle(&tri)
                    .any(|t| self.meets_triangle(&tri, t as usize))
            });
            if hit {
                return Some(true);
            }
            if !keep_going(((i * chunk + ts.len()) as f64 / tris.len() as f64).min(1.0)) {
                return None;
            }
        }
        Some(false)
    }

    /// True when every referenced input vertex has winding number above 1/2 with respect to
    /// `cage` (accurate away from the cage surface, which the contact test guarantees).
    pub fn enclosed_by(&self, cage: &TriMesh) -> bool {
        self.enclosed_by_with_progress(cage, &mut |_| true)
            .expect("never cancelled")
    }

    /// [`CageInput::enclosed_by`], in chunks of input vertices with `keep_going(fraction)`
    /// after the tree and after each chunk (stops at the first chunk with an outside vertex).
    fn enclosed_by_with_progress(
        &self,
        cage: &TriMesh,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<bool> {
        let fwn = FastWindingNumber::new(cage);
        if !keep_going(0.1) {
            return None;
        }
        let chunk = 16 * super::hausdorff::FACES_PER_CHUNK;
        for (i, ps) in self.points.chunks(chunk).enumerate() {
            if !fwn.winding_numbers(ps).iter().all(|&w| w > 0.5) {
                return Some(false);
            }
            let done = (i * chunk + ps.len()) as f64 / self.points.len() as f64;
            if !keep_going(0.1 + 0.9 * done.min(1.0)) {
                return None;
            }
        }
        Some(true)
    }

    /// The exact minimum distance between the triangles of `cage` and the input's triangles, in
    /// model units (0 on contact; `∞` when either is empty). Not sampled: an upper bound `u`
    /// (the smallest distance from a cage vertex to the input) limits the candidates to the
    /// input triangles whose boxes come within `u` of a cage triangle's box (BVH), and each
    /// candidate pair is decided exactly — 0 when they touch or intersect (exact predicates),
    /// else the minimum of its 6 corner–triangle and 9 edge–edge distances, the closed-form
    /// distance of two disjoint triangles. This is the `min_clearance` of a cage's report.
    pub fn min_distance(&self, cage: &TriMesh) -> f64 {
        self.min_distance_with_progress(cage, &mut |_| true)
            .expect("never cancelled")
    }

    /// [`CageInput::min_distance`] with a progress callback, called on the calling thread
    /// between chunks of [`super::hausdorff::FACES_PER_CHUNK`] cage vertices or triangles with
    /// the fraction done; `None` as soon as it returns `false`. The result is the same bytes
    /// (a minimum, which the chunking does not change).
    pub fn min_distance_with_progress(
        &self,
        cage: &TriMesh,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<f64> {
        let pos = cage.positions();
        let points = referenced_points(pos, cage.triangles());
        let tris = cage.triangles();
        let chunk = super::hausdorff::FACES_PER_CHUNK;
        let total = (points.len() + tris.len()).max(1) as f64;
        let mut upper = f64::INFINITY;
        for (i, ps) in points.chunks(chunk).enumerate() {
            let u = ps
                .par_iter()
                .map(|&p| {
                    self.bvh
                        .closest_point(self.positions, self.tris, p, f64::INFINITY)
                        .map_or(f64::INFINITY, |c| c.distance)
                })
                .reduce(|| f64::INFINITY, f64::min);
            upper = upper.min(u);
            if !keep_going(((i * chunk + ps.len()) as f64 / total).min(1.0)) {
                return None;
            }
        }
        if !upper.is_finite() {
            return Some(upper);
        }
        let mut best = upper;
        for (i, ts) in tris.chunks(chunk).enumerate() {
            let b = ts
                .par_iter()
                .map(|t| self.triangle_gap(&t.map(|v| pos[v as usize]), upper))
                .reduce(|| upper, f64::min);
            best = best.min(b);
            let done = points.len() + i * chunk + ts.len();
            if !keep_going((done as f64 / total).min(1.0)) {
                return None;
            }
        }
        Some(best)
    }

    /// Smallest distance from the cage triangle `tri` to the input, or `upper` if that is
    /// smaller (candidates farther than the running minimum are skipped by their boxes).
    fn triangle_gap(&self, tri: &[[f64; 3]; 3], upper: f64) -> f64 {
        let (lo, hi) = corners_box(tri);
        let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
        let pad = Vec3::splat(upper);
        let tv = tri.map(Vec3::from);
        let mut best = upper;
        for t in self
            .bvh
            .query_box((lo - pad).to_array(), (hi + pad).to_array())
        {
            let corners = self.tris[t as usize].map(|v| self.positions[v as usize]);
            let (clo, chi) = corners_box(&corners);
            let gap = (Vec3::from(clo) - hi)
                .max(lo - Vec3::from(chi))
                .max(Vec3::ZERO)
                .length();
            if gap >= best {
                continue;
            }
            let cv = corners.map(Vec3::from);
            let plane = plane_gap_lower_bound(&tv, &cv);
            if plane >= best && plane > 0.0 {
                continue;
            }
            if self.meets_triangle(tri, t as usize) {
                return 0.0;
            }
            best = best.min(disjoint_triangle_distance(&tv, &cv, 0.0));
        }
        best
    }

    /// Whether the cage triangle `tri` meets input triangle `t`: a triangle–triangle test, or
    /// for a degenerate input triangle a test of each of its edges against `tri`.
    fn meets_triangle(&self, tri: &[[f64; 3]; 3], t: usize) -> bool {
        let corners = self.tris[t].map(|v| self.positions[v as usize]);
        if !self.degenerate[t] {
            return triangles_intersect(tri, &corners);
        }
        (0..3).any(|i| segment_triangle_intersect([corners[i], corners[(i + 1) % 3]], tri))
    }
}

/// Checks that `cage` encloses every vertex of `input` and touches none of its triangles —
/// the verification the cage pipeline runs on its output, usable on any mesh (benchmarks,
/// tests, other cage generators).
pub fn check_cage(cage: &TriMesh, input: &TriMesh) -> CageCheck {
    CageInput::new(input).check(cage)
}

/// The exact minimum distance between `cage` and `input` (see [`CageInput::min_distance`]).
pub fn min_distance(cage: &TriMesh, input: &TriMesh) -> f64 {
    CageInput::new(input).min_distance(cage)
}

/// Clearance between `cage` and `input` in model units: the smallest distance from a
/// referenced vertex of either surface to the other surface (exact BVH distances). It bounds
/// the true surface-to-surface gap from above (equal when the closest pair of points involves a
/// vertex); `0` means contact at a vertex, `∞` when either surface is empty.
pub fn clearance(cage: &TriMesh, input: &TriMesh) -> f64 {
    let cage_to_input = vertices_to_surface(cage, input);
    let input_to_cage = vertices_to_surface(input, cage);
    cage_to_input.min(input_to_cage)
}

/// Smallest distance from a referenced vertex of `from` to the surface `to`.
fn vertices_to_surface(from: &TriMesh, to: &TriMesh) -> f64 {
    let bvh = TriangleBvh::new(to.positions(), to.triangles());
    referenced_points(from.positions(), from.triangles())
        .par_iter()
        .map(|&p| {
            bvh.closest_point(to.positions(), to.triangles(), p, f64::INFINITY)
                .map_or(f64::INFINITY, |c| c.distance)
        })
        .reduce(|| f64::INFINITY, f64::min)
}

/// The vertices used by at least one triangle, in index order.
fn referenced_points(positions: &[[f64; 3]], tris: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut used = vec![false; positions.len()];
    for t in tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    (0..positions.len())
        .filter(|&v| used[v])
        .map(|v| positions[v])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Axis-aligned cube `[o, o + s]³`, outward oriented.
    fn cube(s: f64, o: f64) -> TriMesh {
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

    #[test]
    fn nested_cubes() {
        let inner = cube(1.0, 0.0);
        let outer = cube(3.0, -1.0);
        let c = check_cage(&outer, &inner);
        assert!(c.is_cage());
        assert_eq!(clearance(&outer, &inner), 1.0);
        // The inner cube does not enclose the outer one.
        assert!(!check_cage(&inner, &outer).encloses);
        // Touching counts as contact.
        let touching = cube(2.0, 0.0);
        assert!(!check_cage(&touching, &inner).untouched);
        assert_eq!(clearance(&touching, &inner), 0.0);
        assert_eq!(min_distance(&touching, &inner), 0.0);
        assert_eq!(min_distance(&outer, &inner), 1.0);
    }

    /// The exact gap is found where vertex distances overestimate it: a cage triangle whose
    /// bottom edge passes 0.25 above the unit cube's top face, all corners far from it.
    #[test]
    fn exact_gap_not_vertex_samples() {
        let inner = cube(1.0, 0.0);
        let outer = TriMesh::new(
            vec![[-5.0, 0.5, 1.25], [5.0, 0.5, 1.25], [0.0, 0.5, 9.0]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let exact = min_distance(&outer, &inner);
        assert!((exact - 0.25).abs() < 1e-15, "{exact}");
        assert!(clearance(&outer, &inner) > 0.25 + 1e-3);
    }
}
