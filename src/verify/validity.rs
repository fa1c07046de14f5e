//! [`MeshReport`]: the independent verifier of pleat's promises (watertight, manifold,
//! self-intersection-free) for any triangle soup, defined key by key like `meshcheck`'s JSON.
//!
//! May import: `crate::mesh`, `crate::spatial`, `crate::report` (never a producer of meshes:
//! `lowpoly`, `cage`, `wrinkle`).

use std::borrow::Cow;

use rayon::prelude::*;

use crate::mesh::{ExactWeld, TriMesh};
use crate::report::{Stage, StageTimes};
use crate::spatial::is_collinear;
use crate::spatial::self_intersect::{count_self_intersections_welded, MAX_COUNTED_HITS};

/// What [`MeshReport::compute_with`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReportOptions {
    /// Run the self-intersection pass (the most expensive part). When `false`,
    /// [`MeshReport::n_self_intersecting_pairs`] and
    /// [`MeshReport::self_intersection_free`] are `None`. Default `true`.
    pub self_intersections: bool,
    /// Analyse topology after merging exactly coincident points (meshcheck `--weld`). Default
    /// `false`: the soup is analysed exactly as given, so unwelded seams are open boundaries.
    pub weld: bool,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            self_intersections: true,
            weld: false,
        }
    }
}

