//! Marching Cubes 33 topology for the `d`-iso-surface (Chernyaev 1995, with the manifold fixes
//! of Custodio et al. 2013 and Vega et al. 2019).
//!
//! Instead of a case table, pleat derives each cube's MC33 topology from the trilinear
//! interpolant the way the case analysis does, which makes every one of the 256 sign
//! configurations (and every resolution of its ambiguities) handled by the same code:
//!
//! 1. **Signs.** With `v = f − d`, a corner is *inside* iff `v < 0`; `v = 0` counts as outside.
//!    Everywhere below, the same tie rule holds: it is the symbolic perturbation
//!    `v ← v + δ`, `δ → 0⁺`, which adds `δ` to every interpolated value (corners, face saddles,
//!    slice saddles), so "`= 0`" always resolves to "outside", from every cube alike.
//! 2. **Faces** (asymptotic decider). On a face with alternating signs the outside diagonal
//!    `(p, p')` is joined iff the bilinear saddle value is `≥ 0`, i.e. iff
//!    `v_p·v_p' ≥ v_n·v_n'`. The products are commutative, so both cubes sharing the face decide
//!    identically: their boundary curves match, which is what makes the surface watertight.
//! 3. **Loops.** Each face contributes one or two iso-segments between iso-points on its edges,
//!    oriented with the outside region on their left seen from outside the cube. Every crossed
//!    edge has one outgoing and one incoming segment (its two faces traverse it in opposite
//!    directions), so the segments form disjoint oriented loops on the cube surface.
//! 4. **Interior** (the MC33 interior test, generalised). The loops cut the cube surface into
//!    regions; a *tunnel* exists when two same-sign regions are connected through the inside of
//!    the cube but not on its surface. Sweeping planes perpendicular to each axis, the bilinear
//!    slice at height `t` joins a same-sign diagonal iff its saddle numerator
//!    `q(t) = A_i(t)A_k(t) − A_j(t)A_l(t)` (a quadratic in `t`) has the right sign while the
//!    corner signs alternate; the maximum of `q` over that `t`-interval decides (this is
//!    Chernyaev's interior test, as in Vega et al.'s `MC33_interiorTest`, applied to every
//!    diagonal and axis).
//! 5. **Patches.** The iso-surface inside the cube separates its volume into regions that form a
//!    tree (a ball cut by properly embedded connected surfaces); each patch is the interface
//!    between one inside and one outside volume region. Loops that border the same pair of
//!    regions belong to one patch: one loop is a disk, two loops an annulus (the tunnels of MC33
//!    cases 4.1.2, 6.1.2, 7.4.2, 10.1.2, 12.1.2 and 13.5.2). A trilinear function never gives
//!    more; should rounding ever produce three, they are split into disks (the result is still
//!    closed and manifold) and counted.
//!
//! Because every decision that affects a face depends only on that face's four values, and
//! iso-points are keyed by global grid edge, the assembled mesh is watertight; because each
//! patch is triangulated as a disk or annulus with exactly its loops as boundary, it is
//! manifold. The tests check both over all 256 configurations and all ambiguity outcomes.

pub(crate) mod tables;
pub(crate) mod triangulate;

use tables::{EDGE_CORNERS, FACE_CORNERS, FACE_EDGES};

/// Sign decisions of one cube: everything the topology depends on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Decisions {
    /// Bit `c` set iff corner `c` is inside (`f < d`).
    pub inside: u8,
    /// Bit `f` set iff, on ambiguous face `f`, the outside diagonal is joined.
    pub outside_joined: u8,
    /// Number of valid entries in `joins`.
    pub n_joins: u8,
    /// Same-sign corner pairs connected through the cube interior only.
    pub joins: [[u8; 2]; 4],
}

impl Decisions {
    /// Bits used by [`Decisions::pack`].
    pub(crate) const PACKED_BITS: u32 = 41;

    /// The decisions in the low [`Decisions::PACKED_BITS`] bits of a `u64`: `inside` (8),
    /// `outside_joined` (6), `n_joins` (3), then the eight corner indices of `joins` (3 each).
    pub(crate) fn pack(&self) -> u64 {
        let mut x = self.inside as u64
            | (self.outside_joined as u64 & 0x3F) << 8
            | (self.n_joins as u64 & 7) << 14;
        for (i, &c) in self.joins.iter().flatten().enumerate() {
            x |= (c as u64 & 7) << (17 + 3 * i);
        }
        x
    }

