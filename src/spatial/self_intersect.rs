//! Self-intersections of a triangle soup, with the semantics of CGAL's
//! `Polygon_mesh_processing::self_intersections` / `does_self_intersect` as `meshcheck` applies
//! them to any soup:
//!
//! 1. exactly coincident points are welded first ([`ExactWeld`]), so unwelded seams are not
//!    intersections;
//! 2. degenerate faces (exactly collinear corners, including repeated indices after welding) are
//!    reported separately and take part in no pair;
//! 3. every other pair of faces whose closed bounding boxes meet is tested with
//!    [`faces_intersect`](super::faces_intersect): shared vertex or edge is allowed, anything
//!    more (folded-over neighbours, duplicate faces, touching, crossing, coplanar overlap) is an
//!    intersection (dissertation §4.3.3: "a mesh has intersections when any of its two triangles
//!    overlaps, or any of its two non-adjacent triangles touch or intersect").
//!
//! Broad phase: one [`TriangleBvh`] over the non-degenerate faces, traversed against itself
//! (all pairs of leaves with touching boxes, sorted). Narrow phase: exact predicates, in parallel
//! over the sorted candidates with rayon (an order-preserving filter), so the result does not
//! depend on the number of threads. [`has_self_intersection`] instead queries the tree face by
//! face in parallel and stops at the first hit.

use rayon::prelude::*;

use super::bvh::TriangleBvh;
use super::tritri::{faces_intersect, is_collinear, Point3};
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
    positions: &[Point3],
    triangles: &[[u32; 3]],
) -> SelfIntersections {
    let weld = ExactWeld::compute(positions);
    find_self_intersections_welded(positions, triangles, &weld)
}

/// As [`find_self_intersections_in`] with the exact weld of `positions` already computed.
pub(crate) fn find_self_intersections_welded(
    positions: &[Point3],
    triangles: &[[u32; 3]],
    weld: &ExactWeld,
) -> SelfIntersections {
    let prep = Prepared::new(positions, triangles, weld);
    let pairs = prep
        .bvh
        .self_pairs()
        .into_par_iter()
        .with_min_len(1024)
        .filter(|&(f, g)| prep.intersect(f, g))
        .collect();
    SelfIntersections {
        pairs,
        degenerate: prep.degenerate,
    }
}

/// True when `mesh` has a degenerate face or an intersecting face pair (CGAL's
/// `does_self_intersect`). Stops at the first hit found.
pub fn has_self_intersection(mesh: &TriMesh) -> bool {
    has_self_intersection_in(mesh.positions(), mesh.triangles())
}

/// As [`has_self_intersection`], on raw buffers (indices must be in range).
pub fn has_self_intersection_in(positions: &[Point3], triangles: &[[u32; 3]]) -> bool {
    let prep = Prepared::new(positions, triangles, &ExactWeld::compute(positions));
    !prep.degenerate.is_empty()
        || prep
            .faces
            .par_iter()
            .with_min_len(256)
            .any(|&f| prep.any_partner(f))
}

/// Indices of the faces of `triangles` whose corners are exactly collinear, sorted.
pub fn degenerate_faces(positions: &[Point3], triangles: &[[u32; 3]]) -> Vec<u32> {
    (0..triangles.len() as u32)
        .into_par_iter()
        .filter(|&f| is_degenerate(positions, triangles[f as usize]))
        .collect()
}

#[inline]
fn is_degenerate(positions: &[Point3], t: [u32; 3]) -> bool {
    let [a, b, c] = t.map(|v| positions[v as usize]);
    is_collinear(a, b, c)
}

/// Welded faces, degenerate/non-degenerate split and the BVH of the non-degenerate faces.
struct Prepared<'a> {
    positions: &'a [Point3],
    welded: Vec<[u32; 3]>,
    faces: Vec<u32>,
    degenerate: Vec<u32>,
    bvh: TriangleBvh,
}

impl<'a> Prepared<'a> {
    fn new(positions: &'a [Point3], triangles: &[[u32; 3]], weld: &ExactWeld) -> Self {
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
        let bvh = TriangleBvh::from_subset(positions, &welded, &faces);
        Prepared {
            positions,
            welded,
            faces,
            degenerate,
            bvh,
        }
    }

    fn corners(&self, f: u32) -> [Point3; 3] {
        self.welded[f as usize].map(|v| self.positions[v as usize])
    }

    /// Whether faces `f` and `g` (both non-degenerate) intersect.
    fn intersect(&self, f: u32, g: u32) -> bool {
        faces_intersect(
            self.positions,
            self.welded[f as usize],
            self.welded[g as usize],
        )
    }

    fn any_partner(&self, f: u32) -> bool {
        let tf = self.welded[f as usize];
        self.bvh
            .query_triangle(&self.corners(f))
            .any(|g| g > f && faces_intersect(self.positions, tf, self.welded[g as usize]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(p: Vec<Point3>, t: Vec<[u32; 3]>) -> TriMesh {
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
