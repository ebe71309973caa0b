//! Environment light: unpolarized radiance arriving from every direction,
//! constant, from an equirectangular EXR map, or from surroundings the
//! renderer makes (`surroundings`), each map's luminance times `radiance`.
//! Maps are importance-sampled by texel luminance × `sinθ`; both kinds are
//! combined with BSDF sampling by MIS. A scene has at most one.
//!
//! Map layout (world frame): column `u ∈ [0, 1)` is the azimuth
//! `φ = 2πu = atan2(x, −z)` (the map's centre looks along `−z`), row
//! `v ∈ [0, 1)` the polar angle `θ = πv` from `+y` (top row = up).
//!
//! `[[light]] type = "environment"`:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `radiance` | required | constant radiance from every direction (≥ 0), or the factor on the map |
//! | `map` | none | equirectangular EXR (relative to the scene file, or `@name`): Rec. 709 luminance of `R, G, B`, or `Y` |
//! | `surroundings` | none | a generated map instead of a file: a sky or a room ([`super::surroundings`]) |

use super::sample::LightSample;
use super::surroundings::SurroundingsDesc;
use crate::scene_file::Table;
use glam::Vec3A;
use serde::{Deserialize, Serialize};
use sfp_core::{Error, Image, Result, io};
use std::f32::consts::PI;
use std::path::Path;

/// The scene file's `environment` light. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    pub radiance: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surroundings: Option<SurroundingsDesc>,
}

impl EnvironmentDesc {
    /// Checks the values serde cannot.
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        if !(self.radiance >= 0.0 && self.radiance.is_finite()) {
            return Err(t.err("radiance", "must be finite and ≥ 0"));
        }
        match (&self.map, &self.surroundings) {
            (Some(_), Some(_)) => Err(t.err("surroundings", "give either `map` or `surroundings`")),
            (_, Some(s)) => s.validate(t),
            _ => Ok(()),
        }
    }

    /// The light, with its map loaded.
    pub(crate) fn build(&self, t: &Table) -> Result<Environment> {
        let map = match (&self.map, &self.surroundings) {
            (Some(file), _) => Some(EnvMap::load(&t.path(file)?)?),
            (None, Some(s)) => EnvMap::new(&s.luminance()),
            (None, None) => None,
        };
        Ok(Environment {
            radiance: self.radiance as f32,
            map,
        })
    }
}
/// Density of uniform sphere sampling.
const UNIFORM_PDF: f32 = 1.0 / (4.0 * PI);

#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// Radiance (constant), or the factor applied to the map.
    pub radiance: f32,
    pub map: Option<EnvMap>,
}

/// A luminance map with the cumulative distributions for sampling it.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<f32>,
    /// Marginal CDF over rows (`height + 1` entries, from 0 to 1).
    rows: Vec<f32>,
    /// Conditional CDF over columns of each row (`width + 1` per row).
    cols: Vec<f32>,
}

impl EnvMap {
    /// Reads `R, G, B` (Rec. 709 luminance) or `Y` from the first EXR layer.
    pub fn load(path: &Path) -> Result<EnvMap> {
        let y = match io::read_exr(path, &["R", "G", "B"]) {
            Ok(rgb) => {
                let (w, h) = rgb[0].size();
                Image::from_fn(w, h, |x, y| {
                    0.2126 * rgb[0].get(x, y)
                        + 0.7152 * rgb[1].get(x, y)
                        + 0.0722 * rgb[2].get(x, y)
                })
            }
            Err(_) => io::read_exr(path, &["Y"])?.remove(0),
        };
        if y.data().iter().any(|v| !v.is_finite() || *v < 0.0) {
            return Err(Error::file(
                path,
                "environment map has negative or non-finite values",
            ));
        }
        EnvMap::new(&y).ok_or_else(|| Error::file(path, "environment map is empty or black"))
    }

    /// `None` for an empty or all-black map.
    pub fn new(lum: &Image<f32>) -> Option<EnvMap> {
        let (w, h) = lum.size();
        let mut cols = Vec::with_capacity(h * (w + 1));
        let mut row_weights = Vec::with_capacity(h);
        for y in 0..h {
            let sin = (PI * (y as f32 + 0.5) / h as f32).sin();
            let mut acc = 0.0f64;
            cols.push(0.0);
            let start = cols.len();
            for x in 0..w {
                acc += f64::from(*lum.get(x, y) * sin);
                cols.push(acc as f32);
            }
            row_weights.push(acc);
            if acc > 0.0 {
                for c in &mut cols[start..] {
                    *c = (f64::from(*c) / acc) as f32;
                }
            }
        }
        let total: f64 = row_weights.iter().sum();
        if w == 0 || h == 0 || total <= 0.0 {
            return None;
        }
        let mut rows = Vec::with_capacity(h + 1);
        let mut acc = 0.0;
        rows.push(0.0);
        for r in &row_weights {
            acc += r;
            rows.push((acc / total) as f32);
        }
        Some(EnvMap {
            width: w,
            height: h,
            texels: lum.data().to_vec(),
            rows,
            cols,
        })
    }

