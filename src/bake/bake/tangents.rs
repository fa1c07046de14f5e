//! The LOD's shading frame for step 3, the normal map: per-atlas-vertex normals
//! ([`atlas_normals`]), MikkTSpace tangents on the atlas UVs with v flipped ([`mikk_tangents`]),
//! the output vertices split where tangents differ ([`split_by_tangent`]), and the tangent-space
//! coordinates engines reconstruct a normal from ([`tangent_coords`]).

use crate::bake::atlas::Atlas;
use crate::geom::{normalized, Vec3};

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
pub(super) fn atlas_normals(
    atlas: &Atlas,
    positions: &[[f64; 3]],
    lod_normals: &[[f64; 3]],
) -> Vec<[f64; 3]> {
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

/// `(x, y, z)` with `normalize(x T + y B + z N) = target`, `B = w N × T`, normalised; `(0, 0,
/// 1)` when the frame is singular.
pub(super) fn tangent_coords(t: Vec3, n: Vec3, w: f64, target: Vec3) -> Vec3 {
    let b = n.cross(t) * w;
    let m = glam::DMat3::from_cols(t, b, n);
    if m.determinant().abs() < 1e-12 * (t.length() * b.length() * n.length()).max(1e-300) {
        return Vec3::Z;
    }
    normalized(m.inverse() * target).unwrap_or(Vec3::Z)
}

/// MikkTSpace tangents per atlas triangle corner (`3 t + k`), on UVs with v flipped so the
/// bitangent points to image up.
pub(super) fn mikk_tangents(
    positions: &[[f64; 3]],
    normals: &[[f64; 3]],
    atlas: &Atlas,
) -> Vec<[f32; 4]> {
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
pub(super) fn split_by_tangent(
    atlas: &Atlas,
    tangents: &[[f32; 4]],
) -> (Vec<OutVertex>, Vec<[u32; 3]>) {
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
