//! The wrinkle SQP's step by **projected Newton with the curl constraint eliminated** (spec
//! Risk 8's fallback; [`crate::tfw::sqp::QpMethod::ProjectedNewton`]).
//!
//! **Elimination.** The one-forms on the free edges that are curl-free on every face outside W
//! are exactly `ω = G u + Σ_g c_g h_g` (Hodge: exact part + cohomology part of the complex of
//! faces outside W): `G` the vertex-to-edge difference (`ω_e = u_head − u_tail`, pleat's edge
//! orientation), `u` one value per vertex of the complex with one vertex per connected
//! component pinned to 0 (the gauge), and `h_g` a **tree–cotree** basis of the closed,
//! non-exact forms: a spanning forest T of the vertex graph (breadth first, in vertex order),
//! a spanning forest T* of the dual graph over the remaining edges with one virtual node for
//! "outside" joined to every boundary edge (so holes and W islands need no special case), and
//! one generator per edge in neither; `h_g` is 1 on its generator edge, 0 on T and on the
//! other generators, and its cotree values follow face by face from the leaves of T* to its
//! roots, each solving that face's curl row exactly. Dimension count: `(V − P) + (E − V + P −
//! (F − F_closed)) = E − rank C`, so the map is a basis of `ker C` (P primal components,
//! F_closed the faces that root a closed component, whose curl row is implied). On the
//! cylinder the one generator carries the period around the ring (the wave count), which an
//! exact part alone would freeze.
//!
//! **Step.** In `y = (a_free, u, c)` the only constraints left are `a ≥ 0`: Bertsekas'
//! projected Newton — amplitudes at 0 with a positive gradient are held (their rows and columns
//! replaced by the mean diagonal), the rest take the Newton step of `Bᵀ (H + σ W) B` (H the
//! per-face PSD-projected Hessian of the SQP, `W` the first iteration's diagonal of H: the
//! clarabel QP's `σ I` in its scaled variables; σ follows a Levenberg–Marquardt-like schedule
//! (`next_shift`: grown after short line-search steps) where the clarabel SQP halves it after
//! every step), and the Armijo line
//! search runs along the projected arc `max(0, a + t d_a)` with the slope `gᵀ(y(t) − y)`.
//! Near the optimum (after a full step with σ ≤ 1e-8) the step is refined by Steihaug–Toint CG
//! on the **exact** `Bᵀ H B` preconditioned by that factorization ([`CgRefinement`],
//! 2026-11-27): the projected matrix alone made the cylinders converge linearly (r × 0.985–0.994
//! per full step, 526 iterations; now 77, docs/design-notes.md, "Wrinkle SQP").
//! **Valley search** (2026-11-29, for the cylinder at thickness × 10⁻²): after a full step with σ ≤
//! [`CgRefinement::max_shift`] (the refinement's gate), `E` is minimized over the scalar `μ`
//! along `(a, ω) → (a/μ, μω)` ([`SqpOptions::valley_search`]). The membrane term sees the
//! wrinkles only through `½a²ωωᵀ` (eq. 2.21), stiff ∝ h, while the split between amplitude
//! and frequency at fixed `a|ω|` is set by W_s² ∝ h a²κ² against W_b² ∝ h³ a²|ω|⁴ (the
//! spec's uniform-patch optimum `|ω|* ∝ √(κ/h)`): a valley whose floor is ∝ h² flatter than
//! its walls, traversed globally (the wave count around the cylinder) at a linear rate by the
//! projected-and-refined steps (thickness × 10⁻²: r/r₀ 3e-4 after 1000 iterations, the ring
//! period still climbing 349 → 451 turns at 3545). The scaling keeps `a ≥ 0` and
//! `curl ω = 0`, costs a few energy evaluations, and moves that mode in one go: 13 / 14
//! iterations there, 77 / 76 → 14 / 15 on the thick cylinders, the other scenes' answers
//! unchanged (docs/design-notes.md, "Wrinkle SQP").
//! `Bᵀ H B` keeps one sparsity pattern (held entries are stored as zeros), so faer's symbolic
//! analysis is done once. Every iterate is `x = B y`, curl-free to rounding by construction.
//! The stationarity residual is the projected gradient in `y` (`∇_y E`, with `min(g, 0)` for
//! amplitudes at 0), relative to its starting value; the other stop tests are those of
//! [`crate::tfw::sqp`].

use crate::report::{Progress, ProgressFn};
use crate::solve::{
    dot_n, steihaug, sym_matvec_lower_into, AssemblyPlan, CholeskyAnalysis, Entry, Parallelism,
};
use crate::tfw::energy::{HessianMode, WfEval, WfTerms};
use crate::tfw::sqp::{
    feasible_start, qp_shape, rescue_weights, step_sizes, CgRefinement, FeasibleStart,
    SqpIteration, SqpOptions, SqpProblem, SqpResult, SqpStatus, RESCUE_SHIFT,
};
use crate::{Error, Result};
use std::collections::VecDeque;
use std::time::Instant;

const NONE: usize = usize::MAX;

/// Hessian entries `(row, col, value)`, `row ≥ col`, as [`WfEval::hessian`].
type HessianEntries = Vec<(usize, usize, f64)>;

/// `y ↦ (x, E(x))` with `x` the full `[a | ω]` of the reduced unknowns `y`.
type EnergyOfY<'a> = dyn Fn(&[f64]) -> (Vec<f64>, f64) + 'a;

