//! Textured LODs from C: `pleat_lod_provenance`, `pleat_points_provenance`,
//! `pleat_bake_lod` and the `PleatBake` getters.
//!
//! An engine passes its own decoded data: the input as a `PleatMesh`, its UVs, optional
//! normals and vertex colours and RGBA8 images in a versioned [`PleatBakeMaterial`]; pleat
//! bakes them onto a LOD (`crate::bake::bake_level_with_progress`) and hands back an opaque
//! [`PleatBake`] whose mesh (atlas UVs split its vertices) and images are copied into caller
//! buffers. Every array is checked against the count it must hold, every image against
//! `PLEAT_BAKE_MAX_IMAGE_TEXELS` before it is read.
//!
//! The functions exist in every build; without the cargo feature `bake` they return
//! `PLEAT_STATUS_UNSUPPORTED`.

use super::boundary::{full_size, requires, versioned, Versioned};
use super::common::{PleatProgressFn, PleatStatus};
use super::mesh::PleatMesh;

/// `flags` output bit of the provenance calls: the point was found by the cast along its
/// normal (unset: the closest-point fallback).
pub const PLEAT_PROVENANCE_BY_RAY: u8 = 1;

/// `PleatBakeMaterial::uv_layout`: one UV per input vertex.
pub const PLEAT_UV_PER_VERTEX: u32 = 0;
/// `PleatBakeMaterial::uv_layout`: one UV per triangle corner (`3 t + k`).
pub const PLEAT_UV_PER_CORNER: u32 = 1;

/// `PleatBakeMaterial::wrap`: textures repeat (glTF's default).
pub const PLEAT_WRAP_REPEAT: u32 = 0;
/// `PleatBakeMaterial::wrap`: texture coordinates clamp to the edge texels.
pub const PLEAT_WRAP_CLAMP: u32 = 1;
/// `PleatBakeMaterial::wrap`: textures repeat mirrored.
pub const PLEAT_WRAP_MIRROR: u32 = 2;

/// Baked image: base colour (RGB sRGB-encoded, alpha linear).
pub const PLEAT_BAKE_IMAGE_BASE_COLOR: u32 = 0;
/// Baked image: metallic-roughness (G roughness, B metallic; glTF layout).
pub const PLEAT_BAKE_IMAGE_METALLIC_ROUGHNESS: u32 = 1;
/// Baked image: occlusion (R = G = B).
pub const PLEAT_BAKE_IMAGE_OCCLUSION: u32 = 2;
/// Baked image: emissive (sRGB-encoded).
pub const PLEAT_BAKE_IMAGE_EMISSIVE: u32 = 3;
/// Baked image: tangent-space normal map in the MikkTSpace frame of the bake's tangents.
pub const PLEAT_BAKE_IMAGE_NORMAL: u32 = 4;

/// `PleatBakeParams::vertex_colors`: a vertex-coloured input (colours, no image) gets vertex
/// colours when they are good enough for the screen size, else a base-colour texture (the rule
/// of `pleat::bake::VertexColors::Auto`). The default.
pub const PLEAT_VERTEX_COLORS_AUTO: u32 = 0;
/// `PleatBakeParams::vertex_colors`: always vertex colours.
pub const PLEAT_VERTEX_COLORS_VERTEX: u32 = 1;
/// `PleatBakeParams::vertex_colors`: always a base-colour texture.
pub const PLEAT_VERTEX_COLORS_TEXTURE: u32 = 2;

/// `PleatBakeStats::flags` bit: the bake is textured (UVs, tangents and images); unset, the
/// input had no texture and the bake holds vertex colours instead.
pub const PLEAT_BAKE_TEXTURED: u32 = 1;

/// Largest input image `pleat_bake_lod` reads, in texels (8192²); larger ones fail with
/// `PLEAT_STATUS_LIMIT_EXCEEDED`.
pub const PLEAT_BAKE_MAX_IMAGE_TEXELS: u64 = 1 << 26;

/// Most materials `pleat_bake_lod_multi` takes (65536).
pub const PLEAT_BAKE_MAX_MATERIALS: u32 = 1 << 16;

/// Largest `PleatBakeParams::texture_size`.
pub const PLEAT_BAKE_MAX_TEXTURE_SIZE: u32 = 8192;

/// Parameters of the provenance calls. Get the defaults from
/// `pleat_provenance_params_default()`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatProvenanceParams {
    /// `sizeof(PleatProvenanceParams)`.
    pub struct_size: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Screen size n_p the LOD was made for (default 200): the cast searches within
    /// `envelope_d · l / n_p` of the point along its normal (`l` the input's bounding-box
    /// diagonal). Finite and > 0.
    pub screen_size: f64,
    /// Envelope in units of `d = l / n_p` (default 3). Finite and > 0.
    pub envelope_d: f64,
    /// Envelope in model units; > 0 overrides `envelope_d` (default 0). Finite, >= 0.
    pub envelope: f64,
}

