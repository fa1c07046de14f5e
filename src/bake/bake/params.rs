//! The parameters of a material bake ([`BakeParams`]) and the choice between vertex colours and
//! a texture for a `COLOR_0`-only input ([`VertexColors`]), with their defaults.

use crate::bake::atlas::AtlasParams;

/// Parameters of [`bake_level`](crate::bake::bake_level).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BakeParams {
    /// Atlas size rule and gutter.
    pub atlas: AtlasParams,
    /// Provenance envelope in units of the LOD's offset distance `d = l / n_p` (finite, > 0).
    /// Default 3.
    pub envelope_d: f64,
    /// Bake a tangent-space normal map. Default true.
    pub normal_map: bool,
    /// At most this many texels are compared with the input for the appearance error
    /// (0 skips the measurement). Default 20 000.
    pub error_samples: usize,
    /// After the bake (outside `total_seconds`), render the input and the level from 24 views
    /// with [`crate::bake::render::evaluate`] and fill the report's `appearance_psnr_db`,
    /// `appearance_psnr_reference_db` and `normal_map_gain_db`. Default false.
    pub evaluate: bool,
    /// How an input whose only colour source is `COLOR_0` (no texture) is baked. Default
    /// [`VertexColors::Auto`].
    pub vertex_colors: VertexColors,
}

/// How a `COLOR_0`-only input (vertex colours, no texture in any material) is transferred.
/// The output never carries both: glTF multiplies `COLOR_0` into the base colour, so a level
/// is either vertex-coloured (no base-colour texture) or textured (no `COLOR_0`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VertexColors {
    /// Vertex colours when they are good enough for the screen size, else a texture. The rule:
    /// a pixel at `n_p` covers `h = l / n_p` of the surface and shows its colour averaged over
    /// that footprint, so an error of the colour change across half a pixel, `|∇c| · h/2`
    /// (`c` the input's sRGB base colour in 1/255, its gradient over the input triangle at the
    /// closest input point, max over R, G, B), plus one 8-bit step, is not visible at that
    /// size. The vertex fit ([`bake_level`](crate::bake::bake_level)'s L² fit) is kept when its mean error over the
    /// surface samples is at most the mean allowed error over the same samples; otherwise the
    /// level gets a texture at the atlas rule's density. Both numbers are reported
    /// (`BakeReport::vertex_fit_error`, `vertex_fit_allowed_error`).
    #[default]
    Auto,
    /// Always vertex colours (the L² fit), as before this option existed.
    Vertex,
    /// Always a base-colour texture (the textured path samples `factor × COLOR_0`).
    Texture,
}

impl Default for BakeParams {
    fn default() -> Self {
        BakeParams {
            atlas: AtlasParams::default(),
            envelope_d: 3.0,
            normal_map: true,
            error_samples: 20_000,
            evaluate: false,
            vertex_colors: VertexColors::Auto,
        }
    }
}
