//! Feature alignment — dissertation Alg. 6 and eq. 4.4–4.5 (§4.3.2 "Feature Alignment").
//!
//! After the flow, each vertex `v` is moved to the minimiser of
//! `E(v) = Σ_{f ∈ N¹(v)} ‖ n_f(v) / c_f − ñ_f / ‖ñ_f‖ ‖²` (eq. 4.5), where `n_f` is the
//! unnormalised normal of face `f` of the current mesh, `c_f = ‖n_f‖` frozen at its current
//! value (Alg. 6 line 3), and `ñ_f` the normal of the same face before the flow (`M̃`).
//!
//! Derivation of the quadratic (the text only names it): for face `f = (v, b, c)` in
//! counter-clockwise order, `n_f = (b − v) × (c − v) = b × c + v × (b − c) = b × c − [e]ₓ v`
//! with `e = b − c`, linear in `v`. With `A_f = −[e]ₓ / c_f` and `y_f = ñ̂_f − (b × c)/c_f`,
//! `E = Σ ‖A_f v − y_f‖²`, whose normal equations are
//! `Σ (|e|² I − e eᵀ)/c_f² · v = Σ (e × y_f) / c_f` (using `[e]ₓᵀ = −[e]ₓ`). The 3×3 system is
//! solved directly (with a tiny Tikhonov term for rings whose edges are all parallel); the
//! step `v_opt − v` is clamped to `max_step` and applied with the line search of Alg. 4.
//!
//! Drift cap (not in the text): eq. 4.5 sees only normals, so it does not anchor a vertex to
//! the input — on developable or nearly flat rings its optimum can slide, and a vertex whose
//! flow step the guard keeps refusing can be walked away round after round (the teapot's
//! inner wall drifted 8·d over rounds 35–50 before this). A step may therefore not take the
//! vertex farther from the input than `max(cap, its current distance)`; a longer step is
//! halved until it does (at most [`CAP_HALVINGS`] times), else the vertex stays.

use super::flow::{local_update, record, MoveReport};
use super::guard::Guard;
use crate::geom::{normalized, tri_normal, Vec3};
use crate::mesh::halfedge::{FaceData, VertexId};
use crate::{Error, Result};

/// Unit normals of the live faces of the guard's mesh, indexed by face id (`[0; 3]` for
/// deleted or degenerate faces): `ñ_f / ‖ñ_f‖` of `M̃`, taken before the flow.
pub(crate) fn reference_normals(g: &Guard<'_>) -> FaceData<Vec3> {
    let m = g.mesh();
    let mut n = FaceData::filled(m.face_capacity(), Vec3::ZERO);
    for f in m.faces() {
        n[f] = normalized(m.face_area_vector(f)).unwrap_or(Vec3::ZERO);
    }
    n
}

/// The minimiser of eq. 4.5 for vertex `v`, or `None` when the ring is degenerate.
pub(crate) fn aligned_position(
    g: &Guard<'_>,
    v: VertexId,
    reference: &FaceData<Vec3>,
) -> Option<Vec3> {
    let m = g.mesh();
    let pv = Vec3::from(m.position(v));
    let mut h = [[0.0f64; 3]; 3];
    let mut rhs = Vec3::ZERO;
    let mut any = false;
    for out in m.outgoing(v) {
        let Some(f) = m.face(out) else { continue };
        let b = Vec3::from(m.position(m.target(out)));
        let c = Vec3::from(m.position(m.target(m.next(out))));
        let cf = tri_normal(pv, b, c).length();
        let t = reference[f];
        if cf.is_nan() || cf <= 0.0 || t == Vec3::ZERO {
            continue;
        }
        any = true;
        let e = b - c;
        let ee = e.dot(e);
        let w = 1.0 / (cf * cf);
        for (i, row) in h.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                let id = if i == j { ee } else { 0.0 };
                *x += w * (id - e[i] * e[j]);
            }
        }
        let y = t - b.cross(c) * (1.0 / cf);
        rhs += e.cross(y) * (1.0 / cf);
    }
    if !any {
        return None;
    }
    let tr = h[0][0] + h[1][1] + h[2][2];
    for (i, row) in h.iter_mut().enumerate() {
        row[i] += 1e-9 * tr;
    }
    solve3(h, rhs)
}

