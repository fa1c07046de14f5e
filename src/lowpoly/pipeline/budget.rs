//! The memory budget of a bake (`LodParams::memory_budget_bytes`): the offset voxel scales a
//! LOD may take ([`LOD_VOXEL_SCALES`] and the rule by screen size), the peak-memory estimates
//! (up-front from the input, from the input start, and the measured admission's from the
//! offset stage's counts) with their measured per-item constants, the choice of the finest voxel
//! scale that fits, and the refusals (`LimitExceeded`) before any large allocation. Estimates
//! only: nothing here allocates or changes a bake's output, only whether and at which scale it
//! runs.

use super::params::{LodParams, LodStart, Mode};
use crate::lowpoly::offset::{band_estimate_bytes, OffsetCount};
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// How a refused bake may be allowed more memory, appended to every budget refusal.
pub(crate) const RAISE_THE_BUDGET: &str =
    "; to allow it, raise the budget (`--memory-budget` in the \
    CLI and in batch manifests, `memory_budget_bytes` in C, Python and Rust) or lower the \
    screen size";

/// Voxel scales (multiples of the offset stage's voxel edge `d/√3`, `OffsetParams::voxel_scale`)
/// a LOD's offset surface may use, finest first: from the scale its screen size starts from
/// (1, or [`LOD_VOXEL_SCALE`] from [`LOD_COARSE_VOXEL_MIN_SCREEN_SIZE`] on), the finest whose
/// memory estimate fits `memory_budget_bytes` is taken, so large screen
/// sizes trade offset resolution for memory (offset faces ∝ 1/scale²) instead of being
/// refused. Cages keep scale 1: their offset must enclose the input without contact, and its
/// vertices are only within `[d − h, d + h]` of the input. The largest scale, 2, still has a
/// grid point within `√3·h/2 = d` of every input point, the limit below which no thin part is
/// missed (dissertation Fig. 4.4; `OffsetParams`).
pub const LOD_VOXEL_SCALES: [f64; 5] = [1.0, 1.25, 1.5, 1.75, 2.0];
pub(super) const MAX_LOD_VOXEL_SCALE: f64 = LOD_VOXEL_SCALES[LOD_VOXEL_SCALES.len() - 1];

/// The offset voxel a LOD (not a cage, not `offset_surface`) at a screen size of at least
/// [`LOD_COARSE_VOXEL_MIN_SCREEN_SIZE`] starts from, as a multiple of `d/√3` (for speed,
/// 2026-11-27); below it LODs start from scale 1. The first simplification pass works through
/// every face of the offset surface (∝ 1/scale²) and was ≈ 80% of a bake. Measured against
/// scale 1 (docs/design-notes-lod.md, "Offset stage"): at n_p = 200 on 8 corpus meshes
/// the median CPU time of a bake falls by 49% while LOD faces (−0.3%), Hausdorff distance and
/// shading (normal difference +0.0003 ± 0.001, PSNR +0.03 dB) stay within the per-mesh noise;
/// at n_p = 100 on the whole corpus it falls by 40% but the normal difference grows by
/// 0.0029 ± 0.0011 (18 of 23 meshes, 4.5% fewer faces), beyond the noise — hence the rule.
/// Every output passes CGAL's checker. Scale 2 keeps the offset's guarantees: a grid point
/// within `d` of every input point (Fig. 4.4), vertices within `[d − h, d + h]` of the input;
/// the guard and the final verification are unchanged.
pub const LOD_VOXEL_SCALE: f64 = 2.0;

/// The smallest screen size `n_p` at which a LOD starts from [`LOD_VOXEL_SCALE`] (see there).
pub const LOD_COARSE_VOXEL_MIN_SCREEN_SIZE: f64 = 200.0;

