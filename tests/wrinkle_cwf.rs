//! CWF representation (§3.3): energies (3.5, 3.6), the ω split (3.17), Knöppel phase from
//! frequency, the `.cwf` file format, and validation errors.

#![cfg(feature = "wrinkle")]

mod wrinkle_common;

use pleat::mesh::TriMesh;
use pleat::wrinkle::{
    cwf_to_string, parse_cwf, read_cwf, write_cwf, Complex, Cwf, FrequencyField, KnoppelOptions,
    PhaseWeights,
};
use pleat::Error;
use wrinkle_common::*;

fn plane_wave(m: &TriMesh, k: [f64; 3]) -> (Vec<f64>, Vec<Complex>) {
    let th: Vec<f64> = m
        .positions()
        .iter()
        .map(|p| k[0] * p[0] + k[1] * p[1] + k[2] * p[2])
        .collect();
    let omega = m
        .edges()
        .edges
        .iter()
        .map(|e| th[e.0[1] as usize] - th[e.0[0] as usize])
        .collect();
    (omega, th.iter().map(|&t| Complex::cis(t)).collect())
}

#[test]
fn energies_vanish_on_compatible_unit_fields() {
    let m = irregular_grid(8, 0.3, 1);
    let n = m.vertex_count();
    let (omega, zeta) = plane_wave(&m, [9.0, -4.0, 0.0]);
    let cwf = Cwf::new(m.clone(), omega.clone(), vec![1.0; n], zeta).unwrap();
    let (ec, eu) = (cwf.compatibility_energy(), cwf.unit_energy());
    println!("compatible plane wave: E_compat = {ec:.2e}, E_unit = {eu:.2e}");
    assert!(ec < 1e-26 && eu < 1e-26);
    let d = cwf.decompose_omega();
    let max_res = d.residual.iter().map(|r| r.abs()).fold(0.0, f64::max);
    println!("compatible plane wave: max |δω| = {max_res:.2e}");
    assert!(max_res < 1e-13);

    // unit but incompatible: E_unit = 0, E_compat > 0, δω in [−π, π) and ω_com compatible
    let mut rng = Rng::new(3);
    let zeta: Vec<Complex> = (0..n).map(|_| Complex::cis(rng.range(-3.0, 3.0))).collect();
    let cwf = Cwf::new(m, omega, vec![0.5; n], zeta.clone()).unwrap();
    assert!(cwf.unit_energy() < 1e-26);
    assert!(cwf.compatibility_energy() > 1e-3);
    let d = cwf.decompose_omega();
    assert!(d
        .residual
        .iter()
        .all(|r| (-std::f64::consts::PI..std::f64::consts::PI).contains(r)));
    let fixed = Cwf::new(cwf.base().clone(), d.compatible, vec![0.5; n], zeta).unwrap();
    println!(
        "after ω ← ω_com: E_compat = {:.2e}",
        fixed.compatibility_energy()
    );
    assert!(fixed.compatibility_energy() < 1e-24);
}

/// max over vertices of |arg(z̃_j · conj(e^{ik·x_j}) · conj(g))| for the best global phase g.
fn global_phase_error(z: &[Complex], m: &TriMesh, k: [f64; 3]) -> f64 {
    let r: Vec<Complex> = z
        .iter()
        .zip(m.positions())
        .map(|(z, p)| *z * Complex::cis(-(k[0] * p[0] + k[1] * p[1] + k[2] * p[2])))
        .collect();
    let mut g = Complex::ZERO;
    for c in &r {
        g += *c;
    }
    let g = g.scale(1.0 / g.abs());
    r.iter()
        .map(|c| (*c * g.conj()).arg().abs())
        .fold(0.0, f64::max)
}

