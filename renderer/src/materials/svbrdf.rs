//! `svbrdf`: the lobes of `diffuse_polarized` with every parameter a map
//! over the surface ([`MapDesc`]) and an optional normal map: the spatially
//! varying material (SVBRDF) of the paper's datasets. With constant maps and
//! no normal map it renders exactly as `diffuse_polarized` with the same
//! keys. Its shading is [`SurfaceMaps::at`].
//!
//! `material = { type = "svbrdf", ... }`:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `eta` | required | refractive index in [1, 4] (constant) |
//! | `albedo` | required | diffuse albedo map, values in [0, 1] |
//! | `specular` | 0 | specular-lobe weight map, values ≥ 0 |
//! | `roughness` | 0.2 | GGX `α` map, values in (0, 1] |
//! | `normal` | none | normal map (below) |
//!
//! A normal map is one of:
//!
//! | form | meaning |
//! |---|---|
//! | `{ pattern = "noise", seed = 0, frequency = 1.0, amplitude = 0.01 }` | bump mapping: the surface displaced by `amplitude × pattern` (world units) along its normal, for shading only; the normal is tilted by the height field's surface gradient, `n' = normalize(n − (∇h − (∇h·n) n))`, with `∇h` the 3-D gradient in object space (no texture coordinates or tangents needed). |
//! | `{ texture = "normals.png" }` | a tangent-space normal texture, `(R, G, B) = (n' + 1)/2` linear, in the frame of the mesh's texture coordinates: `R` along `∂p/∂u`, `B` along the normal, `G` along `n × ∂p/∂u` (up in the image, the glTF convention). A glTF/GLB model gives its `normalTexture`. Needs texture coordinates. |
//!
//! A mapped normal that turns away from the viewer is tilted back just
//! enough to face it; light arriving below the geometric surface is not
//! used. The specular lobe's polarization follows the mapped normal. Ground
//! truth (`gt/normals.exr`) is the mapped normal; `gt/geometric_normals.exr`
//! holds the surface's own normal and `gt/specular.exr` the specular weight
//! (both written for scenes with an `svbrdf` material); `gt/albedo.exr` is
//! the mapped albedo.

use super::map::{
    ALBEDO, DEFAULT_ROUGHNESS, MapDesc, ROUGHNESS, SPECULAR, ScalarMap, check_parameters, one,
};
use super::surface_maps::{NormalSource, SurfaceMaps};
use crate::bsdf::Material;
use crate::procedural::{Pattern, PatternKind};
use crate::scene_file::Table;
use crate::texture::{ModelTexture, Texture, is_model};
use glam::Affine3A;
use serde::{Deserialize, Serialize};
use sfp_core::{Error, Result};

/// The scene file's `svbrdf` material. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SvbrdfDesc {
    pub eta: f64,
    /// Diffuse albedo.
    pub albedo: MapDesc,
    /// Weight of the specular lobe.
    #[serde(default = "no_specular")]
    pub specular: MapDesc,
    /// GGX `α` of the specular lobe.
    #[serde(default = "default_roughness_map")]
    pub roughness: MapDesc,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<NormalMapDesc>,
}

fn no_specular() -> MapDesc {
    MapDesc::Constant(0.0)
}

fn default_roughness_map() -> MapDesc {
    MapDesc::Constant(DEFAULT_ROUGHNESS)
}

/// A normal map: a tangent-space image, or bumps from a pattern's height field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum NormalMapDesc {
    Texture(NormalTextureDesc),
    Bump(BumpDesc),
}

/// `{ texture = "normals.png" }`: tangent-space RGB normals (a glTF/GLB model
/// gives its `normalTexture`); needs the mesh's texture coordinates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalTextureDesc {
    pub texture: String,
}

/// `{ pattern = "noise", seed, frequency, amplitude }`: the surface displaced
/// by `amplitude × pattern` (world units) along its normal, for shading only.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BumpDesc {
    pub pattern: PatternKind,
    #[serde(default)]
    pub seed: u64,
    #[serde(default = "one")]
    pub frequency: f64,
    pub amplitude: f64,
}

