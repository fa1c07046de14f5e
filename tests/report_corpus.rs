//! `MeshReport` on every mesh of the shared corpus (`../shared/meshes`), compared with
//!
//! 1. the independent checker `meshcheck` (CGAL 5.5) run on the same file, when its binary is
//!    found (`$PLEAT_MESHCHECK`, `/tmp/pleat-tools/meshcheck`, `../shared/tools/meshcheck`,
//!    `../../shared/tools/meshcheck`): every key both JSONs share must agree — integers, flags,
//!    per-component lists and `null`s exactly, floats to 1e-7 relative (meshcheck prints 10
//!    significant digits). The keys the brief requires (components, boundary and non-manifold
//!    edges, watertight, manifold, self-intersection-free) are among them. Not compared:
//!    `n_faces` (meshcheck counts file polygons before fan triangulation; `n_triangles` is
//!    compared).
//! 2. `MANIFEST.csv`, for the columns whose meaning is ours:
//!    `n_faces` = triangles, `n_vertices` = referenced vertices, `n_unreferenced_vertices` =
//!    `n_isolated_vertices`, `n_components`, `n_boundary_edges`, `n_nonmanifold_edges`,
//!    `is_watertight`, `n_duplicate_faces`, `n_coincident_vertices`, `n_inconsistent_edges` =
//!    `n_misoriented_manifold_edges` (two-sided edges whose sides run the same way),
//!    `is_winding_consistent` = that count is 0, `bbox_diag` (6 significant digits).
//!    Columns with another meaning, checked only as stated: `n_degenerate_faces` counts faces
//!    below an area tolerance, so it is ≥ our exact count (equal except on
//!    `dirty_synth_degenerate_s1`: 22 exactly collinear + 28 slivers of area < 1e-17);
//!    `euler` agrees with `euler_characteristic_total` on every file without degenerate faces;
//!    `self_intersects` / `n_self_intersecting_faces` come from a different test (e.g. 0 on
//!    `dirty_thingi10k_42722`, where CGAL finds 19 pairs, 4 of them folded-over neighbours and
//!    5 disjoint faces crossing) and are not compared; `n_sharp_edges_60deg` is not computed.
//!
//! Skips with a message when the corpus is absent; the meshcheck part skips loudly when the
//! binary is absent.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use pleat::mesh::io::read_mesh;
use pleat::report::StageTimes;
use pleat::verify::{MeshReport, ReportOptions};

/// Keys compared exactly between our JSON and meshcheck's.
const EXACT_KEYS: &[&str] = &[
    "n_vertices",
    "n_triangles",
    "welded",
    "n_duplicate_points",
    "n_referenced_vertices",
    "n_isolated_vertices",
    "n_degenerate_faces",
    "n_combinatorially_degenerate_faces",
    "n_duplicate_faces",
    "n_edges",
    "n_boundary_edges",
    "n_nonmanifold_edges",
    "max_faces_per_edge",
    "n_misoriented_edges",
    "n_nonmanifold_vertices",
    "is_closed",
    "is_edge_manifold",
    "is_vertex_manifold",
    "is_manifold",
    "is_watertight",
    "consistently_oriented",
    "is_orientable",
    "n_components",
    "euler_characteristic",
    "euler_characteristic_total",
    "genus",
    "total_genus",
    "n_inward_oriented_components",
    "n_self_intersecting_pairs",
    "n_degenerate_faces_welded",
    "self_intersection_free",
];

/// Keys compared as floating-point numbers (or lists of them), relative tolerance 1e-7.
const FLOAT_KEYS: &[&str] = &[
    "surface_area",
    "signed_volume",
    "bbox_min",
    "bbox_max",
    "bbox_diagonal",
];

