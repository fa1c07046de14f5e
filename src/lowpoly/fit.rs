//! Final input-plane fit (for shading fidelity at equal face count).
//!
//! The loop of Alg. 3 leaves a LOD that approximates the *offset* surface: convex features
//! rounded with radius `d`, the whole surface 1–3 `d` outside the input. Shading follows the
//! normals, so after the loop the LOD is fitted to the **input's** planes, keeping its
//! connectivity's guarantees:
//!
//! 1. **Vertex placement** — Garland & Heckbert's QEM vertex placement (SIGGRAPH 1997, §4),
//!    with the input's planes instead of the decimated surface's. Every LOD face is sampled at
//!    the 10 points of the barycentric lattice `(i, j, k)/3`; each sample's closest input
//!    triangle (within [`SAMPLE_RADIUS`]·`d`) contributes the quadric of its plane,
//!    `w (nᵀx − nᵀq)²`, to the face's three vertices with weight `w = area · λ_k / 10`
//!    (barycentric coordinate `λ_k`: the samples near a vertex count for it). The vertex moves
//!    to the minimiser of `Σ w (nᵀx − nᵀq)² + μ ‖x − p‖²` (`p` its current position,
//!    `μ = ` [`REGULARIZATION`]` · tr A`): `(A + μI) x = b + μ p`. The Tikhonov term keeps a
//!    vertex in place along the directions no plane constrains (flat areas: tangentially;
//!    creases: along the crease), so the fit only removes the offset and re-sharpens creases
//!    and corners where two or three input planes meet. The step is capped at
//!    [`MAX_STEP`]·`d`, halved while it would end farther from the input than
//!    `max(`[`DRIFT_CAP`]`·d, current distance)`, and applied through the guard with the
//!    halving line search of Alg. 4.
//! 2. **Flips** — an edge is flipped when the two triangles after the flip deviate less from
//!    the input's normals than the two before, by a factor [`FLIP_GAIN`]. The deviation of a
//!    triangle `T` is `area(T) · mean_s (1 − |n_T · n_in(s)|)` over 4 samples `s` (centroid and
//!    the points `(4, 1, 1)/6`), `n_in(s)` the unit normal of the input triangle closest to `s`
//!    (a sample without input triangle within the radius counts 1), and when the new edge's
//!    midpoint is within `max(`[`DRIFT_CAP`]`·d, the old edge midpoint's distance)` of the
//!    input. The flip goes through the guard ([`Guard::try_flip`]).
//!
//! [`FIT_SWEEPS`] sweeps of {placement, flips}, then one last placement. Every operation passes
//! the guard, so the mesh stays watertight, manifold, self-intersection-free and of the same
//! topology; the guard also keeps the LOD's sheets [`SELF_CLEARANCE`]`·d` apart (its check 6:
//! no operation brings a face within that distance of a face sharing no vertex with it and
//! facing more than 90° away, or closer than it was), so the two sides of an input sheet thinner
//! than `2d`, which both project onto the sheet's plane, stop that far apart instead of collapsing
//! onto each other; and the coverage check (`coverage.rs`): no line-search trial or flip may leave
//! an input sample farther from the LOD than `max(`[`COVERAGE_FLOOR`]`·d, its distance before the
//! fit)` (input buried deeper than `2 d`: up to one `d` more, never beyond the farthest), so
//! the fit cannot pull the surface off a rim or a thin part of the input. The pipeline skips
//! the fit for cages (a cage must stay outside the input) and reverts it when the measured
//! Hausdorff distance grew (`pipeline.rs`).
//!
//! Deterministic for any thread count: closest points and flip decisions are computed in
//! parallel from an unchanged mesh, quadrics are summed and every operation applied
//! sequentially in id order.

use rayon::prelude::*;

use super::align::capped_step;
use super::coverage::Coverage;
use super::flow::{local_update_if, record, MoveReport};
use super::guard::{Guard, InputModel};
use crate::geom::{normalized, tri_normal, Vec3};
use crate::mesh::halfedge::{EdgeId, FaceId, VertexId};
use crate::{Error, Result};

