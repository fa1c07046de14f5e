//! Wrinkle evaluation (§3.5): upsample a [`Cwf`] `levels` times with the Loop rules of
//! [`subdivide`](super::subdivide) and displace the refined base mesh along its normals.
//!
//! The displacement follows the dissertation's text (§3.5, third bullet): level-k vertex `i`
//! moves by `|z_i| cos(arg z_i) n̂_i = Re(z_i) n̂_i`, where `z` is the upsampled complex field
//! (initialised as `z_j = a_j z̃_j` on the base, so it carries the amplitude) and `n̂_i` is the
//! area-weighted unit normal of the *undisplaced* level-k mesh. This, rather than
//! `a_i cos(arg z_i)` with a separately subdivided `a`, is what makes the surface continuous
//! through singularities: `|z| → 0` there while `arg z` is undefined. The S0-subdivided
//! amplitude is still available as an output for shading.
//!
//! Work is parallel with rayon per vertex / edge / face; every output value is computed by
//! one task from inputs only, so the bytes do not depend on the number of threads.
//!
//! **Zero amplitude.** Every z rule is a sum of votes `b_c z_c e^{iφ}`, so a vote whose face
//! has `z = 0` at all three corners is exactly zero; such votes are skipped (no
//! transcendental, no cotangent-vector evaluation). The mesh itself is always refined
//! everywhere, so the output has no cracks or T-junctions whatever the amplitude, and
//! zero-amplitude regions come out exactly undisplaced. Refining only the faces near non-zero
//! amplitude (red–green closure) would additionally save the topology, position and normal
//! work there; `benches/wrinkle_eval.rs` measures both effects.

use rayon::prelude::*;

use super::complex::Complex;
use super::cwf::Cwf;
use super::report::{EvalReport, EvalStage, LevelPart, LevelReport};
use super::subdivide::{
    apply_s0, apply_s1, apply_z, check_output_size, face_gradients, vertex_rules, BoundaryRule,
    SubdivisionOptions, VertexRule, ZContext,
};
use super::topology::Topology;
use crate::geom::{normalized, tri_normal, Vec3};
use crate::mesh::TriMesh;
use crate::report::{Progress, ProgressFn, StageTimes};
use crate::Result;

/// Options of [`Cwf::evaluate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvalOptions {
    /// Loop boundary rule and corner threshold; default: fixed boundary (App. B.2).
    pub subdivision: SubdivisionOptions,
    /// Multiplies the displacement `Re(z) n̂`; default 1.
    pub displacement_scale: f64,
    /// Fill [`Evaluated::amplitude`]; default false.
    pub want_amplitude: bool,
    /// Fill [`Evaluated::phase`]; default false.
    pub want_phase: bool,
    /// Fill [`Evaluated::normals`]; default false.
    pub want_normals: bool,
    /// Fill [`Evaluated::z`] and [`Evaluated::smooth_positions`]; default false.
    pub want_z: bool,
    /// Fill [`Evaluated::omega`] (costs one more one-form subdivision); default false.
    pub want_omega: bool,
    /// Refuse ([`crate::Error::LimitExceeded`]) when the output would have more triangles;
    /// default 64 Mi.
    pub max_output_faces: usize,
    /// Add the in-plane second-order term of eq. 2.19 (TFW, S:2327):
    /// `Δx += s² (Re z · Im z / 4) ∇φ` (= `a²/8 sin 2φ ∇φ`), `∇φ` per vertex the mean of the
    /// corner phase gradients of the finest level's one-form, `s` the displacement scale.
    /// Default false (outputs unchanged).
    pub in_plane_v2: bool,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            subdivision: SubdivisionOptions::default(),
            displacement_scale: 1.0,
            want_amplitude: false,
            want_phase: false,
            want_normals: false,
            want_z: false,
            want_omega: false,
            max_output_faces: 1 << 26,
            in_plane_v2: false,
        }
    }
}

