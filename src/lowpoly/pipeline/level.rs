//! One level's bake up to its judging: what every level shares ([`Level`]), where its loop
//! starts ([`Start`], [`OffsetStart`]), the rounds of Alg. 3 from that start ([`round_level`])
//! and the input-plane fit after them ([`fit_level`]), with what each step hands to the next
//! ([`LevelRun`], [`Rounded`], [`Looped`]).

use super::optimize::{optimize_fit, optimize_rounds, LoopConfig, LoopStats};
use super::params::{LodParams, Mode};
use super::progress::Reporter;
use crate::lowpoly::guard::{Guard, InputModel};
use crate::lowpoly::report::{LodReport, LodStage};
use crate::mesh::TriMesh;
use crate::verify::{CageInput, MeshReport, ReportOptions};
use crate::Result;

/// What every level of a bake shares: the guard's input model, the input, the mode, and in
/// cage mode the independent verifier's prepared input.
pub(super) struct Level<'a> {
    pub(super) model: &'a InputModel,
    pub(super) input: &'a TriMesh,
    pub(super) mode: Mode,
    pub(super) cage_input: Option<CageInput<'a>>,
}

impl<'a> Level<'a> {
    pub(super) fn new(model: &'a InputModel, input: &'a TriMesh, mode: Mode) -> Level<'a> {
        Level {
            model,
            input,
            mode,
            cage_input: (mode == Mode::Cage).then(|| CageInput::new(input)),
        }
    }
}

/// Where a level's loop starts.
pub(super) enum Start<'m> {
    /// A surface that already has every Pro.III guarantee: the welded clean input, or the next
    /// finer level of a chain. The one-sided distance check of Alg. 5 gets slack `d`.
    Given(&'m TriMesh),
    /// The level's own offset surface ([`offset_start`]).
    Offset(OffsetStart),
}

/// A level's offset surface `M_d` with what the report says about it.
pub(super) struct OffsetStart {
    pub(super) mesh: TriMesh,
    /// Largest vertex deviation over `d` (cages only, see [`initial_surface`]).
    pub(super) deviation: Option<f64>,
    /// The voxel scale taken.
    pub(super) scale: f64,
    /// The measured admission's peak estimate, when the up-front one fitted no scale.
    pub(super) measured_peak: Option<f64>,
    /// Seconds of the offset stage.
    pub(super) seconds: f64,
}

/// The first part of [`bake_level`]: the start, the loop of Alg. 3 and the fit.
pub(super) fn loop_level(
    level: &Level<'_>,
    params: &LodParams,
    start: Start<'_>,
    rep: &mut Reporter<'_, '_>,
    window: (f64, f64),
) -> Result<Looped> {
    let rounded = round_level(level, params, start, rep, window)?;
    fit_level(rounded, rep)
}

/// The first part of [`loop_level`]: the start and the rounds of Alg. 3, before the fit.
pub(super) fn round_level<'m>(
    level: &Level<'m>,
    params: &LodParams,
    start: Start<'_>,
    rep: &mut Reporter<'_, '_>,
    window: (f64, f64),
) -> Result<Rounded<'m>> {
    let (model, mode) = (level.model, level.mode);
    let l = model.diag;
    let d = l / params.screen_size;
    let mut stats = LodReport {
        d,
        ..LodReport::default()
    };
    let (w0, ws) = window;
    let from_offset = matches!(start, Start::Offset(_));
    let (start, slack) = match start {
        Start::Given(m) => {
            stats.stages.push(LodStage::Offset, 0.0);
            (m.clone(), d)
        }
        Start::Offset(o) => {
            stats.measured_estimate_bytes = o.measured_peak;
            stats.offset_max_deviation_over_d = o.deviation;
            stats.offset_voxel_scale = (o.scale != 1.0).then_some(o.scale);
            stats.stages.push(LodStage::Offset, o.seconds);
            (o.mesh, 0.0)
        }
    };
    stats.faces_offset = start.triangle_count() as u64;
    let start_topology = topology_of(&start);
    rep.window(w0 + 0.2 * ws, 0.7 * ws);
    let cfg = LoopConfig {
        d,
        slack,
        target_faces: params.target_faces,
        max_rounds: params.max_rounds,
        r: params.flow_ratio,
        epsilon_abs: params.epsilon * l,
        align: params.align,
        mode,
        clearance: match mode {
            Mode::Cage => params.clearance.resolve(d),
            Mode::Lod => 0.0,
        },
        fit: mode == Mode::Lod && params.fit_to_input,
    };
    let (guard, ls) = optimize_rounds(&start, level.model, &cfg, false, rep)?;
    Ok(Rounded {
        guard,
        ls,
        run: LevelRun {
            stats,
            start,
            start_topology,
            cfg,
            from_offset,
            window,
        },
    })
}

/// The second part of [`loop_level`]: the fit after the rounds ([`optimize_fit`]).
pub(super) fn fit_level(rounded: Rounded<'_>, rep: &mut Reporter<'_, '_>) -> Result<Looped> {
    let Rounded { guard, ls, run } = rounded;
    let (mesh, ls) = optimize_fit(guard, &run.cfg, ls, rep)?;
    Ok(Looped { mesh, ls, run })
}

/// What a level's run carries from its start to its judging ([`round_level`] to
/// [`judge_level`]).
pub(super) struct LevelRun {
    /// The report so far (the start's figures).
    pub(super) stats: LodReport,
    /// The start surface, for an exact rerun.
    pub(super) start: TriMesh,
    pub(super) start_topology: (usize, i64),
    pub(super) cfg: LoopConfig,
    pub(super) from_offset: bool,
    pub(super) window: (f64, f64),
}

/// A level after the rounds of its loop ([`round_level`]), before its fit ([`fit_level`]).
pub(super) struct Rounded<'m> {
    /// The guard holding the rounds' output.
    guard: Guard<'m>,
    ls: LoopStats,
    run: LevelRun,
}

impl Rounded<'_> {
    /// The rounds' output: the surface a coarser chain level starts from.
    pub(super) fn output(&self) -> TriMesh {
        self.guard.mesh().to_trimesh()
    }
}

/// A level after its loop and fit ([`loop_level`]), before its verification and measurement
/// ([`judge_level`]).
pub(super) struct Looped {
    /// The loop's (and fit's) output.
    pub(super) mesh: TriMesh,
    pub(super) ls: LoopStats,
    pub(super) run: LevelRun,
}

/// `(components, Euler characteristic)` of a mesh (no self-intersection pass).
pub(super) fn topology_of(mesh: &TriMesh) -> (usize, i64) {
    let r = MeshReport::compute_with(
        mesh,
        &ReportOptions {
            self_intersections: false,
            weld: false,
        },
    );
    (r.n_components, r.euler_characteristic_total)
}
