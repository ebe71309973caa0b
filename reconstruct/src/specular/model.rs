//! Specular reflection in the data: the `specular` option every method has
//! (issue: mixed specular/diffuse polarization). `"auto"` improves every
//! method on `b --svbrdf`, `a --svbrdf` and `builtin --svbrdf` but costs
//! every method more than 0.1° on the diffuse `b` at 256², so `"off"` stays
//! the default (README, "Specular reflection", has the figures).
//!
//! A glossy dielectric reflects part of the light at its surface. That part
//! is polarized perpendicular to the normal's azimuth with the specular DoP
//! `ρ_s(θ)`, the diffuse part parallel with `ρ_d(θ)`, so the polarization
//! measured along the azimuth `φ` is (intensity share `f` specular)
//! `q = ρ cos 2(ψ − φ) = (1 − f) ρ_d(θ) − f ρ_s(θ)`. Below Brewster's angle
//! `ρ_s ≫ ρ_d`: a few percent of specular light dominate the polarization
//! and turn the AoP by 90° (measured on preset `b --svbrdf` at 256²: 6–38 %
//! of an object's pixels, while the specular share of `s0` exceeds ½ on
//! 0–10 %). Reading those AoPs in the right sense is most of what can be
//! gained: with the sense taken from the ground truth, SMSfP's MAE falls
//! from 17.8° to 14.0° there.
//!
//! - `"off"`: every pixel diffuse, the input as measured.
//! - `"auto"`: the AoP field split into pieces of one sense ([`turned`])
//!   and each piece's sense voted by the occluding boundary, by the
//!   surface of the shared height-from-polarization system solved over the
//!   whole mask (`system`, Smith's configuration) and by its pixels
//!   polarized beyond the diffuse ceiling (`beyond_diffuse`) and, where
//!   the view shows reflected surroundings, by each pixel's intensity
//!   against their radiance (`surroundings`); turned pixels have
//!   their AoP turned by 90°.
//! - `"MASK.png"`: the white pixels are specular (Smith et al.'s
//!   convention): AoP turned by 90°, zenith from the specular DoP on its
//!   branch below Brewster's angle, no shading row. White is the mask's
//!   brightest value, whatever its bit depth ([`from_mask`]).
//!
//! Whichever form, a method's reading also holds each pixel's specular
//! share of `s0` under the normals it outputs (`share`): the
//! turned AoPs are not the highlights.

use crate::input::Input;
use crate::light::LightSource;
use crate::noise::{dop_snr, stokes_noise};
use crate::normal::normal_azimuth;
use crate::parity_union::ParityUnion;
use crate::prior::{ConvexityPrior, DEFAULT_EXPONENT, convexity_prior};
use crate::solver::domain::Domain;
use crate::solver::lsq::Solver;
use crate::solver::ordering::Ordering;
use crate::specular::beyond_diffuse::{diffuse_ceiling, exceeds};
use crate::specular::share::SpecularReading;
use crate::specular::surroundings;
use crate::system::{PixelData, System};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sfp_core::fresnel::{diffuse_dop, specular_zenith_below_brewster};
use sfp_core::{Error, Image, Mask, Result, io};
use std::borrow::Cow;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

/// How a method treats specular reflection: the `specular` option.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum SpecularModel {
    /// Every pixel is diffuse (the input as measured).
    #[default]
    Off,
    /// Pixels labelled from the data.
    Auto,
    /// A mask image: white pixels are specular.
    Mask(String),
}

impl Serialize for SpecularModel {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            SpecularModel::Off => s.serialize_str("off"),
            SpecularModel::Auto => s.serialize_str("auto"),
            SpecularModel::Mask(path) => s.serialize_str(path),
        }
    }
}

impl<'de> Deserialize<'de> for SpecularModel {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        Ok(match text.as_str() {
            "off" => SpecularModel::Off,
            "auto" => SpecularModel::Auto,
            "" => {
                return Err(serde::de::Error::custom(
                    "specular: expected \"auto\", \"off\" or a mask image's path",
                ));
            }
            _ => SpecularModel::Mask(text),
        })
    }
}

/// A method's specular reading, from the input it reads to the reading of
/// its output: the two ends every method shares (module doc).
pub struct SpecularPass<'a> {
    captured: &'a Input,
    prepared: Cow<'a, Input>,
    turned: Option<Mask>,
    eta: f64,
    warnings: Vec<String>,
}

