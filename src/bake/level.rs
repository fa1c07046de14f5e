//! The result of a bake: a [`BakedLevel`] (mesh, atlas UVs, tangents, colours), its
//! [`BakedMaterial`] with [`Image8`] textures, and its [`BakeReport`]. Plain data shared by the
//! baker ([`super::bake`](mod@super::bake)), the evaluation renderer ([`super::render`]) and
//! the writer ([`super::output`]), so none of them depends on another.

use super::appearance::AlphaMode;

/// Timing, sizes and the appearance error of one baked level.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BakeReport {
    /// Seconds spent building the UV atlas (xatlas).
    pub atlas_seconds: f64,
    /// Seconds spent on MikkTSpace tangents.
    pub tangent_seconds: f64,
    /// Seconds spent rasterising the atlas into texels.
    pub raster_seconds: f64,
    /// Seconds spent on provenance and material sampling (texels or vertices).
    pub sample_seconds: f64,
    /// Seconds spent dilating the images into their gutters.
    pub dilate_seconds: f64,
    /// Seconds spent measuring the appearance error.
    pub measure_seconds: f64,
    /// Wall seconds of the whole level bake (the LOD geometry not included).
    pub total_seconds: f64,
    /// Side of the square textures in texels (0 when vertex colours were baked instead).
    pub texture_size: u32,
    /// Texels covered by charts (sampled from the input), the rest being gutter.
    pub texels_covered: u64,
    /// Charts of the atlas.
    pub charts: u32,
    /// Texel centres where two non-adjacent atlas triangles overlap (0 for a valid atlas;
    /// xatlas occasionally leaves a folded chart, see `atlas::overlapping_texels`).
    pub overlapping_texels: u64,
    /// Gutter between charts in texels, as used: the requested padding unless the charts did
    /// not fit with it (thousands of charts), then less, and seams hold to a shallower mip.
    pub atlas_padding: u32,
    /// The deepest mip level, up to [`deepest_mip`](super::atlas::deepest_mip) of the texel
    /// rule, whose bilinear reads at any point of a chart stay in that chart's texels by
    /// construction (no 2^m-texel block reached by two charts' footprints, see
    /// [`footprint_owners`](super::atlas::footprint_owners)); `None` for vertex colours or
    /// when even mip 0 mixes charts.
    pub seam_clean_mip: Option<u32>,
    /// Fraction of samples whose provenance came from the closest-point fallback, in [0, 1].
    pub fallback_fraction: f64,
    /// Mean appearance error: |baked base colour − input base colour at the closest input
    /// point|, max over R, G, B, in sRGB units of 1/255, over up to
    /// [`BakeParams::error_samples`](crate::bake::BakeParams::error_samples) covered texels (vertices for vertex colours).
    pub appearance_error_mean: f64,
    /// 95th percentile of the same error, in 1/255.
    pub appearance_error_p95: f64,
    /// Maximum of the same error, in 1/255.
    pub appearance_error_max: f64,
    /// With [`BakeParams::evaluate`](crate::bake::BakeParams::evaluate): unlit PSNR (dB) of the level's render against the
    /// input's, mean over 24 views at the level's screen size, over pixels both cover
    /// ([`super::render`]).
    pub appearance_psnr_db: Option<f64>,
    /// With [`BakeParams::evaluate`](crate::bake::BakeParams::evaluate): the same PSNR for the level's geometry coloured by the
    /// input at the closest input point (a perfect bake's score; the bake loses
    /// `appearance_psnr_reference_db − appearance_psnr_db`).
    pub appearance_psnr_reference_db: Option<f64>,
    /// With [`BakeParams::evaluate`](crate::bake::BakeParams::evaluate): the unlit PSNR pooled over all views (one mean squared
    /// error over every pixel both renders cover), which a view sharing only a few pixels (a
    /// flat asset seen edge-on) cannot dominate as it can the mean over views.
    pub appearance_psnr_pooled_db: Option<f64>,
    /// With [`BakeParams::evaluate`](crate::bake::BakeParams::evaluate): the closest-point reference's pooled PSNR (the bake
    /// loses `appearance_psnr_reference_pooled_db − appearance_psnr_pooled_db` over all pixels).
    pub appearance_psnr_reference_pooled_db: Option<f64>,
    /// With [`BakeParams::evaluate`](crate::bake::BakeParams::evaluate) and a baked normal map: shaded PSNR with the normal map
    /// minus shaded PSNR without it, dB (> 0: the map brings the level closer to the input).
    pub normal_map_gain_db: Option<f64>,
    /// Seconds spent on the evaluation renders (not in `total_seconds`).
    pub evaluate_seconds: f64,
    /// For a `COLOR_0`-only input under [`VertexColors::Auto`](super::bake::VertexColors): the
    /// vertex-colour fit's mean surface error (1/255 sRGB, as `appearance_error_mean`) that
    /// [`BakeParams::vertex_colors`](super::bake::BakeParams::vertex_colors) compared with
    /// `vertex_fit_allowed_error`; `None` when no decision was made.
    pub vertex_fit_error: Option<f64>,
    /// The error the screen size allows at the same samples (see
    /// [`VertexColors::Auto`](super::bake::VertexColors::Auto)); a texture is baked when
    /// `vertex_fit_error` exceeds it.
    pub vertex_fit_allowed_error: Option<f64>,
}

