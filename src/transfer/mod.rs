//! Attribute transfer (feature `lod`): the input's per-vertex attributes (UVs, colours, skin
//! weights, morph deltas, vertex groups, ids) on the vertices of a LOD or cage made from it.
//!
//! A [`Correspondence`] is computed once per (input, LOD) pair and applied to any number of
//! arrays. Each LOD vertex maps to one input point, an input triangle and barycentric
//! coordinates on it, by [`provenance`](mod@provenance): the segment of half-length
//! `e = envelope_factor · d` cast along the LOD's area-weighted vertex normal, nearest hit
//! first, the closest input point when the segment hits nothing (Möller & Trumbore 1997 for
//! the ray–triangle test; the same correspondence textured bakes use, `crate::bake`). Then:
//!
//! - [`TransferMode::Barycentric`]: `Σ_j b_j · a(corner_j)` per component (reals: UVs,
//!   colours, morph deltas) — the linear interpolation of the input's piecewise-linear
//!   attribute at the corresponding point;
//! - [`TransferMode::Nearest`] and [`Correspondence::transfer_u32`]: the value of the corner
//!   with the largest barycentric coordinate (ties: the first corner in the triangle's order)
//!   — integers, ids, flags, values that must not be mixed;
//! - [`Correspondence::transfer_skin`]: linear-blend-skinning influences (joint, weight) of
//!   each corner, each corner's weights first normalised to sum 1, blended per joint with the
//!   barycentric coordinates, the `k` largest kept (ties: lower joint index first),
//!   renormalised so the `f32` weights sum to 1 within `1e-6`; unused slots are joint 0 with
//!   weight 0 (the glTF convention).
//!
//! # Guarantees
//!
//! - Deterministic: the same input, LOD, parameters and arrays give the same output bytes
//!   whatever the rayon thread count (each LOD vertex is computed independently; ties are
//!   broken by index, never by scheduling).
//! - Barycentric outputs are convex combinations of the corner values of one input triangle,
//!   so each component lies within the input's range; nearest outputs are input values.
//! - Skin outputs: joints are joints of the input, at most `max_influences` non-zero weights
//!   per vertex, sorted by weight descending, summing to 1 within `1e-6`.
//! - Wrong input: [`Correspondence::new`] refuses (`Error::InvalidArgument`) a LOD and input
//!   that are not within `max_distance_factor · d` of each other: every LOD vertex within it
//!   of the input surface, and each side of the input's bounding box within it of the
//!   LOD's (input vertices buried inside the input's union are rightly far from a LOD, so
//!   the converse is checked on the boxes), with `d = l_lod / n_p`
//!   (`l_lod` the LOD's bounding-box diagonal, `n_p` = [`TransferParams::screen_size`], the
//!   screen size the LOD was made at). A pleat LOD or cage lies within about `d` of its input
//!   (offset distance plus the simplification bound), both ways; a different mesh, the input
//!   moved or scaled, or a part of it, is farther. The check cannot tell apart two inputs
//!   whose surfaces are within that distance of each other (which would give the same
//!   attributes anyway up to that distance).
//!
//! # The skin-weight rule, by measurement
//!
//! Where the offset surface bridges parts that move apart (an arm resting on the torso, legs
//! touching), the LOD has vertices whose nearest input point may lie on either part. The
//! rule was chosen on a generated character (`tests/common/character.rs`: 14 joints, arms in
//! an A-pose touching the torso at the armpits, thighs touching, 4 influences per vertex,
//! 5440 triangles) posed at 9 poses plus the bind pose by a linear-blend-skinning evaluator
//! written in the test. Two-sided sampled Hausdorff distance between the posed LOD and the
//! posed input, over `l`; LODs by `crate::lowpoly::generate` (n_p = 50: 70 faces; n_p = 100:
//! 134 faces):
//!
//! | rule | n_p 50: bind | worst posed | mean posed | n_p 100: bind | worst posed | mean posed |
//! |---|---|---|---|---|---|---|
//! | cast along the normal, barycentric blend, top-4 (default) | 0.0544 | 0.0656 | 0.0558 | 0.0421 | 0.0654 | 0.0488 |
//! | closest point, barycentric blend | 0.0544 | 0.0656 | 0.0558 | 0.0421 | 0.0654 | 0.0488 |
//! | cast, the nearest corner's influences | 0.0544 | 0.0657 | 0.0558 | 0.0421 | 0.0654 | 0.0487 |
//! | cast, barycentric, 1 one-ring smoothing | 0.0544 | 0.0845 | 0.0625 | 0.0421 | 0.0765 | 0.0485 |
//! | cast, barycentric, 3 one-ring smoothings | 0.0544 | 0.1202 | 0.0715 | 0.0421 | 0.0987 | 0.0557 |
//!
//! (Worst poses: the right arm forward 30° at n_p = 50, the left elbow bent 60° at n_p = 100,
//! where the coarse LOD's straight arm cannot follow the bend whatever the weights.) Smoothing
//! over the LOD's one-ring spreads a limb's joints onto the torso and legs and is clearly
//! worse; the cast, the closest point and the nearest corner agree within 1e-4 of `l`. The
//! default is the cast with the barycentric blend: equal best, the correspondence textured
//! bakes use, and the blend is continuous across input triangles where the nearest corner
//! jumps. The bound the test keeps: posed ≤ 1.5 × bind + 0.005 at every pose (and the morph
//! target at weight 1, deltas transferred barycentrically: 0.0547 and 0.0421).
//!
//! May import: `crate::geom`, `crate::mesh`, `crate::spatial`, `crate::report`,
//! `crate::error`.