/// The offset voxel a LOD at a screen size in [`LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE`]`..`
/// [`LOD_COARSE_VOXEL_MIN_SCREEN_SIZE`] starts from (for speed, 2026-11-29): 0.64× the
/// offset faces of scale 1, the first simplification pass in proportion. Measured at n_p = 100
/// on the 23 corpus meshes (docs/benchmarks/lod.md, 2026-11-29): with the coarser coverage
/// spacing of the fit (`coverage::SPACING`), median wall 1.09 → 0.69 s (scale 1.5: 0.63 s,
/// scale 2: 0.56 s, with larger per-mesh Hausdorff changes); `run_suite.py --target-from
/// pleat` with MeshLab QEM and meshoptimizer: mean normal difference 0.0807 → 0.0804, PSNR
/// 22.30 → 22.39 dB, silhouette 0.0097 → 0.0092, faces −1.3%, all 23 valid. Only LODs that
/// start from the offset surface change (clean inputs start from themselves).
pub const LOD_MEDIUM_VOXEL_SCALE: f64 = 1.25;

/// The smallest screen size `n_p` at which a LOD starts from [`LOD_MEDIUM_VOXEL_SCALE`].
pub const LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE: f64 = 100.0;

/// Peak bytes per *estimated* offset face ([`LodParams::memory_estimate`]'s face count): the
/// first simplification pass holds the half-edge mesh, the guard's BVH and caches, the pass's
/// quadrics and queue, plus the offset surface kept for an exact rerun and round 0's copy.
/// Measured 2026-11-27 (`examples/lod_memory.rs`): dirty_beetle at n_p = 1000
/// (scale 2, 2.18 M offset faces where the estimate counts 1.58 M: the offset of a thin leg has
/// far more area than twice the leg's) peaked at 1592 MiB (VmHWM), 1056 B per estimated face;
/// with no per-edge target array, the queue filled in chunks and the guard's old BVH freed
/// before a rebuild, at 1195 MiB (VmHWM; 1190 MiB allocated, in the first pass's first BVH
/// rebuild), 793 B per estimated face (900 B then); with the BVH builds streaming their boxes
/// into parry (no 48 B-a-leaf copy during the guard's build and rebuilds) and round 0's
/// convergence reference borrowed from the start surface (2026-11-28), at 1035 MiB allocated
/// (again the first rebuild), 687 B per estimated face (780 B then). With the guard's parry BVH
/// replaced by the compact `spatial::TriTree` (2026-11-28: ≈ 12 B a face instead of ≈ 160 B,
/// and no rebuild workspace), the beetle peaks at 502 MiB allocated (first pass; VmHWM 533 MiB),
/// 333 B per estimated face, the offset stage's interior removal at 424 MiB (281 B), and
/// dirty_truck (5.34 M estimated faces) at 1469 MiB (first pass; 288 B). 400 B bounds the
/// beetle's with a 20% margin (formerly 1100, 900, then 780 B). The measured admission
/// ([`measured_start`]) applies it to the real offset faces: 241 B per real face on the beetle,
/// 235 B on the truck, 232 B on dirty_synth_soup_s1 (913 MiB first pass, 4.13 M faces,
/// 2026-11-29).
const BYTES_PER_WORK_FACE: f64 = 400.0;
/// Peak bytes per mixed cube (a cube of the distance grid the iso-surface crosses, counted by
/// the extraction's first pass over the whole band, buried components included) of the
/// offset stage after that pass: the extraction's iso-points, normals, edge keys and packed
/// cubes beside the distance grid, then the patch set, alive through the interior removal and
/// the feature phases. Used only by the measured admission ([`measured_start`]). Measured
/// 2026-11-29 (counting allocator, n_p = 1000, scale 2): the extraction
/// peaks at 105 B per mixed cube over the grid on dirty_synth_soup_s1 (7.52 M cubes), 78 B on
/// dirty_beetle (1.09 M), 91 B on dirty_teapot (1.68 M), 99 B on dirty_synth_holes_s1
/// (2.20 M); the patch set alive after it is 108, 95, 110 and 117 B. 130 B bounds them
/// (with [`BYTES_PER_SURFACE_FACE`], the feature phases' estimate is 23–39% over their
/// measured peak on these four).
const BYTES_PER_MIXED_CUBE: f64 = 130.0;
/// Peak bytes per template triangle of the offset stage beside its patch set
/// ([`BYTES_PER_MIXED_CUBE`]): the interior removal's winding-number hierarchy (one component
/// at a time, counted on the largest) and the feature phases' assembled and half-edge meshes
/// (counted on the visible components). Used only by the measured admission. Measured
/// 2026-11-29 (as above): the feature phases at 149 B per visible offset face on
/// dirty_synth_soup_s1 (4.13 M) and dirty_beetle (2.18 M), 135 B on dirty_teapot (3.27 M),
/// 144 B on dirty_synth_holes_s1 (4.40 M); the interior removal at 154 B per face of the
/// outer sheet on the beetle, 115 B on the teapot; 200 B bounds them with a 30% margin.
const BYTES_PER_SURFACE_FACE: f64 = 200.0;
/// Peak bytes per input sample of the input-plane fit's coverage check (`coverage.rs`: the
/// input sampled at `SPACING · d`, a budget and a box per sample, the tree over them), which
/// grows like `n_p²` and does not depend on the offset voxel. Measured 2026-11-27:
/// dirty_synth_flipped_s1 at n_p = 1000 (4.09 M samples) peaked at 1920 MiB in the fit with
/// parry's BVH over the samples' boxes (487 B a sample, formerly 500 B here); with the compact
/// `spatial::CubeTree` and the samples' exact allocation (2026-11-28) a sample takes 24 B of
/// position, 8 of budget, 4 of order and ≈ 4 of tree boxes, plus its 8 B Morton code during the
/// build: 48 B, bounded here by 64 B.
pub(super) const BYTES_PER_FIT_SAMPLE: f64 = 64.0;
/// Bytes per *estimated* offset face still alive in the fit (the guard's slot arrays of the
/// dense start, the start surface kept for an exact rerun, the LOD before the fit). Measured
/// 2026-11-27 as the live bytes at the fit's start: 238 MiB on dirty_beetle at n_p = 1000
/// (1.58 M estimated faces: 158 B), 151 MiB on clean_homer, 97 MiB on dirty_synth_flipped_s1.
const BYTES_PER_FIT_WORK_FACE: f64 = 200.0;
/// Per-edge sample cap of the coverage check (`coverage::MAX_SUBDIVISIONS`).
const FIT_MAX_SUBDIVISIONS: f64 = 32.0;

