//! Determinism across thread counts and entry points: the bytes of a LOD,
//! a cage and an evaluated wrinkle field are identical for 1, 2 and 8 worker threads, and
//! identical between the CLI (`pleat lod|cage|wrinkle eval`, pool size from
//! `RAYON_NUM_THREADS`) and the C API (`pleat_set_thread_count`) for the same call.
//!
//! The per-library tests (tests/lod.rs, tests/wrinkle_evaluate.rs, tests/wrinkle_interp.rs)
//! compare thread counts through the Rust API; this file compares the files the two other
//! entry points write, which is what a build farm diffs.
#![cfg(all(feature = "cli", feature = "cage", feature = "wrinkle"))]

#[path = "common/shapes.rs"]
mod shapes;

use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::ptr;

use pleat::ffi::*;

const THREADS: [u32; 3] = [1, 2, 8];
/// Optimization rounds of every bake (the CLI's `--rounds`): enough to run every stage.
const ROUNDS: u32 = 6;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pleat-determinism-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn c_path(p: &Path) -> CString {
    CString::new(p.to_str().unwrap()).unwrap()
}

fn ok(st: PleatStatus, what: &str) {
    let msg = unsafe { std::ffi::CStr::from_ptr(pleat_last_error()) };
    assert_eq!(st, PleatStatus::Ok, "{what}: {}", msg.to_string_lossy());
}

/// The CLI with `threads` rayon workers; returns the bytes of `out`.
fn cli(args: &[&str], threads: u32, out: &Path) -> Vec<u8> {
    let _ = std::fs::remove_file(out);
    let o = Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("run pleat");
    assert!(
        o.status.success(),
        "pleat {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    std::fs::read(out).unwrap()
}

/// Reads `input`, bakes a LOD (or cage) at `np` through the C API with `threads` workers and
/// returns the bytes of the `.ply` it writes.
fn c_bake(input: &Path, np: f64, cage: bool, threads: u32, out: &Path) -> Vec<u8> {
    unsafe {
        ok(pleat_set_thread_count(threads), "thread count");
        let mut mesh: *mut PleatMesh = ptr::null_mut();
        ok(
            pleat_mesh_read_file(c_path(input).as_ptr(), &mut mesh),
            "read",
        );
        let mut p = pleat_lod_params_default();
        p.screen_size = np;
        p.max_rounds = ROUNDS;
        let mut lod: *mut PleatMesh = ptr::null_mut();
        let st = if cage {
            pleat_cage_generate(mesh, &p, None, ptr::null_mut(), &mut lod, ptr::null_mut())
        } else {
            pleat_lod_generate(mesh, &p, None, ptr::null_mut(), &mut lod, ptr::null_mut())
        };
        ok(st, "bake");
        ok(pleat_mesh_write_file(lod, c_path(out).as_ptr()), "write");
        pleat_mesh_destroy(lod);
        pleat_mesh_destroy(mesh);
        ok(pleat_set_thread_count(0), "thread count");
    }
    std::fs::read(out).unwrap()
}

/// Evaluates the `.cwf` at `cwf` on `base` through the C API (3 levels, scale 1) and returns
/// the bytes of the `.ply` it writes.
fn c_wrinkle(base: &Path, cwf: &Path, threads: u32, out: &Path) -> Vec<u8> {
    unsafe {
        ok(pleat_set_thread_count(threads), "thread count");
        let mut mesh: *mut PleatMesh = ptr::null_mut();
        ok(
            pleat_mesh_read_file(c_path(base).as_ptr(), &mut mesh),
            "read",
        );
        let mut field: *mut PleatCwf = ptr::null_mut();
        ok(
            pleat_cwf_read_file(mesh, c_path(cwf).as_ptr(), &mut field),
            "read cwf",
        );
        let mut p = pleat_wrinkle_eval_params_default();
        p.levels = 3;
        let mut wrinkled: *mut PleatMesh = ptr::null_mut();
        ok(
            pleat_cwf_evaluate(
                field,
                &p,
                None,
                ptr::null_mut(),
                &mut wrinkled,
                ptr::null_mut(),
                ptr::null_mut(),
            ),
            "evaluate",
        );
        ok(
            pleat_mesh_write_file(wrinkled, c_path(out).as_ptr()),
            "write",
        );
        pleat_mesh_destroy(wrinkled);
        pleat_cwf_destroy(field);
        pleat_mesh_destroy(mesh);
        ok(pleat_set_thread_count(0), "thread count");
    }
    std::fs::read(out).unwrap()
}

/// One test, because `pleat_set_thread_count` is process-wide.
#[test]
fn lod_cage_and_wrinkle_bytes_equal_for_1_2_8_threads_via_cli_and_c_api() {
    let dir = scratch("all");
    let input = dir.join("torus.ply");
    // ≥ 2048 offset faces at n_p = 100, so the parallel simplification batches run
    pleat::mesh::io::write_mesh(&input, &shapes::torus(1.0, 0.3, 48, 16)).unwrap();
    let input_s = input.to_str().unwrap();
    for (cmd, cage) in [("lod", false), ("cage", true)] {
        let reference = c_bake(&input, 100.0, cage, 1, &dir.join("c1.ply"));
        for t in THREADS {
            let c = c_bake(&input, 100.0, cage, t, &dir.join(format!("c{t}.ply")));
            assert!(
                c == reference,
                "{cmd}: C API bytes differ between 1 and {t} threads"
            );
            let out = dir.join(format!("cli{t}.ply"));
            let args = [
                cmd,
                input_s,
                "--screen-size",
                "100",
                "--rounds",
                &ROUNDS.to_string(),
                "-q",
                "-o",
                out.to_str().unwrap(),
            ];
            assert!(
                cli(&args, t, &out) == reference,
                "{cmd}: CLI with {t} threads differs from the C API"
            );
        }
        println!(
            "{cmd}: {} bytes identical for 1, 2, 8 threads, CLI and C API",
            reference.len()
        );
    }

    let base = dir.join("base.ply");
    pleat::mesh::io::write_mesh(&base, &shapes::torus(1.0, 0.4, 24, 12)).unwrap();
    let cwf = dir.join("wave.cwf");
    let cwf_s = cwf.to_str().unwrap();
    let base_s = base.to_str().unwrap();
    let wave = [
        "wrinkle",
        "plane-wave",
        base_s,
        "--k",
        "9,4,7",
        "--amplitude",
        "0.02",
        "-o",
        cwf_s,
    ];
    cli(&wave, 1, &cwf);
    let reference = c_wrinkle(&base, &cwf, 1, &dir.join("w1.ply"));
    for t in THREADS {
        let c = c_wrinkle(&base, &cwf, t, &dir.join(format!("w{t}.ply")));
        assert!(
            c == reference,
            "wrinkle: C API bytes differ between 1 and {t} threads"
        );
        let out = dir.join(format!("wcli{t}.ply"));
        let args = [
            "wrinkle",
            "eval",
            base_s,
            "--cwf",
            cwf_s,
            "--levels",
            "3",
            "-o",
            out.to_str().unwrap(),
        ];
        assert!(
            cli(&args, t, &out) == reference,
            "wrinkle eval: CLI with {t} threads differs from the C API"
        );
    }
    println!(
        "wrinkle eval: {} bytes identical for 1, 2, 8 threads, CLI and C API",
        reference.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
