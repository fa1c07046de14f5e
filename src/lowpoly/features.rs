//! Feature vertices of the iso-surface (dissertation eq. 4.2–4.3) and the per-cube geometry
//! of the MC33 patches.
//!
//! For every disk patch of a cube, one vertex `x` minimises `Σ_i (n_i·(x − p_i))²` over the
//! patch's iso-points `p_i` with `n_i = (p_i − p_i*)/‖p_i − p_i*‖` (eq. 4.2), subject to
//! `x` lying strictly inside a convex polyhedron `P_k` of the cube (eq. 4.3); the patch is then
//! fan-triangulated around `x`. Flat or cylindrical patches make the quadratic rank-deficient;
//! as in feature-sensitive contouring (Kobbelt et al. 2001, Ju et al. 2002) a small Tikhonov
//! term `w‖x − p̄‖²` (`w = 1%` of the point count, `p̄` the iso-point centroid) pulls the free
//! directions to the centroid and leaves the constrained ones unchanged.
//!
//! **The polyhedra.** `P_k` is the cube shrunk by `μ = 10⁻³ h`, cut, for every other patch `j`
//! of the cube, by a plane that strictly separates the iso-points of `k` from those of `j`
//! (chosen among 13 lattice directions and the centroid difference, largest gap wins; the
//! constraint keeps `x` a further 5% of the gap away from it). So `P_k` contains patch `k`'s
//! loop on its boundary-side and no point of another patch.
//!
//! **Why the fans are intersection-free by construction.**
//! 1. *Within a patch:* `x` is strictly inside the cube. The loop lies on the cube surface and
//!    is simple there (MC33 iso-segments on a face never cross), and radial projection from an
//!    interior point of a convex body onto its boundary is a bijection. Fan triangle
//!    `(p_i, p_{i+1}, x)` is the cone from `x` over the segment `p_i p_{i+1}`, so two fan
//!    triangles meet only in `x` and their shared edge `x p_i`.
//! 2. *Between patches of one cube:* a fan (or a template triangulation) of patch `k` lies in
//!    `conv(x_k, loop_k)`, which lies strictly on `k`'s side of every separating plane; patch `j`
//!    lies strictly on the other side. They cannot meet.
//! 3. *Between cubes:* every triangle lies in its closed cube, and meets the cube surface only
//!    along its loop segments (`x` is at distance `≥ μ` from every face, and template chords
//!    between two iso-points of one face are refused). Neighbouring cubes share exactly those
//!    segments and iso-points (global edge keys), so triangles of different cubes meet only in
//!    shared edges and vertices.
//! 4. *Non-degeneracy:* iso-points are strictly inside cube edges, and `x` is `≥ μ` off every
//!    face plane, so each fan triangle has height `≥ μ` over its loop segment.
//!
//! Patches that cannot be separated by a plane (never observed for value-consistent cubes) get
//! no feature vertex; their cube is then checked with exact predicates and, if needed, counted
//! as unresolved. Tunnels (annuli) get no feature vertex (the dissertation excludes them too);
//! their strip is checked exactly, and replaced by two disks when it fails.

use super::mc33::triangulate::{fan, plain_disk, strip, LocalTri};
use super::mc33::{CubeTopology, NO_LOOP};
use crate::geom::{normalized, Vec3};

/// Shrink of the cube for apex vertices, in units of `h`.
pub(crate) const CUBE_MARGIN: f64 = 1e-3;
/// Regularisation weight per iso-point (eq. 4.2 + Tikhonov).
pub(crate) const REGULARIZATION: f64 = 0.01;

/// A half-space `n·x ≤ c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HalfSpace {
    /// Outward normal.
    pub n: Vec3,
    /// Offset.
    pub c: f64,
}