/// What a triangle soup is — counts, components, boundary, manifoldness, orientation, Euler
/// characteristic and genus, self-intersections — computed by code that is independent of every
/// algorithm producing meshes in pleat.
///
/// Every field is defined exactly as the same-named key of the evaluation harness's `meshcheck`
/// JSON (`../shared/tools/src/meshcheck.cpp`, CGAL 5.5), so the two can be compared number for
/// number (`tests/report_corpus.rs` does, on the 25 corpus meshes):
/// - topology is computed on the soup exactly as given (option [`ReportOptions::weld`] merges
///   exactly coincident points first, like `meshcheck --weld`);
/// - self-intersections are always computed after exact welding (see
///   [`crate::spatial::self_intersect`]).
///
/// Differences from meshcheck: a [`TriMesh`] holds triangles only, so `n_faces` equals
/// `n_triangles` (meshcheck counts file polygons before fan triangulation); meshcheck's
/// `cgal_is_polygon_mesh`, `si_method` and timings have no counterpart;
/// [`MeshReport::n_coincident_vertices`] and [`MeshReport::n_misoriented_manifold_edges`] are
/// additions.
///
/// Cost: O(F log F), dominated by the self-intersection pass: 2.2 s for a closed 1.3 M-triangle
/// mesh on the 2-core development machine, 4 s on one core (`benches/report.rs`).
/// Deterministic whatever the number of threads.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshReport {
    /// Number of vertices in the buffer, referenced or not (`n_vertices`).
    pub n_vertices: usize,
    /// Number of triangles (`n_faces` and `n_triangles` in the JSON; equal for a [`TriMesh`]).
    pub n_faces: usize,
    /// Whether topology was analysed after exact welding ([`ReportOptions::weld`]).
    pub welded: bool,
    /// Vertices that are not the first (smallest-index) of a group of vertices with exactly
    /// equal coordinates: `Σ (group size − 1)` (`n_duplicate_points`; always on the input).
    pub n_duplicate_points: usize,
    /// Vertices that share their exact position with at least one other vertex: `Σ group size`
    /// over groups of size ≥ 2 (not in meshcheck; the corpus MANIFEST's
    /// `n_coincident_vertices`).
    pub n_coincident_vertices: usize,
    /// Vertices used by at least one triangle (`n_referenced_vertices`).
    pub n_referenced_vertices: usize,
    /// Vertices used by no triangle; with `welded`, merged duplicates are not counted
    /// (`n_isolated_vertices`).
    pub n_isolated_vertices: usize,
    /// Triangles whose corners are exactly collinear, including repeated indices: zero area
    /// (`n_degenerate_faces`, CGAL `collinear`, exact).
    pub n_degenerate_faces: usize,
    /// Triangles with a repeated vertex index (`n_combinatorially_degenerate_faces`).
    pub n_combinatorially_degenerate_faces: usize,
    /// Sum of the areas of the non-degenerate triangles (`surface_area`).
    pub surface_area: f64,
    /// Triangles whose vertex-index set equals that of an earlier triangle, in either
    /// orientation: `Σ (group size − 1)` (`n_duplicate_faces`).
    pub n_duplicate_faces: usize,
    /// Distinct undirected edges `{a, b}`, `a ≠ b` (`n_edges`).
    pub n_edges: usize,
    /// Edges with exactly one incident triangle side (`n_boundary_edges`).
    pub n_boundary_edges: usize,
    /// Edges with more than two incident triangle sides (`n_nonmanifold_edges`).
    pub n_nonmanifold_edges: usize,
    /// Largest number of triangle sides on one edge (`max_faces_per_edge`; 0 when there is no
    /// edge).
    pub max_faces_per_edge: usize,
    /// Edges with ≥ 2 incident sides whose sides do not pair up into opposite directions
    /// (number traversed `a→b` ≠ number traversed `b→a`) (`n_misoriented_edges`).
    pub n_misoriented_edges: usize,
    /// Edges with exactly two incident sides that run in the same direction (not in
    /// meshcheck; the corpus MANIFEST's `n_inconsistent_edges`, which ignores non-manifold
    /// edges).
    pub n_misoriented_manifold_edges: usize,
    /// Vertices whose incident non-degenerate triangles form more than one fan — more than one
    /// group connected through edges at the vertex (`n_nonmanifold_vertices`).
    pub n_nonmanifold_vertices: usize,
    /// Every edge has exactly two incident sides (`is_closed`: no boundary and no
    /// non-manifold edge).
    pub is_closed: bool,
    /// No non-manifold edge (`is_edge_manifold`).
    pub is_edge_manifold: bool,
    /// No non-manifold vertex (`is_vertex_manifold`).
    pub is_vertex_manifold: bool,
    /// Edge-manifold, vertex-manifold and no combinatorially degenerate triangle
    /// (`is_manifold`).
    pub is_manifold: bool,
    /// Closed and manifold (`is_watertight`).
    pub is_watertight: bool,
    /// No misoriented edge (`consistently_oriented`).
    pub consistently_oriented: bool,
    /// Whether the triangles can be re-oriented consistently across their 2-manifold edges
    /// (BFS over edges with exactly two distinct incident triangles); `None` when the soup is not
    /// edge-manifold (`is_orientable`).
    pub is_orientable: Option<bool>,
    /// Connected components, where two vertices are connected when a triangle uses both
    /// (`n_components`; unreferenced vertices belong to none).
    pub n_components: usize,
    /// Per component `V − E + F` (referenced vertices, distinct edges, triangles), components
    /// numbered in order of their smallest vertex index (`euler_characteristic`; the JSON lists
    /// the first 100 like meshcheck).
    pub euler_characteristic: Vec<i64>,
    /// Sum of [`Self::euler_characteristic`] (`euler_characteristic_total`).
    pub euler_characteristic_total: i64,
    /// Signed volume `Σ a · (b × c) / 6` over all triangles (`signed_volume`; positive for a
    /// closed outward-oriented surface).
    pub signed_volume: f64,
    /// Per component `(2 − χ) / 2` (truncated), only when the soup is closed and manifold
    /// (`genus`).
    pub genus: Option<Vec<i64>>,
    /// Sum of [`Self::genus`]; `None` also when some component has odd `χ` (non-orientable)
    /// (`total_genus`).
    pub total_genus: Option<i64>,
    /// Components with negative signed volume (inward-facing), only when the soup is closed,
    /// manifold and consistently oriented (`n_inward_oriented_components`).
    pub n_inward_oriented_components: Option<usize>,
    /// Coordinate-wise minimum of the referenced vertices (`bbox_min`).
    pub bbox_min: [f64; 3],
    /// Coordinate-wise maximum of the referenced vertices (`bbox_max`).
    pub bbox_max: [f64; 3],
    /// Length of the bounding-box diagonal (`bbox_diagonal`).
    pub bbox_diagonal: f64,
    /// Intersecting triangle pairs after exact welding, degenerate triangles excluded (CGAL
    /// semantics: sharing a vertex or edge is allowed, anything more is not); `None` when the
    /// pass was skipped (`n_self_intersecting_pairs`). Exact duplicates (stacked copies of a
    /// face) are counted per group, `k(k−1)/2` for `k` copies, so the count is exact and its
    /// cost does not grow with the square of the copies (250 000 copies of a tetrahedron:
    /// 124 999 500 000 pairs, counted in about a second).
    pub n_self_intersecting_pairs: Option<usize>,
    /// True when [`Self::n_self_intersecting_pairs`] is a lower bound rather than the exact
    /// count: the pass stops counting once 2²² exact tests have found an intersection (a
    /// pile of 20 000 near-copies of one face has 1.5·10⁸ intersecting pairs, each
    /// needing its own test; stacked exact copies are counted per group and do not use the
    /// cap). The count is then at least that large and [`Self::self_intersection_free`] is
    /// still exact (`false`). Deterministic: the same for any number of threads. `None` when
    /// the pass was skipped. In [`Self::to_json`] only when `true`
    /// (`n_self_intersecting_pairs_is_lower_bound`, after `self_intersection_free`), so the line
    /// stays meshcheck's whenever the count is exact.
    pub n_self_intersecting_pairs_is_lower_bound: Option<bool>,
    /// Degenerate triangles after exact welding (equal to [`Self::n_degenerate_faces`], since
    /// welding moves no point); `None` when the pass was skipped (`n_degenerate_faces_welded`).
    pub n_degenerate_faces_welded: Option<usize>,
    /// No intersecting pair and no degenerate triangle (CGAL `!does_self_intersect`); `None`
    /// when the pass was skipped (`self_intersection_free`).
    pub self_intersection_free: Option<bool>,
}

/// A timed phase of [`MeshReport::compute_timed`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValidityStage {
    /// Exact welding of coincident points (`weld`).
    Weld,
    /// Referenced vertices, degenerate faces, area, bounding box (`faces`).
    Faces,
    /// Connected components and signed volumes (`components`).
    Components,
    /// Edge sides, boundary / non-manifold / misoriented edges (`edges`).
    Edges,
    /// Vertex fans, non-manifold vertices (`fans`).
    Fans,
    /// Orientability (`orientability`).
    Orientability,
    /// Duplicate faces (`duplicate_faces`).
    DuplicateFaces,
    /// Self-intersections: welded and degenerate faces (`si_prepare`).
    SiPrepare,
    /// Self-intersections: chunk trees (`si_bvh`).
    SiBvh,
    /// Self-intersections: traversal with the exact test of each candidate pair
    /// (`si_pairs_and_tests`).
    SiPairsAndTests,
}

