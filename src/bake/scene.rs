//! glTF scenes in, glTF scenes out: one LOD chain per mesh, with the whole document kept.
//!
//! [`GltfScene`] reads a `.glb`/`.gltf` once: the raw JSON (a `serde_json` value, so every
//! property survives, known or not) and the buffers (validated and loaded as the geometry
//! reader does). [`lod_scene`] bakes one chain per glTF mesh that some node instantiates, in
//! the mesh's **local space** and **once**, however many nodes instance it. [`scene_glb`] writes
//! the document back as one GLB with the levels added.
//!
//! # What is kept
//!
//! Everything in the input JSON is written back unchanged except buffers, buffer views and
//! images, which are repacked: every buffer view is copied into the one `BIN` chunk (4-byte
//! aligned, same index, `buffer` 0), external and `data:` images are embedded as buffer views,
//! and the buffer list becomes one buffer (the first buffer's `name`/`extras` kept). Accessor,
//! buffer view, mesh, material, texture, image, sampler, node, skin, animation and camera
//! indices of the input stay valid: new objects are appended at the end of their arrays, so
//! scene roots, children, skin joints and skeletons, animation channel targets and
//! `KHR_lights_punctual` references need no remapping. Names, `extras` and extensions pleat
//! does not know are copied where they are. Required extensions the reader cannot honour
//! (Draco, meshopt, GPU instancing, ...) make reading fail (ignoring them would give wrong
//! geometry); the readable ones are listed in `mesh::io::gltf`. A `EXT_meshopt_compression`
//! that is only *used* (with a fallback) is not supported: its buffer references are not
//! remapped.
//!
//! # Levels
//!
//! The levels of a chain are sorted finest first (largest `n_p`). The screen size `n_p` maps
//! to the mesh's own local bounding-box diagonal `l` (`d = l / n_p`); a node with scale `s`
//! shows the mesh at `s · l` world units, and `MSFT_screencoverage` is relative to the size of
//! each instance on screen, so the same chain serves every instance at any scale: a level made
//! for `n_p` is indistinguishable from the mesh whenever that instance's diagonal covers at
//! most `n_p` pixels.
//!
//! A level is **kept** (the input mesh is used for it, textures untouched; [`Kept`] says why)
//! when the mesh has at most `target_faces` triangles, when its LOD has at least as many
//! triangles as the mesh, when the mesh is skinned or has morph targets and
//! [`transfer_deformation`] refused the level, or when the LOD pipeline failed on it. So no
//! level is ever larger than its input.
//!
//! # Skinned and morphed meshes
//!
//! A level of a skinned or morphed mesh is made in the bind pose (the mesh's local-space
//! geometry) and carries the mesh's deformation, transferred by [`crate::transfer`]
//! ([`transfer_deformation`]): `JOINTS_0`/`WEIGHTS_0` (and `JOINTS_1`/`WEIGHTS_1` when the
//! mesh has 8 influences) per level vertex, joints as `UNSIGNED_SHORT` indices into the same
//! skin, weights as `FLOAT` summing to 1 within `1e-6`; and every morph target of the mesh,
//! in order, with its `POSITION` (and `NORMAL`/`TANGENT`) displacements interpolated
//! barycentrically, the mesh's default `weights` and `extras.targetNames` copied. The level
//! nodes carry the instancing node's `skin` and `weights`, so the skin's joints and weight
//! animations of the instancing node drive every level.
//!
//! # Written nodes
//!
//! Each node instancing a mesh whose chain has at least one new level gets the extension
//! `MSFT_lod` with `ids` = new nodes, one per coarser level (finest first), appended at the end
//! of `nodes`, each with the instancing node's `translation`/`rotation`/`scale`/`matrix`,
//! `skin` and `weights`, a
//! name `<node>_LOD<k>` and `extras.pleat_screen_size`; and `extras.MSFT_screencoverage`
//! ([`screen_coverage`] of each next level's `n_p`, 0 for the coarsest). The level nodes are
//! not children of any node: a viewer implementing `MSFT_lod` puts them in place of the
//! instancing node (same parent, same transform), and a viewer that does not shows the input
//! mesh alone instead of every level on top of each other. A chain whose levels are all kept
//! adds nothing. With [`WriteOptions::drop_original`] the instancing node shows the finest
//! level instead of the input mesh (which stays in `meshes`, unused).
//!
//! A new level is a mesh `<mesh>_LOD<k>` with one indexed `TRIANGLES` primitive. Baked
//! ([`SceneParams::bake`]), it has its own material and images, as [`super::chain_glb`]
//! writes them. Not baked, it has `POSITION` only (viewers compute flat normals) and the
//! material of the mesh's first triangle primitive, or, when that material samples a texture
//! (a texture needs `TEXCOORD`s the LOD does not have), a copy of it named
//! `<material> (untextured)` without its texture references (factors kept).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::appearance::{mesh_appearance, raw_json, Appearance};
use super::bake::{bake_level_with_progress, BakeParams};
use super::level::BakedLevel;
use super::output::{encode_images, glb_container, push_level, screen_coverage, Arrays, Bin};
use super::provenance::InputIndex;
use crate::lowpoly::{LodParams, LodReport};
use crate::mesh::io::gltf::{self as io, LoadedDocument};
use crate::mesh::io::{parse_error, NodeFilter};
use crate::mesh::TriMesh;
use crate::report::{Progress, ProgressFn};
use crate::{Error, Result};

/// A glTF document read for per-mesh LODs: its raw JSON and its loaded buffers.
pub struct GltfScene {
    json: Value,
    loaded: LoadedDocument,
    name: String,
    base: Option<PathBuf>,
}

impl GltfScene {
    /// Reads a `.glb` or `.gltf` file (external buffers and images relative to its folder).
    /// Errors: `Io` when the file cannot be read, `Parse` when it is not valid glTF for
    /// pleat's reader (including a required extension it cannot read).
    pub fn read(path: &Path) -> Result<GltfScene> {
        let name = path.display().to_string();
        let data = std::fs::read(path).map_err(|e| crate::mesh::io::io_error(&name, &e))?;
        let base = path.parent().unwrap_or(Path::new("."));
        GltfScene::from_bytes(&data, Some(base), &name)
    }

    /// Reads binary or JSON glTF from memory; `name` stands for the file in messages and
    /// external files resolve against `base_dir` (`None`: embedded data only).
    pub fn from_bytes(data: &[u8], base_dir: Option<&Path>, name: &str) -> Result<GltfScene> {
        let loaded = io::load_document(data, base_dir, name)?;
        let json = raw_json(data)
            .ok_or_else(|| parse_error(name, "the glTF JSON cannot be parsed as JSON"))?;
        Ok(GltfScene {
            json,
            loaded,
            name: name.to_string(),
            base: base_dir.map(Path::to_path_buf),
        })
    }

