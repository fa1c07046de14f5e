//! TFW (dissertation ch. 2): scene setup, material law and the base surface solve on
//! small meshes. Finite-difference checks per energy term, analytic solutions and invariants.
#![cfg(feature = "tfw")]

use pleat::tfw::material::{principal_strains, relaxed_density_in_form, Form};
use pleat::tfw::scene::rest_form;
use pleat::tfw::{
    solve_base, BaseOptions, BaseProblem, BaseStatus, Branch, Dirichlet, Lame, Material, Model,
    Motion, Obstacle, ObstacleShape, Panel, Rotation, Scene, Terms,
};

fn no_progress() -> impl FnMut(pleat::Progress<'_>) -> bool {
    |_| true
}

/// A deterministic value in [−1, 1).
fn noise(k: usize) -> f64 {
    let mut z = (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xDEAD_BEEF;
    z = (z ^ (z >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 32;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[test]
fn relaxed_density_branches_are_continuous() {
    let m = Lame::from_young_poisson(1e6, 0.3);
    let l1 = 0.05;
    let l2 = m.relaxed_lambda2(l1);
    let (a, _) = m.relaxed_density(l1, l2 + 1e-12);
    let (b, _) = m.relaxed_density(l1, l2 - 1e-12);
    assert!((a - b).abs() <= 1e-9 * a, "{a} vs {b}");
    // the wrinkled branch is W_s at the relaxed λ2
    assert!((m.stvk_density(l1, l2) - m.wrinkled_coefficient() * l1 * l1).abs() < 1e-12 * a);
}

#[test]
fn form_density_matches_finite_differences_on_every_branch() {
    for nu in [0.0, 0.3, 0.5] {
        let m = Lame::from_young_poisson(1e6, nu);
        let rest: Form = [1.0, 0.3, 0.8];
        let states: [Form; 3] = [[1.1, 0.33, 0.9], [1.1, 0.3, 0.7], [0.9, 0.27, 0.7]];
        let want = [Branch::Tension, Branch::Wrinkled, Branch::Slack];
        for (cur, want) in states.into_iter().zip(want) {
            let f = relaxed_density_in_form(&m, rest, cur);
            assert_eq!(f.branch, want, "ν {nu}, {cur:?}");
            let h = 1e-6;
            for k in 0..3 {
                let (mut p, mut q) = (cur, cur);
                p[k] += h;
                q[k] -= h;
                let (fp, fq) = (
                    relaxed_density_in_form(&m, rest, p),
                    relaxed_density_in_form(&m, rest, q),
                );
                let g = (fp.value - fq.value) / (2.0 * h);
                assert!(
                    (g - f.grad[k]).abs() <= 1e-6 * (1.0 + g.abs()),
                    "grad {k}: {g} vs {}",
                    f.grad[k]
                );
                for j in 0..3 {
                    let hh = (fp.grad[j] - fq.grad[j]) / (2.0 * h);
                    let tol = 1e-5 * (1.0 + hh.abs().max(f.hess[k][j].abs()));
                    assert!((hh - f.hess[k][j]).abs() <= tol, "hess {k}{j}");
                }
            }
        }
    }
}

#[test]
fn principal_strains_match_a_known_stretch() {
    let rest = rest_form([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    // stretch x by 1.1, y by 0.9: Green strains 1.21 − 1 and 0.81 − 1
    let cur = [1.21, 0.0, 0.81];
    let (l1, l2) = principal_strains(rest, cur);
    assert!((l1 - 0.21).abs() < 1e-14 && (l2 + 0.19).abs() < 1e-14);
}

/// A small jittered sheet as a one-panel scene with no conditions.
fn small_sheet(nx: usize, ny: usize) -> Scene {
    let mut s = Scene::stretched_sheet(nx, ny, 0.0);
    s.dirichlet.clear();
    s
}

#[test]
fn corrected_laplacian_annihilates_affine_functions() {
    let model = small_sheet(9, 6).assemble().unwrap();
    let p = BaseProblem::new(&model, 1.0);
    // rest coordinates per vertex (single panel: any corner gives it)
    let mut uv = vec![[0.0; 2]; model.positions.len()];
    for (t, c) in model.triangles.iter().zip(&model.rest_corners) {
        for k in 0..3 {
            uv[t[k] as usize] = c[k];
        }
    }
    for (i, row) in p.laplacian().iter().enumerate() {
        let (mut su, mut sv, mut s1) = (0.0, 0.0, 0.0);
        for &(j, w) in row {
            su += w * uv[j as usize][0];
            sv += w * uv[j as usize][1];
            s1 += w;
        }
        assert!(
            su.abs() < 1e-12 && sv.abs() < 1e-12 && s1.abs() < 1e-9,
            "row {i}: {su} {sv} {s1}"
        );
    }
}

/// Sheet positions stretched by (sx, sy) with a small out-of-plane and in-plane noise.
fn perturbed(model: &Model, sx: f64, sy: f64, amp: f64) -> Vec<f64> {
    model
        .positions
        .iter()
        .enumerate()
        .flat_map(|(i, p)| {
            [
                p[0] * sx + amp * noise(3 * i),
                p[1] * sy + amp * noise(3 * i + 1),
                amp * noise(3 * i + 2),
            ]
        })
        .collect()
}

fn dense_hessian(n3: usize, entries: &[(usize, usize, f64)]) -> Vec<Vec<f64>> {
    let mut h = vec![vec![0.0; n3]; n3];
    for &(r, c, v) in entries {
        h[r][c] += v;
        if r != c {
            h[c][r] += v;
        }
    }
    h
}

fn check_term(problem: &BaseProblem, x: &[f64], terms: Terms, what: &str) {
    let ev = problem.evaluate(x, terms, true);
    assert!(
        (ev.energy - problem.energy(x, terms)).abs() <= 1e-12 * ev.energy.abs().max(1e-30),
        "{what}: energy paths disagree"
    );
    let h = dense_hessian(x.len(), &ev.hessian);
    let gscale = ev.gradient.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let hscale = h.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(gscale > 0.0, "{what}: zero gradient, test is vacuous");
    let step = 1e-7;
    for k in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[k] += step;
        xm[k] -= step;
        let fd = (problem.energy(&xp, terms) - problem.energy(&xm, terms)) / (2.0 * step);
        assert!(
            (fd - ev.gradient[k]).abs() <= 1e-5 * gscale,
            "{what}: gradient {k}: fd {fd} vs {}",
            ev.gradient[k]
        );
        let (gp, gm) = (
            problem.evaluate(&xp, terms, true).gradient,
            problem.evaluate(&xm, terms, true).gradient,
        );
        for j in 0..x.len() {
            let fd = (gp[j] - gm[j]) / (2.0 * step);
            assert!(
                (fd - h[j][k]).abs() <= 1e-5 * hscale,
                "{what}: Hessian ({j},{k}): fd {fd} vs {}",
                h[j][k]
            );
        }
    }
}

#[test]
fn every_energy_term_matches_finite_differences() {
    let mut scene = small_sheet(5, 4);
    scene.pressure = 300.0;
    scene.material.density = 500.0;
    scene.gravity = [0.3, -1.0, -9.81];
    let model = scene.assemble().unwrap();
    let problem = BaseProblem::new(&model, 1.0);
    // stretched along x, compressed along y: wrinkled and tension faces both occur
    let x = perturbed(&model, 1.05, 0.97, 2e-3);
    let s = problem.strain_summary(&x);
    assert!(s.wrinkled_faces > 0, "{s:?}");
    for (terms, what) in [
        (
            Terms {
                membrane: true,
                ..Terms::NONE
            },
            "membrane",
        ),
        (
            Terms {
                bending: true,
                ..Terms::NONE
            },
            "bending",
        ),
        (
            Terms {
                pressure: true,
                ..Terms::NONE
            },
            "pressure",
        ),
        (
            Terms {
                gravity: true,
                ..Terms::NONE
            },
            "gravity",
        ),
    ] {
        check_term(&problem, &x, terms, what);
    }
    // obstacles: a sphere below the middle and a tilted plane, both reaching some vertices
    // (with a margin), the exact Hessian (the sphere's curvature term included)
    scene.obstacles = vec![
        Obstacle {
            shape: ObstacleShape::Sphere {
                centre: [0.0, 0.0, -0.05],
                radius: 0.07,
            },
            stiffness: pleat::tfw::DEFAULT_OBSTACLE_STIFFNESS,
            margin: 0.0,
        },
        Obstacle {
            shape: ObstacleShape::Plane {
                point: [0.06, 0.0, 0.0],
                normal: [-1.0, 0.0, 0.2],
            },
            stiffness: 1e6,
            margin: 0.01,
        },
    ];
    let model = scene.assemble().unwrap();
    let problem = BaseProblem::new(&model, 1.0);
    let obstacles = Terms {
        obstacles: true,
        ..Terms::NONE
    };
    assert!(problem.term_energies(&x).obstacles > 0.0);
    check_term(&problem, &x, obstacles, "obstacles");
}

/// Obstacles: a 0.6 × 0.6 m sheet (ρ 200 kg/m³, h 1 mm, Y 0.1 MPa, ν 0.3, the
/// sphere drape's material, S:676) laid flat on top of a sphere r 0.2 m, its centre vertex
/// pinned at the top (a frictionless sphere's top is an unstable equilibrium: a free sheet
/// slides off), drapes over it under gravity and ends outside the sphere up to the penalty's
/// tolerance (1 mm, 0.5 % of the radius; the default stiffness's `√(q/3k)` is 26 µm for the
/// sheet's own weight, more where the hanging skirt pulls it onto the sphere).
#[test]
fn sheet_drapes_over_a_sphere_and_stays_outside() {
    let n = 13;
    let r = 0.2;
    let centre_vertex = (n / 2) * n + n / 2;
    let scene = Scene::sphere_drape(n, 0.6);
    let model = scene.assemble().unwrap();
    let res = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
    let p = res.mesh.positions();
    let dist = |q: &[f64; 3]| (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() - r;
    let min_d = p.iter().map(dist).fold(f64::INFINITY, f64::min);
    // the vertices next to the pinned centre are pulled onto the sphere by the skirt
    let centre = dist(&p[centre_vertex + 1]);
    let min_z = p.iter().map(|q| q[2]).fold(f64::INFINITY, f64::min);
    eprintln!(
        "drape: {:?} in {} Newton it, relative gradient {:.1e}; min signed distance {:.3e} m, \
         next to the centre {:.3e} m, lowest z {:.3} m, penalty energy {:.3e} J",
        res.status,
        res.history.len(),
        res.relative_gradient,
        min_d,
        centre,
        min_z,
        res.energies.obstacles
    );
    assert!(min_d >= -1e-3, "penetrates by {min_d}");
    assert!(
        centre <= 1e-3,
        "the sheet does not rest on the sphere: {centre}"
    );
    assert!(min_z < 0.1, "the sheet does not hang down: {min_z}");
}

/// The sphere drape solved through (base, W, SQP, phase) on a small grid (13 × 13, a 0.6 m
/// sheet): the skirt hanging off the sphere is compressed around it, so most faces wrinkle
/// (outside W), the SQP's energy never increases and ends stationary, the field is curl-free
/// off W, and the amplitudes are non-negative and below the skirt's length. The dissertation's
/// 1.6k-vertex drape is `pleat bench tfw --builtin sphere-drape` and the picture test
/// `balloon_check::sphere_drape_wrinkles`.
#[test]
fn sphere_drape_wrinkles_where_the_skirt_is_compressed() {
    for (n, side) in [
        (0, 0.6),
        (1, 0.6),
        (5, 0.0),
        (5, f64::NAN),
        (5, f64::INFINITY),
    ] {
        let degenerate = Scene::sphere_drape(n, side);
        assert!(n < 2 || degenerate.assemble().is_err(), "{n} {side}");
    }
    assert_eq!(Scene::sphere_drape(0, 0.6).panels[0].rest.len(), 4);
    assert_eq!(Scene::sphere_drape(5, -0.6), Scene::sphere_drape(5, 0.6));
    assert_drape_wrinkles(&Scene::sphere_drape(13, 0.6));
}

/// Solves a 0.6 m sphere drape through: most faces wrinkle (outside W), the SQP's energy never
/// increases and ends lower, the field is curl-free off W, and the amplitudes are
/// non-negative and below the skirt's length.
fn assert_drape_wrinkles(scene: &Scene) {
    let params = pleat::tfw::TfwParams::default();
    let r = pleat::tfw::solve(scene, &params, &mut no_progress()).unwrap();
    let sqp = r.sqp.as_ref().expect("the drape is compressed");
    let free = r.w_faces.iter().filter(|&&w| w).count();
    assert!(
        2 * free < r.w_faces.len(),
        "{free} of {} faces wrinkle-free",
        r.w_faces.len()
    );
    let e: Vec<f64> = sqp.history.iter().map(|h| h.energy).collect();
    assert!(
        e.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-12)),
        "energy increased"
    );
    assert!(e.last().copied().unwrap_or(sqp.initial_energy) < sqp.initial_energy);
    assert!(r.curl_residual <= 1e-10, "curl {}", r.curl_residual);
    let a = r.cwf.amplitude();
    let peak = a.iter().fold(0.0f64, |m, &x| m.max(x));
    assert!(
        a.iter().all(|&x| x >= 0.0) && peak > 0.0 && peak < 0.3,
        "peak {peak}"
    );
}

/// The sphere drape on an irregular Delaunay mesh (about 200 vertices, a 0.6 m sheet) solves
/// through like the grid's: most faces wrinkle, the SQP's energy never increases, curl-free
/// field, non-negative amplitudes; the pinned vertex is the one nearest the centre; a bad side
/// or too few vertices are refused with an error.
#[test]
fn sphere_drape_on_a_delaunay_mesh_wrinkles_like_the_grid() {
    for side in [0.0, f64::NAN, f64::INFINITY] {
        let refused = match Scene::sphere_drape_delaunay(200, side, 1) {
            Err(_) => true,
            Ok(scene) => scene.assemble().is_err(),
        };
        assert!(refused, "side {side}");
    }
    assert!(Scene::sphere_drape_delaunay(0, 0.6, 1).is_err());
    let scene = Scene::sphere_drape_delaunay(200, 0.6, 1).unwrap();
    let rest = &scene.panels[0].rest;
    let pinned = scene.dirichlet[0].vertices[0] as usize;
    let off = |p: &[f64; 2]| (p[0] - 0.3).hypot(p[1] - 0.3);
    assert!(rest.iter().all(|p| off(p) >= off(&rest[pinned])));
    assert_drape_wrinkles(&scene);
}

#[test]
fn obstacles_round_trip_through_json_and_errors_name_the_field() {
    let with = GOOD.replace(
        "\"dirichlet\"",
        "\"obstacles\": [ {\"type\": \"sphere\", \"centre\": [0, 0, -1], \"radius\": 0.5},
        {\"type\": \"plane\", \"point\": [0, 0, -2], \"normal\": [0, 0, 1], \"stiffness\": 1e6,
         \"margin\": 0.01} ],\n  \"dirichlet\"",
    );
    let s = Scene::from_json_str(&with).unwrap();
    assert_eq!(s.obstacles.len(), 2);
    assert_eq!(
        s.obstacles[0].stiffness,
        pleat::tfw::DEFAULT_OBSTACLE_STIFFNESS
    );
    assert_eq!(s.obstacles[1].margin, 0.01);
    let back = Scene::from_json_str(&s.to_json_string()).unwrap();
    assert_eq!(back.obstacles, s.obstacles);
    for (from, to, want) in [
        ("\"radius\": 0.5", "\"radius\": -1", "obstacles[0].radius"),
        (
            "\"radius\": 0.5",
            "\"radius\": 0.5, \"colour\": 1",
            "obstacles[0].colour",
        ),
        (
            "\"type\": \"sphere\"",
            "\"type\": \"cone\"",
            "obstacles[0].type",
        ),
        (
            "\"normal\": [0, 0, 1]",
            "\"normal\": [0, 0, 0]",
            "obstacles[1].normal",
        ),
        (
            "\"stiffness\": 1e6",
            "\"stiffness\": 0",
            "obstacles[1].stiffness",
        ),
        (
            "\"margin\": 0.01",
            "\"margin\": -0.01",
            "obstacles[1].margin",
        ),
        ("\"centre\": [0, 0, -1], ", "", "obstacles[0].centre"),
    ] {
        let e = err_of(&with.replace(from, to));
        assert!(e.contains(want), "{e} should name {want}");
    }
}

#[test]
fn pure_tension_dilation_is_the_exact_answer_and_relaxed_equals_plain_energy() {
    // every boundary vertex clamped at 1.03 × its rest position: the uniform dilation is the
    // equilibrium (affine ⇒ Lx = 0 and constant stress), every face is in pure tension.
    let mut scene = small_sheet(11, 6);
    let nx = 11;
    let ny = 6;
    let boundary: Vec<u32> = (0..nx * ny)
        .filter(|&k| k % nx == 0 || k % nx == nx - 1 || k / nx == 0 || k / nx == ny - 1)
        .map(|k| k as u32)
        .collect();
    let s = 1.03;
    let panel = &mut scene.panels[0];
    let x0: Vec<[f64; 3]> = panel.positions.clone().unwrap();
    // interior starts undeformed (and slightly off plane), boundary on the dilated positions
    let mut init = x0.clone();
    for (i, p) in init.iter_mut().enumerate() {
        if boundary.contains(&(i as u32)) {
            *p = [p[0] * s, p[1] * s, 0.0];
        } else {
            p[2] = 1e-4 * noise(i);
        }
    }
    panel.positions = Some(init);
    scene.dirichlet = vec![Dirichlet {
        panel: 0,
        vertices: boundary,
        motion: Motion::default(),
    }];
    let model = scene.assemble().unwrap();
    let r = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
    assert_eq!(r.status, BaseStatus::Converged, "{:?}", r.history);
    for (p, q) in r.mesh.positions().iter().zip(&x0) {
        for d in 0..2 {
            assert!((p[d] - s * q[d]).abs() < 1e-9, "{p:?} vs {q:?}");
        }
        assert!(p[2].abs() < 1e-9);
    }
    assert_eq!(r.strain.tension_faces, model.triangles.len());
    // relaxed energy = plain StVK membrane energy Σ (h/4) A_f W_s
    let lame = model.material.lame();
    let h = model.material.thickness;
    let plain: f64 = model
        .triangles
        .iter()
        .zip(&model.rest_forms)
        .map(|(t, rest)| {
            let p = t.map(|v| r.mesh.positions()[v as usize]);
            let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
            let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
            let d = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let (l1, l2) = principal_strains(*rest, [d(e1, e1), d(e1, e2), d(e2, e2)]);
            let area = 0.5 * (rest[0] * rest[2] - rest[1] * rest[1]).sqrt();
            0.25 * h * area * lame.stvk_density(l1, l2)
        })
        .sum();
    assert!(
        (r.energies.membrane - plain).abs() <= 1e-12 * plain,
        "{} vs {plain}",
        r.energies.membrane
    );
}

fn monotone(history: &[pleat::tfw::NewtonIteration], e0: f64) {
    let mut prev = e0;
    for it in history {
        assert!(
            it.energy <= prev + 8.0 * f64::EPSILON * prev.abs(),
            "energy rose: {prev} -> {}",
            it.energy
        );
        prev = it.energy;
    }
}

#[test]
fn twisted_cylinder_converges_with_decreasing_energy_and_wrinkled_faces() {
    let scene = Scene::twisted_cylinder(24, 9, 10.0);
    let model = scene.assemble().unwrap();
    // the seam is sewn: 24 columns, not 25
    assert_eq!(model.positions.len(), 24 * 9);
    let mut calls = 0;
    let r = solve_base(&model, &BaseOptions::default(), &mut |_| {
        calls += 1;
        true
    })
    .unwrap();
    assert!(calls > 0);
    assert!(
        matches!(r.status, BaseStatus::Converged | BaseStatus::EnergyStalled),
        "{:?} {:?}",
        r.status,
        r.history
    );
    assert!(r.relative_gradient < 1e-6, "{}", r.relative_gradient);
    // initial energy: the untwisted cylinder with the top ring rotated
    let problem = BaseProblem::new(&model, 1.0);
    let mut x: Vec<f64> = model.positions.iter().flatten().copied().collect();
    for &(v, m) in &model.clamps {
        let q = m.apply(model.positions[v as usize], 1.0);
        x[3 * v as usize..3 * v as usize + 3].copy_from_slice(&q);
    }
    monotone(&r.history, problem.energy(&x, Terms::ALL));
    // shear by twisting: tension along one diagonal, relaxed compression along the other
    assert!(
        r.strain.wrinkled_faces > model.triangles.len() / 2,
        "{:?}",
        r.strain
    );
    assert_eq!(r.strain.degenerate_faces, 0);
}

#[test]
fn displacement_driven_base_is_independent_of_young_modulus() {
    let solve = |young: f64| {
        let mut scene = Scene::twisted_cylinder(16, 6, 10.0);
        scene.material.young = young;
        let r = solve_base(
            &scene.assemble().unwrap(),
            &BaseOptions::default(),
            &mut no_progress(),
        )
        .unwrap();
        (r.mesh.positions().to_vec(), r.energies.membrane)
    };
    let (a, ea) = solve(1e7);
    let (b, eb) = solve(1e11);
    for (p, q) in a.iter().zip(&b) {
        for d in 0..3 {
            assert!((p[d] - q[d]).abs() < 1e-7, "{p:?} vs {q:?}");
        }
    }
    assert!((eb / ea / 1e4 - 1.0).abs() < 1e-6);
}

#[test]
fn stretched_sheet_relaxes_to_tension_with_wrinkled_middle() {
    let scene = Scene::stretched_sheet(21, 9, 0.1);
    let model = scene.assemble().unwrap();
    let r = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
    assert!(
        matches!(r.status, BaseStatus::Converged | BaseStatus::EnergyStalled),
        "{:?}",
        r.status
    );
    assert!(r.strain.wrinkled_faces > 0, "{:?}", r.strain);
    assert!(r.strain.slack_area_fraction < 0.5);
    // the free long edges contract laterally (ν = 0.5, clamped short edges)
    let mid = r
        .mesh
        .positions()
        .iter()
        .filter(|p| p[0].abs() < 0.01)
        .fold(0.0f64, |m, p| m.max(p[1].abs()));
    assert!(mid < 0.05, "half-width at mid-length {mid}");
}

#[test]
fn load_steps_reach_the_same_answer() {
    let scene = Scene::twisted_cylinder(16, 6, 10.0);
    let model = scene.assemble().unwrap();
    let one = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
    let three = solve_base(
        &model,
        &BaseOptions {
            load_steps: 3,
            ..Default::default()
        },
        &mut no_progress(),
    )
    .unwrap();
    assert!(three.history.iter().any(|h| h.load_step == 3));
    for (p, q) in one.mesh.positions().iter().zip(three.mesh.positions()) {
        for d in 0..3 {
            assert!((p[d] - q[d]).abs() < 1e-6, "{p:?} vs {q:?}");
        }
    }
}

#[test]
fn cancelling_returns_cancelled() {
    let model = Scene::twisted_cylinder(12, 5, 10.0).assemble().unwrap();
    let e = solve_base(&model, &BaseOptions::default(), &mut |_| false).unwrap_err();
    assert_eq!(e, pleat::Error::Cancelled);
}

#[test]
fn rotation_motion_follows_the_right_hand_rule() {
    let m = Motion {
        translation: [0.0, 0.0, 1.0],
        rotation: Some(Rotation {
            axis: [0.0, 0.0, 2.0],
            origin: [1.0, 0.0, 0.0],
            degrees: 90.0,
        }),
    };
    let q = m.apply([2.0, 0.0, 0.0], 1.0);
    for (a, b) in q.iter().zip([1.0, 1.0, 1.0]) {
        assert!((a - b).abs() < 1e-15, "{q:?}");
    }
    assert_eq!(m.apply([2.0, 0.0, 0.0], 0.0), [2.0, 0.0, 0.0]);
}

#[test]
fn scene_json_round_trips() {
    let scene = Scene::twisted_cylinder(8, 4, 10.0);
    let text = scene.to_json_string();
    let back = Scene::from_json_str(&text).unwrap();
    // equal up to an ulp per number (serde_json's default float parsing)
    let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs());
    let (p, q) = (&back.panels[0], &scene.panels[0]);
    assert_eq!(p.triangles, q.triangles);
    for (a, b) in p.rest.iter().zip(&q.rest) {
        assert!(a.iter().zip(b).all(|(x, y)| close(*x, *y)), "{a:?} {b:?}");
    }
    let (pa, qa) = (p.positions.as_ref().unwrap(), q.positions.as_ref().unwrap());
    for (a, b) in pa.iter().zip(qa) {
        assert!(a.iter().zip(b).all(|(x, y)| close(*x, *y)), "{a:?} {b:?}");
    }
    let strip = |s: &Scene| Scene {
        panels: vec![],
        ..s.clone()
    };
    assert_eq!(strip(&back), strip(&scene));
}

fn err_of(text: &str) -> String {
    Scene::from_json_str(text).unwrap_err().to_string()
}

const GOOD: &str = r#"{
  "material": { "young": 1e6, "poisson": 0.3, "thickness": 1e-4 },
  "panels": [ { "rest": [[0, 0], [1, 0], [0, 1]], "triangles": [[0, 1, 2]] } ],
  "dirichlet": [ { "panel": 0, "vertices": [0, 1] } ]
}"#;

#[test]
fn scene_errors_name_the_field() {
    assert!(Scene::from_json_str(GOOD).is_ok());
    let e = err_of(&GOOD.replace("\"young\"", "\"yung\""));
    assert!(e.contains("unknown key material.yung"), "{e}");
    let e = err_of(&GOOD.replace("1e-4", "-1e-4"));
    assert!(e.contains("material.thickness"), "{e}");
    let e = err_of(&GOOD.replace("1e-4", "NaN"));
    assert!(e.contains("not valid JSON"), "{e}");
    let e = err_of(&GOOD.replace("0.3", "1.5"));
    assert!(e.contains("material.poisson"), "{e}");
    let e = err_of(&GOOD.replace("\"panels\"", "\"panel\""));
    assert!(e.contains("unknown key panel"), "{e}");
    let e = err_of(
        r#"{"material": { "young": 1e6, "poisson": 0.3, "thickness": 1e-4 }, "panels": []}"#,
    );
    assert!(e.contains("panels: at least one panel"), "{e}");
    let e = err_of(r#"{"material": { "young": 1e6, "poisson": 0.3, "thickness": 1e-4 }}"#);
    assert!(e.contains("panels: missing"), "{e}");
    let e = err_of(&GOOD.replace("[0, 1] }", "[0, 7] }"));
    assert!(e.contains("dirichlet[0].vertices"), "{e}");
    let e = err_of(&GOOD.replace("[1, 0], [0, 1]]", "[2, 0], [4, 0]]"));
    assert!(
        e.contains("panels[0].triangles[0]: rest triangle has zero area"),
        "{e}"
    );
    let e = err_of(&GOOD.replace("[[0, 1, 2]]", "[[0, 1, 3]]"));
    assert!(e.contains("panels[0].triangles[0]"), "{e}");
    // programmatic scenes are validated too
    let mut s = Scene::stretched_sheet(4, 3, 0.1);
    s.panels[0].rest[5][1] = f64::NAN;
    let e = s.assemble().unwrap_err().to_string();
    assert!(e.contains("panels[0].rest[5][1]"), "{e}");
    let mut s = Scene::stretched_sheet(4, 3, 0.1);
    s.material = Material {
        thickness: -1.0,
        ..s.material
    };
    assert!(s.validate().unwrap_err().to_string().contains("thickness"));
    let mut s = Scene::stretched_sheet(4, 3, 0.1);
    s.panels.push(Panel {
        rest: vec![[0.0, 0.0]],
        triangles: vec![],
        positions: None,
    });
    assert!(s
        .validate()
        .unwrap_err()
        .to_string()
        .contains("panels[1].triangles"));
}

#[test]
fn poisson_zero_warns_and_still_solves() {
    let mut scene = Scene::twisted_cylinder(12, 5, 10.0);
    scene.material.poisson = 0.0;
    let model = scene.assemble().unwrap();
    assert!(model.warnings.iter().any(|w| w.contains("poisson = 0")));
    let r = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
    assert!(r.energies.membrane.is_finite());
    assert!(!r.history.is_empty());
}

#[test]
fn has_feature_reports_tfw() {
    let on = unsafe { pleat::ffi::pleat_has_feature(c"tfw".as_ptr()) };
    assert_eq!(on, 1);
}

/// Iterations and wall time of the base solve on the spec's mesh sizes (run with
/// `cargo test --test tfw -- --ignored --nocapture`).
#[test]
#[ignore]
fn report_base_solve_on_spec_sizes() {
    for scene in [
        Scene::stretched_sheet(41, 13, 0.1),
        Scene::twisted_cylinder(43, 16, 10.0),
        Scene::twisted_cylinder(63, 21, 10.0),
    ] {
        let model = scene.assemble().unwrap();
        let t = std::time::Instant::now();
        let r = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
        println!(
            "{}: {} v, {:?}, {} it, {:.3} s, rel. gradient {:.1e}, {:?}",
            scene.name,
            model.positions.len(),
            r.status,
            r.history.len(),
            t.elapsed().as_secs_f64(),
            r.relative_gradient,
            r.strain
        );
        for h in &r.history {
            println!(
                "  E {:.9e} |g| {:.2e} t {} shift {:.1e} {:.3} s",
                h.energy, h.gradient_norm, h.step, h.shift, h.seconds
            );
        }
    }
}

/// Period snapping off (the library's default) unless `PLEAT_TFW_SNAP=1` (test-side switch
/// for before/after measurements; the library reads no environment).
fn snap_from_env(params: &mut pleat::tfw::TfwParams) {
    params.snap_periods = std::env::var("PLEAT_TFW_SNAP").is_ok_and(|v| v == "1");
}

/// Prints the period snapping of `r` and the phase's defects where the wrinkles show: per
/// edge whose ends both have `a ≥ 10%` of the peak, `δ = wrap(arg z_j − arg z_i − ω_ij)`
/// (Knöppel's phase against ω); "seam edges" have `|δ| > 0.5 rad`, and singular faces (all
/// three corners at ≥ 10%) have a nonzero index `Σδ / 2π`. Returns (seam edges, singular
/// faces).
fn print_phase(r: &pleat::tfw::TfwResult) -> (usize, usize) {
    use std::f64::consts::{PI, TAU};
    if let Some(s) = &r.snap {
        let loops: Vec<String> = s
            .loops
            .iter()
            .map(|l| format!("{:.4}->{:.4} rad (k {})", l.before, l.after, l.waves))
            .collect();
        eprintln!(
            "  period snapping: loops [{}], kept {}, |δω| {:.3e} of |ω| {:.3e} ({:.2e} relative), \
             max |δω_e| {:.3e}",
            loops.join(", "),
            s.kept_loops,
            s.correction_norm,
            s.omega_norm,
            s.correction_norm / s.omega_norm.max(1e-300),
            s.max_correction
        );
        let turns: Vec<String> = s
            .kept_periods
            .iter()
            .map(|p| format!("{:.3}", p / TAU))
            .collect();
        eprintln!("  kept loops' periods (turns): [{}]", turns.join(", "));
    } else {
        eprintln!("  period snapping: off");
    }
    let cwf = &r.cwf;
    let mesh = cwf.base();
    let el = mesh.edges();
    let a = cwf.amplitude();
    let peak = a.iter().fold(0.0f64, |m, &x| m.max(x));
    let shows = |v: u32| a[v as usize] >= 0.1 * peak && peak > 0.0;
    let z = cwf.zeta();
    let wrap = |x: f64| (x + PI).rem_euclid(TAU) - PI;
    let delta: Vec<f64> = el
        .edges
        .iter()
        .zip(cwf.omega())
        .map(|(e, &w)| wrap(z[e.0[1] as usize].arg() - z[e.0[0] as usize].arg() - w))
        .collect();
    let seam = el
        .edges
        .iter()
        .zip(&delta)
        .filter(|(e, d)| shows(e.0[0]) && shows(e.0[1]) && d.abs() > 0.5)
        .count();
    let singular = (0..mesh.triangle_count())
        .filter(|&f| mesh.triangles()[f].iter().all(|&v| shows(v)))
        .filter(|&f| {
            let sum: f64 = (0..3)
                .map(|i| f64::from(el.face_edge_sign[f][i]) * delta[el.face_edges[f][i] as usize])
                .sum();
            (sum / TAU).round() != 0.0
        })
        .count();
    if std::env::var("PLEAT_DEBUG_SEAM").is_ok() {
        let p = mesh.positions();
        let az = |v: u32| p[v as usize][1].atan2(p[v as usize][0]).to_degrees();
        let mut hist = vec![0usize; 36];
        for (f, t) in mesh.triangles().iter().enumerate() {
            if r.w_faces[f] {
                hist[(((az(t[0]) + 180.0) / 10.0) as usize).min(35)] += 1;
            }
        }
        eprintln!("  W faces per 10° of azimuth from -180: {hist:?}");
        let mut amp = vec![0.0f64; 36];
        for (v, &x) in a.iter().enumerate() {
            let b = (((az(v as u32) + 180.0) / 10.0) as usize).min(35);
            amp[b] = amp[b].max(x / peak);
        }
        eprintln!(
            "  max a/peak per 10°: {:?}",
            amp.iter().map(|x| (x * 100.0).round()).collect::<Vec<_>>()
        );
        for (e, d) in el.edges.iter().zip(&delta) {
            if shows(e.0[0]) && shows(e.0[1]) && d.abs() > 0.5 {
                let q = p[e.0[0] as usize];
                eprintln!(
                    "  seam edge at azimuth {:.1}°, z {:.4}, r {:.4}, δ {d:.2}",
                    az(e.0[0]),
                    q[2],
                    q[0].hypot(q[1])
                );
            }
        }
    }
    eprintln!(
        "  phase where a ≥ 10% of the peak: {seam} seam edges (|δ| > 0.5 rad), {singular} \
         singular faces"
    );
    (seam, singular)
}

mod wrinkle_free {
    use super::*;
    use pleat::mesh::TriMesh;
    use pleat::tfw::wfree::{
        embedded_wave_vector, face_neighbours, face_strains, helmholtz_projection,
        initial_face_field, wrinkle_free_faces, WRule,
    };

    #[test]
    fn face_strain_directions_of_a_known_stretch() {
        let rest = rest_form([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let base = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.1, 0.0, 0.0], [0.0, 0.9, 0.0]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let s = face_strains(&[rest], &base)[0];
        assert!((s.lambda_t - 0.21).abs() < 1e-14 && (s.lambda_c + 0.19).abs() < 1e-14);
        assert!(s.tension_dir[1].abs() < 1e-14 && (s.tension_dir[0].abs() - 1.0).abs() < 1e-14);
        assert!(
            s.compression_dir[0].abs() < 1e-14 && (s.compression_dir[1].abs() - 1.0).abs() < 1e-14
        );
    }

    /// Grid faces of a small sheet with λ_c = +1 left of x = 0, −1 right of it, and the face
    /// nearest each of two points given the opposite sign.
    fn synthetic() -> (Vec<[u32; 3]>, Vec<f64>, Vec<f64>, usize, usize) {
        let model = small_sheet(13, 7).assemble().unwrap();
        let cx: Vec<f64> = model
            .triangles
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&v| model.positions[v as usize][0])
                    .sum::<f64>()
                    / 3.0
            })
            .collect();
        let cy: Vec<f64> = model
            .triangles
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&v| model.positions[v as usize][1])
                    .sum::<f64>()
                    / 3.0
            })
            .collect();
        let nearest = |x: f64, y: f64| {
            (0..cx.len())
                .min_by(|&a, &b| {
                    let da = (cx[a] - x).powi(2) + (cy[a] - y).powi(2);
                    let db = (cx[b] - x).powi(2) + (cy[b] - y).powi(2);
                    da.total_cmp(&db)
                })
                .unwrap()
        };
        let mut l: Vec<f64> = cx
            .iter()
            .map(|&x| if x < 0.0 { 1.0 } else { -1.0 })
            .collect();
        let (neg_in_w, pos_out) = (nearest(-0.07, 0.0), nearest(0.07, 0.0));
        l[neg_in_w] = -1.0;
        l[pos_out] = 1.0;
        (model.triangles, l, cx, neg_in_w, pos_out)
    }

    #[test]
    fn text_rule_smooths_outliers() {
        let (tris, l, cx, neg_in_w, pos_out) = synthetic();
        let w = wrinkle_free_faces(&tris, &l, WRule::Text);
        assert!(w[neg_in_w], "a compressed face surrounded by W joins W");
        assert!(!w[pos_out], "an isolated tension face stays out of W");
        for (f, &x) in cx.iter().enumerate() {
            if x < -0.03 {
                assert!(w[f], "face {f} at x {x}");
            }
            if x > 0.03 {
                assert!(!w[f], "face {f} at x {x}");
            }
        }
    }

    #[test]
    fn reference_rule_fills_by_vertices() {
        let (tris, l, cx, neg_in_w, pos_out) = synthetic();
        let w = wrinkle_free_faces(&tris, &l, WRule::Reference);
        assert!(w[neg_in_w] && w[pos_out]);
        for (f, &x) in cx.iter().enumerate() {
            if x < 0.0 {
                assert!(w[f]);
            }
        }
        // λ_c = 0 exactly: W under the reference's ≥ 0, not under the text's > 0
        let zero = vec![0.0; tris.len()];
        assert!(wrinkle_free_faces(&tris, &zero, WRule::Reference)
            .iter()
            .all(|&x| x));
        assert!(wrinkle_free_faces(&tris, &zero, WRule::Text)
            .iter()
            .all(|&x| !x));
        // pure tension: every face in W
        let pos = vec![0.01; tris.len()];
        assert!(wrinkle_free_faces(&tris, &pos, WRule::Text)
            .iter()
            .all(|&x| x));
    }

    #[test]
    fn initialization_on_the_twisted_cylinder() {
        let model = Scene::twisted_cylinder(24, 9, 10.0).assemble().unwrap();
        let r = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
        let strains = face_strains(&model.rest_forms, &r.mesh);
        let lc: Vec<f64> = strains.iter().map(|s| s.lambda_c).collect();
        let w = wrinkle_free_faces(&model.triangles, &lc, WRule::Text);
        let mut clamped = vec![false; model.positions.len()];
        for &(v, _) in &model.clamps {
            clamped[v as usize] = true;
        }
        let k = 0.01;
        let init = initial_face_field(&r.mesh, &model.rest_forms, &strains, &w, &clamped, k);
        let max_a = init.face_amplitude.iter().fold(0.0f64, |m, &a| m.max(a));
        assert!((max_a - k).abs() < 1e-15);
        assert!(init.vertex_amplitude.iter().all(|&a| a >= 0.0));
        assert!(clamped
            .iter()
            .zip(&init.vertex_amplitude)
            .all(|(&c, &a)| !c || a == 0.0));
        let mut active = 0;
        for (f, s) in strains.iter().enumerate() {
            let a = init.face_amplitude[f];
            if a == 0.0 {
                continue;
            }
            active += 1;
            // eq. 2.8: ½ a² |ω|²_Ī = |λ_c|, |ω|²_Ī = ωᵀ Ī⁻¹ ω
            let r = model.rest_forms[f];
            let o = init.face_omega[f];
            let det = r[0] * r[2] - r[1] * r[1];
            let n2 = (r[2] * o[0] * o[0] - 2.0 * r[1] * o[0] * o[1] + r[0] * o[1] * o[1]) / det;
            assert!((0.5 * a * a * n2 - s.lambda_c.abs()).abs() < 1e-12 * s.lambda_c.abs());
        }
        assert!(active > model.triangles.len() / 2);
        // combing: neighbouring wave vectors agree in sign almost everywhere
        let nb = face_neighbours(&model.triangles);
        let (mut agree, mut pairs) = (0, 0);
        for (f, nbf) in nb.iter().enumerate() {
            for &g in nbf {
                if f < g && init.face_amplitude[f] > 0.0 && init.face_amplitude[g] > 0.0 {
                    pairs += 1;
                    let (a, b) = (
                        embedded_wave_vector(&r.mesh, f, init.face_omega[f]),
                        embedded_wave_vector(&r.mesh, g, init.face_omega[g]),
                    );
                    if a[0] * b[0] + a[1] * b[1] + a[2] * b[2] >= 0.0 {
                        agree += 1;
                    }
                }
            }
        }
        assert!(agree as f64 >= 0.95 * pairs as f64, "{agree} of {pairs}");
        // Helmholtz projection: curl-free on every non-W face
        let p = helmholtz_projection(&r.mesh, &model.rest_forms, &init.face_omega, &w).unwrap();
        assert!(p.curl_residual <= 1e-10, "{}", p.curl_residual);
        assert!(p.omega.iter().any(|&x| x.abs() > 1e-3));
    }

    #[test]
    fn projection_of_an_exact_differential_returns_it() {
        let model = small_sheet(9, 6).assemble().unwrap();
        let base = TriMesh::new(model.positions.clone(), model.triangles.clone()).unwrap();
        let psi = |v: u32| {
            let p = model.positions[v as usize];
            30.0 * p[0] + 50.0 * p[1]
        };
        let face_omega: Vec<[f64; 2]> = model
            .triangles
            .iter()
            .map(|t| [psi(t[1]) - psi(t[0]), psi(t[2]) - psi(t[0])])
            .collect();
        let w = vec![false; model.triangles.len()];
        let p = helmholtz_projection(&base, &model.rest_forms, &face_omega, &w).unwrap();
        assert!(p.curl_residual <= 1e-10, "{}", p.curl_residual);
        for (e, &o) in base.edges().edges.iter().zip(&p.omega) {
            let want = psi(e.0[1]) - psi(e.0[0]);
            assert!(
                (o - want).abs() <= 1e-6 * want.abs().max(1e-3),
                "{o} vs {want}"
            );
        }
    }
}

