//! A white, smoothly shaded surface for `pleat::bake::render` (documentation pictures):
//! area-weighted vertex normals. Shared by the tests that render pictures (`wrinkle_edit`, `tfw`).

use pleat::mesh::TriMesh;

/// A shaded surface for the project's rasterizer: smooth area-weighted vertex normals.
pub struct Shaded {
    /// The mesh.
    pub mesh: TriMesh,
    normals: Vec<pleat::geom::Vec3>,
}

impl Shaded {
    /// Computes the vertex normals of `mesh`.
    pub fn new(mesh: TriMesh) -> Shaded {
        use pleat::geom::Vec3;
        let p = mesh.positions();
        let mut n = vec![Vec3::ZERO; p.len()];
        for t in mesh.triangles() {
            let [a, b, c] = t.map(|v| Vec3::from(p[v as usize]));
            let fnrm = (b - a).cross(c - a);
            for &v in t {
                n[v as usize] += fnrm;
            }
        }
        let normals = n
            .into_iter()
            .map(|v| pleat::geom::normalized(v).unwrap_or(Vec3::Z))
            .collect();
        Shaded { mesh, normals }
    }
}

impl pleat::bake::render::Surface for Shaded {
    fn positions(&self) -> &[[f64; 3]] {
        self.mesh.positions()
    }
    fn triangles(&self) -> &[[u32; 3]] {
        self.mesh.triangles()
    }
    fn base_color(&self, _: usize, _: [f64; 3]) -> [f64; 3] {
        [1.0; 3]
    }
    fn normal(&self, t: usize, b: [f64; 3]) -> pleat::geom::Vec3 {
        let tri = self.mesh.triangles()[t];
        let n: pleat::geom::Vec3 = (0..3).map(|k| self.normals[tri[k] as usize] * b[k]).sum();
        pleat::geom::normalized(n).unwrap_or(pleat::geom::Vec3::Z)
    }
}
