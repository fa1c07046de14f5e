//! The committed `include/pleat.h` must be exactly what cbindgen generates from `src/ffi/`.
//! Regenerate with `PLEAT_BLESS=1 cargo test --test header`.

use std::path::PathBuf;

fn generate() -> String {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut out = Vec::new();
    // Only src/ffi/ is the C ABI: parse it alone, so public Rust constants elsewhere in the
    // crate never leak into the header.
    cbindgen::Builder::new()
        .with_src(root.join("src/ffi/mod.rs"))
        .with_config(config)
        .generate()
        .expect("cbindgen failed")
        .write(&mut out);
    String::from_utf8(out).expect("utf8 header")
}

#[test]
fn committed_header_is_current() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("include/pleat.h");
    let fresh = generate();
    if std::env::var_os("PLEAT_BLESS").is_some() {
        std::fs::write(&path, &fresh).expect("write include/pleat.h");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "include/pleat.h is stale: run `PLEAT_BLESS=1 cargo test --test header` and commit it"
    );
}
