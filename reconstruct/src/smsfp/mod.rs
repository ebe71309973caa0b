//! SMSfP: segmentation-based monocular shape from polarization (the seed
//! paper, §4, Algorithm 1, Eqs. 13–26). The method the toolkit exists for.
//!
//! # Pipeline
//! 1. **Input** `I_un`, `ρ`, `ψ` (conventions.md §2); light estimated once
//!    on the whole mask by the shared estimator (`light`).
//! 2. **Refractive index.** The paper starts from `η = 1.15` and refines it
//!    with Eq. 19. From 1.15 every DoP above `ρ_d(90°, 1.15) ≈ 0.139` clamps
//!    to a grazing zenith, so a first solve at 1.15 has little to refine
//!    from. We start the refinement where shading and polarization agree
//!    instead: with the zeniths `θ(ρ, η)` the light fit's residual is zero at
//!    the true `η`, so `η` is the minimiser of that residual over
//!    `[ETA_SEARCH]` (a 0.05 grid on a subsample of pixels whose DoP stands
//!    above its noise, then a golden-section search). Two shading laws are
//!    tried and the one with the smaller residual kept (`run.json`,
//!    `eta.shading`): Lambert's `I = a + n·L` (the paper's Eq. 11; exact on
//!    the analytic views) and the diffuse model of conventions.md §3, which
//!    weights it by the Fresnel transmissions in and out and adds a fill
//!    light transmitted out. On the path-traced sphere Lambert finds
//!    η = 1.25 / 1.39 / 1.61 for 1.3 / 1.5 / 1.8, the diffuse model
//!    1.299 / 1.500 / 1.803. `eta` is where the search would stay without
//!    refinement (`refine = false`: `η = eta` everywhere, the paper's
//!    constant).
//! 3. **PARG** segmentation (`parg`, Algorithm 1, Eqs. 20–26), or one region
//!    per connected component without it.
//! 4. **Which boundaries are contours.** A region's boundary tells the
//!    convexity prior that the normal there points outward in the image
//!    plane; that holds only on an *occluding contour* of the region. Measured
//!    before this was built (shared notes): priors on every cut made
//!    per-region solves worse than one solve. An occluding contour is seen at
//!    a grazing angle, so every trusted pixel has a zenith of at least
//!    `occlusion_zenith_deg` (where the mask ends on a surface facing the
//!    camera — the edge of an open shell, a crease — the outward direction
//!    is a guess: preset-a car body, open wheel arches, 31.3° → 26.3° MAE;
//!    unlit pixels, with no zenith to judge by, are trusted on the mask's
//!    boundary). A mask-boundary pixel needs nothing more; a pixel on a cut
//!    between regions is trusted when the data show an occlusion: the AoP
//!    within `occlusion_aop_deg` of the region's outward direction there
//!    (diffuse AoP is parallel to the azimuth, which at a contour is the
//!    outward normal), and a discontinuity across the cut: the angle between
//!    the polarization normals of neighbours across it (up to the π
//!    ambiguity) at least `occlusion_jump_deg` and 3× the mean angle between
//!    neighbours on either side (a smooth surface continues across a cut
//!    with its own gradient: without this test, cuts along circles of a
//!    sphere passed as contours).
//! 5. **Selective segmentation** (beyond the paper, its Discussion asks for
//!    it): adjacent regions are merged unless at least `keep_cut_fraction`
//!    of the pixel pairs along their cut are discontinuous (step 4), so a
//!    smooth surface is solved as one piece and cuts remain only where the
//!    surface breaks (depth edges, creases). Keeping cuts from a tenth of
//!    discontinuous pairs instead of half of them: preset a 13.7° → 13.6°,
//!    b 7.6° → 7.4°, builtin 5.44° → 5.45°. `merge = false` solves every
//!    PARG region alone.
//! 6. **MFCP** (`mfcp`, Eqs. 13–17): the implicit azimuth is the region's
//!    trusted-boundary convexity prior (`prior`), fused with the measured AoP
//!    at several block scales; it replaces the prior's azimuth in the prior
//!    rows, with Smith's decaying weights `w_con` (Eq. 17).
//! 7. **Per-region solves** of the shared height-from-polarization system
//!    (`system`, Eq. 18), in parallel over regions, each on its bounding box.
//!    The convex/concave light pair is decided once for the whole object:
//!    both members are solved per region (one factorisation), their normals
//!    stitched, and the member whose stitched normals agree better with the
//!    outward directions of the mask's trusted occluding contours (step 4;
//!    the whole mask boundary when none is trusted) is kept everywhere. A
//!    boundary that only cuts the surface (an open shell's rim, a mask
//!    edge facing the camera) says nothing about the sense and outvoted
//!    the limb on a cut sphere (test
//!    `light_is_chosen_on_occluding_contours_only`: 66.5° → 1.2°).
//! 8. **Refinement** (Eq. 19): per region, `η` is fitted within `eta_band`
//!    of the whole object's by least squares on the shading law of step 2
//!    (the region's normals `n(θ(ρ, η), φ)`, `φ` the AoP in the sense of
//!    the solved surface, against `I_un`, with the object's light), and the
//!    relative albedo `α` between `I_un` and the Lambertian shading `n·L`;
//!    `θ` is recomputed (Eq. 7), the rows rebuilt and the region re-solved
//!    until the RMS height change falls below `tolerance` of the RMS height,
//!    `η` and `α` both move by less than 0.005, or `max_iterations` solves.
//!    The light's magnitude carries the albedo × irradiance, so `α` is
//!    relative to the whole object (1 = the object's mean). Eq. 19 as printed
//!    compares `ρ` with `ρ_d(θ(z), η)`; the solved zenith is smoothed by the
//!    integration, so that fit raised `η` at every pass (built-in views: 1.44
//!    → 1.55–2.5 over three passes). Unbounded, the per-region fit followed
//!    the misfits of large complex regions (preset-a camera body: 1.24 for
//!    1.5, 21.9° → 27.6° MAE; preset-a mean 16.7° unbounded, 14.9° within
//!    ±0.2, 13.7° within ±0.05, where b and builtin gain too: 7.6° and 5.4°).
//! 9. **Normals** (beyond the paper; the shared notes measured that
//!    per-pixel polarization normals are exact to 0.1–0.6° where their
//!    azimuth sense is right, while an integrated surface is smoothed and
//!    bends across self-occlusions): each pixel's normal has the measured
//!    AoP as azimuth, in the sense of the solved surface's normal, and the
//!    zenith of its DoP at the region's `η`; where the DoP is noise (below
//!    `min_dop_snr`) the solved surface's zenith, and where the pixel is
//!    unlit the solved normal. The solved surface thus decides the
//!    ambiguity region by region and fills what polarization cannot
//!    measure. `per_pixel = false` outputs the solved surfaces' normals, as
//!    the paper does (built-in demo views, 256²: torus 17.9° → 6.4° MAE,
//!    ellipsoid 5.1° → 2.2°, cup 6.1° → 4.8°).
//!    Where the solved surface takes the wrong sense (a thin strap solved
//!    together with the body it lies on), shading tells: the two senses
//!    predict intensities `α(a + (n±·L)⁺)` that differ by `2α sinθ (L_xy·φ̂)`.
//!    A pixel votes for the other sense when its intensity misses the kept
//!    sense's prediction by more than `shading_sense` times the light fit's
//!    RMS residual (the shading model's own error; at least 3 noise σ) and
//!    the other sense's by less than half that miss; it is flipped when most
//!    measured pixels of its 5×5 window vote so, since a wrong sense of a
//!    smooth solve comes in patches while lone votes are noise or model
//!    error. Only pixels seen at zenith ≤ 65° vote: beyond, the outgoing
//!    Fresnel transmission dims the true sense below Lambert's prediction
//!    (shipped presets, MAE: a 12.91° → 12.07°, b 7.43° → 6.90°, built-in
//!    5.45° → 5.38°; over 120 harder sweep rows at 192² mean −0.05°, 13
//!    better, 4 worse by at most 0.20°, none changed under heavy shot
//!    noise; without the zenith limit the noise-free path-traced sphere
//!    lost 0.08° at the limb).
//! 10. **Stitching**: the regions' normals are put together and filtered by
//!     a guided filter (He et al.) with guide `I_un` in units of its robust
//!     maximum, radius `filter_radius`, `ε = filter_eps`, over the whole mask
//!     (the paper smooths the region seams only; over the whole mask the same
//!     filter also averages the per-pixel noise while keeping intensity
//!     edges: occlusions and shadow lines). Radius 2–5 and `ε` 10⁻³–10⁻¹
//!     changed the mean MAE of the built-in views by less than 0.4°.
//!     `height.exr` integrates the stitched normals over each connected
//!     component of the mask (`integrate`).
//!
//! # Parameters (defaults)
//! `eta = 1.15` (paper), `lambda = 0.1`, `light = estimate`, `seed = 0`,
//! `prior_exponent = 5`, `parg = true` (with `parg_params`), `mfcp = true`
//! (with `mfcp_params`), `refine = true`, `eta_band = 0.05`,
//! `max_iterations = 4`,
//! `tolerance = 0.01`, `guided_filter = true`, `filter_radius = 3`,
//! `filter_eps = 0.01`, `merge = true`, `keep_cut_fraction = 0.1`,
//! `occlusion_zenith_deg = 60`,
//! `occlusion_aop_deg = 25`, `occlusion_jump_deg = 10`, `min_dop_snr = 3`, `per_pixel = true`,
//! `segment_smoothing = 1` (PARG reads the DoP and AoP of Stokes vectors
//! averaged over a 3×3 window, twice: on single noisy pixels it stopped
//! growing everywhere, 9,033 seeds on the built-in torus instead of 1,112;
//! a 5×5 window (421 seeds) blurred the torus' inner rim into the regions
//! on either side). The paper's initial albedo 0.8 is folded into
//! the estimated light with the irradiance (it cannot be told apart from it).
//!
//! # Fallbacks (no panic on any input)
//! A light the lit pixels cannot determine (every AoP equal: the normals
//! span no light) is replaced by a frontal light of fitted intensity
//! (`frontal_fallback` in `run.json`); a region with no trusted boundary
//! has no prior (weight 0); a one-pixel
//! region gets the normal of its height (`[0, 0, 1]`); an all-equal AoP
//! gives one PARG region per component; DoP at or above the model maximum
//! clamps to a grazing zenith (counted); the `η` fit is confined to
//! `[ETA_SEARCH]`; a region with too few lit pixels to fit `η` or `α`
//! keeps the values it has.

