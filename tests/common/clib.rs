//! The C toolchain side of the tests that compile C and C++ against the freshly built library
//! (`c_harness`, `doc_examples`): where the crate is, which features it was built with, the
//! shared library built to match, and a strict compile of one source file.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The crate root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The features this test binary was built with, so the library matches.
pub fn features() -> Vec<&'static str> {
    let mut f = Vec::new();
    // `default` is a feature of its own in cargo's fingerprint: without it a default build's
    // nested call would compile the library again (about 3 minutes on 2 cores).
    if cfg!(feature = "default") {
        f.push("default");
    }
    if cfg!(feature = "lod") {
        f.push("lod");
    }
    if cfg!(feature = "cage") {
        f.push("cage");
    }
    if cfg!(feature = "wrinkle") {
        f.push("wrinkle");
    }
    if cfg!(feature = "io-gltf") {
        f.push("io-gltf");
    }
    if cfg!(feature = "bake") {
        f.push("bake");
    }
    if cfg!(feature = "tfw") {
        f.push("tfw");
    }
    // `cli` too: with any feature missing, the nested build below would compile the library and
    // every test target a second time instead of copying what `cargo test` already built.
    if cfg!(feature = "cli") {
        f.push("cli");
    }
    f
}

/// Builds the cdylib (a nested cargo call; `--tests` keeps the dependency features identical to
/// those of `cargo test` — every test target, the CLI's included, takes part in feature
/// unification — and `--profile test` its profile, so after `cargo test` has compiled every unit
/// the call only copies the library out) and returns its directory.
pub fn build_library() -> PathBuf {
    let feats = features().join(",");
    let mut cmd = Command::new(env!("CARGO"));
    cmd.args([
        "build",
        "--lib",
        "--tests",
        "--profile",
        "test",
        "--no-default-features",
    ])
    .current_dir(root());
    if !feats.is_empty() {
        cmd.args(["--features", &feats]);
    }
    let st = cmd.status().expect("run cargo");
    assert!(st.success(), "cargo build of the shared library failed");
    // This test binary lives in <target>/<profile>/deps/.
    let exe = std::env::current_exe().expect("current_exe");
    let dir = exe.parent().and_then(Path::parent).expect("profile dir");
    assert!(
        dir.join("libpleat.so").exists() || dir.join("libpleat.dylib").exists(),
        "no shared library in {}",
        dir.display()
    );
    link_soname(dir);
    dir.to_path_buf()
}

/// The library's SONAME is `libpleat.so.0` (see build.rs); an install provides that name as a
/// symlink, and so does this test, next to cargo's output.
pub fn link_soname(dir: &Path) {
    #[cfg(target_os = "linux")]
    {
        let link = dir.join("libpleat.so.0");
        let _ = std::fs::remove_file(&link);
        // Another test process may make the same link at the same time: either link will do.
        if let Err(e) = std::os::unix::fs::symlink("libpleat.so", &link) {
            assert!(link.exists(), "symlink libpleat.so.0: {e}");
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = dir;
}

/// Whether `tool --version` runs.
pub fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// The `pkg-config --cflags --libs` flags of `lib`, when pkg-config knows it.
pub fn pkg_config(lib: &str) -> Option<Vec<String>> {
    let out = Command::new("pkg-config")
        .args(["--cflags", "--libs", lib])
        .output()
        .ok()?;
    out.status.success().then(|| {
        String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .map(String::from)
            .collect()
    })
}

/// Compiles `src` (C99, or C++17 when `cxx`) with every warning an error against `include/`,
/// `bindings/cpp/` and the library in `libdir` (found at run time through an rpath).
pub fn try_compile(
    src: &Path,
    out: &Path,
    libdir: &Path,
    cxx: bool,
    extra: &[String],
) -> Result<(), String> {
    let cc = if cxx { "c++" } else { "cc" };
    let std = if cxx { "-std=c++17" } else { "-std=c99" };
    let mut cmd = Command::new(
        std::env::var("CC")
            .ok()
            .filter(|_| !cxx)
            .unwrap_or(cc.into()),
    );
    cmd.args([std, "-Wall", "-Wextra", "-Werror", "-pedantic", "-g"])
        .arg(format!("-I{}", root().join("include").display()))
        .arg(format!("-I{}", root().join("bindings/cpp").display()))
        .arg(src)
        .arg("-o")
        .arg(out)
        .arg(format!("-L{}", libdir.display()))
        .arg(format!("-Wl,-rpath,{}", libdir.display()))
        .arg("-lpleat")
        .arg("-lm")
        .args(extra);
    let o = cmd
        .output()
        .map_err(|e| format!("cannot run the compiler: {e}"))?;
    if o.status.success() {
        Ok(())
    } else {
        Err(format!(
            "compiling {} failed:\n{}",
            src.display(),
            String::from_utf8_lossy(&o.stderr)
        ))
    }
}

/// [`try_compile`], failing the test on an error.
pub fn compile(src: &Path, out: &Path, libdir: &Path, cxx: bool, extra: &[String]) {
    if let Err(e) = try_compile(src, out, libdir, cxx, extra) {
        panic!("{e}");
    }
}
