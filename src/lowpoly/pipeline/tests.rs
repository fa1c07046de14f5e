//! Tests of the pipeline across its files: chain scheduling, budgets and the start, the loop's
//! stall and guard retries.

use super::budget::*;
use super::chain::*;
use super::judge::*;
use super::level::*;
use super::optimize::*;
use super::params::*;
use super::progress::*;
use super::run::*;
use super::start::*;
use crate::lowpoly::guard::InputModel;
use crate::mesh::TriMesh;
use crate::report::Progress;
use crate::Error;

/// The unit cube (the guard tests' shape).
fn cube() -> TriMesh {
    crate::lowpoly::guard::tests::cube(1.0, 0.0)
}

/// The levels that follow a dirty chain's finest level are baked from its rounds output
/// by exactly one thread: the finest level's when the thread beside it was free first,
/// that thread when it became free after the rounds and before the finest level was done,
/// else nobody (the caller, after the finest level).
#[test]
fn the_levels_following_the_finest_are_claimed_once() {
    let rounds = cube();
    // the thread beside is free first: the finest level's thread bakes them
    let f = FinestRounds::default();
    assert!(f.free(2).is_none());
    assert_eq!(f.publish(rounds.clone()), Some((2, &rounds)));
    // the rounds first: the thread beside bakes them when it becomes free
    let f = FinestRounds::default();
    assert!(f.publish(rounds.clone()).is_none());
    assert_eq!(f.free(1), Some(&rounds));
    assert!(f.free(1).is_none(), "claimed once");
    // the finest level done first, or no level following it: nobody
    let f = FinestRounds::default();
    {
        let _done = f.done_on_drop();
        assert!(f.publish(rounds.clone()).is_none());
    }
    assert!(f.free(2).is_none());
    let f = FinestRounds::default();
    assert!(f.free(0).is_none());
    assert!(f.publish(rounds.clone()).is_none());
    assert_eq!(f.published(), Some(&rounds));
}

/// A coarser chain level starts from the next finer level's rounds output, before that
/// level's fit (since 2026-12-06): the chain's n_p = 50 level is the bake of the
/// n_p = 100 level's rounds output, whose fit and judging it ran beside.
#[test]
fn a_chain_level_is_baked_from_the_finer_levels_rounds_output() {
    let m = crate::spatial::winding::tests::torus(48, 16);
    let params = LodParams::default();
    let chain = run_chain(&m, &[50.0, 100.0], &params, Mode::Lod, &mut |_| true).unwrap();
    assert!(chain[0].1.started_from_finer && chain[1].1.started_from_input);
    let model = InputModel::new_with_stop(&m, false, &mut || true).unwrap();
    let level = Level::new(&model, &m, Mode::Lod);
    let mut prog = |_: Progress<'_>| true;
    let mut rep = Reporter::new(&mut prog);
    let p = |s: f64| LodParams {
        screen_size: s,
        ..params.clone()
    };
    let welded = choose_start(&m, &p(100.0), Mode::Lod, &mut rep)
        .unwrap()
        .unwrap();
    let finer = round_level(
        &level,
        &p(100.0),
        Start::Given(&welded),
        &mut rep,
        (0.0, 1.0),
    );
    let finer = finer.unwrap();
    let start = finer.output();
    let fitted = judge_level(
        &level,
        &p(100.0),
        fit_level(finer, &mut rep).unwrap(),
        &mut rep,
    );
    let fitted = fitted.unwrap();
    assert_eq!(fitted.mesh, chain[1].0);
    assert_eq!(*fitted.rounds_output(), start);
    assert_ne!(fitted.mesh, start, "the fit moved the finer level");
    let coarse = bake_level(&level, &p(50.0), Start::Given(&start), &mut rep, (0.0, 1.0));
    assert_eq!(coarse.unwrap().mesh, chain[0].0);
}

/// A LOD whose up-front estimate fits no voxel scale: admitted by measurement with its
/// measured estimate within the budget, or `LimitExceeded`.
fn assert_measured_or_refused(m: &TriMesh, p: &LodParams) {
    assert_eq!(p.offset_voxel_scale(m, Mode::Lod), None);
    match run(m, p, Mode::Lod, &mut |_| true) {
        Ok((lod, rep)) => {
            let measured = rep.measured_estimate_bytes;
            if !rep.started_from_input {
                assert!(measured.is_some_and(|b| b <= p.memory_budget_bytes as f64));
            }
            assert!(rep.verified.all_hold(), "{:?}", rep.verified);
            assert!(lod.triangle_count() >= 4);
        }
        Err(Error::LimitExceeded(_)) => {}
        Err(e) => panic!("{e}"),
    }
}

