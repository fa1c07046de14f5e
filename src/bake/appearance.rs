//! Reading the appearance of a glTF 2.0 asset: metallic-roughness materials, their textures
//! (decoded to linear floats, sRGB undone for baseColor and emissive), the TEXCOORD set and
//! `KHR_texture_transform` of every texture reference, `COLOR_0`, normals and tangents, per
//! triangle material ids — all in world space, instantiated through the node hierarchy exactly
//! as [`crate::mesh::io::gltf::read_gltf`] does (same triangles, same order), so
//! [`Appearance::mesh`] equals the geometry reader's mesh.
//!
//! Sampling ([`Appearance::sample`]) is what a glTF viewer does for an unlit/PBR material at a
//! surface point: bilinear texture filtering with the sampler's wrap modes (REPEAT,
//! CLAMP_TO_EDGE, MIRRORED_REPEAT) in linear space, factors multiplied in, the normal texture
//! applied in the vertex tangent frame (or a per-triangle UV-gradient frame when the primitive
//! has no `TANGENT`). Mipmaps are not used: the bake samples at the LOD's texel rate, coarser
//! than the input's texels.
//!
//! Missing, undecodable, zero-sized or too-large images, texture references to TEXCOORD sets the
//! primitive lacks, and non-finite UVs are errors ([`Error::Parse`]) naming the file and the
//! material, never a silent white.

use std::collections::HashMap;
use std::path::Path;

use ::gltf::accessor::Dimensions;
use ::gltf::texture::WrappingMode;
use ::gltf::{Document, Semantic};

use crate::geom::{normalized, Vec3};
use crate::mesh::io::gltf::{self as io, Matrix4};
use crate::mesh::io::{parse_error, NodeFilter};
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// Largest texture the reader decodes, in texels (64 Mi texels: 8192², 1 GiB as RGBA `f32`).
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 26;

/// How texture coordinates outside `[0, 1]` are mapped (the glTF sampler's `wrapS`/`wrapT`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// Repeat (`u − floor(u)`), the glTF default.
    Repeat,
    /// Clamp to the edge texels.
    Clamp,
    /// Repeat mirrored every other period.
    Mirror,
}

/// A decoded texture image: row-major RGBA texels in linear `[0, 1]` values (row 0 is the image
/// top, glTF's `v = 0`), with its sampler's wrap modes.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Width in texels (> 0).
    pub width: u32,
    /// Height in texels (> 0).
    pub height: u32,
    /// `width × height` RGBA texels, linear (sRGB decoded when the texture holds colour).
    pub texels: Vec<[f32; 4]>,
    /// Wrap mode along u.
    pub wrap_s: Wrap,
    /// Wrap mode along v.
    pub wrap_t: Wrap,
}

impl Texture {
    /// Bilinear sample at texture coordinates `uv` (glTF convention: texel `(i, j)` has its
    /// centre at `((i + ½)/W, (j + ½)/H)`), after the wrap modes. At a texel centre the result is
    /// that texel exactly.
    pub fn sample(&self, uv: [f64; 2]) -> [f64; 4] {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv[0] * w as f64 - 0.5;
        let y = uv[1] * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let xs = [
            wrap(x0 as i64, w, self.wrap_s),
            wrap(x0 as i64 + 1, w, self.wrap_s),
        ];
        let ys = [
            wrap(y0 as i64, h, self.wrap_t),
            wrap(y0 as i64 + 1, h, self.wrap_t),
        ];
        let mut out = [0.0; 4];
        let weights = [
            (1.0 - fx) * (1.0 - fy),
            fx * (1.0 - fy),
            (1.0 - fx) * fy,
            fx * fy,
        ];
        let taps = [
            (xs[0], ys[0]),
            (xs[1], ys[0]),
            (xs[0], ys[1]),
            (xs[1], ys[1]),
        ];
        for (&wgt, &(i, j)) in weights.iter().zip(&taps) {
            if wgt == 0.0 {
                continue;
            }
            let t = self.texels[(j * w + i) as usize];
            for k in 0..4 {
                out[k] += wgt * f64::from(t[k]);
            }
        }
        out
    }
}

/// Texel index `i` wrapped into `0..n`.
fn wrap(i: i64, n: i64, mode: Wrap) -> i64 {
    match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let k = i.rem_euclid(2 * n);
            if k < n {
                k
            } else {
                2 * n - 1 - k
            }
        }
    }
}

/// A material's reference to a texture.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureRef {
    /// Index into [`Appearance::textures`].
    pub texture: usize,
    /// TEXCOORD set (after `KHR_texture_transform`'s `texCoord` override).
    pub tex_coord: usize,
    /// Affine UV transform `uv' = [[a, b, c], [d, e, f]] · (u, v, 1)` (`KHR_texture_transform`;
    /// identity without it).
    pub transform: [[f64; 3]; 2],
    /// Normal scale (normal texture) or occlusion strength (occlusion texture); 1 otherwise.
    pub scale: f64,
}

impl TextureRef {
    /// `uv` after the texture transform.
    pub fn apply(&self, uv: [f64; 2]) -> [f64; 2] {
        let m = &self.transform;
        [
            m[0][0] * uv[0] + m[0][1] * uv[1] + m[0][2],
            m[1][0] * uv[0] + m[1][1] * uv[1] + m[1][2],
        ]
    }
}

/// glTF alpha mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlphaMode {
    /// Alpha ignored.
    Opaque,
    /// Alpha tested against the cutoff.
    Mask,
    /// Alpha blended.
    Blend,
}

/// A metallic-roughness material (glTF core). Factors are linear.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// baseColorFactor, linear RGBA.
    pub base_color_factor: [f64; 4],
    /// baseColorTexture (sRGB decoded to linear at load).
    pub base_color: Option<TextureRef>,
    /// metallicFactor.
    pub metallic_factor: f64,
    /// roughnessFactor.
    pub roughness_factor: f64,
    /// metallicRoughnessTexture (G = roughness, B = metallic).
    pub metallic_roughness: Option<TextureRef>,
    /// normalTexture (tangent space; `scale` in the reference).
    pub normal: Option<TextureRef>,
    /// occlusionTexture (R; `strength` in the reference's `scale`).
    pub occlusion: Option<TextureRef>,
    /// emissiveFactor, linear RGB.
    pub emissive_factor: [f64; 3],
    /// emissiveTexture (sRGB decoded to linear at load).
    pub emissive: Option<TextureRef>,
    /// Alpha mode.
    pub alpha_mode: AlphaMode,
    /// Alpha cutoff (mask mode), default 0.5.
    pub alpha_cutoff: f64,
    /// Whether back faces are rendered.
    pub double_sided: bool,
}

