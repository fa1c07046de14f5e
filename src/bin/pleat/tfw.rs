//! `pleat tfw SCENE.json -o OUT.obj [--cwf OUT.cwf] [--base BASE.obj] [--levels 3]`: wrinkles
//! from physics (feature `tfw`): base surface, wrinkle SQP, and the wrinkled mesh through the
//! existing evaluation with the in-plane v2 term. A thin layer over `pleat::tfw::solve`.

use std::path::PathBuf;
use std::process::ExitCode;

use pleat::mesh::io::write_mesh;
use pleat::tfw::{solve, QpMethod, Scene, TfwParams, TfwResult};
use pleat::wrinkle::{write_cwf, EvalOptions};

use super::{failure_code, progress_bar, show_progress, EXIT_FAILED, EXIT_INPUT};

/// Arguments of `pleat tfw`.
#[derive(clap::Args)]
pub struct TfwArgs {
    /// The scene file (JSON; format in docs/guide/tfw.md).
    pub scene: PathBuf,
    /// The wrinkled mesh (obj, ply, off, stl, glb, gltf).
    #[arg(short = 'o', long = "output")]
    pub out: PathBuf,
    /// Also write the complex wrinkle field on the base mesh (.cwf).
    #[arg(long)]
    pub cwf: Option<PathBuf>,
    /// Also write the base surface (the tension-field relaxed membrane).
    #[arg(long)]
    pub base: Option<PathBuf>,
    /// Loop subdivision levels of the evaluation.
    #[arg(long, default_value_t = 3)]
    pub levels: usize,
    /// Leave out the in-plane v2 term of eq. 2.19.
    #[arg(long)]
    pub no_v2: bool,
    /// SQP iteration limit.
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: usize,
    /// The SQP step solver: `clarabel` (QP with the curl constraint), `newton` (projected
    /// Newton, curl eliminated) or `default` (the library's default).
    #[arg(long, default_value = "default")]
    pub qp: String,
    /// Snap ω's periods around the base's non-contractible loops to multiples of 2π before
    /// the phase (default: as the SQP leaves them; see docs/design-notes.md).
    #[arg(long)]
    pub snap: bool,
    /// Turn off the projected Newton's valley search near the optimum (on by default; see
    /// docs/design-notes.md).
    #[arg(long)]
    pub no_valley_search: bool,
    /// No progress bar.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// Runs `pleat tfw`.
pub fn run(args: &TfwArgs) -> ExitCode {
    let scene = match Scene::from_json_file(&args.scene) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("pleat tfw: {}: {e}", args.scene.display());
            return ExitCode::from(EXIT_INPUT);
        }
    };
    if args.levels > 8 {
        eprintln!("pleat tfw: --levels must be at most 8, got {}", args.levels);
        return ExitCode::from(EXIT_INPUT);
    }
    let mut params = TfwParams::default();
    params.sqp.max_iterations = args.max_iterations;
    params.snap_periods = args.snap;
    params.sqp.valley_search = !args.no_valley_search;
    params.sqp.qp = match super::bench_tfw::parse_qp(&args.qp, params.sqp.qp) {
        Ok(q) => q,
        Err(e) => {
            eprintln!("pleat tfw: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let bar = progress_bar(args.quiet);
    let result = solve(&scene, &params, &mut |p| show_progress(&bar, p));
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let r = match result {
        Ok(r) => r,
        Err(e) => {
            eprintln!("pleat tfw: {e}");
            return ExitCode::from(failure_code(&e));
        }
    };
    print_summary(&r, params.sqp.qp);
    match write_outputs(args, &r) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("pleat tfw: {e}");
            ExitCode::from(EXIT_FAILED)
        }
    }
}

fn write_outputs(args: &TfwArgs, r: &TfwResult) -> pleat::Result<()> {
    if let Some(p) = &args.base {
        write_mesh(p, &r.base.mesh)?;
    }
    if let Some(p) = &args.cwf {
        write_cwf(p, &r.cwf)?;
    }
    let opts = EvalOptions {
        in_plane_v2: !args.no_v2,
        ..EvalOptions::default()
    };
    let (ev, _) = r.cwf.evaluate(args.levels, &opts)?;
    write_mesh(&args.out, &ev.mesh)
}

fn print_summary(r: &TfwResult, qp: QpMethod) {
    println!("status        {:?}: {}", r.status, r.status.describe());
    println!(
        "base          {:?} in {} Newton iterations, {:.3} s",
        r.base.status,
        r.base.history.len(),
        r.seconds.base
    );
    for w in &r.base.warnings {
        println!("  warning     {w}");
    }
    let nw = r.w_faces.iter().filter(|&&w| w).count();
    println!("W faces       {nw} of {}", r.w_faces.len());
    if let Some(s) = &r.sqp {
        println!("step solver   {qp:?}");
        let last_r = s
            .history
            .last()
            .map_or(s.initial_stationarity, |i| i.stationarity);
        println!(
            "SQP           {:?} in {} iterations, {:.3} s ({:.3} s in steps)",
            s.status,
            s.history.len(),
            r.seconds.sqp,
            s.qp_seconds
        );
        println!(
            "energy        {:.6e} J → {:.6e} J; stationarity {:.3e} → {:.3e}",
            s.initial_energy, r.energy, s.initial_stationarity, last_r
        );
        if let Some(i) = s.rescued_at {
            println!("SQP rescue    at iteration {i} (step weights raised; docs/design-notes.md)");
        }
    }
    if let Some(s) = &r.snap {
        let loops: Vec<String> = s
            .loops
            .iter()
            .map(|l| format!("{:.4} → {:.4} rad (k {})", l.before, l.after, l.waves))
            .collect();
        println!(
            "period snap   {} loop(s) [{}], {} kept (around W islands); |δω| {:.3e} of |ω| {:.3e}",
            s.loops.len(),
            loops.join(", "),
            s.kept_loops,
            s.correction_norm,
            s.omega_norm
        );
    }
    let max_a = r.cwf.amplitude().iter().fold(0.0f64, |m, &a| m.max(a));
    println!(
        "peak a        {max_a:.6e} m; curl residual {:.1e}",
        r.curl_residual
    );
    println!(
        "seconds       init {:.3}, phase {:.3}",
        r.seconds.init, r.seconds.phase
    );
}
