//! [`Steps`]: maps a bake's stage progress into a window of the caller's progress and turns the
//! callback's `false` into `Error::Cancelled`.

use crate::report::{Progress, ProgressFn};
use crate::{Error, Result};

/// Maps a bake's stage progress into a window `[base, base + span]` of the caller's progress
/// and turns a `false` answer into `Error::Cancelled`.
pub(crate) struct Steps<'p, 'f> {
    f: &'p mut ProgressFn<'f>,
    base: f64,
    span: f64,
}

impl<'p, 'f> Steps<'p, 'f> {
    /// Reports into `[base, base + span]` of `f`'s range.
    pub(crate) fn new(f: &'p mut ProgressFn<'f>, base: f64, span: f64) -> Self {
        Steps { f, base, span }
    }

    /// Reports `stage` at `fraction` (in `[0, 1]`) of the window; `Err(Cancelled)` when the
    /// callback answers `false`.
    pub(crate) fn check(&mut self, stage: &str, fraction: f64) -> Result<()> {
        let fraction = (self.base + self.span * fraction.clamp(0.0, 1.0)).clamp(0.0, 1.0);
        if (self.f)(Progress { stage, fraction }) {
            Ok(())
        } else {
            Err(Error::Cancelled)
        }
    }
}
