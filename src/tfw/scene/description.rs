//! The description of a TFW problem as plain data: the [`Scene`] (flat panels with initial 3D
//! positions, [`Material`], loads, [`Dirichlet`] conditions with their [`Motion`], rigid
//! [`Obstacle`]s) and the assembled [`Model`] the solver works on, with the few computations
//! that belong to the data (Lamé parameters, a motion at a load step, an obstacle's distance, a
//! panel meshed from an outline, a face's rest form). Nothing here checks a field: see
//! `validate.rs`.

use crate::tfw::delaunay::{mesh_polygon, PolygonPanel};
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
