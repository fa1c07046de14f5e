//! The deformation a LOD must be able to follow: skin weights and morph-target displacements
//! of the input ([`DeformationField`], `LodParams::deformation`).
//!
//! A LOD is made in the bind pose. Posed, each of its vertices moves with the skin weights (and
//! morph displacements) of the input surface it lies on, and each face moves linearly between
//! its corners. Where the input's weights change along the surface — across a joint — the
//! input bends smoothly while a long LOD face spanning the change stays a chord between its
//! corners: a straight tube bent 1 rad at its middle, simplified to a prism with no vertex
//! near the bend, ends 0.18 l from the posed input while its bind-pose distance is 0.013 l
//! (measured with weights transferred exactly). No weight transfer cures that: the vertices are
//! missing.
//!
//! The rule here keeps them, and only them: it bounds the error the deformation adds, in
//! pixels. Every vertex of the simplified mesh carries the deformation of the input point
//! nearest to it (its *label*: weights and displacements interpolated barycentrically on the
//! closest input triangle), and a collapse is refused when an edge it creates
//! - posed, bends away from its own posed ends by more than the allowed error `ε · d`
//!   (`DeformationField::max_skin_error`, default [`SKIN_ERROR`]): linear blend
//!   skinning is bilinear in weights and position, so the middle of an edge `p q` posed is off
//!   the posed middle by `¼ Σ_j Δw_j (T_j − I)(p − q)`, at most `¼ θ Σ_j |Δw_j| |p − q|` for
//!   joints turning by up to `θ` (`DeformationField::max_rotation`) — unless the edge it
//!   replaces already did;
//! - or runs over input whose deformation is not the linear blend of its ends, sampled at a
//!   quarter, half and three quarters of the edge: weights off by `Δw` move a point `p` by
//!   `Σ_j Δw_j (T_j − I) p`, at most `½ θ Σ_j |Δw_j| |p − h_j|` with `h_j` the joints' pivots,
//!   and that may not exceed `ε · d`; morph displacements may not stray more than
//!   [`MORPH_DEVIATION`]` · d`. This keeps a ring where a weight profile starts or stops
//!   changing (a kink the gap bound lets an edge skip), and vertices on a morph's bump.
//!
//! Both bounds scale with `d`: a coarse level keeps fewer rings than a fine one. Parts where
//! the deformation is constant or linear (a bone's rigid middle, a uniform morph, everything
//! of a static mesh) simplify exactly as before. The cost is faces where weights change;
//! figures in the glTF-scenes chapter of the guide.
//!
//! May import what `lowpoly` may.

use crate::geom::{barycentric, Vec3};
use crate::spatial::bvh::TriangleBvh;
use crate::{Error, Result};

/// The default largest posed error, in units of `d = l / n_p` (half a pixel at the level's
/// screen size), that a collapse may introduce through the skin (module docs;
/// `DeformationField::max_skin_error`). Measured 2026-12-07 on the generated 14-joint
/// character (`tests/gltf_scene.rs`, its animation through 10 poses, n_p = 100 and 50): the
/// LOD's one-sided distance to the posed input grows from 0.0104 and 0.0216 `l` in the bind
/// pose to at most 0.0145 and 0.0216 `l` (1.4 × and 1.0 ×) with 0.5; to 0.0192 and 0.0406 `l`
/// (1.8 × and 2.0 ×) with 1; a plain simplification grows from 0.013 and 0.024 to 0.044 and
/// 0.043 (3.3 × and 1.8 ×). The price is faces: 1874 and 1066 with 0.5, 1246 and 654 with 1,
/// 188 and 62 for the plain simplification, out of 5440.
pub const SKIN_ERROR: f64 = 0.5;

/// The joint rotation, in radians, the skin criterion assumes when the field gives none
/// (`DeformationField::max_rotation` = 0): about 57°.
pub const DEFAULT_MAX_ROTATION: f64 = 1.0;

/// Largest difference, in units of `d = l / n_p`, between a morph target's displacement of
/// the input at a point of a new edge and the edge's linear blend of its end displacements
/// (half a pixel at the level's screen size): a LOD point moves by the blend, the input by its
/// own displacement.
pub const MORPH_DEVIATION: f64 = 0.5;

