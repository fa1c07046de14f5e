//! Fuzzes a LOD (or cage) bake through the C API on a small arbitrary triangle soup (up to 12
//! vertices and 16 triangles, arbitrary coordinates including 1e±300) at a small screen size,
//! with a work cap: at most 3 rounds, a 256 MiB memory budget, and a progress callback that
//! cancels after a fuzz-chosen number of calls. Any `PLEAT_STATUS_INTERNAL`, a panic, a hang
//! (libFuzzer `-timeout`) or an allocation beyond `-rss_limit_mb` is a finding.
#![no_main]

use std::ffi::c_void;
use std::ptr;

use libfuzzer_sys::fuzz_target;
use pleat::ffi::*;
use pleat_fuzz::{not_internal, Bytes};

unsafe extern "C" fn countdown(user: *mut c_void, _info: *const PleatProgress) -> i32 {
    let left = &mut *(user as *mut u32);
    if *left == 0 {
        return 1;
    }
    *left -= 1;
    0
}

fuzz_target!(|data: &[u8]| {
    let mut r = Bytes::new(data);
    let mode = r.u8();
    let nv = 3 + (r.u8() % 10) as usize;
    let nt = 1 + (r.u8() % 16) as usize;
    let pos: Vec<f64> = (0..3 * nv).map(|_| r.coord()).collect();
    let idx: Vec<u32> = (0..3 * nt).map(|_| r.u32() % nv as u32).collect();
    let mut mesh: *mut PleatMesh = ptr::null_mut();
    let st =
        unsafe { pleat_mesh_create_f64(pos.as_ptr(), nv, 0, idx.as_ptr(), idx.len(), &mut mesh) };
    if not_internal(st, "pleat_mesh_create_f64") != PleatStatus::Ok {
        return;
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
    unsafe {
        let st = if mode & 1 == 0 {
            pleat_lod_generate(mesh, &p, Some(countdown), user, &mut out, ptr::null_mut())
        } else {
            pleat_cage_generate(mesh, &p, Some(countdown), user, &mut out, ptr::null_mut())
        };
        not_internal(st, "lod/cage bake");
        if st == PleatStatus::Ok {
            assert!(pleat_mesh_triangle_count(out) > 0);
            pleat_mesh_destroy(out);
        } else {
            assert!(out.is_null());
        }
        pleat_mesh_destroy(mesh);
    }
});