impl Default for Material {
    /// The glTF default material: white, `metallicFactor = 1`, `roughnessFactor = 1`, no
    /// texture, opaque, single-sided.
    fn default() -> Self {
        Material {
            base_color_factor: [1.0; 4],
            base_color: None,
            metallic_factor: 1.0,
            roughness_factor: 1.0,
            metallic_roughness: None,
            normal: None,
            occlusion: None,
            emissive_factor: [0.0; 3],
            emissive: None,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
        }
    }
}

impl Material {
    /// Whether any texture is referenced.
    pub fn has_textures(&self) -> bool {
        self.base_color.is_some()
            || self.metallic_roughness.is_some()
            || self.normal.is_some()
            || self.occlusion.is_some()
            || self.emissive.is_some()
    }
}

/// The appearance of an asset: world-space mesh plus per-vertex attributes, per-triangle
/// materials, decoded textures. Vertices are never welded (one per primitive vertex instance),
/// so per-vertex attributes are exact.
#[derive(Debug, Clone)]
pub struct Appearance {
    /// World-space geometry, identical to what `read_gltf` returns for the same file.
    pub mesh: TriMesh,
    /// Material of each triangle (index into [`materials`](Self::materials)).
    pub triangle_material: Vec<u32>,
    /// Whether each triangle is shaded flat (its primitive has no `NORMAL`).
    pub triangle_flat: Vec<bool>,
    /// World-space unit vertex normals (zero for vertices of primitives without `NORMAL`).
    pub normals: Vec<[f64; 3]>,
    /// World-space vertex tangents `(x, y, z, w)`; `w = 0` where the primitive has none.
    pub tangents: Vec<[f64; 4]>,
    /// TEXCOORD sets: `uvs[k][v]`; NaN where the vertex's primitive lacks set `k`.
    pub uvs: Vec<Vec<[f64; 2]>>,
    /// `COLOR_0` (linear RGBA, 1 where a primitive lacks it), or `None` when no primitive has it.
    pub colors: Option<Vec<[f64; 4]>>,
    /// Materials; the last one is the glTF default material when some primitive has none.
    pub materials: Vec<Material>,
    /// Decoded textures.
    pub textures: Vec<Texture>,
}

/// What [`Appearance::sample`] gives at a surface point: the material evaluated there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialSample {
    /// Base colour, linear RGBA (factor × texture × COLOR_0).
    pub base_color: [f64; 4],
    /// Metallic in `[0, 1]`.
    pub metallic: f64,
    /// Roughness in `[0, 1]`.
    pub roughness: f64,
    /// Ambient occlusion in `[0, 1]` (1 = unoccluded), strength applied.
    pub occlusion: f64,
    /// Emissive, linear RGB.
    pub emissive: [f64; 3],
    /// World-space unit shading normal (vertex normal perturbed by the normal texture).
    pub normal: [f64; 3],
}

impl Appearance {
    /// Whether any material references a texture.
    pub fn has_textures(&self) -> bool {
        self.materials.iter().any(Material::has_textures)
    }

    /// The UV of set `set` at barycentric `bary` of triangle `t` (NaN when absent).
    pub fn uv(&self, t: usize, set: usize, bary: [f64; 3]) -> [f64; 2] {
        let Some(uvs) = self.uvs.get(set) else {
            return [f64::NAN; 2];
        };
        let tri = self.mesh.triangles()[t];
        let mut uv = [0.0; 2];
        for k in 0..3 {
            let c = uvs[tri[k] as usize];
            uv[0] += bary[k] * c[0];
            uv[1] += bary[k] * c[1];
        }
        uv
    }

    fn tex(&self, r: &TextureRef, t: usize, bary: [f64; 3]) -> [f64; 4] {
        let uv = r.apply(self.uv(t, r.tex_coord, bary));
        self.textures[r.texture].sample(uv)
    }

