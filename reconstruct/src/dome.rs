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
//!
//! Not every outline is an occluding contour: a relief seen face-on ends
//! on a surface that faces the camera. The polarization tells them apart
//! whichever reflection dominates: seen edge-on a dielectric polarizes the
//! light it sends (the diffuse DoP rises towards grazing; the specular one
//! vanishes only at normal incidence), seen face-on it barely does. So
//! an object's outline, where its zenith is largest, is more polarized
//! than the object as a whole, and a relief's, where it is flattest, less
//! ([`occluding`]). Median DoP of the outline over that of the component:
//! 1.17–7.9 on the objects of the glossy, `builtin`, `a` and `b` presets
//! (256², 44 views), 0.54–0.80 on their reliefs (`bumps`).

use crate::prior::{NORMAL_RADIUS, convexity_prior};
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

/// Share of a component's outline pixels whose DoP stands above its noise
/// from which the outline is taken for an occluding contour: most of an
/// object's outline is seen edge-on, little of a relief's.
/// Whether each component of `mask` (in `Regions::components` order) is
/// outlined by an occluding contour: the median DoP over its outline
/// pixels (within the frame) above the median over the whole component.
/// The measured DoP's noise bias raises both alike. A component without
/// outline pixels is not.
pub fn occluding(mask: &Mask, dop: &Image<f32>) -> Vec<bool> {
    let (w, _) = mask.size();
    Regions::components(mask)
        .list
        .iter()
        .map(|region| {
            let outline: Vec<f32> = region
                .pixels
                .iter()
                .filter(|&&i| {
                    mask.outward_direction(i % w, i / w, NORMAL_RADIUS)
                        .is_some()
                })
                .map(|&i| dop.data()[i])
                .collect();
            let all: Vec<f32> = region.pixels.iter().map(|&i| dop.data()[i]).collect();
            !outline.is_empty() && median(outline) > median(all)
        })
        .collect()
}

/// Median of finite `values` (NaN when there are none).
fn median(mut values: Vec<f32>) -> f32 {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return f32::NAN;
    }
    let mid = values.len() / 2;
    *values.select_nth_unstable_by(mid, f32::total_cmp).1
}

/// The dome over the components of `mask` that [`occluding`] finds
/// outlined by an occluding contour under the DoP `dop`, `otherwise` over
/// the others; and how many components took `otherwise`.
pub fn dome_where_occluding(
    mask: &Mask,
    dop: &Image<f32>,
    otherwise: &Image<f32>,
) -> (Image<f32>, usize) {
    let mut height = dome(mask);
    let (w, _) = mask.size();
    let mut others = 0;
    let components = Regions::components(mask);
    for (region, occluding) in components.list.iter().zip(occluding(mask, dop)) {
        if !occluding {
            others += 1;
            for &i in &region.pixels {
                *height.get_mut(i % w, i / w) = *otherwise.get(i % w, i / w);
            }
        }
    }
    (height, others)
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
    fn the_polarization_tells_an_outline_seen_edge_on_from_a_relief() {
        let (sphere, _) = analytic(Shape::Sphere, 64, 1.5);
        assert_eq!(occluding(&sphere.mask, &sphere.dop), [true]);
        // The blobs' disc ends on a crease facing the camera.
        let (relief, _) = analytic(Shape::Blobs, 64, 1.5);
        assert_eq!(occluding(&relief.mask, &relief.dop), [false]);
        let own = relief.mask.map(|_| 7.0);
        let (start, others) = dome_where_occluding(&relief.mask, &relief.dop, &own);
        assert_eq!(others, 1);
        assert!(
            relief
                .mask
                .data()
                .iter()
                .zip(start.data())
                .all(|(&m, &z)| !m || z == 7.0)
        );
    }

    #[test]
    fn a_mask_filling_the_frame_gives_a_plane() {
        let mask = Mask::from_fn(16, 12, |_, _| true);
        let z = dome(&mask);
        assert!(z.data().iter().all(|&v| v == 0.0));
    }
}
