//! [`Cwf`]: the complex wrinkle field representation of §3.3.1 — a frequency one-form `ω` per
//! edge, an amplitude `a` per vertex and a phase `z̃` per vertex on a base triangle mesh — with
//! its soft-compatibility energies (eqs. 3.5, 3.6) and the compatible/residual split of ω
//! (eq. 3.17).

use super::areas::barycentric_areas;
use super::complex::Complex;
use super::knoppel::{knoppel_phase_with_tick, KnoppelOptions, KnoppelReport};
use super::report::CwfStage;
use super::topology::Topology;
use crate::geom::Vec3;
use crate::mesh::TriMesh;
use crate::report::StageTimes;
use crate::{Error, Result};

/// A complex wrinkle field (§3.3.1) on a validated base mesh.
///
/// - `omega[e]`: the frequency one-form on edge `e` of [`TriMesh::edges`] (the
///   [`EdgeList`](crate::mesh::EdgeList) numbering), integrated from its smaller to its larger
///   vertex index: `ω_kl` with `k < l`, `ω_lk = −ω_kl`;
/// - `amplitude[j] ≥ 0`: the wrinkle amplitude `a_j`;
/// - `zeta[j]`: the approximately unit phase `z̃_j`; the complex field is `z_j = a_j z̃_j`.
///
/// The base mesh must be manifold (edges with one or two triangles, one fan per vertex),
/// possibly with boundary, consistently oriented, without repeated or duplicated triangles;
/// vertices used by no triangle are allowed and carried along unchanged.
#[derive(Debug, Clone)]
pub struct Cwf {
    base: TriMesh,
    omega: Vec<f64>,
    amplitude: Vec<f64>,
    zeta: Vec<Complex>,
    pub(crate) topo: Topology,
}

