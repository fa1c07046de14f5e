//! Wavefront OBJ reading and writing.
//!
//! # Why not `tobj`
//!
//! The design (DESIGN.md) called for `tobj`, and this module was meant to use `tobj::load_obj_buf` with
//! `triangulate: true, single_index: false`. Checked against tobj 4.0.5, that cannot give the
//! checker's soup, even with the workaround of hiding `o`/`g`/`usemtl` lines so that tobj yields
//! one model:
//!
//! - tobj renumbers positions per model (`o`/`g`/material switch) in first-reference order, so a
//!   vertex shared by two groups is duplicated and the seam becomes a false boundary;
//! - even with a single model it drops unreferenced vertices and renumbers the rest, so the
//!   file's global vertex numbering is lost (recovering it means parsing the faces again);
//! - `l 1 2 3` becomes a triangle even with `ignore_lines: true`;
//! - `v x y z w` is divided by `w`, while `v x y z a b` is an error (the checker reads `x y z`
//!   and ignores the rest);
//! - a non-UTF-8 byte anywhere (say a Latin-1 group name) fails the whole load, `\` line
//!   continuations fail, and errors carry no line number;
//! - it allocates a `String` per line.
//!
//! So this is a small reader of its own, byte-based and allocation-free per line, with the
//! checker's semantics: only `v` and `f` lines matter (`vt`, `vn`, `vp`, `l`, `p`, `o`, `g`, `s`,
//! `usemtl`, `mtllib`, comments and unknown keywords are ignored; a `.mtl` file is never
//! opened); `v` takes its first three numbers and ignores the rest; `f` corners may be `v`,
//! `v/vt`, `v//vn` or `v/vt/vn` with 1-based or negative (relative) position indices, and may
//! refer forward to vertices defined later; polygons are fan-triangulated; tabs, CRLF and
//! trailing `\` continuations are accepted. Unreferenced vertices are kept.

use std::io::{BufRead, BufWriter, Write};

use super::text::{parse_f64, parse_i64, show, tokens, LineReader};
use super::{build_mesh, parse_error, push_fan, push_vertex, read_error};
use crate::mesh::TriMesh;
use crate::Result;

/// Reads an OBJ mesh from `reader`; `name` stands for the file in error messages.
///
/// All objects and groups are merged keeping the file's vertex numbering (see the
/// [module docs](self)). Errors with [`Error::Parse`](crate::Error::Parse) (with the line
/// number) on a malformed `v` or `f` line, a non-finite coordinate, a face with fewer than three
/// corners, an index 0 or out of range, or a file without faces; with
/// [`Error::Io`](crate::Error::Io) when reading fails.
pub fn read_obj<R: BufRead>(reader: R, name: &str) -> Result<TriMesh> {
    let mut parser = ObjParser::new(name);
    let mut lines = LineReader::new(reader);
    let mut joined: Vec<u8> = Vec::new();
    let mut first_line = 0;
    while lines
        .next_line()
        .map_err(|e| read_error(name, &e, "a line"))?
    {
        let line = lines.line();
        if joined.is_empty() {
            first_line = lines.line_no();
        }
        if let Some(head) = line.strip_suffix(b"\\") {
            joined.extend_from_slice(head);
            joined.push(b' ');
            continue;
        }
        if joined.is_empty() {
            parser.line(line, first_line)?;
        } else {
            joined.extend_from_slice(line);
            parser.line(&joined, first_line)?;
            joined.clear();
        }
    }
    if !joined.is_empty() {
        parser.line(&joined, first_line)?;
    }
    parser.finish()
}

/// Writes `mesh` as OBJ: `v x y z` lines with Rust's shortest round-trip float formatting
/// (`{:?}`: `0.1`, `-0.0`, `1e-7`; reading the file back is bit-exact), then `f a b c` lines with 1-based indices. The bytes
/// depend only on the mesh. `writer` is buffered internally.
pub fn write_obj<W: Write>(mut writer: W, mesh: &TriMesh) -> std::io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 16, &mut writer);
    for p in mesh.positions() {
        writeln!(w, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
    }
    for t in mesh.triangles() {
        let [a, b, c] = t.map(|i| u64::from(i) + 1);
        writeln!(w, "f {a} {b} {c}")?;
    }
    w.flush()
}

/// Parser state: the soup so far plus the largest index seen (for forward references).
struct ObjParser<'a> {
    name: &'a str,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    polygon: Vec<u32>,
    /// Largest position index used by a face, and the line where it was first used.
    max_index: Option<(u32, usize)>,
}

impl<'a> ObjParser<'a> {
    fn new(name: &'a str) -> Self {
        ObjParser {
            name,
            positions: Vec::new(),
            triangles: Vec::new(),
            polygon: Vec::new(),
            max_index: None,
        }
    }

    fn line(&mut self, line: &[u8], line_no: usize) -> Result<()> {
        let mut toks = tokens(line);
        match toks.next() {
            Some(b"v") => self.vertex(toks, line_no),
            Some(b"f") => self.face(toks, line_no),
            _ => Ok(()),
        }
    }

    fn vertex<'t>(
        &mut self,
        mut toks: impl Iterator<Item = &'t [u8]>,
        line_no: usize,
    ) -> Result<()> {
        let mut p = [0.0; 3];
        for c in &mut p {
            *c = toks.next().and_then(parse_f64).ok_or_else(|| {
                parse_error(
                    self.name,
                    format!("line {line_no}: a 'v' line needs three numeric coordinates"),
                )
            })?;
        }
        push_vertex(&mut self.positions, p, self.name, || {
            format!("line {line_no}")
        })
    }

    fn face<'t>(&mut self, toks: impl Iterator<Item = &'t [u8]>, line_no: usize) -> Result<()> {
        self.polygon.clear();
        for tok in toks {
            let index = self.corner_index(tok, line_no)?;
            if self.max_index.is_none_or(|(m, _)| index > m) {
                self.max_index = Some((index, line_no));
            }
            self.polygon.push(index);
        }
        if self.polygon.len() < 3 {
            return Err(parse_error(
                self.name,
                format!(
                    "line {line_no}: a face needs at least three corners, found {}",
                    self.polygon.len()
                ),
            ));
        }
        push_fan(&mut self.triangles, &self.polygon);
        Ok(())
    }

    /// The 0-based position index of a face corner `v[/vt[/vn]]`.
    fn corner_index(&self, tok: &[u8], line_no: usize) -> Result<u32> {
        let v = tok.split(|&b| b == b'/').next().unwrap_or(tok);
        let err = |what: &str| {
            parse_error(
                self.name,
                format!("line {line_no}: face corner '{}' {what}", show(tok)),
            )
        };
        let raw = parse_i64(v).ok_or_else(|| err("is not an integer vertex index"))?;
        let index = match raw {
            0 => return Err(err("uses index 0 (OBJ indices start at 1)")),
            r if r > 0 => r - 1,
            r => self.positions.len() as i64 + r,
        };
        if index < 0 {
            return Err(err(&format!(
                "refers before the first vertex ({} vertices so far)",
                self.positions.len()
            )));
        }
        u32::try_from(index).map_err(|_| err("exceeds the u32 index range"))
    }

    fn finish(self) -> Result<TriMesh> {
        if let Some((max, line_no)) = self.max_index {
            if max as usize >= self.positions.len() {
                return Err(parse_error(
                    self.name,
                    format!(
                        "line {line_no}: face refers to vertex {} but the file has only {} \
                         vertices",
                        u64::from(max) + 1,
                        self.positions.len()
                    ),
                ));
            }
        }
        build_mesh(self.name, self.positions, self.triangles)
    }
}