/// Sweeps of {vertex placement, flips} (a last placement follows).
pub const FIT_SWEEPS: u32 = 3;

/// Samples farther than this many `d` from the input contribute no plane.
pub const SAMPLE_RADIUS: f64 = 4.0;

/// Longest placement step, in `d`.
pub const MAX_STEP: f64 = 3.0;

/// No placement step ends farther from the input than `max(DRIFT_CAP · d, where it
/// started)` (halved until it does, as the alignment's drift cap, `align::capped_step`): where
/// the planes of a thin spike or a sheet's rim meet far beyond the input, the QEM optimum
/// extrapolates, and the Hausdorff distance would grow there.
pub const DRIFT_CAP: f64 = 1.0;

/// The coverage floor, in `d`: no fit operation leaves an input sample farther from the LOD
/// than `max(COVERAGE_FLOOR · d, its distance before the fit)`, plus up to one `d` for input
/// buried deeper than `2 d` (`coverage.rs`).
pub const COVERAGE_FLOOR: f64 = 1.0;

/// The self-clearance of the fit, in `d`: no fit operation brings a LOD face closer than
/// `SELF_CLEARANCE · d` to a face sharing no vertex with it whose normal points more than 90°
/// away from its own (the other side of a sheet), or closer than it already was
/// (the guard's check 6). Without it, both sides of a double-sided sheet fit onto the same
/// plane and the LOD folds onto itself, 10⁻⁶ apart (docs/design-notes-lod.md,
/// "Textured bakes").
pub const SELF_CLEARANCE: f64 = 0.25;

/// Tikhonov weight `μ / tr A` of the placement (keeps unconstrained directions in place).
pub const REGULARIZATION: f64 = 1e-2;

/// A flip is made when it lowers the normal deviation of its two triangles below this
/// fraction of the deviation before.
pub const FLIP_GAIN: f64 = 0.9;

/// Edges whose two triangles deviate less than this (mean `1 − |cos|`, about 2.6°) are not
/// considered for a flip.
const FLIP_MIN_DEVIATION: f64 = 1e-3;

/// The barycentric lattice `(i, j, k)/3` of the placement samples.
const PLACE_SAMPLES: [[f64; 3]; 10] = {
    const T: f64 = 1.0 / 3.0;
    [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [2.0 * T, T, 0.0],
        [T, 2.0 * T, 0.0],
        [0.0, 2.0 * T, T],
        [0.0, T, 2.0 * T],
        [2.0 * T, 0.0, T],
        [T, 0.0, 2.0 * T],
        [T, T, T],
    ]
};

/// The barycentric points of the flip criterion: centroid and `(4, 1, 1)/6`.
const FLIP_SAMPLES: [[f64; 3]; 4] = {
    const S: f64 = 1.0 / 6.0;
    [
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
        [4.0 * S, S, S],
        [S, 4.0 * S, S],
        [S, S, 4.0 * S],
    ]
};

/// What the fit did.
#[derive(Debug, Clone, Default)]
pub(crate) struct FitReport {
    /// Vertex moves applied (summed over placements).
    pub moves: u64,
    /// Edge flips applied.
    pub flips: u64,
    /// Total length of the applied moves (model units).
    pub motion: f64,
    /// Moves (line-search trials) and flips refused because they would uncover input
    /// (`coverage.rs`).
    pub uncovering_refused: u64,
}

/// The input's triangles as unit normals and a point on their plane (`None` when degenerate).
struct InputPlanes<'a> {
    input: &'a InputModel,
    planes: Vec<Option<(Vec3, Vec3)>>,
    radius: f64,
    /// [`DRIFT_CAP`]` · d`.
    drift_cap: f64,
}

