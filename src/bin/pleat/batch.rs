//! Batch bakes for build steps: `pleat lod A.obj B.ply meshes/ [--manifest M]
//! -o 'out/{stem}_{np}.obj' --jobs N --cache DIR --report R.json`.
//!
//! Guarantees:
//! - every asset is baked exactly as `pleat lod ASSET` would bake it (same parameters, same
//!   code path: [`super::bake_levels`], or for a glTF input with `.glb` outputs the per-mesh
//!   scene bake of `pleat::bake::scene`, one file per level), so its outputs are
//!   byte-identical whatever `--jobs` is;
//! - an output file is written to a temporary file in its own folder and renamed over the
//!   target, so a reader (or an interrupted build) never sees a half-written mesh;
//! - with `--cache DIR`, an asset whose input bytes, parameters and pleat version were baked
//!   before is not baked again: its outputs are copied from the cache entry;
//! - a failing asset (unreadable, corrupt, failed bake) is a `failed` row of the report with its
//!   message; the other assets still bake and the command exits 1 at the end.
//!
//! Exit status: 0 when every asset is baked or cached, 1 when one failed, 2 for bad arguments or
//! an unreadable manifest (before anything is baked).

use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[cfg(not(feature = "bake"))]
use pleat::mesh::io::read_mesh;
use pleat::mesh::io::{write_mesh, MeshFormat};
use rayon::prelude::*;
use serde_json::{json, Value};

use super::{
    bake, bake_levels, lod_params, output_path, parse_memory_budget, progress_bar, BakeArgs,
    EXIT_FAILED, EXIT_INPUT, SIZE_PLACEHOLDERS,
};

/// The columns a CSV manifest may name.
const COLUMNS: [&str; 5] = ["input", "screen_size", "faces", "output", "memory_budget"];

/// Placeholder of the output path replaced by the input's file stem.
const STEM_PLACEHOLDER: &str = "{stem}";

/// Version tag of the cache key layout; bump it when the key or the entry layout changes.
const CACHE_LAYOUT: &str = "pleat batch cache v2";

/// Options that turn `pleat lod`/`pleat cage` into a batch bake.
#[derive(clap::Args)]
pub struct BatchArgs {
    /// Manifest of inputs with per-asset settings: JSON (`.json`: an array of
    /// {"input", "screen_size": n or [n, ...], "faces", "output", "memory_budget"}) or CSV
    /// (header naming `input` and optionally `screen_size` (sizes separated by `;`), `faces`,
    /// `output`, `memory_budget`; no quoted fields). `memory_budget` is a size as for
    /// --memory-budget (`"4GiB"`, or a number of bytes). Paths are relative to the manifest's folder; missing settings come from
    /// the command line.
    #[arg(long)]
    pub manifest: Option<PathBuf>,
    /// Assets baked at once (one thread pool over assets; a bake's own parallel parts share
    /// it) [default: the number of cores]. Outputs do not depend on it.
    #[arg(short, long)]
    pub jobs: Option<usize>,
    /// Content-addressed cache folder: key = BLAKE3 of the input bytes, every parameter and the
    /// pleat version; an asset whose key is there is copied, not baked.
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Write a JSON report: one row per asset with status (baked, cached, failed), faces and
    /// error per level, error message and seconds.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// `pleat lod`/`pleat cage`: one input without batch options runs the single-input command
/// unchanged; anything else (several inputs, a folder, a manifest, `--jobs`, `--cache`,
/// `--report`) runs a batch.
pub fn dispatch(inputs: &[PathBuf], batch: &BatchArgs, args: &BakeArgs, cage: bool) -> ExitCode {
    if is_batch(inputs, batch) {
        run(inputs, batch, args, cage)
    } else {
        bake(&inputs[0], args, cage)
    }
}

fn is_batch(inputs: &[PathBuf], b: &BatchArgs) -> bool {
    inputs.len() != 1
        || inputs[0].is_dir()
        || b.manifest.is_some()
        || b.jobs.is_some()
        || b.cache.is_some()
        || b.report.is_some()
}

/// One asset of the batch: its input, screen sizes, face target and one output per size.
#[derive(Debug, Clone)]
struct Asset {
    input: PathBuf,
    sizes: Vec<f64>,
    faces: Option<usize>,
    outputs: Vec<PathBuf>,
    /// The asset's memory budget in bytes when its manifest row gives one.
    memory_budget: Option<u64>,
}

/// Outcome of one asset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Status {
    Baked,
    Cached,
    Failed,
}