    /// The geometric unit normal of triangle `t` (zero when degenerate).
    pub fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.mesh.triangle_positions(t).map(Vec3::from);
        normalized((b - a).cross(c - a)).unwrap_or(Vec3::ZERO)
    }

    /// The interpolated vertex normal (face normal for flat triangles), unit.
    pub fn vertex_normal(&self, t: usize, bary: [f64; 3]) -> Vec3 {
        let face = self.face_normal(t);
        if self.triangle_flat[t] {
            return face;
        }
        let tri = self.mesh.triangles()[t];
        let n: Vec3 = (0..3)
            .map(|k| Vec3::from(self.normals[tri[k] as usize]) * bary[k])
            .sum();
        normalized(n).unwrap_or(face)
    }

    /// Tangent frame `(T, B)` at the point for the normal texture `r`: vertex tangents when the
    /// primitive has them, else the triangle's UV gradients (orthogonalised against `n`).
    fn tangent_frame(&self, t: usize, bary: [f64; 3], n: Vec3, r: &TextureRef) -> (Vec3, Vec3) {
        let tri = self.mesh.triangles()[t];
        let tw: Vec<[f64; 4]> = tri.iter().map(|&v| self.tangents[v as usize]).collect();
        if tw.iter().all(|x| x[3] != 0.0) {
            let tv: Vec3 = (0..3)
                .map(|k| Vec3::from([tw[k][0], tw[k][1], tw[k][2]]) * bary[k])
                .sum();
            let w = if tw[0][3] < 0.0 { -1.0 } else { 1.0 };
            if let Some(tu) = normalized(tv - n * n.dot(tv)) {
                return (tu, n.cross(tu) * w);
            }
        }
        let [p0, p1, p2] = self.mesh.triangle_positions(t).map(Vec3::from);
        let uvs = &self.uvs[r.tex_coord];
        let [u0, u1, u2] = tri.map(|v| r.apply(uvs[v as usize]));
        let (e1, e2) = (p1 - p0, p2 - p0);
        let (du1, dv1, du2, dv2) = (u1[0] - u0[0], u1[1] - u0[1], u2[0] - u0[0], u2[1] - u0[1]);
        let det = du1 * dv2 - du2 * dv1;
        if det != 0.0 && det.is_finite() {
            let tv = (e1 * dv2 - e2 * dv1) / det;
            let bv = (e2 * du1 - e1 * du2) / det;
            if let Some(tu) = normalized(tv - n * n.dot(tv)) {
                // glTF: the bitangent points to image up, i.e. decreasing v.
                let w = if n.cross(tu).dot(-bv) < 0.0 {
                    -1.0
                } else {
                    1.0
                };
                return (tu, n.cross(tu) * w);
            }
        }
        let any = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        let tu = normalized(any - n * n.dot(any)).unwrap_or(Vec3::X);
        (tu, n.cross(tu))
    }

    /// The material of triangle `t` evaluated at barycentric coordinates `bary`.
    pub fn sample(&self, t: usize, bary: [f64; 3]) -> MaterialSample {
        let m = &self.materials[self.triangle_material[t] as usize];
        let mut base = m.base_color_factor;
        if let Some(r) = &m.base_color {
            let c = self.tex(r, t, bary);
            (0..4).for_each(|k| base[k] *= c[k]);
        }
        if let Some(colors) = &self.colors {
            let tri = self.mesh.triangles()[t];
            let mut c = [0.0; 4];
            for k in 0..3 {
                let v = colors[tri[k] as usize];
                (0..4).for_each(|j| c[j] += bary[k] * v[j]);
            }
            (0..4).for_each(|k| base[k] *= c[k]);
        }
        let (mut metallic, mut roughness) = (m.metallic_factor, m.roughness_factor);
        if let Some(r) = &m.metallic_roughness {
            let c = self.tex(r, t, bary);
            roughness *= c[1];
            metallic *= c[2];
        }
        let occlusion = match &m.occlusion {
            Some(r) => 1.0 + r.scale * (self.tex(r, t, bary)[0] - 1.0),
            None => 1.0,
        };
        let mut emissive = m.emissive_factor;
        if let Some(r) = &m.emissive {
            let c = self.tex(r, t, bary);
            (0..3).for_each(|k| emissive[k] *= c[k]);
        }
        let n = self.vertex_normal(t, bary);
        let normal = match &m.normal {
            Some(r) => {
                let c = self.tex(r, t, bary);
                let x = (2.0 * c[0] - 1.0) * r.scale;
                let y = (2.0 * c[1] - 1.0) * r.scale;
                let z = 2.0 * c[2] - 1.0;
                let (tu, bv) = self.tangent_frame(t, bary, n, r);
                normalized(tu * x + bv * y + n * z).unwrap_or(n)
            }
            None => n,
        };
        MaterialSample {
            base_color: base,
            metallic,
            roughness,
            occlusion,
            emissive,
            normal: normal.to_array(),
        }
    }
}

/// Texture coordinates passed to [`Appearance::from_buffers`] (glTF convention: `v = 0` is the
/// image's top row).
#[derive(Debug, Clone, Copy)]
pub enum UvBuffer<'a> {
    /// One UV per mesh vertex.
    PerVertex(&'a [[f64; 2]]),
    /// One UV per triangle corner (`3 t + k`), as engines store seams; the mesh is then
    /// unwelded (3 vertices per triangle, same triangle order).
    PerCorner(&'a [[f64; 2]]),
}

/// A caller-decoded RGBA8 image for [`Appearance::from_buffers`]: row-major, row 0 at the top.
#[derive(Debug, Clone, Copy)]
pub struct ImageBuffer<'a> {
    /// Width in texels (> 0).
    pub width: u32,
    /// Height in texels (> 0; `width · height` ≤ [`MAX_TEXTURE_TEXELS`]).
    pub height: u32,
    /// `4 · width · height` bytes, RGBA.
    pub rgba: &'a [u8],
    /// The colour channels are sRGB-encoded (glTF: base colour and emissive); alpha is linear.
    pub srgb: bool,
}

/// One metallic-roughness material from caller buffers (glTF semantics and defaults; every
/// texture read with the mesh's one UV set).
#[derive(Debug, Clone, Copy)]
pub struct BufferMaterial<'a> {
    /// baseColorFactor, linear RGBA.
    pub base_color_factor: [f64; 4],
    /// baseColorTexture.
    pub base_color: Option<ImageBuffer<'a>>,
    /// metallicFactor.
    pub metallic_factor: f64,
    /// roughnessFactor.
    pub roughness_factor: f64,
    /// metallicRoughnessTexture (G roughness, B metallic).
    pub metallic_roughness: Option<ImageBuffer<'a>>,
    /// Tangent-space normal texture (glTF/MikkTSpace convention).
    pub normal: Option<ImageBuffer<'a>>,
    /// Normal scale.
    pub normal_scale: f64,
    /// Occlusion texture (R).
    pub occlusion: Option<ImageBuffer<'a>>,
    /// Occlusion strength.
    pub occlusion_strength: f64,
    /// emissiveFactor, linear RGB.
    pub emissive_factor: [f64; 3],
    /// Emissive texture.
    pub emissive: Option<ImageBuffer<'a>>,
    /// Wrap mode of every texture along u and v.
    pub wrap: Wrap,
}

impl Default for BufferMaterial<'_> {
    /// glTF's default material (white, metallic 1, roughness 1, no texture), REPEAT wrap.
    fn default() -> Self {
        BufferMaterial {
            base_color_factor: [1.0; 4],
            base_color: None,
            metallic_factor: 1.0,
            roughness_factor: 1.0,
            metallic_roughness: None,
            normal: None,
            normal_scale: 1.0,
            occlusion: None,
            occlusion_strength: 1.0,
            emissive_factor: [0.0; 3],
            emissive: None,
            wrap: Wrap::Repeat,
        }
    }
}

/// An input's appearance as raw arrays (an engine's own decoded mesh and textures), for
/// [`Appearance::from_buffers`].
#[derive(Debug, Clone, Copy)]
pub struct AppearanceBuffers<'a> {
    /// The input geometry.
    pub mesh: &'a TriMesh,
    /// Texture coordinates (required when the material has a texture).
    pub uvs: Option<UvBuffer<'a>>,
    /// Per-vertex shading normals (need not be unit; `None`: area-weighted vertex normals).
    pub normals: Option<&'a [[f64; 3]]>,
    /// Per-vertex linear RGBA colours multiplying the base colour (glTF `COLOR_0`).
    pub colors: Option<&'a [[f64; 4]]>,
    /// The one material of every triangle.
    pub material: BufferMaterial<'a>,
}