impl SpecularPass<'_> {
    /// The input the method reads: AoPs of the turned pixels turned (and,
    /// with a mask, their zenith from the specular DoP).
    pub fn input(&self) -> &Input {
        &self.prepared
    }

    /// What the user should know about the specular reading
    /// (`MethodRecord::warnings`): a mask without a specular pixel.
    pub fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// What was read as specular under the method's output `normals`, each
    /// pixel's share from the input as captured (`None` when off).
    pub fn read(&self, normals: &Image<[f32; 3]>) -> Option<SpecularReading> {
        let turned = self.turned.clone()?;
        Some(SpecularReading::new(
            turned,
            self.captured,
            normals,
            self.eta,
        ))
    }
}

impl SpecularModel {
    /// The pass of a method that assumes refractive index `eta` over
    /// `input`.
    pub fn pass<'a>(&self, input: &'a Input, eta: f64) -> Result<SpecularPass<'a>> {
        let (prepared, turned) = self.apply(input, eta)?;
        let warnings = match (self, &turned) {
            (SpecularModel::Mask(path), Some(turned)) if turned.count() == 0 => vec![format!(
                "the specular mask {path} has no specular pixel (every pixel is 0): \
                 every pixel is read as diffuse"
            )],
            _ => Vec::new(),
        };
        Ok(SpecularPass {
            captured: input,
            prepared,
            turned,
            eta,
            warnings,
        })
    }

    /// The input a method reads under this model, with refractive index
    /// `eta`, and the specular pixels found (`None` when off).
    fn apply<'a>(&self, input: &'a Input, eta: f64) -> Result<(Cow<'a, Input>, Option<Mask>)> {
        match self {
            SpecularModel::Off => Ok((Cow::Borrowed(input), None)),
            SpecularModel::Auto => {
                // One boundary prior for the solve and the vote.
                let prior = convexity_prior(&input.mask, DEFAULT_EXPONENT);
                let surface = solved_normals(input, eta, &prior)?;
                let specular = turned(input, &surface, &prior, eta);
                let mut out = input.clone();
                for (i, _) in specular.data().iter().enumerate().filter(|(_, t)| **t) {
                    out.aop.data_mut()[i] = wrap(f64::from(input.aop.data()[i]) + FRAC_PI_2) as f32;
                }
                Ok((Cow::Owned(out), Some(specular)))
            }
            SpecularModel::Mask(path) => {
                let specular = from_mask(Path::new(path), input)?;
                let out = from_specular_dop(input, &specular, eta);
                Ok((Cow::Owned(out), Some(specular)))
            }
        }
    }
}

/// Normals of the shared system solved over the whole mask (Smith's
/// configuration: boundary prior, estimated light).
fn solved_normals(input: &Input, eta: f64, prior: &ConvexityPrior) -> Result<Image<[f32; 3]>> {
    let domain = Domain::new(&input.mask);
    let (theta, _) = input.zenith(eta);
    let data = PixelData::gather(&domain, input, &theta, None)?;
    let light = LightSource::Estimate;
    let estimate = light.resolve(&data.light_samples(), 0, input.intensity_scale)?;
    let mut solver = Solver::new(Ordering::default());
    solver.prepare(&domain);
    let system = System {
        domain: &domain,
        data: &data,
        prior,
        lambda: 0.1,
        relative: None,
    };
    let mut solved = system.solve(&mut solver, &estimate.lighting, light.is_ambiguous())?;
    let kept = solved.candidates.swap_remove(solved.chosen);
    Ok(domain.scatter(&kept.normals, [0.0; 3]))
}

/// The input with the `specular` pixels read by the specular model (module
/// doc).
fn from_specular_dop(input: &Input, specular: &Mask, eta: f64) -> Input {
    let mut out = input.clone();
    for (i, &s) in specular.data().iter().enumerate() {
        if !input.mask.data()[i] || !s {
            continue;
        }
        let psi = f64::from(input.aop.data()[i]);
        let theta = specular_zenith_below_brewster(f64::from(input.dop.data()[i]), eta);
        out.aop.data_mut()[i] = wrap(psi + FRAC_PI_2) as f32;
        out.dop.data_mut()[i] = diffuse_dop(theta, eta) as f32;
        out.dark.data_mut()[i] = true;
    }
    out
}

