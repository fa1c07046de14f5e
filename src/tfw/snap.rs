//! **Period snapping** (spec `tfw.md` step 8's optional pre-step and Risk 9): between
//! the wrinkle SQP and the Knöppel phase, the periods `∮ω` of the SQP's one-form around the
//! base surface's non-contractible loops (the cylinder's ring, the torus's two generators) are
//! moved to the nearest multiple of 2π by the smallest closed correction.
//!
//! **Why.** The text rounds the phase with a MIP on a cut mesh (A.6.4–A.6.5, S:2309–2329);
//! pleat takes Knöppel's phase ([`crate::wrinkle::Cwf::from_one_form`]), which can follow ω
//! without a defect only where every period of ω is in 2πℤ. The SQP does not know that: on the
//! twisted cylinder its ω goes 46.21 times around the ring. Measured (docs/design-notes.md,
//! "Wrinkle SQP"): Knöppel spreads such a fraction smoothly (no phase defect on the cylinders, and
//! the torus balloon's lines, first read as a seam, are amplitude bands that stay with
//! snapping), while snapping moves ω off the SQP's stationary point (E^wf +1.25% on the 690-v
//! cylinder). So it is an option, off by default ([`crate::tfw::TfwParams::snap_periods`]),
//! for callers who want ω's periods to agree with the phase's integer winding.
//!
//! **Which loops.** Let K be the complex of the faces outside W (where `curl ω = 0` holds and
//! `a` may be positive) and M the whole base mesh. Every closed ω on K is `G u + Σ_g c_g h_g`
//! with the tree–cotree basis of [`crate::tfw::pnewton`] ([`CurlFreeBasis`]), whose generator
//! cycles `γ_g` carry the periods `c_g`. A cycle of K is either
//! - **contractible in M** (null-homologous: it goes around W islands only). Its period is
//!   kept: the fraction it carries is absorbed by a phase defect that Knöppel can place inside
//!   the W island, where `a ≡ 0` hides it (the SQP fixes `a = 0` on every vertex of a W face),
//!   and snapping it would bend ω around every small W island by up to π; or
//! - **non-contractible in M** (the ring of a cylinder or of an annulus panel — also the loops
//!   around a panel's holes: a boundary is not a place where `a` vanishes, so the remainder
//!   would show as a seam from it —, the torus's generators). Its period is snapped.
//!
//! The split is computed, not assumed: the tree–cotree basis of M (all faces, holes joined to
//! one virtual dual node) gives integer coordinates of each `γ_g` in `H₁(M)`; a unimodular
//! integer row reduction of that matrix gives new cycles of K, `γ'_i = Σ_g U_ig γ_g`, the first
//! `r` of which map to an integer basis of K's image in `H₁(M)` and the rest to 0 (so every
//! non-contractible cycle of K, being an integer combination of the first `r` plus contractible
//! ones, gets period `2πℤ +` the kept periods of the contractible ones).
//!
//! **The correction** (least squares, harmonic): `δω = Σ_g ΔP_g h_g + G u` with
//! `ΔP = U⁻¹ ΔP'`, `ΔP'_i = 2π round(P'_i / 2π) − P'_i` for `i < r` and 0 otherwise; it is
//! closed on every face of K by construction (curl ≤ rounding whatever `u`), changes exactly
//! the snapped periods, and `u` minimizes `‖δω‖² = Σ_{f ∈ K} A_f δω_fᵀ Ī_f⁻¹ δω_f` (the L² norm
//! of the face-wise constant one-form in the rest metric `Ī_f`, the metric of the Helmholtz
//! projection in [`crate::tfw::wfree`]): one Cholesky solve of the P1 stiffness matrix of K
//! (one vertex pinned per component). `δω` is then co-closed in that norm, the discrete
//! harmonic representative of its period class. On a uniform cylinder it is the closed form
//! `(ΔP/2π) dθ`: constant on the ring edges (tested). ω off K (edges with no face outside W) is
//! 0 before and after; `a` is not touched.

use crate::mesh::{EdgeList, TriMesh};
use crate::solve::{assemble, Cholesky, CholeskyAnalysis, Entry, Parallelism};
use crate::tfw::material::Form;
use crate::tfw::pnewton::CurlFreeBasis;
use crate::tfw::sqp::SqpProblem;
use crate::{Error, Result};
use std::f64::consts::TAU;

/// One snapped loop of [`PeriodSnap`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnappedLoop {
    /// `∮ω` around the loop before snapping (rad).
    pub before: f64,
    /// `∮ω` around the loop after snapping (rad), measured on the returned ω: `2π·waves`
    /// to rounding.
    pub after: f64,
    /// The number of waves `k` (`after = 2πk`): the nearest integer to `before / 2π`.
    pub waves: i64,
}

