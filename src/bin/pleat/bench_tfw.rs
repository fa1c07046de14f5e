//! `pleat bench tfw`: error against run time of the tension-field wrinkle solve.
//!
//! Solves each scene (JSON files given, and/or built-ins by name) with [`pleat::tfw::solve`]
//! and writes into `--out-dir`:
//! - `tfw_iterations.csv`: one row per SQP iteration: scene, iteration, wall seconds since the
//!   start of the whole solve (base included), energy `E^wf` (J), stationarity residual `r`,
//!   `r / r₀`, step `‖Δx‖∞`, then (appended 2026-11-27) `waves` and `peak_amplitude` (m, max a)
//!   on the rows of the SQP's start, every `--wave-every` iterations and the last one (empty
//!   elsewhere): the iterate is turned into a `Cwf` (Knöppel phase) and its waves counted by
//!   [`pleat::tfw::measure::count_waves`] (2 Loop levels) along the section that
//!   [`pleat::tfw::measure::count_waves_auto`] picks for the final field — after the solve, so
//!   the timings do not include it;
//! - `tfw_scenes.csv`: one row per scene: vertices, triangles, base seconds and Newton
//!   iterations, SQP seconds and iterations, total seconds, status (or the error), peak
//!   amplitude (m), final energy and relative residual, then (appended) the final `waves`, the
//!   `section` they were counted on and the step solver `qp`;
//! - `tfw_bench.svg`: two panels, `r / r₀` and `E / E₀` (log) against wall seconds, one line per
//!   scene (the plot writer of `pleat bench wrinkle`).
//!
//! A failing scene (unreadable, invalid, numerical failure) becomes a summary row with its
//! status; the sweep continues.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use pleat::tfw::measure::{count_waves, count_waves_auto, Section};
use pleat::tfw::{solve, QpMethod, Scene, TfwParams, TfwResult};
use pleat::wrinkle::Cwf;

use super::interp_bench::{svg_plot, Series};
use super::{progress_bar, show_progress, EXIT_FAILED, EXIT_INPUT};

/// Built-in scene names of `--builtin`.
const BUILTINS: [&str; 9] = [
    "sheet",
    "sheet-small",
    "cylinder",
    "sheared-rectangle",
    "disk-balloon",
    "torus-balloon",
    "teabag",
    "sphere-drape",
    "sphere-drape-delaunay",
];

/// Options of `pleat bench tfw`.
#[derive(clap::Args)]
pub struct TfwBenchArgs {
    /// Scene files (JSON). Without files and without --builtin: the built-in `sheet`.
    pub scenes: Vec<PathBuf>,
    /// Built-in scenes, comma separated: `sheet` (the shipped stretched sheet, 37 × 14
    /// vertices, 5 % stretch), `sheet-small` (13 × 6), `cylinder` (twisted cylinder, 43 × 16,
    /// 10°), and the speed-table scenes of docs/benchmarks/tfw.md: `sheared-rectangle` (1000 v, 3
    /// mm shear), `disk-balloon` (2 × 600 v, 600 Pa), `torus-balloon` (2 × 800 v, 600 Pa), `teabag`
    /// (2 × 468 v, 10 Pa), `sphere-drape` (S:676: 1 m cloth on a 0.2 m sphere, 41 × 41 v) and
    /// `sphere-drape-delaunay` (the same cloth on an irregular Delaunay mesh of ~1681 v).
    #[arg(long, value_delimiter = ',')]
    pub builtin: Vec<String>,
    /// Folder for tfw_iterations.csv, tfw_scenes.csv and tfw_bench.svg (created if missing).
    #[arg(long, default_value = ".")]
    pub out_dir: PathBuf,
    /// SQP iteration limit per scene.
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: usize,
    /// SQP wall-time budget per scene in seconds (0 = none).
    #[arg(long, default_value_t = 0.0)]
    pub time_limit: f64,
    /// Count waves every N SQP iterations (0 = only at the start and the end).
    #[arg(long, default_value_t = 10)]
    pub wave_every: usize,
    /// The SQP step solver: `clarabel` or `newton` (projected Newton, curl eliminated).
    #[arg(long, default_value = "default")]
    pub qp: String,
    /// No progress bar.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// One scene to run: its name and the scene (or why it could not be loaded).
struct Case {
    name: String,
    scene: pleat::Result<Scene>,
}

/// The measurements of one scene.
struct Outcome {
    name: String,
    result: pleat::Result<TfwResult>,
    seconds: f64,
    /// Per measured iteration: (iteration, waves, peak amplitude).
    waves: Vec<(usize, f64, f64)>,
    /// The section the waves were counted on (empty when not measured).
    section: String,
}

/// The built-in scene `name`.
fn builtin(name: &str) -> Option<Scene> {
    match name {
        "sheet" => Some(Scene::stretched_sheet(37, 14, 0.05)),
        "sheet-small" => Some(Scene::stretched_sheet(13, 6, 0.05)),
        "cylinder" => Some(Scene::twisted_cylinder(43, 16, 10.0)),
        // the irregular meshers only fail on degenerate outlines: these are fixed
        "sheared-rectangle" => Scene::sheared_rectangle(1000, 3.0, 0.0, 1).ok(),
        "disk-balloon" => Scene::disk_balloon(600, 600.0, 1).ok(),
        "torus-balloon" => Scene::torus_balloon(800, 600.0, 1).ok(),
        "teabag" => Scene::teabag(468, 10.0, 1).ok(),
        "sphere-drape" => Some(Scene::sphere_drape(41, 1.0)),
        "sphere-drape-delaunay" => Scene::sphere_drape_delaunay(1681, 1.0, 1).ok(),
        _ => None,
    }
}

fn cases(args: &TfwBenchArgs) -> Result<Vec<Case>, String> {
    let mut out = Vec::new();
    for name in &args.builtin {
        let scene = builtin(name).ok_or_else(|| {
            format!(
                "unknown built-in scene {name:?} (known: {})",
                BUILTINS.join(", ")
            )
        })?;
        out.push(Case {
            name: name.clone(),
            scene: Ok(scene),
        });
    }
    for path in &args.scenes {
        let name = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into(),
        );
        out.push(Case {
            name,
            scene: Scene::from_json_file(path),
        });
    }
    if out.is_empty() {
        out.push(Case {
            name: "sheet".into(),
            scene: Ok(builtin("sheet").expect("built-in")),
        });
    }
    Ok(out)
}

