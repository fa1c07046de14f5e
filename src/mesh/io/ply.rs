//! Stanford PLY reading (ASCII, binary little and big endian) and writing (binary little
//! endian).
//!
//! Reading takes the first element named `vertex` (or `vertices`) and the first named `face`
//! (or `faces`), as CGAL does. Vertex `x`, `y`, `z` may have any scalar type and any position
//! among the vertex properties; other vertex properties, lists included, are skipped. Faces are
//! the `vertex_indices` list (or `vertex_index` when there is none) with any integer count and
//! index types; other face properties are skipped. Other elements (edges, materials, ...) are
//! skipped. Scalar types are `char uchar short ushort int uint float double` and their aliases
//! `int8 uint8 int16 uint16 int32 uint32 float32 float64`. Polygons are fan-triangulated.
//!
//! Writing produces binary little endian PLY with `double` coordinates (lossless) and a
//! `list uchar int vertex_indices` face property (`uint` beyond `i32::MAX` vertices).

use std::io::{BufRead, BufWriter, Read, Write};

use super::text::{parse_f64, parse_i64, parse_u64, show, tokens, LineReader, TokenStream};
use super::{build_mesh, capped, io_error, parse_error, push_fan, push_vertex, read_error};
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// Reads a PLY mesh from `reader`; `name` stands for the file in error messages.
///
/// Errors with [`Error::Parse`] on a malformed header, missing `x`/`y`/`z` or face index list,
/// a truncated body, a non-finite coordinate, a face with fewer than three corners, or an index
/// out of range (ASCII errors give the line number, binary errors the element and item); with
/// [`Error::Io`] when reading fails.
pub fn read_ply<R: BufRead>(reader: R, name: &str) -> Result<TriMesh> {
    read_ply_sized(reader, name, None)
}

/// [`read_ply`] knowing the input's total size, so that absurd header counts fail before
/// anything is allocated.
pub(crate) fn read_ply_sized<R: BufRead>(
    reader: R,
    name: &str,
    total_len: Option<u64>,
) -> Result<TriMesh> {
    let mut lines = LineReader::new(reader);
    let header = parse_header(&mut lines, name)?;
    if let Some(len) = total_len {
        check_counts_fit(&header, len.saturating_sub(lines.bytes_read()), name)?;
    }
    let roles = Roles::find(&header, name)?;
    let (positions, triangles) = match header.encoding {
        Encoding::Ascii => {
            let mut src = AsciiSource {
                tokens: TokenStream::new(lines),
                name,
            };
            read_body(&mut src, &header, &roles, name)?
        }
        Encoding::BinaryLittleEndian => {
            let mut src = BinarySource::<_, false>::new(lines.into_inner(), name);
            read_body(&mut src, &header, &roles, name)?
        }
        Encoding::BinaryBigEndian => {
            let mut src = BinarySource::<_, true>::new(lines.into_inner(), name);
            read_body(&mut src, &header, &roles, name)?
        }
    };
    build_mesh(name, positions, triangles)
}

/// Writes `mesh` as binary little endian PLY: `double` x, y, z (bit-exact when read back) and
/// `list uchar int vertex_indices` faces (`uint` when there are more than `i32::MAX`
/// vertices). The bytes depend only on the mesh. `writer` is buffered internally.
pub fn write_ply<W: Write>(mut writer: W, mesh: &TriMesh) -> std::io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 16, &mut writer);
    let index_type = if mesh.vertex_count() > i32::MAX as usize {
        "uint"
    } else {
        "int"
    };
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by pleat\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar {index_type} vertex_indices\nend_header\n",
        mesh.vertex_count(),
        mesh.triangle_count()
    )?;
    for p in mesh.positions() {
        for c in p {
            w.write_all(&c.to_le_bytes())?;
        }
    }
    for t in mesh.triangles() {
        w.write_all(&[3])?;
        for i in t {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    w.flush()
}

/// A PLY scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> u64 {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug)]
enum Property {
    Scalar {
        name: String,
        ty: Scalar,
    },
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

impl Property {
    fn name(&self) -> &str {
        match self {
            Property::Scalar { name, .. } | Property::List { name, .. } => name,
        }
    }
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
}

#[derive(Debug, Clone, Copy)]
enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Debug)]
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
}

