//! Wrinkle design and region edits in the C ABI (capability `wrinkle`, issue 14, dissertation
//! §3.6): [`pleat_cwf_design`] (sources → keyframe), [`pleat_cwf_edit`] (rotate / rescale
//! regions of a keyframe) and [`pleat_mesh_grow_faces`] (a region from seeds grown by rings).
//! Outputs are ordinary immutable `PleatCwf` handles, so `pleat_cwf_interpolate` and
//! `pleat_cwf_evaluate` take them unchanged. The calls take well under a second on meshes of a
//! few thousand vertices and have no progress callback.

#![allow(clippy::too_many_arguments)]

use super::boundary::{full_size, requires, versioned};
#[cfg(feature = "wrinkle")]
use super::common::guard;
use super::common::PleatStatus;
use super::mesh::PleatMesh;
use super::wrinkle::{wrinkle_only, PleatCwf, PleatKnoppelParams};

/// Region growth across shared vertices (the dissertation's n-ring; default).
pub const PLEAT_ADJACENCY_VERTEX: u32 = 0;
/// Region growth across shared edges (the reference implementation's dilation).
pub const PLEAT_ADJACENCY_EDGE: u32 = 1;

/// Phase of an edit (eq. 3.28): compatibility of the unit phase (the dissertation's text).
pub const PLEAT_EDIT_PHASE_UNIT: u32 = 0;
/// Phase of an edit: amplitude-weighted compatibility (the reference implementation).
pub const PLEAT_EDIT_PHASE_AMPLITUDE_WEIGHTED: u32 = 1;

/// Face label written by `pleat_cwf_edit`: fixed (copied bit for bit).
pub const PLEAT_FACE_FIXED: u8 = 0;
/// Face label: inside an edited region.
pub const PLEAT_FACE_EDIT: u8 = 1;
/// Face label: in the solved interface band.
pub const PLEAT_FACE_INTERFACE: u8 = 2;

/// One wrinkle source of `pleat_cwf_design` (a plain array element, no `struct_size`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatWrinkleSource {
    /// The source vertex of the base mesh.
    pub vertex: u32,
    /// Region size in rings of faces, ≥ 1 (5 is the dissertation's GUI default).
    pub rings: u32,
    /// Wave vector in radians per length unit (its tangential part is used); finite.
    pub wave_vector: [f64; 3],
    /// Target amplitude (length unit), finite, ≥ 0.
    pub amplitude: f64,
}

/// Parameters of `pleat_cwf_design`. Get the defaults from `pleat_cwf_design_params_default()`;
/// `struct_size` versioned (at least 8).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatCwfDesignParams {
    /// `sizeof(PleatCwfDesignParams)`; at least 8.
    pub struct_size: u32,
    /// `PLEAT_ADJACENCY_VERTEX` (default) or `PLEAT_ADJACENCY_EDGE`.
    pub adjacency: u32,
    /// 1 (default): the amplitude equals the source's at each source vertex; 0: soft only.
    pub pin_sources: u32,
    /// Reserved, set to 0.
    pub reserved: u32,
    /// Heat time in units of the squared mean edge length, finite, > 0; default 1.
    pub heat_time: f64,
    /// κ of eq. 3.25 (amplitude smoothness), finite, ≥ 0; default 1.
    pub kappa: f64,
    /// γ of eq. 3.25 (curl penalty), finite, ≥ 0; default 1.
    pub gamma: f64,
    /// Multiplier of the data weights `A_j / h̄²`, finite, ≥ 0; default 1.
    pub data_weight: f64,
}