pub mod provenance;

use rayon::prelude::*;

use crate::geom::Vec3;
use crate::mesh::TriMesh;
use crate::{Error, Result};
use provenance::{InputIndex, Provenance, ProvenanceParams};

/// How a LOD vertex finds its input point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Lookup {
    /// Cast along the LOD vertex normal within the envelope, nearest hit; the closest point
    /// when nothing is hit ([`provenance::InputIndex::query`]).
    #[default]
    Cast,
    /// The closest input point ([`provenance::InputIndex::closest`]).
    ClosestPoint,
}

/// Parameters of [`Correspondence::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransferParams {
    /// The screen size `n_p` (pixels, finite, > 0) the LOD was made at: `d = l / n_p`.
    pub screen_size: f64,
    /// Half-length of the cast segment in units of `d` (finite, > 0); default 3 (as
    /// [`ProvenanceParams::for_screen_size`]).
    pub envelope_factor: f64,
    /// The wrong-input bound in units of `d = l_lod / n_p` (finite, > 0); default 4.
    pub max_distance_factor: f64,
    /// How LOD vertices find their input point; default [`Lookup::Cast`].
    pub lookup: Lookup,
}

impl Default for TransferParams {
    /// `n_p = 200` (the LOD default), envelope `3 d`, wrong-input bound `4 d`, cast lookup.
    fn default() -> Self {
        TransferParams {
            screen_size: 200.0,
            envelope_factor: 3.0,
            max_distance_factor: 4.0,
            lookup: Lookup::Cast,
        }
    }
}

impl TransferParams {
    /// The defaults with screen size `n_p`.
    pub fn for_screen_size(screen_size: f64) -> Self {
        TransferParams {
            screen_size,
            ..Default::default()
        }
    }

    fn validate(&self) -> Result<()> {
        let pos = |v: f64, name: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidArgument(format!(
                    "{name} is {v}; must be finite and > 0"
                )))
            }
        };
        pos(self.screen_size, "screen_size")?;
        pos(self.envelope_factor, "envelope_factor")?;
        pos(self.max_distance_factor, "max_distance_factor")
    }
}

/// How real attributes are carried (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TransferMode {
    /// Interpolated with the barycentric coordinates of the corresponding input point.
    #[default]
    Barycentric,
    /// The value of the corner with the largest barycentric coordinate.
    Nearest,
}