fn parse_header<R: BufRead>(lines: &mut LineReader<R>, name: &str) -> Result<Header> {
    let more = lines
        .next_line()
        .map_err(|e| read_error(name, &e, "the header"))?;
    if !more || lines.line().trim_ascii() != b"ply" {
        return Err(parse_error(
            name,
            "not a PLY file (the first line is not 'ply')",
        ));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let more = lines
            .next_line()
            .map_err(|e| read_error(name, &e, "the header"))?;
        if !more {
            return Err(parse_error(name, "the header has no 'end_header' line"));
        }
        let line_no = lines.line_no();
        let err = |reason: String| parse_error(name, format!("line {line_no}: {reason}"));
        let toks: Vec<&[u8]> = tokens(lines.line()).collect();
        match toks.first().copied() {
            Some(b"end_header") => break,
            Some(b"format") => encoding = Some(parse_format(&toks).map_err(err)?),
            Some(b"element") => elements.push(parse_element(&toks).map_err(err)?),
            Some(b"property") => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| err("'property' before any 'element'".into()))?;
                element.props.push(parse_property(&toks).map_err(err)?);
            }
            // comment, obj_info, blank lines and unknown keywords carry no layout.
            _ => {}
        }
    }
    let encoding = encoding.ok_or_else(|| parse_error(name, "the header has no 'format' line"))?;
    Ok(Header { encoding, elements })
}

fn parse_format(toks: &[&[u8]]) -> std::result::Result<Encoding, String> {
    match toks.get(1).copied() {
        Some(b"ascii") => Ok(Encoding::Ascii),
        Some(b"binary_little_endian") => Ok(Encoding::BinaryLittleEndian),
        Some(b"binary_big_endian") => Ok(Encoding::BinaryBigEndian),
        other => Err(format!(
            "unknown PLY format '{}'",
            show(other.unwrap_or_default())
        )),
    }
}

fn parse_element(toks: &[&[u8]]) -> std::result::Result<Element, String> {
    match toks {
        [_, name, count, ..] => Ok(Element {
            name: String::from_utf8_lossy(name).into_owned(),
            count: parse_u64(count)
                .ok_or_else(|| format!("bad element count '{}'", show(count)))?,
            props: Vec::new(),
        }),
        _ => Err("'element' needs a name and a count".into()),
    }
}

fn parse_property(toks: &[&[u8]]) -> std::result::Result<Property, String> {
    let ty = |t: &[u8]| Scalar::parse(t).ok_or_else(|| format!("unknown type '{}'", show(t)));
    let text = |t: &[u8]| String::from_utf8_lossy(t).into_owned();
    match toks {
        [_, b"list", count, item, name, ..] => Ok(Property::List {
            name: text(name),
            count: ty(count)?,
            item: ty(item)?,
        }),
        [_, b"list", ..] => {
            Err("'property list' needs a count type, an item type and a name".into())
        }
        [_, t, name, ..] => Ok(Property::Scalar {
            name: text(name),
            ty: ty(t)?,
        }),
        _ => Err("'property' needs a type and a name".into()),
    }
}

/// Which element holds the vertices and which the faces, and where their data sits.
struct Roles {
    vertex: usize,
    /// Per vertex property: the coordinate (0, 1, 2) it holds, if any.
    xyz_slots: Vec<Option<usize>>,
    face: usize,
    /// Index of the face property holding the corner indices.
    face_list: usize,
}

impl Roles {
    fn find(h: &Header, name: &str) -> Result<Roles> {
        let find_element = |names: [&str; 2]| {
            h.elements
                .iter()
                .position(|e| names.contains(&e.name.as_str()))
        };
        let vertex = find_element(["vertex", "vertices"])
            .ok_or_else(|| parse_error(name, "the header declares no 'vertex' element"))?;
        let face = find_element(["face", "faces"])
            .ok_or_else(|| parse_error(name, "the header declares no 'face' element"))?;
        let ve = &h.elements[vertex];
        if ve.count > u64::from(u32::MAX) {
            return Err(parse_error(
                name,
                format!("{} vertices exceed the u32 index range", ve.count),
            ));
        }
        let xyz_slots = xyz_slots(ve, name)?;
        let face_list = face_list(&h.elements[face], name)?;
        Ok(Roles {
            vertex,
            xyz_slots,
            face,
            face_list,
        })
    }
}

