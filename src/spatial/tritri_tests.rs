//! Unit tests of the exact intersection predicates: hand-made configurations (touching at a
//! vertex / edge, coplanar, near-degenerate, ulp-level misses) checked under every vertex
//! permutation of both triangles and both argument orders, and randomized comparisons with an
//! independent exact oracle (separating-axis theorem in integer arithmetic).

use super::*;

type T3 = [[f64; 3]; 3];

/// The 6 vertex orders of a triangle (3 rotations × 2 orientations).
fn perms(t: &T3) -> [T3; 6] {
    [
        [t[0], t[1], t[2]],
        [t[1], t[2], t[0]],
        [t[2], t[0], t[1]],
        [t[0], t[2], t[1]],
        [t[2], t[1], t[0]],
        [t[1], t[0], t[2]],
    ]
}

/// Asserts `triangles_intersect` gives `expected` for every vertex order of both triangles and
/// both argument orders (symmetry and rotation/reflection invariance).
fn check_tt(a: T3, b: T3, expected: bool, what: &str) {
    for pa in perms(&a) {
        for pb in perms(&b) {
            assert_eq!(
                triangles_intersect(&pa, &pb),
                expected,
                "{what}: a={pa:?} b={pb:?}"
            );
            assert_eq!(
                triangles_intersect(&pb, &pa),
                expected,
                "{what} (swapped): a={pa:?} b={pb:?}"
            );
        }
    }
}

fn check_st(s: [[f64; 3]; 2], t: T3, expected: bool, what: &str) {
    for pt in perms(&t) {
        assert_eq!(
            segment_triangle_intersect(s, &pt),
            expected,
            "{what}: s={s:?} t={pt:?}"
        );
        assert_eq!(
            segment_triangle_intersect([s[1], s[0]], &pt),
            expected,
            "{what} (reversed): s={s:?} t={pt:?}"
        );
    }
}

const XY: T3 = [[0., 0., 0.], [4., 0., 0.], [0., 4., 0.]];

fn up(x: f64) -> f64 {
    f64::from_bits(x.to_bits() + 1)
}

#[test]
fn orientation_convention() {
    let o = [0., 0., 0.];
    assert_eq!(orient3d(o, [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]), 1);
    assert_eq!(orient3d(o, [0., 1., 0.], [1., 0., 0.], [0., 0., 1.]), -1);
    assert_eq!(orient3d(o, [1., 0., 0.], [0., 1., 0.], [5., 7., 0.]), 0);
    assert_eq!(orient2d([0., 0.], [1., 0.], [0., 1.]), 1);
    assert_eq!(orient2d([0., 0.], [1., 0.], [2., 0.]), 0);
    // Near-degenerate: a sliver one ulp off the plane is decided exactly.
    let tiny = [0.1, 0.2, f64::from_bits(1)];
    assert_eq!(orient3d(o, [1., 0., 0.], [0., 1., 0.], tiny), 1);
    assert_eq!(
        orient3d(
            o,
            [1., 0., 0.],
            [0., 1., 0.],
            [0.1, 0.2, -f64::from_bits(1)]
        ),
        -1
    );
}

#[test]
fn collinearity() {
    assert!(is_collinear([0., 0., 0.], [1., 1., 1.], [2., 2., 2.]));
    assert!(is_collinear([0., 0., 0.], [0., 0., 0.], [2., 3., 4.]));
    assert!(is_collinear([1., 2., 3.], [1., 2., 3.], [1., 2., 3.]));
    assert!(!is_collinear([0., 0., 0.], [1., 1., 1.], [2., 2., up(2.)]));
    assert!(!is_collinear(XY[0], XY[1], XY[2]));
    // Collinear in every projection but one.
    assert!(!is_collinear([0., 0., 0.], [1., 0., 0.], [1., 0., 1e-300]));
    // Long needle: 0.1·k are not exactly collinear in binary floating point.
    assert!(!is_collinear(
        [0.1, 0.2, 0.3],
        [0.2, 0.4, 0.6],
        [0.3, 0.6, 0.9]
    ));
    assert!(is_collinear([0.5, 1., 1.5], [1., 2., 3.], [2., 4., 6.]));
}