    /// The document's JSON as read.
    pub fn json(&self) -> &Value {
        &self.json
    }

    /// Number of meshes of the document.
    pub fn mesh_count(&self) -> usize {
        self.array("meshes").len()
    }

    fn array(&self, key: &str) -> &[Value] {
        self.json
            .get(key)
            .and_then(Value::as_array)
            .map_or(&[], Vec::as_slice)
    }

    /// The name of mesh `mesh`, or `mesh <index>` when it has none.
    pub fn mesh_name(&self, mesh: usize) -> String {
        self.array("meshes")
            .get(mesh)
            .and_then(|m| m.get("name"))
            .and_then(Value::as_str)
            .map_or_else(|| format!("mesh {mesh}"), str::to_string)
    }

    /// How many nodes reference mesh `mesh` (in any scene or none).
    pub fn instances(&self, mesh: usize) -> usize {
        self.array("nodes")
            .iter()
            .filter(|n| n.get("mesh").and_then(Value::as_u64) == Some(mesh as u64))
            .count()
    }

    /// Per mesh, whether a node that `filter` selects (by name or index, with its subtree,
    /// in any scene or none) instances it. Errors (`InvalidArgument`) when no node matches.
    pub fn meshes_of(&self, filter: &NodeFilter) -> Result<Vec<bool>> {
        let nodes = self.array("nodes");
        let names: Vec<Option<&str>> = nodes
            .iter()
            .map(|n| n.get("name").and_then(Value::as_str))
            .collect();
        let children: Vec<Vec<usize>> = nodes
            .iter()
            .map(|n| {
                n.get("children")
                    .and_then(Value::as_array)
                    .map_or_else(Vec::new, |c| {
                        c.iter()
                            .filter_map(Value::as_u64)
                            .map(|i| i as usize)
                            .collect()
                    })
            })
            .collect();
        let selected = filter.select(&names, &children)?;
        let mut meshes = vec![false; self.mesh_count()];
        for (node, _) in nodes.iter().zip(&selected).filter(|(_, &s)| s) {
            if let Some(m) = node.get("mesh").and_then(Value::as_u64) {
                if let Some(x) = meshes.get_mut(m as usize) {
                    *x = true;
                }
            }
        }
        Ok(meshes)
    }

    /// Whether mesh `mesh` deforms: a primitive with `JOINTS_0`/`WEIGHTS_0` or morph
    /// `targets`, or a node instancing it with a `skin` or `weights`.
    pub fn is_deformable(&self, mesh: usize) -> bool {
        let prims = self
            .array("meshes")
            .get(mesh)
            .and_then(|m| m.get("primitives"))
            .and_then(Value::as_array);
        let in_prims = prims.is_some_and(|ps| {
            ps.iter().any(|p| {
                let a = p.get("attributes");
                a.is_some_and(|a| a.get("JOINTS_0").is_some() || a.get("WEIGHTS_0").is_some())
                    || p.get("targets")
                        .and_then(Value::as_array)
                        .is_some_and(|t| !t.is_empty())
            })
        });
        in_prims
            || self.array("nodes").iter().any(|n| {
                n.get("mesh").and_then(Value::as_u64) == Some(mesh as u64)
                    && (n.get("skin").is_some() || n.get("weights").is_some())
            })
    }

    /// The triangles of mesh `mesh` in its local space (its triangle primitives in order,
    /// unwelded). `Parse` when it has none.
    pub fn mesh_geometry(&self, mesh: usize) -> Result<TriMesh> {
        io::mesh_geometry(&self.loaded, mesh, &self.name)
    }

    /// The appearance of mesh `mesh` in its local space
    /// ([`super::appearance::read_mesh_appearance_bytes`] on this document); its `mesh` equals
    /// [`mesh_geometry`](Self::mesh_geometry).
    pub fn mesh_appearance(&self, mesh: usize) -> Result<Appearance> {
        mesh_appearance(
            &self.loaded,
            Some(&self.json),
            self.base.as_deref(),
            &self.name,
            mesh,
        )
    }

    /// The deformation attributes of mesh `mesh` per vertex of
    /// [`mesh_geometry`](Self::mesh_geometry) (same vertex order): `JOINTS_0`, `WEIGHTS_0`,
    /// `JOINTS_1`, `WEIGHTS_1` and `TARGET<i>_POSITION`, `TARGET<i>_NORMAL`,
    /// `TARGET<i>_TANGENT` (morph target `i`'s displacements), each a row of components per
    /// vertex (normalised integers read as reals), zeros where a primitive lacks the
    /// attribute. Only semantics some primitive has are present.
    pub fn vertex_attributes(&self, mesh: usize) -> Result<BTreeMap<String, Vec<Vec<f64>>>> {
        let mut out: BTreeMap<String, Vec<Vec<f64>>> = BTreeMap::new();
        let mut count = 0usize;
        let (buffers, name) = (&self.loaded.buffers, self.name.as_str());
        io::for_each_mesh_primitive(
            &self.loaded.document,
            mesh,
            name,
            &mut |prim, pos, _, what| {
                let n = pos.count();
                let mut accessors = Vec::new();
                for set in 0..2 {
                    if let Some(a) = prim.get(&::gltf::Semantic::Joints(set)) {
                        accessors.push((format!("JOINTS_{set}"), a));
                    }
                    if let Some(a) = prim.get(&::gltf::Semantic::Weights(set)) {
                        accessors.push((format!("WEIGHTS_{set}"), a));
                    }
                }
                for (i, t) in prim.morph_targets().enumerate() {
                    let sems = [
                        ("POSITION", t.positions()),
                        ("NORMAL", t.normals()),
                        ("TANGENT", t.tangents()),
                    ];
                    for (sem, a) in sems {
                        if let Some(a) = a {
                            accessors.push((format!("TARGET{i}_{sem}"), a));
                        }
                    }
                }
                for (key, acc) in accessors {
                    let k = acc.dimensions().multiplicity();
                    let v = io::accessor_values(&acc, buffers, name, what)?;
                    if acc.count() != n {
                        return Err(parse_error(name, format!("{what}: {key} count is wrong")));
                    }
                    let rows = out.entry(key).or_insert_with(|| vec![vec![0.0; k]; count]);
                    rows.resize(count, vec![0.0; k]);
                    rows.extend(v.chunks_exact(k).map(<[f64]>::to_vec));
                }
                count += n;
                Ok(())
            },
        )?;
        for rows in out.values_mut() {
            let k = rows.first().map_or(0, Vec::len);
            rows.resize(count, vec![0.0; k]);
        }
        Ok(out)
    }

