//! Complex wrinkle fields in the C ABI (capability `wrinkle`, dissertation ch. 3).
//!
//! - `PleatCwf`: a validated complex wrinkle field (frequency one-form ω per edge, amplitude and
//!   unit phase z̃ per vertex) on a copy of a base mesh. Created from per-edge ω
//!   ([`pleat_cwf_create`]), from per-face-corner ω ([`pleat_cwf_create_from_corner_omega`]),
//!   from wave vectors with Knöppel's phase ([`pleat_cwf_create_from_frequency`]) or from a
//!   `.cwf` file ([`pleat_cwf_read_file`]).
//! - [`pleat_cwf_evaluate`]: the wrinkled surface after `levels` Loop refinements, as a
//!   `PleatMesh`, plus optional per-vertex fields (`PleatWrinkleFields`).
//!
//! Edge numbering: see `pleat_mesh_copy_edges`. Every function exists in every build; without
//! the `wrinkle` capability those that need it return `PLEAT_STATUS_UNSUPPORTED` (counts return
//! 0), so hosts can test `pleat_has_feature("wrinkle")` at run time.

#![allow(clippy::too_many_arguments)]

#[cfg(feature = "wrinkle")]
use super::boundary::required_versioned_out;
use super::boundary::{arg_out, arg_ref, destroy, full_size, guard_value, requires, versioned};
use super::common::{guard, PleatProgressFn, PleatStatus};
use super::mesh::PleatMesh;
use crate::{Error, Result};

/// Runs `$body` (a `PleatStatus` expression) when built with `wrinkle`; otherwise returns
/// `PLEAT_STATUS_UNSUPPORTED` and marks the listed parameters used.
macro_rules! wrinkle_only {
    ([$($arg:expr),*] $body:expr) => {
        requires!("wrinkle", [$($arg),*], $body)
    };
}
pub(super) use wrinkle_only;

/// A count of the live handle `$h` (`*const H`): `$e` with `$c: &H`; 0 when `$h` is NULL,
/// on a panic, or in a build without `wrinkle`.
macro_rules! wrinkle_count {
    ($h:expr, |$c:ident| $e:expr) => {{
        #[cfg(feature = "wrinkle")]
        {
            guard_value(0, || $h.as_ref().map_or(0, |$c| $e))
        }
        #[cfg(not(feature = "wrinkle"))]
        {
            let _ = $h;
            0
        }
    }};
}
pub(super) use wrinkle_count;

// ---------------------------------------------------------------------------------------------
// Constants

/// Per-vertex field of an evaluation: the Loop-subdivided amplitude `a` (1 double per vertex).
pub const PLEAT_WRINKLE_FIELD_AMPLITUDE: u32 = 1;
/// Per-vertex field: the phase `arg z` in (−π, π] radians, 0 where `z = 0` (1 double).
pub const PLEAT_WRINKLE_FIELD_PHASE: u32 = 2;
/// Per-vertex field: unit area-weighted normal of the undisplaced refined mesh, the direction of
/// the displacement; zero where undefined (3 doubles).
pub const PLEAT_WRINKLE_FIELD_NORMALS: u32 = 4;
/// Per-vertex field: the upsampled complex field `z` (amplitude included) as `re, im`
/// (2 doubles). The displacement is `displacement_scale · re · normal`.
pub const PLEAT_WRINKLE_FIELD_Z: u32 = 8;
/// Per-vertex field: the undisplaced (Loop-smoothed) positions (3 doubles).
pub const PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS: u32 = 16;
/// Per-edge field: the one-form ω of the refined mesh on the output mesh's edges in pleat's
/// edge numbering (`pleat_mesh_copy_edges` of the output mesh), 1 double per edge. Costs one
/// more one-form subdivision.
pub const PLEAT_WRINKLE_FIELD_OMEGA: u32 = 32;

#[cfg_attr(not(feature = "wrinkle"), allow(dead_code))]
const ALL_FIELDS: u32 = 63;

/// Loop boundary rule: boundary vertices stay fixed, boundary edges split at their midpoints.
pub const PLEAT_WRINKLE_BOUNDARY_FIXED: u32 = 0;
/// Loop boundary rule: cubic B-spline boundary curve; corners (see `corner_angle`) stay fixed.
pub const PLEAT_WRINKLE_BOUNDARY_SMOOTH: u32 = 1;

/// Knöppel edge weights: cotangent weights (clamped positive).
pub const PLEAT_PHASE_WEIGHTS_COTAN: u32 = 0;
/// Knöppel edge weights: barycentric edge areas.
pub const PLEAT_PHASE_WEIGHTS_EDGE_AREA: u32 = 1;

/// `pleat_cwf_create_from_frequency`: one wave vector per vertex.
pub const PLEAT_FREQUENCY_PER_VERTEX: u32 = 0;
/// `pleat_cwf_create_from_frequency`: one wave vector per triangle.
pub const PLEAT_FREQUENCY_PER_FACE: u32 = 1;

/// Relative tolerance of the antisymmetry check of `pleat_cwf_create_from_corner_omega`: the two
/// corner values `w_ab` (triangle traversing edge a→b) and `w_ba` (its neighbour, b→a) must
/// satisfy `|w_ab + w_ba| ≤ PLEAT_CORNER_OMEGA_TOLERANCE · max(1, |w_ab|, |w_ba|)`.
pub const PLEAT_CORNER_OMEGA_TOLERANCE: f64 = 1e-6;

// ---------------------------------------------------------------------------------------------
// Handles and structs

/// A complex wrinkle field on a base mesh (opaque): ω per edge (pleat's edge numbering),
/// amplitude and unit phase z̃ per vertex, and a private copy of the base mesh (the `PleatMesh`
/// passed at creation may be destroyed afterwards). Created by `pleat_cwf_create*` or
/// `pleat_cwf_read_file`, destroyed by `pleat_cwf_destroy`. Immutable: may be read (evaluated,
/// copied out) from several threads at once; destroying it while in use is undefined.
pub struct PleatCwf {
    #[cfg(feature = "wrinkle")]
    pub(super) cwf: crate::wrinkle::Cwf,
    #[cfg(feature = "wrinkle")]
    pub(super) knoppel: Option<crate::wrinkle::KnoppelReport>,
    /// The report of the `pleat_cwf_edit` call that made this field (None otherwise).
    #[cfg(feature = "wrinkle")]
    pub(super) edit: Option<Box<crate::wrinkle::EditReport>>,
}

/// Optional per-vertex (and per-edge) fields of one evaluation (opaque), requested with
/// `PLEAT_WRINKLE_FIELD_*` bits in `PleatWrinkleEvalParams::flags` and returned by
/// `pleat_cwf_evaluate`. Vertex order is that of the output mesh. Destroyed by
/// `pleat_wrinkle_fields_destroy`. Immutable; thread rules as `PleatCwf`.
pub struct PleatWrinkleFields {
    /// Indexed by the bit position of the `PLEAT_WRINKLE_FIELD_*` value; flattened doubles.
    fields: [Option<Vec<f64>>; 6],
}

