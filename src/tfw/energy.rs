//! The wrinkle-field energy `E^wf = E_s + E_b` (eqs. 2.20–2.27, discretized as A.7) on vertex
//! amplitudes `a` and an edge one-form `ω` (pleat's edge numbering, [`TriMesh::edges`]), with
//! its exact gradient and exact sparse Hessian (spec "Energies").
//!
//! Per face `f` (rest form `Ī`, base form `I`, area `A_f`), with the 3-point rule
//! `(u, v) ∈ {(1/6,1/6), (2/3,1/6), (1/6,2/3)}`, `w_q = 1/3`:
//! `E_f = A_f Σ_q w_q [ (h/4)(W_s¹ + W_s² + W_s³ + W_s⁴) + (h³/12) W_b² ]` where
//! - `W_s¹ = ‖Ī⁻¹(I − Ī + ½ da daᵀ + ½ a² ω_f ω_fᵀ)‖²_SV` (2.21),
//! - `W_s² = 4 a² κ_f² (1+λ_t)² β(α+β)/(α+2β)` when `λ_c < 0 ≤ λ_t`, else 0 (2.22),
//! - `W_s³ = a²/32 ‖Ī⁻¹(ω_f daᵀ + da ω_fᵀ)‖²_SV` (2.23), `W_s⁴ = ⅛ ‖Ī⁻¹ da daᵀ‖²_SV` (2.24),
//! - `W_b² = a²/2 ‖Ī⁻¹ ω_f ω_fᵀ‖²_SV` (2.26); `W_b¹` (2.25) is constant in `(a, ω)` and left out.
//!
//! `a(q)` is the P1 interpolant, `da = (a1−a0, a2−a0)`, `ω_f = (ω(v0→v1), ω(v0→v2))` from the
//! face's edges at corner 0 (`s0 ω[e0]`, `−s2 ω[e2]`). The energy is a polynomial of degree 8
//! in the five local unknowns `(a0, a1, a2, ω01, ω02)`: value, gradient and Hessian come from
//! one evaluation in second-order forward mode (`Jet`), so they are exact to rounding.
//!
//! Unknowns are numbered `[a_0 … a_{n−1}, ω_0 … ω_{m−1}]` (vertices, then edges).

use super::dense::{dot, sub};
use crate::mesh::TriMesh;
use crate::tfw::dense::project_psd_unless_definite;
use crate::tfw::material::{Form, Lame};
use crate::tfw::wfree::FaceStrain;
use rayon::prelude::*;

/// Number of local unknowns of a face: `(a0, a1, a2, ω(v0→v1), ω(v0→v2))`.
const L: usize = 5;

/// A value with its exact gradient and Hessian in the [`L`] local unknowns (second-order
/// forward mode; polynomials only).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Jet {
    v: f64,
    g: [f64; L],
    h: [[f64; L]; L],
}

/// The arithmetic the face energy needs, so one generic formula ([`WrinkleEnergy::face_energy`])
/// gives the plain value (`f64`, for line searches: no derivatives carried) and the value
/// with its exact gradient and Hessian (`Jet`).
pub(crate) trait Scalar: Copy {
    /// A constant.
    fn constant(v: f64) -> Self;
    /// The local unknown `i` with value `v`.
    fn variable(v: f64, i: usize) -> Self;
    /// `self + o`.
    fn add(&self, o: &Self) -> Self;
    /// `s · self`.
    fn scale(&self, s: f64) -> Self;
    /// `self · o`.
    fn mul(&self, o: &Self) -> Self;
    /// `s·self + t·o`.
    fn lin(&self, s: f64, o: &Self, t: f64) -> Self {
        self.scale(s).add(&o.scale(t))
    }
}

impl Scalar for f64 {
    fn constant(v: f64) -> f64 {
        v
    }
    fn variable(v: f64, _: usize) -> f64 {
        v
    }
    fn add(&self, o: &f64) -> f64 {
        self + o
    }
    fn scale(&self, s: f64) -> f64 {
        self * s
    }
    fn mul(&self, o: &f64) -> f64 {
        self * o
    }
}

impl Scalar for Jet {
    fn constant(v: f64) -> Jet {
        Jet {
            v,
            g: [0.0; L],
            h: [[0.0; L]; L],
        }
    }

    fn variable(v: f64, i: usize) -> Jet {
        let mut j = Jet::constant(v);
        j.g[i] = 1.0;
        j
    }

    fn add(&self, o: &Jet) -> Jet {
        let mut r = *self;
        r.v += o.v;
        for i in 0..L {
            r.g[i] += o.g[i];
            for j in 0..L {
                r.h[i][j] += o.h[i][j];
            }
        }
        r
    }