#[test]
fn coplanar_same_side_predicate() {
    let (p, q) = ([0., 0., 0.], [1., 1., 1.]);
    assert!(coplanar_same_side(p, q, [1., 0., 0.], [2., 1., 1.]));
    assert!(!coplanar_same_side(p, q, [1., 0., 0.], [0., 1., 1.]));
    assert!(!coplanar_same_side(p, q, [1., 0., 0.], [3., 3., 3.])); // s on the line
}

#[test]
fn separated_and_crossing() {
    let above = [[0., 0., 1.], [4., 0., 1.], [0., 4., 1.]];
    check_tt(XY, above, false, "parallel planes");
    let pierce = [[1., 1., -1.], [1., 1., 1.], [2., 1., 0.]];
    check_tt(XY, pierce, true, "piercing interior");
    let miss = [[5., 5., -1.], [5., 5., 1.], [6., 5., 0.]];
    check_tt(XY, miss, false, "crossing the plane outside");
    // Crossing through an edge line beyond the triangle.
    let beyond = [[5., -1., -1.], [5., -1., 1.], [5., 1., 0.]];
    check_tt(XY, beyond, false, "crossing the edge line outside the edge");
    // Interlocked like chain links (each pierces the other).
    let a = [[0., 0., 0.], [4., 0., 0.], [2., 0., 4.]];
    let b = [[2., -2., 1.], [2., 2., 1.], [2., 0., -3.]];
    check_tt(a, b, true, "interlocked");
}

#[test]
fn touching_counts() {
    // Vertex of b exactly on the interior of a.
    check_tt(
        XY,
        [[1., 1., 0.], [1., 1., 3.], [2., 1., 3.]],
        true,
        "vertex on face",
    );
    // Vertex on vertex.
    check_tt(
        XY,
        [[4., 0., 0.], [5., 0., 1.], [5., 1., 1.]],
        true,
        "vertex on vertex",
    );
    // Vertex of b on an edge of a.
    check_tt(
        XY,
        [[2., 0., 0.], [2., -1., 1.], [3., -1., 1.]],
        true,
        "vertex on edge",
    );
    // Edge of b lying in a's plane crossing a's boundary.
    check_tt(
        XY,
        [[1., 1., 0.], [6., 1., 0.], [3., 1., 5.]],
        true,
        "edge in plane",
    );
    // Edge of b lying in a's plane entirely outside.
    check_tt(
        XY,
        [[5., 5., 0.], [6., 5., 0.], [5., 5., 5.]],
        false,
        "edge in plane outside",
    );
    // Edge–edge crossing at a single point, non-coplanar.
    check_tt(
        XY,
        [[1., -1., 0.], [1., 1., 0.], [1., 0., 2.]],
        true,
        "edge crossing interior",
    );
    check_tt(
        XY,
        [[2., -1., 1.], [2., 1., -1.], [2., -1., -1.]],
        true,
        "edge touching edge",
    );
    // Same, moved off by one ulp: now disjoint.
    check_tt(
        XY,
        [[2., -1., 1.], [2., 1., -1.], [2., 0., up(1.0)]],
        true,
        "still crossing",
    );
    let x = -f64::from_bits(1);
    check_tt(
        XY,
        [[1., 1., x], [1., 1., -3.], [2., 1., -3.]],
        false,
        "one denormal below the face",
    );
    check_tt(
        XY,
        [[1., 1., 0.0], [1., 1., -3.], [2., 1., -3.]],
        true,
        "exactly on the face",
    );
    // Vertex just outside the hypotenuse x + y = 4 (by one ulp in x).
    check_tt(
        XY,
        [[up(2.), 2., 0.], [3., 3., 3.], [3., 2., 3.]],
        false,
        "ulp outside hypotenuse",
    );
    check_tt(
        XY,
        [[2., 2., 0.], [3., 3., 3.], [3., 2., 3.]],
        true,
        "on hypotenuse",
    );
}

