//! Environment maps the renderer makes itself, so glossy objects reflect
//! surroundings with no file: the light most real captures and the field's
//! synthetic data (rough dielectrics under HDR maps) are lit by, where a
//! specular lobe reflects something bright in almost every direction.
//!
//! `surroundings = { kind = "...", ... }` in an `environment` light, its
//! radiance the factor on the map (relative units: the sky's zenith is 1):
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `kind` | required | `sky` (clear sky with a sun disk), `overcast` (CIE overcast sky, no sun) or `room` (the inside of a box: dim walls, two ceiling panels, a window) |
//! | `sun_elevation` | 45 | `sky`: the sun's elevation above the horizon, degrees in [0, 90] |
//! | `seed` | 0 | `room`: where the panels and the window are |
//! | `turn` | 0 | the whole map turned about `+y` (up), degrees |
//!
//! Below the horizon of both skies lies a grey ground of albedo 0.2 lit by
//! the sky and sun above it (its radiance `0.2 · E / π`, with `E` the map's
//! irradiance on a horizontal plane). None is a measured sky model: they
//! give compact bright sources, broad bright areas and dark regions at
//! known places, which is what specular polarization depends on.

use crate::sampler::{Sampler, Stream};
use crate::scene_file::Table;
use glam::Vec3A;
use serde::{Deserialize, Serialize};
use sfp_core::{Image, Result};
use std::f32::consts::PI;

/// Map resolution: a texel is 0.7° wide, so the sun disk (2.5° in radius)
/// covers about 40 texels and importance sampling finds it.
const WIDTH: usize = 512;
const HEIGHT: usize = 256;

/// Angular radius of the sun disk, larger than the real 0.27° so a
/// roughness-0.05 highlight is resolved at a few hundred samples.
const SUN_RADIUS_DEG: f32 = 2.5;
/// Irradiance of the sun on a surface facing it, in units of the clear
/// sky's zenith radiance (about 5× the sky's own on a horizontal plane).
const SUN_IRRADIANCE: f32 = 15.0;
const GROUND_ALBEDO: f32 = 0.2;

/// The scene file's `surroundings` table. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurroundingsDesc {
    pub kind: SurroundingsKind,
    #[serde(default = "default_sun_elevation")]
    pub sun_elevation: f64,
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub turn: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurroundingsKind {
    Sky,
    Overcast,
    Room,
}

fn default_sun_elevation() -> f64 {
    45.0
}

impl SurroundingsDesc {
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        if !(0.0..=90.0).contains(&self.sun_elevation) {
            return Err(t.err("surroundings.sun_elevation", "must be in [0, 90] degrees"));
        }
        if !self.turn.is_finite() {
            return Err(t.err("surroundings.turn", "must be finite"));
        }
        Ok(())
    }

    /// The luminance map, in the layout of an environment light's map
    /// (column = azimuth `atan2(x, −z)`, row = polar angle from `+y`);
    /// every kind has bright texels.
    pub fn luminance(&self) -> Image<f32> {
        let turn = (self.turn as f32).to_radians();
        let (sin_t, cos_t) = turn.sin_cos();
        let room = Room::new(self.seed);
        let sun = {
            let e = (self.sun_elevation as f32).to_radians();
            Vec3A::new(0.0, e.sin(), -e.cos())
        };
        let sky = |d: Vec3A| match self.kind {
            SurroundingsKind::Sky => clear_sky(d, sun),
            SurroundingsKind::Overcast => overcast_sky(d),
            SurroundingsKind::Room => room.radiance(d),
        };
        // Direction of texel (x, y) with the map turned: the content seen
        // at azimuth φ is the unturned content at φ − turn.
        let direction = |x: usize, y: usize| {
            let phi = 2.0 * PI * (x as f32 + 0.5) / WIDTH as f32;
            let theta = PI * (y as f32 + 0.5) / HEIGHT as f32;
            let d = Vec3A::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            );
            Vec3A::new(d.x * cos_t + d.z * sin_t, d.y, -d.x * sin_t + d.z * cos_t)
        };
        let mut lum = Image::from_fn(WIDTH, HEIGHT, |x, y| sky(direction(x, y)));
        if self.kind != SurroundingsKind::Room {
            let ground = GROUND_ALBEDO * horizontal_irradiance(&lum) / PI;
            for y in HEIGHT / 2..HEIGHT {
                for x in 0..WIDTH {
                    *lum.get_mut(x, y) = ground;
                }
            }
        }
        lum
    }
}