    fn scale(&self, s: f64) -> Jet {
        let mut r = *self;
        r.v *= s;
        for i in 0..L {
            r.g[i] *= s;
            for j in 0..L {
                r.h[i][j] *= s;
            }
        }
        r
    }

    /// One pass instead of `scale`, `scale`, `add` (the same products and sums, so the same
    /// bits: no fused multiply-add).
    fn lin(&self, s: f64, o: &Jet, t: f64) -> Jet {
        let mut r = Jet::constant(self.v * s + o.v * t);
        for i in 0..L {
            r.g[i] = self.g[i] * s + o.g[i] * t;
            for j in 0..L {
                r.h[i][j] = self.h[i][j] * s + o.h[i][j] * t;
            }
        }
        r
    }

    fn mul(&self, o: &Jet) -> Jet {
        let mut r = Jet::constant(self.v * o.v);
        for i in 0..L {
            r.g[i] = self.v * o.g[i] + o.v * self.g[i];
            for j in 0..L {
                r.h[i][j] = self.v * o.h[i][j]
                    + o.v * self.h[i][j]
                    + self.g[i] * o.g[j]
                    + o.g[i] * self.g[j];
            }
        }
        r
    }
}

/// Which terms of `E^wf` to include (all by default); used to test each term on its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WfTerms {
    /// `W_s¹` (2.21).
    pub stretch1: bool,
    /// `W_s²` (2.22).
    pub stretch2: bool,
    /// `W_s³` (2.23).
    pub stretch3: bool,
    /// `W_s⁴` (2.24).
    pub stretch4: bool,
    /// `W_b²` (2.26).
    pub bend2: bool,
}

impl WfTerms {
    /// Every term.
    pub const ALL: WfTerms = WfTerms {
        stretch1: true,
        stretch2: true,
        stretch3: true,
        stretch4: true,
        bend2: true,
    };
    /// No term.
    pub const NONE: WfTerms = WfTerms {
        stretch1: false,
        stretch2: false,
        stretch3: false,
        stretch4: false,
        bend2: false,
    };
}

impl Default for WfTerms {
    fn default() -> Self {
        WfTerms::ALL
    }
}

/// How [`WrinkleEnergy::evaluate`] builds the Hessian.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HessianMode {
    /// The exact Hessian.
    Exact,
    /// Each face's 5×5 block projected onto the PSD cone before assembly (S:2302–2307).
    ProjectedPerFace,
}

/// Energy, gradient and Hessian of [`WrinkleEnergy::evaluate`].
#[derive(Debug, Clone, PartialEq)]
pub struct WfEval {
    /// `E^wf` (J).
    pub energy: f64,
    /// Gradient over all unknowns (vertices then edges).
    pub gradient: Vec<f64>,
    /// Hessian entries `(row, col, value)`, `row ≥ col`, duplicates to be summed; the pattern
    /// depends only on the mesh.
    pub hessian: Vec<(usize, usize, f64)>,
}

#[derive(Debug, Clone, Copy)]
struct FaceData {
    verts: [usize; 3],
    /// Edge indices of ω(v0→v1) and ω(v0→v2) and their signs.
    edges: [usize; 2],
    signs: [f64; 2],
    area: f64,
    rest_inv: Form,
    strain: Form,
    /// `4 κ² (1+λ_t)² β(α+β)/(α+2β)` or 0 (2.22).
    curvature_coeff: f64,
}

/// The wrinkle-field energy of a base surface (module docs).
#[derive(Debug, Clone)]
pub struct WrinkleEnergy {
    faces: Vec<FaceData>,
    n_vertices: usize,
    n_edges: usize,
    lame: Lame,
    thickness: f64,
}

/// The 3-point quadrature rule of A.7 (R: `TFWSetup.cpp`).
pub const QUADRATURE: [(f64, f64); 3] = [
    (1.0 / 6.0, 1.0 / 6.0),
    (2.0 / 3.0, 1.0 / 6.0),
    (1.0 / 6.0, 2.0 / 3.0),
];

