//! Narrow-band unsigned distance field of a triangle soup (dissertation eq. 4.1).
//!
//! `f(p) = min_{q ∈ M_i} ‖p − q‖` is evaluated exactly (closest point on the soup through a BVH)
//! only at the grid points that can matter for the `d`-iso-surface: a point `p` with
//! `f(p) ≤ d + √3·h` (the band radius) may be a corner of a cube the iso-surface crosses, every
//! other point is "far outside". Points are stored sparsely in 8³ bricks kept in a hash keyed by
//! brick coordinates; a brick exists when its centre is within band radius + brick half-diagonal
//! of some input triangle (found by rasterizing each triangle's dilated AABB), so every grid
//! point within the band lies in an existing brick and memory grows with the surface area, not
//! with the bounding-box volume.
//!
//! Values are clamped to the cap `d + 2h` (strictly above the band radius): a missing point and a
//! far point both read as the cap, which is "outside" (`f ≥ d`). No infinities reach the
//! iso-surface code.
//!
//! Determinism: brick keys are sorted before anything is evaluated or iterated; the hash map is
//! used for lookups only, so its iteration order never reaches the output.
//!
//! Degenerate input triangles (collinear or coincident corners) are kept as the segment or point
//! they really are, so a soup with zero-area faces still has its exact distance field.

use std::collections::HashMap;

use rayon::prelude::*;

use crate::geom::Vec3;
use crate::mesh::TriMesh;
use crate::spatial::closest::{closest_on_nondegenerate_triangle, closest_on_segment};
use crate::spatial::BoxTree;
use crate::{Error, Result};

/// Points per brick edge.
pub(crate) const BRICK: u32 = 8;
/// Points per brick.
pub(crate) const BRICK_POINTS: usize = (BRICK * BRICK * BRICK) as usize;
/// Bytes of one stored brick (values only).
pub(crate) const BRICK_BYTES: u64 = (BRICK_POINTS * std::mem::size_of::<f64>()) as u64;
/// Largest grid extent (points per axis); keeps edge keys in 64 bits.
pub(crate) const MAX_GRID_POINTS: u32 = 1 << 20;

/// One primitive of the input soup, with degenerate triangles reduced to what they are.
#[derive(Debug, Clone, Copy)]
enum Prim {
    Triangle([Vec3; 3]),
    Segment(Vec3, Vec3),
    Point(Vec3),
}

impl Prim {
    fn from_triangle(t: [Vec3; 3]) -> Prim {
        let [a, b, c] = t;
        let n = (b - a).cross(c - a);
        let l2 = (b - a)
            .length_squared()
            .max((c - b).length_squared())
            .max((a - c).length_squared());
        if l2 == 0.0 {
            return Prim::Point(a);
        }
        // Relative sliver test: height/length below ~1e-10 is a segment for distance purposes.
        if n.length_squared() <= 1e-20 * l2 * l2 {
            let (p, q) = longest_edge(a, b, c);
            return Prim::Segment(p, q);
        }
        Prim::Triangle(t)
    }

    /// The primitive's box `(min, max)`.
    fn bbox(&self) -> (Vec3, Vec3) {
        let pts: &[Vec3] = match self {
            Prim::Triangle(t) => t,
            Prim::Segment(a, b) => &[*a, *b],
            Prim::Point(a) => std::slice::from_ref(a),
        };
        let mut lo = pts[0];
        let mut hi = pts[0];
        for p in pts {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    fn closest(&self, p: Vec3) -> Vec3 {
        match *self {
            Prim::Triangle([a, b, c]) => closest_on_nondegenerate_triangle(p, a, b, c),
            Prim::Segment(a, b) => closest_on_segment(p, a, b),
            Prim::Point(a) => a,
        }
    }
}

fn longest_edge(a: Vec3, b: Vec3, c: Vec3) -> (Vec3, Vec3) {
    let e = [(a, b), (b, c), (c, a)];
    let mut best = e[0];
    for &(p, q) in &e[1..] {
        if (q - p).length_squared() > (best.1 - best.0).length_squared() {
            best = (p, q);
        }
    }
    best
}

/// Result of a closest-point query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Closest {
    /// Euclidean distance from the query point.
    pub dist: f64,
    /// The closest point on the input.
    pub point: Vec3,
    /// Index of the input primitive (triangle) it lies on.
    pub prim: u32,
}

/// Exact closest-point queries on an input soup (a `spatial::BoxTree` over our own
/// primitives).
pub(crate) struct InputDistance {
    prims: Vec<Prim>,
    tree: BoxTree,
}

impl InputDistance {
    /// Builds the BVH over every triangle of `mesh` (degenerate ones as segments or points).
    pub(crate) fn new(mesh: &TriMesh) -> InputDistance {
        let prims: Vec<Prim> = (0..mesh.triangle_count())
            .map(|t| Prim::from_triangle(mesh.triangle_positions(t).map(Vec3::from)))
            .collect();
        let tree = BoxTree::new(prims.iter().map(Prim::bbox));
        InputDistance { prims, tree }
    }

