//! Matrix-free linear algebra for the spacetime phase solve of [`interpolate`](super::interpolate):
//! a time-ordered block preconditioner and the Steihaug–Toint truncated conjugate gradient
//! method that solves each trust-region subproblem.
//!
//! # Why not one sparse Cholesky factorization
//!
//! The phase unknowns live on the product graph "base mesh × guide frames": a 3-D-like graph.
//! On the knight (502 vertices, 49 unknown frames, 49 196 reals) faer's AMD-ordered Cholesky
//! factor has 30.7 M nonzeros (75× the matrix) and one factorization takes ~1.9 s on this
//! machine: the direct Newton solve costs seconds *per iteration*. Nested dissection does not
//! rescue it — the cheapest separators are whole frames, whose Schur complements are dense.
//!
//! # The preconditioner: symmetric block Gauss–Seidel in time
//!
//! Ordered frame by frame, the Hessian is block tridiagonal, `H = D + L + Lᵀ`:
//!
//! - `D = blockdiag(B_1, …, B_{N'−1})`, where `B_n` is frame `n`'s own part — its compatibility
//!   term `c E_compat` (a connection Laplacian of the base mesh), the diagonal of `E_smooth`
//!   (`4 w_s,j` per real) and the per-vertex `E_unit` block — a sparse `2V × 2V` matrix with a
//!   planar pattern whose Cholesky factor is small (≈ 30 nonzeros per column);
//! - `L` couples frame `n` to `n − 1` only through `E_smooth`, and is *diagonal*: `−2 w_s,j`.
//!
//! The preconditioner is the symmetric block Gauss–Seidel sweep over frames in red–black order
//! (even-indexed frames first, then odd), `M = (D + L) D⁻¹ (D + Lᵀ)` with `L` the coupling
//! between the two colours: solve the even frames, then the odd frames from their even
//! neighbours, then correct the even frames from their odd neighbours. It is symmetric positive
//! definite whenever every `B_n` is (the `E_unit` blocks inside `D` are projected to PSD, and
//! `4 w_s > 0`), and unlike block Jacobi it couples each frame to its neighbours in one
//! application, so the error components that `E_smooth` couples strongly are handled. Frames of
//! one colour are independent: each half-sweep runs in parallel (the lexicographic sweep needs
//! fewer CG iterations — 22 instead of 31 for the torus's initial guess — but is sequential, and
//! was slower on two cores). All `N' − 1` factorizations share one symbolic analysis and run in
//! parallel.
//!
//! # Steihaug–Toint CG
//!
//! [`steihaug`](crate::solve::steihaug) minimizes the quadratic model `gᵀs + ½ sᵀHs` over `‖s‖_M ≤ Δ` with
//! preconditioned CG (Steihaug 1983; Nocedal & Wright, *Numerical Optimization*, Alg. 7.2 with
//! the `M`-norm recurrences of Gould, Lucidi, Roma & Toint 1999). `H` is the *exact* Hessian:
//! where CG meets negative curvature (near phase singularities `E_unit` is concave) it follows
//! that direction to the trust-region boundary instead of damping it away, which is what the
//! Levenberg–Marquardt damping of the direct solver could not do.

use rayon::prelude::*;

use crate::solve::{
    assemble, entry_index, is_out_of_memory, sym_matvec_lower_into, Cholesky, CholeskyAnalysis,
    Entry, Parallelism, SolveScratch, SparseMatrix,
};
use crate::{Error, Result};

/// The frame blocks `B_n` without their `E_unit` part, sharing one sparsity pattern.
pub(super) struct FrameBlocks {
    /// `2V`: reals per frame.
    size: usize,
    /// `K`'s part of `B_n` per unknown frame (lower triangle, identical patterns).
    blocks: Vec<SparseMatrix>,
    /// Per vertex: value slots of `(2j,2j)`, `(2j+1,2j)`, `(2j+1,2j+1)` in every block.
    diag_slots: Vec<[usize; 3]>,
    /// `2 w_s,j` per vertex: minus the time off-diagonal of `H` (both reals of vertex `j`).
    coupling: Vec<f64>,
    /// Added to every diagonal entry when factoring: `1e-10 ×` the mean diagonal of `K`, so a
    /// block stays definite where `E_smooth`'s weight vanishes and the connection is flat.
    shift: f64,
    /// The symbolic analysis of the common pattern.
    analysis: CholeskyAnalysis,
}