/// Per input vertex, the deformation a LOD must follow: skin weights and morph-target
/// displacements, in the input's vertex order (`LodParams::deformation`). Either part may be
/// empty. Checked by `LodParams::validate` against the input: `joints` and `weights` have
/// `influences` entries per vertex, weights are finite and `≥ 0`, every morph target has one
/// finite displacement per vertex.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DeformationField {
    /// Influences per vertex (0 = no skin).
    pub influences: usize,
    /// Joint index of each influence, `influences` per vertex.
    pub joints: Vec<u32>,
    /// Weight of each influence, `influences` per vertex (need not be sorted or normalised; zero
    /// weights are ignored).
    pub weights: Vec<f32>,
    /// Morph targets: each a displacement per vertex (model units).
    pub morph_deltas: Vec<Vec<[f32; 3]>>,
    /// The bind-pose position of each joint's pivot, by joint index (the lever arm of a weight
    /// error; a joint without one counts the input's bounding-box diagonal).
    pub joint_pivots: Vec<[f64; 3]>,
    /// The largest rotation in radians a joint makes relative to the bind pose (0: assume
    /// [`DEFAULT_MAX_ROTATION`]).
    pub max_rotation: f64,
    /// The largest posed error the skin may add, in units of `d = l / n_p` (pixels at the
    /// level's screen size; 0: [`SKIN_ERROR`]). Larger keeps fewer vertices where weights
    /// change.
    pub max_skin_error: f64,
}

impl DeformationField {
    /// `InvalidArgument` naming the first array that does not match `vertices` input vertices
    /// or holds a non-finite or negative weight or a non-finite displacement.
    pub fn validate(&self, vertices: usize) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidArgument(format!("deformation: {m}")));
        let k = self.influences;
        let expected = vertices.checked_mul(k);
        if expected != Some(self.joints.len()) || expected != Some(self.weights.len()) {
            return bad(format!(
                "{} joints and {} weights for {vertices} vertices × {k} influences",
                self.joints.len(),
                self.weights.len()
            ));
        }
        if let Some(w) = self.weights.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
            return bad(format!("weight {w} is not finite and >= 0"));
        }
        if self.joint_pivots.iter().flatten().any(|x| !x.is_finite()) {
            return bad("a joint pivot is not finite".into());
        }
        if !(self.max_skin_error.is_finite() && self.max_skin_error >= 0.0) {
            return bad(format!(
                "max_skin_error must be finite and >= 0, got {}",
                self.max_skin_error
            ));
        }
        if !(self.max_rotation.is_finite() && self.max_rotation >= 0.0) {
            return bad(format!(
                "max_rotation must be finite and >= 0, got {}",
                self.max_rotation
            ));
        }
        for (t, deltas) in self.morph_deltas.iter().enumerate() {
            if deltas.len() != vertices {
                return bad(format!(
                    "morph target {t} has {} displacements for {vertices} vertices",
                    deltas.len()
                ));
            }
            if deltas.iter().flatten().any(|x| !x.is_finite()) {
                return bad(format!("morph target {t} has a non-finite displacement"));
            }
        }
        Ok(())
    }

    /// Whether there is nothing to follow (no influence and no morph target).
    pub(crate) fn is_empty(&self) -> bool {
        self.influences == 0 && self.morph_deltas.is_empty()
    }

    /// The nonzero influences of input vertex `v`.
    fn influences_of(&self, v: usize) -> impl Iterator<Item = (u32, f32)> + '_ {
        let r = v * self.influences..(v + 1) * self.influences;
        self.joints[r.clone()]
            .iter()
            .copied()
            .zip(self.weights[r].iter().copied())
            .filter(|&(_, w)| w > 0.0)
    }
}

/// The deformation at one point of the input: skin weights by joint (sorted by joint, summed
/// over duplicates) and one displacement per morph target.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Label {
    skin: Vec<(u32, f32)>,
    morph: Vec<[f32; 3]>,
}

/// What the skin criterion needs of the field: each joint's pivot, the lever arm of a joint
/// without one, and the rotation assumed.
pub(crate) struct Lever<'f> {
    pivots: &'f [[f64; 3]],
    fallback: f64,
    rotation: f64,
    /// The allowed posed error in units of `d`.
    error: f64,
}

impl<'f> Lever<'f> {
    /// The lever of `field` for an input of bounding-box diagonal `diag`.
    pub(crate) fn new(field: &'f DeformationField, diag: f64) -> Lever<'f> {
        let rotation = if field.max_rotation > 0.0 {
            field.max_rotation
        } else {
            DEFAULT_MAX_ROTATION
        };
        let error = if field.max_skin_error > 0.0 {
            field.max_skin_error
        } else {
            SKIN_ERROR
        };
        Lever {
            pivots: &field.joint_pivots,
            fallback: diag,
            rotation,
            error,
        }
    }

    /// Distance from `p` to joint `j`'s pivot.
    fn arm(&self, j: u32, p: Vec3) -> f64 {
        self.pivots
            .get(j as usize)
            .map_or(self.fallback, |&h| p.distance(Vec3::from(h)))
    }
}

impl Label {
    /// The posed error of an edge `p q` whose ends carry `self` and `o`, over
    /// the allowed error `ε · d` (`DeformationField::max_skin_error`): linear blend skinning is bilinear in weights and position, so the
    /// posed middle of the edge is off the middle of the posed ends by
    /// `¼ Σ_j Δw_j (T_j − I)(p − q)`, at most `¼ θ Σ_j |Δw_j| |p − q|` for joints turning by up
    /// to `θ`. At most 1 is allowed.
    pub(crate) fn skin_gap(&self, o: &Label, length: f64, lever: &Lever<'_>, d: f64) -> f64 {
        let e = 0.25 * lever.rotation * total_abs_difference(&self.skin, &o.skin) * length;
        e / (lever.error * d)
    }

