//! `PleatMesh`: create from caller buffers, copy out, destroy.

use super::boundary::{arg_out, arg_ref, arg_slice, destroy, guard_value, Out};
use super::common::{c_str_arg, guard, PleatStatus};
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// An indexed triangle mesh owned by pleat (opaque). Created by `pleat_mesh_create_*`,
/// `pleat_mesh_read_file` or an operation that returns a mesh; destroyed by
/// `pleat_mesh_destroy`. Immutable after creation, so it may be read from several threads at
/// once; destroying it while another thread uses it is undefined.
pub struct PleatMesh {
    pub(crate) mesh: TriMesh,
}

/// Borrows a mesh handle, failing with InvalidArgument on NULL.
///
/// # Safety
/// `m` is NULL or a live handle from pleat.
pub(crate) unsafe fn mesh_ref<'a>(m: *const PleatMesh, name: &str) -> Result<&'a TriMesh> {
    arg_ref(m, name).map(|m| &m.mesh)
}

impl Out<*mut PleatMesh> {
    /// Hands `mesh` to the caller as a new handle.
    pub(crate) fn put_mesh(self, mesh: TriMesh) {
        self.put_boxed(PleatMesh { mesh });
    }
}

fn check_stride(stride_bytes: usize, elem: usize) -> Result<usize> {
    let tight = 3 * elem;
    let stride = if stride_bytes == 0 {
        tight
    } else {
        stride_bytes
    };
    if stride < tight {
        return Err(Error::InvalidArgument(format!(
            "stride_bytes {stride_bytes} is smaller than 3 coordinates ({tight} bytes)"
        )));
    }
    Ok(stride)
}

fn try_vec<T>(n: usize, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| Error::LimitExceeded(format!("cannot allocate {n} {what}")))?;
    Ok(v)
}

/// Reads `count` strided xyz triples starting at `base`.
///
/// # Safety
/// `base` points to at least `(count-1)*stride + 3*size_of::<T>()` readable bytes.
unsafe fn read_xyz<T: Copy + Into<f64>>(
    base: *const u8,
    count: usize,
    stride: usize,
) -> Result<Vec<[f64; 3]>> {
    let mut out = try_vec(count, "vertices")?;
    for i in 0..count {
        let p = base.add(i * stride) as *const T;
        let c = |k: usize| -> f64 { std::ptr::read_unaligned(p.add(k)).into() };
        out.push([c(0), c(1), c(2)]);
    }
    Ok(out)
}

/// Shared body of the two create functions.
///
/// # Safety
/// As `pleat_mesh_create_f32`.
unsafe fn create<T: Copy + Into<f64>>(
    positions: *const T,
    vertex_count: usize,
    stride_bytes: usize,
    indices: *const u32,
    index_count: usize,
    out: *mut *mut PleatMesh,
) -> Result<()> {
    let out = arg_out(out, "out")?;
    arg_ref(positions, "positions")?;
    let idx = arg_slice(indices, index_count, "indices")?;
    if vertex_count == 0 {
        return Err(Error::InvalidArgument("vertex_count is 0".into()));
    }
    if index_count == 0 || index_count % 3 != 0 {
        return Err(Error::InvalidArgument(format!(
            "index_count {index_count} is not a positive multiple of 3"
        )));
    }
    if vertex_count > u32::MAX as usize {
        return Err(Error::InvalidArgument(format!(
            "vertex_count {vertex_count} exceeds the u32 index range"
        )));
    }
    let stride = check_stride(stride_bytes, std::mem::size_of::<T>())?;
    if (vertex_count - 1).checked_mul(stride).is_none() {
        return Err(Error::InvalidArgument(
            "vertex_count * stride_bytes overflows".into(),
        ));
    }
    let pos = read_xyz::<T>(positions as *const u8, vertex_count, stride)?;
    let mut tris = try_vec(index_count / 3, "triangles")?;
    tris.extend(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
    out.put_mesh(TriMesh::new(pos, tris)?);
    Ok(())
}

/// Creates a mesh from single-precision positions and 32-bit triangle indices.
///
/// - `positions`: `vertex_count` xyz triples, the i-th starting `i * stride_bytes` bytes after
///   `positions` (no alignment required); non-NULL; every coordinate finite.
/// - `vertex_count`: ≥ 1, ≤ 2^32 − 1.
/// - `stride_bytes`: bytes between consecutive vertices; 0 means tightly packed (12); otherwise
///   ≥ 12 (extra bytes, e.g. normals or UVs, are skipped).
/// - `indices`: `index_count` vertex indices, three per triangle, each < `vertex_count`; non-NULL.
/// - `index_count`: a positive multiple of 3.
/// - `out`: receives the new mesh on success (destroy with `pleat_mesh_destroy`); non-NULL.
///
/// Any soup is accepted (non-manifold, open, degenerate faces). Returns
/// `PLEAT_STATUS_INVALID_ARGUMENT` for NULL pointers, bad counts or strides, and
/// `PLEAT_STATUS_INVALID_MESH` for NaN/Inf coordinates or out-of-range indices.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_create_f32(
    positions: *const f32,
    vertex_count: usize,
    stride_bytes: usize,
    indices: *const u32,
    index_count: usize,
    out: *mut *mut PleatMesh,
) -> PleatStatus {
    guard(|| {
        create(
            positions,
            vertex_count,
            stride_bytes,
            indices,
            index_count,
            out,
        )
    })
}

