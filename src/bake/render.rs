//! A small deterministic software rasterizer that **measures** a bake (its error, for the
//! error-against-run-time benchmark): the input and a baked LOD level are rendered from the same
//! views and compared pixel by pixel. It is for evaluation only and shares nothing with the baking
//! code paths: the input is shaded by [`Appearance::sample`] at the rasterized input point; the
//! level by its own UVs, textures, normals and tangents as a glTF viewer would read them from the
//! output (bilinear, clamp to edge, sRGB decoded before filtering, normal map decoded in the
//! per-pixel MikkTSpace frame `normalize(x·T + y·B + z·N)`, `B = w · N × T`).
//!
//! - **Views**: [`views`] places `count` cameras on a Fibonacci sphere around the centre of
//!   the input's bounding box, at 2.5 bounding-box diagonals `l`, with a perspective focal
//!   length that maps `l` to `pixels` pixels at the centre (so `pixels = n_p` renders a level
//!   at the screen size it was made for), image side `⌈1.25 · pixels⌉ + 2`.
//! - **Rasterization** ([`rasterize`]): pixel centres inside a triangle (either orientation:
//!   no culling), z-buffered on the camera depth with ties kept by the lower triangle index,
//!   and perspective-correct barycentric coordinates `b_k = (λ_k / z_k) / Σ_m λ_m / z_m` (`λ`
//!   the screen-space ones), through which every attribute (UV, normal, tangent, point) is
//!   interpolated.
//! - **Shading** ([`shade`], [`Mode`]): unlit base colour; or a fixed light in the camera's
//!   frame (a head light from the upper right, so every view is lit) with white albedo —
//!   `0.1 + 0.9 · max(0, n·L)` — so a shaded comparison measures the shading normals only; or
//!   base colour times that light (pictures). Shading normals face the camera on back faces
//!   (two-sided), for the input and the level alike. Output values are display sRGB in [0, 1].
//! - **Metrics** ([`psnr_db`], [`evaluate`]): PSNR over the pixels both renders cover, per view,
//!   averaged over views; the normal-map gain is the shaded PSNR with the baked normal map
//!   minus the shaded PSNR without it (vertex normals only). The reference PSNR renders the
//!   level's geometry coloured by the input's material at the closest input point: what a
//!   perfect bake on this geometry would score, so `reference − appearance` is what the bake
//!   itself (atlas, texel rate, 8-bit quantisation, provenance) loses.
//!
//! Everything is sequential inside a view and parallel over views, so results do not depend on
//! the thread count.

use rayon::prelude::*;

use super::appearance::{linear_to_srgb, srgb_to_linear, Appearance};
use super::level::{BakedLevel, Image8};
use crate::geom::{normalized, Vec3};
use crate::spatial::TriangleBvh;
use crate::transfer::provenance::barycentric;

/// A pinhole camera with a square image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Camera position.
    pub eye: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Unit image right.
    pub right: Vec3,
    /// Unit image up.
    pub up: Vec3,
    /// Focal length in pixels.
    pub focal: f64,
    /// Image side in pixels.
    pub side: u32,
}

impl View {
    /// A camera at `eye` looking at `target`, `focal` pixels, `side`² pixels.
    pub fn look_at(eye: Vec3, target: Vec3, focal: f64, side: u32) -> View {
        let forward = normalized(target - eye).unwrap_or(Vec3::NEG_Z);
        let world_up = if forward.y.abs() < 0.99 {
            Vec3::Y
        } else {
            Vec3::Z
        };
        let right = normalized(forward.cross(world_up)).unwrap_or(Vec3::X);
        let up = right.cross(forward);
        View {
            eye,
            forward,
            right,
            up,
            focal,
            side,
        }
    }

    /// Screen position `(x, y)` in pixels (y down) and camera depth `z` of `p`; `None` when `p`
    /// is not in front of the camera.
    pub fn project(&self, p: Vec3) -> Option<[f64; 3]> {
        let d = p - self.eye;
        let z = d.dot(self.forward);
        if z.is_nan() || z <= 1e-9 {
            return None;
        }
        let c = 0.5 * f64::from(self.side);
        Some([
            c + self.focal * d.dot(self.right) / z,
            c - self.focal * d.dot(self.up) / z,
            z,
        ])
    }

