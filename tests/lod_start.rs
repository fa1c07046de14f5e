//! The start surface of a LOD (`LodParams::start`): a clean input (closed,
//! manifold, oriented, intersection-free after exact welding) can be the start of the loop
//! instead of its offset surface; `Input` on a dirty soup is refused with the failing
//! property; `Auto` on a dirty soup is the offset start, byte for byte; the C field is checked.
#![cfg(feature = "lod")]

#[path = "common/meshcheck.rs"]
mod meshcheck;
#[path = "common/shapes.rs"]
mod shapes;

use pleat::lowpoly::{check_clean, generate, generate_chain, LodParams, LodReport, LodStart};
use pleat::mesh::TriMesh;
use pleat::verify::MeshReport;
use pleat::Error;

fn params(np: f64, start: LodStart) -> LodParams {
    LodParams {
        screen_size: np,
        start,
        ..LodParams::default()
    }
}

fn bake(m: &TriMesh, p: &LodParams) -> pleat::Result<(TriMesh, LodReport)> {
    generate(m, p, &mut |_| true)
}

/// Pro.III by `MeshReport` and (when installed) CGAL's `meshcheck`.
fn assert_valid(out: &TriMesh, s: &LodReport, what: &str) {
    assert!(s.verified.all_hold(), "{what}: {:?}", s.verified);
    let r = MeshReport::compute(out);
    assert!(
        r.is_watertight && r.is_manifold && r.consistently_oriented,
        "{what}"
    );
    assert_eq!(r.self_intersection_free, Some(true), "{what}");
    meshcheck::assert_valid(out, what);
}

/// `m` as an unwelded soup (three own vertices per triangle) without its last triangle: a
/// hole, and seams that only exact welding closes.
fn holed_soup(m: &TriMesh) -> TriMesh {
    let n = m.triangle_count() - 1;
    let mut p = Vec::with_capacity(3 * n);
    let mut t = Vec::with_capacity(n);
    for i in 0..n {
        let k = p.len() as u32;
        p.extend(m.triangle_positions(i));
        t.push([k, k + 1, k + 2]);
    }
    TriMesh::new(p, t).unwrap()
}

#[test]
fn input_start_on_clean_meshes_is_valid_within_the_bound_and_coarser() {
    let cases = [
        ("sphere", shapes::icosphere(1.0, 4), 100.0),
        ("torus", shapes::torus(1.0, 0.3, 64, 24), 200.0),
        ("box", shapes::box_grid(1.0, 0.6, 0.3, 12), 100.0),
    ];
    for (name, m, np) in &cases {
        for start in [LodStart::Input, LodStart::Auto] {
            let what = format!("{name} n_p={np} {start:?}");
            let (out, s) = bake(m, &params(*np, start)).unwrap();
            assert!(s.started_from_input, "{what}");
            assert_eq!(s.faces_offset, m.triangle_count() as u64, "{what}");
            assert_valid(&out, &s, &what);
            // the one-sided check of Alg. 5 with slack d keeps the LOD within about d
            assert!(s.hausdorff_rel < 2.0 / np, "{what}: {}", s.hausdorff_rel);
            assert!(out.triangle_count() < m.triangle_count(), "{what}");
        }
        let (_, s) = bake(m, &params(*np, LodStart::Offset)).unwrap();
        assert!(!s.started_from_input);
    }
}

#[test]
fn an_unwelded_clean_soup_is_welded_first() {
    let m = shapes::icosphere(1.0, 3);
    let mut p = Vec::new();
    let mut t = Vec::new();
    for i in 0..m.triangle_count() {
        let k = p.len() as u32;
        p.extend(m.triangle_positions(i));
        t.push([k, k + 1, k + 2]);
    }
    let soup = TriMesh::new(p, t).unwrap();
    let welded = check_clean(&soup).unwrap();
    assert_eq!(welded.vertex_count(), m.vertex_count());
    let (out, s) = bake(&soup, &params(50.0, LodStart::Input)).unwrap();
    assert!(s.started_from_input);
    assert_valid(&out, &s, "welded soup");
}

