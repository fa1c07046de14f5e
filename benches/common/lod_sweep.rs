//! The LOD sweep shared by `pleat bench lod` (the CLI's thin front end, which includes this file
//! with `#[path]`) and the benchmarks in `benches/` (`lod.rs`, `report.rs`): the corpus, the
//! measurement of one bake (wall and CPU seconds without the error-floor measurement, validity
//! from the independent `MeshReport`), the CSV with its parser, the error-against-time SVG and
//! the summary table. It exists once, here, and is not part of the library's API.
//!
//! Each includer uses a part of it, hence the `dead_code` allowance.

#![allow(dead_code)]

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[cfg(feature = "lod")]
use pleat::lowpoly::{LodReport, LodStage};
use pleat::mesh::TriMesh;
#[cfg(feature = "lod")]
use pleat::report::Stage as _;
use pleat::verify::MeshReport;

// ---------------------------------------------------------------------------------------------
// Corpus

/// Mesh file extensions a sweep picks up (lower case).
pub const MESH_EXTENSIONS: [&str; 6] = ["obj", "ply", "off", "stl", "glb", "gltf"];

/// The shared mesh corpus: `$PLEAT_MESHES`, else `../shared/meshes` or `../../shared/meshes`
/// from the crate root, if one is a folder.
pub fn corpus_dir() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let candidates = [
        std::env::var_os("PLEAT_MESHES").map(PathBuf::from),
        Some(root.join("../shared/meshes")),
        Some(root.join("../../shared/meshes")),
    ];
    candidates.into_iter().flatten().find(|d| d.is_dir())
}

/// The files of `dir` whose extension (any case) is in `extensions`, sorted by path.
pub fn mesh_files(dir: &Path, extensions: &[&str]) -> Result<Vec<PathBuf>, String> {
    let entries =
        std::fs::read_dir(dir).map_err(|e| format!("cannot list {}: {e}", dir.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_file()
                && p.extension()
                    .and_then(|x| x.to_str())
                    .is_some_and(|x| extensions.contains(&x.to_ascii_lowercase().as_str()))
        })
        .collect();
    files.sort();
    Ok(files)
}

/// The file name of `p` (its display form when it has none).
pub fn file_name(p: &Path) -> String {
    p.file_name()
        .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into())
}

// ---------------------------------------------------------------------------------------------
// Measurement

/// A result with the wall and CPU (user + system, all threads) seconds it took.
pub struct Timed<T> {
    pub value: T,
    pub seconds: f64,
    pub cpu_seconds: f64,
}

/// Runs `f`, timing it.
pub fn timed<T>(f: impl FnOnce() -> T) -> Timed<T> {
    let t0 = Instant::now();
    let c0 = pleat::report::process_cpu_seconds();
    let value = f();
    Timed {
        value,
        seconds: t0.elapsed().as_secs_f64(),
        cpu_seconds: pleat::report::process_cpu_seconds() - c0,
    }
}

/// Wall and CPU seconds of the error-floor measurement (`LodParams::measure_floor`) in a bake's
/// stats: it is for the tables, not part of a bake, so sweeps subtract it from the times.
#[cfg(feature = "lod")]
pub fn floor_seconds(stats: &LodReport) -> (f64, f64) {
    (
        stats.stages.seconds(LodStage::Floor),
        stats.floor.map_or(0.0, |f| f.cpu_seconds),
    )
}

/// Validity of one output by the independent checker.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Validity {
    pub watertight: bool,
    /// Manifold and consistently oriented.
    pub manifold: bool,
    pub self_intersection_free: bool,
}

impl Validity {
    /// The `MeshReport` verdicts on `m`.
    pub fn of(m: &TriMesh) -> Validity {
        let r = MeshReport::compute(m);
        Validity {
            watertight: r.is_watertight,
            manifold: r.is_manifold && r.consistently_oriented,
            self_intersection_free: r.self_intersection_free == Some(true),
        }
    }

    /// All three hold.
    pub fn all(&self) -> bool {
        self.watertight && self.manifold && self.self_intersection_free
    }
}

// ---------------------------------------------------------------------------------------------
// The sweep's rows

