//! The entry points: [`generate`] (one LOD), [`generate_chain`] (one LOD per screen size) and
//! their mode-generic forms `run` / `run_chain` (cages use them too). Each checks the
//! parameters and the budget before any work, builds the guard's input model, chooses the
//! start, and hands the levels to the chain scheduling (`chain.rs`) or bakes the one level.

use super::budget::{check_mode_budget, check_offset_budget};
use super::chain::{chain_from_finer, chain_from_offsets};
use super::judge::{bake_level, Judged};
use super::level::{Level, Start};
use super::offset_start::offset_start;
use super::params::{LodParams, Mode};
use super::progress::Reporter;
use super::start::choose_start;
use crate::lowpoly::guard::InputModel;
use crate::lowpoly::report::LodReport;
use crate::mesh::TriMesh;
use crate::report::ProgressFn;
use crate::{Error, Result};

/// Bakes one LOD of `input` (any triangle soup) at `params.screen_size`: a watertight,
/// manifold, self-intersection-free mesh within about `d = l / n_p` of the input (Pro.I–III),
/// starting from the offset surface or, for a clean input, the input itself
/// ([`LodParams::start`], [`LodReport::started_from_input`]).
/// `progress` is called on this thread; returning `false` cancels with `Error::Cancelled`.
///
/// [`LodReport`]: stage seconds, counts, the achieved error (`hausdorff_rel` = two-sided
/// sampled Hausdorff / `l`, measured by `crate::verify::hausdorff`) and the guarantees verified
/// by `crate::verify` (watertight, manifold, self-intersection-free, same topology).
///
/// Errors: `InvalidArgument` for a bad parameter (NaN or `≤ 0` screen size, …),
/// `LimitExceeded` over the memory budget, `InvalidMesh` for an input with nothing to
/// approximate, `Cancelled`, and `Internal` if a guarantee cannot be established.
pub fn generate(
    input: &TriMesh,
    params: &LodParams,
    progress: &mut ProgressFn<'_>,
) -> Result<(TriMesh, LodReport)> {
    run(input, params, Mode::Lod, progress)
}

/// Bakes one LOD per screen size (in the given order of `screen_sizes`). The finest level is
/// baked from the input (from its offset surface, or from the welded input itself as
/// [`LodParams::start`] decides); a coarser level starts from the next finer level's loop
/// output before that level's input-plane fit (which already has every Pro.III guarantee, so
/// the guard keeps them; the coarser level's own rounds and fit follow), with the one-sided
/// distance check of Alg. 5 relaxed to `d` of the coarser level — the distance its own offset
/// surface would start from — when the finest level started from the input, or when the
/// level's own offset surface has the finer level's topology; otherwise (its offset closed
/// handles or merged components the finer level kept) from its own offset surface, exactly as
/// [`generate`] would bake it ([`LodReport::started_from_finer`]). `params.screen_size` and
/// `params.target_faces` are ignored (a face target is per level: call [`generate`]). Each
/// level's report has its [`LodReport::chain_level`] (0 = finest).
///
/// On a thread pool of more than one thread, levels that do not depend on each other run at
/// the same time (the levels from their own offsets beside the finest level; the coarser
/// levels' bakes beside the finer level's fit, verification and measurement, redone in the
/// rare case the verification reruns the loop): the levels are byte for byte those of a
/// one-thread run. `progress` is called on this thread only, with fractions that never go
/// back.
pub fn generate_chain(
    input: &TriMesh,
    screen_sizes: &[f64],
    params: &LodParams,
    progress: &mut ProgressFn<'_>,
) -> Result<Vec<(TriMesh, LodReport)>> {
    run_chain(input, screen_sizes, params, Mode::Lod, progress)
}

