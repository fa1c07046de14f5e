//! Tests of the TFW C API: versioned parameter fields, obstacles and wave counts from C
//! against the Rust API, and thread-count independence of a solve through it.

use super::result::*;
use super::scene::*;
use super::solve::imp;
use super::solve::*;
use super::types::*;
use crate::ffi::boundary::full_size;
use crate::ffi::common::PleatStatus;
use crate::ffi::{
    pleat_cwf_copy_amplitude, pleat_cwf_destroy, pleat_mesh_copy_positions_f64, pleat_mesh_destroy,
    pleat_set_thread_count,
};
use std::ffi::CString;
use std::ptr::null_mut;

/// `params` as `pleat_tfw_solve` reads them: versioned (a shorter `struct_size` gets the
/// defaults beyond it), then validated.
fn read(p: &PleatTfwParams) -> crate::Result<crate::tfw::TfwParams> {
    // SAFETY: `p` is a live struct of at least `p.struct_size` bytes.
    let v = unsafe { crate::ffi::boundary::read_versioned(p, "params") }?;
    imp::params(&v)
}

/// Base positions, amplitudes and the history of a small sheet solved through the C API
/// on `threads` worker threads.
fn solve_small(threads: u32, qp: u32) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let json =
        CString::new(crate::tfw::Scene::stretched_sheet(9, 4, 0.05).to_json_string()).unwrap();
    let mut params = pleat_tfw_params_default();
    params.sqp_max_iterations = 10;
    params.qp = qp;
    // SAFETY: valid pointers throughout; every handle is destroyed once.
    unsafe {
        assert_eq!(pleat_set_thread_count(threads), PleatStatus::Ok);
        let mut scene = null_mut();
        assert_eq!(
            pleat_tfw_scene_from_json(json.as_ptr(), &mut scene),
            PleatStatus::Ok
        );
        let mut result = null_mut();
        let st = pleat_tfw_solve(scene, &params, None, null_mut(), &mut result);
        assert_eq!(st, PleatStatus::Ok);
        let mut stats = PleatTfwStats {
            struct_size: full_size::<PleatTfwStats>(),
            ..Default::default()
        };
        assert_eq!(
            pleat_tfw_result_get_stats(result, &mut stats),
            PleatStatus::Ok
        );
        let (nv, n) = (stats.vertex_count as usize, stats.sqp_iterations as usize);
        assert_eq!(pleat_tfw_result_history_count(result), n);
        let mut history = vec![0.0; 4 * n];
        let st = pleat_tfw_result_copy_history(result, history.as_mut_ptr(), n);
        assert_eq!(st, PleatStatus::Ok);
        let (mut mesh, mut cwf) = (null_mut(), null_mut());
        assert_eq!(
            pleat_tfw_result_base_mesh(result, &mut mesh),
            PleatStatus::Ok
        );
        assert_eq!(pleat_tfw_result_cwf(result, &mut cwf), PleatStatus::Ok);
        let mut pos = vec![0.0; 3 * nv];
        let st = pleat_mesh_copy_positions_f64(mesh, pos.as_mut_ptr(), nv, 0);
        assert_eq!(st, PleatStatus::Ok);
        let mut amp = vec![0.0; nv];
        assert_eq!(
            pleat_cwf_copy_amplitude(cwf, amp.as_mut_ptr(), nv),
            PleatStatus::Ok
        );
        assert!(amp.iter().fold(0.0f64, |m, &a| m.max(a)) == stats.peak_amplitude);
        pleat_mesh_destroy(mesh);
        pleat_cwf_destroy(cwf);
        pleat_tfw_result_destroy(result);
        pleat_tfw_scene_destroy(scene);
        assert_eq!(pleat_set_thread_count(0), PleatStatus::Ok);
        (pos, amp, history)
    }
}

/// `curvature` (appended 2026-11-27): read from a full struct, defaulted for an older,
/// shorter one, and an unknown value is rejected with a message naming the field.
#[test]
fn curvature_field_is_versioned_and_checked() {
    use crate::tfw::curvature::CurvatureMethod;
    let mut p = pleat_tfw_params_default();
    assert_eq!(p.curvature, PLEAT_TFW_CURVATURE_QUADRIC_FIT);
    p.curvature = PLEAT_TFW_CURVATURE_VERTEX_NORMALS;
    let full = read(&p).unwrap();
    assert_eq!(full.curvature, CurvatureMethod::VertexNormals);
    p.struct_size = std::mem::offset_of!(PleatTfwParams, curvature) as u32;
    let old = read(&p).unwrap();
    assert_eq!(old.curvature, CurvatureMethod::QuadricFit);
    p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
    p.curvature = 7;
    let e = read(&p).unwrap_err().to_string();
    assert!(e.contains("params->curvature"), "{e}");
}