/// `Err(InvalidArgument)` "`name`[i] is not finite" for the first non-finite value.
fn check_finite<const N: usize>(v: &[[f64; N]], name: &str) -> Result<()> {
    match v.iter().position(|x| !x.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::InvalidArgument(format!(
            "{name}[{i}] is not finite (NaN or infinite)"
        ))),
        None => Ok(()),
    }
}

/// `Err(InvalidArgument)` unless `v` holds `want` entries.
fn check_len<T>(v: &[T], want: usize, name: &str, per: &str) -> Result<()> {
    if v.len() == want {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{name} holds {} entries; {want} needed (one per {per})",
            v.len()
        )))
    }
}

impl ImageBuffer<'_> {
    /// The decoded linear texture (the checks of [`Appearance::from_buffers`]).
    fn to_texture(self, name: &str, wrap: Wrap) -> Result<Texture> {
        let texels = u64::from(self.width) * u64::from(self.height);
        if texels == 0 {
            return Err(Error::InvalidArgument(format!(
                "{name} has zero size ({}×{})",
                self.width, self.height
            )));
        }
        if texels > MAX_TEXTURE_TEXELS {
            return Err(Error::LimitExceeded(format!(
                "{name} of {}×{} texels exceeds the budget of {MAX_TEXTURE_TEXELS} texels",
                self.width, self.height
            )));
        }
        check_len(self.rgba, 4 * texels as usize, name, "RGBA byte")?;
        let lut = texel_lut(self.srgb);
        let texels = self
            .rgba
            .chunks_exact(4)
            .map(|p| {
                [
                    lut[p[0] as usize],
                    lut[p[1] as usize],
                    lut[p[2] as usize],
                    f32::from(p[3]) / 255.0,
                ]
            })
            .collect();
        Ok(Texture {
            width: self.width,
            height: self.height,
            texels,
            wrap_s: wrap,
            wrap_t: wrap,
        })
    }
}

/// Byte → linear value of a colour channel (sRGB decoded when `srgb`).
fn texel_lut(srgb: bool) -> Vec<f32> {
    (0..256)
        .map(|i| {
            let c = f64::from(i as u8) / 255.0;
            (if srgb { srgb_to_linear(c) } else { c }) as f32
        })
        .collect()
}

impl Appearance {
    /// The appearance of a mesh given as raw arrays (see [`AppearanceBuffers`]): one material,
    /// one UV set (per vertex or per corner), optional normals and vertex colours. The result
    /// samples exactly like a glTF asset with the same data read by [`read_gltf_appearance`]; with
    /// per-corner UVs its mesh is the input unwelded (triangle `t` keeps its index, so
    /// provenance triangle indices refer to the caller's triangles either way).
    ///
    /// Errors: `InvalidArgument` naming the array for a wrong count, a non-finite UV, normal or
    /// colour, a texture without UVs, or a zero-sized image; `LimitExceeded` for an image over
    /// [`MAX_TEXTURE_TEXELS`].
    pub fn from_buffers(b: &AppearanceBuffers<'_>) -> Result<Appearance> {
        let nt = b.mesh.triangle_count();
        Self::from_buffers_multi(b, std::slice::from_ref(&b.material), &vec![0; nt])
    }

    /// [`from_buffers`](Self::from_buffers) with several materials: triangle `t` takes
    /// `materials[triangle_material[t]]` (`b.material` is not used; the mesh attributes of `b`
    /// are shared by every material). The single-material call is this with one material.
    /// Triangle order is kept, so [`Appearance::triangle_material`] equals
    /// `triangle_material`.
    ///
    /// Errors as [`from_buffers`](Self::from_buffers), naming `materials[i]` when there are
    /// several, plus `InvalidArgument` for no material, a `triangle_material` whose length is
    /// not the triangle count, or an index `>= materials.len()`.
    pub fn from_buffers_multi(
        b: &AppearanceBuffers<'_>,
        materials: &[BufferMaterial<'_>],
        triangle_material: &[u32],
    ) -> Result<Appearance> {
        let (nv, nt) = (b.mesh.vertex_count(), b.mesh.triangle_count());
        if materials.is_empty() {
            return Err(Error::InvalidArgument(
                "no material given (at least one is needed)".into(),
            ));
        }
        check_len(triangle_material, nt, "triangle_material", "triangle")?;
        if let Some(t) = triangle_material
            .iter()
            .position(|&m| m as usize >= materials.len())
        {
            return Err(Error::InvalidArgument(format!(
                "triangle_material[{t}] is {}; there are {} materials",
                triangle_material[t],
                materials.len()
            )));
        }
        if let Some(n) = b.normals {
            check_len(n, nv, "normals", "vertex")?;
            check_finite(n, "normals")?;
        }
        if let Some(c) = b.colors {
            check_len(c, nv, "colors", "vertex")?;
            check_finite(c, "colors")?;
        }
        match b.uvs {
            Some(UvBuffer::PerVertex(uv)) => check_len(uv, nv, "uvs", "vertex")?,
            Some(UvBuffer::PerCorner(uv)) => check_len(uv, 3 * nt, "uvs", "triangle corner")?,
            None => {}
        }
        if let Some(UvBuffer::PerVertex(uv) | UvBuffer::PerCorner(uv)) = b.uvs {
            check_finite(uv, "uvs")?;
        }
        let mut textures = Vec::new();
        let converted = materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let prefix = if materials.len() > 1 {
                    format!("materials[{i}].")
                } else {
                    String::new()
                };
                buffer_material(m, &prefix, b.uvs.is_some(), &mut textures)
            })
            .collect::<Result<Vec<_>>>()?;
        let normals: Vec<[f64; 3]> = match b.normals {
            Some(n) => n
                .iter()
                .map(|&v| normalized(Vec3::from(v)).unwrap_or(Vec3::ZERO).to_array())
                .collect(),
            None => crate::transfer::provenance::vertex_normals(b.mesh),
        };
        // Per-corner UVs: vertex 3t + k copies corner k of triangle t.
        let corners: Option<Vec<u32>> = match b.uvs {
            Some(UvBuffer::PerCorner(_)) => Some(
                b.mesh
                    .triangles()
                    .iter()
                    .flat_map(|t| t.iter().copied())
                    .collect(),
            ),
            _ => None,
        };
        let per_vertex = |v: &[[f64; 3]]| -> Vec<[f64; 3]> {
            match &corners {
                Some(c) => c.iter().map(|&i| v[i as usize]).collect(),
                None => v.to_vec(),
            }
        };
        let mesh = match &corners {
            Some(_) => TriMesh::new(
                per_vertex(b.mesh.positions()),
                (0..nt as u32)
                    .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                    .collect(),
            )?,
            None => b.mesh.clone(),
        };
        let colors = b.colors.map(|c| match &corners {
            Some(cs) => cs.iter().map(|&i| c[i as usize]).collect(),
            None => c.to_vec(),
        });
        let uvs = match b.uvs {
            Some(UvBuffer::PerVertex(uv) | UvBuffer::PerCorner(uv)) => vec![uv.to_vec()],
            None => Vec::new(),
        };
        let n = mesh.vertex_count();
        Ok(Appearance {
            triangle_material: triangle_material.to_vec(),
            triangle_flat: vec![false; nt],
            normals: per_vertex(&normals),
            tangents: vec![[0.0; 4]; n],
            uvs,
            colors,
            materials: converted,
            textures,
            mesh,
        })
    }
}