    /// Inverse of [`Decisions::pack`] (bits above [`Decisions::PACKED_BITS`] are ignored).
    pub(crate) fn unpack(x: u64) -> Decisions {
        let corner = |i: usize| (x >> (17 + 3 * i) & 7) as u8;
        Decisions {
            inside: x as u8,
            outside_joined: (x >> 8 & 0x3F) as u8,
            n_joins: (x >> 14 & 7) as u8,
            joins: std::array::from_fn(|j| [corner(2 * j), corner(2 * j + 1)]),
        }
    }
}

/// The loops and patches of one cube.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct CubeTopology {
    /// Number of loops.
    pub n_loops: u8,
    /// Loop `i` is `loop_edges[loop_start[i]..loop_start[i + 1]]`.
    pub loop_start: [u8; 5],
    /// Crossed cube edges of all loops, each loop in order.
    pub loop_edges: [u8; 12],
    /// Number of patches.
    pub n_patches: u8,
    /// Loops of each patch; the second is `NO_LOOP` for a disk.
    pub patches: [[u8; 2]; 4],
    /// Set when a group of three or more loops had to be split into disks.
    pub split: bool,
}

/// Marker for "no second loop" in [`CubeTopology::patches`].
pub(crate) const NO_LOOP: u8 = u8::MAX;

impl CubeTopology {
    /// Cube edges of loop `i`, in order.
    pub(crate) fn loop_edges(&self, i: usize) -> &[u8] {
        &self.loop_edges[self.loop_start[i] as usize..self.loop_start[i + 1] as usize]
    }

    /// True when patch `p` is an annulus (a tunnel).
    pub(crate) fn is_annulus(&self, p: usize) -> bool {
        self.patches[p][1] != NO_LOOP
    }
}

/// Tiny union–find over the 8 corners.
#[derive(Clone, Copy)]
struct Uf8([u8; 8]);

