//! Sparse symmetric positive definite systems with faer's supernodal Cholesky `LLᵀ`: assemble a
//! matrix from triplets ([`assemble`]), analyse its pattern once ([`CholeskyAnalysis`]: fill-
//! reducing ordering, elimination tree, supernodes), then factor numerically as often as the
//! values change ([`CholeskyAnalysis::factor`]), optionally with a diagonal shift raised until
//! the matrix is numerically positive definite ([`CholeskyAnalysis::factor_with_growing_shift`]),
//! and solve ([`Cholesky::solve`]). Every factorization carries a [`FactorInfo`].
//!
//! Only the lower triangle of a matrix is read (entries above the diagonal are ignored), so a
//! caller may store the full matrix or its lower half.
//!
//! The calls are exactly those of faer's `sparse::linalg::solvers::Llt` (default ordering,
//! default regularization, faer's global parallelism or sequential kernels), so results do not
//! depend on which of the two a caller used.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky};
use faer::sparse::FaerError;
use faer::{Conj, Mat, MatMut, Par, Side};

use crate::{Error, Result};

/// Factor entries from which a numeric factorization is run by [`run_stoppable`] on a helper
/// thread, so that a cancel is seen within 0.5 s. Measured 2026-11-27 on the wrinkle design's
/// systems: Knöppel's factor on a 53k-face base has 4.4·10⁶ entries and takes 0.19 CPU s, so one of
/// 2¹⁹ entries takes a few hundredths of a second: the factorizations left on the calling thread
/// stay far below the 0.5 s cancellation bound, and small ones pay no thread start.
pub const STOPPABLE_FACTOR_LEN: usize = 1 << 19;

/// Stored matrix entries from which [`CholeskyAnalysis::new_stoppable`] runs the analysis (the
/// fill-reducing ordering) on a background thread: measured 2026-11-27, the analyses of the
/// wrinkle design's systems on a 213k-face base took 0.17–0.56 CPU s (matrices of 0.7–1.7·10⁶
/// entries), those of a 53k-face base a few hundredths.
pub const STOPPABLE_MATRIX_NNZ: usize = 1 << 19;

/// How often [`run_stoppable`] asks its `tick` while the work runs.
const STOPPABLE_POLL: std::time::Duration = std::time::Duration::from_millis(100);

/// Runs `work` and returns its value, with a cancellation point every 0.1 s while it runs (one
/// sparse Cholesky factorization has no cancellation point inside: 1.1 CPU s on a 213k-face wrinkle
/// base, more than the 0.5 s a cancel may wait). When `heavy`, `work` runs on a background thread,
/// inside a rayon pool of as many threads as the caller's (so faer's `Par::rayon(0)` there is the
/// caller's parallelism and the result is bit for bit the one of a call on this thread), while this
/// thread calls `tick()` every 0.1 s; its first error is returned at once, and the worker then
/// finishes `work` and drops its value (nothing is returned or kept: the thread owns everything
/// `work` captured). Otherwise `work` runs right here, without a `tick`. A panic in `work` is
/// re-raised on this thread.
pub fn run_stoppable<T: Send + 'static>(
    heavy: bool,
    work: impl FnOnce() -> T + Send + 'static,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<T> {
    if !heavy {
        return Ok(work());
    }
    let threads = rayon::current_num_threads();
    let (tx, rx) = std::sync::mpsc::channel::<std::thread::Result<T>>();
    std::thread::Builder::new()
        .name("pleat-factor".into())
        .spawn(move || {
            let run = || match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
                Ok(pool) => pool.install(work),
                Err(_) => work(),
            };
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(run));
            let _ = tx.send(r); // no receiver after a cancel: the value is dropped here
        })
        .map_err(|e| Error::Internal(format!("cannot start a factorization thread: {e}")))?;
    loop {
        match rx.recv_timeout(STOPPABLE_POLL) {
            Ok(Ok(v)) => return Ok(v),
            Ok(Err(panic)) => std::panic::resume_unwind(panic),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => tick()?,
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(Error::Internal("the factorization thread vanished".into()))
            }
        }
    }
}

