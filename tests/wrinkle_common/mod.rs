//! Mesh generators and a tiny deterministic RNG shared by the wrinkle integration tests.
#![allow(dead_code)]

use pleat::mesh::TriMesh;

#[path = "../common/shapes.rs"]
mod shapes;

/// xorshift64* — deterministic, no dependency.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}

/// An `n × n` grid of `[0, 1]²` (spacing `1/n`), interior vertices jittered by up to `jitter`
/// of the spacing, each square split along a random diagonal. Open (has a boundary).
pub fn irregular_grid(n: usize, jitter: f64, seed: u64) -> TriMesh {
    let mut rng = Rng::new(seed);
    let h = 1.0 / n as f64;
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let inner = i > 0 && j > 0 && i < n && j < n;
            let (dx, dy) = if inner {
                (
                    rng.range(-jitter, jitter) * h,
                    rng.range(-jitter, jitter) * h,
                )
            } else {
                (0.0, 0.0)
            };
            p.push([i as f64 * h + dx, j as f64 * h + dy, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if rng.uniform() < 0.5 {
                t.push([a, b, c]);
                t.push([a, c, d]);
            } else {
                t.push([a, b, d]);
                t.push([b, c, d]);
            }
        }
    }
    TriMesh::new(p, t).unwrap()
}

/// Applies `x ↦ R x + o` with a fixed rotation, so a planar mesh lies in a tilted plane.
pub fn tilt(m: &TriMesh) -> TriMesh {
    let (s, c) = 0.7f64.sin_cos();
    let (s2, c2) = 0.4f64.sin_cos();
    let p = m
        .positions()
        .iter()
        .map(|&[x, y, z]| {
            let (x1, z1) = (c * x + s * z, -s * x + c * z);
            let (y2, z2) = (c2 * y - s2 * z1, s2 * y + c2 * z1);
            [x1 + 0.3, y2 - 0.2, z2 + 0.5]
        })
        .collect();
    TriMesh::new(p, m.triangles().to_vec()).unwrap()
}

/// Icosphere: the icosahedron refined `level` times, on the unit sphere
/// (`tests/common/shapes.rs`).
pub fn icosphere(level: usize) -> TriMesh {
    shapes::icosphere(1.0, level as u32)
}

/// Torus with `nu × nv` quads split into triangles, radii 1 and 0.35, jittered parameters.
pub fn torus(nu: usize, nv: usize, seed: u64) -> TriMesh {
    let mut rng = Rng::new(seed);
    let mut p = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let u = (i as f64 + rng.range(-0.2, 0.2)) / nu as f64 * std::f64::consts::TAU;
            let v = (j as f64 + rng.range(-0.2, 0.2)) / nv as f64 * std::f64::consts::TAU;
            let r = 1.0 + 0.35 * v.cos();
            p.push([r * u.cos(), r * u.sin(), 0.35 * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((j % nv) * nu + (i % nu)) as u32;
    let mut t = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(p, t).unwrap()
}

/// One triangle.
pub fn single_triangle() -> TriMesh {
    TriMesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0.3, 0.9, 0.]],
        vec![[0, 1, 2]],
    )
    .unwrap()
}

/// A hemisphere-like open cap: the icosphere's triangles with all three vertices at z > -0.2.
pub fn open_cap(level: usize) -> TriMesh {
    let s = icosphere(level);
    let t: Vec<[u32; 3]> = s
        .triangles()
        .iter()
        .copied()
        .filter(|t| t.iter().all(|&v| s.positions()[v as usize][2] > -0.2))
        .collect();
    TriMesh::new(s.positions().to_vec(), t).unwrap()
}

/// `[1.2e-15, 3.4e-14, …]`.
pub fn sci(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{x:.1e}")).collect();
    format!("[{}]", s.join(", "))
}

/// A regular hexagonal patch of the triangular lattice (spacing 1/`rings`, radius 1) centred at
/// the origin: the centre vertex (index 0) has six equal neighbours.
pub fn hex_disk(rings: i64) -> TriMesh {
    let inside = |i: i64, j: i64| i.abs().max(j.abs()).max((i + j).abs()) <= rings;
    let mut index = std::collections::HashMap::new();
    let mut p = Vec::new();
    let mut coords = vec![(0i64, 0i64)];
    for i in -rings..=rings {
        for j in -rings..=rings {
            if inside(i, j) && (i, j) != (0, 0) {
                coords.push((i, j));
            }
        }
    }
    let h = 1.0 / rings as f64;
    for (n, &(i, j)) in coords.iter().enumerate() {
        index.insert((i, j), n as u32);
        p.push([
            h * (i as f64 + 0.5 * j as f64),
            h * (j as f64 * 3f64.sqrt() / 2.0),
            0.0,
        ]);
    }
    let mut t = Vec::new();
    for i in -rings..=rings {
        for j in -rings..=rings {
            let tri = [
                [(i, j), (i + 1, j), (i, j + 1)],
                [(i + 1, j), (i + 1, j + 1), (i, j + 1)],
            ];
            for c in tri {
                if c.iter().all(|&(a, b)| inside(a, b)) {
                    t.push(c.map(|k| index[&k]));
                }
            }
        }
    }
    TriMesh::new(p, t).unwrap()
}

/// The boundary loop of a disk-like mesh as an ordered vertex list.
pub fn boundary_loop(m: &TriMesh) -> Vec<u32> {
    let el = m.edges();
    let mut count = vec![0u32; el.len()];
    el.face_edges
        .iter()
        .flatten()
        .for_each(|&e| count[e as usize] += 1);
    let mut next = std::collections::HashMap::new();
    for (f, t) in m.triangles().iter().enumerate() {
        for c in 0..3 {
            if count[el.face_edges[f][c] as usize] == 1 {
                next.insert(t[c], t[(c + 1) % 3]);
            }
        }
    }
    let start = *next.keys().min().unwrap();
    let mut out = vec![start];
    let mut v = next[&start];
    while v != start {
        out.push(v);
        v = next[&v];
    }
    out
}

/// Winding number of the complex values `z` along the closed vertex loop `lp`.
#[cfg(feature = "wrinkle")]
pub fn winding(z: &[pleat::wrinkle::Complex], lp: &[u32]) -> f64 {
    let mut total = 0.0;
    for i in 0..lp.len() {
        let (a, b) = (z[lp[i] as usize], z[lp[(i + 1) % lp.len()] as usize]);
        total += (a.conj() * b).arg();
    }
    total / std::f64::consts::TAU
}