/// An RGBA8 image passed in by the caller: row-major, row 0 at the top (glTF's v = 0),
/// `4 · width · height` bytes. All zero (`rgba` NULL, size 0×0) means "no image".
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct PleatImage {
    /// The texels, or NULL for no image.
    pub rgba: *const u8,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// 1: the colour channels are sRGB-encoded (glTF: base colour and emissive); 0: linear
    /// (metallic-roughness, occlusion, normal maps).
    pub srgb: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// The input's appearance for `pleat_bake_lod`: one metallic-roughness material (glTF
/// semantics) over the whole input, its UV set, optional normals and vertex colours. Get the
/// defaults (glTF's default material, no texture) from `pleat_bake_material_default()`.
///
/// Pointers are borrowed for the call only. Counts follow the input mesh: `normals` holds
/// `3 · vertex_count` floats, `colors` `4 · vertex_count`, `uvs` `2 · uv_count` where
/// `uv_count` is the vertex count (`PLEAT_UV_PER_VERTEX`) or `3 · triangle_count`
/// (`PLEAT_UV_PER_CORNER`).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct PleatBakeMaterial {
    /// `sizeof(PleatBakeMaterial)`.
    pub struct_size: u32,
    /// `PLEAT_UV_PER_VERTEX` or `PLEAT_UV_PER_CORNER`.
    pub uv_layout: u32,
    /// UVs (u, v pairs), or NULL when no image is given.
    pub uvs: *const f32,
    /// Number of UV pairs at `uvs` (0 with NULL).
    pub uv_count: usize,
    /// Per-vertex shading normals (xyz), or NULL for area-weighted vertex normals.
    pub normals: *const f32,
    /// Per-vertex linear RGBA colours multiplying the base colour, or NULL.
    pub colors: *const f32,
    /// Base colour factor, linear RGBA (default 1, 1, 1, 1).
    pub base_color_factor: [f64; 4],
    /// Base colour image (usually `srgb = 1`).
    pub base_color: PleatImage,
    /// Metallic factor (default 1).
    pub metallic_factor: f64,
    /// Roughness factor (default 1).
    pub roughness_factor: f64,
    /// Metallic-roughness image (G roughness, B metallic).
    pub metallic_roughness: PleatImage,
    /// Tangent-space normal map (glTF convention).
    pub normal: PleatImage,
    /// Normal scale (default 1).
    pub normal_scale: f64,
    /// Occlusion image (R).
    pub occlusion: PleatImage,
    /// Occlusion strength (default 1).
    pub occlusion_strength: f64,
    /// Emissive factor, linear RGB (default 0).
    pub emissive_factor: [f64; 3],
    /// Emissive image (usually `srgb = 1`).
    pub emissive: PleatImage,
    /// `PLEAT_WRAP_*` for every image, both axes (default `PLEAT_WRAP_REPEAT`).
    pub wrap: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// Parameters of `pleat_bake_lod`. Get the defaults from `pleat_bake_params_default()`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatBakeParams {
    /// `sizeof(PleatBakeParams)`.
    pub struct_size: u32,
    /// Side of the square textures in texels, or 0 (default) for the screen-size rule
    /// (`texels_per_pixel · n_p / l` texels per unit length, power of two in 32 … 4096).
    /// At most `PLEAT_BAKE_MAX_TEXTURE_SIZE`.
    pub texture_size: u32,
    /// Screen size n_p the LOD was made for (default 200). Finite and > 0.
    pub screen_size: f64,
    /// Gutter between charts in texels (default 8: `2^(m+1)` for the deepest mip `m = 2`
    /// a ×2 chain reads at 2 texels per pixel), at most 64.
    pub padding: u32,
    /// Worker threads for this call: 0 (default) = the pool of `pleat_set_thread_count`.
    /// At most 256. The output bytes do not depend on it.
    pub threads: u32,
    /// Texels per screen pixel of the size rule (default 2). Finite and > 0.
    pub texels_per_pixel: f64,
    /// Provenance envelope in units of d = l / n_p (default 3). Finite and > 0.
    pub envelope_d: f64,
    /// 1 (default): bake a tangent-space normal map; 0: none.
    pub normal_map: u32,
    /// Texels compared with the input for the appearance error (default 20000; 0 skips it).
    pub error_samples: u32,
    /// How an input with vertex colours and no image is baked: `PLEAT_VERTEX_COLORS_AUTO`
    /// (default), `PLEAT_VERTEX_COLORS_VERTEX` or `PLEAT_VERTEX_COLORS_TEXTURE`. Never both in
    /// one result (glTF multiplies vertex colours into the base colour). Appended in v2.
    pub vertex_colors: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// Statistics of a bake. Set `struct_size` to `sizeof(PleatBakeStats)`; pleat fills that many
/// bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatBakeStats {
    /// In: `sizeof(PleatBakeStats)` as the caller knows it. Out: the bytes pleat filled.
    pub struct_size: u32,
    /// `PLEAT_BAKE_TEXTURED` when textured.
    pub flags: u32,
    /// Side of the square textures (0 for vertex colours).
    pub texture_size: u32,
    /// Charts of the atlas.
    pub charts: u32,
    /// Texels covered by charts.
    pub texels_covered: u64,
    /// Texel centres where two atlas triangles overlap (0 for a valid atlas).
    pub overlapping_texels: u64,
    /// Vertices of the baked mesh.
    pub vertex_count: u64,
    /// Triangles of the baked mesh.
    pub triangle_count: u64,
    /// Wall seconds of the whole bake.
    pub seconds_total: f64,
    /// Wall seconds of the UV atlas.
    pub seconds_atlas: f64,
    /// Wall seconds of the MikkTSpace tangents.
    pub seconds_tangents: f64,
    /// Wall seconds of the atlas rasterisation.
    pub seconds_rasterise: f64,
    /// Wall seconds of provenance and material sampling.
    pub seconds_sample: f64,
    /// Wall seconds of the dilation into gutters.
    pub seconds_dilate: f64,
    /// Wall seconds of the appearance-error measurement.
    pub seconds_measure: f64,
    /// Fraction of samples found by the closest-point fallback, in [0, 1].
    pub fallback_fraction: f64,
    /// Mean appearance error (baked vs input base colour at the closest input point, max over
    /// RGB, sRGB units of 1/255).
    pub appearance_error_mean: f64,
    /// 95th percentile of the same error.
    pub appearance_error_p95: f64,
    /// Maximum of the same error.
    pub appearance_error_max: f64,
    /// Gutter between charts in texels as used: the requested padding, or less when the
    /// charts could not be packed with it (then seams hold to a shallower mip); 0 for vertex
    /// colours. Appended 2026-11-27 (older, shorter structs are still accepted).
    pub atlas_padding: u32,
    /// The deepest mip level (up to the texel rule's, 2 by default) whose bilinear reads stay
    /// inside each chart's own texels by construction; −1 for vertex colours or when even
    /// mip 0 mixes charts. Appended 2026-11-27.
    pub seam_clean_mip: i32,
}

/// A baked LOD (opaque): the mesh with atlas UVs, normals, tangents and the baked images, or
/// vertex colours for an untextured input. Made by `pleat_bake_lod`, freed by
/// `pleat_bake_free`; immutable, so it may be read from several threads at once.
pub struct PleatBake {
    #[cfg(feature = "bake")]
    pub(crate) level: crate::bake::BakedLevel,
}

/// The provenance defaults (n_p = 200, envelope 3 d), with `struct_size` set.
#[no_mangle]
pub extern "C" fn pleat_provenance_params_default() -> PleatProvenanceParams {
    PleatProvenanceParams {
        struct_size: full_size::<PleatProvenanceParams>(),
        reserved: 0,
        screen_size: 200.0,
        envelope_d: 3.0,
        envelope: 0.0,
    }
}

/// No image: NULL texels, 0×0.
const NO_IMAGE: PleatImage = PleatImage {
    rgba: std::ptr::null(),
    width: 0,
    height: 0,
    srgb: 0,
    reserved: 0,
};

/// glTF's default material with no texture and no UVs, with `struct_size` set.
#[no_mangle]
pub extern "C" fn pleat_bake_material_default() -> PleatBakeMaterial {
    PleatBakeMaterial {
        struct_size: full_size::<PleatBakeMaterial>(),
        uv_layout: PLEAT_UV_PER_VERTEX,
        uvs: std::ptr::null(),
        uv_count: 0,
        normals: std::ptr::null(),
        colors: std::ptr::null(),
        base_color_factor: [1.0; 4],
        base_color: PleatImage {
            srgb: 1,
            ..NO_IMAGE
        },
        metallic_factor: 1.0,
        roughness_factor: 1.0,
        metallic_roughness: NO_IMAGE,
        normal: NO_IMAGE,
        normal_scale: 1.0,
        occlusion: NO_IMAGE,
        occlusion_strength: 1.0,
        emissive_factor: [0.0; 3],
        emissive: PleatImage {
            srgb: 1,
            ..NO_IMAGE
        },
        wrap: PLEAT_WRAP_REPEAT,
        reserved: 0,
    }
}

