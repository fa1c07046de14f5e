//! The scheduling of a LOD chain's levels: which level starts from which surface (its own
//! offset or the next finer level's rounds output), and which levels are baked beside each other
//! on a pool of more than one thread ([`run_beside`]). Every level is byte for byte the one a
//! one-thread, in-turn chain bakes; progress reaches the caller on its own thread only, with
//! fractions that never go back.

use super::judge::{bake_level, judge_level, Judged};
use super::level::{fit_level, round_level, topology_of, Level, Rounded, Start};
use super::offset_start::offset_start;
use super::params::{LodParams, Mode};
use super::progress::Reporter;
use crate::mesh::TriMesh;
use crate::report::Progress;
use crate::{Error, Result};

/// The progress window of chain level `rank` of `n`.
fn chain_window(rank: usize, n: usize) -> (f64, f64) {
    (rank as f64 / n as f64, 1.0 / n as f64)
}

/// A chain whose finest level starts from the welded clean input `welded`: every level from
/// the next finer one, finest first (`levels` by rank). Sets `started_from_finer`.
pub(super) fn chain_from_finer(
    level: &Level<'_>,
    levels: &[&LodParams],
    welded: &TriMesh,
    rep: &mut Reporter<'_, '_>,
) -> Result<Vec<Judged>> {
    let mut baked = from_finer_run(level, levels, (0, levels.len()), welded, true, rep)?;
    baked[0].stats.started_from_finer = false;
    Ok(baked)
}

/// Chain levels `first..first + run.len()` of `n` (`run` by rank), each from the next finer
/// one, the first from `finer`; all marked `started_from_finer`.
///
/// A level starts from the next finer level's rounds output, before that level's fit
/// ([`Judged::rounds_output`]): the fit pulls a level onto the input's planes for its shading,
/// and the coarser level's own rounds and fit redo that at its own `d`. So the rest of the run
/// is baked from it while the finer level is fitted, verified and measured ([`fit_level`],
/// [`judge_level`]; beside it when the pool has more than one thread, [`run_beside`]); when
/// the judging reruns the loop exactly (a different rounds output), the rest of the run is
/// baked again from the rerun's. Every level is the one a sequential chain bakes, on any
/// thread count (for speed: a coarse level is mostly its fit and its measurement at `l / 400`,
/// which now run beside the finer level's).
fn from_finer_run(
    level: &Level<'_>,
    run: &[&LodParams],
    (first, n): (usize, usize),
    finer: &TriMesh,
    beside: bool,
    rep: &mut Reporter<'_, '_>,
) -> Result<Vec<Judged>> {
    run_from(level, run, (first, n), Start::Given(finer), beside, rep)
}

/// Chain levels `first..first + run.len()` of `n` (`run` by rank): the first from `start`
/// (marked `started_from_finer` when it is [`Start::Given`]), each next one from the one
/// before it as [`from_finer_run`] describes (marked `started_from_finer`). With `beside`, the
/// rest of the run is baked beside the first level's fit and judging ([`run_beside`]), on one
/// thread; without, in turn.
fn run_from(
    level: &Level<'_>,
    run: &[&LodParams],
    (first, n): (usize, usize),
    start: Start<'_>,
    beside: bool,
    rep: &mut Reporter<'_, '_>,
) -> Result<Vec<Judged>> {
    let p = run[0];
    let from_finer = matches!(start, Start::Given(_));
    let rounded = round_level(level, p, start, rep, chain_window(first, n))?;
    let finish = |rounded: Rounded<'_>, r: &mut Reporter<'_, '_>| {
        let looped = fit_level(rounded, r)?;
        let mut judged = judge_level(level, p, looped, r)?;
        judged.stats.started_from_finer = from_finer;
        Ok(judged)
    };
    let rest = &run[1..];
    if rest.is_empty() {
        return Ok(vec![finish(rounded, rep)?]);
    }
    let (judged, guessed) = if beside {
        // the rest on one thread, so that this level's fit keeps a core and the pool's other
        // thread for its parallel parts
        let guess = rounded.output();
        let bake_rest = |r: &mut Reporter<'_, '_>| {
            from_finer_run(level, rest, (first + 1, n), &guess, false, r)
        };
        let (judged, coarser) = run_beside(rep, |r| finish(rounded, r), bake_rest);
        (judged?, Some((guess, coarser)))
    } else {
        (finish(rounded, rep)?, None)
    };
    let (guess, coarser) = guessed.unzip();
    let coarser = match taken_guess(judged.rounds_output(), guess.as_ref().zip(coarser))? {
        Some(c) => c,
        // in turn, or again from the rerun's rounds output
        None => from_finer_run(
            level,
            rest,
            (first + 1, n),
            judged.rounds_output(),
            beside,
            rep,
        )?,
    };
    let mut baked = Vec::with_capacity(run.len());
    baked.push(judged);
    baked.extend(coarser);
    Ok(baked)
}

