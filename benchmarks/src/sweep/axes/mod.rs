//! The axes a sweep may name, each declared once: its key, what its values
//! are, what it changes (a render, an exposure or a method's
//! configuration) and how the report labels it. The sweep file, the plan
//! and the report read this registry; adding an axis is its declaration in
//! the file of its family and one line in [`AXES`].

pub mod axis;
pub mod light;
pub mod light_pose;
pub mod material;
pub mod method;
pub mod noise;

use axis::Axis;

/// Every axis, in name order.
pub const AXES: &[&Axis] = &[
    &material::ETA,
    &light::LIGHT,
    &light::LIGHT_AZIMUTH_DEG,
    &light::LIGHT_ELEVATION_DEG,
    &method::METHOD_ETA,
    &noise::NOISE_FULL_WELL,
    &noise::NOISE_READ_SIGMA,
    &material::ROUGHNESS,
    &material::SPECULAR_WEIGHT,
    &material::TEXTURE,
];

/// The axis of key `key`.
pub fn axis(key: &str) -> Option<&'static Axis> {
    AXES.iter().copied().find(|a| a.key == key)
}

/// The axis `key` names in a sweep file, and whether `key` is its old,
/// deprecated key.
pub fn named(key: &str) -> Option<(&'static Axis, bool)> {
    axis(key).map(|a| (a, false)).or_else(|| {
        AXES.iter()
            .copied()
            .find(|a| a.old_key == Some(key))
            .map(|a| (a, true))
    })
}

/// The keys of every axis, for an error naming the known ones.
pub fn keys() -> Vec<&'static str> {
    AXES.iter().map(|a| a.key).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique_sorted_and_documented() {
        let keys = keys();
        assert!(keys.windows(2).all(|w| w[0] < w[1]), "{keys:?}");
        let readme = include_str!("../../../README.md");
        for a in AXES {
            assert!(
                readme.contains(&format!("| `{}` |", a.key)),
                "{} is not in benchmarks/README.md's axis table",
                a.key
            );
            if let Some(old) = a.old_key {
                assert!(axis(old).is_none(), "{old} is an axis and an old key");
            }
        }
    }

    #[test]
    fn old_keys_name_their_axis() {
        let (a, old) = named("specular").unwrap();
        assert_eq!((a.key, old), ("specular_weight", true));
        let (a, old) = named("specular_weight").unwrap();
        assert_eq!((a.key, old), ("specular_weight", false));
        assert!(named("wobble").is_none());
    }
}