impl Status {
    fn name(self) -> &'static str {
        match self {
            Status::Baked => "baked",
            Status::Cached => "cached",
            Status::Failed => "failed",
        }
    }
}

/// One written level of an asset (also what a cache entry records).
#[derive(Debug, Clone)]
struct Level {
    screen_size: f64,
    faces: usize,
    hausdorff_rel: f64,
    verified: bool,
}

/// One report row.
#[derive(Debug)]
struct Row {
    status: Status,
    seconds: f64,
    error: Option<String>,
    levels: Vec<Level>,
}

/// A row-level failure message.
type AssetResult<T> = Result<T, String>;

/// Runs the batch.
fn run(inputs: &[PathBuf], batch: &BatchArgs, args: &BakeArgs, cage: bool) -> ExitCode {
    let cmd = if cage { "cage" } else { "lod" };
    match plan(inputs, batch, args) {
        Ok((assets, jobs)) => execute(&assets, jobs, batch, args, cage, cmd),
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            ExitCode::from(EXIT_INPUT)
        }
    }
}

/// Checks the options and lists the assets (bad arguments fail here, before any bake).
fn plan(
    inputs: &[PathBuf],
    batch: &BatchArgs,
    args: &BakeArgs,
) -> Result<(Vec<Asset>, usize), String> {
    #[cfg(feature = "bake")]
    if args.textures.bake {
        return Err("--bake (textured chains) takes a single input, not a batch".into());
    }
    let jobs = match batch.jobs {
        Some(0) => return Err("--jobs must be at least 1".into()),
        Some(j) => j,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let mut specs = Vec::new();
    for input in inputs {
        if input.is_dir() {
            for file in mesh_files(input)? {
                specs.push(Spec::new(file));
            }
        } else {
            specs.push(Spec::new(input.clone()));
        }
    }
    if let Some(m) = &batch.manifest {
        specs.extend(read_manifest(m)?);
    }
    if specs.is_empty() {
        return Err(
            "no input meshes (folders are searched for obj, ply, off, stl, glb, gltf)".into(),
        );
    }
    let mut assets = specs
        .into_iter()
        .map(|s| s.resolve(args))
        .collect::<Result<Vec<_>, _>>()?;
    drop_own_outputs(&mut assets);
    check_distinct_outputs(&assets)?;
    Ok((assets, jobs))
}

/// An asset as listed: settings not given fall back to the command line.
#[derive(Debug, Default)]
struct Spec {
    input: PathBuf,
    sizes: Option<Vec<f64>>,
    faces: Option<usize>,
    output: Option<PathBuf>,
    memory_budget: Option<u64>,
}

impl Spec {
    fn new(input: PathBuf) -> Spec {
        Spec {
            input,
            ..Spec::default()
        }
    }

    /// The asset with the command line's defaults and the output pattern expanded.
    fn resolve(self, args: &BakeArgs) -> Result<Asset, String> {
        let name = self.input.display().to_string();
        let sizes = self.sizes.unwrap_or_else(|| args.screen_size.clone());
        if sizes.is_empty() {
            return Err(format!("{name}: no screen size (give --screen-size)"));
        }
        let faces = self.faces.or(args.faces);
        if sizes.len() > 1 && faces.is_some() {
            return Err(format!("{name}: a face budget needs a single screen size"));
        }
        let pattern = self.output.or_else(|| args.output.clone()).ok_or_else(|| {
            format!("{name}: no output (give -o or an output column in the manifest)")
        })?;
        let text = pattern.to_string_lossy();
        if sizes.len() > 1 && !SIZE_PLACEHOLDERS.iter().any(|p| text.contains(p)) {
            return Err(format!(
                "{name}: with several screen sizes the output needs a {{n}} or {{np}} placeholder"
            ));
        }
        let stem = self
            .input
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let pattern = PathBuf::from(text.replace(STEM_PLACEHOLDER, &stem));
        let outputs = sizes.iter().map(|&n| output_path(&pattern, n)).collect();
        Ok(Asset {
            input: self.input,
            sizes,
            faces,
            outputs,
            memory_budget: self.memory_budget,
        })
    }
}

/// Mesh files under `dir` (recursively, sorted, hidden files skipped).
fn mesh_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let entries =
            std::fs::read_dir(&d).map_err(|e| format!("cannot list '{}': {e}", d.display()))?;
        for entry in entries {
            let path = entry
                .map_err(|e| format!("cannot list '{}': {e}", d.display()))?
                .path();
            let hidden = path
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'));
            if hidden {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else if is_mesh_file(&path) {
                out.push(path);
            }
        }
    }
    out.sort();
    Ok(out)
}

