//! SMSfP's part of `run.json`: what each step found, typed, so one type
//! writes it and reads it back (`serde_json::from_value::<SmsfpRecord>`).
//! The keys are those of the record's fields; the registry adds the keys
//! every method's record has (`config`, the options as they ran, `seconds`,
//! `view`, `software`, `time`).

use super::contours::Boundaries;
use super::eta::{EtaSearch, ShadingLaw};
use super::parg::{PargStats, Segmentation};
use super::region::RegionState;
use super::solve::LightChoice;
use crate::input::Input;
use crate::light::Lighting;
use crate::noise::StokesNoise;
use crate::specular::fit::FitRecord;
use crate::specular::limb::Limb;
use crate::specular::reflected_light::CorePolarization;
use serde::{Deserialize, Serialize};
use sfp_core::regions::Regions;

/// SMSfP's `run.json` record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SmsfpRecord {
    /// `smsfp`.
    pub method: String,
    pub light: LightRecord,
    /// The Stokes noise model fitted to the view (`noise::stokes_noise`).
    pub stokes_noise: StokesNoise,
    /// Pixels whose DoP stands above its noise (`min_dop_snr`).
    pub dop_measured_pixels: usize,
    pub eta: EtaRecord,
    pub segmentation: SegmentationRecord,
    /// One per solve region, in label order.
    pub regions: Vec<RegionRecord>,
    pub counts: Counts,
    pub timings: Timings,
    /// Which reflection model the surface is read with, and why
    /// (`mixed_fit`).
    pub model: ModelRecord,
    /// The surface fit under the mixed model (step 11), when it ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitRecord>,
    /// What the data left undetermined (`MethodRecord::warnings`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// Which reflection model ran (`"diffuse"`, or `"mixed"` when step 11's
/// fit ran) and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelRecord {
    pub model: String,
    pub why: String,
    /// The limb's polarization (`specular::limb`), which `"auto"` reads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limb: Option<Limb>,
    /// Whether the fit modelled a compact light reflected by rough facets,
    /// and why.
    #[serde(default)]
    pub reflected_light: bool,
    #[serde(default)]
    pub reflected_light_why: String,
    /// The deepest tenth's polarization (`specular::reflected_light`),
    /// which both `"auto"`s read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub core: Option<CorePolarization>,
}

/// The light of steps 2 and 7.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightRecord {
    /// The estimated light and its convex/concave partner.
    pub candidates: [LightingRecord; 2],
    /// Each candidate's agreement with the trusted contours (empty when the
    /// light is not ambiguous).
    pub boundary_agreement: Vec<f64>,
    /// Index of the kept candidate.
    pub chosen: usize,
    /// RMS residual of the light fit (intensity units of the view over
    /// `intensity_scale`).
    pub rms_residual: f64,
    /// The light could not be estimated: a frontal light instead.
    pub frontal_fallback: bool,
    /// The view's robust maximum intensity, the unit of the light.
    pub intensity_scale: f64,
}

/// One lighting `I = a + n·L`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightingRecord {
    /// `L`.
    pub vector: [f64; 3],
    /// `L / |L|`.
    pub direction: [f64; 3],
    /// `a`.
    pub ambient: f64,
}

/// The refractive index search of step 2.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EtaRecord {
    /// The whole object's `η`, where every region's refinement starts.
    pub initial: f64,
    /// The shading law the data follow better.
    pub shading: ShadingLaw,
    /// `[η, Lambert rms residual, Fresnel rms residual]` on the search grid
    /// (empty without refinement).
    pub search: Vec<[f64; 3]>,
}

/// Segmentation, contours and merging (steps 3–5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentationRecord {
    /// PARG's result (`null` without PARG).
    pub parg: Option<PargRecord>,
    /// Regions after merging.
    pub solve_regions: usize,
    pub trusted_boundary_pixels: usize,
    pub discontinuous_boundary_pixels: usize,
}

/// PARG's regions and what each of its stages did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PargRecord {
    pub regions: usize,
    pub stats: PargStats,
}

