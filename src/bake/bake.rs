//! Baking the input's material onto a LOD: per texel of the LOD's atlas, the LOD surface point
//! → its provenance on the input → the input's material there.
//!
//! 1. **Rasterise** the atlas: each texel whose centre lies in an atlas triangle gets that
//!    triangle and the centre's barycentric coordinates; texels within half a texel diagonal of
//!    a triangle but outside every one get the nearest point of the nearest such triangle, so
//!    bilinear filtering at chart borders reads surface values, not gutter.
//! 2. **Sample** (rayon over rows, each texel independent, so the bytes do not depend on the
//!    thread count): point and interpolated normal on the LOD, provenance
//!    ([`InputIndex::query`]), material evaluation ([`Appearance::sample`]). Base colour is
//!    interpolated in linear space by the input sampler and stored sRGB-encoded with linear
//!    alpha; emissive likewise; metallic-roughness as glTF's (–, roughness, metallic);
//!    occlusion in R (G = B = R).
//! 3. **Normal map**: the input's shading normal (its own normal map included), flipped to the
//!    LOD normal's side (the LOD wraps soups and thin parts from both sides), expressed in the
//!    LOD's MikkTSpace frame exactly as engines reconstruct it: `n' = normalize(x·T + y·B +
//!    z·N)` with `T`, `N` interpolated per pixel and `B = w · N × T`; the stored `(x, y, z)`
//!    solves that 3×3 system, normalised. Tangents come from the `mikktspace` crate on the
//!    atlas UVs with v flipped, so `B` points to image up (glTF's convention).
//! 4. **Dilate** every image into the gutters and empty space: each empty texel copies the
//!    texel a breadth-first search from all covered texels reaches it from (4-neighbours, fixed
//!    order), so mip levels average a chart only with copies of its own border.
//!
//! Without any texture in the input, the LOD gets vertex colours instead (the L² fit of the
//! base colour, factor × COLOR_0, over the LOD surface) and no atlas — except that a
//! `COLOR_0`-only input follows [`BakeParams::vertex_colors`]: under [`VertexColors::Auto`] it
//! gets a base-colour texture when the vertex fit's error exceeds what the screen size allows.

use std::time::Instant;

use rayon::prelude::*;

use super::appearance::{linear_to_srgb, Appearance, MaterialSample};
use super::atlas::{
    build_atlas_growing, deepest_mip, footprint_owners, triangle_charts, uv_area, Atlas,
    AtlasParams, Gutter, BLOCK_SHARED,
};
use super::level::{BakeReport, BakedLevel, BakedMaterial, Image8};
use crate::geom::{normalized, Vec3};
use crate::mesh::TriMesh;
use crate::report::{Progress, ProgressFn};
use crate::transfer::provenance::{vertex_normals, InputIndex, ProvenanceParams};
use crate::{Error, Result};

/// Texels baked between two progress reports (and cancellation checks): about 10 ms of work
/// on one core, so a cancel takes effect well within 0.1 s.
const TEXELS_PER_CHECK: usize = 4096;

/// Maps a bake's stage progress into a window `[base, base + span]` of the caller's progress
/// and turns a `false` answer into `Error::Cancelled`.
pub(crate) struct Steps<'p, 'f> {
    f: &'p mut ProgressFn<'f>,
    base: f64,
    span: f64,
}

impl<'p, 'f> Steps<'p, 'f> {
    /// Reports into `[base, base + span]` of `f`'s range.
    pub(crate) fn new(f: &'p mut ProgressFn<'f>, base: f64, span: f64) -> Self {
        Steps { f, base, span }
    }

    /// Reports `stage` at `fraction` (in `[0, 1]`) of the window; `Err(Cancelled)` when the
    /// callback answers `false`.
    pub(crate) fn check(&mut self, stage: &str, fraction: f64) -> Result<()> {
        let fraction = (self.base + self.span * fraction.clamp(0.0, 1.0)).clamp(0.0, 1.0);
        if (self.f)(Progress { stage, fraction }) {
            Ok(())
        } else {
            Err(Error::Cancelled)
        }
    }
}

/// Parameters of [`bake_level`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BakeParams {
    /// Atlas size rule and gutter.
    pub atlas: AtlasParams,
    /// Provenance envelope in units of the LOD's offset distance `d = l / n_p` (finite, > 0).
    /// Default 3.
    pub envelope_d: f64,
    /// Bake a tangent-space normal map. Default true.
    pub normal_map: bool,
    /// At most this many texels are compared with the input for the appearance error
    /// (0 skips the measurement). Default 20 000.
    pub error_samples: usize,
    /// After the bake (outside `total_seconds`), render the input and the level from 24 views
    /// with [`super::render::evaluate`] and fill the report's `appearance_psnr_db`,
    /// `appearance_psnr_reference_db` and `normal_map_gain_db`. Default false.
    pub evaluate: bool,
    /// How an input whose only colour source is `COLOR_0` (no texture) is baked. Default
    /// [`VertexColors::Auto`].
    pub vertex_colors: VertexColors,
}

/// How a `COLOR_0`-only input (vertex colours, no texture in any material) is transferred.
/// The output never carries both: glTF multiplies `COLOR_0` into the base colour, so a level
/// is either vertex-coloured (no base-colour texture) or textured (no `COLOR_0`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VertexColors {
    /// Vertex colours when they are good enough for the screen size, else a texture. The rule:
    /// a pixel at `n_p` covers `h = l / n_p` of the surface and shows its colour averaged over
    /// that footprint, so an error of the colour change across half a pixel, `|∇c| · h/2`
    /// (`c` the input's sRGB base colour in 1/255, its gradient over the input triangle at the
    /// closest input point, max over R, G, B), plus one 8-bit step, is not visible at that
    /// size. The vertex fit ([`bake_level`]'s L² fit) is kept when its mean error over the
    /// surface samples is at most the mean allowed error over the same samples; otherwise the
    /// level gets a texture at the atlas rule's density. Both numbers are reported
    /// (`BakeReport::vertex_fit_error`, `vertex_fit_allowed_error`).
    #[default]
    Auto,
    /// Always vertex colours (the L² fit), as before this option existed.
    Vertex,
    /// Always a base-colour texture (the textured path samples `factor × COLOR_0`).
    Texture,
}

/// Surface samples the [`VertexColors::Auto`] decision compares at most.
const AUTO_SAMPLES: usize = 20_000;

impl Default for BakeParams {
    fn default() -> Self {
        BakeParams {
            atlas: AtlasParams::default(),
            envelope_d: 3.0,
            normal_map: true,
            error_samples: 20_000,
            evaluate: false,
            vertex_colors: VertexColors::Auto,
        }
    }
}

/// Bakes `app`'s appearance onto `lod`, a LOD of `app.mesh` made for screen size `screen_size`.
/// `index` must index `app.mesh`. See the [module docs](self).
///
/// Errors: `InvalidArgument` for bad parameters; `Internal` when the atlas fails.
pub fn bake_level(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    screen_size: f64,
    params: &BakeParams,
) -> Result<BakedLevel> {
    bake_level_with_progress(app, index, lod, screen_size, params, &mut |_| true)
}