/// Why a numeric factorization failed (faer's error: a non-positive pivot, or out of memory).
pub use faer::sparse::linalg::LltError;

/// True when `e` reports an allocation failure (not a numerical one).
pub fn is_out_of_memory(e: &LltError) -> bool {
    matches!(e, LltError::Generic(FaerError::OutOfMemory))
}

/// A real sparse matrix in compressed columns with `usize` indices (faer's `SparseColMat`).
pub type SparseMatrix = faer::sparse::SparseColMat<usize, f64>;

/// One `(row, column, value)` entry for [`assemble`] (faer's `Triplet`).
pub type Entry = faer::sparse::Triplet<usize, usize, f64>;

/// Assembles the `dim × dim` matrix with the given entries, summing duplicates. Errors
/// ([`Error::Numerical`] "assembling {what}: …") on an index out of range; `what` names the
/// matrix for the message.
pub fn assemble(dim: usize, entries: &[Entry], what: &str) -> Result<SparseMatrix> {
    SparseMatrix::try_new_from_triplets(dim, dim, entries)
        .map_err(|e| Error::Numerical(format!("assembling {what}: {e:?}")))
}

/// A fixed pattern and the order that sums a list of entries into it (faer's argsort), for
/// matrices re-assembled many times with the same entries in the same order and only the
/// values changing (Newton iterations): [`AssemblyPlan::new`] sorts the indices once,
/// [`AssemblyPlan::assemble`] then fills the values without sorting.
#[derive(Debug, Clone)]
pub struct AssemblyPlan {
    symbolic: faer::sparse::SymbolicSparseColMat<usize>,
    argsort: faer::sparse::Argsort<usize>,
    entries: usize,
}

impl AssemblyPlan {
    /// The plan of the `dim × dim` matrix with the indices of `entries` (their values are
    /// ignored). Errors as [`assemble`].
    pub fn new(dim: usize, entries: &[Entry], what: &str) -> Result<AssemblyPlan> {
        let idx: Vec<faer::sparse::Pair<usize, usize>> = entries
            .iter()
            .map(|e| faer::sparse::Pair::new(e.row, e.col))
            .collect();
        let (symbolic, argsort) =
            faer::sparse::SymbolicSparseColMat::try_new_from_indices(dim, dim, &idx)
                .map_err(|e| Error::Numerical(format!("assembling {what}: {e:?}")))?;
        Ok(AssemblyPlan {
            symbolic,
            argsort,
            entries: entries.len(),
        })
    }

    /// The matrix whose entry `k` (indices as given to [`AssemblyPlan::new`]) has the value
    /// `values[k]`, duplicates summed: the matrix [`assemble`] gives for those entries.
    /// Errors ([`Error::InvalidArgument`]) when the count differs from the plan's.
    pub fn assemble(&self, values: &[f64]) -> Result<SparseMatrix> {
        if values.len() != self.entries {
            return Err(Error::InvalidArgument(format!(
                "assembly plan of {} entries given {} values",
                self.entries,
                values.len()
            )));
        }
        SparseMatrix::new_from_argsort(self.symbolic.clone(), &self.argsort, values)
            .map_err(|e| Error::Numerical(format!("assembling: {e:?}")))
    }
}

/// Index into `a.val()` of the stored entry `(row, col)`, or `None` when it is not in the
/// pattern.
pub fn entry_index(a: &SparseMatrix, row: usize, col: usize) -> Option<usize> {
    let cp = a.symbolic().col_ptr();
    let rows = &a.symbolic().row_idx()[cp[col]..cp[col + 1]];
    rows.binary_search(&row).ok().map(|k| cp[col] + k)
}

/// `y = H v` for a symmetric `H` stored as its lower triangle (`y` overwritten): each stored
/// `h_ij` (i ≥ j) contributes `h_ij v_j` to `y_i` and, off the diagonal, `h_ij v_i` to `y_j`.
pub fn sym_matvec_lower_into(h: &SparseMatrix, v: &[f64], y: &mut [f64]) {
    let cp = h.symbolic().col_ptr();
    let ri = h.symbolic().row_idx();
    let val = h.val();
    y.iter_mut().for_each(|x| *x = 0.0);
    for j in 0..v.len() {
        let mut acc = 0.0;
        for k in cp[j]..cp[j + 1] {
            let (i, a) = (ri[k], val[k]);
            y[i] += a * v[j];
            if i != j {
                acc += a * v[i];
            }
        }
        y[j] += acc;
    }
}