/// The wrinkled level-k mesh and optional per-vertex fields (all in the mesh's vertex order:
/// base vertices first, then one new vertex per edge of each level, see
/// [`LoopHierarchy`](super::LoopHierarchy)).
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluated {
    /// The displaced mesh `x_i + s Re(z_i) n̂_i`.
    pub mesh: TriMesh,
    /// The S0-subdivided amplitude `a` (eq. 3.23 rules applied to `a`; subdivided only when
    /// requested — the displacement needs only `z`, which carries the amplitude).
    pub amplitude: Option<Vec<f64>>,
    /// `arg z_i` in `(−π, π]` (0 where `z_i = 0`).
    pub phase: Option<Vec<f64>>,
    /// Unit area-weighted normals of the undisplaced level-k mesh (zero where undefined).
    pub normals: Option<Vec<[f64; 3]>>,
    /// The upsampled complex field `z`.
    pub z: Option<Vec<Complex>>,
    /// The undisplaced (Loop) positions of the level-k mesh.
    pub smooth_positions: Option<Vec<[f64; 3]>>,
    /// The one-form `ω` on level k, on the [`EdgeList`](crate::mesh::EdgeList) of `mesh`.
    pub omega: Option<Vec<f64>>,
}

/// The state carried from one level to the next.
struct Level<'a> {
    topo: std::borrow::Cow<'a, Topology>,
    rules: Vec<VertexRule>,
    x: Vec<[f64; 3]>,
    omega: Vec<f64>,
    z: Vec<Complex>,
    amplitude: Vec<f64>,
}

impl Cwf {
    /// Evaluates the wrinkled surface after `levels` Loop refinements (§3.5). The
    /// [`EvalReport`] records the wall time of each part of each level ([`EvalStage`]) and of
    /// the displacement, and per level its seconds, vertices and faces. Errors with
    /// [`crate::Error::LimitExceeded`] above [`EvalOptions::max_output_faces`] and
    /// [`crate::Error::InvalidArgument`] for a non-finite displacement scale.
    pub fn evaluate(&self, levels: usize, opts: &EvalOptions) -> Result<(Evaluated, EvalReport)> {
        self.evaluate_with_progress(levels, opts, &mut |_| true)
    }

    /// [`Cwf::evaluate`] with a progress callback, called on the calling thread between the
    /// parts of each level (positions, amplitude, cotangent vectors, `z`, topology), after each
    /// level and before the displacement with the stage name and the fraction done (by output
    /// size: level `k` of `n` costs about `4^k`). Returning `false` stops the evaluation
    /// promptly with [`crate::Error::Cancelled`].
    pub fn evaluate_with_progress(
        &self,
        levels: usize,
        opts: &EvalOptions,
        progress: &mut ProgressFn<'_>,
    ) -> Result<(Evaluated, EvalReport)> {
        if !opts.displacement_scale.is_finite() {
            return crate::invalid_arg!(
                "displacement_scale is {} (must be finite)",
                opts.displacement_scale
            );
        }
        check_output_size(self.topo.n_faces(), levels, opts.max_output_faces)?;
        let mut stats = EvalReport::default();
        let mut level = stats.stages.time(EvalStage::Setup, || {
            self.base_level(&opts.subdivision, opts.want_amplitude)
        });
        let mut faces = self.topo.faces.clone();
        for l in 0..levels {
            let last = l + 1 == levels;
            let keep_topology = !last || opts.want_omega || opts.in_plane_v2;
            let t0 = std::time::Instant::now();
            let stage = format!("level {}", l + 1);
            let (f0, f1) = (work_done(l, levels), work_done(l + 1, levels));
            let mut part = 0.0;
            // a progress call (and cancellation point) between the parts of a level,
            // at increasing fractions below the level's own report
            let mut keep_going = || {
                part += 1.0;
                progress(Progress {
                    stage: &stage,
                    fraction: f0 + (f1 - f0) * part / (LEVEL_PARTS + 1.0),
                })
            };
            let (next, next_faces) = refine_level(
                &level,
                keep_topology,
                opts.subdivision.boundary,
                &mut stats.stages,
                l + 1,
                &mut keep_going,
            )
            .ok_or(crate::Error::Cancelled)?;
            stats.levels.push(LevelReport {
                seconds: t0.elapsed().as_secs_f64(),
                vertices: next.x.len() as u64,
                faces: next_faces.len() as u64,
            });
            level = next;
            faces = next_faces;
            if !progress(Progress {
                stage: &stage,
                fraction: work_done(l + 1, levels),
            }) {
                return Err(crate::Error::Cancelled);
            }
        }
        let out = stats
            .stages
            .time(EvalStage::Displace, || finish(level, faces, opts))?;
        if !progress(Progress {
            stage: "displace",
            fraction: 1.0,
        }) {
            return Err(crate::Error::Cancelled);
        }
        Ok((out, stats))
    }