#[test]
fn pure_compression_is_reported_out_of_scope_without_panic() {
    // every boundary vertex pushed inward to 0.97 × its rest position: all faces slack
    let (nx, ny) = (9, 5);
    let mut scene = small_sheet(nx, ny);
    let boundary: Vec<u32> = (0..nx * ny)
        .filter(|&k| k % nx == 0 || k % nx == nx - 1 || k / nx == 0 || k / nx == ny - 1)
        .map(|k| k as u32)
        .collect();
    let panel = &mut scene.panels[0];
    let init: Vec<[f64; 3]> = panel
        .positions
        .as_ref()
        .unwrap()
        .iter()
        .map(|p| [0.97 * p[0], 0.97 * p[1], 0.0])
        .collect();
    panel.positions = Some(init);
    scene.dirichlet = vec![Dirichlet {
        panel: 0,
        vertices: boundary,
        motion: Motion::default(),
    }];
    let model = scene.assemble().unwrap();
    let r = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
    assert!(r.strain.slack_area_fraction > 0.99, "{:?}", r.strain);
    assert!(
        r.warnings.iter().any(|w| w.contains("out of scope")),
        "{:?}",
        r.warnings
    );
    assert_eq!(r.energies.membrane, 0.0);
}

mod wrinkle_energy {
    use super::*;
    use pleat::mesh::TriMesh;
    use pleat::tfw::curvature::tension_curvature;
    use pleat::tfw::energy::{HessianMode, WfTerms, WrinkleEnergy};
    use pleat::tfw::wfree::face_strains;

