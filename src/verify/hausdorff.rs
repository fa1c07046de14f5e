//! Sampled Hausdorff distances (Metro-style, Cignoni et al. 1998) between any two triangle
//! soups: the error a LOD reports, and the floor of that error set by the offset stage.
//!
//! # Sampling density
//! A surface is sampled at all its referenced vertices plus, on every triangle of nonzero area
//! (exactly collinear corners are skipped, as area-weighted sampling would), a regular
//! barycentric grid with `k = clamp(⌈longest edge / spacing⌉, 1, 32)` subdivisions per edge
//! (`(k+1)(k+2)/2` points, corners included once via the vertices; the centroid is always
//! added), with `spacing = l / `[`SAMPLES_PER_DIAGONAL`] and `l` the input's bounding-box
//! diagonal. Each sample's exact distance to the other surface comes from a BVH closest-point
//! query — skipped for a face sample whose 1-Lipschitz upper bound (from its face's corners
//! and the last sample queried) cannot raise the maximum already found, which leaves the
//! maximum's bytes unchanged. The two-sided distance is the larger of the
//! two one-sided maxima.
//!
//! The sampler is this module's own (it shares no code with the LOD loop's convergence test).
//!
//! May import: `crate::mesh`, `crate::spatial`, `crate::geom` (never `lowpoly`, `cage` or
//! `wrinkle`).

use rayon::prelude::*;

use crate::geom::Vec3;
use crate::mesh::TriMesh;
use crate::spatial::{is_collinear, TriangleBvh};

/// Samples per bounding-box diagonal of the measurement (spacing `l / 400`).
pub const SAMPLES_PER_DIAGONAL: f64 = 400.0;

/// Cap on the per-edge subdivisions of one triangle.
pub const MAX_SUBDIVISIONS: usize = 32;

/// Two-sided sampled Hausdorff distance (model units) between `output` and `input`: both
/// surfaces sampled at their vertices plus a barycentric grid of spacing `l / 400` (`l` = the
/// input's bounding-box diagonal), see the module docs. This is the `hausdorff` a LOD reports.
/// Works on any two triangle soups, so benchmarks score other simplifiers with the same measure.
pub fn hausdorff_to_input(output: &TriMesh, input: &TriMesh) -> f64 {
    let s = hausdorff_sides(output, input);
    s.input_to_output.max(s.output_to_input)
}

/// The two one-sided distances (model units) whose larger is [`hausdorff_to_input`].
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
    hausdorff_sides_with_progress(output, input, &mut |_| true).expect("never cancelled")
}

/// [`hausdorff_sides`] with a progress callback, called on the calling thread between chunks
/// of samples (about [`FACES_PER_CHUNK`] faces, tens of milliseconds of work) with the
/// fraction done; `None` as soon as it returns `false`. The result is the same bytes as
/// [`hausdorff_sides`]'s: each side is a maximum, which the chunking does not change.
pub fn hausdorff_sides_with_progress(
    output: &TriMesh,
    input: &TriMesh,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Option<HausdorffSides> {
    let input_to_output = one_sided_with(input, &Surface::new(output), input, &mut |f| {
        keep_going(0.5 * f)
    })?;
    if !keep_going(0.5) {
        return None;
    }
    let output_to_input = one_sided_with(output, &Surface::new(input), input, &mut |f| {
        keep_going(0.5 + 0.5 * f)
    })?;
    Some(HausdorffSides {
        input_to_output,
        output_to_input,
    })
}

/// Faces sampled between two progress calls of [`hausdorff_sides_with_progress`]. A face has
/// at most 561 samples (`MAX_SUBDIVISIONS` = 32), typically a few; the vertices go in chunks
/// of `16 ×` this.
pub const FACES_PER_CHUNK: usize = 2048;

/// One-sided sampled distance (model units) from `input` to `surface` (sampling of
/// [`hausdorff_to_input`]). Applied to the offset surface it gives the *floor* of the
/// input-to-output error: input the offset already hides (buried components, cavities and
/// crevices narrower than `2d`) stays hidden through the LOD loop, which keeps its topology.
pub fn input_to_surface(surface: &TriMesh, input: &TriMesh) -> f64 {
    one_sided_with(input, &Surface::new(surface), input, &mut |_| true).expect("never cancelled")
}

/// A triangle set with its BVH.
struct Surface<'a> {
    positions: &'a [[f64; 3]],
    tris: &'a [[u32; 3]],
    bvh: TriangleBvh,
}

