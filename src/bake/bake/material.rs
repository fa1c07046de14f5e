//! What a baked material holds besides its images: the fields that are not baked (from the
//! input's first material, [`base_material`]) and which images the input needs ([`Channels`]).

use super::params::BakeParams;
use crate::bake::appearance::Appearance;
use crate::bake::level::BakedMaterial;

/// The material fields that are not baked: from the input's first material.
pub(super) fn base_material(app: &Appearance) -> BakedMaterial {
    let m = app.materials.first().cloned().unwrap_or_default();
    BakedMaterial {
        base_color_factor: [1.0; 4],
        base_color: None,
        metallic_factor: m.metallic_factor,
        roughness_factor: m.roughness_factor,
        metallic_roughness: None,
        occlusion: None,
        emissive_factor: [0.0; 3],
        emissive: None,
        normal: None,
        alpha_mode: m.alpha_mode,
        alpha_cutoff: m.alpha_cutoff,
        double_sided: app.materials.iter().any(|m| m.double_sided),
    }
}

/// Which images the input needs.
pub(super) struct Channels {
    pub(super) metallic_roughness: bool,
    pub(super) occlusion: bool,
    pub(super) emissive: bool,
    pub(super) normal: bool,
}

impl Channels {
    pub(super) fn of(app: &Appearance, params: &BakeParams) -> Self {
        let first = app.materials.first();
        let differ = |f: &dyn Fn(&crate::bake::appearance::Material) -> f64| {
            first.is_some_and(|m0| app.materials.iter().any(|m| f(m) != f(m0)))
        };
        Channels {
            metallic_roughness: app.materials.iter().any(|m| m.metallic_roughness.is_some())
                || differ(&|m| m.metallic_factor)
                || differ(&|m| m.roughness_factor),
            occlusion: app.materials.iter().any(|m| m.occlusion.is_some()),
            emissive: app
                .materials
                .iter()
                .any(|m| m.emissive_factor.iter().any(|&c| c != 0.0)),
            normal: params.normal_map,
        }
    }
}