/// Which kernels a factorization and its solves use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Parallelism {
    /// faer's global parallelism (all threads of its pool unless the host changed it).
    #[default]
    Global,
    /// Sequential kernels: for many small systems that are themselves processed in parallel.
    Sequential,
}

impl Parallelism {
    fn par(self) -> Par {
        match self {
            Parallelism::Global => faer::get_global_parallelism(),
            Parallelism::Sequential => Par::Seq,
        }
    }
}

/// What one numeric factorization was and cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorInfo {
    /// Number of rows (= columns) of the matrix.
    pub dim: usize,
    /// Stored entries of the matrix (both triangles as given).
    pub matrix_nnz: usize,
    /// Stored entries of the Cholesky factor `L`.
    pub factor_nnz: usize,
    /// The diagonal shift σ added before factoring (`A + σW`, see
    /// [`CholeskyAnalysis::factor_shifted`]); 0 for an unshifted factorization.
    pub shift: f64,
    /// Factorizations tried to get this one (1 unless the shift had to be raised).
    pub attempts: usize,
    /// Wall-clock seconds of the numeric factorization(s).
    pub seconds: f64,
}

/// How [`CholeskyAnalysis::factor_with_growing_shift`] raises the shift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShiftSchedule {
    /// The first shift σ tried.
    pub initial: f64,
    /// σ is multiplied by this after each failed attempt.
    pub growth: f64,
    /// Attempts before giving up (at least 1).
    pub max_attempts: usize,
}

impl Default for ShiftSchedule {
    /// σ = 1e-9, multiplied by 100 up to 4 times (5 attempts).
    fn default() -> Self {
        ShiftSchedule {
            initial: 1e-9,
            growth: 100.0,
            max_attempts: 5,
        }
    }
}

/// The symbolic Cholesky analysis of one sparsity pattern (lower triangle read), computed once
/// and shared by every numeric factorization of matrices with that pattern. Cheap to clone.
#[derive(Debug, Clone)]
pub struct CholeskyAnalysis {
    symbolic: Arc<SymbolicCholesky<usize>>,
    /// Value index of each diagonal entry in the analysed pattern.
    diagonal: Arc<Vec<usize>>,
    /// Scratch buffers of the numeric factorizations and solves, kept between calls (a
    /// Newton solve factors and solves with one pattern hundreds of times; allocating the
    /// scratch each time cost page faults). Shared by the clones; never read before faer
    /// writes it, so it does not change any result.
    scratch: Arc<ScratchPool>,
}

/// A few scratch buffers, each with the requirement it was made for (reused only for the
/// same requirement).
#[derive(Default)]
struct ScratchPool(Mutex<Vec<(StackReq, MemBuffer)>>);

impl std::fmt::Debug for ScratchPool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ScratchPool")
    }
}

/// Buffers a pool keeps at most (one for factoring, one for solving, a spare for a
/// concurrent caller).
const SCRATCH_POOL_LEN: usize = 3;

impl ScratchPool {
    /// Runs `work` on a buffer of requirement `req`: a pooled one when there is one of that
    /// requirement, else a new one (`None` when it cannot be allocated); the buffer goes back
    /// to the pool afterwards.
    fn with<T>(&self, req: StackReq, work: impl FnOnce(&mut MemBuffer) -> T) -> Option<T> {
        let pooled = {
            let mut pool = self.0.lock().unwrap_or_else(|e| e.into_inner());
            pool.iter()
                .position(|(r, _)| *r == req)
                .map(|k| pool.swap_remove(k).1)
        };
        let mut buf = match pooled {
            Some(b) => b,
            None => MemBuffer::try_new(req).ok()?,
        };
        let out = work(&mut buf);
        let mut pool = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if pool.len() < SCRATCH_POOL_LEN {
            pool.push((req, buf));
        }
        Some(out)
    }
}