/// The bake defaults (`crate::bake::BakeParams::default()`, n_p = 200), with `struct_size`
/// set.
#[no_mangle]
pub extern "C" fn pleat_bake_params_default() -> PleatBakeParams {
    PleatBakeParams {
        struct_size: full_size::<PleatBakeParams>(),
        texture_size: 0,
        screen_size: 200.0,
        // `bake::atlas::gutter_for_mip(deepest_mip(2.0))` (the defaults test checks it).
        padding: 8,
        threads: 0,
        texels_per_pixel: 2.0,
        envelope_d: 3.0,
        normal_map: 1,
        error_samples: 20_000,
        vertex_colors: PLEAT_VERTEX_COLORS_AUTO,
        reserved: 0,
    }
}

versioned!(PleatProvenanceParams, 32, pleat_provenance_params_default);
versioned!(PleatBakeParams, 48, pleat_bake_params_default);
versioned!(PleatBakeStats, 8);

// SAFETY: repr(C), leading `struct_size: u32`; its fields are integers, reals, arrays of them
// and raw pointers, for all of which every bit pattern is a valid value.
unsafe impl Versioned for PleatBakeMaterial {
    const NAME: &'static str = "PleatBakeMaterial";
    const MIN_SIZE: u32 = std::mem::size_of::<PleatBakeMaterial>() as u32;
}

impl super::boundary::VersionedParams for PleatBakeMaterial {
    const DEFAULT_FN: &'static str = "pleat_bake_material_default";
    fn defaults() -> Self {
        pleat_bake_material_default()
    }
}

#[cfg(feature = "bake")]
pub(super) mod imp {
    use super::*;
    use crate::bake::appearance::{Wrap, MAX_TEXTURE_TEXELS};
    use crate::bake::{
        AppearanceBuffers, AtlasParams, BakeParams, BakedLevel, BufferMaterial, ImageBuffer,
        InputIndex, Provenance, ProvenanceParams, UvBuffer, VertexColors,
    };
    use crate::ffi::boundary::{arg_slice, bool_field, check_f64, check_range, finite_slice};
    use crate::mesh::TriMesh;
    use crate::{Error, Result};

    const _: () = assert!(PLEAT_BAKE_MAX_IMAGE_TEXELS == MAX_TEXTURE_TEXELS);

    /// The Rust provenance parameters for `input` (checked).
    pub(in crate::ffi) fn provenance_params(
        p: &PleatProvenanceParams,
        input: &TriMesh,
    ) -> Result<ProvenanceParams> {
        check_f64(
            p.screen_size,
            p.screen_size.is_finite() && p.screen_size > 0.0,
            "params->screen_size",
            "finite and > 0",
        )?;
        check_f64(
            p.envelope_d,
            p.envelope_d.is_finite() && p.envelope_d > 0.0,
            "params->envelope_d",
            "finite and > 0",
        )?;
        check_f64(
            p.envelope,
            p.envelope.is_finite() && p.envelope >= 0.0,
            "params->envelope",
            "finite and >= 0",
        )?;
        let envelope = if p.envelope > 0.0 {
            p.envelope
        } else {
            p.envelope_d * input.bbox_diagonal() / p.screen_size
        };
        Ok(ProvenanceParams { envelope })
    }

    /// Caller output arrays of the provenance calls, checked against `n` points before the
    /// work: `tri` (n), `bary` (3 n), optional `flags` (n).
    pub(in crate::ffi) struct ProvenanceOut {
        tri: *mut u32,
        bary: *mut f64,
        flags: *mut u8,
    }

    /// Checks one caller array: non-NULL (unless `optional`) and `capacity >= need`.
    fn capacity(
        p: *const std::ffi::c_void,
        capacity: usize,
        need: usize,
        name: &str,
        optional: bool,
    ) -> Result<()> {
        if p.is_null() {
            if optional {
                return Ok(());
            }
            return Err(crate::ffi::common::null_arg(name));
        }
        if capacity < need {
            return Err(Error::LimitExceeded(format!(
                "{name} holds {capacity} values; {need} are needed"
            )));
        }
        Ok(())
    }

    impl ProvenanceOut {
        /// Checks the three outputs for `n` points.
        #[allow(clippy::too_many_arguments)]
        pub(in crate::ffi) fn new(
            n: usize,
            tri: *mut u32,
            tri_capacity: usize,
            bary: *mut f64,
            bary_capacity: usize,
            flags: *mut u8,
            flags_capacity: usize,
        ) -> Result<Self> {
            let three = n
                .checked_mul(3)
                .ok_or_else(|| Error::InvalidArgument(format!("{n} points overflow")))?;
            capacity(tri.cast(), tri_capacity, n, "tri", false)?;
            capacity(bary.cast(), bary_capacity, three, "bary", false)?;
            capacity(flags.cast(), flags_capacity, n, "flags", true)?;
            Ok(ProvenanceOut { tri, bary, flags })
        }

        /// Writes the results (after all the fallible work).
        ///
        /// # Safety
        /// The arrays hold the capacities checked by [`ProvenanceOut::new`] for `found.len()`.
        pub(in crate::ffi) unsafe fn write(&self, found: &[Provenance]) {
            for (i, p) in found.iter().enumerate() {
                *self.tri.add(i) = p.triangle;
                for k in 0..3 {
                    *self.bary.add(3 * i + k) = p.bary[k];
                }
                if !self.flags.is_null() {
                    *self.flags.add(i) = if p.by_ray { PLEAT_PROVENANCE_BY_RAY } else { 0 };
                }
            }
        }
    }