/// One CSV row: one mesh at one screen size.
#[derive(Debug, Clone, Default)]
pub struct Row {
    pub mesh: String,
    pub faces_in: usize,
    pub n_p: f64,
    pub target_faces: Option<usize>,
    pub status: String,
    pub faces_out: usize,
    pub seconds: f64,
    /// User + system CPU seconds of the bake (all threads): an upper bound of its wall time
    /// on an unloaded machine, so a robust figure when the machine is shared.
    pub cpu_seconds: f64,
    pub hausdorff_over_l: f64,
    /// One-sided parts of `hausdorff_over_l`: input to output, output to input.
    pub in_to_out_over_l: f64,
    pub out_to_in_over_l: f64,
    /// Input to the offset surface: the floor of `in_to_out_over_l` (hidden input).
    pub floor_over_l: f64,
    pub watertight: bool,
    pub manifold: bool,
    pub self_intersection_free: bool,
    /// Cage mode: `(encloses every input vertex, touches no input triangle)`.
    pub cage: Option<(bool, bool)>,
    /// Cage mode: `(exact min clearance / d, required clearance / d, kept)` from the report
    /// (`LodReport::clearance`, measured by `pleat::verify`).
    pub clearance: Option<(f64, f64, bool)>,
    pub rounds: u64,
    pub faces_offset: u64,
    pub reruns_exact: u64,
    pub stages: Vec<(String, f64)>,
    /// `--bake`: the textured bake of the output (`pleat::bake::bake_level`, evaluated).
    pub bake: Option<BakeCols>,
}

/// The bake columns of a row (`pleat bench lod --bake`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BakeCols {
    /// Wall seconds of the level's bake (`BakeReport::total_seconds`, evaluation excluded).
    pub seconds: f64,
    /// Side of the square textures.
    pub texture_size: u32,
    /// Texels covered by charts.
    pub texels_covered: u64,
    /// Unlit PSNR of the level against the input over 24 views (`BakeReport::appearance_psnr_db`).
    pub psnr_db: f64,
    /// The closest-point reference's PSNR (`BakeReport::appearance_psnr_reference_db`).
    pub psnr_reference_db: f64,
    /// Normal-map PSNR gain (`BakeReport::normal_map_gain_db`; NaN without a normal map).
    pub normal_gain_db: f64,
}

/// Bake columns of the CSV, in order.
pub const BAKE_COLUMNS: [&str; 6] = [
    "bake_s",
    "texture_size",
    "texels_covered",
    "psnr_db",
    "psnr_reference_db",
    "normal_gain_db",
];

impl BakeCols {
    /// The columns of a [`pleat::bake::BakeReport`] (NaN where not measured).
    #[cfg(feature = "bake")]
    pub fn of(r: &pleat::bake::BakeReport) -> BakeCols {
        BakeCols {
            seconds: r.total_seconds,
            texture_size: r.texture_size,
            texels_covered: r.texels_covered,
            psnr_db: r.appearance_psnr_db.unwrap_or(f64::NAN),
            psnr_reference_db: r.appearance_psnr_reference_db.unwrap_or(f64::NAN),
            normal_gain_db: r.normal_map_gain_db.unwrap_or(f64::NAN),
        }
    }

    fn fields(&self) -> [String; 6] {
        [
            format!("{:.4}", self.seconds),
            self.texture_size.to_string(),
            self.texels_covered.to_string(),
            num(self.psnr_db),
            num(self.psnr_reference_db),
            num(self.normal_gain_db),
        ]
    }
}

impl Row {
    /// The bake succeeded.
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }

    /// Watertight, manifold, self-intersection-free, and in cage mode enclosing and untouched.
    pub fn valid(&self) -> bool {
        self.ok()
            && self.watertight
            && self.manifold
            && self.self_intersection_free
            && self.cage.is_none_or(|(e, u)| e && u)
    }
}

/// Stage columns of the CSV (seconds from `LodReport::stages`, by `LodStage` name); `fit`
/// (LODs: the final input-plane fit) and `clearance` (cages) come last, so older CSVs without
/// them still parse.
pub const STAGES: [&str; 9] = [
    "offset",
    "simplify",
    "flow",
    "align",
    "convergence",
    "verify",
    "measure",
    "fit",
    "clearance",
];

