//! LOD and cage pipeline: guarantees verified independently (MeshReport, and the CGAL
//! `meshcheck` when present), chains, stability on extreme inputs, determinism, cancellation.
#![cfg(feature = "lod")]

#[path = "common/shapes.rs"]
mod shapes;

use pleat::lowpoly::{generate, generate_chain, LodParams};
use pleat::mesh::{MeshReport, TriMesh};
use pleat::{Error, Stats};

fn params(np: f64) -> LodParams {
    LodParams {
        screen_size: np,
        ..LodParams::default()
    }
}

fn bake(m: &TriMesh, p: &LodParams, cage: bool) -> pleat::Result<(TriMesh, Stats)> {
    let mut prog = |_: pleat::Progress<'_>| true;
    if cage {
        #[cfg(feature = "cage")]
        return pleat::cage::generate(m, p, &mut prog);
    }
    generate(m, p, &mut prog)
}

/// Pro.III checked by code independent of the pipeline, plus the pipeline's own record.
fn assert_valid(out: &TriMesh, s: &Stats, what: &str) {
    assert!(
        s.verified.iter().all(|v| v.1),
        "{what}: verification failed {:?}",
        s.verified
    );
    let r = MeshReport::compute(out);
    assert!(r.is_watertight, "{what}: not watertight");
    assert!(r.is_manifold, "{what}: not manifold");
    assert!(r.consistently_oriented, "{what}: not oriented");
    assert_eq!(
        r.self_intersection_free,
        Some(true),
        "{what}: self-intersects"
    );
    meshcheck(out, what);
}

/// Runs the independent CGAL checker when it is installed.
fn meshcheck(m: &TriMesh, what: &str) {
    let tool = std::env::var("PLEAT_MESHCHECK").unwrap_or("/tmp/pleat-tools/meshcheck".into());
    if !std::path::Path::new(&tool).exists() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("pleat-lod-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!(
        "{}.obj",
        what.replace(|c: char| !c.is_alphanumeric(), "_")
    ));
    pleat::mesh::io::write_mesh(&file, m).unwrap();
    let out = std::process::Command::new(&tool)
        .arg(&file)
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&file);
    let json = String::from_utf8_lossy(&out.stdout);
    for key in [
        "\"is_watertight\":true",
        "\"is_manifold\":true",
        "\"self_intersection_free\":true",
    ] {
        assert!(
            json.replace(' ', "").contains(key),
            "{what}: meshcheck disagrees ({key}): {json}"
        );
    }
}

fn rel_hausdorff(s: &Stats) -> f64 {
    s.get_metric("hausdorff_rel").unwrap()
}

#[test]
fn sphere_torus_box_at_three_screen_sizes() {
    let shapes = [
        ("sphere", shapes::icosphere(1.0, 4)),
        ("torus", shapes::torus(1.0, 0.3, 64, 24)),
        ("box", shapes::box_grid(1.0, 0.6, 0.3, 12)),
    ];
    for (name, m) in &shapes {
        let mut faces = Vec::new();
        for np in [50.0, 100.0, 200.0] {
            let (out, s) = bake(m, &params(np), false).unwrap();
            let what = format!("{name} n_p={np}");
            assert_valid(&out, &s, &what);
            let h = rel_hausdorff(&s);
            assert!(h < 4.0 / np, "{what}: Hausdorff/l = {h}");
            faces.push(out.triangle_count());
        }
        assert!(
            faces[0] <= faces[2],
            "{name}: finer LODs have more faces: {faces:?}"
        );
    }
}

#[test]
fn face_target_is_met() {
    let m = shapes::icosphere(1.0, 4);
    for (np, target) in [(50.0, 300), (200.0, 120)] {
        let p = LodParams {
            target_faces: Some(target),
            ..params(np)
        };
        let (out, s) = bake(&m, &p, false).unwrap();
        assert_valid(&out, &s, &format!("sphere n_F={target}"));
        let n = out.triangle_count();
        assert!(
            n <= target && n + 10 >= target,
            "{n} faces for target {target}"
        );
        assert_eq!(s.get_count("target_met"), Some(1));
    }
}

