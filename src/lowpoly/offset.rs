//! [`offset_surface`]: stage 1 of the LOD pipeline — a watertight, manifold,
//! self-intersection-free, feature-preserving `d`-offset surface of any triangle soup
//! (dissertation §4.3.1, Algorithm 1).
//!
//! Peak memory (measured with the offset benchmark's per-stage VmHWM/VmRSS trace,
//! `PLEAT_BENCH_MEMTRACE=1`): the input's distance structures live throughout; the distance
//! grid is dropped inside the extraction before the patch set is built (see `extract`); the
//! interior test then holds the patch set plus one container's winding-number tree (see
//! `interior`); the flip phases hold the patch set plus the assembled half-edge mesh. On
//! `large_cycloidal_mid16` at n_p = 400 these three peaks are now about 750, 850 and 870 MiB
//! (VmHWM) where they were 1170, 1300 and 1300 MiB.

use std::time::Instant;

use rayon::prelude::*;

use super::distance::{
    band_bricks, band_radius, estimate_bricks, evaluate_band, BandParams, DistanceGrid, GridSpec,
    InputDistance, BRICK_BYTES,
};
use super::extract::{deviation, extract, Crossings, ExtractParams, Mode, PatchSet};
use super::filter::vertices_on_real_curves;
use super::flips::{flip_to_features, FlipCounts};
use super::interior::{visible_components, ComponentBox};
use super::report::{
    ExtractionCounts, FeatureCounts, InteriorCounts, OffsetReport, OffsetStage, OffsetVerification,
};
use crate::mesh::{HalfEdgeMesh, TriMesh};
use crate::report::{Progress, ProgressFn};
use crate::verify::{MeshReport, ReportOptions};
use crate::{Error, Result};

/// How the offset distance `d` is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OffsetDistance {
    /// `d = l / n_p` with `l` the input's bounding-box diagonal and `n_p` the screen size in
    /// pixels covered by that diagonal (dissertation §4.3; default `n_p = 200`).
    ScreenSize(f64),
    /// An explicit `d` in model units (`> 0`).
    Absolute(f64),
}

/// Parameters of [`offset_surface`]. Start from [`OffsetParams::default`].
#[derive(Debug, Clone, PartialEq)]
pub struct OffsetParams {
    /// The offset distance (default: screen size 200).
    pub distance: OffsetDistance,
    /// Voxel edge as a multiple of the default `d/√3` (default 1; `< 1` is finer). Values above
    /// 2√3/√3 = 2 can miss thin parts entirely (dissertation Fig. 4.4).
    pub voxel_scale: f64,
    /// Insert feature vertices (eq. 4.2–4.3) to recover sharp creases (default true).
    pub features: bool,
    /// Feature-curve dihedral threshold θ0 in degrees (default 120).
    pub theta0_deg: f64,
    /// Minimum number of edges of a real feature curve, l0 (default 4).
    pub l0: u32,
    /// Drop components that lie inside another one (default true).
    pub remove_interior: bool,
    /// Regula-falsi steps refining each iso-point against the exact distance (default 0).
    pub iso_refinement_steps: u32,
    /// Upper bound on the memory of the distance band and the extraction, in bytes
    /// (default 2 GiB). Inputs that would exceed it fail with `Error::LimitExceeded` before
    /// the expensive work starts.
    pub memory_budget_bytes: u64,
    /// Verify the output with independent checks and record them in
    /// [`OffsetReport::verified`] (default true).
    pub verify: bool,
}

impl Default for OffsetParams {
    fn default() -> Self {
        OffsetParams {
            distance: OffsetDistance::ScreenSize(200.0),
            voxel_scale: 1.0,
            features: true,
            theta0_deg: 120.0,
            l0: 4,
            remove_interior: true,
            iso_refinement_steps: 0,
            memory_budget_bytes: 2 << 30,
            verify: true,
        }
    }
}

/// `d` and `h` of a validated parameter set.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Resolved {
    d: f64,
    h: f64,
}

