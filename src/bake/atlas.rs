//! UV atlas of a LOD with xatlas (Jonathan Young's, the generator Godot, Blender add-ons and
//! many glTF pipelines use; compiled by the `xatlas-rs` crate, called through declarations in
//! this file — see `ffi`): charts grown by xatlas's proxy-fit /
//! normal-seam metrics, each parameterised by LSCM (planar charts by projection), validated to
//! be injective (xatlas splits charts whose parameterisation folds), and packed without
//! overlaps with a gutter of [`AtlasParams::padding`] texels between charts.
//!
//! **Texel density rule.** A LOD for `n_p` pixels is seen with its bounding-box diagonal `l`
//! covering `n_p` pixels, so one pixel spans `l / n_p` of the surface. The atlas gives
//! `k = texels_per_pixel` texels per pixel (default 2, Nyquist for the magnification a LOD
//! switch allows before the next finer level takes over): `ρ = k · n_p / l` texels per unit
//! length; the atlas side is the next power of two of `√(A ρ² / 0.75)` (`A` the LOD's area,
//! 75 % packing efficiency), clamped to `[min_size, max_size]` (default 32 … 4096). A
//! caller-given size overrides the rule.
//!
//! **Gutter rule.** At its own `n_p` a level is read at mip `log2 k` (1 for `k = 2`); it stays
//! on screen down to `n_p / 2`, where the next level of a ×2 chain takes over, so the deepest
//! mip it needs is `m = ⌈log2 k⌉ + 1` ([`deepest_mip`], 2 by default). Bilinear filtering at
//! mip `m` of a point `s` reads the 2×2 mip texels whose centres surround it: exactly the
//! `B × B` blocks of level-0 texels (`B = 2^m`) that meet the open square `s ± B/2`. The bake
//! gives every block to one chart — the chart whose points' squares reach it
//! ([`footprint_owners`]) — and dilates each chart's texels only into its own blocks, so a
//! mip-`m` texel a chart reads averages only that chart's texels as long as no block is
//! reached from two charts. Two charts' points `a`, `b` reach a common block only when
//! `|a − b| < B/2 + B + B/2 = 2B` along both axes. xatlas (this version) reserves for each
//! chart its texels dilated by `padding` (8-neighbour) on its right and top side within its
//! bit image, so two charts' texels differ by more than `padding` along some axis and their
//! points by more than `padding`: **`padding = 2B = 2^(m+1)`** ([`gutter_for_mip`], 8 by
//! default) keeps every block single-owned, whatever the charts' alignment to blocks. The
//! bake checks it ([`BakeReport::seam_clean_mip`](super::level::BakeReport::seam_clean_mip):
//! the deepest mip with no shared block, lower when a packing with a halved padding or a
//! caller's smaller padding leaves shared blocks; those blocks take the nearest texel, the
//! others stay single-owned). Measured (`tests/bake_eval.rs`
//! `seam_levers`, bilinear reads at mips 0–3 of every triangle's corners, edge midpoints and
//! centroid; 2026-11-27): padding 8 clean at mip 2 on every shared asset's LOD; 6 mixed up to
//! 1.9 % of mip-2 samples, 1.2 % with xatlas's 4×4 block alignment
//! ([`AtlasParams::block_align`], which only aligns charts facing each other along an axis;
//! diagonal and nested neighbours keep arbitrary offsets), and 8 with alignment gained nothing
//! over 8 without.
//! Before this rule the dilation gave each gutter texel to the nearest chart, which needed
//! charts `3B` apart plus one mip texel for xatlas's one-sided reservation (`4 · 2^m − 1` = 15).

use crate::mesh::TriMesh;
use crate::{Error, Result};

/// Parameters of [`build_atlas`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtlasParams {
    /// Square atlas side in texels; `None` applies the density rule of the [module docs](self).
    pub size: Option<u32>,
    /// Texels per screen pixel `k` of the density rule (finite, > 0). Default 2.
    pub texels_per_pixel: f64,
    /// Smallest side the rule may choose (power of two). Default 32.
    pub min_size: u32,
    /// Largest side the rule may choose (power of two). Default 4096.
    pub max_size: u32,
    /// Gutter between charts, in texels. Default [`gutter_for_mip`]`(`[`deepest_mip`]`(2))`
    /// = 8, the [gutter rule](self) for the default `texels_per_pixel`.
    pub padding: u32,
    /// Place charts on 4×4-texel blocks (xatlas `blockAlign`: chart origins on multiples of
    /// 4 texels, extents rounded so a chart's texels end one texel before a block boundary).
    /// Default `false`: measured no gain at the [gutter rule](self)'s padding (see there).
    pub block_align: bool,
}

/// The deepest mip level a level made with `texels_per_pixel = k` texels per pixel is read
/// at in a ×2 chain: `⌈log2 k⌉ + 1` (see the [gutter rule](self)); 1 for `k ≤ 1`.
pub fn deepest_mip(texels_per_pixel: f64) -> u32 {
    let m = texels_per_pixel.log2().ceil();
    if m.is_finite() && m > 0.0 {
        m.min(16.0) as u32 + 1
    } else {
        1
    }
}

/// xatlas padding that keeps bilinear reads at mip `m` inside their chart's own texels with
/// the bake's block-owning dilation: `2^(m+1)` (the [gutter rule](self)).
pub fn gutter_for_mip(m: u32) -> u32 {
    2 * (1u32 << m.min(16))
}

impl Default for AtlasParams {
    fn default() -> Self {
        AtlasParams {
            size: None,
            texels_per_pixel: 2.0,
            min_size: 32,
            max_size: 4096,
            padding: gutter_for_mip(deepest_mip(2.0)),
            block_align: false,
        }
    }
}

impl AtlasParams {
    /// The atlas side for `lod` at screen size `n_p` with input diagonal `l` (the rule of the
    /// [module docs](self)), or the caller's size.
    pub fn side(&self, lod: &TriMesh, screen_size: f64, diagonal: f64) -> u32 {
        if let Some(s) = self.size {
            return s;
        }
        let rho = self.texels_per_pixel * screen_size / diagonal;
        let texels = lod.surface_area() * rho * rho / 0.75;
        let side = texels.sqrt().ceil().max(1.0);
        let side = if side.is_finite() && side < f64::from(1u32 << 30) {
            (side as u32).next_power_of_two()
        } else {
            self.max_size
        };
        side.clamp(self.min_size, self.max_size)
    }
}

