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

use serde_json::{Map, Value};

use crate::tfw::delaunay::{hash_unit, mesh_polygon, PolygonPanel};
use crate::tfw::material::{Form, Lame};
use crate::{Error, Result};

/// Material of the shell (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus Y (Pa), > 0.
    pub young: f64,
    /// Poisson's ratio ν, in (−1, 1) (plane stress; a warning outside [0, 0.5]).
    pub poisson: f64,
    /// Thickness h (m), > 0.
    pub thickness: f64,
    /// Density ρ (kg/m³), ≥ 0.
    pub density: f64,
}

impl Material {
    /// The Lamé parameters of eq. A.3.
    pub fn lame(&self) -> Lame {
        Lame::from_young_poisson(self.young, self.poisson)
    }
}

/// One flat panel of the pattern: rest (2D) coordinates, triangles, initial 3D positions.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Rest position of each vertex in the flat pattern (m).
    pub rest: Vec<[f64; 2]>,
    /// Triangles indexing `rest` (any orientation; each must have positive rest area).
    pub triangles: Vec<[u32; 3]>,
    /// Initial 3D position of each vertex; `None` = `(u, v, 0)`.
    pub positions: Option<Vec<[f64; 3]>>,
}

/// A rotation about an axis through a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    /// Axis direction (any nonzero length).
    pub axis: [f64; 3],
    /// A point on the axis.
    pub origin: [f64; 3],
    /// Angle in degrees (right-hand rule about `axis`).
    pub degrees: f64,
}

/// Prescribed motion of clamped vertices: rotation (about the axis through `origin`) of the
/// initial position, then translation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Motion {
    /// Translation (m) applied after the rotation.
    pub translation: [f64; 3],
    /// Optional rotation.
    pub rotation: Option<Rotation>,
}

impl Panel {
    /// The panel meshed irregularly from an outline ([`crate::tfw::delaunay::mesh_polygon`]);
    /// initial positions `(u, v, 0)`. Errors as `mesh_polygon`.
    pub fn from_polygon(polygon: &PolygonPanel) -> Result<Panel> {
        let m = mesh_polygon(polygon)?;
        Ok(Panel {
            rest: m.rest,
            triangles: m.triangles,
            positions: None,
        })
    }

    /// The panel meshed from an outline as [`from_polygon`](Self::from_polygon), lifted into a
    /// thin tent-shaped lens: initial `z = height · d / d_max`, `d` the distance of the rest
    /// position to the outline (outer ring and holes), `d_max` its largest value, so the
    /// boundary vertices stay at `z = 0` (exactly) and the interior ones leave the plane.
    /// `height < 0` also reverses the triangles (the panel then faces −z): two copies of the
    /// same outline, `height` and `−height`, sew into a closed, outward-oriented balloon
    /// (identical boundary samples, sewn; interior vertices apart). Errors as `from_polygon`,
    /// or `InvalidArgument` when `height` is zero or not finite.
    pub fn lens(polygon: &PolygonPanel, height: f64) -> Result<Panel> {
        if !(height.is_finite() && height != 0.0) {
            return Err(Error::InvalidArgument(format!(
                "lens height is {height}; must be finite and nonzero"
            )));
        }
        let m = mesh_polygon(polygon)?;
        let d: Vec<f64> = m
            .rest
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                if i < m.boundary_count {
                    0.0
                } else {
                    distance_to_rings(p, &polygon.outer, &polygon.holes)
                }
            })
            .collect();
        let d_max = d.iter().fold(0.0f64, |a, &b| a.max(b));
        let positions = m
            .rest
            .iter()
            .zip(&d)
            .map(|(p, &di)| [p[0], p[1], height * di / d_max.max(f64::MIN_POSITIVE)])
            .collect();
        let triangles = if height > 0.0 {
            m.triangles
        } else {
            m.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect()
        };
        Ok(Panel {
            rest: m.rest,
            triangles,
            positions: Some(positions),
        })
    }

    /// The panel's vertices whose rest position lies in the box `[lo, hi]` (inclusive, with a
    /// tolerance of 1e-9 of the box's size plus 1e-12 m): how a scene file names the clamped
    /// vertices of a panel it asks to be meshed.
    pub fn vertices_in_rest_box(&self, lo: [f64; 2], hi: [f64; 2]) -> Vec<u32> {
        let tol = 1e-9 * (hi[0] - lo[0]).abs().max((hi[1] - lo[1]).abs()) + 1e-12;
        (0..self.rest.len() as u32)
            .filter(|&i| {
                let p = self.rest[i as usize];
                (0..2).all(|k| p[k] >= lo[k] - tol && p[k] <= hi[k] + tol)
            })
            .collect()
    }
}

/// Rolls rest coordinates `(u, v)` onto the cylinder of radius `r` about the z axis:
/// `(r cos(u/r), r sin(u/r), v)` (arc length along u, height v).
pub fn roll_onto_cylinder(rest: &[[f64; 2]], r: f64) -> Vec<[f64; 3]> {
    rest.iter()
        .map(|p| {
            let (s, c) = (p[0] / r).sin_cos();
            [r * c, r * s, p[1]]
        })
        .collect()
}

impl Motion {
    /// The target of a vertex at initial position `p` after the fraction `s ∈ [0, 1]` of the
    /// motion (angle and translation scaled by `s`; load steps). `s = 0` returns `p`.
    pub fn apply(&self, p: [f64; 3], s: f64) -> [f64; 3] {
        let mut q = p;
        if let Some(r) = self.rotation {
            let n = (r.axis[0].powi(2) + r.axis[1].powi(2) + r.axis[2].powi(2)).sqrt();
            let k = [r.axis[0] / n, r.axis[1] / n, r.axis[2] / n];
            let v = [p[0] - r.origin[0], p[1] - r.origin[1], p[2] - r.origin[2]];
            let th = (s * r.degrees).to_radians();
            let (sn, cs) = th.sin_cos();
            let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
            let kxv = [
                k[1] * v[2] - k[2] * v[1],
                k[2] * v[0] - k[0] * v[2],
                k[0] * v[1] - k[1] * v[0],
            ];
            // Rodrigues' formula.
            q = std::array::from_fn(|i| {
                r.origin[i] + v[i] * cs + kxv[i] * sn + k[i] * kv * (1.0 - cs)
            });
        }
        std::array::from_fn(|i| q[i] + s * self.translation[i])
    }
}

/// A Dirichlet condition: vertices of one panel clamped to a prescribed motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Dirichlet {
    /// Index of the panel in [`Scene::panels`].
    pub panel: usize,
    /// Vertex indices of that panel.
    pub vertices: Vec<u32>,
    /// The motion (identity = clamped in place).
    pub motion: Motion,
}

/// A TFW problem: pattern, material, loads and boundary conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// A name for reports.
    pub name: String,
    /// The material.
    pub material: Material,
    /// The panels (at least one).
    pub panels: Vec<Panel>,
    /// Gravity acceleration (m/s²).
    pub gravity: [f64; 3],
    /// Internal pressure (Pa); the load is `−p·V` (enclosed volume, outward = face orientation).
    pub pressure: f64,
    /// Dirichlet conditions.
    pub dirichlet: Vec<Dirichlet>,
    /// Vertices whose initial positions are closer than this (m) are sewn into one.
    pub seam_tolerance: f64,
    /// Rigid obstacles kept out by a penalty in the base solve (JSON `obstacles`).
    pub obstacles: Vec<Obstacle>,
}

