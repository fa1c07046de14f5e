//! Integration tests of `lowpoly::offset_surface` on synthetic soups generated here, plus the
//! shared corpus when it is present. Every guarantee is checked by code independent of this
//! stage: `MeshReport` (run by the stage's verification, recorded in `OffsetReport::verified`) and the
//! edge/vertex check and brute-force distances of this file.

use std::collections::HashMap;

#[path = "common/meshcheck.rs"]
mod meshcheck;

use pleat::lowpoly::OffsetReport;
use pleat::lowpoly::{offset_surface, offset_surface_with_progress, OffsetDistance, OffsetParams};
use pleat::mesh::TriMesh;
use pleat::Error;

type V3 = [f64; 3];

// ---------------------------------------------------------------------------------------------
// Generators

/// Deterministic SplitMix64.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
}

#[derive(Default)]
struct Soup {
    pos: Vec<V3>,
    tris: Vec<[u32; 3]>,
}

impl Soup {
    fn add(&mut self, pos: &[V3], tris: &[[u32; 3]]) {
        let base = self.pos.len() as u32;
        self.pos.extend_from_slice(pos);
        self.tris.extend(tris.iter().map(|t| t.map(|v| v + base)));
    }

    fn box_(&mut self, lo: V3, hi: V3) {
        let p: Vec<V3> = (0..8)
            .map(|i| {
                [
                    if i & 1 == 1 { hi[0] } else { lo[0] },
                    if i & 2 == 2 { hi[1] } else { lo[1] },
                    if i & 4 == 4 { hi[2] } else { lo[2] },
                ]
            })
            .collect();
        self.add(&p, &BOX_TRIS);
    }

    /// Open cylinder from `a` to `b` (no caps: a dirty, non-closed part).
    fn cylinder(&mut self, a: V3, b: V3, r: f64, seg: usize) {
        let axis = sub(b, a);
        let helper = if axis[0].abs() < 0.9 * norm(axis) {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let u = unit(cross(axis, helper));
        let v = unit(cross(axis, u));
        let mut p = Vec::new();
        for i in 0..seg {
            let t = i as f64 / seg as f64 * std::f64::consts::TAU;
            let off = add(scale(u, r * t.cos()), scale(v, r * t.sin()));
            p.push(add(a, off));
            p.push(add(b, off));
        }
        let mut t = Vec::new();
        for i in 0..seg as u32 {
            let j = (i + 1) % seg as u32;
            t.push([2 * i, 2 * j, 2 * i + 1]);
            t.push([2 * j, 2 * j + 1, 2 * i + 1]);
        }
        self.add(&p, &t);
    }

    fn quad(&mut self, c: V3, u: V3, v: V3) {
        let p = [
            sub(sub(c, u), v),
            sub(add(c, u), v),
            add(add(c, u), v),
            add(sub(c, u), v),
        ];
        self.add(&p, &[[0, 1, 2], [0, 2, 3]]);
    }

    fn mesh(self) -> TriMesh {
        TriMesh::new(self.pos, self.tris).expect("valid soup")
    }
}

const BOX_TRIS: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3],
    [4, 5, 6],
    [5, 7, 6],
    [0, 1, 4],
    [1, 5, 4],
    [2, 6, 3],
    [3, 6, 7],
    [0, 4, 2],
    [2, 4, 6],
    [1, 3, 5],
    [3, 7, 5],
];

fn overlapping_boxes() -> TriMesh {
    let mut s = Soup::default();
    s.box_([0.0, 0.0, 0.0], [2.0, 1.0, 1.0]);
    s.box_([1.0, 0.5, 0.5], [3.0, 1.5, 1.2]);
    s.box_([0.5, -0.5, 0.2], [1.5, 2.0, 0.8]);
    s.mesh()
}

