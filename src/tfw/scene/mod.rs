//! TFW problem setup: a [`Scene`] (flat panels with initial 3D positions, material, loads,
//! Dirichlet conditions), its JSON format ([`Scene::from_json_str`]), validation that names the
//! bad field, assembly of the panels into one stitched [`Model`] whose faces keep their own rest
//! form `Ī_f` (spec "Model and variables"), and the built-in scenes ([`Scene::stretched_sheet`],
//! [`Scene::twisted_cylinder`], [`Scene::sheared_rectangle`], the balloons
//! [`Scene::disk_balloon`] and [`Scene::torus_balloon`]).
//!
//! ## JSON format
//!
//! ```json
//! {
//!   "name": "sheet",
//!   "material": { "young": 1e6, "poisson": 0.5, "thickness": 1e-4, "density": 0 },
//!   "loads": { "gravity": [0, 0, -9.81], "pressure": 0 },
//!   "seam_tolerance": 1e-6,
//!   "panels": [ { "rest": [[0, 0], [1, 0], [0, 1]], "triangles": [[0, 1, 2]],
//!                 "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]] } ],
//!   "dirichlet": [ { "panel": 0, "vertices": [0, 1],
//!                    "translation": [0, 0, 0],
//!                    "rotation": { "axis": [0, 0, 1], "origin": [0, 0, 0], "degrees": 10 } } ]
//! }
//! ```
//! Optional `"obstacles": [ {"type": "sphere", "centre": [0, 0, 0], "radius": 0.2},
//! {"type": "plane", "point": [0, 0, -1], "normal": [0, 0, 1], "stiffness": 1e9, "margin": 0} ]`
//! ([`Obstacle`]: a one-sided cubic penalty in the base solve; `stiffness` in J/m⁵, default
//! [`DEFAULT_OBSTACLE_STIFFNESS`]; `margin` in m, default 0; errors name the field, e.g.
//! `scene: obstacles[0].radius: must be > 0`).
//! SI units. `loads`, `seam_tolerance`, `name`, `dirichlet`, a panel's `positions` (default:
//! the rest position at z = 0), a condition's `translation` and `rotation`, and
//! `material.density` (default 0) are optional. Unknown keys are errors. Panels are sewn by
//! merging vertices whose initial 3D positions lie within `seam_tolerance` (default 1e-6 m) of
//! each other, in or across panels (R: `Stitch.cpp` merges within 1e-5).
//!
//! **Panels meshed from an outline** (irregular Delaunay, [`crate::tfw::delaunay`]): instead of
//! `rest`/`triangles`/`positions`, a panel may give `"polygon": [[u, v], …]` (outer ring),
//! optional `"holes": [[[u, v], …], …]`, `"target_vertices": 700`, optional `"seed"` (default 0)
//! and optional `"roll_radius": r` (initial positions rolled onto the cylinder of radius `r`
//! about z, `(r cos(u/r), r sin(u/r), v)`; default `(u, v, 0)`). Its vertex numbers are then
//! not known in advance, so a Dirichlet condition may name vertices by
//! `"rest_box": [[umin, vmin], [umax, vmax]]` (the panel's vertices whose rest position lies
//! in the box, inclusive) instead of, or in addition to, `vertices`. Example:
//! `examples/tfw/twisted_cylinder.json`. Balloons: `"lens": h` (m, nonzero; not with
//! `roll_radius`) lifts the meshed panel into a thin lens ([`Panel::lens`]; `h < 0` also
//! reverses its triangles); two panels with the same outline and `h`, `−h` sew into a closed
//! balloon (`examples/tfw/disk_balloon.json`, `torus_balloon.json`). [`Scene::to_json_string`] writes the meshed panel.
//!
//! ## Files
//!
//! `description.rs` (the data), `validate.rs` (field checks and the field-error functions),
//! `assemble.rs` (panels stitched into the [`Model`]), `json.rs` (the format above, read and
//! written) and `builtin.rs` (the built-in scenes); they import each other without cycles, in
//! that order from the bottom. This module only declares them and re-exports their API.

mod assemble;
mod builtin;
mod description;
mod json;
mod validate;

pub use description::{
    rest_form, roll_onto_cylinder, Dirichlet, Material, Model, Motion, Obstacle, ObstacleShape,
    Panel, Rotation, Scene, DEFAULT_OBSTACLE_STIFFNESS,
};
