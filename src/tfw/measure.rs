//! Wave counting on an evaluated wrinkle field (spec "Measurements": "cross-
//! checked by zero crossings of `Re z` on the evaluated mesh").
//!
//! A [`Section`] is a plane; where a mesh crosses it, a per-vertex value (`Re z`, or a
//! displacement) is interpolated along the crossed edges. The samples are ordered along the
//! section curve — by angle about the plane's normal through [`Section::point`] for a closed
//! ring, or by the position along the samples' principal direction for an open line — and
//! **waves = sign changes / 2** (values below [`Section::ignore_fraction`] of the peak |value|
//! are skipped, so rounding noise around a node does not count; a closed ring also counts the
//! change between its last and first sample). [`count_waves`] does this on `Re z` of a
//! [`Cwf`] evaluated at the smooth (wrinkle-free) positions, [`section_waves`] on any mesh and
//! values (the tests use it on the normal displacement of the wrinkled mesh, an independent
//! cross-check). [`count_waves_auto`] picks, among the three axis-aligned planes through the
//! bounding-box centre, the one that crosses the most waves (for `pleat bench tfw` and
//! scene files that name no section).

use crate::mesh::TriMesh;
use crate::tfw::dense::{dot, sub};
use crate::wrinkle::{Cwf, EvalOptions};
use crate::Result;

/// A plane section along which waves are counted (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// A point of the plane; for a closed section, the centre the angles are measured about.
    pub point: [f64; 3],
    /// The plane's normal (any length > 0).
    pub normal: [f64; 3],
    /// Closed ring (ordered by angle about the normal through `point`, last and first samples
    /// compared) or open line (ordered along the principal direction of the samples).
    pub closed: bool,
    /// Samples closer than this to the line through `point` along `normal` are dropped (e.g.
    /// the inner half of a balloon's equator); 0 keeps all.
    pub min_radius: f64,
    /// Samples with |value| below this fraction of the peak |value| are ignored (default 0.01).
    pub ignore_fraction: f64,
}

impl Section {
    /// A closed ring: the plane through `centre` with normal `axis`, ordered by angle about
    /// the axis.
    pub fn ring(centre: [f64; 3], axis: [f64; 3]) -> Section {
        Section {
            point: centre,
            normal: axis,
            closed: true,
            min_radius: 0.0,
            ignore_fraction: 0.01,
        }
    }

    /// An open line: the plane through `point` with normal `normal`, ordered along the
    /// samples' principal direction.
    pub fn line(point: [f64; 3], normal: [f64; 3]) -> Section {
        Section {
            closed: false,
            ..Section::ring(point, normal)
        }
    }
}

/// The result of a wave count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaveCount {
    /// Sign changes / 2 (half waves count ½).
    pub waves: f64,
    /// Peak |value| over the section samples.
    pub peak: f64,
    /// Number of section samples (crossed edges).
    pub samples: usize,
}

/// Two unit vectors spanning the plane orthogonal to unit `n`.
fn plane_frame(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let d = dot(helper, n);
    let u = sub(helper, [d * n[0], d * n[1], d * n[2]]);
    let l = dot(u, u).sqrt();
    let u = [u[0] / l, u[1] / l, u[2] / l];
    let v = [
        n[1] * u[2] - n[2] * u[1],
        n[2] * u[0] - n[0] * u[2],
        n[0] * u[1] - n[1] * u[0],
    ];
    (u, v)
}

/// Where the edges of (`positions`, `triangles`) cross `section`'s plane: the crossing point
/// and the linearly interpolated value (each interior edge appears once per incident face;
/// duplicates have the same value and do not change the count). Points nearer the axis than
/// `min_radius` are dropped.
fn section_samples(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    values: &[f64],
    section: &Section,
) -> Vec<([f64; 3], f64)> {
    let l = dot(section.normal, section.normal).sqrt();
    let n = section.normal.map(|c| c / l);
    let height = |p: [f64; 3]| dot(sub(p, section.point), n);
    let mut out = Vec::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let (ha, hb) = (height(positions[a]), height(positions[b]));
            if (ha < 0.0) == (hb < 0.0) {
                continue;
            }
            let s = ha / (ha - hb);
            let p =
                std::array::from_fn(|i| positions[a][i] + s * (positions[b][i] - positions[a][i]));
            let r = sub(p, section.point);
            let along = dot(r, n);
            let radial = sub(r, [along * n[0], along * n[1], along * n[2]]);
            if dot(radial, radial).sqrt() < section.min_radius {
                continue;
            }
            out.push((p, values[a] + s * (values[b] - values[a])));
        }
    }
    out
}