    /// The skin of the first node instancing mesh `mesh` with one.
    fn skin_of(&self, mesh: usize) -> Option<usize> {
        self.array("nodes").iter().find_map(|n| {
            (n.get("mesh").and_then(Value::as_u64) == Some(mesh as u64))
                .then(|| n.get("skin").and_then(Value::as_u64))
                .flatten()
                .map(|s| s as usize)
        })
    }

    /// The bind-pose pivot of each joint of mesh `mesh`'s skin in the mesh's space, by joint
    /// index: the origin of the joint's space, i.e. the inverse of its inverse bind matrix
    /// applied to the origin (identity matrices when the skin has none). Empty without a skin;
    /// a joint whose matrix is singular gets no pivot (the lever of a joint without one).
    pub fn joint_pivots(&self, mesh: usize) -> Vec<[f64; 3]> {
        let Some(skin) = self
            .skin_of(mesh)
            .and_then(|s| self.loaded.document.skins().nth(s))
        else {
            return Vec::new();
        };
        let buffers = &self.loaded.buffers;
        let reader = skin.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let n = skin.joints().count();
        let matrices: Vec<[[f32; 4]; 4]> = match reader.read_inverse_bind_matrices() {
            Some(m) => m.collect(),
            None => vec![glam::Mat4::IDENTITY.to_cols_array_2d(); n],
        };
        let mut pivots = Vec::with_capacity(n);
        for m in matrices {
            let m = glam::DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)));
            if m.determinant().abs() <= f64::EPSILON {
                break;
            }
            pivots.push(m.inverse().transform_point3(glam::DVec3::ZERO).to_array());
        }
        pivots
    }

    /// The largest angle in radians by which an animation turns one of mesh `mesh`'s skin
    /// joints from its rest rotation (its node's `rotation`), over every rotation keyframe;
    /// 0 without a skin or rotation animation.
    pub fn max_joint_rotation(&self, mesh: usize) -> f64 {
        let Some(skin) = self
            .skin_of(mesh)
            .and_then(|s| self.loaded.document.skins().nth(s))
        else {
            return 0.0;
        };
        let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
        let buffers = &self.loaded.buffers;
        let mut max = 0.0f64;
        for anim in self.loaded.document.animations() {
            for ch in anim.channels() {
                let node = ch.target().node();
                if !joints.contains(&node.index()) {
                    continue;
                }
                let reader = ch.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
                let Some(::gltf::animation::util::ReadOutputs::Rotations(r)) =
                    reader.read_outputs()
                else {
                    continue;
                };
                let rest = glam::DQuat::from_array(node.transform().decomposed().1.map(f64::from));
                for q in r.into_f32() {
                    let q = glam::DQuat::from_array(q.map(f64::from)).normalize();
                    let cos = q.dot(rest).abs().min(1.0);
                    max = max.max(2.0 * cos.acos());
                }
            }
        }
        max
    }

    /// The number of morph targets of mesh `mesh` (the most any of its primitives has).
    pub fn morph_target_count(&self, mesh: usize) -> usize {
        self.array("meshes")
            .get(mesh)
            .and_then(|m| m.get("primitives"))
            .and_then(Value::as_array)
            .map_or(0, |ps| {
                ps.iter()
                    .filter_map(|p| p.get("targets").and_then(Value::as_array))
                    .map(Vec::len)
                    .max()
                    .unwrap_or(0)
            })
    }

    /// The material index of mesh `mesh`'s first triangle primitive (`None`: default material).
    fn first_material(&self, mesh: usize) -> Option<usize> {
        let prims = self
            .array("meshes")
            .get(mesh)?
            .get("primitives")?
            .as_array()?;
        let p = prims
            .iter()
            .find(|p| p.get("mode").and_then(Value::as_u64).unwrap_or(4) >= 4)?;
        p.get("material")?.as_u64().map(|m| m as usize)
    }
}

/// Parameters of [`lod_scene`].
#[derive(Debug, Clone)]
pub struct SceneParams {
    /// Screen sizes `n_p` of the levels (any order; levels come out finest first, duplicates
    /// removed).
    pub screen_sizes: Vec<f64>,
    /// LOD parameters (`screen_size` is replaced per level; `target_faces` applies to a
    /// single screen size only, as in [`super::bake_chain`]).
    pub lod: LodParams,
    /// Cages instead of LODs (`crate::cage`); cages are never baked.
    pub cage: bool,
    /// Bake the mesh's materials onto each new level.
    pub bake: Option<BakeParams>,
    /// The largest posed error the skin of a skinned mesh may add to its levels, in pixels at
    /// each level's screen size (`DeformationField::max_skin_error`; 0: the default
    /// [`crate::lowpoly::SKIN_ERROR`]).
    pub skin_error: f64,
    /// Chains only for the meshes that a node it selects instances (`None`: every instanced
    /// mesh). A mesh also instanced by unselected nodes gets its chain there too: the chain
    /// belongs to the mesh.
    pub nodes: Option<NodeFilter>,
}

/// Why a level is the input mesh itself.
#[derive(Debug, Clone, PartialEq)]
pub enum Kept {
    /// The mesh has at most the level's face target.
    AtBudget {
        /// The face target.
        budget: usize,
    },
    /// The LOD has at least as many triangles as the mesh.
    NotSmaller {
        /// Triangles of the LOD that was discarded.
        lod_faces: usize,
    },
    /// The mesh has at most 4 triangles: no closed LOD (a tetrahedron at least) has fewer.
    Minimal,
    /// The mesh is skinned or has morph targets and [`transfer_deformation`] refused this
    /// level (the reason).
    Deformable(String),
    /// The LOD pipeline or the bake failed on this mesh (the message).
    Failed(String),
}

impl std::fmt::Display for Kept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Kept::AtBudget { budget } => write!(f, "unchanged (at or below {budget} faces)"),
            Kept::NotSmaller { lod_faces } => {
                write!(f, "unchanged (the LOD had {lod_faces} faces, not fewer)")
            }
            Kept::Minimal => write!(f, "unchanged (no closed LOD has fewer faces)"),
            Kept::Deformable(e) => write!(
                f,
                "unchanged (skinned/morphed: deformation transfer refused: {e})"
            ),
            Kept::Failed(e) => write!(f, "unchanged (LOD failed: {e})"),
        }
    }
}

