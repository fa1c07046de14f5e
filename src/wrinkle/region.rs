//! Face regions for wrinkle design and editing (dissertation §3.6; spec
//! `specs/cwf-design.md`, "Regions"): grow a face set from seed faces or vertices by rings
//! ([`grow_faces`]), and classify faces, vertices and edges of a base mesh into
//! {fixed, edit, interface} for [`edit`](super::edit::edit).
//!
//! Ring 1 is the seed faces (a seed vertex contributes its incident faces); ring `k + 1` adds
//! every face sharing a vertex ([`Adjacency::Vertex`], the text's "n-ring") or an edge
//! ([`Adjacency::Edge`], the reference code's dilation) with a face of ring ≤ k.

use super::topology::{Topology, NONE};
use crate::mesh::TriMesh;
use crate::Result;

/// How a face region grows by one ring.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u32)]
pub enum Adjacency {
    /// Faces sharing a vertex with the region join it (the dissertation's n-ring; default).
    #[default]
    Vertex = 0,
    /// Faces sharing an edge with the region join it (the reference code's dilation).
    Edge = 1,
}

/// The role of a face (and of its vertices and edges) in an edit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum FaceClass {
    /// Outside every region and its interface: values are copied bit for bit.
    Fixed = 0,
    /// Inside a region: values follow the region's operation.
    Edit = 1,
    /// In the interface band between an edit region and the fixed part: values are solved
    /// (eqs. 3.26–3.28).
    Interface = 2,
}

/// Grows the face set of `base` from `seed_faces` and `seed_vertices` by `rings` rings (ring 1
/// = the seeds themselves) across `adjacency`. Returns the faces, ascending.
///
/// Errors: [`Error::InvalidMesh`](crate::Error::InvalidMesh) when `base` is not an oriented
/// manifold (as [`Cwf::new`](super::Cwf::new)); [`Error::InvalidArgument`](crate::Error)
/// naming the element for an out-of-range seed, `rings = 0`, or an empty seed set (or seed
/// vertices that lie in no face).
pub fn grow_faces(
    base: &TriMesh,
    seed_faces: &[u32],
    seed_vertices: &[u32],
    rings: usize,
    adjacency: Adjacency,
) -> Result<Vec<u32>> {
    let topo = Topology::from_mesh(base, &base.edges())?;
    let mask = grow_mask(&topo, seed_faces, seed_vertices, rings, adjacency)?;
    Ok(mask_to_ids(&mask))
}

/// [`grow_faces`] on a built topology, as a per-face mask.
pub(crate) fn grow_mask(
    topo: &Topology,
    seed_faces: &[u32],
    seed_vertices: &[u32],
    rings: usize,
    adjacency: Adjacency,
) -> Result<Vec<bool>> {
    if rings == 0 {
        return crate::invalid_arg!("rings = 0: a region has at least one ring (its seeds)");
    }
    let mut mask = vec![false; topo.n_faces()];
    for &f in seed_faces {
        if f as usize >= topo.n_faces() {
            return crate::invalid_arg!(
                "seed face {f} is out of range (the mesh has {} triangles)",
                topo.n_faces()
            );
        }
        mask[f as usize] = true;
    }
    for &v in seed_vertices {
        if v as usize >= topo.n_vertices {
            return crate::invalid_arg!(
                "seed vertex {v} is out of range (the mesh has {} vertices)",
                topo.n_vertices
            );
        }
        for &c in topo.vert_corners.row(v as usize) {
            mask[c as usize / 3] = true;
        }
    }
    if !mask.iter().any(|&m| m) {
        return crate::invalid_arg!(
            "empty region: no seed face given and the seed vertices {seed_vertices:?} lie in \
             no triangle"
        );
    }
    dilate(topo, &mut mask, rings - 1, adjacency);
    Ok(mask)
}

