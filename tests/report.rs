//! `MeshReport` and self-intersections on synthetic meshes with known answers: tetrahedron,
//! cube, torus (genus 1), two cubes sharing an edge, bowtie vertices, a flipped face, an open box,
//! folded-over neighbours, duplicate faces, unwelded seams, degenerate faces, coplanar overlap,
//! 10⁴ components; plus brute-force and thread-count determinism checks.

use pleat::mesh::TriMesh;
use pleat::spatial::{
    faces_intersect, find_self_intersections, has_self_intersection, is_collinear,
    self_intersections,
};
use pleat::verify::{MeshReport, ReportOptions};

type P = [f64; 3];

/// Report options analysing topology after exact welding.
const WELD: ReportOptions = ReportOptions {
    self_intersections: true,
    weld: true,
};

fn mesh(p: Vec<P>, t: Vec<[u32; 3]>) -> TriMesh {
    TriMesh::new(p, t).unwrap()
}

fn tetra() -> (Vec<P>, Vec<[u32; 3]>) {
    (
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    )
}

/// Axis-aligned box `[lo, hi]`, 8 vertices, 12 outward triangles.
fn cube_at(lo: P, hi: P) -> (Vec<P>, Vec<[u32; 3]>) {
    let p = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect();
    // Quads as (a, b, c, d) counter-clockwise seen from outside.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (p, t)
}

fn cube() -> (Vec<P>, Vec<[u32; 3]>) {
    cube_at([0.; 3], [1.; 3])
}

/// Appends mesh `b` to `a`.
fn merge(a: &mut (Vec<P>, Vec<[u32; 3]>), b: (Vec<P>, Vec<[u32; 3]>)) {
    let off = a.0.len() as u32;
    a.0.extend(b.0);
    a.1.extend(b.1.into_iter().map(|t| t.map(|v| v + off)));
}

