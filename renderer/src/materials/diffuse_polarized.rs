//! `diffuse_polarized`: a dielectric with polarized subsurface diffuse
//! reflection and an optional GGX specular reflection lobe (polarized
//! plastic). Its shading is [`Material`] (`bsdf`); an `albedo_texture`
//! makes its albedo vary over the surface ([`SurfaceMaps::albedo_texture`]).
//!
//! `material = { type = "diffuse_polarized", ... }`:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `albedo` | required | diffuse albedo in [0, 1] |
//! | `albedo_texture` | none | image (PNG etc., relative to the scene file or `@name`), or a glTF/GLB model whose single base-colour texture is used, whose sRGB-decoded Rec. 709 luminance multiplies `albedo`; bilinear, repeating. Texture coordinates: from the mesh (OBJ `vt`, glTF `TEXCOORD_0`; image top-left at glTF `(0, 0)` and OBJ `(0, 1)`); on spheres the equirectangular layout of environment maps; on planes world units along the plane's own axes (one repeat per unit). |
//! | `tint` | none | `[r, g, b]` in [0, 1]: a colour render's albedo of each channel is `albedo × tint`, a grey render's `albedo ×` the tint's Rec. 709 luminance (the grey render of the colour's luminance); with `albedo_texture`, times the texel |
//! | `eta` | required | refractive index in [1, 4] |
//! | `specular` | 0 | weight of a GGX Fresnel-reflection lobe; 0 = pure diffuse |
//! | `roughness` | 0.2 | GGX `α` of the specular lobe, in (0, 1] |
//!
//! The diffuse part is Fresnel transmission in → depolarization → Lambert →
//! Fresnel transmission out (full Mueller matrices), so single scattering of
//! unpolarized light gives `s0 = albedo/π · E cosθ_i · T(θ_i) T(θ_o)` with
//! `T = (T_s + T_p)/2`, DoP = `ρ_d(θ_o, η)` (conventions.md §3) and AoP
//! parallel to the normal's azimuth.

use super::map::{DEFAULT_ROUGHNESS, MapDesc, check_parameters};
use super::surface_maps::SurfaceMaps;
use crate::bsdf::Material;
use crate::scene_file::Table;
use crate::texture::Texture;
use serde::{Deserialize, Serialize};
use sfp_core::{Result, colour};

/// The scene file's `diffuse_polarized` material. Field names are the
/// file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiffusePolarizedDesc {
    pub albedo: f64,
    /// Image multiplying `albedo` (sRGB-decoded luminance; path relative
    /// to the scene file, or `@name`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo_texture: Option<String>,
    /// Colour of the albedo: each channel's share, in [0, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tint: Option<[f64; 3]>,
    pub eta: f64,
    /// Weight of the GGX Fresnel-reflection lobe (0 = pure diffuse).
    #[serde(default)]
    pub specular: f64,
    /// GGX `α` of the specular lobe.
    #[serde(default = "default_roughness")]
    pub roughness: f64,
}

fn default_roughness() -> f64 {
    DEFAULT_ROUGHNESS
}

impl DiffusePolarizedDesc {
    /// Checks the values serde cannot (as constant maps).
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        if let Some(tint) = self.tint
            && !tint.iter().all(|v| (0.0..=1.0).contains(v))
        {
            return Err(t.err("tint", "each of r, g, b must be in [0, 1]"));
        }
        check_parameters(
            t,
            self.eta,
            &MapDesc::Constant(self.albedo),
            &MapDesc::Constant(self.specular),
            &MapDesc::Constant(self.roughness),
        )
    }

    /// The material, and the maps of its albedo texture (loaded) if it has one.
    pub(crate) fn build(&self, t: &Table) -> Result<(Material, Option<SurfaceMaps>)> {
        let tint = self.tint.unwrap_or([1.0; 3]);
        let grey = self.tint.map_or(1.0, colour::luminance);
        let m = Material {
            albedo: (self.albedo * grey) as f32,
            rgb: tint.map(|t| (self.albedo * t) as f32),
            eta: self.eta as f32,
            specular: self.specular as f32,
            roughness: self.roughness as f32,
        };
        let maps = match &self.albedo_texture {
            Some(file) => Some(SurfaceMaps::albedo_texture(
                &m,
                Texture::load(&t.path(file)?)?,
            )),
            None => None,
        };
        Ok((m, maps))
    }
}
