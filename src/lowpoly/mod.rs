//! Low-poly meshes by screen size (dissertation ch. 4).
//!
//! Stage 2, the mesh-optimization loop (§4.3.2–4.3.3, Alg. 3–7): [`generate`] bakes one LOD,
//! [`generate_chain`] several. Every local operation of the loop — edge collapses
//! ([`simplify`](self) , Alg. 5), the flow (Alg. 3–4) and the feature alignment (Alg. 6, eq.
//! 4.5) — goes through one guard (`guard.rs`) that keeps the mesh watertight, manifold, of the
//! same topology and free of self-intersections, and in cage mode (`crate::cage`) disjoint
//! from the input and enclosing it.

mod align;
mod flow;
pub(crate) mod guard;
pub(crate) mod measure;
mod pipeline;
mod simplify;
mod vec3;

pub use guard::CONE_HALF_ANGLE;
pub use pipeline::{generate, generate_chain, LodParams};
#[cfg(feature = "cage")]
pub(crate) use pipeline::{run, run_chain, Mode};
