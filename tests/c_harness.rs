//! Builds every C program in `examples_c/` against the freshly built shared library and runs it,
//! so `cargo test` alone covers the C ABI. Also compiles the header in strict C99 and C++17.
//!
//! - Programs whose name starts with `assimp_` are built only when `pkg-config` finds assimp
//!   (Debian: `apt-get install libassimp-dev`); otherwise they are skipped with a loud message.
//! - When `valgrind` is on PATH (and `PLEAT_NO_VALGRIND` is unset) the programs also run under
//!   memcheck: any invalid access or definite leak fails the test (`examples_c/valgrind.supp`
//!   suppresses the leaks of the vendored xatlas only). Every program that exercises the
//!   boundary (misuse, transfer, wrinkle, offset, checks, C++ RAII) does so in every run; the
//!   four that bake for tens of seconds under memcheck ([`LONG_UNDER_MEMCHECK`]) only with
//!   `PLEAT_FULL_TESTS=1`, which `.ci/run` sets: they call the same entry points with larger
//!   inputs, and they cost a first `cargo test` two minutes.
//! - The programs run side by side, one per core (memcheck runs a program on one core): the
//!   harness's wall time is about the longest program's plus the rest shared among the cores.

#[path = "common/clib.rs"]
mod clib;

use clib::{build_library, compile, have, pkg_config, root};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `exe` (under memcheck when `valgrind`) from the crate root and returns its stdout and
/// stderr, or the failure as a message with the same text.
fn run(exe: &Path, valgrind: bool) -> Result<String, String> {
    let mut cmd = if valgrind {
        let mut c = Command::new("valgrind");
        c.args([
            "--quiet",
            "--error-exitcode=99",
            "--leak-check=full",
            "--errors-for-leak-kinds=definite",
            "--show-leak-kinds=definite",
        ])
        // Leaks inside the vendored xatlas (see the file's comment).
        .arg(format!(
            "--suppressions={}",
            root().join("examples_c/valgrind.supp").display()
        ))
        .arg(exe)
        // programs that bake may shrink their workload under memcheck (see lod_chain.c)
        .env("PLEAT_HARNESS_MEMCHECK", "1");
        c
    } else {
        Command::new(exe)
    };
    let o = cmd.current_dir(root()).output().expect("run C program");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    if o.status.success() {
        Ok(text)
    } else {
        Err(format!(
            "{text}{} failed (valgrind: {valgrind}, status {:?})",
            exe.display(),
            o.status
        ))
    }
}

/// Runs every `(exe, valgrind)` job on as many workers as the machine has cores (at most 4):
/// memcheck runs a program on one core, and the programs are independent (each writes its own
/// files). Prints each program's output as it ends and returns the failures' messages.
fn run_all(jobs: &[(PathBuf, bool)]) -> Vec<String> {
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((exe, valgrind)) = jobs.get(i) else {
                    break;
                };
                match run(exe, *valgrind) {
                    Ok(text) => print!("{text}"),
                    Err(msg) => {
                        print!("{msg}");
                        failures.lock().unwrap().push(msg);
                    }
                }
            });
        }
    });
    failures.into_inner().unwrap()
}

/// The programs that bake for tens of seconds under memcheck (measured 2026-12-07 on 2 cores:
/// bake_lod 44 s, lod_chain 40 s, tfw 26 s, bake_raii 19 s; every other program below 9 s),
/// memchecked only with `PLEAT_FULL_TESTS=1` (module docs).
const LONG_UNDER_MEMCHECK: [&str; 4] = ["bake_lod", "lod_chain", "tfw", "bake_raii"];

#[test]
fn c_programs_pass() {
    if !have("cc") {
        println!("SKIPPED: no C compiler `cc` on PATH; the C harness did not run");
        return;
    }
    let libdir = build_library();
    let out_dir = libdir.join("c-harness");
    std::fs::create_dir_all(&out_dir).unwrap();
    let valgrind = std::env::var_os("PLEAT_NO_VALGRIND").is_none() && have("valgrind");
    let full = std::env::var_os("PLEAT_FULL_TESTS").is_some();
    if valgrind && !full {
        println!(
            "NOTE: {} run without memcheck (PLEAT_FULL_TESTS=1 adds it, as .ci/run does)",
            LONG_UNDER_MEMCHECK.join(", ")
        );
    }
    if !valgrind {
        println!(
            "NOTE: valgrind not found (apt-get install valgrind): C programs run without memcheck"
        );
    }
    let assimp = pkg_config("assimp");
    let mut srcs: Vec<PathBuf> = std::fs::read_dir(root().join("examples_c"))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "c" || x == "cpp"))
        .collect();
    srcs.sort();
    let mut jobs = Vec::new();
    for src in &srcs {
        let stem = src.file_stem().unwrap().to_string_lossy().to_string();
        let cxx = src.extension().is_some_and(|x| x == "cpp");
        let mut extra = Vec::new();
        if stem.starts_with("assimp_") {
            match &assimp {
                Some(flags) => extra.extend(flags.iter().cloned()),
                None => {
                    println!("SKIPPED: {stem} (assimp not found by pkg-config; apt-get install libassimp-dev)");
                    continue;
                }
            }
        }
        if stem == "threads" || stem == "lod_chain" {
            extra.push("-pthread".into());
        }
        let exe = out_dir.join(&stem);
        compile(src, &exe, &libdir, cxx, &extra);
        // threads.c bakes 17 LODs on 4 host threads: minutes under memcheck, which serializes
        // threads; exhaustion.c builds 10⁶-element inputs. They run natively here and under
        // ASan (threads.c also TSan) in .ci/asan.sh.
        let memcheck = valgrind
            && stem != "threads"
            && stem != "exhaustion"
            && (full || !LONG_UNDER_MEMCHECK.contains(&stem.as_str()));
        jobs.push((exe, memcheck));
    }
    assert!(!jobs.is_empty(), "no C program ran");
    let failures = run_all(&jobs);
    assert!(
        failures.is_empty(),
        "C programs failed:\n{}",
        failures.join("\n")
    );
    run_python_bindings(&libdir);
}

/// Runs the ctypes package's tests against the same library.
fn run_python_bindings(libdir: &Path) {
    if !have("python3") {
        println!("SKIPPED: python3 not found; the Python bindings were not tested");
        return;
    }
    let o = Command::new("python3")
        .arg(root().join("bindings/python/tests/test_pleat.py"))
        .env("PLEAT_LIBRARY", libdir.join("libpleat.so"))
        .output()
        .expect("run python3");
    print!("{}", String::from_utf8_lossy(&o.stdout));
    eprint!("{}", String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "Python binding tests failed");
}

#[test]
fn header_compiles_strict_c99_and_cxx17() {
    if !have("cc") {
        println!("SKIPPED: no C compiler");
        return;
    }
    let dir = std::env::temp_dir().join(format!("pleat-hdr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let c = dir.join("h.c");
    std::fs::write(
        &c,
        "#include \"pleat.h\"\nint main(void){return PLEAT_STATUS_OK;}\n",
    )
    .unwrap();
    for (cc, std, src) in [("cc", "-std=c99", &c), ("c++", "-std=c++17", &c)] {
        if !have(cc) {
            println!("SKIPPED: {cc} not found");
            continue;
        }
        let mut cmd = Command::new(cc);
        if cc == "c++" {
            cmd.args(["-x", "c++"]);
        }
        let o = cmd
            .args([
                std,
                "-Wall",
                "-Wextra",
                "-Werror",
                "-pedantic",
                "-fsyntax-only",
            ])
            .arg(format!("-I{}", root().join("include").display()))
            .arg(src)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{cc} {std}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}
