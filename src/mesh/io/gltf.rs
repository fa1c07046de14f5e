//! glTF 2.0 reading and writing (`.glb` and `.gltf`; feature `io-gltf`).
//!
//! # Reading
//!
//! Every mesh primitive of mode `TRIANGLES`, `TRIANGLE_STRIP` or `TRIANGLE_FAN` is read, indexed
//! or not (primitives of other modes, or without `POSITION`, are skipped), and instantiated
//! through the node hierarchy of the default scene (the document's `scene`, else its first
//! scene) with each node's world transform applied, in depth-first order. A document without
//! scenes gives every mesh once, untransformed. Everything is merged into one soup; no vertex is
//! welded. Strips give `(v_i, v_{i+1+i%2}, v_{i+2-i%2})`, fans `(v_0, v_{i+1}, v_{i+2})`, as the
//! specification says. Under a world transform with negative determinant the winding is
//! reversed, so that triangles keep their front side (the specification makes such instances
//! clockwise).
//!
//! At most 2²⁸ vertices plus triangles are instantiated (instancing multiplies the stored
//! geometry, so the file size alone does not bound the result); beyond that reading fails.
//!
//! Buffers come from the GLB `BIN` chunk, `data:` URIs (base64), or files relative to the
//! `.gltf` file's folder (never absolute paths or other URI schemes; at most the declared
//! `byteLength` is read). Accessors may be strided, sparse, or quantized (integer positions,
//! normalized or not). The `gltf` crate parses and validates the JSON; the accessor data is
//! decoded here with every offset checked, so a malformed file gives an error, never a panic.
//!
//! # Writing
//!
//! One mesh with one indexed `TRIANGLES` primitive in one node of one scene: `f32` positions
//! (glTF has no `f64` vertex attribute, so coordinates are rounded to the nearest `f32`: about 7
//! significant digits, a relative precision of 6·10⁻⁸) with `min`/`max` set, and `u32`
//! indices. [`glb_bytes`] writes binary glTF; [`gltf_embedded_string`] writes JSON glTF with the
//! buffer embedded as a base64 `data:` URI.

use std::fs::File;
use std::io::Read;
use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::buffer::Source;
use ::gltf::mesh::Mode;
use ::gltf::{Accessor, Document, Gltf, Semantic};

use super::{build_mesh, io_error, parse_error, push_vertex, NodeFilter, MAX_RESERVE};
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// Reads a `.glb` or `.gltf` file; external buffers are resolved relative to its folder.
/// See the [module docs](self).
///
/// Errors with [`Error::Io`] when a file cannot be read and [`Error::Parse`] when the content
/// is malformed or has no triangle.
pub fn read_gltf(path: &Path) -> Result<TriMesh> {
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| io_error(&name, &e))?;
    let base = path.parent().unwrap_or(Path::new("."));
    read_gltf_bytes(&data, Some(base), &name)
}

/// Reads binary (GLB) or JSON glTF from memory; `name` stands for the file in error messages.
/// External buffer files are resolved relative to `base_dir`; with `None`, only the GLB `BIN`
/// chunk and `data:` URIs are available.
pub fn read_gltf_bytes(data: &[u8], base_dir: Option<&Path>, name: &str) -> Result<TriMesh> {
    read_gltf_bytes_selected(data, base_dir, name, None)
}

/// Reads a `.glb` or `.gltf` file as [`read_gltf`] does, instancing only the nodes `filter`
/// selects (matched nodes and their subtrees, see [`NodeFilter`]); `None` reads every node.
/// Errors as [`read_gltf`], plus `InvalidArgument` when the filter matches no node.
pub fn read_gltf_selected(path: &Path, filter: Option<&NodeFilter>) -> Result<TriMesh> {
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| io_error(&name, &e))?;
    let base = path.parent().unwrap_or(Path::new("."));
    read_gltf_bytes_selected(&data, Some(base), &name, filter)
}

