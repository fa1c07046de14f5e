//! `pleat lod` as a batch build step: many inputs, `--jobs`, atomic outputs,
//! the content-addressed `--cache`, the JSON `--report`, and a corrupt asset that fails its row
//! but not the batch.
#![cfg(all(feature = "cli", feature = "lod"))]

#[path = "common/shapes.rs"]
mod shapes;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pleat(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args(args)
        .output()
        .expect("run pleat")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pleat-batch-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Three small closed meshes in three formats, plus (when `corrupt`) an unparsable OBJ.
fn write_assets(dir: &Path, corrupt: bool) {
    let w = |name: &str, m: &pleat::mesh::TriMesh| {
        pleat::mesh::io::write_mesh(&dir.join(name), m).unwrap();
    };
    w("torus.obj", &shapes::torus(1.0, 0.3, 32, 12));
    w("sphere.off", &shapes::icosphere(1.0, 2));
    w("box.ply", &shapes::box_grid(1.0, 0.5, 0.25, 4));
    if corrupt {
        std::fs::write(dir.join("broken.obj"), "v 0 0 0\nv 1 0\nf 1 2 zz\n").unwrap();
    }
}

fn report(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn row<'a>(r: &'a Value, stem: &str) -> &'a Value {
    r["assets"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["input"].as_str().unwrap().contains(stem))
        .unwrap_or_else(|| panic!("no row for {stem}: {r}"))
}

const GOOD: [&str; 3] = ["torus", "sphere", "box"];