/// Parameters of `pleat_cwf_evaluate`. Get the defaults from
/// `pleat_wrinkle_eval_params_default()` and change what you need; `struct_size` must stay
/// `sizeof(PleatWrinkleEvalParams)` (an older, shorter struct is accepted: missing fields take
/// their defaults).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatWrinkleEvalParams {
    /// `sizeof(PleatWrinkleEvalParams)`; at least 8.
    pub struct_size: u32,
    /// Loop refinements; default 3. Each multiplies the triangle count by 4: levels whose output
    /// would exceed `max_output_triangles` fail with `PLEAT_STATUS_LIMIT_EXCEEDED` before any
    /// allocation.
    pub levels: u32,
    /// Bitwise OR of `PLEAT_WRINKLE_FIELD_*`: the fields to compute into `*out_fields`; ignored
    /// when `out_fields` is NULL; default 0.
    pub flags: u32,
    /// `PLEAT_WRINKLE_BOUNDARY_FIXED` (default) or `PLEAT_WRINKLE_BOUNDARY_SMOOTH`.
    pub boundary: u32,
    /// With the smooth boundary rule: a boundary vertex whose triangle angles sum to a value
    /// differing from π by more than this is a corner and stays fixed. Radians in [0, π];
    /// default π/6.
    pub corner_angle: f64,
    /// Multiplies the displacement `Re(z) n̂` (so it is in the base mesh's length unit per unit
    /// amplitude); finite; default 1.
    pub displacement_scale: f64,
    /// Upper bound on the output triangle count, ≥ 1; default 2^26 (67,108,864). The output is
    /// also limited to the u32 index range.
    pub max_output_triangles: u64,
}

/// What `pleat_cwf_evaluate` did. Set `struct_size = sizeof(PleatWrinkleEvalStats)` before the
/// call; pleat fills at most that many bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatWrinkleEvalStats {
    /// In: `sizeof(PleatWrinkleEvalStats)` as the caller knows it (≥ 8). Out: bytes filled.
    pub struct_size: u32,
    /// Loop refinements done.
    pub levels: u32,
    /// Vertices of the output mesh.
    pub vertex_count: u64,
    /// Triangles of the output mesh.
    pub triangle_count: u64,
    /// Wall seconds of the whole evaluation.
    pub total_seconds: f64,
    /// Wall seconds of the Loop refinements (all levels).
    pub subdivision_seconds: f64,
    /// Wall seconds of the normals and the displacement.
    pub displacement_seconds: f64,
}

/// Parameters of Knöppel et al.'s phase solve (used when pleat computes z̃ from ω). Get the
/// defaults from `pleat_knoppel_params_default()`; `struct_size` versioned as
/// `PleatWrinkleEvalParams`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PleatKnoppelParams {
    /// `sizeof(PleatKnoppelParams)`; at least 8.
    pub struct_size: u32,
    /// `PLEAT_PHASE_WEIGHTS_COTAN` (default) or `PLEAT_PHASE_WEIGHTS_EDGE_AREA`.
    pub weights: u32,
    /// Maximum inverse-iteration steps, 1 to 1,000,000; default 200.
    pub max_iterations: u32,
    /// Reserved, set to 0.
    pub reserved: u32,
    /// Convergence tolerance on the relative residual, finite, ≥ 0; default 1e-12.
    pub tolerance: f64,
    /// Relative shift of the inverse iteration, finite, in [0, 1); default 1e-9.
    pub shift: f64,
}

/// Outcome of the Knöppel phase solve of a `PleatCwf` (`pleat_cwf_get_knoppel_report`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PleatKnoppelReport {
    /// In: `sizeof(PleatKnoppelReport)` (≥ 8). Out: bytes filled.
    pub struct_size: u32,
    /// Inverse-iteration steps taken.
    pub iterations: u32,
    /// Smallest generalized eigenvalue found (largest over connected components); 0 for a
    /// perfectly compatible ω.
    pub eigenvalue: f64,
    /// Final relative residual.
    pub residual: f64,
    /// Absolute shift σ used.
    pub shift: f64,
}

/// The default evaluation parameters (levels 3, no fields, fixed boundary, corner angle π/6,
/// displacement scale 1, at most 2^26 output triangles), with `struct_size` set. Available in
/// every build.
#[no_mangle]
pub extern "C" fn pleat_wrinkle_eval_params_default() -> PleatWrinkleEvalParams {
    #[cfg(feature = "wrinkle")]
    return PleatWrinkleEvalParams::from(&crate::wrinkle::EvalOptions::default());
    #[cfg(not(feature = "wrinkle"))]
    return defaults_without_wrinkle().0;
}

/// The default Knöppel parameters (cotangent weights, 200 iterations, tolerance 1e-12, shift
/// 1e-9), with `struct_size` set. Available in every build.
#[no_mangle]
pub extern "C" fn pleat_knoppel_params_default() -> PleatKnoppelParams {
    #[cfg(feature = "wrinkle")]
    return PleatKnoppelParams::from(&crate::wrinkle::KnoppelOptions::default());
    #[cfg(not(feature = "wrinkle"))]
    return defaults_without_wrinkle().1;
}

/// Default `PleatWrinkleEvalParams::levels`: the Rust API takes the level count as an
/// argument of `Cwf::evaluate`, so it is the one C default without a Rust `Default`.
const DEFAULT_EVAL_LEVELS: u32 = 3;

#[cfg(feature = "wrinkle")]
impl From<&crate::wrinkle::EvalOptions> for PleatWrinkleEvalParams {
    /// `levels` is `DEFAULT_EVAL_LEVELS`; `want_z` sets `PLEAT_WRINKLE_FIELD_Z`.
    fn from(o: &crate::wrinkle::EvalOptions) -> Self {
        use crate::wrinkle::BoundaryRule;
        let bit = |on: bool, b: u32| if on { b } else { 0 };
        PleatWrinkleEvalParams {
            struct_size: full_size::<PleatWrinkleEvalParams>(),
            levels: DEFAULT_EVAL_LEVELS,
            flags: bit(o.want_amplitude, PLEAT_WRINKLE_FIELD_AMPLITUDE)
                | bit(o.want_phase, PLEAT_WRINKLE_FIELD_PHASE)
                | bit(o.want_normals, PLEAT_WRINKLE_FIELD_NORMALS)
                | bit(o.want_z, PLEAT_WRINKLE_FIELD_Z)
                | bit(o.want_omega, PLEAT_WRINKLE_FIELD_OMEGA),
            boundary: match o.subdivision.boundary {
                BoundaryRule::Fixed => PLEAT_WRINKLE_BOUNDARY_FIXED,
                BoundaryRule::Smooth => PLEAT_WRINKLE_BOUNDARY_SMOOTH,
            },
            corner_angle: o.subdivision.corner_angle,
            displacement_scale: o.displacement_scale,
            max_output_triangles: o.max_output_faces as u64,
        }
    }
}

