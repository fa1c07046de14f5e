//! The built-in scenes of the dissertation and the examples: the stretched sheet, sphere drapes,
//! twisted cylinders, the sheared rectangle, the disk and torus balloons and the teabag, with the
//! pattern functions they are made of (grids, outlines, balloon panels). Deterministic: a seed is
//! the only source of variation.

use super::description::{
    roll_onto_cylinder, Dirichlet, Material, Motion, Obstacle, ObstacleShape, Panel, Rotation,
    Scene, DEFAULT_OBSTACLE_STIFFNESS,
};
use crate::tfw::delaunay::{hash_unit, PolygonPanel};
use crate::Result;

impl Scene {
    /// The stretched sheet of S:714: a 0.25 × 0.1 m rectangle, h 0.1 mm, ν 0.5, Y 1 MPa, on a
    /// structured `nx × ny` vertex grid (alternating diagonals, interior vertices jittered by
    /// up to 20% of the spacing to break the grid's direction bias, S:698). The initial state
    /// is the sheet stretched uniformly along x by the factor `1 + stretch` (the dissertation
    /// does not give the stretch); both short edges are clamped there.
    pub fn stretched_sheet(nx: usize, ny: usize, stretch: f64) -> Scene {
        let (lx, ly) = (0.25, 0.1);
        let (rest, triangles) = grid(nx, ny, lx, ly, true);
        let positions = rest
            .iter()
            .map(|r| [(r[0] - 0.5 * lx) * (1.0 + stretch), r[1] - 0.5 * ly, 0.0])
            .collect();
        let edge = |col: usize| (0..ny).map(|j| (j * nx + col) as u32).collect::<Vec<_>>();
        let mut clamped = edge(0);
        clamped.extend(edge(nx - 1));
        Scene {
            name: format!("stretched sheet {nx}x{ny}, stretch {stretch}"),
            material: Material {
                young: 1e6,
                poisson: 0.5,
                thickness: 1e-4,
                density: 0.0,
            },
            panels: vec![Panel {
                rest,
                triangles,
                positions: Some(positions),
            }],
            gravity: [0.0; 3],
            pressure: 0.0,
            dirichlet: vec![Dirichlet {
                panel: 0,
                vertices: clamped,
                motion: Motion::default(),
            }],
            seam_tolerance: 1e-6,
            obstacles: Vec::new(),
        }
    }

    /// The sphere drape of S:676 (Fig. 2.19): a square cloth of side `side` (m; the
    /// dissertation's is 1 m) on a structured `n × n` vertex grid (alternating diagonals, not
    /// jittered; `n = 41` gives the dissertation's 1.6k vertices), laid flat at height `r` over
    /// a sphere of radius `r = 0.2` m centred at the origin ([`ObstacleShape::Sphere`], default
    /// stiffness), under gravity `-9.81 z`; the cloth of S:676 (ρ 200 kg/m³, ν 0.3, Y 0.1 MPa,
    /// h 1 mm). Departure: the vertex at the cloth's centre (`n` odd; the one right of it for
    /// even `n`) is pinned where it lies — the dissertation's solvers have friction, and a
    /// frictionless sphere's top is an unstable equilibrium from which a free sheet slides off.
    /// `n` below 2 is taken as 2, `side` as its absolute value; a zero, infinite or NaN `side`
    /// gives a scene that [`Scene::assemble`] refuses.
    pub fn sphere_drape(n: usize, side: f64) -> Scene {
        let (n, side) = (n.max(2), side.abs());
        let (rest, triangles) = grid(n, n, side, side, false);
        let centre = (n / 2) * n + n / 2;
        let name = format!("sphere drape {n}x{n}, {side} m on r {SPHERE_DRAPE_RADIUS} m");
        sphere_drape_scene(name, rest, triangles, side, centre)
    }