#[test]
fn coplanar_cases() {
    check_tt(XY, XY, true, "identical");
    check_tt(
        XY,
        [[1., 1., 0.], [5., 1., 0.], [1., 5., 0.]],
        true,
        "overlap",
    );
    check_tt(
        XY,
        [[1., 1., 0.], [2., 1., 0.], [1., 2., 0.]],
        true,
        "contained",
    );
    check_tt(
        XY,
        [[4., 0., 0.], [6., 0., 0.], [5., 1., 0.]],
        true,
        "touch at vertex",
    );
    check_tt(
        XY,
        [[0., 0., 0.], [4., 0., 0.], [2., -3., 0.]],
        true,
        "shared edge, opposite sides",
    );
    check_tt(
        XY,
        [[1., 0., 0.], [3., 0., 0.], [2., -3., 0.]],
        true,
        "touch along part of an edge",
    );
    check_tt(
        XY,
        [[5., 0., 0.], [6., 0., 0.], [5., 1., 0.]],
        false,
        "disjoint",
    );
    check_tt(
        XY,
        [[2., 2.5, 0.], [3., 2.5, 0.], [3., 3., 0.]],
        false,
        "disjoint near hypotenuse",
    );
    check_tt(
        XY,
        [[-1., 6., 0.], [6., -1., 0.], [5., 5., 0.]],
        false,
        "parallel band outside",
    );
    check_tt(
        XY,
        [[-1., 5., 0.], [5., -1., 0.], [5., 5., 0.]],
        true,
        "edge on the hypotenuse line",
    );
    check_tt(
        XY,
        [[-1., 5., 0.], [5., -1., 0.], [0., 0., 0.]],
        true,
        "star of david-like crossing",
    );
    // Tilted common plane x + y + z = 1.
    let a = [[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    check_tt(
        a,
        [[0.5, 0.5, 0.], [0.5, 0., 0.5], [2., 0., -1.]],
        true,
        "tilted overlap",
    );
    check_tt(
        a,
        [[1., 0., 0.], [2., 0., -1.], [2., -1., 0.]],
        true,
        "tilted vertex touch",
    );
    check_tt(
        a,
        [[1.5, 0., -0.5], [2., 0., -1.], [2., -1., 0.]],
        false,
        "tilted disjoint",
    );
}

#[test]
fn segment_triangle_cases() {
    check_st([[1., 1., -1.], [1., 1., 1.]], XY, true, "through interior");
    check_st([[1., 1., 0.], [1., 1., 1.]], XY, true, "endpoint on face");
    check_st(
        [[1., 1., up(0.)], [1., 1., 1.]],
        XY,
        false,
        "endpoint a denormal above",
    );
    check_st([[4., 0., -1.], [4., 0., 1.]], XY, true, "through a vertex");
    check_st(
        [[2., 2., -1.], [2., 2., 1.]],
        XY,
        true,
        "through the hypotenuse",
    );
    check_st([[5., 5., -1.], [5., 5., 1.]], XY, false, "outside");
    check_st([[1., 1., 0.], [2., 1., 0.]], XY, true, "coplanar inside");
    check_st([[-1., 1., 0.], [5., 1., 0.]], XY, true, "coplanar across");
    check_st(
        [[-1., 6., 0.], [6., -1., 0.]],
        XY,
        false,
        "coplanar parallel outside",
    );
    check_st(
        [[-1., 5., 0.], [5., -1., 0.]],
        XY,
        true,
        "coplanar along the hypotenuse line",
    );
    check_st(
        [[-1., 5., 0.], [4., 0., 0.]],
        XY,
        true,
        "coplanar ending on a vertex",
    );
    check_st(
        [[1., 1., 0.], [1., 1., 0.]],
        XY,
        true,
        "point segment on face",
    );
    check_st(
        [[1., 1., 1.], [1., 1., 1.]],
        XY,
        false,
        "point segment off face",
    );
}

#[test]
fn mesh_face_rules() {
    // Shared edge (0, 1) along x, third vertices in z = 0.
    let p = vec![
        [0., 0., 0.],  // 0
        [4., 0., 0.],  // 1
        [1., 3., 0.],  // 2
        [2., -3., 0.], // 3: flat neighbour across the edge
        [3., 2., 0.],  // 4: folded on top of face (0,1,2)
        [2., 1., 3.],  // 5: dihedral neighbour
        [0., 0., 0.],  // 6 (unused duplicate position; faces are compared by index)
        [-3., 1., 0.], // 7: fan neighbour around vertex 0
        [2., 2., -1.], // 8
        [2., 2., 1.],  // 9
    ];
    let f = [0u32, 1, 2];
    let check = |a: [u32; 3], b: [u32; 3], expected: bool, what: &str| {
        for r in 0..3 {
            let ra = [a[r], a[(r + 1) % 3], a[(r + 2) % 3]];
            for s in 0..3 {
                let rb = [b[s], b[(s + 1) % 3], b[(s + 2) % 3]];
                let rb_rev = [rb[0], rb[2], rb[1]];
                for bb in [rb, rb_rev] {
                    assert_eq!(
                        faces_intersect(&p, ra, bb),
                        expected,
                        "{what}: {ra:?} {bb:?}"
                    );
                    assert_eq!(
                        faces_intersect(&p, bb, ra),
                        expected,
                        "{what} swapped: {ra:?} {bb:?}"
                    );
                }
            }
        }
    };
    check(f, [1, 0, 3], false, "flat neighbour across a shared edge");
    check(
        f,
        [1, 0, 4],
        true,
        "folded onto each other across a shared edge",
    );
    check(f, [1, 0, 5], false, "dihedral neighbour");
    check(f, [2, 1, 0], true, "reversed duplicate face");
    check(f, [0, 1, 2], true, "duplicate face");
    check(f, [0, 2, 7], false, "fan neighbour sharing vertex 0");
    check(
        f,
        [0, 8, 9],
        true,
        "shared vertex, opposite edge pierces the face",
    );
    check(
        f,
        [0, 4, 8],
        true,
        "shared vertex, coplanar overlapping wedge",
    );
    assert_eq!(sharing([0, 1, 2], [5, 6, 7]), Sharing::None);
    assert!(matches!(
        sharing([0, 1, 2], [2, 6, 7]),
        Sharing::Vertex { ia: 2, ib: 0 }
    ));
    // Index-disjoint faces that only touch geometrically (the unwelded duplicate vertex 6)
    // intersect: welding is the caller's job.
    check(
        f,
        [6, 7, 8],
        true,
        "touching at an unwelded duplicate point",
    );
}

// ---------------------------------------------------------------------------------------------
// Randomized cross-check against an exact separating-axis oracle on small integer coordinates.

type I3 = [i64; 3];

fn isub(a: I3, b: I3) -> I3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn icross(a: I3, b: I3) -> I3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn idot(a: I3, b: I3) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Closed convex sets (given by vertices) are disjoint iff some candidate axis strictly
/// separates their projections. Candidates: normals, cross products of edge directions, and
/// in-plane edge normals (complete for the Minkowski difference of two flat polytopes).
fn sat_intersect(a: &[I3], b: &[I3]) -> bool {
    let edges = |v: &[I3]| -> Vec<I3> {
        (0..v.len())
            .flat_map(|i| (i + 1..v.len()).map(move |j| (i, j)))
            .map(|(i, j)| isub(v[j], v[i]))
            .collect()
    };
    let (ea, eb) = (edges(a), edges(b));
    let mut axes: Vec<I3> = Vec::new();
    let normal = |e: &[I3]| {
        e.iter()
            .flat_map(|x| e.iter().map(move |y| icross(*x, *y)))
            .find(|n| *n != [0; 3])
    };
    let na = normal(&ea);
    let nb = normal(&eb);
    for n in [na, nb].into_iter().flatten() {
        axes.push(n);
        for e in ea.iter().chain(&eb) {
            axes.push(icross(n, *e));
        }
    }
    for x in &ea {
        for y in &eb {
            axes.push(icross(*x, *y));
        }
    }
    // Collinear sets (segments parallel to each other) need axes orthogonal to the common line.
    for e in ea.iter().chain(&eb) {
        axes.push(*e);
        for k in [[1, 0, 0], [0, 1, 0], [0, 0, 1]] {
            let n = icross(*e, k);
            axes.push(n);
            axes.push(icross(*e, n));
        }
    }
    !axes.iter().filter(|ax| **ax != [0; 3]).any(|&ax| {
        let pa: Vec<i64> = a.iter().map(|p| idot(*p, ax)).collect();
        let pb: Vec<i64> = b.iter().map(|p| idot(*p, ax)).collect();
        let (amin, amax) = (*pa.iter().min().unwrap(), *pa.iter().max().unwrap());
        let (bmin, bmax) = (*pb.iter().min().unwrap(), *pb.iter().max().unwrap());
        amax < bmin || bmax < amin
    })
}

/// Small deterministic PRNG (SplitMix64) so the test needs no dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn coord(&mut self, range: i64) -> i64 {
        (self.next() % (2 * range as u64 + 1)) as i64 - range
    }
    fn point(&mut self, range: i64) -> I3 {
        [self.coord(range), self.coord(range), self.coord(range)]
    }
}