/// One level of a mesh's chain.
#[derive(Debug, Clone)]
pub struct SceneLevel {
    /// Screen size `n_p`.
    pub screen_size: f64,
    /// Triangles of the level (the mesh's own when kept).
    pub faces: usize,
    /// `Some` when the level is the input mesh itself.
    pub kept: Option<Kept>,
    /// The new geometry (`None` when kept).
    pub lod: Option<TriMesh>,
    /// The pipeline's report of the new geometry.
    pub stats: Option<LodReport>,
    /// The baked level when baking (`None` when kept or not baking).
    pub baked: Option<BakedLevel>,
    /// Skin influences and morph targets per vertex of the written level (of `baked` when
    /// baked, else of `lod`); `None` when kept or when the mesh does not deform.
    pub deformation: Option<Deformation>,
}

/// The chain of one glTF mesh.
#[derive(Debug, Clone)]
pub struct MeshChain {
    /// Index of the mesh in the document.
    pub mesh: usize,
    /// Its name (or `mesh <index>`).
    pub name: String,
    /// Nodes instancing it.
    pub instances: usize,
    /// Triangles of the mesh (its triangle primitives together).
    pub faces: usize,
    /// Levels, finest first.
    pub levels: Vec<SceneLevel>,
    /// Wall seconds spent on this mesh (geometry and bake).
    pub seconds: f64,
}

/// Triangles of the smallest closed mesh (a tetrahedron): a mesh with at most this many is
/// kept without running the pipeline, whose output is always closed.
const MIN_CLOSED_FACES: usize = 4;

/// Per-vertex deformation attributes of a level: what a skinned or morphed mesh's level needs.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Deformation {
    /// Influences per vertex: 4 (`JOINTS_0`/`WEIGHTS_0`), 8 when the mesh also has
    /// `JOINTS_1`/`WEIGHTS_1`, 0 when it is not skinned.
    pub influences: usize,
    /// Joint indices (into the skin's `joints`), `influences` per vertex, slots sorted by weight
    /// descending; unused slots are joint 0 with weight 0.
    pub joints: Vec<u16>,
    /// Weights, `influences` per vertex, each vertex's summing to 1 within `1e-6`.
    pub weights: Vec<f32>,
    /// Morph targets in the mesh's order: per target, its displacements by semantic
    /// (`POSITION`, `NORMAL`, `TANGENT`, those the mesh has; `POSITION` zeros when it has none),
    /// one entry per vertex.
    pub targets: Vec<Vec<(String, Vec<[f32; 3]>)>>,
}

impl Deformation {
    /// The attributes of vertex `map[i]` on vertex `i` (a level whose vertices were split).
    fn remap(&self, map: &[usize]) -> Deformation {
        let k = self.influences;
        Deformation {
            influences: k,
            joints: map
                .iter()
                .flat_map(|&i| &self.joints[i * k..(i + 1) * k])
                .copied()
                .collect(),
            weights: map
                .iter()
                .flat_map(|&i| &self.weights[i * k..(i + 1) * k])
                .copied()
                .collect(),
            targets: self
                .targets
                .iter()
                .map(|t| {
                    t.iter()
                        .map(|(s, v)| (s.clone(), map.iter().map(|&i| v[i]).collect()))
                        .collect()
                })
                .collect(),
        }
    }
}

/// The one place where skin weights and morph targets are carried from a mesh to its LOD, by
/// [`crate::transfer`]: `input` is the mesh in local space (its bind pose,
/// [`GltfScene::mesh_geometry`]), `attributes` its per-vertex attributes
/// ([`GltfScene::vertex_attributes`]), `targets` the mesh's morph target count, `lod` the
/// level made at screen size `screen_size`.
///
/// Skin: the influences of `JOINTS_0`/`WEIGHTS_0` (and `JOINTS_1`/`WEIGHTS_1`: up to 8) by
/// [`crate::transfer::Correspondence::transfer_skin`] with the default rule, as many per vertex
/// as the mesh has (4 or 8). Morph targets: each displacement interpolated barycentrically
/// ([`crate::transfer::TransferMode::Barycentric`]).
///
/// Errors: `InvalidArgument` when the correspondence is refused (the LOD is not within the
/// wrong-input bound of the mesh), when the attributes do not have one row per input vertex,
/// when an input vertex used by the LOD has no positive skin weight, or when a joint index
/// exceeds 65535.
pub fn transfer_deformation(
    input: &TriMesh,
    attributes: &BTreeMap<String, Vec<Vec<f64>>>,
    targets: usize,
    lod: &TriMesh,
    screen_size: f64,
) -> Result<Deformation> {
    use crate::transfer::{Correspondence, SkinParams, TransferMode, TransferParams};
    let n = input.vertex_count();
    if let Some((key, rows)) = attributes.iter().find(|(_, r)| r.len() != n) {
        return Err(Error::InvalidArgument(format!(
            "{key} has {} rows for {n} vertices",
            rows.len()
        )));
    }
    let corr = Correspondence::new(input, lod, &TransferParams::for_screen_size(screen_size))?;
    let flat = |key: &str, k: usize| -> Option<Vec<f64>> {
        attributes.get(key).map(|rows| {
            rows.iter()
                .flat_map(|r| (0..k).map(|j| r.get(j).copied().unwrap_or(0.0)))
                .collect()
        })
    };
    let mut out = Deformation::default();
    if let (Some(j0), Some(w0)) = (flat("JOINTS_0", 4), flat("WEIGHTS_0", 4)) {
        let second = flat("JOINTS_1", 4).zip(flat("WEIGHTS_1", 4));
        let m = if second.is_some() { 8 } else { 4 };
        let (mut joints, mut weights) = (Vec::with_capacity(n * m), Vec::with_capacity(n * m));
        for v in 0..n {
            let r = v * 4..v * 4 + 4;
            joints.extend(j0[r.clone()].iter().map(|&j| j as u32));
            weights.extend(w0[r.clone()].iter().map(|&w| w as f32));
            if let Some((j1, w1)) = &second {
                joints.extend(j1[r.clone()].iter().map(|&j| j as u32));
                weights.extend(w1[r].iter().map(|&w| w as f32));
            }
        }
        let params = SkinParams {
            max_influences: m,
            ..SkinParams::default()
        };
        let skin = corr.transfer_skin(&joints, &weights, m, &params)?;
        out.influences = skin.influences;
        out.joints = skin
            .joints
            .iter()
            .map(|&j| {
                u16::try_from(j)
                    .map_err(|_| Error::InvalidArgument(format!("joint index {j} exceeds 65535")))
            })
            .collect::<Result<_>>()?;
        out.weights = skin.weights;
    }
    for t in 0..targets {
        let mut target = Vec::new();
        for sem in ["POSITION", "NORMAL", "TANGENT"] {
            let Some(values) = flat(&format!("TARGET{t}_{sem}"), 3) else {
                continue;
            };
            let values: Vec<f32> = values.iter().map(|&x| x as f32).collect();
            let moved = corr.transfer_f32(&values, 3, TransferMode::Barycentric)?;
            let rows = moved.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            target.push((sem.to_string(), rows));
        }
        if target.is_empty() {
            target.push(("POSITION".into(), vec![[0.0; 3]; lod.vertex_count()]));
        }
        out.targets.push(target);
    }
    Ok(out)
}