/// One caller material as a [`Material`], its images decoded into `textures` (checks of
/// [`Appearance::from_buffers`]; `prefix` is prepended to the names in messages).
fn buffer_material(
    m: &BufferMaterial<'_>,
    prefix: &str,
    has_uvs: bool,
    textures: &mut Vec<Texture>,
) -> Result<Material> {
    for (v, name) in [
        (m.metallic_factor, "metallic_factor"),
        (m.roughness_factor, "roughness_factor"),
        (m.normal_scale, "normal_scale"),
        (m.occlusion_strength, "occlusion_strength"),
    ] {
        if !v.is_finite() {
            return Err(Error::InvalidArgument(format!(
                "{prefix}{name} is {v}; must be finite"
            )));
        }
    }
    check_finite(
        &[m.base_color_factor],
        &format!("{prefix}base_color_factor"),
    )?;
    check_finite(&[m.emissive_factor], &format!("{prefix}emissive_factor"))?;
    let mut slot = |img: Option<ImageBuffer<'_>>, name: &str, scale: f64| {
        img.map(|img| -> Result<TextureRef> {
            let name = format!("{prefix}{name}");
            if !has_uvs {
                return Err(Error::InvalidArgument(format!(
                    "{name} is given but there are no UVs to sample it with"
                )));
            }
            textures.push(img.to_texture(&name, m.wrap)?);
            Ok(TextureRef {
                texture: textures.len() - 1,
                tex_coord: 0,
                transform: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                scale,
            })
        })
        .transpose()
    };
    Ok(Material {
        base_color_factor: m.base_color_factor,
        base_color: slot(m.base_color, "base_color", 1.0)?,
        metallic_factor: m.metallic_factor,
        roughness_factor: m.roughness_factor,
        metallic_roughness: slot(m.metallic_roughness, "metallic_roughness", 1.0)?,
        normal: slot(m.normal, "normal", m.normal_scale)?,
        occlusion: slot(m.occlusion, "occlusion", m.occlusion_strength)?,
        emissive_factor: m.emissive_factor,
        emissive: slot(m.emissive, "emissive", 1.0)?,
        ..Material::default()
    })
}

/// Reads a `.glb`/`.gltf` file's appearance (external buffers and images relative to its
/// folder). See the [module docs](self); [`super::read_appearance`] picks the reader by
/// extension.
pub fn read_gltf_appearance(path: &Path) -> Result<Appearance> {
    read_gltf_appearance_selected(path, None)
}

/// [`read_gltf_appearance`] of the nodes `filter` selects (matched nodes with their subtrees,
/// see [`NodeFilter`]); `None` reads every node. The geometry is what
/// [`crate::mesh::io::gltf::read_gltf_selected`] returns with the same filter. Errors as
/// [`read_gltf_appearance`], plus `InvalidArgument` when the filter matches no node.
pub fn read_gltf_appearance_selected(
    path: &Path,
    filter: Option<&NodeFilter>,
) -> Result<Appearance> {
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| crate::mesh::io::io_error(&name, &e))?;
    let base = path.parent().unwrap_or(Path::new("."));
    read_appearance_bytes_selected(&data, Some(base), &name, filter)
}

/// Reads a glTF/GLB's appearance from memory; `name` stands for the file in messages; external
/// files resolve against `base_dir` (`None`: only embedded data).
pub fn read_appearance_bytes(
    data: &[u8],
    base_dir: Option<&Path>,
    name: &str,
) -> Result<Appearance> {
    read_appearance_bytes_selected(data, base_dir, name, None)
}

/// [`read_appearance_bytes`] of the nodes `filter` selects (see
/// [`read_gltf_appearance_selected`]).
pub fn read_appearance_bytes_selected(
    data: &[u8],
    base_dir: Option<&Path>,
    name: &str,
    filter: Option<&NodeFilter>,
) -> Result<Appearance> {
    let loaded = io::load_document(data, base_dir, name)?;
    let raw = raw_json(data);
    let mut reader = Reader {
        filter,
        doc: &loaded.document,
        buffers: &loaded.buffers,
        raw: raw.as_ref(),
        name,
        base: base_dir,
        out: Builder::default(),
        texture_slots: HashMap::new(),
        material_slots: HashMap::new(),
    };
    reader.read_scene()?;
    reader.finish()
}

/// Reads the appearance of one glTF mesh (index `mesh`) alone, in the mesh's local space: its
/// triangle primitives in order with no node transform, materials, textures, UV sets, colours,
/// normals and tangents read exactly as [`read_appearance_bytes`] reads them for one instance
/// under an identity transform. This is the appearance a per-mesh LOD chain is baked from
/// (`bake::scene`). Errors as [`read_appearance_bytes`], plus `Parse` for a mesh index out of
/// range or a mesh without triangles.
pub fn read_mesh_appearance_bytes(
    data: &[u8],
    base_dir: Option<&Path>,
    name: &str,
    mesh: usize,
) -> Result<Appearance> {
    let loaded = io::load_document(data, base_dir, name)?;
    let raw = raw_json(data);
    mesh_appearance(&loaded, raw.as_ref(), base_dir, name, mesh)
}

