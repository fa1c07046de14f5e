//! STL reading (ASCII and binary) and writing (binary).
//!
//! STL stores three points per facet. Reading merges points with exactly equal coordinates
//! (`-0.0` equals `0.0`) into one vertex, numbered in first-seen order, exactly as CGAL's STL
//! reader (the checker's) does; nothing else is welded, and degenerate facets are kept. Binary
//! coordinates are `f32`, widened exactly to `f64`; ASCII coordinates are parsed as `f64`.
//!
//! A file is binary when its size is `84 + 50·n` with `n` the facet count at byte 80; the
//! leading word `solid`, which many binary files start with, decides nothing by itself. A file
//! of another size is ASCII if it starts with `solid`; should that parse fail and the size be
//! large enough for the binary facet count, it is read as binary with trailing bytes ignored
//! (as CGAL does).
//!
//! Writing produces binary STL with `f32` coordinates and normals: positions lose precision
//! beyond `f32` (about 7 significant digits), and identical `f32` points are merged when read
//! back.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};
use std::io::{BufWriter, Read, Write};

use super::text::{is_space, parse_f64, show};
use super::{build_mesh, capped, parse_error, push_vertex, read_error};
use crate::geom::{tri_normal, Vec3};
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// Reads an STL mesh (ASCII or binary) from `reader`, which is read to its end first; `name`
/// stands for the file in error messages. See [`read_stl_bytes`].
pub fn read_stl<R: Read>(mut reader: R, name: &str) -> Result<TriMesh> {
    let mut data = Vec::new();
    reader
        .read_to_end(&mut data)
        .map_err(|e| read_error(name, &e, "the file"))?;
    read_stl_bytes(&data, name)
}

/// Reads an STL mesh (ASCII or binary) from memory; `name` stands for the file in error
/// messages.
///
/// Errors with [`Error::Parse`] when the data is neither a well-formed ASCII STL nor a binary
/// STL of consistent size (ASCII errors give the line number), or has a non-finite coordinate.
pub fn read_stl_bytes(data: &[u8], name: &str) -> Result<TriMesh> {
    let binary_facets = binary_facet_count(data);
    let (positions, triangles) = match binary_facets {
        Some(n) if binary_size(n) == data.len() as u64 => read_binary(data, n, name)?,
        _ if starts_with_solid(data) => match read_ascii(data, name) {
            Ok(soup) => soup,
            Err(e) => match binary_facets {
                Some(n) if binary_size(n) <= data.len() as u64 => read_binary(data, n, name)?,
                _ => return Err(e),
            },
        },
        Some(n) if binary_size(n) < data.len() as u64 => read_binary(data, n, name)?,
        Some(n) => {
            return Err(parse_error(
                name,
                format!(
                    "binary STL truncated: the header claims {n} facets ({} bytes) but the file \
                     has {} bytes",
                    binary_size(n),
                    data.len()
                ),
            ))
        }
        None => {
            return Err(parse_error(
                name,
                format!(
                    "not an STL file: {} bytes, too short for binary STL and not starting with \
                     'solid'",
                    data.len()
                ),
            ))
        }
    };
    build_mesh(name, positions, triangles)
}

/// Writes `mesh` as binary STL: an 80-byte header (not starting with `solid`), the facet count,
/// and per triangle its unit normal (zero when degenerate) and corners as `f32`. The bytes
/// depend only on the mesh. `writer` is buffered internally.
///
/// Coordinates beyond the `f32` range become infinite; [`write_mesh`](super::write_mesh)
/// rejects such meshes first. Fails with
/// [`std::io::ErrorKind::InvalidInput`] beyond `u32::MAX` triangles.
pub fn write_stl<W: Write>(mut writer: W, mesh: &TriMesh) -> std::io::Result<()> {
    let n = u32::try_from(mesh.triangle_count()).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "binary STL holds at most u32::MAX triangles",
        )
    })?;
    let mut w = BufWriter::with_capacity(1 << 16, &mut writer);
    let mut header = [b' '; 80];
    let label = b"binary STL written by pleat";
    header[..label.len()].copy_from_slice(label);
    w.write_all(&header)?;
    w.write_all(&n.to_le_bytes())?;
    for t in 0..mesh.triangle_count() {
        let [a, b, c] = mesh.triangle_positions(t);
        let normal = unit_normal(a, b, c);
        for v in [normal, a, b, c] {
            for x in v {
                w.write_all(&(x as f32).to_le_bytes())?;
            }
        }
        w.write_all(&[0, 0])?;
    }
    w.flush()
}

