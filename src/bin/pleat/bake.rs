//! `pleat lod IN.glb|IN.obj --screen-size 50,100,200 --bake [--texture-size N] -o OUT.glb`: the
//! LOD chain with the input's materials (glTF, or OBJ + MTL) baked onto every level, written as
//! one `.glb` linked with `MSFT_lod` (feature `bake`).

use std::path::Path;
use std::process::ExitCode;

use pleat::bake::{
    bake_chain, chain_glb_with_progress, AtlasParams, BakeParams, BakedLevel, VertexColors,
};

use super::{
    failure_code, output_path, progress_bar, show_progress, BakeArgs, EXIT_FAILED, EXIT_INPUT,
    SIZE_PLACEHOLDERS,
};

/// Options of the textured bake (flattened into `lod`'s options).
#[derive(clap::Args)]
pub struct TextureArgs {
    /// Bake the input's materials (glTF: base colour, metallic-roughness, occlusion, emissive,
    /// normal map; OBJ + MTL: Kd, map_Kd; vertex colours when untextured) onto every level and
    /// write ONE .glb holding the chain (MSFT_lod); with an {np} placeholder in the output, one
    /// .glb per level instead.
    #[arg(long)]
    pub bake: bool,
    /// Side of the baked square textures in texels [default: 2 texels per screen pixel at the
    /// level's n_p, next power of two, 32..4096].
    #[arg(long, requires = "bake")]
    pub texture_size: Option<u32>,
    /// How an input whose only colour is COLOR_0 (no texture) is baked: `auto` keeps vertex
    /// colours when they are within the error the screen size allows, else bakes a texture;
    /// `vertex` or `texture` force one.
    #[arg(long, requires = "bake", value_enum, default_value_t = VertexColorsArg::Auto)]
    pub vertex_colors: VertexColorsArg,
}

/// `--vertex-colors`: [`VertexColors`] on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexColorsArg {
    /// Vertex colours when good enough for the screen size, else a texture.
    Auto,
    /// Always vertex colours.
    Vertex,
    /// Always a base-colour texture.
    Texture,
}

impl From<VertexColorsArg> for VertexColors {
    fn from(a: VertexColorsArg) -> Self {
        match a {
            VertexColorsArg::Auto => VertexColors::Auto,
            VertexColorsArg::Vertex => VertexColors::Vertex,
            VertexColorsArg::Texture => VertexColors::Texture,
        }
    }
}

