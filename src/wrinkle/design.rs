//! Wrinkle design from sources (dissertation §3.6.1, eq. 3.25; spec `specs/cwf-design.md`,
//! "Design"): the user places sources — a vertex, a wave vector, an amplitude, a region size in
//! rings — and gets a keyframe [`Cwf`] with wrinkles of that direction and wavelength around each
//! source, blending smoothly where regions meet, and nothing (`a = 0`, `ω = 0`) elsewhere.
//!
//! 1. Regions: `in_i` = the vertices of [`grow_faces`](super::grow_faces)`({s_i}, n_i)`;
//!    `in_V`, `in_F`, `in_E` the unions of vertices, faces and their edges.
//! 2. Wave vectors by the vector heat method (Sharp et al. 2019): `(M + tL_ρ)X = Y`,
//!    `(M + tL)m = |Y|`, `(M + tL)δ = 1_S`, `v_j = (m_j/δ_j) X_j/|X_j|` in the tangent frame of
//!    `j`; `L_ρ` is Knöppel's connection Laplacian with the transport angles `ρ` in place of ω,
//!    `t = heat_time · h̄²` (h̄ the mean edge length). **Departure from the spec:** `ρ` is the
//!    discrete Levi-Civita connection of the vertex normals (the minimal rotation taking `n_k`
//!    to `n_l`, expressed in the two vertices' frames) rather than the intrinsic fan angles; both
//!    are exact on flat meshes and agree to first order in the normal change.
//! 3. `ω_ij = ½(v_i + v_j)·(x_j − x_i)` on `in_E`, 0 elsewhere.
//! 4. Eq. 3.25, `min_a ½κ aᵀLa + Σ_i Σ_{j∈in_i} w_j (a_j − c_i)² +
//!    γ Σ_{F∈in_F} ((a_l²+a_m²+a_n²)/3)(dω_F)²`, `a = 0` off `in_V`, `a_{s_i} = c_i` (when
//!    pinned), `w_j = A_j/h̄²` (scale-invariant, spec ambiguity 2); one SPD solve; clamped ≥ 0.
//! 5. `z̃` = Knöppel's phase of `ω` ([`Cwf::from_one_form`]).

use std::time::Instant;

use super::areas::barycentric_areas;
use super::complex::Complex;
use super::cwf::Cwf;
use super::interpolate::checkpoint;
use super::knoppel::{cotan_weights, cotan_weights_raw, KnoppelOptions, KnoppelReport};
use super::region::{grow_mask, Adjacency};
use super::spd::{push_hermitian, push_outer_lower, solve_spd_many_with_tick, solve_spd_with_tick};
use super::topology::Topology;
use crate::geom::Vec3;
use crate::mesh::TriMesh;
use crate::report::ProgressFn;
use crate::solve::Entry;
use crate::Result;

/// One wrinkle source: wrinkles of wave vector `wave_vector` and amplitude `amplitude` around
/// `vertex`, over `rings` rings of faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WrinkleSource {
    /// The source vertex.
    pub vertex: u32,
    /// Wave vector (radians per unit length, xyz); its tangential part is used.
    pub wave_vector: [f64; 3],
    /// Target amplitude `c_i ≥ 0`.
    pub amplitude: f64,
    /// Region size in rings (≥ 1); the spec's default is 5.
    pub rings: usize,
}

/// Parameters of [`design`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesignOptions {
    /// How the source regions grow; default [`Adjacency::Vertex`].
    pub adjacency: Adjacency,
    /// Heat time in units of the squared mean edge length; default 1.
    pub heat_time: f64,
    /// κ of eq. 3.25 (smoothness); default 1.
    pub kappa: f64,
    /// γ of eq. 3.25 (curl penalty); default 1 (reference ¼).
    pub gamma: f64,
    /// Multiplier of the data weights `w_j = A_j/h̄²`; default 1 (reference ½ with `A_j`).
    pub data_weight: f64,
    /// Pin `a_{s_i} = c_i` at the sources (the text); default true (reference false).
    pub pin_sources: bool,
    /// Options of the final Knöppel phase solve.
    pub knoppel: KnoppelOptions,
}

