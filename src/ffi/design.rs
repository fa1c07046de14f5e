//! Wrinkle design and region edits in the C ABI (capability `wrinkle`, dissertation §3.6):
//! [`pleat_cwf_design`] (sources → keyframe), [`pleat_cwf_edit`] (rotate / rescale regions of a
//! keyframe) and [`pleat_mesh_grow_faces`] (a region from seeds grown by rings).
//! Outputs are ordinary immutable `PleatCwf` handles, so `pleat_cwf_interpolate` and
//! `pleat_cwf_evaluate` take them unchanged. The calls take well under a second on meshes of a
//! few thousand vertices; on large meshes, [`pleat_cwf_design_with_progress`] and
//! [`pleat_cwf_edit_with_progress`] report progress and can be cancelled.

#![allow(clippy::too_many_arguments)]

use super::boundary::{full_size, requires, versioned};
#[cfg(feature = "wrinkle")]
use super::common::{guard, guard_progress};
use super::common::{PleatProgressFn, PleatStatus};
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
    /// Weight of the edit edges' compatibility terms in the phase solve (eq. 3.28) relative to
    /// the interface edges', finite, ≥ 1; default 1 (the literal eq. 3.28). Appended
    /// 2026-11-27: an older, shorter struct gets the default.
    pub edit_weight: f64,
    /// Adaptive interface width: target RMS compatibility residual over edit + interface edges,
    /// radians, finite, ≥ 0; default 0.3 (the smoothness asked of an interface; also what an older,
    /// shorter struct gets), 0 = off: the regions' `interface_rings` exactly. While the
    /// residual exceeds it, every band is widened by one ring (up to `max_interface_rings`) and
    /// the edit redone; the edit with the smallest residual is returned
    /// (`pleat_cwf_get_edit_report`, `pleat_cwf_copy_edit_interface_rings`). Appended
    /// 2026-11-27; default 0.3 since 2026-11-27 b (was 0).
    pub compat_target: f64,
    /// Widest band the adaptive width may reach, 1 to 1,000,000; default 8. Appended 2026-11-27.
    pub max_interface_rings: u32,
    /// Reserved, set to 0.
    pub reserved: u32,
}

/// What `pleat_cwf_edit` did (`pleat_cwf_get_edit_report`): class sizes, each solve's residual
/// and seconds, the compatibility residual by class and what the adaptive width did.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatCwfEditReport {
    /// In: `sizeof(PleatCwfEditReport)` (≥ 8). Out: bytes filled.
    pub struct_size: u32,
    /// Edits computed: 1 + the widenings tried (`compat_target`).
    pub attempts: u32,
    /// Regions edited (the length of `pleat_cwf_copy_edit_interface_rings`' output).
    pub region_count: u32,
    /// Narrowest interface band used, in rings.
    pub interface_rings_min: u32,
    /// Widest interface band used, in rings (wider than requested when `compat_target` widened
    /// it).
    pub interface_rings_max: u32,
    /// 1 when no vertex is fixed (a global edit: plain Knöppel phase), else 0.
    pub global: u32,
    /// 1 when the phase fell back to `s = 1` (harmonic extension), else 0.
    pub phase_fallback: u32,
    /// Inverse-iteration steps of the phase solve.
    pub phase_iterations: u32,
    /// Faces `[fixed, edit, interface]`.
    pub face_counts: [u64; 3],
    /// Vertices `[fixed, edit, interface-only]`.
    pub vertex_counts: [u64; 3],
    /// Edges `[fixed, edit, interface-only]`.
    pub edge_counts: [u64; 3],
    /// Interface amplitudes clamped to 0.
    pub clamped: u64,
    /// Relative residual of eq. 3.26 (0 without interface edges).
    pub omega_residual: f64,
    /// Relative residual of eq. 3.27 (0 without interface vertices).
    pub amplitude_residual: f64,
    /// Smallest eigenvalue of the phase pencil (3.28), or Knöppel's for a global edit.
    pub eigenvalue: f64,
    /// Final inverse-iteration residual of the phase solve.
    pub phase_residual: f64,
    /// RMS of `|wrap(ω¹ − Δarg z̃¹)|` over edit + interface edges, radians (what
    /// `compat_target` bounds).
    pub compat_rms: f64,
    /// The same RMS over the edit edges only.
    pub compat_rms_edit: f64,
    /// The same RMS over the interface-only edges only.
    pub compat_rms_interface: f64,
    /// The smallest RMS any phase without singularities can reach for this ω¹ (how
    /// incompatible the requested field is, not the phase solve).
    pub compat_floor: f64,
    /// Wall seconds: `[labels + ω¹, eq. 3.26, eq. 3.27, eq. 3.28]` of the returned edit.
    pub seconds: [f64; 4],
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
        edit_weight: 1.0,
        compat_target: 0.3,
        max_interface_rings: 8,
        reserved: 0,
    }
}