#[cfg(feature = "wrinkle")]
impl From<&crate::wrinkle::KnoppelOptions> for PleatKnoppelParams {
    fn from(o: &crate::wrinkle::KnoppelOptions) -> Self {
        use crate::wrinkle::PhaseWeights;
        PleatKnoppelParams {
            struct_size: full_size::<PleatKnoppelParams>(),
            weights: match o.weights {
                PhaseWeights::Cotan => PLEAT_PHASE_WEIGHTS_COTAN,
                PhaseWeights::EdgeArea => PLEAT_PHASE_WEIGHTS_EDGE_AREA,
            },
            max_iterations: o.max_iterations.min(u32::MAX as usize) as u32,
            reserved: 0,
            tolerance: o.tolerance,
            shift: o.shift,
        }
    }
}

/// `EvalOptions::default()` and `KnoppelOptions::default()` as C, for builds without `wrinkle`
/// (which have no such types); the test `ffi::defaults` pins them to the conversions above.
#[cfg_attr(feature = "wrinkle", allow(dead_code))]
pub(super) fn defaults_without_wrinkle() -> (PleatWrinkleEvalParams, PleatKnoppelParams) {
    let eval = PleatWrinkleEvalParams {
        struct_size: full_size::<PleatWrinkleEvalParams>(),
        levels: DEFAULT_EVAL_LEVELS,
        flags: 0,
        boundary: PLEAT_WRINKLE_BOUNDARY_FIXED,
        corner_angle: std::f64::consts::FRAC_PI_6,
        displacement_scale: 1.0,
        max_output_triangles: 1 << 26,
    };
    let knoppel = PleatKnoppelParams {
        struct_size: full_size::<PleatKnoppelParams>(),
        weights: PLEAT_PHASE_WEIGHTS_COTAN,
        max_iterations: 200,
        reserved: 0,
        tolerance: 1e-12,
        shift: 1e-9,
    };
    (eval, knoppel)
}

// ---------------------------------------------------------------------------------------------
// Versioned structs: every one accepts a `struct_size` down to 8 (the size field and one u32).

versioned!(PleatWrinkleEvalParams, 8, pleat_wrinkle_eval_params_default);
versioned!(PleatKnoppelParams, 8, pleat_knoppel_params_default);
versioned!(PleatWrinkleEvalStats, 8);
versioned!(PleatKnoppelReport, 8);

// ---------------------------------------------------------------------------------------------
// Creation

/// Creates a wrinkle field from ω on the base mesh's edges, amplitudes and (optionally) phases.
///
/// - `base`: the base mesh; non-NULL. Must be a consistently oriented manifold (each edge in one
///   or two triangles, one fan per vertex), boundary allowed, no degenerate or duplicate
///   triangles, else `PLEAT_STATUS_INVALID_MESH`. pleat keeps its own copy.
/// - `omega`: `edge_count` doubles; non-NULL. `omega[e]` is the frequency one-form on edge `e`
///   of `pleat_mesh_copy_edges(base)`, integrated from its smaller to its larger vertex
///   index: the phase advance in radians (`ω_ij ≈ k·(x_j − x_i)` for a plane wave of wave
///   vector `k`, in radians per length unit). Finite.
/// - `edge_count`: must equal `pleat_mesh_edge_count(base)`.
/// - `amplitude`: `vertex_count` doubles, finite, ≥ 0, in the mesh's length unit; non-NULL.
/// - `zeta_re_im`: 2 doubles per vertex (`re, im`), the unit phase z̃ (need not be exactly unit;
///   the field is `z = amplitude · z̃`), finite. NULL: z̃ is computed from ω by Knöppel et al.'s
///   method with default parameters (`pleat_cwf_create_from_frequency` takes parameters).
/// - `vertex_count`: must equal `pleat_mesh_vertex_count(base)`.
/// - `out`: receives the new field (destroy with `pleat_cwf_destroy`); non-NULL.
///
/// Returns `PLEAT_STATUS_INVALID_ARGUMENT` for NULL pointers, mismatched counts, NaN/Inf or
/// negative amplitudes; `PLEAT_STATUS_NUMERICAL` if the phase solve fails;
/// `PLEAT_STATUS_UNSUPPORTED` without the `wrinkle` capability.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_create(
    base: *const PleatMesh,
    omega: *const f64,
    edge_count: usize,
    amplitude: *const f64,
    zeta_re_im: *const f64,
    vertex_count: usize,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    wrinkle_only!([base, omega, edge_count, amplitude, zeta_re_im, vertex_count, out]
        guard(|| imp::create(base, omega, edge_count, amplitude, zeta_re_im, vertex_count, out)))
}

/// Creates a wrinkle field from ω given per triangle corner, so callers need not know pleat's
/// edge numbering.
///
/// - `base`: as `pleat_cwf_create`; non-NULL.
/// - `corner_omega`: `corner_count` doubles, 3 per triangle: `corner_omega[3t + i]` is ω
///   integrated along triangle `t`'s edge from its corner `i` to corner `(i + 1) % 3`, in
///   radians. Finite. An interior edge is seen by its two triangles in opposite directions;
///   their values must be opposite: `|w_ab + w_ba| ≤ PLEAT_CORNER_OMEGA_TOLERANCE ·
///   max(1, |w_ab|, |w_ba|)`, else `PLEAT_STATUS_INVALID_ARGUMENT` naming the edge. The field
///   stores their mean `(w_ab − w_ba) / 2` (per edge, oriented min → max).
/// - `corner_count`: must equal `3 * pleat_mesh_triangle_count(base)`.
/// - `amplitude`, `zeta_re_im` (NULL = Knöppel phase), `vertex_count`, `out`: as
///   `pleat_cwf_create`.
///
/// Base-mesh problems (`PLEAT_STATUS_INVALID_MESH`) are reported before antisymmetry
/// violations.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_create_from_corner_omega(
    base: *const PleatMesh,
    corner_omega: *const f64,
    corner_count: usize,
    amplitude: *const f64,
    zeta_re_im: *const f64,
    vertex_count: usize,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    wrinkle_only!([base, corner_omega, corner_count, amplitude, zeta_re_im, vertex_count, out]
    guard(|| imp::create_from_corners(
        base, corner_omega, corner_count, amplitude, zeta_re_im, vertex_count, out
    )))
}