    /// A stretched, compressed and slightly curved small sheet, its energy and a state
    /// `[a | ω]` with `a > 0`.
    fn fixture() -> (WrinkleEnergy, Vec<f64>) {
        let model = small_sheet(5, 4).assemble().unwrap();
        let x = perturbed(&model, 1.05, 0.95, 2e-3);
        let pos: Vec<[f64; 3]> = x.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        let base = TriMesh::new(pos, model.triangles.clone()).unwrap();
        let strains = face_strains(&model.rest_forms, &base);
        let kappa = tension_curvature(&base, &strains);
        assert!(kappa.iter().any(|k| k.abs() > 1e-3));
        let lame = model.material.lame();
        let e = WrinkleEnergy::new(
            &base,
            &model.rest_forms,
            &strains,
            &kappa,
            lame,
            model.material.thickness,
        );
        let nv = e.vertex_count();
        let state: Vec<f64> = (0..e.dimension())
            .map(|k| {
                if k < nv {
                    0.02 * (1.5 + noise(100 + k))
                } else {
                    3.0 * noise(100 + k)
                }
            })
            .collect();
        (e, state)
    }

    fn check(e: &WrinkleEnergy, x: &[f64], terms: WfTerms, what: &str) {
        let ev = e.evaluate(x, terms, HessianMode::Exact);
        // one generic formula in two arithmetics: the same bits (the line search's energy
        // is the Newton step's)
        assert_eq!(
            ev.energy.to_bits(),
            e.energy(x, terms).to_bits(),
            "{what}: energy paths disagree"
        );
        assert!(ev.energy > 0.0, "{what}: zero energy, test is vacuous");
        let h = dense_hessian(x.len(), &ev.hessian);
        let gscale = ev.gradient.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let hscale = h.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let nv = e.vertex_count();
        for k in 0..x.len() {
            let step = if k < nv { 1e-6 } else { 1e-5 };
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[k] += step;
            xm[k] -= step;
            let fd = (e.energy(&xp, terms) - e.energy(&xm, terms)) / (2.0 * step);
            assert!(
                (fd - ev.gradient[k]).abs() <= 1e-6 * gscale,
                "{what}: gradient {k}: fd {fd} vs {}",
                ev.gradient[k]
            );
            let gp = e.evaluate(&xp, terms, HessianMode::Exact).gradient;
            let gm = e.evaluate(&xm, terms, HessianMode::Exact).gradient;
            for j in 0..x.len() {
                let fd = (gp[j] - gm[j]) / (2.0 * step);
                assert!(
                    (fd - h[j][k]).abs() <= 1e-6 * hscale,
                    "{what}: Hessian ({j},{k}): fd {fd} vs {}",
                    h[j][k]
                );
            }
        }
    }

    #[test]
    fn every_wrinkle_energy_term_matches_finite_differences() {
        let (e, x) = fixture();
        let one = |f: fn(&mut WfTerms)| {
            let mut t = WfTerms::NONE;
            f(&mut t);
            t
        };
        check(&e, &x, one(|t| t.stretch1 = true), "W_s1 (2.21)");
        check(&e, &x, one(|t| t.stretch2 = true), "W_s2 (2.22)");
        check(&e, &x, one(|t| t.stretch3 = true), "W_s3 (2.23)");
        check(&e, &x, one(|t| t.stretch4 = true), "W_s4 (2.24)");
        check(&e, &x, one(|t| t.bend2 = true), "W_b2 (2.26)");
        let all = e.energy(&x, WfTerms::ALL);
        let parts: f64 = [
            one(|t| t.stretch1 = true),
            one(|t| t.stretch2 = true),
            one(|t| t.stretch3 = true),
            one(|t| t.stretch4 = true),
            one(|t| t.bend2 = true),
        ]
        .iter()
        .map(|&t| e.energy(&x, t))
        .sum();
        assert!((all - parts).abs() <= 1e-12 * all);
    }

    #[test]
    fn projected_hessian_is_positive_semidefinite_per_face_and_keeps_the_gradient() {
        let (e, x) = fixture();
        let ex = e.evaluate(&x, WfTerms::ALL, HessianMode::Exact);
        let pr = e.evaluate(&x, WfTerms::ALL, HessianMode::ProjectedPerFace);
        assert_eq!(ex.gradient, pr.gradient);
        let h = dense_hessian(x.len(), &pr.hessian);
        // vᵀHv ≥ 0 on a few pseudo-random directions
        for s in 0..20 {
            let v: Vec<f64> = (0..x.len()).map(|k| noise(1000 * s + k)).collect();
            let q: f64 = (0..x.len())
                .map(|i| v[i] * (0..x.len()).map(|j| h[i][j] * v[j]).sum::<f64>())
                .sum();
            assert!(q >= -1e-12 * h.iter().flatten().fold(0.0f64, |m, y| m.max(y.abs())));
        }
    }

    /// The one-pass evaluation of the exact-Hessian CG refinement (2026-11-27)
    /// returns exactly the two evaluations it replaces.
    #[test]
    fn projected_and_exact_in_one_pass_equal_the_two_evaluations() {
        let (e, x) = fixture();
        let ex = e.evaluate(&x, WfTerms::ALL, HessianMode::Exact);
        let pr = e.evaluate(&x, WfTerms::ALL, HessianMode::ProjectedPerFace);
        let (p, h) = e.evaluate_projected_and_exact(&x, WfTerms::ALL);
        assert_eq!(p, pr);
        assert_eq!(h, ex.hessian);
    }

