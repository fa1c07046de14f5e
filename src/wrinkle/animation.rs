//! [`CwfAnimation`]: the result of [`interpolate`](super::interpolate()) — `N' + 1` guide
//! frames at `t = n/N'` and `k` linear sub-steps per guide interval (§3.4.1 "Linear
//! substepping") — evaluable at any `t ∈ [0, 1]`, and its `.cwfa` text file format.
//!
//! # The `.cwfa` format (version 1)
//!
//! ```text
//! pleat-cwf-animation 1
//! vertices 4
//! edges 5
//! faces 2
//! connectivity 9c1f0e3a57d2b4e8
//! guide-frames 50        (N': guide frames at t = n/N', n = 0..=N', all stored)
//! substeps 4             (k: the animation has N'·k + 1 frames, at t = i/(N'·k))
//! amplitude
//! 0.01 0.005             (one line per vertex: a⁰ a¹ — the amplitude is linear in t)
//! …
//! frame 0                (N' + 1 blocks, n = 0..=N')
//! omega
//! 0.25                   (one line per edge in EdgeList order, oriented min → max vertex)
//! …
//! zeta
//! 1 0                    (one line per vertex: Re(z̃) Im(z̃))
//! …
//! end
//! ```
//!
//! Header lines, the `connectivity` hash and the base-mesh check are those of the `.cwf`
//! format ([`io`](super::io)): the base mesh is stored separately and must have the
//! connectivity the file records. `#` comments and blank lines are ignored. Numbers use Rust's
//! shortest round-trip formatting: write → read reproduces every bit, so frames evaluated after
//! loading are identical to frames evaluated before saving.

use std::fmt::Write as _;
use std::path::Path;

use super::complex::Complex;
use super::cwf::Cwf;
use super::io::connectivity_hash;
use crate::mesh::TriMesh;
use crate::{Error, Result};

/// The `.cwfa` format version written by [`write_animation`].
pub const ANIMATION_FORMAT_VERSION: u32 = 1;

/// A wrinkle animation on one base mesh: guide frames `(ω_n, z̃_n)` at `t_n = n/N'`
/// (`n = 0..=N'`, the first and last being the keyframes exactly), an amplitude linear in `t`,
/// and `k` sub-steps per guide interval for frame-indexed playback.
///
/// [`CwfAnimation::frame_at`] is linear between guide frames in `ω` and `z̃` (§3.4.1), exact in
/// `a`; at `t = 0` and `t = 1` it returns the keyframes bit for bit. Immutable and `Sync`: frames
/// can be evaluated from several threads at once.
#[derive(Debug, Clone)]
pub struct CwfAnimation {
    /// Keyframe 0 (base mesh and connectivity for building frames).
    template: Cwf,
    amplitude: [Vec<f64>; 2],
    omega: Vec<Vec<f64>>,
    zeta: Vec<Vec<Complex>>,
    substeps: usize,
}