/// A mesh's per-vertex deformation attributes ([`GltfScene::vertex_attributes`]) and its morph
/// target count.
type MeshDeformation = (BTreeMap<String, Vec<Vec<f64>>>, usize);

/// The deformation the LOD of a skinned or morphed mesh follows (`LodParams::deformation`):
/// its `JOINTS_0`/`WEIGHTS_0` (and `JOINTS_1`/`WEIGHTS_1`) influences and its morph targets'
/// `POSITION` displacements, per vertex of `input` ([`GltfScene::vertex_attributes`] and the
/// target count), its skin's joint pivots and the largest joint turn of its animations (at
/// least [`crate::lowpoly::DEFAULT_MAX_ROTATION`]). `None` for a mesh without either.
fn deformation_field(
    scene: &GltfScene,
    mesh: usize,
    input: &TriMesh,
    deform: Option<&MeshDeformation>,
    skin_error: f64,
) -> Result<Option<crate::lowpoly::DeformationField>> {
    let Some((attributes, targets)) = deform else {
        return Ok(None);
    };
    let n = input.vertex_count();
    let rows = |key: &str| attributes.get(key).filter(|r| r.len() == n);
    let mut field = crate::lowpoly::DeformationField {
        joint_pivots: scene.joint_pivots(mesh),
        // The animations' largest turn, and at least the default: an engine may play others.
        max_rotation: scene
            .max_joint_rotation(mesh)
            .max(crate::lowpoly::DEFAULT_MAX_ROTATION),
        max_skin_error: skin_error,
        ..Default::default()
    };
    for set in 0..2 {
        let (Some(j), Some(w)) = (
            rows(&format!("JOINTS_{set}")),
            rows(&format!("WEIGHTS_{set}")),
        ) else {
            break;
        };
        field.influences += 4;
        let (mut joints, mut weights) = (Vec::new(), Vec::new());
        for v in 0..n {
            for k in 0..4 {
                joints.push(j[v].get(k).copied().unwrap_or(0.0) as u32);
                weights.push(w[v].get(k).copied().unwrap_or(0.0) as f32);
            }
        }
        field.joints = interleave(&field.joints, &joints, field.influences - 4, n);
        field.weights = interleave(&field.weights, &weights, field.influences - 4, n);
    }
    for t in 0..*targets {
        if let Some(d) = rows(&format!("TARGET{t}_POSITION")) {
            let deltas = d
                .iter()
                .map(|r| [0, 1, 2].map(|i| r.get(i).copied().unwrap_or(0.0) as f32))
                .collect();
            field.morph_deltas.push(deltas);
        }
    }
    field.validate(n)?;
    Ok((!field.is_empty()).then_some(field))
}

/// Per vertex, the `k` entries of `a` then the 4 of `b` (`n` vertices).
fn interleave<T: Copy>(a: &[T], b: &[T], k: usize, n: usize) -> Vec<T> {
    (0..n)
        .flat_map(|v| a[v * k..(v + 1) * k].iter().chain(&b[v * 4..v * 4 + 4]))
        .copied()
        .collect()
}

/// The chains of every mesh that some node instantiates, in mesh order. Each is baked once in
/// the mesh's local space (see the [module docs](self)); `progress` sees `mesh i/n: <stage>`
/// with the fraction over all meshes; returning `false` cancels with `Error::Cancelled`. A
/// failure of the pipeline on one mesh keeps that mesh ([`Kept::Failed`]); reading errors and
/// cancellation are returned. Deterministic: meshes run one after the other, each level being
/// the pipeline's deterministic output.
pub fn lod_scene(
    scene: &GltfScene,
    params: &SceneParams,
    progress: &mut ProgressFn<'_>,
) -> Result<Vec<MeshChain>> {
    let mut sizes = params.screen_sizes.clone();
    if sizes.is_empty() || sizes.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(Error::InvalidArgument(
            "screen sizes must be finite and > 0 (at least one)".into(),
        ));
    }
    sizes.sort_by(|a, b| b.total_cmp(a));
    sizes.dedup();
    let chosen = match &params.nodes {
        Some(f) => scene.meshes_of(f)?,
        None => vec![true; scene.mesh_count()],
    };
    let meshes: Vec<usize> = (0..scene.mesh_count())
        .filter(|&m| chosen[m] && scene.instances(m) > 0)
        .collect();
    let n = meshes.len().max(1) as f64;
    let mut chains = Vec::new();
    for (i, &m) in meshes.iter().enumerate() {
        let t = std::time::Instant::now();
        let label = format!("mesh {}/{}", i + 1, meshes.len());
        let mut prog = |p: Progress<'_>| {
            progress(Progress {
                stage: &format!("{label}: {}", p.stage),
                fraction: (i as f64 + p.fraction.clamp(0.0, 1.0)) / n,
            })
        };
        if !prog(Progress {
            stage: "read",
            fraction: 0.0,
        }) {
            return Err(Error::Cancelled);
        }
        let app = match &params.bake {
            Some(_) if !params.cage => Some(scene.mesh_appearance(m)?),
            _ => None,
        };
        let geometry = match &app {
            Some(a) => a.mesh.clone(),
            None => match scene.mesh_geometry(m) {
                Ok(g) => g,
                // A mesh without triangles (points, lines) has no chain.
                Err(Error::Parse { .. }) if no_triangles(scene, m) => continue,
                Err(e) => return Err(e),
            },
        };
        let faces = geometry.triangle_count();
        let kept_all = |k: Kept| -> Vec<SceneLevel> {
            sizes
                .iter()
                .map(|&s| SceneLevel {
                    screen_size: s,
                    faces,
                    kept: Some(k.clone()),
                    lod: None,
                    stats: None,
                    baked: None,
                    deformation: None,
                })
                .collect()
        };
        let levels = if faces <= MIN_CLOSED_FACES {
            kept_all(Kept::Minimal)
        } else if let Some(budget) = params.lod.target_faces.filter(|&f| faces <= f) {
            kept_all(Kept::AtBudget { budget })
        } else {
            match mesh_levels(scene, m, &geometry, app.as_ref(), &sizes, params, &mut prog) {
                Ok(l) => l,
                Err(Error::Cancelled) => return Err(Error::Cancelled),
                Err(e) => kept_all(Kept::Failed(e.to_string())),
            }
        };
        chains.push(MeshChain {
            mesh: m,
            name: scene.mesh_name(m),
            instances: scene.instances(m),
            faces,
            levels,
            seconds: t.elapsed().as_secs_f64(),
        });
    }
    Ok(chains)
}

