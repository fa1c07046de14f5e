//! Tension-field wrinkles in the C ABI (capability `tfw`, dissertation ch. 2; Rust API
//! [`crate::tfw::solve`]).
//!
//! - `PleatTfwScene`: a validated scene (panels, material, loads, Dirichlet conditions), from a
//!   JSON file ([`pleat_tfw_scene_read_file`]), a JSON string ([`pleat_tfw_scene_from_json`])
//!   or arrays describing one panel ([`pleat_tfw_scene_from_arrays`]).
//! - [`pleat_tfw_solve`]: base surface → wrinkle-free faces, initialization → SQP → a complex
//!   wrinkle field, as a `PleatTfwResult`.
//! - Getters: the base mesh and the wrinkle field as the existing `PleatMesh` / `PleatCwf`
//!   handles (so `pleat_mesh_*` copies them out and `pleat_cwf_*` evaluates them), the
//!   wrinkled mesh ([`pleat_tfw_result_evaluate`], with the in-plane v2 term of eq. 2.19),
//!   stats ([`PleatTfwStats`]) and the SQP iteration history.
//!
//! Every function exists in every build; without `tfw` those that can fail return
//! `PLEAT_STATUS_UNSUPPORTED` (counts return 0).
//!
//! The C entry points of each concern sit with their implementation (an `imp` module built
//! only with `tfw`): `types.rs` (constants, handles, versioned structs and their defaults),
//! `scene.rs`, `solve.rs` and `result.rs` (the getters). This module declares them in that
//! order, which is the order of the C header (`include/pleat.h`), and re-exports them.

#![allow(clippy::too_many_arguments)]
// Builds without `tfw` compile only the UNSUPPORTED branches.
#![cfg_attr(not(feature = "tfw"), allow(unused_imports))]

/// Runs `$body` when built with `tfw`; otherwise `PLEAT_STATUS_UNSUPPORTED`.
macro_rules! tfw_only {
    ([$($arg:expr),*] $body:expr) => {
        requires!("tfw", [$($arg),*], $body)
    };
}

// In the order of the C header: cbindgen reads the modules in the order they are declared.
mod types;

mod scene;

mod solve;

mod result;

#[cfg(all(test, feature = "tfw"))]
mod tests;

pub use result::*;
pub use scene::*;
pub use solve::*;
pub use types::*;

/// The parameter conversion, as `ffi::defaults` reaches it.
#[cfg(all(test, feature = "tfw"))]
pub(super) use solve::imp;
#[cfg(test)]
pub(super) use types::defaults_without_tfw;