impl CwfAnimation {
    /// Builds an animation from guide data on `template`'s base mesh. Errors
    /// ([`Error::InvalidArgument`]) when there are fewer than 2 guide frames, `substeps` is 0,
    /// a length does not match the mesh, a value is not finite or an amplitude is negative.
    pub fn from_guides(
        template: &Cwf,
        amplitude: [Vec<f64>; 2],
        omega: Vec<Vec<f64>>,
        zeta: Vec<Vec<Complex>>,
        substeps: usize,
    ) -> Result<CwfAnimation> {
        let (nv, ne) = (template.amplitude().len(), template.omega().len());
        if omega.len() < 2 || omega.len() != zeta.len() {
            return crate::invalid_arg!(
                "an animation needs at least 2 guide frames with ω and z̃ each ({} and {} given)",
                omega.len(),
                zeta.len()
            );
        }
        if substeps == 0 {
            return crate::invalid_arg!("substeps must be ≥ 1");
        }
        // `frame_count() = N'·k + 1` must be representable (a `.cwfa` header may claim any k).
        if (omega.len() - 1)
            .checked_mul(substeps)
            .and_then(|n| n.checked_add(1))
            .is_none()
        {
            return crate::invalid_arg!(
                "{} guide intervals × {substeps} substeps: the frame count overflows",
                omega.len() - 1
            );
        }
        for a in &amplitude {
            if a.len() != nv || a.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return crate::invalid_arg!(
                    "amplitudes: {nv} finite values ≥ 0 per keyframe are needed"
                );
            }
        }
        for (n, (w, z)) in omega.iter().zip(&zeta).enumerate() {
            if w.len() != ne || z.len() != nv {
                return crate::invalid_arg!(
                    "guide frame {n}: {} ω values and {} z̃ values; the mesh needs {ne} and {nv}",
                    w.len(),
                    z.len()
                );
            }
            if w.iter().any(|v| !v.is_finite()) || z.iter().any(|v| !v.is_finite()) {
                return crate::invalid_arg!("guide frame {n} holds a NaN or infinite value");
            }
        }
        Ok(CwfAnimation {
            template: template.clone(),
            amplitude,
            omega,
            zeta,
            substeps,
        })
    }

    /// The base mesh.
    pub fn base(&self) -> &TriMesh {
        self.template.base()
    }

    /// `N'`: the number of guide intervals (there are `N' + 1` guide frames).
    pub fn guide_intervals(&self) -> usize {
        self.omega.len() - 1
    }

    /// `k`: linear sub-steps per guide interval.
    pub fn substeps(&self) -> usize {
        self.substeps
    }

    /// Number of playback frames, `N'·k + 1` (frame `i` is at `t = i / (N'·k)`).
    pub fn frame_count(&self) -> usize {
        self.guide_intervals() * self.substeps + 1
    }

    /// Time of playback frame `i` (clamped to the last frame).
    pub fn frame_time(&self, i: usize) -> f64 {
        let last = self.frame_count() - 1;
        i.min(last) as f64 / last as f64
    }

    /// `ω` of guide frame `n` (`n ≤ N'`).
    pub fn guide_omega(&self, n: usize) -> &[f64] {
        &self.omega[n]
    }

    /// `z̃` of guide frame `n` (`n ≤ N'`).
    pub fn guide_zeta(&self, n: usize) -> &[Complex] {
        &self.zeta[n]
    }

    /// Keyframe amplitudes `[a⁰, a¹]`.
    pub fn keyframe_amplitudes(&self) -> &[Vec<f64>; 2] {
        &self.amplitude
    }

    /// The CWF at time `t ∈ [0, 1]` (error outside, or NaN): `a(t) = (1−t)a⁰ + t a¹`, `ω` and `z̃`
    /// linear between the two guide frames around `t`. Exact keyframes at `t = 0` and `1`.
    pub fn frame_at(&self, t: f64) -> Result<Cwf> {
        check_time(t)?;
        let n = self.guide_intervals();
        let s = t * n as f64;
        let i = (s.floor() as usize).min(n - 1);
        let lam = s - i as f64;
        // the ends return stored values untouched (bit-exact keyframes, signed zeros included)
        let mix = |l: f64, x: f64, y: f64| match l {
            0.0 => x,
            1.0 => y,
            _ => (1.0 - l) * x + l * y,
        };
        let lerp = |x: f64, y: f64| mix(lam, x, y);
        let omega = self.omega[i]
            .iter()
            .zip(&self.omega[i + 1])
            .map(|(&x, &y)| lerp(x, y))
            .collect();
        let zeta = self.zeta[i]
            .iter()
            .zip(&self.zeta[i + 1])
            .map(|(x, y)| Complex::new(lerp(x.re, y.re), lerp(x.im, y.im)))
            .collect();
        let amp = self.amplitude[0]
            .iter()
            .zip(&self.amplitude[1])
            .map(|(&x, &y)| mix(t, x, y).max(0.0))
            .collect();
        Ok(self.template.with_fields(omega, amp, zeta))
    }

    /// Playback frame `i < frame_count()` (error otherwise): `frame_at(i / (N'·k))`.
    pub fn frame(&self, i: usize) -> Result<Cwf> {
        if i >= self.frame_count() {
            return crate::invalid_arg!(
                "frame {i} does not exist; the animation has {} frames",
                self.frame_count()
            );
        }
        self.frame_at(self.frame_time(i))
    }
}

