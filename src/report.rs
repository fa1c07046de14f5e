//! Typed reports: what every long operation returns besides its result — wall time per stage,
//! counts, achieved error and which guarantees independent code verified. This is how pleat
//! reports "error against run time".
//!
//! Each long operation returns its own report struct (the way faer returns an info struct from
//! a solver): [`crate::lowpoly::LodReport`] (LODs and cages), [`crate::lowpoly::OffsetReport`],
//! `wrinkle::EvalReport`, `wrinkle::InterpReport`, `wrinkle::KnoppelReport`. Their fields carry
//! units in their docs, so a misspelt metric is a compile error. This module holds what they
//! share:
//! - [`Stage`] and [`StageTimes`]: per-stage wall seconds keyed by a per-operation stage enum;
//! - [`Guarantees`]: the verified properties, one named field each;
//! - [`StatEntries`]: the flat, named form (the generic C `PleatStats` entry list and the JSON
//!   report). Each report has exactly one method producing it (`entries()`), which is the only
//!   place where its entry names are written.
//!
//! May import: nothing from the crate (with `error`, `geom`, the bottom layer).

use std::borrow::Cow;
use std::time::Instant;

/// A stage of a long operation, as a per-operation enum (`LodStage`, `OffsetStage`, ...).
pub trait Stage: Copy + PartialEq + std::fmt::Debug {
    /// The stage's name in the JSON report, the C `PleatStats` entries and progress callbacks
    /// (e.g. `"simplify"`, `"level 2: z"`).
    fn name(&self) -> Cow<'static, str>;
}

/// Wall-clock seconds per stage, in execution order. A stage may occur more than once (a
/// rerun); [`StageTimes::seconds`] sums its occurrences.
#[derive(Debug, Clone, PartialEq)]
pub struct StageTimes<S> {
    entries: Vec<(S, f64)>,
}

impl<S> Default for StageTimes<S> {
    fn default() -> Self {
        StageTimes {
            entries: Vec::new(),
        }
    }
}

impl<S: Stage> StageTimes<S> {
    /// Runs `f`, records its wall time (seconds) under `stage`, and returns its result.
    pub fn time<T>(&mut self, stage: S, f: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let r = f();
        self.entries.push((stage, t0.elapsed().as_secs_f64()));
        r
    }

    /// Records `seconds` of wall time for `stage` (appended: execution order is kept).
    pub fn push(&mut self, stage: S, seconds: f64) {
        self.entries.push((stage, seconds));
    }

    /// Appends every entry of `other`, in its order.
    pub fn extend(&mut self, other: StageTimes<S>) {
        self.entries.extend(other.entries);
    }

    /// Seconds spent in `stage` (summed over its occurrences; 0 when it did not run).
    pub fn seconds(&self, stage: S) -> f64 {
        self.entries
            .iter()
            .filter(|e| e.0 == stage)
            .map(|e| e.1)
            .sum()
    }

    /// Total seconds over all stages (summed in execution order).
    pub fn total(&self) -> f64 {
        self.entries.iter().map(|e| e.1).sum()
    }

    /// `(stage, seconds)` in execution order.
    pub fn iter(&self) -> impl Iterator<Item = (S, f64)> + '_ {
        self.entries.iter().copied()
    }

    /// Number of recorded entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True when no stage was recorded.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Appends the stages, in execution order, to `out.stages` under their names.
    pub fn write_entries(&self, out: &mut StatEntries) {
        out.stages
            .extend(self.entries.iter().map(|(s, t)| (s.name(), *t)));
    }
}

/// Guarantees checked by code independent of the operation that produced the output
/// (`crate::verify`). `None`: not checked by this operation; `Some(holds)` otherwise.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Guarantees {
    /// Closed and manifold (`MeshReport::is_watertight`).
    pub watertight: Option<bool>,
    /// Manifold (for LODs and cages: manifold and consistently oriented).
    pub manifold: Option<bool>,
    /// No misoriented edge (offset surfaces).
    pub consistently_oriented: Option<bool>,
    /// No two faces intersect beyond shared vertices/edges, no degenerate face.
    pub self_intersection_free: Option<bool>,
    /// Every vertex of an offset surface lies within `h` of the `d`-iso-surface.
    pub vertices_within_h_of_offset: Option<bool>,
    /// The cage encloses every input vertex and touches no input triangle.
    pub cage_encloses_without_touching: Option<bool>,
    /// Same components and Euler characteristic as the offset surface the loop started from.
    pub same_topology_as_offset: Option<bool>,
}

impl Guarantees {
    /// `(name, holds)` of every checked guarantee, in a fixed order (the order of the fields).
    pub fn checked(&self) -> Vec<(&'static str, bool)> {
        [
            ("watertight", self.watertight),
            ("manifold", self.manifold),
            ("consistently_oriented", self.consistently_oriented),
            ("self_intersection_free", self.self_intersection_free),
            (
                "vertices_within_h_of_offset",
                self.vertices_within_h_of_offset,
            ),
            (
                "cage_encloses_without_touching",
                self.cage_encloses_without_touching,
            ),
            ("same_topology_as_offset", self.same_topology_as_offset),
        ]
        .into_iter()
        .filter_map(|(n, v)| v.map(|v| (n, v)))
        .collect()
    }

