//! Scores of a specular labelling against the ground truth of the mixture
//! (`gt/specular_stokes.exr`, conventions.md §4–5): which pixels a method
//! read as specular, against the two ways a pixel can be specular.

use crate::{Image, Mask};
use serde::{Deserialize, Serialize};

/// A binary labelling's figures over the mask.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LabelScores {
    /// Mask pixels that are positive in the ground truth.
    pub positives: usize,
    /// Mask pixels labelled positive.
    pub labelled: usize,
    /// Labelled and positive.
    pub true_positives: usize,
    /// `true_positives / labelled` (1 when nothing is labelled).
    pub precision: f64,
    /// `true_positives / positives` (1 when nothing is positive).
    pub recall: f64,
    /// Harmonic mean of precision and recall (0 when both are 0).
    pub f1: f64,
}

impl LabelScores {
    /// The figures of these counts (several views' counts summed give the
    /// pooled figures of a sweep cell).
    pub fn from_counts(positives: usize, labelled: usize, true_positives: usize) -> LabelScores {
        let ratio = |a: usize, b: usize| if b == 0 { 1.0 } else { a as f64 / b as f64 };
        let (precision, recall) = (
            ratio(true_positives, labelled),
            ratio(true_positives, positives),
        );
        let f1 = if precision + recall > 0.0 {
            2.0 * precision * recall / (precision + recall)
        } else {
            0.0
        };
        LabelScores {
            positives,
            labelled,
            true_positives,
            precision,
            recall,
            f1,
        }
    }

    /// `found` against `truth` over `mask`.
    pub fn of(found: &Mask, truth: &Mask, mask: &Mask) -> LabelScores {
        let (mut positives, mut labelled, mut true_positives) = (0, 0, 0);
        for ((&m, &f), &t) in mask.data().iter().zip(found.data()).zip(truth.data()) {
            if m {
                positives += usize::from(t);
                labelled += usize::from(f);
                true_positives += usize::from(f && t);
            }
        }
        LabelScores::from_counts(positives, labelled, true_positives)
    }
}

/// A specular labelling scored two ways.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpecularScores {
    /// Positive: the specular part's linear polarization outweighs the
    /// diffuse part's (the AoP is turned by 90°): what a method must read.
    pub polarization: LabelScores,
    /// Positive: the specular share of `s0` exceeds ½.
    pub intensity: LabelScores,
}

impl SpecularScores {
    /// A labelling scored over `mask` against a view's noise-free Stokes
    /// images and their specular part (`GroundTruth::stokes`,
    /// `specular_stokes`): `found`, the pixels whose AoP a method turned,
    /// against the polarization class, and `highlights`, those it found
    /// mostly specular in `s0`, against the intensity class; `None` without
    /// both or when sizes differ.
    pub fn of(
        found: &Mask,
        highlights: &Mask,
        stokes: Option<&[Image<f32>; 3]>,
        specular: Option<&[Image<f32>; 3]>,
        mask: &Mask,
    ) -> Option<SpecularScores> {
        let [s0, s1, s2] = stokes?;
        let [p0, p1, p2] = specular?;
        let (w, h) = s0.size();
        if found.size() != (w, h) || highlights.size() != (w, h) || mask.size() != (w, h) {
            return None;
        }
        let polarized = Image::from_fn(w, h, |x, y| {
            let (a, b) = (*p1.get(x, y), *p2.get(x, y));
            let (c, d) = (*s1.get(x, y) - a, *s2.get(x, y) - b);
            a.hypot(b) > c.hypot(d)
        });
        let bright = Image::from_fn(w, h, |x, y| 2.0 * *p0.get(x, y) > *s0.get(x, y));
        Some(SpecularScores {
            polarization: LabelScores::of(found, &polarized, mask),
            intensity: LabelScores::of(highlights, &bright, mask),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_count_and_divide() {
        let mask = Image::from_vec(5, 1, vec![true, true, true, true, false]).unwrap();
        let truth = Image::from_vec(5, 1, vec![true, true, false, false, true]).unwrap();
        let found = Image::from_vec(5, 1, vec![true, false, true, false, true]).unwrap();
        let s = LabelScores::of(&found, &truth, &mask);
        assert_eq!((s.positives, s.labelled, s.true_positives), (2, 2, 1));
        assert_eq!((s.precision, s.recall, s.f1), (0.5, 0.5, 0.5));
        let none = Image::new(5, 1, false);
        let s = LabelScores::of(&none, &none, &mask);
        assert_eq!((s.precision, s.recall, s.f1), (1.0, 1.0, 1.0));
        let s = LabelScores::of(&none, &truth, &mask);
        assert_eq!((s.recall, s.f1), (0.0, 0.0));
    }
}
