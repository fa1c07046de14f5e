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
use pleat::verify::{MeshReport, ReportOptions};
use std::path::PathBuf;
use std::process::ExitCode;

#[cfg(feature = "lod")]
#[path = "pleat/bench_lod.rs"]
mod bench_lod;

#[cfg(feature = "lod")]
#[path = "pleat/bench_chain.rs"]
mod bench_chain;
#[cfg(feature = "wrinkle")]
#[path = "pleat/interp_bench.rs"]
mod interp_bench;
#[cfg(feature = "wrinkle")]
#[path = "pleat/wrinkle_edit.rs"]
mod wrinkle_edit;

#[cfg(feature = "bake")]
#[path = "pleat/bake.rs"]
mod bake_cmd;

#[cfg(feature = "bake")]
#[path = "pleat/scene.rs"]
mod scene_cmd;

#[cfg(feature = "lod")]
#[path = "pleat/batch.rs"]
mod batch;

#[cfg(feature = "tfw")]
#[path = "pleat/tfw.rs"]
mod tfw_cmd;

#[cfg(feature = "tfw")]
#[path = "pleat/bench_tfw.rs"]
mod bench_tfw;

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
    #[cfg(feature = "lod")]
    /// Bake LODs by screen size: watertight, manifold, self-intersection-free meshes that look
    /// like the input when its bounding-box diagonal covers N pixels.
    ///
    /// glTF input with a .glb output keeps the whole document (nodes, skins, animations,
    /// cameras, lights, materials, extras) and gives every mesh its own chain, baked once in
    /// the mesh's local space and linked to each instancing node with MSFT_lod; a mesh whose
    /// LOD would not have fewer faces is kept unchanged; the levels of a skinned or morphed
    /// mesh carry its joints, weights and morph targets (transferred from the input).
    /// `--merge` fuses everything into one proxy instead.
    Lod {
        /// The input mesh (any triangle soup); several files, folders or --manifest bake a batch.
        #[arg(required_unless_present = "manifest")]
        inputs: Vec<PathBuf>,
        #[command(flatten)]
        batch: batch::BatchArgs,
        #[command(flatten)]
        bake: BakeArgs,
    },
    #[cfg(feature = "cage")]
    /// Bake a cage: like `lod`, but enclosing the input without touching it.
    Cage {
        /// The input mesh (any triangle soup); several files, folders or --manifest bake a batch.
        #[arg(required_unless_present = "manifest")]
        inputs: Vec<PathBuf>,
        #[command(flatten)]
        batch: batch::BatchArgs,
        #[command(flatten)]
        bake: BakeArgs,
    },
    /// Complex wrinkle fields: build (.cwf files) and evaluate wrinkled meshes.
    #[command(subcommand)]
    Wrinkle(WrinkleCommand),
    /// Wrinkles from physics (tension-field statics): a scene file in, the wrinkled mesh out.
    #[cfg(feature = "tfw")]
    Tfw(tfw_cmd::TfwArgs),
    /// Benchmarks that write CSV tables and SVG plots.
    #[command(subcommand)]
    Bench(BenchCommand),
}

/// `pleat bench ...`: one sub-subcommand per benchmark.
#[derive(Subcommand)]
enum BenchCommand {
    /// LOD error against run time: sweep screen sizes over a mesh folder, write
    /// lod_bench.csv and lod_bench.svg (Hausdorff/l against seconds, log-log).
    #[cfg(feature = "lod")]
    Lod(bench_lod::LodBenchArgs),
    /// A LOD chain against its finest level alone: per mesh, interleaved best-of wall times
    /// and their ratio; writes chain_bench.csv.
    #[cfg(feature = "lod")]
    Chain(bench_chain::ChainBenchArgs),
    /// Tension-field wrinkles: energy and residual against wall time per scene (built-ins or
    /// scene files); writes tfw_iterations.csv, tfw_scenes.csv and tfw_bench.svg.
    #[cfg(feature = "tfw")]
    Tfw(bench_tfw::TfwBenchArgs),
    /// Wrinkle interpolation: residual vs seconds per keyframe pair (rotation, frequency ×3,
    /// local rotation) and quality vs number of guide frames (ablation B.7.1). Writes
    /// interp_convergence.csv/.svg and interp_guide_frames.csv/.svg into OUT_DIR.
    Wrinkle {
        /// Base meshes [default: ../shared/meshes/coarse_decimated-knight.off].
        #[arg(long)]
        mesh: Vec<PathBuf>,
        /// Output directory (created).
        #[arg(long, default_value = "bench-wrinkle")]
        out_dir: PathBuf,
        /// Guide frames N' of the convergence runs.
        #[arg(long, default_value_t = 50)]
        frames: usize,
        /// Wave periods per bounding-box diagonal.
        #[arg(long, default_value_t = 8.0)]
        wavelengths: f64,
    },
}

