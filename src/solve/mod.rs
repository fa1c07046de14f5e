//! Numerics shared by pleat's solvers: sparse symmetric positive definite factorization
//! ([`sparse`]), inverse iteration for the smallest eigenpair ([`eigen`]) and Krylov methods on
//! plain vectors ([`krylov`]: the N-dimensional dot product, Steihaug–Toint CG). The
//! factorization and the eigen solver report what they did in an info struct (parameters struct with `Default` in, info struct out, in the style
//! of faer's `CgParams`/`CgInfo`).
//!
//! Users: the Knöppel phase solve and the keyframe interpolation of [`crate::wrinkle`]. The
//! clarabel QP wrapper joins this module with the tension-field wrinkles (TFW) when that code
//! lands; it is not written yet.
//!
//! Built with the features that need faer (currently `wrinkle`).
//!
//! May import: `faer`, `rayon` (a background thread's pool, [`run_stoppable`]), `crate::error` (the crate's `Error`/`Result`). Nothing else of the crate.

pub mod eigen;
pub mod krylov;
pub mod sparse;

pub use eigen::{
    inverse_iteration, inverse_iteration_with_stop, InverseIterationError, InverseIterationInfo,
    InverseIterationParams, ShiftedProblem,
};
pub use krylov::{dot_n, steihaug, steihaug_with_stop, TrustStep};
pub use sparse::{
    assemble, entry_index, is_out_of_memory, run_stoppable, sym_matvec_lower_into, AssemblyPlan,
    Cholesky, CholeskyAnalysis, Entry, FactorInfo, LltError, Parallelism, ShiftSchedule,
    SolveScratch, SparseMatrix, STOPPABLE_FACTOR_LEN,
};