/// A UV atlas of a mesh: the mesh's triangles re-indexed over atlas vertices, each atlas vertex
/// a copy of a mesh vertex (`xref`) with a UV; vertices are split only at chart seams.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// Side of the square atlas in texels.
    pub size: u32,
    /// Mesh vertex each atlas vertex copies.
    pub xref: Vec<u32>,
    /// UV of each atlas vertex in texels (`0 … size`, glTF orientation: v = 0 is the top row);
    /// divide by `size` for glTF texture coordinates.
    pub uv: Vec<[f32; 2]>,
    /// Triangles over atlas vertices, one per mesh triangle, in the mesh's order.
    pub triangles: Vec<[u32; 3]>,
    /// Number of charts.
    pub chart_count: u32,
    /// Texel centres covered by two triangles that share no vertex (an overlap or fold in the
    /// parameterisation): 0, or when xatlas folds a chart at every threshold tried, at most
    /// one per 2²⁰ texels (`NEGLIGIBLE_OVERLAP_PER_MEGATEXEL`) or the fewest found. See
    /// [`overlapping_texels`].
    pub overlapping_texels: u64,
    /// Gutter in texels between charts actually used: the requested padding, or less when
    /// the charts could not be packed with it (see [`build_atlas_growing`]).
    pub padding: u32,
}

/// Builds the atlas of `mesh` with side `side` (see [`AtlasParams::side`]) and `padding` texels
/// between charts. xatlas computes and parameterises the charts once; they are packed at the
/// density planned from the total chart area and the gutters (`pack_density`), and only when they
/// still do not fit one atlas is the density lowered (by 15 % steps) and the same charts
/// packed again. Deterministic: the same mesh gives the same atlas bytes.
///
/// Errors: `InvalidArgument` for a zero side; `Internal` when xatlas drops a face or produces
/// a non-finite UV.
pub fn build_atlas(mesh: &TriMesh, side: u32, padding: u32) -> Result<Atlas> {
    build_atlas_growing(mesh, side, Gutter::plain(padding), None)
}

/// The gutter of a packing: `padding` texels between charts, charts on 4×4 blocks or not
/// ([`AtlasParams::block_align`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Gutter {
    /// Texels between charts (xatlas `padding`).
    pub padding: u32,
    /// Charts on 4×4-texel blocks (xatlas `blockAlign`).
    pub block_align: bool,
}

impl Gutter {
    /// `padding` texels, no block alignment.
    pub fn plain(padding: u32) -> Self {
        Gutter {
            padding,
            block_align: false,
        }
    }

    /// The gutter of `params`.
    pub fn of(params: &AtlasParams) -> Self {
        Gutter {
            padding: params.padding,
            block_align: params.block_align,
        }
    }

    /// The same gutter with another padding.
    fn with_padding(self, padding: u32) -> Self {
        Gutter { padding, ..self }
    }

    /// Texels a chart's reservation adds to its extent along one axis, besides its own
    /// texels: the padding, one texel of extent rounding, and with block alignment up to
    /// 3 more texels of extent rounding (to `4k − 2`) plus up to 3 of position rounding.
    fn reserve(self) -> u32 {
        self.padding + 1 + if self.block_align { 3 } else { 0 }
    }
}

/// [`build_atlas`] that may grow the side so the gutters do not eat the texel density: with
/// `grow = Some((ρ, max_side))` (ρ the density rule's texels per unit length), once the
/// charts are known the side doubles, up to `max_side`, while the density planned for them
/// with their gutters (`pack_density`) is below `ρ / 2` or the gutters alone do not fit
/// (`gutters_fit`). Small atlases need it: at 64² the 15-texel gutters of a handful of charts
/// alone exceed the atlas, and a soup's LOD with thousands of charts needs it at any side
/// the rule picks. The returned [`Atlas::size`] is the side used. When the charts still do
/// not fit (no growth allowed, or the cap reached), the padding is halved until they do
/// ([`Atlas::padding`] is the one used) instead of failing.
pub fn build_atlas_growing(
    mesh: &TriMesh,
    side: u32,
    gutter: Gutter,
    grow: Option<(f64, u32)>,
) -> Result<Atlas> {
    if side == 0 {
        return Err(Error::InvalidArgument("atlas size must be > 0".into()));
    }
    let positions: Vec<f32> = mesh
        .positions()
        .iter()
        .flat_map(|p| p.map(|c| c as f32))
        .collect();
    let indices: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
    let area = mesh.surface_area().max(f64::MIN_POSITIVE);
    // Gutters are what a huge chart count cannot afford (a soup's LOD can have thousands of
    // charts): when no packing fits at the requested padding, halve it rather than fail, and
    // say so in `Atlas::padding` (the bake reports it; seams then hold to a shallower mip).
    let mut pad = gutter.padding;
    loop {
        let g = gutter.with_padding(pad);
        if let Some(a) = best_of_thresholds(&positions, &indices, area, side, g, grow)? {
            return Ok(a);
        }
        if pad == 0 {
            break;
        }
        pad /= 2;
    }
    Err(Error::Internal(format!(
        "xatlas could not pack the charts of {} triangles into one {side}² atlas, even without \
         gutters",
        mesh.triangle_count()
    )))
}

/// At most this many overlapping texels per 2²⁰ texels of the atlas end the search over chart
/// thresholds (below 1024² that is none). Each retry recomputes the charts, and xatlas's chart
/// merging is cubic in their number: on the tree soup's 5108-face level at n_p = 200 (2049
/// charts, 2048²) the thresholds 2, 1, 0.5 and 0.25 took 3.2, 13.6, 28.7 and 44.6 s to turn 3
/// overlapping texels of 4.2 million into 0 (measured 2026-12-08). One stray texel in a
/// million is below what a renderer can show; the count is still reported
/// (`BakeReport::overlapping_texels`).
const NEGLIGIBLE_OVERLAP_PER_MEGATEXEL: u64 = 1;

/// Whether `texels` overlapping texels in a `side`² atlas are negligible
/// ([`NEGLIGIBLE_OVERLAP_PER_MEGATEXEL`]).
fn negligible_overlap(texels: u64, side: u32) -> bool {
    texels << 20 <= NEGLIGIBLE_OVERLAP_PER_MEGATEXEL * u64::from(side) * u64::from(side)
}

