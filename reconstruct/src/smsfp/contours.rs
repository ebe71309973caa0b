//! Step 4 of SMSfP (module doc): which region boundaries are occluding
//! contours, and which cuts between regions are discontinuities.
//!
//! A region's boundary tells the convexity prior that the normal there
//! points outward in the image plane; that holds only on an *occluding
//! contour* of the region. Measured before this was built (shared notes):
//! priors on every cut made per-region solves worse than one solve. An
//! occluding contour is seen at a grazing angle, so every trusted pixel has a
//! zenith of at least `occlusion_zenith_deg` (where the mask ends on a
//! surface facing the camera — the edge of an open shell, a crease — the
//! outward direction is a guess: preset-a car body, open wheel arches, 31.3°
//! → 26.3° MAE; unlit pixels, with no zenith to judge by, are trusted on the
//! mask's boundary). A mask-boundary pixel needs nothing more, or, with
//! [`Occlusion::boundary_needs_aop`], an AoP along or across its outward
//! direction; a pixel on a cut between regions is trusted when the data
//! show an occlusion: the AoP within `occlusion_aop_deg` of the region's
//! outward direction there (diffuse AoP is parallel to the azimuth, which
//! at a contour is the outward normal), and a discontinuity across the cut: the angle between the
//! polarization normals of neighbours across it (up to the π ambiguity) at
//! least `occlusion_jump_deg` and [`JUMP_RATIO`] times the mean angle between
//! neighbours on either side (a smooth surface continues across a cut with
//! its own gradient: without this test, cuts along circles of a sphere passed
//! as contours). The discontinuous cut pixels also decide the merging of
//! step 5 (`merge`).

use crate::input::Input;
use crate::normal::zenith_azimuth_normal;
use rayon::prelude::*;
use sfp_core::{Image, Mask};

/// A depth edge's zenith step across a cut is at least this many times the
/// mean step between neighbours on either side.
const JUMP_RATIO: f64 = 3.0;

/// The thresholds of the contour tests, in degrees (`Smsfp::occlusion_*`).
pub(super) struct Occlusion {
    /// Least zenith of a trusted contour pixel.
    pub zenith_deg: f64,
    /// Largest angle between the AoP and the outward direction on a cut.
    pub aop_deg: f64,
    /// Least angle between polarization normals across a discontinuous cut.
    pub jump_deg: f64,
    /// Mask-boundary pixels need their AoP along the outward direction or
    /// across it (within `aop_deg` of either). With noise, a frame edge
    /// facing the camera reads a grazing zenith from a DoP the noise lifted,
    /// but its AoP points anywhere; a limb's AoP points outwards where its
    /// diffuse part dominates and along the limb where a gloss does (the
    /// specular AoP is turned by 90°). SMSfP asks for it with
    /// `azimuth_noise_deg > 0`, whose weighting leaves a region's shape to
    /// its prior (analytic blobs at 5000 e⁻: 29.7° → 23.0°). Asking for the
    /// outward AoP alone lost the glossy rims of the real fruit capture and
    /// flipped the apple and the banana (59% of the mask moved by > 45°;
    /// 3% with either direction accepted).
    pub boundary_needs_aop: bool,
}

/// Boundary pixels of the PARG regions.
pub(super) struct Boundaries {
    /// Trusted occluding contours: where the convexity prior applies.
    pub trusted: Mask,
    /// Cut pixels where the polarization normal jumps: regions are not
    /// merged across them.
    pub discontinuous: Mask,
}