impl OffsetParams {
    /// Checks every parameter against `mesh` and returns `(d, h)`.
    fn resolve(&self, mesh: &TriMesh) -> Result<Resolved> {
        let d = match self.distance {
            OffsetDistance::ScreenSize(np) => {
                if !(np.is_finite() && np > 0.0) {
                    return crate::invalid_arg!("screen size n_p must be finite and > 0, got {np}");
                }
                let l = mesh.bbox_diagonal();
                if l.is_nan() || l <= 0.0 {
                    return crate::invalid_arg!(
                        "the input's bounding-box diagonal is 0 (a point): pass an explicit \
                         OffsetDistance::Absolute"
                    );
                }
                l / np
            }
            OffsetDistance::Absolute(d) => d,
        };
        if !(d.is_finite() && d > 0.0) {
            return crate::invalid_arg!("offset distance d must be finite and > 0, got {d}");
        }
        if !(self.voxel_scale.is_finite() && self.voxel_scale > 0.0) {
            return crate::invalid_arg!(
                "voxel_scale must be finite and > 0, got {}",
                self.voxel_scale
            );
        }
        if !(self.theta0_deg.is_finite() && self.theta0_deg > 0.0 && self.theta0_deg < 180.0) {
            return crate::invalid_arg!("theta0_deg must be in (0, 180), got {}", self.theta0_deg);
        }
        if self.iso_refinement_steps > 64 {
            return crate::invalid_arg!("iso_refinement_steps must be at most 64");
        }
        let h = self.voxel_scale * d / 3f64.sqrt();
        Ok(Resolved { d, h })
    }
}

/// Computes the `d`-offset surface of `mesh` (any soup) — see [`offset_surface_with_progress`].
pub fn offset_surface(mesh: &TriMesh, params: &OffsetParams) -> Result<(TriMesh, OffsetReport)> {
    offset_surface_with_progress(mesh, params, &mut |_| true)
}

/// Computes the `d`-offset surface of `mesh`: the `d`-iso-surface of the unsigned distance
/// field (eq. 4.1), extracted with MC33 and feature vertices (eq. 4.2–4.3), with interior
/// components removed. The output is watertight, manifold, consistently oriented (normals
/// away from the input) and, by construction, free of self-intersections; every vertex lies
/// within `[d − h, d + h]` of the input. `progress` is called on this thread between steps
/// and chunks; returning `false` cancels with `Error::Cancelled`.
///
/// Errors: `InvalidArgument` for a bad parameter (non-positive or NaN `n_p`, `d`, scale),
/// `LimitExceeded` when the band would exceed `memory_budget_bytes` (checked before the
/// distance evaluation), `Cancelled`, `OutOfMemory`, and `InvalidMesh` when the offset is
/// empty (cannot happen for a valid mesh and `d > 0`).
pub fn offset_surface_with_progress(
    mesh: &TriMesh,
    params: &OffsetParams,
    progress: &mut ProgressFn<'_>,
) -> Result<(TriMesh, OffsetReport)> {
    offset_surface_admitted(mesh, params, &mut |_| Ok(()), progress)
}

/// What the offset stage has counted when it asks its measured admission ([`Admit`]), each
/// before the allocations that grow with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum OffsetCount {
    /// After the extraction's first pass, beside the distance grid: before the iso-points,
    /// their normals and the patch set.
    Crossings(Crossings),
    /// After the extraction (the grid dropped), before the interior removal's winding-number
    /// hierarchies (one alive at a time, `interior`): the mixed cubes (the patch set's size)
    /// and the template triangles of the largest component (the largest hierarchy).
    Components {
        /// Mixed cubes of the extraction.
        mixed_cubes: u64,
        /// Template triangles of the component with the most.
        largest_component_faces: u64,
    },
    /// After the interior removal, before the feature phases assemble the visible surface.
    Visible {
        /// Mixed cubes of the extraction.
        mixed_cubes: u64,
        /// Template triangles of the visible components.
        visible_faces: u64,
    },
}