/// The default [`Obstacle::stiffness`] (J/m⁵ = Pa/m²): under a normal load `q` (Pa) a surface
/// resting on an obstacle sinks in by about `√(q / (3k))` (the cubic penalty's balance):
/// 26 µm for the sphere drape's weight `ρ h g ≈ 2 Pa`, 0.45 mm for 600 Pa.
pub const DEFAULT_OBSTACLE_STIFFNESS: f64 = 1e9;

/// The shape of an [`Obstacle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObstacleShape {
    /// The half-space behind a plane: the surface is kept on the side the normal points to.
    Plane {
        /// A point of the plane.
        point: [f64; 3],
        /// The normal (any nonzero length), pointing to the allowed side.
        normal: [f64; 3],
    },
    /// A solid ball: the surface is kept outside.
    Sphere {
        /// The centre.
        centre: [f64; 3],
        /// The radius (> 0).
        radius: f64,
    },
}

/// A rigid obstacle of the base solve (spec: "Obstacles (drapes) by penalty"): every vertex
/// `i` with signed distance `d_i < margin` from the obstacle's surface (positive outside)
/// pays `k · Ā_i · (margin − d_i)³` (`Ā_i` its barycentric rest area): a one-sided penalty,
/// twice continuously differentiable, zero outside the margin ([`crate::tfw::base`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obstacle {
    /// Plane or sphere.
    pub shape: ObstacleShape,
    /// Penalty stiffness `k` (J/m⁵; default [`DEFAULT_OBSTACLE_STIFFNESS`]).
    pub stiffness: f64,
    /// Distance from the obstacle's surface where the penalty starts (m, ≥ 0; default 0).
    pub margin: f64,
}

impl Obstacle {
    /// Signed distance of `x` from the obstacle's surface (positive outside), its gradient and
    /// the Hessian of the distance (0 for a plane; `(I − uuᵀ)/|x − c|` for a sphere).
    pub fn distance(&self, x: [f64; 3]) -> (f64, [f64; 3], [[f64; 3]; 3]) {
        match self.shape {
            ObstacleShape::Plane { point, normal } => {
                let l =
                    (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
                let n = normal.map(|c| c / l);
                let d = (0..3).map(|k| (x[k] - point[k]) * n[k]).sum();
                (d, n, [[0.0; 3]; 3])
            }
            ObstacleShape::Sphere { centre, radius } => {
                let r = [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]];
                let rho = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt().max(1e-300);
                let u = r.map(|c| c / rho);
                let h = std::array::from_fn(|a| {
                    std::array::from_fn(|b| (f64::from(u8::from(a == b)) - u[a] * u[b]) / rho)
                });
                (rho - radius, u, h)
            }
        }
    }

    fn validate(&self, path: &str) -> Result<()> {
        match self.shape {
            ObstacleShape::Plane { point, normal } => {
                finite3(&format!("{path}.point"), point)?;
                finite3(&format!("{path}.normal"), normal)?;
                if normal.iter().all(|&c| c == 0.0) {
                    return Err(bad(&format!("{path}.normal"), "must be nonzero"));
                }
            }
            ObstacleShape::Sphere { centre, radius } => {
                finite3(&format!("{path}.centre"), centre)?;
                if finite(&format!("{path}.radius"), radius)? <= 0.0 {
                    return Err(bad(&format!("{path}.radius"), "must be > 0"));
                }
            }
        }
        if finite(&format!("{path}.stiffness"), self.stiffness)? <= 0.0 {
            return Err(bad(&format!("{path}.stiffness"), "must be > 0"));
        }
        if finite(&format!("{path}.margin"), self.margin)? < 0.0 {
            return Err(bad(&format!("{path}.margin"), "must be >= 0"));
        }
        Ok(())
    }

    fn to_json(self) -> Value {
        let mut o = match self.shape {
            ObstacleShape::Plane { point, normal } => {
                serde_json::json!({"type": "plane", "point": point, "normal": normal})
            }
            ObstacleShape::Sphere { centre, radius } => {
                serde_json::json!({"type": "sphere", "centre": centre, "radius": radius})
            }
        };
        o["stiffness"] = Value::from(self.stiffness);
        o["margin"] = Value::from(self.margin);
        o
    }
}

fn parse_obstacle(v: &Value, path: &str) -> Result<Obstacle> {
    let kind = v
        .get("type")
        .ok_or_else(|| {
            bad(
                &format!("{path}.type"),
                "missing (required): plane or sphere",
            )
        })?
        .as_str()
        .ok_or_else(|| bad(&format!("{path}.type"), "expected \"plane\" or \"sphere\""))?;
    let shape = match kind {
        "plane" => {
            let o = object(v, path, &["type", "point", "normal", "stiffness", "margin"])?;
            ObstacleShape::Plane {
                point: fixed::<3>(required(o, path, "point")?, &format!("{path}.point"))?,
                normal: fixed::<3>(required(o, path, "normal")?, &format!("{path}.normal"))?,
            }
        }
        "sphere" => {
            let o = object(
                v,
                path,
                &["type", "centre", "radius", "stiffness", "margin"],
            )?;
            ObstacleShape::Sphere {
                centre: fixed::<3>(required(o, path, "centre")?, &format!("{path}.centre"))?,
                radius: number(required(o, path, "radius")?, &format!("{path}.radius"))?,
            }
        }
        other => {
            return Err(bad(
                &format!("{path}.type"),
                format!("unknown obstacle type {other:?} (plane or sphere)"),
            ))
        }
    };
    let o = v.as_object().expect("checked by object()");
    Ok(Obstacle {
        shape,
        stiffness: opt_number(o, path, "stiffness", DEFAULT_OBSTACLE_STIFFNESS)?,
        margin: opt_number(o, path, "margin", 0.0)?,
    })
}

/// The assembled problem: panels stitched into one mesh whose faces keep their rest forms.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Initial 3D position per (stitched) vertex.
    pub positions: Vec<[f64; 3]>,
    /// Triangles of the stitched mesh.
    pub triangles: Vec<[u32; 3]>,
    /// Per face, the rest (2D pattern) coordinates of its three corners.
    pub rest_corners: Vec<[[f64; 2]; 3]>,
    /// Per face, the rest metric `Ī_f` in its barycentric frame (S:2029–2033), all with
    /// positive determinant.
    pub rest_forms: Vec<Form>,
    /// The material.
    pub material: Material,
    /// Gravity (m/s²).
    pub gravity: [f64; 3],
    /// Pressure (Pa).
    pub pressure: f64,
    /// Obstacles (penalty in the base solve).
    pub obstacles: Vec<Obstacle>,
    /// Clamped vertices with their motion (each stitched vertex at most once; the last
    /// condition naming a vertex wins).
    pub clamps: Vec<(u32, Motion)>,
    /// Per panel, the stitched vertex of each panel vertex.
    pub panel_vertices: Vec<Vec<u32>>,
    /// Warnings found during validation (e.g. ν outside [0, 0.5]).
    pub warnings: Vec<String>,
}

fn bad(path: &str, msg: impl std::fmt::Display) -> Error {
    Error::InvalidArgument(format!("scene: {path}: {msg}"))
}

fn finite(path: &str, x: f64) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(bad(path, format!("must be finite, got {x}")))
    }
}

fn finite3(path: &str, v: [f64; 3]) -> Result<()> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{path}[{i}]"), *x)?;
    }
    Ok(())
}