/// [`read_gltf_bytes`] with a node filter (see [`read_gltf_selected`]).
pub fn read_gltf_bytes_selected(
    data: &[u8],
    base_dir: Option<&Path>,
    name: &str,
    filter: Option<&NodeFilter>,
) -> Result<TriMesh> {
    check_glb_header(data, name)?;
    let gltf = Gltf::from_slice_without_validation(data)
        .map_err(|e| parse_error(name, format!("glTF: {e}")))?;
    let Gltf { document, blob } = gltf;
    validate(&document, name)?;
    let buffers = load_buffers(&document, blob, base_dir, name)?;
    let mut soup = Soup::default();
    let ctx = Ctx {
        buffers: &buffers,
        name,
    };
    for_each_primitive(&document, name, filter, &mut |prim, pos, world, what| {
        add_primitive(prim, pos, world, what, &ctx, &mut soup)
    })?;
    build_mesh(name, soup.positions, soup.triangles)
}

/// Encodes `mesh` as binary glTF (GLB): `f32` positions, `u32` indices (see the
/// [module docs](self) for the precision loss).
///
/// Errors with [`Error::InvalidArgument`] when a coordinate exceeds the `f32` range or the
/// result would exceed GLB's 4 GiB limit.
pub fn glb_bytes(mesh: &TriMesh) -> Result<Vec<u8>> {
    let bin = binary_buffer(mesh)?;
    let mut json = document_json(mesh, None).into_bytes();
    pad_to_four(&mut json, b' ');
    let bin_len = bin.len().next_multiple_of(4);
    let total = 12 + 8 + json.len() + 8 + bin_len;
    let total32 = u32::try_from(total)
        .map_err(|_| Error::InvalidArgument("the mesh exceeds GLB's 4 GiB size limit".into()))?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total32.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin_len as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out.resize(total, 0);
    Ok(out)
}

/// Encodes `mesh` as JSON glTF with its buffer embedded as a base64 `data:` URI: `f32`
/// positions, `u32` indices (see the [module docs](self) for the precision loss).
///
/// Errors with [`Error::InvalidArgument`] when a coordinate exceeds the `f32` range.
pub fn gltf_embedded_string(mesh: &TriMesh) -> Result<String> {
    let bin = binary_buffer(mesh)?;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64_encode(&bin)
    );
    Ok(document_json(mesh, Some(&uri)))
}

// ---------------------------------------------------------------------------------- reading --

/// Most vertices plus triangles a document may instantiate (2²⁸, about 3 GiB of mesh): node
/// instancing multiplies stored geometry, so the file size does not bound the result.
const MAX_INSTANCED: usize = 1 << 28;

/// Column-major 4×4 matrix, `m[column][row]`.
type Mat4 = [[f64; 4]; 4];

const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

#[derive(Default)]
struct Soup {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

struct Ctx<'a> {
    buffers: &'a [Vec<u8>],
    name: &'a str,
}

impl Ctx<'_> {
    fn err(&self, reason: impl Into<String>) -> Error {
        parse_error(self.name, reason)
    }
}

/// `gltf` computes `header.length - 12` unchecked; reject such headers first.
fn check_glb_header(data: &[u8], name: &str) -> Result<()> {
    if !data.starts_with(b"glTF") {
        return Ok(());
    }
    let length = data
        .get(8..12)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    match length {
        Some(len) if len >= 12 && len as usize <= data.len() => Ok(()),
        Some(len) => Err(parse_error(
            name,
            format!(
                "GLB header declares {len} bytes but the file has {}",
                data.len()
            ),
        )),
        None => Err(parse_error(name, "GLB file truncated in its header")),
    }
}

/// Required extensions that change nothing this reader uses (materials, textures, lights), plus
/// `KHR_mesh_quantization`, which it implements.
fn extension_is_readable(ext: &str) -> bool {
    ext.starts_with("KHR_materials_")
        || ext.starts_with("KHR_texture_")
        || matches!(
            ext,
            "KHR_mesh_quantization"
                | "KHR_lights_punctual"
                | "KHR_xmp_json_ld"
                | "EXT_texture_webp"
                | "EXT_texture_avif"
                | "MSFT_texture_dds"
        )
}

/// The `gltf` crate's validation (which keeps its accessors from panicking), except that
/// required extensions are judged by [`extension_is_readable`] instead of by the crate's own
/// list; any other required extension (Draco or meshopt compression, GPU instancing, ...) is an
/// error, since ignoring it would silently give the wrong geometry.
fn validate(doc: &Document, name: &str) -> Result<()> {
    use ::gltf::json::validation::Validate;
    let root = doc.as_json();
    if let Some(ext) = root
        .extensions_required
        .iter()
        .find(|e| !extension_is_readable(e))
    {
        return Err(parse_error(
            name,
            format!("the file requires glTF extension {ext}, which pleat cannot read"),
        ));
    }
    check_attribute_indices(root, name)?;
    let mut first_error = None;
    root.validate(root, ::gltf::json::Path::new, &mut |path, error| {
        let path = path();
        if first_error.is_none() && !path.as_str().starts_with("extensionsRequired") {
            first_error = Some(format!("invalid glTF: {path}: {error:?}"));
        }
    });
    first_error.map_or(Ok(()), |e| Err(parse_error(name, e)))
}

