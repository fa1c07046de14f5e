//! TFW scenes in the C ABI: read from a JSON file or string, built from arrays describing one
//! panel, obstacles added, destroyed. A scene handed back is validated (errors name the field).

use super::types::*;
use crate::ffi::boundary::{destroy, requires};
use crate::ffi::common::{guard, PleatStatus};

/// Reads and validates a scene file (JSON; format in docs/guide/tfw.md).
///
/// - `path`: NUL-terminated UTF-8 path; non-NULL.
/// - `out`: receives the new scene (destroy with `pleat_tfw_scene_destroy`); non-NULL.
///
/// Returns `PLEAT_STATUS_IO` when the file cannot be read, `PLEAT_STATUS_INVALID_ARGUMENT`
/// for malformed JSON or an invalid scene (the message names the field, e.g.
/// `scene: material.thickness: must be > 0`), `PLEAT_STATUS_UNSUPPORTED` without `tfw`.
///
/// # Safety
/// `path` is NULL or NUL-terminated; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_read_file(
    path: *const std::ffi::c_char,
    out: *mut *mut PleatTfwScene,
) -> PleatStatus {
    tfw_only!([path, out] guard(|| imp::read_file(path, out)))
}

/// Parses and validates a scene from JSON text (as `pleat_tfw_scene_read_file`).
///
/// - `json`: NUL-terminated UTF-8 text; non-NULL.
/// - `out`: receives the new scene; non-NULL.
///
/// # Safety
/// `json` is NULL or NUL-terminated; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_from_json(
    json: *const std::ffi::c_char,
    out: *mut *mut PleatTfwScene,
) -> PleatStatus {
    tfw_only!([json, out] guard(|| imp::from_json(json, out)))
}

/// Builds a scene of one flat panel from arrays.
///
/// - `rest`: `2 * vertex_count` doubles, the rest (pattern) coordinates `u, v` of each vertex
///   (m); finite; non-NULL.
/// - `vertex_count`: ≥ 3.
/// - `triangles`: `3 * triangle_count` vertex indices, each < `vertex_count`; every triangle
///   must have a positive rest area; non-NULL.
/// - `triangle_count`: ≥ 1.
/// - `positions`: NULL (the initial 3D position of vertex i is `(u_i, v_i, 0)`) or
///   `3 * vertex_count` finite doubles.
/// - `material`: NULL = `pleat_tfw_material_default()`, else a `PleatTfwMaterial` with
///   `struct_size` set.
/// - `clamped`: `clamped_count` vertex indices held by a Dirichlet condition (their target is
///   the initial position plus `translation`); NULL only when `clamped_count` is 0.
/// - `translation`: NULL (no motion) or 3 finite doubles (m).
/// - `out`: receives the new scene; non-NULL.
///
/// Returns `PLEAT_STATUS_INVALID_ARGUMENT` naming the bad argument or scene field.
///
/// # Safety
/// Pointers are NULL or valid for the sizes described above.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_from_arrays(
    rest: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    positions: *const f64,
    material: *const PleatTfwMaterial,
    clamped: *const u32,
    clamped_count: usize,
    translation: *const f64,
    out: *mut *mut PleatTfwScene,
) -> PleatStatus {
    tfw_only!([rest, vertex_count, triangles, triangle_count, positions, material, clamped,
               clamped_count, translation, out]
    guard(|| imp::from_arrays(
        rest, vertex_count, triangles, triangle_count, positions, material, clamped,
        clamped_count, translation, out
    )))
}

/// Adds a rigid obstacle (plane or sphere) to a scene, kept out of by a penalty in the base
/// solve (the scene file's `obstacles`). The obstacle is validated first; on error the scene
/// is unchanged.
///
/// - `scene`: non-NULL; not being solved on another thread.
/// - `obstacle`: non-NULL, `struct_size` set (start from `pleat_tfw_obstacle_default()`);
///   `kind` one of `PLEAT_TFW_OBSTACLE_*`, finite fields, a nonzero plane normal, a sphere
///   radius > 0, stiffness > 0, margin ≥ 0 (the message names the field, e.g.
///   `scene: obstacles[0].radius: must be > 0`).
///
/// # Safety
/// `scene` is NULL or live; `obstacle` is NULL or valid for `obstacle->struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_add_obstacle(
    scene: *mut PleatTfwScene,
    obstacle: *const PleatTfwObstacle,
) -> PleatStatus {
    tfw_only!([scene, obstacle] guard(|| imp::add_obstacle(scene, obstacle)))
}

