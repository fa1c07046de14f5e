//! Validation of a [`Scene`]: every field is checked and an error (`InvalidArgument`, message
//! `scene: <field path>: <what>`) names the bad one; questionable but valid values come back as
//! warnings. The field-error functions here are shared by the JSON reader and the assembly.

use super::description::{rest_form, Obstacle, ObstacleShape, Panel, Scene};
use crate::{Error, Result};

pub(super) fn bad(path: &str, msg: impl std::fmt::Display) -> Error {
    Error::InvalidArgument(format!("scene: {path}: {msg}"))
}

pub(super) fn finite(path: &str, x: f64) -> Result<f64> {
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
}

impl Obstacle {
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