/// [`read_mesh_appearance_bytes`] on a document already loaded (`raw`: its JSON, for
/// `KHR_texture_transform`).
pub(crate) fn mesh_appearance(
    loaded: &io::LoadedDocument,
    raw: Option<&serde_json::Value>,
    base_dir: Option<&Path>,
    name: &str,
    mesh: usize,
) -> Result<Appearance> {
    let mut reader = Reader {
        filter: None,
        doc: &loaded.document,
        buffers: &loaded.buffers,
        raw,
        name,
        base: base_dir,
        out: Builder::default(),
        texture_slots: HashMap::new(),
        material_slots: HashMap::new(),
    };
    let doc = reader.doc;
    io::for_each_mesh_primitive(doc, mesh, name, &mut |prim, pos, world, what| {
        reader.add_primitive(prim, pos, world, what)
    })?;
    reader.finish()
}

/// The document's JSON as a `serde_json` value (for extensions the `gltf` crate drops).
pub(crate) fn raw_json(data: &[u8]) -> Option<serde_json::Value> {
    let json = if data.starts_with(b"glTF") {
        let len = u32::from_le_bytes(data.get(12..16)?.try_into().ok()?) as usize;
        if data.get(16..20)? != b"JSON" {
            return None;
        }
        data.get(20..20usize.checked_add(len)?)?
    } else {
        data
    };
    serde_json::from_slice(json).ok()
}

/// An [`Appearance`] under construction, one primitive (or OBJ group) after another: every
/// per-vertex vector grows with `positions`, every per-triangle one with `triangles`.
#[derive(Default)]
pub(super) struct Builder {
    pub(super) positions: Vec<[f64; 3]>,
    pub(super) triangles: Vec<[u32; 3]>,
    pub(super) triangle_material: Vec<u32>,
    pub(super) triangle_flat: Vec<bool>,
    pub(super) normals: Vec<[f64; 3]>,
    pub(super) tangents: Vec<[f64; 4]>,
    pub(super) uvs: Vec<Vec<[f64; 2]>>,
    pub(super) colors: Vec<[f64; 4]>,
    pub(super) any_color: bool,
    pub(super) materials: Vec<Material>,
    pub(super) textures: Vec<Texture>,
}

impl Builder {
    /// The appearance (its mesh checked by `TriMesh::new`; errors name `name`).
    pub(super) fn finish(self, name: &str) -> Result<Appearance> {
        let mesh = io_build(name, self.positions, self.triangles)?;
        Ok(Appearance {
            mesh,
            triangle_material: self.triangle_material,
            triangle_flat: self.triangle_flat,
            normals: self.normals,
            tangents: self.tangents,
            uvs: self.uvs,
            colors: self.any_color.then_some(self.colors),
            materials: self.materials,
            textures: self.textures,
        })
    }
}

struct Reader<'a> {
    /// The nodes read (`None`: all).
    filter: Option<&'a NodeFilter>,
    doc: &'a Document,
    buffers: &'a [Vec<u8>],
    raw: Option<&'a serde_json::Value>,
    name: &'a str,
    base: Option<&'a Path>,
    out: Builder,
    /// (glTF texture index, sRGB) → index in `out.textures`.
    texture_slots: HashMap<(usize, bool), usize>,
    /// glTF material index (`None` = default) → index in `out.materials`.
    material_slots: HashMap<Option<usize>, u32>,
}