/// A measured admission of the offset stage (the memory budget), called with each
/// [`OffsetCount`] in turn: once the band's distances are known and the extraction's first
/// pass has counted the surface's [`Crossings`], then before the interior removal and before
/// the feature phases. Its `Err` (e.g. `LimitExceeded` naming the measured figure) ends the
/// stage there, before the allocation the count predicts; `Ok` continues with what is already
/// computed (the grid, the patch set): nothing is recomputed.
pub(crate) type Admit<'a> = dyn FnMut(OffsetCount) -> Result<()> + 'a;

/// [`offset_surface_with_progress`] with a measured admission `admit` (see [`Admit`]): the
/// same output whenever `admit` returns `Ok`.
pub(crate) fn offset_surface_admitted(
    mesh: &TriMesh,
    params: &OffsetParams,
    admit: &mut Admit<'_>,
    progress: &mut ProgressFn<'_>,
) -> Result<(TriMesh, OffsetReport)> {
    let r = params.resolve(mesh)?;
    let mut stats = OffsetReport {
        d: r.d,
        h: r.h,
        ..OffsetReport::default()
    };
    let band = BandParams {
        d: r.d,
        h: r.h,
        memory_budget: params.memory_budget_bytes,
    };
    check_budget_estimate(mesh, &band)?;
    step(progress, "bvh", 0.0)?;
    let input = stats
        .stages
        .time(OffsetStage::Bvh, || InputDistance::new(mesh));
    let grid = distance_field(mesh, &input, &band, &mut stats, progress)?;
    let xp = ExtractParams {
        d: r.d,
        features: params.features,
        feature_min_spread_deg: CREASE_CANDIDATE_DEG,
        refine_steps: params.iso_refinement_steps,
    };
    let t = Instant::now();
    let grid_bytes = grid.memory_bytes();
    let set = extract(
        grid,
        &input,
        &xp,
        &mut |c| admit(OffsetCount::Crossings(c)),
        &mut |f| {
            progress(Progress {
                stage: "extract",
                fraction: 0.5 + 0.28 * f,
            })
        },
    )?;
    stats
        .stages
        .push(OffsetStage::Extract, t.elapsed().as_secs_f64());
    record_extraction(&mut stats, &set);
    // The extraction holds the grid, the iso-points (key 8 B, position 24 B, normal and
    // closest primitive 32 B) and the packed mixed cubes (8 B) together; after dropping the
    // grid it builds the patch set.
    let transient = set.n_iso as u64 * 64 + set.counts.mixed * 8;
    let mut peak = (grid_bytes + transient).max(transient + patchset_bytes(&set));
    step(progress, "interior", 0.8)?;
    let visible = if params.remove_interior {
        let t = Instant::now();
        let v = visible_patches(&set, admit, &mut stats)?;
        stats
            .stages
            .push(OffsetStage::Interior, t.elapsed().as_secs_f64());
        v
    } else {
        vec![true; set.len()]
    };
    admit(OffsetCount::Visible {
        mixed_cubes: set.counts.mixed,
        visible_faces: (0..set.len())
            .filter(|&p| visible[p])
            .map(|p| template_faces(&set, p))
            .sum(),
    })?;
    step(progress, "features", 0.85)?;
    let (pos, tris) = surface_with_features(&set, &visible, params, r.h, &mut stats)?;
    if tris.is_empty() {
        return Err(Error::InvalidMesh("the offset surface is empty".into()));
    }
    peak = peak.max(patchset_bytes(&set) + mesh_bytes(pos.len(), tris.len()));
    drop(set);
    stats.output_vertices = pos.len() as u64;
    stats.output_triangles = tris.len() as u64;
    stats.peak_memory_bytes = peak;
    let out = TriMesh::new(pos, tris)?;
    if params.verify {
        step(progress, "verify", 0.95)?;
        let t = Instant::now();
        verify(&out, &input, r, &mut stats, progress)?;
        stats
            .stages
            .push(OffsetStage::Verify, t.elapsed().as_secs_f64());
    }
    step(progress, "done", 1.0)?;
    Ok((out, stats))
}

/// Reports progress; `Err(Cancelled)` when the callback says stop.
fn step(progress: &mut ProgressFn<'_>, stage: &str, fraction: f64) -> Result<()> {
    if progress(Progress { stage, fraction }) {
        Ok(())
    } else {
        Err(Error::Cancelled)
    }
}