/// [`bake_level`] with progress and cancellation: `progress` is called on this thread with
/// the stages `bake: provenance` (untextured inputs), `bake: atlas`, `bake: tangents` (the
/// normal map's MikkTSpace frame), `bake: rasterise`, `bake: texels` (every
/// `TEXELS_PER_CHECK` texels, so a cancel is honoured within about 10 ms of work),
/// `bake: dilation` and `bake: measure`; fractions rise from 0 to 1. Returning `false` stops
/// the bake with `Error::Cancelled`. The output is the same bytes as [`bake_level`]'s, whatever
/// the thread count.
pub fn bake_level_with_progress(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    screen_size: f64,
    params: &BakeParams,
    progress: &mut ProgressFn<'_>,
) -> Result<BakedLevel> {
    if !(params.envelope_d.is_finite() && params.envelope_d > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "bake envelope must be finite and > 0 (in units of d), got {}",
            params.envelope_d
        )));
    }
    if !(screen_size.is_finite() && screen_size > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "screen size must be finite and > 0, got {screen_size}"
        )));
    }
    let start = Instant::now();
    let diag = app.mesh.bbox_diagonal();
    let prov = ProvenanceParams {
        envelope: params.envelope_d * diag / screen_size,
    };
    let mut steps = Steps::new(progress, 0.0, 1.0);
    let textured = |steps: &mut Steps<'_, '_>| {
        bake_textured(app, index, lod, screen_size, diag, &prov, params, steps)
    };
    let color0_only = !app.has_textures() && app.colors.is_some();
    let mut level = match params.vertex_colors {
        _ if app.has_textures() => textured(&mut steps)?,
        VertexColors::Texture if color0_only => textured(&mut steps)?,
        VertexColors::Auto if color0_only => {
            let vertex =
                bake_vertex_colors(app, index, lod, screen_size, &prov, params, &mut steps)?;
            let (fit, allowed) = (
                vertex.report.vertex_fit_error,
                vertex.report.vertex_fit_allowed_error,
            );
            let mut level = if fit.zip(allowed).is_some_and(|(f, a)| f > a) {
                let mut t = textured(&mut steps)?;
                t.report.sample_seconds += vertex.report.sample_seconds;
                t
            } else {
                vertex
            };
            level.report.vertex_fit_error = fit;
            level.report.vertex_fit_allowed_error = allowed;
            level
        }
        _ => bake_vertex_colors(app, index, lod, screen_size, &prov, params, &mut steps)?,
    };
    level.report.total_seconds = start.elapsed().as_secs_f64();
    if params.evaluate {
        evaluate_into(app, &mut level);
    }
    Ok(level)
}

/// Fills the report's evaluation fields ([`BakeParams::evaluate`]).
fn evaluate_into(app: &Appearance, level: &mut BakedLevel) {
    let t = Instant::now();
    let e = super::render::evaluate(app, level, &super::render::EvalParams::default());
    let finite = |x: f64| x.is_finite().then_some(x);
    level.report.appearance_psnr_db = finite(e.appearance_psnr_db);
    level.report.appearance_psnr_reference_db = finite(e.reference_psnr_db);
    level.report.appearance_psnr_pooled_db = finite(e.appearance_pooled_psnr_db);
    level.report.appearance_psnr_reference_pooled_db = finite(e.reference_pooled_psnr_db);
    level.report.normal_map_gain_db = e.normal_map_gain_db.and_then(finite);
    level.report.evaluate_seconds = t.elapsed().as_secs_f64();
}

/// The material fields that are not baked: from the input's first material.
fn base_material(app: &Appearance) -> BakedMaterial {
    let m = app.materials.first().cloned().unwrap_or_default();
    BakedMaterial {
        base_color_factor: [1.0; 4],
        base_color: None,
        metallic_factor: m.metallic_factor,
        roughness_factor: m.roughness_factor,
        metallic_roughness: None,
        occlusion: None,
        emissive_factor: [0.0; 3],
        emissive: None,
        normal: None,
        alpha_mode: m.alpha_mode,
        alpha_cutoff: m.alpha_cutoff,
        double_sided: app.materials.iter().any(|m| m.double_sided),
    }
}

fn bake_vertex_colors(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    screen_size: f64,
    prov: &ProvenanceParams,
    params: &BakeParams,
    steps: &mut Steps<'_, '_>,
) -> Result<BakedLevel> {
    steps.check("bake: provenance", 0.0)?;
    let t0 = Instant::now();
    let normals = vertex_normals(lod);
    let fit = fit_vertex_colors(app, index, lod, &normals, prov);
    let colors: Vec<[f32; 4]> = fit.colors.iter().map(|c| c.map(|x| x as f32)).collect();
    let mut report = BakeReport {
        sample_seconds: t0.elapsed().as_secs_f64(),
        fallback_fraction: fit.fallback_fraction,
        ..BakeReport::default()
    };
    if params.vertex_colors == VertexColors::Auto && app.colors.is_some() {
        let h = app.mesh.bbox_diagonal() / screen_size;
        let (e, a) = auto_verdict(app, index, lod, &fit.samples, &colors, h);
        report.vertex_fit_error = Some(e);
        report.vertex_fit_allowed_error = Some(a);
    }
    if params.error_samples > 0 {
        steps.check("bake: measure", 0.9)?;
        let t = Instant::now();
        // Errors over the surface (the fit's quadrature points), where the fit is optimal, not
        // at the vertices only.
        let stride = fit.samples.len().div_ceil(params.error_samples).max(1);
        let errs: Vec<f64> = fit
            .samples
            .iter()
            .step_by(stride)
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&&(t, b)| {
                let tri = lod.triangles()[t];
                let at = |k: usize| Vec3::from(lod.positions()[tri[k] as usize]);
                let p = at(0) * b[0] + at(1) * b[1] + at(2) * b[2];
                let baked: [f64; 4] = std::array::from_fn(|j| {
                    (0..3)
                        .map(|k| b[k] * f64::from(colors[tri[k] as usize][j]))
                        .sum()
                });
                color_error(app, index, p, baked)
            })
            .collect();
        set_errors(&mut report, errs);
        report.measure_seconds = t.elapsed().as_secs_f64();
    }
    let mut material = base_material(app);
    let m = app.materials.first().cloned().unwrap_or_default();
    material.emissive_factor = m.emissive_factor;
    steps.check("bake: measure", 1.0)?;
    Ok(BakedLevel {
        screen_size,
        positions: lod.positions().to_vec(),
        normals: normals.iter().map(|n| n.map(|c| c as f32)).collect(),
        tangents: None,
        uvs: None,
        colors: Some(colors),
        triangles: lod.triangles().to_vec(),
        material,
        report,
    })
}

/// The [`VertexColors::Auto`] comparison over up to [`AUTO_SAMPLES`] of the fit's surface
/// samples: (mean fit error, mean allowed error), both in 1/255 sRGB; `h` is one pixel's
/// footprint `l / n_p` on the surface.
fn auto_verdict(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    samples: &[(usize, [f64; 3])],
    colors: &[[f32; 4]],
    h: f64,
) -> (f64, f64) {
    let stride = samples.len().div_ceil(AUTO_SAMPLES).max(1);
    let pairs: Vec<(f64, f64)> = samples
        .iter()
        .step_by(stride)
        .collect::<Vec<_>>()
        .par_iter()
        .map(|&&(t, b)| {
            let tri = lod.triangles()[t];
            let at = |k: usize| Vec3::from(lod.positions()[tri[k] as usize]);
            let p = at(0) * b[0] + at(1) * b[1] + at(2) * b[2];
            let baked: [f64; 4] = std::array::from_fn(|j| {
                (0..3)
                    .map(|k| b[k] * f64::from(colors[tri[k] as usize][j]))
                    .sum()
            });
            let allowed = index.closest(p).map_or(1.0, |q| {
                1.0 + 0.5 * h * srgb_gradient(app, q.triangle as usize)
            });
            (color_error(app, index, p, baked), allowed)
        })
        .collect();
    let n = pairs.len().max(1) as f64;
    (
        pairs.iter().map(|p| p.0).sum::<f64>() / n,
        pairs.iter().map(|p| p.1).sum::<f64>() / n,
    )
}

