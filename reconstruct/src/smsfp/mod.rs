//! SMSfP: segmentation-based monocular shape from polarization (the seed
//! paper, §4, Algorithm 1, Eqs. 13–26). The method the toolkit exists for.
//!
//! # Pipeline
//! [`Smsfp::reconstruct`] runs these steps in this order, one function each;
//! the doc of each step's file gives its details, the choices it makes where
//! the paper leaves them open, and what they were measured to change.
//! 1. **Input** `I_un`, `ρ`, `ψ` (conventions.md §2) and the Stokes noise
//!    fitted to it (`noise`): a pixel's DoP is *measured* where it stands at
//!    least `min_dop_snr` times above its noise.
//! 2. **Refractive index and light** (`eta`). The paper starts from
//!    `η = 1.15`; from there every DoP above 0.139 clamps to a grazing
//!    zenith. We start where shading and polarization agree instead: the `η`
//!    whose zeniths let the light fit (`light`, once on the whole mask)
//!    explain the intensities best, over [`ETA_SEARCH`], under Lambert's law
//!    (the paper's Eq. 11) or the diffuse model of conventions.md §3,
//!    whichever fits better. Under the diffuse model the light direction
//!    and `η` are then fitted with that model itself (`fresnel_fit`), on
//!    every lit pixel weighted by its zenith's noise, and the solves' light
//!    gets a fill. Without refinement `η = eta` everywhere.
//! 3. **Segmentation** (`segmentation`): PARG (`parg`, Algorithm 1,
//!    Eqs. 20–26) on Stokes vectors averaged over `segment_smoothing`
//!    pixels, or one region per connected component without it.
//! 4. **Which boundaries are contours** (`contours`): the convexity prior
//!    holds only on a region's occluding contours, so a boundary pixel is
//!    trusted when seen at a grazing zenith (on the mask's boundary, with
//!    `azimuth_noise_deg > 0`, with its AoP along or across the outward
//!    direction) and, on a cut between regions, when the AoP points across
//!    the cut and the polarization normals jump across it (a
//!    discontinuity).
//! 5. **Selective merging** (`merge`, beyond the paper, its Discussion asks
//!    for it): adjacent regions are merged unless enough of their cut is
//!    discontinuous, so a smooth surface is solved as one piece.
//! 6. **Regions and priors** (`region`, MFCP in `mfcp`, Eqs. 13–17): each
//!    region's window and its trusted-boundary convexity prior (`prior`);
//!    MFCP fuses the prior's azimuth with the measured AoP at several block
//!    scales, and the AoP in the sense of the fused azimuth replaces the
//!    prior's azimuth in the prior rows, with Smith's weights `w_con`
//!    (Eq. 17).
//!    As far as the trusted contours leave a region free, its AoP oriented
//!    by continuity (`orientation`, beyond the paper) adds the prior's
//!    zenith rows, in a sense that goes with the light's convex/concave
//!    member: a relief without contours under a light along the view is
//!    otherwise solved flat.
//! 7. **Per-region solves** (`solve`) of the shared height-from-polarization
//!    system (`system`, Eq. 18), each azimuth row weighted by its AoP's
//!    noise as far as the region's prior holds it (`region`), in parallel,
//!    with both members of the convex/concave light pair; the member whose
//!    stitched normals agree better with the trusted contours is kept for
//!    the whole object.
//! 8. **Refinement** (`refine`, Eq. 19): per region, `η` within `eta_band`
//!    of the whole object's and the relative albedo `α` are fitted to the
//!    shading law of step 2, and the region re-solved until it converges.
//! 9. **Per-pixel normals** (`sense`, beyond the paper): each pixel's normal
//!    has the measured AoP as azimuth in the sense of the solved surface and
//!    the zenith of its DoP; where shading shows the solved sense wrong in a
//!    patch, the patch is flipped.
//! 10. **Stitching** (`stitch`): the regions' normals in one map, filtered by
//!     a guided filter with guide `I_un` over the whole mask, and each pixel
//!     blended between its own and the filtered normal by its noise: the
//!     filtered one weighs `σ² / (σ² + σ_a²)`, `σ` the pixel's normal noise
//!     from the Stokes noise and `σ_a = filter_noise_deg`, so noise-free data
//!     are not blurred. `height.exr` integrates the stitched normals over each
//!     connected component of the mask (`integrate`).
//!
//! 11. **Mixed-model fit** (`specular::fit`, beyond the paper; by default
//!     where step 2's η search ends at the top of its range, `mixed_fit`):
//!     heights and each pixel's specular share fitted to the measured
//!     polarization under both reflection models and to the diffuse
//!     intensity (`specular::shading`), coarse to fine,
//!     from the occluding contour's convex surface (`dome`, default), step
//!     10's, or both (`fit_start`); between several surfaces (with
//!     `fit_keeps_own`, SMSfP's own too) the one a smooth light explains
//!     best is kept (`mixed`).
//!
//! What the steps found goes to `run.json` as an [`SmsfpRecord`] (`record`);
//! the segmentation's and regions' pictures are drawn by `pictures`.
//!
//! # Parameters
//! The fields of [`Smsfp`], each documented where it is declared; the
//! defaults are its `Default`. `sfp reconstruct --help` and the README's
//! option table list them with their defaults and meaning, generated from
//! the fields (`listing`), so the list cannot drift from the code.
//!
//! The paper's initial albedo 0.8 is folded into the estimated light with
//! the irradiance (it cannot be told apart from it).
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