/// A chain whose finest level starts from its offset surface (`levels` by rank, finest
/// first). Each coarser level computes its own offset surface, and starts from it when its
/// topology differs from the next finer level's ([`starts_from_finer`]; the loop keeps its
/// start's topology, so a level's is its start's), else from the finer level
/// ([`from_finer_run`]).
///
/// The levels that start from their own offsets, and the levels that follow them from the
/// finer one, depend on nothing but the input: when the pool has more than one thread and the
/// budget holds the finest level and any one coarser level at once ([`beside_fits`]), they are
/// baked beside the finest level ([`run_beside`], [`coarser_own_offsets`]). The levels that
/// follow the finest one start from its rounds output, which it publishes before its fit
/// ([`FinestRounds`]): the thread beside it bakes them from there while the finest level is
/// fitted, verified and measured, as [`from_finer_run`] does for a clean chain (again after it
/// when its judging reran the loop, or when the finest level was done first: then beside each
/// other's fits). Each level's computation is the same whichever thread runs it and whether
/// it runs beside another, so the outputs do not depend on it (for speed: a dirty
/// input's chain bakes its coarser levels' offsets, the levels those close, and the levels
/// that follow the finest one on the second core).
pub(super) fn chain_from_offsets(
    level: &Level<'_>,
    levels: &[&LodParams],
    rep: &mut Reporter<'_, '_>,
) -> Result<Vec<Judged>> {
    let n = levels.len();
    rep.window(0.0, 0.2 * chain_window(0, n).1);
    let finest = offset_start(level, levels[0], rep)?;
    let finest_topology = topology_of(&finest.mesh);
    let rounds = FinestRounds::default();
    let bake_finest = |r: &mut Reporter<'_, '_>| {
        let _done = rounds.done_on_drop();
        let rounded = round_level(
            level,
            levels[0],
            Start::Offset(finest),
            r,
            chain_window(0, n),
        )?;
        let claimed = rounds.publish(rounded.output());
        let fit_and_judge = |r: &mut Reporter<'_, '_>| {
            let looped = fit_level(rounded, r)?;
            judge_level(level, levels[0], looped, r)
        };
        match claimed {
            None => Ok((fit_and_judge(r)?, None)),
            Some((k, finest_rounds)) => {
                let following = |r: &mut Reporter<'_, '_>| {
                    from_finer_run(level, &levels[1..=k], (1, n), finest_rounds, false, r)
                };
                let (judged, following) = run_beside(r, fit_and_judge, following);
                Ok((judged?, Some(following)))
            }
        }
    };
    let coarser = |r: &mut Reporter<'_, '_>| {
        let own = coarser_own_offsets(level, levels, finest_topology, r)?;
        // the leading levels that follow the finest one (`coarser_own_offsets` bakes the rest)
        let k = own.iter().take_while(|o| o.is_none()).count();
        let following = rounds.free(k).map(|finest_rounds| {
            from_finer_run(level, &levels[1..=k], (1, n), finest_rounds, false, r)
        });
        Ok((own, following))
    };
    let ((finest_level, by_a), (own, by_b)) = if n > 1 && beside_fits(level, levels) {
        let (a, b) = run_beside(rep, bake_finest, coarser);
        (a?, b?)
    } else {
        let a = bake_finest(rep)?;
        (a, coarser(rep)?)
    };
    let guessed = by_a.or(by_b).and_then(|f| Some((rounds.published()?, f)));
    let mut baked: Vec<Judged> = vec![finest_level];
    if let Some(run) = taken_guess(baked[0].rounds_output(), guessed)? {
        baked.extend(run);
    }
    let mut own = own.into_iter().skip(baked.len() - 1).peekable();
    while let Some(next) = own.next() {
        if let Some(done) = next {
            baked.push(done);
            continue;
        }
        // a run of levels from the finer one, up to the next level from its own offset
        let first = baked.len();
        let mut len = 1;
        while own.next_if(|o| o.is_none()).is_some() {
            len += 1;
        }
        let finer = baked[first - 1].rounds_output();
        let run = from_finer_run(
            level,
            &levels[first..first + len],
            (first, n),
            finer,
            true,
            rep,
        )?;
        baked.extend(run);
    }
    Ok(baked)
}