impl SvbrdfDesc {
    /// Checks the values serde cannot: the bump map's, then the parameters'.
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        if let Some(NormalMapDesc::Bump(b)) = &self.normal {
            if !(b.frequency > 0.0 && b.frequency.is_finite()) {
                return Err(t.err("normal.frequency", "must be positive"));
            }
            if !b.amplitude.is_finite() {
                return Err(t.err("normal.amplitude", "must be finite"));
            }
        }
        check_parameters(t, self.eta, &self.albedo, &self.specular, &self.roughness)
    }

    /// The texture files its maps read.
    pub fn texture_files(&self) -> Vec<&str> {
        let maps = [&self.albedo, &self.specular, &self.roughness];
        let mut files: Vec<&str> = maps.into_iter().filter_map(MapDesc::texture_file).collect();
        if let Some(NormalMapDesc::Texture(t)) = &self.normal {
            files.push(&t.texture);
        }
        files
    }

    /// The material (its `eta`; the rest comes from the maps) and the maps
    /// of an object placed by `to_world` (its rotation and translation;
    /// scale is not undone), with their images loaded.
    pub(crate) fn build(
        &self,
        t: &Table,
        to_world: Affine3A,
    ) -> Result<(Material, Option<SurfaceMaps>)> {
        let material = Material {
            albedo: 0.0,
            rgb: [0.0; 3],
            eta: self.eta as f32,
            specular: 0.0,
            roughness: 0.0,
        };
        let albedo = ScalarMap::from_desc(&self.albedo, t, ALBEDO, Texture::load)?;
        let specular = ScalarMap::from_desc(&self.specular, t, SPECULAR, |path| {
            if is_model(path) {
                return Err(Error::file(
                    path,
                    "glTF models have no specular-weight texture: give an image",
                ));
            }
            Texture::load_linear(path, ModelTexture::BaseColour, 0)
        })?;
        // glTF keeps roughness in the green channel; a plain image is gray.
        let roughness = ScalarMap::from_desc(&self.roughness, t, ROUGHNESS, |path| {
            let channel = if is_model(path) { 1 } else { 0 };
            Texture::load_linear(path, ModelTexture::MetallicRoughness, channel)
        })?;
        let normal = match &self.normal {
            None => None,
            Some(NormalMapDesc::Texture(n)) => {
                let path = t.path(&n.texture)?;
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
        let maps = SurfaceMaps {
            albedo,
            specular,
            roughness,
            normal,
            to_object: to_world.inverse(),
        };
        Ok((material, Some(maps)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::MaterialDesc;
    use crate::scene::{Scene, SceneDesc};
    use std::path::Path;

    const EXAMPLE: &str = include_str!("../../../scenes/examples/sphere.toml");

    fn parse(text: &str) -> Result<Scene> {
        Scene::from_toml(text, Path::new("/scenes/test.toml"))
    }

    #[test]
    fn svbrdf_maps_parse_round_trip_and_are_checked() {
        let svbrdf = |maps: &str| {
            EXAMPLE.replace(
                "{ type = \"diffuse_polarized\", albedo = 0.8, eta = 1.5 }",
                &format!("{{ type = \"svbrdf\", eta = 1.5, {maps} }}"),
            )
        };
        let good = svbrdf(
            r#"albedo = { pattern = "cells", seed = 2, low = 0.2, high = 0.9 }, specular = { texture = "s.png" }, normal = { pattern = "noise", amplitude = 0.01 }"#,
        );
        let s = parse(&good).unwrap();
        let MaterialDesc::Svbrdf(m) = &s.desc.objects[0].material else {
            panic!("not svbrdf");
        };
        assert_eq!(m.roughness, MapDesc::Constant(0.2));
        assert_eq!(m.texture_files(), ["s.png"]);
        // meta.json keeps the scene as JSON: it must read back the same.
        let json = serde_json::to_value(&s.desc).unwrap();
        assert_eq!(serde_json::from_value::<SceneDesc>(json).unwrap(), s.desc);
        for (maps, key) in [
            ("albedo = 1.5", "material.albedo"),
            (
                r#"albedo = 0.5, roughness = { pattern = "noise", low = 0.0 }"#,
                "material.roughness",
            ),
            (
                r#"albedo = { pattern = "noise", frequency = 0.0 }"#,
                "material.albedo",
            ),
            (
                r#"albedo = 0.5, normal = { pattern = "cells", frequency = -1.0, amplitude = 1.0 }"#,
                "material.normal.frequency",
            ),
            (r#"albedo = { pattern = "plaid" }"#, "albedo"),
            (r#"albedo = 0.5, gloss = 1.0"#, "gloss"),
        ] {
            let err = parse(&svbrdf(maps)).expect_err(key).to_string();
            assert!(
                err.contains("test.toml") && err.contains(key),
                "{key}: {err}"
            );
        }
    }

    #[test]
    fn texture_values_are_checked_and_maps_of_no_form_list_the_forms() {
        let dir = tempfile::tempdir().unwrap();
        let png = |name: &str, v: u8| {
            let img = sfp_core::Image::new(4, 4, v);
            sfp_core::io::write_png8(&dir.path().join(name), &img).unwrap();
        };
        png("black.png", 0);
        png("white.png", 255);
        let scene = |maps: &str| {
            let text = EXAMPLE.replace(
                "{ type = \"diffuse_polarized\", albedo = 0.8, eta = 1.5 }",
                &format!("{{ type = \"svbrdf\", eta = 1.5, {maps} }}"),
            );
            Scene::from_toml(&text, &dir.path().join("scene.toml"))
        };
        let build =
            |maps: &str| scene(maps).and_then(|s| crate::world::World::build(&s).map(|_| ()));
        build(r#"albedo = { texture = "white.png" }, roughness = { texture = "white.png" }"#)
            .unwrap();
        for (maps, needle) in [
            (
                r#"albedo = 0.5, roughness = { texture = "black.png" }"#,
                "black.png",
            ),
            (
                r#"albedo = 0.5, roughness = { texture = "white.png", scale = 10.0 }"#,
                "(0, 1]",
            ),
            (
                r#"albedo = { texture = "white.png", scale = 5.0 }"#,
                "[0, 1]",
            ),
            (
                r#"albedo = { texture = "white.png", scale = -1.0 }"#,
                "scale",
            ),
        ] {
            let err = build(maps).expect_err(maps).to_string();
            assert!(err.contains(needle), "{maps}: {err}");
        }
        let err = scene(r#"albedo = "bright""#).unwrap_err().to_string();
        assert!(err.contains("expected a number, { texture"), "{err}");
        let err = scene(r#"albedo = { texture = "a.png", scael = 1.0 }"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("scael"), "{err}");
    }
}
