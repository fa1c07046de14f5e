//! The independent CGAL checker (`../shared/tools`, built by `.ci/run`; path in
//! `$PLEAT_MESHCHECK`) as a test oracle.

use pleat::mesh::TriMesh;

/// Path of the checker binary, when it is installed.
pub fn tool() -> Option<std::path::PathBuf> {
    let tool = std::env::var("PLEAT_MESHCHECK").unwrap_or("/tmp/pleat-tools/meshcheck".into());
    let p = std::path::PathBuf::from(tool);
    p.exists().then_some(p)
}

/// Asserts that the checker finds `m` watertight, manifold and free of self-intersections;
/// does nothing (returns false) when the checker is not installed.
pub fn assert_valid(m: &TriMesh, what: &str) -> bool {
    let Some(tool) = tool() else { return false };
    let dir = std::env::temp_dir().join(format!("pleat-meshcheck-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!(
        "{}.obj",
        what.replace(|c: char| !c.is_alphanumeric(), "_")
    ));
    pleat::mesh::io::write_mesh(&file, m).unwrap();
    let out = std::process::Command::new(&tool)
        .arg(&file)
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&file);
    let json = String::from_utf8_lossy(&out.stdout).replace(' ', "");
    for key in [
        "\"is_watertight\":true",
        "\"is_manifold\":true",
        "\"self_intersection_free\":true",
    ] {
        assert!(
            json.contains(key),
            "{what}: meshcheck disagrees ({key}): {json}"
        );
    }
    true
}
