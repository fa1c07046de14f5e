//! `pleat bench lod`: error against run time.
//!
//! Bakes every mesh of a folder at every screen size `n_p` with [`pleat::lowpoly::generate`]
//! (or [`pleat::cage::generate`] with `--cage`), checks each output independently with
//! [`MeshReport`] (and the cage checks of [`pleat::verify::check_cage`]), and writes
//! - `lod_bench.csv`: one row per (mesh, `n_p`) with faces, wall seconds, per-stage seconds,
//!   the sampled two-sided Hausdorff distance relative to the bounding-box diagonal `l`
//!   ([`pleat::verify::hausdorff_to_input`]: vertices plus a barycentric grid of spacing
//!   `l / 400`), the validity flags, and a `status` column (`ok`, or why the case failed);
//! - `lod_bench.svg`: Hausdorff/l against seconds, both log scale, one polyline per mesh
//!   (points in `n_p` order) and the mean over the meshes.
//!
//! With `--bake` (feature `bake`) the folder is one of textured glTF assets (default
//! `../shared/assets/textured`): each LOD is also baked ([`pleat::bake::bake_level`], with the
//! evaluation renders of `pleat::bake::render`), adding the columns `bake_s`, `texture_size`,
//! `texels_covered`, `psnr_db`, `psnr_reference_db` and `normal_gain_db`.
//!
//! A failing mesh (unreadable, rejected, error or panic inside the bake) becomes a CSV row with
//! its status; the sweep always continues.
//!
//! This file is the command's front end (arguments, progress bar, files); the sweep itself —
//! measurement, CSV, SVG, summary — is `benches/common/lod_sweep.rs`, shared with
//! `cargo bench --bench lod`, so benchmark code is not part of the library.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use pleat::mesh::io::read_mesh;
use pleat::mesh::TriMesh;

#[path = "../../../benches/common/lod_sweep.rs"]
pub(crate) mod lod_sweep;

use lod_sweep::{
    bake_case, csv_text, file_name, mesh_files, parse_csv, print_summary, read_face_targets,
    row_line, svg_text, Row, MESH_EXTENSIONS,
};

use super::{progress_bar, EXIT_FAILED, EXIT_INPUT};

/// Options of `pleat bench lod`.
#[derive(clap::Args)]
pub struct LodBenchArgs {
    /// Folder of meshes (obj, ply, off, stl, glb, gltf) [default: ../shared/meshes].
    pub dir: Option<PathBuf>,
    /// Screen sizes n_p to sweep, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "25,50,100,200,400")]
    pub screen_sizes: Vec<f64>,
    /// Folder for lod_bench.csv and lod_bench.svg (created if missing).
    #[arg(long, default_value = ".")]
    pub out_dir: PathBuf,
    /// Bake cages instead of LODs (adds the enclosure and contact columns).
    #[arg(long)]
    pub cage: bool,
    /// With --cage: the clearance, `0.05d` (fraction of d, the default) or a length in model
    /// units (see `pleat cage --clearance`).
    #[arg(long, value_parser = super::parse_clearance)]
    pub clearance: Option<pleat::lowpoly::Clearance>,
    /// LODs: the offset voxel to start from, a multiple of d/√3 in (0, 2] (`1` = the
    /// dissertation's voxel) [default: 2 from n_p = 200 on, 1.25 from 100, 1 below]; see `pleat lod
    /// --voxel-scale`.
    #[arg(long)]
    pub voxel_scale: Option<f64>,
    /// Face target per (mesh, n_p) from a CSV with columns `mesh`, `n_p`, `meshopt_faces`
    /// (the one `cargo bench --bench lod` writes) [default: target/bench/lod_vs_meshopt.csv].
    #[arg(long, num_args = 0..=1, default_missing_value = "target/bench/lod_vs_meshopt.csv")]
    pub faces_from_meshopt: Option<PathBuf>,
    /// Skip meshes with more input triangles than this (status `skipped` in the CSV).
    #[arg(long)]
    pub max_input_faces: Option<usize>,
    /// Also write each output mesh to OUT_DIR/meshes/<mesh>_<n_p>.obj.
    #[arg(long)]
    pub keep_meshes: bool,
    /// Re-plot instead of baking: read the rows of these lod_bench.csv files (comma
    /// separated; a later file's row replaces an earlier one of the same mesh and n_p) and
    /// write the merged CSV and its SVG to OUT_DIR.
    #[arg(long, value_delimiter = ',')]
    pub from_csv: Vec<PathBuf>,
    /// Also bake every LOD with the input's materials (glTF inputs only; default folder
    /// ../shared/assets/textured) and add the bake columns: seconds, texture size, covered
    /// texels, PSNR of renders against the input and its closest-point reference, normal-map
    /// gain.
    #[arg(long, conflicts_with = "cage")]
    pub bake: bool,
    /// No progress bar and no summary table.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `pleat bench lod`.
pub fn run(args: &LodBenchArgs) -> ExitCode {
    match sweep(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, msg)) => {
            eprintln!("pleat bench lod: {msg}");
            ExitCode::from(code)
        }
    }
}