impl CholeskyAnalysis {
    /// Analyses the pattern of `a` (square; its values are not read). Errors
    /// ([`Error::Numerical`]) when faer's analysis fails or a diagonal entry is missing from the
    /// pattern (such a matrix cannot be positive definite).
    pub fn new(a: &SparseMatrix) -> Result<CholeskyAnalysis> {
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| Error::Numerical(format!("symbolic Cholesky analysis failed: {e:?}")))?;
        let diagonal = (0..a.ncols())
            .map(|i| {
                entry_index(a, i, i).ok_or_else(|| {
                    Error::Numerical(format!(
                        "symbolic Cholesky analysis: the pattern misses diagonal entry {i}"
                    ))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(CholeskyAnalysis {
            symbolic: Arc::new(symbolic),
            diagonal: Arc::new(diagonal),
            scratch: Arc::default(),
        })
    }

    /// [`new`](Self::new) with `tick` as a cancellation point every 0.1 s ([`run_stoppable`])
    /// when `a` has at least [`STOPPABLE_MATRIX_NNZ`] stored entries; the same analysis.
    pub fn new_stoppable(
        a: &Arc<SparseMatrix>,
        tick: &mut dyn FnMut() -> Result<()>,
    ) -> Result<CholeskyAnalysis> {
        let shared = a.clone();
        let heavy = a.val().len() >= STOPPABLE_MATRIX_NNZ;
        run_stoppable(heavy, move || CholeskyAnalysis::new(&shared), tick)?
    }

    /// Number of rows (= columns) of the analysed pattern.
    pub fn dim(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Stored entries of the Cholesky factor `L` of this pattern (the size of every numeric
    /// factorization: its cost grows with it).
    pub fn factor_len(&self) -> usize {
        self.symbolic.len_val()
    }

    /// True when a numeric factorization of this pattern is long enough to run on a helper
    /// thread with cancellation polling ([`run_stoppable`]): at least
    /// [`STOPPABLE_FACTOR_LEN`] factor entries.
    pub fn is_heavy(&self) -> bool {
        self.factor_len() >= STOPPABLE_FACTOR_LEN
    }

    /// Numeric factorization of `a`, which must have the analysed pattern. Fails when `a` is
    /// not numerically positive definite (or memory runs out).
    pub fn factor(
        &self,
        a: &SparseMatrix,
        par: Parallelism,
    ) -> std::result::Result<Cholesky, LltError> {
        let start = Instant::now();
        let values = self.factor_values(a, par)?;
        Ok(self.cholesky(values, par, a, 0.0, 1, start))
    }

    /// Numeric factorization of `A + σ W`, `W` the diagonal matrix of `weights` (one per row):
    /// `σ w_i` is added to the stored `a_ii` (one rounding per diagonal entry). `a` must have
    /// the analysed pattern.
    pub fn factor_shifted(
        &self,
        a: &SparseMatrix,
        sigma: f64,
        weights: &[f64],
        par: Parallelism,
    ) -> std::result::Result<Cholesky, LltError> {
        let start = Instant::now();
        let shifted = self.shifted(a, sigma, weights);
        let values = self.factor_values(&shifted, par)?;
        Ok(self.cholesky(values, par, a, sigma, 1, start))
    }

    /// [`factor_shifted`](Self::factor_shifted) with `σ = schedule.initial`, multiplied by
    /// `schedule.growth` after each failure, up to `schedule.max_attempts` attempts. The
    /// result's [`FactorInfo`] records the σ that worked and the attempts; the error is that of
    /// the last attempt.
    pub fn factor_with_growing_shift(
        &self,
        a: &SparseMatrix,
        weights: &[f64],
        schedule: ShiftSchedule,
        par: Parallelism,
    ) -> std::result::Result<Cholesky, LltError> {
        let start = Instant::now();
        let mut sigma = schedule.initial;
        let mut last = LltError::Generic(FaerError::IndexOverflow);
        for attempt in 1..=schedule.max_attempts.max(1) {
            let shifted = self.shifted(a, sigma, weights);
            match self.factor_values(&shifted, par) {
                Ok(values) => return Ok(self.cholesky(values, par, a, sigma, attempt, start)),
                Err(e) => last = e,
            }
            sigma *= schedule.growth;
        }
        Err(last)
    }

    /// Scratch space for [`Cholesky::solve_in_place_with`] (one per thread).
    pub fn solve_scratch(&self, par: Parallelism) -> SolveScratch {
        SolveScratch(MemBuffer::new(
            self.symbolic.solve_in_place_scratch::<f64>(1, par.par()),
        ))
    }

    fn shifted(&self, a: &SparseMatrix, sigma: f64, weights: &[f64]) -> SparseMatrix {
        let mut b = a.clone();
        let vals = b.val_mut();
        for (&slot, &w) in self.diagonal.iter().zip(weights) {
            vals[slot] += sigma * w;
        }
        b
    }

    fn factor_values(
        &self,
        a: &SparseMatrix,
        par: Parallelism,
    ) -> std::result::Result<Vec<f64>, LltError> {
        let sym = &self.symbolic;
        let par = par.par();
        let mut values = Vec::new();
        values
            .try_reserve_exact(sym.len_val())
            .map_err(|_| LltError::Generic(FaerError::OutOfMemory))?;
        values.resize(sym.len_val(), 0.0);
        let req = sym.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        self.scratch
            .with(req, |buf| {
                sym.factorize_numeric_llt(
                    &mut values,
                    a.as_ref(),
                    Side::Lower,
                    LltRegularization::default(),
                    par,
                    MemStack::new(buf),
                    Default::default(),
                )
            })
            .ok_or(LltError::Generic(FaerError::OutOfMemory))??;
        Ok(values)
    }

    fn cholesky(
        &self,
        values: Vec<f64>,
        par: Parallelism,
        a: &SparseMatrix,
        shift: f64,
        attempts: usize,
        start: Instant,
    ) -> Cholesky {
        let info = FactorInfo {
            dim: self.dim(),
            matrix_nnz: a.val().len(),
            factor_nnz: values.len(),
            shift,
            attempts,
            seconds: start.elapsed().as_secs_f64(),
        };
        Cholesky {
            analysis: self.clone(),
            values,
            par,
            info,
        }
    }
}

/// A numeric Cholesky factorization `A = LLᵀ` (on the analysis' fill-reducing permutation).
#[derive(Debug, Clone)]
pub struct Cholesky {
    analysis: CholeskyAnalysis,
    values: Vec<f64>,
    par: Parallelism,
    info: FactorInfo,
}

/// Reusable scratch space for [`Cholesky::solve_in_place_with`].
pub struct SolveScratch(MemBuffer);

impl Cholesky {
    /// What the factorization was and cost.
    pub fn info(&self) -> &FactorInfo {
        &self.info
    }

    /// `A⁻¹ b` (`b` has [`FactorInfo::dim`] entries), with the factorization's parallelism.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = b.len();
        let mut m = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
        let par = self.par.par();
        let sym = &self.analysis.symbolic;
        let req = sym.solve_in_place_scratch::<f64>(1, par);
        let mut run = |buf: &mut MemBuffer| {
            LltRef::new(sym, &self.values).solve_in_place_with_conj(
                Conj::No,
                m.as_mut(),
                par,
                MemStack::new(buf),
            )
        };
        if self.analysis.scratch.with(req, &mut run).is_none() {
            run(&mut MemBuffer::new(req)); // panics on allocation failure, as before
        }
        (0..n).map(|i| m[(i, 0)]).collect()
    }

    /// `x ← A⁻¹ x` in place, using `scratch` (from [`CholeskyAnalysis::solve_scratch`] with the
    /// same parallelism) instead of allocating.
    pub fn solve_in_place_with(&self, x: &mut [f64], scratch: &mut SolveScratch) {
        let len = x.len();
        LltRef::new(&self.analysis.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, len, 1),
            self.par.par(),
            MemStack::new(&mut scratch.0),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 1-D Laplacian with Dirichlet ends (SPD), full storage.
    fn laplacian(n: usize) -> SparseMatrix {
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Entry::new(i, i, 2.0));
            if i + 1 < n {
                t.push(Entry::new(i + 1, i, -1.0));
                t.push(Entry::new(i, i + 1, -1.0));
            }
        }
        assemble(n, &t, "a test matrix").unwrap()
    }

    /// The plan gives the matrix `assemble` gives (duplicates summed, any order), for new
    /// values too, and refuses a different count.
    #[test]
    fn assembly_plan_matches_assemble() {
        let mut t = vec![
            Entry::new(2, 1, 1.0),
            Entry::new(0, 0, 2.0),
            Entry::new(2, 1, 0.5),
            Entry::new(1, 1, 3.0),
            Entry::new(2, 2, 4.0),
        ];
        let plan = AssemblyPlan::new(3, &t, "a test matrix").unwrap();
        for scale in [1.0, -2.5] {
            t.iter_mut().for_each(|e| e.val *= scale);
            let vals: Vec<f64> = t.iter().map(|e| e.val).collect();
            let a = plan.assemble(&vals).unwrap();
            let b = assemble(3, &t, "a test matrix").unwrap();
            assert_eq!(a.symbolic().col_ptr(), b.symbolic().col_ptr());
            assert_eq!(a.symbolic().row_idx(), b.symbolic().row_idx());
            assert_eq!(a.val(), b.val());
        }
        assert!(plan.assemble(&[1.0]).is_err());
    }

    /// The 5-point Laplacian of an `n × n` grid plus the identity (SPD), full storage.
    fn grid_laplacian(n: usize) -> SparseMatrix {
        let id = |i: usize, j: usize| i * n + j;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                t.push(Entry::new(id(i, j), id(i, j), 5.0));
                for (di, dj) in [(1, 0), (0, 1)] {
                    if i + di < n && j + dj < n {
                        t.push(Entry::new(id(i + di, j + dj), id(i, j), -1.0));
                        t.push(Entry::new(id(i, j), id(i + di, j + dj), -1.0));
                    }
                }
            }
        }
        assemble(n * n, &t, "a test matrix").unwrap()
    }

    #[test]
    fn a_factorization_on_the_helper_thread_is_bitwise_the_same() {
        let a = grid_laplacian(60);
        let an = CholeskyAnalysis::new(&a).unwrap();
        let b: Vec<f64> = (0..a.ncols()).map(|i| (i as f64 * 0.37).sin()).collect();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let here = pool.install(|| an.factor(&a, Parallelism::Global).unwrap().solve(&b));
            let there = pool.install(|| {
                let (an, a) = (an.clone(), a.clone());
                let work = move || an.factor(&a, Parallelism::Global).unwrap();
                run_stoppable(true, work, &mut || Ok(())).unwrap().solve(&b)
            });
            let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&here), bits(&there), "{threads} threads");
        }
    }

    #[test]
    fn stoppable_work_answers_a_cancel_while_it_runs() {
        // The work waits until released after the return: a cancel must not wait for it.
        let (release, wait) = std::sync::mpsc::channel::<()>();
        let (done_tx, done) = std::sync::mpsc::channel::<()>();
        let work = move || {
            let _ = wait.recv();
            let _ = done_tx.send(());
            7
        };
        let mut ticks = 0;
        let r = run_stoppable(true, work, &mut || {
            ticks += 1;
            if ticks < 3 {
                Ok(())
            } else {
                Err(Error::Cancelled)
            }
        });
        assert!(matches!(r, Err(Error::Cancelled)), "{r:?}");
        assert_eq!(ticks, 3);
        release.send(()).unwrap();
        done.recv().unwrap(); // the helper finished on its own
                              // light work runs here, without a tick
        let r = run_stoppable(false, || 5, &mut || panic!("no tick for light work"));
        assert_eq!(r.unwrap(), 5);
        // a panic of the work reaches the caller
        let p = std::panic::catch_unwind(|| {
            run_stoppable(true, || -> u32 { panic!("boom") }, &mut || Ok(()))
        });
        assert!(p.is_err());
    }

    #[test]
    fn solves_and_reports() {
        let a = laplacian(50);
        let an = CholeskyAnalysis::new(&a).unwrap();
        let f = an.factor(&a, Parallelism::Global).unwrap();
        let b: Vec<f64> = (0..50).map(|i| (i as f64).sin()).collect();
        let x = f.solve(&b);
        // residual of the tridiagonal system
        for i in 0..50 {
            let mut r = 2.0 * x[i] - b[i];
            if i > 0 {
                r -= x[i - 1];
            }
            if i + 1 < 50 {
                r -= x[i + 1];
            }
            assert!(r.abs() < 1e-12, "row {i}: {r}");
        }
        assert_eq!(
            (f.info().dim, f.info().shift, f.info().attempts),
            (50, 0.0, 1)
        );
        let mut y = b.clone();
        let seq = an.factor(&a, Parallelism::Sequential).unwrap();
        seq.solve_in_place_with(&mut y, &mut an.solve_scratch(Parallelism::Sequential));
        assert!(y.iter().zip(&x).all(|(p, q)| (p - q).abs() < 1e-12));
    }

    #[test]
    fn shift_is_raised_until_definite() {
        // −L is negative definite: needs σ > 4 with unit weights
        let mut a = laplacian(20);
        a.val_mut().iter_mut().for_each(|v| *v = -*v);
        let an = CholeskyAnalysis::new(&a).unwrap();
        assert!(an.factor(&a, Parallelism::Global).is_err());
        let schedule = ShiftSchedule {
            initial: 1e-3,
            growth: 10.0,
            max_attempts: 5,
        };
        let f = an
            .factor_with_growing_shift(&a, &[1.0; 20], schedule, Parallelism::Global)
            .unwrap();
        assert_eq!(f.info().attempts, 5);
        assert!(f.info().shift > 4.0 && f.info().shift < 11.0);
        let too_few = ShiftSchedule {
            max_attempts: 3,
            ..schedule
        };
        assert!(an
            .factor_with_growing_shift(&a, &[1.0; 20], too_few, Parallelism::Global)
            .is_err());
    }

    /// The factorization and solve are bit for bit those of faer's high-level `Llt` (which the
    /// wrinkle solvers called before this module existed).
    #[test]
    fn bitwise_equal_to_faer_llt() {
        use faer::linalg::solvers::Solve;
        use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
        // a 2-D grid Laplacian plus a varying diagonal: supernodes with real dense blocks
        let n = 30;
        let id = |i: usize, j: usize| i * n + j;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                t.push(Entry::new(id(i, j), id(i, j), 4.1 + (i * j) as f64 * 1e-3));
                if i + 1 < n {
                    t.push(Entry::new(id(i + 1, j), id(i, j), -1.0 - 1e-3 * j as f64));
                }
                if j + 1 < n {
                    t.push(Entry::new(id(i, j + 1), id(i, j), -0.7));
                }
            }
        }
        let a = assemble(n * n, &t, "a test matrix").unwrap();
        let b: Vec<f64> = (0..n * n).map(|i| (i as f64 * 0.37).cos()).collect();
        let ours = CholeskyAnalysis::new(&a)
            .unwrap()
            .factor(&a, Parallelism::Global)
            .unwrap()
            .solve(&b);
        let sym = SymbolicLlt::try_new(a.symbolic(), Side::Lower).unwrap();
        let llt = Llt::try_new_with_symbolic(sym, a.as_ref(), Side::Lower).unwrap();
        let mut m = Mat::<f64>::from_fn(n * n, 1, |i, _| b[i]);
        llt.solve_in_place(&mut m);
        let theirs: Vec<f64> = (0..n * n).map(|i| m[(i, 0)]).collect();
        assert!(ours
            .iter()
            .zip(&theirs)
            .all(|(x, y)| x.to_bits() == y.to_bits()));
    }

    #[test]
    fn missing_diagonal_is_refused() {
        let a = assemble(2, &[Entry::new(1, 0, 1.0), Entry::new(0, 0, 1.0)], "m").unwrap();
        let err = CholeskyAnalysis::new(&a).unwrap_err();
        assert!(err.to_string().contains("diagonal entry 1"), "{err}");
        assert_eq!(entry_index(&a, 1, 0), Some(1));
    }
}
