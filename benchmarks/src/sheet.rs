//! Contact sheets: pictures laid out in a grid, for people to compare methods
//! at a glance.

use sfp_core::Image;
use sfp_core::colormap::{self, BACKGROUND};
use sfp_core::metrics::Metrics;
use sfp_core::text::{draw_text, fitting_scale, text_width};

/// Largest side of a picture in a labelled sheet, pixels: a 256² view is
/// shown pixel for pixel.
pub const CELL: usize = 256;
const GAP: usize = 8;
/// Space between lines of text, pixels.
const LEADING: usize = 4;
const TEXT: [u8; 3] = [235, 235, 235];
/// Side of the normal-colour key under a sheet's colour bar, pixels.
const KEY: usize = 64;
/// What the normal colours mean, beside the key.
const KEY_TEXT: &str = "normal colours: (n + 1)/2 as RGB - red = right (+x), green = up (+y), \
                        blue = towards the camera (+z)";

/// The caption under a method's tile: its MAE and its share of pixels
/// under 11.25°, each named (a bare "97.0%" says nothing).
pub fn figures_caption(m: &Metrics) -> String {
    format!("MAE {:.2}°\n<11.25° {:.1}%", m.mae_deg, m.acc_11_25)
}

/// Height of `lines` lines of text at `scale`.
fn text_height(lines: usize, scale: usize) -> usize {
    lines * (8 * scale + LEADING)
}

/// Width of the widest line of `text` at `scale`.
fn block_width(text: &str, scale: usize) -> usize {
    text.lines()
        .map(|l| text_width(l, scale))
        .max()
        .unwrap_or(0)
}

/// The largest scale (≤ `max_scale`) at which every line of `text` fits
/// `width`.
fn block_scale(text: &str, width: usize, max_scale: usize) -> usize {
    text.lines()
        .map(|l| fitting_scale(l, width, max_scale))
        .min()
        .unwrap_or(max_scale)
}

/// Draws each line of `text` centred in `[x, x + width)` from `y` down.
fn draw_centred(
    img: &mut Image<[u8; 3]>,
    x: usize,
    width: usize,
    y: usize,
    text: &str,
    scale: usize,
) {
    for (k, line) in text.lines().enumerate() {
        let lx = x + width.saturating_sub(text_width(line, scale)) / 2;
        draw_text(img, lx, y + k * (8 * scale + LEADING), line, scale, TEXT);
    }
}
const CANVAS: [u8; 3] = [0, 0, 0];

/// A picture cell: the image (or `None`: missing) and the text under it.
pub struct Cell {
    pub image: Option<Image<[u8; 3]>>,
    pub caption: String,
}

/// Lays out `rows` of pictures left to right, top to bottom, with a 4-pixel
/// gap; each cell is as large as the largest picture, smaller ones are
/// top-left aligned.
pub fn contact_sheet(rows: &[Vec<Image<[u8; 3]>>]) -> Image<[u8; 3]> {
    const GAP: usize = 4;
    let cell_w = rows.iter().flatten().map(Image::width).max().unwrap_or(1);
    let cell_h = rows.iter().flatten().map(Image::height).max().unwrap_or(1);
    let cols = rows.iter().map(Vec::len).max().unwrap_or(1).max(1);
    let w = cols * (cell_w + GAP) + GAP;
    let h = rows.len().max(1) * (cell_h + GAP) + GAP;
    let mut sheet = Image::new(w, h, [0u8; 3]);
    for (r, row) in rows.iter().enumerate() {
        for (c, pic) in row.iter().enumerate() {
            let (x0, y0) = (GAP + c * (cell_w + GAP), GAP + r * (cell_h + GAP));
            for y in 0..cell_h {
                for x in 0..cell_w {
                    let v = if x < pic.width() && y < pic.height() {
                        *pic.get(x, y)
                    } else {
                        BACKGROUND
                    };
                    *sheet.get_mut(x0 + x, y0 + y) = v;
                }
            }
        }
    }
    sheet
}

/// How a sheet's pictures are brought to about `CELL` pixels: one factor
/// for all of them, so a pixel is the same size in every tile and views of
/// different sizes compare as they are.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fit {
    /// Pixels repeated `k × k` (small views stay sharp).
    Enlarge(usize),
    /// Box means of `k × k` pixels.
    Shrink(usize),
}

impl Fit {
    /// The factor that brings the longest side `side` to at most `CELL`:
    /// the largest whole enlargement, or the smallest whole reduction.
    fn for_side(side: usize) -> Fit {
        let side = side.max(1);
        if side <= CELL {
            Fit::Enlarge((CELL / side).max(1))
        } else {
            Fit::Shrink(side.div_ceil(CELL))
        }
    }

