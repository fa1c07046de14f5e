//! Fuzzes the `.cwf` reader against a fixed base mesh (an octahedron): no input may panic; an
//! accepted file writes back to text that reads again to the same text (bit-exact round trip).
#![no_main]

use libfuzzer_sys::fuzz_target;
use pleat::wrinkle::io::{cwf_to_string, parse_cwf};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(cwf) = parse_cwf(&text, pleat_fuzz::octahedron(), "fuzz-input") {
        let out = cwf_to_string(&cwf);
        let again = parse_cwf(&out, pleat_fuzz::octahedron(), "round-trip").expect("re-read");
        assert_eq!(cwf_to_string(&again), out);
    }
});
