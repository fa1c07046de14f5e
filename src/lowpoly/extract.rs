//! Extraction of the `d`-iso-surface from the narrow band: MC33 patches per cube, iso-points
//! shared through global edge keys, feature vertices per disk patch (Algorithm 1, lines 3–10).
//!
//! Iso-points: on a crossed grid edge with values `f_in < d ≤ f_out`, the point sits at the
//! linear-interpolation parameter clamped into `[ε, 1 − ε]` (`ε = 10⁻³`), so it is strictly
//! inside the edge even when a grid value equals `d` exactly (which counts as outside). It is a
//! function of the edge's two values only, computed once per edge, so every cube sharing the
//! edge uses the bit-identical point. Optionally it is refined against the true distance by a
//! few regula-falsi (Illinois) steps inside the same bracket.
//!
//! Determinism: bricks are visited in sorted key order, cubes in a fixed order inside a brick,
//! edge keys are sorted before vertex ids are assigned, and parallel results are concatenated
//! in brick order.
//!
//! Memory layout (what is alive when): pass 1 reads the distance grid and records the sorted
//! keys of the crossed grid edges (8 B each) and every mixed cube's MC33 [`Decisions`] packed
//! with its index in its brick ([`MixedCubes`], 8 B per cube). The iso-points are computed from
//! the grid — positions (24 B) directly into [`PatchSet::positions`], normal and closest input
//! primitive ([`IsoNormal`], 32 B) beside them — and the grid is dropped before pass 2, which
//! builds the patches from the packed decisions alone. Since every cube reads the same stored
//! corner values in pass 1, cubes sharing a face agree on its decisions. Keys, cubes and
//! normals are dropped when pass 2 ends. Only crease candidates (normal spread at least
//! [`ExtractParams::feature_min_spread_deg`]) get a feature vertex, so extra vertices are
//! few.

use rayon::prelude::*;

use super::distance::{brick_coords, brick_key, DistanceGrid, GridSpec, InputDistance, BRICK};
use super::features::{cube_geometry, CubeFlags};
use super::mc33::tables::{CORNER_POS, EDGE_AXIS, EDGE_CORNERS};
use super::mc33::triangulate::{fan, LocalTri};
use super::mc33::{decide, topology, CubeTopology, Decisions};
use crate::geom::{lerp, normalized, Vec3};
use crate::{Error, Result};

/// Clamp of the iso-point parameter away from grid points.
pub(crate) const ISO_EPS: f64 = 1e-3;
/// "No vertex".
pub(crate) const NONE: u32 = u32::MAX;

/// Global key of the grid edge from point `p` along `axis` (points `< 2^20` per axis).
#[inline]
pub(crate) fn edge_key(p: [u32; 3], axis: u8) -> u64 {
    ((((p[0] as u64) << 42) | ((p[1] as u64) << 21) | p[2] as u64) << 2) | axis as u64
}

#[inline]
fn edge_from_key(k: u64) -> ([u32; 3], u8) {
    let m = (1u64 << 21) - 1;
    let p = k >> 2;
    (
        [(p >> 42) as u32, ((p >> 21) & m) as u32, (p & m) as u32],
        (k & 3) as u8,
    )
}

/// Settings of one extraction.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ExtractParams {
    /// Iso-value.
    pub d: f64,
    /// Compute feature vertices (eq. 4.3).
    pub features: bool,
    /// Only disk patches whose iso-point normals spread at least this much (degrees) get a
    /// feature vertex (0: every disk patch).
    pub feature_min_spread_deg: f32,
    /// Regula-falsi steps refining each iso-point against the exact distance (0 = off).
    pub refine_steps: u32,
}

