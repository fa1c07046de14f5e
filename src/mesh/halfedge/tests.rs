use std::collections::HashMap;

use super::*;
use crate::mesh::test_shapes::grid;
use crate::mesh::TriMesh;

fn vid(i: u32) -> VertexId {
    VertexId::new(i)
}

fn fid(i: u32) -> FaceId {
    FaceId::new(i)
}

fn hid(i: u32) -> HalfedgeId {
    HalfedgeId::new(i)
}

// ---------------------------------------------------------------------------------------------
// Test meshes.

fn tet() -> TriMesh {
    TriMesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    )
    .unwrap()
}

fn quads_to_tris(quads: &[[u32; 4]]) -> Vec<[u32; 3]> {
    quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect()
}

fn cube() -> TriMesh {
    let p = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    TriMesh::new(p, quads_to_tris(&quads)).unwrap()
}

fn normalize(p: [f64; 3]) -> [f64; 3] {
    let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    [p[0] / l, p[1] / l, p[2] / l]
}

/// Unit icosphere: 20 · 4^level faces.
fn icosphere(level: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<[f64; 3]> = [
        [-1., t, 0.],
        [1., t, 0.],
        [-1., -t, 0.],
        [1., -t, 0.],
        [0., -1., t],
        [0., 1., t],
        [0., -1., -t],
        [0., 1., -t],
        [t, 0., -1.],
        [t, 0., 1.],
        [-t, 0., -1.],
        [-t, 0., 1.],
    ]
    .into_iter()
    .map(normalize)
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, p: &mut Vec<[f64; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (x, y) = (p[a as usize], p[b as usize]);
                p.push(normalize([x[0] + y[0], x[1] + y[1], x[2] + y[2]]));
                p.len() as u32 - 1
            })
        };
        f = f
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = midpoint(a, b, &mut p);
                let bc = midpoint(b, c, &mut p);
                let ca = midpoint(c, a, &mut p);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    TriMesh::new(p, f).unwrap()
}

/// Torus with `nu × nv` squares (two triangles each).
fn torus(nu: u32, nv: u32) -> TriMesh {
    let id = |i: u32, j: u32| (j % nv) * nu + (i % nu);
    let mut p = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let (u, v) = (
                std::f64::consts::TAU * i as f64 / nu as f64,
                std::f64::consts::TAU * j as f64 / nv as f64,
            );
            let r = 2.0 + 0.7 * v.cos();
            p.push([r * u.cos(), r * u.sin(), 0.7 * v.sin()]);
        }
    }
    let mut quads = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(p, quads_to_tris(&quads)).unwrap()
}

fn build(m: &TriMesh) -> HalfEdgeMesh {
    let he = HalfEdgeMesh::from_trimesh(m).unwrap();
    he.check_invariants().unwrap();
    he
}

fn build_err(p: Vec<[f64; 3]>, t: Vec<[u32; 3]>) -> String {
    let m = TriMesh::new(p, t).unwrap();
    match HalfEdgeMesh::from_trimesh(&m) {
        Err(e @ Error::InvalidMesh(_)) => e.to_string(),
        other => panic!("expected InvalidMesh, got {other:?}"),
    }
}

/// Simple 64-bit LCG (Knuth's MMIX constants), high bits out.
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) % n as u64) as usize
    }
}

/// Every stored record, to compare states exactly (the stamps aside).
#[derive(Debug, PartialEq)]
struct State {
    positions: VertexData<[f64; 3]>,
    v_out: VertexData<HalfedgeId>,
    v_alive: VertexData<bool>,
    halfedges: HalfedgeData<HalfEdge>,
    f_he: FaceData<HalfedgeId>,
    counts: [usize; 3],
}

fn state(m: &HalfEdgeMesh) -> State {
    State {
        positions: m.positions.clone(),
        v_out: m.v_out.clone(),
        v_alive: m.v_alive.clone(),
        halfedges: m.halfedges.clone(),
        f_he: m.f_he.clone(),
        counts: [m.n_vertices, m.n_edges, m.n_faces],
    }
}

fn midpoint(m: &HalfEdgeMesh, h: HalfedgeId) -> [f64; 3] {
    let (a, b) = (m.position(m.origin(h)), m.position(m.target(h)));
    [
        (a[0] + b[0]) / 2.0,
        (a[1] + b[1]) / 2.0,
        (a[2] + b[2]) / 2.0,
    ]
}

