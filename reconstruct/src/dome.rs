//! The surface the occluding contour alone implies: each object of the mask
//! read as a convex body whose normals turn from facing the camera at its
//! middle to grazing at its outline (a start for fits that keep the start's
//! azimuth sense, `specular::fit`).
//!
//! A pixel at distance `d` from the outline of a component whose deepest
//! pixel lies `R` from it gets the height `√(d (2R − d))`: exactly a
//! hemisphere for a disc (`d = R − r`), a half cylinder across a band of
//! width `2R`, and in general normals whose azimuths point outwards
//! (perpendicular to the nearest outline) and whose zeniths reach 90° on
//! it. Distances are measured to the pixel boundary half a pixel outside
//! the outermost mask pixels. Where the frame cuts an object there is no
//! contour (`prior`), so the dome stays level there; a mask without any
//! contour gets a plane facing the camera.

use crate::prior::convexity_prior;
use sfp_core::regions::Regions;
use sfp_core::{Image, Mask};

/// Heights (pixels) of the dome over `mask`; NaN outside it.
pub fn dome(mask: &Mask) -> Image<f32> {
    let prior = convexity_prior(mask, 1.0);
    let mut height = mask.map(|&m| if m { 0.0 } else { f32::NAN });
    if prior.contour_share == 0.0 {
        return height;
    }
    let components = Regions::components(mask);
    let (w, _) = mask.size();
    let outline = |i: usize| f64::from(prior.distance.data()[i]) + 0.5;
    for region in &components.list {
        let deepest = region
            .pixels
            .iter()
            .map(|&i| outline(i))
            .fold(0.0, f64::max);
        for &i in &region.pixels {
            let d = outline(i).min(deepest);
            *height.get_mut(i % w, i / w) = (d * (2.0 * deepest - d)).sqrt() as f32;
        }
    }
    height
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::integrate::normals_from_height;
    use crate::test_support::analytic;
    use sfp_core::analytic::Shape;
    use sfp_core::metrics::evaluate;

    #[test]
    fn a_disc_gives_the_sphere_it_outlines() {
        let (input, gt) = analytic(Shape::Sphere, 96, 1.5);
        let normals = normals_from_height(&dome(&input.mask), &input.mask);
        let mae = evaluate(&normals, &gt, &input.mask).unwrap().mae_deg;
        // The outline is a staircase of pixels, so the rim's azimuths and
        // zeniths are off by a pixel's worth; inside, the sphere.
        assert!(mae < 4.5, "dome of a disc: {mae}° from the sphere");
    }

    #[test]
    fn a_mask_filling_the_frame_gives_a_plane() {
        let mask = Mask::from_fn(16, 12, |_, _| true);
        let z = dome(&mask);
        assert!(z.data().iter().all(|&v| v == 0.0));
    }
}
