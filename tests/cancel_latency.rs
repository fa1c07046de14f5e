//! Cancellation latency of every long operation (requirement: every long operation honours
//! cancellation within 0.5 s of the request; the worst case is measured per operation).
//!
//! Ignored tests (timings are not asserted; run in the release test profile):
//! `cargo test --release --test cancel_latency -- --ignored --nocapture --test-threads 1`.
//! Each prints one row of the docs/benchmarks/wrinkle.md table ("Cancellation latency"):
//!
//! 1. one uncancelled run records the time of every progress call: the longest gap between two
//!    calls (from the start to the first call, and from the last call to the return, included)
//!    is how long a request can wait before the operation sees it;
//! 2. [`REQUESTS`] runs request cancellation at times spread over the run (the callback answers
//!    "cancel" at its first call after the request) and measure request → return;
//! 3. [`REQUESTS`] runs answer "cancel" at call `k` for `k` spread over the calls and measure
//!    that answer → return (the unwinding: nothing but returning should follow it).
//!
//! With `PLEAT_LATENCY_GAPS_ONLY=1` only the uncancelled run is made (to locate the gaps: each
//! test prints its 3 longest gaps with the stages before and after them).
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
type Op<'a> = OpWith<'a, ()>;

/// As [`Op`], with an output of type `T`.
type OpWith<'a, T> = dyn FnMut(&mut dyn FnMut(Progress<'_>) -> bool) -> pleat::Result<T> + 'a;

/// Measures the cancellation latency of `op` (module docs) and prints its table row.
fn measure(name: &str, op: &mut Op<'_>) -> Latency {
    let mut lat = uncancelled_gaps(op);
    if std::env::var_os("PLEAT_LATENCY_GAPS_ONLY").is_some() {
        println!("{}", lat.row(name));
        return lat;
    }
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
    let mut calls: Vec<(Duration, f64, String)> = Vec::new();
    let t0 = Instant::now();
    let cpu0 = process_cpu_seconds();
    op(&mut |p: Progress<'_>| {
        let label = format!("{} {:.3}", p.stage, p.fraction);
        calls.push((t0.elapsed(), process_cpu_seconds() - cpu0, label));
        true
    })
    .expect("the uncancelled run succeeds");
    let total = t0.elapsed();
    calls.push((total, process_cpu_seconds() - cpu0, "(return)".into()));
    let mut lat = Latency {
        total: total.as_secs_f64(),
        calls: calls.len() - 1,
        ..Latency::default()
    };
    let mut prev = (Duration::ZERO, 0.0, String::from("(start)"));
    let mut gaps: Vec<Gap> = Vec::new();
    for (t, cpu, stage) in calls {
        let gap = (t - prev.0).as_secs_f64();
        gaps.push(Gap {
            wall: gap,
            cpu: cpu - prev.1,
            between: format!("{} → {stage}", prev.2),
        });
        if gap > lat.max_gap {
            lat.max_gap = gap;
            lat.gap_stage = stage.clone();
        }
        prev = (t, cpu, stage);
    }
    print_longest_gaps(gaps);
    lat
}

/// One interval between progress calls: wall seconds, CPU seconds of the process (all
/// threads), and the calls on both sides (stage and fraction).
struct Gap {
    wall: f64,
    cpu: f64,
    between: String,
}

/// Prints the 3 longest gaps by wall time and the longest by CPU time, with the calls on both
/// sides (where to add a cancellation point). The CPU time does not grow with the load of a
/// shared machine: on a free machine a gap takes at most its CPU seconds (fewer when parallel).
fn print_longest_gaps(mut gaps: Vec<Gap>) {
    gaps.sort_by(|a, b| b.wall.total_cmp(&a.wall));
    for g in gaps.iter().take(3) {
        println!("  gap {:.3} s ({:.2} CPU s): {}", g.wall, g.cpu, g.between);
    }
    if let Some(g) = gaps.iter().max_by(|a, b| a.cpu.total_cmp(&b.cpu)) {
        println!(
            "  longest by CPU: {:.2} CPU s ({:.3} s): {}",
            g.cpu, g.wall, g.between
        );
    }
}

