//! Interior removal (Algorithm 1, line 13): the unsigned offset has invisible components —
//! the inner sheet of a closed input, bubbles inside thick parts. Each component of the
//! (closed, oriented, intersection-free) offset mesh is dropped when a point of it has a
//! non-zero winding number with respect to another component.
//!
//! Since the mesh is intersection-free, a component lies entirely inside or entirely outside
//! another, so one sample vertex decides; the winding number of a closed surface at a point not
//! on it is an integer, so `|w| > ½` is a robust test. Candidates come from a BVH over the
//! components' boxes (a container's box contains the contained one's), and each container's
//! winding number is evaluated with the hierarchical approximation of Barill et al. 2018
//! (`spatial::FastWindingNumber`), so 10⁴ components or a million-triangle outer shell cost
//! O(n log n).

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use rayon::prelude::*;

use super::geom::V3;
use crate::mesh::TriMesh;
use crate::spatial::FastWindingNumber;

/// Connected components of a triangle mesh through shared vertices: `comp[t]` per triangle and
/// the component count. Components are numbered by their smallest triangle index.
pub(crate) fn components(n_vertices: usize, tris: &[[u32; 3]]) -> (Vec<u32>, usize) {
    let mut parent: Vec<u32> = (0..n_vertices as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    for t in tris {
        for k in 1..3 {
            let (a, b) = (find(&mut parent, t[0]), find(&mut parent, t[k]));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut label = vec![u32::MAX; n_vertices];
    let mut n = 0usize;
    let comp = tris
        .iter()
        .map(|t| {
            let r = find(&mut parent, t[0]) as usize;
            if label[r] == u32::MAX {
                label[r] = n as u32;
                n += 1;
            }
            label[r]
        })
        .collect();
    (comp, n)
}

/// Which components to keep: those not inside any other component.
pub(crate) fn visible_components(
    pos: &[V3],
    tris: &[[u32; 3]],
    comp: &[u32],
    n: usize,
) -> Vec<bool> {
    if n <= 1 {
        return vec![true; n];
    }
    let mut members: Vec<Vec<[u32; 3]>> = vec![Vec::new(); n];
    for (t, &c) in tris.iter().zip(comp) {
        members[c as usize].push(*t);
    }
    let boxes: Vec<(V3, V3)> = members.iter().map(|m| bbox(pos, m)).collect();
    // Candidate containers of each component: components whose box contains its box.
    let aabbs: Vec<Aabb> = boxes
        .iter()
        .map(|b| Aabb::new(Vector::from(b.0), Vector::from(b.1)))
        .collect();
    let tree = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
    let mut inside_of: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (a, ab) in aabbs.iter().enumerate() {
        for b in tree.intersect_aabb(ab) {
            if b as usize != a && contains(&boxes[b as usize], &boxes[a]) {
                inside_of[b as usize].push(a as u32);
            }
        }
    }
    // One winding-number hierarchy per actual container (Barill et al. 2018).
    let hidden: Vec<Vec<u32>> = (0..n)
        .into_par_iter()
        .filter(|&b| !inside_of[b].is_empty())
        .map(|b| {
            let Some(mesh) = component_mesh(pos, &members[b]) else {
                return Vec::new();
            };
            let fwn = FastWindingNumber::new(&mesh);
            inside_of[b]
                .iter()
                .copied()
                .filter(|&a| {
                    let q = pos[members[a as usize][0][0] as usize];
                    fwn.winding_number(q).abs() > 0.5
                })
                .collect()
        })
        .collect();
    let mut keep = vec![true; n];
    for a in hidden.into_iter().flatten() {
        keep[a as usize] = false;
    }
    keep
}

/// The triangles `tris` (indexing `pos`) as a compact mesh.
fn component_mesh(pos: &[V3], tris: &[[u32; 3]]) -> Option<TriMesh> {
    let mut map = std::collections::HashMap::new();
    let mut p = Vec::new();
    let t: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| {
            t.map(|v| {
                *map.entry(v).or_insert_with(|| {
                    p.push(pos[v as usize]);
                    (p.len() - 1) as u32
                })
            })
        })
        .collect();
    TriMesh::new(p, t).ok()
}

fn bbox(pos: &[V3], tris: &[[u32; 3]]) -> (V3, V3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in tris {
        for &v in t {
            let p = pos[v as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (lo, hi)
}

fn contains(outer: &(V3, V3), inner: &(V3, V3)) -> bool {
    (0..3).all(|k| outer.0[k] <= inner.0[k] && inner.1[k] <= outer.1[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(c: V3, r: f64, flip: bool) -> (Vec<V3>, Vec<[u32; 3]>) {
        let p: Vec<V3> = (0..8)
            .map(|i| {
                [
                    c[0] + if i & 1 == 1 { r } else { -r },
                    c[1] + if i & 2 == 2 { r } else { -r },
                    c[2] + if i & 4 == 4 { r } else { -r },
                ]
            })
            .collect();
        let mut t = vec![
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
        if flip {
            for x in &mut t {
                x.swap(1, 2);
            }
        }
        (p, t)
    }

    #[test]
    fn nested_components_are_removed() {
        let (mut pos, mut tris) = cube([0.0; 3], 1.0, false);
        for (c, r, flip) in [([0.0; 3], 0.5, true), ([3.0, 0.0, 0.0], 0.5, false)] {
            let (p, t) = cube(c, r, flip);
            let base = pos.len() as u32;
            pos.extend(p);
            tris.extend(t.iter().map(|x| x.map(|v| v + base)));
        }
        let (comp, n) = components(pos.len(), &tris);
        assert_eq!(n, 3);
        assert_eq!(
            visible_components(&pos, &tris, &comp, n),
            vec![true, false, true]
        );
    }
}
