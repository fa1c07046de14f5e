//! Runs the examples of the documentation: every fenced block of `README.md` and
//! `docs/guide/*.md` whose info string starts with `c`, `cpp`, `python` or `sh`.
//!
//! - `c` / `cpp`: a complete program, compiled (C99 / C++17, warnings are errors) against
//!   `include/`, `bindings/cpp/` and the freshly built library, then run.
//! - `python`: run by `python3` with `PYTHONPATH=bindings/python` and `PLEAT_LIBRARY` set to
//!   the freshly built library; skipped (with a message) without python3 or numpy.
//! - C, C++ and Python examples run in a scratch directory holding a link `assets` to the
//!   repository's `assets/`, so they read `assets/...` and write beside themselves.
//! - `sh`: run by `bash -euo pipefail` from the repository root, with this build's `pleat`
//!   first on `PATH` and `cargo run --release --` replaced by `pleat`.
//! - A block whose info string holds `no-run` (`sh no-run`: installation commands) is not run;
//!   `text`, `console` and other languages are output or listings, never run.
//!
//! Each block prints `ran FILE:LINE (LANG)`; failures are listed with their file and line.
//! The test needs the `pleat` binary, so it is built only with the `cli` feature (a default).
#![cfg(feature = "cli")]

#[path = "common/clib.rs"]
mod clib;

use clib::{build_library, have, root, try_compile};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One fenced block: where it starts, its language, whether it runs, and its text.
struct Block {
    file: String,
    line: usize,
    lang: String,
    no_run: bool,
    code: String,
}

/// The fenced blocks of a Markdown text (fences of three or more backticks, possibly indented).
fn blocks(file: &str, text: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<(usize, usize, String, bool, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        let ticks = t.len() - t.trim_start_matches('`').len();
        match &mut open {
            None if ticks >= 3 => {
                let info = t[ticks..].trim();
                let mut words = info.split_whitespace();
                let lang = words.next().unwrap_or("").to_string();
                let no_run = info.split_whitespace().any(|w| w == "no-run");
                open = Some((i + 1, ticks, lang, no_run, String::new()));
            }
            Some((start, n, lang, no_run, code)) => {
                if ticks >= *n && t[ticks..].trim().is_empty() {
                    out.push(Block {
                        file: file.to_string(),
                        line: *start,
                        lang: std::mem::take(lang),
                        no_run: *no_run,
                        code: std::mem::take(code),
                    });
                    open = None;
                } else {
                    code.push_str(line);
                    code.push('\n');
                }
            }
            None => {}
        }
    }
    assert!(open.is_none(), "{file}: a fenced block is not closed");
    out
}

/// Every documentation file the test scans, relative to the root: README.md, then the guide's
/// chapters in name order.
fn doc_files() -> Vec<String> {
    let mut files = vec!["README.md".to_string()];
    let mut guide: Vec<String> = std::fs::read_dir(root().join("docs/guide"))
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().to_string())
                .filter(|n| n.ends_with(".md"))
                .map(|n| format!("docs/guide/{n}"))
                .collect()
        })
        .unwrap_or_default();
    guide.sort();
    files.extend(guide);
    files
}

/// A scratch directory for one block, with `assets` linking to the repository's assets.
fn scratch(base: &Path, b: &Block) -> PathBuf {
    let name = format!("{}_{}", b.file.replace(['/', '.'], "_"), b.line);
    let dir = base.join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(root().join("assets"), dir.join("assets")).unwrap();
    dir
}

/// The output of a finished command, or its failure as a message with that output.
fn finish(cmd: &mut Command, what: &str) -> Result<String, String> {
    let o = cmd
        .output()
        .map_err(|e| format!("cannot run {what}: {e}"))?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    if o.status.success() {
        Ok(text)
    } else {
        Err(format!("{text}{what} failed ({})", o.status))
    }
}

/// What the runs share: the library's folder (built on first use), the scratch folder and
/// the tools found.
struct Env {
    libdir: Option<PathBuf>,
    scratch: PathBuf,
    cc: bool,
    cxx: bool,
    python: Option<bool>,
}

impl Env {
    fn libdir(&mut self) -> PathBuf {
        self.libdir.get_or_insert_with(build_library).clone()
    }

    /// Whether python3 with numpy is there (asked once).
    fn python(&mut self) -> bool {
        *self.python.get_or_insert_with(|| {
            Command::new("python3")
                .args(["-c", "import numpy"])
                .output()
                .map(|o| o.status.success())
                .unwrap_or(false)
        })
    }

