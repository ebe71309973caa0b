//! The maps of one object (diffuse albedo, specular weight, roughness,
//! normal map) and the [`Material`] and shading normal they give at a hit:
//! what an `svbrdf` material, or a `diffuse_polarized` one with an albedo
//! texture, shades with. The lobes themselves are those of `bsdf`; with
//! constant maps and no normal map the result is exactly the constant
//! material.
//!
//! Texture images are looked up by the hit's texture coordinates; patterns
//! (`procedural`) are solid textures in object space: the world point with
//! the object's rotation and translation undone, so the pattern moves with
//! the object (objects in datasets span about two units).

use crate::bsdf::Material;
use crate::materials::map::ScalarMap;
use crate::normal_map::{bump, face_viewer, from_tangent_space};
use crate::procedural::Pattern;
use crate::texture::Texture;
use glam::{Affine3A, Vec2, Vec3A};

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

impl SurfaceMaps {
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

    /// Whether the specular weight can be positive somewhere.
    pub fn has_specular(&self) -> bool {
        !matches!(self.specular, ScalarMap::Constant(w) if w <= 0.0)
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
        let albedo = self.albedo.at(q, s.uv).clamp(0.0, 1.0);
        // Each channel keeps the base material's tint (none: grey).
        let tint = |c: usize| {
            if base.albedo > 0.0 {
                base.rgb[c] / base.albedo
            } else {
                1.0
            }
        };
        let material = Material {
            albedo,
            rgb: std::array::from_fn(|c| (albedo * tint(c)).clamp(0.0, 1.0)),
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
