//! A generated skinned test character and a linear-blend-skinning evaluator written here,
//! independent of the library: 14 joints in a hierarchy (pelvis, spine, chest, head, two arms
//! of three bones, two legs of two bones), closed tubes per body part (one triangle soup),
//! arms in an A-pose resting on the torso at the armpits, thighs touching at the hips, four
//! influences per vertex, one morph target (a belly bulge) and a set of animation poses.
//!
//! Skinning is linear blend skinning (Magnenat-Thalmann et al. 1988; Kavan et al. 2008, eq. 1):
//! `v' = Σ_j w_j · G_j · v` with `G_j` the joint's world transform relative to the bind pose.
#![allow(dead_code, clippy::needless_range_loop, clippy::type_complexity)]

use pleat::mesh::TriMesh;

/// A joint: its parent (`None` for the root) and its head (pivot) in bind pose.
pub struct Joint {
    pub parent: Option<usize>,
    pub head: [f64; 3],
}

/// The character: mesh, skin (`influences` per vertex), morph deltas per vertex, joints.
pub struct Character {
    pub mesh: TriMesh,
    pub joints: Vec<Joint>,
    pub influences: usize,
    pub skin_joints: Vec<u32>,
    pub skin_weights: Vec<f32>,
    pub morph: Vec<[f64; 3]>,
}

/// Local rotations per joint (axis-angle: unit axis, radians); unlisted joints stay still.
pub struct Pose {
    pub name: &'static str,
    pub rotations: Vec<(usize, [f64; 3], f64)>,
}

type M3 = [[f64; 3]; 3];