    /// Reads `n` xyz triples from `p` (checked finite, named `name`).
    ///
    /// # Safety
    /// `p` is NULL or valid for `3 n` doubles.
    pub(in crate::ffi) unsafe fn xyz(p: *const f64, n: usize, name: &str) -> Result<Vec<[f64; 3]>> {
        let three = n
            .checked_mul(3)
            .ok_or_else(|| Error::InvalidArgument(format!("`{name}` cannot hold {n} points")))?;
        let s = arg_slice(p, three, name)?;
        finite_slice(s, name)?;
        Ok(s.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }

    /// The Rust bake parameters (checked) and the screen size.
    pub(in crate::ffi) fn bake_params(p: &PleatBakeParams) -> Result<(BakeParams, f64)> {
        if p.texture_size != 0 {
            check_range(
                p.texture_size,
                1,
                PLEAT_BAKE_MAX_TEXTURE_SIZE,
                "params->texture_size",
            )?;
        }
        check_range(p.padding, 0, 64, "params->padding")?;
        check_range(p.threads, 0, 256, "params->threads")?;
        check_f64(
            p.screen_size,
            p.screen_size.is_finite() && p.screen_size > 0.0,
            "params->screen_size",
            "finite and > 0",
        )?;
        check_f64(
            p.texels_per_pixel,
            p.texels_per_pixel.is_finite() && p.texels_per_pixel > 0.0,
            "params->texels_per_pixel",
            "finite and > 0",
        )?;
        check_f64(
            p.envelope_d,
            p.envelope_d.is_finite() && p.envelope_d > 0.0,
            "params->envelope_d",
            "finite and > 0",
        )?;
        let normal_map = bool_field(p.normal_map, "params->normal_map")?;
        let vertex_colors = match p.vertex_colors {
            PLEAT_VERTEX_COLORS_AUTO => VertexColors::Auto,
            PLEAT_VERTEX_COLORS_VERTEX => VertexColors::Vertex,
            PLEAT_VERTEX_COLORS_TEXTURE => VertexColors::Texture,
            v => {
                return Err(Error::InvalidArgument(format!(
                    "params->vertex_colors must be PLEAT_VERTEX_COLORS_AUTO (0), _VERTEX (1) or \
                     _TEXTURE (2), got {v}"
                )))
            }
        };
        let params = BakeParams {
            atlas: AtlasParams {
                size: (p.texture_size != 0).then_some(p.texture_size),
                texels_per_pixel: p.texels_per_pixel,
                padding: p.padding,
                ..AtlasParams::default()
            },
            envelope_d: p.envelope_d,
            normal_map,
            error_samples: p.error_samples as usize,
            evaluate: false,
            vertex_colors,
        };
        Ok((params, p.screen_size))
    }

    /// One caller image (`None` when all zero), its size checked against the pixel budget
    /// before its bytes are borrowed.
    ///
    /// # Safety
    /// `img.rgba` is NULL or valid for `4 · width · height` bytes.
    unsafe fn image<'a>(img: &PleatImage, name: &str) -> Result<Option<ImageBuffer<'a>>> {
        if img.rgba.is_null() {
            if img.width != 0 || img.height != 0 {
                return Err(Error::InvalidArgument(format!(
                    "{name}.rgba is NULL but its size is {}×{} (set width = height = 0 for no \
                     image)",
                    img.width, img.height
                )));
            }
            return Ok(None);
        }
        let texels = u64::from(img.width) * u64::from(img.height);
        if texels == 0 {
            return Err(Error::InvalidArgument(format!(
                "{name} has zero size ({}×{})",
                img.width, img.height
            )));
        }
        if texels > PLEAT_BAKE_MAX_IMAGE_TEXELS {
            return Err(Error::LimitExceeded(format!(
                "{name} of {}×{} texels exceeds the budget of \
                 {PLEAT_BAKE_MAX_IMAGE_TEXELS} texels",
                img.width, img.height
            )));
        }
        let srgb = bool_field(img.srgb, &format!("{name}.srgb"))?;
        let rgba = arg_slice(img.rgba, 4 * texels as usize, &format!("{name}.rgba"))?;
        Ok(Some(ImageBuffer {
            width: img.width,
            height: img.height,
            rgba,
            srgb,
        }))
    }

    /// `n` tuples of `K` floats at `p` as doubles, checked finite (`name[i]` in the message).
    ///
    /// # Safety
    /// `p` is NULL or valid for `K n` floats.
    unsafe fn tuples<const K: usize>(p: *const f32, n: usize, name: &str) -> Result<Vec<[f64; K]>> {
        let len = n
            .checked_mul(K)
            .ok_or_else(|| Error::InvalidArgument(format!("`{name}` cannot hold {n} values")))?;
        let s = arg_slice(p, len, name)?;
        let out: Vec<[f64; K]> = s
            .chunks_exact(K)
            .map(|c| std::array::from_fn(|k| f64::from(c[k])))
            .collect();
        if let Some(i) = out.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(Error::InvalidArgument(format!(
                "{name}[{i}] is not finite (NaN or infinite)"
            )));
        }
        Ok(out)
    }

    const MAX_MATERIALS: usize = PLEAT_BAKE_MAX_MATERIALS as usize;

    /// The caller's arrays of a material, owned (the `AppearanceBuffers` borrow them).
    pub(in crate::ffi) struct MaterialArrays {
        uvs: Option<Vec<[f64; 2]>>,
        normals: Option<Vec<[f64; 3]>>,
        colors: Option<Vec<[f64; 4]>>,
    }

    /// Reads and checks the arrays of `m` for `input`.
    ///
    /// # Safety
    /// The pointers of `m` are NULL or valid for the counts documented on
    /// [`PleatBakeMaterial`].
    pub(in crate::ffi) unsafe fn material_arrays(
        m: &PleatBakeMaterial,
        input: &TriMesh,
    ) -> Result<MaterialArrays> {
        if m.uv_layout > PLEAT_UV_PER_CORNER {
            return Err(Error::InvalidArgument(format!(
                "material->uv_layout is {}; use PLEAT_UV_PER_VERTEX (0) or PLEAT_UV_PER_CORNER \
                 (1)",
                m.uv_layout
            )));
        }
        let nv = input.vertex_count();
        let uvs = if m.uvs.is_null() && m.uv_count == 0 {
            None
        } else {
            let want = if m.uv_layout == PLEAT_UV_PER_CORNER {
                3 * input.triangle_count()
            } else {
                nv
            };
            if m.uv_count != want {
                return Err(Error::InvalidArgument(format!(
                    "material->uv_count is {}; the input needs {want} (one per {})",
                    m.uv_count,
                    if m.uv_layout == PLEAT_UV_PER_CORNER {
                        "triangle corner"
                    } else {
                        "vertex"
                    }
                )));
            }
            Some(tuples::<2>(m.uvs, want, "material->uvs")?)
        };
        let normals = (!m.normals.is_null())
            .then(|| tuples::<3>(m.normals, nv, "material->normals"))
            .transpose()?;
        let colors = (!m.colors.is_null())
            .then(|| tuples::<4>(m.colors, nv, "material->colors"))
            .transpose()?;
        Ok(MaterialArrays {
            uvs,
            normals,
            colors,
        })
    }

    /// The factors and images of `m` (`name` prefixes field names in messages:
    /// `material->` or `materials[i].`).
    ///
    /// # Safety
    /// `m`'s images are NULL or hold `4 · width · height` bytes.
    unsafe fn buffer_material<'a>(m: &PleatBakeMaterial, name: &str) -> Result<BufferMaterial<'a>> {
        let wrap = match m.wrap {
            PLEAT_WRAP_REPEAT => Wrap::Repeat,
            PLEAT_WRAP_CLAMP => Wrap::Clamp,
            PLEAT_WRAP_MIRROR => Wrap::Mirror,
            w => {
                return Err(Error::InvalidArgument(format!(
                    "{name}wrap is {w}; use a PLEAT_WRAP_* value (0 to 2)"
                )))
            }
        };
        let img = |i: &PleatImage, field: &str| image(i, &format!("{name}{field}"));
        Ok(BufferMaterial {
            base_color_factor: m.base_color_factor,
            base_color: img(&m.base_color, "base_color")?,
            metallic_factor: m.metallic_factor,
            roughness_factor: m.roughness_factor,
            metallic_roughness: img(&m.metallic_roughness, "metallic_roughness")?,
            normal: img(&m.normal, "normal")?,
            normal_scale: m.normal_scale,
            occlusion: img(&m.occlusion, "occlusion")?,
            occlusion_strength: m.occlusion_strength,
            emissive_factor: m.emissive_factor,
            emissive: img(&m.emissive, "emissive")?,
            wrap,
        })
    }