/// A frequency field to build a [`Cwf`] from (§3.2.1: `ω = dθ`, the wave vector).
#[derive(Debug, Clone, Copy)]
pub enum FrequencyField<'a> {
    /// One wave vector per vertex: `ω_ij = ½ (v_i + v_j) · (x_j − x_i)`.
    PerVertex(&'a [[f64; 3]]),
    /// One wave vector per triangle: `ω_ij` is the mean over the edge's triangles `f` of
    /// `v_f · (x_j − x_i)`.
    PerFace(&'a [[f64; 3]]),
}

/// `ω = ω_com + δω` (eq. 3.17 ff.): `ω_com` agrees exactly with the phase of `z̃`
/// (`arg z̃_l − arg z̃_k ≡ ω_com,kl mod 2π` on every edge) and `δω ∈ [−π, π)`.
#[derive(Debug, Clone, PartialEq)]
pub struct OmegaDecomposition {
    /// The compatible part `ω_com = ω − δω`.
    pub compatible: Vec<f64>,
    /// The residual `δω` in `[−π, π)` (0 on edges with a vanishing `z̃` endpoint).
    pub residual: Vec<f64>,
}

impl Cwf {
    /// Validates and builds a CWF. Errors with [`Error::InvalidMesh`] when the base mesh is not
    /// a consistently oriented manifold (message names the offending edge or vertex), and
    /// [`Error::InvalidArgument`] when a length does not match (`omega`: one per edge of
    /// `base.edges()`, `amplitude`/`zeta`: one per vertex) or a value is NaN, infinite, or (for
    /// the amplitude) negative.
    pub fn new(
        base: TriMesh,
        omega: Vec<f64>,
        amplitude: Vec<f64>,
        zeta: Vec<Complex>,
    ) -> Result<Cwf> {
        let topo = Topology::from_mesh(&base, &base.edges())?;
        check_len("omega (one per edge)", omega.len(), topo.n_edges())?;
        check_len(
            "amplitude (one per vertex)",
            amplitude.len(),
            topo.n_vertices,
        )?;
        check_len("zeta (one per vertex)", zeta.len(), topo.n_vertices)?;
        check_finite("omega", omega.iter().copied())?;
        check_finite("amplitude", amplitude.iter().copied())?;
        check_finite("zeta", zeta.iter().flat_map(|z| [z.re, z.im]))?;
        if let Some(j) = amplitude.iter().position(|&a| a < 0.0) {
            return crate::invalid_arg!(
                "amplitude[{j}] = {} is negative; amplitudes are ≥ 0 (a sign flip is a phase \
                 shift of π in zeta)",
                amplitude[j]
            );
        }
        Ok(Cwf {
            base,
            omega,
            amplitude,
            zeta,
            topo,
        })
    }

    /// Builds a CWF from a frequency one-form alone: `z̃` is Knöppel et al.'s phase
    /// ([`knoppel`](super::knoppel)). Validation as [`Cwf::new`].
    pub fn from_one_form(
        base: TriMesh,
        omega: Vec<f64>,
        amplitude: Vec<f64>,
        opts: &KnoppelOptions,
    ) -> Result<(Cwf, KnoppelReport)> {
        Cwf::from_one_form_with_progress(base, omega, amplitude, opts, &mut || Ok(()))
    }

    /// As [`Cwf::from_one_form`], with a cancellation point: `tick` runs after the validation,
    /// after Knöppel's factorization and before each of its inverse iterations after the first (so
    /// a cancel is seen within 0.5 s); its error is returned as is. When it never fails, the result
    /// is that of [`Cwf::from_one_form`], bit for bit.
    pub fn from_one_form_with_progress(
        base: TriMesh,
        omega: Vec<f64>,
        amplitude: Vec<f64>,
        opts: &KnoppelOptions,
        tick: &mut dyn FnMut() -> Result<()>,
    ) -> Result<(Cwf, KnoppelReport)> {
        let n = base.vertex_count();
        let mut stages = StageTimes::default();
        let mut cwf = stages.time(CwfStage::Validate, || {
            Cwf::new(base, omega, amplitude, vec![Complex::ONE; n])
        })?;
        tick()?;
        let (zeta, mut report) = stages.time(CwfStage::Knoppel, || {
            knoppel_phase_with_tick(&cwf.topo, cwf.base.positions(), &cwf.omega, opts, tick)
        })?;
        report.stages = stages;
        cwf.zeta = zeta;
        Ok((cwf, report))
    }

    /// Builds a CWF from per-vertex or per-face wave vectors and amplitudes (§3.2.1):
    /// `ω` by [`FrequencyField`], then `z̃` by Knöppel et al. ([`Cwf::from_one_form`]).
    pub fn from_frequency_field(
        base: TriMesh,
        frequency: FrequencyField<'_>,
        amplitude: Vec<f64>,
        opts: &KnoppelOptions,
    ) -> Result<(Cwf, KnoppelReport)> {
        let omega = one_form_from_vectors(&base, frequency)?;
        Cwf::from_one_form(base, omega, amplitude, opts)
    }

    /// A CWF on the same (already validated) base mesh with other fields. Crate-internal: the
    /// caller guarantees the lengths (one ω per edge, one amplitude and z̃ per vertex) and that
    /// every value is finite and every amplitude ≥ 0, as [`Cwf::new`] would check.
    pub(crate) fn with_fields(
        &self,
        omega: Vec<f64>,
        amplitude: Vec<f64>,
        zeta: Vec<Complex>,
    ) -> Cwf {
        debug_assert_eq!(omega.len(), self.omega.len());
        debug_assert_eq!(amplitude.len(), self.amplitude.len());
        debug_assert_eq!(zeta.len(), self.zeta.len());
        Cwf {
            base: self.base.clone(),
            omega,
            amplitude,
            zeta,
            topo: self.topo.clone(),
        }
    }

    /// The base mesh.
    pub fn base(&self) -> &TriMesh {
        &self.base
    }

    /// The frequency one-form, one value per edge of `base().edges()`, oriented min → max.
    pub fn omega(&self) -> &[f64] {
        &self.omega
    }

    /// The amplitude per vertex.
    pub fn amplitude(&self) -> &[f64] {
        &self.amplitude
    }

    /// The phase `z̃` per vertex.
    pub fn zeta(&self) -> &[Complex] {
        &self.zeta
    }

    /// The edges `[v0, v1]` (`v0 < v1`) the one-form lives on, in its order.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.topo.edges
    }

    /// Consumes the CWF: `(base, omega, amplitude, zeta)`.
    pub fn into_parts(self) -> (TriMesh, Vec<f64>, Vec<f64>, Vec<Complex>) {
        (self.base, self.omega, self.amplitude, self.zeta)
    }

    /// `Ê_compat(z̃, ω) = Σ_edges A_kl |z̃_k e^{iω_kl} − z̃_l|²` (eq. 3.5), `A_kl` the barycentric
    /// edge area (a third of the area of each adjacent triangle).
    pub fn compatibility_energy(&self) -> f64 {
        let (edge_area, _) = barycentric_areas(&self.topo, self.base.positions());
        self.topo
            .edges
            .iter()
            .enumerate()
            .map(|(e, &[k, l])| {
                let d = self.zeta[k as usize] * Complex::cis(self.omega[e]) - self.zeta[l as usize];
                edge_area[e] * d.norm_sqr()
            })
            .sum()
    }

    /// `Ê_unit(z̃) = Σ_vertices A_j (|z̃_j|² − 1)²` (eq. 3.6), `A_j` the barycentric vertex area.
    pub fn unit_energy(&self) -> f64 {
        let (_, vertex_area) = barycentric_areas(&self.topo, self.base.positions());
        self.zeta
            .iter()
            .zip(&vertex_area)
            .map(|(z, a)| a * (z.norm_sqr() - 1.0).powi(2))
            .sum()
    }

    /// The split `ω = ω_com + δω` of eq. 3.17 ff.: per edge `k → l`,
    /// `δω = wrap(ω_kl − (arg z̃_l − arg z̃_k))` into `[−π, π)`. Where `z̃_k` or `z̃_l` is zero the
    /// phase difference is undefined and `δω = 0`. `z̃_k e^{iω_com} = z̃_l` then holds exactly
    /// wherever `|z̃_k| = |z̃_l|`.
    pub fn decompose_omega(&self) -> OmegaDecomposition {
        let residual: Vec<f64> = self
            .topo
            .edges
            .iter()
            .enumerate()
            .map(|(e, &[k, l])| {
                let (zk, zl) = (self.zeta[k as usize], self.zeta[l as usize]);
                if zk == Complex::ZERO || zl == Complex::ZERO {
                    0.0
                } else {
                    // arg(z̄_k z_l) is the phase difference in (−π, π] without cancellation
                    wrap_to_pi(self.omega[e] - (zk.conj() * zl).arg())
                }
            })
            .collect();
        let compatible = self
            .omega
            .iter()
            .zip(&residual)
            .map(|(w, d)| w - d)
            .collect();
        OmegaDecomposition {
            compatible,
            residual,
        }
    }
}