/// One region of `pleat_cwf_edit` (array element; `struct_size` must be
/// `sizeof(PleatCwfRegionEdit)` in every element).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatCwfRegionEdit {
    /// `sizeof(PleatCwfRegionEdit)`.
    pub struct_size: u32,
    /// Interface band width in rings (≥ 1 unless the region covers the mesh); typical 3.
    pub interface_rings: u32,
    /// The region's triangles (e.g. from `pleat_mesh_grow_faces`); non-NULL.
    pub faces: *const u32,
    /// Number of `faces`, ≥ 1.
    pub face_count: usize,
    /// Counter-clockwise rotation of the wrinkles about the normals, radians, finite.
    pub rotate_radians: f64,
    /// Frequency scale σ, finite, > 0 (1: unchanged).
    pub frequency_scale: f64,
    /// Amplitude scale μ, finite, ≥ 0 (1/σ keeps a·|ω|).
    pub amplitude_scale: f64,
}

/// Parameters of `pleat_cwf_edit`. Get the defaults from `pleat_cwf_edit_params_default()`;
/// `struct_size` versioned (at least 8).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatCwfEditParams {
    /// `sizeof(PleatCwfEditParams)`; at least 8.
    pub struct_size: u32,
    /// `PLEAT_ADJACENCY_VERTEX` (default) or `PLEAT_ADJACENCY_EDGE` (interface growth).
    pub adjacency: u32,
    /// `PLEAT_EDIT_PHASE_UNIT` (default) or `PLEAT_EDIT_PHASE_AMPLITUDE_WEIGHTED`.
    pub phase: u32,
    /// Inverse-iteration steps of the phase solve, 1 to 1,000,000; default 200.
    pub max_iterations: u32,
    /// ε_ω of eq. 3.26, finite, ≥ 0; default 1e-3.
    pub eps_omega: f64,
    /// ε_a of eq. 3.27, finite, ≥ 0; default 1e-3.
    pub eps_amplitude: f64,
    /// γ of eq. 3.27, finite, ≥ 0; default 1.
    pub gamma: f64,
    /// Inverse-iteration tolerance, finite, > 0; default 1e-12.
    pub tolerance: f64,
}

/// The default design parameters (vertex rings, sources pinned, heat time 1, κ = γ = 1, data
/// weight 1), with `struct_size` set. Available in every build.
#[no_mangle]
pub extern "C" fn pleat_cwf_design_params_default() -> PleatCwfDesignParams {
    PleatCwfDesignParams {
        struct_size: full_size::<PleatCwfDesignParams>(),
        adjacency: PLEAT_ADJACENCY_VERTEX,
        pin_sources: 1,
        reserved: 0,
        heat_time: 1.0,
        kappa: 1.0,
        gamma: 1.0,
        data_weight: 1.0,
    }
}

/// The default edit parameters (vertex rings, unit phase, 200 iterations, ε_ω = ε_a = 1e-3,
/// γ = 1, tolerance 1e-12), with `struct_size` set. Available in every build.
#[no_mangle]
pub extern "C" fn pleat_cwf_edit_params_default() -> PleatCwfEditParams {
    PleatCwfEditParams {
        struct_size: full_size::<PleatCwfEditParams>(),
        adjacency: PLEAT_ADJACENCY_VERTEX,
        phase: PLEAT_EDIT_PHASE_UNIT,
        max_iterations: 200,
        eps_omega: 1e-3,
        eps_amplitude: 1e-3,
        gamma: 1.0,
        tolerance: 1e-12,
    }
}

versioned!(PleatCwfDesignParams, 8, pleat_cwf_design_params_default);
versioned!(PleatCwfEditParams, 8, pleat_cwf_edit_params_default);

