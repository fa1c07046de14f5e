//! Measuring textured bakes against their targets: renders of the input and of its baked LOD
//! at `n_p = 200` compared by the independent rasterizer of `pleat::bake::render` (PSNR within
//! 2 dB of the closest-point reference, normal-map gain > 0), and the chart gutters checked
//! down to the mip level the texel rule implies (no texel a LOD UV samples mixes in another
//! chart's or unowned colour).
//!
//! Ignored tests write the published numbers and files (run them with `--release`):
//! - `publish_targets`: the docs/benchmarks/bake.md table, per shared asset and the generated
//!   sphere;
//! - `write_sphere_100k`: `target/bake_eval/sphere_100k.glb`, the speed benchmark input;
//! - `readme_picture`: `docs/bake_lods.png`.
#![cfg(feature = "bake")]

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use pleat::bake::appearance::AlphaMode;
use pleat::bake::render::{self, Mode, Surface};
use pleat::bake::{
    bake_chain, chain_glb, read_appearance, read_appearance_bytes, Appearance, BakeParams,
    BakeReport, BakedLevel, BakedMaterial, Image8,
};
use pleat::geom::Vec3;
use pleat::lowpoly::LodParams;

// ------------------------------------------------------------------------ generated asset --

/// Point of the unit sphere at texture coordinates (u, v): u = longitude, v = colatitude.
fn sphere_point(u: f64, v: f64) -> Vec3 {
    let (th, ph) = (PI * v, 2.0 * PI * u);
    Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
}

/// A smooth colour field of position (display sRGB in [0, 1]).
fn field(p: Vec3) -> [f64; 3] {
    let d = [
        Vec3::new(0.94, 0.28, 0.19).normalize(),
        Vec3::new(-0.18, 0.91, 0.37).normalize(),
        Vec3::new(0.27, -0.36, 0.89).normalize(),
    ];
    let f = [2.0, 2.5, 3.0];
    std::array::from_fn(|k| 0.5 + 0.5 * (PI * f[k] * d[k].dot(p) + k as f64).sin())
}

/// A UV sphere of `2 nu (nu/2 − 1)` triangles textured with [`field`] at `w × w/2`,
/// as a one-level GLB written by pleat's own writer (so read back exactly like an asset).
fn sphere_glb(nu: u32, w: u32) -> Vec<u8> {
    let nv = nu / 2;
    let (mut pos, mut nrm, mut uv, mut tris) = (vec![], vec![], vec![], vec![]);
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (f64::from(i) / f64::from(nu), f64::from(j) / f64::from(nv));
            let p = sphere_point(u, v);
            pos.push(p.to_array());
            nrm.push(p.to_array().map(|c| c as f32));
            uv.push([u as f32, v as f32]);
        }
    }
    let id = |i: u32, j: u32| j * (nu + 1) + i;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // Outward with this parameterisation: (a, c, b), (a, d, c).
            if j > 0 {
                tris.push([a, c, b]);
            }
            if j + 1 < nv {
                tris.push([a, d, c]);
            }
        }
    }
    let h = w / 2;
    let mut rgba = Vec::with_capacity((4 * w * h) as usize);
    for j in 0..h {
        for i in 0..w {
            let p = sphere_point(
                (f64::from(i) + 0.5) / f64::from(w),
                (f64::from(j) + 0.5) / f64::from(h),
            );
            let c = field(p).map(|x| (255.0 * x).round() as u8);
            rgba.extend_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }
    let level = BakedLevel {
        screen_size: 1.0,
        positions: pos,
        normals: nrm,
        tangents: None,
        uvs: Some(uv),
        colors: None,
        triangles: tris,
        material: BakedMaterial {
            base_color_factor: [1.0; 4],
            base_color: Some(Image8 {
                width: w,
                height: h,
                rgba,
            }),
            metallic_factor: 0.0,
            roughness_factor: 1.0,
            metallic_roughness: None,
            occlusion: None,
            emissive_factor: [0.0; 3],
            emissive: None,
            normal: None,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
        },
        report: BakeReport::default(),
    };
    chain_glb(&[&level]).unwrap()
}

