//! Step 6 of SMSfP (module doc): one solve region — its window of the view,
//! its prior, and the state the solves (step 7), the refinement (step 8) and
//! the per-pixel normals (step 9) carry.
//!
//! The prior is the region's trusted-boundary convexity prior (`prior`, the
//! contours of step 4); with MFCP (`mfcp`, Eqs. 13–17) its azimuth is fused
//! with the measured AoP at several block scales, and the AoP in the sense
//! of the fused azimuth ([`measured_sense`]) replaces the prior's azimuth in
//! the prior rows, with Smith's decaying weights `w_con` (Eq. 17).

use super::azimuth::azimuth_toward;
use super::mfcp::{MfcpParams, mfcp};
use super::orientation::oriented_rows;
use crate::input::Input;
use crate::light::Lighting;
use crate::prior::{ConvexityPrior, convexity_prior_trusted};
use crate::solver::domain::Domain;
use crate::solver::lsq::Solver;
use crate::solver::ordering::Ordering;
use crate::system::{RelativePrior, Solved};
use rayon::prelude::*;
use sfp_core::regions::Regions;
use sfp_core::{Image, Mask};

/// A region is held by its convexity prior once this share of its outline
/// is trusted contour (a disc cut along a diameter keeps 61% of its outline
/// on the contour); below it the azimuth rows' noise weights
/// (`noise::azimuth_weight`) apply in proportion. A relief's rim is trusted
/// only where noise fakes a contour (analytic blobs at 1250 e⁻: 0.5–2.5% of
/// it), and releasing its rows on that left its shape to nothing (seed 3:
/// 22.1° → 36.8°; 5 of 12 seeds 12–17° worse). Full release from any share
/// cost `a`'s camera at 1024² 6° (flat faces bulge); the share read 0.26–0.70
/// on the reference sweep's objects at 1250 e⁻.
const HELD_SHARE: f64 = 0.5;

/// Margin of a region's bounding box, so its boundary has outside pixels
/// around it (the prior needs them to see a contour).
const MARGIN: usize = 3;

/// One solve region: its window of the view, its system and its state.
pub(super) struct RegionState {
    /// Top-left corner of the window in the view.
    pub x0: usize,
    pub y0: usize,
    pub input: Input,
    /// Pixels whose DoP stands above its noise (`min_dop_snr`).
    pub measured: Mask,
    /// Weight of each unknown's azimuth row (`noise::azimuth_weight`);
    /// `None`: 1 everywhere.
    pub azimuth_weight: Option<Vec<f64>>,
    pub domain: Domain,
    pub prior: ConvexityPrior,
    /// The AoP oriented by continuity where the contours leave the region
    /// free (`orientation`), in the sense of the light's kept member.
    pub relative: Option<RelativePrior>,
    pub solver: Solver,
    pub eta: f64,
    /// The whole object's `η` (the search's).
    pub eta0: f64,
    pub alpha: f64,
    pub iterations: usize,
    /// Both light candidates after the first solve, then the kept one.
    pub solved: Option<Solved>,
    /// Kept candidate's heights and normals.
    pub z: Vec<f64>,
    pub normals: Vec<[f32; 3]>,
    /// Zenith from the DoP at the `η` of the last solve.
    pub theta: Image<f32>,
    pub clamped: usize,
    pub converged: bool,
}

/// What every region's window, prior and state are made from.
pub(super) struct RegionSetup<'a> {
    pub input: &'a Input,
    /// Trusted occluding contours (step 4).
    pub trusted: &'a Mask,
    /// Pixels whose DoP stands above its noise.
    pub measured: &'a Mask,
    /// Weight of each pixel's azimuth row; `None`: 1 everywhere.
    pub azimuth_weight: Option<&'a Image<f32>>,
    /// Each pixel's AoP confidence in `[0, 1]` (`orientation`).
    pub confidence: &'a Image<f32>,
    /// The estimated light (its first convex/concave member).
    pub lighting: &'a Lighting,
    /// Exponent of the prior's distance weight `w_con`.
    pub prior_exponent: f64,
    /// MFCP's parameters; `None`: the plain convexity prior.
    pub mfcp: Option<&'a MfcpParams>,
    pub ordering: Ordering,
    /// The whole object's `η` every region starts from.
    pub eta: f64,
}

impl RegionSetup<'_> {
    /// One state per region of `regions`, in label order.
    pub(super) fn states(&self, regions: &Regions) -> Vec<RegionState> {
        let (w, h) = self.input.size();
        regions
            .list
            .par_iter()
            .enumerate()
            .map(|(label, region)| {
                let (x0, y0, rw, rh) = region.bbox_with_margin(MARGIN, w, h);
                let own = regions
                    .labels
                    .crop(x0, y0, rw, rh)
                    .map(|&l| l == label as u32);
                let crop = self.input.crop((x0, y0, rw, rh), &own);
                let trusted = self.trusted.crop(x0, y0, rw, rh);
                let mut prior =
                    convexity_prior_trusted(&crop.mask, self.prior_exponent, |x, y, _| {
                        *trusted.get(x, y)
                    });
                if let Some(params) = self.mfcp {
                    // Unlit pixels have no AoP to take detail from.
                    let lit = Image::from_fn(rw, rh, |x, y| {
                        *crop.mask.get(x, y) && !*crop.unlit.get(x, y)
                    });
                    let fused = mfcp(&prior.azimuth, &crop.aop, &lit, params);
                    prior.azimuth = measured_sense(&prior.azimuth, &fused.azimuth, &crop);
                }
                let domain = Domain::new(&crop.mask);
                // The noisy AoPs' rows are released only as far as the prior
                // holds the region: without a trusted contour the AoPs,
                // however noisy, are all that orients it, and their rows
                // keep weight 1.
                let release = (prior.contour_share / HELD_SHARE).min(1.0);
                let azimuth_weight = self.azimuth_weight.filter(|_| release > 0.0).map(|w| {
                    (0..domain.len())
                        .map(|k| {
                            let (x, y) = domain.pixel(k);
                            1.0 - release * (1.0 - f64::from(*w.get(x0 + x, y0 + y)))
                        })
                        .collect()
                });
                let (theta, _) = crop.zenith(self.eta);
                let relative = oriented_rows(
                    &domain,
                    &crop,
                    &self.confidence.crop(x0, y0, rw, rh),
                    &theta,
                    self.lighting,
                    1.0 - release,
                );
                RegionState {
                    x0,
                    y0,
                    measured: self.measured.crop(x0, y0, rw, rh),
                    azimuth_weight,
                    input: crop,
                    domain,
                    prior,
                    relative,
                    solver: Solver::new(self.ordering),
                    eta: self.eta,
                    eta0: self.eta,
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
            .collect()
    }
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
