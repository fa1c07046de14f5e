//! The one error type of pleat. Every fallible operation returns [`Result`]; the C ABI maps each
//! variant to a `PleatStatus` code (see `ffi`), and its `Display` text becomes the message of
//! `pleat_last_error_message`.

use std::fmt;

/// Everything that can go wrong in pleat, with a readable reason.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A parameter is out of range, NULL, NaN, or inconsistent with another parameter.
    InvalidArgument(String),
    /// The mesh violates a precondition (index out of range, non-finite coordinate,
    /// non-manifold where a manifold mesh is required, ...).
    InvalidMesh(String),
    /// A file could not be opened, read or written.
    Io {
        /// The file concerned.
        path: String,
        /// What the operating system said.
        reason: String,
    },
    /// A file was read but its content could not be parsed.
    Parse {
        /// The file concerned.
        path: String,
        /// What is wrong with its content.
        reason: String,
    },
    /// A numerical method failed (factorization, non-convergence, non-finite result).
    Numerical(String),
    /// The caller's progress callback asked to stop.
    Cancelled,
    /// A size or memory limit set in the parameters would be exceeded.
    LimitExceeded(String),
    /// An allocation failed.
    OutOfMemory,
    /// A bug in pleat: please report it with the input that triggered it.
    Internal(String),
    /// This build was compiled without the capability (cargo feature) the call needs.
    Unsupported(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidArgument(m) => write!(f, "invalid argument: {m}"),
            Error::InvalidMesh(m) => write!(f, "invalid mesh: {m}"),
            Error::Io { path, reason } => write!(f, "cannot access '{path}': {reason}"),
            Error::Parse { path, reason } => write!(f, "cannot parse '{path}': {reason}"),
            Error::Numerical(m) => write!(f, "numerical failure: {m}"),
            Error::Cancelled => write!(f, "cancelled by the progress callback"),
            Error::LimitExceeded(m) => write!(f, "limit exceeded: {m}"),
            Error::OutOfMemory => write!(f, "out of memory"),
            Error::Internal(m) => write!(f, "internal error (a bug in pleat): {m}"),
            Error::Unsupported(m) => write!(f, "not supported by this build: {m}"),
        }
    }
}

impl std::error::Error for Error {}

/// `Result` with pleat's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

/// Shorthand for `Err(Error::InvalidArgument(..))` with `format!` arguments.
#[macro_export]
macro_rules! invalid_arg {
    ($($t:tt)*) => { Err($crate::Error::InvalidArgument(format!($($t)*))) };
}
