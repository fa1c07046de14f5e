//! The measured admission of a LOD's memory budget: where the up-front
//! estimate (`LodParams::memory_estimate_bytes`, every soup piece's offset counted whole)
//! fits no voxel scale, the offset stage counts its surface before allocating it and the
//! budget is checked against the peak estimated from those counts. Checked on a generated soup
//! of 200 overlapping spheres, whose offset after interior removal is a fraction of the
//! pieces' total: it bakes under a budget the up-front estimate refuses, with the output of
//! an up-front admitted bake at the same voxel; under a budget below its measured estimate
//! it is refused with `LimitExceeded` naming the measured count.
#![cfg(feature = "lod")]

#[path = "common/meshcheck.rs"]
mod meshcheck;
#[path = "common/shapes.rs"]
mod shapes;

use pleat::lowpoly::{generate, generate_chain, LodParams, LodStart};
use pleat::mesh::TriMesh;
use pleat::Error;

/// `n` unit icosahedra (20 faces each) at fixed pseudo-random centres in `[0, 6]³`: they
/// overlap heavily (a soup: `LodStart::Auto` would take the offset too).
fn sphere_soup(n: u32) -> TriMesh {
    let sphere = shapes::icosphere(1.0, 0);
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 6001) as f64 * 1e-3
    };
    let mut p = Vec::new();
    let mut t = Vec::new();
    for _ in 0..n {
        let c = [next(), next(), next()];
        let base = p.len() as u32;
        p.extend(
            sphere
                .positions()
                .iter()
                .map(|q| [q[0] + c[0], q[1] + c[1], q[2] + c[2]]),
        );
        t.extend(sphere.triangles().iter().map(|f| f.map(|v| v + base)));
    }
    TriMesh::new(p, t).unwrap()
}

/// A cheap LOD from the offset at voxel scale 2 (the only scale then: the coarsest), without
/// the input-plane fit, whose coverage samples (known before any offset) would dominate the
/// budget of so small a bake.
fn params(budget: u64) -> LodParams {
    LodParams {
        screen_size: 40.0,
        max_rounds: 2,
        fit_to_input: false,
        start: LodStart::Offset,
        offset_voxel_scale: Some(2.0),
        memory_budget_bytes: budget,
        ..LodParams::default()
    }
}

#[test]
fn a_soup_refused_up_front_bakes_by_measurement() {
    let soup = sphere_soup(200);
    let up_front = params(u64::MAX).memory_estimate_bytes(&soup, 2.0);
    let budget = (up_front / 2.0) as u64;
    let p = params(budget);
    // the up-front estimate fits no voxel scale: today's rule would refuse
    assert_eq!(p.lod_voxel_scale(&soup), None);
    assert!(p.validate(&soup).is_ok());
    let (lod, rep) = generate(&soup, &p, &mut |_| true).expect("admitted by measurement");
    let measured = rep
        .measured_estimate_bytes
        .expect("the measured path was taken");
    println!(
        "up-front {:.1} MiB, measured {:.1} MiB, budget {:.1} MiB, {} offset faces",
        up_front / 1048576.0,
        measured / 1048576.0,
        budget as f64 / 1048576.0,
        rep.faces_offset
    );
    assert!(measured <= budget as f64 && measured < up_front);
    assert_eq!(rep.offset_voxel_scale, Some(2.0));
    assert!(rep.verified.all_hold(), "{:?}", rep.verified);
    meshcheck::assert_valid(&lod, "sphere soup, measured admission");
    // the same bake admitted up front (a roomy budget): the same output, byte for byte
    let (roomy, roomy_rep) = generate(&soup, &params(64 << 30), &mut |_| true).unwrap();
    assert_eq!(roomy_rep.measured_estimate_bytes, None);
    assert_eq!(roomy_rep.faces_offset, rep.faces_offset);
    assert_eq!(roomy.positions(), lod.positions());
    assert_eq!(roomy.triangles(), lod.triangles());
    // a chain's finest level takes the same path
    let chain = generate_chain(&soup, &[40.0, 20.0], &p, &mut |_| true).unwrap();
    assert_eq!(chain[0].1.measured_estimate_bytes, Some(measured));
    assert_eq!(chain[0].0.triangles(), lod.triangles());
}

#[test]
fn a_soup_over_its_measured_estimate_is_refused() {
    let soup = sphere_soup(200);
    let up_front = params(u64::MAX).memory_estimate_bytes(&soup, 2.0);
    let (_, rep) = generate(&soup, &params((up_front / 2.0) as u64), &mut |_| true).unwrap();
    let measured = rep.measured_estimate_bytes.unwrap();
    // just below the measured estimate (above what is known before any offset: the input's
    // structures and the band's area-based estimate)
    let p = params(measured as u64 - 1);
    assert!(p.validate(&soup).is_ok());
    match generate(&soup, &p, &mut |_| true) {
        Err(Error::LimitExceeded(msg)) => {
            println!("{msg}");
            assert!(msg.contains("measured"), "{msg}");
        }
        other => panic!("expected LimitExceeded, got {:?}", other.map(|x| x.1)),
    }
    // below the a-priori part (the input's own structures): refused before any work
    let tiny = params(64 << 10);
    assert!(matches!(tiny.validate(&soup), Err(Error::LimitExceeded(_))));
}
