//! Region edits of a complex wrinkle field (dissertation §3.6.2, eqs. 3.26–3.28; spec
//! `specs/cwf-design.md`, "Edit"): per region rotate the wrinkles by θ, scale their frequency by
//! σ and their amplitude by μ; solve the interface band between the regions and the fixed part
//! so the new keyframe blends into the untouched field; copy the fixed part bit for bit.
//!
//! 1. Labels ([`region`](super::region)): edit faces = the regions, interface = faces within
//!    `interface_rings` of a region, fixed = the rest; vertices and edges take the class of
//!    their faces with precedence edit > fixed > interface.
//! 2. `ω¹` on edit edges: per edge the mean over its faces and its two endpoints of
//!    `(R_θ u_{f,v})·(x_b − x_a)` (`u_{f,v}` the corner vector of B.51–B.52, `R_θ` the rotation
//!    about the unit face normal), times σ. Pure scaling is `σ ω⁰`; an identity op copies `ω⁰`.
//! 3. `a¹ = μ a⁰` on edit vertices.
//! 4. Eq. 3.26 on the interface-only edges: `min Σ_F (dω_F)² + Σ_m (Σ_n c_mn ω_{m→n})² +
//!    ε_ω ‖ω − ω⁰‖²` (unclamped cotan `c_mn`), normal equations by sparse Cholesky.
//! 5. Eq. 3.27 on the interface-only vertices: `min ½ aᵀLa + γ Σ_F ((Σ_{j∈F} a_j²)/3)(dω_F)² +
//!    (ε_a/2)‖a − a⁰‖²`, clamped at 0.
//! 6. Eq. 3.28 (augmented pencil): `x = Pũ + s u⁰` minimizing the compatibility energy
//!    `Σ_e A_kl |x_k e^{iω_kl} − x_l|²` over `‖x‖_M = 1`; smallest eigenpair of
//!    `A' = [[PᴴAP, PᴴAu⁰], [u⁰ᴴAP, u⁰ᴴAu⁰]]`, `B' = diag(PᴴMP, u⁰ᴴMu⁰)` by inverse iteration
//!    (s complex, see the spec), `z̃¹ = normalize(Pũ/s)` on the free vertices. Without any
//!    fixed vertex (a global edit) the phase is plain Knöppel on `ω¹`.
//! 7. The fixed entries of `ω`, `a`, `z̃` are copies of the input's.
//! 8. Adaptive width ([`EditOptions::compat_target`], default 0.3 rad, 0 = off): while the RMS
//!    compatibility residual over edit + interface edges, or over the interface-only edges, is
//!    above the target, every band is
//!    widened by a ring and steps 1–7 redone (the residual is forced by the curl of the 3.26
//!    blend across the band; a wider band spreads it).

use std::time::Instant;

use super::areas::barycentric_areas;
use super::complex::Complex;
use super::cwf::{wrap_to_pi, Cwf};
use super::interpolate::checkpoint;
use super::knoppel::{
    components, cotan_weights_raw, iterate_with_tick, knoppel_phase_with_tick, KnoppelOptions,
    PhaseWeights,
};
use super::omega_path::{corner_vector, face_unit_normal};
use super::region::{classify, Adjacency, FaceClass, Labels};
use super::spd::{matvec_full, push_hermitian, push_outer_lower, solve_spd, solve_spd_with_tick};
use super::topology::{Topology, NONE};
use crate::geom::Vec3;
use crate::report::ProgressFn;
use crate::solve::{
    assemble, run_stoppable, CholeskyAnalysis, Entry, InverseIterationParams, Parallelism,
    ShiftSchedule, ShiftedProblem,
};
use crate::{Error, Result};

/// Default [`EditOptions::compat_target`]: the RMS compatibility residual (radians) over edit and
/// interface edges required of a smooth interface.
pub const DEFAULT_COMPAT_TARGET: f64 = 0.3;

/// One edited region: its faces and the operation applied to the wrinkles in it.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionEdit {
    /// The region's faces (e.g. from [`grow_faces`](super::grow_faces)); non-empty.
    pub faces: Vec<u32>,
    /// Width of the interface band around the region, in rings (≥ 1 unless the region covers
    /// the mesh); default 3. The narrowest width: [`EditOptions::compat_target`] (on by
    /// default) widens it while the interface is not smooth.
    pub interface_rings: usize,
    /// Rotation of the wrinkle direction about each face normal, counter-clockwise, radians.
    pub rotate: f64,
    /// Frequency scale σ > 0 (σ = 3: three times finer wrinkles).
    pub frequency_scale: f64,
    /// Amplitude scale μ ≥ 0.
    pub amplitude_scale: f64,
}

impl RegionEdit {
    /// The identity operation on `faces` with the default 3 interface rings.
    pub fn new(faces: Vec<u32>) -> RegionEdit {
        RegionEdit {
            faces,
            interface_rings: 3,
            rotate: 0.0,
            frequency_scale: 1.0,
            amplitude_scale: 1.0,
        }
    }