/// Checks that every primitive attribute names an existing accessor. gltf-json 1.4's
/// validation indexes `accessors` with the POSITION index unchecked and panics on an
/// out-of-range one (found by `fuzz/fuzz_targets/gltf.rs`), so this runs before it.
fn check_attribute_indices(root: &::gltf::json::Root, name: &str) -> Result<()> {
    let n = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(bad) = prim.attributes.values().find(|a| a.value() >= n) {
                return Err(parse_error(
                    name,
                    format!(
                        "invalid glTF: mesh {m} primitive {p}: attribute accessor {} does not \
                         exist ({n} accessors)",
                        bad.value()
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn load_buffers(
    doc: &Document,
    mut blob: Option<Vec<u8>>,
    base: Option<&Path>,
    name: &str,
) -> Result<Vec<Vec<u8>>> {
    let mut buffers = Vec::new();
    for buffer in doc.buffers() {
        let length = buffer.length();
        let data = match buffer.source() {
            Source::Bin => blob.take().ok_or_else(|| {
                parse_error(
                    name,
                    format!(
                        "buffer {} refers to a missing GLB BIN chunk",
                        buffer.index()
                    ),
                )
            })?,
            Source::Uri(uri) if uri.starts_with("data:") => {
                decode_data_uri(uri).ok_or_else(|| {
                    parse_error(
                        name,
                        format!("buffer {}: malformed base64 data URI", buffer.index()),
                    )
                })?
            }
            Source::Uri(uri) => read_external(uri, length, base, name)?,
        };
        if data.len() < length {
            return Err(parse_error(
                name,
                format!(
                    "buffer {} declares {length} bytes but holds only {}",
                    buffer.index(),
                    data.len()
                ),
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Reads at most `length` bytes of an external buffer file relative to `base`.
fn read_external(uri: &str, length: usize, base: Option<&Path>, name: &str) -> Result<Vec<u8>> {
    let relative = percent_decode(uri)
        .ok_or_else(|| parse_error(name, format!("malformed buffer URI '{uri}'")))?;
    let has_scheme = relative
        .split_once(':')
        .is_some_and(|(scheme, _)| !scheme.contains('/'));
    if has_scheme || Path::new(&relative).is_absolute() {
        return Err(parse_error(
            name,
            format!("buffer URI '{uri}' is not a relative file path (unsupported)"),
        ));
    }
    let base = base.ok_or_else(|| {
        parse_error(
            name,
            format!("external buffer '{uri}' cannot be resolved when reading from memory"),
        )
    })?;
    let path = base.join(&relative);
    let shown = path.display().to_string();
    let file = File::open(&path).map_err(|e| io_error(&shown, &e))?;
    let meta = file.metadata().map_err(|e| io_error(&shown, &e))?;
    if !meta.is_file() || meta.len() < length as u64 {
        return Err(parse_error(
            name,
            format!("external buffer '{shown}' is not a file of at least {length} bytes"),
        ));
    }
    let mut data = Vec::with_capacity(length);
    file.take(length as u64)
        .read_to_end(&mut data)
        .map_err(|e| io_error(&shown, &e))?;
    Ok(data)
}

/// Visits every mesh primitive the document instantiates, in the reader's order (see the
/// [module docs](self)): the default scene (else the first) depth-first with each node's world
/// transform, or every mesh once untransformed when there is no scene. Primitives without
/// `POSITION` or of a mode other than `TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN` are
/// skipped; a non-`VEC3` `POSITION` or a node reached twice is an error naming `name`.
/// `visit` gets the primitive, its `POSITION` accessor, the world matrix and a
/// "mesh M primitive P" label. The geometry reader and `bake::appearance` both walk with this.
/// With a `filter`, only the meshes of selected nodes are visited (a document without scenes
/// then has no node to select: every mesh is still visited once, untransformed, when some node
/// matches; the filter's error otherwise).
pub(crate) fn for_each_primitive(
    doc: &Document,
    name: &str,
    filter: Option<&NodeFilter>,
    visit: &mut dyn FnMut(&::gltf::Primitive, &Accessor, &Mat4, &str) -> Result<()>,
) -> Result<()> {
    let selected = filter.map(|f| select_nodes(doc, f)).transpose()?;
    let mut mesh_primitives = |mesh: &::gltf::Mesh, world: &Mat4| -> Result<()> {
        visit_mesh(mesh, world, name, &mut *visit)
    };
    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        for mesh in doc.meshes() {
            mesh_primitives(&mesh, &IDENTITY)?;
        }
        return Ok(());
    };
    let is_selected = |node: &::gltf::Node| selected.as_ref().is_none_or(|s| s[node.index()]);
    let mut visited = vec![false; doc.nodes().len()];
    let mut stack: Vec<(::gltf::Node, Mat4)> = scene.nodes().map(|n| (n, IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(parse_error(
                name,
                format!(
                    "node {} is reached twice from scene {}: the node hierarchy is not a tree",
                    node.index(),
                    scene.index()
                ),
            ));
        }
        let world = mul(&parent, &to_f64(node.transform().matrix()));
        if let Some(mesh) = node.mesh().filter(|_| is_selected(&node)) {
            mesh_primitives(&mesh, &world)?;
        }
        let first_child = stack.len();
        stack.extend(node.children().map(|c| (c, world)));
        stack[first_child..].reverse();
    }
    Ok(())
}

/// The nodes of `doc` that `filter` selects (by name or `#index`, with their subtrees).
fn select_nodes(doc: &Document, filter: &NodeFilter) -> Result<Vec<bool>> {
    let names: Vec<Option<&str>> = doc.nodes().map(|n| n.name()).collect();
    let children: Vec<Vec<usize>> = doc
        .nodes()
        .map(|n| n.children().map(|c| c.index()).collect())
        .collect();
    filter.select(&names, &children)
}

/// The primitives of one mesh that [`for_each_primitive`] visits (triangle modes with a `VEC3`
/// `POSITION`), in order, each with `world`.
fn visit_mesh(
    mesh: &::gltf::Mesh,
    world: &Mat4,
    name: &str,
    visit: &mut dyn FnMut(&::gltf::Primitive, &Accessor, &Mat4, &str) -> Result<()>,
) -> Result<()> {
    for prim in mesh.primitives() {
        let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
        let Some(pos) = prim.get(&Semantic::Positions) else {
            continue;
        };
        if !matches!(
            prim.mode(),
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            continue;
        }
        if pos.dimensions() != Dimensions::Vec3 {
            return Err(parse_error(name, format!("{what}: POSITION is not VEC3")));
        }
        visit(&prim, &pos, world, &what)?;
    }
    Ok(())
}

/// Visits the triangle primitives of glTF mesh `mesh` alone, untransformed (its local space),
/// with the same filter and labels as [`for_each_primitive`].
#[cfg(feature = "bake")]
pub(crate) fn for_each_mesh_primitive(
    doc: &Document,
    mesh: usize,
    name: &str,
    visit: &mut dyn FnMut(&::gltf::Primitive, &Accessor, &Mat4, &str) -> Result<()>,
) -> Result<()> {
    let m = doc
        .meshes()
        .nth(mesh)
        .ok_or_else(|| parse_error(name, format!("mesh {mesh} does not exist")))?;
    visit_mesh(&m, &IDENTITY, name, visit)
}

/// The triangles of glTF mesh `mesh` in its local space: its triangle primitives in order,
/// unwelded, exactly the triangles [`read_gltf_bytes`] gives for one instance under an identity
/// transform. `Err(Parse)` when the mesh has no triangle.
#[cfg(feature = "bake")]
pub(crate) fn mesh_geometry(loaded: &LoadedDocument, mesh: usize, name: &str) -> Result<TriMesh> {
    let mut soup = Soup::default();
    let ctx = Ctx {
        buffers: &loaded.buffers,
        name,
    };
    for_each_mesh_primitive(
        &loaded.document,
        mesh,
        name,
        &mut |prim, pos, world, what| add_primitive(prim, pos, world, what, &ctx, &mut soup),
    )?;
    build_mesh(name, soup.positions, soup.triangles)
}

/// Appends one primitive (world transform applied) to the soup.
fn add_primitive(
    prim: &::gltf::Primitive,
    pos: &Accessor,
    world: &Mat4,
    what: &str,
    ctx: &Ctx,
    soup: &mut Soup,
) -> Result<()> {
    let values = read_accessor(pos, ctx, what)?;
    let base = soup.positions.len();
    let n_indices = prim.indices().map_or(pos.count(), |a| a.count());
    if base + pos.count() + soup.triangles.len() + n_indices > MAX_INSTANCED {
        return Err(ctx.err(format!(
            "{what}: instancing would create more than {MAX_INSTANCED} vertices and triangles"
        )));
    }
    for (i, p) in values.chunks_exact(3).enumerate() {
        let q = transform(world, [p[0], p[1], p[2]]);
        push_vertex(&mut soup.positions, q, ctx.name, || {
            format!("{what} vertex {i}")
        })?;
    }
    let indices = match prim.indices() {
        Some(acc) => read_indices(&acc, pos.count(), ctx, what)?,
        None => (0..pos.count() as u32).collect(),
    };
    let flip = det3(world) < 0.0;
    let offset = base as u32;
    triangulate(prim.mode(), &indices, |t| {
        let [a, b, c] = t.map(|i| i + offset);
        soup.triangles
            .push(if flip { [a, c, b] } else { [a, b, c] });
    });
    Ok(())
}

/// Emits the triangles of a `TRIANGLES`, `TRIANGLE_STRIP` or `TRIANGLE_FAN` index list.
fn triangulate(mode: Mode, idx: &[u32], mut emit: impl FnMut([u32; 3])) {
    match mode {
        Mode::Triangles => idx.chunks_exact(3).for_each(|t| emit([t[0], t[1], t[2]])),
        Mode::TriangleStrip => {
            for i in 0..idx.len().saturating_sub(2) {
                let odd = i % 2;
                emit([idx[i], idx[i + 1 + odd], idx[i + 2 - odd]]);
            }
        }
        Mode::TriangleFan => {
            for i in 1..idx.len().saturating_sub(1) {
                emit([idx[0], idx[i], idx[i + 1]]);
            }
        }
        _ => {}
    }
}

fn read_indices(acc: &Accessor, n_vertices: usize, ctx: &Ctx, what: &str) -> Result<Vec<u32>> {
    if acc.dimensions() != Dimensions::Scalar
        || acc.normalized()
        || !matches!(
            acc.data_type(),
            DataType::U8 | DataType::U16 | DataType::U32
        )
    {
        return Err(ctx.err(format!("{what}: indices must be unsigned integer scalars")));
    }
    let values = read_accessor(acc, ctx, what)?;
    values
        .iter()
        .map(|&v| {
            if v < n_vertices as f64 {
                Ok(v as u32)
            } else {
                Err(ctx.err(format!(
                    "{what}: index {v} is out of range ({n_vertices} vertices)"
                )))
            }
        })
        .collect()
}

/// The accessor's `count × components` values as `f64`, with byte stride, normalization and
/// sparse substitution applied, every offset checked against the buffers.
fn read_accessor(acc: &Accessor, ctx: &Ctx, what: &str) -> Result<Vec<f64>> {
    let dims = acc.dimensions().multiplicity();
    let ty = acc.data_type();
    let elem = ty.size() * dims;
    let count = acc.count();
    let mut out = match acc.view() {
        Some(view) => {
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(ctx.err(format!(
                    "{what}: byte stride {stride} is smaller than an element ({elem} bytes)"
                )));
            }
            let data = view_slice(&view, acc.offset(), count, stride, elem, ctx, what)?;
            let mut out = Vec::with_capacity(count * dims);
            for i in 0..count {
                let e = &data[i * stride..i * stride + elem];
                out.extend(
                    e.chunks_exact(ty.size())
                        .map(|c| decode(c, ty, acc.normalized())),
                );
            }
            out
        }
        None if count <= MAX_RESERVE => vec![0.0; count * dims],
        None => {
            return Err(ctx.err(format!(
                "{what}: accessor of {count} elements has no buffer view"
            )))
        }
    };
    if let Some(sparse) = acc.sparse() {
        apply_sparse(&sparse, &mut out, acc, ctx, what)?;
    }
    Ok(out)
}

fn apply_sparse(
    sparse: &::gltf::accessor::sparse::Sparse,
    out: &mut [f64],
    acc: &Accessor,
    ctx: &Ctx,
    what: &str,
) -> Result<()> {
    let dims = acc.dimensions().multiplicity();
    let ty = acc.data_type();
    let elem = ty.size() * dims;
    let n = sparse.count();
    let (indices, values) = (sparse.indices(), sparse.values());
    let index_size = indices.index_type().size();
    let index_type = match index_size {
        1 => DataType::U8,
        2 => DataType::U16,
        _ => DataType::U32,
    };
    let idx = view_slice(
        &indices.view(),
        indices.offset(),
        n,
        index_size,
        index_size,
        ctx,
        what,
    )?;
    let val = view_slice(&values.view(), values.offset(), n, elem, elem, ctx, what)?;
    for k in 0..n {
        let target = decode(
            &idx[k * index_size..(k + 1) * index_size],
            index_type,
            false,
        ) as usize;
        if target >= acc.count() {
            return Err(ctx.err(format!(
                "{what}: sparse index {target} is out of range ({} elements)",
                acc.count()
            )));
        }
        let src = val[k * elem..(k + 1) * elem].chunks_exact(ty.size());
        for (slot, c) in out[target * dims..(target + 1) * dims].iter_mut().zip(src) {
            *slot = decode(c, ty, acc.normalized());
        }
    }
    Ok(())
}

/// The bytes of `count` elements of `elem` bytes every `stride` bytes from `offset` in `view`,
/// checked against the view and its buffer. Element `i` starts at `i * stride`.
fn view_slice<'b>(
    view: &::gltf::buffer::View,
    offset: usize,
    count: usize,
    stride: usize,
    elem: usize,
    ctx: &Ctx<'b>,
    what: &str,
) -> Result<&'b [u8]> {
    let buffer = ctx
        .buffers
        .get(view.buffer().index())
        .ok_or_else(|| ctx.err(format!("{what}: missing buffer")))?;
    let view_end = view.offset().checked_add(view.length());
    let view_data = view_end
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            ctx.err(format!(
                "{what}: buffer view {} exceeds its buffer",
                view.index()
            ))
        })?;
    let needed = match count {
        0 => Some(0),
        _ => stride
            .checked_mul(count - 1)
            .and_then(|b| b.checked_add(elem)),
    };
    needed
        .and_then(|len| offset.checked_add(len))
        .and_then(|end| view_data.get(offset..end))
        .ok_or_else(|| {
            ctx.err(format!(
                "{what}: {count} elements of {elem} bytes at offset {offset} exceed buffer view {}",
                view.index()
            ))
        })
}

/// Decodes one little-endian component (`c.len() == ty.size()`).
fn decode(c: &[u8], ty: DataType, normalized: bool) -> f64 {
    let b = |i: usize| c.get(i).copied().unwrap_or(0);
    match (ty, normalized) {
        (DataType::F32, _) => f64::from(f32::from_le_bytes([b(0), b(1), b(2), b(3)])),
        (DataType::U32, _) => f64::from(u32::from_le_bytes([b(0), b(1), b(2), b(3)])),
        (DataType::I8, false) => f64::from(b(0) as i8),
        (DataType::I8, true) => (f64::from(b(0) as i8) / 127.0).max(-1.0),
        (DataType::U8, false) => f64::from(b(0)),
        (DataType::U8, true) => f64::from(b(0)) / 255.0,
        (DataType::I16, false) => f64::from(i16::from_le_bytes([b(0), b(1)])),
        (DataType::I16, true) => (f64::from(i16::from_le_bytes([b(0), b(1)])) / 32767.0).max(-1.0),
        (DataType::U16, false) => f64::from(u16::from_le_bytes([b(0), b(1)])),
        (DataType::U16, true) => f64::from(u16::from_le_bytes([b(0), b(1)])) / 65535.0,
    }
}

fn to_f64(m: [[f32; 4]; 4]) -> Mat4 {
    m.map(|col| col.map(f64::from))
}

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut r = [[0.0; 4]; 4];
    for (c, col) in r.iter_mut().enumerate() {
        for (row, x) in col.iter_mut().enumerate() {
            *x = (0..4).map(|k| a[k][row] * b[c][k]).sum();
        }
    }
    r
}

fn transform(m: &Mat4, p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|row| m[0][row] * p[0] + m[1][row] * p[1] + m[2][row] * p[2] + m[3][row])
}

/// Determinant of the linear (upper-left 3×3) part.
fn det3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

// ------------------------------------------------------- hooks for the appearance reader --

/// A validated document and its buffers, as [`read_gltf_bytes`] loads them (used by
/// `bake::appearance`, which reads materials, attributes and images on top of them).
#[cfg(feature = "bake")]
pub(crate) struct LoadedDocument {
    /// The parsed document (validated as the geometry reader validates it).
    pub document: Document,
    /// Buffer contents, indexed like the document's buffers.
    pub buffers: Vec<Vec<u8>>,
}

/// Parses, validates and loads the buffers of a glTF/GLB exactly as [`read_gltf_bytes`] does.
#[cfg(feature = "bake")]
pub(crate) fn load_document(
    data: &[u8],
    base_dir: Option<&Path>,
    name: &str,
) -> Result<LoadedDocument> {
    check_glb_header(data, name)?;
    let Gltf { document, blob } = Gltf::from_slice_without_validation(data)
        .map_err(|e| parse_error(name, format!("glTF: {e}")))?;
    validate(&document, name)?;
    let buffers = load_buffers(&document, blob, base_dir, name)?;
    Ok(LoadedDocument { document, buffers })
}

/// [`read_accessor`] for the appearance reader: `count × components` values as `f64`.
#[cfg(feature = "bake")]
pub(crate) fn accessor_values(
    acc: &Accessor,
    buffers: &[Vec<u8>],
    name: &str,
    what: &str,
) -> Result<Vec<f64>> {
    read_accessor(acc, &Ctx { buffers, name }, what)
}

/// [`read_indices`] for the appearance reader: every index checked `< n_vertices`.
#[cfg(feature = "bake")]
pub(crate) fn index_values(
    acc: &Accessor,
    n_vertices: usize,
    buffers: &[Vec<u8>],
    name: &str,
    what: &str,
) -> Result<Vec<u32>> {
    read_indices(acc, n_vertices, &Ctx { buffers, name }, what)
}

/// The triangles of an index list in `mode`, as the geometry reader emits them.
#[cfg(feature = "bake")]
pub(crate) fn triangle_list(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    triangulate(mode, idx, |t| out.push(t));
    out
}

/// The bytes of a whole buffer view, checked against its buffer.
#[cfg(feature = "bake")]
pub(crate) fn view_bytes<'b>(
    view: &::gltf::buffer::View,
    buffers: &'b [Vec<u8>],
    name: &'b str,
) -> Result<&'b [u8]> {
    let ctx = Ctx { buffers, name };
    view_slice(view, 0, 1, view.length(), view.length(), &ctx, "image")
}