/// A "tree": hundreds of intersecting open cylinders and quad leaves.
fn tree(n_branches: usize) -> TriMesh {
    let mut rng = Rng(42);
    let mut s = Soup::default();
    let mut tips = vec![([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.08)];
    s.cylinder([0.0, 0.0, -1.0], [0.0, 0.0, 0.0], 0.1, 12);
    for _ in 0..n_branches {
        let k = (rng.unit() * tips.len() as f64) as usize % tips.len();
        let (base, dir, r) = tips[k];
        let d = unit(add(
            dir,
            [
                rng.range(-0.8, 0.8),
                rng.range(-0.8, 0.8),
                rng.range(-0.3, 0.5),
            ],
        ));
        let len = rng.range(0.15, 0.4);
        let end = add(base, scale(d, len));
        s.cylinder(base, end, r, 8);
        let r2 = (r * 0.8).max(0.01);
        tips.push((end, d, r2));
        if rng.unit() < 0.5 {
            let u = scale(unit(cross(d, [0.3, 0.5, 0.8])), 0.06);
            s.quad(end, u, scale(unit(cross(d, u)), 0.04));
        }
    }
    s.mesh()
}

/// A box with some faces flipped and some duplicated (possibly flipped again).
fn flipped_and_duplicated() -> TriMesh {
    let mut s = Soup::default();
    s.box_([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    for t in s.tris.iter_mut().step_by(3) {
        t.swap(1, 2);
    }
    let dup: Vec<[u32; 3]> = s
        .tris
        .iter()
        .step_by(2)
        .map(|t| [t[0], t[2], t[1]])
        .collect();
    s.tris.extend(dup);
    let again = s.tris[0];
    s.tris.push(again);
    s.mesh()
}

fn single_triangle() -> TriMesh {
    TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.2, 0.9, 0.1]],
        vec![[0, 1, 2]],
    )
    .unwrap()
}

fn point_like_triangle() -> TriMesh {
    TriMesh::new(
        vec![
            [1.0, 2.0, 3.0],
            [1.0 + 1e-12, 2.0, 3.0],
            [1.0, 2.0 + 1e-12, 3.0],
        ],
        vec![[0, 1, 2]],
    )
    .unwrap()
}

fn coplanar_overlapping() -> TriMesh {
    let mut s = Soup::default();
    for i in 0..6 {
        let a = i as f64 * 0.5;
        let c = [a.cos() * 0.2, a.sin() * 0.2, 0.0];
        s.add(
            &[
                add(c, [-1.0, -0.6, 0.0]),
                add(c, [1.0, -0.6, 0.0]),
                add(c, [0.0, 1.0, 0.0]),
            ],
            &[[0, 1, 2]],
        );
    }
    // An exact duplicate and a reversed copy on the same plane.
    let first = s.tris[0];
    s.tris.push(first);
    s.tris.push([first[0], first[2], first[1]]);
    s.mesh()
}

/// `n³`-ish lattice of small tetrahedra: many separate components.
fn many_components(n: usize) -> TriMesh {
    let mut s = Soup::default();
    let side = (n as f64).cbrt().ceil() as usize;
    let mut count = 0;
    'outer: for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                if count == n {
                    break 'outer;
                }
                let c = [i as f64, j as f64, k as f64];
                let p = [
                    c,
                    add(c, [0.2, 0.0, 0.0]),
                    add(c, [0.0, 0.2, 0.0]),
                    add(c, [0.0, 0.0, 0.2]),
                ];
                s.add(&p, &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]);
                count += 1;
            }
        }
    }
    s.mesh()
}

fn unit_cube() -> TriMesh {
    let mut s = Soup::default();
    s.box_([-1.0; 3], [1.0; 3]);
    s.mesh()
}

// ---------------------------------------------------------------------------------------------
// Independent checks

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
fn unit(a: V3) -> V3 {
    scale(a, 1.0 / norm(a))
}