/// All patches of the iso-surface, before choosing feature or template triangulations.
#[derive(Debug, Clone, Default)]
pub(crate) struct PatchSet {
    /// Iso-points (ids `0..n_iso`), then feature and center vertices.
    pub positions: Vec<Vec3>,
    /// Number of iso-points.
    pub n_iso: usize,
    /// Per patch `p`, its loop vertex ids are `loop_ids[loop_off[p]..loop_off[p + 1]]`.
    pub loop_off: Vec<u32>,
    /// Loop vertex ids of all patches.
    pub loop_ids: Vec<u32>,
    /// Length of the first loop (less than the patch's id count for an annulus).
    pub first_len: Vec<u8>,
    /// Per patch, its template triangles are `plain[plain_off[p]..plain_off[p + 1]]`.
    pub plain_off: Vec<u32>,
    /// Template triangles (local indices; the patch's id count means its center).
    pub plain: Vec<LocalTri>,
    /// Center vertex of the template, or [`NONE`].
    pub center: Vec<u32>,
    /// Feature vertex, or [`NONE`].
    pub feature: Vec<u32>,
    /// Patch of each extra vertex (id `n_iso + i`), [`NONE`] for centers.
    pub feature_patch: Vec<u32>,
    /// Counters.
    pub counts: ExtractCounts,
}

/// Counters of an extraction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct ExtractCounts {
    /// Cubes examined.
    pub cells: u64,
    /// Cubes with corners on both sides.
    pub mixed: u64,
    /// Disk patches.
    pub disks: u64,
    /// Annulus (tunnel) patches.
    pub annuli: u64,
    /// Tunnels replaced by two disks.
    pub tunnels_split: u64,
    /// Cubes whose patches had no separating plane.
    pub unseparated: u64,
    /// Cubes that failed their exact check.
    pub unresolved: u64,
    /// Iso-points whose normal fell back to the edge direction (no usable closest point).
    pub gradient_normals: u64,
}

impl ExtractCounts {
    fn add(&mut self, o: &ExtractCounts) {
        self.cells += o.cells;
        self.mixed += o.mixed;
        self.disks += o.disks;
        self.annuli += o.annuli;
        self.tunnels_split += o.tunnels_split;
        self.unseparated += o.unseparated;
        self.unresolved += o.unresolved;
        self.gradient_normals += o.gradient_normals;
    }

    fn add_flags(&mut self, f: &CubeFlags) {
        self.tunnels_split += f.tunnel_split as u64;
        self.unseparated += f.unseparated as u64;
        self.unresolved += f.unresolved as u64;
    }
}

impl PatchSet {
    /// Components of the surface, per patch (patches are connected through shared
    /// iso-points), numbered from 0 by their first patch; and the count.
    pub(crate) fn patch_components(&self) -> (Vec<u32>, usize) {
        let mut parent: Vec<u32> = (0..self.n_iso as u32).collect();
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                p[x as usize] = p[p[x as usize] as usize];
                x = p[x as usize];
            }
            x
        }
        for p in 0..self.len() {
            let ids = self.ids(p);
            for &v in &ids[1..] {
                let (a, b) = (find(&mut parent, ids[0]), find(&mut parent, v));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
        let mut label = vec![NONE; self.n_iso];
        let mut n = 0usize;
        let comp = (0..self.len())
            .map(|p| {
                let r = find(&mut parent, self.ids(p)[0]) as usize;
                if label[r] == NONE {
                    label[r] = n as u32;
                    n += 1;
                }
                label[r]
            })
            .collect();
        (comp, n)
    }

    /// The patch whose feature vertex is `id`, if `id` is one.
    pub(crate) fn patch_of_feature(&self, id: u32) -> Option<usize> {
        let i = (id as usize).checked_sub(self.n_iso)?;
        self.feature_patch
            .get(i)
            .filter(|&&p| p != NONE)
            .map(|&p| p as usize)
    }

    /// Number of patches.
    pub(crate) fn len(&self) -> usize {
        self.first_len.len()
    }

    /// Vertex ids of patch `p` (both loops for an annulus).
    pub(crate) fn ids(&self, p: usize) -> &[u32] {
        &self.loop_ids[self.loop_off[p] as usize..self.loop_off[p + 1] as usize]
    }

    /// Template triangles of patch `p`.
    fn plain_tris(&self, p: usize) -> &[LocalTri] {
        &self.plain[self.plain_off[p] as usize..self.plain_off[p + 1] as usize]
    }

    /// Triangles of patch `p`, with its feature vertex when `use_feature` and it has one.
    pub(crate) fn patch_triangles(&self, p: usize, use_feature: bool, out: &mut Vec<[u32; 3]>) {
        let ids = self.ids(p);
        let n = ids.len();
        let map = |i: u8, extra: u32| {
            if (i as usize) < n {
                ids[i as usize]
            } else {
                extra
            }
        };
        if use_feature && self.feature[p] != NONE {
            let mut buf = Vec::with_capacity(n);
            fan(n, &mut buf);
            out.extend(buf.iter().map(|t| t.map(|i| map(i, self.feature[p]))));
        } else {
            let c = self.center[p];
            out.extend(self.plain_tris(p).iter().map(|t| t.map(|i| map(i, c))));
        }
    }

    /// The mesh of the patches as `mode` says: compacted positions, triangles, and for each
    /// output vertex its id in [`PatchSet::positions`].
    pub(crate) fn assemble(
        &self,
        mode: &dyn Fn(usize) -> Mode,
    ) -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<u32>) {
        let mut tris = Vec::new();
        for p in 0..self.len() {
            match mode(p) {
                Mode::Skip => {}
                Mode::Template => self.patch_triangles(p, false, &mut tris),
                Mode::Feature => self.patch_triangles(p, true, &mut tris),
            }
        }
        let mut remap = vec![NONE; self.positions.len()];
        let mut back = Vec::new();
        for t in &mut tris {
            for v in t.iter_mut() {
                if remap[*v as usize] == NONE {
                    remap[*v as usize] = back.len() as u32;
                    back.push(*v);
                }
                *v = remap[*v as usize];
            }
        }
        let pos = back
            .iter()
            .map(|&v| self.positions[v as usize].to_array())
            .collect();
        (pos, tris, back)
    }
}