/// Creates a wrinkle field from wave vectors (the gradient of the phase, radians per length
/// unit) and amplitudes; the phase z̃ is Knöppel et al.'s (2015) smoothest unit field whose
/// gradient best matches the wave vectors.
///
/// - `base`: as `pleat_cwf_create`; non-NULL.
/// - `frequency`: `3 * frequency_count` doubles, xyz wave vectors (tangent to the surface; a
///   normal component is harmless: only its projection on the edges counts). Finite; non-NULL.
///   Per vertex: `ω_ij = ½ (k_i + k_j)·(x_j − x_i)`; per face: the mean over the edge's triangles
///   of `k_f·(x_j − x_i)`.
/// - `frequency_count`: the number of vectors: `pleat_mesh_vertex_count(base)` for
///   `PLEAT_FREQUENCY_PER_VERTEX`, `pleat_mesh_triangle_count(base)` for
///   `PLEAT_FREQUENCY_PER_FACE`.
/// - `location`: `PLEAT_FREQUENCY_PER_VERTEX` or `PLEAT_FREQUENCY_PER_FACE`.
/// - `amplitude`: `vertex_count` doubles, finite, ≥ 0; non-NULL.
/// - `vertex_count`: must equal `pleat_mesh_vertex_count(base)`.
/// - `params`: Knöppel parameters; NULL = `pleat_knoppel_params_default()`.
/// - `out`: receives the new field; non-NULL.
///
/// A singularity (vortex) of the wave field becomes a vertex with z̃ = 0 when it falls on one.
/// Cost: one sparse Cholesky factorization of a 2V × 2V matrix and a few solves.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_create_from_frequency(
    base: *const PleatMesh,
    frequency: *const f64,
    frequency_count: usize,
    location: u32,
    amplitude: *const f64,
    vertex_count: usize,
    params: *const PleatKnoppelParams,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    wrinkle_only!([base, frequency, frequency_count, location, amplitude, vertex_count, params, out]
    guard(|| imp::create_from_frequency(
        base, frequency, frequency_count, location, amplitude, vertex_count, params, out
    )))
}

/// Reads a `.cwf` file (format: docs/guide/wrinkle-evaluation.md, `src/wrinkle/io.rs`) written for
/// `base`, whose connectivity (vertex, edge and triangle counts and a hash of the triangles)
/// must match what the file records; positions may differ (a deformed base mesh).
///
/// - `base`: non-NULL; pleat keeps its own copy.
/// - `path`: NUL-terminated UTF-8 path; non-NULL.
/// - `out`: receives the new field; non-NULL.
///
/// Returns `PLEAT_STATUS_IO` when the file cannot be read, `PLEAT_STATUS_PARSE` when its content
/// is malformed (message with the line), `PLEAT_STATUS_INVALID_ARGUMENT` when it was written
/// for other connectivity or holds invalid values.
///
/// # Safety
/// `base` is NULL or live; `path` is NULL or NUL-terminated; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_read_file(
    base: *const PleatMesh,
    path: *const std::ffi::c_char,
    out: *mut *mut PleatCwf,
) -> PleatStatus {
    wrinkle_only!([base, path, out] guard(|| imp::read_file(base, path, out)))
}

/// Writes `cwf` as a `.cwf` text file (lossless: every double round-trips bit for bit). The
/// base mesh is not written; store it separately (e.g. `pleat_mesh_write_file` to `.ply`/`.obj`,
/// which keep the vertex order).
///
/// - `cwf`: non-NULL.
/// - `path`: NUL-terminated UTF-8 path; non-NULL. An existing file is replaced.
///
/// # Safety
/// `cwf` is NULL or live; `path` is NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_write_file(
    cwf: *const PleatCwf,
    path: *const std::ffi::c_char,
) -> PleatStatus {
    wrinkle_only!([cwf, path] guard(|| {
        let c = imp::cwf_ref(cwf)?;
        let path = super::common::c_str_arg(path, "path")?;
        crate::wrinkle::write_cwf(path, &c.cwf)
    }))
}

/// Destroys a wrinkle field. NULL is accepted and ignored. Destroying twice is undefined.
///
/// # Safety
/// `cwf` is NULL or a handle from pleat not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_destroy(cwf: *mut PleatCwf) {
    destroy(cwf)
}

// ---------------------------------------------------------------------------------------------
// Copy-out of the field

/// Number of vertices of the field's base mesh (the length of its per-vertex arrays); 0 when
/// `cwf` is NULL or the build lacks `wrinkle`.
///
/// # Safety
/// `cwf` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_vertex_count(cwf: *const PleatCwf) -> usize {
    wrinkle_count!(cwf, |c| c.cwf.amplitude().len())
}

/// Number of edges of the field's base mesh (the length of ω); 0 when `cwf` is NULL or the
/// build lacks `wrinkle`.
///
/// # Safety
/// `cwf` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_edge_count(cwf: *const PleatCwf) -> usize {
    wrinkle_count!(cwf, |c| c.cwf.omega().len())
}

/// Number of triangles of the field's base mesh (a third of the length of per-corner ω); 0
/// when `cwf` is NULL or the build lacks `wrinkle`.
///
/// # Safety
/// `cwf` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_triangle_count(cwf: *const PleatCwf) -> usize {
    wrinkle_count!(cwf, |c| c.cwf.base().triangle_count())
}

/// Copies ω, one double per edge in pleat's edge numbering (`pleat_mesh_copy_edges` of the base
/// mesh), integrated from the smaller to the larger vertex index, in radians.
///
/// - `cwf`, `dst`: non-NULL.
/// - `edge_capacity`: doubles `dst` holds; ≥ `pleat_cwf_edge_count(cwf)`, else
///   `PLEAT_STATUS_LIMIT_EXCEEDED` and nothing is written.
///
/// # Safety
/// `cwf` is NULL or live; `dst` is NULL or valid for `edge_capacity` doubles.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_copy_omega(
    cwf: *const PleatCwf,
    dst: *mut f64,
    edge_capacity: usize,
) -> PleatStatus {
    wrinkle_only!([cwf, dst, edge_capacity] guard(|| {
        let c = imp::cwf_ref(cwf)?;
        copy_doubles(c.cwf.omega(), dst, edge_capacity, "one per edge")
    }))
}

/// Copies ω per triangle corner, 3 doubles per triangle: `dst[3t + i]` is ω integrated along
/// triangle `t` from its corner `i` to corner `(i + 1) % 3` (the layout accepted by
/// `pleat_cwf_create_from_corner_omega`).
///
/// - `cwf`, `dst`: non-NULL.
/// - `corner_capacity`: doubles `dst` holds; ≥ `3 * pleat_cwf_triangle_count(cwf)`, else
///   `PLEAT_STATUS_LIMIT_EXCEEDED` and nothing is written.
///
/// # Safety
/// `cwf` is NULL or live; `dst` is NULL or valid for `corner_capacity` doubles.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_copy_corner_omega(
    cwf: *const PleatCwf,
    dst: *mut f64,
    corner_capacity: usize,
) -> PleatStatus {
    wrinkle_only!([cwf, dst, corner_capacity] guard(|| {
        let c = imp::cwf_ref(cwf)?;
        let corners = imp::corner_omega(&c.cwf);
        copy_doubles(&corners, dst, corner_capacity, "three per triangle")
    }))
}

/// Copies the amplitude, one double per base vertex (length unit, ≥ 0).
///
/// - `cwf`, `dst`: non-NULL.
/// - `vertex_capacity`: doubles `dst` holds; ≥ `pleat_cwf_vertex_count(cwf)`, else
///   `PLEAT_STATUS_LIMIT_EXCEEDED` and nothing is written.
///
/// # Safety
/// `cwf` is NULL or live; `dst` is NULL or valid for `vertex_capacity` doubles.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_copy_amplitude(
    cwf: *const PleatCwf,
    dst: *mut f64,
    vertex_capacity: usize,
) -> PleatStatus {
    wrinkle_only!([cwf, dst, vertex_capacity] guard(|| {
        let c = imp::cwf_ref(cwf)?;
        copy_doubles(c.cwf.amplitude(), dst, vertex_capacity, "one per vertex")
    }))
}

