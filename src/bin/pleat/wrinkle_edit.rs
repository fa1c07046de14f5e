//! `pleat wrinkle design` and `pleat wrinkle edit` (dissertation §3.6): parse sources
//! and region specs, run [`pleat::wrinkle::design`] / [`pleat::wrinkle::edit`], print each
//! solve's seconds and residual, write the keyframe.

use std::path::Path;

use pleat::mesh::io::read_mesh;
use pleat::wrinkle::{
    design, edit, grow_faces, read_cwf, write_cwf, Adjacency, DesignOptions, EditOptions,
    FaceClass, PhaseCoupling, RegionEdit, WrinkleSource,
};
use pleat::Error;

/// A failure: `(input error?, message)`; input errors (bad arguments, unreadable files) exit 2.
pub type Fail = (bool, String);

fn classify(e: Error) -> Fail {
    let input = matches!(
        e,
        Error::InvalidArgument(_) | Error::InvalidMesh(_) | Error::Io { .. } | Error::Parse { .. }
    );
    (input, e.to_string())
}

fn bad(msg: String) -> Fail {
    (true, msg)
}

/// Parses `V,KX,KY,KZ,A[,RINGS]` (rings default 5).
pub fn parse_source(s: &str) -> Result<WrinkleSource, Fail> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if !(5..=6).contains(&parts.len()) {
        return Err(bad(format!(
            "--source {s:?}: expected V,KX,KY,KZ,A[,RINGS] (vertex, wave vector, amplitude, rings)"
        )));
    }
    let num = |i: usize| -> Result<f64, Fail> {
        parts[i]
            .parse::<f64>()
            .map_err(|_| bad(format!("--source {s:?}: field {} is not a number", i + 1)))
    };
    let int = |i: usize| -> Result<u64, Fail> {
        parts[i]
            .parse::<u64>()
            .map_err(|_| bad(format!("--source {s:?}: field {} is not a count", i + 1)))
    };
    Ok(WrinkleSource {
        vertex: u32::try_from(int(0)?)
            .map_err(|_| bad(format!("--source {s:?}: vertex too large")))?,
        wave_vector: [num(1)?, num(2)?, num(3)?],
        amplitude: num(4)?,
        rings: if parts.len() == 6 {
            int(5)? as usize
        } else {
            5
        },
    })
}

/// One `--region` spec: `seed=F` (face) or `vertex=V`, `rings=N` (default 5), `interface=M`
/// (default 3), `rotate=DEG`, `scale=σ` (or `freq=σ`), `amplitude=μ` (or `amp=μ`) or `couple`.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionSpec {
    seed_faces: Vec<u32>,
    seed_vertices: Vec<u32>,
    rings: usize,
    edit: RegionEdit,
    couple: bool,
}

/// Parses a `--region` spec (see [`RegionSpec`]).
pub fn parse_region(s: &str) -> Result<RegionSpec, Fail> {
    let mut r = RegionSpec {
        seed_faces: Vec::new(),
        seed_vertices: Vec::new(),
        rings: 5,
        edit: RegionEdit::new(Vec::new()),
        couple: false,
    };
    let mut amplitude_given = false;
    for item in s.split(',').map(str::trim).filter(|i| !i.is_empty()) {
        if item == "couple" {
            r.couple = true;
            continue;
        }
        let (k, v) = item
            .split_once('=')
            .ok_or_else(|| bad(format!("--region {s:?}: {item:?} is not key=value")))?;
        let num = || -> Result<f64, Fail> {
            v.parse::<f64>()
                .map_err(|_| bad(format!("--region {s:?}: {k}={v:?} is not a number")))
        };
        let int = || -> Result<u32, Fail> {
            v.parse::<u32>()
                .map_err(|_| bad(format!("--region {s:?}: {k}={v:?} is not a count")))
        };
        match k {
            "seed" | "face" => r.seed_faces.push(int()?),
            "vertex" => r.seed_vertices.push(int()?),
            "rings" => r.rings = int()? as usize,
            "interface" => r.edit.interface_rings = int()? as usize,
            "rotate" => r.edit.rotate = num()?.to_radians(),
            "scale" | "freq" => r.edit.frequency_scale = num()?,
            "amplitude" | "amp" => {
                r.edit.amplitude_scale = num()?;
                amplitude_given = true;
            }
            _ => return Err(bad(format!("--region {s:?}: unknown key {k:?}"))),
        }
    }
    if r.couple && amplitude_given {
        return Err(bad(format!(
            "--region {s:?}: give either amplitude= or couple"
        )));
    }
    if r.seed_faces.is_empty() && r.seed_vertices.is_empty() {
        return Err(bad(format!(
            "--region {s:?}: no seed (seed=FACE or vertex=V)"
        )));
    }
    Ok(r)
}

