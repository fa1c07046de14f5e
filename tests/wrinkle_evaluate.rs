//! Wrinkle evaluation (§3.5): incompatible input, vortices, stiff and extreme inputs,
//! determinism across thread counts.

#![cfg(feature = "wrinkle")]

mod wrinkle_common;

use pleat::mesh::TriMesh;
use pleat::wrinkle::{Complex, Cwf, EvalOptions, Evaluated};
use wrinkle_common::*;

fn with_z() -> EvalOptions {
    EvalOptions {
        want_z: true,
        want_normals: true,
        want_amplitude: true,
        want_phase: true,
        ..Default::default()
    }
}

fn all_finite(e: &Evaluated) -> bool {
    e.mesh.positions().iter().flatten().all(|c| c.is_finite())
        && e.z.as_ref().unwrap().iter().all(|z| z.is_finite())
        && e.normals
            .as_ref()
            .unwrap()
            .iter()
            .flatten()
            .all(|c| c.is_finite())
        && e.amplitude.as_ref().unwrap().iter().all(|c| c.is_finite())
}

/// Largest change of `f` across an edge of `m`.
fn max_jump<T: Copy>(m: &TriMesh, f: &[T], dist: impl Fn(T, T) -> f64) -> f64 {
    m.edges()
        .edges
        .iter()
        .map(|e| dist(f[e.0[0] as usize], f[e.0[1] as usize]))
        .fold(0.0, f64::max)
}

fn displacement_jump(e: &Evaluated) -> f64 {
    let s = e.smooth_positions.as_ref().unwrap();
    let d: Vec<[f64; 3]> = e
        .mesh
        .positions()
        .iter()
        .zip(s)
        .map(|(p, q)| [p[0] - q[0], p[1] - q[1], p[2] - q[2]])
        .collect();
    max_jump(&e.mesh, &d, |a, b| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    })
}

fn plane_wave_omega(m: &TriMesh, k: [f64; 3]) -> Vec<f64> {
    let p = m.positions();
    m.edges()
        .edges
        .iter()
        .map(|e| {
            let (a, b) = (p[e.0[0] as usize], p[e.0[1] as usize]);
            k[0] * (b[0] - a[0]) + k[1] * (b[1] - a[1]) + k[2] * (b[2] - a[2])
        })
        .collect()
}

#[test]
fn incompatible_input_gives_finite_smooth_output() {
    let m = irregular_grid(8, 0.3, 21);
    let n = m.vertex_count();
    let mut rng = Rng::new(5);
    let zeta: Vec<Complex> = (0..n).map(|_| Complex::cis(rng.range(-3.2, 3.2))).collect();
    let omega = plane_wave_omega(&m, [40.0, 10.0, 0.0]);
    let cwf = Cwf::new(m, omega, vec![0.02; n], zeta).unwrap();
    println!("incompatible: E_compat = {:.3}", cwf.compatibility_energy());
    let mut jumps = vec![];
    for levels in 1..=5 {
        let (e, _) = cwf.evaluate(levels, &with_z()).unwrap();
        assert!(all_finite(&e));
        let z = e.z.as_ref().unwrap();
        jumps.push(max_jump(&e.mesh, z, |a, b| (a - b).abs()));
    }
    println!(
        "incompatible: max |z_a - z_b| over edges, levels 1..5: {}",
        sci(&jumps)
    );
    // a continuous limit: jumps shrink geometrically once the wave is resolved
    assert!(
        jumps[4] < 0.6 * jumps[3] && jumps[3] < 0.7 * jumps[2],
        "{jumps:?}"
    );
}