#[test]
fn knoppel_recovers_plane_waves() {
    let cases: Vec<(&str, TriMesh, [f64; 3])> = vec![
        ("grid", irregular_grid(12, 0.3, 2), [20.0, 7.0, 0.0]),
        (
            "tilted grid",
            tilt(&irregular_grid(10, 0.3, 4)),
            [0.0, 0.0, 0.0],
        ),
        (
            "grid high freq",
            irregular_grid(10, 0.25, 8),
            [150.0, -60.0, 0.0],
        ),
    ];
    for (name, m, k) in cases {
        let k = if name == "tilted grid" {
            let p = m.positions();
            let ex = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
            let l = (ex[0] * ex[0] + ex[1] * ex[1] + ex[2] * ex[2]).sqrt();
            [15.0 * ex[0] / l, 15.0 * ex[1] / l, 15.0 * ex[2] / l]
        } else {
            k
        };
        for weights in [PhaseWeights::Cotan, PhaseWeights::EdgeArea] {
            let n = m.vertex_count();
            let opts = KnoppelOptions {
                weights,
                ..Default::default()
            };
            let kv = vec![k; n];
            let (cwf, rep) = Cwf::from_frequency_field(
                m.clone(),
                FrequencyField::PerVertex(&kv),
                vec![1.0; n],
                &opts,
            )
            .unwrap();
            let err = global_phase_error(cwf.zeta(), &m, k);
            println!(
                "knoppel {name:14} {weights:?}: phase error up to a global phase {err:.2e}, \
                 λ = {:.1e}, {} iterations, residual {:.1e}, {:.1} ms, E_compat {:.1e}",
                rep.eigenvalue,
                rep.iterations,
                rep.residual,
                1e3 * rep.total_seconds(),
                cwf.compatibility_energy()
            );
            assert!(err < 1e-8, "{err}");
        }
    }
}

#[test]
fn knoppel_on_a_closed_surface_with_singularities() {
    // a swirl around the z axis is not integrable on the sphere (its circulation around a
    // latitude is not a multiple of 2π): singularities must appear; the result must be finite
    // and unit (or zero) per vertex
    let m = icosphere(3);
    let n = m.vertex_count();
    let kv: Vec<[f64; 3]> = m
        .positions()
        .iter()
        .map(|p| [-8.0 * p[1], 8.0 * p[0], 0.0])
        .collect();
    let (cwf, rep) = Cwf::from_frequency_field(
        m,
        FrequencyField::PerVertex(&kv),
        vec![1.0; n],
        &KnoppelOptions::default(),
    )
    .unwrap();
    println!(
        "knoppel sphere: λ = {:.3}, {} iterations, residual {:.1e}",
        rep.eigenvalue, rep.iterations, rep.residual
    );
    assert!(cwf
        .zeta()
        .iter()
        .all(|z| z.is_finite() && (z.abs() == 0.0 || (z.abs() - 1.0).abs() < 1e-12)));
    assert!(rep.eigenvalue > 0.0);
}

#[test]
fn per_face_frequency_matches_per_vertex_for_constant_fields() {
    let m = irregular_grid(4, 0.3, 9);
    let k = [3.0, 1.0, 0.0];
    let a = pleat::wrinkle::one_form_from_vectors(
        &m,
        FrequencyField::PerVertex(&vec![k; m.vertex_count()]),
    )
    .unwrap();
    let b = pleat::wrinkle::one_form_from_vectors(
        &m,
        FrequencyField::PerFace(&vec![k; m.triangle_count()]),
    )
    .unwrap();
    let (w, _) = plane_wave(&m, k);
    for i in 0..a.len() {
        assert!((a[i] - w[i]).abs() < 1e-14 && (b[i] - w[i]).abs() < 1e-14);
    }
}