/// Creates a mesh from double-precision positions; as `pleat_mesh_create_f32` with 8-byte
/// coordinates (tight stride 24 bytes).
///
/// # Safety
/// Pointers are NULL or valid for the sizes described in `pleat_mesh_create_f32`.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_create_f64(
    positions: *const f64,
    vertex_count: usize,
    stride_bytes: usize,
    indices: *const u32,
    index_count: usize,
    out: *mut *mut PleatMesh,
) -> PleatStatus {
    guard(|| {
        create(
            positions,
            vertex_count,
            stride_bytes,
            indices,
            index_count,
            out,
        )
    })
}

/// Destroys a mesh. NULL is accepted and ignored. Destroying the same handle twice is undefined.
///
/// # Safety
/// `mesh` is NULL or a handle from pleat not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_destroy(mesh: *mut PleatMesh) {
    destroy(mesh)
}

/// Number of vertices of `mesh` (0 when `mesh` is NULL).
///
/// # Safety
/// `mesh` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_vertex_count(mesh: *const PleatMesh) -> usize {
    guard_value(0, || mesh.as_ref().map_or(0, |m| m.mesh.vertex_count()))
}

/// Number of triangles of `mesh` (0 when `mesh` is NULL). The index count is 3× this.
///
/// # Safety
/// `mesh` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_triangle_count(mesh: *const PleatMesh) -> usize {
    guard_value(0, || mesh.as_ref().map_or(0, |m| m.mesh.triangle_count()))
}

/// Copies the positions into a caller buffer.
///
/// # Safety
/// `dst` is NULL or valid for `(vertex_capacity-1)*stride + 3*size_of::<T>()` bytes.
unsafe fn copy_positions<T: Copy>(
    mesh: *const PleatMesh,
    dst: *mut T,
    vertex_capacity: usize,
    stride_bytes: usize,
    conv: impl Fn(f64) -> T,
) -> Result<()> {
    let m = mesh_ref(mesh, "mesh")?;
    arg_out(dst, "dst")?;
    let stride = check_stride(stride_bytes, std::mem::size_of::<T>())?;
    let n = m.vertex_count();
    if vertex_capacity < n {
        return Err(Error::LimitExceeded(format!(
            "dst holds {vertex_capacity} vertices, the mesh has {n}"
        )));
    }
    for (i, p) in m.positions().iter().enumerate() {
        let q = (dst as *mut u8).add(i * stride) as *mut T;
        for (k, &c) in p.iter().enumerate() {
            std::ptr::write_unaligned(q.add(k), conv(c));
        }
    }
    Ok(())
}