/// A clear sky: brighter towards the horizon and around the sun, plus the
/// sun disk; black below the horizon (the ground is added after).
fn clear_sky(d: Vec3A, sun: Vec3A) -> f32 {
    if d.y < 0.0 {
        return 0.0;
    }
    let elevation = d.y.asin();
    let gamma = d.dot(sun).clamp(-1.0, 1.0).acos();
    let sun_radius = SUN_RADIUS_DEG.to_radians();
    if gamma < sun_radius {
        let solid_angle = 2.0 * PI * (1.0 - sun_radius.cos());
        return SUN_IRRADIANCE / solid_angle;
    }
    0.5 * (1.0 + 2.0 * (-4.0 * elevation).exp()) * (1.0 + 3.0 * (-gamma / 0.25).exp())
}

/// The CIE overcast sky: three times brighter at the zenith than at the
/// horizon.
fn overcast_sky(d: Vec3A) -> f32 {
    if d.y < 0.0 {
        return 0.0;
    }
    (1.0 + 2.0 * d.y) / 3.0
}

/// Irradiance of the map on a horizontal plane facing up (`∫ L cosθ dω`
/// over the upper hemisphere), summed texel by texel.
fn horizontal_irradiance(lum: &Image<f32>) -> f32 {
    let (w, h) = lum.size();
    let d_phi = 2.0 * PI / w as f32;
    let d_theta = PI / h as f32;
    let mut e = 0.0f64;
    for y in 0..h / 2 {
        let theta = (y as f32 + 0.5) * d_theta;
        let weight = theta.cos() * theta.sin() * d_phi * d_theta;
        let row: f32 = (0..w).map(|x| *lum.get(x, y)).sum();
        e += f64::from(row * weight);
    }
    e as f32
}

/// The inside of the box `[−1, 1]³` around the object: walls, floor and
/// ceiling of different greys, two light panels on the ceiling and a
/// window on one wall, placed by the seed.
struct Room {
    /// Ceiling panels: centre (x, z) and half sizes.
    panels: [([f32; 2], [f32; 2]); 2],
    /// The window's wall (0: −z, 1: +x, 2: +z, 3: −x), centre (along the
    /// wall, height) and half sizes.
    window: (usize, [f32; 2], [f32; 2]),
}

/// Radiance of the panels and the window, and of the surfaces.
const PANEL: f32 = 30.0;
const WINDOW: f32 = 10.0;
const CEILING: f32 = 0.35;
const WALLS: [f32; 4] = [0.25, 0.3, 0.2, 0.28];
const FLOOR: f32 = 0.12;

impl Room {
    fn new(seed: u64) -> Room {
        let mut s = Sampler::new(seed, Stream::Surroundings, 0, 0, 0);
        let mut at = |half: f32| (s.next_f32() * 2.0 - 1.0) * (1.0 - half);
        let mut panel = || {
            let half = [0.25, 0.15];
            ([at(half[0]), at(half[1])], half)
        };
        let panels = [panel(), panel()];
        let wall = (Sampler::new(seed, Stream::Surroundings, 1, 0, 0).next_f32() * 4.0) as usize;
        let half = [0.4, 0.3];
        let window = (wall.min(3), [at(half[0]), 0.2 * at(half[1])], half);
        Room { panels, window }
    }