/// Copies the unit phase z̃, two doubles (`re, im`) per base vertex (0, 0 at a singularity).
///
/// - `cwf`, `dst`: non-NULL.
/// - `vertex_capacity`: vertices `dst` holds (it holds `2 * vertex_capacity` doubles);
///   ≥ `pleat_cwf_vertex_count(cwf)`, else `PLEAT_STATUS_LIMIT_EXCEEDED`.
///
/// # Safety
/// `cwf` is NULL or live; `dst` is NULL or valid for `2 * vertex_capacity` doubles.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_copy_zeta(
    cwf: *const PleatCwf,
    dst: *mut f64,
    vertex_capacity: usize,
) -> PleatStatus {
    wrinkle_only!([cwf, dst, vertex_capacity] guard(|| {
        let c = imp::cwf_ref(cwf)?;
        let flat: Vec<f64> = c.cwf.zeta().iter().flat_map(|z| [z.re, z.im]).collect();
        let cap = vertex_capacity.checked_mul(2).ok_or_else(|| {
            Error::InvalidArgument("vertex_capacity * 2 overflows".into())
        })?;
        copy_doubles(&flat, dst, cap, "two per vertex")
    }))
}

/// Fills `*out` with the report of the Knöppel phase solve that produced the field's z̃.
///
/// - `cwf`: non-NULL. Fields whose z̃ was given by the caller or read from a file have no
///   report: `PLEAT_STATUS_INVALID_ARGUMENT`.
/// - `out`: non-NULL, `out->struct_size = sizeof(PleatKnoppelReport)` (≥ 8).
///
/// # Safety
/// `cwf` is NULL or live; `out` is NULL or valid for `out->struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_get_knoppel_report(
    cwf: *const PleatCwf,
    out: *mut PleatKnoppelReport,
) -> PleatStatus {
    wrinkle_only!([cwf, out] guard(|| {
        let c = imp::cwf_ref(cwf)?;
        let out = required_versioned_out(out, "out")?;
        let Some(r) = &c.knoppel else {
            return Err(Error::InvalidArgument(
                "this field's phase was given, not computed by Knöppel's method".into(),
            ));
        };
        let v = PleatKnoppelReport {
            struct_size: 0,
            iterations: r.iterations.min(u32::MAX as usize) as u32,
            eigenvalue: r.eigenvalue,
            residual: r.residual,
            shift: r.shift,
        };
        out.write(v);
        Ok(())
    }))
}

/// Copies `src` to a caller buffer of `capacity` doubles.
///
/// # Safety
/// `dst` is NULL or valid for `capacity` doubles.
#[cfg_attr(not(feature = "wrinkle"), allow(dead_code))]
unsafe fn copy_doubles(src: &[f64], dst: *mut f64, capacity: usize, unit: &str) -> Result<()> {
    arg_out(dst, "dst")?;
    if capacity < src.len() {
        return Err(Error::LimitExceeded(format!(
            "dst holds {capacity} values, {} are needed ({unit})",
            src.len()
        )));
    }
    std::ptr::copy_nonoverlapping(src.as_ptr(), dst, src.len());
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Evaluation

/// Evaluates the wrinkled surface (dissertation §3.5): `params->levels` Loop refinements of the
/// base mesh, ω and z, then every vertex moves by `displacement_scale · Re(z) · n̂` along the
/// unit normal of the undisplaced refined mesh. The output is watertight (closed and manifold)
/// when the base mesh is, with the base vertices first, then one new vertex per edge of each
/// level; triangles are oriented like the base.
///
/// - `cwf`: non-NULL.
/// - `params`: NULL = `pleat_wrinkle_eval_params_default()`; see `PleatWrinkleEvalParams` for
///   each field's range. `PLEAT_STATUS_LIMIT_EXCEEDED` (before allocating) when
///   `triangles · 4^levels` exceeds `max_output_triangles` or the u32 index range.
/// - `progress`: NULL or a callback, called on the calling thread after each level and after
///   the displacement; returning non-zero cancels (`PLEAT_STATUS_CANCELLED`, no output).
/// - `user_data`: passed to `progress` unchanged; may be NULL.
/// - `out_mesh`: receives the wrinkled mesh (destroy with `pleat_mesh_destroy`); non-NULL.
/// - `out_fields`: NULL, or receives the fields requested by `params->flags` (destroy with
///   `pleat_wrinkle_fields_destroy`; a handle is returned even when no field was requested).
/// - `stats`: NULL, or a `PleatWrinkleEvalStats` with `struct_size` set (≥ 8), filled on
///   success.
///
/// Runs in parallel on pleat's thread pool; output bytes do not depend on the thread count.
/// Time and memory grow with the output size, `triangles · 4^levels` (see
/// `benches/wrinkle_eval.rs` for measurements).
///
/// # Safety
/// Pointers are NULL or valid as described; `progress` is a valid function or NULL.
#[no_mangle]
pub unsafe extern "C" fn pleat_cwf_evaluate(
    cwf: *const PleatCwf,
    params: *const PleatWrinkleEvalParams,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out_mesh: *mut *mut PleatMesh,
    out_fields: *mut *mut PleatWrinkleFields,
    stats: *mut PleatWrinkleEvalStats,
) -> PleatStatus {
    wrinkle_only!([cwf, params, progress, user_data, out_mesh, out_fields, stats]
        imp::evaluate(cwf, params, progress, user_data, out_mesh, out_fields, stats))
}

/// Bit position of a single `PLEAT_WRINKLE_FIELD_*` value, and its doubles per element.
fn field_slot(field: u32) -> Option<(usize, usize)> {
    let components = match field {
        PLEAT_WRINKLE_FIELD_AMPLITUDE | PLEAT_WRINKLE_FIELD_PHASE | PLEAT_WRINKLE_FIELD_OMEGA => 1,
        PLEAT_WRINKLE_FIELD_Z => 2,
        PLEAT_WRINKLE_FIELD_NORMALS | PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS => 3,
        _ => return None,
    };
    Some((field.trailing_zeros() as usize, components))
}

/// Number of elements of one evaluated field: vertices of the output mesh for per-vertex
/// fields, its edges for `PLEAT_WRINKLE_FIELD_OMEGA`. 0 when `fields` is NULL, `field` is not a
/// single `PLEAT_WRINKLE_FIELD_*` value, or the field was not requested.
///
/// Elements have 1 (amplitude, phase, omega), 2 (z) or 3 (normals, smooth positions) doubles.
///
/// # Safety
/// `fields` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_wrinkle_fields_count(
    fields: *const PleatWrinkleFields,
    field: u32,
) -> usize {
    guard_value(0, || {
        let (Some(f), Some((slot, comps))) = (fields.as_ref(), field_slot(field)) else {
            return 0;
        };
        f.fields[slot].as_ref().map_or(0, |v| v.len() / comps)
    })
}

