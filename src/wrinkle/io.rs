//! The `.cwf` text format: a [`Cwf`]'s per-edge and per-vertex data, stored next to its base
//! mesh (which is kept in its own file: OBJ, PLY, …).
//!
//! ```text
//! pleat-cwf 1
//! vertices 4
//! edges 5
//! faces 2
//! connectivity 9c1f0e3a57d2b4e8
//! omega
//! 0 1 0.25
//! 0 2 -1.5
//! …                      (one line per edge: v0 v1 ω, edges in EdgeList order)
//! vertex
//! 1 0.7071067811865476 0.7071067811865475
//! …                      (one line per vertex: amplitude Re(z̃) Im(z̃))
//! end
//! ```
//!
//! - Line 1 is the magic `pleat-cwf` and the format version (this is version 1). Lines
//!   starting with `#` and blank lines are ignored anywhere.
//! - `connectivity` is the FNV-1a 64-bit hash (16 lowercase hex digits) of the base mesh
//!   connectivity: the bytes of the vertex count and the triangle count as little-endian `u64`,
//!   then every triangle's three vertex indices as little-endian `u32`, in order. Positions are
//!   not hashed: a CWF stays valid on a deformed (e.g. animated) base mesh with the same
//!   triangles. Reading checks the counts and the hash against the given base mesh and fails
//!   with a message naming both when they differ.
//! - `omega`: edge `e` of [`TriMesh::edges`] per line, in that order, as `v0 v1 ω` with
//!   `v0 < v1`; `ω` is integrated from `v0` to `v1` (`ω_{v1 v0} = −ω`). The vertex pair is
//!   checked on reading.
//! - `vertex`: `a Re(z̃) Im(z̃)` per vertex.
//! - Numbers are written with Rust's shortest round-trip formatting, so a write/read round
//!   trip reproduces every `f64` bit for bit.

use std::fmt::Write as _;
use std::path::Path;

use super::complex::Complex;
use super::cwf::Cwf;
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// The format version written by [`write_cwf`].
pub const CWF_FORMAT_VERSION: u32 = 1;

/// FNV-1a 64 of the base-mesh connectivity, as stored in the `connectivity` header line.
pub fn connectivity_hash(mesh: &TriMesh) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    eat(&(mesh.vertex_count() as u64).to_le_bytes());
    eat(&(mesh.triangle_count() as u64).to_le_bytes());
    for t in mesh.triangles() {
        for v in t {
            eat(&v.to_le_bytes());
        }
    }
    h
}

/// The `.cwf` text of `cwf`.
pub fn cwf_to_string(cwf: &Cwf) -> String {
    let m = cwf.base();
    let mut s = String::with_capacity(64 * (cwf.omega().len() + m.vertex_count()) + 256);
    let _ = writeln!(s, "pleat-cwf {CWF_FORMAT_VERSION}");
    let _ = writeln!(s, "vertices {}", m.vertex_count());
    let _ = writeln!(s, "edges {}", cwf.omega().len());
    let _ = writeln!(s, "faces {}", m.triangle_count());
    let _ = writeln!(s, "connectivity {:016x}", connectivity_hash(m));
    s.push_str("omega\n");
    for (&[a, b], w) in cwf.edges().iter().zip(cwf.omega()) {
        let _ = writeln!(s, "{a} {b} {w}");
    }
    s.push_str("vertex\n");
    for (a, z) in cwf.amplitude().iter().zip(cwf.zeta()) {
        let _ = writeln!(s, "{a} {} {}", z.re, z.im);
    }
    s.push_str("end\n");
    s
}

/// Writes `cwf` to `path` in the `.cwf` format.
pub fn write_cwf(path: impl AsRef<Path>, cwf: &Cwf) -> Result<()> {
    let path = path.as_ref();
    std::fs::write(path, cwf_to_string(cwf)).map_err(|e| Error::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })
}

/// Reads a `.cwf` file written for `base` (see the [module docs](self)) and builds the
/// validated [`Cwf`].
pub fn read_cwf(path: impl AsRef<Path>, base: TriMesh) -> Result<Cwf> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    parse_cwf(&text, base, &path.display().to_string())
}