#[cfg(feature = "cage")]
#[test]
fn cages_enclose_and_do_not_touch() {
    for (name, m) in [
        ("sphere", shapes::icosphere(1.0, 3)),
        ("torus", shapes::torus(1.0, 0.3, 48, 16)),
        ("box", shapes::box_grid(1.0, 0.6, 0.3, 8)),
    ] {
        let (out, s) = bake(&m, &params(50.0), true).unwrap();
        assert_valid(&out, &s, &format!("{name} cage"));
        assert!(s
            .verified
            .contains(&("cage_encloses_without_touching".into(), true)));
        let fwn = pleat::spatial::FastWindingNumber::new(&out);
        for w in fwn.winding_numbers(m.positions()) {
            assert!(
                w > 0.5,
                "{name}: an input vertex is outside the cage (w = {w})"
            );
        }
    }
}

#[test]
fn chain_levels_are_valid_and_coarser() {
    let m = shapes::torus(1.0, 0.3, 64, 24);
    let mut prog = |_: pleat::Progress<'_>| true;
    let sizes = [50.0, 200.0, 100.0];
    let levels = generate_chain(&m, &sizes, &LodParams::default(), &mut prog).unwrap();
    assert_eq!(levels.len(), 3);
    for ((out, s), np) in levels.iter().zip(sizes) {
        assert_valid(out, s, &format!("chain n_p={np}"));
        assert!(
            rel_hausdorff(s) < 4.0 / np,
            "chain n_p={np}: {}",
            rel_hausdorff(s)
        );
    }
    assert_eq!(levels[1].1.get_count("chain_level"), Some(0));
    assert!(levels[0].0.triangle_count() <= levels[2].0.triangle_count());
    assert!(levels[2].0.triangle_count() <= levels[1].0.triangle_count());
}

#[test]
fn extreme_scales_and_shapes_give_valid_output_or_a_clear_error() {
    let sphere = shapes::icosphere(1.0, 3);
    let cases = [
        ("tiny", shapes::scaled(&sphere, [1e-4; 3]), 100.0),
        ("huge", shapes::scaled(&sphere, [1e4; 3]), 100.0),
        ("flat", shapes::box_grid(1.0, 1.0, 1e-3, 8), 100.0),
        ("needle", shapes::box_grid(100.0, 1.0, 1.0, 8), 100.0),
        ("np5", sphere.clone(), 5.0),
        ("np1000", sphere.clone(), 1000.0),
    ];
    for (name, m, np) in cases {
        for cage in [false, cfg!(feature = "cage")] {
            let what = format!("{name} cage={cage}");
            match bake(&m, &params(np), cage) {
                Ok((out, s)) => assert_valid(&out, &s, &what),
                Err(e) => assert!(
                    matches!(e, Error::InvalidMesh(_) | Error::LimitExceeded(_)),
                    "{what}: unexpected error {e}"
                ),
            }
        }
    }
}

#[test]
fn bad_parameters_are_rejected_up_front() {
    let m = shapes::icosphere(1.0, 1);
    for p in [
        params(f64::NAN),
        params(0.0),
        params(-5.0),
        params(f64::INFINITY),
        LodParams {
            flow_ratio: 0.0,
            ..params(50.0)
        },
        LodParams {
            epsilon: f64::NAN,
            ..params(50.0)
        },
        LodParams {
            target_faces: Some(2),
            ..params(50.0)
        },
    ] {
        assert!(
            matches!(bake(&m, &p, false), Err(Error::InvalidArgument(_))),
            "{p:?}"
        );
    }
    let p = LodParams {
        memory_budget_bytes: 1000,
        ..params(50.0)
    };
    assert!(matches!(bake(&m, &p, false), Err(Error::LimitExceeded(_))));
    let mut prog = |_: pleat::Progress<'_>| true;
    assert!(generate_chain(&m, &[], &LodParams::default(), &mut prog).is_err());
    assert!(generate_chain(&m, &[50.0, f64::NAN], &LodParams::default(), &mut prog).is_err());
}

#[test]
fn cancellation_is_prompt() {
    let m = shapes::icosphere(1.0, 4);
    let mut calls = 0;
    let mut prog = |_: pleat::Progress<'_>| {
        calls += 1;
        calls < 5
    };
    let r = generate(&m, &params(100.0), &mut prog);
    assert_eq!(r.unwrap_err(), Error::Cancelled);
    assert_eq!(calls, 5);
}

#[test]
fn output_does_not_depend_on_thread_count() {
    let m = shapes::torus(1.0, 0.3, 48, 16);
    let run = |n: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap();
        pool.install(|| bake(&m, &params(100.0), false).unwrap().0)
    };
    assert_eq!(run(1), run(2));
}