    fn base_level(&self, sub_opts: &SubdivisionOptions, want_amplitude: bool) -> Level<'_> {
        let topo = if sub_opts.boundary == BoundaryRule::Smooth {
            let mut t = self.topo.clone();
            t.mark_corners(self.base().positions(), sub_opts.corner_angle);
            std::borrow::Cow::Owned(t)
        } else {
            std::borrow::Cow::Borrowed(&self.topo)
        };
        let rules = vertex_rules(&topo, sub_opts.boundary);
        let z = self
            .zeta()
            .iter()
            .zip(self.amplitude())
            .map(|(z, &a)| z.scale(a))
            .collect();
        Level {
            topo,
            rules,
            x: self.base().positions().to_vec(),
            omega: self.omega().to_vec(),
            z,
            amplitude: if want_amplitude {
                self.amplitude().to_vec()
            } else {
                Vec::new()
            },
        }
    }
}

/// Fraction of the work done after `k` of `n` levels (level `j` costs about `4^j`; the
/// displacement is counted as one more finest level).
fn work_done(k: usize, n: usize) -> f64 {
    let cost = |j: usize| 4f64.powi(j as i32);
    let total: f64 = (1..=n).map(cost).sum::<f64>() + cost(n);
    (1..=k).map(cost).sum::<f64>() / total
}

/// Progress calls inside a level of [`Cwf::evaluate_with_progress`]: after the positions, the
/// amplitude, the cotangent vectors, `z` and (except on the last level) the topology.
const LEVEL_PARTS: f64 = 5.0;

/// One Loop step of every field, timing its parts as [`EvalStage::Level`] in `stats`. Without
/// `keep_topology` only the fine triangles are built (the last level needs no adjacency and no
/// one-form). `keep_going` is called between the parts (the cancellation points inside a
/// level); `None` as soon as it returns `false`.
fn refine_level<'a>(
    c: &Level<'_>,
    keep_topology: bool,
    boundary: BoundaryRule,
    stats: &mut StageTimes<EvalStage>,
    k: usize,
    keep_going: &mut dyn FnMut() -> bool,
) -> Option<(Level<'a>, Vec<[u32; 3]>)> {
    let topo = c.topo.as_ref();
    let name = |part: LevelPart| EvalStage::Level(k, part);
    let x = stats.time(name(LevelPart::Positions), || {
        apply_s0(topo, &c.rules, &c.x)
    });
    keep_going().then_some(())?;
    let amplitude = stats.time(name(LevelPart::Amplitude), || {
        if c.amplitude.is_empty() {
            Vec::new()
        } else {
            apply_s0(topo, &c.rules, &c.amplitude)
        }
    });
    keep_going().then_some(())?;
    let faces = stats.time(name(LevelPart::CotangentVectors), || {
        face_gradients(topo, &c.x, &c.omega)
    });
    keep_going().then_some(())?;
    let ctx = ZContext {
        topo,
        rules: &c.rules,
        x: &c.x,
        omega: &c.omega,
        z: &c.z,
        faces,
    };
    let z = stats.time(name(LevelPart::Z), || apply_z(&ctx, &x));
    keep_going().then_some(())?;
    if !keep_topology {
        let faces = stats.time(name(LevelPart::Triangles), || topo.refine_faces());
        let next = Level {
            topo: std::borrow::Cow::Owned(empty_topology()),
            rules: Vec::new(),
            x,
            omega: Vec::new(),
            z,
            amplitude,
        };
        return Some((next, faces));
    }
    let fine = stats.time(name(LevelPart::Topology), || topo.refine());
    keep_going().then_some(())?;
    let omega = stats.time(name(LevelPart::OneForm), || {
        apply_s1(topo, &fine, &c.rules, &c.omega)
    });
    let rules = vertex_rules(&fine, boundary);
    let faces = fine.faces.clone();
    let next = Level {
        topo: std::borrow::Cow::Owned(fine),
        rules,
        x,
        omega,
        z,
        amplitude,
    };
    Some((next, faces))
}