    /// The sphere drape of [`sphere_drape`](Self::sphere_drape) on an irregular Delaunay mesh
    /// of the square with about `target_vertices` vertices ([`crate::tfw::delaunay`]; `seed`
    /// selects the sampling), as the dissertation's experiments use (irregular meshes, S:698):
    /// no grid direction for the wrinkles to follow. The pinned vertex is the one nearest the
    /// cloth's centre (the first such in index order). `side` as its absolute value. Errors as
    /// [`Panel::from_polygon`] (e.g. a zero, infinite or NaN `side`, too few vertices).
    pub fn sphere_drape_delaunay(target_vertices: usize, side: f64, seed: u64) -> Result<Scene> {
        let side = side.abs();
        let panel = Panel::from_polygon(&PolygonPanel {
            outer: vec![[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]],
            holes: vec![],
            target_vertices,
            seed,
        })?;
        let dist = |p: &[f64; 2]| (p[0] - 0.5 * side).hypot(p[1] - 0.5 * side);
        let centre = (0..panel.rest.len())
            .min_by(|&a, &b| {
                dist(&panel.rest[a])
                    .total_cmp(&dist(&panel.rest[b]))
                    .then(a.cmp(&b))
            })
            .unwrap_or(0);
        let name = format!(
            "sphere drape, Delaunay {target_vertices} v (seed {seed}), {side} m on r \
             {SPHERE_DRAPE_RADIUS} m"
        );
        Ok(sphere_drape_scene(
            name,
            panel.rest,
            panel.triangles,
            side,
            centre,
        ))
    }

    /// The twisted cylinder of S:682: radius 1 m, height 5 m, h 0.1 mm, ν 0.44, Y 10 MPa. The
    /// pattern is the 2π × 5 m rectangle on a structured `n_around + 1` × `n_height` grid
    /// (jittered interior, see [`stretched_sheet`](Self::stretched_sheet)), rolled into the
    /// untwisted cylinder (the initial state, S:2226) and sewn along the seam. The bottom ring
    /// is clamped; the top ring is rotated by `twist_degrees` about the axis (height fixed).
    pub fn twisted_cylinder(n_around: usize, n_height: usize, twist_degrees: f64) -> Scene {
        let (r, hgt) = (1.0, 5.0);
        let nx = n_around + 1;
        let (rest, triangles) = grid(nx, n_height, 2.0 * std::f64::consts::PI * r, hgt, true);
        let panel = Panel {
            positions: Some(roll_onto_cylinder(&rest, r)),
            rest,
            triangles,
        };
        let name = format!("twisted cylinder {n_around}x{n_height}, {twist_degrees} deg");
        twisted_cylinder_scene(name, panel, r, hgt, twist_degrees)
    }

    /// The twisted cylinder of [`twisted_cylinder`](Self::twisted_cylinder) on an irregular
    /// Delaunay mesh of the pattern with about `target_vertices` vertices before sewing
    /// ([`crate::tfw::delaunay`]; the seam's two sides get the same samples, so the sewn mesh
    /// has `target_vertices − (samples on the seam)` vertices), as the dissertation's
    /// experiments use (irregular meshes, S:698). `seed` selects the sampling.
    pub fn twisted_cylinder_delaunay(
        target_vertices: usize,
        twist_degrees: f64,
        seed: u64,
    ) -> Result<Scene> {
        let (r, hgt) = (1.0, 5.0);
        let w = 2.0 * std::f64::consts::PI * r;
        let mut panel = Panel::from_polygon(&PolygonPanel {
            outer: vec![[0.0, 0.0], [w, 0.0], [w, hgt], [0.0, hgt]],
            holes: vec![],
            target_vertices,
            seed,
        })?;
        panel.positions = Some(roll_onto_cylinder(&panel.rest, r));
        let name = format!(
            "twisted cylinder, Delaunay {target_vertices} v (seed {seed}), {twist_degrees} deg"
        );
        Ok(twisted_cylinder_scene(name, panel, r, hgt, twist_degrees))
    }
}