/// Designs a keyframe from wrinkle sources (§3.6.1): wave vectors extended from the sources by
/// the vector heat method, amplitude by eq. 3.25, phase by Knöppel; ω = 0 and a = 0 outside the
/// sources' regions.
///
/// - `base`: non-NULL, a consistently oriented manifold; pleat keeps its own copy.
/// - `sources`, `source_count`: at least one source; vertices in range, distinct.
/// - `params`: NULL = `pleat_cwf_design_params_default()`.
/// - `knoppel_params`: the final phase solve; NULL = `pleat_knoppel_params_default()`.
/// - `out`: receives the new field; non-NULL; written only on success.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_design(
    base: *const PleatMesh,
    sources: *const PleatWrinkleSource,
    source_count: usize,
    params: *const PleatCwfDesignParams,
    knoppel_params: *const PleatKnoppelParams,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    wrinkle_only!([base, sources, source_count, params, knoppel_params, out]
    guard(|| imp::design(base, sources, source_count, params, knoppel_params, out)))
}

/// Edits regions of a keyframe (§3.6.2): per region rotate by `rotate_radians`, scale the
/// frequency by σ and the amplitude by μ; the interface band is solved (eqs. 3.26–3.28) and the
/// rest copied bit for bit. Regions must not share a vertex, and the interface must separate
/// edited from fixed vertices (the message names the vertex).
///
/// - `cwf`: the keyframe; non-NULL.
/// - `regions`, `region_count`: at least one region.
/// - `params`: NULL = `pleat_cwf_edit_params_default()`.
/// - `out`: receives the edited keyframe (same base mesh); non-NULL.
/// - `face_labels_out`: NULL, or `pleat_cwf_triangle_count(cwf)` bytes receiving
///   `PLEAT_FACE_FIXED` / `_EDIT` / `_INTERFACE` per triangle.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_edit(
    cwf: *const PleatCwf,
    regions: *const PleatCwfRegionEdit,
    region_count: usize,
    params: *const PleatCwfEditParams,
    out: *mut *mut PleatCwf,
    face_labels_out: *mut u8,
) -> PleatStatus {
    wrinkle_only!([cwf, regions, region_count, params, out, face_labels_out]
    guard(|| imp::edit(cwf, regions, region_count, params, out, face_labels_out)))
}

/// A region of `mesh`: the seed triangles and the triangles of the seed vertices (ring 1),
/// grown by `rings − 1` more rings across `adjacency`. Writes 1 (in the region) or 0 per
/// triangle to `flags_out` (`pleat_mesh_triangle_count(mesh)` bytes) and the number of region
/// triangles to `count_out` (NULL allowed).
///
/// - `seed_faces` / `seed_vertices`: NULL only when their count is 0; ids in range.
/// - `rings` ≥ 1; `adjacency`: `PLEAT_ADJACENCY_VERTEX` or `PLEAT_ADJACENCY_EDGE`.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_grow_faces(
    mesh: *const PleatMesh,
    seed_faces: *const u32,
    seed_face_count: usize,
    seed_vertices: *const u32,
    seed_vertex_count: usize,
    rings: u32,
    adjacency: u32,
    flags_out: *mut u8,
    count_out: *mut usize,
) -> PleatStatus {
    wrinkle_only!([mesh, seed_faces, seed_face_count, seed_vertices, seed_vertex_count, rings,
        adjacency, flags_out, count_out]
    guard(|| imp::grow_faces(
        mesh, seed_faces, seed_face_count, seed_vertices, seed_vertex_count, rings, adjacency,
        flags_out, count_out
    )))
}

#[cfg(feature = "wrinkle")]
pub(super) mod imp {
    use super::*;
    use crate::ffi::boundary::{
        arg_out, arg_ref, arg_slice, bool_field, check_f64, check_range, read_versioned,
    };
    use crate::ffi::mesh::mesh_ref;
    use crate::ffi::wrinkle::imp::knoppel_options;
    use crate::wrinkle::{
        design as design_rs, edit as edit_rs, grow_faces as grow_rs, Adjacency, DesignOptions,
        EditOptions, FaceClass, PhaseCoupling, RegionEdit, WrinkleSource,
    };
    use crate::{Error, Result};