fn sphere(nu: u32, w: u32) -> Appearance {
    read_appearance_bytes(&sphere_glb(nu, w), None, "sphere").unwrap()
}

/// `../shared/assets/textured` from the crate root or a worktree; `None` (skipped) if absent.
fn assets() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let found = ["../shared/assets/textured", "../../shared/assets/textured"]
        .iter()
        .map(|d| root.join(d))
        .find(|d| d.join("MANIFEST.csv").is_file());
    if found.is_none() {
        eprintln!("SKIPPED: ../shared/assets/textured is absent");
    }
    found
}

fn eval_params() -> BakeParams {
    BakeParams {
        evaluate: true,
        ..BakeParams::default()
    }
}

fn bake_one(app: &Appearance, n_p: f64, params: &BakeParams) -> BakedLevel {
    let chain = bake_chain(app, &[n_p], &LodParams::default(), params, &mut |_| true).unwrap();
    chain.levels.into_iter().next().unwrap().baked
}

// ------------------------------------------------------------------------------- targets --

/// PSNR of the bake within 2 dB of the closest-point reference, and the PSNR itself (with
/// its reference) printed.
fn check_appearance(name: &str, level: &BakedLevel) {
    let r = &level.report;
    let psnr = r.appearance_psnr_db.expect("evaluated");
    let reference = r.appearance_psnr_reference_db.expect("evaluated");
    eprintln!(
        "{name}: n_p {} {} faces {}² — PSNR {psnr:.2} dB (reference {reference:.2}), normal gain \
         {:?}, eval {:.2} s",
        level.screen_size,
        level.triangles.len(),
        r.texture_size,
        r.normal_map_gain_db,
        r.evaluate_seconds
    );
    assert!(psnr > 20.0, "{name}: PSNR {psnr}");
    assert!(
        reference - psnr <= 2.0,
        "{name}: the bake loses {} dB against the closest-point reference",
        reference - psnr
    );
}

#[test]
fn generated_sphere_meets_the_appearance_target() {
    let app = sphere(96, 512);
    let level = bake_one(&app, 200.0, &eval_params());
    check_appearance("sphere", &level);
    // A smooth sphere's normal map encodes its vertex normals: nothing to gain or lose.
    let gain = level.report.normal_map_gain_db.expect("normal map baked");
    assert!(
        gain.abs() < 0.2,
        "normal map gain {gain} dB on a smooth sphere"
    );
    // Without `evaluate` nothing is measured.
    let plain = bake_one(&app, 50.0, &BakeParams::default());
    assert_eq!(plain.report.appearance_psnr_db, None);
}

#[test]
fn shared_torus_normal_map_earns_its_place() {
    let Some(dir) = assets() else { return };
    let app = read_appearance(&dir.join("gen_torus_normalmap.glb")).unwrap();
    let level = bake_one(&app, 200.0, &eval_params());
    check_appearance("torus", &level);
    let gain = level.report.normal_map_gain_db.expect("normal map baked");
    assert!(gain > 0.0, "normal map gain {gain} dB");
}

/// The COLOR_0-only teapot: 920 LOD vertices cannot follow its colour field (the vertex fit
/// lost 5.75 dB), so `VertexColors::Auto` bakes a base-colour texture, within the 2 dB target.
#[test]
fn shared_vertex_colour_teapot_meets_the_appearance_target() {
    let Some(dir) = assets() else { return };
    let app = read_appearance(&dir.join("gen_teapot_vertexcolor.glb")).unwrap();
    assert!(!app.has_textures() && app.colors.is_some());
    let level = bake_one(&app, 200.0, &eval_params());
    let r = &level.report;
    let (fit, allowed) = (
        r.vertex_fit_error.unwrap(),
        r.vertex_fit_allowed_error.unwrap(),
    );
    eprintln!("teapot: vertex fit error {fit:.2} /255, allowed {allowed:.2}");
    assert!(fit > allowed);
    assert!(level.uvs.is_some() && level.colors.is_none());
    check_appearance("teapot", &level);
    // Its 554 charts mixed 0.11 % of mip-2 samples with the nearest-chart dilation and the
    // 15-texel gutter; the block-owning dilation keeps them clean.
    check_seams("teapot", &level, 0.0);
}