/// Destroys a scene. NULL is accepted and ignored.
///
/// # Safety
/// `scene` is NULL or a handle from pleat not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_tfw_scene_destroy(scene: *mut PleatTfwScene) {
    destroy(scene)
}

// ---------------------------------------------------------------------------------------------
// Implementation (only with the `tfw` capability)

#[cfg(feature = "tfw")]
pub(super) mod imp {
    use super::*;
    use crate::ffi::boundary::{
        arg_out, arg_ref, arg_slice, check_f64, finite_slice, read_versioned,
    };
    use crate::ffi::common::c_str_arg;

    use crate::tfw::{Dirichlet, Material, Motion, Obstacle, ObstacleShape, Panel, Scene};

    use crate::{Error, Result};

    pub(in crate::ffi::tfw) unsafe fn scene_ref<'a>(s: *const PleatTfwScene) -> Result<&'a Scene> {
        arg_ref(s, "scene").map(|s| &s.scene)
    }

    /// # Safety
    /// As `pleat_tfw_scene_read_file`.
    pub(super) unsafe fn read_file(
        path: *const std::ffi::c_char,
        out: *mut *mut PleatTfwScene,
    ) -> Result<()> {
        let path = c_str_arg(path, "path")?;
        let out = arg_out(out, "out")?;
        let scene = Scene::from_json_file(std::path::Path::new(path))?;
        out.put_boxed(PleatTfwScene { scene });
        Ok(())
    }

    /// # Safety
    /// As `pleat_tfw_scene_from_json`.
    pub(super) unsafe fn from_json(
        json: *const std::ffi::c_char,
        out: *mut *mut PleatTfwScene,
    ) -> Result<()> {
        let text = c_str_arg(json, "json")?;
        let out = arg_out(out, "out")?;
        let scene = Scene::from_json_str(text)?;
        out.put_boxed(PleatTfwScene { scene });
        Ok(())
    }

