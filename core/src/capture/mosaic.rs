//! Division-of-focal-plane (DoFP) polarization sensors: one raw frame whose
//! 2×2 cells carry four micro-polarizers, and its demosaicing into the four
//! polarizer images of a view (conventions.md §5).
//!
//! The common Sony sensors (IMX250MZR and relatives) put 90° 45° on the top
//! row of every cell and 135° 0° below ([`Pattern::SONY`]); other cameras
//! differ, so the pattern is a parameter.
//!
//! Colour polarization sensors (Sony IMX250MYR) put each 2×2 polarizer
//! cell under one colour filter, the cells in a Bayer order ([`Bayer`]):
//! a 4×4 block holds every polarizer under R, twice under G and under B.
//! [`mosaic_colour`] and [`demosaic_colour`] write and read such frames.

use crate::{Error, Image, Result};
use std::fmt;

/// The polarizer of each pixel of a 2×2 cell, as an index into the standard
/// angle order 0°, 45°, 90°, 135°: `cell[row parity][column parity]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pattern {
    cell: [[usize; 2]; 2],
}

/// How the four images are interpolated from the mosaic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Demosaic {
    /// One output pixel per 2×2 cell (half resolution, no interpolation):
    /// the four values of a pixel come from four neighbouring photosites.
    #[default]
    SuperPixel,
    /// Full resolution; each missing value is the mean of its nearest
    /// photosites of that polarizer (2 or 4, fewer at the border). Smooth
    /// but it blurs each image by a different sub-pixel shift, which shows as
    /// false polarization along sharp edges.
    Bilinear,
}

const ANGLES: [u16; 4] = [0, 45, 90, 135];

impl Pattern {
    /// 90° 45° over 135° 0° (Sony IMX250MZR / IMX253MZR).
    pub const SONY: Pattern = Pattern {
        cell: [[2, 1], [3, 0]],
    };

    /// The pattern with each polarizer `k` (index into 0°, 45°, 90°, 135°)
    /// labelled `map(k)` instead: a pattern given in another angle frame,
    /// or the pattern a capture fits when its images are in another order.
    pub fn relabel(self, map: impl Fn(usize) -> usize) -> Pattern {
        Pattern {
            cell: self.cell.map(|row| row.map(&map)),
        }
    }

    /// Parses the four angles of a cell in reading order (top-left,
    /// top-right, bottom-left, bottom-right), e.g. `"90,45,135,0"`.
    pub fn parse(text: &str) -> Result<Pattern> {
        let bad = || {
            Error::invalid(format!(
                "mosaic pattern `{text}`: expected the four angles 0, 45, 90, 135 \
                 in reading order of a 2×2 cell, e.g. 90,45,135,0"
            ))
        };
        let angles: Vec<u16> = text
            .split(',')
            .map(|a| a.trim().parse::<u16>().map_err(|_| bad()))
            .collect::<Result<_>>()?;
        let mut index = [0usize; 4];
        for (slot, angle) in index.iter_mut().zip(&angles) {
            *slot = ANGLES.iter().position(|a| a == angle).ok_or_else(bad)?;
        }
        let mut seen = [false; 4];
        for &i in &index {
            seen[i] = true;
        }
        if angles.len() != 4 || seen.contains(&false) {
            return Err(bad());
        }
        Ok(Pattern {
            cell: [[index[0], index[1]], [index[2], index[3]]],
        })
    }

    /// Index (into 0°, 45°, 90°, 135°) of the polarizer at pixel `(x, y)`.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> usize {
        self.cell[y % 2][x % 2]
    }

    /// Position `(x, y)` of polarizer `index` inside a cell.
    fn offset(&self, index: usize) -> (usize, usize) {
        let k = (0..4)
            .find(|&k| self.cell[k / 2][k % 2] == index)
            .expect("a pattern holds every polarizer");
        (k % 2, k / 2)
    }
}

