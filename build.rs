//! Gives the shared library a SONAME with the ABI major version, so loaders can tell ABI
//! generations apart and two plugins can carry different versions.
fn main() {
    let target = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target == "linux" || target == "android" || target == "freebsd" {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libpleat.so.0");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