fn torus(n: u32, m: u32) -> (Vec<P>, Vec<[u32; 3]>) {
    let (big, small) = (2.0, 0.5);
    let mut p = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (
                i as f64 * std::f64::consts::TAU / n as f64,
                j as f64 * std::f64::consts::TAU / m as f64,
            );
            let r = big + small * v.cos();
            p.push([r * u.cos(), r * u.sin(), small * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    (p, t)
}

#[track_caller]
fn report(m: (Vec<P>, Vec<[u32; 3]>)) -> MeshReport {
    report_with(m, &ReportOptions::default())
}

/// Computes the report; with `PLEAT_REPORT_DUMP=dir` set, also writes the mesh as OBJ and the
/// report as JSON there (named by the calling test), for comparison with `meshcheck`.
#[track_caller]
fn report_with(m: (Vec<P>, Vec<[u32; 3]>), options: &ReportOptions) -> MeshReport {
    let r = MeshReport::compute_with(&mesh(m.0.clone(), m.1.clone()), options);
    if let Ok(dir) = std::env::var("PLEAT_REPORT_DUMP") {
        let name = format!("{}/line{}", dir, std::panic::Location::caller().line());
        let mut obj = String::new();
        for p in &m.0 {
            obj += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]);
        }
        for t in &m.1 {
            obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        std::fs::write(format!("{name}.obj"), obj).unwrap();
        std::fs::write(format!("{name}.json"), r.to_json()).unwrap();
    }
    r
}

#[test]
fn tetrahedron() {
    let r = report(tetra());
    assert_eq!(
        (r.n_vertices, r.n_faces, r.n_edges, r.n_components),
        (4, 4, 6, 1)
    );
    assert!(r.is_closed && r.is_manifold && r.is_watertight && r.consistently_oriented);
    assert_eq!(r.is_orientable, Some(true));
    assert_eq!(r.euler_characteristic, vec![2]);
    assert_eq!(r.genus, Some(vec![0]));
    assert_eq!(r.total_genus, Some(0));
    assert_eq!(r.n_inward_oriented_components, Some(0));
    assert!((r.signed_volume - 1.0 / 6.0).abs() < 1e-15);
    assert!((r.surface_area - (1.5 + 3f64.sqrt() / 2.0)).abs() < 1e-12);
    assert_eq!(r.n_self_intersecting_pairs, Some(0));
    assert_eq!(r.self_intersection_free, Some(true));
    assert_eq!((r.bbox_min, r.bbox_max), ([0.; 3], [1.; 3]));
}

#[test]
fn cube_and_inward_cube() {
    let r = report(cube());
    assert!(r.is_watertight && r.consistently_oriented && r.self_intersection_free == Some(true));
    assert_eq!((r.n_edges, r.euler_characteristic_total), (18, 2));
    assert!((r.signed_volume - 1.0).abs() < 1e-15 && (r.surface_area - 6.0).abs() < 1e-15);
    let (p, t) = cube();
    let inward: Vec<[u32; 3]> = t.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let r = report((p, inward));
    assert!(r.is_watertight && r.consistently_oriented);
    assert_eq!(r.n_inward_oriented_components, Some(1));
}

#[test]
fn torus_has_genus_one() {
    let r = report(torus(24, 12));
    assert!(r.is_watertight && r.consistently_oriented);
    assert_eq!(r.euler_characteristic, vec![0]);
    assert_eq!((r.genus, r.total_genus), (Some(vec![1]), Some(1)));
    assert_eq!(r.self_intersection_free, Some(true));
    assert_eq!(r.n_inward_oriented_components, Some(0));
}

#[test]
fn two_cubes_sharing_an_edge() {
    let mut m = cube();
    merge(&mut m, cube_at([1., 1., 0.], [2., 2., 1.]));
    let r = report_with(m.clone(), &WELD);
    // Welded: the edge x = y = 1 has four incident faces.
    assert_eq!(r.n_duplicate_points, 2);
    assert_eq!(r.n_nonmanifold_edges, 1);
    assert_eq!(r.max_faces_per_edge, 4);
    assert!(!r.is_closed && !r.is_edge_manifold && !r.is_manifold && !r.is_watertight);
    assert_eq!(r.n_boundary_edges, 0);
    assert_eq!(r.n_components, 1);
    assert_eq!(r.is_orientable, None);
    assert_eq!(r.genus, None);
    // Touching along the shared edge only: allowed.
    assert_eq!(r.self_intersection_free, Some(true));
    // Unwelded: two separate closed cubes, and the seam does not count as an intersection.
    let r = report(m);
    assert_eq!((r.n_components, r.n_nonmanifold_edges), (2, 0));
    assert!(r.is_watertight);
    assert_eq!(r.self_intersection_free, Some(true));
}

#[test]
fn bowtie_vertices() {
    // Two triangles meeting at one vertex.
    let r = report((
        vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [-1., 0., 0.],
            [0., -1., 0.],
        ],
        vec![[0, 1, 2], [0, 3, 4]],
    ));
    assert_eq!(
        (r.n_nonmanifold_vertices, r.n_boundary_edges, r.n_components),
        (1, 6, 1)
    );
    assert!(r.is_edge_manifold && !r.is_vertex_manifold && !r.is_manifold);
    assert_eq!(r.self_intersection_free, Some(true));
    // Two closed tetrahedra sharing a vertex: closed but not manifold.
    let mut m = tetra();
    let (p, t) = tetra();
    merge(
        &mut m,
        (
            p.iter().map(|q| [-q[0], -q[1], -q[2]]).collect(),
            t.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        ),
    );
    let r = report_with(m, &WELD);
    assert_eq!(r.n_nonmanifold_vertices, 1);
    assert!(r.is_closed && !r.is_manifold && !r.is_watertight);
    assert_eq!(r.n_isolated_vertices, 0);
    assert_eq!(r.n_components, 1);
    assert_eq!(r.self_intersection_free, Some(true));
}

#[test]
fn flipped_face() {
    let (p, mut t) = cube();
    t[3] = [t[3][0], t[3][2], t[3][1]];
    let r = report((p, t));
    assert_eq!(r.n_misoriented_edges, 3);
    assert!(!r.consistently_oriented && r.is_watertight);
    assert_eq!(r.is_orientable, Some(true));
    assert_eq!(r.n_inward_oriented_components, None);
    assert_eq!(r.genus, Some(vec![0]));
}

#[test]
fn open_box() {
    let (p, mut t) = cube();
    t.truncate(10); // drop the two triangles of the x = 1 side
    let r = report((p, t));
    assert_eq!((r.n_boundary_edges, r.n_edges), (4, 17));
    assert!(!r.is_closed && r.is_manifold && !r.is_watertight);
    assert_eq!(r.euler_characteristic, vec![1]);
    assert_eq!((r.genus, r.n_inward_oriented_components), (None, None));
    assert_eq!(r.self_intersection_free, Some(true));
}

#[test]
fn folded_over_neighbours() {
    let p = vec![
        [0., 0., 0.],
        [4., 0., 0.],
        [1., 3., 0.],
        [3., 1., 0.],
        [2., -3., 0.],
    ];
    // (0,1,2) and (1,0,3): same side of the shared edge, coplanar: folded.
    let r = report((p.clone(), vec![[0, 1, 2], [1, 0, 3]]));
    assert_eq!(r.n_self_intersecting_pairs, Some(1));
    assert_eq!(r.self_intersection_free, Some(false));
    // (0,1,2) and (1,0,4): flat neighbours.
    let r = report((p, vec![[0, 1, 2], [1, 0, 4]]));
    assert_eq!(r.self_intersection_free, Some(true));
}

