//! Fuzzes wrinkle-field creation and evaluation through the C API from arbitrary arrays: a
//! small arbitrary base mesh (which `pleat_cwf_create` must reject unless it is an oriented
//! manifold), arbitrary ω / amplitude / z̃ values (NaN, negative, 1e±300), mismatched counts,
//! z̃ omitted (Knöppel solve), then `pleat_cwf_evaluate` with arbitrary levels, flags, boundary
//! rule, corner angle, displacement scale and output cap, and a copy of every field.
//! Any `PLEAT_STATUS_INTERNAL` or panic is a finding.
#![no_main]

use std::ptr;

use libfuzzer_sys::fuzz_target;
use pleat::ffi::*;
use pleat_fuzz::{not_internal, Bytes};

fuzz_target!(|data: &[u8]| {
    let mut r = Bytes::new(data);
    let mode = r.u8();
    let (pos, idx): (Vec<f64>, Vec<u32>) = if mode & 1 == 0 {
        // the octahedron, so most inputs reach evaluation
        let m = pleat_fuzz::octahedron();
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
    let st =
        unsafe { pleat_mesh_create_f64(pos.as_ptr(), nv, 0, idx.as_ptr(), idx.len(), &mut base) };
    if not_internal(st, "pleat_mesh_create_f64") != PleatStatus::Ok {
        return;
    }
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
            return;
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
    }
});