/// Options shared by `lod` and `cage`.
#[cfg(feature = "lod")]
#[derive(clap::Args)]
struct BakeArgs {
    /// Screen size(s) n_p in pixels, comma separated (`50,100,200`): one output per size
    /// (in a batch: for the manifest rows that give none).
    #[arg(long, value_delimiter = ',', required_unless_present = "manifest")]
    screen_size: Vec<f64>,
    /// Target triangle count (only with a single screen size).
    #[arg(long)]
    faces: Option<usize>,
    // clap turns `{n}` into a line break anywhere in help text, so the help names `{np}`,
    // which works the same (see `output_path`).
    /// Output file; `{np}` is replaced by the screen size (required with several sizes). In a
    /// batch: the pattern for the manifest rows that name no output (optional when all do).
    #[arg(short, long, required_unless_present = "manifest")]
    output: Option<PathBuf>,
    /// Maximum optimization rounds N (a LOD without --faces also stops after 5 rounds without a new
    /// smallest face count).
    #[arg(long, default_value_t = 50)]
    rounds: u32,
    /// Skip the feature-alignment step.
    #[arg(long)]
    no_align: bool,
    /// Skip the final fit of LODs to the input's planes (keeps the loop's output, which sits
    /// about d outside the input with rounded creases; ignored for cages).
    #[arg(long)]
    no_fit: bool,
    /// Cages: the distance kept from the input, a fraction of d with a `d` suffix (`0.05d`,
    /// the default) or a length in model units (`0.002`); below d. `0d` only forbids contact.
    #[arg(long, value_parser = parse_clearance)]
    clearance: Option<pleat::lowpoly::Clearance>,
    /// LODs: the surface the loop starts from: `input` (the welded input; it must be closed,
    /// manifold, oriented and intersection-free), `offset` (the offset surface at d, any
    /// soup) or `auto` (input when it is clean, else offset). Cages always start from the
    /// offset surface.
    #[arg(long, value_parser = parse_start, default_value = "auto")]
    start: pleat::lowpoly::LodStart,
    /// LODs: the offset voxel to start from, a multiple of d/√3 in (0, 2] (`1` = the
    /// dissertation's voxel) [default: 2 from n_p = 200 on, 1.25 from 100, 1 below]; a coarser one
    /// is taken when the memory estimate needs it. Ignored for cages.
    #[arg(long)]
    voxel_scale: Option<f64>,
    /// Upper bound on the memory of each bake: bytes or a size with a unit (`4GiB`, `512MiB`,
    /// `3G`, `800M`; K, M, G, T are powers of 1024) [default: 2GiB]. A bake whose estimate
    /// exceeds it takes a coarser offset voxel, or is refused with the figure it would need.
    #[arg(long, value_parser = parse_memory_budget)]
    memory_budget: Option<u64>,
    /// No progress bar and no summary.
    #[arg(short, long)]
    quiet: bool,
    /// Also print every statistic (stage seconds, counts, metrics) of each level.
    #[arg(short, long)]
    verbose: bool,
    #[cfg(feature = "bake")]
    #[command(flatten)]
    textures: bake_cmd::TextureArgs,
    #[cfg(feature = "bake")]
    #[command(flatten)]
    scene: scene_cmd::SceneArgs,
}