impl Occlusion {
    /// Which boundary pixels of the regions `labels` are discontinuous cuts
    /// and which are trusted occluding contours, with the zeniths `theta`.
    pub(super) fn boundaries(
        &self,
        input: &Input,
        theta: &Image<f32>,
        labels: &Image<u32>,
    ) -> Boundaries {
        let (w, h) = input.size();
        let min_zenith = self.zenith_deg.to_radians();
        let max_cos = self.aop_deg.to_radians().cos();
        let max_sin = self.aop_deg.to_radians().sin();
        let min_jump = self.jump_deg.to_radians();
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
                // |cos| of the angle between the AoP and the outward direction.
                let cos = (len > 1e-9).then(|| ((psi.cos() * ox + psi.sin() * oy) / len).abs());
                let along = cos.is_some_and(|c| c >= max_cos);
                let across = cos.is_some_and(|c| c <= max_sin);
                let trusted = grazing
                    && ((background && (along || across || !self.boundary_needs_aop))
                        || (discontinuous && along));
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
}

/// Angle between `a` and the nearer of `b` and its azimuth-flipped twin
/// `(−b_x, −b_y, b_z)`: how far apart two polarization normals are whatever
/// the π ambiguity.
fn ambiguous_angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let planar = (a[0] * b[0] + a[1] * b[1]).abs();
    (planar + a[2] * b[2]).clamp(-1.0, 1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::analytic;
    use sfp_core::analytic::Shape;
    use sfp_core::regions::OUTSIDE;

    /// A sphere cut in two halves: the cut crosses a smooth surface, so
    /// no pixel of it is a contour; the limb is.
    #[test]
    fn a_cut_across_a_smooth_surface_is_no_contour() {
        let (input, _) = analytic(Shape::Sphere, 64, 1.5);
        let labels = Image::from_fn(64, 64, |x, y| {
            if *input.mask.get(x, y) {
                u32::from(x >= 32)
            } else {
                OUTSIDE
            }
        });
        let (theta, _) = input.zenith(1.5);
        let occlusion = Occlusion {
            zenith_deg: 60.0,
            aop_deg: 25.0,
            jump_deg: 10.0,
            boundary_needs_aop: false,
        };
        let b = occlusion.boundaries(&input, &theta, &labels);
        let background = |x: usize, y: usize| {
            [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().any(|&(dx, dy)| {
                let (nx, ny) = (x as isize + dx, y as isize + dy);
                nx < 0
                    || ny < 0
                    || nx >= 64
                    || ny >= 64
                    || !*input.mask.get(nx as usize, ny as usize)
            })
        };
        let limb = (0..64 * 64)
            .filter(|&i| *input.mask.get(i % 64, i / 64) && background(i % 64, i / 64))
            .count();
        let trusted: Vec<usize> = (0..64 * 64)
            .filter(|&i| *b.trusted.get(i % 64, i / 64))
            .collect();
        // The whole limb (grazing everywhere) and nothing else.
        assert_eq!(trusted.len(), limb);
        assert!(trusted.iter().all(|&i| background(i % 64, i / 64)));
        assert_eq!(b.discontinuous.count(), 0);
    }

    /// A mask edge facing the camera whose noisy DoP reads grazing is a
    /// contour by zenith alone; asked for the AoP too, it is not when its
    /// AoP is neither along nor across the outward direction, while the
    /// sphere's limb is, diffuse (AoP outward) or glossy (AoP along the
    /// limb, turned by 90°).
    #[test]
    fn a_boundary_with_an_oblique_aop_is_no_contour_when_the_aop_is_asked() {
        let (mut input, _) = analytic(Shape::Sphere, 64, 1.5);
        let labels = input.mask.map(|&m| if m { 0 } else { OUTSIDE });
        // The AoP of the left half turned by 45° (as noise may), of the
        // lower right quarter by 90° (as a gloss does).
        let turn = |x: usize, y: usize| match (x < 32, y < 32) {
            (true, _) => std::f32::consts::FRAC_PI_4,
            (false, false) => std::f32::consts::FRAC_PI_2,
            (false, true) => 0.0,
        };
        for y in 0..64 {
            for x in 0..64 {
                if *input.mask.get(x, y) {
                    let a = *input.aop.get(x, y);
                    *input.aop.get_mut(x, y) = (a + turn(x, y)) % std::f32::consts::PI;
                }
            }
        }
        let (theta, _) = input.zenith(1.5);
        let trusted = |needs: bool| {
            Occlusion {
                zenith_deg: 60.0,
                aop_deg: 25.0,
                jump_deg: 10.0,
                boundary_needs_aop: needs,
            }
            .boundaries(&input, &theta, &labels)
            .trusted
        };
        let (by_zenith, by_aop) = (trusted(false), trusted(true));
        // Unlit limb pixels have no AoP to ask: the boundary decides there.
        let count = |m: &Mask, part: &dyn Fn(usize, usize) -> bool| {
            (0..64 * 64)
                .filter(|&i| {
                    let (x, y) = (i % 64, i / 64);
                    *m.get(x, y) && !*input.unlit.get(x, y) && part(x, y)
                })
                .count()
        };
        let (left, right) = (|x, _| x < 32, |x, _| x >= 32);
        let glossy = |x, y| x >= 32 && y >= 32;
        assert!(
            count(&by_zenith, &left) > 10,
            "{}",
            count(&by_zenith, &left)
        );
        assert_eq!(count(&by_aop, &left), 0);
        assert!(count(&by_aop, &glossy) > 10, "{}", count(&by_aop, &glossy));
        assert_eq!(count(&by_aop, &right), count(&by_zenith, &right));
    }
}