/// Splits one CSV line, honouring double-quoted fields with `""` escapes.
pub fn split_csv_line(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// Rows of a CSV written by [`csv_text`]; also whether it has the cage columns.
pub fn parse_csv(text: &str) -> Result<(Vec<Row>, bool), String> {
    let mut lines = text.lines();
    let header = split_csv_line(lines.next().unwrap_or(""));
    let col = |name: &str| header.iter().position(|h| h == name);
    let need = |name: &str| col(name).ok_or_else(|| format!("no `{name}` column"));
    let c = [
        need("mesh")?,
        need("faces_in")?,
        need("n_p")?,
        need("status")?,
        need("faces_out")?,
        need("seconds")?,
        need("hausdorff_over_l")?,
        need("watertight")?,
        need("manifold")?,
        need("self_intersection_free")?,
    ];
    let cage_cols = col("encloses").zip(col("untouched"));
    let bake_cols: Option<Vec<usize>> = BAKE_COLUMNS.iter().map(|c| col(c)).collect();
    let clearance_cols = col("min_clearance_over_d")
        .zip(col("clearance_over_d"))
        .zip(col("clearance_kept"));
    let cpu = col("cpu_seconds");
    let mut rows = Vec::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let f = split_csv_line(line);
        let get = |i: usize| f.get(i).map(String::as_str).unwrap_or("");
        let num = |i: usize| get(i).parse::<f64>().unwrap_or(f64::NAN);
        let flag = |i: usize| get(i) == "true";
        let mut stages = Vec::new();
        for st in STAGES {
            if let Some(i) = col(&format!("{st}_s")) {
                stages.push((st.to_string(), num(i)));
            }
        }
        rows.push(Row {
            mesh: get(c[0]).to_string(),
            faces_in: get(c[1]).parse().unwrap_or(0),
            n_p: num(c[2]),
            target_faces: col("target_faces").and_then(|i| get(i).parse().ok()),
            status: get(c[3]).to_string(),
            faces_out: get(c[4]).parse().unwrap_or(0),
            seconds: num(c[5]),
            cpu_seconds: cpu.map_or(f64::NAN, num),
            hausdorff_over_l: num(c[6]),
            in_to_out_over_l: col("in_to_out_over_l").map_or(f64::NAN, num),
            out_to_in_over_l: col("out_to_in_over_l").map_or(f64::NAN, num),
            floor_over_l: col("floor_over_l").map_or(f64::NAN, num),
            watertight: flag(c[7]),
            manifold: flag(c[8]),
            self_intersection_free: flag(c[9]),
            cage: cage_cols.map(|(e, u)| (flag(e), flag(u))),
            clearance: clearance_cols.map(|((m, r), k)| (num(m), num(r), flag(k))),
            rounds: col("rounds").and_then(|i| get(i).parse().ok()).unwrap_or(0),
            faces_offset: col("faces_offset")
                .and_then(|i| get(i).parse().ok())
                .unwrap_or(0),
            reruns_exact: col("reruns_exact")
                .and_then(|i| get(i).parse().ok())
                .unwrap_or(0),
            stages,
            bake: bake_cols.as_ref().and_then(|b| {
                let seconds = num(b[0]);
                seconds.is_finite().then(|| BakeCols {
                    seconds,
                    texture_size: get(b[1]).parse().unwrap_or(0),
                    texels_covered: get(b[2]).parse().unwrap_or(0),
                    psnr_db: num(b[3]),
                    psnr_reference_db: num(b[4]),
                    normal_gain_db: num(b[5]),
                })
            }),
        });
    }
    Ok((rows, cage_cols.is_some()))
}