/// `pleat wrinkle ...` (needs the `wrinkle` feature; otherwise exits 2 with a message).
#[derive(Subcommand)]
enum WrinkleCommand {
    /// Evaluate a wrinkle field: Loop-refine BASE `--levels` times and displace along the
    /// normals; writes the wrinkled mesh (format by extension of OUT).
    Eval {
        /// The base mesh the field was made for (obj, ply, off, stl, glb, gltf).
        base: PathBuf,
        /// The wrinkle field (.cwf).
        #[arg(long)]
        cwf: PathBuf,
        /// Loop refinements (each multiplies the triangle count by 4).
        #[arg(long, default_value_t = 3)]
        levels: u32,
        /// Multiplies the displacement.
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// Smooth (B-spline) boundary instead of a fixed one.
        #[arg(long)]
        smooth_boundary: bool,
        /// Refuse outputs with more triangles than this.
        #[arg(long, default_value_t = 1 << 26)]
        max_triangles: usize,
        /// Output mesh file.
        #[arg(short = 'o', long = "output")]
        out: PathBuf,
    },
    /// Build a .cwf from a per-vertex wave-vector field (phase by Knöppel et al. 2015).
    ///
    /// FIELD format: one line per base vertex, in vertex order: `fx fy fz [amplitude]` — the
    /// wave vector (the phase gradient, radians per length unit) and optionally that vertex's
    /// amplitude (length unit, ≥ 0). Blank lines and lines starting with `#` are ignored.
    FromField {
        /// The base mesh.
        base: PathBuf,
        /// The per-vertex field text file.
        #[arg(long)]
        field: PathBuf,
        /// Amplitude of vertices whose line has none [default: 0.005 × bbox diagonal].
        #[arg(long)]
        amplitude: Option<f64>,
        /// Knöppel edge weights: cotangent or barycentric edge areas.
        #[arg(long, value_parser = ["cotan", "edge-area"], default_value = "cotan")]
        weights: String,
        /// Output .cwf file.
        #[arg(short = 'o', long = "output")]
        out: PathBuf,
    },
    /// Interpolate between two keyframes (dissertation §3.4): writes a .cwfa animation of
    /// `--frames` guide frames and `--substeps` linear sub-steps each.
    Interp {
        /// Keyframe at t = 0 (.cwf).
        a: PathBuf,
        /// Keyframe at t = 1 (.cwf), on the same base mesh.
        b: PathBuf,
        /// The base mesh both keyframes were made for.
        #[arg(long)]
        base: PathBuf,
        /// Guide frames N'.
        #[arg(long, default_value_t = 50)]
        frames: usize,
        /// Linear sub-steps k per guide interval (N'·k + 1 playback frames).
        #[arg(long, default_value_t = 4)]
        substeps: usize,
        /// c = C_SCALE · g_ave.
        #[arg(long, default_value_t = 1e3)]
        c_scale: f64,
        /// Gradient-norm tolerance.
        #[arg(long, default_value_t = 1e-6)]
        tolerance: f64,
        /// Newton iteration cap.
        #[arg(long, default_value_t = 200)]
        max_iterations: usize,
        /// Solve the phase at every vertex (eq. 3.12 as printed). By default vertices whose star
        /// is the same in both keyframes (an edit's fixed part) keep their keyframe phase on
        /// every frame, so a local edit animates locally (spec check C10).
        #[arg(long)]
        no_locality: bool,
        /// Output animation (.cwfa).
        #[arg(short = 'o', long = "output")]
        out: PathBuf,
    },
    /// Evaluate every playback frame of an animation to a mesh file; `{i}` in OUT is replaced
    /// by the frame number.
    EvalAnim {
        /// The base mesh.
        base: PathBuf,
        /// The animation (.cwfa).
        anim: PathBuf,
        /// Loop refinements.
        #[arg(long, default_value_t = 3)]
        levels: u32,
        /// Multiplies the displacement.
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// Output pattern, e.g. frame_{i}.obj.
        #[arg(short = 'o', long = "output")]
        out: PathBuf,
    },
    /// Design a keyframe from wrinkle sources (dissertation §3.6.1): wave vectors extended by
    /// the vector heat method, amplitude by eq. 3.25, phase by Knöppel; zero outside the
    /// sources' regions. Prints each solve's seconds and residual.
    Design {
        /// The base mesh.
        base: PathBuf,
        /// A source `V,KX,KY,KZ,A[,RINGS]`: vertex, wave vector (radians per length unit),
        /// amplitude, region size in rings (default 5). Repeat for several sources.
        #[arg(long = "source", allow_hyphen_values = true, required = true)]
        sources: Vec<String>,
        /// Heat time in units of the squared mean edge length.
        #[arg(long, default_value_t = 1.0)]
        heat_time: f64,
        /// The reference implementation's weights (edge rings, γ = ¼, sources not pinned).
        #[arg(long)]
        reference: bool,
        /// Output .cwf file.
        #[arg(short = 'o', long = "output")]
        out: PathBuf,
    },
    /// Edit regions of a keyframe (dissertation §3.6.2): rotate, rescale frequency and
    /// amplitude; the interface is solved (eqs. 3.26–3.28), the rest copied bit for bit. The
    /// result animates with `pleat wrinkle interp A.cwf B.cwf`.
    Edit {
        /// The base mesh.
        base: PathBuf,
        /// The keyframe to edit (.cwf).
        #[arg(long)]
        cwf: PathBuf,
        /// A region `seed=FACE|vertex=V,rings=N,interface=M,rotate=DEG,scale=σ,amplitude=μ`
        /// (or `couple` for μ = 1/σ); defaults rings 5, interface 3, identity op. Repeat for
        /// several regions (they must not share a vertex).
        #[arg(long = "region", allow_hyphen_values = true, required = true)]
        regions: Vec<String>,
        /// How rings grow: across vertices or across edges.
        #[arg(long, value_parser = ["vertex", "edge"], default_value = "vertex")]
        adjacency: String,
        /// The reference implementation's weights (edge rings, γ = ¼, amplitude-weighted phase).
        #[arg(long)]
        reference: bool,
        /// Also write the face labels (one per line: 0 fixed, 1 edit, 2 interface).
        #[arg(long)]
        labels: Option<PathBuf>,
        /// Adaptive interface width: widen every band by one ring while the compatibility RMS
        /// over edit + interface edges exceeds RAD radians (default 0.3, the required interface
        /// smoothness; 0 = off: the requested widths). The widths used are printed.
        #[arg(
            long,
            value_name = "RAD",
            default_value_t = DEFAULT_COMPAT_TARGET,
            allow_hyphen_values = true
        )]
        compat_target: f64,
        /// Widest band the adaptive width (--compat-target) may reach, in rings.
        #[arg(long, value_name = "N", default_value_t = 8)]
        max_interface_rings: usize,
        /// Weight (≥ 1) of the edit edges' compatibility terms in the phase solve (eq. 3.28)
        /// relative to the interface edges'; 1 is the literal eq. 3.28.
        #[arg(
            long,
            value_name = "W",
            default_value_t = 1.0,
            allow_hyphen_values = true
        )]
        edit_weight: f64,
        /// Output .cwf file.
        #[arg(short = 'o', long = "output")]
        out: PathBuf,
    },
    /// Build a .cwf holding the global plane wave exp(i k·x) (exactly compatible, no solve).
    PlaneWave {
        /// The base mesh.
        base: PathBuf,
        /// Wave vector in radians per length unit: KX,KY,KZ (wavelength 2π/|k|).
        #[arg(
            long,
            value_delimiter = ',',
            allow_hyphen_values = true,
            required = true
        )]
        k: Vec<f64>,
        /// Amplitude (length unit) [default: 0.005 × bbox diagonal].
        #[arg(long)]
        amplitude: Option<f64>,
        /// Output .cwf file.
        #[arg(short = 'o', long = "output")]
        out: PathBuf,
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
        #[cfg(feature = "lod")]
        Command::Lod {
            inputs,
            batch: batch_args,
            bake: b,
        } => batch::dispatch(&inputs, &batch_args, &b, false),
        #[cfg(feature = "cage")]
        Command::Cage {
            inputs,
            batch: batch_args,
            bake: b,
        } => batch::dispatch(&inputs, &batch_args, &b, true),
        Command::Wrinkle(cmd) => wrinkle_cmd::run(cmd),
        #[cfg(feature = "tfw")]
        Command::Tfw(args) => tfw_cmd::run(&args),
        Command::Bench(cmd) => bench(cmd),
    }
}

/// `pleat bench ...`.
fn bench(cmd: BenchCommand) -> ExitCode {
    match cmd {
        #[cfg(feature = "lod")]
        BenchCommand::Lod(args) => bench_lod::run(&args),
        #[cfg(feature = "lod")]
        BenchCommand::Chain(args) => bench_chain::run(&args),
        #[cfg(feature = "tfw")]
        BenchCommand::Tfw(args) => bench_tfw::run(&args),
        cmd @ BenchCommand::Wrinkle { .. } => wrinkle_cmd::bench(cmd),
    }
}

/// Exit code for a failed operation.
#[cfg(any(feature = "lod", feature = "tfw"))]
const EXIT_FAILED: u8 = 1;

/// Placeholders of the output path replaced by the screen size: `{n}` (the older
/// spelling) and `{np}` (the one `--help` can show).
#[cfg(feature = "lod")]
const SIZE_PLACEHOLDERS: [&str; 2] = ["{n}", "{np}"];