/// Watertight (every undirected edge in exactly two faces, used once in each direction) and
/// manifold (one fan of faces around every vertex). Independent of the library's own check.
fn edge_and_vertex_check(m: &TriMesh) -> Result<(), String> {
    let mut dir: HashMap<(u32, u32), u32> = HashMap::new();
    for t in m.triangles() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(format!("degenerate face {t:?}"));
        }
        for k in 0..3 {
            *dir.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &c) in &dir {
        if c != 1 || dir.get(&(b, a)) != Some(&1) {
            return Err(format!(
                "edge {a}-{b}: {c} forward, {:?} backward",
                dir.get(&(b, a))
            ));
        }
    }
    let mut ring: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    for t in m.triangles() {
        for k in 0..3 {
            ring.entry(t[k])
                .or_default()
                .push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    for (v, r) in ring {
        let next: HashMap<u32, u32> = r.iter().copied().collect();
        let mut cur = r[0].0;
        for _ in 0..r.len() {
            cur = next[&cur];
        }
        let mut seen = 1;
        let mut c = next[&r[0].0];
        while c != r[0].0 {
            c = next[&c];
            seen += 1;
        }
        if seen != r.len() || cur != r[0].0 {
            return Err(format!(
                "vertex {v}: {} faces in more than one fan",
                r.len()
            ));
        }
    }
    Ok(())
}

fn closest_on_triangle(p: V3, a: V3, b: V3, c: V3) -> V3 {
    // Minimum over the plane projection (if inside) and the three edges.
    let n = cross(sub(b, a), sub(c, a));
    let mut best = seg_closest(p, a, b);
    for q in [seg_closest(p, b, c), seg_closest(p, c, a)] {
        if norm(sub(q, p)) < norm(sub(best, p)) {
            best = q;
        }
    }
    let nn = dot(n, n);
    if nn > 0.0 {
        let q = sub(p, scale(n, dot(sub(p, a), n) / nn));
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(u, v)| dot(cross(sub(v, u), sub(q, u)), n) >= 0.0);
        if inside && norm(sub(q, p)) < norm(sub(best, p)) {
            best = q;
        }
    }
    best
}

fn seg_closest(p: V3, a: V3, b: V3) -> V3 {
    let ab = sub(b, a);
    let l = dot(ab, ab);
    if l == 0.0 {
        return a;
    }
    add(a, scale(ab, (dot(sub(p, a), ab) / l).clamp(0.0, 1.0)))
}

fn brute_distance(input: &TriMesh, p: V3) -> f64 {
    (0..input.triangle_count())
        .map(|t| {
            let [a, b, c] = input.triangle_positions(t);
            norm(sub(closest_on_triangle(p, a, b, c), p))
        })
        .fold(f64::INFINITY, f64::min)
}

/// Max |f(v) − d| / d over (a deterministic sample of at most `cap` of) the output vertices.
fn max_deviation_over_d(input: &TriMesh, out: &TriMesh, d: f64, cap: usize) -> f64 {
    let n = out.vertex_count();
    let stride = n.div_ceil(cap).max(1);
    out.positions()
        .iter()
        .step_by(stride)
        .map(|&p| (brute_distance(input, p) - d).abs() / d)
        .fold(0.0, f64::max)
}

/// Runs the offset, checks the guarantees, returns the mesh, stats and max deviation / d.
fn run_and_check(
    name: &str,
    input: &TriMesh,
    params: &OffsetParams,
    sample: usize,
) -> (TriMesh, OffsetReport, f64) {
    let (out, stats) = offset_surface(input, params).unwrap_or_else(|e| panic!("{name}: {e}"));
    edge_and_vertex_check(&out).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(
        stats.verified.watertight == Some(true) && stats.verified.manifold == Some(true),
        "{name}: {:?}",
        stats.verified
    );
    let (d, h) = (stats.d, stats.h);
    let dev = max_deviation_over_d(input, &out, d, sample);
    assert!(
        dev * d <= h * (1.0 + 1e-9),
        "{name}: deviation {dev} d > h = {} d",
        h / d
    );
    eprintln!(
        "{name:<28} {:>8} tris, {:>3} components kept ({} removed), max |f−d|/d = {dev:.4}, {:.3} s",
        out.triangle_count(),
        stats.interior.map_or(1, |i| i.components - i.components_removed),
        stats.interior.map_or(0, |i| i.components_removed),
        stats.total_seconds()
    );
    (out, stats, dev)
}

fn np(n: f64) -> OffsetParams {
    OffsetParams {
        distance: OffsetDistance::ScreenSize(n),
        ..Default::default()
    }
}

// ---------------------------------------------------------------------------------------------
// Tests

#[test]
fn synthetic_soups_give_closed_manifold_offsets() {
    let cases: Vec<(&str, TriMesh, OffsetParams)> = vec![
        ("overlapping boxes", overlapping_boxes(), np(100.0)),
        (
            "flipped + duplicated faces",
            flipped_and_duplicated(),
            np(60.0),
        ),
        ("single triangle", single_triangle(), np(80.0)),
        (
            "point-like triangle",
            point_like_triangle(),
            OffsetParams {
                distance: OffsetDistance::Absolute(0.01),
                ..Default::default()
            },
        ),
        ("coplanar overlapping", coplanar_overlapping(), np(100.0)),
    ];
    for (name, mesh, params) in cases {
        for features in [true, false] {
            let p = OffsetParams {
                features,
                ..params.clone()
            };
            run_and_check(name, &mesh, &p, 4000);
        }
    }
}