    /// Unit direction towards the light: from the camera's upper right, in front.
    pub fn light(&self) -> Vec3 {
        normalized(-self.forward + 0.6 * self.up + 0.4 * self.right).unwrap_or(-self.forward)
    }
}

/// `count` views on a Fibonacci sphere around the box `(lo, hi)` (see the [module
/// docs](self)), the box diagonal spanning `pixels` pixels at its centre.
pub fn views(bbox: ([f64; 3], [f64; 3]), count: usize, pixels: f64) -> Vec<View> {
    let (lo, hi) = (Vec3::from(bbox.0), Vec3::from(bbox.1));
    let center = 0.5 * (lo + hi);
    let diag = (hi - lo).length().max(f64::MIN_POSITIVE);
    let distance = 2.5 * diag;
    let focal = pixels * distance / diag;
    let side = (1.25 * pixels).ceil() as u32 + 2;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let a = golden * i as f64;
            let dir = Vec3::new(r * a.cos(), y, r * a.sin());
            View::look_at(center + distance * dir, center, focal, side)
        })
        .collect()
}

/// The visible surface of each pixel: triangle and perspective-correct barycentric
/// coordinates, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct GBuffer {
    /// Image side in pixels.
    pub side: u32,
    /// Per pixel: `(triangle, barycentric)` of the nearest surface, or `None`.
    pub hit: Vec<Option<(u32, [f64; 3])>>,
}

/// Z-buffered rasterization of `triangles` seen from `view` (see the [module docs](self)).
pub fn rasterize(view: &View, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> GBuffer {
    let n = view.side as usize;
    let mut depth = vec![f64::INFINITY; n * n];
    let mut hit = vec![None; n * n];
    for (t, tri) in triangles.iter().enumerate() {
        let Some(s) = project_triangle(view, positions, tri) else {
            continue;
        };
        let area = edge(s[0], s[1], s[2]);
        if area == 0.0 || !area.is_finite() {
            continue;
        }
        let (lo, hi) = pixel_range(&s, n);
        for j in lo[1]..hi[1] {
            for i in lo[0]..hi[0] {
                let c = [i as f64 + 0.5, j as f64 + 0.5, 0.0];
                let lam = [
                    edge(s[1], s[2], c),
                    edge(s[2], s[0], c),
                    edge(s[0], s[1], c),
                ]
                .map(|e| e / area);
                if lam.iter().any(|&l| l < 0.0) {
                    continue;
                }
                let w = [0, 1, 2].map(|k| lam[k] / s[k][2]);
                let sum = w[0] + w[1] + w[2];
                let z = 1.0 / sum;
                let k = j * n + i;
                if z < depth[k] {
                    depth[k] = z;
                    hit[k] = Some((t as u32, w.map(|x| x / sum)));
                }
            }
        }
    }
    GBuffer {
        side: view.side,
        hit,
    }
}

fn project_triangle(view: &View, positions: &[[f64; 3]], tri: &[u32; 3]) -> Option<[[f64; 3]; 3]> {
    let a = view.project(Vec3::from(positions[tri[0] as usize]))?;
    let b = view.project(Vec3::from(positions[tri[1] as usize]))?;
    let c = view.project(Vec3::from(positions[tri[2] as usize]))?;
    Some([a, b, c])
}

/// Twice the signed area of screen triangle `(a, b, c)` (`z` ignored).
fn edge(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Pixel index ranges `[lo, hi)` of the triangle's screen box, clipped to the image.
fn pixel_range(s: &[[f64; 3]; 3], n: usize) -> ([usize; 2], [usize; 2]) {
    let lo = [0, 1].map(|a| {
        let m = s[0][a].min(s[1][a]).min(s[2][a]) - 0.5;
        m.ceil().clamp(0.0, n as f64) as usize
    });
    let hi = [0, 1].map(|a| {
        let m = s[0][a].max(s[1][a]).max(s[2][a]) - 0.5;
        (m.floor() + 1.0).clamp(0.0, n as f64) as usize
    });
    (lo, hi)
}

/// What a pixel shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The base colour, unlit.
    Unlit,
    /// White albedo under the view's light (shading normals only).
    Shaded,
    /// Base colour under the view's light (pictures).
    TexturedShaded,
}

/// A surface that can be shaded at a rasterized point.
pub trait Surface: Sync {
    /// Vertex positions.
    fn positions(&self) -> &[[f64; 3]];
    /// Triangles over [`positions`](Self::positions).
    fn triangles(&self) -> &[[u32; 3]];
    /// Linear RGB base colour at barycentric `b` of triangle `t`.
    fn base_color(&self, t: usize, b: [f64; 3]) -> [f64; 3];
    /// Unit shading normal at barycentric `b` of triangle `t` (either side).
    fn normal(&self, t: usize, b: [f64; 3]) -> Vec3;

    /// The point at barycentric `b` of triangle `t`.
    fn point(&self, t: usize, b: [f64; 3]) -> Vec3 {
        let tri = self.triangles()[t];
        (0..3)
            .map(|k| Vec3::from(self.positions()[tri[k] as usize]) * b[k])
            .sum()
    }

    /// Unnormalised geometric normal of triangle `t`.
    fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangles()[t].map(|v| Vec3::from(self.positions()[v as usize]));
        (b - a).cross(c - a)
    }
}

