//! The C ABI: the only place with `extern "C"`. Thin wrappers over the safe Rust API.
//!
//! Conventions (see docs/guide/c-abi.md):
//! - Every fallible function returns [`PleatStatus`]; outputs are written only on success; the
//!   reason of the last failure on the calling thread is available from
//!   [`pleat_last_error`] / [`pleat_last_error_message`].
//! - Every entry point runs inside `catch_unwind`: a panic becomes
//!   `PLEAT_STATUS_INTERNAL`, never an abort of the host. The one fence is `common::guard` /
//!   `common::guard_progress`; argument checks, versioned structs (`struct_size`) and handle
//!   outputs go through the helpers of `boundary`, so each export is a few lines of real work.
//! - The C defaults (`pleat_*_params_default`) are conversions of the Rust parameters'
//!   `Default`; the test module `defaults` checks every one round-trips.
//! - Every pointer is checked for NULL, every count against overflow and the data it describes,
//!   every coordinate for NaN/Inf. Pointers that are non-NULL but invalid cannot be detected:
//!   they are the caller's responsibility, as in any C API.
//! - Work runs on pleat's own thread pool ([`pleat_set_thread_count`]); callbacks run on the
//!   calling thread only.
//! - The ABI is the same whatever cargo features the library was built with: a function whose
//!   capability was left out returns `PLEAT_STATUS_UNSUPPORTED`.

mod bake;
mod boundary;
mod common;
mod deform;
mod design;
mod edges;
mod interpolate;
mod lod;
mod mesh;
mod offset;
mod report;
mod stats;
mod tfw;
mod transfer;
mod wrinkle;

pub use bake::*;
pub use common::*;
pub use deform::*;
pub use design::*;
pub use edges::*;
pub use interpolate::*;
pub use lod::*;
pub use mesh::*;
pub use offset::*;
pub use report::*;
pub use stats::*;
pub use tfw::*;
pub use transfer::*;
pub use wrinkle::*;

#[cfg(test)]
mod defaults;
