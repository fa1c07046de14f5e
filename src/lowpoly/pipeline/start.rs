//! The choice of a LOD's start surface ([`LodStart`]): the clean-input check ([`check_clean`],
//! by the independent verifier after exact welding), the welded input a clean LOD starts from,
//! and the decision between it and the offset surface (`choose_start`, honouring the budget).
//! Cages always start from the offset surface.

use super::params::{LodParams, LodStart, Mode, AUTO_MAX_GENUS};
use super::progress::Reporter;
use crate::mesh::TriMesh;
use crate::report::Progress;
use crate::verify::{MeshReport, ReportOptions};
use crate::{Error, Result};

/// Checks that `input` is *clean* — after exact welding (`ReportOptions::weld`, as
/// `meshcheck --weld`): watertight, manifold, consistently and outward oriented, without
/// degenerate faces, self-intersection-free, all by the independent verifier
/// [`MeshReport`] — and returns the welded input (unreferenced vertices dropped, first-use
/// order of the representatives) that [`LodStart::Input`] starts from. `Err` names the
/// first property that fails.
pub fn check_clean(input: &TriMesh) -> std::result::Result<TriMesh, String> {
    clean_welded(input, &|_| false, &mut |_| true)
        .expect("never cancelled")
        .map(|c| c.mesh)
}

/// A clean input ([`check_clean`]) and what [`LodStart::Auto`] decides from.
struct CleanInput {
    /// The welded input.
    mesh: TriMesh,
    /// Its genus and components.
    topology: CleanTopology,
}

/// The topology of a clean input that [`LodStart::Auto`] decides from.
struct CleanTopology {
    /// Total genus.
    genus: i64,
    /// Connected components.
    components: usize,
}

impl CleanTopology {
    /// Whether [`LodStart::Auto`] starts from the offset surface rather than this input.
    fn auto_refuses(&self) -> bool {
        self.genus > AUTO_MAX_GENUS || self.components > 1
    }
}

/// [`check_clean`] with the input's total genus, and a progress callback (a cancellation
/// point; `None` when it returns `false`). Topology first, the self-intersection pass only when topology is clean, so
/// that `LodStart::Auto` costs a dirty input only the topology pass. `skip(&topology)`: the
/// caller will not use a clean input of this topology (`LodStart::Auto` and too many
/// components or too high a genus), so `Err` without the self-intersection pass.
fn clean_welded(
    input: &TriMesh,
    skip: &dyn Fn(&CleanTopology) -> bool,
    keep_going: &mut dyn FnMut(f64) -> bool,
) -> Option<std::result::Result<CleanInput, String>> {
    let topo = MeshReport::compute_with_progress(
        input,
        &ReportOptions {
            self_intersections: false,
            weld: true,
        },
        &mut |f| keep_going(0.1 * f),
    )?;
    let failing = [
        ("closed (watertight)", topo.is_watertight),
        ("manifold", topo.is_manifold),
        ("consistently oriented", topo.consistently_oriented),
        (
            "free of degenerate faces",
            topo.n_degenerate_faces == 0 && topo.n_combinatorially_degenerate_faces == 0,
        ),
        (
            "outward oriented",
            topo.n_inward_oriented_components == Some(0),
        ),
    ]
    .into_iter()
    .find(|(_, holds)| !holds);
    if let Some((name, _)) = failing {
        return Some(Err(format!("the input is not {name} after exact welding")));
    }
    let topology = CleanTopology {
        genus: topo.total_genus.unwrap_or(0),
        components: topo.n_components,
    };
    if skip(&topology) {
        return Some(Err("the input's topology is not started from".into()));
    }
    let welded = weld_compact(input);
    let si = MeshReport::compute_with_progress(&welded, &ReportOptions::default(), &mut |f| {
        keep_going(0.1 + 0.9 * f)
    })?;
    if si.self_intersection_free != Some(true) {
        return Some(Err(format!(
            "the input is not self-intersection-free after exact welding ({} intersecting \
             pairs)",
            si.n_self_intersecting_pairs.unwrap_or(0)
        )));
    }
    Some(Ok(CleanInput {
        mesh: welded,
        topology,
    }))
}

/// `input` with exactly coincident vertices merged (`crate::mesh::ExactWeld`) and only the
/// referenced representatives kept, numbered in order of first use by the triangles.
fn weld_compact(input: &TriMesh) -> TriMesh {
    let weld = crate::mesh::ExactWeld::compute(input.positions());
    let mut new_index = vec![u32::MAX; input.vertex_count()];
    let mut positions = Vec::new();
    let triangles: Vec<[u32; 3]> = weld
        .apply(input.triangles())
        .into_iter()
        .map(|t| {
            t.map(|v| {
                let slot = &mut new_index[v as usize];
                if *slot == u32::MAX {
                    *slot = positions.len() as u32;
                    positions.push(input.positions()[v as usize]);
                }
                *slot
            })
        })
        .collect();
    TriMesh::new(positions, triangles).expect("a welded copy of a valid mesh is valid")
}

/// The start of a LOD bake (`None`: the offset surface) by `params.start`, with
/// `InvalidArgument` for [`LodStart::Input`] on an input that is not clean. Cages: `None`.
pub(super) fn choose_start(
    input: &TriMesh,
    params: &LodParams,
    mode: Mode,
    rep: &mut Reporter<'_, '_>,
) -> Result<Option<TriMesh>> {
    if mode == Mode::Cage || params.start == LodStart::Offset {
        return Ok(None);
    }
    let auto = params.start == LodStart::Auto;
    // the budget decision honours the start taken: an input start must fit its own estimate
    let fits = params.input_start_may_fit(input);
    if !fits && params.start == LodStart::Input {
        return Err(Error::LimitExceeded(format!(
            "starting from the input needs about {:.0} MiB at screen size {} but the memory \
             budget is {:.0} MiB",
            params.input_start_estimate(input) / (1u64 << 20) as f64,
            params.screen_size,
            params.memory_budget_bytes as f64 / (1u64 << 20) as f64
        )));
    }
    if auto && !fits {
        // Auto then takes the offset (no clean-input check); `run` checks its budget
        return Ok(None);
    }
    // Auto never starts from an input it refuses by topology: no self-intersection pass then
    let skip = |t: &CleanTopology| auto && t.auto_refuses();
    let clean =
        clean_welded(input, &skip, &mut |f| rep.report("setup", f)).ok_or(Error::Cancelled)?;
    match (clean, params.start) {
        (Ok(c), LodStart::Auto) if c.topology.auto_refuses() => Ok(None),
        (Ok(c), _) => Ok(Some(c.mesh)),
        (Err(why), LodStart::Input) => Err(Error::InvalidArgument(format!(
            "start = input needs a clean input: {why}; use start = auto or offset"
        ))),
        (Err(_), _) => Ok(None),
    }
}

impl LodParams {
    /// Whether a LOD of `input` with these parameters starts from the input ([`LodStart`]):
    /// the decision `generate` takes, including the clean-input check (a self-intersection
    /// pass on a clean-topology input) and the budget. `Err` as `generate` for
    /// [`LodStart::Input`] on an input that is not clean or does not fit. For tools.
    pub fn lod_starts_from_input(&self, input: &TriMesh) -> Result<bool> {
        let mut quiet = |_: Progress<'_>| true;
        let mut rep = Reporter::new(&mut quiet);
        choose_start(input, self, Mode::Lod, &mut rep).map(|s| s.is_some())
    }
}