fn rot(axis: [f64; 3], angle: f64) -> M3 {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = axis.map(|a| a / n);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

fn mul(a: &M3, b: &M3) -> M3 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

fn apply(a: &M3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|x| x * s)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Distance from `p` to the segment `a`–`b`.
fn seg_dist(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let t = (dot(sub(p, a), ab) / dot(ab, ab)).clamp(0.0, 1.0);
    norm(sub(p, add(a, scale(ab, t))))
}

/// Closed tube from `a` to `b` of radius `r` (flat caps), `seg` around, rings every `step`.
fn tube(
    a: [f64; 3],
    b: [f64; 3],
    r: f64,
    seg: usize,
    step: f64,
    pos: &mut Vec<[f64; 3]>,
    tri: &mut Vec<[u32; 3]>,
) {
    let axis = sub(b, a);
    let len = norm(axis);
    let w = scale(axis, 1.0 / len);
    let helper = if w[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let u = {
        let c = cross(w, helper);
        scale(c, 1.0 / norm(c))
    };
    let v = cross(w, u);
    let rings = ((len / step).ceil() as usize).max(1);
    let base = pos.len() as u32;
    for i in 0..=rings {
        let c = add(a, scale(axis, i as f64 / rings as f64));
        for k in 0..seg {
            let t = std::f64::consts::TAU * k as f64 / seg as f64;
            pos.push(add(c, add(scale(u, r * t.cos()), scale(v, r * t.sin()))));
        }
    }
    let id = |i: usize, k: usize| base + (i * seg + k % seg) as u32;
    for i in 0..rings {
        for k in 0..seg {
            tri.push([id(i, k), id(i + 1, k), id(i + 1, k + 1)]);
            tri.push([id(i, k), id(i + 1, k + 1), id(i, k + 1)]);
        }
    }
    let ca = pos.len() as u32;
    pos.push(a);
    let cb = pos.len() as u32;
    pos.push(b);
    for k in 0..seg {
        tri.push([ca, id(0, k + 1), id(0, k)]);
        tri.push([cb, id(rings, k), id(rings, k + 1)]);
    }
}

/// The character (about 1.8 units tall; bounding-box diagonal about 1.9).
pub fn character() -> Character {
    let a_pose = 12f64.to_radians();
    let (sa, ca) = a_pose.sin_cos();
    let arm = |side: f64, from: f64, to: f64| {
        // The arm axis leaves the shoulder (x = 0.205 at y = 1.44) at `a_pose` from vertical.
        let p = |s: f64| [side * (0.205 + s * sa), 1.44 - s * ca, 0.0];
        (p(from), p(to))
    };
    // joints: 0 pelvis, 1 spine, 2 chest, 3 head, 4-6 left arm, 7-9 right arm, 10-11 left leg,
    // 12-13 right leg
    let (ls, le) = arm(1.0, 0.0, 0.28);
    let (_, lw) = arm(1.0, 0.28, 0.52);
    let (_, lh) = arm(1.0, 0.52, 0.64);
    let (rs, re) = arm(-1.0, 0.0, 0.28);
    let (_, rw) = arm(-1.0, 0.28, 0.52);
    let (_, rh) = arm(-1.0, 0.52, 0.64);
    let heads: [(Option<usize>, [f64; 3]); 14] = [
        (None, [0.0, 0.90, 0.0]),
        (Some(0), [0.0, 1.10, 0.0]),
        (Some(1), [0.0, 1.30, 0.0]),
        (Some(2), [0.0, 1.52, 0.0]),
        (Some(2), ls),
        (Some(4), le),
        (Some(5), lw),
        (Some(2), rs),
        (Some(7), re),
        (Some(8), rw),
        (Some(0), [0.076, 0.92, 0.0]),
        (Some(10), [0.10, 0.50, 0.0]),
        (Some(0), [-0.076, 0.92, 0.0]),
        (Some(12), [-0.10, 0.50, 0.0]),
    ];
    let joints: Vec<Joint> = heads
        .iter()
        .map(|&(parent, head)| Joint { parent, head })
        .collect();
    // bones (joint, segment) for the skin distances
    let bones: Vec<(usize, [f64; 3], [f64; 3])> = vec![
        (0, [0.0, 0.84, 0.0], [0.0, 1.10, 0.0]),
        (1, [0.0, 1.10, 0.0], [0.0, 1.30, 0.0]),
        (2, [0.0, 1.30, 0.0], [0.0, 1.50, 0.0]),
        (3, [0.0, 1.52, 0.0], [0.0, 1.80, 0.0]),
        (4, ls, le),
        (5, le, lw),
        (6, lw, lh),
        (7, rs, re),
        (8, re, rw),
        (9, rw, rh),
        (10, [0.076, 0.92, 0.0], [0.10, 0.50, 0.0]),
        (11, [0.10, 0.50, 0.0], [0.11, 0.06, 0.0]),
        (12, [-0.076, 0.92, 0.0], [-0.10, 0.50, 0.0]),
        (13, [-0.10, 0.50, 0.0], [-0.11, 0.06, 0.0]),
    ];
    // parts: (segment, radius, bones whose neighbourhood skins it). Each limb is one tube
    // capped at its two ends only, so no input vertex is buried deep inside another part
    // (a LOD rightly leaves buried geometry out, which would swamp the measured distances).
    let (_, arm_end) = arm(1.0, 0.0, 0.64);
    let (_, rarm_end) = arm(-1.0, 0.0, 0.64);
    let parts: Vec<([f64; 3], [f64; 3], f64, Vec<usize>)> = vec![
        ([0.0, 0.84, 0.0], [0.0, 1.48, 0.0], 0.15, vec![0, 1, 2]),
        ([0.0, 1.52, 0.0], [0.0, 1.80, 0.0], 0.09, vec![3]),
        (ls, arm_end, 0.048, vec![4, 5, 6]),
        (rs, rarm_end, 0.048, vec![7, 8, 9]),
        ([0.076, 0.86, 0.0], [0.11, 0.06, 0.0], 0.07, vec![10, 11]),
        ([-0.076, 0.86, 0.0], [-0.11, 0.06, 0.0], 0.07, vec![12, 13]),
    ];
    let influences = 4;
    let mut pos = Vec::new();
    let mut tri = Vec::new();
    let mut skin_joints = Vec::new();
    let mut skin_weights = Vec::new();
    for (a, b, r, own) in &parts {
        let first = pos.len();
        tube(*a, *b, *r, 20, 0.03, &mut pos, &mut tri);
        // candidates: the part's bones, their parents and children
        let mut cand: Vec<usize> = Vec::new();
        for &j in own {
            cand.push(j);
            if let Some(p) = joints[j].parent {
                cand.push(p);
            }
            for (c, jc) in joints.iter().enumerate() {
                if jc.parent == Some(j) {
                    cand.push(c);
                }
            }
        }
        cand.sort_unstable();
        cand.dedup();
        for p in &pos[first..] {
            let mut w: Vec<(f64, usize)> = cand
                .iter()
                .map(|&j| {
                    let (_, s0, s1) = bones[j];
                    let dist = seg_dist(*p, s0, s1);
                    let own_bonus = if own.contains(&j) { 1.0 } else { 0.35 };
                    (own_bonus * (-(dist / 0.07).powi(2)).exp() + 1e-6, j)
                })
                .collect();
            w.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
            w.truncate(influences);
            while w.len() < influences {
                w.push((0.0, 0));
            }
            let s: f64 = w.iter().map(|e| e.0).sum();
            for (wt, j) in w {
                skin_joints.push(j as u32);
                skin_weights.push((wt / s) as f32);
            }
        }
    }
    // morph: a belly bulge on the torso's front
    let morph = pos
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let torso = skin_joints[i * influences] <= 2 && p[2] > 0.0;
            let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
            if !torso || r < 0.14 {
                return [0.0; 3];
            }
            let bump = (-((p[1] - 1.12) / 0.12).powi(2)).exp() * (p[2] / r).max(0.0);
            [0.0, 0.0, 0.06 * bump]
        })
        .collect();
    Character {
        mesh: TriMesh::new(pos, tri).expect("character mesh"),
        joints,
        influences,
        skin_joints,
        skin_weights,
        morph,
    }
}

