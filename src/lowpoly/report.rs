//! Typed reports of the LOD capability: [`LodReport`] (one LOD or cage level, from
//! [`super::generate`] and `crate::cage::generate`) and [`OffsetReport`] (from
//! [`super::offset_surface`]). Every field states its unit; each report's `entries()` is the
//! one place naming its entries for the JSON report and the generic C `PleatStats`.

use std::borrow::Cow;

use crate::report::{Guarantees, Stage, StageTimes, StatEntries};

/// A timed stage of a LOD or cage bake.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LodStage {
    /// The offset surface (or, in a chain, copying the finer level) (`offset`).
    Offset,
    /// Guarded QEM collapses, all rounds (`simplify`).
    Simplify,
    /// Flow toward the input, all rounds (`flow`).
    Flow,
    /// Feature alignment, all rounds (`align`).
    Align,
    /// Convergence tests between rounds (`convergence`).
    Convergence,
    /// Independent verification, including an exact rerun if one was needed (`verify`).
    Verify,
    /// Hausdorff measurement (`measure`).
    Measure,
    /// Measurement of the error floor, only with `LodParams::measure_floor` (`floor`).
    Floor,
    /// Cages: exact measurement of the clearance (`clearance`).
    Clearance,
    /// LODs: the final input-plane fit and its safety check (`fit`).
    Fit,
}

impl Stage for LodStage {
    fn name(&self) -> Cow<'static, str> {
        Cow::Borrowed(match self {
            LodStage::Offset => "offset",
            LodStage::Simplify => "simplify",
            LodStage::Flow => "flow",
            LodStage::Align => "align",
            LodStage::Convergence => "convergence",
            LodStage::Verify => "verify",
            LodStage::Measure => "measure",
            LodStage::Floor => "floor",
            LodStage::Clearance => "clearance",
            LodStage::Fit => "fit",
        })
    }
}

/// Edge-collapse counters of the simplification (Alg. 5), summed over rounds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SimplifyCounts {
    /// Collapses done.
    pub collapses: u64,
    /// Collapse candidates evaluated.
    pub candidates: u64,
    /// Rejected: a face would fold over.
    pub rejected_fold: u64,
    /// Rejected: the one-sided Hausdorff bound `d` would be exceeded.
    pub rejected_hausdorff: u64,
    /// Rejected: the new vertex would be too far from the input.
    pub rejected_distance: u64,
    /// Rejected by the guard (topology, intersections, cage contact).
    pub rejected_guard: u64,
    /// Rejected: an edge would span more change of the input's deformation (skin weights,
    /// morph displacements) than `LodParams::deformation` allows.
    pub rejected_deformation: u64,
    /// Collapses re-checked after a neighbour changed.
    pub rechecked: u64,
}

impl SimplifyCounts {
    /// Adds `o`'s counters to these.
    pub fn add(&mut self, o: &SimplifyCounts) {
        self.collapses += o.collapses;
        self.candidates += o.candidates;
        self.rejected_fold += o.rejected_fold;
        self.rejected_hausdorff += o.rejected_hausdorff;
        self.rejected_distance += o.rejected_distance;
        self.rejected_guard += o.rejected_guard;
        self.rejected_deformation += o.rejected_deformation;
        self.rechecked += o.rechecked;
    }
}

/// Counters of the guard of local operations, summed over rounds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GuardCounts {
    /// Operations checked.
    pub checks: u64,
    /// Operations accepted.
    pub accepted: u64,
    /// Rejected: would break manifoldness or change topology.
    pub rejected_topology: u64,
    /// Rejected: would create a degenerate face.
    pub rejected_degenerate: u64,
    /// Rejected: would create a self-intersection.
    pub rejected_intersection: u64,
    /// Rejected (cage): would touch the input.
    pub rejected_touch: u64,
    /// Rejected (cage): an input vertex would leave the cage.
    pub rejected_uncover: u64,
    /// Rejected (cage with clearance): a face would come closer to the input than the
    /// clearance.
    pub rejected_clearance: u64,
    /// Rejected (LOD with a self-clearance, the input-plane fit): a face would come closer to
    /// a face sharing no vertex with it than the self-clearance.
    pub rejected_self_clearance: u64,
    /// Patches whose normal cone allowed skipping the shared-vertex pairs.
    pub cone_fast_path: u64,
    /// Exact triangle–triangle tests run.
    pub exact_tests: u64,
}

