//! Small linear-system helpers shared by wrinkle design ([`design`](super::design)) and editing
//! ([`edit`](super::edit)): one SPD solve by faer's sparse Cholesky with its relative residual,
//! complex Hermitian entries in the interleaved real form of [`knoppel`](super::knoppel), and
//! the product with a fully stored sparse matrix.

use super::complex::Complex;
use crate::solve::{
    assemble, run_stoppable, sym_matvec_lower_into, Cholesky, CholeskyAnalysis, Entry, LltError,
    Parallelism, ShiftSchedule, SparseMatrix,
};
use crate::{Error, Result};

/// Solves `N x = b` for a symmetric positive (semi-)definite `N` given by its lower-triangle
/// `entries` (duplicates summed). A numerically singular `N` gets the smallest diagonal shift
/// `σ = 1e-12·max N_ii · 100^k` that factors. Returns `x` and the relative residual
/// The factorization of `a`, or of `a + σI` with the smallest `σ = 1e-12·max a_ii · 100^k`
/// (k < 6) that factors when `a` is numerically singular.
fn factor_or_shift(
    an: &CholeskyAnalysis,
    a: &SparseMatrix,
) -> std::result::Result<Cholesky, LltError> {
    an.factor(a, Parallelism::Global).or_else(|_| {
        let max_diag = diagonal(a).into_iter().fold(0.0, f64::max).max(1e-300);
        let schedule = ShiftSchedule {
            initial: 1e-12 * max_diag,
            growth: 100.0,
            max_attempts: 6,
        };
        an.factor_with_growing_shift(a, &vec![1.0; a.ncols()], schedule, Parallelism::Global)
    })
}

/// `‖N x − b‖ / ‖b‖` (0 when `b = 0`). `what` names the system in errors.
pub(crate) fn solve_spd(
    dim: usize,
    entries: &[Entry],
    rhs: &[f64],
    what: &str,
) -> Result<(Vec<f64>, f64)> {
    solve_spd_with_tick(dim, entries, rhs, what, &mut || Ok(()))
}

/// [`solve_spd`] with `tick` as a cancellation point (its error returned as is) every 0.1 s
/// of a large factorization ([`run_stoppable`]); the same result.
pub(crate) fn solve_spd_with_tick(
    dim: usize,
    entries: &[Entry],
    rhs: &[f64],
    what: &str,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<(Vec<f64>, f64)> {
    let mut x = solve_spd_many_with_tick(dim, entries, &[rhs], what, tick)?;
    Ok(x.pop().expect("one right-hand side"))
}

/// [`solve_spd`] for several right-hand sides on one factorization (each result as
/// [`solve_spd`] would give it, bit for bit), with `tick` as a cancellation point (its error
/// returned as is) after the analysis and every 0.1 s of a large factorization
/// ([`run_stoppable`]); the same results.
pub(crate) fn solve_spd_many_with_tick(
    dim: usize,
    entries: &[Entry],
    rhs: &[&[f64]],
    what: &str,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<Vec<(Vec<f64>, f64)>> {
    if dim == 0 {
        return Ok(rhs.iter().map(|_| (Vec::new(), 0.0)).collect());
    }
    let a = std::sync::Arc::new(assemble(dim, entries, what)?);
    let an = CholeskyAnalysis::new_stoppable(&a, tick)?;
    let heavy = an.is_heavy();
    if heavy {
        tick()?;
    }
    let shared = a.clone();
    let llt = run_stoppable(heavy, move || factor_or_shift(&an, &shared), tick)?.map_err(|_| {
        Error::Numerical(format!(
            "{what} is not positive definite (degenerate mesh?)"
        ))
    })?;
    rhs.iter()
        .map(|b| {
            let x = llt.solve(b);
            if !x.iter().all(|v| v.is_finite()) {
                return Err(Error::Numerical(format!("{what}: the solve is not finite")));
            }
            let residual = relative_residual(&a, &x, b);
            Ok((x, residual))
        })
        .collect()
}

/// `‖N x − b‖ / ‖b‖` (`‖N x‖` when `b = 0`) for `N` stored as its lower triangle.
fn relative_residual(a: &SparseMatrix, x: &[f64], b: &[f64]) -> f64 {
    let mut nx = vec![0.0; x.len()];
    sym_matvec_lower_into(a, x, &mut nx);
    let num = nx
        .iter()
        .zip(b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt();
    let den = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    if den > 0.0 {
        num / den
    } else {
        num
    }
}

/// The diagonal of a square sparse matrix.
fn diagonal(a: &SparseMatrix) -> Vec<f64> {
    let cp = a.symbolic().col_ptr();
    let ri = a.symbolic().row_idx();
    (0..a.ncols())
        .map(|j| {
            (cp[j]..cp[j + 1])
                .filter(|&k| ri[k] == j)
                .map(|k| a.val()[k])
                .sum()
        })
        .collect()
}

/// Pushes the lower-triangle entries of the symmetric outer product `g gᵀ` of a sparse row
/// `g` (`(index, value)` pairs, indices distinct): the normal-equation contribution of one
/// least-squares row.
pub(crate) fn push_outer_lower(t: &mut Vec<Entry>, g: &[(usize, f64)]) {
    for &(i, gi) in g {
        for &(j, gj) in g {
            if i >= j {
                t.push(Entry::new(i, j, gi * gj));
            }
        }
    }
}

/// Pushes the complex entry `h` at `(r, c)` and, off the diagonal, `h̄` at `(c, r)` of a
/// Hermitian matrix in the interleaved real form (block `[[re, −im], [im, re]]`), full storage.
pub(crate) fn push_hermitian(t: &mut Vec<Entry>, r: usize, c: usize, h: Complex) {
    let block = |t: &mut Vec<Entry>, r: usize, c: usize, h: Complex| {
        for (p, q, v) in [(0, 0, h.re), (0, 1, -h.im), (1, 0, h.im), (1, 1, h.re)] {
            if v != 0.0 || p == q {
                t.push(Entry::new(2 * r + p, 2 * c + q, v));
            }
        }
    };
    block(t, r, c, h);
    if r != c {
        block(t, c, r, h.conj());
    }
}

/// `y = A v` for a fully stored sparse `A`.
pub(crate) fn matvec_full(a: &SparseMatrix, v: &[f64]) -> Vec<f64> {
    let cp = a.symbolic().col_ptr();
    let ri = a.symbolic().row_idx();
    let val = a.val();
    let mut y = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        for k in cp[j]..cp[j + 1] {
            y[ri[k]] += val[k] * v[j];
        }
    }
    y
}
