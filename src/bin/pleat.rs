//! `pleat`: command-line front end for build-step baking and checking.
//!
//! Exit status: 0 on success, 2 when an input cannot be read or an argument is invalid, 1 when
//! an operation fails.

use clap::{Parser, Subcommand};
#[cfg(feature = "lod")]
use pleat::lowpoly::LodParams;
use pleat::mesh::io::read_mesh;
#[cfg(feature = "lod")]
use pleat::mesh::io::write_mesh;
use pleat::mesh::{MeshReport, ReportOptions};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "pleat",
    version,
    about = "LODs by screen size, cages and wrinkle fields"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the validity report of a mesh file (obj, ply, off, stl, glb, gltf).
    Check {
        /// The mesh file.
        mesh: PathBuf,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
        /// Skip the self-intersection test (the most expensive part).
        #[arg(long)]
        no_self_intersections: bool,
        /// Analyse topology after merging exactly coincident points.
        #[arg(long)]
        weld: bool,
    },
    #[cfg(feature = "lod")]
    /// Bake LODs by screen size: watertight, manifold, self-intersection-free meshes that look
    /// like the input when its bounding-box diagonal covers N pixels.
    Lod {
        /// The input mesh (any triangle soup).
        input: PathBuf,
        #[command(flatten)]
        bake: BakeArgs,
    },
    #[cfg(feature = "cage")]
    /// Bake a cage: like `lod`, but enclosing the input without touching it.
    Cage {
        /// The input mesh (any triangle soup).
        input: PathBuf,
        #[command(flatten)]
        bake: BakeArgs,
    },
}

/// Options shared by `lod` and `cage`.
#[cfg(feature = "lod")]
#[derive(clap::Args)]
struct BakeArgs {
    /// Screen size(s) n_p in pixels, comma separated (`50,100,200`): one output per size.
    #[arg(long, value_delimiter = ',', required = true)]
    screen_size: Vec<f64>,
    /// Target triangle count (only with a single screen size).
    #[arg(long)]
    faces: Option<usize>,
    /// Output file; `{n}` is replaced by the screen size (required with several sizes).
    #[arg(short, long)]
    output: PathBuf,
    /// Maximum optimization rounds N.
    #[arg(long, default_value_t = 50)]
    rounds: u32,
    /// Skip the feature-alignment step.
    #[arg(long)]
    no_align: bool,
    /// No progress bar and no summary.
    #[arg(short, long)]
    quiet: bool,
    /// Also print every statistic (stage seconds, counts, metrics) of each level.
    #[arg(short, long)]
    verbose: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check {
            mesh,
            json,
            no_self_intersections,
            weld,
        } => check(&mesh, json, !no_self_intersections, weld),
        #[cfg(feature = "lod")]
        Command::Lod { input, bake: b } => bake(&input, &b, false),
        #[cfg(feature = "cage")]
        Command::Cage { input, bake: b } => bake(&input, &b, true),
    }
}

/// Exit code for a failed operation.
#[cfg(feature = "lod")]
const EXIT_FAILED: u8 = 1;

/// The output path of screen size `n_p`.
#[cfg(feature = "lod")]
fn output_path(pattern: &std::path::Path, n_p: f64) -> PathBuf {
    let s = pattern.to_string_lossy();
    PathBuf::from(s.replace("{n}", &format!("{n_p}")))
}

/// `pleat lod` / `pleat cage`.
#[cfg(feature = "lod")]
fn bake(input: &std::path::Path, args: &BakeArgs, cage: bool) -> ExitCode {
    let cmd = if cage { "cage" } else { "lod" };
    let sizes = &args.screen_size;
    let many = sizes.len() > 1;
    if many && !args.output.to_string_lossy().contains("{n}") {
        eprintln!("pleat {cmd}: with several screen sizes the output needs a {{n}} placeholder");
        return ExitCode::from(EXIT_INPUT);
    }
    if many && args.faces.is_some() {
        eprintln!("pleat {cmd}: --faces needs a single screen size");
        return ExitCode::from(EXIT_INPUT);
    }
    let mesh = match read_mesh(input) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let params = LodParams {
        screen_size: sizes[0],
        target_faces: args.faces,
        max_rounds: args.rounds,
        align: !args.no_align,
        ..LodParams::default()
    };
    let bar = progress_bar(args.quiet);
    let mut prog = |p: pleat::Progress<'_>| {
        if let Some(b) = &bar {
            b.set_position((p.fraction * 1000.0) as u64);
            b.set_message(p.stage.to_string());
        }
        true
    };
    let result = match (many, cage) {
        (false, false) => pleat::lowpoly::generate(&mesh, &params, &mut prog).map(|r| vec![r]),
        (true, false) => pleat::lowpoly::generate_chain(&mesh, sizes, &params, &mut prog),
        #[cfg(feature = "cage")]
        (false, true) => pleat::cage::generate(&mesh, &params, &mut prog).map(|r| vec![r]),
        #[cfg(feature = "cage")]
        (true, true) => pleat::cage::generate_chain(&mesh, sizes, &params, &mut prog),
        #[cfg(not(feature = "cage"))]
        (_, true) => unreachable!("the cage subcommand needs the cage feature"),
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let levels = match result {
        Ok(l) => l,
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            let code = match e {
                pleat::Error::InvalidArgument(_) => EXIT_INPUT,
                _ => EXIT_FAILED,
            };
            return ExitCode::from(code);
        }
    };
    for ((out, stats), &n_p) in levels.iter().zip(sizes) {
        let path = output_path(&args.output, n_p);
        if let Err(e) = write_mesh(&path, out) {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(EXIT_FAILED);
        }
        if !args.quiet {
            print_bake_summary(&path, n_p, out, stats);
        }
        if args.verbose {
            print_stats(stats);
        }
    }
    ExitCode::SUCCESS
}

