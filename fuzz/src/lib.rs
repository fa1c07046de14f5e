//! The fuzz targets' bodies and the helpers they share: a byte reader that turns fuzz input
//! into numbers, the fixed base mesh of the `.cwf`/`.cwfa` targets, and the checks every result
//! must pass.
//!
//! Each target is one function `fn(&[u8]) -> bool` listed in [`TARGETS`]: it panics on a
//! finding (a panic inside pleat, `PLEAT_STATUS_INTERNAL`, a broken invariant) and otherwise
//! returns whether the input was accepted (parsed, created, baked), so a caller can see how deep
//! its inputs reach. `fuzz/fuzz_targets/<name>.rs` is a one-line `fuzz_target!` over it (cargo-fuzz,
//! libFuzzer + ASan, nightly), and `tests/fuzz_smoke.rs` at the repository root includes this
//! file through `#[path]` for a bounded, stable-toolchain replay + mutation run in `cargo test`.
//! So this file depends on `pleat` (features lod, cage, wrinkle, io-gltf, tfw) and `std` only.

use std::ffi::c_void;
use std::mem::size_of;
use std::ptr;

use pleat::ffi::*;
use pleat::mesh::io::{read_mesh_bytes, MeshFormat};
use pleat::mesh::TriMesh;
use pleat::tfw::{solve_base, BaseOptions, Scene};
use pleat::wrinkle::animation::{animation_to_string, parse_animation};
use pleat::wrinkle::io::{cwf_to_string, parse_cwf};

/// A fuzz target: panics on a finding, otherwise returns whether the input was accepted.
pub type Target = fn(&[u8]) -> bool;

/// Every target by its cargo-fuzz name (`fuzz/Cargo.toml` `[[bin]]`, `fuzz/seeds/<name>/`).
pub const TARGETS: [(&str, Target); 11] = [
    ("obj", obj),
    ("ply", ply),
    ("off", off),
    ("stl", stl),
    ("gltf", gltf),
    ("cwf", cwf),
    ("cwfa", cwfa),
    ("mesh_create", mesh_create),
    ("lod_bake", lod_bake),
    ("wrinkle_eval", wrinkle_eval),
    ("tfw_scene", tfw_scene),
];

/// The target named `name`, if any.
pub fn target(name: &str) -> Option<Target> {
    TARGETS.iter().find(|(n, _)| *n == name).map(|&(_, t)| t)
}

/// The target a regression input belongs to: `fuzz/regressions/<target>-<what>.bin` (an
/// `-open` suffix marks a finding not fixed yet).
pub fn target_of_regression(file_name: &str) -> Option<(&'static str, Target)> {
    let prefix = file_name.split('-').next()?;
    TARGETS.iter().find(|(n, _)| *n == prefix).copied()
}

/// The regular files of `dir`, sorted by path (the seed and regression directories, read in
/// a fixed order by `tests/hardening.rs` and `tests/fuzz_smoke.rs`).
pub fn sorted_files(dir: &std::path::Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_file() {
            paths.push(path);
        }
    }
    paths.sort();
    Ok(paths)
}

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
/// Returns whether the reader accepted it.
pub fn read_and_check(data: &[u8], format: MeshFormat) -> bool {
    match read_mesh_bytes(data, format, "fuzz-input") {
        Ok(m) => {
            check_mesh(&m);
            true
        }
        Err(_) => false,
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
        // SAFETY: pleat_last_error returns a NUL-terminated string owned by this thread.
        let msg = unsafe { std::ffi::CStr::from_ptr(pleat_last_error()) };
        panic!("{what}: PLEAT_STATUS_INTERNAL: {}", msg.to_string_lossy());
    }
    status
}

// ---------------------------------------------------------------------------------------------
// The targets. Each doc comment says what the target feeds and checks (fuzz/README.md table).

/// OBJ reader (`read_mesh_bytes` with `MeshFormat::Obj`): no input may panic, hang or exhaust
/// memory; an accepted mesh satisfies the `TriMesh` invariants.
pub fn obj(data: &[u8]) -> bool {
    read_and_check(data, MeshFormat::Obj)
}