fn vortex_cwf(m: &TriMesh, c: [f64; 2], winding: f64, singular_vertex: Option<usize>) -> Cwf {
    let theta: Vec<f64> = m
        .positions()
        .iter()
        .map(|p| winding * (p[1] - c[1]).atan2(p[0] - c[0]))
        .collect();
    let wrap = |x: f64| {
        x - std::f64::consts::TAU * ((x + std::f64::consts::PI) / std::f64::consts::TAU).floor()
    };
    let omega: Vec<f64> = m
        .edges()
        .edges
        .iter()
        .map(|e| {
            let [a, b] = e.0.map(|v| v as usize);
            if Some(a) == singular_vertex || Some(b) == singular_vertex {
                0.0
            } else {
                wrap(theta[b] - theta[a])
            }
        })
        .collect();
    let zeta: Vec<Complex> = (0..m.vertex_count())
        .map(|j| {
            if Some(j) == singular_vertex {
                Complex::ZERO
            } else {
                Complex::cis(theta[j])
            }
        })
        .collect();
    Cwf::new(m.clone(), omega, vec![0.05; m.vertex_count()], zeta).unwrap()
}

#[test]
fn vortices_vanish_at_the_singularity() {
    let grid = irregular_grid(10, 0.25, 31);
    let disk = hex_disk(4);
    type Case<'a> = (&'a str, &'a TriMesh, [f64; 2], f64, Option<usize>);
    let cases: Vec<Case> = vec![
        ("in face, +1", &grid, [0.512, 0.487], 1.0, None),
        ("in face, -1", &grid, [0.431, 0.566], -1.0, None),
        ("at vertex, +1", &disk, [0.0, 0.0], 1.0, Some(0)),
        ("at vertex, -1", &disk, [0.0, 0.0], -1.0, Some(0)),
    ];
    for (name, m, c, w, sv) in cases {
        let cwf = vortex_cwf(m, c, w, sv);
        let mut near = vec![];
        let mut jumps = vec![];
        for levels in 1..=5 {
            let (e, _) = cwf.evaluate(levels, &with_z()).unwrap();
            assert!(all_finite(&e), "{name}");
            let z = e.z.as_ref().unwrap();
            let x = e.smooth_positions.as_ref().unwrap();
            // smallest |z| within 0.05 of the singularity, relative to the amplitude
            let zmin = x
                .iter()
                .zip(z)
                .filter(|(p, _)| (p[0] - c[0]).hypot(p[1] - c[1]) < 0.05)
                .map(|(_, z)| z.abs() / 0.05)
                .fold(f64::INFINITY, f64::min);
            near.push(zmin);
            jumps.push(displacement_jump(&e));
            if levels == 5 {
                let wn = winding(z, &boundary_loop(&e.mesh));
                println!("vortex {name:14}: winding number along the level-5 boundary {wn:+.6}");
                assert!((wn - w).abs() < 1e-9);
                if let Some(v) = sv {
                    println!(
                        "vortex {name:14}: |z| at the singular vertex {:.1e}",
                        z[v].abs()
                    );
                    assert!(z[v].abs() < 1e-12);
                }
            }
        }
        println!(
            "vortex {name:14}: min |z|/a near the singularity, levels 1..5: {}",
            sci(&near)
        );
        println!(
            "vortex {name:14}: max displacement jump across an edge, levels 1..5: {}",
            sci(&jumps)
        );
        assert!(near[4] < 0.1, "{name}: {near:?}");
        assert!(jumps[4] < 0.5 * jumps[2], "{name}: {jumps:?}");
    }
}

fn scaled(m: &TriMesh, s: f64) -> TriMesh {
    let p = m.positions().iter().map(|p| p.map(|c| c * s)).collect();
    TriMesh::new(p, m.triangles().to_vec()).unwrap()
}

