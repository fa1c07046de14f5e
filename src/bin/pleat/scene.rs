//! `pleat lod IN.glb --screen-size 50,100,200 [--bake] -o OUT.glb` (and `pleat cage`): the
//! glTF document kept whole, one LOD chain per mesh (`pleat::bake::scene`), the default for
//! glTF input with a `.glb` output; `--merge` gives the merged proxy instead.

use std::path::Path;
use std::process::ExitCode;

use pleat::bake::scene::{lod_scene, scene_glb, GltfScene, SceneParams, WriteOptions};
use pleat::bake::{AtlasParams, BakeParams};
use pleat::mesh::io::{MeshFormat, NodeFilter};

use super::{
    failure_code, output_path, progress_bar, show_progress, BakeArgs, EXIT_FAILED, EXIT_INPUT,
    SIZE_PLACEHOLDERS,
};

/// Options of glTF scene input (flattened into `lod`'s and `cage`'s options).
#[derive(clap::Args)]
pub struct SceneArgs {
    /// glTF input: fuse every mesh instance into one world-space soup and write one merged
    /// proxy (one node `LOD0`, one baked atlas with --bake), as for OBJ/PLY/OFF/STL input.
    /// Without it a glTF input keeps its document (nodes, skins, animations, cameras, lights,
    /// materials, extras) and every mesh gets its own LOD chain (MSFT_lod), written to a .glb.
    #[arg(long)]
    pub merge: bool,
    /// Per-mesh chains: the instancing nodes show the finest new level instead of the input
    /// mesh (the input mesh stays in the file, unused).
    #[arg(long, conflicts_with = "merge")]
    pub drop_original: bool,
    /// Per-mesh chains: the largest error, in pixels at each level's screen size, that the
    /// skin of a skinned mesh may add when posed (joints turning by up to their animations'
    /// largest angle, at least 1 rad). Smaller keeps more vertices where weights change
    /// [default: 0.5].
    #[arg(long, value_parser = parse_skin_error, conflicts_with = "merge")]
    pub skin_error: Option<f64>,
    /// glTF input: only these nodes, each with everything below it: node names separated by
    /// commas, `*` and `?` as wildcards, `#N` for node N. With --merge only they are fused into
    /// the proxy; otherwise only the meshes they instance get chains.
    #[arg(long, value_name = "NAMES", value_parser = parse_nodes)]
    pub nodes: Option<NodeFilter>,
}

fn parse_nodes(s: &str) -> Result<NodeFilter, String> {
    NodeFilter::parse(s).map_err(|e| e.to_string())
}

/// Whether `p` names a glTF file (`.glb`, `.gltf`, any case).
fn is_gltf(p: &Path) -> bool {
    matches!(
        MeshFormat::from_path(p),
        Ok(MeshFormat::Glb | MeshFormat::Gltf)
    )
}

/// Refuses `--nodes` on an input that is not glTF (nodes are glTF's).
fn nodes_need_gltf(input: &Path, args: &SceneArgs) -> Result<(), String> {
    if args.nodes.is_some() && !is_gltf(input) {
        return Err(format!(
            "--nodes selects glTF nodes, and '{}' is not a .glb or .gltf file",
            input.display()
        ));
    }
    Ok(())
}

/// The merged geometry of `input`: the nodes `--nodes` selects, or the whole file.
pub fn read_merged(input: &Path, args: &SceneArgs) -> Result<pleat::mesh::TriMesh, String> {
    nodes_need_gltf(input, args)?;
    match &args.nodes {
        Some(f) => pleat::mesh::io::gltf::read_gltf_selected(input, Some(f)),
        None => pleat::mesh::io::read_mesh(input),
    }
    .map_err(|e| e.to_string())
}

/// The merged appearance of `input` (textured bakes): the nodes `--nodes` selects, or the whole
/// file.
pub fn read_merged_appearance(
    input: &Path,
    args: &SceneArgs,
) -> Result<pleat::bake::Appearance, String> {
    nodes_need_gltf(input, args)?;
    match &args.nodes {
        Some(f) => pleat::bake::read_gltf_appearance_selected(input, Some(f)),
        None => pleat::bake::read_appearance(input),
    }
    .map_err(|e| e.to_string())
}

fn parse_skin_error(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "the skin error must be a number of pixels > 0, got {s}"
        )),
    }
}

/// Whether `input` → `output` runs as a scene (glTF in, `.glb` out, no `--merge`).
pub fn applies(input: &Path, args: &BakeArgs) -> bool {
    let gltf_in = is_gltf(input);
    let glb_out = args.output.as_deref().is_some_and(is_glb);
    if gltf_in && !args.scene.merge && !glb_out && !args.quiet {
        eprintln!(
            "pleat: the output is not .glb, so the glTF input is merged into one mesh (as with \
             --merge)"
        );
    }
    gltf_in && !args.scene.merge && glb_out
}

/// The scene parameters of the command line, with the levels `sizes` and LOD parameters `lod`.
pub fn scene_params(
    args: &BakeArgs,
    sizes: &[f64],
    lod: pleat::lowpoly::LodParams,
    cage: bool,
) -> SceneParams {
    let bake = args.textures.bake.then(|| BakeParams {
        atlas: AtlasParams {
            size: args.textures.texture_size,
            ..AtlasParams::default()
        },
        vertex_colors: args.textures.vertex_colors.into(),
        ..BakeParams::default()
    });
    SceneParams {
        screen_sizes: sizes.to_vec(),
        lod,
        cage,
        bake,
        skin_error: args.scene.skin_error.unwrap_or(0.0),
        nodes: args.scene.nodes.clone(),
    }
}

