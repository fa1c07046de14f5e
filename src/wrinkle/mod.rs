//! Complex wrinkle fields (dissertation ch. 3): representation, energies, phase from frequency,
//! and evaluation of the wrinkled surface by Loop upsampling.
//!
//! - [`Cwf`] ([`cwf`]): the representation of §3.3.1 — frequency one-form `ω` per edge,
//!   amplitude `a` and phase `z̃` per vertex on a validated manifold base mesh — with
//!   `E_compat` (eq. 3.5), `E_unit` (eq. 3.6) and the split `ω = ω_com + δω` (eq. 3.17).
//! - [`knoppel`]: `z̃` from `ω` (Knöppel et al. 2015) by inverse iteration on a cached sparse
//!   Cholesky factorization; [`Cwf::from_frequency_field`] builds a CWF from wave vectors.
//! - [`subdivide`]: Loop subdivision S0, the one-form subdivision S1 with `S1 d = d S0`, and
//!   the z rules of eqs. 3.18–3.24 (derivations in its docs); [`LoopHierarchy`] exposes them
//!   level by level.
//! - [`evaluate`]: [`Cwf::evaluate`] — `levels` refinements, then the displacement
//!   `Re(z) n̂` of §3.5.
//! - [`io`]: the `.cwf` text format ([`write_cwf`], [`read_cwf`]).
//! - [`interpolate`](mod@interpolate): animation between two keyframes (§3.4) — the explicit
//!   `ω(t)`, linear `a(t)` and the spacetime phase solve — giving a [`CwfAnimation`]
//!   ([`animation`]: frames at any `t`, the `.cwfa` format).
//!
//! **Edge convention.** Every one-form (input, file, outputs, every subdivision level) is one
//! value per edge of [`TriMesh::edges`](crate::mesh::TriMesh::edges): edges sorted by
//! `(min vertex, max vertex)`, value integrated from the smaller to the larger vertex index.
//!
//! ```
//! use pleat::mesh::TriMesh;
//! use pleat::wrinkle::{Cwf, EvalOptions, FrequencyField, KnoppelOptions};
//! let base = TriMesh::new(
//!     vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
//!     vec![[0, 1, 2], [0, 2, 3]],
//! )?;
//! let k = [[12.0, 0.0, 0.0]; 4]; // wave vector per vertex
//! let (cwf, _) = Cwf::from_frequency_field(
//!     base, FrequencyField::PerVertex(&k), vec![0.01; 4], &KnoppelOptions::default())?;
//! let (wrinkled, stats) = cwf.evaluate(3, &EvalOptions::default())?;
//! assert_eq!(wrinkled.mesh.triangle_count(), 2 * 64);
//! # let _ = stats;
//! # Ok::<(), pleat::Error>(())
//! ```

pub mod animation;
mod areas;
mod complex;
pub mod cwf;
pub mod design;
pub mod edit;
pub mod evaluate;
pub mod interpolate;
pub mod io;
pub mod knoppel;
mod omega_path;
pub mod region;
pub mod report;
mod spacetime;
mod spd;
pub mod subdivide;
mod topology;

pub use animation::{
    animation_to_string, parse_animation, read_animation, write_animation, CwfAnimation,
    ANIMATION_FORMAT_VERSION,
};
pub use complex::Complex;
pub use cwf::{one_form_from_vectors, Cwf, FrequencyField, OmegaDecomposition};
pub use design::{design, design_with_progress, DesignOptions, DesignReport, WrinkleSource};
pub use edit::{
    edit, edit_with_progress, EditOptions, EditReport, PhaseCoupling, RegionEdit,
    DEFAULT_COMPAT_TARGET,
};
pub use evaluate::{EvalOptions, Evaluated};
pub use interpolate::{
    explicit_omega, interpolate, interpolate_with_progress, linear_interpolation,
    unchanged_vertices, HessianModel, InterpOptions, InterpReport, IterationRecord, StopReason,
};
pub use io::{
    connectivity_hash, cwf_to_string, parse_cwf, read_cwf, write_cwf, CWF_FORMAT_VERSION,
};
pub use knoppel::{KnoppelOptions, KnoppelReport, PhaseWeights};
pub use region::{grow_faces, Adjacency, FaceClass};
pub use report::{CwfStage, EvalReport, EvalStage, InterpStage, LevelPart, LevelReport};
pub use subdivide::{BoundaryRule, LoopHierarchy, SubdivisionOptions};
