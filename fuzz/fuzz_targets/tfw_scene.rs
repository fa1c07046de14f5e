//! Fuzzes the TFW scene reader (issue 15 part 1: "TFW scene files once they exist"): the JSON
//! bytes go through the Rust parser (`Scene::from_json_str`) and the C entry point
//! (`pleat_tfw_scene_from_json`), which must agree on acceptance; no input may panic. An
//! accepted scene writes back to JSON that reads again, assembles to a model or a clear error,
//! and, when tiny (≤ 64 vertices), gets a bounded base solve (5 Newton iterations).
#![no_main]

use libfuzzer_sys::fuzz_target;
use pleat::ffi::{pleat_tfw_scene_destroy, pleat_tfw_scene_from_json, PleatStatus};
use pleat::tfw::{solve_base, BaseOptions, Scene};

/// Vertices up to which an accepted scene also gets its base solve.
const SOLVE_MAX_VERTICES: usize = 64;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let rust = Scene::from_json_str(text);
    if !text.contains('\0') {
        let c_text = std::ffi::CString::new(text).expect("no interior NUL");
        let mut scene = std::ptr::null_mut();
        // SAFETY: a NUL-terminated string and a writable out slot.
        let status = unsafe { pleat_tfw_scene_from_json(c_text.as_ptr(), &mut scene) };
        assert_ne!(
            status,
            PleatStatus::Internal,
            "a panic behind the C entry point"
        );
        assert_eq!(
            status == PleatStatus::Ok,
            rust.is_ok(),
            "the C and Rust parsers disagree: {status:?} vs {:?}",
            rust.as_ref().err()
        );
        // SAFETY: NULL or a scene made above.
        unsafe { pleat_tfw_scene_destroy(scene) };
    }
    let Ok(scene) = rust else {
        return;
    };
    let json = scene.to_json_string();
    Scene::from_json_str(&json).expect("an accepted scene's JSON reads again");
    let Ok(model) = scene.assemble() else {
        return;
    };
    if model.positions.len() <= SOLVE_MAX_VERTICES {
        let options = BaseOptions {
            max_iterations: 5,
            ..BaseOptions::default()
        };
        // numerical trouble is a status of the result, never a panic
        let _ = solve_base(&model, &options, &mut |_| true);
    }
});