/// How the corners' influences are combined in [`Correspondence::transfer_skin`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SkinBlend {
    /// Per joint, weighted by the barycentric coordinates (then top-k).
    #[default]
    Barycentric,
    /// The influences of the corner with the largest barycentric coordinate.
    NearestVertex,
}

/// Parameters of [`Correspondence::transfer_skin`]; the default is the rule chosen by the
/// measurement in the [module docs](self).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkinParams {
    /// Influences kept per LOD vertex `k`: 1 to 4, or up to 8 when the input has at least
    /// that many per vertex. Default 4.
    pub max_influences: usize,
    /// Corner combination; default [`SkinBlend::Barycentric`].
    pub blend: SkinBlend,
    /// Jacobi smoothing iterations of the blended weights over the LOD's one-ring (each
    /// vertex: the mean of itself and its neighbours), before the top-k; default 0.
    pub smoothing_iterations: u32,
}

impl Default for SkinParams {
    fn default() -> Self {
        SkinParams {
            max_influences: 4,
            blend: SkinBlend::Barycentric,
            smoothing_iterations: 0,
        }
    }
}

/// Skin influences on the LOD's vertices: `influences` slots per vertex, slot `s` of vertex
/// `i` at `i * influences + s`, sorted by weight descending; unused slots are (0, 0.0).
#[derive(Debug, Clone, PartialEq)]
pub struct SkinWeights {
    /// Slots per vertex (the `max_influences` asked for).
    pub influences: usize,
    /// Joint indices, as in the input.
    pub joints: Vec<u32>,
    /// Weights, non-negative, each vertex's summing to 1 within `1e-6`.
    pub weights: Vec<f32>,
}

/// The LOD→input correspondence: per LOD vertex, an input triangle's corners and barycentric
/// coordinates. Plain data: apply it to any number of attribute arrays of the input.
#[derive(Debug, Clone, PartialEq)]
pub struct Correspondence {
    input_vertices: usize,
    corners: Vec<[u32; 3]>,
    bary: Vec<[f64; 3]>,
    /// LOD one-ring (CSR: `ring[ring_start[i]..ring_start[i+1]]`, sorted).
    ring_start: Vec<usize>,
    ring: Vec<u32>,
    max_distance: f64,
    cast_fraction: f64,
}