#[test]
fn corpus_agrees_with_meshcheck_and_manifest() {
    let Some(dir) = corpus_dir() else { return };
    let checker = meshcheck_binary();
    let rows = manifest(&dir);
    assert_eq!(rows.len(), 25, "MANIFEST.csv rows");
    let mut table = vec![format!(
        "{:<32} {:>7} {:>5} {:>6} {:>5} {:>4} {:>4} {:>4} {:>8} {:>7}  {}",
        "file",
        "faces",
        "comp",
        "bound",
        "nm-e",
        "wt",
        "man",
        "sif",
        "si-pairs",
        "ours s",
        "meshcheck"
    )];
    let mut failures = Vec::new();
    for row in &rows {
        let name = &row["path"];
        let path = dir.join(name);
        // Start the checker first so it runs while we compute.
        let child = checker.as_ref().map(|c| {
            Command::new(c)
                .arg(&path)
                .stdout(Stdio::piped())
                .spawn()
                .expect("run meshcheck")
        });
        let mesh = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut stats = StageTimes::default();
        let report = MeshReport::compute_timed(&mesh, &ReportOptions::default(), &mut stats);
        let ours = report.to_json();
        let mut problems = compare_with_manifest(&report, row);
        let verdict = match child {
            Some(child) => {
                let out = child.wait_with_output().expect("meshcheck output");
                let theirs = String::from_utf8_lossy(&out.stdout).to_string();
                let diffs = compare_with_meshcheck(&ours, &theirs);
                let verdict = if diffs.is_empty() {
                    "agrees".to_string()
                } else {
                    format!("{} diffs", diffs.len())
                };
                problems.extend(diffs);
                verdict
            }
            None => "not run".to_string(),
        };
        let yn = |b: bool| if b { "yes" } else { "no" };
        table.push(format!(
            "{:<32} {:>7} {:>5} {:>6} {:>5} {:>4} {:>4} {:>4} {:>8} {:>7.2}  {}",
            name,
            report.n_faces,
            report.n_components,
            report.n_boundary_edges,
            report.n_nonmanifold_edges,
            yn(report.is_watertight),
            yn(report.is_manifold),
            yn(report.self_intersection_free == Some(true)),
            report.n_self_intersecting_pairs.unwrap_or(0),
            stats.total(),
            verdict
        ));
        failures.extend(problems.into_iter().map(|p| format!("{name}: {p}")));
    }
    println!("{}", table.join("\n"));
    assert!(
        failures.is_empty(),
        "disagreements:\n{}",
        failures.join("\n")
    );
}

// ------------------------------------------------------------------------------- meshcheck ----

/// Every shared key: exact for integers, flags, lists and nulls; 1e-7 relative for floats.
fn compare_with_meshcheck(ours: &str, theirs: &str) -> Vec<String> {
    let mut diffs = Vec::new();
    if json_value(theirs, "load_ok") != Some("true") {
        return vec![format!("meshcheck failed: {theirs}")];
    }
    for key in EXACT_KEYS {
        let (a, b) = (json_value(ours, key), json_value(theirs, key));
        if a.is_none() || a != b {
            diffs.push(format!("{key}: ours {a:?}, meshcheck {b:?}"));
        }
    }
    for key in FLOAT_KEYS {
        let (a, b) = (json_value(ours, key), json_value(theirs, key));
        let (fa, fb) = (a.map(numbers), b.map(numbers));
        let close = match (&fa, &fb) {
            (Some(x), Some(y)) => {
                x.len() == y.len() && x.iter().zip(y).all(|(p, q)| close(*p, *q, 1e-7))
            }
            _ => false,
        };
        if !close {
            diffs.push(format!("{key}: ours {a:?}, meshcheck {b:?}"));
        }
    }
    diffs
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-30)
}

/// The numbers in a JSON scalar or flat list.
fn numbers(v: &str) -> Vec<f64> {
    v.trim_matches(|c| c == '[' || c == ']')
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap_or(f64::NAN))
        .collect()
}

/// The raw text of the value of top-level `key` in a one-line JSON object (scalars and flat
/// lists, as both writers produce).
fn json_value<'a>(json: &'a str, key: &str) -> Option<&'a str> {
    let pat = format!("\"{key}\": ");
    let start = json.find(&pat)? + pat.len();
    let rest = &json[start..];
    let end = if rest.starts_with('[') {
        rest.find(']')? + 1
    } else if let Some(text) = rest.strip_prefix('"') {
        text.find('"')? + 2
    } else {
        rest.find([',', '}'])?
    };
    Some(rest[..end].trim())
}

/// `$PLEAT_MESHCHECK`, else the places the tools README builds it.
fn meshcheck_binary() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let candidates = [
        std::env::var_os("PLEAT_MESHCHECK").map(PathBuf::from),
        Some(PathBuf::from("/tmp/pleat-tools/meshcheck")),
        Some(root.join("../shared/tools/meshcheck")),
        Some(root.join("../../shared/tools/meshcheck")),
    ];
    let found = candidates.into_iter().flatten().find(|p| p.is_file());
    if found.is_none() {
        let bar = "!".repeat(100);
        println!(
            "{bar}\n!!! meshcheck NOT FOUND: the comparison with the independent checker is SKIPPED.\n\
             !!! Build it (see ../shared/tools/README.md) and/or set PLEAT_MESHCHECK=/path/to/meshcheck.\n{bar}"
        );
    }
    found
}