/// The packed atlas with the fewest overlapping texels over xatlas chart thresholds (stopping
/// at the first whose overlaps are negligible, [`negligible_overlap`]); `None` when no
/// threshold's charts fit one atlas.
fn best_of_thresholds(
    positions: &[f32],
    indices: &[u32],
    area: f64,
    side: u32,
    gutter: Gutter,
    grow: Option<(f64, u32)>,
) -> Result<Option<Atlas>> {
    // xatlas (this version) can leave a chart whose LSCM boundary self-intersects; such
    // atlases are detected by rasterisation and recomputed with a lower chart-growth threshold
    // (smaller charts), keeping the one with the fewest overlaps.
    let mut best: Option<Atlas> = None;
    for threshold in [2.0f32, 1.0, 0.5, 0.25] {
        let Some(mut a) = charts_packed(positions, indices, area, side, gutter, threshold, grow)?
        else {
            continue;
        };
        a.overlapping_texels = overlapping_texels(&a);
        a.padding = gutter.padding;
        let done = negligible_overlap(a.overlapping_texels, a.size);
        if best
            .as_ref()
            .is_none_or(|b| a.overlapping_texels < b.overlapping_texels)
        {
            best = Some(a);
        }
        if done {
            break;
        }
    }
    Ok(best)
}

/// Fraction of the atlas the charts and their gutters are planned to cover (xatlas's packer
/// reaches ~0.7 on LOD charts; planning a little below leaves room for its rounding).
const PACK_FILL: f64 = 0.65;

/// Largest density factor of a retry: a retry lowers the density by at least 15 %.
const RETRY_SCALE: f64 = 0.85;

/// Share of a full atlas's utilisation a retry plans for (see [`retry_scale`]).
const RETRY_FILL: f64 = 0.9;

/// Density factor for the retry after a packing spilled over into further atlases: `spill` is
/// the summed utilisation of all atlases over that of the first (full) one, so the charts
/// need `spill` full atlases at the tried density; scaling their area by `RETRY_FILL / spill`
/// plans them into [`RETRY_FILL`] of one, at most [`RETRY_SCALE`] of the tried density.
fn retry_scale(spill: f64) -> f64 {
    if spill.is_finite() && spill > 0.0 {
        (RETRY_FILL / spill).sqrt().min(RETRY_SCALE)
    } else {
        RETRY_SCALE
    }
}

/// Texels per unit length at which `charts` charts of total surface area `area` fill
/// [`PACK_FILL`] of a `side`² atlas together with their gutters. A chart of area `a_c` at
/// density `d` covers `a_c d²` texels; its gutter (`padding` texels plus up to one of extent
/// rounding, `g = padding + 1`) adds about `4 g √(a_c) d + 4 g²` (a square chart's ring), and
/// `Σ √(a_c) ≤ √(charts · area)`. With `x = d √area` the plan is
/// `x² + 4 g √charts · x + 4 g² charts = PACK_FILL · side²`, a quadratic in `x`.
fn pack_density(area: f64, charts: u32, side: u32, gutter: Gutter) -> f64 {
    let s2 = PACK_FILL * f64::from(side) * f64::from(side);
    let g = f64::from(gutter.reserve());
    let n = f64::from(charts.max(1));
    let b = 2.0 * g * n.sqrt(); // half the linear coefficient
    let c = 4.0 * g * g * n - s2;
    // Positive root of x² + 2 b x + c = 0; when the gutters alone exceed the plan, fall back
    // to a quarter of the gutter-free density (the retries lower it further if needed).
    let x = if c < 0.0 {
        -b + (b * b - c).sqrt()
    } else {
        0.25 * s2.sqrt()
    };
    x / area.max(f64::MIN_POSITIVE).sqrt()
}

/// Whether the gutters of `charts` charts alone (`4 g² charts` texels, `g = padding + 1`, see
/// [`pack_density`]) leave room in the planned [`PACK_FILL`] of a `side`² atlas. When they do
/// not, [`pack_density`]'s fallback density says nothing about fitting, so the side must grow.
fn gutters_fit(charts: u32, side: u32, gutter: Gutter) -> bool {
    let g = f64::from(gutter.reserve());
    4.0 * g * g * f64::from(charts.max(1)) < PACK_FILL * f64::from(side) * f64::from(side)
}

/// False when `charts` charts certainly cannot share one `side`² atlas with `padding`-texel
/// gutters: xatlas reserves at least `(1 + 1 + padding)²` texels per chart (one texel of
/// extent, one of conservative rasterisation, the gutter), so the packing attempts are skipped.
fn could_fit(charts: u32, side: u32, gutter: Gutter) -> bool {
    let per_chart = (u64::from(gutter.reserve()) + 1).pow(2);
    u64::from(charts) * per_chart <= u64::from(side) * u64::from(side)
}

/// The side [`build_atlas_growing`] packs `charts` charts of total area `area` into: `side`
/// doubled while [`pack_density`] is below half the rule's density and the side is below the
/// cap.
fn grown_side(area: f64, charts: u32, side: u32, gutter: Gutter, grow: Option<(f64, u32)>) -> u32 {
    let Some((rho, max_side)) = grow else {
        return side;
    };
    let mut side = side;
    while side < max_side
        && (!gutters_fit(charts, side, gutter)
            || pack_density(area, charts, side, gutter) < 0.5 * rho)
    {
        side = side.saturating_mul(2).min(max_side);
    }
    side
}

/// The charts of one xatlas chart computation at `max_threshold`, packed into one `side`²
/// atlas: first at [`pack_density`], then at densities lowered by [`RETRY_SCALE`]; `None`
/// when no density tried fits.
fn charts_packed(
    positions: &[f32],
    indices: &[u32],
    area: f64,
    side: u32,
    gutter: Gutter,
    max_threshold: f32,
    grow: Option<(f64, u32)>,
) -> Result<Option<Atlas>> {
    let atlas = parameterised_charts(positions, indices, max_threshold)?;
    // SAFETY: `atlas` is live; ParameterizeCharts has set its chart count.
    let charts = unsafe { (*atlas.0).chart_count };
    let side = grown_side(area, charts, side, gutter, grow);
    if !could_fit(charts, side, gutter) {
        return Ok(None);
    }
    let mut density = pack_density(area, charts, side, gutter);
    for _ in 0..12 {
        match pack(&atlas, side, gutter, density as f32)? {
            Packed::One(a) => {
                check_atlas(&a, indices)?;
                return Ok(Some(a));
            }
            Packed::Spilled(spill) => {
                density *= retry_scale(spill);
            }
        }
    }
    Ok(None)
}

