//! The loop of Alg. 3 on one level: rounds of simplify (Alg. 5) → flow (Alg. 3–4) → align
//! (Alg. 6) under the guard, until convergence (line 17), the face target, a stall (LODs) or
//! `N` rounds, then the input-plane fit; its settings ([`LoopConfig`]) and totals
//! ([`LoopStats`]). The guard keeps every Pro.III guarantee of the start surface.

use std::borrow::Cow;
use std::time::Instant;

use super::params::Mode;
use super::progress::Reporter;
use crate::lowpoly::align::{align_sweep, reference_normals};
use crate::lowpoly::fit::{fit_to_input, FitReport};
use crate::lowpoly::flow::flow_sweep;
use crate::lowpoly::guard::{Guard, InputModel};
use crate::lowpoly::measure::{self, Surface};
use crate::lowpoly::report::{GuardCounts, LodReport, LodStage, SimplifyCounts};
use crate::lowpoly::simplify::{simplify_pass, SimplifyOptions, DRIFT_CAP};
use crate::mesh::{HalfEdgeMesh, TriMesh};
use crate::{Error, Result};

/// Settings of the loop for one level.
#[derive(Debug, Clone, Copy)]
pub(super) struct LoopConfig {
    pub(super) d: f64,
    pub(super) slack: f64,
    pub(super) target_faces: Option<usize>,
    pub(super) max_rounds: u32,
    pub(super) r: f64,
    pub(super) epsilon_abs: f64,
    pub(super) align: bool,
    pub(super) mode: Mode,
    /// Cage mode: the clearance the guard keeps (model units); 0 for LODs.
    pub(super) clearance: f64,
    /// Run the input-plane fit after the loop (LODs with `fit_to_input`).
    pub(super) fit: bool,
}

/// Relative margin the guard adds to a cage's clearance: [`guard_clearance`].
const CLEARANCE_MARGIN: f64 = 1e-9;

/// The clearance the guard keeps for a cage asked to keep `c`: `c · (1 + `[`CLEARANCE_MARGIN`]`)`.
/// The guard and the independent measurement (`verify::CageInput::min_distance`) compute the
/// same exact distance by different routes, whose roundings differ by a few ulps; a face the
/// guard accepts at exactly `c` (the flow pulls vertices to that distance) could then measure
/// one ulp below it and the cage report `clearance_kept = false` (2026-12-07: the
/// non-manifold cubes at n_p = 100, measured 0.049999999999999996 d for 0.05 d). The margin
/// is far above the roundings (≈ 1e-13 of `c` at n_p = 100) and far below anything a user can
/// see.
pub(super) fn guard_clearance(c: f64) -> f64 {
    c * (1.0 + CLEARANCE_MARGIN)
}

/// Totals of one run of the loop.
#[derive(Debug, Default)]
pub(super) struct LoopStats {
    simplify_s: f64,
    /// Seconds of the first simplification pass (the one on the dense offset surface).
    simplify_first_s: f64,
    flow_s: f64,
    align_s: f64,
    converge_s: f64,
    rounds: u64,
    faces_per_round: Vec<u64>,
    simplify: SimplifyCounts,
    guard: GuardCounts,
    converged: bool,
    stalled: bool,
    flow_motion: f64,
    align_motion: f64,
    target_met: bool,
    relaxations: u64,
    /// Seconds of the input-plane fit (with the measurement of its safety revert).
    pub(super) fit_s: f64,
    fit: FitReport,
    pub(super) fit_reverted: bool,
    /// The fitted LOD's one-sided distances over `l` (in→out, out→in), kept or not.
    pub(super) fit_sides: Option<[f64; 2]>,
    /// The loop's output before the fit, kept for the safety revert.
    pub(super) prefit: Option<TriMesh>,
}

impl LoopStats {
    pub(super) fn write(&self, s: &mut LodReport) {
        s.stages.push(LodStage::Simplify, self.simplify_s);
        s.stages.push(LodStage::Flow, self.flow_s);
        s.stages.push(LodStage::Align, self.align_s);
        s.stages.push(LodStage::Convergence, self.converge_s);
        s.stages.push(LodStage::Fit, self.fit_s);
        s.simplify_first_pass_seconds = self.simplify_first_s;
        s.rounds = self.rounds;
        s.faces_per_round = self.faces_per_round.clone();
        s.simplify = self.simplify;
        s.guard = self.guard;
        s.target_met = self.target_met;
        s.target_relaxations = self.relaxations;
        s.converged = self.converged;
        s.stalled = self.stalled;
        s.flow_motion = self.flow_motion;
        s.align_motion = self.align_motion;
        s.fit_moves = self.fit.moves;
        s.fit_flips = self.fit.flips;
        s.fit_motion = self.fit.motion;
        s.fit_uncovering_refused = self.fit.uncovering_refused;
        s.fit_reverted = self.fit_reverted;
        s.fit_sides_rel = self.fit_sides;
    }
}

