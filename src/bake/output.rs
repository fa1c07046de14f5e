//! One `.glb` holding a chain of baked LOD levels.
//!
//! Levels are written finest first (largest `n_p`): level `i` is node `i` with mesh `i` (one
//! indexed `TRIANGLES` primitive: `f32` POSITION with min/max, NORMAL, TANGENT and TEXCOORD_0
//! when textured, COLOR_0 for vertex colours, `u32` indices) and material `i` with its images
//! embedded as PNG buffer views. The scene holds node 0 only; node 0 carries the `MSFT_lod`
//! extension listing the coarser nodes, and `extras.MSFT_screencoverage` the switch thresholds
//! ([`screen_coverage`]), so viewers that implement `MSFT_lod` switch levels themselves and
//! others show the finest level. Every node's `extras.pleat_screen_size` records its `n_p`.
//! Samplers clamp to the edge (the atlas has no wrapping charts) with trilinear filtering.
//! The bytes depend only on the levels (PNG encoding is deterministic).

use serde_json::{json, Value};

use super::level::{BakedLevel, Image8};
use crate::{Error, Result};

/// Reference viewport height in pixels for [`screen_coverage`].
pub const REFERENCE_VIEWPORT: f64 = 1080.0;

/// The `MSFT_screencoverage` value for `n_p` pixels: the fraction of a
/// [`REFERENCE_VIEWPORT`]-pixel-high square viewport covered by a square whose side is the
/// bounding-box diagonal at `n_p` pixels, `min(1, (n_p / 1080)²)`. In the chain, level `i`
/// (finest first) gets the coverage of level `i + 1`'s `n_p` — above it the finer level `i`
/// is shown — and the coarsest level gets 0.
pub fn screen_coverage(screen_size: f64) -> f64 {
    (screen_size / REFERENCE_VIEWPORT).powi(2).min(1.0)
}

/// A GLB's binary chunk under construction with its buffer views and accessors (all in buffer
/// 0); shared with the scene writer (`super::scene`), which starts it from the input's repacked
/// views.
pub(crate) struct Bin {
    pub(crate) data: Vec<u8>,
    pub(crate) views: Vec<Value>,
    pub(crate) accessors: Vec<Value>,
}

impl Bin {
    pub(crate) fn align(&mut self) {
        self.data.resize(self.data.len().next_multiple_of(4), 0);
    }

