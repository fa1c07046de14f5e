//! Wrinkle interpolation benchmark (`cargo bench --bench wrinkle_interp`, plain `std::time`):
//! time to converge (gradient ≤ 1e-6) with 50 guide frames on the coarse corpus meshes
//! (`../shared/meshes/coarse_*` relative to the crate, or `$PLEAT_MESHES`) for the keyframe
//! pairs of the dissertation (global 90° rotation, frequency ×3 with amplitude ÷3, a local
//! rotation) with the default trust-region solver, and on the rotation pair the three direct
//! (sparse-Cholesky) solvers it replaced, for comparison.
//!
//! Environment: `PLEAT_BENCH_FRAMES` (default 50), `PLEAT_BENCH_MAX_ITER` (default 200),
//! `PLEAT_BENCH_MESHES` (comma-separated file-name filter), `PLEAT_BENCH_HESSIANS=1` to also
//! compare the Hessian models. Skips with a message when the corpus is absent.

use std::path::{Path, PathBuf};

// The keyframe pairs shared with `pleat bench wrinkle` (benchmark code, not library API); the
// SVG plot in it is used by the CLI only.
#[allow(dead_code)]
#[path = "../src/bin/pleat/interp_bench.rs"]
mod interp_bench;

use interp_bench::{keyframe_pair, PairKind};
use pleat::mesh::io::read_mesh;
use pleat::wrinkle::{interpolate, HessianModel, InterpOptions};

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn corpus_dir() -> Option<PathBuf> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let candidates = [
        std::env::var("PLEAT_MESHES").map(PathBuf::from).ok(),
        Some(root.join("../shared/meshes")),
        Some(root.join("../../shared/meshes")),
    ];
    candidates.into_iter().flatten().find(|p| p.is_dir())
}

fn coarse_files(dir: &Path) -> Vec<PathBuf> {
    let filter: Option<Vec<String>> = std::env::var("PLEAT_BENCH_MESHES")
        .ok()
        .map(|s| s.split(',').map(String::from).collect());
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.retain(|p| {
        let n = p.file_name().unwrap().to_string_lossy().to_string();
        n.starts_with("coarse_")
            && filter
                .as_ref()
                .is_none_or(|f| f.iter().any(|x| n.contains(x.as_str())))
    });
    v.sort();
    v
}

fn main() {
    let Some(dir) = corpus_dir() else {
        println!("[wrinkle_interp] no corpus (../shared/meshes or $PLEAT_MESHES) — skipped");
        return;
    };
    let files = coarse_files(&dir);
    if files.is_empty() {
        println!(
            "[wrinkle_interp] no coarse_* meshes under {} — skipped",
            dir.display()
        );
        return;
    }
    let frames = env_usize("PLEAT_BENCH_FRAMES", 50);
    let max_it = env_usize("PLEAT_BENCH_MAX_ITER", 200);
    println!(
        "[wrinkle_interp] {frames} guide frames, tolerance 1e-6, cap {max_it} iterations, {} threads",
        rayon::current_num_threads()
    );
    println!(
        "{:28} {:>6} {:16} {:>14} {:>6} {:>6} {:>6} {:>10} {:>9}",
        "mesh", "verts", "pair", "stop", "iters", "facts", "cg", "gradient", "seconds"
    );
    let mut times = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mesh = match read_mesh(path) {
            Ok(m) => m,
            Err(e) => {
                println!("{name:28} skipped: {e}");
                continue;
            }
        };
        for kind in PairKind::ALL {
            let (a, b) = match keyframe_pair(&mesh, kind, 8.0) {
                Ok(p) => p,
                Err(e) => {
                    println!("{name:28} {}: skipped: {e}", kind.name());
                    continue;
                }
            };
            let opts = InterpOptions {
                guide_frames: frames,
                max_iterations: max_it,
                ..Default::default()
            };
            let t0 = std::time::Instant::now();
            let (_, r) = interpolate(&a, &b, &opts).expect("interpolate");
            let secs = t0.elapsed().as_secs_f64();
            times.push(secs);
            println!(
                "{name:28} {:>6} {:16} {:>14} {:>6} {:>6} {:>6} {:>10.2e} {secs:>9.2}",
                mesh.vertex_count(),
                kind.name(),
                r.stop.name(),
                r.iterations,
                r.factorizations,
                r.cg_iterations,
                r.final_gradient_norm()
            );
            if std::env::var_os("PLEAT_BENCH_HESSIANS").is_some()
                && kind == PairKind::GlobalRotation
            {
                for h in [
                    HessianModel::Exact,
                    HessianModel::Projected,
                    HessianModel::GaussNewton,
                ] {
                    let o = InterpOptions { hessian: h, ..opts };
                    let t0 = std::time::Instant::now();
                    let (_, r) = interpolate(&a, &b, &o).expect("interpolate");
                    println!(
                        "{name:28} {:>6} {:16} {:>14} {:>6} {:>6} {:>6} {:>10.2e} {:>9.2}  ({h:?})",
                        mesh.vertex_count(),
                        kind.name(),
                        r.stop.name(),
                        r.iterations,
                        r.factorizations,
                        r.cg_iterations,
                        r.final_gradient_norm(),
                        t0.elapsed().as_secs_f64()
                    );
                }
            }
        }
    }
    times.sort_by(f64::total_cmp);
    if !times.is_empty() {
        println!(
            "median {:.2} s over {} runs (target ≤ 5 s), min {:.2}, max {:.2}",
            times[times.len() / 2],
            times.len(),
            times[0],
            times[times.len() - 1]
        );
    }
}