/// The map `x_free = B y` from the reduced unknowns `y = (a_free, u, c)` to the free unknowns
/// of an [`SqpProblem`] (module docs).
#[derive(Debug, Clone)]
pub struct CurlFreeBasis {
    /// Free amplitudes (first in both `x_free` and `y`).
    na: usize,
    /// Reduced unknowns.
    ny: usize,
    /// Per free unknown, its row of `B`: `(y index, coefficient)`.
    rows: Vec<Vec<(usize, f64)>>,
    /// Spanning-forest edges in breadth-first order: `(vertex, parent vertex, free edge)`.
    tree: Vec<(usize, usize, usize)>,
    /// Per vertex, its `u` index in `y` (`NONE`: pinned root or not in the complex).
    u_index: Vec<usize>,
    /// The generator edges (free edge indices), one per `c`.
    generator_edges: Vec<usize>,
}

impl CurlFreeBasis {
    /// The tree–cotree basis of `problem`'s curl-free one-forms (module docs).
    pub fn new(problem: &SqpProblem) -> CurlFreeBasis {
        CurlFreeBasis::of_complex(problem.n_free_a, &problem.edge_ends, &problem.curl)
    }

    /// The tree–cotree basis of the one-forms on the edges `ends` (`[tail, head]`) that are
    /// curl-free on the faces `curl` (three `(na + edge, sign)` per face), behind `na`
    /// amplitude unknowns (module docs). [`CurlFreeBasis::new`] is this on an [`SqpProblem`];
    /// the period snapping ([`crate::tfw::snap`]) also runs it on the whole base mesh.
    pub(crate) fn of_complex(
        na: usize,
        ends: &[[usize; 2]],
        curl: &[[(usize, f64); 3]],
    ) -> CurlFreeBasis {
        let ne = ends.len();
        let nv = ends
            .iter()
            .flat_map(|e| e.iter().copied())
            .max()
            .map_or(0, |m| m + 1);
        let Forest {
            tree,
            in_tree,
            roots,
        } = spanning_forest(nv, ends);
        let mut u_index = vec![NONE; nv];
        let mut ny = na;
        let mut in_complex = vec![false; nv];
        for e in ends {
            in_complex[e[0]] = true;
            in_complex[e[1]] = true;
        }
        for v in 0..nv {
            if in_complex[v] && !roots[v] {
                u_index[v] = ny;
                ny += 1;
            }
        }
        let (order, parent_edge) = dual_forest(na, curl, ne, &in_tree);
        let mut is_cotree = vec![false; ne];
        for &p in &parent_edge {
            if p != NONE {
                is_cotree[p] = true;
            }
        }
        let generator_edges: Vec<usize> =
            (0..ne).filter(|&j| !in_tree[j] && !is_cotree[j]).collect();
        let mut rows: Vec<Vec<(usize, f64)>> = (0..na).map(|k| vec![(k, 1.0)]).collect();
        rows.extend(ends.iter().map(|&[t, h]| {
            let mut r = Vec::with_capacity(2);
            if u_index[h] != NONE {
                r.push((u_index[h], 1.0));
            }
            if u_index[t] != NONE {
                r.push((u_index[t], -1.0));
            }
            r
        }));
        for &g in &generator_edges {
            let h = generator_form(na, curl, ne, g, &order, &parent_edge);
            for (j, v) in h.into_iter().enumerate() {
                if v != 0.0 {
                    rows[na + j].push((ny, v));
                }
            }
            ny += 1;
        }
        CurlFreeBasis {
            na,
            ny,
            rows,
            tree,
            u_index,
            generator_edges,
        }
    }

    /// Number of reduced unknowns `y`.
    pub fn dimension(&self) -> usize {
        self.ny
    }

    /// Number of cohomology generators (closed, non-exact basis forms).
    pub fn generators(&self) -> usize {
        self.generator_edges.len()
    }

    /// The periods `∮_γg ω` of a curl-free `x_free` (as [`CurlFreeBasis::y_of`]) around the
    /// generator cycles, one per generator: cycle `γg` runs along its generator edge (tail →
    /// head, pleat's orientation) and back through the spanning forest. The basis form `h_g`
    /// has period 1 on `γg` and 0 on the others (it is 1 on its own generator edge and 0 on the
    /// forest and the other generator edges), so these are `y`'s `c` part.
    pub fn periods(&self, x_free: &[f64]) -> Vec<f64> {
        let y = self.y_of(x_free);
        y[self.ny - self.generator_edges.len()..].to_vec()
    }

    /// The basis form `h_g` of generator `g` over the free unknowns (`B e_c(g)`: amplitudes 0,
    /// closed on every curl row, period 1 on `γg`, 0 on the other generator cycles).
    pub fn generator_values(&self, g: usize) -> Vec<f64> {
        let mut y = vec![0.0; self.ny];
        y[self.ny - self.generator_edges.len() + g] = 1.0;
        self.x_of(&y)
    }

    /// Per vertex, the index of its exact-part unknown `u` counted from 0 (`None`: pinned
    /// root of its component, or not in the complex).
    pub(crate) fn exact_unknown(&self, v: usize) -> Option<usize> {
        self.u_index
            .get(v)
            .filter(|&&i| i != NONE)
            .map(|&i| i - self.na)
    }

    /// Number of exact-part unknowns `u` (vertices of the complex minus one root per
    /// component).
    pub(crate) fn exact_unknowns(&self) -> usize {
        self.ny - self.na - self.generator_edges.len()
    }

    /// `x_free = B y`.
    pub fn x_of(&self, y: &[f64]) -> Vec<f64> {
        self.rows
            .iter()
            .map(|r| r.iter().map(|&(i, c)| c * y[i]).sum())
            .collect()
    }

