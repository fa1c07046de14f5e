//! Irregular Delaunay meshing of a flat panel to a target vertex count (A.6.1, S:2254–2258;
//! spec "Algorithm" 1): TFT results depend on the mesh, and symmetric or direction-biased
//! meshes bias them (S:698), so panels are meshed irregularly.
//!
//! [`mesh_polygon`]: a polygon (outer ring, optional holes) → rest vertices and triangles.
//! 1. **Boundary samples**: every polygon edge split uniformly into `⌈length/d⌉` segments
//!    (corners kept). Two edges of equal length get samples at the same arc lengths, so
//!    panels sewn along equal edges (the cylinder's seam, two sewn disks) get identical vertex
//!    sets on both sides, as the seams need.
//! 2. **Interior samples**: Poisson-disk dart throwing (a fixed number of candidates per target
//!    vertex, deterministic from `seed`): a candidate is kept when it is at least `d` from
//!    every kept sample and at least `d/2` from every boundary segment. Near-maximal
//!    Poisson-disk sets have no preferred direction (unlike jittered grids) and bounded
//!    circumradii, so their Delaunay triangles have no small angles away from the boundary.
//! 3. The spacing `d` is found by bisection on `log d` so that the vertex count is as close to
//!    the target as the sampling allows (within a few percent for targets ≥ 100).
//! 4. **Constrained Delaunay triangulation** (spade, the CDT already in the tree through
//!    parry) with the boundary segments as constraint edges; triangles outside the polygon or
//!    in a hole (centroid test, even–odd over all rings) dropped; counter-clockwise.
//!
//! Same input (polygon, target, seed) ⇒ same output bytes (no threads, no hashing of addresses).

use crate::{Error, Result};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// A flat panel given by its outline, to be meshed by [`mesh_polygon`].
#[derive(Debug, Clone, PartialEq)]
pub struct PolygonPanel {
    /// The outer boundary (m), a simple polygon, either orientation, not closed (the last
    /// corner connects to the first).
    pub outer: Vec<[f64; 2]>,
    /// Holes: simple polygons strictly inside `outer`, pairwise disjoint.
    pub holes: Vec<Vec<[f64; 2]>>,
    /// The wanted number of vertices (boundary included), ≥ 3.
    pub target_vertices: usize,
    /// Seed of the deterministic interior sampling.
    pub seed: u64,
}

/// The mesh of a [`PolygonPanel`].
#[derive(Debug, Clone, PartialEq)]
pub struct PanelMesh {
    /// Vertex positions in the plane (m); the boundary samples come first, ring by ring (the
    /// outer ring, then each hole), in the order of the given corners.
    pub rest: Vec<[f64; 2]>,
    /// Counter-clockwise triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Number of boundary vertices (the first `boundary_count` of `rest`).
    pub boundary_count: usize,
    /// The sample spacing `d` (m) that was used.
    pub spacing: f64,
}

/// Upper bound on `target_vertices` (a coarse-mesh method: 10⁶ is far beyond its use).
pub const MAX_TARGET_VERTICES: usize = 1_000_000;

/// Candidates thrown per target vertex by the dart throwing (near-maximal packing).
const CANDIDATES_PER_VERTEX: usize = 40;

/// Meshes `panel` (module docs). Errors ([`Error::InvalidArgument`]): a ring with fewer than 3
/// corners, a non-finite coordinate, a ring of zero area, a target below 3 or above
/// [`MAX_TARGET_VERTICES`], or a triangulation failure (self-intersecting rings).
pub fn mesh_polygon(panel: &PolygonPanel) -> Result<PanelMesh> {
    validate(panel)?;
    let rings: Vec<&[[f64; 2]]> = std::iter::once(panel.outer.as_slice())
        .chain(panel.holes.iter().map(|h| h.as_slice()))
        .collect();
    let area =
        ring_area(&panel.outer).abs() - panel.holes.iter().map(|h| ring_area(h).abs()).sum::<f64>();
    if area <= 0.0 {
        return Err(bad("holes cover the outer polygon"));
    }
    let Sampling {
        spacing: d,
        points,
        ring_counts,
    } = sample_to_target(&rings, area, panel)?;
    let triangles = constrained_delaunay(&rings, &points, &ring_counts)?;
    let boundary_count = ring_counts.iter().sum();
    Ok(PanelMesh {
        rest: points,
        triangles,
        boundary_count,
        spacing: d,
    })
}

