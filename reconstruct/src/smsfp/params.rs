//! SMSfP's options: the [`Smsfp`] struct (each field documented where it
//! is declared, the defaults its `Default`), its declaration to the
//! registry, and the parameter groups it hands to its steps.

use super::contours::Occlusion;
use super::eta::ShadingLaw;
use super::mfcp::MfcpParams;
use super::parg::PargParams;
use super::refine::Refinement;
use super::stitch::Filter;
use crate::method::{Ablation, About, Declared, validate_lambda};
use crate::options::Options;
use crate::prior::DEFAULT_EXPONENT;
use crate::shared_options::SharedOptions;
use crate::solver::ordering::Ordering;
use crate::specular::fit::{FitStart, MixedFit};
use crate::specular::reflected_light::ReflectedLight;
use crate::switch::flag_or_name;
use serde::{Deserialize, Serialize};
use sfp_core::{Error, Result};

/// The SMSfP method with its parameters (module doc).
#[derive(Clone, Debug, Serialize, Deserialize, Options)]
#[serde(default, deny_unknown_fields)]
pub struct Smsfp {
    /// `eta` (the search's start, paper: 1.15), `light`, `seed` and
    /// `specular` (`About::shared`).
    #[serde(skip)]
    pub shared: SharedOptions,
    /// Laplacian smoothness weight `λ`.
    pub lambda: f64,
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
    /// Least angle (degrees) between the polarization normals of
    /// neighbours across a cut for the cut to be discontinuous (step 4; also
    /// at least 3× the mean angle between neighbours on either side).
    pub occlusion_jump_deg: f64,
    /// A cut between two PARG regions is kept when at least this fraction
    /// of its pixel pairs is discontinuous (step 5).
    pub keep_cut_fraction: f64,
    /// The `η` search and fit use only pixels whose DoP is at least this many
    /// times its noise (`noise::dop_snr`).
    pub min_dop_snr: f64,
    /// The AoP's error (degrees) that is not noise: each azimuth row is
    /// weighted by how far its AoP's noise stays below it (step 7,
    /// `noise::azimuth_weight`), as far as the region's prior holds it (half
    /// its outline trusted contour), and a mask boundary pixel is a contour
    /// only with its AoP along or across its outward direction (step 4); 0:
    /// every row weight 1 and the zenith alone decides, as the paper. 10 puts
    /// SMSfP 14–33% below Smith's MAE at 1250 e⁻ on the reference sweep and
    /// lowers it at 20000 e⁻ (README, "Noise"); noise-free views are
    /// unchanged.
    pub azimuth_noise_deg: f64,
    /// Output the per-pixel polarization normals disambiguated by the
    /// solved surface (step 9), not the solved surface's own normals.
    pub per_pixel: bool,
    /// Radius of the Stokes averaging before segmentation (0: none).
    pub segment_smoothing: usize,
    /// Per-pixel sense from shading: flip a pixel's azimuth when the other
    /// sense explains its intensity better by this many times the light
    /// fit's RMS residual (0: off).
    pub shading_sense: f64,
    /// Fit the surface to the polarization under the mixed diffuse and
    /// specular model, coarse to fine from `fit_start`'s surface (step 11,
    /// `specular::fit`): `"on"` (or `true`), `"off"` (or `false`) or
    /// `"auto"`, when the η search ends at the upper end of its range (read
    /// as diffuse, the polarization asks for an index beyond any
    /// dielectric's) or when the occluding contour is polarized along the
    /// outline, where diffuse polarization lies across it
    /// (`specular::limb`); `run.json`: `model`.
    #[serde(deserialize_with = "flag_or_name")]
    pub mixed_fit: MixedFit,
    /// The surface the mixed-model fit starts from: `"convex"` (the
    /// occluding contour's two convex surfaces, the dome and the
    /// crease-free membrane, keeping the fit that ends at the lower cost),
    /// `"dome"` (the first alone), `"stitched"` (step 10's) or `"both"`
    /// (the dome and step 10's, keeping the fitted surface whose normals
    /// explain the intensity better under a smooth light).
    pub fit_start: FitStart,
    /// SMSfP's own surface competes with the fitted ones: the fit's
    /// replaces it only when it explains the intensity better.
    pub fit_keeps_own: bool,
    /// The mixed-model fit also explains the diffuse intensity under a
    /// smooth light, weighted by how well SMSfP's own surface explains it
    /// (`specular::shading`).
    pub fit_shading: bool,
    /// The mixed-model fit also models a compact light reflected by rough
    /// microfacets: polarized across the plane of the light and the view,
    /// the same direction at every pixel whatever its normal. `"on"` (or
    /// `true`), `"off"` (or `false`) or `"auto"`, when the deepest tenth of
    /// the mask is polarized in one direction beyond what reflection by the
    /// surface gives there (`specular::reflected_light`); `run.json`:
    /// `model`.
    #[serde(deserialize_with = "flag_or_name")]
    pub reflected_light: ReflectedLight,
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
        shared: &["eta", "light", "seed", "specular"],
        ablations: &[
            Ablation::new("parg", "PARG"),
            Ablation::new("mfcp", "MFCP"),
            Ablation::new("refine", "refine"),
            Ablation::new("guided_filter", "guided filter"),
            Ablation::new("merge", "merge"),
            Ablation::new("per_pixel", "per pixel"),
            Ablation::new("shading_sense", "shading sense"),
            Ablation::new("mixed_fit", "mixed-model fit"),
        ],
    };

    fn validate(&self) -> Result<()> {
        self.shared.validate()?;
        validate_lambda(self.lambda)?;
        self.mfcp_params.validate()?;
        let positive = |v: f64| v > 0.0 && v.is_finite();
        let at_least_0 = |v: f64| v >= 0.0 && v.is_finite();
        let degrees = |v: f64| (0.0..=90.0).contains(&v);
        // (key, whether its value is in range, the range)
        let checks = [
            (
                "prior_exponent",
                positive(self.prior_exponent),
                "finite, > 0",
            ),
            ("max_iterations", self.max_iterations >= 1, ">= 1"),
            ("eta_band", at_least_0(self.eta_band), "finite, >= 0"),
            ("tolerance", positive(self.tolerance), "finite, > 0"),
            ("filter_radius", self.filter_radius >= 1, ">= 1"),
            ("filter_eps", positive(self.filter_eps), "finite, > 0"),
            (
                "occlusion_zenith_deg",
                degrees(self.occlusion_zenith_deg),
                "in [0, 90]",
            ),
            (
                "occlusion_aop_deg",
                degrees(self.occlusion_aop_deg),
                "in [0, 90]",
            ),
            (
                "occlusion_jump_deg",
                degrees(self.occlusion_jump_deg),
                "in [0, 90]",
            ),
            (
                "keep_cut_fraction",
                (0.0..=1.0).contains(&self.keep_cut_fraction),
                "in [0, 1]",
            ),
            ("min_dop_snr", at_least_0(self.min_dop_snr), "finite, >= 0"),
            (
                "shading_sense",
                at_least_0(self.shading_sense),
                "finite, >= 0",
            ),
            (
                "azimuth_noise_deg",
                degrees(self.azimuth_noise_deg),
                "in [0, 90]",
            ),
            // 0 would weigh noise-free pixels by 0/0.
            (
                "filter_noise_deg",
                positive(self.filter_noise_deg),
                "finite, > 0",
            ),
        ];
        for (name, ok, range) in checks {
            if !ok {
                return Err(Error::invalid(format!(
                    "smsfp: {name} is out of range: valid values are {range}"
                )));
            }
        }
        Ok(())
    }

    fn shared(&self) -> &SharedOptions {
        &self.shared
    }

    fn shared_mut(&mut self) -> &mut SharedOptions {
        &mut self.shared
    }
}

