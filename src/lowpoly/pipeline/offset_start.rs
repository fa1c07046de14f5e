//! A level's offset start `M_d` (§4.3.1): the offset surface at the finest voxel scale whose
//! up-front memory estimate fits, or for a LOD, the one admitted by measurement
//! ([`measured_start`]); in cage mode the enclosure without contact is checked here, since the
//! guard only keeps it.

use std::time::Instant;

use super::budget::Measured;
use super::level::{Level, OffsetStart};
use super::params::{LodParams, Mode};
use super::progress::Reporter;
use crate::lowpoly::offset::{
    offset_surface_admitted, Admit, OffsetCount, OffsetDistance, OffsetParams,
};
use crate::mesh::TriMesh;
use crate::report::Progress;
use crate::verify::CageCheck;
use crate::{Error, Result};

/// The offset start of a level at `params.screen_size` (§4.3.1): the finest voxel scale whose
/// up-front memory estimate fits, or for a LOD, the one admitted by measurement
/// ([`measured_start`]). Reports progress as the "offset" stage of the current window.
pub(super) fn offset_start(
    level: &Level<'_>,
    params: &LodParams,
    rep: &mut Reporter<'_, '_>,
) -> Result<OffsetStart> {
    let d = level.model.diag / params.screen_size;
    rep.check("offset", 0.0)?;
    let t0 = Instant::now();
    let (mesh, deviation, scale, measured_peak) =
        match params.offset_voxel_scale(level.input, level.mode) {
            Some(scale) => {
                let (m, dev) = initial_surface(level, params, d, scale, &mut |_| Ok(()), rep)?;
                (m, dev, scale, None)
            }
            None if level.mode == Mode::Lod => {
                let (m, dev, scale, peak) = measured_start(level, params, d, rep)?;
                (m, dev, scale, Some(peak))
            }
            None => return Err(Error::LimitExceeded("over the memory budget".into())),
        };
    Ok(OffsetStart {
        mesh,
        deviation,
        scale,
        measured_peak,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// The offset start of a LOD whose up-front estimate ([`LodParams::memory_estimate`]) fits no
/// voxel scale, admitted by measurement: the up-front estimate counts every
/// soup piece's offset whole (`2 · area / h²`), where overlapping and buried pieces leave far
/// less after the interior removal. For each scale of [`LodParams::measured_scales`], finest
/// first, the offset stage runs its band and distance step and the extraction's first pass;
/// from the mixed cubes counted there the offset stage's peak is estimated
/// ([`LodParams::measured_peak`]) and the stage refused (`LimitExceeded` naming the count)
/// before it allocates the surface, else it continues on the grid already computed; the
/// finished surface's real face count then estimates the loop's and the fit's peak, refused
/// before the loop allocates. A refused scale predicts the coarser ones (counts ∝ 1/scale²):
/// those predicted over the budget are skipped, the next is measured. Returns the surface,
/// its deviation (as [`initial_surface`]), the scale and the larger of the two measured
/// estimates. Deterministic: the counts do not depend on the thread count.
fn measured_start(
    level: &Level<'_>,
    params: &LodParams,
    d: f64,
    rep: &mut Reporter<'_, '_>,
) -> Result<(TriMesh, Option<f64>, f64, f64)> {
    let input = level.input;
    let budget = params.memory_budget_bytes as f64;
    let mut refused: Option<(f64, Measured)> = None;
    let mut error: Option<Error> = None;
    for scale in params.measured_scales(input) {
        if let Some((s0, m)) = refused {
            if params.measured_peak(input, d, m, (s0 / scale).powi(2)) > budget {
                continue;
            }
        }
        // the offset stage's largest measured estimate, and the last count (refused or not)
        let mut offset_stage: Option<(Measured, f64)> = None;
        let result = {
            let mut admit = |c: OffsetCount| {
                let m = Measured::Offset(c);
                let peak = params.measured_peak(input, d, m, 1.0);
                let largest = offset_stage.map_or(0.0, |(_, p)| p).max(peak);
                offset_stage = Some((m, largest));
                if peak > budget {
                    Err(params.measured_refusal(m, scale, peak))
                } else {
                    Ok(())
                }
            };
            initial_surface(level, params, d, scale, &mut admit, rep)
        };
        match result {
            Ok((mesh, dev)) => {
                let m = Measured::StartFaces(mesh.triangle_count() as u64);
                let peak = params.measured_peak(input, d, m, 1.0);
                if peak <= budget {
                    let offset_peak = offset_stage.map_or(0.0, |(_, p)| p);
                    return Ok((mesh, dev, scale, peak.max(offset_peak)));
                }
                refused = Some((scale, m));
                error = Some(params.measured_refusal(m, scale, peak));
            }
            Err(Error::LimitExceeded(msg)) => {
                if let Some((m, _)) = offset_stage.filter(|&(_, p)| p > budget) {
                    refused = Some((scale, m));
                }
                error = Some(Error::LimitExceeded(msg));
            }
            Err(e) => return Err(e),
        }
    }
    Err(error.unwrap_or_else(|| params.offset_over_budget(input, None)))
}

/// The start surface `M_d`: the offset surface of stage 1 (§4.3.1) at distance `d`, which is
/// watertight, manifold and intersection-free, and encloses the input at distance about `d`,
/// with its largest vertex deviation over `d` (cages only: a LOD's offset is not verified,
/// see below), on a voxel `voxel_scale` times `d/√3` ([`LOD_VOXEL_SCALES`]). In cage mode the
/// enclosure and the absence of contact are checked here, since the guard only keeps them.
fn initial_surface(
    level: &Level<'_>,
    params: &LodParams,
    d: f64,
    voxel_scale: f64,
    admit: &mut Admit<'_>,
    rep: &mut Reporter<'_, '_>,
) -> Result<(TriMesh, Option<f64>)> {
    let op = OffsetParams {
        distance: OffsetDistance::Absolute(d),
        voxel_scale,
        theta0_deg: params.theta0_deg,
        l0: params.l0,
        memory_budget_bytes: params.memory_budget_bytes,
        // A LOD's own output is verified independently at the end (`verify_level`), and the
        // guard only keeps what the start surface has (a bad start ends in `Internal` there):
        // verifying the dense intermediate surface too cost ≈ 5% of a LOD bake's CPU at scale
        // 2, with the same output bytes (docs/design-notes-lod.md, "Offset stage").
        // Cages keep it, with the enclosure check below.
        verify: level.mode == Mode::Cage,
        ..OffsetParams::default()
    };
    let (mesh, ostats) = {
        let mut prog = |p: Progress<'_>| rep.report(p.stage, p.fraction);
        offset_surface_admitted(level.input, &op, admit, &mut prog)?
    };
    let v = &ostats.verified;
    let essential = [
        ("watertight", v.watertight),
        ("manifold", v.manifold),
        ("self_intersection_free", v.self_intersection_free),
    ];
    for (name, holds) in essential {
        if holds == Some(false) {
            return Err(Error::Internal(format!(
                "the offset surface failed its verification ({name}); please report the input"
            )));
        }
    }
    if let Some(c) = &level.cage_input {
        let CageCheck {
            untouched,
            encloses,
        } = c.check(&mesh);
        if !(untouched && encloses) {
            return Err(Error::Internal(format!(
                "the offset surface does not enclose the input without contact \
                 (untouched: {untouched}, encloses: {encloses})"
            )));
        }
    }
    let deviation = ostats.verification.map(|v| v.max_deviation_over_d);
    Ok((mesh, deviation))
}