    /// `n` caller values at `p` (checked count, `n * k` elements), finite when doubles.
    ///
    /// # Safety
    /// `p` is NULL or valid for `n * k` values.
    pub(in crate::ffi::tfw) unsafe fn doubles<'a>(
        p: *const f64,
        n: usize,
        k: usize,
        name: &str,
    ) -> Result<&'a [f64]> {
        let len = n
            .checked_mul(k)
            .ok_or_else(|| Error::InvalidArgument(format!("{name}: count overflows")))?;
        let s = arg_slice(p, len, name)?;
        finite_slice(s, name)?;
        Ok(s)
    }

    /// The Rust material of a C material (checked by `Scene::validate`, which names the
    /// field; only the gravity and pressure are checked here).
    fn material(m: &PleatTfwMaterial) -> Result<(Material, [f64; 3], f64)> {
        finite_slice(&m.gravity, "material->gravity")?;
        let p = m.pressure;
        check_f64(p, p.is_finite(), "material->pressure", "finite")?;
        let mat = Material {
            young: m.young,
            poisson: m.poisson,
            thickness: m.thickness,
            density: m.density,
        };
        Ok((mat, m.gravity, m.pressure))
    }

    /// # Safety
    /// As `pleat_tfw_scene_from_arrays`.
    pub(super) unsafe fn from_arrays(
        rest: *const f64,
        vertex_count: usize,
        triangles: *const u32,
        triangle_count: usize,
        positions: *const f64,
        material_p: *const PleatTfwMaterial,
        clamped: *const u32,
        clamped_count: usize,
        translation: *const f64,
        out: *mut *mut PleatTfwScene,
    ) -> Result<()> {
        let out = arg_out(out, "out")?;
        if vertex_count < 3 || vertex_count > u32::MAX as usize {
            return Err(Error::InvalidArgument(format!(
                "vertex_count is {vertex_count}; must be 3 to 2^32 - 1"
            )));
        }
        if triangle_count == 0 {
            return Err(Error::InvalidArgument("triangle_count is 0".into()));
        }
        let uv = doubles(rest, vertex_count, 2, "rest")?;
        let tri_len = triangle_count
            .checked_mul(3)
            .ok_or_else(|| Error::InvalidArgument("triangle_count overflows".into()))?;
        let tris = arg_slice(triangles, tri_len, "triangles")?;
        if let Some(i) = tris.iter().position(|&v| v as usize >= vertex_count) {
            return Err(Error::InvalidArgument(format!(
                "triangles[{i}] is {}; must be < vertex_count {vertex_count}",
                tris[i]
            )));
        }
        let pos = if positions.is_null() {
            None
        } else {
            let p = doubles(positions, vertex_count, 3, "positions")?;
            Some(p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
        };
        let clamps: &[u32] = if clamped_count == 0 {
            &[]
        } else {
            arg_slice(clamped, clamped_count, "clamped")?
        };
        if let Some(i) = clamps.iter().position(|&v| v as usize >= vertex_count) {
            return Err(Error::InvalidArgument(format!(
                "clamped[{i}] is {}; must be < vertex_count {vertex_count}",
                clamps[i]
            )));
        }
        let shift = if translation.is_null() {
            [0.0; 3]
        } else {
            let t = doubles(translation, 1, 3, "translation")?;
            [t[0], t[1], t[2]]
        };
        let (mat, gravity, pressure) = material(&read_versioned(material_p, "material")?)?;
        let panel = Panel {
            rest: uv.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
            triangles: tris.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            positions: pos,
        };
        let dirichlet = if clamps.is_empty() {
            Vec::new()
        } else {
            vec![Dirichlet {
                panel: 0,
                vertices: clamps.to_vec(),
                motion: Motion {
                    translation: shift,
                    rotation: None,
                },
            }]
        };
        let scene = Scene {
            name: "arrays".into(),
            material: mat,
            panels: vec![panel],
            gravity,
            pressure,
            dirichlet,
            seam_tolerance: 1e-6,
            obstacles: Vec::new(),
        };
        scene.validate()?;
        out.put_boxed(PleatTfwScene { scene });
        Ok(())
    }

    /// The Rust obstacle of a C obstacle (validated by `Obstacle`'s scene check).
    fn obstacle(o: &PleatTfwObstacle) -> Result<Obstacle> {
        let shape = match o.kind {
            PLEAT_TFW_OBSTACLE_PLANE => ObstacleShape::Plane {
                point: o.point,
                normal: o.normal,
            },
            PLEAT_TFW_OBSTACLE_SPHERE => ObstacleShape::Sphere {
                centre: o.point,
                radius: o.radius,
            },
            k => {
                return Err(Error::InvalidArgument(format!(
                    "obstacle->kind is {k}; use PLEAT_TFW_OBSTACLE_PLANE or _SPHERE"
                )))
            }
        };
        Ok(Obstacle {
            shape,
            stiffness: o.stiffness,
            margin: o.margin,
        })
    }

    /// # Safety
    /// As `pleat_tfw_scene_add_obstacle`.
    pub(super) unsafe fn add_obstacle(
        scene: *mut PleatTfwScene,
        obstacle_p: *const PleatTfwObstacle,
    ) -> Result<()> {
        let s = scene
            .as_mut()
            .ok_or_else(|| crate::ffi::common::null_arg("scene"))?;
        crate::ffi::boundary::non_null(obstacle_p, "obstacle")?;
        let o = obstacle(&read_versioned(obstacle_p, "obstacle")?)?;
        let mut next = s.scene.clone();
        next.obstacles.push(o);
        next.validate()?;
        s.scene = next;
        Ok(())
    }
}
