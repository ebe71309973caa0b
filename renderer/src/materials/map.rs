//! A material parameter over the surface: a number, an image, or a pattern.
//! Both material kinds give their diffuse albedo, specular weight and
//! roughness as maps (`diffuse_polarized` as constants), so the parameters'
//! ranges are checked here, once.
//!
//! | form | meaning |
//! |---|---|
//! | `0.5` | a constant |
//! | `{ texture = "file", scale = 1.0 }` | an image times `scale`, looked up by the mesh's texture coordinates (as `albedo_texture`). `albedo` images are sRGB-decoded Rec. 709 luminance; `specular` and `roughness` images are read as linear data (gray or red channel). EXR files are linear (`R`, or `Y`). A glTF/GLB model gives its own texture: `baseColorTexture` for `albedo`, the green channel of `metallicRoughnessTexture` for `roughness` (models with one texture per part are refused). |
//! | `{ pattern = "noise", seed = 0, frequency = 1.0, low = 0.0, high = 1.0 }` | a procedural solid texture in [0, 1] mapped to `[low, high]` (`low > high` inverts it): `noise` (fractal Perlin noise), `cells` (Worley distance to random feature points), `stripes` (`½ + ½ sin 2π x`), `scratches` (thin random curves), `stains` (smooth blobs). `frequency` is features per unit length. Patterns live in **object space** (the world point with the object's rotation and translation undone), so they need no texture coordinates and move with the object. |

use crate::procedural::{Pattern, PatternKind};
use crate::scene_file::Table;
use crate::texture::Texture;
use glam::{Vec2, Vec3A};
use serde::{Deserialize, Serialize};
use sfp_core::Result;
use sfp_core::fresnel::MATERIAL_ETA_MAX;
use std::path::Path;

/// GGX `α` of the specular lobe when a material does not give one.
pub const DEFAULT_ROUGHNESS: f64 = 0.2;

/// A map as the scene file gives it.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum MapDesc {
    Constant(f64),
    Texture(TextureMapDesc),
    Pattern(PatternMapDesc),
}

/// The forms a map takes, for the error when a value is none of them.
const MAP_FORMS: &str = "a number, { texture = \"file\", scale = 1.0 } or \
                         { pattern = \"noise\", seed = 0, frequency = 1.0, low = 0.0, high = 1.0 }";

/// By the form's own key, so that an error names what is wrong inside a
/// texture or pattern table, and a value of no form lists the forms
/// (instead of "did not match any variant of untagged enum MapDesc").
impl<'de> Deserialize<'de> for MapDesc {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let value = toml::Value::deserialize(d)?;
        let detail = |e: toml::de::Error| D::Error::custom(e.message().trim().to_string());
        match &value {
            toml::Value::Float(v) => Ok(MapDesc::Constant(*v)),
            toml::Value::Integer(v) => Ok(MapDesc::Constant(*v as f64)),
            toml::Value::Table(t) if t.contains_key("texture") => {
                TextureMapDesc::deserialize(value)
                    .map(MapDesc::Texture)
                    .map_err(detail)
            }
            toml::Value::Table(t) if t.contains_key("pattern") => {
                PatternMapDesc::deserialize(value)
                    .map(MapDesc::Pattern)
                    .map_err(detail)
            }
            other => Err(D::Error::custom(format!(
                "expected {MAP_FORMS}, found {}",
                other.type_str()
            ))),
        }
    }
}

/// The values a material parameter may take, checked for constants and
/// patterns when the scene is read and for texture values when loaded.
#[derive(Clone, Copy)]
pub(crate) struct Bounds {
    pub ok: fn(f64) -> bool,
    pub message: &'static str,
}

pub(crate) const ALBEDO: Bounds = Bounds {
    ok: |v| (0.0..=1.0).contains(&v),
    message: "must be in [0, 1]",
};
pub(crate) const SPECULAR: Bounds = Bounds {
    ok: |v| v >= 0.0 && v.is_finite(),
    message: "must be finite and ≥ 0",
};
pub(crate) const ROUGHNESS: Bounds = Bounds {
    ok: |v| v > 0.0 && v <= 1.0,
    message: "must be in (0, 1]",
};

/// `{ texture = "file", scale = 1 }`: an image (or a glTF/GLB model's own
/// texture) looked up by the mesh's texture coordinates, times `scale`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureMapDesc {
    pub texture: String,
    #[serde(default = "one")]
    pub scale: f64,
}