    /// How far this label (the input's, at the point `p` a fraction `t` along an edge from
    /// `a`'s end to `b`'s) is from the edge's linear blend `(1 − t) a + t b`, relative to what
    /// is allowed: the larger of the skin's posed error over the allowed `ε · d` and the
    /// largest morph displacement difference over [`MORPH_DEVIATION`]` · d`. The skin's error:
    /// a point skinned with weights off by `Δw` moves by `Σ_j Δw_j (T_j − I) p` (`Σ_j Δw_j = 0`),
    /// at most `½ θ Σ_j |Δw_j| |p − h_j|` for joints turning by up to `θ` about their pivots
    /// `h_j`. At most 1 is allowed.
    pub(crate) fn deviation(
        &self,
        a: &Label,
        b: &Label,
        t: f32,
        p: Vec3,
        lever: &Lever<'_>,
        d: f64,
    ) -> f64 {
        let blend = lerp_weights(&a.skin, &b.skin, t);
        let skin =
            0.5 * lever.rotation * weighted_abs_difference(&self.skin, &blend, |j| lever.arm(j, p));
        let morph = self
            .morph
            .iter()
            .zip(a.morph.iter().zip(&b.morph))
            .map(|(m, (ma, mb))| {
                let e = [0, 1, 2].map(|i| f64::from(m[i] - ((1.0 - t) * ma[i] + t * mb[i])));
                Vec3::from(e).length()
            })
            .fold(0.0, f64::max);
        (skin / (lever.error * d)).max(morph / (MORPH_DEVIATION * d))
    }
}

/// `Σ_j |a_j − b_j| · arm(j)` of two joint-sorted sparse weight lists.
fn weighted_abs_difference(a: &[(u32, f32)], b: &[(u32, f32)], arm: impl Fn(u32) -> f64) -> f64 {
    let (mut i, mut j, mut s) = (0, 0, 0.0f64);
    while i < a.len() || j < b.len() {
        let (ja, jb) = (a.get(i).map(|x| x.0), b.get(j).map(|x| x.0));
        let (joint, diff) = if ja.is_some() && (jb.is_none() || ja < jb) {
            i += 1;
            (a[i - 1].0, a[i - 1].1)
        } else if jb.is_some() && (ja.is_none() || jb < ja) {
            j += 1;
            (b[j - 1].0, b[j - 1].1)
        } else {
            i += 1;
            j += 1;
            (a[i - 1].0, (a[i - 1].1 - b[j - 1].1).abs())
        };
        if diff != 0.0 {
            s += f64::from(diff) * arm(joint);
        }
    }
    s
}

/// `(1 − t) a + t b` of two joint-sorted sparse weight lists (joint-sorted).
fn lerp_weights(a: &[(u32, f32)], b: &[(u32, f32)], t: f32) -> Vec<(u32, f32)> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let (ja, jb) = (a.get(i).map(|x| x.0), b.get(j).map(|x| x.0));
        if ja.is_some() && (jb.is_none() || ja < jb) {
            out.push((a[i].0, (1.0 - t) * a[i].1));
            i += 1;
        } else if jb.is_some() && (ja.is_none() || jb < ja) {
            out.push((b[j].0, t * b[j].1));
            j += 1;
        } else {
            out.push((a[i].0, (1.0 - t) * a[i].1 + t * b[j].1));
            i += 1;
            j += 1;
        }
    }
    out
}

/// `Σ_j |a_j − b_j|` of two joint-sorted sparse weight lists.
fn total_abs_difference(a: &[(u32, f32)], b: &[(u32, f32)]) -> f64 {
    weighted_abs_difference(a, b, |_| 1.0)
}

/// The input as [`label_at`] queries it: its vertices, triangles and their tree.
pub(crate) struct LabelInput<'i> {
    pub positions: &'i [[f64; 3]],
    pub tris: &'i [[u32; 3]],
    pub bvh: &'i TriangleBvh,
}

