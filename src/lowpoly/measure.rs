//! Sampled Hausdorff distances (Metro-style, Cignoni et al. 1998) and the independent
//! verification of the loop's output.
//!
//! # Sampling density
//! A surface is sampled at all its referenced vertices plus, on every triangle of nonzero area
//! (exactly collinear corners are skipped, as area-weighted sampling would), a regular
//! barycentric grid with `k = clamp(⌈longest edge / spacing⌉, 1, max_k)` subdivisions per edge
//! (`(k+1)(k+2)/2` points, corners included once via the vertices; the centroid is always
//! added). Each sample's exact distance to the other surface comes from a BVH closest-point
//! query. The two-sided distance is the larger of the two one-sided maxima. Spacings:
//! - consecutive rounds of the loop (Alg. 3 line 17): `spacing = d`, `max_k = 8`;
//! - the final reported error: `spacing = l / `[`FINAL_SAMPLES_PER_DIAGONAL`], `max_k = 32`.

use rayon::prelude::*;

use crate::geom::Vec3;
use crate::spatial::closest::{for_each_sample, sample_resolution};

/// A stored point.
type P3 = [f64; 3];
use crate::mesh::TriMesh;
use crate::mesh::{MeshReport, ReportOptions};
use crate::spatial::{FastWindingNumber, TriangleBvh};

/// Samples per bounding-box diagonal of the final Hausdorff measurement (spacing `l / 400`).
pub const FINAL_SAMPLES_PER_DIAGONAL: f64 = 400.0;

/// Cap on the per-edge subdivisions of one triangle in the final measurement.
pub(crate) const FINAL_MAX_SUBDIVISIONS: usize = 32;

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

/// Max over the samples of `from` (see the module docs) of the distance to `to`.
pub(crate) fn one_sided(
    from_pos: &[P3],
    from_tris: &[[u32; 3]],
    to: &Surface,
    spacing: f64,
    max_k: usize,
) -> f64 {
    let mut used = vec![false; from_pos.len()];
    for t in from_tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let vmax = (0..from_pos.len())
        .into_par_iter()
        .filter(|&v| used[v])
        .map(|v| to.distance(from_pos[v]))
        .reduce(|| 0.0, f64::max);
    let fmax = from_tris
        .par_iter()
        .map(|t| {
            let tri = t.map(|v| from_pos[v as usize]);
            if crate::spatial::is_collinear(tri[0], tri[1], tri[2]) {
                // Zero area: nothing of it is visible, and area-weighted sampling (Metro,
                // the CGAL `compare` tool) never lands on it; its corners are sampled above.
                return 0.0;
            }
            let tri = tri.map(Vec3::from);
            let k = sample_resolution(&tri, spacing, max_k);
            let mut m: f64 = 0.0;
            for_each_sample(&tri, k, true, |p| m = m.max(to.distance(p.to_array())));
            m
        })
        .reduce(|| 0.0, f64::max);
    vmax.max(fmax)
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

/// Two-sided sampled Hausdorff distance between `output` and `input`, exactly as the pipeline
/// reports it in `Stats` (`hausdorff`, `hausdorff_rel`): both surfaces sampled at their
/// vertices plus a barycentric grid of spacing `l / 400` (`l` = the input's bounding-box
/// diagonal, at most 32 subdivisions per triangle edge), see the module docs. Works on any two
/// triangle soups, so benchmarks use it to score other simplifiers with the same measure.
pub fn hausdorff_to_input(output: &TriMesh, input: &TriMesh) -> f64 {
    let s = hausdorff_sides(output, input);
    s.input_to_output.max(s.output_to_input)
}

/// The two one-sided distances whose larger is [`hausdorff_to_input`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HausdorffSides {
    /// Farthest input sample from the output: input the output does not cover (buried parts,
    /// cavities closed by the offset, features cut off).
    pub input_to_output: f64,
    /// Farthest output sample from the input: output surface that is not on the input
    /// (bridges over gaps, chords, drift).
    pub output_to_input: f64,
}

/// Both one-sided sampled distances between `output` and `input`, with the sampling of
/// [`hausdorff_to_input`].
pub fn hausdorff_sides(output: &TriMesh, input: &TriMesh) -> HausdorffSides {
    HausdorffSides {
        input_to_output: final_one_sided(input, &Surface::new(output), input),
        output_to_input: final_one_sided(output, &Surface::new(input), input),
    }
}

/// One-sided sampled distance from `input` to `surface` (sampling of [`hausdorff_to_input`]).
/// Applied to the offset surface it gives the *floor* of the input-to-output error: input
/// the offset already hides (buried components, cavities and crevices narrower than `2d`)
/// stays hidden through the loop, since the loop keeps the offset's topology.
pub fn input_to_surface(surface: &TriMesh, input: &TriMesh) -> f64 {
    final_one_sided(input, &Surface::new(surface), input)
}

/// [`one_sided`] from `from` to `to` at the final measurement's sampling (spacing from the
/// input's diagonal `l`).
fn final_one_sided(from: &TriMesh, to: &Surface, input: &TriMesh) -> f64 {
    let spacing = input.bbox_diagonal() / FINAL_SAMPLES_PER_DIAGONAL;
    one_sided(
        from.positions(),
        from.triangles(),
        to,
        spacing,
        FINAL_MAX_SUBDIVISIONS,
    )
}

/// What the independent verification ([`MeshReport`]) found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Verification {
    /// Edge- and vertex-manifold, no repeated-index faces, consistently oriented.
    pub manifold: bool,
    /// Closed and manifold.
    pub watertight: bool,
    /// No two faces intersect beyond their shared vertices/edges (CGAL's rules) and no face is
    /// degenerate.
    pub self_intersection_free: bool,
    /// Number of connected components.
    pub components: usize,
    /// Total Euler characteristic.
    pub euler: i64,
}

/// Verifies watertightness, manifoldness and intersection-freeness of `mesh` with
/// [`MeshReport`], which shares none of the guard's shortcuts.
pub(crate) fn verify(mesh: &TriMesh) -> Verification {
    let r = MeshReport::compute_with(mesh, &ReportOptions::default());
    Verification {
        manifold: r.is_manifold && r.consistently_oriented,
        watertight: r.is_watertight,
        self_intersection_free: r.self_intersection_free == Some(true),
        components: r.n_components,
        euler: r.euler_characteristic_total,
    }
}

/// Cage checks: the mesh touches no input triangle (exact tests on BVH candidates), and every
/// referenced input vertex has winding number above 1/2 with respect to it (hierarchical
/// winding numbers, Barill et al. 2018 — accurate away from the surface, which the no-touch
/// test guarantees). Returns `(untouched, encloses)`.
pub(crate) fn verify_cage(cage: &TriMesh, input: &super::guard::InputModel) -> (bool, bool) {
    let pos = cage.positions();
    let tris = cage.triangles();
    let untouched = !(0..tris.len()).into_par_iter().any(|f| {
        let tri = tris[f].map(|v| pos[v as usize]);
        input.bvh.query_triangle(&tri).any(|t| {
            super::guard::touches_input_triangle(
                &tri,
                &input.triangle(t),
                input.degenerate[t as usize],
            )
        })
    });
    let mut used = vec![false; input.positions.len()];
    for t in &input.tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let points: Vec<P3> = (0..input.positions.len())
        .filter(|&v| used[v])
        .map(|v| input.positions[v])
        .collect();
    let fwn = FastWindingNumber::new(cage);
    let encloses = fwn.winding_numbers(&points).iter().all(|&w| w > 0.5);
    (untouched, encloses)
}