fn bad(msg: impl std::fmt::Display) -> Error {
    Error::InvalidArgument(format!("polygon panel: {msg}"))
}

fn validate(panel: &PolygonPanel) -> Result<()> {
    if panel.target_vertices < 3 || panel.target_vertices > MAX_TARGET_VERTICES {
        return Err(bad(format!(
            "target_vertices must be in [3, {MAX_TARGET_VERTICES}], got {}",
            panel.target_vertices
        )));
    }
    let rings = std::iter::once(&panel.outer).chain(&panel.holes);
    for (k, r) in rings.enumerate() {
        let name = if k == 0 {
            "polygon".to_string()
        } else {
            format!("holes[{}]", k - 1)
        };
        if r.len() < 3 {
            return Err(bad(format!("{name}: needs at least 3 corners")));
        }
        if r.iter().flatten().any(|x| !x.is_finite()) {
            return Err(bad(format!("{name}: coordinates must be finite")));
        }
        let scale = r
            .iter()
            .flatten()
            .fold(0.0f64, |m, x| m.max(x.abs()))
            .max(f64::MIN_POSITIVE);
        if ring_area(r).abs() <= 1e-12 * scale * scale {
            return Err(bad(format!("{name}: zero area")));
        }
    }
    Ok(())
}

/// Signed area (shoelace), positive when counter-clockwise.
fn ring_area(r: &[[f64; 2]]) -> f64 {
    let n = r.len();
    0.5 * (0..n)
        .map(|i| {
            let (p, q) = (r[i], r[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
}

/// Even–odd point-in-domain test over all rings (outer and holes).
fn inside(rings: &[&[[f64; 2]]], p: [f64; 2]) -> bool {
    let mut c = false;
    for r in rings {
        let n = r.len();
        for i in 0..n {
            let (a, b) = (r[i], r[(i + 1) % n]);
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if p[0] < x {
                    c = !c;
                }
            }
        }
    }
    c
}

/// Distance from `p` to the segment `ab`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let ap = [p[0] - a[0], p[1] - a[1]];
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if l2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (ap[0] - t * ab[0]).hypot(ap[1] - t * ab[1])
}

/// The boundary samples at spacing `d` (module docs, step 1), ring by ring.
fn boundary_samples(rings: &[&[[f64; 2]]], d: f64) -> (Vec<[f64; 2]>, Vec<usize>) {
    let mut out = Vec::new();
    let mut counts = Vec::with_capacity(rings.len());
    for r in rings {
        let before = out.len();
        let n = r.len();
        for i in 0..n {
            let (a, b) = (r[i], r[(i + 1) % n]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let k = (len / d).ceil().max(1.0) as usize;
            for j in 0..k {
                let t = j as f64 / k as f64;
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        counts.push(out.len() - before);
    }
    (out, counts)
}

/// A uniform grid over the bounding box with cells of side `cell`, holding point indices.
struct Grid {
    origin: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(lo: [f64; 2], hi: [f64; 2], cell: f64) -> Grid {
        let nx = (((hi[0] - lo[0]) / cell).ceil() as usize).clamp(1, 4096);
        let ny = (((hi[1] - lo[1]) / cell).ceil() as usize).clamp(1, 4096);
        let cell = cell
            .max((hi[0] - lo[0]) / nx as f64)
            .max((hi[1] - lo[1]) / ny as f64);
        Grid {
            origin: lo,
            cell,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        }
    }

    fn cell_of(&self, p: [f64; 2]) -> (usize, usize) {
        let i = ((p[0] - self.origin[0]) / self.cell).floor().max(0.0) as usize;
        let j = ((p[1] - self.origin[1]) / self.cell).floor().max(0.0) as usize;
        (i.min(self.nx - 1), j.min(self.ny - 1))
    }

    fn insert(&mut self, p: [f64; 2], id: u32) {
        let (i, j) = self.cell_of(p);
        self.cells[j * self.nx + i].push(id);
    }

    /// Whether any stored item within `reach` cells of `p` satisfies `near`.
    fn any_near(&self, p: [f64; 2], reach: usize, mut near: impl FnMut(u32) -> bool) -> bool {
        let (i, j) = self.cell_of(p);
        let (i0, i1) = (i.saturating_sub(reach), (i + reach).min(self.nx - 1));
        let (j0, j1) = (j.saturating_sub(reach), (j + reach).min(self.ny - 1));
        (j0..=j1)
            .any(|jj| (i0..=i1).any(|ii| self.cells[jj * self.nx + ii].iter().any(|&k| near(k))))
    }
}

/// Boundary samples plus Poisson-disk interior samples at spacing `d` (steps 1–2).
fn sample(rings: &[&[[f64; 2]]], d: f64, target: usize, seed: u64) -> (Vec<[f64; 2]>, Vec<usize>) {
    let (mut pts, ring_counts) = boundary_samples(rings, d);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in rings.iter().flat_map(|r| r.iter()) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    // points and boundary segments share one grid of cell d; segments are registered in every
    // cell their bounding box touches (ids ≥ SEG mark segments)
    const SEG: u32 = 1 << 31;
    let segs: Vec<([f64; 2], [f64; 2])> = rings
        .iter()
        .flat_map(|r| (0..r.len()).map(move |i| (r[i], r[(i + 1) % r.len()])))
        .collect();
    let mut grid = Grid::new(lo, hi, d);
    for (s, &(a, b)) in segs.iter().enumerate() {
        let (i0, j0) = grid.cell_of([a[0].min(b[0]), a[1].min(b[1])]);
        let (i1, j1) = grid.cell_of([a[0].max(b[0]), a[1].max(b[1])]);
        for j in j0..=j1 {
            for i in i0..=i1 {
                grid.cells[j * grid.nx + i].push(SEG | s as u32);
            }
        }
    }
    for (k, &p) in pts.iter().enumerate() {
        grid.insert(p, k as u32);
    }
    let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
    let candidates = CANDIDATES_PER_VERTEX * target;
    for c in 0..candidates as u64 {
        let u = 0.5 * (1.0 + hash_unit(seed.wrapping_mul(0x1000_0001) ^ (2 * c)));
        let v = 0.5 * (1.0 + hash_unit(seed.wrapping_mul(0x1000_0001) ^ (2 * c + 1)));
        let p = [lo[0] + u * w, lo[1] + v * h];
        if !inside(rings, p) {
            continue;
        }
        let blocked = grid.any_near(p, 1, |id| {
            if id & SEG != 0 {
                let (a, b) = segs[(id & !SEG) as usize];
                segment_distance(p, a, b) < 0.5 * d
            } else {
                let q = pts[id as usize];
                (p[0] - q[0]).hypot(p[1] - q[1]) < d
            }
        });
        if !blocked {
            grid.insert(p, pts.len() as u32);
            pts.push(p);
        }
    }
    (pts, ring_counts)
}

/// The samples at one spacing: boundary samples first (ring by ring), then the interior.
struct Sampling {
    spacing: f64,
    points: Vec<[f64; 2]>,
    ring_counts: Vec<usize>,
}

/// Bisection on `log d` for the vertex count closest to the target (step 3).
fn sample_to_target(rings: &[&[[f64; 2]]], area: f64, panel: &PolygonPanel) -> Result<Sampling> {
    let target = panel.target_vertices;
    let d0 = (area / target as f64).sqrt();
    let perimeter: f64 = rings
        .iter()
        .map(|r| {
            (0..r.len())
                .map(|i| {
                    let (a, b) = (r[i], r[(i + 1) % r.len()]);
                    (b[0] - a[0]).hypot(b[1] - a[1])
                })
                .sum::<f64>()
        })
        .sum();
    let (mut lo, mut hi) = ((0.2 * d0).ln(), (5.0 * d0).max(perimeter).ln());
    let mut best: Option<(usize, Sampling)> = None;
    for _ in 0..40 {
        let d = (0.5 * (lo + hi)).exp();
        let (pts, counts) = sample(rings, d, target, panel.seed);
        let err = pts.len().abs_diff(target);
        if best.as_ref().is_none_or(|b| err < b.0) {
            best = Some((
                err,
                Sampling {
                    spacing: d,
                    points: pts.clone(),
                    ring_counts: counts,
                },
            ));
        }
        if pts.len() > target {
            lo = d.ln();
        } else {
            hi = d.ln();
        }
        if err == 0 || hi - lo < 1e-4 {
            break;
        }
    }
    best.map(|b| b.1).ok_or_else(|| bad("sampling failed"))
}

/// The constraint edges `(min, max)` of the boundary rings, sorted.
fn ring_edges(ring_counts: &[usize]) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    let mut start = 0;
    for &len in ring_counts {
        for i in 0..len {
            let (a, b) = ((start + i) as u32, (start + (i + 1) % len) as u32);
            out.push((a.min(b), a.max(b)));
        }
        start += len;
    }
    out.sort_unstable();
    out
}

/// Which triangles of the CDT lie in the domain: flood fill across non-constraint edges from
/// the triangles touching an interior sample (interior samples lie in the domain, at least
/// `d/2` from the boundary, and no triangle crosses a constraint edge). Robust where a
/// centroid test is not (slivers of collinear boundary samples inside a hole). Without
/// interior samples, the seeds are the triangles whose centroid is inside.
fn faces_inside(
    rings: &[&[[f64; 2]]],
    points: &[[f64; 2]],
    tris: &[[u32; 3]],
    boundary_count: usize,
    constraints: &[(u32, u32)],
) -> Vec<bool> {
    let mut by_edge: Vec<((u32, u32), usize)> = Vec::with_capacity(3 * tris.len());
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge.push(((a.min(b), a.max(b)), f));
        }
    }
    by_edge.sort_unstable();
    let mut keep = vec![false; tris.len()];
    let mut stack: Vec<usize> = (0..tris.len())
        .filter(|&f| tris[f].iter().any(|&v| v as usize >= boundary_count))
        .collect();
    if stack.is_empty() {
        stack = (0..tris.len())
            .filter(|&f| {
                let c = tris[f].map(|v| points[v as usize]);
                inside(
                    rings,
                    [
                        (c[0][0] + c[1][0] + c[2][0]) / 3.0,
                        (c[0][1] + c[1][1] + c[2][1]) / 3.0,
                    ],
                )
            })
            .collect();
    }
    for &f in &stack {
        keep[f] = true;
    }
    while let Some(f) = stack.pop() {
        let t = tris[f];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = (a.min(b), a.max(b));
            if constraints.binary_search(&e).is_ok() {
                continue;
            }
            let lo = by_edge.partition_point(|x| x.0 < e);
            for &(ee, g) in &by_edge[lo..] {
                if ee != e {
                    break;
                }
                if !keep[g] {
                    keep[g] = true;
                    stack.push(g);
                }
            }
        }
    }
    keep
}

/// Constrained Delaunay triangulation of `points` (boundary samples first, ring by ring) with
/// the boundary segments as constraints; triangles outside the domain dropped (step 4).
fn constrained_delaunay(
    rings: &[&[[f64; 2]]],
    points: &[[f64; 2]],
    ring_counts: &[usize],
) -> Result<Vec<[u32; 3]>> {
    // constraint edges: consecutive boundary samples of each ring, closing each ring
    let mut edges = Vec::new();
    let mut start = 0;
    for &len in ring_counts {
        for i in 0..len {
            edges.push([start + i, start + (i + 1) % len]);
        }
        start += len;
    }
    let verts: Vec<Point2<f64>> = points.iter().map(|p| Point2::new(p[0], p[1])).collect();
    let mut conflict = false;
    let cdt =
        ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(verts, edges, |_| {
            conflict = true
        })
        .map_err(|e| bad(format!("triangulation failed: {e:?}")))?;
    if conflict || cdt.num_vertices() != points.len() {
        return Err(bad(
            "boundary rings intersect themselves or each other (or repeat a corner)",
        ));
    }
    let all: Vec<[u32; 3]> = cdt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    let boundary_count: usize = ring_counts.iter().sum();
    let keep = faces_inside(
        rings,
        points,
        &all,
        boundary_count,
        &ring_edges(ring_counts),
    );
    let tris: Vec<[u32; 3]> = all
        .into_iter()
        .zip(keep)
        .filter_map(|(t, k)| k.then_some(t))
        .collect();
    Ok(tris)
}

/// A deterministic value in [−1, 1) from an integer (splitmix64).
pub(crate) fn hash_unit(k: u64) -> f64 {
    let mut z = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(target: usize) -> PolygonPanel {
        PolygonPanel {
            outer: vec![[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]],
            holes: vec![],
            target_vertices: target,
            seed: 7,
        }
    }

    fn angle_at(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        (u[0] * v[1] - u[1] * v[0])
            .atan2(u[0] * v[0] + u[1] * v[1])
            .abs()
    }

    /// Vertex count within 10% of the target, counter-clockwise non-degenerate triangles
    /// (smallest angle > 10°), total area = polygon area, every vertex used.
    fn check_basic(panel: &PolygonPanel, m: &PanelMesh, area: f64) {
        let n = m.rest.len();
        let t = panel.target_vertices;
        assert!(n.abs_diff(t) * 10 <= t, "{n} vertices for a target of {t}");
        let mut used = vec![false; n];
        let mut total = 0.0;
        let mut min_angle = f64::INFINITY;
        for tri in &m.triangles {
            let [a, b, c] = tri.map(|i| m.rest[i as usize]);
            let cr = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(cr > 0.0, "triangle {tri:?} not counter-clockwise");
            total += 0.5 * cr;
            min_angle = min_angle
                .min(angle_at(a, b, c))
                .min(angle_at(b, c, a))
                .min(angle_at(c, a, b));
            for &i in tri {
                used[i as usize] = true;
            }
        }
        assert!((total - area).abs() < 1e-9 * area, "area {total} vs {area}");
        assert!(used.iter().all(|&u| u), "an unused vertex");
        assert!(
            min_angle.to_degrees() > 10.0,
            "min angle {}",
            min_angle.to_degrees()
        );
    }

    /// Every edge shared by two triangles is locally Delaunay: the two opposite angles sum to
    /// at most π (the boundary is the only constraint, so the CDT is Delaunay inside).
    fn check_delaunay(m: &PanelMesh) {
        let mut by_edge = std::collections::BTreeMap::new();
        for (f, t) in m.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                by_edge
                    .entry((a.min(b), a.max(b)))
                    .or_insert_with(Vec::new)
                    .push((f, t[(k + 2) % 3]));
            }
        }
        for (&(a, b), fs) in &by_edge {
            assert!(fs.len() <= 2, "non-manifold edge");
            if fs.len() == 2 {
                let [pa, pb] = [a, b].map(|i| m.rest[i as usize]);
                let s: f64 = fs
                    .iter()
                    .map(|&(_, o)| angle_at(m.rest[o as usize], pa, pb))
                    .sum();
                assert!(
                    s <= std::f64::consts::PI + 1e-9,
                    "edge ({a},{b}) not Delaunay"
                );
            }
        }
    }

    #[test]
    fn rectangle_meets_target_count_delaunay_and_quality() {
        for target in [50, 300, 700, 1300] {
            let p = square(target);
            let m = mesh_polygon(&p).unwrap();
            check_basic(&p, &m, 2.0);
            check_delaunay(&m);
        }
    }

    #[test]
    fn boundary_is_kept_with_equal_samples_on_equal_edges() {
        let m = mesh_polygon(&square(700)).unwrap();
        // every boundary sample lies on the outline, corners included
        for c in [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]] {
            assert!(m.rest[..m.boundary_count].contains(&c));
        }
        let on_outline = |p: [f64; 2]| p[0] == 0.0 || p[0] == 2.0 || p[1] == 0.0 || p[1] == 1.0;
        assert!(m.rest[..m.boundary_count].iter().all(|&p| on_outline(p)));
        assert!(m.rest[m.boundary_count..].iter().all(|&p| !on_outline(p)));
        // boundary edges of the mesh are exactly the consecutive boundary samples
        let mut count = std::collections::BTreeMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let boundary: Vec<_> = count
            .iter()
            .filter(|(_, &c)| c == 1)
            .map(|(e, _)| *e)
            .collect();
        assert_eq!(boundary.len(), m.boundary_count);
        let nb = m.boundary_count as u32;
        for (a, b) in boundary {
            assert!(
                b < nb && (b == a + 1 || (a == 0 && b == nb - 1)),
                "edge {a}-{b}"
            );
        }
        // left and right edges (equal length) have the same sample heights
        let mut left: Vec<f64> = m
            .rest
            .iter()
            .filter(|p| p[0] == 0.0)
            .map(|p| p[1])
            .collect();
        let mut right: Vec<f64> = m
            .rest
            .iter()
            .filter(|p| p[0] == 2.0)
            .map(|p| p[1])
            .collect();
        left.sort_by(f64::total_cmp);
        right.sort_by(f64::total_cmp);
        assert_eq!(left.len(), right.len());
        for (l, r) in left.iter().zip(&right) {
            assert!((l - r).abs() < 1e-12);
        }
    }

    #[test]
    fn annulus_with_hole_and_nonconvex_polygon() {
        let n = 24;
        let ring = |r: f64| -> Vec<[f64; 2]> {
            (0..n)
                .map(|i| {
                    let t = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
                    [r * t.cos(), r * t.sin()]
                })
                .collect()
        };
        let p = PolygonPanel {
            outer: ring(0.1),
            holes: vec![ring(0.04)],
            target_vertices: 400,
            seed: 1,
        };
        let m = mesh_polygon(&p).unwrap();
        let area = ring_area(&p.outer) - ring_area(&p.holes[0]);
        check_basic(&p, &m, area);
        check_delaunay(&m);
        // an L shape (non-convex)
        let l = PolygonPanel {
            outer: vec![
                [0.0, 0.0],
                [2.0, 0.0],
                [2.0, 1.0],
                [1.0, 1.0],
                [1.0, 2.0],
                [0.0, 2.0],
            ],
            holes: vec![],
            target_vertices: 300,
            seed: 3,
        };
        let m = mesh_polygon(&l).unwrap();
        check_basic(&l, &m, 3.0);
    }

    #[test]
    fn same_input_same_mesh_and_bad_input_errors() {
        let a = mesh_polygon(&square(200)).unwrap();
        let b = mesh_polygon(&square(200)).unwrap();
        assert_eq!(a, b);
        let mut other = square(200);
        other.seed = 8;
        assert_ne!(mesh_polygon(&other).unwrap().rest, a.rest);
        let mut p = square(200);
        p.outer[1][0] = f64::NAN;
        assert!(mesh_polygon(&p).is_err());
        let mut p = square(2);
        assert!(mesh_polygon(&p).is_err());
        p = square(100);
        p.outer.truncate(2);
        assert!(mesh_polygon(&p).is_err());
        // a bow tie intersects itself
        let bow = PolygonPanel {
            outer: vec![[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]],
            holes: vec![],
            target_vertices: 50,
            seed: 0,
        };
        assert!(mesh_polygon(&bow).is_err());
    }
}