impl Scene {
    /// Checks every field and returns the warnings. Errors ([`Error::InvalidArgument`],
    /// message `scene: <field path>: <what>`) on a non-finite number, `young ≤ 0`,
    /// `thickness ≤ 0`, `density < 0`, `poisson ∉ (−1, 1)`, no panel, a panel without
    /// triangles, an index out of range, a rest triangle of zero area, a `positions` list of
    /// the wrong length, a zero rotation axis, or a negative seam tolerance.
    pub fn validate(&self) -> Result<Vec<String>> {
        let mut warnings = Vec::new();
        let m = &self.material;
        if finite("material.young", m.young)? <= 0.0 {
            return Err(bad("material.young", "must be > 0"));
        }
        let nu = finite("material.poisson", m.poisson)?;
        if !(nu > -1.0 && nu < 1.0) {
            return Err(bad(
                "material.poisson",
                format!("must be in (-1, 1), got {nu}"),
            ));
        }
        if !(0.0..=0.5).contains(&nu) {
            warnings.push(format!("material.poisson = {nu} is outside [0, 0.5]"));
        }
        if nu == 0.0 {
            warnings.push(
                "material.poisson = 0: the quadratic bending (2.28, ∝ α) vanishes; the base \
                 solve relies on its regularization out of plane"
                    .into(),
            );
        }
        if finite("material.thickness", m.thickness)? <= 0.0 {
            return Err(bad("material.thickness", "must be > 0"));
        }
        if finite("material.density", m.density)? < 0.0 {
            return Err(bad("material.density", "must be >= 0"));
        }
        finite3("loads.gravity", self.gravity)?;
        finite("loads.pressure", self.pressure)?;
        for (k, o) in self.obstacles.iter().enumerate() {
            o.validate(&format!("obstacles[{k}]"))?;
        }
        if finite("seam_tolerance", self.seam_tolerance)? < 0.0 {
            return Err(bad("seam_tolerance", "must be >= 0"));
        }
        if self.panels.is_empty() {
            return Err(bad("panels", "at least one panel is required"));
        }
        for (p, panel) in self.panels.iter().enumerate() {
            validate_panel(&format!("panels[{p}]"), panel)?;
        }
        for (k, d) in self.dirichlet.iter().enumerate() {
            let path = format!("dirichlet[{k}]");
            let Some(panel) = self.panels.get(d.panel) else {
                return Err(bad(
                    &format!("{path}.panel"),
                    format!("{} is not a panel index (< {})", d.panel, self.panels.len()),
                ));
            };
            if let Some(&v) = d.vertices.iter().find(|&&v| v as usize >= panel.rest.len()) {
                return Err(bad(
                    &format!("{path}.vertices"),
                    format!("vertex {v} out of range (panel has {})", panel.rest.len()),
                ));
            }
            finite3(&format!("{path}.translation"), d.motion.translation)?;
            if let Some(r) = d.motion.rotation {
                finite3(&format!("{path}.rotation.axis"), r.axis)?;
                finite3(&format!("{path}.rotation.origin"), r.origin)?;
                finite(&format!("{path}.rotation.degrees"), r.degrees)?;
                if r.axis.iter().all(|&a| a == 0.0) {
                    return Err(bad(&format!("{path}.rotation.axis"), "must be nonzero"));
                }
            }
        }
        Ok(warnings)
    }

