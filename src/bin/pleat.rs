//! `pleat`: command-line front end for build-step baking and checking.
//!
//! Exit status: 0 on success, 2 when an input cannot be read or an argument is invalid, 1 when
//! an operation fails.

use clap::{Parser, Subcommand};
use pleat::mesh::io::read_mesh;
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
    /// Watertight, manifold, self-intersection-free d-offset surface of any mesh (LOD stage 1).
    #[cfg(feature = "lod")]
    Offset {
        /// The input mesh (any soup).
        input: PathBuf,
        /// Screen size n_p in pixels covered by the bounding-box diagonal: d = diagonal / n_p.
        #[arg(long, default_value_t = 200.0)]
        screen_size: f64,
        /// Explicit offset distance d in model units (overrides --screen-size).
        #[arg(long)]
        distance: Option<f64>,
        /// Plain MC33 without feature vertices.
        #[arg(long)]
        no_features: bool,
        /// Output file (format by extension).
        #[arg(short, long)]
        output: PathBuf,
        /// Print the stats as JSON on stdout.
        #[arg(long)]
        stats_json: bool,
    },
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
        Command::Offset {
            input,
            screen_size,
            distance,
            no_features,
            output,
            stats_json,
        } => {
            let mut params = pleat::lowpoly::OffsetParams {
                features: !no_features,
                ..Default::default()
            };
            params.distance = match distance {
                Some(d) => pleat::lowpoly::OffsetDistance::Absolute(d),
                None => pleat::lowpoly::OffsetDistance::ScreenSize(screen_size),
            };
            offset(&input, &output, &params, stats_json)
        }
    }
}

/// Exit code for a failed operation.
#[cfg(feature = "lod")]
const EXIT_FAILED: u8 = 1;

/// A progress bar on stderr when it is a terminal (hidden otherwise, e.g. in build logs).
#[cfg(feature = "lod")]
fn progress_bar() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::with_draw_target(
        Some(1000),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}") {
        bar.set_style(style);
    }
    bar
}

#[cfg(feature = "lod")]
fn offset(
    input: &std::path::Path,
    output: &std::path::Path,
    params: &pleat::lowpoly::OffsetParams,
    stats_json: bool,
) -> ExitCode {
    let mesh = match read_mesh(input) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("pleat offset: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let bar = progress_bar();
    let result = pleat::lowpoly::offset_surface_with_progress(&mesh, params, &mut |p| {
        bar.set_position((p.fraction * 1000.0) as u64);
        bar.set_message(p.stage.to_string());
        true
    });
    bar.finish_and_clear();
    let (out, stats) = match result {
        Ok(r) => r,
        Err(e) => {
            eprintln!("pleat offset: {e}");
            return ExitCode::from(match e {
                pleat::Error::InvalidArgument(_) => EXIT_INPUT,
                _ => EXIT_FAILED,
            });
        }
    };
    if let Err(e) = pleat::mesh::io::write_mesh(output, &out) {
        eprintln!("pleat offset: {e}");
        return ExitCode::from(EXIT_FAILED);
    }
    if stats_json {
        println!("{}", stats.to_json());
    } else {
        eprintln!(
            "{} -> {}: {} triangles in {:.2} s; verified: {}",
            input.display(),
            output.display(),
            out.triangle_count(),
            stats.total_seconds(),
            stats
                .verified
                .iter()
                .map(|(n, ok)| format!("{n}={ok}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    ExitCode::SUCCESS
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