/// How a patch enters an assembled mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Left out (an invisible component).
    Skip,
    /// MC33 template triangulation.
    Template,
    /// Fan around the feature vertex (the template when it has none).
    Feature,
}

/// Eight corner values of the cube at `p` through a brick's neighbourhood.
struct BrickView<'a> {
    base: [u32; 3],
    nb: [Option<&'a [f64]>; 8],
    cap: f64,
}

impl<'a> BrickView<'a> {
    fn new(grid: &'a DistanceGrid, key: u64) -> BrickView<'a> {
        let b = brick_coords(key);
        let nb = std::array::from_fn(|i| {
            let c = CORNER_POS[i];
            let k = brick_key([b[0] + c[0] as u32, b[1] + c[1] as u32, b[2] + c[2] as u32]);
            grid.brick_index(k).map(|bi| grid.brick_values(bi))
        });
        BrickView {
            base: b.map(|x| x * BRICK),
            nb,
            cap: grid.cap,
        }
    }

    /// Value at local point `q ∈ [0, 8]³` of this brick.
    #[inline]
    fn value(&self, q: [u32; 3]) -> f64 {
        let s = (q[0] / BRICK) as usize
            | ((q[1] / BRICK) as usize) << 1
            | ((q[2] / BRICK) as usize) << 2;
        match self.nb[s] {
            Some(v) => {
                v[((q[2] % BRICK) * BRICK * BRICK + (q[1] % BRICK) * BRICK + q[0] % BRICK) as usize]
            }
            None => self.cap,
        }
    }

    /// Corner values `f − d` of the cube with local min corner `q`.
    fn cube(&self, q: [u32; 3], d: f64) -> [f64; 8] {
        std::array::from_fn(|c| {
            let o = CORNER_POS[c];
            self.value([q[0] + o[0] as u32, q[1] + o[1] as u32, q[2] + o[2] as u32]) - d
        })
    }
}

/// Calls `f(global min corner, values)` for every mixed cube of brick `key`; returns the
/// number of cubes examined.
fn for_mixed_cubes(
    grid: &DistanceGrid,
    key: u64,
    d: f64,
    mut f: impl FnMut([u32; 3], &[f64; 8]),
) -> u64 {
    let view = BrickView::new(grid, key);
    let dims = grid.spec.dims;
    let mut cells = 0;
    for z in 0..BRICK {
        for y in 0..BRICK {
            for x in 0..BRICK {
                let g = [view.base[0] + x, view.base[1] + y, view.base[2] + z];
                if g[0] + 1 >= dims[0] || g[1] + 1 >= dims[1] || g[2] + 1 >= dims[2] {
                    continue;
                }
                cells += 1;
                let v = view.cube([x, y, z], d);
                let inside = v.iter().filter(|&&x| x < 0.0).count();
                if inside != 0 && inside != 8 {
                    f(g, &v);
                }
            }
        }
    }
    cells
}

/// Global key of cube edge `e` of the cube at `g`.
#[inline]
fn cube_edge_key(g: [u32; 3], e: usize) -> u64 {
    let c = CORNER_POS[EDGE_CORNERS[e][0] as usize];
    edge_key(
        [g[0] + c[0] as u32, g[1] + c[1] as u32, g[2] + c[2] as u32],
        EDGE_AXIS[e],
    )
}

/// What pass 1 of the extraction counts before anything proportional to the surface is
/// allocated (pass 1 holds 8 B per crossed edge and per mixed cube): the figures the offset
/// stage's measured admission (`offset::Admit`) decides from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Crossings {
    /// Cubes with corners on both sides of the iso-value (over the whole band, buried
    /// components included: interior removal comes later).
    pub mixed_cubes: u64,
    /// Crossed grid edges, i.e. iso-points.
    pub iso_points: u64,
    /// Bytes of the distance grid, alive until the iso-points are computed.
    pub grid_bytes: u64,
}

