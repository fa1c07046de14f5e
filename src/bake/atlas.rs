//! UV atlas of a LOD with xatlas (Jonathan Young's, the generator Godot, Blender add-ons and
//! many glTF pipelines use; compiled by the `xatlas-rs` crate, called through declarations in
//! this file — see `ffi`): charts grown by xatlas's proxy-fit /
//! normal-seam metrics, each parameterised by LSCM (planar charts by projection), validated to
//! be injective (xatlas splits charts whose parameterisation folds), and packed without
//! overlaps with a gutter of [`AtlasParams::padding`] texels between charts.
//!
//! **Texel density rule.** A LOD for `n_p` pixels is seen with its bounding-box diagonal `l`
//! covering `n_p` pixels, so one pixel spans `l / n_p` of the surface. The atlas gives
//! `k = texels_per_pixel` texels per pixel (default 2, Nyquist for the magnification a LOD
//! switch allows before the next finer level takes over): `ρ = k · n_p / l` texels per unit
//! length; the atlas side is the next power of two of `√(A ρ² / 0.75)` (`A` the LOD's area,
//! 75 % packing efficiency), clamped to `[min_size, max_size]` (default 32 … 4096). A
//! caller-given size overrides the rule. The gutter is 2 texels per mip level the rule implies
//! needs (default 4), enough that the box filter of the first two mip levels reads only the
//! chart's own (dilated) texels.

use crate::mesh::TriMesh;
use crate::{Error, Result};

/// Parameters of [`build_atlas`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtlasParams {
    /// Square atlas side in texels; `None` applies the density rule of the [module docs](self).
    pub size: Option<u32>,
    /// Texels per screen pixel `k` of the density rule (finite, > 0). Default 2.
    pub texels_per_pixel: f64,
    /// Smallest side the rule may choose (power of two). Default 32.
    pub min_size: u32,
    /// Largest side the rule may choose (power of two). Default 4096.
    pub max_size: u32,
    /// Gutter between charts, in texels. Default 4.
    pub padding: u32,
}

impl Default for AtlasParams {
    fn default() -> Self {
        AtlasParams {
            size: None,
            texels_per_pixel: 2.0,
            min_size: 32,
            max_size: 4096,
            padding: 4,
        }
    }
}

impl AtlasParams {
    /// The atlas side for `lod` at screen size `n_p` with input diagonal `l` (the rule of the
    /// [module docs](self)), or the caller's size.
    pub fn side(&self, lod: &TriMesh, screen_size: f64, diagonal: f64) -> u32 {
        if let Some(s) = self.size {
            return s;
        }
        let rho = self.texels_per_pixel * screen_size / diagonal;
        let texels = lod.surface_area() * rho * rho / 0.75;
        let side = texels.sqrt().ceil().max(1.0);
        let side = if side.is_finite() && side < f64::from(1u32 << 30) {
            (side as u32).next_power_of_two()
        } else {
            self.max_size
        };
        side.clamp(self.min_size, self.max_size)
    }
}

/// A UV atlas of a mesh: the mesh's triangles re-indexed over atlas vertices, each atlas vertex
/// a copy of a mesh vertex (`xref`) with a UV; vertices are split only at chart seams.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// Side of the square atlas in texels.
    pub size: u32,
    /// Mesh vertex each atlas vertex copies.
    pub xref: Vec<u32>,
    /// UV of each atlas vertex in texels (`0 … size`, glTF orientation: v = 0 is the top row);
    /// divide by `size` for glTF texture coordinates.
    pub uv: Vec<[f32; 2]>,
    /// Triangles over atlas vertices, one per mesh triangle, in the mesh's order.
    pub triangles: Vec<[u32; 3]>,
    /// Number of charts.
    pub chart_count: u32,
    /// Texel centres covered by two triangles that share no vertex (an overlap or fold in the
    /// parameterisation); 0 for a valid atlas. See [`overlapping_texels`].
    pub overlapping_texels: u64,
}