/// Face targets keyed by `(mesh file name, n_p bits)` from a CSV with a header naming the
/// columns `mesh`, `n_p` and `meshopt_faces`.
pub fn read_face_targets(path: &Path) -> Result<HashMap<(String, u64), usize>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h.trim() == name)
            .ok_or_else(|| format!("{} has no `{name}` column", path.display()))
    };
    let (cm, cn, cf) = (col("mesh")?, col("n_p")?, col("meshopt_faces")?);
    let mut out = HashMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let get = |i: usize| f.get(i).map(|s| s.trim()).unwrap_or("");
        if let (Ok(n_p), Ok(faces)) = (get(cn).parse::<f64>(), get(cf).parse::<usize>()) {
            if faces >= 4 {
                out.insert((get(cm).to_string(), n_p.to_bits()), faces);
            }
        }
    }
    Ok(out)
}

#[cfg(feature = "lod")]
/// Bakes one case and checks it; never panics (a panic in the bake becomes the status).
// The case's parameters, one by one, as `pleat bench lod` takes them from its flags.
#[allow(clippy::too_many_arguments)]
pub fn bake_case(
    name: &str,
    mesh: &TriMesh,
    n_p: f64,
    target: Option<usize>,
    cage: bool,
    clearance: Option<pleat::lowpoly::Clearance>,
    voxel_scale: Option<f64>,
    prog: &mut pleat::report::ProgressFn<'_>,
) -> (Row, Option<TriMesh>) {
    let mut row = Row {
        mesh: name.to_string(),
        faces_in: mesh.triangle_count(),
        n_p,
        target_faces: target,
        ..Row::default()
    };
    let params = pleat::lowpoly::LodParams {
        screen_size: n_p,
        target_faces: target,
        measure_floor: true,
        clearance: clearance.unwrap_or_default(),
        offset_voxel_scale: voxel_scale,
        ..Default::default()
    };
    let mut run = timed(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            bake_mesh(mesh, &params, cage, prog)
        }))
    });
    if let Ok(Ok((_, stats))) = &run.value {
        let (wall, cpu) = floor_seconds(stats);
        run.seconds -= wall;
        run.cpu_seconds -= cpu;
    }
    row.seconds = run.seconds;
    row.cpu_seconds = run.cpu_seconds;
    let (out, stats) = match run.value {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            row.status = format!("error: {e}");
            return (row, None);
        }
        Err(p) => {
            row.status = format!("panic: {}", panic_message(&p));
            return (row, None);
        }
    };
    fill_from_output(&mut row, mesh, &out, &stats, cage);
    (row, Some(out))
}

#[cfg(feature = "lod")]
/// `generate` or the cage `generate`.
fn bake_mesh(
    mesh: &TriMesh,
    params: &pleat::lowpoly::LodParams,
    cage: bool,
    prog: &mut pleat::report::ProgressFn<'_>,
) -> pleat::Result<(TriMesh, LodReport)> {
    #[cfg(feature = "cage")]
    if cage {
        return pleat::cage::generate(mesh, params, prog);
    }
    let _ = cage;
    pleat::lowpoly::generate(mesh, params, prog)
}

#[cfg(feature = "lod")]
/// Counts, error, stage times from the stats; validity from independent checks of `out`.
fn fill_from_output(row: &mut Row, input: &TriMesh, out: &TriMesh, stats: &LodReport, cage: bool) {
    row.status = "ok".into();
    row.faces_out = out.triangle_count();
    row.hausdorff_over_l = stats.hausdorff_rel;
    row.in_to_out_over_l = stats.hausdorff_in_to_out_rel;
    row.out_to_in_over_l = stats.hausdorff_out_to_in_rel;
    row.floor_over_l = stats.floor.map_or(f64::NAN, |f| f.rel);
    row.rounds = stats.rounds;
    row.faces_offset = stats.faces_offset;
    row.reruns_exact = stats.reruns_exact;
    row.stages = stats
        .stages
        .iter()
        .map(|(s, t)| (s.name().into_owned(), t))
        .collect();
    let v = Validity::of(out);
    row.watertight = v.watertight;
    row.manifold = v.manifold;
    row.self_intersection_free = v.self_intersection_free;
    if cage {
        row.cage = Some(cage_flags(out, input));
        row.clearance = stats
            .clearance
            .map(|c| (c.min / stats.d, c.required / stats.d, c.kept));
    }
    if !row.valid() {
        row.status = "ok (INVALID output)".into();
    }
}