#[test]
fn duplicate_faces() {
    let (p, mut t) = tetra();
    t.push(t[0]);
    t.push([t[1][0], t[1][2], t[1][1]]);
    let r = report((p, t));
    assert_eq!(r.n_duplicate_faces, 2);
    assert_eq!(r.n_nonmanifold_edges, 5); // the edges of faces 0 and 1 (they share one)
    assert_eq!(r.n_self_intersecting_pairs, Some(2));
    assert!(!r.is_watertight);
}

#[test]
fn coplanar_overlapping_triangles() {
    let p = vec![
        [0., 0., 0.],
        [4., 0., 0.],
        [0., 4., 0.],
        [1., 1., 0.],
        [5., 1., 0.],
        [1., 5., 0.],
    ];
    let m = mesh(p, vec![[0, 1, 2], [3, 4, 5]]);
    assert_eq!(self_intersections(&m), vec![(0, 1)]);
    assert_eq!(MeshReport::compute(&m).n_components, 2);
}

#[test]
fn unwelded_cube_and_weld_option() {
    // Each side of the cube has its own four vertices.
    let (p, t) = cube();
    let mut q = Vec::new();
    let mut s = Vec::new();
    for pair in t.chunks(2) {
        let base = q.len() as u32;
        let verts = [pair[0][0], pair[0][1], pair[0][2], pair[1][2]];
        q.extend(verts.iter().map(|&v| p[v as usize]));
        s.push([base, base + 1, base + 2]);
        s.push([base, base + 2, base + 3]);
    }
    let m = mesh(q, s);
    let r = MeshReport::compute(&m);
    assert_eq!(
        (
            r.n_components,
            r.n_boundary_edges,
            r.n_duplicate_points,
            r.n_coincident_vertices
        ),
        (6, 24, 16, 24)
    );
    assert!(!r.is_closed && r.self_intersection_free == Some(true));
    let w = MeshReport::compute_with(&m, &WELD);
    assert!(w.is_watertight && w.welded && w.consistently_oriented);
    assert_eq!(
        (
            w.n_components,
            w.n_isolated_vertices,
            w.n_referenced_vertices
        ),
        (1, 0, 8)
    );
    assert_eq!(w.genus, Some(vec![0]));
}

#[test]
fn degenerate_faces() {
    let (mut p, mut t) = tetra();
    p.push([0.5, 0., 0.]); // on the edge 0–1
    t.push([0, 4, 1]); // collinear
    t.push([2, 2, 3]); // repeated index
    let r = report((p, t));
    assert_eq!(
        (r.n_degenerate_faces, r.n_combinatorially_degenerate_faces),
        (2, 1)
    );
    assert_eq!(r.n_degenerate_faces_welded, Some(2));
    assert_eq!(r.n_self_intersecting_pairs, Some(0));
    assert_eq!(r.self_intersection_free, Some(false));
    assert!(!r.is_manifold);
    let (p, t) = tetra();
    assert!(!has_self_intersection(&mesh(p.clone(), t.clone())));
    let mut t2 = t.clone();
    t2.push([0, 0, 1]);
    assert!(has_self_intersection(&mesh(p, t2)));
}

#[test]
fn ten_thousand_components() {
    let mut m = (Vec::new(), Vec::new());
    for i in 0..100 {
        for j in 0..100 {
            let (p, t) = tetra();
            merge(
                &mut m,
                (
                    p.iter()
                        .map(|q| [q[0] + 2.0 * i as f64, q[1] + 2.0 * j as f64, q[2]])
                        .collect(),
                    t,
                ),
            );
        }
    }
    let r = report(m);
    assert_eq!(r.n_components, 10_000);
    assert_eq!(r.euler_characteristic.len(), 10_000);
    assert!(r.euler_characteristic.iter().all(|&c| c == 2));
    assert_eq!(r.total_genus, Some(0));
    assert_eq!(r.n_inward_oriented_components, Some(0));
    assert!(r.is_watertight && r.self_intersection_free == Some(true));
    // The JSON lists at most 100 per-component values, like meshcheck.
    assert!(r.to_json().contains(&format!(
        "\"euler_characteristic\": [{}]",
        vec!["2"; 100].join(",")
    )));
}