fn non_degenerate(t: &[I3; 3]) -> bool {
    icross(isub(t[1], t[0]), isub(t[2], t[0])) != [0; 3]
}

/// Maps an integer point to floats exactly, with a scale and offset that keep every value
/// exactly representable (so the float geometry is the integer geometry, moved).
fn to_f(p: I3, scale: f64, offset: f64) -> [f64; 3] {
    [
        p[0] as f64 * scale + offset,
        p[1] as f64 * scale - offset,
        p[2] as f64 * scale + 0.5 * offset,
    ]
}

#[test]
fn random_triangles_match_sat_oracle() {
    let mut rng = Rng(0x5EED);
    let (mut hits, mut coplanar) = (0, 0);
    for round in 0..60_000 {
        // Tiny ranges make coplanar, touching and collinear-edge cases frequent.
        let range = if round % 3 == 0 { 1 } else { 2 };
        let a = [rng.point(range), rng.point(range), rng.point(range)];
        let mut b = [rng.point(range), rng.point(range), rng.point(range)];
        if round % 2 == 0 {
            // Force b into a's plane: points of the lattice a0 + i (a1 − a0) + j (a2 − a0).
            let (u, v) = (isub(a[1], a[0]), isub(a[2], a[0]));
            for p in &mut b {
                let (i, j) = (rng.coord(1), rng.coord(1));
                *p = [0, 1, 2].map(|k| a[0][k] + i * u[k] + j * v[k]);
            }
        }
        if !non_degenerate(&a) || !non_degenerate(&b) {
            continue;
        }
        let expected = sat_intersect(&a, &b);
        let n = icross(isub(a[1], a[0]), isub(a[2], a[0]));
        if b.iter().all(|p| idot(n, isub(*p, a[0])) == 0) {
            coplanar += 1;
        }
        hits += expected as usize;
        for (scale, offset) in [(1.0, 0.0), (0.125, 1024.0), (3.0f64.powi(5), -7.5)] {
            let fa = a.map(|p| to_f(p, scale, offset));
            let fb = b.map(|p| to_f(p, scale, offset));
            assert_eq!(
                triangles_intersect(&fa, &fb),
                expected,
                "a={a:?} b={b:?} scale={scale}"
            );
            assert_eq!(
                triangles_intersect(&fb, &fa),
                expected,
                "swapped a={a:?} b={b:?}"
            );
        }
    }
    assert!(
        hits > 5_000 && coplanar > 10_000,
        "too few interesting cases: {hits} hits, {coplanar} coplanar"
    );
}

