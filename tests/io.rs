//! Tests of `pleat::mesh::io`: round trips of every writable format, hand-written files for
//! every quirk the readers accept, malformed and hostile inputs (never a panic, always an error
//! naming the file), and the shared corpus checked against its MANIFEST (and, when
//! `PLEAT_MESHCHECK` names the checker binary, against `meshcheck` itself).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use pleat::mesh::io::{self, read_mesh, read_mesh_bytes, write_mesh, MeshFormat};
use pleat::mesh::TriMesh;
use pleat::Error;

// ------------------------------------------------------------------------------- helpers ----

/// A unique path under the temp dir ending in `file_name`; its folder is removed on drop.
struct TmpPath(PathBuf);

impl std::ops::Deref for TmpPath {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TmpPath {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TmpPath {
    fn drop(&mut self) {
        if let Some(dir) = self.0.parent() {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

fn tmp_path(file_name: &str) -> TmpPath {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("pleat-io-test-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create temp dir");
    TmpPath(dir.join(file_name))
}

fn write_tmp(file_name: &str, data: &[u8]) -> TmpPath {
    let p = tmp_path(file_name);
    std::fs::write(&p, data).expect("write temp file");
    p
}

fn obj(text: &str) -> pleat::Result<TriMesh> {
    io::obj::read_obj(text.as_bytes(), "test.obj")
}

fn off(text: &str) -> pleat::Result<TriMesh> {
    io::off::read_off(text.as_bytes(), "test.off")
}

fn ply(data: &[u8]) -> pleat::Result<TriMesh> {
    io::ply::read_ply(data, "test.ply")
}

fn stl(data: &[u8]) -> pleat::Result<TriMesh> {
    io::stl::read_stl_bytes(data, "test.stl")
}

fn tris(m: &TriMesh) -> Vec<[u32; 3]> {
    m.triangles().to_vec()
}

/// The error message, asserting that it is a parse error naming `file`.
fn parse_err(r: pleat::Result<TriMesh>, file: &str) -> String {
    match r {
        Err(e @ Error::Parse { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains(file), "error does not name {file}: {msg}");
            msg
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

/// A mesh with awkward coordinates (shortest-repr edge cases, signed zero, subnormal, huge) and
/// an unreferenced vertex.
fn awkward_mesh() -> TriMesh {
    TriMesh::new(
        vec![
            [0.1, -0.0, 1e-300],
            [1.0 / 3.0, 2.5e-8, -7.0],
            [
                123456789.12345679,
                f64::MIN_POSITIVE / 4.0,
                0.30000000000000004,
            ],
            [9.0, 9.0, 9.0],
            [-1e300, 1e21, 5e-324],
        ],
        vec![[0, 1, 2], [2, 1, 4], [4, 1, 0]],
    )
    .expect("valid mesh")
}

/// A closed tetrahedron with `f32`-exact coordinates.
fn tetra() -> TriMesh {
    TriMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.5, 0.0, 0.0],
            [0.0, 2.25, 0.0],
            [0.0, 0.0, -0.125],
        ],
        vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [0, 2, 3]],
    )
    .expect("valid mesh")
}

// ----------------------------------------------------------------------------- dispatch ----

#[test]
fn format_from_extension_ignores_case() {
    for (p, f) in [
        ("a.obj", MeshFormat::Obj),
        ("a.OBJ", MeshFormat::Obj),
        ("dir.x/b.Ply", MeshFormat::Ply),
        ("c.off", MeshFormat::Off),
        ("d.StL", MeshFormat::Stl),
        ("e.GLB", MeshFormat::Glb),
        ("f.gltf", MeshFormat::Gltf),
    ] {
        assert_eq!(MeshFormat::from_path(Path::new(p)).ok(), Some(f), "{p}");
    }
}

#[test]
fn unknown_or_missing_extension_is_invalid_argument() {
    for p in ["mesh.xyz", "mesh", "mesh.obj.bak"] {
        let e = read_mesh(Path::new(p)).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument(_)), "{e:?}");
        assert!(e.to_string().contains(".obj, .ply"), "{e}");
        let e = write_mesh(Path::new(p), &tetra()).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument(_)), "{e:?}");
    }
}

#[test]
fn missing_file_is_io_error_naming_the_path() {
    let p = tmp_path("does-not-exist.PLY");
    match read_mesh(&p) {
        Err(Error::Io { path, .. }) => assert_eq!(path, p.display().to_string()),
        other => panic!("expected an I/O error, got {other:?}"),
    }
    let p = tmp_path("no-such-dir").join("out.obj");
    assert!(matches!(write_mesh(&p, &tetra()), Err(Error::Io { .. })));
}

#[test]
fn read_mesh_uses_the_extension_case_insensitively() {
    let p = write_tmp("UPPER.OBJ", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_eq!(read_mesh(&p).unwrap().triangle_count(), 1);
}

#[test]
fn parse_errors_name_the_file() {
    let p = write_tmp("nan.obj", b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    let msg = parse_err(read_mesh(&p), &p.display().to_string());
    assert!(
        msg.contains("line 2") && msg.contains("non-finite"),
        "{msg}"
    );
}

// ---------------------------------------------------------------------------------- OBJ ----

#[test]
fn obj_groups_keep_the_global_vertex_numbering() {
    // tobj would renumber per group and duplicate vertices 2 and 3 (a false boundary).
    let m = obj(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\no a\ng a1\nf 1 2 3\no b\ng b1\nusemtl m\nf 2 4 3\n",
    )
    .unwrap();
    assert_eq!(m.vertex_count(), 4);
    assert_eq!(tris(&m), vec![[0, 1, 2], [1, 3, 2]]);
    assert_eq!(m.edges().len(), 5);
}

#[test]
fn obj_accepts_every_corner_syntax_and_relative_indices() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n\
                f 1/1/1 2/2/1 3/3/1\nf 2//1 4//1 3//1\nf 1/1 2/2 4/3\nf -4 -3 -2\nf -3/1/1 -1/2/1 -2/1/1\n";
    let m = obj(text).unwrap();
    assert_eq!(
        tris(&m),
        vec![[0, 1, 2], [1, 3, 2], [0, 1, 3], [0, 1, 2], [1, 3, 2]]
    );
}

#[test]
fn obj_relative_indices_follow_the_vertices_read_so_far() {
    let m = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -1 -3 -2\n").unwrap();
    assert_eq!(tris(&m), vec![[0, 1, 2], [3, 1, 2]]);
}

#[test]
fn obj_fan_triangulates_polygons() {
    let m = obj("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\nf 1 2 3 4\n").unwrap();
    assert_eq!(
        tris(&m),
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 1, 2], [0, 2, 3]]
    );
}