    /// The spec's uniform-patch optimum (da = 0): `|ω|* = (48β(α+β)/(α+2β)²)^{1/4}
    /// √(κ(1+λ_t)/h)` and `½[α(λ_t+λ_c+P/2) + 2β(λ_c+P/2)] = −(h²/6)(α+2β)s`, `s = |ω|²`,
    /// `P = a²s`, reproduced by Newton on `(a, w)` with the code's gradient and Hessian.
    #[test]
    fn uniform_patch_closed_form() {
        let (lt, lc, kappa, h) = (0.02, -0.03, 2.0, 1e-4);
        let lame = Lame::from_young_poisson(1e6, 0.3);
        let (al, be) = (lame.alpha, lame.beta);
        let rest = rest_form([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let base = TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [(1.0f64 + lt).sqrt(), 0.0, 0.0],
                [0.0, (1.0f64 + lc).sqrt(), 0.0],
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let strains = face_strains(&[rest], &base);
        let e = WrinkleEnergy::new(&base, &[rest], &strains, &[kappa], lame, h);
        // edges (0,1), (0,2), (1,2): ω(0→1) = 0, ω(0→2) = w, ω(1→2) = w
        let state = |a: f64, w: f64| vec![a, a, a, 0.0, w, w];
        // chain rule to (a, w): J = [[1,1,1,0,0,0],[0,0,0,0,1,1]]
        let jac = [
            [1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 1.0, 1.0],
        ];
        let s_star = (48.0 * kappa * kappa * (1.0 + lt).powi(2) * be * (al + be)).sqrt()
            / ((al + 2.0 * be) * h);
        let w_star = s_star.sqrt();
        // P from the amplitude condition
        let p_star = 2.0
            * (-(h * h / 6.0) * (al + 2.0 * be) * s_star * 2.0 - al * (lt + lc) - 2.0 * be * lc)
            / (al + 2.0 * be);
        let a_star = (p_star / s_star).sqrt();
        let (mut a, mut w) = (1.1 * a_star, 0.9 * w_star);
        for _ in 0..60 {
            let ev = e.evaluate(&state(a, w), WfTerms::ALL, HessianMode::Exact);
            let hd = dense_hessian(6, &ev.hessian);
            let g: [f64; 2] =
                std::array::from_fn(|r| (0..6).map(|k| jac[r][k] * ev.gradient[k]).sum());
            let hm: [[f64; 2]; 2] = std::array::from_fn(|r| {
                std::array::from_fn(|c| {
                    (0..6)
                        .map(|i| {
                            (0..6)
                                .map(|j| jac[r][i] * hd[i][j] * jac[c][j])
                                .sum::<f64>()
                        })
                        .sum()
                })
            });
            let det = hm[0][0] * hm[1][1] - hm[0][1] * hm[1][0];
            let da = (hm[1][1] * g[0] - hm[0][1] * g[1]) / det;
            let dw = (-hm[1][0] * g[0] + hm[0][0] * g[1]) / det;
            a -= da;
            w -= dw;
        }
        assert!(
            (w.abs() - w_star).abs() <= 1e-6 * w_star,
            "|ω| {w} vs {w_star}"
        );
        assert!((a - a_star).abs() <= 1e-6 * a_star, "a {a} vs {a_star}");
    }
}

mod wrinkle_sqp {
    use super::*;
    use pleat::tfw::{solve, QpMethod, SqpOptions, TfwParams, TfwStatus};

    fn params(max_iterations: usize) -> TfwParams {
        TfwParams {
            sqp: SqpOptions {
                max_iterations,
                ..SqpOptions::default()
            },
            ..TfwParams::default()
        }
    }

    pub fn params_with(max_iterations: usize, qp: QpMethod) -> TfwParams {
        let mut p = params(max_iterations);
        p.sqp.qp = qp;
        p
    }

    #[test]
    fn sqp_keeps_curl_free_nonnegative_amplitude_and_lowers_the_energy() {
        invariants(QpMethod::Clarabel);
    }

    /// The same invariants for the projected Newton with the curl eliminated.
    #[test]
    fn projected_newton_keeps_curl_free_nonnegative_amplitude_and_lowers_the_energy() {
        invariants(QpMethod::ProjectedNewton);
    }

    /// Both step solvers run to convergence on a small sheet reach the same energy (1e-6
    /// relative; measured 8e-7) and the same peak amplitude within 2 % (measured 1.5 %; the
    /// energy is flat along some directions and both stop on the relative energy test, as in
    /// the Young-modulus test below).
    #[test]
    fn projected_newton_agrees_with_clarabel_on_a_small_sheet() {
        let scene = Scene::stretched_sheet(21, 9, 0.1);
        let r1 = solve(
            &scene,
            &params_with(1000, QpMethod::Clarabel),
            &mut no_progress(),
        )
        .unwrap();
        let r2 = solve(
            &scene,
            &params_with(1000, QpMethod::ProjectedNewton),
            &mut no_progress(),
        )
        .unwrap();
        let peak =
            |r: &pleat::tfw::TfwResult| r.cwf.amplitude().iter().fold(0.0f64, |m, &a| m.max(a));
        let (s1, s2) = (r1.sqp.as_ref().unwrap(), r2.sqp.as_ref().unwrap());
        eprintln!(
            "clarabel: {:?} {} it, {:.3}s, E {:.9e}, peak {:.4e}; projected Newton: {:?} {} it, \
             {:.3}s, E {:.9e}, peak {:.4e}",
            s1.status,
            s1.history.len(),
            s1.seconds,
            r1.energy,
            peak(&r1),
            s2.status,
            s2.history.len(),
            s2.seconds,
            r2.energy,
            peak(&r2)
        );
        assert!(
            (r1.energy - r2.energy).abs() <= 1e-6 * r1.energy.abs(),
            "energies differ"
        );
        assert!(
            (peak(&r1) - peak(&r2)).abs() <= 2e-2 * peak(&r1),
            "peaks differ"
        );
    }

    fn invariants(qp: QpMethod) {
        let scene = Scene::stretched_sheet(21, 9, 0.1);
        let r = solve(&scene, &params_with(40, qp), &mut no_progress()).unwrap();
        let sqp = r.sqp.as_ref().expect("the sheet has compressed faces");
        eprintln!(
            "sheet 21x9: status {:?} / {:?}, {} it, E0 {:.6e} → {:.6e}, r0 {:.3e}, seconds {:?}, qp {:.3}s",
            r.status,
            sqp.status,
            sqp.history.len(),
            sqp.initial_energy,
            r.energy,
            sqp.initial_stationarity,
            r.seconds,
            sqp.qp_seconds
        );
        for (k, it) in sqp.history.iter().enumerate() {
            eprintln!(
                "  {k:3} E {:.9e} r {:.3e} |dx| {:.3e} t {} qp_it {} curl {:.1e} {:.3}s",
                it.energy,
                it.stationarity,
                it.step_norm,
                it.step_length,
                it.qp_iterations,
                it.curl_residual,
                it.seconds
            );
        }
        assert!(r.init_curl_residual <= 1e-10, "{}", r.init_curl_residual);
        assert!(!sqp.history.is_empty());
        let mut prev = sqp.initial_energy;
        for it in &sqp.history {
            assert!(it.curl_residual <= 1e-10, "curl {}", it.curl_residual);
            assert!(it.energy <= prev, "E rose: {prev} → {}", it.energy);
            prev = it.energy;
        }
        assert!(r.cwf.amplitude().iter().all(|&a| a >= 0.0));
        assert!(r.cwf.amplitude().iter().any(|&a| a > 0.0));
        assert!(r.energy < sqp.initial_energy);
        assert_ne!(r.status, TfwStatus::OutOfScope);
    }

    /// Displacement-driven scene: E^wf ∝ Y and the base is Y-independent, so with the relative
    /// tolerances the amplitudes and the one-form do not change with Y × 10⁴. Measured: 0.6 %
    /// of the peak amplitude (the energy is flat along some directions: both runs stop on the
    /// relative energy test 1e-10 at slightly different points); the bound is 2 %.
    #[test]
    fn young_modulus_times_1e4_gives_the_same_wrinkles() {
        same_wrinkles_under_young_times_1e4(QpMethod::Clarabel);
    }

    /// The same check with the projected Newton step solver.
    #[test]
    fn young_modulus_times_1e4_gives_the_same_wrinkles_projected_newton() {
        same_wrinkles_under_young_times_1e4(QpMethod::ProjectedNewton);
    }

    fn same_wrinkles_under_young_times_1e4(qp: QpMethod) {
        let scene = Scene::stretched_sheet(21, 9, 0.1);
        let mut stiff = scene.clone();
        stiff.material.young *= 1e4;
        let r1 = solve(&scene, &params_with(200, qp), &mut no_progress()).unwrap();
        let r2 = solve(&stiff, &params_with(200, qp), &mut no_progress()).unwrap();
        for (name, r) in [("Y", &r1), ("Y x 1e4", &r2)] {
            let s = r.sqp.as_ref().unwrap();
            eprintln!(
                "{qp:?} {name}: base {:?} {} it rel. gradient {:.2e}; W faces {}; SQP {:?} {} it, \
                 E0 {:.9e} E {:.9e} r0 {:.3e}",
                r.base.status,
                r.base.history.len(),
                r.base.relative_gradient,
                r.w_faces.iter().filter(|&&w| w).count(),
                s.status,
                s.history.len(),
                s.initial_energy,
                r.energy,
                s.initial_stationarity
            );
        }
        let (h1, h2) = (
            &r1.sqp.as_ref().unwrap().history,
            &r2.sqp.as_ref().unwrap().history,
        );
        for (k, (a, b)) in h1.iter().zip(h2.iter()).enumerate() {
            eprintln!(
                "  {k:3} E ratio {:.12e} r/r0 {:.3e} {:.3e} t {} {} shift {:.1e} {:.1e}",
                b.energy / a.energy,
                a.stationarity / r1.sqp.as_ref().unwrap().initial_stationarity,
                b.stationarity / r2.sqp.as_ref().unwrap().initial_stationarity,
                a.step_length,
                b.step_length,
                a.shift,
                b.shift
            );
        }
        let e_ratio = r2.energy / r1.energy;
        assert!(
            (e_ratio - 1e4).abs() <= 1e-4 * 1e4,
            "energy ratio {e_ratio}"
        );
        let close = |x: &[f64], y: &[f64], what: &str| {
            let big = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = x
                .iter()
                .zip(y)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(diff <= 2e-2 * big, "{what}: max diff {diff} vs max {big}");
        };
        close(r1.cwf.amplitude(), r2.cwf.amplitude(), "a");
        // ω only where the amplitude is not small: where a ≈ 0 the energy does not see ω
        // (flat directions, only the curl constraint holds it)
        let a = r1.cwf.amplitude();
        let amax = a.iter().fold(0.0f64, |m, &v| m.max(v));
        let (w1, w2): (Vec<f64>, Vec<f64>) = r1
            .cwf
            .edges()
            .iter()
            .zip(r1.cwf.omega().iter().zip(r2.cwf.omega()))
            .filter(|(e, _)| e.iter().all(|&v| a[v as usize] >= 0.3 * amax))
            .map(|(_, (x, y))| (*x, *y))
            .unzip();
        assert!(!w1.is_empty());
        close(&w1, &w2, "omega where a ≥ 0.3 max a");
    }

    /// Pure tension (all boundary stretched outward by 5 %): every face is wrinkle-free, the
    /// call returns at once with a ≡ 0, ω ≡ 0 and `NoCompression`.
    #[test]
    fn pure_tension_returns_no_compression_with_zero_field() {
        let (nx, ny) = (9, 5);
        let mut scene = small_sheet(nx, ny);
        let boundary: Vec<u32> = (0..nx * ny)
            .filter(|&k| k % nx == 0 || k % nx == nx - 1 || k / nx == 0 || k / nx == ny - 1)
            .map(|k| k as u32)
            .collect();
        let panel = &mut scene.panels[0];
        let init: Vec<[f64; 3]> = panel
            .positions
            .as_ref()
            .unwrap()
            .iter()
            .map(|p| [1.05 * p[0], 1.05 * p[1], 0.0])
            .collect();
        panel.positions = Some(init);
        scene.dirichlet = vec![Dirichlet {
            panel: 0,
            vertices: boundary,
            motion: Motion::default(),
        }];
        let r = solve(&scene, &params(10), &mut no_progress()).unwrap();
        assert_eq!(
            r.status,
            TfwStatus::NoCompression,
            "{}",
            r.status.describe()
        );
        assert!(r.sqp.is_none());
        assert!(r.cwf.amplitude().iter().all(|&a| a == 0.0));
        assert!(r.cwf.omega().iter().all(|&w| w == 0.0));
    }

    /// The shipped example scene is the built-in stretched sheet at 5 % (regenerate with
    /// `PLEAT_BLESS=1`).
    #[test]
    fn shipped_stretched_sheet_scene_matches_the_builtin() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/tfw/stretched_sheet.json");
        let want = Scene::stretched_sheet(37, 14, 0.05).to_json_string();
        if std::env::var_os("PLEAT_BLESS").is_some() {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, &want).unwrap();
        }
        let got = Scene::from_json_file(&path).unwrap();
        assert_eq!(got.to_json_string(), want);
    }

    /// The shipped cylinder scene (a polygon panel meshed at load time, Dirichlet rings by
    /// `rest_box`) is the built-in Delaunay cylinder.
    #[test]
    fn shipped_twisted_cylinder_scene_matches_the_builtin() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/tfw/twisted_cylinder.json");
        let mut got = Scene::from_json_file(&path).unwrap();
        let want = Scene::twisted_cylinder_delaunay(720, 10.0, 1).unwrap();
        got.name = want.name.clone();
        assert_eq!(got, want);
        let model = got.assemble().unwrap();
        let n = model.positions.len();
        assert!((650..=760).contains(&n), "{n} vertices after sewing");
        // both rings clamped, the seam sewn: a closed tube has as many boundary vertices as
        // clamped ones
        assert_eq!(model.clamps.len(), 2 * want.dirichlet[0].vertices.len() - 2);
        // the parsed-and-written scene reads back to the same model
        let again = Scene::from_json_str(&got.to_json_string()).unwrap();
        assert_eq!(again.assemble().unwrap().triangles, model.triangles);
    }

    /// The shipped sheared rectangle is the built-in one (3 mm shear, no pre-stretch).
    #[test]
    fn shipped_sheared_rectangle_scene_matches_the_builtin() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/tfw/sheared_rectangle.json");
        let mut got = Scene::from_json_file(&path).unwrap();
        let want = Scene::sheared_rectangle(1000, 3.0, 0.0, 1).unwrap();
        got.name = want.name.clone();
        assert_eq!(got, want);
        let n = got.panels[0].rest.len();
        assert!((900..=1100).contains(&n), "{n} vertices");
    }

    /// Polygon panels: errors name the field.
    #[test]
    fn polygon_panel_errors_name_the_field() {
        let base = |panel: &str, dir: &str| {
            format!(
                r#"{{"material": {{"young": 1e6, "poisson": 0.3, "thickness": 1e-4}},
                    "panels": [{panel}], "dirichlet": [{dir}]}}"#
            )
        };
        let ok = r#"{"polygon": [[0,0],[1,0],[1,1],[0,1]], "target_vertices": 50}"#;
        let s =
            Scene::from_json_str(&base(ok, r#"{"panel": 0, "rest_box": [[0,0],[1,0]]}"#)).unwrap();
        assert!((45..=55).contains(&s.panels[0].rest.len()));
        assert!(s.dirichlet[0].vertices.len() >= 2);
        for (panel, dir, want) in [
            (
                r#"{"polygon": [[0,0],[1,0],[1,1]], "target_vertices": 50, "rest": []}"#,
                "",
                "panels[0].rest",
            ),
            (
                r#"{"polygon": [[0,0],[1,0],[1,1]]}"#,
                "",
                "panels[0].target_vertices",
            ),
            (
                r#"{"polygon": [[0,0],[1,0]], "target_vertices": 50}"#,
                "",
                "panels[0]: polygon panel: polygon",
            ),
            (
                r#"{"rest": [[0,0],[1,0],[0,1]], "triangles": [[0,1,2]], "seed": 3}"#,
                "",
                "panels[0].seed",
            ),
            (
                ok,
                r#"{"panel": 0, "rest_box": [[5,5],[6,6]]}"#,
                "dirichlet[0].rest_box",
            ),
            (ok, r#"{"panel": 0}"#, "dirichlet[0].vertices"),
            (
                r#"{"polygon": [[0,0],[1,0],[1,1]], "target_vertices": 50, "roll_radius": -1}"#,
                "",
                "panels[0].roll_radius",
            ),
            (
                r#"{"polygon": [[0,0],[1,0],[1,1]], "target_vertices": 50, "lens": 0}"#,
                "",
                "panels[0].lens",
            ),
            (
                r#"{"rest": [[0,0],[1,0],[0,1]], "triangles": [[0,1,2]], "lens": 0.1}"#,
                "",
                "panels[0].lens",
            ),
        ] {
            let e = Scene::from_json_str(&base(panel, dir))
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{e} should name {want}");
        }
    }
}

mod stretched_sheet_check {
    use super::*;
    use pleat::mesh::TriMesh;
    use pleat::tfw::measure::{section_waves, Section};
    use pleat::tfw::{solve, TfwParams};
    use pleat::wrinkle::EvalOptions;

    /// Independent wave counter: sign changes of the normal displacement (z: the base stays
    /// in the plane z = 0) where the wrinkled mesh crosses the plane x = 0, ordered across the
    /// width, values below 1% of the peak ignored (the library's
    /// [`pleat::tfw::measure::section_waves`]); periods = crossings / 2. Returns (periods,
    /// peak |z|).
    fn periods_and_peak(mesh: &TriMesh) -> (f64, f64) {
        let z: Vec<f64> = mesh.positions().iter().map(|p| p[2]).collect();
        let c = section_waves(
            mesh.positions(),
            mesh.triangles(),
            &z,
            &Section::line([0.0; 3], [1.0, 0.0, 0.0]),
        );
        (c.waves, c.peak)
    }

    /// Solves the stretched sheet (0.25 × 0.1 m, h 0.1 mm, ν 0.5, Y 1 MPa, 37 × 14 =
    /// 518 vertices) at `stretch`, evaluates 3 Loop levels with the v2 term and returns
    /// (periods across the width on the mid line, peak |z| there, max a), all in m.
    fn sheet(stretch: f64) -> (f64, f64, f64) {
        let scene = Scene::stretched_sheet(37, 14, stretch);
        let r = solve(&scene, &TfwParams::default(), &mut no_progress()).unwrap();
        let sqp = r.sqp.as_ref().unwrap();
        let opts = EvalOptions {
            in_plane_v2: true,
            ..EvalOptions::default()
        };
        let (ev, _) = r.cwf.evaluate(3, &opts).unwrap();
        let (periods, peak_z) = periods_and_peak(&ev.mesh);
        let max_a = r.cwf.amplitude().iter().fold(0.0f64, |m, &a| m.max(a));
        eprintln!(
            "stretch {stretch}: {:?} / {:?} in {} it, {:.2}s (base {:.2}s, sqp {:.2}s); \
             periods across the width {periods}, peak |z| on the mid line {:.3} mm, \
             max a {:.3} mm, {} of {} faces in W",
            r.status,
            sqp.status,
            sqp.history.len(),
            r.seconds.base + r.seconds.init + r.seconds.sqp + r.seconds.phase,
            r.seconds.base,
            r.seconds.sqp,
            peak_z * 1e3,
            max_a * 1e3,
            r.w_faces.iter().filter(|&&w| w).count(),
            r.w_faces.len()
        );
        (periods, peak_z, max_a)
    }

    /// The expected result: 5 periods across the width and a peak amplitude in [0.28, 0.50] mm.
    /// The dissertation does not give the stretch; 5% is used (see the ignored sweep).
    #[test]
    fn stretched_sheet_has_five_periods_and_the_expected_amplitude() {
        let (periods, peak_z, max_a) = sheet(0.05);
        assert!((4.5..=5.5).contains(&periods), "{periods} periods");
        assert!((0.28e-3..=0.50e-3).contains(&peak_z), "peak |z| {peak_z}");
        assert!((0.28e-3..=0.50e-3).contains(&max_a), "max a {max_a}");
    }

    /// The sheet at several stretches (report only). Run with
    /// `cargo test --test tfw stretched_sheet_sweep -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn stretched_sheet_sweep() {
        for stretch in [0.02, 0.05, 0.1, 0.2] {
            sheet(stretch);
        }
    }
}

