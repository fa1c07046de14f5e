//! Provenance: which input triangle, at which barycentric coordinates, a point of the LOD
//! surface stands for.
//!
//! A LOD is an offset surface simplified within about `d = l / n_p` of the input, so the input
//! lies within a few `d` of it along its normal. Each query point `p` with unit normal `n` casts
//! the segment `p − e·n … p + e·n` (`e` = [`ProvenanceParams::envelope`]) against the input's
//! triangles (Möller–Trumbore, every triangle whose box meets the segment's box) and takes the
//! hit nearest to `p`; when the segment hits nothing (holes, thin parts seen edge-on), it falls
//! back to the closest point of the input. Ties are broken by the lower triangle index, and the
//! queries run in parallel with rayon but each is independent, so the result does not depend
//! on the thread count.
//!
//! Used by [`Correspondence`](super::Correspondence) (attribute transfer, feature `lod`) and
//! by textured bakes (`crate::bake`, which re-exports this module).

use rayon::prelude::*;

use crate::geom::{normalized, Vec3};
use crate::mesh::TriMesh;
use crate::spatial::TriangleBvh;

/// Parameters of [`provenance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProvenanceParams {
    /// Half-length `e` of the segment cast along the normal, in the mesh's units (finite, > 0).
    /// [`ProvenanceParams::for_screen_size`] gives `3·d`.
    pub envelope: f64,
}

impl ProvenanceParams {
    /// Envelope `3·d` with `d = l / n_p` (`l` the input's bounding-box diagonal): the LOD is
    /// within about `d` of the input (offset distance plus the simplification bound), so three
    /// `d` catch the input below a LOD point with room for the LOD's normal error.
    pub fn for_screen_size(input: &TriMesh, screen_size: f64) -> Self {
        ProvenanceParams {
            envelope: 3.0 * input.bbox_diagonal() / screen_size,
        }
    }
}

/// Where a LOD surface point maps to on the input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Provenance {
    /// Input triangle index.
    pub triangle: u32,
    /// Barycentric coordinates on that triangle (non-negative, sum 1 up to rounding).
    pub bary: [f64; 3],
    /// The input point (`Σ bary_k · corner_k`).
    pub point: [f64; 3],
    /// Distance from the query point to `point`, in the mesh's units.
    pub distance: f64,
    /// True when found by the cast along the normal; false for the closest-point fallback.
    pub by_ray: bool,
}

/// The input with its BVH, for many provenance queries.
pub struct InputIndex<'a> {
    mesh: &'a TriMesh,
    bvh: TriangleBvh,
}

impl<'a> InputIndex<'a> {
    /// Builds the BVH over `mesh`'s triangles.
    pub fn new(mesh: &'a TriMesh) -> Self {
        InputIndex {
            mesh,
            bvh: TriangleBvh::new(mesh.positions(), mesh.triangles()),
        }
    }

    /// The indexed mesh.
    pub fn mesh(&self) -> &TriMesh {
        self.mesh
    }

    /// Provenance of one point `p` with unit normal `n` (see the [module docs](self)); `None`
    /// only for a non-finite query.
    pub fn query(&self, p: Vec3, n: Vec3, params: &ProvenanceParams) -> Option<Provenance> {
        if !p.is_finite() {
            return None;
        }
        if let Some(hit) = self.cast(p, n, params.envelope) {
            return Some(hit);
        }
        self.closest(p)
    }

    /// The closest input point to `p`.
    pub fn closest(&self, p: Vec3) -> Option<Provenance> {
        let pos = self.mesh.positions();
        let c = self
            .bvh
            .closest_point(pos, self.mesh.triangles(), p.to_array(), f64::INFINITY)?;
        let t = c.triangle as usize;
        let bary = barycentric(
            self.mesh.triangle_positions(t).map(Vec3::from),
            Vec3::from(c.point),
        );
        Some(Provenance {
            triangle: c.triangle,
            bary,
            point: c.point,
            distance: c.distance,
            by_ray: false,
        })
    }

