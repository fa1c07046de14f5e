//! Keyframe pairs and plotting for the interpolation benchmark (`pleat bench wrinkle`,
//! `benches/wrinkle_interp.rs`): the dissertation's kinds of edits (§3.4.2, Table B.1) on any
//! base mesh, and a dependency-free SVG line plot.
//!
//! Not part of the library's API: the CLI includes this file as a module, and the bench includes
//! the same file with `#[path = "../src/bin/pleat/interp_bench.rs"]`, so it exists once. It uses
//! only the library's public API.

use std::fmt::Write as _;

use pleat::geom::{tri_normal, Vec3};
use pleat::mesh::TriMesh;
use pleat::wrinkle::{Cwf, FrequencyField, KnoppelOptions};
use pleat::Result;

/// The kind of keyframe pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PairKind {
    /// The wave vector turned by 90° in every tangent plane (Figs. 3.1, 3.10).
    GlobalRotation,
    /// Frequency × 3 and amplitude ÷ 3 everywhere (Fig. 3.5).
    FrequencyTripled,
    /// 90° rotation inside a geodesic-ish ball around vertex 0 (a quarter of the bounding-box
    /// diagonal), blended smoothly to the unchanged field (Fig. 3.7).
    LocalRotation,
}

impl PairKind {
    /// All kinds, in benchmark order.
    pub const ALL: [PairKind; 3] = [
        PairKind::GlobalRotation,
        PairKind::FrequencyTripled,
        PairKind::LocalRotation,
    ];

    /// A short name ("rotation", "frequency x3", "local rotation").
    pub fn name(self) -> &'static str {
        match self {
            PairKind::GlobalRotation => "rotation",
            PairKind::FrequencyTripled => "frequency x3",
            PairKind::LocalRotation => "local rotation",
        }
    }
}

/// Two keyframes of `kind` on `mesh`: wave vectors are the tangent projection of the x axis
/// scaled to `wavelengths` periods per bounding-box diagonal (and their edit), amplitude
/// `0.005 · diagonal`, phases by Knöppel et al. Deterministic.
pub fn keyframe_pair(mesh: &TriMesh, kind: PairKind, wavelengths: f64) -> Result<(Cwf, Cwf)> {
    let diag = mesh.bbox_diagonal();
    let kmag = 2.0 * std::f64::consts::PI * wavelengths / diag;
    let normals = vertex_normals(mesh);
    let k0: Vec<Vec3> = normals
        .iter()
        .map(|&n| {
            let d = Vec3::X;
            (d - n * d.dot(n)) * kmag
        })
        .collect();
    let turned: Vec<Vec3> = k0.iter().zip(&normals).map(|(&k, &n)| n.cross(k)).collect();
    let n = mesh.vertex_count();
    let a0 = 0.005 * diag;
    let (k1, amp1) = match kind {
        PairKind::GlobalRotation => (turned, vec![a0; n]),
        PairKind::FrequencyTripled => (k0.iter().map(|&k| k * 3.0).collect(), vec![a0 / 3.0; n]),
        PairKind::LocalRotation => {
            let c = Vec3::from(mesh.positions()[0]);
            let r = 0.25 * diag;
            let k1 = (0..n)
                .map(|j| {
                    let d = (Vec3::from(mesh.positions()[j]) - c).length() / r;
                    let w = smoothstep(1.0 - (d - 0.6) / 0.4);
                    k0[j] * (1.0 - w) + turned[j] * w
                })
                .collect();
            (k1, vec![a0; n])
        }
    };
    let opts = KnoppelOptions::default();
    let (k0, k1) = (to_arrays(&k0), to_arrays(&k1));
    let (a, _) = Cwf::from_frequency_field(
        mesh.clone(),
        FrequencyField::PerVertex(&k0),
        vec![a0; n],
        &opts,
    )?;
    let (b, _) =
        Cwf::from_frequency_field(mesh.clone(), FrequencyField::PerVertex(&k1), amp1, &opts)?;
    Ok((a, b))
}

fn to_arrays(v: &[Vec3]) -> Vec<[f64; 3]> {
    v.iter().map(|k| k.to_array()).collect()
}

fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Area-weighted unit vertex normals (zero where undefined).
fn vertex_normals(m: &TriMesh) -> Vec<Vec3> {
    let x = |v: u32| Vec3::from(m.positions()[v as usize]);
    let mut acc = vec![Vec3::ZERO; m.vertex_count()];
    for t in m.triangles() {
        let f = tri_normal(x(t[0]), x(t[1]), x(t[2]));
        for &v in t {
            acc[v as usize] += f;
        }
    }
    acc.iter()
        .map(|&a| {
            let l = a.length();
            // not `geom::normalized`: an infinite length is scaled here, not rejected
            if l > 0.0 {
                a * (1.0 / l)
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// One line of an [`svg_plot`]: a label and its `(x, y)` points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in data coordinates.
    pub points: Vec<(f64, f64)>,
}

/// A self-contained SVG line plot (640×400) of `series`, optionally with a log₁₀ y axis
/// (non-positive values are dropped there). Plain string formatting, no dependency.
pub fn svg_plot(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_y: bool,
) -> String {
    let (w, h, ml, mr, mt, mb) = (640.0, 400.0, 70.0, 170.0, 40.0, 50.0);
    let ty = |y: f64| if log_y { y.log10() } else { y };
    let pts: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0))
                .map(|&(x, y)| (x, ty(y)))
                .collect()
        })
        .collect();
    let all = pts.iter().flatten();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    if x1 - x0 < 1e-12 {
        x1 = x0 + 1.0;
    }
    if y1 - y0 < 1e-12 {
        y1 = y0 + 1.0;
    }
    let px = |x: f64| ml + (x - x0) / (x1 - x0) * (w - ml - mr);
    let py = |y: f64| h - mb - (y - y0) / (y1 - y0) * (h - mt - mb);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="14">{}</text>"#,
        (w - mr + ml) / 2.0,
        esc(title)
    );
    let _ = writeln!(
        s,
        r#"<path d="M{ml} {mt} V{} H{}" stroke="black" fill="none"/>"#,
        h - mb,
        w - mr
    );
    for i in 0..=4 {
        let fx = x0 + (x1 - x0) * i as f64 / 4.0;
        let fy = y0 + (y1 - y0) * i as f64 / 4.0;
        let ylab = if log_y {
            format!("1e{fy:.1}")
        } else {
            format!("{fy:.3}")
        };
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{}" text-anchor="middle">{fx:.3}</text>"#,
            px(fx),
            h - mb + 16.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{:.1}" text-anchor="end">{ylab}</text>"#,
            ml - 4.0,
            py(fy) + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        (w - mr + ml) / 2.0,
        h - 10.0,
        esc(x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="16" y="{}" text-anchor="middle" transform="rotate(-90 16 {})">{}</text>"#,
        h / 2.0,
        h / 2.0,
        esc(y_label)
    );
    const COLORS: [&str; 8] = [
        "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
    ];
    for (i, (ser, p)) in series.iter().zip(&pts).enumerate() {
        let c = COLORS[i % COLORS.len()];
        let d: Vec<String> = p
            .iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
            .collect();
        if !d.is_empty() {
            let _ = writeln!(
                s,
                r#"<polyline points="{}" stroke="{c}" fill="none" stroke-width="1.5"/>"#,
                d.join(" ")
            );
        }
        let ly = mt + 16.0 * i as f64;
        let _ = writeln!(
            s,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="2"/>"#,
            w - mr + 10.0,
            w - mr + 30.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            w - mr + 34.0,
            ly + 4.0,
            esc(&ser.label)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn esc(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
