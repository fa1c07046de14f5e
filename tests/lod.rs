//! LOD pipeline: guarantees, stability, chains.

#[path = "common/shapes.rs"]
mod shapes;

use pleat::lowpoly::{generate, LodParams};
use pleat::Stats;

fn bake(m: &pleat::mesh::TriMesh, np: f64) -> (pleat::mesh::TriMesh, Stats) {
    let p = LodParams {
        screen_size: np,
        ..LodParams::default()
    };
    let mut prog = |_: pleat::Progress<'_>| true;
    generate(m, &p, &mut prog).unwrap()
}

fn show(name: &str, s: &Stats) {
    eprintln!(
        "{name}: {:?}\n  {:?}\n  {:?}\n  {:?}",
        s.stages, s.counts, s.metrics, s.verified
    );
}

#[test]
fn sphere_lod() {
    let m = shapes::icosphere(1.0, 4);
    let (out, s) = bake(&m, 50.0);
    show("sphere", &s);
    assert!(s.verified.iter().all(|v| v.1));
    assert!(out.triangle_count() < m.triangle_count());
}

fn bake_mode(
    m: &pleat::mesh::TriMesh,
    np: f64,
    cage: bool,
) -> pleat::Result<(pleat::mesh::TriMesh, Stats)> {
    let p = LodParams {
        screen_size: np,
        ..LodParams::default()
    };
    let mut prog = |_: pleat::Progress<'_>| true;
    if cage {
        pleat::cage::generate(m, &p, &mut prog)
    } else {
        generate(m, &p, &mut prog)
    }
}

#[test]
fn torus_and_box() {
    for (name, m) in [
        ("torus", shapes::torus(1.0, 0.3, 64, 24)),
        ("box", shapes::box_grid(1.0, 0.6, 0.3, 12)),
    ] {
        for cage in [false, true] {
            let t = std::time::Instant::now();
            let (out, s) = bake_mode(&m, 100.0, cage).unwrap();
            eprintln!(
                "{name} cage={cage} {:.2}s faces {} -> {}",
                t.elapsed().as_secs_f64(),
                m.triangle_count(),
                out.triangle_count()
            );
            show(name, &s);
            assert!(s.verified.iter().all(|v| v.1));
        }
    }
}