#[test]
fn input_start_on_a_dirty_soup_is_refused_with_the_failing_property() {
    let soup = holed_soup(&shapes::icosphere(1.0, 3));
    let why = check_clean(&soup).unwrap_err();
    assert!(why.contains("closed"), "{why}");
    match bake(&soup, &params(50.0, LodStart::Input)) {
        Err(Error::InvalidArgument(m)) => assert!(m.contains("closed"), "{m}"),
        other => panic!("expected InvalidArgument, got {other:?}"),
    }
    // two overlapping spheres: closed and manifold, but intersecting
    let a = shapes::icosphere(1.0, 2);
    let b = shapes::scaled(&a, [1.0, 1.0, 1.0]);
    let mut p = a.positions().to_vec();
    let k = p.len() as u32;
    p.extend(b.positions().iter().map(|q| [q[0] + 0.5, q[1], q[2]]));
    let mut t = a.triangles().to_vec();
    t.extend(b.triangles().iter().map(|f| f.map(|i| i + k)));
    let two = TriMesh::new(p, t).unwrap();
    let why = check_clean(&two).unwrap_err();
    assert!(why.contains("self-intersection"), "{why}");
    // an inside-out sphere is consistently oriented but not outward
    let inv: Vec<[u32; 3]> = a.triangles().iter().map(|f| [f[0], f[2], f[1]]).collect();
    let inside_out = TriMesh::new(a.positions().to_vec(), inv).unwrap();
    assert!(check_clean(&inside_out).unwrap_err().contains("outward"));
}

#[test]
fn auto_on_a_dirty_soup_is_the_offset_start_byte_for_byte() {
    let soup = holed_soup(&shapes::torus(1.0, 0.3, 48, 16));
    let (auto, sa) = bake(&soup, &params(100.0, LodStart::Auto)).unwrap();
    let (offset, so) = bake(&soup, &params(100.0, LodStart::Offset)).unwrap();
    assert!(!sa.started_from_input && !so.started_from_input);
    assert_eq!(auto, offset);
    assert_valid(&auto, &sa, "dirty torus auto");
}

/// A sphere buried in another is clean but not connected: `Auto` takes the offset start,
/// whose interior removal drops the buried sphere; `Input` keeps it (as asked).
#[test]
fn auto_starts_a_clean_input_with_a_buried_component_from_the_offset() {
    let outer = shapes::icosphere(1.0, 3);
    let inner = shapes::scaled(&shapes::icosphere(1.0, 2), [0.5; 3]);
    let mut p = outer.positions().to_vec();
    let k = p.len() as u32;
    p.extend_from_slice(inner.positions());
    let mut t = outer.triangles().to_vec();
    t.extend(inner.triangles().iter().map(|f| f.map(|i| i + k)));
    let nested = TriMesh::new(p, t).unwrap();
    assert!(check_clean(&nested).is_ok());
    let (_, s) = bake(&nested, &params(50.0, LodStart::Auto)).unwrap();
    assert!(!s.started_from_input);
    let (out, s) = bake(&nested, &params(50.0, LodStart::Input)).unwrap();
    assert!(s.started_from_input);
    assert_valid(&out, &s, "nested input start");
    assert_eq!(MeshReport::compute(&out).n_components, 2);
}

#[test]
fn input_start_reaches_a_face_target() {
    let m = shapes::icosphere(1.0, 4);
    let target = 120;
    let p = LodParams {
        target_faces: Some(target),
        ..params(200.0, LodStart::Input)
    };
    let (out, s) = bake(&m, &p).unwrap();
    assert_valid(&out, &s, "sphere input n_F=120");
    assert!(s.target_met && out.triangle_count() <= target);
    assert!(
        out.triangle_count() + 10 >= target,
        "{}",
        out.triangle_count()
    );
}

