//! Which way a camera measures its polarizer angles. The project measures
//! them from `+x` (image right) towards `+y` (up), counter-clockwise as
//! displayed (conventions.md §1); some cameras and data sets measure them
//! from the vertical, clockwise. Labels in such a frame are mapped to the
//! project's before anything else sees them.

/// The frame polarizer-angle labels are given in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AngleFrame {
    /// From the horizontal (image right), counter-clockwise: the project's.
    #[default]
    HorizontalCcw,
    /// From the vertical (image up), clockwise: `ϑ = 90° − β`.
    VerticalCw,
}

impl AngleFrame {
    /// The frame's name on the command line and in `meta.json`.
    pub fn name(self) -> &'static str {
        match self {
            AngleFrame::HorizontalCcw => "horizontal-ccw",
            AngleFrame::VerticalCw => "vertical-cw",
        }
    }

    /// The polarizer angle `ϑ` (conventions.md §1, degrees in `[0, 180)`)
    /// of the label `degrees` in this frame.
    pub fn to_conventions(self, degrees: f64) -> f64 {
        match self {
            AngleFrame::HorizontalCcw => degrees.rem_euclid(180.0),
            AngleFrame::VerticalCw => (90.0 - degrees).rem_euclid(180.0),
        }
    }

    /// For the standard angles 0°, 45°, 90°, 135° by index: the index, in
    /// the project's frame, of the angle labelled `index` in this frame.
    /// The map is its own inverse (it maps project labels back too).
    pub fn standard_index(self, index: usize) -> usize {
        let degrees = self.to_conventions(45.0 * index as f64);
        (degrees / 45.0).round() as usize % 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stokes::Stokes;

    #[test]
    fn vertical_clockwise_labels_swap_0_and_90() {
        let v = AngleFrame::VerticalCw;
        assert_eq!(
            (0..4).map(|k| v.standard_index(k)).collect::<Vec<_>>(),
            [2, 1, 0, 3]
        );
        for k in 0..4 {
            assert_eq!(AngleFrame::HorizontalCcw.standard_index(k), k);
            assert_eq!(v.standard_index(v.standard_index(k)), k);
        }
        assert_eq!(v.to_conventions(30.0), 60.0);
        assert_eq!(v.to_conventions(120.0), 150.0);
    }

    /// Light polarized at ψ seen through polarizers labelled from the
    /// vertical, clockwise: the intensities, put in the project's order by
    /// the map, give back ψ.
    #[test]
    fn relabelled_images_give_the_same_aop() {
        let v = AngleFrame::VerticalCw;
        for psi in [0.1, 0.7, 1.3, 2.0, 2.9] {
            let light = Stokes::from_polarization(1.0, 0.4, psi);
            // Image taken behind the polarizer labelled β = 0°, 45°, … from the vertical.
            let labelled: [f64; 4] = std::array::from_fn(|b| {
                let beta = 45.0 * b as f64;
                light.through_polarizer((90.0 - beta).to_radians())
            });
            let mut ours = [0.0; 4];
            for (b, value) in labelled.iter().enumerate() {
                ours[v.standard_index(b)] = *value;
            }
            let st = Stokes::from_four(ours[0], ours[1], ours[2], ours[3]);
            assert!((st.aop() - psi).abs() < 1e-12, "{psi}: {}", st.aop());
        }
    }
}
