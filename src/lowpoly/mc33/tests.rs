use super::tables::*;
use super::triangulate::{fan, LocalTri};
use super::*;
use crate::geom::normalized;
use crate::geom::{lerp, Vec3};
use crate::lowpoly::features::{cube_geometry, CubeFlags};
use crate::spatial::faces_intersect;
use std::collections::HashMap;

/// Deterministic SplitMix64.
pub(crate) struct Rng(pub u64);

impl Rng {
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^ (z >> 31)
    }
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Heavy-tailed positive magnitude, so that extreme ratios (tunnels) occur.
    pub(crate) fn magnitude(&mut self) -> f64 {
        (8.0 * (self.unit() - 0.5)).exp()
    }
}

fn corner(c: u8) -> Vec3 {
    Vec3::from(CORNER_POS[c as usize].map(f64::from))
}

/// Iso-point on cube edge `e` at parameter `t` from its first corner.
fn edge_point(e: u8, t: f64) -> Vec3 {
    let [a, b] = EDGE_CORNERS[e as usize];
    lerp(corner(a), corner(b), t)
}

/// All decisions reachable by choosing face outcomes freely and adding at most one interior
/// join between two same-sign surface regions (a superset of what values can produce).
fn all_resolutions(inside: u8) -> Vec<Decisions> {
    let amb = ambiguous_faces(inside);
    let mut out = Vec::new();
    for sub in 0..64u8 {
        if sub & !amb != 0 {
            continue;
        }
        let base = Decisions {
            inside,
            outside_joined: sub,
            ..Decisions::default()
        };
        out.push(base);
        let roots = surface_region_roots(&base);
        for a in 0..8u8 {
            for b in a + 1..8 {
                let same_sign = (inside >> a & 1) == (inside >> b & 1);
                if same_sign && roots[a as usize] == a && roots[b as usize] == b {
                    let mut d = base;
                    d.joins[0] = [a, b];
                    d.n_joins = 1;
                    out.push(d);
                }
            }
        }
    }
    out
}

/// Checks loops: every crossed edge exactly once, consecutive points on a common face, loops
/// of at least three points.
fn check_loops(dec: &Decisions, topo: &CubeTopology) {
    let mut seen = [0u8; 12];
    for l in 0..topo.n_loops as usize {
        let le = topo.loop_edges(l);
        assert!(le.len() >= 3, "{dec:?}: short loop");
        for (i, &e) in le.iter().enumerate() {
            seen[e as usize] += 1;
            assert!(edges_share_face(e, le[(i + 1) % le.len()]));
        }
    }
    for (e, ec) in EDGE_CORNERS.iter().enumerate() {
        let crossed = (dec.inside >> ec[0] & 1) != (dec.inside >> ec[1] & 1);
        assert_eq!(seen[e], crossed as u8, "{dec:?}: edge {e}");
    }
}

/// Triangulates a cube the way the extractor does (`cube_geometry`), with feature fans where
/// available, and returns triangles over point ids (iso-points are `e`, extra vertices
/// `100 + k`), positions, and the flags.
///
/// [`no_conflicts`] checks such a cube with the exact `spatial::faces_intersect`.
pub(crate) fn triangulate_cube(
    topo: &CubeTopology,
    iso: &[Vec3; 12],
    normals: Option<&[Vec3; 12]>,
) -> (Vec<[u32; 3]>, HashMap<u32, Vec3>, CubeFlags) {
    let (patches, flags) = cube_geometry(topo, iso, normals, 0.0, None);
    let mut tris = Vec::new();
    let mut pos: HashMap<u32, Vec3> = HashMap::new();
    for e in 0..12u8 {
        pos.insert(e as u32, iso[e as usize]);
    }
    let mut buf: Vec<LocalTri> = Vec::new();
    for (k, g) in patches.iter().enumerate() {
        let mut ids: Vec<u32> = g.edges.iter().map(|&e| e as u32).collect();
        let extra = 100 + k as u32;
        ids.push(extra);
        let local: &[LocalTri] = match g.feature {
            Some(x) => {
                pos.insert(extra, x);
                buf.clear();
                fan(g.edges.len(), &mut buf);
                &buf
            }
            None => {
                if let Some(c) = g.center {
                    pos.insert(extra, c);
                }
                &g.plain
            }
        };
        for t in local {
            tris.push(t.map(|i| ids[i as usize]));
        }
    }
    (tris, pos, flags)
}

/// No two triangles of the cube intersect beyond what they share (exact).
fn no_conflicts(tris: &[[u32; 3]], pos: &HashMap<u32, Vec3>) -> Result<(), String> {
    let mut ids: Vec<u32> = pos.keys().copied().collect();
    ids.sort_unstable();
    let dense: Vec<[f64; 3]> = (0..=ids.last().copied().unwrap_or(0))
        .map(|i| pos.get(&i).map_or([f64::NAN; 3], |p| p.to_array()))
        .collect();
    for (x, a) in tris.iter().enumerate() {
        for b in &tris[x + 1..] {
            if faces_intersect(&dense, *a, *b) {
                return Err(format!("{a:?} x {b:?}"));
            }
        }
    }
    Ok(())
}