    /// Validates and stitches the scene into a [`Model`]. Errors as [`validate`](Self::validate),
    /// and when sewing collapses a triangle (two corners within the seam tolerance).
    pub fn assemble(&self) -> Result<Model> {
        let warnings = self.validate()?;
        let mut all = Vec::new();
        let mut offsets = Vec::new();
        for p in &self.panels {
            offsets.push(all.len());
            match &p.positions {
                Some(x) => all.extend_from_slice(x),
                None => all.extend(p.rest.iter().map(|r| [r[0], r[1], 0.0])),
            }
        }
        let rep = weld_within(&all, self.seam_tolerance);
        // compact numbering in order of first appearance of each representative
        let mut new_index = vec![u32::MAX; all.len()];
        let mut positions = Vec::new();
        for i in 0..all.len() {
            let r = rep[i] as usize;
            if new_index[r] == u32::MAX {
                new_index[r] = positions.len() as u32;
                positions.push(all[r]);
            }
            new_index[i] = new_index[r];
        }
        let mut triangles = Vec::new();
        let mut rest_corners = Vec::new();
        let mut rest_forms = Vec::new();
        let mut panel_vertices = Vec::new();
        for (p, panel) in self.panels.iter().enumerate() {
            let off = offsets[p];
            panel_vertices.push(
                (0..panel.rest.len())
                    .map(|i| new_index[off + i])
                    .collect::<Vec<_>>(),
            );
            for (t, tri) in panel.triangles.iter().enumerate() {
                let v = tri.map(|i| new_index[off + i as usize]);
                if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
                    return Err(bad(
                        &format!("panels[{p}].triangles[{t}]"),
                        "two corners were sewn together (seam_tolerance too large?)",
                    ));
                }
                let c = tri.map(|i| panel.rest[i as usize]);
                triangles.push(v);
                rest_forms.push(rest_form(c));
                rest_corners.push(c);
            }
        }
        let mut clamp_of: Vec<Option<Motion>> = vec![None; positions.len()];
        for d in &self.dirichlet {
            for &v in &d.vertices {
                clamp_of[panel_vertices[d.panel][v as usize] as usize] = Some(d.motion);
            }
        }
        let clamps = clamp_of
            .into_iter()
            .enumerate()
            .filter_map(|(v, m)| m.map(|m| (v as u32, m)))
            .collect();
        Ok(Model {
            positions,
            triangles,
            rest_corners,
            rest_forms,
            material: self.material,
            gravity: self.gravity,
            pressure: self.pressure,
            obstacles: self.obstacles.clone(),
            clamps,
            panel_vertices,
            warnings,
        })
    }

    /// Parses and validates a scene from JSON text (format in the module docs). Errors
    /// ([`Error::InvalidArgument`]) name the field: `scene: panels[0].rest[3][1]: ...`,
    /// `scene: unknown key material.yung (allowed: ...)`, or the JSON syntax position.
    pub fn from_json_str(text: &str) -> Result<Scene> {
        let v: Value = serde_json::from_str(text)
            .map_err(|e| Error::InvalidArgument(format!("scene: not valid JSON: {e}")))?;
        let scene = parse_scene(&v)?;
        scene.validate()?;
        Ok(scene)
    }

    /// Reads a scene file (see [`from_json_str`](Self::from_json_str)); I/O errors are
    /// [`Error::Io`].
    pub fn from_json_file(path: &std::path::Path) -> Result<Scene> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Scene::from_json_str(&text)
    }

    /// The scene as JSON text in the format [`from_json_str`](Self::from_json_str) reads
    /// (numbers are written in the shortest round-trip form; reading them back is exact up to
    /// an ulp: serde_json's default float parser is not correctly rounded, and enabling its
    /// `float_roundtrip` feature would change what the `bake` code parses).
    pub fn to_json_string(&self) -> String {
        let m = &self.material;
        let mut o = Map::new();
        o.insert("name".into(), Value::from(self.name.clone()));
        o.insert(
            "material".into(),
            serde_json::json!({"young": m.young, "poisson": m.poisson,
                               "thickness": m.thickness, "density": m.density}),
        );
        o.insert(
            "loads".into(),
            serde_json::json!({"gravity": self.gravity, "pressure": self.pressure}),
        );
        o.insert("seam_tolerance".into(), Value::from(self.seam_tolerance));
        let panels: Vec<Value> = self
            .panels
            .iter()
            .map(|p| {
                let mut po = Map::new();
                po.insert("rest".into(), serde_json::json!(p.rest));
                po.insert("triangles".into(), serde_json::json!(p.triangles));
                if let Some(x) = &p.positions {
                    po.insert("positions".into(), serde_json::json!(x));
                }
                Value::Object(po)
            })
            .collect();
        o.insert("panels".into(), Value::Array(panels));
        let dir: Vec<Value> = self
            .dirichlet
            .iter()
            .map(|d| {
                let mut dm = Map::new();
                dm.insert("panel".into(), Value::from(d.panel));
                dm.insert("vertices".into(), serde_json::json!(d.vertices));
                dm.insert(
                    "translation".into(),
                    serde_json::json!(d.motion.translation),
                );
                if let Some(r) = d.motion.rotation {
                    dm.insert(
                        "rotation".into(),
                        serde_json::json!({"axis": r.axis, "origin": r.origin,
                                           "degrees": r.degrees}),
                    );
                }
                Value::Object(dm)
            })
            .collect();
        o.insert("dirichlet".into(), Value::Array(dir));
        if !self.obstacles.is_empty() {
            o.insert(
                "obstacles".into(),
                Value::Array(self.obstacles.iter().map(|ob| ob.to_json()).collect()),
            );
        }
        serde_json::to_string_pretty(&Value::Object(o)).expect("JSON values serialize")
    }

    /// The stretched sheet of S:714: a 0.25 × 0.1 m rectangle, h 0.1 mm, ν 0.5, Y 1 MPa, on a
    /// structured `nx × ny` vertex grid (alternating diagonals, interior vertices jittered by
    /// up to 20% of the spacing to break the grid's direction bias, S:698). The initial state
    /// is the sheet stretched uniformly along x by the factor `1 + stretch` (the dissertation
    /// does not give the stretch); both short edges are clamped there.
    pub fn stretched_sheet(nx: usize, ny: usize, stretch: f64) -> Scene {
        let (lx, ly) = (0.25, 0.1);
        let (rest, triangles) = grid(nx, ny, lx, ly, true);
        let positions = rest
            .iter()
            .map(|r| [(r[0] - 0.5 * lx) * (1.0 + stretch), r[1] - 0.5 * ly, 0.0])
            .collect();
        let edge = |col: usize| (0..ny).map(|j| (j * nx + col) as u32).collect::<Vec<_>>();
        let mut clamped = edge(0);
        clamped.extend(edge(nx - 1));
        Scene {
            name: format!("stretched sheet {nx}x{ny}, stretch {stretch}"),
            material: Material {
                young: 1e6,
                poisson: 0.5,
                thickness: 1e-4,
                density: 0.0,
            },
            panels: vec![Panel {
                rest,
                triangles,
                positions: Some(positions),
            }],
            gravity: [0.0; 3],
            pressure: 0.0,
            dirichlet: vec![Dirichlet {
                panel: 0,
                vertices: clamped,
                motion: Motion::default(),
            }],
            seam_tolerance: 1e-6,
            obstacles: Vec::new(),
        }
    }

    /// The sphere drape of S:676 (Fig. 2.19): a square cloth of side `side` (m; the
    /// dissertation's is 1 m) on a structured `n × n` vertex grid (alternating diagonals, not
    /// jittered; `n = 41` gives the dissertation's 1.6k vertices), laid flat at height `r` over
    /// a sphere of radius `r = 0.2` m centred at the origin ([`ObstacleShape::Sphere`], default
    /// stiffness), under gravity `-9.81 z`; the cloth of S:676 (ρ 200 kg/m³, ν 0.3, Y 0.1 MPa,
    /// h 1 mm). Departure: the vertex at the cloth's centre (`n` odd; the one right of it for
    /// even `n`) is pinned where it lies — the dissertation's solvers have friction, and a
    /// frictionless sphere's top is an unstable equilibrium from which a free sheet slides off.
    /// `n` below 2 is taken as 2, `side` as its absolute value; a zero, infinite or NaN `side`
    /// gives a scene that [`Scene::assemble`] refuses.
    pub fn sphere_drape(n: usize, side: f64) -> Scene {
        let (n, side) = (n.max(2), side.abs());
        let (rest, triangles) = grid(n, n, side, side, false);
        let centre = (n / 2) * n + n / 2;
        let name = format!("sphere drape {n}x{n}, {side} m on r {SPHERE_DRAPE_RADIUS} m");
        sphere_drape_scene(name, rest, triangles, side, centre)
    }

    /// The sphere drape of [`sphere_drape`](Self::sphere_drape) on an irregular Delaunay mesh
    /// of the square with about `target_vertices` vertices ([`crate::tfw::delaunay`]; `seed`
    /// selects the sampling), as the dissertation's experiments use (irregular meshes, S:698):
    /// no grid direction for the wrinkles to follow. The pinned vertex is the one nearest the
    /// cloth's centre (the first such in index order). `side` as its absolute value. Errors as
    /// [`Panel::from_polygon`] (e.g. a zero, infinite or NaN `side`, too few vertices).
    pub fn sphere_drape_delaunay(target_vertices: usize, side: f64, seed: u64) -> Result<Scene> {
        let side = side.abs();
        let panel = Panel::from_polygon(&PolygonPanel {
            outer: vec![[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]],
            holes: vec![],
            target_vertices,
            seed,
        })?;
        let dist = |p: &[f64; 2]| (p[0] - 0.5 * side).hypot(p[1] - 0.5 * side);
        let centre = (0..panel.rest.len())
            .min_by(|&a, &b| {
                dist(&panel.rest[a])
                    .total_cmp(&dist(&panel.rest[b]))
                    .then(a.cmp(&b))
            })
            .unwrap_or(0);
        let name = format!(
            "sphere drape, Delaunay {target_vertices} v (seed {seed}), {side} m on r \
             {SPHERE_DRAPE_RADIUS} m"
        );
        Ok(sphere_drape_scene(
            name,
            panel.rest,
            panel.triangles,
            side,
            centre,
        ))
    }

    /// The twisted cylinder of S:682: radius 1 m, height 5 m, h 0.1 mm, ν 0.44, Y 10 MPa. The
    /// pattern is the 2π × 5 m rectangle on a structured `n_around + 1` × `n_height` grid
    /// (jittered interior, see [`stretched_sheet`](Self::stretched_sheet)), rolled into the
    /// untwisted cylinder (the initial state, S:2226) and sewn along the seam. The bottom ring
    /// is clamped; the top ring is rotated by `twist_degrees` about the axis (height fixed).
    pub fn twisted_cylinder(n_around: usize, n_height: usize, twist_degrees: f64) -> Scene {
        let (r, hgt) = (1.0, 5.0);
        let nx = n_around + 1;
        let (rest, triangles) = grid(nx, n_height, 2.0 * std::f64::consts::PI * r, hgt, true);
        let panel = Panel {
            positions: Some(roll_onto_cylinder(&rest, r)),
            rest,
            triangles,
        };
        let name = format!("twisted cylinder {n_around}x{n_height}, {twist_degrees} deg");
        twisted_cylinder_scene(name, panel, r, hgt, twist_degrees)
    }

    /// The twisted cylinder of [`twisted_cylinder`](Self::twisted_cylinder) on an irregular
    /// Delaunay mesh of the pattern with about `target_vertices` vertices before sewing
    /// ([`crate::tfw::delaunay`]; the seam's two sides get the same samples, so the sewn mesh
    /// has `target_vertices − (samples on the seam)` vertices), as the dissertation's
    /// experiments use (irregular meshes, S:698). `seed` selects the sampling.
    pub fn twisted_cylinder_delaunay(
        target_vertices: usize,
        twist_degrees: f64,
        seed: u64,
    ) -> Result<Scene> {
        let (r, hgt) = (1.0, 5.0);
        let w = 2.0 * std::f64::consts::PI * r;
        let mut panel = Panel::from_polygon(&PolygonPanel {
            outer: vec![[0.0, 0.0], [w, 0.0], [w, hgt], [0.0, hgt]],
            holes: vec![],
            target_vertices,
            seed,
        })?;
        panel.positions = Some(roll_onto_cylinder(&panel.rest, r));
        let name = format!(
            "twisted cylinder, Delaunay {target_vertices} v (seed {seed}), {twist_degrees} deg"
        );
        Ok(twisted_cylinder_scene(name, panel, r, hgt, twist_degrees))
    }
}