/// `|∇c|` over input triangle `t`, max over R, G, B, in 1/255 sRGB per unit length: `c` the
/// sRGB-encoded base colour at the triangle's corners, interpolated linearly. For a linear
/// function with corner values `f_k` over corners `p_k`, `∇f = a e₁ + b e₂` with `e₁ = p₁ − p₀`,
/// `e₂ = p₂ − p₀` and `(a, b)` solving the Gram system `[e₁·e₁ e₁·e₂; e₁·e₂ e₂·e₂] (a, b) =
/// (f₁ − f₀, f₂ − f₀)`. 0 on a degenerate triangle.
fn srgb_gradient(app: &Appearance, t: usize) -> f64 {
    let tri = app.mesh.triangles()[t];
    let p = tri.map(|v| Vec3::from(app.mesh.positions()[v as usize]));
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = g11 * g22 - g12 * g12;
    if det.is_nan() || det <= 1e-300 {
        return 0.0;
    }
    let corner = |k: usize| {
        let mut b = [0.0; 3];
        b[k] = 1.0;
        app.sample(t, b)
            .base_color
            .map(|x| 255.0 * linear_to_srgb(x))
    };
    let c = [corner(0), corner(1), corner(2)];
    (0..3)
        .map(|ch| {
            let (d1, d2) = (c[1][ch] - c[0][ch], c[2][ch] - c[0][ch]);
            let a = (g22 * d1 - g12 * d2) / det;
            let b = (g11 * d2 - g12 * d1) / det;
            (e1 * a + e2 * b).length()
        })
        .fold(0.0, f64::max)
}

/// Vertex colours fitted to the input's base colour, with the share of quadrature samples whose
/// provenance came from the closest-point fallback.
struct VertexColorFit {
    /// Linear RGBA per LOD vertex, each channel clamped to `[0, 1]`.
    colors: Vec<[f64; 4]>,
    /// Fraction of samples not found by the cast along the normal.
    fallback_fraction: f64,
    /// The quadrature points: LOD triangle and barycentric coordinates.
    samples: Vec<(usize, [f64; 3])>,
}

/// Least-squares vertex colours (issue 11, "vertex colours transfer as vertex colours"): the
/// per-vertex linear RGBA `c` minimising `∫_LOD |Σ_k c_k φ_k(x) − c_in(x)|² dA`, with `φ_k` the
/// LOD's piecewise-linear hat functions and `c_in` the input's base colour at the provenance of
/// `x` (cast along the interpolated LOD normal, closest-point fallback). Its normal equations
/// are the P1 mass system `M c = b`, `M_ij = ∫ φ_i φ_j`, `b_i = ∫ φ_i c_in` (the L² projection
/// onto the LOD's linear elements); `b` is integrated by [`triangle_samples`], `M` exactly.
///
/// Sampling provenance at the LOD vertices only gives a LOD triangle that spans many input
/// colours three point samples of it; the projection uses all of them, weighted by area.
/// Vertices on no triangle of positive area keep the point sample at the vertex. Deterministic:
/// samples are gathered in order and the solve is sequential.
fn fit_vertex_colors(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    normals: &[[f64; 3]],
    prov: &ProvenanceParams,
) -> VertexColorFit {
    let (pos, tris) = (lod.positions(), lod.triangles());
    let at = |v: u32| Vec3::from(pos[v as usize]);
    let areas: Vec<f64> = tris
        .iter()
        .map(|t| 0.5 * (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0])).length())
        .collect();
    let levels = quadrature_levels(&app.mesh, &areas);
    let samples: Vec<(usize, [f64; 3], f64)> = (0..tris.len())
        .flat_map(|t| {
            let a = areas[t];
            triangle_samples(levels[t])
                .into_iter()
                .map(move |(b, w)| (t, b, w * a))
        })
        .filter(|s| s.2 > 0.0)
        .collect();
    let found: Vec<Option<(bool, [f64; 4])>> = samples
        .par_iter()
        .map(|&(t, b, _)| {
            let tri = tris[t];
            let p: Vec3 = (0..3).map(|k| at(tri[k]) * b[k]).sum();
            let n: Vec3 = (0..3)
                .map(|k| Vec3::from(normals[tri[k] as usize]) * b[k])
                .sum();
            let face = (at(tri[1]) - at(tri[0])).cross(at(tri[2]) - at(tri[0]));
            let n = normalized(n)
                .or_else(|| normalized(face))
                .unwrap_or(Vec3::Z);
            index
                .query(p, n, prov)
                .map(|q| (q.by_ray, app.sample(q.triangle as usize, q.bary).base_color))
        })
        .collect();
    let mut rhs = vec![[0.0; 4]; lod.vertex_count()];
    for (&(t, b, w), f) in samples.iter().zip(&found) {
        if let Some((_, c)) = f {
            for k in 0..3 {
                let r = &mut rhs[tris[t][k] as usize];
                (0..4).for_each(|j| r[j] += w * b[k] * c[j]);
            }
        }
    }
    let mass = MassMatrix::new(tris, &areas, lod.vertex_count());
    let point = index.query_all(pos, normals, prov);
    let mut colors: Vec<[f64; 4]> = point
        .iter()
        .map(|p| app.sample(p.triangle as usize, p.bary).base_color)
        .collect();
    for ch in 0..4 {
        let b: Vec<f64> = rhs.iter().map(|r| r[ch]).collect();
        let x = mass.solve(&b);
        for (v, c) in colors.iter_mut().enumerate() {
            if mass.diagonal[v] > 0.0 {
                c[ch] = x[v].clamp(0.0, 1.0);
            }
        }
    }
    VertexColorFit {
        colors,
        fallback_fraction: fallback(found.iter().flatten().map(|f| f.0)),
        samples: samples.iter().map(|&(t, b, _)| (t, b)).collect(),
    }
}

/// Subdivision level `m` of each LOD triangle for [`triangle_samples`]: about three samples
/// per input-triangle edge length, `m = ⌈3 √(A_t / ā)⌉` clamped to `[3, 16]` (`ā` the input's
/// mean triangle area), so a LOD triangle over `r` input triangles gets about `9 r` samples.
fn quadrature_levels(input: &TriMesh, areas: &[f64]) -> Vec<usize> {
    let p = input.positions();
    let at = |v: u32| Vec3::from(p[v as usize]);
    let total: f64 = input
        .triangles()
        .iter()
        .map(|t| 0.5 * (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0])).length())
        .sum();
    let mean = total / input.triangle_count().max(1) as f64;
    areas
        .iter()
        .map(|&a| {
            let m = if mean > 0.0 {
                3.0 * (a / mean).sqrt()
            } else {
                3.0
            };
            (m.ceil() as usize).clamp(3, 16)
        })
        .collect()
}

/// Quadrature on the reference triangle: the `m²` congruent sub-triangles of the level-`m`
/// subdivision, each sampled at its centroid with weight `1/m²` (barycentric coordinates, weights
/// summing to 1). Exact for linear integrands; error `O(h²)` for smooth ones.
fn triangle_samples(m: usize) -> Vec<([f64; 3], f64)> {
    let (mf, w) = (m as f64, 1.0 / (m * m) as f64);
    let bary = |u: f64, v: f64| [1.0 - (u + v) / mf, u / mf, v / mf];
    let mut out = Vec::with_capacity(m * m);
    for i in 0..m {
        for j in 0..m - i {
            out.push((bary(i as f64 + 1.0 / 3.0, j as f64 + 1.0 / 3.0), w));
            if i + j + 1 < m {
                out.push((bary(i as f64 + 2.0 / 3.0, j as f64 + 2.0 / 3.0), w));
            }
        }
    }
    out
}