/// `qp` (appended 2026-11-27): read from a full struct, defaulted for an older, shorter
/// one, an unknown value rejected with a message naming the field.
#[test]
fn qp_field_is_versioned_and_checked() {
    use crate::tfw::QpMethod;
    let mut p = pleat_tfw_params_default();
    let default = crate::tfw::TfwParams::default().sqp.qp;
    assert_eq!(read(&p).unwrap().sqp.qp, default);
    p.qp = PLEAT_TFW_QP_PROJECTED_NEWTON;
    assert_eq!(read(&p).unwrap().sqp.qp, QpMethod::ProjectedNewton);
    p.qp = PLEAT_TFW_QP_CLARABEL;
    assert_eq!(read(&p).unwrap().sqp.qp, QpMethod::Clarabel);
    p.qp = if default == QpMethod::Clarabel {
        PLEAT_TFW_QP_PROJECTED_NEWTON
    } else {
        PLEAT_TFW_QP_CLARABEL
    };
    p.struct_size = std::mem::offset_of!(PleatTfwParams, qp) as u32;
    assert_eq!(read(&p).unwrap().sqp.qp, default);
    p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
    p.qp = 9;
    let e = read(&p).unwrap_err().to_string();
    assert!(e.contains("params->qp"), "{e}");
}

/// `snap_periods` (appended 2026-11-29): read from a full struct, defaulted (off) for an
/// older, shorter one, a value other than 0 or 1 rejected with a message naming the field.
#[test]
fn snap_periods_field_is_versioned_and_checked() {
    let mut p = pleat_tfw_params_default();
    assert_eq!(p.snap_periods, 0);
    assert!(!read(&p).unwrap().snap_periods);
    p.snap_periods = 1;
    assert!(read(&p).unwrap().snap_periods);
    p.struct_size = std::mem::offset_of!(PleatTfwParams, snap_periods) as u32;
    assert!(!read(&p).unwrap().snap_periods);
    p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
    p.snap_periods = 2;
    let e = read(&p).unwrap_err().to_string();
    assert!(e.contains("params->snap_periods"), "{e}");
}

/// `valley_search` (appended 2026-11-29): on by default and for an older, shorter
/// struct, off with 0, a value other than 0 or 1 rejected naming the field.
#[test]
fn valley_search_field_is_versioned_and_checked() {
    let mut p = pleat_tfw_params_default();
    assert_eq!(p.valley_search, 1);
    assert!(read(&p).unwrap().sqp.valley_search);
    p.valley_search = 0;
    assert!(!read(&p).unwrap().sqp.valley_search);
    p.struct_size = std::mem::offset_of!(PleatTfwParams, valley_search) as u32;
    assert!(read(&p).unwrap().sqp.valley_search);
    p.struct_size = std::mem::size_of::<PleatTfwParams>() as u32;
    p.valley_search = 2;
    let e = read(&p).unwrap_err().to_string();
    assert!(e.contains("params->valley_search"), "{e}");
}