/// Whether mesh `m` has no triangle primitive at all (so reading its geometry fails by
/// design, not because the file is broken).
fn no_triangles(scene: &GltfScene, m: usize) -> bool {
    let prims = scene
        .array("meshes")
        .get(m)
        .and_then(|x| x.get("primitives"))
        .and_then(Value::as_array);
    prims.is_none_or(|ps| {
        ps.iter()
            .all(|p| p.get("mode").and_then(Value::as_u64).unwrap_or(4) < 4)
    })
}

/// The levels of one mesh: the pipeline's chain, each level kept when not smaller, baked when
/// asked.
fn mesh_levels(
    scene: &GltfScene,
    m: usize,
    geometry: &TriMesh,
    app: Option<&Appearance>,
    sizes: &[f64],
    params: &SceneParams,
    prog: &mut ProgressFn<'_>,
) -> Result<Vec<SceneLevel>> {
    let deform = if scene.is_deformable(m) {
        Some((scene.vertex_attributes(m)?, scene.morph_target_count(m)))
    } else {
        None
    };
    let share = if app.is_some() {
        super::GEOMETRY_SHARE
    } else {
        1.0
    };
    let lods = {
        let mut geo = |p: Progress<'_>| {
            prog(Progress {
                stage: p.stage,
                fraction: share * p.fraction,
            })
        };
        let single = sizes.len() == 1 && params.lod.target_faces.is_some();
        let p = LodParams {
            screen_size: sizes[0],
            deformation: deformation_field(scene, m, geometry, deform.as_ref(), params.skin_error)?
                .map(std::sync::Arc::new),
            ..params.lod.clone()
        };
        match (single, params.cage) {
            (true, false) => vec![crate::lowpoly::generate(geometry, &p, &mut geo)?],
            (false, false) => crate::lowpoly::generate_chain(geometry, sizes, &p, &mut geo)?,
            #[cfg(feature = "cage")]
            (true, true) => vec![crate::cage::generate(geometry, &p, &mut geo)?],
            #[cfg(feature = "cage")]
            (false, true) => crate::cage::generate_chain(geometry, sizes, &p, &mut geo)?,
            #[cfg(not(feature = "cage"))]
            (_, true) => {
                return Err(Error::InvalidArgument(
                    "cages need pleat's `cage` feature".into(),
                ))
            }
        }
    };
    let faces = geometry.triangle_count();
    let index = app.map(|a| InputIndex::new(&a.mesh));
    let per = (1.0 - share) / sizes.len() as f64;
    let mut levels = Vec::new();
    for (k, ((lod, stats), &n_p)) in lods.into_iter().zip(sizes).enumerate() {
        let lod_faces = lod.triangle_count();
        if lod_faces >= faces {
            levels.push(SceneLevel {
                screen_size: n_p,
                faces,
                kept: Some(Kept::NotSmaller { lod_faces }),
                lod: None,
                stats: Some(stats),
                baked: None,
                deformation: None,
            });
            continue;
        }
        let deformation = if let Some((attributes, targets)) = &deform {
            match transfer_deformation(geometry, attributes, *targets, &lod, n_p) {
                Ok(d) => Some(d),
                Err(e) => {
                    levels.push(SceneLevel {
                        screen_size: n_p,
                        faces,
                        kept: Some(Kept::Deformable(e.to_string())),
                        lod: None,
                        stats: Some(stats),
                        baked: None,
                        deformation: None,
                    });
                    continue;
                }
            }
        } else {
            None
        };
        let baked = match (app, &index, &params.bake) {
            (Some(app), Some(index), Some(bp)) => {
                let base = share + per * k as f64;
                let mut lp = |p: Progress<'_>| {
                    prog(Progress {
                        stage: p.stage,
                        fraction: base + per * p.fraction,
                    })
                };
                Some(bake_level_with_progress(
                    app, index, &lod, n_p, bp, &mut lp,
                )?)
            }
            _ => None,
        };
        // A baked level splits vertices at seams: each copy takes its LOD vertex's attributes.
        let deformation = match (deformation, &baked) {
            (Some(d), Some(b)) => Some(d.remap(&split_map(&lod, &b.positions)?)),
            (d, _) => d,
        };
        levels.push(SceneLevel {
            screen_size: n_p,
            faces: lod_faces,
            kept: None,
            lod: Some(lod),
            stats: Some(stats),
            baked,
            deformation,
        });
    }
    Ok(levels)
}

/// For each of `positions` (a baked level's vertices, copies of the LOD's split at seams),
/// the LOD vertex at the same position. `InvalidArgument` when one has none.
fn split_map(lod: &TriMesh, positions: &[[f64; 3]]) -> Result<Vec<usize>> {
    let key = |p: &[f64; 3]| p.map(f64::to_bits);
    let mut at = std::collections::HashMap::new();
    for (i, p) in lod.positions().iter().enumerate() {
        at.entry(key(p)).or_insert(i);
    }
    positions
        .iter()
        .map(|p| {
            at.get(&key(p)).copied().ok_or_else(|| {
                Error::InvalidArgument("a baked vertex is not a vertex of its LOD".into())
            })
        })
        .collect()
}

/// Options of [`scene_glb`].
#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// The instancing nodes show the finest level instead of the input mesh.
    pub drop_original: bool,
    /// Write only the levels of these screen sizes (`None`: every level).
    pub only_sizes: Option<Vec<f64>>,
}