/// The P1 (piecewise-linear) mass matrix of a triangle mesh: per triangle of area `A` the element
/// matrix `A/12 · [[2,1,1],[1,2,1],[1,1,2]]`, kept as triangles and areas (matrix-free).
struct MassMatrix<'a> {
    triangles: &'a [[u32; 3]],
    areas: &'a [f64],
    /// `M_ii = Σ A/6` over the triangles at `i` (zero on vertices of no area).
    diagonal: Vec<f64>,
}

impl<'a> MassMatrix<'a> {
    fn new(triangles: &'a [[u32; 3]], areas: &'a [f64], n: usize) -> Self {
        let mut diagonal = vec![0.0; n];
        for (t, &a) in triangles.iter().zip(areas) {
            t.iter().for_each(|&v| diagonal[v as usize] += a / 6.0);
        }
        MassMatrix {
            triangles,
            areas,
            diagonal,
        }
    }

    /// `y = M x`.
    fn apply(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        for (t, &a) in self.triangles.iter().zip(self.areas) {
            let s: f64 = t.iter().map(|&v| x[v as usize]).sum();
            t.iter()
                .for_each(|&v| y[v as usize] += a / 12.0 * (s + x[v as usize]));
        }
        y
    }

    /// Solves `M x = b` on the vertices of positive mass (others get 0) by conjugate gradients
    /// preconditioned with the diagonal, from the lumped solution `b_i / Σ_t A_t/3`. Jacobi
    /// makes the system's condition number at most 4 whatever the mesh (the element matrix
    /// over its diagonal has eigenvalues ½, ½, 2), so a relative residual of 1e-10 takes a few
    /// dozen iterations; the cap of 200 is never reached on a finite input.
    fn solve(&self, b: &[f64]) -> Vec<f64> {
        let live = |i: usize| self.diagonal[i] > 0.0;
        let inv: Vec<f64> = (0..b.len())
            .map(|i| if live(i) { 1.0 / self.diagonal[i] } else { 0.0 })
            .collect();
        let dot = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
        let mut x: Vec<f64> = (0..b.len()).map(|i| 0.5 * b[i] * inv[i]).collect();
        let ax = self.apply(&x);
        let mut r: Vec<f64> = (0..b.len())
            .map(|i| if live(i) { b[i] - ax[i] } else { 0.0 })
            .collect();
        let mut z: Vec<f64> = r.iter().zip(&inv).map(|(a, c)| a * c).collect();
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let tol = 1e-20 * dot(b, b).max(f64::MIN_POSITIVE);
        for _ in 0..200 {
            if dot(&r, &r) <= tol {
                break;
            }
            let q = self.apply(&p);
            let pq = dot(&p, &q);
            if pq <= 0.0 {
                break;
            }
            let alpha = rz / pq;
            (0..x.len()).for_each(|i| {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
            });
            z = r.iter().zip(&inv).map(|(a, c)| a * c).collect();
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            (0..p.len()).for_each(|i| p[i] = z[i] + beta * p[i]);
        }
        x
    }
}

/// Which images the input needs.
struct Channels {
    metallic_roughness: bool,
    occlusion: bool,
    emissive: bool,
    normal: bool,
}

impl Channels {
    fn of(app: &Appearance, params: &BakeParams) -> Self {
        let first = app.materials.first();
        let differ = |f: &dyn Fn(&super::appearance::Material) -> f64| {
            first.is_some_and(|m0| app.materials.iter().any(|m| f(m) != f(m0)))
        };
        Channels {
            metallic_roughness: app.materials.iter().any(|m| m.metallic_roughness.is_some())
                || differ(&|m| m.metallic_factor)
                || differ(&|m| m.roughness_factor),
            occlusion: app.materials.iter().any(|m| m.occlusion.is_some()),
            emissive: app
                .materials
                .iter()
                .any(|m| m.emissive_factor.iter().any(|&c| c != 0.0)),
            normal: params.normal_map,
        }
    }
}

/// Per texel: the atlas triangle and barycentric coordinates (`u32::MAX` = empty).
struct Coverage {
    size: u32,
    tri: Vec<u32>,
    bary: Vec<[f32; 3]>,
}

#[allow(clippy::too_many_arguments)]
fn bake_textured(
    app: &Appearance,
    index: &InputIndex<'_>,
    lod: &TriMesh,
    screen_size: f64,
    diag: f64,
    prov: &ProvenanceParams,
    params: &BakeParams,
    steps: &mut Steps<'_, '_>,
) -> Result<BakedLevel> {
    let mut report = BakeReport::default();
    steps.check("bake: atlas", 0.0)?;
    let t = Instant::now();
    let side = params.atlas.side(lod, screen_size, diag);
    // The rule's side may grow so the gutters keep half the rule's density (a caller's size
    // is kept as given).
    let grow = params.atlas.size.is_none().then(|| {
        let rho = params.atlas.texels_per_pixel * screen_size / diag;
        (rho, params.atlas.max_size.max(side))
    });
    let atlas = build_atlas_growing(lod, side, Gutter::of(&params.atlas), grow)?;
    let side = atlas.size;
    report.atlas_seconds = t.elapsed().as_secs_f64();
    report.texture_size = side;
    report.charts = atlas.chart_count;
    report.overlapping_texels = atlas.overlapping_texels;
    report.atlas_padding = atlas.padding;

    let lod_normals = vertex_normals(lod);
    let positions: Vec<[f64; 3]> = atlas
        .xref
        .iter()
        .map(|&v| lod.positions()[v as usize])
        .collect();
    let normals = atlas_normals(&atlas, &positions, &lod_normals);

    steps.check("bake: tangents", 0.1)?;
    let t = Instant::now();
    let corner_tangents = mikk_tangents(&positions, &normals, &atlas);
    report.tangent_seconds = t.elapsed().as_secs_f64();

    steps.check("bake: rasterise", 0.15)?;
    let t = Instant::now();
    let cov = rasterize(&atlas);
    report.raster_seconds = t.elapsed().as_secs_f64();
    report.texels_covered = cov.tri.iter().filter(|&&t| t != u32::MAX).count() as u64;

    let ch = Channels::of(app, params);
    let t = Instant::now();
    let n = side as usize;
    let row_bytes = 4 * n;
    let mut base = vec![0u8; row_bytes * n];
    let mut mr = vec![
        0u8;
        if ch.metallic_roughness {
            row_bytes * n
        } else {
            0
        }
    ];
    let mut occ = vec![0u8; if ch.occlusion { row_bytes * n } else { 0 }];
    let mut emi = vec![0u8; if ch.emissive { row_bytes * n } else { 0 }];
    let mut nrm = vec![0u8; if ch.normal { row_bytes * n } else { 0 }];
    let ctx = TexelCtx {
        app,
        index,
        prov,
        atlas: &atlas,
        positions: &positions,
        normals: &normals,
        tangents: &corner_tangents,
        cov: &cov,
    };
    let mut rows: Vec<Rows<'_>> = rows_of(&mut base, row_bytes, n)
        .into_iter()
        .zip(rows_of(&mut mr, row_bytes, n))
        .zip(rows_of(&mut occ, row_bytes, n))
        .zip(rows_of(&mut emi, row_bytes, n))
        .zip(rows_of(&mut nrm, row_bytes, n))
        .map(|((((base, mr), occ), emi), nrm)| Rows {
            base,
            mr,
            occ,
            emi,
            nrm,
        })
        .collect();
    // Rows in chunks of about TEXELS_PER_CHECK texels, each chunk in parallel, a progress
    // report (and cancellation point) between chunks; each row is independent, so the bytes
    // do not depend on the chunking or the thread count.
    let chunk = (TEXELS_PER_CHECK / n.max(1)).max(1);
    let mut by_ray: Vec<(u64, u64)> = Vec::with_capacity(n);
    steps.check("bake: texels", 0.2)?;
    for (ci, part) in rows.chunks_mut(chunk).enumerate() {
        let first = ci * chunk;
        by_ray.par_extend(
            part.par_iter_mut()
                .enumerate()
                .map(|(k, r)| ctx.bake_row(first + k, r)),
        );
        let done = (first + part.len()) as f64 / n.max(1) as f64;
        steps.check("bake: texels", 0.2 + 0.7 * done)?;
    }
    drop(rows);
    let (hits, total) = by_ray.iter().fold((0, 0), |(h, t), &(a, b)| (h + a, t + b));
    report.fallback_fraction = if total == 0 {
        0.0
    } else {
        1.0 - hits as f64 / total as f64
    };
    report.sample_seconds = t.elapsed().as_secs_f64();

    if is_flat_normal_map(&nrm, &cov) {
        // The LOD's own normals already are the input's shading normals: the map would only
        // add its 8-bit rounding (see `is_flat_normal_map`).
        nrm = Vec::new();
    }
    steps.check("bake: dilation", 0.9)?;
    let t = Instant::now();
    let chart = triangle_charts(&atlas);
    let deepest = deepest_mip(params.atlas.texels_per_pixel);
    let uv = |v: u32| atlas.uv[v as usize].map(f64::from);
    let owners = footprint_owners(side, deepest, &atlas.triangles, &uv, &chart);
    report.seam_clean_mip = clean_mip(&atlas, &chart, deepest, &owners);
    let source = dilation_sources(&cov, &chart, &owners, deepest);
    for img in [&mut base, &mut mr, &mut occ, &mut emi, &mut nrm] {
        if !img.is_empty() {
            apply_dilation(img, &source);
        }
    }
    report.dilate_seconds = t.elapsed().as_secs_f64();

    let image = |rgba: Vec<u8>| {
        (!rgba.is_empty()).then_some(Image8 {
            width: side,
            height: side,
            rgba,
        })
    };
    let base_img = Image8 {
        width: side,
        height: side,
        rgba: base,
    };
    if params.error_samples > 0 {
        steps.check("bake: measure", 0.95)?;
        let t = Instant::now();
        let errs = texel_errors(&ctx, &base_img, params.error_samples);
        set_errors(&mut report, errs);
        report.measure_seconds = t.elapsed().as_secs_f64();
    }

    // Output vertices: atlas vertices split where MikkTSpace gives corners different tangents.
    let (out_vertices, out_triangles) = split_by_tangent(&atlas, &corner_tangents);
    let mut material = base_material(app);
    material.base_color = Some(base_img);
    if ch.metallic_roughness {
        material.metallic_factor = 1.0;
        material.roughness_factor = 1.0;
    }
    material.metallic_roughness = image(mr);
    material.occlusion = image(occ);
    if ch.emissive {
        material.emissive_factor = [1.0; 3];
    }
    material.emissive = image(emi);
    material.normal = image(nrm);
    let inv = 1.0 / f64::from(side);
    steps.check("bake: measure", 1.0)?;
    Ok(BakedLevel {
        screen_size,
        positions: out_vertices
            .iter()
            .map(|&(v, _)| positions[v as usize])
            .collect(),
        normals: out_vertices
            .iter()
            .map(|&(v, _)| normals[v as usize].map(|c| c as f32))
            .collect(),
        tangents: Some(out_vertices.iter().map(|&(_, t)| t).collect()),
        uvs: Some(
            out_vertices
                .iter()
                .map(|&(v, _)| atlas.uv[v as usize].map(|c| (f64::from(c) * inv) as f32))
                .collect(),
        ),
        colors: None,
        triangles: out_triangles,
        material,
        report,
    })
}

