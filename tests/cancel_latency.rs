//! Cancellation latency of every long operation (issue 15: "every long operation honours
//! cancellation within 0.5 s of the request; measure the worst case per operation").
//!
//! Ignored tests (timings are not asserted; run in the release test profile):
//! `cargo test --release --test cancel_latency -- --ignored --nocapture --test-threads 1`.
//! Each prints one row of the README table ("Security and robustness"):
//!
//! 1. one uncancelled run records the time of every progress call: the longest gap between two
//!    calls (from the start to the first call, and from the last call to the return, included)
//!    is how long a request can wait before the operation sees it;
//! 2. [`REQUESTS`] runs request cancellation at times spread over the run (the callback answers
//!    "cancel" at its first call after the request) and measure request → return;
//! 3. [`REQUESTS`] runs answer "cancel" at call `k` for `k` spread over the calls and measure
//!    that answer → return (the unwinding: nothing but returning should follow it).
//!
//! Inputs come from `../shared/meshes` (skipped with a message when absent) and from generated
//! scenes; sizes are chosen so that each run takes seconds.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use pleat::mesh::TriMesh;
use pleat::{Error, Progress};

/// Cancellation requests per kind (time-spread and call-spread).
const REQUESTS: usize = 4;

/// The measured latencies of one operation (seconds).
#[derive(Debug, Default)]
struct Latency {
    /// Wall time of the uncancelled run.
    total: f64,
    /// Progress calls in the uncancelled run.
    calls: usize,
    /// The longest interval without a progress call, and the stage reported at its end.
    max_gap: f64,
    gap_stage: String,
    /// Worst request → return over the time-spread requests.
    worst_request: f64,
    /// Worst "cancel" answer → return over the call-spread answers.
    worst_unwind: f64,
}

impl Latency {
    /// The latency bound: a request waits at most the longest gap, then unwinds.
    fn bound(&self) -> f64 {
        self.max_gap + self.worst_unwind
    }

    fn row(&self, name: &str) -> String {
        format!(
            "| {name} | {:.2} | {} | {:.3} ({}) | {:.3} | {:.3} | {:.3} |",
            self.total,
            self.calls,
            self.max_gap,
            self.gap_stage,
            self.worst_request,
            self.worst_unwind,
            self.bound()
        )
    }
}

/// One run of the operation under measurement with the given progress callback; `Ok(())` when
/// it completed, `Err(Cancelled)` when cancelled.
type Op<'a> = dyn FnMut(&mut dyn FnMut(Progress<'_>) -> bool) -> pleat::Result<()> + 'a;

/// Measures the cancellation latency of `op` (module docs) and prints its table row.
fn measure(name: &str, op: &mut Op<'_>) -> Latency {
    let mut lat = uncancelled_gaps(op);
    for j in 1..=REQUESTS {
        let at = Duration::from_secs_f64(lat.total * j as f64 / (REQUESTS + 1) as f64);
        let dt = cancel_at_time(op, at);
        lat.worst_request = lat.worst_request.max(dt);
    }
    for j in 0..REQUESTS {
        let k = 1 + j * lat.calls.saturating_sub(1) / REQUESTS.max(1);
        if let Some(dt) = cancel_at_call(op, k) {
            lat.worst_unwind = lat.worst_unwind.max(dt);
        }
    }
    println!("{}", lat.row(name));
    lat
}

/// The uncancelled run: total time, call count, longest gap between calls.
fn uncancelled_gaps(op: &mut Op<'_>) -> Latency {
    let mut calls: Vec<(Duration, String)> = Vec::new();
    let t0 = Instant::now();
    op(&mut |p: Progress<'_>| {
        calls.push((t0.elapsed(), p.stage.to_string()));
        true
    })
    .expect("the uncancelled run succeeds");
    let total = t0.elapsed();
    calls.push((total, "(return)".into()));
    let mut lat = Latency {
        total: total.as_secs_f64(),
        calls: calls.len() - 1,
        ..Latency::default()
    };
    let mut prev = Duration::ZERO;
    for (t, stage) in calls {
        let gap = (t - prev).as_secs_f64();
        if gap > lat.max_gap {
            lat.max_gap = gap;
            lat.gap_stage = stage;
        }
        prev = t;
    }
    lat
}

/// Requests cancellation `at` after the start; seconds from the request to the return.
fn cancel_at_time(op: &mut Op<'_>, at: Duration) -> f64 {
    let t0 = Instant::now();
    let r = op(&mut |_p: Progress<'_>| t0.elapsed() < at);
    let end = t0.elapsed();
    match r {
        Err(Error::Cancelled) => (end.saturating_sub(at)).as_secs_f64(),
        Ok(()) => (end.saturating_sub(at)).as_secs_f64(), // finished before seeing it
        Err(e) => panic!("cancelled run failed otherwise: {e}"),
    }
}

/// Answers "cancel" at call `k` (1-based); seconds from that answer to the return, `None` when
/// the run made fewer calls.
fn cancel_at_call(op: &mut Op<'_>, k: usize) -> Option<f64> {
    let mut n = 0;
    let mut answered: Option<Instant> = None;
    let r = op(&mut |_p: Progress<'_>| {
        n += 1;
        if n >= k {
            answered.get_or_insert_with(Instant::now);
            false
        } else {
            true
        }
    });
    let end = Instant::now();
    match r {
        Err(Error::Cancelled) => answered.map(|a| (end - a).as_secs_f64()),
        Ok(()) => None,
        Err(e) => panic!("cancelled run failed otherwise: {e}"),
    }
}