#[test]
fn obj_ignores_everything_but_v_and_f() {
    let text = "# comment\r\nmtllib missing.mtl\r\no thing\r\ng grp\r\ns 1\r\nusemtl red\r\n\
                v\t0\t0\t0\r\nv 1 0 0 1.0 0.5 0.25\r\nv 0 1 0 2\r\nv 3 3 3 0.5 0.5\r\n\
                vp 0.5 0.5\r\nvn 0 0 1\r\nvt 0 0\r\nl 1 2 3\r\nl 1 2\r\np 1\r\np 1 2 3\r\n\
                cstype bezier\r\n   \r\n\t# indented comment\r\nf\t1 2\t3\r\n#f 1 2 4\r\n";
    let m = obj(text).unwrap();
    assert_eq!(
        m.vertex_count(),
        4,
        "w and colour values are ignored, not applied"
    );
    assert_eq!(m.position(2), [0.0, 1.0, 0.0]);
    assert_eq!(m.position(3), [3.0, 3.0, 3.0]);
    assert_eq!(tris(&m), vec![[0, 1, 2]]);
}

#[test]
fn obj_line_continuation_and_forward_references() {
    let m = obj("f 1 2 \\\n  3\nv 0 0 0\nv 1 0 0\nv 0 \\\n 1 0\n").unwrap();
    assert_eq!(tris(&m), vec![[0, 1, 2]]);
    assert_eq!(m.position(2), [0.0, 1.0, 0.0]);
}

#[test]
fn obj_keeps_unreferenced_vertices_in_file_order() {
    let m = obj("v 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 8 8 8\nf 2 3 4\n").unwrap();
    assert_eq!(m.vertex_count(), 5);
    assert_eq!(m.position(0), [9.0; 3]);
    assert_eq!(tris(&m), vec![[1, 2, 3]]);
}

#[test]
fn obj_tolerates_non_utf8_outside_numbers() {
    let mut data = b"g caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\n# \xff\xfe\nf 1 2 3\n".to_vec();
    data.extend_from_slice(b"o \x80\n");
    assert_eq!(
        io::obj::read_obj(&data[..], "latin1.obj")
            .unwrap()
            .triangle_count(),
        1
    );
}

#[test]
fn obj_malformed_lines_are_errors_with_line_numbers() {
    let cases = [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "only 3 vertices"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
            "before the first vertex",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
            "at least three corners",
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 a 3\n", "not an integer"),
        ("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", "line 2"),
        ("v 0 0 0\nv 1 0 x\nv 0 1 0\nf 1 2 3\n", "line 2"),
        ("v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n", "non-finite"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999\n", "u32"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no triangles"),
        ("", "no triangles"),
    ];
    for (text, want) in cases {
        let msg = parse_err(obj(text), "test.obj");
        assert!(msg.contains(want), "{text:?}: {msg}");
    }
}

#[test]
fn obj_round_trip_is_bit_exact_and_deterministic() {
    let m = awkward_mesh();
    let mut a = Vec::new();
    io::obj::write_obj(&mut a, &m).unwrap();
    let back = io::obj::read_obj(&a[..], "rt.obj").unwrap();
    assert_eq!(bits(&back), bits(&m));
    assert_eq!(tris(&back), tris(&m));
    let mut b = Vec::new();
    io::obj::write_obj(&mut b, &back).unwrap();
    assert_eq!(a, b);
    let text = String::from_utf8(a).unwrap();
    assert!(text.starts_with("v 0.1 -0.0 1e-300\n"), "{text}");
    assert!(text.ends_with("f 5 2 1\n"), "{text}");
}

fn bits(m: &TriMesh) -> Vec<[u64; 3]> {
    m.positions().iter().map(|p| p.map(f64::to_bits)).collect()
}

// ---------------------------------------------------------------------------------- OFF ----

#[test]
fn off_reads_plain_colour_and_normal_variants() {
    let plain =
        "OFF\n# comment\n4 2 0\n0 0 0\n1 0 0\n\n0 1 0 # trailing\n1 1 0\n3 0 1 2\n3 1 3 2\n";
    let m = off(plain).unwrap();
    assert_eq!(tris(&m), vec![[0, 1, 2], [1, 3, 2]]);
    let coff =
        "COFF 4 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n0 1 0 1 1 1 1\n\
                4 0 1 2 3 200 10 10\n";
    assert_eq!(tris(&off(coff).unwrap()), vec![[0, 1, 2], [0, 2, 3]]);
    let noff = "NOFF\r\n3 1 3\r\n0 0 0 0 0 1\r\n1 0 0 0 0 1\r\n0 1 0 0 0 1\r\n3 0 1 2\r\n";
    assert_eq!(off(noff).unwrap().position(1), [1.0, 0.0, 0.0]);
    let homogeneous = "4OFF\n3 1 0\n2 0 0 2\n4 0 0 2\n0 2 0 2\n3 0 1 2\n";
    assert_eq!(off(homogeneous).unwrap().position(1), [2.0, 0.0, 0.0]);
    assert!(off(
        "CNOFF\n3 1 0\n0 0 0 1 1 1 0 0 1\n1 0 0 1 1 1 0 0 1\n0 1 0 1 1 1 0 0 1\n3 0 1 2\n"
    )
    .is_ok());
}

#[test]
fn off_errors() {
    let cases = [
        ("PLY\n3 1 0\n", "OFF header"),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n", "ends after 2 of 3 vertices"),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n",
            "ends after 0 of 1 faces",
        ),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6"),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "three corners"),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
            "fewer indices",
        ),
        ("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "non-finite"),
        ("OFF BINARY\n", "binary OFF"),
        ("OFF\n", "counts"),
        ("", "empty"),
    ];
    for (text, want) in cases {
        let msg = parse_err(off(text), "test.off");
        assert!(msg.contains(want), "{text:?}: {msg}");
    }
}

#[test]
fn off_round_trip_is_bit_exact() {
    let m = awkward_mesh();
    let p = tmp_path("rt.off");
    write_mesh(&p, &m).unwrap();
    let back = read_mesh(&p).unwrap();
    assert_eq!(bits(&back), bits(&m));
    assert_eq!(tris(&back), tris(&m));
}