/// Copies the vertex positions as floats (rounded to nearest) into `dst`.
///
/// - `dst`: room for `vertex_capacity` vertices at `stride_bytes` apart (0 = tight, 12); non-NULL.
/// - `vertex_capacity`: must be ≥ `pleat_mesh_vertex_count(mesh)`, else
///   `PLEAT_STATUS_LIMIT_EXCEEDED` and nothing is written.
///
/// Bytes of `dst` between the xyz triples are left untouched (interleaved layouts work).
///
/// # Safety
/// `mesh` is NULL or live; `dst` is NULL or valid for the described size.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_copy_positions_f32(
    mesh: *const PleatMesh,
    dst: *mut f32,
    vertex_capacity: usize,
    stride_bytes: usize,
) -> PleatStatus {
    guard(|| copy_positions(mesh, dst, vertex_capacity, stride_bytes, |c| c as f32))
}

/// Copies the vertex positions as doubles (exact); as `pleat_mesh_copy_positions_f32` with a
/// tight stride of 24 bytes.
///
/// # Safety
/// `mesh` is NULL or live; `dst` is NULL or valid for the described size.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_copy_positions_f64(
    mesh: *const PleatMesh,
    dst: *mut f64,
    vertex_capacity: usize,
    stride_bytes: usize,
) -> PleatStatus {
    guard(|| copy_positions(mesh, dst, vertex_capacity, stride_bytes, |c| c))
}

/// Copies the triangle indices (3 per triangle, counter-clockwise seen from outside for
/// outputs that promise orientation) into `dst`, which holds `index_capacity` values and must
/// hold at least `3 * pleat_mesh_triangle_count(mesh)`.
///
/// # Safety
/// `mesh` is NULL or live; `dst` is NULL or valid for `index_capacity` u32 values.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_copy_indices(
    mesh: *const PleatMesh,
    dst: *mut u32,
    index_capacity: usize,
) -> PleatStatus {
    guard(|| {
        let m = mesh_ref(mesh, "mesh")?;
        arg_out(dst, "dst")?;
        let n = 3 * m.triangle_count();
        if index_capacity < n {
            return Err(Error::LimitExceeded(format!(
                "dst holds {index_capacity} indices, the mesh has {n}"
            )));
        }
        let out = std::slice::from_raw_parts_mut(dst, n);
        for (o, t) in out.chunks_exact_mut(3).zip(m.triangles()) {
            o.copy_from_slice(t);
        }
        Ok(())
    })
}

/// Reads a mesh file: `.obj`, `.ply` (ascii/binary), `.off`, `.stl` (ascii/binary), and
/// `.glb`/`.gltf` when built with glTF support. The format is chosen by the (case-insensitive)
/// extension. The mesh is the soup exactly as stored (polygons fan-triangulated, all objects
/// merged, no welding except exact duplicates in STL).
///
/// - `path`: NUL-terminated UTF-8 path; non-NULL.
/// - `out`: receives the new mesh; non-NULL.
///
/// Returns `PLEAT_STATUS_IO` when the file cannot be read and `PLEAT_STATUS_PARSE` when its
/// content is invalid; the message names the file and, for text formats, the line.
///
/// # Safety
/// `path` is NULL or NUL-terminated; `out` is NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_read_file(
    path: *const std::ffi::c_char,
    out: *mut *mut PleatMesh,
) -> PleatStatus {
    guard(|| {
        let path = c_str_arg(path, "path")?;
        let out = arg_out(out, "out")?;
        out.put_mesh(crate::mesh::io::read_mesh(std::path::Path::new(path))?);
        Ok(())
    })
}

/// Writes a mesh file; the format is chosen by the extension: `.obj` and `.ply` (binary,
/// double precision) are lossless, `.off`, `.stl` (binary, float) and `.glb`/`.gltf` (float)
/// round coordinates to the format's precision.
///
/// # Safety
/// `mesh` is NULL or live; `path` is NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_write_file(
    mesh: *const PleatMesh,
    path: *const std::ffi::c_char,
) -> PleatStatus {
    guard(|| {
        let m = mesh_ref(mesh, "mesh")?;
        let path = c_str_arg(path, "path")?;
        crate::mesh::io::write_mesh(std::path::Path::new(path), m)
    })
}