    /// The `y` with `B y = x_free` for a curl-free `x_free` (integrates ω along the tree; the
    /// generator coefficients are ω's residual on the generator edges).
    pub fn y_of(&self, x_free: &[f64]) -> Vec<f64> {
        let na = self.na;
        let mut u = vec![0.0; self.u_index.len()];
        for &(v, parent, j) in &self.tree {
            // ω_j = u_head − u_tail; the row of j says which end v is
            let sign = self.rows[na + j]
                .iter()
                .find(|&&(i, _)| i == self.u_index[v])
                .map_or(1.0, |&(_, c)| c);
            u[v] = u[parent] + sign * x_free[na + j];
        }
        let mut y = vec![0.0; self.ny];
        y[..na].copy_from_slice(&x_free[..na]);
        for (v, &i) in self.u_index.iter().enumerate() {
            if i != NONE {
                y[i] = u[v];
            }
        }
        let first_c = self.ny - self.generator_edges.len();
        for (g, &j) in self.generator_edges.iter().enumerate() {
            let exact: f64 = self.rows[na + j]
                .iter()
                .filter(|&&(i, _)| i < first_c)
                .map(|&(i, c)| c * y[i])
                .sum();
            y[first_c + g] = x_free[na + j] - exact;
        }
        y
    }

    /// `Bᵀ v` for `v` over the free unknowns.
    fn transpose_times(&self, v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.ny];
        for (r, &vk) in self.rows.iter().zip(v) {
            for &(i, c) in r {
                out[i] += c * vk;
            }
        }
        out
    }
}

/// A spanning forest of the vertex graph.
struct Forest {
    /// Tree edges `(vertex, parent, edge)` in breadth-first order.
    tree: Vec<(usize, usize, usize)>,
    /// Per edge, whether it is in the forest.
    in_tree: Vec<bool>,
    /// Per vertex, whether it roots a component.
    roots: Vec<bool>,
}

/// Breadth-first spanning forest of the vertex graph of the free edges, vertices in increasing
/// order.
fn spanning_forest(nv: usize, ends: &[[usize; 2]]) -> Forest {
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); nv];
    for (j, &[t, h]) in ends.iter().enumerate() {
        adj[t].push((h, j));
        adj[h].push((t, j));
    }
    let mut seen = vec![false; nv];
    let mut roots = vec![false; nv];
    let mut in_tree = vec![false; ends.len()];
    let mut tree = Vec::new();
    let mut queue = VecDeque::new();
    for s in 0..nv {
        if seen[s] || adj[s].is_empty() {
            continue;
        }
        seen[s] = true;
        roots[s] = true;
        queue.push_back(s);
        while let Some(v) = queue.pop_front() {
            for &(w, j) in &adj[v] {
                if !seen[w] {
                    seen[w] = true;
                    in_tree[j] = true;
                    tree.push((w, v, j));
                    queue.push_back(w);
                }
            }
        }
    }
    Forest {
        tree,
        in_tree,
        roots,
    }
}

/// Breadth-first spanning forest of the dual graph (curl rows as nodes, non-tree edges as dual
/// edges, one virtual node joined to every boundary edge): `(rows in BFS order, per row its
/// parent edge or NONE for the root of a closed component)`.
fn dual_forest(
    na: usize,
    curl: &[[(usize, f64); 3]],
    ne: usize,
    in_tree: &[bool],
) -> (Vec<usize>, Vec<usize>) {
    let nf = curl.len();
    let mut edge_rows: Vec<Vec<usize>> = vec![Vec::new(); ne];
    for (r, row) in curl.iter().enumerate() {
        for &(k, _) in row {
            edge_rows[k - na].push(r);
        }
    }
    let mut parent = vec![NONE; nf];
    let mut seen = vec![false; nf];
    let mut order = Vec::with_capacity(nf);
    let mut queue = VecDeque::new();
    // the virtual node's neighbours first: boundary edges in edge order
    for (j, rows) in edge_rows.iter().enumerate() {
        if !in_tree[j] && rows.len() == 1 && !seen[rows[0]] {
            seen[rows[0]] = true;
            parent[rows[0]] = j;
            queue.push_back(rows[0]);
        }
    }
    let mut next_root = 0;
    loop {
        while let Some(f) = queue.pop_front() {
            order.push(f);
            for &(k, _) in &curl[f] {
                let j = k - na;
                if in_tree[j] {
                    continue;
                }
                for &g in &edge_rows[j] {
                    if !seen[g] {
                        seen[g] = true;
                        parent[g] = j;
                        queue.push_back(g);
                    }
                }
            }
        }
        while next_root < nf && seen[next_root] {
            next_root += 1;
        }
        if next_root == nf {
            break;
        }
        seen[next_root] = true;
        queue.push_back(next_root);
    }
    (order, parent)
}

/// The closed form of generator edge `g` (module docs): 1 on `g`, cotree values solved from the
/// leaves of the dual forest to its roots.
fn generator_form(
    na: usize,
    curl: &[[(usize, f64); 3]],
    ne: usize,
    g: usize,
    order: &[usize],
    parent_edge: &[usize],
) -> Vec<f64> {
    let mut h = vec![0.0; ne];
    h[g] = 1.0;
    for &f in order.iter().rev() {
        let p = parent_edge[f];
        if p == NONE {
            continue;
        }
        let mut rest = 0.0;
        let mut sp = 0.0;
        for &(k, s) in &curl[f] {
            if k - na == p {
                sp = s;
            } else {
                rest += s * h[k - na];
            }
        }
        h[p] = -rest / sp;
    }
    h
}

/// Values of a reduced matrix in a fixed entry order, with the entries' indices too when
/// `entries` is `Some` (the first assembly, which makes the [`AssemblyPlan`]; later ones
/// only need the values in the same order).
struct ReducedSink {
    values: Vec<f64>,
    entries: Option<Vec<Entry>>,
}

impl ReducedSink {
    /// An empty sink for about `capacity` entries, recording indices when `with_indices`.
    fn new(capacity: usize, with_indices: bool) -> ReducedSink {
        ReducedSink {
            values: Vec::with_capacity(capacity),
            entries: with_indices.then(|| Vec::with_capacity(capacity)),
        }
    }