/// Whether a batch asset `input` → `outputs` bakes as a scene: glTF in, every output `.glb`,
/// no `--merge` (the batch form of [`applies`], without its notice).
pub fn applies_to_asset(input: &Path, outputs: &[std::path::PathBuf], args: &BakeArgs) -> bool {
    is_gltf(input) && !args.scene.merge && outputs.iter().all(|o| is_glb(o))
}

/// Whether `p` ends in `.glb` (any case).
fn is_glb(p: &Path) -> bool {
    matches!(MeshFormat::from_path(p), Ok(MeshFormat::Glb))
}

/// The scene options in the form a cache key hashes (every one that changes the output).
pub fn cache_fields(args: &SceneArgs) -> String {
    format!(
        "merge={} drop_original={} skin_error={:?} nodes={:?}",
        args.merge,
        args.drop_original,
        args.skin_error.map(f64::to_bits),
        args.nodes.as_ref().map(NodeFilter::patterns)
    )
}

/// Runs the per-mesh bake of a glTF scene; `cage` bakes cages.
pub fn run(input: &Path, args: &BakeArgs, cage: bool) -> ExitCode {
    let cmd = if cage { "cage" } else { "lod" };
    let Some(output) = args.output.as_deref() else {
        eprintln!("pleat {cmd}: no output file (give -o)");
        return ExitCode::from(EXIT_INPUT);
    };
    if cage && args.textures.bake {
        eprintln!("pleat {cmd}: --bake is only available for `pleat lod`");
        return ExitCode::from(EXIT_INPUT);
    }
    if args.screen_size.len() > 1 && args.faces.is_some() {
        eprintln!("pleat {cmd}: --faces needs a single screen size");
        return ExitCode::from(EXIT_INPUT);
    }
    let scene = match GltfScene::read(input) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let lod = super::lod_params(args, &args.screen_size, args.faces);
    let params = scene_params(args, &args.screen_size, lod, cage);
    let t = std::time::Instant::now();
    let bar = progress_bar(args.quiet);
    let mut prog = |p: pleat::Progress<'_>| show_progress(&bar, p);
    let result = lod_scene(&scene, &params, &mut prog);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let chains = match result {
        Ok(c) => c,
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(failure_code(&e));
        }
    };
    let per_level = SIZE_PLACEHOLDERS
        .iter()
        .any(|p| output.to_string_lossy().contains(p));
    let mut sizes = args.screen_size.clone();
    sizes.sort_by(|a, b| b.total_cmp(a));
    sizes.dedup();
    let files: Vec<(std::path::PathBuf, Option<Vec<f64>>)> = if per_level {
        sizes
            .iter()
            .map(|&s| (output_path(output, s), Some(vec![s])))
            .collect()
    } else {
        vec![(output.to_path_buf(), None)]
    };
    for (path, only) in &files {
        let opts = WriteOptions {
            drop_original: args.scene.drop_original,
            only_sizes: only.clone(),
        };
        let bytes = match scene_glb(&scene, &chains, &opts) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("pleat {cmd}: {e}");
                return ExitCode::from(failure_code(&e));
            }
        };
        if let Err(e) = std::fs::write(path, bytes) {
            eprintln!("pleat {cmd}: cannot write '{}': {e}", path.display());
            return ExitCode::from(EXIT_FAILED);
        }
    }
    if !args.quiet {
        for c in &chains {
            println!(
                "{} (mesh {}, {} instance{}, {} faces, {:.2} s):",
                c.name,
                c.mesh,
                c.instances,
                if c.instances == 1 { "" } else { "s" },
                c.faces,
                c.seconds
            );
            for l in &c.levels {
                match &l.kept {
                    Some(k) => println!("  n_p {:>5}: {:>7} faces in, {k}", l.screen_size, c.faces),
                    None => {
                        print!(
                            "  n_p {:>5}: {:>7} faces in, {:>7} out",
                            l.screen_size, c.faces, l.faces
                        );
                        if let Some(s) = &l.stats {
                            print!(", Hausdorff/l {:.5}", s.hausdorff_rel);
                            if !s.verified.all_hold() {
                                print!(", verified: NO");
                            }
                        }
                        if let Some(b) = &l.baked {
                            print!(", {}² texels", b.report.texture_size);
                        }
                        println!();
                    }
                }
                if args.verbose {
                    if let Some(s) = &l.stats {
                        super::print_stats(&s.entries());
                    }
                }
            }
        }
        let skipped = scene.mesh_count() - chains.len();
        if skipped > 0 {
            let why = if args.scene.nodes.is_some() {
                "not instanced by the selected nodes, without triangles or instancing node"
            } else {
                "without triangles or instancing node"
            };
            println!("{skipped} mesh(es) {why}: left as they are");
        }
        let names: Vec<String> = files.iter().map(|(p, _)| p.display().to_string()).collect();
        println!(
            "{} mesh chains in {:.2} s; wrote {}",
            chains.len(),
            t.elapsed().as_secs_f64(),
            names.join(", ")
        );
    }
    ExitCode::SUCCESS
}