/// `{ pattern = "noise", seed, frequency, low, high }`: a procedural solid
/// texture in `[0, 1]` mapped linearly to `[low, high]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatternMapDesc {
    pub pattern: PatternKind,
    #[serde(default)]
    pub seed: u64,
    /// Features per unit length (objects in datasets span about 2 units).
    #[serde(default = "one")]
    pub frequency: f64,
    #[serde(default)]
    pub low: f64,
    #[serde(default = "one")]
    pub high: f64,
}

pub(crate) fn one() -> f64 {
    1.0
}

/// Checks a material's parameters, in this order: `eta`, then the
/// `albedo`, `specular` and `roughness` maps; errors name `t`'s key.
pub(crate) fn check_parameters(
    t: &Table,
    eta: f64,
    albedo: &MapDesc,
    specular: &MapDesc,
    roughness: &MapDesc,
) -> Result<()> {
    if !(1.0..=MATERIAL_ETA_MAX).contains(&eta) {
        return Err(t.err("eta", format!("must be in [1, {MATERIAL_ETA_MAX}]")));
    }
    albedo.check(t, "albedo", ALBEDO)?;
    specular.check(t, "specular", SPECULAR)?;
    roughness.check(t, "roughness", ROUGHNESS)
}

impl MapDesc {
    /// A map's values (a constant, or a pattern's `low` and `high`) must
    /// satisfy `ok`; patterns need a positive frequency, images a scale ≥ 0.
    fn check(&self, t: &Table, field: &str, bounds: Bounds) -> Result<()> {
        let Bounds { ok, message } = bounds;
        match self {
            MapDesc::Constant(v) if !ok(*v) => Err(t.err(field, message)),
            MapDesc::Pattern(p) if !(ok(p.low) && ok(p.high)) => {
                Err(t.err(field, format!("`low` and `high` {message}")))
            }
            MapDesc::Pattern(p) if !(p.frequency > 0.0 && p.frequency.is_finite()) => {
                Err(t.err(field, "`frequency` must be positive"))
            }
            MapDesc::Texture(t_) if !(t_.scale >= 0.0 && t_.scale.is_finite()) => {
                Err(t.err(field, "`scale` must be finite and ≥ 0"))
            }
            _ => Ok(()),
        }
    }

    /// The texture file it reads.
    pub fn texture_file(&self) -> Option<&str> {
        match self {
            MapDesc::Texture(t) => Some(t.texture.as_str()),
            _ => None,
        }
    }
}

/// One material parameter over the surface, ready to look up.
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

impl ScalarMap {
    /// The map of `desc`, its image read by `load`; the image's values
    /// times its scale must be within `bounds` (a roughness map of 0, an
    /// albedo times 5 rendered silently).
    pub(crate) fn from_desc(
        desc: &MapDesc,
        t: &Table,
        bounds: Bounds,
        load: impl Fn(&Path) -> Result<Texture>,
    ) -> Result<ScalarMap> {
        Ok(match desc {
            MapDesc::Constant(v) => ScalarMap::Constant(*v as f32),
            MapDesc::Texture(m) => {
                let path = t.path(&m.texture)?;
                let texture = load(&path)?;
                let (lo, hi) = texture.range();
                let (lo, hi) = (m.scale * f64::from(lo), m.scale * f64::from(hi));
                if !((bounds.ok)(lo) && (bounds.ok)(hi)) {
                    return Err(sfp_core::Error::file(
                        &path,
                        format!(
                            "its values times `scale` {} span [{lo}, {hi}]; the parameter {}",
                            m.scale, bounds.message
                        ),
                    ));
                }
                ScalarMap::Image {
                    texture,
                    scale: m.scale as f32,
                }
            }
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
    pub(crate) fn at(&self, p_object: Vec3A, uv: Vec2) -> f32 {
        match self {
            ScalarMap::Constant(v) => *v,
            ScalarMap::Image { texture, scale } => scale * texture.lookup(uv),
            ScalarMap::Pattern { pattern, low, high } => {
                low + (high - low) * pattern.value(p_object)
            }
        }
    }

    pub(crate) fn uses_uv(&self) -> bool {
        matches!(self, ScalarMap::Image { .. })
    }
}