pub mod guided_filter;
pub mod mfcp;
pub mod parg;

use crate::domain::Domain;
use crate::guided_filter::{filter_normals, guided_filter};
use crate::input::Input;
use crate::integrate::height_from_normals;
use crate::light::{LightEstimate, LightSource, Lighting, Sample};
use crate::lsq::Solver;
use crate::method::{Ablation, About, Declared, Method, Picture, Reconstruction, validate_eta};
use crate::method_record::MethodRecord;
use crate::mfcp::{MfcpParams, mfcp};
use crate::noise::{StokesNoise, dop_snr, normal_noise, stokes_noise};
use crate::normal::zenith_azimuth_normal;
use crate::options::Options;
use crate::ordering::Ordering;
use crate::parg::{PargParams, labels_png, segment, segments_preview};
use crate::prior::{ConvexityPrior, DEFAULT_EXPONENT, convexity_prior, convexity_prior_trusted};
use crate::regions::{OUTSIDE, Regions};
use crate::system::{PixelData, Solved, System, agreement_band, boundary_agreement};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::json;
use sfp_core::fresnel::{diffuse_zenith, unpolarized_transmittance};
use sfp_core::stokes::{Polarimetry, Stokes};
use sfp_core::{Error, Image, Mask, NormalMap, Result};
use std::time::Instant;

/// Range of refractive indices the search and the refinement consider.
pub const ETA_SEARCH: (f64, f64) = (1.05, 2.5);

/// Samples used for the refractive-index search (a strided subsample).
const SEARCH_SAMPLES: usize = 4_000;

/// Margin of a region's bounding box, so its boundary has outside pixels
/// around it (the prior needs them to see a contour).
const MARGIN: usize = 3;

/// A depth edge's zenith step across a cut is at least this many times the
/// mean step between neighbours on either side.
const JUMP_RATIO: f64 = 3.0;

/// Refinement stops without another solve when `η` and `α` move less.
const PARAMETER_STEP: f64 = 0.005;

/// The shading check of step 9 stays where Lambert's law is within 10% of
/// the diffuse model of conventions.md §3 for η up to 1.8: zenith ≤ 65°
/// (sin). Towards the limb the out-going Fresnel transmission dims the
/// true sense below Lambert's prediction, which would favour the wrong one.
const SHADING_SENSE_MAX_SIN: f64 = 0.906;

/// Pixels a region needs for the `η`/`α` fit.
const MIN_FIT_PIXELS: usize = 200;

/// The SMSfP method with its parameters (module doc).
#[derive(Clone, Debug, Serialize, Deserialize, Options)]
#[serde(default, deny_unknown_fields)]
pub struct Smsfp {
    /// Initial refractive index (paper: 1.15); the constant one without
    /// refinement.
    pub eta: f64,
    /// Laplacian smoothness weight `λ`.
    pub lambda: f64,
    /// The light: `"estimate"`, `"estimate_ambient"`, `{ direction = [x, y,
    /// z] }` (intensity estimated) or `{ known = { light = [x, y, z], albedo
    /// = a } }`.
    pub light: LightSource,
    /// Seed of the light estimator's starting lights.
    pub seed: u64,
    /// Exponent of the prior's distance weight `w_con`.
    pub prior_exponent: f64,
    /// Segment with PARG (step 3); `false`: one region per connected
    /// component.
    pub parg: bool,
    /// PARG's parameters (`parg::PargParams`).
    pub parg_params: PargParams,
    /// Fuse the measured AoP into the prior's azimuth with MFCP (step 6).
    pub mfcp: bool,
    /// MFCP's parameters (`mfcp::MfcpParams`).
    pub mfcp_params: MfcpParams,
    /// Refine `η` and the albedo per region (step 8); `false`: `η = eta`
    /// everywhere.
    pub refine: bool,
    /// A region's refined `η` stays within this of the whole object's.
    pub eta_band: f64,
    /// Most solves of a region during refinement.
    pub max_iterations: usize,
    /// Refinement stops when the RMS height change falls below this
    /// fraction of the RMS height.
    pub tolerance: f64,
    /// Filter the stitched normals with a guided filter (step 10).
    pub guided_filter: bool,
    /// Radius of the guided filter.
    pub filter_radius: usize,
    /// Regularisation `ε` of the guided filter.
    pub filter_eps: f64,
    /// Per-pixel normal noise (degrees) at which raw and filtered normals
    /// are weighted equally (step 10).
    pub filter_noise_deg: f64,
    /// Merge adjacent regions where the surface continues across their cut
    /// (step 5); `false`: solve every PARG region alone.
    pub merge: bool,
    /// Least zenith (degrees) of a pixel trusted as an occluding contour
    /// (step 4).
    pub occlusion_zenith_deg: f64,
    /// Largest angle (degrees) between the AoP and the region's outward
    /// direction on a cut trusted as a contour (step 4).
    pub occlusion_aop_deg: f64,
    /// Least zenith step from a pixel on the occluding side of an internal
    /// contour to its neighbour across it (and at least `JUMP_RATIO` times
    /// the mean step between neighbours on either side in a 5×5 window).
    pub occlusion_jump_deg: f64,
    /// A cut between two PARG regions is kept when at least this fraction
    /// of its pixel pairs is discontinuous (step 5).
    pub keep_cut_fraction: f64,
    /// The `η` search and fit use only pixels whose DoP is at least this many
    /// times its noise (`noise::dop_snr`).
    pub min_dop_snr: f64,
    /// Output the per-pixel polarization normals disambiguated by the
    /// solved surface (step 9), not the solved surface's own normals.
    pub per_pixel: bool,
    /// Radius of the Stokes averaging before segmentation (0: none).
    pub segment_smoothing: usize,
    /// Per-pixel sense from shading: flip a pixel's azimuth when the other
    /// sense explains its intensity better by this many times the light
    /// fit's RMS residual (0: off).
    pub shading_sense: f64,
    /// Fill-reducing ordering of the sparse solves: `"nested_dissection"`
    /// or `"amd"`.
    pub ordering: Ordering,
}