/// The ordering key of each sample: angle about the normal (closed) or the coordinate along
/// the samples' principal direction in the plane (open).
fn order_keys(samples: &[([f64; 3], f64)], section: &Section) -> Vec<f64> {
    let l = dot(section.normal, section.normal).sqrt();
    let (u, v) = plane_frame(section.normal.map(|c| c / l));
    let planar: Vec<[f64; 2]> = samples
        .iter()
        .map(|(p, _)| {
            let r = sub(*p, section.point);
            [dot(r, u), dot(r, v)]
        })
        .collect();
    if section.closed {
        return planar.iter().map(|q| q[1].atan2(q[0])).collect();
    }
    // principal direction of the 2×2 covariance
    let m = planar.len().max(1) as f64;
    let c = planar
        .iter()
        .fold([0.0; 2], |c, q| [c[0] + q[0] / m, c[1] + q[1] / m]);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for q in &planar {
        let (x, y) = (q[0] - c[0], q[1] - c[1]);
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let d = [theta.cos(), theta.sin()];
    planar.iter().map(|q| q[0] * d[0] + q[1] * d[1]).collect()
}

/// Counts waves along `section` of per-vertex `values` on the mesh (`positions`,
/// `triangles`): sign changes of the interpolated values, ordered along the section curve,
/// divided by 2 (module docs). Deterministic; an empty section gives 0 waves.
pub fn section_waves(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    values: &[f64],
    section: &Section,
) -> WaveCount {
    let samples = section_samples(positions, triangles, values, section);
    let keys = order_keys(&samples, section);
    let mut order: Vec<usize> = (0..samples.len()).collect();
    order.sort_by(|&i, &j| keys[i].total_cmp(&keys[j]).then(i.cmp(&j)));
    let peak = samples.iter().fold(0.0f64, |m, s| m.max(s.1.abs()));
    let signs: Vec<bool> = order
        .iter()
        .map(|&i| samples[i].1)
        .filter(|v| v.abs() >= section.ignore_fraction * peak && *v != 0.0)
        .map(|v| v > 0.0)
        .collect();
    let mut changes = signs.windows(2).filter(|w| w[0] != w[1]).count();
    if section.closed && signs.len() > 1 && signs[0] != signs[signs.len() - 1] {
        changes += 1;
    }
    WaveCount {
        waves: changes as f64 / 2.0,
        peak,
        samples: samples.len(),
    }
}

/// Counts waves of `Re z` along `section` on `cwf` evaluated with `levels` Loop subdivisions,
/// the section cut through the smooth (wrinkle-free) positions; `peak` is the peak |Re z|
/// on the section (m). Errors: those of [`Cwf::evaluate`].
pub fn count_waves(cwf: &Cwf, levels: usize, section: &Section) -> Result<WaveCount> {
    let e = evaluated_re_z(cwf, levels)?;
    Ok(section_waves(&e.positions, &e.triangles, &e.re, section))
}

/// Smooth positions, triangles and `Re z` of an evaluation.
struct ReZ {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    re: Vec<f64>,
}

/// [`ReZ`] of the `levels`-level evaluation.
fn evaluated_re_z(cwf: &Cwf, levels: usize) -> Result<ReZ> {
    let opts = EvalOptions {
        want_z: true,
        ..EvalOptions::default()
    };
    let (ev, _) = cwf.evaluate(levels, &opts)?;
    let re =
        ev.z.as_ref()
            .map(|z| z.iter().map(|c| c.re).collect())
            .unwrap_or_default();
    let positions = ev
        .smooth_positions
        .clone()
        .unwrap_or_else(|| ev.mesh.positions().to_vec());
    Ok(ReZ {
        positions,
        triangles: ev.mesh.triangles().to_vec(),
        re,
    })
}

/// The three candidate sections of [`count_waves_auto`] for `mesh`: per coordinate axis, the
/// plane through the bounding-box centre normal to it, closed when its samples surround the
/// centre (no angular gap above 90°).
pub fn candidate_sections(mesh: &TriMesh) -> Vec<Section> {
    let p = mesh.positions();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let centre: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let zeros = vec![0.0; p.len()];
    (0..3)
        .map(|axis| {
            let mut n = [0.0; 3];
            n[axis] = 1.0;
            let ring = Section::ring(centre, n);
            let samples = section_samples(p, mesh.triangles(), &zeros, &ring);
            let mut angles = order_keys(&samples, &ring);
            angles.sort_by(f64::total_cmp);
            let closed = angles.len() > 2 && {
                let wrap = angles[0] + std::f64::consts::TAU - angles[angles.len() - 1];
                angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, f64::max)
                    <= std::f64::consts::FRAC_PI_2
            };
            Section { closed, ..ring }
        })
        .collect()
}