versioned!(PleatCwfDesignParams, 8, pleat_cwf_design_params_default);
versioned!(PleatCwfEditParams, 8, pleat_cwf_edit_params_default);
versioned!(PleatCwfEditReport, 8);

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
    pleat_cwf_design_with_progress(
        base,
        sources,
        source_count,
        params,
        knoppel_params,
        None,
        std::ptr::null_mut(),
        out,
    )
}

/// As `pleat_cwf_design`, with a progress callback that can cancel.
///
/// - `progress`, `user_data`: optional callback (NULL for none), called on this thread with
///   stage `"design"` after each step (regions, each vector heat solve, ω, the amplitude) and
///   in the phase solve after its factorization and each inverse iteration; a non-zero return
///   cancels: `PLEAT_STATUS_CANCELLED`, `*out` not written.
/// - the other arguments: as `pleat_cwf_design`; the field is the same.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above; `progress` is a valid function
/// or NULL.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_design_with_progress(
    base: *const PleatMesh,
    sources: *const PleatWrinkleSource,
    source_count: usize,
    params: *const PleatCwfDesignParams,
    knoppel_params: *const PleatKnoppelParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    wrinkle_only!([base, sources, source_count, params, knoppel_params, progress, user_data, out]
    guard_progress(progress, user_data, |relay| {
        imp::design(base, sources, source_count, params, knoppel_params, relay, out)
    }))
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
/// The output keeps the edit's report: `pleat_cwf_get_edit_report` and
/// `pleat_cwf_copy_edit_interface_rings` (the widths used, per region).
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
    pleat_cwf_edit_with_progress(
        cwf,
        regions,
        region_count,
        params,
        None,
        std::ptr::null_mut(),
        out,
        face_labels_out,
    )
}

/// As `pleat_cwf_edit`, with a progress callback that can cancel.
///
/// - `progress`, `user_data`: optional callback (NULL for none), called on this thread with
///   stage `"edit"` after each step of every attempt (labels, the interface ω and amplitude
///   solves, the phase solve's factorization and each of its inverse iterations); a non-zero
///   return cancels: `PLEAT_STATUS_CANCELLED`, `*out` and `face_labels_out` not written.
/// - the other arguments: as `pleat_cwf_edit`; the field and labels are the same.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above; `progress` is a valid function
/// or NULL.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_edit_with_progress(
    cwf: *const PleatCwf,
    regions: *const PleatCwfRegionEdit,
    region_count: usize,
    params: *const PleatCwfEditParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut *mut PleatCwf,
    face_labels_out: *mut u8,
) -> PleatStatus {
    wrinkle_only!([cwf, regions, region_count, params, progress, user_data, out, face_labels_out]
    guard_progress(progress, user_data, |relay| {
        imp::edit(cwf, regions, region_count, params, relay, out, face_labels_out)
    }))
}

/// Fills `*out` with the report of the `pleat_cwf_edit` call that produced `cwf`.
///
/// - `cwf`: non-NULL; a field not made by `pleat_cwf_edit` has no edit report:
///   `PLEAT_STATUS_INVALID_ARGUMENT`.
/// - `out`: non-NULL, `out->struct_size = sizeof(PleatCwfEditReport)` (≥ 8; an older, shorter
///   struct receives its prefix).
///
/// # Safety
/// `cwf` is NULL or live; `out` is NULL or valid for `out->struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_get_edit_report(
    cwf: *const PleatCwf,
    out: *mut PleatCwfEditReport,
) -> PleatStatus {
    wrinkle_only!([cwf, out] guard(|| imp::get_edit_report(cwf, out)))
}