/// An xatlas atlas holding `positions`/`indices` with its charts computed (chart-growth
/// threshold `max_threshold`) and parameterised, ready for [`pack`].
fn parameterised_charts(
    positions: &[f32],
    indices: &[u32],
    max_threshold: f32,
) -> Result<ffi::Handle> {
    let decl = ffi::MeshDecl {
        vertex_count: (positions.len() / 3) as u32,
        vertex_position_data: positions.as_ptr().cast(),
        vertex_position_stride: 12,
        vertex_normal_data: std::ptr::null(),
        vertex_normal_stride: 0,
        vertex_uv_data: std::ptr::null(),
        vertex_uv_stride: 0,
        index_count: indices.len() as u32,
        index_data: indices.as_ptr().cast(),
        index_offset: 0,
        index_format: ffi::INDEX_FORMAT_UINT32,
        face_ignore_data: std::ptr::null(),
    };
    // SAFETY: a null print function silences xatlas's warnings on stdout; the realloc
    // function is a valid realloc (see `realloc_or_free`).
    unsafe {
        ffi::set_print(None, false);
        ffi::set_realloc(Some(realloc_or_free));
    }
    let atlas = ffi::Handle::new()?;
    // SAFETY: `atlas` is a live atlas; `decl` points into `positions` and `indices`, which
    // outlive the call (xatlas copies the mesh in AddMesh).
    let status = unsafe { ffi::add_mesh(atlas.0, &decl) };
    if status != 0 {
        return Err(Error::Internal(format!(
            "xatlas AddMesh failed with status {status}"
        )));
    }
    // SAFETY: live atlas with its mesh added, plain-data options, no callbacks; the default
    // (null) parameterisation is xatlas's LSCM.
    unsafe {
        ffi::compute_charts(
            atlas.0,
            ffi::ChartOptions {
                max_threshold,
                ..ffi::ChartOptions::default()
            },
            None,
            std::ptr::null_mut(),
        );
        ffi::parameterize_charts(atlas.0, None, None, std::ptr::null_mut());
    }
    Ok(atlas)
}

/// Outcome of one packing.
enum Packed {
    /// Every chart in one atlas.
    One(Atlas),
    /// The charts spilled over into further atlases: their summed utilisation over that of
    /// the first atlas.
    Spilled(f64),
}

/// One packing of the parameterised charts of `atlas` at `texels_per_unit`. xatlas restores the charts' parameterisation before
/// each packing, so packings of the same atlas are independent.
fn pack(atlas: &ffi::Handle, side: u32, gutter: Gutter, texels_per_unit: f32) -> Result<Packed> {
    let padding = gutter.padding;
    let pack = ffi::PackOptions {
        attempts: 4096,
        texels_per_unit,
        resolution: side,
        max_chart_size: max_chart_size(side, gutter),
        block_align: gutter.block_align,
        conservative: padding > 0,
        padding,
    };
    // SAFETY: live atlas whose charts are computed and parameterised; no callbacks.
    unsafe { ffi::pack_charts(atlas.0, pack, None, std::ptr::null_mut()) };
    // SAFETY: after PackCharts, the atlas's arrays are valid until the next PackCharts or
    // Destroy; the copy is taken before either.
    let raw = unsafe { &*atlas.0 };
    if raw.atlas_count > 1 {
        return Ok(Packed::Spilled(spill(raw)));
    }
    // SAFETY: as above.
    let out = unsafe { copy_output(raw, side) }?;
    out.map(Packed::One)
        .ok_or_else(|| Error::Internal("xatlas returned no atlas".into()))
}

/// The `maxChartSize` that keeps every chart inside a `side`² atlas. xatlas (this version)
/// scales a chart whose extent exceeds `maxChartSize` down to just below it, rounds its extent
/// `e` up to whole texels `w = ⌈e⌉ ≤ maxChartSize`, reserves a bit image of `w + 1 + padding`
/// texels for it (conservative rasterisation: half a texel each side plus the gutter) and
/// places it at `x ≤ side − (w + 1 + padding)` with UVs `x + t + 0.5`, `t ≤ e < w`. When the
/// bit image is wider than the atlas no place exists, and xatlas puts the chart at the origin
/// of an atlas anyway: its UVs reach `w + 0.5 > side` (the "half a texel outside" the check
/// in [`check_atlas`] rejected, on a long chart of a COLOR_0-only teapot). With
/// `maxChartSize = side − padding − 1` the bit image fits (`w + 1 + padding ≤ side`) and every
/// UV is below `side − padding − 0.5`. A chart that large is baked at a lower density than the
/// others rather than failing the bake.
fn max_chart_size(side: u32, gutter: Gutter) -> u32 {
    side.saturating_sub(gutter.reserve()).max(1)
}

/// Summed utilisation of all atlases of a packing over that of the first; infinite when
/// xatlas reports none.
fn spill(a: &ffi::RawAtlas) -> f64 {
    if a.utilization.is_null() || a.atlas_count == 0 {
        return f64::INFINITY;
    }
    // SAFETY: PackCharts allocates `atlas_count` utilisations.
    let u = unsafe { std::slice::from_raw_parts(a.utilization, a.atlas_count as usize) };
    u.iter().map(|&x| f64::from(x)).sum::<f64>() / f64::from(u[0])
}