impl Declared for Smsfp {
    const ABOUT: About = About {
        name: "smsfp",
        display: "SMSfP",
        paper: "the SMSfP paper: segmentation-based monocular shape from polarization \
                (§4, Algorithm 1, Eqs. 13–26)",
        ablations: &[
            Ablation {
                option: "parg",
                step: "PARG",
            },
            Ablation {
                option: "mfcp",
                step: "MFCP",
            },
            Ablation {
                option: "refine",
                step: "refine",
            },
            Ablation {
                option: "guided_filter",
                step: "guided filter",
            },
            Ablation {
                option: "merge",
                step: "merge",
            },
            Ablation {
                option: "per_pixel",
                step: "per pixel",
            },
            Ablation {
                option: "shading_sense",
                step: "shading sense",
            },
        ],
    };
}

impl Default for Smsfp {
    fn default() -> Self {
        Smsfp {
            eta: 1.15,
            lambda: 0.1,
            light: LightSource::Estimate,
            seed: 0,
            prior_exponent: DEFAULT_EXPONENT,
            parg: true,
            parg_params: PargParams::default(),
            mfcp: true,
            mfcp_params: MfcpParams::default(),
            refine: true,
            eta_band: 0.05,
            max_iterations: 4,
            tolerance: 0.01,
            guided_filter: true,
            filter_radius: 3,
            filter_eps: 0.01,
            filter_noise_deg: 2.0,
            merge: true,
            occlusion_zenith_deg: 60.0,
            occlusion_aop_deg: 25.0,
            occlusion_jump_deg: 10.0,
            keep_cut_fraction: 0.1,
            min_dop_snr: 3.0,
            per_pixel: true,
            segment_smoothing: 1,
            shading_sense: 2.0,
            ordering: Ordering::default(),
        }
    }
}

/// The refractive index where shading and polarization agree best (module
/// doc, step 2), the light fitted there, and the search curve
/// `(η, rms residual)` on the subsample.
struct EtaSearch {
    eta: f64,
    estimate: LightEstimate,
    /// The light could not be estimated: frontal fallback.
    frontal: bool,
    /// The shading law the data follow better.
    model: ShadingLaw,
    /// `(η, [Lambert, Fresnel] rms residual)` on the subsample.
    curve: Vec<(f64, [f64; 2])>,
}

/// The shading law `η` is fitted with (module doc, step 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
enum ShadingLaw {
    /// `I = a + n·L` (the paper's Eq. 11).
    Lambert = 0,
    /// The diffuse model of conventions.md §3: Lambert weighted by the
    /// Fresnel transmissions in and out, plus a fill light transmitted out.
    Fresnel = 1,
}

/// Boundary pixels of the PARG regions (module doc, steps 4–5).
struct Boundaries {
    /// Trusted occluding contours: where the convexity prior applies.
    trusted: Mask,
    /// Cut pixels where the polarization normal jumps: regions are not
    /// merged across them.
    discontinuous: Mask,
}

/// One solve region: its window of the view, its system and its state.
struct RegionState {
    /// Top-left corner of the window in the view.
    x0: usize,
    y0: usize,
    input: Input,
    /// Pixels whose DoP stands above its noise (`min_dop_snr`).
    measured: Mask,
    domain: Domain,
    prior: ConvexityPrior,
    solver: Solver,
    eta: f64,
    /// The whole object's `η` (the search's).
    eta0: f64,
    alpha: f64,
    iterations: usize,
    /// Both light candidates after the first solve, then the kept one.
    solved: Option<Solved>,
    /// Kept candidate's heights and normals.
    z: Vec<f64>,
    normals: Vec<[f32; 3]>,
    /// Zenith from the DoP at the `η` of the last solve.
    theta: Image<f32>,
    clamped: usize,
    converged: bool,
}

impl Method for Smsfp {
    fn reconstruct(&self, input: &Input) -> Result<Reconstruction> {
        self.validate()?;
        let total = Instant::now();
        let (w, h) = input.size();
        let noise = stokes_noise(input);
        let snr = dop_snr(input, &noise);
        let measured = snr.map(|&v| f64::from(v) >= self.min_dop_snr);

        // 1–2. Light and initial refractive index on the whole mask.
        let start = Instant::now();
        let whole = Domain::new(&input.mask);
        let EtaSearch {
            eta: eta0,
            estimate,
            frontal,
            model,
            curve: search,
        } = if self.refine {
            self.search_eta(input, &whole, &measured)?
        } else {
            let (theta, _) = input.zenith(self.eta);
            let samples = PixelData::gather(&whole, input, &theta, None)?.light_samples();
            let (estimate, frontal) = self.light_for(&samples, input.intensity_scale)?;
            EtaSearch {
                eta: self.eta,
                estimate,
                frontal,
                model: ShadingLaw::Lambert,
                curve: Vec::new(),
            }
        };
        let seconds_light = start.elapsed().as_secs_f64();

        // 3–5. Segmentation, contour evidence, selective merging.
        let start = Instant::now();
        let (theta0, _) = input.zenith(eta0);
        let segments = if self.parg {
            let (dop, aop) = smoothed_polarization(input, self.segment_smoothing);
            let seg = segment(&dop, &aop, &input.mask, &self.parg_params)?;
            Some(seg)
        } else {
            None
        };
        let parg_regions = match &segments {
            Some(seg) => {
                Regions::from_labels(seg.labels.map(|&l| if l == 0 { OUTSIDE } else { l - 1 }))
            }
            None => Regions::components(&input.mask),
        };
        let Boundaries {
            trusted,
            discontinuous,
        } = self.boundaries(input, &theta0, &parg_regions.labels);
        let regions = if self.merge {
            merge_across_cuts(
                &parg_regions,
                &input.mask,
                &discontinuous,
                self.keep_cut_fraction,
            )
        } else {
            parg_regions
        };
        let seconds_segmentation = start.elapsed().as_secs_f64();

        // 6. Per-region windows, trusted-boundary priors and MFCP.
        let start = Instant::now();
        let mut states: Vec<RegionState> = regions
            .list
            .par_iter()
            .enumerate()
            .map(|(label, region)| {
                let (x0, y0, rw, rh) = region.bbox_with_margin(MARGIN, w, h);
                let own = regions
                    .labels
                    .crop(x0, y0, rw, rh)
                    .map(|&l| l == label as u32);
                let crop = input.crop((x0, y0, rw, rh), &own);
                let trusted = trusted.crop(x0, y0, rw, rh);
                let mut prior =
                    convexity_prior_trusted(&crop.mask, self.prior_exponent, |x, y, _| {
                        *trusted.get(x, y)
                    });
                if self.mfcp {
                    // Unlit pixels have no AoP to take detail from.
                    let lit = Image::from_fn(rw, rh, |x, y| {
                        *crop.mask.get(x, y) && !*crop.unlit.get(x, y)
                    });
                    let fused = mfcp(&prior.azimuth, &crop.aop, &lit, &self.mfcp_params);
                    prior.azimuth = measured_sense(&prior.azimuth, &fused.azimuth, &crop);
                }
                let domain = Domain::new(&crop.mask);
                RegionState {
                    x0,
                    y0,
                    measured: measured.crop(x0, y0, rw, rh),
                    input: crop,
                    domain,
                    prior,
                    solver: Solver::new(self.ordering),
                    eta: eta0,
                    eta0,
                    alpha: 1.0,
                    iterations: 0,
                    solved: None,
                    z: Vec::new(),
                    normals: Vec::new(),
                    theta: Image::new(0, 0, 0.0),
                    clamped: 0,
                    converged: false,
                }
            })
            .collect();
        let seconds_mfcp = start.elapsed().as_secs_f64();

        // 7. First solves with both light candidates, one choice for all.
        let start = Instant::now();
        let ambiguous = self.light.is_ambiguous() && !frontal;
        let lighting = estimate.lighting;
        states
            .par_iter_mut()
            .try_for_each(|s| self.solve_region(s, &lighting, ambiguous))?;
        let mut scores = Vec::new();
        let chosen = if ambiguous {
            let contour = convexity_prior_trusted(&input.mask, self.prior_exponent, |x, y, _| {
                *trusted.get(x, y)
            });
            let prior = if contour.weight.data().iter().any(|&w| w > 0.0) {
                contour
            } else {
                convexity_prior(&input.mask, self.prior_exponent)
            };
            let band = agreement_band(&whole, &prior);
            for c in 0..2 {
                let normals = stitch(&states, w, h, |s| {
                    &s.solved.as_ref().expect("solved").candidates[c].normals
                });
                scores.push(boundary_agreement(
                    &whole,
                    &whole.gather(&normals),
                    &prior,
                    band,
                ));
            }
            usize::from(scores[1] > scores[0])
        } else {
            0
        };
        let lighting = if chosen == 1 {
            lighting.flipped()
        } else {
            lighting
        };
        for s in &mut states {
            let kept = s
                .solved
                .take()
                .expect("solved")
                .candidates
                .swap_remove(chosen);
            s.z = kept.z;
            s.normals = kept.normals;
        }
        let seconds_solves = start.elapsed().as_secs_f64();

        // 8. Refinement of η and α per region (Eq. 19), re-solving.
        let start = Instant::now();
        if self.refine {
            states
                .par_iter_mut()
                .try_for_each(|s| self.refine_region(s, &lighting, model))?;
        }
        let seconds_refinement = start.elapsed().as_secs_f64();

        // 9. Stitching.
        let start = Instant::now();
        if self.per_pixel {
            let margin = self.shading_sense * estimate.rms_residual;
            states
                .par_iter_mut()
                .for_each(|s| polarization_normals(s, &lighting, &noise, margin));
        }
        let mut normals = stitch(&states, w, h, |s| &s.normals);
        if self.guided_filter {
            let guide = input
                .intensity
                .map(|&v| (f64::from(v) / input.intensity_scale) as f32);
            let filtered = filter_normals(
                &guide,
                &normals,
                &input.mask,
                None,
                self.filter_radius,
                self.filter_eps,
            );
            let sigma = normal_noise(input, &noise, eta0);
            let accept = self.filter_noise_deg.to_radians().powi(2);
            normals = Image::from_fn(w, h, |x, y| {
                let s2 = f64::from(*sigma.get(x, y)).powi(2);
                let t = s2 / (s2 + accept);
                let (a, b) = (normals.get(x, y), filtered.get(x, y));
                blend(a, b, t)
            });
        }
        let height = height_from_normals(&normals, &input.mask)?;
        let seconds_stitching = start.elapsed().as_secs_f64();

        let mut pictures = Vec::new();
        if let Some(seg) = &segments {
            pictures.push(Picture::Rgb(
                "segments.png",
                segments_preview(&seg.labels, &input.intensity),
            ));
            pictures.push(Picture::Gray16("labels.png", labels_png(&seg.labels)));
        }
        let solve_labels = regions
            .labels
            .map(|&l| if l == OUTSIDE { 0 } else { l + 1 });
        pictures.push(Picture::Rgb(
            "regions.png",
            segments_preview(&solve_labels, &input.intensity),
        ));

        let region_json: Vec<_> = states
            .iter()
            .map(|s| {
                json!({
                    "pixels": s.domain.len(),
                    "window": [s.x0, s.y0, s.input.size().0, s.input.size().1],
                    "eta": s.eta,
                    "alpha": s.alpha,
                    "solves": s.iterations,
                    "converged": s.converged,
                    "dop_clamped": s.clamped,
                })
            })
            .collect();
        let run = json!({
            "method": Self::ABOUT.name,
            "parameters": serde_json::to_value(self).expect("parameters serialise"),
            "light": {
                "candidates": [lighting_json(&estimate.lighting), lighting_json(&estimate.lighting.flipped())],
                "boundary_agreement": scores,
                "chosen": chosen,
                "rms_residual": estimate.rms_residual,
                "frontal_fallback": frontal,
                "intensity_scale": input.intensity_scale,
            },
            "stokes_noise": noise,
            "dop_measured_pixels": measured.count(),
            "eta": {
                "initial": eta0,
                "shading": model,
                "search": search.iter().map(|&(e, r)| json!([e, r[0], r[1]])).collect::<Vec<_>>(),
            },
            "segmentation": {
                "parg": segments.as_ref().map(|s| json!({ "regions": s.regions, "stats": s.stats })),
                "solve_regions": regions.len(),
                "trusted_boundary_pixels": trusted.count(),
                "discontinuous_boundary_pixels": discontinuous.count(),
            },
            "regions": region_json,
            "counts": {
                "pixels": input.mask.count(),
                "dark_pixels": input.dark.count(),
                "unlit_pixels": input.unlit.count(),
                "nonfinite_dropped": input.dropped_nonfinite,
            },
            "timings": {
                "light": seconds_light,
                "segmentation": seconds_segmentation,
                "mfcp": seconds_mfcp,
                "solves": seconds_solves,
                "refinement": seconds_refinement,
                "stitching": seconds_stitching,
                "total": total.elapsed().as_secs_f64(),
            },
        });
        Ok(Reconstruction {
            normals,
            height,
            run: MethodRecord::from_json(run),
            pictures,
        })
    }
}

