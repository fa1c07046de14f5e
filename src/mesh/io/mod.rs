//! Mesh file I/O: OBJ, PLY, OFF, STL and (feature `io-gltf`) glTF 2.0.
//!
//! [`read_mesh`] and [`write_mesh`] choose the format from the file extension
//! (case-insensitive). Each format module also reads from any [`BufRead`](std::io::BufRead)
//! (or byte slice) so callers can load meshes from memory.
//!
//! # Semantics
//!
//! The reader semantics are those of the project's independent checker (`meshcheck`), so that
//! topology reports computed on a [`TriMesh`] read here agree with it:
//!
//! - The mesh is the triangle soup exactly as the file gives it: no welding, no removal of
//!   unreferenced vertices, degenerate or duplicate faces.
//! - Polygons are fan-triangulated as `(v0, vi, vi+1)`.
//! - All objects and groups of an OBJ file are merged into one mesh that keeps the file's global
//!   vertex numbering.
//! - STL stores three points per facet; exactly-equal points (`-0.0 == 0.0`) are merged in
//!   first-seen order, as CGAL's STL reader does.
//!
//! Whenever a read succeeds on a file the checker also loads, the result is the checker's soup
//! (verified on the whole shared corpus, see `tests/io.rs`). Where the checker is lenient (it
//! drops faces with out-of-range indices or fewer than three corners, and replaces unparsable
//! OBJ vertices by the origin), these readers return [`Error::Parse`] instead, naming the file
//! and, for text formats, the line. Conversely they read some files the checker rejects (PLY
//! face lists with 8- or 16-bit indices, OBJ `l` lines).
//!
//! # Errors
//!
//! [`Error::Io`] when a file cannot be opened, read or written; [`Error::Parse`] when its content
//! is malformed (including a mesh that [`TriMesh::new`] rejects: no triangle, a non-finite
//! coordinate, an index out of range); [`Error::InvalidArgument`] for an unknown extension or a
//! glTF file when the `io-gltf` feature is disabled. Every message names the file.
//!
//! # Robustness
//!
//! No input panics. Element counts claimed by headers are checked against the file size before
//! anything is allocated when the size is known, and up-front reservations are capped otherwise,
//! so a header claiming 10¹² vertices costs nothing.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::Path;

use crate::mesh::TriMesh;
use crate::{Error, Result};

#[cfg(feature = "io-gltf")]
pub mod gltf;
pub mod nodes;
pub mod obj;
pub mod off;
pub mod ply;
pub mod stl;
mod text;

pub use nodes::NodeFilter;

/// The mesh file formats pleat reads and writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Wavefront OBJ (`.obj`): read and write.
    Obj,
    /// Stanford PLY (`.ply`), ASCII or binary: read; written as binary little endian.
    Ply,
    /// Object File Format (`.off`): read and write (ASCII).
    Off,
    /// STL (`.stl`), ASCII or binary: read; written as binary.
    Stl,
    /// Binary glTF 2.0 (`.glb`); needs the `io-gltf` feature.
    Glb,
    /// JSON glTF 2.0 (`.gltf`); needs the `io-gltf` feature. Written with the buffer embedded
    /// as a base64 data URI.
    Gltf,
}

impl MeshFormat {
    /// The format for a file extension without the dot (`"obj"`, `"PLY"`, ...), ignoring case.
    pub fn from_extension(ext: &str) -> Option<MeshFormat> {
        match ext.to_ascii_lowercase().as_str() {
            "obj" => Some(MeshFormat::Obj),
            "ply" => Some(MeshFormat::Ply),
            "off" => Some(MeshFormat::Off),
            "stl" => Some(MeshFormat::Stl),
            "glb" => Some(MeshFormat::Glb),
            "gltf" => Some(MeshFormat::Gltf),
            _ => None,
        }
    }

    /// The format of `path` from its extension.
    ///
    /// Errors with [`Error::InvalidArgument`] when the extension is missing or unknown.
    pub fn from_path(path: &Path) -> Result<MeshFormat> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        MeshFormat::from_extension(ext).ok_or_else(|| {
            let shown = if ext.is_empty() {
                "no extension".to_string()
            } else {
                format!("extension '.{ext}'")
            };
            Error::InvalidArgument(format!(
                "cannot tell the mesh format of '{}' from its {shown}: expected .obj, .ply, \
                 .off, .stl, .glb or .gltf",
                path.display()
            ))
        })
    }
}

