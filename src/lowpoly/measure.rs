//! The loop's convergence test (Alg. 3 line 17): whether a round moved the surface by more
//! than `ε·l`, by sampled distances between the meshes before and after it.
//!
//! A surface is sampled at its vertices plus, on every triangle, a regular barycentric grid
//! with `k = clamp(⌈longest edge / d⌉, 1, 8)` subdivisions per edge (the centroid always
//! added); each sample's exact distance to the other surface comes from a BVH closest-point
//! query. The reported error of a LOD is measured independently, by
//! `crate::verify::hausdorff`.

use rayon::prelude::*;

use crate::geom::Vec3;
use crate::spatial::closest::{for_each_sample, sample_resolution};

/// A stored point.
type P3 = [f64; 3];
use crate::mesh::TriMesh;
use crate::spatial::TriangleBvh;

/// A triangle set with its BVH.
pub(crate) struct Surface {
    pub positions: Vec<P3>,
    pub tris: Vec<[u32; 3]>,
    pub bvh: TriangleBvh,
}

impl Surface {
    pub fn new(mesh: &TriMesh) -> Surface {
        let positions = mesh.positions().to_vec();
        let tris = mesh.triangles().to_vec();
        let bvh = TriangleBvh::new(&positions, &tris);
        Surface {
            positions,
            tris,
            bvh,
        }
    }

    fn distance(&self, p: P3) -> f64 {
        self.bvh
            .closest_point(&self.positions, &self.tris, p, f64::INFINITY)
            .map_or(f64::INFINITY, |c| c.distance)
    }
}

/// True when some sample of `from` (see the module docs) lies farther than `threshold` from
/// `to`. Stops at the first such sample, so a clearly changed surface costs little.
pub(crate) fn one_sided_exceeds(
    from_pos: &[P3],
    from_tris: &[[u32; 3]],
    to: &Surface,
    spacing: f64,
    max_k: usize,
    threshold: f64,
) -> bool {
    from_tris.par_iter().any(|t| {
        let tri = t.map(|v| from_pos[v as usize]);
        if tri.iter().any(|&p| to.distance(p) > threshold) {
            return true;
        }
        let tri = tri.map(Vec3::from);
        let k = sample_resolution(&tri, spacing, max_k);
        let mut over = false;
        for_each_sample(&tri, k, true, |p| {
            over = over || to.distance(p.to_array()) > threshold;
        });
        over
    })
}