/// Covered texels a normal map may hold away from the neutral normal and still count as flat
/// ([`is_flat_normal_map`]): one in a thousand.
const FLAT_MAP_OUTLIERS: f64 = 1e-3;

/// True when a baked tangent-space normal map (`nrm`, RGBA8, empty when not baked) holds the
/// neutral normal `(0, 0, 1)` up to 8-bit rounding (x, y bytes 127 or 128, z byte ≥ 254) at
/// all but [`FLAT_MAP_OUTLIERS`] of its covered texels: the LOD's interpolated normals already
/// are the input's shading normals (a LOD lying on a flat input), so the map could only add
/// its rounding (byte 128 decodes to 0.0039, not 0) and is not written. Measured on the Khronos
/// texture-coordinate test's fitted LOD: of 584 000 covered texels all but about a hundred are
/// neutral (the rest tilt by up to 7°, at sliver triangles); shaded PSNR 100 dB (the cap: no
/// pixel differs from the input's render) without the map, 63.6 dB with it.
fn is_flat_normal_map(nrm: &[u8], cov: &Coverage) -> bool {
    if nrm.is_empty() {
        return false;
    }
    let (mut covered, mut tilted) = (0u64, 0u64);
    for (_, px) in cov
        .tri
        .iter()
        .zip(nrm.chunks_exact(4))
        .filter(|(&t, _)| t != u32::MAX)
    {
        covered += 1;
        let neutral = (127..=128).contains(&px[0]) && (127..=128).contains(&px[1]) && px[2] >= 254;
        tilted += u64::from(!neutral);
    }
    covered > 0 && tilted as f64 <= FLAT_MAP_OUTLIERS * covered as f64
}

/// Unit normal of every atlas vertex: the LOD's smooth vertex normal, except where it points
/// away from the vertex's own chart (`n_v · c_a ≤ 0`, `c_a` the area-weighted normal of the
/// atlas triangles at atlas vertex `a`, which all lie in one chart), where `c_a` is used.
///
/// That happens on folds: a LOD whose two sides touch (the input-plane fit projects both sides
/// of a sheet thinner than `2d` onto the sheet's plane, e.g. the Khronos texture-coordinate
/// test's quads) shares vertices between faces of opposite orientation, so the smooth normal
/// is that of whichever side has more area and the other side's interpolated normal turns
/// through zero, wrecking its tangent frame and normal map. A chart is flattened without
/// folding, so its faces around a vertex face one way and the chart normal is the side's own.
/// Elsewhere the smooth normal is kept. Measured on the shared assets' n_p = 200 LODs: 0–5
/// atlas vertices switch on the closed ones, 747 of 2806 on the open teapot, 57 of 119 on the
/// texture-coordinate test (whose shaded PSNR without a map rose from 17.8 to 100 dB).
fn atlas_normals(atlas: &Atlas, positions: &[[f64; 3]], lod_normals: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut chart = vec![Vec3::ZERO; atlas.xref.len()];
    for tri in &atlas.triangles {
        let [a, b, c] = tri.map(|v| Vec3::from(positions[v as usize]));
        let n = (b - a).cross(c - a);
        for &v in tri {
            chart[v as usize] += n;
        }
    }
    atlas
        .xref
        .iter()
        .zip(chart)
        .map(|(&v, c)| {
            let smooth = lod_normals[v as usize];
            match normalized(c) {
                Some(c) if Vec3::from(smooth).dot(c) <= 0.0 => c.to_array(),
                _ => smooth,
            }
        })
        .collect()
}

/// The rows of an optional image (empty image: `n` empty rows).
fn rows_of(img: &mut [u8], row_bytes: usize, n: usize) -> Vec<&mut [u8]> {
    if img.is_empty() {
        (0..n).map(|_| &mut [][..]).collect()
    } else {
        img.chunks_mut(row_bytes).collect()
    }
}

struct Rows<'a> {
    base: &'a mut [u8],
    mr: &'a mut [u8],
    occ: &'a mut [u8],
    emi: &'a mut [u8],
    nrm: &'a mut [u8],
}