    /// The appearance buffers of `m` over `input` with the arrays `a`.
    ///
    /// # Safety
    /// As [`material_arrays`], for the images.
    pub(in crate::ffi) unsafe fn appearance_buffers<'a>(
        m: &PleatBakeMaterial,
        input: &'a TriMesh,
        a: &'a MaterialArrays,
    ) -> Result<AppearanceBuffers<'a>> {
        let material = buffer_material(m, "material->")?;
        let uvs = a.uvs.as_deref().map(|uv| {
            if m.uv_layout == PLEAT_UV_PER_CORNER {
                UvBuffer::PerCorner(uv)
            } else {
                UvBuffer::PerVertex(uv)
            }
        });
        Ok(AppearanceBuffers {
            mesh: input,
            uvs,
            normals: a.normals.as_deref(),
            colors: a.colors.as_deref(),
            material,
        })
    }

    /// Reads the caller's array of `count` materials: the stride is `materials[0].struct_size`
    /// (every element must carry the same), each read like a single versioned struct.
    ///
    /// # Safety
    /// `p` is NULL or holds `count` structs of `p->struct_size` bytes each.
    pub(in crate::ffi) unsafe fn material_array(
        p: *const PleatBakeMaterial,
        count: usize,
    ) -> Result<Vec<PleatBakeMaterial>> {
        if p.is_null() {
            return Err(crate::ffi::common::null_arg("materials"));
        }
        if count == 0 || count > MAX_MATERIALS {
            return Err(Error::InvalidArgument(format!(
                "material_count is {count}; it must be in 1..={MAX_MATERIALS}"
            )));
        }
        let first = read_versioned(p, "materials[0]")?;
        let stride = std::ptr::read_unaligned(p as *const u32) as usize;
        (0..count)
            .map(|i| {
                let q = (p as *const u8).add(i * stride) as *const PleatBakeMaterial;
                let size = std::ptr::read_unaligned(q as *const u32) as usize;
                if size != stride {
                    return Err(Error::InvalidArgument(format!(
                        "materials[{i}].struct_size is {size} but materials[0]'s is {stride}: \
                         every element of the array needs the same sizeof(PleatBakeMaterial)"
                    )));
                }
                let m = if i == 0 {
                    first
                } else {
                    read_versioned(q, &format!("materials[{i}]"))?
                };
                if i > 0
                    && (!m.uvs.is_null()
                        || m.uv_count != 0
                        || !m.normals.is_null()
                        || !m.colors.is_null())
                {
                    return Err(Error::InvalidArgument(format!(
                        "materials[{i}] sets uvs, uv_count, normals or colors: the mesh's \
                         arrays come from materials[0] only (leave them NULL/0 in the others)"
                    )));
                }
                Ok(m)
            })
            .collect()
    }

    /// The input's appearance from the caller's materials (`materials[0]` holds the mesh
    /// arrays) and the material of every triangle (`None`: all material 0).
    ///
    /// # Safety
    /// As [`material_arrays`] and [`buffer_material`] for every material.
    pub(in crate::ffi) unsafe fn appearance(
        materials: &[PleatBakeMaterial],
        triangle_material: Option<&[u32]>,
        input: &TriMesh,
    ) -> Result<crate::bake::Appearance> {
        let arrays = material_arrays(&materials[0], input)?;
        let buffers = appearance_buffers(&materials[0], input, &arrays)?;
        let Some(tm) = triangle_material else {
            return crate::bake::Appearance::from_buffers(&buffers);
        };
        let converted = materials
            .iter()
            .enumerate()
            .map(|(i, m)| buffer_material(m, &format!("materials[{i}].")))
            .collect::<Result<Vec<_>>>()?;
        crate::bake::Appearance::from_buffers_multi(&buffers, &converted, tm)
    }

    /// Bakes `app` onto `lod`.
    pub(in crate::ffi) fn bake(
        lod: &TriMesh,
        app: &crate::bake::Appearance,
        params: &BakeParams,
        screen_size: f64,
        prog: &mut crate::report::ProgressFn<'_>,
    ) -> Result<BakedLevel> {
        let index = InputIndex::new(&app.mesh);
        crate::bake::bake_level_with_progress(app, &index, lod, screen_size, params, prog)
    }

    /// The C stats of a baked level.
    pub(in crate::ffi) fn stats(l: &BakedLevel) -> PleatBakeStats {
        let r = &l.report;
        PleatBakeStats {
            struct_size: full_size::<PleatBakeStats>(),
            flags: if l.uvs.is_some() {
                PLEAT_BAKE_TEXTURED
            } else {
                0
            },
            texture_size: r.texture_size,
            charts: r.charts,
            texels_covered: r.texels_covered,
            overlapping_texels: r.overlapping_texels,
            vertex_count: l.positions.len() as u64,
            triangle_count: l.triangles.len() as u64,
            seconds_total: r.total_seconds,
            seconds_atlas: r.atlas_seconds,
            seconds_tangents: r.tangent_seconds,
            seconds_rasterise: r.raster_seconds,
            seconds_sample: r.sample_seconds,
            seconds_dilate: r.dilate_seconds,
            seconds_measure: r.measure_seconds,
            fallback_fraction: r.fallback_fraction,
            appearance_error_mean: r.appearance_error_mean,
            appearance_error_p95: r.appearance_error_p95,
            appearance_error_max: r.appearance_error_max,
            atlas_padding: r.atlas_padding,
            seam_clean_mip: r
                .seam_clean_mip
                .map_or(-1, |m| i32::try_from(m).unwrap_or(i32::MAX)),
        }
    }

    /// The baked image `which` (`Ok(None)` when this bake has none).
    pub(in crate::ffi) fn image_of(
        l: &BakedLevel,
        which: u32,
    ) -> Result<Option<&crate::bake::Image8>> {
        let m = &l.material;
        Ok(match which {
            PLEAT_BAKE_IMAGE_BASE_COLOR => m.base_color.as_ref(),
            PLEAT_BAKE_IMAGE_METALLIC_ROUGHNESS => m.metallic_roughness.as_ref(),
            PLEAT_BAKE_IMAGE_OCCLUSION => m.occlusion.as_ref(),
            PLEAT_BAKE_IMAGE_EMISSIVE => m.emissive.as_ref(),
            PLEAT_BAKE_IMAGE_NORMAL => m.normal.as_ref(),
            w => {
                return Err(Error::InvalidArgument(format!(
                    "which is {w}; use a PLEAT_BAKE_IMAGE_* value (0 to 4)"
                )))
            }
        })
    }

    /// Copies `src` (tuples of `K` scalars) into the caller's `dst` holding `capacity`
    /// tuples; `what` names the attribute when the bake has none.
    ///
    /// # Safety
    /// `dst` is NULL or valid for `K · capacity` values.
    pub(in crate::ffi) unsafe fn copy_tuples<T: Copy, U: Copy, const K: usize>(
        src: Option<&[[T; K]]>,
        dst: *mut U,
        capacity: usize,
        what: &str,
        conv: impl Fn(T) -> U,
    ) -> Result<()> {
        let src = src.ok_or_else(|| {
            Error::InvalidArgument(format!(
                "this bake has no {what} (the input had no texture: see PLEAT_BAKE_TEXTURED)"
            ))
        })?;
        if dst.is_null() {
            return Err(crate::ffi::common::null_arg("dst"));
        }
        if capacity < src.len() {
            return Err(Error::LimitExceeded(format!(
                "dst holds {capacity} {what}; the bake has {}",
                src.len()
            )));
        }
        let out = std::slice::from_raw_parts_mut(dst, K * src.len());
        for (o, v) in out.chunks_exact_mut(K).zip(src) {
            for k in 0..K {
                o[k] = conv(v[k]);
            }
        }
        Ok(())
    }
}

