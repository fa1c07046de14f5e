//! Reading the appearance of a Wavefront OBJ with its MTL material library (`pleat lod in.obj
//! --bake`), through `tobj` (triangulated, one index per `v/vt/vn` corner, so per-vertex
//! attributes are exact).
//!
//! What is read, and the conventions:
//!
//! - **Materials:** every `usemtl` group becomes a triangle range of the material it names; faces
//!   before any `usemtl` get glTF's default material (white). `Kd` is the baseColor factor and
//!   `Ke` the emissive factor, both taken as **linear** RGB as written (the convention of
//!   obj2gltf and Blender's importer, which put `Kd` straight into a linear baseColor); `d`
//!   (or `1 − Tr`) is the alpha factor, blended when below 1. `metallicFactor` is 0 and
//!   `roughnessFactor` 1 (a diffuse surface).
//! - **`map_Kd`** is the baseColor texture, **sRGB**-encoded like glTF's, multiplied by `Kd`
//!   (the MTL specification: "the map_Kd value is multiplied by the Kd value"). PNG or JPEG
//!   (the decoders the crate already has); any other format is an error naming the file and
//!   the format. Options `-o u v` and `-s u v` become a texture transform, `-clamp on` the
//!   clamp wrap mode (else REPEAT); other options are skipped. Other maps (`map_Ks`, `map_d`,
//!   `bump`, ...) are not read.
//! - **Texture coordinates:** OBJ's `vt` has `v = 0` at the image's bottom row; it is stored in
//!   glTF's convention (`v = 0` top) as `(u, 1 − v)`.
//! - **Normals:** `vn` when every corner of a group has one, else the group is shaded flat (as
//!   a glTF primitive without `NORMAL`); vertex colours (`v x y z r g b`) become `COLOR_0`
//!   (linear, like `Kd`).
//! - **Paths:** `mtllib` resolves against the OBJ's folder; texture paths against the folder
//!   of the MTL that names them, then the OBJ's folder; backslashes are read as folder
//!   separators; absolute paths are not followed (their file name is looked up next to the MTL).
//!
//! A missing or unreadable MTL, a `usemtl` naming no material, a missing, unreadable,
//! undecodable, zero-sized or over-budget image, a textured group without `vt`, and non-finite
//! coordinates are errors ([`Error::Parse`]/[`Error::Io`]) naming the file, never a silent
//! white. Vertices are unwelded per group and corner index (triangle order and geometry are
//! the file's, as [`read_obj`](crate::mesh::io::obj::read_obj) gives them).

use std::cell::RefCell;
use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use super::appearance::{decode_image, AlphaMode, Appearance, Builder, Material, Texture};
use super::appearance::{TextureRef, Wrap};
use crate::geom::{normalized, Vec3};
use crate::mesh::io::{io_error, parse_error};
use crate::{Error, Result};

/// Largest image file read for `map_Kd` (1 GiB; the decoded size is bounded separately by
/// [`super::appearance::MAX_TEXTURE_TEXELS`]).
const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;

/// Reads an OBJ file's appearance with its MTL libraries and `map_Kd` images. See the
/// [module docs](self) for the conventions and errors.
pub fn read_obj_appearance(path: &Path) -> Result<Appearance> {
    let name = path.display().to_string();
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let text = std::fs::read(path).map_err(|e| io_error(&name, &e))?;
    let libraries = RefCell::new(Vec::<(PathBuf, usize)>::new());
    let mtl_error = RefCell::new(None::<Error>);
    // `..default()` keeps this compiling if tobj's optional features (which add fields) get
    // enabled elsewhere in the dependency graph.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..tobj::LoadOptions::default()
    };
    let loaded = tobj::load_obj_buf(&mut BufReader::new(&text[..]), &options, |mtl| {
        let full = dir.join(separators(&mtl.to_string_lossy()));
        let shown = full.display().to_string();
        let result = std::fs::File::open(&full)
            .map_err(|e| {
                parse_error(
                    &name,
                    format!(
                        "mtllib '{}' cannot be read: {}",
                        mtl.display(),
                        io_error(&shown, &e)
                    ),
                )
            })
            .and_then(|f| {
                tobj::load_mtl_buf(&mut BufReader::new(f))
                    .map_err(|e| parse_error(&shown, format!("MTL: {e} (tobj)")))
            });
        match result {
            Ok((mats, map)) => {
                let folder = full.parent().unwrap_or(&dir).to_path_buf();
                libraries.borrow_mut().push((folder, mats.len()));
                Ok((mats, map))
            }
            Err(e) => {
                mtl_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    });
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) =
        loaded.map_err(|e| parse_error(&name, format!("OBJ: {e} (read by tobj)")))?;
    let materials = materials.map_err(|e| parse_error(&name, format!("MTL: {e}")))?;
    check_usemtl(&text, &materials, &name)?;
    let folders = material_folders(&libraries.into_inner(), materials.len(), &dir);
    let mut reader = ObjReader {
        name: &name,
        obj_dir: &dir,
        out: Builder::default(),
        material_slots: HashMap::new(),
        texture_slots: HashMap::new(),
    };
    for model in &models {
        reader.add_model(model, &materials, &folders)?;
    }
    if reader.out.triangles.is_empty() {
        return Err(parse_error(&name, "the OBJ has no face"));
    }
    reader.out.finish(&name)
}