/// A LOD's loop also ends when [`STALL_ROUNDS`] rounds in a row made no new smallest face
/// count (for speed, 2026-11-29): the rounds after that only move vertices (flow and
/// alignment) — on the corpus most rounds after about 10 changed the count by 0–2 around a
/// plateau, and a chain's coarser levels ran all 50 at one count. Measured with the shared
/// harness against MeshLab QEM and meshoptimizer at equal faces on the 23 corpus meshes
/// (docs/benchmarks/lod.md, 2026-11-29): n_p = 100 faces +1.7%, normal difference
/// 0.0804 → 0.0793, PSNR 22.39 → 22.57 dB, Hausdorff 3.43 → 3.35 % of l; n_p = 200 faces
/// +0.4%, 0.0479 → 0.0477, 25.37 → 25.43 dB, 2.64 → 2.59 %; median wall at n_p = 100
/// 0.67 → 0.62 s. With a face target the loop goes on relaxing its bound instead. Cages
/// stop the same way since 2026-12-08: their rounds after the plateau only moved vertices
/// under the clearance guard, 80% of a cage's time (ogre at n_p = 50: 50 rounds, 58 s, faces
/// at 288 from round 3; now 8 rounds, 10 s). Measured with the shared harness on the 23 corpus
/// meshes at n_p = 50 (docs/benchmarks/cage.md): total time 369 → 72 s, median 10.0 → 1.9 s,
/// faces +1.1%, PSNR 19.12 → 19.05 dB, normal difference 0.1086 → 0.1088, Hausdorff 5.38 →
/// 5.42 % of l; 23/23 valid cages that keep the clearance.
pub const STALL_ROUNDS: usize = 5;

/// Whether the last [`STALL_ROUNDS`] rounds' face counts are all at or above the smallest
/// count of the rounds before them.
pub(super) fn has_stalled(faces_per_round: &[u64]) -> bool {
    let s = STALL_ROUNDS;
    if faces_per_round.len() <= s {
        return false;
    }
    let (before, last) = faces_per_round.split_at(faces_per_round.len() - s);
    let best = before.iter().copied().min().unwrap_or(u64::MAX);
    last.iter().all(|&f| f >= best)
}

/// Whether round `i`'s simplification tries the next candidate position after a guard
/// refusal (`SimplifyOptions::retry_guard`): in a cage with a clearance, from the second round
/// on. There a refusal is mostly the clearance or contact, which depend on where along the
/// edge the vertex lands; the first pass, on the dense offset surface, does not retry (it is
/// most of a bake's time, and retried placements there led small cages into worse ends).
/// Measured 2026-12-07 at n_p = 25 with 0.05 d: retrying in every round took fandisk 76 → 74
/// faces and suzanne 122 → 108 but thingi10k 42722 28 → 44 (34 without clearance); from the
/// second round on 72, 106 and 30, all within the +20% faces a cage's clearance may cost over
/// the cage without clearance
/// (docs/benchmarks/cage.md, for all 69 corpus cages). LODs and cages without a
/// clearance never retry, and their outputs do not change.
pub(super) fn retries_guard_refusals(cfg: &LoopConfig, i: u32) -> bool {
    cfg.mode == Mode::Cage && cfg.clearance > 0.0 && i >= 1
}

/// Alg. 3 line 17: the sampled two-sided Hausdorff distance between the meshes before and
/// after a round is below `ε·l`. Decided with early exits (the first far sample settles it).
fn has_converged(before: &TriMesh, after: &TriMesh, cfg: &LoopConfig) -> bool {
    let eps = cfg.epsilon_abs;
    let a = Surface::new(after);
    if measure::one_sided_exceeds(before.positions(), before.triangles(), &a, cfg.d, 8, eps) {
        return false;
    }
    let b = Surface::new(before);
    !measure::one_sided_exceeds(after.positions(), after.triangles(), &b, cfg.d, 8, eps)
}

/// Alg. 3 from `start` (watertight, manifold, intersection-free; in cage mode enclosing the
/// input without touching it).
pub(super) fn optimize(
    start: &TriMesh,
    model: &InputModel,
    cfg: &LoopConfig,
    exact_only: bool,
    rep: &mut Reporter<'_, '_>,
) -> Result<(TriMesh, LoopStats)> {
    let (g, ls) = optimize_rounds(start, model, cfg, exact_only, rep)?;
    optimize_fit(g, cfg, ls, rep)
}