    /// The coupled scaling μ = 1/σ (keeps `a·|ω|`, Figs. 3.6, B.3, B.7).
    pub fn coupled(mut self) -> RegionEdit {
        self.amplitude_scale = 1.0 / self.frequency_scale;
        self
    }

    fn is_identity(&self) -> bool {
        self.rotate == 0.0 && self.frequency_scale == 1.0
    }
}

/// Which compatibility energy the phase solve (eq. 3.28) minimizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u32)]
pub enum PhaseCoupling {
    /// `Σ A_kl |x_k e^{iω} − x_l|²` with `u⁰ = z̃⁰` (the dissertation's text; default).
    #[default]
    Unit = 0,
    /// `Σ A_kl |a¹_l x_k e^{iω} − a¹_k x_l|²` with `u⁰ = a⁰ z̃⁰` (the reference code).
    AmplitudeWeighted = 1,
}

/// Parameters of [`edit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EditOptions {
    /// How interface rings grow; default [`Adjacency::Vertex`].
    pub adjacency: Adjacency,
    /// ε_ω of eq. 3.26; default 1e-3.
    pub eps_omega: f64,
    /// ε_a of eq. 3.27; default 1e-3.
    pub eps_amplitude: f64,
    /// γ of eq. 3.27; default 1 (reference ¼).
    pub gamma: f64,
    /// Phase energy; default [`PhaseCoupling::Unit`].
    pub phase: PhaseCoupling,
    /// Weight of the edit edges' compatibility terms in the phase solve (eq. 3.28) relative to
    /// the interface edges' (≥ 1). The text asks for `z̃` consistent with `ω¹` on the edit
    /// edges; a weight above 1 keeps the interface's mismatch (the curl of the blended `ω`) in
    /// the interface, where singularities can absorb it, instead of spreading it into the
    /// edited region at the cost of a larger interface residual (measured in
    /// docs/benchmarks/wrinkle.md). Default 1 (the literal eq. 3.28, as the reference).
    pub edit_weight: f64,
    /// Inverse-iteration steps of the phase solve; default 200.
    pub max_iterations: usize,
    /// Inverse-iteration tolerance; default 1e-12.
    pub tolerance: f64,
    /// Adaptive interface width (radians; 0 = off). Each region's `interface_rings` is the
    /// *narrowest* band: while the RMS compatibility residual over edit + interface edges
    /// ([`EditReport::compat_rms`]) or over the interface-only edges
    /// ([`EditReport::compat_rms_by_class`]`[1]`) exceeds this target, every region's band is
    /// widened by one ring (up to [`max_interface_rings`](Self::max_interface_rings)) and the
    /// edit redone; the edit with the smallest of these two maxima is returned
    /// ([`EditReport::interface_rings`] says which widths). A widening that would leave no fixed
    /// vertex or make the layout invalid stops it. The residual is forced by the curl of the eq.
    /// 3.26 blend, which only a wider band spreads (docs/benchmarks/wrinkle.md, "Interface
    /// smoothness"); the corpus torus needs 7 rings for 0.3. Default [`DEFAULT_COMPAT_TARGET`] =
    /// 0.3 rad, the required interface smoothness, so a default edit has a smooth interface
    /// wherever a band of at most `max_interface_rings` rings can give one (the widening takes
    /// rings from the fixed region, which stays bit-for-bit copied; [`EditReport::interface_rings`]
    /// says how wide). 0 gives the requested widths exactly, as the reference code does.
    pub compat_target: f64,
    /// Widest band the adaptive width may reach; default 8.
    pub max_interface_rings: usize,
}

impl Default for EditOptions {
    fn default() -> Self {
        EditOptions {
            adjacency: Adjacency::Vertex,
            eps_omega: 1e-3,
            eps_amplitude: 1e-3,
            gamma: 1.0,
            phase: PhaseCoupling::Unit,
            edit_weight: 1.0,
            max_iterations: 200,
            tolerance: 1e-12,
            compat_target: DEFAULT_COMPAT_TARGET,
            max_interface_rings: 8,
        }
    }
}

impl EditOptions {
    /// The reference implementation's values: edge adjacency, γ = ¼, amplitude-weighted phase,
    /// the requested interface widths exactly (`compat_target` 0).
    pub fn reference() -> EditOptions {
        EditOptions {
            adjacency: Adjacency::Edge,
            gamma: 0.25,
            phase: PhaseCoupling::AmplitudeWeighted,
            edit_weight: 1.0,
            compat_target: 0.0,
            ..EditOptions::default()
        }
    }
}