/// Checks that every coordinate of `mesh` is finite as `f32` (needed by STL and glTF);
/// errors with [`Error::InvalidArgument`] naming `name` otherwise.
pub(crate) fn check_f32_range(mesh: &TriMesh, name: &str) -> Result<()> {
    match first_beyond_f32(mesh) {
        None => Ok(()),
        Some(i) => Err(Error::InvalidArgument(format!(
            "cannot write '{name}': vertex {i} {:?} exceeds the f32 range of the format",
            mesh.positions()[i]
        ))),
    }
}

/// The first vertex with a coordinate that overflows `f32`.
pub(crate) fn first_beyond_f32(mesh: &TriMesh) -> Option<usize> {
    mesh.positions()
        .iter()
        .position(|p| p.iter().any(|&c| !(c as f32).is_finite()))
}

fn unit_normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let n = tri_normal(Vec3::from(a), Vec3::from(b), Vec3::from(c));
    let len = n.length();
    if len > 0.0 && len.is_finite() {
        (n / len).to_array()
    } else {
        [0.0; 3]
    }
}

const BINARY_HEADER: usize = 84;
const BINARY_FACET: u64 = 50;

/// The facet count at byte 80, when the data is long enough for a binary header.
fn binary_facet_count(data: &[u8]) -> Option<u32> {
    let b = data.get(80..84)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn binary_size(n: u32) -> u64 {
    BINARY_HEADER as u64 + BINARY_FACET * u64::from(n)
}

fn starts_with_solid(data: &[u8]) -> bool {
    let start = data.iter().take_while(|&&b| is_space(b)).count();
    let rest = &data[start..];
    rest.starts_with(b"solid") && rest.get(5).is_none_or(|&b| is_space(b))
}

type Soup = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Reads `n` binary facets; the caller checked that the data holds them.
fn read_binary(data: &[u8], n: u32, name: &str) -> Result<Soup> {
    let mut merger = PointMerger::with_capacity(capped(u64::from(n) / 2));
    let mut triangles = Vec::with_capacity(n as usize);
    let facets = data[BINARY_HEADER..].chunks_exact(BINARY_FACET as usize);
    for (f, facet) in facets.take(n as usize).enumerate() {
        let mut tri = [0u32; 3];
        for (k, corner) in tri.iter_mut().enumerate() {
            let o = 12 + 12 * k;
            let p = [0, 4, 8].map(|d| f64::from(f32_le(&facet[o + d..o + d + 4])));
            *corner = merger.index(p, name, || format!("binary facet {f}"))?;
        }
        triangles.push(tri);
    }
    Ok((merger.positions, triangles))
}

fn f32_le(b: &[u8]) -> f32 {
    f32::from_le_bytes([b[0], b[1], b[2], b[3]])
}

/// Reads ASCII STL (`solid ... facet ... vertex x y z ... endfacet ... endsolid`), as CGAL
/// does: inside a facet only the three `vertex` lines matter.
fn read_ascii(data: &[u8], name: &str) -> Result<Soup> {
    let mut toks = Tokens::new(data);
    let mut merger = PointMerger::with_capacity(capped(data.len() as u64 / 400));
    let mut triangles = Vec::with_capacity(capped(data.len() as u64 / 200));
    let mut in_solid = false;
    let mut solids = 0;
    while let Some(tok) = toks.next() {
        match tok {
            b"solid" if !in_solid => {
                in_solid = true;
                toks.skip_line();
            }
            b"facet" if in_solid => triangles.push(read_ascii_facet(&mut toks, &mut merger, name)?),
            b"endsolid" if in_solid => {
                in_solid = false;
                solids += 1;
                toks.skip_line();
            }
            other => {
                return Err(parse_error(
                    name,
                    format!("line {}: unexpected '{}'", toks.line, show(other)),
                ))
            }
        }
    }
    if in_solid || solids == 0 {
        return Err(parse_error(
            name,
            format!("line {}: file ends before 'endsolid'", toks.line),
        ));
    }
    Ok((merger.positions, triangles))
}

fn read_ascii_facet(toks: &mut Tokens, merger: &mut PointMerger, name: &str) -> Result<[u32; 3]> {
    let mut tri = [0u32; 3];
    let mut count = 0;
    while let Some(tok) = toks.next() {
        match tok {
            b"endfacet" if count == 3 => return Ok(tri),
            b"endfacet" => {
                return Err(parse_error(
                    name,
                    format!("line {}: facet has {count} vertices, not 3", toks.line),
                ))
            }
            b"vertex" if count < 3 => {
                let p = read_ascii_point(toks, name)?;
                let line = toks.line;
                tri[count] = merger.index(p, name, || format!("line {line}"))?;
                count += 1;
            }
            b"vertex" => {
                return Err(parse_error(
                    name,
                    format!("line {}: facet has more than 3 vertices", toks.line),
                ))
            }
            // normal, its components, outer, loop, endloop
            _ => {}
        }
    }
    Err(parse_error(
        name,
        format!("line {}: file ends inside a facet", toks.line),
    ))
}

fn read_ascii_point(toks: &mut Tokens, name: &str) -> Result<[f64; 3]> {
    let mut p = [0.0; 3];
    for c in &mut p {
        let tok = toks.next().unwrap_or_default();
        *c = parse_f64(tok).ok_or_else(|| {
            parse_error(
                name,
                format!(
                    "line {}: expected a vertex coordinate, found '{}'",
                    toks.line,
                    show(tok)
                ),
            )
        })?;
    }
    Ok(p)
}

/// Whitespace-separated tokens of a byte slice, tracking the 1-based line of the last token.
struct Tokens<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Tokens<'a> {
    fn new(data: &'a [u8]) -> Self {
        Tokens {
            data,
            pos: 0,
            line: 1,
        }
    }

    fn next(&mut self) -> Option<&'a [u8]> {
        while let Some(&b) = self.data.get(self.pos) {
            if !is_space(b) {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        let len = self.data[start..]
            .iter()
            .take_while(|&&b| !is_space(b))
            .count();
        self.pos += len;
        (len > 0).then(|| &self.data[start..start + len])
    }

    /// Skips the rest of the current line (a solid's name).
    fn skip_line(&mut self) {
        let rest = &self.data[self.pos..];
        self.pos += rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
    }
}

/// Merges exactly equal points into one vertex, numbered in first-seen order.
struct PointMerger {
    map: HashMap<PointKey, u32, BuildHasherDefault<PointHasher>>,
    positions: Vec<[f64; 3]>,
}

impl PointMerger {
    fn with_capacity(n: usize) -> Self {
        PointMerger {
            map: HashMap::with_capacity_and_hasher(n, BuildHasherDefault::default()),
            positions: Vec::with_capacity(n),
        }
    }

    fn index(&mut self, p: [f64; 3], name: &str, at: impl FnOnce() -> String) -> Result<u32> {
        // `+ 0.0` turns -0.0 into +0.0 so that both merge, as `==` (and CGAL) would.
        let key = PointKey(p.map(|c| (c + 0.0).to_bits()));
        if let Some(&i) = self.map.get(&key) {
            return Ok(i);
        }
        let i = self.positions.len() as u32;
        push_vertex(&mut self.positions, p, name, at)?;
        self.map.insert(key, i);
        Ok(i)
    }
}

#[derive(PartialEq, Eq)]
struct PointKey([u64; 3]);

impl Hash for PointKey {
    fn hash<H: Hasher>(&self, state: &mut H) {
        for b in self.0 {
            state.write_u64(b);
        }
    }
}

/// A small fast hasher for coordinate bit patterns (multiply-rotate, with a final mix).
#[derive(Default)]
struct PointHasher(u64);

impl Hasher for PointHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn finish(&self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}