/// The `.cwfa` text of `anim` (see the [module docs](self)).
pub fn animation_to_string(anim: &CwfAnimation) -> String {
    let m = anim.base();
    let (nv, ne) = (m.vertex_count(), anim.omega[0].len());
    let mut s = String::with_capacity(48 * (anim.omega.len() * (ne + nv) + nv) + 256);
    let _ = writeln!(s, "pleat-cwf-animation {ANIMATION_FORMAT_VERSION}");
    let _ = writeln!(s, "vertices {nv}");
    let _ = writeln!(s, "edges {ne}");
    let _ = writeln!(s, "faces {}", m.triangle_count());
    let _ = writeln!(s, "connectivity {:016x}", connectivity_hash(m));
    let _ = writeln!(s, "guide-frames {}", anim.guide_intervals());
    let _ = writeln!(s, "substeps {}", anim.substeps);
    s.push_str("amplitude\n");
    for (a, b) in anim.amplitude[0].iter().zip(&anim.amplitude[1]) {
        let _ = writeln!(s, "{a} {b}");
    }
    for (n, (w, z)) in anim.omega.iter().zip(&anim.zeta).enumerate() {
        let _ = writeln!(s, "frame {n}");
        s.push_str("omega\n");
        for v in w {
            let _ = writeln!(s, "{v}");
        }
        s.push_str("zeta\n");
        for c in z {
            let _ = writeln!(s, "{} {}", c.re, c.im);
        }
    }
    s.push_str("end\n");
    s
}

/// Writes `anim` to `path` in the `.cwfa` format.
pub fn write_animation(path: impl AsRef<Path>, anim: &CwfAnimation) -> Result<()> {
    let path = path.as_ref();
    std::fs::write(path, animation_to_string(anim)).map_err(|e| Error::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })
}

/// Reads a `.cwfa` file written for `base` (connectivity checked as for `.cwf`).
pub fn read_animation(path: impl AsRef<Path>, base: TriMesh) -> Result<CwfAnimation> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    parse_animation(&text, base, &path.display().to_string())
}