    pub(crate) fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        self.align();
        let mut v = json!({"buffer": 0, "byteOffset": self.data.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.data.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    pub(crate) fn floats<const N: usize>(
        &mut self,
        values: &[[f32; N]],
        ty: &str,
        bounds: bool,
    ) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        let view = self.view(&bytes, Some(34962));
        let mut acc = json!({"bufferView": view, "componentType": 5126, "count": values.len(),
                             "type": ty});
        if bounds {
            let lo: Vec<f32> = (0..N)
                .map(|k| values.iter().map(|v| v[k]).fold(f32::INFINITY, f32::min))
                .collect();
            let hi: Vec<f32> = (0..N)
                .map(|k| {
                    values
                        .iter()
                        .map(|v| v[k])
                        .fold(f32::NEG_INFINITY, f32::max)
                })
                .collect();
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    pub(crate) fn indices(&mut self, tris: &[[u32; 3]]) -> usize {
        let bytes: Vec<u8> = tris
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let view = self.view(&bytes, Some(34963));
        self.accessors
            .push(json!({"bufferView": view, "componentType": 5125,
                                   "count": 3 * tris.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }
}

/// PNG bytes of an RGBA image.
pub fn png_bytes(img: &Image8) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &img.rgba,
            img.width,
            img.height,
            image::ExtendedColorType::Rgba8,
        )
        .map_err(|e| Error::Internal(format!("PNG encoding failed: {e}")))?;
    Ok(out)
}

/// Encodes the levels (any order; written finest first) as one GLB. See the
/// [module docs](self).
///
/// Errors: `InvalidArgument` for no level or a coordinate beyond `f32`; `Internal` when PNG
/// encoding fails.
pub fn chain_glb(levels: &[&BakedLevel]) -> Result<Vec<u8>> {
    chain_glb_with_progress(levels, &mut |_| true).map(|(bytes, _)| bytes)
}

/// The images of a material in the order the writer embeds them.
fn material_images(m: &super::level::BakedMaterial) -> [&Option<Image8>; 5] {
    [
        &m.base_color,
        &m.metallic_roughness,
        &m.normal,
        &m.occlusion,
        &m.emissive,
    ]
}

/// [`chain_glb`] with the PNG encoding as a progress stage (`write: png`, before and after;
/// `false` cancels with `Error::Cancelled`) and its wall seconds returned with the bytes.
/// Every image is encoded in parallel (rayon) before the file is assembled; the bytes are
/// [`chain_glb`]'s.
pub fn chain_glb_with_progress(
    levels: &[&BakedLevel],
    progress: &mut crate::report::ProgressFn<'_>,
) -> Result<(Vec<u8>, f64)> {
    use rayon::prelude::*;
    if levels.is_empty() {
        return Err(Error::InvalidArgument("no LOD level to write".into()));
    }
    let mut order: Vec<usize> = (0..levels.len()).collect();
    order.sort_by(|&a, &b| {
        levels[b]
            .screen_size
            .total_cmp(&levels[a].screen_size)
            .then(a.cmp(&b))
    });
    let stage = |progress: &mut crate::report::ProgressFn<'_>, fraction| {
        if progress(crate::report::Progress {
            stage: "write: png",
            fraction,
        }) {
            Ok(())
        } else {
            Err(Error::Cancelled)
        }
    };
    stage(progress, 0.0)?;
    let t = std::time::Instant::now();
    let all: Vec<&Image8> = order
        .iter()
        .flat_map(|&li| material_images(&levels[li].material))
        .flatten()
        .collect();
    let encoded = all
        .par_iter()
        .map(|img| png_bytes(img))
        .collect::<Result<Vec<_>>>()?;
    let png_seconds = t.elapsed().as_secs_f64();
    stage(progress, 1.0)?;
    let mut encoded = encoded.into_iter();
    let mut bin = Bin {
        data: Vec::new(),
        views: Vec::new(),
        accessors: Vec::new(),
    };
    let mut arrays = Arrays::default();
    let mut nodes = Vec::new();
    for (rank, &li) in order.iter().enumerate() {
        let level = levels[li];
        let name = format!("LOD{rank}");
        let mesh = push_level(level, &name, &mut encoded, 0, &mut bin, &mut arrays)?;
        nodes.push(json!({"name": name, "mesh": mesh,
                          "extras": {"pleat_screen_size": level.screen_size}}));
    }
    let Arrays {
        meshes,
        materials,
        images,
        textures,
    } = arrays;
    if order.len() > 1 {
        let coverage: Vec<f64> = (0..order.len())
            .map(|r| {
                order
                    .get(r + 1)
                    .map_or(0.0, |&next| screen_coverage(levels[next].screen_size))
            })
            .collect();
        nodes[0]["extensions"] = json!({"MSFT_lod": {"ids": (1..order.len()).collect::<Vec<_>>()}});
        nodes[0]["extras"]["MSFT_screencoverage"] = json!(coverage);
    }
    bin.align();
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "pleat bake"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": bin.accessors,
        "bufferViews": bin.views,
        "buffers": [{"byteLength": bin.data.len()}],
    });
    if !images.is_empty() {
        doc["images"] = json!(images);
        doc["textures"] = json!(textures);
        doc["samplers"] = json!([{"magFilter": 9729, "minFilter": 9987,
                                   "wrapS": 33071, "wrapT": 33071}]);
    }
    if order.len() > 1 {
        doc["extensionsUsed"] = json!(["MSFT_lod"]);
    }
    let out = glb_container(&doc, &bin.data)?;
    Ok((out, png_seconds))
}

/// The mesh, material, image and texture arrays of a document under construction.
#[derive(Default)]
pub(crate) struct Arrays {
    pub(crate) meshes: Vec<Value>,
    pub(crate) materials: Vec<Value>,
    pub(crate) images: Vec<Value>,
    pub(crate) textures: Vec<Value>,
}

/// The PNG bytes of every image of `levels`, in the order [`push_level`] consumes them (level
/// by level, each material's images in the writer's order), encoded in parallel.
pub(crate) fn encode_images(levels: &[&BakedLevel]) -> Result<Vec<Vec<u8>>> {
    use rayon::prelude::*;
    let all: Vec<&Image8> = levels
        .iter()
        .flat_map(|l| material_images(&l.material))
        .flatten()
        .collect();
    all.par_iter().map(|img| png_bytes(img)).collect()
}

/// Appends one baked level as a mesh (one indexed `TRIANGLES` primitive) named `name` with its
/// own material named `name` and its images (taken from `encoded`, see [`encode_images`]) as
/// PNG buffer views whose textures use sampler `sampler`. Returns the mesh index.
pub(crate) fn push_level(
    level: &BakedLevel,
    name: &str,
    encoded: &mut dyn Iterator<Item = Vec<u8>>,
    sampler: usize,
    bin: &mut Bin,
    out: &mut Arrays,
) -> Result<usize> {
    let positions: Vec<[f32; 3]> = level
        .positions
        .iter()
        .map(|p| p.map(|c| c as f32))
        .collect();
    if let Some(p) = positions.iter().find(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Error::InvalidArgument(format!(
            "vertex {p:?} exceeds the f32 range of glTF positions"
        )));
    }
    let mut attributes = serde_json::Map::new();
    attributes.insert(
        "POSITION".into(),
        json!(bin.floats(&positions, "VEC3", true)),
    );
    attributes.insert(
        "NORMAL".into(),
        json!(bin.floats(&level.normals, "VEC3", false)),
    );
    if let Some(t) = &level.tangents {
        attributes.insert("TANGENT".into(), json!(bin.floats(t, "VEC4", false)));
    }
    if let Some(uv) = &level.uvs {
        attributes.insert("TEXCOORD_0".into(), json!(bin.floats(uv, "VEC2", false)));
    }
    if let Some(c) = &level.colors {
        attributes.insert("COLOR_0".into(), json!(bin.floats(c, "VEC4", false)));
    }
    let indices = bin.indices(&level.triangles);
    let material = out.materials.len();
    out.meshes.push(json!({"name": name, "primitives": [{
        "attributes": attributes, "indices": indices, "mode": 4, "material": material}]}));
    let (images, textures) = (&mut out.images, &mut out.textures);
    let mut tex = |img: &Option<Image8>, bin: &mut Bin| -> Result<Option<usize>> {
        if img.is_none() {
            return Ok(None);
        }
        let png = encoded
            .next()
            .ok_or_else(|| Error::Internal("PNG missing for an image".into()))?;
        let view = bin.view(&png, None);
        images.push(json!({"bufferView": view, "mimeType": "image/png"}));
        textures.push(json!({"sampler": sampler, "source": images.len() - 1}));
        Ok(Some(textures.len() - 1))
    };
    let m = &level.material;
    let mut pbr = json!({
        "baseColorFactor": m.base_color_factor,
        "metallicFactor": m.metallic_factor,
        "roughnessFactor": m.roughness_factor,
    });
    if let Some(t) = tex(&m.base_color, bin)? {
        pbr["baseColorTexture"] = json!({"index": t});
    }
    if let Some(t) = tex(&m.metallic_roughness, bin)? {
        pbr["metallicRoughnessTexture"] = json!({"index": t});
    }
    let mut mat = json!({"name": name, "pbrMetallicRoughness": pbr,
                         "emissiveFactor": m.emissive_factor,
                         "doubleSided": m.double_sided});
    if let Some(t) = tex(&m.normal, bin)? {
        mat["normalTexture"] = json!({"index": t});
    }
    if let Some(t) = tex(&m.occlusion, bin)? {
        mat["occlusionTexture"] = json!({"index": t});
    }
    if let Some(t) = tex(&m.emissive, bin)? {
        mat["emissiveTexture"] = json!({"index": t});
    }
    match m.alpha_mode {
        super::appearance::AlphaMode::Opaque => {}
        super::appearance::AlphaMode::Mask => {
            mat["alphaMode"] = json!("MASK");
            mat["alphaCutoff"] = json!(m.alpha_cutoff);
        }
        super::appearance::AlphaMode::Blend => mat["alphaMode"] = json!("BLEND"),
    }
    out.materials.push(mat);
    Ok(out.meshes.len() - 1)
}

/// A GLB container (header, JSON chunk padded with spaces, BIN chunk padded with zeros when
/// `bin` is not empty). `InvalidArgument` beyond GLB's 4 GiB.
pub(crate) fn glb_container(doc: &Value, bin: &[u8]) -> Result<Vec<u8>> {
    let mut json_bytes = serde_json::to_vec(doc)
        .map_err(|e| Error::Internal(format!("glTF JSON encoding failed: {e}")))?;
    json_bytes.resize(json_bytes.len().next_multiple_of(4), b' ');
    let bin_len = bin.len().next_multiple_of(4);
    let chunk = if bin.is_empty() { 0 } else { 8 + bin_len };
    let total = 12 + 8 + json_bytes.len() + chunk;
    let total32 = u32::try_from(total)
        .map_err(|_| Error::InvalidArgument("the document exceeds GLB's 4 GiB limit".into()))?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total32.to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin_len as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(bin);
        out.resize(total, 0);
    }
    Ok(out)
}
