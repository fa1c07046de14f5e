//! Wrinkle animation (dissertation §3.4): invariants of the interpolant between two CWF
//! keyframes — exact keyframes, rigid rotation of a plane wave (Fig. 3.8) against plain linear
//! interpolation, temporal coherence against per-frame Knöppel, and stability cases.
//!
//! Meshes are generated here and kept small (a few hundred vertices) so the file runs in
//! seconds; the corpus meshes are only used by `benches/wrinkle_interp.rs`.

#![cfg(feature = "wrinkle")]

mod wrinkle_common;

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use pleat::mesh::TriMesh;
use pleat::wrinkle::{
    animation_to_string, explicit_omega, interpolate, linear_interpolation, parse_animation,
    Complex, Cwf, CwfAnimation, FrequencyField, HessianModel, InterpOptions, InterpReport,
    KnoppelOptions, StopReason,
};
use wrinkle_common::{hex_disk, icosphere, Rng};

// ---------------------------------------------------------------------------------------------
// helpers

/// `hex_disk(rings)` (radius 1, spacing 1/rings) with interior vertices jittered by ±20 % of
/// the spacing: a flat irregular disk-like patch with boundary.
fn disk(rings: i64, seed: u64) -> TriMesh {
    let m = hex_disk(rings);
    let h = 1.0 / rings as f64;
    let mut rng = Rng::new(seed);
    let boundary = boundary_flags(&m);
    let p = m
        .positions()
        .iter()
        .enumerate()
        .map(|(i, &[x, y, z])| {
            if boundary[i] {
                [x, y, z]
            } else {
                [
                    x + rng.range(-0.2, 0.2) * h,
                    y + rng.range(-0.2, 0.2) * h,
                    z,
                ]
            }
        })
        .collect();
    TriMesh::new(p, m.triangles().to_vec()).unwrap()
}

