//! Hardening regression tests: defects found by fuzzing and while writing the
//! fuzz targets (fuzz/), and the resource-exhaustion cases — headers claiming huge counts,
//! deeply nested glTF, coordinates near 1e±300, a screen size that would need 100 GB, 10⁶ tiny
//! components, 10⁶ coincident vertices. Each must end in a clear answer (a result or a status)
//! before any large allocation, within the memory budget, in seconds, and never panic.

use std::time::{Duration, Instant};

use pleat::mesh::io::{read_mesh_bytes, MeshFormat};
use pleat::mesh::TriMesh;
use pleat::verify::{MeshReport, ReportOptions};
use pleat::Error;

#[path = "common/shapes.rs"]
mod shapes;
use shapes::{jittered_pile, tiny_components};

/// Runs `f`, asserting it returns within `secs` seconds.
fn within<T>(secs: u64, what: &str, f: impl FnOnce() -> T) -> T {
    let t = Instant::now();
    let r = f();
    let dt = t.elapsed();
    assert!(dt < Duration::from_secs(secs), "{what} took {dt:?}");
    println!("{what}: {dt:?}");
    r
}

fn parse_err(data: &[u8], format: MeshFormat, what: &str) -> String {
    let r = within(5, what, || read_mesh_bytes(data, format, what));
    match r {
        Err(e @ Error::Parse { .. }) => {
            println!("  {e}");
            e.to_string()
        }
        other => panic!("{what}: expected a parse error, got {other:?}"),
    }
}

fn tet_ply_binary(vertex_claim: &str, face_claim: &str) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {vertex_claim}\nproperty double x\n\
         property double y\nproperty double z\nelement face {face_claim}\n\
         property list uchar uint vertex_indices\nend_header\n"
    )
    .into_bytes();
    for p in [
        [0.0f64, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ] {
        for c in p {
            b.extend(c.to_le_bytes());
        }
    }
    for t in [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
        b.push(3);
        for v in t {
            b.extend(v.to_le_bytes());
        }
    }
    b
}

#[test]
fn ply_and_off_headers_claiming_huge_counts_fail_fast() {
    for (v, f) in [
        ("4000000000", "4"),
        ("4", "100000000"),
        ("18446744073709551615", "4"),
    ] {
        parse_err(
            &tet_ply_binary(v, f),
            MeshFormat::Ply,
            &format!("PLY claiming {v}/{f}"),
        );
    }
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3000000000\nproperty float x\n\
                  property float y\nproperty float z\nelement face 1\n\
                  property list uchar int vertex_indices\nend_header\n0 0 0\n";
    parse_err(ascii, MeshFormat::Ply, "ASCII PLY claiming 3e9 vertices");
    let off = b"OFF\n4000000000 100000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    parse_err(off, MeshFormat::Off, "OFF claiming 4e9 vertices, 1e8 faces");
}

#[test]
fn stl_claiming_100m_triangles_in_a_small_file_fails_fast() {
    let mut b = vec![b' '; 80];
    b.extend(100_000_000u32.to_le_bytes());
    b.extend(vec![0u8; 50 * 4]);
    // the header does not start with "solid", so this is binary: 50 bytes per claimed facet
    parse_err(&b, MeshFormat::Stl, "binary STL claiming 1e8 triangles");
}

/// A minimal glTF JSON document around `accessors`/`nodes`, with one 48-byte buffer of four
/// float positions... in a data URI.
fn gltf_doc(accessors: &str, bufferviews: &str, nodes: &str, primitive: &str) -> Vec<u8> {
    let mut buf = Vec::new();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ] {
        for c in p {
            buf.extend(c.to_le_bytes());
        }
    }
    let b64 = base64(&buf);
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":{nodes},
        "meshes":[{{"primitives":[{primitive}]}}],"accessors":{accessors},
        "bufferViews":{bufferviews},
        "buffers":[{{"byteLength":48,"uri":"data:application/octet-stream;base64,{b64}"}}]}}"#
    )
    .into_bytes()
}

fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = c
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | (u32::from(b) << (16 - 8 * i)));
        for i in 0..=c.len() {
            s.push(char::from(A[((n >> (18 - 6 * i)) & 63) as usize]));
        }
        for _ in c.len()..3 {
            s.push('=');
        }
    }
    s
}