    fn push(&mut self, row: usize, col: usize, v: f64) {
        self.values.push(v);
        if let Some(e) = &mut self.entries {
            e.push(Entry::new(row, col, v));
        }
    }
}

/// `Bᵀ H B` as lower-triangle entries pushed to `sink` (entries touching a held unknown
/// stored as 0, so the pattern never changes); returns the mean positive diagonal of the
/// unheld unknowns.
fn reduced_hessian(
    problem: &SqpProblem,
    basis: &CurlFreeBasis,
    hessian: &[(usize, usize, f64)],
    held: &[bool],
    sink: &mut ReducedSink,
) -> f64 {
    let mut diag = vec![0.0; basis.ny];
    for &(r, c, v) in hessian {
        let (sr, sc) = (problem.slot[r], problem.slot[c]);
        if sr == NONE || sc == NONE {
            continue;
        }
        let off = r != c;
        for &(i, bi) in &basis.rows[sr] {
            for &(j, bj) in &basis.rows[sc] {
                if !off && i < j {
                    continue;
                }
                let mut w = v * bi * bj;
                if i == j && off {
                    w *= 2.0;
                }
                if held[i] || held[j] {
                    w = 0.0;
                }
                if i == j {
                    diag[i] += w;
                }
                sink.push(i.max(j), i.min(j), w);
            }
        }
    }
    let pos: Vec<f64> = diag.iter().copied().filter(|&d| d > 0.0).collect();
    if pos.is_empty() {
        1.0
    } else {
        pos.iter().sum::<f64>() / pos.len() as f64
    }
}

/// The projected gradient's max norm: `g` on unknowns off the bound, `min(g, 0)` at `a = 0`.
fn projected_gradient_norm(g: &[f64], y: &[f64], na: usize) -> f64 {
    g.iter()
        .enumerate()
        .map(|(i, &gi)| {
            if i < na && y[i] <= 0.0 {
                gi.min(0.0).abs()
            } else {
                gi.abs()
            }
        })
        .fold(0.0, f64::max)
}

/// Runs the SQP by projected Newton (module docs, [`crate::tfw::QpMethod::ProjectedNewton`]) from
/// `x0 = [a | ω]` (made feasible first), whatever `options.qp` says; otherwise as
/// [`crate::tfw::sqp::run_sqp`]. The step is refined on the exact Hessian as
/// `options.cg_refinement` says ([`CgRefinement::DEFAULT`] unless set).
pub fn run_sqp_projected_newton(
    problem: &SqpProblem,
    x0: &[f64],
    options: &SqpOptions,
    progress: &mut ProgressFn<'_>,
) -> Result<SqpResult> {
    run_sqp_projected_newton_with(problem, x0, options, &options.cg_refinement, progress)
}

/// [`run_sqp_projected_newton`] with the step's exact-Hessian refinement given explicitly
/// (`cg.iterations == 0`: the projected step). Same guarantees: every iterate curl-free to
/// rounding, `a ≥ 0`, E non-increasing.
pub fn run_sqp_projected_newton_with(
    problem: &SqpProblem,
    x0: &[f64],
    options: &SqpOptions,
    cg: &CgRefinement,
    progress: &mut ProgressFn<'_>,
) -> Result<SqpResult> {
    match feasible_start(problem, x0)? {
        FeasibleStart::Run { x, eval, start, .. } => {
            run(problem, x, eval, options, cg, progress, start)
        }
        FeasibleStart::Done(r) => Ok(r),
    }
}