/// The payload of a base64 `data:` URI.
#[cfg(feature = "bake")]
pub(crate) fn data_uri_bytes(uri: &str) -> Option<Vec<u8>> {
    decode_data_uri(uri)
}

/// An external file relative to `base` (same rules as external buffers), at most `limit` bytes.
#[cfg(feature = "bake")]
pub(crate) fn external_bytes(
    uri: &str,
    limit: usize,
    base: Option<&Path>,
    name: &str,
) -> Result<Vec<u8>> {
    let relative =
        percent_decode(uri).ok_or_else(|| parse_error(name, format!("malformed URI '{uri}'")))?;
    let base = base.ok_or_else(|| {
        parse_error(
            name,
            format!("external file '{uri}' cannot be resolved when reading from memory"),
        )
    })?;
    let len = std::fs::metadata(base.join(&relative))
        .map_err(|e| io_error(&base.join(&relative).display().to_string(), &e))?
        .len();
    read_external(uri, (len as usize).min(limit), Some(base), name)
}

/// `m · (p, 1)`.
#[cfg(feature = "bake")]
pub(crate) fn mat_point(m: &Mat4, p: [f64; 3]) -> [f64; 3] {
    transform(m, p)
}

/// Determinant of the linear part of `m`.
#[cfg(feature = "bake")]
pub(crate) fn mat_det3(m: &Mat4) -> f64 {
    det3(m)
}

