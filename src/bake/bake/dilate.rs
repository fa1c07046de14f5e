//! Step 4, dilation: every empty texel copies the texel a breadth-first search from all covered
//! texels reaches it from (4-neighbours, fixed order), so mip levels average a chart only with
//! copies of its own border.

use super::rasterize::Coverage;
use crate::bake::atlas::{footprint_owners, Atlas, BLOCK_SHARED};

/// For every texel, the covered texel whose value it takes (itself when covered; `u32::MAX`
/// when nothing is covered at all), with the blocks of mip `mip` owned by one chart each:
/// a breadth-first search from all covered texels (4-neighbours, fixed order) where a texel
/// of a block [`footprint_owners`] gives to chart `c` takes only `c`'s texels (free and shared
/// blocks take any); texels that search cannot reach (a chart's blocks cut off by shared
/// ones) then take the nearest assigned texel.
pub(super) fn dilation_sources(
    cov: &Coverage,
    chart: &[u32],
    owners: &[u32],
    mip: u32,
) -> Vec<u32> {
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
pub(super) fn clean_mip(atlas: &Atlas, chart: &[u32], deepest: u32, owners: &[u32]) -> Option<u32> {
    if !owners.contains(&BLOCK_SHARED) {
        return Some(deepest);
    }
    let uv = |v: u32| atlas.uv[v as usize].map(f64::from);
    (0..deepest).rev().find(|&m| {
        !footprint_owners(atlas.size, m, &atlas.triangles, &uv, chart).contains(&BLOCK_SHARED)
    })
}

pub(super) fn apply_dilation(img: &mut [u8], src: &[u32]) {
    for (k, &s) in src.iter().enumerate() {
        let s = s as usize;
        if s != k && s != u32::MAX as usize {
            let (a, b) = (4 * s, 4 * k);
            let px = [img[a], img[a + 1], img[a + 2], img[a + 3]];
            img[b..b + 4].copy_from_slice(&px);
        }
    }
}