fn lighting_json(l: &Lighting) -> serde_json::Value {
    json!({ "vector": l.vector, "direction": l.direction(), "ambient": l.ambient })
}

impl Smsfp {
    fn validate(&self) -> Result<()> {
        validate_eta(self.eta)?;
        let checks = [
            ("lambda", self.lambda >= 0.0 && self.lambda.is_finite()),
            (
                "prior_exponent",
                self.prior_exponent > 0.0 && self.prior_exponent.is_finite(),
            ),
            ("max_iterations", self.max_iterations >= 1),
            (
                "eta_band",
                self.eta_band >= 0.0 && self.eta_band.is_finite(),
            ),
            (
                "tolerance",
                self.tolerance > 0.0 && self.tolerance.is_finite(),
            ),
            ("filter_radius", self.filter_radius >= 1),
            (
                "filter_eps",
                self.filter_eps > 0.0 && self.filter_eps.is_finite(),
            ),
            (
                "occlusion_zenith_deg",
                (0.0..=90.0).contains(&self.occlusion_zenith_deg),
            ),
            (
                "occlusion_aop_deg",
                (0.0..=90.0).contains(&self.occlusion_aop_deg),
            ),
            (
                "occlusion_jump_deg",
                (0.0..=90.0).contains(&self.occlusion_jump_deg),
            ),
            (
                "keep_cut_fraction",
                (0.0..=1.0).contains(&self.keep_cut_fraction),
            ),
            (
                "min_dop_snr",
                self.min_dop_snr >= 0.0 && self.min_dop_snr.is_finite(),
            ),
            // 0 would weigh noise-free pixels by 0/0.
            (
                "filter_noise_deg",
                self.filter_noise_deg > 0.0 && self.filter_noise_deg.is_finite(),
            ),
        ];
        for (name, ok) in checks {
            if !ok {
                return Err(Error::invalid(format!("smsfp: {name} is out of range")));
            }
        }
        Ok(())
    }

    /// Step 2 of the module doc: the `η` whose zeniths let the light fit
    /// explain the intensities best, the light fitted there, and the search
    /// curve `(η, rms residual)` on the subsample.
    fn search_eta(&self, input: &Input, whole: &Domain, measured: &Mask) -> Result<EtaSearch> {
        let (theta, _) = input.zenith(self.eta);
        let data = PixelData::gather(whole, input, &theta, None)?;
        let lit: Vec<usize> = (0..whole.len())
            .filter(|&k| {
                let (x, y) = whole.pixel(k);
                !data.dark[k] && *measured.get(x, y)
            })
            .collect();
        let stride = lit.len().div_ceil(SEARCH_SAMPLES).max(1);
        let sub: Vec<usize> = lit.iter().copied().step_by(stride).collect();
        let rho: Vec<f64> = sub
            .iter()
            .map(|&k| {
                let (x, y) = whole.pixel(k);
                f64::from(*input.dop.get(x, y))
            })
            .collect();
        // Both shading laws' residuals at `eta`, with the light fitted there.
        let residuals = |eta: f64| -> Result<[f64; 2]> {
            let samples: Vec<Sample> = sub
                .iter()
                .zip(&rho)
                .map(|(&k, &r)| Sample {
                    intensity: data.intensity[k],
                    zenith: diffuse_zenith(r, eta),
                    aop: data.aop[k],
                })
                .collect();
            let est = self.light_for(&samples, input.intensity_scale)?.0;
            Ok([
                est.rms_residual,
                fresnel_residual(&samples, &est.lighting, eta, false),
            ])
        };
        let (grid, step) = eta_grid(ETA_SEARCH);
        let curve = grid
            .into_iter()
            .map(|eta| residuals(eta).map(|r| (eta, r)))
            .collect::<Result<Vec<_>>>()?;
        // The law that explains the data better, and its best grid point.
        let minimum = |m: usize| {
            curve
                .iter()
                .map(|&(e, r)| (e, r[m]))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .expect("non-empty grid")
        };
        let model = if minimum(1).1 < minimum(0).1 {
            ShadingLaw::Fresnel
        } else {
            ShadingLaw::Lambert
        };
        let (lo, hi) = around(minimum(model as usize).0, step, ETA_SEARCH);
        let eta = golden_min(lo, hi, 20, |e| {
            residuals(e).map_or(f64::INFINITY, |r| r[model as usize])
        });
        let (theta, _) = input.zenith(eta);
        let samples = PixelData::gather(whole, input, &theta, None)?.light_samples();
        let (estimate, frontal) = self.light_for(&samples, input.intensity_scale)?;
        Ok(EtaSearch {
            eta,
            estimate,
            frontal,
            model,
            curve,
        })
    }