/// The whole command; `Err((exit code, message))` only for problems with the arguments or the
/// output folder — a failing mesh is a CSV row.
fn sweep(args: &LodBenchArgs) -> Result<(), (u8, String)> {
    if !args.from_csv.is_empty() {
        return replot(args);
    }
    let default_dir = if args.bake {
        "../shared/assets/textured"
    } else {
        "../shared/meshes"
    };
    let dir = args
        .dir
        .clone()
        .unwrap_or_else(|| PathBuf::from(default_dir));
    check_arguments(args)?;
    let files = list_meshes(&dir, args.bake).map_err(|e| (EXIT_INPUT, e))?;
    let targets = match &args.faces_from_meshopt {
        Some(p) => read_face_targets(p).map_err(|e| (EXIT_INPUT, e))?,
        None => HashMap::new(),
    };
    std::fs::create_dir_all(&args.out_dir).map_err(|e| {
        (
            EXIT_FAILED,
            format!("cannot create {}: {e}", args.out_dir.display()),
        )
    })?;
    let sizes = &args.screen_sizes;
    let bar = progress_bar(args.quiet);
    if let Some(b) = &bar {
        b.set_length((files.len() * sizes.len() * 1000) as u64);
    }
    let mut rows = Vec::new();
    for (i, file) in files.iter().enumerate() {
        let name = file_name(file);
        let base = (i * sizes.len() * 1000) as u64;
        if let Some(b) = &bar {
            b.set_position(base);
            b.set_message(format!("{name}: loading"));
        }
        let input = match load(file, args.max_input_faces, args.bake) {
            Ok(m) => m,
            Err(status) => {
                rows.push(Row {
                    mesh: name,
                    n_p: f64::NAN,
                    status,
                    ..Row::default()
                });
                continue;
            }
        };
        let mesh = input.mesh();
        for (j, &n_p) in sizes.iter().enumerate() {
            let job = base + (j * 1000) as u64;
            let mut prog = |p: pleat::Progress<'_>| {
                if let Some(b) = &bar {
                    b.set_position(job + (p.fraction * 1000.0) as u64);
                    b.set_message(format!("{name} n_p={n_p}: {}", p.stage));
                }
                true
            };
            let target = targets.get(&(name.clone(), n_p.to_bits())).copied();
            let (mut row, out) = bake_case(
                &name,
                mesh,
                n_p,
                target,
                args.cage,
                args.clearance,
                args.voxel_scale,
                &mut prog,
            );
            if let (Some(out), true) = (&out, row.ok()) {
                input.bake(&mut row, out);
            }
            if let (true, Some(out)) = (args.keep_meshes, out) {
                keep_mesh(&args.out_dir, &name, n_p, &out);
            }
            if let (Some(b), false) = (&bar, args.quiet) {
                b.println(row_line(&row));
            } else if !args.quiet {
                println!("{}", row_line(&row));
            }
            rows.push(row);
        }
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let csv = args.out_dir.join("lod_bench.csv");
    let svg = args.out_dir.join("lod_bench.svg");
    write_file(&csv, &csv_text(&rows, args.cage))?;
    write_file(&svg, &svg_text(&rows, sizes, args.cage))?;
    if !args.quiet {
        print_summary(&rows, sizes);
        println!("wrote {} and {}", csv.display(), svg.display());
    }
    Ok(())
}

/// `--from-csv`: merge earlier results and write them again with their plot.
fn replot(args: &LodBenchArgs) -> Result<(), (u8, String)> {
    let mut rows: Vec<Row> = Vec::new();
    let mut cage = false;
    for path in &args.from_csv {
        let text = std::fs::read_to_string(path)
            .map_err(|e| (EXIT_INPUT, format!("cannot read {}: {e}", path.display())))?;
        let (new, has_cage) =
            parse_csv(&text).map_err(|e| (EXIT_INPUT, format!("{}: {e}", path.display())))?;
        cage |= has_cage;
        for r in new {
            rows.retain(|o| !(o.mesh == r.mesh && o.n_p.to_bits() == r.n_p.to_bits()));
            rows.push(r);
        }
    }
    rows.sort_by(|a, b| a.mesh.cmp(&b.mesh).then(a.n_p.total_cmp(&b.n_p)));
    let mut sizes: Vec<f64> = rows
        .iter()
        .map(|r| r.n_p)
        .filter(|n| n.is_finite())
        .collect();
    sizes.sort_by(f64::total_cmp);
    sizes.dedup();
    std::fs::create_dir_all(&args.out_dir).map_err(|e| {
        (
            EXIT_FAILED,
            format!("cannot create {}: {e}", args.out_dir.display()),
        )
    })?;
    let csv = args.out_dir.join("lod_bench.csv");
    let svg = args.out_dir.join("lod_bench.svg");
    write_file(&csv, &csv_text(&rows, cage))?;
    write_file(&svg, &svg_text(&rows, &sizes, cage))?;
    if !args.quiet {
        print_summary(&rows, &sizes);
        println!("wrote {} and {}", csv.display(), svg.display());
    }
    Ok(())
}