/// Minimises `½ xᵀAx − bᵀx` subject to `nᵢ·x ≤ cᵢ` (A symmetric positive definite, 3×3) by
/// enumerating active sets of size 0..3 and returning the first KKT point (for a strictly
/// convex QP it is the unique optimum). `None` when no KKT point is found (infeasible or
/// numerically degenerate).
pub(crate) fn solve_qp(a: [[f64; 3]; 3], b: Vec3, cons: &[HalfSpace]) -> Option<Vec3> {
    let ainv = inverse3(a)?;
    let tol = 1e-12;
    let feasible = |x: Vec3| cons.iter().all(|h| h.n.dot(x) <= h.c + tol);
    let x0 = mul3(&ainv, b);
    if feasible(x0) {
        return Some(x0);
    }
    let m = cons.len();
    for size in 1..=3usize.min(m) {
        let mut idx = [0usize; 3];
        for (k, slot) in idx.iter_mut().enumerate().take(size) {
            *slot = k;
        }
        loop {
            if let Some((x, lam)) = solve_active(&ainv, b, cons, &idx[..size]) {
                if lam[..size].iter().all(|&l| l >= -tol) && feasible(x) {
                    return Some(x);
                }
            }
            if !next_combination(&mut idx[..size], m) {
                break;
            }
        }
    }
    None
}

fn next_combination(idx: &mut [usize], m: usize) -> bool {
    let k = idx.len();
    let mut i = k;
    while i > 0 {
        i -= 1;
        if idx[i] < m - k + i {
            idx[i] += 1;
            for j in i + 1..k {
                idx[j] = idx[j - 1] + 1;
            }
            return true;
        }
    }
    false
}

/// Equality-constrained minimiser with constraints `set` active; returns `(x, λ)`.
fn solve_active(
    ainv: &[[f64; 3]; 3],
    b: Vec3,
    cons: &[HalfSpace],
    set: &[usize],
) -> Option<(Vec3, [f64; 3])> {
    let k = set.len();
    let g: Vec<Vec3> = set.iter().map(|&i| cons[i].n).collect();
    let ag: Vec<Vec3> = g.iter().map(|gi| mul3(ainv, *gi)).collect();
    let ab = mul3(ainv, b);
    let mut mtx = [[0.0; 4]; 3];
    for r in 0..k {
        for c in 0..k {
            mtx[r][c] = g[r].dot(ag[c]);
        }
        mtx[r][3] = g[r].dot(ab) - cons[set[r]].c;
    }
    let lam = gauss_solve(&mut mtx, k)?;
    let mut rhs = b;
    for r in 0..k {
        rhs -= g[r] * lam[r];
    }
    Some((mul3(ainv, rhs), lam))
}

/// Solves the `k×k` system in `m` (augmented column 3) with partial pivoting.
fn gauss_solve(m: &mut [[f64; 4]; 3], k: usize) -> Option<[f64; 3]> {
    let scale_ref = (0..k)
        .flat_map(|r| (0..k).map(move |c| (r, c)))
        .fold(0.0f64, |s, (r, c)| s.max(m[r][c].abs()));
    for col in 0..k {
        let piv = (col..k).max_by(|&x, &y| m[x][col].abs().total_cmp(&m[y][col].abs()))?;
        if m[piv][col].abs() <= 1e-12 * scale_ref.max(f64::MIN_POSITIVE) {
            return None;
        }
        m.swap(col, piv);
        let pivot_row = m[col];
        for (r, row) in m.iter_mut().enumerate().take(k) {
            if r != col {
                let f = row[col] / pivot_row[col];
                for (x, p) in row.iter_mut().zip(pivot_row.iter()).skip(col) {
                    *x -= f * p;
                }
            }
        }
    }
    let mut x = [0.0; 3];
    for r in 0..k {
        x[r] = m[r][3] / m[r][r];
    }
    Some(x)
}

fn mul3(m: &[[f64; 3]; 3], v: Vec3) -> Vec3 {
    Vec3::new(
        Vec3::from(m[0]).dot(v),
        Vec3::from(m[1]).dot(v),
        Vec3::from(m[2]).dot(v),
    )
}

fn inverse3(a: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |r: usize, s: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (s1, s2) = ((s + 1) % 3, (s + 2) % 3);
        a[r1][s1] * a[r2][s2] - a[r1][s2] * a[r2][s1]
    };
    let det = a[0][0] * c(0, 0) + a[0][1] * c(0, 1) + a[0][2] * c(0, 2);
    if !det.is_finite() || det.abs() <= 1e-300 {
        return None;
    }
    Some(std::array::from_fn(|r| {
        std::array::from_fn(|s| c(s, r) / det)
    }))
}

