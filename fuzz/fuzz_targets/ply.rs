//! cargo-fuzz target `ply`: the body is `pleat_fuzz::ply` (fuzz/src/lib.rs), which says
//! what it feeds and checks; `tests/fuzz_smoke.rs` runs the same function on stable.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _accepted = pleat_fuzz::ply(data);
});