    fn texel(&self, dir: Vec3A) -> (usize, usize) {
        let phi = dir.x.atan2(-dir.z).rem_euclid(2.0 * PI);
        let theta = dir.y.clamp(-1.0, 1.0).acos();
        let x = ((phi / (2.0 * PI)) * self.width as f32) as usize;
        let y = ((theta / PI) * self.height as f32) as usize;
        (x.min(self.width - 1), y.min(self.height - 1))
    }

    /// Probability of texel `(x, y)` (row choice × column choice).
    fn texel_probability(&self, x: usize, y: usize) -> f32 {
        let c = &self.cols[y * (self.width + 1)..];
        (self.rows[y + 1] - self.rows[y]) * (c[x + 1] - c[x])
    }

    /// Solid-angle density of [`EnvMap::sample`] for direction `dir`.
    fn pdf(&self, dir: Vec3A) -> f32 {
        let (x, y) = self.texel(dir);
        let sin = (PI * (y as f32 + 0.5) / self.height as f32).sin();
        let texel_solid_angle = 2.0 * PI * PI * sin / (self.width * self.height) as f32;
        self.texel_probability(x, y) / texel_solid_angle
    }

    fn sample(&self, u: [f32; 2]) -> Vec3A {
        let y = (self.rows.partition_point(|&c| c <= u[0]) - 1).min(self.height - 1);
        let c = &self.cols[y * (self.width + 1)..(y + 1) * (self.width + 1)];
        let x = (c.partition_point(|&v| v <= u[1]) - 1).min(self.width - 1);
        // Uniform inside the texel in (u, v), re-using the leftover fraction.
        let fx = ((u[1] - c[x]) / (c[x + 1] - c[x]).max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
        let fy = ((u[0] - self.rows[y]) / (self.rows[y + 1] - self.rows[y]).max(f32::MIN_POSITIVE))
            .clamp(0.0, 1.0);
        let phi = 2.0 * PI * (x as f32 + fx) / self.width as f32;
        let theta = PI * (y as f32 + fy) / self.height as f32;
        Vec3A::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        )
    }
}

impl Environment {
    /// Radiance arriving from direction `dir` (pointing away from the scene).
    #[inline]
    pub fn radiance(&self, dir: Vec3A) -> f32 {
        match &self.map {
            None => self.radiance,
            Some(m) => {
                let (x, y) = m.texel(dir);
                self.radiance * m.texels[y * m.width + x]
            }
        }
    }

    /// Solid-angle density of [`Environment::sample`].
    #[inline]
    pub fn pdf(&self, dir: Vec3A) -> f32 {
        self.map.as_ref().map_or(UNIFORM_PDF, |m| m.pdf(dir))
    }

    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> LightSample {
        let wi = match &self.map {
            None => {
                let z = 1.0 - 2.0 * u[0];
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u[1];
                Vec3A::new(r * phi.cos(), r * phi.sin(), z)
            }
            Some(m) => m.sample(u),
        };
        let pdf = self.pdf(wi);
        LightSample {
            wi,
            value: if pdf > 0.0 {
                self.radiance(wi) / pdf
            } else {
                0.0
            },
            dist: f32::INFINITY,
            pdf,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, Stream};
    use std::f64::consts::PI as PI64;

    /// A map with a bright patch: `E[L·g/pdf]` over importance samples must
    /// equal `∫ L g dω` summed texel by texel (`g = max(0, y)`, a cosine).
    #[test]
    fn importance_sampling_is_unbiased() {
        let (w, h) = (32, 16);
        let lum = Image::from_fn(w, h, |x, y| {
            if (10..14).contains(&x) && (3..6).contains(&y) {
                50.0
            } else {
                0.5
            }
        });
        let env = Environment {
            radiance: 2.0,
            map: EnvMap::new(&lum),
        };
        let mut exact = 0.0f64;
        // The integrand depends on θ only: integrate each texel over θ.
        let n = 256;
        for y in 0..h {
            for x in 0..w {
                for j in 0..n {
                    let theta = PI64 * (y as f64 + (j as f64 + 0.5) / n as f64) / h as f64;
                    let d_omega = theta.sin() * (2.0 * PI64 / w as f64) * (PI64 / (h * n) as f64);
                    exact += 2.0 * f64::from(*lum.get(x, y)) * theta.cos().max(0.0) * d_omega;
                }
            }
        }
        let mut s = Sampler::new(9, Stream::Path, 0, 0, 0);
        let count = 400_000;
        let mut mc = 0.0f64;
        for _ in 0..count {
            let ls = env.sample(s.next_2d());
            assert!((env.pdf(ls.wi) - ls.pdf).abs() <= 1e-3 * ls.pdf);
            mc += f64::from(ls.value * ls.wi.y.max(0.0));
        }
        mc /= f64::from(count);
        assert!((mc / exact - 1.0).abs() < 5e-3, "{mc} vs {exact}");
    }

    #[test]
    fn black_map_is_rejected() {
        assert!(EnvMap::new(&Image::new(4, 2, 0.0)).is_none());
    }
}