/// The exit code of a failed bake: `EXIT_INPUT` when the caller's arguments or input are
/// at fault (`InvalidArgument`), `EXIT_FAILED` otherwise.
#[cfg(any(feature = "lod", feature = "tfw"))]
fn failure_code(e: &pleat::Error) -> u8 {
    match e {
        pleat::Error::InvalidArgument(_) => EXIT_INPUT,
        _ => EXIT_FAILED,
    }
}

/// The output path of screen size `n_p`.
#[cfg(feature = "lod")]
fn output_path(pattern: &std::path::Path, n_p: f64) -> PathBuf {
    let mut s = pattern.to_string_lossy().to_string();
    for p in SIZE_PLACEHOLDERS {
        s = s.replace(p, &format!("{n_p}"));
    }
    PathBuf::from(s)
}

/// `pleat lod` / `pleat cage`.
#[cfg(feature = "lod")]
fn bake(input: &std::path::Path, args: &BakeArgs, cage: bool) -> ExitCode {
    let cmd = if cage { "cage" } else { "lod" };
    #[cfg(feature = "bake")]
    if scene_cmd::applies(input, args) {
        return scene_cmd::run(input, args, cage);
    }
    #[cfg(feature = "bake")]
    if args.textures.bake {
        return bake_cmd::run(input, args, cmd);
    }
    let Some(output) = args.output.as_deref() else {
        eprintln!("pleat {cmd}: no output file (give -o)");
        return ExitCode::from(EXIT_INPUT);
    };
    let sizes = &args.screen_size;
    let many = sizes.len() > 1;
    let pattern = output.to_string_lossy();
    if many && !SIZE_PLACEHOLDERS.iter().any(|p| pattern.contains(p)) {
        eprintln!(
            "pleat {cmd}: with several screen sizes the output needs a {{n}} or {{np}} placeholder"
        );
        return ExitCode::from(EXIT_INPUT);
    }
    if many && args.faces.is_some() {
        eprintln!("pleat {cmd}: --faces needs a single screen size");
        return ExitCode::from(EXIT_INPUT);
    }
    #[cfg(feature = "bake")]
    let mesh = scene_cmd::read_merged(input, &args.scene);
    #[cfg(not(feature = "bake"))]
    let mesh = read_mesh(input).map_err(|e| e.to_string());
    let mesh = match mesh {
        Ok(m) => m,
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let params = lod_params(args, sizes, args.faces);
    let bar = progress_bar(args.quiet);
    let mut prog = |p: pleat::Progress<'_>| show_progress(&bar, p);
    let result = bake_levels(&mesh, sizes, &params, cage, &mut prog);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let levels = match result {
        Ok(l) => l,
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(failure_code(&e));
        }
    };
    for ((out, stats), &n_p) in levels.iter().zip(sizes) {
        let path = output_path(output, n_p);
        // Never larger than the input: a LOD with more faces than the input soup is replaced
        // by the input itself.
        if out.triangle_count() > mesh.triangle_count() {
            if let Err(e) = write_mesh(&path, &mesh) {
                eprintln!("pleat {cmd}: {e}");
                return ExitCode::from(EXIT_FAILED);
            }
            if !args.quiet {
                println!(
                    "{}: n_p={n_p} unchanged: the input ({} triangles) is written, its LOD had {}",
                    path.display(),
                    mesh.triangle_count(),
                    out.triangle_count()
                );
            }
            continue;
        }
        if let Err(e) = write_mesh(&path, out) {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(EXIT_FAILED);
        }
        if !args.quiet {
            print_bake_summary(&path, n_p, out, stats);
        }
        if args.verbose {
            print_stats(&stats.entries());
        }
    }
    ExitCode::SUCCESS
}

/// The LOD parameters of a bake at screen sizes `sizes` (the first one is the finest level's)
/// with face target `faces`.
#[cfg(feature = "lod")]
fn lod_params(args: &BakeArgs, sizes: &[f64], faces: Option<usize>) -> LodParams {
    LodParams {
        screen_size: sizes[0],
        target_faces: faces,
        max_rounds: args.rounds,
        align: !args.no_align,
        fit_to_input: !args.no_fit,
        clearance: args.clearance.unwrap_or_default(),
        start: args.start,
        offset_voxel_scale: args.voxel_scale,
        memory_budget_bytes: args
            .memory_budget
            .unwrap_or(LodParams::default().memory_budget_bytes),
        ..LodParams::default()
    }
}

/// One level per screen size of `mesh`: a LOD (or a cage when `cage`), a chain when there are
/// several sizes. The single-input command and the batch both bake through here, so a batch
/// writes the same bytes as one `pleat lod` per asset.
#[cfg(feature = "lod")]
fn bake_levels(
    mesh: &pleat::mesh::TriMesh,
    sizes: &[f64],
    params: &LodParams,
    cage: bool,
    prog: &mut pleat::report::ProgressFn<'_>,
) -> pleat::Result<Vec<(pleat::mesh::TriMesh, pleat::lowpoly::LodReport)>> {
    match (sizes.len() > 1, cage) {
        (false, false) => pleat::lowpoly::generate(mesh, params, prog).map(|r| vec![r]),
        (true, false) => pleat::lowpoly::generate_chain(mesh, sizes, params, prog),
        #[cfg(feature = "cage")]
        (false, true) => pleat::cage::generate(mesh, params, prog).map(|r| vec![r]),
        #[cfg(feature = "cage")]
        (true, true) => pleat::cage::generate_chain(mesh, sizes, params, prog),
        #[cfg(not(feature = "cage"))]
        (_, true) => unreachable!("the cage subcommand needs the cage feature"),
    }
}

/// `--start`: `auto`, `offset` or `input`.
#[cfg(feature = "lod")]
fn parse_start(s: &str) -> Result<pleat::lowpoly::LodStart, String> {
    use pleat::lowpoly::LodStart;
    match s {
        "auto" => Ok(LodStart::Auto),
        "offset" => Ok(LodStart::Offset),
        "input" => Ok(LodStart::Input),
        _ => Err(format!("expected auto, offset or input, got {s}")),
    }
}