/// `(encloses, untouched)` from [`pleat::verify::check_cage`].
#[cfg(feature = "cage")]
fn cage_flags(out: &TriMesh, input: &TriMesh) -> (bool, bool) {
    let c = pleat::verify::check_cage(out, input);
    (c.encloses, c.untouched)
}

#[cfg(not(feature = "cage"))]
fn cage_flags(_out: &TriMesh, _input: &TriMesh) -> (bool, bool) {
    (false, false)
}

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// A CSV field, quoted when it holds a comma, quote or line break.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\"").replace(['\n', '\r'], " "))
    } else {
        s.to_string()
    }
}

/// A number for the CSV (empty when not finite).
pub fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// The whole CSV: header, then one line per row.
pub fn csv_text(rows: &[Row], cage: bool) -> String {
    let mut s = String::from(
        "mesh,faces_in,n_p,target_faces,status,faces_out,seconds,cpu_seconds,hausdorff_over_l,\
         in_to_out_over_l,out_to_in_over_l,floor_over_l,watertight,manifold,\
         self_intersection_free",
    );
    if cage {
        s.push_str(",encloses,untouched,min_clearance_over_d,clearance_over_d,clearance_kept");
    }
    s.push_str(",rounds,faces_offset,reruns_exact");
    for st in STAGES {
        let _ = write!(s, ",{st}_s");
    }
    let bake = rows.iter().any(|r| r.bake.is_some());
    if bake {
        for c in BAKE_COLUMNS {
            let _ = write!(s, ",{c}");
        }
    }
    s.push('\n');
    for r in rows {
        s.push_str(&csv_line(r, cage));
        if bake {
            let f = r.bake.map_or_else(Default::default, |b| b.fields());
            for x in f {
                s.push(',');
                s.push_str(&x);
            }
        }
        s.push('\n');
    }
    s
}

fn csv_line(r: &Row, cage: bool) -> String {
    let ok = r.ok() || r.status.starts_with("ok");
    let flag = |b: bool| if ok { b.to_string() } else { String::new() };
    let mut f = vec![
        csv_field(&r.mesh),
        if r.faces_in > 0 {
            r.faces_in.to_string()
        } else {
            String::new()
        },
        num(r.n_p),
        r.target_faces.map_or(String::new(), |t| t.to_string()),
        csv_field(&r.status),
        if ok {
            r.faces_out.to_string()
        } else {
            String::new()
        },
        if r.n_p.is_finite() {
            format!("{:.4}", r.seconds)
        } else {
            String::new()
        },
        if r.n_p.is_finite() {
            format!("{:.4}", r.cpu_seconds)
        } else {
            String::new()
        },
        if ok {
            num(r.hausdorff_over_l)
        } else {
            String::new()
        },
        num(r.in_to_out_over_l),
        num(r.out_to_in_over_l),
        num(r.floor_over_l),
        flag(r.watertight),
        flag(r.manifold),
        flag(r.self_intersection_free),
    ];
    if cage {
        let (e, u) = r.cage.unwrap_or((false, false));
        f.push(flag(e));
        f.push(flag(u));
        match r.clearance {
            Some((m, req, k)) if ok => {
                f.push(num(m));
                f.push(num(req));
                f.push(flag(k));
            }
            _ => f.extend([String::new(), String::new(), String::new()]),
        }
    }
    for c in [r.rounds, r.faces_offset, r.reruns_exact] {
        f.push(if ok { c.to_string() } else { String::new() });
    }
    for st in STAGES {
        // fold from +0.0: an empty `sum` of floats is -0.0, printed "-0.0000"
        let t: f64 = r
            .stages
            .iter()
            .filter(|s| s.0 == st)
            .fold(0.0, |a, s| a + s.1);
        f.push(if ok { format!("{t:.4}") } else { String::new() });
    }
    f.join(",")
}

