//! The entry points [`bake_level`] and [`bake_level_with_progress`]: validate, then bake the
//! input's material onto a LOD as vertex colours (no texture in the input) or textures, and,
//! when asked, evaluate the result against the input (`BakeParams::evaluate`).

use std::time::Instant;

use super::params::{BakeParams, VertexColors};
use super::progress::Steps;
use super::textured::bake_textured;
use super::vertex_colors::bake_vertex_colors;
use crate::bake::appearance::Appearance;
use crate::bake::level::BakedLevel;
use crate::mesh::TriMesh;
use crate::report::ProgressFn;
use crate::transfer::provenance::{InputIndex, ProvenanceParams};
use crate::{Error, Result};

/// Bakes `app`'s appearance onto `lod`, a LOD of `app.mesh` made for screen size `screen_size`.
/// `index` must index `app.mesh`. See the [module docs](crate::bake::bake).
///
/// Errors: `InvalidArgument` for bad parameters; `Internal` when the atlas fails.
pub fn bake_level(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    screen_size: f64,
    params: &BakeParams,
) -> Result<BakedLevel> {
    bake_level_with_progress(app, index, lod, screen_size, params, &mut |_| true)
}

/// [`bake_level`] with progress and cancellation: `progress` is called on this thread with
/// the stages `bake: provenance` (untextured inputs), `bake: atlas`, `bake: tangents` (the
/// normal map's MikkTSpace frame), `bake: rasterise`, `bake: texels` (every
/// `TEXELS_PER_CHECK` texels, so a cancel is honoured within about 10 ms of work),
/// `bake: dilation` and `bake: measure`; fractions rise from 0 to 1. Returning `false` stops
/// the bake with `Error::Cancelled`. The output is the same bytes as [`bake_level`]'s, whatever
/// the thread count.
pub fn bake_level_with_progress(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    screen_size: f64,
    params: &BakeParams,
    progress: &mut ProgressFn<'_>,
) -> Result<BakedLevel> {
    if !(params.envelope_d.is_finite() && params.envelope_d > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "bake envelope must be finite and > 0 (in units of d), got {}",
            params.envelope_d
        )));
    }
    if !(screen_size.is_finite() && screen_size > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "screen size must be finite and > 0, got {screen_size}"
        )));
    }
    let start = Instant::now();
    let diag = app.mesh.bbox_diagonal();
    let prov = ProvenanceParams {
        envelope: params.envelope_d * diag / screen_size,
    };
    let mut steps = Steps::new(progress, 0.0, 1.0);
    let textured = |steps: &mut Steps<'_, '_>| {
        bake_textured(app, index, lod, screen_size, diag, &prov, params, steps)
    };
    let color0_only = !app.has_textures() && app.colors.is_some();
    let mut level = match params.vertex_colors {
        _ if app.has_textures() => textured(&mut steps)?,
        VertexColors::Texture if color0_only => textured(&mut steps)?,
        VertexColors::Auto if color0_only => {
            let vertex =
                bake_vertex_colors(app, index, lod, screen_size, &prov, params, &mut steps)?;
            let (fit, allowed) = (
                vertex.report.vertex_fit_error,
                vertex.report.vertex_fit_allowed_error,
            );
            let mut level = if fit.zip(allowed).is_some_and(|(f, a)| f > a) {
                let mut t = textured(&mut steps)?;
                t.report.sample_seconds += vertex.report.sample_seconds;
                t
            } else {
                vertex
            };
            level.report.vertex_fit_error = fit;
            level.report.vertex_fit_allowed_error = allowed;
            level
        }
        _ => bake_vertex_colors(app, index, lod, screen_size, &prov, params, &mut steps)?,
    };
    level.report.total_seconds = start.elapsed().as_secs_f64();
    if params.evaluate {
        evaluate_into(app, &mut level);
    }
    Ok(level)
}

/// Fills the report's evaluation fields ([`BakeParams::evaluate`]).
fn evaluate_into(app: &Appearance, level: &mut BakedLevel) {
    let t = Instant::now();
    let e = crate::bake::render::evaluate(app, level, &crate::bake::render::EvalParams::default());
    let finite = |x: f64| x.is_finite().then_some(x);
    level.report.appearance_psnr_db = finite(e.appearance_psnr_db);
    level.report.appearance_psnr_reference_db = finite(e.reference_psnr_db);
    level.report.appearance_psnr_pooled_db = finite(e.appearance_pooled_psnr_db);
    level.report.appearance_psnr_reference_pooled_db = finite(e.reference_pooled_psnr_db);
    level.report.normal_map_gain_db = e.normal_map_gain_db.and_then(finite);
    level.report.evaluate_seconds = t.elapsed().as_secs_f64();
}