/// The finest level's rounds output in [`chain_from_offsets`], and who bakes the levels that
/// follow the finest one from it before its judging: the finest level's thread, beside its
/// fit, when the thread beside it is free by then; else that thread, when it becomes free
/// while the finest level is still being fitted or judged; else (the finest level done first,
/// or a pool of one thread) nobody here, and the caller bakes them after it.
#[derive(Default)]
pub(super) struct FinestRounds {
    /// The rounds output, once the rounds are done.
    rounds: std::sync::OnceLock<TriMesh>,
    state: std::sync::Mutex<FollowingState>,
}

/// Who has done what in [`FinestRounds`].
#[derive(Default)]
struct FollowingState {
    /// The finest level's bake has ended (done, failed or unwound).
    finest_done: bool,
    /// The thread beside the finest level is free, and this many levels follow the finest one.
    free: Option<usize>,
    /// The levels that follow the finest one are being baked from the rounds output.
    claimed: bool,
}

/// Marks the finest level's bake ended in [`FinestRounds`] when it drops, whatever way it ends.
pub(super) struct FinestDone<'r>(&'r FinestRounds);

impl Drop for FinestDone<'_> {
    fn drop(&mut self) {
        if let Ok(mut s) = self.0.state.lock() {
            s.finest_done = true;
        }
    }
}

impl FinestRounds {
    /// A guard that marks the finest level's bake ended when it drops.
    pub(super) fn done_on_drop(&self) -> FinestDone<'_> {
        FinestDone(self)
    }

    /// Publishes the finest level's rounds output; `Some((k, rounds))` when the thread beside
    /// it is already free and `k > 0` levels follow it: the caller bakes them, beside its fit.
    pub(super) fn publish(&self, rounds: TriMesh) -> Option<(usize, &TriMesh)> {
        let _ = self.rounds.set(rounds);
        let mut s = self.state.lock().ok()?;
        let k = s.free.filter(|&k| k > 0 && !s.claimed)?;
        s.claimed = true;
        Some((k, self.rounds.get()?))
    }

    /// The thread beside the finest level is free and `k` levels follow the finest one:
    /// `Some(rounds)` when they are to be baked by it now, from the published rounds output
    /// (the finest level is still being fitted or judged).
    pub(super) fn free(&self, k: usize) -> Option<&TriMesh> {
        let mut s = self.state.lock().ok()?;
        s.free = Some(k);
        if k == 0 || self.rounds.get().is_none() || s.finest_done || s.claimed {
            return None;
        }
        s.claimed = true;
        self.rounds.get()
    }

    /// The published rounds output, if any.
    pub(super) fn published(&self) -> Option<&TriMesh> {
        self.rounds.get()
    }
}