impl FrameBlocks {
    /// Builds the blocks from each frame's triplets (`frame_triplets(n)` lists frame `n`'s
    /// entries of `K` in local indices, lower triangle; every frame must list the same
    /// positions) and the time coupling `2 w_s,j`.
    pub(super) fn new(
        n_v: usize,
        n_unknown_frames: usize,
        coupling: Vec<f64>,
        frame_triplets: impl Fn(usize) -> Vec<Entry> + Sync,
    ) -> Result<FrameBlocks> {
        let size = 2 * n_v;
        let blocks = (1..=n_unknown_frames)
            .into_par_iter()
            .map(|n| assemble(size, &frame_triplets(n), "a frame block"))
            .collect::<Result<Vec<_>>>()?;
        let first = blocks
            .first()
            .ok_or_else(|| Error::Numerical("no unknown frames".into()))?;
        let pattern = first.symbolic();
        if blocks.iter().any(|b| {
            b.symbolic().col_ptr() != pattern.col_ptr()
                || b.symbolic().row_idx() != pattern.row_idx()
        }) {
            return Err(Error::Numerical(
                "frame blocks of the interpolation Hessian differ in pattern".into(),
            ));
        }
        let slot = |r: usize, c: usize| -> Result<usize> {
            entry_index(first, r, c)
                .ok_or_else(|| Error::Numerical("frame block misses a diagonal entry".into()))
        };
        let diag_slots = (0..n_v)
            .map(|j| {
                Ok([
                    slot(2 * j, 2 * j)?,
                    slot(2 * j + 1, 2 * j)?,
                    slot(2 * j + 1, 2 * j + 1)?,
                ])
            })
            .collect::<Result<Vec<_>>>()?;
        let analysis = CholeskyAnalysis::new(first)?;
        let diag_sum: f64 = blocks
            .iter()
            .flat_map(|b| {
                diag_slots
                    .iter()
                    .map(move |s| b.val()[s[0]] + b.val()[s[2]])
            })
            .sum();
        let mean = diag_sum / (size * blocks.len()).max(1) as f64;
        Ok(FrameBlocks {
            size,
            shift: if mean > 0.0 && mean.is_finite() {
                1e-10 * mean
            } else {
                1e-300
            },
            blocks,
            diag_slots,
            coupling,
            analysis,
        })
    }

    /// `y = K v` from the frame blocks and the time coupling, frames in parallel.
    pub(super) fn k_matvec(&self, v: &[f64], y: &mut [f64]) {
        let s = self.size;
        let m = self.blocks.len();
        y.par_chunks_mut(s).enumerate().for_each(|(i, yi)| {
            sym_matvec_lower_into(&self.blocks[i], &v[i * s..(i + 1) * s], yi);
            for nb in [i.wrapping_sub(1), i + 1] {
                if nb < m {
                    let vn = &v[nb * s..(nb + 1) * s];
                    for (k, yk) in yi.iter_mut().enumerate() {
                        *yk -= self.coupling[k / 2] * vn[k];
                    }
                }
            }
        });
    }

    /// Factors every `B_n = K_n + U_n`, where `unit(n, j)` gives vertex `j`'s 2×2 block
    /// `(h00, h10, h11)` of frame `n` (1-based), which must keep `B_n` positive definite.
    ///
    /// The frames are factored in parallel, [`FACTOR_BATCH`] at a time, and `tick` (a
    /// cancellation point) runs between two batches; its error is returned as is.
    /// The factors do not depend on the batching.
    pub(super) fn factor(
        &self,
        unit: impl Fn(usize, usize) -> [f64; 3] + Sync,
        tick: &mut dyn FnMut() -> Result<()>,
    ) -> Result<TimeGaussSeidel<'_>> {
        let mut factors = Vec::with_capacity(self.blocks.len());
        for (c, batch) in self.blocks.chunks(FACTOR_BATCH).enumerate() {
            if c > 0 {
                tick()?;
            }
            let first = c * FACTOR_BATCH;
            let part = batch
                .par_iter()
                .enumerate()
                .map(|(k, block)| self.factor_frame(first + k, block, &unit))
                .collect::<Result<Vec<_>>>()?;
            factors.extend(part);
        }
        Ok(TimeGaussSeidel {
            blocks: self,
            factors,
        })
    }

    /// The Cholesky factor of `B_n = K_n + U_n + shift·I` for the unknown frame of index `i`
    /// (frame `n = i + 1`), `k` its block of `K`.
    fn factor_frame(
        &self,
        i: usize,
        k: &SparseMatrix,
        unit: &(impl Fn(usize, usize) -> [f64; 3] + Sync),
    ) -> Result<Cholesky> {
        let mut b = k.clone();
        let vals = b.val_mut();
        for (j, s) in self.diag_slots.iter().enumerate() {
            let u = unit(i + 1, j);
            vals[s[0]] += u[0] + self.shift;
            vals[s[1]] += u[1];
            vals[s[2]] += u[2] + self.shift;
        }
        // small blocks: sequential kernels, the frames themselves run in parallel
        self.analysis
            .factor(&b, Parallelism::Sequential)
            .map_err(|e| {
                if is_out_of_memory(&e) {
                    Error::Numerical("out of memory factoring a frame".into())
                } else {
                    Error::Numerical(format!("a frame block is not positive definite: {e:?}"))
                }
            })
    }
}