/// Specular pixels from a mask image: those at least half its brightest
/// value. A mask is a label, not a measurement: the value its tool writes
/// for "specular" (255, 1 from a saved NumPy bool, 127, 255 in a 16-bit
/// PNG) says nothing, so white is the brightest value present, and
/// half of it splits the grey of an anti-aliased edge as a full-scale
/// mask's half scale always did. A mask of zeros has no specular pixel.
fn from_mask(path: &Path, input: &Input) -> Result<Mask> {
    let png = io::read_gray_png(path)?;
    let (w, h) = input.size();
    if png.size() != (w, h) {
        let (pw, ph) = png.size();
        return Err(Error::file(
            path,
            format!("is a {pw}×{ph} specular mask but the view is {w}×{h}"),
        ));
    }
    let values = png.into_u16();
    let white = values.data().iter().copied().max().unwrap_or(0);
    if white == 0 {
        return Ok(values.map(|_| false));
    }
    Ok(values.map(|&v| 2 * u32::from(v) >= u32::from(white)))
}

/// An angle wrapped to `[0, π)`.
fn wrap(a: f64) -> f64 {
    a.rem_euclid(PI)
}

/// Least DoP signal-to-noise ratio of both pixels for their AoPs to say
/// whether they share a sense.
const MIN_EDGE_SNR: f32 = 3.0;
/// Least `cos 2Δψ` of a neighbour pair's AoPs for them to share a sense
/// (`Δψ` within 22.5°).
const CLEAR_RELATION: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// Whether each pixel's AoP is turned by 90° from its azimuth (specular
/// polarization dominates): the AoP field split into pieces of one sense,
/// then each piece's sense voted.
///
/// A smooth surface has a continuous azimuth, so neighbours whose AoPs
/// differ by less than 22.5° ([`CLEAR_RELATION`]), both clear of their
/// noise ([`MIN_EDGE_SNR`]), share a sense and join one piece. Neighbours
/// turned by 90° from each other join nothing: on a surface of even albedo
/// the polarization along the azimuth passes through zero between a
/// diffuse- and a specular-dominated part (the cancellation rings, below
/// [`MIN_EDGE_SNR`]), so clear neighbours 90° apart are an edge of the
/// geometry (an occlusion or a crease inside the mask) or of the albedo,
/// and carrying a sense across them turned diffuse pieces of the diffuse
/// presets (`reports/specular.md`). Each piece's pixels
/// then vote, weighted by their DoP signal-to-noise ratio: near the outline
/// with the outward azimuth, elsewhere with the solved azimuth, and every
/// pixel polarized beyond the diffuse ceiling at its distance from the
/// outline (`beyond_diffuse`) for being turned; when the occluding boundary
/// shows reflected surroundings (`surroundings`), every pixel also
/// votes turned when darker than their radiance, diffuse when brighter,
/// [`SURROUNDINGS_VOTE`] times. A piece is turned when the weighted mean
/// vote says so by at least [`CLEAR_VOTE`] and one of its pixels is one the
/// diffuse model cannot explain (turned on the occluding boundary, polarized
/// beyond the diffuse ceiling, darker than the reflected surroundings), and
/// left diffuse otherwise: diffuse is what the methods assume, turning a
/// diffuse piece costs them more than leaving a specular one, and a surface
/// solved from the same AoPs that merely disagrees with a piece is no
/// evidence of specular light (without that condition the diffuse presets
/// had 10–50× more turned pixels, `reports/specular.md`).
fn turned(input: &Input, normals: &Image<[f32; 3]>, prior: &ConvexityPrior, eta: f64) -> Mask {
    let (w, h) = input.size();
    let snr = dop_snr(input, &stokes_noise(input));
    let deepest = f64::from(prior.deepest());
    let n = w * h;
    let usable = |i: usize| input.mask.data()[i] && !input.unlit.data()[i];
    let clear = |i: usize| is_clear(input, &snr, i);
    let mut pieces = ParityUnion::new(n);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !clear(i) {
                continue;
            }
            for j in [(x + 1 < w).then_some(i + 1), (y + 1 < h).then_some(i + w)]
                .into_iter()
                .flatten()
                .filter(|&j| clear(j))
            {
                let c =
                    (2.0 * (f64::from(input.aop.data()[i]) - f64::from(input.aop.data()[j]))).cos();
                if c >= CLEAR_RELATION {
                    pieces.join(i, j, false);
                }
            }
        }
    }
    let weight_of = |i: usize| aop_weight(snr.data()[i]);
    let on_boundary = |i: usize| is_on_boundary(prior, i);
    let surroundings = surroundings::estimate(input, prior, boundary_evidence(input, prior, &snr));
    // Per piece root: the votes (> 0: diffuse) and their total weight.
    let mut votes = vec![0.0f64; n];
    let mut weight = vec![0.0f64; n];
    // Per piece root: its pixels the diffuse model cannot explain.
    let mut unexplained = vec![false; n];
    for i in (0..n).filter(|&i| usable(i)) {
        let root = pieces.find(i).0;
        let (x, y) = (i % w, i / w);
        let q = weight_of(i);
        // Along the occluding boundary the surface's azimuth points outwards
        // (the convexity prior), and diffuse polarization is strongest.
        let d = *prior.distance.get(x, y);
        let (phi, k) = if on_boundary(i) {
            (f64::from(*prior.azimuth.get(x, y)), BOUNDARY_VOTE)
        } else {
            (normal_azimuth(normals.data()[i]), 1.0)
        };
        let agree = (2.0 * (f64::from(input.aop.data()[i]) - phi)).cos();
        votes[root] += k * agree * q;
        weight[root] += k * q;
        unexplained[root] |= on_boundary(i) && agree < 0.0;
        // Darker than the reflected surroundings: turned
        // (`surroundings`).
        if let Some(l) = surroundings {
            let bright = if input.intensity.data()[i] < l {
                -1.0
            } else {
                1.0
            };
            votes[root] += SURROUNDINGS_VOTE * bright * q;
            unexplained[root] |= bright < 0.0;
            weight[root] += SURROUNDINGS_VOTE * q;
        }
        // Polarized beyond what diffuse reflection gives at this distance
        // from the outline: a vote for the pixel's AoP being turned.
        let ceiling = diffuse_ceiling(f64::from(d), deepest, eta);
        if exceeds(
            f64::from(input.dop.data()[i]),
            f64::from(snr.data()[i]),
            ceiling,
        ) {
            votes[root] -= q;
            weight[root] += q;
            unexplained[root] = true;
        }
    }
    let mut out = Image::new(w, h, false);
    for i in (0..n).filter(|&i| usable(i)) {
        let root = pieces.find(i).0;
        out.data_mut()[i] = unexplained[root] && votes[root] < -CLEAR_VOTE * weight[root];
    }
    out
}