#[test]
fn off_absurd_counts_fail_before_allocating() {
    let p = write_tmp("huge.off", b"OFF\n1000000000000 1000000000000 0\n0 0 0\n");
    let msg = parse_err(read_mesh(&p), "huge.off");
    assert!(msg.contains("at least"), "{msg}");
    // Without a size hint the reservation is capped and the file simply ends early.
    let msg = parse_err(off("OFF\n1000000000000 1 0\n0 0 0\n"), "test.off");
    assert!(msg.contains("ends after 1 of"), "{msg}");
}

// ---------------------------------------------------------------------------------- PLY ----

/// A PLY scalar type: its header name, size, and little-endian encoder.
#[derive(Clone, Copy)]
struct Ty(&'static str);

impl Ty {
    fn encode(self, v: f64, big: bool) -> Vec<u8> {
        let mut b = match self.0 {
            "char" | "int8" => (v as i8).to_le_bytes().to_vec(),
            "uchar" | "uint8" => (v as u8).to_le_bytes().to_vec(),
            "short" | "int16" => (v as i16).to_le_bytes().to_vec(),
            "ushort" | "uint16" => (v as u16).to_le_bytes().to_vec(),
            "int" | "int32" => (v as i32).to_le_bytes().to_vec(),
            "uint" | "uint32" => (v as u32).to_le_bytes().to_vec(),
            "float" | "float32" => (v as f32).to_le_bytes().to_vec(),
            "double" | "float64" => v.to_le_bytes().to_vec(),
            other => panic!("{other}"),
        };
        if big {
            b.reverse();
        }
        b
    }
}

const ALL_TYPES: [&str; 16] = [
    "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16",
    "uint16", "int32", "uint32", "float32", "float64",
];

/// A binary PLY of a unit square (two triangles as one quad plus one extra triangle) whose
/// vertex has `z y x` in the given coordinate type among other properties, with a list property
/// on vertices, an edge element, and the face list using the given count/index types.
fn square_ply(coord: Ty, count: Ty, index: Ty, big: bool, list_name: &str) -> Vec<u8> {
    let format = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let header = format!(
        "ply\r\nformat {format} 1.0\r\ncomment made by a test\r\nobj_info none\r\n\
         element vertex 4\r\nproperty uchar red\r\nproperty {c} z\r\n\
         property list uchar float tags\r\nproperty {c} y\r\nproperty double w\r\n\
         property {c} x\r\n\
         element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\n\
         element face 2\r\nproperty uchar flags\r\nproperty list {n} {i} {list_name}\r\n\
         property list uchar int other\r\n\
         end_header\r\n",
        c = coord.0,
        n = count.0,
        i = index.0
    );
    let mut b = header.into_bytes();
    let u8t = Ty("uchar");
    let pts = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    for p in pts {
        b.extend(u8t.encode(7.0, big));
        b.extend(coord.encode(p[2], big));
        b.extend(u8t.encode(2.0, big));
        b.extend(Ty("float").encode(0.5, big));
        b.extend(Ty("float").encode(0.25, big));
        b.extend(coord.encode(p[1], big));
        b.extend(Ty("double").encode(-3.0, big));
        b.extend(coord.encode(p[0], big));
    }
    b.extend(Ty("int").encode(0.0, big));
    b.extend(Ty("int").encode(1.0, big));
    for face in [&[0.0, 1.0, 2.0, 3.0][..], &[2.0, 1.0, 0.0]] {
        b.extend(u8t.encode(1.0, big));
        b.extend(count.encode(face.len() as f64, big));
        for &v in face {
            b.extend(index.encode(v, big));
        }
        b.extend(u8t.encode(1.0, big));
        b.extend(Ty("int").encode(42.0, big));
    }
    b
}

#[test]
fn ply_binary_reads_every_type_order_and_endianness() {
    let int_types = [
        "char", "uchar", "short", "ushort", "int", "uint", "int8", "uint32",
    ];
    for coord in ALL_TYPES {
        for (count, index) in [("uchar", "int"), ("int", "uint"), ("ushort", "uchar")]
            .into_iter()
            .chain(int_types.iter().map(|&t| ("uint8", t)))
        {
            for big in [false, true] {
                for list in ["vertex_indices", "vertex_index"] {
                    let data = square_ply(Ty(coord), Ty(count), Ty(index), big, list);
                    let what = format!("{coord} {count} {index} big={big} {list}");
                    let m = ply(&data).unwrap_or_else(|e| panic!("{what}: {e}"));
                    assert_eq!(m.position(2), [1.0, 1.0, 0.0], "{what}");
                    assert_eq!(tris(&m), vec![[0, 1, 2], [0, 2, 3], [2, 1, 0]], "{what}");
                }
            }
        }
    }
}

#[test]
fn ply_ascii_reads_properties_in_any_order() {
    let text = "ply\nformat ascii 1.0\ncomment hello\nelement material 1\nproperty float shine\n\
                element vertex 4\nproperty float nx\nproperty float z\nproperty list uchar int tags\n\
                property int y\nproperty double x\nelement face 2\nproperty list uchar uint vertex_indices\n\
                property uchar red\nelement edge 1\nproperty int a\nproperty int b\nend_header\n\
                0.5\n\
                9 0 2 5 6 0 0\n9 0 0 0 1.5\n9 0.25 1 7 1 1\n9 0 3 1 2 3 1 0\n\
                4 0 1 2 3 255\n3 2 1 0 0\n0 1\n";
    let m = ply(text.as_bytes()).unwrap();
    assert_eq!(m.vertex_count(), 4);
    assert_eq!(m.position(1), [1.5, 0.0, 0.0]);
    assert_eq!(m.position(2), [1.0, 1.0, 0.25]);
    assert_eq!(tris(&m), vec![[0, 1, 2], [0, 2, 3], [2, 1, 0]]);
}

#[test]
fn ply_round_trip_is_bit_exact_and_deterministic() {
    let m = awkward_mesh();
    let mut a = Vec::new();
    io::ply::write_ply(&mut a, &m).unwrap();
    assert!(a.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    let header_end = b"end_header\n";
    let text = String::from_utf8_lossy(&a[..200]);
    assert!(
        text.contains("property double x")
            && text.contains("property list uchar int vertex_indices")
    );
    assert!(a.windows(header_end.len()).any(|w| w == header_end));
    let back = ply(&a).unwrap();
    assert_eq!(bits(&back), bits(&m));
    assert_eq!(tris(&back), tris(&m));
    let mut b = Vec::new();
    io::ply::write_ply(&mut b, &back).unwrap();
    assert_eq!(a, b);
    let p = tmp_path("rt.ply");
    write_mesh(&p, &m).unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), a);
}

