//! Interior removal (Algorithm 1, line 13): the unsigned offset has invisible components —
//! the inner sheet of a closed input, bubbles inside thick parts. Each component of the
//! (closed, oriented, intersection-free) offset surface is dropped when a point of it has a
//! non-zero winding number with respect to another component. The pipeline decides this on the
//! MC33 template surface right after extraction (see `offset::visible_patches`), so invisible
//! components never reach the feature phase.
//!
//! Since the mesh is intersection-free, a component lies entirely inside or entirely outside
//! another, so one sample vertex decides; the winding number of a closed surface at a point not
//! on it is an integer, so `|w| > ½` is a robust test. Candidates come from a BVH over the
//! components' boxes (a container's box contains the contained one's), and each container's
//! winding number is evaluated with the hierarchical approximation of Barill et al. 2018
//! (`spatial::FastWindingNumber`), so 10⁴ components or a million-triangle outer shell cost
//! O(n log n).
//!
//! Memory: containers are processed one at a time, largest box first, and a container found
//! hidden is skipped (whatever it holds is inside the larger container that hid it, which
//! already tested it). So one hierarchy is alive at a time — for a closed input, only the
//! outer sheet's, not also the inner sheet's — and its leaves hold up to 32 triangles, which
//! makes the tree about 4× smaller than the default.

use rayon::prelude::*;

use crate::geom::Vec3;
use crate::mesh::TriMesh;
use crate::spatial::{BoxTree, FastWindingNumber};

#[cfg(test)]
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

/// A component as the containment test sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ComponentBox {
    /// Bounding box.
    pub lo: Vec3,
    /// Bounding box.
    pub hi: Vec3,
    /// A point on the component.
    pub sample: Vec3,
}

impl ComponentBox {
    /// An empty box with sample point `sample`.
    pub(crate) fn empty(sample: Vec3) -> ComponentBox {
        ComponentBox {
            lo: Vec3::INFINITY,
            hi: Vec3::NEG_INFINITY,
            sample,
        }
    }

    /// Extends the box to contain `x`.
    pub(crate) fn grow(&mut self, x: Vec3) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(x[k]);
            self.hi[k] = self.hi[k].max(x[k]);
        }
    }
}

/// Which of `n` components to keep: those not inside any other. `boxes[c]` describes
/// component `c`; `triangles(c)` yields its closed triangle set (asked only for components
/// that contain another's box, the only possible containers).
pub(crate) fn visible_components(
    pos: &[Vec3],
    boxes: &[ComponentBox],
    triangles: &(dyn Fn(usize) -> Vec<[u32; 3]> + Sync),
) -> Vec<bool> {
    let n = boxes.len();
    if n <= 1 {
        return vec![true; n];
    }
    let tree = BoxTree::new(boxes.iter().map(|b| (b.lo, b.hi)));
    let mut inside_of: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (a, ab) in boxes.iter().enumerate() {
        for b in tree.overlapping(ab.lo, ab.hi) {
            if b as usize != a && contains(&boxes[b as usize], &boxes[a]) {
                inside_of[b as usize].push(a as u32);
            }
        }
    }
    let mut keep = vec![true; n];
    for b in containers_largest_first(boxes, &inside_of) {
        // A hidden container lies inside a larger one, which was tested first and holds
        // (by box) everything this one holds: nothing to do.
        if !keep[b] {
            continue;
        }
        let candidates: Vec<u32> = inside_of[b]
            .iter()
            .copied()
            .filter(|&a| keep[a as usize])
            .collect();
        if candidates.is_empty() {
            continue;
        }
        for a in hidden_inside(pos, triangles(b), boxes, &candidates) {
            keep[a as usize] = false;
        }
    }
    keep
}

/// Leaf size of the containers' winding-number trees: a tree node takes about 400 bytes,
/// so 32 makes the tree of a million-triangle shell ~4× smaller than the default 8; only a
/// handful of sample points are queried.
const CONTAINER_LEAF_SIZE: usize = 32;

/// The components that contain another one's box, by decreasing box size (sum of extents;
/// a component inside another has a strictly smaller box), ties by index.
fn containers_largest_first(boxes: &[ComponentBox], inside_of: &[Vec<u32>]) -> Vec<usize> {
    let size = |b: usize| (0..3).map(|k| boxes[b].hi[k] - boxes[b].lo[k]).sum::<f64>();
    let mut order: Vec<usize> = (0..boxes.len())
        .filter(|&b| !inside_of[b].is_empty())
        .collect();
    order.sort_by(|&a, &b| size(b).total_cmp(&size(a)).then(a.cmp(&b)));
    order
}

/// The `candidates` whose sample point is inside the closed surface `tris` (winding number
/// of the hierarchy of Barill et al. 2018). One container's hierarchy is alive at a time.
fn hidden_inside(
    pos: &[Vec3],
    tris: Vec<[u32; 3]>,
    boxes: &[ComponentBox],
    candidates: &[u32],
) -> Vec<u32> {
    let Some(mesh) = component_mesh(pos, tris) else {
        return Vec::new();
    };
    let fwn = FastWindingNumber::with_options(&mesh, 2.0, CONTAINER_LEAF_SIZE);
    drop(mesh);
    candidates
        .par_iter()
        .copied()
        .filter(|&a| {
            fwn.winding_number(boxes[a as usize].sample.to_array())
                .abs()
                > 0.5
        })
        .collect()
}

/// The triangles `tris` (indexing `pos`) as a compact mesh, renumbered in place.
fn component_mesh(pos: &[Vec3], mut tris: Vec<[u32; 3]>) -> Option<TriMesh> {
    let mut map = std::collections::HashMap::new();
    let mut p = Vec::new();
    for v in tris.iter_mut().flatten() {
        *v = *map.entry(*v).or_insert_with(|| {
            p.push(pos[*v as usize].to_array());
            (p.len() - 1) as u32
        });
    }
    drop(map);
    TriMesh::new(p, tris).ok()
}

fn contains(outer: &ComponentBox, inner: &ComponentBox) -> bool {
    (0..3).all(|k| outer.lo[k] <= inner.lo[k] && inner.hi[k] <= outer.hi[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(c: Vec3, r: f64, flip: bool) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    c[0] + if i & 1 == 1 { r } else { -r },
                    c[1] + if i & 2 == 2 { r } else { -r },
                    c[2] + if i & 4 == 4 { r } else { -r },
                )
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
        let (mut pos, mut tris) = cube(Vec3::ZERO, 1.0, false);
        for (c, r, flip) in [
            (Vec3::ZERO, 0.5, true),
            (Vec3::new(3.0, 0.0, 0.0), 0.5, false),
        ] {
            let (p, t) = cube(c, r, flip);
            let base = pos.len() as u32;
            pos.extend(p);
            tris.extend(t.iter().map(|x| x.map(|v| v + base)));
        }
        let (comp, n) = components(pos.len(), &tris);
        assert_eq!(n, 3);
        let members: Vec<Vec<[u32; 3]>> = (0..n as u32)
            .map(|c| {
                tris.iter()
                    .zip(&comp)
                    .filter(|x| *x.1 == c)
                    .map(|x| *x.0)
                    .collect()
            })
            .collect();
        let boxes: Vec<ComponentBox> = members
            .iter()
            .map(|m| {
                let mut b = ComponentBox::empty(pos[m[0][0] as usize]);
                for &v in m.iter().flatten() {
                    b.grow(pos[v as usize]);
                }
                b
            })
            .collect();
        assert_eq!(
            visible_components(&pos, &boxes, &|c| members[c].clone()),
            vec![true, false, true]
        );
    }
}