#[test]
fn random_segments_match_sat_oracle() {
    let mut rng = Rng(42);
    let mut hits = 0;
    for round in 0..60_000 {
        let t = [rng.point(2), rng.point(2), rng.point(2)];
        let s = [
            rng.point(2),
            if round % 7 == 0 { t[0] } else { rng.point(2) },
        ];
        if !non_degenerate(&t) {
            continue;
        }
        let expected = sat_intersect(&s, &t);
        hits += expected as usize;
        let ft = t.map(|p| to_f(p, 0.25, 64.0));
        let fs = s.map(|p| to_f(p, 0.25, 64.0));
        assert_eq!(
            segment_triangle_intersect(fs, &ft),
            expected,
            "s={s:?} t={t:?}"
        );
    }
    assert!(hits > 5_000);
}

#[test]
fn sat_oracle_sanity() {
    let a = [[0, 0, 0], [4, 0, 0], [0, 4, 0]];
    assert!(sat_intersect(&a, &[[4, 0, 0], [5, 0, 1], [5, 1, 1]]));
    assert!(!sat_intersect(&a, &[[5, 0, 0], [6, 0, 0], [5, 1, 0]]));
    assert!(sat_intersect(&a, &[[1, 1, -1], [1, 1, 1]]));
    assert!(!sat_intersect(
        &[[0, 0, 0], [1, 0, 0]],
        &[[0, 1, 0], [1, 1, 0]]
    ));
    assert!(sat_intersect(
        &[[0, 0, 0], [2, 0, 0]],
        &[[1, 0, 0], [3, 0, 0]]
    ));
    assert!(!sat_intersect(
        &[[0, 0, 0], [1, 0, 0]],
        &[[2, 0, 0], [3, 0, 0]]
    ));
}