fn random_live_halfedge(m: &HalfEdgeMesh, rng: &mut Lcg) -> HalfedgeId {
    loop {
        let h = hid(rng.below(m.halfedge_capacity()) as u32);
        if m.is_halfedge_live(h) {
            return h;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Construction and accessors.

fn check_closed(m: &TriMesh, chi: i64) -> HalfEdgeMesh {
    let he = build(m);
    assert_eq!(he.euler_characteristic(), chi);
    assert_eq!(he.boundary_loop_count(), 0);
    assert_eq!(he.vertex_count(), m.vertex_count());
    assert_eq!(he.face_count(), m.triangle_count());
    assert_eq!(he.edge_count(), m.edges().len());
    assert_eq!(2 * he.edge_count(), 3 * he.face_count());
    assert!(he.vertices().all(|v| !he.is_boundary_vertex(v)));
    assert_eq!(he.to_trimesh(), *m);
    he
}

#[test]
fn builds_closed_meshes() {
    check_closed(&tet(), 2);
    check_closed(&cube(), 2);
    let s = check_closed(&icosphere(3), 2);
    assert_eq!(s.face_count(), 1280);
    let val: Vec<usize> = s.vertices().map(|v| s.valence(v)).collect();
    assert_eq!(val.iter().filter(|&&k| k == 5).count(), 12);
    assert!(val.iter().all(|&k| k == 5 || k == 6));
    check_closed(&torus(12, 7), 0);
}

#[test]
fn builds_open_grid_with_boundary_first_vertices() {
    let (nx, ny) = (7, 5);
    let g = grid(nx, ny);
    let he = build(&g);
    assert_eq!(he.euler_characteristic(), 1);
    assert_eq!(he.boundary_loop_count(), 1);
    let boundary: Vec<_> = he
        .vertices()
        .filter(|&v| he.is_boundary_vertex(v))
        .collect();
    assert_eq!(boundary.len() as u32, 2 * (nx + ny));
    let boundary_edges = he.edges().filter(|&e| he.is_boundary_edge(e)).count();
    assert_eq!(boundary_edges as u32, 2 * (nx + ny));
    // Faces around each vertex, from the half-edge structure and by brute force.
    for v in he.vertices() {
        let out: Vec<_> = he.outgoing(v).collect();
        assert_eq!(he.is_boundary_halfedge(out[0]), he.is_boundary_vertex(v));
        assert!(out[1..].iter().all(|&h| !he.is_boundary_halfedge(h)));
        let mut faces: Vec<_> = he.vertex_faces(v).collect();
        faces.sort_unstable();
        let brute: Vec<_> = (0..g.triangle_count() as u32)
            .filter(|&f| g.triangles()[f as usize].contains(&v.raw()))
            .map(fid)
            .collect();
        assert_eq!(faces, brute, "faces around vertex {v}");
        let nb: Vec<_> = he.vertex_neighbors(v).collect();
        assert_eq!(nb.len(), he.valence(v));
        for (&h, &n) in out.iter().zip(&nb) {
            assert_eq!(he.find_halfedge(v, n), Some(h));
        }
    }
    // The corner vertex (0, 0) has 2 faces (its cell's diagonal leaves it) and valence 3.
    assert_eq!(he.vertex_faces(vid(0)).count(), 2);
    assert_eq!(he.valence(vid(0)), 3);
    assert_eq!(he.to_trimesh(), g);
}

#[test]
fn navigation_on_tetrahedron() {
    let m = build(&tet());
    for h in m.halfedges() {
        assert_eq!(m.twin(m.twin(h)), h);
        assert_eq!(m.next(m.next(m.next(h))), h);
        assert_eq!(m.prev(m.next(h)), h);
        assert_eq!(m.target(h), m.origin(m.twin(h)));
        assert_eq!(m.origin(m.next(h)), m.target(h));
        assert_eq!(m.edge_halfedge(m.edge(h)).raw(), h.raw() & !1);
        let f = m.face(h).unwrap();
        assert!(m.face_halfedges(f).contains(&h));
    }
    assert_eq!(m.face_vertices(fid(0)), [0, 2, 1].map(vid));
    assert_eq!(
        m.face_halfedge(fid(0)),
        m.find_halfedge(vid(0), vid(2)).unwrap()
    );
    assert_eq!(m.find_halfedge(vid(1), vid(1)), None);
    // Face 0 = (0, 2, 1) lies in z = 0 with its normal pointing down (outwards).
    assert_eq!(m.face_normal(fid(0)).to_array(), [0., 0., -1.]);
    assert!((m.face_area(fid(0)) - 0.5).abs() < 1e-15);
    let total: f64 = m.faces().map(|f| m.face_area(f)).sum();
    assert!((total - tet().surface_area()).abs() < 1e-12);
    for f in m.faces() {
        // Outward normals: away from the centroid (0.25, 0.25, 0.25).
        let [a, ..] = m.face_positions(f);
        let n = m.face_normal(f);
        let d: f64 = (0..3).map(|k| n[k] * (a[k] - 0.25)).sum();
        assert!(d > 0.0, "face {f} points inwards");
    }
}

#[test]
fn positions_and_isolated_vertices() {
    let mut p = tet().positions().to_vec();
    p.push([5., 5., 5.]);
    let src = TriMesh::new(p, tet().triangles().to_vec()).unwrap();
    let mut m = build(&src);
    assert!(m.is_isolated_vertex(vid(4)));
    assert_eq!(m.vertex_halfedge(vid(4)), None);
    assert_eq!(m.outgoing(vid(4)).count(), 0);
    assert!(!m.is_boundary_vertex(vid(4)));
    assert_eq!(m.vertex_count(), 5);
    assert_eq!(m.euler_characteristic(), 3);
    assert_eq!(m.to_trimesh(), src);
    m.set_position(vid(1), [2., 0., 0.]).unwrap();
    assert_eq!(m.position(vid(1)), [2., 0., 0.]);
    let err = m.set_position(vid(1), [f64::NAN, 0., 0.]).unwrap_err();
    assert!(err.to_string().contains("vertex 1"), "{err}");
    assert_eq!(m.position(vid(1)), [2., 0., 0.]);
}

#[test]
#[should_panic(expected = "half-edge id 12 is out of range")]
fn out_of_range_id_panics_clearly() {
    build(&tet()).next(hid(12));
}

#[test]
fn deleted_ids_do_not_panic() {
    let mut m = build(&icosphere(1));
    let h = m
        .find_halfedge(vid(0), m.vertex_neighbors(vid(0)).next().unwrap())
        .unwrap();
    let r = m.collapse_edge(h, m.position(vid(0))).unwrap();
    let (v, f, e) = (r.removed_vertex, r.removed_faces[0], r.removed_edges[0]);
    assert!(!m.is_vertex_live(v) && !m.is_face_live(f) && !m.is_edge_live(e));
    assert_eq!(m.vertex_halfedge(v), None);
    assert_eq!(m.outgoing(v).count(), 0);
    assert_eq!(m.face_vertices(f), [VertexId::INVALID; 3]);
    assert_eq!(m.next(e.halfedge()), HalfedgeId::INVALID);
    assert_eq!(m.face(e.halfedge()), None);
    assert!(!m.is_boundary_halfedge(e.halfedge()) && !m.is_boundary_edge(e));
    assert_eq!(m.can_collapse(e.halfedge()), Err(Refusal::Deleted));
    assert_eq!(m.can_flip(e.halfedge()), Err(Refusal::Deleted));
    assert!(m.set_position(v, [0.; 3]).is_err());
}

fn assert_detects(m: &HalfEdgeMesh, what: &str) {
    match m.check_invariants() {
        Err(e @ Error::Internal(_)) => assert!(e.to_string().contains(what), "{e}"),
        other => panic!("corruption not detected (wanted '{what}'): {other:?}"),
    }
}

#[test]
fn check_invariants_detects_corruption() {
    let good = build(&grid(3, 3));
    let mut m = good.clone();
    let n = m.halfedges[hid(0)].next;
    m.halfedges[hid(0)].next = m.halfedges[n].next;
    assert_detects(&m, "prev(next(0))");

    let mut m = good.clone();
    let v = vid(1); // on the bottom border
    let inner = m.outgoing(v).nth(1).unwrap();
    m.v_out[v] = inner;
    assert_detects(&m, "is not its boundary half-edge");

    let mut m = good.clone();
    m.n_faces += 1;
    assert_detects(&m, "live counts");

    let mut m = good.clone();
    m.positions[vid(4)][1] = f64::INFINITY;
    assert_detects(&m, "vertex 4 has a non-finite position");

    let mut m = good.clone();
    m.halfedges[hid(3)] = HalfEdge::DELETED;
    assert_detects(&m, "half-edge 2 is live but its twin is deleted");

    // Unchecked operations that the guards refuse break the invariants detectably.
    let mut t = build(&tet());
    t.apply_flip(hid(0));
    assert_detects(&t, "have the same three vertices");
    // A flip onto an existing edge c–d whose faces avoid a and b duplicates only the edge.
    let (mut m, _) = random_ops(&icosphere(2), 400, 21);
    let dup = m.halfedges().find(|&h| {
        let Err(Refusal::EdgeExists { a: c, b: d }) = m.can_flip(h) else {
            return false;
        };
        let cd = m.find_halfedge(c, d).unwrap();
        let ab = [Some(m.origin(h)), Some(m.target(h))];
        !ab.contains(&m.opposite_vertex(cd)) && !ab.contains(&m.opposite_vertex(cd.twin()))
    });
    m.apply_flip(dup.expect("some flip would duplicate an edge"));
    assert_detects(&m, "two edges join vertices");
    let mut t = build(&tet());
    t.apply_collapse(hid(0), [0.; 3]);
    assert!(t.check_invariants().is_err());
    let mut g = build(&grid(3, 3));
    g.apply_collapse(g.find_halfedge(vid(2), vid(7)).unwrap(), [0.; 3]);
    assert!(
        g.check_invariants().is_err(),
        "a boundary pinch must be detected"
    );
}

// ---------------------------------------------------------------------------------------------
// Refusals.

#[test]
fn refuses_non_manifold_edge() {
    let p = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., -1., 0.],
        [0., 0., 1.],
    ];
    let msg = build_err(p, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
    assert!(
        msg.contains("edge (0, 1)") && msg.contains("3 triangles (0, 1, 2)"),
        "{msg}"
    );
}

#[test]
fn refuses_bowtie_vertex() {
    let p = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [-1., 0., 0.],
        [-1., -1., 0.],
    ];
    let msg = build_err(p, vec![[0, 1, 2], [0, 3, 4]]);
    assert!(
        msg.contains("vertex 0 is non-manifold") && msg.contains("2 fans"),
        "{msg}"
    );
}

#[test]
fn refuses_two_closed_fans_at_a_vertex() {
    // Two tetrahedra sharing vertex 0: every edge is manifold, vertex 0 is not.
    let mut p = tet().positions().to_vec();
    p.extend([[-1., 0., 0.], [0., -1., 0.], [0., 0., -1.]]);
    let mut t = tet().triangles().to_vec();
    t.extend([[0, 5, 4], [0, 4, 6], [4, 5, 6], [0, 6, 5]]);
    let msg = build_err(p, t);
    assert!(
        msg.contains("vertex 0 is non-manifold") && msg.contains("2 fans"),
        "{msg}"
    );
}

#[test]
fn refuses_flipped_face() {
    let c = cube();
    let mut t = c.triangles().to_vec();
    t[5].swap(1, 2);
    let msg = build_err(c.positions().to_vec(), t);
    assert!(
        msg.contains("inconsistently oriented") && msg.contains("triangles"),
        "{msg}"
    );
    assert!(
        msg.contains(" 5 ") || msg.contains(" 5"),
        "names the flipped triangle: {msg}"
    );
}

#[test]
fn refuses_repeated_vertex_index() {
    let msg = build_err(tet().positions().to_vec(), vec![[0, 1, 2], [3, 1, 3]]);
    assert!(
        msg.contains("triangle 1 (3, 1, 3) repeats vertex 3"),
        "{msg}"
    );
}

#[test]
fn refuses_duplicate_triangle() {
    let msg = build_err(tet().positions().to_vec(), vec![[0, 1, 2], [0, 2, 1]]);
    assert!(
        msg.contains("triangles 0 and 1 use the same three vertices"),
        "{msg}"
    );
}

// ---------------------------------------------------------------------------------------------
// Local operations.

#[test]
fn collapse_record_and_undo_on_icosphere() {
    let mut m = build(&icosphere(2));
    let before = state(&m);
    let before_mesh = m.to_trimesh();
    let h = m
        .find_halfedge(vid(0), m.vertex_neighbors(vid(0)).next().unwrap())
        .unwrap();
    let (a, b) = (m.origin(h), m.target(h));
    let valence = m.valence(a) + m.valence(b) - 4;
    let p = midpoint(&m, h);
    let r = m.collapse_edge(h, p).unwrap();
    m.check_invariants().unwrap();
    assert_eq!((r.kept_vertex, r.removed_vertex), (a, b));
    assert_eq!(r.removed_faces.len(), 2);
    assert_eq!(r.removed_edges.len(), 3);
    assert_eq!(r.removed_edges[0], h.edge());
    assert_eq!(m.position(a), p);
    assert_eq!(m.valence(a), valence);
    let mut around: Vec<_> = m.vertex_faces(a).collect();
    let mut modified = r.modified_faces.clone();
    around.sort_unstable();
    modified.sort_unstable();
    assert_eq!(around, modified);
    for [gone, kept] in &r.merged_edges {
        assert!(!m.is_edge_live(*gone) && m.is_edge_live(*kept));
        let k = m.edge_halfedge(*kept);
        assert!(m.origin(k) == a || m.target(k) == a);
    }
    assert_eq!(m.euler_characteristic(), 2);
    assert_ne!(m.to_trimesh(), before_mesh);
    m.undo(r.undo).unwrap();
    assert_eq!(state(&m), before);
    assert_eq!(m.to_trimesh(), before_mesh);
    m.check_invariants().unwrap();
}

#[test]
fn undo_stack_and_stale_records() {
    let mut m = build(&icosphere(2));
    let s0 = state(&m);
    let mut rng = Lcg(7);
    let mut undos = Vec::new();
    let mut states = Vec::new();
    while undos.len() < 20 {
        let h = random_live_halfedge(&m, &mut rng);
        states.push(state(&m));
        let undo = if undos.len() % 2 == 0 {
            m.collapse_edge(h, midpoint(&m, h)).map(|r| r.undo)
        } else {
            m.flip_edge(h).map(|r| r.undo)
        };
        match undo {
            Ok(u) => undos.push(u),
            Err(_) => {
                states.pop();
            }
        }
    }
    // An older record does not apply to the current state.
    let old = undos[3].clone();
    assert!(m
        .undo(old)
        .unwrap_err()
        .to_string()
        .contains("stale undo record"));
    while let Some(u) = undos.pop() {
        m.undo(u).unwrap();
        assert_eq!(state(&m), states.pop().unwrap());
        m.check_invariants().unwrap();
    }
    assert_eq!(state(&m), s0);
    // A record undone once is stale afterwards, even when a later operation reuses the stamp
    // position.
    let h = m
        .find_halfedge(vid(0), m.vertex_neighbors(vid(0)).next().unwrap())
        .unwrap();
    let r1 = m.flip_edge(h).unwrap();
    let again = r1.undo.clone();
    m.undo(r1.undo).unwrap();
    let r2 = m.flip_edge(h).unwrap();
    assert!(m.undo(again).is_err());
    m.undo(r2.undo).unwrap();
    assert_eq!(state(&m), s0);
}

#[test]
fn flip_on_octahedron_like_patch() {
    let mut m = build(&icosphere(0));
    let before = state(&m);
    let h = m.find_halfedge(vid(0), vid(11)).unwrap();
    let (c, d) = (m.target(m.next(h)), m.target(m.next(h.twin())));
    let fl = m.face(h).unwrap();
    let r = m.flip_edge(h).unwrap();
    m.check_invariants().unwrap();
    assert_eq!(r.old_vertices, [vid(0), vid(11)]);
    assert_eq!(r.new_vertices, [c, d]);
    assert_eq!((m.origin(h), m.target(h)), (c, d));
    assert_eq!(m.face(h), Some(fl));
    assert_eq!(m.find_halfedge(vid(0), vid(11)), None);
    assert_eq!(m.valence(vid(0)), 4);
    // Flipping back restores the connectivity (not necessarily the same records).
    assert_eq!(m.can_flip(h.twin()), Ok(()));
    m.undo(r.undo).unwrap();
    assert_eq!(state(&m), before);
}

#[test]
fn specific_refusals() {
    // Tetrahedron: no collapse (it is the smallest closed surface), no flip (the new edge
    // exists).
    let mut t = build(&tet());
    let before = state(&t);
    for h in t.halfedges().collect::<Vec<_>>() {
        assert_eq!(t.can_collapse(h), Err(Refusal::Tetrahedron));
        assert!(matches!(t.can_flip(h), Err(Refusal::EdgeExists { .. })));
        let err = t.collapse_edge(h, [0.; 3]).unwrap_err().to_string();
        assert!(
            err.contains(&format!("half-edge {h}")) && err.contains("tetrahedron"),
            "{err}"
        );
        assert!(t.flip_edge(h).is_err());
    }
    assert_eq!(state(&t), before);

    // A lone triangle cannot collapse.
    let tri = TriMesh::new(tet().positions().to_vec(), vec![[0, 1, 2]]).unwrap();
    let tri = HalfEdgeMesh::from_trimesh(&tri).unwrap();
    for h in tri.halfedges() {
        assert_eq!(tri.can_collapse(h), Err(Refusal::IsolatedTriangle));
        assert_eq!(tri.can_flip(h), Err(Refusal::BoundaryEdge));
    }

    // Grid: an interior edge between two boundary vertices pinches; boundary edges don't flip.
    let mut g = build(&grid(3, 3));
    // Diagonal of the corner cell (2, 0): from (2, 0) to (3, 1), both on the boundary.
    let pinch = g.find_halfedge(vid(2), vid(7)).unwrap();
    assert!(!g.is_boundary_edge(pinch.edge()));
    assert_eq!(g.can_collapse(pinch), Err(Refusal::BoundaryPinch));
    assert_eq!(g.can_collapse(pinch.twin()), Err(Refusal::BoundaryPinch));
    let inner = g.find_halfedge(vid(1), vid(5)).unwrap(); // boundary vertex 1 to interior vertex 5
    assert_eq!(g.can_collapse(inner), Ok(()));
    let border = g.find_halfedge(vid(0), vid(1)).unwrap();
    assert_eq!(g.can_flip(border), Err(Refusal::BoundaryEdge));
    // A boundary endpoint may drop to valence 2 by a flip: corner 0 then has a single face.
    let mut corner = g.clone();
    let diagonal = corner.find_halfedge(vid(0), vid(5)).unwrap();
    assert_eq!(corner.valence(vid(0)), 3);
    corner.flip_edge(diagonal).unwrap();
    corner.check_invariants().unwrap();
    assert_eq!(
        (corner.valence(vid(0)), corner.vertex_faces(vid(0)).count()),
        (2, 1)
    );
    // Collapsing the boundary edge 0→1 keeps the corner vertex 0 and removes 1.
    assert_eq!(g.can_collapse(border), Ok(()));
    g.collapse_edge(border, g.position(vid(0))).unwrap();
    g.check_invariants().unwrap();
    assert_eq!(g.boundary_loop_count(), 1);
    assert_eq!(g.euler_characteristic(), 1);

    // Link condition: on the icosphere, contract until a vertex of valence 3 appears and check
    // that collapsing an edge into a "triangle without face" is refused.
    let mut s = build(&icosphere(0));
    // Vertex 0's neighbours 11, 5, 1, 7, 10 form a ring; flip 0–11 then 0–5: 0 has valence 3.
    s.flip_edge(s.find_halfedge(vid(0), vid(11)).unwrap())
        .unwrap();
    s.flip_edge(s.find_halfedge(vid(0), vid(1)).unwrap())
        .unwrap();
    s.check_invariants().unwrap();
    assert_eq!(s.valence(vid(0)), 3);
    let nb: Vec<_> = s.vertex_neighbors(vid(0)).collect();
    // Flipping an edge at a valence-3 interior vertex would leave it with valence 2; in a
    // simplicial surface its neighbours are pairwise adjacent, so the new edge already exists.
    for &x in &nb {
        let h = s.find_halfedge(vid(0), x).unwrap();
        assert!(matches!(s.can_flip(h), Err(Refusal::EdgeExists { .. })));
        assert!(matches!(
            s.can_flip(h.twin()),
            Err(Refusal::EdgeExists { .. })
        ));
    }
    // Collapsing an edge between two neighbours of the valence-3 vertex 0 that are not
    // opposite each other's faces: neighbours of vertex 0 are pairwise adjacent, so collapsing
    // nb[0]→x for a vertex x adjacent to nb[0] but outside the fan shares vertex 0 and more.
    let mut found_link_refusal = false;
    for h in s.halfedges().collect::<Vec<_>>() {
        if let Err(Refusal::LinkCondition { vertex }) = s.can_collapse(h) {
            found_link_refusal = true;
            let (a, b) = (s.origin(h), s.target(h));
            assert!(s.find_halfedge(a, vertex).is_some() && s.find_halfedge(b, vertex).is_some());
            let opp = [s.opposite_vertex(h), s.opposite_vertex(h.twin())];
            assert!(!opp.contains(&Some(vertex)));
        }
    }
    assert!(found_link_refusal);
}

// ---------------------------------------------------------------------------------------------
// Random sequences.

#[derive(Default, Debug)]
struct Tally {
    collapses: usize,
    flips: usize,
    refusals: usize,
    undos: usize,
}

/// Applies `steps` random collapses (2/3) and flips (1/3), undoing a quarter of them, checking
/// invariants, Euler characteristic and boundary loops after each, and exact restoration after
/// each undo.
fn random_ops(mesh: &TriMesh, steps: usize, seed: u64) -> (HalfEdgeMesh, Tally) {
    let mut m = build(mesh);
    let (chi, loops) = (m.euler_characteristic(), m.boundary_loop_count());
    let mut rng = Lcg(seed);
    let mut tally = Tally::default();
    for step in 0..steps {
        let h = random_live_halfedge(&m, &mut rng);
        let before = state(&m);
        let collapse = rng.below(3) < 2;
        let result = if collapse {
            let allowed = m.can_collapse(h);
            let r = m.collapse_edge(h, midpoint(&m, h));
            assert_eq!(
                allowed.is_ok(),
                r.is_ok(),
                "step {step}: can_collapse disagrees"
            );
            r.map(|r| r.undo)
        } else {
            let allowed = m.can_flip(h);
            let r = m.flip_edge(h);
            assert_eq!(
                allowed.is_ok(),
                r.is_ok(),
                "step {step}: can_flip disagrees"
            );
            r.map(|r| r.undo)
        };
        let Ok(undo) = result else {
            tally.refusals += 1;
            assert_eq!(
                state(&m),
                before,
                "step {step}: a refused operation changed the mesh"
            );
            continue;
        };
        if collapse {
            tally.collapses += 1;
        } else {
            tally.flips += 1;
        }
        if let Err(e) = m.check_invariants() {
            panic!(
                "step {step} ({}): {e}",
                if collapse { "collapse" } else { "flip" }
            );
        }
        assert_eq!(m.euler_characteristic(), chi, "step {step}");
        assert_eq!(m.boundary_loop_count(), loops, "step {step}");
        if rng.below(4) == 0 {
            let after = m.to_trimesh();
            m.undo(undo).unwrap();
            tally.undos += 1;
            assert_eq!(state(&m), before, "step {step}: undo is not exact");
            assert_ne!(m.to_trimesh(), after);
            m.check_invariants().unwrap();
        }
    }
    (m, tally)
}

#[test]
fn random_operations_on_closed_icosphere() {
    let (m, t) = random_ops(&icosphere(4), 6000, 1);
    println!("{t:?}");
    assert!(
        t.collapses > 1500 && t.flips > 900 && t.undos > 500,
        "{t:?}"
    );
    assert_eq!(m.euler_characteristic(), 2);
    assert!(m.face_count() < 5120 / 2, "{}", m.face_count());
}

#[test]
fn random_operations_on_grid_with_boundary() {
    let (m, t) = random_ops(&grid(60, 40), 8000, 2);
    assert!(t.collapses > 2500 && t.flips > 1000, "{t:?}");
    assert_eq!(m.euler_characteristic(), 1);
    assert_eq!(m.boundary_loop_count(), 1);
}

#[test]
fn random_operations_on_torus() {
    let (m, t) = random_ops(&torus(40, 25), 4000, 3);
    assert!(t.collapses > 1000 && t.flips > 500, "{t:?}");
    assert_eq!(m.euler_characteristic(), 0);
}

/// Collapses random allowed edges until none is left.
fn collapse_to_minimum(mesh: &TriMesh, seed: u64) -> HalfEdgeMesh {
    let mut m = build(mesh);
    let mut rng = Lcg(seed);
    loop {
        let mut candidates: Vec<_> = m
            .halfedges()
            .filter(|&h| m.can_collapse(h).is_ok())
            .collect();
        if candidates.is_empty() {
            return m;
        }
        let h = candidates.swap_remove(rng.below(candidates.len()));
        m.collapse_edge(h, m.position(m.origin(h))).unwrap();
        m.check_invariants().unwrap();
    }
}

#[test]
fn collapsing_reaches_the_minimal_triangulations() {
    // Every triangulated sphere but the tetrahedron has a contractible edge.
    let s = collapse_to_minimum(&icosphere(2), 11);
    assert_eq!((s.vertex_count(), s.face_count()), (4, 4));
    // A triangulated disk shrinks to one triangle.
    let g = collapse_to_minimum(&grid(6, 5), 12);
    assert_eq!((g.vertex_count(), g.face_count()), (3, 1));
    assert_eq!(g.boundary_loop_count(), 1);
    // Irreducible triangulations of the torus have 7 to 10 vertices.
    let t = collapse_to_minimum(&torus(9, 8), 13);
    assert!((7..=10).contains(&t.vertex_count()), "{}", t.vertex_count());
    assert_eq!(t.euler_characteristic(), 0);
}

// ---------------------------------------------------------------------------------------------
// Conversion and compaction.

#[test]
fn round_trips_preserve_triangles() {
    for m in [tet(), cube(), icosphere(2), grid(5, 4), torus(8, 5)] {
        let he = build(&m);
        let (back, map) = he.to_trimesh_with_map();
        assert_eq!(back, m);
        assert!(map.iter().all(|(i, &j)| i == j));
    }
}

#[test]
fn garbage_collect_compacts_in_order() {
    let (mut m, _) = random_ops(&icosphere(3), 800, 5);
    let (before, vmap) = m.to_trimesh_with_map();
    let h = m.halfedges().find(|&h| m.can_flip(h).is_ok()).unwrap();
    let r = m.flip_edge(h).unwrap();
    m.undo(r.undo.clone()).unwrap();
    let old = m.clone();
    let c = m.garbage_collect();
    m.check_invariants().unwrap();
    assert_eq!(c.vertices, vmap);
    assert_eq!(m.vertex_capacity(), m.vertex_count());
    assert_eq!(m.face_capacity(), m.face_count());
    assert_eq!(m.halfedge_capacity(), m.halfedge_count());
    assert_eq!(m.to_trimesh(), before);
    for h in old.halfedges() {
        let n = c.halfedges[h];
        assert_eq!(c.halfedges[h.twin()], n.twin());
        assert_eq!(m.origin(n), c.vertices[old.origin(h)]);
        assert_eq!(m.next(n), c.halfedges[old.next(h)]);
        assert_eq!(m.face(n), old.face(h).map(|f| c.faces[f]));
    }
    // Records from before the compaction, or from another mesh, are refused.
    assert!(m.undo(r.undo).is_err());
    let h = old.halfedges().find(|&h| old.can_flip(h).is_ok()).unwrap();
    let u = old.clone().flip_edge(h).unwrap().undo;
    assert!(m.undo(u).is_err());
    assert_eq!(m.euler_characteristic(), 2);
}

// ---------------------------------------------------------------------------------------------
// Performance (run with `cargo test --release --lib mesh::halfedge -- --ignored --nocapture`).

#[test]
#[ignore]
fn timing_one_million_faces() {
    use std::time::Instant;
    let src = torus(1000, 500);
    assert_eq!(src.triangle_count(), 1_000_000);
    let t = Instant::now();
    let mut m = HalfEdgeMesh::from_trimesh(&src).unwrap();
    let build = t.elapsed();
    let t = Instant::now();
    m.check_invariants().unwrap();
    let check = t.elapsed();
    let t = Instant::now();
    let back = m.to_trimesh();
    let convert = t.elapsed();
    assert_eq!(back, src);
    let g = grid(707, 707);
    let t = Instant::now();
    let mg = HalfEdgeMesh::from_trimesh(&g).unwrap();
    let build_grid = t.elapsed();
    assert_eq!(mg.boundary_loop_count(), 1);

    let mut rng = Lcg(9);
    let n = 200_000;
    let (mut collapses, mut flips, mut undone) = (0, 0, 0);
    let t = Instant::now();
    for i in 0..n {
        let h = random_live_halfedge(&m, &mut rng);
        if i % 2 == 0 {
            if let Ok(r) = m.collapse_edge(h, m.position(m.origin(h))) {
                collapses += 1;
                if i % 8 == 0 {
                    m.undo(r.undo).unwrap();
                    undone += 1;
                }
            }
        } else if m.flip_edge(h).is_ok() {
            flips += 1;
        }
    }
    let ops = t.elapsed();
    m.check_invariants().unwrap();
    let t = Instant::now();
    m.garbage_collect();
    let gc = t.elapsed();
    println!(
        "1M faces: from_trimesh {build:?} (grid 1M with boundary: {build_grid:?}), \
         check_invariants {check:?}, to_trimesh {convert:?}, garbage_collect {gc:?}"
    );
    println!(
        "{n} random ops ({collapses} collapses, {undone} undone, {flips} flips, rest refused): \
         {ops:?} = {:.2} µs/op",
        ops.as_secs_f64() * 1e6 / n as f64
    );
}
