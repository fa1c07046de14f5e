//! The judging of a level after its loop (§4.3.3): independent verification of Pro.III (and in
//! cage mode of the enclosure without contact) with the exact rerun when an intersection got
//! through, the two-sided Hausdorff measurement, the input-plane fit's safety revert, the floor
//! and clearance measures, and the level's report. A level that fails its verification is an
//! `Error::Internal`, never an output.

use std::time::Instant;

use super::level::{loop_level, Level, LevelRun, Looped, Start};
use super::optimize::optimize;
use super::params::{LodParams, Mode, FIT_HAUSDORFF_SLACK};
use super::progress::Reporter;
use crate::lowpoly::report::{ClearanceMeasure, FloorMeasure, LodReport, LodStage};
use crate::mesh::TriMesh;
use crate::verify::{self, MeshReport, ReportOptions};
use crate::{Error, Result};

/// Bakes one level from `start`: the loop, verification, measurement.
pub(super) fn bake_level(
    level: &Level<'_>,
    params: &LodParams,
    start: Start<'_>,
    rep: &mut Reporter<'_, '_>,
    window: (f64, f64),
) -> Result<Judged> {
    let looped = loop_level(level, params, start, rep, window)?;
    judge_level(level, params, looped, rep)
}

/// The verification and measurement of a level after its loop ([`loop_level`]): the exact
/// rerun when the independent check finds an intersection (§4.3.3), the two-sided Hausdorff
/// distance, the fit's safety revert, the floor and clearance measures, the report.
pub(super) fn judge_level(
    level: &Level<'_>,
    params: &LodParams,
    looped: Looped,
    rep: &mut Reporter<'_, '_>,
) -> Result<Judged> {
    let (model, input, mode) = (level.model, level.input, level.mode);
    let l = model.diag;
    let Looped {
        mut mesh,
        mut ls,
        run:
            LevelRun {
                mut stats,
                start,
                start_topology,
                cfg,
                from_offset,
                window: (w0, ws),
            },
    } = looped;
    rep.window(w0 + 0.9 * ws, 0.1 * ws);
    rep.check("verify", 0.0)?;
    let t0 = Instant::now();
    let mut v = verify_level(&mesh, level, rep, (0.0, 0.5))?;
    let mut reruns = 0;
    if !v.self_intersection_free || !v.cage_ok {
        // §4.3.3: the normal-cone shortcut let an intersection through: rerun exactly.
        reruns = 1;
        rep.window(w0 + 0.2 * ws, 0.7 * ws);
        let (m2, ls2) = optimize(&start, model, &cfg, true, rep)?;
        mesh = m2;
        ls = ls2;
        rep.window(w0 + 0.9 * ws, 0.1 * ws);
        v = verify_level(&mesh, level, rep, (0.0, 0.5))?;
    }
    let mut verify_s = t0.elapsed().as_secs_f64();
    // the pre-fit mesh when the fit is kept; `None`: the output is the rounds output
    let mut rounds_output = None;
    rep.check("measure", 0.5)?;
    let t0 = Instant::now();
    // chunked so that a cancel is seen within tens of milliseconds (every long operation
    // honours cancellation within 0.5 s)
    let mut sides = verify::hausdorff_sides_with_progress(&mesh, input, &mut |f| {
        rep.report("measure", 0.5 + 0.25 * f)
    })
    .ok_or(Error::Cancelled)?;
    let measure_s = t0.elapsed().as_secs_f64();
    if let Some(pre) = ls.prefit.take() {
        let t0 = Instant::now();
        let fitted = hausdorff_of(&sides);
        let pre_sides = verify::hausdorff_sides_unless(
            &pre,
            input,
            &|x| keeps_fit(fitted, x, l),
            // the pre-fit maximum is most likely on the side of the fitted one
            sides.output_to_input >= sides.input_to_output,
            &mut |f| rep.report("fit", 0.75 + 0.25 * f),
        )
        .ok_or(Error::Cancelled)?;
        ls.fit_s += t0.elapsed().as_secs_f64();
        ls.fit_sides = Some([sides.input_to_output / l, sides.output_to_input / l]);
        if let Some(pre_sides) = pre_sides.filter(|p| !keeps_fit(fitted, hausdorff_of(p), l)) {
            // The fit's safety revert: the loop's output (guarded like the fit's) instead.
            let t0 = Instant::now();
            mesh = pre;
            sides = pre_sides;
            ls.fit_reverted = true;
            v = verify_level(&mesh, level, rep, (1.0, 1.0))?;
            verify_s += t0.elapsed().as_secs_f64();
        } else {
            rounds_output = Some(pre);
        }
    }
    ls.write(&mut stats);
    stats.stages.push(LodStage::Verify, verify_s);
    stats.reruns_exact = reruns;
    let same_topology = (v.components, v.euler) == start_topology;
    stats.verified.watertight = Some(v.watertight);
    stats.verified.manifold = Some(v.manifold);
    stats.verified.self_intersection_free = Some(v.self_intersection_free);
    if mode == Mode::Cage {
        stats.verified.cage_encloses_without_touching = Some(v.cage_ok);
    }
    stats.verified.same_topology_as_offset = Some(same_topology);
    let ok = v.manifold && v.watertight && v.self_intersection_free && v.cage_ok && same_topology;
    if !ok {
        return Err(Error::Internal(format!(
            "the output failed independent verification ({v:?}); please report the input"
        )));
    }
    let h = hausdorff_of(&sides);
    stats.stages.push(LodStage::Measure, measure_s);
    if params.measure_floor && from_offset {
        let (t0, c0) = (Instant::now(), crate::report::process_cpu_seconds());
        let floor = verify::input_to_surface(&start, input);
        let rel = floor / l;
        stats
            .stages
            .push(LodStage::Floor, t0.elapsed().as_secs_f64());
        stats.floor = Some(FloorMeasure {
            rel,
            cpu_seconds: crate::report::process_cpu_seconds() - c0,
        });
    }
    if let Some(c) = &level.cage_input {
        let t0 = Instant::now();
        let min = c
            .min_distance_with_progress(&mesh, &mut |f| rep.report("clearance", 0.75 + 0.25 * f))
            .ok_or(Error::Cancelled)?;
        stats
            .stages
            .push(LodStage::Clearance, t0.elapsed().as_secs_f64());
        stats.clearance = Some(ClearanceMeasure {
            required: cfg.clearance,
            min,
            min_rel: min / l,
            kept: min >= cfg.clearance && min > 0.0,
        });
    }
    stats.hausdorff = h;
    stats.hausdorff_rel = h / l;
    stats.hausdorff_in_to_out_rel = sides.input_to_output / l;
    stats.hausdorff_out_to_in_rel = sides.output_to_input / l;
    stats.faces = mesh.triangle_count() as u64;
    stats.vertices = mesh.vertex_count() as u64;
    rep.check("done", 1.0)?;
    Ok(Judged {
        mesh,
        stats,
        rounds_output,
    })
}

