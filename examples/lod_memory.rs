//! Where a LOD bake's memory goes, per stage, in bytes (to check the memory budget): a counting
//! global allocator (this example only — never the library or the `pleat` binary) keeps the live
//! and peak heap bytes; each time the progress callback reports a new stage name, the previous
//! stage's peak is recorded and the peak restarts from the live bytes.
//!
//! `cargo run --release --example lod_memory --features lod -- MESH NP [--voxel-scale S]
//! [--budget-mib B] [--out OUT.obj]`
//!
//! Prints one line per stage episode (stage, live bytes at its start, peak bytes during it,
//! seconds), the peak per stage name, and the estimate the budget check used (the measured
//! one, `LodReport::measured_estimate_bytes`, when the up-front estimate fitted no voxel scale).
//!
//! `... -- --estimates NP MESH...` prints instead, per mesh, the memory estimate at every
//! voxel scale of `LOD_VOXEL_SCALES` and the scale the default 2 GiB budget takes, the estimate
//! of a start from the input, whether `LodStart::Auto` starts from the input (the clean-input
//! check), and whether the estimate of the start taken fits (no bake).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use pleat::lowpoly::LodParams;

/// The system allocator, counting live bytes and their running maximum.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(n: usize) {
    let now = LIVE.fetch_add(n, Ordering::Relaxed) + n;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = System.alloc(l);
        if !p.is_null() {
            grew(l.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(l);
        if !p.is_null() {
            grew(l.size());
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l);
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = System.realloc(p, l, new);
        if !q.is_null() {
            if new >= l.size() {
                grew(new - l.size());
            } else {
                LIVE.fetch_sub(l.size() - new, Ordering::Relaxed);
            }
        }
        q
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// One contiguous run of progress calls with the same stage name.
struct Episode {
    stage: String,
    live_at_start: usize,
    peak: usize,
    seconds: f64,
}

fn mib(b: usize) -> f64 {
    b as f64 / (1u64 << 20) as f64
}

fn arg_after(args: &[String], flag: &str) -> Option<String> {
    args.iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1).cloned())
}