/// [`run_sqp_projected_newton`] from the feasible `x` with its evaluation `eval`.
fn run(
    problem: &SqpProblem,
    x: Vec<f64>,
    eval: WfEval,
    options: &SqpOptions,
    cg: &CgRefinement,
    progress: &mut ProgressFn<'_>,
    start: Instant,
) -> Result<SqpResult> {
    let e = problem.energy();
    let na = problem.n_free_a;
    let basis = CurlFreeBasis::new(problem);
    let x_free: Vec<f64> = problem.free.iter().map(|&g| x[g]).collect();
    let mut y = basis.y_of(&x_free);
    let scatter = |y: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; x.len()];
        for (&g, v) in problem.free.iter().zip(basis.x_of(y)) {
            out[g] = v;
        }
        out
    };
    let initial_energy = eval.energy;
    let shape = qp_shape(problem, &eval, initial_energy);
    // W = E₀ / D² = the first iteration's diagonal of H (floored), per free unknown
    let mut weights: Vec<f64> = shape
        .scale
        .iter()
        .map(|d| shape.energy_scale / (d * d))
        .collect();
    let mut rescued_at = None;
    let mut x = scatter(&y);
    let evaluate = |x: &[f64]| -> (WfEval, Option<HessianEntries>) {
        if cg.iterations > 0 {
            let (p, h) = e.evaluate_projected_and_exact(x, WfTerms::ALL);
            (p, Some(h))
        } else {
            (
                e.evaluate(x, WfTerms::ALL, HessianMode::ProjectedPerFace),
                None,
            )
        }
    };
    let (mut eval, mut exact) = evaluate(&x);
    let grad_y = |eval: &WfEval| -> Vec<f64> {
        let g_free: Vec<f64> = problem.free.iter().map(|&g| eval.gradient[g]).collect();
        basis.transpose_times(&g_free)
    };
    let mut g = grad_y(&eval);
    let r0 = projected_gradient_norm(&g, &y, na);
    let mut snapshots = Vec::new();
    if options.snapshot_every > 0 {
        snapshots.push((0, x.clone()));
    }
    let mut state = NewtonState {
        plan: None,
        exact_plan: None,
        analysis: None,
        shift: options.initial_shift,
        last_full: false,
    };
    let mut history = Vec::new();
    let mut qp_seconds = 0.0;
    let mut status = SqpStatus::MaxIterations;
    for it in 0..options.max_iterations {
        if !progress(Progress {
            stage: "tfw wrinkle SQP",
            fraction: it as f64 / options.max_iterations as f64,
        }) {
            return Err(Error::Cancelled);
        }
        if start.elapsed().as_secs_f64() > options.time_limit_seconds {
            status = SqpStatus::TimeLimit;
            break;
        }
        let t0 = Instant::now();
        let held: Vec<bool> = (0..basis.ny)
            .map(|i| i < na && y[i] <= 0.0 && g[i] > 0.0)
            .collect();
        // the step for given weights: the planned one, and the rescue retry below
        let direction = |weights: &[f64], state: &mut NewtonState| {
            newton_direction(
                problem,
                &basis,
                &eval,
                exact.as_deref(),
                cg,
                &g,
                &held,
                weights,
                state,
            )
        };
        let energy_at = |y: &[f64]| {
            let xc = scatter(y);
            let ec = e.energy(&xc, WfTerms::ALL);
            (xc, ec)
        };
        let mut step = direction(&weights, &mut state)?;
        qp_seconds += t0.elapsed().as_secs_f64();
        let mut accepted = None;
        // one rescue per iteration: the step from the first iteration's weights found no
        // decrease, so retry it once with the rescue weights (`rescue_weights`) kept from then on
        for attempt in 0..2 {
            let Some((d, _, _)) = &step else { break };
            accepted = armijo(&y, d, &g, na, eval.energy, options.armijo, &energy_at);
            if accepted.is_some() || attempt == 1 || rescued_at.is_some() {
                break;
            }
            rescued_at = Some(history.len());
            weights = rescue_weights(&weights, na);
            state.shift = state.shift.max(RESCUE_SHIFT);
            let t1 = Instant::now();
            step = direction(&weights, &mut state)?;
            qp_seconds += t1.elapsed().as_secs_f64();
        }
        let Some((_, attempts, cg_iterations)) = step else {
            status = SqpStatus::QpFailed;
            break;
        };
        let Some((yn, xn, en, t)) = accepted else {
            status = SqpStatus::LineSearchFailed;
            break;
        };
        // the valley search near the optimum only (the refinement's gate: a full step at
        // σ ≤ max_shift); from every full step it led the sheared rectangle and the torus to
        // stationary points of higher energy (docs/design-notes.md, "Wrinkle SQP")
        let near = t >= 1.0 && state.shift <= cg.max_shift;
        let (yn, xn, en) = if options.valley_search && near {
            valley_search(&yn, xn, en, na, &energy_at)
        } else {
            (yn, xn, en)
        };
        let (step_norm, scaled_step) = step_sizes(problem, &shape, &x, &xn);
        let de = eval.energy - en;
        y = yn;
        x = xn;
        (eval, exact) = evaluate(&x);
        g = grad_y(&eval);
        let r = projected_gradient_norm(&g, &y, na);
        history.push(SqpIteration {
            energy: en,
            stationarity: r,
            step_norm,
            step_length: t,
            shift: state.shift,
            qp_iterations: attempts,
            cg_iterations: cg_iterations as u32,
            held: held.iter().filter(|&&h| h).count() as u32,
            curl_residual: problem.curl_residual(&x),
            seconds: start.elapsed().as_secs_f64(),
        });
        if options.snapshot_every > 0 && history.len() % options.snapshot_every == 0 {
            snapshots.push((history.len(), x.clone()));
        }
        state.shift = next_shift(state.shift, t);
        state.last_full = t >= 1.0;
        if r <= options.stationarity_tolerance * r0 {
            status = SqpStatus::Stationary;
            break;
        }
        if de.abs() <= options.energy_tolerance * en.abs() {
            status = SqpStatus::EnergyConverged;
            break;
        }
        if scaled_step <= options.step_tolerance {
            status = SqpStatus::StepConverged;
            break;
        }
    }
    Ok(SqpResult {
        x,
        status,
        initial_energy,
        initial_stationarity: r0,
        history,
        qp_seconds,
        seconds: start.elapsed().as_secs_f64(),
        snapshots,
        rescued_at,
    })
}

/// Armijo backtracking along the projected arc `y + t d` (amplitudes `..na` clipped at 0)
/// from the energy `e0`: the first `t = 1, ½, ¼, … ≥ 1e-10` whose energy (`energy_at`: the
/// scattered `x` and `E`) is at most `e0 + c · slope` and at most `e0`; returns the candidate,
/// its `x`, energy and `t`.
fn armijo(
    y: &[f64],
    d: &[f64],
    g: &[f64],
    na: usize,
    e0: f64,
    c: f64,
    energy_at: &EnergyOfY<'_>,
) -> Option<(Vec<f64>, Vec<f64>, f64, f64)> {
    let mut t = 1.0;
    loop {
        let mut cand: Vec<f64> = y.iter().zip(d).map(|(a, b)| a + t * b).collect();
        for v in &mut cand[..na] {
            *v = v.max(0.0);
        }
        let slope: f64 = g
            .iter()
            .zip(cand.iter().zip(y))
            .map(|(gi, (c, o))| gi * (c - o))
            .sum();
        let (xc, ec) = energy_at(&cand);
        if ec <= e0 + c * slope.min(0.0) && ec <= e0 {
            return Some((cand, xc, ec, t));
        }
        t *= 0.5;
        if t < 1e-10 {
            return None;
        }
    }
}

/// The relative shift σ after an accepted step of length `t` (a Levenberg–Marquardt-like
/// schedule): halved after a full step (floor 1e-16), kept after `t = ½`, ×4 after a shorter
/// one (cap 1e2). The clarabel SQP's plain halving let σ fall to 1e-16 while the line search
/// cut the steps to 1/8–1/128 (measured on the 21 × 9 sheet: r/r₀ rose from 1.5e-5 to 1e-2
/// while E stalled, and rounding then sent Y and Y × 10⁴ to points 10 % apart in amplitude).
fn next_shift(shift: f64, t: f64) -> f64 {
    if t >= 1.0 {
        (shift * 0.5).max(1e-16)
    } else if t >= 0.5 {
        shift
    } else {
        (shift * 4.0).min(1e2)
    }
}