impl Correspondence {
    /// The correspondence of every vertex of `lod` on `input` (see the [module docs](self)).
    ///
    /// Errors: `InvalidArgument` for bad parameters, for an input or LOD without triangles,
    /// and when `lod` is not within `max_distance_factor · d` of `input` (some LOD vertex
    /// farther from the input, or a side of the bounding boxes farther apart: not a LOD of
    /// that input, or not at that screen size); the message names the farthest vertex or
    /// the side.
    pub fn new(input: &TriMesh, lod: &TriMesh, params: &TransferParams) -> Result<Self> {
        params.validate()?;
        if input.triangle_count() == 0 || lod.triangle_count() == 0 {
            return Err(Error::InvalidArgument(
                "the input and the LOD must both have triangles".into(),
            ));
        }
        let d_in = input.bbox_diagonal() / params.screen_size;
        let d_lod = lod.bbox_diagonal() / params.screen_size;
        let bound = params.max_distance_factor * d_lod;
        let prov = ProvenanceParams {
            envelope: params.envelope_factor * d_in,
        };
        if !(prov.envelope > 0.0 && prov.envelope.is_finite() && bound > 0.0) {
            return Err(Error::InvalidArgument(
                "the input or LOD has a zero or non-finite bounding box".into(),
            ));
        }
        let index = InputIndex::new(input);
        let normals = provenance::vertex_normals(lod);
        let found: Vec<(Provenance, f64)> = lod
            .positions()
            .par_iter()
            .zip(normals.par_iter())
            .map(|(&p, &n)| {
                let q = match params.lookup {
                    Lookup::Cast => index.query(Vec3::from(p), Vec3::from(n), &prov),
                    Lookup::ClosestPoint => index.closest(Vec3::from(p)),
                };
                let q = q.unwrap_or(Provenance {
                    triangle: 0,
                    bary: [1.0, 0.0, 0.0],
                    point: p,
                    distance: f64::INFINITY,
                    by_ray: false,
                });
                // The cast distance bounds the surface distance from above.
                let dist = if q.distance <= bound {
                    q.distance
                } else {
                    index
                        .closest(Vec3::from(p))
                        .map_or(f64::INFINITY, |c| c.distance)
                };
                (q, dist)
            })
            .collect();
        let far = far_vertex(found.iter().map(|f| f.1));
        if let Some((i, dist)) = far.filter(|&(_, dist)| dist > bound) {
            return Err(wrong_input("LOD vertex", i, dist, bound, params));
        }
        // The other side: the input's bounding box within the bound of the LOD's (a LOD or
        // cage grows the input's box by about d per side). Not every input vertex: parts
        // buried inside the input's union are rightly absent from the LOD.
        let (ilo, ihi) = input.bbox();
        let (llo, lhi) = lod.bbox();
        for a in 0..3 {
            for (side, gap) in [
                ("min", (llo[a] - ilo[a]).abs()),
                ("max", (lhi[a] - ihi[a]).abs()),
            ] {
                if gap.is_nan() || gap > bound {
                    return Err(Error::InvalidArgument(format!(
                        "the bounding boxes differ by {gap:.6} at the {side} of axis {a}, more \
                         than {} d = {bound:.6} (d = l_lod / n_p, n_p = {}): the input is not \
                         the mesh this LOD was made from, or screen_size is not the LOD's",
                        params.max_distance_factor, params.screen_size
                    )));
                }
            }
        }
        let tris = input.triangles();
        let corners = found.iter().map(|f| tris[f.0.triangle as usize]).collect();
        let bary = found.iter().map(|f| f.0.bary).collect();
        let cast = found.iter().filter(|f| f.0.by_ray).count();
        let (ring_start, ring) = one_ring(lod);
        Ok(Correspondence {
            input_vertices: input.vertex_count(),
            corners,
            bary,
            ring_start,
            ring,
            max_distance: found.iter().map(|f| f.1).fold(0.0, f64::max),
            cast_fraction: cast as f64 / found.len().max(1) as f64,
        })
    }

    /// Number of LOD vertices (the rows of every output).
    pub fn lod_vertex_count(&self) -> usize {
        self.corners.len()
    }

    /// Number of input vertices (the rows every input array must have).
    pub fn input_vertex_count(&self) -> usize {
        self.input_vertices
    }

    /// The input triangle's corners (input vertex indices) of LOD vertex `i`.
    pub fn corners(&self, i: usize) -> [u32; 3] {
        self.corners[i]
    }

    /// The barycentric coordinates (non-negative, summing to 1) of LOD vertex `i` on its
    /// input triangle.
    pub fn barycentric(&self, i: usize) -> [f64; 3] {
        self.bary[i]
    }

    /// The largest distance from a LOD vertex to the input surface, in the mesh's units.
    pub fn max_distance(&self) -> f64 {
        self.max_distance
    }

    /// Fraction of LOD vertices found by the cast (the rest by the closest point).
    pub fn cast_fraction(&self) -> f64 {
        self.cast_fraction
    }

    /// The corner slot (0..3) with the largest barycentric coordinate of LOD vertex `i`.
    fn nearest_slot(&self, i: usize) -> usize {
        let b = self.bary[i];
        (1..3).fold(0, |s, j| if b[j] > b[s] { j } else { s })
    }