/// The budget decision honours the start taken (since 2026-11-28): a clean
/// input whose offset fits no voxel scale still bakes from itself when its own estimate
/// fits; forced to the offset, or as a cage, it is refused before any work; an input start
/// that does not fit is refused (`Input`) or not taken (`Auto`).
#[test]
fn a_clean_input_start_has_its_own_budget() {
    let m = cube();
    let auto = LodParams {
        screen_size: 10.0,
        max_rounds: 2,
        ..LodParams::default()
    };
    let from_input = auto.input_start_estimate(&m);
    assert!(from_input >= fit_samples(&m, m.bbox_diagonal() / 10.0) * BYTES_PER_FIT_SAMPLE);
    assert!(from_input < auto.memory_estimate(&m, MAX_LOD_VOXEL_SCALE));
    // between the two estimates: only the input start fits
    let p = LodParams {
        memory_budget_bytes: from_input.ceil() as u64,
        ..auto.clone()
    };
    assert_eq!(p.offset_voxel_scale(&m, Mode::Lod), None);
    assert!(p.validate(&m).is_ok());
    assert!(p.lod_starts_from_input(&m).unwrap());
    let (lod, rep) = run(&m, &p, Mode::Lod, &mut |_| true).unwrap();
    assert!(rep.started_from_input);
    assert_eq!(rep.offset_voxel_scale, None);
    assert!(rep.verified.all_hold(), "{:?}", rep.verified);
    assert!(lod.triangle_count() >= 4);
    let chain = run_chain(&m, &[10.0, 5.0], &p, Mode::Lod, &mut |_| true).unwrap();
    assert!(chain[0].1.started_from_input);
    // as a cage: refused before any work
    let cage = LodParams {
        start: LodStart::Auto,
        ..p.clone()
    };
    assert!(matches!(
        run(&m, &cage, Mode::Cage, &mut |_| true),
        Err(Error::LimitExceeded(_))
    ));
    // forced to the offset: the measured admission decides (2026-11-29)
    let offset = LodParams {
        start: LodStart::Offset,
        ..p.clone()
    };
    assert_measured_or_refused(&m, &offset);
    // below the input start's estimate too: refused by validate whatever the start, unless
    // the measured admission may still take the offset
    let tight = LodParams {
        memory_budget_bytes: from_input as u64 - 1,
        ..auto.clone()
    };
    assert_eq!(
        tight.validate(&m).is_ok(),
        tight.measured_admission_may_fit(&m)
    );
    assert_measured_or_refused(&m, &tight);
    // an input start over the budget: `Input` is refused before the clean-input check
    let forced = LodParams {
        start: LodStart::Input,
        memory_budget_bytes: from_input as u64 - 1,
        screen_size: 10.0,
        ..auto.clone()
    };
    assert!(matches!(
        forced.lod_starts_from_input(&m),
        Err(Error::LimitExceeded(_))
    ));
}

/// Guard refusals are retried only by a cage with a clearance, and not in its first pass;
/// the guard keeps the clearance with its margin, and no clearance stays none.
#[test]
fn only_cages_with_a_clearance_retry_guard_refusals_after_the_first_pass() {
    let cfg = |mode, clearance| LoopConfig {
        d: 1.0,
        slack: 0.0,
        target_faces: None,
        max_rounds: 50,
        r: 0.5,
        epsilon_abs: 1e-4,
        align: true,
        mode,
        clearance,
        fit: false,
    };
    for i in 0..3 {
        assert_eq!(retries_guard_refusals(&cfg(Mode::Cage, 0.05), i), i >= 1);
        assert!(!retries_guard_refusals(&cfg(Mode::Cage, 0.0), i));
        assert!(!retries_guard_refusals(&cfg(Mode::Lod, 0.0), i));
    }
    assert_eq!(guard_clearance(0.0), 0.0);
    let c = 0.05;
    assert!(guard_clearance(c) > c && guard_clearance(c) <= c * (1.0 + 2e-9));
}

#[test]
fn the_loop_stalls_after_rounds_without_a_new_smallest_face_count() {
    let s = STALL_ROUNDS as u64;
    // still falling, or too few rounds to tell
    assert!(!has_stalled(&(0..2 * s).rev().collect::<Vec<_>>()));
    assert!(!has_stalled(&[100; STALL_ROUNDS]));
    // a plateau (with ups and downs above its floor) of STALL_ROUNDS rounds
    let mut f = vec![120, 100];
    f.extend((0..s).map(|i| 100 + 2 * (i % 2)));
    assert!(has_stalled(&f));
    // a new low in the last rounds resets it
    *f.last_mut().unwrap() = 99;
    assert!(!has_stalled(&f));
}