mod azimuth;
mod contours;
mod eta;
mod fresnel_fit;
pub mod guided_filter;
mod merge;
pub mod mfcp;
mod mixed;
mod orientation;
mod params;
pub mod parg;
mod pictures;
pub mod record;
mod refine;
mod region;
mod segmentation;
mod sense;
mod solve;
mod stitch;

use crate::input::Input;
use crate::method::{Declared, Method, Reconstruction};
use crate::method_record::MethodRecord;
use crate::noise::{azimuth_weight, dop_snr, stokes_noise};
use crate::prior::{DEFAULT_EXPONENT, convexity_prior};
use crate::solver::domain::Domain;
use crate::specular::fit::{self, FitRecord};
use crate::specular::limb::Limb;
use crate::specular::reflected_light::CorePolarization;
use crate::specular::share::SpecularReading;
use crate::stage;
pub use eta::{ETA_SEARCH, ShadingLaw};
use eta::{EtaSearch, LightFit, ZenithNoise};
use merge::merge_across_cuts;
pub use params::Smsfp;
pub use record::SmsfpRecord;
use record::{
    Counts, EtaRecord, LightRecord, ModelRecord, RegionRecord, SegmentationRecord, Timings,
};
use region::RegionSetup;
use sfp_core::Result;
use std::time::Instant;

