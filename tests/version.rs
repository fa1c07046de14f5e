//! `pleat_version()` must say what Cargo.toml says, and the ABI version must match the header.

use std::ffi::CStr;

#[test]
fn version_matches_cargo_toml() {
    let toml = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml")).unwrap();
    let declared = toml
        .lines()
        .find_map(|l| l.strip_prefix("version = "))
        .map(|v| v.trim().trim_matches('"').to_string())
        .expect("version in Cargo.toml");
    let reported = unsafe { CStr::from_ptr(pleat::ffi::pleat_version()) };
    assert_eq!(reported.to_str().unwrap(), declared);
}

#[test]
fn abi_version_matches_header() {
    let header =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/pleat.h")).unwrap();
    let line = format!(
        "#define PLEAT_ABI_VERSION {}",
        pleat::ffi::pleat_abi_version()
    );
    assert!(header.contains(&line), "header lacks `{line}`");
}

/// Cargo.toml's `[package]` version.
fn cargo_version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

fn repo_file(path: &str) -> String {
    std::fs::read_to_string(format!("{}/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// `pleat --version` prints the package version (clap's `version` is `CARGO_PKG_VERSION`).
#[cfg(feature = "cli")]
#[test]
fn cli_version_matches_cargo_toml() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_pleat"))
        .arg("--version")
        .output()
        .unwrap();
    assert!(o.status.success());
    let line = String::from_utf8_lossy(&o.stdout).trim().to_string();
    assert_eq!(line, format!("pleat {}", cargo_version()));
    let reported = unsafe { CStr::from_ptr(pleat::ffi::pleat_version()) };
    assert_eq!(reported.to_str().unwrap(), cargo_version());
}

/// packaging/install.sh writes the pkg-config `Version:` and the CMake `PACKAGE_VERSION` from
/// the version it reads out of Cargo.toml: run its own reading line, and check the templates
/// and the substitution. (.ci/packaging.sh checks the installed files: `pkg-config
/// --modversion`, `find_package(pleat X.Y.Z EXACT)`.)
#[test]
fn install_script_versions_come_from_cargo_toml() {
    let script = repo_file("packaging/install.sh");
    let line = script
        .lines()
        .find(|l| l.starts_with("version=$("))
        .expect("install.sh reads the version in one `version=$(...)` line");
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "root='{}'; {line}; echo \"$version\"",
            env!("CARGO_MANIFEST_DIR")
        ))
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), cargo_version());
    assert!(script.contains("s|@VERSION@|$version|g"));
    assert!(repo_file("packaging/pleat.pc.in").contains("\nVersion: @VERSION@\n"));
    assert!(repo_file("packaging/pleatConfigVersion.cmake.in")
        .contains("set(PACKAGE_VERSION \"@VERSION@\")"));
}

/// The Python package's version is setup.py's `cargo_version()` (pyproject.toml declares it
/// dynamic): run that function out of setup.py (without running setup()).
#[test]
fn python_package_version_comes_from_cargo_toml() {
    let pyproject = repo_file("bindings/python/pyproject.toml");
    assert!(pyproject.contains("dynamic = [\"version\"]"), "{pyproject}");
    let setup = format!("{}/bindings/python/setup.py", env!("CARGO_MANIFEST_DIR"));
    let code = format!(
        "import ast, os, re, sys\n\
         src = open({setup:?}).read()\n\
         fn = [n for n in ast.parse(src).body if getattr(n, 'name', '') == 'cargo_version']\n\
         ns = {{'os': os, 're': re, 'sys': sys, 'ROOT': {root:?}}}\n\
         exec(compile(ast.Module(body=fn, type_ignores=[]), 'setup.py', 'exec'), ns)\n\
         print(ns['cargo_version']())\n",
        root = env!("CARGO_MANIFEST_DIR")
    );
    let Ok(out) = std::process::Command::new("python3")
        .arg("-c")
        .arg(code)
        .output()
    else {
        eprintln!("SKIPPED: no python3");
        return;
    };
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), cargo_version());
    assert!(
        repo_file("bindings/python/pleat/__init__.py").contains("__version__ = version()"),
        "pleat.__version__ is the library's pleat_version()"
    );
}