impl Default for DesignOptions {
    fn default() -> Self {
        DesignOptions {
            adjacency: Adjacency::Vertex,
            heat_time: 1.0,
            kappa: 1.0,
            gamma: 1.0,
            data_weight: 1.0,
            pin_sources: true,
            knoppel: KnoppelOptions::default(),
        }
    }
}

/// What [`design`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignReport {
    /// Influenced vertices, faces, edges (`in_V`, `in_F`, `in_E`).
    pub influenced: [usize; 3],
    /// Relative residual of the complex heat solve `(M + tL_ρ)X = Y`.
    pub heat_residual: f64,
    /// Relative residual of the amplitude solve (eq. 3.25).
    pub amplitude_residual: f64,
    /// Amplitudes clamped to 0.
    pub clamped: usize,
    /// The Knöppel phase solve.
    pub knoppel: KnoppelReport,
    /// Wall seconds `[regions + vector heat, eq. 3.25, Knöppel]`.
    pub seconds: [f64; 3],
}

/// Designs a keyframe on `base` from `sources` (see the [module docs](self)).
///
/// Guarantees: `ω = 0` on edges outside the source regions and `a = 0` on vertices outside
/// them (exact zeros); on a flat mesh with equal-direction sources `ω = k·e` on the region edges
/// to rounding. Errors: [`Error::InvalidMesh`](crate::Error::InvalidMesh) for a base that is not
/// an oriented manifold; [`Error::InvalidArgument`](crate::Error) naming the source for no
/// source, an out-of-range vertex, a non-finite wave vector, a negative or non-finite amplitude,
/// `rings = 0`, two sources on one vertex, or invalid options.
pub fn design(
    base: TriMesh,
    sources: &[WrinkleSource],
    opts: &DesignOptions,
) -> Result<(Cwf, DesignReport)> {
    design_with_progress(base, sources, opts, &mut |_| true)
}

/// As [`design`], calling `progress` (stage `"design"`, on the calling thread) after each step
/// of the [module docs](self) and inside the long ones: after the topology, every 64 sources'
/// regions, the vector heat method's vector solve and scalar solves, the amplitude solve,
/// and in Knöppel's phase solve after its factorization and each inverse iteration.
/// The callback returning `false` stops with [`Error::Cancelled`](crate::Error::Cancelled).
/// When not cancelled, the result is that of [`design`], bit for bit.
pub fn design_with_progress(
    base: TriMesh,
    sources: &[WrinkleSource],
    opts: &DesignOptions,
    progress: &mut ProgressFn<'_>,
) -> Result<(Cwf, DesignReport)> {
    let t0 = Instant::now();
    let mut tick = |fraction: f64| checkpoint(progress, "design", fraction);
    let topo = Topology::from_mesh(&base, &base.edges())?;
    check_sources(&topo, sources, opts)?;
    tick(0.05)?;
    let x = base.positions();
    let nv = topo.n_vertices;
    // (1) regions
    let mut in_i = Vec::with_capacity(sources.len());
    let mut in_f = vec![false; topo.n_faces()];
    for (i, s) in sources.iter().enumerate() {
        if i > 0 && i % 64 == 0 {
            tick(0.05)?;
        }
        let mask = grow_mask(&topo, &[], &[s.vertex], s.rings, opts.adjacency)?;
        let mut verts = vec![false; nv];
        for (f, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
            in_f[f] = true;
            for &v in &topo.faces[f] {
                verts[v as usize] = true;
            }
        }
        in_i.push(verts);
    }
    let in_v: Vec<bool> = (0..nv).map(|j| in_i.iter().any(|m| m[j])).collect();
    let in_e: Vec<bool> = (0..topo.n_edges())
        .map(|e| {
            topo.edge_faces[e]
                .iter()
                .any(|&f| f != super::topology::NONE && in_f[f as usize])
        })
        .collect();
    tick(0.1)?;
    // (2) vector heat
    let h = mean_edge_length(&topo, x);
    let (v, heat_residual) = vector_heat(&topo, x, sources, opts.heat_time * h * h, &mut tick)?;
    // (3) ω
    let omega: Vec<f64> = topo
        .edges
        .iter()
        .enumerate()
        .map(|(e, &[a, b])| {
            if !in_e[e] {
                return 0.0;
            }
            let ev = Vec3::from(x[b as usize]) - Vec3::from(x[a as usize]);
            0.5 * (v[a as usize] + v[b as usize]).dot(ev)
        })
        .collect();
    tick(0.5)?;
    let t1 = Instant::now();
    // (4) amplitude
    let (amp, amplitude_residual, clamped) = design_amplitude(
        &topo,
        x,
        sources,
        &in_i,
        &in_v,
        &in_f,
        &omega,
        h,
        opts,
        &mut || tick(0.5),
    )?;
    tick(0.6)?;
    let t2 = Instant::now();
    // (5) phase
    let (cwf, knoppel) =
        Cwf::from_one_form_with_progress(base, omega, amp, &opts.knoppel, &mut || tick(0.8))?;
    let t3 = Instant::now();
    let report = DesignReport {
        influenced: [
            in_v.iter().filter(|&&b| b).count(),
            in_f.iter().filter(|&&b| b).count(),
            in_e.iter().filter(|&&b| b).count(),
        ],
        heat_residual,
        amplitude_residual,
        clamped,
        knoppel,
        seconds: [
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            (t3 - t2).as_secs_f64(),
        ],
    };
    Ok((cwf, report))
}