struct TexelCtx<'a> {
    app: &'a Appearance,
    index: &'a InputIndex<'a>,
    prov: &'a ProvenanceParams,
    atlas: &'a Atlas,
    positions: &'a [[f64; 3]],
    normals: &'a [[f64; 3]],
    /// Per atlas triangle corner.
    tangents: &'a [[f32; 4]],
    cov: &'a Coverage,
}

/// `v` quantised to 8 bits.
fn q8(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

impl TexelCtx<'_> {
    /// LOD point, interpolated normal (unit), and the (unnormalised) interpolated frame.
    fn surface(&self, t: usize, b: [f32; 3]) -> (Vec3, Vec3, Vec3, Vec3, f64) {
        let tri = self.atlas.triangles[t];
        let b = b.map(f64::from);
        let mut p = Vec3::ZERO;
        let mut nn = Vec3::ZERO;
        let mut tt = Vec3::ZERO;
        let mut w = 0.0;
        for k in 0..3 {
            p += Vec3::from(self.positions[tri[k] as usize]) * b[k];
            nn += Vec3::from(self.normals[tri[k] as usize]) * b[k];
            let tg = self.tangents[3 * t + k];
            tt += Vec3::new(f64::from(tg[0]), f64::from(tg[1]), f64::from(tg[2])) * b[k];
            w += f64::from(tg[3]) * b[k];
        }
        let unit = normalized(nn).unwrap_or_else(|| {
            let [a, bb, c] = tri.map(|v| Vec3::from(self.positions[v as usize]));
            normalized((bb - a).cross(c - a)).unwrap_or(Vec3::Z)
        });
        (p, unit, nn, tt, if w < 0.0 { -1.0 } else { 1.0 })
    }

    /// Bakes row `j`; returns (texels found by ray, texels sampled).
    fn bake_row(&self, j: usize, rows: &mut Rows<'_>) -> (u64, u64) {
        let n = self.cov.size as usize;
        let (mut hits, mut total) = (0, 0);
        for i in 0..n {
            let k = j * n + i;
            let t = self.cov.tri[k];
            if t == u32::MAX {
                continue;
            }
            let (p, unit, nn, tt, w) = self.surface(t as usize, self.cov.bary[k]);
            let Some(found) = self.index.query(p, unit, self.prov) else {
                continue;
            };
            total += 1;
            hits += u64::from(found.by_ray);
            let s = self.app.sample(found.triangle as usize, found.bary);
            self.write(i, rows, &s, unit, nn, tt, w);
        }
        (hits, total)
    }

    #[allow(clippy::too_many_arguments)]
    fn write(
        &self,
        i: usize,
        rows: &mut Rows<'_>,
        s: &MaterialSample,
        unit: Vec3,
        nn: Vec3,
        tt: Vec3,
        w: f64,
    ) {
        let o = 4 * i;
        let c = s.base_color;
        rows.base[o..o + 4].copy_from_slice(&[
            q8(linear_to_srgb(c[0])),
            q8(linear_to_srgb(c[1])),
            q8(linear_to_srgb(c[2])),
            q8(c[3]),
        ]);
        if !rows.mr.is_empty() {
            rows.mr[o..o + 4].copy_from_slice(&[0, q8(s.roughness), q8(s.metallic), 255]);
        }
        if !rows.occ.is_empty() {
            let a = q8(s.occlusion);
            rows.occ[o..o + 4].copy_from_slice(&[a, a, a, 255]);
        }
        if !rows.emi.is_empty() {
            let e = s.emissive.map(|x| q8(linear_to_srgb(x)));
            rows.emi[o..o + 4].copy_from_slice(&[e[0], e[1], e[2], 255]);
        }
        if !rows.nrm.is_empty() {
            let mut target = Vec3::from(s.normal);
            if target.dot(unit) < 0.0 {
                target = -target;
            }
            let xyz = tangent_coords(tt, nn, w, target);
            rows.nrm[o..o + 4].copy_from_slice(&[
                q8(0.5 * xyz.x + 0.5),
                q8(0.5 * xyz.y + 0.5),
                q8(0.5 * xyz.z + 0.5),
                255,
            ]);
        }
    }
}

/// `(x, y, z)` with `normalize(x T + y B + z N) = target`, `B = w N × T`, normalised; `(0, 0,
/// 1)` when the frame is singular.
fn tangent_coords(t: Vec3, n: Vec3, w: f64, target: Vec3) -> Vec3 {
    let b = n.cross(t) * w;
    let m = glam::DMat3::from_cols(t, b, n);
    if m.determinant().abs() < 1e-12 * (t.length() * b.length() * n.length()).max(1e-300) {
        return Vec3::Z;
    }
    normalized(m.inverse() * target).unwrap_or(Vec3::Z)
}

/// Rasterises the atlas (see the [module docs](self), step 1).
fn rasterize(atlas: &Atlas) -> Coverage {
    let n = atlas.size as usize;
    let mut cov = Coverage {
        size: atlas.size,
        tri: vec![u32::MAX; n * n],
        bary: vec![[0.0; 3]; n * n],
    };
    // 0 empty, 1 border (outside, within reach), 2 inside.
    let mut state = vec![0u8; n * n];
    const REACH: f64 = 0.7072;
    for (t, tri) in atlas.triangles.iter().enumerate() {
        let uv = tri.map(|v| atlas.uv[v as usize].map(f64::from));
        // A triangle of zero UV area (a sliver chart xatlas collapsed to a point) covers no
        // texel and claims no border: the point may lie in another chart's gutter.
        if uv_area(&uv) == 0.0 {
            continue;
        }
        let lo = [0, 1].map(|a| {
            (uv[0][a].min(uv[1][a]).min(uv[2][a]) - 1.0)
                .floor()
                .max(0.0) as usize
        });
        let hi = [0, 1].map(|a| {
            ((uv[0][a].max(uv[1][a]).max(uv[2][a]) + 1.0).ceil().max(0.0) as usize).min(n)
        });
        for j in lo[1]..hi[1] {
            for i in lo[0]..hi[0] {
                let c = [i as f64 + 0.5, j as f64 + 0.5];
                let (b, dist) = closest_in_triangle(&uv, c);
                let k = j * n + i;
                let (new_state, take) = if dist == 0.0 {
                    (2, state[k] < 2)
                } else if dist <= REACH {
                    (1, state[k] == 0)
                } else {
                    (0, false)
                };
                if take {
                    state[k] = new_state;
                    cov.tri[k] = t as u32;
                    cov.bary[k] = b.map(|x| x as f32);
                }
            }
        }
    }
    cov
}