impl GuardCounts {
    /// Adds `o`'s counters to these.
    pub fn add(&mut self, o: &GuardCounts) {
        self.checks += o.checks;
        self.accepted += o.accepted;
        self.rejected_topology += o.rejected_topology;
        self.rejected_degenerate += o.rejected_degenerate;
        self.rejected_intersection += o.rejected_intersection;
        self.rejected_touch += o.rejected_touch;
        self.rejected_uncover += o.rejected_uncover;
        self.rejected_clearance += o.rejected_clearance;
        self.rejected_self_clearance += o.rejected_self_clearance;
        self.cone_fast_path += o.cone_fast_path;
        self.exact_tests += o.exact_tests;
    }
}

/// The error floor set by the offset stage (measured only with `LodParams::measure_floor`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorMeasure {
    /// One-sided sampled distance from the input to the offset surface, over the input's
    /// bounding-box diagonal `l` (dimensionless): no later step can lower the input-to-output
    /// error below it.
    pub rel: f64,
    /// CPU seconds (all threads) of that measurement.
    pub cpu_seconds: f64,
}

/// A cage's clearance: required and measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClearanceMeasure {
    /// The clearance the guard kept, in model units (`LodParams::clearance` resolved).
    pub required: f64,
    /// The exact minimum distance between output and input triangles, in model units,
    /// measured by `crate::verify` (`CageInput::min_distance`, no samples).
    pub min: f64,
    /// `min / l` (dimensionless).
    pub min_rel: f64,
    /// `min ≥ required` (and `min > 0`). False only when the start surface was already closer
    /// than the clearance somewhere (the guard never lowers a patch's distance below the
    /// clearance, nor below what it was): the cage then still encloses without contact but
    /// does not keep the requested clearance — a larger screen size or smaller clearance does.
    pub kept: bool,
}

/// What one LOD (or cage) level of [`super::generate`] / [`super::generate_chain`] /
/// `crate::cage::generate` measured and verified.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LodReport {
    /// Wall seconds per stage, in execution order (`offset`, `simplify`, `flow`, `align`,
    /// `convergence`, `fit`, `verify`, `measure`, then `floor` when measured).
    pub stages: StageTimes<LodStage>,
    /// Offset distance `d = l / n_p` (model units).
    pub d: f64,
    /// Largest distance of an offset-surface vertex from the `d`-iso-surface, over `d`
    /// (dimensionless), measured by the offset stage's verification, which only cages run
    /// (a LOD's output is verified at the end instead); `None` for LODs and in a chain level
    /// started from the finer level.
    pub offset_max_deviation_over_d: Option<f64>,
    /// The offset stage's voxel edge over the offset's default `d/√3` when not 1: for a LOD at
    /// `n_p ≥ lowpoly::LOD_COARSE_VOXEL_MIN_SCREEN_SIZE`, `lowpoly::LOD_VOXEL_SCALE` (2), at
    /// `n_p ≥ lowpoly::LOD_MEDIUM_VOXEL_MIN_SCREEN_SIZE`, `lowpoly::LOD_MEDIUM_VOXEL_SCALE` (1.25), or a
    /// coarser scale of `lowpoly::LOD_VOXEL_SCALES` when the memory budget needs one; `None` for cages (always 1) and in a chain level started
    /// from the finer level.
    pub offset_voxel_scale: Option<f64>,
    /// Set when the bake was admitted by measurement: the up-front memory estimate fitted no voxel
    /// scale, so the offset stage counted its surface before allocating it and the budget was
    /// checked against the peak estimated from those counts (the larger of the offset stage's and
    /// the loop's/fit's, in bytes). `None` otherwise.
    pub measured_estimate_bytes: Option<f64>,
    /// Faces of the start surface (offset surface, the welded input, or the finer level in a
    /// chain).
    pub faces_offset: u64,
    /// Rounds of Alg. 3 run.
    pub rounds: u64,
    /// Faces after each round, in order.
    pub faces_per_round: Vec<u64>,
    /// Simplification counters.
    pub simplify: SimplifyCounts,
    /// Guard counters.
    pub guard: GuardCounts,
    /// A face target was given and met.
    pub target_met: bool,
    /// Times the per-collapse bound was doubled to reach the face target.
    pub target_relaxations: u64,
    /// The last round's convergence test passed (change below `ε·l`).
    pub converged: bool,
    /// The loop ended because [`crate::lowpoly::STALL_ROUNDS`] rounds in a row made no new
    /// smallest face count (LODs without a face target).
    pub stalled: bool,
    /// Wall seconds of the first simplification pass (on the dense start surface).
    pub simplify_first_pass_seconds: f64,
    /// Total vertex motion of the flow steps (model units, summed over vertices and rounds).
    pub flow_motion: f64,
    /// Total vertex motion of the alignment steps (model units, summed).
    pub align_motion: f64,
    /// Vertex moves of the input-plane fit (`LodParams::fit_to_input`).
    pub fit_moves: u64,
    /// Edge flips of the input-plane fit.
    pub fit_flips: u64,
    /// Total vertex motion of the fit (model units).
    pub fit_motion: f64,
    /// Fit operations (line-search trials and flips) refused because they would have left an
    /// input sample farther from the LOD than its budget (`lowpoly/coverage.rs`).
    pub fit_uncovering_refused: u64,
    /// The fit was reverted because the Hausdorff distance grew (the output is the loop's).
    pub fit_reverted: bool,
    /// The fitted LOD's one-sided Hausdorff distances over `l`, `[in→out, out→in]`, whether
    /// it was kept or reverted (`None` without a fit).
    pub fit_sides_rel: Option<[f64; 2]>,
    /// Reruns with exact checks only (0 or 1; §4.3.3: the normal-cone shortcut let an
    /// intersection through).
    pub reruns_exact: u64,
    /// The error floor, when measured.
    pub floor: Option<FloorMeasure>,
    /// Cages: the required and the measured clearance; `None` for LODs.
    pub clearance: Option<ClearanceMeasure>,
    /// Two-sided sampled Hausdorff distance between output and input (model units;
    /// `crate::verify::hausdorff_to_input`).
    pub hausdorff: f64,
    /// `hausdorff / l` (dimensionless).
    pub hausdorff_rel: f64,
    /// Input-to-output part of the Hausdorff distance, over `l` (dimensionless).
    pub hausdorff_in_to_out_rel: f64,
    /// Output-to-input part of the Hausdorff distance, over `l` (dimensionless).
    pub hausdorff_out_to_in_rel: f64,
    /// Output triangles.
    pub faces: u64,
    /// Output vertices.
    pub vertices: u64,
    /// Rank of this level in a chain, 0 = finest (baked first); `None` outside a chain.
    pub chain_level: Option<u64>,
    /// The loop started from the welded input (`LodParams::start`) instead of
    /// the offset surface (in a chain: this level is the finest and started from the input).
    pub started_from_input: bool,
    /// In a chain, a coarser level that started from the next finer level's loop output before
    /// its fit (same topology as its own offset surface) rather than from its own offset
    /// surface.
    pub started_from_finer: bool,
    /// Guarantees verified afterwards by `crate::verify`: watertight, manifold (and
    /// consistently oriented), self-intersection-free, same topology as the offset surface,
    /// and for cages enclosure without contact.
    pub verified: Guarantees,
}

