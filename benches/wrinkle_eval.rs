//! Wrinkle evaluation benchmark (plain `std::time`, `cargo bench --bench wrinkle_eval`):
//!
//! 1. evaluation time per level on the coarse corpus meshes (`/work/shared/meshes/coarse_*`,
//!    or `$PLEAT_MESHES`) up to ~1M output faces, with 1 and 2 rayon threads;
//! 2. error against run time for the plane-wave test (max phase error vs level vs seconds);
//! 3. the effect of zero-amplitude regions (z work skipped where the stencil is all zero).

use std::path::{Path, PathBuf};
use std::time::Instant;

use pleat::mesh::TriMesh;
use pleat::report::Stage as _;
use pleat::wrinkle::{
    Complex, Cwf, EvalOptions, EvalStage, FrequencyField, KnoppelOptions, LevelPart,
};

const MAX_FACES: usize = 1_100_000;
const REPEATS: usize = 3;

fn main() {
    let dir = std::env::var("PLEAT_MESHES").unwrap_or_else(|_| "/work/shared/meshes".into());
    if std::env::var("PLEAT_BENCH_ONLY").as_deref() == Ok("profile") {
        // one 1M-face evaluation on one thread, for `perf record`
        let cwf =
            swirl_cwf(load(&Path::new(&dir).join("coarse_decimated-knight.off")).unwrap()).unwrap();
        let t = best_time(&cwf, 5, 1);
        println!(
            "knight level 5, 1 thread: {t:.4} s wall, {:.4} s CPU",
            best_cpu_time(&cwf, 5)
        );
        let t = best_time(&cwf, 5, 2);
        println!("knight level 5, 2 threads: {t:.4} s wall");
        let (_, stats) = in_pool(1, || cwf.evaluate(5, &EvalOptions::default()).unwrap());
        for (n, s) in stats.stages.iter() {
            println!("  {:32} {s:.4}", n.name());
        }
        return;
    }
    if std::env::var("PLEAT_BENCH_ONLY").as_deref() == Ok("render") {
        render_examples(Path::new(&dir));
        return;
    }
    corpus(Path::new(&dir));
    plane_wave_error_vs_time();
    zero_amplitude_regions(Path::new(&dir));
}

fn corpus(dir: &Path) {
    let files = coarse_files(dir);
    if files.is_empty() {
        println!(
            "[corpus] no coarse_* meshes under {} — skipped",
            dir.display()
        );
        return;
    }
    println!("[corpus] evaluation time per level (best of {REPEATS}), 1 and 2 threads");
    println!(
        "{:28} {:>5} {:>9} {:>9} {:>11} {:>10} {:>11} {:>7}",
        "mesh", "level", "vertices", "faces", "1 thr CPU s", "1 thread s", "2 threads s", "speedup"
    );
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mesh = match load(&path) {
            Ok(m) => m,
            Err(e) => {
                println!("{name:28} skipped: {e}");
                continue;
            }
        };
        let cwf = match swirl_cwf(mesh) {
            Ok(c) => c,
            Err(e) => {
                println!("{name:28} skipped: {e}");
                continue;
            }
        };
        let f0 = cwf.base().triangle_count();
        let mut level = 1;
        while f0 << (2 * level) <= MAX_FACES {
            let c1 = best_cpu_time(&cwf, level);
            let t1 = best_time(&cwf, level, 1);
            let t2 = best_time(&cwf, level, 2);
            let (e, _) = cwf.evaluate(level, &EvalOptions::default()).unwrap();
            println!(
                "{name:28} {level:>5} {:>9} {:>9} {c1:>11.4} {t1:>10.4} {t2:>11.4} {:>7.2}",
                e.mesh.vertex_count(),
                e.mesh.triangle_count(),
                t1 / t2
            );
            level += 1;
        }
        let (_, stats) = in_pool(2, || {
            cwf.evaluate(level - 1, &EvalOptions::default()).unwrap()
        });
        let stages: Vec<String> = stats
            .stages
            .iter()
            .map(|(n, s)| format!("{} {s:.4}", n.name()))
            .collect();
        println!(
            "{name:28} stages at level {} (2 threads): {}",
            level - 1,
            stages.join(", ")
        );
    }
}