impl Scene {
    /// The sheared rectangle of S:730 (Wong & Pellegrino 2006, "Wrinkled membranes Part I:
    /// experiments", J. Mech. Mater. Struct. 1(1)): a 380 × 128 mm Kapton HN foil, 25 µm
    /// thick, E 3.53 GPa, ν 0.3 (the dimensions and material the spec takes from that paper;
    /// the dissertation gives none of them), on an irregular Delaunay mesh of about
    /// `target_vertices` vertices. The bottom edge is clamped; the top edge is clamped and
    /// moved by `shear_mm` (mm) along the long side (x) and by `stretch_mm` (mm) away from
    /// the bottom edge (a small pre-tension; 0 = pure shear). The sides are free.
    pub fn sheared_rectangle(
        target_vertices: usize,
        shear_mm: f64,
        stretch_mm: f64,
        seed: u64,
    ) -> Result<Scene> {
        let (w, h) = (0.38, 0.128);
        let panel = Panel::from_polygon(&PolygonPanel {
            outer: vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]],
            holes: vec![],
            target_vertices,
            seed,
        })?;
        let name = format!(
            "sheared rectangle (Wong-Pellegrino), {target_vertices} v (seed {seed}), \
             shear {shear_mm} mm, stretch {stretch_mm} mm"
        );
        let material = Material {
            young: 3.53e9,
            poisson: 0.3,
            thickness: 25e-6,
            density: 0.0,
        };
        let motion = Motion {
            translation: [shear_mm / 1000.0, stretch_mm / 1000.0, 0.0],
            rotation: None,
        };
        let mut scene = bottom_clamped_top_moved(name, material, panel, [w, h], motion);
        scene.seam_tolerance = 1e-9;
        Ok(scene)
    }
}

impl Scene {
    /// The Mylar balloon of S:750 ("two disks (radius 0.1m) sewn along their boundary"): two
    /// identical disks of radius 0.1 m, meshed irregularly (same outline, target and seed, so
    /// their rims get identical samples) with about `target_vertices_per_panel` vertices each,
    /// sewn along the rim into a closed surface and inflated by `pressure` (Pa). Material as
    /// the dissertation's torus balloon ("the same material parameters", S:750: ν 0.44,
    /// Y 10 MPa); thickness 0.1 mm (not in the text; the spec's reference-code disk) and the
    /// spec's 600 Pa are the defaults callers use. No Dirichlet condition: the rigid motions
    /// are left to the base solve's diagonal shift (pressure and membrane are invariant).
    /// Initial state ([`Panel::lens`]): a thin lens, `z = ±0.05 R (R − r)/R`; the rim is a
    /// polygon of `target_vertices_per_panel / 3` corners (clamped to 24..4096).
    pub fn disk_balloon(
        target_vertices_per_panel: usize,
        pressure: f64,
        seed: u64,
    ) -> Result<Scene> {
        let r = 0.1;
        let n = (target_vertices_per_panel / 3).clamp(24, 4096);
        let outline = PolygonPanel {
            outer: circle(r, n),
            holes: vec![],
            target_vertices: target_vertices_per_panel,
            seed,
        };
        let panels = balloon_panels(&outline, 0.05 * r)?;
        let name = format!(
            "disk balloon r 0.1 m, 2 x {target_vertices_per_panel} v (seed {seed}), {pressure} Pa"
        );
        Ok(balloon_scene(name, panels, pressure))
    }

    /// The torus balloon of S:746: two annuli (inner radius 0.04 m, outer 0.1 m, ν 0.44,
    /// Y 10 MPa; thickness 0.1 mm as [`disk_balloon`](Self::disk_balloon)) sewn along both
    /// rims and inflated by `pressure` (Pa); about `target_vertices_per_panel` vertices per
    /// annulus (the dissertation's mesh: 2k in all). Initial state ([`Panel::lens`]): a thin
    /// tent, `z = ±0.05 w · d/(w/2)`, `w = r_o − r_i`, `d` the distance to the nearer rim; the
    /// rims are polygons of `target_vertices_per_panel / 4` and `· r_i/r_o` corners.
    pub fn torus_balloon(
        target_vertices_per_panel: usize,
        pressure: f64,
        seed: u64,
    ) -> Result<Scene> {
        let (ri, ro) = (0.04, 0.1);
        let n = (target_vertices_per_panel / 4).clamp(24, 4096);
        let ni = ((n as f64 * ri / ro).round() as usize).max(12);
        let outline = PolygonPanel {
            outer: circle(ro, n),
            holes: vec![circle(ri, ni)],
            target_vertices: target_vertices_per_panel,
            seed,
        };
        let panels = balloon_panels(&outline, 0.05 * (ro - ri))?;
        let name = format!(
            "torus balloon r 0.04-0.1 m, 2 x {target_vertices_per_panel} v (seed {seed}), \
             {pressure} Pa"
        );
        Ok(balloon_scene(name, panels, pressure))
    }
}