    fn adjacency(v: u32, name: &str) -> Result<Adjacency> {
        match v {
            PLEAT_ADJACENCY_VERTEX => Ok(Adjacency::Vertex),
            PLEAT_ADJACENCY_EDGE => Ok(Adjacency::Edge),
            _ => Err(Error::InvalidArgument(format!(
                "{name} is {v}; use PLEAT_ADJACENCY_VERTEX or PLEAT_ADJACENCY_EDGE"
            ))),
        }
    }

    /// The Rust options of a C design parameter struct (validated).
    pub(in crate::ffi) fn design_options(p: &PleatCwfDesignParams) -> Result<DesignOptions> {
        let nonneg = |v: f64, n: &str| check_f64(v, v.is_finite() && v >= 0.0, n, "finite, ≥ 0");
        nonneg(p.kappa, "params->kappa")?;
        nonneg(p.gamma, "params->gamma")?;
        nonneg(p.data_weight, "params->data_weight")?;
        check_f64(
            p.heat_time,
            p.heat_time.is_finite() && p.heat_time > 0.0,
            "params->heat_time",
            "finite, > 0",
        )?;
        Ok(DesignOptions {
            adjacency: adjacency(p.adjacency, "params->adjacency")?,
            heat_time: p.heat_time,
            kappa: p.kappa,
            gamma: p.gamma,
            data_weight: p.data_weight,
            pin_sources: bool_field(p.pin_sources, "params->pin_sources")?,
            ..DesignOptions::default()
        })
    }

    /// The Rust options of a C edit parameter struct (validated).
    pub(in crate::ffi) fn edit_options(p: &PleatCwfEditParams) -> Result<EditOptions> {
        let nonneg = |v: f64, n: &str| check_f64(v, v.is_finite() && v >= 0.0, n, "finite, ≥ 0");
        nonneg(p.eps_omega, "params->eps_omega")?;
        nonneg(p.eps_amplitude, "params->eps_amplitude")?;
        nonneg(p.gamma, "params->gamma")?;
        check_f64(
            p.tolerance,
            p.tolerance.is_finite() && p.tolerance > 0.0,
            "params->tolerance",
            "finite, > 0",
        )?;
        check_range(p.max_iterations, 1, 1_000_000, "params->max_iterations")?;
        Ok(EditOptions {
            adjacency: adjacency(p.adjacency, "params->adjacency")?,
            phase: match p.phase {
                PLEAT_EDIT_PHASE_UNIT => PhaseCoupling::Unit,
                PLEAT_EDIT_PHASE_AMPLITUDE_WEIGHTED => PhaseCoupling::AmplitudeWeighted,
                v => {
                    return Err(Error::InvalidArgument(format!(
                        "params->phase is {v}; use PLEAT_EDIT_PHASE_UNIT or \
                         PLEAT_EDIT_PHASE_AMPLITUDE_WEIGHTED"
                    )))
                }
            },
            max_iterations: p.max_iterations as usize,
            eps_omega: p.eps_omega,
            eps_amplitude: p.eps_amplitude,
            gamma: p.gamma,
            tolerance: p.tolerance,
            ..EditOptions::default()
        })
    }

    /// # Safety
    /// As `pleat_cwf_design`.
    pub(super) unsafe fn design(
        base: *const PleatMesh,
        sources: *const PleatWrinkleSource,
        source_count: usize,
        params: *const PleatCwfDesignParams,
        knoppel_params: *const PleatKnoppelParams,
        out: *mut *mut PleatCwf,
    ) -> Result<()> {
        let out = arg_out(out, "out")?;
        let m = mesh_ref(base, "base")?;
        let src = arg_slice(sources, source_count, "sources")?;
        let mut opts = design_options(&read_versioned(params, "params")?)?;
        opts.knoppel = knoppel_options(&read_versioned(knoppel_params, "knoppel_params")?)?;
        let rs: Vec<WrinkleSource> = src
            .iter()
            .map(|s| WrinkleSource {
                vertex: s.vertex,
                wave_vector: s.wave_vector,
                amplitude: s.amplitude,
                rings: s.rings as usize,
            })
            .collect();
        let (cwf, report) = design_rs(m.clone(), &rs, &opts)?;
        out.put_boxed(PleatCwf {
            cwf,
            knoppel: Some(report.knoppel),
        });
        Ok(())
    }