impl fmt::Display for Pattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = |r: usize, c: usize| ANGLES[self.cell[r][c]];
        write!(f, "{},{},{},{}", a(0, 0), a(0, 1), a(1, 0), a(1, 1))
    }
}

/// The colour filter of each 2×2 polarizer cell of a colour sensor, by the
/// cell's row and column parity: the Bayer orders, named by their top-left
/// 2×2 cells in reading order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bayer {
    Rggb,
    Bggr,
    Grbg,
    Gbrg,
}

impl Bayer {
    pub const ALL: [Bayer; 4] = [Bayer::Rggb, Bayer::Bggr, Bayer::Grbg, Bayer::Gbrg];

    pub fn name(self) -> &'static str {
        match self {
            Bayer::Rggb => "rggb",
            Bayer::Bggr => "bggr",
            Bayer::Grbg => "grbg",
            Bayer::Gbrg => "gbrg",
        }
    }

    /// Parses `rggb`, `bggr`, `grbg` or `gbrg` (any case).
    pub fn parse(text: &str) -> Result<Bayer> {
        Bayer::ALL
            .into_iter()
            .find(|b| b.name().eq_ignore_ascii_case(text.trim()))
            .ok_or_else(|| {
                Error::invalid(format!(
                    "colour filter order `{text}`: expected rggb, bggr, grbg or gbrg (the \
                     colours of the top-left 2×2 polarizer cells in reading order)"
                ))
            })
    }

    /// Channel (0 = R, 1 = G, 2 = B) of polarizer cell `(cx, cy)`.
    #[inline]
    pub fn at(self, cx: usize, cy: usize) -> usize {
        let order = match self {
            Bayer::Rggb => [0, 1, 1, 2],
            Bayer::Bggr => [2, 1, 1, 0],
            Bayer::Grbg => [1, 0, 2, 1],
            Bayer::Gbrg => [1, 2, 0, 1],
        };
        order[2 * (cy % 2) + cx % 2]
    }
}

/// The raw frame a colour DoFP sensor with `pattern` and `bayer` records
/// of four colour polarizer images: each pixel takes its polarizer's value
/// in its cell's colour.
pub fn mosaic_colour(rgb: &[Image<[u16; 3]>; 4], pattern: Pattern, bayer: Bayer) -> Image<u16> {
    let (w, h) = rgb[0].size();
    Image::from_fn(w, h, |x, y| {
        rgb[pattern.at(x, y)].get(x, y)[bayer.at(x / 2, y / 2)]
    })
}

/// The four colour polarizer images (0°, 45°, 90°, 135°; R, G, B) of a
/// colour sensor's raw frame. `SuperPixel`: one pixel per 4×4 block, each
/// value read from its photosite (G the mean of the block's two);
/// `Bilinear`: full resolution, each (polarizer, colour) plane filled from
/// its photosites by normalised tent weights over ±3 pixels (the planes'
/// photosites lie 4 pixels apart, G's on a checkerboard of cells).
pub fn demosaic_colour(
    raw: &Image<u16>,
    pattern: Pattern,
    bayer: Bayer,
    method: Demosaic,
) -> Result<[Image<[u16; 3]>; 4]> {
    let (w, h) = raw.size();
    if w < 4 || h < 4 {
        return Err(Error::invalid(format!(
            "a {w}×{h} colour mosaic holds no complete 4×4 block of polarizer cells"
        )));
    }
    let colour_at = |x: usize, y: usize| bayer.at(x / 2, y / 2);
    Ok(match method {
        Demosaic::SuperPixel => std::array::from_fn(|k| {
            let (ox, oy) = pattern.offset(k);
            Image::from_fn(w / 4, h / 4, |bx, by| {
                let (mut sum, mut n) = ([0u32; 3], [0u32; 3]);
                for (cx, cy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (x, y) = (4 * bx + 2 * cx + ox, 4 * by + 2 * cy + oy);
                    let c = colour_at(x, y);
                    sum[c] += u32::from(*raw.get(x, y));
                    n[c] += 1;
                }
                std::array::from_fn(|c| ((sum[c] + n[c] / 2) / n[c].max(1)) as u16)
            })
        }),
        Demosaic::Bilinear => std::array::from_fn(|k| {
            let planes: [Image<u16>; 3] = std::array::from_fn(|c| {
                tent_fill(raw, |x, y| pattern.at(x, y) == k && colour_at(x, y) == c)
            });
            Image::from_fn(w, h, |x, y| planes.each_ref().map(|p| *p.get(x, y)))
        }),
    })
}