/// The valley search (module docs, the uniform-patch balance of the spec's derived test):
/// `E` along `y(s) = (e^{−s} a, e^{s} u, e^{s} c)` (every
/// amplitude divided and ω multiplied by `μ = e^s`, so `a|ω|` and with it the membrane
/// strain `½a²ωωᵀ` of eq. 2.21 stay put while the curvature and bending terms W_s², W_b²,
/// which set the wavelength, change), minimized by at most eight rounds around the current
/// best `s`: samples at `s ± ε` (ε = 1e-3), then the minimum of the parabola through the three
/// points (at most 0.5 away, halved at most thrice until it lowers `E`) or, where `E` is concave in
/// `s`, doubling steps downhill while `E` falls; stops when a round does not lower `E`. Keeps `a ≥
/// 0` and `curl ω = 0` (a scaling of both), returns `(y, x, E)` with `E` never above `energy`.
fn valley_search(
    y: &[f64],
    x: Vec<f64>,
    energy: f64,
    na: usize,
    energy_at: &EnergyOfY<'_>,
) -> (Vec<f64>, Vec<f64>, f64) {
    const EPS: f64 = 1e-3;
    let sample = |s: f64| -> (f64, Vec<f64>, Vec<f64>, f64) {
        let (down, up) = ((-s).exp(), s.exp());
        let ys: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(i, &v)| if i < na { v * down } else { v * up })
            .collect();
        let (xs, es) = energy_at(&ys);
        (s, ys, xs, es)
    };
    let mut best = (0.0, y.to_vec(), x, energy);
    for _ in 0..8 {
        let c = best.0;
        let (l, r) = (sample(c - EPS), sample(c + EPS));
        let curvature = (l.3 + r.3 - 2.0 * best.3) / (EPS * EPS);
        let slope = (r.3 - l.3) / (2.0 * EPS);
        let before = best.3;
        let downhill = if r.3 < l.3 { 1.0 } else { -1.0 };
        for cand in [l, r] {
            if cand.3 < best.3 {
                best = cand;
            }
        }
        if curvature > 0.0 {
            // the parabola's minimum (at most 0.5 away), halved (at most thrice) until it
            // lowers E
            let mut p = (-slope / curvature).clamp(-0.5, 0.5);
            for _ in 0..4 {
                let cand = sample(c + p);
                if cand.3 < best.3 {
                    best = cand;
                    break;
                }
                p *= 0.5;
            }
        } else if best.3 < before {
            // concave here: doubling steps downhill while E falls (at most 0.5 away)
            let mut h = 2.0 * EPS;
            while h <= 0.5 {
                let cand = sample(c + downhill * h);
                if cand.3 >= best.3 {
                    break;
                }
                best = cand;
                h *= 2.0;
            }
        }
        if best.3 >= before {
            break;
        }
    }
    (best.1, best.2, best.3)
}

/// Steihaug–Toint CG on `h` (exact reduced Hessian, lower triangle) with the right-hand side
/// `rhs = −g` (0 on held unknowns) preconditioned by `precond` (`M⁻¹`), region
/// `cg.radius · ‖d₀‖_M` where `d₀ = M⁻¹ rhs` is the projected step; returns the step and the
/// CG iterations. Its first CG iterate is `d₀` at its exact-model best length.
fn refine_by_cg(
    h: &crate::solve::SparseMatrix,
    precond: &dyn Fn(&[f64]) -> Vec<f64>,
    rhs: &[f64],
    d0: &[f64],
    cg: &CgRefinement,
) -> (Vec<f64>, usize) {
    let g: Vec<f64> = rhs.iter().map(|v| -v).collect();
    let m_norm0 = dot_n(rhs, d0).max(0.0).sqrt(); // ‖d₀‖_M² = d₀ᵀ M d₀ = −gᵀd₀
    let hess = |v: &[f64], y: &mut [f64]| sym_matvec_lower_into(h, v, y);
    let gnorm = dot_n(&g, &g).sqrt();
    let st = steihaug(
        &g,
        &hess,
        precond,
        cg.radius * m_norm0,
        cg.tolerance * gnorm,
        cg.iterations,
    );
    (st.step, st.iterations)
}

/// What the Newton steps carry over: the assembly plan and the symbolic analysis of the
/// reduced matrix (its entries keep one pattern and order: held unknowns enter as zeros), and
/// the relative shift σ.
struct NewtonState {
    plan: Option<AssemblyPlan>,
    /// The plan of the exact reduced Hessian (CG refinement only).
    exact_plan: Option<AssemblyPlan>,
    analysis: Option<CholeskyAnalysis>,
    shift: f64,
    /// The last accepted step was full (`t = 1`).
    last_full: bool,
}

