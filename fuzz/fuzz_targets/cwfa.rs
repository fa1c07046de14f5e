//! Fuzzes the `.cwfa` animation reader against a fixed base mesh (an octahedron): no input may
//! panic or exhaust memory; an accepted animation evaluates its first, middle and last frames
//! and writes back to text that reads again to the same text.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pleat::wrinkle::animation::{animation_to_string, parse_animation};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(anim) = parse_animation(&text, pleat_fuzz::octahedron(), "fuzz-input") {
        let last = anim.frame_count() - 1;
        for i in [0, last / 2, last] {
            anim.frame(i).expect("an existing frame");
        }
        assert!(anim.frame(last + 1).is_err() || last == usize::MAX);
        anim.frame_at(0.5).expect("t = 0.5");
        let out = animation_to_string(&anim);
        let again = parse_animation(&out, pleat_fuzz::octahedron(), "round-trip").expect("re-read");
        assert_eq!(animation_to_string(&again), out);
    }
});