impl Scene {
    /// The teabag of S:752: two 1.4 × 0.74 m rectangles sewn along their whole boundary into
    /// a pillow and inflated by `pressure` (Pa; the dissertation does not give it), h 1 mm,
    /// ν 0.3, Y 0.1 MPa (S:752), about `target_vertices_per_panel` vertices per rectangle
    /// (the dissertation's mesh: 936 in all), meshed irregularly (same outline, target and
    /// seed, so both get identical boundary samples and sew). The corners are rounded (radius
    /// 4 cm, 6 segments): at a square corner the mesher puts a triangle with three boundary
    /// vertices, whose inner edge both panels would share, which does not sew into a manifold.
    /// Initial state a thin tent ([`Panel::lens`], `z = ±0.05 · 0.37 m · d/d_max`). No Dirichlet
    /// condition, as the balloons. Expected (S:752): fine wrinkles along the seam, no creases.
    pub fn teabag(target_vertices_per_panel: usize, pressure: f64, seed: u64) -> Result<Scene> {
        let (w, h) = (1.4, 0.74);
        let outline = PolygonPanel {
            outer: rounded_rectangle(w, h, 0.04, 6),
            holes: vec![],
            target_vertices: target_vertices_per_panel,
            seed,
        };
        let panels = balloon_panels(&outline, 0.05 * 0.5 * h)?;
        let name = format!(
            "teabag 1.4 x 0.74 m, 2 x {target_vertices_per_panel} v (seed {seed}), {pressure} Pa"
        );
        let mut scene = balloon_scene(name, panels, pressure);
        scene.material = Material {
            young: 1e5,
            poisson: 0.3,
            thickness: 1e-3,
            density: 0.0,
        };
        Ok(scene)
    }
}

/// The `w × h` rectangle about the origin with its corners rounded to radius `r` (each arc
/// `segments` chords), counter-clockwise.
fn rounded_rectangle(w: f64, h: f64, r: f64, segments: usize) -> Vec<[f64; 2]> {
    let (cx, cy) = (0.5 * w - r, 0.5 * h - r);
    let centres = [[cx, -cy], [cx, cy], [-cx, cy], [-cx, -cy]];
    let mut out = Vec::with_capacity(4 * (segments + 1));
    for (q, c) in centres.iter().enumerate() {
        for k in 0..=segments {
            let t = std::f64::consts::FRAC_PI_2 * (q as f64 - 1.0 + k as f64 / segments as f64);
            out.push([c[0] + r * t.cos(), c[1] + r * t.sin()]);
        }
    }
    out
}

/// `n` corners of the circle of radius `r` about the origin, counter-clockwise.
fn circle(r: f64, n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let (s, c) = (2.0 * std::f64::consts::PI * k as f64 / n as f64).sin_cos();
            [r * c, r * s]
        })
        .collect()
}

/// The two panels of a balloon: [`Panel::lens`] of `outline` at `+height` (top, facing +z)
/// and `−height` (bottom, facing −z).
fn balloon_panels(outline: &PolygonPanel, height: f64) -> Result<Vec<Panel>> {
    Ok(vec![
        Panel::lens(outline, height)?,
        Panel::lens(outline, -height)?,
    ])
}

/// A balloon scene: the panels, the balloon material of S:746–750 (ν 0.44, Y 10 MPa,
/// h 0.1 mm, no density), `pressure`, no gravity, no Dirichlet condition, seams sewn within
/// 1e-9 m (the twins are bit-identical).
fn balloon_scene(name: String, panels: Vec<Panel>, pressure: f64) -> Scene {
    Scene {
        name,
        material: Material {
            young: 1e7,
            poisson: 0.44,
            thickness: 1e-4,
            density: 0.0,
        },
        panels,
        gravity: [0.0; 3],
        pressure,
        dirichlet: vec![],
        seam_tolerance: 1e-9,
        obstacles: Vec::new(),
    }
}