/// The projected Newton direction in `y` (held unknowns: 0) and the factorizations tried, or
/// `None` when the factorization fails even with a relative shift above 1e4 (doubled per
/// failure, as the clarabel QP's). The symbolic analysis is made on the first call and reused.
#[allow(clippy::too_many_arguments)]
fn newton_direction(
    problem: &SqpProblem,
    basis: &CurlFreeBasis,
    eval: &WfEval,
    exact: Option<&[(usize, usize, f64)]>,
    cg: &CgRefinement,
    g: &[f64],
    held: &[bool],
    weights: &[f64],
    state: &mut NewtonState,
) -> Result<Option<(Vec<f64>, u32, usize)>> {
    let NewtonState {
        plan,
        exact_plan,
        analysis,
        shift,
        last_full,
    } = state;
    let ny = basis.ny;
    let capacity = 4 * eval.hessian.len() + 2 * ny;
    let mut sink = ReducedSink::new(capacity, plan.is_none());
    let mean = reduced_hessian(problem, basis, &eval.hessian, held, &mut sink);
    // the shift σ Bᵀ W B (W = the first iteration's diagonal of H: the clarabel QP's σ I in
    // its scaled variables), then one diagonal entry per unknown for the held ones
    let first_shift = sink.values.len();
    let mut shift_base = Vec::new();
    for (row, &w) in basis.rows.iter().zip(weights) {
        for &(i, bi) in row {
            for &(j, bj) in row {
                if i >= j {
                    let v = if held[i] || held[j] { 0.0 } else { w * bi * bj };
                    sink.push(i, j, 0.0);
                    shift_base.push(v);
                }
            }
        }
    }
    for (i, &h) in held.iter().enumerate() {
        sink.push(i, i, if h { mean } else { 0.0 });
    }
    let rhs: Vec<f64> = g
        .iter()
        .zip(held)
        .map(|(&gi, &h)| if h { 0.0 } else { -gi })
        .collect();
    if let Some(entries) = &sink.entries {
        *plan = Some(AssemblyPlan::new(ny, entries, "tfw projected Newton")?);
    }
    let plan = plan.as_ref().expect("made above");
    let mut values = sink.values;
    let mut attempts = 0;
    loop {
        attempts += 1;
        for (v, &b) in values[first_shift..].iter_mut().zip(&shift_base) {
            *v = *shift * b;
        }
        let h = plan.assemble(&values)?;
        if analysis.is_none() {
            *analysis = Some(CholeskyAnalysis::new(&h)?);
        }
        let an = analysis.as_ref().expect("analysed above");
        if let Ok(chol) = an.factor(&h, Parallelism::Global) {
            let d = chol.solve(&rhs);
            if d.iter().all(|v| v.is_finite()) {
                let near = *last_full && *shift <= cg.max_shift;
                let refine = cg.iterations > 0 && (!cg.after_full_step || near);
                let Some(exact) = exact.filter(|_| refine) else {
                    return Ok(Some((d, attempts, 0)));
                };
                let mut xe = ReducedSink::new(capacity, exact_plan.is_none());
                reduced_hessian(problem, basis, exact, held, &mut xe);
                for (i, &h) in held.iter().enumerate() {
                    xe.push(i, i, if h { mean } else { 0.0 });
                }
                if let Some(entries) = &xe.entries {
                    *exact_plan =
                        Some(AssemblyPlan::new(ny, entries, "tfw exact reduced Hessian")?);
                }
                let hx = exact_plan
                    .as_ref()
                    .expect("made above")
                    .assemble(&xe.values)?;
                let (s, its) = refine_by_cg(&hx, &|r| chol.solve(r), &rhs, &d, cg);
                if s.iter().all(|v| v.is_finite()) {
                    return Ok(Some((s, attempts, its)));
                }
                return Ok(Some((d, attempts, its)));
            }
        }
        *shift *= 2.0;
        if *shift > 1e4 {
            return Ok(None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The valley search on `E = (a c − 1)² + 10⁻⁴ (c/a − 4)²` (one amplitude `a`, one
    /// one-form unknown `c`; the wrinkle energy's shape: stiff in the product, soft in the
    /// ratio) from `(1, 1)`: it keeps `a c` exactly, moves to the ratio's minimum `c/a = 4`
    /// (`μ = 2`), and never raises `E`.
    #[test]
    fn valley_search_finds_the_ratio_at_fixed_product() {
        let energy = |y: &[f64]| (y[0] * y[1] - 1.0).powi(2) + 1e-4 * (y[1] / y[0] - 4.0).powi(2);
        let y0 = [1.0, 1.0];
        let e0 = energy(&y0);
        let (y, x, e) = valley_search(&y0, y0.to_vec(), e0, 1, &|y| (y.to_vec(), energy(y)));
        assert_eq!(x, y);
        assert!(e < e0 && (e - energy(&y)).abs() == 0.0);
        assert!((y[0] * y[1] - 1.0).abs() < 1e-14, "product {}", y[0] * y[1]);
        assert!((y[1] / y[0] - 4.0).abs() < 1e-3, "ratio {}", y[1] / y[0]);
        // at the minimum it stays put
        let (y2, _, e2) = valley_search(&y, y.clone(), e, 1, &|y| (y.to_vec(), energy(y)));
        assert!(e2 <= e && (y2[1] / y2[0] - 4.0).abs() < 1e-3);
    }

    /// The exact-Hessian refinement (default gating) keeps the SQP's invariants on a
    /// compressed annulus (curl ≤ 1e-10, a ≥ 0, E non-increasing) and reaches a stationary
    /// point of the same energy as the projected step.
    #[test]
    fn cg_refinement_keeps_the_invariants() {
        let n = 12;
        let mut p = Vec::new();
        for r in [1.0, 1.5, 2.0] {
            for k in 0..n {
                let th = std::f64::consts::TAU * k as f64 / n as f64;
                p.push([r * th.cos(), r * th.sin(), 0.0]);
            }
        }
        let mut t = Vec::new();
        for ring in 0..2u32 {
            let o = ring * n as u32;
            for k in 0..n as u32 {
                let k1 = (k + 1) % n as u32;
                t.push([o + k, o + k1, o + k1 + n as u32]);
                t.push([o + k, o + k1 + n as u32, o + k + n as u32]);
            }
        }
        let mesh = crate::mesh::TriMesh::new(p, t).unwrap();
        let nv = mesh.vertex_count();
        let nf = mesh.triangle_count();
        let kappa = vec![0.5; nf];
        // rest forms: each face's current form lengthened along its first edge and shortened
        // along its second (compressed along one direction, stretched along the other)
        let forms: Vec<[f64; 3]> = mesh
            .triangles()
            .iter()
            .map(|t| {
                let q = t.map(|v| mesh.positions()[v as usize]);
                let e1 = [q[1][0] - q[0][0], q[1][1] - q[0][1], 0.0];
                let e2 = [q[2][0] - q[0][0], q[2][1] - q[0][1], 0.0];
                let d = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1];
                [1.1 * d(e1, e1), d(e1, e2), 0.95 * d(e2, e2)]
            })
            .collect();
        let strains = crate::tfw::wfree::face_strains(&forms, &mesh);
        let energy = crate::tfw::energy::WrinkleEnergy::new(
            &mesh,
            &forms,
            &strains,
            &kappa,
            crate::tfw::Lame {
                alpha: 1.0,
                beta: 1.0,
            },
            1e-2,
        );
        let problem = SqpProblem::new(energy, &mesh, &vec![false; nf], &vec![false; nv]);
        let ne = mesh.edges().edges.len();
        let mut x0 = vec![0.05; nv];
        x0.extend((0..ne).map(|j| 3.0 + 0.1 * ((j * 7) % 5) as f64));
        // the refinement alone (with the valley search, whose gate is the refinement's,
        // `CgRefinement::OFF` searches after every full step: it found a lower stationary point
        // here, 3.6839e-4 against 3.6847e-4, so the two are compared without it; the default
        // with it is checked below)
        let options = SqpOptions {
            max_iterations: 200,
            valley_search: false,
            ..SqpOptions::default()
        };
        // the default (near the optimum only): refining every step from the start
        // (`..CgRefinement::OFF` with 50 iterations) jumped to a ≡ 0 here in one step, a
        // stationary point with twice the energy (docs/design-notes.md)
        let cg = CgRefinement::DEFAULT;
        let plain =
            run_sqp_projected_newton_with(&problem, &x0, &options, &CgRefinement::OFF, &mut |_| {
                true
            })
            .unwrap();
        let refined =
            run_sqp_projected_newton_with(&problem, &x0, &options, &cg, &mut |_| true).unwrap();
        let default = SqpOptions {
            valley_search: true,
            ..options
        };
        let valley =
            run_sqp_projected_newton_with(&problem, &x0, &default, &cg, &mut |_| true).unwrap();
        assert!(refined.history.iter().any(|h| h.cg_iterations > 0));
        for r in [&plain, &refined, &valley] {
            let mut last = r.initial_energy;
            for h in &r.history {
                assert!(h.energy <= last, "E rose: {} > {last}", h.energy);
                assert!(h.curl_residual <= 1e-10, "curl {}", h.curl_residual);
                last = h.energy;
            }
            assert!(r.x[..nv].iter().all(|&a| a >= 0.0));
        }
        let (ep, er) = (
            plain.history.last().unwrap().energy,
            refined.history.last().unwrap().energy,
        );
        eprintln!(
            "plain {:?} {} it E {ep:e}; refined {:?} {} it E {er:e}",
            plain.status,
            plain.history.len(),
            refined.status,
            refined.history.len()
        );
        assert!(
            (ep - er).abs() <= 1e-6 * ep.abs().max(1e-30) + 1e-12,
            "{ep} vs {er}"
        );
        let ev = valley.history.last().unwrap().energy;
        assert!(valley.status.converged(), "{:?}", valley.status);
        assert!(ev <= er * (1.0 + 1e-6), "valley search {ev} vs {er}");
    }

    /// A 3 × 3-vertex grid has a disk complex (no generator); removing nothing, the basis
    /// reproduces a random curl-free form exactly.
    #[test]
    fn basis_has_the_dimension_of_the_kernel_and_round_trips() {
        // annulus: a ring of 8 quads (16 triangles) between radius 1 and 2
        let n = 8;
        let mut p = Vec::new();
        for r in [1.0, 2.0] {
            for k in 0..n {
                let th = std::f64::consts::TAU * k as f64 / n as f64;
                p.push([r * th.cos(), r * th.sin(), 0.0]);
            }
        }
        let mut t = Vec::new();
        for k in 0..n as u32 {
            let k1 = (k + 1) % n as u32;
            t.push([k, k1, k1 + n as u32]);
            t.push([k, k1 + n as u32, k + n as u32]);
        }
        let mesh = crate::mesh::TriMesh::new(p, t).unwrap();
        let nv = mesh.vertex_count();
        let nf = mesh.triangle_count();
        let zeros = vec![0.0; nf];
        let forms: Vec<[f64; 3]> = vec![[1.0, 0.0, 1.0]; nf];
        let strains = crate::tfw::wfree::face_strains(&forms, &mesh);
        let energy = crate::tfw::energy::WrinkleEnergy::new(
            &mesh,
            &forms,
            &strains,
            &zeros,
            crate::tfw::Lame {
                alpha: 1.0,
                beta: 1.0,
            },
            1e-3,
        );
        let problem = SqpProblem::new(energy, &mesh, &vec![false; nf], &vec![false; nv]);
        let basis = CurlFreeBasis::new(&problem);
        // annulus: one generator; y = a (16) + u (16 − 1) + c (1)
        assert_eq!(basis.generators(), 1);
        assert_eq!(basis.dimension(), nv + nv - 1 + 1);
        // B y is curl-free for any y, and y_of inverts it
        let y: Vec<f64> = (0..basis.dimension())
            .map(|i| ((i * 7919) % 113) as f64 / 50.0 - 1.0)
            .collect();
        let xf = basis.x_of(&y);
        let mut x = vec![0.0; nv + mesh.edges().edges.len()];
        for (&g, v) in problem.free.iter().zip(&xf) {
            x[g] = *v;
        }
        assert!(problem.curl_residual(&x) < 1e-12);
        let back = basis.y_of(&xf);
        for (a, b) in y.iter().zip(&back) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }
}