/// Smallest CPU time of one single-threaded evaluation over `REPEATS` runs.
fn best_cpu_time(cwf: &Cwf, levels: usize) -> f64 {
    (0..REPEATS)
        .map(|_| {
            in_pool(1, || {
                let t = pleat::report::process_cpu_seconds();
                let r = cwf.evaluate(levels, &EvalOptions::default()).unwrap();
                std::hint::black_box(r);
                pleat::report::process_cpu_seconds() - t
            })
        })
        .fold(f64::INFINITY, f64::min)
}

fn best_time(cwf: &Cwf, levels: usize, threads: usize) -> f64 {
    (0..REPEATS)
        .map(|_| {
            in_pool(threads, || {
                let t = Instant::now();
                let r = cwf.evaluate(levels, &EvalOptions::default()).unwrap();
                std::hint::black_box(r);
                t.elapsed().as_secs_f64()
            })
        })
        .fold(f64::INFINITY, f64::min)
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// A CWF from a smooth tangent swirl (wave length ~ diag/25) with Knöppel's phase; amplitude
/// 0.4% of the diagonal.
fn swirl_cwf(mesh: TriMesh) -> pleat::Result<Cwf> {
    let diag = mesh.bbox_diagonal();
    let (lo, hi) = mesh.bbox();
    let c = [
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    ];
    let k = 2.0 * std::f64::consts::PI * 25.0 / diag;
    let normals = vertex_normals(&mesh);
    let v: Vec<[f64; 3]> = mesh
        .positions()
        .iter()
        .zip(&normals)
        .map(|(p, n)| {
            let d = [p[0] - c[0] + 0.3 * diag, p[1] - c[1], p[2] - c[2]];
            let t = [d[1] - d[2], d[2] - d[0], d[0] - d[1]]; // a smooth non-integrable field
            let tn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
            let tt = [t[0] - tn * n[0], t[1] - tn * n[1], t[2] - tn * n[2]];
            let l = (tt[0] * tt[0] + tt[1] * tt[1] + tt[2] * tt[2])
                .sqrt()
                .max(1e-12 * diag);
            [k * tt[0] / l, k * tt[1] / l, k * tt[2] / l]
        })
        .collect();
    let n = mesh.vertex_count();
    let t = Instant::now();
    let (cwf, rep) = Cwf::from_frequency_field(
        mesh,
        FrequencyField::PerVertex(&v),
        vec![0.004 * diag; n],
        &KnoppelOptions::default(),
    )?;
    println!(
        "  knoppel: {n} vertices, {:.3} s, {} iterations, λ = {:.3e}, residual {:.1e}",
        t.elapsed().as_secs_f64(),
        rep.iterations,
        rep.eigenvalue,
        rep.residual
    );
    Ok(cwf)
}

fn vertex_normals(m: &TriMesh) -> Vec<[f64; 3]> {
    let p = m.positions();
    let mut n = vec![[0.0; 3]; m.vertex_count()];
    for t in m.triangles() {
        let [a, b, c] = t.map(|v| p[v as usize]);
        let (u, w) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let x = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        for &v in t {
            for k in 0..3 {
                n[v as usize][k] += x[k];
            }
        }
    }
    n.iter()
        .map(|v| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.0 {
                [v[0] / l, v[1] / l, v[2] / l]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

fn plane_wave_error_vs_time() {
    println!("\n[plane wave] 32×32 irregular grid (2048 faces), |k|·h = 2, max phase error vs level vs time (2 threads)");
    println!(
        "{:>5} {:>9} {:>10} {:>12}",
        "level", "faces", "seconds", "max error"
    );
    let m = grid(32, 0.3);
    let h = 1.0 / 32.0;
    let k = [2.0 / h * 0.8, 2.0 / h * 0.6, 0.0];
    let ph = |p: &[f64; 3]| k[0] * p[0] + k[1] * p[1];
    let el = m.edges();
    let p = m.positions();
    let omega = el
        .edges
        .iter()
        .map(|e| ph(&p[e.0[1] as usize]) - ph(&p[e.0[0] as usize]))
        .collect();
    let zeta = p.iter().map(|q| Complex::cis(ph(q))).collect();
    let n = m.vertex_count();
    let cwf = Cwf::new(m, omega, vec![1.0; n], zeta).unwrap();
    let opts = EvalOptions {
        want_z: true,
        ..Default::default()
    };
    for level in 0..=5 {
        let (t, (e, _)) = in_pool(2, || {
            let t = Instant::now();
            let r = cwf.evaluate(level, &opts).unwrap();
            (t.elapsed().as_secs_f64(), r)
        });
        let err =
            e.z.as_ref()
                .unwrap()
                .iter()
                .zip(e.smooth_positions.as_ref().unwrap())
                .map(|(z, q)| (*z * Complex::cis(-ph(q))).arg().abs())
                .fold(0.0, f64::max);
        println!(
            "{level:>5} {:>9} {t:>10.4} {err:>12.2e}",
            e.mesh.triangle_count()
        );
    }
}

fn zero_amplitude_regions(dir: &Path) {
    let path = dir.join("coarse_decimated-knight.off");
    let Ok(mesh) = load(&path) else {
        println!("\n[zero amplitude] {} not found — skipped", path.display());
        return;
    };
    let Ok(cwf) = swirl_cwf(mesh) else { return };
    println!(
        "\n[zero amplitude] coarse_decimated-knight, 5 levels (1.02M faces), 1 thread, best of {REPEATS}: \
         amplitude zero on a fraction of the base vertices (z work is skipped where a face's z \
         are all zero; the mesh is always fully refined, so there are no cracks)"
    );
    let (b, w, a, z) = (
        cwf.base().clone(),
        cwf.omega().to_vec(),
        cwf.amplitude().to_vec(),
        cwf.zeta().to_vec(),
    );
    let xs: Vec<f64> = b.positions().iter().map(|p| p[0]).collect();
    let mut sorted = xs.clone();
    sorted.sort_by(f64::total_cmp);
    for frac in [0.0, 0.5, 0.9, 1.0] {
        let cut = if frac == 0.0 {
            f64::NEG_INFINITY
        } else {
            sorted[((sorted.len() - 1) as f64 * frac) as usize]
        };
        let amp: Vec<f64> = a
            .iter()
            .zip(&xs)
            .map(|(&a, &x)| if x <= cut { 0.0 } else { a })
            .collect();
        // faces whose one-ring neighbourhood has non-zero amplitude: what adaptive refinement
        // would have to refine
        let live: Vec<bool> = amp.iter().map(|&x| x > 0.0).collect();
        let mut touched = vec![false; b.vertex_count()];
        for t in b.triangles() {
            if t.iter().any(|&v| live[v as usize]) {
                t.iter().for_each(|&v| touched[v as usize] = true);
            }
        }
        let active = b
            .triangles()
            .iter()
            .filter(|t| t.iter().any(|&v| touched[v as usize]))
            .count();
        let c = Cwf::new(b.clone(), w.clone(), amp, z.clone()).unwrap();
        let t = best_time(&c, 5, 1);
        let (_, stats) = in_pool(1, || c.evaluate(5, &EvalOptions::default()).unwrap());
        let part = |p: LevelPart| {
            stats
                .stages
                .iter()
                .filter(|(n, _)| matches!(n, EvalStage::Level(_, part) if *part == p))
                .map(|(_, s)| s)
                .sum::<f64>()
        };
        println!(
            "  zero on {:>3.0}% of base vertices: {t:.4} s (z {:.4} s, rest {:.4} s); base faces with \
             non-zero amplitude in their neighbourhood: {:.0}%",
            100.0 * frac,
            part(LevelPart::Z),
            stats.total_seconds() - part(LevelPart::Z),
            100.0 * active as f64 / b.triangle_count() as f64
        );
    }
}

fn grid(n: usize, jitter: f64) -> TriMesh {
    let mut s = 12345u64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let h = 1.0 / n as f64;
    let mut p = vec![];
    for j in 0..=n {
        for i in 0..=n {
            let inner = i > 0 && j > 0 && i < n && j < n;
            let (dx, dy) = if inner {
                (2.0 * jitter * h * rnd(), 2.0 * jitter * h * rnd())
            } else {
                (0.0, 0.0)
            };
            p.push([i as f64 * h + dx, j as f64 * h + dy, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut t = vec![];
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(p, t).unwrap()
}

fn coarse_files(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return vec![];
    };
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy();
            n.starts_with("coarse_") && (n.ends_with(".obj") || n.ends_with(".off"))
        })
        .collect();
    v.sort();
    v
}

/// Loads a corpus mesh with pleat's own reader.
fn load(path: &Path) -> Result<TriMesh, String> {
    pleat::mesh::io::read_mesh(path).map_err(|e| e.to_string())
}

/// Renders a few evaluated surfaces to `$PLEAT_RENDER_DIR` (default `/tmp`) as PNG, for a look.
fn render_examples(dir: &Path) {
    let out = PathBuf::from(std::env::var("PLEAT_RENDER_DIR").unwrap_or_else(|_| "/tmp".into()));
    for (name, levels) in [
        ("coarse_spot_1k.obj", 4),
        ("coarse_decimated-knight.off", 4),
    ] {
        let Ok(mesh) = load(&dir.join(name)) else {
            continue;
        };
        let cwf = swirl_cwf(mesh).unwrap();
        let (e, _) = cwf.evaluate(levels, &EvalOptions::default()).unwrap();
        let path = out.join(format!("wrinkle_{}.png", name.split('.').next().unwrap()));
        write_png(&path, &rasterize(&e.mesh, 900));
        println!("wrote {}", path.display());
    }
}

/// Orthographic z-buffered Lambert rendering (view along −z after a fixed tilt), greyscale.
fn rasterize(m: &TriMesh, size: usize) -> Vec<u8> {
    let (s, c) = 0.5f64.sin_cos();
    let view = |p: [f64; 3]| [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]];
    let pts: Vec<[f64; 3]> = m.positions().iter().map(|&p| view(p)).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &pts {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let scale = 0.95 * size as f64 / (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let px = |p: [f64; 3]| {
        [
            (p[0] - lo[0]) * scale + 0.025 * size as f64,
            size as f64 - ((p[1] - lo[1]) * scale + 0.025 * size as f64),
            p[2],
        ]
    };
    let mut depth = vec![f64::NEG_INFINITY; size * size];
    let mut img = vec![255u8; size * size];
    for t in m.triangles() {
        let [a, b, cc] = t.map(|v| pts[v as usize]);
        let (u, w) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]],
        );
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if l == 0.0 {
            continue;
        }
        let light = [0.3, 0.5, 0.81];
        let shade = ((n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / l).abs();
        let grey = (40.0 + 215.0 * shade) as u8;
        let [p0, p1, p2] = [a, b, cc].map(px);
        let (x0, x1) = (
            p0[0].min(p1[0]).min(p2[0]).max(0.0) as usize,
            (p0[0].max(p1[0]).max(p2[0]) as usize).min(size - 1),
        );
        let (y0, y1) = (
            p0[1].min(p1[1]).min(p2[1]).max(0.0) as usize,
            (p0[1].max(p1[1]).max(p2[1]) as usize).min(size - 1),
        );
        let area = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]);
        if area.abs() < 1e-12 {
            continue;
        }
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (fx, fy) = (x as f64 + 0.5, y as f64 + 0.5);
                let w0 = ((p1[0] - fx) * (p2[1] - fy) - (p2[0] - fx) * (p1[1] - fy)) / area;
                let w1 = ((p2[0] - fx) * (p0[1] - fy) - (p0[0] - fx) * (p2[1] - fy)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * p0[2] + w1 * p1[2] + w2 * p2[2];
                let i = y * size + x;
                if z > depth[i] {
                    depth[i] = z;
                    img[i] = grey;
                }
            }
        }
    }
    img
}

/// A greyscale PNG with stored (uncompressed) deflate blocks: no compression library needed.
fn write_png(path: &Path, grey: &[u8]) {
    let size = (grey.len() as f64).sqrt() as usize;
    let mut raw = Vec::with_capacity(grey.len() + size);
    for row in grey.chunks_exact(size) {
        raw.push(0u8);
        raw.extend_from_slice(row);
    }
    let mut z = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = raw.chunks(65_535).collect();
    for (i, b) in blocks.iter().enumerate() {
        z.push(u8::from(i + 1 == blocks.len()));
        z.extend_from_slice(&(b.len() as u16).to_le_bytes());
        z.extend_from_slice(&(!(b.len() as u16)).to_le_bytes());
        z.extend_from_slice(b);
    }
    let (mut s1, mut s2) = (1u32, 0u32);
    for &b in &raw {
        s1 = (s1 + b as u32) % 65_521;
        s2 = (s2 + s1) % 65_521;
    }
    z.extend_from_slice(&((s2 << 16) | s1).to_be_bytes());
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&(size as u32).to_be_bytes());
    ihdr.extend_from_slice(&(size as u32).to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]);
    for (kind, data) in [(b"IHDR", ihdr), (b"IDAT", z), (b"IEND", vec![])] {
        png.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut chunk = kind.to_vec();
        chunk.extend_from_slice(&data);
        png.extend_from_slice(&chunk);
        png.extend_from_slice(&crc32(&chunk).to_be_bytes());
    }
    std::fs::write(path, png).unwrap();
}

fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}