/// Every `usemtl` name of the OBJ text must be a material of the libraries (tobj silently
/// gives such groups no material).
fn check_usemtl(text: &[u8], materials: &[tobj::Material], name: &str) -> Result<()> {
    for (i, line) in text.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let Some(rest) = line.trim_start().strip_prefix("usemtl") else {
            continue;
        };
        if !rest.starts_with(char::is_whitespace) {
            continue;
        }
        let wanted = rest.trim();
        if !materials.iter().any(|m| m.name == wanted) {
            let known: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
            return Err(parse_error(
                name,
                format!(
                    "line {}: usemtl '{wanted}' names no material of the MTL libraries ({})",
                    i + 1,
                    if known.is_empty() {
                        "none loaded: is there an mtllib line before it?".to_string()
                    } else {
                        format!("known: {}", known.join(", "))
                    }
                ),
            ));
        }
    }
    Ok(())
}

/// The folder of the MTL that defined each material (tobj appends libraries in load order).
fn material_folders(libraries: &[(PathBuf, usize)], n: usize, obj_dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = libraries
        .iter()
        .flat_map(|(folder, count)| std::iter::repeat_n(folder.clone(), *count))
        .collect();
    out.resize(n, obj_dir.to_path_buf());
    out
}

/// A path written in an OBJ/MTL with `\` read as a folder separator.
fn separators(p: &str) -> PathBuf {
    PathBuf::from(p.replace('\\', "/"))
}

/// A `map_Kd` statement: options parsed, file name kept.
#[derive(Debug, Clone, PartialEq)]
struct MapStatement {
    file: String,
    offset: [f64; 2],
    scale: [f64; 2],
    clamp: bool,
}

/// Parses `[-option args]... file` of a texture map statement (MTL specification options;
/// `-o`/`-s`/`-t` take one to three numbers, the others one or two arguments).
fn parse_map(statement: &str) -> std::result::Result<MapStatement, String> {
    let toks: Vec<&str> = statement.split_whitespace().collect();
    let mut m = MapStatement {
        file: String::new(),
        offset: [0.0; 2],
        scale: [1.0; 2],
        clamp: false,
    };
    let mut i = 0;
    while i < toks.len() && toks[i].starts_with('-') && toks[i].len() > 1 {
        let opt = toks[i];
        i += 1;
        match opt {
            "-o" | "-s" | "-t" => {
                let mut v = Vec::new();
                while v.len() < 3 && i < toks.len() - 1 {
                    match toks[i].parse::<f64>() {
                        Ok(x) if x.is_finite() => v.push(x),
                        _ => break,
                    }
                    i += 1;
                }
                if v.is_empty() {
                    return Err(format!("option {opt} needs numbers"));
                }
                let uv = [
                    v[0],
                    v.get(1)
                        .copied()
                        .unwrap_or(if opt == "-s" { 1.0 } else { 0.0 }),
                ];
                match opt {
                    "-o" => m.offset = uv,
                    "-s" => m.scale = uv,
                    _ => {}
                }
            }
            "-mm" => i += 2,
            "-clamp" => {
                m.clamp = toks.get(i) == Some(&"on");
                i += 1;
            }
            _ => i += 1,
        }
    }
    if i >= toks.len() {
        return Err("no file name".into());
    }
    m.file = toks[i..].join(" ");
    Ok(m)
}

struct ObjReader<'a> {
    name: &'a str,
    obj_dir: &'a Path,
    out: Builder,
    /// tobj material index (`None` = default material) → index in `out.materials`.
    material_slots: HashMap<Option<usize>, u32>,
    /// (resolved image file, wrap) → index in `out.textures`.
    texture_slots: HashMap<(PathBuf, Wrap), usize>,
}

