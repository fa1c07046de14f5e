//! The JSON format of a [`Scene`] (described in the module docs of `tfw::scene`): reading, where
//! every accessor names the field path in its error and unknown keys are errors, and writing
//! ([`Scene::to_json_string`]) in the form the reader reads back.

use serde_json::{Map, Value};

use super::description::{
    roll_onto_cylinder, Dirichlet, Material, Motion, Obstacle, ObstacleShape, Panel, Rotation,
    Scene, DEFAULT_OBSTACLE_STIFFNESS,
};
use super::validate::{bad, finite};
use crate::tfw::delaunay::PolygonPanel;
use crate::{Error, Result};

impl Scene {
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
}

impl Obstacle {
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

pub(super) fn required<'a>(m: &'a Map<String, Value>, path: &str, key: &str) -> Result<&'a Value> {
    m.get(key)
        .ok_or_else(|| bad(&join(path, key), "missing (required)"))
}

fn opt_number(m: &Map<String, Value>, path: &str, key: &str, default: f64) -> Result<f64> {
    m.get(key)
        .map_or(Ok(default), |v| number(v, &join(path, key)))
}

pub(super) fn array<'a>(v: &'a Value, path: &str) -> Result<&'a Vec<Value>> {
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

pub(super) fn index(v: &Value, path: &str) -> Result<u64> {
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
