//! Cages that strictly enclose the input (dissertation ch. 4.5.2).
//!
//! A cage is a coarse, watertight, manifold, self-intersection-free mesh that fully encloses
//! the input without touching it. It is the LOD pipeline of [`crate::lowpoly`] (offset surface
//! at `d = l / n_p`, then Alg. 3) with one more check in the guard of every local operation
//! (§4.5.2: "adding one more intersection check between the current mesh and the input"):
//! - no face of the modified patch touches or intersects any input triangle (exact tests on
//!   the candidates of a BVH over the input, degenerate input triangles tested by their edges);
//! - no input vertex changes side: the winding-number change at each input vertex inside the
//!   box swept by the operation, computed from the solid angles of the patch before and after,
//!   must be 0.
//!
//! - **clearance**: no modified face comes closer to the input than
//!   [`crate::lowpoly::LodParams::clearance`] (default a twentieth of `d`; exact
//!   triangle–triangle distances), so the cage does not merely avoid contact but keeps a real
//!   gap. The independent verification measures the exact minimum distance between cage and
//!   input triangles ([`LodReport::clearance`], `min_clearance`) and says when the requested
//!   clearance could not be kept (only where the start surface was already closer).
//!
//! The offset surface encloses the input at distance `d`, and each accepted operation keeps
//! both properties, so the result encloses every input vertex (and, as nothing touches, every
//! input point). The input may be any soup: non-manifold, open, self-intersecting.
//! The result is verified independently, at the end of every bake, by `crate::verify` (code
//! that shares nothing with the guard): [`crate::verify::MeshReport`] for Pro.III, an exact
//! surface–surface test against the input, and hierarchical winding numbers (Barill et al.
//! 2018) of every input vertex ([`LodReport::verified`]`.cage_encloses_without_touching`).
//!
//! May import: `crate::lowpoly`, `crate::verify`, `crate::mesh`, `crate::report`,
//! `crate::error`.

use crate::lowpoly::{run, run_chain, LodParams, LodReport, Mode};
use crate::mesh::TriMesh;
use crate::report::ProgressFn;
use crate::Result;

pub use crate::verify::CageCheck;

/// Bakes a cage of `input` at `params.screen_size` (offset `d = l / n_p`; a larger screen size
/// gives a tighter cage with more faces). Same parameters, report, progress and errors as
/// [`crate::lowpoly::generate`].
pub fn generate(
    input: &TriMesh,
    params: &LodParams,
    progress: &mut ProgressFn<'_>,
) -> Result<(TriMesh, LodReport)> {
    run(input, params, Mode::Cage, progress)
}

/// One cage per screen size (see [`crate::lowpoly::generate_chain`]). With a clearance (the
/// default) every level is baked from its own offset surface — a coarser cage needs a larger
/// clearance than the finer cage keeps — so the chain costs the sum of its levels; with
/// `Clearance::FractionOfD(0.0)` a coarser cage starts from the finer cage, which already
/// encloses the input without touching it.
pub fn generate_chain(
    input: &TriMesh,
    screen_sizes: &[f64],
    params: &LodParams,
    progress: &mut ProgressFn<'_>,
) -> Result<Vec<(TriMesh, LodReport)>> {
    run_chain(input, screen_sizes, params, Mode::Cage, progress)
}

/// Checks that `cage` encloses every vertex of `input` and touches none of its triangles —
/// the verification the pipeline runs on its own output, usable on any mesh (benchmarks,
/// tests, other cage generators). Same as [`crate::verify::check_cage`].
pub fn check(cage: &TriMesh, input: &TriMesh) -> CageCheck {
    crate::verify::check_cage(cage, input)
}