impl Method for Smsfp {
    /// The steps of the module doc, in order.
    fn reconstruct(&self, input: &Input) -> Result<Reconstruction> {
        self.validate()?;
        let total = Instant::now();
        let mut timings = Timings::default();
        let mut clock = Instant::now();
        let mut lap = || {
            let seconds = clock.elapsed().as_secs_f64();
            clock = Instant::now();
            seconds
        };

        // 1. Input and its noise.
        let noise = stokes_noise(input);
        let snr = dop_snr(input, &noise);
        let measured = snr.map(|&v| f64::from(v) >= self.min_dop_snr);
        let azimuth_weights = (self.azimuth_noise_deg > 0.0)
            .then(|| snr.map(|&v| azimuth_weight(f64::from(v), self.azimuth_noise_deg) as f32));

        // 2. Refractive index and light on the whole mask.
        stage::enter(if self.refine {
            "η search and light"
        } else {
            "light"
        });
        let whole = Domain::new(&input.mask);
        let light = LightFit {
            source: &self.shared.light,
            seed: self.shared.seed,
        };
        let search = if self.refine {
            EtaSearch::search(
                input,
                &whole,
                &measured,
                &ZenithNoise {
                    stokes: noise,
                    model: self.azimuth_noise_deg.to_radians(),
                },
                self.shared.eta,
                &light,
            )?
        } else {
            EtaSearch::fixed(input, &whole, self.shared.eta, &light)?
        };
        let pass = self.shared.specular.pass(input, search.eta)?;
        let measured_input = input;
        let input = pass.input();
        timings.light = lap();

        // 3. Segmentation.
        stage::enter("segmentation");
        let (segments, parg_regions) = segmentation::segment_regions(
            input,
            self.parg.then_some(&self.parg_params),
            self.segment_smoothing,
        )?;
        // 4. Which boundaries are contours.
        let (theta, _) = input.zenith(search.eta);
        let boundaries = self
            .occlusion()
            .boundaries(input, &theta, &parg_regions.labels);
        // 5. Selective merging.
        let regions = if self.merge {
            let cuts = &boundaries.discontinuous;
            merge_across_cuts(&parg_regions, &input.mask, cuts, self.keep_cut_fraction)
        } else {
            parg_regions
        };
        timings.segmentation = lap();

        // 6. Regions and their priors.
        stage::enter(&format!("priors of {} regions", regions.list.len()));
        let confidence = azimuth_weights
            .clone()
            .unwrap_or_else(|| measured.map(|&m| f32::from(u8::from(m))));
        let mut states = RegionSetup {
            input,
            trusted: &boundaries.trusted,
            measured: &measured,
            azimuth_weight: azimuth_weights.as_ref(),
            confidence: &confidence,
            lighting: &search.estimate.lighting,
            prior_exponent: self.prior_exponent,
            mfcp: self.mfcp.then_some(&self.mfcp_params),
            ordering: self.ordering,
            eta: search.eta,
        }
        .states(&regions);
        timings.mfcp = lap();

        // 7. Per-region solves and the one light for all.
        stage::enter(&format!("solving {} regions", states.len()));
        let choice = solve::solve_regions(
            &mut states,
            input,
            &boundaries.trusted,
            search.estimate.lighting,
            self.shared.light.is_ambiguous() && !search.frontal,
            self.lambda,
            self.prior_exponent,
        )?;
        timings.solves = lap();

        // 8. Refinement of η and α per region.
        if self.refine {
            stage::enter("refining η and albedo");
            self.refinement(search.model)
                .refine(&mut states, &choice.lighting)?;
        }
        timings.refinement = lap();

        // 9. Per-pixel normals.
        if self.per_pixel {
            let margin = self.shading_sense * search.estimate.rms_residual;
            sense::polarization_normals(&mut states, &choice.lighting, &noise, margin);
        }
        // 10. Stitching.
        stage::enter("stitching");
        let filter = self.guided_filter.then(|| self.filter());
        let (w, h) = input.size();
        let own = stitch::stitch(&states, w, h, |s| &s.normals);
        // The share is a per-pixel reading: from the regions' own normals,
        // before the guided filter lowers the grazing zeniths it hangs on
        // (b --svbrdf 512², azimuth_noise_deg = 10: intensity-class F1 0.52
        // filtered, 0.69 not).
        let mut specular = pass.read(&own);
        let mut normals = stitch::filtered(input, own, filter.as_ref(), &noise, search.eta);
        let mut height = stitch::height(&mut states, &normals, &input.mask)?;
        timings.stitching = lap();

        // 11. The surface fit under the mixed model.
        let prior = convexity_prior(&measured_input.mask, DEFAULT_EXPONENT);
        let limb = Limb::of(measured_input, &prior);
        let reading_eta = fit::reading_eta(self.refine, self.shared.eta);
        let core = CorePolarization::of(measured_input, &prior, &noise, reading_eta);
        let (mixed, why) =
            self.mixed_fit
                .decide(search.at_upper_end(), limb.as_ref(), core.as_ref());
        let (reflected_light, reflected_light_why) = if mixed {
            self.reflected_light.decide(core.as_ref())
        } else {
            (false, "the mixed model does not run")
        };
        let fit = if mixed {
            stage::enter("fitting the mixed model");
            let kept = mixed::mixed_fit(
                self,
                measured_input,
                &normals,
                &height,
                &noise,
                reflected_light,
            )?;
            if let Some(fitted) = kept.fit {
                normals = fitted.normals;
                height = fitted.height;
                let turned = specular.map_or_else(|| input.mask.map(|_| false), |s| s.turned);
                specular = Some(SpecularReading {
                    turned,
                    share: fitted.share,
                });
            }
            Some(kept.record)
        } else {
            None
        };
        timings.fit = lap();

        let pictures = pictures::pictures(segments.as_ref(), &regions, &input.intensity);
        timings.total = total.elapsed().as_secs_f64();
        let warnings = search
            .undetermined(fit.as_ref().map(|f| f.eta))
            .into_iter()
            .chain(pass.warnings())
            .chain(fit.iter().flat_map(FitRecord::warnings))
            .collect();
        let record = SmsfpRecord {
            method: Self::ABOUT.name.to_string(),
            light: LightRecord::new(&search, &choice, input),
            stokes_noise: noise,
            dop_measured_pixels: measured.count(),
            eta: EtaRecord::new(&search),
            segmentation: SegmentationRecord::new(segments.as_ref(), &regions, &boundaries),
            regions: states.iter().map(RegionRecord::new).collect(),
            counts: Counts::from(input),
            timings,
            model: ModelRecord {
                model: if mixed { "mixed" } else { "diffuse" }.to_string(),
                why: why.to_string(),
                limb,
                reflected_light,
                reflected_light_why: reflected_light_why.to_string(),
                core,
            },
            fit,
            warnings,
        };
        Ok(Reconstruction {
            normals,
            height,
            run: MethodRecord::from_json(serde_json::to_value(record).expect("record serialises")),
            pictures,
            specular,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::smith::Smith;
    use crate::test_support::{analytic, mae};
    use sfp_core::analytic::Shape;
    use sfp_core::stokes::Polarimetry;
    use sfp_core::{Image, Mask};

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
        let cases: [(Setter, &str); 5] = [
            (|m| m.filter_noise_deg = 0.0, "filter_noise_deg"),
            (|m| m.keep_cut_fraction = 1.5, "keep_cut_fraction"),
            (|m| m.min_dop_snr = f64::NAN, "min_dop_snr"),
            (|m| m.occlusion_jump_deg = -1.0, "occlusion_jump_deg"),
            (|m| m.azimuth_noise_deg = f64::NAN, "azimuth_noise_deg"),
        ];
        for (set, name) in cases {
            let mut method = Smsfp::default();
            set(&mut method);
            let err = method.reconstruct(&input).unwrap_err().to_string();
            assert!(err.contains(name), "{err}");
        }
    }
}
