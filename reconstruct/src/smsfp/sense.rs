//! Step 9 of SMSfP (module doc): per-pixel polarization normals, each in the
//! sense of the solved surface unless shading says otherwise (beyond the
//! paper).
//!
//! The shared notes measured that per-pixel polarization normals are exact
//! to 0.1–0.6° where their azimuth sense is right, while an integrated
//! surface is smoothed and bends across self-occlusions. So each pixel's
//! normal has the measured AoP as azimuth, in the sense of the solved
//! surface's normal, and the zenith of its DoP at the region's `η`; where the
//! DoP is noise (below `min_dop_snr`) the solved surface's zenith, and where
//! the pixel is unlit the solved normal. The solved surface thus decides the
//! ambiguity region by region and fills what polarization cannot measure.
//! `per_pixel = false` outputs the solved surfaces' normals, as the paper
//! does (built-in demo views, 256²: torus 17.9° → 6.4° MAE, ellipsoid 5.1° →
//! 2.2°, cup 6.1° → 4.8°).
//!
//! Where the solved surface takes the wrong sense (a thin strap solved
//! together with the body it lies on), shading tells: the two senses predict
//! intensities `α(a + (n±·L)⁺)` that differ by `2α sinθ (L_xy·φ̂)`. A pixel
//! votes for the other sense when its intensity misses the kept sense's
//! prediction by more than `shading_sense` times the light fit's RMS
//! residual (the shading model's own error; at least 3 noise σ) and the
//! other sense's by less than half that miss; it is flipped when most
//! measured pixels of its 5×5 window vote so, since a wrong sense of a
//! smooth solve comes in patches while lone votes are noise or model error.
//! Only pixels seen at zenith ≤ 65° vote: beyond, the outgoing Fresnel
//! transmission dims the true sense below Lambert's prediction (shipped
//! presets, MAE: a 12.91° → 12.07°, b 7.43° → 6.90°, built-in 5.45° → 5.38°;
//! over 120 harder sweep rows at 192² mean −0.05°, 13 better, 4 worse by at
//! most 0.20°, none changed under heavy shot noise; without the zenith limit
//! the noise-free path-traced sphere lost 0.08° at the limb).

use super::azimuth::azimuth_in_sense;
use super::region::RegionState;
use crate::light::Lighting;
use crate::noise::StokesNoise;
use crate::solver::domain::Domain;
use rayon::prelude::*;

/// The shading check stays where Lambert's law is within 10% of the diffuse
/// model of conventions.md §3 for η up to 1.8: zenith ≤ 65° (sin). Towards
/// the limb the out-going Fresnel transmission dims the true sense below
/// Lambert's prediction, which would favour the wrong one.
const SHADING_SENSE_MAX_SIN: f64 = 0.906;

/// Replaces every region's solved normals by its per-pixel polarization
/// normals; a pixel votes to flip when shading misses by more than `margin`
/// (0: no shading check).
pub(super) fn polarization_normals(
    states: &mut [RegionState],
    lighting: &Lighting,
    noise: &StokesNoise,
    margin: f64,
) {
    states
        .par_iter_mut()
        .for_each(|s| region_normals(s, lighting, noise, margin));
}

/// The per-pixel polarization normals of a solved region (module doc).
/// Azimuth: the AoP in the sense of the solved surface's normal, flipped
/// where shading votes so in patches; zenith: from the DoP with the region's
/// `η` where the DoP is measured, the solved surface's where it is noise;
/// unlit pixels keep the surface normal.
fn region_normals(s: &mut RegionState, lighting: &Lighting, noise: &StokesNoise, margin: f64) {
    let theta = &s.theta;
    let shading = Shading {
        lighting,
        alpha: s.alpha,
    };
    // Per pixel: azimuth in the solved sense, zenith, and whether shading
    // votes for the other sense.
    let picked: Vec<Option<(CosSin, CosSin, bool)>> = (0..s.normals.len())
        .map(|k| {
            let (x, y) = s.domain.pixel(k);
            if *s.input.unlit.get(x, y) {
                return None;
            }
            let n = &s.normals[k];
            let azimuth = azimuth_in_sense(f64::from(*s.input.aop.get(x, y)), n);
            let t = if !*s.measured.get(x, y) {
                f64::from(n[2]).clamp(-1.0, 1.0).acos()
            } else {
                f64::from(*theta.get(x, y))
            };
            let zenith = t.min(std::f64::consts::FRAC_PI_2).sin_cos();
            let vote =
                margin > 0.0 && *s.measured.get(x, y) && zenith.0 <= SHADING_SENSE_MAX_SIN && {
                    let raw = f64::from(*s.input.intensity.get(x, y));
                    let scale = s.input.intensity_scale;
                    let sigma = noise.intensity_sigma(raw) / scale;
                    shading.votes_to_flip(raw / scale, azimuth, zenith, margin.max(3.0 * sigma))
                };
            Some((azimuth, zenith, vote))
        })
        .collect();
    let flips = majority(&s.domain, |k| picked[k].map(|(_, _, vote)| vote));
    for (k, n) in s.normals.iter_mut().enumerate() {
        let Some(((cp, sp), (st, ct), _)) = picked[k] else {
            continue;
        };
        let sense = if flips[k] { -1.0 } else { 1.0 };
        *n = [
            (st * cp * sense) as f32,
            (st * sp * sense) as f32,
            ct as f32,
        ];
    }
}