#[test]
fn a_budget_between_voxel_scales_coarsens_the_lod_and_refuses_the_cage() {
    let m = cube();
    let base = LodParams {
        screen_size: 10.0,
        max_rounds: 2,
        fit_to_input: false,
        // the clean cube would start from itself under `Auto`
        start: LodStart::Offset,
        ..LodParams::default()
    };
    // the fit's coverage samples are counted whatever the voxel
    let fit = LodParams {
        fit_to_input: true,
        ..base.clone()
    };
    let samples = fit_samples(&m, m.bbox_diagonal() / 10.0);
    assert!(samples >= 12.0 * 3.0 + 8.0);
    for &s in &LOD_VOXEL_SCALES {
        assert!(fit.memory_estimate(&m, s) >= samples * BYTES_PER_FIT_SAMPLE);
        assert!(fit.memory_estimate(&m, s) >= base.memory_estimate(&m, s));
    }
    // the estimate falls with the voxel scale (faces ∝ 1/scale²)
    for w in LOD_VOXEL_SCALES.windows(2) {
        assert!(base.memory_estimate(&m, w[1]) < base.memory_estimate(&m, w[0]));
    }
    let p = LodParams {
        memory_budget_bytes: base.memory_estimate(&m, 1.5).ceil() as u64,
        ..base.clone()
    };
    // below LOD_COARSE_VOXEL_MIN_SCREEN_SIZE a LOD starts from scale 1: the budget picks 1.5
    assert_eq!(p.offset_voxel_scale(&m, Mode::Lod), Some(1.5));
    assert_eq!(p.voxel_scale_from(&m, Mode::Lod, 1.75), Some(1.75));
    assert_eq!(p.offset_voxel_scale(&m, Mode::Cage), None);
    let (lod, rep) = run(&m, &p, Mode::Lod, &mut |_| true).unwrap();
    assert_eq!(rep.offset_voxel_scale, Some(1.5));
    assert!(rep.verified.all_hold(), "{:?}", rep.verified);
    assert!(lod.triangle_count() >= 4);
    // cages keep the default voxel: refused before any work
    assert!(matches!(
        run(&m, &p, Mode::Cage, &mut |_| true),
        Err(Error::LimitExceeded(_))
    ));
    // below the coarsest scale's estimate: the measured admission decides (2026-11-29);
    // below what is known before any offset (the input's structures): refused by validate
    let tight = LodParams {
        memory_budget_bytes: base.memory_estimate(&m, 2.0) as u64 - 1,
        ..base.clone()
    };
    assert_eq!(tight.offset_voxel_scale(&m, Mode::Lod), None);
    assert_measured_or_refused(&m, &tight);
    let tiny = LodParams {
        memory_budget_bytes: (m.triangle_count() as f64 * BYTES_PER_INPUT_FACE) as u64 - 1,
        ..base.clone()
    };
    assert!(!tiny.measured_admission_may_fit(&m));
    assert!(matches!(tiny.validate(&m), Err(Error::LimitExceeded(_))));
    // the default budget keeps the default voxel: 1 below the thresholds,
    // LOD_MEDIUM_VOXEL_SCALE and LOD_VOXEL_SCALE from them on (cages: 1)
    let (_, rep) = run(&m, &base, Mode::Lod, &mut |_| true).unwrap();
    assert_eq!(rep.offset_voxel_scale, None);
    for (threshold, scale) in [
        (LOD_COARSE_VOXEL_MIN_SCREEN_SIZE, LOD_VOXEL_SCALE),
        (LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE, LOD_MEDIUM_VOXEL_SCALE),
    ] {
        let at = LodParams {
            screen_size: threshold,
            ..base.clone()
        };
        assert_eq!(at.offset_voxel_scale(&m, Mode::Lod), Some(scale));
        assert_eq!(at.offset_voxel_scale(&m, Mode::Cage), Some(1.0));
    }
    // a requested scale replaces the rule (here: scale 1 below the threshold; also a scale
    // off the list), the budget's fallback
    // to the coarser listed scales still applies, cages ignore it
    let asked = |s: f64, budget: u64| LodParams {
        offset_voxel_scale: Some(s),
        memory_budget_bytes: budget,
        ..base.clone()
    };
    let roomy = 1u64 << 40;
    assert_eq!(
        asked(1.0, roomy).offset_voxel_scale(&m, Mode::Lod),
        Some(1.0)
    );
    assert_eq!(
        asked(1.1, roomy).offset_voxel_scale(&m, Mode::Lod),
        Some(1.1)
    );
    assert_eq!(
        asked(1.1, p.memory_budget_bytes).offset_voxel_scale(&m, Mode::Lod),
        Some(1.5)
    );
    assert_eq!(
        asked(1.1, roomy).offset_voxel_scale(&m, Mode::Cage),
        Some(1.0)
    );
    assert!(asked(2.0, roomy).validate(&m).is_ok());
    for bad in [0.0, -1.0, 2.01, f64::NAN, f64::INFINITY] {
        match asked(bad, roomy).validate(&m) {
            Err(Error::InvalidArgument(msg)) => assert!(msg.contains("offset_voxel_scale")),
            other => panic!("scale {bad}: {other:?}"),
        }
    }
}