fn is_mesh_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| MeshFormat::from_extension(&e.to_string_lossy().to_ascii_lowercase()))
        .is_some()
}

/// Drops the inputs that are outputs of this batch: an output folder inside an input folder
/// must not turn last run's LODs into this run's assets.
fn drop_own_outputs(assets: &mut Vec<Asset>) {
    let outputs: HashSet<PathBuf> = assets
        .iter()
        .flat_map(|a| a.outputs.iter().cloned())
        .collect();
    assets.retain(|a| !outputs.contains(&a.input));
}

/// Two assets writing the same file would race: refused before baking.
fn check_distinct_outputs(assets: &[Asset]) -> Result<(), String> {
    let mut seen: HashMap<&Path, &Path> = HashMap::new();
    for a in assets {
        for o in &a.outputs {
            if let Some(prev) = seen.insert(o, &a.input) {
                return Err(format!(
                    "'{}' and '{}' both write '{}' (use {STEM_PLACEHOLDER} in the output)",
                    prev.display(),
                    a.input.display(),
                    o.display()
                ));
            }
        }
    }
    Ok(())
}

/// Reads a JSON (`.json`) or CSV manifest; paths in it are relative to its folder.
fn read_manifest(path: &Path) -> Result<Vec<Spec>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read manifest '{}': {e}", path.display()))?;
    let base = path.parent().unwrap_or(Path::new(""));
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let specs = if json {
        parse_json_manifest(&text)
    } else {
        parse_csv_manifest(&text)
    }
    .map_err(|e| format!("manifest '{}': {e}", path.display()))?;
    Ok(specs
        .into_iter()
        .map(|mut s| {
            s.input = base.join(&s.input);
            s.output = s.output.map(|o| base.join(o));
            s
        })
        .collect())
}

/// JSON manifest: an array of objects (or `{"assets": [...]}`).
fn parse_json_manifest(text: &str) -> Result<Vec<Spec>, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
    let rows = match &v {
        Value::Array(a) => a,
        Value::Object(o) => match o.get("assets") {
            Some(Value::Array(a)) => a,
            _ => return Err("expected an array of assets or {\"assets\": [...]}".into()),
        },
        _ => return Err("expected an array of assets".into()),
    };
    rows.iter()
        .enumerate()
        .map(|(i, r)| json_row(r).map_err(|e| format!("asset {i}: {e}")))
        .collect()
}

fn json_row(r: &Value) -> Result<Spec, String> {
    let input = r
        .get("input")
        .and_then(Value::as_str)
        .ok_or("needs \"input\": a path")?;
    let sizes = match r.get("screen_size") {
        None | Some(Value::Null) => None,
        Some(Value::Array(a)) => Some(
            a.iter()
                .map(|x| x.as_f64().ok_or("screen_size entries must be numbers"))
                .collect::<Result<Vec<_>, _>>()?,
        ),
        Some(x) => Some(vec![x.as_f64().ok_or("screen_size must be a number")?]),
    };
    let faces = match r.get("faces") {
        None | Some(Value::Null) => None,
        Some(x) => Some(x.as_u64().ok_or("faces must be a non-negative integer")? as usize),
    };
    let output = match r.get("output") {
        None | Some(Value::Null) => None,
        Some(x) => Some(PathBuf::from(x.as_str().ok_or("output must be a path")?)),
    };
    let memory_budget = match r.get("memory_budget") {
        None | Some(Value::Null) => None,
        Some(Value::String(t)) => Some(parse_memory_budget(t)?),
        Some(x) => Some(
            x.as_u64()
                .filter(|&b| b > 0)
                .ok_or("memory_budget must be a size (\"4GiB\") or a positive number of bytes")?,
        ),
    };
    Ok(Spec {
        input: PathBuf::from(input),
        sizes,
        faces,
        output,
        memory_budget,
    })
}