/// PLY reader (ascii and binary, chosen by the header): as [`obj`].
pub fn ply(data: &[u8]) -> bool {
    read_and_check(data, MeshFormat::Ply)
}

/// OFF reader: as [`obj`].
pub fn off(data: &[u8]) -> bool {
    read_and_check(data, MeshFormat::Off)
}

/// STL reader (ascii and binary, chosen by the content): as [`obj`].
pub fn stl(data: &[u8]) -> bool {
    read_and_check(data, MeshFormat::Stl)
}

/// glTF 2.0 reader, JSON (`.gltf`, buffers as `data:` URIs) and binary (`.glb`): the first
/// input byte picks the format (even: JSON, odd: GLB), the rest is the file. As [`obj`].
pub fn gltf(data: &[u8]) -> bool {
    let Some((&which, rest)) = data.split_first() else {
        return false;
    };
    let format = if which & 1 == 0 {
        MeshFormat::Gltf
    } else {
        MeshFormat::Glb
    };
    read_and_check(rest, format)
}

/// `.cwf` reader against a fixed base mesh (an octahedron): no input may panic; an accepted
/// file writes back to text that reads again to the same text (bit-exact round trip).
pub fn cwf(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    let Ok(cwf) = parse_cwf(&text, octahedron(), "fuzz-input") else {
        return false;
    };
    let out = cwf_to_string(&cwf);
    let again = parse_cwf(&out, octahedron(), "round-trip").expect("re-read");
    assert_eq!(cwf_to_string(&again), out);
    true
}

/// `.cwfa` animation reader against a fixed base mesh (an octahedron): no input may panic or
/// exhaust memory; an accepted animation evaluates its first, middle and last frames and writes
/// back to text that reads again to the same text.
pub fn cwfa(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    let Ok(anim) = parse_animation(&text, octahedron(), "fuzz-input") else {
        return false;
    };
    let last = anim.frame_count() - 1;
    for i in [0, last / 2, last] {
        anim.frame(i).expect("an existing frame");
    }
    assert!(anim.frame(last + 1).is_err() || last == usize::MAX);
    anim.frame_at(0.5).expect("t = 0.5");
    let out = animation_to_string(&anim);
    let again = parse_animation(&out, octahedron(), "round-trip").expect("re-read");
    assert_eq!(animation_to_string(&again), out);
    true
}