/// Copies one evaluated field into a caller buffer, element by element.
///
/// - `fields`: non-NULL.
/// - `field`: one `PLEAT_WRINKLE_FIELD_*` value that was set in `params->flags`, else
///   `PLEAT_STATUS_INVALID_ARGUMENT`.
/// - `dst`: room for `element_capacity` elements `stride_bytes` apart; non-NULL.
/// - `element_capacity`: ≥ `pleat_wrinkle_fields_count(fields, field)`, else
///   `PLEAT_STATUS_LIMIT_EXCEEDED` and nothing is written.
/// - `stride_bytes`: bytes between consecutive elements; 0 = packed (8 × components); otherwise
///   ≥ 8 × components (bytes in between are left untouched, so interleaved vertex buffers work).
///
/// # Safety
/// `fields` is NULL or live; `dst` is NULL or valid for
/// `(element_capacity - 1) * stride + 8 * components` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_wrinkle_fields_copy(
    fields: *const PleatWrinkleFields,
    field: u32,
    dst: *mut f64,
    element_capacity: usize,
    stride_bytes: usize,
) -> PleatStatus {
    guard(|| copy_field(fields, field, dst, element_capacity, stride_bytes, |x| x))
}

/// As `pleat_wrinkle_fields_copy`, converting to float (rounded to nearest; packed element size
/// 4 × components bytes).
///
/// # Safety
/// As `pleat_wrinkle_fields_copy` with 4-byte components.
#[no_mangle]
pub unsafe extern "C" fn pleat_wrinkle_fields_copy_f32(
    fields: *const PleatWrinkleFields,
    field: u32,
    dst: *mut f32,
    element_capacity: usize,
    stride_bytes: usize,
) -> PleatStatus {
    guard(|| {
        copy_field(fields, field, dst, element_capacity, stride_bytes, |x| {
            x as f32
        })
    })
}

/// Shared body of the two field copies.
///
/// # Safety
/// As `pleat_wrinkle_fields_copy`.
unsafe fn copy_field<T: Copy>(
    fields: *const PleatWrinkleFields,
    field: u32,
    dst: *mut T,
    element_capacity: usize,
    stride_bytes: usize,
    conv: impl Fn(f64) -> T,
) -> Result<()> {
    let f = arg_ref(fields, "fields")?;
    arg_out(dst, "dst")?;
    let (slot, comps) = field_slot(field).ok_or_else(|| {
        Error::InvalidArgument(format!(
            "field {field:#x} is not one PLEAT_WRINKLE_FIELD_* value"
        ))
    })?;
    let values = f.fields[slot].as_ref().ok_or_else(|| {
        Error::InvalidArgument(format!(
            "field {field:#x} was not computed: set it in PleatWrinkleEvalParams::flags"
        ))
    })?;
    let tight = comps * std::mem::size_of::<T>();
    let stride = if stride_bytes == 0 {
        tight
    } else {
        stride_bytes
    };
    if stride < tight {
        return Err(Error::InvalidArgument(format!(
            "stride_bytes {stride_bytes} is smaller than one element ({tight} bytes)"
        )));
    }
    let n = values.len() / comps;
    if element_capacity < n {
        return Err(Error::LimitExceeded(format!(
            "dst holds {element_capacity} elements, the field has {n}"
        )));
    }
    if n.saturating_sub(1).checked_mul(stride).is_none() {
        return Err(Error::InvalidArgument(format!(
            "stride_bytes {stride_bytes} times {n} elements overflows"
        )));
    }
    for (i, e) in values.chunks_exact(comps).enumerate() {
        let q = (dst as *mut u8).add(i * stride) as *mut T;
        for (k, &c) in e.iter().enumerate() {
            std::ptr::write_unaligned(q.add(k), conv(c));
        }
    }
    Ok(())
}

/// Destroys evaluated fields. NULL is accepted and ignored.
///
/// # Safety
/// `fields` is NULL or a handle from pleat not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_wrinkle_fields_destroy(fields: *mut PleatWrinkleFields) {
    destroy(fields)
}

// ---------------------------------------------------------------------------------------------
// Implementation (only with the `wrinkle` capability)

#[cfg(feature = "wrinkle")]
pub(super) mod imp {
    use super::*;
    use crate::ffi::boundary::{
        arg_slice, check_f64, check_flags, check_range, finite_slice, non_null, read_versioned,
        versioned_out, Out,
    };
    use crate::ffi::common::{c_str_arg, guard_progress};
    use crate::ffi::mesh::mesh_ref;
    use crate::mesh::TriMesh;
    use crate::wrinkle::{
        BoundaryRule, Complex, Cwf, EvalOptions, EvalStage, FrequencyField, KnoppelOptions,
        PhaseWeights, SubdivisionOptions,
    };

    /// Borrows a field handle, failing with InvalidArgument on NULL.
    ///
    /// # Safety
    /// `c` is NULL or live.
    pub(super) unsafe fn cwf_ref<'a>(c: *const PleatCwf) -> Result<&'a PleatCwf> {
        arg_ref(c, "cwf")
    }

    fn check_count(name: &str, got: usize, want: usize, query: &str) -> Result<()> {
        if got != want {
            return Err(Error::InvalidArgument(format!(
                "{name} is {got} but the base mesh needs {want} ({query})"
            )));
        }
        Ok(())
    }

    /// Copies `n` caller doubles, checking each is finite.
    ///
    /// # Safety
    /// `p` is non-NULL and valid for `n` doubles.
    unsafe fn read_finite(p: *const f64, n: usize, name: &str) -> Result<Vec<f64>> {
        let s = arg_slice(p, n, name)?;
        finite_slice(s, name)?;
        let mut v = Vec::new();
        v.try_reserve_exact(n)
            .map_err(|_| Error::LimitExceeded(format!("cannot allocate {n} values of {name}")))?;
        v.extend_from_slice(s);
        Ok(v)
    }

    /// The caller's amplitude and optional z̃, both per vertex.
    ///
    /// # Safety
    /// As `pleat_cwf_create`.
    unsafe fn vertex_data(
        base: &TriMesh,
        amplitude: *const f64,
        zeta_re_im: *const f64,
        vertex_count: usize,
    ) -> Result<(Vec<f64>, Option<Vec<Complex>>)> {
        non_null(amplitude, "amplitude")?;
        check_count(
            "vertex_count",
            vertex_count,
            base.vertex_count(),
            "pleat_mesh_vertex_count",
        )?;
        let a = read_finite(amplitude, vertex_count, "amplitude")?;
        let z = if zeta_re_im.is_null() {
            None
        } else {
            let flat = read_finite(zeta_re_im, 2 * vertex_count, "zeta_re_im")?;
            Some(
                flat.chunks_exact(2)
                    .map(|c| Complex::new(c[0], c[1]))
                    .collect(),
            )
        };
        Ok((a, z))
    }