/// What [`edit`] did: the labels, each solve's seconds and residual.
#[derive(Debug, Clone, PartialEq)]
pub struct EditReport {
    /// Per face: fixed, edit or interface.
    pub face_class: Vec<FaceClass>,
    /// Faces `[fixed, edit, interface]`.
    pub face_counts: [usize; 3],
    /// Vertices `[fixed, edit, interface-only]`.
    pub vertex_counts: [usize; 3],
    /// Edges `[fixed, edit, interface-only]`.
    pub edge_counts: [usize; 3],
    /// Relative normal-equation residual of eq. 3.26 (0 without interface edges).
    pub omega_residual: f64,
    /// Relative residual of eq. 3.27 (0 without interface vertices).
    pub amplitude_residual: f64,
    /// Smallest eigenvalue of the phase pencil (3.28) or of Knöppel's (global edit).
    pub eigenvalue: f64,
    /// Final inverse-iteration residual of the phase solve.
    pub phase_residual: f64,
    /// Inverse-iteration steps.
    pub phase_iterations: usize,
    /// The pencil's `s` (1 for a global edit).
    pub s: Complex,
    /// True when `|s|²u⁰ᴴMu⁰ < 1e-20` and the phase fell back to `s = 1` (harmonic extension).
    pub phase_fallback: bool,
    /// True when no vertex is fixed (plain Knöppel phase).
    pub global: bool,
    /// Interface amplitudes clamped to 0.
    pub clamped: usize,
    /// RMS over edit and interface edges of `|wrap(ω¹ − Δarg z̃¹)|` (radians).
    pub compat_rms: f64,
    /// The same RMS over the edit edges only and over the interface-only edges only.
    pub compat_rms_by_class: [f64; 2],
    /// The smallest RMS over edit and interface edges that *any* phase without singularities
    /// can reach for this `ω¹`: the minimum-norm residual `δ` with `curl δ = curl ω¹` on every
    /// non-fixed face and `δ = 0` on fixed edges. A phase can only beat it by placing
    /// singularities (each absorbs 2π of curl). It measures how incompatible the requested
    /// field is (a rotated wave on a curved patch, the frequency blend of eq. 3.26), not the
    /// phase solve.
    pub compat_floor: f64,
    /// Wall seconds: `[labels + ω¹, eq. 3.26, eq. 3.27, eq. 3.28]` of the returned edit.
    pub seconds: [f64; 4],
    /// Interface width used per region (wider than requested when
    /// [`EditOptions::compat_target`] widened it).
    pub interface_rings: Vec<usize>,
    /// Edits computed (1 + the widenings tried).
    pub attempts: usize,
}

/// Applies `regions` to the keyframe `cwf` (see the [module docs](self)). The result shares
/// `cwf`'s base mesh, so it goes straight into [`interpolate`](super::interpolate()).
///
/// Guarantees: ω on fixed edges, a and z̃ on fixed vertices are bitwise copies of the input; an
/// identity op copies ω on its edges. Errors ([`Error::InvalidArgument`], naming the element):
/// no region, an empty region, an out-of-range face, overlapping regions, an interface too thin
/// to separate edited and fixed vertices, a non-finite rotation, σ ≤ 0 or non-finite, μ < 0 or
/// non-finite, invalid options.
pub fn edit(cwf: &Cwf, regions: &[RegionEdit], opts: &EditOptions) -> Result<(Cwf, EditReport)> {
    edit_with_progress(cwf, regions, opts, &mut |_| true)
}

/// As [`edit`], calling `progress` (stage `"edit"`, on the calling thread) after each step of
/// every attempt (labels and ω, the interface ω and amplitude solves, the phase solve's
/// factorization and each of its inverse iterations, the compatibility measures).
/// The callback returning `false` stops with [`Error::Cancelled`]. When not cancelled, the
/// result is that of [`edit`], bit for bit.
pub fn edit_with_progress(
    cwf: &Cwf,
    regions: &[RegionEdit],
    opts: &EditOptions,
    progress: &mut ProgressFn<'_>,
) -> Result<(Cwf, EditReport)> {
    check_inputs(regions, opts)?;
    // attempt k reports its steps in [1 − 1/k, 1 − 1/(k+1)): fractions never go back
    let mut tick = |k: usize, f: f64| {
        let k = k as f64;
        checkpoint(progress, "edit", 1.0 - 1.0 / k + f / (k * (k + 1.0)))
    };
    let mut best = edit_with_rings(cwf, regions, opts, &mut |f| tick(1, f))?;
    if opts.compat_target <= 0.0 || best.1.global {
        return Ok(best);
    }
    let mut wide = regions.to_vec();
    let mut attempts = 1;
    while roughness(&best.1) > opts.compat_target {
        let mut grew = false;
        for r in wide.iter_mut() {
            if r.interface_rings < opts.max_interface_rings {
                r.interface_rings += 1;
                grew = true;
            }
        }
        if !grew {
            break;
        }
        attempts += 1;
        match edit_with_rings(cwf, &wide, opts, &mut |f| tick(attempts, f)) {
            Err(Error::Cancelled) => return Err(Error::Cancelled),
            Ok(next) if !next.1.global && next.1.vertex_counts[0] > 0 => {
                if roughness(&next.1) < roughness(&best.1) {
                    best = next;
                }
            }
            _ => break,
        }
    }
    best.1.attempts = attempts;
    Ok(best)
}

/// What the adaptive width ([`EditOptions::compat_target`]) drives below its target: the larger
/// of the compatibility RMS over edit + interface edges and over the interface-only edges (the
/// interface itself must be smooth; the mean over both classes can hide a rough band
/// behind a smooth edited region).
fn roughness(r: &EditReport) -> f64 {
    r.compat_rms.max(r.compat_rms_by_class[1])
}