/// Runs `pleat bench tfw`.
pub fn run(args: &TfwBenchArgs) -> ExitCode {
    if !(args.time_limit.is_finite() && args.time_limit >= 0.0) || args.max_iterations == 0 {
        eprintln!("pleat bench tfw: --time-limit must be finite and ≥ 0, --max-iterations ≥ 1");
        return ExitCode::from(EXIT_INPUT);
    }
    let cases = match cases(args) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("pleat bench tfw: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let mut params = TfwParams::default();
    params.sqp.max_iterations = args.max_iterations;
    params.sqp.snapshot_every = args.wave_every;
    params.sqp.qp = match parse_qp(&args.qp, params.sqp.qp) {
        Ok(q) => q,
        Err(e) => {
            eprintln!("pleat bench tfw: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    if args.time_limit > 0.0 {
        params.sqp.time_limit_seconds = args.time_limit;
    }
    let bar = progress_bar(args.quiet);
    let count = cases.len();
    let outcomes: Vec<Outcome> = cases
        .into_iter()
        .enumerate()
        .map(|(i, c)| {
            let t = std::time::Instant::now();
            let result = c.scene.and_then(|s| {
                solve(&s, &params, &mut |p| {
                    show_progress(
                        &bar,
                        pleat::Progress {
                            stage: p.stage,
                            fraction: (i as f64 + p.fraction) / count as f64,
                        },
                    )
                })
            });
            let seconds = t.elapsed().as_secs_f64();
            let (waves, section) = match &result {
                Ok(r) => wave_history(r, &params),
                Err(_) => (Vec::new(), String::new()),
            };
            Outcome {
                name: c.name,
                result,
                seconds,
                waves,
                section,
            }
        })
        .collect();
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    match write_outputs(&args.out_dir, &outcomes, params.sqp.qp) {
        Ok(()) => {
            print_summary(&outcomes);
            println!(
                "wrote {}/tfw_iterations.csv, tfw_scenes.csv and tfw_bench.svg",
                args.out_dir.display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("pleat bench tfw: {e}");
            ExitCode::from(EXIT_FAILED)
        }
    }
}

/// Levels of the evaluation the waves are counted on.
const WAVE_LEVELS: usize = 2;

/// Waves and peak amplitude at the SQP's snapshots and at the end (module docs), and the
/// section used. Measurement failures leave the rows empty.
fn wave_history(r: &TfwResult, params: &TfwParams) -> (Vec<(usize, f64, f64)>, String) {
    let Ok((section, last)) = count_waves_auto(&r.cwf, WAVE_LEVELS) else {
        return (Vec::new(), String::new());
    };
    let peak = |a: &[f64]| a.iter().fold(0.0f64, |m, &v| m.max(v));
    let mut out = Vec::new();
    let nv = r.base.mesh.vertex_count();
    let iterations = r.sqp.as_ref().map_or(0, |s| s.history.len());
    if let Some(s) = &r.sqp {
        for (k, x) in &s.snapshots {
            if *k == iterations {
                continue;
            }
            let (a, w) = x.split_at(nv);
            let counted =
                Cwf::from_one_form(r.base.mesh.clone(), w.to_vec(), a.to_vec(), &params.knoppel)
                    .ok()
                    .and_then(|(cwf, _)| count_waves(&cwf, WAVE_LEVELS, &section).ok());
            if let Some(c) = counted {
                out.push((*k, c.waves, peak(a)));
            }
        }
    }
    out.push((iterations, last.waves, peak(r.cwf.amplitude())));
    (out, describe(&section))
}

/// `ring n=(…) at (…)` / `line n=(…) at (…)`.
fn describe(s: &Section) -> String {
    let v = |p: [f64; 3]| format!("{:.4} {:.4} {:.4}", p[0], p[1], p[2]);
    format!(
        "{} normal ({}) through ({})",
        if s.closed { "ring" } else { "line" },
        v(s.normal),
        v(s.point)
    )
}

/// The step solver named by a `--qp` value (`default` keeps `default`), or the message.
pub(super) fn parse_qp(name: &str, default: QpMethod) -> Result<QpMethod, String> {
    match name {
        "default" => Ok(default),
        "clarabel" => Ok(QpMethod::Clarabel),
        "newton" => Ok(QpMethod::ProjectedNewton),
        other => Err(format!(
            "--qp {other:?}: expected clarabel, newton or default"
        )),
    }
}

fn write_outputs(dir: &Path, outcomes: &[Outcome], qp: QpMethod) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("tfw_iterations.csv"), iterations_csv(outcomes))?;
    std::fs::write(dir.join("tfw_scenes.csv"), scenes_csv(outcomes, qp))?;
    std::fs::write(dir.join("tfw_bench.svg"), svg(outcomes))
}

/// A CSV field: quoted when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// One SQP iteration of a scene, as written to the CSV and plotted.
struct IterRow {
    /// Wall seconds since the solve started (base included).
    seconds: f64,
    /// `E^wf` (J).
    energy: f64,
    /// Stationarity residual `r`.
    residual: f64,
    /// `r / r₀`.
    relative: f64,
    /// `‖Δx‖∞` of the accepted step.
    step: f64,
    /// Waves and peak amplitude when measured at this iteration.
    waves: Option<(f64, f64)>,
}

/// Per SQP iteration, the row of [`IterRow`]; row 0 is the SQP's starting point.
fn iteration_rows(r: &TfwResult) -> Vec<IterRow> {
    iteration_rows_with(r, &[])
}

/// [`iteration_rows`] with the measured waves (iteration, waves, peak) filled in.
fn iteration_rows_with(r: &TfwResult, waves: &[(usize, f64, f64)]) -> Vec<IterRow> {
    let Some(s) = &r.sqp else {
        return Vec::new();
    };
    let t0 = r.seconds.base + r.seconds.init;
    let r0 = s.initial_stationarity;
    let rel = |x: f64| if r0 > 0.0 { x / r0 } else { 0.0 };
    let mut rows = vec![IterRow {
        seconds: t0,
        energy: s.initial_energy,
        residual: r0,
        relative: rel(r0),
        step: 0.0,
        waves: None,
    }];
    rows.extend(s.history.iter().map(|it| IterRow {
        seconds: t0 + it.seconds,
        energy: it.energy,
        residual: it.stationarity,
        relative: rel(it.stationarity),
        step: it.step_norm,
        waves: None,
    }));
    for &(k, w, p) in waves {
        if let Some(row) = rows.get_mut(k) {
            row.waves = Some((w, p));
        }
    }
    rows
}

fn iterations_csv(outcomes: &[Outcome]) -> String {
    let mut s = String::from(
        "scene,iteration,seconds,energy,residual,relative_residual,step,waves,peak_amplitude\n",
    );
    for o in outcomes {
        let Ok(r) = &o.result else { continue };
        for (i, row) in iteration_rows_with(r, &o.waves).into_iter().enumerate() {
            let waves = row
                .waves
                .map_or_else(|| ",".to_string(), |(w, p)| format!("{w},{p:e}"));
            let _ = writeln!(
                s,
                "{},{i},{:.6},{:e},{:e},{:e},{:e},{waves}",
                csv_field(&o.name),
                row.seconds,
                row.energy,
                row.residual,
                row.relative,
                row.step
            );
        }
    }
    s
}

fn scenes_csv(outcomes: &[Outcome], qp: QpMethod) -> String {
    let mut s = String::from(
        "scene,vertices,triangles,base_seconds,base_iterations,sqp_seconds,sqp_iterations,\
         total_seconds,status,peak_amplitude,energy,relative_residual,waves,section,qp\n",
    );
    for o in outcomes {
        let name = csv_field(&o.name);
        match &o.result {
            Ok(r) => {
                let m = &r.base.mesh;
                let iters = r.sqp.as_ref().map_or(0, |q| q.history.len());
                let rel = iteration_rows(r).last().map_or(0.0, |row| row.relative);
                let peak = r.cwf.amplitude().iter().fold(0.0f64, |a, &b| a.max(b));
                let waves = o.waves.last().map_or(String::new(), |w| w.1.to_string());
                let _ = writeln!(
                    s,
                    "{name},{},{},{:.6},{},{:.6},{iters},{:.6},{:?},{peak:e},{:e},{rel:e},{waves},{},{:?}",
                    m.vertex_count(),
                    m.triangle_count(),
                    r.seconds.base,
                    r.base.history.len(),
                    r.seconds.sqp,
                    o.seconds,
                    r.status,
                    r.energy,
                    csv_field(&o.section),
                    qp,
                );
            }
            Err(e) => {
                let status = csv_field(&format!("error: {e}"));
                let _ = writeln!(s, "{name},,,,,,,{:.6},{status},,,,,,", o.seconds);
            }
        }
    }
    s
}

/// Two plots stacked in one SVG: `r/r₀` and `E/E₀` against seconds, log y.
fn svg(outcomes: &[Outcome]) -> String {
    let series = |col: fn(&IterRow, f64) -> f64| -> Vec<Series> {
        outcomes
            .iter()
            .filter_map(|o| o.result.as_ref().ok().map(|r| (o, r)))
            .map(|(o, r)| {
                let rows = iteration_rows(r);
                let e0 = rows.first().map_or(1.0, |row| row.energy);
                Series {
                    label: o.name.clone(),
                    points: rows.iter().map(|row| (row.seconds, col(row, e0))).collect(),
                }
            })
            .collect()
    };
    let residual = svg_plot(
        "TFW SQP: relative stationarity residual",
        "wall seconds (base included)",
        "r / r0",
        &series(|row, _| row.relative),
        true,
    );
    let energy = svg_plot(
        "TFW SQP: wrinkle energy",
        "wall seconds (base included)",
        "E / E0",
        &series(|row, e0| if e0 != 0.0 { row.energy / e0 } else { 0.0 }),
        true,
    );
    let inner = |svg: &str, y: u32| svg.replacen("<svg ", &format!("<svg y=\"{y}\" "), 1);
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"800\">\n{}{}</svg>\n",
        inner(&residual, 0),
        inner(&energy, 400)
    )
}

fn print_summary(outcomes: &[Outcome]) {
    println!(
        "{:<16} {:>6} {:>8} {:>8} {:>6} {:>10} {:>10} {:>6}  status",
        "scene", "verts", "base s", "SQP s", "iters", "peak mm", "r/r0", "waves"
    );
    for o in outcomes {
        match &o.result {
            Ok(r) => {
                let rel = iteration_rows(r).last().map_or(0.0, |row| row.relative);
                let peak = r.cwf.amplitude().iter().fold(0.0f64, |a, &b| a.max(b));
                let waves = o.waves.last().map_or(f64::NAN, |w| w.1);
                println!(
                    "{:<16} {:>6} {:>8.3} {:>8.3} {:>6} {:>10.4} {:>10.2e} {:>6}  {:?}",
                    o.name,
                    r.base.mesh.vertex_count(),
                    r.seconds.base,
                    r.seconds.sqp,
                    r.sqp.as_ref().map_or(0, |q| q.history.len()),
                    peak * 1e3,
                    rel,
                    waves,
                    r.status
                );
            }
            Err(e) => println!("{:<16} error: {e}", o.name),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every name `--builtin` lists builds its scene, and no other name does.
    #[test]
    fn every_listed_builtin_builds() {
        for name in BUILTINS {
            assert!(builtin(name).is_some(), "{name}");
        }
        assert!(builtin("tea-bag").is_none());
    }
}