/// The document with the chains' levels added, as one GLB (see the [module docs](self)).
/// Deterministic: the bytes depend only on the input and the chains.
///
/// Errors: `Parse` for a buffer view outside its buffer or an image that cannot be read;
/// `InvalidArgument` for a coordinate beyond `f32` or a file over GLB's 4 GiB.
pub fn scene_glb(scene: &GltfScene, chains: &[MeshChain], opts: &WriteOptions) -> Result<Vec<u8>> {
    let mut doc = scene.json.clone();
    let root = doc
        .as_object_mut()
        .ok_or_else(|| parse_error(&scene.name, "the glTF JSON is not an object"))?;
    let take = |root: &mut serde_json::Map<String, Value>, key: &str| -> Vec<Value> {
        match root.remove(key) {
            Some(Value::Array(a)) => a,
            _ => Vec::new(),
        }
    };
    // Buffer views repacked into one buffer.
    let mut bin = Bin {
        data: Vec::new(),
        views: take(root, "bufferViews"),
        accessors: take(root, "accessors"),
    };
    for (i, v) in bin.views.iter_mut().enumerate() {
        let get = |k: &str| v.get(k).and_then(Value::as_u64).map(|x| x as usize);
        let (buf, off, len) = (
            get("buffer").unwrap_or(0),
            get("byteOffset").unwrap_or(0),
            get("byteLength").unwrap_or(0),
        );
        let bytes = scene
            .loaded
            .buffers
            .get(buf)
            .and_then(|b| b.get(off..off.checked_add(len)?))
            .ok_or_else(|| {
                parse_error(
                    &scene.name,
                    format!("buffer view {i} lies outside buffer {buf}"),
                )
            })?;
        bin.data.resize(bin.data.len().next_multiple_of(4), 0);
        v["buffer"] = json!(0);
        v["byteOffset"] = json!(bin.data.len());
        bin.data.extend_from_slice(bytes);
    }
    // Images by URI embedded.
    let mut images = take(root, "images");
    for (i, img) in images.iter_mut().enumerate() {
        let Some(uri) = img.get("uri").and_then(Value::as_str).map(str::to_string) else {
            continue;
        };
        let bytes = if uri.starts_with("data:") {
            io::data_uri_bytes(&uri)
                .ok_or_else(|| parse_error(&scene.name, format!("image {i}: malformed data URI")))?
        } else {
            io::external_bytes(&uri, 1 << 30, scene.base.as_deref(), &scene.name)?
        };
        let view = bin.view(&bytes, None);
        let obj = img
            .as_object_mut()
            .expect("an image with a uri is an object");
        obj.remove("uri");
        obj.insert("bufferView".into(), json!(view));
        if !obj.contains_key("mimeType") {
            obj.insert("mimeType".into(), json!(mime_type(&bytes)));
        }
    }
    let mut arrays = Arrays {
        meshes: take(root, "meshes"),
        materials: take(root, "materials"),
        images,
        textures: take(root, "textures"),
    };
    let mut samplers = take(root, "samplers");
    let mut nodes = take(root, "nodes");
    let wanted = |s: f64| opts.only_sizes.as_ref().is_none_or(|o| o.contains(&s));
    // Baked images, encoded in the order the levels are written.
    let baked: Vec<&BakedLevel> = chains
        .iter()
        .flat_map(|c| &c.levels)
        .filter(|l| wanted(l.screen_size))
        .filter_map(|l| l.baked.as_ref())
        .collect();
    let encoded = encode_images(&baked)?;
    let sampler = samplers.len();
    if !encoded.is_empty() {
        samplers.push(json!({"magFilter": 9729, "minFilter": 9987,
                             "wrapS": 33071, "wrapT": 33071}));
    }
    let mut encoded = encoded.into_iter();
    let mut untextured: BTreeMap<Option<usize>, Option<usize>> = BTreeMap::new();
    let mut any_lod = false;
    let n_nodes = nodes.len();
    for chain in chains {
        // (screen size, mesh of the level) of the written levels, finest first.
        let mut levels: Vec<(f64, usize)> = Vec::new();
        for l in &chain.levels {
            if !wanted(l.screen_size) {
                continue;
            }
            // Level k (1 = finest written) of the mesh; its level nodes carry the same k.
            let name = format!("{}_LOD{}", chain.name, levels.len() + 1);
            let mesh = match (&l.lod, &l.baked) {
                (_, Some(b)) => push_level(b, &name, &mut encoded, sampler, &mut bin, &mut arrays)?,
                (Some(lod), None) => {
                    let src = scene.first_material(chain.mesh);
                    let material = *untextured
                        .entry(src)
                        .or_insert_with(|| untextured_material(src, &mut arrays.materials));
                    push_plain(lod, &name, material, &mut bin, &mut arrays)?
                }
                (None, None) => chain.mesh,
            };
            if let (Some(d), true) = (&l.deformation, mesh != chain.mesh) {
                let src = arrays
                    .meshes
                    .get(chain.mesh)
                    .cloned()
                    .unwrap_or(Value::Null);
                push_deformation(d, &src, &mut arrays.meshes[mesh], &mut bin);
            }
            levels.push((l.screen_size, mesh));
        }
        if levels.iter().all(|&(_, m)| m == chain.mesh) {
            continue;
        }
        for i in 0..n_nodes {
            if nodes[i].get("mesh").and_then(Value::as_u64) != Some(chain.mesh as u64) {
                continue;
            }
            let node_name = nodes[i]
                .get("name")
                .and_then(Value::as_str)
                .map_or_else(|| format!("node {i}"), str::to_string);
            let rest = if opts.drop_original {
                nodes[i]["mesh"] = json!(levels[0].1);
                &levels[1..]
            } else {
                &levels[..]
            };
            if rest.is_empty() {
                continue;
            }
            let first = if opts.drop_original { 2 } else { 1 };
            let mut ids = Vec::new();
            for (k, &(n_p, mesh)) in rest.iter().enumerate() {
                let mut lod = json!({"name": format!("{node_name}_LOD{}", k + first),
                                     "mesh": mesh, "extras": {"pleat_screen_size": n_p}});
                for key in [
                    "matrix",
                    "translation",
                    "rotation",
                    "scale",
                    "skin",
                    "weights",
                ] {
                    if let Some(v) = nodes[i].get(key) {
                        lod[key] = v.clone();
                    }
                }
                ids.push(nodes.len());
                nodes.push(lod);
            }
            let mut coverage: Vec<f64> = rest.iter().map(|&(s, _)| screen_coverage(s)).collect();
            coverage.push(0.0);
            let node = nodes[i].as_object_mut().expect("a node is an object");
            let ext = node.entry("extensions").or_insert_with(|| json!({}));
            if let Some(e) = ext.as_object_mut() {
                e.insert("MSFT_lod".into(), json!({ "ids": ids }));
            }
            let extras = node.entry("extras").or_insert_with(|| json!({}));
            if let Some(e) = extras.as_object_mut() {
                e.insert("MSFT_screencoverage".into(), json!(coverage));
            }
            any_lod = true;
        }
    }
    let Arrays {
        meshes,
        materials,
        images,
        textures,
    } = arrays;
    for (key, v) in [
        ("nodes", nodes),
        ("meshes", meshes),
        ("materials", materials),
        ("images", images),
        ("textures", textures),
        ("samplers", samplers),
        ("accessors", std::mem::take(&mut bin.accessors)),
        ("bufferViews", std::mem::take(&mut bin.views)),
    ] {
        if !v.is_empty() {
            root.insert(key.into(), Value::Array(v));
        }
    }
    bin.align();
    let old = take(root, "buffers");
    if !bin.data.is_empty() {
        let mut buffer = json!({"byteLength": bin.data.len()});
        for key in ["name", "extras"] {
            if let Some(v) = old.first().and_then(|b| b.get(key)) {
                buffer[key] = v.clone();
            }
        }
        root.insert("buffers".into(), json!([buffer]));
    }
    if any_lod {
        let used = root
            .entry("extensionsUsed")
            .or_insert_with(|| json!([]))
            .as_array_mut();
        if let Some(used) = used {
            if !used.iter().any(|e| e == "MSFT_lod") {
                used.push(json!("MSFT_lod"));
            }
        }
    }
    if let Some(asset) = root.get_mut("asset").and_then(Value::as_object_mut) {
        let generator = match asset.get("generator").and_then(Value::as_str) {
            Some(g) if !g.starts_with("pleat") => format!("pleat (LODs); input by {g}"),
            Some(g) => g.to_string(),
            None => "pleat (LODs)".to_string(),
        };
        asset.insert("generator".into(), json!(generator));
    }
    glb_container(&doc, &bin.data)
}