/// An 8-bit RGBA image, row-major, row 0 at the top (glTF's v = 0).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image8 {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `4 · width · height` bytes, RGBA.
    pub rgba: Vec<u8>,
}

impl Image8 {
    /// The RGBA texel at column `i`, row `j`.
    pub fn texel(&self, i: u32, j: u32) -> [u8; 4] {
        let k = 4 * (j as usize * self.width as usize + i as usize);
        [
            self.rgba[k],
            self.rgba[k + 1],
            self.rgba[k + 2],
            self.rgba[k + 3],
        ]
    }
}

/// The material of a baked level (glTF metallic-roughness).
#[derive(Debug, Clone, PartialEq)]
pub struct BakedMaterial {
    /// baseColorFactor (linear).
    pub base_color_factor: [f64; 4],
    /// baseColorTexture (sRGB RGB, linear alpha).
    pub base_color: Option<Image8>,
    /// metallicFactor.
    pub metallic_factor: f64,
    /// roughnessFactor.
    pub roughness_factor: f64,
    /// metallicRoughnessTexture (G roughness, B metallic).
    pub metallic_roughness: Option<Image8>,
    /// occlusionTexture (R).
    pub occlusion: Option<Image8>,
    /// emissiveFactor (linear).
    pub emissive_factor: [f64; 3],
    /// emissiveTexture (sRGB).
    pub emissive: Option<Image8>,
    /// normalTexture (tangent space, MikkTSpace of the level's TANGENTs).
    pub normal: Option<Image8>,
    /// Alpha mode (of the input's first material).
    pub alpha_mode: AlphaMode,
    /// Alpha cutoff.
    pub alpha_cutoff: f64,
    /// Double-sided.
    pub double_sided: bool,
}

/// One baked LOD level: a mesh with normals, optional tangents, UVs and colours, and its
/// material.
#[derive(Debug, Clone, PartialEq)]
pub struct BakedLevel {
    /// Screen size `n_p` the level was made for.
    pub screen_size: f64,
    /// Vertex positions (split at chart seams and tangent discontinuities).
    pub positions: Vec<[f64; 3]>,
    /// Unit vertex normals.
    pub normals: Vec<[f32; 3]>,
    /// MikkTSpace tangents `(x, y, z, w)` when textured.
    pub tangents: Option<Vec<[f32; 4]>>,
    /// glTF texture coordinates (0 … 1) when textured.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Linear RGBA vertex colours (the untextured path).
    pub colors: Option<Vec<[f32; 4]>>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Material.
    pub material: BakedMaterial,
    /// Timing and error.
    pub report: BakeReport,
}
