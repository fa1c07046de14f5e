//! The C defaults cannot drift from the Rust ones: for every C parameters struct, its
//! `pleat_*_params_default()` converts back to the Rust parameters' `Default`, field by field
//! (the Rust types derive `PartialEq`), and the copy used by builds without the capability is
//! the same struct.

use super::*;

/// Bitwise equality of two `#[repr(C)]` parameter structs without padding-sensitive fields
/// (`PartialEq` is not derived by every one of them; NaN-free defaults compare equal bitwise).
fn same_bytes<T: Copy>(a: &T, b: &T) -> bool {
    let n = std::mem::size_of::<T>();
    // SAFETY: both are valid `T`s; the C parameter structs have no padding.
    unsafe {
        std::slice::from_raw_parts(a as *const T as *const u8, n)
            == std::slice::from_raw_parts(b as *const T as *const u8, n)
    }
}

/// `lod::imp::to_rust` on parameters whose `deformation` is NULL (every test struct here).
#[cfg(feature = "lod")]
fn lod_to_rust(c: &PleatLodParams) -> crate::Result<crate::lowpoly::LodParams> {
    assert!(c.deformation.is_null());
    // SAFETY: no deformation handle to read.
    unsafe { lod::imp::to_rust(c) }
}

#[cfg(feature = "lod")]
#[test]
fn lod_params_default_is_rust_default() {
    let c = pleat_lod_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatLodParams>()
    );
    let rust = lod_to_rust(&c).expect("the C default is valid");
    assert_eq!(rust, crate::lowpoly::LodParams::default());
    assert!(same_bytes(&c, &lod::defaults_without_lod()));
}

#[cfg(feature = "lod")]
#[test]
fn transfer_params_default_is_rust_default() {
    let c = pleat_transfer_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatTransferParams>()
    );
    let rust = transfer::imp::to_rust(&c).expect("the C default is valid");
    assert_eq!(rust, crate::transfer::TransferParams::default());
    assert_eq!(
        c.skin_smoothing,
        crate::transfer::SkinParams::default().smoothing_iterations
    );
}

#[cfg(feature = "lod")]
#[test]
fn offset_params_default_is_rust_default() {
    let c = pleat_offset_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatOffsetParams>()
    );
    let rust = offset::to_rust(&c).expect("the C default is valid");
    assert_eq!(rust, crate::lowpoly::OffsetParams::default());
    assert!(same_bytes(&c, &offset::defaults_without_lod()));
}

#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_eval_params_default_is_rust_default() {
    let c = pleat_wrinkle_eval_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatWrinkleEvalParams>()
    );
    let rust = wrinkle::imp::eval_options(&c, true).expect("the C default is valid");
    assert_eq!(rust, crate::wrinkle::EvalOptions::default());
    assert_eq!(c, wrinkle::defaults_without_wrinkle().0);
}

#[cfg(feature = "wrinkle")]
#[test]
fn knoppel_params_default_is_rust_default() {
    let c = pleat_knoppel_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatKnoppelParams>()
    );
    let rust = wrinkle::imp::knoppel_options(&c).expect("the C default is valid");
    assert_eq!(rust, crate::wrinkle::KnoppelOptions::default());
    assert_eq!(c, wrinkle::defaults_without_wrinkle().1);
}

#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_interp_params_default_is_rust_default() {
    let c = pleat_wrinkle_interp_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatWrinkleInterpParams>()
    );
    let rust = interpolate::imp::options(&c).expect("the C default is valid");
    assert_eq!(rust, crate::wrinkle::InterpOptions::default());
    assert_eq!(c, interpolate::defaults_without_wrinkle());
}

/// A shorter caller struct keeps the defaults past its `struct_size`; a too-short one is
/// refused with the one message format.
#[test]
fn read_versioned_honours_struct_size() {
    use super::boundary::read_versioned;
    let mut p = pleat_lod_params_default();
    p.struct_size = 16;
    p.screen_size = 50.0;
    p.flow_ratio = 0.5; // beyond 16 bytes: ignored
                        // SAFETY: `p` is a valid struct.
    let r = unsafe { read_versioned(&p, "params") }.unwrap();
    assert_eq!(r.screen_size, 50.0);
    assert_eq!(r.flow_ratio, pleat_lod_params_default().flow_ratio);
    assert_eq!(
        r.struct_size as usize,
        std::mem::size_of::<PleatLodParams>()
    );
    p.struct_size = 4;
    // SAFETY: as above.
    let e = unsafe { read_versioned(&p, "params") }.unwrap_err();
    assert_eq!(
        e.to_string(),
        "invalid argument: params->struct_size is 4 (at least 16 is needed); set it to \
         sizeof(PleatLodParams), e.g. with pleat_lod_params_default()"
    );
}

