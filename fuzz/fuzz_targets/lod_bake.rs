//! cargo-fuzz target `lod_bake`: the body is `pleat_fuzz::lod_bake` (fuzz/src/lib.rs), which says
//! what it feeds and checks; `tests/fuzz_smoke.rs` runs the same function on stable.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _accepted = pleat_fuzz::lod_bake(data);
});