impl LodReport {
    /// Total wall seconds over all stages.
    pub fn total_seconds(&self) -> f64 {
        self.stages.total()
    }

    /// The report as named entries (JSON report, verbose CLI output), in pleat's documented
    /// order. The only place the entry names are written.
    pub fn entries(&self) -> StatEntries {
        let mut e = StatEntries::default();
        self.stages.write_entries(&mut e);
        e.metric_entry("d", self.d);
        if let Some(dev) = self.offset_max_deviation_over_d {
            e.metric_entry("offset_max_deviation_over_d", dev);
        }
        if let Some(s) = self.offset_voxel_scale {
            e.metric_entry("offset_voxel_scale", s);
        }
        if let Some(b) = self.measured_estimate_bytes {
            e.metric_entry("measured_estimate_bytes", b);
        }
        e.count_entry("faces_offset", self.faces_offset);
        e.count_entry("started_from_input", self.started_from_input as u64);
        if self.chain_level.is_some_and(|l| l > 0) {
            e.count_entry("started_from_finer", self.started_from_finer as u64);
        }
        e.metric_entry("simplify_first_pass_s", self.simplify_first_pass_seconds);
        e.count_entry("rounds", self.rounds);
        for (i, f) in self.faces_per_round.iter().enumerate() {
            e.count_entry(format!("faces_round_{}", i + 1), *f);
        }
        let s = &self.simplify;
        e.count_entry("collapses", s.collapses);
        e.count_entry("collapse_candidates", s.candidates);
        e.count_entry("rejected_fold", s.rejected_fold);
        e.count_entry("rejected_hausdorff", s.rejected_hausdorff);
        e.count_entry("rejected_distance", s.rejected_distance);
        e.count_entry("rejected_guard", s.rejected_guard);
        if s.rejected_deformation > 0 {
            e.count_entry("rejected_deformation", s.rejected_deformation);
        }
        e.count_entry("collapses_rechecked", s.rechecked);
        let g = &self.guard;
        e.count_entry("guard_checks", g.checks);
        e.count_entry("guard_rejected_topology", g.rejected_topology);
        e.count_entry("guard_rejected_degenerate", g.rejected_degenerate);
        e.count_entry("guard_rejected_intersection", g.rejected_intersection);
        e.count_entry("guard_rejected_touch", g.rejected_touch);
        e.count_entry("guard_rejected_uncover", g.rejected_uncover);
        if self.clearance.is_some() {
            e.count_entry("guard_rejected_clearance", g.rejected_clearance);
        }
        e.count_entry("guard_rejected_self_clearance", g.rejected_self_clearance);
        e.count_entry("guard_cone_fast_path", g.cone_fast_path);
        e.count_entry("guard_exact_tests", g.exact_tests);
        e.count_entry("target_met", self.target_met as u64);
        e.count_entry("target_relaxations", self.target_relaxations);
        e.count_entry("converged", self.converged as u64);
        e.count_entry("stalled", self.stalled as u64);
        e.metric_entry("flow_motion", self.flow_motion);
        e.metric_entry("align_motion", self.align_motion);
        e.count_entry("fit_moves", self.fit_moves);
        e.count_entry("fit_flips", self.fit_flips);
        e.metric_entry("fit_motion", self.fit_motion);
        e.count_entry("fit_uncovering_refused", self.fit_uncovering_refused);
        e.count_entry("fit_reverted", self.fit_reverted as u64);
        if let Some([i, o]) = self.fit_sides_rel {
            e.metric_entry("fit_in_to_out_rel", i);
            e.metric_entry("fit_out_to_in_rel", o);
        }
        e.count_entry("reruns_exact", self.reruns_exact);
        self.verified.write_entries(&mut e);
        if let Some(f) = &self.floor {
            e.metric_entry("hausdorff_floor_rel", f.rel);
            e.metric_entry("floor_cpu_seconds", f.cpu_seconds);
        }
        if let Some(c) = &self.clearance {
            e.metric_entry("clearance_required", c.required);
            e.metric_entry("min_clearance", c.min);
            e.metric_entry("min_clearance_rel", c.min_rel);
            e.count_entry("clearance_kept", c.kept as u64);
        }
        e.metric_entry("hausdorff", self.hausdorff);
        e.metric_entry("hausdorff_rel", self.hausdorff_rel);
        e.metric_entry("hausdorff_in_to_out_rel", self.hausdorff_in_to_out_rel);
        e.metric_entry("hausdorff_out_to_in_rel", self.hausdorff_out_to_in_rel);
        e.count_entry("faces", self.faces);
        e.count_entry("vertices", self.vertices);
        if let Some(level) = self.chain_level {
            e.count_entry("chain_level", level);
        }
        e
    }
}