/// The cylinder scene around a rolled panel of the `2πr × hgt` pattern: bottom ring (rest
/// v = 0) clamped, top ring (v = hgt) rotated about the z axis, height fixed.
fn twisted_cylinder_scene(
    name: String,
    panel: Panel,
    r: f64,
    hgt: f64,
    twist_degrees: f64,
) -> Scene {
    let w = 2.0 * std::f64::consts::PI * r;
    let material = Material {
        young: 1e7,
        poisson: 0.44,
        thickness: 1e-4,
        density: 0.0,
    };
    let motion = Motion {
        translation: [0.0; 3],
        rotation: Some(Rotation {
            axis: [0.0, 0.0, 1.0],
            origin: [0.0; 3],
            degrees: twist_degrees,
        }),
    };
    bottom_clamped_top_moved(name, material, panel, [w, hgt], motion)
}

/// A one-panel scene on the `size[0] × size[1]` rest rectangle: the bottom edge (rest v = 0)
/// clamped, the top edge (v = `size[1]`) clamped and moved by `motion`; no gravity, no
/// pressure, seam tolerance 1e-6.
fn bottom_clamped_top_moved(
    name: String,
    material: Material,
    panel: Panel,
    size: [f64; 2],
    motion: Motion,
) -> Scene {
    let [w, h] = size;
    let bottom = panel.vertices_in_rest_box([0.0, 0.0], [w, 0.0]);
    let top = panel.vertices_in_rest_box([0.0, h], [w, h]);
    Scene {
        name,
        material,
        panels: vec![panel],
        gravity: [0.0; 3],
        pressure: 0.0,
        dirichlet: vec![
            Dirichlet {
                panel: 0,
                vertices: bottom,
                motion: Motion::default(),
            },
            Dirichlet {
                panel: 0,
                vertices: top,
                motion,
            },
        ],
        seam_tolerance: 1e-6,
        obstacles: Vec::new(),
    }
}

/// Structured grid of `nx × ny` vertices on `[0, lx] × [0, ly]` (row-major, `j·nx + i`), two
/// triangles per cell with alternating diagonals, counter-clockwise. With `jitter`, interior
/// vertices move by a deterministic pseudo-random offset of up to 20% of the spacing.
/// Radius of the sphere of the drape (S:676), m.
const SPHERE_DRAPE_RADIUS: f64 = 0.2;

/// The drape of [`Scene::sphere_drape`] for a pattern `rest` / `triangles` of the square
/// `[0, side]²`: laid flat at height `r` centred over the sphere, vertex `centre` pinned.
fn sphere_drape_scene(
    name: String,
    rest: Vec<[f64; 2]>,
    triangles: Vec<[u32; 3]>,
    side: f64,
    centre: usize,
) -> Scene {
    let r = SPHERE_DRAPE_RADIUS;
    let positions = rest
        .iter()
        .map(|p| [p[0] - 0.5 * side, p[1] - 0.5 * side, r])
        .collect();
    Scene {
        name,
        material: Material {
            young: 1e5,
            poisson: 0.3,
            thickness: 1e-3,
            density: 200.0,
        },
        panels: vec![Panel {
            rest,
            triangles,
            positions: Some(positions),
        }],
        gravity: [0.0, 0.0, -9.81],
        pressure: 0.0,
        dirichlet: vec![Dirichlet {
            panel: 0,
            vertices: vec![centre as u32],
            motion: Motion::default(),
        }],
        seam_tolerance: 1e-6,
        obstacles: vec![Obstacle {
            shape: ObstacleShape::Sphere {
                centre: [0.0; 3],
                radius: r,
            },
            stiffness: DEFAULT_OBSTACLE_STIFFNESS,
            margin: 0.0,
        }],
    }
}

fn grid(nx: usize, ny: usize, lx: f64, ly: f64, jitter: bool) -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
    let (dx, dy) = (lx / (nx - 1) as f64, ly / (ny - 1) as f64);
    let mut rest = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let mut p = [i as f64 * dx, j as f64 * dy];
            if jitter && i > 0 && i + 1 < nx && j > 0 && j + 1 < ny {
                let k = (j * nx + i) as u64;
                p[0] += 0.2 * dx * hash_unit(2 * k);
                p[1] += 0.2 * dy * hash_unit(2 * k + 1);
            }
            rest.push(p);
        }
    }
    let mut tris = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let v = |a: usize, b: usize| (b * nx + a) as u32;
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            if (i + j) % 2 == 0 {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            } else {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            }
        }
    }
    (rest, tris)
}
