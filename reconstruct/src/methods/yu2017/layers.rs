//! The layer ("onion") decomposition behind the outward-normal prior
//! (spec §3.3, quirk Q7): the mask's outer contours are traced, their
//! pixels form ring 1 and leave the mask, and so on until nothing is left.
//! Every pixel of ring `i` is asked to point its azimuth outward along its
//! ring (weight `1/i`) and its zenith towards 90°: a dome over the whole
//! mask, strongest at the occluding contour. The port keeps this (it is the
//! method's prior) with two fixes: a spur's tip takes its tangent with the
//! row sign flipped like every other pixel (Q4: the authors' code leaves it
//! unflipped, so vertical tips point inward), and where a contour passes a
//! junction pixel several times its targets are averaged as directions,
//! not as angles (an arithmetic mean of angles across ±π points backwards).
//! `authors_quirks` keeps both of their choices.

use super::refine::{inside, pieces4};
use sfp_core::Mask;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};

/// One pixel of a ring: its raster index, outward target azimuth and weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerPixel {
    pub pixel: usize,
    /// Target azimuth `α*` in `(−π, π]`, camera frame (y up).
    pub azimuth: f64,
    /// `1 / ring` (ring 1 is the outer contour).
    pub weight: f64,
}

/// Directions in clockwise order on screen: N, E, S, W as (dx, drow).
const STEPS: [(isize, isize); 4] = [(0, -1), (1, 0), (0, 1), (-1, 0)];

/// Every ring's pixels with their targets, ring by ring; pixels never
/// peeled (lone pixels left at the end) carry no prior.
pub fn layers(mask: &Mask, authors_quirks: bool) -> Vec<LayerPixel> {
    let w = mask.width();
    let mut work = mask.clone();
    let mut out = Vec::new();
    for ring in 1.. {
        // Each contour: (pixel, prev, next) per entry, closing entry dropped.
        let mut entries: Vec<(usize, usize, usize)> = Vec::new();
        for piece in pieces4(&work) {
            let start = *piece.iter().min_by_key(|&&i| (i % w, i / w)).expect("non-empty");
            let contour = trace(&work, start);
            if contour.len() <= 2 {
                continue;
            }
            let n = contour.len() - 1;
            for e in 0..n {
                let prev = contour[(e + n - 1) % n];
                let next = contour[(e + 1) % n];
                entries.push((contour[e], prev, next));
            }
        }
        if entries.is_empty() {
            break;
        }
        let weight = 1.0 / f64::from(ring);
        out.extend(
            targets(&entries, w, authors_quirks)
                .into_iter()
                .map(|(pixel, azimuth)| LayerPixel {
                    pixel,
                    azimuth,
                    weight,
                }),
        );
        for &(pixel, _, _) in &entries {
            work.data_mut()[pixel] = false;
        }
        if work.count() == 0 {
            break;
        }
    }
    out
}

/// The target azimuth of every distinct pixel of the ring `entries`, in
/// order of first occurrence.
fn targets(entries: &[(usize, usize, usize)], w: usize, authors_quirks: bool) -> Vec<(usize, f64)> {
    let col = |i: usize| (i % w) as f64;
    let row = |i: usize| (i / w) as f64;
    let mut first: HashMap<usize, usize> = HashMap::new();
    // Positions after the first of each repeated pixel, in order of the
    // pixel's first repetition.
    let mut repeats: Vec<(usize, Vec<usize>)> = Vec::new();
    for (e, &(pixel, _, _)) in entries.iter().enumerate() {
        match first.get(&pixel) {
            None => {
                first.insert(pixel, e);
            }
            Some(_) => match repeats.iter_mut().find(|(p, _)| *p == pixel) {
                Some((_, list)) => list.push(e),
                None => repeats.push((pixel, vec![e])),
            },
        }
    }
    // A run of consecutive repeated positions retraces a spur; the pixel at
    // its end is where the spur joins ("thin start"); other repeated pixels
    // lie on the spur ("thin").
    let sequence: Vec<usize> = repeats.iter().flat_map(|(_, l)| l.iter().copied()).collect();
    let mut thin_start: Vec<usize> = Vec::new();
    for (i, &e) in sequence.iter().enumerate() {
        if sequence.get(i + 1) != Some(&(e + 1)) && !thin_start.contains(&entries[e].0) {
            thin_start.push(entries[e].0);
        }
    }
    let angle = |e: usize| {
        let (b, prev, next) = entries[e];
        let branch_end = prev == next;
        let (tx, ty) = if branch_end {
            let rise = row(b) - row(prev);
            (col(b) - col(prev), if authors_quirks { rise } else { -rise })
        } else {
            (col(next) - col(prev), -(row(next) - row(prev)))
        };
        let thin = repeats.iter().any(|(p, _)| *p == b) && !thin_start.contains(&b);
        let along = ty.atan2(tx);
        if thin || branch_end { along } else { along + FRAC_PI_2 }
    };
    let mut out: Vec<(usize, f64)> = Vec::with_capacity(first.len());
    for (e, &(pixel, _, _)) in entries.iter().enumerate() {
        if first[&pixel] != e {
            continue;
        }
        let mut alpha = angle(e);
        if thin_start.contains(&pixel) {
            let later = &repeats.iter().find(|(p, _)| *p == pixel).expect("repeated").1;
            let all = later.iter().map(|&l| angle(l)).chain([alpha]);
            alpha = if authors_quirks {
                all.sum::<f64>() / (later.len() + 1) as f64
            } else {
                let (s, c) = all.fold((0.0, 0.0), |(s, c), a| (s + a.sin(), c + a.cos()));
                s.atan2(c)
            };
        }
        out.push((pixel, wrap(alpha)));
    }
    out
}