/// The distance band's area-based size estimate in bytes for `mesh` at offset distance `d`
/// and voxel edge `h`: the figure [`offset_surface`] compares with its budget before any work.
pub(crate) fn band_estimate_bytes(mesh: &TriMesh, d: f64, h: f64) -> f64 {
    let band = BandParams {
        d,
        h,
        memory_budget: u64::MAX,
    };
    estimate_bricks(mesh, &band) * BRICK_BYTES as f64
}

/// Rejects, before any work, bands whose area-based size estimate exceeds the budget.
fn check_budget_estimate(mesh: &TriMesh, band: &BandParams) -> Result<()> {
    let estimate = band_estimate_bytes(mesh, band.d, band.h);
    if estimate > band.memory_budget as f64 {
        return Err(Error::LimitExceeded(format!(
            "the distance band is estimated at {:.0} MiB, over the memory budget of {} MiB; \
             lower the screen size or raise memory_budget_bytes",
            estimate / (1u64 << 20) as f64,
            band.memory_budget >> 20
        )));
    }
    Ok(())
}

/// Band bricks and exact distances (eq. 4.1) at their points.
fn distance_field(
    mesh: &TriMesh,
    input: &InputDistance,
    band: &BandParams,
    stats: &mut OffsetReport,
    progress: &mut ProgressFn<'_>,
) -> Result<DistanceGrid> {
    let (lo, hi) = mesh.bbox();
    let spec = GridSpec::covering(
        lo.into(),
        hi.into(),
        band_radius(band) + 2.0 * band.h,
        band.h,
    )?;
    step(progress, "band", 0.02)?;
    let keys = stats
        .stages
        .time(OffsetStage::Band, || band_bricks(input, &spec, band))?;
    let t = Instant::now();
    let grid = evaluate_band(input, spec, keys, band, &mut |f| {
        progress(Progress {
            stage: "distance",
            fraction: 0.05 + 0.45 * f,
        })
    })?;
    stats
        .stages
        .push(OffsetStage::Distance, t.elapsed().as_secs_f64());
    stats.bricks = grid.keys.len() as u64;
    stats.grid_points = grid.stored_points();
    Ok(grid)
}

/// A patch gets its feature vertex in phase 1 only when two of its iso-point normals (eq. 4.3,
/// exact) differ by at least this angle. A patch on a crease of dihedral angle below θ0 has
/// normals `180° − θ0 = 60°` apart or more; 30° leaves room for the difference between mesh
/// and exact normals. Flat and gently curved patches (most of the surface) keep their template
/// in phase 1, which halves its size; they would have been reverted by the filter anyway.
/// The extraction computes feature vertices for these candidates only, which saves their QP,
/// their projection and their storage (24 + 4 bytes each).
/// Measured at n_p = 100 against fanning every patch: feature vertices kept 332 vs 320
/// (fandisk), 209 vs 181 (homer), 980 vs 975 (truck); output sizes within 0.1%.
const CREASE_CANDIDATE_DEG: f32 = 30.0;