/// A count from a live bake handle (0 for NULL, a panic or a build without `bake`).
macro_rules! bake_count {
    ($h:expr, |$b:ident| $e:expr) => {{
        #[cfg(feature = "bake")]
        {
            guard_value(0, || $h.as_ref().map_or(0, |$b: &PleatBake| $e))
        }
        #[cfg(not(feature = "bake"))]
        {
            let _ = $h;
            0
        }
    }};
}

#[cfg(feature = "bake")]
use super::boundary::{arg_out, arg_ref, read_versioned, versioned_out};
#[cfg(feature = "bake")]
use super::common::{c_str_arg, guard, guard_progress_threads, guard_value};
#[cfg(feature = "bake")]
use super::mesh::mesh_ref;
#[cfg(feature = "bake")]
use crate::Error;

/// Provenance of every vertex of a LOD on the input: for LOD vertex `i`, the input triangle
/// `tri[i]` and barycentric coordinates `bary[3i .. 3i+3]` (non-negative, summing to 1) of the
/// input point it stands for, found by casting along the LOD's area-weighted vertex normal
/// within the envelope, else the closest input point (`flags[i]` tells which:
/// `PLEAT_PROVENANCE_BY_RAY`). An engine transfers any attribute of its own with these.
///
/// - `lod`, `input`: mesh handles (the LOD from `pleat_lod_generate*`, the input it was made
///   from); non-NULL.
/// - `params`: NULL for the defaults, else set the screen size the LOD was made for.
/// - `tri` (`tri_capacity` values), `bary` (`bary_capacity` values): non-NULL, holding at
///   least `n` and `3 n` values (`n` = LOD vertex count), else `PLEAT_STATUS_LIMIT_EXCEEDED`.
/// - `flags`: NULL, or `flags_capacity >= n` bytes.
///
/// Deterministic, whatever the thread count. Nothing is written on failure.
///
/// # Safety
/// Handles are NULL or live; arrays are NULL or hold their stated capacities.
#[no_mangle]
pub unsafe extern "C" fn pleat_lod_provenance(
    lod: *const PleatMesh,
    input: *const PleatMesh,
    params: *const PleatProvenanceParams,
    tri: *mut u32,
    tri_capacity: usize,
    bary: *mut f64,
    bary_capacity: usize,
    flags: *mut u8,
    flags_capacity: usize,
) -> PleatStatus {
    requires!(
        "bake",
        [
            lod,
            input,
            params,
            tri,
            tri_capacity,
            bary,
            bary_capacity,
            flags,
            flags_capacity
        ],
        {
            guard(|| {
                let lod = mesh_ref(lod, "lod")?;
                let input = mesh_ref(input, "input")?;
                let p = read_versioned(params, "params")?;
                let prov = imp::provenance_params(&p, input)?;
                let out = imp::ProvenanceOut::new(
                    lod.vertex_count(),
                    tri,
                    tri_capacity,
                    bary,
                    bary_capacity,
                    flags,
                    flags_capacity,
                )?;
                let found = crate::bake::provenance(lod, input, &prov);
                out.write(&found);
                Ok(())
            })
        }
    )
}

/// Provenance of arbitrary points on the input (e.g. an engine's own vertices or samples):
/// as `pleat_lod_provenance` for `count` points `points[3i .. 3i+3]` cast along
/// `normals[3i .. 3i+3]` (need not be unit; a zero normal, or `normals` NULL, takes the
/// closest input point).
///
/// # Safety
/// `input` is NULL or live; `points` (and `normals`) are NULL or hold `3 count` doubles; the
/// outputs as in `pleat_lod_provenance` with `n = count`.
#[no_mangle]
pub unsafe extern "C" fn pleat_points_provenance(
    input: *const PleatMesh,
    points: *const f64,
    normals: *const f64,
    count: usize,
    params: *const PleatProvenanceParams,
    tri: *mut u32,
    tri_capacity: usize,
    bary: *mut f64,
    bary_capacity: usize,
    flags: *mut u8,
    flags_capacity: usize,
) -> PleatStatus {
    requires!(
        "bake",
        [
            input,
            points,
            normals,
            count,
            params,
            tri,
            tri_capacity,
            bary,
            bary_capacity,
            flags,
            flags_capacity
        ],
        {
            guard(|| {
                let input = mesh_ref(input, "input")?;
                let p = read_versioned(params, "params")?;
                let prov = imp::provenance_params(&p, input)?;
                let pts = imp::xyz(points, count, "points")?;
                let nrm = if normals.is_null() {
                    vec![[0.0; 3]; count]
                } else {
                    imp::xyz(normals, count, "normals")?
                };
                let out = imp::ProvenanceOut::new(
                    count,
                    tri,
                    tri_capacity,
                    bary,
                    bary_capacity,
                    flags,
                    flags_capacity,
                )?;
                let found = crate::bake::InputIndex::new(input).query_all(&pts, &nrm, &prov);
                out.write(&found);
                Ok(())
            })
        }
    )
}