fn empty_topology() -> Topology {
    Topology::empty()
}

/// Normals, displacement and the optional outputs; `Numerical` when a displaced position is not
/// finite (finite but huge amplitudes, scales or coordinates overflow `f64` in the upsampling
/// or the displacement: found by fuzzing `wrinkle_eval`).
fn finish(level: Level<'_>, faces: Vec<[u32; 3]>, opts: &EvalOptions) -> crate::Result<Evaluated> {
    let normals = vertex_normals(&level.x, &faces);
    let s = opts.displacement_scale;
    let displaced: Vec<[f64; 3]> = level
        .x
        .par_iter()
        .zip(&level.z)
        .zip(&normals)
        .map(|((&p, z), &n)| (Vec3::from(p) + Vec3::from(n) * (s * z.re)).to_array())
        .collect();
    let displaced = if opts.in_plane_v2 && level.omega.len() == level.topo.n_edges() {
        add_in_plane_v2(&level, &faces, displaced, s)
    } else {
        displaced
    };
    let phase = opts
        .want_phase
        .then(|| level.z.par_iter().map(|z| z.arg()).collect());
    let has_omega = opts.want_omega && level.omega.len() == level.topo.n_edges();
    if let Some(v) = displaced
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(crate::Error::Numerical(format!(
            "the evaluated surface is not finite at vertex {v}: the amplitudes, the displacement \
             scale or the coordinates are too large for f64 once upsampled and displaced; scale \
             them down"
        )));
    }
    Ok(Evaluated {
        mesh: TriMesh::new(displaced, faces).expect("refined meshes are valid"),
        amplitude: opts.want_amplitude.then_some(level.amplitude),
        phase,
        normals: opts.want_normals.then_some(normals),
        smooth_positions: opts.want_z.then(|| level.x.clone()),
        z: opts.want_z.then_some(level.z),
        omega: has_omega.then_some(level.omega),
    })
}

/// Adds the in-plane term of [`EvalOptions::in_plane_v2`] to `displaced`.
fn add_in_plane_v2(
    level: &Level<'_>,
    faces: &[[u32; 3]],
    mut displaced: Vec<[f64; 3]>,
    s: f64,
) -> Vec<[f64; 3]> {
    let fields = face_gradients(&level.topo, &level.x, &level.omega);
    let mut sum = vec![Vec3::ZERO; level.x.len()];
    let mut count = vec![0u32; level.x.len()];
    for (t, f) in faces.iter().zip(&fields) {
        for (&v, g) in t.iter().zip(f.corner_gradients()) {
            sum[v as usize] += g;
            count[v as usize] += 1;
        }
    }
    for (((d, g), &c), z) in displaced.iter_mut().zip(&sum).zip(&count).zip(&level.z) {
        if c > 0 {
            let shift = *g * (s * s * z.re * z.im / (4.0 * f64::from(c)));
            *d = (Vec3::from(*d) + shift).to_array();
        }
    }
    displaced
}

/// Unit area-weighted vertex normals (sum of `(x1 − x0) × (x2 − x0)` over incident triangles);
/// zero for vertices whose triangles cancel or have no area.
pub(crate) fn vertex_normals(x: &[[f64; 3]], faces: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let p = |v: u32| Vec3::from(x[v as usize]);
    let face_n: Vec<Vec3> = faces
        .par_iter()
        .map(|t| tri_normal(p(t[0]), p(t[1]), p(t[2])))
        .collect();
    let mut acc = vec![Vec3::ZERO; x.len()];
    for (t, n) in faces.iter().zip(&face_n) {
        for &v in t {
            acc[v as usize] += *n;
        }
    }
    acc.par_iter()
        .map(|&n| normalized(n).unwrap_or(Vec3::ZERO).to_array())
        .collect()
}
