//! Render axes of the light: the rig and the key light's elevation and
//! azimuth. They are read together into a `LightPose` (`light_pose`), which places the
//! lights once every axis of a point has set its part.

use super::axis::{Axis, Change, number, text};

/// The light rigs of the `light` axis.
pub const LIGHT_RIGS: [&str; 4] = ["scene", "sun", "two_lights", "environment"];

pub const LIGHT: Axis = Axis {
    key: "light",
    old_key: None,
    meaning: "a light rig: scene, sun, two_lights or environment",
    accepts: |v| text(v).is_some_and(|t| LIGHT_RIGS.contains(&t)),
    label: "light rig",
    unit: "",
    change: Change::Render {
        scene: |c, v| c.light.rig = text(v).map(str::to_string),
        analytic: None,
    },
};

pub const LIGHT_AZIMUTH_DEG: Axis = Axis {
    key: "light_azimuth_deg",
    old_key: None,
    meaning: "degrees in the image plane from +x towards +y",
    accepts: |v| number(v).is_some_and(f64::is_finite),
    label: "light azimuth",
    unit: "°",
    change: Change::Render {
        scene: |c, v| c.light.azimuth_deg = number(v),
        analytic: Some(|c, v| c.light.azimuth_deg = number(v)),
    },
};

pub const LIGHT_ELEVATION_DEG: Axis = Axis {
    key: "light_elevation_deg",
    old_key: None,
    meaning: "degrees above the image plane, in (0, 90]",
    accepts: |v| number(v).is_some_and(|x| x > 0.0 && x <= 90.0),
    label: "light elevation",
    unit: "°",
    change: Change::Render {
        scene: |c, v| c.light.elevation_deg = number(v),
        analytic: Some(|c, v| c.light.elevation_deg = number(v)),
    },
};