mod twisted_cylinder_check {
    use super::*;
    use pleat::tfw::{solve, TfwParams};

    /// Base-surface measurements on the mid-height ring (|z − 2.5| ≤ 0.25 m): mean radius,
    /// mean angle between the tension direction and the axis (degrees), mean |κ| along it,
    /// mean λ_t and λ_c.
    pub struct MidRing {
        pub radius: f64,
        pub tension_angle_deg: f64,
        pub kappa: f64,
        pub lambda_t: f64,
        pub lambda_c: f64,
    }

    pub fn mid_ring(r: &pleat::tfw::TfwResult, model: &Model) -> MidRing {
        use pleat::tfw::wfree::face_strains;
        let mesh = &r.base.mesh;
        let p = mesh.positions();
        let near = |z: f64| (z - 2.5).abs() <= 0.25;
        let ring_v: Vec<f64> = p
            .iter()
            .filter(|q| near(q[2]))
            .map(|q| q[0].hypot(q[1]))
            .collect();
        let strains = face_strains(&model.rest_forms, mesh);
        let (mut n, mut ang, mut kap, mut lt, mut lc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (f, t) in mesh.triangles().iter().enumerate() {
            let c = t.map(|v| p[v as usize]);
            if !near((c[0][2] + c[1][2] + c[2][2]) / 3.0) {
                continue;
            }
            let w = strains[f].tension_dir;
            let d: Vec<f64> = (0..3)
                .map(|k| (c[1][k] - c[0][k]) * w[0] + (c[2][k] - c[0][k]) * w[1])
                .collect();
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            ang += (d[2].abs() / len).acos().to_degrees();
            kap += r.curvature[f].abs();
            lt += strains[f].lambda_t;
            lc += strains[f].lambda_c;
            n += 1.0;
        }
        MidRing {
            radius: ring_v.iter().sum::<f64>() / ring_v.len() as f64,
            tension_angle_deg: ang / n,
            kappa: kap / n,
            lambda_t: lt / n,
            lambda_c: lc / n,
        }
    }

    /// Waves around the mid-height ring: [`ring_waves`] on the plane z = 2.5.
    pub fn mid_ring_waves(cwf: &pleat::wrinkle::Cwf) -> f64 {
        ring_waves(cwf, 2.5, 0.0)
    }

    /// Waves around a ring: sign changes of `Re z` where the evaluated mesh (2 Loop levels)
    /// crosses the plane z = `plane_z` at a distance ≥ `min_radius` from the z axis, ordered
    /// by angle about the axis, values below 1% of the peak ignored; waves = crossings / 2
    /// (the library's [`pleat::tfw::measure::count_waves`]).
    pub fn ring_waves(cwf: &pleat::wrinkle::Cwf, plane_z: f64, min_radius: f64) -> f64 {
        use pleat::tfw::measure::{count_waves, Section};
        let section = Section {
            min_radius,
            ..Section::ring([0.0, 0.0, plane_z], [0.0, 0.0, 1.0])
        };
        count_waves(cwf, 2, &section).unwrap().waves
    }

    /// Solves `scene` and prints the base measurements and the wave count; returns the count.
    pub fn report(scene: &Scene, params: &TfwParams) -> f64 {
        let model = scene.assemble().unwrap();
        let r = solve(scene, params, &mut no_progress()).unwrap();
        super::print_phase(&r);
        let sqp = r.sqp.as_ref().unwrap();
        let ring = mid_ring(&r, &model);
        let waves = mid_ring_waves(&r.cwf);
        let every: usize = std::env::var("PLEAT_CYL_HISTORY").map_or(50, |v| v.parse().unwrap());
        for (k, it) in sqp.history.iter().enumerate() {
            if k % every == 0 || k + 1 == sqp.history.len() {
                eprintln!(
                    "  it {k}: E {:.10e}, r/r0 {:.2e}, step {:.2e}, t {:.2}, shift {:.1e}, cg {}, \
                     held {}, {:.1}s",
                    it.energy,
                    it.stationarity / sqp.initial_stationarity,
                    it.step_norm,
                    it.step_length,
                    it.shift,
                    it.cg_iterations,
                    it.held,
                    it.seconds
                );
            }
        }
        let max_a = r.cwf.amplitude().iter().fold(0.0f64, |m, &a| m.max(a));
        eprintln!(
            "{} ({} v): {:?} / {:?} in {} it, base {:.2}s ({:?}), sqp {:.2}s (qp {:.2}s); \
             mid ring: radius {:.4} m, tension {:.1}° from the axis, |κ| {:.4} 1/m, \
             λ_t {:.4}, λ_c {:.4}; waves around the mid ring {waves}, max a {:.3} mm, \
             {} of {} faces in W",
            scene.name,
            model.positions.len(),
            r.status,
            sqp.status,
            sqp.history.len(),
            r.seconds.base,
            r.base.status,
            r.seconds.sqp,
            sqp.qp_seconds,
            ring.radius,
            ring.tension_angle_deg,
            ring.kappa,
            ring.lambda_t,
            ring.lambda_c,
            max_a * 1e3,
            r.w_faces.iter().filter(|&&w| w).count(),
            r.w_faces.len()
        );
        waves
    }

    /// Measurements (report only): `PLEAT_CYL_TARGET` (default 720) vertices, curvature
    /// method `PLEAT_CYL_KAPPA` (`normals` or `quadric`), `PLEAT_CYL_ITERS` SQP iterations,
    /// thickness × `PLEAT_CYL_THICKNESS_SCALE` (default 1; 10⁻² for the thin-shell case),
    /// initial amplitude `PLEAT_CYL_K` (m), only the stationarity test at `PLEAT_CYL_RTOL`,
    /// every `PLEAT_CYL_HISTORY`-th SQP iteration printed (default 50).
    #[test]
    #[ignore]
    fn twisted_cylinder_measure() {
        use pleat::tfw::curvature::CurvatureMethod;
        let env = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.to_string());
        let target: usize = env("PLEAT_CYL_TARGET", "720").parse().unwrap();
        let iters: usize = env("PLEAT_CYL_ITERS", "1000").parse().unwrap();
        let mut params = TfwParams::default();
        params.sqp.max_iterations = iters;
        params.sqp.cg_refinement = crate::scene_speed::cg_refinement_from_env();
        params.sqp.valley_search = crate::scene_speed::valley_search_from_env();
        if let Ok(v) = std::env::var("PLEAT_CYL_RTOL") {
            params.sqp.stationarity_tolerance = v.parse().unwrap();
            params.sqp.energy_tolerance = 0.0;
            params.sqp.step_tolerance = 0.0;
        }
        params.initial_amplitude = std::env::var("PLEAT_CYL_K")
            .ok()
            .map(|v| v.parse().unwrap());
        super::snap_from_env(&mut params);
        params.curvature = match env("PLEAT_CYL_KAPPA", "quadric").as_str() {
            "normals" => CurvatureMethod::VertexNormals,
            _ => CurvatureMethod::QuadricFit,
        };
        let mut scene = Scene::twisted_cylinder_delaunay(target, 10.0, 1).unwrap();
        let h_scale: f64 = env("PLEAT_CYL_THICKNESS_SCALE", "1").parse().unwrap();
        scene.material.thickness *= h_scale;
        report(&scene, &params);
    }

    /// The thin-shell requirement, thickness × 10⁻² (≈10× more waves on the cylinder; no loss
    /// of convergence), on a coarse irregular twisted cylinder (378 v; main before the valley
    /// search: 1000 iterations, r/r₀ 2.4e-4, the same failure as at 690 and 1289 v): the SQP
    /// meets an A.6.3 test within the default 1000 iterations, every iterate keeps curl ≤ 1e-10
    /// and E non-increasing, a ≥ 0 at the end, and ω's period around the mid ring is ≈10× the
    /// thick shell's 46 turns (λ ∝ h^½, the spec's uniform-patch optimum |ω|* ∝ √(κ/h)).
    #[test]
    fn thin_twisted_cylinder_converges() {
        use pleat::tfw::TfwStatus;
        let mut scene = Scene::twisted_cylinder_delaunay(400, 10.0, 1).unwrap();
        scene.material.thickness *= 1e-2;
        // the snapping reports ω's period around the ring (it runs after the SQP)
        let params = TfwParams {
            snap_periods: true,
            ..TfwParams::default()
        };
        let r = solve(&scene, &params, &mut no_progress()).unwrap();
        let sqp = r.sqp.as_ref().unwrap();
        assert!(sqp.status.converged(), "{:?}", sqp.status);
        assert_eq!(r.status, TfwStatus::Converged);
        assert!(sqp.history.len() < 1000);
        let mut last = sqp.initial_energy;
        for h in &sqp.history {
            assert!(h.energy <= last, "E rose: {} > {last}", h.energy);
            assert!(h.curl_residual <= 1e-10, "curl {}", h.curl_residual);
            last = h.energy;
        }
        let nv = r.base.mesh.vertex_count();
        assert!(sqp.x[..nv].iter().all(|&a| a >= 0.0));
        let snap = r.snap.as_ref().unwrap();
        assert_eq!(snap.loops.len(), 1, "one loop around the cylinder");
        let turns = (snap.loops[0].before / std::f64::consts::TAU).abs();
        eprintln!(
            "thin cylinder: {:?} in {} it, ring period {turns:.1} turns",
            sqp.status,
            sqp.history.len()
        );
        assert!((345.0..=575.0).contains(&turns), "{turns} turns");
    }

    /// The twisted cylinder (r 1 m, height 5 m, h 0.1 mm, ν 0.44, Y 10 MPa, 10°) on
    /// irregular Delaunay meshes of ~700 and ~1300 vertices: expected 46 ± 5 waves around the
    /// mid-height ring ([`mid_ring_waves`]). Slow (ignored): `cargo test --release --test tfw
    /// twisted_cylinder_waves -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn twisted_cylinder_waves() {
        let params = TfwParams::default();
        for target in [720, 1330] {
            let scene = Scene::twisted_cylinder_delaunay(target, 10.0, 1).unwrap();
            let waves = report(&scene, &params);
            assert!((41.0..=51.0).contains(&waves), "{waves} waves");
        }
    }
}

mod curvature_check {
    use super::*;
    use pleat::mesh::TriMesh;
    use pleat::tfw::curvature::{tension_curvature, tension_curvature_quadric};
    use pleat::tfw::wfree::{face_strains, FaceStrain};

    /// On the untwisted cylinder (r = 1), the normal curvature along the circumferential
    /// direction is 1/r and along the axis 0 (Euler's formula in between).
    #[test]
    fn curvature_of_a_cylinder_by_direction() {
        let model = Scene::twisted_cylinder(43, 16, 0.0).assemble().unwrap();
        let base = TriMesh::new(model.positions.clone(), model.triangles.clone()).unwrap();
        let strains = face_strains(&model.rest_forms, &base);
        // rest frame: u around (arc length), v along the axis; direction (cos θ, sin θ) in the
        // rest plane → barycentric coordinates through the rest corners
        for theta_deg in [0.0f64, 45.0, 90.0] {
            let th = theta_deg.to_radians();
            let s: Vec<FaceStrain> = model
                .rest_corners
                .iter()
                .zip(&strains)
                .map(|(c, st)| {
                    let e1 = [c[1][0] - c[0][0], c[1][1] - c[0][1]];
                    let e2 = [c[2][0] - c[0][0], c[2][1] - c[0][1]];
                    let d = [th.cos(), th.sin()];
                    let det = e1[0] * e2[1] - e1[1] * e2[0];
                    let t = [
                        (d[0] * e2[1] - d[1] * e2[0]) / det,
                        (e1[0] * d[1] - e1[1] * d[0]) / det,
                    ];
                    FaceStrain {
                        tension_dir: t,
                        ..*st
                    }
                })
                .collect();
            let want = th.cos().powi(2);
            // the 5-ring fit (the spec's and R's default) spans ±42° of this 43-around
            // cylinder, where a circle is no parabola: it overestimates 1/r by ~12%
            // (z = 1 − √(1 − x²) ≈ x²/2 + x⁴/8); the 2-ring fit by ~2%
            for (name, k, tol) in [
                ("normals", tension_curvature(&base, &s), 0.05),
                ("quadric 2", tension_curvature_quadric(&base, &s, 2), 0.05),
                ("quadric 5", tension_curvature_quadric(&base, &s, 5), 0.15),
            ] {
                let mean = k.iter().map(|x| x.abs()).sum::<f64>() / k.len() as f64;
                eprintln!("{name}, θ {theta_deg}: mean |κ| {mean} (want {want})");
                assert!(
                    (mean - want).abs() < tol * want.max(0.05) + 0.01,
                    "{name}, θ {theta_deg}: {mean} vs {want}"
                );
            }
        }
    }
}

mod sheared_rectangle_check {
    use super::*;
    use pleat::tfw::{solve, TfwParams};
    use pleat::wrinkle::EvalOptions;

    /// Wrinkles across the horizontal mid-line (y = `y0`) of the evaluated mesh (3 Loop
    /// levels, v2 on): sign changes of z (the base stays in z = 0) ordered along x, values
    /// below 1% of the peak ignored; wrinkles = crossings / 2 (the library's
    /// [`pleat::tfw::measure::section_waves`]). Returns (wrinkles, peak |z|).
    fn mid_line_wrinkles(mesh: &pleat::mesh::TriMesh, y0: f64) -> (f64, f64) {
        use pleat::tfw::measure::{section_waves, Section};
        let z: Vec<f64> = mesh.positions().iter().map(|p| p[2]).collect();
        let section = Section::line([0.0, y0, 0.0], [0.0, 1.0, 0.0]);
        let c = section_waves(mesh.positions(), mesh.triangles(), &z, &section);
        (c.waves, c.peak)
    }

