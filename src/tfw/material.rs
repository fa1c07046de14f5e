//! Material law of the TFW model: Lamé parameters (eq. A.3), the Saint-Venant–Kirchhoff norm
//! `‖M‖²_SV` (eq. 2.4) and the tension-field relaxed membrane density `W̃` (appendix A.2) as a
//! function of the first fundamental form, with its exact gradient and Hessian.
//!
//! Fundamental forms are symmetric 2×2 matrices in a face's barycentric frame, stored as
//! `[m11, m12, m22]` ([`Form`]).

/// A symmetric 2×2 matrix `[[m11, m12], [m12, m22]]` stored as `[m11, m12, m22]`.
pub type Form = [f64; 3];

/// Lamé parameters in plane stress (eq. A.3): `α = Yν/(1−ν²)`, `β = Y/(2(1+ν))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lame {
    /// First Lamé parameter α (Pa).
    pub alpha: f64,
    /// Second Lamé parameter (shear modulus) β (Pa).
    pub beta: f64,
}

impl Lame {
    /// α and β from Young's modulus `young` (Pa) and Poisson's ratio `poisson` (eq. A.3). The
    /// caller validates `poisson ∈ (−1, 1)`; then β > 0 and α is finite.
    pub fn from_young_poisson(young: f64, poisson: f64) -> Lame {
        Lame {
            alpha: young * poisson / (1.0 - poisson * poisson),
            beta: young / (2.0 * (1.0 + poisson)),
        }
    }

    /// `‖M‖²_SV = α/2 tr(M)² + β tr(M²)` (eq. 2.4) of a general (not necessarily symmetric)
    /// 2×2 matrix `m` (row-major): `tr(M²)`, not `tr(MMᵀ)`, as the spec prescribes.
    pub fn sv_norm2(&self, m: [[f64; 2]; 2]) -> f64 {
        let tr = m[0][0] + m[1][1];
        let tr_m2 = m[0][0] * m[0][0] + 2.0 * m[0][1] * m[1][0] + m[1][1] * m[1][1];
        0.5 * self.alpha * tr * tr + self.beta * tr_m2
    }

    /// The plain StVK density `W_s(λ1, λ2) = α/2 (λ1+λ2)² + β(λ1²+λ2²)` (eq. A.4).
    pub fn stvk_density(&self, l1: f64, l2: f64) -> f64 {
        0.5 * self.alpha * (l1 + l2).powi(2) + self.beta * (l1 * l1 + l2 * l2)
    }

    /// `λ̂2(λ1) = argmin_λ2 W_s(λ1, λ2) = −α λ1/(α+2β)` (A.2).
    pub fn relaxed_lambda2(&self, l1: f64) -> f64 {
        -self.alpha * l1 / (self.alpha + 2.0 * self.beta)
    }

    /// Coefficient `2β(α+β)/(α+2β)` of the wrinkled branch `W̃ = c λ1²` (A.2, reconstructed
    /// from `W_s(λ1, λ̂2(λ1))`).
    pub fn wrinkled_coefficient(&self) -> f64 {
        2.0 * self.beta * (self.alpha + self.beta) / (self.alpha + 2.0 * self.beta)
    }

    /// The relaxed density `W̃(λ1, λ2)` of A.2 (`λ1 ≥ λ2` the principal Green strains) and its
    /// branch: 0 when `λ1 < 0`; `W_s` when `λ2 ≥ λ̂2(λ1)`; `W_s(λ1, λ̂2(λ1))` otherwise.
    pub fn relaxed_density(&self, l1: f64, l2: f64) -> (f64, Branch) {
        let (l1, l2) = if l1 >= l2 { (l1, l2) } else { (l2, l1) };
        if l1 < 0.0 {
            (0.0, Branch::Slack)
        } else if l2 >= self.relaxed_lambda2(l1) {
            (self.stvk_density(l1, l2), Branch::Tension)
        } else {
            (self.wrinkled_coefficient() * l1 * l1, Branch::Wrinkled)
        }
    }
}

/// Which branch of the relaxed density a strain state falls on (A.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Branch {
    /// Both principal strains negative: no stress (`W̃ = 0`).
    Slack,
    /// Pure tension: `W̃ = W_s`.
    Tension,
    /// Tension in one direction, relaxed compression in the other: `W̃ = c λ1²`; wrinkles form.
    Wrinkled,
}

/// The principal Green strains `λ1 ≥ λ2` of `Ī⁻¹I − id` (generalized eigenvalues of
/// `(I − Ī)w = λĪw`, eq. 2.29), from the invariants `t = tr`, `d = det`.
pub fn principal_strains(rest: Form, cur: Form) -> (f64, f64) {
    let (t, d) = strain_invariants(rest, cur);
    let r = (0.25 * t * t - d).max(0.0).sqrt();
    (0.5 * t + r, 0.5 * t - r)
}