    /// `img` at this factor.
    fn apply(self, img: &Image<[u8; 3]>) -> Image<[u8; 3]> {
        match self {
            Fit::Enlarge(1) => img.clone(),
            Fit::Enlarge(k) => Image::from_fn(img.width() * k, img.height() * k, |x, y| {
                *img.get(x / k, y / k)
            }),
            Fit::Shrink(k) => shrink(img, k),
        }
    }
}

/// `img` reduced `k` times by box means.
fn shrink(img: &Image<[u8; 3]>, k: usize) -> Image<[u8; 3]> {
    let (w, h) = (img.width().div_ceil(k), img.height().div_ceil(k));
    Image::from_fn(w, h, |x, y| {
        let mut sum = [0u32; 3];
        let mut n = 0;
        for yy in y * k..((y + 1) * k).min(img.height()) {
            for xx in x * k..((x + 1) * k).min(img.width()) {
                let p = img.get(xx, yy);
                for c in 0..3 {
                    sum[c] += u32::from(p[c]);
                }
                n += 1;
            }
        }
        sum.map(|s| ((s + n / 2) / n) as u8)
    })
}

/// Lays out labelled rows of pictures (all at one scale, the largest fitted
/// to about [`CELL`] pixels, a caption under each) under a header of column names; an optional colour
/// bar of the angular error (viridis, 0–90°) goes at the bottom.
pub fn labelled_sheet(
    columns: &[String],
    rows: &[(String, Vec<Cell>)],
    colour_bar: bool,
) -> Image<[u8; 3]> {
    let side = rows
        .iter()
        .flat_map(|(_, pics)| pics.iter().filter_map(|p| p.image.as_ref()))
        .map(|img| img.width().max(img.height()))
        .max()
        .unwrap_or(CELL);
    let fit = Fit::for_side(side);
    let fitted: Vec<Vec<Option<Image<[u8; 3]>>>> = rows
        .iter()
        .map(|(_, pics)| {
            pics.iter()
                .map(|p| p.image.as_ref().map(|i| fit.apply(i)))
                .collect()
        })
        .collect();
    let cw = fitted
        .iter()
        .flatten()
        .flatten()
        .map(Image::width)
        .max()
        .unwrap_or(CELL / 2)
        .max(96);
    // Wide enough for the captions and column names (each line) at the
    // larger text size, within reason.
    let texts = columns.iter().map(String::as_str).chain(
        rows.iter()
            .flat_map(|(_, pics)| pics.iter().map(|p| p.caption.as_str())),
    );
    let want = texts.map(|t| block_width(t, 2) + 8).max().unwrap_or(0);
    let cw = cw.max(want.min(CELL + 64));
    let ch = fitted
        .iter()
        .flatten()
        .flatten()
        .map(Image::height)
        .max()
        .unwrap_or(CELL / 2);
    let label_scale = 2;
    let label_w = rows
        .iter()
        .map(|(l, _)| text_width(l, label_scale))
        .max()
        .unwrap_or(0)
        .clamp(64, 16 * 20)
        + 2 * GAP;
    // One text size for all column names and one for all captions: the
    // largest at which every one of them fits its cell with a margin.
    let common = |texts: &mut dyn Iterator<Item = &str>| {
        texts
            .map(|t| block_scale(t, cw.saturating_sub(8), 2))
            .min()
            .unwrap_or(2)
    };
    let head_scale = common(&mut columns.iter().map(String::as_str));
    let lines =
        |texts: &mut dyn Iterator<Item = &str>| texts.map(|t| t.lines().count()).max().unwrap_or(0);
    let header_h = text_height(lines(&mut columns.iter().map(String::as_str)), head_scale) + GAP;
    let caption_lines = lines(
        &mut rows
            .iter()
            .flat_map(|(_, pics)| pics.iter().map(|p| p.caption.as_str())),
    );
    // One size for all row labels too.
    let label_text_scale = rows
        .iter()
        .map(|(l, _)| fitting_scale(l, label_w - 2 * GAP, label_scale))
        .min()
        .unwrap_or(label_scale);
    let caption_scale = common(
        &mut rows
            .iter()
            .flat_map(|(_, pics)| pics.iter().map(|p| p.caption.as_str())),
    );
    let caption_h = text_height(caption_lines.max(1), caption_scale) + LEADING;
    let row_h = ch + caption_h + GAP;
    let bar_h = if colour_bar { 64 + KEY + GAP } else { 0 };
    let width = label_w + columns.len().max(1) * (cw + GAP) + GAP;
    let height = header_h + rows.len() * row_h + bar_h + GAP;
    let mut img = Image::new(width, height, CANVAS);
    let col_x = |c: usize| label_w + GAP + c * (cw + GAP);
    for (c, name) in columns.iter().enumerate() {
        draw_centred(&mut img, col_x(c), cw, GAP / 2, name, head_scale);
    }
    for (r, ((label, pics), fitted)) in rows.iter().zip(&fitted).enumerate() {
        let y0 = header_h + r * row_h;
        let s = label_text_scale;
        draw_text(&mut img, GAP, y0 + ch / 2 - 4 * s, label, s, TEXT);
        for (c, (pic, image)) in pics.iter().zip(fitted).enumerate() {
            let x0 = col_x(c);
            match image {
                Some(p) => {
                    let (ox, oy) = ((cw - p.width()) / 2, (ch - p.height()) / 2);
                    for y in 0..p.height() {
                        for x in 0..p.width() {
                            *img.get_mut(x0 + ox + x, y0 + oy + y) = *p.get(x, y);
                        }
                    }
                }
                None => {
                    for y in 0..ch {
                        for x in 0..cw {
                            *img.get_mut(x0 + x, y0 + y) = BACKGROUND;
                        }
                    }
                    draw_text(
                        &mut img,
                        x0 + 4,
                        y0 + ch / 2 - 4,
                        "missing",
                        1,
                        [255, 90, 90],
                    );
                }
            }
            draw_centred(
                &mut img,
                x0,
                cw,
                y0 + ch + LEADING,
                &pic.caption,
                caption_scale,
            );
        }
    }
    if colour_bar {
        let y0 = header_h + rows.len() * row_h + 8;
        // Room for half a tick label on either side of the bar.
        let x0 = col_x(0) + 16;
        let bar_w = width.saturating_sub(x0 + 32).max(90);
        let bar = colormap::colour_bar(bar_w, 16, colormap::viridis);
        for y in 0..bar.height() {
            for x in 0..bar.width() {
                *img.get_mut(x0 + x, y0 + y) = *bar.get(x, y);
            }
        }
        let s = fitting_scale("error (°)", label_w - 2 * GAP, 2);
        draw_text(&mut img, GAP, y0, "error (°)", s, TEXT);
        // Ticks every 15°, or every 30° when the labels would touch.
        let step = if bar_w / 6 >= text_width("90°", 2) + 8 {
            15
        } else {
            30
        };
        for deg in (0..=90).step_by(step) {
            let text = deg.to_string();
            let x = x0 + (bar_w - 1) * deg / 90;
            for y in y0 + 16..y0 + 22 {
                *img.get_mut(x.min(width - 1), y) = TEXT;
            }
            let tw = text_width(&text, 2);
            let tx = x.saturating_sub(tw / 2).min(width - tw);
            draw_text(&mut img, tx, y0 + 26, &text, 2, TEXT);
        }
    }
    if colour_bar {
        let y0 = header_h + rows.len() * row_h + 64 + GAP;
        let key = normal_key(KEY);
        let x0 = col_x(0) + 16;
        for y in 0..KEY {
            for x in 0..KEY {
                *img.get_mut(x0 + x, y0 + y) = *key.get(x, y);
            }
        }
        let s = fitting_scale(KEY_TEXT, width.saturating_sub(x0 + KEY + 2 * GAP), 2);
        draw_text(
            &mut img,
            x0 + KEY + 2 * GAP,
            y0 + KEY / 2 - 4 * s,
            KEY_TEXT,
            s,
            TEXT,
        );
    }
    img
}