/// Copies the interface width used per region (rings, in `regions` order) by the
/// `pleat_cwf_edit` call that produced `cwf`: the requested widths, or wider ones when
/// `compat_target` widened them.
///
/// - `cwf`: non-NULL, made by `pleat_cwf_edit` (else `PLEAT_STATUS_INVALID_ARGUMENT`).
/// - `dst`: non-NULL; `capacity` ≥ the region count (`PleatCwfEditReport::region_count`), else
///   `PLEAT_STATUS_LIMIT_EXCEEDED`.
///
/// # Safety
/// `cwf` is NULL or live; `dst` is NULL or valid for `capacity` values.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_copy_edit_interface_rings(
    cwf: *const PleatCwf,
    dst: *mut u32,
    capacity: usize,
) -> PleatStatus {
    wrinkle_only!([cwf, dst, capacity] guard(|| imp::copy_interface_rings(cwf, dst, capacity)))
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
        required_versioned_out,
    };
    use crate::ffi::mesh::mesh_ref;
    use crate::ffi::wrinkle::imp::knoppel_options;
    use crate::report::ProgressFn;
    use crate::wrinkle::{
        design_with_progress, edit_with_progress, grow_faces as grow_rs, Adjacency, DesignOptions,
        EditOptions, EditReport, FaceClass, PhaseCoupling, RegionEdit, WrinkleSource,
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
        check_f64(
            p.edit_weight,
            p.edit_weight.is_finite() && p.edit_weight >= 1.0,
            "params->edit_weight",
            "finite, ≥ 1",
        )?;
        check_f64(
            p.compat_target,
            p.compat_target.is_finite() && p.compat_target >= 0.0,
            "params->compat_target",
            "finite, ≥ 0 radians (0: the requested interface widths)",
        )?;
        check_range(
            p.max_interface_rings,
            1,
            1_000_000,
            "params->max_interface_rings",
        )?;
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
            edit_weight: p.edit_weight,
            compat_target: p.compat_target,
            max_interface_rings: p.max_interface_rings as usize,
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
        progress: &mut ProgressFn<'_>,
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
        let (cwf, report) = design_with_progress(m.clone(), &rs, &opts, progress)?;
        out.put_boxed(PleatCwf {
            cwf,
            knoppel: Some(report.knoppel),
            edit: None,
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
        progress: &mut ProgressFn<'_>,
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
        let (k1, report) = edit_with_progress(&c.cwf, &edits, &opts, progress)?;
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
            edit: Some(Box::new(report)),
        });
        Ok(())
    }

    /// The edit report kept in `cwf`, or an error naming why there is none.
    ///
    /// # Safety
    /// `cwf` is NULL or live.
    unsafe fn edit_report_of<'a>(cwf: *const PleatCwf) -> Result<&'a EditReport> {
        let c = arg_ref(cwf, "cwf")?;
        c.edit.as_deref().ok_or_else(|| {
            Error::InvalidArgument(
                "this field was not made by pleat_cwf_edit: no edit report".into(),
            )
        })
    }

    /// The C report of an edit.
    pub(in crate::ffi) fn edit_report(r: &EditReport) -> PleatCwfEditReport {
        let n32 = |n: usize| n.min(u32::MAX as usize) as u32;
        let n64 = |c: [usize; 3]| c.map(|n| n as u64);
        PleatCwfEditReport {
            struct_size: 0,
            attempts: n32(r.attempts),
            region_count: n32(r.interface_rings.len()),
            interface_rings_min: n32(r.interface_rings.iter().copied().min().unwrap_or(0)),
            interface_rings_max: n32(r.interface_rings.iter().copied().max().unwrap_or(0)),
            global: r.global as u32,
            phase_fallback: r.phase_fallback as u32,
            phase_iterations: n32(r.phase_iterations),
            face_counts: n64(r.face_counts),
            vertex_counts: n64(r.vertex_counts),
            edge_counts: n64(r.edge_counts),
            clamped: r.clamped as u64,
            omega_residual: r.omega_residual,
            amplitude_residual: r.amplitude_residual,
            eigenvalue: r.eigenvalue,
            phase_residual: r.phase_residual,
            compat_rms: r.compat_rms,
            compat_rms_edit: r.compat_rms_by_class[0],
            compat_rms_interface: r.compat_rms_by_class[1],
            compat_floor: r.compat_floor,
            seconds: r.seconds,
        }
    }

    /// # Safety
    /// As `pleat_cwf_get_edit_report`.
    pub(super) unsafe fn get_edit_report(
        cwf: *const PleatCwf,
        out: *mut PleatCwfEditReport,
    ) -> Result<()> {
        let out = required_versioned_out(out, "out")?;
        out.write(edit_report(edit_report_of(cwf)?));
        Ok(())
    }

    /// # Safety
    /// As `pleat_cwf_copy_edit_interface_rings`.
    pub(super) unsafe fn copy_interface_rings(
        cwf: *const PleatCwf,
        dst: *mut u32,
        capacity: usize,
    ) -> Result<()> {
        let r = edit_report_of(cwf)?;
        let dst = arg_out(dst, "dst")?;
        let n = r.interface_rings.len();
        if capacity < n {
            return Err(Error::LimitExceeded(format!(
                "dst holds {capacity} values, {n} are needed (one per region)"
            )));
        }
        for (i, &w) in r.interface_rings.iter().enumerate() {
            dst.add(i).put(w.min(u32::MAX as usize) as u32);
        }
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
