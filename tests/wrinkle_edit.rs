//! Wrinkle design and editing (dissertation §3.6; checks of `specs/cwf-design.md`):
//! fixed bits, identity and global edits of plane waves, interface quality, amplitude bounds,
//! bad input, design from sources, and edit → interpolate → evaluate end to end.

#![cfg(feature = "wrinkle")]

mod wrinkle_common;

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

use pleat::mesh::TriMesh;
use pleat::wrinkle::{
    design, edit, grow_faces, interpolate, Adjacency, Complex, Cwf, DesignOptions, EditOptions,
    EvalOptions, FaceClass, FrequencyField, InterpOptions, KnoppelOptions, PhaseCoupling,
    RegionEdit, WrinkleSource,
};
use wrinkle_common::{irregular_grid, Rng};

const K: [f64; 3] = [
    4.0 * std::f64::consts::TAU,
    1.5 * std::f64::consts::TAU,
    0.0,
];

fn plane_wave(base: TriMesh, k: [f64; 3], a: f64) -> Cwf {
    let n = base.vertex_count();
    Cwf::from_frequency_field(
        base,
        FrequencyField::PerVertex(&vec![k; n]),
        vec![a; n],
        &KnoppelOptions::default(),
    )
    .unwrap()
    .0
}

/// The vertex nearest to `p`.
fn nearest(m: &TriMesh, p: [f64; 2]) -> u32 {
    let d = |q: &[f64; 3]| (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
    (0..m.vertex_count() as u32)
        .min_by(|&a, &b| d(&m.positions()[a as usize]).total_cmp(&d(&m.positions()[b as usize])))
        .unwrap()
}

fn disk_region(m: &TriMesh, centre: [f64; 2], rings: usize) -> Vec<u32> {
    grow_faces(m, &[], &[nearest(m, centre)], rings, Adjacency::Vertex).unwrap()
}

fn rot_z(k: [f64; 3], theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [c * k[0] - s * k[1], s * k[0] + c * k[1], k[2]]
}

fn edge_vec(m: &TriMesh, e: [u32; 2]) -> [f64; 3] {
    let (a, b) = (m.positions()[e[0] as usize], m.positions()[e[1] as usize]);
    [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Edge classes from face classes (edit > fixed > interface).
fn edge_classes(cwf: &Cwf, face_class: &[FaceClass]) -> Vec<FaceClass> {
    let el = cwf.base().edges();
    let mut cls = vec![FaceClass::Interface; cwf.edges().len()];
    let mut has = vec![[false; 3]; cwf.edges().len()];
    for (f, fe) in el.face_edges.iter().enumerate() {
        for &e in fe {
            has[e as usize][face_class[f] as usize] = true;
        }
    }
    for (e, h) in has.iter().enumerate() {
        cls[e] = if h[1] {
            FaceClass::Edit
        } else if h[0] {
            FaceClass::Fixed
        } else {
            FaceClass::Interface
        };
    }
    cls
}

fn vertex_fixed(cwf: &Cwf, face_class: &[FaceClass]) -> Vec<bool> {
    let n = cwf.base().vertex_count();
    let mut fixed = vec![false; n];
    let mut non_fixed = vec![false; n];
    for (f, t) in cwf.base().triangles().iter().enumerate() {
        for &v in t {
            if face_class[f] == FaceClass::Fixed {
                fixed[v as usize] = true;
            } else {
                non_fixed[v as usize] = true;
            }
        }
    }
    (0..n).map(|j| fixed[j] || !non_fixed[j]).collect()
}

// ---------------------------------------------------------------------------------------------
// C1: fixed region bit for bit

#[test]
fn fixed_region_is_copied_bit_for_bit() {
    let mut rng = Rng::new(7);
    for seed in 0..4u64 {
        let m = irregular_grid(24, 0.25, seed);
        let cwf = plane_wave(m.clone(), K, 0.01);
        let centre = [rng.range(0.3, 0.7), rng.range(0.3, 0.7)];
        let mut r = RegionEdit::new(disk_region(&m, centre, 3));
        r.rotate = rng.range(-3.0, 3.0);
        r.frequency_scale = rng.range(0.5, 3.0);
        r.amplitude_scale = rng.range(0.2, 2.0);
        for opts in [EditOptions::default(), EditOptions::reference()] {
            let (out, rep) = edit(&cwf, std::slice::from_ref(&r), &opts).unwrap();
            let ec = edge_classes(&cwf, &rep.face_class);
            for (e, &c) in ec.iter().enumerate() {
                if c == FaceClass::Fixed {
                    assert_eq!(
                        out.omega()[e].to_bits(),
                        cwf.omega()[e].to_bits(),
                        "edge {e}"
                    );
                }
            }
            let vf = vertex_fixed(&cwf, &rep.face_class);
            for (j, &fixed) in vf.iter().enumerate() {
                if fixed {
                    assert_eq!(out.amplitude()[j].to_bits(), cwf.amplitude()[j].to_bits());
                    assert_eq!(out.zeta()[j].re.to_bits(), cwf.zeta()[j].re.to_bits());
                    assert_eq!(out.zeta()[j].im.to_bits(), cwf.zeta()[j].im.to_bits());
                }
            }
            assert!(
                rep.face_counts.iter().all(|&c| c > 0),
                "{:?}",
                rep.face_counts
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// C2: plane wave, flat grid: edit edges rotate exactly; scaling; identity copies ω bits

#[test]
fn local_rotation_of_a_plane_wave_rotates_edit_edges_exactly() {
    let m = irregular_grid(24, 0.25, 3);
    let cwf = plane_wave(m.clone(), K, 0.01);
    let mut r = RegionEdit::new(disk_region(&m, [0.5, 0.5], 3));
    r.rotate = FRAC_PI_2;
    r.frequency_scale = 2.0;
    let (out, rep) = edit(&cwf, &[r], &EditOptions::default()).unwrap();
    let ec = edge_classes(&cwf, &rep.face_class);
    let kr = rot_z(K, FRAC_PI_2).map(|c| 2.0 * c);
    let h = 1.0 / 24.0;
    let knorm = dot(K, K).sqrt();
    for (e, &edge) in cwf.edges().iter().enumerate() {
        if ec[e] == FaceClass::Edit {
            let want = dot(kr, edge_vec(&m, edge));
            assert!(
                (out.omega()[e] - want).abs() <= 1e-12 * knorm * h * 4.0,
                "edge {e}: {} vs {want}",
                out.omega()[e]
            );
        }
    }
    assert!(rep.omega_residual < 1e-10, "{rep:?}");
    assert!(rep.amplitude_residual < 1e-10, "{rep:?}");
}

#[test]
fn identity_edit_returns_the_input() {
    let m = irregular_grid(24, 0.25, 5);
    let cwf = plane_wave(m.clone(), K, 0.01);
    let regions = [
        RegionEdit::new(disk_region(&m, [0.35, 0.35], 2)),
        RegionEdit::new(disk_region(&m, [0.68, 0.62], 2)),
    ];
    let (out, rep) = edit(&cwf, &regions, &EditOptions::default()).unwrap();
    let ec = edge_classes(&cwf, &rep.face_class);
    for (e, &c) in ec.iter().enumerate() {
        if c == FaceClass::Edit {
            assert_eq!(out.omega()[e].to_bits(), cwf.omega()[e].to_bits());
        }
        assert!((out.omega()[e] - cwf.omega()[e]).abs() < 1e-12, "edge {e}");
    }
    for j in 0..m.vertex_count() {
        assert!(
            (out.amplitude()[j] - cwf.amplitude()[j]).abs() < 1e-12,
            "a[{j}]"
        );
        let d = out.zeta()[j] - cwf.zeta()[j];
        assert!(
            d.abs() < 1e-9,
            "z[{j}] {:?} vs {:?}",
            out.zeta()[j],
            cwf.zeta()[j]
        );
    }
    assert!(!rep.global && !rep.phase_fallback);
}

// ---------------------------------------------------------------------------------------------
// C4: global edits

#[test]
fn global_rotation_and_scale_give_the_transformed_plane_wave() {
    let m = irregular_grid(16, 0.25, 9);
    let cwf = plane_wave(m.clone(), K, 0.02);
    let all: Vec<u32> = (0..m.triangle_count() as u32).collect();
    for (theta, sigma) in [(FRAC_PI_2, 1.0), (FRAC_PI_4, 1.0), (0.0, 2.0), (0.3, 0.5)] {
        let mut r = RegionEdit::new(all.clone());
        r.interface_rings = 0;
        r.rotate = theta;
        r.frequency_scale = sigma;
        let r = r.coupled();
        let (out, rep) = edit(&cwf, &[r], &EditOptions::default()).unwrap();
        assert!(rep.global);
        let k1 = rot_z(K, theta).map(|c| sigma * c);
        for (e, &edge) in cwf.edges().iter().enumerate() {
            let want = dot(k1, edge_vec(&m, edge));
            assert!(
                (out.omega()[e] - want).abs() < 1e-12,
                "θ {theta} σ {sigma} edge {e}"
            );
        }
        for j in 0..m.vertex_count() {
            assert!((out.amplitude()[j] - 0.02 / sigma).abs() < 1e-15);
        }
        // z̃ = e^{iφ} e^{i k1·x}
        let p = m.positions();
        let phase = |j: usize| Complex::cis(dot(k1, p[j]));
        let g = out.zeta()[0] * phase(0).conj();
        for j in 0..m.vertex_count() {
            let d = out.zeta()[j] - g * phase(j);
            assert!(
                d.abs() < 1e-6,
                "θ {theta} σ {sigma} vertex {j}: {}",
                d.abs()
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// C5/C6: interface quality, net index

#[test]
fn local_edits_are_compatible_inside_the_region() {
    // the spec's setting: 40² grid, 4 waves across, disk r = 0.3, 3 interface rings
    let n = 40;
    let m = irregular_grid(n, 0.2, 11);
    let cwf = plane_wave(m.clone(), [4.0 * std::f64::consts::TAU, 0.0, 0.0], 0.01);
    let centre = [0.5, 0.5];
    let region: Vec<u32> = (0..m.triangle_count() as u32)
        .filter(|&f| {
            m.triangles()[f as usize].iter().all(|&v| {
                let q = m.positions()[v as usize];
                (q[0] - centre[0]).hypot(q[1] - centre[1]) < 0.3
            })
        })
        .collect();
    for (theta, sigma) in [(FRAC_PI_2, 1.0), (0.0, 2.0)] {
        let mut r = RegionEdit::new(region.clone());
        r.rotate = theta;
        r.frequency_scale = sigma;
        let (out, rep) = edit(&cwf, &[r], &EditOptions::default()).unwrap();
        let dec = out.decompose_omega();
        let ec = edge_classes(&cwf, &rep.face_class);
        let (mut sum, mut cnt) = (0.0, 0);
        for (e, &[a, b]) in out.edges().iter().enumerate() {
            let (pa, pb) = (m.positions()[a as usize], m.positions()[b as usize]);
            let mid = [(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0];
            if ec[e] == FaceClass::Edit && (mid[0] - 0.5).hypot(mid[1] - 0.5) < 0.2 {
                sum += dec.residual[e].powi(2);
                cnt += 1;
            }
        }
        let rms = (sum / cnt as f64).sqrt();
        eprintln!(
            "θ {theta} σ {sigma}: inner RMS {rms:.3} rad, report {rep:?}",
            rep = (rep.compat_rms, rep.eigenvalue, rep.seconds)
        );
        assert!(rms <= 0.3, "θ {theta} σ {sigma}: RMS {rms}");
        // net singularity index over the edited area is unchanged (the region is interior)
        let idx = |c: &Cwf| -> i64 {
            let d = c.decompose_omega();
            let curls = face_curls(c, &d.compatible);
            rep.face_class
                .iter()
                .enumerate()
                .filter(|(_, &k)| k != FaceClass::Fixed)
                .map(|(f, _)| (curls[f] / std::f64::consts::TAU).round() as i64)
                .sum()
        };
        assert_eq!(idx(&out), idx(&cwf), "θ {theta} σ {sigma}");
    }
}

fn face_curls(c: &Cwf, omega: &[f64]) -> Vec<f64> {
    let el = c.base().edges();
    c.base()
        .triangles()
        .iter()
        .enumerate()
        .map(|(f, t)| {
            (0..3)
                .map(|i| {
                    let e = el.face_edges[f][i] as usize;
                    if c.edges()[e][0] == t[i] {
                        omega[e]
                    } else {
                        -omega[e]
                    }
                })
                .sum()
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// C7: amplitude bounds (maximum principle)

#[test]
fn interface_amplitude_obeys_the_maximum_principle() {
    let m = irregular_grid(24, 0.0, 2); // right triangles: non-obtuse
    let cwf = plane_wave(m.clone(), K, 0.01);
    for (theta, sigma, mu) in [
        (FRAC_PI_2, 1.0, 1.0),
        (0.0, 3.0, 1.0 / 3.0),
        (0.5, 1.0, 2.5),
    ] {
        let mut r = RegionEdit::new(disk_region(&m, [0.5, 0.5], 3));
        r.rotate = theta;
        r.frequency_scale = sigma;
        r.amplitude_scale = mu;
        let (out, _) = edit(&cwf, &[r], &EditOptions::default()).unwrap();
        let hi = 0.01f64.max(0.01 * mu) * (1.0 + 1e-12);
        for (j, &a) in out.amplitude().iter().enumerate() {
            assert!((0.0..=hi).contains(&a), "vertex {j}: {a} > {hi}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// C12: bad input

#[test]
fn bad_input_is_refused_with_a_message() {
    let m = irregular_grid(12, 0.2, 1);
    let cwf = plane_wave(m.clone(), K, 0.01);
    let region = disk_region(&m, [0.5, 0.5], 2);
    let mut r = RegionEdit::new(region.clone());
    r.frequency_scale = 0.0;
    let e = edit(&cwf, &[r.clone()], &EditOptions::default()).unwrap_err();
    assert!(e.to_string().contains("frequency scale"), "{e}");
    r.frequency_scale = -2.0;
    assert!(edit(&cwf, &[r.clone()], &EditOptions::default()).is_err());
    r.frequency_scale = 1.0;
    r.rotate = f64::NAN;
    assert!(edit(&cwf, &[r], &EditOptions::default()).is_err());
    let e = edit(&cwf, &[RegionEdit::new(vec![])], &EditOptions::default()).unwrap_err();
    assert!(e.to_string().contains("empty"), "{e}");
    let e = edit(
        &cwf,
        &[RegionEdit::new(vec![100_000])],
        &EditOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("100000"), "{e}");
    let e = edit(
        &cwf,
        &[
            RegionEdit::new(region.clone()),
            RegionEdit::new(region.clone()),
        ],
        &EditOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("overlap"), "{e}");
    let mut thin = RegionEdit::new(region);
    thin.interface_rings = 0;
    let e = edit(&cwf, &[thin], &EditOptions::default()).unwrap_err();
    assert!(e.to_string().contains("vertex"), "{e}");

    let src = |k: [f64; 3]| WrinkleSource {
        vertex: nearest(&m, [0.5, 0.5]),
        wave_vector: k,
        amplitude: 0.01,
        rings: 3,
    };
    let e = design(
        m.clone(),
        &[src([f64::NAN, 0.0, 0.0])],
        &DesignOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("source 0"), "{e}");
    let mut s = src(K);
    s.vertex = 9999;
    let e = design(m.clone(), &[s], &DesignOptions::default()).unwrap_err();
    assert!(e.to_string().contains("9999"), "{e}");
    assert!(design(m.clone(), &[], &DesignOptions::default()).is_err());
    // non-manifold base: three triangles on one edge
    let p = vec![
        [0.; 3],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., -1., 0.],
        [0., 0., 1.],
    ];
    let bad = TriMesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap();
    let mut s = src(K);
    s.vertex = 0;
    let e = design(bad, &[s], &DesignOptions::default()).unwrap_err();
    assert!(e.to_string().contains("non-manifold"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// C11: design

#[test]
fn design_on_a_flat_grid_reproduces_the_wave_vector_and_zeros_outside() {
    let m = irregular_grid(20, 0.0, 4);
    let v = nearest(&m, [0.5, 0.5]);
    let src = WrinkleSource {
        vertex: v,
        wave_vector: K,
        amplitude: 0.02,
        rings: 4,
    };
    let (cwf, rep) = design(m.clone(), &[src], &DesignOptions::default()).unwrap();
    let region = grow_faces(&m, &[], &[v], 4, Adjacency::Vertex).unwrap();
    let mut in_f = vec![false; m.triangle_count()];
    region.iter().for_each(|&f| in_f[f as usize] = true);
    let fc: Vec<FaceClass> = in_f
        .iter()
        .map(|&b| if b { FaceClass::Edit } else { FaceClass::Fixed })
        .collect();
    let ec = edge_classes(&cwf, &fc);
    let vf = vertex_fixed(&cwf, &fc);
    for (e, &edge) in cwf.edges().iter().enumerate() {
        if ec[e] == FaceClass::Edit {
            let want = dot(K, edge_vec(&m, edge));
            assert!((cwf.omega()[e] - want).abs() < 1e-12, "edge {e}");
        } else {
            assert_eq!(cwf.omega()[e].to_bits(), 0f64.to_bits());
        }
    }
    let mut in_v = vec![false; m.vertex_count()];
    for &f in &region {
        m.triangles()[f as usize]
            .iter()
            .for_each(|&v| in_v[v as usize] = true);
    }
    for (j, &inside) in in_v.iter().enumerate() {
        let a = cwf.amplitude()[j];
        if !inside {
            assert_eq!(
                a.to_bits(),
                0f64.to_bits(),
                "vertex {j} outside has a = {a}"
            );
        }
        assert!((0.0..=0.02 * (1.0 + 1e-12)).contains(&a), "vertex {j}: {a}");
    }
    assert!(vf.iter().any(|&b| b));
    assert_eq!(cwf.amplitude()[v as usize], 0.02);
    assert_eq!(rep.influenced[1], region.len());
    assert!(
        rep.amplitude_residual < 1e-10 && rep.heat_residual < 1e-10,
        "{rep:?}"
    );
}

#[test]
fn symmetric_sources_give_a_symmetric_amplitude() {
    let n = 20;
    let m = irregular_grid(n, 0.0, 0);
    // make the diagonals point-symmetric: regenerate with a fixed diagonal direction
    let p = m.positions().to_vec();
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let m = TriMesh::new(p, t).unwrap();
    let (a, b) = (id(6, 8), id(n - 6, n - 8));
    let s = |v| WrinkleSource {
        vertex: v,
        wave_vector: K,
        amplitude: 0.01,
        rings: 4,
    };
    let (cwf, _) = design(m.clone(), &[s(a), s(b)], &DesignOptions::default()).unwrap();
    for j in 0..=n {
        for i in 0..=n {
            let (p, q) = (id(i, j) as usize, id(n - i, n - j) as usize);
            let (x, y) = (cwf.amplitude()[p], cwf.amplitude()[q]);
            assert!((x - y).abs() < 1e-12, "({i}, {j}): {x} vs {y}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// C10: edit → interpolate → evaluate

#[test]
fn edited_keyframe_animates_and_evaluates() {
    let m = irregular_grid(14, 0.2, 6);
    let cwf = plane_wave(m.clone(), [12.0, 0.0, 0.0], 0.01);
    let mut r = RegionEdit::new(disk_region(&m, [0.5, 0.5], 2));
    r.rotate = FRAC_PI_2;
    r.interface_rings = 2;
    for phase in [PhaseCoupling::Unit, PhaseCoupling::AmplitudeWeighted] {
        let opts = EditOptions {
            phase,
            ..EditOptions::default()
        };
        let (k1, _) = edit(&cwf, std::slice::from_ref(&r), &opts).unwrap();
        let iopts = InterpOptions {
            guide_frames: 8,
            ..InterpOptions::default()
        };
        let (anim, _) = interpolate(&cwf, &k1, &iopts).unwrap();
        let first = anim.frame(0).unwrap();
        let last = anim.frame(anim.frame_count() - 1).unwrap();
        assert_eq!(first.omega(), cwf.omega());
        assert_eq!(last.omega(), k1.omega());
        let mid = anim.frame_at(0.5).unwrap();
        let (ev, _) = mid.evaluate(2, &EvalOptions::default()).unwrap();
        assert_eq!(ev.mesh.triangle_count(), 16 * m.triangle_count());
        assert!(ev.mesh.positions().iter().flatten().all(|c| c.is_finite()));
    }
}

/// Largest `|z̃(t) − z̃⁰|`, `|a(t) − a⁰|` and `|ω(t) − ω⁰|` over the animation's frames, on the
/// vertices `far` and on the edges between two of them.
fn fixed_drift(anim: &pleat::wrinkle::CwfAnimation, k0: &Cwf, far: &[usize]) -> [f64; 3] {
    let mut is_far = vec![false; k0.base().vertex_count()];
    far.iter().for_each(|&v| is_far[v] = true);
    let mut d = [0.0f64; 3];
    for i in 0..anim.frame_count() {
        let f = anim.frame(i).unwrap();
        for &v in far {
            d[0] = d[0].max((f.zeta()[v] - k0.zeta()[v]).abs());
            d[1] = d[1].max((f.amplitude()[v] - k0.amplitude()[v]).abs());
        }
        for (e, &[a, b]) in k0.edges().iter().enumerate() {
            if is_far[a as usize] && is_far[b as usize] {
                d[2] = d[2].max((f.omega()[e] - k0.omega()[e]).abs());
            }
        }
    }
    d
}

/// C10 locality: interpolating a plane wave towards a local edit of it leaves the fixed region
/// alone. With `InterpOptions::locality` (default) the vertices whose star the edit did not touch
/// are held, so on every frame `z̃` there equals `z̃⁰` up to the linear sub-step blend's round-off
/// (`(1−s)z + s z`: a few ulp, bounded by 1e-15), `a` likewise, and `ω` on edges between them to
/// the explicit path's round-off (1e-12 of |ω|). Without it (the literal eq. 3.12) the far
/// phases drift (measured here, and asserted to be visible so the test cannot pass vacuously).
#[test]
fn local_edit_animation_keeps_the_fixed_region_still() {
    let m = irregular_grid(16, 0.2, 11);
    let k0 = plane_wave(m.clone(), [12.0, 0.0, 0.0], 0.01);
    let mut r = RegionEdit::new(disk_region(&m, [0.5, 0.5], 2));
    r.rotate = FRAC_PI_2;
    r.interface_rings = 2;
    // the requested 2 rings exactly: the default adaptive width would widen the band of this
    // small grid's 12-per-unit wave into most of the fixed region this test watches
    let exact = EditOptions {
        compat_target: 0.0,
        ..EditOptions::default()
    };
    let (k1, rep) = edit(&k0, &[r], &exact).unwrap();
    let far = far_fixed_vertices(&k0, &rep.face_class, 2);
    assert!(far.len() > 50, "only {} far fixed vertices", far.len());
    let pinned = pleat::wrinkle::unchanged_vertices(&k0, &k1);
    assert!(
        far.iter().all(|&v| pinned[v]),
        "a far fixed vertex is not pinned"
    );
    let mut drift_off = 0.0;
    for locality in [true, false] {
        let iopts = InterpOptions {
            guide_frames: 10,
            substeps: 3,
            locality,
            ..InterpOptions::default()
        };
        let (anim, irep) = interpolate(&k0, &k1, &iopts).unwrap();
        let d = fixed_drift(&anim, &k0, &far);
        eprintln!(
            "locality {locality}: {} pinned, stop {:?}, max drift |Δz̃| {:.2e}, |Δa| {:.2e}, |Δω| {:.2e}",
            irep.pinned_vertices, irep.stop, d[0], d[1], d[2]
        );
        let last = anim.frame(anim.frame_count() - 1).unwrap();
        assert_eq!(
            last.zeta(),
            k1.zeta(),
            "the animation ends on the edited keyframe"
        );
        if locality {
            assert_eq!(irep.pinned_vertices, pinned.iter().filter(|&&p| p).count());
            assert!(d[0] <= 1e-15, "fixed phase drifts by {:e}", d[0]);
            assert!(d[1] <= 1e-15 * 0.01, "fixed amplitude drifts by {:e}", d[1]);
            assert!(d[2] <= 1e-12 * 12.0, "fixed ω drifts by {:e}", d[2]);
        } else {
            assert_eq!(irep.pinned_vertices, 0);
            drift_off = d[0];
        }
    }
    assert!(
        drift_off > 1e-6,
        "without locality the far phase should move ({drift_off:e})"
    );
}

// ---------------------------------------------------------------------------------------------
// corpus meshes (skipped without ../shared/meshes)

/// A mesh of the shared corpus: `$PLEAT_MESHES`, `../shared/meshes` from the crate root or
/// `../../shared/meshes` (a worktree); `None` (the test skips) when absent.
fn corpus_mesh(name: &str) -> Option<TriMesh> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = [
        std::env::var_os("PLEAT_MESHES").map(std::path::PathBuf::from),
        Some(root.join("../shared/meshes")),
        Some(root.join("../../shared/meshes")),
    ]
    .into_iter()
    .flatten()
    .find(|d| d.join(name).is_file());
    match dir {
        Some(d) => Some(pleat::mesh::io::read_mesh(&d.join(name)).unwrap()),
        None => {
            eprintln!("skipping: {name} not found (../shared/meshes)");
            None
        }
    }
}

/// The exactly compatible plane wave `e^{i k·x}` (ω = k·e on every edge), as `pleat wrinkle
/// plane-wave` builds it.
fn exact_plane_wave(base: TriMesh, k: [f64; 3], a: f64) -> Cwf {
    let x = base.positions().to_vec();
    let omega = base
        .edges()
        .edges
        .iter()
        .map(|e| dot(k, x[e.0[1] as usize]) - dot(k, x[e.0[0] as usize]))
        .collect();
    let zeta = x.iter().map(|p| Complex::cis(dot(k, *p))).collect();
    let n = base.vertex_count();
    Cwf::new(base, omega, vec![a; n], zeta).unwrap()
}

/// The demo script's corpus edits (`examples_c/wrinkle_edit_demo.sh`): name, mesh, wave
/// vector, regions `(seed vertex, rings, interface, rotate, σ, coupled)`, reference options.
#[allow(clippy::type_complexity)]
fn corpus_edits() -> Vec<(
    &'static str,
    &'static str,
    [f64; 3],
    Vec<(u32, usize, usize, f64, f64, bool)>,
    bool,
)> {
    vec![
        (
            "spot rot90",
            "coarse_spot_1k.obj",
            [7.0, 0.0, 0.0],
            vec![(500, 5, 3, FRAC_PI_2, 1.0, false)],
            false,
        ),
        (
            "spot ×2.5 + rot90",
            "coarse_spot_1k.obj",
            [7.0, 0.0, 0.0],
            vec![
                (500, 4, 2, 0.0, 2.5, true),
                (100, 4, 2, FRAC_PI_2, 1.0, false),
            ],
            false,
        ),
        (
            "fertility ×3 ÷3",
            "coarse_fertility_1500.obj",
            [0.06, 0.0, 0.0],
            vec![(700, 5, 3, 0.0, 3.0, true)],
            false,
        ),
        (
            "torus rot90 ref",
            "coarse_torus.obj",
            [4.0, 0.0, 0.0],
            vec![(200, 5, 3, FRAC_PI_2, 1.0, false)],
            true,
        ),
        (
            "torus rot90",
            "coarse_torus.obj",
            [4.0, 0.0, 0.0],
            vec![(200, 5, 3, FRAC_PI_2, 1.0, false)],
            false,
        ),
    ]
}

fn run_corpus_edit(
    mesh: &TriMesh,
    k: [f64; 3],
    regions: &[(u32, usize, usize, f64, f64, bool)],
    opts: &EditOptions,
) -> (Cwf, Cwf, pleat::wrinkle::EditReport) {
    let k0 = exact_plane_wave(mesh.clone(), k, 0.01);
    let edits: Vec<RegionEdit> = regions
        .iter()
        .map(|&(v, rings, inter, rot, sigma, couple)| {
            let faces = grow_faces(mesh, &[], &[v], rings, opts.adjacency).unwrap();
            let mut r = RegionEdit::new(faces);
            r.interface_rings = inter;
            r.rotate = rot;
            r.frequency_scale = sigma;
            if couple {
                r = r.coupled();
            }
            r
        })
        .collect();
    let (k1, rep) = edit(&k0, &edits, opts).unwrap();
    (k0, k1, rep)
}

/// Diagnostic (ignored): where the compatibility residual of the corpus edits comes from.
#[test]
#[ignore]
#[allow(clippy::type_complexity)]
fn corpus_compat_diagnostic() {
    for (name, file, k, regions, reference) in corpus_edits() {
        let Some(mesh) = corpus_mesh(file) else {
            return;
        };
        let mut opts = if reference {
            EditOptions::reference()
        } else {
            EditOptions::default()
        };
        if let Ok(w) = std::env::var("EDIT_WEIGHT") {
            opts.edit_weight = w.parse().unwrap();
        }
        let mut regions = regions;
        if let Ok(m) = std::env::var("INTERFACE_RINGS") {
            regions.iter_mut().for_each(|r| r.2 = m.parse().unwrap());
        }
        let (k0, k1, rep) = run_corpus_edit(&mesh, k, &regions, &opts);
        let ec = edge_classes(&k0, &rep.face_class);
        let dec = k1.decompose_omega();
        let curls = face_curls(&k1, &dec.compatible);
        let curl1 = face_curls(&k1, k1.omega());
        let el = mesh.edges();
        let mut singular_edge = vec![false; ec.len()];
        let mut n_sing = 0;
        for (f, c) in curls.iter().enumerate() {
            if (c / std::f64::consts::TAU).round() != 0.0 {
                n_sing += 1;
                for &e in &el.face_edges[f] {
                    singular_edge[e as usize] = true;
                }
            }
        }
        let amax = k1.amplitude().iter().cloned().fold(0.0, f64::max);
        let mut rows: Vec<(FaceClass, f64, f64, bool)> = vec![];
        for (e, &[a, b]) in k1.edges().iter().enumerate() {
            if ec[e] == FaceClass::Fixed {
                continue;
            }
            let am = 0.5 * (k1.amplitude()[a as usize] + k1.amplitude()[b as usize]) / amax;
            rows.push((ec[e], dec.residual[e], am, singular_edge[e]));
        }
        let rms = |f: &dyn Fn(&(FaceClass, f64, f64, bool)) -> bool| {
            let v: Vec<f64> = rows.iter().filter(|r| f(r)).map(|r| r.1 * r.1).collect();
            (
                (v.iter().sum::<f64>() / v.len().max(1) as f64).sqrt(),
                v.len(),
            )
        };
        let wrms = {
            let (s, w) = rows.iter().fold((0.0, 0.0), |(s, w), r| {
                (s + r.2 * r.2 * r.1 * r.1, w + r.2 * r.2)
            });
            (s / w).sqrt()
        };
        eprintln!(
            "   report: by class {:?}, floor {:.3}",
            rep.compat_rms_by_class, rep.compat_floor
        );
        eprintln!("== {name}: report compat_rms {:.3}, λ {:.3e}, |s| {:.3}, singular faces {n_sing}, clamped {}", rep.compat_rms, rep.eigenvalue, rep.s.abs(), rep.clamped);
        eprintln!("  all {:?}", rms(&|_| true));
        eprintln!(
            "  edit {:?}  interface {:?}",
            rms(&|r| r.0 == FaceClass::Edit),
            rms(&|r| r.0 == FaceClass::Interface)
        );
        eprintln!(
            "  non-singular {:?}  singular {:?}",
            rms(&|r| !r.3),
            rms(&|r| r.3)
        );
        for (lo, hi) in [(0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.01)] {
            eprintln!(
                "  a/amax in [{lo}, {hi}) {:?}",
                rms(&|r| r.2 >= lo && r.2 < hi)
            );
        }
        eprintln!("  amplitude-weighted {wrms:.3}");
        // curl of ω¹ on edit / interface faces
        let mut cs = [(0.0, 0usize); 3];
        for (f, c) in curl1.iter().enumerate() {
            let i = rep.face_class[f] as usize;
            cs[i].0 += c * c;
            cs[i].1 += 1;
        }
        eprintln!(
            "  RMS curl ω¹ fixed {:.3} edit {:.3} interface {:.3}",
            (cs[0].0 / cs[0].1 as f64).sqrt(),
            (cs[1].0 / cs[1].1.max(1) as f64).sqrt(),
            (cs[2].0 / cs[2].1.max(1) as f64).sqrt()
        );
        // lower bound: min ‖δ‖ over non-fixed edges with curl δ = curl ω¹ on non-fixed faces
        for only_edit in [false, true] {
            let keep_e = |e: usize| {
                if only_edit {
                    ec[e] == FaceClass::Edit
                } else {
                    ec[e] != FaceClass::Fixed
                }
            };
            let nonfixed_f: Vec<usize> = (0..curl1.len())
                .filter(|&f| {
                    if only_edit {
                        rep.face_class[f] == FaceClass::Edit
                    } else {
                        rep.face_class[f] != FaceClass::Fixed
                    }
                })
                .collect();
            let sign = |f: usize, i: usize| -> f64 {
                let e = el.face_edges[f][i] as usize;
                if k1.edges()[e][0] == mesh.triangles()[f][i] {
                    1.0
                } else {
                    -1.0
                }
            };
            let dt = |y: &[f64]| -> Vec<f64> {
                let mut d = vec![0.0; ec.len()];
                for (i, &f) in nonfixed_f.iter().enumerate() {
                    for j in 0..3 {
                        let e = el.face_edges[f][j] as usize;
                        if keep_e(e) {
                            d[e] += sign(f, j) * y[i];
                        }
                    }
                }
                d
            };
            let dd = |d: &[f64]| -> Vec<f64> {
                nonfixed_f
                    .iter()
                    .map(|&f| {
                        (0..3)
                            .map(|j| sign(f, j) * d[el.face_edges[f][j] as usize])
                            .sum()
                    })
                    .collect()
            };
            let c: Vec<f64> = nonfixed_f.iter().map(|&f| curl1[f]).collect();
            let (mut y, mut r) = (vec![0.0; c.len()], c.clone());
            let mut p = r.clone();
            let mut rr: f64 = r.iter().map(|v| v * v).sum();
            for _ in 0..2000 {
                let ap = dd(&dt(&p));
                let alpha = rr / p.iter().zip(&ap).map(|(a, b)| a * b).sum::<f64>();
                y.iter_mut().zip(&p).for_each(|(a, b)| *a += alpha * b);
                r.iter_mut().zip(&ap).for_each(|(a, b)| *a -= alpha * b);
                let rn: f64 = r.iter().map(|v| v * v).sum();
                if rn < 1e-28 {
                    break;
                }
                p = r.iter().zip(&p).map(|(a, b)| a + rn / rr * b).collect();
                rr = rn;
            }
            let delta = dt(&y);
            let chk = dd(&delta);
            let err: f64 = chk
                .iter()
                .zip(&c)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt();
            let cn: f64 = c.iter().map(|v| v * v).sum::<f64>().sqrt();
            eprintln!("  CG: |Dδ − c| {err:.2e}, |c| {cn:.3}, faces {}", c.len());
            let lb: f64 = delta.iter().map(|v| v * v).sum::<f64>();
            let signed: [f64; 3] = [0, 1, 2].map(|k| {
                curl1
                    .iter()
                    .enumerate()
                    .filter(|(f, _)| rep.face_class[*f] as usize == k)
                    .map(|(_, c)| c)
                    .sum()
            });
            let ne = (0..ec.len()).filter(|&e| keep_e(e)).count();
            eprintln!("  only_edit {only_edit}: curl-forced lower bound RMS {:.3}; Σcurl ω¹ edit {:.3} interface {:.3}", (lb / ne as f64).sqrt(), signed[1], signed[2]);
        }
        // |ω| per edge in edit region (resolution)
        let om: Vec<f64> = (0..ec.len())
            .filter(|&e| ec[e] != FaceClass::Fixed)
            .map(|e| k1.omega()[e].abs())
            .collect();
        eprintln!(
            "  max |ω| {:.2}, mean {:.2}",
            om.iter().cloned().fold(0.0, f64::max),
            om.iter().sum::<f64>() / om.len() as f64
        );
    }
}

/// Singular faces of `c` (index `round(curl ω_com / 2π)` ≠ 0) among the faces `keep`: `(face,
/// index)`.
fn singular_faces(c: &Cwf, keep: &dyn Fn(usize) -> bool) -> Vec<(usize, i64)> {
    let d = c.decompose_omega();
    face_curls(c, &d.compatible)
        .iter()
        .enumerate()
        .filter(|&(f, _)| keep(f))
        .map(|(f, v)| (f, (v / std::f64::consts::TAU).round() as i64))
        .filter(|&(_, i)| i != 0)
        .collect()
}

/// Interface smoothness, C5/C8: on every edit the RMS compatibility residual over edit +
/// interface edges is ≤ 0.3 rad or within 1.5× the floor that the requested `ω¹` forces on any
/// phase without singularities (`EditReport::compat_floor`); singularities that appear come in
/// ± pairs (net index over the edited area unchanged), and the upsampled amplitude |z| vanishes
/// at each of them.
fn check_interface(name: &str, k0: &Cwf, k1: &Cwf, rep: &pleat::wrinkle::EditReport) {
    eprintln!(
        "{name}: compat RMS {:.3} (edit {:.3}, interface {:.3}), floor {:.3}",
        rep.compat_rms, rep.compat_rms_by_class[0], rep.compat_rms_by_class[1], rep.compat_floor
    );
    assert!(
        rep.compat_rms <= 0.3f64.max(1.5 * rep.compat_floor),
        "{name}: RMS {} vs floor {}",
        rep.compat_rms,
        rep.compat_floor
    );
    let edited = |f: usize| rep.face_class[f] != FaceClass::Fixed;
    let before = singular_faces(k0, &edited);
    let after = singular_faces(k1, &edited);
    let net = |s: &[(usize, i64)]| s.iter().map(|p| p.1).sum::<i64>();
    assert_eq!(net(&after), net(&before), "{name}: net index {after:?}");
    // the upsampled |z| = a|z̃| goes to 0 inside (near) every singular face
    let (ev, _) = k1
        .evaluate(
            3,
            &EvalOptions {
                displacement_scale: 0.0,
                want_z: true,
                ..EvalOptions::default()
            },
        )
        .unwrap();
    let z = ev.z.as_ref().unwrap();
    let p = ev.mesh.positions();
    let amax = k1.amplitude().iter().cloned().fold(0.0, f64::max);
    let x = k1.base().positions();
    for &(f, idx) in &after {
        let t = k1.base().triangles()[f];
        let c: [f64; 3] =
            std::array::from_fn(|i| t.iter().map(|&v| x[v as usize][i]).sum::<f64>() / 3.0);
        let r = t
            .iter()
            .map(|&v| dot(edge_vec_p(x[v as usize], c), edge_vec_p(x[v as usize], c)).sqrt())
            .fold(0.0, f64::max);
        let near = (0..p.len())
            .filter(|&i| dot(edge_vec_p(p[i], c), edge_vec_p(p[i], c)).sqrt() <= 1.5 * r)
            .map(|i| z[i].abs())
            .fold(f64::INFINITY, f64::min);
        eprintln!(
            "  singular face {f} index {idx}: min |z| nearby {:.3} max a",
            near / amax
        );
        assert!(
            near <= 0.1 * amax,
            "{name}: face {f}: |z| {near} near a singularity"
        );
    }
}

fn edge_vec_p(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
}

#[test]
fn corpus_interfaces_are_smooth_and_singularities_pair() {
    for (name, file, k, regions, reference) in corpus_edits() {
        let Some(mesh) = corpus_mesh(file) else {
            return;
        };
        let opts = if reference {
            EditOptions::reference()
        } else {
            EditOptions::default()
        };
        // the requested widths exactly (compat_target 0, as the reference)
        let exact = EditOptions {
            compat_target: 0.0,
            ..opts
        };
        let (k0, k1, rep) = run_corpus_edit(&mesh, k, &regions, &exact);
        check_interface(name, &k0, &k1, &rep);
        // with 5 interface rings (about half a wavelength of these waves) the required 0.3 rad
        // holds over edit + interface edges on spot and fertility (the torus's curl floor is
        // 0.28 there, its RMS 0.34)
        let wide: Vec<_> = regions
            .iter()
            .map(|r| (r.0, r.1, 5, r.3, r.4, r.5))
            .collect();
        let (k0, k1, rep) = run_corpus_edit(&mesh, k, &wide, &exact);
        check_interface(&format!("{name}, 5 interface rings"), &k0, &k1, &rep);
        eprintln!(
            "  interface rings used {:?} ({} edits)",
            rep.interface_rings, rep.attempts
        );
        if !file.contains("torus") {
            assert!(rep.compat_rms <= 0.3, "{name}: {}", rep.compat_rms);
        }
        if !reference {
            // the default adaptive width (EditOptions::compat_target = 0.3, from the requested
            // 3 rings) widens every band until its curl floor lets the phase meet the target
            assert_eq!(opts.compat_target, 0.3);
            let (k0, k1, rep) = run_corpus_edit(&mesh, k, &regions, &opts);
            eprintln!(
                "  adaptive: interface rings used {:?} ({} edits)",
                rep.interface_rings, rep.attempts
            );
            check_interface(&format!("{name}, adaptive width"), &k0, &k1, &rep);
            // over edit + interface edges and over the interface alone (as required)
            assert!(rep.compat_rms <= 0.3, "{name}: {}", rep.compat_rms);
            let band = rep.compat_rms_by_class[1];
            assert!(band <= 0.3, "{name}: interface-only {band}");
        }
    }
}

#[test]
fn curved_generated_interfaces_are_smooth_and_singularities_pair() {
    let m = wrinkle_common::torus(48, 24, 3);
    for (theta, sigma) in [(FRAC_PI_2, 1.0), (0.0, 3.0), (FRAC_PI_4, 2.0)] {
        let k0 = exact_plane_wave(m.clone(), [9.0, 0.0, 0.0], 0.01);
        let mut r = RegionEdit::new(grow_faces(&m, &[], &[300], 5, Adjacency::Vertex).unwrap());
        r.rotate = theta;
        r.frequency_scale = sigma;
        let (k1, rep) = edit(&k0, &[r.coupled()], &EditOptions::default()).unwrap();
        check_interface(&format!("torus θ {theta} σ {sigma}"), &k0, &k1, &rep);
    }
}

// ---------------------------------------------------------------------------------------------
// Bad input: each a clear status (exit 2 + message), nothing written — from the CLI

/// Runs the `pleat` binary; returns (exit code, stderr).
fn pleat_cli(args: &[&str]) -> (Option<i32>, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args(args)
        .output()
        .expect("run pleat");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// `m` as OBJ text.
fn obj_text(m: &TriMesh) -> String {
    let mut s = String::new();
    for p in m.positions() {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in m.triangles() {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

#[test]
fn cli_bad_input_is_refused_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("pleat-edit14-bad-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_owned();
    let base = dir.join("grid.obj");
    let m = irregular_grid(12, 0.2, 1);
    std::fs::write(&base, obj_text(&m)).unwrap();
    let a = dir.join("a.cwf");
    let (code, err) = pleat_cli(&[
        "wrinkle",
        "plane-wave",
        &s(&base),
        "--k",
        "25,0,0",
        "-o",
        &s(&a),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let centre = nearest(&m, [0.5, 0.5]).to_string();
    let out = dir.join("out.cwf");
    let edit_case = |region: &str| {
        pleat_cli(&[
            "wrinkle",
            "edit",
            &s(&base),
            "--cwf",
            &s(&a),
            "--region",
            region,
            "-o",
            &s(&out),
        ])
    };
    let v = format!("vertex={centre},rings=2,interface=2");
    let cases: Vec<(String, &str)> = vec![
        (format!("{v},rotate=nan"), "rotation"),
        (format!("{v},scale=0"), "frequency scale"),
        (format!("{v},scale=-2"), "frequency scale"),
        (format!("{v},amplitude=-1"), "amplitude scale"),
        (format!("{v},scale=nan"), "frequency scale"),
        ("vertex=99999,rings=2".to_string(), "99999"),
        ("rings=2".to_string(), "no seed"),
        (format!("vertex={centre},rings=0"), "rings = 0"),
        (format!("vertex={centre},rings=3,interface=0"), "too thin"),
    ];
    for (region, want) in &cases {
        let (code, err) = edit_case(region);
        assert_eq!(code, Some(2), "{region}: {err}");
        assert!(err.contains(want), "{region}: {err}");
        assert!(!out.exists(), "{region}: output written");
    }
    // two overlapping regions
    let (code, err) = pleat_cli(&[
        "wrinkle",
        "edit",
        &s(&base),
        "--cwf",
        &s(&a),
        "--region",
        &v,
        "--region",
        &v,
        "-o",
        &s(&out),
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("overlap"), "{err}");
    assert!(!out.exists());
    // design: NaN wave vector, negative amplitude, zero rings, out-of-range vertex
    for (src, want) in [
        (format!("{centre},nan,0,0,0.01,3"), "source 0"),
        (format!("{centre},5,0,0,-0.01,3"), "source 0"),
        (format!("{centre},5,0,0,0.01,0"), "source 0"),
        ("99999,5,0,0,0.01,3".to_string(), "99999"),
    ] {
        let (code, err) = pleat_cli(&[
            "wrinkle",
            "design",
            &s(&base),
            "--source",
            &src,
            "-o",
            &s(&out),
        ]);
        assert_eq!(code, Some(2), "{src}: {err}");
        assert!(err.contains(want), "{src}: {err}");
        assert!(!out.exists(), "{src}: output written");
    }
    // a base that is not an oriented manifold: three triangles on one edge
    let bad = dir.join("fin.obj");
    std::fs::write(
        &bad,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
    )
    .unwrap();
    let (code, err) = pleat_cli(&[
        "wrinkle",
        "design",
        &s(&bad),
        "--source",
        "0,5,0,0,0.01,1",
        "-o",
        &s(&out),
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("manifold"), "{err}");
    assert!(!out.exists());
    let (code, err) = pleat_cli(&[
        "wrinkle",
        "edit",
        &s(&bad),
        "--cwf",
        &s(&a),
        "--region",
        "vertex=0,rings=1,interface=1,rotate=90",
        "-o",
        &s(&out),
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(!err.is_empty());
    assert!(!out.exists());
    // a region covering the whole mesh is a global edit: plain Knöppel phase, said so
    let (code, err) = edit_case(&format!("vertex={centre},rings=40,interface=0,rotate=90"));
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("global edit: Knöppel"), "{err}");
    assert!(out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// C10: edit → interpolate → evaluate → rendered frames (docs/wrinkle_edit_*.png)

#[cfg(feature = "bake")]
#[path = "common/shaded.rs"]
mod shaded;
#[cfg(feature = "bake")]
use shaded::Shaded;

/// Vertices at least `rings` vertex rings away from every non-fixed vertex.
fn far_fixed_vertices(c: &Cwf, face_class: &[FaceClass], rings: usize) -> Vec<usize> {
    let n = c.base().vertex_count();
    let mut dist = vec![usize::MAX; n];
    let mut front = vec![];
    for (f, t) in c.base().triangles().iter().enumerate() {
        if face_class[f] != FaceClass::Fixed {
            for &v in t {
                if dist[v as usize] != 0 {
                    dist[v as usize] = 0;
                    front.push(v as usize);
                }
            }
        }
    }
    let mut nbr = vec![vec![]; n];
    for &[a, b] in c.edges() {
        nbr[a as usize].push(b as usize);
        nbr[b as usize].push(a as usize);
    }
    for d in 1..=rings {
        let mut next = vec![];
        for &v in &front {
            for &w in &nbr[v] {
                if dist[w] == usize::MAX {
                    dist[w] = d;
                    next.push(w);
                }
            }
        }
        front = next;
    }
    (0..n).filter(|&v| dist[v] == usize::MAX).collect()
}

/// The dissertation's three edits (Figs. 3.7, 3.6, 3.19) on corpus meshes: edit → interpolate
/// (40 guide frames, 41 frames; `GUIDE=n` changes it) → evaluate (3 levels, displacement ×2.5) →
/// one PNG strip of 7 shaded frames per edit under `docs/`, from one fixed camera facing the edited
/// area. Prints per frame step the RMS change of the displacement `Re z` (a temporal discontinuity
/// shows as a spike) and, C10, the largest drift `|z̃(t) − z̃⁰|` over the fixed vertices ≥ 2 rings
/// from the interface (no locality weights). `cargo test --release --test wrinkle_edit
/// readme_frames -- --ignored --nocapture`
#[cfg(feature = "bake")]
#[test]
#[ignore]
#[allow(clippy::type_complexity)]
fn readme_frames() {
    use pleat::bake::render::{rasterize, shade, Mode, View};
    use pleat::geom::Vec3;
    type Reg = (u32, usize, usize, f64, f64, bool);
    let cases: [(&str, &str, [f64; 3], f64, Vec<Reg>); 3] = [
        (
            "wrinkle_edit_rot90",
            "coarse_spot_1k.obj",
            [25.0, 0.0, 0.0],
            0.01,
            vec![(500, 5, 5, FRAC_PI_2, 1.0, false)],
        ),
        (
            "wrinkle_edit_x3",
            "coarse_fertility_1500.obj",
            [0.14, 0.0, 0.0],
            1.2,
            vec![(700, 5, 5, 0.0, 3.0, true)],
        ),
        (
            "wrinkle_edit_two",
            "coarse_spot_1k.obj",
            [12.0, 0.0, 0.0],
            0.02,
            vec![
                (500, 4, 4, FRAC_PI_2, 1.0, false),
                (100, 4, 4, 0.0, 2.5, true),
            ],
        ),
    ];
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for (name, file, k, amp, regions) in cases {
        let Some(mesh) = corpus_mesh(file) else {
            return;
        };
        let k0 = exact_plane_wave(mesh.clone(), k, amp);
        let edits: Vec<RegionEdit> = regions
            .iter()
            .map(|&(v, rings, inter, rot, sigma, couple)| {
                let mut r = RegionEdit::new(
                    grow_faces(&mesh, &[], &[v], rings, Adjacency::Vertex).unwrap(),
                );
                r.interface_rings = inter;
                r.rotate = rot;
                r.frequency_scale = sigma;
                if couple {
                    r = r.coupled();
                }
                r
            })
            .collect();
        let t0 = std::time::Instant::now();
        let (k1, rep) = edit(&k0, &edits, &EditOptions::default()).unwrap();
        let t_edit = t0.elapsed().as_secs_f64();
        let guide = std::env::var("GUIDE").map_or(40, |g| g.parse().unwrap());
        let iopts = InterpOptions {
            guide_frames: guide,
            substeps: 1,
            ..InterpOptions::default()
        };
        let t0 = std::time::Instant::now();
        let (anim, irep) = interpolate(&k0, &k1, &iopts).unwrap();
        let t_interp = t0.elapsed().as_secs_f64();
        eprintln!(
            "{name}: edit {t_edit:.3} s (compat RMS {:.3}, floor {:.3}), interpolate {t_interp:.2} s ({:?}), {} frames",
            rep.compat_rms,
            rep.compat_floor,
            irep.stop,
            anim.frame_count()
        );
        // C10: drift of the far fixed vertices
        let far = far_fixed_vertices(&k0, &rep.face_class, 2);
        let mut drift: f64 = 0.0;
        for i in 0..anim.frame_count() {
            let f = anim.frame(i).unwrap();
            for &v in &far {
                drift = drift.max((f.zeta()[v] - k0.zeta()[v]).abs());
            }
        }
        eprintln!(
            "  C10: max |z̃(t) − z̃⁰| over {} fixed vertices ≥ 2 rings from the interface: {drift:.2e}",
            far.len()
        );
        // camera facing the edited area
        let x = mesh.positions();
        let active: Vec<usize> = {
            let mut on = vec![false; x.len()];
            for (f, t) in mesh.triangles().iter().enumerate() {
                if rep.face_class[f] != FaceClass::Fixed {
                    t.iter().for_each(|&v| on[v as usize] = true);
                }
            }
            (0..x.len()).filter(|&v| on[v]).collect()
        };
        let c: Vec3 = active.iter().map(|&v| Vec3::from(x[v])).sum::<Vec3>() / active.len() as f64;
        let mut nrm = Vec3::ZERO;
        for (f, t) in mesh.triangles().iter().enumerate() {
            if rep.face_class[f] != FaceClass::Fixed {
                let [a, b, d] = t.map(|v| Vec3::from(x[v as usize]));
                nrm += (b - a).cross(d - a);
            }
        }
        let nrm = pleat::geom::normalized(nrm).unwrap();
        let r = active
            .iter()
            .map(|&v| (Vec3::from(x[v]) - c).length())
            .fold(0.0, f64::max)
            * 0.8;
        let side = 240u32;
        let dist = 4.0 * r;
        let view = View::look_at(c + nrm * dist, c, f64::from(side) * dist / (2.6 * r), side);
        let n_tiles = 7;
        let eopts = EvalOptions {
            want_z: true,
            displacement_scale: 2.5,
            ..EvalOptions::default()
        };
        let mut tiles = vec![];
        let mut last: Option<Vec<f64>> = None;
        let mut steps = vec![];
        for i in 0..anim.frame_count() {
            let f = anim.frame(i).unwrap();
            let (ev, _) = f.evaluate(3, &eopts).unwrap();
            let re: Vec<f64> = ev.z.as_ref().unwrap().iter().map(|z| z.re).collect();
            if let Some(prev) = &last {
                let d = (re
                    .iter()
                    .zip(prev)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    / re.len() as f64)
                    .sqrt();
                steps.push(d / amp);
            }
            last = Some(re);
            if i > 0 {
                let p = anim.frame(i - 1).unwrap();
                let mut dz = [0.0f64; 3];
                for (j, c) in rep_vertex_class(&k0, &rep.face_class).iter().enumerate() {
                    dz[*c as usize] = dz[*c as usize].max((f.zeta()[j] - p.zeta()[j]).abs());
                }
                let dw = f
                    .omega()
                    .iter()
                    .zip(p.omega())
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                eprintln!("    step {i}: max |Δz̃| fixed/edit/interface {dz:.3?}, max |Δω| {dw:.3}");
            }
            let tiles_at: Vec<usize> = (0..n_tiles)
                .map(|j| {
                    ((j * (anim.frame_count() - 1)) as f64 / (n_tiles - 1) as f64).round() as usize
                })
                .collect();
            if tiles_at.contains(&i) {
                let s = Shaded::new(ev.mesh);
                let g = rasterize(&view, s.mesh.positions(), s.mesh.triangles());
                tiles.push(shade(&g, &view, &s, Mode::Shaded).to_image([255, 255, 255]));
            }
        }
        eprintln!(
            "  RMS change of Re z per frame step / amplitude: {}",
            steps
                .iter()
                .map(|s| format!("{s:.3}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
        let sd = side as usize;
        let w = sd * tiles.len();
        let mut rgba = vec![255u8; 4 * w * sd];
        for (c, img) in tiles.iter().enumerate() {
            for j in 0..sd {
                let dst = 4 * (j * w + c * sd);
                rgba[dst..dst + 4 * sd].copy_from_slice(&img.rgba[4 * j * sd..4 * (j + 1) * sd]);
            }
        }
        let img = pleat::bake::Image8 {
            width: w as u32,
            height: sd as u32,
            rgba,
        };
        let png = pleat::bake::output::png_bytes(&img).unwrap();
        std::fs::create_dir_all(root.join("docs")).unwrap();
        let path = root.join(format!("docs/{name}.png"));
        std::fs::write(&path, &png).unwrap();
        eprintln!("  {}: {w}×{sd}, {} bytes", path.display(), png.len());
    }
}

/// Per frame step `i → i+1` of an animation: the RMS change of the coarse displacement field
/// `Re(a z̃)` over the vertices, divided by the largest keyframe amplitude.
fn frame_steps(anim: &pleat::wrinkle::CwfAnimation, amp: f64) -> Vec<f64> {
    let re = |i: usize| -> Vec<f64> {
        let f = anim.frame(i).unwrap();
        f.zeta()
            .iter()
            .zip(f.amplitude())
            .map(|(z, a)| a * z.re)
            .collect()
    };
    let mut prev = re(0);
    (1..anim.frame_count())
        .map(|i| {
            let cur = re(i);
            let d = cur
                .iter()
                .zip(&prev)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                / cur.len() as f64;
            prev = cur;
            d.sqrt() / amp
        })
        .collect()
}

/// The two-region spot edit of docs/guide/wrinkle-design.md (head 90°, body ×2.5 coupled; |k| = 12,
/// 4 rings, 4 interface rings) animated with `guide` guide frames: per-step changes and the
/// keyframes.
fn two_region_animation(
    guide: usize,
    locality: bool,
) -> Option<(Vec<f64>, pleat::wrinkle::InterpReport)> {
    let mesh = corpus_mesh("coarse_spot_1k.obj")?;
    let amp = 0.02;
    let k0 = exact_plane_wave(mesh.clone(), [12.0, 0.0, 0.0], amp);
    let mut edits = vec![];
    for (v, rot, sigma) in [(500u32, FRAC_PI_2, 1.0), (100, 0.0, 2.5)] {
        let mut r = RegionEdit::new(grow_faces(&mesh, &[], &[v], 4, Adjacency::Vertex).unwrap());
        r.interface_rings = 4;
        r.rotate = rot;
        r.frequency_scale = sigma;
        edits.push(if sigma != 1.0 { r.coupled() } else { r });
    }
    // the documented 4 interface rings exactly; with the default adaptive width (both bands
    // widened to 8 rings, RMS 0.347) the largest step is 0.265 / 0.184 / 0.099 at 20 / 40 / 80
    // guide frames (2026-11-27 b): it shrinks with the step too, no pop
    let exact = EditOptions {
        compat_target: 0.0,
        ..EditOptions::default()
    };
    let (k1, _) = edit(&k0, &edits, &exact).unwrap();
    let iopts = InterpOptions {
        guide_frames: guide,
        substeps: 1,
        locality,
        ..InterpOptions::default()
    };
    let (anim, irep) = interpolate(&k0, &k1, &iopts).unwrap();
    Some((frame_steps(&anim, amp), irep))
}

/// The two-region animation has no temporal pop (found 2026-11-27). Without locality the
/// far fixed region's phase drifted and snapped back at t ≈ 0.56–0.6: one step of 0.21–0.23
/// (RMS of `Δ Re(a z̃)` over the amplitude) at both 20 and 40 guide frames — a jump, since it
/// does not shrink with the step. With [`InterpOptions::locality`] the largest step halves when
/// the guide frames double (0.202 → 0.080, measured; a continuous motion moving at finite speed
/// halves, a jump stays), and at 40 guide frames it is 5.5× the median step (10.2× without).
/// Bounds: doubling the frames must cut the largest step to ≤ 0.6× and the peak must stay
/// ≤ 8× the median.
#[test]
fn two_region_animation_has_no_temporal_pop() {
    let Some((s20, _)) = two_region_animation(20, true) else {
        return;
    };
    let (s40, _) = two_region_animation(40, true).unwrap();
    let max = |s: &[f64]| s.iter().cloned().fold(0.0, f64::max);
    let mut sorted = s40.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    eprintln!(
        "largest step: {:.3} (20 frames), {:.3} (40 frames); median (40) {median:.4}",
        max(&s20),
        max(&s40)
    );
    assert!(
        max(&s40) <= 0.6 * max(&s20),
        "largest step does not shrink with the frame step: {} vs {}",
        max(&s40),
        max(&s20)
    );
    assert!(
        max(&s40) <= 8.0 * median,
        "peak {} vs median {median}",
        max(&s40)
    );
}

/// Diagnostic (ignored): the per-step change of the two-region animation, with and without
/// locality, at 20 and 40 guide frames.
#[test]
#[ignore]
fn two_region_pop_diagnostic() {
    for guide in [20, 40] {
        for locality in [true, false] {
            let Some((steps, rep)) = two_region_animation(guide, locality) else {
                return;
            };
            let mut sorted = steps.clone();
            sorted.sort_by(f64::total_cmp);
            let med = sorted[sorted.len() / 2];
            let (imax, max) =
                steps
                    .iter()
                    .enumerate()
                    .fold((0, 0.0), |b, (i, &s)| if s > b.1 { (i, s) } else { b });
            eprintln!(
                "guide {guide} locality {locality}: {:?} {} it, median {med:.4}, max {max:.4} at t = {:.3}, ratio {:.1}\n  {}",
                rep.stop,
                rep.iterations,
                (imax + 1) as f64 / guide as f64,
                max / med,
                steps.iter().map(|s| format!("{s:.3}")).collect::<Vec<_>>().join(" ")
            );
        }
    }
}

/// Per vertex: fixed, edit or interface (edit > fixed > interface), from the face classes.
fn rep_vertex_class(c: &Cwf, face_class: &[FaceClass]) -> Vec<FaceClass> {
    let fixed = vertex_fixed(c, face_class);
    let mut cls: Vec<FaceClass> = fixed
        .iter()
        .map(|&f| {
            if f {
                FaceClass::Fixed
            } else {
                FaceClass::Interface
            }
        })
        .collect();
    for (f, t) in c.base().triangles().iter().enumerate() {
        if face_class[f] == FaceClass::Edit {
            t.iter().for_each(|&v| cls[v as usize] = FaceClass::Edit);
        }
    }
    cls
}