#[test]
fn ply_errors() {
    let good = square_ply(Ty("float"), Ty("uchar"), Ty("int"), false, "vertex_indices");
    let header = |body: &str| format!("ply\nformat ascii 1.0\n{body}end_header\n").into_bytes();
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"plx\n".to_vec(), "not a PLY"),
        (b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec(), "end_header"),
        (
            header("element vertex 1\nproperty float x\nproperty float y\nelement face 0\nproperty list uchar int vertex_indices\n"),
            "no 'z'",
        ),
        (b"ply\nelement vertex 1\nend_header\n".to_vec(), "format"),
        (header("element vertex 0\nproperty float x\nproperty float y\nproperty float z\n"), "no 'face'"),
        (
            header("element vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar float vertex_indices\n"),
            "integer",
        ),
        (
            header("element vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty int flags\n"),
            "vertex_indices",
        ),
        (header("property float x\n"), "before any 'element'"),
        (header("element vertex 1\nproperty quad x\n"), "unknown type"),
        (b"ply\nformat binary_middle_endian 1.0\nend_header\n".to_vec(), "unknown PLY format"),
        (good[..good.len() - 3].to_vec(), "truncated"),
        (good[..header_len(&good) + 30].to_vec(), "truncated"),
    ];
    for (data, want) in cases {
        let msg = parse_err(ply(&data), "test.ply");
        assert!(
            msg.contains(want),
            "{}: {msg}",
            String::from_utf8_lossy(&data)
        );
    }
    let vfmt = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\n";
    for (body, want) in [
        ("0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "out of range"),
        ("0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "out of range"),
        ("0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "three corners"),
        ("0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "non-finite"),
        ("0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "line 11"),
        ("0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "file ends"),
    ] {
        let mut data = header(vfmt);
        data.extend_from_slice(body.as_bytes());
        let msg = parse_err(ply(&data), "test.ply");
        assert!(msg.contains(want), "{body:?}: {msg}");
    }
}

fn header_len(ply: &[u8]) -> usize {
    let end = b"end_header\r\n";
    ply.windows(end.len()).position(|w| w == end).unwrap() + end.len()
}

#[test]
fn ply_binary_index_out_of_range_is_an_error() {
    let mut data = square_ply(Ty("float"), Ty("uchar"), Ty("int"), false, "vertex_indices");
    let end = data.len();
    // The last face is `3 2 1 0` followed by the `other` list `1 42`: corrupt its last index.
    data[end - 9..end - 5].copy_from_slice(&4i32.to_le_bytes());
    let msg = parse_err(ply(&data), "test.ply");
    assert!(
        msg.contains("'face' element 1 of 2: vertex index 4 is out of range"),
        "{msg}"
    );
}

#[test]
fn ply_absurd_counts_fail_before_allocating() {
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n\
                  property float x\nproperty float y\nproperty float z\n\
                  element face 1000000000000\nproperty list uchar int vertex_indices\nend_header\n";
    let mut data = header.as_bytes().to_vec();
    data.extend_from_slice(&[0; 64]);
    let p = write_tmp("huge.ply", &data);
    let msg = parse_err(read_mesh(&p), "huge.ply");
    assert!(msg.contains("1000000000000 'vertex' elements"), "{msg}");
    let msg = parse_err(
        read_mesh_bytes(&data, MeshFormat::Ply, "mem.ply"),
        "mem.ply",
    );
    assert!(msg.contains("at least"), "{msg}");
    // Through the streaming API there is no size: the reservation is capped, the data ends.
    let msg = parse_err(ply(&data), "test.ply");
    assert!(msg.contains("u32 index range"), "{msg}");
    let small_header = header.replace("1000000000000", "5000000000");
    let mut data = small_header.into_bytes();
    data.extend_from_slice(&[0; 64]);
    let msg = parse_err(ply(&data), "test.ply");
    assert!(msg.contains("u32"), "{msg}");
    // An element without properties costs nothing however many items it claims.
    let empty = "ply\nformat binary_little_endian 1.0\nelement nothing 1000000000000000\n\
                 element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let mut data = empty.as_bytes().to_vec();
    for c in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        data.extend_from_slice(&c.to_le_bytes());
    }
    data.push(3);
    for i in [0i32, 1, 2] {
        data.extend_from_slice(&i.to_le_bytes());
    }
    assert_eq!(ply(&data).unwrap().triangle_count(), 1);
    let mid = header.replace("1000000000000", "400000000");
    let mut data = mid.into_bytes();
    data.extend_from_slice(&[0; 64]);
    let msg = parse_err(ply(&data), "test.ply");
    assert!(msg.contains("truncated"), "{msg}");
}

// ---------------------------------------------------------------------------------- STL ----

fn binary_stl(header: &[u8; 80], facets: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = header.to_vec();
    b.extend_from_slice(&(facets.len() as u32).to_le_bytes());
    for f in facets {
        b.extend_from_slice(&[0; 12]);
        for p in f {
            for c in p {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

#[test]
fn stl_ascii_merges_exactly_equal_points_in_first_seen_order() {
    let text = "solid my part\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n\
                vertex 1 0 0\n      vertex 0 1 0\n    endloop\n  endfacet\n\
                facet normal 0 0 1\n outer loop\n vertex 1 0 0\n vertex 1.0 1 0\n vertex -0.0 1 0\n\
                endloop\n endfacet\nfacet normal 0 0 0\nouter loop\nvertex 5 5 5\nvertex 5 5 5\n\
                vertex 1 1 1e-30\nendloop\nendfacet\nendsolid my part\n";
    let m = stl(text.as_bytes()).unwrap();
    assert_eq!(m.vertex_count(), 6);
    assert_eq!(tris(&m), vec![[0, 1, 2], [1, 3, 2], [4, 4, 5]]);
    assert_eq!(m.position(2), [0.0, 1.0, 0.0]);
}

#[test]
fn stl_binary_is_detected_by_size_even_when_it_starts_with_solid() {
    let mut header = [b' '; 80];
    header[..11].copy_from_slice(b"solid shiny");
    let f = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        [[-0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 1.0, 0.0]],
    ];
    let m = stl(&binary_stl(&header, &f)).unwrap();
    assert_eq!(m.vertex_count(), 5);
    assert_eq!(tris(&m), vec![[0, 1, 2], [1, 3, 2], [0, 4, 2]]);
    assert_eq!(m.position(4), [f64::from(0.1f32), 0.0, 0.0]);
    // Trailing bytes after the declared facets are ignored when not starting with "solid".
    let mut padded = binary_stl(&[0; 80], &f);
    padded.extend_from_slice(b"trailing");
    assert_eq!(stl(&padded).unwrap().triangle_count(), 3);
}

#[test]
fn stl_round_trip_keeps_f32_exact_meshes() {
    let m = tetra();
    let p = tmp_path("rt.STL");
    write_mesh(&p, &m).unwrap();
    let data = std::fs::read(&p).unwrap();
    assert_eq!(data.len(), 84 + 50 * 4);
    assert!(!data.starts_with(b"solid"));
    let back = read_mesh(&p).unwrap();
    assert_eq!(back, m);
    // Normals are unit and outward for the consistently oriented tetrahedron.
    let n0: Vec<f32> = (0..3)
        .map(|k| f32::from_le_bytes(data[84 + 4 * k..88 + 4 * k].try_into().unwrap()))
        .collect();
    assert_eq!(n0, vec![0.0, 0.0, 1.0]);
    let mut again = Vec::new();
    io::stl::write_stl(&mut again, &back).unwrap();
    assert_eq!(again, data);
}

#[test]
fn stl_write_rejects_coordinates_beyond_f32() {
    let m = awkward_mesh();
    let e = write_mesh(&tmp_path("big.stl"), &m).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument(_)), "{e:?}");
    assert!(e.to_string().contains("f32"), "{e}");
}

#[test]
fn stl_errors() {
    let one = binary_stl(&[0; 80], &[[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]);
    let mut huge = one.clone();
    huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let mut nan = one.clone();
    nan[84 + 12..84 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (huge, "truncated"),
        (one[..120].to_vec(), "truncated"),
        (nan, "non-finite"),
        (b"hello".to_vec(), "not an STL"),
        (Vec::new(), "not an STL"),
        (b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n".to_vec(), "inside a facet"),
        (b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n".to_vec(), "2 vertices"),
        (b"solid x\nfacet\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 1\nendfacet\nendsolid\n".to_vec(), "more than 3"),
        (b"solid x\nfacet\nvertex 0 0 zero\n".to_vec(), "line 3"),
        (b"solid x\nfacet\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendfacet\n".to_vec(), "endsolid"),
        (b"solid x\nbanana\nendsolid\n".to_vec(), "unexpected 'banana'"),
        (b"solid x\nendsolid x\n".to_vec(), "no triangles"),
    ];
    for (data, want) in cases {
        let msg = parse_err(stl(&data), "test.stl");
        assert!(
            msg.contains(want),
            "{}: {msg}",
            String::from_utf8_lossy(&data)
        );
    }
}

// --------------------------------------------------------------------------------- glTF ----

#[cfg(feature = "io-gltf")]
mod gltf_tests {
    use super::*;
    use pleat::mesh::io::gltf::{glb_bytes, gltf_embedded_string, read_gltf_bytes};

    fn f32_rounded(m: &TriMesh) -> Vec<[f64; 3]> {
        m.positions()
            .iter()
            .map(|p| p.map(|c| f64::from(c as f32)))
            .collect()
    }

    #[test]
    fn glb_and_gltf_round_trip_up_to_f32() {
        let m = TriMesh::new(
            vec![
                [0.1, 0.2, 0.3],
                [1.0 / 3.0, -5.0, 1e-9],
                [7.0, 8.0, -9.0],
                [1.0, 1.0, 1.0],
            ],
            vec![[0, 1, 2], [2, 1, 0]],
        )
        .unwrap();
        for file in ["rt.glb", "rt.GLTF"] {
            let p = tmp_path(file);
            write_mesh(&p, &m).unwrap();
            let back = read_mesh(&p).unwrap();
            assert_eq!(back.positions(), &f32_rounded(&m)[..], "{file}");
            assert_eq!(tris(&back), tris(&m), "{file}");
            let first = std::fs::read(&p).unwrap();
            write_mesh(&p, &back).unwrap();
            assert_eq!(std::fs::read(&p).unwrap(), first, "{file}: deterministic");
        }
        let json = gltf_embedded_string(&m).unwrap();
        assert!(json.contains("\"min\":[0.1,-5.0,-9.0]"), "{json}");
        assert!(json.contains("\"max\":[7.0,8.0,1.0]"), "{json}");
        assert!(json.contains("data:application/octet-stream;base64,"));
        let glb = glb_bytes(&m).unwrap();
        assert_eq!(&glb[..4], b"glTF");
        assert_eq!(glb.len() % 4, 0);
        assert_eq!(
            u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
            glb.len()
        );
    }

    #[test]
    fn gltf_write_rejects_coordinates_beyond_f32() {
        let e = write_mesh(&tmp_path("big.glb"), &awkward_mesh()).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument(_)), "{e:?}");
    }

    fn b64(data: &[u8]) -> String {
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for c in data.chunks(3) {
            let n = c
                .iter()
                .enumerate()
                .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
            for k in 0..4 {
                s.push(if k <= c.len() {
                    A[(n >> (18 - 6 * k) & 63) as usize] as char
                } else {
                    '='
                });
            }
        }
        s
    }

    /// Buffer: 4 positions (a unit square in z = 0) then u16 indices.
    fn square_buffer() -> Vec<u8> {
        let mut b = Vec::new();
        for p in [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]] {
            for c in p {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            b.extend_from_slice(&i.to_le_bytes());
        }
        b
    }

    /// A document whose buffer is `uri`, with meshes: 0 indexed triangles, 1 non-indexed strip,
    /// 2 fan, 3 points (skipped). `rest` adds "scene"/"scenes"/"nodes" members.
    fn document(uri: &str, rest: &str) -> String {
        format!(
            r#"{{"asset":{{"version":"2.0"}},{rest}
            "buffers":[{{"byteLength":60,"uri":"{uri}"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},
                           {{"buffer":0,"byteOffset":48,"byteLength":12}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3",
                           "min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}},
                      {{"primitives":[{{"attributes":{{"POSITION":0}},"mode":5}}]}},
                      {{"primitives":[{{"attributes":{{"POSITION":0}},"mode":6}},
                                      {{"attributes":{{"POSITION":0}},"mode":0}}]}}]}}"#
        )
    }

    fn data_uri() -> String {
        format!(
            "data:application/octet-stream;base64,{}",
            b64(&square_buffer())
        )
    }

    #[test]
    fn gltf_instantiates_the_default_scene_with_world_transforms() {
        let nodes = r#""scene":1,
            "scenes":[{"nodes":[3]},{"nodes":[0,2]}],
            "nodes":[{"translation":[10,0,0],"children":[1],"mesh":0},
                     {"scale":[2,2,2],"mesh":1},
                     {"matrix":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1],"mesh":2},
                     {"mesh":0}],"#;
        let json = document(&data_uri(), nodes);
        let m = read_gltf_bytes(json.as_bytes(), None, "scene.gltf").unwrap();
        assert_eq!(m.vertex_count(), 12);
        // Node 0: translated square; node 1 (child): translated then scaled strip; node 2:
        // mirrored fan (winding reversed), the points primitive skipped.
        assert_eq!(m.position(0), [10.0, 0.0, 0.0]);
        assert_eq!(m.position(6), [12.0, 2.0, 0.0]);
        assert_eq!(m.position(9), [-1.0, 0.0, 5.0]);
        assert_eq!(
            tris(&m),
            vec![
                [0, 1, 2],
                [0, 2, 3],
                [4, 5, 6],
                [5, 7, 6],
                [8, 10, 9],
                [8, 11, 10]
            ]
        );
    }

    #[test]
    fn gltf_without_scenes_takes_every_mesh_untransformed() {
        let json = document(&data_uri(), "");
        let m = read_gltf_bytes(json.as_bytes(), None, "flat.gltf").unwrap();
        assert_eq!(m.vertex_count(), 12);
        assert_eq!(m.triangle_count(), 6);
        assert_eq!(m.position(9), [1.0, 0.0, 0.0]);
    }

    #[test]
    fn gltf_reads_external_buffers_next_to_the_file() {
        let p = tmp_path("ext.gltf");
        std::fs::write(p.with_file_name("sq%20buf.bin"), square_buffer()).unwrap();
        std::fs::write(&p, document("sq%2520buf.bin", "")).unwrap();
        assert_eq!(read_mesh(&p).unwrap().triangle_count(), 6);
        let msg = parse_err(
            read_gltf_bytes(&std::fs::read(&p).unwrap(), None, "m.gltf"),
            "m.gltf",
        );
        assert!(msg.contains("from memory"), "{msg}");
        for uri in [
            "/etc/passwd",
            "file:///etc/passwd",
            "http://example.com/x.bin",
        ] {
            let msg = parse_err(
                read_gltf_bytes(document(uri, "").as_bytes(), Some(Path::new("/")), "u.gltf"),
                "u.gltf",
            );
            assert!(msg.contains("not a relative file path"), "{uri}: {msg}");
        }
    }

    #[test]
    fn gltf_reads_sparse_and_quantized_accessors() {
        // Positions: 4 × u16 VEC3 normalized (24 bytes) then a sparse substitution of vertex 2:
        // u8 index (padded to 4 bytes) and one f32 VEC3 for the f32 accessor.
        let mut buf = Vec::new();
        for p in [
            [0u16, 0, 0],
            [65535, 0, 0],
            [65535, 65535, 0],
            [0, 65535, 0],
        ] {
            for c in p {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        buf.extend_from_slice(&[2, 0, 0, 0]);
        for c in [5f32, 6., 7.] {
            buf.extend_from_slice(&c.to_le_bytes());
        }
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},
            "extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],
            "buffers":[{{"byteLength":{len},"uri":"data:;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":24}},
                           {{"buffer":0,"byteOffset":24,"byteLength":4}},
                           {{"buffer":0,"byteOffset":28,"byteLength":12}}],
            "accessors":[{{"bufferView":0,"componentType":5123,"normalized":true,"count":4,
                           "type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[5,6,7],
                           "sparse":{{"count":1,"indices":{{"bufferView":1,"componentType":5121}},
                                      "values":{{"bufferView":2}}}}}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"mode":6}},
                                      {{"attributes":{{"POSITION":1}},"mode":4}}]}}]}}"#,
            len = buf.len(),
            data = b64(&buf)
        );
        let m = read_gltf_bytes(json.as_bytes(), None, "q.gltf").unwrap();
        assert_eq!(m.position(2), [1.0, 1.0, 0.0]);
        assert_eq!(m.position(6), [5.0, 6.0, 7.0]);
        assert_eq!(m.position(7), [0.0, 0.0, 0.0]);
        assert_eq!(tris(&m), vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]);
    }

    #[test]
    fn gltf_hostile_documents_are_errors() {
        let cyclic = r#""scene":0,"scenes":[{"nodes":[0]}],
            "nodes":[{"children":[1],"mesh":0},{"children":[0]}],"#;
        let msg = parse_err(
            read_gltf_bytes(document(&data_uri(), cyclic).as_bytes(), None, "c.gltf"),
            "c.gltf",
        );
        assert!(msg.contains("not a tree"), "{msg}");
        let short = document(&format!("data:;base64,{}", b64(&square_buffer()[..40])), "");
        let msg = parse_err(read_gltf_bytes(short.as_bytes(), None, "s.gltf"), "s.gltf");
        assert!(msg.contains("holds only"), "{msg}");
        let over = document(&data_uri(), "").replace("\"count\":6", "\"count\":7");
        let msg = parse_err(read_gltf_bytes(over.as_bytes(), None, "o.gltf"), "o.gltf");
        assert!(msg.contains("exceed"), "{msg}");
        let strided = document(&data_uri(), "").replace(
            "\"byteOffset\":0,\"byteLength\":48}",
            "\"byteOffset\":0,\"byteLength\":48,\"byteStride\":4}",
        );
        let msg = parse_err(
            read_gltf_bytes(strided.as_bytes(), None, "st.gltf"),
            "st.gltf",
        );
        assert!(msg.contains("stride"), "{msg}");
        let mut nan = square_buffer();
        nan[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
        let doc = document(&format!("data:;base64,{}", b64(&nan)), "");
        let msg = parse_err(read_gltf_bytes(doc.as_bytes(), None, "n.gltf"), "n.gltf");
        assert!(msg.contains("non-finite"), "{msg}");
        let mut bad_index = square_buffer();
        bad_index[58] = 9;
        let doc = document(&format!("data:;base64,{}", b64(&bad_index)), "");
        let msg = parse_err(read_gltf_bytes(doc.as_bytes(), None, "i.gltf"), "i.gltf");
        assert!(msg.contains("out of range"), "{msg}");
        let draco = document(
            &data_uri(),
            r#""extensionsRequired":["KHR_draco_mesh_compression"],"#,
        );
        let msg = parse_err(read_gltf_bytes(draco.as_bytes(), None, "d.gltf"), "d.gltf");
        assert!(msg.contains("KHR_draco_mesh_compression"), "{msg}");
        let unlit = document(
            &data_uri(),
            r#""extensionsRequired":["KHR_materials_unlit"],"#,
        );
        assert!(read_gltf_bytes(unlit.as_bytes(), None, "u.gltf").is_ok());
        let invalid = document(&data_uri(), "").replace("\"bufferView\":1,", "\"bufferView\":7,");
        let msg = parse_err(
            read_gltf_bytes(invalid.as_bytes(), None, "v.gltf"),
            "v.gltf",
        );
        assert!(msg.contains("invalid glTF"), "{msg}");
        for data in [
            &b"glTF"[..],
            b"glTF\x02\0\0\0\0\0\0\0",
            b"glTF\x02\0\0\0\xff\xff\0\0JSON",
            b"{not json",
            b"",
        ] {
            parse_err(read_gltf_bytes(data, None, "g.glb"), "g.glb");
        }
    }

    #[test]
    fn gltf_hostile_glb_never_panics() {
        let glb = glb_bytes(&tetra()).unwrap();
        for cut in 0..glb.len() {
            let _ = read_gltf_bytes(&glb[..cut], None, "cut.glb");
        }
        let mut rng = Lcg(7);
        for _ in 0..300 {
            let mut g = glb.clone();
            for _ in 0..4 {
                let i = rng.below(g.len());
                g[i] = rng.next() as u8;
            }
            let _ = read_gltf_bytes(&g, None, "flip.glb");
        }
    }
}

