//! A bounded fuzzing run on the stable toolchain, in `cargo test` (requirement: CI runs each
//! target for a short bounded time within the CI budget).
//!
//! The cargo-fuzz targets (fuzz/, libFuzzer + ASan) need a nightly ASan build that takes 20–30
//! minutes from a cold cache on 2 cores: more than `.ci/run`'s budget. This test runs the same
//! target bodies (`fuzz/src/lib.rs`, included below) without them: for each target, every
//! committed seed (`fuzz/seeds/<target>/`), every regression input (`fuzz/regressions/`), then a
//! fixed number of blind mutations of the seeds from a fixed RNG seed — bit flips, byte
//! overwrites, inserts, erasures, duplicated runs, splices of two seeds, interesting integers
//! (0, ±1, 0x7f…, 2³², NaN/∞/1e±300 bits) and, for text, interesting numbers. Deterministic:
//! the same inputs on every run. What it is not: coverage-guided (nothing learns which inputs
//! reach new code), instrumented (no ASan; safe Rust's bounds checks and pleat's C boundary
//! panics still show), or long: it catches regressions on and near the seeds, the nightly
//! campaign (`bash .ci/fuzz.sh`) finds new bugs.
//!
//! A finding fails the target's test, naming the input (`seed-…`, `regression-…`,
//! `mutant-<n>`) and writing its bytes to `target/tmp/fuzz-smoke/<target>-<input>.bin` (keep it
//! as `fuzz/regressions/<target>-<what>.bin`, which `tests/hardening.rs` replays too).
//! `PLEAT_FUZZ_SMOKE_SCALE=k` runs k times the executions (longer local runs; the inputs of the
//! default run are a prefix of the longer one's).
#![cfg(all(
    feature = "lod",
    feature = "cage",
    feature = "wrinkle",
    feature = "io-gltf",
    feature = "tfw"
))]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[path = "../fuzz/src/lib.rs"]
#[allow(dead_code)]
mod fuzz;

/// The longest input a mutation may produce (the `-max_len` of `.ci/fuzz.sh`).
const MAX_LEN: usize = 65_536;

/// splitmix64: a small fixed-seed generator, so every run mutates the same way.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Integers that sit on boundaries (sign, width, counts) and the bits of special doubles.
const INTERESTING: [u64; 16] = [
    0,
    1,
    0x7f,
    0x80,
    0xff,
    0x7fff,
    0xffff,
    0x7fff_ffff,
    0xffff_ffff,
    0x1_0000_0000,
    u64::MAX,
    0x7ff8_0000_0000_0000, // NaN
    0x7ff0_0000_0000_0000, // +inf
    0x7e37_e43c_8800_759c, // 1e300
    0x01a5_6e1f_c2f8_f359, // 1e-300
    0x0000_0000_0000_0001, // smallest subnormal
];

/// Numbers that text readers must handle: huge counts, negatives, overflow, NaN, exponents.
const NUMBERS: [&str; 10] = [
    "0",
    "-1",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "1e308",
    "1e-320",
    "nan",
    "-inf",
    "99999999999999999999999999",
];

/// One random edit of `data` in place; `other` is a second seed for splices.
fn mutate_once(data: &mut Vec<u8>, other: &[u8], rng: &mut Rng) {
    let len = data.len();
    match rng.below(9) {
        0 if len > 0 => {
            let i = rng.below(len);
            data[i] ^= 1 << rng.below(8);
        }
        1 if len > 0 => {
            let i = rng.below(len);
            data[i] = rng.next() as u8;
        }
        2 => {
            let i = rng.below(len + 1);
            let n = 1 + rng.below(8);
            let bytes: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
            data.splice(i..i, bytes);
        }
        3 if len > 0 => {
            let i = rng.below(len);
            let n = 1 + rng.below((len - i).min(16));
            data.drain(i..i + n);
        }
        4 if len > 0 => {
            // duplicate a run (repeated records, nesting)
            let i = rng.below(len);
            let n = 1 + rng.below((len - i).min(64));
            let run = data[i..i + n].to_vec();
            let at = rng.below(len + 1);
            data.splice(at..at, run);
        }
        5 if !other.is_empty() => {
            // splice: a prefix of this input and a suffix of the other
            let cut = rng.below(len + 1);
            let from = rng.below(other.len());
            data.truncate(cut);
            data.extend_from_slice(&other[from..]);
        }
        6 if len > 0 => {
            let width = [1, 2, 4, 8][rng.below(4)];
            let i = rng.below(len);
            let v = INTERESTING[rng.below(INTERESTING.len())];
            let bytes = if rng.below(2) == 0 {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            };
            let n = width.min(len - i);
            let src = if rng.below(2) == 0 { 0 } else { 8 - width };
            data[i..i + n].copy_from_slice(&bytes[src..src + n]);
        }
        7 | 8 => replace_number(data, rng),
        _ => {}
    }
}

/// Replaces the digit run at or after a random position with an interesting number (a
/// no-op in inputs without digits).
fn replace_number(data: &mut Vec<u8>, rng: &mut Rng) {
    if data.is_empty() {
        return;
    }
    let start = rng.below(data.len());
    let Some(off) = data[start..].iter().position(u8::is_ascii_digit) else {
        return;
    };
    let i = start + off;
    let n = data[i..].iter().take_while(|b| b.is_ascii_digit()).count();
    let num = NUMBERS[rng.below(NUMBERS.len())].as_bytes();
    data.splice(i..i + n, num.iter().copied());
}