#[test]
fn batch_twice_bakes_nothing_the_second_time_and_a_corrupt_asset_is_a_failed_row() {
    let dir = scratch("cache");
    let assets = dir.join("assets");
    std::fs::create_dir_all(&assets).unwrap();
    write_assets(&assets, true);
    let (out, cache) = (dir.join("out"), dir.join("cache"));
    let pattern = out.join("{stem}_{np}.obj");
    let run = |report: &Path, jobs: &str| {
        pleat(&[
            "lod",
            s(&assets),
            "--screen-size",
            "20,10",
            "--rounds",
            "3",
            "-o",
            s(&pattern),
            "--jobs",
            jobs,
            "--cache",
            s(&cache),
            "--report",
            s(report),
        ])
    };
    let first = run(&dir.join("r1.json"), "2");
    assert_eq!(first.status.code(), Some(1), "a failed asset exits 1");
    let r1 = report(&dir.join("r1.json"));
    assert_eq!(
        (r1["baked"].as_u64(), r1["failed"].as_u64()),
        (Some(3), Some(1))
    );
    let broken = row(&r1, "broken");
    assert_eq!(broken["status"], "failed");
    assert!(
        broken["error"].as_str().unwrap().contains("broken.obj"),
        "{broken}"
    );
    let mut bytes = Vec::new();
    for stem in GOOD {
        let r = row(&r1, stem);
        assert_eq!(
            (r["status"].as_str(), r["cache_hit"].as_bool()),
            (Some("baked"), Some(false))
        );
        assert!(r["error"].is_null() && r["seconds"].as_f64().unwrap() >= 0.0);
        for (level, n) in r["levels"].as_array().unwrap().iter().zip(["20", "10"]) {
            let file = out.join(format!("{stem}_{n}.obj"));
            assert_eq!(level["output"].as_str(), Some(s(&file)));
            let m = pleat::mesh::io::read_mesh(&file).unwrap();
            assert_eq!(level["faces"].as_u64(), Some(m.triangle_count() as u64));
            let check = pleat::verify::MeshReport::compute(&m);
            assert!(check.is_watertight && check.self_intersection_free == Some(true));
            bytes.push(std::fs::read(&file).unwrap());
        }
    }
    // Second run: every good asset comes from the cache, byte for byte; the corrupt one fails.
    let second = run(&dir.join("r2.json"), "3");
    assert_eq!(second.status.code(), Some(1));
    let r2 = report(&dir.join("r2.json"));
    assert_eq!(
        (
            r2["baked"].as_u64(),
            r2["cached"].as_u64(),
            r2["failed"].as_u64()
        ),
        (Some(0), Some(3), Some(1)),
        "{r2}"
    );
    for stem in GOOD {
        let (a, b) = (row(&r1, stem), row(&r2, stem));
        assert_eq!(b["cache_hit"], true);
        assert_eq!(a["faces"], b["faces"]);
    }
    let again: Vec<Vec<u8>> = GOOD
        .iter()
        .flat_map(|stem| ["20", "10"].map(|n| out.join(format!("{stem}_{n}.obj"))))
        .map(|f| std::fs::read(f).unwrap())
        .collect();
    assert!(again == bytes, "cached outputs differ from baked ones");
    // Atomic writes leave no temporary file behind.
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with(".pleat-tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // A changed input is baked again; the others still hit.
    pleat::mesh::io::write_mesh(
        &assets.join("box.ply"),
        &shapes::box_grid(1.0, 0.6, 0.25, 4),
    )
    .unwrap();
    std::fs::remove_file(assets.join("broken.obj")).unwrap();
    let third = run(&dir.join("r3.json"), "1");
    assert!(
        third.status.success(),
        "{}",
        String::from_utf8_lossy(&third.stderr)
    );
    let r3 = report(&dir.join("r3.json"));
    assert_eq!(
        (r3["baked"].as_u64(), r3["cached"].as_u64()),
        (Some(1), Some(2))
    );
    assert_eq!(row(&r3, "box")["status"], "baked");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn batch_outputs_equal_single_bakes_whatever_the_job_count() {
    let dir = scratch("determinism");
    write_assets(&dir, false);
    let inputs: Vec<PathBuf> = ["torus.obj", "sphere.off", "box.ply"]
        .iter()
        .map(|n| dir.join(n))
        .collect();
    let batch = |jobs: &str, out: &str| {
        let pattern = dir.join(out).join("{stem}.obj");
        let mut args = vec!["lod", "--screen-size", "15", "--rounds", "3", "-q"];
        args.extend(inputs.iter().map(|p| s(p)));
        args.extend(["-o", s(&pattern), "--jobs", jobs]);
        let o = pleat(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    batch("1", "j1");
    batch("3", "j3");
    for (input, stem) in inputs.iter().zip(GOOD) {
        let single = dir.join(format!("single_{stem}.obj"));
        let o = pleat(&[
            "lod",
            s(input),
            "--screen-size",
            "15",
            "--rounds",
            "3",
            "-q",
            "-o",
            s(&single),
        ]);
        assert!(o.status.success());
        let expected = std::fs::read(&single).unwrap();
        for out in ["j1", "j3"] {
            let got = std::fs::read(dir.join(out).join(format!("{stem}.obj"))).unwrap();
            assert!(
                got == expected,
                "{out}/{stem}.obj differs from the single bake"
            );
        }
    }
    // An output folder inside the input folder: last run's LODs are not this run's assets.
    let folder = dir.join("nested");
    std::fs::create_dir_all(&folder).unwrap();
    write_assets(&folder, false);
    let nested = folder.join("lod").join("{stem}.obj");
    for _ in 0..2 {
        let o = pleat(&[
            "lod",
            s(&folder),
            "--screen-size",
            "10",
            "--rounds",
            "2",
            "-o",
            s(&nested),
            "--report",
            s(&dir.join("nested.json")),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r = report(&dir.join("nested.json"));
        assert_eq!(r["assets"].as_array().unwrap().len(), 3, "{r}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn manifests_give_per_asset_screen_sizes_and_budgets() {
    let dir = scratch("manifest");
    write_assets(&dir, false);
    std::fs::write(
        dir.join("assets.csv"),
        "# per-asset settings\ninput,screen_size,faces,output,memory_budget\n\
         torus.obj,20;10,,out/torus_{n}.obj,\nsphere.off,12,60,out/sphere.ply,1GiB\nbox.ply,,,,\n",
    )
    .unwrap();
    let default_out = dir.join("out").join("{stem}_default.obj");
    let o = pleat(&[
        "lod",
        "--manifest",
        s(&dir.join("assets.csv")),
        "--screen-size",
        "8",
        "--rounds",
        "3",
        "-o",
        s(&default_out),
        "--report",
        s(&dir.join("r.json")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "torus_20.obj",
        "torus_10.obj",
        "sphere.ply",
        "box_default.obj",
    ] {
        assert!(dir.join("out").join(f).is_file(), "{f}");
    }
    let r = report(&dir.join("r.json"));
    let sphere = &row(&r, "sphere")["levels"][0];
    assert_eq!(sphere["screen_size"].as_f64(), Some(12.0));
    assert!(sphere["faces"].as_u64().unwrap() <= 60, "{sphere}");
    assert_eq!(
        row(&r, "box")["levels"][0]["screen_size"].as_f64(),
        Some(8.0)
    );

    // The same as JSON; a missing input is a failed row, not the end of the batch. Every row
    // names its output, so no -o is needed.
    std::fs::write(
        dir.join("assets.json"),
        r#"[{"input": "torus.obj", "screen_size": [20, 10], "output": "json/t_{np}.obj"},
            {"input": "missing.obj", "screen_size": 9, "output": "json/m.obj"},
            {"input": "box.ply", "screen_size": 20, "output": "json/b.obj",
             "memory_budget": "1K"}]"#,
    )
    .unwrap();
    let o = pleat(&[
        "lod",
        "--manifest",
        s(&dir.join("assets.json")),
        "--rounds",
        "3",
        "--report",
        s(&dir.join("rj.json")),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let r = report(&dir.join("rj.json"));
    assert_eq!(row(&r, "torus")["status"], "baked");
    assert_eq!(row(&r, "missing")["status"], "failed");
    assert!(dir.join("json").join("t_10.obj").is_file());
    // A row's memory budget is its own: 1 KiB refuses the box, naming how to allow it.
    let boxed = row(&r, "box");
    assert_eq!(boxed["status"], "failed");
    assert!(
        boxed["error"].as_str().unwrap().contains("--memory-budget"),
        "{boxed}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn batch_argument_errors_exit_two_before_baking() {
    let dir = scratch("args");
    write_assets(&dir, false);
    // Two assets onto one output file.
    let o = pleat(&[
        "lod",
        s(&dir.join("torus.obj")),
        s(&dir.join("box.ply")),
        "--screen-size",
        "10",
        "-o",
        s(&dir.join("same.obj")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("{stem}"));
    assert!(!dir.join("same.obj").exists());
    // A malformed manifest.
    std::fs::write(dir.join("bad.csv"), "input,colour\ntorus.obj,red\n").unwrap();
    let o = pleat(&[
        "lod",
        "--manifest",
        s(&dir.join("bad.csv")),
        "--screen-size",
        "10",
        "-o",
        "x.obj",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("colour"));
    let _ = std::fs::remove_dir_all(&dir);
}