/// Solves the 3×3 system `h x = r` by Cramer's rule; `None` when singular or non-finite.
pub(crate) fn solve3(h: [[f64; 3]; 3], r: Vec3) -> Option<Vec3> {
    let det3 = |m: [[f64; 3]; 3]| {
        let [r0, r1, r2] = m.map(Vec3::from);
        r0.dot(r1.cross(r2))
    };
    let d = det3(h);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut m = h;
        for (row, rv) in m.iter_mut().zip(r.to_array()) {
            row[k] = rv;
        }
        *xk = det3(m) / d;
    }
    x.iter().all(|c| c.is_finite()).then_some(Vec3::from(x))
}

/// Halvings of an alignment step that would end farther from the input than the drift cap.
pub const CAP_HALVINGS: u32 = 4;

/// Shortens `d` (halving) until `p + d` is within `max(cap, dist(p))` of the input; `None`
/// when [`CAP_HALVINGS`] halvings do not suffice.
pub(crate) fn capped_step(g: &Guard<'_>, p: Vec3, mut d: Vec3, cap: f64) -> Option<Vec3> {
    let input = g.input();
    // The allowance grows to the current distance only when the cap alone refuses a step.
    let mut allowed = None;
    for _ in 0..=CAP_HALVINGS {
        let dn = input.distance((p + d).to_array());
        if dn <= cap || dn <= *allowed.get_or_insert_with(|| cap.max(input.distance(p.to_array())))
        {
            return Some(d);
        }
        d *= 0.5;
    }
    None
}

/// One alignment sweep (Alg. 3 lines 12–16): every vertex in id order towards its eq. 4.5
/// optimum, step length at most `max_step`, through the guarded line search; no step ends
/// farther than `max(cap, current distance)` from the input (module docs).
pub(crate) fn align_sweep(
    g: &mut Guard<'_>,
    reference: &FaceData<Vec3>,
    max_step: f64,
    cap: f64,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<MoveReport> {
    let verts: Vec<VertexId> = g
        .mesh()
        .vertices()
        .filter(|&v| g.mesh().vertex_halfedge(v).is_some())
        .collect();
    let mut rep = MoveReport::default();
    for (i, &v) in verts.iter().enumerate() {
        if i % 1024 == 0 && !keep_going(i as f64 / verts.len() as f64) {
            return Err(Error::Cancelled);
        }
        let Some(opt) = aligned_position(g, v, reference) else {
            rep.stuck += 1;
            continue;
        };
        let mut d = opt - Vec3::from(g.mesh().position(v));
        let len = d.length();
        if len > max_step {
            d *= max_step / len;
        }
        let step = if len > 0.0 {
            capped_step(g, g.mesh().position(v).into(), d, cap)
        } else {
            None
        };
        let moved = step.map_or(0.0, |d| local_update(g, v, d));
        record(&mut rep, moved);
    }
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lowpoly::guard::tests::cube;
    use crate::lowpoly::guard::InputModel;
    use crate::mesh::halfedge::HalfEdgeMesh;

    /// The drift cap against distances known in closed form, around the unit cube's top face
    /// (`z = 1`) with cap `0.31`: from `z = 1.1`, a step to `z = 1.5` is halved once (to
    /// `z = 1.3`), a step to `z = 1.15` and a sideways step along the face pass unchanged;
    /// from `z = 1.6` (already beyond the cap) a step away is refused and a step back passes.
    #[test]
    fn capped_step_keeps_vertices_within_the_cap_or_their_distance() {
        let m = cube(1.0, 0.0);
        let input = InputModel::new(&m, false);
        let g = Guard::new(HalfEdgeMesh::from_trimesh(&m).unwrap(), &input, false);
        let v = Vec3::new;
        let close = |a: Vec3, b: Vec3| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12);
        let p = v(0.5, 0.5, 1.1);
        let cap = 0.31;
        let d = capped_step(&g, p, v(0.0, 0.0, 0.4), cap).unwrap();
        assert!(close(d, v(0.0, 0.0, 0.2)), "{d:?}");
        let d = capped_step(&g, p, v(0.0, 0.0, 0.05), cap).unwrap();
        assert!(close(d, v(0.0, 0.0, 0.05)), "{d:?}");
        let d = capped_step(&g, p, v(0.3, 0.0, 0.0), cap).unwrap();
        assert!(close(d, v(0.3, 0.0, 0.0)), "{d:?}");
        assert!(capped_step(&g, v(0.5, 0.5, 1.6), v(0.0, 0.0, 0.1), cap).is_none());
        let d = capped_step(&g, v(0.5, 0.5, 1.6), v(0.0, 0.0, -0.1), cap).unwrap();
        assert!(close(d, v(0.0, 0.0, -0.1)), "{d:?}");
    }
}