/// The result of [`snap_periods`].
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodSnap {
    /// The snapped one-form, one value per edge of the base mesh (pleat's orientation);
    /// bit-identical to the input when no loop is snapped.
    pub omega: Vec<f64>,
    /// The snapped loops (cycles of the non-W complex K that are non-contractible in the base
    /// mesh, an integer basis of their classes), in a deterministic order.
    pub loops: Vec<SnappedLoop>,
    /// Independent cycles of K that are contractible in the base mesh (around W islands);
    /// their periods are kept.
    pub kept_loops: usize,
    /// `∮ω` around those kept cycles (rad; unchanged by the snapping; empty when no loop is
    /// snapped).
    pub kept_periods: Vec<f64>,
    /// `‖δω‖`: the correction's L² norm in the rest metric over the faces of K (rad).
    pub correction_norm: f64,
    /// `‖ω‖` before snapping, same norm (rad), for a relative size.
    pub omega_norm: f64,
    /// `max_e |δω_e|` (rad).
    pub max_correction: f64,
}

impl PeriodSnap {
    /// Largest `|after − 2π·waves|` over the snapped loops (0 when none).
    pub fn max_period_error(&self) -> f64 {
        self.loops
            .iter()
            .map(|l| (l.after - TAU * l.waves as f64).abs())
            .fold(0.0, f64::max)
    }
}

/// Snaps the periods of `omega` (one value per edge of `base`, closed on the faces outside W
/// that take part in `problem`) around the base mesh's non-contractible loops to the nearest
/// multiple of 2π with the least-squares harmonic correction (module docs). `rest_forms` are
/// the faces' rest first fundamental forms (the norm), `w_faces` the W flags `problem` was
/// built with. Guarantees: the returned ω is closed wherever `omega` was (the correction's
/// curl is rounding); each snapped loop's period is `2π·waves` to rounding; the periods around
/// loops contractible in `base` are unchanged; nothing changes (bit for bit) when no loop is
/// snapped. Errors ([`Error::Numerical`]) when the stiffness factorization fails.
pub fn snap_periods(
    problem: &SqpProblem,
    base: &TriMesh,
    rest_forms: &[Form],
    w_faces: &[bool],
    omega: &[f64],
) -> Result<PeriodSnap> {
    let nv = base.vertex_count();
    let na = problem.n_free_a;
    let free_edges: Vec<usize> = problem.free[na..].iter().map(|&g| g - nv).collect();
    let x_free_of = |w: &[f64]| -> Vec<f64> {
        let mut x = vec![0.0; na];
        x.extend(free_edges.iter().map(|&e| w[e]));
        x
    };
    let el = base.edges();
    let metric = Metric::new(&el, rest_forms, w_faces);
    let omega_norm = metric.norm(omega);
    let unchanged = |kept_loops: usize| PeriodSnap {
        omega: omega.to_vec(),
        loops: Vec::new(),
        kept_loops,
        kept_periods: Vec::new(),
        correction_norm: 0.0,
        omega_norm,
        max_correction: 0.0,
    };
    let basis = CurlFreeBasis::new(problem);
    let n = basis.generators();
    if n == 0 {
        return Ok(unchanged(0));
    }
    let homology = homology_in_base(&el, &basis, &x_free_of);
    let Reduction { u, u_inv, rank } = integer_row_reduce(&homology);
    if rank == 0 {
        return Ok(unchanged(n));
    }
    let periods = basis.periods(&x_free_of(omega));
    let combine = |m: &[Vec<i64>], v: &[f64]| -> Vec<f64> {
        m.iter()
            .map(|row| row.iter().zip(v).map(|(&k, &x)| k as f64 * x).sum())
            .collect()
    };
    let loop_periods = combine(&u, &periods);
    let gauge = HarmonicGauge::new(&metric, base.triangles(), &basis)?;
    // η_i: the harmonic form with period 1 around snapped loop i and 0 around the others
    let eta: Vec<Vec<f64>> = (0..rank)
        .map(|i| {
            let unit: Vec<f64> = (0..n).map(|k| i64::from(k == i) as f64).collect();
            let delta = combine(&u_inv, &unit);
            let mut h = vec![0.0; omega.len()];
            for (g, &dg) in delta.iter().enumerate() {
                if dg != 0.0 {
                    for (&e, v) in free_edges.iter().zip(&basis.generator_values(g)[na..]) {
                        h[e] += dg * v;
                    }
                }
            }
            gauge.harmonic(&free_edges, h)
        })
        .collect();
    let gram: Vec<Vec<f64>> = eta
        .iter()
        .map(|a| eta.iter().map(|b| metric.inner(a, b)).collect())
        .collect();
    let waves = nearest_waves(&loop_periods[..rank], &gram);
    let mut correction = vec![0.0; omega.len()];
    for (i, e) in eta.iter().enumerate() {
        let t = TAU * waves[i] as f64 - loop_periods[i];
        for (c, v) in correction.iter_mut().zip(e) {
            *c += t * v;
        }
    }
    let snapped: Vec<f64> = omega.iter().zip(&correction).map(|(w, d)| w + d).collect();
    let after = combine(&u, &basis.periods(&x_free_of(&snapped)));
    let loops = (0..rank)
        .map(|i| SnappedLoop {
            before: loop_periods[i],
            after: after[i],
            waves: waves[i],
        })
        .collect();
    Ok(PeriodSnap {
        correction_norm: metric.norm(&correction),
        max_correction: correction.iter().fold(0.0, |m, d| m.max(d.abs())),
        omega: snapped,
        loops,
        kept_loops: n - rank,
        kept_periods: after[rank..].to_vec(),
        omega_norm,
    })
}