impl WrinkleEnergy {
    /// The energy on `base` (the solved base surface) with per-face rest forms, strains
    /// ([`crate::tfw::wfree::face_strains`]) and normal curvatures `curvature` along the
    /// tension direction. Faces with a degenerate corner or a non-positive rest determinant
    /// are left out (their unknowns then get no energy from them).
    pub fn new(
        base: &TriMesh,
        rest_forms: &[Form],
        strains: &[FaceStrain],
        curvature: &[f64],
        lame: Lame,
        thickness: f64,
    ) -> WrinkleEnergy {
        let el = base.edges();
        let k_coeff = lame.beta * (lame.alpha + lame.beta) / (lame.alpha + 2.0 * lame.beta);
        let mut faces = Vec::with_capacity(base.triangle_count());
        for (f, t) in base.triangles().iter().enumerate() {
            let (fe, fs) = (el.face_edges[f], el.face_edge_sign[f]);
            let r = rest_forms[f];
            let det = r[0] * r[2] - r[1] * r[1];
            if fs.contains(&0) || det <= 0.0 || !det.is_finite() {
                continue;
            }
            let p = t.map(|v| base.positions()[v as usize]);
            let e1 = sub(p[1], p[0]);
            let e2 = sub(p[2], p[0]);
            let cur = [dot(e1, e1), dot(e1, e2), dot(e2, e2)];
            let s = strains[f];
            let curvature_coeff = if s.lambda_c < 0.0 && s.lambda_t >= 0.0 {
                let k = curvature[f] * (1.0 + s.lambda_t);
                4.0 * k * k * k_coeff
            } else {
                0.0
            };
            faces.push(FaceData {
                verts: t.map(|v| v as usize),
                edges: [fe[0] as usize, fe[2] as usize],
                signs: [f64::from(fs[0]), -f64::from(fs[2])],
                area: 0.5 * det.sqrt(),
                rest_inv: [r[2] / det, -r[1] / det, r[0] / det],
                strain: [cur[0] - r[0], cur[1] - r[1], cur[2] - r[2]],
                curvature_coeff,
            });
        }
        WrinkleEnergy {
            faces,
            n_vertices: base.vertex_count(),
            n_edges: el.len(),
            lame,
            thickness,
        }
    }

    /// Number of unknowns (vertices + edges).
    pub fn dimension(&self) -> usize {
        self.n_vertices + self.n_edges
    }

    /// Number of vertices (the first unknowns are the amplitudes).
    pub fn vertex_count(&self) -> usize {
        self.n_vertices
    }

    /// `E^wf` of the selected terms at `x = [a | ω]`.
    pub fn energy(&self, x: &[f64], terms: WfTerms) -> f64 {
        self.faces
            .par_iter()
            .with_min_len(64)
            .map(|f| self.face_value(f, x, terms))
            .collect::<Vec<f64>>()
            .iter()
            .sum()
    }

    /// Energy, gradient and Hessian of the selected terms at `x = [a | ω]` (deterministic:
    /// faces are summed in order).
    pub fn evaluate(&self, x: &[f64], terms: WfTerms, mode: HessianMode) -> WfEval {
        let locals: Vec<Jet> = self
            .faces
            .par_iter()
            .map(|f| {
                let mut j = self.face_jet(f, x, terms);
                if mode == HessianMode::ProjectedPerFace {
                    project_psd_unless_definite(&mut j.h);
                }
                j
            })
            .collect();
        self.assemble_jets(&locals)
    }

    /// [`Self::evaluate`] with [`HessianMode::ProjectedPerFace`] and, from the same face jets,
    /// the exact Hessian's entries (same order and pattern as [`WfEval::hessian`]): one
    /// forward-mode pass for both (the exact-Hessian CG of [`crate::tfw::pnewton`]).
    pub fn evaluate_projected_and_exact(
        &self,
        x: &[f64],
        terms: WfTerms,
    ) -> (WfEval, Vec<(usize, usize, f64)>) {
        let exact: Vec<Jet> = self
            .faces
            .par_iter()
            .map(|f| self.face_jet(f, x, terms))
            .collect();
        let projected: Vec<Jet> = exact
            .par_iter()
            .map(|j| {
                let mut p = *j;
                project_psd_unless_definite(&mut p.h);
                p
            })
            .collect();
        (
            self.assemble_jets(&projected),
            self.assemble_jets(&exact).hessian,
        )
    }

    /// Sums the face jets in face order into energy, gradient and Hessian entries.
    fn assemble_jets(&self, locals: &[Jet]) -> WfEval {
        let mut gradient = vec![0.0; self.dimension()];
        let mut hessian = Vec::with_capacity(15 * locals.len());
        let mut energy = 0.0;
        for (f, j) in self.faces.iter().zip(locals) {
            energy += j.v;
            let (idx, sg) = self.local_map(f);
            for i in 0..L {
                gradient[idx[i]] += sg[i] * j.g[i];
                for k in 0..=i {
                    let (r, c) = (idx[i].max(idx[k]), idx[i].min(idx[k]));
                    hessian.push((r, c, sg[i] * sg[k] * j.h[i][k]));
                }
            }
        }
        WfEval {
            energy,
            gradient,
            hessian,
        }
    }

