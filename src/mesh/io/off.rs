//! Object File Format (OFF) reading and writing (ASCII).
//!
//! Reading accepts the header keyword `OFF` with the optional prefixes `ST`, `C`, `N` and `4`
//! (texture coordinates, colours, normals, homogeneous coordinates: `COFF`, `NOFF`, `CNOFF`,
//! `STOFF`, `4OFF`, ...), the counts on the header line or the next one, `#` comments anywhere,
//! and blank lines. Each vertex and each face is one line; a vertex line's first three numbers
//! are the position (four for `4OFF`, divided by `w`) and anything after them (colour, normal,
//! texture coordinate) is ignored, as is anything after a face's indices (face colour).
//! Polygons are fan-triangulated. Binary OFF and `nOFF` are not supported.

use std::io::{BufRead, BufWriter, Write};

use super::text::{parse_f64, parse_u64, show, strip_comment, tokens, LineReader};
use super::{build_mesh, capped, parse_error, push_fan, push_vertex, read_error};
use crate::mesh::TriMesh;
use crate::Result;

/// Reads an OFF mesh from `reader`; `name` stands for the file in error messages.
///
/// Errors with [`Error::Parse`](crate::Error::Parse) (with the line number) on a malformed
/// header, vertex or face line, a non-finite coordinate, a face with fewer than three corners,
/// an out-of-range index, or a file that ends early; with [`Error::Io`](crate::Error::Io) when
/// reading fails.
pub fn read_off<R: BufRead>(reader: R, name: &str) -> Result<TriMesh> {
    read_off_sized(reader, name, None)
}

/// [`read_off`] knowing the input's total size, so absurd header counts fail before allocating.
pub(crate) fn read_off_sized<R: BufRead>(
    reader: R,
    name: &str,
    total_len: Option<u64>,
) -> Result<TriMesh> {
    let mut r = OffReader {
        lines: LineReader::new(reader),
        name,
    };
    let header = r.header()?;
    if let Some(len) = total_len {
        check_counts_fit(&header, len, name)?;
    }
    let positions = r.vertices(&header)?;
    let triangles = r.faces(&header)?;
    build_mesh(name, positions, triangles)
}

/// Writes `mesh` as ASCII OFF with Rust's shortest round-trip float formatting (bit-exact when
/// read back). `writer` is buffered internally.
pub fn write_off<W: Write>(mut writer: W, mesh: &TriMesh) -> std::io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 16, &mut writer);
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.vertex_count(), mesh.triangle_count())?;
    for p in mesh.positions() {
        writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
    }
    for [a, b, c] in mesh.triangles() {
        writeln!(w, "3 {a} {b} {c}")?;
    }
    w.flush()
}

struct Header {
    homogeneous: bool,
    n_vertices: u64,
    n_faces: u64,
}

struct OffReader<'a, R> {
    lines: LineReader<R>,
    name: &'a str,
}