impl Scene {
    /// The sheared rectangle of S:730 (Wong & Pellegrino 2006, "Wrinkled membranes Part I:
    /// experiments", J. Mech. Mater. Struct. 1(1)): a 380 × 128 mm Kapton HN foil, 25 µm
    /// thick, E 3.53 GPa, ν 0.3 (the dimensions and material the spec takes from that paper;
    /// the dissertation gives none of them), on an irregular Delaunay mesh of about
    /// `target_vertices` vertices. The bottom edge is clamped; the top edge is clamped and
    /// moved by `shear_mm` (mm) along the long side (x) and by `stretch_mm` (mm) away from
    /// the bottom edge (a small pre-tension; 0 = pure shear). The sides are free.
    pub fn sheared_rectangle(
        target_vertices: usize,
        shear_mm: f64,
        stretch_mm: f64,
        seed: u64,
    ) -> Result<Scene> {
        let (w, h) = (0.38, 0.128);
        let panel = Panel::from_polygon(&PolygonPanel {
            outer: vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]],
            holes: vec![],
            target_vertices,
            seed,
        })?;
        let name = format!(
            "sheared rectangle (Wong-Pellegrino), {target_vertices} v (seed {seed}), \
             shear {shear_mm} mm, stretch {stretch_mm} mm"
        );
        let material = Material {
            young: 3.53e9,
            poisson: 0.3,
            thickness: 25e-6,
            density: 0.0,
        };
        let motion = Motion {
            translation: [shear_mm / 1000.0, stretch_mm / 1000.0, 0.0],
            rotation: None,
        };
        let mut scene = bottom_clamped_top_moved(name, material, panel, [w, h], motion);
        scene.seam_tolerance = 1e-9;
        Ok(scene)
    }
}

impl Scene {
    /// The Mylar balloon of S:750 ("two disks (radius 0.1m) sewn along their boundary"): two
    /// identical disks of radius 0.1 m, meshed irregularly (same outline, target and seed, so
    /// their rims get identical samples) with about `target_vertices_per_panel` vertices each,
    /// sewn along the rim into a closed surface and inflated by `pressure` (Pa). Material as
    /// the dissertation's torus balloon ("the same material parameters", S:750: ν 0.44,
    /// Y 10 MPa); thickness 0.1 mm (not in the text; the spec's reference-code disk) and the
    /// spec's 600 Pa are the defaults callers use. No Dirichlet condition: the rigid motions
    /// are left to the base solve's diagonal shift (pressure and membrane are invariant).
    /// Initial state ([`Panel::lens`]): a thin lens, `z = ±0.05 R (R − r)/R`; the rim is a
    /// polygon of `target_vertices_per_panel / 3` corners (clamped to 24..4096).
    pub fn disk_balloon(
        target_vertices_per_panel: usize,
        pressure: f64,
        seed: u64,
    ) -> Result<Scene> {
        let r = 0.1;
        let n = (target_vertices_per_panel / 3).clamp(24, 4096);
        let outline = PolygonPanel {
            outer: circle(r, n),
            holes: vec![],
            target_vertices: target_vertices_per_panel,
            seed,
        };
        let panels = balloon_panels(&outline, 0.05 * r)?;
        let name = format!(
            "disk balloon r 0.1 m, 2 x {target_vertices_per_panel} v (seed {seed}), {pressure} Pa"
        );
        Ok(balloon_scene(name, panels, pressure))
    }

    /// The torus balloon of S:746: two annuli (inner radius 0.04 m, outer 0.1 m, ν 0.44,
    /// Y 10 MPa; thickness 0.1 mm as [`disk_balloon`](Self::disk_balloon)) sewn along both
    /// rims and inflated by `pressure` (Pa); about `target_vertices_per_panel` vertices per
    /// annulus (the dissertation's mesh: 2k in all). Initial state ([`Panel::lens`]): a thin
    /// tent, `z = ±0.05 w · d/(w/2)`, `w = r_o − r_i`, `d` the distance to the nearer rim; the
    /// rims are polygons of `target_vertices_per_panel / 4` and `· r_i/r_o` corners.
    pub fn torus_balloon(
        target_vertices_per_panel: usize,
        pressure: f64,
        seed: u64,
    ) -> Result<Scene> {
        let (ri, ro) = (0.04, 0.1);
        let n = (target_vertices_per_panel / 4).clamp(24, 4096);
        let ni = ((n as f64 * ri / ro).round() as usize).max(12);
        let outline = PolygonPanel {
            outer: circle(ro, n),
            holes: vec![circle(ri, ni)],
            target_vertices: target_vertices_per_panel,
            seed,
        };
        let panels = balloon_panels(&outline, 0.05 * (ro - ri))?;
        let name = format!(
            "torus balloon r 0.04-0.1 m, 2 x {target_vertices_per_panel} v (seed {seed}), \
             {pressure} Pa"
        );
        Ok(balloon_scene(name, panels, pressure))
    }
}

impl Scene {
    /// The teabag of S:752: two 1.4 × 0.74 m rectangles sewn along their whole boundary into
    /// a pillow and inflated by `pressure` (Pa; the dissertation does not give it), h 1 mm,
    /// ν 0.3, Y 0.1 MPa (S:752), about `target_vertices_per_panel` vertices per rectangle
    /// (the dissertation's mesh: 936 in all), meshed irregularly (same outline, target and
    /// seed, so both get identical boundary samples and sew). The corners are rounded (radius
    /// 4 cm, 6 segments): at a square corner the mesher puts a triangle with three boundary
    /// vertices, whose inner edge both panels would share, which does not sew into a manifold.
    /// Initial state a thin tent ([`Panel::lens`], `z = ±0.05 · 0.37 m · d/d_max`). No Dirichlet
    /// condition, as the balloons. Expected (S:752): fine wrinkles along the seam, no creases.
    pub fn teabag(target_vertices_per_panel: usize, pressure: f64, seed: u64) -> Result<Scene> {
        let (w, h) = (1.4, 0.74);
        let outline = PolygonPanel {
            outer: rounded_rectangle(w, h, 0.04, 6),
            holes: vec![],
            target_vertices: target_vertices_per_panel,
            seed,
        };
        let panels = balloon_panels(&outline, 0.05 * 0.5 * h)?;
        let name = format!(
            "teabag 1.4 x 0.74 m, 2 x {target_vertices_per_panel} v (seed {seed}), {pressure} Pa"
        );
        let mut scene = balloon_scene(name, panels, pressure);
        scene.material = Material {
            young: 1e5,
            poisson: 0.3,
            thickness: 1e-3,
            density: 0.0,
        };
        Ok(scene)
    }
}