#[cfg(not(feature = "io-gltf"))]
#[test]
fn gltf_without_the_feature_is_a_clear_error() {
    let e = read_mesh(Path::new("x.glb")).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument(_)) && e.to_string().contains("io-gltf"));
    let e = write_mesh(&tmp_path("x.gltf"), &tetra()).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument(_)) && e.to_string().contains("io-gltf"));
}

// ----------------------------------------------------------------------------- robustness ----

/// Deterministic pseudo-random numbers for mutation tests.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Valid encodings of a small mesh in every readable format.
fn encodings() -> Vec<(MeshFormat, Vec<u8>)> {
    let m = tetra();
    let mut out = Vec::new();
    let mut b = Vec::new();
    io::obj::write_obj(&mut b, &m).unwrap();
    out.push((MeshFormat::Obj, b));
    let mut b = Vec::new();
    io::ply::write_ply(&mut b, &m).unwrap();
    out.push((MeshFormat::Ply, b));
    let ascii_ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                     property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                     end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    out.push((MeshFormat::Ply, ascii_ply.as_bytes().to_vec()));
    out.push((
        MeshFormat::Ply,
        square_ply(Ty("double"), Ty("uchar"), Ty("uint"), true, "vertex_index"),
    ));
    let mut b = Vec::new();
    io::off::write_off(&mut b, &m).unwrap();
    out.push((MeshFormat::Off, b));
    let mut b = Vec::new();
    io::stl::write_stl(&mut b, &m).unwrap();
    out.push((MeshFormat::Stl, b));
    let ascii_stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
                     vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    out.push((MeshFormat::Stl, ascii_stl.as_bytes().to_vec()));
    out
}

