//! What a dataset view draws beside its orientation: the material values
//! from the preset's ranges (`[dataset.vary]`) and one of its lightings
//! (`[[lighting]]`), generated surroundings turned at random about up. The
//! draws come from `(seed, view)` alone (stream `Appearance`), so a view
//! keeps its look when other views are added and `--seed` changes it, as it
//! changes the orientations: views of one's own can be held out.

use crate::lights::LightDesc;
use crate::materials::MaterialDesc;
use crate::sampler::{Sampler, Stream};
use serde::{Deserialize, Serialize};

/// `[dataset.vary]`: ranges `[low, high]` each view's material values are
/// drawn from (uniformly; the roughness log-uniformly, since a highlight
/// changes as much from 0.05 to 0.1 as from 0.25 to 0.5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vary {
    pub albedo: [f64; 2],
    pub specular: [f64; 2],
    pub roughness: [f64; 2],
    pub eta: [f64; 2],
}

/// `[[lighting]]`: one set of lights a view may be lit by.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lighting {
    /// Recorded in `dataset.json` with each view lit by it.
    pub name: String,
    #[serde(rename = "light")]
    pub lights: Vec<LightDesc>,
}

impl Vary {
    /// The first range that is not `0 ≤ low ≤ high` within its bounds, as
    /// `(key, what is wrong)`.
    pub fn problem(&self) -> Option<(&'static str, &'static str)> {
        let ranges = [
            ("albedo", self.albedo, 0.0, 1.0, "within [0, 1]"),
            ("specular", self.specular, 0.0, 1.0, "within [0, 1]"),
            ("roughness", self.roughness, 1e-3, 1.0, "within [0.001, 1]"),
            ("eta", self.eta, 1.0, 4.0, "within [1, 4]"),
        ];
        ranges
            .into_iter()
            .find(|(_, [lo, hi], min, max, _)| !(min <= lo && lo <= hi && hi <= max))
            .map(|(key, _, _, _, bounds)| (key, bounds))
    }

    /// `base` with this view's values.
    fn draw(&self, base: &MaterialDesc, s: &mut Sampler) -> MaterialDesc {
        let mut uniform = |[lo, hi]: [f64; 2]| lo + (hi - lo) * s.next_f64();
        let mut m = base.clone();
        m.set_albedo(uniform(self.albedo));
        m.set_specular(uniform(self.specular));
        let [lo, hi] = self.roughness.map(f64::ln);
        m.set_roughness(uniform([lo, hi]).exp());
        m.set_eta(uniform(self.eta));
        m
    }
}

/// The material and lights of view `view_index`, and the name of the
/// lighting drawn (`None` when the preset has no `[[lighting]]`).
pub fn draw(
    seed: u64,
    view_index: u64,
    vary: Option<&Vary>,
    lightings: &[Lighting],
    material: &MaterialDesc,
    lights: &[LightDesc],
) -> (MaterialDesc, Vec<LightDesc>, Option<String>) {
    let mut s = Sampler::new(seed, Stream::Appearance, view_index, 0, 0);
    let material = vary.map_or_else(|| material.clone(), |v| v.draw(material, &mut s));
    if lightings.is_empty() {
        return (material, lights.to_vec(), None);
    }
    let pick = ((s.next_f64() * lightings.len() as f64) as usize).min(lightings.len() - 1);
    let turn = 360.0 * s.next_f64();
    let lighting = &lightings[pick];
    let lights = lighting.lights.iter().map(|l| l.turned(turn)).collect();
    (material, lights, Some(lighting.name.clone()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lights::EnvironmentDesc;
    use crate::lights::surroundings::{SurroundingsDesc, SurroundingsKind};
    use crate::materials::DiffusePolarizedDesc;

    fn base() -> MaterialDesc {
        MaterialDesc::DiffusePolarized(DiffusePolarizedDesc {
            albedo: 0.5,
            albedo_texture: None,
            tint: None,
            eta: 1.5,
            specular: 0.0,
            roughness: 0.2,
        })
    }

    fn sky(kind: SurroundingsKind) -> Lighting {
        Lighting {
            name: format!("{kind:?}"),
            lights: vec![LightDesc::Environment(EnvironmentDesc {
                radiance: 1.0,
                map: None,
                surroundings: Some(SurroundingsDesc {
                    kind,
                    sun_elevation: 40.0,
                    seed: 0,
                    turn: 0.0,
                }),
            })],
        }
    }

    /// Over many views every value stays in its range and fills it, both
    /// lightings are drawn about equally, and a view's draw depends on
    /// `(seed, view)` only.
    #[test]
    fn draws_cover_the_ranges_and_lightings_and_are_reproducible() {
        let vary = Vary {
            albedo: [0.05, 0.9],
            specular: [0.3, 1.0],
            roughness: [0.05, 0.5],
            eta: [1.4, 1.7],
        };
        assert_eq!(vary.problem(), None);
        let lightings = [sky(SurroundingsKind::Sky), sky(SurroundingsKind::Room)];
        let mut rough = Vec::new();
        let mut rooms = 0;
        for view in 0..400 {
            let (m, lights, name) = draw(7, view, Some(&vary), &lightings, &base(), &[]);
            let MaterialDesc::DiffusePolarized(d) = &m else {
                panic!("kind changed")
            };
            assert!((0.05..=0.9).contains(&d.albedo) && (1.4..=1.7).contains(&d.eta));
            assert!((0.3..=1.0).contains(&d.specular));
            rough.push(d.roughness);
            rooms += usize::from(name.as_deref() == Some("Room"));
            assert_eq!(lights.len(), 1);
            let again = draw(7, view, Some(&vary), &lightings, &base(), &[]);
            assert_eq!(again, (m.clone(), lights, name));
        }
        rough.sort_by(f64::total_cmp);
        assert!(rough[0] >= 0.05 && rough[0] < 0.06 && rough[399] > 0.45 && rough[399] <= 0.5);
        // Log-uniform: the median near √(0.05 · 0.5) = 0.158.
        assert!((rough[200] - 0.158).abs() < 0.03, "{}", rough[200]);
        assert!((150..250).contains(&rooms), "{rooms}");
        let other_seed = draw(8, 0, Some(&vary), &lightings, &base(), &[]);
        assert_ne!(
            other_seed.0,
            draw(7, 0, Some(&vary), &lightings, &base(), &[]).0
        );
    }

    #[test]
    fn bad_ranges_are_named() {
        let mut vary = Vary {
            albedo: [0.5, 0.2],
            specular: [0.0, 1.0],
            roughness: [0.05, 0.5],
            eta: [1.4, 1.7],
        };
        assert_eq!(vary.problem().map(|p| p.0), Some("albedo"));
        vary.albedo = [0.2, 0.5];
        vary.roughness = [0.0, 0.5];
        assert_eq!(vary.problem().map(|p| p.0), Some("roughness"));
    }
}