/// An image rendered by [`shade`]: display sRGB values in [0, 1], `None` where no surface is.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Image side in pixels.
    pub side: u32,
    /// Row-major pixels, row 0 at the top.
    pub rgb: Vec<Option<[f64; 3]>>,
}

impl Frame {
    /// The frame as an 8-bit RGBA image, `background` where nothing is.
    pub fn to_image(&self, background: [u8; 3]) -> Image8 {
        let rgba = self
            .rgb
            .iter()
            .flat_map(|p| match p {
                Some(c) => {
                    let q = c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8);
                    [q[0], q[1], q[2], 255]
                }
                None => [background[0], background[1], background[2], 255],
            })
            .collect();
        Image8 {
            width: self.side,
            height: self.side,
            rgba,
        }
    }
}

/// Shades every covered pixel of `g` (rasterized from `view`) with `surface` in `mode`.
pub fn shade(g: &GBuffer, view: &View, surface: &dyn Surface, mode: Mode) -> Frame {
    let light = view.light();
    let rgb = g
        .hit
        .iter()
        .map(|h| {
            let &(t, b) = h.as_ref()?;
            let t = t as usize;
            let lit = || {
                let mut n = surface.normal(t, b);
                if surface.face_normal(t).dot(view.eye - surface.point(t, b)) < 0.0 {
                    n = -n;
                }
                0.1 + 0.9 * n.dot(light).max(0.0)
            };
            let linear = match mode {
                Mode::Unlit => surface.base_color(t, b),
                Mode::Shaded => [lit(); 3],
                Mode::TexturedShaded => {
                    let l = lit();
                    surface.base_color(t, b).map(|c| c * l)
                }
            };
            Some(linear.map(linear_to_srgb))
        })
        .collect();
    Frame { side: g.side, rgb }
}

/// The input as rendered: its material through [`Appearance::sample`].
pub struct InputSurface<'a>(pub &'a Appearance);

impl Surface for InputSurface<'_> {
    fn positions(&self) -> &[[f64; 3]] {
        self.0.mesh.positions()
    }
    fn triangles(&self) -> &[[u32; 3]] {
        self.0.mesh.triangles()
    }
    fn base_color(&self, t: usize, b: [f64; 3]) -> [f64; 3] {
        let c = self.0.sample(t, b).base_color;
        [c[0], c[1], c[2]]
    }
    fn normal(&self, t: usize, b: [f64; 3]) -> Vec3 {
        Vec3::from(self.0.sample(t, b).normal)
    }
}

/// A baked level as a glTF viewer shows it (see the [module docs](self)); `normal_map: false`
/// ignores its normal texture.
pub struct LevelSurface<'a> {
    /// The level.
    pub level: &'a BakedLevel,
    /// Whether the level's normal texture perturbs the vertex normals.
    pub normal_map: bool,
}

impl LevelSurface<'_> {
    fn uv(&self, t: usize, b: [f64; 3]) -> Option<[f64; 2]> {
        let uvs = self.level.uvs.as_ref()?;
        let tri = self.level.triangles[t];
        let mut uv = [0.0; 2];
        for k in 0..3 {
            let c = uvs[tri[k] as usize];
            uv[0] += b[k] * f64::from(c[0]);
            uv[1] += b[k] * f64::from(c[1]);
        }
        Some(uv)
    }
}

