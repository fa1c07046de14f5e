//! Subdivision exterior calculus and z upsampling (dissertation §3.5): `S1 d = d S0` on closed
//! and open meshes, and exact reproduction of plane waves.

#![cfg(feature = "wrinkle")]

mod wrinkle_common;

use pleat::mesh::TriMesh;
use pleat::wrinkle::{BoundaryRule, Complex, LoopHierarchy, SubdivisionOptions};
use wrinkle_common::*;

fn opts(boundary: BoundaryRule) -> SubdivisionOptions {
    SubdivisionOptions {
        boundary,
        ..Default::default()
    }
}

fn commutation_error(mesh: &TriMesh, rule: BoundaryRule, levels: usize, seed: u64) -> Vec<f64> {
    let h = LoopHierarchy::new(mesh, levels, &opts(rule)).unwrap();
    let mut rng = Rng::new(seed);
    (0..levels)
        .map(|l| {
            let n = h.mesh(l).vertex_count();
            let f: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            let lhs = h.subdivide_one_form(l, &h.d(l, &f).unwrap()).unwrap();
            let rhs = h.d(l + 1, &h.subdivide_scalar(l, &f).unwrap()).unwrap();
            lhs.iter()
                .zip(&rhs)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .collect()
}

#[test]
fn s1_commutes_with_d() {
    let meshes: Vec<(&str, TriMesh)> = vec![
        ("icosphere", icosphere(1)),
        ("torus", torus(12, 8, 3)),
        ("irregular grid", irregular_grid(6, 0.3, 7)),
        ("open cap", open_cap(1)),
        ("single triangle", single_triangle()),
    ];
    for (name, m) in &meshes {
        for rule in [BoundaryRule::Fixed, BoundaryRule::Smooth] {
            let err = commutation_error(m, rule, 3, 11);
            println!(
                "commutation |S1 d f - d S0 f|_max  {name:16} {rule:?}: {}",
                sci(&err)
            );
            for e in err {
                assert!(e < 1e-12, "{name} {rule:?}: {e}");
            }
        }
    }
}

/// Max |z − e^{ik·x}| per level for a plane wave of wave vector `k` (in the mesh plane).
fn plane_wave_errors(mesh: &TriMesh, k: [f64; 3], levels: usize, rule: BoundaryRule) -> Vec<f64> {
    let h = LoopHierarchy::new(mesh, levels, &opts(rule)).unwrap();
    let phase = |x: &[f64; 3]| k[0] * x[0] + k[1] * x[1] + k[2] * x[2];
    let m0 = h.mesh(0);
    let th: Vec<f64> = m0.positions().iter().map(phase).collect();
    let mut omega = h.d(0, &th).unwrap();
    let mut z: Vec<Complex> = th.iter().map(|&t| Complex::cis(t)).collect();
    let mut errs = vec![];
    for l in 0..levels {
        let z1 = h.subdivide_z(l, &omega, &z).unwrap();
        omega = h.subdivide_one_form(l, &omega).unwrap();
        z = z1;
        let x = h.mesh(l + 1);
        let e = x
            .positions()
            .iter()
            .zip(&z)
            .map(|(p, zi)| (*zi - Complex::cis(phase(p))).abs())
            .fold(0.0, f64::max);
        errs.push(e);
    }
    errs
}

#[test]
fn plane_waves_are_reproduced() {
    let base = irregular_grid(5, 0.3, 5);
    let edge = 1.0 / 5.0;
    for (name, m) in [("flat", base.clone()), ("tilted", tilt(&base))] {
        // in-plane direction of the (possibly tilted) grid's x axis and y axis
        let p = m.positions();
        let ex = unit(sub(p[1], p[0]));
        let ey = unit(sub(p[6], p[0]));
        for kh in [0.1, 1.0, 5.0, 20.0 * std::f64::consts::PI] {
            let kk = kh / edge;
            let k = add(scale(ex, 0.8 * kk), scale(ey, 0.6 * kk));
            for rule in [BoundaryRule::Fixed, BoundaryRule::Smooth] {
                let err = plane_wave_errors(&m, k, 5, rule);
                println!(
                    "plane wave {name:6} |k|h = {kh:7.3} {rule:?}: max|z - e^(ik.x)| per level {}",
                    sci(&err)
                );
                assert!(err.iter().all(|&e| e < 1e-11), "{err:?}");
            }
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    scale(a, 1.0 / l)
}