/// The docs/benchmarks/bake.md table: every shared asset and the generated sphere at n_p = 200.
#[test]
#[ignore = "publishes the docs/benchmarks/bake.md numbers; run with --release"]
fn publish_targets() {
    let mut cases: Vec<(String, Appearance)> =
        vec![("generated sphere 9k".into(), sphere(96, 512))];
    if let Some(dir) = assets() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "glb"))
            .collect();
        files.sort();
        // `PLEAT_ASSETS=a.glb,b.glb` restricts the table to those files.
        let only: Option<Vec<String>> = std::env::var("PLEAT_ASSETS")
            .ok()
            .map(|s| s.split(',').map(String::from).collect());
        for f in files {
            let name = f.file_name().unwrap().to_string_lossy().to_string();
            if only.as_ref().is_some_and(|o| !o.contains(&name)) {
                continue;
            }
            cases.push((name, read_appearance(&f).unwrap()));
        }
    }
    println!(
        "| asset | faces in | LOD faces | texels | bake s | PSNR dB | reference dB | loss dB | \
         pooled loss dB | normal gain dB | seams clean to mip | mip 2 mixed | padding | \
         report clean mip | zero-UV slivers |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (name, app) in &cases {
        // The LOD as `bake_chain` makes it, cached (see `cached_lod`), baked as `bake_chain` does.
        let lod = cached_lod(name, app);
        let index = pleat::bake::InputIndex::new(&app.mesh);
        let level = pleat::bake::bake_level(app, &index, &lod, 200.0, &eval_params()).unwrap();
        let r = &level.report;
        let f = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.2}"));
        let slivers = if level.uvs.is_some() {
            zero_uv_area(&level).to_string()
        } else {
            "–".into()
        };
        let (seams, mixed) = if level.uvs.is_some() {
            let clean = (0..=4)
                .take_while(|&l| seam_violations(&level, l).0 == 0)
                .last()
                .map_or("none".into(), |l| l.to_string());
            let (bad, total) = seam_violations(&level, 2);
            (clean, format!("{:.2} %", 100.0 * bad as f64 / total as f64))
        } else {
            ("(vertex colours)".into(), "–".into())
        };
        println!(
            "| {name} | {} | {} | {}² | {:.2} | {} | {} | {} | {} | {} | {seams} | {mixed} | {} | \
             {} | {slivers} |",
            app.mesh.triangle_count(),
            level.triangles.len(),
            r.texture_size,
            r.total_seconds,
            f(r.appearance_psnr_db),
            f(r.appearance_psnr_reference_db),
            f(r.appearance_psnr_reference_db
                .zip(r.appearance_psnr_db)
                .map(|(a, b)| a - b)),
            f(r.appearance_psnr_reference_pooled_db
                .zip(r.appearance_psnr_pooled_db)
                .map(|(a, b)| a - b)),
            f(r.normal_map_gain_db),
            r.atlas_padding,
            r.seam_clean_mip.map_or("none".into(), |m| m.to_string()),
        );
    }
}

// ------------------------------------------------------------------------------ mip seams --

/// Half a texel diagonal: texels this close to a triangle hold surface values (the bake's
/// documented coverage rule).
const REACH: f64 = 0.7072;