/// Candidate plane normals: axes, face diagonals, body diagonals.
const DIRECTIONS: [[f64; 3]; 13] = [
    [1., 0., 0.],
    [0., 1., 0.],
    [0., 0., 1.],
    [1., 1., 0.],
    [1., -1., 0.],
    [1., 0., 1.],
    [1., 0., -1.],
    [0., 1., 1.],
    [0., 1., -1.],
    [1., 1., 1.],
    [1., 1., -1.],
    [1., -1., 1.],
    [-1., 1., 1.],
];

/// A plane strictly separating point sets `a` and `b`, as the half-space containing `a`
/// (with the apex margin already applied) and the one containing `b`.
pub(crate) fn separating_plane(a: &[Vec3], b: &[Vec3]) -> Option<(HalfSpace, HalfSpace)> {
    let centroid = |s: &[Vec3]| s.iter().fold(Vec3::ZERO, |x, p| x + *p) * (1.0 / s.len() as f64);
    let diff = centroid(b) - centroid(a);
    let mut best: Option<(f64, Vec3, f64, f64)> = None;
    let extra = normalized(diff).into_iter();
    for n in DIRECTIONS
        .iter()
        .filter_map(|d| normalized(Vec3::from(*d)))
        .chain(extra)
    {
        for n in [n, n * -1.0] {
            let amax = a
                .iter()
                .map(|p| n.dot(*p))
                .fold(f64::NEG_INFINITY, f64::max);
            let bmin = b.iter().map(|p| n.dot(*p)).fold(f64::INFINITY, f64::min);
            let gap = bmin - amax;
            if gap > 0.0 && best.is_none_or(|bb| gap > bb.0) {
                best = Some((gap, n, amax, bmin));
            }
        }
    }
    let (gap, n, amax, bmin) = best?;
    let mid = 0.5 * (amax + bmin);
    let m = 0.05 * gap;
    Some((
        HalfSpace { n, c: mid - m },
        HalfSpace {
            n: n * -1.0,
            c: -(mid + m),
        },
    ))
}

/// The six half-spaces of the unit cube shrunk by `margin`.
fn cube_halfspaces(margin: f64) -> [HalfSpace; 6] {
    let mut out = [HalfSpace {
        n: Vec3::ZERO,
        c: 0.0,
    }; 6];
    for a in 0..3 {
        let mut n = Vec3::ZERO;
        n[a] = 1.0;
        out[2 * a] = HalfSpace { n, c: 1.0 - margin };
        out[2 * a + 1] = HalfSpace {
            n: n * -1.0,
            c: -margin,
        };
    }
    out
}

/// One patch of a cube, in cube-local coordinates (unit cube).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PatchGeom {
    /// Cube edges of the first loop followed by those of the second (annulus) loop.
    pub edges: Vec<u8>,
    /// Number of edges of the first loop (`edges.len()` for a disk).
    pub first_len: usize,
    /// The feature vertex (eq. 4.3), local coordinates; disks only.
    pub feature: Option<Vec3>,
    /// Extra vertex needed by the template triangulation, if any (index `edges.len()`).
    pub center: Option<Vec3>,
    /// Template triangulation (local indices; `edges.len()` is the center).
    pub plain: Vec<LocalTri>,
    /// Largest angle (degrees) between two iso-point normals of the patch (0 without normals).
    pub normal_spread_deg: f32,
}

impl PatchGeom {
    /// True for a tunnel.
    pub(crate) fn is_annulus(&self) -> bool {
        self.first_len < self.edges.len()
    }
}

/// What [`cube_geometry`] reports besides the patches.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct CubeFlags {
    /// A tunnel strip failed its exact check and became two disks.
    pub tunnel_split: bool,
    /// Two patches had no separating plane (features off in this cube, exact check applied).
    pub unseparated: bool,
    /// The exact check of an unseparated cube failed: the cube may intersect itself.
    pub unresolved: bool,
}

