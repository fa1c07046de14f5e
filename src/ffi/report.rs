//! `pleat_mesh_check`: the validity report of any mesh, as a versioned C struct.

use super::boundary::{check_flags, required_versioned_out, versioned};
use super::common::{guard, guard_progress, PleatProgressFn, PleatStatus};
use super::mesh::{mesh_ref, PleatMesh};
use crate::verify::{MeshReport, ReportOptions};
use crate::{Error, Progress};

/// `pleat_mesh_check` flag: skip the self-intersection test (the most expensive part);
/// `self_intersections_checked` is then 0.
pub const PLEAT_CHECK_SKIP_SELF_INTERSECTIONS: u32 = 1;
/// `pleat_mesh_check` flag: analyse topology after merging exactly coincident vertices.
pub const PLEAT_CHECK_WELD: u32 = 2;

/// Validity report of a triangle soup, filled by `pleat_mesh_check`. Counts follow the
/// independent checker's definitions (see docs/guide/errors-and-limits.md). Yes/no fields are 0 or
/// 1.
///
/// Set `struct_size = sizeof(PleatMeshReport)` before the call; pleat fills only that many
/// bytes, so a caller compiled against an older, shorter struct keeps working.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct PleatMeshReport {
    /// In: `sizeof(PleatMeshReport)` as the caller knows it. Out: the bytes pleat filled.
    pub struct_size: u32,
    /// 1 when the mesh is closed (every edge has exactly two faces).
    pub is_closed: u32,
    /// Number of vertices (referenced or not).
    pub vertex_count: u64,
    /// Number of vertices used by at least one triangle.
    pub referenced_vertex_count: u64,
    /// Number of triangles.
    pub triangle_count: u64,
    /// Number of unique undirected edges.
    pub edge_count: u64,
    /// Vertex-connected components.
    pub component_count: u64,
    /// Edges with exactly one incident triangle.
    pub boundary_edge_count: u64,
    /// Edges with more than two incident triangles.
    pub nonmanifold_edge_count: u64,
    /// Vertices whose incident triangles form more than one fan.
    pub nonmanifold_vertex_count: u64,
    /// Triangles with a repeated index or exactly collinear corners.
    pub degenerate_face_count: u64,
    /// Triangles with the same vertex set as an earlier triangle.
    pub duplicate_face_count: u64,
    /// Interior edges whose two triangles traverse it in the same direction.
    pub misoriented_edge_count: u64,
    /// Intersecting triangle pairs (exact predicates; neighbours sharing a vertex or an edge
    /// count only when they overlap). 0 when not checked.
    pub self_intersecting_pair_count: u64,
    /// Sum over components of the genus; -1 when not closed and manifold.
    pub total_genus: i64,
    /// Euler characteristic V − E + F over referenced vertices.
    pub euler_characteristic: i64,
    /// 1 when no edge is non-manifold.
    pub is_edge_manifold: u32,
    /// 1 when no edge and no vertex is non-manifold and no triangle repeats an index.
    pub is_manifold: u32,
    /// 1 when closed and manifold.
    pub is_watertight: u32,
    /// 1 when every interior edge is traversed in opposite directions by its two triangles.
    pub consistently_oriented: u32,
    /// 1 when the self-intersection test ran.
    pub self_intersections_checked: u32,
    /// 1 when the test ran and found no intersecting pair and no degenerate triangle.
    pub self_intersection_free: u32,
    /// Total surface area.
    pub surface_area: f64,
    /// Signed volume (positive for outward-oriented closed meshes).
    pub signed_volume: f64,
    /// Bounding-box diagonal length of the referenced vertices.
    pub bbox_diagonal: f64,
    /// Bounding-box minimum corner.
    pub bbox_min: [f64; 3],
    /// Bounding-box maximum corner.
    pub bbox_max: [f64; 3],
    /// 1 when `self_intersecting_pair_count` is a lower bound, not the exact count: counting
    /// stops once 2²² exact tests have found an intersection (a pile of near-copies of one
    /// triangle; stacked exact copies are counted per group without using it up).
    /// `self_intersection_free` is exact (0) then. Appended 2026-11-27.
    pub self_intersecting_pair_count_is_lower_bound: u32,
    /// Padding; written as 0.
    pub reserved: u32,
}