/// Distance from `c` to the boundary of 2D triangle `p`.
fn distance(p: &[[f64; 2]; 3], c: [f64; 2]) -> f64 {
    (0..3)
        .map(|k| {
            let (a, b) = (p[k], p[(k + 1) % 3]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let len2 = d[0] * d[0] + d[1] * d[1];
            let s = if len2 > 0.0 {
                (((c[0] - a[0]) * d[0] + (c[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            ((a[0] + s * d[0] - c[0]).powi(2) + (a[1] + s * d[1] - c[1]).powi(2)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Chart of every level-0 texel: the chart whose triangle covers its centre, or lies within
/// [`REACH`] of it (the bake samples those too), else (gutter) the chart whose texel the
/// bake's documented dilation copies there: a 4-neighbour breadth-first search from the
/// covered texels in which a texel of a `2^m`-block owned by one chart's bilinear footprint
/// (`pleat::bake::atlas::footprint_owners`, `m` = the rule's deepest mip 2) takes only
/// that chart's texels, then the nearest assigned texel for what is left. Charts are the
/// components of triangles sharing a vertex UV.
fn texel_charts(level: &BakedLevel) -> (Vec<u32>, Vec<u32>) {
    use pleat::bake::atlas::{footprint_owners, BLOCK_FREE, BLOCK_SHARED};
    let uvs = level.uvs.as_ref().unwrap();
    let side = level.material.base_color.as_ref().unwrap().width as usize;
    let tris = &level.triangles;
    // Union-find over triangles by shared UV points.
    let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let key = |v: u32| uvs[v as usize].map(f32::to_bits);
    let mut first = std::collections::HashMap::new();
    for (t, tri) in tris.iter().enumerate() {
        for &v in tri {
            if let Some(&o) = first.get(&key(v)) {
                let (x, y) = (find(&mut parent, o), find(&mut parent, t as u32));
                parent[x.max(y) as usize] = x.min(y);
            } else {
                first.insert(key(v), t as u32);
            }
        }
    }
    let chart: Vec<u32> = (0..tris.len() as u32)
        .map(|t| find(&mut parent, t))
        .collect();
    let mut owner = vec![u32::MAX; side * side];
    let mut inside = vec![false; side * side];
    let s = side as f64;
    for (t, tri) in tris.iter().enumerate() {
        let p = tri.map(|v| uvs[v as usize].map(|c| f64::from(c) * s));
        let area =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        if area == 0.0 {
            continue;
        }
        let lo =
            [0, 1].map(|a| (p[0][a].min(p[1][a]).min(p[2][a]) - 1.0).floor().max(0.0) as usize);
        let hi =
            [0, 1].map(|a| ((p[0][a].max(p[1][a]).max(p[2][a]) + 1.0).ceil() as usize).min(side));
        for j in lo[1]..hi[1] {
            for i in lo[0]..hi[0] {
                let c = [i as f64 + 0.5, j as f64 + 0.5];
                let e = |a: [f64; 2], b: [f64; 2]| {
                    ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) / area
                };
                let k = j * side + i;
                if e(p[1], p[2]) >= 0.0 && e(p[2], p[0]) >= 0.0 && e(p[0], p[1]) >= 0.0 {
                    owner[k] = chart[t];
                    inside[k] = true;
                } else if !inside[k] && owner[k] == u32::MAX && distance(&p, c) <= REACH {
                    owner[k] = chart[t];
                }
            }
        }
    }
    let m = pleat::bake::atlas::deepest_mip(2.0);
    let uv = |v: u32| uvs[v as usize].map(|c| f64::from(c) * s);
    let blocks = footprint_owners(side as u32, m, tris, &uv, &chart);
    let (b, nb) = (1usize << m, side.div_ceil(1 << m));
    let takes = |k: usize, c: u32| {
        let o = blocks[(k / side / b) * nb + (k % side) / b];
        o == BLOCK_FREE || o == BLOCK_SHARED || o == c
    };
    let mut queue: std::collections::VecDeque<usize> =
        (0..owner.len()).filter(|&k| owner[k] != u32::MAX).collect();
    for pass in 0..2 {
        if pass == 1 {
            queue.extend((0..owner.len()).filter(|&k| owner[k] != u32::MAX));
        }
        while let Some(k) = queue.pop_front() {
            let (i, j) = (k % side, k / side);
            let mut near = vec![];
            if i > 0 {
                near.push(k - 1);
            }
            if i + 1 < side {
                near.push(k + 1);
            }
            if j > 0 {
                near.push(k - side);
            }
            if j + 1 < side {
                near.push(k + side);
            }
            for n in near {
                if owner[n] == u32::MAX && (pass == 1 || takes(n, owner[k])) {
                    owner[n] = owner[k];
                    queue.push_back(n);
                }
            }
        }
    }
    (owner, chart)
}

/// At mip level `l` (box filter: mip texel `(I, J)` averages level-0 texels
/// `[2^l I, 2^l (I+1))²`), the texels bilinear filtering reads at points of every triangle
/// (corners, edge points, centroid) — those with non-zero weight — must average only level-0
/// texels of the triangle's own chart. Triangles of zero UV area are left out (see
/// [`zero_uv_area`]). Returns (violating samples, samples).
fn seam_violations(level: &BakedLevel, l: u32) -> (usize, usize) {
    let (owner, chart) = texel_charts(level);
    let uvs = level.uvs.as_ref().unwrap();
    let side = level.material.base_color.as_ref().unwrap().width as usize;
    let block = 1usize << l;
    let mip = (side / block).max(1);
    // Per mip texel: its single chart, or u32::MAX when mixed.
    let mut pure = vec![u32::MAX; mip * mip];
    for (jj, row) in pure.chunks_mut(mip).enumerate() {
        for (ii, px) in row.iter_mut().enumerate() {
            let first = owner[jj * block * side + ii * block];
            let same = (0..block).all(|dj| {
                (0..block).all(|di| owner[(jj * block + dj) * side + ii * block + di] == first)
            });
            *px = if same { first } else { u32::MAX };
        }
    }
    let mut bad = 0;
    let mut total = 0;
    let bary = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [1.0 / 3.0; 3],
    ];
    for (t, tri) in level.triangles.iter().enumerate() {
        // Zero UV area: a sliver chart xatlas collapsed to a point; it covers no texel and is
        // counted apart (`zero_uv_area`).
        let p = tri.map(|v| uvs[v as usize].map(f64::from));
        if pleat::bake::atlas::uv_area(&p) == 0.0 {
            continue;
        }
        for b in bary {
            let uv = [0, 1].map(|a| {
                (0..3)
                    .map(|k| b[k] * f64::from(uvs[tri[k] as usize][a]))
                    .sum::<f64>()
            });
            let x = uv[0] * mip as f64 - 0.5;
            let y = uv[1] * mip as f64 - 0.5;
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let taps = [
                (x0, y0, (1.0 - fx) * (1.0 - fy)),
                (x0 + 1.0, y0, fx * (1.0 - fy)),
                (x0, y0 + 1.0, (1.0 - fx) * fy),
                (x0 + 1.0, y0 + 1.0, fx * fy),
            ];
            total += 1;
            let clean = taps.iter().filter(|tap| tap.2 > 1e-6).all(|&(i, j, _)| {
                let i = (i as i64).clamp(0, mip as i64 - 1) as usize;
                let j = (j as i64).clamp(0, mip as i64 - 1) as usize;
                pure[j * mip + i] == chart[t]
            });
            bad += usize::from(!clean);
        }
    }
    (bad, total)
}

/// Triangles of `level` with zero UV area: LOD slivers (~10⁻⁶ of the median face area)
/// whose chart xatlas collapsed to a point; they cover no texel, so the seam check leaves
/// them out and the tables count them.
fn zero_uv_area(level: &BakedLevel) -> usize {
    let uvs = level.uvs.as_ref().unwrap();
    level
        .triangles
        .iter()
        .filter(|t| pleat::bake::atlas::uv_area(&t.map(|v| uvs[v as usize].map(f64::from))) == 0.0)
        .count()
}

/// The mip level the texel rule implies: the atlas gives `k = 2` texels per screen pixel at
/// the level's `n_p` (`AtlasParams::texels_per_pixel`), so at its own screen size the level is
/// read at mip `log2 k = 1`, and at `n_p / 2`, where the next level of a ×2 chain takes over,
/// at mip 2 (`pleat::bake::atlas::deepest_mip`); the default gutter follows that rule.
const RULE_MIP: u32 = 2;

/// At most `tolerance` (a fraction) of the samples may read another chart at mips 0 … 2;
/// with no tolerance the bake must also report seams clean to mip 2 by construction.
fn check_seams(name: &str, level: &BakedLevel, tolerance: f64) {
    if tolerance == 0.0 {
        assert_eq!(level.report.seam_clean_mip, Some(RULE_MIP), "{name}");
    }
    for l in 0..=RULE_MIP {
        let (bad, total) = seam_violations(level, l);
        eprintln!("{name}: mip {l}: {bad} of {total} samples mix charts");
        assert!(
            bad as f64 <= tolerance * total as f64,
            "{name}: mip {l}: {bad} of {total} samples read another chart"
        );
    }
}

#[test]
fn chart_gutters_hold_down_to_the_rule_mip_level() {
    assert_eq!(pleat::bake::atlas::deepest_mip(2.0), RULE_MIP);
    let params = BakeParams::default();
    let app = sphere(64, 256);
    for n_p in [50.0, 200.0] {
        let level = bake_one(&app, n_p, &params);
        check_seams(&format!("sphere n_p {n_p}"), &level, 0.0);
    }
    let Some(dir) = assets() else { return };
    for name in [
        "gen_elephant_sin.glb",
        "gen_torus_normalmap.glb",
        "gen_spot_two_materials.glb",
        "khronos_box_textured.glb",
    ] {
        let app = read_appearance(&dir.join(name)).unwrap();
        let level = bake_one(&app, 100.0, &params);
        check_seams(name, &level, 0.0);
    }
}

#[test]
fn the_seam_check_sees_bleeding() {
    // A level whose padding is 0 packs charts edge to edge: the check must flag mip 2.
    let app = sphere(64, 256);
    let mut params = BakeParams::default();
    params.atlas.padding = 0;
    let level = bake_one(&app, 200.0, &params);
    let (bad, _) = seam_violations(&level, 2);
    assert!(bad > 0, "no violation found without a gutter");
    // The bake's own by-construction report sees it too.
    assert!(level.report.seam_clean_mip.is_none_or(|m| m < RULE_MIP));
}

// ------------------------------------------------------------------------ published files --

/// `target/bake_eval/sphere_100k.glb`: a ~100k-face textured sphere (2048×1024 texture).
#[test]
#[ignore = "writes the speed benchmark's input"]
fn write_sphere_100k() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bake_eval");
    std::fs::create_dir_all(&dir).unwrap();
    let glb = sphere_glb(316, 2048);
    let app = read_appearance_bytes(&glb, None, "sphere").unwrap();
    eprintln!("{} faces", app.mesh.triangle_count());
    std::fs::write(dir.join("sphere_100k.glb"), glb).unwrap();
}

/// `docs/bake_lods.png`: the input and its baked LODs at n_p = 200, 100, 50, side by side,
/// textured and lit, rendered by `pleat::bake::render` from one view at 200 pixels.
#[test]
#[ignore = "writes docs/bake_lods.png; run with --release"]
fn readme_picture() {
    let Some(dir) = assets() else { return };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rows = ["gen_spot_two_materials.glb", "gen_torus_normalmap.glb"];
    let sizes = [200.0, 100.0, 50.0];
    let mut tiles: Vec<Vec<Image8>> = vec![];
    for name in rows {
        let app = read_appearance(&dir.join(name)).unwrap();
        let chain = bake_chain(
            &app,
            &sizes,
            &LodParams::default(),
            &BakeParams::default(),
            &mut |_| true,
        )
        .unwrap();
        let view = render::views(app.mesh.bbox(), 24, 200.0)[9];
        let bg = [255, 255, 255];
        let input = render::InputSurface(&app);
        let g = render::rasterize(&view, input.positions(), input.triangles());
        let mut row = vec![render::shade(&g, &view, &input, Mode::TexturedShaded).to_image(bg)];
        for l in &chain.levels {
            let s = render::LevelSurface {
                level: &l.baked,
                normal_map: true,
            };
            let g = render::rasterize(&view, &l.baked.positions, &l.baked.triangles);
            row.push(render::shade(&g, &view, &s, Mode::TexturedShaded).to_image(bg));
        }
        tiles.push(row);
    }
    let side = tiles[0][0].width as usize;
    let (w, h) = (side * tiles[0].len(), side * tiles.len());
    let mut rgba = vec![255u8; 4 * w * h];
    for (r, row) in tiles.iter().enumerate() {
        for (c, img) in row.iter().enumerate() {
            for j in 0..side {
                let dst = 4 * ((r * side + j) * w + c * side);
                let src = 4 * j * side;
                rgba[dst..dst + 4 * side].copy_from_slice(&img.rgba[src..src + 4 * side]);
            }
        }
    }
    let img = Image8 {
        width: w as u32,
        height: h as u32,
        rgba,
    };
    let png = pleat::bake::output::png_bytes(&img).unwrap();
    std::fs::create_dir_all(root.join("docs")).unwrap();
    std::fs::write(root.join("docs/bake_lods.png"), &png).unwrap();
    eprintln!("docs/bake_lods.png: {}×{}, {} bytes", w, h, png.len());
}

/// The speed target: a 1024² bake of a ~1k-face LOD of `target/bake_eval/sphere_100k.glb`
/// (`write_sphere_100k`), stage by stage, best of 3. The LOD (`PLEAT_NP`, default 400) is
/// cached as `target/bake_eval/sphere_100k_lod<n_p>.obj`; `PLEAT_PADDING` overrides the gutter.
#[test]
#[ignore = "speed benchmark; run with --release after write_sphere_100k"]
fn bake_speed() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bake_eval");
    let app = read_appearance(&dir.join("sphere_100k.glb")).unwrap();
    let n_p: f64 = std::env::var("PLEAT_NP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(400.0);
    let cache = dir.join(format!("sphere_100k_lod{n_p}.obj"));
    let lod = match pleat::mesh::io::read_mesh(&cache) {
        Ok(m) => m,
        Err(_) => {
            let params = LodParams {
                screen_size: n_p,
                ..LodParams::default()
            };
            let (m, _) = pleat::lowpoly::generate(&app.mesh, &params, &mut |_| true).unwrap();
            pleat::mesh::io::write_mesh(&cache, &m).unwrap();
            m
        }
    };
    let mut params = BakeParams::default();
    params.atlas.size = Some(1024);
    // `PLEAT_PADDING` compares gutters (default: the rule's).
    if let Some(p) = std::env::var("PLEAT_PADDING")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        params.atlas.padding = p;
    }
    let t = std::time::Instant::now();
    let index = pleat::bake::InputIndex::new(&app.mesh);
    eprintln!("input index {:.3} s", t.elapsed().as_secs_f64());
    for _ in 0..3 {
        let l = pleat::bake::bake_level(&app, &index, &lod, n_p, &params).unwrap();
        let r = &l.report;
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        l.material.base_color.as_ref().map(|i| &i.rgba).hash(&mut h);
        l.material.normal.as_ref().map(|i| &i.rgba).hash(&mut h);
        format!("{:?}", l.uvs).hash(&mut h);
        eprintln!("output hash {:016x}", h.finish());
        eprintln!(
            "{} → {} faces, {}²: total {:.3} s = atlas {:.3} + tangents {:.3} + raster {:.3} + \
             sample {:.3} + dilate {:.3} + measure {:.3}",
            app.mesh.triangle_count(),
            lod.triangle_count(),
            r.texture_size,
            r.total_seconds,
            r.atlas_seconds,
            r.tangent_seconds,
            r.raster_seconds,
            r.sample_seconds,
            r.dilate_seconds,
            r.measure_seconds
        );
    }
}

/// Bake speed: the whole `--bake` chain {50, 100, 200} (geometry, bake, PNG
/// encoding) against the geometry-only chain, measured in one process on the same assets
/// (`PLEAT_ASSETS=a.glb,b.glb`, default duck, spot, torus). The geometry seconds are
/// `lowpoly::generate_chain`'s inside `bake_chain` — exactly the geometry-only chain. Prints
/// one row per asset: geometry s, bake s (per stage summed over levels), png s, ratio.
#[test]
#[ignore = "measures the chain speed ratio; run with --release"]
fn chain_speed() {
    let Some(dir) = assets() else { return };
    let names: Vec<String> = std::env::var("PLEAT_ASSETS").map_or_else(
        |_| {
            [
                "khronos_duck.glb",
                "gen_spot_two_materials.glb",
                "gen_torus_normalmap.glb",
            ]
            .map(String::from)
            .to_vec()
        },
        |s| s.split(',').map(String::from).collect(),
    );
    println!(
        "| asset | geometry s | bake s | atlas s | sample s | dilate s | measure s | png s | \
         ratio |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for name in names {
        let app = read_appearance(&dir.join(&name)).unwrap();
        let chain = bake_chain(
            &app,
            &[50.0, 100.0, 200.0],
            &LodParams::default(),
            &BakeParams::default(),
            &mut |_| true,
        )
        .unwrap();
        let refs: Vec<&BakedLevel> = chain.levels.iter().map(|l| &l.baked).collect();
        let (_, png) = pleat::bake::chain_glb_with_progress(&refs, &mut |_| true).unwrap();
        let sum = |f: fn(&BakeReport) -> f64| refs.iter().map(|l| f(&l.report)).sum::<f64>();
        let g = chain.geometry_seconds;
        println!(
            "| {name} | {g:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {png:.2} | {:.2} |",
            chain.bake_seconds,
            sum(|r| r.atlas_seconds),
            sum(|r| r.sample_seconds),
            sum(|r| r.dilate_seconds),
            sum(|r| r.measure_seconds),
            (g + chain.bake_seconds + png) / g
        );
    }
}

// ------------------------------------------------------------------------- seam levers --

/// The n_p = 200 LOD of `app` (as `bake_chain` makes it), cached bit-exactly as PLY in
/// `target/bake_eval/lod_<name>_200.ply` so parameter sweeps of the bake skip the geometry.
fn cached_lod(name: &str, app: &Appearance) -> pleat::mesh::TriMesh {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bake_eval");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("lod_{name}_200.ply"));
    if let Ok(m) = pleat::mesh::io::read_mesh(&path) {
        return m;
    }
    let chain =
        pleat::lowpoly::generate_chain(&app.mesh, &[200.0], &LodParams::default(), &mut |_| true)
            .unwrap();
    let lod = chain.into_iter().next().unwrap().0;
    pleat::mesh::io::write_mesh(&path, &lod).unwrap();
    lod
}

/// Sweep of the gutter levers (`PLEAT_ASSETS` picks assets, `PLEAT_LEVERS` the
/// `padding:block_align` pairs, e.g. `15:0,8:0,8:1`): per asset and lever, the texture size,
/// charts, padding used, mip-2 mixing and PSNR at n_p = 200 (docs/design-notes-lod.md, "Textured
/// bakes").
#[test]
#[ignore = "parameter sweep for the design notes; run with --release"]
fn seam_levers() {
    let Some(dir) = assets() else { return };
    let names = std::env::var("PLEAT_ASSETS").unwrap_or("gen_teapot_vertexcolor.glb".into());
    let levers = std::env::var("PLEAT_LEVERS").unwrap_or("15:0".into());
    for name in names.split(',') {
        let app = read_appearance(&dir.join(name)).unwrap();
        let lod = cached_lod(name, &app);
        let index = pleat::bake::InputIndex::new(&app.mesh);
        for lever in levers.split(',').filter(|s| !s.is_empty()) {
            let (p, b) = lever.split_once(':').unwrap();
            let mut params = eval_params();
            params.atlas.padding = p.parse().unwrap();
            params.atlas.block_align = b == "1";
            let level = pleat::bake::bake_level(&app, &index, &lod, 200.0, &params).unwrap();
            let r = &level.report;
            let mixed: Vec<String> = (0..=3)
                .map(|l| {
                    let (bad, total) = seam_violations(&level, l);
                    format!("{:.2}", 100.0 * bad as f64 / total as f64)
                })
                .collect();
            let zero = zero_uv_area(&level);
            println!(
                "{name} padding {p} align {b}: {}² charts {} used {} clean mip {:?} overlapping {} \
                 zero-area {zero} mixed % mip0..3 {} PSNR {:.2} ref {:.2} bake {:.2} s",
                r.texture_size,
                r.charts,
                r.atlas_padding,
                r.seam_clean_mip,
                r.overlapping_texels,
                mixed.join("/"),
                r.appearance_psnr_db.unwrap_or(f64::NAN),
                r.appearance_psnr_reference_db.unwrap_or(f64::NAN),
                r.total_seconds
            );
        }
    }
}
