//! Render axes of the objects' material: its refractive index, specular
//! lobe and albedo texture. A swept value replaces a whole map (an
//! SVBRDF's) by a constant, on every object of the scene.

use super::axis::{Axis, Change, number, text};
use crate::row::AxisValue;

pub const ETA: Axis = Axis {
    key: "eta",
    old_key: None,
    meaning: "a refractive index in [1, 4]",
    accepts: |v| number(v).is_some_and(|x| (1.0..=4.0).contains(&x)),
    label: "true refractive index η",
    unit: "",
    change: Change::Render {
        scene: |c, v| {
            for o in &mut c.desc.objects {
                o.material.set_eta(number(v).expect("checked"));
            }
        },
        analytic: Some(|c, v| c.scene.eta = number(v).expect("checked")),
    },
};

pub const ROUGHNESS: Axis = Axis {
    key: "roughness",
    old_key: None,
    meaning: "a GGX roughness in (0, 1]",
    accepts: |v| number(v).is_some_and(|x| x > 0.0 && x <= 1.0),
    label: "roughness",
    unit: "",
    change: Change::Render {
        scene: |c, v| {
            for o in &mut c.desc.objects {
                o.material.set_roughness(number(v).expect("checked"));
            }
        },
        analytic: None,
    },
};

/// The weight of the specular lobe; `specular` before, which is also the
/// name of the methods' option (the specular model they assume).
pub const SPECULAR_WEIGHT: Axis = Axis {
    key: "specular_weight",
    old_key: Some("specular"),
    meaning: "a specular weight ≥ 0",
    accepts: |v| number(v).is_some_and(|x| x >= 0.0 && x.is_finite()),
    label: "specular weight",
    unit: "",
    change: Change::Render {
        scene: |c, v| {
            for o in &mut c.desc.objects {
                o.material.set_specular(number(v).expect("checked"));
            }
        },
        analytic: None,
    },
};

/// The objects' albedo textures, `on` or `off`: a sweep with this axis
/// renders presets with their textures, which `off` then removes.
pub const TEXTURE: Axis = Axis {
    key: "texture",
    old_key: None,
    meaning: "on or off",
    accepts: |v| matches!(text(v), Some("on" | "off")),
    label: "texture",
    unit: "",
    change: Change::Render {
        scene: |c, v| {
            if v == &AxisValue::Text("off".into()) {
                for o in &mut c.desc.objects {
                    o.material.remove_albedo_texture();
                }
            }
        },
        analytic: None,
    },
};