    /// Builds the field from ω and the vertex data (Knöppel's phase when z̃ is absent).
    fn build(
        base: TriMesh,
        omega: Vec<f64>,
        amplitude: Vec<f64>,
        zeta: Option<Vec<Complex>>,
        out: Out<*mut PleatCwf>,
    ) -> Result<()> {
        let (cwf, report) = match zeta {
            Some(z) => (Cwf::new(base, omega, amplitude, z)?, None),
            None => {
                let (c, r) =
                    Cwf::from_one_form(base, omega, amplitude, &KnoppelOptions::default())?;
                (c, Some(r))
            }
        };
        out.put_boxed(PleatCwf {
            cwf,
            knoppel: report,
            edit: None,
        });
        Ok(())
    }

    /// # Safety
    /// As `pleat_cwf_create`.
    pub(super) unsafe fn create(
        base: *const PleatMesh,
        omega: *const f64,
        edge_count: usize,
        amplitude: *const f64,
        zeta_re_im: *const f64,
        vertex_count: usize,
        out: *mut *mut PleatCwf,
    ) -> Result<()> {
        let out = arg_out(out, "out")?;
        let m = mesh_ref(base, "base")?;
        non_null(omega, "omega")?;
        check_count(
            "edge_count",
            edge_count,
            m.edges().len(),
            "pleat_mesh_edge_count",
        )?;
        let (a, z) = vertex_data(m, amplitude, zeta_re_im, vertex_count)?;
        let w = read_finite(omega, edge_count, "omega")?;
        build(m.clone(), w, a, z, out)
    }

    /// # Safety
    /// As `pleat_cwf_create_from_corner_omega`.
    pub(super) unsafe fn create_from_corners(
        base: *const PleatMesh,
        corner_omega: *const f64,
        corner_count: usize,
        amplitude: *const f64,
        zeta_re_im: *const f64,
        vertex_count: usize,
        out: *mut *mut PleatCwf,
    ) -> Result<()> {
        let out = arg_out(out, "out")?;
        let m = mesh_ref(base, "base")?;
        non_null(corner_omega, "corner_omega")?;
        check_count(
            "corner_count",
            corner_count,
            3 * m.triangle_count(),
            "3 * pleat_mesh_triangle_count",
        )?;
        let (a, z) = vertex_data(m, amplitude, zeta_re_im, vertex_count)?;
        let corners = read_finite(corner_omega, corner_count, "corner_omega")?;
        let (w, violation) = omega_from_corners(m, &corners);
        if let Some(msg) = violation {
            // Report a base-mesh problem first: it is the likelier cause.
            let n = m.vertex_count();
            Cwf::new(
                m.clone(),
                vec![0.0; w.len()],
                vec![0.0; n],
                vec![Complex::ONE; n],
            )?;
            return Err(Error::InvalidArgument(msg));
        }
        build(m.clone(), w, a, z, out)
    }

    /// Per-edge ω (min → max) as the mean of the corner values, and the first antisymmetry
    /// violation, if any.
    pub(super) fn omega_from_corners(m: &TriMesh, corners: &[f64]) -> (Vec<f64>, Option<String>) {
        let el = m.edges();
        let n = el.len();
        let mut sum = vec![0.0; n];
        let mut count = vec![0u32; n];
        // (value in edge orientation, triangle, corner) of the first corner seen on each edge
        let mut first = vec![(0.0, 0usize, 0usize); n];
        let mut violation = None;
        for (t, (fe, fs)) in el.face_edges.iter().zip(&el.face_edge_sign).enumerate() {
            for i in 0..3 {
                if fe[i] == u32::MAX {
                    continue; // degenerate corner (rejected later with the base mesh)
                }
                let e = fe[i] as usize;
                let raw = corners[3 * t + i];
                let w = fs[i] as f64 * raw;
                if count[e] == 0 {
                    first[e] = (w, t, i);
                } else if violation.is_none() {
                    let (w0, t0, i0) = first[e];
                    let tol = PLEAT_CORNER_OMEGA_TOLERANCE * 1f64.max(w.abs()).max(w0.abs());
                    if (w - w0).abs() > tol {
                        let [a, b] = el.edges[e].0;
                        violation = Some(format!(
                            "corner_omega is not antisymmetric on edge ({a}, {b}): triangle {t0} \
                             corner {i0} gives {} and triangle {t} corner {i} gives {raw} for \
                             the opposite direction (their sum must be within {} of 0 relative \
                             to max(1, |ω|))",
                            corners[3 * t0 + i0],
                            PLEAT_CORNER_OMEGA_TOLERANCE
                        ));
                    }
                }
                sum[e] += w;
                count[e] += 1;
            }
        }
        let w = sum
            .iter()
            .zip(&count)
            .map(|(s, &c)| s / c.max(1) as f64)
            .collect();
        (w, violation)
    }

    /// ω per corner (the inverse of `omega_from_corners` on antisymmetric input).
    pub(super) fn corner_omega(cwf: &Cwf) -> Vec<f64> {
        let el = cwf.base().edges();
        let w = cwf.omega();
        el.face_edges
            .iter()
            .zip(&el.face_edge_sign)
            .flat_map(|(fe, fs)| {
                (0..3).map(move |i| {
                    if fe[i] == u32::MAX {
                        0.0
                    } else {
                        fs[i] as f64 * w[fe[i] as usize]
                    }
                })
            })
            .collect()
    }

    /// The Rust options of C Knöppel parameters, every field checked.
    pub(in crate::ffi) fn knoppel_options(p: &PleatKnoppelParams) -> Result<KnoppelOptions> {
        let weights = match p.weights {
            PLEAT_PHASE_WEIGHTS_COTAN => PhaseWeights::Cotan,
            PLEAT_PHASE_WEIGHTS_EDGE_AREA => PhaseWeights::EdgeArea,
            w => {
                return Err(Error::InvalidArgument(format!(
                    "params->weights is {w}; use PLEAT_PHASE_WEIGHTS_COTAN or _EDGE_AREA"
                )))
            }
        };
        check_range(p.max_iterations, 1, 1_000_000, "params->max_iterations")?;
        let t = p.tolerance;
        check_f64(
            t,
            t.is_finite() && t >= 0.0,
            "params->tolerance",
            "finite and ≥ 0",
        )?;
        let s = p.shift;
        let shift_ok = s.is_finite() && (0.0..1.0).contains(&s);
        check_f64(s, shift_ok, "params->shift", "in [0, 1)")?;
        Ok(KnoppelOptions {
            weights,
            max_iterations: p.max_iterations as usize,
            tolerance: p.tolerance,
            shift: p.shift,
        })
    }