/// Mesh buffers (positions, triangles), as [`TriMesh::into_parts`] returns them.
type MeshParts = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Phase 1: every feature vertex, flips (Algorithm 2), feature filtering; phase 2: real
/// feature vertices only, flips again (§4.3.1). Without features: the MC33 templates.
fn surface_with_features(
    set: &PatchSet,
    visible: &[bool],
    params: &OffsetParams,
    h: f64,
    stats: &mut OffsetReport,
) -> Result<MeshParts> {
    let mode = |p: usize, feature: bool| match (visible[p], feature) {
        (false, _) => Mode::Skip,
        (true, false) => Mode::Template,
        (true, true) => Mode::Feature,
    };
    if !params.features {
        let (pos, tris, _) = stats
            .stages
            .time(OffsetStage::Assemble, || set.assemble(&|p| mode(p, false)));
        return Ok((pos, tris));
    }
    let t = Instant::now();
    // Phase 1 fans only the patches that can straddle a crease: the only ones with a feature
    // vertex (see `CREASE_CANDIDATE_DEG`).
    let (pos, tris, back) = set.assemble(&|p| mode(p, true));
    let cos_sharp = (180.0 - params.theta0_deg).to_radians().cos();
    let (mesh, flips1) = flipped(pos, tris, &back, set, h, Some(cos_sharp))?;
    stats
        .stages
        .push(OffsetStage::Flips, t.elapsed().as_secs_f64());
    let t = Instant::now();
    let real = vertices_on_real_curves(&mesh, params.theta0_deg, params.l0);
    let mut keep = vec![false; set.len()];
    for (v, &id) in back.iter().enumerate() {
        if real[v] {
            if let Some(p) = set.patch_of_feature(id) {
                keep[p] = true;
            }
        }
    }
    drop((mesh, real, back));
    stats
        .stages
        .push(OffsetStage::Filter, t.elapsed().as_secs_f64());
    let t = Instant::now();
    let (pos, tris, back) = set.assemble(&|p| mode(p, keep[p]));
    let (mesh, flips2) = flipped(pos, tris, &back, set, h, None)?;
    stats
        .stages
        .push(OffsetStage::FlipsFiltered, t.elapsed().as_secs_f64());
    stats.features = Some(FeatureCounts {
        flip_candidates: flips1.candidates,
        flips: flips1.flipped,
        flips_refused_geometry: flips1.refused_geometry,
        feature_vertices_kept: keep.iter().filter(|&&k| k).count() as u64,
        flips_filtered: flips2.flipped,
    });
    Ok(mesh.to_trimesh().into_parts())
}

/// Builds the half-edge mesh and runs Algorithm 2 with the patch set's feature vertices.
fn flipped(
    pos: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    back: &[u32],
    set: &PatchSet,
    h: f64,
    sharp_only: Option<f64>,
) -> Result<(HalfEdgeMesh, FlipCounts)> {
    let tm = TriMesh::new(pos, tris)?;
    let mut mesh = HalfEdgeMesh::from_trimesh(&tm)
        .map_err(|e| Error::Internal(format!("offset surface is not manifold: {e}")))?;
    drop(tm);
    let is_feature: Vec<bool> = back
        .iter()
        .map(|&id| set.patch_of_feature(id).is_some())
        .collect();
    let counts = flip_to_features(&mut mesh, &is_feature, h, sharp_only);
    Ok((mesh, counts))
}

fn record_extraction(stats: &mut OffsetReport, set: &PatchSet) {
    let c = &set.counts;
    stats.extraction = ExtractionCounts {
        cells_visited: c.cells,
        cells_mixed: c.mixed,
        patches_disk: c.disks,
        patches_annulus: c.annuli,
        feature_vertices: set
            .feature
            .iter()
            .filter(|&&f| f != super::extract::NONE)
            .count() as u64,
        tunnels_split: c.tunnels_split,
        cells_unseparated: c.unseparated,
        cells_unresolved: c.unresolved,
        iso_points: set.n_iso as u64,
    };
}

fn patchset_bytes(set: &PatchSet) -> u64 {
    (set.positions.len() * 24
        + set.loop_ids.len() * 4
        + set.loop_off.len() * 4
        + set.plain.len() * 3
        + set.plain_off.len() * 4
        + set.first_len.len()
        + set.center.len() * 8
        + set.feature_patch.len() * 4) as u64
}

fn mesh_bytes(nv: usize, nt: usize) -> u64 {
    (nv * 24 + nt * 12) as u64
}