/// Animation poses (the bind pose first).
pub fn poses() -> Vec<Pose> {
    let x = [1.0, 0.0, 0.0];
    let y = [0.0, 1.0, 0.0];
    let z = [0.0, 0.0, 1.0];
    let deg = |d: f64| d.to_radians();
    vec![
        Pose {
            name: "bind",
            rotations: vec![],
        },
        Pose {
            name: "left arm out 15°",
            rotations: vec![(4, z, deg(15.0))],
        },
        Pose {
            name: "arms out 10°",
            rotations: vec![(4, z, deg(10.0)), (7, z, deg(-10.0))],
        },
        Pose {
            name: "left elbow 60°",
            rotations: vec![(5, x, deg(-60.0))],
        },
        Pose {
            name: "right arm forward 30°",
            rotations: vec![(7, x, deg(-30.0)), (8, x, deg(-30.0))],
        },
        Pose {
            name: "left step",
            rotations: vec![(10, x, deg(-15.0)), (11, x, deg(25.0))],
        },
        Pose {
            name: "knees 30°",
            rotations: vec![
                (10, x, deg(-20.0)),
                (11, x, deg(30.0)),
                (12, x, deg(-20.0)),
                (13, x, deg(30.0)),
            ],
        },
        Pose {
            name: "twist",
            rotations: vec![(1, y, deg(10.0)), (2, y, deg(10.0)), (3, y, deg(30.0))],
        },
        Pose {
            name: "bend",
            rotations: vec![(1, x, deg(10.0)), (2, x, deg(10.0)), (3, x, deg(15.0))],
        },
        Pose {
            name: "wave",
            rotations: vec![(7, z, deg(-15.0)), (8, x, deg(-50.0)), (9, z, deg(-20.0))],
        },
    ]
}

/// World transforms (rotation, translation) of every joint for `pose`, relative to the bind
/// pose: `G_j(v) = R_j v + t_j`, with `G_j = G_parent ∘ T(h_j) R_local T(−h_j)`.
pub fn joint_transforms(joints: &[Joint], pose: &Pose) -> Vec<(M3, [f64; 3])> {
    let id: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut g: Vec<(M3, [f64; 3])> = Vec::with_capacity(joints.len());
    for (j, joint) in joints.iter().enumerate() {
        let local = pose
            .rotations
            .iter()
            .filter(|r| r.0 == j)
            .fold(id, |m, r| mul(&rot(r.1, r.2), &m));
        let h = joint.head;
        // local affine: v ↦ R (v − h) + h
        let lt = sub(h, apply(&local, h));
        let (pr, pt) = match joint.parent {
            Some(p) => g[p],
            None => (id, [0.0; 3]),
        };
        // parent ∘ local: v ↦ pr (R v + lt) + pt
        g.push((mul(&pr, &local), add(apply(&pr, lt), pt)));
    }
    g
}

/// Linear blend skinning of `positions` with `influences` (joints, weights) per vertex.
pub fn skin(
    positions: &[[f64; 3]],
    joints: &[u32],
    weights: &[f32],
    influences: usize,
    transforms: &[(M3, [f64; 3])],
) -> Vec<[f64; 3]> {
    positions
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let mut out = [0.0; 3];
            for s in 0..influences {
                let w = weights[i * influences + s] as f64;
                if w == 0.0 {
                    continue;
                }
                let (r, t) = &transforms[joints[i * influences + s] as usize];
                out = add(out, scale(add(apply(r, p), *t), w));
            }
            out
        })
        .collect()
}