/// The label of point `p`: the field interpolated barycentrically on the input triangle closest
/// to `p` (the triangle's nearest corner when it is degenerate). `None` when the input has no
/// triangle.
pub(crate) fn label_at(
    model: &LabelInput<'_>,
    field: &DeformationField,
    p: [f64; 3],
) -> Option<Label> {
    let c = model
        .bvh
        .closest_point(model.positions, model.tris, p, f64::INFINITY)?;
    let t = model.tris[c.triangle as usize];
    let corners = t.map(|v| Vec3::from(model.positions[v as usize]));
    let bary = barycentric(corners, Vec3::from(c.point));
    let mut skin: Vec<(u32, f32)> = Vec::with_capacity(3 * field.influences);
    for (k, &v) in t.iter().enumerate() {
        if bary[k] > 0.0 {
            let b = bary[k] as f32;
            skin.extend(field.influences_of(v as usize).map(|(j, w)| (j, b * w)));
        }
    }
    skin.sort_by_key(|&(j, _)| j);
    skin.dedup_by(|next, kept| {
        let same = next.0 == kept.0;
        if same {
            kept.1 += next.1;
        }
        same
    });
    let morph = field
        .morph_deltas
        .iter()
        .map(|deltas| {
            let mut s = [0.0f32; 3];
            for (k, &v) in t.iter().enumerate() {
                let dv = deltas[v as usize];
                for i in 0..3 {
                    s[i] += bary[k] as f32 * dv[i];
                }
            }
            s
        })
        .collect();
    Some(Label { skin, morph })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn label(skin: &[(u32, f32)], morph: &[[f32; 3]]) -> Label {
        Label {
            skin: skin.to_vec(),
            morph: morph.to_vec(),
        }
    }

    fn lever(pivots: &[[f64; 3]]) -> Lever<'_> {
        Lever {
            pivots,
            fallback: 10.0,
            rotation: 1.0,
            error: SKIN_ERROR,
        }
    }

    #[test]
    fn skin_gap_is_the_posed_midpoint_error() {
        let a = label(&[(0, 1.0)], &[]);
        let b = label(&[(0, 0.75), (3, 0.25)], &[]);
        let lv = lever(&[]);
        // ¼ θ Σ|Δw| |p − q| = ¼ · 1 · 0.5 · 2 = 0.25, over SKIN_ERROR · d.
        assert!((a.skin_gap(&b, 2.0, &lv, 1.0) - 0.25 / SKIN_ERROR).abs() < 1e-6);
        assert_eq!(a.skin_gap(&a, 2.0, &lv, 1.0), 0.0);
    }

    #[test]
    fn deviation_is_zero_on_a_linear_profile_and_measures_a_kink() {
        // Weights of joint 1 rising linearly from a to b: the midpoint's are the blend.
        let a = label(&[(0, 1.0)], &[[0.0; 3]]);
        let b = label(&[(0, 0.5), (1, 0.5)], &[[0.0, 1.0, 0.0]]);
        let mid = label(&[(0, 0.75), (1, 0.25)], &[[0.0, 0.5, 0.0]]);
        let pivots = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let (lv, p) = (lever(&pivots), Vec3::new(0.0, 1.0, 0.0));
        assert!(mid.deviation(&a, &b, 0.5, p, &lv, 1.0) < 1e-6);
        // A kink: the midpoint still has joint 0 only. ½ θ (0.25 · 1 + 0.25 · 1) = 0.25.
        let kink = label(&[(0, 1.0)], &[[0.0, 0.5, 0.0]]);
        let e = kink.deviation(&a, &b, 0.5, p, &lv, 1.0);
        assert!((e - 0.25 / SKIN_ERROR).abs() < 1e-5, "{e}");
        // A morph bump: 0.5 off the blend is MORPH_DEVIATION · d for d = 1.
        let bump = label(&[(0, 0.75), (1, 0.25)], &[[0.0, 1.0, 0.0]]);
        let e = bump.deviation(&a, &b, 0.5, p, &lv, 1.0);
        assert!((e - 0.5 / MORPH_DEVIATION).abs() < 1e-5, "{e}");
    }

    #[test]
    fn labels_interpolate_on_the_closest_triangle() {
        let mesh = crate::mesh::TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let bvh = TriangleBvh::new(mesh.positions(), mesh.triangles());
        let model = LabelInput {
            positions: mesh.positions(),
            tris: mesh.triangles(),
            bvh: &bvh,
        };
        let field = DeformationField {
            influences: 1,
            joints: vec![0, 1, 1],
            weights: vec![1.0, 1.0, 1.0],
            morph_deltas: vec![vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0; 3]]],
            ..DeformationField::default()
        };
        field.validate(3).unwrap();
        let l = label_at(&model, &field, [0.5, 0.0, 0.3]).unwrap();
        assert_eq!(l.skin.len(), 2);
        assert!((l.skin[0].1 - 0.5).abs() < 1e-6 && (l.skin[1].1 - 0.5).abs() < 1e-6);
        assert!((l.morph[0][0] - 1.0).abs() < 1e-6);
        assert!(DeformationField {
            influences: 2,
            ..field.clone()
        }
        .validate(3)
        .is_err());
    }
}
