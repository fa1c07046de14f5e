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