/// Max |z − a e^{ik·x}| / a over the level-`levels` vertices for a compatible plane wave.
fn plane_wave_eval_error(m: &TriMesh, k: [f64; 3], levels: usize) -> f64 {
    let n = m.vertex_count();
    let zeta = m
        .positions()
        .iter()
        .map(|p| Complex::cis(k[0] * p[0] + k[1] * p[1] + k[2] * p[2]))
        .collect();
    let a = 0.25;
    let cwf = Cwf::new(m.clone(), plane_wave_omega(m, k), vec![a; n], zeta).unwrap();
    let (e, _) = cwf.evaluate(levels, &with_z()).unwrap();
    assert!(all_finite(&e));
    let x = e.smooth_positions.as_ref().unwrap();
    e.z.as_ref()
        .unwrap()
        .iter()
        .zip(x)
        .map(|(z, p)| {
            (*z - Complex::cis(k[0] * p[0] + k[1] * p[1] + k[2] * p[2]).scale(a)).abs() / a
        })
        .fold(0.0, f64::max)
}

#[test]
fn stiff_and_extreme_inputs() {
    let mut rng = Rng::new(77);
    // zero amplitude everywhere: no displacement at all, z stays exactly zero
    let m = torus(12, 8, 2);
    let (n, ne) = (m.vertex_count(), m.edges().len());
    let omega: Vec<f64> = (0..ne).map(|_| rng.range(-1e3, 1e3)).collect();
    let zeta: Vec<Complex> = (0..n).map(|_| Complex::cis(rng.range(-3.0, 3.0))).collect();
    let cwf = Cwf::new(m.clone(), omega, vec![0.0; n], zeta.clone()).unwrap();
    let (e, _) = cwf.evaluate(3, &with_z()).unwrap();
    assert!(e.z.as_ref().unwrap().iter().all(|z| *z == Complex::ZERO));
    assert_eq!(e.mesh.positions(), &e.smooth_positions.unwrap()[..]);
    println!(
        "a = 0: z ≡ 0 and zero displacement on {} vertices",
        e.mesh.vertex_count()
    );

    // huge frequencies: finite, bounded by the amplitude
    let omega: Vec<f64> = (0..ne).map(|_| rng.range(-1e6, 1e6)).collect();
    let cwf = Cwf::new(m.clone(), omega, vec![0.1; n], zeta).unwrap();
    let (e, _) = cwf.evaluate(3, &with_z()).unwrap();
    assert!(all_finite(&e));
    let zmax =
        e.z.as_ref()
            .unwrap()
            .iter()
            .map(|z| z.abs())
            .fold(0.0, f64::max);
    println!("|ω| ≤ 1e6: finite, max |z| = {zmax:.3} (amplitude 0.1)");
    assert!(zmax <= 0.1 * (1.0 + 1e-12));

    // nearly degenerate triangles: an interior vertex 1e-12 off the line of two neighbours
    let g = irregular_grid(6, 0.0, 1);
    let mut p = g.positions().to_vec();
    let id = |i: usize, j: usize| j * 7 + i;
    p[id(3, 3)] = [0.5, 0.5 + 1e-12, 0.0];
    p[id(2, 3)] = [0.5 - 1.0 / 6.0, 0.5, 0.0];
    p[id(4, 3)] = [0.5 + 1.0 / 6.0, 0.5, 0.0];
    p[id(3, 2)] = [0.5, 0.5 - 1e-12, 0.0];
    let sliver = TriMesh::new(p, g.triangles().to_vec()).unwrap();
    let min_area = (0..sliver.triangle_count())
        .map(|t| sliver.triangle_area(t))
        .fold(f64::INFINITY, f64::min);
    let err = plane_wave_eval_error(&sliver, [30.0, 20.0, 0.0], 4);
    println!("slivers (min area {min_area:.1e}): plane-wave error after 4 levels {err:.1e}");
    assert!(err < 1e-10);

    // scale invariance: coordinates × 1e-6 and × 1e6 with k / s
    let base = irregular_grid(6, 0.3, 12);
    for s in [1e-6, 1.0, 1e6] {
        let err = plane_wave_eval_error(&scaled(&base, s), [50.0 / s, -20.0 / s, 0.0], 4);
        println!("coordinates × {s:.0e}: plane-wave error after 4 levels {err:.1e}");
        assert!(err < 1e-11);
    }

    // an unreferenced vertex is carried along unchanged
    let mut p = single_triangle().positions().to_vec();
    p.push([5.0, 5.0, 5.0]);
    let lonely = TriMesh::new(p, vec![[0, 1, 2]]).unwrap();
    let cwf = Cwf::new(lonely, vec![1.0; 3], vec![0.1; 4], vec![Complex::ONE; 4]).unwrap();
    let (e, _) = cwf.evaluate(2, &with_z()).unwrap();
    assert!(all_finite(&e));
    assert_eq!(e.mesh.positions()[3], [5.0, 5.0, 5.0]);

    // a single triangle
    let err = plane_wave_eval_error(&single_triangle(), [40.0, 25.0, 0.0], 5);
    println!("single triangle: plane-wave error after 5 levels {err:.1e}");
    assert!(err < 1e-11);

    // a non-manifold base is refused with a clear error
    let p = vec![
        [0.; 3],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., -1., 0.],
        [0., 0., 1.],
    ];
    let nm = TriMesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 4, 1]]).unwrap();
    let err = Cwf::new(nm, vec![0.0; 7], vec![1.0; 5], vec![Complex::ONE; 5]).unwrap_err();
    println!("non-manifold base: {err}");
    assert!(err.to_string().contains("more than two triangles"));
}