#[test]
fn gltf_accessor_counts_beyond_the_data_fail_fast() {
    // POSITION accessor claiming 1e9 elements in a 48-byte view
    let doc = gltf_doc(
        r#"[{"bufferView":0,"componentType":5126,"count":1000000000,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}]"#,
        r#"[{"buffer":0,"byteLength":48}]"#,
        r#"[{"mesh":0}]"#,
        r#"{"attributes":{"POSITION":0}}"#,
    );
    parse_err(
        &doc,
        MeshFormat::Gltf,
        "glTF accessor claiming 1e9 positions",
    );
    // an index accessor without a buffer view (all zeros by the spec) claiming 4e9 indices
    let doc = gltf_doc(
        r#"[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},
            {"componentType":5125,"count":4000000000,"type":"SCALAR"}]"#,
        r#"[{"buffer":0,"byteLength":48}]"#,
        r#"[{"mesh":0}]"#,
        r#"{"attributes":{"POSITION":0},"indices":1}"#,
    );
    parse_err(
        &doc,
        MeshFormat::Gltf,
        "glTF view-less accessor claiming 4e9 indices",
    );
}

#[test]
fn gltf_position_accessor_out_of_range_is_a_parse_error_not_a_panic() {
    // found by fuzz/fuzz_targets/gltf.rs: gltf-json's validation indexed `accessors` with the
    // POSITION index unchecked and panicked
    let doc = gltf_doc(
        r#"[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}]"#,
        r#"[{"buffer":0,"byteLength":48}]"#,
        r#"[{"mesh":0}]"#,
        r#"{"attributes":{"POSITION":5}}"#,
    );
    let msg = parse_err(&doc, MeshFormat::Gltf, "glTF POSITION accessor 5 of 1");
    assert!(msg.contains("accessor 5 does not exist"), "{msg}");
    let glb = include_bytes!("../fuzz/seeds/gltf/regress_position_accessor_out_of_range.glb");
    parse_err(&glb[1..], MeshFormat::Glb, "fuzz crash input (GLB)");
}