    /// Closest input point to `p` if it is closer than `max_dist`.
    pub(crate) fn closest(&self, p: Vec3, max_dist: f64) -> Option<Closest> {
        self.closest_hinted(p, max_dist, None)
    }

    /// Distance from `p` to primitive `i`.
    fn closest_on(&self, i: u32, p: Vec3) -> Option<Closest> {
        let q = self.prims.get(i as usize)?.closest(p);
        Some(Closest {
            dist: p.distance(q),
            point: q,
            prim: i,
        })
    }

    /// [`InputDistance::closest`] seeded with primitive `hint` (typically the closest
    /// primitive of a nearby point): its exact distance bounds the search, so the BVH prunes
    /// everything farther. The result is the same as without the hint up to ties.
    pub(crate) fn closest_hinted(
        &self,
        p: Vec3,
        max_dist: f64,
        hint: Option<u32>,
    ) -> Option<Closest> {
        let seed = hint
            .and_then(|i| self.closest_on(i, p))
            .filter(|c| c.dist < max_dist);
        let bound = seed.map_or(max_dist, |c| c.dist);
        let found = self.tree.nearest(p, bound, |leaf| {
            self.closest_on(leaf, p).map(|c| (c.dist, c))
        });
        found.or(seed)
    }

    /// `min(f(p), max_dist)`.
    pub(crate) fn distance_capped(&self, p: Vec3, max_dist: f64) -> f64 {
        self.closest(p, max_dist).map_or(max_dist, |c| c.dist)
    }

    /// Exact distance from `p` to primitive `i` (brick culling).
    fn prim_distance(&self, i: usize, p: Vec3) -> f64 {
        p.distance(self.prims[i].closest(p))
    }

    fn prim_aabb(&self, i: usize) -> (Vec3, Vec3) {
        self.prims[i].bbox()
    }

    fn len(&self) -> usize {
        self.prims.len()
    }
}

/// The regular grid: point `(i, j, k)` sits at `origin + h·(i, j, k)`, `0 ≤ i < dims[0]`, ….
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GridSpec {
    /// Position of grid point (0, 0, 0).
    pub origin: Vec3,
    /// Voxel edge length.
    pub h: f64,
    /// Number of grid points per axis.
    pub dims: [u32; 3],
}

impl GridSpec {
    /// A grid covering the box `[lo, hi]` padded by `pad` on every side.
    pub(crate) fn covering(lo: Vec3, hi: Vec3, pad: f64, h: f64) -> Result<GridSpec> {
        let origin = lo - Vec3::splat(pad);
        let mut dims = [0u32; 3];
        for k in 0..3 {
            let n = ((hi[k] - lo[k] + 2.0 * pad) / h).ceil() + 2.0;
            if !(n.is_finite() && n < (MAX_GRID_POINTS - 2 * BRICK) as f64) {
                return Err(Error::LimitExceeded(format!(
                    "the grid would need {n:.0} points along axis {k}; at most {} are supported \
                     (lower the screen size or raise the offset distance)",
                    MAX_GRID_POINTS - 2 * BRICK
                )));
            }
            dims[k] = n as u32;
        }
        Ok(GridSpec { origin, h, dims })
    }

