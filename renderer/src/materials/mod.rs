//! Materials, one file per kind of `material = { type = "..." }`, each
//! holding its description (the TOML keys, with their table in the file's
//! doc comment), its validation and its build; both kinds shade with the
//! lobes of `bsdf`, through [`SurfaceMaps`] where a parameter varies over
//! the surface. This module lists the kinds, dispatches to them, and gives
//! the changes datasets and sweeps make to a material, so no code outside
//! the kinds' files reads their fields. A new kind is a file and a line in
//! [`MaterialDesc`] and in each `match` here.

pub mod diffuse_polarized;
pub mod map;
pub mod surface_maps;
pub mod svbrdf;

pub use diffuse_polarized::DiffusePolarizedDesc;
pub use map::MapDesc;
pub use surface_maps::{SurfaceMaps, SurfacePoint};
pub use svbrdf::SvbrdfDesc;

use crate::bsdf::Material;
use crate::scene_file::Table;
use glam::Affine3A;
use serde::{Deserialize, Serialize};
use sfp_core::Result;

/// An object's `material` table: its `type` names the kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum MaterialDesc {
    DiffusePolarized(DiffusePolarizedDesc),
    Svbrdf(SvbrdfDesc),
}

impl MaterialDesc {
    /// Checks the values serde cannot; errors name `t`'s file and key.
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.validate(t),
            MaterialDesc::Svbrdf(m) => m.validate(t),
        }
    }

    /// The material of an object placed by `to_world` (rotation and
    /// translation), and its maps (images loaded) when it varies over the
    /// surface.
    pub(crate) fn build(
        &self,
        t: &Table,
        to_world: Affine3A,
    ) -> Result<(Material, Option<SurfaceMaps>)> {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.build(t),
            MaterialDesc::Svbrdf(m) => m.build(t, to_world),
        }
    }

    /// Refractive index (constant in every material).
    pub fn eta(&self) -> f64 {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.eta,
            MaterialDesc::Svbrdf(m) => m.eta,
        }
    }

    /// The albedo when it is one number over the whole surface.
    pub fn constant_albedo(&self) -> Option<f64> {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.albedo_texture.is_none().then_some(m.albedo),
            MaterialDesc::Svbrdf(m) => match m.albedo {
                MapDesc::Constant(a) => Some(a),
                _ => None,
            },
        }
    }

    /// Whether views of it also record the geometric normals under the
    /// mapped ones and the specular weight (the `svbrdf` kind).
    pub fn records_svbrdf_ground_truth(&self) -> bool {
        matches!(self, MaterialDesc::Svbrdf(_))
    }

    /// The image files it reads.
    pub fn texture_files(&self) -> Vec<&str> {
        match self {
            MaterialDesc::DiffusePolarized(m) => {
                m.albedo_texture.iter().map(String::as_str).collect()
            }
            MaterialDesc::Svbrdf(m) => m.texture_files(),
        }
    }

    pub fn set_eta(&mut self, eta: f64) {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.eta = eta,
            MaterialDesc::Svbrdf(m) => m.eta = eta,
        }
    }

    /// Sets the diffuse albedo (a map becomes this constant).
    pub fn set_albedo(&mut self, albedo: f64) {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.albedo = albedo,
            MaterialDesc::Svbrdf(m) => m.albedo = MapDesc::Constant(albedo),
        }
    }

    /// Sets the specular-lobe weight (a map becomes this constant).
    pub fn set_specular(&mut self, specular: f64) {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.specular = specular,
            MaterialDesc::Svbrdf(m) => m.specular = MapDesc::Constant(specular),
        }
    }

    /// Sets the specular lobe's roughness (a map becomes this constant).
    pub fn set_roughness(&mut self, roughness: f64) {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.roughness = roughness,
            MaterialDesc::Svbrdf(m) => m.roughness = MapDesc::Constant(roughness),
        }
    }

    /// Gives a `diffuse_polarized` material `texture` as its albedo
    /// texture, replacing any it had (other kinds keep their maps).
    pub fn set_albedo_texture(&mut self, texture: Option<String>) {
        if let MaterialDesc::DiffusePolarized(m) = self {
            m.albedo_texture = texture;
        }
    }

    /// Drops the albedo's image: `diffuse_polarized` keeps its constant
    /// albedo, an `svbrdf` albedo image becomes its scale (at most 1).
    pub fn remove_albedo_texture(&mut self) {
        match self {
            MaterialDesc::DiffusePolarized(m) => m.albedo_texture = None,
            MaterialDesc::Svbrdf(m) => {
                if let MapDesc::Texture(t) = &m.albedo {
                    m.albedo = MapDesc::Constant(t.scale.min(1.0));
                }
            }
        }
    }
}