/// Upper bound on the fit's coverage samples of `input` at offset distance `d`: the referenced
/// vertices plus, per triangle, the `(k + 1)(k + 2)/2` barycentric points of resolution
/// `k = ⌈longest edge / (SPACING · d)⌉ ≤ 32` (`verify::hausdorff::surface_samples`).
pub(super) fn fit_samples(input: &TriMesh, d: f64) -> f64 {
    let spacing = crate::lowpoly::coverage::SPACING * d;
    let per_triangle: f64 = (0..input.triangle_count())
        .map(|t| {
            let [a, b, c] = input.triangle_positions(t).map(crate::geom::Vec3::from);
            let e = a.distance(b).max(b.distance(c)).max(c.distance(a));
            let k = (e / spacing).ceil().clamp(1.0, FIT_MAX_SUBDIVISIONS);
            (k + 1.0) * (k + 2.0) / 2.0
        })
        .sum();
    input.vertex_count() as f64 + per_triangle
}

/// Approximate bytes per input face (copy, BVH, flags, reader buffers). Measured 2026-11-27 as
/// the peak RSS of `pleat lod --screen-size 8` (an offset surface of a few hundred faces) less
/// the 8 MB of a tiny input, per input face: 700 B (cad_thingi10k_908460, 36k faces), 680 B
/// (dirty_ogre, 124k), 670 B (large_armadillo_loopA, 600k), 670 B (large_cycloidal_mid16,
/// 694k). With the work term, dirty_ogre at n_p 200 peaks at 205 MB against an estimate of
/// 211 MB (149 MB with the former 200 B).
pub(super) const BYTES_PER_INPUT_FACE: f64 = 700.0;