/// One solve region after refinement (steps 6–8).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionRecord {
    pub pixels: usize,
    /// `[x0, y0, width, height]` of its window in the view.
    pub window: [usize; 4],
    pub eta: f64,
    /// Relative albedo.
    pub alpha: f64,
    pub solves: usize,
    pub converged: bool,
    /// Pixels whose DoP clamped to a grazing zenith at the last solve.
    pub dop_clamped: usize,
    /// Share of its outline that is trusted contour (the prior's seeds).
    pub contour_share: f64,
}

/// Pixel counts of the view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Counts {
    /// Pixels of the mask.
    pub pixels: usize,
    pub dark_pixels: usize,
    pub unlit_pixels: usize,
    pub nonfinite_dropped: usize,
}

/// Seconds spent per step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Steps 1–2.
    pub light: f64,
    /// Steps 3–5.
    pub segmentation: f64,
    /// Step 6.
    pub mfcp: f64,
    /// Step 7.
    pub solves: f64,
    /// Step 8.
    pub refinement: f64,
    /// Steps 9–10.
    pub stitching: f64,
    /// Step 11.
    #[serde(default)]
    pub fit: f64,
    pub total: f64,
}

impl From<&Lighting> for LightingRecord {
    fn from(l: &Lighting) -> Self {
        LightingRecord {
            vector: l.vector,
            direction: l.direction(),
            ambient: l.ambient,
        }
    }
}

impl LightRecord {
    pub(super) fn new(search: &EtaSearch, choice: &LightChoice, input: &Input) -> Self {
        let estimated = &search.estimate.lighting;
        LightRecord {
            candidates: [estimated.into(), (&estimated.flipped()).into()],
            boundary_agreement: choice.scores.clone(),
            chosen: choice.chosen,
            rms_residual: search.estimate.rms_residual,
            frontal_fallback: search.frontal,
            intensity_scale: input.intensity_scale,
        }
    }
}

impl EtaRecord {
    pub(super) fn new(search: &EtaSearch) -> Self {
        EtaRecord {
            initial: search.eta,
            shading: search.model,
            search: search.curve.iter().map(|&(e, r)| [e, r[0], r[1]]).collect(),
        }
    }
}

impl SegmentationRecord {
    pub(super) fn new(
        segments: Option<&Segmentation>,
        regions: &Regions,
        boundaries: &Boundaries,
    ) -> Self {
        SegmentationRecord {
            parg: segments.map(|s| PargRecord {
                regions: s.regions,
                stats: s.stats.clone(),
            }),
            solve_regions: regions.len(),
            trusted_boundary_pixels: boundaries.trusted.count(),
            discontinuous_boundary_pixels: boundaries.discontinuous.count(),
        }
    }
}

impl RegionRecord {
    pub(super) fn new(s: &RegionState) -> Self {
        let (w, h) = s.input.size();
        RegionRecord {
            pixels: s.domain.len(),
            window: [s.x0, s.y0, w, h],
            eta: s.eta,
            alpha: s.alpha,
            solves: s.iterations,
            converged: s.converged,
            dop_clamped: s.clamped,
            contour_share: s.prior.contour_share,
        }
    }
}

impl From<&Input> for Counts {
    fn from(input: &Input) -> Self {
        Counts {
            pixels: input.mask.count(),
            dark_pixels: input.dark.count(),
            unlit_pixels: input.unlit.count(),
            nonfinite_dropped: input.dropped_nonfinite,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::Smsfp;
    use super::*;
    use crate::method::Method;
    use crate::test_support::analytic;
    use sfp_core::analytic::Shape;

    #[test]
    fn the_record_reads_back_what_the_driver_writes() {
        let (input, _) = analytic(Shape::Sphere, 48, 1.5);
        for parg in [true, false] {
            let method = Smsfp {
                parg,
                ..Smsfp::default()
            };
            let rec = method.reconstruct(&input).unwrap();
            let written = serde_json::to_value(&rec.run).unwrap();
            let record: SmsfpRecord = serde_json::from_value(written.clone()).unwrap();
            assert_eq!(serde_json::to_value(&record).unwrap(), written);
            assert_eq!(record.method, "smsfp");
            assert_eq!(record.segmentation.parg.is_some(), parg);
            assert_eq!(record.regions.len(), record.segmentation.solve_regions);
        }
    }
}