    /// The configured light fitted to `samples`; when the samples cannot
    /// determine it (the lit normals do not span the light, e.g. every AoP
    /// equal), a frontal light `[0, 0, 1]` of fitted intensity instead
    /// (`true`): the shading then still constrains the zenith.
    fn light_for(&self, samples: &[Sample], scale: f64) -> Result<(LightEstimate, bool)> {
        match self.light.resolve(samples, self.seed, scale) {
            Ok(est) => Ok((est, false)),
            Err(_) if self.light.is_ambiguous() => {
                let frontal = LightSource::Direction([0.0, 0.0, 1.0]);
                Ok((frontal.resolve(samples, self.seed, scale)?, true))
            }
            Err(e) => Err(e),
        }
    }

    /// The boundary analysis of the module doc, steps 4–5: which region
    /// boundary pixels are depth or orientation discontinuities, and which
    /// boundary pixels are trusted occluding contours.
    fn boundaries(&self, input: &Input, theta: &Image<f32>, labels: &Image<u32>) -> Boundaries {
        let (w, h) = input.size();
        let min_zenith = self.occlusion_zenith_deg.to_radians();
        let max_cos = self.occlusion_aop_deg.to_radians().cos();
        let min_jump = self.occlusion_jump_deg.to_radians();
        let mask = &input.mask;
        let usable = |x: usize, y: usize| *mask.get(x, y) && !*input.unlit.get(x, y);
        // Polarization normals, once for the whole image (the window tests
        // below visit each pixel many times).
        let normals = Image::from_fn(w, h, |x, y| {
            zenith_azimuth_normal(f64::from(*theta.get(x, y)), f64::from(*input.aop.get(x, y)))
        });
        let normal = |x: usize, y: usize| *normals.get(x, y);
        // Per pixel: (on the mask's boundary, discontinuous cut, outward
        // direction of its region).
        let analysis = |x: usize, y: usize| -> (bool, bool, [f64; 2]) {
            let label = *labels.get(x, y);
            let (xi, yi) = (x as isize, y as isize);
            let at = |dx: isize, dy: isize| {
                let (nx, ny) = (xi + dx, yi + dy);
                (nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h)
                    .then_some((nx as usize, ny as usize))
            };
            let (mut background, mut cut) = (false, false);
            for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                if let Some((nx, ny)) = at(dx, dy) {
                    if !*mask.get(nx, ny) {
                        background = true;
                    } else if *labels.get(nx, ny) != label {
                        cut = true;
                    }
                }
            }
            let (mut ox, mut oy) = (0.0f64, 0.0f64);
            for dy in -2..=2isize {
                for dx in -2..=2isize {
                    if let Some((nx, ny)) = at(dx, dy)
                        && *labels.get(nx, ny) != label
                    {
                        let r = ((dx * dx + dy * dy) as f64).sqrt();
                        ox += dx as f64 / r;
                        oy -= dy as f64 / r;
                    }
                }
            }
            if !cut || !usable(x, y) {
                return (background, false, [ox, oy]);
            }
            // A discontinuity is a step between the polarization normals of
            // neighbours across the cut (up to the π ambiguity) far larger
            // than the steps between neighbours on either side: a smooth
            // surface continues across a cut with its own gradient (steep
            // near a limb: 7°/px on a sphere of radius 30 px at 75°).
            let (mut cross, mut within, mut pairs) = (0.0f64, 0.0f64, 0usize);
            for dy in -2..=2isize {
                for dx in -2..=2isize {
                    let Some(p) = at(dx, dy).filter(|&(px, py)| usable(px, py)) else {
                        continue;
                    };
                    for q in [at(dx + 1, dy), at(dx, dy + 1)].into_iter().flatten() {
                        if !usable(q.0, q.1) {
                            continue;
                        }
                        let step = ambiguous_angle(normal(p.0, p.1), normal(q.0, q.1));
                        if labels.get(p.0, p.1) == labels.get(q.0, q.1) {
                            within += step;
                            pairs += 1;
                        } else if p == (x, y) || q == (x, y) {
                            cross = cross.max(step);
                        }
                    }
                }
            }
            let typical = if pairs > 0 {
                within / pairs as f64
            } else {
                0.0
            };
            (
                background,
                cross >= min_jump.max(JUMP_RATIO * typical),
                [ox, oy],
            )
        };
        let per_pixel: Vec<(bool, bool)> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if !*mask.get(x, y) {
                    return (false, false);
                }
                let (background, discontinuous, [ox, oy]) = analysis(x, y);
                // Unlit pixels have no zenith to judge by: the mask's
                // boundary is taken as a contour there, a cut is not.
                if !usable(x, y) {
                    return (background, false);
                }
                let grazing = f64::from(*theta.get(x, y)) >= min_zenith;
                let len = ox.hypot(oy);
                let psi = f64::from(*input.aop.get(x, y));
                let along =
                    len > 1e-9 && ((psi.cos() * ox + psi.sin() * oy) / len).abs() >= max_cos;
                let trusted = grazing && (background || (discontinuous && along));
                (trusted, discontinuous)
            })
            .collect();
        Boundaries {
            trusted: Image::from_vec(w, h, per_pixel.iter().map(|p| p.0).collect())
                .expect("image size"),
            discontinuous: Image::from_vec(w, h, per_pixel.iter().map(|p| p.1).collect())
                .expect("image size"),
        }
    }

    /// Solves region `s` for `lighting` (both members when `ambiguous`),
    /// with the region's current `η` and `α`.
    fn solve_region(
        &self,
        s: &mut RegionState,
        lighting: &Lighting,
        ambiguous: bool,
    ) -> Result<()> {
        let (theta, clamped) = s.input.zenith(s.eta);
        s.clamped = clamped;
        let mut data = PixelData::gather(&s.domain, &s.input, &theta, None)?;
        s.theta = theta;
        data.intensity.iter_mut().for_each(|v| *v /= s.alpha);
        let system = System {
            domain: &s.domain,
            data: &data,
            prior: &s.prior,
            lambda: self.lambda,
        };
        s.solved = Some(system.solve(&mut s.solver, lighting, ambiguous)?);
        s.iterations += 1;
        Ok(())
    }

    /// Step 8 of the module doc for one region.
    fn refine_region(
        &self,
        s: &mut RegionState,
        lighting: &Lighting,
        model: ShadingLaw,
    ) -> Result<()> {
        while s.iterations < self.max_iterations {
            let band = self.eta_band;
            let range = (
                (s.eta0 - band).max(ETA_SEARCH.0),
                (s.eta0 + band).min(ETA_SEARCH.1),
            );
            let Some((eta, alpha)) = fit_eta_alpha(s, lighting, range, model) else {
                break;
            };
            // The rows would be the same to a few parts in a thousand.
            if (eta - s.eta).abs() < PARAMETER_STEP && (alpha - s.alpha).abs() < PARAMETER_STEP {
                s.converged = true;
                break;
            }
            s.eta = eta;
            s.alpha = alpha;
            let previous = std::mem::take(&mut s.z);
            self.solve_region(s, lighting, false)?;
            let kept = s.solved.take().expect("solved").candidates.swap_remove(0);
            s.z = kept.z;
            s.normals = kept.normals;
            let (mut change, mut size) = (0.0, 0.0);
            for (a, b) in s.z.iter().zip(&previous) {
                change += (a - b) * (a - b);
                size += a * a;
            }
            if change <= self.tolerance * self.tolerance * size.max(1e-300) {
                s.converged = true;
                break;
            }
        }
        Ok(())
    }
}