/// Texel centres inside two atlas triangles that share no atlas vertex (edge-adjacent and
/// vertex-adjacent triangles may both claim a centre on their common boundary).
pub fn overlapping_texels(a: &Atlas) -> u64 {
    let n = a.size as usize;
    let mut owner = vec![u32::MAX; n * n];
    let mut count = 0;
    for (t, tri) in a.triangles.iter().enumerate() {
        let uv = tri.map(|v| a.uv[v as usize].map(f64::from));
        let area = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1])
            - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
        if area == 0.0 {
            continue;
        }
        let lo = [0, 1].map(|k| (uv[0][k].min(uv[1][k]).min(uv[2][k]).floor().max(0.0)) as usize);
        let hi =
            [0, 1].map(|k| (uv[0][k].max(uv[1][k]).max(uv[2][k]).ceil().max(0.0) as usize).min(n));
        for j in lo[1]..hi[1] {
            for i in lo[0]..hi[0] {
                let c = [i as f64 + 0.5, j as f64 + 0.5];
                let e = |p: [f64; 2], q: [f64; 2]| {
                    ((q[0] - p[0]) * (c[1] - p[1]) - (c[0] - p[0]) * (q[1] - p[1])) / area
                };
                let inside =
                    e(uv[1], uv[2]) >= 0.0 && e(uv[2], uv[0]) >= 0.0 && e(uv[0], uv[1]) >= 0.0;
                if !inside {
                    continue;
                }
                let k = j * n + i;
                let o = owner[k];
                if o == u32::MAX {
                    owner[k] = t as u32;
                } else if !a.triangles[o as usize].iter().any(|v| tri.contains(v)) {
                    count += 1;
                }
            }
        }
    }
    count
}

/// A block no chart's bilinear footprint reaches (see [`footprint_owners`]).
pub const BLOCK_FREE: u32 = u32::MAX;

/// A block the bilinear footprints of two or more charts reach (see [`footprint_owners`]).
pub const BLOCK_SHARED: u32 = u32::MAX - 1;

/// Chart of every atlas triangle: the components of triangles sharing an atlas vertex
/// (xatlas splits vertices at chart seams, so these are its charts).
pub fn triangle_charts(a: &Atlas) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..a.triangles.len() as u32).collect();
    fn root(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let mut first = vec![u32::MAX; a.uv.len()];
    for (t, tri) in a.triangles.iter().enumerate() {
        for &v in tri {
            let f = &mut first[v as usize];
            if *f == u32::MAX {
                *f = t as u32;
            } else {
                let (x, y) = (root(&mut parent, *f), root(&mut parent, t as u32));
                parent[x.max(y) as usize] = x.min(y);
            }
        }
    }
    (0..a.triangles.len() as u32)
        .map(|t| root(&mut parent, t))
        .collect()
}

/// Owner of every `2^mip × 2^mip`-texel block (a mip-`mip` texel; row-major,
/// `⌈side / 2^mip⌉` per row) of a `side`² atlas: the chart whose **bilinear footprint at mip
/// `mip`** reaches the block, [`BLOCK_FREE`] when none does, [`BLOCK_SHARED`] when several do.
/// Bilinear filtering at mip `m` of a point `s` (level-0 texel units) reads the 2×2 mip texels
/// whose centres surround it, i.e. exactly the blocks meeting the open square
/// `s ± 2^(m−1)`; a chart's footprint is its triangles grown by that square. `uv(v)` is vertex
/// `v`'s UV in texels, `chart[t]` triangle `t`'s chart. Triangles of zero UV area are
/// skipped: they cover no texel (xatlas collapses a chart whose parametric area rounds to
/// zero — a LOD sliver of ~10⁻⁶ the median face area — to one point, and reserves no space
/// for it). When no block is shared, a dilation that fills every block
/// with its owner's texels keeps every bilinear read of a chart point at mips `0 … mip` inside
/// that chart's own texels (see the [gutter rule](self)).
pub fn footprint_owners(
    side: u32,
    mip: u32,
    triangles: &[[u32; 3]],
    uv: &dyn Fn(u32) -> [f64; 2],
    chart: &[u32],
) -> Vec<u32> {
    let block = f64::from(1u32 << mip.min(16));
    let half = 0.5 * block;
    let nb = side.div_ceil(1 << mip.min(16)).max(1) as usize;
    let mut owner = vec![BLOCK_FREE; nb * nb];
    let cell = |x: f64| ((x / block).floor().max(0.0) as usize).min(nb - 1);
    for (t, tri) in triangles.iter().enumerate() {
        let p = tri.map(uv);
        let lo = [0, 1].map(|a| p[0][a].min(p[1][a]).min(p[2][a]));
        let hi = [0, 1].map(|a| p[0][a].max(p[1][a]).max(p[2][a]));
        if !(lo.iter().chain(&hi).all(|c| c.is_finite())) || uv_area(&p) == 0.0 {
            continue;
        }
        for bj in cell(lo[1] - half)..=cell(hi[1] + half) {
            for bi in cell(lo[0] - half)..=cell(hi[0] + half) {
                let sq_lo = [bi as f64 * block - half, bj as f64 * block - half];
                let sq_hi = [sq_lo[0] + 2.0 * block, sq_lo[1] + 2.0 * block];
                if !square_meets_triangle(sq_lo, sq_hi, &p) {
                    continue;
                }
                let o = &mut owner[bj * nb + bi];
                *o = match *o {
                    BLOCK_FREE => chart[t],
                    c if c == chart[t] => c,
                    _ => BLOCK_SHARED,
                };
            }
        }
    }
    owner
}

/// Twice the signed area of 2D triangle `p` (positive counter-clockwise).
pub fn uv_area(p: &[[f64; 2]; 3]) -> f64 {
    (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1])
}

/// Whether the open axis-aligned square `(lo, hi)` meets the closed triangle `p` (separating
/// axes: the square's two, the triangle's three edge normals; a degenerate triangle counts as
/// its bounding box).
fn square_meets_triangle(lo: [f64; 2], hi: [f64; 2], p: &[[f64; 2]; 3]) -> bool {
    for a in 0..2 {
        let (mn, mx) = (
            p[0][a].min(p[1][a]).min(p[2][a]),
            p[0][a].max(p[1][a]).max(p[2][a]),
        );
        if mx <= lo[a] || mn >= hi[a] {
            return false;
        }
    }
    let area = uv_area(p);
    if area == 0.0 {
        return true;
    }
    let corners = [lo, [hi[0], lo[1]], [lo[0], hi[1]], hi];
    (0..3).all(|k| {
        let (a, b) = (p[k], p[(k + 1) % 3]);
        // Positive on the triangle's side of edge a→b.
        let side = |c: [f64; 2]| {
            area.signum() * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
        };
        corners.iter().any(|&c| side(c) > 0.0)
    })
}