fn xyz_slots(ve: &Element, name: &str) -> Result<Vec<Option<usize>>> {
    let mut slots = vec![None; ve.props.len()];
    for (axis, axis_name) in ["x", "y", "z"].iter().enumerate() {
        let k = ve
            .props
            .iter()
            .position(|p| p.name() == *axis_name)
            .ok_or_else(|| {
                parse_error(
                    name,
                    format!("the vertex element has no '{axis_name}' property"),
                )
            })?;
        if matches!(ve.props[k], Property::List { .. }) {
            return Err(parse_error(
                name,
                format!("vertex property '{axis_name}' is a list, not a scalar"),
            ));
        }
        slots[k] = Some(axis);
    }
    Ok(slots)
}

fn face_list(fe: &Element, name: &str) -> Result<usize> {
    let k = ["vertex_indices", "vertex_index"]
        .iter()
        .find_map(|n| fe.props.iter().position(|p| p.name() == *n))
        .ok_or_else(|| {
            parse_error(
                name,
                "the face element has no 'vertex_indices' or 'vertex_index' property",
            )
        })?;
    match fe.props[k] {
        Property::List { count, item, .. } if count.is_integer() && item.is_integer() => Ok(k),
        _ => Err(parse_error(
            name,
            format!(
                "face property '{}' must be a list with integer count and index types",
                fe.props[k].name()
            ),
        )),
    }
}

/// Rejects headers whose element counts cannot fit in the `body_len` bytes after the header.
fn check_counts_fit(h: &Header, body_len: u64, name: &str) -> Result<()> {
    let binary = !matches!(h.encoding, Encoding::Ascii);
    let mut needed: u64 = 0;
    for e in &h.elements {
        // Binary: a scalar's size, a list's count size (the list may be empty). ASCII: at least
        // one character and one separator per value.
        let per_item: u64 = e
            .props
            .iter()
            .map(|p| match (binary, p) {
                (true, Property::Scalar { ty, .. }) => ty.size(),
                (true, Property::List { count, .. }) => count.size(),
                (false, _) => 2,
            })
            .sum();
        let bytes = e.count.saturating_mul(per_item);
        needed = needed.saturating_add(bytes);
        if bytes > body_len || needed > body_len {
            return Err(parse_error(
                name,
                format!(
                    "the header claims {} '{}' elements, which need at least {bytes} bytes, but \
                     only {body_len} bytes follow the header",
                    e.count, e.name
                ),
            ));
        }
    }
    Ok(())
}

/// Where the body's values come from (ASCII tokens or binary scalars).
trait Source {
    /// Reads a value of type `ty` as `f64`.
    fn value(&mut self, ty: Scalar, at: &At) -> Result<f64>;
    /// Reads an integer value of type `ty` (a list count or index).
    fn integer(&mut self, ty: Scalar, at: &At) -> Result<i64>;
    /// Skips a value of type `ty`.
    fn skip(&mut self, ty: Scalar, at: &At) -> Result<()>;
    /// Describes the read position for an error about item `at`.
    fn locate(&self, at: &At) -> String;
}

/// The element item being read, for error messages.
struct At<'a> {
    element: &'a str,
    item: u64,
    count: u64,
}

impl At<'_> {
    fn describe(&self) -> String {
        format!("'{}' element {} of {}", self.element, self.item, self.count)
    }
}

type Soup = (Vec<[f64; 3]>, Vec<[u32; 3]>);

fn read_body<S: Source>(src: &mut S, h: &Header, roles: &Roles, name: &str) -> Result<Soup> {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut n_vertices = None;
    for (ei, e) in h.elements.iter().enumerate() {
        if ei == roles.vertex {
            positions = read_vertices(src, e, &roles.xyz_slots, name)?;
            n_vertices = Some(positions.len() as u64);
        } else if ei == roles.face {
            triangles = read_faces(src, e, roles.face_list, n_vertices, name)?;
        } else {
            skip_element(src, e)?;
        }
    }
    Ok((positions, triangles))
}

