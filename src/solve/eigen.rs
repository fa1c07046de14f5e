//! Inverse iteration for the smallest eigenpair of a generalized symmetric problem
//! `A u = λ B u` with `B` diagonal positive, on a cached factorization of the shifted matrix
//! `A + σB` ([`inverse_iteration`]).
//!
//! The problem may be block diagonal: unknowns are split into `groups` (e.g. the connected
//! components of a mesh) that `A` does not couple. Each group is normalized on its own, so each
//! gets its own smallest eigenvector instead of the iteration decaying towards the group with the
//! smallest eigenvalue; one solve per step serves all groups.

use std::fmt;

use super::sparse::Cholesky;

/// Parameters of [`inverse_iteration`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InverseIterationParams {
    /// Maximum steps (at least one is taken); default 200.
    pub max_iterations: usize,
    /// Stop when the relative residual `‖A u − λ B u‖_{B⁻¹} / scale` falls below this, or (after
    /// the third step) the largest change of a Rayleigh quotient, relative to `scale`, falls
    /// below `tolerance · 1e-3`; default 1e-12.
    pub tolerance: f64,
}

impl Default for InverseIterationParams {
    fn default() -> Self {
        InverseIterationParams {
            max_iterations: 200,
            tolerance: 1e-12,
        }
    }
}

/// What [`inverse_iteration`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct InverseIterationInfo {
    /// Per group, the Rayleigh quotient `uᵀAu / uᵀBu` of the final vector.
    pub eigenvalues: Vec<f64>,
    /// Steps taken (≥ 1).
    pub iterations: usize,
    /// Final residual `‖A u − λ B u‖_{B⁻¹} / scale` (each group with its own `λ`, `u`
    /// B-normalized per group).
    pub residual: f64,
    /// True when a stopping test of [`InverseIterationParams::tolerance`] was met; false when
    /// [`InverseIterationParams::max_iterations`] ran out first (the vector is still returned).
    pub converged: bool,
}

/// Why [`inverse_iteration`] failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InverseIterationError {
    /// A solve produced a NaN or infinite entry (the shifted matrix is numerically singular).
    NonFinite {
        /// The step at which it happened (1-based).
        iteration: usize,
        /// The residual after the previous step (∞ at the first).
        residual: f64,
    },
}

impl fmt::Display for InverseIterationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InverseIterationError::NonFinite { .. } => {
                write!(f, "inverse iteration produced a non-finite vector")
            }
        }
    }
}

impl std::error::Error for InverseIterationError {}

impl From<InverseIterationError> for crate::Error {
    fn from(e: InverseIterationError) -> crate::Error {
        crate::Error::Numerical(e.to_string())
    }
}

/// The generalized problem `A u = λ B u` that [`inverse_iteration`] solves.
pub struct ShiftedProblem<'a, F: Fn(&[f64]) -> Vec<f64>> {
    /// The factorization of `A + σB` for a shift σ that makes it positive definite.
    pub shifted: &'a Cholesky,
    /// `u ↦ A u`.
    pub apply_a: F,
    /// The diagonal of `B` (positive), one entry per unknown.
    pub mass: &'a [f64],
    /// The group of each unknown (`0..n_groups`); `A` must not couple different groups.
    pub groups: &'a [u32],
    /// Number of groups.
    pub n_groups: usize,
    /// The scale of the eigenvalues (e.g. `max_i A_ii / B_ii`) the residual and the change of
    /// the Rayleigh quotients are measured against.
    pub scale: f64,
}

/// Inverse iteration `(A + σB) u_{k+1} = B u_k` from `start`, each group B-normalized after
/// every step. Returns the final vector (B-normalized per group) and what was done; an error
/// when a step produced a non-finite vector. Non-convergence is reported in
/// [`InverseIterationInfo::converged`], not as an error.
pub fn inverse_iteration<F: Fn(&[f64]) -> Vec<f64>>(
    problem: &ShiftedProblem<'_, F>,
    start: Vec<f64>,
    params: &InverseIterationParams,
) -> Result<(Vec<f64>, InverseIterationInfo), InverseIterationError> {
    inverse_iteration_with_stop(problem, start, params, &mut |_| false).expect("never stopped")
}