/// The IANA type of embedded image bytes by their signature (PNG, JPEG, WebP, KTX2), PNG when
/// unknown.
fn mime_type(bytes: &[u8]) -> &'static str {
    if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        "image/jpeg"
    } else if bytes.len() >= 12 && &bytes[0..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
        "image/webp"
    } else if bytes.starts_with(&[0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30]) {
        "image/ktx2"
    } else {
        "image/png"
    }
}

/// Whether a JSON value references a texture (a key ending in `Texture` anywhere inside).
fn samples_texture(v: &Value) -> bool {
    match v {
        Value::Object(o) => o
            .iter()
            .any(|(k, x)| k.ends_with("Texture") || samples_texture(x)),
        Value::Array(a) => a.iter().any(samples_texture),
        _ => false,
    }
}

/// `v` without any texture reference (keys ending in `Texture` removed at every depth).
fn strip_textures(v: &mut Value) {
    match v {
        Value::Object(o) => {
            o.retain(|k, _| !k.ends_with("Texture"));
            o.values_mut().for_each(strip_textures);
        }
        Value::Array(a) => a.iter_mut().for_each(strip_textures),
        _ => {}
    }
}

/// The material an unbaked level uses for source material `src`: `src` itself when it samples
/// no texture, else a new untextured copy appended to `materials` (`None`: the default).
fn untextured_material(src: Option<usize>, materials: &mut Vec<Value>) -> Option<usize> {
    let i = src?;
    let m = materials.get(i)?;
    if !samples_texture(m) {
        return Some(i);
    }
    let mut copy = m.clone();
    strip_textures(&mut copy);
    let name = m
        .get("name")
        .and_then(Value::as_str)
        .map_or_else(|| format!("material {i}"), str::to_string);
    copy["name"] = json!(format!("{name} (untextured)"));
    materials.push(copy);
    Some(materials.len() - 1)
}

/// Adds a level's skin and morph targets to its mesh `level` (one primitive): `JOINTS_<s>`
/// (`UNSIGNED_SHORT`) and `WEIGHTS_<s>` (`FLOAT`) per 4 influences, the `targets` (`POSITION`
/// with bounds), and the source mesh `src`'s default `weights` and `extras.targetNames`.
fn push_deformation(d: &Deformation, src: &Value, level: &mut Value, bin: &mut Bin) {
    let prim = &mut level["primitives"][0];
    for set in 0..d.influences / 4 {
        let rows = d.joints.len() / d.influences;
        let (mut joints, mut weights) = (Vec::new(), Vec::with_capacity(rows));
        for v in 0..rows {
            let r = v * d.influences + 4 * set..v * d.influences + 4 * set + 4;
            joints.extend(d.joints[r.clone()].iter().flat_map(|j| j.to_le_bytes()));
            weights.push([
                d.weights[r.start],
                d.weights[r.start + 1],
                d.weights[r.start + 2],
                d.weights[r.start + 3],
            ]);
        }
        let view = bin.view(&joints, Some(34962));
        bin.accessors
            .push(json!({"bufferView": view, "componentType": 5123,
                                  "count": rows, "type": "VEC4"}));
        prim["attributes"][format!("JOINTS_{set}")] = json!(bin.accessors.len() - 1);
        prim["attributes"][format!("WEIGHTS_{set}")] = json!(bin.floats(&weights, "VEC4", false));
    }
    if !d.targets.is_empty() {
        // A target may only displace attributes the primitive has (glTF 2.0 §3.7.2.2): an
        // unbaked level has no NORMAL or TANGENT (engines compute its normals), so their
        // displacements are left out there.
        let base: Vec<String> = prim["attributes"]
            .as_object()
            .map(|a| a.keys().cloned().collect())
            .unwrap_or_default();
        let targets: Vec<Value> = d
            .targets
            .iter()
            .map(|t| {
                let mut o = serde_json::Map::new();
                for (sem, v) in t.iter().filter(|(sem, _)| base.contains(sem)) {
                    o.insert(sem.clone(), json!(bin.floats(v, "VEC3", sem == "POSITION")));
                }
                Value::Object(o)
            })
            .collect();
        prim["targets"] = json!(targets);
        if let Some(w) = src.get("weights") {
            level["weights"] = w.clone();
        }
        if let Some(names) = src.get("extras").and_then(|e| e.get("targetNames")) {
            level["extras"]["targetNames"] = names.clone();
        }
    }
}

/// Appends an unbaked level: `POSITION` (f32, min/max) and `u32` indices, `material`.
fn push_plain(
    lod: &TriMesh,
    name: &str,
    material: Option<usize>,
    bin: &mut Bin,
    arrays: &mut Arrays,
) -> Result<usize> {
    let positions: Vec<[f32; 3]> = lod
        .positions()
        .iter()
        .map(|p| p.map(|c| c as f32))
        .collect();
    if positions.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Error::InvalidArgument(format!(
            "a vertex of {name} exceeds the f32 range of glTF positions"
        )));
    }
    let pos = bin.floats(&positions, "VEC3", true);
    let indices = bin.indices(lod.triangles());
    let mut prim = json!({"attributes": {"POSITION": pos}, "indices": indices, "mode": 4});
    if let Some(m) = material {
        prim["material"] = json!(m);
    }
    arrays
        .meshes
        .push(json!({"name": name, "primitives": [prim]}));
    Ok(arrays.meshes.len() - 1)
}