/// The `w × h` rectangle about the origin with its corners rounded to radius `r` (each arc
/// `segments` chords), counter-clockwise.
fn rounded_rectangle(w: f64, h: f64, r: f64, segments: usize) -> Vec<[f64; 2]> {
    let (cx, cy) = (0.5 * w - r, 0.5 * h - r);
    let centres = [[cx, -cy], [cx, cy], [-cx, cy], [-cx, -cy]];
    let mut out = Vec::with_capacity(4 * (segments + 1));
    for (q, c) in centres.iter().enumerate() {
        for k in 0..=segments {
            let t = std::f64::consts::FRAC_PI_2 * (q as f64 - 1.0 + k as f64 / segments as f64);
            out.push([c[0] + r * t.cos(), c[1] + r * t.sin()]);
        }
    }
    out
}

/// `n` corners of the circle of radius `r` about the origin, counter-clockwise.
fn circle(r: f64, n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let (s, c) = (2.0 * std::f64::consts::PI * k as f64 / n as f64).sin_cos();
            [r * c, r * s]
        })
        .collect()
}

/// The two panels of a balloon: [`Panel::lens`] of `outline` at `+height` (top, facing +z)
/// and `−height` (bottom, facing −z).
fn balloon_panels(outline: &PolygonPanel, height: f64) -> Result<Vec<Panel>> {
    Ok(vec![
        Panel::lens(outline, height)?,
        Panel::lens(outline, -height)?,
    ])
}

/// Distance from `p` to the nearest edge of the closed rings `outer` and `holes`.
fn distance_to_rings(p: [f64; 2], outer: &[[f64; 2]], holes: &[Vec<[f64; 2]>]) -> f64 {
    let ring_distance = |r: &[[f64; 2]]| {
        (0..r.len())
            .map(|k| {
                let (a, b) = (r[k], r[(k + 1) % r.len()]);
                let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
                let (px, py) = (p[0] - a[0], p[1] - a[1]);
                let len2 = ex * ex + ey * ey;
                let t = if len2 > 0.0 {
                    ((px * ex + py * ey) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (px - t * ex).hypot(py - t * ey)
            })
            .fold(f64::INFINITY, f64::min)
    };
    holes
        .iter()
        .map(|h| ring_distance(h))
        .fold(ring_distance(outer), f64::min)
}

/// A balloon scene: the panels, the balloon material of S:746–750 (ν 0.44, Y 10 MPa,
/// h 0.1 mm, no density), `pressure`, no gravity, no Dirichlet condition, seams sewn within
/// 1e-9 m (the twins are bit-identical).
fn balloon_scene(name: String, panels: Vec<Panel>, pressure: f64) -> Scene {
    Scene {
        name,
        material: Material {
            young: 1e7,
            poisson: 0.44,
            thickness: 1e-4,
            density: 0.0,
        },
        panels,
        gravity: [0.0; 3],
        pressure,
        dirichlet: vec![],
        seam_tolerance: 1e-9,
        obstacles: Vec::new(),
    }
}

/// The cylinder scene around a rolled panel of the `2πr × hgt` pattern: bottom ring (rest
/// v = 0) clamped, top ring (v = hgt) rotated about the z axis, height fixed.
fn twisted_cylinder_scene(
    name: String,
    panel: Panel,
    r: f64,
    hgt: f64,
    twist_degrees: f64,
) -> Scene {
    let w = 2.0 * std::f64::consts::PI * r;
    let material = Material {
        young: 1e7,
        poisson: 0.44,
        thickness: 1e-4,
        density: 0.0,
    };
    let motion = Motion {
        translation: [0.0; 3],
        rotation: Some(Rotation {
            axis: [0.0, 0.0, 1.0],
            origin: [0.0; 3],
            degrees: twist_degrees,
        }),
    };
    bottom_clamped_top_moved(name, material, panel, [w, hgt], motion)
}

/// A one-panel scene on the `size[0] × size[1]` rest rectangle: the bottom edge (rest v = 0)
/// clamped, the top edge (v = `size[1]`) clamped and moved by `motion`; no gravity, no
/// pressure, seam tolerance 1e-6.
fn bottom_clamped_top_moved(
    name: String,
    material: Material,
    panel: Panel,
    size: [f64; 2],
    motion: Motion,
) -> Scene {
    let [w, h] = size;
    let bottom = panel.vertices_in_rest_box([0.0, 0.0], [w, 0.0]);
    let top = panel.vertices_in_rest_box([0.0, h], [w, h]);
    Scene {
        name,
        material,
        panels: vec![panel],
        gravity: [0.0; 3],
        pressure: 0.0,
        dirichlet: vec![
            Dirichlet {
                panel: 0,
                vertices: bottom,
                motion: Motion::default(),
            },
            Dirichlet {
                panel: 0,
                vertices: top,
                motion,
            },
        ],
        seam_tolerance: 1e-6,
        obstacles: Vec::new(),
    }
}

/// `Ī = [[ē1·ē1, ē1·ē2], [ē1·ē2, ē2·ē2]]`, `ēi = c_i − c_0` (S:2029–2033).
pub fn rest_form(c: [[f64; 2]; 3]) -> Form {
    let e1 = [c[1][0] - c[0][0], c[1][1] - c[0][1]];
    let e2 = [c[2][0] - c[0][0], c[2][1] - c[0][1]];
    [
        e1[0] * e1[0] + e1[1] * e1[1],
        e1[0] * e2[0] + e1[1] * e2[1],
        e2[0] * e2[0] + e2[1] * e2[1],
    ]
}

fn validate_panel(path: &str, p: &Panel) -> Result<()> {
    if p.triangles.is_empty() {
        return Err(bad(&format!("{path}.triangles"), "a panel needs triangles"));
    }
    for (i, r) in p.rest.iter().enumerate() {
        for (k, x) in r.iter().enumerate() {
            finite(&format!("{path}.rest[{i}][{k}]"), *x)?;
        }
    }
    if let Some(x) = &p.positions {
        if x.len() != p.rest.len() {
            return Err(bad(
                &format!("{path}.positions"),
                format!("{} positions for {} rest vertices", x.len(), p.rest.len()),
            ));
        }
        for (i, q) in x.iter().enumerate() {
            finite3(&format!("{path}.positions[{i}]"), *q)?;
        }
    }
    for (t, tri) in p.triangles.iter().enumerate() {
        let tp = format!("{path}.triangles[{t}]");
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= p.rest.len()) {
            return Err(bad(
                &tp,
                format!("vertex {v} out of range ({} vertices)", p.rest.len()),
            ));
        }
        let f = rest_form(tri.map(|i| p.rest[i as usize]));
        let det = f[0] * f[2] - f[1] * f[1];
        if det.is_nan() || det <= 1e-24 * (f[0] + f[2]).powi(2) {
            return Err(bad(&tp, "rest triangle has zero area"));
        }
    }
    Ok(())
}

/// Structured grid of `nx × ny` vertices on `[0, lx] × [0, ly]` (row-major, `j·nx + i`), two
/// triangles per cell with alternating diagonals, counter-clockwise. With `jitter`, interior
/// vertices move by a deterministic pseudo-random offset of up to 20% of the spacing.
/// Radius of the sphere of the drape (S:676), m.
const SPHERE_DRAPE_RADIUS: f64 = 0.2;

/// The drape of [`Scene::sphere_drape`] for a pattern `rest` / `triangles` of the square
/// `[0, side]²`: laid flat at height `r` centred over the sphere, vertex `centre` pinned.
fn sphere_drape_scene(
    name: String,
    rest: Vec<[f64; 2]>,
    triangles: Vec<[u32; 3]>,
    side: f64,
    centre: usize,
) -> Scene {
    let r = SPHERE_DRAPE_RADIUS;
    let positions = rest
        .iter()
        .map(|p| [p[0] - 0.5 * side, p[1] - 0.5 * side, r])
        .collect();
    Scene {
        name,
        material: Material {
            young: 1e5,
            poisson: 0.3,
            thickness: 1e-3,
            density: 200.0,
        },
        panels: vec![Panel {
            rest,
            triangles,
            positions: Some(positions),
        }],
        gravity: [0.0, 0.0, -9.81],
        pressure: 0.0,
        dirichlet: vec![Dirichlet {
            panel: 0,
            vertices: vec![centre as u32],
            motion: Motion::default(),
        }],
        seam_tolerance: 1e-6,
        obstacles: vec![Obstacle {
            shape: ObstacleShape::Sphere {
                centre: [0.0; 3],
                radius: r,
            },
            stiffness: DEFAULT_OBSTACLE_STIFFNESS,
            margin: 0.0,
        }],
    }
}

fn grid(nx: usize, ny: usize, lx: f64, ly: f64, jitter: bool) -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
    let (dx, dy) = (lx / (nx - 1) as f64, ly / (ny - 1) as f64);
    let mut rest = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let mut p = [i as f64 * dx, j as f64 * dy];
            if jitter && i > 0 && i + 1 < nx && j > 0 && j + 1 < ny {
                let k = (j * nx + i) as u64;
                p[0] += 0.2 * dx * hash_unit(2 * k);
                p[1] += 0.2 * dy * hash_unit(2 * k + 1);
            }
            rest.push(p);
        }
    }
    let mut tris = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let v = |a: usize, b: usize| (b * nx + a) as u32;
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            if (i + j) % 2 == 0 {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            } else {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            }
        }
    }
    (rest, tris)
}