/// Builds the atlas of `mesh` with side `side` (see [`AtlasParams::side`]) and `padding` texels
/// between charts. When the charts do not fit one atlas at xatlas's estimated density, the
/// density is lowered by 10 % steps until they do.
///
/// Errors: `InvalidArgument` for a zero side; `Internal` when xatlas drops a face or produces
/// a non-finite UV.
pub fn build_atlas(mesh: &TriMesh, side: u32, padding: u32) -> Result<Atlas> {
    if side == 0 {
        return Err(Error::InvalidArgument("atlas size must be > 0".into()));
    }
    let positions: Vec<f32> = mesh
        .positions()
        .iter()
        .flat_map(|p| p.map(|c| c as f32))
        .collect();
    let indices: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
    let area = mesh.surface_area().max(f64::MIN_POSITIVE);
    // xatlas's own estimate for a given resolution (75 % utilisation), lowered until one atlas
    // holds every chart. xatlas (this version) can leave a chart whose LSCM boundary
    // self-intersects; such atlases are detected by rasterisation and recomputed with a lower
    // chart-growth threshold (smaller charts), keeping the one with the fewest overlaps.
    let estimate = (f64::from(side) * f64::from(side) * 0.75 / area).sqrt();
    let mut best: Option<Atlas> = None;
    for threshold in [2.0f32, 1.0, 0.5, 0.25] {
        let mut scale = 1.0;
        let mut found = None;
        for _ in 0..12 {
            let density = (estimate * scale) as f32;
            if let Some(a) = run_xatlas(&positions, &indices, side, padding, density, threshold)? {
                check_atlas(&a, &indices)?;
                found = Some(a);
                break;
            }
            scale *= 0.9;
        }
        let Some(mut a) = found else { continue };
        a.overlapping_texels = overlapping_texels(&a);
        let done = a.overlapping_texels == 0;
        if best
            .as_ref()
            .is_none_or(|b| a.overlapping_texels < b.overlapping_texels)
        {
            best = Some(a);
        }
        if done {
            break;
        }
    }
    best.ok_or_else(|| {
        Error::Internal(format!(
            "xatlas could not pack the charts of {} triangles into one {side}² atlas",
            mesh.triangle_count()
        ))
    })
}

/// Texel centres inside two atlas triangles that share no atlas vertex (edge-adjacent and
/// vertex-adjacent triangles may both claim a centre on their common boundary).
pub fn overlapping_texels(a: &Atlas) -> u64 {
    let n = a.size as usize;
    let mut owner = vec![u32::MAX; n * n];
    let mut count = 0;
    for (t, tri) in a.triangles.iter().enumerate() {
        let uv = tri.map(|v| a.uv[v as usize].map(f64::from));
        let area = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1])
            - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
        if area == 0.0 {
            continue;
        }
        let lo = [0, 1].map(|k| (uv[0][k].min(uv[1][k]).min(uv[2][k]).floor().max(0.0)) as usize);
        let hi =
            [0, 1].map(|k| (uv[0][k].max(uv[1][k]).max(uv[2][k]).ceil().max(0.0) as usize).min(n));
        for j in lo[1]..hi[1] {
            for i in lo[0]..hi[0] {
                let c = [i as f64 + 0.5, j as f64 + 0.5];
                let e = |p: [f64; 2], q: [f64; 2]| {
                    ((q[0] - p[0]) * (c[1] - p[1]) - (c[0] - p[0]) * (q[1] - p[1])) / area
                };
                let inside =
                    e(uv[1], uv[2]) >= 0.0 && e(uv[2], uv[0]) >= 0.0 && e(uv[0], uv[1]) >= 0.0;
                if !inside {
                    continue;
                }
                let k = j * n + i;
                let o = owner[k];
                if o == u32::MAX {
                    owner[k] = t as u32;
                } else if !a.triangles[o as usize].iter().any(|v| tri.contains(v)) {
                    count += 1;
                }
            }
        }
    }
    count
}

/// One xatlas run; `None` when the charts spill over into a second atlas.
fn run_xatlas(
    positions: &[f32],
    indices: &[u32],
    side: u32,
    padding: u32,
    texels_per_unit: f32,
    max_threshold: f32,
) -> Result<Option<Atlas>> {
    let decl = ffi::MeshDecl {
        vertex_count: (positions.len() / 3) as u32,
        vertex_position_data: positions.as_ptr().cast(),
        vertex_position_stride: 12,
        vertex_normal_data: std::ptr::null(),
        vertex_normal_stride: 0,
        vertex_uv_data: std::ptr::null(),
        vertex_uv_stride: 0,
        index_count: indices.len() as u32,
        index_data: indices.as_ptr().cast(),
        index_offset: 0,
        index_format: ffi::INDEX_FORMAT_UINT32,
        face_ignore_data: std::ptr::null(),
    };
    let pack = ffi::PackOptions {
        attempts: 4096,
        texels_per_unit,
        resolution: side,
        max_chart_size: side,
        block_align: false,
        conservative: padding > 0,
        padding,
    };
    // SAFETY: a null print function silences xatlas's warnings on stdout; the realloc
    // function is a valid realloc (see `realloc_or_free`).
    unsafe {
        ffi::set_print(None, false);
        ffi::set_realloc(Some(realloc_or_free));
    }
    let atlas = ffi::Handle::new()?;
    // SAFETY: `atlas` is a live atlas; `decl` points into `positions` and `indices`, which
    // outlive the call (xatlas copies the mesh in AddMesh).
    let status = unsafe { ffi::add_mesh(atlas.0, &decl) };
    if status != 0 {
        return Err(Error::Internal(format!(
            "xatlas AddMesh failed with status {status}"
        )));
    }
    // SAFETY: live atlas, plain-data options, no callbacks.
    unsafe {
        ffi::generate(
            atlas.0,
            ffi::ChartOptions {
                max_threshold,
                ..ffi::ChartOptions::default()
            },
            None,
            pack,
            None,
            std::ptr::null_mut(),
        );
    }
    // SAFETY: after Generate, the atlas's arrays are valid until Destroy (when `atlas` drops,
    // after the copies below).
    let out = unsafe { copy_output(&*atlas.0, side) }?;
    Ok(out)
}

