//! `pleat bench chain`: what a LOD chain costs against its finest level alone (target: a
//! chain {50, 100, 200} costs ≤ 1.3× the n_p = 200 bake alone).
//!
//! For every mesh of a folder, in this process: the finest level alone
//! ([`pleat::lowpoly::generate`] at the largest screen size) and the chain
//! ([`pleat::lowpoly::generate_chain`] at every size), **interleaved** (single, chain, single,
//! chain, …) so that a change of machine load hits both, best of `--reps` wall times each
//! (CPU seconds of the same runs beside them). Writes `chain_bench.csv` — one row per mesh:
//! input faces, the two best wall times and their ratio, the CPU seconds, whether the chain's
//! finest level is byte for byte the single bake (it must be: the ratio compares the same
//! finest level), and a `status` — and prints the per-mesh ratios and their median.
//!
//! Reading a mesh is outside the timings (a `pleat lod` process also reads and writes it, so
//! its chain/single ratio is a little lower than this one's).

use std::path::PathBuf;
use std::process::ExitCode;

use pleat::lowpoly::{generate, generate_chain, LodParams};
use pleat::mesh::io::read_mesh;
use pleat::mesh::TriMesh;

use crate::bench_lod::lod_sweep::{file_name, median, mesh_files, timed, MESH_EXTENSIONS};
use crate::bench_lod::{check_screen_sizes, write_file};

use super::{progress_bar, EXIT_FAILED, EXIT_INPUT};

/// Options of `pleat bench chain`.
#[derive(clap::Args)]
pub struct ChainBenchArgs {
    /// Folder of meshes (obj, ply, off, stl, glb, gltf) [default: ../shared/meshes].
    pub dir: Option<PathBuf>,
    /// The chain's screen sizes, comma separated; the largest one is also baked alone.
    #[arg(long, value_delimiter = ',', default_value = "50,100,200")]
    pub screen_sizes: Vec<f64>,
    /// Runs of each (single, chain) pair, interleaved; the best wall time of each counts.
    #[arg(long, default_value_t = 3)]
    pub reps: usize,
    /// Folder for chain_bench.csv (created if missing).
    #[arg(long, default_value = ".")]
    pub out_dir: PathBuf,
    /// Skip meshes with more input triangles than this (status `skipped` in the CSV).
    #[arg(long)]
    pub max_input_faces: Option<usize>,
    /// No progress bar and no per-mesh lines.
    #[arg(short, long)]
    pub quiet: bool,
}

/// One mesh's measurement.
#[derive(Default)]
struct ChainRow {
    mesh: String,
    input_faces: usize,
    /// Best wall seconds of the finest level alone and of the chain.
    single_s: f64,
    chain_s: f64,
    /// CPU seconds (all threads) of the runs with the best wall times.
    single_cpu_s: f64,
    chain_cpu_s: f64,
    /// The chain's finest level is the single bake, byte for byte.
    finest_is_single: bool,
    /// `ok`, or why the mesh has no figures.
    status: String,
}

impl ChainRow {
    fn ratio(&self) -> f64 {
        self.chain_s / self.single_s
    }

    fn csv_line(&self) -> String {
        format!(
            "{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{},{}",
            self.mesh,
            self.input_faces,
            self.single_s,
            self.chain_s,
            self.ratio(),
            self.single_cpu_s,
            self.chain_cpu_s,
            self.finest_is_single,
            self.status
        )
    }
}

/// `pleat bench chain`.
pub fn run(args: &ChainBenchArgs) -> ExitCode {
    match sweep(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, msg)) => {
            eprintln!("pleat bench chain: {msg}");
            ExitCode::from(code)
        }
    }
}

