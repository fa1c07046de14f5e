//! Benchmark of instancing in glTF scenes: a scene of 5 distinct meshes, once each, against
//! the same 5 meshes instanced by 200 nodes. Each mesh's chain is baked once however many
//! nodes show it, so the two should take the same time; the output (one level node per
//! instance and level) is written too. Interleaved runs; prints both medians and their ratio.
//!
//! `cargo bench --bench scene` (release). Options after `--`: `--repeat N` (default 5),
//! `--screen-size N` (default 30).

use std::time::Instant;

use pleat::bake::scene::{lod_scene, scene_glb, GltfScene, SceneParams, WriteOptions};
use pleat::lowpoly::LodParams;

#[path = "../tests/common/gltf_build.rs"]
mod gltf_build;

/// Seconds to read, bake and write `bytes` as a scene at `n_p`; the number of chains.
fn bake(bytes: &[u8], n_p: f64) -> (f64, usize) {
    let t = Instant::now();
    let scene = GltfScene::from_bytes(bytes, None, "bench").expect("a valid scene");
    let params = SceneParams {
        screen_sizes: vec![n_p],
        lod: LodParams::default(),
        cage: false,
        bake: None,
        skin_error: 0.0,
        nodes: None,
    };
    let chains = lod_scene(&scene, &params, &mut |_| true).expect("the bake");
    let out = scene_glb(&scene, &chains, &WriteOptions::default()).expect("the output");
    assert!(!out.is_empty());
    (t.elapsed().as_secs_f64(), chains.len())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let opt = |name: &str, default: f64| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .map_or(default, |v| v.parse().expect("a number"))
    };
    let (repeat, n_p) = (opt("--repeat", 5.0) as usize, opt("--screen-size", 30.0));
    let few = gltf_build::instanced_scene(5, 5);
    let many = gltf_build::instanced_scene(5, 200);
    let (mut t_few, mut t_many) = (Vec::new(), Vec::new());
    for _ in 0..repeat.max(1) {
        let (a, ca) = bake(&few, n_p);
        let (b, cb) = bake(&many, n_p);
        assert_eq!((ca, cb), (5, 5), "one chain per mesh");
        t_few.push(a);
        t_many.push(b);
    }
    let (a, b) = (median(t_few), median(t_many));
    println!(
        "threads: {}, n_p = {n_p}, {repeat} interleaved runs",
        rayon::current_num_threads()
    );
    println!("5 meshes, 5 nodes:   {a:.3} s (median)");
    println!("5 meshes, 200 nodes: {b:.3} s (median)");
    println!("ratio: {:.2}", b / a);
}
