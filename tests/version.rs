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