/// `pleat_tfw_scene_add_obstacle` gives the scene a JSON `obstacles` entry gives, takes
/// the defaults for an older (shorter) struct, and rejects bad fields naming them with the
/// scene unchanged.
#[test]
fn obstacles_from_c_match_the_scene_file() {
    use crate::tfw::{Obstacle, ObstacleShape, DEFAULT_OBSTACLE_STIFFNESS};
    assert_eq!(
        pleat_tfw_obstacle_default().stiffness,
        DEFAULT_OBSTACLE_STIFFNESS
    );
    let json =
        CString::new(crate::tfw::Scene::stretched_sheet(5, 3, 0.05).to_json_string()).unwrap();
    // SAFETY: valid pointers throughout; the scene is destroyed once.
    unsafe {
        let mut scene = null_mut();
        assert_eq!(
            pleat_tfw_scene_from_json(json.as_ptr(), &mut scene),
            PleatStatus::Ok
        );
        let mut o = pleat_tfw_obstacle_default();
        o.kind = PLEAT_TFW_OBSTACLE_SPHERE;
        o.point = [0.1, 0.0, -0.3];
        o.radius = 0.25;
        o.margin = 1e-3;
        let st = pleat_tfw_scene_add_obstacle(scene, &o);
        assert_eq!(st, PleatStatus::Ok);
        let mut old = pleat_tfw_obstacle_default();
        old.normal = [0.0, 1.0, 0.0];
        old.stiffness = 5.0;
        old.struct_size = std::mem::offset_of!(PleatTfwObstacle, stiffness) as u32;
        assert_eq!(pleat_tfw_scene_add_obstacle(scene, &old), PleatStatus::Ok);
        let expected = vec![
            Obstacle {
                shape: ObstacleShape::Sphere {
                    centre: [0.1, 0.0, -0.3],
                    radius: 0.25,
                },
                stiffness: DEFAULT_OBSTACLE_STIFFNESS,
                margin: 1e-3,
            },
            Obstacle {
                shape: ObstacleShape::Plane {
                    point: [0.0; 3],
                    normal: [0.0, 1.0, 0.0],
                },
                stiffness: DEFAULT_OBSTACLE_STIFFNESS,
                margin: 0.0,
            },
        ];
        assert_eq!((*scene).scene.obstacles, expected);
        let bad = [
            (PleatTfwObstacle { kind: 5, ..o }, "obstacle->kind"),
            (PleatTfwObstacle { radius: 0.0, ..o }, "obstacles[2].radius"),
            (
                PleatTfwObstacle {
                    point: [f64::NAN, 0.0, 0.0],
                    ..o
                },
                "obstacles[2].centre",
            ),
            (
                PleatTfwObstacle {
                    kind: PLEAT_TFW_OBSTACLE_PLANE,
                    normal: [0.0; 3],
                    ..o
                },
                "obstacles[2].normal",
            ),
            (
                PleatTfwObstacle { margin: -1.0, ..o },
                "obstacles[2].margin",
            ),
            (
                PleatTfwObstacle {
                    stiffness: 0.0,
                    ..o
                },
                "obstacles[2].stiffness",
            ),
            (
                PleatTfwObstacle {
                    struct_size: 4,
                    ..o
                },
                "obstacle",
            ),
        ];
        for (b, field) in bad {
            let st = pleat_tfw_scene_add_obstacle(scene, &b);
            assert_eq!(st, PleatStatus::InvalidArgument, "{field}");
            let msg = std::ffi::CStr::from_ptr(crate::ffi::pleat_last_error()).to_string_lossy();
            assert!(msg.contains(field), "{field}: {msg}");
        }
        let st = pleat_tfw_scene_add_obstacle(scene, std::ptr::null());
        assert_eq!(st, PleatStatus::InvalidArgument);
        let st = pleat_tfw_scene_add_obstacle(null_mut(), &o);
        assert_eq!(st, PleatStatus::InvalidArgument);
        assert_eq!((*scene).scene.obstacles, expected);
        pleat_tfw_scene_destroy(scene);
    }
}