#[test]
fn tree_of_hundreds_of_cylinders_and_quads() {
    let mesh = tree(300);
    assert!(mesh.triangle_count() > 4000);
    for n in [50.0, 200.0] {
        let (_, stats, _) = run_and_check("tree", &mesh, &np(n), 1500);
        assert_eq!(stats.extraction.cells_unresolved, 0);
    }
}

#[test]
fn ten_thousand_components() {
    let mesh = many_components(10_000);
    let (out, stats, _) = run_and_check("10^4 components", &mesh, &np(150.0), 300);
    // Separated tetrahedra stay separate: one outer shell each.
    let interior = stats.interior.expect("interior removal ran");
    let kept = interior.components - interior.components_removed;
    assert_eq!(kept, 10_000);
    assert!(out.triangle_count() > 10_000);
}

/// Area-weighted normal error of `out` against the true offset of `input`: at each face
/// centroid `g`, the true normal is `(g − g*)/‖g − g*‖` with `g*` the closest input point
/// (brute force). Returns (mean angle in degrees, area fraction with error above 20°).
fn normal_error(input: &TriMesh, out: &TriMesh) -> (f64, f64) {
    let (mut sum, mut area, mut big) = (0.0, 0.0, 0.0);
    for t in 0..out.triangle_count() {
        let [a, b, c] = out.triangle_positions(t);
        let n = cross(sub(b, a), sub(c, a));
        let w = norm(n);
        if w == 0.0 {
            continue;
        }
        let g = scale(add(add(a, b), c), 1.0 / 3.0);
        let mut best = g;
        let mut bd = f64::INFINITY;
        for f in 0..input.triangle_count() {
            let [p, q, r] = input.triangle_positions(f);
            let x = closest_on_triangle(g, p, q, r);
            let dd = norm(sub(x, g));
            if dd < bd {
                bd = dd;
                best = x;
            }
        }
        let e = dot(scale(n, 1.0 / w), unit(sub(g, best)))
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        sum += e * w;
        area += w;
        if e > 20.0 {
            big += w;
        }
    }
    (sum / area, big / area)
}

/// Three crossed boxes: their offset has sharp concave creases.
fn crossed_boxes() -> TriMesh {
    let mut s = Soup::default();
    s.box_([-1.0, -0.3, -0.3], [1.0, 0.3, 0.3]);
    s.box_([-0.3, -1.0, -0.3], [0.3, 1.0, 0.3]);
    s.box_([-0.3, -0.3, -1.0], [0.3, 0.3, 1.0]);
    s.mesh()
}

#[test]
fn sharp_features_and_normal_error() {
    for (name, input, n) in [
        ("cube", unit_cube(), 40.0),
        ("crossed boxes", crossed_boxes(), 60.0),
    ] {
        let mut err = Vec::new();
        for features in [false, true] {
            let p = OffsetParams { features, ..np(n) };
            let (out, st, _) = run_and_check(name, &input, &p, 2000);
            eprintln!(
                "  flips {:?}, feature vertices kept {:?}",
                st.features.map(|f| f.flips),
                st.features.map(|f| f.feature_vertices_kept)
            );
            err.push(normal_error(&input, &out));
        }
        eprintln!(
            "{name}, n_p = {n}: mean normal error plain MC33 {:.3}° (area > 20°: {:.2}%), with features {:.3}° ({:.2}%)",
            err[0].0,
            100.0 * err[0].1,
            err[1].0,
            100.0 * err[1].1
        );
        if name == "crossed boxes" {
            // Creases: the feature vertices remove most of the chamfered (badly oriented) area.
            assert!(err[1].1 < err[0].1);
        }
    }
}

