//! Krylov methods on plain `f64` slices: the N-dimensional dot product [`dot_n`] and the
//! Steihaug–Toint truncated conjugate gradient method for trust-region subproblems
//! ([`steihaug`]; Steihaug 1983; Nocedal & Wright, *Numerical Optimization*, Alg. 7.2, with the
//! `M`-norm recurrences of Gould, Lucidi, Roma & Toint 1999).

/// Euclidean dot product `Σ a_i b_i` of two N-dimensional vectors (summed in index order).
/// Not the 3-vector dot: that is `geom::Vec3::dot`.
pub fn dot_n(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// What [`steihaug`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct TrustStep {
    /// The step `s`.
    pub step: Vec<f64>,
    /// `‖s‖_M`.
    pub m_norm: f64,
    /// The step ends on the trust-region boundary (negative curvature or a long step).
    pub on_boundary: bool,
    /// CG iterations done.
    pub iterations: usize,
}

/// Approximately minimizes `gᵀs + ½ sᵀHs` subject to `‖s‖_M ≤ Δ` by Steihaug–Toint CG
/// preconditioned with `M` (`precond` applies `M⁻¹`, `hess` applies `H`). Stops when the
/// model's gradient `‖g + Hs‖₂ ≤ tol`, at the boundary, on negative curvature (followed to the
/// boundary), or after `max_iter` iterations. The returned step always decreases the model
/// unless `g = 0`.
pub fn steihaug(
    g: &[f64],
    hess: &dyn Fn(&[f64], &mut [f64]),
    precond: &dyn Fn(&[f64]) -> Vec<f64>,
    delta: f64,
    tol: f64,
    max_iter: usize,
) -> TrustStep {
    steihaug_with_stop(g, hess, precond, delta, tol, max_iter, &mut |_| false)
        .expect("never stopped")
}

/// [`steihaug`] with `stop(iteration)` asked before each CG iteration after the first
/// (a cancellation point for callers with a progress callback); `None` as soon as it answers
/// `true`. When it never does, the same step as [`steihaug`].
pub fn steihaug_with_stop(
    g: &[f64],
    hess: &dyn Fn(&[f64], &mut [f64]),
    precond: &dyn Fn(&[f64]) -> Vec<f64>,
    delta: f64,
    tol: f64,
    max_iter: usize,
    stop: &mut dyn FnMut(usize) -> bool,
) -> Option<TrustStep> {
    let n = g.len();
    let mut s = vec![0.0; n];
    let mut r = g.to_vec();
    let mut y = precond(&r);
    let mut d: Vec<f64> = y.iter().map(|v| -v).collect();
    let mut ry = dot_n(&r, &y);
    // M-norm recurrences: ⟨s,Ms⟩, ⟨s,Md⟩, ⟨d,Md⟩
    let (mut sms, mut smd, mut dmd) = (0.0, 0.0, ry);
    let mut hd = vec![0.0; n];
    let to_boundary = |s: &mut Vec<f64>, d: &[f64], sms: f64, smd: f64, dmd: f64| {
        // τ ≥ 0 with ‖s + τ d‖_M = Δ
        let disc = (smd * smd + dmd * (delta * delta - sms)).max(0.0);
        let tau = if dmd > 0.0 {
            (-smd + disc.sqrt()) / dmd
        } else {
            0.0
        };
        for (si, di) in s.iter_mut().zip(d) {
            *si += tau * di;
        }
    };
    if dot_n(&r, &r).sqrt() <= tol || ry <= 0.0 {
        return Some(TrustStep {
            step: s,
            m_norm: 0.0,
            on_boundary: false,
            iterations: 0,
        });
    }
    for it in 0..max_iter {
        if it > 0 && stop(it) {
            return None;
        }
        hess(&d, &mut hd);
        let dhd = dot_n(&d, &hd);
        // negative curvature (followed to the boundary) or a step leaving the region
        let alpha = ry / dhd;
        let sms_next = sms + 2.0 * alpha * smd + alpha * alpha * dmd;
        if dhd.is_nan() || dhd <= 0.0 || sms_next >= delta * delta {
            to_boundary(&mut s, &d, sms, smd, dmd);
            return Some(TrustStep {
                step: s,
                m_norm: delta,
                on_boundary: true,
                iterations: it + 1,
            });
        }
        for i in 0..n {
            s[i] += alpha * d[i];
            r[i] += alpha * hd[i];
        }
        if dot_n(&r, &r).sqrt() <= tol {
            return Some(TrustStep {
                step: s,
                m_norm: sms_next.sqrt(),
                on_boundary: false,
                iterations: it + 1,
            });
        }
        y = precond(&r);
        let ry_next = dot_n(&r, &y);
        let beta = ry_next / ry;
        ry = ry_next;
        smd = beta * (smd + alpha * dmd);
        dmd = ry + beta * beta * dmd;
        sms = sms_next;
        for i in 0..n {
            d[i] = -y[i] + beta * d[i];
        }
    }
    Some(TrustStep {
        step: s,
        m_norm: sms.sqrt(),
        on_boundary: false,
        iterations: max_iter,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-D Laplacian-like SPD system: unconstrained CG (huge Δ) solves it; a small Δ stops on
    /// the boundary with ‖s‖_M = Δ.
    #[test]
    fn steihaug_solves_spd_and_respects_radius() {
        let n = 20;
        let hess = |v: &[f64], y: &mut [f64]| {
            for i in 0..n {
                y[i] = 3.0 * v[i]
                    - if i > 0 { v[i - 1] } else { 0.0 }
                    - if i + 1 < n { v[i + 1] } else { 0.0 };
            }
        };
        let pre = |r: &[f64]| r.iter().map(|x| x / 3.0).collect::<Vec<_>>();
        let g: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let st = steihaug(&g, &hess, &pre, 1e9, 1e-12, 200);
        assert!(!st.on_boundary);
        let mut hs = vec![0.0; n];
        hess(&st.step, &mut hs);
        let res: f64 = hs.iter().zip(&g).map(|(a, b)| (a + b).powi(2)).sum::<f64>();
        assert!(res.sqrt() < 1e-10, "residual {res}");
        let small = steihaug(&g, &hess, &pre, 0.1, 1e-12, 200);
        assert!(small.on_boundary);
        let mnorm = (small.step.iter().map(|x| 3.0 * x * x).sum::<f64>()).sqrt();
        assert!((mnorm - 0.1).abs() < 1e-9, "‖s‖_M = {mnorm}");
    }

    /// On an indefinite model CG follows the negative-curvature direction to the boundary and
    /// the model decreases.
    #[test]
    fn steihaug_follows_negative_curvature() {
        let hess = |v: &[f64], y: &mut [f64]| {
            y[0] = -v[0];
            y[1] = 2.0 * v[1];
        };
        let pre = |r: &[f64]| r.to_vec();
        let g = [0.5, 1.0];
        let st = steihaug(&g, &hess, &pre, 2.0, 1e-12, 10);
        assert!(st.on_boundary);
        let s = &st.step;
        let model = g[0] * s[0] + g[1] * s[1] + 0.5 * (-s[0] * s[0] + 2.0 * s[1] * s[1]);
        assert!(model < -0.5, "model {model}");
        assert!(((s[0] * s[0] + s[1] * s[1]).sqrt() - 2.0).abs() < 1e-9);
    }
}