/// A mutant of a random seed: 1 to 4 stacked edits, cut to [`MAX_LEN`].
fn mutant(seeds: &[Vec<u8>], rng: &mut Rng) -> Vec<u8> {
    let mut data = seeds[rng.below(seeds.len())].clone();
    let other = &seeds[rng.below(seeds.len())];
    for _ in 0..1 + rng.below(4) {
        mutate_once(&mut data, other, rng);
    }
    data.truncate(MAX_LEN);
    data
}

/// The files of `dir` whose names pass `keep`, sorted by name, with their bytes.
fn files(dir: &Path, keep: impl Fn(&str) -> bool) -> Vec<(PathBuf, Vec<u8>)> {
    let Ok(paths) = fuzz::sorted_files(dir) else {
        return Vec::new();
    };
    paths
        .into_iter()
        .filter(|p| keep(&p.file_name().unwrap().to_string_lossy()))
        .map(|p| {
            let bytes = std::fs::read(&p).expect("readable input");
            (p, bytes)
        })
        .collect()
}

/// Runs `target` on `data`; on a panic saves the input and fails with where it is.
fn run_one(name: &str, target: fuzz::Target, label: &str, data: &[u8]) -> bool {
    match catch_unwind(AssertUnwindSafe(|| target(data))) {
        Ok(accepted) => accepted,
        Err(_) => {
            let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-smoke");
            std::fs::create_dir_all(&dir).expect("a directory for the finding");
            let path = dir.join(format!("{name}-{}.bin", label.trim_end_matches(".bin")));
            std::fs::write(&path, data).expect("the finding written");
            panic!(
                "fuzz target {name} failed on {label} ({} bytes, saved as {})",
                data.len(),
                path.display()
            );
        }
    }
}

/// Seeds, regressions, then `execs` mutants (times `PLEAT_FUZZ_SMOKE_SCALE`) through `name`.
fn smoke(name: &str, execs: usize) {
    let target = fuzz::target(name).expect("a target of fuzz/src/lib.rs");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let seeds = files(&root.join("seeds").join(name), |_| true);
    assert!(!seeds.is_empty(), "no seeds for {name}");
    let regressions = files(&root.join("regressions"), |f| {
        fuzz::target_of_regression(f).is_some_and(|(t, _)| t == name)
    });
    let scale: usize = std::env::var("PLEAT_FUZZ_SMOKE_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let t0 = Instant::now();
    let mut slowest = (Duration::ZERO, String::new());
    let mut timed = |label: String, data: &[u8]| {
        let t = Instant::now();
        let accepted = run_one(name, target, &label, data);
        if t.elapsed() > slowest.0 {
            slowest = (t.elapsed(), label);
        }
        accepted
    };
    let mut seeds_accepted = 0;
    for (path, data) in &seeds {
        let file = path.file_name().unwrap().to_string_lossy();
        seeds_accepted += usize::from(timed(format!("seed-{file}"), data));
    }
    for (path, data) in &regressions {
        let file = path.file_name().unwrap().to_string_lossy();
        timed(format!("regression-{file}"), data);
    }
    let corpus: Vec<Vec<u8>> = seeds.into_iter().map(|(_, d)| d).collect();
    let mut rng = Rng(0x5EED_0000
        ^ name
            .bytes()
            .fold(0u64, |h, b| h.wrapping_mul(31).wrapping_add(u64::from(b))));
    let n = execs * scale;
    let mut accepted = 0;
    for i in 0..n {
        let data = mutant(&corpus, &mut rng);
        accepted += usize::from(timed(format!("mutant-{i}"), &data));
    }
    println!(
        "{name}: {} seeds ({seeds_accepted} accepted), {} regressions, {n} mutants \
         ({accepted} accepted) in {:.2} s; slowest input {:.3} s ({})",
        corpus.len(),
        regressions.len(),
        t0.elapsed().as_secs_f64(),
        slowest.0.as_secs_f64(),
        slowest.1
    );
    assert!(seeds_accepted > 0, "{name}: no seed is accepted");
}

// Executions per target: sized to about 4 CPU s each in the test profile (measured 2026-11-27:
// 46 CPU s for all 11, user + sys; 124 s of wall time with 2 test threads at load 17–20 on the
// shared 2 cores, so about 25 s on 2 free cores). docs/guide/errors-and-limits.md, "How it is
// tested".

#[test]
fn fuzz_smoke_obj() {
    smoke("obj", 2_000_000);
}

#[test]
fn fuzz_smoke_ply() {
    smoke("ply", 1_500_000);
}

#[test]
fn fuzz_smoke_off() {
    smoke("off", 2_000_000);
}

#[test]
fn fuzz_smoke_stl() {
    smoke("stl", 1_500_000);
}

#[test]
fn fuzz_smoke_gltf() {
    smoke("gltf", 1_500_000);
}

#[test]
fn fuzz_smoke_cwf() {
    smoke("cwf", 750_000);
}

#[test]
fn fuzz_smoke_cwfa() {
    smoke("cwfa", 500_000);
}

#[test]
fn fuzz_smoke_mesh_create() {
    smoke("mesh_create", 200_000);
}

#[test]
fn fuzz_smoke_lod_bake() {
    smoke("lod_bake", 200);
}

#[test]
fn fuzz_smoke_wrinkle_eval() {
    smoke("wrinkle_eval", 125_000);
}

#[test]
fn fuzz_smoke_tfw_scene() {
    smoke("tfw_scene", 50_000);
}