/// Oriented-edge bookkeeping: boundary edges (loop segments, in loop direction) exactly once,
/// every other directed edge paired with its reverse.
fn check_patch_surface(topo: &CubeTopology, tris: &[[u32; 3]]) {
    let mut count: HashMap<(u32, u32), i32> = HashMap::new();
    for t in tris {
        assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        for k in 0..3 {
            *count.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut boundary = std::collections::HashSet::new();
    for l in 0..topo.n_loops as usize {
        let le = topo.loop_edges(l);
        for i in 0..le.len() {
            boundary.insert((le[i] as u32, le[(i + 1) % le.len()] as u32));
        }
    }
    for (&(a, b), &c) in &count {
        assert_eq!(
            c, 1,
            "directed edge {a}->{b} used {c} times; {topo:?} {tris:?}"
        );
        if !boundary.contains(&(a, b)) {
            assert_eq!(count.get(&(b, a)), Some(&1), "edge {a}->{b} unpaired");
        }
    }
    for b in &boundary {
        assert_eq!(count.get(b), Some(&1), "loop segment {b:?} missing");
        assert!(!count.contains_key(&(b.1, b.0)));
    }
}

#[test]
fn every_configuration_and_resolution_gives_closed_patches() {
    let mut rng = Rng(7);
    let mut n_cases = 0;
    let mut tunnels = 0;
    let (mut unseparated, mut unresolved) = (0, 0);
    for inside in 1..255u8 {
        for dec in all_resolutions(inside) {
            let topo = topology(&dec);
            check_loops(&dec, &topo);
            assert!(!topo.split);
            let n_loops_in_patches: usize = (0..topo.n_patches as usize)
                .map(|p| 1 + topo.is_annulus(p) as usize)
                .sum();
            assert_eq!(n_loops_in_patches, topo.n_loops as usize);
            tunnels += (0..topo.n_patches as usize)
                .filter(|&p| topo.is_annulus(p))
                .count();
            for round in 0..4 {
                let iso: [Vec3; 12] =
                    std::array::from_fn(|e| edge_point(e as u8, 0.02 + 0.96 * rng.unit()));
                let nrm: [Vec3; 12] = std::array::from_fn(|_| {
                    normalized(Vec3::new(
                        rng.unit() - 0.5,
                        rng.unit() - 0.5,
                        rng.unit() - 0.5,
                    ))
                    .unwrap_or(Vec3::X)
                });
                let normals = (round % 2 == 1).then_some(&nrm);
                let (tris, pos, flags) = triangulate_cube(&topo, &iso, normals);
                check_patch_surface(&topo, &tris);
                unseparated += flags.unseparated as usize;
                if flags.unresolved {
                    unresolved += 1;
                    continue;
                }
                if let Err(e) = no_conflicts(&tris, &pos) {
                    panic!("{dec:?}: {e}");
                }
            }
            n_cases += 1;
        }
    }
    eprintln!("{n_cases} resolutions, {tunnels} tunnels; arbitrary iso-points: {unseparated} cubes unseparated, {unresolved} unresolved");
    assert!(n_cases > 254 && tunnels > 0);
}

/// Components of `{v ≥ 0}` and `{v < 0}` on an `n³` sampling of the closed cube, reported as
/// "are corners a and b connected".
fn sampled_connectivity(v: &[f64; 8], n: usize) -> [[bool; 8]; 8] {
    let idx = |i: usize, j: usize, k: usize| (k * n + j) * n + i;
    let mut sign = vec![false; n * n * n];
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = [i, j, k].map(|x| x as f64 / (n - 1) as f64);
                sign[idx(i, j, k)] = trilinear(v, p) >= 0.0;
            }
        }
    }
    let mut comp = vec![usize::MAX; n * n * n];
    let mut next = 0;
    for s in 0..comp.len() {
        if comp[s] != usize::MAX {
            continue;
        }
        let mut stack = vec![s];
        comp[s] = next;
        while let Some(c) = stack.pop() {
            let (i, j, k) = (c % n, (c / n) % n, c / (n * n));
            let mut nb = Vec::new();
            if i > 0 {
                nb.push(idx(i - 1, j, k));
            }
            if i + 1 < n {
                nb.push(idx(i + 1, j, k));
            }
            if j > 0 {
                nb.push(idx(i, j - 1, k));
            }
            if j + 1 < n {
                nb.push(idx(i, j + 1, k));
            }
            if k > 0 {
                nb.push(idx(i, j, k - 1));
            }
            if k + 1 < n {
                nb.push(idx(i, j, k + 1));
            }
            for q in nb {
                if comp[q] == usize::MAX && sign[q] == sign[c] {
                    comp[q] = next;
                    stack.push(q);
                }
            }
        }
        next += 1;
    }
    let corner_comp: [usize; 8] = std::array::from_fn(|c| {
        let p = CORNER_POS[c].map(|x| x as usize * (n - 1));
        comp[idx(p[0], p[1], p[2])]
    });
    std::array::from_fn(|a| std::array::from_fn(|b| corner_comp[a] == corner_comp[b]))
}