/// [`inverse_iteration`] with a cancellation point: `stop(it)` runs before step `it` (from the
/// second step on) and `None` is returned as soon as it answers `true`. When it never does,
/// the result is that of [`inverse_iteration`], bit for bit.
pub fn inverse_iteration_with_stop<F: Fn(&[f64]) -> Vec<f64>>(
    problem: &ShiftedProblem<'_, F>,
    start: Vec<f64>,
    params: &InverseIterationParams,
    stop: &mut dyn FnMut(usize) -> bool,
) -> Option<Result<(Vec<f64>, InverseIterationInfo), InverseIterationError>> {
    let p = problem;
    let mut u = start;
    normalize_b(&mut u, p);
    let mut lambda = vec![f64::INFINITY; p.n_groups];
    let mut info = InverseIterationInfo {
        eigenvalues: lambda.clone(),
        iterations: 0,
        residual: f64::INFINITY,
        converged: false,
    };
    for it in 1..=params.max_iterations.max(1) {
        if it > 1 && stop(it) {
            return None;
        }
        let rhs: Vec<f64> = u.iter().zip(p.mass).map(|(v, m)| m * v).collect();
        u = p.shifted.solve(&rhs);
        if !u.iter().all(|v| v.is_finite()) {
            return Some(Err(InverseIterationError::NonFinite {
                iteration: it,
                residual: info.residual,
            }));
        }
        normalize_b(&mut u, p);
        let au = (p.apply_a)(&u);
        let new_lambda = rayleigh_quotients(&u, &au, p);
        let residual = residual_b(&au, &u, &new_lambda, p) / p.scale;
        let change = new_lambda
            .iter()
            .zip(&lambda)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / p.scale;
        lambda = new_lambda;
        let converged = residual < params.tolerance || (change < params.tolerance * 1e-3 && it > 2);
        info = InverseIterationInfo {
            eigenvalues: lambda.clone(),
            iterations: it,
            residual,
            converged,
        };
        if converged {
            break;
        }
    }
    Some(Ok((u, info)))
}

/// Scales each group of `u` to unit B-norm (a group of norm 0 is left as it is).
fn normalize_b<F: Fn(&[f64]) -> Vec<f64>>(u: &mut [f64], p: &ShiftedProblem<'_, F>) {
    let mut n2 = vec![0.0; p.n_groups];
    for (i, v) in u.iter().enumerate() {
        n2[p.groups[i] as usize] += p.mass[i] * v * v;
    }
    let s: Vec<f64> = n2.iter().map(|x| 1.0 / x.sqrt()).collect();
    for (i, v) in u.iter_mut().enumerate() {
        let f = s[p.groups[i] as usize];
        if f.is_finite() {
            *v *= f;
        }
    }
}

/// Per group, `u_gᵀ A u_g` (u is B-normalized per group).
fn rayleigh_quotients<F: Fn(&[f64]) -> Vec<f64>>(
    u: &[f64],
    au: &[f64],
    p: &ShiftedProblem<'_, F>,
) -> Vec<f64> {
    let mut q = vec![0.0; p.n_groups];
    for (i, (a, b)) in u.iter().zip(au).enumerate() {
        q[p.groups[i] as usize] += a * b;
    }
    q
}

/// `‖A u − λ B u‖_{B⁻¹}` with each group's own `λ`.
fn residual_b<F: Fn(&[f64]) -> Vec<f64>>(
    au: &[f64],
    u: &[f64],
    lambda: &[f64],
    p: &ShiftedProblem<'_, F>,
) -> f64 {
    au.iter()
        .zip(u)
        .enumerate()
        .map(|(i, (l, v))| {
            let r = l - lambda[p.groups[i] as usize] * p.mass[i] * v;
            r * r / p.mass[i]
        })
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::super::sparse::{assemble, CholeskyAnalysis, Entry, Parallelism};
    use super::*;

    #[test]
    fn smallest_eigenpair_of_two_decoupled_blocks() {
        // two 1-D Neumann Laplacians (smallest eigenvalue 0, constant eigenvector), B = I
        let n = 10;
        let mut t = Vec::new();
        for b in 0..2 {
            for i in 0..n {
                let deg = if i == 0 || i + 1 == n { 1.0 } else { 2.0 };
                t.push(Entry::new(b * n + i, b * n + i, deg));
                if i + 1 < n {
                    t.push(Entry::new(b * n + i + 1, b * n + i, -1.0));
                }
            }
        }
        let a = assemble(2 * n, &t, "a test matrix").unwrap();
        let an = CholeskyAnalysis::new(&a).unwrap();
        let mass = vec![1.0; 2 * n];
        let f = an
            .factor_shifted(&a, 1e-6, &mass, Parallelism::Global)
            .unwrap();
        let apply = |u: &[f64]| {
            (0..2 * n)
                .map(|i| {
                    let j = i % n;
                    let mut y = 0.0;
                    if j > 0 {
                        y += u[i] - u[i - 1];
                    }
                    if j + 1 < n {
                        y += u[i] - u[i + 1];
                    }
                    y
                })
                .collect()
        };
        let groups: Vec<u32> = (0..2 * n).map(|i| (i / n) as u32).collect();
        let problem = ShiftedProblem {
            shifted: &f,
            apply_a: apply,
            mass: &mass,
            groups: &groups,
            n_groups: 2,
            scale: 4.0,
        };
        let start: Vec<f64> = (0..2 * n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
        let (u, info) =
            inverse_iteration(&problem, start, &InverseIterationParams::default()).unwrap();
        assert!(info.converged, "{info:?}");
        assert!(info.eigenvalues.iter().all(|l| l.abs() < 1e-10), "{info:?}");
        let want = 1.0 / (n as f64).sqrt();
        assert!(u.iter().all(|v| (v.abs() - want).abs() < 1e-6), "{u:?}");
    }
}