    fn cast(&self, p: Vec3, n: Vec3, envelope: f64) -> Option<Provenance> {
        let n = normalized(n)?;
        if !(envelope > 0.0 && envelope.is_finite()) {
            return None;
        }
        // The segment is searched in rings of |s| nearest to `p` first ([0, e/3], then
        // [e/3, 2e/3] on both sides, then [2e/3, e]), each through the BVH boxes of its pieces
        // (slightly enlarged against rounding): smaller boxes meet far fewer triangles than the
        // whole segment's box, and once a hit lies inside the rings searched, no later ring can
        // hold a nearer one. The result is the hit minimising (|s|, triangle) as over the whole
        // segment.
        const RINGS: [f64; 4] = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0];
        let margin = 1e-6 * envelope;
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for k in 0..3 {
            let (r0, r1) = (RINGS[k] * envelope, RINGS[k + 1] * envelope);
            if k == 0 {
                self.cast_piece(p, n, (-r1, r1), margin, envelope, &mut best);
            } else {
                self.cast_piece(p, n, (r0, r1), margin, envelope, &mut best);
                self.cast_piece(p, n, (-r1, -r0), margin, envelope, &mut best);
            }
            if best.is_some_and(|(bs, ..)| bs.abs() < r1 * (1.0 - 1e-9)) {
                break;
            }
        }
        let (s, t, bary) = best?;
        let tri = self.mesh.triangle_positions(t as usize).map(Vec3::from);
        let point = tri[0] * bary[0] + tri[1] * bary[1] + tri[2] * bary[2];
        Some(Provenance {
            triangle: t,
            bary,
            point: point.to_array(),
            distance: s.abs(),
            by_ray: true,
        })
    }

    /// Updates `best` (lexicographic minimum of `(|s|, triangle)`) with the hits of the ray
    /// `p + s·n`, `|s| ≤ envelope`, on the triangles whose boxes meet the box of the piece
    /// `s ∈ [s0, s1]` enlarged by `margin`.
    fn cast_piece(
        &self,
        p: Vec3,
        n: Vec3,
        (s0, s1): (f64, f64),
        margin: f64,
        envelope: f64,
        best: &mut Option<(f64, u32, [f64; 3])>,
    ) {
        let a = p + n * s0;
        let b = p + n * s1;
        let lo = (a.min(b) - Vec3::splat(margin)).to_array();
        let hi = (a.max(b) + Vec3::splat(margin)).to_array();
        for t in self.bvh.query_box(lo, hi) {
            let tri = self.mesh.triangle_positions(t as usize).map(Vec3::from);
            let Some((s, bary)) = ray_triangle(p, n, &tri) else {
                continue;
            };
            if s.abs() > envelope {
                continue;
            }
            let better = match *best {
                None => true,
                Some((bs, bt, _)) => s.abs() < bs.abs() || (s.abs() == bs.abs() && t < bt),
            };
            if better {
                *best = Some((s, t, bary));
            }
        }
    }

    /// [`query`](Self::query) for many points in parallel; `normals[i]` belongs to
    /// `points[i]`. Non-finite queries fall back to triangle 0's first corner with
    /// `distance = ∞`.
    pub fn query_all(
        &self,
        points: &[[f64; 3]],
        normals: &[[f64; 3]],
        params: &ProvenanceParams,
    ) -> Vec<Provenance> {
        points
            .par_iter()
            .zip(normals.par_iter())
            .map(|(&p, &n)| {
                self.query(Vec3::from(p), Vec3::from(n), params)
                    .unwrap_or(Provenance {
                        triangle: 0,
                        bary: [1.0, 0.0, 0.0],
                        point: self.mesh.positions()[self.mesh.triangles()[0][0] as usize],
                        distance: f64::INFINITY,
                        by_ray: false,
                    })
            })
            .collect()
    }
}

/// Provenance of every vertex of `lod` (normals: area-weighted vertex normals of `lod`) on
/// `input`. Deterministic; parallel over vertices.
pub fn provenance(lod: &TriMesh, input: &TriMesh, params: &ProvenanceParams) -> Vec<Provenance> {
    let index = InputIndex::new(input);
    let normals = vertex_normals(lod);
    index.query_all(lod.positions(), &normals, params)
}

/// Area-weighted unit vertex normals (zero for isolated or degenerate vertices).
pub fn vertex_normals(mesh: &TriMesh) -> Vec<[f64; 3]> {
    let mut acc = vec![Vec3::ZERO; mesh.vertex_count()];
    for (t, tri) in mesh.triangles().iter().enumerate() {
        let [a, b, c] = mesh.triangle_positions(t).map(Vec3::from);
        let n = (b - a).cross(c - a);
        for &v in tri {
            acc[v as usize] += n;
        }
    }
    acc.into_iter()
        .map(|n| normalized(n).unwrap_or(Vec3::ZERO).to_array())
        .collect()
}

/// Möller–Trumbore: the line `p + s·n` meets triangle `t` at parameter `s` with barycentric
/// coordinates `bary` (closed triangle, either side).
fn ray_triangle(p: Vec3, n: Vec3, t: &[Vec3; 3]) -> Option<(f64, [f64; 3])> {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let h = n.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s0 = p - t[0];
    let u = s0.dot(h) * inv;
    if !(-1e-12..=1.0 + 1e-12).contains(&u) {
        return None;
    }
    let q = s0.cross(e1);
    let v = n.dot(q) * inv;
    if v < -1e-12 || u + v > 1.0 + 1e-12 {
        return None;
    }
    let s = e2.dot(q) * inv;
    let (u, v) = (u.max(0.0), v.max(0.0));
    let sum = (u + v).max(1.0);
    let (u, v) = (u / sum, v / sum);
    Some((s, [1.0 - u - v, u, v]))
}

/// Barycentric coordinates of `q` with respect to `t`, clamped to the triangle
/// ([`crate::geom::barycentric`], kept here for callers of this module).
pub use crate::geom::barycentric;

#[cfg(test)]
mod tests {
    use super::*;

    fn plane() -> TriMesh {
        TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap()
    }

    #[test]
    fn ray_finds_the_point_below() {
        let m = plane();
        let idx = InputIndex::new(&m);
        let p = idx
            .query(
                Vec3::new(0.7, 0.2, 0.1),
                Vec3::Z,
                &ProvenanceParams { envelope: 0.5 },
            )
            .unwrap();
        assert!(p.by_ray);
        assert_eq!(p.triangle, 0);
        assert!((Vec3::from(p.point) - Vec3::new(0.7, 0.2, 0.0)).length() < 1e-12);
        assert!((p.distance - 0.1).abs() < 1e-12);
    }

    #[test]
    fn falls_back_to_the_closest_point() {
        let m = plane();
        let idx = InputIndex::new(&m);
        let p = idx
            .query(
                Vec3::new(2.0, 0.5, 0.1),
                Vec3::Z,
                &ProvenanceParams { envelope: 0.5 },
            )
            .unwrap();
        assert!(!p.by_ray);
        assert!((Vec3::from(p.point) - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-12);
    }
}