/// One progress line per case.
pub fn row_line(r: &Row) -> String {
    if r.ok() || r.status.starts_with("ok") {
        let bake = r.bake.map_or(String::new(), |b| {
            format!(
                "  bake {:.2} s {}² PSNR {:.2} dB (ref {:.2}) normal {:+.2} dB",
                b.seconds, b.texture_size, b.psnr_db, b.psnr_reference_db, b.normal_gain_db
            )
        });
        let line = format!(
            "{:<34} n_p={:<5} {:>6} -> {:>5} faces  {:>7.2} s ({:>6.2} s cpu)  HD/l={:.4}  {}",
            r.mesh,
            r.n_p,
            r.faces_in,
            r.faces_out,
            r.seconds,
            r.cpu_seconds,
            r.hausdorff_over_l,
            if r.valid() { "valid" } else { "INVALID" }
        ) + &r.clearance.map_or(String::new(), |(m, req, kept)| {
            format!(
                "  clearance {m:.3} d (required {req:.3} d{})",
                if kept { "" } else { ", NOT KEPT" }
            )
        });
        line + &bake
    } else {
        format!("{:<34} n_p={:<5} {}", r.mesh, r.n_p, r.status)
    }
}

/// Per screen size: cases, valid cases, mean and median seconds, mean Hausdorff/l.
pub fn print_summary(rows: &[Row], sizes: &[f64]) {
    println!(
        "\n{:>6} {:>6} {:>6} {:>10} {:>10} {:>12} {:>10} {:>10} {:>10} {:>8}",
        "n_p",
        "cases",
        "valid",
        "median s",
        "mean s",
        "median cpu s",
        "mean HD/l",
        "out→in",
        "floor",
        "mean #F"
    );
    for &n_p in sizes {
        let all: Vec<&Row> = rows.iter().filter(|r| r.n_p == n_p).collect();
        let ok: Vec<&Row> = all.iter().copied().filter(|r| r.valid()).collect();
        let col = |f: fn(&Row) -> f64| -> Vec<f64> { ok.iter().map(|r| f(r)).collect() };
        let secs = col(|r| r.seconds);
        println!(
            "{:>6} {:>6} {:>6} {:>10.2} {:>10.2} {:>12.2} {:>10.4} {:>10.4} {:>10.4} {:>8.0}",
            n_p,
            all.len(),
            ok.len(),
            median(&secs),
            mean(&secs),
            median(&col(|r| r.cpu_seconds)),
            mean(&col(|r| r.hausdorff_over_l)),
            mean(&col(|r| r.out_to_in_over_l)),
            mean(&col(|r| r.floor_over_l)),
            mean(&col(|r| r.faces_out as f64))
        );
    }
    println!(
        "(HD/l: two-sided; out→in: output to input; floor: input to the offset surface, the \
         input the offset hides, which no later step uncovers)"
    );
}

pub fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// Plot geometry of the SVG.
struct Frame {
    left: f64,
    top: f64,
    width: f64,
    height: f64,
    /// log10 ranges `[lo, hi]` of the axes.
    x: (f64, f64),
    y: (f64, f64),
}

impl Frame {
    fn px(&self, seconds: f64) -> f64 {
        self.left + (seconds.log10() - self.x.0) / (self.x.1 - self.x.0) * self.width
    }

    fn py(&self, hd: f64) -> f64 {
        self.top + self.height - (hd.log10() - self.y.0) / (self.y.1 - self.y.0) * self.height
    }
}

/// Decade range `[floor log10 min, ceil log10 max]` of positive finite values.
fn decades(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v.log10());
        hi = hi.max(v.log10());
    }
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let (lo, hi) = (lo.floor(), hi.ceil());
    if hi > lo {
        (lo, hi)
    } else {
        (lo, lo + 1.0)
    }
}