/// Weight of a pixel's AoP in a vote: its DoP signal-to-noise ratio,
/// capped so that no few pixels outvote a piece.
fn aop_weight(snr: f32) -> f64 {
    f64::from(snr.min(10.0 * MIN_EDGE_SNR))
}

/// Whether pixel `i` is lit, in the mask, and its AoP clear of its noise
/// (DoP signal-to-noise ratio `snr`).
fn is_clear(input: &Input, snr: &Image<f32>, i: usize) -> bool {
    input.mask.data()[i] && !input.unlit.data()[i] && snr.data()[i] >= MIN_EDGE_SNR
}

/// Whether pixel `i` lies within [`BOUNDARY_BAND`] of the mask's outline.
fn is_on_boundary(prior: &ConvexityPrior, i: usize) -> bool {
    prior.distance.data()[i] <= BOUNDARY_BAND
}

/// The occluding boundary's pixels whose AoP is clear of its noise, each
/// with its vote's weight: the evidence `surroundings` reads.
pub(crate) fn boundary_evidence<'a>(
    input: &'a Input,
    prior: &'a ConvexityPrior,
    snr: &'a Image<f32>,
) -> impl Iterator<Item = (usize, f64)> + 'a {
    (0..input.mask.len())
        .filter(move |&i| is_clear(input, snr, i) && is_on_boundary(prior, i))
        .map(move |i| (i, aop_weight(snr.data()[i])))
}

/// Least weighted mean agreement, in `[0, 1]`, that decides a piece's sense.
const CLEAR_VOTE: f64 = 0.2;