#[test]
fn interior_test_matches_dense_sampling() {
    let mut rng = Rng(11);
    let (mut checked, mut mismatched, mut tunnels) = (0, 0, 0);
    for trial in 0..6000 {
        let inside = (trial % 254 + 1) as u8;
        let v: [f64; 8] = std::array::from_fn(|c| {
            let m = rng.magnitude();
            if inside >> c & 1 == 1 {
                -m
            } else {
                m
            }
        });
        let dec = decide(&v);
        let topo = topology(&dec);
        if dec.n_joins == 0 && topo.n_loops < 2 {
            continue;
        }
        tunnels += (0..topo.n_patches as usize)
            .filter(|&p| topo.is_annulus(p))
            .count();
        let vol = volume_regions(&dec);
        let sampled = sampled_connectivity(&v, 41);
        checked += 1;
        let ok = (0..8).all(|a| (0..8).all(|b| (vol[a] == vol[b]) == sampled[a][b]));
        if !ok {
            mismatched += 1;
        }
    }
    eprintln!("interior test: {checked} multi-loop cubes, {tunnels} tunnels, {mismatched} disagree with 41³ sampling");
    assert!(tunnels > 20);
    // Sampling misses features thinner than 1/40 of the cube; allow a small residue.
    assert!(mismatched * 200 <= checked, "{mismatched} of {checked}");
}

#[test]
fn ties_resolve_to_outside_consistently() {
    // A face whose saddle is exactly at the iso-value: outside diagonal joined.
    let mut v = [1.0; 8];
    // face z = 0: corners 0 (out), 1 (in), 3 (out), 2 (in): v0 v3 = 1 = v1 v2.
    v[1] = -1.0;
    v[2] = -1.0;
    let dec = decide(&v);
    let f = 4; // z = 0
    assert_eq!(ambiguous_faces(dec.inside) >> f & 1, 1);
    assert_eq!(dec.outside_joined >> f & 1, 1);
    // Zero values are outside.
    let dec = decide(&[0.0, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
    assert_eq!(dec.inside, 0b10);
}

/// Iso-point of edge `e` by linear interpolation of `v` (clamped like the extractor).
pub(crate) fn iso_from_values(v: &[f64; 8], e: u8) -> Vec3 {
    let [a, b] = EDGE_CORNERS[e as usize];
    let (va, vb) = (v[a as usize], v[b as usize]);
    let t = if va == vb { 0.5 } else { va / (va - vb) };
    edge_point(e, t.clamp(1e-3, 1.0 - 1e-3))
}

#[test]
fn value_consistent_cubes_separate_and_embed() {
    let mut rng = Rng(5);
    let mut stats = [0usize; 4];
    for trial in 0..40000 {
        let inside = (trial % 254 + 1) as u8;
        let v: [f64; 8] = std::array::from_fn(|c| {
            let m = rng.magnitude();
            if inside >> c & 1 == 1 {
                -m
            } else {
                m
            }
        });
        let topo = topology(&decide(&v));
        let iso: [Vec3; 12] = std::array::from_fn(|e| iso_from_values(&v, e as u8));
        let nrm: [Vec3; 12] = std::array::from_fn(|_| {
            normalized(Vec3::new(
                rng.unit() - 0.5,
                rng.unit() - 0.5,
                rng.unit() - 0.5,
            ))
            .unwrap_or(Vec3::X)
        });
        let (tris, pos, flags) = triangulate_cube(&topo, &iso, Some(&nrm));
        check_patch_surface(&topo, &tris);
        stats[0] += flags.unseparated as usize;
        stats[1] += flags.unresolved as usize;
        stats[2] += flags.tunnel_split as usize;
        stats[3] += (0..topo.n_patches as usize)
            .filter(|&p| topo.is_annulus(p))
            .count();
        if let Err(e) = no_conflicts(&tris, &pos) {
            panic!("{v:?}: {e}");
        }
    }
    eprintln!(
        "value-consistent cubes: {} unseparated, {} unresolved, {} of {} tunnels split",
        stats[0], stats[1], stats[2], stats[3]
    );
    assert_eq!(stats[0], 0);
    assert_eq!(stats[1], 0);
}

#[test]
fn packed_decisions_round_trip() {
    let mut rng = Rng(11);
    for _ in 0..20_000 {
        let v: [f64; 8] = std::array::from_fn(|_| (rng.unit() - 0.5) * rng.magnitude());
        let dec = decide(&v);
        let x = dec.pack();
        assert!(x < 1 << Decisions::PACKED_BITS);
        assert_eq!(Decisions::unpack(x), dec);
    }
    for inside in 0..=255u8 {
        for dec in all_resolutions(inside) {
            assert_eq!(Decisions::unpack(dec.pack()), dec);
        }
    }
    let full = Decisions {
        inside: 0xA5,
        outside_joined: 0x3F,
        n_joins: 4,
        joins: [[7, 6], [5, 4], [3, 2], [1, 0]],
    };
    assert_eq!(Decisions::unpack(full.pack()), full);
}
