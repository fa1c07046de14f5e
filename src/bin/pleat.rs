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
    }
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