/// The faces of K with their rest metric: the norm of the module docs.
struct Metric<'a> {
    el: &'a EdgeList,
    /// Per face of K with a positive rest area: `(face, A_f, Ī_f⁻¹ as [i00, i01, i11])`.
    faces: Vec<(usize, f64, [f64; 3])>,
}

impl<'a> Metric<'a> {
    /// The faces of K (outside W, no degenerate corner: those [`SqpProblem::new`] constrains)
    /// with a positive, finite rest area.
    fn new(el: &'a EdgeList, rest_forms: &[Form], w_faces: &[bool]) -> Metric<'a> {
        let faces = (0..el.face_edges.len())
            .filter(|&f| !w_faces[f] && !el.face_edge_sign[f].contains(&0))
            .filter_map(|f| {
                let r = rest_forms[f];
                let det = r[0] * r[2] - r[1] * r[1];
                (det > 0.0 && det.is_finite())
                    .then(|| (f, 0.5 * det.sqrt(), [r[2] / det, -r[1] / det, r[0] / det]))
            })
            .collect();
        Metric { el, faces }
    }

    /// `(ω(v0→v1), ω(v0→v2))` of face `f` from edge values (pleat's orientation).
    fn face_form(&self, f: usize, omega: &[f64]) -> [f64; 2] {
        let (fe, fs) = (self.el.face_edges[f], self.el.face_edge_sign[f]);
        [
            f64::from(fs[0]) * omega[fe[0] as usize],
            -f64::from(fs[2]) * omega[fe[2] as usize],
        ]
    }

    /// `⟨a, b⟩ = Σ_{f ∈ K} A_f a_fᵀ Ī_f⁻¹ b_f` (module docs), one value per edge.
    fn inner(&self, a: &[f64], b: &[f64]) -> f64 {
        self.faces
            .iter()
            .map(|&(f, area, inv)| {
                let (x, y) = (self.face_form(f, a), self.face_form(f, b));
                area * (inv[0] * x[0] * y[0]
                    + inv[1] * (x[0] * y[1] + x[1] * y[0])
                    + inv[2] * x[1] * y[1])
            })
            .sum()
    }

    /// `‖ω‖ = ⟨ω, ω⟩^{1/2}`.
    fn norm(&self, omega: &[f64]) -> f64 {
        self.inner(omega, omega).max(0.0).sqrt()
    }
}

/// Per generator cycle of `basis` (a cycle of K), its integer coordinates in `H₁(M)` of the
/// whole base mesh M: the periods of M's tree–cotree basis forms around it (integers: those
/// forms take integer values).
fn homology_in_base(
    el: &EdgeList,
    basis: &CurlFreeBasis,
    x_free_of: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Vec<i64>> {
    let ends: Vec<[usize; 2]> = el.edges.iter().map(|e| e.0.map(|v| v as usize)).collect();
    let curl: Vec<[(usize, f64); 3]> = (0..el.face_edges.len())
        .filter(|&f| !el.face_edge_sign[f].contains(&0))
        .map(|f| {
            let (fe, fs) = (el.face_edges[f], el.face_edge_sign[f]);
            std::array::from_fn(|i| (fe[i] as usize, f64::from(fs[i])))
        })
        .collect();
    let whole = CurlFreeBasis::of_complex(0, &ends, &curl);
    let mut rows = vec![Vec::with_capacity(whole.generators()); basis.generators()];
    for j in 0..whole.generators() {
        let form = whole.generator_values(j);
        for (row, p) in rows.iter_mut().zip(basis.periods(&x_free_of(&form))) {
            row.push(p.round() as i64);
        }
    }
    rows
}

/// A unimodular row reduction over ℤ: `u · a = [R; 0]` with the `rank` rows of `R`
/// independent; `u_inv = u⁻¹` (integer).
struct Reduction {
    u: Vec<Vec<i64>>,
    u_inv: Vec<Vec<i64>>,
    rank: usize,
}

/// `m[i] −= q · m[p]`.
fn sub_row(m: &mut [Vec<i64>], i: usize, p: usize, q: i64) {
    let src = m[p].clone();
    for (x, y) in m[i].iter_mut().zip(&src) {
        *x -= q * y;
    }
}

/// Integer row echelon form of `a` (`n` rows of equal length) by Euclid's algorithm on each
/// column (row swaps and integer row additions only, so `u` is unimodular and `u⁻¹` integer).
fn integer_row_reduce(a: &[Vec<i64>]) -> Reduction {
    let n = a.len();
    let m = a.first().map_or(0, Vec::len);
    let identity = |n: usize| -> Vec<Vec<i64>> {
        (0..n)
            .map(|i| (0..n).map(|j| i64::from(i == j)).collect())
            .collect()
    };
    let (mut rows, mut u, mut u_inv) = (a.to_vec(), identity(n), identity(n));
    let mut pivot = 0;
    for col in 0..m {
        if pivot == n {
            break;
        }
        // the row with the smallest nonzero entry in `col` becomes the pivot row
        while let Some(p) = (pivot..n)
            .filter(|&i| rows[i][col] != 0)
            .min_by_key(|&i| (rows[i][col].abs(), i))
        {
            rows.swap(p, pivot);
            u.swap(p, pivot);
            for r in &mut u_inv {
                r.swap(p, pivot);
            }
            let mut done = true;
            for i in pivot + 1..n {
                let q = rows[i][col] / rows[pivot][col];
                if q != 0 {
                    // row_i −= q row_pivot; u⁻¹: column pivot += q column i
                    sub_row(&mut rows, i, pivot, q);
                    sub_row(&mut u, i, pivot, q);
                    for r in &mut u_inv {
                        r[pivot] += q * r[i];
                    }
                }
                done &= rows[i][col] == 0;
            }
            if done {
                pivot += 1;
                break;
            }
        }
    }
    Reduction {
        u,
        u_inv,
        rank: pivot,
    }
}

/// The least-squares exact part of [`snap_periods`]: the P1 stiffness matrix `Gᵀ Q G` of K
/// in the rest metric (module docs), one vertex pinned per component (the basis's forest
/// roots), the mean diagonal on the rows of vertices touched only by degenerate faces;
/// factored once.
struct HarmonicGauge<'a> {
    metric: &'a Metric<'a>,
    triangles: &'a [[u32; 3]],
    basis: &'a CurlFreeBasis,
    /// `None` when K has no exact unknown.
    chol: Option<Cholesky>,
}

/// `D` maps a face's corner values `(u0, u1, u2)` to `(u1 − u0, u2 − u0)`.
const D: [[f64; 3]; 2] = [[-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]];

/// `Dᵀ Ī⁻¹` per corner, `inv = Ī⁻¹` as `[i00, i01, i11]`.
fn dt_inv(inv: [f64; 3]) -> [[f64; 2]; 3] {
    let m = [[inv[0], inv[1]], [inv[1], inv[2]]];
    std::array::from_fn(|a| std::array::from_fn(|q| (0..2).map(|p| D[p][a] * m[p][q]).sum()))
}

impl<'a> HarmonicGauge<'a> {
    /// Assembles and factors the stiffness matrix of the faces of `metric` (module docs).
    fn new(
        metric: &'a Metric<'a>,
        triangles: &'a [[u32; 3]],
        basis: &'a CurlFreeBasis,
    ) -> Result<HarmonicGauge<'a>> {
        let nu = basis.exact_unknowns();
        let mut gauge = HarmonicGauge {
            metric,
            triangles,
            basis,
            chol: None,
        };
        if nu == 0 {
            return Ok(gauge);
        }
        let mut entries = Vec::new();
        for &(f, area, inv) in &metric.faces {
            let idx = triangles[f].map(|v| basis.exact_unknown(v as usize));
            let dm = dt_inv(inv);
            for a in 0..3 {
                let Some(ia) = idx[a] else { continue };
                for b in 0..3 {
                    let Some(ib) = idx[b] else { continue };
                    if ia >= ib {
                        let k = area * (dm[a][0] * D[0][b] + dm[a][1] * D[1][b]);
                        entries.push(Entry::new(ia, ib, k));
                    }
                }
            }
        }
        // a vertex reached only through degenerate faces has no norm: its row gets the mean
        // diagonal (its u then stays 0)
        let mut diag = vec![0.0; nu];
        for e in entries.iter().filter(|e| e.row == e.col) {
            diag[e.row] += e.val;
        }
        let mean = diag.iter().sum::<f64>() / nu as f64;
        let fill = if mean > 0.0 { mean } else { 1.0 };
        for (i, d) in diag.iter().enumerate() {
            if *d <= 0.0 {
                entries.push(Entry::new(i, i, fill));
            }
        }
        let k = assemble(nu, &entries, "tfw period snapping")?;
        let chol = CholeskyAnalysis::new(&k)?
            .factor(&k, Parallelism::Global)
            .map_err(|e| Error::Numerical(format!("tfw period snapping: {e:?}")))?;
        gauge.chol = Some(chol);
        Ok(gauge)
    }