/// Barycentric coordinates of the point of 2D triangle `t` closest to `c`, and its distance
/// (0 inside, edges included).
fn closest_in_triangle(t: &[[f64; 2]; 3], c: [f64; 2]) -> ([f64; 3], f64) {
    let area =
        (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
    if area != 0.0 {
        let e = |a: [f64; 2], b: [f64; 2]| {
            (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
        };
        let b = [
            e(t[1], t[2]) / area,
            e(t[2], t[0]) / area,
            e(t[0], t[1]) / area,
        ];
        if b.iter().all(|&x| x >= 0.0) {
            return (b, 0.0);
        }
    }
    let mut best = ([1.0, 0.0, 0.0], f64::INFINITY);
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let s = if len2 > 0.0 {
            (((c[0] - a[0]) * d[0] + (c[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + s * d[0], a[1] + s * d[1]];
        let dist = ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2)).sqrt();
        if dist < best.1 {
            let mut bary = [0.0; 3];
            bary[k] = 1.0 - s;
            bary[(k + 1) % 3] = s;
            best = (bary, dist);
        }
    }
    best
}

/// For every texel, the covered texel whose value it takes (itself when covered; `u32::MAX`
/// when nothing is covered at all), with the blocks of mip `mip` owned by one chart each:
/// a breadth-first search from all covered texels (4-neighbours, fixed order) where a texel
/// of a block [`footprint_owners`] gives to chart `c` takes only `c`'s texels (free and shared
/// blocks take any); texels that search cannot reach (a chart's blocks cut off by shared
/// ones) then take the nearest assigned texel.
fn dilation_sources(cov: &Coverage, chart: &[u32], owners: &[u32], mip: u32) -> Vec<u32> {
    let n = cov.size as usize;
    let b = 1usize << mip.min(16);
    let nb = n.div_ceil(b).max(1);
    let mut src = vec![u32::MAX; n * n];
    let mut queue = std::collections::VecDeque::new();
    for (k, &t) in cov.tri.iter().enumerate() {
        if t != u32::MAX {
            src[k] = k as u32;
            queue.push_back(k);
        }
    }
    let allowed = |m: usize, s: u32| {
        let o = owners[(m / n / b) * nb + (m % n) / b];
        o >= BLOCK_SHARED || o == chart[cov.tri[s as usize] as usize]
    };
    spread(&mut src, &mut queue, n, &allowed);
    if src.contains(&u32::MAX) {
        queue.extend((0..n * n).filter(|&k| src[k] != u32::MAX));
        spread(&mut src, &mut queue, n, &|_, _| true);
    }
    src
}

/// Breadth-first spread of `src` from the texels in `queue` to unassigned 4-neighbours
/// (left, right, up, down) that `allowed(texel, source)` lets take the source.
fn spread(
    src: &mut [u32],
    queue: &mut std::collections::VecDeque<usize>,
    n: usize,
    allowed: &dyn Fn(usize, u32) -> bool,
) {
    while let Some(k) = queue.pop_front() {
        let (i, j) = (k % n, k / n);
        let s = src[k];
        let near = [
            (i > 0).then(|| k - 1),
            (i + 1 < n).then(|| k + 1),
            (j > 0).then(|| k - n),
            (j + 1 < n).then(|| k + n),
        ];
        for m in near.into_iter().flatten() {
            if src[m] == u32::MAX && allowed(m, s) {
                src[m] = s;
                queue.push_back(m);
            }
        }
    }
}

/// The deepest mip `m ≤ deepest` at which no block is reached by two charts' bilinear
/// footprints ([`footprint_owners`]; `owners` are those of mip `deepest`, reused when they
/// have no shared block); `None` when even mip 0 has shared texels (charts touching or
/// overlapping).
fn clean_mip(atlas: &Atlas, chart: &[u32], deepest: u32, owners: &[u32]) -> Option<u32> {
    if !owners.contains(&BLOCK_SHARED) {
        return Some(deepest);
    }
    let uv = |v: u32| atlas.uv[v as usize].map(f64::from);
    (0..deepest).rev().find(|&m| {
        !footprint_owners(atlas.size, m, &atlas.triangles, &uv, chart).contains(&BLOCK_SHARED)
    })
}

fn apply_dilation(img: &mut [u8], src: &[u32]) {
    for (k, &s) in src.iter().enumerate() {
        let s = s as usize;
        if s != k && s != u32::MAX as usize {
            let (a, b) = (4 * s, 4 * k);
            let px = [img[a], img[a + 1], img[a + 2], img[a + 3]];
            img[b..b + 4].copy_from_slice(&px);
        }
    }
}

/// MikkTSpace tangents per atlas triangle corner (`3 t + k`), on UVs with v flipped so the
/// bitangent points to image up.
fn mikk_tangents(positions: &[[f64; 3]], normals: &[[f64; 3]], atlas: &Atlas) -> Vec<[f32; 4]> {
    struct Geo<'a> {
        positions: &'a [[f64; 3]],
        normals: &'a [[f64; 3]],
        atlas: &'a Atlas,
        out: Vec<[f32; 4]>,
    }
    impl mikktspace::Geometry for Geo<'_> {
        fn num_faces(&self) -> usize {
            self.atlas.triangles.len()
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.positions[self.atlas.triangles[face][vert] as usize].map(|c| c as f32)
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.normals[self.atlas.triangles[face][vert] as usize].map(|c| c as f32)
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            let uv = self.atlas.uv[self.atlas.triangles[face][vert] as usize];
            let s = self.atlas.size as f32;
            [uv[0] / s, 1.0 - uv[1] / s]
        }
        fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
            self.out[3 * face + vert] = tangent;
        }
    }
    let mut geo = Geo {
        positions,
        normals,
        atlas,
        out: vec![[1.0, 0.0, 0.0, 1.0]; 3 * atlas.triangles.len()],
    };
    mikktspace::generate_tangents(&mut geo);
    geo.out
}

/// An output vertex: the atlas vertex it copies and its tangent.
type OutVertex = (u32, [f32; 4]);

/// Output vertices `(atlas vertex, tangent)` deduplicated in first-use order, and triangles
/// over them.
fn split_by_tangent(atlas: &Atlas, tangents: &[[f32; 4]]) -> (Vec<OutVertex>, Vec<[u32; 3]>) {
    let mut map = std::collections::HashMap::new();
    let mut verts = Vec::new();
    let mut tris = Vec::with_capacity(atlas.triangles.len());
    for (t, tri) in atlas.triangles.iter().enumerate() {
        let mut out = [0u32; 3];
        for k in 0..3 {
            let tg = tangents[3 * t + k];
            let key = (tri[k], tg.map(f32::to_bits));
            out[k] = *map.entry(key).or_insert_with(|| {
                verts.push((tri[k], tg));
                (verts.len() - 1) as u32
            });
        }
        tris.push(out);
    }
    (verts, tris)
}

fn fallback(by_ray: impl Iterator<Item = bool>) -> f64 {
    let (mut n, mut miss) = (0usize, 0usize);
    for b in by_ray {
        n += 1;
        miss += usize::from(!b);
    }
    if n == 0 {
        0.0
    } else {
        miss as f64 / n as f64
    }
}

/// |baked − input at the closest input point|, max over RGB, in sRGB 1/255 (`baked` linear).
fn color_error(app: &Appearance, index: &InputIndex<'_>, p: Vec3, baked: [f64; 4]) -> f64 {
    let Some(q) = index.closest(p) else {
        return 0.0;
    };
    let c = app.sample(q.triangle as usize, q.bary).base_color;
    (0..3)
        .map(|k| (255.0 * (linear_to_srgb(c[k]) - linear_to_srgb(baked[k]))).abs())
        .fold(0.0, f64::max)
}

/// Errors at up to `max` texel centres inside charts (every k-th).
fn texel_errors(ctx: &TexelCtx<'_>, base: &Image8, max: usize) -> Vec<f64> {
    let inside: Vec<usize> = (0..ctx.cov.tri.len())
        .filter(|&k| ctx.cov.tri[k] != u32::MAX)
        .collect();
    let stride = inside.len().div_ceil(max).max(1);
    let n = ctx.cov.size as usize;
    inside
        .iter()
        .step_by(stride)
        .copied()
        .collect::<Vec<_>>()
        .par_iter()
        .map(|&k| {
            let (p, ..) = ctx.surface(ctx.cov.tri[k] as usize, ctx.cov.bary[k]);
            let px = base.texel((k % n) as u32, (k / n) as u32);
            let baked =
                [0, 1, 2].map(|c| super::appearance::srgb_to_linear(f64::from(px[c]) / 255.0));
            color_error(ctx.app, ctx.index, p, [baked[0], baked[1], baked[2], 1.0])
        })
        .collect()
}

fn set_errors(report: &mut BakeReport, mut errs: Vec<f64>) {
    if errs.is_empty() {
        return;
    }
    errs.sort_by(f64::total_cmp);
    report.appearance_error_mean = errs.iter().sum::<f64>() / errs.len() as f64;
    report.appearance_error_p95 = errs[((errs.len() - 1) as f64 * 0.95) as usize];
    report.appearance_error_max = errs[errs.len() - 1];
}