impl<'a> Surface<'a> {
    fn new(mesh: &'a TriMesh) -> Surface<'a> {
        let positions = mesh.positions();
        let tris = mesh.triangles();
        Surface {
            positions,
            tris,
            bvh: TriangleBvh::new(positions, tris),
        }
    }

    /// Exact distance from `p` to the surface (∞ when it is empty).
    fn distance(&self, p: Vec3) -> f64 {
        self.bvh
            .closest_point(self.positions, self.tris, p.to_array(), f64::INFINITY)
            .map_or(f64::INFINITY, |c| c.distance)
    }
}

/// Max over the samples of `from` (see the module docs) of the distance to `to`, at the
/// spacing set by `input`'s diagonal; `keep_going(fraction)` between chunks, `None` when it
/// returns `false`.
fn one_sided_with(
    from: &TriMesh,
    to: &Surface<'_>,
    input: &TriMesh,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Option<f64> {
    match one_sided_until(from, to, input, &|_| false, keep_going)? {
        Scan::Max(m) => Some(m),
        Scan::Reached => unreachable!("nothing reaches a bound that is never reached"),
    }
}

/// How a scan of [`one_sided_until`] ended.
enum Scan {
    /// Every sample scanned: their maximum distance.
    Max(f64),
    /// A sample's distance satisfied the `reach` predicate (the scan stopped there).
    Reached,
}

/// [`one_sided_with`] that stops as soon as a sample's distance satisfies `reach` (checked on
/// each face's maximum and each vertex's distance, so a monotone `reach` is checked on every
/// sample). Without a stop, the maximum is the same bytes as [`one_sided_with`]'s (the same
/// samples, the same exact `max`).
///
/// Faster than a query per sample: the vertices are measured first, then a
/// face sample is queried only when an upper bound on its distance could exceed the maximum
/// found before its chunk of faces ([`face_max`]) — a sample it skips is at most that maximum,
/// so the scan's maximum is the same bytes, and (for a monotone `reach`) its stop the same.
fn one_sided_until(
    from: &TriMesh,
    to: &Surface<'_>,
    input: &TriMesh,
    reach: &(dyn Fn(f64) -> bool + Sync),
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Option<Scan> {
    let spacing = input.bbox_diagonal() / SAMPLES_PER_DIAGONAL;
    let from_pos = from.positions();
    let from_tris = from.triangles();
    let mut used = vec![false; from_pos.len()];
    for t in from_tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let total = (from_pos.len() + 16 * from_tris.len()).max(1) as f64;
    let checked = |d: f64| if reach(d) { Err(()) } else { Ok(d) };
    let max_ok = |a: f64, b: f64| Ok(a.max(b));
    let mut done = 0usize;
    let mut m: f64 = 0.0;
    let vertices: Vec<usize> = (0..from_pos.len()).filter(|&v| used[v]).collect();
    // each vertex's distance, for the faces' bounds (∞ for unreferenced vertices)
    let mut vertex_dist = vec![f64::INFINITY; from_pos.len()];
    for chunk in vertices.chunks(16 * FACES_PER_CHUNK) {
        let dists: Result<Vec<f64>, ()> = chunk
            .par_iter()
            .map(|&v| checked(to.distance(Vec3::from(from_pos[v]))))
            .collect();
        let Ok(dists) = dists else {
            return Some(Scan::Reached);
        };
        for (&v, &dist) in chunk.iter().zip(&dists) {
            vertex_dist[v] = dist;
            m = m.max(dist);
        }
        done += chunk.len();
        if !keep_going(done as f64 / total) {
            return None;
        }
    }
    done = from_pos.len();
    for chunk in from_tris.chunks(FACES_PER_CHUNK) {
        let fmax = chunk
            .par_iter()
            .map(|t| checked(face_max(t, from_pos, &vertex_dist, to, spacing, m)))
            .try_reduce(|| 0.0, max_ok);
        let Ok(fmax) = fmax else {
            return Some(Scan::Reached);
        };
        m = m.max(fmax);
        done += 16 * chunk.len();
        if !keep_going(done as f64 / total) {
            return None;
        }
    }
    Some(Scan::Max(m))
}

/// [`hausdorff_sides_with_progress`] that stops as soon as one sample of either side has a
/// distance `x` with `reach(x)`: `Some(None)` then, `Some(Some(sides))` (the same bytes as
/// [`hausdorff_sides_with_progress`]) when no sample does, `None` when cancelled. For a
/// monotone `reach` (`x ≤ y` and `reach(x)` imply `reach(y)`), `Some(None)` means exactly that
/// `reach` holds for the two-sided maximum: a comparison of the measure against a bound is
/// decided without measuring all of it. `output_first`: scan the output→input side first
/// (where the caller expects the stop); the answer does not depend on it.
pub fn hausdorff_sides_unless(
    output: &TriMesh,
    input: &TriMesh,
    reach: &(dyn Fn(f64) -> bool + Sync),
    output_first: bool,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Option<Option<HausdorffSides>> {
    let side = |out_in: bool, keep_going: &mut dyn FnMut(f64) -> bool| {
        if out_in {
            one_sided_until(output, &Surface::new(input), input, reach, keep_going)
        } else {
            one_sided_until(input, &Surface::new(output), input, reach, keep_going)
        }
    };
    let first = side(output_first, &mut |f| keep_going(0.5 * f))?;
    let Scan::Max(first) = first else {
        return Some(None);
    };
    if !keep_going(0.5) {
        return None;
    }
    let second = side(!output_first, &mut |f| keep_going(0.5 + 0.5 * f))?;
    let Scan::Max(second) = second else {
        return Some(None);
    };
    let (input_to_output, output_to_input) = if output_first {
        (second, first)
    } else {
        (first, second)
    };
    Some(Some(HausdorffSides {
        input_to_output,
        output_to_input,
    }))
}

/// The samples of the triangle soup `(pos, tris)` in this module's sampling (module docs) at
/// `spacing`: its referenced vertices in id order, then the interior grid of every nonzero-area
/// triangle in triangle order (at most `max_k` subdivisions per edge). Deterministic.
#[cfg_attr(not(feature = "lod"), allow(dead_code))]
pub(crate) fn surface_samples(
    pos: &[[f64; 3]],
    tris: &[[u32; 3]],
    spacing: f64,
    max_k: usize,
) -> Vec<Vec3> {
    let mut used = vec![false; pos.len()];
    for t in tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    // counted first so that the samples take exactly their bytes (the fit's coverage check
    // holds millions of them; a growing vector would keep up to twice that)
    let grid = |t: &[u32; 3]| {
        let corners = t.map(|v| pos[v as usize]);
        let area = !is_collinear(corners[0], corners[1], corners[2]);
        area.then(|| {
            let tri = corners.map(Vec3::from);
            (resolution(&tri, spacing, max_k), tri)
        })
    };
    let vertices = used.iter().filter(|&&u| u).count();
    let interior: usize = tris
        .iter()
        .filter_map(|t| grid(t).map(|(k, _)| interior_sample_count(k)))
        .sum();
    let mut out: Vec<Vec3> = Vec::with_capacity(vertices + interior);
    out.extend(
        (0..pos.len())
            .filter(|&v| used[v])
            .map(|v| Vec3::from(pos[v])),
    );
    for (k, tri) in tris.iter().filter_map(grid) {
        for_each_interior_sample(&tri, k, |p| out.push(p));
    }
    debug_assert_eq!(out.len(), vertices + interior);
    out
}

/// How many points [`for_each_interior_sample`] gives at resolution `k`.
#[cfg_attr(not(feature = "lod"), allow(dead_code))]
fn interior_sample_count(k: usize) -> usize {
    let k = k.max(1);
    (k + 1) * (k + 2) / 2 - 3 + usize::from(k < 3)
}

/// The maximum distance to `to` over the interior samples of face `t` of `from_pos` that may
/// exceed `floor`: at least every such sample's distance, and `floor` or less when no sample's
/// distance exceeds `floor`. `vertex_dist` holds the distances of `from_pos`'s vertices.
///
/// The distance to a surface is 1-Lipschitz, so a sample `p` is within `dist(q) + |p − q|` of
/// `to` for each corner `q` of `t` and the last sample queried; a sample whose bound (plus a
/// margin of 10⁻⁹ of its size, far beyond the rounding of the distances) is at most
/// `max(floor, the face's maximum so far)` cannot raise the maximum and is not queried (most
/// are skipped: a LOD's samples lie mostly much closer to the input than the Hausdorff distance,
/// a dense input's faces are smaller than the spacing).
fn face_max(
    t: &[u32; 3],
    from_pos: &[[f64; 3]],
    vertex_dist: &[f64],
    to: &Surface<'_>,
    spacing: f64,
    floor: f64,
) -> f64 {
    let corners = t.map(|v| from_pos[v as usize]);
    if is_collinear(corners[0], corners[1], corners[2]) {
        // Zero area: nothing of it is visible, and area-weighted sampling (Metro,
        // the CGAL `compare` tool) never lands on it; its corners are sampled above.
        return 0.0;
    }
    let tri = corners.map(Vec3::from);
    let corner_dist = t.map(|v| vertex_dist[v as usize]);
    let k = resolution(&tri, spacing, MAX_SUBDIVISIONS);
    let mut m: f64 = 0.0;
    let mut last: Option<(Vec3, f64)> = None;
    for_each_interior_sample(&tri, k, |p| {
        let mut bound = (0..3).fold(f64::INFINITY, |b, i| {
            b.min(corner_dist[i] + (p - tri[i]).length())
        });
        if let Some((q, dq)) = last {
            bound = bound.min(dq + (p - q).length());
        }
        let margin = 1e-9 * (bound + p.abs().max_element());
        if bound + margin <= floor.max(m) {
            return;
        }
        let dist = to.distance(p);
        m = m.max(dist);
        last = Some((p, dist));
    });
    m
}

/// Calls `f` at the barycentric grid points of `t` with `k` subdivisions per edge, corners
/// excluded (they are sampled as vertices), plus the centroid when `k < 3`.
fn for_each_interior_sample(t: &[Vec3; 3], k: usize, mut f: impl FnMut(Vec3)) {
    let k = k.max(1);
    for i in 0..=k {
        for j in 0..=(k - i) {
            if i == k || j == k || i + j == 0 {
                continue;
            }
            let u = i as f64 / k as f64;
            let v = j as f64 / k as f64;
            let w = 1.0 - u - v;
            f(t[0] * w + t[1] * u + t[2] * v);
        }
    }
    if k < 3 {
        f((t[0] + t[1] + t[2]) * (1.0 / 3.0));
    }
}

/// Subdivisions per edge so that samples are at most about `spacing` apart, in `[1, max_k]`.
fn resolution(t: &[Vec3; 3], spacing: f64, max_k: usize) -> usize {
    let e = (t[0] - t[1])
        .length()
        .max((t[1] - t[2]).length())
        .max((t[2] - t[0]).length());
    if spacing.is_nan() || spacing <= 0.0 || !e.is_finite() {
        return 1;
    }
    ((e / spacing).ceil() as usize).clamp(1, max_k.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The count `surface_samples` reserves is the number of points the grid gives.
    #[test]
    fn interior_sample_count_matches_the_grid() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for k in 0..40 {
            let mut n = 0;
            for_each_interior_sample(&t, k, |_| n += 1);
            assert_eq!(interior_sample_count(k), n, "k = {k}");
        }
    }

    fn square(z: f64) -> TriMesh {
        TriMesh::new(
            vec![[0., 0., z], [1., 0., z], [1., 1., z], [0., 1., z]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap()
    }

    #[test]
    fn parallel_squares_are_their_gap_apart() {
        let s = hausdorff_sides(&square(0.25), &square(0.0));
        assert_eq!(s.input_to_output, 0.25);
        assert_eq!(s.output_to_input, 0.25);
        assert_eq!(hausdorff_to_input(&square(0.0), &square(0.0)), 0.0);
    }

    /// A bound no sample reaches gives the full measure (same bytes, either side first); one
    /// some sample reaches stops the scan.
    #[test]
    fn a_reached_bound_stops_the_measure() {
        let (a, b) = (square(0.25), square(0.0));
        let full = Some(Some(hausdorff_sides(&a, &b)));
        for first in [false, true] {
            let never = hausdorff_sides_unless(&a, &b, &|x| x > 0.3, first, &mut |_| true);
            assert_eq!(never, full);
            let reached = hausdorff_sides_unless(&a, &b, &|x| x >= 0.25, first, &mut |_| true);
            assert_eq!(reached, Some(None));
        }
    }

    #[test]
    fn progress_sees_every_chunk_and_can_cancel() {
        let (a, b) = (square(0.25), square(0.0));
        let mut calls = Vec::new();
        let s = hausdorff_sides_with_progress(&a, &b, &mut |f| {
            calls.push(f);
            true
        });
        assert_eq!(s, Some(hausdorff_sides(&a, &b)));
        assert!(calls.windows(2).all(|w| w[0] <= w[1]), "{calls:?}");
        assert_eq!(calls.last(), Some(&1.0));
        let mut n = 0;
        let cancelled = hausdorff_sides_with_progress(&a, &b, &mut |_| {
            n += 1;
            n < 2
        });
        assert_eq!((cancelled, n), (None, 2));
    }

    /// A height field `z = 0.05 sin(7x) cos(5y)` on an `n × n` grid of the unit square.
    fn bumpy(n: u32) -> TriMesh {
        let mut pos = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                pos.push([x, y, 0.05 * (7.0 * x).sin() * (5.0 * y).cos()]);
            }
        }
        let at = |i: u32, j: u32| j * (n + 1) + i;
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                tris.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                tris.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        TriMesh::new(pos, tris).unwrap()
    }

    /// The scan that skips samples by their Lipschitz bounds (`face_max`) gives the bytes of
    /// the maximum over every sample of the module's sampling, queried one by one, for fine and
    /// coarse faces on either side.
    #[test]
    fn bounded_scan_is_the_maximum_over_every_sample() {
        let brute = |from: &TriMesh, to: &TriMesh, input: &TriMesh| {
            let spacing = input.bbox_diagonal() / SAMPLES_PER_DIAGONAL;
            let surface = Surface::new(to);
            surface_samples(
                from.positions(),
                from.triangles(),
                spacing,
                MAX_SUBDIVISIONS,
            )
            .into_iter()
            .map(|p| surface.distance(p))
            .fold(0.0, f64::max)
        };
        for (output, input) in [(bumpy(3), bumpy(40)), (square(0.01), bumpy(25))] {
            let s = hausdorff_sides(&output, &input);
            assert_eq!(s.input_to_output, brute(&input, &output, &input));
            assert_eq!(s.output_to_input, brute(&output, &input, &input));
            assert!(s.input_to_output > 0.0 && s.output_to_input > 0.0);
        }
    }

    #[test]
    fn grid_counts() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mut n = 0;
        for_each_interior_sample(&t, 4, |_| n += 1);
        assert_eq!(n, 12);
        assert_eq!(resolution(&t, 0.5, 8), 3);
    }
}