#[test]
fn skipping_self_intersections() {
    let (p, t) = cube();
    let r = MeshReport::compute_with(
        &mesh(p, t),
        &ReportOptions {
            self_intersections: false,
            weld: false,
        },
    );
    assert_eq!(
        (
            r.n_self_intersecting_pairs,
            r.self_intersection_free,
            r.n_degenerate_faces_welded
        ),
        (None, None, None)
    );
    let j = r.to_json();
    assert!(
        j.contains("\"n_self_intersecting_pairs\": null")
            && j.contains("\"self_intersection_free\": null")
    );
}

#[test]
fn json_is_one_line_in_meshcheck_key_order() {
    let j = report(tetra()).to_json();
    assert!(!j.contains('\n'));
    assert!(
        j.starts_with("{\"n_vertices\": 4, \"n_faces\": 4, \"n_triangles\": 4, \"welded\": false")
    );
    assert!(j.ends_with("\"n_self_intersecting_pairs\": 0, \"n_degenerate_faces_welded\": 0, \"self_intersection_free\": true}"));
    let keys = [
        "is_closed",
        "is_watertight",
        "n_components",
        "euler_characteristic",
        "genus",
        "bbox_diagonal",
    ];
    let pos: Vec<usize> = keys
        .iter()
        .map(|k| j.find(&format!("\"{k}\":")).unwrap())
        .collect();
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{j}");
    assert!(
        j.contains("\"genus\": [0]")
            && j.contains("\"total_genus\": 0")
            && j.contains("\"is_orientable\": true")
    );
}

// ---------------------------------------------------------------------------------------------
// Randomized: broad phase vs brute force, and thread-count determinism.

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A soup of small random triangles (many crossing), some sharing a vertex or an edge with the
/// previous triangle, coordinates on a coarse grid so that exact duplicates, touching and
/// coplanar cases occur.
fn random_soup(n: usize, seed: u64, spread: f64) -> TriMesh {
    let mut rng = Rng(seed);
    let side = spread * 4.0 * (n as f64 / 600.0).cbrt(); // spread 1: ~50 overlaps per triangle
    let mut p: Vec<P> = Vec::new();
    let mut t: Vec<[u32; 3]> = Vec::new();
    let grid = |x: f64| (x * 16.0).round() / 16.0;
    for _ in 0..n {
        // Half of the triangles start at a corner of the previous one and may share its corners.
        let prev = t.last().copied().filter(|_| rng.next() < 0.5);
        let c = match prev {
            Some(q) => p[q[0] as usize],
            None => [rng.next() * side, rng.next() * side, rng.next() * side],
        };
        let mut tri = [0u32; 3];
        for v in &mut tri {
            match prev {
                Some(q) if rng.next() < 0.3 => *v = q[(rng.next() * 3.0) as usize % 3],
                _ => {
                    p.push([0, 1, 2].map(|k| grid(c[k] + rng.next() - 0.5)));
                    *v = p.len() as u32 - 1;
                }
            }
        }
        t.push(tri);
    }
    TriMesh::new(p, t).unwrap()
}

fn brute_force(m: &TriMesh) -> (Vec<(u32, u32)>, Vec<u32>) {
    let w = pleat::mesh::ExactWeld::compute(m.positions());
    let tw = w.apply(m.triangles());
    let p = m.positions();
    let deg: Vec<bool> = tw
        .iter()
        .map(|t| is_collinear(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]))
        .collect();
    let mut pairs = Vec::new();
    for f in 0..tw.len() {
        for g in f + 1..tw.len() {
            if !deg[f] && !deg[g] && faces_intersect(p, tw[f], tw[g]) {
                pairs.push((f as u32, g as u32));
            }
        }
    }
    (
        pairs,
        (0..tw.len() as u32).filter(|&f| deg[f as usize]).collect(),
    )
}

#[test]
fn self_intersections_match_brute_force() {
    for seed in 1..6 {
        let m = random_soup(600, seed, 1.0);
        let si = find_self_intersections(&m);
        let (pairs, deg) = brute_force(&m);
        assert!(pairs.len() > 50, "seed {seed}: only {} pairs", pairs.len());
        assert_eq!(si.pairs, pairs, "seed {seed}");
        assert_eq!(si.degenerate, deg, "seed {seed}");
        assert_eq!(
            has_self_intersection(&m),
            !pairs.is_empty() || !deg.is_empty()
        );
    }
}

#[test]
fn results_do_not_depend_on_thread_count() {
    let m = random_soup(20_000, 99, 1.0);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| (find_self_intersections(&m), MeshReport::compute(&m)))
    };
    let one = run(1);
    assert!(one.0.pairs.len() > 10_000, "{}", one.0.pairs.len());
    for threads in [2, 3, 8] {
        assert_eq!(run(threads), one, "{threads} threads");
    }
}