/// Runs the textured bake; `cmd` names the subcommand in messages.
pub fn run(input: &Path, args: &BakeArgs, cmd: &str) -> ExitCode {
    if cmd != "lod" {
        eprintln!("pleat {cmd}: --bake is only available for `pleat lod`");
        return ExitCode::from(EXIT_INPUT);
    }
    let Some(output) = args.output.as_deref() else {
        eprintln!("pleat {cmd}: no output file (give -o)");
        return ExitCode::from(EXIT_INPUT);
    };
    if args.screen_size.len() > 1 && args.faces.is_some() {
        eprintln!("pleat {cmd}: --faces needs a single screen size");
        return ExitCode::from(EXIT_INPUT);
    }
    if let Some(s) = args.textures.texture_size {
        if !(1..=16384).contains(&s) {
            eprintln!("pleat {cmd}: --texture-size must be in 1..=16384, got {s}");
            return ExitCode::from(EXIT_INPUT);
        }
    }
    let app = match super::scene_cmd::read_merged_appearance(input, &args.scene) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let lod_params = super::lod_params(args, &args.screen_size, args.faces);
    let params = BakeParams {
        atlas: AtlasParams {
            size: args.textures.texture_size,
            ..AtlasParams::default()
        },
        vertex_colors: args.textures.vertex_colors.into(),
        ..BakeParams::default()
    };
    let bar = progress_bar(args.quiet);
    let mut prog = |p: pleat::Progress<'_>| show_progress(&bar, p);
    let result = bake_chain(&app, &args.screen_size, &lod_params, &params, &mut prog);
    let mut chain = match result {
        Ok(l) => l,
        Err(e) => {
            if let Some(b) = &bar {
                b.finish_and_clear();
            }
            eprintln!("pleat {cmd}: {e}");
            return ExitCode::from(failure_code(&e));
        }
    };
    // Never larger than the input: a level whose LOD has more faces than the input soup is
    // the input geometry itself, baked the same way.
    let input_faces = app.mesh.triangle_count();
    let mut kept = Vec::new();
    for l in &mut chain.levels {
        if l.lod.triangle_count() <= input_faces {
            continue;
        }
        let index = pleat::bake::InputIndex::new(&app.mesh);
        let n_p = l.baked.screen_size;
        match pleat::bake::bake_level(&app, &index, &app.mesh, n_p, &params) {
            Ok(b) => {
                kept.push((n_p, l.lod.triangle_count()));
                l.baked = b;
            }
            Err(e) => {
                eprintln!("pleat {cmd}: {e}");
                return ExitCode::from(failure_code(&e));
            }
        }
    }
    let levels = &chain.levels;
    let refs: Vec<&BakedLevel> = levels.iter().map(|l| &l.baked).collect();
    // `-o OUT.glb`: one file holding the chain; `-o 'OUT_{np}.glb'`: one file per level.
    let per_level = SIZE_PLACEHOLDERS
        .iter()
        .any(|p| output.to_string_lossy().contains(p));
    let files: Vec<(std::path::PathBuf, Vec<&BakedLevel>)> = if per_level {
        refs.iter()
            .map(|&l| (output_path(output, l.screen_size), vec![l]))
            .collect()
    } else {
        vec![(output.to_path_buf(), refs)]
    };
    let mut png_seconds = 0.0;
    for (path, file_levels) in &files {
        let (bytes, png) = match chain_glb_with_progress(file_levels, &mut prog) {
            Ok(b) => b,
            Err(e) => {
                if let Some(b) = &bar {
                    b.finish_and_clear();
                }
                eprintln!("pleat {cmd}: {e}");
                return ExitCode::from(failure_code(&e));
            }
        };
        png_seconds += png;
        if let Err(e) = std::fs::write(path, bytes) {
            eprintln!("pleat {cmd}: cannot write '{}': {e}", path.display());
            return ExitCode::from(EXIT_FAILED);
        }
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if !args.quiet {
        for l in levels {
            let r = &l.baked.report;
            println!(
                "n_p {:>5}: {:>6} faces, {:>4}² texels ({} covered, {} charts), appearance \
                 error mean {:.2} p95 {:.2} /255, bake {:.2} s",
                l.baked.screen_size,
                l.baked.triangles.len(),
                r.texture_size,
                r.texels_covered,
                r.charts,
                r.appearance_error_mean,
                r.appearance_error_p95,
                r.total_seconds
            );
            if let (Some(fit), Some(allowed)) = (r.vertex_fit_error, r.vertex_fit_allowed_error) {
                println!(
                    "  vertex colours: fit error {fit:.2} /255, the screen size allows \
                     {allowed:.2}: {}",
                    if r.texture_size > 0 {
                        "baked a texture"
                    } else {
                        "kept vertex colours"
                    }
                );
            }
            let requested_padding = params.atlas.padding;
            if r.texture_size > 0 && r.atlas_padding < requested_padding {
                println!(
                    "  warning: {} charts needed a {}-texel gutter instead of {requested_padding}",
                    r.charts, r.atlas_padding
                );
            }
            let rule_mip = pleat::bake::atlas::deepest_mip(params.atlas.texels_per_pixel);
            if r.texture_size > 0 && r.seam_clean_mip.is_none_or(|m| m < rule_mip) {
                println!(
                    "  warning: chart seams are clean down to mip {} only (the texel rule reads \
                     mip {rule_mip})",
                    r.seam_clean_mip
                        .map_or("none".to_string(), |m| m.to_string())
                );
            }
            if r.overlapping_texels > 0 {
                println!(
                    "  warning: {} texels where atlas charts overlap (xatlas left a folded chart)",
                    r.overlapping_texels
                );
            }
        }
        for (n_p, lod_faces) in &kept {
            println!(
                "n_p {n_p:>5}: unchanged geometry: the input's {input_faces} faces are written \
                 (its LOD had {lod_faces})"
            );
        }
        let names: Vec<String> = files.iter().map(|(p, _)| p.display().to_string()).collect();
        println!(
            "geometry {:.2} s, bake {:.2} s, png {png_seconds:.2} s; wrote {}",
            chain.geometry_seconds,
            chain.bake_seconds,
            names.join(", ")
        );
    }
    ExitCode::SUCCESS
}