    /// Position of grid point `p`.
    #[inline]
    pub(crate) fn point(&self, p: [u32; 3]) -> Vec3 {
        Vec3::new(
            self.origin.x + self.h * p[0] as f64,
            self.origin.y + self.h * p[1] as f64,
            self.origin.z + self.h * p[2] as f64,
        )
    }

    /// Number of bricks per axis.
    fn brick_dims(&self) -> [u32; 3] {
        self.dims.map(|n| n.div_ceil(BRICK))
    }
}

/// Packs brick coordinates (each `< 2^17`) into a sortable key.
#[inline]
pub(crate) fn brick_key(b: [u32; 3]) -> u64 {
    ((b[0] as u64) << 34) | ((b[1] as u64) << 17) | b[2] as u64
}

/// Inverse of [`brick_key`].
#[inline]
pub(crate) fn brick_coords(key: u64) -> [u32; 3] {
    let m = (1u64 << 17) - 1;
    [
        (key >> 34) as u32,
        ((key >> 17) & m) as u32,
        (key & m) as u32,
    ]
}

/// Index of a point inside its brick.
#[inline]
pub(crate) fn local_index(p: [u32; 3]) -> usize {
    ((p[2] % BRICK) * BRICK * BRICK + (p[1] % BRICK) * BRICK + p[0] % BRICK) as usize
}

/// The sparse narrow-band distance field.
pub(crate) struct DistanceGrid {
    /// Grid geometry.
    pub spec: GridSpec,
    /// Value stored for every point outside the band (`d + 2h`).
    pub cap: f64,
    /// Sorted brick keys.
    pub keys: Vec<u64>,
    values: Vec<f64>,
    index: HashMap<u64, u32>,
}

impl DistanceGrid {
    /// `f` at grid point `p` (the cap for points in no brick).
    #[inline]
    pub(crate) fn value(&self, p: [u32; 3]) -> f64 {
        let b = [p[0] / BRICK, p[1] / BRICK, p[2] / BRICK];
        match self.index.get(&brick_key(b)) {
            Some(&i) => self.values[i as usize * BRICK_POINTS + local_index(p)],
            None => self.cap,
        }
    }

    /// Values of brick number `i` (in sorted key order).
    #[inline]
    pub(crate) fn brick_values(&self, i: usize) -> &[f64] {
        &self.values[i * BRICK_POINTS..(i + 1) * BRICK_POINTS]
    }

    /// Position of brick `key` in [`DistanceGrid::keys`], if it exists.
    #[inline]
    pub(crate) fn brick_index(&self, key: u64) -> Option<usize> {
        self.index.get(&key).map(|&i| i as usize)
    }

    /// Number of stored grid points.
    pub(crate) fn stored_points(&self) -> u64 {
        self.keys.len() as u64 * BRICK_POINTS as u64
    }