#[test]
fn deeply_nested_gltf_nodes_are_read_without_recursion() {
    // a chain of 20 000 nodes, each the only child of the previous, the last holding the mesh
    let n = 20_000;
    let mut nodes: Vec<String> = (0..n - 1)
        .map(|i| format!(r#"{{"children":[{}]}}"#, i + 1))
        .collect();
    nodes.push(r#"{"mesh":0}"#.into());
    let doc = gltf_doc(
        r#"[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}]"#,
        r#"[{"buffer":0,"byteLength":48}]"#,
        &format!("[{}]", nodes.join(",")),
        r#"{"attributes":{"POSITION":0}}"#,
    );
    let m = within(10, "glTF with 20000 nested nodes", || {
        read_mesh_bytes(&doc, MeshFormat::Gltf, "nested.gltf")
    })
    .expect("a deep but valid node tree");
    assert_eq!(m.vertex_count(), 4);
    // a node that is its own descendant: an error, not a loop
    let doc = gltf_doc(
        r#"[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}]"#,
        r#"[{"buffer":0,"byteLength":48}]"#,
        r#"[{"children":[1]},{"children":[0],"mesh":0}]"#,
        r#"{"attributes":{"POSITION":0}}"#,
    );
    within(5, "glTF node cycle", || {
        read_mesh_bytes(&doc, MeshFormat::Gltf, "cycle.gltf")
    })
    .expect_err("a node cycle");
}

#[test]
fn deeply_nested_gltf_json_is_an_error_not_a_stack_overflow() {
    let deep = format!(
        r#"{{"asset":{{"version":"2.0"}},"extras":{}{}}}"#,
        "[".repeat(100_000),
        "]".repeat(100_000)
    );
    parse_err(
        deep.as_bytes(),
        MeshFormat::Gltf,
        "glTF JSON nested 1e5 deep",
    );
}

#[cfg(feature = "wrinkle")]
#[test]
fn cwfa_substeps_that_overflow_the_frame_count_are_rejected() {
    // found while writing fuzz/fuzz_targets/cwfa.rs: `substeps 18446744073709551615` made
    // frame_count() overflow (a panic in debug builds, a wrong count in release)
    use pleat::wrinkle::{parse_animation, Complex, Cwf, CwfAnimation};
    let base = TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let key = Cwf::new(
        base.clone(),
        vec![0.0; 3],
        vec![0.1; 3],
        vec![Complex::ONE; 3],
    )
    .unwrap();
    let guides = || (vec![vec![0.0; 3]; 3], vec![vec![Complex::ONE; 3]; 3]);
    let (w, z) = guides();
    let err = CwfAnimation::from_guides(&key, [vec![0.1; 3], vec![0.1; 3]], w, z, usize::MAX)
        .unwrap_err();
    assert!(err.to_string().contains("overflows"), "{err}");
    let (w, z) = guides();
    let ok = CwfAnimation::from_guides(&key, [vec![0.1; 3], vec![0.1; 3]], w, z, 7).unwrap();
    assert_eq!(ok.frame_count(), 15);
    let text = pleat::wrinkle::animation_to_string(&ok)
        .replace("substeps 7", &format!("substeps {}", usize::MAX));
    let err = parse_animation(&text, base, "huge-substeps.cwfa").unwrap_err();
    println!("{err}");
}

#[cfg(feature = "lod")]
mod lod_limits {
    use super::*;
    use pleat::lowpoly::{generate, LodParams, LodStart};

    fn tetra(scale: f64) -> TriMesh {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        TriMesh::new(
            p.iter().map(|v| v.map(|c| c * scale)).collect(),
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
        .unwrap()
    }

    fn bake(m: &TriMesh, np: f64) -> pleat::Result<TriMesh> {
        let p = LodParams {
            screen_size: np,
            max_rounds: 2,
            ..LodParams::default()
        };
        generate(m, &p, &mut |_| true).map(|(m, _)| m)
    }

    /// A LOD at a small screen size, or a clean `LimitExceeded` under a 1 GiB budget: either
    /// way an answer in seconds, and a valid mesh when there is one.
    pub(super) fn bake_or_limit(m: &TriMesh, what: &str) {
        let p = LodParams {
            screen_size: 16.0,
            memory_budget_bytes: 1 << 30,
            ..LodParams::default()
        };
        let r = within(120, &format!("{what}: LOD at n_p 16"), || {
            generate(m, &p, &mut |_| true)
        });
        match r {
            Ok((lod, rep)) => {
                println!("  {} faces", lod.triangle_count());
                assert!(rep.verified.all_hold(), "{:?}", rep.verified);
            }
            Err(Error::LimitExceeded(msg)) => println!("  {msg}"),
            Err(e) => panic!("{what}: {e}"),
        }
        // a budget too small for the input itself is refused before any work
        let tight = LodParams {
            memory_budget_bytes: 1 << 20,
            ..p
        };
        let r = within(5, &format!("{what}: 1 MiB budget"), || {
            generate(m, &tight, &mut |_| true)
        });
        assert!(matches!(r, Err(Error::LimitExceeded(_))), "{:?}", r.err());
    }

    #[test]
    fn a_screen_size_needing_100_gb_is_refused_before_allocating() {
        // (1e5)^3 grid cells of the offset stage: far beyond the default 2 GiB budget. Forced
        // to start from the offset, and an open tetrahedron (not clean: `LodStart::Auto` takes
        // the offset), are refused before any large allocation.
        let (p, mut tris) = tetra(1.0).into_parts();
        tris.pop();
        let open = TriMesh::new(p, tris).unwrap();
        let offset = LodParams {
            screen_size: 1e5,
            max_rounds: 2,
            start: LodStart::Offset,
            ..LodParams::default()
        };
        let auto = LodParams {
            start: LodStart::Auto,
            ..offset.clone()
        };
        let cases = [
            ("n_p = 1e5 from the offset", tetra(1.0), offset),
            ("n_p = 1e5, an open tetrahedron", open, auto),
        ];
        for (what, m, p) in cases {
            let r = within(5, what, || generate(&m, &p, &mut |_| true));
            match r {
                Err(Error::LimitExceeded(m)) => println!("  {m}"),
                other => panic!(
                    "{what}: expected LimitExceeded, got {:?}",
                    other.map(|(m, _)| m.triangle_count())
                ),
            }
        }
    }

    /// A clean input starts from itself (`LodStart::Auto`), whose estimate does not grow with
    /// the offset grid (2026-11-28): the clean tetrahedron at n_p = 1e5 bakes from its input
    /// within the default budget, in seconds, or is refused; never the 100 GB offset.
    #[test]
    fn a_clean_input_at_a_huge_screen_size_bakes_from_itself_or_is_refused() {
        let p = LodParams {
            screen_size: 1e5,
            max_rounds: 2,
            ..LodParams::default()
        };
        let m = tetra(1.0);
        assert!(p.input_start_memory_estimate_bytes(&m) < p.memory_budget_bytes as f64);
        let r = within(5, "clean tetrahedron at n_p = 1e5", || {
            generate(&m, &p, &mut |_| true)
        });
        match r {
            Ok((lod, rep)) => {
                assert!(rep.started_from_input);
                assert!(rep.verified.all_hold(), "{:?}", rep.verified);
                println!("  {} faces", lod.triangle_count());
            }
            Err(Error::LimitExceeded(m)) => println!("  {m}"),
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn coordinates_near_1e300_and_1e_minus_300_get_a_clear_answer() {
        for scale in [1e300, 1e-300, 1e-310] {
            let r = within(
                30,
                &format!("LOD of a tetrahedron scaled by {scale:e}"),
                || bake(&tetra(scale), 8.0),
            );
            match r {
                Ok(m) => assert!(m.positions().iter().flatten().all(|c| c.is_finite())),
                Err(Error::Internal(m)) => panic!("internal error at scale {scale:e}: {m}"),
                Err(e) => println!("  scale {scale:e}: {e}"),
            }
        }
    }

    /// The `lod_bake` fuzz finding (fuzz/regressions/lod_bake-cage-extreme-range.bin): a soup
    /// with one corner at 5·10⁵⁴ and the rest within ±422. Its cage failed the enclosure check
    /// (`PLEAT_STATUS_INTERNAL`) because the fast winding numbers overflowed to NaN at that
    /// extent (fixed: they scale the mesh to unit extent); such coordinates are now refused up
    /// front as beyond ±2^128, as is an input whose voxels are below its coordinates'
    /// precision. Inside the range, scales from 10⁻³⁰ to 10³⁰ and a tetrahedron 10¹⁰ from the
    /// origin bake to a cage and a LOD.
    #[cfg(feature = "cage")]
    #[test]
    fn extreme_dynamic_range_is_refused_or_baked_never_an_internal_error() {
        let soup = TriMesh::new(
            vec![
                [36.125, 48.171875, 60.21875],
                [72.265625, 84.3125, 96.359375],
                [164.625, 208.671875, 222.515625],
                [269.03125, -2.921875, 5.035446863090189e54],
            ],
            vec![[3, 1, 2], [0, 0, 0]],
        )
        .unwrap();
        let shifted = |t: f64| {
            let (p, tris) = tetra(1.0).into_parts();
            TriMesh::new(p.iter().map(|v| v.map(|c| c + t)).collect(), tris).unwrap()
        };
        let refused = [
            ("soup reaching 5e54", soup, 0.5),
            ("tetrahedron at 1e15, n_p 8", shifted(1e15), 8.0),
            ("tetrahedron of 1e-40", tetra(1e-40), 8.0),
            ("tetrahedron of 1e37, n_p 0.01", tetra(1e37), 0.01),
        ];
        for (what, m, np) in refused {
            let p = LodParams {
                screen_size: np,
                max_rounds: 2,
                ..LodParams::default()
            };
            let lod = generate(&m, &p, &mut |_| true).map(|(m, _)| m);
            let cage = pleat::cage::generate(&m, &p, &mut |_| true).map(|(m, _)| m);
            for r in [lod, cage] {
                match r {
                    Err(Error::LimitExceeded(msg) | Error::InvalidMesh(msg)) => {
                        println!("  {what}: {msg}")
                    }
                    other => panic!("{what}: expected a refusal, got {:?}", other.err()),
                }
            }
        }
        let baked = [
            ("tetrahedron of 1e30", tetra(1e30)),
            ("tetrahedron of 1e-30", tetra(1e-30)),
            ("tetrahedron at 1e10", shifted(1e10)),
        ];
        for (what, m) in baked {
            let p = LodParams {
                screen_size: 8.0,
                max_rounds: 2,
                ..LodParams::default()
            };
            let (lod, rep) = generate(&m, &p, &mut |_| true).expect(what);
            assert!(rep.verified.all_hold(), "{what}: {:?}", rep.verified);
            let (cage, _) = pleat::cage::generate(&m, &p, &mut |_| true).expect(what);
            assert!(pleat::cage::check(&cage, &m).is_cage(), "{what}");
            println!(
                "  {what}: LOD {} faces, cage {} faces",
                lod.triangle_count(),
                cage.triangle_count()
            );
        }
    }
}

/// The fuzz targets' bodies (fuzz/src/lib.rs, the same functions cargo-fuzz runs).
#[cfg(all(
    feature = "lod",
    feature = "cage",
    feature = "wrinkle",
    feature = "io-gltf",
    feature = "tfw"
))]
#[path = "../fuzz/src/lib.rs"]
#[allow(dead_code)]
mod fuzz;

/// The committed fuzz inputs (regressions, seeds) through [`fuzz`]'s targets, which need
/// every feature they use.
#[cfg(all(
    feature = "lod",
    feature = "cage",
    feature = "wrinkle",
    feature = "io-gltf",
    feature = "tfw"
))]
mod fuzz_inputs {
    use super::{fuzz, within};