    /// The Wong–Pellegrino sheared rectangle ([`Scene::sheared_rectangle`]: 380 × 128 mm,
    /// 25 µm Kapton, 3 mm shear, ~1k vertices): expected 25 ± 6 wrinkles (experiment
    /// 19, the dissertation 25). Slow (ignored): `cargo test --release --test tfw
    /// sheared_rectangle_wrinkles -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn sheared_rectangle_wrinkles() {
        let scene = Scene::sheared_rectangle(1000, 3.0, 0.0, 1).unwrap();
        let r = solve(&scene, &TfwParams::default(), &mut no_progress()).unwrap();
        let sqp = r.sqp.as_ref().unwrap();
        let opts = EvalOptions {
            in_plane_v2: true,
            ..EvalOptions::default()
        };
        let (ev, _) = r.cwf.evaluate(3, &opts).unwrap();
        let (wrinkles, peak) = mid_line_wrinkles(&ev.mesh, 0.064);
        eprintln!(
            "{}: {:?} / {:?} in {} it, base {:.2}s ({:?}, {} Newton it, relative gradient \
             {:.1e}), sqp {:.2}s; wrinkles on the mid line {wrinkles}, peak |z| {:.3} mm, \
             {} of {} faces in W",
            scene.name,
            r.status,
            sqp.status,
            sqp.history.len(),
            r.seconds.base,
            r.base.status,
            r.base.history.len(),
            r.base.relative_gradient,
            r.seconds.sqp,
            peak * 1e3,
            r.w_faces.iter().filter(|&&w| w).count(),
            r.w_faces.len()
        );
        assert!((19.0..=31.0).contains(&wrinkles), "{wrinkles} wrinkles");
    }
}

#[cfg(feature = "bake")]
#[path = "common/shaded.rs"]
mod shaded;

mod balloon_check {
    use super::twisted_cylinder_check::ring_waves;
    use super::*;
    use pleat::tfw::{solve, solve_base, TfwParams};
    use pleat::wrinkle::EvalOptions;
    use std::collections::HashMap;