/// Reads a triangle mesh from `path`, choosing the format from the extension
/// (case-insensitive: obj, ply, off, stl, glb, gltf). See the [module docs](self) for the
/// semantics and errors.
pub fn read_mesh(path: &Path) -> Result<TriMesh> {
    let format = MeshFormat::from_path(path)?;
    let name = path.display().to_string();
    match format {
        MeshFormat::Obj => obj::read_obj(open(path, &name)?, &name),
        MeshFormat::Ply => {
            let len = file_len(path, &name)?;
            ply::read_ply_sized(open(path, &name)?, &name, Some(len))
        }
        MeshFormat::Off => {
            let len = file_len(path, &name)?;
            off::read_off_sized(open(path, &name)?, &name, Some(len))
        }
        MeshFormat::Stl => {
            let data = std::fs::read(path).map_err(|e| io_error(&name, &e))?;
            stl::read_stl_bytes(&data, &name)
        }
        MeshFormat::Glb | MeshFormat::Gltf => read_gltf_file(path),
    }
}

/// Reads a triangle mesh of the given `format` from memory. `name` stands for the file in error
/// messages. A `.gltf` file read this way may only reference its buffers through `data:` URIs.
pub fn read_mesh_bytes(data: &[u8], format: MeshFormat, name: &str) -> Result<TriMesh> {
    let len = Some(data.len() as u64);
    match format {
        MeshFormat::Obj => obj::read_obj(data, name),
        MeshFormat::Ply => ply::read_ply_sized(data, name, len),
        MeshFormat::Off => off::read_off_sized(data, name, len),
        MeshFormat::Stl => stl::read_stl_bytes(data, name),
        MeshFormat::Glb | MeshFormat::Gltf => read_gltf_bytes(data, name),
    }
}

/// Writes `mesh` to `path`, choosing the format from the extension (case-insensitive): OBJ
/// (bit-exact positions), PLY (binary little endian, `double` coordinates, bit-exact), OFF
/// (ASCII, bit-exact), STL (binary, `f32` coordinates) and, with the `io-gltf` feature, GLB or
/// glTF (`f32` coordinates). Output bytes are deterministic.
///
/// Errors with [`Error::InvalidArgument`] for an unknown extension, a glTF extension without the
/// `io-gltf` feature, or coordinates beyond the `f32` range for STL/glTF; [`Error::Io`] when the
/// file cannot be created or written.
pub fn write_mesh(path: &Path, mesh: &TriMesh) -> Result<()> {
    let format = MeshFormat::from_path(path)?;
    let name = path.display().to_string();
    let bytes_or_stream = match format {
        MeshFormat::Stl => {
            stl::check_f32_range(mesh, &name)?;
            None
        }
        MeshFormat::Glb | MeshFormat::Gltf => Some(encode_gltf(mesh, format, &name)?),
        _ => None,
    };
    let file = File::create(path).map_err(|e| io_error(&name, &e))?;
    let mut w = BufWriter::new(file);
    let written = match (format, bytes_or_stream) {
        (_, Some(bytes)) => w.write_all(&bytes),
        (MeshFormat::Obj, None) => obj::write_obj(&mut w, mesh),
        (MeshFormat::Ply, None) => ply::write_ply(&mut w, mesh),
        (MeshFormat::Off, None) => off::write_off(&mut w, mesh),
        (MeshFormat::Stl, None) => stl::write_stl(&mut w, mesh),
        (MeshFormat::Glb | MeshFormat::Gltf, None) => Ok(()),
    };
    written
        .and_then(|()| w.flush())
        .map_err(|e| io_error(&name, &e))
}

#[cfg(feature = "io-gltf")]
fn read_gltf_file(path: &Path) -> Result<TriMesh> {
    gltf::read_gltf(path)
}

#[cfg(not(feature = "io-gltf"))]
fn read_gltf_file(path: &Path) -> Result<TriMesh> {
    Err(gltf_feature_off(&path.display().to_string()))
}

#[cfg(feature = "io-gltf")]
fn read_gltf_bytes(data: &[u8], name: &str) -> Result<TriMesh> {
    gltf::read_gltf_bytes(data, None, name)
}