fn boundary_flags(m: &TriMesh) -> Vec<bool> {
    let el = m.edges();
    let mut count = vec![0u32; el.len()];
    for fe in &el.face_edges {
        for &e in fe {
            count[e as usize] += 1;
        }
    }
    let mut b = vec![false; m.vertex_count()];
    for (e, &c) in count.iter().enumerate() {
        if c == 1 {
            let [p, q] = el.edges[e].0;
            b[p as usize] = true;
            b[q as usize] = true;
        }
    }
    b
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The exactly compatible plane wave `a · exp(i k·x)`.
fn plane_wave(m: &TriMesh, k: [f64; 3], amp: f64) -> Cwf {
    let x = m.positions();
    let omega = m
        .edges()
        .edges
        .iter()
        .map(|e| dot(k, x[e.0[1] as usize]) - dot(k, x[e.0[0] as usize]))
        .collect();
    let zeta = x.iter().map(|&p| Complex::cis(dot(k, p))).collect();
    Cwf::new(m.clone(), omega, vec![amp; m.vertex_count()], zeta).unwrap()
}

/// Mean edge length.
fn mean_edge(m: &TriMesh) -> f64 {
    let x = m.positions();
    let el = m.edges();
    el.edges
        .iter()
        .map(|e| {
            let (p, q) = (x[e.0[0] as usize], x[e.0[1] as usize]);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        })
        .sum::<f64>()
        / el.len() as f64
}

/// Least-squares plane wave `exp(i(k·x + φ0))` fitted to `z` on a flat (z = 0) mesh: the wave
/// vector from the wrapped phase differences of edges whose endpoints have `|z| > 0.3`, then the
/// phase offset. Returns `(k, rms |z − fit|)` over all vertices (magnitude deficits count).
fn fit_plane_wave(m: &TriMesh, z: &[Complex]) -> ([f64; 2], f64) {
    let x = m.positions();
    let (mut a11, mut a12, mut a22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for e in &m.edges().edges {
        let [p, q] = e.0;
        let (zp, zq) = (z[p as usize], z[q as usize]);
        if zp.abs() < 0.3 || zq.abs() < 0.3 {
            continue;
        }
        let d = (zp.conj() * zq).arg();
        let (dx, dy) = (
            x[q as usize][0] - x[p as usize][0],
            x[q as usize][1] - x[p as usize][1],
        );
        a11 += dx * dx;
        a12 += dx * dy;
        a22 += dy * dy;
        b1 += dx * d;
        b2 += dy * d;
    }
    let det = a11 * a22 - a12 * a12;
    let k = [(a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det];
    let phase = |p: [f64; 3]| k[0] * p[0] + k[1] * p[1];
    let mut s = Complex::ZERO;
    for (zj, &p) in z.iter().zip(x) {
        s += *zj * Complex::cis(-phase(p));
    }
    let phi0 = s.arg();
    let rms = (z
        .iter()
        .zip(x)
        .map(|(zj, &p)| (*zj - Complex::cis(phase(p) + phi0)).norm_sqr())
        .sum::<f64>()
        / z.len() as f64)
        .sqrt();
    (k, rms)
}

/// Largest `|z̃_{n+1} − z̃_n|` over consecutive frames and vertices with `|z̃| > 0.5` in both.
fn max_frame_change(frames: &[Vec<Complex>]) -> f64 {
    frames
        .windows(2)
        .flat_map(|w| {
            w[0].iter()
                .zip(&w[1])
                .filter(|(a, b)| a.abs() > 0.5 && b.abs() > 0.5)
                .map(|(a, b)| (*b - *a).abs())
        })
        .fold(0.0, f64::max)
}

fn guide_zetas(anim: &CwfAnimation) -> Vec<Vec<Complex>> {
    (0..=anim.guide_intervals())
        .map(|n| anim.guide_zeta(n).to_vec())
        .collect()
}

fn print_report(name: &str, r: &InterpReport, seconds: f64) {
    println!(
        "{name}: {} after {} iterations ({} factorizations, {} unknowns), gradient {:.2e} -> \
         {:.2e}, E_smooth {:.3e}, E_compat {:.3e}, E_unit {:.3e}, g_ave {:.3e}, {seconds:.3} s",
        r.stop.name(),
        r.iterations,
        r.factorizations,
        r.unknowns,
        r.history.first().map_or(0.0, |h| h.gradient_norm),
        r.final_gradient_norm(),
        r.smooth_energy,
        r.compat_energy,
        r.unit_energy,
        r.g_ave,
    );
}

fn run(a: &Cwf, b: &Cwf, opts: &InterpOptions, name: &str) -> (CwfAnimation, InterpReport) {
    let t0 = std::time::Instant::now();
    let (anim, report) = interpolate(a, b, opts).unwrap();
    print_report(name, &report, t0.elapsed().as_secs_f64());
    (anim, report)
}

fn small_opts() -> InterpOptions {
    InterpOptions {
        guide_frames: 20,
        ..Default::default()
    }
}

/// The rotation pair of Fig. 3.8 on a jittered disk of radius 1 (`k = 2π`: two wavelengths
/// across) and its default interpolation (50 guide frames), solved once for the tests using it.
struct Rotation {
    mesh: TriMesh,
    k: f64,
    a: Cwf,
    b: Cwf,
    anim: CwfAnimation,
}

fn rotation() -> &'static Rotation {
    static R: std::sync::OnceLock<Rotation> = std::sync::OnceLock::new();
    R.get_or_init(|| {
        let mesh = disk(7, 7);
        let k = 2.0 * PI;
        let a = plane_wave(&mesh, [k, 0.0, 0.0], 0.01);
        let b = plane_wave(&mesh, [0.0, k, 0.0], 0.01);
        let (anim, report) = run(&a, &b, &InterpOptions::default(), "rotation");
        assert_eq!(report.stop, StopReason::Converged);
        Rotation {
            mesh,
            k,
            a,
            b,
            anim,
        }
    })
}

// ---------------------------------------------------------------------------------------------
// tests

#[test]
fn keyframes_are_reproduced_exactly() {
    let m = disk(6, 1);
    let a = plane_wave(&m, [2.0 * PI, 0.0, 0.0], 0.02);
    let b = plane_wave(&m, [0.0, 5.0, 0.0], 0.01);
    let (anim, report) = run(&a, &b, &small_opts(), "keyframes");
    assert_eq!(report.stop, StopReason::Converged);
    for (t, key) in [(0.0, &a), (1.0, &b)] {
        let f = anim.frame_at(t).unwrap();
        assert_eq!(f.omega(), key.omega(), "ω at t = {t}");
        assert_eq!(f.amplitude(), key.amplitude(), "a at t = {t}");
        assert_eq!(f.zeta(), key.zeta(), "z̃ at t = {t}");
    }
    let last = anim.frame(anim.frame_count() - 1).unwrap();
    assert_eq!(last.zeta(), b.zeta());
    // the explicit ω(t) starts and ends at the keyframes too
    assert_eq!(explicit_omega(&a, &b, 0.0).unwrap(), a.omega());
    assert_eq!(explicit_omega(&a, &b, 1.0).unwrap(), b.omega());
    assert!(anim.frame_at(1.5).is_err() && anim.frame_at(f64::NAN).is_err());
    // save → load reproduces every frame bit for bit
    let text = animation_to_string(&anim);
    let back = parse_animation(&text, m.clone(), "<memory>").unwrap();
    for t in [0.0, 0.13, 0.5, 0.777, 1.0] {
        let (p, q) = (anim.frame_at(t).unwrap(), back.frame_at(t).unwrap());
        assert_eq!(p.omega(), q.omega());
        assert_eq!(p.zeta(), q.zeta());
        assert_eq!(p.amplitude(), q.amplitude());
    }
    assert_eq!(animation_to_string(&back), text);
}

#[test]
fn rigid_rotation_beats_linear_interpolation() {
    // Fig. 3.8: z0 = exp(i k x), z1 = exp(i k y) on a flat disk of radius 1 (k = 2π: two
    // wavelengths across). The interpolant should rotate the wave rigidly: at t = 0.5 a plane
    // wave of the same wavenumber at 45°.
    let r = rotation();
    let (m, k, a, b, anim) = (&r.mesh, r.k, &r.a, &r.b, &r.anim);
    let mid = anim.frame_at(0.5).unwrap();
    let (kv, rms) = fit_plane_wave(m, mid.zeta());
    let angle = kv[1].atan2(kv[0]);
    let kn = kv[0].hypot(kv[1]);
    let lin = linear_interpolation(a, b, 0.5).unwrap();
    let (kl, rms_lin) = fit_plane_wave(m, lin.zeta());
    let min_lin = lin
        .zeta()
        .iter()
        .map(|z| z.abs())
        .fold(f64::INFINITY, f64::min);
    let min_ours = mid
        .zeta()
        .iter()
        .map(|z| z.abs())
        .fold(f64::INFINITY, f64::min);
    println!(
        "rotation t=0.5 — ours: plane-wave residual {rms:.4}, angle {:.3}° (error {:.3}°), |k| \
         {kn:.4} (expected {k:.4}), min |z̃| {min_ours:.3}",
        angle.to_degrees(),
        (angle - FRAC_PI_4).abs().to_degrees()
    );
    println!(
        "rotation t=0.5 — linear: plane-wave residual {rms_lin:.4}, angle {:.3}°, |k| {:.4}, \
         min |z̃| {min_lin:.3} (degenerates along lines x − y = odd·π/k)",
        kl[1].atan2(kl[0]).to_degrees(),
        kl[0].hypot(kl[1])
    );
    assert!(
        rms < 0.15,
        "ours is not a plane wave at t = 0.5: residual {rms}"
    );
    assert!(
        (angle - FRAC_PI_4).abs() < 3f64.to_radians(),
        "angle {angle}"
    );
    assert!((kn / k - 1.0).abs() < 0.1, "|k| = {kn}");
    assert!(rms_lin > 3.0 * rms && min_lin < 0.1);
    // the explicit ω(t) is the rotated plane wave at every t (B.34 on exact input)
    for t in [0.25, 0.5, 0.75] {
        let w = explicit_omega(a, b, t).unwrap();
        let th = FRAC_PI_2 * t;
        let kt = [k * th.cos(), k * th.sin(), 0.0];
        let x = m.positions();
        let worst = m
            .edges()
            .edges
            .iter()
            .zip(&w)
            .map(|(e, wv)| (wv - (dot(kt, x[e.0[1] as usize]) - dot(kt, x[e.0[0] as usize]))).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-12,
            "ω({t}) differs from the rotated wave by {worst}"
        );
    }
}

#[test]
fn temporal_coherence_beats_per_frame_knoppel() {
    let r = rotation();
    let (m, k, a, b) = (&r.mesh, r.k, &r.a, &r.b);
    let opts = InterpOptions::default();
    let ours = max_frame_change(&guide_zetas(&r.anim));
    // per-frame Knöppel on the same ω(t) and a(t)
    let n = opts.guide_frames;
    let knoppel: Vec<Vec<Complex>> = (0..=n)
        .map(|i| {
            let t = i as f64 / n as f64;
            let w = explicit_omega(a, b, t).unwrap();
            let amp = vec![0.01; m.vertex_count()];
            let (c, _) = Cwf::from_one_form(m.clone(), w, amp, &KnoppelOptions::default()).unwrap();
            c.zeta().to_vec()
        })
        .collect();
    let theirs = max_frame_change(&knoppel);
    // Bound: between guide frames wrinkles should travel at most one edge length (§3.4.1), so the
    // phase at a point changes by at most |k|·h: |Δz̃| ≤ |k| h.
    let bound = k * mean_edge(m);
    println!(
        "coherence: max |Δz̃| per guide step — ours {ours:.4}, per-frame Knöppel {theirs:.4}, \
         bound |k|·h = {bound:.4}"
    );
    assert!(ours <= bound, "ours {ours} exceeds {bound}");
    assert!(theirs > ours);
}

#[test]
fn stability_zero_amplitude() {
    // g_ave = 0: no wrinkles anywhere; the phase still interpolates (unweighted E_smooth)
    let m = disk(4, 2);
    let mut a = plane_wave(&m, [6.0, 0.0, 0.0], 0.0);
    let b = plane_wave(&m, [0.0, 6.0, 0.0], 0.0);
    let (anim, r) = run(&a, &b, &small_opts(), "zero amplitude");
    assert_eq!(r.g_ave, 0.0);
    assert_eq!(r.stop, StopReason::Converged);
    check_finite(&anim);
    // a zero-amplitude keyframe next to a non-zero one takes the linear ω fallback
    a = plane_wave(&m, [6.0, 0.0, 0.0], 0.0);
    let b2 = plane_wave(&m, [0.0, 6.0, 0.0], 0.01);
    let w = explicit_omega(&a, &b2, 0.5).unwrap();
    for ((x, y), z) in a.omega().iter().zip(b2.omega()).zip(&w) {
        assert!((0.5 * (x + y) - z).abs() < 1e-12);
    }
    let (anim, r) = run(&a, &b2, &small_opts(), "zero → non-zero amplitude");
    assert!(matches!(
        r.stop,
        StopReason::Converged | StopReason::Stalled
    ));
    check_finite(&anim);
}

fn check_finite(anim: &CwfAnimation) {
    for i in 0..anim.frame_count() {
        let f = anim.frame(i).unwrap();
        assert!(f.omega().iter().all(|w| w.is_finite()));
        assert!(f.zeta().iter().all(|z| z.is_finite()));
    }
}

#[test]
fn stability_penalty_scale() {
    // c × 10 and c × 10⁵ (the paper's unstable end): converge, or stop cleanly with a status
    let m = disk(4, 5);
    let a = plane_wave(&m, [2.0 * PI, 0.0, 0.0], 0.01);
    let b = plane_wave(&m, [0.0, 2.0 * PI, 0.0], 0.01);
    for factor in [10.0, 1e5] {
        let opts = InterpOptions {
            c_scale: 1e3 * factor,
            max_iterations: 100,
            ..small_opts()
        };
        let (anim, r) = run(&a, &b, &opts, &format!("c × {factor:e}"));
        check_finite(&anim);
        assert!(r
            .history
            .windows(2)
            .all(|w| w[1].objective <= w[0].objective));
        assert!(matches!(
            r.stop,
            StopReason::Converged | StopReason::Stalled | StopReason::IterationCap
        ));
    }
}

#[test]
fn stability_identical_keyframes() {
    let m = disk(4, 9);
    let a = plane_wave(&m, [5.0, 2.0, 0.0], 0.01);
    let (anim, r) = run(&a, &a.clone(), &small_opts(), "identical");
    assert_eq!(r.iterations, 0);
    assert_eq!(r.stop, StopReason::IdenticalKeyframes);
    for i in 0..anim.frame_count() {
        let f = anim.frame(i).unwrap();
        assert_eq!(f.zeta(), a.zeta());
        assert_eq!(f.omega(), a.omega());
    }
}

#[test]
fn stability_frequency_tripled() {
    // frequency × 3, amplitude ÷ 3 (Fig. 3.5): new wrinkles are born through singularities
    let m = disk(6, 11);
    let a = plane_wave(&m, [4.0, 0.0, 0.0], 0.03);
    let b = plane_wave(&m, [12.0, 0.0, 0.0], 0.01);
    let (anim, r) = run(&a, &b, &small_opts(), "frequency × 3");
    assert_eq!(r.stop, StopReason::Converged);
    check_finite(&anim);
    let singular: Vec<usize> = (0..=anim.guide_intervals())
        .map(|n| anim.guide_zeta(n).iter().filter(|z| z.abs() < 0.3).count())
        .collect();
    println!("frequency × 3: vertices with |z̃| < 0.3 per guide frame: {singular:?}");
    assert_eq!(singular[0], 0);
    // ω(t) grows monotonically from 4 to 12 along x
    let x = m.positions();
    let mut last = 4.0;
    for t in [0.25, 0.5, 0.75] {
        let w = explicit_omega(&a, &b, t).unwrap();
        let e = m.edges().edges[0].0;
        let kx = w[0] / (x[e[1] as usize][0] - x[e[0] as usize][0]);
        assert!(kx > last && kx < 12.0, "k_x({t}) = {kx}");
        last = kx;
    }
}

#[test]
fn stability_closed_mesh_and_incompatible_keyframes() {
    // a sphere (closed) with Knöppel keyframes, and keyframes whose z̃ disagrees with ω (eq. 3.17)
    let m = icosphere(2);
    let n = m.vertex_count();
    let ka = vec![[6.0, 0.0, 0.0]; n];
    let kb = vec![[0.0, 0.0, 6.0]; n];
    let opts = KnoppelOptions::default();
    let (a, _) = Cwf::from_frequency_field(
        m.clone(),
        FrequencyField::PerVertex(&ka),
        vec![0.01; n],
        &opts,
    )
    .unwrap();
    let (b, _) = Cwf::from_frequency_field(
        m.clone(),
        FrequencyField::PerVertex(&kb),
        vec![0.01; n],
        &opts,
    )
    .unwrap();
    let (anim, r) = run(&a, &b, &small_opts(), "sphere");
    assert_eq!(r.stop, StopReason::Converged);
    check_finite(&anim);
    // perturb b's phase by up to ±0.6 rad per vertex: the keyframe is no CWF any more (its ω
    // and z̃ disagree), yet the ends stay exact
    let mut rng = Rng::new(4);
    let zeta: Vec<Complex> = b
        .zeta()
        .iter()
        .map(|&z| z * Complex::cis(rng.range(-0.6, 0.6)))
        .collect();
    let c = Cwf::new(m.clone(), b.omega().to_vec(), vec![0.01; n], zeta).unwrap();
    let (anim, r) = run(&a, &c, &small_opts(), "incompatible keyframe");
    assert!(matches!(
        r.stop,
        StopReason::Converged | StopReason::Stalled
    ));
    assert_eq!(anim.frame_at(1.0).unwrap().omega(), c.omega());
    assert_eq!(anim.frame_at(1.0).unwrap().zeta(), c.zeta());
}

#[test]
fn different_base_meshes_are_rejected() {
    let a = plane_wave(&disk(4, 1), [3.0, 0.0, 0.0], 0.01);
    let b = plane_wave(&disk(4, 2), [3.0, 0.0, 0.0], 0.01);
    let e = interpolate(&a, &b, &small_opts()).unwrap_err();
    assert!(e.to_string().contains("different base meshes"), "{e}");
    let c = plane_wave(&disk(5, 1), [3.0, 0.0, 0.0], 0.01);
    let e = interpolate(&a, &c, &small_opts()).unwrap_err();
    assert!(e.to_string().contains("different base meshes"), "{e}");
    let bad = InterpOptions {
        guide_frames: 0,
        ..Default::default()
    };
    assert!(interpolate(&a, &a, &bad).is_err());
}

#[test]
fn deterministic_across_thread_counts() {
    let m = disk(4, 13);
    let a = plane_wave(&m, [2.0 * PI, 0.0, 0.0], 0.01);
    let b = plane_wave(&m, [0.0, 2.0 * PI, 0.0], 0.02);
    let texts: Vec<String> = [1, 2, 8]
        .iter()
        .map(|&n| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap();
            pool.install(|| animation_to_string(&interpolate(&a, &b, &small_opts()).unwrap().0))
        })
        .collect();
    assert!(
        texts[0] == texts[1] && texts[0] == texts[2],
        "output depends on the thread count (1, 2, 8)"
    );
}

/// The matrix-free trust-region solver (default) and the direct damped Newton solver (exact
/// Hessian, sparse Cholesky of the whole spacetime system) minimize the same objective: on the
/// rotation pair they reach the same energies and the same phases.
#[test]
fn trust_region_matches_direct_newton() {
    let m = disk(5, 3);
    let a = plane_wave(&m, [2.0 * PI, 0.0, 0.0], 0.01);
    let b = plane_wave(&m, [0.0, 2.0 * PI, 0.0], 0.01);
    let solve = |hessian, name| {
        let opts = InterpOptions {
            hessian,
            gradient_tolerance: 1e-9,
            ..small_opts()
        };
        run(&a, &b, &opts, name)
    };
    let (tr, rt) = solve(HessianModel::TrustRegion, "trust region");
    let (direct, rd) = solve(HessianModel::Exact, "direct exact Newton");
    assert_eq!(rt.stop, StopReason::Converged);
    assert_eq!(rd.stop, StopReason::Converged);
    assert!(rt.cg_iterations > 0 && rd.cg_iterations == 0);
    let total = |r: &InterpReport| r.smooth_energy + r.c * (r.compat_energy + r.unit_energy);
    let (et, ed) = (total(&rt), total(&rd));
    println!("objective: trust region {et:.12e}, direct {ed:.12e}");
    assert!((et - ed).abs() <= 1e-8 * ed.abs(), "{et} vs {ed}");
    let (zt, zd) = (guide_zetas(&tr), guide_zetas(&direct));
    let diff = zt
        .iter()
        .flatten()
        .zip(zd.iter().flatten())
        .map(|(x, y)| (*x - *y).abs())
        .fold(0.0, f64::max);
    println!("max |z̃_tr − z̃_direct| = {diff:.2e}");
    assert!(diff < 1e-5, "phases differ by {diff}");
}