    /// Runs one block: `Ok(None)` when skipped (with the reason printed), `Ok(Some(output))`
    /// when it ran and passed.
    fn run(&mut self, b: &Block) -> Result<Option<String>, String> {
        let at = format!("{}:{}", b.file, b.line);
        match b.lang.as_str() {
            "c" | "cpp" => {
                let cxx = b.lang == "cpp";
                if !(if cxx { self.cxx } else { self.cc }) {
                    println!(
                        "SKIPPED: {at} (no {} on PATH)",
                        if cxx { "c++" } else { "cc" }
                    );
                    return Ok(None);
                }
                let libdir = self.libdir();
                let dir = scratch(&self.scratch, b);
                let src = dir.join(if cxx { "example.cpp" } else { "example.c" });
                std::fs::write(&src, &b.code).unwrap();
                let exe = dir.join("example");
                try_compile(&src, &exe, &libdir, cxx, &[])?;
                finish(Command::new(&exe).current_dir(&dir), "the program").map(Some)
            }
            "python" => {
                if !self.python() {
                    println!("SKIPPED: {at} (python3 with numpy not found)");
                    return Ok(None);
                }
                let libdir = self.libdir();
                let dir = scratch(&self.scratch, b);
                let src = dir.join("example.py");
                std::fs::write(&src, &b.code).unwrap();
                finish(
                    Command::new("python3")
                        .arg(&src)
                        .current_dir(&dir)
                        .env("PYTHONPATH", root().join("bindings/python"))
                        .env("PLEAT_LIBRARY", libdir.join("libpleat.so")),
                    "python3",
                )
                .map(Some)
            }
            "sh" => {
                let bin = Path::new(env!("CARGO_BIN_EXE_pleat")).parent().unwrap();
                let path = std::env::var_os("PATH").unwrap_or_default();
                let mut dirs = vec![bin.to_path_buf()];
                dirs.extend(std::env::split_paths(&path));
                let script = b.code.replace("cargo run --release --", "pleat");
                finish(
                    Command::new("bash")
                        .args(["-euo", "pipefail", "-c", &script])
                        .current_dir(root())
                        .env("PATH", std::env::join_paths(dirs).unwrap()),
                    "bash",
                )
                .map(Some)
            }
            _ => Ok(None),
        }
    }
}

#[test]
fn documentation_examples_run() {
    let mut all = Vec::new();
    for file in doc_files() {
        let text = std::fs::read_to_string(root().join(&file)).unwrap();
        all.extend(blocks(&file, &text));
    }
    let runnable =
        |b: &&Block| !b.no_run && matches!(b.lang.as_str(), "c" | "cpp" | "python" | "sh");
    let scratch = std::env::temp_dir().join(format!("pleat-doc-examples-{}", std::process::id()));
    let mut env = Env {
        libdir: None,
        scratch: scratch.clone(),
        cc: have("cc"),
        cxx: have("c++"),
        python: None,
    };
    let needs_library =
        |b: &Block| (b.lang == "c" && env.cc) || (b.lang == "cpp" && env.cxx) || b.lang == "python";
    if all.iter().filter(runnable).any(needs_library) {
        let t = std::time::Instant::now();
        let dir = env.libdir();
        println!(
            "built the library in {} in {:.1} s",
            dir.display(),
            t.elapsed().as_secs_f64()
        );
    }
    let mut failures = Vec::new();
    let mut ran = 0;
    for b in all.iter().filter(runnable) {
        let at = format!("{}:{} ({})", b.file, b.line, b.lang);
        let t = std::time::Instant::now();
        match env.run(b) {
            Ok(Some(_)) => {
                ran += 1;
                println!("ran {at} in {:.1} s", t.elapsed().as_secs_f64());
            }
            Ok(None) => {}
            Err(msg) => {
                println!("FAILED {at}:\n{msg}");
                failures.push(format!("{at}\n{msg}"));
            }
        }
    }
    let skipped_on_purpose = all.iter().filter(|b| b.no_run).count();
    println!("{ran} examples ran, {skipped_on_purpose} blocks marked no-run");
    let _ = std::fs::remove_dir_all(&scratch);
    assert!(
        failures.is_empty(),
        "{} documentation example(s) failed:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

/// The block scanner itself: languages, `no-run`, lines and longer fences.
#[test]
fn blocks_are_found_with_their_lines() {
    let text = "# t\n\n```sh\necho a\n```\n\n````c no-run\n```\n````\n\n```text\nout\n```\n";
    let b = blocks("x.md", text);
    assert_eq!(b.len(), 3);
    assert_eq!(
        (b[0].line, b[0].lang.as_str(), b[0].no_run),
        (3, "sh", false)
    );
    assert_eq!(b[0].code, "echo a\n");
    assert_eq!((b[1].line, b[1].lang.as_str(), b[1].no_run), (7, "c", true));
    assert_eq!(b[1].code, "```\n");
    assert_eq!(b[2].lang, "text");
}