#[test]
fn invalid_parameters_are_rejected_before_work() {
    let m = single_triangle();
    for bad in [0.0, -3.0, f64::NAN, f64::INFINITY] {
        let e = offset_surface(&m, &np(bad)).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument(_)), "{bad}: {e}");
        let p = OffsetParams {
            distance: OffsetDistance::Absolute(bad),
            ..Default::default()
        };
        assert!(matches!(
            offset_surface(&m, &p),
            Err(Error::InvalidArgument(_))
        ));
    }
    let p = OffsetParams {
        voxel_scale: 0.0,
        ..Default::default()
    };
    assert!(matches!(
        offset_surface(&m, &p),
        Err(Error::InvalidArgument(_))
    ));
    let p = OffsetParams {
        theta0_deg: 200.0,
        ..Default::default()
    };
    assert!(matches!(
        offset_surface(&m, &p),
        Err(Error::InvalidArgument(_))
    ));
    // A point: the screen size has no diagonal to refer to.
    let pt = TriMesh::new(vec![[1.0; 3]; 3], vec![[0, 1, 2]]).unwrap();
    assert!(matches!(
        offset_surface(&pt, &np(100.0)),
        Err(Error::InvalidArgument(_))
    ));
    // Over the memory budget: clear error, and the callback is never reached.
    let p = OffsetParams {
        memory_budget_bytes: 1 << 20,
        ..np(5000.0)
    };
    let mut called = false;
    let e = offset_surface_with_progress(&unit_cube(), &p, &mut |_| {
        called = true;
        true
    })
    .unwrap_err();
    assert!(matches!(e, Error::LimitExceeded(_)), "{e}");
    assert!(!called);
    let p = OffsetParams {
        memory_budget_bytes: 1 << 40,
        ..np(1e9)
    };
    assert!(matches!(
        offset_surface(&unit_cube(), &p),
        Err(Error::LimitExceeded(_))
    ));
}

#[test]
fn progress_is_monotone_and_cancel_is_prompt() {
    let m = overlapping_boxes();
    let mut fr = Vec::new();
    offset_surface_with_progress(&m, &np(60.0), &mut |p| {
        fr.push(p.fraction);
        true
    })
    .unwrap();
    assert!(fr.windows(2).all(|w| w[0] <= w[1]) && fr.last() == Some(&1.0));
    for stop_at in [1, 3, 6] {
        let mut calls = 0;
        let e = offset_surface_with_progress(&m, &np(60.0), &mut |_| {
            calls += 1;
            calls < stop_at
        })
        .unwrap_err();
        assert_eq!(e, Error::Cancelled);
        assert_eq!(calls, stop_at);
    }
}

#[test]
fn output_is_deterministic() {
    let m = tree(60);
    let a = offset_surface(&m, &np(120.0)).unwrap().0;
    let b = offset_surface(&m, &np(120.0)).unwrap().0;
    assert_eq!(a, b);
}

#[test]
fn corpus_offsets_are_closed_manifolds() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes");
    let dir = if dir.is_dir() {
        dir
    } else {
        std::path::PathBuf::from("/work/shared/meshes")
    };
    if !dir.is_dir() {
        eprintln!("corpus not found at {}: skipping", dir.display());
        return;
    }
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    files.retain(|p| {
        p.extension()
            .is_some_and(|e| ["obj", "ply", "off", "stl"].contains(&e.to_string_lossy().as_ref()))
    });
    files.sort();
    for f in files {
        let Some(mesh) = load(&f) else { continue };
        if mesh.triangle_count() > 200_000 {
            continue;
        }
        // n_p = 200, the finest grid and the slowest, runs with `PLEAT_FULL_TESTS=1` (as
        // `.ci/run` does); the CGAL checker at n_p ≥ 100 (seconds per output) with
        // `PLEAT_FULL_CORPUS=1`.
        let full = std::env::var_os("PLEAT_FULL_TESTS").is_some();
        let sizes: &[f64] = if full {
            &[50.0, 100.0, 200.0]
        } else {
            &[50.0, 100.0]
        };
        for &n in sizes {
            let name = format!("{} @{n}", f.file_name().unwrap().to_string_lossy());
            let (out, _, _) = run_and_check(&name, &mesh, &np(n), 200);
            if n <= 50.0 || std::env::var_os("PLEAT_FULL_CORPUS").is_some() {
                meshcheck::assert_valid(&out, &name);
            }
        }
    }
}

fn load(path: &std::path::Path) -> Option<TriMesh> {
    pleat::mesh::io::read_mesh(path).ok()
}