#[test]
fn truncated_inputs_never_panic() {
    for (format, data) in encodings() {
        assert!(
            read_mesh_bytes(&data, format, "whole").is_ok(),
            "{format:?}"
        );
        for cut in 0..data.len() {
            if let Err(e) = read_mesh_bytes(&data[..cut], format, "cut") {
                assert!(
                    matches!(e, Error::Parse { .. }),
                    "{format:?} cut {cut}: {e:?}"
                );
            }
        }
    }
}

#[test]
fn mutated_and_garbage_inputs_never_panic() {
    let mut rng = Lcg(12345);
    for (format, data) in encodings() {
        for _ in 0..400 {
            let mut d = data.clone();
            for _ in 0..1 + rng.below(6) {
                let i = rng.below(d.len());
                d[i] = match rng.below(4) {
                    0 => rng.next() as u8,
                    1 => b'9',
                    2 => 0xff,
                    _ => b'-',
                };
            }
            let _ = read_mesh_bytes(&d, format, "mutated");
        }
    }
    for len in [0, 1, 5, 83, 84, 134, 1000, 4096] {
        let garbage: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        for format in [
            MeshFormat::Obj,
            MeshFormat::Ply,
            MeshFormat::Off,
            MeshFormat::Stl,
            MeshFormat::Glb,
        ] {
            if let Ok(m) = read_mesh_bytes(&garbage, format, "garbage") {
                panic!("{format:?} accepted {len} garbage bytes as {m:?}");
            }
        }
    }
}