/// [`generate`] for either mode.
pub(crate) fn run(
    input: &TriMesh,
    params: &LodParams,
    mode: Mode,
    progress: &mut ProgressFn<'_>,
) -> Result<(TriMesh, LodReport)> {
    params.validate(input)?;
    check_mode_budget(params, input, mode)?;
    let mut rep = Reporter::new(progress);
    // cancellation points between the setup's trees (each about 1 s on a 10⁶-face input)
    rep.check("setup", 0.0)?;
    let mut model =
        InputModel::new_with_stop(input, mode == Mode::Cage, &mut || rep.report("setup", 0.0))
            .ok_or(Error::Cancelled)?;
    model.deformation = followed_deformation(params);
    rep.check("setup", 0.0)?;
    let start = choose_start(input, params, mode, &mut rep)?;
    check_offset_budget(params, input, mode, start.is_some())?;
    let level = Level::new(&model, input, mode);
    let from_input = start.is_some();
    let start = match &start {
        Some(m) => Start::Given(m),
        None => {
            rep.window(0.0, 0.2);
            Start::Offset(offset_start(&level, params, &mut rep)?)
        }
    };
    let Judged {
        mesh, mut stats, ..
    } = bake_level(&level, params, start, &mut rep, (0.0, 1.0))?;
    stats.started_from_input = from_input;
    Ok((mesh, stats))
}

/// [`generate_chain`] for either mode.
pub(crate) fn run_chain(
    input: &TriMesh,
    screen_sizes: &[f64],
    params: &LodParams,
    mode: Mode,
    progress: &mut ProgressFn<'_>,
) -> Result<Vec<(TriMesh, LodReport)>> {
    if screen_sizes.is_empty() {
        return Err(Error::InvalidArgument("no screen size given".into()));
    }
    let mut level_params = Vec::with_capacity(screen_sizes.len());
    for &s in screen_sizes {
        let p = LodParams {
            screen_size: s,
            target_faces: None,
            ..params.clone()
        };
        p.validate(input)?;
        check_mode_budget(&p, input, mode)?;
        level_params.push(p);
    }
    let mut order: Vec<usize> = (0..screen_sizes.len()).collect();
    order.sort_by(|&a, &b| screen_sizes[b].total_cmp(&screen_sizes[a]).then(a.cmp(&b)));
    let mut rep = Reporter::new(progress);
    // cancellation points between the setup's trees (each about 1 s on a 10⁶-face input)
    rep.check("setup", 0.0)?;
    let mut model =
        InputModel::new_with_stop(input, mode == Mode::Cage, &mut || rep.report("setup", 0.0))
            .ok_or(Error::Cancelled)?;
    model.deformation = followed_deformation(&level_params[0]);
    rep.check("setup", 0.0)?;
    let level = Level::new(&model, input, mode);
    // the finest level starts from the welded input when it is clean (`LodStart`)
    let welded = choose_start(input, &level_params[order[0]], mode, &mut rep)?;
    check_offset_budget(&level_params[order[0]], input, mode, welded.is_some())?;
    let levels: Vec<&LodParams> = order.iter().map(|&i| &level_params[i]).collect();
    let by_rank = match &welded {
        // the welded clean input's topology is every level's (a single bake of each level
        // would start from the input too): each level from the next finer one
        Some(w) => chain_from_finer(&level, &levels, w, &mut rep)?,
        None => chain_from_offsets(&level, &levels, &mut rep)?,
    };
    let mut out: Vec<Option<(TriMesh, LodReport)>> = vec![None; screen_sizes.len()];
    for (
        rank,
        Judged {
            mesh, mut stats, ..
        },
    ) in by_rank.into_iter().enumerate()
    {
        stats.chain_level = Some(rank as u64);
        stats.started_from_input = rank == 0 && welded.is_some();
        out[order[rank]] = Some((mesh, stats));
    }
    Ok(out
        .into_iter()
        .map(|x| x.expect("every level baked"))
        .collect())
}

/// The deformation the simplification keeps vertices for: `params.deformation` unless it is
/// empty (the same for every level of a chain).
fn followed_deformation(
    params: &LodParams,
) -> Option<std::sync::Arc<crate::lowpoly::DeformationField>> {
    params.deformation.clone().filter(|f| !f.is_empty())
}