/// The whole command; `Err((exit code, message))` for bad arguments or an unwritable output
/// folder — a failing mesh is a CSV row with its status.
fn sweep(args: &ChainBenchArgs) -> Result<(), (u8, String)> {
    let sizes = &args.screen_sizes;
    check_screen_sizes(sizes)?;
    if args.reps == 0 {
        return Err((EXIT_INPUT, "--reps must be at least 1".into()));
    }
    let dir = args
        .dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("../shared/meshes"));
    let files = mesh_files(&dir, &MESH_EXTENSIONS).map_err(|e| (EXIT_INPUT, e))?;
    if files.is_empty() {
        return Err((EXIT_INPUT, format!("no mesh files in {}", dir.display())));
    }
    std::fs::create_dir_all(&args.out_dir).map_err(|e| {
        let msg = format!("cannot create {}: {e}", args.out_dir.display());
        (EXIT_FAILED, msg)
    })?;
    let bar = progress_bar(args.quiet);
    if let Some(b) = &bar {
        b.set_length(files.len() as u64);
    }
    let mut rows = Vec::with_capacity(files.len());
    for file in &files {
        let name = file_name(file);
        if let Some(b) = &bar {
            b.set_message(name.clone());
        }
        let row = match read_mesh(file) {
            Err(e) => ChainRow {
                mesh: name,
                status: format!("load error: {e}"),
                ..ChainRow::default()
            },
            Ok(m) => match args.max_input_faces {
                Some(n) if m.triangle_count() > n => ChainRow {
                    mesh: name,
                    input_faces: m.triangle_count(),
                    status: format!("skipped: more than --max-input-faces {n}"),
                    ..ChainRow::default()
                },
                _ => measure(&name, &m, sizes, args.reps),
            },
        };
        if !args.quiet {
            let line = row_line(&row);
            match &bar {
                Some(b) => b.println(line),
                None => println!("{line}"),
            }
        }
        if let Some(b) = &bar {
            b.inc(1);
        }
        rows.push(row);
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let csv = args.out_dir.join("chain_bench.csv");
    let mut text = String::from(
        "mesh,input_faces,single_s,chain_s,ratio,single_cpu_s,chain_cpu_s,finest_is_single,status\n",
    );
    for r in &rows {
        text.push_str(&r.csv_line());
        text.push('\n');
    }
    write_file(&csv, &text)?;
    let ratios: Vec<f64> = rows
        .iter()
        .filter(|r| r.status == "ok")
        .map(ChainRow::ratio)
        .collect();
    println!(
        "chain {sizes:?} / n_p = {} alone: median {:.3}x over {} meshes; wrote {}",
        finest(sizes),
        median(&ratios),
        ratios.len(),
        csv.display()
    );
    Ok(())
}

/// The largest screen size (the chain's finest level).
fn finest(sizes: &[f64]) -> f64 {
    sizes.iter().copied().fold(f64::MIN, f64::max)
}

/// The interleaved runs of one mesh: best wall time of each kind and the CPU of that run.
fn measure(name: &str, m: &TriMesh, sizes: &[f64], reps: usize) -> ChainRow {
    let params = LodParams {
        screen_size: finest(sizes),
        ..LodParams::default()
    };
    let mut row = ChainRow {
        mesh: name.to_string(),
        input_faces: m.triangle_count(),
        single_s: f64::INFINITY,
        chain_s: f64::INFINITY,
        finest_is_single: true,
        status: "ok".into(),
        ..ChainRow::default()
    };
    let finest_rank = sizes
        .iter()
        .position(|&s| s == params.screen_size)
        .unwrap_or(0);
    for _ in 0..reps {
        let single = timed(|| guarded(|| generate(m, &params, &mut |_| true)));
        let chain = timed(|| guarded(|| generate_chain(m, sizes, &params, &mut |_| true)));
        let (single_mesh, chain_levels) = match (single.value, chain.value) {
            (Ok((s, _)), Ok(c)) => (s, c),
            (Err(e), _) | (_, Err(e)) => {
                row.status = e;
                return row;
            }
        };
        row.finest_is_single &= chain_levels[finest_rank].0 == single_mesh;
        if single.seconds < row.single_s {
            (row.single_s, row.single_cpu_s) = (single.seconds, single.cpu_seconds);
        }
        if chain.seconds < row.chain_s {
            (row.chain_s, row.chain_cpu_s) = (chain.seconds, chain.cpu_seconds);
        }
    }
    row
}

/// `f`'s result, its error or a panic inside it as a status.
fn guarded<T>(f: impl FnOnce() -> pleat::Result<T>) -> Result<T, String> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(format!("error: {e}")),
        Err(_) => Err("panic inside the bake".into()),
    }
}

/// The per-mesh line printed while the sweep runs.
fn row_line(r: &ChainRow) -> String {
    if r.status != "ok" {
        return format!("{:34} {}", r.mesh, r.status);
    }
    format!(
        "{:34} alone {:7.3} s  chain {:7.3} s  {:5.2}x  (CPU {:.2} / {:.2} s){}",
        r.mesh,
        r.single_s,
        r.chain_s,
        r.ratio(),
        r.single_cpu_s,
        r.chain_cpu_s,
        if r.finest_is_single {
            ""
        } else {
            "  FINEST LEVEL DIFFERS"
        }
    )
}