/// CSV manifest: a header naming the columns (`input` required; `screen_size`, `faces`,
/// `output`, `memory_budget` optional), then one asset per line; empty cells take the command line's value.
/// Blank lines and lines starting with `#` are skipped. No quoting.
fn parse_csv_manifest(text: &str) -> Result<Vec<Spec>, String> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or("empty manifest")?;
    let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
    for c in &columns {
        if !COLUMNS.contains(&c.as_str()) {
            return Err(format!("unknown column '{c}' ({})", COLUMNS.join(", ")));
        }
    }
    if !columns.iter().any(|c| c == "input") {
        return Err("the header needs an 'input' column".into());
    }
    lines
        .map(|(i, l)| csv_row(&columns, l).map_err(|e| format!("line {}: {e}", i + 1)))
        .collect()
}

fn csv_row(columns: &[String], line: &str) -> Result<Spec, String> {
    let cells: Vec<&str> = line.split(',').map(str::trim).collect();
    if cells.len() != columns.len() {
        return Err(format!(
            "{} cells, the header has {}",
            cells.len(),
            columns.len()
        ));
    }
    let mut spec = Spec::default();
    for (c, &v) in columns.iter().zip(&cells) {
        if v.is_empty() {
            continue;
        }
        match c.as_str() {
            "input" => spec.input = PathBuf::from(v),
            "screen_size" => {
                let sizes = v
                    .split(';')
                    .map(|s| s.trim().parse::<f64>())
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(|e| format!("screen_size '{v}': {e}"))?;
                spec.sizes = Some(sizes);
            }
            "faces" => {
                spec.faces = Some(v.parse().map_err(|e| format!("faces '{v}': {e}"))?);
            }
            "memory_budget" => spec.memory_budget = Some(parse_memory_budget(v)?),
            _ => spec.output = Some(PathBuf::from(v)),
        }
    }
    if spec.input.as_os_str().is_empty() {
        return Err("empty input".into());
    }
    Ok(spec)
}