/// Copies xatlas's single output mesh; `None` when it produced more than one atlas.
///
/// # Safety
/// `a` must be a generated xatlas atlas with one mesh.
unsafe fn copy_output(a: &ffi::RawAtlas, side: u32) -> Result<Option<Atlas>> {
    if a.atlas_count > 1 {
        return Ok(None);
    }
    if a.mesh_count != 1 || a.meshes.is_null() {
        return Err(Error::Internal("xatlas returned no mesh".into()));
    }
    let m = &*a.meshes;
    let slice = |p: *const u32, n: u32| -> &[u32] {
        if n == 0 || p.is_null() {
            &[]
        } else {
            std::slice::from_raw_parts(p, n as usize)
        }
    };
    let verts: &[ffi::Vertex] = if m.vertex_count == 0 || m.vertex_array.is_null() {
        &[]
    } else {
        std::slice::from_raw_parts(m.vertex_array, m.vertex_count as usize)
    };
    if verts.iter().any(|v| v.atlas_index > 0) {
        return Ok(None);
    }
    let idx = slice(m.index_array, m.index_count);
    Ok(Some(Atlas {
        size: side,
        xref: verts.iter().map(|v| v.xref).collect(),
        uv: verts.iter().map(|v| v.uv).collect(),
        triangles: idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        chart_count: a.chart_count,
        overlapping_texels: 0,
        padding: 0,
    }))
}

/// Checks an atlas against the mesh it was made for: same triangles (through `xref`), every
/// vertex in one atlas with a finite UV inside it.
fn check_atlas(a: &Atlas, indices: &[u32]) -> Result<()> {
    if a.triangles.len() * 3 != indices.len() {
        return Err(Error::Internal(format!(
            "xatlas returned {} triangles for {}",
            a.triangles.len(),
            indices.len() / 3
        )));
    }
    let s = a.size as f32;
    if let Some(uv) =
        a.uv.iter()
            .find(|uv| !uv.iter().all(|c| c.is_finite() && (0.0..=s).contains(c)))
    {
        return Err(Error::Internal(format!(
            "xatlas produced UV {uv:?} outside the atlas"
        )));
    }
    for (t, tri) in a.triangles.iter().enumerate() {
        for k in 0..3 {
            if a.xref.get(tri[k] as usize).copied() != Some(indices[3 * t + k]) {
                return Err(Error::Internal(format!(
                    "xatlas reordered or dropped triangle {t}"
                )));
            }
        }
    }
    Ok(())
}

/// xatlas's allocator: it frees with `realloc(p, 0)`, which for `p = NULL` (an empty array
/// destroyed) is `malloc(0)` under glibc, a small block leaked each time (valgrind reports
/// them as definitely lost). This one frees and returns NULL for size 0.
unsafe extern "C" fn realloc_or_free(
    ptr: *mut std::ffi::c_void,
    size: usize,
) -> *mut std::ffi::c_void {
    if size == 0 {
        // SAFETY: `ptr` is NULL or a block from this allocator (libc), as xatlas guarantees.
        unsafe { libc::free(ptr) };
        return std::ptr::null_mut();
    }
    // SAFETY: as above.
    unsafe { libc::realloc(ptr, size) }
}

/// The C++ API of xatlas (the version vendored by `xatlas-rs` 0.1.3), declared here with the
/// Itanium-mangled names of its symbols: the crate's own bindings were generated on Windows
/// (MSVC-mangled names, and a `ChartOptions` field order that does not match its header), so
/// pleat uses the crate only to compile and link xatlas. Structs mirror `xatlas.h` field by
/// field; all are plain data passed as C would pass them (x86-64 SysV / AArch64 AAPCS treat
/// these C++ aggregates exactly as C structs).
mod ffi {
    use std::os::raw::{c_int, c_void};

    // Link the static library the crate builds.
    use xatlas_rs as _;

    pub const INDEX_FORMAT_UINT32: c_int = 1;

    #[repr(C)]
    pub struct MeshDecl {
        pub vertex_count: u32,
        pub vertex_position_data: *const c_void,
        pub vertex_position_stride: u32,
        pub vertex_normal_data: *const c_void,
        pub vertex_normal_stride: u32,
        pub vertex_uv_data: *const c_void,
        pub vertex_uv_stride: u32,
        pub index_count: u32,
        pub index_data: *const c_void,
        pub index_offset: i32,
        pub index_format: c_int,
        pub face_ignore_data: *const bool,
    }

    #[repr(C)]
    pub struct ChartOptions {
        pub max_chart_area: f32,
        pub max_boundary_length: f32,
        pub proxy_fit_metric_weight: f32,
        pub roundness_metric_weight: f32,
        pub straightness_metric_weight: f32,
        pub normal_seam_metric_weight: f32,
        pub texture_seam_metric_weight: f32,
        pub max_threshold: f32,
        pub grow_face_count: u32,
        pub max_iterations: u32,
    }

    impl Default for ChartOptions {
        /// xatlas's defaults (`xatlas.h`).
        fn default() -> Self {
            ChartOptions {
                max_chart_area: 0.0,
                max_boundary_length: 0.0,
                proxy_fit_metric_weight: 2.0,
                roundness_metric_weight: 0.01,
                straightness_metric_weight: 6.0,
                normal_seam_metric_weight: 4.0,
                texture_seam_metric_weight: 0.5,
                max_threshold: 2.0,
                grow_face_count: 32,
                max_iterations: 1,
            }
        }
    }

    #[repr(C)]
    pub struct PackOptions {
        pub attempts: c_int,
        pub texels_per_unit: f32,
        pub resolution: u32,
        pub max_chart_size: u32,
        pub block_align: bool,
        pub conservative: bool,
        pub padding: u32,
    }

    #[repr(C)]
    pub struct Vertex {
        pub atlas_index: i32,
        pub uv: [f32; 2],
        pub xref: u32,
    }

    #[repr(C)]
    pub struct Chart {
        pub atlas_index: u32,
        pub index_array: *const u32,
        pub index_count: u32,
    }

    #[repr(C)]
    pub struct RawMesh {
        pub chart_array: *const Chart,
        pub chart_count: u32,
        pub index_array: *const u32,
        pub index_count: u32,
        pub vertex_array: *const Vertex,
        pub vertex_count: u32,
    }

    #[repr(C)]
    pub struct RawAtlas {
        pub width: u32,
        pub height: u32,
        pub atlas_count: u32,
        pub chart_count: u32,
        pub mesh_count: u32,
        pub meshes: *const RawMesh,
        pub utilization: *const f32,
        pub texels_per_unit: f32,
    }