/// Parses `.cwf` text for `base`; `name` labels error messages (a path or `"<memory>"`).
pub fn parse_cwf(text: &str, base: TriMesh, name: &str) -> Result<Cwf> {
    let mut lines = Lines::new(text, name);
    let header = read_header(&mut lines)?;
    check_base(&header, &base, name)?;
    lines.keyword("omega")?;
    let el = base.edges();
    let mut omega = Vec::with_capacity(header.edges);
    for e in 0..header.edges {
        let (n, f) = lines.fields(3)?;
        let (a, b) = (lines.int(n, f[0])?, lines.int(n, f[1])?);
        let want = el.edges[e].0;
        if [a, b] != want {
            return Err(lines.err(
                n,
                &format!(
                "edge {e} is ({a}, {b}) but the base mesh's edge {e} is ({}, {}); the file was \
                 written for other connectivity or reordered",
                want[0], want[1]
            ),
            ));
        }
        omega.push(lines.float(n, f[2])?);
    }
    lines.keyword("vertex")?;
    let mut amplitude = Vec::with_capacity(header.vertices);
    let mut zeta = Vec::with_capacity(header.vertices);
    for _ in 0..header.vertices {
        let (n, f) = lines.fields(3)?;
        amplitude.push(lines.float(n, f[0])?);
        zeta.push(Complex::new(lines.float(n, f[1])?, lines.float(n, f[2])?));
    }
    lines.keyword("end")?;
    Cwf::new(base, omega, amplitude, zeta)
}

struct Header {
    vertices: usize,
    edges: usize,
    faces: usize,
    hash: u64,
}

fn read_header(lines: &mut Lines<'_>) -> Result<Header> {
    let (n, f) = lines.fields(2)?;
    if f[0] != "pleat-cwf" {
        return Err(lines.err(n, "not a pleat .cwf file (expected 'pleat-cwf <version>')"));
    }
    let version = lines.int(n, f[1])?;
    if version != CWF_FORMAT_VERSION {
        return Err(lines.err(n, &format!(
            "format version {version} is not supported (this pleat reads version {CWF_FORMAT_VERSION})"
        )));
    }
    let vertices = lines.header_number("vertices")?;
    let edges = lines.header_number("edges")?;
    let faces = lines.header_number("faces")?;
    let (n, f) = lines.fields(2)?;
    if f[0] != "connectivity" {
        return Err(lines.err(n, "expected 'connectivity <16 hex digits>'"));
    }
    let hash = u64::from_str_radix(f[1], 16)
        .map_err(|_| lines.err(n, &format!("'{}' is not a 64-bit hex hash", f[1])))?;
    Ok(Header {
        vertices,
        edges,
        faces,
        hash,
    })
}

fn check_base(h: &Header, base: &TriMesh, name: &str) -> Result<()> {
    let hash = connectivity_hash(base);
    let edges = base.edges().len();
    if h.vertices != base.vertex_count()
        || h.faces != base.triangle_count()
        || h.edges != edges
        || h.hash != hash
    {
        return Err(Error::InvalidArgument(format!(
            "'{name}' was written for a base mesh with {} vertices, {} edges, {} triangles and \
             connectivity hash {:016x}; the given base mesh has {} vertices, {edges} edges, {} \
             triangles and hash {hash:016x}",
            h.vertices,
            h.edges,
            h.faces,
            h.hash,
            base.vertex_count(),
            base.triangle_count()
        )));
    }
    Ok(())
}

/// Non-empty, non-comment lines with 1-based line numbers.
struct Lines<'a> {
    it: Box<dyn Iterator<Item = (usize, &'a str)> + 'a>,
    name: &'a str,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str, name: &'a str) -> Lines<'a> {
        let it = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        Lines {
            it: Box::new(it),
            name,
        }
    }

    fn err(&self, line: usize, reason: &str) -> Error {
        Error::Parse {
            path: self.name.to_string(),
            reason: format!("line {line}: {reason}"),
        }
    }

    fn next(&mut self) -> Result<(usize, &'a str)> {
        self.it.next().ok_or_else(|| Error::Parse {
            path: self.name.to_string(),
            reason: "unexpected end of file".into(),
        })
    }

    fn fields(&mut self, k: usize) -> Result<(usize, Vec<&'a str>)> {
        let (n, l) = self.next()?;
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.len() != k {
            return Err(self.err(n, &format!("expected {k} fields, found {}: '{l}'", f.len())));
        }
        Ok((n, f))
    }

    fn keyword(&mut self, kw: &str) -> Result<()> {
        let (n, l) = self.next()?;
        if l != kw {
            return Err(self.err(n, &format!("expected '{kw}', found '{l}'")));
        }
        Ok(())
    }

    /// The `<count>` of the next line, which must read `kw <count>`.
    fn header_number(&mut self, kw: &str) -> Result<usize> {
        let (n, f) = self.fields(2)?;
        if f[0] != kw {
            return Err(self.err(n, &format!("expected '{kw} <count>', found '{}'", f[0])));
        }
        f[1].parse()
            .map_err(|_| self.err(n, &format!("'{}' is not a count", f[1])))
    }

    fn int(&self, n: usize, s: &str) -> Result<u32> {
        s.parse()
            .map_err(|_| self.err(n, &format!("'{s}' is not a vertex index")))
    }

    fn float(&self, n: usize, s: &str) -> Result<f64> {
        s.parse()
            .map_err(|_| self.err(n, &format!("'{s}' is not a number")))
    }
}