impl Surface for LevelSurface<'_> {
    fn positions(&self) -> &[[f64; 3]] {
        &self.level.positions
    }
    fn triangles(&self) -> &[[u32; 3]] {
        &self.level.triangles
    }
    fn base_color(&self, t: usize, b: [f64; 3]) -> [f64; 3] {
        let m = &self.level.material;
        let mut c = [
            m.base_color_factor[0],
            m.base_color_factor[1],
            m.base_color_factor[2],
        ];
        if let (Some(img), Some(uv)) = (&m.base_color, self.uv(t, b)) {
            let s = sample_image(img, uv, true);
            (0..3).for_each(|k| c[k] *= s[k]);
        }
        if let Some(colors) = &self.level.colors {
            let tri = self.level.triangles[t];
            let mut v = [0.0; 3];
            for k in 0..3 {
                let col = colors[tri[k] as usize];
                (0..3).for_each(|j| v[j] += b[k] * f64::from(col[j]));
            }
            (0..3).for_each(|k| c[k] *= v[k]);
        }
        c
    }
    fn normal(&self, t: usize, b: [f64; 3]) -> Vec3 {
        let tri = self.level.triangles[t];
        let n: Vec3 = (0..3)
            .map(|k| Vec3::from(self.level.normals[tri[k] as usize].map(f64::from)) * b[k])
            .sum();
        let geometric = || normalized(self.face_normal(t)).unwrap_or(Vec3::Z);
        let unit = normalized(n).unwrap_or_else(geometric);
        let (Some(img), Some(tangents), Some(uv), true) = (
            &self.level.material.normal,
            &self.level.tangents,
            self.uv(t, b),
            self.normal_map,
        ) else {
            return unit;
        };
        let mut tg = Vec3::ZERO;
        let mut w = 0.0;
        for k in 0..3 {
            let x = tangents[tri[k] as usize].map(f64::from);
            tg += Vec3::new(x[0], x[1], x[2]) * b[k];
            w += x[3] * b[k];
        }
        let bt = n.cross(tg) * if w < 0.0 { -1.0 } else { 1.0 };
        let s = sample_image(img, uv, false);
        let xyz = [0, 1, 2].map(|k| 2.0 * s[k] - 1.0);
        normalized(tg * xyz[0] + bt * xyz[1] + n * xyz[2]).unwrap_or(unit)
    }
}

/// Bilinear sample of `img` at glTF texture coordinates `uv` (texel centres at `(i + ½)/W`),
/// clamped to the edge; RGB sRGB-decoded before filtering when `srgb`, else raw `/255`.
pub fn sample_image(img: &Image8, uv: [f64; 2], srgb: bool) -> [f64; 3] {
    let x = uv[0] * f64::from(img.width) - 0.5;
    let y = uv[1] * f64::from(img.height) - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |i: f64, j: f64| {
        let i = (i as i64).clamp(0, i64::from(img.width) - 1) as u32;
        let j = (j as i64).clamp(0, i64::from(img.height) - 1) as u32;
        let t = img.texel(i, j);
        [0, 1, 2].map(|k| {
            let v = f64::from(t[k]) / 255.0;
            if srgb {
                srgb_to_linear(v)
            } else {
                v
            }
        })
    };
    let taps = [
        (at(x0, y0), (1.0 - fx) * (1.0 - fy)),
        (at(x0 + 1.0, y0), fx * (1.0 - fy)),
        (at(x0, y0 + 1.0), (1.0 - fx) * fy),
        (at(x0 + 1.0, y0 + 1.0), fx * fy),
    ];
    let mut out = [0.0; 3];
    for (v, w) in taps {
        (0..3).for_each(|k| out[k] += w * v[k]);
    }
    out
}

/// The level's geometry coloured with the input's material at the closest input point: what a
/// perfect bake onto this geometry shows (the reference of [`Evaluation::reference_psnr_db`]).
pub struct ReferenceSurface<'a> {
    level: LevelSurface<'a>,
    app: &'a Appearance,
    bvh: TriangleBvh,
}

impl<'a> ReferenceSurface<'a> {
    /// Indexes `app`'s mesh for closest-point queries.
    pub fn new(app: &'a Appearance, level: &'a BakedLevel) -> Self {
        ReferenceSurface {
            level: LevelSurface {
                level,
                normal_map: false,
            },
            app,
            bvh: TriangleBvh::new(app.mesh.positions(), app.mesh.triangles()),
        }
    }
}