    /// True when every checked guarantee holds (and vacuously when none was checked).
    pub fn all_hold(&self) -> bool {
        self.checked().iter().all(|c| c.1)
    }

    /// Appends the checked guarantees to `out.verified`.
    pub fn write_entries(&self, out: &mut StatEntries) {
        out.verified.extend(self.checked());
    }
}

/// A report flattened into named entries of four kinds — the shape of the generic C
/// `PleatStats` and of the JSON report. Built only by a report's `entries()` method; nothing
/// in pleat looks entries up by name.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StatEntries {
    /// `(stage name, wall seconds)` in execution order.
    pub stages: Vec<(Cow<'static, str>, f64)>,
    /// `(name, count)`.
    pub counts: Vec<(Cow<'static, str>, u64)>,
    /// `(name, value)`; each name's unit is in the doc of the report field it comes from.
    pub metrics: Vec<(Cow<'static, str>, f64)>,
    /// `(guarantee, holds)`.
    pub verified: Vec<(&'static str, bool)>,
}

impl StatEntries {
    /// Appends a count.
    pub fn count_entry(&mut self, name: impl Into<Cow<'static, str>>, value: u64) {
        self.counts.push((name.into(), value));
    }

    /// Appends a metric.
    pub fn metric_entry(&mut self, name: impl Into<Cow<'static, str>>, value: f64) {
        self.metrics.push((name.into(), value));
    }

    /// Total seconds over all stages.
    pub fn total_seconds(&self) -> f64 {
        self.stages.iter().map(|s| s.1).sum()
    }

    /// The entries as one JSON object with four maps in order:
    /// `{"stages":{name:seconds},"counts":{..},"metrics":{..},"verified":{name:bool}}`.
    /// Non-finite metrics are written as `null`.
    pub fn to_json(&self) -> String {
        fn esc(s: &str) -> String {
            let mut o = String::with_capacity(s.len() + 2);
            o.push('"');
            for c in s.chars() {
                match c {
                    '"' => o.push_str("\\\""),
                    '\\' => o.push_str("\\\\"),
                    c if (c as u32) < 0x20 => o.push_str(&format!("\\u{:04x}", c as u32)),
                    c => o.push(c),
                }
            }
            o.push('"');
            o
        }
        fn num(v: f64) -> String {
            if v.is_finite() {
                format!("{v:?}")
            } else {
                "null".into()
            }
        }
        fn map<'a>(items: impl Iterator<Item = (&'a str, String)>) -> String {
            let body: Vec<String> = items.map(|(k, v)| format!("{}:{v}", esc(k))).collect();
            format!("{{{}}}", body.join(","))
        }
        format!(
            "{{\"stages\":{},\"counts\":{},\"metrics\":{},\"verified\":{}}}",
            map(self.stages.iter().map(|(k, v)| (k.as_ref(), num(*v)))),
            map(self.counts.iter().map(|(k, v)| (k.as_ref(), v.to_string()))),
            map(self.metrics.iter().map(|(k, v)| (k.as_ref(), num(*v)))),
            map(self.verified.iter().map(|(k, v)| (*k, v.to_string()))),
        )
    }
}

/// CPU seconds (user + system, all threads) this process has used so far, 0 when the OS
/// cannot tell. Differences of two calls measure an operation's CPU time, which unlike wall
/// time does not grow while the process waits for a shared CPU (the benchmarks report both).
pub fn process_cpu_seconds() -> f64 {
    // SAFETY: getrusage only writes into the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return 0.0;
    }
    let t = |tv: libc::timeval| tv.tv_sec as f64 + tv.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

/// Progress information passed to a progress callback.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress<'a> {
    /// Name of the running stage.
    pub stage: &'a str,
    /// Fraction of the whole operation done, in `[0, 1]`.
    pub fraction: f64,
}

/// A progress callback: return `true` to continue, `false` to cancel (the operation then
/// returns `Error::Cancelled` promptly). Called on the calling thread only.
pub type ProgressFn<'a> = dyn FnMut(Progress<'_>) -> bool + 'a;

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum T {
        A,
        B,
    }

    impl Stage for T {
        fn name(&self) -> Cow<'static, str> {
            match self {
                T::A => "a".into(),
                T::B => "b \"q\"".into(),
            }
        }
    }

    #[test]
    fn json_keeps_order_and_escapes() {
        let mut st = StageTimes::default();
        st.push(T::B, 0.5);
        st.push(T::A, 0.25);
        st.push(T::B, 1.0);
        assert_eq!(st.seconds(T::B), 1.5);
        assert_eq!(st.total(), 1.75);
        let mut e = StatEntries::default();
        st.write_entries(&mut e);
        e.count_entry("n", 3);
        e.metric_entry("x", f64::NAN);
        Guarantees {
            manifold: Some(true),
            watertight: Some(false),
            ..Guarantees::default()
        }
        .write_entries(&mut e);
        assert_eq!(
            e.to_json(),
            "{\"stages\":{\"b \\\"q\\\"\":0.5,\"a\":0.25,\"b \\\"q\\\"\":1.0},\"counts\":{\"n\":3},\
             \"metrics\":{\"x\":null},\"verified\":{\"watertight\":false,\"manifold\":true}}"
        );
    }
}