// -------------------------------------------------------------------------------- manifest ----

/// The columns of MANIFEST.csv whose meaning matches the report (see the file docs).
fn compare_with_manifest(r: &MeshReport, row: &HashMap<String, String>) -> Vec<String> {
    let int = |k: &str| -> usize {
        row[k]
            .parse()
            .unwrap_or_else(|_| panic!("column {k} = {:?}", row[k]))
    };
    let flag = |k: &str| row[k] == "True";
    let mut diffs = Vec::new();
    let mut check = |what: &str, ours: String, theirs: String| {
        if ours != theirs {
            diffs.push(format!("MANIFEST {what}: ours {ours}, manifest {theirs}"));
        }
    };
    check("n_faces", r.n_faces.to_string(), int("n_faces").to_string());
    check(
        "n_vertices",
        r.n_referenced_vertices.to_string(),
        int("n_vertices").to_string(),
    );
    check(
        "n_unreferenced_vertices",
        r.n_isolated_vertices.to_string(),
        int("n_unreferenced_vertices").to_string(),
    );
    check(
        "n_components",
        r.n_components.to_string(),
        int("n_components").to_string(),
    );
    check(
        "n_boundary_edges",
        r.n_boundary_edges.to_string(),
        int("n_boundary_edges").to_string(),
    );
    check(
        "n_nonmanifold_edges",
        r.n_nonmanifold_edges.to_string(),
        int("n_nonmanifold_edges").to_string(),
    );
    check(
        "is_watertight",
        r.is_watertight.to_string(),
        flag("is_watertight").to_string(),
    );
    check(
        "n_duplicate_faces",
        r.n_duplicate_faces.to_string(),
        int("n_duplicate_faces").to_string(),
    );
    check(
        "n_coincident_vertices",
        r.n_coincident_vertices.to_string(),
        int("n_coincident_vertices").to_string(),
    );
    check(
        "n_inconsistent_edges",
        r.n_misoriented_manifold_edges.to_string(),
        int("n_inconsistent_edges").to_string(),
    );
    check(
        "is_winding_consistent",
        (r.n_misoriented_manifold_edges == 0).to_string(),
        flag("is_winding_consistent").to_string(),
    );
    let diag: f64 = row["bbox_diag"].parse().unwrap();
    check(
        "bbox_diag",
        close(r.bbox_diagonal, diag, 5e-6).to_string(),
        "true".to_string(),
    );
    let degenerate = int("n_degenerate_faces");
    check(
        "n_degenerate_faces ≥ exact count",
        (degenerate >= r.n_degenerate_faces).to_string(),
        "true".to_string(),
    );
    if degenerate == 0 {
        check(
            "euler",
            r.euler_characteristic_total.to_string(),
            row["euler"].clone(),
        );
    }
    diffs
}

/// The shared corpus: `$PLEAT_MESHES` when set, else `../shared/meshes` from the crate root
/// (the main checkout), else `../../shared/meshes` (a worktree under `/work/wt/`).
fn corpus_dir() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let candidates = [
        std::env::var_os("PLEAT_MESHES").map(PathBuf::from),
        Some(PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/meshes"
        ))),
        Some(root.join("../../shared/meshes")),
    ];
    let found = candidates
        .into_iter()
        .flatten()
        .find(|d| d.join("MANIFEST.csv").is_file());
    if found.is_none() {
        println!("SKIPPED: the mesh corpus ../shared/meshes was not found (set PLEAT_MESHES to its directory)");
    }
    found
}

/// MANIFEST.csv rows as column → value maps (fields may be quoted and contain commas).
fn manifest(dir: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(dir.join("MANIFEST.csv")).expect("read MANIFEST.csv");
    let mut lines = text.lines().map(split_csv);
    let header = lines.next().expect("header row");
    lines
        .filter(|r| r.len() == header.len())
        .map(|r| header.iter().cloned().zip(r).collect())
        .collect()
}

fn split_csv(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(String::new()),
            c => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}