/// Rejects an empty `--screen-sizes` or one that is not finite and > 0 (exit code 2).
pub(crate) fn check_screen_sizes(sizes: &[f64]) -> Result<(), (u8, String)> {
    if sizes.is_empty() || sizes.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        let msg = format!("--screen-sizes must be finite and > 0, got {sizes:?}");
        return Err((EXIT_INPUT, msg));
    }
    Ok(())
}

/// Rejects bad screen sizes and a cage request without the `cage` feature.
fn check_arguments(args: &LodBenchArgs) -> Result<(), (u8, String)> {
    check_screen_sizes(&args.screen_sizes)?;
    if args.bake && !cfg!(feature = "bake") {
        return Err((EXIT_INPUT, "--bake needs the `bake` feature".into()));
    }
    if args.cage && !cfg!(feature = "cage") {
        return Err((EXIT_INPUT, "--cage needs the `cage` feature".into()));
    }
    Ok(())
}

/// The mesh files of `dir` (glTF only with `bake`), sorted by name; an error when there is
/// none.
fn list_meshes(dir: &Path, bake: bool) -> Result<Vec<PathBuf>, String> {
    let ext: &[&str] = if bake {
        &["glb", "gltf"]
    } else {
        &MESH_EXTENSIONS
    };
    let files = mesh_files(dir, ext)?;
    if files.is_empty() {
        return Err(format!("no mesh files in {}", dir.display()));
    }
    Ok(files)
}

/// What a case is made from: a mesh, or (`--bake`) a glTF asset's appearance.
enum Input {
    Mesh(TriMesh),
    #[cfg(feature = "bake")]
    Textured(Box<pleat::bake::Appearance>),
}

impl Input {
    fn mesh(&self) -> &TriMesh {
        match self {
            Input::Mesh(m) => m,
            #[cfg(feature = "bake")]
            Input::Textured(a) => &a.mesh,
        }
    }

    /// Bakes `out` (a LOD of this input at `row.n_p`) and fills the row's bake columns; a
    /// failed bake becomes the row's status.
    fn bake(&self, row: &mut Row, out: &TriMesh) {
        match self {
            Input::Mesh(_) => {
                let _ = (row, out);
            }
            #[cfg(feature = "bake")]
            Input::Textured(app) => {
                let index = pleat::bake::InputIndex::new(&app.mesh);
                let params = pleat::bake::BakeParams {
                    evaluate: true,
                    ..Default::default()
                };
                match pleat::bake::bake_level(app, &index, out, row.n_p, &params) {
                    Ok(level) => row.bake = Some(lod_sweep::BakeCols::of(&level.report)),
                    Err(e) => row.status = format!("bake error: {e}"),
                }
            }
        }
    }
}

/// Reads a mesh (with `bake`, a glTF asset's appearance); `Err(status)` when it cannot be read
/// or is over the size limit.
fn load(file: &Path, max_faces: Option<usize>, bake: bool) -> Result<Input, String> {
    let input = if bake {
        read_textured(file)?
    } else {
        Input::Mesh(read_mesh(file).map_err(|e| format!("load error: {e}"))?)
    };
    match max_faces {
        Some(n) if input.mesh().triangle_count() > n => Err(format!(
            "skipped: {} input triangles > --max-input-faces {n}",
            input.mesh().triangle_count()
        )),
        _ => Ok(input),
    }
}

#[cfg(feature = "bake")]
fn read_textured(file: &Path) -> Result<Input, String> {
    pleat::bake::read_appearance(file)
        .map(|a| Input::Textured(Box::new(a)))
        .map_err(|e| format!("load error: {e}"))
}

#[cfg(not(feature = "bake"))]
fn read_textured(_file: &Path) -> Result<Input, String> {
    Err("--bake needs the `bake` feature".into())
}

/// Writes `out` to `OUT_DIR/meshes/<mesh stem>_<n_p>.obj`, warning on failure.
fn keep_mesh(out_dir: &Path, name: &str, n_p: f64, out: &TriMesh) {
    let dir = out_dir.join("meshes");
    let stem = Path::new(name)
        .file_stem()
        .map_or(name.into(), |s| s.to_string_lossy().to_string());
    let path = dir.join(format!("{stem}_{n_p}.obj"));
    let r = std::fs::create_dir_all(&dir)
        .map_err(|e| e.to_string())
        .and_then(|_| pleat::mesh::io::write_mesh(&path, out).map_err(|e| e.to_string()));
    if let Err(e) = r {
        eprintln!("pleat bench lod: cannot write {}: {e}", path.display());
    }
}

/// Writes `text` to `path`; `Err` with exit code 1 and the reason.
pub(crate) fn write_file(path: &Path, text: &str) -> Result<(), (u8, String)> {
    std::fs::write(path, text)
        .map_err(|e| (EXIT_FAILED, format!("cannot write {}: {e}", path.display())))
}