impl Stage for ValidityStage {
    fn name(&self) -> Cow<'static, str> {
        Cow::Borrowed(match self {
            ValidityStage::Weld => "weld",
            ValidityStage::Faces => "faces",
            ValidityStage::Components => "components",
            ValidityStage::Edges => "edges",
            ValidityStage::Fans => "fans",
            ValidityStage::Orientability => "orientability",
            ValidityStage::DuplicateFaces => "duplicate_faces",
            ValidityStage::SiPrepare => "si_prepare",
            ValidityStage::SiBvh => "si_bvh",
            ValidityStage::SiPairsAndTests => "si_pairs_and_tests",
        })
    }
}

impl MeshReport {
    /// The full report with default options (self-intersections included, no welding).
    pub fn compute(mesh: &TriMesh) -> MeshReport {
        Self::compute_with(mesh, &ReportOptions::default())
    }

    /// The report with the given options.
    pub fn compute_with(mesh: &TriMesh, options: &ReportOptions) -> MeshReport {
        Self::compute_timed(mesh, options, &mut StageTimes::default())
    }

    /// The report with the given options, recording the wall time of each phase in `stats`
    /// (every [`ValidityStage`] in declaration order; the three `Si*` stages only with the
    /// self-intersection pass).
    pub fn compute_timed(
        mesh: &TriMesh,
        options: &ReportOptions,
        stats: &mut StageTimes<ValidityStage>,
    ) -> MeshReport {
        Self::compute_timed_with_progress(mesh, options, stats, &mut |_| true)
            .expect("never cancelled")
    }