    /// # Safety
    /// As `pleat_cwf_edit`.
    pub(super) unsafe fn edit(
        cwf: *const PleatCwf,
        regions: *const PleatCwfRegionEdit,
        region_count: usize,
        params: *const PleatCwfEditParams,
        out: *mut *mut PleatCwf,
        face_labels_out: *mut u8,
    ) -> Result<()> {
        let out = arg_out(out, "out")?;
        let c = arg_ref(cwf, "cwf")?;
        let regs = arg_slice(regions, region_count, "regions")?;
        let opts = edit_options(&read_versioned(params, "params")?)?;
        let mut edits = Vec::with_capacity(regs.len());
        for (i, r) in regs.iter().enumerate() {
            if r.struct_size != full_size::<PleatCwfRegionEdit>() {
                return Err(Error::InvalidArgument(format!(
                    "regions[{i}].struct_size is {}; set it to sizeof(PleatCwfRegionEdit) = {}",
                    r.struct_size,
                    full_size::<PleatCwfRegionEdit>()
                )));
            }
            let faces = arg_slice(r.faces, r.face_count, &format!("regions[{i}].faces"))?;
            edits.push(RegionEdit {
                faces: faces.to_vec(),
                interface_rings: r.interface_rings as usize,
                rotate: r.rotate_radians,
                frequency_scale: r.frequency_scale,
                amplitude_scale: r.amplitude_scale,
            });
        }
        let (k1, report) = edit_rs(&c.cwf, &edits, &opts)?;
        if !face_labels_out.is_null() {
            // SAFETY: the caller provides triangle_count bytes (documented contract)
            let labels = std::slice::from_raw_parts_mut(face_labels_out, report.face_class.len());
            for (l, fc) in labels.iter_mut().zip(&report.face_class) {
                *l = match fc {
                    FaceClass::Fixed => PLEAT_FACE_FIXED,
                    FaceClass::Edit => PLEAT_FACE_EDIT,
                    FaceClass::Interface => PLEAT_FACE_INTERFACE,
                };
            }
        }
        out.put_boxed(PleatCwf {
            cwf: k1,
            knoppel: None,
        });
        Ok(())
    }

    /// # Safety
    /// As `pleat_mesh_grow_faces`.
    pub(super) unsafe fn grow_faces(
        mesh: *const PleatMesh,
        seed_faces: *const u32,
        seed_face_count: usize,
        seed_vertices: *const u32,
        seed_vertex_count: usize,
        rings: u32,
        adjacency_v: u32,
        flags_out: *mut u8,
        count_out: *mut usize,
    ) -> Result<()> {
        let m = mesh_ref(mesh, "mesh")?;
        let flags = arg_out(flags_out, "flags_out")?;
        let sf: &[u32] = if seed_face_count == 0 {
            &[]
        } else {
            arg_slice(seed_faces, seed_face_count, "seed_faces")?
        };
        let sv: &[u32] = if seed_vertex_count == 0 {
            &[]
        } else {
            arg_slice(seed_vertices, seed_vertex_count, "seed_vertices")?
        };
        let faces = grow_rs(
            m,
            sf,
            sv,
            rings as usize,
            adjacency(adjacency_v, "adjacency")?,
        )?;
        let mut mask = vec![0u8; m.triangle_count()];
        for &f in &faces {
            mask[f as usize] = 1;
        }
        for (i, &b) in mask.iter().enumerate() {
            flags.add(i).put(b);
        }
        if !count_out.is_null() {
            count_out.write(faces.len());
        }
        Ok(())
    }
}