/// Distinct colour of series `i` of `n` (HSL hue wheel).
fn colour(i: usize, n: usize) -> String {
    let hue = 360.0 * i as f64 / n.max(1) as f64;
    format!("hsl({hue:.0},65%,45%)")
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The error-against-time plot as an SVG document.
pub fn svg_text(rows: &[Row], sizes: &[f64], cage: bool) -> String {
    let ok: Vec<&Row> = rows
        .iter()
        .filter(|r| r.valid() && r.hausdorff_over_l > 0.0 && r.seconds > 0.0)
        .collect();
    let mut meshes: Vec<&str> = ok.iter().map(|r| r.mesh.as_str()).collect();
    meshes.dedup();
    let f = Frame {
        left: 80.0,
        top: 50.0,
        width: 620.0,
        height: 480.0,
        x: decades(ok.iter().map(|r| r.seconds)),
        y: decades(ok.iter().map(|r| r.hausdorff_over_l)),
    };
    let (w, h) = (1000.0, 600.0);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n"
    );
    let title = if cage { "pleat cages" } else { "pleat LODs" };
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"28\" font-size=\"16\" text-anchor=\"middle\">{title}: error \
         against run time, n_p = {}</text>",
        f.left + f.width / 2.0,
        sizes
            .iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    svg_axes(&mut s, &f);
    for (i, m) in meshes.iter().enumerate() {
        let pts: Vec<(f64, f64)> = sizes
            .iter()
            .filter_map(|&n| ok.iter().find(|r| r.mesh == *m && r.n_p == n))
            .map(|r| (r.seconds, r.hausdorff_over_l))
            .collect();
        svg_series(&mut s, &f, &pts, &colour(i, meshes.len()), 1.2, 0.75);
        svg_legend_entry(&mut s, i, m, &colour(i, meshes.len()));
    }
    let means: Vec<(f64, f64, f64)> = sizes
        .iter()
        .filter_map(|&n| {
            let at: Vec<&&Row> = ok.iter().filter(|r| r.n_p == n).collect();
            (!at.is_empty()).then(|| {
                let t = at.iter().map(|r| r.seconds).sum::<f64>() / at.len() as f64;
                let e = at.iter().map(|r| r.hausdorff_over_l).sum::<f64>() / at.len() as f64;
                (n, t, e)
            })
        })
        .collect();
    let pts: Vec<(f64, f64)> = means.iter().map(|m| (m.1, m.2)).collect();
    svg_series(&mut s, &f, &pts, "black", 3.0, 1.0);
    for (n, t, e) in &means {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-weight=\"bold\">{n}</text>",
            f.px(*t) + 6.0,
            f.py(*e) - 6.0
        );
    }
    svg_legend_entry(&mut s, meshes.len(), "mean (labels: n_p)", "black");
    s.push_str("</svg>\n");
    s
}

/// Frame, decade grid lines with labels (1, 2, 5 per decade), axis titles.
fn svg_axes(s: &mut String, f: &Frame) {
    let _ = writeln!(
        s,
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\"/>",
        f.left, f.top, f.width, f.height
    );
    for e in f.x.0 as i32..=f.x.1 as i32 {
        for m in [1.0, 2.0, 5.0] {
            let v = m * 10f64.powi(e);
            if v.log10() > f.x.1 + 1e-9 {
                continue;
            }
            let x = f.px(v);
            grid_line(s, (x, f.top), (x, f.top + f.height), m == 1.0);
            let _ = writeln!(
                s,
                "<text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
                f.top + f.height + 16.0,
                short_number(v)
            );
        }
    }
    for e in f.y.0 as i32..=f.y.1 as i32 {
        for m in [1.0, 2.0, 5.0] {
            let v = m * 10f64.powi(e);
            if v.log10() > f.y.1 + 1e-9 {
                continue;
            }
            let y = f.py(v);
            grid_line(s, (f.left, y), (f.left + f.width, y), m == 1.0);
            let _ = writeln!(
                s,
                "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
                f.left - 6.0,
                y + 4.0,
                short_number(v)
            );
        }
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">wall time per bake (s, log \
         scale)</text>",
        f.left + f.width / 2.0,
        f.top + f.height + 40.0
    );
    let _ = writeln!(
        s,
        "<text transform=\"translate(24,{:.1}) rotate(-90)\" text-anchor=\"middle\">two-sided \
         Hausdorff / bbox diagonal (log scale)</text>",
        f.top + f.height / 2.0
    );
}

fn grid_line(s: &mut String, a: (f64, f64), b: (f64, f64), major: bool) {
    let _ = writeln!(
        s,
        "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\"/>",
        a.0,
        a.1,
        b.0,
        b.1,
        if major { "#bbb" } else { "#e6e6e6" }
    );
}