fn check_sources(topo: &Topology, sources: &[WrinkleSource], opts: &DesignOptions) -> Result<()> {
    if sources.is_empty() {
        return crate::invalid_arg!("no wrinkle source given");
    }
    let mut seen = vec![u32::MAX; topo.n_vertices];
    for (i, s) in sources.iter().enumerate() {
        if s.vertex as usize >= topo.n_vertices {
            return crate::invalid_arg!(
                "source {i}: vertex {} is out of range (the mesh has {} vertices)",
                s.vertex,
                topo.n_vertices
            );
        }
        if !s.wave_vector.iter().all(|c| c.is_finite()) {
            return crate::invalid_arg!(
                "source {i}: wave vector {:?} is not finite",
                s.wave_vector
            );
        }
        if !(s.amplitude.is_finite() && s.amplitude >= 0.0) {
            return crate::invalid_arg!(
                "source {i}: amplitude {} must be finite and ≥ 0",
                s.amplitude
            );
        }
        if s.rings == 0 {
            return crate::invalid_arg!("source {i}: rings = 0 (at least 1)");
        }
        let slot = &mut seen[s.vertex as usize];
        if *slot != u32::MAX {
            return crate::invalid_arg!(
                "sources {} and {i} are both on vertex {}; merge them",
                *slot,
                s.vertex
            );
        }
        *slot = i as u32;
    }
    for (name, v) in [
        ("kappa", opts.kappa),
        ("gamma", opts.gamma),
        ("data_weight", opts.data_weight),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return crate::invalid_arg!("{name} = {v} must be finite and ≥ 0");
        }
    }
    if !(opts.heat_time.is_finite() && opts.heat_time > 0.0) {
        return crate::invalid_arg!("heat_time = {} must be finite and > 0", opts.heat_time);
    }
    Ok(())
}

fn mean_edge_length(topo: &Topology, x: &[[f64; 3]]) -> f64 {
    let sum: f64 = topo
        .edges
        .iter()
        .map(|&[a, b]| (Vec3::from(x[b as usize]) - Vec3::from(x[a as usize])).length())
        .sum();
    let h = sum / topo.n_edges().max(1) as f64;
    if h > 0.0 && h.is_finite() {
        h
    } else {
        1.0
    }
}

/// Per-vertex unit normal (area-weighted face normals) and tangent frame `(e1, e2)`: `e1` the
/// first incident edge projected off the normal, `e2 = n × e1`.
fn vertex_frames(topo: &Topology, x: &[[f64; 3]]) -> Vec<[Vec3; 3]> {
    let mut n = vec![Vec3::ZERO; topo.n_vertices];
    for t in &topo.faces {
        let p = t.map(|v| Vec3::from(x[v as usize]));
        let an = (p[1] - p[0]).cross(p[2] - p[0]);
        for &v in t {
            n[v as usize] += an;
        }
    }
    (0..topo.n_vertices)
        .map(|j| {
            let nj = unit_or(n[j], Vec3::Z);
            let e1 = match topo.vert_edges.row(j).first() {
                Some(&e) => {
                    let o = topo.other_end(e as usize, j as u32) as usize;
                    let d = Vec3::from(x[o]) - Vec3::from(x[j]);
                    unit_or(d - nj * nj.dot(d), any_perp(nj))
                }
                None => any_perp(nj),
            };
            [nj, e1, nj.cross(e1)]
        })
        .collect()
}

fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let l = v.length();
    if l > 0.0 && l.is_finite() {
        v * (1.0 / l)
    } else {
        fallback
    }
}

fn any_perp(n: Vec3) -> Vec3 {
    let a = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    unit_or(a - n * n.dot(a), Vec3::Y)
}

/// Transport angle `ρ_kl` from `k`'s frame to `l`'s: the minimal rotation taking `n_k` to `n_l`
/// applied to `e1_k`, measured in `(e1_l, e2_l)`.
fn transport_angle(fk: &[Vec3; 3], fl: &[Vec3; 3]) -> f64 {
    let (nk, nl) = (fk[0], fl[0]);
    let c = nk.dot(nl);
    let axis = nk.cross(nl);
    let v = fk[1];
    let rv = if c > -1.0 + 1e-12 {
        v * c + axis.cross(v) + axis * (axis.dot(v) / (1.0 + c))
    } else {
        v
    };
    rv.dot(fl[2]).atan2(rv.dot(fl[1]))
}

/// The vector heat method (step 2): per vertex the extended wave vector (zero where the heat
/// did not reach), and the complex solve's relative residual.
/// `tick(fraction)` is a cancellation point, called before and after the vector solve (the
/// two scalar solves share one factorization).
fn vector_heat(
    topo: &Topology,
    x: &[[f64; 3]],
    sources: &[WrinkleSource],
    t: f64,
    tick: &mut dyn FnMut(f64) -> Result<()>,
) -> Result<(Vec<Vec3>, f64)> {
    let nv = topo.n_vertices;
    let frames = vertex_frames(topo, x);
    let (_, area) = barycentric_areas(topo, x);
    let mean_area = area.iter().sum::<f64>() / nv.max(1) as f64;
    let mass: Vec<f64> = area
        .iter()
        .map(|&a| a.max(1e-12 * mean_area.max(1e-300)))
        .collect();
    let w = cotan_weights(topo, x);
    // complex M + tL_ρ (knoppel's convention: H_lk = −w e^{iρ_kl}) and real M + tL
    let mut tc = Vec::new();
    let mut tr = Vec::new();
    let mut diag = mass.clone();
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        let rho = transport_angle(&frames[k], &frames[l]);
        push_hermitian(&mut tc, l, k, Complex::cis(rho).scale(-t * w[e]));
        tr.push(Entry::new(l, k, -t * w[e]));
        diag[k] += t * w[e];
        diag[l] += t * w[e];
    }
    for (j, &d) in diag.iter().enumerate() {
        push_hermitian(&mut tc, j, j, Complex::new(d, 0.0));
        tr.push(Entry::new(j, j, d));
    }
    let tc: Vec<Entry> = tc.into_iter().filter(|e| e.row >= e.col).collect();
    let mut y = vec![0.0; 2 * nv];
    let mut y_abs = vec![0.0; nv];
    let mut ind = vec![0.0; nv];
    for s in sources {
        let j = s.vertex as usize;
        let k = Vec3::from(s.wave_vector);
        let z = Complex::new(k.dot(frames[j][1]), k.dot(frames[j][2]));
        y[2 * j] += z.re;
        y[2 * j + 1] += z.im;
        y_abs[j] += z.abs();
        ind[j] = 1.0;
    }
    tick(0.1)?;
    let (xs, heat_residual) =
        solve_spd_with_tick(2 * nv, &tc, &y, "the vector heat system", &mut || tick(0.2))?;
    tick(0.3)?;
    // both scalar solves on one factorization
    let mut scalar = solve_spd_many_with_tick(
        nv,
        &tr,
        &[&y_abs, &ind],
        "the scalar heat system",
        &mut || tick(0.3),
    )?;
    let (delta, _) = scalar.pop().expect("two solves");
    let (m, _) = scalar.pop().expect("two solves");
    let v = (0..nv)
        .map(|j| {
            let z = Complex::new(xs[2 * j], xs[2 * j + 1]);
            let r = z.abs();
            if r > 0.0 && delta[j] > 0.0 && r.is_finite() {
                let mag = m[j] / delta[j];
                (frames[j][1] * z.re + frames[j][2] * z.im) * (mag / r)
            } else {
                Vec3::ZERO
            }
        })
        .collect();
    Ok((v, heat_residual))
}