/// A v1 `PleatBakeParams` (48 bytes, before `vertex_colors`) reads the appended fields'
/// defaults; an unknown `vertex_colors` is a readable error.
#[cfg(feature = "bake")]
#[test]
fn bake_params_v1_size_and_vertex_colors_are_checked() {
    use super::boundary::read_versioned;
    let mut c = pleat_bake_params_default();
    c.vertex_colors = PLEAT_VERTEX_COLORS_TEXTURE;
    c.struct_size = 48;
    // SAFETY: `c` is a full, live struct; pleat reads its first 48 bytes.
    let v1 = unsafe { read_versioned(&c, "params") }.unwrap();
    assert_eq!(v1.vertex_colors, PLEAT_VERTEX_COLORS_AUTO);
    c.struct_size = std::mem::size_of::<PleatBakeParams>() as u32;
    let (rust, _) = bake::imp::bake_params(&c).unwrap();
    assert_eq!(rust.vertex_colors, crate::bake::VertexColors::Texture);
    c.vertex_colors = 3;
    let e = bake::imp::bake_params(&c).unwrap_err().to_string();
    assert!(e.contains("params->vertex_colors"), "{e}");
}

#[cfg(feature = "bake")]
#[test]
fn bake_params_default_is_rust_default() {
    let c = pleat_bake_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatBakeParams>()
    );
    let (rust, screen_size) = bake::imp::bake_params(&c).expect("the C default is valid");
    assert_eq!(rust, crate::bake::BakeParams::default());
    assert_eq!(
        screen_size,
        crate::lowpoly::LodParams::default().screen_size
    );
    let p = pleat_provenance_params_default();
    assert_eq!(p.struct_size as usize, std::mem::size_of_val(&p));
    assert_eq!(
        (p.screen_size, p.envelope_d),
        (screen_size, rust.envelope_d)
    );
    let m = pleat_bake_material_default();
    let r = crate::bake::BufferMaterial::default();
    assert_eq!(m.struct_size as usize, std::mem::size_of_val(&m));
    assert_eq!(
        (m.base_color_factor, m.metallic_factor, m.roughness_factor),
        (r.base_color_factor, r.metallic_factor, r.roughness_factor)
    );
    assert_eq!(
        (m.normal_scale, m.occlusion_strength, m.emissive_factor),
        (r.normal_scale, r.occlusion_strength, r.emissive_factor)
    );
}

#[cfg(feature = "wrinkle")]
#[test]
fn cwf_design_and_edit_params_default_are_rust_default() {
    let c = pleat_cwf_design_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatCwfDesignParams>()
    );
    let rust = design::imp::design_options(&c).expect("the C default is valid");
    assert_eq!(rust, crate::wrinkle::DesignOptions::default());
    let c = pleat_cwf_edit_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatCwfEditParams>()
    );
    let rust = design::imp::edit_options(&c).expect("the C default is valid");
    assert_eq!(rust, crate::wrinkle::EditOptions::default());
}

#[cfg(feature = "tfw")]
#[test]
fn tfw_params_default_is_rust_default() {
    let c = pleat_tfw_params_default();
    assert_eq!(
        c.struct_size as usize,
        std::mem::size_of::<PleatTfwParams>()
    );
    let rust = tfw::imp::params(&c).expect("the C default is valid");
    assert_eq!(rust, crate::tfw::TfwParams::default());
    assert_eq!(c, tfw::defaults_without_tfw());
}