/// Bakes every asset on a pool of `jobs` threads, writes the report, prints one line per level.
fn execute(
    assets: &[Asset],
    jobs: usize,
    batch: &BatchArgs,
    args: &BakeArgs,
    cage: bool,
    cmd: &str,
) -> ExitCode {
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(jobs).build() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("pleat {cmd}: cannot start {jobs} threads: {e}");
            return ExitCode::from(EXIT_FAILED);
        }
    };
    let bar = progress_bar(args.quiet);
    if let Some(b) = &bar {
        b.set_length(assets.len() as u64);
        b.set_message(format!("{cmd} batch"));
    }
    let cache = batch.cache.as_deref();
    let rows: Vec<Row> = pool.install(|| {
        assets
            .par_iter()
            .map(|a| {
                let row = bake_asset(a, args, cage, cmd, cache);
                if !args.quiet {
                    emit(&bar, &summary(a, &row));
                }
                if let Some(b) = &bar {
                    b.inc(1);
                }
                row
            })
            .collect()
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let count = |s: Status| rows.iter().filter(|r| r.status == s).count();
    let (baked, cached, failed) = (
        count(Status::Baked),
        count(Status::Cached),
        count(Status::Failed),
    );
    if !args.quiet {
        println!(
            "pleat {cmd}: {} assets: {baked} baked, {cached} cached, {failed} failed",
            assets.len()
        );
    }
    if let Some(path) = &batch.report {
        let report = report_json(assets, &rows, cmd, jobs);
        let text = serde_json::to_string_pretty(&report).unwrap_or_default() + "\n";
        if let Err(e) = write_atomically(path, |tmp| {
            std::fs::write(tmp, &text).map_err(|e| e.to_string())
        }) {
            eprintln!("pleat {cmd}: report '{}': {e}", path.display());
            return ExitCode::from(EXIT_FAILED);
        }
    }
    if failed > 0 {
        ExitCode::from(EXIT_FAILED)
    } else {
        ExitCode::SUCCESS
    }
}

/// Prints `text` above the bar (or on stdout without one).
fn emit(bar: &Option<indicatif::ProgressBar>, text: &str) {
    match bar {
        Some(b) => b.println(text),
        None => {
            let mut out = std::io::stdout().lock();
            let _ = writeln!(out, "{text}");
        }
    }
}

/// The lines printed for one asset.
fn summary(a: &Asset, r: &Row) -> String {
    if let Some(e) = &r.error {
        return format!("{}: FAILED: {e}", a.input.display());
    }
    let lines: Vec<String> = a
        .outputs
        .iter()
        .zip(&r.levels)
        .map(|(o, l)| {
            format!(
                "{}: n_p={} {} triangles, Hausdorff/l={:.5}, {}",
                o.display(),
                l.screen_size,
                l.faces,
                l.hausdorff_rel,
                r.status.name()
            )
        })
        .collect();
    lines.join("\n")
}

/// Bakes (or copies from the cache) one asset; never panics the batch on a bad asset.
fn bake_asset(a: &Asset, args: &BakeArgs, cage: bool, cmd: &str, cache: Option<&Path>) -> Row {
    let start = Instant::now();
    let result = bake_or_copy(a, args, cage, cmd, cache);
    let seconds = start.elapsed().as_secs_f64();
    match result {
        Ok((status, levels)) => Row {
            status,
            seconds,
            error: None,
            levels,
        },
        Err(e) => Row {
            status: Status::Failed,
            seconds,
            error: Some(e),
            levels: Vec::new(),
        },
    }
}

fn bake_or_copy(
    a: &Asset,
    args: &BakeArgs,
    cage: bool,
    cmd: &str,
    cache: Option<&Path>,
) -> AssetResult<(Status, Vec<Level>)> {
    let bytes =
        std::fs::read(&a.input).map_err(|e| format!("cannot read '{}': {e}", a.input.display()))?;
    let entry = cache.map(|dir| dir.join(cache_key(&bytes, a, args, cmd)));
    if let Some(entry) = &entry {
        if let Some(levels) = read_entry(entry, a) {
            copy_from_entry(entry, a)?;
            return Ok((Status::Cached, levels));
        }
    }
    let levels = bake_and_write(a, args, cage)?;
    if let Some(entry) = &entry {
        if let Err(e) = store_entry(entry, a, &levels) {
            eprintln!(
                "pleat {cmd}: warning: cannot cache '{}': {e}",
                a.input.display()
            );
        }
    }
    Ok((Status::Baked, levels))
}

/// The LOD parameters of asset `a`: the command line's, with the asset's sizes, face target
/// and (when its manifest row gives one) memory budget.
fn asset_params(args: &BakeArgs, a: &Asset) -> pleat::lowpoly::LodParams {
    let mut p = lod_params(args, &a.sizes, a.faces);
    if let Some(b) = a.memory_budget {
        p.memory_budget_bytes = b;
    }
    p
}

/// Reads, bakes and writes one asset's levels: a glTF scene with `.glb` outputs as
/// `pleat lod IN.glb -o OUT.glb` does (one chain per mesh, one file per level), anything else
/// merged into one mesh.
fn bake_and_write(a: &Asset, args: &BakeArgs, cage: bool) -> AssetResult<Vec<Level>> {
    #[cfg(feature = "bake")]
    if super::scene_cmd::applies_to_asset(&a.input, &a.outputs, args) {
        return bake_scene(a, args, cage);
    }
    #[cfg(feature = "bake")]
    let mesh = super::scene_cmd::read_merged(&a.input, &args.scene)?;
    #[cfg(not(feature = "bake"))]
    let mesh = read_mesh(&a.input).map_err(|e| e.to_string())?;
    let params = asset_params(args, a);
    let result = bake_levels(&mesh, &a.sizes, &params, cage, &mut |_| true);
    let baked = result.map_err(|e| e.to_string())?;
    let mut levels = Vec::with_capacity(baked.len());
    for (((m, report), &n_p), out) in baked.iter().zip(&a.sizes).zip(&a.outputs) {
        write_atomically(out, |tmp| write_mesh(tmp, m).map_err(|e| e.to_string()))?;
        levels.push(Level {
            screen_size: n_p,
            faces: m.triangle_count(),
            hausdorff_rel: report.hausdorff_rel,
            verified: report.verified.all_hold(),
        });
    }
    Ok(levels)
}

/// A glTF scene asset: every mesh's chain (`pleat::bake::scene`), then one `.glb` per level
/// holding the document with that level. A level's row sums the faces of every mesh at that
/// level (kept meshes count their own), with the largest error and whether every new level
/// verified.
#[cfg(feature = "bake")]
fn bake_scene(a: &Asset, args: &BakeArgs, cage: bool) -> AssetResult<Vec<Level>> {
    use pleat::bake::scene::{lod_scene, scene_glb, GltfScene, WriteOptions};
    let scene = GltfScene::read(&a.input).map_err(|e| e.to_string())?;
    let params = super::scene_cmd::scene_params(args, &a.sizes, asset_params(args, a), cage);
    let chains = lod_scene(&scene, &params, &mut |_| true).map_err(|e| e.to_string())?;
    let mut levels = Vec::with_capacity(a.sizes.len());
    for (&n_p, out) in a.sizes.iter().zip(&a.outputs) {
        let opts = WriteOptions {
            drop_original: args.scene.drop_original,
            only_sizes: Some(vec![n_p]),
        };
        let bytes = scene_glb(&scene, &chains, &opts).map_err(|e| e.to_string())?;
        write_atomically(out, |tmp| {
            std::fs::write(tmp, &bytes)
                .map_err(|e| format!("cannot write '{}': {e}", tmp.display()))
        })?;
        let at_size = chains
            .iter()
            .filter_map(|c| c.levels.iter().find(|l| l.screen_size == n_p));
        let mut level = Level {
            screen_size: n_p,
            faces: 0,
            hausdorff_rel: 0.0,
            verified: true,
        };
        for l in at_size {
            level.faces += l.faces;
            if let Some(s) = &l.stats {
                level.hausdorff_rel = level.hausdorff_rel.max(s.hausdorff_rel);
                level.verified &= s.verified.all_hold();
            }
        }
        levels.push(level);
    }
    Ok(levels)
}

/// Writes `path` through `write(tmp)` on a temporary file in the same folder (same extension,
/// so format-by-extension writers pick the right format), then renames it over `path`.
fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> AssetResult<()>) -> AssetResult<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create '{}': {e}", dir.display()))?;
    let name = path
        .file_name()
        .ok_or_else(|| format!("'{}' names no file", path.display()))?;
    let tmp = dir.join(format!(
        ".pleat-tmp-{}-{}-{}",
        std::process::id(),
        unique(),
        name.to_string_lossy()
    ));
    let written = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path)
            .map_err(|e| format!("cannot rename onto '{}': {e}", path.display()))
    });
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// A number not returned before in this process (temporary names of concurrent writers).
fn unique() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// The cache key of asset `a`: BLAKE3 over the layout tag, the pleat version, the command, every
/// parameter that reaches the bake or the writer (sizes, face target, rounds, alignment, output
/// formats) and the input bytes. Defaults of parameters the CLI does not expose are fixed by the
/// version.
fn cache_key(input: &[u8], a: &Asset, args: &BakeArgs, cmd: &str) -> String {
    let mut h = blake3::Hasher::new();
    let mut field = |s: &str| {
        h.update(&(s.len() as u64).to_le_bytes());
        h.update(s.as_bytes());
    };
    field(CACHE_LAYOUT);
    field(env!("CARGO_PKG_VERSION"));
    field(cmd);
    for n in &a.sizes {
        field(&format!("n_p={:016x}", n.to_bits()));
    }
    // Every LOD parameter the bake will use (its `Debug` form prints each field, f64s exactly),
    // so a parameter added to `lod_params` can never be left out of the key.
    field(&format!("{:?}", asset_params(args, a)));
    #[cfg(feature = "bake")]
    field(&super::scene_cmd::cache_fields(&args.scene));
    for o in &a.outputs {
        field(&format!("format={}", extension(o)));
    }
    h.update(&(input.len() as u64).to_le_bytes());
    h.update(input);
    h.finalize().to_hex().to_string()
}