/// The C entry points that build a mesh from caller arrays: `pleat_mesh_create_f32/f64` with
/// arbitrary counts, strides, index values and coordinate bits (NaN, infinities, 1e±300), NULL
/// pointers and vertex counts beyond the documented 2³² − 1 (which must be rejected before any
/// read), then `pleat_mesh_check` on every accepted mesh with arbitrary flags and report
/// sizes, and a copy-back that must return the input exactly.
///
/// The buffers handed to pleat are always as large as the counts and stride claim (the C
/// contract); everything else is arbitrary. Any `PLEAT_STATUS_INTERNAL` is a finding.
pub fn mesh_create(data: &[u8]) -> bool {
    let mut r = Bytes::new(data);
    let mode = r.u8();
    let double = mode & 1 == 1;
    let elem = if double { 8 } else { 4 };
    let nv = (r.u8() % 24) as usize;
    let stride = match r.u8() % 4 {
        0 => 0,
        1 => 3 * elem,
        2 => 3 * elem + 4,
        _ => (r.u8() % 48) as usize, // may be below 3 * elem: must be rejected
    };
    let ni = (r.u8() % 64) as usize; // may be 0 or not a multiple of 3
    let step = stride.max(3 * elem);
    let mut pos = vec![0u8; nv * step + 3 * elem];
    for chunk in pos.chunks_mut(elem).take(nv * step / elem) {
        if double {
            chunk.copy_from_slice(&r.coord().to_le_bytes());
        } else {
            chunk.copy_from_slice(&(r.coord() as f32).to_le_bytes());
        }
    }
    let bound = nv as u32 + (mode >> 6) as u32; // sometimes out of range
    let idx: Vec<u32> = (0..ni)
        .map(|_| {
            let v = r.u32();
            if mode & 2 == 0 {
                v % bound.max(1)
            } else {
                v
            }
        })
        .collect();
    // Documented rejections that must happen before reading: a huge vertex count, NULLs.
    let claimed_nv = if mode & 4 != 0 && mode & 8 != 0 {
        (u32::MAX as usize) + 1 + (r.u8() as usize)
    } else {
        nv
    };
    let pos_ptr = if mode & 16 != 0 && ni % 5 == 0 {
        ptr::null()
    } else {
        pos.as_ptr()
    };
    let idx_ptr = if mode & 32 != 0 && nv % 7 == 0 {
        ptr::null()
    } else {
        idx.as_ptr()
    };
    let mut mesh: *mut PleatMesh = ptr::null_mut();
    // SAFETY: the buffers are as large as the counts and stride claim, or NULL.
    let status = unsafe {
        if double {
            pleat_mesh_create_f64(pos_ptr.cast(), claimed_nv, stride, idx_ptr, ni, &mut mesh)
        } else {
            pleat_mesh_create_f32(pos_ptr.cast(), claimed_nv, stride, idx_ptr, ni, &mut mesh)
        }
    };
    not_internal(status, "pleat_mesh_create");
    if status != PleatStatus::Ok {
        assert!(mesh.is_null());
        return false;
    }
    assert!(claimed_nv == nv && ni > 0 && ni % 3 == 0 && idx.iter().all(|&v| (v as usize) < nv));
    // SAFETY: `mesh` is a live handle; every output buffer is as large as the count passed.
    unsafe {
        assert_eq!(pleat_mesh_vertex_count(mesh), nv);
        assert_eq!(pleat_mesh_triangle_count(mesh), ni / 3);
        let mut back = vec![0u32; ni];
        assert_eq!(
            pleat_mesh_copy_indices(mesh, back.as_mut_ptr(), ni),
            PleatStatus::Ok
        );
        assert_eq!(back, idx);
        let mut xyz = vec![0f64; 3 * nv];
        assert_eq!(
            pleat_mesh_copy_positions_f64(mesh, xyz.as_mut_ptr(), nv, 0),
            PleatStatus::Ok
        );
        assert!(xyz.iter().all(|c| c.is_finite()));
        let mut report: PleatMeshReport = std::mem::zeroed();
        let full = size_of::<PleatMeshReport>() as u32;
        report.struct_size = match r.u8() % 3 {
            0 => full,
            1 => 8 + 4 * u32::from(r.u8()) % full.saturating_sub(8).max(1),
            _ => u32::from(r.u8()), // may be below 8: must be rejected
        }
        .min(full);
        let flags = u32::from(r.u8());
        not_internal(
            pleat_mesh_check(mesh, flags, &mut report),
            "pleat_mesh_check",
        );
        pleat_mesh_destroy(mesh);
    }
    true
}

/// A progress callback that cancels once the `u32` behind `user` has counted down to 0.
unsafe extern "C" fn countdown(user: *mut c_void, _info: *const PleatProgress) -> i32 {
    let left = &mut *(user as *mut u32);
    if *left == 0 {
        return 1;
    }
    *left -= 1;
    0
}