fn to_c(r: &MeshReport) -> PleatMeshReport {
    let u = |n: usize| n as u64;
    PleatMeshReport {
        struct_size: std::mem::size_of::<PleatMeshReport>() as u32,
        is_closed: r.is_closed as u32,
        vertex_count: u(r.n_vertices),
        referenced_vertex_count: u(r.n_referenced_vertices),
        triangle_count: u(r.n_faces),
        edge_count: u(r.n_edges),
        component_count: u(r.n_components),
        boundary_edge_count: u(r.n_boundary_edges),
        nonmanifold_edge_count: u(r.n_nonmanifold_edges),
        nonmanifold_vertex_count: u(r.n_nonmanifold_vertices),
        degenerate_face_count: u(r.n_degenerate_faces),
        duplicate_face_count: u(r.n_duplicate_faces),
        misoriented_edge_count: u(r.n_misoriented_edges),
        self_intersecting_pair_count: u(r.n_self_intersecting_pairs.unwrap_or(0)),
        total_genus: r.total_genus.unwrap_or(-1),
        euler_characteristic: r.euler_characteristic_total,
        is_edge_manifold: r.is_edge_manifold as u32,
        is_manifold: r.is_manifold as u32,
        is_watertight: r.is_watertight as u32,
        consistently_oriented: r.consistently_oriented as u32,
        self_intersections_checked: r.self_intersection_free.is_some() as u32,
        self_intersection_free: r.self_intersection_free.unwrap_or(false) as u32,
        surface_area: r.surface_area,
        signed_volume: r.signed_volume,
        bbox_diagonal: r.bbox_diagonal,
        bbox_min: r.bbox_min,
        bbox_max: r.bbox_max,
        self_intersecting_pair_count_is_lower_bound: r
            .n_self_intersecting_pairs_is_lower_bound
            .unwrap_or(false) as u32,
        reserved: 0,
    }
}

// Smallest size: through `is_closed`.
versioned!(PleatMeshReport, 8);

/// The report options of `flags` (`PLEAT_CHECK_*`); InvalidArgument on an unknown bit.
fn check_options(flags: u32) -> crate::Result<ReportOptions> {
    let known = PLEAT_CHECK_SKIP_SELF_INTERSECTIONS | PLEAT_CHECK_WELD;
    check_flags(flags, known, "flags")?;
    Ok(ReportOptions {
        self_intersections: flags & PLEAT_CHECK_SKIP_SELF_INTERSECTIONS == 0,
        weld: flags & PLEAT_CHECK_WELD != 0,
    })
}

/// Computes the validity report of `mesh` (any soup) into `*out`.
///
/// - `mesh`: non-NULL.
/// - `flags`: 0 or a bitwise OR of `PLEAT_CHECK_SKIP_SELF_INTERSECTIONS`, `PLEAT_CHECK_WELD`.
/// - `out`: non-NULL, with `out->struct_size` set to `sizeof(PleatMeshReport)` (at least 8).
///
/// Runs in parallel on pleat's thread pool; about 5 s for a million triangles on two cores with
/// the self-intersection test. To report progress or cancel, use
/// `pleat_mesh_check_with_progress`.
///
/// # Safety
/// `mesh` is NULL or live; `out` is NULL or points to `out->struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_check(
    mesh: *const PleatMesh,
    flags: u32,
    out: *mut PleatMeshReport,
) -> PleatStatus {
    guard(|| {
        let m = mesh_ref(mesh, "mesh")?;
        let out = required_versioned_out(out, "out")?;
        let options = check_options(flags)?;
        out.write(to_c(&MeshReport::compute_with(m, &options)));
        Ok(())
    })
}

/// As `pleat_mesh_check`, with a progress callback that can cancel.
///
/// - `progress`, `user_data`: optional callback (NULL for none), called on this thread with
///   stage `"check"` after each topology phase and, in the self-intersection test, after each
///   batch of face chunks (at most about 10⁶ faces' worth of work between two calls); a
///   non-zero return cancels: `PLEAT_STATUS_CANCELLED`, and `*out` is not written.
/// - `mesh`, `flags`, `out`: as `pleat_mesh_check`; the report is the same.
///
/// # Safety
/// `mesh` is NULL or live; `out` is NULL or points to `out->struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_mesh_check_with_progress(
    mesh: *const PleatMesh,
    flags: u32,
    progress: PleatProgressFn,
    user_data: *mut std::ffi::c_void,
    out: *mut PleatMeshReport,
) -> PleatStatus {
    guard_progress(progress, user_data, |relay| {
        let m = mesh_ref(mesh, "mesh")?;
        let out = required_versioned_out(out, "out")?;
        let options = check_options(flags)?;
        let mut keep_going = |fraction: f64| {
            relay(Progress {
                stage: "check",
                fraction,
            })
        };
        let report = MeshReport::compute_with_progress(m, &options, &mut keep_going)
            .ok_or(Error::Cancelled)?;
        out.write(to_c(&report));
        Ok(())
    })
}