/// `--memory-budget` (and the batch manifest's `memory_budget`): bytes, or a number with a unit
/// K, M, G or T (powers of 1024; `KiB`, `MB`, … read the same); at least one byte.
#[cfg(feature = "lod")]
pub(crate) fn parse_memory_budget(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let v: f64 = num
        .parse()
        .map_err(|_| format!("`{s}` is not a size (e.g. 4GiB, 512MiB, 3G or bytes)"))?;
    let power = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 1,
        "m" | "mb" | "mib" => 2,
        "g" | "gb" | "gib" => 3,
        "t" | "tb" | "tib" => 4,
        _ => {
            return Err(format!(
                "`{s}`: unknown unit `{unit}` (K, M, G, T, or none for bytes)"
            ))
        }
    };
    let bytes = v * 1024f64.powi(power);
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!(
            "the memory budget must be at least one byte, got {s}"
        ));
    }
    Ok(bytes as u64)
}

/// `--clearance`: `0.25d` (a fraction of d) or `0.002` (model units); finite and `>= 0`.
#[cfg(feature = "lod")]
fn parse_clearance(s: &str) -> Result<pleat::lowpoly::Clearance, String> {
    use pleat::lowpoly::Clearance;
    let (num, relative) = match s.trim().strip_suffix('d') {
        Some(n) => (n, true),
        None => (s.trim(), false),
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number, or a number followed by `d`"))?;
    if !(v.is_finite() && v >= 0.0) {
        return Err(format!("the clearance must be finite and >= 0, got {s}"));
    }
    Ok(if relative {
        Clearance::FractionOfD(v)
    } else {
        Clearance::Absolute(v)
    })
}

/// An indicatif bar on a terminal (stderr), nothing otherwise.
#[cfg(any(feature = "lod", feature = "tfw"))]
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

/// Shows a library progress report on `bar` (when there is one); never cancels.
fn show_progress(bar: &Option<indicatif::ProgressBar>, p: pleat::Progress<'_>) -> bool {
    if let Some(b) = bar {
        b.set_position((p.fraction * 1000.0) as u64);
        b.set_message(p.stage.to_string());
    }
    true
}

#[cfg(feature = "lod")]
fn print_stats(s: &pleat::report::StatEntries) {
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
    s: &pleat::lowpoly::LodReport,
) {
    let ok = s.verified.all_hold();
    println!(
        "{}: n_p={n_p} {} triangles, Hausdorff/l={:.5} (d/l={:.5}), {} rounds, {:.2} s, \
         verified: {}",
        path.display(),
        m.triangle_count(),
        s.hausdorff_rel,
        1.0 / n_p,
        s.rounds,
        s.total_seconds(),
        if ok {
            "watertight, manifold, intersection-free"
        } else {
            "NO"
        }
    );
    if s.started_from_input {
        println!("  started from the input (clean: closed, manifold, intersection-free)");
    }
    if let Some(c) = &s.clearance {
        println!(
            "  clearance: exact minimum {:.3e} ({:.2} d), required {:.3e} ({:.2} d){}",
            c.min,
            c.min / s.d,
            c.required,
            c.required / s.d,
            if c.kept {
                ""
            } else {
                " — NOT KEPT: the start surface was closer; try a smaller --clearance"
            }
        );
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
            "  self-intersections  {} ({}{n} intersecting pairs)",
            if free { "none" } else { "yes" },
            if r.n_self_intersecting_pairs_is_lower_bound == Some(true) {
                "at least "
            } else {
                ""
            }
        ),
        _ => println!("  self-intersections  not checked"),
    }
    println!("  bbox diagonal       {}", r.bbox_diagonal);
    println!("  surface area        {}", r.surface_area);
}