/// CPU seconds used by this process so far (user + system, all threads; from `/proc/self/stat`
/// at the kernel's 100 Hz tick, so 10 ms resolution); 0 where unavailable.
fn process_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // fields after the parenthesized command name: state is field 3, utime 14, stime 15
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        f.get(i - 3)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(14) + ticks(15)) / 100.0
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

#[path = "common/shapes.rs"]
mod shapes;

/// The validity report (`MeshReport::compute_with_progress`, behind
/// `pleat_mesh_check_with_progress`) of 10⁶ tiny disjoint triangles, self-intersections
/// included.
#[test]
#[ignore = "measurement: seconds per run"]
fn mesh_check_cancellation_latency() {
    header();
    measure_mesh_check(
        "mesh check (10⁶ tiny components)",
        &shapes::tiny_components(100),
    );
}

/// Measures `MeshReport::compute_with_progress` (default options) on `m` (stage `"check"`).
fn measure_mesh_check(name: &str, m: &TriMesh) {
    use pleat::verify::{MeshReport, ReportOptions};
    let opts = ReportOptions::default();
    measure(name, &mut |cb| {
        let mut keep_going = |fraction: f64| {
            cb(Progress {
                stage: "check",
                fraction,
            })
        };
        MeshReport::compute_with_progress(m, &opts, &mut keep_going)
            .map(drop)
            .ok_or(Error::Cancelled)
    });
}