/// The lower-case extension of `p` (the output format).
fn extension(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// File name of level `i` inside a cache entry.
fn entry_file(entry: &Path, i: usize, out: &Path) -> PathBuf {
    entry.join(format!("level{i}.{}", extension(out)))
}

/// The levels recorded in a complete cache entry, `None` when there is none (or it is unusable).
fn read_entry(entry: &Path, a: &Asset) -> Option<Vec<Level>> {
    let text = std::fs::read_to_string(entry.join("meta.json")).ok()?;
    let v: Value = serde_json::from_str(&text).ok()?;
    let levels: Vec<Level> = v
        .get("levels")?
        .as_array()?
        .iter()
        .map(|l| {
            Some(Level {
                screen_size: l.get("screen_size")?.as_f64()?,
                faces: l.get("faces")?.as_u64()? as usize,
                hausdorff_rel: l.get("hausdorff_rel")?.as_f64()?,
                verified: l.get("verified")?.as_bool()?,
            })
        })
        .collect::<Option<_>>()?;
    let complete = levels.len() == a.outputs.len()
        && a.outputs
            .iter()
            .enumerate()
            .all(|(i, o)| entry_file(entry, i, o).is_file());
    complete.then_some(levels)
}

/// Copies a cache entry's level files to the asset's outputs (each atomically).
fn copy_from_entry(entry: &Path, a: &Asset) -> AssetResult<()> {
    for (i, out) in a.outputs.iter().enumerate() {
        let src = entry_file(entry, i, out);
        write_atomically(out, |tmp| {
            std::fs::copy(&src, tmp)
                .map(|_| ())
                .map_err(|e| format!("cannot copy '{}': {e}", src.display()))
        })?;
    }
    Ok(())
}

/// Stores the written outputs as a cache entry: built in a temporary folder, then renamed to
/// its key, so a concurrent reader sees either no entry or a complete one.
fn store_entry(entry: &Path, a: &Asset, levels: &[Level]) -> AssetResult<()> {
    let dir = entry.parent().ok_or("cache entry has no folder")?;
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create '{}': {e}", dir.display()))?;
    let key = entry.file_name().unwrap_or_default().to_string_lossy();
    let tmp = dir.join(format!(".tmp-{key}-{}-{}", std::process::id(), unique()));
    let filled = fill_entry(&tmp, a, levels).and_then(|()| {
        std::fs::rename(&tmp, entry).or_else(|e| {
            // Another run stored the same key first: its entry is as good as ours.
            if entry.join("meta.json").is_file() {
                Ok(())
            } else {
                Err(format!("cannot rename onto '{}': {e}", entry.display()))
            }
        })
    });
    if tmp.exists() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    filled
}

fn fill_entry(tmp: &Path, a: &Asset, levels: &[Level]) -> AssetResult<()> {
    let io = |e: std::io::Error| format!("'{}': {e}", tmp.display());
    std::fs::create_dir_all(tmp).map_err(io)?;
    for (i, out) in a.outputs.iter().enumerate() {
        std::fs::copy(out, entry_file(tmp, i, out)).map_err(io)?;
    }
    let meta = json!({
        "pleat_version": env!("CARGO_PKG_VERSION"),
        "input": a.input.display().to_string(),
        "levels": levels.iter().map(level_json).collect::<Vec<_>>(),
    });
    let text = serde_json::to_string_pretty(&meta).unwrap_or_default();
    std::fs::write(tmp.join("meta.json"), text).map_err(io)
}

fn level_json(l: &Level) -> Value {
    json!({
        "screen_size": l.screen_size,
        "faces": l.faces,
        "hausdorff_rel": l.hausdorff_rel,
        "verified": l.verified,
    })
}

/// The `--report` document.
fn report_json(assets: &[Asset], rows: &[Row], cmd: &str, jobs: usize) -> Value {
    let assets: Vec<Value> = assets
        .iter()
        .zip(rows)
        .map(|(a, r)| {
            let levels: Vec<Value> = a
                .outputs
                .iter()
                .zip(&r.levels)
                .map(|(o, l)| {
                    let mut v = level_json(l);
                    v["output"] = json!(o.display().to_string());
                    v
                })
                .collect();
            json!({
                "input": a.input.display().to_string(),
                "status": r.status.name(),
                "cache_hit": r.status == Status::Cached,
                "seconds": r.seconds,
                "faces": r.levels.iter().map(|l| l.faces).collect::<Vec<_>>(),
                "error": r.error,
                "levels": levels,
            })
        })
        .collect();
    let count = |s: Status| rows.iter().filter(|r| r.status == s).count();
    json!({
        "pleat_version": env!("CARGO_PKG_VERSION"),
        "command": cmd,
        "jobs": jobs,
        "baked": count(Status::Baked),
        "cached": count(Status::Cached),
        "failed": count(Status::Failed),
        "assets": assets,
    })
}