#[test]
fn output_bytes_do_not_depend_on_thread_count() {
    let m = torus(16, 10, 4);
    let n = m.vertex_count();
    let mut rng = Rng::new(8);
    let omega = plane_wave_omega(&m, [7.0, 3.0, 5.0]);
    let zeta: Vec<Complex> = (0..n).map(|_| Complex::cis(rng.range(-3.0, 3.0))).collect();
    let cwf = Cwf::new(m, omega, vec![0.05; n], zeta).unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| cwf.evaluate(4, &with_z()).unwrap().0)
    };
    let (a, b, c) = (run(1), run(2), run(8));
    let bits = |e: &Evaluated| {
        let mut v: Vec<u64> = e
            .mesh
            .positions()
            .iter()
            .flatten()
            .map(|c| c.to_bits())
            .collect();
        v.extend(
            e.z.as_ref()
                .unwrap()
                .iter()
                .flat_map(|z| [z.re.to_bits(), z.im.to_bits()]),
        );
        v.extend(
            e.normals
                .as_ref()
                .unwrap()
                .iter()
                .flatten()
                .map(|c| c.to_bits()),
        );
        v
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(bits(&a), bits(&c));
    assert_eq!(a.mesh.triangles(), b.mesh.triangles());
    assert_eq!(a.mesh.triangles(), c.mesh.triangles());
    println!(
        "1 vs 2 vs 8 threads: {} output values identical bit for bit",
        bits(&a).len()
    );
}

#[test]
fn progress_reports_and_cancels() {
    let m = irregular_grid(4, 0.2, 3);
    let n = m.vertex_count();
    let cwf = Cwf::new(
        m,
        plane_wave_omega(&irregular_grid(4, 0.2, 3), [5.0, 0.0, 0.0]),
        vec![0.1; n],
        vec![Complex::ONE; n],
    )
    .unwrap();
    let mut seen = vec![];
    let (e, stats) = cwf
        .evaluate_with_progress(3, &EvalOptions::default(), &mut |p| {
            seen.push((p.stage.to_string(), p.fraction));
            true
        })
        .unwrap();
    assert_eq!(e.mesh.triangle_count(), 32 * 64);
    // per level: 5 parts (4 on the last) and the level; then the displacement
    assert_eq!(seen.len(), 3 * 6);
    assert!(seen.windows(2).all(|w| w[0].1 < w[1].1) && seen[17].1 == 1.0);
    assert_eq!(stats.levels[2].faces, 2048);
    let err = cwf
        .evaluate_with_progress(3, &EvalOptions::default(), &mut |p| p.stage != "level 2")
        .unwrap_err();
    assert_eq!(err, pleat::Error::Cancelled);
    println!("progress: {seen:?}");
}
