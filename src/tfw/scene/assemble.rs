//! The assembly of a validated [`Scene`] into one stitched [`Model`]: panels sewn by merging
//! vertices within the seam tolerance (in or across panels, numbered in order of first
//! appearance), each face keeping its own rest form `Ī_f` (`rest_form`), and the Dirichlet
//! conditions mapped to the stitched vertices.

use super::description::{rest_form, Model, Motion, Scene};
use super::validate::bad;
use crate::Result;

impl Scene {
    /// Validates and stitches the scene into a [`Model`]. Errors as [`validate`](Self::validate),
    /// and when sewing collapses a triangle (two corners within the seam tolerance).
    pub fn assemble(&self) -> Result<Model> {
        let warnings = self.validate()?;
        let mut all = Vec::new();
        let mut offsets = Vec::new();
        for p in &self.panels {
            offsets.push(all.len());
            match &p.positions {
                Some(x) => all.extend_from_slice(x),
                None => all.extend(p.rest.iter().map(|r| [r[0], r[1], 0.0])),
            }
        }
        let rep = weld_within(&all, self.seam_tolerance);
        // compact numbering in order of first appearance of each representative
        let mut new_index = vec![u32::MAX; all.len()];
        let mut positions = Vec::new();
        for i in 0..all.len() {
            let r = rep[i] as usize;
            if new_index[r] == u32::MAX {
                new_index[r] = positions.len() as u32;
                positions.push(all[r]);
            }
            new_index[i] = new_index[r];
        }
        let mut triangles = Vec::new();
        let mut rest_corners = Vec::new();
        let mut rest_forms = Vec::new();
        let mut panel_vertices = Vec::new();
        for (p, panel) in self.panels.iter().enumerate() {
            let off = offsets[p];
            panel_vertices.push(
                (0..panel.rest.len())
                    .map(|i| new_index[off + i])
                    .collect::<Vec<_>>(),
            );
            for (t, tri) in panel.triangles.iter().enumerate() {
                let v = tri.map(|i| new_index[off + i as usize]);
                if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
                    return Err(bad(
                        &format!("panels[{p}].triangles[{t}]"),
                        "two corners were sewn together (seam_tolerance too large?)",
                    ));
                }
                let c = tri.map(|i| panel.rest[i as usize]);
                triangles.push(v);
                rest_forms.push(rest_form(c));
                rest_corners.push(c);
            }
        }
        let mut clamp_of: Vec<Option<Motion>> = vec![None; positions.len()];
        for d in &self.dirichlet {
            for &v in &d.vertices {
                clamp_of[panel_vertices[d.panel][v as usize] as usize] = Some(d.motion);
            }
        }
        let clamps = clamp_of
            .into_iter()
            .enumerate()
            .filter_map(|(v, m)| m.map(|m| (v as u32, m)))
            .collect();
        Ok(Model {
            positions,
            triangles,
            rest_corners,
            rest_forms,
            material: self.material,
            gravity: self.gravity,
            pressure: self.pressure,
            obstacles: self.obstacles.clone(),
            clamps,
            panel_vertices,
            warnings,
        })
    }
}

/// Per vertex, the smallest index of the vertices within `tol` (Euclidean) of it, merged
/// transitively (union–find over pairs found by a sweep along x).
fn weld_within(p: &[[f64; 3]], tol: f64) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..p.len() as u32).collect();
    fn find(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by(|&a, &b| p[a][0].total_cmp(&p[b][0]).then(a.cmp(&b)));
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if p[b][0] - p[a][0] > tol {
                break;
            }
            let d2: f64 = (0..3).map(|c| (p[a][c] - p[b][c]).powi(2)).sum();
            if d2 <= tol * tol {
                let (ra, rb) = (find(&mut parent, a as u32), find(&mut parent, b as u32));
                let (lo, hi) = (ra.min(rb), ra.max(rb));
                parent[hi as usize] = lo;
            }
        }
    }
    (0..p.len() as u32).map(|i| find(&mut parent, i)).collect()
}