fn read_vertices<S: Source>(
    src: &mut S,
    e: &Element,
    slots: &[Option<usize>],
    name: &str,
) -> Result<Vec<[f64; 3]>> {
    let mut positions = Vec::with_capacity(capped(e.count));
    for i in 0..e.count {
        let at = At {
            element: &e.name,
            item: i,
            count: e.count,
        };
        let mut p = [0.0; 3];
        for (prop, slot) in e.props.iter().zip(slots) {
            match (prop, slot) {
                (Property::Scalar { ty, .. }, Some(axis)) => p[*axis] = src.value(*ty, &at)?,
                (Property::Scalar { ty, .. }, None) => src.skip(*ty, &at)?,
                (Property::List { count, item, .. }, _) => skip_list(src, *count, *item, &at)?,
            }
        }
        push_vertex(&mut positions, p, name, || src.locate(&at))?;
    }
    Ok(positions)
}

fn read_faces<S: Source>(
    src: &mut S,
    e: &Element,
    list: usize,
    n_vertices: Option<u64>,
    name: &str,
) -> Result<Vec<[u32; 3]>> {
    let mut triangles = Vec::with_capacity(capped(e.count));
    let mut polygon = Vec::new();
    for i in 0..e.count {
        let at = At {
            element: &e.name,
            item: i,
            count: e.count,
        };
        for (k, prop) in e.props.iter().enumerate() {
            match prop {
                Property::List { count, item, .. } if k == list => {
                    read_polygon(src, *count, *item, n_vertices, &at, &mut polygon, name)?
                }
                Property::List { count, item, .. } => skip_list(src, *count, *item, &at)?,
                Property::Scalar { ty, .. } => src.skip(*ty, &at)?,
            }
        }
        push_fan(&mut triangles, &polygon);
    }
    Ok(triangles)
}

fn read_polygon<S: Source>(
    src: &mut S,
    count_ty: Scalar,
    index_ty: Scalar,
    n_vertices: Option<u64>,
    at: &At,
    polygon: &mut Vec<u32>,
    name: &str,
) -> Result<()> {
    polygon.clear();
    let n = src.integer(count_ty, at)?;
    if n < 3 {
        return Err(parse_error(
            name,
            format!(
                "{}: a face needs at least three corners, found {n}",
                src.locate(at)
            ),
        ));
    }
    for _ in 0..n {
        let v = src.integer(index_ty, at)?;
        let in_range = v >= 0 && n_vertices.map_or(v <= i64::from(u32::MAX), |n| (v as u64) < n);
        if !in_range {
            let bound = n_vertices.map_or(String::new(), |n| format!(" ({n} vertices)"));
            return Err(parse_error(
                name,
                format!(
                    "{}: vertex index {v} is out of range{bound}",
                    src.locate(at)
                ),
            ));
        }
        polygon.push(v as u32);
    }
    Ok(())
}

fn skip_list<S: Source>(src: &mut S, count_ty: Scalar, item_ty: Scalar, at: &At) -> Result<()> {
    let n = src.integer(count_ty, at)?;
    for _ in 0..n.max(0) {
        src.skip(item_ty, at)?;
    }
    Ok(())
}

fn skip_element<S: Source>(src: &mut S, e: &Element) -> Result<()> {
    if e.props.is_empty() {
        return Ok(()); // nothing to read, however many items the header claims
    }
    for i in 0..e.count {
        let at = At {
            element: &e.name,
            item: i,
            count: e.count,
        };
        for prop in &e.props {
            match prop {
                Property::Scalar { ty, .. } => src.skip(*ty, &at)?,
                Property::List { count, item, .. } => skip_list(src, *count, *item, &at)?,
            }
        }
    }
    Ok(())
}

/// ASCII body: whitespace-separated tokens.
struct AsciiSource<'a, R> {
    tokens: TokenStream<R>,
    name: &'a str,
}

