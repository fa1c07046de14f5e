//! The whole TFW statics pipeline (spec "Algorithm" 2–8): base surface → strains, W,
//! curvature → initialization with Helmholtz projection → wrinkle SQP → period snapping on
//! the non-contractible loops ([`crate::tfw::snap`]) → `Cwf` (phase by the existing Knöppel
//! solve). One call, [`solve`], with a params struct in and a result with its
//! report out, and a progress/cancel callback: the shape a thin C layer wraps.

use crate::mesh::TriMesh;
use crate::report::{Progress, ProgressFn};
use crate::tfw::base::{solve_base, BaseOptions, BaseResult, BaseStatus};
use crate::tfw::curvature::{tension_curvature_by, CurvatureMethod};
use crate::tfw::energy::{WfTerms, WrinkleEnergy};
use crate::tfw::pnewton::run_sqp_projected_newton;
use crate::tfw::scene::Scene;
use crate::tfw::snap::{snap_periods, PeriodSnap};
use crate::tfw::sqp::{run_sqp, QpMethod, SqpOptions, SqpProblem, SqpResult, SqpStatus};
use crate::tfw::wfree::{
    face_strains, helmholtz_projection, initial_face_field, wrinkle_free_faces, WRule,
};
use crate::wrinkle::{Cwf, KnoppelOptions};
use crate::{Error, Result};
use std::time::Instant;

/// Parameters of [`solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TfwParams {
    /// The base solve.
    pub base: BaseOptions,
    /// The rule deciding the wrinkle-free faces W (default: the text's).
    pub w_rule: WRule,
    /// Initial peak amplitude `k` of A.6.2 (m); `None` = `min(0.01 m, 0.1 · bbox diagonal)`.
    pub initial_amplitude: Option<f64>,
    /// The wrinkle SQP.
    pub sqp: SqpOptions,
    /// How the curvature `κ_f` along the tension direction (eq. 2.22) is estimated.
    pub curvature: CurvatureMethod,
    /// The phase solve of the output `Cwf`.
    pub knoppel: KnoppelOptions,
    /// Rest-area fraction of slack faces above which the scene is out of scope (S:588;
    /// default 0.5).
    pub out_of_scope_slack_fraction: f64,
    /// Snap the periods of ω around the base's non-contractible loops to 2πℤ before the phase
    /// ([`crate::tfw::snap`]; default false). Off: the SQP's ω goes to Knöppel as it is, and
    /// the Knöppel phase still winds an integer number of times around every loop (it spreads
    /// the fractional part; no phase defect on the twisted cylinders). On: ω agrees with the
    /// phase's winding, at the cost of leaving the SQP's stationary point (E^wf +1.25% on the
    /// 690-v twisted cylinder; docs/design-notes.md, "Wrinkle SQP").
    pub snap_periods: bool,
}

impl Default for TfwParams {
    fn default() -> Self {
        TfwParams {
            base: BaseOptions::default(),
            w_rule: WRule::Text,
            initial_amplitude: None,
            sqp: SqpOptions::default(),
            curvature: CurvatureMethod::default(),
            knoppel: KnoppelOptions::default(),
            out_of_scope_slack_fraction: 0.5,
            snap_periods: false,
        }
    }
}

/// The outcome of [`solve`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TfwStatus {
    /// The base solve and the SQP both met a convergence test.
    Converged,
    /// A result was produced but the base solve or the SQP stopped without converging (see
    /// [`TfwResult::base`] and [`TfwResult::sqp`]).
    NotConverged,
    /// No compression anywhere (every face in W): `a ≡ 0`, `ω ≡ 0`, returned at once.
    NoCompression,
    /// Compressed in every direction over most of the surface (S:588): out of the model's
    /// scope; the best-effort base surface is returned with `a ≡ 0`.
    OutOfScope,
}

impl TfwStatus {
    /// A one-line explanation.
    pub fn describe(&self) -> &'static str {
        match self {
            TfwStatus::Converged => "converged",
            TfwStatus::NotConverged => "stopped before convergence (see the base and SQP status)",
            TfwStatus::NoCompression => "no compression: every face is wrinkle-free, a = 0",
            TfwStatus::OutOfScope => {
                "out of scope: the base is compressed in every direction over most of its area"
            }
        }
    }
}

/// Seconds per stage of [`solve`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TfwSeconds {
    /// Base solve.
    pub base: f64,
    /// Strains, W, curvature, initialization and Helmholtz projection.
    pub init: f64,
    /// The SQP.
    pub sqp: f64,
    /// The period snapping and the Knöppel phase.
    pub phase: f64,
}

/// The result of [`solve`].
#[derive(Debug, Clone)]
pub struct TfwResult {
    /// The base solve (mesh, status, Newton history, energies, strain summary, warnings).
    pub base: BaseResult,
    /// The complex wrinkle field on the base mesh: amplitude, ω on pleat's edge numbering,
    /// phase by Knöppel.
    pub cwf: Cwf,
    /// Per face, whether it is wrinkle-free (W).
    pub w_faces: Vec<bool>,
    /// Per face, the normal curvature along the tension direction used by W_s².
    pub curvature: Vec<f64>,
    /// The SQP (history, status); `None` when it did not run (no compression, out of scope).
    pub sqp: Option<SqpResult>,
    /// The period snapping between the SQP and the phase (loops, periods before and after,
    /// the correction's norm); `None` when it did not run (off, or no SQP).
    pub snap: Option<PeriodSnap>,
    /// `E^wf` of the returned field, after the period snapping (J; without the constant
    /// W_b¹). The SQP's own final energy is the last entry of its history.
    pub energy: f64,
    /// `max |curl ω|` over the faces outside W after initialization.
    pub init_curl_residual: f64,
    /// `max |curl ω|` over the faces outside W at the result.
    pub curl_residual: f64,
    /// The overall outcome.
    pub status: TfwStatus,
    /// Seconds per stage.
    pub seconds: TfwSeconds,
}