/// One edit with the regions' interface widths as given (steps 1–7 of the module docs);
/// `tick(fraction of this edit)` is a cancellation point between the steps and inside the
/// phase solve.
fn edit_with_rings(
    cwf: &Cwf,
    regions: &[RegionEdit],
    opts: &EditOptions,
    tick: &mut dyn FnMut(f64) -> Result<()>,
) -> Result<(Cwf, EditReport)> {
    let t0 = Instant::now();
    let topo = &cwf.topo;
    let x = cwf.base().positions();
    let faces: Vec<&[u32]> = regions.iter().map(|r| r.faces.as_slice()).collect();
    let rings: Vec<usize> = regions.iter().map(|r| r.interface_rings).collect();
    let labels = classify(topo, &faces, &rings, opts.adjacency)?;
    let mut omega = edit_omega(topo, x, cwf.omega(), regions, &labels);
    let mut amp = cwf.amplitude().to_vec();
    for (j, a) in amp.iter_mut().enumerate() {
        if labels.vertex[j] == FaceClass::Edit {
            let mu = regions[labels.vertex_region[j] as usize].amplitude_scale;
            if mu != 1.0 {
                *a *= mu;
            }
        }
    }
    tick(0.1)?;
    let t1 = Instant::now();
    let cot = cotan_weights_raw(topo, x);
    let omega_residual = solve_interface_omega(topo, &cot, cwf.omega(), &mut omega, &labels, opts)?;
    tick(0.3)?;
    let t2 = Instant::now();
    let (amplitude_residual, clamped) =
        solve_interface_amplitude(topo, &cot, &omega, cwf.amplitude(), &mut amp, &labels, opts)?;
    tick(0.5)?;
    let t3 = Instant::now();
    let phase = solve_phase(cwf, &omega, &amp, &labels, opts, &mut || tick(0.7))?;
    tick(0.9)?;
    let t4 = Instant::now();
    let mut zeta = phase.zeta;
    for (j, z) in zeta.iter_mut().enumerate() {
        if labels.vertex[j] == FaceClass::Fixed {
            *z = cwf.zeta()[j];
        }
    }
    let out = cwf.with_fields(omega, amp, zeta);
    let count = |c: &[FaceClass]| {
        [FaceClass::Fixed, FaceClass::Edit, FaceClass::Interface]
            .map(|k| c.iter().filter(|&&v| v == k).count())
    };
    let report = EditReport {
        face_counts: count(&labels.face),
        vertex_counts: count(&labels.vertex),
        edge_counts: count(&labels.edge),
        face_class: labels.face.clone(),
        omega_residual,
        amplitude_residual,
        eigenvalue: phase.eigenvalue,
        phase_residual: phase.residual,
        phase_iterations: phase.iterations,
        s: phase.s,
        phase_fallback: phase.fallback,
        global: phase.global,
        clamped,
        compat_rms: compat_rms(&out, &labels, &[FaceClass::Edit, FaceClass::Interface]),
        compat_rms_by_class: [
            compat_rms(&out, &labels, &[FaceClass::Edit]),
            compat_rms(&out, &labels, &[FaceClass::Interface]),
        ],
        compat_floor: compat_floor(topo, out.omega(), &labels, &mut || tick(0.95))?,
        seconds: [
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            (t3 - t2).as_secs_f64(),
            (t4 - t3).as_secs_f64(),
        ],
        interface_rings: rings,
        attempts: 1,
    };
    Ok((out, report))
}

fn check_inputs(regions: &[RegionEdit], opts: &EditOptions) -> Result<()> {
    if regions.is_empty() {
        return crate::invalid_arg!("no region to edit");
    }
    for (r, reg) in regions.iter().enumerate() {
        if !reg.rotate.is_finite() {
            return crate::invalid_arg!("region {r}: rotation {} is not finite", reg.rotate);
        }
        if !(reg.frequency_scale.is_finite() && reg.frequency_scale > 0.0) {
            return crate::invalid_arg!(
                "region {r}: frequency scale {} must be finite and > 0",
                reg.frequency_scale
            );
        }
        if !(reg.amplitude_scale.is_finite() && reg.amplitude_scale >= 0.0) {
            return crate::invalid_arg!(
                "region {r}: amplitude scale {} must be finite and ≥ 0",
                reg.amplitude_scale
            );
        }
    }
    for (name, v) in [
        ("eps_omega", opts.eps_omega),
        ("eps_amplitude", opts.eps_amplitude),
        ("gamma", opts.gamma),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return crate::invalid_arg!("{name} = {v} must be finite and ≥ 0");
        }
    }
    if !(opts.edit_weight.is_finite() && opts.edit_weight >= 1.0) {
        return crate::invalid_arg!("edit_weight = {} must be finite and ≥ 1", opts.edit_weight);
    }
    if !(opts.tolerance.is_finite() && opts.tolerance > 0.0) {
        return crate::invalid_arg!("tolerance = {} must be finite and > 0", opts.tolerance);
    }
    if !(opts.compat_target.is_finite() && opts.compat_target >= 0.0) {
        return crate::invalid_arg!(
            "compat_target = {} must be finite and ≥ 0 (0: exact interface widths)",
            opts.compat_target
        );
    }
    Ok(())
}