impl Surface for ReferenceSurface<'_> {
    fn positions(&self) -> &[[f64; 3]] {
        self.level.positions()
    }
    fn triangles(&self) -> &[[u32; 3]] {
        self.level.triangles()
    }
    fn base_color(&self, t: usize, b: [f64; 3]) -> [f64; 3] {
        let p = self.point(t, b);
        let mesh = &self.app.mesh;
        let Some(c) = self.bvh.closest_point(
            mesh.positions(),
            mesh.triangles(),
            p.to_array(),
            f64::INFINITY,
        ) else {
            return [0.0; 3];
        };
        let tri = c.triangle as usize;
        let bary = barycentric(
            mesh.triangle_positions(tri).map(Vec3::from),
            Vec3::from(c.point),
        );
        let s = self.app.sample(tri, bary).base_color;
        [s[0], s[1], s[2]]
    }
    fn normal(&self, t: usize, b: [f64; 3]) -> Vec3 {
        self.level.normal(t, b)
    }
}

/// PSNR in dB of `b` against `a` over the pixels both cover (peak 1, mean squared error over
/// R, G, B); `None` when they share no pixel; capped at 100 dB for identical images.
pub fn psnr_db(a: &Frame, b: &Frame) -> Option<f64> {
    let (sum, count) = squared_error(a, b);
    psnr_of(sum, count)
}

/// Sum of squared differences over R, G, B of the pixels both frames cover, and the number of
/// values summed (3 per pixel).
pub fn squared_error(a: &Frame, b: &Frame) -> (f64, usize) {
    let (mut sum, mut count) = (0.0, 0usize);
    for (x, y) in a.rgb.iter().zip(&b.rgb) {
        if let (Some(x), Some(y)) = (x, y) {
            sum += (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>();
            count += 3;
        }
    }
    (sum, count)
}

/// PSNR (peak 1, capped at 100 dB) of `sum` squared errors over `count` values; `None` for no
/// values.
fn psnr_of(sum: f64, count: usize) -> Option<f64> {
    if count == 0 {
        return None;
    }
    let mse = sum / count as f64;
    Some(if mse <= 1e-10 {
        100.0
    } else {
        (-10.0 * mse.log10()).min(100.0)
    })
}

/// Fraction of the pixels covered by either frame that both cover (intersection over union of
/// the silhouettes; 1 when neither covers any).
pub fn coverage_iou(a: &Frame, b: &Frame) -> f64 {
    let (mut both, mut either) = (0usize, 0usize);
    for (x, y) in a.rgb.iter().zip(&b.rgb) {
        both += usize::from(x.is_some() && y.is_some());
        either += usize::from(x.is_some() || y.is_some());
    }
    if either == 0 {
        1.0
    } else {
        both as f64 / either as f64
    }
}

/// Parameters of [`evaluate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvalParams {
    /// Number of views (Fibonacci sphere). Default 24.
    pub views: usize,
    /// Pixels the bounding-box diagonal spans; `None` uses the level's screen size `n_p`.
    pub pixels: Option<f64>,
    /// Also render the closest-point reference ([`Evaluation::reference_psnr_db`]). Default
    /// true.
    pub reference: bool,
}

impl Default for EvalParams {
    fn default() -> Self {
        EvalParams {
            views: 24,
            pixels: None,
            reference: true,
        }
    }
}

/// Renders compared (means over the views where both renders cover some pixel).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Evaluation {
    /// Views rendered.
    pub views: usize,
    /// Image side of each view in pixels.
    pub side: u32,
    /// Unlit PSNR of the baked level against the input, dB.
    pub appearance_psnr_db: f64,
    /// Unlit PSNR of the closest-point reference against the input, dB (NaN when not asked).
    pub reference_psnr_db: f64,
    /// Shaded PSNR of the level with its normal map against the input, dB.
    pub shaded_psnr_db: f64,
    /// Shaded PSNR of the level with vertex normals only, dB.
    pub shaded_psnr_without_map_db: f64,
    /// `shaded_psnr_db − shaded_psnr_without_map_db`, dB; `None` without a normal map.
    pub normal_map_gain_db: Option<f64>,
    /// Mean silhouette agreement ([`coverage_iou`]).
    pub coverage_iou: f64,
    /// Unlit PSNR of the baked level over the pixels both renders cover in all views pooled
    /// (one mean squared error over every such pixel), dB: unlike the mean over views, a view
    /// that shares only a few pixels (a flat asset seen edge-on) weighs only those pixels.
    pub appearance_pooled_psnr_db: f64,
    /// The same pooled PSNR for the closest-point reference, dB (NaN when not asked).
    pub reference_pooled_psnr_db: f64,
}

