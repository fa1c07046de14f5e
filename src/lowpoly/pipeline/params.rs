//! The parameters of a LOD or cage bake: [`LodParams`] with its defaults (the dissertation's,
//! §4.4), the cage [`Clearance`], the LOD start [`LodStart`], and the bake's [`Mode`]. Plain
//! data and their documented defaults; the checks are in `validate.rs`, the memory budget in
//! `budget.rs`.

use crate::lowpoly::DeformationField;
// Targets of the doc links below (the items live in sibling files of this module).
#[allow(unused_imports)]
use crate::lowpoly::{
    check_clean, generate, generate_chain, LodReport, LOD_COARSE_VOXEL_MIN_SCREEN_SIZE,
    LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE, LOD_MEDIUM_VOXEL_SCALE, LOD_VOXEL_SCALE, LOD_VOXEL_SCALES,
    STALL_ROUNDS,
};

/// Default cage clearance as a fraction of `d` ([`Clearance::FractionOfD`]).
pub const DEFAULT_CLEARANCE_FRACTION: f64 = 0.05;

/// How far a cage stays from its input (ignored for LODs). The guard refuses
/// every operation that would bring a cage face closer to the input than this, measured as
/// exact triangle–triangle distance; the report's `min_clearance` is the independently
/// measured result.
///
/// The default, `FractionOfD(0.05)` — a twentieth of the offset distance `d = l / n_p`, i.e.
/// a twentieth of a pixel at the screen size the cage is made for — is non-zero so that the cage
/// never touches the input in floating point (a ray cast from the cage towards the input, as
/// in a texture bake, or a collision proxy, needs a real gap: without a clearance cages ended
/// ~1e-15 l from the input), scales with the cage's own resolution (invisible at the screen
/// size it is made for), and leaves 95% of the `[0, d]` band the start surface sits in to the
/// simplification: the band's width sets the face count (a chord within a band of width `w`
/// on a curvature radius `R` is `√(8Rw)` long, so faces grow like `1/w`). Measured 2026-12-07
/// (the default was 0.1 before): over the 69 corpus cages at n_p = 25/50/100, a tenth of `d`
/// cost a median +12% faces against a cage without clearance and 10 cages more than +20% (the
/// bound a cage's clearance may cost in faces); a twentieth costs a median +6%, 2 cages above
/// +20% (62 → 76 and 100 → 122 faces at n_p = 25), none once collapses refused by the guard are
/// retried (`retries_guard_refusals`; docs/benchmarks/cage.md).
/// Both are far below a pixel and far above rounding. It must stay below
/// `d`: the cage starts from the offset surface at distance `d`, whose faces dip a few percent
/// of `d` closer (chords of its rounded parts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Clearance {
    /// A fraction of the offset distance `d`, in `[0, 1)`.
    FractionOfD(f64),
    /// A length in model units, `≥ 0` and below `d`.
    Absolute(f64),
}

impl Default for Clearance {
    fn default() -> Self {
        Clearance::FractionOfD(DEFAULT_CLEARANCE_FRACTION)
    }
}

impl Clearance {
    /// The clearance in model units for offset distance `d`.
    pub fn resolve(&self, d: f64) -> f64 {
        match *self {
            Clearance::FractionOfD(f) => f * d,
            Clearance::Absolute(c) => c,
        }
    }
}