/// Column-major 4×4 matrix, `m[column][row]` (for the appearance reader).
#[cfg(feature = "bake")]
pub(crate) type Matrix4 = Mat4;

// ---------------------------------------------------------------------------------- writing --

/// Positions as `f32` followed by `u32` indices, little endian.
fn binary_buffer(mesh: &TriMesh) -> Result<Vec<u8>> {
    if let Some(i) = super::stl::first_beyond_f32(mesh) {
        return Err(Error::InvalidArgument(format!(
            "vertex {i} {:?} exceeds the f32 range of glTF positions",
            mesh.positions()[i]
        )));
    }
    let mut bin = Vec::with_capacity(12 * (mesh.vertex_count() + mesh.triangle_count()));
    for p in mesh.positions() {
        for &c in p {
            bin.extend_from_slice(&(c as f32).to_le_bytes());
        }
    }
    for t in mesh.triangles() {
        for i in t {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    Ok(bin)
}

/// The glTF JSON for `mesh`; `uri` embeds the buffer (JSON glTF) or is `None` (GLB BIN chunk).
fn document_json(mesh: &TriMesh, uri: Option<&str>) -> String {
    let n = mesh.vertex_count();
    let m = mesh.triangle_count();
    let (lo, hi) = f32_bounds(mesh);
    let pos_len = 12 * n;
    let idx_len = 12 * m;
    let uri_field = uri.map_or(String::new(), |u| format!(",\"uri\":\"{u}\""));
    format!(
        concat!(
            "{{\"asset\":{{\"version\":\"2.0\",\"generator\":\"pleat\"}},",
            "\"scene\":0,\"scenes\":[{{\"nodes\":[0]}}],\"nodes\":[{{\"mesh\":0}}],",
            "\"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":0}},",
            "\"indices\":1,\"mode\":4}}]}}],",
            "\"accessors\":[",
            "{{\"bufferView\":0,\"componentType\":5126,\"count\":{n},\"type\":\"VEC3\",",
            "\"min\":[{lo0:?},{lo1:?},{lo2:?}],\"max\":[{hi0:?},{hi1:?},{hi2:?}]}},",
            "{{\"bufferView\":1,\"componentType\":5125,\"count\":{ni},\"type\":\"SCALAR\"}}],",
            "\"bufferViews\":[",
            "{{\"buffer\":0,\"byteOffset\":0,\"byteLength\":{pl},\"target\":34962}},",
            "{{\"buffer\":0,\"byteOffset\":{pl},\"byteLength\":{il},\"target\":34963}}],",
            "\"buffers\":[{{\"byteLength\":{bl}{uri}}}]}}"
        ),
        n = n,
        ni = 3 * m,
        lo0 = lo[0],
        lo1 = lo[1],
        lo2 = lo[2],
        hi0 = hi[0],
        hi1 = hi[1],
        hi2 = hi[2],
        pl = pos_len,
        il = idx_len,
        bl = pos_len + idx_len,
        uri = uri_field,
    )
}