/// A LOD (or cage) bake through the C API on a small arbitrary triangle soup (up to 12
/// vertices and 16 triangles, arbitrary coordinates including 1e±300) at a small screen size,
/// with a work cap: at most 3 rounds, a 256 MiB memory budget, and a progress callback that
/// cancels after a fuzz-chosen number of calls. Any `PLEAT_STATUS_INTERNAL`, a panic, a hang
/// or an allocation beyond the fuzzer's RSS limit is a finding; a failed bake returns no mesh.
pub fn lod_bake(data: &[u8]) -> bool {
    let mut r = Bytes::new(data);
    let mode = r.u8();
    let nv = 3 + (r.u8() % 10) as usize;
    let nt = 1 + (r.u8() % 16) as usize;
    let pos: Vec<f64> = (0..3 * nv).map(|_| r.coord()).collect();
    let idx: Vec<u32> = (0..3 * nt).map(|_| r.u32() % nv as u32).collect();
    let mut mesh: *mut PleatMesh = ptr::null_mut();
    // SAFETY: buffers as large as the counts passed.
    let st =
        unsafe { pleat_mesh_create_f64(pos.as_ptr(), nv, 0, idx.as_ptr(), idx.len(), &mut mesh) };
    if not_internal(st, "pleat_mesh_create_f64") != PleatStatus::Ok {
        return false;
    }
    let mut p = pleat_lod_params_default();
    p.screen_size = match r.u8() % 4 {
        0 => f64::from(r.u8() % 32) + 0.5,
        1 => 4.0,
        2 => 16.0,
        _ => f64::from_bits(r.u64()), // arbitrary: NaN, negative, huge must be rejected
    };
    p.max_rounds = u32::from(r.u8() % 4);
    p.target_faces = if mode & 2 != 0 { u64::from(r.u8()) } else { 0 };
    p.flags = u32::from(r.u8() % 4);
    p.memory_budget_bytes = 256 << 20;
    let mut budget: u32 = if mode & 4 != 0 {
        u32::from(r.u8())
    } else {
        u32::MAX
    };
    let user = &mut budget as *mut u32 as *mut c_void;
    let mut out: *mut PleatMesh = ptr::null_mut();
    // SAFETY: live handles, valid params, a callback whose `user` outlives the call.
    unsafe {
        let st = if mode & 1 == 0 {
            pleat_lod_generate(mesh, &p, Some(countdown), user, &mut out, ptr::null_mut())
        } else {
            pleat_cage_generate(mesh, &p, Some(countdown), user, &mut out, ptr::null_mut())
        };
        not_internal(st, "lod/cage bake");
        pleat_mesh_destroy(mesh);
        if st == PleatStatus::Ok {
            assert!(pleat_mesh_triangle_count(out) > 0);
            pleat_mesh_destroy(out);
            true
        } else {
            assert!(out.is_null());
            false
        }
    }
}

/// Wrinkle-field creation and evaluation through the C API from arbitrary arrays: a small
/// arbitrary base mesh (which `pleat_cwf_create` must reject unless it is an oriented
/// manifold), arbitrary ω / amplitude / z̃ values (NaN, negative, 1e±300), mismatched counts,
/// z̃ omitted (Knöppel solve), then `pleat_cwf_evaluate` with arbitrary levels, flags, boundary
/// rule, corner angle, displacement scale and output cap, and a copy of every field.
/// Any `PLEAT_STATUS_INTERNAL` or panic is a finding.
pub fn wrinkle_eval(data: &[u8]) -> bool {
    let mut r = Bytes::new(data);
    let mode = r.u8();
    let (pos, idx): (Vec<f64>, Vec<u32>) = if mode & 1 == 0 {
        // the octahedron, so most inputs reach evaluation
        let m = octahedron();
        let p = m.positions().iter().flatten().copied().collect();
        let t = m.triangles().iter().flatten().copied().collect();
        (p, t)
    } else {
        let nv = 3 + (r.u8() % 8) as usize;
        let nt = 1 + (r.u8() % 10) as usize;
        let p = (0..3 * nv).map(|_| r.coord()).collect();
        let t = (0..3 * nt).map(|_| r.u32() % nv as u32).collect();
        (p, t)
    };
    let nv = pos.len() / 3;
    let mut base: *mut PleatMesh = ptr::null_mut();
    // SAFETY: buffers as large as the counts passed.
    let st =
        unsafe { pleat_mesh_create_f64(pos.as_ptr(), nv, 0, idx.as_ptr(), idx.len(), &mut base) };
    if not_internal(st, "pleat_mesh_create_f64") != PleatStatus::Ok {
        return false;
    }
    // SAFETY: live handles; every array is as long as the count passed with it.
    unsafe {
        let ne = pleat_mesh_edge_count(base);
        let ne_claim = if mode & 2 != 0 {
            ne + (r.u8() % 3) as usize
        } else {
            ne
        };
        let nv_claim = if mode & 4 != 0 {
            nv + (r.u8() % 3) as usize
        } else {
            nv
        };
        let small = |r: &mut Bytes<'_>| {
            if r.u8() < 250 {
                f64::from(r.u8() as i8) / 16.0
            } else {
                f64::from_bits(r.u64())
            }
        };
        let omega: Vec<f64> = (0..ne_claim).map(|_| small(&mut r)).collect();
        let amp: Vec<f64> = (0..nv_claim).map(|_| small(&mut r).abs() / 8.0).collect();
        let zeta: Vec<f64> = (0..2 * nv_claim).map(|_| small(&mut r)).collect();
        let zeta_ptr = if mode & 8 != 0 {
            ptr::null()
        } else {
            zeta.as_ptr()
        };
        let mut cwf: *mut PleatCwf = ptr::null_mut();
        let st = pleat_cwf_create(
            base,
            omega.as_ptr(),
            ne_claim,
            amp.as_ptr(),
            zeta_ptr,
            nv_claim,
            &mut cwf,
        );
        pleat_mesh_destroy(base);
        if not_internal(st, "pleat_cwf_create") != PleatStatus::Ok {
            return false;
        }
        let mut p = pleat_wrinkle_eval_params_default();
        p.levels = u32::from(r.u8() % 5);
        p.flags = u32::from(r.u8());
        p.boundary = u32::from(r.u8() % 4);
        if r.u8() & 1 == 1 {
            p.corner_angle = small(&mut r);
            p.displacement_scale = small(&mut r);
        }
        p.max_output_triangles = match r.u8() % 3 {
            0 => u64::from(r.u32()),
            1 => 1 << 14,
            _ => r.u64(),
        }
        .min(1 << 16);
        let mut out: *mut PleatMesh = ptr::null_mut();
        let mut fields: *mut PleatWrinkleFields = ptr::null_mut();
        let st = pleat_cwf_evaluate(
            cwf,
            &p,
            None,
            ptr::null_mut(),
            &mut out,
            &mut fields,
            ptr::null_mut(),
        );
        not_internal(st, "pleat_cwf_evaluate");
        if st == PleatStatus::Ok {
            for bit in 0..6 {
                let f = 1u32 << bit;
                let n = pleat_wrinkle_fields_count(fields, f);
                let mut buf = vec![0f64; 3 * n + 3];
                let st = pleat_wrinkle_fields_copy(fields, f, buf.as_mut_ptr(), n, 0);
                not_internal(st, "pleat_wrinkle_fields_copy");
            }
            pleat_wrinkle_fields_destroy(fields);
            pleat_mesh_destroy(out);
        }
        pleat_cwf_destroy(cwf);
        st == PleatStatus::Ok
    }
}

