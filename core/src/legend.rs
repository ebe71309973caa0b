//! Legends drawn under the pictures the tool writes, so each explains itself:
//! a colour bar with its range and unit for scalar maps (intensity, DoP,
//! angular error), a wheel for the axial AoP with the colour of unpolarized
//! pixels, and a sphere key for normal maps.

use crate::Image;
use crate::colormap::{self, UNPOLARIZED};
use crate::text::{draw_text, text_width};

/// What a picture's legend explains.
#[derive(Clone, Copy, Debug)]
pub enum Legend<'a> {
    /// A scalar shown through `map` from `lo` to `hi`, in `unit` (appended to
    /// the tick values, e.g. `°`).
    Bar {
        name: &'a str,
        lo: f64,
        hi: f64,
        unit: &'a str,
        map: fn(f32) -> [u8; 3],
    },
    /// The AoP through [`colormap::cyclic`]: a wheel whose colour at each
    /// direction is that of an AoP along it (opposite sides agree: the AoP is
    /// axial), and the grey of pixels whose DoP is below `unpolarized_below`.
    AopWheel { unpolarized_below: f64 },
    /// Normals as `(n + 1)/2` RGB: a sphere seen along the camera's `−z`.
    NormalKey,
    /// Named colours: of a picture's categories (SMSfP's segments), or of
    /// pixels marked over another map (saturated pixels, under that map's
    /// own legend). A swatch and its name each, in rows as wide as the strip.
    Swatches(&'a [([u8; 3], &'a str)]),
}

/// Narrowest legend strip: its longest line of text fits.
pub const MIN_WIDTH: usize = 256;
const TEXT: [u8; 3] = [235, 235, 235];
const STRIP: [u8; 3] = [0, 0, 0];
const PAD: usize = 4;
/// Radius of the AoP wheel and of the normal sphere.
const KEY_RADIUS: usize = 14;

/// `picture` with `legend` drawn in a strip below it (the picture keeps its
/// pixels at the top left; the canvas is widened to [`MIN_WIDTH`] if needed).
pub fn with_legend(picture: &Image<[u8; 3]>, legend: &Legend) -> Image<[u8; 3]> {
    let width = picture.width().max(MIN_WIDTH);
    let strip_h = match legend {
        Legend::Bar { .. } => 32,
        Legend::AopWheel { .. } | Legend::NormalKey => 2 * (KEY_RADIUS + PAD),
        Legend::Swatches(entries) => {
            2 * PAD + SWATCH_ROW * swatch_places(entries, width).last().map_or(0, |p| p.1 + 1)
        }
    };
    let mut out = Image::new(width, picture.height() + strip_h, STRIP);
    for y in 0..picture.height() {
        for x in 0..picture.width() {
            *out.get_mut(x, y) = *picture.get(x, y);
        }
    }
    let y0 = picture.height();
    match *legend {
        Legend::Bar {
            name,
            lo,
            hi,
            unit,
            map,
        } => draw_bar(&mut out, y0, name, (lo, hi), unit, map),
        Legend::AopWheel { unpolarized_below } => {
            draw_key(&mut out, y0, |right, up| {
                let r = right.hypot(up);
                (r >= 0.45)
                    .then(|| colormap::cyclic(up.atan2(right).rem_euclid(std::f32::consts::PI)))
            });
            let x = 2 * (KEY_RADIUS + PAD);
            draw_text(
                &mut out,
                x,
                y0 + PAD + 2,
                "AoP 0-180°, from +x ccw",
                1,
                TEXT,
            );
            let swatch_y = y0 + PAD + 16;
            for y in swatch_y..swatch_y + 8 {
                for sx in x..x + 8 {
                    *out.get_mut(sx, y) = UNPOLARIZED;
                }
            }
            let note = format!("DoP < {}: no AoP", tick(unpolarized_below));
            draw_text(&mut out, x + 12, swatch_y, &note, 1, TEXT);
        }
        Legend::Swatches(entries) => {
            for (&(colour, name), (x, row)) in entries.iter().zip(swatch_places(entries, width)) {
                let y = y0 + PAD + row * SWATCH_ROW;
                for sy in y..y + 8 {
                    for sx in x..x + 8 {
                        *out.get_mut(sx, sy) = colour;
                    }
                }
                draw_text(&mut out, x + 12, y, name, 1, TEXT);
            }
        }
        Legend::NormalKey => {
            draw_key(&mut out, y0, |right, up| {
                let z2 = 1.0 - right * right - up * up;
                (z2 >= 0.0).then(|| colormap::normal_rgb([right, up, z2.sqrt()]))
            });
            let x = 2 * (KEY_RADIUS + PAD);
            draw_text(&mut out, x, y0 + PAD + 2, "normal (n+1)/2 as RGB", 1, TEXT);
            draw_text(
                &mut out,
                x,
                y0 + PAD + 16,
                "x right, y up, z to camera",
                1,
                TEXT,
            );
        }
    }
    out
}

/// Height of a row of swatches.
const SWATCH_ROW: usize = 12;

