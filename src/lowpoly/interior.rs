//! Interior removal (Algorithm 1, line 13): the unsigned offset has invisible components —
//! the inner sheet of a closed input, bubbles inside thick parts. Each component of the
//! (closed, oriented, intersection-free) offset mesh is dropped when a point of it has a
//! non-zero winding number with respect to another component.
//!
//! Since the mesh is intersection-free, a component lies entirely inside or entirely outside
//! another, so one sample vertex decides; the winding number of a closed surface at a point not
//! on it is an integer, so `|w| > ½` is a robust test.

use rayon::prelude::*;

use super::geom::{cross, dot, norm, sub, V3};

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

/// Winding number of the closed triangle set `tris` at `q` (solid angles, Van Oosterom and
/// Strackee 1983).
pub(crate) fn winding_number(pos: &[V3], tris: &[[u32; 3]], q: V3) -> f64 {
    let mut sum = 0.0;
    for t in tris {
        let a = sub(pos[t[0] as usize], q);
        let b = sub(pos[t[1] as usize], q);
        let c = sub(pos[t[2] as usize], q);
        let (la, lb, lc) = (norm(a), norm(b), norm(c));
        let num = dot(a, cross(b, c));
        let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
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
    let bbox: Vec<(V3, V3)> = members
        .iter()
        .map(|m| {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for t in m {
                for &v in t {
                    let p = pos[v as usize];
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
            }
            (lo, hi)
        })
        .collect();
    // Candidate containers: components whose box contains this one's box, largest first.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        volume(&bbox[b])
            .total_cmp(&volume(&bbox[a]))
            .then(a.cmp(&b))
    });
    (0..n)
        .into_par_iter()
        .map(|a| {
            let q = pos[members[a][0][0] as usize];
            !order.iter().any(|&b| {
                b != a
                    && contains(&bbox[b], &bbox[a])
                    && winding_number(pos, &members[b], q).abs() > 0.5
            })
        })
        .collect()
}

fn volume(b: &(V3, V3)) -> f64 {
    (0..3).map(|k| (b.1[k] - b.0[k]).max(0.0)).product()
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
        assert!((winding_number(&pos, &tris[..12], [0.1, 0.2, 0.3]) - 1.0).abs() < 1e-9);
        let (comp, n) = components(pos.len(), &tris);
        assert_eq!(n, 3);
        assert_eq!(
            visible_components(&pos, &tris, &comp, n),
            vec![true, false, true]
        );
    }
}
