//! Helpers shared by the fuzz targets: a byte reader that turns fuzz input into numbers, the
//! fixed base mesh of the `.cwf`/`.cwfa` targets, and the checks every reader result must pass.

use pleat::ffi::PleatStatus;
use pleat::mesh::io::{read_mesh_bytes, MeshFormat};
use pleat::mesh::TriMesh;

/// Reads little-endian numbers from the fuzz input; past the end it yields zeros, so every
/// input, however short, drives the target to the end.
pub struct Bytes<'a> {
    data: &'a [u8],
}

impl<'a> Bytes<'a> {
    /// A reader over `data`.
    pub fn new(data: &'a [u8]) -> Bytes<'a> {
        Bytes { data }
    }

    /// The next `n` bytes, zero-padded.
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let n = N.min(self.data.len());
        out[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        out
    }

    /// The next byte.
    pub fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }

    /// The next `u32`.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }

    /// The next `u64`.
    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }

    /// A coordinate: mostly a small grid value (`i16 / 64`), sometimes raw `f64` bits (NaN,
    /// infinities, 1e±300, subnormals).
    pub fn coord(&mut self) -> f64 {
        if self.u8() < 240 {
            f64::from(i16::from_le_bytes(self.take())) / 64.0
        } else {
            f64::from_bits(self.u64())
        }
    }

    /// Whether input remains.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}

/// Reads `data` as `format` and, on success, checks the mesh invariants the readers promise.
pub fn read_and_check(data: &[u8], format: MeshFormat) {
    if let Ok(m) = read_mesh_bytes(data, format, "fuzz-input") {
        check_mesh(&m);
    }
}

/// The [`TriMesh`] invariants: at least one triangle, indices in range, finite coordinates.
pub fn check_mesh(m: &TriMesh) {
    assert!(m.triangle_count() > 0);
    let nv = m.vertex_count();
    assert!(m.triangles().iter().flatten().all(|&v| (v as usize) < nv));
    assert!(m.positions().iter().flatten().all(|c| c.is_finite()));
}

/// A regular octahedron (6 vertices, 12 edges, 8 consistently oriented triangles): the base
/// mesh of the `.cwf` and `.cwfa` targets. `fuzz/gen_seeds.py` writes seeds for it.
pub fn octahedron() -> TriMesh {
    let p = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let t = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    TriMesh::new(p, t).expect("octahedron")
}

/// Panics (a fuzz finding) when a C entry point reports an internal error: a caught panic or
/// a bug, never an acceptable answer to any input. Returns `status` otherwise.
pub fn not_internal(status: PleatStatus, what: &str) -> PleatStatus {
    if status == PleatStatus::Internal {
        let msg = unsafe { std::ffi::CStr::from_ptr(pleat::ffi::pleat_last_error()) };
        panic!("{what}: PLEAT_STATUS_INTERNAL: {}", msg.to_string_lossy());
    }
    status
}