    fn local_map(&self, f: &FaceData) -> ([usize; L], [f64; L]) {
        let nv = self.n_vertices;
        (
            [
                f.verts[0],
                f.verts[1],
                f.verts[2],
                nv + f.edges[0],
                nv + f.edges[1],
            ],
            [1.0, 1.0, 1.0, f.signs[0], f.signs[1]],
        )
    }

    /// The face energy alone (plain arithmetic: ≈ 1/30 of the cost of [`Self::face_jet`]).
    fn face_value(&self, f: &FaceData, x: &[f64], terms: WfTerms) -> f64 {
        self.face_energy::<f64>(f, x, terms)
    }

    /// The face energy in second-order forward mode on the local unknowns.
    fn face_jet(&self, f: &FaceData, x: &[f64], terms: WfTerms) -> Jet {
        self.face_energy::<Jet>(f, x, terms)
    }

    /// The face energy (module docs, eqs. 2.21–2.26 with the 3-point rule) in the arithmetic
    /// `T`: the value (`f64`) or the value with exact derivatives (`Jet`); one formula, so
    /// the line search's energy is bit-for-bit the value the Newton step's evaluation gives.
    fn face_energy<T: Scalar>(&self, f: &FaceData, x: &[f64], terms: WfTerms) -> T {
        let (idx, sg) = self.local_map(f);
        let var: [T; L] = std::array::from_fn(|i| T::variable(sg[i] * x[idx[i]], i));
        let da = [
            var[1].lin(1.0, &var[0], -1.0),
            var[2].lin(1.0, &var[0], -1.0),
        ];
        let om = [var[3], var[4]];
        let (h, lame) = (self.thickness, self.lame);
        let outer = |p: &[T; 2], q: &[T; 2]| -> [T; 3] {
            [p[0].mul(&q[0]), p[0].mul(&q[1]), p[1].mul(&q[1])]
        };
        let dd = outer(&da, &da);
        let ww = outer(&om, &om);
        // ω daᵀ + da ωᵀ (symmetric)
        let wd = [
            om[0].mul(&da[0]).scale(2.0),
            om[0].mul(&da[1]).add(&da[0].mul(&om[1])),
            om[1].mul(&da[1]).scale(2.0),
        ];
        let sv = |s: &[T; 3]| sv_norm2_sym(&lame, f.rest_inv, s);
        let s4 = if terms.stretch4 {
            sv(&dd).scale(0.125)
        } else {
            T::constant(0.0)
        };
        let s3n = sv(&wd);
        let bn = sv(&ww);
        let mut total = T::constant(0.0);
        for &(u, v) in &QUADRATURE {
            let a = var[0].lin(1.0 - u - v, &var[1], u).add(&var[2].scale(v));
            let a2 = a.mul(&a);
            let mut stretch = T::constant(0.0);
            if terms.stretch1 {
                let s: [T; 3] = std::array::from_fn(|k| {
                    T::constant(f.strain[k])
                        .add(&dd[k].scale(0.5))
                        .add(&a2.mul(&ww[k]).scale(0.5))
                });
                stretch = stretch.add(&sv(&s));
            }
            if terms.stretch2 {
                stretch = stretch.add(&a2.scale(f.curvature_coeff));
            }
            if terms.stretch3 {
                stretch = stretch.add(&a2.mul(&s3n).scale(1.0 / 32.0));
            }
            stretch = stretch.add(&s4);
            let mut q = stretch.scale(0.25 * h);
            if terms.bend2 {
                q = q.add(&a2.mul(&bn).scale(0.5 * h * h * h / 12.0));
            }
            total = total.add(&q.scale(1.0 / 3.0));
        }
        total.scale(f.area)
    }
}

/// `‖Ī⁻¹S‖²_SV` (eq. 2.4, `tr(M²)`) of a symmetric `S = [s11, s12, s22]` given `Ī⁻¹`.
fn sv_norm2_sym<T: Scalar>(lame: &Lame, inv: Form, s: &[T; 3]) -> T {
    let (p, q, r) = (inv[0], inv[1], inv[2]);
    let m00 = s[0].lin(p, &s[1], q);
    let m01 = s[1].lin(p, &s[2], q);
    let m10 = s[0].lin(q, &s[1], r);
    let m11 = s[1].lin(q, &s[2], r);
    let tr = m00.add(&m11);
    let tr_m2 = m00
        .mul(&m00)
        .add(&m01.mul(&m10).scale(2.0))
        .add(&m11.mul(&m11));
    tr.mul(&tr)
        .scale(0.5 * lame.alpha)
        .add(&tr_m2.scale(lame.beta))
}