/// The coarser levels baked from a guess of the finer level's rounds output (`guessed`: the
/// guess and their bake), taken when the finer level's judged rounds output `judged` is the
/// guess (`Ok(Some)`; its error too); `Ok(None)`: to be baked again from `judged`. A cancel is
/// a cancel whichever the guess.
fn taken_guess(
    judged: &TriMesh,
    guessed: Option<(&TriMesh, Result<Vec<Judged>>)>,
) -> Result<Option<Vec<Judged>>> {
    match guessed {
        Some((guess, Ok(c))) if *judged == *guess => Ok(Some(c)),
        Some((_, Err(Error::Cancelled))) => Err(Error::Cancelled),
        Some((guess, Err(e))) if *judged == *guess => Err(e),
        _ => Ok(None),
    }
}

/// The coarser levels (ranks `1..`) of [`chain_from_offsets`]: each one's own offset surface,
/// and the bake of those that start from it (`Some`); a level that starts from the next finer
/// one (its offset discarded) is baked here too when that one was (`Some`, from its rounds
/// output: [`from_finer_run`]), else it follows the finest level (`None`).
/// `finest_topology` is the finest level's start's.
fn coarser_own_offsets(
    level: &Level<'_>,
    levels: &[&LodParams],
    finest_topology: (usize, i64),
    rep: &mut Reporter<'_, '_>,
) -> Result<Vec<Option<Judged>>> {
    let n = levels.len();
    let mut finer_topology = finest_topology;
    let mut own: Vec<Option<Judged>> = Vec::with_capacity(n.saturating_sub(1));
    for (rank, p) in levels.iter().enumerate().skip(1) {
        let window = chain_window(rank, n);
        rep.window(window.0, 0.2 * window.1);
        let start = offset_start(level, p, rep)?;
        let topology = topology_of(&start.mesh);
        if starts_from_finer(finer_topology, topology, p, level.mode) {
            drop(start);
            let next = match own.last() {
                Some(Some(finer)) => {
                    let run = &levels[rank..=rank];
                    from_finer_run(level, run, (rank, n), finer.rounds_output(), false, rep)?.pop()
                }
                _ => None,
            };
            own.push(next);
            continue;
        }
        finer_topology = topology;
        own.push(Some(bake_level(
            level,
            p,
            Start::Offset(start),
            rep,
            window,
        )?));
    }
    Ok(own)
}

/// Whether the budget holds the finest level (`levels[0]`) and any one coarser level at once,
/// by their up-front estimates ([`LodParams::memory_estimate`], the input's structures
/// counted twice); `false` when a level has no up-front scale (its admission is measured).
fn beside_fits(level: &Level<'_>, levels: &[&LodParams]) -> bool {
    let (input, mode) = (level.input, level.mode);
    let estimate = |p: &LodParams| {
        p.offset_voxel_scale(input, mode)
            .map(|s| p.memory_estimate(input, s))
    };
    let Some(finest) = estimate(levels[0]) else {
        return false;
    };
    let coarser = levels[1..]
        .iter()
        .try_fold(0.0f64, |m, p| estimate(p).map(|e| m.max(e)));
    coarser.is_some_and(|c| finest + c <= levels[0].memory_budget_bytes as f64)
}