/// Adds `steps` rings to the face mask.
pub(crate) fn dilate(topo: &Topology, mask: &mut [bool], steps: usize, adjacency: Adjacency) {
    for _ in 0..steps {
        let current = mask.to_vec();
        match adjacency {
            Adjacency::Vertex => {
                let mut touched = vec![false; topo.n_vertices];
                for (f, _) in current.iter().enumerate().filter(|(_, &m)| m) {
                    for &v in &topo.faces[f] {
                        touched[v as usize] = true;
                    }
                }
                for (f, m) in mask.iter_mut().enumerate() {
                    *m |= topo.faces[f].iter().any(|&v| touched[v as usize]);
                }
            }
            Adjacency::Edge => {
                for (f, _) in current.iter().enumerate().filter(|(_, &m)| m) {
                    for &e in &topo.face_edges[f] {
                        let g = topo.other_face(e as usize, f as u32);
                        if g != NONE {
                            mask[g as usize] = true;
                        }
                    }
                }
            }
        }
    }
}

/// The ids of the set entries, ascending.
pub(crate) fn mask_to_ids(mask: &[bool]) -> Vec<u32> {
    (0..mask.len() as u32)
        .filter(|&i| mask[i as usize])
        .collect()
}

/// Per face, vertex and edge: the class of an edit and, for edit elements, the region index.
#[derive(Debug, Clone)]
pub(crate) struct Labels {
    pub face: Vec<FaceClass>,
    pub vertex: Vec<FaceClass>,
    pub edge: Vec<FaceClass>,
    /// Region of each edit vertex / edge (`u32::MAX` elsewhere).
    pub vertex_region: Vec<u32>,
    pub edge_region: Vec<u32>,
}

