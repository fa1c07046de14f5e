//! Typed reports of the wrinkle capability: [`EvalReport`] (evaluation) and the stage enums of
//! evaluation, interpolation ([`InterpStage`], carried by `InterpReport`) and CWF creation
//! ([`CwfStage`], carried by `KnoppelReport`). Every field states its unit; each report's
//! `entries()` is the one place naming its entries.
//!
//! May import: `crate::report`.

use std::borrow::Cow;

use crate::report::{Stage, StageTimes, StatEntries};

/// The part of one Loop level of an evaluation (see [`EvalStage::Level`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LevelPart {
    /// Refined positions (`positions`).
    Positions,
    /// Refined amplitude (`amplitude`).
    Amplitude,
    /// Per-face cotangent vectors of the one-form (`cotangent vectors`).
    CotangentVectors,
    /// Refined `z` (`z`).
    Z,
    /// Fine triangles only, on the last level (`triangles`).
    Triangles,
    /// Fine topology (`topology`).
    Topology,
    /// Refined one-form (`one-form`).
    OneForm,
}

impl LevelPart {
    fn name(self) -> &'static str {
        match self {
            LevelPart::Positions => "positions",
            LevelPart::Amplitude => "amplitude",
            LevelPart::CotangentVectors => "cotangent vectors",
            LevelPart::Z => "z",
            LevelPart::Triangles => "triangles",
            LevelPart::Topology => "topology",
            LevelPart::OneForm => "one-form",
        }
    }
}

/// A timed stage of a wrinkle evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvalStage {
    /// Base level: rules, corners, amplitude (`setup`).
    Setup,
    /// A part of Loop level `k` (1-based) (`level k: <part>`).
    Level(usize, LevelPart),
    /// Displacement along the normals (`displace`).
    Displace,
}

impl Stage for EvalStage {
    fn name(&self) -> Cow<'static, str> {
        match self {
            EvalStage::Setup => "setup".into(),
            EvalStage::Level(k, part) => format!("level {k}: {}", part.name()).into(),
            EvalStage::Displace => "displace".into(),
        }
    }
}

/// Size and time of one Loop level of an evaluation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LevelReport {
    /// Wall seconds of the whole level.
    pub seconds: f64,
    /// Vertices after the level.
    pub vertices: u64,
    /// Triangles after the level.
    pub faces: u64,
}

/// What `Cwf::evaluate` did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EvalReport {
    /// Wall seconds per stage, in execution order.
    pub stages: StageTimes<EvalStage>,
    /// Per Loop level, in order (level 1 first).
    pub levels: Vec<LevelReport>,
}

impl EvalReport {
    /// Total wall seconds over all stages.
    pub fn total_seconds(&self) -> f64 {
        self.stages.total()
    }

    /// Wall seconds of the subdivision levels (sum of [`LevelReport::seconds`]).
    pub fn subdivision_seconds(&self) -> f64 {
        self.levels.iter().map(|l| l.seconds).sum()
    }

    /// The report as named entries (`level k seconds`, `level k vertices`, `level k faces`).
    pub fn entries(&self) -> StatEntries {
        let mut e = StatEntries::default();
        self.stages.write_entries(&mut e);
        for (i, l) in self.levels.iter().enumerate() {
            let k = i + 1;
            e.metric_entry(format!("level {k} seconds"), l.seconds);
            e.count_entry(format!("level {k} vertices"), l.vertices);
            e.count_entry(format!("level {k} faces"), l.faces);
        }
        e
    }
}

/// A timed stage of keyframe interpolation (`InterpReport::stages`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InterpStage {
    /// Weights, compatible one-forms (`setup`).
    Setup,
    /// The spacetime problem (`assemble`).
    Assemble,
    /// The Newton solve (`solve`).
    Solve,
}

impl Stage for InterpStage {
    fn name(&self) -> Cow<'static, str> {
        Cow::Borrowed(match self {
            InterpStage::Setup => "setup",
            InterpStage::Assemble => "assemble",
            InterpStage::Solve => "solve",
        })
    }
}

/// A timed stage of building a CWF from a one-form (`KnoppelReport::stages`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CwfStage {
    /// Validation of the base mesh and fields (`validate`).
    Validate,
    /// Knöppel's phase solve (`knoppel`).
    Knoppel,
}

impl Stage for CwfStage {
    fn name(&self) -> Cow<'static, str> {
        Cow::Borrowed(match self {
            CwfStage::Validate => "validate",
            CwfStage::Knoppel => "knoppel",
        })
    }
}