impl Reader<'_> {
    fn err(&self, reason: impl Into<String>) -> Error {
        parse_error(self.name, reason)
    }

    /// Every primitive the geometry reader instantiates, in its order (one walker:
    /// [`io::for_each_primitive`]).
    fn read_scene(&mut self) -> Result<()> {
        let (doc, name, filter) = (self.doc, self.name, self.filter);
        io::for_each_primitive(doc, name, filter, &mut |prim, pos, world, what| {
            self.add_primitive(prim, pos, world, what)
        })
    }

    fn values(&self, acc: &::gltf::Accessor, what: &str) -> Result<Vec<f64>> {
        io::accessor_values(acc, self.buffers, self.name, what)
    }

    fn add_primitive(
        &mut self,
        prim: &::gltf::Primitive,
        pos: &::gltf::Accessor,
        world: &Matrix4,
        what: &str,
    ) -> Result<()> {
        let n = pos.count();
        let base = self.out.positions.len();
        let p = self.values(pos, what)?;
        for (i, c) in p.chunks_exact(3).enumerate() {
            let q = io::mat_point(world, [c[0], c[1], c[2]]);
            if !q.iter().all(|x| x.is_finite()) {
                return Err(self.err(format!("{what} vertex {i}: non-finite coordinate")));
            }
            self.out.positions.push(q);
        }
        let det = io::mat_det3(world);
        let sign = if det < 0.0 { -1.0 } else { 1.0 };
        let cof = cofactor(world);
        let lin = |v: [f64; 3]| -> Vec3 {
            Vec3::from(io::mat_point(world, v)) - Vec3::from(io::mat_point(world, [0.0; 3]))
        };
        // Normals.
        let normals = match prim.get(&Semantic::Normals) {
            Some(acc) if acc.count() == n && acc.dimensions() == Dimensions::Vec3 => {
                Some(self.values(&acc, what)?)
            }
            Some(_) => return Err(self.err(format!("{what}: NORMAL count or type is wrong"))),
            None => None,
        };
        let flat = normals.is_none();
        for i in 0..n {
            let nv = normals.as_ref().map_or(Vec3::ZERO, |v| {
                let m = Vec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
                normalized(cof_apply(&cof, m) * sign).unwrap_or(Vec3::ZERO)
            });
            self.out.normals.push(nv.to_array());
        }
        // Tangents.
        let tangents = match prim.get(&Semantic::Tangents) {
            Some(acc) if acc.count() == n && acc.dimensions() == Dimensions::Vec4 => {
                Some(self.values(&acc, what)?)
            }
            _ => None,
        };
        for i in 0..n {
            let t = tangents.as_ref().map_or([0.0; 4], |v| {
                let d = lin([v[4 * i], v[4 * i + 1], v[4 * i + 2]]);
                let w = if v[4 * i + 3] < 0.0 { -sign } else { sign };
                match normalized(d) {
                    Some(u) => [u.x, u.y, u.z, w],
                    None => [0.0; 4],
                }
            });
            self.out.tangents.push(t);
        }
        // UV sets.
        let mut set = 0;
        while let Some(acc) = prim.get(&Semantic::TexCoords(set)) {
            if acc.count() != n || acc.dimensions() != Dimensions::Vec2 {
                return Err(self.err(format!("{what}: TEXCOORD_{set} count or type is wrong")));
            }
            let v = self.values(&acc, what)?;
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(self.err(format!(
                    "{what}: TEXCOORD_{set} of vertex {} is not finite",
                    i / 2
                )));
            }
            let set_idx = set as usize;
            while self.out.uvs.len() <= set_idx {
                self.out.uvs.push(vec![[f64::NAN; 2]; base]);
            }
            self.out.uvs[set_idx].extend(v.chunks_exact(2).map(|c| [c[0], c[1]]));
            set += 1;
        }
        for uvs in &mut self.out.uvs {
            uvs.resize(base + n, [f64::NAN; 2]);
        }
        // COLOR_0.
        match prim.get(&Semantic::Colors(0)) {
            Some(acc) if acc.count() == n => {
                let k = acc.dimensions().multiplicity();
                if k != 3 && k != 4 {
                    return Err(self.err(format!("{what}: COLOR_0 is neither VEC3 nor VEC4")));
                }
                let v = self.values(&acc, what)?;
                self.out.any_color = true;
                self.out.colors.extend(
                    v.chunks_exact(k)
                        .map(|c| [c[0], c[1], c[2], if k == 4 { c[3] } else { 1.0 }]),
                );
            }
            Some(_) => return Err(self.err(format!("{what}: COLOR_0 count is wrong"))),
            None => self.out.colors.resize(base + n, [1.0; 4]),
        }
        // Material.
        let mat = self.material(prim.material(), what)?;
        for r in self.out.materials[mat as usize].refs() {
            if self
                .out
                .uvs
                .get(r.tex_coord)
                .is_none_or(|u| n > 0 && u[base][0].is_nan())
            {
                return Err(self.err(format!(
                    "{what}: its material samples TEXCOORD_{} but the primitive has no such \
                     attribute",
                    r.tex_coord
                )));
            }
        }
        // Triangles.
        let indices = match prim.indices() {
            Some(acc) => io::index_values(&acc, n, self.buffers, self.name, what)?,
            None => (0..n as u32).collect(),
        };
        let flip = det < 0.0;
        let off = base as u32;
        for t in io::triangle_list(prim.mode(), &indices) {
            let [a, b, c] = t.map(|i| i + off);
            self.out
                .triangles
                .push(if flip { [a, c, b] } else { [a, b, c] });
            self.out.triangle_material.push(mat);
            self.out.triangle_flat.push(flat);
        }
        Ok(())
    }

    fn material(&mut self, m: ::gltf::Material, what: &str) -> Result<u32> {
        if let Some(&i) = self.material_slots.get(&m.index()) {
            return Ok(i);
        }
        let pbr = m.pbr_metallic_roughness();
        let idx = m.index();
        let json = |slot: &str| -> Option<&serde_json::Value> {
            let i = idx?;
            self.raw?.pointer(&format!(
                "/materials/{i}/{slot}/extensions/KHR_texture_transform"
            ))
        };
        let transforms = [
            "pbrMetallicRoughness/baseColorTexture",
            "pbrMetallicRoughness/metallicRoughnessTexture",
            "normalTexture",
            "occlusionTexture",
            "emissiveTexture",
        ]
        .map(|s| json(s).cloned());
        let what = format!(
            "{what} (material {})",
            idx.map_or("default".into(), |i| i.to_string())
        );
        let base_color = match pbr.base_color_texture() {
            Some(info) => Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                1.0,
                true,
                transforms[0].as_ref(),
                &what,
            )?),
            None => None,
        };
        let metallic_roughness = match pbr.metallic_roughness_texture() {
            Some(info) => Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                1.0,
                false,
                transforms[1].as_ref(),
                &what,
            )?),
            None => None,
        };
        let normal = match m.normal_texture() {
            Some(info) => Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                f64::from(info.scale()),
                false,
                transforms[2].as_ref(),
                &what,
            )?),
            None => None,
        };
        let occlusion = match m.occlusion_texture() {
            Some(info) => Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                f64::from(info.strength()),
                false,
                transforms[3].as_ref(),
                &what,
            )?),
            None => None,
        };
        let emissive = match m.emissive_texture() {
            Some(info) => Some(self.texture_ref(
                info.texture(),
                info.tex_coord(),
                1.0,
                true,
                transforms[4].as_ref(),
                &what,
            )?),
            None => None,
        };
        let material = Material {
            base_color_factor: pbr.base_color_factor().map(f64::from),
            base_color,
            metallic_factor: f64::from(pbr.metallic_factor()),
            roughness_factor: f64::from(pbr.roughness_factor()),
            metallic_roughness,
            normal,
            occlusion,
            emissive_factor: m.emissive_factor().map(f64::from),
            emissive,
            alpha_mode: match m.alpha_mode() {
                ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                ::gltf::material::AlphaMode::Mask => AlphaMode::Mask,
                ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            alpha_cutoff: f64::from(m.alpha_cutoff().unwrap_or(0.5)),
            double_sided: m.double_sided(),
        };
        let i = self.out.materials.len() as u32;
        self.out.materials.push(material);
        self.material_slots.insert(idx, i);
        Ok(i)
    }

    fn texture_ref(
        &mut self,
        tex: ::gltf::Texture,
        tex_coord: u32,
        scale: f64,
        srgb: bool,
        transform: Option<&serde_json::Value>,
        what: &str,
    ) -> Result<TextureRef> {
        let texture = self.texture(&tex, srgb, what)?;
        let (matrix, tc) = texture_transform(transform);
        Ok(TextureRef {
            texture,
            tex_coord: tc.unwrap_or(tex_coord) as usize,
            transform: matrix,
            scale,
        })
    }

    fn texture(&mut self, tex: &::gltf::Texture, srgb: bool, what: &str) -> Result<usize> {
        if let Some(&i) = self.texture_slots.get(&(tex.index(), srgb)) {
            return Ok(i);
        }
        let image = tex.source();
        let label = format!("{what}: texture {} (image {})", tex.index(), image.index());
        let bytes = match image.source() {
            ::gltf::image::Source::View { view, .. } => {
                io::view_bytes(&view, self.buffers, self.name)?.to_vec()
            }
            ::gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
                io::data_uri_bytes(uri)
                    .ok_or_else(|| self.err(format!("{label}: malformed base64 data URI")))?
            }
            ::gltf::image::Source::Uri { uri, .. } => {
                io::external_bytes(uri, 1 << 30, self.base, self.name)
                    .map_err(|e| self.err(format!("{label}: image '{uri}' cannot be read: {e}")))?
            }
        };
        let texels = decode_image(&bytes, srgb).map_err(|e| self.err(format!("{label}: {e}")))?;
        let sampler = tex.sampler();
        let texture = Texture {
            width: texels.0,
            height: texels.1,
            texels: texels.2,
            wrap_s: wrap_mode(sampler.wrap_s()),
            wrap_t: wrap_mode(sampler.wrap_t()),
        };
        let i = self.out.textures.len();
        self.out.textures.push(texture);
        self.texture_slots.insert((tex.index(), srgb), i);
        Ok(i)
    }

    fn finish(self) -> Result<Appearance> {
        self.out.finish(self.name)
    }
}