/// Per vertex, the smallest index of the vertices within `tol` (Euclidean) of it, merged
/// transitively (union–find over pairs found by a sweep along x).
fn weld_within(p: &[[f64; 3]], tol: f64) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..p.len() as u32).collect();
    fn find(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by(|&a, &b| p[a][0].total_cmp(&p[b][0]).then(a.cmp(&b)));
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if p[b][0] - p[a][0] > tol {
                break;
            }
            let d2: f64 = (0..3).map(|c| (p[a][c] - p[b][c]).powi(2)).sum();
            if d2 <= tol * tol {
                let (ra, rb) = (find(&mut parent, a as u32), find(&mut parent, b as u32));
                let (lo, hi) = (ra.min(rb), ra.max(rb));
                parent[hi as usize] = lo;
            }
        }
    }
    (0..p.len() as u32).map(|i| find(&mut parent, i)).collect()
}

// ---------------------------------------------------------------------------------------------
// JSON reading: every accessor names the field path in its error.

fn object<'a>(v: &'a Value, path: &str, allowed: &[&str]) -> Result<&'a Map<String, Value>> {
    let m = v
        .as_object()
        .ok_or_else(|| bad(path, "expected a JSON object"))?;
    if let Some(k) = m.keys().find(|k| !allowed.contains(&k.as_str())) {
        let full = if path.is_empty() {
            k.clone()
        } else {
            format!("{path}.{k}")
        };
        return Err(Error::InvalidArgument(format!(
            "scene: unknown key {full} (allowed: {})",
            allowed.join(", ")
        )));
    }
    Ok(m)
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

fn number(v: &Value, path: &str) -> Result<f64> {
    v.as_f64()
        .ok_or_else(|| bad(path, "expected a number"))
        .and_then(|x| finite(path, x))
}

fn required<'a>(m: &'a Map<String, Value>, path: &str, key: &str) -> Result<&'a Value> {
    m.get(key)
        .ok_or_else(|| bad(&join(path, key), "missing (required)"))
}

fn opt_number(m: &Map<String, Value>, path: &str, key: &str, default: f64) -> Result<f64> {
    m.get(key)
        .map_or(Ok(default), |v| number(v, &join(path, key)))
}

fn array<'a>(v: &'a Value, path: &str) -> Result<&'a Vec<Value>> {
    v.as_array().ok_or_else(|| bad(path, "expected an array"))
}

fn fixed<const N: usize>(v: &Value, path: &str) -> Result<[f64; N]> {
    let a = array(v, path)?;
    if a.len() != N {
        return Err(bad(path, format!("expected {N} numbers, got {}", a.len())));
    }
    let mut out = [0.0; N];
    for (i, x) in a.iter().enumerate() {
        out[i] = number(x, &format!("{path}[{i}]"))?;
    }
    Ok(out)
}

fn index(v: &Value, path: &str) -> Result<u64> {
    v.as_u64()
        .ok_or_else(|| bad(path, "expected a non-negative integer"))
}

/// A panel given by its outline (`polygon`, optional `holes`, `target_vertices`, optional
/// `seed` and `roll_radius`), meshed here by [`mesh_polygon`].
fn parse_polygon_panel(po: &Map<String, Value>, path: &str) -> Result<Panel> {
    for key in ["rest", "triangles", "positions"] {
        if po.contains_key(key) {
            return Err(bad(
                &join(path, key),
                "not allowed with \"polygon\" (the panel is meshed from its outline)",
            ));
        }
    }
    let ring = |v: &Value, rp: &str| -> Result<Vec<[f64; 2]>> {
        array(v, rp)?
            .iter()
            .enumerate()
            .map(|(i, x)| fixed::<2>(x, &format!("{rp}[{i}]")))
            .collect()
    };
    let outer = ring(&po["polygon"], &join(path, "polygon"))?;
    let mut holes = Vec::new();
    if let Some(h) = po.get("holes") {
        let hp = join(path, "holes");
        for (k, x) in array(h, &hp)?.iter().enumerate() {
            holes.push(ring(x, &format!("{hp}[{k}]"))?);
        }
    }
    let tp = join(path, "target_vertices");
    let target_vertices = usize::try_from(index(required(po, path, "target_vertices")?, &tp)?)
        .map_err(|_| bad(&tp, "too large"))?;
    let seed = match po.get("seed") {
        None => 0,
        Some(x) => index(x, &join(path, "seed"))?,
    };
    let polygon = PolygonPanel {
        outer,
        holes,
        target_vertices,
        seed,
    };
    let mut panel = Panel::from_polygon(&polygon).map_err(|e| match e {
        Error::InvalidArgument(m) => bad(path, m),
        other => other,
    })?;
    if let Some(h) = po.get("lens") {
        let lp = join(path, "lens");
        let h = number(h, &lp)?;
        if h == 0.0 {
            return Err(bad(&lp, "must be nonzero"));
        }
        if po.contains_key("roll_radius") {
            return Err(bad(&lp, "not allowed with \"roll_radius\""));
        }
        return Panel::lens(&polygon, h).map_err(|e| match e {
            Error::InvalidArgument(m) => bad(path, m),
            other => other,
        });
    }
    if let Some(r) = po.get("roll_radius") {
        let rp = join(path, "roll_radius");
        let r = number(r, &rp)?;
        if r <= 0.0 {
            return Err(bad(&rp, "must be > 0"));
        }
        panel.positions = Some(roll_onto_cylinder(&panel.rest, r));
    }
    Ok(panel)
}

