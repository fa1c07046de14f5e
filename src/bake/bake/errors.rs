//! The appearance error of a bake for its report: the colour error at a point against the input
//! at its closest point (sRGB 1/255), sampled at texel centres, and its mean, 95th percentile
//! and maximum.

use rayon::prelude::*;

use super::sample::TexelCtx;
use crate::bake::appearance::{linear_to_srgb, Appearance};
use crate::bake::level::{BakeReport, Image8};
use crate::geom::Vec3;
use crate::transfer::provenance::InputIndex;

/// |baked − input at the closest input point|, max over RGB, in sRGB 1/255 (`baked` linear).
pub(super) fn color_error(
    app: &Appearance,
    index: &InputIndex<'_>,
    p: Vec3,
    baked: [f64; 4],
) -> f64 {
    let Some(q) = index.closest(p) else {
        return 0.0;
    };
    let c = app.sample(q.triangle as usize, q.bary).base_color;
    (0..3)
        .map(|k| (255.0 * (linear_to_srgb(c[k]) - linear_to_srgb(baked[k]))).abs())
        .fold(0.0, f64::max)
}

/// Errors at up to `max` texel centres inside charts (every k-th).
pub(super) fn texel_errors(ctx: &TexelCtx<'_>, base: &Image8, max: usize) -> Vec<f64> {
    let inside: Vec<usize> = (0..ctx.cov.tri.len())
        .filter(|&k| ctx.cov.tri[k] != u32::MAX)
        .collect();
    let stride = inside.len().div_ceil(max).max(1);
    let n = ctx.cov.size as usize;
    inside
        .iter()
        .step_by(stride)
        .copied()
        .collect::<Vec<_>>()
        .par_iter()
        .map(|&k| {
            let (p, ..) = ctx.surface(ctx.cov.tri[k] as usize, ctx.cov.bary[k]);
            let px = base.texel((k % n) as u32, (k / n) as u32);
            let baked = [0, 1, 2]
                .map(|c| crate::bake::appearance::srgb_to_linear(f64::from(px[c]) / 255.0));
            color_error(ctx.app, ctx.index, p, [baked[0], baked[1], baked[2], 1.0])
        })
        .collect()
}

pub(super) fn set_errors(report: &mut BakeReport, mut errs: Vec<f64>) {
    if errs.is_empty() {
        return;
    }
    errs.sort_by(f64::total_cmp);
    report.appearance_error_mean = errs.iter().sum::<f64>() / errs.len() as f64;
    report.appearance_error_p95 = errs[((errs.len() - 1) as f64 * 0.95) as usize];
    report.appearance_error_max = errs[errs.len() - 1];
}