/// Runs the extraction, consuming the grid (it is dropped as soon as the iso-points are
/// known: pass 2 works from the decisions recorded in pass 1). After pass 1, `admit` is told
/// the [`Crossings`]; its `Err` ends the extraction there, before the iso-points, normals and
/// patches are allocated. `keep_going(fraction)` is called on this thread between chunks.
pub(crate) fn extract(
    grid: DistanceGrid,
    input: &InputDistance,
    p: &ExtractParams,
    admit: &mut dyn FnMut(Crossings) -> Result<()>,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<PatchSet> {
    let mut counts = ExtractCounts::default();
    let chunk = 512;
    let (keys, mixed) = crossed_edges(&grid, p.d, chunk, &mut counts, keep_going)?;
    admit(Crossings {
        mixed_cubes: counts.mixed,
        iso_points: keys.len() as u64,
        grid_bytes: grid.memory_bytes(),
    })?;
    // Iso-points and their normals (eq. 4.3).
    let (iso_pos, iso): (Vec<Vec3>, Vec<IsoNormal>) = keys
        .par_iter()
        .map(|&k| iso_point(&grid, input, k, p))
        .unzip();
    counts.gradient_normals = iso.iter().filter(|x| x.fallback).count() as u64;
    let (spec, cap) = (grid.spec, grid.cap);
    drop(grid);
    if !keep_going(0.5) {
        return Err(Error::Cancelled);
    }
    // Pass 2: patches. Feature and center vertices collect in `extra` (ids from `n_iso`).
    let mut set = PatchSet {
        n_iso: keys.len(),
        loop_off: vec![0],
        plain_off: vec![0],
        ..PatchSet::default()
    };
    let mut extra = Vec::new();
    let ctx = CubeCtx {
        spec,
        cap,
        input,
        keys: &keys,
        iso_pos: &iso_pos,
        iso: &iso,
        p,
    };
    let n_bricks = mixed.bricks.len();
    let n_chunks = n_bricks.div_ceil(chunk).max(1);
    for ci in 0..n_chunks {
        let part: Vec<BrickPatches> = (ci * chunk..((ci + 1) * chunk).min(n_bricks))
            .into_par_iter()
            .map(|b| {
                let (key, cubes) = mixed.brick(b);
                brick_patches(&ctx, key, cubes)
            })
            .collect();
        for bp in part {
            append(&mut set, &mut extra, bp);
        }
        if !keep_going(0.5 + 0.5 * (ci + 1) as f64 / n_chunks as f64) {
            return Err(Error::Cancelled);
        }
    }
    drop((iso, mixed, keys));
    set.positions = iso_pos;
    set.positions.extend(extra);
    set.counts.add(&counts);
    set.feature_patch = vec![NONE; set.positions.len() - set.n_iso];
    for (p, &f) in set.feature.iter().enumerate() {
        if f != NONE {
            set.feature_patch[f as usize - set.n_iso] = p as u32;
        }
    }
    Ok(set)
}

/// The mixed cubes found by pass 1, packed (8 bytes per cube): what pass 2 needs once the
/// distance grid is gone.
#[derive(Debug, Default)]
struct MixedCubes {
    /// Per cube: its [`Decisions::pack`] shifted left by 9, or'ed with its index inside its
    /// brick (`x | y << 3 | z << 6`). Grouped by brick, bricks in sorted key order, cubes in
    /// the order [`for_mixed_cubes`] visits them.
    cubes: Vec<u64>,
    /// Per brick with mixed cubes: its key and the end of its cubes in `cubes`.
    bricks: Vec<(u64, u32)>,
}

/// Bits of a cube's index inside its brick.
const LOCAL_BITS: u32 = 9;
const _: () = assert!(LOCAL_BITS + Decisions::PACKED_BITS <= 64);

impl MixedCubes {
    /// The cubes of brick `i`: its key and its packed cubes.
    fn brick(&self, i: usize) -> (u64, &[u64]) {
        let start = if i == 0 { 0 } else { self.bricks[i - 1].1 };
        let (key, end) = self.bricks[i];
        (key, &self.cubes[start as usize..end as usize])
    }

    /// Global min corner and decisions of a packed cube of the brick at `base` (its min point).
    fn unpack(base: [u32; 3], c: u64) -> ([u32; 3], Decisions) {
        let l = (c & ((1 << LOCAL_BITS) - 1)) as u32;
        let g = [
            base[0] + (l & 7),
            base[1] + (l >> 3 & 7),
            base[2] + (l >> 6),
        ];
        (g, Decisions::unpack(c >> LOCAL_BITS))
    }
}

/// Packs a mixed cube (global min corner `g`, decisions `dec`) for [`MixedCubes::cubes`].
fn pack_cube(g: [u32; 3], dec: &Decisions) -> u64 {
    let l = (g[0] % BRICK) | (g[1] % BRICK) << 3 | (g[2] % BRICK) << 6;
    dec.pack() << LOCAL_BITS | l as u64
}

/// Pass 1: sorted keys of the crossed grid edges (each once) and the mixed cubes.
fn crossed_edges(
    grid: &DistanceGrid,
    d: f64,
    chunk: usize,
    counts: &mut ExtractCounts,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Result<(Vec<u64>, MixedCubes)> {
    let mut keys: Vec<u64> = Vec::new();
    let mut mixed = MixedCubes::default();
    let n_chunks = grid.keys.len().div_ceil(chunk).max(1);
    for (ci, ks) in grid.keys.chunks(chunk).enumerate() {
        let part: Vec<(Vec<u64>, Vec<u64>, u64)> = ks
            .par_iter()
            .map(|&k| {
                let mut out = Vec::new();
                let mut cubes = Vec::new();
                let cells = for_mixed_cubes(grid, k, d, |g, v| {
                    cubes.push(pack_cube(g, &decide(v)));
                    // Each grid edge is edge 0, 4 or 8 (leaving corner 0) of exactly one cube:
                    // emit it from there only, so every key appears once.
                    for e in [0usize, 4, 8] {
                        let ec = EDGE_CORNERS[e];
                        if (v[ec[0] as usize] < 0.0) != (v[ec[1] as usize] < 0.0) {
                            out.push(cube_edge_key(g, e));
                        }
                    }
                });
                (out, cubes, cells)
            })
            .collect();
        for (&k, (o, m, c)) in ks.iter().zip(part) {
            keys.extend(o);
            counts.cells += c;
            counts.mixed += m.len() as u64;
            if !m.is_empty() {
                mixed.cubes.extend(m);
                mixed.bricks.push((k, mixed.cubes.len() as u32));
            }
        }
        if !keep_going(0.3 * (ci + 1) as f64 / n_chunks as f64) {
            return Err(Error::Cancelled);
        }
    }
    keys.par_sort_unstable();
    mixed.cubes.shrink_to_fit();
    Ok((keys, mixed))
}

/// What pass 2 needs of an iso-point besides its position (kept apart: positions go straight
/// into [`PatchSet::positions`]).
#[derive(Debug, Clone, Copy)]
struct IsoNormal {
    /// Unit normal `(p − p*)/‖p − p*‖` (eq. 4.3), or the direction of increasing `f` along
    /// the edge when there is no usable closest point (`fallback`).
    normal: Vec3,
    /// Input primitive of the closest point (`u32::MAX` when unknown).
    prim: u32,
    /// The normal is the edge-direction fallback.
    fallback: bool,
}

/// The iso-point of edge `k` with its normal.
fn iso_point(
    grid: &DistanceGrid,
    input: &InputDistance,
    k: u64,
    p: &ExtractParams,
) -> (Vec3, IsoNormal) {
    let (g, a) = edge_from_key(k);
    let mut g1 = g;
    g1[a as usize] += 1;
    let (f0, f1) = (grid.value(g), grid.value(g1));
    let (x0, x1) = (grid.spec.point(g), grid.spec.point(g1));
    let mut t = iso_parameter(f0, f1, p.d);
    if p.refine_steps > 0 {
        t = refine(input, x0, x1, f0, f1, t, p, grid.cap);
    }
    let t = t.clamp(ISO_EPS, 1.0 - ISO_EPS);
    let x = lerp(x0, x1, t);
    let mut prim = u32::MAX;
    if p.features {
        if let Some(c) = input.closest(x, grid.cap * 2.0) {
            prim = c.prim;
            if let Some(normal) = normalized(x - c.point) {
                let n = IsoNormal {
                    normal,
                    prim,
                    fallback: false,
                };
                return (x, n);
            }
        }
    }
    // The direction of increasing f along the edge is a usable fallback normal.
    let mut normal = Vec3::ZERO;
    normal[a as usize] = if f1 > f0 { 1.0 } else { -1.0 };
    let n = IsoNormal {
        normal,
        prim,
        fallback: p.features,
    };
    (x, n)
}

/// Linear-interpolation parameter of `d` between `f0` and `f1` (which straddle `d`).
#[inline]
pub(crate) fn iso_parameter(f0: f64, f1: f64, d: f64) -> f64 {
    let den = f1 - f0;
    if den == 0.0 {
        return 0.5;
    }
    ((d - f0) / den).clamp(0.0, 1.0)
}

/// Illinois regula falsi on `g(t) = f(x0 + t(x1 − x0)) − d` inside `[0, 1]`.
#[allow(clippy::too_many_arguments)]
fn refine(
    input: &InputDistance,
    x0: Vec3,
    x1: Vec3,
    f0: f64,
    f1: f64,
    t0: f64,
    p: &ExtractParams,
    cap: f64,
) -> f64 {
    let (mut a, mut b) = (0.0, 1.0);
    let (mut ga, mut gb) = (f0 - p.d, f1 - p.d);
    if ga * gb > 0.0 {
        return t0;
    }
    let mut t = t0;
    let mut side = 0i8;
    for _ in 0..p.refine_steps {
        let gt = input.distance_capped(lerp(x0, x1, t), cap) - p.d;
        if gt == 0.0 {
            return t;
        }
        if (gt < 0.0) == (ga < 0.0) {
            a = t;
            ga = gt;
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        } else {
            b = t;
            gb = gt;
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        }
        let den = gb - ga;
        t = if den != 0.0 {
            (a * gb - b * ga) / den
        } else {
            0.5 * (a + b)
        };
        if !(t > a && t < b) {
            t = 0.5 * (a + b);
        }
    }
    t
}

struct CubeCtx<'a> {
    spec: GridSpec,
    cap: f64,
    input: &'a InputDistance,
    keys: &'a [u64],
    iso_pos: &'a [Vec3],
    iso: &'a [IsoNormal],
    p: &'a ExtractParams,
}

/// Patches of one brick, with brick-local extra vertices.
#[derive(Default)]
struct BrickPatches {
    loop_ids: Vec<u32>,
    loop_len: Vec<u32>,
    first_len: Vec<u8>,
    plain: Vec<LocalTri>,
    plain_len: Vec<u32>,
    extra: Vec<Vec3>,
    center: Vec<u32>,
    feature: Vec<u32>,
    counts: ExtractCounts,
}

fn brick_patches(ctx: &CubeCtx, key: u64, cubes: &[u64]) -> BrickPatches {
    let mut out = BrickPatches::default();
    let base = brick_coords(key).map(|b| b * BRICK);
    for &c in cubes {
        let (g, dec) = MixedCubes::unpack(base, c);
        let topo = topology(&dec);
        cube_patches(ctx, g, dec.inside, &topo, &mut out);
    }
    out
}

fn cube_patches(
    ctx: &CubeCtx,
    g: [u32; 3],
    inside: u8,
    topo: &CubeTopology,
    out: &mut BrickPatches,
) {
    let h = ctx.spec.h;
    let d = ctx.p.d;
    let origin = ctx.spec.point(g);
    let mut ids = [NONE; 12];
    let mut local = [Vec3::ZERO; 12];
    let mut normals = [Vec3::ZERO; 12];
    let mut hint = None;
    for e in 0..12 {
        let ec = EDGE_CORNERS[e];
        if (inside >> ec[0] & 1) == (inside >> ec[1] & 1) {
            continue;
        }
        let Ok(i) = ctx.keys.binary_search(&cube_edge_key(g, e)) else {
            continue;
        };
        ids[e] = i as u32;
        let ip = ctx.iso[i];
        local[e] = (ctx.iso_pos[i] - origin) * (1.0 / h);
        normals[e] = ip.normal;
        if ip.prim != u32::MAX {
            hint = Some(ip.prim);
        }
    }
    let normals = ctx.p.features.then_some(&normals);
    let project = |x: Vec3| -> Option<Vec3> {
        let w = Vec3::new(
            origin[0] + h * x[0],
            origin[1] + h * x[1],
            origin[2] + h * x[2],
        );
        let c = ctx.input.closest_hinted(w, 2.0 * ctx.cap, hint)?;
        let n = normalized(w - c.point)?;
        let y = lerp(c.point, c.point + n, d);
        Some((y - origin) * (1.0 / h))
    };
    let (patches, flags) = cube_geometry(
        topo,
        &local,
        normals,
        ctx.p.feature_min_spread_deg,
        Some(&project),
    );
    out.counts.add_flags(&flags);
    let world = |x: Vec3| {
        Vec3::new(
            origin[0] + h * x[0],
            origin[1] + h * x[1],
            origin[2] + h * x[2],
        )
    };
    for pg in patches {
        if pg.is_annulus() {
            out.counts.annuli += 1;
        } else {
            out.counts.disks += 1;
        }
        out.loop_ids
            .extend(pg.edges.iter().map(|&e| ids[e as usize]));
        out.loop_len.push(pg.edges.len() as u32);
        out.first_len.push(pg.first_len as u8);
        out.plain.extend_from_slice(&pg.plain);
        out.plain_len.push(pg.plain.len() as u32);
        let mut push_extra = |x: Option<Vec3>| match x {
            Some(x) => {
                out.extra.push(world(x));
                (out.extra.len() - 1) as u32
            }
            None => NONE,
        };
        let c = push_extra(pg.center);
        let f = push_extra(pg.feature);
        out.center.push(c);
        out.feature.push(f);
    }
}

/// Appends one brick's patches; its extra vertices go to `extra` (ids from `set.n_iso`).
fn append(set: &mut PatchSet, extra: &mut Vec<Vec3>, bp: BrickPatches) {
    let base = (set.n_iso + extra.len()) as u32;
    extra.extend(bp.extra);
    let shift = |x: u32| if x == NONE { NONE } else { base + x };
    set.center.extend(bp.center.into_iter().map(shift));
    set.feature.extend(bp.feature.into_iter().map(shift));
    set.loop_ids.extend(bp.loop_ids);
    for l in bp.loop_len {
        let last = *set.loop_off.last().unwrap_or(&0);
        set.loop_off.push(last + l);
    }
    set.first_len.extend(bp.first_len);
    set.plain.extend(bp.plain);
    for l in bp.plain_len {
        let last = *set.plain_off.last().unwrap_or(&0);
        set.plain_off.push(last + l);
    }
    set.counts.add(&bp.counts);
}

/// Distance from `x` to the input, for reporting (`max |f(x) − d|`).
pub(crate) fn deviation(input: &InputDistance, x: Vec3, d: f64, cap: f64) -> f64 {
    (input.distance_capped(x, cap) - d).abs()
}