/// Every pixel of `raw` from the photosites where `known` holds: the
/// tent-weighted (`(4 − |dx|)(4 − |dy|)`) mean over `|dx|, |dy| ≤ 3`,
/// rounded to the nearest code; a photosite keeps its own value.
fn tent_fill(raw: &Image<u16>, known: impl Fn(usize, usize) -> bool) -> Image<u16> {
    const R: isize = 3;
    let (w, h) = raw.size();
    let weight = |d: isize| (4 - d.abs()) as f64;
    // Separable: rows first (value and weight sums), then columns.
    let mut row_sum = Image::new(w, h, (0.0f64, 0.0f64));
    for y in 0..h {
        for x in 0..w {
            let mut acc = (0.0, 0.0);
            for dx in -R..=R {
                let sx = x as isize + dx;
                if (0..w as isize).contains(&sx) && known(sx as usize, y) {
                    let wt = weight(dx);
                    acc.0 += wt * f64::from(*raw.get(sx as usize, y));
                    acc.1 += wt;
                }
            }
            *row_sum.get_mut(x, y) = acc;
        }
    }
    Image::from_fn(w, h, |x, y| {
        if known(x, y) {
            return *raw.get(x, y);
        }
        let mut acc = (0.0, 0.0);
        for dy in -R..=R {
            let sy = y as isize + dy;
            if (0..h as isize).contains(&sy) {
                let (v, wt) = *row_sum.get(x, sy as usize);
                acc.0 += weight(dy) * v;
                acc.1 += weight(dy) * wt;
            }
        }
        if acc.1 > 0.0 {
            (acc.0 / acc.1).round() as u16
        } else {
            0
        }
    })
}

/// The raw frame a DoFP sensor with `pattern` records of the four polarizer
/// images: each pixel takes its own polarizer's value.
pub fn mosaic(pol: &[Image<u16>; 4], pattern: Pattern) -> Image<u16> {
    let (w, h) = pol[0].size();
    Image::from_fn(w, h, |x, y| *pol[pattern.at(x, y)].get(x, y))
}

/// Columns and rows at the right and bottom of a `width × height` raw
/// frame that `method` leaves out: an odd last column or row holds no
/// complete 2×2 cell for the super-pixel method.
pub fn unused_edge(width: usize, height: usize, method: Demosaic) -> (usize, usize) {
    match method {
        Demosaic::SuperPixel => (width % 2, height % 2),
        Demosaic::Bilinear => (0, 0),
    }
}

/// [`unused_edge`] of a colour mosaic, whose super-pixel is a 4×4 block.
pub fn unused_edge_colour(width: usize, height: usize, method: Demosaic) -> (usize, usize) {
    match method {
        Demosaic::SuperPixel => (width % 4, height % 4),
        Demosaic::Bilinear => (0, 0),
    }
}

/// The four polarizer images (0°, 45°, 90°, 135°) of a raw frame.
pub fn demosaic(raw: &Image<u16>, pattern: Pattern, method: Demosaic) -> Result<[Image<u16>; 4]> {
    let (w, h) = raw.size();
    if w < 2 || h < 2 {
        return Err(Error::invalid(format!(
            "a {w}×{h} mosaic holds no complete 2×2 polarizer cell"
        )));
    }
    Ok(match method {
        Demosaic::SuperPixel => std::array::from_fn(|i| {
            let (ox, oy) = pattern.offset(i);
            Image::from_fn(w / 2, h / 2, |x, y| *raw.get(2 * x + ox, 2 * y + oy))
        }),
        Demosaic::Bilinear => std::array::from_fn(|i| bilinear(raw, pattern.offset(i))),
    })
}