/// Runs the pipeline (module docs) on `scene`. Errors: scene validation
/// ([`Error::InvalidArgument`] naming the field), [`Error::Cancelled`], numerical failure of a
/// factorization that cannot be regularized. Non-convergence is a status, not an error.
pub fn solve(
    scene: &Scene,
    params: &TfwParams,
    progress: &mut ProgressFn<'_>,
) -> Result<TfwResult> {
    let model = scene.assemble()?;
    let mut seconds = TfwSeconds::default();
    let t = Instant::now();
    let base = {
        let mut sub = |p: Progress<'_>| {
            progress(Progress {
                stage: p.stage,
                fraction: 0.3 * p.fraction,
            })
        };
        solve_base(&model, &params.base, &mut sub)?
    };
    seconds.base = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mesh = base.mesh.clone();
    let nv = mesh.vertex_count();
    let ne = mesh.edges().len();
    let strains = face_strains(&model.rest_forms, &mesh);
    let lc: Vec<f64> = strains.iter().map(|s| s.lambda_c).collect();
    let w_faces = wrinkle_free_faces(&model.triangles, &lc, params.w_rule);
    let curvature = tension_curvature_by(&mesh, &strains, params.curvature);
    let mut clamped = vec![false; nv];
    for &(v, _) in &model.clamps {
        clamped[v as usize] = true;
    }
    let lame = model.material.lame();
    let energy = WrinkleEnergy::new(
        &mesh,
        &model.rest_forms,
        &strains,
        &curvature,
        lame,
        model.material.thickness,
    );
    let out_of_scope = base.strain.slack_area_fraction > params.out_of_scope_slack_fraction;
    let no_compression = w_faces.iter().all(|&w| w);
    if out_of_scope || no_compression {
        seconds.init = t.elapsed().as_secs_f64();
        let zero = vec![0.0; nv + ne];
        let e = energy.energy(&zero, WfTerms::ALL);
        let cwf = zero_cwf(mesh, &params.knoppel)?;
        return Ok(TfwResult {
            base,
            cwf,
            w_faces,
            curvature,
            sqp: None,
            snap: None,
            energy: e,
            init_curl_residual: 0.0,
            curl_residual: 0.0,
            status: if out_of_scope {
                TfwStatus::OutOfScope
            } else {
                TfwStatus::NoCompression
            },
            seconds,
        });
    }
    let k = params
        .initial_amplitude
        .unwrap_or_else(|| 0.01f64.min(0.1 * bbox_diagonal(&mesh)));
    let init = initial_face_field(&mesh, &model.rest_forms, &strains, &w_faces, &clamped, k);
    let proj = helmholtz_projection(&mesh, &model.rest_forms, &init.face_omega, &w_faces)?;
    let mut x0 = init.vertex_amplitude.clone();
    x0.extend_from_slice(&proj.omega);
    let problem = SqpProblem::new(energy, &mesh, &w_faces, &clamped);
    let init_curl_residual = problem.curl_residual(&x0);
    seconds.init = t.elapsed().as_secs_f64();
    if !progress(Progress {
        stage: "tfw initialization",
        fraction: 0.35,
    }) {
        return Err(Error::Cancelled);
    }
    let t = Instant::now();
    let sqp = {
        let mut sub = |p: Progress<'_>| {
            progress(Progress {
                stage: p.stage,
                fraction: 0.35 + 0.6 * p.fraction,
            })
        };
        match params.sqp.qp {
            QpMethod::Clarabel => run_sqp(&problem, &x0, &params.sqp, &mut sub)?,
            QpMethod::ProjectedNewton => {
                run_sqp_projected_newton(&problem, &x0, &params.sqp, &mut sub)?
            }
        }
    };
    seconds.sqp = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let amplitude = sqp.x[..nv].to_vec();
    let mut omega = sqp.x[nv..].to_vec();
    let snap = if params.snap_periods {
        let s = snap_periods(&problem, &mesh, &model.rest_forms, &w_faces, &omega)?;
        omega.clone_from(&s.omega);
        Some(s)
    } else {
        None
    };
    let mut x = amplitude.clone();
    x.extend_from_slice(&omega);
    let energy_value = problem.energy().energy(&x, WfTerms::ALL);
    let curl_residual = problem.curl_residual(&x);
    let (cwf, _) = Cwf::from_one_form(mesh, omega, amplitude, &params.knoppel)?;
    seconds.phase = t.elapsed().as_secs_f64();
    let converged = sqp.status.converged()
        && matches!(
            base.status,
            BaseStatus::Converged | BaseStatus::EnergyStalled
        );
    let status = if sqp.status == SqpStatus::NoFreeUnknowns {
        TfwStatus::NoCompression
    } else if converged {
        TfwStatus::Converged
    } else {
        TfwStatus::NotConverged
    };
    progress(Progress {
        stage: "tfw done",
        fraction: 1.0,
    });
    Ok(TfwResult {
        base,
        cwf,
        w_faces,
        curvature,
        sqp: Some(sqp),
        snap,
        energy: energy_value,
        init_curl_residual,
        curl_residual,
        status,
        seconds,
    })
}

fn zero_cwf(mesh: TriMesh, knoppel: &KnoppelOptions) -> Result<Cwf> {
    let (nv, ne) = (mesh.vertex_count(), mesh.edges().len());
    Ok(Cwf::from_one_form(mesh, vec![0.0; ne], vec![0.0; nv], knoppel)?.0)
}

fn bbox_diagonal(mesh: &TriMesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in mesh.positions() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}
