//! Mesh flow — dissertation Alg. 3 lines 7–11 with the local update of Alg. 4.
//!
//! Every vertex `v` is pushed a fraction `r` (default 1/8, §4.4.3) of the way to its closest
//! input point `v*`: `d_v = r (v* − v)` (for a cage with clearance `c`, to the point at
//! distance `c` from `v*` on the segment `v* v`). The [`local_update`] line search halves the step
//! until the move passes the [`Guard`], and applies `0.95 α d_v` — the 0.95 safety factor of
//! Alg. 4. Unlike the pseudo-code, the position actually applied (`v + 0.95 α d_v`) is the one
//! the guard checks, so no unchecked position is ever written.
//!
//! Closest points are computed for all vertices up front in parallel (each depends only on its
//! own vertex, which does not move before its turn), then vertices are updated sequentially in
//! id order (Gauss–Seidel, deterministic for any thread count).

use rayon::prelude::*;

use super::guard::Guard;
use crate::geom::Vec3;
use crate::mesh::halfedge::VertexId;
use crate::{Error, Result};

/// The safety factor of Alg. 4 line 5.
pub const SAFETY_FACTOR: f64 = 0.95;

/// Halvings of the line search before a vertex is left in place (α ≥ 2⁻¹⁰).
pub const MAX_HALVINGS: u32 = 10;

/// What one flow (or alignment) sweep did.
#[derive(Debug, Clone, Default)]
pub(crate) struct MoveReport {
    /// Vertices moved (with some α).
    pub moved: u64,
    /// Vertices left in place (every α rejected, or zero step).
    pub stuck: u64,
    /// Sum of the lengths of the applied displacements.
    pub total_motion: f64,
}

/// Alg. 4: tries `v + 0.95 α d` for `α = 1, 1/2, …` and applies the first the guard accepts.
/// Returns the applied displacement length (0 when none was accepted).
pub(crate) fn local_update(g: &mut Guard<'_>, v: VertexId, d: Vec3) -> f64 {
    local_update_if(g, v, d, &mut |_, _, _| true)
}

/// [`local_update`] with an extra acceptance test: a trial position `q` of `v` is offered to
/// the guard only when `accept(guard, v, q)` holds (the input-plane fit's coverage check).
pub(crate) fn local_update_if(
    g: &mut Guard<'_>,
    v: VertexId,
    d: Vec3,
    accept: &mut dyn FnMut(&Guard<'_>, VertexId, Vec3) -> bool,
) -> f64 {
    let p = Vec3::from(g.mesh().position(v));
    let mut alpha = 1.0;
    for _ in 0..=MAX_HALVINGS {
        let step = d * (SAFETY_FACTOR * alpha);
        if accept(g, v, p + step) && g.try_move(v, (p + step).to_array()).is_ok() {
            return step.length();
        }
        alpha *= 0.5;
    }
    0.0
}

/// One flow sweep (Alg. 3 lines 7–11) with ratio `r`. `keep_going` is polled with the
/// fraction done; `false` cancels.
pub(crate) fn flow_sweep(
    g: &mut Guard<'_>,
    r: f64,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<MoveReport> {
    let verts: Vec<VertexId> = g
        .mesh()
        .vertices()
        .filter(|&v| g.mesh().vertex_halfedge(v).is_some())
        .collect();
    let input = g.input();
    let positions: Vec<[f64; 3]> = verts.iter().map(|&v| g.mesh().position(v)).collect();
    let c = g.clearance();
    let targets: Vec<[f64; 3]> = positions
        .par_iter()
        .map(|&p| {
            let q = input.closest(p).0;
            if c > 0.0 {
                target_at_clearance(p, q, c)
            } else {
                q
            }
        })
        .collect();
    let mut rep = MoveReport::default();
    for (i, &v) in verts.iter().enumerate() {
        if i % 1024 == 0 && !keep_going(i as f64 / verts.len() as f64) {
            return Err(Error::Cancelled);
        }
        let d = (Vec3::from(targets[i]) - Vec3::from(positions[i])) * r;
        record(
            &mut rep,
            if d.length() > 0.0 {
                local_update(g, v, d)
            } else {
                0.0
            },
        );
    }
    Ok(rep)
}

/// Cage with clearance `c`: the flow target of a vertex at `p` whose closest input point is
/// `q` is the point at distance `c` from `q` towards `p` (the closest place the guard accepts
/// on that line), or `p` itself (no motion) when it is already within `c`.
fn target_at_clearance(p: [f64; 3], q: [f64; 3], c: f64) -> [f64; 3] {
    let (p, q) = (Vec3::from(p), Vec3::from(q));
    let dist = p.distance(q);
    if dist <= c {
        return p.to_array();
    }
    (q + (p - q) * (c / dist)).to_array()
}

pub(crate) fn record(rep: &mut MoveReport, moved: f64) {
    if moved > 0.0 {
        rep.moved += 1;
        rep.total_motion += moved;
    } else {
        rep.stuck += 1;
    }
}