impl ObjReader<'_> {
    fn err(&self, reason: impl Into<String>) -> Error {
        parse_error(self.name, reason)
    }

    /// Appends one tobj model (a group of one material).
    fn add_model(
        &mut self,
        model: &tobj::Model,
        materials: &[tobj::Material],
        folders: &[PathBuf],
    ) -> Result<()> {
        let mesh = &model.mesh;
        let n = mesh.positions.len() / 3;
        if mesh.indices.is_empty() {
            return Ok(());
        }
        let what = format!("object '{}'", model.name);
        let mat = self.material(mesh.material_id, materials, folders)?;
        let base = self.out.positions.len();
        for (i, p) in mesh.positions.chunks_exact(3).enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(self.err(format!("{what}: vertex {i} has a non-finite coordinate")));
            }
            self.out.positions.push([p[0], p[1], p[2]]);
        }
        // Texture coordinates: (u, 1 − v), glTF's v = 0 at the top.
        let has_uv = !mesh.texcoords.is_empty();
        if has_uv && mesh.texcoords.len() != 2 * n {
            return Err(self.err(format!(
                "{what}: some faces have texture coordinates (vt) and some do not"
            )));
        }
        if let Some(i) = mesh.texcoords.iter().position(|x| !x.is_finite()) {
            return Err(self.err(format!(
                "{what}: texture coordinate of vertex {} is not finite",
                i / 2
            )));
        }
        let textured = self.out.materials[mat as usize].base_color.is_some();
        if textured && !has_uv {
            return Err(self.err(format!(
                "{what}: its material has a map_Kd texture but its faces have no texture \
                 coordinates (vt)"
            )));
        }
        if has_uv || !self.out.uvs.is_empty() {
            if self.out.uvs.is_empty() {
                self.out.uvs.push(vec![[f64::NAN; 2]; base]);
            }
            let uvs = &mut self.out.uvs[0];
            if has_uv {
                uvs.extend(mesh.texcoords.chunks_exact(2).map(|c| [c[0], 1.0 - c[1]]));
            } else {
                uvs.resize(base + n, [f64::NAN; 2]);
            }
        }
        // Normals: all or flat.
        let smooth = mesh.normals.len() == 3 * n;
        for i in 0..n {
            let v = if smooth {
                let c = &mesh.normals[3 * i..3 * i + 3];
                normalized(Vec3::new(c[0], c[1], c[2])).unwrap_or(Vec3::ZERO)
            } else {
                Vec3::ZERO
            };
            self.out.normals.push(v.to_array());
        }
        self.out.tangents.resize(base + n, [0.0; 4]);
        // Vertex colours.
        if mesh.vertex_color.len() == 3 * n {
            self.out.any_color = true;
            self.out.colors.extend(
                mesh.vertex_color
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2], 1.0]),
            );
        } else {
            self.out.colors.resize(base + n, [1.0; 4]);
        }
        for t in mesh.indices.chunks_exact(3) {
            if let Some(&i) = t.iter().find(|&&i| i as usize >= n) {
                return Err(self.err(format!("{what}: corner index {i} is out of range")));
            }
            let off = base as u32;
            self.out
                .triangles
                .push([t[0] + off, t[1] + off, t[2] + off]);
            self.out.triangle_material.push(mat);
            self.out.triangle_flat.push(!smooth);
        }
        Ok(())
    }

    /// The appearance material of tobj material `id`, read once.
    fn material(
        &mut self,
        id: Option<usize>,
        materials: &[tobj::Material],
        folders: &[PathBuf],
    ) -> Result<u32> {
        if let Some(&i) = self.material_slots.get(&id) {
            return Ok(i);
        }
        let material = match id.and_then(|i| materials.get(i).map(|m| (i, m))) {
            None => Material::default(),
            Some((i, m)) => self.convert(m, &folders[i])?,
        };
        let i = self.out.materials.len() as u32;
        self.out.materials.push(material);
        self.material_slots.insert(id, i);
        Ok(i)
    }

    /// An MTL material as a metallic-roughness one (see the [module docs](self)).
    fn convert(&mut self, m: &tobj::Material, folder: &Path) -> Result<Material> {
        let what = format!("material '{}'", m.name);
        let kd = m.diffuse.unwrap_or([1.0; 3]);
        let alpha = match (m.dissolve, m.unknown_param.get("Tr")) {
            (Some(d), _) => d,
            (None, Some(tr)) => 1.0 - tr.trim().parse::<f64>().unwrap_or(0.0),
            (None, None) => 1.0,
        };
        let factor = [kd[0], kd[1], kd[2], alpha];
        let emissive = m.emissive.unwrap_or([0.0; 3]);
        if !factor.iter().chain(&emissive).all(|x| x.is_finite()) {
            return Err(self.err(format!("{what}: Kd, Ke or d is not finite")));
        }
        let base_color = match &m.diffuse_texture {
            Some(stmt) => Some(self.texture(stmt, folder, &what)?),
            None => None,
        };
        Ok(Material {
            base_color_factor: factor,
            base_color,
            metallic_factor: 0.0,
            roughness_factor: 1.0,
            emissive_factor: emissive,
            alpha_mode: if alpha < 1.0 {
                AlphaMode::Blend
            } else {
                AlphaMode::Opaque
            },
            ..Material::default()
        })
    }

    /// The `map_Kd` texture reference of `statement` (image read and decoded once per file).
    fn texture(&mut self, statement: &str, folder: &Path, what: &str) -> Result<TextureRef> {
        let map = parse_map(statement)
            .map_err(|e| self.err(format!("{what}: map_Kd '{statement}': {e}")))?;
        let path = self.resolve(&map.file, folder, what)?;
        let wrap = if map.clamp { Wrap::Clamp } else { Wrap::Repeat };
        let key = (path.clone(), wrap);
        let texture = match self.texture_slots.get(&key) {
            Some(&i) => i,
            None => {
                let shown = path.display().to_string();
                let len = std::fs::metadata(&path)
                    .map_err(|e| io_error(&shown, &e))?
                    .len();
                if len > MAX_IMAGE_FILE_BYTES {
                    return Err(Error::LimitExceeded(format!(
                        "{}: {what}: map_Kd '{shown}' holds {len} bytes, more than the \
                         {MAX_IMAGE_FILE_BYTES}-byte limit",
                        self.name
                    )));
                }
                let bytes = std::fs::read(&path).map_err(|e| io_error(&shown, &e))?;
                let (width, height, texels) = decode_image(&bytes, true)
                    .map_err(|e| self.err(format!("{what}: map_Kd '{shown}': {e}")))?;
                self.out.textures.push(Texture {
                    width,
                    height,
                    texels,
                    wrap_s: wrap,
                    wrap_t: wrap,
                });
                self.texture_slots.insert(key, self.out.textures.len() - 1);
                self.out.textures.len() - 1
            }
        };
        let [su, sv] = map.scale;
        let [ou, ov] = map.offset;
        Ok(TextureRef {
            texture,
            tex_coord: 0,
            // OBJ space uv' = s·uv + o, with v stored flipped (v_gltf = 1 − v_obj).
            transform: [[su, 0.0, ou], [0.0, sv, 1.0 - sv - ov]],
            scale: 1.0,
        })
    }

    /// The image file of a texture statement: next to the MTL, then next to the OBJ; an
    /// absolute path only by its file name.
    fn resolve(&self, file: &str, folder: &Path, what: &str) -> Result<PathBuf> {
        let rel = separators(file);
        let mut tried = Vec::new();
        let mut candidates = Vec::new();
        if rel.is_absolute() || rel.has_root() {
            if let Some(base) = rel.file_name() {
                candidates.push(folder.join(base));
            }
        } else {
            candidates.push(folder.join(&rel));
            if folder != self.obj_dir {
                candidates.push(self.obj_dir.join(&rel));
            }
        }
        for c in candidates {
            if c.is_file() {
                return Ok(c);
            }
            tried.push(format!("'{}'", c.display()));
        }
        Err(self.err(format!(
            "{what}: map_Kd image '{file}' is missing (looked for {})",
            if tried.is_empty() {
                "nothing: no file name".to_string()
            } else {
                tried.join(", ")
            }
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_options_are_parsed() {
        let m = parse_map("-s 2 3 1 -o 0.5 0.25 -clamp on -bm 0.3 my tex.png").unwrap();
        assert_eq!(m.file, "my tex.png");
        assert_eq!(m.scale, [2.0, 3.0]);
        assert_eq!(m.offset, [0.5, 0.25]);
        assert!(m.clamp);
        let plain = parse_map("tex.jpg").unwrap();
        assert_eq!(plain.file, "tex.jpg");
        assert_eq!(
            (plain.scale, plain.offset, plain.clamp),
            ([1.0; 2], [0.0; 2], false)
        );
        assert!(parse_map("-s 2").is_err());
    }

    #[test]
    fn flipped_transform_matches_obj_space() {
        // uv_obj' = s uv_obj + o; stored v_g = 1 − v_obj; sampled v must be 1 − v_obj'.
        let (s, o) = ([2.0, 3.0], [0.5, 0.25]);
        let r = TextureRef {
            texture: 0,
            tex_coord: 0,
            transform: [[s[0], 0.0, o[0]], [0.0, s[1], 1.0 - s[1] - o[1]]],
            scale: 1.0,
        };
        let (u, v) = (0.3, 0.8);
        let got = r.apply([u, 1.0 - v]);
        assert!((got[0] - (s[0] * u + o[0])).abs() < 1e-12);
        assert!((got[1] - (1.0 - (s[1] * v + o[1]))).abs() < 1e-12);
    }
}