/// The validity report of a pile of 20 000 near-copies of one triangle (corners jittered by
/// ±10⁻⁹, `shapes::jittered_pile`): one broad-phase chunk of 2·10⁸ candidate pairs, counted in
/// rounds with a call after each and stopped at the cap on counted hits.
#[test]
#[ignore = "measurement: seconds per run"]
fn mesh_check_pile_cancellation_latency() {
    header();
    measure_mesh_check(
        "mesh check (20 000 jittered copies of a triangle)",
        &shapes::jittered_pile(20_000),
    );
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

    /// The setup of a LOD (the guard's input model: the face BVH of 10⁶ tiny components and
    /// their degeneracy flags) up to its first progress call after the setup, where the run
    /// stops (the bake itself is measured above on a corpus mesh).
    #[test]
    #[ignore = "measurement: seconds per run"]
    fn lod_setup_cancellation_latency() {
        let m = super::shapes::tiny_components(100);
        header();
        // the memory estimate counts the fit's coverage samples (≈ 3.5 GiB here, measured
        // peak 1.96 GiB), over the default 2 GiB: this measures cancellation, not the budget
        let p = LodParams {
            screen_size: 16.0,
            memory_budget_bytes: 8 << 30,
            ..LodParams::default()
        };
        measure("LOD setup (10⁶ tiny components, n_p 16)", &mut |cb| {
            let mut past_setup = false;
            let r = generate(&m, &p, &mut |q: Progress<'_>| {
                if q.stage != "setup" {
                    past_setup = true;
                    return false;
                }
                cb(q)
            });
            match r {
                Err(Error::Cancelled) if past_setup => Ok(()),
                other => other.map(drop),
            }
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

/// Runs `op` uncancelled with a callback recording its calls, checks that the output (`bytes`)
/// equals that of `plain` (no callback) and that the fractions never go back, then answers
/// "cancel" at the first, a third, two thirds and the last call: each run must end in
/// `Cancelled` at exactly that call. Returns the call count.
#[cfg(feature = "wrinkle")]
fn cancels_at_every_point<T>(
    what: &str,
    plain: &mut dyn FnMut() -> pleat::Result<T>,
    op: &mut OpWith<'_, T>,
    bytes: &dyn Fn(&T) -> String,
) -> usize {
    let expected = bytes(&plain().expect("the plain run succeeds"));
    let mut fractions = Vec::new();
    let out = op(&mut |p: Progress<'_>| {
        fractions.push(p.fraction);
        true
    })
    .expect("the uncancelled run succeeds");
    assert!(
        bytes(&out) == expected,
        "{what}: the output with a progress callback differs from the plain one"
    );
    let n = fractions.len();
    assert!(n >= 2, "{what}: only {n} progress calls");
    assert!(
        fractions.windows(2).all(|w| w[0] <= w[1])
            && fractions.iter().all(|f| (0.0..=1.0).contains(f)),
        "{what}: fractions go back or leave [0, 1]: {fractions:?}"
    );
    for k in [1, n.div_ceil(3), 2 * n / 3, n] {
        let mut calls = 0;
        let r = op(&mut |_p: Progress<'_>| {
            calls += 1;
            calls < k
        });
        assert!(
            matches!(r, Err(Error::Cancelled)),
            "{what}: cancel at call {k} of {n} did not cancel"
        );
        assert_eq!(calls, k, "{what}: calls after the cancel at {k}");
    }
    n
}

#[cfg(feature = "wrinkle")]
mod wrinkle {
    use super::shapes::icosphere;
    use super::*;
    use pleat::wrinkle::{
        animation_to_string, cwf_to_string, design, design_with_progress, edit, edit_with_progress,
        grow_faces, interpolate, interpolate_with_progress, Adjacency, Cwf, DesignOptions,
        EditOptions, EvalOptions, FrequencyField, InterpOptions, KnoppelOptions, LoopHierarchy,
        RegionEdit, SubdivisionOptions, WrinkleSource,
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

    /// `sources` wrinkle sources spread over the vertices of `mesh` (every `n/sources`-th), of
    /// `rings` rings, 20 wavelengths over the diagonal along x, amplitude 0.5 % of it.
    fn spread_sources(mesh: &TriMesh, sources: usize, rings: usize) -> Vec<WrinkleSource> {
        let diag = mesh.bbox_diagonal();
        let k = 2.0 * std::f64::consts::PI * 20.0 / diag;
        let n = mesh.vertex_count();
        (0..sources)
            .map(|i| WrinkleSource {
                vertex: (i * n / sources) as u32,
                wave_vector: [k, 0.0, 0.3 * k],
                amplitude: 0.005 * diag,
                rings,
            })
            .collect()
    }

    /// The vertex of `mesh` minimizing `f(position)`.
    fn vertex_min_by(mesh: &TriMesh, f: impl Fn(&[f64; 3]) -> f64) -> u32 {
        let p = mesh.positions();
        (0..p.len() as u32)
            .min_by(|&a, &b| f(&p[a as usize]).total_cmp(&f(&p[b as usize])))
            .expect("a vertex")
    }

    /// A region of `rings` rings around vertex `v`, rotated by 1 rad, frequency ×2.
    fn rotated_region(mesh: &TriMesh, v: u32, rings: usize) -> RegionEdit {
        let faces = grow_faces(mesh, &[], &[v], rings, Adjacency::Vertex).expect("a region");
        RegionEdit {
            rotate: 1.0,
            frequency_scale: 2.0,
            ..RegionEdit::new(faces)
        }
    }

    #[test]
    fn interpolation_cancels_at_every_point_and_is_unchanged_otherwise() {
        let m = icosphere(1.0, 2);
        let a = plane_wave(&m, [1.0, 0.0, 0.0], 2.0);
        let b = plane_wave(&m, [0.0, 1.0, 0.0], 2.0);
        // 19 unknown frames: three batches of the preconditioner's factorization
        let opts = InterpOptions {
            guide_frames: 20,
            ..Default::default()
        };
        let n = cancels_at_every_point(
            "interpolation",
            &mut || interpolate(&a, &b, &opts).map(|r| r.0),
            &mut |cb| interpolate_with_progress(&a, &b, &opts, cb).map(|r| r.0),
            &|anim| animation_to_string(anim),
        );
        println!("interpolation: {n} progress calls");
    }

    #[test]
    fn design_cancels_at_every_point_and_is_unchanged_otherwise() {
        let m = icosphere(1.0, 3);
        let sources = spread_sources(&m, 3, 3);
        let opts = DesignOptions::default();
        let n = cancels_at_every_point(
            "design",
            &mut || design(m.clone(), &sources, &opts).map(|r| r.0),
            &mut |cb| design_with_progress(m.clone(), &sources, &opts, cb).map(|r| r.0),
            &|cwf| cwf_to_string(cwf),
        );
        println!("design: {n} progress calls");
    }

    #[test]
    fn edit_cancels_at_every_point_and_is_unchanged_otherwise() {
        let m = icosphere(1.0, 3);
        let cwf = plane_wave(&m, [1.0, 0.0, 0.0], 3.0);
        let centre = vertex_min_by(&m, |p| -p[2]);
        let regions = [rotated_region(&m, centre, 2)];
        // a compatibility target that needs several attempts (wider interfaces)
        let opts = EditOptions {
            compat_target: 1e-9,
            max_interface_rings: 5,
            ..Default::default()
        };
        let labels = |r: &(Cwf, pleat::wrinkle::EditReport)| {
            format!(
                "{}{:?}{}",
                cwf_to_string(&r.0),
                r.1.face_class,
                r.1.attempts
            )
        };
        let n = cancels_at_every_point(
            "edit",
            &mut || edit(&cwf, &regions, &opts),
            &mut |cb| edit_with_progress(&cwf, &regions, &opts, cb),
            &labels,
        );
        println!("edit: {n} progress calls");
    }

    /// `name` Loop-subdivided `levels` times (the wrinkle evaluation's Loop scheme).
    fn subdivided(name: &str, levels: usize) -> Option<TriMesh> {
        let m = shared_mesh(name)?;
        let h = LoopHierarchy::new(&m, levels, &SubdivisionOptions::default()).expect("Loop");
        Some(h.mesh(levels))
    }

    /// Base of the design and edit measurements: 13 334 faces × 4 = 53 336 (Loop 2: 213 344,
    /// with `PLEAT_LATENCY_LOOP=2`).
    const LARGE: (&str, usize) = ("clean_cheburashka.obj", 1);

    /// The Loop levels of the design and edit base: `PLEAT_LATENCY_LOOP`, default `LARGE.1`.
    fn large_levels() -> usize {
        std::env::var("PLEAT_LATENCY_LOOP")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(LARGE.1)
    }

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn wrinkle_design_cancellation_latency() {
        let Some(m) = subdivided(LARGE.0, large_levels()) else {
            return;
        };
        header();
        let sources = spread_sources(&m, 8, 40);
        let opts = DesignOptions::default();
        measure(
            &format!(
                "wrinkle design ({} Loop {}, {} faces, 8 sources of 40 rings)",
                LARGE.0,
                large_levels(),
                m.triangle_count()
            ),
            &mut |cb| design_with_progress(m.clone(), &sources, &opts, cb).map(drop),
        );
    }

    #[test]
    #[ignore = "measurement: seconds per run"]
    fn wrinkle_edit_cancellation_latency() {
        let Some(m) = subdivided(LARGE.0, large_levels()) else {
            return;
        };
        header();
        let cwf = plane_wave(&m, [1.0, 0.0, 0.0], 20.0);
        // at the two ends along x: the regions stay apart
        let (left, right) = (vertex_min_by(&m, |p| p[0]), vertex_min_by(&m, |p| -p[0]));
        let regions = [rotated_region(&m, left, 30), rotated_region(&m, right, 30)];
        let opts = EditOptions::default();
        measure(
            &format!(
                "wrinkle edit ({} Loop {}, {} faces, 2 regions of 30 rings)",
                LARGE.0,
                large_levels(),
                m.triangle_count()
            ),
            &mut |cb| edit_with_progress(&cwf, &regions, &opts, cb).map(drop),
        );
        let global = [RegionEdit {
            rotate: 1.0,
            ..RegionEdit::new((0..m.triangle_count() as u32).collect())
        }];
        measure(
            &format!(
                "wrinkle edit ({} Loop {}, every face: Knöppel)",
                LARGE.0,
                large_levels()
            ),
            &mut |cb| edit_with_progress(&cwf, &global, &opts, cb).map(drop),
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
