//! The textured bake of a LOD: atlas, rasterisation, per-texel sampling of every image the input
//! needs, the normal map, dilation, and the output vertices split by tangent (steps 1–4 of the
//! module docs of `bake::bake`). Rows are sampled in parallel, each texel independently, so the
//! bytes do not depend on the thread count.

use std::time::Instant;

use rayon::prelude::*;

use super::dilate::{apply_dilation, clean_mip, dilation_sources};
use super::errors::{set_errors, texel_errors};
use super::material::{base_material, Channels};
use super::params::BakeParams;
use super::progress::Steps;
use super::rasterize::{rasterize, Coverage};
use super::sample::{rows_of, Rows, TexelCtx, TEXELS_PER_CHECK};
use super::tangents::{atlas_normals, mikk_tangents, split_by_tangent};
use crate::bake::appearance::Appearance;
use crate::bake::atlas::{
    build_atlas_growing, deepest_mip, footprint_owners, triangle_charts, Gutter,
};
use crate::bake::level::{BakeReport, BakedLevel, Image8};
use crate::mesh::TriMesh;
use crate::transfer::provenance::{vertex_normals, InputIndex, ProvenanceParams};
use crate::Result;

#[allow(clippy::too_many_arguments)]
pub(super) fn bake_textured(
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
pub(super) fn is_flat_normal_map(nrm: &[u8], cov: &Coverage) -> bool {
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