/// `pleat wrinkle design`.
pub fn run_design(
    base: &Path,
    sources: &[String],
    heat_time: f64,
    reference: bool,
    out: &Path,
) -> Result<(), Fail> {
    let mesh = read_mesh(base).map_err(classify)?;
    let sources = sources
        .iter()
        .map(|s| parse_source(s))
        .collect::<Result<Vec<_>, _>>()?;
    let mut opts = DesignOptions {
        heat_time,
        ..DesignOptions::default()
    };
    if reference {
        opts.adjacency = Adjacency::Edge;
        opts.gamma = 0.25;
        opts.pin_sources = false;
    }
    let (cwf, rep) = design(mesh, &sources, &opts).map_err(classify)?;
    eprintln!(
        "design: {} sources, influenced {} vertices / {} faces / {} edges",
        sources.len(),
        rep.influenced[0],
        rep.influenced[1],
        rep.influenced[2]
    );
    eprintln!(
        "  vector heat  {:.4} s  residual {:.2e}",
        rep.seconds[0], rep.heat_residual
    );
    eprintln!(
        "  amplitude    {:.4} s  residual {:.2e}  clamped {}",
        rep.seconds[1], rep.amplitude_residual, rep.clamped
    );
    eprintln!(
        "  phase        {:.4} s  residual {:.2e}  eigenvalue {:.4e}",
        rep.seconds[2], rep.knoppel.residual, rep.knoppel.eigenvalue
    );
    write_cwf(out, &cwf).map_err(classify)?;
    Ok(())
}

/// The `pleat wrinkle edit` flags that set the solve's options (besides the regions).
#[derive(Debug, Clone, PartialEq)]
pub struct EditTuning {
    /// `--adjacency`: `vertex` or `edge` (ignored with `--reference` unless given).
    pub adjacency: String,
    /// `--reference`: start from [`EditOptions::reference`].
    pub reference: bool,
    /// `--compat-target` ([`EditOptions::compat_target`]).
    pub compat_target: f64,
    /// `--max-interface-rings` ([`EditOptions::max_interface_rings`]).
    pub max_interface_rings: usize,
    /// `--edit-weight` ([`EditOptions::edit_weight`]).
    pub edit_weight: f64,
}

impl EditTuning {
    /// Refuses NaN, negative or out-of-range values with a message naming the flag.
    fn check(&self) -> Result<(), Fail> {
        if !(self.compat_target.is_finite() && self.compat_target >= 0.0) {
            return Err(bad(format!(
                "--compat-target {}: must be finite and ≥ 0 radians (0: the requested widths)",
                self.compat_target
            )));
        }
        if self.max_interface_rings == 0 {
            return Err(bad("--max-interface-rings 0: must be ≥ 1".into()));
        }
        if !(self.edit_weight.is_finite() && self.edit_weight >= 1.0) {
            return Err(bad(format!(
                "--edit-weight {}: must be finite and ≥ 1",
                self.edit_weight
            )));
        }
        Ok(())
    }
}