#[test]
fn file_round_trip_is_bit_exact() {
    let m = torus(9, 7, 1);
    let n = m.vertex_count();
    let mut rng = Rng::new(17);
    let omega: Vec<f64> = (0..m.edges().len())
        .map(|_| rng.range(-50.0, 50.0) * rng.uniform().powi(7))
        .collect();
    let amp: Vec<f64> = (0..n).map(|_| rng.uniform() / 3.0).collect();
    let zeta: Vec<Complex> = (0..n)
        .map(|_| Complex::new(rng.range(-1.0, 1.0), -rng.uniform() * 1e-300))
        .collect();
    let cwf = Cwf::new(m.clone(), omega, amp, zeta).unwrap();
    let dir = std::env::temp_dir().join(format!("pleat-wrinkle-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("torus.cwf");
    write_cwf(&path, &cwf).unwrap();
    let back = read_cwf(&path, m.clone()).unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(back.omega()), bits(cwf.omega()));
    assert_eq!(bits(back.amplitude()), bits(cwf.amplitude()));
    for (a, b) in back.zeta().iter().zip(cwf.zeta()) {
        assert_eq!(
            (a.re.to_bits(), a.im.to_bits()),
            (b.re.to_bits(), b.im.to_bits())
        );
    }
    let text = cwf_to_string(&cwf);
    println!(
        "torus .cwf: {} bytes, header:\n{}",
        text.len(),
        text.lines().take(5).collect::<Vec<_>>().join("\n")
    );

    // another mesh with the same counts but other connectivity → clear error
    let mut t = m.triangles().to_vec();
    t.swap(0, 1);
    let other = TriMesh::new(m.positions().to_vec(), t).unwrap();
    let err = read_cwf(&path, other).unwrap_err();
    println!("mismatched base: {err}");
    assert!(
        matches!(err, Error::InvalidArgument(_)) && err.to_string().contains("connectivity hash")
    );
    let err = parse_cwf(
        &text.replace("pleat-cwf 1", "pleat-cwf 7"),
        m.clone(),
        "x.cwf",
    )
    .unwrap_err();
    assert!(err.to_string().contains("version 7"), "{err}");
    let cut: String = text.lines().take(20).collect::<Vec<_>>().join("\n");
    let err = parse_cwf(&cut, m, "x.cwf").unwrap_err();
    assert!(err.to_string().contains("end of file"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn validation_errors_are_clear() {
    let m = irregular_grid(2, 0.0, 1);
    let (n, ne) = (m.vertex_count(), m.edges().len());
    let ok = || (vec![0.0; ne], vec![1.0; n], vec![Complex::ONE; n]);
    let (w, a, z) = ok();
    assert!(Cwf::new(m.clone(), w[1..].to_vec(), a, z)
        .unwrap_err()
        .to_string()
        .contains("omega"));
    let (mut w, a, z) = ok();
    w[3] = f64::NAN;
    assert!(Cwf::new(m.clone(), w, a, z)
        .unwrap_err()
        .to_string()
        .contains("NaN"));
    let (w, mut a, z) = ok();
    a[2] = -1.0;
    assert!(Cwf::new(m.clone(), w, a, z)
        .unwrap_err()
        .to_string()
        .contains("negative"));
    // non-manifold: a third triangle on an interior edge
    let mut p = m.positions().to_vec();
    p.push([0.5, 0.5, 1.0]);
    let mut t = m.triangles().to_vec();
    let el = m.edges();
    let mut count = vec![0; el.len()];
    el.face_edges
        .iter()
        .flatten()
        .for_each(|&e| count[e as usize] += 1);
    let [a0, b0] = el.edges[count.iter().position(|&c| c == 2).unwrap()].0;
    t.push([a0, b0, (p.len() - 1) as u32]);
    let nm = TriMesh::new(p, t).unwrap();
    let ne = nm.edges().len();
    let err = Cwf::new(
        nm,
        vec![0.0; ne],
        vec![1.0; n + 1],
        vec![Complex::ONE; n + 1],
    )
    .unwrap_err();
    println!("non-manifold base: {err}");
    assert!(matches!(err, Error::InvalidMesh(_)) && err.to_string().contains("non-manifold"));
}

#[test]
fn knoppel_solves_each_component() {
    // two separate grids: one with a compatible plane wave, one with a non-integrable swirl;
    // both must come out unit (the compatible one exactly the plane wave up to a phase)
    let a = irregular_grid(8, 0.3, 1);
    let b = irregular_grid(8, 0.3, 2);
    let na = a.vertex_count() as u32;
    let mut p = a.positions().to_vec();
    p.extend(b.positions().iter().map(|q| [q[0] + 3.0, q[1], q[2]]));
    let mut t = a.triangles().to_vec();
    t.extend(b.triangles().iter().map(|f| f.map(|v| v + na)));
    let m = TriMesh::new(p, t).unwrap();
    let k = [11.0, 4.0, 0.0];
    let kv: Vec<[f64; 3]> = m
        .positions()
        .iter()
        .map(|q| {
            if q[0] < 2.0 {
                k
            } else {
                [-30.0 * (q[1] - 0.5), 30.0 * (q[0] - 3.5), 0.0]
            }
        })
        .collect();
    let n = m.vertex_count();
    let (cwf, rep) = Cwf::from_frequency_field(
        m.clone(),
        FrequencyField::PerVertex(&kv),
        vec![1.0; n],
        &KnoppelOptions::default(),
    )
    .unwrap();
    let zs = cwf.zeta();
    let units = zs.iter().filter(|z| (z.abs() - 1.0).abs() < 1e-12).count();
    let first: Vec<Complex> = zs[..na as usize].to_vec();
    let ma = TriMesh::new(
        m.positions()[..na as usize].to_vec(),
        a.triangles().to_vec(),
    )
    .unwrap();
    let err = global_phase_error(&first, &ma, k);
    println!("knoppel two components: {units}/{n} unit, plane-wave component error {err:.1e}, λ_max = {:.2}", rep.eigenvalue);
    assert!(units >= n - 2 && err < 1e-8);
}