/// Where each swatch goes in a strip `width` wide: `(x, row)`, entries
/// left to right, a new row when the next would not fit.
fn swatch_places(entries: &[([u8; 3], &str)], width: usize) -> Vec<(usize, usize)> {
    let (mut x, mut row) = (PAD, 0);
    let mut places = Vec::with_capacity(entries.len());
    for (_, name) in entries {
        let w = 12 + text_width(name, 1) + 2 * PAD;
        if x > PAD && x + w > width {
            (x, row) = (PAD, row + 1);
        }
        places.push((x, row));
        x += w;
    }
    places
}

/// The picture of a legended image whose picture is `size` (it sits at the
/// top left, [`with_legend`]): for a tile that has no room for the key.
/// An image smaller than `size` (written without a legend) is returned whole.
pub fn picture_part(legended: &Image<[u8; 3]>, (w, h): (usize, usize)) -> Image<[u8; 3]> {
    if legended.width() < w || legended.height() < h {
        return legended.clone();
    }
    legended.crop(0, 0, w, h)
}

/// A compact tick value: `0`, `0.42`, `2.5`, `90`.
fn tick(v: f64) -> String {
    let a = v.abs();
    let s = if a >= 10.0 || v == v.round() {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    };
    if s == "-0" { "0".into() } else { s }
}

fn draw_bar(
    out: &mut Image<[u8; 3]>,
    y0: usize,
    name: &str,
    (lo, hi): (f64, f64),
    unit: &str,
    map: fn(f32) -> [u8; 3],
) {
    let width = out.width();
    draw_text(out, PAD, y0 + PAD + 1, name, 1, TEXT);
    let labels = [lo, 0.5 * (lo + hi), hi].map(|v| format!("{}{unit}", tick(v)));
    // Half a tick label of room on either side of the bar.
    let half = labels.iter().map(|l| text_width(l, 1)).max().unwrap_or(0) / 2 + 1;
    let x0 = PAD + text_width(name, 1) + PAD + half;
    let x1 = width.saturating_sub(PAD + half).max(x0 + 2);
    let bar = colormap::colour_bar(x1 - x0, 10, map);
    // On a picture narrower than the name and labels need, the bar and its
    // ticks are cut at the right edge rather than wrapped onto the next row.
    for y in 0..bar.height() {
        for x in 0..bar.width().min(width.saturating_sub(x0)) {
            *out.get_mut(x0 + x, y0 + PAD + y) = *bar.get(x, y);
        }
    }
    for (k, label) in labels.iter().enumerate() {
        let x = x0 + (x1 - x0 - 1) * k / 2;
        if x >= width {
            continue;
        }
        for y in y0 + PAD + 10..y0 + PAD + 13 {
            *out.get_mut(x, y) = TEXT;
        }
        let tx = x.saturating_sub(text_width(label, 1) / 2);
        draw_text(out, tx, y0 + PAD + 15, label, 1, TEXT);
    }
}

