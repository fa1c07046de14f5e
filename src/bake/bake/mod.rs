//! Baking the input's material onto a LOD: per texel of the LOD's atlas, the LOD surface point
//! → its provenance on the input → the input's material there.
//!
//! 1. **Rasterise** the atlas: each texel whose centre lies in an atlas triangle gets that
//!    triangle and the centre's barycentric coordinates; texels within half a texel diagonal of
//!    a triangle but outside every one get the nearest point of the nearest such triangle, so
//!    bilinear filtering at chart borders reads surface values, not gutter.
//! 2. **Sample** (rayon over rows, each texel independent, so the bytes do not depend on the
//!    thread count): point and interpolated normal on the LOD, provenance
//!    ([`InputIndex::query`](crate::bake::InputIndex::query)), material evaluation ([`Appearance::sample`](crate::bake::Appearance::sample)). Base colour is
//!    interpolated in linear space by the input sampler and stored sRGB-encoded with linear
//!    alpha; emissive likewise; metallic-roughness as glTF's (–, roughness, metallic);
//!    occlusion in R (G = B = R).
//! 3. **Normal map**: the input's shading normal (its own normal map included), flipped to the
//!    LOD normal's side (the LOD wraps soups and thin parts from both sides), expressed in the
//!    LOD's MikkTSpace frame exactly as engines reconstruct it: `n' = normalize(x·T + y·B +
//!    z·N)` with `T`, `N` interpolated per pixel and `B = w · N × T`; the stored `(x, y, z)`
//!    solves that 3×3 system, normalised. Tangents come from the `mikktspace` crate on the
//!    atlas UVs with v flipped, so `B` points to image up (glTF's convention).
//! 4. **Dilate** every image into the gutters and empty space: each empty texel copies the
//!    texel a breadth-first search from all covered texels reaches it from (4-neighbours, fixed
//!    order), so mip levels average a chart only with copies of its own border.
//!
//! Without any texture in the input, the LOD gets vertex colours instead (the L² fit of the
//! base colour, factor × COLOR_0, over the LOD surface) and no atlas — except that a
//! `COLOR_0`-only input follows [`BakeParams::vertex_colors`]: under [`VertexColors::Auto`] it
//! gets a base-colour texture when the vertex fit's error exceeds what the screen size allows.
//!
//! ## Files
//!
//! `params.rs` and `progress.rs` (parameters, progress windows), `material.rs` (the material
//! fields that are not baked), `rasterize.rs` (step 1), `tangents.rs` (the LOD's shading
//! frame), `sample.rs` (step 2 and the normal map's encoding), `dilate.rs` (step 4),
//! `errors.rs` (the report's appearance error), `vertex_colors.rs` (the untextured bake),
//! `textured.rs` (steps 1–4 put together) and `entry.rs` (the entry points); they import each
//! other without cycles, in that order from the bottom. This module only declares them and
//! re-exports their API.

mod dilate;
mod entry;
mod errors;
mod material;
mod params;
mod progress;
mod rasterize;
mod sample;
mod tangents;
mod textured;
mod vertex_colors;

#[cfg(test)]
mod vertex_color_tests;

pub use entry::{bake_level, bake_level_with_progress};
pub use params::{BakeParams, VertexColors};