/// Eq. 3.25 (step 4): the amplitude, its solve's residual and the number clamped. `tick` is a
/// cancellation point every 0.1 s of a large factorization (the same result).
#[allow(clippy::too_many_arguments)]
fn design_amplitude(
    topo: &Topology,
    x: &[[f64; 3]],
    sources: &[WrinkleSource],
    in_i: &[Vec<bool>],
    in_v: &[bool],
    in_f: &[bool],
    omega: &[f64],
    h: f64,
    opts: &DesignOptions,
    tick: &mut dyn FnMut() -> Result<()>,
) -> Result<(Vec<f64>, f64, usize)> {
    let nv = topo.n_vertices;
    let mut fixed = vec![None; nv]; // Some(value) for constrained vertices
    for (j, f) in fixed.iter_mut().enumerate() {
        if !in_v[j] {
            *f = Some(0.0);
        }
    }
    if opts.pin_sources {
        for s in sources {
            fixed[s.vertex as usize] = Some(s.amplitude);
        }
    }
    let mut free = vec![u32::MAX; nv];
    let mut n = 0usize;
    for j in 0..nv {
        if fixed[j].is_none() {
            free[j] = n as u32;
            n += 1;
        }
    }
    let (_, area) = barycentric_areas(topo, x);
    let cot = cotan_weights_raw(topo, x);
    let curl = topo.face_curls(omega);
    let mut t = Vec::new();
    let mut rhs = vec![0.0; n];
    for j in 0..nv {
        let Some(i) = (free[j] != u32::MAX).then_some(free[j] as usize) else {
            continue;
        };
        let wj = opts.data_weight * area[j] / (h * h);
        let mut d = 0.0;
        for (s, reg) in sources.iter().zip(in_i) {
            if reg[j] {
                d += 2.0 * wj;
                rhs[i] += 2.0 * wj * s.amplitude;
            }
        }
        let curl_term: f64 = topo
            .vert_corners
            .row(j)
            .iter()
            .map(|&c| c as usize / 3)
            .filter(|&f| in_f[f])
            .map(|f| curl[f].powi(2))
            .sum();
        d += 2.0 * opts.gamma / 3.0 * curl_term;
        t.push(Entry::new(i, i, d));
    }
    for (e, &[k, l]) in topo.edges.iter().enumerate() {
        let (k, l) = (k as usize, l as usize);
        let c = opts.kappa * cot[e];
        let mut g = Vec::with_capacity(2);
        let mut h_const = 0.0;
        // ½κ c (a_k − a_l)²: gradient κ c (a_k − a_l) — the outer product of (1, −1)·√(κc)
        for (v, sign) in [(k, 1.0), (l, -1.0)] {
            match fixed[v] {
                Some(a) => h_const += sign * a,
                None => g.push((free[v] as usize, sign)),
            }
        }
        if g.is_empty() {
            continue;
        }
        let gc: Vec<(usize, f64)> = g.iter().map(|&(i, s)| (i, s * c)).collect();
        // entries c·g gᵀ (c may be negative: push scaled pairs)
        let mut tmp = Vec::new();
        push_outer_lower(&mut tmp, &g);
        t.extend(
            tmp.into_iter()
                .map(|en| Entry::new(en.row, en.col, en.val * c)),
        );
        for &(i, gi) in &gc {
            rhs[i] -= gi * h_const;
        }
    }
    let what = "the design amplitude system (eq. 3.25)";
    let (sol, residual) = solve_spd_with_tick(n, &t, &rhs, what, tick)?;
    let mut clamped = 0;
    let amp = (0..nv)
        .map(|j| match fixed[j] {
            Some(a) => a,
            None => {
                let a = sol[free[j] as usize];
                if a < 0.0 {
                    clamped += 1;
                }
                a.max(0.0)
            }
        })
        .collect();
    Ok((amp, residual, clamped))
}