/// An indicatif bar on a terminal (stderr), nothing otherwise.
#[cfg(feature = "lod")]
fn progress_bar(quiet: bool) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let b = indicatif::ProgressBar::new(1000);
    b.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent:>3}% {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    Some(b)
}

#[cfg(feature = "lod")]
fn print_stats(s: &pleat::Stats) {
    for (n, t) in &s.stages {
        println!("  {n:<28} {t:>10.3} s");
    }
    for (n, c) in &s.counts {
        println!("  {n:<28} {c:>10}");
    }
    for (n, m) in &s.metrics {
        println!("  {n:<28} {m:>10.6}");
    }
    for (n, v) in &s.verified {
        println!("  {n:<28} {v:>10}");
    }
}

#[cfg(feature = "lod")]
fn print_bake_summary(
    path: &std::path::Path,
    n_p: f64,
    m: &pleat::mesh::TriMesh,
    s: &pleat::Stats,
) {
    let ok = s.verified.iter().all(|v| v.1);
    println!(
        "{}: n_p={n_p} {} triangles, Hausdorff/l={:.5} (d/l={:.5}), {} rounds, {:.2} s, \
         verified: {}",
        path.display(),
        m.triangle_count(),
        s.get_metric("hausdorff_rel").unwrap_or(f64::NAN),
        1.0 / n_p,
        s.get_count("rounds").unwrap_or(0),
        s.total_seconds(),
        if ok {
            "watertight, manifold, intersection-free"
        } else {
            "NO"
        }
    );
}

/// Exit code for errors reading input or bad arguments.
const EXIT_INPUT: u8 = 2;

fn check(path: &std::path::Path, json: bool, self_intersections: bool, weld: bool) -> ExitCode {
    let mesh = match read_mesh(path) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("pleat check: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let options = ReportOptions {
        self_intersections,
        weld,
    };
    let report = MeshReport::compute_with(&mesh, &options);
    if json {
        println!("{}", report.to_json());
    } else {
        print_report(path, &report);
    }
    ExitCode::SUCCESS
}

fn yes_no(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn print_report(path: &std::path::Path, r: &MeshReport) {
    println!("{}", path.display());
    println!(
        "  vertices            {} ({} referenced)",
        r.n_vertices, r.n_referenced_vertices
    );
    println!("  triangles           {}", r.n_faces);
    println!("  components          {}", r.n_components);
    println!("  boundary edges      {}", r.n_boundary_edges);
    println!("  non-manifold edges  {}", r.n_nonmanifold_edges);
    println!("  non-manifold verts  {}", r.n_nonmanifold_vertices);
    println!("  degenerate faces    {}", r.n_degenerate_faces);
    println!("  duplicate faces     {}", r.n_duplicate_faces);
    println!(
        "  oriented            {} ({} misoriented edges)",
        yes_no(r.consistently_oriented),
        r.n_misoriented_edges
    );
    println!("  closed              {}", yes_no(r.is_closed));
    println!("  manifold            {}", yes_no(r.is_manifold));
    println!("  watertight          {}", yes_no(r.is_watertight));
    if let Some(g) = r.total_genus {
        println!("  genus               {g}");
    }
    match (r.self_intersection_free, r.n_self_intersecting_pairs) {
        (Some(free), Some(n)) => println!(
            "  self-intersections  {} ({n} intersecting pairs)",
            if free { "none" } else { "yes" }
        ),
        _ => println!("  self-intersections  not checked"),
    }
    println!("  bbox diagonal       {}", r.bbox_diagonal);
    println!("  surface area        {}", r.surface_area);
}