/// A baked level ([`judge_level`]).
pub(super) struct Judged {
    /// The output.
    pub(super) mesh: TriMesh,
    pub(super) stats: LodReport,
    /// The rounds output ([`Judged::rounds_output`]) when it is not `mesh` (the fit was kept).
    rounds_output: Option<TriMesh>,
}

impl Judged {
    /// The output of the rounds of the run the output comes from (of the exact rerun if there
    /// was one), before the fit: the surface the next coarser chain level starts from.
    pub(super) fn rounds_output(&self) -> &TriMesh {
        self.rounds_output.as_ref().unwrap_or(&self.mesh)
    }
}

/// Whether a pre-fit Hausdorff distance `pre` keeps a fit that measured `fitted` (the fit's
/// safety revert is `fitted > pre + FIT_HAUSDORFF_SLACK · l`). Monotone in `pre` (rounding of
/// `pre + slack` is), and the pre-fit distance is a maximum over samples, so one sample `x`
/// with `keeps_fit(fitted, x, l)` decides it: the pre-fit measure stops there
/// (`verify::hausdorff_sides_unless`), with the same decision as the full measure.
fn keeps_fit(fitted: f64, pre: f64, l: f64) -> bool {
    // not `fitted > pre + slack`, NaN included (no revert)
    fitted.partial_cmp(&(pre + FIT_HAUSDORFF_SLACK * l)) != Some(std::cmp::Ordering::Greater)
}

/// The two-sided distance of measured `sides`.
fn hausdorff_of(sides: &verify::HausdorffSides) -> f64 {
    sides.input_to_output.max(sides.output_to_input)
}

/// What the independent verification (`crate::verify`) found on a level's output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Verification {
    /// Edge- and vertex-manifold, no repeated-index faces, consistently oriented.
    manifold: bool,
    /// Closed and manifold.
    watertight: bool,
    /// No two faces intersect beyond their shared vertices/edges (CGAL's rules) and no face is
    /// degenerate.
    self_intersection_free: bool,
    /// Number of connected components.
    components: usize,
    /// Total Euler characteristic.
    euler: i64,
    /// Cage mode: encloses the input without touching it; `true` for a LOD.
    cage_ok: bool,
}

/// Pro.III by [`MeshReport`] (which shares none of the guard's shortcuts) and, in cage mode,
/// the cage checks of `crate::verify::cage`, reporting stage "verify" from `range.0` to
/// `range.1` of the current window: a progress call (and cancellation point) per phase and per
/// chunk of both (every long operation honours cancellation within 0.5 s).
fn verify_level(
    mesh: &TriMesh,
    level: &Level<'_>,
    rep: &mut Reporter<'_, '_>,
    range: (f64, f64),
) -> Result<Verification> {
    let (lo, span) = (range.0, range.1 - range.0);
    let report_share = if level.cage_input.is_some() { 0.5 } else { 1.0 };
    let r = MeshReport::compute_with_progress(mesh, &ReportOptions::default(), &mut |f| {
        rep.report("verify", lo + span * report_share * f)
    })
    .ok_or(Error::Cancelled)?;
    let cage_ok = match &level.cage_input {
        None => true,
        Some(c) => c
            .check_with_progress(mesh, &mut |f| {
                rep.report("verify", lo + span * (0.5 + 0.5 * f))
            })
            .ok_or(Error::Cancelled)?
            .is_cage(),
    };
    Ok(Verification {
        manifold: r.is_manifold && r.consistently_oriented,
        watertight: r.is_watertight,
        self_intersection_free: r.self_intersection_free == Some(true),
        components: r.n_components,
        euler: r.euler_characteristic_total,
        cage_ok,
    })
}