/// Draws a disc key left in the strip: `colour(right, up)` over the unit
/// disc (display directions, `up` towards the top), `None` leaves the strip.
fn draw_key(out: &mut Image<[u8; 3]>, y0: usize, colour: impl Fn(f32, f32) -> Option<[u8; 3]>) {
    let r = KEY_RADIUS as f32;
    let (cx, cy) = ((PAD + KEY_RADIUS) as f32, (y0 + PAD + KEY_RADIUS) as f32);
    for y in y0 + PAD..y0 + PAD + 2 * KEY_RADIUS {
        for x in PAD..PAD + 2 * KEY_RADIUS {
            let right = (x as f32 + 0.5 - cx) / r;
            let up = (cy - (y as f32 + 0.5)) / r;
            if right.hypot(up) > 1.0 {
                continue;
            }
            if let Some(c) = colour(right, up) {
                *out.get_mut(x, y) = c;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lit(img: &Image<[u8; 3]>, rows: std::ops::Range<usize>) -> usize {
        rows.map(|y| (0..img.width()).filter(|&x| *img.get(x, y) == TEXT).count())
            .sum()
    }

    #[test]
    fn bar_spans_its_range_with_labelled_ends() {
        let pic = Image::new(300, 10, [9u8, 9, 9]);
        let legend = Legend::Bar {
            name: "error",
            lo: 0.0,
            hi: 90.0,
            unit: "°",
            map: colormap::viridis,
        };
        let out = with_legend(&pic, &legend);
        assert_eq!(out.size(), (300, 42));
        assert_eq!(*out.get(299, 9), [9, 9, 9], "picture kept");
        // The bar runs from the map's low end to its high end, left to right.
        let y = 10 + PAD + 5;
        let row: Vec<[u8; 3]> = (0..300).map(|x| *out.get(x, y)).collect();
        let first = row
            .iter()
            .position(|&c| c == colormap::viridis(0.0))
            .unwrap();
        let last = row
            .iter()
            .rposition(|&c| c == colormap::viridis(1.0))
            .unwrap();
        assert!(first < 100 && last > 250, "{first} {last}");
        // Name, and tick labels "0°", "45°", "90°" under the bar.
        assert!(lit(&out, 10..24) > 0);
        let ticks = lit(&out, 10 + PAD + 15..10 + PAD + 23);
        let want: usize = ["0°", "45°", "90°"]
            .iter()
            .flat_map(|t| t.chars())
            .map(|c| {
                crate::text::glyph(c)
                    .iter()
                    .map(|b| b.count_ones() as usize)
                    .sum::<usize>()
            })
            .sum();
        assert_eq!(ticks, want);
    }

    #[test]
    fn narrow_pictures_get_a_strip_wide_enough_for_its_text() {
        let pic = Image::new(16, 16, [1u8, 2, 3]);
        let out = with_legend(&pic, &Legend::NormalKey);
        assert_eq!(out.width(), MIN_WIDTH);
        assert_eq!(*out.get(15, 15), [1, 2, 3]);
        assert_eq!(*out.get(20, 5), STRIP, "the widened canvas is blank");
        // The sphere key's centre faces the camera: n = (0, 0, 1).
        let c = (PAD + KEY_RADIUS, 16 + PAD + KEY_RADIUS);
        let centre = *out.get(c.0, c.1);
        assert!(
            centre[2] == 255 && (centre[0] as i32 - 128).abs() <= 10,
            "{centre:?}"
        );
        // Its right edge points along +x (red high), its top along +y (green high).
        assert!(out.get(c.0 + KEY_RADIUS - 2, c.1)[0] > 220);
        assert!(out.get(c.0, c.1 - KEY_RADIUS + 2)[1] > 220);
    }

    #[test]
    fn a_bar_wider_than_its_picture_is_cut_at_the_edge() {
        // The name alone fills the strip: the bar would start past its
        // right edge. Its colour is one nothing else in the strip has.
        const BAR: [u8; 3] = [7, 7, 7];
        let pic = Image::new(48, 48, [1u8, 2, 3]);
        let legend = Legend::Bar {
            name: "read as specular (0 no, 1 yes)",
            lo: 0.0,
            hi: 1.0,
            unit: "",
            map: |_| BAR,
        };
        let out = with_legend(&pic, &legend);
        let bar_rows = 48 + PAD..48 + PAD + 10;
        for y in 48..out.height() {
            for x in 0..out.width() {
                if *out.get(x, y) == BAR {
                    assert!(bar_rows.contains(&y), "bar colour wrapped to ({x}, {y})");
                }
            }
        }
    }

    #[test]
    fn aop_wheel_is_axial_and_counter_clockwise_from_x() {
        let out = with_legend(
            &Image::new(64, 8, [0u8; 3]),
            &Legend::AopWheel {
                unpolarized_below: 0.01,
            },
        );
        let (cx, cy) = (PAD + KEY_RADIUS, 8 + PAD + KEY_RADIUS);
        let k = KEY_RADIUS - 3;
        let right = *out.get(cx + k, cy);
        let left = *out.get(cx - k, cy);
        let up = *out.get(cx, cy - k);
        let down = *out.get(cx, cy + k);
        let near = |a: [u8; 3], b: [u8; 3]| (0..3).all(|i| (a[i] as i32 - b[i] as i32).abs() <= 24);
        // Opposite sides agree (pixel centres sit half a pixel off the axes).
        assert!(near(right, left), "{right:?} {left:?}");
        assert!(near(up, down), "{up:?} {down:?}");
        assert!(!near(right, up));
        assert!(near(right, colormap::cyclic(0.0)));
        assert!(near(up, colormap::cyclic(std::f32::consts::FRAC_PI_2)));
        // Up-right (display) is 45°.
        let d = (k as f32 / 2f32.sqrt()) as usize;
        assert!(near(
            *out.get(cx + d, cy - d),
            colormap::cyclic(std::f32::consts::FRAC_PI_4)
        ));
        // The grey swatch of unpolarized pixels is there.
        assert!(out.data().contains(&UNPOLARIZED));
    }

    #[test]
    fn swatches_name_their_colours_in_rows_that_fit() {
        let entries = [([255u8, 0, 255], "saturated"), ([1, 2, 3], "second colour")];
        let out = with_legend(&Image::new(40, 8, [0u8; 3]), &Legend::Swatches(&entries));
        // Both fit in one row of a 256-wide strip.
        assert_eq!(out.size(), (MIN_WIDTH, 8 + 2 * PAD + SWATCH_ROW));
        assert_eq!(*out.get(PAD, 8 + PAD), [255, 0, 255]);
        assert!(out.data().contains(&[1, 2, 3]));
        assert!(lit(&out, 8..out.height()) > 0);
        // Three long names wrap onto rows of their own.
        let long = [([9u8, 9, 9], "a long name for a colour in a key"); 3];
        let out = with_legend(&Image::new(40, 8, [0u8; 3]), &Legend::Swatches(&long));
        assert_eq!(out.height(), 8 + 2 * PAD + 3 * SWATCH_ROW);
    }

    #[test]
    fn ticks_are_compact() {
        assert_eq!(tick(0.0), "0");
        assert_eq!(tick(0.4213), "0.42");
        assert_eq!(tick(2.46), "2.5");
        assert_eq!(tick(90.0), "90");
        assert_eq!(tick(-0.0), "0");
    }
}