/// `ω¹`: ω⁰ copied, edit edges replaced by the region's rotated/scaled value (step 2).
fn edit_omega(
    topo: &Topology,
    x: &[[f64; 3]],
    omega0: &[f64],
    regions: &[RegionEdit],
    labels: &Labels,
) -> Vec<f64> {
    let mut omega = omega0.to_vec();
    for e in 0..topo.n_edges() {
        if labels.edge[e] != FaceClass::Edit {
            continue;
        }
        let op = &regions[labels.edge_region[e] as usize];
        if op.is_identity() {
            continue;
        }
        omega[e] = if op.rotate == 0.0 {
            op.frequency_scale * omega0[e]
        } else {
            op.frequency_scale * rotated_edge_value(topo, x, omega0, e, op.rotate)
        };
    }
    omega
}

/// Mean over the edge's faces and endpoints of `(R_θ u_{f,v})·(x_b − x_a)`.
fn rotated_edge_value(
    topo: &Topology,
    x: &[[f64; 3]],
    omega0: &[f64],
    e: usize,
    theta: f64,
) -> f64 {
    let [a, b] = topo.edges[e];
    let ev = Vec3::from(x[b as usize]) - Vec3::from(x[a as usize]);
    let (s, c) = theta.sin_cos();
    let (mut sum, mut n) = (0.0, 0u32);
    for &f in topo.edge_faces[e].iter().filter(|&&f| f != NONE) {
        let f = f as usize;
        let normal = face_unit_normal(topo, x, f);
        for v in [a, b] {
            let u = corner_vector(topo, x, omega0, f, topo.corner_of(f, v));
            // Rodrigues: R u = u cos θ + (n × u) sin θ + n (n·u)(1 − cos θ)
            let ru = u * c + normal.cross(u) * s + normal * (normal.dot(u) * (1.0 - c));
            sum += ru.dot(ev);
            n += 1;
        }
    }
    if n == 0 {
        omega0[e]
    } else {
        sum / n as f64
    }
}

/// Eq. 3.26 on the interface-only edges; returns the relative residual.
fn solve_interface_omega(
    topo: &Topology,
    cot: &[f64],
    omega0: &[f64],
    omega: &mut [f64],
    labels: &Labels,
    opts: &EditOptions,
) -> Result<f64> {
    let (free, n) = index_of(&labels.edge, FaceClass::Interface);
    if n == 0 {
        return Ok(0.0);
    }
    let mut t = Vec::new();
    let mut rhs = vec![0.0; n];
    // one least-squares row: Σ coef·ω; free edges become unknowns, the others constants
    let mut add_row = |terms: &mut dyn Iterator<Item = (usize, f64)>| {
        let (mut g, mut h) = (Vec::new(), 0.0);
        for (e, coef) in terms {
            match free[e] {
                u32::MAX => h += coef * omega[e],
                i => g.push((i as usize, coef)),
            }
        }
        if !g.is_empty() {
            push_outer_lower(&mut t, &g);
            for &(i, gi) in &g {
                rhs[i] -= gi * h;
            }
        }
    };
    // curl rows (faces)
    for f in 0..topo.n_faces() {
        let tri = topo.faces[f];
        add_row(&mut (0..3).map(|i| {
            let e = topo.face_edges[f][i] as usize;
            (
                e,
                if topo.edges[e][0] == tri[i] {
                    1.0
                } else {
                    -1.0
                },
            )
        }));
    }
    // divergence rows (vertices)
    for m in 0..topo.n_vertices {
        add_row(&mut topo.vert_edges.row(m).iter().map(|&e| {
            let e = e as usize;
            let sign = if topo.edges[e][0] == m as u32 {
                1.0
            } else {
                -1.0
            };
            (e, sign * cot[e])
        }));
    }
    for e in 0..topo.n_edges() {
        if free[e] != u32::MAX {
            let i = free[e] as usize;
            t.push(Entry::new(i, i, opts.eps_omega));
            rhs[i] += opts.eps_omega * omega0[e];
        }
    }
    let (sol, residual) = solve_spd(n, &t, &rhs, "the interface frequency system (eq. 3.26)")?;
    for e in 0..topo.n_edges() {
        if free[e] != u32::MAX {
            omega[e] = sol[free[e] as usize];
        }
    }
    Ok(residual)
}