/// `--estimates NP MESH...`: the estimate per voxel scale and the scale chosen, per mesh.
fn estimates(n_p: f64, paths: &[String]) {
    let params = LodParams {
        screen_size: n_p,
        ..LodParams::default()
    };
    let scales = pleat::lowpoly::LOD_VOXEL_SCALES;
    let head: Vec<String> = scales.iter().map(|s| format!("MiB@{s}")).collect();
    println!(
        "mesh,faces,{},chosen,MiB@input,starts_from_input,fits",
        head.join(",")
    );
    let mut fit = 0;
    for p in paths {
        let Ok(mesh) = pleat::mesh::io::read_mesh(std::path::Path::new(p)) else {
            println!("{p},unreadable");
            continue;
        };
        let est: Vec<String> = scales
            .iter()
            .map(|&s| {
                format!(
                    "{:.0}",
                    mib(params.memory_estimate_bytes(&mesh, s) as usize)
                )
            })
            .collect();
        let chosen = params.lod_voxel_scale(&mesh);
        let input_est = params.input_start_memory_estimate_bytes(&mesh);
        // the start `generate` takes (runs the clean-input check), and whether its estimate fits
        let from_input = params.lod_starts_from_input(&mesh).unwrap_or(false);
        let fits = if from_input {
            input_est <= params.memory_budget_bytes as f64
        } else {
            chosen.is_some()
        };
        fit += fits as usize;
        let name = std::path::Path::new(p)
            .file_name()
            .map_or(p.clone(), |n| n.to_string_lossy().into_owned());
        println!(
            "{name},{},{},{},{:.0},{from_input},{fits}",
            mesh.triangle_count(),
            est.join(","),
            chosen.map_or("none".into(), |s| s.to_string()),
            mib(input_est as usize)
        );
    }
    println!("FIT {fit} of {} at n_p {n_p} in 2 GiB", paths.len());
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("--estimates") {
        estimates(args[2].parse().expect("NP"), &args[3..]);
        return;
    }
    if args.len() < 3 {
        eprintln!("usage: lod_memory MESH NP [--voxel-scale S] [--budget-mib B] [--out OUT]");
        std::process::exit(2);
    }
    let mesh = pleat::mesh::io::read_mesh(std::path::Path::new(&args[1])).expect("read mesh");
    let n_p: f64 = args[2].parse().expect("NP");
    let mut params = LodParams {
        screen_size: n_p,
        offset_voxel_scale: arg_after(&args, "--voxel-scale").map(|s| s.parse().expect("S")),
        ..LodParams::default()
    };
    if let Some(b) = arg_after(&args, "--budget-mib") {
        params.memory_budget_bytes = b.parse::<u64>().expect("B") << 20;
    }
    let scale = params.lod_voxel_scale(&mesh);
    let from_input = params.lod_starts_from_input(&mesh).unwrap_or(false);
    let estimate = if from_input {
        println!("starts from the input");
        Some(params.input_start_memory_estimate_bytes(&mesh))
    } else {
        scale.map(|s| params.memory_estimate_bytes(&mesh, s))
    };
    println!(
        "mesh {} faces {} n_p {n_p} voxel scale {scale:?} estimate {:.1} MiB; live before bake {:.1} MiB",
        args[1],
        mesh.triangle_count(),
        estimate.map_or(f64::NAN, |e| e / (1u64 << 20) as f64),
        mib(LIVE.load(Ordering::Relaxed))
    );
    let mut episodes: Vec<Episode> = Vec::new();
    let mut t = Instant::now();
    let t0 = Instant::now();
    let close = |eps: &mut Vec<Episode>, t: &mut Instant| {
        if let Some(e) = eps.last_mut() {
            e.peak = PEAK.load(Ordering::Relaxed);
            e.seconds = t.elapsed().as_secs_f64();
        }
        *t = Instant::now();
    };
    PEAK.store(LIVE.load(Ordering::Relaxed), Ordering::Relaxed);
    let result = {
        let mut tick = Instant::now();
        let mut progress = |p: pleat::Progress<'_>| {
            // a timeline of the first simplification pass (the peak), every 2 s
            let first_pass = p.stage == "simplify"
                && episodes.iter().filter(|e| e.stage == "simplify").count() <= 1;
            if first_pass && tick.elapsed().as_secs_f64() >= 2.0 {
                tick = Instant::now();
                println!(
                    "  first pass at {:.5}: live {:.1} MiB, peak so far {:.1} MiB",
                    p.fraction,
                    mib(LIVE.load(Ordering::Relaxed)),
                    mib(PEAK.load(Ordering::Relaxed))
                );
            }
            if episodes.last().is_none_or(|e| e.stage != p.stage) {
                close(&mut episodes, &mut t);
                let live = LIVE.load(Ordering::Relaxed);
                PEAK.store(live, Ordering::Relaxed);
                episodes.push(Episode {
                    stage: p.stage.to_string(),
                    live_at_start: live,
                    peak: live,
                    seconds: 0.0,
                });
            }
            true
        };
        pleat::lowpoly::generate(&mesh, &params, &mut progress)
    };
    close(&mut episodes, &mut t);
    let overall = episodes.iter().map(|e| e.peak).max().unwrap_or(0);
    println!("episode  stage        live-at-start MiB   peak MiB   seconds");
    for (i, e) in episodes.iter().enumerate() {
        if e.peak > overall / 20 || i < 12 {
            println!(
                "{i:>7}  {:<12} {:>16.1} {:>10.1} {:>9.2}",
                e.stage,
                mib(e.live_at_start),
                mib(e.peak),
                e.seconds
            );
        }
    }
    let mut names: Vec<&str> = episodes.iter().map(|e| e.stage.as_str()).collect();
    names.dedup();
    let mut seen = Vec::new();
    for n in names {
        if seen.contains(&n) {
            continue;
        }
        seen.push(n);
        let of = episodes.iter().filter(|e| e.stage == n);
        let peak = of.clone().map(|e| e.peak).max().unwrap_or(0);
        let secs: f64 = of.map(|e| e.seconds).sum();
        println!("STAGE {n:<12} peak {:>9.1} MiB  {secs:>8.2} s", mib(peak));
    }
    match result {
        Ok((lod, rep)) => {
            // admitted by measurement (the up-front estimate fitted no scale): its estimate
            let estimate = estimate.or(rep.measured_estimate_bytes);
            println!(
                "OK faces {} offset faces {} voxel {:?} hd/l {:.5} peak {:.1} MiB estimate {:.1} MiB{} bytes/offset face {:.0} wall {:.1} s",
                lod.triangle_count(),
                rep.faces_offset,
                rep.offset_voxel_scale,
                rep.hausdorff_rel,
                mib(overall),
                estimate.map_or(f64::NAN, |e| e / (1u64 << 20) as f64),
                if rep.measured_estimate_bytes.is_some() { " (measured admission)" } else { "" },
                overall as f64 / rep.faces_offset.max(1) as f64,
                t0.elapsed().as_secs_f64()
            );
            if let Some(out) = arg_after(&args, "--out") {
                pleat::mesh::io::write_mesh(std::path::Path::new(&out), &lod).expect("write");
            }
        }
        Err(e) => println!("ERR {e}"),
    }
}