    /// Enclosed volume `Σ x0·(x1×x2)/6` (outward orientation).
    fn volume(p: &[[f64; 3]], tris: &[[u32; 3]]) -> f64 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| p[v as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    /// Every undirected edge is used by exactly two faces, once in each direction (a closed,
    /// consistently oriented surface).
    fn is_closed_and_oriented(tris: &[[u32; 3]]) -> bool {
        let mut count: HashMap<(u32, u32), i32> = HashMap::new();
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { 100 };
            }
        }
        count.values().all(|&c| c == 101)
    }

    /// Fast: both balloons build, are sewn into a closed oriented surface (the twin boundary
    /// vertices merged, the interior ones not), enclose a positive volume and the base solve
    /// inflates them (volume grows at least ×2; the Newton status is printed, not asserted:
    /// the coarse torus does not reach 1e-8 in 200 iterations, see docs/design-notes.md).
    #[test]
    fn balloons_are_sewn_closed_and_inflate() {
        for (scene, rims) in [
            (Scene::disk_balloon(120, 600.0, 1).unwrap(), 1),
            (Scene::torus_balloon(160, 600.0, 1).unwrap(), 2),
        ] {
            let model = scene.assemble().unwrap();
            let per_panel = scene.panels[0].rest.len();
            let seam = 2 * per_panel - model.positions.len();
            assert!(seam > 0 && seam < per_panel, "{}: {seam} sewn", scene.name);
            assert!(is_closed_and_oriented(&model.triangles), "{}", scene.name);
            let v0 = volume(&model.positions, &model.triangles);
            assert!(v0 > 0.0, "{}: volume {v0}", scene.name);
            let opts = pleat::tfw::BaseOptions::default(); // 200 Newton iterations
            let base = solve_base(&model, &opts, &mut no_progress()).unwrap();
            let v1 = volume(base.mesh.positions(), base.mesh.triangles());
            eprintln!(
                "{}: {} v, {rims} rim(s), {seam} seam vertices, volume {v0:.3e} -> {v1:.3e} m³, \
                 {:?} in {} Newton it, relative gradient {:.1e}",
                scene.name,
                model.positions.len(),
                base.status,
                base.history.len(),
                base.relative_gradient
            );
            assert!(v1 > 2.0 * v0, "{}: volume {v0} -> {v1}", scene.name);
        }
    }

    /// `n` corners of the circle of radius `r` (as `Scene::disk_balloon` builds its rims).
    fn circle_json(r: f64, n: usize) -> String {
        let c: Vec<String> = (0..n)
            .map(|k| {
                let (s, c) = (2.0 * std::f64::consts::PI * k as f64 / n as f64).sin_cos();
                format!("[{:?}, {:?}]", r * c, r * s)
            })
            .collect();
        format!("[{}]", c.join(", "))
    }

    /// A balloon scene file: two lens panels of the outline `polygon` (+ `holes`).
    fn balloon_json(name: &str, polygon: &str, holes: &str, target: usize, h: f64) -> String {
        let panel = |h: f64| {
            format!(
                "    {{ \"polygon\": {polygon},\n      \"holes\": {holes},\n      \
                 \"target_vertices\": {target}, \"seed\": 1, \"lens\": {h:?} }}"
            )
        };
        format!(
            "{{\n  \"name\": \"{name}\",\n  \"material\": {{ \"young\": 1e7, \"poisson\": 0.44, \
             \"thickness\": 1e-4, \"density\": 0 }},\n  \"loads\": {{ \"pressure\": 600 }},\n  \
             \"seam_tolerance\": 1e-9,\n  \"panels\": [\n{},\n{}\n  ]\n}}\n",
            panel(h),
            panel(-h)
        )
    }

    /// The shipped balloon scenes (two `"lens"` panels of the same outline; `PLEAT_BLESS=1`
    /// rewrites them) are the built-ins.
    #[test]
    fn shipped_balloon_scenes_match_the_builtins() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        for (file, target, outer, holes) in [
            (
                "disk_balloon.json",
                600,
                circle_json(0.1, 200),
                "[]".to_string(),
            ),
            (
                "torus_balloon.json",
                800,
                circle_json(0.1, 200),
                format!("[{}]", circle_json(0.04, 80)),
            ),
        ] {
            let scene = if holes == "[]" {
                Scene::disk_balloon(target, 600.0, 1).unwrap()
            } else {
                Scene::torus_balloon(target, 600.0, 1).unwrap()
            };
            let path = root.join("examples/tfw").join(file);
            let h = scene.panels[0]
                .positions
                .as_ref()
                .unwrap()
                .iter()
                .fold(0.0f64, |m, p| m.max(p[2]));
            if std::env::var_os("PLEAT_BLESS").is_some() {
                let text = balloon_json(
                    &scene.name,
                    &outer,
                    &holes,
                    600 + 200 * (file.starts_with('t') as usize),
                    h,
                );
                std::fs::write(&path, text).unwrap();
            }
            let got = Scene::from_json_file(&path).unwrap();
            assert_eq!(got, scene, "{file}");
        }
    }

    /// Solves a balloon, counts the waves around the outer equator ([`ring_waves`] on the
    /// plane 20% of the half-height above the seam, outside the mean radius of that ring),
    /// checks the invariants (a ≥ 0, curl ≤ 1e-10, energy non-increasing), renders the
    /// evaluated wrinkled mesh (3 Loop levels, v2 on) to `docs/<picture>.png` and returns the
    /// wave count.
    fn balloon(scene: &Scene, picture: &str) -> f64 {
        let model = scene.assemble().unwrap();
        let mut params = TfwParams::default();
        if let Ok(n) = std::env::var("PLEAT_BALLOON_ITERS") {
            params.sqp.max_iterations = n.parse().unwrap();
        }
        super::snap_from_env(&mut params);
        let r = solve(scene, &params, &mut no_progress()).unwrap();
        super::print_phase(&r);
        let sqp = r.sqp.as_ref().expect("balloons are compressed");
        let p = r.base.mesh.positions();
        let zc = p.iter().map(|q| q[2]).sum::<f64>() / p.len() as f64;
        let ztop = p.iter().fold(f64::MIN, |m, q| m.max(q[2]));
        let rmax = p.iter().fold(0.0f64, |m, q| m.max(q[0].hypot(q[1])));
        let v0 = volume(&model.positions, &model.triangles);
        let v1 = volume(p, r.base.mesh.triangles());
        let mut counts = vec![];
        for frac in [0.05, 0.1, 0.2, 0.3] {
            let plane = zc + frac * (ztop - zc);
            counts.push((frac, ring_waves(&r.cwf, plane, 0.5 * rmax)));
        }
        let waves = counts[2].1;
        for (k, it) in sqp.history.iter().enumerate() {
            if k % 50 == 0 || k + 1 == sqp.history.len() {
                eprintln!(
                    "  it {k}: E {:.6e}, r/r0 {:.2e}, step {:.2e}, t {:.2}, curl {:.1e}, {:.1}s",
                    it.energy,
                    it.stationarity / sqp.initial_stationarity,
                    it.step_norm,
                    it.step_length,
                    it.curl_residual,
                    it.seconds
                );
            }
        }
        let a = r.cwf.amplitude();
        let max_a = a.iter().fold(0.0f64, |m, &x| m.max(x));
        eprintln!(
            "{} ({} v, {} f): {:?} / {:?} in {} SQP it; base {:.2}s ({:?}, {} Newton it, \
             relative gradient {:.1e}), volume {v0:.3e} -> {v1:.3e} m³, equator radius \
             {rmax:.4} m, half-height {:.4} m; sqp {:.2}s (qp {:.2}s); waves around the outer \
             equator at 5/10/20/30% of the half-height {:?}; max a {:.3} mm; {} of {} faces in \
             W; curl {:.1e}",
            scene.name,
            model.positions.len(),
            model.triangles.len(),
            r.status,
            sqp.status,
            sqp.history.len(),
            r.seconds.base,
            r.base.status,
            r.base.history.len(),
            r.base.relative_gradient,
            ztop - zc,
            r.seconds.sqp,
            sqp.qp_seconds,
            counts.iter().map(|c| c.1).collect::<Vec<_>>(),
            max_a * 1e3,
            r.w_faces.iter().filter(|&&w| w).count(),
            r.w_faces.len(),
            r.curl_residual
        );
        assert!(a.iter().all(|&x| x >= 0.0));
        assert!(r.curl_residual <= 1e-10, "curl {}", r.curl_residual);
        let e: Vec<f64> = sqp.history.iter().map(|h| h.energy).collect();
        assert!(
            e.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-12)),
            "energy increased"
        );
        render(&r.cwf, picture);
        waves
    }

    /// The evaluated wrinkled mesh (3 Loop levels, v2 on, displacement ×1) shaded white from
    /// about 37° above the equator, 480 px, to `docs/<name>.png` (the project's rasterizer).
    #[cfg(feature = "bake")]
    fn render(cwf: &pleat::wrinkle::Cwf, name: &str) {
        use super::shaded::Shaded;
        use pleat::bake::render::{rasterize, shade, Mode, View};
        use pleat::geom::Vec3;
        let opts = EvalOptions {
            in_plane_v2: true,
            ..EvalOptions::default()
        };
        let (ev, _) = cwf.evaluate(3, &opts).unwrap();
        // the balloon's axis (z) up on screen (the rasterizer's up is +y)
        let upright: Vec<[f64; 3]> = ev
            .mesh
            .positions()
            .iter()
            .map(|p| [p[0], p[2], -p[1]])
            .collect();
        let mesh = pleat::mesh::TriMesh::new(upright, ev.mesh.triangles().to_vec()).unwrap();
        let (lo, hi) = mesh.bbox();
        let c = Vec3::from(std::array::from_fn::<f64, 3, _>(|k| 0.5 * (lo[k] + hi[k])));
        let rad = 0.5 * (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let side = 480u32;
        let dist = 4.0 * rad;
        let dir = Vec3::from([0.75, 0.6, 0.45]);
        let dir = pleat::geom::normalized(dir).unwrap();
        let view = View::look_at(
            c + dir * dist,
            c,
            f64::from(side) * dist / (2.3 * rad),
            side,
        );
        let s = Shaded::new(mesh);
        let g = rasterize(&view, s.mesh.positions(), s.mesh.triangles());
        let img = shade(&g, &view, &s, Mode::Shaded).to_image([255, 255, 255]);
        let png = pleat::bake::output::png_bytes(&img).unwrap();
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let path = root.join(format!("docs/{name}.png"));
        std::fs::write(&path, &png).unwrap();
        eprintln!("  {}: {side}×{side}, {} bytes", path.display(), png.len());
    }

    #[cfg(not(feature = "bake"))]
    fn render(_: &pleat::wrinkle::Cwf, name: &str) {
        eprintln!("SKIPPED: picture {name} (feature bake off)");
    }

    /// The Mylar balloon ([`Scene::disk_balloon`], 2 × `PLEAT_BALLOON_V` (default
    /// 600) vertices, 600 Pa): wrinkles around the equator. Slow (ignored): `cargo test
    /// --release --test tfw disk_balloon_wrinkles -- --ignored --nocapture`; writes
    /// docs/tfw_disk_balloon.png.
    #[test]
    #[ignore]
    fn disk_balloon_wrinkles() {
        let n = std::env::var("PLEAT_BALLOON_V").map_or(600, |v| v.parse().unwrap());
        let scene = Scene::disk_balloon(n, 600.0, 1).unwrap();
        let waves = balloon(&scene, "tfw_disk_balloon");
        assert!(waves > 0.0, "no wrinkles around the equator");
    }

    /// The torus balloon ([`Scene::torus_balloon`], 2 × `PLEAT_BALLOON_V` (default
    /// 800) vertices, 600 Pa): wrinkles around the outer equator. Slow (ignored): `cargo
    /// test --release --test tfw torus_balloon_wrinkles -- --ignored --nocapture`; writes
    /// docs/tfw_torus_balloon.png.
    #[test]
    #[ignore]
    fn torus_balloon_wrinkles() {
        let n = std::env::var("PLEAT_BALLOON_V").map_or(800, |v| v.parse().unwrap());
        let scene = Scene::torus_balloon(n, 600.0, 1).unwrap();
        let waves = balloon(&scene, "tfw_torus_balloon");
        assert!(waves > 0.0, "no wrinkles around the outer equator");
    }

    /// The teabag of S:752 ([`Scene::teabag`], 2 × `PLEAT_BALLOON_V` (default 468, the
    /// dissertation's 936 in all) vertices, `PLEAT_TEABAG_PA` (default 10) Pa): fine wrinkles
    /// along the seam. Slow (ignored): `cargo test --release --test tfw teabag_wrinkles --
    /// --ignored --nocapture`; writes docs/tfw_teabag.png.
    #[test]
    #[ignore]
    fn teabag_wrinkles() {
        let n = std::env::var("PLEAT_BALLOON_V").map_or(468, |v| v.parse().unwrap());
        let pa = std::env::var("PLEAT_TEABAG_PA").map_or(10.0, |v| v.parse().unwrap());
        let scene = Scene::teabag(n, pa, 1).unwrap();
        balloon(&scene, "tfw_teabag");
    }

    /// The sphere drape of S:676 at the dissertation's size (`Scene::sphere_drape(41, 1.0)`,
    /// 1681 v): prints the solve and writes docs/tfw_drape.png. Slow (ignored): `cargo test
    /// --release --test tfw sphere_drape_wrinkles -- --ignored --nocapture`
    /// (`PLEAT_DRAPE_N` for another grid).
    #[test]
    #[ignore]
    fn sphere_drape_wrinkles() {
        let n = std::env::var("PLEAT_DRAPE_N").map_or(41, |v| v.parse().unwrap());
        drape(&Scene::sphere_drape(n, 1.0), "tfw_drape");
    }

    /// The same drape on an irregular Delaunay mesh of about 1681 vertices
    /// (`Scene::sphere_drape_delaunay`, seed 1): no grid direction for the wrinkles to follow
    /// (S:698); writes docs/tfw_drape_delaunay.png. Slow (ignored), as above
    /// (`PLEAT_DRAPE_V` for another size).
    #[test]
    #[ignore]
    fn sphere_drape_delaunay_wrinkles() {
        let v = std::env::var("PLEAT_DRAPE_V").map_or(1681, |v| v.parse().unwrap());
        drape(
            &Scene::sphere_drape_delaunay(v, 1.0, 1).unwrap(),
            "tfw_drape_delaunay",
        );
    }

    /// Solves a sphere drape, prints the solve and writes docs/`picture`.png.
    fn drape(scene: &Scene, picture: &str) {
        let mut params = TfwParams::default();
        if let Ok(it) = std::env::var("PLEAT_DRAPE_NEWTON") {
            params.base.max_iterations = it.parse().unwrap();
        }
        let r = solve(scene, &params, &mut no_progress()).unwrap();
        let sqp = r.sqp.as_ref().expect("the drape is compressed");
        let a = r.cwf.amplitude();
        let p = r.base.mesh.positions();
        let min_d = p
            .iter()
            .map(|q| (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() - 0.2)
            .fold(f64::INFINITY, f64::min);
        eprintln!(
            "{}: base {:?} in {} Newton it (relative gradient {:.1e}, {:.2} s), SQP {:?} in {} it \
             ({:.2} s), {} of {} faces wrinkle-free, peak a {:.1} mm, lowest base z {:.3} m, \
             deepest penetration {:.2e} m, curl {:.1e}",
            scene.name,
            r.base.status,
            r.base.history.len(),
            r.base.relative_gradient,
            r.seconds.base,
            sqp.status,
            sqp.history.len(),
            r.seconds.sqp,
            r.w_faces.iter().filter(|&&w| w).count(),
            r.w_faces.len(),
            1e3 * a.iter().fold(0.0f64, |m, &x| m.max(x)),
            p.iter().map(|q| q[2]).fold(f64::INFINITY, f64::min),
            -min_d.min(0.0),
            r.curl_residual
        );
        assert!(r.curl_residual <= 1e-10, "curl {}", r.curl_residual);
        render(&r.cwf, picture);
    }
}

/// Speed: the clarabel QP against the projected Newton with the curl eliminated on
/// the sheet, the cylinder and the sheared rectangle in one run (report + invariants + the
/// agreement the default switch depends on). Slow (ignored): `cargo test --release --test tfw
/// solver_comparison -- --ignored --nocapture`.
mod solver_comparison {
    use super::wrinkle_sqp::params_with;
    use super::*;
    use pleat::tfw::measure::{count_waves, Section};
    use pleat::tfw::{solve, QpMethod, TfwResult};

    /// Iterations and SQP seconds until `E` is within 1e-3 relative of its final value (the
    /// spec's "stable time").
    fn stable(r: &TfwResult) -> (usize, f64) {
        let s = r.sqp.as_ref().unwrap();
        let last = s.history.last().map_or(s.initial_energy, |i| i.energy);
        s.history
            .iter()
            .enumerate()
            .find(|(_, i)| (i.energy - last).abs() <= 1e-3 * last.abs())
            .map_or((0, 0.0), |(k, i)| (k + 1, i.seconds))
    }

    fn run(name: &str, scene: &Scene, section: Section, levels: usize, qp: QpMethod) -> (f64, f64) {
        let r = solve(scene, &params_with(1000, qp), &mut no_progress()).unwrap();
        let s = r.sqp.as_ref().unwrap();
        let waves = count_waves(&r.cwf, levels, &section).unwrap().waves;
        let peak = r.cwf.amplitude().iter().fold(0.0f64, |m, &a| m.max(a));
        let n = s.history.len().max(1);
        let (stable_it, stable_s) = stable(&r);
        eprintln!(
            "| {name} | {} v | {qp:?} | {:?} | {} | {:.1} ms ({:.1} ms step solver) | {:.2} s | \
             {stable_it} it / {stable_s:.2} s | {:.9e} | {waves} | {:.3} mm | {:.1e} |",
            r.base.mesh.vertex_count(),
            s.status,
            s.history.len(),
            1e3 * s.seconds / n as f64,
            1e3 * s.qp_seconds / n as f64,
            s.seconds,
            r.energy,
            peak * 1e3,
            s.history.iter().fold(0.0f64, |m, i| m.max(i.curl_residual)),
        );
        let mut prev = s.initial_energy;
        for it in &s.history {
            assert!(it.curl_residual <= 1e-10, "curl {}", it.curl_residual);
            assert!(it.energy <= prev, "E rose");
            prev = it.energy;
        }
        assert!(r.cwf.amplitude().iter().all(|&a| a >= 0.0));
        (r.energy, waves)
    }

    #[test]
    #[ignore]
    fn solver_comparison() {
        let cases = [
            (
                "stretched sheet 5 %",
                Scene::stretched_sheet(37, 14, 0.05),
                Section::line([0.0; 3], [1.0, 0.0, 0.0]),
                3,
            ),
            (
                "twisted cylinder (Delaunay)",
                Scene::twisted_cylinder_delaunay(720, 10.0, 1).unwrap(),
                Section::ring([0.0, 0.0, 2.5], [0.0, 0.0, 1.0]),
                2,
            ),
            (
                "sheared rectangle",
                Scene::sheared_rectangle(1000, 3.0, 0.0, 1).unwrap(),
                Section::line([0.0, 0.064, 0.0], [0.0, 1.0, 0.0]),
                3,
            ),
        ];
        eprintln!(
            "| scene | mesh | step solver | SQP status | iterations | per iteration | SQP total | \
             stable (E within 1e-3) | final E (J) | waves | max a | max curl |"
        );
        // PLEAT_TFW_SCENES=rectangle (a substring of the names) and PLEAT_TFW_QP=newton or
        // clarabel narrow the run (profiling one scene)
        let only = std::env::var("PLEAT_TFW_SCENES").unwrap_or_default();
        let qp_only = std::env::var("PLEAT_TFW_QP").unwrap_or_default();
        let cases = cases.into_iter().filter(|c| c.0.contains(only.as_str()));
        if qp_only == "newton" || qp_only == "clarabel" {
            let qp = if qp_only == "newton" {
                QpMethod::ProjectedNewton
            } else {
                QpMethod::Clarabel
            };
            for (name, scene, section, levels) in cases {
                run(name, &scene, section, levels, qp);
            }
            return;
        }
        for (name, scene, section, levels) in cases {
            let (e1, w1) = run(name, &scene, section, levels, QpMethod::Clarabel);
            let (e2, w2) = run(name, &scene, section, levels, QpMethod::ProjectedNewton);
            eprintln!(
                "{name}: energy relative difference {:.1e}, waves {w1} vs {w2}",
                (e1 - e2).abs() / e1.abs()
            );
        }
    }
}

/// Speed, per scene: wall time until the answer is stable, base solve included,
/// against Table 2.1 / 5 (S:792–815; the dissertation's stable times exclude the base solve,
/// ours include it). "Stable" = the first SQP iteration from which on the wave count equals the
/// final one and the peak amplitude stays within 1 % of the final one at every later checked
/// iteration (every `PLEAT_TFW_WAVE_EVERY` = 5 iterations), and E is within 1e-3 of its final
/// value. Total = base + set-up (W faces, curvature, initialization) + SQP until stable +
/// phase (Knöppel). Slow (ignored): `cargo test --release --test tfw scene_speed -- --ignored
/// --nocapture`; `PLEAT_TFW_SCENES` (substring of the names) and `PLEAT_TFW_QP`
/// (`newton` / `clarabel`, default both) narrow it.
mod scene_speed {
    use super::*;
    use pleat::tfw::measure::{count_waves, Section};
    use pleat::tfw::{solve, CgRefinement, QpMethod, SqpOptions, TfwParams, TfwResult};

    struct Case {
        name: &'static str,
        scene: Scene,
        /// The section; `None`: a ring 20 % of the half-height above the centre, outer half.
        section: Option<Section>,
        levels: usize,
        /// Table 2.1's stable time (s) / 5.
        target: f64,
    }

    fn balloon_section(r: &TfwResult) -> Section {
        let p = r.base.mesh.positions();
        let zc = p.iter().map(|q| q[2]).sum::<f64>() / p.len() as f64;
        let ztop = p.iter().fold(f64::MIN, |m, q| m.max(q[2]));
        let rmax = p.iter().fold(0.0f64, |m, q| m.max(q[0].hypot(q[1])));
        let mut s = Section::ring([0.0, 0.0, zc + 0.2 * (ztop - zc)], [0.0, 0.0, 1.0]);
        s.min_radius = 0.5 * rmax;
        s
    }

    fn cases() -> Vec<Case> {
        let ring = Section::ring([0.0, 0.0, 2.5], [0.0, 0.0, 1.0]);
        vec![
            Case {
                name: "stretched sheet 5 %",
                scene: Scene::stretched_sheet(37, 14, 0.05),
                section: Some(Section::line([0.0; 3], [1.0, 0.0, 0.0])),
                levels: 3,
                target: 2.57 / 5.0,
            },
            Case {
                name: "twisted cylinder 720",
                scene: Scene::twisted_cylinder_delaunay(720, 10.0, 1).unwrap(),
                section: Some(ring),
                levels: 2,
                target: 50.94 / 5.0,
            },
            Case {
                name: "twisted cylinder 1330",
                scene: Scene::twisted_cylinder_delaunay(1330, 10.0, 1).unwrap(),
                section: Some(ring),
                levels: 2,
                target: 50.94 / 5.0,
            },
            Case {
                name: "sheared rectangle",
                scene: Scene::sheared_rectangle(1000, 3.0, 0.0, 1).unwrap(),
                section: Some(Section::line([0.0, 0.064, 0.0], [0.0, 1.0, 0.0])),
                levels: 3,
                target: 9.63 / 5.0,
            },
            Case {
                name: "disk balloon",
                scene: Scene::disk_balloon(600, 600.0, 1).unwrap(),
                section: None,
                levels: 2,
                target: 52.33 / 5.0,
            },
            Case {
                name: "torus balloon",
                scene: Scene::torus_balloon(800, 600.0, 1).unwrap(),
                section: None,
                levels: 2,
                target: 44.81 / 5.0,
            },
        ]
    }

    /// `(iterations, SQP seconds)` until stable (module docs), and the final waves and peak;
    /// prints from which iteration on each criterion holds alone.
    fn stable_point(
        r: &TfwResult,
        params: &TfwParams,
        section: &Section,
        levels: usize,
        every: usize,
    ) -> (usize, f64, f64, f64) {
        let s = r.sqp.as_ref().unwrap();
        let nv = r.base.mesh.vertex_count();
        let peak = |a: &[f64]| a.iter().fold(0.0f64, |m, &v| m.max(v));
        let final_waves = count_waves(&r.cwf, levels, section).unwrap().waves;
        let final_peak = peak(r.cwf.amplitude());
        let final_e = r.energy;
        let n = s.history.len();
        let energy_at = |k: usize| {
            if k == 0 {
                s.initial_energy
            } else {
                s.history[k - 1].energy
            }
        };
        let seconds_at = |k: usize| {
            if k == 0 {
                0.0
            } else {
                s.history[k - 1].seconds
            }
        };
        // PLEAT_TFW_WAVE_TRACE: print waves / peak / E at every checked snapshot
        let trace = std::env::var("PLEAT_TFW_WAVE_TRACE").is_ok();
        // from which checked iteration on each criterion holds (walking back from the end)
        let (mut kw, mut kp1, mut kp5, mut ke) = (n, n, n, n);
        let (mut w_ok, mut p1_ok, mut p5_ok, mut e_ok) = (true, true, true, true);
        for (k, x) in s.snapshots.iter().rev() {
            if *k == n || k % every != 0 {
                continue;
            }
            let (a, w) = x.split_at(nv);
            let (cwf, _) = pleat::wrinkle::Cwf::from_one_form(
                r.base.mesh.clone(),
                w.to_vec(),
                a.to_vec(),
                &params.knoppel,
            )
            .unwrap();
            let waves = count_waves(&cwf, levels, section).unwrap().waves;
            let dp = (peak(a) - final_peak).abs();
            if trace {
                eprintln!(
                    "  trace {k:4}: waves {waves} peak {:.4} mm E {:.10e}",
                    1e3 * peak(a),
                    energy_at(*k)
                );
            }
            w_ok &= waves == final_waves;
            p1_ok &= dp <= 1e-2 * final_peak;
            p5_ok &= dp <= 5e-2 * final_peak;
            e_ok &= (energy_at(*k) - final_e).abs() <= 1e-3 * final_e.abs();
            for (ok, kk) in [
                (w_ok, &mut kw),
                (p1_ok, &mut kp1),
                (p5_ok, &mut kp5),
                (e_ok, &mut ke),
            ] {
                if ok {
                    *kk = *k;
                }
            }
            if !(w_ok || p1_ok || p5_ok || e_ok || trace) {
                break;
            }
        }
        eprintln!(
            "  from: waves {kw} it / {:.2} s, peak ±1 % {kp1} it / {:.2} s, peak ±5 % {kp5} it / \
             {:.2} s, E ±1e-3 {ke} it / {:.2} s",
            seconds_at(kw),
            seconds_at(kp1),
            seconds_at(kp5),
            seconds_at(ke)
        );
        let stable = kw.max(kp1).max(ke);
        (stable, seconds_at(stable), final_waves, final_peak)
    }

    /// The spread of the principal strains over the base's faces: how many faces sit near
    /// the triple point `λ1 = λ2 = 0` of the relaxed density (where its third derivatives
    /// grow like 1/(λ1 − λ2), so the Newton model is valid only in a tiny region).
    fn print_strain_spread(scene: &Scene, base: &pleat::mesh::TriMesh) {
        let model = scene.assemble().unwrap();
        let p = base.positions();
        let mut r: Vec<(f64, f64)> = model
            .triangles
            .iter()
            .zip(&model.rest_forms)
            .map(|(t, rest)| {
                let q = t.map(|v| p[v as usize]);
                let e1 = [0, 1, 2].map(|k| q[1][k] - q[0][k]);
                let e2 = [0, 1, 2].map(|k| q[2][k] - q[0][k]);
                let d = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                let cur = [d(e1, e1), d(e1, e2), d(e2, e2)];
                pleat::tfw::material::principal_strains(*rest, cur)
            })
            .collect();
        let big = r.iter().fold(0.0f64, |m, s| m.max(s.0.abs()));
        r.sort_by(|a, b| (a.0 - a.1).total_cmp(&(b.0 - b.1)));
        let count = |f: f64| r.iter().filter(|s| s.0 - s.1 < f * big).count();
        eprintln!(
            "  base strains: max |λ1| {big:.2e}; faces with λ1 − λ2 below 1e-1 / 1e-2 / 1e-3 of it: \
             {} / {} / {} of {}",
            count(1e-1),
            count(1e-2),
            count(1e-3),
            r.len()
        );
    }

    /// Every `every`-th SQP iteration (`PLEAT_TFW_SQP_HISTORY=every`): r/r₀, the rate of r over
    /// the last `every` iterations (geometric mean factor per iteration), the accepted step
    /// length t (line-search halvings), the shift σ, CG iterations, ΔE.
    fn print_sqp_history(s: &pleat::tfw::SqpResult, every: usize) {
        let h = &s.history;
        let r0 = s.initial_stationarity;
        for k in (0..h.len()).filter(|k| (k + 1) % every == 0 || k + 1 == h.len()) {
            let back = k.saturating_sub(every);
            let rate = if k > back {
                (h[k].stationarity / h[back].stationarity).powf(1.0 / (k - back) as f64)
            } else {
                f64::NAN
            };
            let lo = k + 1 - every.min(k + 1);
            let halvings: f64 =
                h[lo..=k].iter().map(|i| -i.step_length.log2()).sum::<f64>() / (k + 1 - lo) as f64;
            let cg: f64 = h[lo..=k]
                .iter()
                .map(|i| i.cg_iterations as f64)
                .sum::<f64>()
                / (k + 1 - lo) as f64;
            eprintln!(
                "  sqp {:4} E {:.10e} r/r0 {:.2e} rate {:.4} t {} halvings {:.2} shift {:.1e} cg \
                 {:.1} held {} {:.2} s",
                k + 1,
                h[k].energy,
                h[k].stationarity / r0,
                rate,
                h[k].step_length,
                halvings,
                h[k].shift,
                cg,
                h[k].held,
                h[k].seconds
            );
        }
    }

    /// The measurement switch `PLEAT_TFW_SQP_CG=iterations[,radius[,tolerance[,after_full_step[,
    /// max_shift]]]]` (`0` = the projected step alone; radius 1e3, tolerance 1e-3, every step
    /// unless given); unset: the library's default [`CgRefinement::DEFAULT`].
    /// The measurement switch `PLEAT_TFW_VALLEY=0` turns the projected Newton's valley search
    /// off; unset: the library's default.
    pub(crate) fn valley_search_from_env() -> bool {
        std::env::var("PLEAT_TFW_VALLEY").map_or(SqpOptions::default().valley_search, |v| v != "0")
    }

    pub(crate) fn cg_refinement_from_env() -> CgRefinement {
        let Ok(v) = std::env::var("PLEAT_TFW_SQP_CG") else {
            return CgRefinement::DEFAULT;
        };
        let mut c = CgRefinement::OFF;
        let f: Vec<f64> = v.split(',').filter_map(|t| t.trim().parse().ok()).collect();
        if let Some(&n) = f.first() {
            c.iterations = n.max(0.0) as usize;
        }
        if let Some(&r) = f.get(1) {
            c.radius = r;
        }
        if let Some(&t) = f.get(2) {
            c.tolerance = t;
        }
        c.after_full_step = f.get(3).is_some_and(|&g| g > 0.0);
        if let Some(&m) = f.get(4) {
            c.max_shift = m;
        }
        c
    }

    fn run(case: &Case, qp: QpMethod, every: usize) {
        let mut params = TfwParams::default();
        params.sqp.qp = qp;
        params.sqp.snapshot_every = every;
        params.sqp.cg_refinement = cg_refinement_from_env();
        params.sqp.valley_search = valley_search_from_env();
        if let Ok(n) = std::env::var("PLEAT_TFW_BASE_ITERS") {
            params.base.max_iterations = n.parse().unwrap();
        }
        let r = solve(&case.scene, &params, &mut no_progress()).unwrap();
        let b = &r.base;
        if std::env::var("PLEAT_TFW_BASE_HISTORY").is_ok() {
            for (k, h) in b.history.iter().enumerate() {
                eprintln!(
                    "  base {k:3} E {:.15e} |g| {:.3e} t {} |dx| {:.2e} shift {:.2e} cg {} \
                     switched {} {}{:.3} s",
                    h.energy,
                    h.gradient_norm,
                    h.step,
                    h.step_norm,
                    h.shift,
                    h.times.cg_iterations,
                    h.branch_changes,
                    if h.gradient_step {
                        "gradient step "
                    } else {
                        ""
                    },
                    h.seconds
                );
            }
        }
        if std::env::var("PLEAT_TFW_BASE_HISTORY").is_ok() {
            print_strain_spread(&case.scene, &b.mesh);
        }
        let per_it = r.seconds.base / b.history.len().max(1) as f64;
        {
            let k = b.history.len().max(1) as f64;
            let sum = |f: &dyn Fn(&pleat::tfw::NewtonTimes) -> f64| {
                b.history.iter().map(|h| f(&h.times)).sum::<f64>() / k
            };
            eprintln!(
                "  base per iteration: evaluate {:.1} ms, assemble {:.1} ms, factor {:.1} ms \
                 ({:.2} attempts), solve {:.1} ms ({:.1} CG it), line search {:.1} ms ({:.2} \
                 evaluations)",
                1e3 * sum(&|t| t.evaluate),
                1e3 * sum(&|t| t.assemble),
                1e3 * sum(&|t| t.factor),
                sum(&|t| t.factor_attempts as f64),
                1e3 * sum(&|t| t.solve),
                sum(&|t| t.cg_iterations as f64),
                1e3 * sum(&|t| t.line_search),
                sum(&|t| t.line_search_evaluations as f64),
            );
        }
        let tail: Vec<String> = b
            .history
            .iter()
            .rev()
            .take(3)
            .map(|h| {
                format!(
                    "|g| {:.2e} t {} shift {:.1e}",
                    h.gradient_norm, h.step, h.shift
                )
            })
            .collect();
        let halvings: f64 =
            b.history.iter().map(|h| -h.step.log2()).sum::<f64>() / b.history.len().max(1) as f64;
        eprintln!(
            "{} ({} v): base {:?} {} it {:.2} s ({:.1} ms/it, mean line-search halvings {:.2}, \
             rel. gradient {:.1e}; last: {:?})",
            case.name,
            b.mesh.vertex_count(),
            b.status,
            b.history.len(),
            r.seconds.base,
            1e3 * per_it,
            halvings,
            b.relative_gradient,
            tail
        );
        let Some(s) = r.sqp.as_ref() else {
            eprintln!("  no SQP: {:?}", r.status);
            return;
        };
        if let Ok(every) = std::env::var("PLEAT_TFW_SQP_HISTORY") {
            print_sqp_history(s, every.parse().unwrap_or(10));
        }
        let section = case.section.unwrap_or_else(|| balloon_section(&r));
        let (k, sqp_s, waves, peak) = stable_point(&r, &params, &section, case.levels, every);
        let fixed = r.seconds.base + r.seconds.init + r.seconds.phase;
        let total = fixed + sqp_s;
        eprintln!(
            "| {} | {} v | {qp:?} | {:.2} | {:.2} | {k} it / {sqp_s:.2} | {:.2} | {:.2} | {:.2} | \
             {} | {waves} | {:.3} mm | {:?} {} it, {:.2} s, E {:.9e} |",
            case.name,
            b.mesh.vertex_count(),
            r.seconds.base,
            r.seconds.init + r.seconds.phase,
            total,
            case.target,
            total / case.target,
            if total <= case.target {
                "met"
            } else {
                "not met"
            },
            peak * 1e3,
            s.status,
            s.history.len(),
            s.seconds,
            s.history.last().map_or(s.initial_energy, |h| h.energy)
        );
    }

    #[test]
    #[ignore]
    fn scene_speed() {
        let only = std::env::var("PLEAT_TFW_SCENES").unwrap_or_default();
        let qp_only = std::env::var("PLEAT_TFW_QP").unwrap_or_default();
        let every = std::env::var("PLEAT_TFW_WAVE_EVERY").map_or(5, |v| v.parse().unwrap());
        let qps: Vec<QpMethod> = match qp_only.as_str() {
            "newton" => vec![QpMethod::ProjectedNewton],
            "clarabel" => vec![QpMethod::Clarabel],
            _ => vec![QpMethod::Clarabel, QpMethod::ProjectedNewton],
        };
        eprintln!(
            "| scene | mesh | step solver | base s | set-up + phase s | SQP until stable | total \
             s | Table 2.1 / 5 | ratio | met | waves | peak | SQP end |"
        );
        for case in cases()
            .iter()
            .filter(|c| only.split(',').any(|o| c.name.contains(o)))
        {
            for &qp in &qps {
                run(case, qp, every);
            }
        }
    }
}

/// The torus saddle (docs/design-notes.md, "Base solve"): is the converged base of the
/// torus balloon, bent out of its plane, a local minimum, and is the mirror-symmetric state the
/// old projected-pressure iteration crawled along one? The exact base Hessian (pressure not
/// projected) with six coordinates pinned against the rigid motions (a principal submatrix:
/// if it has a negative eigenvalue the full Hessian is indefinite; if it is positive
/// definite the Hessian is positive on a complement of the rigid motions) and its smallest
/// eigenvalue by bisection on the shift of a Cholesky factorization (`H + τI` factors iff
/// `λ_min > −τ`, Sylvester). Slow (ignored): `cargo test --release --test tfw
/// torus_base_stability -- --ignored --nocapture`.
mod torus_stability {
    use super::*;
    use pleat::solve::{assemble, CholeskyAnalysis, Entry, Parallelism};
    use pleat::tfw::{solve_base, BaseOptions, BaseProblem, BaseResult, Model, Terms};
    use std::collections::HashMap;

    /// Six coordinates fixing the rigid motions of a torus around the z axis: all of the
    /// vertex with the largest x, y and z of the one with the smallest x, z of the one with
    /// the largest y.
    fn gauge(p: &[[f64; 3]]) -> Vec<usize> {
        let arg = |f: &dyn Fn(&[f64; 3]) -> f64| {
            (0..p.len())
                .max_by(|&a, &b| f(&p[a]).total_cmp(&f(&p[b])))
                .unwrap()
        };
        let (a, b, c) = (arg(&|q| q[0]), arg(&|q| -q[0]), arg(&|q| q[1]));
        let mut g = vec![3 * a, 3 * a + 1, 3 * a + 2, 3 * b + 1, 3 * b + 2, 3 * c + 2];
        g.sort_unstable();
        g
    }

    /// Smallest eigenvalue of the exact base Hessian at `x` with the `pinned` coordinates
    /// removed, and the mean |diagonal| (its scale).
    fn smallest_eigenvalue(problem: &BaseProblem, x: &[f64], pinned: &[usize]) -> (f64, f64) {
        let eval = problem.evaluate(x, Terms::ALL, true);
        let mut index = vec![usize::MAX; x.len()];
        let mut dim = 0;
        for (i, slot) in index.iter_mut().enumerate() {
            if pinned.binary_search(&i).is_err() {
                *slot = dim;
                dim += 1;
            }
        }
        let mut entries = Vec::new();
        let mut diag = vec![0.0; dim];
        for &(r, c, v) in &eval.hessian {
            let (i, j) = (index[r], index[c]);
            if i == usize::MAX || j == usize::MAX {
                continue;
            }
            if i == j {
                diag[i] += v;
            }
            entries.push(Entry::new(i.max(j), i.min(j), v));
        }
        entries.extend((0..dim).map(|i| Entry::new(i, i, 0.0)));
        let a = assemble(dim, &entries, "torus base Hessian").unwrap();
        let an = CholeskyAnalysis::new(&a).unwrap();
        let w = vec![1.0; dim];
        let factors = |tau: f64| an.factor_shifted(&a, tau, &w, Parallelism::Global).is_ok();
        let scale = diag.iter().map(|d| d.abs()).sum::<f64>() / dim as f64;
        // Gershgorin-sized bracket, then bisection on τ* = −λ_min
        let mut hi = 1e3 * scale;
        while !factors(hi) {
            hi *= 10.0;
        }
        let mut lo = -hi;
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if factors(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        (-hi, scale)
    }

    /// Per vertex, its mirror image under `z → −z` (the two panels are mirror copies; seam
    /// vertices are their own image), from the start positions.
    fn mirror_pairs(model: &Model) -> Vec<usize> {
        let key = |q: &[f64; 3]| (q[0].to_bits(), q[1].to_bits(), q[2].abs().to_bits());
        let mut by: HashMap<_, Vec<usize>> = HashMap::new();
        for (i, q) in model.positions.iter().enumerate() {
            by.entry(key(q)).or_default().push(i);
        }
        model
            .positions
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let v = &by[&key(q)];
                *v.iter().find(|&&j| j != i).unwrap_or(&i)
            })
            .collect()
    }

    /// Max distance between the state and its mirror image, and the z spread of the seam
    /// vertices (0 for a planar, mirror-symmetric torus).
    fn asymmetry(p: &[[f64; 3]], pairs: &[usize]) -> (f64, f64) {
        let mut d = 0.0f64;
        let (mut zmin, mut zmax) = (f64::MAX, f64::MIN);
        for (i, &j) in pairs.iter().enumerate() {
            let (a, b) = (p[i], p[j]);
            d = d.max(
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] + b[2]).powi(2)).sqrt(),
            );
            if i == j {
                zmin = zmin.min(a[2]);
                zmax = zmax.max(a[2]);
            }
        }
        (d, zmax - zmin)
    }

    fn report(name: &str, model: &Model, r: &BaseResult, pairs: &[usize]) -> f64 {
        let problem = BaseProblem::new(model, 1.0);
        let p = r.mesh.positions();
        let x: Vec<f64> = p.iter().flatten().copied().collect();
        let pinned = gauge(p);
        let (lmin, scale) = smallest_eigenvalue(&problem, &x, &pinned);
        let (mirror, seam_dz) = asymmetry(p, pairs);
        let energy = problem.energy(&x, Terms::ALL);
        eprintln!(
            "{name}: {:?} {} it, rel. gradient {:.1e}, E {energy:.9} J, mirror asymmetry {:.2} \
             mm, seam z spread {:.2} mm, λ_min (6 rigid coordinates pinned) {lmin:.3e} \
             (mean |H_ii| {scale:.3e}, ratio {:.2e})",
            r.status,
            r.history.len(),
            r.relative_gradient,
            1e3 * mirror,
            1e3 * seam_dz,
            lmin / scale
        );
        lmin / scale
    }

    #[test]
    #[ignore]
    fn torus_base_stability() {
        let scene = Scene::torus_balloon(800, 600.0, 1).unwrap();
        let model = scene.assemble().unwrap();
        let pairs = mirror_pairs(&model);
        assert!(pairs.iter().enumerate().all(|(i, &j)| pairs[j] == i));
        let converged = solve_base(&model, &BaseOptions::default(), &mut no_progress()).unwrap();
        let a = report(
            "(a) converged (exact-Hessian CG)",
            &model,
            &converged,
            &pairs,
        );
        let old = BaseOptions {
            cg_iterations: 0,
            ..BaseOptions::default()
        };
        let crawled = solve_base(&model, &old, &mut no_progress()).unwrap();
        let b = report("(b) old path, 200 it", &model, &crawled, &pairs);
        // (c) the old state made exactly mirror-symmetric, then solved with the default
        let p = crawled.mesh.positions();
        let mut sym = model.clone();
        sym.positions = (0..p.len())
            .map(|i| {
                let (a, b) = (p[i], p[pairs[i]]);
                let z = if pairs[i] == i {
                    0.0
                } else {
                    0.5 * (a[2] - b[2])
                };
                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), z]
            })
            .collect();
        let from_sym = solve_base(&sym, &BaseOptions::default(), &mut no_progress()).unwrap();
        let c = report(
            "(c) from the symmetrised old state",
            &model,
            &from_sym,
            &pairs,
        );
        // the converged state must be a local minimum (up to rounding of the pinned Hessian)
        assert!(
            a > -1e-9,
            "converged torus base is not a local minimum: {a:e}"
        );
        let _ = (b, c);
    }
}