/// Maps a cube-local point onto the exact iso-surface (`None` when it cannot).
pub(crate) type Projector<'a> = &'a dyn Fn(Vec3) -> Option<Vec3>;

/// Geometry of all patches of one cube. `iso[e]` is the iso-point of crossed edge `e` and
/// `normals[e]` its unit normal (eq. 4.3), both in cube-local coordinates (unit cube);
/// `normals = None` computes no feature vertices; otherwise a disk patch gets one when its
/// normal spread is at least `min_spread_deg` (0 for every disk patch). With `project`, each
/// apex (feature or center vertex) is moved onto the exact iso-surface when the moved point
/// still satisfies its polyhedron's constraints (so the embedding argument is unaffected).
pub(crate) fn cube_geometry(
    topo: &CubeTopology,
    iso: &[Vec3; 12],
    normals: Option<&[Vec3; 12]>,
    min_spread_deg: f32,
    project: Option<Projector<'_>>,
) -> (Vec<PatchGeom>, CubeFlags) {
    let mut flags = CubeFlags::default();
    let groups = patch_groups(topo, iso, &mut flags);
    let pts: Vec<Vec<Vec3>> = groups
        .iter()
        .map(|g| g.0.iter().map(|&e| iso[e as usize]).collect())
        .collect();
    // Pairwise separating planes.
    let mut cons: Vec<Vec<HalfSpace>> = (0..groups.len())
        .map(|_| cube_halfspaces(CUBE_MARGIN).to_vec())
        .collect();
    let mut separated = vec![true; groups.len()];
    for k in 0..groups.len() {
        for j in k + 1..groups.len() {
            match separating_plane(&pts[k], &pts[j]) {
                Some((hk, hj)) => {
                    cons[k].push(hk);
                    cons[j].push(hj);
                }
                None => {
                    separated[k] = false;
                    separated[j] = false;
                    flags.unseparated = true;
                }
            }
        }
    }
    let mut out = Vec::with_capacity(groups.len());
    for (k, (edges, first_len)) in groups.into_iter().enumerate() {
        let mut g = PatchGeom {
            edges,
            first_len,
            feature: None,
            center: None,
            plain: Vec::new(),
            normal_spread_deg: 0.0,
        };
        if g.is_annulus() {
            let (a, b) = pts[k].split_at(first_len);
            let (ea, eb) = g.edges.split_at(first_len);
            let ok = strip(a, ea, b, eb, &[], &mut g.plain);
            debug_assert!(ok, "strip was validated in patch_groups");
        } else {
            let feature = normals.map(|n| (n, min_spread_deg));
            disk_geometry(&mut g, &pts[k], &cons[k], separated[k], feature, project);
        }
        out.push(g);
    }
    if flags.unseparated && !cube_is_embedded(&out, iso) {
        flags.unresolved = true;
    }
    (out, flags)
}

/// Patches as (edges, first loop length); tunnels whose strip fails, or which cannot be
/// separated from another patch, become two disks.
fn patch_groups(
    topo: &CubeTopology,
    iso: &[Vec3; 12],
    flags: &mut CubeFlags,
) -> Vec<(Vec<u8>, usize)> {
    let mut groups: Vec<(Vec<u8>, usize)> = Vec::with_capacity(topo.n_patches as usize);
    for p in 0..topo.n_patches as usize {
        let [l0, l1] = topo.patches[p];
        let e0 = topo.loop_edges(l0 as usize).to_vec();
        if !topo.is_annulus(p) {
            let n = e0.len();
            groups.push((e0, n));
            continue;
        }
        let e1 = topo.loop_edges(l1 as usize).to_vec();
        let p0: Vec<Vec3> = e0.iter().map(|&e| iso[e as usize]).collect();
        let p1: Vec<Vec3> = e1.iter().map(|&e| iso[e as usize]).collect();
        let mut others: Vec<Vec3> = Vec::new();
        for q in 0..topo.n_patches as usize {
            if q != p {
                for &l in topo.patches[q].iter().filter(|&&l| l != NO_LOOP) {
                    others.extend(topo.loop_edges(l as usize).iter().map(|&e| iso[e as usize]));
                }
            }
        }
        let both: Vec<Vec3> = p0.iter().chain(&p1).copied().collect();
        let separable = others.is_empty() || separating_plane(&both, &others).is_some();
        let mut tmp = Vec::new();
        if separable && strip(&p0, &e0, &p1, &e1, &[], &mut tmp) {
            let n = e0.len();
            let mut e = e0;
            e.extend(e1);
            groups.push((e, n));
        } else {
            flags.tunnel_split = true;
            let (n0, n1) = (e0.len(), e1.len());
            groups.push((e0, n0));
            groups.push((e1, n1));
        }
    }
    groups
}

