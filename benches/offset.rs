//! Offset-surface benchmark: time per step and peak memory at n_p = 50/100/200/400 on the
//! shared corpus (`../shared/meshes`, or `$PLEAT_MESHES`). Each case runs in a child process so
//! that its peak resident memory (VmHWM) is its own.
//!
//! `cargo bench --bench offset [-- <name filter>] [-- --np 200,400]`
//! Targets: median total ≤ 2 s at n_p = 200; peak ≤ 1 GiB at n_p = 400.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use pleat::lowpoly::{offset_surface_with_progress, OffsetDistance, OffsetParams};
use pleat::mesh::TriMesh;
use pleat::report::Stage as _;

fn corpus_dir() -> Option<PathBuf> {
    let cands = [
        std::env::var("PLEAT_MESHES").ok().map(PathBuf::from),
        Some(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes")),
        Some(PathBuf::from("/work/shared/meshes")),
    ];
    cands.into_iter().flatten().find(|p| p.is_dir())
}

fn load(path: &Path) -> Option<TriMesh> {
    pleat::mesh::io::read_mesh(path).ok()
}

/// A `/proc/self/status` memory field (`VmHWM`, `VmRSS`) in bytes.
fn status_bytes(field: &str) -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(field))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

fn peak_rss_bytes() -> u64 {
    status_bytes("VmHWM:")
}

fn child(path: &Path, np: f64) {
    let Some(mesh) = load(path) else {
        println!("SKIP");
        return;
    };
    let params = OffsetParams {
        distance: OffsetDistance::ScreenSize(np),
        verify: false,
        ..Default::default()
    };
    let t = Instant::now();
    let cpu0 = pleat::report::process_cpu_seconds();
    let trace = std::env::var("PLEAT_BENCH_MEMTRACE").is_ok();
    let mut last = String::new();
    let mut progress = |p: pleat::Progress<'_>| {
        if trace && p.stage != last {
            eprintln!(
                "  [{:>8.3} s] {:<10} VmHWM {:7.1} MiB  VmRSS {:7.1} MiB",
                t.elapsed().as_secs_f64(),
                p.stage,
                peak_rss_bytes() as f64 / 1048576.0,
                status_bytes("VmRSS:") as f64 / 1048576.0
            );
            last = p.stage.to_string();
        }
        true
    };
    match offset_surface_with_progress(&mesh, &params, &mut progress) {
        Ok((out, stats)) => {
            let total = t.elapsed().as_secs_f64();
            if trace {
                for (n, c) in &stats.entries().counts {
                    eprintln!("  {n:<24} {c}");
                }
            }
            let cpu = pleat::report::process_cpu_seconds() - cpu0;
            let stages: Vec<String> = stats
                .stages
                .iter()
                .map(|(n, s)| format!("{}={s:.3}", n.name()))
                .collect();
            println!(
                "OK {total:.3} {} {} {} {cpu:.3} {}",
                peak_rss_bytes(),
                out.triangle_count(),
                stats.peak_memory_bytes,
                stages.join(",")
            );
        }
        Err(e) => println!("ERR {e}"),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let (Ok(path), Ok(np)) = (
        std::env::var("PLEAT_BENCH_CASE"),
        std::env::var("PLEAT_BENCH_NP"),
    ) {
        child(Path::new(&path), np.parse().unwrap_or(200.0));
        return;
    }
    let Some(dir) = corpus_dir() else {
        eprintln!("offset bench: corpus not found (set PLEAT_MESHES); skipping");
        return;
    };
    // `--np 200` or `--np 200,400`; any other argument not starting with '-' filters by name.
    let np_at = args.iter().position(|a| a == "--np");
    let filter = args
        .iter()
        .enumerate()
        .skip(1)
        .find(|(i, a)| !a.starts_with('-') && Some(i - 1) != np_at)
        .map(|(_, a)| a.clone());
    let nps: Vec<f64> = match np_at {
        Some(i) => args
            .get(i + 1)
            .map(|s| s.split(',').filter_map(|x| x.parse().ok()).collect())
            .unwrap_or_default(),
        None => vec![50.0, 100.0, 200.0, 400.0],
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|r| r.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| {
        p.extension()
            .is_some_and(|e| ["obj", "ply", "off", "stl"].contains(&e.to_string_lossy().as_ref()))
    });
    files.sort();
    let exe = std::env::current_exe().expect("own path");
    for np in nps {
        let mut totals = Vec::new();
        let mut cpus = Vec::new();
        let mut peaks = Vec::new();
        for f in &files {
            let name = f
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .to_string();
            if filter.as_ref().is_some_and(|x| !name.contains(x.as_str())) {
                continue;
            }
            let out = Command::new(&exe)
                .env("PLEAT_BENCH_CASE", f)
                .env("PLEAT_BENCH_NP", np.to_string())
                .output();
            let Ok(out) = out else { continue };
            let line = String::from_utf8_lossy(&out.stdout).trim().to_string();
            let w: Vec<&str> = line.split_whitespace().collect();
            if w.first() == Some(&"OK") && w.len() >= 7 {
                let total: f64 = w[1].parse().unwrap_or(0.0);
                let rss: u64 = w[2].parse().unwrap_or(0);
                let cpu: f64 = w[5].parse().unwrap_or(0.0);
                totals.push(total);
                cpus.push(cpu);
                peaks.push(rss);
                println!(
                    "n_p={np:<4} {name:<32} {total:7.3} s (cpu {cpu:6.2} s)  peak {:7.1} MiB  (est {:6.1} MiB)  {:>8} tris  {}",
                    rss as f64 / 1048576.0,
                    w[4].parse::<f64>().unwrap_or(0.0) / 1048576.0,
                    w[3],
                    w[6]
                );
            } else {
                println!("n_p={np:<4} {name:<32} {line}");
            }
        }
        totals.sort_by(f64::total_cmp);
        cpus.sort_by(f64::total_cmp);
        if !totals.is_empty() {
            println!(
                "n_p={np}: median {:.3} s wall ({:.3} s cpu on {} threads), max {:.3} s, max peak {:.1} MiB over {} meshes",
                totals[totals.len() / 2],
                cpus[cpus.len() / 2],
                rayon::current_num_threads(),
                totals[totals.len() - 1],
                peaks.iter().max().copied().unwrap_or(0) as f64 / 1048576.0,
                totals.len()
            );
        }
    }
}