impl<'a> InputPlanes<'a> {
    fn new(input: &'a InputModel, radius: f64, drift_cap: f64) -> Self {
        let planes = (0..input.tris.len() as u32)
            .into_par_iter()
            .map(|t| {
                let [a, b, c] = input.triangle(t).map(Vec3::from);
                normalized(tri_normal(a, b, c)).map(|n| (n, a))
            })
            .collect();
        InputPlanes {
            input,
            planes,
            radius,
            drift_cap,
        }
    }

    /// The plane of the input triangle closest to `p`, if one is within the radius.
    fn plane_near(&self, p: Vec3) -> Option<(Vec3, Vec3)> {
        let i = self.input;
        let c = i
            .bvh
            .closest_point(&i.positions, &i.tris, p.to_array(), self.radius)?;
        self.planes[c.triangle as usize]
    }
}

/// A point of triangle `t` by barycentric coordinates.
fn at(t: &[Vec3; 3], b: [f64; 3]) -> Vec3 {
    t[0] * b[0] + t[1] * b[1] + t[2] * b[2]
}

/// Runs the fit on the guard's mesh (a LOD: never call it in cage mode). `keep_going` is
/// polled with the fraction done; `false` cancels.
pub(crate) fn fit_to_input(
    g: &mut Guard<'_>,
    d: f64,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<FitReport> {
    g.set_self_clearance(SELF_CLEARANCE * d);
    let r = fit_sweeps(g, d, keep_going);
    g.set_self_clearance(0.0);
    r
}

/// The sweeps of [`fit_to_input`] (module docs).
fn fit_sweeps(
    g: &mut Guard<'_>,
    d: f64,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<FitReport> {
    let planes = InputPlanes::new(g.input(), SAMPLE_RADIUS * d, DRIFT_CAP * d);
    let mut cov = Coverage::new(g.input(), g.mesh(), d, COVERAGE_FLOOR * d);
    let mut rep = FitReport::default();
    let steps = 2 * FIT_SWEEPS + 1;
    for step in 0..steps {
        if !keep_going(step as f64 / steps as f64) {
            return Err(Error::Cancelled);
        }
        if step % 2 == 0 {
            let mr = place_vertices(g, &planes, &mut cov, MAX_STEP * d);
            rep.moves += mr.moved;
            rep.motion += mr.total_motion;
        } else {
            rep.flips += flip_sweep(g, &planes, &mut cov);
        }
    }
    rep.uncovering_refused = cov.refused;
    Ok(rep)
}

/// A plane quadric `Σ w (nᵀx − nᵀq)²` as `A = Σ w n nᵀ`, `b = Σ w n (nᵀq)`.
#[derive(Debug, Clone, Copy, Default)]
struct Quadric {
    a: [[f64; 3]; 3],
    b: Vec3,
}

impl Quadric {
    fn add(&mut self, n: Vec3, q: Vec3, w: f64) {
        for i in 0..3 {
            for j in 0..3 {
                self.a[i][j] += w * n[i] * n[j];
            }
        }
        self.b += n * (w * n.dot(q));
    }

    /// The minimiser of the quadric plus `μ ‖x − p‖²`, `μ = REGULARIZATION · tr A`; `None`
    /// without any plane.
    fn minimiser(&self, p: Vec3) -> Option<Vec3> {
        let tr = self.a[0][0] + self.a[1][1] + self.a[2][2];
        if !(tr > 0.0 && tr.is_finite()) {
            return None;
        }
        let mu = REGULARIZATION * tr;
        let mut a = self.a;
        for (i, row) in a.iter_mut().enumerate() {
            row[i] += mu;
        }
        super::align::solve3(a, self.b + p * mu)
    }
}

/// One placement sweep: quadrics from the current mesh, then every vertex in id order toward
/// its minimiser (step capped at `max_step`) through the guarded line search.
fn place_vertices(
    g: &mut Guard<'_>,
    planes: &InputPlanes<'_>,
    cov: &mut Coverage,
    max_step: f64,
) -> MoveReport {
    let m = g.mesh();
    let faces: Vec<FaceId> = m.faces().collect();
    let hits: Vec<[Option<(Vec3, Vec3)>; 10]> = faces
        .par_iter()
        .map(|&f| {
            let t = m.face_positions(f).map(Vec3::from);
            PLACE_SAMPLES.map(|b| planes.plane_near(at(&t, b)))
        })
        .collect();
    let mut quadrics = vec![Quadric::default(); m.vertex_capacity()];
    for (&f, hit) in faces.iter().zip(&hits) {
        let area = 0.5 * m.face_area_vector(f).length();
        let vs = m.face_vertices(f);
        for (b, h) in PLACE_SAMPLES.iter().zip(hit) {
            let Some((n, q)) = *h else { continue };
            for k in 0..3 {
                if b[k] > 0.0 {
                    quadrics[vs[k].index()].add(n, q, area * b[k] / PLACE_SAMPLES.len() as f64);
                }
            }
        }
    }
    let verts: Vec<VertexId> = m
        .vertices()
        .filter(|&v| m.vertex_halfedge(v).is_some())
        .collect();
    let mut rep = MoveReport::default();
    for v in verts {
        let p = Vec3::from(g.mesh().position(v));
        let Some(x) = quadrics[v.index()].minimiser(p) else {
            rep.stuck += 1;
            continue;
        };
        let mut step = x - p;
        let len = step.length();
        if len > max_step {
            step *= max_step / len;
        }
        let capped = if len > 0.0 {
            capped_step(g, p, step, planes.drift_cap)
        } else {
            None
        };
        let moved = capped.map_or(0.0, |step| {
            // the line search tries `SAFETY_FACTOR · step` and halvings of it, which move `v`
            // (measured as `|(p + s) − p|`, rounding included) less than this
            let max_move = step.length() + 1e-9 * (p.abs().max_element() + step.length());
            let relying = cov.relying_on_ring(g.mesh(), v, max_move);
            let mut hint = 0;
            let mut keeps =
                |g: &Guard<'_>, v, q| cov.keeps_move(&relying, g.mesh(), v, q, &mut hint);
            local_update_if(g, v, step, &mut keeps)
        });
        record(&mut rep, moved);
    }
    rep
}

/// Normal deviation of triangle `t` from the input (module docs, item 2).
fn deviation(t: [Vec3; 3], planes: &InputPlanes<'_>) -> f64 {
    let nt = tri_normal(t[0], t[1], t[2]);
    let area = 0.5 * nt.length();
    let Some(nt) = normalized(nt) else {
        return 0.0;
    };
    let sum: f64 = FLIP_SAMPLES
        .iter()
        .map(|&b| match planes.plane_near(at(&t, b)) {
            Some((n, _)) => 1.0 - nt.dot(n).abs(),
            None => 1.0,
        })
        .sum();
    area * sum / FLIP_SAMPLES.len() as f64
}

/// A flip decided on the unchanged mesh: the edge and its quad `a → b`, opposite `c`, `d`.
#[derive(Debug, Clone, Copy)]
struct FlipPlan {
    edge: EdgeId,
    quad: [VertexId; 4],
}

/// One flip sweep: decisions on the unchanged mesh in parallel, then the flips in edge order
/// through the guard (skipping edges whose quad an earlier flip changed). Returns the flips.
fn flip_sweep(g: &mut Guard<'_>, planes: &InputPlanes<'_>, cov: &mut Coverage) -> u64 {
    let shared: &Guard<'_> = g;
    let edges: Vec<EdgeId> = shared.mesh().edges().collect();
    let plans: Vec<FlipPlan> = edges
        .par_iter()
        .filter_map(|&e| plan_flip(shared, e, planes))
        .collect();
    let mut flips = 0;
    for plan in plans {
        let m = g.mesh();
        if quad_of(g, plan.edge) != Some(plan.quad) {
            continue;
        }
        let [a, b, c, d] = plan.quad.map(|v| Vec3::from(m.position(v)));
        let relying = cov.relying_on(&[[a, b, c], [b, a, d]]);
        if !cov.keeps(&relying, &[[c, d, b], [d, c, a]]) {
            continue;
        }
        let h = m.edge_halfedge(plan.edge);
        if g.try_flip(h).is_ok() {
            flips += 1;
        }
    }
    flips
}

/// The quad of edge `e`: `a → b` (its half-edge), `c` opposite in `a → b`'s face, `d` in the
/// twin's.
fn quad_of(g: &Guard<'_>, e: EdgeId) -> Option<[VertexId; 4]> {
    let m = g.mesh();
    let h = m.edge_halfedge(e);
    let t = m.twin(h);
    m.face(h)?;
    m.face(t)?;
    let c = m.target(m.next(h));
    let d = m.target(m.next(t));
    Some([m.origin(h), m.target(h), c, d])
}

/// Whether flipping `e` lowers the normal deviation by [`FLIP_GAIN`] (module docs).
fn plan_flip(g: &Guard<'_>, e: EdgeId, planes: &InputPlanes<'_>) -> Option<FlipPlan> {
    let quad = quad_of(g, e)?;
    let p = quad.map(|v| Vec3::from(g.mesh().position(v)));
    let [a, b, c, d] = p;
    let before = deviation([a, b, c], planes) + deviation([b, a, d], planes);
    let area = 0.5 * (tri_normal(a, b, c).length() + tri_normal(b, a, d).length());
    if before.is_nan() || before <= FLIP_MIN_DEVIATION * area {
        return None;
    }
    // No fold: both new triangles face the way the quad did.
    let old_normal = tri_normal(a, b, c) + tri_normal(b, a, d);
    if [[c, d, b], [d, c, a]]
        .iter()
        .any(|t| tri_normal(t[0], t[1], t[2]).dot(old_normal) <= 0.0)
    {
        return None;
    }
    let after = deviation([c, d, b], planes) + deviation([d, c, a], planes);
    if after >= FLIP_GAIN * before {
        return None;
    }
    // The drift cap of the placement, at the new edge's midpoint.
    let input = g.input();
    let new_mid = input.distance(((c + d) * 0.5).to_array());
    let allowed = planes
        .drift_cap
        .max(input.distance(((a + b) * 0.5).to_array()));
    (new_mid <= allowed).then_some(FlipPlan { edge: e, quad })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-9
    }

    /// Three orthogonal planes meeting at `(1, 2, 3)`: the minimiser is their corner up to the
    /// Tikhonov term (`μ = 0.03` against weight 1 per axis: 3% of the way back to `p`).
    #[test]
    fn three_planes_place_the_vertex_at_their_corner() {
        let mut q = Quadric::default();
        let corner = Vec3::new(1.0, 2.0, 3.0);
        for n in [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ] {
            q.add(n, corner, 1.0);
        }
        let p = Vec3::new(1.5, 2.5, 3.5);
        let mu = REGULARIZATION * 3.0;
        let expect = (corner + p * mu) * (1.0 / (1.0 + mu));
        assert!(close(q.minimiser(p).unwrap(), expect));
    }

    /// One plane `z = 0`: the vertex moves along the normal only (tangential position kept
    /// exactly), to within the Tikhonov fraction `μ / (1 + μ)` of the plane.
    #[test]
    fn one_plane_moves_along_its_normal_only() {
        let mut q = Quadric::default();
        q.add(Vec3::new(0.0, 0.0, 1.0), Vec3::new(5.0, 5.0, 0.0), 2.0);
        let p = Vec3::new(0.3, -0.7, 1.0);
        let x = q.minimiser(p).unwrap();
        let mu = REGULARIZATION * 2.0;
        assert!(close(x, Vec3::new(0.3, -0.7, mu / (2.0 + mu))), "{x:?}");
        assert!(Quadric::default().minimiser(p).is_none());
    }
}