/// The rounds of [`optimize`] (simplify, flow, align until converged, stalled, at the target
/// or after `N` rounds): the guard holding their output, and their totals.
pub(super) fn optimize_rounds<'m>(
    start: &TriMesh,
    model: &'m InputModel,
    cfg: &LoopConfig,
    exact_only: bool,
    rep: &mut Reporter<'_, '_>,
) -> Result<(Guard<'m>, LoopStats)> {
    let he = HalfEdgeMesh::from_trimesh(start)
        .map_err(|e| Error::Internal(format!("the start surface is not manifold: {e}")))?;
    let mut g = Guard::new(he, model, cfg.mode == Mode::Cage);
    g.set_exact_only(exact_only);
    g.set_clearance(guard_clearance(cfg.clearance));
    let mut ls = LoopStats::default();
    let mut sopt = SimplifyOptions {
        d: cfg.d,
        target_faces: cfg.target_faces,
        slack: cfg.slack,
        spacing: cfg.d,
        retry_guard: false,
    };
    let rounds = cfg.max_rounds;
    for i in 0..rounds {
        let frac = |x: f64| (i as f64 + x) / rounds as f64;
        rep.check("simplify", frac(0.0))?;
        sopt.retry_guard = retries_guard_refusals(cfg, i);
        let before = round_start(i, start, &g);
        let t0 = Instant::now();
        let sr = {
            let mut kg = |x: f64| rep.report("simplify", frac(0.5 * x));
            simplify_pass(&mut g, &sopt, &mut kg)?
        };
        ls.simplify.add(&sr);
        ls.simplify_s += t0.elapsed().as_secs_f64();
        if i == 0 {
            ls.simplify_first_s = ls.simplify_s;
        }
        let reference = reference_normals(&g);
        let t0 = Instant::now();
        {
            let mut kg = |x: f64| rep.report("flow", frac(0.5 + 0.25 * x));
            let fr = flow_sweep(&mut g, cfg.r, &mut kg)?;
            ls.flow_motion += fr.total_motion;
        }
        ls.flow_s += t0.elapsed().as_secs_f64();
        if cfg.align {
            let t0 = Instant::now();
            let mut kg = |x: f64| rep.report("align", frac(0.75 + 0.25 * x));
            let ar = align_sweep(&mut g, &reference, cfg.d, DRIFT_CAP * cfg.d, &mut kg)?;
            ls.align_motion += ar.total_motion;
            ls.align_s += t0.elapsed().as_secs_f64();
        }
        ls.rounds += 1;
        ls.faces_per_round.push(g.mesh().face_count() as u64);
        let t0 = Instant::now();
        let converged = has_converged(&before, &g.mesh().to_trimesh(), cfg);
        ls.converged = converged;
        ls.converge_s += t0.elapsed().as_secs_f64();
        ls.target_met = cfg.target_faces.is_some_and(|n| g.mesh().face_count() <= n);
        if ls.target_met {
            break;
        }
        if cfg.target_faces.is_some() && (converged || sr.collapses == 0) {
            // Pro.I with a face target: relax the per-collapse bound until it is reached.
            sopt.d *= 2.0;
            sopt.slack = sopt.slack.max(sopt.d);
            ls.relaxations += 1;
            continue;
        }
        if converged {
            break;
        }
        if cfg.target_faces.is_none() && has_stalled(&ls.faces_per_round) {
            ls.stalled = true;
            break;
        }
    }
    Ok((g, ls))
}

/// The end of [`optimize`] after its rounds: the input-plane fit when `cfg.fit` (the rounds'
/// output kept in `ls.prefit` for the safety revert), then the output and the totals.
pub(super) fn optimize_fit(
    mut g: Guard<'_>,
    cfg: &LoopConfig,
    mut ls: LoopStats,
    rep: &mut Reporter<'_, '_>,
) -> Result<(TriMesh, LoopStats)> {
    if cfg.fit {
        rep.check("fit", 1.0)?;
        let t0 = Instant::now();
        ls.prefit = Some(g.mesh().to_trimesh());
        let mut kg = |_: f64| rep.report("fit", 1.0);
        ls.fit = fit_to_input(&mut g, cfg.d, &mut kg)?;
        ls.fit_s += t0.elapsed().as_secs_f64();
    }
    ls.guard = g.stats;
    Ok((g.mesh().to_trimesh(), ls))
}

/// The surface round `i` starts from, for the convergence test: round 0's is `start` itself
/// (the guard's mesh is `start`'s half-edge form, unmodified, whose `to_trimesh` is `start`
/// exactly), borrowed rather than copied — 24 B per offset face less in the first pass, where
/// a bake's memory peaks; later rounds copy the guard's mesh.
fn round_start<'s>(i: u32, start: &'s TriMesh, g: &Guard<'_>) -> Cow<'s, TriMesh> {
    if i == 0 {
        debug_assert!(
            g.mesh().to_trimesh() == *start,
            "round 0 starts from `start`"
        );
        Cow::Borrowed(start)
    } else {
        Cow::Owned(g.mesh().to_trimesh())
    }
}