    fn radiance(&self, d: Vec3A) -> f32 {
        let a = d.abs();
        let inside = |p: [f32; 2], (c, h): ([f32; 2], [f32; 2])| {
            (p[0] - c[0]).abs() < h[0] && (p[1] - c[1]).abs() < h[1]
        };
        if a.y >= a.x && a.y >= a.z {
            let p = [d.x / a.y, d.z / a.y];
            return if d.y < 0.0 {
                FLOOR
            } else if self.panels.iter().any(|&panel| inside(p, panel)) {
                PANEL
            } else {
                CEILING
            };
        }
        // Which wall, and the point on it as (along the wall, height).
        let (wall, p) = if a.z >= a.x {
            let p = [d.x / a.z, d.y / a.z];
            if d.z < 0.0 {
                (0, p)
            } else {
                (2, [-p[0], p[1]])
            }
        } else {
            let p = [d.z / a.x, d.y / a.x];
            if d.x > 0.0 {
                (1, p)
            } else {
                (3, [-p[0], p[1]])
            }
        };
        let (window_wall, c, h) = self.window;
        if wall == window_wall && inside(p, (c, h)) {
            WINDOW
        } else {
            WALLS[wall]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn desc(kind: SurroundingsKind) -> SurroundingsDesc {
        SurroundingsDesc {
            kind,
            sun_elevation: 30.0,
            seed: 4,
            turn: 0.0,
        }
    }

    /// The sun disk holds the irradiance it is given; the ground below
    /// reflects 0.2 of what the sky and sun send down, divided by π.
    #[test]
    fn the_sky_s_sun_and_ground_carry_their_irradiance() {
        let d = desc(SurroundingsKind::Sky);
        let sun = Vec3A::new(0.0, 0.5, -(0.75f32).sqrt());
        let radius = SUN_RADIUS_DEG.to_radians();
        let on_sun = clear_sky(sun, sun) * 2.0 * PI * (1.0 - radius.cos());
        assert!((on_sun - SUN_IRRADIANCE).abs() < 1e-3, "{on_sun}");
        let lum = d.luminance();
        let e = horizontal_irradiance(&lum);
        // Sun at 30°: 15 · sin 30° = 7.5 from the sun, the rest from the sky.
        assert!(e > 7.5 && e < 7.5 + 3.0 * PI, "{e}");
        let ground = *lum.get(0, HEIGHT - 1);
        assert!((ground - 0.2 * e / PI).abs() < 1e-5, "{ground} {e}");
    }

    /// Turning the map by 90° moves its content 90° in azimuth: the sun,
    /// 30° high at azimuth 0 (`−z`), is then at azimuth 90° (`+x`).
    #[test]
    fn turn_rotates_the_content_about_up() {
        let mut d = desc(SurroundingsKind::Sky);
        // Row 85 is 60.1° from up; columns 0 and 128 are at azimuths 0.35° and 90.35°.
        let sun = SUN_IRRADIANCE / (2.0 * PI * (1.0 - SUN_RADIUS_DEG.to_radians().cos()));
        let lum = d.luminance();
        assert_eq!((*lum.get(0, 85), *lum.get(128, 85) < 10.0), (sun, true));
        d.turn = 90.0;
        let lum = d.luminance();
        assert_eq!((*lum.get(128, 85), *lum.get(0, 85) < 10.0), (sun, true));
    }

    #[test]
    fn the_room_has_its_panels_above_and_a_window_on_a_wall() {
        let room = Room::new(4);
        let ([cx, cz], _) = room.panels[0];
        assert_eq!(room.radiance(Vec3A::new(cx, 1.0, cz).normalize()), PANEL);
        assert_eq!(room.radiance(Vec3A::new(0.0, -1.0, 0.0)), FLOOR);
        let (wall, [u, v], _) = room.window;
        let d = match wall {
            0 => Vec3A::new(u, v, -1.0),
            1 => Vec3A::new(1.0, v, u),
            2 => Vec3A::new(-u, v, 1.0),
            _ => Vec3A::new(-1.0, v, -u),
        };
        assert_eq!(room.radiance(d.normalize()), WINDOW);
        // Another seed moves them.
        assert_ne!(Room::new(5).panels[0].0, room.panels[0].0);
    }
}
