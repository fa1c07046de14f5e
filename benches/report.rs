//! Benchmark of `MeshReport` (plain `std::time`, no harness): a generated closed bumpy sphere of
//! 1,310,720 triangles (the same surface as `../shared/tools/tests/make_big.py`, which the
//! tools README times meshcheck on), then the large corpus meshes when `../shared/meshes` exists.
//! Prints seconds per phase.
//!
//! `cargo bench --bench report` (release). Options after `--`: `--subdivisions N` (default 8),
//! `--threads N` (default: rayon's), `--repeat N` (default 1).

use std::time::Instant;

use pleat::mesh::TriMesh;
use pleat::report::{Stage as _, StageTimes};
use pleat::verify::{MeshReport, ReportOptions};

#[path = "../tests/common/shapes.rs"]
mod shapes;

#[path = "common/lod_sweep.rs"]
mod lod_sweep;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let opt = |name: &str, default: usize| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .map_or(default, |v| v.parse().expect("a number"))
    };
    let (subdivisions, threads, repeat) = (
        opt("--subdivisions", 8),
        opt("--threads", 0),
        opt("--repeat", 1),
    );
    if threads > 0 {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .unwrap();
    }
    println!("threads: {}", rayon::current_num_threads());

    let t0 = Instant::now();
    let mesh = bumpy_sphere(subdivisions as u32);
    println!(
        "generated bumpy sphere: {} vertices, {} triangles in {:.2} s",
        mesh.vertex_count(),
        mesh.triangle_count(),
        t0.elapsed().as_secs_f64()
    );
    for _ in 0..repeat {
        let r = run("bumpy_sphere", &mesh);
        assert!(
            r.is_watertight && r.self_intersection_free == Some(true) && r.total_genus == Some(0)
        );
    }
    winding(&mesh);
    corpus(repeat);
}

/// Winding numbers on the bumpy sphere: hierarchical build and queries, exact queries, and the
/// largest difference between the two.
fn winding(mesh: &TriMesh) {
    use pleat::spatial::{winding_numbers, FastWindingNumber};
    let t0 = Instant::now();
    let fast = FastWindingNumber::new(mesh);
    let build = t0.elapsed().as_secs_f64();
    // Points on a line through the sphere (inside, near the surface, outside) and a 3D grid.
    let mut points: Vec<[f64; 3]> = (0..100)
        .map(|i| [-1.5 + 0.03 * i as f64, 0.013, 0.007])
        .collect();
    let n = 46;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                points.push([i, j, k].map(|c| -1.3 + 2.6 * c as f64 / (n - 1) as f64));
            }
        }
    }
    let t0 = Instant::now();
    let approx = fast.winding_numbers(&points);
    let query = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let exact = winding_numbers(mesh, &points[..100]);
    let direct = t0.elapsed().as_secs_f64();
    let err = exact
        .iter()
        .zip(&approx)
        .map(|(e, a)| (e - a).abs())
        .fold(0.0, f64::max);
    println!(
        "winding numbers: hierarchy build {build:.3} s, {} queries {query:.3} s ({:.1} µs each); \
         exact 100 queries {direct:.3} s; max |fast − exact| on those {err:.1e}",
        points.len(),
        1e6 * query / points.len() as f64
    );
}

/// Times one full report and prints its phases.
fn run(name: &str, mesh: &TriMesh) -> MeshReport {
    let mut stats = StageTimes::default();
    let t0 = Instant::now();
    let r = MeshReport::compute_timed(mesh, &ReportOptions::default(), &mut stats);
    let total = t0.elapsed().as_secs_f64();
    let phases: Vec<String> = stats
        .iter()
        .map(|(n, s)| format!("{} {s:.3}", n.name()))
        .collect();
    println!(
        "{name}: {} triangles, total {total:.3} s [{}]; watertight {}, self-intersecting pairs {:?}",
        mesh.triangle_count(),
        phases.join(", "),
        r.is_watertight,
        r.n_self_intersecting_pairs
    );
    r
}

/// The `large_*` meshes of the shared corpus, when present ([`lod_sweep::corpus_dir`]).
fn corpus(repeat: usize) {
    let Some(dir) = lod_sweep::corpus_dir() else {
        println!("corpus: ../shared/meshes not found (set PLEAT_MESHES), skipped");
        return;
    };
    let Ok(mut files) = lod_sweep::mesh_files(&dir, &lod_sweep::MESH_EXTENSIONS) else {
        return;
    };
    files.retain(|p| lod_sweep::file_name(p).starts_with("large_"));
    for f in files {
        let t0 = Instant::now();
        let mesh = match pleat::mesh::io::read_mesh(&f) {
            Ok(m) => m,
            Err(e) => {
                println!("{}: cannot read: {e}", f.display());
                continue;
            }
        };
        let read = t0.elapsed().as_secs_f64();
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        println!("{name}: read in {read:.3} s");
        for _ in 0..repeat {
            run(&name, &mesh);
        }
    }
}

/// An icosphere subdivided `n` times (20·4ⁿ triangles, `tests/common/shapes.rs`), displaced
/// radially by `1 + 0.08 sin(7x) cos(5y) + 0.03 sin(23z)` (make_big.py's bumps).
fn bumpy_sphere(n: u32) -> TriMesh {
    let sphere = shapes::icosphere(1.0, n);
    let p = sphere
        .positions()
        .iter()
        .map(|v| {
            let r =
                1.0 + 0.08 * (7.0 * v[0]).sin() * (5.0 * v[1]).cos() + 0.03 * (23.0 * v[2]).sin();
            v.map(|c| c * r)
        })
        .collect();
    TriMesh::new(p, sphere.triangles().to_vec()).unwrap()
}