/// Pixels within this distance of the mask's boundary vote with the
/// outward direction, [`BOUNDARY_VOTE`] times as much as the others.
const BOUNDARY_BAND: f32 = 2.0;
const BOUNDARY_VOTE: f64 = 5.0;
/// Weight of a pixel's vote by its intensity against the reflected
/// surroundings' radiance, when the view shows one: measured on
/// `b --svbrdf` and `a --svbrdf` at 512², SMSfP's mean 13.63° (1), 12.58°
/// (3), 12.61° (10) and 18.39°, 18.39°, 18.64°.
const SURROUNDINGS_VOTE: f64 = 3.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{analytic, glossy_sphere};
    use sfp_core::analytic::Shape;
    use sfp_core::fresnel::specular_dop;

    fn sphere() -> Input {
        analytic(Shape::Sphere, 64, 1.5).0
    }

    /// Pixels within `r` of the image centre.
    fn disc(input: &Input, r: f64) -> Mask {
        let (w, h) = input.size();
        Image::from_fn(w, h, |x, y| {
            let (dx, dy) = (
                x as f64 + 0.5 - w as f64 / 2.0,
                y as f64 + 0.5 - h as f64 / 2.0,
            );
            *input.mask.get(x, y) && dx.hypot(dy) < r
        })
    }

    /// The pixels of `patch` that `found` holds, asserted to be at least 90%
    /// of them.
    fn most_found(found: &Mask, patch: &Mask) -> usize {
        let hits = (0..found.len())
            .filter(|&i| found.data()[i] && patch.data()[i])
            .count();
        assert!(
            hits * 10 >= patch.count() * 9,
            "{hits} of {}",
            patch.count()
        );
        hits
    }

    #[test]
    fn off_reads_the_input_as_measured() {
        let input = sphere();
        let (out, found) = SpecularModel::Off.apply(&input, 1.5).unwrap();
        assert!(matches!(out, Cow::Borrowed(_)) && found.is_none());
    }

    #[test]
    fn auto_finds_a_turned_patch_and_leaves_a_diffuse_sphere() {
        let input = sphere();
        let (_, found) = SpecularModel::Auto.apply(&input, 1.5).unwrap();
        let found = found.unwrap();
        assert!(
            found.count() * 100 < input.mask.count(),
            "{} turned",
            found.count()
        );

        // A highlight at 31° zenith: a specular share of up to 0.6 falling
        // off smoothly, `q = (1 − f) ρ_d − f ρ_s` along the azimuth (the AoP
        // turned by 90° where it is negative, the DoP through zero around
        // it), polarized beyond what diffuse reflection can be there.
        let (_, normals) = analytic(Shape::Sphere, 64, 1.5);
        let mut glossy = input.clone();
        let mut patch = Mask::new(64, 64, false);
        for y in 0..64 {
            for x in 0..64 {
                if !*input.mask.get(x, y) {
                    continue;
                }
                let r = (x as f64 - 48.0).hypot(y as f64 - 32.0);
                let f = 0.6 * (-(r / 8.0).powi(2)).exp();
                let theta = f64::from(normals.get(x, y)[2]).clamp(-1.0, 1.0).acos();
                let q = (1.0 - f) * diffuse_dop(theta, 1.5) - f * specular_dop(theta, 1.5);
                *glossy.dop.get_mut(x, y) = q.abs() as f32;
                if q < 0.0 {
                    *patch.get_mut(x, y) = true;
                    let turned = wrap(f64::from(*input.aop.get(x, y)) + FRAC_PI_2);
                    *glossy.aop.get_mut(x, y) = turned as f32;
                }
            }
        }
        assert!(patch.count() > 100, "{} turned pixels", patch.count());
        let (out, found) = SpecularModel::Auto.apply(&glossy, 1.5).unwrap();
        let found = found.unwrap();
        let hits = most_found(&found, &patch);
        assert!(found.count() <= patch.count() + input.mask.count() / 100);
        // The turned patch reads as the diffuse sphere again.
        let restored = (0..found.len())
            .filter(|&i| patch.data()[i])
            .filter(|&i| (out.aop.data()[i] - input.aop.data()[i]).abs() < 1e-4)
            .count();
        assert_eq!(restored, hits);
    }

    #[test]
    fn auto_turns_a_glossy_sphere_where_it_is_darker_than_its_surroundings() {
        let (input, surroundings) = glossy_sphere(64, 0.1);
        let (_, found) = SpecularModel::Auto.apply(&input, 1.5).unwrap();
        let found = found.unwrap();
        let lit = (0..input.mask.len()).filter(|&i| input.mask.data()[i] && !input.unlit.data()[i]);
        let (mut right, mut all) = (0, 0);
        for i in lit {
            all += 1;
            right += usize::from(found.data()[i] == (input.intensity.data()[i] < surroundings));
        }
        assert!(right * 100 >= all * 95, "{right} of {all}");
    }

    #[test]
    fn a_disagreeing_surface_alone_turns_no_piece() {
        // A diffuse sphere with a patch at 40° zenith cut off as its own piece
        // by a ring without polarization, and a surface turned by 90° there.
        let (mut input, mut normals) = analytic(Shape::Sphere, 64, 1.5);
        let from_patch = |i: usize| ((i % 64) as f64 - 52.0).hypot((i / 64) as f64 - 32.0);
        let patch = Image::from_fn(64, 64, |x, y| from_patch(y * 64 + x) < 5.0);
        for i in 0..input.mask.len() {
            let r = from_patch(i);
            if r < 5.0 {
                let [x, y, z] = normals.data()[i];
                normals.data_mut()[i] = [-y, x, z];
            } else if r < 7.0 {
                input.dop.data_mut()[i] = 0.0;
            }
        }
        let prior = convexity_prior(&input.mask, DEFAULT_EXPONENT);
        let found = turned(&input, &normals, &prior, 1.5);
        assert_eq!(found.count(), 0);
        // One pixel polarized beyond what diffuse light can be there: the
        // surface's vote now decides the piece.
        *input.dop.get_mut(52, 32) = 0.5;
        let found = turned(&input, &normals, &prior, 1.5);
        assert_eq!(most_found(&found, &patch), found.count());
    }

    #[test]
    fn a_mask_names_its_file_and_turns_its_white_pixels() {
        let input = sphere();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("spec.png");
        let patch = disc(&input, 8.0);
        io::write_png8(&path, &patch.map(|&p| if p { 255 } else { 0 })).unwrap();
        let model = SpecularModel::Mask(path.display().to_string());
        let (out, found) = model.apply(&input, 1.5).unwrap();
        assert_eq!(found.unwrap(), patch);
        for i in 0..patch.len() {
            let turned = (out.aop.data()[i] - input.aop.data()[i]).abs() > 1e-3;
            assert_eq!(turned, patch.data()[i], "pixel {i}");
            assert_eq!(out.dark.data()[i], input.dark.data()[i] || patch.data()[i]);
        }
        let small = dir.path().join("small.png");
        io::write_png8(&small, &Image::new(8, 8, 0u8)).unwrap();
        let err = SpecularModel::Mask(small.display().to_string())
            .apply(&input, 1.5)
            .unwrap_err()
            .to_string();
        assert!(err.contains("small.png") && err.contains("8×8"), "{err}");
    }

    #[test]
    fn a_mask_below_full_scale_reads_as_drawn_and_an_empty_one_warns() {
        let input = sphere();
        let dir = tempfile::tempdir().unwrap();
        let patch = disc(&input, 8.0);
        let read = |name: &str| {
            let model = SpecularModel::Mask(dir.path().join(name).display().to_string());
            let pass = model.pass(&input, 1.5).unwrap();
            (pass.turned.clone().unwrap(), pass.warnings())
        };
        for white in [1u8, 127] {
            let name = format!("white{white}.png");
            let drawn = patch.map(|&p| if p { white } else { 0 });
            io::write_png8(&dir.path().join(&name), &drawn).unwrap();
            assert_eq!(read(&name), (patch.clone(), Vec::new()), "white {white}");
        }
        io::write_png16(
            &dir.path().join("deep.png"),
            &patch.map(|&p| if p { 255 } else { 0 }),
        )
        .unwrap();
        assert_eq!(read("deep.png"), (patch.clone(), Vec::new()));
        io::write_png8(&dir.path().join("none.png"), &patch.map(|_| 0)).unwrap();
        let (none, warnings) = read("none.png");
        assert_eq!(none.count(), 0);
        assert!(
            warnings.len() == 1 && warnings[0].contains("none.png"),
            "{warnings:?}"
        );
    }

    #[test]
    fn the_option_reads_and_writes_its_three_forms() {
        for (text, model) in [
            ("\"off\"", SpecularModel::Off),
            ("\"auto\"", SpecularModel::Auto),
            ("\"m.png\"", SpecularModel::Mask("m.png".into())),
        ] {
            let parsed: SpecularModel = serde_json::from_str(text).unwrap();
            assert_eq!(parsed, model);
            assert_eq!(serde_json::to_string(&model).unwrap(), text);
        }
        assert!(serde_json::from_str::<SpecularModel>("\"\"").is_err());
    }
}
