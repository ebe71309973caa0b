//! The light the light axes of one point gather (rig, key-light elevation
//! and azimuth), placed once every axis of the point has set its part.

use sfp_core::analytic::AnalyticScene;
use sfp_core::{Error, Result};
use sfp_renderer::lights::LightDesc;
use sfp_renderer::scene::Scene;

/// The light the axes of one point ask for; `None` keeps the view's.
#[derive(Clone, Debug, Default)]
pub struct LightPose {
    pub rig: Option<String>,
    pub elevation_deg: Option<f64>,
    pub azimuth_deg: Option<f64>,
}

impl LightPose {
    /// Whether an axis set any part of the light.
    pub fn is_set(&self) -> bool {
        self.rig.is_some() || self.elevation_deg.is_some() || self.azimuth_deg.is_some()
    }

    /// Turns an analytic view's light to this elevation and azimuth, its
    /// irradiance (the vector's length) kept.
    pub fn place_analytic(&self, a: &mut AnalyticScene) {
        let l = a.light;
        let norm = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        let (el, az) = (
            (self.elevation_deg).unwrap_or_else(|| (l[2] / norm).asin().to_degrees()),
            (self.azimuth_deg).unwrap_or_else(|| l[1].atan2(l[0]).to_degrees()),
        );
        let (el, az) = (el.to_radians(), az.to_radians());
        a.light = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()].map(|v| v * norm);
    }

    /// The lights of `scene` with this rig and key-light elevation and
    /// azimuth. The key light is the scene's first directional light;
    /// angles are in the camera frame (conventions.md §1).
    pub fn lights(&self, scene: &Scene) -> Result<Vec<LightDesc>> {
        let d = &scene.desc;
        let c = &d.camera;
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let unit = |a: [f64; 3]| {
            let n = dot(a, a).sqrt();
            a.map(|x| x / n)
        };
        let back = unit(sub(c.position, c.look_at));
        let right = unit(cross(c.up, back));
        let up = cross(back, right);
        let rig = self.rig.as_deref().unwrap_or("scene");
        let key = d.lights.iter().position(|l| l.direction().is_some());
        let environment = d.lights.iter().find_map(|l| l.environment_radiance());
        if rig == "environment" {
            // Uniform light: elevation and azimuth do not change it.
            return Ok(vec![LightDesc::uniform_environment(
                environment.filter(|&r| r > 0.0).unwrap_or(1.0),
            )]);
        }
        let Some(key) = key else {
            return Err(Error::file(
                &scene.source,
                "the light axes need a directional (key) light in the scene",
            ));
        };
        let key_light = &d.lights[key];
        let direction = key_light.direction().expect("the key light is directional");
        let local = unit([
            dot(direction, right),
            dot(direction, up),
            dot(direction, back),
        ]);
        let el = (self.elevation_deg.map(f64::to_radians))
            .unwrap_or_else(|| local[2].clamp(-1.0, 1.0).asin());
        let az =
            (self.azimuth_deg.map(f64::to_radians)).unwrap_or_else(|| local[1].atan2(local[0]));
        let toward = |az: f64| {
            let (x, y, z) = (el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            [0, 1, 2].map(|k| x * right[k] + y * up[k] + z * back[k])
        };
        let directional = |az: f64| key_light.with_direction(toward(az));
        Ok(match rig {
            "sun" => vec![directional(az)],
            "two_lights" => vec![directional(az), directional(az + std::f64::consts::PI)],
            _ => {
                let mut lights = d.lights.clone();
                lights[key] = directional(az);
                lights
            }
        })
    }
}