/// The finest voxel scale a bake in `mode` at `screen_size` starts from: for LODs the caller's
/// `requested` scale (the field `LodParams::offset_voxel_scale`) or else [`LOD_VOXEL_SCALE`] from
/// [`LOD_COARSE_VOXEL_MIN_SCREEN_SIZE`] on, [`LOD_MEDIUM_VOXEL_SCALE`] from
/// [`LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE`] on and 1 below; for cages 1.
fn finest_voxel_scale(mode: Mode, screen_size: f64, requested: Option<f64>) -> f64 {
    let rule = if screen_size >= LOD_COARSE_VOXEL_MIN_SCREEN_SIZE {
        LOD_VOXEL_SCALE
    } else if screen_size >= LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE {
        LOD_MEDIUM_VOXEL_SCALE
    } else {
        1.0
    };
    match mode {
        Mode::Cage => 1.0,
        Mode::Lod => requested.unwrap_or(rule),
    }
}

impl LodParams {
    /// `LimitExceeded` for a LOD whose offset start fits no voxel scale, with the estimate at
    /// the coarsest; `why_not_input` says why the input is not started from, when known.
    pub(super) fn offset_over_budget(&self, input: &TriMesh, why_not_input: Option<&str>) -> Error {
        let est = self.memory_estimate(input, MAX_LOD_VOXEL_SCALE);
        let mib = |b: f64| b / (1u64 << 20) as f64;
        let input_start = match (self.start, why_not_input) {
            (LodStart::Offset, _) => String::new(),
            (_, Some(why)) => format!("; it does not start from the input ({why})"),
            (_, None) => format!(
                "; starting from the input would need about {:.0} MiB",
                mib(self.input_start_estimate(input))
            ),
        };
        Error::LimitExceeded(format!(
            "the bake needs about {:.0} MiB at screen size {} (offset voxel {}× the default) \
             but the memory budget is {:.0} MiB{input_start}{RAISE_THE_BUDGET}",
            mib(est),
            self.screen_size,
            MAX_LOD_VOXEL_SCALE,
            mib(self.memory_budget_bytes as f64)
        ))
    }

    /// Whether a LOD with these parameters may start from the input within the budget: the
    /// start is not forced to the offset and [`input_start_memory_estimate_bytes`]
    /// (Self::input_start_memory_estimate_bytes) fits. Cheap (no clean-input check).
    pub(super) fn input_start_may_fit(&self, input: &TriMesh) -> bool {
        self.start != LodStart::Offset
            && self.input_start_estimate(input) <= self.memory_budget_bytes as f64
    }

    /// The estimated peak bytes of a LOD of `input` that starts from the (welded) input itself
    /// ([`LodStart`]) — the figure compared with `memory_budget_bytes` when that start is
    /// taken; meant to be an upper bound of the measured peak (docs/design-notes-lod.md, "Memory
    /// budget"). It does not depend on the offset voxel (no offset surface is built).
    pub fn input_start_memory_estimate_bytes(&self, input: &TriMesh) -> f64 {
        self.input_start_estimate(input)
    }
}

impl LodParams {
    /// The offset voxel scale a LOD of `input` with these parameters starts from (see the
    /// field `offset_voxel_scale` and [`LOD_VOXEL_SCALES`]), or `None`
    /// when even the coarsest scale's up-front estimate exceeds the budget: then the bake
    /// starts from the input if it may, else the measured admission decides during the bake
    /// (its scale is [`LodReport::offset_voxel_scale`](crate::lowpoly::LodReport::offset_voxel_scale), its estimate
    /// [`LodReport::measured_estimate_bytes`](crate::lowpoly::LodReport::measured_estimate_bytes)), else `validate` refuses. The same choice
    /// `generate` makes; for benchmarks and tools.
    pub fn lod_voxel_scale(&self, input: &TriMesh) -> Option<f64> {
        self.offset_voxel_scale(input, Mode::Lod)
    }

    /// The estimated peak bytes of a LOD bake of `input` at offset voxel `voxel_scale` — the
    /// figure compared with `memory_budget_bytes` (see the private `memory_estimate`); meant to
    /// be an upper bound of the measured peak (docs/design-notes-lod.md, "Memory budget").
    pub fn memory_estimate_bytes(&self, input: &TriMesh, voxel_scale: f64) -> f64 {
        self.memory_estimate(input, voxel_scale)
    }