/// Parses `.cwfa` text for `base`; `name` labels error messages.
pub fn parse_animation(text: &str, base: TriMesh, name: &str) -> Result<CwfAnimation> {
    let mut tk = Tokens::new(text, name);
    tk.keyword("pleat-cwf-animation")?;
    let version = tk.number::<u32>("format version")?;
    if version != ANIMATION_FORMAT_VERSION {
        return Err(tk.err(&format!(
            "format version {version} is not supported (this pleat reads version \
             {ANIMATION_FORMAT_VERSION})"
        )));
    }
    let nv = tk.labelled("vertices")?;
    let ne = tk.labelled("edges")?;
    let nf = tk.labelled("faces")?;
    tk.keyword("connectivity")?;
    let hash_text = tk.next()?;
    let hash = u64::from_str_radix(hash_text, 16)
        .map_err(|_| tk.err(&format!("'{hash_text}' is not a 64-bit hex hash")))?;
    let edges = base.edges().len();
    let want = connectivity_hash(&base);
    if nv != base.vertex_count() || ne != edges || nf != base.triangle_count() || hash != want {
        return Err(Error::InvalidArgument(format!(
            "'{name}' was written for a base mesh with {nv} vertices, {ne} edges, {nf} triangles \
             and connectivity hash {hash:016x}; the given base mesh has {} vertices, {edges} \
             edges, {} triangles and hash {want:016x}",
            base.vertex_count(),
            base.triangle_count()
        )));
    }
    let intervals = tk.labelled("guide-frames")?;
    let substeps = tk.labelled("substeps")?;
    if intervals == 0 || intervals > 100_000 {
        return Err(tk.err(&format!("guide-frames {intervals} is not in 1..=100000")));
    }
    tk.keyword("amplitude")?;
    let mut amplitude = [Vec::with_capacity(nv), Vec::with_capacity(nv)];
    for _ in 0..nv {
        amplitude[0].push(tk.number::<f64>("amplitude")?);
        amplitude[1].push(tk.number::<f64>("amplitude")?);
    }
    let mut omega = Vec::with_capacity(intervals + 1);
    let mut zeta = Vec::with_capacity(intervals + 1);
    for n in 0..=intervals {
        tk.keyword("frame")?;
        let got = tk.number::<usize>("frame index")?;
        if got != n {
            return Err(tk.err(&format!("expected 'frame {n}', found 'frame {got}'")));
        }
        tk.keyword("omega")?;
        let w = (0..ne)
            .map(|_| tk.number::<f64>("ω"))
            .collect::<Result<Vec<f64>>>()?;
        tk.keyword("zeta")?;
        let mut z = Vec::with_capacity(nv);
        for _ in 0..nv {
            let re = tk.number::<f64>("Re z̃")?;
            z.push(Complex::new(re, tk.number::<f64>("Im z̃")?));
        }
        omega.push(w);
        zeta.push(z);
    }
    tk.keyword("end")?;
    let template = Cwf::new(
        base,
        omega[0].clone(),
        amplitude[0].clone(),
        zeta[0].clone(),
    )?;
    CwfAnimation::from_guides(&template, amplitude, omega, zeta, substeps)
}

/// Whitespace-separated tokens of non-comment lines, with line numbers for messages.
struct Tokens<'a> {
    it: Box<dyn Iterator<Item = (usize, &'a str)> + 'a>,
    line: usize,
    name: &'a str,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str, name: &'a str) -> Tokens<'a> {
        let it = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim_start().starts_with('#'))
            .flat_map(|(i, l)| l.split_whitespace().map(move |t| (i + 1, t)));
        Tokens {
            it: Box::new(it),
            line: 0,
            name,
        }
    }

    fn err(&self, reason: &str) -> Error {
        Error::Parse {
            path: self.name.to_string(),
            reason: format!("line {}: {reason}", self.line),
        }
    }

    fn next(&mut self) -> Result<&'a str> {
        match self.it.next() {
            Some((l, t)) => {
                self.line = l;
                Ok(t)
            }
            None => Err(Error::Parse {
                path: self.name.to_string(),
                reason: "unexpected end of file".into(),
            }),
        }
    }

    fn keyword(&mut self, kw: &str) -> Result<()> {
        let t = self.next()?;
        if t != kw {
            return Err(self.err(&format!("expected '{kw}', found '{t}'")));
        }
        Ok(())
    }

    fn number<T: std::str::FromStr>(&mut self, what: &str) -> Result<T> {
        let t = self.next()?;
        t.parse()
            .map_err(|_| self.err(&format!("'{t}' is not a valid {what}")))
    }

    fn labelled(&mut self, kw: &str) -> Result<usize> {
        self.keyword(kw)?;
        self.number::<usize>(kw)
    }
}

/// `Ok` when `t ∈ [0, 1]`; an invalid-argument error otherwise (NaN included). Shared by
/// [`CwfAnimation::frame_at`] and the keyframe blends of [`interpolate`](mod@super::interpolate).
pub(crate) fn check_time(t: f64) -> Result<()> {
    if !(0.0..=1.0).contains(&t) {
        return crate::invalid_arg!("t = {t} is outside [0, 1]");
    }
    Ok(())
}