/// Eq. 3.27 on the interface-only vertices, clamped at 0; returns (residual, clamped count).
fn solve_interface_amplitude(
    topo: &Topology,
    cot: &[f64],
    omega: &[f64],
    amp0: &[f64],
    amp: &mut [f64],
    labels: &Labels,
    opts: &EditOptions,
) -> Result<(f64, usize)> {
    let (free, n) = index_of(&labels.vertex, FaceClass::Interface);
    if n == 0 {
        return Ok((0.0, 0));
    }
    let curl = topo.face_curls(omega);
    let mut t = Vec::new();
    let mut rhs = vec![0.0; n];
    for j in 0..topo.n_vertices {
        if free[j] == u32::MAX {
            continue;
        }
        let i = free[j] as usize;
        let curl_term: f64 = topo
            .vert_corners
            .row(j)
            .iter()
            .map(|&c| curl[c as usize / 3].powi(2))
            .sum::<f64>()
            * (2.0 * opts.gamma / 3.0);
        t.push(Entry::new(i, i, curl_term + opts.eps_amplitude));
        rhs[i] += opts.eps_amplitude * amp0[j];
    }
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        let c = cot[e];
        for (p, q) in [(k, l), (l, k)] {
            if free[p] == u32::MAX {
                continue;
            }
            let i = free[p] as usize;
            t.push(Entry::new(i, i, c));
            match free[q] {
                u32::MAX => rhs[i] += c * amp[q],
                jq if (jq as usize) < i => t.push(Entry::new(i, jq as usize, -c)),
                _ => {}
            }
        }
    }
    let (sol, residual) = solve_spd(n, &t, &rhs, "the interface amplitude system (eq. 3.27)")?;
    let mut clamped = 0;
    for j in 0..topo.n_vertices {
        if free[j] != u32::MAX {
            let v = sol[free[j] as usize];
            if v < 0.0 {
                clamped += 1;
            }
            amp[j] = v.max(0.0);
        }
    }
    Ok((residual, clamped))
}

/// Per element, its index among those of class `class` (`u32::MAX` for the others), and their
/// number.
fn index_of(class: &[FaceClass], want: FaceClass) -> (Vec<u32>, usize) {
    let mut n = 0u32;
    let idx = class
        .iter()
        .map(|&c| {
            if c == want {
                n += 1;
                n - 1
            } else {
                u32::MAX
            }
        })
        .collect();
    (idx, n as usize)
}

struct Phase {
    zeta: Vec<Complex>,
    eigenvalue: f64,
    residual: f64,
    iterations: usize,
    s: Complex,
    fallback: bool,
    global: bool,
}