/// Bakes the input's appearance onto a LOD: a UV atlas for the LOD (xatlas; texel density
/// from the screen size unless `params->texture_size` is set), every texel sampled at its
/// provenance on the input (base colour sRGB-correct with alpha, metallic-roughness,
/// occlusion, emissive when the input has them), a tangent-space normal map in the LOD's
/// MikkTSpace frame, charts dilated into their gutters. Without any image the LOD gets
/// vertex colours instead (no UVs). Output bytes do not depend on the thread count.
///
/// - `lod`: the LOD mesh; `input`: the mesh it was made from (vertex order as the material's
///   per-vertex arrays); both non-NULL.
/// - `material`: the input's appearance (see `PleatBakeMaterial`); non-NULL.
/// - `params`: NULL for the defaults (n_p = 200).
/// - `progress`, `user_data`: progress and cancel callback (may be NULL); stages
///   `bake: atlas`, `bake: tangents`, `bake: rasterise`, `bake: texels` (every few thousand
///   texels: cancel is honoured within about 10 ms of work), `bake: dilation`,
///   `bake: measure`. Cancelling returns `PLEAT_STATUS_CANCELLED`.
/// - `out`: receives the new `PleatBake` (free with `pleat_bake_free`); non-NULL.
/// - `stats`: NULL, or filled up to its `struct_size`.
///
/// # Safety
/// Handles are NULL or live; `material`'s pointers hold the counts it documents.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_lod(
    lod: *const PleatMesh,
    input: *const PleatMesh,
    material: *const PleatBakeMaterial,
    params: *const PleatBakeParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatBake,
    stats: *mut PleatBakeStats,
) -> PleatStatus {
    requires!(
        "bake",
        [lod, input, material, params, progress, user_data, out, stats],
        {
            // The thread count is needed before the fence (it picks the pool); an invalid
            // struct is reported from inside.
            guard_progress_threads(params_threads(params), progress, user_data, |prog| {
                let lod = mesh_ref(lod, "lod")?;
                let input = mesh_ref(input, "input")?;
                if material.is_null() {
                    return Err(crate::ffi::common::null_arg("material"));
                }
                let m = read_versioned(material, "material")?;
                let p = read_versioned(params, "params")?;
                let out = arg_out(out, "out")?;
                let stats = versioned_out(stats, "stats")?;
                bake_checked(lod, input, &[m], None, &p, prog, out, stats)
            })
        }
    )
}

/// The thread count of `params` (0, the global pool, when it is NULL, invalid or out of
/// range: the error is reported from inside the guard).
///
/// # Safety
/// `params` is NULL or readable for its `struct_size`.
#[cfg(feature = "bake")]
unsafe fn params_threads(params: *const PleatBakeParams) -> u32 {
    read_versioned(params, "params").map_or(0, |p| if p.threads <= 256 { p.threads } else { 0 })
}

/// The body shared by `pleat_bake_lod` and `pleat_bake_lod_multi`, after their arguments are
/// read: the appearance, the bake, the outputs.
///
/// # Safety
/// The materials' pointers hold the counts they document.
#[cfg(feature = "bake")]
#[allow(clippy::too_many_arguments)]
unsafe fn bake_checked(
    lod: &crate::mesh::TriMesh,
    input: &crate::mesh::TriMesh,
    materials: &[PleatBakeMaterial],
    triangle_material: Option<&[u32]>,
    p: &PleatBakeParams,
    prog: &mut crate::report::ProgressFn<'_>,
    out: super::boundary::Out<*mut PleatBake>,
    stats: Option<super::boundary::VersionedOut<PleatBakeStats>>,
) -> crate::Result<()> {
    let (bp, screen_size) = imp::bake_params(p)?;
    let app = imp::appearance(materials, triangle_material, input)?;
    let level = imp::bake(lod, &app, &bp, screen_size, prog)?;
    if let Some(s) = &stats {
        s.write(imp::stats(&level));
    }
    out.put_boxed(PleatBake { level });
    Ok(())
}

/// `pleat_bake_lod` with several materials: input triangle `t` takes
/// `materials[triangle_material[t]]`. The mesh arrays (`uv_layout`, `uvs`, `uv_count`,
/// `normals`, `colors`) come from `materials[0]` and are shared by all; the other materials
/// set only factors, images and `wrap` (their array fields NULL/0). One atlas and one baked
/// material hold every input material. `pleat_bake_lod` is this call with one material.
///
/// - `materials`: `material_count` structs (1 … `PLEAT_BAKE_MAX_MATERIALS`), each with the
///   same `struct_size` (the array's stride); non-NULL.
/// - `triangle_material`: `triangle_count` indices, `triangle_count` = the input's triangle
///   count, each `< material_count`; NULL (with `triangle_count` 0) puts every triangle in
///   material 0.
/// - The rest as in `pleat_bake_lod`. Any invalid index, count or struct is
///   `PLEAT_STATUS_INVALID_ARGUMENT` naming it, before any work.
///
/// # Safety
/// Handles are NULL or live; the arrays hold their stated counts; every material's pointers
/// hold the counts `PleatBakeMaterial` documents.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_lod_multi(
    lod: *const PleatMesh,
    input: *const PleatMesh,
    materials: *const PleatBakeMaterial,
    material_count: usize,
    triangle_material: *const u32,
    triangle_count: usize,
    params: *const PleatBakeParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatBake,
    stats: *mut PleatBakeStats,
) -> PleatStatus {
    requires!(
        "bake",
        [
            lod,
            input,
            materials,
            material_count,
            triangle_material,
            triangle_count,
            params,
            progress,
            user_data,
            out,
            stats
        ],
        {
            guard_progress_threads(params_threads(params), progress, user_data, |prog| {
                let lod = mesh_ref(lod, "lod")?;
                let input = mesh_ref(input, "input")?;
                let ms = imp::material_array(materials, material_count)?;
                let tm = if triangle_material.is_null() && triangle_count == 0 {
                    None
                } else {
                    if triangle_count != input.triangle_count() {
                        return Err(Error::InvalidArgument(format!(
                            "triangle_count is {triangle_count}; the input has {} triangles",
                            input.triangle_count()
                        )));
                    }
                    let tm = super::boundary::arg_slice(
                        triangle_material,
                        triangle_count,
                        "triangle_material",
                    )?;
                    if let Some(t) = tm.iter().position(|&m| m as usize >= ms.len()) {
                        return Err(Error::InvalidArgument(format!(
                            "triangle_material[{t}] is {}; material_count is {}",
                            tm[t],
                            ms.len()
                        )));
                    }
                    Some(tm)
                };
                let p = read_versioned(params, "params")?;
                let out = arg_out(out, "out")?;
                let stats = versioned_out(stats, "stats")?;
                bake_checked(lod, input, &ms, tm, &p, prog, out, stats)
            })
        }
    )
}

/// Frees a bake (NULL is ignored).
///
/// # Safety
/// `bake` is NULL or a live bake, not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_free(bake: *mut PleatBake) {
    super::boundary::destroy(bake);
}

/// Number of vertices of the baked mesh (0 for NULL). The atlas splits LOD vertices at chart
/// seams, so it is at least the LOD's.
///
/// # Safety
/// `bake` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_vertex_count(bake: *const PleatBake) -> usize {
    bake_count!(bake, |b| b.level.positions.len())
}

/// Number of triangles of the baked mesh (0 for NULL).
///
/// # Safety
/// `bake` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_triangle_count(bake: *const PleatBake) -> usize {
    bake_count!(bake, |b| b.level.triangles.len())
}

/// Fills `stats` (its `struct_size` set by the caller) with the bake's statistics.
///
/// # Safety
/// `bake` is NULL or live; `stats` is NULL or holds `stats->struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_get_stats(
    bake: *const PleatBake,
    stats: *mut PleatBakeStats,
) -> PleatStatus {
    requires!("bake", [bake, stats], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            let s = super::boundary::required_versioned_out(stats, "stats")?;
            s.write(imp::stats(&b.level));
            Ok(())
        })
    })
}