/// Parameters of [`generate`] and [`generate_chain`] (and of cages, `crate::cage`). Start from
/// [`LodParams::default`]; defaults are the dissertation's (§4.4: `n_p = 200`, `N = 50`,
/// `r = 1/8`, `ε = 1e-4`, `θ0 = 120°`, `l0 = 4`).
#[derive(Debug, Clone, PartialEq)]
pub struct LodParams {
    /// Screen size `n_p`: pixels covered by the input's bounding-box diagonal `l`. The offset
    /// distance and per-collapse error bound is `d = l / n_p`. Finite, `> 0`.
    pub screen_size: f64,
    /// Optional target face count `n_F` (Pro.I): simplification stops there and the loop ends
    /// when it is met. When a round makes no collapse (or the loop converges) before the target
    /// is reached, the per-collapse distance bound `d` of Alg. 5 is doubled and the one-sided
    /// distance check tolerates patches up to that bound (counted in
    /// [`LodReport::target_relaxations`]), so the target is reached unless topology or the
    /// guarantees forbid it or the `N` rounds run out. `None` minimises the count at error `d`.
    /// At least 4 when given.
    pub target_faces: Option<usize>,
    /// Maximum number of rounds `N` of Alg. 3 (0 returns the offset surface). A LOD or cage
    /// without a face target also stops after [`STALL_ROUNDS`] rounds without a new smallest
    /// face count ([`LodReport::stalled`]).
    pub max_rounds: u32,
    /// Flow fraction `r` in `(0, 1]` (Alg. 3 line 9).
    pub flow_ratio: f64,
    /// Convergence threshold `ε` relative to `l` (Alg. 3 line 17), `≥ 0`.
    pub epsilon: f64,
    /// Feature-curve dihedral threshold `θ0` in degrees, `(0, 180)` (offset stage).
    pub theta0_deg: f64,
    /// Minimum feature-curve length `l0` in edges (offset stage).
    pub l0: u32,
    /// Upper bound on the memory of the bake in bytes; estimated before the expensive work
    /// starts. A LOD takes the finest voxel of [`LOD_VOXEL_SCALES`] whose estimate fits, from
    /// the one its screen size starts from on (see [`LOD_VOXEL_SCALE`]; reported as
    /// [`LodReport::offset_voxel_scale`]); beyond the coarsest (cages: beyond scale 1) it fails
    /// with `Error::LimitExceeded` before any large allocation — except a LOD from the offset
    /// whose input structures and distance band fit: the offset stage then counts its surface
    /// before allocating it and the budget is checked against the peak estimated from those
    /// counts (the measured admission, for a soup of overlapping pieces, whose
    /// up-front estimate counts every piece's offset whole), refusing with `LimitExceeded` before
    /// the allocation that would exceed it ([`LodReport::measured_estimate_bytes`]).
    pub memory_budget_bytes: u64,
    /// Run the feature-alignment step (Alg. 6). Default true.
    pub align: bool,
    /// Also measure the error floor set by the offset stage: the one-sided distance from the
    /// input to the offset surface ([`LodReport::floor`]), which no later
    /// step can lower. Costs one more distance measurement; for benchmarks. Default false.
    pub measure_floor: bool,
    /// Cages only: the distance the cage keeps from the input (see [`Clearance`]; default a
    /// twentieth of `d`). `FractionOfD(0.0)` keeps only "no contact", as cages did before they
    /// had a clearance.
    pub clearance: Clearance,
    /// LODs only (ignored for cages): after the loop, fit the LOD to the input's planes
    /// (guarded QEM vertex placement and normal-improving flips, `fit.rs`), which removes the
    /// offset and re-sharpens rounded creases; reverted when the two-sided Hausdorff distance
    /// would grow by more than [`FIT_HAUSDORFF_SLACK`]` · l`. Default true.
    pub fit_to_input: bool,
    /// LODs only (cages always start from the offset surface, which encloses the input): the
    /// surface the loop starts from (see [`LodStart`]). Default
    /// [`LodStart::Auto`].
    pub start: LodStart,
    /// LODs only (ignored for cages): the offset voxel the bake starts from, as a multiple of
    /// `d/√3`. `None` (default) follows the rule of [`LOD_VOXEL_SCALE`] (scale 2 from
    /// [`LOD_COARSE_VOXEL_MIN_SCREEN_SIZE`] on, [`LOD_MEDIUM_VOXEL_SCALE`] from
    /// [`LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE`] on, 1 below); `Some(s)` starts from `s`, finite and
    /// in `(0, 2]` (else `InvalidArgument`), e.g. `Some(1.0)` for the dissertation's voxel. The
    /// memory-budget fallback still applies: when `s` does not fit, the finest of
    /// [`LOD_VOXEL_SCALES`] coarser than `s` that fits is taken. Replaces the former benchmark
    /// environment variable `PLEAT_LOD_VOXEL_SCALE`, so the output depends on
    /// the parameters only.
    pub offset_voxel_scale: Option<f64>,
    /// The input's skin weights and morph targets, per input vertex, when the LOD will be
    /// deformed by them (a skinned or morphed mesh; see [`DeformationField`]). The
    /// simplification then keeps the vertices the deformation needs: no collapse creates an
    /// edge whose posed shape would leave the posed input by more than [`SKIN_ERROR`]` · d`
    /// (joints turning by up to the field's `max_rotation`), or along which the input's morph
    /// displacements stray more than [`MORPH_DEVIATION`]` · d` from the linear blend of the
    /// edge's ends, so the posed LOD bends with its input (more faces where weights change).
    /// `None` (default): a static mesh.
    ///
    /// [`SKIN_ERROR`]: crate::lowpoly::SKIN_ERROR
    /// [`MORPH_DEVIATION`]: crate::lowpoly::MORPH_DEVIATION
    pub deformation: Option<std::sync::Arc<DeformationField>>,
}