/// `0.002`, `0.05`, `1`, `20`, `500` — a label without trailing noise.
fn short_number(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// A polyline with a dot at each point.
fn svg_series(s: &mut String, f: &Frame, pts: &[(f64, f64)], col: &str, width: f64, op: f64) {
    if pts.is_empty() {
        return;
    }
    let coords: Vec<String> = pts
        .iter()
        .map(|&(t, e)| format!("{:.1},{:.1}", f.px(t), f.py(e)))
        .collect();
    let _ = writeln!(
        s,
        "<polyline points=\"{}\" fill=\"none\" stroke=\"{col}\" stroke-width=\"{width}\" \
         opacity=\"{op}\"/>",
        coords.join(" ")
    );
    for &(t, e) in pts {
        let _ = writeln!(
            s,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"{:.1}\" fill=\"{col}\" opacity=\"{op}\"/>",
            f.px(t),
            f.py(e),
            width + 1.0
        );
    }
}

fn svg_legend_entry(s: &mut String, i: usize, label: &str, col: &str) {
    let (x, y) = (720.0, 58.0 + 19.0 * i as f64);
    let _ = writeln!(
        s,
        "<line x1=\"{x}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"{col}\" stroke-width=\"3\"/>\
         <text x=\"{}\" y=\"{}\">{}</text>",
        x + 18.0,
        x + 24.0,
        y + 4.0,
        xml_escape(label)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(mesh: &str, n_p: f64, t: f64, e: f64) -> Row {
        Row {
            mesh: mesh.into(),
            faces_in: 100,
            n_p,
            status: "ok".into(),
            faces_out: 10,
            seconds: t,
            hausdorff_over_l: e,
            in_to_out_over_l: e,
            out_to_in_over_l: 0.5 * e,
            floor_over_l: f64::NAN,
            watertight: true,
            manifold: true,
            self_intersection_free: true,
            ..Row::default()
        }
    }

    #[test]
    fn csv_quotes_statuses_and_blanks_failed_cases() {
        let mut bad = row("b,c.obj", 50.0, 1.0, 0.1);
        bad.status = "error: bad \"mesh\", sorry".into();
        let text = csv_text(&[row("a.obj", 50.0, 1.5, 0.02), bad], false);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[1]
            .starts_with("a.obj,100,50,,ok,10,1.5000,0.0000,0.02,0.02,0.01,,true,true,true"));
        assert!(lines[2].starts_with("\"b,c.obj\",100,50,,\"error: bad \"\"mesh\"\", sorry\",,"));
    }

    #[test]
    fn csv_round_trips_through_the_replot_parser() {
        let mut bad = row("b,c.obj", 50.0, 1.0, 0.1);
        bad.status = "error: bad \"mesh\"".into();
        let rows = [row("a.obj", 50.0, 1.5, 0.02), bad];
        let text = csv_text(&rows, false);
        let (back, cage) = parse_csv(&text).unwrap();
        assert!(!cage);
        assert_eq!(back.len(), 2);
        assert_eq!(back[1].mesh, "b,c.obj");
        assert_eq!(back[1].status, "error: bad \"mesh\"");
        assert!(back[0].valid() && !back[1].valid());
        assert_eq!(csv_text(&back, false), text);
    }

    #[test]
    fn svg_has_one_polyline_per_mesh_and_the_mean() {
        let rows = [
            row("a", 50.0, 0.5, 0.05),
            row("a", 100.0, 2.0, 0.02),
            row("b", 50.0, 0.8, 0.04),
            row("b", 100.0, 3.0, 0.01),
        ];
        let svg = svg_text(&rows, &[50.0, 100.0], false);
        assert_eq!(svg.matches("<polyline").count(), 3);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    }

    #[test]
    fn face_targets_are_read_by_header() {
        let dir = std::env::temp_dir().join(format!("pleat-bench-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.csv");
        std::fs::write(&p, "n_p,mesh,meshopt_faces\n100,a.obj,240\n200,a.obj,\n").unwrap();
        let t = read_face_targets(&p).unwrap();
        assert_eq!(t.get(&("a.obj".into(), 100f64.to_bits())), Some(&240));
        assert_eq!(t.len(), 1);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