/// Frames factored between two cancellation points of [`FrameBlocks::factor`]: a refactor of
/// 50 frames of 1000 vertices took 0.35 s at load 7 on 2 cores in one piece.
const FACTOR_BATCH: usize = 8;

/// The symmetric block Gauss–Seidel preconditioner `M = (D + L) D⁻¹ (D + Lᵀ)` (module docs).
pub(super) struct TimeGaussSeidel<'a> {
    blocks: &'a FrameBlocks,
    /// Cholesky factor per frame (sequential kernels; analysis: `blocks.analysis`).
    factors: Vec<Cholesky>,
}

impl TimeGaussSeidel<'_> {
    /// `M⁻¹ r` for the red–black ordering of the frames (even-indexed frames first, then odd):
    /// the forward sweep solves the even frames, `y_e = B_e⁻¹ r_e`, then the odd ones,
    /// `y_o = B_o⁻¹ (r_o + C (y_{o−1} + y_{o+1}))`; the backward sweep corrects the even ones,
    /// `z_e = y_e + B_e⁻¹ C (y_{e−1} + y_{e+1})`, with `C = diag(2 w_s)` the time coupling.
    /// Frames of one colour do not touch each other, so each half-sweep runs in parallel.
    pub(super) fn apply(&self, r: &[f64]) -> Vec<f64> {
        let s = self.blocks.size;
        let mut y = r.to_vec();
        // even frames
        self.solve_colour(&mut y, 0, |_, _| {});
        // odd frames, from the even neighbours
        let even_y = y.clone();
        self.solve_colour(&mut y, 1, |i, v| self.add_neighbours(&even_y, i, v));
        // even frames again, corrected by the odd neighbours
        let mut t = vec![0.0; y.len()];
        let odd_y = &y;
        t.par_chunks_mut(s)
            .enumerate()
            .filter(|(i, _)| i % 2 == 0)
            .for_each_init(
                || self.solve_buffer(),
                |buf, (i, ti)| {
                    self.add_neighbours(odd_y, i, ti);
                    self.factors[i].solve_in_place_with(ti, buf);
                },
            );
        y.par_chunks_mut(s)
            .zip(t.par_chunks(s))
            .enumerate()
            .filter(|(i, _)| i % 2 == 0)
            .for_each(|(_, (yi, ti))| yi.iter_mut().zip(ti).for_each(|(a, b)| *a += b));
        y
    }

    /// `v += C (x_{i−1} + x_{i+1})` (missing neighbours are the fixed keyframes: nothing).
    fn add_neighbours(&self, x: &[f64], i: usize, v: &mut [f64]) {
        let s = self.blocks.size;
        let c = &self.blocks.coupling;
        let m = self.factors.len();
        for nb in [i.wrapping_sub(1), i + 1] {
            if nb < m {
                let xn = &x[nb * s..(nb + 1) * s];
                for (k, vk) in v.iter_mut().enumerate() {
                    *vk += c[k / 2] * xn[k];
                }
            }
        }
    }

    /// Frames `i ≡ parity (mod 2)`: `y_i ← B_i⁻¹ (y_i + extra(i))`, in parallel.
    fn solve_colour(&self, y: &mut [f64], parity: usize, extra: impl Fn(usize, &mut [f64]) + Sync) {
        let s = self.blocks.size;
        y.par_chunks_mut(s)
            .enumerate()
            .filter(|(i, _)| i % 2 == parity)
            .for_each_init(
                || self.solve_buffer(),
                |buf, (i, yi)| {
                    extra(i, yi);
                    self.factors[i].solve_in_place_with(yi, buf);
                },
            );
    }

    fn solve_buffer(&self) -> SolveScratch {
        self.blocks.analysis.solve_scratch(Parallelism::Sequential)
    }
}