/// `pleat offset`.
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
    let bar = progress_bar(false);
    let result = pleat::lowpoly::offset_surface_with_progress(&mesh, params, &mut |p| {
        show_progress(&bar, p)
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let (out, stats) = match result {
        Ok(r) => r,
        Err(e) => {
            eprintln!("pleat offset: {e}");
            return ExitCode::from(failure_code(&e));
        }
    };
    if let Err(e) = pleat::mesh::io::write_mesh(output, &out) {
        eprintln!("pleat offset: {e}");
        return ExitCode::from(EXIT_FAILED);
    }
    if stats_json {
        println!("{}", stats.entries().to_json());
    } else {
        eprintln!(
            "{} -> {}: {} triangles in {:.2} s; verified: {}",
            input.display(),
            output.display(),
            out.triangle_count(),
            stats.total_seconds(),
            stats
                .verified
                .checked()
                .iter()
                .map(|(n, ok)| format!("{n}={ok}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    ExitCode::SUCCESS
}

/// The default of `pleat wrinkle edit --compat-target` (the library's, when it is built in).
#[cfg(feature = "wrinkle")]
const DEFAULT_COMPAT_TARGET: f64 = pleat::wrinkle::DEFAULT_COMPAT_TARGET;
/// Without the `wrinkle` feature the option is parsed, then the command refuses to run.
#[cfg(not(feature = "wrinkle"))]
const DEFAULT_COMPAT_TARGET: f64 = 0.3;

/// `pleat wrinkle ...`.
#[cfg(feature = "wrinkle")]
mod wrinkle_cmd {
    use super::{BenchCommand, WrinkleCommand, EXIT_INPUT};
    use crate::interp_bench::{keyframe_pair, svg_plot, PairKind, Series};
    use pleat::mesh::io::{read_mesh, write_mesh};
    use pleat::mesh::TriMesh;
    use pleat::wrinkle::{
        interpolate_with_progress, read_animation, read_cwf, write_animation, write_cwf,
        BoundaryRule, Complex, Cwf, EvalOptions, FrequencyField, InterpOptions, KnoppelOptions,
        PhaseWeights, SubdivisionOptions,
    };
    use pleat::Error;
    use std::fmt::Write as _;
    use std::path::Path;
    use std::process::ExitCode;

    /// A failure and its exit code: 2 for unreadable input or bad arguments, 1 otherwise.
    struct Fail(u8, String);

    fn input(e: Error) -> Fail {
        Fail(EXIT_INPUT, e.to_string())
    }

    fn op(e: Error) -> Fail {
        let code = match e {
            Error::InvalidArgument(_) | Error::InvalidMesh(_) | Error::LimitExceeded(_) => {
                EXIT_INPUT
            }
            _ => 1,
        };
        Fail(code, e.to_string())
    }

    fn edit_fail((input, msg): crate::wrinkle_edit::Fail) -> Fail {
        Fail(if input { EXIT_INPUT } else { 1 }, msg)
    }

    pub fn run(cmd: WrinkleCommand) -> ExitCode {
        let (name, r) = match cmd {
            WrinkleCommand::Eval {
                base,
                cwf,
                levels,
                scale,
                smooth_boundary,
                max_triangles,
                out,
            } => {
                let boundary = if smooth_boundary {
                    BoundaryRule::Smooth
                } else {
                    BoundaryRule::Fixed
                };
                let opts = EvalOptions {
                    subdivision: SubdivisionOptions {
                        boundary,
                        ..Default::default()
                    },
                    displacement_scale: scale,
                    max_output_faces: max_triangles,
                    ..Default::default()
                };
                ("eval", eval(&base, &cwf, levels as usize, &opts, &out))
            }
            WrinkleCommand::FromField {
                base,
                field,
                amplitude,
                weights,
                out,
            } => {
                let weights = if weights == "edge-area" {
                    PhaseWeights::EdgeArea
                } else {
                    PhaseWeights::Cotan
                };
                (
                    "from-field",
                    from_field(&base, &field, amplitude, weights, &out),
                )
            }
            WrinkleCommand::PlaneWave {
                base,
                k,
                amplitude,
                out,
            } => ("plane-wave", plane_wave(&base, &k, amplitude, &out)),
            WrinkleCommand::Interp {
                a,
                b,
                base,
                frames,
                substeps,
                c_scale,
                tolerance,
                max_iterations,
                no_locality,
                out,
            } => {
                let opts = InterpOptions {
                    guide_frames: frames,
                    substeps,
                    c_scale,
                    gradient_tolerance: tolerance,
                    max_iterations,
                    hessian: Default::default(),
                    locality: !no_locality,
                };
                ("interp", interp(&a, &b, &base, &opts, &out))
            }
            WrinkleCommand::EvalAnim {
                base,
                anim,
                levels,
                scale,
                out,
            } => (
                "eval-anim",
                eval_anim(&base, &anim, levels as usize, scale, &out),
            ),
            WrinkleCommand::Design {
                base,
                sources,
                heat_time,
                reference,
                out,
            } => (
                "design",
                crate::wrinkle_edit::run_design(&base, &sources, heat_time, reference, &out)
                    .map_err(edit_fail),
            ),
            WrinkleCommand::Edit {
                base,
                cwf,
                regions,
                adjacency,
                reference,
                labels,
                compat_target,
                max_interface_rings,
                edit_weight,
                out,
            } => (
                "edit",
                crate::wrinkle_edit::run_edit(
                    &base,
                    &cwf,
                    &regions,
                    &crate::wrinkle_edit::EditTuning {
                        adjacency,
                        reference,
                        compat_target,
                        max_interface_rings,
                        edit_weight,
                    },
                    labels.as_deref(),
                    &out,
                )
                .map_err(edit_fail),
            ),
        };
        match r {
            Ok(()) => ExitCode::SUCCESS,
            Err(Fail(code, msg)) => {
                eprintln!("pleat wrinkle {name}: {msg}");
                ExitCode::from(code)
            }
        }
    }

    fn eval(
        base: &Path,
        cwf: &Path,
        levels: usize,
        opts: &EvalOptions,
        out: &Path,
    ) -> Result<(), Fail> {
        let mesh = read_mesh(base).map_err(input)?;
        let field = read_cwf(cwf, mesh).map_err(input)?;
        let bar = indicatif::ProgressBar::new(1000);
        let (ev, stats) = field
            .evaluate_with_progress(levels, opts, &mut |p| {
                bar.set_message(p.stage.to_string());
                bar.set_position((p.fraction * 1000.0) as u64);
                true
            })
            .map_err(op)?;
        bar.finish_and_clear();
        write_mesh(out, &ev.mesh).map_err(op)?;
        println!(
            "{}: {} levels, {} vertices, {} triangles in {:.3} s",
            out.display(),
            levels,
            ev.mesh.vertex_count(),
            ev.mesh.triangle_count(),
            stats.total_seconds()
        );
        Ok(())
    }

    fn default_amplitude(mesh: &TriMesh, amplitude: Option<f64>) -> Result<f64, Fail> {
        let a = amplitude.unwrap_or(0.005 * mesh.bbox_diagonal());
        if !(a.is_finite() && a >= 0.0) {
            return Err(Fail(
                EXIT_INPUT,
                format!("--amplitude {a} must be finite and ≥ 0"),
            ));
        }
        Ok(a)
    }

    /// Parses the per-vertex field file: `fx fy fz [amplitude]` per line, `#` comments.
    fn parse_field(
        text: &str,
        name: &str,
        n: usize,
        default_amplitude: f64,
    ) -> Result<(Vec<[f64; 3]>, Vec<f64>), Fail> {
        let mut k = Vec::with_capacity(n);
        let mut a = Vec::with_capacity(n);
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let bad = |what: &str| Fail(EXIT_INPUT, format!("{name}:{}: {what}", i + 1));
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|t| t.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad(&format!("'{line}' is not 3 or 4 numbers")))?;
            if !(v.len() == 3 || v.len() == 4) || v.iter().any(|x| !x.is_finite()) {
                return Err(bad(&format!(
                    "'{line}': expected 'fx fy fz [amplitude]' (finite numbers)"
                )));
            }
            if k.len() == n {
                return Err(bad(&format!(
                    "more lines than the base mesh's {n} vertices"
                )));
            }
            k.push([v[0], v[1], v[2]]);
            a.push(v.get(3).copied().unwrap_or(default_amplitude));
        }
        if k.len() != n {
            return Err(Fail(
                EXIT_INPUT,
                format!(
                    "{name} has {} vectors but the base mesh has {n} vertices (one line per \
                     vertex)",
                    k.len()
                ),
            ));
        }
        Ok((k, a))
    }

    fn from_field(
        base: &Path,
        field: &Path,
        amplitude: Option<f64>,
        weights: PhaseWeights,
        out: &Path,
    ) -> Result<(), Fail> {
        let mesh = read_mesh(base).map_err(input)?;
        let a0 = default_amplitude(&mesh, amplitude)?;
        let text = std::fs::read_to_string(field).map_err(|e| {
            Fail(
                EXIT_INPUT,
                format!("cannot read '{}': {e}", field.display()),
            )
        })?;
        let (k, a) = parse_field(&text, &field.display().to_string(), mesh.vertex_count(), a0)?;
        let opts = KnoppelOptions {
            weights,
            ..Default::default()
        };
        let (cwf, report) =
            Cwf::from_frequency_field(mesh, FrequencyField::PerVertex(&k), a, &opts).map_err(op)?;
        write_cwf(out, &cwf).map_err(op)?;
        println!(
            "{}: {} vertices, {} edges; Knöppel eigenvalue {:.3e} after {} iterations",
            out.display(),
            cwf.amplitude().len(),
            cwf.omega().len(),
            report.eigenvalue,
            report.iterations
        );
        Ok(())
    }

    fn interp(
        a: &Path,
        b: &Path,
        base: &Path,
        opts: &InterpOptions,
        out: &Path,
    ) -> Result<(), Fail> {
        let mesh = read_mesh(base).map_err(input)?;
        let ka = read_cwf(a, mesh.clone()).map_err(input)?;
        let kb = read_cwf(b, mesh).map_err(input)?;
        let bar = indicatif::ProgressBar::new(1000);
        let (anim, report) = interpolate_with_progress(&ka, &kb, opts, &mut |p| {
            bar.set_position((p.fraction * 1000.0) as u64);
            true
        })
        .map_err(op)?;
        bar.finish_and_clear();
        write_animation(out, &anim).map_err(op)?;
        let secs = report.history.last().map_or(0.0, |h| h.seconds);
        println!(
            "{}: {} guide frames × {} sub-steps = {} frames; {} after {} iterations (gradient \
             {:.2e}) in {secs:.2} s; E_smooth {:.4e}, E_compat {:.4e}, E_unit {:.4e}; {}",
            out.display(),
            anim.guide_intervals(),
            anim.substeps(),
            anim.frame_count(),
            report.stop.name(),
            report.iterations,
            report.final_gradient_norm(),
            report.smooth_energy,
            report.compat_energy,
            report.unit_energy,
            if opts.locality {
                format!("locality held {} vertices", report.pinned_vertices)
            } else {
                "locality off (--no-locality)".to_string()
            }
        );
        Ok(())
    }

    fn eval_anim(
        base: &Path,
        anim: &Path,
        levels: usize,
        scale: f64,
        out: &Path,
    ) -> Result<(), Fail> {
        let mesh = read_mesh(base).map_err(input)?;
        let anim = read_animation(anim, mesh).map_err(input)?;
        let pattern = out.to_string_lossy().to_string();
        if !pattern.contains("{i}") && anim.frame_count() > 1 {
            return Err(Fail(
                EXIT_INPUT,
                format!("output '{pattern}' needs a {{i}} placeholder for the frame number"),
            ));
        }
        let opts = EvalOptions {
            displacement_scale: scale,
            ..Default::default()
        };
        let width = (anim.frame_count() - 1).to_string().len();
        for i in 0..anim.frame_count() {
            let frame = anim.frame(i).map_err(op)?;
            let (ev, _) = frame.evaluate(levels, &opts).map_err(op)?;
            let path = pattern.replace("{i}", &format!("{i:0width$}"));
            write_mesh(Path::new(&path), &ev.mesh).map_err(op)?;
        }
        println!(
            "{} frames of {} triangles written to {pattern}",
            anim.frame_count(),
            anim.base().triangle_count() << (2 * levels)
        );
        Ok(())
    }

    /// `pleat bench ...`.
    pub fn bench(cmd: BenchCommand) -> ExitCode {
        #[allow(irrefutable_let_patterns)] // one variant in builds without `lod`
        let BenchCommand::Wrinkle {
            mesh,
            out_dir,
            frames,
            wavelengths,
        } = cmd
        else {
            unreachable!("only called for `bench wrinkle`")
        };
        match bench_wrinkle(&mesh, &out_dir, frames, wavelengths) {
            Ok(()) => ExitCode::SUCCESS,
            Err(Fail(code, msg)) => {
                eprintln!("pleat bench wrinkle: {msg}");
                ExitCode::from(code)
            }
        }
    }

    fn bench_wrinkle(
        meshes: &[std::path::PathBuf],
        out_dir: &Path,
        frames: usize,
        wavelengths: f64,
    ) -> Result<(), Fail> {
        let default = vec![std::path::PathBuf::from(
            "../shared/meshes/coarse_decimated-knight.off",
        )];
        let meshes = if meshes.is_empty() { &default } else { meshes };
        std::fs::create_dir_all(out_dir)
            .map_err(|e| Fail(1, format!("cannot create '{}': {e}", out_dir.display())))?;
        let mut conv_csv = String::from("mesh,pair,iteration,seconds,gradient_norm,objective\n");
        let mut conv_series = Vec::new();
        let mut abl_csv =
            String::from("mesh,pair,guide_frames,seconds,iterations,rms_difference_to_finest\n");
        let mut abl_series = Vec::new();
        for path in meshes {
            let mesh = read_mesh(path).map_err(input)?;
            let name = path
                .file_stem()
                .map_or("mesh".into(), |s| s.to_string_lossy().to_string());
            for kind in PairKind::ALL {
                let (a, b) = keyframe_pair(&mesh, kind, wavelengths).map_err(op)?;
                let opts = InterpOptions {
                    guide_frames: frames,
                    ..Default::default()
                };
                let (anim, rep) =
                    interpolate_with_progress(&a, &b, &opts, &mut |_| true).map_err(op)?;
                for h in &rep.history {
                    let _ = writeln!(
                        conv_csv,
                        "{name},{},{},{},{:e},{:e}",
                        kind.name(),
                        h.iteration,
                        h.seconds,
                        h.gradient_norm,
                        h.objective
                    );
                }
                println!(
                    "{name} / {}: {} after {} iterations, {:.2} s, gradient {:.2e}",
                    kind.name(),
                    rep.stop.name(),
                    rep.iterations,
                    rep.history.last().map_or(0.0, |h| h.seconds),
                    rep.final_gradient_norm()
                );
                conv_series.push(Series {
                    label: format!("{name} {}", kind.name()),
                    points: rep
                        .history
                        .iter()
                        .map(|h| (h.seconds, h.gradient_norm))
                        .collect(),
                });
                // ablation B.7.1: z̃(t) with fewer guide frames against the finest run
                let samples: Vec<f64> = (1..16).map(|i| i as f64 / 16.0).collect();
                let mut pts = Vec::new();
                for n in [1usize, 2, 5, 10, 25] {
                    let o = InterpOptions {
                        guide_frames: n,
                        ..opts
                    };
                    let (an, r) =
                        interpolate_with_progress(&a, &b, &o, &mut |_| true).map_err(op)?;
                    let mut sum = 0.0;
                    let mut count = 0usize;
                    for &t in &samples {
                        let (p, q) = (an.frame_at(t).map_err(op)?, anim.frame_at(t).map_err(op)?);
                        for (x, y) in p.zeta().iter().zip(q.zeta()) {
                            sum += (*x - *y).norm_sqr();
                            count += 1;
                        }
                    }
                    let rms = (sum / count.max(1) as f64).sqrt();
                    let secs = r.history.last().map_or(0.0, |h| h.seconds);
                    let _ = writeln!(
                        abl_csv,
                        "{name},{},{n},{secs},{},{rms:e}",
                        kind.name(),
                        r.iterations
                    );
                    pts.push((n as f64, rms));
                }
                abl_series.push(Series {
                    label: format!("{name} {}", kind.name()),
                    points: pts,
                });
            }
        }
        let write = |file: &str, text: &str| {
            let p = out_dir.join(file);
            std::fs::write(&p, text)
                .map_err(|e| Fail(1, format!("cannot write '{}': {e}", p.display())))
        };
        write("interp_convergence.csv", &conv_csv)?;
        write(
            "interp_convergence.svg",
            &svg_plot(
                "Interpolation: residual vs time",
                "seconds",
                "gradient norm (log10)",
                &conv_series,
                true,
            ),
        )?;
        write("interp_guide_frames.csv", &abl_csv)?;
        write(
            "interp_guide_frames.svg",
            &svg_plot(
                &format!("Ablation B.7.1: difference to N' = {frames}"),
                "guide frames N'",
                "RMS |z̃ − z̃_ref| (log10)",
                &abl_series,
                true,
            ),
        )?;
        println!(
            "wrote {}/interp_convergence.{{csv,svg}} and interp_guide_frames.{{csv,svg}}",
            out_dir.display()
        );
        Ok(())
    }

    fn plane_wave(base: &Path, k: &[f64], amplitude: Option<f64>, out: &Path) -> Result<(), Fail> {
        let mesh = read_mesh(base).map_err(input)?;
        if k.len() != 3 || k.iter().any(|c| !c.is_finite()) {
            return Err(Fail(
                EXIT_INPUT,
                "--k needs three finite numbers KX,KY,KZ".into(),
            ));
        }
        let k = [k[0], k[1], k[2]];
        let a = default_amplitude(&mesh, amplitude)?;
        let dot = |p: &[f64; 3]| k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
        let x = mesh.positions();
        let omega = mesh
            .edges()
            .edges
            .iter()
            .map(|e| dot(&x[e.0[1] as usize]) - dot(&x[e.0[0] as usize]))
            .collect();
        let zeta = x.iter().map(|p| Complex::cis(dot(p))).collect();
        let n = mesh.vertex_count();
        let cwf = Cwf::new(mesh, omega, vec![a; n], zeta).map_err(op)?;
        write_cwf(out, &cwf).map_err(op)?;
        println!(
            "{}: plane wave k = ({}, {}, {}), amplitude {a}, {} vertices, {} edges",
            out.display(),
            k[0],
            k[1],
            k[2],
            n,
            cwf.omega().len()
        );
        Ok(())
    }
}

/// Stand-in when the binary was built without the `wrinkle` feature.
#[cfg(not(feature = "wrinkle"))]
mod wrinkle_cmd {
    use super::{BenchCommand, WrinkleCommand, EXIT_INPUT};
    use std::process::ExitCode;

    pub fn run(_cmd: WrinkleCommand) -> ExitCode {
        eprintln!("pleat wrinkle: this pleat was built without the `wrinkle` feature");
        ExitCode::from(EXIT_INPUT)
    }

    pub fn bench(_cmd: BenchCommand) -> ExitCode {
        eprintln!("pleat bench wrinkle: this pleat was built without the `wrinkle` feature");
        ExitCode::from(EXIT_INPUT)
    }
}
