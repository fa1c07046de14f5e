//! Step 1, rasterising the atlas ([`Coverage`]): each texel whose centre lies in an atlas
//! triangle gets that triangle and the centre's barycentric coordinates; texels within half a
//! texel diagonal of a triangle but outside every one get the nearest point of the nearest such
//! triangle, so bilinear filtering at chart borders reads surface values, not gutter.

use crate::bake::atlas::{uv_area, Atlas};

/// Per texel: the atlas triangle and barycentric coordinates (`u32::MAX` = empty).
pub(super) struct Coverage {
    pub(super) size: u32,
    pub(super) tri: Vec<u32>,
    pub(super) bary: Vec<[f32; 3]>,
}

/// Rasterises the atlas (see the [module docs](self), step 1).
pub(super) fn rasterize(atlas: &Atlas) -> Coverage {
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