impl Uf8 {
    fn new() -> Uf8 {
        Uf8([0, 1, 2, 3, 4, 5, 6, 7])
    }
    fn find(&self, mut c: u8) -> u8 {
        while self.0[c as usize] != c {
            c = self.0[c as usize];
        }
        c
    }
    fn union(&mut self, a: u8, b: u8) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

#[inline]
fn is_inside(inside: u8, c: u8) -> bool {
    inside >> c & 1 == 1
}

/// Faces whose corner signs alternate (the ambiguous ones), as a bit mask.
pub(crate) fn ambiguous_faces(inside: u8) -> u8 {
    let mut m = 0;
    for (f, fc) in FACE_CORNERS.iter().enumerate() {
        let s: [bool; 4] = fc.map(|c| is_inside(inside, c));
        if s[0] == s[2] && s[1] == s[3] && s[0] != s[1] {
            m |= 1 << f;
        }
    }
    m
}

/// Asymptotic decider on face `f`: is the outside diagonal joined? (Ties: joined.)
fn face_outside_joined(v: &[f64; 8], inside: u8, f: usize) -> bool {
    let c = FACE_CORNERS[f].map(|c| c as usize);
    let (p, n) = if is_inside(inside, c[0] as u8) {
        ([c[1], c[3]], [c[0], c[2]])
    } else {
        ([c[0], c[2]], [c[1], c[3]])
    };
    v[p[0]] * v[p[1]] >= v[n[0]] * v[n[1]]
}

/// All decisions for the cube with values `v = f − d` (corner order of [`tables`]).
pub(crate) fn decide(v: &[f64; 8]) -> Decisions {
    let mut inside = 0u8;
    for (c, &x) in v.iter().enumerate() {
        if x < 0.0 {
            inside |= 1 << c;
        }
    }
    let amb = ambiguous_faces(inside);
    let mut outside_joined = 0u8;
    for f in 0..6 {
        if amb >> f & 1 == 1 && face_outside_joined(v, inside, f) {
            outside_joined |= 1 << f;
        }
    }
    let mut dec = Decisions {
        inside,
        outside_joined,
        ..Decisions::default()
    };
    if inside != 0 && inside != 0xFF {
        interior_joins(v, &mut dec);
    }
    dec
}

/// Union–find of the cube-surface regions implied by the signs and face decisions.
fn surface_regions(dec: &Decisions) -> Uf8 {
    let mut uf = Uf8::new();
    for ec in &EDGE_CORNERS {
        if is_inside(dec.inside, ec[0]) == is_inside(dec.inside, ec[1]) {
            uf.union(ec[0], ec[1]);
        }
    }
    let amb = ambiguous_faces(dec.inside);
    for (f, fc) in FACE_CORNERS.iter().enumerate() {
        if amb >> f & 1 == 0 {
            continue;
        }
        let outside_joined = dec.outside_joined >> f & 1 == 1;
        // The joined diagonal: corners 0/2 or 1/3 of the face, whichever has the joined sign.
        let d02_inside = is_inside(dec.inside, fc[0]);
        let pair = if d02_inside != outside_joined {
            (fc[0], fc[2])
        } else {
            (fc[1], fc[3])
        };
        uf.union(pair.0, pair.1);
    }
    uf
}

/// Adds the interior joins (step 4 of the module doc) for pairs not joined on the surface.
fn interior_joins(v: &[f64; 8], dec: &mut Decisions) {
    let surface = surface_regions(dec);
    let mut vol = surface;
    for axis in 0..3 {
        // Columns: the edges parallel to `axis`, in cyclic order around it.
        let cols = FACE_CORNERS[2 * axis].map(|c| [c, c | (1 << axis)]);
        for (i, j, k, l) in [(0, 1, 2, 3), (1, 2, 3, 0)] {
            for outside in [true, false] {
                let (Some(ci), Some(ck)) = (
                    column_corner(cols[i], dec.inside, outside),
                    column_corner(cols[k], dec.inside, outside),
                ) else {
                    continue;
                };
                if vol.find(ci) == vol.find(ck) {
                    continue;
                }
                let a = |m: usize| (v[cols[m][0] as usize], v[cols[m][1] as usize]);
                if slice_joins([a(i), a(j), a(k), a(l)], outside) && (dec.n_joins as usize) < 4 {
                    vol.union(ci, ck);
                    dec.joins[dec.n_joins as usize] = [ci, ck];
                    dec.n_joins += 1;
                }
            }
        }
    }
}

/// A corner of column `col` with the requested sign, if any.
fn column_corner(col: [u8; 2], inside: u8, outside: bool) -> Option<u8> {
    col.into_iter().find(|&c| is_inside(inside, c) != outside)
}

/// Is there a height `t ∈ (0, 1)` where the slice has the diagonal `(0, 2)` of the requested
/// sign, the diagonal `(1, 3)` of the other sign, and the `(0, 2)` diagonal joined?
/// `cols[m] = (value at t = 0, value at t = 1)`; columns in cyclic order.
fn slice_joins(cols: [(f64, f64); 4], outside: bool) -> bool {
    // Each column's sign condition is an interval of t.
    let mut lo = 0.0f64;
    let mut hi = 1.0f64;
    for (m, &(a, b)) in cols.iter().enumerate() {
        let want_outside = (m % 2 == 0) == outside;
        let Some((s, e)) = sign_interval(a, b, want_outside) else {
            return false;
        };
        lo = lo.max(s);
        hi = hi.min(e);
    }
    if lo >= hi {
        return false;
    }
    let q = |t: f64| {
        let at = |m: usize| cols[m].0 + t * (cols[m].1 - cols[m].0);
        at(0) * at(2) - at(1) * at(3)
    };
    // Outside diagonal joined iff saddle ≥ 0 iff q ≥ 0; inside diagonal joined iff q > 0
    // (for the inside diagonal, the saddle's denominator is negative; ties go outside).
    let ok = |x: f64| if outside { x >= 0.0 } else { x > 0.0 };
    if q(lo) > 0.0 || q(hi) > 0.0 {
        return true;
    }
    // q(t) = α t² + β t + γ; its maximum over (lo, hi) if α < 0.
    let d = |m: usize| cols[m].1 - cols[m].0;
    let (a0, a1, a2, a3) = (cols[0].0, cols[1].0, cols[2].0, cols[3].0);
    let alpha = d(0) * d(2) - d(1) * d(3);
    let beta = a0 * d(2) + a2 * d(0) - a1 * d(3) - a3 * d(1);
    if alpha < 0.0 {
        let t = -beta / (2.0 * alpha);
        if t > lo && t < hi && ok(q(t)) {
            return true;
        }
    }
    false
}

/// The `t`-interval (closed, within `[0, 1]`) where `a + t(b − a)` is outside (`≥ 0`) or inside.
fn sign_interval(a: f64, b: f64, outside: bool) -> Option<(f64, f64)> {
    let sa = (a >= 0.0) == outside;
    let sb = (b >= 0.0) == outside;
    match (sa, sb) {
        (true, true) => Some((0.0, 1.0)),
        (false, false) => None,
        _ => {
            let t = (a / (a - b)).clamp(0.0, 1.0);
            if sa {
                Some((0.0, t))
            } else {
                Some((t, 1.0))
            }
        }
    }
}

/// Builds loops and patches from the decisions (steps 3 and 5 of the module doc).
pub(crate) fn topology(dec: &Decisions) -> CubeTopology {
    let mut topo = CubeTopology::default();
    if dec.inside == 0 || dec.inside == 0xFF {
        return topo;
    }
    let next = segment_successors(dec);
    trace_loops(&next, &mut topo);
    group_patches(dec, &mut topo);
    topo
}

/// For every crossed edge, the crossed edge its outgoing iso-segment leads to (`u8::MAX` for
/// uncrossed edges).
fn segment_successors(dec: &Decisions) -> [u8; 12] {
    let mut next = [u8::MAX; 12];
    let amb = ambiguous_faces(dec.inside);
    for f in 0..6 {
        let fc = FACE_CORNERS[f];
        let fe = FACE_EDGES[f];
        let out =
            |i: usize| !is_inside(dec.inside, fc[i]) && is_inside(dec.inside, fc[(i + 1) % 4]);
        let into =
            |i: usize| is_inside(dec.inside, fc[i]) && !is_inside(dec.inside, fc[(i + 1) % 4]);
        for i in 0..4 {
            if !out(i) {
                continue;
            }
            let partner = if amb >> f & 1 == 1 {
                // Outside joined: cut off the inside corner that follows (i + 1);
                // inside joined: cut off the outside corner before (i − 1).
                if dec.outside_joined >> f & 1 == 1 {
                    (i + 1) % 4
                } else {
                    (i + 3) % 4
                }
            } else {
                (0..4).find(|&j| into(j)).unwrap_or(i)
            };
            next[fe[i] as usize] = fe[partner];
        }
    }
    next
}

fn trace_loops(next: &[u8; 12], topo: &mut CubeTopology) {
    let mut seen = [false; 12];
    let mut n = 0usize;
    for start in 0..12u8 {
        if next[start as usize] == u8::MAX || seen[start as usize] {
            continue;
        }
        let mut e = start;
        while !seen[e as usize] && n < 12 {
            seen[e as usize] = true;
            topo.loop_edges[n] = e;
            n += 1;
            e = next[e as usize];
            if e == u8::MAX {
                break;
            }
        }
        topo.n_loops += 1;
        topo.loop_start[topo.n_loops as usize] = n as u8;
        if topo.n_loops == 4 {
            break;
        }
    }
}

/// Groups loops bordering the same pair of volume regions into patches.
fn group_patches(dec: &Decisions, topo: &mut CubeTopology) {
    let mut vol = surface_regions(dec);
    for j in &dec.joins[..dec.n_joins as usize] {
        vol.union(j[0], j[1]);
    }
    let keys: Vec<(u8, u8)> = (0..topo.n_loops as usize)
        .map(|i| {
            let e = topo.loop_edges(i)[0] as usize;
            let [a, b] = EDGE_CORNERS[e];
            let (cin, cout) = if is_inside(dec.inside, a) {
                (a, b)
            } else {
                (b, a)
            };
            (vol.find(cin), vol.find(cout))
        })
        .collect();
    let mut used = [false; 4];
    for i in 0..keys.len() {
        if used[i] {
            continue;
        }
        let same: Vec<usize> = (i..keys.len())
            .filter(|&j| !used[j] && keys[j] == keys[i])
            .collect();
        if same.len() == 2 {
            push_patch(topo, [same[0] as u8, same[1] as u8]);
            used[same[0]] = true;
            used[same[1]] = true;
        } else {
            if same.len() > 2 {
                topo.split = true;
            }
            for &j in &same {
                push_patch(topo, [j as u8, NO_LOOP]);
                used[j] = true;
            }
        }
    }
}

fn push_patch(topo: &mut CubeTopology, loops: [u8; 2]) {
    if (topo.n_patches as usize) < 4 {
        topo.patches[topo.n_patches as usize] = loops;
        topo.n_patches += 1;
    }
}

/// Trilinear interpolation of corner values `v` at local coordinates `p ∈ [0, 1]³`.
#[cfg(test)]
pub(crate) fn trilinear(v: &[f64; 8], p: [f64; 3]) -> f64 {
    let mut s = 0.0;
    for (c, pos) in tables::CORNER_POS.iter().enumerate() {
        let mut w = 1.0;
        for k in 0..3 {
            w *= if pos[k] == 1 { p[k] } else { 1.0 - p[k] };
        }
        s += w * v[c];
    }
    s
}

/// Volume region (a representative corner) of every corner: surface regions merged by the
/// interior joins.
#[cfg(test)]
pub(crate) fn volume_regions(dec: &Decisions) -> [u8; 8] {
    let mut vol = surface_regions(dec);
    for j in &dec.joins[..dec.n_joins as usize] {
        vol.union(j[0], j[1]);
    }
    std::array::from_fn(|c| vol.find(c as u8))
}

/// Surface region of every corner.
#[cfg(test)]
pub(crate) fn surface_region_roots(dec: &Decisions) -> [u8; 8] {
    let uf = surface_regions(dec);
    std::array::from_fn(|c| uf.find(c as u8))
}

#[cfg(test)]
mod tests;