impl<R: BufRead> OffReader<'_, R> {
    /// Advances to the next line with content (comments stripped); `false` at end of input.
    fn next_content_line(&mut self) -> Result<bool> {
        loop {
            let more = self
                .lines
                .next_line()
                .map_err(|e| read_error(self.name, &e, "a line"))?;
            if !more {
                return Ok(false);
            }
            if tokens(strip_comment(self.lines.line())).next().is_some() {
                return Ok(true);
            }
        }
    }

    fn current_tokens(&self) -> impl Iterator<Item = &[u8]> {
        tokens(strip_comment(self.lines.line()))
    }

    fn err(&self, reason: impl std::fmt::Display) -> crate::Error {
        parse_error(
            self.name,
            format!("line {}: {reason}", self.lines.line_no()),
        )
    }

    fn header(&mut self) -> Result<Header> {
        if !self.next_content_line()? {
            return Err(parse_error(self.name, "empty file (no OFF header)"));
        }
        let (homogeneous, header_counts) = self.keyword_line()?;
        let counts = match header_counts {
            Some(counts) => counts,
            None => {
                if !self.next_content_line()? {
                    return Err(self.err("file ends before the vertex and face counts"));
                }
                self.current_tokens()
                    .take(2)
                    .filter_map(parse_u64)
                    .collect()
            }
        };
        match counts[..] {
            [n_vertices, n_faces] => Ok(Header {
                homogeneous,
                n_vertices,
                n_faces,
            }),
            _ => Err(self.err("expected the vertex and face counts")),
        }
    }

    /// Parses the keyword line: whether coordinates are homogeneous, and the counts when they
    /// follow the keyword on the same line.
    fn keyword_line(&self) -> Result<(bool, Option<Vec<u64>>)> {
        let mut toks = self.current_tokens();
        let keyword = toks.next().unwrap_or_default();
        let homogeneous = parse_keyword(keyword).ok_or_else(|| {
            self.err(format!(
                "expected an OFF header keyword (OFF, COFF, NOFF, 4OFF, ...), found '{}'",
                show(keyword)
            ))
        })?;
        let rest: Vec<&[u8]> = toks.take(2).collect();
        if rest.first() == Some(&&b"BINARY"[..]) {
            return Err(self.err("binary OFF is not supported"));
        }
        let counts = (!rest.is_empty()).then(|| rest.iter().filter_map(|t| parse_u64(t)).collect());
        Ok((homogeneous, counts))
    }

    fn vertices(&mut self, h: &Header) -> Result<Vec<[f64; 3]>> {
        let mut positions = Vec::with_capacity(capped(h.n_vertices));
        for i in 0..h.n_vertices {
            if !self.next_content_line()? {
                return Err(parse_error(
                    self.name,
                    format!("file ends after {i} of {} vertices", h.n_vertices),
                ));
            }
            let p = self.vertex_line(h.homogeneous)?;
            let line_no = self.lines.line_no();
            push_vertex(&mut positions, p, self.name, || format!("line {line_no}"))?;
        }
        Ok(positions)
    }

    fn vertex_line(&self, homogeneous: bool) -> Result<[f64; 3]> {
        let mut toks = self.current_tokens();
        let mut xyzw = [1.0; 4];
        let n = if homogeneous { 4 } else { 3 };
        for c in &mut xyzw[..n] {
            *c = toks
                .next()
                .and_then(parse_f64)
                .ok_or_else(|| self.err(format!("a vertex needs {n} numeric coordinates")))?;
        }
        let w = xyzw[3];
        Ok([xyzw[0] / w, xyzw[1] / w, xyzw[2] / w])
    }

    fn faces(&mut self, h: &Header) -> Result<Vec<[u32; 3]>> {
        let mut triangles = Vec::with_capacity(capped(h.n_faces));
        let mut polygon = Vec::new();
        for i in 0..h.n_faces {
            if !self.next_content_line()? {
                return Err(parse_error(
                    self.name,
                    format!("file ends after {i} of {} faces", h.n_faces),
                ));
            }
            self.face_line(h.n_vertices, &mut polygon)?;
            push_fan(&mut triangles, &polygon);
        }
        Ok(triangles)
    }

    fn face_line(&self, n_vertices: u64, polygon: &mut Vec<u32>) -> Result<()> {
        polygon.clear();
        let mut toks = self.current_tokens();
        let k = toks
            .next()
            .and_then(parse_u64)
            .ok_or_else(|| self.err("a face must start with its corner count"))?;
        if k < 3 {
            return Err(self.err(format!("a face needs at least three corners, found {k}")));
        }
        for _ in 0..k {
            let tok = toks
                .next()
                .ok_or_else(|| self.err(format!("a face with {k} corners lists fewer indices")))?;
            let v = parse_u64(tok)
                .ok_or_else(|| self.err(format!("'{}' is not a vertex index", show(tok))))?;
            if v >= n_vertices {
                return Err(self.err(format!(
                    "vertex index {v} is out of range ({n_vertices} vertices)"
                )));
            }
            // n_vertices <= u32::MAX is enforced while reading the vertices.
            polygon.push(v as u32);
        }
        Ok(())
    }
}

/// Parses `[ST][C][N][4]OFF`; returns whether coordinates are homogeneous (`4`).
fn parse_keyword(keyword: &[u8]) -> Option<bool> {
    let mut rest = keyword.strip_suffix(b"OFF")?;
    for prefix in [&b"ST"[..], b"C", b"N"] {
        rest = rest.strip_prefix(prefix).unwrap_or(rest);
    }
    match rest {
        b"" => Some(false),
        b"4" => Some(true),
        _ => None,
    }
}

/// Rejects counts that cannot fit in `total_len` bytes (at least 6 bytes per vertex line
/// `0 0 0\n` and 8 per face line `3 0 1 2\n`).
fn check_counts_fit(h: &Header, total_len: u64, name: &str) -> Result<()> {
    let needed = h
        .n_vertices
        .saturating_mul(6)
        .saturating_add(h.n_faces.saturating_mul(8));
    if needed > total_len {
        return Err(parse_error(
            name,
            format!(
                "header claims {} vertices and {} faces, which need at least {needed} bytes, \
                 but the file has {total_len}",
                h.n_vertices, h.n_faces
            ),
        ));
    }
    Ok(())
}
