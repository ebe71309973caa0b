//! Spatially varying materials: the maps of one object (diffuse albedo,
//! specular weight, roughness, normal map) and the [`Material`] and shading
//! normal they give at a hit. The lobes themselves are those of `bsdf`; with
//! constant maps and no normal map the result is exactly the constant
//! material.
//!
//! Texture images are looked up by the hit's texture coordinates; patterns
//! (`procedural`) are solid textures in object space: the world point with
//! the object's rotation and translation undone, so the pattern moves with
//! the object (objects in datasets span about two units).

use crate::bsdf::Material;
use crate::normal_map::{bump, face_viewer, from_tangent_space};
use crate::procedural::Pattern;
use crate::scene::{MapDesc, NormalMapDesc, Scene, SvbrdfDesc};
use crate::texture::{ModelTexture, Texture, is_model};
use glam::{Affine3A, Vec2, Vec3A};
use sfp_core::{Error, Result};

/// One material parameter over the surface.
#[derive(Clone, Debug, PartialEq)]
pub enum ScalarMap {
    Constant(f32),
    /// `scale × texel` at the hit's texture coordinates.
    Image {
        texture: Texture,
        scale: f32,
    },
    /// `low + (high − low) × pattern` at the object-space point.
    Pattern {
        pattern: Pattern,
        low: f32,
        high: f32,
    },
}

/// Where a mapped normal comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum NormalSource {
    /// Tangent-space components (R, G, B) in `[0, 1]`.
    Image([Texture; 3]),
    /// Height `amplitude × pattern` in world units.
    Bump { pattern: Pattern, amplitude: f32 },
}

/// What the shading of one hit needs to know about its place on the object.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3A,
    pub uv: Vec2,
    /// `∂p/∂u` in world space (zero where the surface has no texture
    /// coordinates).
    pub dpdu: Vec3A,
}

/// The maps of one object.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceMaps {
    pub albedo: ScalarMap,
    pub specular: ScalarMap,
    pub roughness: ScalarMap,
    pub normal: Option<NormalSource>,
    /// World → object space (rotation and translation undone).
    pub to_object: Affine3A,
}

impl ScalarMap {
    fn from_desc(
        desc: &MapDesc,
        scene: &Scene,
        load: impl Fn(&std::path::Path) -> Result<Texture>,
    ) -> Result<ScalarMap> {
        Ok(match desc {
            MapDesc::Constant(v) => ScalarMap::Constant(*v as f32),
            MapDesc::Texture(t) => ScalarMap::Image {
                texture: load(&scene.file_path(&t.texture)?)?,
                scale: t.scale as f32,
            },
            MapDesc::Pattern(p) => ScalarMap::Pattern {
                pattern: Pattern {
                    kind: p.pattern,
                    seed: p.seed,
                    frequency: p.frequency as f32,
                },
                low: p.low as f32,
                high: p.high as f32,
            },
        })
    }

    #[inline]
    fn at(&self, p_object: Vec3A, uv: Vec2) -> f32 {
        match self {
            ScalarMap::Constant(v) => *v,
            ScalarMap::Image { texture, scale } => scale * texture.lookup(uv),
            ScalarMap::Pattern { pattern, low, high } => {
                low + (high - low) * pattern.value(p_object)
            }
        }
    }

    fn uses_uv(&self) -> bool {
        matches!(self, ScalarMap::Image { .. })
    }
}

impl SurfaceMaps {
    /// The maps of an `svbrdf` material of an object placed by `to_world`
    /// (its rotation and translation; scale is not undone).
    pub fn from_desc(desc: &SvbrdfDesc, scene: &Scene, to_world: Affine3A) -> Result<SurfaceMaps> {
        let albedo = ScalarMap::from_desc(&desc.albedo, scene, Texture::load)?;
        let specular = ScalarMap::from_desc(&desc.specular, scene, |path| {
            if is_model(path) {
                return Err(Error::file(
                    path,
                    "glTF models have no specular-weight texture: give an image",
                ));
            }
            Texture::load_linear(path, ModelTexture::BaseColour, 0)
        })?;
        // glTF keeps roughness in the green channel; a plain image is gray.
        let roughness = ScalarMap::from_desc(&desc.roughness, scene, |path| {
            let channel = if is_model(path) { 1 } else { 0 };
            Texture::load_linear(path, ModelTexture::MetallicRoughness, channel)
        })?;
        let normal = match &desc.normal {
            None => None,
            Some(NormalMapDesc::Texture(t)) => {
                let path = scene.file_path(&t.texture)?;
                let channel = |k| Texture::load_linear(&path, ModelTexture::Normal, k);
                Some(NormalSource::Image([channel(0)?, channel(1)?, channel(2)?]))
            }
            Some(NormalMapDesc::Bump(b)) => Some(NormalSource::Bump {
                pattern: Pattern {
                    kind: b.pattern,
                    seed: b.seed,
                    frequency: b.frequency as f32,
                },
                amplitude: b.amplitude as f32,
            }),
        };
        Ok(SurfaceMaps {
            albedo,
            specular,
            roughness,
            normal,
            to_object: to_world.inverse(),
        })
    }

    /// An object with a constant `diffuse_polarized` material and an albedo
    /// texture: its albedo is `albedo × texel`.
    pub fn albedo_texture(material: &Material, texture: Texture) -> SurfaceMaps {
        SurfaceMaps {
            albedo: ScalarMap::Image {
                texture,
                scale: material.albedo,
            },
            specular: ScalarMap::Constant(material.specular),
            roughness: ScalarMap::Constant(material.roughness),
            normal: None,
            to_object: Affine3A::IDENTITY,
        }
    }

    /// Whether any map needs texture coordinates (or the tangent `∂p/∂u`).
    pub fn uses_uv(&self) -> bool {
        self.albedo.uses_uv()
            || self.specular.uses_uv()
            || self.roughness.uses_uv()
            || matches!(self.normal, Some(NormalSource::Image(_)))
    }

    /// The material at `s` (on top of `base`, which holds `eta`) and the
    /// shading normal: `ns` (already facing `wo`) normal-mapped, and kept
    /// facing the viewer.
    #[inline]
    pub fn at(&self, base: Material, s: &SurfacePoint, ns: Vec3A, wo: Vec3A) -> (Material, Vec3A) {
        let q = self.to_object.transform_point3a(s.p);
        let material = Material {
            albedo: self.albedo.at(q, s.uv).clamp(0.0, 1.0),
            eta: base.eta,
            specular: self.specular.at(q, s.uv).max(0.0),
            roughness: self.roughness.at(q, s.uv).clamp(0.0, 1.0),
        };
        let n = match &self.normal {
            None => return (material, ns),
            Some(NormalSource::Bump { pattern, amplitude }) => {
                // Object-space gradient back to world: the inverse's
                // transpose, i.e. the rotation itself.
                let g = pattern.gradient(q) * *amplitude;
                bump(ns, self.to_object.matrix3.transpose() * g)
            }
            Some(NormalSource::Image(rgb)) => {
                let c = Vec3A::from(rgb.each_ref().map(|t| 2.0 * t.lookup(s.uv) - 1.0));
                from_tangent_space(ns, s.dpdu, c)
            }
        };
        (material, face_viewer(n, wo))
    }
}