/// A timed stage of the offset surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OffsetStage {
    /// The input's distance structures (`bvh`).
    Bvh,
    /// Bricks of the narrow band (`band`).
    Band,
    /// Exact distances at the band's grid points (`distance`).
    Distance,
    /// MC33 extraction and feature vertices (`extract`).
    Extract,
    /// Interior removal (`interior`).
    Interior,
    /// Assembly of the plain MC33 surface, without features (`assemble`).
    Assemble,
    /// Phase 1: every feature vertex, edge flips (`flips`).
    Flips,
    /// Feature filtering (`filter`).
    Filter,
    /// Phase 2: real feature vertices only, flips again (`flips_filtered`).
    FlipsFiltered,
    /// Independent verification of the output (`verify`).
    Verify,
}

impl Stage for OffsetStage {
    fn name(&self) -> Cow<'static, str> {
        Cow::Borrowed(match self {
            OffsetStage::Bvh => "bvh",
            OffsetStage::Band => "band",
            OffsetStage::Distance => "distance",
            OffsetStage::Extract => "extract",
            OffsetStage::Interior => "interior",
            OffsetStage::Assemble => "assemble",
            OffsetStage::Flips => "flips",
            OffsetStage::Filter => "filter",
            OffsetStage::FlipsFiltered => "flips_filtered",
            OffsetStage::Verify => "verify",
        })
    }
}

/// Counts of the MC33 extraction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ExtractionCounts {
    /// Cells visited.
    pub cells_visited: u64,
    /// Cells with corners on both sides of the iso-value.
    pub cells_mixed: u64,
    /// Disk-like patches.
    pub patches_disk: u64,
    /// Annulus patches.
    pub patches_annulus: u64,
    /// Feature vertices computed (before filtering).
    pub feature_vertices: u64,
    /// Tunnels split into two patches.
    pub tunnels_split: u64,
    /// Cells whose components could not be separated.
    pub cells_unseparated: u64,
    /// Cells whose MC33 case could not be resolved.
    pub cells_unresolved: u64,
    /// Iso-points (edge crossings).
    pub iso_points: u64,
}

