//! Vertex colours of a LOD without textures: the L² fit of the input's base colour (factor ×
//! `COLOR_0`) over the LOD surface, by quadrature and a mass-matrix solve, and for a
//! `COLOR_0`-only input under `VertexColors::Auto` the verdict whether the fit's error is
//! within what the screen size allows (else a texture is baked).

use std::time::Instant;

use rayon::prelude::*;

use super::errors::{color_error, set_errors};
use super::material::base_material;
use super::params::{BakeParams, VertexColors};
use super::progress::Steps;
use crate::bake::appearance::{linear_to_srgb, Appearance};
use crate::bake::level::{BakeReport, BakedLevel};
use crate::geom::{normalized, Vec3};
use crate::mesh::TriMesh;
use crate::transfer::provenance::{vertex_normals, InputIndex, ProvenanceParams};
use crate::Result;

/// Surface samples the [`VertexColors::Auto`] decision compares at most.
const AUTO_SAMPLES: usize = 20_000;

pub(super) fn bake_vertex_colors(
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
pub(super) struct VertexColorFit {
    /// Linear RGBA per LOD vertex, each channel clamped to `[0, 1]`.
    pub(super) colors: Vec<[f64; 4]>,
    /// Fraction of samples not found by the cast along the normal.
    pub(super) fallback_fraction: f64,
    /// The quadrature points: LOD triangle and barycentric coordinates.
    samples: Vec<(usize, [f64; 3])>,
}

/// Least-squares vertex colours (the requirement "vertex colours transfer as vertex colours"): the
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
pub(super) fn fit_vertex_colors(
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
pub(super) fn triangle_samples(m: usize) -> Vec<([f64; 3], f64)> {
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