/// Component-wise min and max of the `f32` positions.
fn f32_bounds(mesh: &TriMesh) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in mesh.positions() {
        for k in 0..3 {
            let c = p[k] as f32;
            lo[k] = lo[k].min(c);
            hi[k] = hi[k].max(c);
        }
    }
    (lo, hi)
}

fn pad_to_four(v: &mut Vec<u8>, fill: u8) {
    v.resize(v.len().next_multiple_of(4), fill);
}

const BASE64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

fn base64_encode(data: &[u8]) -> String {
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [0, 1, 2].map(|i| chunk.get(i).copied().unwrap_or(0));
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(BASE64[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Decodes standard base64 (padding optional); `None` on any other character.
fn base64_decode(text: &[u8]) -> Option<Vec<u8>> {
    let text = text
        .strip_suffix(b"==")
        .or_else(|| text.strip_suffix(b"="))
        .unwrap_or(text);
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 2);
    let mut acc = 0u32;
    let mut bits = 0;
    for &c in text {
        let v = BASE64.iter().position(|&b| b == c)? as u32;
        acc = acc << 6 | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// The payload of a `data:[<media type>];base64,<data>` URI.
fn decode_data_uri(uri: &str) -> Option<Vec<u8>> {
    let (_, payload) = uri.split_once(";base64,")?;
    base64_decode(payload.as_bytes())
}

/// Decodes `%XX` escapes of a URI reference; `None` when malformed or not UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}
