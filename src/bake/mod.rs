//! Textured LODs (issue 11; feature `bake`): read a glTF asset's appearance, build LODs by
//! screen size, give each an atlas, bake the input's material onto it, and write one `.glb`
//! holding the chain.
//!
//! - [`appearance`]: glTF materials, textures (sRGB-correct), UV sets, texture transforms,
//!   vertex colours, normals and tangents, in world space.
//! - [`provenance`]: LOD point → input triangle and barycentric coordinates (cast along the
//!   LOD normal within an envelope of a few `d`, closest point as fallback).
//! - [`atlas`]: xatlas charts and packing with a texel density rule from the screen size.
//! - [`bake`](mod@bake): per-texel sampling, MikkTSpace normal map, dilation; vertex colours
//!   for untextured inputs.
//! - [`output`]: a `.glb` with every level (`MSFT_lod`, `MSFT_screencoverage`).
//! - [`render`]: an independent software rasterizer measuring a bake (PSNR of renders of the
//!   input and a level, normal-map gain); evaluation only.
//!
//! Each level's [`BakeReport`] gives seconds per stage, texels, charts and the appearance
//! error.

pub mod appearance;
pub mod atlas;
#[allow(clippy::module_inception)]
pub mod bake;
pub mod output;
pub mod provenance;
pub mod render;

pub use appearance::{read_appearance, read_appearance_bytes, Appearance, MaterialSample};
pub use atlas::{build_atlas, Atlas, AtlasParams};
pub use bake::{bake_level, BakeParams, BakeReport, BakedLevel, BakedMaterial, Image8};
pub use output::{chain_glb, screen_coverage};
pub use provenance::{provenance, InputIndex, Provenance, ProvenanceParams};

use crate::lowpoly::LodParams;
use crate::report::ProgressFn;
use crate::Result;

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
/// [`bake_level`]. Levels are returned in the order of `screen_sizes`. `progress` sees the
/// geometry stages (the bake reports nothing; it is short next to them).
pub fn bake_chain(
    app: &Appearance,
    screen_sizes: &[f64],
    lod_params: &LodParams,
    params: &BakeParams,
    progress: &mut ProgressFn<'_>,
) -> Result<BakedChain> {
    let t = std::time::Instant::now();
    let levels = crate::lowpoly::generate_chain(&app.mesh, screen_sizes, lod_params, progress)?;
    let geometry_seconds = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let index = InputIndex::new(&app.mesh);
    let levels = levels
        .into_iter()
        .zip(screen_sizes)
        .map(|((lod, stats), &n_p)| {
            let baked = bake_level(app, &index, &lod, n_p, params)?;
            Ok(ChainLevel { lod, stats, baked })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(BakedChain {
        levels,
        geometry_seconds,
        bake_seconds: t.elapsed().as_secs_f64(),
    })
}