    type ParameterizeFunc =
        Option<unsafe extern "C" fn(*const f32, *mut f32, u32, *const u32, u32, bool)>;
    type ProgressFunc = Option<unsafe extern "C" fn(c_int, c_int, *mut c_void)>;

    extern "C" {
        #[link_name = "_ZN6xatlas8SetPrintEPFiPKczEb"]
        pub fn set_print(
            print: Option<unsafe extern "C" fn(*const std::os::raw::c_char, ...) -> c_int>,
            verbose: bool,
        );
        #[link_name = "_ZN6xatlas10SetReallocEPFPvS0_mE"]
        pub fn set_realloc(
            realloc: Option<unsafe extern "C" fn(*mut c_void, usize) -> *mut c_void>,
        );
        #[link_name = "_ZN6xatlas6CreateEv"]
        pub fn create() -> *mut RawAtlas;
        #[link_name = "_ZN6xatlas7DestroyEPNS_5AtlasE"]
        pub fn destroy(atlas: *mut RawAtlas);
        #[link_name = "_ZN6xatlas7AddMeshEPNS_5AtlasERKNS_8MeshDeclE"]
        pub fn add_mesh(atlas: *mut RawAtlas, decl: *const MeshDecl) -> c_int;
        #[link_name = "_ZN6xatlas13ComputeChartsEPNS_5AtlasENS_12ChartOptionsEPFvNS_16ProgressCategory4EnumEiPvES5_"]
        pub fn compute_charts(
            atlas: *mut RawAtlas,
            chart: ChartOptions,
            progress: ProgressFunc,
            user: *mut c_void,
        );
        #[link_name = "_ZN6xatlas18ParameterizeChartsEPNS_5AtlasEPFvPKfPfjPKjjbEPFvNS_16ProgressCategory4EnumEiPvESB_"]
        pub fn parameterize_charts(
            atlas: *mut RawAtlas,
            param: ParameterizeFunc,
            progress: ProgressFunc,
            user: *mut c_void,
        );
        #[link_name = "_ZN6xatlas10PackChartsEPNS_5AtlasENS_11PackOptionsEPFvNS_16ProgressCategory4EnumEiPvES5_"]
        pub fn pack_charts(
            atlas: *mut RawAtlas,
            pack: PackOptions,
            progress: ProgressFunc,
            user: *mut c_void,
        );
    }

    /// Owns an xatlas atlas; destroys it on drop.
    pub struct Handle(pub *mut RawAtlas);

    impl Handle {
        pub fn new() -> crate::Result<Self> {
            // SAFETY: no preconditions.
            let p = unsafe { create() };
            if p.is_null() {
                return Err(crate::Error::OutOfMemory);
            }
            Ok(Handle(p))
        }
    }