    /// Every input in fuzz/regressions/ (`<target>-<what>.bin`) replayed through its target's
    /// checks: no panic, no `PLEAT_STATUS_INTERNAL`, the target's invariants. A file still named
    /// `-open` is a finding not fixed yet and fails here until it is.
    #[test]
    fn fuzz_regressions_pass_their_targets_checks() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions");
        let files = fuzz::sorted_files(&dir).expect("fuzz/regressions/");
        assert!(
            !files.is_empty(),
            "no regression inputs in {}",
            dir.display()
        );
        for path in &files {
            let name = path.file_name().unwrap().to_string_lossy();
            let (target, run) = fuzz::target_of_regression(&name)
                .unwrap_or_else(|| panic!("{name}: not named <target>-<what>"));
            let data = std::fs::read(path).expect("readable");
            let accepted = within(60, &name, || run(&data));
            println!("  {name}: target {target}, accepted: {accepted}");
        }
    }

    /// The `tfw_scene` fuzz target's checks (`fuzz::tfw_scene`, fuzz/src/lib.rs) on its committed
    /// seeds: the Rust parser and `pleat_tfw_scene_from_json` agree on acceptance, no panic
    /// reaches the C boundary, an accepted scene's JSON reads again, and a tiny accepted scene
    /// assembles and gets a bounded base solve without a panic; at least 4 of the seeds are
    /// accepted, so the target starts past the parser.
    #[test]
    fn tfw_scene_fuzz_seeds_pass_the_targets_checks() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/tfw_scene");
        let seeds = fuzz::sorted_files(&dir).expect("the committed seeds");
        assert!(seeds.len() >= 5, "{} seeds", seeds.len());
        let accepted = seeds
            .iter()
            .filter(|path| fuzz::tfw_scene(&std::fs::read(path).expect("a readable seed")))
            .count();
        assert!(
            accepted >= 4,
            "{accepted} of {} seeds accepted",
            seeds.len()
        );
    }
}

