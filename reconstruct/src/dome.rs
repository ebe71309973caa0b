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
//! Its creases (where two nearest outline stretches meet, the medial axis)
//! are the outline's, not the object's. [`membrane`] is the crease-free
//! convex surface over the same outline: `2√u` with `∇²u = −1` inside and
//! `u = 0` outside, again exactly a hemisphere over a disc, but a pillow
//! over a box's face where the dome is a pyramid. Neither is right for
//! every object; `specular::fit` starts from both and keeps the fit that
//! explains the data better.

use crate::prior::convexity_prior;
use crate::solver::domain::Domain;
use crate::solver::lsq::{NormalEquations, Solver};
use crate::solver::operators::Stencil;
use crate::solver::ordering::Ordering;
use sfp_core::regions::Regions;
use sfp_core::{Image, Mask, Result};

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

/// Heights (pixels) of the membrane surface over `mask` (module doc); NaN
/// outside it. `u` is solved as the least-squares fit of its differences
/// to those of `ψ = −(x² + y²)/4` (`∇²ψ = −1`), one row per pair of
/// 4-neighbours, a neighbour outside the mask held at `u = 0`: the
/// normal equations are then the 5-point Laplacian itself, as sparse as
/// the height systems. The frame is no contour: no row reaches past it.
pub fn membrane(mask: &Mask) -> Result<Image<f32>> {
    let mut height = mask.map(|&m| if m { 0.0 } else { f32::NAN });
    let domain = Domain::new(mask);
    if domain.is_empty() {
        return Ok(height);
    }
    let (w, h) = mask.size();
    let psi = |x: isize, y: isize| -((x * x + y * y) as f64) / 4.0;
    let mut eq = NormalEquations::new(&domain);
    // The rows to outside neighbours, `(unknown, target)`: they restore
    // the level the solver's gauge removes (below).
    let mut held = Vec::new();
    for k in 0..domain.len() {
        let (x, y) = domain.pixel(k);
        let (x, y) = (x as isize, y as isize);
        for (nx, ny) in [(x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)] {
            if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                continue;
            }
            let difference = psi(x, y) - psi(nx, ny);
            let mut row = Stencil::default();
            row.push(k, 1.0);
            match domain.at(nx, ny) {
                // Each inner pair once.
                Some(j) if j > k => row.push(j, -1.0),
                Some(_) => continue,
                None => held.push((k, difference)),
            }
            eq.add(&row, difference, 1.0);
        }
    }
    let solution = Solver::new(Ordering::default()).solve(&eq)?;
    let u = &solution.z[0];
    // The solver returns each component at zero mean (heights are known up
    // to a constant); the rows holding `u = 0` outside fix it.
    let mut level = vec![(0.0, 0usize); domain.len()];
    for (k, target) in held {
        level[k].0 += target - u[k];
        level[k].1 += 1;
    }
    for region in &Regions::components(mask).list {
        let unknowns: Vec<usize> = region
            .pixels
            .iter()
            .map(|&i| domain.unknown(i).expect("a mask pixel is an unknown"))
            .collect();
        let (sum, count) = unknowns
            .iter()
            .fold((0.0, 0), |(s, n), &k| (s + level[k].0, n + level[k].1));
        for (&i, &k) in region.pixels.iter().zip(&unknowns) {
            // Without any contour: a plane facing the camera.
            let v = if count > 0 {
                u[k] + sum / count as f64
            } else {
                0.0
            };
            height.data_mut()[i] = (2.0 * v.max(0.0).sqrt()) as f32;
        }
    }
    Ok(height)
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

    #[test]
    fn the_membrane_of_a_disc_is_its_sphere_and_has_no_creases() {
        let (input, gt) = analytic(Shape::Sphere, 96, 1.5);
        let z = membrane(&input.mask).unwrap();
        let normals = normals_from_height(&z, &input.mask);
        let mae = evaluate(&normals, &gt, &input.mask).unwrap().mae_deg;
        assert!(mae < 4.5, "membrane of a disc: {mae}° from the sphere");
        // Over a square the dome is a pyramid, whose faces meet at creases;
        // the membrane turns smoothly: its largest normal turn between
        // neighbours inside is far below the dome's.
        let square = Mask::from_fn(40, 40, |x, y| (4..36).contains(&x) && (4..36).contains(&y));
        let turn = |z: &Image<f32>| {
            let n = normals_from_height(z, &square);
            let mut worst = 0.0f32;
            for y in 8..32 {
                for x in 8..31 {
                    let (a, b) = (n.get(x, y), n.get(x + 1, y));
                    let dot: f32 = (0..3).map(|c| a[c] * b[c]).sum();
                    worst = worst.max(dot.clamp(-1.0, 1.0).acos().to_degrees());
                }
            }
            worst
        };
        let (smooth, creased) = (turn(&membrane(&square).unwrap()), turn(&dome(&square)));
        assert!(smooth * 3.0 < creased, "membrane {smooth}° dome {creased}°");
        // A mask filling the frame has no contour: a plane.
        let full = Mask::from_fn(16, 12, |_, _| true);
        assert!(membrane(&full).unwrap().data().iter().all(|&v| v == 0.0));
    }
}