impl Default for Smsfp {
    fn default() -> Self {
        Smsfp {
            shared: SharedOptions {
                eta: 1.15,
                ..SharedOptions::default()
            },
            lambda: 0.1,
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
            azimuth_noise_deg: 10.0,
            per_pixel: true,
            segment_smoothing: 1,
            shading_sense: 2.0,
            mixed_fit: MixedFit::default(),
            fit_start: FitStart::default(),
            fit_keeps_own: false,
            fit_shading: true,
            reflected_light: ReflectedLight::default(),
            ordering: Ordering::default(),
        }
    }
}

impl Smsfp {
    /// The contour tests' thresholds (step 4).
    pub(super) fn occlusion(&self) -> Occlusion {
        Occlusion {
            zenith_deg: self.occlusion_zenith_deg,
            aop_deg: self.occlusion_aop_deg,
            jump_deg: self.occlusion_jump_deg,
            boundary_needs_aop: self.azimuth_noise_deg > 0.0,
        }
    }

    /// The refinement's parameters (step 8) with the shading law `model`.
    pub(super) fn refinement(&self, model: ShadingLaw) -> Refinement {
        Refinement {
            eta_band: self.eta_band,
            max_iterations: self.max_iterations,
            tolerance: self.tolerance,
            lambda: self.lambda,
            model,
        }
    }

    /// The guided filter's parameters (step 10).
    pub(super) fn filter(&self) -> Filter {
        Filter {
            radius: self.filter_radius,
            eps: self.filter_eps,
            noise_deg: self.filter_noise_deg,
        }
    }
}