/// A sphere's normals seen from the camera, coloured as the normal maps
/// are: the key to reading them.
fn normal_key(side: usize) -> Image<[u8; 3]> {
    let r = side as f32 / 2.0;
    Image::from_fn(side, side, |x, y| {
        let nx = (x as f32 + 0.5 - r) / r;
        let ny = (r - y as f32 - 0.5) / r;
        let zz = 1.0 - nx * nx - ny * ny;
        if zz < 0.0 {
            CANVAS
        } else {
            colormap::normal_rgb([nx, ny, zz.sqrt()])
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pictures_land_in_their_cells() {
        let a = Image::new(2, 2, [255u8, 0, 0]);
        let b = Image::new(3, 1, [0u8, 255, 0]);
        let s = contact_sheet(&[vec![a.clone(), b], vec![a]]);
        assert_eq!(s.size(), (2 * 7 + 4, 2 * 6 + 4));
        assert_eq!(*s.get(4, 4), [255, 0, 0]);
        assert_eq!(*s.get(11, 4), [0, 255, 0]);
        assert_eq!(*s.get(11, 5), BACKGROUND);
        assert_eq!(*s.get(4, 10), [255, 0, 0]);
        assert_eq!(*s.get(0, 0), [0, 0, 0]);
    }

    #[test]
    fn pictures_are_fitted_to_the_cell_size() {
        // Small views are enlarged by whole pixels, large ones shrunk by a
        // box mean: both end within one factor of CELL.
        let small = Image::from_fn(48, 32, |x, _| [x as u8, 0, 0]);
        let up = Fit::for_side(48).apply(&small);
        assert_eq!(up.size(), (240, 160));
        assert_eq!(*up.get(9, 0), [1, 0, 0]);
        // Shrunk by 3 (700 / 256 rounded up): each box mean of 0, 150, 150.
        let large = Image::from_fn(700, 250, |x, _| if x % 3 == 0 { [0; 3] } else { [150; 3] });
        let down = Fit::for_side(700).apply(&large);
        assert_eq!(down.size(), (234, 84));
        assert_eq!(*down.get(10, 10), [100; 3]);
        assert_eq!(Fit::for_side(CELL), Fit::Enlarge(1));
    }

    #[test]
    fn every_tile_of_a_sheet_has_one_scale() {
        // A 32² and a 64² view: both enlarged 4× (the larger one's factor),
        // not each to the cell (8× and 4×).
        let pic = |side| Cell {
            image: Some(Image::new(side, side, [255u8, 0, 0])),
            caption: String::new(),
        };
        let rows = vec![("m".to_string(), vec![pic(32), pic(64)])];
        let img = labelled_sheet(&["a".into(), "b".into()], &rows, false);
        let red = img.data().iter().filter(|p| **p == [255, 0, 0]).count();
        assert_eq!(red, 128 * 128 + 256 * 256);
    }

    #[test]
    fn a_missing_picture_is_a_placeholder_and_the_colour_bar_spans_0_to_90() {
        let pic = |image| Cell {
            image,
            caption: "MAE 12.00°\n<11.25° 50.0%".into(),
        };
        let rows = vec![(
            "smith".to_string(),
            vec![pic(Some(Image::new(128, 128, [255, 0, 0]))), pic(None)],
        )];
        let img = labelled_sheet(&["a\nnormals".into(), "b".into()], &rows, true);
        let count = |c: [u8; 3]| img.data().iter().filter(|p| **p == c).count();
        assert_eq!(
            count([255, 0, 0]),
            128 * 128 * 4,
            "the picture, enlarged 2×"
        );
        // The missing picture's cell is the background with a red label.
        assert!(count(BACKGROUND) >= 256 * 256 - 8 * 64);
        assert!(count([255, 90, 90]) > 0);
        // Both ends of the colour map are in the bar.
        assert!(count(colormap::viridis(0.0)) >= 16);
        assert!(count(colormap::viridis(1.0)) >= 16);
        // The normal key: its centre faces the camera (blue full, red and
        // green halfway).
        let facing = img
            .data()
            .iter()
            .filter(|p| p[2] > 250 && (120..136).contains(&p[0]) && (120..136).contains(&p[1]))
            .count();
        assert!(facing >= 4, "{facing}");
    }

    #[test]
    fn captions_and_column_names_take_two_lines_at_a_readable_size() {
        // Two 64² tiles enlarged to 256: each line fits its cell at the
        // larger text size (16 px glyphs), so the header is two such lines.
        let pic = Cell {
            image: Some(Image::new(64, 64, [255, 0, 0])),
            caption: "MAE 12.00°\n<11.25° 50.0%".into(),
        };
        let rows = vec![("smith".to_string(), vec![pic])];
        let two = labelled_sheet(&["atkinson\nnormals".into()], &rows, false);
        let one = labelled_sheet(&["atkinson".into()], &rows, false);
        assert_eq!(two.height() - one.height(), 16 + LEADING);
        // The first lit header pixel is within the header's top margin,
        // and the second line's text reaches below the first line.
        let lit_rows: Vec<usize> = (0..two.height())
            .filter(|&y| (0..two.width()).any(|x| *two.get(x, y) == TEXT))
            .collect();
        assert!(lit_rows.contains(&(GAP / 2 + 16 + LEADING + 1)));
    }
}
