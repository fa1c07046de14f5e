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
        let r = pleat::mesh::MeshReport::compute(&m);
        assert!(r.is_watertight && r.self_intersection_free == Some(true));
        assert!(m.triangle_count() < torus.triangle_count());
    }
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