/// Runs `a` on this thread with `rep` and `b` beside it on the thread pool, and returns both
/// results. Progress reaches the caller's callback on this thread only: `b` reports into a
/// relay that this thread forwards while it waits for `b` after `a`; a cancel (the callback's
/// `false`) or an error of `a` stops `b` at its next report. A panic of either propagates.
/// On a pool of one thread, `a` then (unless it failed) `b`, both on this thread with `rep`.
fn run_beside<A, B>(
    rep: &mut Reporter<'_, '_>,
    a: impl FnOnce(&mut Reporter<'_, '_>) -> Result<A>,
    b: impl FnOnce(&mut Reporter<'_, '_>) -> Result<B> + Send,
) -> (Result<A>, Result<B>)
where
    B: Send,
{
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Mutex;
    if rayon::current_num_threads() == 1 {
        let a_result = a(rep);
        let b_result = match a_result {
            Ok(_) => b(rep),
            Err(_) => Err(Error::Cancelled),
        };
        return (a_result, b_result);
    }
    /// Sets its flag when dropped, also by a panic's unwinding.
    struct SetOnDrop<'f>(&'f AtomicBool);
    impl Drop for SetOnDrop<'_> {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
        }
    }
    let stop = AtomicBool::new(false);
    let done = AtomicBool::new(false);
    let latest: Mutex<Option<(String, f64)>> = Mutex::new(None);
    let b_result: Mutex<Option<Result<B>>> = Mutex::new(None);
    let (a_result, went_on) = rayon::in_place_scope(|s| {
        s.spawn(|_| {
            let _done = SetOnDrop(&done);
            let mut relay = |p: Progress<'_>| {
                if let Ok(mut l) = latest.lock() {
                    *l = Some((p.stage.to_string(), p.fraction));
                }
                !stop.load(Ordering::Acquire)
            };
            let r = b(&mut Reporter::new(&mut relay));
            if let Ok(mut slot) = b_result.lock() {
                *slot = Some(r);
            }
        });
        let a_result = a(rep);
        // the caller's callback is not called again once it cancelled or `a` failed
        let mut go_on = a_result.is_ok();
        if !go_on {
            stop.store(true, Ordering::Release);
        }
        while !done.load(Ordering::Acquire) {
            let last = latest.lock().ok().and_then(|mut l| l.take());
            if let (true, Some((stage, fraction))) = (go_on, last) {
                go_on = rep.report_absolute(&stage, fraction);
                if !go_on {
                    stop.store(true, Ordering::Release);
                }
            }
            // run `b` here when no other thread has taken it; else wait a little
            if !matches!(rayon::yield_now(), Some(rayon::Yield::Executed)) {
                std::thread::sleep(std::time::Duration::from_millis(2));
            }
        }
        (a_result, go_on)
    });
    let b_result = match b_result.into_inner().ok().flatten() {
        // a cancel that came after `b`'s last report still cancels
        Some(_) if a_result.is_ok() && !went_on => Err(Error::Cancelled),
        Some(r) => r,
        None => Err(Error::Internal("a chain level did not finish".into())),
    };
    (a_result, b_result)
}

/// Whether a coarser chain level whose own offset surface has topology `own` (components,
/// Euler characteristic: [`topology_of`]) starts from the next finer level, of topology `finer`,
/// instead: only when both are the same.
/// The loop keeps its start's topology, and the coarser offset closes the handles, gaps and
/// small components that the finer level's `d` kept open; from the finer level such a level
/// kept them, with 2–7× the faces of its own bake (measured 2026-11-29 at n_p = 50 / 100:
/// dirty_teapot 644 / 794 faces against 104 / 214, dirty_synth_tree_s1 2354 / 2752 against
/// 332 / 1364). A cage with clearance never does: the finer cage keeps only the finer level's
/// (smaller) clearance, which the coarser level's guard could then never raise to its own.
fn starts_from_finer(
    finer: (usize, i64),
    own: (usize, i64),
    params: &LodParams,
    mode: Mode,
) -> bool {
    !(mode == Mode::Cage && has_clearance(params)) && finer == own
}

/// Whether a cage baked with `p` keeps a positive clearance (its sign does not depend on `d`).
fn has_clearance(p: &LodParams) -> bool {
    p.clearance.resolve(1.0) > 0.0
}