    /// The voxel scale a bake in `mode` uses: see [`voxel_scale_from`](Self::voxel_scale_from),
    /// from [`finest_voxel_scale`].
    pub(super) fn offset_voxel_scale(&self, input: &TriMesh, mode: Mode) -> Option<f64> {
        let finest = finest_voxel_scale(mode, self.screen_size, self.offset_voxel_scale);
        self.voxel_scale_from(input, mode, finest)
    }

    /// The first of `finest` and the coarser scales of [`LOD_VOXEL_SCALES`] (cages: only 1)
    /// whose [`memory_estimate`](Self::memory_estimate) fits the budget, or `None`.
    pub(super) fn voxel_scale_from(&self, input: &TriMesh, mode: Mode, finest: f64) -> Option<f64> {
        let scales: &[f64] = match mode {
            Mode::Lod => &LOD_VOXEL_SCALES,
            Mode::Cage => &LOD_VOXEL_SCALES[..1],
        };
        let budget = self.memory_budget_bytes as f64;
        let coarser = scales.iter().copied().filter(|&s| s > finest);
        std::iter::once(finest)
            .filter(|&s| mode == Mode::Lod || scales.contains(&s))
            .chain(coarser)
            .find(|&s| self.memory_estimate(input, s) <= budget)
    }

    /// Estimated peak bytes: the input structures plus the larger of the loop's term — the
    /// offset surface, whose face count is about `2 · area / h²` with voxel edge
    /// `h = voxel_scale · d/√3` (area of a thin part's offset ≤ twice the input's, plus a
    /// sphere of radius `d` per component, bounded by the box), at [`BYTES_PER_WORK_FACE`] —
    /// and, with `fit_to_input`, the fit's: its coverage samples at [`BYTES_PER_FIT_SAMPLE`]
    /// plus what the loop leaves alive, [`BYTES_PER_FIT_WORK_FACE`] per offset face.
    pub(super) fn memory_estimate(&self, input: &TriMesh, voxel_scale: f64) -> f64 {
        let l = input.bbox_diagonal();
        let d = l / self.screen_size;
        let h = voxel_scale * d / 3f64.sqrt();
        let area = 2.0 * input.surface_area() + 4.0 * std::f64::consts::PI * d * d;
        let (lo, hi) = input.bbox();
        let ext: Vec<f64> = (0..3).map(|k| hi[k] - lo[k] + 2.0 * d).collect();
        let box_area = 2.0 * (ext[0] * ext[1] + ext[1] * ext[2] + ext[0] * ext[2]);
        let faces = 2.0 * area.min(8.0 * box_area) / (h * h);
        self.peak_from_start_faces(input, d, faces)
    }

    /// The input structures plus the larger of the loop's term, [`BYTES_PER_WORK_FACE`] per
    /// start-surface face, and (with `fit_to_input`) the fit's: its coverage samples at
    /// [`BYTES_PER_FIT_SAMPLE`] plus [`BYTES_PER_FIT_WORK_FACE`] per start face. `faces` is the
    /// up-front estimate ([`memory_estimate`](Self::memory_estimate)) or, on the measured
    /// admission's path, the offset surface's real face count ([`measured_start`]).
    fn peak_from_start_faces(&self, input: &TriMesh, d: f64, faces: f64) -> f64 {
        let fit = if self.fit_to_input {
            fit_samples(input, d) * BYTES_PER_FIT_SAMPLE + faces * BYTES_PER_FIT_WORK_FACE
        } else {
            0.0
        };
        // the loop's peak and the fit's come one after the other (the fit's LOD is small)
        (faces * BYTES_PER_WORK_FACE).max(fit)
            + input.triangle_count() as f64 * BYTES_PER_INPUT_FACE
    }