/// `../shared/meshes/<name>` from the worktree or the main checkout; `None` (skipped, with a
/// message) when absent.
fn shared_mesh(name: &str) -> Option<TriMesh> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let found: Option<PathBuf> = ["../shared/meshes", "../../shared/meshes"]
        .iter()
        .map(|d| root.join(d).join(name))
        .find(|p| p.is_file());
    match found {
        Some(p) => Some(pleat::mesh::io::read_mesh(&p).expect("a corpus mesh reads")),
        None => {
            eprintln!("SKIPPED: ../shared/meshes/{name} is absent");
            None
        }
    }
}

fn header() {
    println!(
        "| operation | run s | progress calls | longest gap s (stage after it) | worst request→return s | worst cancel→return s | bound s |"
    );
    println!("|---|---|---|---|---|---|---|");
}

#[cfg(feature = "lod")]
mod lod {
    use super::*;
    use pleat::lowpoly::{generate, offset_surface_with_progress, LodParams, OffsetParams};

    /// 12 946 faces, sharp features: a LOD at n_p 200 takes ~10 s on one free core.
    const MESH: &str = "cad_fandisk.obj";

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn offset_cancellation_latency() {
        let Some(m) = shared_mesh(MESH) else { return };
        header();
        let p = OffsetParams::default();
        measure(&format!("offset ({MESH}, n_p 200)"), &mut |cb| {
            offset_surface_with_progress(&m, &p, cb).map(drop)
        });
    }

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn lod_cancellation_latency() {
        let Some(m) = shared_mesh(MESH) else { return };
        header();
        let p = LodParams::default();
        measure(&format!("LOD ({MESH}, n_p 200)"), &mut |cb| {
            generate(&m, &p, cb).map(drop)
        });
    }

    #[cfg(feature = "cage")]
    #[test]
    #[ignore = "measurement: seconds per run"]
    fn cage_cancellation_latency() {
        let Some(m) = shared_mesh(MESH) else { return };
        header();
        let p = LodParams::default();
        measure(&format!("cage ({MESH}, n_p 200)"), &mut |cb| {
            pleat::cage::generate(&m, &p, cb).map(drop)
        });
    }
}

#[cfg(feature = "wrinkle")]
mod wrinkle {
    use super::*;
    use pleat::wrinkle::{
        interpolate_with_progress, Cwf, EvalOptions, FrequencyField, InterpOptions, KnoppelOptions,
    };

    /// A CWF on `mesh`: `waves` wavelengths over the bounding-box diagonal along `dir`
    /// (tangential part), amplitude 0.5% of the diagonal.
    fn plane_wave(mesh: &TriMesh, dir: [f64; 3], waves: f64) -> Cwf {
        let diag = mesh.bbox_diagonal();
        let k = 2.0 * std::f64::consts::PI * waves / diag;
        let v = vec![dir.map(|c| c * k); mesh.vertex_count()];
        let amp = vec![0.005 * diag; mesh.vertex_count()];
        let opts = KnoppelOptions::default();
        Cwf::from_frequency_field(mesh.clone(), FrequencyField::PerVertex(&v), amp, &opts)
            .expect("a plane-wave CWF")
            .0
    }

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn wrinkle_evaluation_cancellation_latency() {
        let name = "coarse_decimated-knight.off";
        let Some(m) = shared_mesh(name) else { return };
        header();
        let cwf = plane_wave(&m, [1.0, 0.0, 0.0], 20.0);
        let opts = EvalOptions::default();
        // level 5: 1000 · 4⁵ ≈ 10⁶ output faces
        measure(
            &format!("wrinkle evaluation ({name}, level 5)"),
            &mut |cb| cwf.evaluate_with_progress(5, &opts, cb).map(drop),
        );
    }

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn wrinkle_interpolation_cancellation_latency() {
        let name = "coarse_spot_1k.obj";
        let Some(m) = shared_mesh(name) else { return };
        header();
        let a = plane_wave(&m, [1.0, 0.0, 0.0], 10.0);
        let b = plane_wave(&m, [0.0, 0.0, 1.0], 10.0);
        let opts = InterpOptions::default();
        measure(
            &format!("wrinkle interpolation ({name}, defaults)"),
            &mut |cb| interpolate_with_progress(&a, &b, &opts, cb).map(drop),
        );
    }
}

#[cfg(feature = "tfw")]
mod tfw {
    use super::*;
    use pleat::tfw::{solve, Scene, TfwParams};

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn tfw_solve_cancellation_latency() {
        header();
        let scene = Scene::twisted_cylinder(32, 12, 10.0);
        let p = TfwParams::default();
        measure("tfw solve (twisted cylinder 32 × 12)", &mut |cb| {
            solve(&scene, &p, cb).map(drop)
        });
    }
}

#[cfg(feature = "bake")]
mod bake {
    use super::*;
    use pleat::bake::{bake_chain, read_appearance, BakeParams};
    use pleat::lowpoly::LodParams;

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn feature_bake_cancellation_latency() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let name = "gen_fandisk_sin_xform.glb";
        let Some(path) = ["../shared/assets/textured", "../../shared/assets/textured"]
            .iter()
            .map(|d| root.join(d).join(name))
            .find(|p| p.is_file())
        else {
            eprintln!("SKIPPED: ../shared/assets/textured/{name} is absent");
            return;
        };
        let app = read_appearance(&path).expect("the asset reads");
        header();
        let (lod, params) = (LodParams::default(), BakeParams::default());
        measure(&format!("bake ({name}, n_p 50)"), &mut |cb| {
            bake_chain(&app, &[50.0], &lod, &params, cb).map(drop)
        });
    }
}