    /// # Safety
    /// As `pleat_cwf_create_from_frequency`.
    pub(super) unsafe fn create_from_frequency(
        base: *const PleatMesh,
        frequency: *const f64,
        frequency_count: usize,
        location: u32,
        amplitude: *const f64,
        vertex_count: usize,
        params: *const PleatKnoppelParams,
        out: *mut *mut PleatCwf,
    ) -> Result<()> {
        let out = arg_out(out, "out")?;
        let m = mesh_ref(base, "base")?;
        non_null(frequency, "frequency")?;
        let opts = knoppel_options(&read_versioned(params, "params")?)?;
        let want = match location {
            PLEAT_FREQUENCY_PER_VERTEX => m.vertex_count(),
            PLEAT_FREQUENCY_PER_FACE => m.triangle_count(),
            l => {
                return Err(Error::InvalidArgument(format!(
                    "location is {l}; use PLEAT_FREQUENCY_PER_VERTEX or PLEAT_FREQUENCY_PER_FACE"
                )))
            }
        };
        check_count(
            "frequency_count",
            frequency_count,
            want,
            "vertices or triangles, by location",
        )?;
        let (a, _) = vertex_data(m, amplitude, std::ptr::null(), vertex_count)?;
        let flat = read_finite(frequency, 3 * frequency_count, "frequency")?;
        let k: Vec<[f64; 3]> = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let field = if location == PLEAT_FREQUENCY_PER_VERTEX {
            FrequencyField::PerVertex(&k)
        } else {
            FrequencyField::PerFace(&k)
        };
        let (cwf, report) = Cwf::from_frequency_field(m.clone(), field, a, &opts)?;
        out.put_boxed(PleatCwf {
            cwf,
            knoppel: Some(report),
            edit: None,
        });
        Ok(())
    }

    /// # Safety
    /// As `pleat_cwf_read_file`.
    pub(super) unsafe fn read_file(
        base: *const PleatMesh,
        path: *const std::ffi::c_char,
        out: *mut *mut PleatCwf,
    ) -> Result<()> {
        let m = mesh_ref(base, "base")?;
        let path = c_str_arg(path, "path")?;
        let out = arg_out(out, "out")?;
        let cwf = crate::wrinkle::read_cwf(path, m.clone())?;
        out.put_boxed(PleatCwf {
            cwf,
            knoppel: None,
            edit: None,
        });
        Ok(())
    }

    /// The Rust options of C evaluation parameters (fields only when `want_fields`), every
    /// field checked.
    pub(in crate::ffi) fn eval_options(
        p: &PleatWrinkleEvalParams,
        want_fields: bool,
    ) -> Result<EvalOptions> {
        check_flags(p.flags, ALL_FIELDS, "params->flags")?;
        let boundary = match p.boundary {
            PLEAT_WRINKLE_BOUNDARY_FIXED => BoundaryRule::Fixed,
            PLEAT_WRINKLE_BOUNDARY_SMOOTH => BoundaryRule::Smooth,
            b => {
                return Err(Error::InvalidArgument(format!(
                    "params->boundary is {b}; use PLEAT_WRINKLE_BOUNDARY_FIXED or _SMOOTH"
                )))
            }
        };
        let a = p.corner_angle;
        let angle_ok = a.is_finite() && (0.0..=std::f64::consts::PI).contains(&a);
        check_f64(a, angle_ok, "params->corner_angle", "in [0, π] radians")?;
        let d = p.displacement_scale;
        check_f64(d, d.is_finite(), "params->displacement_scale", "finite")?;
        if p.max_output_triangles == 0 {
            return Err(Error::InvalidArgument(
                "params->max_output_triangles is 0; must be ≥ 1".into(),
            ));
        }
        let f = if want_fields { p.flags } else { 0 };
        Ok(EvalOptions {
            subdivision: SubdivisionOptions {
                boundary,
                corner_angle: p.corner_angle,
            },
            displacement_scale: p.displacement_scale,
            want_amplitude: f & PLEAT_WRINKLE_FIELD_AMPLITUDE != 0,
            want_phase: f & PLEAT_WRINKLE_FIELD_PHASE != 0,
            want_normals: f & PLEAT_WRINKLE_FIELD_NORMALS != 0,
            want_z: f & (PLEAT_WRINKLE_FIELD_Z | PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS) != 0,
            want_omega: f & PLEAT_WRINKLE_FIELD_OMEGA != 0,
            max_output_faces: usize::try_from(p.max_output_triangles).unwrap_or(usize::MAX),
            in_plane_v2: false,
        })
    }

    fn flatten3(v: Vec<[f64; 3]>) -> Vec<f64> {
        v.into_iter().flatten().collect()
    }

    /// # Safety
    /// As `pleat_cwf_evaluate`.
    pub(super) unsafe fn evaluate(
        cwf: *const PleatCwf,
        params: *const PleatWrinkleEvalParams,
        progress: PleatProgressFn,
        user_data: *mut std::ffi::c_void,
        out_mesh: *mut *mut PleatMesh,
        out_fields: *mut *mut PleatWrinkleFields,
        stats: *mut PleatWrinkleEvalStats,
    ) -> PleatStatus {
        guard_progress(progress, user_data, |relay| {
            let c = cwf_ref(cwf)?;
            let out_mesh = arg_out(out_mesh, "out_mesh")?;
            let stats = versioned_out(stats, "stats")?;
            let p = read_versioned(params, "params")?;
            let opts = eval_options(&p, !out_fields.is_null())?;
            let (ev, st) = c
                .cwf
                .evaluate_with_progress(p.levels as usize, &opts, relay)?;
            let flags = if out_fields.is_null() { 0 } else { p.flags };
            let keep = |bit: u32| flags & bit != 0;
            let fields = [
                ev.amplitude.filter(|_| keep(PLEAT_WRINKLE_FIELD_AMPLITUDE)),
                ev.phase.filter(|_| keep(PLEAT_WRINKLE_FIELD_PHASE)),
                ev.normals
                    .filter(|_| keep(PLEAT_WRINKLE_FIELD_NORMALS))
                    .map(flatten3),
                ev.z.filter(|_| keep(PLEAT_WRINKLE_FIELD_Z))
                    .map(|z| z.iter().flat_map(|z| [z.re, z.im]).collect()),
                ev.smooth_positions
                    .filter(|_| keep(PLEAT_WRINKLE_FIELD_SMOOTH_POSITIONS))
                    .map(flatten3),
                ev.omega.filter(|_| keep(PLEAT_WRINKLE_FIELD_OMEGA)),
            ];
            let subdivision = st.subdivision_seconds();
            let displacement = st.stages.seconds(EvalStage::Displace);
            let s = PleatWrinkleEvalStats {
                struct_size: 0,
                levels: p.levels,
                vertex_count: ev.mesh.vertex_count() as u64,
                triangle_count: ev.mesh.triangle_count() as u64,
                total_seconds: st.total_seconds(),
                subdivision_seconds: subdivision,
                displacement_seconds: displacement,
            };
            // Nothing below fails: every output is written or none is.
            out_mesh.put_mesh(ev.mesh);
            if !out_fields.is_null() {
                *out_fields = Box::into_raw(Box::new(PleatWrinkleFields { fields }));
            }
            if let Some(stats) = stats {
                stats.write(s);
            }
            Ok(())
        })
    }
}