    /// Estimated peak bytes of a LOD that starts from the welded input (2026-11-28): the
    /// input structures, plus the larger of the loop's term on the input's faces (the first
    /// pass works through them as through an offset surface's, at [`BYTES_PER_WORK_FACE`]) and,
    /// with `fit_to_input`, the fit's (its coverage samples at [`BYTES_PER_FIT_SAMPLE`] plus
    /// [`BYTES_PER_FIT_WORK_FACE`] per start face). The same constants as the offset path's
    /// [`memory_estimate`](Self::memory_estimate) with the start's real face count in place of
    /// the offset's estimated one.
    pub(super) fn input_start_estimate(&self, input: &TriMesh) -> f64 {
        let d = input.bbox_diagonal() / self.screen_size;
        let faces = input.triangle_count() as f64;
        let fit = if self.fit_to_input {
            fit_samples(input, d) * BYTES_PER_FIT_SAMPLE + faces * BYTES_PER_FIT_WORK_FACE
        } else {
            0.0
        };
        (faces * BYTES_PER_WORK_FACE).max(fit) + faces * BYTES_PER_INPUT_FACE
    }

    /// The voxel scales the measured admission ([`measured_start`]) may try for a LOD of
    /// `input` from the offset surface, finest first — the finest the screen size starts from
    /// ([`finest_voxel_scale`]) and the coarser ones of [`LOD_VOXEL_SCALES`], as the up-front
    /// rule — keeping those whose a-priori part fits the budget: the input's structures plus
    /// the distance band's estimate at that scale (the offset stage's own check), and the
    /// input's structures plus the fit's coverage samples (no offset face counted). Empty when
    /// none does: then the bake is refused before any work.
    pub(super) fn measured_scales(&self, input: &TriMesh) -> Vec<f64> {
        let budget = self.memory_budget_bytes as f64;
        let d = input.bbox_diagonal() / self.screen_size;
        if self.peak_from_start_faces(input, d, 0.0) > budget {
            return Vec::new();
        }
        let input_bytes = input.triangle_count() as f64 * BYTES_PER_INPUT_FACE;
        let finest = finest_voxel_scale(Mode::Lod, self.screen_size, self.offset_voxel_scale);
        std::iter::once(finest)
            .chain(LOD_VOXEL_SCALES.iter().copied().filter(|&s| s > finest))
            .filter(|&s| input_bytes + band_estimate_bytes(input, d, s * d / 3f64.sqrt()) <= budget)
            .collect()
    }

    /// Whether a LOD of `input` from the offset surface is decided by the measured admission
    /// ([`measured_start`]): the up-front estimate fits no voxel scale (so no bake admitted up
    /// front changes), but some scale's a-priori part does
    /// ([`measured_scales`](Self::measured_scales)).
    pub(super) fn measured_admission_may_fit(&self, input: &TriMesh) -> bool {
        self.offset_voxel_scale(input, Mode::Lod).is_none()
            && !self.measured_scales(input).is_empty()
    }

    /// The peak bytes a measurement `m` at voxel scale `s0` estimates for scale `s`, with
    /// `shrink = (s0 / s)²` (band and surface counts ∝ 1/scale²: a prediction for a coarser
    /// scale; 1 for the measured scale itself): the input's structures plus, in the offset
    /// stage, [`BYTES_PER_MIXED_CUBE`] per mixed cube (the iso-points and the patch set) and
    /// the distance grid while it lives, or [`BYTES_PER_SURFACE_FACE`] per template triangle of
    /// the largest component (the interior removal's hierarchy) or of the visible ones (the
    /// feature phases' meshes); on the finished offset surface, [`peak_from_start_faces`]
    /// (Self::peak_from_start_faces) with its real face count (the loop's and the fit's peak).
    pub(super) fn measured_peak(&self, input: &TriMesh, d: f64, m: Measured, shrink: f64) -> f64 {
        let input_bytes = input.triangle_count() as f64 * BYTES_PER_INPUT_FACE;
        let (grid, cubes, faces) = match m {
            Measured::Offset(OffsetCount::Crossings(c)) => (c.grid_bytes, c.mixed_cubes, 0),
            Measured::Offset(OffsetCount::Components {
                mixed_cubes,
                largest_component_faces: faces,
            })
            | Measured::Offset(OffsetCount::Visible {
                mixed_cubes,
                visible_faces: faces,
            }) => (0, mixed_cubes, faces),
            Measured::StartFaces(f) => {
                return self.peak_from_start_faces(input, d, shrink * f as f64)
            }
        };
        let surface = cubes as f64 * BYTES_PER_MIXED_CUBE + faces as f64 * BYTES_PER_SURFACE_FACE;
        input_bytes + shrink * (grid as f64 + surface)
    }