#[test]
fn a_chain_of_a_clean_input_starts_its_finest_level_from_the_input() {
    let m = shapes::torus(1.0, 0.3, 64, 24);
    let sizes = [50.0, 200.0];
    let levels = generate_chain(&m, &sizes, &LodParams::default(), &mut |_| true).unwrap();
    for ((out, s), np) in levels.iter().zip(sizes) {
        assert_valid(out, s, &format!("chain n_p={np}"));
        assert!(s.hausdorff_rel < 2.0 / np, "n_p={np}: {}", s.hausdorff_rel);
    }
    assert!(levels[1].1.started_from_input && !levels[0].1.started_from_input);
    let offset = LodParams {
        start: LodStart::Offset,
        ..LodParams::default()
    };
    let levels = generate_chain(&m, &sizes, &offset, &mut |_| true).unwrap();
    assert!(levels.iter().all(|(_, s)| !s.started_from_input));
}

#[cfg(feature = "cage")]
#[test]
fn cages_ignore_the_start_and_enclose() {
    let m = shapes::icosphere(1.0, 3);
    let (_, s) = pleat::cage::generate(&m, &params(50.0, LodStart::Input), &mut |_| true).unwrap();
    assert!(!s.started_from_input);
    assert_eq!(s.verified.cage_encloses_without_touching, Some(true));
}

/// Same bytes for 1, 2 and 3 threads from a clean input (≥ 2048 faces, so the first pass
/// evaluates its collapse batches in parallel).
#[test]
fn input_start_does_not_depend_on_thread_count() {
    let m = shapes::torus(1.0, 0.3, 96, 32);
    assert!(m.triangle_count() >= 2048);
    let run = |n: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap();
        pool.install(|| bake(&m, &params(100.0, LodStart::Input)).unwrap().0)
    };
    let one = run(1);
    for n in [2, 3] {
        assert_eq!(one, run(n), "{n} threads");
    }
}

#[test]
fn c_start_field_is_checked_and_older_sizes_get_auto() {
    use pleat::ffi::*;
    use std::ptr;
    let m = shapes::icosphere(1.0, 2);
    let pos: Vec<f64> = m.positions().iter().flatten().copied().collect();
    let idx: Vec<u32> = m.triangles().iter().flatten().copied().collect();
    unsafe {
        let mut mesh: *mut PleatMesh = ptr::null_mut();
        let st = pleat_mesh_create_f64(
            pos.as_ptr(),
            m.vertex_count(),
            24,
            idx.as_ptr(),
            idx.len(),
            &mut mesh,
        );
        assert_eq!(st, PleatStatus::Ok);
        let bake = |p: &PleatLodParams, stats: &mut PleatLodStats| {
            let mut out: *mut PleatMesh = ptr::null_mut();
            let st = pleat_lod_generate(mesh, p, None, ptr::null_mut(), &mut out, stats);
            pleat_mesh_destroy(out);
            st
        };
        let mut p = pleat_lod_params_default();
        p.screen_size = 50.0;
        assert_eq!(p.start, PLEAT_LOD_START_AUTO);
        let mut stats = PleatLodStats {
            struct_size: std::mem::size_of::<PleatLodStats>() as u32,
            ..Default::default()
        };
        for bad in [3, 7, u32::MAX] {
            p.start = bad;
            assert_eq!(bake(&p, &mut stats), PleatStatus::InvalidArgument);
            let msg = std::ffi::CStr::from_ptr(pleat_last_error()).to_string_lossy();
            assert!(msg.contains("start"), "{msg}");
        }
        p.start = PLEAT_LOD_START_INPUT;
        assert_eq!(bake(&p, &mut stats), PleatStatus::Ok);
        assert_eq!(stats.started_from_input, 1);
        p.start = PLEAT_LOD_START_OFFSET;
        assert_eq!(bake(&p, &mut stats), PleatStatus::Ok);
        assert_eq!(stats.started_from_input, 0);
        // an older caller (struct ending at `clearance`) with garbage after it gets auto
        p.start = 99;
        p.struct_size = std::mem::offset_of!(PleatLodParams, start) as u32;
        assert_eq!(bake(&p, &mut stats), PleatStatus::Ok);
        assert_eq!(stats.started_from_input, 1);
        pleat_mesh_destroy(mesh);
    }
}