/// `pleat wrinkle edit`.
pub fn run_edit(
    base: &Path,
    cwf: &Path,
    regions: &[String],
    tuning: &EditTuning,
    labels: Option<&Path>,
    out: &Path,
) -> Result<(), Fail> {
    let mesh = read_mesh(base).map_err(classify)?;
    let k0 = read_cwf(cwf, mesh.clone()).map_err(classify)?;
    let reference = tuning.reference;
    let mut opts = if reference {
        EditOptions::reference()
    } else {
        EditOptions::default()
    };
    opts.adjacency = match tuning.adjacency.as_str() {
        "vertex" => Adjacency::Vertex,
        "edge" => Adjacency::Edge,
        _ if reference => opts.adjacency,
        other => return Err(bad(format!("--adjacency {other:?}: vertex or edge"))),
    };
    tuning.check()?;
    opts.compat_target = tuning.compat_target;
    opts.max_interface_rings = tuning.max_interface_rings;
    opts.edit_weight = tuning.edit_weight;
    let mut edits = Vec::new();
    for s in regions {
        let spec = parse_region(s)?;
        let faces = grow_faces(
            &mesh,
            &spec.seed_faces,
            &spec.seed_vertices,
            spec.rings,
            opts.adjacency,
        )
        .map_err(classify)?;
        let mut e = RegionEdit { faces, ..spec.edit };
        if spec.couple {
            e = e.coupled();
        }
        edits.push(e);
    }
    let (k1, rep) = edit(&k0, &edits, &opts).map_err(classify)?;
    eprintln!(
        "edit: {} regions; faces fixed/edit/interface {:?}, vertices {:?}, edges {:?}",
        edits.len(),
        rep.face_counts,
        rep.vertex_counts,
        rep.edge_counts
    );
    if opts.compat_target > 0.0 {
        eprintln!(
            "  interface rings used {:?} ({} edit(s); widened while compat RMS > {} rad, up to \
             {} rings)",
            rep.interface_rings, rep.attempts, opts.compat_target, opts.max_interface_rings
        );
    } else {
        eprintln!(
            "  interface rings used {:?} (as requested; --compat-target off)",
            rep.interface_rings
        );
    }
    eprintln!("  labels + ω¹   {:.4} s", rep.seconds[0]);
    eprintln!(
        "  ω (3.26)     {:.4} s  residual {:.2e}",
        rep.seconds[1], rep.omega_residual
    );
    eprintln!(
        "  a (3.27)     {:.4} s  residual {:.2e}  clamped {}",
        rep.seconds[2], rep.amplitude_residual, rep.clamped
    );
    let phase = match opts.phase {
        PhaseCoupling::Unit => "unit",
        PhaseCoupling::AmplitudeWeighted => "amplitude-weighted",
    };
    eprintln!(
        "  z̃ (3.28, {phase}) {:.4} s  residual {:.2e}  eigenvalue {:.4e}  |s| {:.4}{}{}",
        rep.seconds[3],
        rep.phase_residual,
        rep.eigenvalue,
        rep.s.abs(),
        if rep.global {
            "  (global edit: Knöppel)"
        } else {
            ""
        },
        if rep.phase_fallback {
            "  (fallback s = 1)"
        } else {
            ""
        }
    );
    eprintln!(
        "  compatibility RMS on edit + interface edges {:.3} rad (edit {:.3}, interface {:.3}; \
         floor without singularities {:.3})",
        rep.compat_rms, rep.compat_rms_by_class[0], rep.compat_rms_by_class[1], rep.compat_floor
    );
    if let Some(path) = labels {
        let text: String = rep
            .face_class
            .iter()
            .map(|c| match c {
                FaceClass::Fixed => "0\n",
                FaceClass::Edit => "1\n",
                FaceClass::Interface => "2\n",
            })
            .collect();
        std::fs::write(path, text)
            .map_err(|e| (false, format!("writing {}: {e}", path.display())))?;
    }
    write_cwf(out, &k1).map_err(classify)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_sources_and_regions() {
        let s = parse_source("12,1,2,3,0.01").unwrap();
        assert_eq!((s.vertex, s.rings), (12, 5));
        assert!(parse_source("1,2").is_err());
        let r = parse_region("seed=532,rings=7,interface=3,rotate=90,scale=2,couple").unwrap();
        assert_eq!(r.seed_faces, vec![532]);
        assert!((r.edit.rotate - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert!(r.couple);
        assert!(parse_region("rings=3").is_err());
        assert!(parse_region("seed=1,amplitude=2,couple").is_err());
    }
}