/// Interior removal (Algorithm 1, line 13) on the MC33 template surface, before the feature
/// phase: per patch, whether its component is visible (not inside another component). Asks
/// `admit` with [`OffsetCount::Components`] before the first hierarchy is built.
/// Feature vertices and flips change the surface only inside each patch's polyhedron and each
/// flip's tetrahedron, which no other component enters, so neither components nor
/// containment change afterwards — and invisible components cost no feature work.
fn visible_patches(
    set: &PatchSet,
    admit: &mut Admit<'_>,
    stats: &mut OffsetReport,
) -> Result<Vec<bool>> {
    let (pcomp, n) = set.patch_components();
    let mut counts = InteriorCounts {
        components: n as u64,
        components_removed: 0,
    };
    if n <= 1 {
        stats.interior = Some(counts);
        return Ok(vec![true; set.len()]);
    }
    let mut faces_of = vec![0u64; n];
    for (p, &c) in pcomp.iter().enumerate() {
        faces_of[c as usize] += template_faces(set, p);
    }
    admit(OffsetCount::Components {
        mixed_cubes: set.counts.mixed,
        largest_component_faces: faces_of.iter().copied().max().unwrap_or(0),
    })?;
    drop(faces_of);
    let mut boxes = vec![ComponentBox::empty(crate::geom::Vec3::ZERO); n];
    let mut patches_of: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (p, &c) in pcomp.iter().enumerate() {
        let b = &mut boxes[c as usize];
        if patches_of[c as usize].is_empty() {
            b.sample = set.positions[set.ids(p)[0] as usize];
        }
        patches_of[c as usize].push(p as u32);
        for &v in set.ids(p) {
            b.grow(set.positions[v as usize]);
        }
    }
    let triangles = |c: usize| {
        let mut t = Vec::new();
        for &p in &patches_of[c] {
            set.patch_triangles(p as usize, false, &mut t);
        }
        t
    };
    let keep = visible_components(&set.positions, &boxes, &triangles);
    counts.components_removed = keep.iter().filter(|&&k| !k).count() as u64;
    stats.interior = Some(counts);
    Ok(pcomp.iter().map(|&c| keep[c as usize]).collect())
}

/// Template triangles of patch `p` (what the interior removal's hierarchies and the feature
/// phases' first assembly hold of it).
fn template_faces(set: &PatchSet, p: usize) -> u64 {
    (set.plain_off[p + 1] - set.plain_off[p]) as u64
}

/// Independent checks of the output ([`MeshReport`], code independent of this stage):
/// watertight, manifold, consistently oriented, self-intersection-free; plus the exact
/// distance of every vertex to the input (`|f(v) − d| ≤ h`), in chunks with a progress call
/// (and cancellation point) after each.
fn verify(
    out: &TriMesh,
    input: &InputDistance,
    r: Resolved,
    stats: &mut OffsetReport,
    progress: &mut ProgressFn<'_>,
) -> Result<()> {
    // a progress call per phase and per batch of the self-intersection pass (cancellation points)
    let report = MeshReport::compute_with_progress(out, &ReportOptions::default(), &mut |f| {
        progress(Progress {
            stage: "verify",
            fraction: 0.95 + 0.01 * f,
        })
    })
    .ok_or(Error::Cancelled)?;
    let v = &mut stats.verified;
    v.watertight = Some(report.is_watertight);
    v.manifold = Some(report.is_manifold);
    v.consistently_oriented = Some(report.consistently_oriented);
    v.self_intersection_free = Some(report.self_intersection_free == Some(true));
    step(progress, "verify", 0.96)?;
    let cap = r.d + 4.0 * r.h;
    let positions = out.positions();
    let mut max_dev: f64 = 0.0;
    // chunked so that a cancel is seen between chunks; a maximum, so the same bytes
    for (i, chunk) in positions.chunks(DEVIATION_CHUNK).enumerate() {
        let m = chunk
            .par_iter()
            .map(|&x| deviation(input, x.into(), r.d, cap))
            .reduce(|| 0.0, f64::max);
        max_dev = max_dev.max(m);
        let done = (i * DEVIATION_CHUNK + chunk.len()) as f64 / positions.len() as f64;
        step(progress, "verify", 0.96 + 0.04 * done)?;
    }
    v.vertices_within_h_of_offset = Some(max_dev <= r.h);
    stats.verification = Some(OffsetVerification {
        output_components: report.n_components as u64,
        max_deviation_over_d: max_dev / r.d,
    });
    Ok(())
}

/// Output vertices whose deviation [`verify`] measures between two progress calls.
const DEVIATION_CHUNK: usize = 8192;
