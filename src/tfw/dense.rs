//! Small dense symmetric matrices (per-face Hessian blocks): projection onto the positive
//! semidefinite cone by cyclic Jacobi eigen-decomposition.

/// Replaces the symmetric `N×N` matrix `a` by its projection onto the PSD cone (negative
/// eigenvalues clamped to 0), `V max(Λ, 0) Vᵀ`. Cyclic Jacobi: accurate to rounding for the
/// 9×9 blocks it is used on (stops when the off-diagonal norm is ≤ 1e-13 ‖A‖_F or stops
/// decreasing); at most 50 sweeps.
#[allow(clippy::needless_range_loop)] // rotations index two rows and columns at once
pub fn project_psd<const N: usize>(a: &mut [[f64; N]; N]) {
    let mut m = *a;
    let mut v = [[0.0; N]; N];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let scale: f64 = m.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    if scale == 0.0 {
        return;
    }
    let mut last_off = f64::INFINITY;
    for _sweep in 0..50 {
        let off: f64 = (0..N)
            .flat_map(|i| (0..N).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i][j] * m[i][j])
            .sum();
        // converged to rounding (the off-diagonal left by a sweep is ≈ 8 ε ‖A‖ for 9×9, so
        // the former 1e-15 was never met and every block ran all 50 sweeps: ≈ 0.2 ms per 9×9
        // pressure block, most of the balloons' base solve; measured 2026-11-27), or stalled
        if off.sqrt() <= 1e-13 * scale || off >= last_off {
            break;
        }
        last_off = off;
        for p in 0..N {
            for q in p + 1..N {
                if m[p][q].abs() <= 1e-300 {
                    continue;
                }
                let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in m.iter_mut() {
                    let (mp, mq) = (row[p], row[q]);
                    row[p] = c * mp - s * mq;
                    row[q] = s * mp + c * mq;
                }
                for k in 0..N {
                    let (mp, mq) = (m[p][k], m[q][k]);
                    m[p][k] = c * mp - s * mq;
                    m[q][k] = s * mp + c * mq;
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    let lam: [f64; N] = std::array::from_fn(|k| m[k][k].max(0.0));
    for i in 0..N {
        for j in 0..N {
            a[i][j] = (0..N).map(|k| v[i][k] * lam[k] * v[j][k]).sum();
        }
    }
}

/// True when the symmetric `N×N` matrix `a` is positive definite: its Cholesky
/// factorization (lower triangle read) meets only positive, finite pivots.
#[allow(clippy::needless_range_loop)] // the factor is indexed by row and column
pub fn is_positive_definite<const N: usize>(a: &[[f64; N]; N]) -> bool {
    let mut l = [[0.0; N]; N];
    for j in 0..N {
        let d = a[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        l[j][j] = d.sqrt();
        for i in j + 1..N {
            l[i][j] = (a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>()) / l[j][j];
        }
    }
    true
}

/// [`project_psd`], except that a positive definite `a` (its own projection) is left as it
/// is: one small Cholesky instead of the Jacobi sweeps, and no rounding from `V Λ Vᵀ`.
pub fn project_psd_unless_definite<const N: usize>(a: &mut [[f64; N]; N]) {
    if !is_positive_definite(a) {
        project_psd(a);
    }
}

/// `a − b` on `[f64; 3]` (the storage form of the TFW code).
#[inline]
pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s · a`.
#[inline]
pub(super) fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a · b`, summed left to right.
#[inline]
pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline]
pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_keeps_psd_and_clamps_indefinite() {
        let mut a = [[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
        let b = a;
        project_psd(&mut a);
        for i in 0..3 {
            for j in 0..3 {
                assert!((a[i][j] - b[i][j]).abs() < 1e-12);
            }
        }
        assert!(is_positive_definite(&b));
        let mut d = b;
        project_psd_unless_definite(&mut d);
        assert_eq!(d, b);
        assert!(!is_positive_definite(&[[1.0, 2.0], [2.0, 1.0]]));
        assert!(!is_positive_definite(&[[1.0, 0.0], [0.0, 0.0]]));
        let mut e = [[1.0, 2.0], [2.0, 1.0]];
        project_psd_unless_definite(&mut e);
        assert!(e.iter().flatten().all(|x| (x - 1.5).abs() < 1e-12), "{e:?}");
        // eigenvalues 3 and -1 (eigvecs (1,1)/√2, (1,-1)/√2): projection = 1.5 [[1,1],[1,1]]
        let mut c = [[1.0, 2.0], [2.0, 1.0]];
        project_psd(&mut c);
        for row in c {
            for x in row {
                assert!((x - 1.5).abs() < 1e-12, "{c:?}");
            }
        }
    }
}
