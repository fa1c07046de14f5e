//! Step 2, sampling one texel ([`TexelCtx`]): the LOD surface point and normal, its provenance
//! on the input, the input's material there, encoded into each image's bytes (base colour and
//! emissive sRGB, metallic-roughness as glTF's, occlusion, the normal in tangent space). Each
//! texel is independent of the others.

use super::rasterize::Coverage;
use super::tangents::tangent_coords;
use crate::bake::appearance::{linear_to_srgb, Appearance, MaterialSample};
use crate::bake::atlas::Atlas;
use crate::geom::{normalized, Vec3};
use crate::transfer::provenance::{InputIndex, ProvenanceParams};

/// Texels baked between two progress reports (and cancellation checks): about 10 ms of work
/// on one core, so a cancel takes effect well within 0.1 s.
pub(super) const TEXELS_PER_CHECK: usize = 4096;

/// The rows of an optional image (empty image: `n` empty rows).
pub(super) fn rows_of(img: &mut [u8], row_bytes: usize, n: usize) -> Vec<&mut [u8]> {
    if img.is_empty() {
        (0..n).map(|_| &mut [][..]).collect()
    } else {
        img.chunks_mut(row_bytes).collect()
    }
}

pub(super) struct Rows<'a> {
    pub(super) base: &'a mut [u8],
    pub(super) mr: &'a mut [u8],
    pub(super) occ: &'a mut [u8],
    pub(super) emi: &'a mut [u8],
    pub(super) nrm: &'a mut [u8],
}

pub(super) struct TexelCtx<'a> {
    pub(super) app: &'a Appearance,
    pub(super) index: &'a InputIndex<'a>,
    pub(super) prov: &'a ProvenanceParams,
    pub(super) atlas: &'a Atlas,
    pub(super) positions: &'a [[f64; 3]],
    pub(super) normals: &'a [[f64; 3]],
    /// Per atlas triangle corner.
    pub(super) tangents: &'a [[f32; 4]],
    pub(super) cov: &'a Coverage,
}

/// `v` quantised to 8 bits.
fn q8(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

impl TexelCtx<'_> {
    /// LOD point, interpolated normal (unit), and the (unnormalised) interpolated frame.
    pub(super) fn surface(&self, t: usize, b: [f32; 3]) -> (Vec3, Vec3, Vec3, Vec3, f64) {
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
    pub(super) fn bake_row(&self, j: usize, rows: &mut Rows<'_>) -> (u64, u64) {
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