    /// `h + G u` with `u` minimizing its norm (`h` closed on K, one value per edge, 0 off
    /// `free_edges`): the harmonic representative of `h`'s periods.
    fn harmonic(&self, free_edges: &[usize], mut h: Vec<f64>) -> Vec<f64> {
        let Some(chol) = &self.chol else { return h };
        let basis = self.basis;
        let mut rhs = vec![0.0; basis.exact_unknowns()];
        for &(f, area, inv) in &self.metric.faces {
            let hf = self.metric.face_form(f, &h);
            let dm = dt_inv(inv);
            for (a, &v) in self.triangles[f].iter().enumerate() {
                if let Some(ia) = basis.exact_unknown(v as usize) {
                    rhs[ia] -= area * (dm[a][0] * hf[0] + dm[a][1] * hf[1]);
                }
            }
        }
        let u = chol.solve(&rhs);
        let at = |v: usize| basis.exact_unknown(v).map_or(0.0, |i| u[i]);
        for &e in free_edges {
            let [t, hd] = self.metric.el.edges[e].0.map(|v| v as usize);
            h[e] += at(hd) - at(t);
        }
        h
    }
}

/// The winding numbers `k` minimizing the correction's norm² `tᵀ gram t`, `t = 2πk − P`,
/// over `k_i ∈ {⌊P_i/2π⌋, ⌈P_i/2π⌉}` (all `2^r` corners for up to 10 loops, the nearest
/// integers beyond): rounding each period alone can miss the smallest correction when the
/// loops' harmonic forms are not orthogonal. Ties keep the first corner (all floors first).
fn nearest_waves(periods: &[f64], gram: &[Vec<f64>]) -> Vec<i64> {
    let r = periods.len();
    let nearest: Vec<i64> = periods.iter().map(|p| (p / TAU).round() as i64).collect();
    if r > 10 {
        return nearest;
    }
    let floor: Vec<i64> = periods.iter().map(|p| (p / TAU).floor() as i64).collect();
    let norm2 = |k: &[i64]| -> f64 {
        let t: Vec<f64> = k
            .iter()
            .zip(periods)
            .map(|(&k, p)| TAU * k as f64 - p)
            .collect();
        (0..r)
            .map(|i| (0..r).map(|j| t[i] * gram[i][j] * t[j]).sum::<f64>())
            .sum()
    };
    let mut best = (norm2(&nearest), nearest);
    for mask in 0u32..1 << r {
        let k: Vec<i64> = (0..r)
            .map(|i| floor[i] + i64::from(mask >> i & 1 == 1))
            .collect();
        let n2 = norm2(&k);
        if n2 < best.0 {
            best = (n2, k);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tfw::energy::WrinkleEnergy;

    /// The rest forms equal to the mesh's own metric (`[e1·e1, e1·e2, e2·e2]`).
    fn own_forms(mesh: &TriMesh) -> Vec<Form> {
        mesh.triangles()
            .iter()
            .map(|t| {
                let q = t.map(|v| mesh.positions()[v as usize]);
                let e1: [f64; 3] = std::array::from_fn(|k| q[1][k] - q[0][k]);
                let e2: [f64; 3] = std::array::from_fn(|k| q[2][k] - q[0][k]);
                let d = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                [d(e1, e1), d(e1, e2), d(e2, e2)]
            })
            .collect()
    }

    /// The SQP problem of `mesh` with the faces `w` in W (nothing clamped).
    fn problem(mesh: &TriMesh, forms: &[Form], w: &[bool]) -> SqpProblem {
        let nf = mesh.triangle_count();
        let strains = crate::tfw::wfree::face_strains(forms, mesh);
        let energy = WrinkleEnergy::new(
            mesh,
            forms,
            &strains,
            &vec![0.0; nf],
            crate::tfw::Lame {
                alpha: 1.0,
                beta: 1.0,
            },
            1e-3,
        );
        SqpProblem::new(energy, mesh, w, &vec![false; mesh.vertex_count()])
    }

    /// A grid of `n` (periodic) × `m` vertices, two triangles per quad; `wrap_m` closes the
    /// second direction too.
    fn grid(n: usize, m: usize, wrap_m: bool, pos: impl Fn(usize, usize) -> [f64; 3]) -> TriMesh {
        let mut p = Vec::new();
        for j in 0..m {
            for k in 0..n {
                p.push(pos(k, j));
            }
        }
        let id = |k: usize, j: usize| ((j % m) * n + k % n) as u32;
        let mut t = Vec::new();
        for j in 0..if wrap_m { m } else { m - 1 } {
            for k in 0..n {
                t.push([id(k, j), id(k + 1, j), id(k + 1, j + 1)]);
                t.push([id(k, j), id(k + 1, j + 1), id(k, j + 1)]);
            }
        }
        TriMesh::new(p, t).unwrap()
    }

    /// Per edge of `mesh`, `f(head) − f(tail)` with a wrapped angle difference for `angle`.
    fn edge_values(mesh: &TriMesh, f: impl Fn(usize) -> f64, angle: bool) -> Vec<f64> {
        mesh.edges()
            .edges
            .iter()
            .map(|e| {
                let d = f(e.0[1] as usize) - f(e.0[0] as usize);
                if angle {
                    (d + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI
                } else {
                    d
                }
            })
            .collect()
    }

    /// `max_f |curl ω|` over every face.
    fn max_curl(mesh: &TriMesh, omega: &[f64]) -> f64 {
        let el = mesh.edges();
        (0..mesh.triangle_count())
            .map(|f| {
                (0..3)
                    .map(|i| {
                        f64::from(el.face_edge_sign[f][i]) * omega[el.face_edges[f][i] as usize]
                    })
                    .sum::<f64>()
                    .abs()
            })
            .fold(0.0, f64::max)
    }

    fn add(a: &[f64], b: &[f64], s: f64) -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| x + s * y).collect()
    }

    /// A uniform cylinder (an intrinsically flat prism) with `ω = (k + frac) dθ + 3 dz +
    /// d(noise)`: the ring's period goes to the nearest `2πk'`, exactly, and the correction is
    /// the closed form `(k' − k − frac) dθ` — constant `2π(k' − k − frac)/n` on the ring edges,
    /// 0 along the axis — whatever the exact noise; curl stays at rounding.
    #[test]
    fn cylinder_ring_snaps_to_the_nearest_multiple_with_the_closed_form_correction() {
        let (n, m) = (24, 9);
        let theta = |k: usize| TAU * k as f64 / n as f64;
        let mesh = grid(n, m, false, |k, j| {
            [theta(k).cos(), theta(k).sin(), 0.3 * j as f64]
        });
        let forms = own_forms(&mesh);
        let nf = mesh.triangle_count();
        let p = problem(&mesh, &forms, &vec![false; nf]);
        let th = edge_values(&mesh, |v| theta(v % n), true);
        let dz = edge_values(&mesh, |v| mesh.positions()[v][2], false);
        let noise = edge_values(&mesh, |v| (v as f64 * 1.7).sin(), false);
        for (frac, expect) in [(0.3, 7), (0.7, 8), (-0.45, 7), (-0.6, 6)] {
            let omega: Vec<f64> = (0..th.len())
                .map(|e| (7.0 + frac) * th[e] + 3.0 * dz[e] + noise[e])
                .collect();
            let s = snap_periods(&p, &mesh, &forms, &vec![false; nf], &omega).unwrap();
            assert_eq!(s.loops.len(), 1);
            assert_eq!(s.kept_loops, 0);
            let l = s.loops[0];
            assert_eq!(l.waves.abs(), expect, "{l:?}");
            assert!((l.before.abs() - TAU * (7.0 + frac)).abs() < 1e-10, "{l:?}");
            assert!(s.max_period_error() <= 1e-10, "{l:?}");
            // the ring's own sum, measured independently of the basis
            let ring: f64 = (0..n)
                .map(|k| th_edge_sum(&mesh, &s.omega, k, (k + 1) % n))
                .sum();
            assert!((ring - TAU * expect as f64).abs() <= 1e-10, "ring {ring}");
            assert!(max_curl(&mesh, &s.omega) <= 1e-12);
            let closed = expect as f64 - 7.0 - frac;
            for (e, (&d, &t)) in add(&s.omega, &omega, -1.0).iter().zip(&th).enumerate() {
                assert!(
                    (d - closed * t).abs() <= 1e-10,
                    "edge {e}: {d} vs {}",
                    closed * t
                );
            }
            let expected_norm = closed.abs() * TAU * (0.3 * (m - 1) as f64 / TAU).sqrt();
            // ‖c dθ‖² = c² ∫ |∇θ|² = c² (2π)² · height / (2π · radius) on the prism (n large)
            assert!((s.correction_norm / expected_norm - 1.0).abs() < 0.01);
        }
    }

    /// `ω(k → l)` for ring-0 vertices `k`, `l` (oriented k → l).
    fn th_edge_sum(mesh: &TriMesh, omega: &[f64], k: usize, l: usize) -> f64 {
        let (a, b) = (k.min(l) as u32, k.max(l) as u32);
        let e = mesh
            .edges()
            .edges
            .iter()
            .position(|e| e.0 == [a, b])
            .unwrap();
        if k < l {
            omega[e]
        } else {
            -omega[e]
        }
    }

    /// A torus with fractional periods around both generators: both snap (each ring's sum
    /// becomes the nearest multiple of 2π), the curl stays at rounding, and the correction is
    /// harmonic: co-closed (`Gᵀ Q δω = 0` at every vertex) in the norm of the module docs.
    #[test]
    fn torus_snaps_both_generators_with_a_harmonic_correction() {
        let (n, m) = (30, 12);
        let (big, small) = (3.0, 1.0);
        let th = |k: usize| TAU * k as f64 / n as f64;
        let ph = |j: usize| TAU * j as f64 / m as f64;
        let mesh = grid(n, m, true, |k, j| {
            let r = big + small * ph(j).cos();
            [r * th(k).cos(), r * th(k).sin(), small * ph(j).sin()]
        });
        let forms = own_forms(&mesh);
        let nf = mesh.triangle_count();
        let p = problem(&mesh, &forms, &vec![false; nf]);
        let dth = edge_values(&mesh, |v| th(v % n), true);
        let dph = edge_values(&mesh, |v| ph(v / n), true);
        let noise = edge_values(&mesh, |v| (v as f64 * 0.37).cos(), false);
        let omega: Vec<f64> = (0..dth.len())
            .map(|e| 40.3 * dth[e] + 4.8 * dph[e] + noise[e])
            .collect();
        let s = snap_periods(&p, &mesh, &forms, &vec![false; nf], &omega).unwrap();
        assert_eq!(s.loops.len(), 2);
        assert!(s.max_period_error() <= 1e-10, "{:?}", s.loops);
        assert!(max_curl(&mesh, &s.omega) <= 1e-12);
        let el = mesh.edges();
        let sum_along = |path: &[usize]| -> f64 {
            path.windows(2)
                .map(|w| {
                    let (a, b) = (w[0].min(w[1]) as u32, w[0].max(w[1]) as u32);
                    let e = el.edges.iter().position(|e| e.0 == [a, b]).unwrap();
                    if w[0] < w[1] {
                        s.omega[e]
                    } else {
                        -s.omega[e]
                    }
                })
                .sum()
        };
        let long: Vec<usize> = (0..=n).map(|k| k % n).collect();
        let merid: Vec<usize> = (0..=m).map(|j| (j % m) * n).collect();
        assert!((sum_along(&long) - TAU * 40.0).abs() <= 1e-10);
        assert!((sum_along(&merid) - TAU * 5.0).abs() <= 1e-10);
        // co-closed: Σ_f A_f Dᵀ Ī⁻¹ δω_f vanishes at every vertex
        let delta = add(&s.omega, &omega, -1.0);
        let metric = Metric::new(&el, &forms, &vec![false; nf]);
        let mut div = vec![0.0; mesh.vertex_count()];
        let mut scale = 0.0f64;
        for &(f, area, inv) in &metric.faces {
            let d = metric.face_form(f, &delta);
            let dm = dt_inv(inv);
            for (a, &v) in mesh.triangles()[f].iter().enumerate() {
                let x = area * (dm[a][0] * d[0] + dm[a][1] * d[1]);
                div[v as usize] += x;
                scale = scale.max(x.abs());
            }
        }
        let worst = div.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        assert!(worst <= 1e-9 * scale, "divergence {worst} vs {scale}");
    }

    /// No loop on a disk: nothing changes, bit for bit.
    #[test]
    fn disk_is_a_bit_identical_no_op() {
        let mesh = grid(7, 6, false, |k, j| {
            [k as f64 + 0.1 * (j as f64).sin(), j as f64, 0.0]
        });
        // grid() wraps the first direction; cut it open by dropping the wrapping quads
        let t: Vec<[u32; 3]> = mesh
            .triangles()
            .iter()
            .copied()
            .filter(|t| {
                let ks: Vec<u32> = t.iter().map(|v| v % 7).collect();
                !(ks.contains(&0) && ks.contains(&6))
            })
            .collect();
        let mesh = TriMesh::new(mesh.positions().to_vec(), t).unwrap();
        let forms = own_forms(&mesh);
        let nf = mesh.triangle_count();
        let p = problem(&mesh, &forms, &vec![false; nf]);
        let omega = edge_values(&mesh, |v| (v as f64 * 2.3).sin() * 5.0, false);
        let s = snap_periods(&p, &mesh, &forms, &vec![false; nf], &omega).unwrap();
        assert!(s.loops.is_empty());
        assert_eq!(s.kept_loops, 0);
        assert_eq!(s.correction_norm, 0.0);
        for (a, b) in s.omega.iter().zip(&omega) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }

    /// A W island inside a cylinder: the loop around the island is contractible in the base
    /// and keeps its (fractional) period; the ring still snaps.
    #[test]
    fn loops_around_w_islands_are_kept() {
        let (n, m) = (16, 7);
        let theta = |k: usize| TAU * k as f64 / n as f64;
        let mesh = grid(n, m, false, |k, j| {
            [theta(k).cos(), theta(k).sin(), 0.4 * j as f64]
        });
        let forms = own_forms(&mesh);
        let nf = mesh.triangle_count();
        // the two triangles of one quad in the middle (ring 3, column 5) form the island
        let mut w = vec![false; nf];
        w[2 * (3 * n + 5)] = true;
        w[2 * (3 * n + 5) + 1] = true;
        let p = problem(&mesh, &forms, &w);
        let th = edge_values(&mesh, |v| theta(v % n), true);
        // a closed form on K with a period 0.4 around the island: the harmonic ring form plus
        // a point-vortex-like form would do; the ring form alone has period 0 there
        let omega: Vec<f64> = th.iter().map(|t| 5.3 * t).collect();
        let mut omega = omega;
        // island loop gets a fractional period: add 0.4 · (the K-basis form of the island)
        let basis = CurlFreeBasis::new(&p);
        assert_eq!(basis.generators(), 2);
        let s0 = snap_periods(&p, &mesh, &forms, &w, &omega).unwrap();
        assert_eq!((s0.loops.len(), s0.kept_loops), (1, 1));
        let na = p.n_free_a;
        let nv = mesh.vertex_count();
        let before = basis.periods(&{
            let mut x = vec![0.0; na];
            x.extend(p.free[na..].iter().map(|&g| omega[g - nv]));
            x
        });
        for g in 0..2 {
            let h = basis.generator_values(g);
            for (k, &gl) in p.free[na..].iter().enumerate() {
                omega[gl - nv] += 0.4 * h[na + k];
            }
        }
        let s = snap_periods(&p, &mesh, &forms, &w, &omega).unwrap();
        assert_eq!((s.loops.len(), s.kept_loops), (1, 1));
        assert!(s.max_period_error() <= 1e-10);
        // the island's loop: among the basis cycles, the combination that is contractible
        let period = |om: &[f64]| {
            let mut x = vec![0.0; na];
            x.extend(p.free[na..].iter().map(|&g| om[g - nv]));
            basis.periods(&x)
        };
        let (pb, pa) = (period(&omega), period(&s.omega));
        let homology = homology_in_base(&mesh.edges(), &basis, &|om: &[f64]| {
            let mut x = vec![0.0; na];
            x.extend(p.free[na..].iter().map(|&g| om[g - nv]));
            x
        });
        let red = integer_row_reduce(&homology);
        let island =
            |v: &[f64]| -> f64 { red.u[1].iter().zip(v).map(|(&k, x)| k as f64 * x).sum() };
        assert!((island(&pa) - island(&pb)).abs() <= 1e-10);
        assert!((island(&pb) - island(&before)).abs() > 0.1);
        assert!(max_curl_on(&p, &mesh, &s.omega) <= 1e-12);
    }

    fn max_curl_on(p: &SqpProblem, mesh: &TriMesh, omega: &[f64]) -> f64 {
        let mut x = vec![0.0; mesh.vertex_count()];
        x.extend_from_slice(omega);
        p.curl_residual(&x)
    }

    /// The integer reduction is unimodular (`u · u⁻¹ = I`) and puts `a` in echelon form.
    #[test]
    fn integer_reduction_is_unimodular_echelon() {
        let a = vec![
            vec![2, 4, 0],
            vec![3, 1, 1],
            vec![5, 5, 1],
            vec![0, 0, 0],
            vec![4, -2, 2],
        ];
        let r = integer_row_reduce(&a);
        let n = a.len();
        for i in 0..n {
            for j in 0..n {
                let p: i64 = (0..n).map(|k| r.u[i][k] * r.u_inv[k][j]).sum();
                assert_eq!(p, i64::from(i == j));
            }
        }
        let ua: Vec<Vec<i64>> = (0..n)
            .map(|i| {
                (0..3)
                    .map(|c| (0..n).map(|k| r.u[i][k] * a[k][c]).sum())
                    .collect()
            })
            .collect();
        assert_eq!(r.rank, 2);
        for row in &ua[r.rank..] {
            assert!(row.iter().all(|&v| v == 0), "{ua:?}");
        }
    }
}