impl<R: BufRead> AsciiSource<'_, R> {
    fn token(&mut self, at: &At) -> Result<&[u8]> {
        let name = self.name;
        match self.tokens.next_token() {
            Ok(Some(t)) => Ok(t),
            Ok(None) => Err(parse_error(name, format!("file ends in {}", at.describe()))),
            Err(e) => Err(io_error(name, &e)),
        }
    }

    fn bad_token(&self, tok: &[u8], what: &str) -> Error {
        parse_error(
            self.name,
            format!(
                "line {}: expected {what}, found '{}'",
                self.tokens.line_no(),
                show(tok)
            ),
        )
    }
}

impl<R: BufRead> Source for AsciiSource<'_, R> {
    fn value(&mut self, _ty: Scalar, at: &At) -> Result<f64> {
        let tok = self.token(at)?;
        match parse_f64(tok) {
            Some(v) => Ok(v),
            None => {
                let tok = tok.to_vec();
                Err(self.bad_token(&tok, "a number"))
            }
        }
    }

    fn integer(&mut self, _ty: Scalar, at: &At) -> Result<i64> {
        let tok = self.token(at)?;
        match parse_i64(tok) {
            Some(v) => Ok(v),
            None => {
                let tok = tok.to_vec();
                Err(self.bad_token(&tok, "an integer"))
            }
        }
    }

    fn skip(&mut self, _ty: Scalar, at: &At) -> Result<()> {
        self.token(at).map(|_| ())
    }

    fn locate(&self, _at: &At) -> String {
        format!("line {}", self.tokens.line_no())
    }
}

/// Binary body; `BIG` selects big endian.
struct BinarySource<'a, R, const BIG: bool> {
    reader: R,
    name: &'a str,
}

impl<'a, R: Read, const BIG: bool> BinarySource<'a, R, BIG> {
    fn new(reader: R, name: &'a str) -> Self {
        BinarySource { reader, name }
    }

    #[inline]
    fn bytes<const N: usize>(&mut self, at: &At) -> Result<[u8; N]> {
        let mut b = [0u8; N];
        self.reader
            .read_exact(&mut b)
            .map_err(|e| read_error(self.name, &e, &at.describe()))?;
        if BIG {
            b.reverse();
        }
        Ok(b)
    }

    /// Reads a scalar as `i64` when it is an integer type, `f64` otherwise.
    #[inline]
    fn scalar(&mut self, ty: Scalar, at: &At) -> Result<Number> {
        Ok(match ty {
            Scalar::I8 => Number::Int(i8::from_le_bytes(self.bytes(at)?).into()),
            Scalar::U8 => Number::Int(u8::from_le_bytes(self.bytes(at)?).into()),
            Scalar::I16 => Number::Int(i16::from_le_bytes(self.bytes(at)?).into()),
            Scalar::U16 => Number::Int(u16::from_le_bytes(self.bytes(at)?).into()),
            Scalar::I32 => Number::Int(i32::from_le_bytes(self.bytes(at)?).into()),
            Scalar::U32 => Number::Int(u32::from_le_bytes(self.bytes(at)?).into()),
            Scalar::F32 => Number::Float(f32::from_le_bytes(self.bytes(at)?).into()),
            Scalar::F64 => Number::Float(f64::from_le_bytes(self.bytes(at)?)),
        })
    }
}

enum Number {
    Int(i64),
    Float(f64),
}

impl<R: Read, const BIG: bool> Source for BinarySource<'_, R, BIG> {
    #[inline]
    fn value(&mut self, ty: Scalar, at: &At) -> Result<f64> {
        Ok(match self.scalar(ty, at)? {
            Number::Int(i) => i as f64,
            Number::Float(f) => f,
        })
    }

    #[inline]
    fn integer(&mut self, ty: Scalar, at: &At) -> Result<i64> {
        match self.scalar(ty, at)? {
            Number::Int(i) => Ok(i),
            // Only integer types reach here: the header check rejects float lists.
            Number::Float(f) => Err(parse_error(
                self.name,
                format!("{}: expected an integer, found {f}", at.describe()),
            )),
        }
    }

    #[inline]
    fn skip(&mut self, ty: Scalar, at: &At) -> Result<()> {
        self.scalar(ty, at).map(|_| ())
    }

    fn locate(&self, at: &At) -> String {
        at.describe()
    }
}