#[test]
fn random_shared_vertex_pairs_match_segment_rule() {
    // faces_intersect's shared-vertex branch (one projection for coplanar pairs) against the
    // plain CGAL rule written with two independent segment–triangle tests.
    let mut rng = Rng(7);
    let mut hits = 0;
    for round in 0..40_000 {
        let v = rng.point(2);
        let a = [v, rng.point(2), rng.point(2)];
        let mut b = [v, rng.point(2), rng.point(2)];
        if round % 2 == 0 {
            let (u, w) = (isub(a[1], a[0]), isub(a[2], a[0]));
            for p in &mut b[1..] {
                let (i, j) = (rng.coord(1), rng.coord(1));
                *p = [0, 1, 2].map(|k| a[0][k] + i * u[k] + j * w[k]);
            }
        }
        if !non_degenerate(&a) || !non_degenerate(&b) || a[1..].iter().any(|p| b.contains(p)) {
            continue;
        }
        let positions: Vec<[f64; 3]> = a
            .iter()
            .chain(&b[1..])
            .map(|&p| to_f(p, 0.5, 8.0))
            .collect();
        let (fa, fb) = ([0u32, 1, 2], [0u32, 3, 4]);
        let ta = [positions[0], positions[1], positions[2]];
        let tb = [positions[0], positions[3], positions[4]];
        let expected = segment_triangle_intersect([tb[1], tb[2]], &ta)
            || segment_triangle_intersect([ta[1], ta[2]], &tb);
        hits += expected as usize;
        assert_eq!(
            faces_intersect(&positions, fa, fb),
            expected,
            "a={a:?} b={b:?}"
        );
        assert_eq!(
            faces_intersect(&positions, fb, fa),
            expected,
            "swapped a={a:?} b={b:?}"
        );
    }
    assert!(hits > 2_000, "{hits}");
}