#[cfg(not(feature = "io-gltf"))]
fn read_gltf_bytes(_data: &[u8], name: &str) -> Result<TriMesh> {
    Err(gltf_feature_off(name))
}

#[cfg(feature = "io-gltf")]
fn encode_gltf(mesh: &TriMesh, format: MeshFormat, name: &str) -> Result<Vec<u8>> {
    let encoded = if format == MeshFormat::Glb {
        gltf::glb_bytes(mesh)
    } else {
        gltf::gltf_embedded_string(mesh).map(String::into_bytes)
    };
    encoded.map_err(|e| match e {
        Error::InvalidArgument(m) => Error::InvalidArgument(format!("cannot write '{name}': {m}")),
        other => other,
    })
}

#[cfg(not(feature = "io-gltf"))]
fn encode_gltf(_mesh: &TriMesh, _format: MeshFormat, name: &str) -> Result<Vec<u8>> {
    Err(gltf_feature_off(name))
}

#[cfg(not(feature = "io-gltf"))]
fn gltf_feature_off(name: &str) -> Error {
    Error::InvalidArgument(format!(
        "'{name}': glTF (.glb/.gltf) support is disabled in this build of pleat; enable the \
         `io-gltf` cargo feature"
    ))
}

fn open(path: &Path, name: &str) -> Result<BufReader<File>> {
    let file = File::open(path).map_err(|e| io_error(name, &e))?;
    Ok(BufReader::with_capacity(1 << 16, file))
}

fn file_len(path: &Path, name: &str) -> Result<u64> {
    std::fs::metadata(path)
        .map(|m| m.len())
        .map_err(|e| io_error(name, &e))
}

/// Most elements any reader reserves up front from a count claimed by a file; beyond that the
/// vectors grow only as data actually arrives.
pub(crate) const MAX_RESERVE: usize = 1 << 20;

/// `Vec` capacity to reserve for `claimed` elements (capped at [`MAX_RESERVE`]).
pub(crate) fn capped(claimed: u64) -> usize {
    usize::try_from(claimed).map_or(MAX_RESERVE, |c| c.min(MAX_RESERVE))
}

/// [`Error::Io`] for `name`.
pub(crate) fn io_error(name: &str, e: &std::io::Error) -> Error {
    Error::Io {
        path: name.to_string(),
        reason: e.to_string(),
    }
}

/// [`Error::Parse`] for `name`.
pub(crate) fn parse_error(name: &str, reason: impl Into<String>) -> Error {
    Error::Parse {
        path: name.to_string(),
        reason: reason.into(),
    }
}

/// A read error: end of input means the file is truncated ([`Error::Parse`]), anything else is
/// an [`Error::Io`].
pub(crate) fn read_error(name: &str, e: &std::io::Error, what: &str) -> Error {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        parse_error(name, format!("file truncated while reading {what}"))
    } else {
        io_error(name, e)
    }
}

/// Builds the mesh, reporting a validation failure as a parse error of `name`.
pub(crate) fn build_mesh(
    name: &str,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
) -> Result<TriMesh> {
    TriMesh::new(positions, triangles).map_err(|e| match e {
        Error::InvalidMesh(m) => parse_error(name, m),
        other => other,
    })
}

/// Appends the fan triangulation `(p0, pi, pi+1)` of polygon `poly` to `tris`.
pub(crate) fn push_fan(tris: &mut Vec<[u32; 3]>, poly: &[u32]) {
    if let Some((&first, rest)) = poly.split_first() {
        for pair in rest.windows(2) {
            tris.push([first, pair[0], pair[1]]);
        }
    }
}

/// Appends a vertex, checking that its coordinates are finite and that the count stays within
/// the `u32` index range; `at` describes the location for the error message.
pub(crate) fn push_vertex(
    positions: &mut Vec<[f64; 3]>,
    p: [f64; 3],
    name: &str,
    at: impl FnOnce() -> String,
) -> Result<()> {
    if !p.iter().all(|c| c.is_finite()) {
        return Err(parse_error(
            name,
            format!(
                "{}: non-finite vertex coordinate ({}, {}, {})",
                at(),
                p[0],
                p[1],
                p[2]
            ),
        ));
    }
    if positions.len() >= u32::MAX as usize {
        return Err(parse_error(
            name,
            format!("{}: more vertices than the u32 index range allows", at()),
        ));
    }
    positions.push(p);
    Ok(())
}