    /// Bytes held by the field (values, keys, hash).
    pub(crate) fn memory_bytes(&self) -> u64 {
        let n = self.keys.len() as u64;
        n * BRICK_BYTES + n * 8 + n * 24
    }
}

/// What the band construction needs to know.
pub(crate) struct BandParams {
    /// Iso-value `d`.
    pub d: f64,
    /// Voxel edge `h`.
    pub h: f64,
    /// Upper bound on the bytes the field may take.
    pub memory_budget: u64,
}

/// Estimated bricks of the band from the surface area (a quick check before any work).
pub(crate) fn estimate_bricks(mesh: &TriMesh, p: &BandParams) -> f64 {
    let side = BRICK as f64 * p.h;
    let thickness = 2.0 * band_radius(p) / side + 2.0;
    mesh.surface_area() / (side * side) * thickness
}

/// Distance up to which values are exact: `d + √3·h`, with a little slack.
pub(crate) fn band_radius(p: &BandParams) -> f64 {
    p.d + 3f64.sqrt() * p.h * 1.0001
}

/// Finds the bricks of the band (sorted keys). Errors when they exceed the memory budget.
pub(crate) fn band_bricks(
    input: &InputDistance,
    spec: &GridSpec,
    p: &BandParams,
) -> Result<Vec<u64>> {
    let r = band_radius(p);
    let half_diag = 0.5 * (BRICK - 1) as f64 * p.h * 3f64.sqrt();
    let reach = r + half_diag;
    let side = BRICK as f64 * p.h;
    let bdims = spec.brick_dims();
    let budget_bricks = p.memory_budget / BRICK_BYTES.max(1);
    // Candidate (triangle, brick) pairs may not exceed a budget-derived cap either.
    let max_candidates = (p.memory_budget / 8).max(1 << 16) as usize;
    let chunk = 4096;
    let mut all: Vec<u64> = Vec::new();
    for start in (0..input.len()).step_by(chunk) {
        let end = (start + chunk).min(input.len());
        let mut part: Vec<u64> = (start..end)
            .into_par_iter()
            .flat_map_iter(|t| triangle_bricks(input, t, spec, bdims, reach, side))
            .collect();
        part.sort_unstable();
        part.dedup();
        all.extend(part);
        if all.len() > max_candidates {
            all.sort_unstable();
            all.dedup();
            if all.len() > max_candidates {
                return Err(over_budget(all.len() as u64, p.memory_budget));
            }
        }
    }
    all.par_sort_unstable();
    all.dedup();
    if all.len() as u64 > budget_bricks {
        return Err(over_budget(all.len() as u64, p.memory_budget));
    }
    Ok(all)
}

fn over_budget(bricks: u64, budget: u64) -> Error {
    Error::LimitExceeded(format!(
        "the distance band needs at least {} MiB ({} bricks of 8³ points), over the memory \
         budget of {} MiB; lower the screen size or raise memory_budget_bytes",
        bricks * BRICK_BYTES / (1 << 20),
        bricks,
        budget / (1 << 20)
    ))
}

/// Bricks whose centre is within `reach` of primitive `t`.
fn triangle_bricks(
    input: &InputDistance,
    t: usize,
    spec: &GridSpec,
    bdims: [u32; 3],
    reach: f64,
    side: f64,
) -> Vec<u64> {
    let (lo, hi) = input.prim_aabb(t);
    let mut range = [[0u32; 2]; 3];
    for k in 0..3 {
        let a = ((lo[k] - reach - spec.origin[k]) / side).floor().max(0.0);
        let b = ((hi[k] + reach - spec.origin[k]) / side).floor();
        let b = b.min(bdims[k] as f64 - 1.0);
        if a.is_nan() || b.is_nan() || a > b {
            return Vec::new();
        }
        range[k] = [a as u32, b as u32];
    }
    let mut out = Vec::new();
    let centre_offset = 0.5 * (BRICK - 1) as f64 * spec.h;
    for bx in range[0][0]..=range[0][1] {
        for by in range[1][0]..=range[1][1] {
            for bz in range[2][0]..=range[2][1] {
                let c =
                    spec.point([bx * BRICK, by * BRICK, bz * BRICK]) + Vec3::splat(centre_offset);
                if input.prim_distance(t, c) <= reach {
                    out.push(brick_key([bx, by, bz]));
                }
            }
        }
    }
    out
}

/// Evaluates `f` (capped) at every point of the given bricks. `keep_going` is called on the
/// calling thread between chunks with the fraction done; returning `false` cancels.
pub(crate) fn evaluate_band(
    input: &InputDistance,
    spec: GridSpec,
    keys: Vec<u64>,
    p: &BandParams,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<DistanceGrid> {
    let cap = p.d + 2.0 * p.h;
    let mut values = Vec::new();
    values
        .try_reserve_exact(keys.len() * BRICK_POINTS)
        .map_err(|_| Error::OutOfMemory)?;
    let chunk = 256;
    for (ci, ks) in keys.chunks(chunk).enumerate() {
        let part: Vec<f64> = ks
            .par_iter()
            .flat_map_iter(|&k| brick_values(input, &spec, k, cap))
            .collect();
        values.extend_from_slice(&part);
        let done = ((ci + 1) * chunk).min(keys.len()) as f64 / keys.len().max(1) as f64;
        if !keep_going(done) {
            return Err(Error::Cancelled);
        }
    }
    let index = keys
        .iter()
        .enumerate()
        .map(|(i, &k)| (k, i as u32))
        .collect();
    Ok(DistanceGrid {
        spec,
        cap,
        keys,
        values,
        index,
    })
}

/// Capped distances of one brick's points, each query seeded with the closest primitive of
/// the previous point (grid points `h` apart nearly always share it).
fn brick_values(input: &InputDistance, spec: &GridSpec, key: u64, cap: f64) -> Vec<f64> {
    let b = brick_coords(key);
    let mut out = vec![cap; BRICK_POINTS];
    let mut hint = None;
    for z in 0..BRICK {
        for y in 0..BRICK {
            for x in 0..BRICK {
                // Serpentine order keeps consecutive points adjacent.
                let x = if y % 2 == 1 { BRICK - 1 - x } else { x };
                let gp = [b[0] * BRICK + x, b[1] * BRICK + y, b[2] * BRICK + z];
                if gp[0] >= spec.dims[0] || gp[1] >= spec.dims[1] || gp[2] >= spec.dims[2] {
                    continue;
                }
                if let Some(c) = input.closest_hinted(spec.point(gp), cap, hint) {
                    out[local_index(gp)] = c.dist;
                    hint = Some(c.prim);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(mesh: &TriMesh, p: Vec3) -> f64 {
        (0..mesh.triangle_count())
            .map(|t| {
                let q = Prim::from_triangle(mesh.triangle_positions(t).map(Vec3::from)).closest(p);
                p.distance(q)
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn closest_point_matches_brute_force_on_degenerate_soup() {
        let mesh = TriMesh::new(
            vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [0., 1., 0.],
                [2., 2., 2.],
                [3., 3., 3.],
                [4., 4., 4.],
                [-1., 5., 0.],
            ],
            // a triangle, a collinear triangle, a point triangle, a repeated-vertex one
            vec![[0, 1, 2], [3, 4, 5], [6, 6, 6], [0, 0, 3]],
        )
        .unwrap();
        let q = InputDistance::new(&mesh);
        let mut s = 1u64;
        for _ in 0..500 {
            let mut p = [0.0; 3];
            for c in &mut p {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                *c = (s >> 11) as f64 / (1u64 << 53) as f64 * 8.0 - 2.0;
            }
            let p = Vec3::from(p);
            let exact = brute(&mesh, p);
            let got = q.closest(p, f64::INFINITY).unwrap().dist;
            assert!((exact - got).abs() < 1e-12, "{p:?}: {exact} vs {got}");
            assert!(exact.is_finite());
        }
    }

    #[test]
    fn band_holds_every_point_within_radius() {
        let mesh = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.3]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let q = InputDistance::new(&mesh);
        let d = 0.1;
        let h = d / 3f64.sqrt();
        let p = BandParams {
            d,
            h,
            memory_budget: 1 << 30,
        };
        let (lo, hi) = mesh.bbox();
        let spec = GridSpec::covering(Vec3::from(lo), Vec3::from(hi), d + 3.0 * h, h).unwrap();
        let keys = band_bricks(&q, &spec, &p).unwrap();
        assert!(keys.windows(2).all(|w| w[0] < w[1]));
        let grid = evaluate_band(&q, spec, keys, &p, &mut |_| true).unwrap();
        let r = band_radius(&p);
        for i in 0..spec.dims[0] {
            for j in 0..spec.dims[1] {
                for k in 0..spec.dims[2] {
                    let x = spec.point([i, j, k]);
                    let f = brute(&mesh, x);
                    let g = grid.value([i, j, k]);
                    if f <= r {
                        assert!((f - g).abs() < 1e-12);
                    } else {
                        assert!(g > d);
                    }
                }
            }
        }
    }

    #[test]
    fn budget_is_enforced() {
        let mesh = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let q = InputDistance::new(&mesh);
        let d = 0.001;
        let p = BandParams {
            d,
            h: d / 3f64.sqrt(),
            memory_budget: 1 << 20,
        };
        let (lo, hi) = mesh.bbox();
        let spec = GridSpec::covering(Vec3::from(lo), Vec3::from(hi), 3.0 * d, p.h).unwrap();
        assert!(matches!(
            band_bricks(&q, &spec, &p),
            Err(Error::LimitExceeded(_))
        ));
    }
}
