//! [`Reporter`]: maps a stage's progress into a window of the caller's progress, never going
//! back, and turns the callback's `false` into `Error::Cancelled`.

use crate::report::{Progress, ProgressFn};
use crate::{Error, Result};

/// Maps stage progress into a window of the caller's progress and turns `false` into
/// `Error::Cancelled`.
pub(crate) struct Reporter<'p, 'f> {
    f: &'p mut ProgressFn<'f>,
    base: f64,
    span: f64,
    /// The largest fraction reported so far: reports never go back (a chain's levels baked
    /// beside the finest one report before the levels between them).
    reached: f64,
}

impl<'p, 'f> Reporter<'p, 'f> {
    pub fn new(f: &'p mut ProgressFn<'f>) -> Self {
        Reporter {
            f,
            base: 0.0,
            span: 1.0,
            reached: 0.0,
        }
    }

    /// Sets the window `[base, base + span]` of the whole operation.
    pub fn window(&mut self, base: f64, span: f64) {
        self.base = base;
        self.span = span;
    }

    /// Reports `stage` at `fraction` of the current window (never below an earlier report).
    pub fn report(&mut self, stage: &str, fraction: f64) -> bool {
        self.report_absolute(stage, self.base + self.span * fraction.clamp(0.0, 1.0))
    }

    /// Reports `stage` at `fraction` of the whole operation, not of the window (never below
    /// an earlier report).
    pub fn report_absolute(&mut self, stage: &str, fraction: f64) -> bool {
        self.reached = self.reached.max(fraction.clamp(0.0, 1.0));
        (self.f)(Progress {
            stage,
            fraction: self.reached,
        })
    }

    /// As [`report`](Self::report), with `Err(Cancelled)` on `false`.
    pub fn check(&mut self, stage: &str, fraction: f64) -> Result<()> {
        if self.report(stage, fraction) {
            Ok(())
        } else {
            Err(Error::Cancelled)
        }
    }
}
