//! `PleatStats`: what a long operation measured — wall time per stage, counts, metrics (error
//! against run time) and which guarantees independent code verified.

use super::boundary::{arg_ref, destroy};
use super::common::{guard, null_arg, PleatStatus};
use crate::report::StatEntries;
use crate::Error;
use std::ffi::{c_char, CString};

/// Statistics of one long operation (opaque). Returned through the optional `PleatStats **`
/// output of long operations; destroyed with `pleat_stats_destroy`. Immutable.
pub struct PleatStats {
    /// The operation's typed report flattened by its `entries()` method.
    pub(crate) stats: StatEntries,
    names: Vec<CString>,
}

// Only the offset export (feature `lod`) hands stats out.
#[cfg_attr(not(feature = "lod"), allow(dead_code))]
impl PleatStats {
    fn new(stats: StatEntries) -> PleatStats {
        let names = stats
            .stages
            .iter()
            .map(|s| s.0.as_ref())
            .chain(stats.counts.iter().map(|s| s.0.as_ref()))
            .chain(stats.metrics.iter().map(|s| s.0.as_ref()))
            .chain(stats.verified.iter().map(|s| s.0))
            .map(|n| CString::new(n.replace('\0', "")).unwrap_or_default())
            .collect();
        PleatStats { stats, names }
    }
}

/// Writes a stats handle holding `stats` (a report's `entries()`) to `out` when `out` is
/// non-NULL.
///
/// # Safety
/// `out` is NULL or valid for a write.
#[cfg_attr(not(feature = "lod"), allow(dead_code))]
pub(crate) unsafe fn emit_stats(out: *mut *mut PleatStats, stats: StatEntries) {
    if !out.is_null() {
        *out = Box::into_raw(Box::new(PleatStats::new(stats)));
    }
}

/// Kind of entry in a `PleatStats`, for `pleat_stats_entry`.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PleatStatsKind {
    /// Wall-clock seconds of a stage, in execution order.
    Stage = 0,
    /// A count (cells visited, faces out, flips, ...); the value is an integer.
    Count = 1,
    /// A real metric (e.g. `hausdorff_rel`: two-sided Hausdorff distance / bbox diagonal).
    Metric = 2,
    /// A guarantee checked by independent code after the operation: value 1 (holds) or 0.
    Verified = 3,
}

fn entries(s: &StatEntries, kind: PleatStatsKind) -> (usize, Vec<f64>) {
    let offset = match kind {
        PleatStatsKind::Stage => 0,
        PleatStatsKind::Count => s.stages.len(),
        PleatStatsKind::Metric => s.stages.len() + s.counts.len(),
        PleatStatsKind::Verified => s.stages.len() + s.counts.len() + s.metrics.len(),
    };
    let values = match kind {
        PleatStatsKind::Stage => s.stages.iter().map(|e| e.1).collect(),
        PleatStatsKind::Count => s.counts.iter().map(|e| e.1 as f64).collect(),
        PleatStatsKind::Metric => s.metrics.iter().map(|e| e.1).collect(),
        PleatStatsKind::Verified => s.verified.iter().map(|e| e.1 as u8 as f64).collect(),
    };
    (offset, values)
}

/// Number of entries of `kind` (0 when `stats` is NULL).
///
/// # Safety
/// `stats` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_stats_count(
    stats: *const PleatStats,
    kind: PleatStatsKind,
) -> usize {
    stats
        .as_ref()
        .map_or(0, |s| entries(&s.stats, kind).1.len())
}

/// Entry `index` of `kind`: its name (NUL-terminated, valid until the stats are destroyed) and
/// value (seconds for stages, the count as a double for counts, 1/0 for verified guarantees).
///
/// - `name`, `value`: outputs; either may be NULL to skip it.
/// - Returns `PLEAT_STATUS_INVALID_ARGUMENT` for a NULL `stats` or an index out of range.
///
/// # Safety
/// `stats` is NULL or live; `name`/`value` are NULL or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn pleat_stats_entry(
    stats: *const PleatStats,
    kind: PleatStatsKind,
    index: usize,
    name: *mut *const c_char,
    value: *mut f64,
) -> PleatStatus {
    guard(|| {
        let s = arg_ref(stats, "stats")?;
        let (offset, values) = entries(&s.stats, kind);
        let v = values.get(index).copied().ok_or_else(|| {
            Error::InvalidArgument(format!("index {index} >= {} entries", values.len()))
        })?;
        if !name.is_null() {
            *name = s.names[offset + index].as_ptr();
        }
        if !value.is_null() {
            *value = v;
        }
        Ok(())
    })
}

/// Total wall-clock seconds over all stages (0 when `stats` is NULL).
///
/// # Safety
/// `stats` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn pleat_stats_total_seconds(stats: *const PleatStats) -> f64 {
    stats.as_ref().map_or(0.0, |s| s.stats.total_seconds())
}

/// Copies the stats as one JSON object (`{"stages":{..},"counts":{..},"metrics":{..},
/// "verified":{..}}`) into `buf` (capacity `len`, NUL-terminated, truncated if needed); the
/// full length without the NUL goes to `needed` (may be NULL). `buf` may be NULL with `len` 0.
///
/// # Safety
/// `stats` is NULL or live; `buf` valid for `len` bytes; `needed` NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn pleat_stats_to_json(
    stats: *const PleatStats,
    buf: *mut c_char,
    len: usize,
    needed: *mut usize,
) -> PleatStatus {
    guard(|| {
        let s = arg_ref(stats, "stats")?;
        let json = s.stats.to_json();
        if !needed.is_null() {
            *needed = json.len();
        }
        if len == 0 {
            return Ok(());
        }
        if buf.is_null() {
            return Err(null_arg("buf"));
        }
        let n = json.len().min(len - 1);
        std::ptr::copy_nonoverlapping(json.as_ptr(), buf as *mut u8, n);
        *buf.add(n) = 0;
        Ok(())
    })
}

/// Destroys stats; NULL is ignored.
///
/// # Safety
/// `stats` is NULL or a live handle not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn pleat_stats_destroy(stats: *mut PleatStats) {
    destroy(stats)
}