/// One view's scores: the five per-view PSNR/IoU figures of [`evaluate`] (unlit, reference,
/// shaded with and without the map, coverage IoU) and the (squared error, pixels) sums of the
/// unlit bake and the reference, pooled over views afterwards.
type ViewScores = ([Option<f64>; 5], [(f64, usize); 2]);

/// Renders `app` and its baked level `level` from [`EvalParams::views`] views (see the [module
/// docs](self)) and compares them.
pub fn evaluate(app: &Appearance, level: &BakedLevel, params: &EvalParams) -> Evaluation {
    let pixels = params.pixels.unwrap_or(level.screen_size).max(1.0);
    let cams = views(app.mesh.bbox(), params.views.max(1), pixels);
    let reference = params.reference.then(|| ReferenceSurface::new(app, level));
    let input = InputSurface(app);
    let with_map = LevelSurface {
        level,
        normal_map: true,
    };
    let without_map = LevelSurface {
        level,
        normal_map: false,
    };
    let has_map = level.material.normal.is_some() && level.tangents.is_some();
    let per_view: Vec<ViewScores> = cams
        .par_iter()
        .map(|v| {
            let gi = rasterize(v, input.positions(), input.triangles());
            let gl = rasterize(v, with_map.positions(), with_map.triangles());
            let in_unlit = shade(&gi, v, &input, Mode::Unlit);
            let in_shaded = shade(&gi, v, &input, Mode::Shaded);
            let lod_unlit = shade(&gl, v, &with_map, Mode::Unlit);
            let lod_shaded = shade(&gl, v, &with_map, Mode::Shaded);
            let plain = if has_map {
                psnr_db(&in_shaded, &shade(&gl, v, &without_map, Mode::Shaded))
            } else {
                psnr_db(&in_shaded, &lod_shaded)
            };
            let ref_err = reference.as_ref().map_or((0.0, 0), |r| {
                squared_error(&in_unlit, &shade(&gl, v, r, Mode::Unlit))
            });
            let lod_err = squared_error(&in_unlit, &lod_unlit);
            let per_view = [
                psnr_of(lod_err.0, lod_err.1),
                psnr_of(ref_err.0, ref_err.1),
                psnr_db(&in_shaded, &lod_shaded),
                plain,
                Some(coverage_iou(&in_unlit, &lod_unlit)),
            ];
            (per_view, [lod_err, ref_err])
        })
        .collect();
    let pooled = |k: usize| {
        let (sum, count) = per_view
            .iter()
            .fold((0.0, 0), |(s, c), (_, e)| (s + e[k].0, c + e[k].1));
        psnr_of(sum, count).unwrap_or(f64::NAN)
    };
    let mean = |k: usize| {
        let v: Vec<f64> = per_view.iter().filter_map(|r| r.0[k]).collect();
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let (shaded, plain) = (mean(2), mean(3));
    Evaluation {
        views: cams.len(),
        side: cams.first().map_or(0, |v| v.side),
        appearance_psnr_db: mean(0),
        reference_psnr_db: mean(1),
        shaded_psnr_db: shaded,
        shaded_psnr_without_map_db: plain,
        normal_map_gain_db: has_map.then_some(shaded - plain),
        coverage_iou: mean(4),
        appearance_pooled_psnr_db: pooled(0),
        reference_pooled_psnr_db: pooled(1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_view(side: u32) -> View {
        // Looking down −z at the unit square [0, 1]² at z = 0 from z = 2, focal = side.
        View::look_at(
            Vec3::new(0.5, 0.5, 2.0),
            Vec3::new(0.5, 0.5, 0.0),
            f64::from(side),
            side,
        )
    }

    #[test]
    fn projection_centres_the_target() {
        let v = quad_view(64);
        let p = v.project(Vec3::new(0.5, 0.5, 0.0)).unwrap();
        assert!((p[0] - 32.0).abs() < 1e-12 && (p[1] - 32.0).abs() < 1e-12);
        assert!((p[2] - 2.0).abs() < 1e-12);
        assert!(v.project(Vec3::new(0.5, 0.5, 3.0)).is_none());
    }

    #[test]
    fn perspective_correct_barycentrics_reproduce_the_point() {
        // A tilted triangle: interpolating the corners with the perspective-correct
        // barycentric coordinates gives a point that projects back to the pixel centre.
        let pos = [[0.0, 0.0, -0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.2]];
        let v = quad_view(40);
        let g = rasterize(&v, &pos, &[[0, 1, 2]]);
        let mut covered = 0;
        for (k, h) in g.hit.iter().enumerate() {
            let Some((_, b)) = h else { continue };
            covered += 1;
            let p: Vec3 = (0..3).map(|i| Vec3::from(pos[i]) * b[i]).sum();
            let s = v.project(p).unwrap();
            let (i, j) = (k % 40, k / 40);
            assert!((s[0] - (i as f64 + 0.5)).abs() < 1e-9, "{s:?} at {i},{j}");
            assert!((s[1] - (j as f64 + 0.5)).abs() < 1e-9, "{s:?} at {i},{j}");
        }
        assert!(covered > 50);
    }

    #[test]
    fn z_buffer_keeps_the_nearest_triangle() {
        // Two overlapping triangles: a large one at z = 0 (far), a unit one at z = 0.5 (near).
        let pos = [
            [0.0, 0.0, 0.0],
            [1.5, 0.0, 0.0],
            [0.0, 1.5, 0.0],
            [0.0, 0.0, 0.5],
            [1.0, 0.0, 0.5],
            [0.0, 1.0, 0.5],
        ];
        let v = quad_view(32);
        let g = rasterize(&v, &pos, &[[0, 1, 2], [3, 4, 5]]);
        let near = g.hit.iter().flatten().filter(|h| h.0 == 1).count();
        let far = g.hit.iter().flatten().filter(|h| h.0 == 0).count();
        assert!(
            near > 0 && far > 0,
            "the far one shows beyond the near one's edge"
        );
        // At the screen centre of the near triangle, the near one wins.
        let c = v.project(Vec3::new(0.25, 0.25, 0.5)).unwrap();
        let k = c[1] as usize * 32 + c[0] as usize;
        assert_eq!(g.hit[k].unwrap().0, 1);
    }

    #[test]
    fn bilinear_image_sampling_hits_texel_centres() {
        let img = Image8 {
            width: 2,
            height: 1,
            rgba: vec![0, 0, 0, 255, 255, 255, 255, 255],
        };
        assert_eq!(sample_image(&img, [0.25, 0.5], false), [0.0; 3]);
        assert_eq!(sample_image(&img, [0.75, 0.5], false), [1.0; 3]);
        let mid = sample_image(&img, [0.5, 0.5], false);
        assert!((mid[0] - 0.5).abs() < 1e-12);
        // Clamped to the edge beyond the image.
        assert_eq!(sample_image(&img, [2.0, 0.5], false), [1.0; 3]);
        // sRGB is decoded before filtering: the mean of linear 0 and 1.
        assert!((sample_image(&img, [0.5, 0.5], true)[0] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn psnr_of_a_known_difference() {
        let a = Frame {
            side: 1,
            rgb: vec![Some([0.5; 3]), None],
        };
        let b = Frame {
            side: 1,
            rgb: vec![Some([0.6; 3]), Some([0.0; 3])],
        };
        // MSE 0.01 over the one shared pixel: 20 dB.
        assert!((psnr_db(&a, &b).unwrap() - 20.0).abs() < 1e-9);
        assert_eq!(psnr_db(&a, &a), Some(100.0));
        assert!((coverage_iou(&a, &b) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn views_surround_the_box() {
        let v = views(([-1.0; 3], [1.0; 3]), 24, 100.0);
        assert_eq!(v.len(), 24);
        let mean: Vec3 = v.iter().map(|c| c.eye).sum::<Vec3>() / 24.0;
        assert!(mean.length() < 0.2 * v[0].eye.length());
        for c in &v {
            let p = c.project(Vec3::ZERO).unwrap();
            let mid = 0.5 * f64::from(c.side);
            assert!((p[0] - mid).abs() < 1e-9 && (p[1] - mid).abs() < 1e-9);
        }
    }
}