/// The section (among [`candidate_sections`] of the cwf's base mesh) crossing the most waves
/// of `Re z` at `levels`, and its count (ties: the lower axis). One evaluation.
pub fn count_waves_auto(cwf: &Cwf, levels: usize) -> Result<(Section, WaveCount)> {
    let e = evaluated_re_z(cwf, levels)?;
    let mut best: Option<(Section, WaveCount)> = None;
    for s in candidate_sections(cwf.base()) {
        let c = section_waves(&e.positions, &e.triangles, &e.re, &s);
        if best.as_ref().is_none_or(|b| c.waves > b.1.waves) {
            best = Some((s, c));
        }
    }
    Ok(best.expect("three candidates"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat strip `[0, lx] × [0, ly]` triangulated on an `nx × ny` grid.
    fn strip(nx: usize, ny: usize, lx: f64, ly: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                p.push([
                    lx * i as f64 / (nx - 1) as f64,
                    ly * j as f64 / (ny - 1) as f64,
                    0.0,
                ]);
            }
        }
        let mut t = Vec::new();
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let v = (j * nx + i) as u32;
                let w = nx as u32;
                t.push([v, v + 1, v + w + 1]);
                t.push([v, v + w + 1, v + w]);
            }
        }
        (p, t)
    }

    #[test]
    fn counts_periods_of_a_sine_along_an_open_line() {
        let (p, t) = strip(201, 5, 1.0, 0.1);
        // 7 periods plus a phase so no sample is exactly 0
        let vals: Vec<f64> = p
            .iter()
            .map(|q| (std::f64::consts::TAU * 7.0 * q[0] + 0.3).sin())
            .collect();
        let c = section_waves(
            &p,
            &t,
            &vals,
            &Section::line([0.5, 0.05, 0.0], [0.0, 1.0, 0.0]),
        );
        assert_eq!(c.waves, 7.0);
        assert!((c.peak - 1.0).abs() < 1e-3);
    }

    #[test]
    fn counts_waves_around_a_closed_ring() {
        // a cylinder r = 1 around z with cos(12 θ + 0.2) on it
        let (flat, t) = strip(97, 5, std::f64::consts::TAU, 1.0);
        let p: Vec<[f64; 3]> = flat
            .iter()
            .map(|q| [q[0].cos(), q[0].sin(), q[1]])
            .collect();
        let vals: Vec<f64> = flat.iter().map(|q| (12.0 * q[0] + 0.2).cos()).collect();
        let c = section_waves(
            &p,
            &t,
            &vals,
            &Section::ring([0.0, 0.0, 0.5], [0.0, 0.0, 1.0]),
        );
        assert_eq!(c.waves, 12.0);
        let mesh = TriMesh::new(p, t).unwrap();
        let cands = candidate_sections(&mesh);
        assert!(cands[2].closed && !cands[0].closed && !cands[1].closed);
    }
}
