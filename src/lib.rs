//! # pleat
//!
//! LODs by screen size, cages, and complex wrinkle fields, with a stable C ABI.
//!
//! Capabilities (each a cargo feature; `default` enables all):
//! - `lod`: any triangle soup in, a watertight, manifold, self-intersection-free low-poly mesh
//!   out that is indistinguishable from the input at a given screen size (dissertation ch. 4).
//!   With it, [`transfer`]: the input's per-vertex attributes (UVs, colours, skin weights, morph
//!   deltas, ids) on a LOD's or cage's vertices.
//! - `cage`: the same, strictly enclosing the input without touching it (ch. 4.5.2).
//! - `wrinkle`: complex wrinkle fields — evaluation, interpolation, design (ch. 3); brings the
//!   numerics module [`solve`] (sparse Cholesky, inverse iteration, Krylov; faer).
//! - `cli`: the `pleat` command-line tool; `io-gltf`: glTF 2.0 reading and writing.
//!
//! - `bake`: textured LODs — UV atlas, baked materials and normal maps, glTF LOD chains.
//! - `tfw`: wrinkles from physics (ch. 2) — scenes and the tension-field base surface solve
//!   ([`tfw`]); builds on `wrinkle` and [`solve`].
//!
//! The mesh core ([`mesh`], [`spatial`]) and the independent verifier ([`verify`]) are always
//! present.
//!
//! ## Layers
//!
//! Each module imports only the layers below it (checked by `tests/import_graph.rs`):
//! [`geom`] (the one vector type), `error` and [`report`] at the bottom; then [`mesh`];
//! [`spatial`] (the only user of parry's types); [`verify`] (independent checks, never a
//! pipeline); the pipelines `lowpoly` → `cage` → `bake` (`bake` also uses `transfer`), `wrinkle` → `solve`, and `tfw` →
//! `wrinkle`, `solve`; [`ffi`] and
//! the CLI on top. docs/guide/architecture.md has the table.
//!
//! ```
//! use pleat::mesh::TriMesh;
//! let m = TriMesh::new(
//!     vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
//! )?;
//! assert_eq!(m.edges().len(), 6);
//! # Ok::<(), pleat::Error>(())
//! ```

#![warn(missing_docs)]

mod error;
pub mod geom;
pub mod mesh;
pub mod report;
pub mod spatial;
pub mod verify;

#[cfg(feature = "lod")]
pub mod lowpoly;

#[cfg(feature = "lod")]
pub mod transfer;

#[cfg(feature = "cage")]
pub mod cage;

#[cfg(feature = "bake")]
pub mod bake;

#[cfg(feature = "wrinkle")]
pub mod wrinkle;

#[cfg(feature = "tfw")]
pub mod tfw;

// Numerics (faer): built with the features that need it.
#[cfg(feature = "wrinkle")]
pub mod solve;

pub mod ffi;

pub use error::{Error, Result};
pub use report::Progress;
