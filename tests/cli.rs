//! The `pleat` binary as a build step uses it: exit codes and output.
#![cfg(feature = "cli")]

use std::process::Command;

fn pleat(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run pleat")
}

/// The stdout of a run that must have succeeded (else fails with its stdout and stderr).
fn stdout_of_success(o: &std::process::Output) -> String {
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    out
}

#[test]
fn check_prints_report_and_exits_zero() {
    let o = pleat(&["check", "assets/dirty_two_boxes.obj"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(s.contains("components          3"), "{s}");
    assert!(s.contains("watertight          no"), "{s}");
}

#[test]
fn check_json_is_one_object() {
    let o = pleat(&["check", "--json", "assets/dirty_two_boxes.obj"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    let t = s.trim();
    assert!(
        t.starts_with('{') && t.ends_with('}') && t.lines().count() == 1,
        "{t}"
    );
    assert!(t.contains("\"n_components\": 3"), "{t}");
    assert!(t.contains("\"self_intersection_free\": false"), "{t}");
}

#[test]
fn unreadable_input_exits_two_with_message() {
    let o = pleat(&["check", "assets/does_not_exist.obj"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does_not_exist.obj"));
}

#[cfg(feature = "lod")]
#[test]
fn lod_chain_writes_one_valid_file_per_screen_size() {
    let dir = std::env::temp_dir().join(format!("pleat-cli-lod-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("torus.obj");
    let torus = {
        let (n, m) = (32u32, 12u32);
        let mut p = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (u, v) = (
                    i as f64 / n as f64 * std::f64::consts::TAU,
                    j as f64 / m as f64 * std::f64::consts::TAU,
                );
                let r = 1.0 + 0.3 * v.cos();
                p.push([r * u.cos(), r * u.sin(), 0.3 * v.sin()]);
            }
        }
        let id = |i: u32, j: u32| (i % n) * m + (j % m);
        let mut f = Vec::new();
        for i in 0..n {
            for j in 0..m {
                f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        pleat::mesh::TriMesh::new(p, f).unwrap()
    };
    pleat::mesh::io::write_mesh(&input, &torus).unwrap();
    let pattern = dir.join("lod_{n}.obj");
    let o = pleat(&[
        "lod",
        input.to_str().unwrap(),
        "--screen-size",
        "25,50",
        "--rounds",
        "10",
        "-o",
        pattern.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for n in ["25", "50"] {
        let f = dir.join(format!("lod_{n}.obj"));
        let m = pleat::mesh::io::read_mesh(&f).unwrap();
        let r = pleat::verify::MeshReport::compute(&m);
        assert!(r.is_watertight && r.self_intersection_free == Some(true));
        assert!(m.triangle_count() < torus.triangle_count());
    }
    // `{np}` works like `{n}`, and `--help` shows it intact (clap eats a literal `{n}`).
    let o = pleat(&[
        "lod",
        input.to_str().unwrap(),
        "--screen-size",
        "25",
        "--rounds",
        "2",
        "-o",
        dir.join("np_{np}.obj").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("np_25.obj").is_file());
    let help = String::from_utf8_lossy(&pleat(&["lod", "--help"]).stdout).to_string();
    assert!(help.contains("`{np}` is replaced"), "{help}");
    // Several sizes need a {n} placeholder; --faces needs a single size.
    let o = pleat(&[
        "lod",
        input.to_str().unwrap(),
        "--screen-size",
        "25,50",
        "-o",
        "x.obj",
    ]);
    assert_eq!(o.status.code(), Some(2));
    #[cfg(feature = "cage")]
    {
        let cage = dir.join("cage.obj");
        let o = pleat(&[
            "cage",
            input.to_str().unwrap(),
            "--screen-size",
            "25",
            "--rounds",
            "5",
            "-o",
            cage.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(String::from_utf8_lossy(&o.stdout).contains("verified: watertight"));
    }
    let o = pleat(&[
        "lod",
        input.to_str().unwrap(),
        "--screen-size",
        "nan",
        "-o",
        "x.obj",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(feature = "lod")]
#[test]
fn offset_writes_a_verified_watertight_mesh() {
    let out = std::env::temp_dir().join(format!("pleat-cli-offset-{}.obj", std::process::id()));
    let o = pleat(&[
        "offset",
        "assets/dirty_two_boxes.obj",
        "--screen-size",
        "25",
        "-o",
        out.to_str().unwrap(),
        "--stats-json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stats = String::from_utf8_lossy(&o.stdout);
    assert!(stats.contains("\"watertight\":true"), "{stats}");
    let c = pleat(&["check", "--json", out.to_str().unwrap()]);
    let report = String::from_utf8_lossy(&c.stdout);
    assert!(report.contains("\"is_watertight\": true"), "{report}");
    assert!(
        report.contains("\"self_intersection_free\": true"),
        "{report}"
    );
    let _ = std::fs::remove_file(out);
}

#[cfg(feature = "lod")]
#[test]
fn offset_rejects_bad_screen_size() {
    let o = pleat(&[
        "offset",
        "assets/dirty_two_boxes.obj",
        "--screen-size",
        "0",
        "-o",
        "x.obj",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("screen size"));
}

/// `pleat bench chain` on a folder with a clean mesh and an unreadable file: one CSV row each,
/// the mesh's with both times, their ratio and its chain's finest level equal to the single
/// bake; the unreadable file's with its load error; the median printed.
#[cfg(feature = "lod")]
#[test]
fn bench_chain_writes_one_row_per_mesh() {
    let dir = scratch_with_octahedron("bench-chain");
    std::fs::write(dir.join("bad.obj"), "f 1 2 3\n").unwrap();
    let out_dir = dir.join("out");
    let o = pleat(&[
        "bench",
        "chain",
        path_str(&dir),
        "--screen-sizes",
        "25,50",
        "--reps",
        "1",
        "--out-dir",
        path_str(&out_dir),
        "-q",
    ]);
    let out = stdout_of_success(&o);
    assert!(
        out.contains("median") && out.contains("over 1 meshes"),
        "{out}"
    );
    let csv = std::fs::read_to_string(out_dir.join("chain_bench.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert_eq!(rows[0][4], "ratio");
    let (bad, oct) = (&rows[1], &rows[2]);
    assert!(
        bad[0] == "bad.obj" && bad[8].starts_with("load error"),
        "{csv}"
    );
    assert_eq!(
        (oct[0], oct[1], oct[7], oct[8]),
        ("oct.obj", "8", "true", "ok")
    );
    let ratio: f64 = oct[4].parse().unwrap();
    assert!(ratio.is_finite() && ratio > 0.0, "{csv}");
    let o = pleat(&["bench", "chain", path_str(&dir), "--reps", "0"]);
    assert_eq!(o.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fresh scratch directory holding the regular octahedron as `oct.obj`.
#[cfg(any(feature = "wrinkle", feature = "lod"))]
fn scratch_with_octahedron(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("pleat-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("oct.obj"),
        "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
         f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n",
    )
    .unwrap();
    dir
}

#[cfg(any(feature = "wrinkle", feature = "lod"))]
fn path_str(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_plane_wave_then_eval_gives_watertight_mesh() {
    let dir = scratch_with_octahedron("plane-wave");
    let (base, cwf, out) = (dir.join("oct.obj"), dir.join("w.cwf"), dir.join("w.ply"));
    let o = pleat(&[
        "wrinkle",
        "plane-wave",
        path_str(&base),
        "--k",
        "-4,2,1",
        "--amplitude",
        "0.02",
        "-o",
        path_str(&cwf),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&cwf).unwrap();
    assert!(
        text.starts_with("pleat-cwf 1\nvertices 6\nedges 12\n"),
        "{text}"
    );
    let o = pleat(&[
        "wrinkle",
        "eval",
        path_str(&base),
        "--cwf",
        path_str(&cwf),
        "--levels",
        "2",
        "-o",
        path_str(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("128 triangles"));
    let o = pleat(&["check", path_str(&out)]);
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(s.contains("triangles           128"), "{s}");
    assert!(s.contains("watertight          yes"), "{s}");
    assert!(s.contains("self-intersections  none"), "{s}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_from_field_reads_the_documented_format() {
    let dir = scratch_with_octahedron("from-field");
    let (base, field, cwf) = (dir.join("oct.obj"), dir.join("f.txt"), dir.join("f.cwf"));
    // one `fx fy fz [amplitude]` line per vertex; comments and blank lines ignored
    std::fs::write(
        &field,
        "# wave vectors\n3 0 0\n3 0 0 0.05\n\n0 3 0\n0 3 0   # trailing text is not allowed\n",
    )
    .unwrap();
    let args = |f: &std::path::Path| {
        vec![
            "wrinkle".to_string(),
            "from-field".into(),
            path_str(&base).into(),
            "--field".into(),
            path_str(f).into(),
            "--amplitude".into(),
            "0.01".into(),
            "-o".into(),
            path_str(&cwf).into(),
        ]
    };
    let run = |f: &std::path::Path| {
        let a = args(f);
        pleat(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let o = run(&field);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("f.txt:6"), "{err}");
    std::fs::write(
        &field,
        "# wave vectors\n3 0 0\n3 0 0 0.05\n\n0 3 0\n0 3 0\n0 0 3\n0 0 3 0\n",
    )
    .unwrap();
    let o = run(&field);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&cwf).unwrap();
    let vertex: Vec<&str> = text
        .lines()
        .skip_while(|l| *l != "vertex")
        .skip(1)
        .take(6)
        .collect();
    let amp: Vec<f64> = vertex
        .iter()
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(amp, [0.01, 0.05, 0.01, 0.01, 0.01, 0.0]);
    // too few lines
    std::fs::write(&field, "1 0 0\n").unwrap();
    let o = run(&field);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("one line per vertex"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_eval_refuses_bad_input_with_exit_two() {
    let dir = scratch_with_octahedron("eval-errors");
    let (base, cwf, out) = (dir.join("oct.obj"), dir.join("w.cwf"), dir.join("w.obj"));
    let o = pleat(&[
        "wrinkle",
        "plane-wave",
        path_str(&base),
        "--k=1,2,3",
        "-o",
        path_str(&cwf),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // too many levels: refused before any allocation
    let o = pleat(&[
        "wrinkle",
        "eval",
        path_str(&base),
        "--cwf",
        path_str(&cwf),
        "--levels",
        "40",
        "-o",
        path_str(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("limit exceeded"));
    // a field written for another base mesh
    let o = pleat(&[
        "wrinkle",
        "eval",
        "assets/dirty_two_boxes.obj",
        "--cwf",
        path_str(&cwf),
        "-o",
        path_str(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("was written for a base mesh"));
    // a wave vector with two components
    let o = pleat(&[
        "wrinkle",
        "plane-wave",
        path_str(&base),
        "--k",
        "1,2",
        "-o",
        path_str(&cwf),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_demo_script_runs() {
    let dir = scratch_with_octahedron("demo");
    let out = dir.join("demo.ply");
    let o = Command::new("sh")
        .arg("examples_c/wrinkle_demo.sh")
        .arg("")
        .arg(&out)
        .env("PLEAT", env!("CARGO_BIN_EXE_pleat"))
        .env("LEVELS", "2")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output();
    let Ok(o) = o else {
        println!("SKIPPED: no `sh` to run examples_c/wrinkle_demo.sh");
        return;
    };
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{s}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(s.contains("triangles           320"), "{s}");
    assert!(s.matches("watertight          yes").count() == 2, "{s}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `pleat lod IN.glb --bake --merge` writes one GLB holding the merged chain, readable as glTF.
#[cfg(feature = "bake")]
#[test]
fn lod_bake_writes_one_glb_chain() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let Some(asset) = ["../shared", "../../shared"]
        .iter()
        .map(|d| {
            root.join(d)
                .join("assets/textured/gen_spot_two_materials.glb")
        })
        .find(|p| p.is_file())
    else {
        eprintln!("SKIPPED: ../shared/assets/textured is absent");
        return;
    };
    let dir = std::env::temp_dir().join(format!("pleat-cli-bake-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("chain.glb");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args([
            "lod",
            asset.to_str().unwrap(),
            "--screen-size",
            "25,50",
            "--bake",
            "--merge",
            "-q",
            "-o",
        ])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let (doc, _, images) = gltf::import(&out).unwrap();
    assert_eq!(doc.meshes().count(), 2);
    assert!(images.len() >= 2);

    // A face target applies to a single-level bake (it used to be refused with --bake).
    let one = dir.join("one.glb");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args(["lod", asset.to_str().unwrap(), "--screen-size", "50"])
        .args(["--faces", "60", "--bake", "--merge", "-q", "-o"])
        .arg(&one)
        .status()
        .unwrap();
    assert!(status.success());
    let (doc, buffers, _) = gltf::import(&one).unwrap();
    let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|b| Some(&buffers[b.index()]));
    let triangles = reader.read_indices().unwrap().into_u32().count() / 3;
    assert!(triangles <= 60, "{triangles} faces for --faces 60");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args(["lod", asset.to_str().unwrap(), "--screen-size", "25,50"])
        .args(["--faces", "60", "--bake", "-q", "-o"])
        .arg(&one)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--faces needs a single screen size"));
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_design_then_edit_reports_solves_and_refuses_bad_regions() {
    let dir = scratch_with_octahedron("design-edit");
    let base = dir.join("oct.obj");
    let (d, e, labels) = (dir.join("d.cwf"), dir.join("e.cwf"), dir.join("labels.txt"));
    let o = pleat(&[
        "wrinkle",
        "design",
        path_str(&base),
        "--source",
        "4,3,-1,0,0.02,1",
        "-o",
        path_str(&d),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("vector heat") && err.contains("residual"),
        "{err}"
    );
    let o = pleat(&[
        "wrinkle",
        "edit",
        path_str(&base),
        "--cwf",
        path_str(&d),
        "--region",
        "vertex=4,rings=1,interface=1,rotate=90,scale=2,couple",
        "--labels",
        path_str(&labels),
        "-o",
        path_str(&e),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("3.26") && err.contains("3.28"), "{err}");
    assert_eq!(std::fs::read_to_string(&labels).unwrap().lines().count(), 8);
    assert!(std::fs::read_to_string(&e)
        .unwrap()
        .starts_with("pleat-cwf 1\n"));
    // no seed, and a zero frequency scale: exit 2 with a message, nothing written
    for region in ["rings=2", "vertex=4,scale=0"] {
        let bad = dir.join("bad.cwf");
        let o = pleat(&[
            "wrinkle",
            "edit",
            path_str(&base),
            "--cwf",
            path_str(&d),
            "--region",
            region,
            "-o",
            path_str(&bad),
        ]);
        assert_eq!(o.status.code(), Some(2), "{region}");
        assert!(!String::from_utf8_lossy(&o.stderr).is_empty());
        assert!(!bad.exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `pleat bench tfw` on a small built-in sheet and a scene file: both CSVs and the SVG exist
/// and parse (one summary row per scene, iteration rows with finite numbers, energies
/// non-increasing per scene).
#[cfg(feature = "tfw")]
#[test]
fn bench_tfw_writes_csv_and_svg() {
    let dir = std::env::temp_dir().join(format!("pleat-cli-bench-tfw-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("small.json");
    std::fs::write(
        &scene,
        pleat::tfw::Scene::stretched_sheet(11, 5, 0.05).to_json_string(),
    )
    .unwrap();
    let o = pleat(&[
        "bench",
        "tfw",
        "--builtin",
        "sheet-small",
        path_str(&scene),
        "--max-iterations",
        "20",
        "--out-dir",
        path_str(&dir),
        "-q",
    ]);
    stdout_of_success(&o);
    let scenes = std::fs::read_to_string(dir.join("tfw_scenes.csv")).unwrap();
    let rows: Vec<Vec<&str>> = scenes.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3, "{scenes}");
    assert_eq!(rows[0][0], "scene");
    assert_eq!(
        (rows[1][0], rows[2][0], rows[1][1], rows[2][1]),
        ("sheet-small", "small", "78", "55"),
        "{scenes}"
    );
    for r in &rows[1..] {
        assert_eq!(r.len(), rows[0].len(), "{scenes}");
        let peak: f64 = r[9].parse().unwrap();
        assert!(peak > 0.0 && peak < 5e-3, "{scenes}");
        let waves: f64 = r[12].parse().unwrap();
        assert!(waves >= 0.0, "{scenes}");
    }
    let iters = std::fs::read_to_string(dir.join("tfw_iterations.csv")).unwrap();
    let mut last: Option<(String, f64)> = None;
    for l in iters.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        assert_eq!(f.len(), 9, "{l}");
        let v: Vec<f64> = f[2..7].iter().map(|x| x.parse().unwrap()).collect();
        // waves, peak amplitude: empty or measured (at the start, every 10 it., the end)
        assert!(f[7].is_empty() == f[8].is_empty(), "{l}");
        if f[1] == "0" {
            let (w, p): (f64, f64) = (f[7].parse().unwrap(), f[8].parse().unwrap());
            assert!(w >= 0.0 && p > 0.0, "{l}");
        }
        assert!(v.iter().all(|x| x.is_finite()), "{l}");
        if let Some((s, e)) = &last {
            if s == f[0] {
                assert!(v[1] <= *e, "energy rose: {l}");
            }
        }
        last = Some((f[0].to_string(), v[1]));
    }
    assert!(iters.lines().count() > 2, "{iters}");
    let svg = std::fs::read_to_string(dir.join("tfw_bench.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("sheet-small") && svg.contains("r / r0"));
    let o = pleat(&[
        "bench",
        "tfw",
        "--builtin",
        "nope",
        "--out-dir",
        path_str(&dir),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `pleat tfw --qp newton|clarabel` picks the step solver (printed in the summary),
/// `--no-valley-search` runs; an unknown solver name exits 2 naming the flag.
#[cfg(feature = "tfw")]
#[test]
fn tfw_qp_flag_picks_the_step_solver() {
    let dir = std::env::temp_dir().join(format!("pleat-cli-tfw-qp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("sheet.json");
    std::fs::write(
        &scene,
        pleat::tfw::Scene::stretched_sheet(11, 5, 0.05).to_json_string(),
    )
    .unwrap();
    let out = dir.join("out.obj");
    for (name, printed) in [("newton", "ProjectedNewton"), ("clarabel", "Clarabel")] {
        let o = pleat(&[
            "tfw",
            path_str(&scene),
            "-o",
            path_str(&out),
            "--levels",
            "1",
            "--qp",
            name,
            "-q",
        ]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{name}: {text}");
        assert!(text.contains(&format!("step solver   {printed}")), "{text}");
        assert!(out.exists());
    }
    // the valley search can be turned off (C: `valley_search = 0`, Python `valley_search=0`)
    let args = [
        "--levels",
        "1",
        "--qp",
        "newton",
        "--no-valley-search",
        "-q",
    ];
    let o = pleat(&[&["tfw", path_str(&scene), "-o", path_str(&out)][..], &args].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = pleat(&["tfw", path_str(&scene), "-o", path_str(&out), "--qp", "cg"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--qp"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A flat `n × n`-vertex grid on [0,1]² as OBJ in `dir/grid.obj` (vertex `j·n + i` at
/// `(i, j)/(n − 1)`).
#[cfg(feature = "wrinkle")]
fn write_grid(dir: &std::path::Path, n: usize) -> std::path::PathBuf {
    use std::fmt::Write as _;
    let mut s = String::new();
    for j in 0..n {
        for i in 0..n {
            let d = (n - 1) as f64;
            let _ = writeln!(s, "v {} {} 0", i as f64 / d, j as f64 / d);
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = j * n + i + 1;
            let _ = writeln!(
                s,
                "f {} {} {}\nf {} {} {}",
                v,
                v + 1,
                v + n + 1,
                v,
                v + n + 1,
                v + n
            );
        }
    }
    let path = dir.join("grid.obj");
    std::fs::write(&path, s).unwrap();
    path
}

/// `--compat-target 0.3` widens the interface of a 90° rotation on a flat grid (the printed
/// report says which width), the other edit flags are accepted, bad values exit 2 naming the
/// flag, and `wrinkle interp --no-locality` solves every vertex.
#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_edit_compat_target_widens_and_interp_no_locality() {
    let dir = scratch_with_octahedron("compat-target");
    let base = write_grid(&dir, 21);
    let (k0, k1) = (dir.join("k0.cwf"), dir.join("k1.cwf"));
    let o = pleat(&[
        "wrinkle",
        "plane-wave",
        path_str(&base),
        "--k",
        "12.566370614359172,0,0",
        "--amplitude",
        "0.01",
        "-o",
        path_str(&k0),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let edit = |extra: &[&str], out: &std::path::Path| {
        let mut args = vec![
            "wrinkle",
            "edit",
            path_str(&base),
            "--cwf",
            path_str(&k0),
            "--region",
            "vertex=220,rings=3,interface=1,rotate=90",
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", path_str(out)]);
        pleat(&args)
    };
    let o = edit(&["--compat-target", "0"], &k1);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("interface rings used [1] (as requested"),
        "{err}"
    );
    let o = edit(
        &[
            "--compat-target",
            "0.3",
            "--max-interface-rings",
            "6",
            "--edit-weight",
            "1",
        ],
        &k1,
    );
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    let used: usize = err
        .split("interface rings used [")
        .nth(1)
        .and_then(|s| s.split(']').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no widths in {err}"));
    assert!((2..=6).contains(&used), "{err}");
    assert!(err.contains("widened while compat RMS > 0.3 rad"), "{err}");
    for (flag, value) in [
        ("--compat-target", "-0.3"),
        ("--compat-target", "NaN"),
        ("--edit-weight", "0.5"),
        ("--max-interface-rings", "0"),
    ] {
        let bad = dir.join("bad.cwf");
        let o = edit(&[flag, value], &bad);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {err}");
        assert!(err.contains(flag), "{err}");
        assert!(!bad.exists());
    }
    for (extra, expect) in [
        (None, "locality held"),
        (Some("--no-locality"), "locality off"),
    ] {
        let anim = dir.join("a.cwfa");
        let mut args = vec![
            "wrinkle",
            "interp",
            path_str(&k0),
            path_str(&k1),
            "--base",
            path_str(&base),
            "--frames",
            "2",
            "--substeps",
            "1",
            "--max-iterations",
            "5",
        ];
        args.extend(extra);
        args.extend_from_slice(&["-o", path_str(&anim)]);
        let o = pleat(&args);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(out.contains(expect), "{out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--start`: `input` on a clean mesh says so in the summary, on a dirty
/// soup fails with the property that fails; an unknown value is a usage error.
#[cfg(feature = "lod")]
#[test]
fn lod_start_option() {
    let dir = std::env::temp_dir().join(format!("pleat-cli-start-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("o.obj");
    let out_s = out.to_str().unwrap();
    let dirty = "assets/dirty_two_boxes.obj";
    let o = pleat(&[
        "lod",
        dirty,
        "--screen-size",
        "20",
        "--start",
        "input",
        "-o",
        out_s,
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("start = input needs a clean input"), "{err}");
    let o = pleat(&[
        "lod",
        dirty,
        "--screen-size",
        "20",
        "--start",
        "sideways",
        "-o",
        out_s,
    ]);
    assert_eq!(o.status.code(), Some(2));
    let o = pleat(&[
        "lod",
        dirty,
        "--screen-size",
        "20",
        "--rounds",
        "2",
        "-o",
        out_s,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!String::from_utf8_lossy(&o.stdout).contains("started from the input"));
    let box_ = dir.join("box.obj");
    let b = pleat::mesh::TriMesh::new(
        vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
        ],
        vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ],
    )
    .unwrap();
    pleat::mesh::io::write_mesh(&box_, &b).unwrap();
    let o = pleat(&[
        "lod",
        box_.to_str().unwrap(),
        "--screen-size",
        "20",
        "--start",
        "input",
        "-o",
        out_s,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("started from the input"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--memory-budget` takes a size with a unit; a bake over it exits 1 with the figure it would
/// need and how to allow it; a budget that fits bakes; a malformed one exits 2.
#[cfg(feature = "lod")]
#[test]
fn memory_budget_option_refuses_and_allows() {
    let dir = std::env::temp_dir().join(format!("pleat-cli-budget-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("lod.obj");
    let lod = |budget: &str| {
        pleat(&[
            "lod",
            "assets/dirty_two_boxes.obj",
            "--screen-size",
            "50",
            "--memory-budget",
            budget,
            "-q",
            "-o",
            out.to_str().unwrap(),
        ])
    };
    let refused = lod("1K");
    let err = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{err}");
    assert!(
        err.contains("MiB") && err.contains("--memory-budget"),
        "the refusal names the need and the option: {err}"
    );
    assert!(!out.exists());
    stdout_of_success(&lod("1GiB"));
    assert!(out.exists());
    for bad in ["lots", "3X", "0", "-1G"] {
        let o = lod(bad);
        assert_eq!(o.status.code(), Some(2), "{bad}: {:?}", o);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