// -------------------------------------------------------------------------------- corpus ----

/// The shared corpus: `$PLEAT_MESHES` when set, else `../shared/meshes` from the crate root
/// (the main checkout), else `../../shared/meshes` (a worktree under `/work/wt/`).
fn corpus_dir() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let candidates = [
        std::env::var_os("PLEAT_MESHES").map(PathBuf::from),
        Some(PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/meshes"
        ))),
        Some(root.join("../../shared/meshes")),
    ];
    let found = candidates
        .into_iter()
        .flatten()
        .find(|d| d.join("MANIFEST.csv").is_file());
    if found.is_none() {
        println!("skipping: ../shared/meshes not found");
    }
    found
}

/// MANIFEST.csv rows as column → value maps (fields may be quoted and contain commas).
fn manifest(dir: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(dir.join("MANIFEST.csv")).expect("read MANIFEST.csv");
    let mut lines = text.lines().map(split_csv);
    let header = lines.next().expect("header row");
    lines
        .filter(|r| r.len() == header.len())
        .map(|r| header.iter().cloned().zip(r).collect())
        .collect()
}

fn split_csv(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(String::new()),
            c => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

/// The topology numbers the checker reports on the unwelded soup.
struct Topology {
    referenced: usize,
    boundary_edges: usize,
    components: usize,
}

/// Counts as `meshcheck` does: an edge's incidence is the number of face corners `(u, v)` with
/// `u != v` on it; boundary edges have incidence 1; components are vertex-connected.
fn topology(m: &TriMesh) -> Topology {
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * m.triangle_count());
    let mut parent: Vec<u32> = (0..m.vertex_count() as u32).collect();
    fn find(p: &mut [u32], mut v: u32) -> u32 {
        while p[v as usize] != v {
            p[v as usize] = p[p[v as usize] as usize];
            v = p[v as usize];
        }
        v
    }
    let mut used = vec![false; m.vertex_count()];
    for t in m.triangles() {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            used[u as usize] = true;
            if u != v {
                edges.push((u.min(v), u.max(v)));
            }
            let (ru, rv) = (find(&mut parent, u), find(&mut parent, v));
            parent[ru as usize] = rv;
        }
    }
    edges.sort_unstable();
    let mut boundary_edges = 0;
    let mut i = 0;
    while i < edges.len() {
        let j = i + edges[i..].iter().take_while(|&&e| e == edges[i]).count();
        boundary_edges += usize::from(j - i == 1);
        i = j;
    }
    let referenced = used.iter().filter(|&&u| u).count();
    let components = (0..m.vertex_count() as u32)
        .filter(|&v| used[v as usize] && find(&mut parent, v) == v)
        .count();
    Topology {
        referenced,
        boundary_edges,
        components,
    }
}