/// Copies xatlas's single output mesh; `None` when it produced more than one atlas.
///
/// # Safety
/// `a` must be a generated xatlas atlas with one mesh.
unsafe fn copy_output(a: &ffi::RawAtlas, side: u32) -> Result<Option<Atlas>> {
    if a.atlas_count > 1 {
        return Ok(None);
    }
    if a.mesh_count != 1 || a.meshes.is_null() {
        return Err(Error::Internal("xatlas returned no mesh".into()));
    }
    let m = &*a.meshes;
    let slice = |p: *const u32, n: u32| -> &[u32] {
        if n == 0 || p.is_null() {
            &[]
        } else {
            std::slice::from_raw_parts(p, n as usize)
        }
    };
    let verts: &[ffi::Vertex] = if m.vertex_count == 0 || m.vertex_array.is_null() {
        &[]
    } else {
        std::slice::from_raw_parts(m.vertex_array, m.vertex_count as usize)
    };
    if verts.iter().any(|v| v.atlas_index > 0) {
        return Ok(None);
    }
    let idx = slice(m.index_array, m.index_count);
    Ok(Some(Atlas {
        size: side,
        xref: verts.iter().map(|v| v.xref).collect(),
        uv: verts.iter().map(|v| v.uv).collect(),
        triangles: idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        chart_count: a.chart_count,
        overlapping_texels: 0,
    }))
}

/// Checks an atlas against the mesh it was made for: same triangles (through `xref`), every
/// vertex in one atlas with a finite UV inside it.
fn check_atlas(a: &Atlas, indices: &[u32]) -> Result<()> {
    if a.triangles.len() * 3 != indices.len() {
        return Err(Error::Internal(format!(
            "xatlas returned {} triangles for {}",
            a.triangles.len(),
            indices.len() / 3
        )));
    }
    let s = a.size as f32;
    if let Some(uv) =
        a.uv.iter()
            .find(|uv| !uv.iter().all(|c| c.is_finite() && (0.0..=s).contains(c)))
    {
        return Err(Error::Internal(format!(
            "xatlas produced UV {uv:?} outside the atlas"
        )));
    }
    for (t, tri) in a.triangles.iter().enumerate() {
        for k in 0..3 {
            if a.xref.get(tri[k] as usize).copied() != Some(indices[3 * t + k]) {
                return Err(Error::Internal(format!(
                    "xatlas reordered or dropped triangle {t}"
                )));
            }
        }
    }
    Ok(())
}

/// xatlas's allocator: it frees with `realloc(p, 0)`, which for `p = NULL` (an empty array
/// destroyed) is `malloc(0)` under glibc, a small block leaked each time (valgrind reports
/// them as definitely lost). This one frees and returns NULL for size 0.
unsafe extern "C" fn realloc_or_free(
    ptr: *mut std::ffi::c_void,
    size: usize,
) -> *mut std::ffi::c_void {
    if size == 0 {
        // SAFETY: `ptr` is NULL or a block from this allocator (libc), as xatlas guarantees.
        unsafe { libc::free(ptr) };
        return std::ptr::null_mut();
    }
    // SAFETY: as above.
    unsafe { libc::realloc(ptr, size) }
}

/// The C++ API of xatlas (the version vendored by `xatlas-rs` 0.1.3), declared here with the
/// Itanium-mangled names of its symbols: the crate's own bindings were generated on Windows
/// (MSVC-mangled names, and a `ChartOptions` field order that does not match its header), so
/// pleat uses the crate only to compile and link xatlas. Structs mirror `xatlas.h` field by
/// field; all are plain data passed as C would pass them (x86-64 SysV / AArch64 AAPCS treat
/// these C++ aggregates exactly as C structs).
mod ffi {
    use std::os::raw::{c_int, c_void};

    // Link the static library the crate builds.
    use xatlas_rs as _;

    pub const INDEX_FORMAT_UINT32: c_int = 1;