/// Copies the vertex positions (xyz doubles) into `dst`, which holds `vertex_capacity`
/// vertices (at least `pleat_bake_vertex_count`, else `PLEAT_STATUS_LIMIT_EXCEEDED`).
///
/// # Safety
/// `bake` is NULL or live; `dst` is NULL or holds `3 vertex_capacity` doubles.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_copy_positions(
    bake: *const PleatBake,
    dst: *mut f64,
    vertex_capacity: usize,
) -> PleatStatus {
    requires!("bake", [bake, dst, vertex_capacity], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            imp::copy_tuples(
                Some(&b.level.positions),
                dst,
                vertex_capacity,
                "positions",
                |c| c,
            )
        })
    })
}

/// Copies the triangles (3 indices each) into `dst`, which holds `index_capacity` indices
/// (at least `3 pleat_bake_triangle_count`).
///
/// # Safety
/// `bake` is NULL or live; `dst` is NULL or holds `index_capacity` values.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_copy_indices(
    bake: *const PleatBake,
    dst: *mut u32,
    index_capacity: usize,
) -> PleatStatus {
    requires!("bake", [bake, dst, index_capacity], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            let n = 3 * b.level.triangles.len();
            if index_capacity < n {
                return Err(Error::LimitExceeded(format!(
                    "dst holds {index_capacity} indices; the bake has {n}"
                )));
            }
            imp::copy_tuples(Some(&b.level.triangles), dst, n / 3, "triangles", |c| c)
        })
    })
}

/// Copies the atlas UVs (u, v floats in [0, 1], glTF convention: v = 0 is the images' top
/// row) into `dst` holding `vertex_capacity` pairs. `PLEAT_STATUS_INVALID_ARGUMENT` for an
/// untextured bake (vertex colours, no UVs).
///
/// # Safety
/// `bake` is NULL or live; `dst` is NULL or holds `2 vertex_capacity` floats.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_copy_uvs(
    bake: *const PleatBake,
    dst: *mut f32,
    vertex_capacity: usize,
) -> PleatStatus {
    requires!("bake", [bake, dst, vertex_capacity], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            imp::copy_tuples(b.level.uvs.as_deref(), dst, vertex_capacity, "UVs", |c| c)
        })
    })
}

/// Copies the unit vertex normals (xyz floats) into `dst` holding `vertex_capacity` normals.
///
/// # Safety
/// `bake` is NULL or live; `dst` is NULL or holds `3 vertex_capacity` floats.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_copy_normals(
    bake: *const PleatBake,
    dst: *mut f32,
    vertex_capacity: usize,
) -> PleatStatus {
    requires!("bake", [bake, dst, vertex_capacity], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            imp::copy_tuples(
                Some(&b.level.normals),
                dst,
                vertex_capacity,
                "normals",
                |c| c,
            )
        })
    })
}

/// Copies the MikkTSpace tangents (x, y, z, w floats; glTF `TANGENT`, the frame of the
/// normal map) into `dst` holding `vertex_capacity` tangents. Untextured bakes have none.
///
/// # Safety
/// `bake` is NULL or live; `dst` is NULL or holds `4 vertex_capacity` floats.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_copy_tangents(
    bake: *const PleatBake,
    dst: *mut f32,
    vertex_capacity: usize,
) -> PleatStatus {
    requires!("bake", [bake, dst, vertex_capacity], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            imp::copy_tuples(
                b.level.tangents.as_deref(),
                dst,
                vertex_capacity,
                "tangents",
                |c| c,
            )
        })
    })
}

/// Copies the linear RGBA vertex colours of an untextured bake into `dst` holding
/// `vertex_capacity` colours. Textured bakes have none (`PLEAT_STATUS_INVALID_ARGUMENT`).
///
/// # Safety
/// `bake` is NULL or live; `dst` is NULL or holds `4 vertex_capacity` floats.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_copy_colors(
    bake: *const PleatBake,
    dst: *mut f32,
    vertex_capacity: usize,
) -> PleatStatus {
    requires!("bake", [bake, dst, vertex_capacity], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            let colors = b.level.colors.as_deref();
            if colors.is_none() {
                return Err(Error::InvalidArgument(
                    "this bake has no vertex colours (it is textured: copy its images)".into(),
                ));
            }
            imp::copy_tuples(colors, dst, vertex_capacity, "colours", |c| c)
        })
    })
}

/// Writes the size of baked image `which` (`PLEAT_BAKE_IMAGE_*`) to `width` and `height`
/// (0 × 0 when the bake has no such image); both non-NULL.
///
/// # Safety
/// `bake` is NULL or live; `width`, `height` are NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_image_size(
    bake: *const PleatBake,
    which: u32,
    width: *mut u32,
    height: *mut u32,
) -> PleatStatus {
    requires!("bake", [bake, which, width, height], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            let w = arg_out(width, "width")?;
            let h = arg_out(height, "height")?;
            let (iw, ih) = imp::image_of(&b.level, which)?.map_or((0, 0), |i| (i.width, i.height));
            w.put(iw);
            h.put(ih);
            Ok(())
        })
    })
}

/// Copies baked image `which` (RGBA8, row 0 at the top) into `dst` holding `capacity_bytes`
/// bytes (at least `4 · width · height`). `PLEAT_STATUS_INVALID_ARGUMENT` when the bake has
/// no such image (see `pleat_bake_image_size`).
///
/// # Safety
/// `bake` is NULL or live; `dst` is NULL or holds `capacity_bytes` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_copy_image(
    bake: *const PleatBake,
    which: u32,
    dst: *mut u8,
    capacity_bytes: usize,
) -> PleatStatus {
    requires!("bake", [bake, which, dst, capacity_bytes], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            let img = imp::image_of(&b.level, which)?
                .ok_or_else(|| Error::InvalidArgument(format!("this bake has no image {which}")))?;
            arg_out(dst, "dst")?;
            let n = img.rgba.len();
            if capacity_bytes < n {
                return Err(Error::LimitExceeded(format!(
                    "dst holds {capacity_bytes} bytes; the {}×{} image needs {n}",
                    img.width, img.height
                )));
            }
            std::ptr::copy_nonoverlapping(img.rgba.as_ptr(), dst, n);
            Ok(())
        })
    })
}

/// Writes the bake as a `.glb` (one mesh, its material with embedded PNG textures, or vertex
/// colours) at `path` (NUL-terminated UTF-8).
///
/// # Safety
/// `bake` is NULL or live; `path` is NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn pleat_bake_write_glb(
    bake: *const PleatBake,
    path: *const std::ffi::c_char,
) -> PleatStatus {
    requires!("bake", [bake, path], {
        guard(|| {
            let b = arg_ref(bake, "bake")?;
            let path = c_str_arg(path, "path")?;
            let bytes = crate::bake::chain_glb(&[&b.level])?;
            std::fs::write(path, bytes).map_err(|e| Error::Io {
                path: path.into(),
                reason: e.to_string(),
            })
        })
    })
}
