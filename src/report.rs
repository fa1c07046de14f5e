//! [`Stats`]: what every long operation reports — wall time per stage, counts, achieved error and
//! which guarantees were verified. This is how pleat reports "error against run time".

use std::time::Instant;

/// Timing and quality figures of one long operation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// `(stage name, wall seconds)` in execution order.
    pub stages: Vec<(String, f64)>,
    /// Named counts (cells visited, faces out, flips, ...), in insertion order.
    pub counts: Vec<(String, u64)>,
    /// Named real-valued metrics (Hausdorff / bbox diagonal, max deviation / d, ...).
    pub metrics: Vec<(String, f64)>,
    /// Guarantees checked by independent code after the operation: `(name, holds)`.
    pub verified: Vec<(String, bool)>,
}

impl Stats {
    /// Runs `f`, records its wall time under `name`, and returns its result.
    pub fn time<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let r = f();
        self.stages
            .push((name.to_string(), t0.elapsed().as_secs_f64()));
        r
    }

    /// Records a count.
    pub fn count(&mut self, name: &str, value: u64) {
        self.counts.push((name.to_string(), value));
    }

    /// Records a metric.
    pub fn metric(&mut self, name: &str, value: f64) {
        self.metrics.push((name.to_string(), value));
    }

    /// Records the outcome of an independent verification.
    pub fn verify(&mut self, name: &str, holds: bool) {
        self.verified.push((name.to_string(), holds));
    }

    /// Total seconds over all stages.
    pub fn total_seconds(&self) -> f64 {
        self.stages.iter().map(|s| s.1).sum()
    }

    /// Looks up a stage time, count, or metric by name.
    pub fn get_metric(&self, name: &str) -> Option<f64> {
        self.metrics.iter().find(|m| m.0 == name).map(|m| m.1)
    }

    /// Seconds spent in stages named `name` (0 when there is none).
    pub fn stage_seconds(&self, name: &str) -> f64 {
        self.stages
            .iter()
            .filter(|s| s.0 == name)
            .map(|s| s.1)
            .sum()
    }

    /// Looks up a count by name.
    pub fn get_count(&self, name: &str) -> Option<u64> {
        self.counts.iter().find(|m| m.0 == name).map(|m| m.1)
    }
}

impl Stats {
    /// The stats as one JSON object with four maps in insertion order:
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
        let map = |items: Vec<(String, String)>| {
            let body: Vec<String> = items
                .iter()
                .map(|(k, v)| format!("{}:{v}", esc(k)))
                .collect();
            format!("{{{}}}", body.join(","))
        };
        format!(
            "{{\"stages\":{},\"counts\":{},\"metrics\":{},\"verified\":{}}}",
            map(self
                .stages
                .iter()
                .map(|(k, v)| (k.clone(), num(*v)))
                .collect()),
            map(self
                .counts
                .iter()
                .map(|(k, v)| (k.clone(), v.to_string()))
                .collect()),
            map(self
                .metrics
                .iter()
                .map(|(k, v)| (k.clone(), num(*v)))
                .collect()),
            map(self
                .verified
                .iter()
                .map(|(k, v)| (k.clone(), v.to_string()))
                .collect()),
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