/// Vertices up to which an accepted TFW scene also gets its base solve.
const SOLVE_MAX_VERTICES: usize = 64;

/// TFW scene reader (scene files are untrusted input like the mesh files): the JSON bytes go
/// through the Rust parser (`Scene::from_json_str`) and the C entry point
/// (`pleat_tfw_scene_from_json`), which must agree on acceptance; no input may panic. An
/// accepted scene writes back to JSON that reads again, assembles to a model or a clear error,
/// and, when tiny (≤ 64 vertices), gets a bounded base solve (5 Newton iterations).
pub fn tfw_scene(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let rust = Scene::from_json_str(text);
    if !text.contains('\0') {
        let c_text = std::ffi::CString::new(text).expect("no interior NUL");
        let mut scene = ptr::null_mut();
        // SAFETY: a NUL-terminated string and a writable out slot.
        let status = unsafe { pleat_tfw_scene_from_json(c_text.as_ptr(), &mut scene) };
        assert_ne!(
            status,
            PleatStatus::Internal,
            "a panic behind the C entry point"
        );
        assert_eq!(
            status == PleatStatus::Ok,
            rust.is_ok(),
            "the C and Rust parsers disagree: {status:?} vs {:?}",
            rust.as_ref().err()
        );
        // SAFETY: NULL or a scene made above.
        unsafe { pleat_tfw_scene_destroy(scene) };
    }
    let Ok(scene) = rust else {
        return false;
    };
    let json = scene.to_json_string();
    Scene::from_json_str(&json).expect("an accepted scene's JSON reads again");
    let Ok(model) = scene.assemble() else {
        return true;
    };
    if model.positions.len() <= SOLVE_MAX_VERTICES {
        let options = BaseOptions {
            max_iterations: 5,
            ..BaseOptions::default()
        };
        // numerical trouble is a status of the result, never a panic
        let _ = solve_base(&model, &options, &mut |_| true);
    }
    true
}