/// Full-resolution image of the polarizer whose photosites sit at
/// `(ox + 2i, oy + 2j)`.
fn bilinear(raw: &Image<u16>, (ox, oy): (usize, usize)) -> Image<u16> {
    let (w, h) = raw.size();
    // Photosites of this polarizer at offsets (dx, dy) from (x, y), when inside.
    let mean = |x: usize, y: usize, offsets: &[(isize, isize)]| {
        let (mut sum, mut n) = (0u32, 0u32);
        for &(dx, dy) in offsets {
            let (sx, sy) = (x as isize + dx, y as isize + dy);
            if (0..w as isize).contains(&sx) && (0..h as isize).contains(&sy) {
                sum += u32::from(*raw.get(sx as usize, sy as usize));
                n += 1;
            }
        }
        // Every pixel of a ≥ 2×2 frame has a photosite of each polarizer
        // among its 8 neighbours; rounded to the nearest code.
        ((sum + n / 2) / n) as u16
    };
    Image::from_fn(w, h, |x, y| {
        match ((x + 2 - ox) % 2 == 1, (y + 2 - oy) % 2 == 1) {
            (false, false) => *raw.get(x, y),
            (true, false) => mean(x, y, &[(-1, 0), (1, 0)]),
            (false, true) => mean(x, y, &[(0, -1), (0, 1)]),
            (true, true) => mean(x, y, &[(-1, -1), (1, -1), (-1, 1), (1, 1)]),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distinct() -> [Image<u16>; 4] {
        std::array::from_fn(|c| Image::from_fn(6, 4, |x, y| (1000 * c + 10 * y + x) as u16))
    }

    #[test]
    fn sony_pattern_places_90_45_over_135_0() {
        let pol: [Image<u16>; 4] = std::array::from_fn(|c| Image::new(4, 4, c as u16));
        let raw = mosaic(&pol, Pattern::SONY);
        let cell = [
            *raw.get(0, 0),
            *raw.get(1, 0),
            *raw.get(0, 1),
            *raw.get(1, 1),
        ];
        assert_eq!(cell, [2, 1, 3, 0]);
        assert_eq!(Pattern::parse("90, 45,135,0").unwrap(), Pattern::SONY);
        assert_eq!(Pattern::SONY.to_string(), "90,45,135,0");
        let turned = Pattern::SONY.relabel(|k| (k + 2) % 4);
        assert_eq!(turned.to_string(), "0,135,45,90");
    }

    #[test]
    fn an_odd_last_column_or_row_is_counted() {
        let raw = Image::new(7, 5, 1u16);
        let out = demosaic(&raw, Pattern::SONY, Demosaic::SuperPixel).unwrap();
        assert_eq!(out[0].size(), (3, 2));
        assert_eq!(unused_edge(7, 5, Demosaic::SuperPixel), (1, 1));
        assert_eq!(unused_edge(8, 5, Demosaic::SuperPixel), (0, 1));
        assert_eq!(unused_edge(7, 5, Demosaic::Bilinear), (0, 0));
    }

    #[test]
    fn bad_patterns_are_errors() {
        for text in [
            "90,45,135",
            "90,45,135,0,0",
            "90,45,135,45",
            "90,45,135,30",
            "a,b,c,d",
        ] {
            let e = Pattern::parse(text).unwrap_err().to_string();
            assert!(e.contains(text), "{e}");
        }
        let tiny = Image::new(1, 5, 0u16);
        assert!(demosaic(&tiny, Pattern::SONY, Demosaic::Bilinear).is_err());
    }

    #[test]
    fn super_pixel_takes_each_cell_apart() {
        let pattern = Pattern::parse("0,45,135,90").unwrap();
        let pol = distinct();
        let raw = mosaic(&pol, pattern);
        let out = demosaic(&raw, pattern, Demosaic::SuperPixel).unwrap();
        for (c, img) in out.iter().enumerate() {
            assert_eq!(img.size(), (3, 2));
            let (ox, oy) = pattern.offset(c);
            for y in 0..2 {
                for x in 0..3 {
                    assert_eq!(img.get(x, y), pol[c].get(2 * x + ox, 2 * y + oy));
                }
            }
        }
    }

    #[test]
    fn bilinear_keeps_photosites_and_reproduces_linear_images() {
        // Images linear in x and y (even slopes, so the means are exact
        // codes) come back exactly away from the last row and column, where
        // the one-sided fallback takes a single neighbour.
        let (w, h) = (20, 14);
        let pol: [Image<u16>; 4] =
            std::array::from_fn(|c| Image::from_fn(w, h, |x, y| (500 * c + 6 * x + 4 * y) as u16));
        for pattern in [Pattern::SONY, Pattern::parse("45,0,90,135").unwrap()] {
            let raw = mosaic(&pol, pattern);
            let out = demosaic(&raw, pattern, Demosaic::Bilinear).unwrap();
            for (c, img) in out.iter().enumerate() {
                for y in 0..h {
                    for x in 0..w {
                        if pattern.at(x, y) == c {
                            assert_eq!(img.get(x, y), raw.get(x, y));
                        } else if x > 0 && y > 0 && x + 1 < w && y + 1 < h {
                            assert_eq!(img.get(x, y), pol[c].get(x, y), "{c} at {x},{y}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn colour_mosaics_put_each_cell_under_its_filter_and_come_back() {
        assert_eq!(Bayer::parse("RGGB").unwrap(), Bayer::Rggb);
        assert!(Bayer::parse("rgbg").is_err());
        let cells = |b: Bayer| [b.at(0, 0), b.at(1, 0), b.at(0, 1), b.at(1, 1)];
        assert_eq!(cells(Bayer::Rggb), [0, 1, 1, 2]);
        assert_eq!(cells(Bayer::Gbrg), [1, 2, 0, 1]);
        // Each polarizer and channel constant over every 4×4 block: both
        // demosaics give it back exactly.
        let (w, h) = (16, 12);
        let rgb: [Image<[u16; 3]>; 4] = std::array::from_fn(|k| {
            Image::from_fn(w, h, |x, y| {
                std::array::from_fn(|c| (1000 * k + 100 * c + 10 * (x / 4) + y / 4) as u16)
            })
        });
        let raw = mosaic_colour(&rgb, Pattern::SONY, Bayer::Rggb);
        // Top-left cell: 90° 45° / 135° 0° under red; the next cell green.
        assert_eq!(*raw.get(0, 0), rgb[2].get(0, 0)[0]);
        assert_eq!(*raw.get(1, 1), rgb[0].get(1, 1)[0]);
        assert_eq!(*raw.get(2, 0), rgb[2].get(2, 0)[1]);
        assert_eq!(*raw.get(3, 3), rgb[0].get(3, 3)[2]);
        let sp = demosaic_colour(&raw, Pattern::SONY, Bayer::Rggb, Demosaic::SuperPixel).unwrap();
        for k in 0..4 {
            assert_eq!(sp[k].size(), (4, 3));
            for (bx, by) in [(0, 0), (3, 2), (1, 1)] {
                assert_eq!(sp[k].get(bx, by), rgb[k].get(4 * bx, 4 * by));
            }
        }
        let flat: [Image<[u16; 3]>; 4] =
            std::array::from_fn(|k| Image::new(w, h, [7 + k as u16, 300, 5000]));
        let raw = mosaic_colour(&flat, Pattern::SONY, Bayer::Grbg);
        let bl = demosaic_colour(&raw, Pattern::SONY, Bayer::Grbg, Demosaic::Bilinear).unwrap();
        assert_eq!(bl, flat);
        assert!(
            demosaic_colour(
                &Image::new(3, 8, 0),
                Pattern::SONY,
                Bayer::Rggb,
                Demosaic::Bilinear
            )
            .is_err()
        );
    }
}