fn rest_det(rest: Form) -> f64 {
    rest[0] * rest[2] - rest[1] * rest[1]
}

/// `t = tr(Ī⁻¹I) − 2` and `d = det(I − Ī)/det Ī`: trace and determinant of the strain.
fn strain_invariants(rest: Form, cur: Form) -> (f64, f64) {
    let dr = rest_det(rest);
    let t = (rest[2] * cur[0] - 2.0 * rest[1] * cur[1] + rest[0] * cur[2]) / dr - 2.0;
    let (e0, e1, e2) = (cur[0] - rest[0], cur[1] - rest[1], cur[2] - rest[2]);
    let d = (e0 * e2 - e1 * e1) / dr;
    (t, d)
}

/// `W̃` as a function of the current form `I = [p0, p1, p2]` at rest form `Ī`, with its exact
/// gradient and Hessian in `(p0, p1, p2)` and the branch. The density is convex and
/// nondecreasing (Loewner order) in `I` (Pipkin 1986), so the Hessian is positive
/// semidefinite and the gradient, read as the matrix `[[g0, g1/2], [g1/2, g2]]`, is too.
pub fn relaxed_density_in_form(lame: &Lame, rest: Form, cur: Form) -> FormDensity {
    let dr = rest_det(rest);
    let (t, d) = strain_invariants(rest, cur);
    let gt = [rest[2] / dr, -2.0 * rest[1] / dr, rest[0] / dr];
    let gd = [
        (cur[2] - rest[2]) / dr,
        -2.0 * (cur[1] - rest[1]) / dr,
        (cur[0] - rest[0]) / dr,
    ];
    let hd = [
        [0.0, 0.0, 1.0 / dr],
        [0.0, -2.0 / dr, 0.0],
        [1.0 / dr, 0.0, 0.0],
    ];
    let r = (0.25 * t * t - d).max(0.0).sqrt();
    let (l1, l2) = (0.5 * t + r, 0.5 * t - r);
    let (value, branch) = lame.relaxed_density(l1, l2);
    // φ(t, d) and its first and second partial derivatives.
    let (pt, pd, ptt, ptd, pdd) = match branch {
        Branch::Slack => (0.0, 0.0, 0.0, 0.0, 0.0),
        Branch::Tension => {
            // W_s = (α/2 + β) t² − 2β d
            let a = 0.5 * lame.alpha + lame.beta;
            (2.0 * a * t, -2.0 * lame.beta, 2.0 * a, 0.0, 0.0)
        }
        Branch::Wrinkled => {
            // c λ1², λ1 = t/2 + √(t²/4 − d); r > 0 on this branch (λ1 ≥ 0 > λ̂2 > λ2 or
            // λ1 = 0 > λ2).
            let c = lame.wrinkled_coefficient();
            let r = r.max(f64::MIN_POSITIVE);
            let l_t = 0.5 + t / (4.0 * r);
            let l_d = -0.5 / r;
            let r3 = r * r * r;
            let l_tt = 0.25 / r - t * t / (16.0 * r3);
            let l_td = t / (8.0 * r3);
            let l_dd = -0.25 / r3;
            (
                2.0 * c * l1 * l_t,
                2.0 * c * l1 * l_d,
                2.0 * c * (l_t * l_t + l1 * l_tt),
                2.0 * c * (l_t * l_d + l1 * l_td),
                2.0 * c * (l_d * l_d + l1 * l_dd),
            )
        }
    };
    let mut grad = [0.0; 3];
    let mut hess = [[0.0; 3]; 3];
    for i in 0..3 {
        grad[i] = pt * gt[i] + pd * gd[i];
        for j in 0..3 {
            hess[i][j] = ptt * gt[i] * gt[j]
                + ptd * (gt[i] * gd[j] + gd[i] * gt[j])
                + pdd * gd[i] * gd[j]
                + pd * hd[i][j];
        }
    }
    FormDensity {
        value,
        grad,
        hess,
        branch,
        strains: (l1, l2),
    }
}

/// Value, gradient and Hessian of a density as a function of a [`Form`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FormDensity {
    /// The density value.
    pub value: f64,
    /// Gradient with respect to `(p0, p1, p2)` of `I = [[p0, p1], [p1, p2]]`.
    pub grad: [f64; 3],
    /// Hessian with respect to `(p0, p1, p2)`.
    pub hess: [[f64; 3]; 3],
    /// The branch of A.2 the state falls on.
    pub branch: Branch,
    /// The principal strains `(λ1, λ2)`, `λ1 ≥ λ2`.
    pub strains: (f64, f64),
}