/// Reads every corpus file and checks it against MANIFEST.csv. The columns, established by
/// running `meshcheck` (without `--weld`) on every file:
///
/// - `n_faces`: triangles after fan triangulation (meshcheck `n_triangles`);
/// - `n_file_faces`, `n_nontri_faces`: polygons in the file and those with more than three
///   corners (meshcheck `n_faces`, `n_non_triangle_faces`): not visible in a `TriMesh`;
/// - `n_vertices`: *referenced* vertices (meshcheck `n_referenced_vertices`), and
///   `n_vertices + n_unreferenced_vertices` is the file's vertex count (meshcheck `n_vertices`);
///   for STL (`note` = `stl-merged-exact`) vertices are the exactly-merged facet corners;
/// - `n_boundary_edges`, `n_components`: the unwelded soup's boundary edges and
///   vertex-connected components (meshcheck's numbers);
/// - `n_coincident_vertices` counts vertices sharing a position with another (not compared).
#[test]
fn corpus_matches_the_manifest() {
    let Some(dir) = corpus_dir() else { return };
    let rows = manifest(&dir);
    assert!(rows.len() >= 25, "MANIFEST has {} rows", rows.len());
    let num = |r: &HashMap<String, String>, k: &str| -> usize {
        r[k].parse()
            .unwrap_or_else(|_| panic!("column {k} = {:?}", r[k]))
    };
    for r in &rows {
        let path = dir.join(&r["path"]);
        let start = std::time::Instant::now();
        let m = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        let secs = start.elapsed().as_secs_f64();
        let t = topology(&m);
        let name = &r["path"];
        println!(
            "{name}: {} vertices, {} triangles, read in {:.3} s",
            m.vertex_count(),
            m.triangle_count(),
            secs
        );
        assert_eq!(m.triangle_count(), num(r, "n_faces"), "{name}: triangles");
        assert_eq!(
            t.referenced,
            num(r, "n_vertices"),
            "{name}: referenced vertices"
        );
        assert_eq!(
            m.vertex_count(),
            num(r, "n_vertices") + num(r, "n_unreferenced_vertices"),
            "{name}: vertices in the file"
        );
        assert_eq!(
            t.boundary_edges,
            num(r, "n_boundary_edges"),
            "{name}: boundary edges"
        );
        assert_eq!(t.components, num(r, "n_components"), "{name}: components");
        assert!(num(r, "n_faces") >= num(r, "n_file_faces"), "{name}");
    }
}

/// With `PLEAT_MESHCHECK=/path/to/meshcheck`, checks every corpus file read by pleat, written
/// back as OBJ, against the checker run on the original file: every count of the soup's
/// topology and geometry must agree (so the triangle index structure is the checker's).
#[test]
fn corpus_agrees_with_meshcheck() {
    let Ok(checker) = std::env::var("PLEAT_MESHCHECK") else {
        println!("skipping: set PLEAT_MESHCHECK to the meshcheck binary to run");
        return;
    };
    let Some(dir) = corpus_dir() else { return };
    let keys = [
        "n_vertices",
        "n_triangles",
        "n_duplicate_points",
        "n_referenced_vertices",
        "n_isolated_vertices",
        "n_degenerate_faces",
        "n_combinatorially_degenerate_faces",
        "surface_area",
        "n_edges",
        "n_boundary_edges",
        "n_nonmanifold_edges",
        "max_faces_per_edge",
        "n_misoriented_edges",
        "n_nonmanifold_vertices",
        "is_orientable",
        "n_components",
        "euler_characteristic",
        "signed_volume",
        "bbox_diagonal",
        "cgal_is_polygon_mesh",
    ];
    for r in manifest(&dir) {
        let path = dir.join(&r["path"]);
        let m = read_mesh(&path).unwrap();
        let dump = tmp_path(&format!("{}.obj", r["path"]));
        write_mesh(&dump, &m).unwrap();
        let theirs = run_meshcheck(&checker, &path);
        let ours = run_meshcheck(&checker, &dump);
        for k in keys {
            assert_eq!(
                json_field(&ours, k),
                json_field(&theirs, k),
                "{}: {k}",
                r["path"]
            );
        }
        println!("{}: agrees with meshcheck", r["path"]);
    }
}

fn run_meshcheck(checker: &str, path: &Path) -> String {
    let out = std::process::Command::new(checker)
        .arg("--no-si")
        .arg(path)
        .output()
        .expect("run meshcheck");
    String::from_utf8(out.stdout).expect("utf-8 JSON")
}

/// The raw text of `"key": value` in meshcheck's one-line JSON.
fn json_field(json: &str, key: &str) -> String {
    let pat = format!("\"{key}\": ");
    let start = json
        .find(&pat)
        .unwrap_or_else(|| panic!("no {key} in {json}"))
        + pat.len();
    let rest = &json[start..];
    let end = if rest.starts_with('[') {
        rest.find(']').map_or(rest.len(), |i| i + 1)
    } else {
        rest.find([',', '}']).unwrap_or(rest.len())
    };
    rest[..end].to_string()
}