    /// The report with the given options and a progress callback (a cancellation point),
    /// called on the calling thread with the fraction done after each phase and, in the
    /// self-intersection pass, after each batch of chunk trees and of about 2¹⁹ candidate
    /// pairs per thread, also inside one pile of overlapping faces; `None` as soon
    /// as it returns `false`. When not cancelled, the same report as [`Self::compute_with`].
    pub fn compute_with_progress(
        mesh: &TriMesh,
        options: &ReportOptions,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<MeshReport> {
        Self::compute_timed_with_progress(mesh, options, &mut StageTimes::default(), keep_going)
    }

    /// [`Self::compute_timed`] with the progress callback of [`Self::compute_with_progress`].
    pub fn compute_timed_with_progress(
        mesh: &TriMesh,
        options: &ReportOptions,
        stats: &mut StageTimes<ValidityStage>,
        keep_going: &mut dyn FnMut(f64) -> bool,
    ) -> Option<MeshReport> {
        use ValidityStage as S;
        // Fractions: the topology phases share the first 30 %, the self-intersection pass
        // the rest (or all of it when skipped).
        let topo = if options.self_intersections { 0.3 } else { 1.0 };
        let positions = mesh.positions();
        let weld = stats.time(S::Weld, || ExactWeld::compute(positions));
        phase_done(keep_going, topo, 1)?;
        let welded_tris;
        let tris: &[[u32; 3]] = if options.weld && !weld.is_identity() {
            welded_tris = weld.apply(mesh.triangles());
            &welded_tris
        } else {
            mesh.triangles()
        };
        let faces = stats.time(S::Faces, || FaceStats::compute(positions, tris));
        phase_done(keep_going, topo, 2)?;
        let comps = stats.time(S::Components, || {
            Components::compute(positions, tris, &faces.used)
        });
        phase_done(keep_going, topo, 3)?;
        let edges = stats.time(S::Edges, || {
            EdgePass::compute(positions.len(), tris, &comps)
        });
        phase_done(keep_going, topo, 4)?;
        let n_nonmanifold_vertices = stats.time(S::Fans, || {
            edges.count_nonmanifold_vertices(tris, &faces.comb_degenerate)
        });
        phase_done(keep_going, topo, 5)?;
        let orientable = stats.time(S::Orientability, || edges.is_orientable());
        phase_done(keep_going, topo, 6)?;
        let n_duplicate_faces = stats.time(S::DuplicateFaces, || count_duplicate_faces(tris));
        phase_done(keep_going, topo, 7)?;
        let si = if options.self_intersections {
            let (si, t) = count_self_intersections_welded(
                positions,
                mesh.triangles(),
                &weld,
                MAX_COUNTED_HITS,
                &mut |f| keep_going(topo + (1.0 - topo) * f),
            )?;
            stats.push(S::SiPrepare, t.prepare);
            stats.push(S::SiBvh, t.bvh);
            stats.push(S::SiPairsAndTests, t.pairs_and_tests);
            Some(si)
        } else {
            None
        };

        let is_edge_manifold = edges.n_nonmanifold == 0;
        let is_closed = edges.n_boundary == 0 && is_edge_manifold;
        let is_vertex_manifold = n_nonmanifold_vertices == 0;
        let is_manifold = is_edge_manifold && is_vertex_manifold && faces.n_comb_degenerate == 0;
        let euler = comps.euler(&edges.edges_per_component);
        let (genus, total_genus) = genus_of(&euler, is_closed && is_manifold);
        let n_inward_oriented_components = (is_closed && is_manifold && edges.n_misoriented == 0)
            .then(|| comps.volume.iter().filter(|&&v| v < 0.0).count());
        let n_isolated_vertices = (0..positions.len())
            .filter(|&v| !faces.used[v] && (!options.weld || weld.rep[v] as usize == v))
            .count();
        let bbox_diagonal = (0..3)
            .map(|k| (faces.bbox_max[k] - faces.bbox_min[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        Some(MeshReport {
            n_vertices: positions.len(),
            n_faces: tris.len(),
            welded: options.weld,
            n_duplicate_points: weld.n_duplicates,
            n_coincident_vertices: weld.n_coincident,
            n_referenced_vertices: faces.n_referenced,
            n_isolated_vertices,
            n_degenerate_faces: faces.n_geom_degenerate,
            n_combinatorially_degenerate_faces: faces.n_comb_degenerate,
            surface_area: faces.area,
            n_duplicate_faces,
            n_edges: edges.n_edges,
            n_boundary_edges: edges.n_boundary,
            n_nonmanifold_edges: edges.n_nonmanifold,
            max_faces_per_edge: edges.max_faces,
            n_misoriented_edges: edges.n_misoriented,
            n_misoriented_manifold_edges: edges.n_misoriented_manifold,
            n_nonmanifold_vertices,
            is_closed,
            is_edge_manifold,
            is_vertex_manifold,
            is_manifold,
            is_watertight: is_closed && is_manifold,
            consistently_oriented: edges.n_misoriented == 0,
            is_orientable: is_edge_manifold.then_some(orientable),
            n_components: comps.count,
            euler_characteristic_total: euler.iter().sum(),
            euler_characteristic: euler,
            signed_volume: comps.volume.iter().sum(),
            genus,
            total_genus,
            n_inward_oriented_components,
            bbox_min: faces.bbox_min,
            bbox_max: faces.bbox_max,
            bbox_diagonal,
            n_self_intersecting_pairs: si.map(|s| usize::try_from(s.pairs).unwrap_or(usize::MAX)),
            n_self_intersecting_pairs_is_lower_bound: si.map(|s| s.pairs_is_lower_bound),
            n_degenerate_faces_welded: si.map(|s| s.degenerate),
            self_intersection_free: si.map(|s| s.pairs == 0 && s.degenerate == 0),
        })
    }

    /// The report as one line of JSON with a fixed key order (meshcheck's order and names;
    /// `None` is `null`; lists of per-component values are cut after 100 entries like
    /// meshcheck's; floats in shortest round-trip form, non-finite as `null`).
    pub fn to_json(&self) -> String {
        let mut j = JsonLine::default();
        j.num("n_vertices", self.n_vertices);
        j.num("n_faces", self.n_faces);
        j.num("n_triangles", self.n_faces);
        j.boolean("welded", self.welded);
        j.num("n_duplicate_points", self.n_duplicate_points);
        j.num("n_coincident_vertices", self.n_coincident_vertices);
        j.num("n_referenced_vertices", self.n_referenced_vertices);
        j.num("n_isolated_vertices", self.n_isolated_vertices);
        j.num("n_degenerate_faces", self.n_degenerate_faces);
        j.num(
            "n_combinatorially_degenerate_faces",
            self.n_combinatorially_degenerate_faces,
        );
        j.float("surface_area", self.surface_area);
        j.num("n_duplicate_faces", self.n_duplicate_faces);
        j.num("n_edges", self.n_edges);
        j.num("n_boundary_edges", self.n_boundary_edges);
        j.num("n_nonmanifold_edges", self.n_nonmanifold_edges);
        j.num("max_faces_per_edge", self.max_faces_per_edge);
        j.num("n_misoriented_edges", self.n_misoriented_edges);
        j.num(
            "n_misoriented_manifold_edges",
            self.n_misoriented_manifold_edges,
        );
        j.num("n_nonmanifold_vertices", self.n_nonmanifold_vertices);
        j.boolean("is_closed", self.is_closed);
        j.boolean("is_edge_manifold", self.is_edge_manifold);
        j.boolean("is_vertex_manifold", self.is_vertex_manifold);
        j.boolean("is_manifold", self.is_manifold);
        j.boolean("is_watertight", self.is_watertight);
        j.boolean("consistently_oriented", self.consistently_oriented);
        j.opt_bool("is_orientable", self.is_orientable);
        j.num("n_components", self.n_components);
        j.int_list("euler_characteristic", Some(&self.euler_characteristic));
        j.raw(
            "euler_characteristic_total",
            self.euler_characteristic_total.to_string(),
        );
        j.float("signed_volume", self.signed_volume);
        j.int_list("genus", self.genus.as_deref());
        j.raw("total_genus", opt_to_json(self.total_genus));
        j.raw(
            "n_inward_oriented_components",
            opt_to_json(self.n_inward_oriented_components),
        );
        j.float_list("bbox_min", &self.bbox_min);
        j.float_list("bbox_max", &self.bbox_max);
        j.float("bbox_diagonal", self.bbox_diagonal);
        j.raw(
            "n_self_intersecting_pairs",
            opt_to_json(self.n_self_intersecting_pairs),
        );
        j.raw(
            "n_degenerate_faces_welded",
            opt_to_json(self.n_degenerate_faces_welded),
        );
        j.opt_bool("self_intersection_free", self.self_intersection_free);
        if self.n_self_intersecting_pairs_is_lower_bound == Some(true) {
            j.opt_bool("n_self_intersecting_pairs_is_lower_bound", Some(true));
        }
        j.finish()
    }
}

// ---------------------------------------------------------------------------------------------
// per-face quantities

/// Referenced vertices, degenerate faces, area and bounding box.
struct FaceStats {
    used: Vec<bool>,
    n_referenced: usize,
    comb_degenerate: Vec<bool>,
    n_comb_degenerate: usize,
    n_geom_degenerate: usize,
    area: f64,
    bbox_min: [f64; 3],
    bbox_max: [f64; 3],
}

/// Faces per parallel work item; fixed so floating-point sums do not depend on thread count.
const CHUNK: usize = 4096;

impl FaceStats {
    fn compute(positions: &[[f64; 3]], tris: &[[u32; 3]]) -> FaceStats {
        let mut used = vec![false; positions.len()];
        for t in tris {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let comb_degenerate: Vec<bool> = tris
            .iter()
            .map(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            .collect();
        // Geometric degeneracy and area in fixed chunks, summed in chunk order.
        let per_chunk: Vec<(usize, f64)> = tris
            .par_chunks(CHUNK)
            .map(|chunk| {
                let mut n = 0;
                let mut area = 0.0;
                for t in chunk {
                    let [a, b, c] = t.map(|v| positions[v as usize]);
                    if is_collinear(a, b, c) {
                        n += 1;
                    } else {
                        area += triangle_area(a, b, c);
                    }
                }
                (n, area)
            })
            .collect();
        let (bbox_min, bbox_max) = referenced_bbox(positions, &used);
        FaceStats {
            n_referenced: used.iter().filter(|&&u| u).count(),
            used,
            n_comb_degenerate: comb_degenerate.iter().filter(|&&d| d).count(),
            comb_degenerate,
            n_geom_degenerate: per_chunk.iter().map(|c| c.0).sum(),
            area: per_chunk.iter().map(|c| c.1).sum(),
            bbox_min,
            bbox_max,
        }
    }
}

fn triangle_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}

fn referenced_bbox(positions: &[[f64; 3]], used: &[bool]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (p, _) in positions.iter().zip(used).filter(|(_, &u)| u) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Triangles whose sorted index triple equals an earlier one's: `Σ (group size − 1)`.
fn count_duplicate_faces(tris: &[[u32; 3]]) -> usize {
    let mut keys: Vec<[u32; 3]> = tris
        .par_iter()
        .map(|t| {
            let mut s = *t;
            s.sort_unstable();
            s
        })
        .collect();
    keys.par_sort_unstable();
    keys.windows(2).filter(|w| w[0] == w[1]).count()
}

// ---------------------------------------------------------------------------------------------
// vertex-connected components

/// Union–find with path halving; the root of a set is its smallest element (as meshcheck's).
struct UnionFind(Vec<u32>);

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind((0..n as u32).collect())
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let grand = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = grand;
            x = grand;
        }
        x
    }

    fn unite(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}

/// Components numbered in order of first referenced vertex, with per-component V, F, volume.
struct Components {
    count: usize,
    of_vertex: Vec<u32>,
    vertices: Vec<i64>,
    faces: Vec<i64>,
    volume: Vec<f64>,
}

impl Components {
    fn compute(positions: &[[f64; 3]], tris: &[[u32; 3]], used: &[bool]) -> Components {
        let n_vertices = positions.len();
        let mut uf = UnionFind::new(n_vertices);
        for t in tris {
            uf.unite(t[0], t[1]);
            uf.unite(t[1], t[2]);
        }
        let mut id_of_root = vec![u32::MAX; n_vertices];
        let mut of_vertex = vec![u32::MAX; n_vertices];
        let mut count = 0u32;
        let mut vertices = Vec::new();
        for v in 0..n_vertices as u32 {
            if !used[v as usize] {
                continue;
            }
            let r = uf.find(v) as usize;
            if id_of_root[r] == u32::MAX {
                id_of_root[r] = count;
                count += 1;
                vertices.push(0);
            }
            of_vertex[v as usize] = id_of_root[r];
            vertices[id_of_root[r] as usize] += 1;
        }
        let mut comps = Components {
            count: count as usize,
            of_vertex,
            vertices,
            faces: vec![0; count as usize],
            volume: vec![0.0; count as usize],
        };
        comps.accumulate_faces(positions, tris);
        comps
    }

    /// Faces and signed volume (divergence theorem: `Σ a · (b × c) / 6`, the formula meshcheck
    /// evaluates) per component, summed in face order.
    fn accumulate_faces(&mut self, positions: &[[f64; 3]], tris: &[[u32; 3]]) {
        for t in tris {
            let c = self.of_vertex[t[0] as usize] as usize;
            let [a, b, d] = t.map(|v| positions[v as usize]);
            self.faces[c] += 1;
            self.volume[c] += (a[0] * (b[1] * d[2] - b[2] * d[1])
                - a[1] * (b[0] * d[2] - b[2] * d[0])
                + a[2] * (b[0] * d[1] - b[1] * d[0]))
                / 6.0;
        }
    }

    /// Per component `V − E + F`.
    fn euler(&self, edges: &[i64]) -> Vec<i64> {
        (0..self.count)
            .map(|c| self.vertices[c] - edges[c] + self.faces[c])
            .collect()
    }
}

/// The progress call after topology phase `k` of 7 (their share of the report is `topo`);
/// `None` when it asks to cancel.
fn phase_done(keep_going: &mut dyn FnMut(f64) -> bool, topo: f64, k: u32) -> Option<()> {
    keep_going(topo * f64::from(k) / 7.0).then_some(())
}

/// Genus per component and total, when the soup is closed and manifold.
fn genus_of(euler: &[i64], closed_manifold: bool) -> (Option<Vec<i64>>, Option<i64>) {
    if !closed_manifold {
        return (None, None);
    }
    let genus: Vec<i64> = euler.iter().map(|chi| (2 - chi) / 2).collect();
    let orientable = euler.iter().all(|chi| (2 - chi) % 2 == 0);
    let total = orientable.then(|| genus.iter().sum());
    (Some(genus), total)
}

// ---------------------------------------------------------------------------------------------
// edges, fans and orientability

/// One triangle side, bucketed under its smaller endpoint: `max endpoint << 32 | face << 2 |
/// corner` (sorted within a bucket by other endpoint, then face).
type SideKey = u64;

/// Edge statistics from one pass over the sides grouped by undirected edge.
struct EdgePass {
    n_edges: usize,
    n_boundary: usize,
    n_nonmanifold: usize,
    max_faces: usize,
    n_misoriented: usize,
    n_misoriented_manifold: usize,
    edges_per_component: Vec<i64>,
    /// Per face, the faces across its 2-manifold edges (`u32::MAX` = none) and whether the
    /// neighbour traverses the shared edge in the same direction (an orientation conflict).
    adjacency: Vec<[(u32, bool); 3]>,
    /// CSR of sides by smaller endpoint.
    offsets: Vec<u32>,
    sides: Vec<SideKey>,
}

impl EdgePass {
    fn compute(n_vertices: usize, tris: &[[u32; 3]], comps: &Components) -> EdgePass {
        assert!(tris.len() < (1 << 30), "more than 2^30 triangles");
        let (offsets, sides) = bucket_sides(n_vertices, tris);
        let mut pass = EdgePass {
            n_edges: 0,
            n_boundary: 0,
            n_nonmanifold: 0,
            max_faces: 0,
            n_misoriented: 0,
            n_misoriented_manifold: 0,
            edges_per_component: vec![0; comps.count],
            adjacency: vec![[(u32::MAX, false); 3]; tris.len()],
            offsets,
            sides,
        };
        pass.scan_edges(tris, comps);
        pass
    }

    /// Visits each undirected edge `{a, b}` with the slice of its sides.
    fn for_each_edge(&self, mut f: impl FnMut(u32, u32, &[SideKey])) {
        for a in 0..self.offsets.len() - 1 {
            let bucket = &self.sides[self.offsets[a] as usize..self.offsets[a + 1] as usize];
            let mut i = 0;
            while i < bucket.len() {
                let b = (bucket[i] >> 32) as u32;
                let mut j = i + 1;
                while j < bucket.len() && (bucket[j] >> 32) as u32 == b {
                    j += 1;
                }
                f(a as u32, b, &bucket[i..j]);
                i = j;
            }
        }
    }

    fn scan_edges(&mut self, tris: &[[u32; 3]], comps: &Components) {
        let mut stats = [0usize; 6];
        let mut per_comp = std::mem::take(&mut self.edges_per_component);
        let mut adjacency = std::mem::take(&mut self.adjacency);
        self.for_each_edge(|a, _b, group| {
            let n = group.len();
            let forward = group.iter().filter(|&&s| side_is_forward(tris, s)).count();
            stats[0] += 1;
            stats[1] += (n == 1) as usize;
            stats[2] += (n > 2) as usize;
            stats[3] = stats[3].max(n);
            stats[4] += (n >= 2 && 2 * forward != n) as usize;
            stats[5] += (n == 2 && forward != 1) as usize;
            per_comp[comps.of_vertex[a as usize] as usize] += 1;
            if n == 2 && side_face(group[0]) != side_face(group[1]) {
                let same = side_is_forward(tris, group[0]) == side_is_forward(tris, group[1]);
                link_faces(
                    &mut adjacency,
                    side_face(group[0]),
                    side_face(group[1]),
                    same,
                );
            }
        });
        [
            self.n_edges,
            self.n_boundary,
            self.n_nonmanifold,
            self.max_faces,
            self.n_misoriented,
            self.n_misoriented_manifold,
        ] = stats;
        self.edges_per_component = per_comp;
        self.adjacency = adjacency;
    }

    /// Vertices whose non-degenerate incident faces form more than one fan. Fans are the
    /// classes of the corners at a vertex under "the two faces share an edge at the vertex" —
    /// the components of the vertex's link, which meshcheck counts link by link.
    fn count_nonmanifold_vertices(&self, tris: &[[u32; 3]], comb_degenerate: &[bool]) -> usize {
        let mut uf = UnionFind::new(3 * tris.len());
        self.for_each_edge(|a, b, group| {
            let mut live = group
                .iter()
                .copied()
                .filter(|&s| !comb_degenerate[side_face(s) as usize]);
            if let Some(first) = live.next() {
                for s in live {
                    uf.unite(corner_at(tris, first, a), corner_at(tris, s, a));
                    uf.unite(corner_at(tris, first, b), corner_at(tris, s, b));
                }
            }
        });
        let mut fans = vec![0u32; self.offsets.len() - 1];
        for (f, t) in tris.iter().enumerate() {
            if comb_degenerate[f] {
                continue;
            }
            for (k, &v) in t.iter().enumerate() {
                let c = (3 * f + k) as u32;
                if uf.find(c) == c {
                    fans[v as usize] += 1;
                }
            }
        }
        fans.iter().filter(|&&n| n > 1).count()
    }

    /// BFS over the 2-manifold edges giving each face a flip bit; fails on a contradiction
    /// (meshcheck's `is_orientable`).
    fn is_orientable(&self) -> bool {
        let n = self.adjacency.len();
        let mut flip = vec![-1i8; n];
        let mut stack = Vec::new();
        for s in 0..n {
            if flip[s] != -1 {
                continue;
            }
            flip[s] = 0;
            stack.push(s as u32);
            while let Some(f) = stack.pop() {
                for &(g, same) in &self.adjacency[f as usize] {
                    if g == u32::MAX {
                        continue;
                    }
                    let want = if same {
                        1 - flip[f as usize]
                    } else {
                        flip[f as usize]
                    };
                    if flip[g as usize] == -1 {
                        flip[g as usize] = want;
                        stack.push(g);
                    } else if flip[g as usize] != want {
                        return false;
                    }
                }
            }
        }
        true
    }
}

/// CSR of all non-loop triangle sides bucketed by their smaller endpoint, each bucket sorted.
fn bucket_sides(n_vertices: usize, tris: &[[u32; 3]]) -> (Vec<u32>, Vec<SideKey>) {
    let mut offsets = vec![0u32; n_vertices + 1];
    for t in tris {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            if u != v {
                offsets[u.min(v) as usize + 1] += 1;
            }
        }
    }
    for v in 0..n_vertices {
        offsets[v + 1] += offsets[v];
    }
    let mut fill = offsets.clone();
    let mut sides = vec![0u64; offsets[n_vertices] as usize];
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            if u != v {
                let slot = &mut fill[u.min(v) as usize];
                sides[*slot as usize] = (u64::from(u.max(v)) << 32) | ((f as u64) << 2) | k as u64;
                *slot += 1;
            }
        }
    }
    sort_buckets(&offsets, &mut sides);
    (offsets, sides)
}

/// Sorts each CSR bucket, in parallel over disjoint runs of buckets.
fn sort_buckets(offsets: &[u32], sides: &mut [SideKey]) {
    let n = offsets.len() - 1;
    let per_task = 1 << 14;
    let mut tasks: Vec<(&[u32], &mut [SideKey])> = Vec::new();
    let mut rest = sides;
    let mut start = 0;
    while start < n {
        let end = (start + per_task).min(n);
        let len = (offsets[end] - offsets[start]) as usize;
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        tasks.push((&offsets[start..=end], head));
        rest = tail;
        start = end;
    }
    tasks.into_par_iter().for_each(|(offs, chunk)| {
        let base = offs[0];
        for w in offs.windows(2) {
            chunk[(w[0] - base) as usize..(w[1] - base) as usize].sort_unstable();
        }
    });
}

#[inline]
fn side_face(s: SideKey) -> u32 {
    ((s >> 2) & 0x3fff_ffff) as u32
}

#[inline]
fn side_corner(s: SideKey) -> usize {
    (s & 3) as usize
}

/// True when the side runs from its smaller to its larger endpoint.
#[inline]
fn side_is_forward(tris: &[[u32; 3]], s: SideKey) -> bool {
    let t = tris[side_face(s) as usize];
    let k = side_corner(s);
    t[k] < t[(k + 1) % 3]
}

/// The corner id (`3 · face + k`) at vertex `x` of the side `s` (an endpoint of the side).
#[inline]
fn corner_at(tris: &[[u32; 3]], s: SideKey, x: u32) -> u32 {
    let f = side_face(s);
    let k = side_corner(s);
    let k = if tris[f as usize][k] == x {
        k
    } else {
        (k + 1) % 3
    };
    3 * f + k as u32
}

fn link_faces(adjacency: &mut [[(u32, bool); 3]], f: u32, g: u32, same: bool) {
    for (a, b) in [(f, g), (g, f)] {
        if let Some(slot) = adjacency[a as usize].iter_mut().find(|s| s.0 == u32::MAX) {
            *slot = (b, same);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// JSON

/// A one-line JSON object writer with insertion-ordered keys (meshcheck's `Json`).
#[derive(Default)]
struct JsonLine(Vec<(String, String)>);

/// Per-component lists are cut after this many entries in JSON (as meshcheck does).
const JSON_LIST_MAX: usize = 100;

impl JsonLine {
    fn raw(&mut self, k: &str, v: String) {
        self.0.push((k.to_string(), v));
    }
    fn num(&mut self, k: &str, v: usize) {
        self.raw(k, v.to_string());
    }
    fn boolean(&mut self, k: &str, v: bool) {
        self.raw(k, v.to_string());
    }
    fn opt_bool(&mut self, k: &str, v: Option<bool>) {
        self.raw(k, opt_to_json(v));
    }
    fn float(&mut self, k: &str, v: f64) {
        self.raw(k, float_to_json(v));
    }
    fn float_list(&mut self, k: &str, v: &[f64]) {
        let items: Vec<String> = v.iter().map(|&x| float_to_json(x)).collect();
        self.raw(k, format!("[{}]", items.join(",")));
    }
    fn int_list(&mut self, k: &str, v: Option<&[i64]>) {
        let s = match v {
            None => "null".to_string(),
            Some(v) => {
                let items: Vec<String> = v
                    .iter()
                    .take(JSON_LIST_MAX)
                    .map(|x| x.to_string())
                    .collect();
                format!("[{}]", items.join(","))
            }
        };
        self.raw(k, s);
    }
    fn finish(self) -> String {
        let items: Vec<String> = self
            .0
            .into_iter()
            .map(|(k, v)| format!("\"{k}\": {v}"))
            .collect();
        format!("{{{}}}", items.join(", "))
    }
}

/// Shortest round-trip form; exponent notation for very small or large magnitudes (`1e-7`),
/// which JSON accepts; `null` when not finite.
fn float_to_json(v: f64) -> String {
    if v.is_finite() {
        format!("{v:?}")
    } else {
        "null".to_string()
    }
}

fn opt_to_json<T: ToString>(v: Option<T>) -> String {
    v.map_or_else(|| "null".to_string(), |x| x.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{find_self_intersections_in, has_self_intersection_in};

    /// A small random soup: `n` triangles with corners on a coarse grid (so that touching,
    /// shared corners and coplanar overlaps occur), then `dups` exact duplicates of random
    /// faces — on shared or on their own copied vertices, rotated or flipped — and a few
    /// degenerate faces.
    fn soup_with_duplicates(seed: u64, n: usize, dups: usize) -> TriMesh {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = move |m: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % m
        };
        let mut p: Vec<[f64; 3]> = Vec::new();
        let mut t: Vec<[u32; 3]> = Vec::new();
        for _ in 0..n {
            let base = p.len() as u32;
            for _ in 0..3 {
                p.push([0, 1, 2].map(|_| next(4) as f64));
            }
            t.push([base, base + 1, base + 2]);
        }
        for _ in 0..dups {
            let f = t[next(t.len() as u64) as usize];
            let r = next(3) as usize;
            let mut g = [f[r], f[(r + 1) % 3], f[(r + 2) % 3]];
            if next(2) == 0 {
                g.swap(1, 2);
            }
            if next(2) == 0 {
                let base = p.len() as u32;
                for k in 0..3 {
                    p.push(p[g[k] as usize]);
                }
                g = [base, base + 1, base + 2];
            }
            t.push(g);
        }
        t.push([0, 0, 1]);
        TriMesh::new(p, t).unwrap()
    }

    #[test]
    fn grouped_self_intersection_counts_equal_the_enumeration() {
        let mut hits = 0;
        for seed in 0..40 {
            let n = 3 + (seed as usize % 7) * 5;
            let dups = [0, 1, 3, 12, 40][seed as usize % 5];
            let mut m = soup_with_duplicates(seed, n, dups);
            if seed % 3 == 0 {
                // without the degenerate face, so that `self_intersection_free` can be true
                let t = m.triangles()[..m.triangle_count() - 1].to_vec();
                m = TriMesh::new(m.positions().to_vec(), t).unwrap();
            }
            let listed = find_self_intersections_in(m.positions(), m.triangles());
            for weld in [false, true] {
                let options = ReportOptions {
                    self_intersections: true,
                    weld,
                };
                let r = MeshReport::compute_with(&m, &options);
                assert_eq!(
                    r.n_self_intersecting_pairs,
                    Some(listed.pairs.len()),
                    "{seed}"
                );
                assert_eq!(r.n_degenerate_faces_welded, Some(listed.degenerate.len()));
                assert_eq!(r.self_intersection_free, Some(listed.is_free()), "{seed}");
                assert_eq!(r.n_self_intersecting_pairs_is_lower_bound, Some(false));
                let mut calls = 0;
                let with = MeshReport::compute_with_progress(&m, &options, &mut |_| {
                    calls += 1;
                    true
                });
                assert_eq!(with.as_ref(), Some(&r));
                assert!(calls >= 10);
            }
            assert_eq!(
                has_self_intersection_in(m.positions(), m.triangles()),
                !listed.is_free()
            );
            hits += listed.pairs.len();
        }
        assert!(hits > 100, "the soups should intersect often: {hits}");
    }

    #[test]
    fn stacked_copies_are_counted_per_group() {
        // 3 copies of a triangle and 2 of a crossing one: 3 + 1 pairs inside, 3·2 across.
        let p = vec![
            [0., 0., 0.],
            [4., 0., 0.],
            [0., 4., 0.],
            [1., 1., -1.],
            [1., 1., 1.],
            [2., 1., 0.],
        ];
        let t = vec![[0, 1, 2], [3, 4, 5], [1, 2, 0], [0, 2, 1], [5, 4, 3]];
        let m = TriMesh::new(p, t).unwrap();
        let r = MeshReport::compute(&m);
        assert_eq!(r.n_self_intersecting_pairs, Some(3 + 1 + 6));
        assert_eq!(
            find_self_intersections_in(m.positions(), m.triangles())
                .pairs
                .len(),
            10
        );
        assert_eq!(r.n_duplicate_faces, 3);
    }

    #[test]
    fn the_report_can_be_cancelled_in_every_phase() {
        let m = soup_with_duplicates(7, 30, 10);
        let options = ReportOptions::default();
        let mut total = 0;
        MeshReport::compute_with_progress(&m, &options, &mut |_| {
            total += 1;
            true
        })
        .unwrap();
        for stop in 0..total {
            let mut calls = 0;
            let mut last = 0.0;
            let r = MeshReport::compute_with_progress(&m, &options, &mut |f| {
                assert!(f >= last && f <= 1.0);
                last = f;
                calls += 1;
                calls <= stop
            });
            assert!(r.is_none());
            assert_eq!(calls, stop + 1, "no call after the cancel");
        }
    }

    #[test]
    fn json_numbers() {
        assert_eq!(float_to_json(1.0), "1.0");
        assert_eq!(float_to_json(0.1), "0.1");
        assert_eq!(float_to_json(-2.5e-300), "-2.5e-300");
        assert_eq!(float_to_json(f64::NAN), "null");
        assert_eq!(float_to_json(f64::INFINITY), "null");
        assert_eq!(opt_to_json::<usize>(None), "null");
        let mut j = JsonLine::default();
        j.int_list("l", Some(&(0..150).collect::<Vec<i64>>()));
        j.int_list("n", None);
        j.float_list("f", &[1.0, -0.5]);
        let s = j.finish();
        assert!(
            s.starts_with("{\"l\": [0,1,2,") && s.contains(",99], \"n\": null, \"f\": [1.0,-0.5]}"),
            "{s}"
        );
    }
}