/// Classifies the mesh for an edit of the face sets `regions` (each a list of face ids) with an
/// interface band of `interface_rings[r]` rings around region `r`. Precedence for vertices and
/// edges: edit > fixed > interface; vertices in no face are fixed. Errors naming the element:
/// out-of-range or empty region, two regions sharing a vertex, a vertex both edited and fixed
/// (an interface too thin to separate them).
pub(crate) fn classify(
    topo: &Topology,
    regions: &[&[u32]],
    interface_rings: &[usize],
    adjacency: Adjacency,
) -> Result<Labels> {
    let nf = topo.n_faces();
    let mut face = vec![FaceClass::Fixed; nf];
    let mut vertex_region = vec![u32::MAX; topo.n_vertices];
    let mut near = vec![false; nf];
    for (r, faces) in regions.iter().enumerate() {
        if faces.is_empty() {
            return crate::invalid_arg!("region {r} is empty (no face)");
        }
        let mut mask = vec![false; nf];
        for &f in faces.iter() {
            if f as usize >= nf {
                return crate::invalid_arg!(
                    "region {r}: face {f} is out of range (the mesh has {nf} triangles)"
                );
            }
            mask[f as usize] = true;
        }
        for (f, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
            face[f] = FaceClass::Edit;
            for &v in &topo.faces[f] {
                let slot = &mut vertex_region[v as usize];
                if *slot != u32::MAX && *slot != r as u32 {
                    return crate::invalid_arg!(
                        "regions {} and {r} overlap: vertex {v} belongs to both (regions must \
                         not share a vertex; merge them or shrink one)",
                        *slot
                    );
                }
                *slot = r as u32;
            }
        }
        dilate(topo, &mut mask, interface_rings[r], adjacency);
        near.iter_mut().zip(&mask).for_each(|(n, m)| *n |= m);
    }
    for (c, &n) in face.iter_mut().zip(&near) {
        if n && *c != FaceClass::Edit {
            *c = FaceClass::Interface;
        }
    }
    let mut vertex = vec![FaceClass::Interface; topo.n_vertices];
    let mut fixed_v = vec![false; topo.n_vertices];
    let mut any_face = vec![false; topo.n_vertices];
    for (t, &c) in topo.faces.iter().zip(&face) {
        for &v in t {
            any_face[v as usize] = true;
            fixed_v[v as usize] |= c == FaceClass::Fixed;
        }
    }
    for v in 0..topo.n_vertices {
        if vertex_region[v] != u32::MAX {
            if fixed_v[v] {
                return crate::invalid_arg!(
                    "vertex {v} is both edited (region {}) and fixed: the interface is too \
                     thin (use at least 1 interface ring)",
                    vertex_region[v]
                );
            }
            vertex[v] = FaceClass::Edit;
        } else if fixed_v[v] || !any_face[v] {
            vertex[v] = FaceClass::Fixed;
        }
    }
    let mut edge = vec![FaceClass::Interface; topo.n_edges()];
    let mut edge_region = vec![u32::MAX; topo.n_edges()];
    for e in 0..topo.n_edges() {
        let classes = topo.edge_faces[e]
            .iter()
            .filter(|&&g| g != NONE)
            .map(|&g| face[g as usize]);
        let (mut is_edit, mut is_fixed) = (false, false);
        for c in classes {
            is_edit |= c == FaceClass::Edit;
            is_fixed |= c == FaceClass::Fixed;
        }
        if is_edit {
            edge[e] = FaceClass::Edit;
            edge_region[e] = vertex_region[topo.edges[e][0] as usize];
        } else if is_fixed {
            edge[e] = FaceClass::Fixed;
        }
    }
    Ok(Labels {
        face,
        vertex,
        edge,
        vertex_region,
        edge_region,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crate's test grid, `n × n` squares.
    fn grid(n: u32) -> TriMesh {
        crate::mesh::test_shapes::grid(n, n)
    }

    #[test]
    fn rings_grow_monotonically_and_edge_rings_are_smaller() {
        let m = grid(10);
        let centre = 5 * 11 + 5;
        let mut last = 0;
        for rings in 1..5 {
            let v = grow_faces(&m, &[], &[centre], rings, Adjacency::Vertex).unwrap();
            let e = grow_faces(&m, &[], &[centre], rings, Adjacency::Edge).unwrap();
            assert!(v.len() > last);
            assert!(e.len() <= v.len());
            last = v.len();
        }
        // an interior vertex of this grid has 6 faces
        assert_eq!(
            grow_faces(&m, &[], &[centre], 1, Adjacency::Vertex)
                .unwrap()
                .len(),
            6
        );
    }

    #[test]
    fn bad_seeds_are_named() {
        let m = grid(3);
        let e = grow_faces(&m, &[99], &[], 2, Adjacency::Vertex).unwrap_err();
        assert!(e.to_string().contains("face 99"), "{e}");
        let e = grow_faces(&m, &[], &[77], 2, Adjacency::Vertex).unwrap_err();
        assert!(e.to_string().contains("vertex 77"), "{e}");
        let e = grow_faces(&m, &[], &[], 2, Adjacency::Vertex).unwrap_err();
        assert!(e.to_string().contains("empty"), "{e}");
    }

    #[test]
    fn classify_rejects_thin_interface_and_overlap() {
        let m = grid(10);
        let topo = Topology::from_mesh(&m, &m.edges()).unwrap();
        let a = grow_faces(&m, &[], &[5 * 11 + 5], 2, Adjacency::Vertex).unwrap();
        let e = classify(&topo, &[&a], &[0], Adjacency::Vertex).unwrap_err();
        assert!(e.to_string().contains("too thin"), "{e}");
        let b = grow_faces(&m, &[], &[5 * 11 + 7], 2, Adjacency::Vertex).unwrap();
        let e = classify(&topo, &[&a, &b], &[1, 1], Adjacency::Vertex).unwrap_err();
        assert!(e.to_string().contains("overlap"), "{e}");
        let l = classify(&topo, &[&a], &[2], Adjacency::Vertex).unwrap();
        let n_edit = l.face.iter().filter(|&&c| c == FaceClass::Edit).count();
        assert_eq!(n_edit, a.len());
        assert!(l.face.contains(&FaceClass::Interface));
        assert!(l.vertex.contains(&FaceClass::Fixed));
    }
}