/// A caller compiled before `edit_weight`, `compat_target` and `max_interface_rings` were
/// appended (struct_size = offset of `edit_weight`) gets their defaults, whatever the bytes
/// after its struct; the new fields are validated with messages naming them.
#[cfg(feature = "wrinkle")]
#[test]
fn cwf_edit_params_older_size_and_new_fields() {
    use super::boundary::read_versioned;
    let mut p = pleat_cwf_edit_params_default();
    p.struct_size = std::mem::offset_of!(PleatCwfEditParams, edit_weight) as u32;
    assert_eq!(p.struct_size, 48, "the published size before 2026-11-27");
    (p.edit_weight, p.compat_target, p.max_interface_rings) = (f64::NAN, -1.0, 0);
    let read = unsafe { read_versioned(&p, "params") }.unwrap();
    let rust = design::imp::edit_options(&read).expect("older struct valid");
    assert_eq!(rust, crate::wrinkle::EditOptions::default());
    let full = pleat_cwf_edit_params_default();
    for (bad, field) in [
        (
            PleatCwfEditParams {
                compat_target: f64::NAN,
                ..full
            },
            "compat_target",
        ),
        (
            PleatCwfEditParams {
                compat_target: -0.3,
                ..full
            },
            "compat_target",
        ),
        (
            PleatCwfEditParams {
                edit_weight: f64::NAN,
                ..full
            },
            "edit_weight",
        ),
        (
            PleatCwfEditParams {
                edit_weight: 0.5,
                ..full
            },
            "edit_weight",
        ),
        (
            PleatCwfEditParams {
                max_interface_rings: 0,
                ..full
            },
            "max_interface_rings",
        ),
    ] {
        let e = design::imp::edit_options(&bad).unwrap_err().to_string();
        assert!(e.contains(&format!("params->{field}")), "{e}");
    }
    let set = PleatCwfEditParams {
        compat_target: 0.3,
        edit_weight: 4.0,
        max_interface_rings: 6,
        ..full
    };
    let rust = design::imp::edit_options(&set).unwrap();
    assert_eq!(
        (
            rust.compat_target,
            rust.edit_weight,
            rust.max_interface_rings
        ),
        (0.3, 4.0, 6)
    );
}

/// The interpolation params before `locality` was appended keep locality on; 0 turns it off;
/// other values are refused naming the field.
#[cfg(feature = "wrinkle")]
#[test]
fn wrinkle_interp_params_locality_field() {
    use super::boundary::read_versioned;
    let mut p = pleat_wrinkle_interp_params_default();
    p.struct_size = std::mem::offset_of!(PleatWrinkleInterpParams, locality) as u32;
    assert_eq!(p.struct_size, 40, "the published size before 2026-11-27");
    p.locality = 0;
    let read = unsafe { read_versioned(&p, "params") }.unwrap();
    assert!(interpolate::imp::options(&read).unwrap().locality);
    let off = PleatWrinkleInterpParams {
        locality: 0,
        ..pleat_wrinkle_interp_params_default()
    };
    assert!(!interpolate::imp::options(&off).unwrap().locality);
    let bad = PleatWrinkleInterpParams { locality: 2, ..off };
    let e = interpolate::imp::options(&bad).unwrap_err().to_string();
    assert!(e.contains("params->locality"), "{e}");
}

/// `PleatLodParams::offset_voxel_scale`: 0 and older struct sizes are automatic, (0, 2] is passed
/// on, NaN/negative/> 2 are refused naming the field.
#[cfg(feature = "lod")]
#[test]
fn lod_params_offset_voxel_scale_is_checked() {
    use super::boundary::read_versioned;
    let mut c = pleat_lod_params_default();
    c.offset_voxel_scale = 1.5;
    assert_eq!(lod_to_rust(&c).unwrap().offset_voxel_scale, Some(1.5));
    // an older caller (up to `clearance`) gets automatic
    c.struct_size = std::mem::offset_of!(PleatLodParams, offset_voxel_scale) as u32;
    // SAFETY: `c` is a full, live struct; pleat reads its first `struct_size` bytes.
    let old = unsafe { read_versioned(&c, "params") }.unwrap();
    assert_eq!(lod_to_rust(&old).unwrap().offset_voxel_scale, None);
    for bad in [f64::NAN, -1.0, 2.5, f64::INFINITY] {
        c.offset_voxel_scale = bad;
        let e = lod_to_rust(&c).unwrap_err().to_string();
        assert!(e.contains("params->offset_voxel_scale"), "{e}");
    }
}