/// `pleat_tfw_result_count_waves` is the library counter: automatic and given sections
/// agree with `tfw::measure` on a solved sheet; bad arguments are named.
#[test]
fn wave_count_from_c_is_the_library_counter() {
    let json =
        CString::new(crate::tfw::Scene::stretched_sheet(13, 6, 0.05).to_json_string()).unwrap();
    // SAFETY: valid pointers throughout; every handle is destroyed once.
    unsafe {
        let mut scene = null_mut();
        assert_eq!(
            pleat_tfw_scene_from_json(json.as_ptr(), &mut scene),
            PleatStatus::Ok
        );
        let mut result = null_mut();
        let st = pleat_tfw_solve(scene, std::ptr::null(), None, null_mut(), &mut result);
        assert_eq!(st, PleatStatus::Ok);
        let mut w = PleatTfwWaveCount {
            struct_size: full_size::<PleatTfwWaveCount>(),
            ..Default::default()
        };
        let st =
            pleat_tfw_result_count_waves(result, 2, std::ptr::null(), std::ptr::null(), 0, &mut w);
        assert_eq!(st, PleatStatus::Ok);
        let cwf = &(*result).result.cwf;
        let (s, c) = crate::tfw::measure::count_waves_auto(cwf, 2).unwrap();
        assert_eq!(
            (w.waves, w.peak_amplitude, w.samples),
            (c.waves, c.peak, c.samples as u64)
        );
        assert_eq!(
            (w.point, w.normal, w.closed),
            (s.point, s.normal, u32::from(s.closed))
        );
        assert!(w.waves >= 1.0 && w.peak_amplitude > 0.0, "{w:?}");
        let mut g = PleatTfwWaveCount {
            struct_size: full_size::<PleatTfwWaveCount>(),
            ..Default::default()
        };
        let st =
            pleat_tfw_result_count_waves(result, 2, s.point.as_ptr(), s.normal.as_ptr(), 0, &mut g);
        assert_eq!(st, PleatStatus::Ok);
        assert_eq!((g.waves, g.peak_amplitude), (w.waves, w.peak_amplitude));
        // min_radius (appended): the library counter with that section; an older struct
        // size is not read (0); a bad value is named
        let mut m = PleatTfwWaveCount {
            struct_size: full_size::<PleatTfwWaveCount>(),
            min_radius: 0.02,
            ..Default::default()
        };
        let st =
            pleat_tfw_result_count_waves(result, 2, s.point.as_ptr(), s.normal.as_ptr(), 0, &mut m);
        assert_eq!(st, PleatStatus::Ok);
        let cut = crate::tfw::measure::Section {
            min_radius: 0.02,
            ..s
        };
        let c2 = crate::tfw::measure::count_waves(cwf, 2, &cut).unwrap();
        assert_eq!(
            (m.waves, m.samples, m.min_radius),
            (c2.waves, c2.samples as u64, 0.02)
        );
        assert!(m.samples < w.samples, "{m:?} vs {w:?}");
        let mut old = PleatTfwWaveCount {
            struct_size: std::mem::offset_of!(PleatTfwWaveCount, min_radius) as u32,
            min_radius: -1.0,
            ..Default::default()
        };
        let st = pleat_tfw_result_count_waves(
            result,
            2,
            std::ptr::null(),
            std::ptr::null(),
            0,
            &mut old,
        );
        assert_eq!(st, PleatStatus::Ok);
        assert_eq!((old.waves, old.samples), (w.waves, w.samples));
        assert_eq!(old.min_radius, -1.0, "beyond struct_size: not written");
        m.min_radius = f64::NAN;
        let st =
            pleat_tfw_result_count_waves(result, 2, std::ptr::null(), std::ptr::null(), 0, &mut m);
        assert_eq!(st, PleatStatus::InvalidArgument);
        let msg = std::ffi::CStr::from_ptr(crate::ffi::pleat_last_error()).to_string_lossy();
        assert!(msg.contains("out->min_radius"), "{msg}");
        let zero = [0.0; 3];
        let nan = [f64::NAN, 0.0, 1.0];
        let cases: [(u32, *const f64, *const f64, u32, &str); 5] = [
            (7, std::ptr::null(), std::ptr::null(), 0, "levels"),
            (2, s.point.as_ptr(), std::ptr::null(), 0, "section_normal"),
            (2, s.point.as_ptr(), zero.as_ptr(), 0, "section_normal"),
            (2, nan.as_ptr(), s.normal.as_ptr(), 0, "section_point"),
            (2, s.point.as_ptr(), s.normal.as_ptr(), 2, "section_closed"),
        ];
        for (levels, p, n, closed, field) in cases {
            let st = pleat_tfw_result_count_waves(result, levels, p, n, closed, &mut g);
            assert_eq!(st, PleatStatus::InvalidArgument, "{field}");
            let msg = std::ffi::CStr::from_ptr(crate::ffi::pleat_last_error()).to_string_lossy();
            assert!(msg.contains(field), "{field}: {msg}");
        }
        let st = pleat_tfw_result_count_waves(
            result,
            2,
            std::ptr::null(),
            std::ptr::null(),
            0,
            null_mut(),
        );
        assert_eq!(st, PleatStatus::InvalidArgument);
        pleat_tfw_result_destroy(result);
        pleat_tfw_scene_destroy(scene);
    }
}

/// Same scene and parameters ⇒ the same bytes on 1 and 2 threads (the history's wall
/// times aside).
#[test]
fn c_api_solve_is_thread_count_independent() {
    for qp in [PLEAT_TFW_QP_CLARABEL, PLEAT_TFW_QP_PROJECTED_NEWTON] {
        solve_is_thread_count_independent(qp);
    }
}

fn solve_is_thread_count_independent(qp: u32) {
    let (p1, a1, h1) = solve_small(1, qp);
    let (p2, a2, h2) = solve_small(2, qp);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&p1), bits(&p2));
    assert_eq!(bits(&a1), bits(&a2));
    let numbers = |h: &[f64]| {
        h.chunks_exact(4)
            .flat_map(|r| [r[0].to_bits(), r[1].to_bits(), r[2].to_bits()])
            .collect::<Vec<_>>()
    };
    assert!(!h1.is_empty());
    assert_eq!(numbers(&h1), numbers(&h2));
}