    fn check_rows(&self, len: usize, k: usize, name: &str) -> Result<()> {
        if k == 0 {
            return Err(Error::InvalidArgument(format!(
                "{name}: k is 0; give at least one component"
            )));
        }
        if k > 1 << 16 {
            return Err(Error::InvalidArgument(format!(
                "{name}: k is {k}; at most 65536 components"
            )));
        }
        match self.input_vertices.checked_mul(k) {
            Some(n) if n == len => Ok(()),
            _ => Err(Error::InvalidArgument(format!(
                "{name} has {len} values; the input has {} vertices × k = {k}",
                self.input_vertices
            ))),
        }
    }

    /// `values` (`n_input × k`, row per input vertex) on the LOD's vertices (`n_lod × k`),
    /// by `mode`. Computed in `f64`, rounded once to `f32`.
    ///
    /// Errors: `InvalidArgument` when `k` is 0 or the length is not `n_input × k`, or a value
    /// is NaN or infinite (naming the first).
    pub fn transfer_f32(&self, values: &[f32], k: usize, mode: TransferMode) -> Result<Vec<f32>> {
        self.check_rows(values.len(), k, "values")?;
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "values[{i}] is {} (NaN or infinite)",
                values[i]
            )));
        }
        let rows: Vec<Vec<f32>> = (0..self.corners.len())
            .into_par_iter()
            .map(|i| {
                let c = self.corners[i];
                match mode {
                    TransferMode::Nearest => {
                        let v = c[self.nearest_slot(i)] as usize;
                        values[v * k..(v + 1) * k].to_vec()
                    }
                    TransferMode::Barycentric => {
                        let b = self.bary[i];
                        (0..k)
                            .map(|j| {
                                let s: f64 = (0..3)
                                    .map(|t| b[t] * values[c[t] as usize * k + j] as f64)
                                    .sum();
                                s as f32
                            })
                            .collect()
                    }
                }
            })
            .collect();
        Ok(rows.concat())
    }

    /// Integer attributes (`n_input × k`; ids, flags, material indices) on the LOD's vertices:
    /// the row of the nearest corner ([`TransferMode::Nearest`]).
    ///
    /// Errors: `InvalidArgument` when `k` is 0 or the length is not `n_input × k`.
    pub fn transfer_u32(&self, values: &[u32], k: usize) -> Result<Vec<u32>> {
        self.check_rows(values.len(), k, "values")?;
        let mut out = Vec::with_capacity(self.corners.len() * k);
        for i in 0..self.corners.len() {
            let v = self.corners[i][self.nearest_slot(i)] as usize;
            out.extend_from_slice(&values[v * k..(v + 1) * k]);
        }
        Ok(out)
    }

    /// Skin influences on the LOD's vertices. `joints` and `weights` are `n_input × m`
    /// (`m` influences per input vertex; a weight of 0 marks an unused slot).
    ///
    /// Errors: `InvalidArgument` when `m` is 0, the lengths are not `n_input × m`, a weight is
    /// negative, NaN or infinite, an input vertex has no positive weight, or
    /// `max_influences` is not in 1..=4 (or 5..=8 with `m ≥ max_influences`).
    pub fn transfer_skin(
        &self,
        joints: &[u32],
        weights: &[f32],
        m: usize,
        params: &SkinParams,
    ) -> Result<SkinWeights> {
        self.check_rows(joints.len(), m, "joints")?;
        self.check_rows(weights.len(), m, "weights")?;
        let k = params.max_influences;
        let allowed = (1..=4).contains(&k) || ((5..=8).contains(&k) && k <= m);
        if !allowed {
            return Err(Error::InvalidArgument(format!(
                "max_influences is {k}; allowed 1 to 4, or up to 8 when the input has as many \
                 influences per vertex (it has {m})"
            )));
        }
        if let Some(i) = weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(Error::InvalidArgument(format!(
                "weights[{i}] is {}; must be finite and >= 0",
                weights[i]
            )));
        }
        // Each input vertex's influences, merged per joint and normalised.
        let input: Vec<Vec<(u32, f64)>> = (0..self.input_vertices)
            .into_par_iter()
            .map(|v| {
                let mut inf: Vec<(u32, f64)> = Vec::with_capacity(m);
                for s in 0..m {
                    let w = weights[v * m + s] as f64;
                    if w > 0.0 {
                        add(&mut inf, joints[v * m + s], w);
                    }
                }
                inf
            })
            .collect();
        let used = self.used_input_vertices();
        if let Some(v) = (0..self.input_vertices).find(|&v| used[v] && input[v].is_empty()) {
            return Err(Error::InvalidArgument(format!(
                "input vertex {v} has no positive skin weight"
            )));
        }
        let input: Vec<Vec<(u32, f64)>> = input.into_iter().map(normalised).collect();
        let mut blended: Vec<Vec<(u32, f64)>> = (0..self.corners.len())
            .into_par_iter()
            .map(|i| {
                let c = self.corners[i];
                match params.blend {
                    SkinBlend::NearestVertex => input[c[self.nearest_slot(i)] as usize].clone(),
                    SkinBlend::Barycentric => {
                        let b = self.bary[i];
                        let mut inf = Vec::new();
                        for (&bt, &ct) in b.iter().zip(&c) {
                            if bt > 0.0 {
                                for &(j, w) in &input[ct as usize] {
                                    add(&mut inf, j, bt * w);
                                }
                            }
                        }
                        inf
                    }
                }
            })
            .collect();
        for _ in 0..params.smoothing_iterations {
            blended = (0..blended.len())
                .into_par_iter()
                .map(|i| {
                    let ring = &self.ring[self.ring_start[i]..self.ring_start[i + 1]];
                    let mut inf = blended[i].clone();
                    for &n in ring {
                        for &(j, w) in &blended[n as usize] {
                            add(&mut inf, j, w);
                        }
                    }
                    normalised(inf)
                })
                .collect();
        }
        let rows: Vec<(Vec<u32>, Vec<f32>)> =
            blended.into_par_iter().map(|inf| top_k(inf, k)).collect();
        let mut out = SkinWeights {
            influences: k,
            joints: Vec::with_capacity(rows.len() * k),
            weights: Vec::with_capacity(rows.len() * k),
        };
        for (j, w) in rows {
            out.joints.extend(j);
            out.weights.extend(w);
        }
        Ok(out)
    }

    fn used_input_vertices(&self) -> Vec<bool> {
        let mut used = vec![false; self.input_vertices];
        for c in &self.corners {
            for &v in c {
                used[v as usize] = true;
            }
        }
        used
    }
}