fn centroid(p: &[Vec3]) -> Vec3 {
    p.iter().fold(Vec3::ZERO, |a, q| a + *q) * (1.0 / p.len() as f64)
}

/// Feature vertex and template triangulation of a disk patch. `feature` holds the normals and
/// the least normal spread (degrees) for which the feature vertex is computed.
fn disk_geometry(
    g: &mut PatchGeom,
    pts: &[Vec3],
    cons: &[HalfSpace],
    separated: bool,
    feature: Option<(&[Vec3; 12], f32)>,
    project: Option<Projector<'_>>,
) {
    let c = centroid(pts);
    let cons: &[HalfSpace] = if separated { cons } else { &cons[..6] };
    let onto_surface = |x: Vec3| {
        project
            .and_then(|f| f(x))
            .filter(|y| cons.iter().all(|h| h.n.dot(*y) <= h.c))
            .unwrap_or(x)
    };
    if let (Some((nrm, min_spread)), true) = (feature, separated) {
        g.normal_spread_deg = normal_spread(&g.edges, nrm);
        if g.normal_spread_deg >= min_spread {
            g.feature = feature_vertex(pts, &g.edges, nrm, c, cons).map(onto_surface);
        }
    }
    if !plain_disk(pts, &g.edges, &mut g.plain) {
        // Template needs a center: the centroid projected into the polyhedron.
        let w = REGULARIZATION * pts.len() as f64;
        let a = [[w, 0.0, 0.0], [0.0, w, 0.0], [0.0, 0.0, w]];
        let x = solve_qp(a, c * w, cons).unwrap_or_else(|| clamp_into_cube(c));
        g.center = Some(onto_surface(x));
        fan(pts.len(), &mut g.plain);
    }
}

fn clamp_into_cube(p: Vec3) -> Vec3 {
    p.map(|x| x.clamp(0.25, 0.75))
}

/// Largest angle between two of the normals of `edges`, in degrees.
fn normal_spread(edges: &[u8], nrm: &[Vec3; 12]) -> f32 {
    let mut min_cos = 1.0f64;
    for (i, &a) in edges.iter().enumerate() {
        for &b in &edges[i + 1..] {
            min_cos = min_cos.min(nrm[a as usize].dot(nrm[b as usize]));
        }
    }
    min_cos.clamp(-1.0, 1.0).acos().to_degrees() as f32
}

/// Eq. 4.3 with Tikhonov regularisation toward the centroid `c`.
fn feature_vertex(
    pts: &[Vec3],
    edges: &[u8],
    nrm: &[Vec3; 12],
    c: Vec3,
    cons: &[HalfSpace],
) -> Option<Vec3> {
    let w = REGULARIZATION * pts.len() as f64;
    let mut a = [[w, 0.0, 0.0], [0.0, w, 0.0], [0.0, 0.0, w]];
    let mut b = c * w;
    for (p, &e) in pts.iter().zip(edges) {
        let n = nrm[e as usize];
        for r in 0..3 {
            for s in 0..3 {
                a[r][s] += n[r] * n[s];
            }
        }
        b += n * n.dot(*p);
    }
    solve_qp(a, b, cons)
}