/// Eq. 3.28 (augmented pencil), or Knöppel on `ω¹` when nothing is fixed; `tick` is a
/// cancellation point after the factorization and before each inverse iteration after the
/// first.
fn solve_phase(
    cwf: &Cwf,
    omega: &[f64],
    amp: &[f64],
    labels: &Labels,
    opts: &EditOptions,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<Phase> {
    let topo = &cwf.topo;
    let x = cwf.base().positions();
    let nv = topo.n_vertices;
    if !labels.vertex.contains(&FaceClass::Fixed) {
        let kopts = KnoppelOptions {
            weights: PhaseWeights::EdgeArea,
            max_iterations: opts.max_iterations,
            tolerance: opts.tolerance,
            ..KnoppelOptions::default()
        };
        let (zeta, rep) = knoppel_phase_with_tick(topo, x, omega, &kopts, tick)?;
        return Ok(Phase {
            zeta,
            eigenvalue: rep.eigenvalue,
            residual: rep.residual,
            iterations: rep.iterations,
            s: Complex::ONE,
            fallback: false,
            global: true,
        });
    }
    let (edge_area, vertex_area) = barycentric_areas(topo, x);
    let mean_area = vertex_area.iter().sum::<f64>() / nv.max(1) as f64;
    let mass: Vec<f64> = vertex_area
        .iter()
        .map(|&a| a.max(1e-12 * mean_area.max(1e-300)))
        .collect();
    let (free, m) = index_of_not(&labels.vertex, FaceClass::Fixed);
    let u0: Vec<Complex> = (0..nv)
        .map(|j| match (labels.vertex[j], opts.phase) {
            (FaceClass::Fixed, PhaseCoupling::Unit) => cwf.zeta()[j],
            (FaceClass::Fixed, PhaseCoupling::AmplitudeWeighted) => {
                cwf.zeta()[j].scale(cwf.amplitude()[j])
            }
            _ => Complex::ZERO,
        })
        .collect();
    // Hermitian entries of A: per edge (k, l), weights α_k, α_l (1 or the other end's amplitude)
    let mut t = Vec::new();
    let mut a_u0 = vec![Complex::ZERO; m]; // PᴴAu⁰
    let mut u0_a_u0 = 0.0;
    let s_idx = m;
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        let (ak, al) = match opts.phase {
            PhaseCoupling::Unit => (1.0, 1.0),
            PhaseCoupling::AmplitudeWeighted => (amp[l], amp[k]),
        };
        let w = if labels.edge[e] == FaceClass::Edit {
            edge_area[e] * opts.edit_weight
        } else {
            edge_area[e]
        };
        let tr = Complex::cis(omega[e]);
        // energy w|α_k t x_k − α_l x_l|²: H_kk = wα_k², H_ll = wα_l², H_lk = −wα_kα_l t
        let h_kk = w * ak * ak;
        let h_ll = w * al * al;
        let h_lk = tr.scale(-w * ak * al);
        let entries = [
            (k, k, Complex::new(h_kk, 0.0)),
            (l, l, Complex::new(h_ll, 0.0)),
            (l, k, h_lk),
            (k, l, h_lk.conj()),
        ];
        for (r, c, h) in entries {
            match (free[r], free[c]) {
                (u32::MAX, u32::MAX) => u0_a_u0 += (u0[r].conj() * h * u0[c]).re,
                (fr, u32::MAX) => a_u0[fr as usize] += h * u0[c],
                (u32::MAX, _) => {} // the conjugate of the (c, r) entry, pushed with it
                (fr, fc) => {
                    if fr >= fc {
                        // push_hermitian adds the mirrored entry itself
                        push_hermitian(&mut t, fr as usize, fc as usize, h);
                    }
                }
            }
        }
    }
    for (i, v) in a_u0.iter().enumerate() {
        if *v != Complex::ZERO {
            push_hermitian(&mut t, s_idx, i, v.conj());
        }
    }
    push_hermitian(&mut t, s_idx, s_idx, Complex::new(u0_a_u0, 0.0));
    let u0_m_u0: f64 = (0..nv).map(|j| mass[j] * u0[j].norm_sqr()).sum();
    // groups: components with a fixed vertex share s (group 0); the others their own groups
    let (comp, n_comp) = components(topo);
    let mut has_fixed = vec![false; n_comp];
    for j in 0..nv {
        has_fixed[comp[j] as usize] |= labels.vertex[j] == FaceClass::Fixed;
    }
    let mut group_of_comp = vec![0u32; n_comp];
    let mut n_groups = 1u32;
    for c in 0..n_comp {
        if !has_fixed[c] {
            group_of_comp[c] = n_groups;
            n_groups += 1;
        }
    }
    let dim = 2 * (m + 1);
    let mut mass2 = vec![0.0; dim];
    let mut groups = vec![0u32; dim];
    let mut start = vec![0.0; dim];
    for j in 0..nv {
        if free[j] != u32::MAX {
            let i = free[j] as usize;
            mass2[2 * i] = mass[j];
            mass2[2 * i + 1] = mass[j];
            let g = group_of_comp[comp[j] as usize];
            groups[2 * i] = g;
            groups[2 * i + 1] = g;
            let z = cwf.zeta()[j];
            let z = if z == Complex::ZERO {
                Complex::new(1.0, 0.5)
            } else {
                z
            };
            start[2 * i] = z.re;
            start[2 * i + 1] = z.im;
        }
    }
    let s_mass = u0_m_u0.max(1e-12 * mean_area.max(1e-300));
    mass2[2 * s_idx] = s_mass;
    mass2[2 * s_idx + 1] = s_mass;
    start[2 * s_idx] = 1.0;
    let a = assemble(dim, &t, "the phase pencil (eq. 3.28)")?;
    let scale = {
        let diag = diag_of(&a);
        diag.iter()
            .zip(&mass2)
            .map(|(d, m)| d / m)
            .fold(0.0, f64::max)
            .max(1e-300)
    };
    let a = std::sync::Arc::new(a);
    let an = CholeskyAnalysis::new_stoppable(&a, tick)?;
    let schedule = ShiftSchedule {
        initial: 1e-9 * scale,
        growth: 100.0,
        max_attempts: 5,
    };
    // a large factorization runs with `tick` every 0.1 s (the same factor)
    if an.is_heavy() {
        tick()?;
    }
    let mass2 = std::sync::Arc::new(mass2);
    let (a2, m2) = (a.clone(), mass2.clone());
    let llt = run_stoppable(
        an.is_heavy(),
        move || an.factor_with_growing_shift(&a2, &m2, schedule, Parallelism::Global),
        tick,
    )?
    .map_err(|_| Error::Numerical("the phase pencil (eq. 3.28) is not positive definite".into()))?;
    let problem = ShiftedProblem {
        shifted: &llt,
        apply_a: |u: &[f64]| matvec_full(&a, u),
        mass: &mass2,
        groups: &groups,
        n_groups: n_groups as usize,
        scale,
    };
    let params = InverseIterationParams {
        max_iterations: opts.max_iterations,
        tolerance: opts.tolerance,
    };
    tick()?;
    let (u, info) = iterate_with_tick(&problem, start, &params, tick)?;
    let mut s = Complex::new(u[2 * s_idx], u[2 * s_idx + 1]);
    let mut fallback = false;
    let mut ut: Vec<Complex> = (0..m)
        .map(|i| Complex::new(u[2 * i], u[2 * i + 1]))
        .collect();
    if s.norm_sqr() * u0_m_u0 < 1e-20 {
        fallback = true;
        s = Complex::ONE;
        ut = harmonic_extension(&t, m, &a_u0)?;
    }
    // z̃ = normalize(ũ / s) = normalize(ũ s̄) on free vertices of s's group
    let mut zeta = vec![Complex::ZERO; nv];
    let max = ut.iter().map(|z| z.abs()).fold(0.0, f64::max);
    for j in 0..nv {
        if free[j] == u32::MAX {
            continue;
        }
        let v = ut[free[j] as usize];
        let v = if group_of_comp[comp[j] as usize] == 0 {
            v * s.conj()
        } else {
            v
        };
        let r = v.abs();
        let rel = ut[free[j] as usize].abs();
        zeta[j] = if rel > 1e-12 * max && r > 0.0 {
            v.scale(1.0 / r)
        } else {
            Complex::ZERO
        };
    }
    Ok(Phase {
        zeta,
        eigenvalue: info.eigenvalues[0],
        residual: info.residual,
        iterations: info.iterations,
        s,
        fallback,
        global: false,
    })
}