/// The SQP's rescue (`SqpResult::rescued_at`): on the teabag at 10 Pa (S:752, 2 × 468 v) the
/// first iteration's scales give a step of ~1e10 m on amplitudes the PSD projection left
/// almost without curvature, and both step solvers used to stop at once with
/// `LineSearchFailed`; with the rescue scales they converge, keeping the invariants.
#[test]
fn teabag_sqp_rescues_a_step_without_curvature() {
    use pleat::tfw::{solve, QpMethod, TfwParams};
    let scene = Scene::teabag(468, 10.0, 1).unwrap();
    for qp in [QpMethod::ProjectedNewton, QpMethod::Clarabel] {
        let mut p = TfwParams::default();
        p.sqp.qp = qp;
        let r = solve(&scene, &p, &mut no_progress()).unwrap();
        let s = r.sqp.as_ref().unwrap();
        assert!(s.status.converged(), "{qp:?}: {:?}", s.status);
        assert_eq!(s.rescued_at, Some(0), "{qp:?}");
        assert!(
            r.energy < 0.9 * s.initial_energy,
            "{qp:?}: E {} from {}",
            r.energy,
            s.initial_energy
        );
        let mut prev = s.initial_energy;
        for it in &s.history {
            assert!(it.curl_residual <= 1e-10 && it.energy <= prev, "{qp:?}");
            prev = it.energy;
        }
        assert!(r.cwf.amplitude().iter().all(|&a| a >= 0.0));
    }
}

/// Inverted or degenerate base triangles must be reported, without a panic: the stretched sheet
/// started with one interior vertex pushed across its neighbours (inverted triangles) and one
/// moved onto the midpoint of its row neighbours (zero-area triangles). The solve returns (no
/// panic); the base solve untangles the start (the membrane's energy is finite there) or, where
/// faces stay collapsed, reports them in `strain.degenerate_faces` with a warning; the SQP keeps
/// its invariants.
#[test]
fn inverted_and_collapsed_start_triangles_are_solved_or_reported() {
    use pleat::tfw::{solve, TfwParams};
    let (nx, ny) = (13, 6);
    let mut scene = Scene::stretched_sheet(nx, ny, 0.05);
    let pos = scene.panels[0].positions.as_mut().unwrap();
    let (a, b) = (2 * nx + 4, 2 * nx + 5);
    // invert: move vertex a two spacings to the far side of b; flatten: c onto the midpoint
    // of its row neighbours (zero-area triangles; onto a neighbour it would be sewn to it)
    let d = [pos[b][0] - pos[a][0], pos[b][1] - pos[a][1]];
    pos[a] = [pos[a][0] + 2.0 * d[0], pos[a][1] + 2.0 * d[1], 0.0];
    let c = 3 * nx + 8;
    pos[c] = std::array::from_fn(|k| 0.5 * (pos[c - 1][k] + pos[c + 1][k]));
    let r = solve(&scene, &TfwParams::default(), &mut no_progress());
    let r = match r {
        Ok(r) => r,
        Err(e) => {
            let m = e.to_string();
            eprintln!("error: {m}");
            assert!(
                m.contains("invert") || m.contains("degenerate") || m.contains("collapsed"),
                "{m}"
            );
            return;
        }
    };
    eprintln!(
        "base {:?}, degenerate {}, warnings {:?}",
        r.base.status, r.base.strain.degenerate_faces, r.base.warnings
    );
    if r.base.strain.degenerate_faces > 0 {
        assert!(
            r.base.warnings.iter().any(|w| w.contains("collapsed")),
            "{:?}",
            r.base.warnings
        );
    }
    assert!(r.curl_residual <= 1e-10);
    assert!(r.cwf.amplitude().iter().all(|&x| x >= 0.0 && x.is_finite()));
}
