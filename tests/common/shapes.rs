//! Closed test meshes generated in code (no files needed).
#![allow(dead_code)]

use pleat::mesh::TriMesh;

/// Icosphere of radius `r` with `sub` 1→4 subdivisions (20·4^sub faces).
pub fn icosphere(r: f64, sub: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<[f64; 3]> = vec![
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
    ];
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
    for _ in 0..sub {
        let mut mid = std::collections::HashMap::new();
        let mut nf = Vec::with_capacity(f.len() * 4);
        let mut m = |a: u32, b: u32, p: &mut Vec<[f64; 3]>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (x, y) = (p[a as usize], p[b as usize]);
                p.push([(x[0] + y[0]) / 2., (x[1] + y[1]) / 2., (x[2] + y[2]) / 2.]);
                (p.len() - 1) as u32
            })
        };
        for &[a, b, c] in &f {
            let ab = m(a, b, &mut p);
            let bc = m(b, c, &mut p);
            let ca = m(c, a, &mut p);
            nf.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = nf;
    }
    for q in &mut p {
        let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        *q = [q[0] * r / l, q[1] * r / l, q[2] * r / l];
    }
    TriMesh::new(p, f).unwrap()
}

/// Torus with radii `big` > `small`, `n` × `m` quads split into triangles.
pub fn torus(big: f64, small: f64, n: u32, m: u32) -> TriMesh {
    let mut p = Vec::new();
    for i in 0..n {
        let u = i as f64 / n as f64 * std::f64::consts::TAU;
        for j in 0..m {
            let v = j as f64 / m as f64 * std::f64::consts::TAU;
            let r = big + small * v.cos();
            p.push([r * u.cos(), r * u.sin(), small * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            f.push([a, b, c]);
            f.push([a, c, d]);
        }
    }
    TriMesh::new(p, f).unwrap()
}

/// Axis-aligned box `[0,sx]×[0,sy]×[0,sz]` with each face split into an `n × n` grid.
pub fn box_grid(sx: f64, sy: f64, sz: f64, n: u32) -> TriMesh {
    let mut p: Vec<[f64; 3]> = Vec::new();
    let mut f: Vec<[u32; 3]> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut vid = |q: [i64; 3], p: &mut Vec<[f64; 3]>| -> u32 {
        *index.entry(q).or_insert_with(|| {
            p.push([
                q[0] as f64 / n as f64 * sx,
                q[1] as f64 / n as f64 * sy,
                q[2] as f64 / n as f64 * sz,
            ]);
            (p.len() - 1) as u32
        })
    };
    let n = n as i64;
    // (normal axis, side, u axis, v axis) with u × v pointing outwards.
    let sides = [
        (0usize, 0i64, 2usize, 1usize),
        (0, 1, 1, 2),
        (1, 0, 0, 2),
        (1, 1, 2, 0),
        (2, 0, 1, 0),
        (2, 1, 0, 1),
    ];
    for &(ax, side, ua, va) in &sides {
        for i in 0..n {
            for j in 0..n {
                let mut q = |di: i64, dj: i64| {
                    let mut c = [0i64; 3];
                    c[ax] = side * n;
                    c[ua] = i + di;
                    c[va] = j + dj;
                    vid(c, &mut p)
                };
                let (a, b, c, d) = (q(0, 0), q(1, 0), q(1, 1), q(0, 1));
                f.push([a, b, c]);
                f.push([a, c, d]);
            }
        }
    }
    TriMesh::new(p, f).unwrap()
}

/// `m` scaled by `s` about the origin.
pub fn scaled(m: &TriMesh, s: [f64; 3]) -> TriMesh {
    let p = m
        .positions()
        .iter()
        .map(|q| [q[0] * s[0], q[1] * s[1], q[2] * s[2]])
        .collect();
    TriMesh::new(p, m.triangles().to_vec()).unwrap()
}

/// `n³` disjoint tiny right triangles (legs 10⁻³) on an `n × n × n` lattice of the unit cube:
/// `n³` components, `3n³` vertices.
pub fn tiny_components(n: u32) -> TriMesh {
    let step = 1.0 / f64::from(n);
    let mut p = Vec::with_capacity(3 * (n as usize).pow(3));
    let mut t = Vec::with_capacity((n as usize).pow(3));
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let o = [i, j, k].map(|c| f64::from(c) * step);
                let v = p.len() as u32;
                p.push(o);
                p.push([o[0] + 1e-3, o[1], o[2]]);
                p.push([o[0], o[1] + 1e-3, o[2]]);
                t.push([v, v + 1, v + 2]);
            }
        }
    }
    TriMesh::new(p, t).unwrap()
}

/// A pile of `n` near-copies of one triangle, each corner moved by up to ±1e-9 (a fixed
/// pseudo-random jitter): every pair has touching boxes and is decided by the exact test.
pub fn jittered_pile(n: u32) -> TriMesh {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut jitter = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 2001) as f64 * 1e-12 - 1e-9
    };
    let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let p: Vec<[f64; 3]> = (0..n)
        .flat_map(|_| corners)
        .map(|c: [f64; 3]| c.map(|x| x + jitter()))
        .collect();
    let t = (0..n).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    TriMesh::new(p, t).unwrap()
}