    /// `LimitExceeded` naming what the measured admission counted at `scale` and the peak
    /// `peak` it estimates from it.
    pub(super) fn measured_refusal(&self, m: Measured, scale: f64, peak: f64) -> Error {
        let mib = |b: f64| b / (1u64 << 20) as f64;
        let what = match m {
            Measured::Offset(OffsetCount::Crossings(c)) => format!(
                "{} surface cells ({} iso-points) in a {:.0} MiB distance band",
                c.mixed_cubes,
                c.iso_points,
                mib(c.grid_bytes as f64)
            ),
            Measured::Offset(OffsetCount::Components {
                mixed_cubes,
                largest_component_faces,
            }) => format!(
                "{mixed_cubes} surface cells and {largest_component_faces} faces in its largest \
                 component"
            ),
            Measured::Offset(OffsetCount::Visible {
                mixed_cubes,
                visible_faces,
            }) => format!("{mixed_cubes} surface cells and {visible_faces} visible faces"),
            Measured::StartFaces(f) => format!("{f} offset-surface faces"),
        };
        Error::LimitExceeded(format!(
            "the offset surface at screen size {} (offset voxel {scale}× the default) measured \
             {what}: the bake would need about {:.0} MiB but the memory budget is {:.0} MiB\
             {RAISE_THE_BUDGET}",
            self.screen_size,
            mib(peak),
            mib(self.memory_budget_bytes as f64)
        ))
    }
}

/// What the measured admission ([`measured_start`]) counted at one voxel scale.
#[derive(Debug, Clone, Copy)]
pub(super) enum Measured {
    /// A count of the offset stage, before the allocation it predicts.
    Offset(OffsetCount),
    /// The finished offset surface's faces, before the loop: the loop's and the fit's peak.
    StartFaces(u64),
}

/// Refuses, before any allocation, a bake whose memory estimate fits no voxel scale allowed in
/// `mode` ([`LodParams::validate`] checks the LOD scales; cages allow only scale 1) — for a
/// LOD unless it may start from the input within the budget (then [`check_offset_budget`]
/// decides once the start is known).
pub(super) fn check_mode_budget(p: &LodParams, input: &TriMesh, mode: Mode) -> Result<()> {
    if p.offset_voxel_scale(input, mode).is_some()
        || (mode == Mode::Lod
            && (p.input_start_may_fit(input) || p.measured_admission_may_fit(input)))
    {
        return Ok(());
    }
    Err(Error::LimitExceeded(format!(
        "the bake needs about {:.0} MiB at screen size {} but the memory budget is {:.0} MiB\
         {RAISE_THE_BUDGET}",
        p.memory_estimate(input, 1.0) / (1u64 << 20) as f64,
        p.screen_size,
        p.memory_budget_bytes as f64 / (1u64 << 20) as f64
    )))
}

/// Once the start is known (`from_input`: [`choose_start`] took the input, whose estimate it
/// checked): a bake from the offset surface needs a voxel scale whose estimate fits, else
/// `LimitExceeded` before the offset stage allocates. The scale is the one
/// [`LodParams::offset_voxel_scale`] gives whatever the start, so outputs from the offset are
/// those of the budget rule before the input start was estimated on its own.
pub(super) fn check_offset_budget(
    p: &LodParams,
    input: &TriMesh,
    mode: Mode,
    from_input: bool,
) -> Result<()> {
    if from_input
        || p.offset_voxel_scale(input, mode).is_some()
        || (mode == Mode::Lod && p.measured_admission_may_fit(input))
    {
        return Ok(());
    }
    let why = match p.start {
        LodStart::Auto if p.input_start_may_fit(input) => {
            "LodStart::Auto: it is not clean, connected and of low genus"
        }
        _ => "over the budget",
    };
    Err(p.offset_over_budget(input, Some(why)))
}