/// `a` wrapped into `(−π, π]`.
fn wrap(a: f64) -> f64 {
    let mut a = a % (2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    } else if a <= -PI {
        a += 2.0 * PI;
    }
    a
}

/// The outer contour of the 4-connected piece holding `start` (its first
/// pixel in column-major order), traced clockwise on screen by the
/// Moore-neighbour rule in 4-connectivity: test N, E, S, W clockwise from
/// the search direction, move to the first pixel inside, search next from
/// the move's direction turned 90° counter-clockwise; stop on `start`
/// about to leave as at first. The list ends with `start` again; a lone
/// pixel gives `[start, start]`.
pub fn trace(mask: &Mask, start: usize) -> Vec<usize> {
    let w = mask.width();
    let mut contour = vec![start];
    let (mut at, mut search, mut first) = (start, 1usize, None);
    loop {
        let (x, y) = ((at % w) as isize, (at / w) as isize);
        let Some(d) = (0..4)
            .map(|i| (search + i) % 4)
            .find(|&d| inside(mask, x + STEPS[d].0, y + STEPS[d].1))
        else {
            contour.push(start);
            return contour;
        };
        if at == start && first == Some(d) {
            return contour;
        }
        first.get_or_insert(d);
        at = (y + STEPS[d].1) as usize * w + (x + STEPS[d].0) as usize;
        contour.push(at);
        search = (d + 3) % 4;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::mask_of as mask;

    #[test]
    fn a_square_is_traced_clockwise_from_its_top_left() {
        let m = mask(&[".....", ".###.", ".###.", ".###.", "....."]);
        let at = |x: usize, y: usize| y * 5 + x;
        let contour = trace(&m, at(1, 1));
        let expected = [
            at(1, 1),
            at(2, 1),
            at(3, 1),
            at(3, 2),
            at(3, 3),
            at(2, 3),
            at(1, 3),
            at(1, 2),
            at(1, 1),
        ];
        assert_eq!(contour, expected);
        assert_eq!(trace(&mask(&["#"]), 0), vec![0, 0]);
    }

    #[test]
    fn a_square_peels_into_two_rings_pointing_outward() {
        let m = mask(&[".....", ".###.", ".###.", ".###.", "....."]);
        let rings = layers(&m, false);
        // Ring 1: the 8 contour pixels; the lone centre is never peeled.
        assert_eq!(rings.len(), 8);
        assert!(rings.iter().all(|l| l.weight == 1.0));
        let target = |x: usize, y: usize| {
            rings.iter().find(|l| l.pixel == y * 5 + x).unwrap().azimuth
        };
        // Edge midpoints point out along ±x and ±y (y up: the top row is +y).
        assert!((target(2, 1) - FRAC_PI_2).abs() < 1e-12);
        assert!((target(3, 2) - 0.0).abs() < 1e-12);
        assert!((target(2, 3) + FRAC_PI_2).abs() < 1e-12);
        assert!((target(1, 2) - PI).abs() < 1e-12);
        // Corners point diagonally out: top-right at 45°.
        assert!((target(3, 1) - PI / 4.0).abs() < 1e-12);
    }

    #[test]
    fn a_thick_disc_peels_ring_by_ring_with_falling_weights() {
        let m = Mask::from_fn(15, 15, |x, y| {
            (x as f64 - 7.0).powi(2) + (y as f64 - 7.0).powi(2) < 36.0
        });
        let rings = layers(&m, false);
        let max_ring = rings.iter().map(|l| (1.0 / l.weight).round() as usize).max().unwrap();
        assert!(max_ring >= 4, "{max_ring} rings");
        // Every pixel but at most a few lone centres is peeled exactly once.
        let mut seen: Vec<usize> = rings.iter().map(|l| l.pixel).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), rings.len());
        assert!(m.count() - rings.len() <= 1);
        // Outer ring targets point away from the centre.
        for l in rings.iter().filter(|l| l.weight == 1.0) {
            let (x, y) = ((l.pixel % 15) as f64 - 7.0, -((l.pixel / 15) as f64 - 7.0));
            let off = (l.azimuth - y.atan2(x)).sin().abs();
            assert!(off < 0.75, "pixel {} target {}", l.pixel, l.azimuth);
        }
    }

    #[test]
    fn a_spur_tip_points_along_the_spur() {
        // A vertical spur above a block: its tip (2,0) is a branch end whose
        // target points up the spur, out of the object (+y).
        let m = mask(&["..#..", "..#..", "#####", "#####", "#####"]);
        let rings = layers(&m, false);
        let tip = rings.iter().find(|l| l.pixel == 2).unwrap();
        assert!((tip.azimuth - FRAC_PI_2).abs() < 1e-12, "{}", tip.azimuth);
        // The authors' unflipped row points it into the object (Q4).
        let theirs = layers(&m, true);
        let tip = theirs.iter().find(|l| l.pixel == 2).unwrap();
        assert!((tip.azimuth + FRAC_PI_2).abs() < 1e-12, "{}", tip.azimuth);
    }
}