fn parse_scene(v: &Value) -> Result<Scene> {
    let top = object(
        v,
        "",
        &[
            "name",
            "material",
            "loads",
            "seam_tolerance",
            "panels",
            "dirichlet",
            "obstacles",
        ],
    )?;
    let name = match top.get("name") {
        None => String::new(),
        Some(n) => n
            .as_str()
            .ok_or_else(|| bad("name", "expected a string"))?
            .to_string(),
    };
    let mv = required(top, "", "material")?;
    let mo = object(
        mv,
        "material",
        &["young", "poisson", "thickness", "density"],
    )?;
    let material = Material {
        young: number(required(mo, "material", "young")?, "material.young")?,
        poisson: number(required(mo, "material", "poisson")?, "material.poisson")?,
        thickness: number(required(mo, "material", "thickness")?, "material.thickness")?,
        density: opt_number(mo, "material", "density", 0.0)?,
    };
    let (mut gravity, mut pressure) = ([0.0; 3], 0.0);
    if let Some(l) = top.get("loads") {
        let lo = object(l, "loads", &["gravity", "pressure"])?;
        if let Some(g) = lo.get("gravity") {
            gravity = fixed::<3>(g, "loads.gravity")?;
        }
        pressure = opt_number(lo, "loads", "pressure", 0.0)?;
    }
    let seam_tolerance = opt_number(top, "", "seam_tolerance", 1e-6)?;
    let mut obstacles = Vec::new();
    if let Some(ov) = top.get("obstacles") {
        for (k, o) in array(ov, "obstacles")?.iter().enumerate() {
            obstacles.push(parse_obstacle(o, &format!("obstacles[{k}]"))?);
        }
    }
    let pv = array(required(top, "", "panels")?, "panels")?;
    let mut panels = Vec::with_capacity(pv.len());
    for (p, v) in pv.iter().enumerate() {
        let path = format!("panels[{p}]");
        let po = object(
            v,
            &path,
            &[
                "rest",
                "triangles",
                "positions",
                "polygon",
                "holes",
                "target_vertices",
                "seed",
                "roll_radius",
                "lens",
            ],
        )?;
        if po.contains_key("polygon") {
            panels.push(parse_polygon_panel(po, &path)?);
            continue;
        }
        for key in ["holes", "target_vertices", "seed", "roll_radius", "lens"] {
            if po.contains_key(key) {
                return Err(bad(&join(&path, key), "only allowed with \"polygon\""));
            }
        }
        let rest = array(required(po, &path, "rest")?, &format!("{path}.rest"))?
            .iter()
            .enumerate()
            .map(|(i, x)| fixed::<2>(x, &format!("{path}.rest[{i}]")))
            .collect::<Result<Vec<_>>>()?;
        let triangles = array(
            required(po, &path, "triangles")?,
            &format!("{path}.triangles"),
        )?
        .iter()
        .enumerate()
        .map(|(t, x)| {
            let tp = format!("{path}.triangles[{t}]");
            let a = array(x, &tp)?;
            if a.len() != 3 {
                return Err(bad(&tp, "expected 3 vertex indices"));
            }
            let mut tri = [0u32; 3];
            for (k, y) in a.iter().enumerate() {
                let i = index(y, &format!("{tp}[{k}]"))?;
                tri[k] = u32::try_from(i).map_err(|_| bad(&tp, "index exceeds u32"))?;
            }
            Ok(tri)
        })
        .collect::<Result<Vec<_>>>()?;
        let positions = match po.get("positions") {
            None => None,
            Some(x) => Some(
                array(x, &format!("{path}.positions"))?
                    .iter()
                    .enumerate()
                    .map(|(i, y)| fixed::<3>(y, &format!("{path}.positions[{i}]")))
                    .collect::<Result<Vec<_>>>()?,
            ),
        };
        panels.push(Panel {
            rest,
            triangles,
            positions,
        });
    }
    let mut dirichlet = Vec::new();
    if let Some(dv) = top.get("dirichlet") {
        for (k, d) in array(dv, "dirichlet")?.iter().enumerate() {
            let path = format!("dirichlet[{k}]");
            let o = object(
                d,
                &path,
                &["panel", "vertices", "rest_box", "translation", "rotation"],
            )?;
            let panel = index(required(o, &path, "panel")?, &format!("{path}.panel"))? as usize;
            if !o.contains_key("vertices") && !o.contains_key("rest_box") {
                return Err(bad(
                    &format!("{path}.vertices"),
                    "missing (required unless rest_box is given)",
                ));
            }
            let mut vertices = match o.get("vertices") {
                None => Vec::new(),
                Some(vv) => array(vv, &format!("{path}.vertices"))?
                    .iter()
                    .enumerate()
                    .map(|(i, x)| {
                        let vp = format!("{path}.vertices[{i}]");
                        u32::try_from(index(x, &vp)?).map_err(|_| bad(&vp, "index exceeds u32"))
                    })
                    .collect::<Result<Vec<_>>>()?,
            };
            if let Some(b) = o.get("rest_box") {
                let bp = format!("{path}.rest_box");
                let corners = array(b, &bp)?;
                if corners.len() != 2 {
                    return Err(bad(&bp, "expected [[umin, vmin], [umax, vmax]]"));
                }
                let lo = fixed::<2>(&corners[0], &format!("{bp}[0]"))?;
                let hi = fixed::<2>(&corners[1], &format!("{bp}[1]"))?;
                let Some(p) = panels.get(panel) else {
                    return Err(bad(
                        &format!("{path}.panel"),
                        format!("{panel} is not a panel index (< {})", panels.len()),
                    ));
                };
                let found = p.vertices_in_rest_box(lo, hi);
                if found.is_empty() {
                    return Err(bad(&bp, "no vertex of the panel lies in the box"));
                }
                vertices.extend(found);
                vertices.sort_unstable();
                vertices.dedup();
            }
            let translation = match o.get("translation") {
                None => [0.0; 3],
                Some(t) => fixed::<3>(t, &format!("{path}.translation"))?,
            };
            let rotation = match o.get("rotation") {
                None => None,
                Some(r) => {
                    let rp = format!("{path}.rotation");
                    let ro = object(r, &rp, &["axis", "origin", "degrees"])?;
                    Some(Rotation {
                        axis: fixed::<3>(required(ro, &rp, "axis")?, &format!("{rp}.axis"))?,
                        origin: match ro.get("origin") {
                            None => [0.0; 3],
                            Some(x) => fixed::<3>(x, &format!("{rp}.origin"))?,
                        },
                        degrees: number(required(ro, &rp, "degrees")?, &format!("{rp}.degrees"))?,
                    })
                }
            };
            dirichlet.push(Dirichlet {
                panel,
                vertices,
                motion: Motion {
                    translation,
                    rotation,
                },
            });
        }
    }
    Ok(Scene {
        name,
        material,
        panels,
        gravity,
        pressure,
        dirichlet,
        seam_tolerance,
        obstacles,
    })
}