#[cfg(test)]
mod vertex_color_tests {
    use super::*;
    use crate::bake::appearance::{AppearanceBuffers, BufferMaterial};
    use crate::mesh::test_shapes::grid;

    /// `grid(n, n)` scaled to the unit square, lifted to height `z`.
    fn square(n: u32, z: f64) -> TriMesh {
        let g = grid(n, n);
        let s = 1.0 / f64::from(n);
        let p = g
            .positions()
            .iter()
            .map(|p| [p[0] * s, p[1] * s, z])
            .collect();
        TriMesh::new(p, g.triangles().to_vec()).unwrap()
    }

    /// Input: a 60 × 60 square whose vertex colours are `f` at the vertices.
    fn input(f: &dyn Fn(f64, f64) -> [f64; 4]) -> Appearance {
        let mesh = square(60, 0.0);
        let colors: Vec<[f64; 4]> = mesh.positions().iter().map(|p| f(p[0], p[1])).collect();
        Appearance::from_buffers(&AppearanceBuffers {
            mesh: &mesh,
            uvs: None,
            normals: None,
            colors: Some(&colors),
            material: BufferMaterial::default(),
        })
        .unwrap()
    }

    /// A smooth colour field with values in [0.1, 0.9] (no clamping).
    fn smooth(x: f64, y: f64) -> [f64; 4] {
        use std::f64::consts::PI;
        [
            0.5 + 0.4 * (2.0 * PI * 1.3 * x).sin() * (2.0 * PI * 0.9 * y).cos(),
            0.5 + 0.4 * (2.0 * PI * (x + 1.7 * y)).cos(),
            0.5 + 0.4 * (5.0 * x * y).sin(),
            1.0,
        ]
    }

    /// RMS over the LOD (fine centroid quadrature) of the interpolated vertex colours against
    /// `f` at the point below (the nearest input point: the input is the plane z = 0).
    fn rms(lod: &TriMesh, colors: &[[f64; 4]], f: &dyn Fn(f64, f64) -> [f64; 4]) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for tri in lod.triangles() {
            for (b, _) in triangle_samples(20) {
                let p: Vec3 = (0..3)
                    .map(|k| Vec3::from(lod.positions()[tri[k] as usize]) * b[k])
                    .sum();
                let want = f(p.x, p.y);
                for ch in 0..3 {
                    let got: f64 = (0..3).map(|k| b[k] * colors[tri[k] as usize][ch]).sum();
                    sum += (got - want[ch]).powi(2);
                    n += 1;
                }
            }
        }
        (sum / n as f64).sqrt()
    }

    fn fit(app: &Appearance, lod: &TriMesh) -> (Vec<[f64; 4]>, Vec<[f64; 4]>) {
        let index = InputIndex::new(&app.mesh);
        let normals = vertex_normals(lod);
        let prov = ProvenanceParams { envelope: 0.05 };
        let point: Vec<[f64; 4]> = index
            .query_all(lod.positions(), &normals, &prov)
            .iter()
            .map(|p| app.sample(p.triangle as usize, p.bary).base_color)
            .collect();
        let fitted = fit_vertex_colors(app, &index, lod, &normals, &prov);
        assert_eq!(
            fitted.fallback_fraction, 0.0,
            "every sample is found by the cast"
        );
        (point, fitted.colors)
    }

    #[test]
    fn quadrature_is_exact_for_linear_functions() {
        for m in 1..=7 {
            let s = triangle_samples(m);
            assert_eq!(s.len(), m * m);
            let w: f64 = s.iter().map(|x| x.1).sum();
            assert!((w - 1.0).abs() < 1e-14);
            for k in 0..3 {
                let i: f64 = s.iter().map(|(b, w)| w * b[k]).sum();
                assert!((i - 1.0 / 3.0).abs() < 1e-14, "∫ φ_k = 1/3 of the area");
            }
        }
    }

    #[test]
    fn linear_colours_are_reproduced_exactly() {
        // The L² projection onto linear elements of a linear field is that field, up to the
        // centroid rule's error on `φ_k · c_in` (quadratic): O((h/m)²), 1e-4 here.
        let f = |x: f64, y: f64| [0.2 + 0.5 * x, 0.7 - 0.4 * y, 0.1 + 0.3 * x + 0.4 * y, 1.0];
        let app = input(&f);
        let lod = square(4, 0.01);
        let (_, colors) = fit(&app, &lod);
        for (p, c) in lod.positions().iter().zip(&colors) {
            let want = f(p[0], p[1]);
            (0..4).for_each(|k| assert!((c[k] - want[k]).abs() < 5e-4, "{c:?} vs {want:?}"));
        }
    }

    #[test]
    fn least_squares_beats_vertex_sampling_on_a_smooth_field() {
        let app = input(&smooth);
        let lod = square(5, 0.01);
        let (point, fitted) = fit(&app, &lod);
        let (old, new) = (rms(&lod, &point, &smooth), rms(&lod, &fitted, &smooth));
        println!("RMS colour error: vertex sampling {old:.5}, least squares {new:.5}");
        // Measured: 0.084 vs 0.112 (the L² projection is the best linear fit in this norm).
        assert!(
            new < 0.8 * old,
            "least squares {new} vs vertex sampling {old}"
        );
    }

    /// A fold: two coincident triangles of opposite orientation sharing their LOD vertices
    /// (a sheet whose two sides the fit projected onto one plane), each its own chart. The
    /// smooth vertex normal is zero there; each atlas vertex gets its own side's normal.
    #[test]
    fn folded_sides_get_their_own_normals() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let lod = TriMesh::new(p.to_vec(), vec![[0, 1, 2], [0, 2, 1]]).unwrap();
        let atlas = Atlas {
            size: 16,
            xref: vec![0, 1, 2, 0, 2, 1],
            uv: vec![
                [1.0, 1.0],
                [7.0, 1.0],
                [1.0, 7.0],
                [9.0, 9.0],
                [15.0, 9.0],
                [9.0, 15.0],
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
            chart_count: 2,
            overlapping_texels: 0,
            padding: 1,
        };
        let positions: Vec<[f64; 3]> = atlas.xref.iter().map(|&v| p[v as usize]).collect();
        let smooth = vertex_normals(&lod);
        let n = atlas_normals(&atlas, &positions, &smooth);
        for (a, want) in [
            (0, 1.0),
            (1, 1.0),
            (2, 1.0),
            (3, -1.0),
            (4, -1.0),
            (5, -1.0),
        ] {
            assert_eq!(n[a], [0.0, 0.0, want], "atlas vertex {a}");
        }
        // Where the smooth normal agrees with the chart, it is kept as is.
        let tilted = vec![[0.6, 0.0, 0.8]; 3];
        let one = Atlas {
            xref: vec![0, 1, 2],
            triangles: vec![[0, 1, 2]],
            ..atlas
        };
        assert_eq!(atlas_normals(&one, &p, &tilted), tilted);
    }

    #[test]
    fn a_neutral_normal_map_is_flat() {
        let cov = Coverage {
            size: 2,
            tri: vec![0, 0, 0, u32::MAX],
            bary: vec![[1.0, 0.0, 0.0]; 4],
        };
        let neutral = [128, 127, 255, 255, 127, 128, 255, 255, 128, 128, 254, 255];
        let mut img = neutral.to_vec();
        img.extend([255, 0, 0, 255]); // an uncovered texel does not count
        assert!(is_flat_normal_map(&img, &cov));
        img[0] = 140; // one of three covered texels tilted
        assert!(!is_flat_normal_map(&img, &cov));
        assert!(!is_flat_normal_map(&[], &cov));
    }
}
