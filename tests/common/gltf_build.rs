//! glTF test scenes built by hand: a GLB writer, a buffer/accessor builder, a gridded box and
//! a scene of many instances of a few meshes. Shared by `tests/gltf_scene.rs` and
//! `benches/scene.rs` (and the GLB writer by `tests/bake.rs`).
#![allow(dead_code)]

use serde_json::{json, Value};

/// A GLB from a document and its binary chunk.
pub fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(doc).unwrap();
    j.resize(j.len().next_multiple_of(4), b' ');
    let mut b = bin.to_vec();
    b.resize(b.len().next_multiple_of(4), 0);
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// Buffer, buffer views and accessors under construction.
#[derive(Default)]
pub struct Builder {
    pub bin: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
}

impl Builder {
    /// The GLB of `doc` with this builder's accessors, buffer views and one buffer.
    pub fn into_glb(self, mut doc: Value) -> Vec<u8> {
        doc["accessors"] = json!(self.accessors);
        doc["bufferViews"] = json!(self.views);
        doc["buffers"] = json!([{"byteLength": self.bin.len().next_multiple_of(4)}]);
        glb(&doc, &self.bin)
    }

    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    pub fn floats(
        &mut self,
        v: &[f32],
        ty: &str,
        n: usize,
        target: Option<u32>,
        bounds: bool,
    ) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let mut a = json!({"bufferView": view, "componentType": 5126, "count": v.len() / n,
                           "type": ty});
        if bounds {
            let lo: Vec<f32> = (0..n)
                .map(|k| {
                    v.iter()
                        .skip(k)
                        .step_by(n)
                        .copied()
                        .fold(f32::MAX, f32::min)
                })
                .collect();
            let hi: Vec<f32> = (0..n)
                .map(|k| {
                    v.iter()
                        .skip(k)
                        .step_by(n)
                        .copied()
                        .fold(f32::MIN, f32::max)
                })
                .collect();
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    pub fn indices(&mut self, t: &[[u32; 3]]) -> usize {
        let bytes: Vec<u8> = t.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(34963));
        self.accessors
            .push(json!({"bufferView": view, "componentType": 5125,
                                   "count": 3 * t.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    pub fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let flat: Vec<f32> = p.iter().flatten().copied().collect();
        self.floats(&flat, "VEC3", 3, Some(34962), true)
    }
}

/// A closed box `[−s, s]³` (stretched by `stretch` along y), each face an `n × n` grid, welded.
pub fn grid_box(n: usize, s: f32, stretch: f32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut pos: Vec<[f32; 3]> = Vec::new();
    let mut tris = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut vid = |p: [f32; 3], pos: &mut Vec<[f32; 3]>| -> u32 {
        let key = p.map(|c| (c * 1000.0).round() as i64);
        *index.entry(key).or_insert_with(|| {
            pos.push(p);
            pos.len() as u32 - 1
        })
    };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut ids = vec![vec![0u32; n + 1]; n + 1];
            for (i, row) in ids.iter_mut().enumerate() {
                for (j, id) in row.iter_mut().enumerate() {
                    let mut p = [0.0f32; 3];
                    p[axis] = sign * s;
                    p[u] = s * (2.0 * i as f32 / n as f32 - 1.0);
                    p[v] = s * (2.0 * j as f32 / n as f32 - 1.0);
                    p[1] *= stretch;
                    *id = vid(p, &mut pos);
                }
            }
            for i in 0..n {
                for j in 0..n {
                    let (a, b, c, d) = (ids[i][j], ids[i + 1][j], ids[i + 1][j + 1], ids[i][j + 1]);
                    if sign > 0.0 {
                        tris.push([a, b, c]);
                        tris.push([a, c, d]);
                    } else {
                        tris.push([a, c, b]);
                        tris.push([a, d, c]);
                    }
                }
            }
        }
    }
    (pos, tris)
}

/// A scene of `meshes` distinct closed meshes and `instances` nodes cycling through them.
pub fn instanced_scene(meshes: usize, instances: usize) -> Vec<u8> {
    let mut b = Builder::default();
    let mut ms = Vec::new();
    for m in 0..meshes {
        let (p, t) = grid_box(4 + m, 1.0, 1.0 + 0.3 * m as f32);
        ms.push(json!({"name": format!("M{m}"), "primitives": [{
            "attributes": {"POSITION": b.positions(&p)}, "indices": b.indices(&t)}]}));
    }
    let nodes: Vec<Value> = (0..instances)
        .map(|i| {
            let s = 1.0 + 0.01 * i as f32;
            json!({"name": format!("N{i}"), "mesh": i % meshes,
                   "translation": [3.0 * (i % 20) as f32, 3.0 * (i / 20) as f32, 0.0],
                   "scale": [s, s, s]})
        })
        .collect();
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": (0..instances).collect::<Vec<_>>()}],
        "nodes": nodes, "meshes": ms,
        "accessors": b.accessors, "bufferViews": b.views,
        "buffers": [{"byteLength": b.bin.len().next_multiple_of(4)}],
    });
    glb(&doc, &b.bin)
}