    #[repr(C)]
    pub struct MeshDecl {
        pub vertex_count: u32,
        pub vertex_position_data: *const c_void,
        pub vertex_position_stride: u32,
        pub vertex_normal_data: *const c_void,
        pub vertex_normal_stride: u32,
        pub vertex_uv_data: *const c_void,
        pub vertex_uv_stride: u32,
        pub index_count: u32,
        pub index_data: *const c_void,
        pub index_offset: i32,
        pub index_format: c_int,
        pub face_ignore_data: *const bool,
    }

    #[repr(C)]
    pub struct ChartOptions {
        pub max_chart_area: f32,
        pub max_boundary_length: f32,
        pub proxy_fit_metric_weight: f32,
        pub roundness_metric_weight: f32,
        pub straightness_metric_weight: f32,
        pub normal_seam_metric_weight: f32,
        pub texture_seam_metric_weight: f32,
        pub max_threshold: f32,
        pub grow_face_count: u32,
        pub max_iterations: u32,
    }

    impl Default for ChartOptions {
        /// xatlas's defaults (`xatlas.h`).
        fn default() -> Self {
            ChartOptions {
                max_chart_area: 0.0,
                max_boundary_length: 0.0,
                proxy_fit_metric_weight: 2.0,
                roundness_metric_weight: 0.01,
                straightness_metric_weight: 6.0,
                normal_seam_metric_weight: 4.0,
                texture_seam_metric_weight: 0.5,
                max_threshold: 2.0,
                grow_face_count: 32,
                max_iterations: 1,
            }
        }
    }

    #[repr(C)]
    pub struct PackOptions {
        pub attempts: c_int,
        pub texels_per_unit: f32,
        pub resolution: u32,
        pub max_chart_size: u32,
        pub block_align: bool,
        pub conservative: bool,
        pub padding: u32,
    }

    #[repr(C)]
    pub struct Vertex {
        pub atlas_index: i32,
        pub uv: [f32; 2],
        pub xref: u32,
    }

    #[repr(C)]
    pub struct Chart {
        pub atlas_index: u32,
        pub index_array: *const u32,
        pub index_count: u32,
    }

    #[repr(C)]
    pub struct RawMesh {
        pub chart_array: *const Chart,
        pub chart_count: u32,
        pub index_array: *const u32,
        pub index_count: u32,
        pub vertex_array: *const Vertex,
        pub vertex_count: u32,
    }

    #[repr(C)]
    pub struct RawAtlas {
        pub width: u32,
        pub height: u32,
        pub atlas_count: u32,
        pub chart_count: u32,
        pub mesh_count: u32,
        pub meshes: *const RawMesh,
        pub utilization: *const f32,
        pub texels_per_unit: f32,
    }

    type ParameterizeFunc =
        Option<unsafe extern "C" fn(*const f32, *mut f32, u32, *const u32, u32, bool)>;
    type ProgressFunc = Option<unsafe extern "C" fn(c_int, c_int, *mut c_void)>;

    extern "C" {
        #[link_name = "_ZN6xatlas8SetPrintEPFiPKczEb"]
        pub fn set_print(
            print: Option<unsafe extern "C" fn(*const std::os::raw::c_char, ...) -> c_int>,
            verbose: bool,
        );
        #[link_name = "_ZN6xatlas10SetReallocEPFPvS0_mE"]
        pub fn set_realloc(
            realloc: Option<unsafe extern "C" fn(*mut c_void, usize) -> *mut c_void>,
        );
        #[link_name = "_ZN6xatlas6CreateEv"]
        pub fn create() -> *mut RawAtlas;
        #[link_name = "_ZN6xatlas7DestroyEPNS_5AtlasE"]
        pub fn destroy(atlas: *mut RawAtlas);
        #[link_name = "_ZN6xatlas7AddMeshEPNS_5AtlasERKNS_8MeshDeclE"]
        pub fn add_mesh(atlas: *mut RawAtlas, decl: *const MeshDecl) -> c_int;
        #[link_name = "_ZN6xatlas8GenerateEPNS_5AtlasENS_12ChartOptionsEPFvPKfPfjPKjjbENS_11PackOptionsEPFvNS_16ProgressCategory4EnumEiPvESD_"]
        pub fn generate(
            atlas: *mut RawAtlas,
            chart: ChartOptions,
            param: ParameterizeFunc,
            pack: PackOptions,
            progress: ProgressFunc,
            user: *mut c_void,
        );
    }

    /// Owns an xatlas atlas; destroys it on drop.
    pub struct Handle(pub *mut RawAtlas);

    impl Handle {
        pub fn new() -> crate::Result<Self> {
            // SAFETY: no preconditions.
            let p = unsafe { create() };
            if p.is_null() {
                return Err(crate::Error::OutOfMemory);
            }
            Ok(Handle(p))
        }
    }

    impl Drop for Handle {
        fn drop(&mut self) {
            // SAFETY: created by `create`, destroyed once.
            unsafe { destroy(self.0) }
        }
    }
}
