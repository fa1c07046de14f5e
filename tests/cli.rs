//! The `pleat` binary as a build step uses it: exit codes and output.
#![cfg(feature = "cli")]

use std::process::Command;

fn pleat(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pleat"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run pleat")
}

#[test]
fn check_prints_report_and_exits_zero() {
    let o = pleat(&["check", "assets/dirty_two_boxes.obj"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(s.contains("components          3"), "{s}");
    assert!(s.contains("watertight          no"), "{s}");
}

#[test]
fn check_json_is_one_object() {
    let o = pleat(&["check", "--json", "assets/dirty_two_boxes.obj"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    let t = s.trim();
    assert!(
        t.starts_with('{') && t.ends_with('}') && t.lines().count() == 1,
        "{t}"
    );
    assert!(t.contains("\"n_components\": 3"), "{t}");
    assert!(t.contains("\"self_intersection_free\": false"), "{t}");
}

#[test]
fn unreadable_input_exits_two_with_message() {
    let o = pleat(&["check", "assets/does_not_exist.obj"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does_not_exist.obj"));
}