/// Module doc, step 9: the per-pixel polarization normals of a solved
/// region. Azimuth: the AoP in the sense of the solved surface's normal;
/// zenith: from the DoP with the region's `η` where the DoP is measured,
/// the solved surface's where it is noise; unlit pixels keep the surface
/// normal.
fn polarization_normals(
    s: &mut RegionState,
    lighting: &Lighting,
    noise: &StokesNoise,
    margin: f64,
) {
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

/// The shading law of step 9's sense check: `α(a + (n·L)⁺)`.
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

/// DoP and AoP of the Stokes vectors averaged over the mask in a
/// `(2r+1)²` window (twice: the guided filter with a constant guide is the
/// masked box mean applied twice). PARG's features are differences between
/// neighbours; where the DoP is near the noise the AoP of single pixels is
/// noise, and growth stops at every pixel (built-in torus, 256²: 9,033 seeds
/// on the raw data). Averaging the Stokes vectors, not the angles, keeps the
/// π-periodicity right.
fn smoothed_polarization(input: &Input, radius: usize) -> (Image<f32>, Image<f32>) {
    if radius == 0 {
        return (input.dop.clone(), input.aop.clone());
    }
    let (w, h) = input.size();
    let ones = Image::new(w, h, 1.0f32);
    let stokes = |x: usize, y: usize| {
        Stokes::from_polarization(
            2.0 * f64::from(*input.intensity.get(x, y)),
            f64::from(*input.dop.get(x, y)),
            f64::from(*input.aop.get(x, y)),
        )
    };
    let averaged = |part: fn(&Stokes) -> f64| {
        let src = Image::from_fn(w, h, |x, y| part(&stokes(x, y)) as f32);
        guided_filter(&ones, &src, &input.mask, radius, 1.0)
    };
    let Polarimetry { dop, aop, .. } =
        Polarimetry::from_stokes(&[averaged(|s| s.s0), averaged(|s| s.s1), averaged(|s| s.s2)]);
    (dop, aop)
}

/// The prior azimuth of Eq. 14: the measured AoP in the half-plane the
/// fused implicit azimuth points to (`ψ` or `ψ + π`, whichever is closer),
/// or the implicit azimuth where there is no polarization signal. The
/// block mapping of MFCP bends the azimuth by up to a quarter of a block's
/// range (`γ = 0.5`); the measured AoP has no such error modulo π, so the
/// prior keeps MFCP's sense (convexity) and the measurement's direction
/// (analytic sphere 128²: 1.9° MAE with the fused azimuth itself, 0.5° with
/// this).
fn measured_sense(implicit: &Image<f32>, fused: &Image<f32>, input: &Input) -> Image<f32> {
    Image::from_fn(fused.width(), fused.height(), |x, y| {
        if !*input.mask.get(x, y) || *input.unlit.get(x, y) {
            return *implicit.get(x, y);
        }
        let f = f64::from(*fused.get(x, y));
        let (c, s) = azimuth_toward(f64::from(*input.aop.get(x, y)), [f.cos(), f.sin()]);
        s.atan2(c) as f32
    })
}

/// Eq. 19 for one region (module doc, step 8): `η` in `range` minimising
/// the residual of the shading law `model` over the region's lit pixels
/// whose DoP is measured, the normals `n(θ(ρ, η), φ)` with `φ` the AoP in
/// the sense of the solved surface's normal and the whole object's light
/// (on a 0.05 grid, then by golden section); and the relative albedo `α`
/// minimising `Σ (I_un − α n·L)²` at that `η`. `None` with too few pixels.
fn fit_eta_alpha(
    s: &RegionState,
    lighting: &Lighting,
    range: (f64, f64),
    model: ShadingLaw,
) -> Option<(f64, f64)> {
    // (intensity, ρ, cos φ, sin φ) per usable pixel.
    let mut pixels = Vec::new();
    for (k, n) in s.normals.iter().enumerate() {
        let (x, y) = s.domain.pixel(k);
        if *s.input.dark.get(x, y) || !*s.measured.get(x, y) {
            continue;
        }
        let (cp, sp) = azimuth_in_sense(f64::from(*s.input.aop.get(x, y)), n);
        pixels.push((
            f64::from(*s.input.intensity.get(x, y)) / s.input.intensity_scale,
            f64::from(*s.input.dop.get(x, y)),
            cp,
            sp,
        ));
    }
    if pixels.len() < MIN_FIT_PIXELS {
        return None;
    }
    let [lx, ly, lz] = lighting.vector;
    // Best α for `eta` and the residual sum of squares with it.
    let fit = |eta: f64| {
        let (mut num, mut den, mut ii) = (0.0, 0.0, 0.0);
        for &(i, rho, c, s) in &pixels {
            let (st, ct) = diffuse_zenith(rho, eta).sin_cos();
            let shade = lighting.ambient + st * (c * lx + s * ly) + ct * lz;
            num += i * shade;
            den += shade * shade;
            ii += i * i;
        }
        if den <= 0.0 {
            return (1.0, f64::INFINITY);
        }
        (num / den, ii - num * num / den)
    };
    let criterion = |eta: f64| match model {
        ShadingLaw::Fresnel => {
            let samples: Vec<Sample> = pixels
                .iter()
                .map(|&(i, rho, c, s)| Sample {
                    intensity: i,
                    zenith: diffuse_zenith(rho, eta),
                    aop: s.atan2(c),
                })
                .collect();
            fresnel_residual(&samples, lighting, eta, true)
        }
        ShadingLaw::Lambert => fit(eta).1,
    };
    let (grid, step) = eta_grid(range);
    let best = grid
        .into_iter()
        .map(|e| (e, criterion(e)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("non-empty grid")
        .0;
    let (lo, hi) = around(best, step, range);
    let eta = golden_min(lo, hi, 20, criterion);
    let (alpha, _) = fit(eta);
    (alpha > 0.0 && alpha.is_finite()).then_some((eta, alpha))
}

/// RMS residual of the diffuse model of conventions.md §3 with the light
/// direction `l̂` of `lighting`: `I = T(θ)/T(0) · (a + k (n·l̂)⁺ T(θ_i)/T(0))`
/// (`T` the unpolarized Fresnel transmission, `θ_i` the incidence angle, `a`
/// a fill light that enters from everywhere and leaves through `T(θ)`), `a`
/// and `k` by linear least squares alternating with each sample's choice of
/// candidate normal (± azimuth; the given azimuth when `fixed_sense`).
fn fresnel_residual(samples: &[Sample], lighting: &Lighting, eta: f64, fixed_sense: bool) -> f64 {
    let t = |c: f64| unpolarized_transmittance(c.clamp(0.0, 1.0), eta);
    let t0 = t(1.0);
    let l = lighting.direction();
    // Per sample, per candidate: (exit factor, key-light term).
    let terms: Vec<[(f64, f64); 2]> = samples
        .iter()
        .map(|s| {
            let (st, ct) = s.zenith.sin_cos();
            let (sp, cp) = s.aop.sin_cos();
            let out = t(ct) / t0;
            [1.0, -1.0].map(|sense| {
                let cos_i = sense * st * (cp * l[0] + sp * l[1]) + ct * l[2];
                (out, out * cos_i.max(0.0) * t(cos_i) / t0)
            })
        })
        .collect();
    // Alternate: candidate choice, then (a, k).
    let (mut a, mut k) = (0.0, 1.0);
    let mut sse = f64::INFINITY;
    for _ in 0..10 {
        let chosen: Vec<(f64, f64, f64)> = samples
            .iter()
            .zip(&terms)
            .map(|(s, c)| {
                let r = |(o, f): (f64, f64)| (s.intensity - a * o - k * f).abs();
                let (o, f) = if !fixed_sense && r(c[1]) < r(c[0]) {
                    c[1]
                } else {
                    c[0]
                };
                (s.intensity, o, f)
            })
            .collect();
        let (mut soo, mut sof, mut sff, mut sio, mut sif) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for &(i, o, f) in &chosen {
            soo += o * o;
            sof += o * f;
            sff += f * f;
            sio += i * o;
            sif += i * f;
        }
        let det = soo * sff - sof * sof;
        if det.abs() <= 1e-12 * soo * sff {
            break;
        }
        a = (sio * sff - sif * sof) / det;
        k = (soo * sif - sof * sio) / det;
        let next: f64 = chosen
            .iter()
            .map(|&(i, o, f)| (i - a * o - k * f).powi(2))
            .sum();
        let done = (sse - next).abs() <= 1e-12 * next.max(1e-300);
        sse = next;
        if done {
            break;
        }
    }
    (sse / samples.len().max(1) as f64).sqrt()
}

/// `(cos φ, sin φ)` of the azimuth `φ ∈ {ψ, ψ + π}` on the side of the
/// image-plane direction `d`: the AoP resolved by a sense from elsewhere
/// (a solved normal's projection, a prior's azimuth).
fn azimuth_toward(psi: f64, d: [f64; 2]) -> (f64, f64) {
    let (sp, cp) = psi.sin_cos();
    if d[0] * cp + d[1] * sp >= 0.0 {
        (cp, sp)
    } else {
        (-cp, -sp)
    }
}

/// The AoP in the sense of the normal `n`'s projection.
fn azimuth_in_sense(psi: f64, n: &[f32; 3]) -> (f64, f64) {
    azimuth_toward(psi, [f64::from(n[0]), f64::from(n[1])])
}

/// Angle between `a` and the nearer of `b` and its azimuth-flipped twin
/// `(−b_x, −b_y, b_z)`: how far apart two polarization normals are whatever
/// the π ambiguity.
fn ambiguous_angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let planar = (a[0] * b[0] + a[1] * b[1]).abs();
    (planar + a[2] * b[2]).clamp(-1.0, 1.0).acos()
}

/// `(1 − t) a + t b`, renormalised (`a` where the sum vanishes; zero stays
/// zero outside the mask).
fn blend(a: &[f32; 3], b: &[f32; 3], t: f64) -> [f32; 3] {
    let v: [f64; 3] = std::array::from_fn(|i| (1.0 - t) * f64::from(a[i]) + t * f64::from(b[i]));
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len > 1e-9 {
        v.map(|c| (c / len) as f32)
    } else {
        *a
    }
}

/// Refractive indices every ~0.05 across `range` (both ends included) and
/// their spacing: where the searches for `η` look before refining.
fn eta_grid(range: (f64, f64)) -> (Vec<f64>, f64) {
    let steps = ((range.1 - range.0) / 0.05).round().max(1.0) as usize;
    let step = (range.1 - range.0) / steps as f64;
    (
        (0..=steps).map(|i| range.0 + step * i as f64).collect(),
        step,
    )
}

/// One grid step either side of `best`, within `range`: where the golden
/// section refines a grid minimum.
fn around(best: f64, step: f64, range: (f64, f64)) -> (f64, f64) {
    ((best - step).max(range.0), (best + step).min(range.1))
}

/// Minimiser of `f` on `[lo, hi]` by golden-section search (`f` assumed
/// unimodal there), after `steps` reductions.
fn golden_min(lo: f64, hi: f64, steps: usize, f: impl Fn(f64) -> f64) -> f64 {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..steps {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    (a + b) / 2.0
}

/// The regions' normals (as chosen by `normals`) in one `w × h` map.
fn stitch<'a>(
    states: &'a [RegionState],
    w: usize,
    h: usize,
    normals: impl Fn(&'a RegionState) -> &'a Vec<[f32; 3]>,
) -> NormalMap {
    let mut out = Image::new(w, h, [0.0f32; 3]);
    for s in states {
        for (k, n) in normals(s).iter().enumerate() {
            let (x, y) = s.domain.pixel(k);
            *out.get_mut(s.x0 + x, s.y0 + y) = *n;
        }
    }
    out
}

/// Selective segmentation (module doc, step 5): merges adjacent regions
/// unless at least `keep_fraction` of the pixel pairs along their shared
/// boundary have a discontinuous pixel; the result is relabelled in raster
/// order.
fn merge_across_cuts(
    regions: &Regions,
    mask: &Mask,
    discontinuous: &Mask,
    keep_fraction: f64,
) -> Regions {
    let (w, h) = mask.size();
    let labels = &regions.labels;
    let n = regions.len();
    // Per adjacent pair (low label, high label): [boundary pixels, trusted].
    let mut pairs: std::collections::BTreeMap<(u32, u32), [usize; 2]> = Default::default();
    for y in 0..h {
        for x in 0..w {
            let a = *labels.get(x, y);
            if a == OUTSIDE {
                continue;
            }
            for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                if nx >= w || ny >= h {
                    continue;
                }
                let b = *labels.get(nx, ny);
                if b == OUTSIDE || b == a {
                    continue;
                }
                let entry = pairs.entry((a.min(b), a.max(b))).or_default();
                entry[0] += 1;
                entry[1] += usize::from(*discontinuous.get(x, y) || *discontinuous.get(nx, ny));
            }
        }
    }
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut k: u32) -> u32 {
        while parent[k as usize] != k {
            parent[k as usize] = parent[parent[k as usize] as usize];
            k = parent[k as usize];
        }
        k
    }
    for (&(a, b), &[count, jumps]) in &pairs {
        if (jumps as f64) < keep_fraction * count as f64 {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    // Relabel roots in raster order of their first pixel.
    let mut new_label = vec![OUTSIDE; n];
    let mut next = 0u32;
    let merged = Image::from_vec(
        w,
        h,
        labels
            .data()
            .iter()
            .map(|&l| {
                if l == OUTSIDE {
                    return OUTSIDE;
                }
                let root = find(&mut parent, l) as usize;
                if new_label[root] == OUTSIDE {
                    new_label[root] = next;
                    next += 1;
                }
                new_label[root]
            })
            .collect(),
    )
    .expect("same size");
    Regions::from_labels(merged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::smith::Smith;
    use sfp_core::analytic::{AnalyticScene, Shape};
    use sfp_core::metrics::evaluate;
    use sfp_core::stokes::Polarimetry;

    const LIGHT: [f64; 3] = [0.35, 0.25, 0.9];

    fn analytic(shape: Shape, size: usize, eta: f64) -> (Input, NormalMap) {
        let view = AnalyticScene {
            shape,
            size,
            eta,
            albedo: 0.8,
            light: LIGHT,
        }
        .render()
        .unwrap();
        let input = Input::from_view(&view.input).unwrap();
        (input, view.gt.unwrap().normals)
    }

    fn mae(method: &dyn Method, input: &Input, gt: &NormalMap) -> (f64, Reconstruction) {
        let rec = method.reconstruct(input).unwrap();
        let m = evaluate(&rec.normals, gt, &input.mask).unwrap();
        assert_eq!(m.missing, 0);
        (m.mae_deg, rec)
    }

    #[test]
    fn analytic_shapes_are_no_worse_than_smith() {
        for shape in [Shape::Sphere, Shape::Blobs] {
            let (input, gt) = analytic(shape, 128, 1.5);
            let (ours, _) = mae(&Smsfp::default(), &input, &gt);
            let (smith, _) = mae(&Smith::default(), &input, &gt);
            println!("{shape:?} 128²: smsfp {ours:.3}°, smith {smith:.3}°");
            assert!(
                ours <= smith + 0.5,
                "{shape:?}: smsfp {ours}° vs smith {smith}°"
            );
        }
    }

    #[test]
    fn refractive_index_is_found_from_the_papers_start() {
        for truth in [1.3, 1.5, 1.8] {
            let (input, gt) = analytic(Shape::Sphere, 96, truth);
            let (err, rec) = mae(&Smsfp::default(), &input, &gt);
            let initial = rec.run.own["eta"]["initial"].as_f64().unwrap();
            for region in rec.run.own["regions"].as_array().unwrap() {
                let eta = region["eta"].as_f64().unwrap();
                assert!((eta - truth).abs() < 0.05, "true η {truth}: region η {eta}");
            }
            println!("η {truth}: found {initial:.4}, MAE {err:.3}°");
            assert!(
                (initial - truth).abs() < 0.05 && err < 1.0,
                "η {truth}: {initial}, {err}°"
            );
        }
    }

    #[test]
    fn refractive_index_under_fresnel_weighted_shading() {
        // The analytic sphere's Lambertian intensity weighted as the diffuse
        // model of conventions.md §3 (and the renderer) weights it: by the
        // Fresnel transmissions in and out. A Lambertian search finds a
        // biased η here (path-traced sphere: 1.39 for 1.5); the search must
        // pick the Fresnel law and the true η.
        let t = |c: f64, eta: f64| unpolarized_transmittance(c.clamp(0.0, 1.0), eta);
        let norm = LIGHT.iter().map(|v| v * v).sum::<f64>().sqrt();
        for truth in [1.3, 1.5, 1.8] {
            let (input, gt) = analytic(Shape::Sphere, 96, truth);
            let intensity = Image::from_fn(96, 96, |x, y| {
                let n = gt.get(x, y).map(f64::from);
                let cos_i = (n[0] * LIGHT[0] + n[1] * LIGHT[1] + n[2] * LIGHT[2]) / norm;
                let weight = t(cos_i, truth) * t(n[2], truth) / t(1.0, truth).powi(2);
                (f64::from(*input.intensity.get(x, y)) * weight) as f32
            });
            let pol = Polarimetry {
                intensity,
                dop: input.dop.clone(),
                aop: input.aop.clone(),
            };
            let input = Input::new(pol, Some(input.mask.clone())).unwrap();
            let (err, rec) = mae(&Smsfp::default(), &input, &gt);
            let found = rec.run.own["eta"]["initial"].as_f64().unwrap();
            println!("Fresnel-weighted η {truth}: found {found:.4}, MAE {err:.3}°");
            assert_eq!(rec.run.own["eta"]["shading"], "fresnel");
            assert!(
                (found - truth).abs() < 0.02 && err < 1.0,
                "η {truth}: {found}, {err}°"
            );
        }
    }

    #[test]
    fn every_ablation_runs_and_stays_close_on_the_sphere() {
        let (input, gt) = analytic(Shape::Sphere, 64, 1.5);
        let off: [fn(&mut Smsfp); 7] = [
            |m| m.parg = false,
            |m| m.mfcp = false,
            |m| m.refine = false,
            |m| m.guided_filter = false,
            |m| m.merge = false,
            |m| m.per_pixel = false,
            |m| m.segment_smoothing = 0,
        ];
        for (i, switch) in off.iter().enumerate() {
            let mut method = Smsfp::default();
            switch(&mut method);
            let (err, _) = mae(&method, &input, &gt);
            // refine = false keeps the paper's η = 1.15 on data made with
            // 1.5: zeniths are far off, but the normals stay finite.
            let bound = if method.refine { 3.0 } else { 30.0 };
            assert!(err < bound, "ablation {i}: MAE {err}°");
        }
    }

    #[test]
    fn light_is_chosen_on_occluding_contours_only() {
        // The right part of a sphere, cut along n_x = 0.5: the cut is mask
        // boundary but no occluding contour (zenith 30° there), and its
        // outward direction opposes the normals. Only the limb may vote.
        let (full, gt) = analytic(Shape::Sphere, 96, 1.5);
        let mask = Mask::from_fn(96, 96, |x, y| {
            *full.mask.get(x, y) && gt.get(x, y)[0] >= 0.5
        });
        let pol = Polarimetry {
            intensity: full.intensity.clone(),
            dop: full.dop.clone(),
            aop: full.aop.clone(),
        };
        let input = Input::new(pol, Some(mask)).unwrap();
        let rec = Smsfp::default().reconstruct(&input).unwrap();
        let light = rec.run.light.unwrap();
        let (chosen, scores) = (light.chosen, light.boundary_agreement.unwrap());
        let m = evaluate(&rec.normals, &gt, &input.mask).unwrap();
        println!("scores {scores:?}, chosen {chosen}, MAE {}", m.mae_deg);
        assert!(scores[chosen] > 0.7, "agreement {scores:?}");
        assert!(m.mae_deg < 2.0, "MAE {}°", m.mae_deg);
    }

    /// A sphere's polarization with the mask replaced by `mask`.
    fn sphere_with_mask(mask: impl Fn(usize, usize) -> bool) -> Input {
        let (input, _) = analytic(Shape::Sphere, 48, 1.5);
        let pol = Polarimetry {
            intensity: input.intensity.clone(),
            dop: input.dop.clone(),
            aop: input.aop.clone(),
        };
        Input::new(pol, Some(Mask::from_fn(48, 48, mask))).unwrap()
    }

    fn assert_finite(rec: &Reconstruction, mask: &Mask) {
        for (n, &m) in rec.normals.data().iter().zip(mask.data()) {
            if m {
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                assert!((len - 1.0).abs() < 1e-3 && n[2] >= 0.0, "normal {n:?}");
            } else {
                assert_eq!(*n, [0.0; 3]);
            }
        }
    }

    /// Step 9's sense check: a normal on the wrong side of a side light
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

    #[test]
    fn bad_inputs_fall_back_without_panics() {
        // A disc plus a lone pixel and a two-pixel sliver: regions of one and
        // two pixels.
        let input = sphere_with_mask(|x, y| {
            let r2 = (x as f64 - 24.0).powi(2) + (y as f64 - 24.0).powi(2);
            r2 < 100.0 || (x, y) == (40, 40) || (y == 5 && (5..7).contains(&x))
        });
        let rec = Smsfp::default().reconstruct(&input).unwrap();
        assert_finite(&rec, &input.mask);
        // The mask fills the frame: no boundary pixel at all, so no prior.
        let (full, _) = analytic(Shape::Sphere, 48, 1.5);
        let square = Input::new(
            Polarimetry {
                intensity: full.intensity.map(|&v| v.max(0.1)),
                dop: full.dop.clone(),
                aop: full.aop.clone(),
            },
            Some(Mask::from_fn(48, 48, |x, y| {
                (14..34).contains(&x) && (14..34).contains(&y)
            }))
            .map(|m| m.crop(14, 14, 20, 20)),
        );
        assert!(square.is_err(), "sizes differ: an error, not a panic");
        let inner = Input::new(
            Polarimetry {
                intensity: full.intensity.crop(14, 14, 20, 20),
                dop: full.dop.crop(14, 14, 20, 20),
                aop: full.aop.crop(14, 14, 20, 20),
            },
            None,
        )
        .unwrap();
        let rec = Smsfp::default().reconstruct(&inner).unwrap();
        assert_finite(&rec, &inner.mask);
        // All-equal AoP, and DoP at the model's maximum everywhere.
        for pol in [
            Polarimetry {
                intensity: full.intensity.clone(),
                dop: full.dop.clone(),
                aop: Image::new(48, 48, 0.7),
            },
            Polarimetry {
                intensity: full.intensity.clone(),
                dop: Image::new(48, 48, sfp_core::fresnel::diffuse_dop_max(1.15) as f32),
                aop: full.aop.clone(),
            },
        ] {
            let input = Input::new(pol, Some(full.mask.clone())).unwrap();
            let rec = Smsfp::default().reconstruct(&input);
            let rec = rec.unwrap_or_else(|e| panic!("{e}"));
            assert_finite(&rec, &input.mask);
        }
    }

    #[test]
    fn parameters_out_of_range_are_refused_by_name() {
        let (input, _) = analytic(Shape::Sphere, 32, 1.5);
        type Setter = fn(&mut Smsfp);
        let cases: [(Setter, &str); 4] = [
            (|m| m.filter_noise_deg = 0.0, "filter_noise_deg"),
            (|m| m.keep_cut_fraction = 1.5, "keep_cut_fraction"),
            (|m| m.min_dop_snr = f64::NAN, "min_dop_snr"),
            (|m| m.occlusion_jump_deg = -1.0, "occlusion_jump_deg"),
        ];
        for (set, name) in cases {
            let mut method = Smsfp::default();
            set(&mut method);
            let err = method.reconstruct(&input).unwrap_err().to_string();
            assert!(err.contains(name), "{err}");
        }
    }

    #[test]
    fn merging_joins_across_cuts_and_keeps_occlusions() {
        // Two regions side by side in one 20×10 mask.
        let mask = Mask::new(20, 10, true);
        let labels = Image::from_fn(20, 10, |x, _| u32::from(x >= 10));
        let regions = Regions::from_labels(labels);
        let none = Mask::new(20, 10, false);
        assert_eq!(merge_across_cuts(&regions, &mask, &none, 0.1).len(), 1);
        let cut = Mask::from_fn(20, 10, |x, _| x == 9);
        assert_eq!(merge_across_cuts(&regions, &mask, &cut, 0.1).len(), 2);
        // One discontinuous pixel pair of ten: kept at 0.1, merged at 0.2.
        let one = Mask::from_fn(20, 10, |x, y| x == 9 && y == 4);
        assert_eq!(merge_across_cuts(&regions, &mask, &one, 0.1).len(), 2);
        assert_eq!(merge_across_cuts(&regions, &mask, &one, 0.2).len(), 1);
    }
}