/// The fallback `s = 1`: `PᴴAP ũ = −PᴴAu⁰` (the free block of the pencil's entries `t`).
fn harmonic_extension(t: &[Entry], m: usize, a_u0: &[Complex]) -> Result<Vec<Complex>> {
    let lower: Vec<Entry> = t
        .iter()
        .filter(|e| e.row < 2 * m && e.col < 2 * m && e.row >= e.col)
        .copied()
        .collect();
    let rhs: Vec<f64> = a_u0.iter().flat_map(|z| [-z.re, -z.im]).collect();
    let (x, _) = solve_spd(
        2 * m,
        &lower,
        &rhs,
        "the phase harmonic extension (eq. 3.28, s = 1)",
    )?;
    Ok(x.chunks_exact(2)
        .map(|c| Complex::new(c[0], c[1]))
        .collect())
}

fn diag_of(a: &crate::solve::SparseMatrix) -> Vec<f64> {
    let cp = a.symbolic().col_ptr();
    let ri = a.symbolic().row_idx();
    (0..a.ncols())
        .map(|j| {
            (cp[j]..cp[j + 1])
                .filter(|&k| ri[k] == j)
                .map(|k| a.val()[k])
                .sum()
        })
        .collect()
}

/// Like [`index_of`] for the elements *not* of class `class`.
fn index_of_not(class: &[FaceClass], not: FaceClass) -> (Vec<u32>, usize) {
    let mut n = 0u32;
    let idx = class
        .iter()
        .map(|&c| {
            if c != not {
                n += 1;
                n - 1
            } else {
                u32::MAX
            }
        })
        .collect();
    (idx, n as usize)
}

/// RMS of `|wrap(ω − Δarg z̃)|` over the edges of the classes `which` with non-zero endpoints.
fn compat_rms(cwf: &Cwf, labels: &Labels, which: &[FaceClass]) -> f64 {
    let dec = cwf.decompose_omega();
    let (mut sum, mut n) = (0.0, 0usize);
    for (e, &[k, l]) in cwf.edges().iter().enumerate() {
        if !which.contains(&labels.edge[e]) {
            continue;
        }
        if cwf.zeta()[k as usize] == Complex::ZERO || cwf.zeta()[l as usize] == Complex::ZERO {
            continue;
        }
        let r = wrap_to_pi(dec.residual[e]);
        sum += r * r;
        n += 1;
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

/// [`EditReport::compat_floor`]: `min ‖δ‖²` over non-fixed edges subject to `D δ = D ω` on the
/// non-fixed faces (`D` the face curl, fixed edges held at 0), by the normal equations
/// `D Dᵀ y = D ω`, `δ = Dᵀ y`; returns `‖δ‖ / √(non-fixed edges)`. `tick` is a cancellation
/// point every 0.1 s of a large factorization (0.8 CPU s on a 213k-face global edit).
fn compat_floor(
    topo: &Topology,
    omega: &[f64],
    labels: &Labels,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<f64> {
    let (row, n_rows) = index_of_not(&labels.face, FaceClass::Fixed);
    let n_edges = labels
        .edge
        .iter()
        .filter(|&&c| c != FaceClass::Fixed)
        .count();
    if n_rows == 0 || n_edges == 0 {
        return Ok(0.0);
    }
    let curl = topo.face_curls(omega);
    // per non-fixed edge: its (row, sign) entries of D
    let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); topo.n_edges()];
    for (f, &r) in row.iter().enumerate() {
        if r == u32::MAX {
            continue;
        }
        for i in 0..3 {
            let e = topo.face_edges[f][i] as usize;
            if labels.edge[e] != FaceClass::Fixed {
                let sign = if topo.edges[e][0] == topo.faces[f][i] {
                    1.0
                } else {
                    -1.0
                };
                cols[e].push((r as usize, sign));
            }
        }
    }
    let mut t = Vec::new();
    for c in &cols {
        push_outer_lower(&mut t, c);
    }
    // a row of D without a free edge (a face whose edges are all fixed) has curl 0 here
    for r in 0..n_rows {
        t.push(Entry::new(r, r, 1e-12));
    }
    let rhs: Vec<f64> = (0..topo.n_faces())
        .filter(|&f| row[f] != u32::MAX)
        .map(|f| curl[f])
        .collect();
    let (y, _) = solve_spd_with_tick(n_rows, &t, &rhs, "the compatibility floor", tick)?;
    let norm2: f64 = cols
        .iter()
        .map(|c| c.iter().map(|&(r, s)| s * y[r]).sum::<f64>().powi(2))
        .sum();
    Ok((norm2 / n_edges as f64).sqrt())
}