/// Adds `w` to joint `j` in `inf` (kept sorted by joint).
fn add(inf: &mut Vec<(u32, f64)>, j: u32, w: f64) {
    match inf.binary_search_by_key(&j, |e| e.0) {
        Ok(p) => inf[p].1 += w,
        Err(p) => inf.insert(p, (j, w)),
    }
}

fn normalised(mut inf: Vec<(u32, f64)>) -> Vec<(u32, f64)> {
    let s: f64 = inf.iter().map(|e| e.1).sum();
    if s > 0.0 {
        for e in &mut inf {
            e.1 /= s;
        }
    }
    inf
}

/// The `k` largest influences (weight descending, then joint ascending), renormalised so the
/// `f32` weights sum to 1 within `1e-6`; padded with (0, 0.0).
fn top_k(mut inf: Vec<(u32, f64)>, k: usize) -> (Vec<u32>, Vec<f32>) {
    inf.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    inf.truncate(k);
    inf.retain(|e| e.1 > 0.0);
    let s: f64 = inf.iter().map(|e| e.1).sum();
    let mut joints = vec![0u32; k];
    let mut weights = vec![0f32; k];
    for (slot, &(j, w)) in inf.iter().enumerate() {
        joints[slot] = j;
        weights[slot] = (w / s) as f32;
    }
    if !inf.is_empty() {
        // Put the f32 rounding residual on the largest weight.
        let sum: f64 = weights.iter().map(|&w| w as f64).sum();
        weights[0] = (weights[0] as f64 + (1.0 - sum)) as f32;
    }
    (joints, weights)
}