    impl Drop for Handle {
        fn drop(&mut self) {
            // SAFETY: created by `create`, destroyed once.
            unsafe { destroy(self.0) }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without gutters the plan is the charts' area alone: `A d² = PACK_FILL · side²`.
    #[test]
    fn pack_density_without_gutter_fills_the_plan() {
        let (area, side) = (3.0, 512u32);
        let d = pack_density(area, 1, side, Gutter::plain(0));
        // g = 1 even without padding (extent rounding): solve the quadratic's residual.
        let x = d * area.sqrt();
        let plan = PACK_FILL * f64::from(side * side);
        assert!((x * x + 4.0 * x + 4.0 - plan).abs() < 1e-6 * plan);
    }

    /// The planned density satisfies the gutter quadratic, falls as charts or padding grow,
    /// and stays positive when the gutters alone would overflow the plan.
    #[test]
    fn pack_density_solves_the_gutter_quadratic() {
        let (area, side, n, p) = (2.0, 1024u32, 60u32, 4u32);
        let d = pack_density(area, n, side, Gutter::plain(p));
        let (x, g, nf) = (d * area.sqrt(), f64::from(p) + 1.0, f64::from(n));
        let plan = PACK_FILL * f64::from(side * side);
        let lhs = x * x + 4.0 * g * nf.sqrt() * x + 4.0 * g * g * nf;
        assert!((lhs - plan).abs() < 1e-6 * plan, "{lhs} vs {plan}");
        assert!(pack_density(area, 2 * n, side, Gutter::plain(p)) < d);
        assert!(pack_density(area, n, side, Gutter::plain(2 * p)) < d);
        assert!(pack_density(area, 1_000_000, 64, Gutter::plain(8)) > 0.0);
    }

    /// A planar strip 40 times longer than wide is one chart whose extent at the planned
    /// density is several atlas sides: xatlas shrinks it to `maxChartSize`, and with the bound
    /// of [`max_chart_size`] every UV lands inside the atlas (before: up to `side + 0.5`,
    /// an `Internal` error).
    #[test]
    fn a_chart_longer_than_the_atlas_stays_inside_it() {
        let (n, len) = (4u32, 40.0);
        let mut p = Vec::new();
        for i in 0..=10 * n {
            for j in 0..=n {
                let x = len * f64::from(i) / f64::from(10 * n);
                p.push([x, f64::from(j) / f64::from(n), 0.0]);
            }
        }
        let mut t = Vec::new();
        let id = |i: u32, j: u32| i * (n + 1) + j;
        for i in 0..10 * n {
            for j in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let strip = TriMesh::new(p, t).unwrap();
        for (side, padding) in [(64u32, 4u32), (128, 12), (32, 0)] {
            let a = build_atlas(&strip, side, padding).unwrap();
            let hi = a.uv.iter().flatten().fold(0.0f32, |m, &c| m.max(c));
            assert!(
                hi <= (side - padding) as f32 - 0.5,
                "{side}/{padding}: UV {hi}"
            );
            assert_eq!(a.overlapping_texels, 0);
        }
        assert_eq!(max_chart_size(64, Gutter::plain(4)), 59);
        // Growth: 7 charts with 15-texel gutters cannot keep half of ρ in 64²; they can in a
        // larger side, never beyond the cap, and never without `grow`.
        let (area, rho) = (1.0, 55.0);
        let g = grown_side(area, 7, 64, Gutter::plain(15), Some((rho, 4096)));
        assert!(g > 64 && pack_density(area, 7, g, Gutter::plain(15)) >= 0.5 * rho);
        assert!(pack_density(area, 7, g / 2, Gutter::plain(15)) < 0.5 * rho);
        assert_eq!(
            grown_side(area, 7, 64, Gutter::plain(15), Some((rho, 64))),
            64
        );
        assert_eq!(grown_side(area, 7, 64, Gutter::plain(15), None), 64);
        assert_eq!(max_chart_size(4, Gutter::plain(8)), 1);
    }

    /// `n` disjoint unit squares (two triangles each) in a row: `n` charts.
    fn squares(n: u32) -> TriMesh {
        let mut p = Vec::new();
        let mut t = Vec::new();
        for i in 0..n {
            let x = 2.0 * f64::from(i);
            let b = 4 * i;
            p.extend([
                [x, 0.0, 0.0],
                [x + 1.0, 0.0, 0.0],
                [x + 1.0, 1.0, 0.0],
                [x, 1.0, 0.0],
            ]);
            t.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        }
        TriMesh::new(p, t).unwrap()
    }

    /// A soup's LOD can have thousands of charts whose 15-texel gutters alone exceed the atlas
    /// the texel rule picks (the 6036-face LOD of `gen_tree_soup_sin` at n_p = 200 failed with
    /// "xatlas could not pack the charts … into one 512² atlas"): the side grows until the
    /// gutters fit, and without growth the padding shrinks instead of failing.
    #[test]
    fn thousands_of_charts_grow_the_side_or_shrink_the_gutter() {
        assert!(!gutters_fit(150, 64, Gutter::plain(15)));
        assert!(gutters_fit(150, 512, Gutter::plain(15)));
        let g = grown_side(150.0, 150, 64, Gutter::plain(15), Some((1.0, 4096)));
        assert!(
            g >= 512 && gutters_fit(150, g, Gutter::plain(15)),
            "grew to {g}"
        );
        assert!(!could_fit(150, 64, Gutter::plain(15)) && could_fit(150, 64, Gutter::plain(3)));
        let mesh = squares(150);
        let grown = build_atlas_growing(&mesh, 64, Gutter::plain(15), Some((1.0, 4096))).unwrap();
        assert_eq!(grown.padding, 15);
        assert!(grown.size >= 512);
        assert_eq!(grown.overlapping_texels, 0);
        let fixed = build_atlas(&mesh, 64, 15).unwrap();
        assert_eq!(fixed.size, 64);
        assert!(fixed.padding < 15, "padding {}", fixed.padding);
        assert_eq!(fixed.overlapping_texels, 0);
        let hi = fixed.uv.iter().flatten().fold(0.0f32, |m, &c| m.max(c));
        assert!(hi <= 64.0, "UV {hi}");
        // A few charts keep the requested gutter.
        assert_eq!(build_atlas(&squares(3), 128, 15).unwrap().padding, 15);
    }

    /// The footprint rule: two charts whose points are more than `2B = gutter_for_mip(m)`
    /// apart along an axis never reach a common block, at any offset against the block grid;
    /// closer than that, some offset makes them share one.
    #[test]
    fn charts_more_than_two_blocks_apart_own_their_blocks() {
        let m = 2;
        let gap = f64::from(gutter_for_mip(m));
        let shared_at = |offset: f64, gap: f64| {
            // Chart 0: a 3-texel right triangle at x = offset; chart 1: the same `gap` to its right.
            let x1 = offset + 3.0 + gap;
            let p = [
                [offset, 10.0],
                [offset + 3.0, 10.0],
                [offset + 3.0, 13.0],
                [x1, 10.0],
                [x1 + 3.0, 10.0],
                [x1, 13.0],
            ];
            let tris = [[0, 1, 2], [3, 4, 5]];
            let owners = footprint_owners(64, m, &tris, &|v| p[v as usize], &[0, 1]);
            assert!(owners.contains(&0) && owners.contains(&1));
            owners.contains(&BLOCK_SHARED)
        };
        for k in 0..32 {
            let offset = 8.0 + f64::from(k) / 8.0;
            assert!(!shared_at(offset, gap + 1e-3), "offset {offset}");
        }
        assert!((0..32).any(|k| shared_at(8.0 + f64::from(k) / 8.0, gap - 0.5)));
        // A point just below a block centre (18, 18) reads that block and the ones left/above.
        let tiny = [[17.99, 17.99], [18.0, 17.99], [17.99, 18.0]];
        let owners = footprint_owners(64, m, &[[0, 1, 2]], &|v| tiny[v as usize], &[7]);
        let owned: Vec<usize> = (0..owners.len()).filter(|&k| owners[k] == 7).collect();
        assert_eq!(owned, vec![3 * 16 + 3, 3 * 16 + 4, 4 * 16 + 3, 4 * 16 + 4]);
    }

    /// Separating axes: a triangle's bounding box overlapping the square is not enough.
    #[test]
    fn square_meets_triangle_by_separating_axes() {
        let t = [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]];
        assert!(square_meets_triangle([1.0, 1.0], [2.0, 2.0], &t));
        assert!(!square_meets_triangle([3.0, 3.0], [4.0, 4.0], &t));
        assert!(!square_meets_triangle([4.0, 0.0], [5.0, 1.0], &t));
        assert!(square_meets_triangle([-1.0, -1.0], [0.5, 0.5], &t));
    }

    /// The gutter rule: mip 2 for the default 2 texels per pixel, 8 texels of padding.
    #[test]
    fn the_default_gutter_follows_the_mip_rule() {
        assert_eq!(deepest_mip(2.0), 2);
        assert_eq!(deepest_mip(1.0), 1);
        assert_eq!(deepest_mip(4.0), 3);
        assert_eq!(deepest_mip(f64::NAN), 1);
        assert_eq!(gutter_for_mip(1), 4);
        assert_eq!(gutter_for_mip(2), 8);
        assert_eq!(AtlasParams::default().padding, 8);
    }

    /// A retry plans the spilled charts into `RETRY_FILL` of one atlas, lowers the density by
    /// at least `1 - RETRY_SCALE`, and falls back to that step when xatlas reports nothing.
    #[test]
    fn retry_scale_plans_the_spill_into_one_atlas() {
        assert!((retry_scale(2.0) - (RETRY_FILL / 2.0).sqrt()).abs() < 1e-12);
        assert_eq!(retry_scale(1.01), RETRY_SCALE);
        assert_eq!(retry_scale(f64::INFINITY), RETRY_SCALE);
        assert_eq!(retry_scale(f64::NAN), RETRY_SCALE);
    }
}