/// An angle as `(cos, sin)`.
type CosSin = (f64, f64);

/// The shading law of the sense check: `α(a + (n·L)⁺)`.
struct Shading<'a> {
    lighting: &'a Lighting,
    alpha: f64,
}

impl Shading<'_> {
    fn predict(&self, (c, s): (f64, f64), (st, ct): (f64, f64)) -> f64 {
        let [lx, ly, lz] = self.lighting.vector;
        self.alpha * (self.lighting.ambient + (st * (c * lx + s * ly) + ct * lz).max(0.0))
    }

    /// Whether intensity `i` misses the prediction of azimuth `(cos φ,
    /// sin φ)` by more than `margin` and the opposite azimuth's by less than
    /// half as much.
    fn votes_to_flip(&self, i: f64, azimuth: (f64, f64), zenith: (f64, f64), margin: f64) -> bool {
        let keep = (i - self.predict(azimuth, zenith)).abs();
        let flip = (i - self.predict((-azimuth.0, -azimuth.1), zenith)).abs();
        keep - flip > margin && keep > 2.0 * flip
    }
}

/// Pixels of `domain` voting `true` (`vote(k)`; `None`: no say) whose 5×5
/// window's voting pixels mostly vote `true` too.
fn majority(domain: &Domain, vote: impl Fn(usize) -> Option<bool>) -> Vec<bool> {
    (0..domain.len())
        .map(|k| {
            if vote(k) != Some(true) {
                return false;
            }
            let (x, y) = domain.pixel(k);
            let (mut yes, mut all) = (0, 0);
            for dy in -2..=2isize {
                for dx in -2..=2isize {
                    let j = domain.at(x as isize + dx, y as isize + dy);
                    if let Some(v) = j.and_then(&vote) {
                        all += 1;
                        yes += usize::from(v);
                    }
                }
            }
            2 * yes > all
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::Image;

    /// The sense check: a normal on the wrong side of a side light
    /// misses its shading and votes to flip; the right one does not; under a
    /// light along the view both senses shade alike and nobody votes; and
    /// only patches of votes flip, not lone pixels.
    #[test]
    fn shading_flips_wrong_senses_in_patches_only() {
        let side = Lighting {
            ambient: 0.05,
            vector: [0.6, 0.0, 0.8],
        };
        let shading = Shading {
            lighting: &side,
            alpha: 1.0,
        };
        let zenith = 50f64.to_radians().sin_cos();
        let toward = (1.0, 0.0); // azimuth towards the light
        let i = shading.predict(toward, zenith);
        assert!(!shading.votes_to_flip(i, toward, zenith, 0.05));
        assert!(shading.votes_to_flip(i, (-1.0, 0.0), zenith, 0.05));
        // A miss within the margin is no evidence.
        assert!(!shading.votes_to_flip(i, (-1.0, 0.0), zenith, 2.0));
        let frontal = Lighting {
            ambient: 0.05,
            vector: [0.0, 0.0, 1.0],
        };
        let shading = Shading {
            lighting: &frontal,
            alpha: 1.0,
        };
        let i = shading.predict(toward, zenith);
        assert!(!shading.votes_to_flip(i, (-1.0, 0.0), zenith, 1e-9));

        let mask = Image::new(12, 12, true);
        let domain = Domain::new(&mask);
        // A 6×6 patch voting to flip, one lone vote, one pixel without a say.
        let votes: Vec<Option<bool>> = (0..domain.len())
            .map(|k| {
                let (x, y) = domain.pixel(k);
                match (x, y) {
                    (10, 10) => None,
                    (10, 1) => Some(true),
                    _ => Some(x < 6 && y < 6),
                }
            })
            .collect();
        let flips = majority(&domain, |k| votes[k]);
        let at = |x: usize, y: usize| flips[domain.at(x as isize, y as isize).unwrap()];
        assert!(at(2, 2) && at(0, 0) && at(5, 2));
        assert!(!at(10, 1) && !at(10, 10) && !at(8, 8));
        // The patch's corner sees 9 votes in 25: it stays.
        assert!(!at(5, 5));
    }
}