impl Material {
    /// Every texture reference of the material.
    pub(super) fn refs(&self) -> impl Iterator<Item = &TextureRef> {
        [
            &self.base_color,
            &self.metallic_roughness,
            &self.normal,
            &self.occlusion,
            &self.emissive,
        ]
        .into_iter()
        .flatten()
    }
}

fn io_build(name: &str, positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<TriMesh> {
    TriMesh::new(positions, triangles).map_err(|e| match e {
        Error::InvalidMesh(m) => parse_error(name, m),
        other => other,
    })
}

fn wrap_mode(m: WrappingMode) -> Wrap {
    match m {
        WrappingMode::Repeat => Wrap::Repeat,
        WrappingMode::ClampToEdge => Wrap::Clamp,
        WrappingMode::MirroredRepeat => Wrap::Mirror,
    }
}

/// `KHR_texture_transform` as an affine matrix (`T · R · S`) and its optional texCoord override.
fn texture_transform(ext: Option<&serde_json::Value>) -> ([[f64; 3]; 2], Option<u32>) {
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let Some(ext) = ext else {
        return (identity, None);
    };
    let pair = |key: &str, default: f64| -> [f64; 2] {
        let v = ext.get(key).and_then(|v| v.as_array());
        let g = |i: usize| {
            v.and_then(|a| a.get(i))
                .and_then(|x| x.as_f64())
                .unwrap_or(default)
        };
        [g(0), g(1)]
    };
    let offset = pair("offset", 0.0);
    let scale = pair("scale", 1.0);
    let rotation = ext.get("rotation").and_then(|v| v.as_f64()).unwrap_or(0.0);
    let (s, c) = rotation.sin_cos();
    let matrix = [
        [c * scale[0], s * scale[1], offset[0]],
        [-s * scale[0], c * scale[1], offset[1]],
    ];
    let tc = ext
        .get("texCoord")
        .and_then(|v| v.as_u64())
        .map(|v| v as u32);
    (matrix, tc)
}

/// Cofactor matrix of the linear part (rows), `cof · n` transforms normals up to `det`'s sign.
fn cofactor(m: &Matrix4) -> [[f64; 3]; 3] {
    // a[r][c] = m[c][r]
    let a = |r: usize, c: usize| m[c][r];
    let mut out = [[0.0; 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            *x = a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1);
        }
    }
    out
}

fn cof_apply(cof: &[[f64; 3]; 3], n: Vec3) -> Vec3 {
    let v = n.to_array();
    Vec3::from(std::array::from_fn::<f64, 3, _>(|r| {
        (0..3).map(|c| cof[r][c] * v[c]).sum()
    }))
}

/// sRGB transfer function decoded: display value in `[0, 1]` to linear.
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// sRGB transfer function encoded: linear in `[0, 1]` to display value.
pub fn linear_to_srgb(c: f64) -> f64 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// `Err` naming the problem when a `w × h` image is empty or over [`MAX_TEXTURE_TEXELS`].
fn check_image_size(w: u32, h: u32) -> std::result::Result<(), String> {
    if w == 0 || h == 0 {
        return Err("image has zero size".into());
    }
    if u64::from(w) * u64::from(h) > MAX_TEXTURE_TEXELS {
        return Err(format!(
            "image of {w}×{h} texels exceeds the budget of {MAX_TEXTURE_TEXELS} texels"
        ));
    }
    Ok(())
}

/// Decodes a PNG or JPEG into `(width, height, linear RGBA texels)`; `srgb` decodes the colour
/// channels' sRGB transfer (alpha is always linear).
pub(super) fn decode_image(
    bytes: &[u8],
    srgb: bool,
) -> std::result::Result<(u32, u32, Vec<[f32; 4]>), String> {
    let format = image::guess_format(bytes)
        .map_err(|e| format!("image data is neither PNG nor JPEG ({e})"))?;
    if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
        return Err(format!(
            "image format {format:?} is not supported (PNG or JPEG)"
        ));
    }
    // The header's size first, so an over-budget or empty image is named as such rather
    // than by the decoder's allocation limit (which stays as a backstop).
    let header = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
    if let Ok((w, h)) = header.into_dimensions() {
        check_image_size(w, h)?;
    }
    let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(MAX_TEXTURE_TEXELS * 8);
    reader.limits(limits);
    let img = reader
        .decode()
        .map_err(|e| format!("image cannot be decoded: {e}"))?;
    let (w, h) = (img.width(), img.height());
    check_image_size(w, h)?;
    let lut = texel_lut(srgb);
    let rgba = img.to_rgba8();
    let texels = rgba
        .pixels()
        .map(|p| {
            [
                lut[p[0] as usize],
                lut[p[1] as usize],
                lut[p[2] as usize],
                f32::from(p[3]) / 255.0,
            ]
        })
        .collect();
    Ok((w, h, texels))
}
