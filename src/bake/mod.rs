//! Textured LODs (feature `bake`): read a glTF asset's appearance, build LODs by
//! screen size, give each an atlas, bake the input's material onto it, and write one `.glb`
//! holding the chain.
//!
//! - [`appearance`]: glTF materials, textures (sRGB-correct), UV sets, texture transforms,
//!   vertex colours, normals and tangents, in world space.
//! - [`obj`]: the same from a Wavefront OBJ + MTL (`Kd`, `map_Kd`, `vt`, several materials).
//! - [`provenance`](mod@provenance): LOD point → input triangle and barycentric coordinates (cast along the
//!   LOD normal within an envelope of a few `d`, closest point as fallback); it lives in
//!   [`crate::transfer::provenance`] (feature `lod`, shared with attribute transfer) and is
//!   re-exported here.
//! - [`atlas`]: xatlas charts and packing with a texel density rule from the screen size.
//! - [`bake`](mod@bake): per-texel sampling, MikkTSpace normal map, dilation; vertex colours
//!   for untextured inputs.
//! - [`level`]: the baked result (mesh, material, images, report), plain data.
//! - [`output`]: a `.glb` with every level (`MSFT_lod`, `MSFT_screencoverage`).
//! - [`scene`]: a glTF document kept whole, one LOD chain per mesh in local space (`MSFT_lod`
//!   on every instancing node), written back as one GLB.
//! - [`render`]: an independent software rasterizer measuring a bake (PSNR of renders of the
//!   input and a level, normal-map gain); evaluation only.
//!
//! Each level's [`BakeReport`] gives seconds per stage, texels, charts and the appearance
//! error.

pub mod appearance;
pub mod atlas;
#[allow(clippy::module_inception)]
pub mod bake;
pub mod level;
pub mod obj;
pub mod output;
pub use crate::transfer::provenance;
pub mod render;
pub mod scene;

pub use appearance::{
    read_appearance_bytes, read_appearance_bytes_selected, read_gltf_appearance,
    read_gltf_appearance_selected, read_mesh_appearance_bytes, Appearance, AppearanceBuffers,
    BufferMaterial, ImageBuffer, MaterialSample, UvBuffer,
};
pub use atlas::{build_atlas, build_atlas_growing, Atlas, AtlasParams, Gutter};
pub use bake::{bake_level, bake_level_with_progress, BakeParams, VertexColors};
pub use level::{BakeReport, BakedLevel, BakedMaterial, Image8};
pub use obj::read_obj_appearance;
pub use output::{chain_glb, chain_glb_with_progress, screen_coverage};
pub use provenance::{provenance, InputIndex, Provenance, ProvenanceParams};
pub use scene::{
    lod_scene, scene_glb, GltfScene, Kept, MeshChain, SceneLevel, SceneParams, WriteOptions,
};

use crate::lowpoly::LodParams;
use crate::report::{Progress, ProgressFn};
use crate::Result;

/// Reads a file's appearance, by extension (case-insensitive): `.obj` through
/// [`obj::read_obj_appearance`] (OBJ + MTL), `.ply`, `.off` and `.stl` are refused
/// (`InvalidArgument`: they carry no material), anything else is read as glTF/GLB by
/// [`read_gltf_appearance`]. (Here, not in `appearance`, so that `obj` → `appearance` is the
/// only edge between the two readers.)
pub fn read_appearance(path: &std::path::Path) -> Result<Appearance> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "obj" => obj::read_obj_appearance(path),
        "ply" | "off" | "stl" => Err(crate::Error::InvalidArgument(format!(
            "'{}': a .{ext} file has no materials to bake; textured bakes read glTF \
             (.glb, .gltf) or OBJ + MTL (.obj)",
            path.display()
        ))),
        _ => read_gltf_appearance(path),
    }
}

/// Share of [`bake_chain`]'s progress range given to the geometry (the bake gets the rest).
pub const GEOMETRY_SHARE: f64 = 0.7;

/// A baked chain level: the LOD geometry, its `Stats` (passed through untouched) and the bake.
pub struct ChainLevel {
    /// The LOD mesh as `lowpoly` produced it.
    pub lod: crate::mesh::TriMesh,
    /// The LOD's own report (geometry stages, error, verified guarantees).
    pub stats: crate::lowpoly::LodReport,
    /// The baked level.
    pub baked: BakedLevel,
}

/// The result of [`bake_chain`].
pub struct BakedChain {
    /// One level per screen size, in the order given.
    pub levels: Vec<ChainLevel>,
    /// Wall seconds of the geometry (`lowpoly::generate_chain`) for the whole chain.
    pub geometry_seconds: f64,
    /// Wall seconds of every level's bake together (input BVH included).
    pub bake_seconds: f64,
}

/// LODs of `app.mesh` at every screen size (`lowpoly::generate_chain`), each baked with
/// [`bake_level`]. Levels are returned in the order of `screen_sizes`. With one screen size and
/// `lod_params.target_faces` set, the level is `lowpoly::generate` with that face target (a
/// chain ignores face targets). `progress` sees the
/// geometry stages in the first [`GEOMETRY_SHARE`] of the range, then each level's bake stages
/// ([`bake_level_with_progress`]) in an equal share of the rest; returning `false` cancels
/// with `Error::Cancelled` (within a texel chunk during the bake).
pub fn bake_chain(
    app: &Appearance,
    screen_sizes: &[f64],
    lod_params: &LodParams,
    params: &BakeParams,
    progress: &mut ProgressFn<'_>,
) -> Result<BakedChain> {
    let t = std::time::Instant::now();
    let levels = {
        let mut geometry = |p: Progress<'_>| {
            progress(Progress {
                stage: p.stage,
                fraction: GEOMETRY_SHARE * p.fraction,
            })
        };
        match (screen_sizes, lod_params.target_faces) {
            // One level with a face target: the chain ignores targets (they are per level).
            ([n_p], Some(_)) => {
                let p = LodParams {
                    screen_size: *n_p,
                    ..lod_params.clone()
                };
                vec![crate::lowpoly::generate(&app.mesh, &p, &mut geometry)?]
            }
            _ => {
                crate::lowpoly::generate_chain(&app.mesh, screen_sizes, lod_params, &mut geometry)?
            }
        }
    };
    let geometry_seconds = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let index = InputIndex::new(&app.mesh);
    let share = (1.0 - GEOMETRY_SHARE) / levels.len().max(1) as f64;
    let levels = levels
        .into_iter()
        .zip(screen_sizes)
        .enumerate()
        .map(|(i, ((lod, stats), &n_p))| {
            let base = GEOMETRY_SHARE + share * i as f64;
            let mut level = |p: Progress<'_>| {
                progress(Progress {
                    stage: p.stage,
                    fraction: base + share * p.fraction,
                })
            };
            let baked = bake_level_with_progress(app, &index, &lod, n_p, params, &mut level)?;
            Ok(ChainLevel { lod, stats, baked })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(BakedChain {
        levels,
        geometry_seconds,
        bake_seconds: t.elapsed().as_secs_f64(),
    })
}