/// Counts of interior removal.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct InteriorCounts {
    /// Components of the template surface.
    pub components: u64,
    /// Components removed as lying inside another.
    pub components_removed: u64,
}

/// Counts of the feature phases (edge flips and feature filtering).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FeatureCounts {
    /// Flip candidates of phase 1.
    pub flip_candidates: u64,
    /// Flips done in phase 1.
    pub flips: u64,
    /// Flips refused for geometric reasons in phase 1.
    pub flips_refused_geometry: u64,
    /// Feature vertices on real feature curves (kept for phase 2).
    pub feature_vertices_kept: u64,
    /// Flips done in phase 2.
    pub flips_filtered: u64,
}

/// Results of the independent verification of an offset surface.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OffsetVerification {
    /// Connected components of the output.
    pub output_components: u64,
    /// Largest `|f(v) − d|` over output vertices `v`, over `d` (dimensionless).
    pub max_deviation_over_d: f64,
}

/// What [`super::offset_surface`] measured and verified.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OffsetReport {
    /// Wall seconds per stage, in execution order.
    pub stages: StageTimes<OffsetStage>,
    /// Offset distance `d` (model units).
    pub d: f64,
    /// Voxel edge `h` (model units).
    pub h: f64,
    /// Bricks of the narrow band.
    pub bricks: u64,
    /// Grid points with a stored distance.
    pub grid_points: u64,
    /// Extraction counts.
    pub extraction: ExtractionCounts,
    /// Interior removal counts (`None` when it was off).
    pub interior: Option<InteriorCounts>,
    /// Feature-phase counts (`None` without feature vertices).
    pub features: Option<FeatureCounts>,
    /// Output vertices.
    pub output_vertices: u64,
    /// Output triangles.
    pub output_triangles: u64,
    /// Estimated peak bytes of the largest stores (the benchmark's VmHWM is the measurement).
    pub peak_memory_bytes: u64,
    /// Verification results (`None` when verification was off).
    pub verification: Option<OffsetVerification>,
    /// Guarantees verified by `crate::verify` (empty when verification was off): watertight,
    /// manifold, consistently oriented, self-intersection-free, vertices within `h`.
    pub verified: Guarantees,
}

impl OffsetReport {
    /// Total wall seconds over all stages.
    pub fn total_seconds(&self) -> f64 {
        self.stages.total()
    }

    /// The report as named entries (the generic C `PleatStats` and `pleat offset
    /// --stats-json`), in pleat's documented order. The only place the entry names are
    /// written.
    pub fn entries(&self) -> StatEntries {
        let mut e = StatEntries::default();
        self.stages.write_entries(&mut e);
        e.metric_entry("d", self.d);
        e.metric_entry("h", self.h);
        e.count_entry("bricks", self.bricks);
        e.count_entry("grid_points", self.grid_points);
        let x = &self.extraction;
        e.count_entry("cells_visited", x.cells_visited);
        e.count_entry("cells_mixed", x.cells_mixed);
        e.count_entry("patches_disk", x.patches_disk);
        e.count_entry("patches_annulus", x.patches_annulus);
        e.count_entry("feature_vertices", x.feature_vertices);
        e.count_entry("tunnels_split", x.tunnels_split);
        e.count_entry("cells_unseparated", x.cells_unseparated);
        e.count_entry("cells_unresolved", x.cells_unresolved);
        e.count_entry("iso_points", x.iso_points);
        if let Some(i) = &self.interior {
            e.count_entry("components", i.components);
            e.count_entry("components_removed", i.components_removed);
        }
        if let Some(f) = &self.features {
            e.count_entry("flip_candidates", f.flip_candidates);
            e.count_entry("flips", f.flips);
            e.count_entry("flips_refused_geometry", f.flips_refused_geometry);
            e.count_entry("feature_vertices_kept", f.feature_vertices_kept);
            e.count_entry("flips_filtered", f.flips_filtered);
        }
        e.count_entry("output_vertices", self.output_vertices);
        e.count_entry("output_triangles", self.output_triangles);
        e.metric_entry("peak_memory_bytes", self.peak_memory_bytes as f64);
        self.verified.write_entries(&mut e);
        if let Some(v) = &self.verification {
            e.count_entry("output_components", v.output_components);
            e.metric_entry("max_deviation_over_d", v.max_deviation_over_d);
        }
        e
    }
}
