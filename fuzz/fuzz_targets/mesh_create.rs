//! Fuzzes the C entry points that build a mesh from caller arrays: `pleat_mesh_create_f32/f64`
//! with arbitrary counts, strides, index values and coordinate bits (NaN, infinities,
//! 1e±300), NULL pointers and vertex counts beyond the documented 2³² − 1 (which must be
//! rejected before any read), then `pleat_mesh_check` on every accepted mesh with arbitrary
//! flags and report sizes, and a copy-back that must return the input exactly.
//!
//! The buffers handed to pleat are always as large as the counts and stride claim (the C
//! contract); everything else is arbitrary. Any `PLEAT_STATUS_INTERNAL` is a finding.
#![no_main]

use std::mem::size_of;
use std::ptr;

use libfuzzer_sys::fuzz_target;
use pleat::ffi::*;
use pleat_fuzz::{not_internal, Bytes};

fuzz_target!(|data: &[u8]| {
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
        return;
    }
    assert!(claimed_nv == nv && ni > 0 && ni % 3 == 0 && idx.iter().all(|&v| (v as usize) < nv));
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
});