/// The vertex with the largest distance (first on ties; NaN counts as largest).
fn far_vertex(d: impl Iterator<Item = f64>) -> Option<(usize, f64)> {
    let mut best: Option<(usize, f64)> = None;
    for (i, v) in d.enumerate() {
        let v = if v.is_nan() { f64::INFINITY } else { v };
        if best.is_none_or(|(_, b)| v > b) {
            best = Some((i, v));
        }
    }
    best
}

fn wrong_input(what: &str, i: usize, dist: f64, bound: f64, p: &TransferParams) -> Error {
    Error::InvalidArgument(format!(
        "{what} {i} is {dist:.6} from the other mesh, more than {} d = {bound:.6} \
         (d = l_lod / n_p, n_p = {}): the input is not the mesh this LOD was made from, \
         or screen_size is not the LOD's",
        p.max_distance_factor, p.screen_size
    ))
}

/// Sorted one-ring neighbours of every vertex of `m`, as CSR.
fn one_ring(m: &TriMesh) -> (Vec<usize>, Vec<u32>) {
    let mut nb: Vec<Vec<u32>> = vec![Vec::new(); m.vertex_count()];
    for t in m.triangles() {
        for &a in t {
            for &b in t {
                if a != b {
                    nb[a as usize].push(b);
                }
            }
        }
    }
    let mut start = Vec::with_capacity(nb.len() + 1);
    let mut ring = Vec::new();
    start.push(0);
    for mut n in nb {
        n.sort_unstable();
        n.dedup();
        ring.extend(n);
        start.push(ring.len());
    }
    (start, ring)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(z: f64, s: f64) -> TriMesh {
        TriMesh::new(
            vec![[0.0, 0.0, z], [s, 0.0, z], [s, s, z], [0.0, s, z]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap()
    }

    #[test]
    fn barycentric_nearest_and_u32_on_a_shifted_copy() {
        let input = plane(0.0, 1.0);
        let lod = plane(0.005, 1.0);
        let c = Correspondence::new(&input, &lod, &TransferParams::for_screen_size(100.0)).unwrap();
        let uv: Vec<f32> = input
            .positions()
            .iter()
            .flat_map(|p| [p[0] as f32, p[1] as f32])
            .collect();
        let out = c.transfer_f32(&uv, 2, TransferMode::Barycentric).unwrap();
        assert_eq!(out, uv);
        let ids = c.transfer_u32(&[7, 8, 9, 10], 1).unwrap();
        assert_eq!(ids, vec![7, 8, 9, 10]);
        assert!(c.transfer_f32(&uv, 0, TransferMode::Nearest).is_err());
        assert!(c.transfer_f32(&uv[1..], 2, TransferMode::Nearest).is_err());
        let mut nan = uv.clone();
        nan[3] = f32::NAN;
        assert!(c.transfer_f32(&nan, 2, TransferMode::Nearest).is_err());
    }

    #[test]
    fn a_far_mesh_is_refused() {
        let input = plane(0.0, 1.0);
        let lod = plane(0.5, 1.0);
        let e = Correspondence::new(&input, &lod, &TransferParams::for_screen_size(100.0));
        assert!(e.unwrap_err().to_string().contains("not the mesh"));
    }

    #[test]
    fn top_k_sorts_breaks_ties_by_joint_and_sums_to_one() {
        let (j, w) = top_k(vec![(5, 0.2), (1, 0.2), (3, 0.5), (9, 0.1)], 3);
        assert_eq!(j, vec![3, 1, 5]);
        let s: f64 = w.iter().map(|&x| x as f64).sum();
        assert!((s - 1.0).abs() <= 1e-6);
        let (j, w) = top_k(vec![(2, 1.0)], 4);
        assert_eq!((j, w), (vec![2, 0, 0, 0], vec![1.0, 0.0, 0.0, 0.0]));
    }
}