/// Exact check of a cube whose patches could not all be separated.
fn cube_is_embedded(patches: &[PatchGeom], iso: &[Vec3; 12]) -> bool {
    // Point ids: iso-point of edge e is e, the center of patch k is 12 + k.
    let mut pos: Vec<[f64; 3]> = iso.iter().map(|p| p.to_array()).collect();
    pos.extend(
        patches
            .iter()
            .map(|g| g.center.unwrap_or(Vec3::splat(0.5)).to_array()),
    );
    let mut tris: Vec<[u32; 3]> = Vec::new();
    for (k, g) in patches.iter().enumerate() {
        let id = |i: u8| -> u32 {
            match g.edges.get(i as usize) {
                Some(&e) => e as u32,
                None => 12 + k as u32,
            }
        };
        tris.extend(g.plain.iter().map(|t| t.map(id)));
    }
    tris.iter().enumerate().all(|(x, &a)| {
        tris[x + 1..]
            .iter()
            .all(|&b| !crate::spatial::faces_intersect(&pos, a, b))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn qp_matches_brute_force() {
        let mut s = 3u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            // random SPD A = MᵀM + 0.1 I, random b, unit cube constraints plus a random plane
            let m: [[f64; 3]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| rnd() - 0.5));
            let mut a = [[0.0; 3]; 3];
            for r in 0..3 {
                for c in 0..3 {
                    a[r][c] = (0..3).map(|k| m[k][r] * m[k][c]).sum::<f64>()
                        + if r == c { 0.1 } else { 0.0 };
                }
            }
            let b = Vec3::from(std::array::from_fn::<f64, 3, _>(|_| 4.0 * (rnd() - 0.5)));
            let mut cons = cube_halfspaces(0.0).to_vec();
            let n = normalized(Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)).unwrap();
            cons.push(HalfSpace {
                n,
                c: n.dot(Vec3::splat(0.5)) + 0.1,
            });
            let x = solve_qp(a, b, &cons).expect("feasible");
            let f = |x: Vec3| 0.5 * x.dot(mul3(&a, x)) - b.dot(x);
            // brute force over a grid of feasible points
            let k = 24;
            let mut best = f64::INFINITY;
            for i in 0..=k {
                for j in 0..=k {
                    for l in 0..=k {
                        let p = Vec3::from([i, j, l].map(|t| t as f64 / k as f64));
                        if cons.iter().all(|h| h.n.dot(p) <= h.c + 1e-12) {
                            best = best.min(f(p));
                        }
                    }
                }
            }
            assert!(cons.iter().all(|h| h.n.dot(x) <= h.c + 1e-9));
            assert!(f(x) <= best + 1e-9, "{} > {}", f(x), best);
        }
    }

    #[test]
    fn corner_patch_recovers_the_corner() {
        // Iso-points of a cube corner region: three planes x = 0.6, y = 0.6, z = 0.6 meeting
        // at (0.6, 0.6, 0.6); points on the planes with their normals.
        let pts = [
            [0.6, 0.2, 0.0],
            [0.6, 0.0, 0.3],
            [0.2, 0.6, 0.0],
            [0.0, 0.6, 0.3],
            [0.3, 0.0, 0.6],
            [0.0, 0.2, 0.6],
        ];
        let nrm = [
            [1., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [0., 0., 1.],
        ];
        let w = 0.0;
        let mut a = [[w, 0.0, 0.0], [0.0, w, 0.0], [0.0, 0.0, w]];
        let mut b = Vec3::ZERO;
        for (p, n) in pts.iter().zip(&nrm) {
            let (p, n) = (Vec3::from(*p), Vec3::from(*n));
            for r in 0..3 {
                for s in 0..3 {
                    a[r][s] += n[r] * n[s];
                }
            }
            b += n * n.dot(p);
        }
        let x = solve_qp(a, b, &cube_halfspaces(CUBE_MARGIN)).unwrap();
        assert!(x.distance(Vec3::splat(0.6)) < 1e-12);
        // A corner outside the cube is clamped to the shrunk cube.
        let b2 = b + Vec3::new(3.0, 0.0, 0.0);
        let y = solve_qp(a, b2, &cube_halfspaces(CUBE_MARGIN)).unwrap();
        assert!((y[0] - (1.0 - CUBE_MARGIN)).abs() < 1e-12);
    }
}