/// A unit tetrahedron whose 4 corners are each stored `copies` times (`4·copies` vertices at 4
/// points) and whose faces are repeated `copies` times, each copy on its own vertices: a soup
/// of `4·copies` exactly coincident triangles.
fn coincident_tetrahedron(copies: u32) -> TriMesh {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let faces = [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let p: Vec<[f64; 3]> = (0..copies).flat_map(|_| corners).collect();
    let t: Vec<[u32; 3]> = (0..copies)
        .flat_map(|c| faces.map(|f| f.map(|v| 4 * c + v)))
        .collect();
    TriMesh::new(p, t).unwrap()
}

/// The mesh report (exact welding off and on; the self-intersection pass when `si`): an answer
/// in seconds.
fn report_both(m: &TriMesh, what: &str, si: bool) -> (MeshReport, MeshReport) {
    let options = ReportOptions {
        self_intersections: si,
        weld: false,
    };
    let plain = within(60, &format!("{what}: report"), || {
        MeshReport::compute_with(m, &options)
    });
    let options = ReportOptions {
        weld: true,
        ..options
    };
    let welded = within(60, &format!("{what}: welded report"), || {
        MeshReport::compute_with(m, &options)
    });
    (plain, welded)
}

#[test]
#[ignore = "10^6 components: 26 s in release (reports 3 s each, LOD 19 s); docs/guide/errors-and-limits.md"]
fn a_million_tiny_components_are_reported_and_baked() {
    let m = tiny_components(100);
    let (plain, welded) = report_both(&m, "10^6 tiny components", true);
    assert_eq!(plain.n_components, 1_000_000);
    assert_eq!(plain.self_intersection_free, Some(true));
    assert_eq!(welded.n_components, 1_000_000);
    #[cfg(feature = "lod")]
    lod_limits::bake_or_limit(&m, "10^6 tiny components");
}

#[test]
fn a_million_coincident_vertices_are_reported_and_baked() {
    let m = coincident_tetrahedron(250_000);
    assert_eq!(m.vertex_count(), 1_000_000);
    // The full report, self-intersection pass included: 250 000 stacked copies of each face
    // are C(250 000, 2) intersecting pairs per face, counted per group of duplicates (the faces
    // of the tetrahedron share edges, so no pair across groups intersects).
    let (plain, welded) = report_both(&m, "10^6 coincident vertices", true);
    let per_face = 250_000usize * 249_999 / 2;
    for r in [&plain, &welded] {
        assert_eq!(r.n_self_intersecting_pairs, Some(4 * per_face));
        assert_eq!(r.n_degenerate_faces_welded, Some(0));
        assert_eq!(r.self_intersection_free, Some(false));
    }
    assert_eq!(plain.n_coincident_vertices, 1_000_000);
    assert_eq!(plain.n_components, 250_000);
    assert_eq!(welded.n_components, 1);
    assert_eq!(welded.n_duplicate_faces, 4 * 249_999);
    #[cfg(feature = "lod")]
    lod_limits::bake_or_limit(&m, "10^6 coincident vertices");
}

/// docs/guide/errors-and-limits.md, "Not guaranteed": the self-intersection pass tests a pile of
/// near-duplicate faces pair by pair. Measures, for a 20k-face jittered pile, the full report's
/// time and the latency of a cancel requested 0.2 s into it (from the first `false` to the return).
#[test]
#[ignore = "measurement: cargo test --release --test hardening jittered -- --ignored --nocapture"]
fn jittered_pile_report_time_and_cancel_latency() {
    let m = jittered_pile(20_000);
    let options = ReportOptions::default();
    let t0 = Instant::now();
    let mut calls = 0;
    let full = MeshReport::compute_with_progress(&m, &options, &mut |_| {
        calls += 1;
        true
    })
    .expect("not cancelled");
    println!(
        "  20k jittered pile: report {:.2} s, {calls} progress calls, {:?} intersecting pairs \
         (lower bound: {:?})",
        t0.elapsed().as_secs_f64(),
        full.n_self_intersecting_pairs,
        full.n_self_intersecting_pairs_is_lower_bound
    );
    assert_eq!(full.self_intersection_free, Some(false));
    // the request is at 0.2 s; the callback sees it at its next call
    let request = Duration::from_millis(200);
    let t0 = Instant::now();
    let r = MeshReport::compute_with_progress(&m, &options, &mut |_| t0.elapsed() < request);
    let latency = t0.elapsed().saturating_sub(request).as_secs_f64();
    println!(
        "  cancel requested at 0.2 s: returned {latency:.2} s later (cancelled: {})",
        r.is_none()
    );
}