/// `x − 2πk` in `[−π, π)`.
pub(crate) fn wrap_to_pi(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let mut r = x - TAU * ((x + PI) / TAU).floor();
    if r >= PI {
        r -= TAU;
    }
    if r < -PI {
        r += TAU;
    }
    r
}

/// `ω` on the EdgeList edges of `base` from per-vertex or per-face wave vectors.
pub fn one_form_from_vectors(base: &TriMesh, frequency: FrequencyField<'_>) -> Result<Vec<f64>> {
    let el = base.edges();
    let x = base.positions();
    let edge_vec = |e: usize| {
        let [a, b] = el.edges[e].0;
        Vec3::from(x[b as usize]) - Vec3::from(x[a as usize])
    };
    match frequency {
        FrequencyField::PerVertex(v) => {
            check_len("frequency (one per vertex)", v.len(), base.vertex_count())?;
            check_finite("frequency", v.iter().flatten().copied())?;
            Ok((0..el.len())
                .map(|e| {
                    let [a, b] = el.edges[e].0;
                    let (va, vb) = (v[a as usize], v[b as usize]);
                    0.5 * (Vec3::from(va) + Vec3::from(vb)).dot(edge_vec(e))
                })
                .collect())
        }
        FrequencyField::PerFace(v) => {
            check_len("frequency (one per face)", v.len(), base.triangle_count())?;
            check_finite("frequency", v.iter().flatten().copied())?;
            let mut sum = vec![0.0; el.len()];
            let mut count = vec![0u32; el.len()];
            for (f, fe) in el.face_edges.iter().enumerate() {
                for &e in fe.iter().filter(|&&e| e != u32::MAX) {
                    sum[e as usize] += Vec3::from(v[f]).dot(edge_vec(e as usize));
                    count[e as usize] += 1;
                }
            }
            Ok(sum
                .iter()
                .zip(&count)
                .map(|(s, &c)| s / c.max(1) as f64)
                .collect())
        }
    }
}

fn check_len(what: &str, got: usize, want: usize) -> Result<()> {
    if got != want {
        return crate::invalid_arg!("{what}: {got} values given, {want} needed");
    }
    Ok(())
}

fn check_finite(what: &str, values: impl Iterator<Item = f64>) -> Result<()> {
    for (i, v) in values.enumerate() {
        if !v.is_finite() {
            return Err(Error::InvalidArgument(format!(
                "{what}: value {i} is {v} (NaN or infinite)"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap() {
        use std::f64::consts::PI;
        assert_eq!(wrap_to_pi(PI), -PI);
        assert!((wrap_to_pi(7.0) - (7.0 - 2.0 * PI)).abs() < 1e-15);
        assert!((wrap_to_pi(-3.0) + 3.0).abs() < 1e-15);
        for k in -50..50 {
            let r = wrap_to_pi(k as f64 * 0.77);
            assert!((-PI..PI).contains(&r));
        }
    }
}
