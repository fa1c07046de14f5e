//! [`ExactWeld`]: merging of vertices with exactly equal coordinates, as `meshcheck` does
//! (`weld_map` in its `meshio.hpp`): each vertex maps to the smallest index with the same
//! coordinates. Comparison is IEEE equality, so `-0.0` and `0.0` are the same coordinate; there is
//! no tolerance.

use rayon::prelude::*;
use std::cmp::Ordering;

/// The result of exact welding: a representative per vertex and duplicate counts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExactWeld {
    /// `rep[v]` is the smallest vertex index whose coordinates equal those of `v` exactly
    /// (`rep[v] == v` for representatives).
    pub rep: Vec<u32>,
    /// Number of vertices that are not their own representative (meshcheck's
    /// `n_duplicate_points`): `Σ (group size − 1)` over groups of coincident vertices.
    pub n_duplicates: usize,
    /// Number of vertices that share their position with at least one other vertex:
    /// `Σ group size` over groups of size ≥ 2 (the corpus MANIFEST's `n_coincident_vertices`).
    pub n_coincident: usize,
}

impl ExactWeld {
    /// Welds `positions` (which must be free of NaN). Deterministic; sorts in parallel.
    pub fn compute(positions: &[[f64; 3]]) -> ExactWeld {
        let mut order: Vec<u32> = (0..positions.len() as u32).collect();
        let key = |i: u32| positions[i as usize];
        order.par_sort_unstable_by(|&a, &b| cmp_point(key(a), key(b)).then(a.cmp(&b)));
        let mut rep = vec![0u32; positions.len()];
        let (mut n_duplicates, mut n_coincident) = (0, 0);
        let mut i = 0;
        while i < order.len() {
            let first = order[i];
            let mut j = i + 1;
            while j < order.len() && cmp_point(key(order[j]), key(first)) == Ordering::Equal {
                j += 1;
            }
            for &v in &order[i..j] {
                rep[v as usize] = first; // the group is sorted by index: `first` is the smallest
            }
            if j - i > 1 {
                n_duplicates += j - i - 1;
                n_coincident += j - i;
            }
            i = j;
        }
        ExactWeld {
            rep,
            n_duplicates,
            n_coincident,
        }
    }

    /// True when no two vertices coincide.
    pub fn is_identity(&self) -> bool {
        self.n_duplicates == 0
    }

    /// The triangles with every index replaced by its representative.
    pub fn apply(&self, triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
        triangles
            .par_iter()
            .map(|t| t.map(|v| self.rep[v as usize]))
            .collect()
    }
}

/// Lexicographic order on coordinates with IEEE equality (`-0.0 == 0.0`); inputs are finite.
#[inline]
fn cmp_point(a: [f64; 3], b: [f64; 3]) -> Ordering {
    for k in 0..3 {
        match a[k].partial_cmp(&b[k]) {
            Some(Ordering::Equal) | None => continue,
            Some(o) => return o,
        }
    }
    Ordering::Equal
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welds_exact_duplicates_to_smallest_index() {
        let p = [
            [1., 2., 3.],
            [0., 0., 0.],
            [1., 2., 3.],
            [-0.0, 0., 0.],
            [1., 2., 3. + 1e-15],
            [1., 2., 3.],
        ];
        let w = ExactWeld::compute(&p);
        assert_eq!(w.rep, vec![0, 1, 0, 1, 4, 0]);
        assert_eq!((w.n_duplicates, w.n_coincident), (3, 5));
        assert_eq!(w.apply(&[[5, 3, 4]]), vec![[0, 1, 4]]);
        assert!(!w.is_identity());
        assert!(ExactWeld::compute(&[[0.; 3], [1.; 3]]).is_identity());
    }
}