/// The largest total genus of a clean input that [`LodStart::Auto`] starts from (see there):
/// the offset surface closes handles narrower than about `2d`, and on the corpus' genus-23
/// tray that halves the face count; genus ≤ 4 (fertility, a CAD part, tori) did better from
/// the input. The threshold between 4 and 23 is not measured more finely.
pub const AUTO_MAX_GENUS: i64 = 8;

/// The surface a LOD's loop starts from (ignored for cages, which must
/// enclose the input and always start from the offset surface).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LodStart {
    /// [`Input`](Self::Input) when the input is clean ([`check_clean`]), connected and of
    /// total genus at most [`AUTO_MAX_GENUS`], else [`Offset`](Self::Offset). Connected,
    /// because a second component may be buried in the first (invisible, removed by the
    /// offset stage's interior removal, kept by Input); every clean corpus mesh is connected,
    /// so clean multi-component inputs are not measured.
    ///
    /// Measured 2026-11-27 (docs/design-notes-lod.md, "LOD loop and fit") on
    /// the 11 clean corpus meshes ≤ 40k faces at n_p = 200, Input against Offset: 24% fewer
    /// faces on average (412 against 545), two-sided Hausdorff 0.99% of l against 1.47%, less
    /// CPU on 10 of 11 (median 4.8 against 7.3 s), every output CGAL-valid; at pleat's face
    /// count Input's normal difference is below MeshLab QEM's on 10 of 11 and its PSNR above on
    /// 10 of 11. The exception is the one high-genus mesh, the tray (genus 23): Input keeps its
    /// 23 handles where the offset closes most of them, and ends at 2.5× Offset's faces —
    /// hence the genus limit. On the 600k-face armadillo Input costs 1.6× Offset's CPU (the
    /// first pass works through the dense input; 750 against 922 faces, Hausdorff 1.04 against
    /// 1.13% of l). The check costs a topology pass on every input (0.04 s on the 124k-face
    /// ogre, no measurable change of its bake) and a self-intersection pass only on inputs whose
    /// topology is clean (≈ 1 s on the 600k-face armadillo, ≈ 3% of its bake).
    #[default]
    Auto,
    /// The offset surface at `d` (§4.3.1), the dissertation's start: works on any soup.
    Offset,
    /// The exactly welded input itself, as a chain level starts from a finer level: the
    /// one-sided distance check of Alg. 5 is relaxed to `slack = d`, so the output stays
    /// within about `d` of the input. The input must be clean ([`check_clean`]), else
    /// `InvalidArgument` names the property that fails.
    Input,
}

/// The largest growth of the two-sided Hausdorff distance (over `l`) the input-plane fit may
/// cause; beyond it the fit is reverted ([`LodReport::fit_reverted`]). A quarter of the 0.001 l
/// a LOD's Hausdorff distance may exceed the offset stage's floor by.
pub const FIT_HAUSDORFF_SLACK: f64 = 2.5e-4;

impl Default for LodParams {
    fn default() -> Self {
        LodParams {
            screen_size: 200.0,
            target_faces: None,
            max_rounds: 50,
            flow_ratio: 0.125,
            epsilon: 1e-4,
            theta0_deg: 120.0,
            l0: 4,
            memory_budget_bytes: 2 << 30,
            align: true,
            measure_floor: false,
            clearance: Clearance::default(),
            fit_to_input: true,
            start: LodStart::Auto,
            offset_voxel_scale: None,
            deformation: None,
        }
    }
}

/// Whether the loop builds a LOD or a cage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    Lod,
    Cage,
}
