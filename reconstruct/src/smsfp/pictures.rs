//! The pictures SMSfP leaves beside its result: PARG's segments
//! (`segments.png`) and labels (`labels.png`) when it segmented, and the
//! regions it solved after merging (`regions.png`), each with its key.

use super::parg::{NEIGHBOURS4, Segmentation};
use crate::method::Picture;
use sfp_core::legend::{Legend, with_legend};
use sfp_core::regions::{OUTSIDE, Regions};
use sfp_core::result_folder::ResultFolder;
use sfp_core::{Image, colormap};

/// The pictures of a run: PARG's `segments` (if any) and the solve
/// `regions`, over the view's `intensity`.
pub(super) fn pictures(
    segments: Option<&Segmentation>,
    regions: &Regions,
    intensity: &Image<f32>,
) -> Vec<Picture> {
    let mut pictures = Vec::new();
    if let Some(seg) = segments {
        pictures.push(Picture::Rgb(
            ResultFolder::SEGMENTS,
            keyed(
                segments_preview(&seg.labels, intensity),
                &seg.labels,
                ("segment", "segments"),
            ),
        ));
        pictures.push(Picture::Gray16(
            ResultFolder::LABELS,
            labels_png(&seg.labels),
        ));
    }
    let solve_labels = regions
        .labels
        .map(|&l| if l == OUTSIDE { 0 } else { l + 1 });
    pictures.push(Picture::Rgb(
        ResultFolder::REGIONS,
        keyed(
            segments_preview(&solve_labels, intensity),
            &solve_labels,
            ("region solved", "regions solved"),
        ),
    ));
    pictures
}

/// `preview` of `labels` with its key below: how many `what` (singular,
/// plural) there are (a colour each, over the intensity), boundaries, the
/// background. The names stay short: the key strip of a small view is
/// 256 pixels wide, 30 characters of its font.
fn keyed(preview: Image<[u8; 3]>, labels: &Image<u32>, what: (&str, &str)) -> Image<[u8; 3]> {
    let count = labels
        .data()
        .iter()
        .filter(|&&l| l != 0)
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    let name = format!("{count} {}", if count == 1 { what.0 } else { what.1 });
    let key = [
        (label_colour(1), name.as_str()),
        (label_colour(1).map(|c| c / 4), "boundaries"),
        (colormap::BACKGROUND, "outside the mask"),
    ];
    with_legend(&preview, &Legend::Swatches(&key))
}

/// Label colours blended half-and-half over the intensity (scaled by its
/// maximum inside the labels), with pixels next to another region darkened so
/// that boundaries read even between similar colours. An intensity of another
/// size is replaced by flat grey.
pub(super) fn segments_preview(labels: &Image<u32>, intensity: &Image<f32>) -> Image<[u8; 3]> {
    let (w, h) = labels.size();
    let usable = labels.same_size(intensity);
    let max = if usable {
        labels
            .data()
            .iter()
            .zip(intensity.data())
            .filter(|&(&l, v)| l != 0 && v.is_finite())
            .fold(0.0f32, |m, (_, &v)| m.max(v))
    } else {
        0.0
    };
    Image::from_fn(w, h, |x, y| {
        let l = *labels.get(x, y);
        if l == 0 {
            return colormap::BACKGROUND;
        }
        let boundary = NEIGHBOURS4.iter().any(|&(dx, dy)| {
            let (nx, ny) = (x as isize + dx, y as isize + dy);
            nx >= 0
                && ny >= 0
                && (nx as usize) < w
                && (ny as usize) < h
                && !matches!(*labels.get(nx as usize, ny as usize), 0)
                && *labels.get(nx as usize, ny as usize) != l
        });
        let t = if max > 0.0 {
            (intensity.get(x, y) / max).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let c = label_colour(l);
        let shade = if boundary { 0.25 } else { 1.0 };
        c.map(|c| ((0.5 * f32::from(c) + 0.5 * 255.0 * t) * shade).round() as u8)
    })
}

/// A saturated colour per id: hues stepped by the golden ratio, so that
/// neighbouring ids differ strongly.
fn label_colour(l: u32) -> [u8; 3] {
    let hue = (f64::from(l) * 0.618_033_988_75).fract() * 6.0;
    let f = hue.fract();
    let (v, p) = (1.0, 0.3);
    let (q, t) = (v - (v - p) * f, p + (v - p) * f);
    let rgb = match hue as u32 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    };
    rgb.map(|c| (c * 255.0).round() as u8)
}

/// Region ids as 16-bit values for `labels.png` (0 outside; ids beyond 65535,
/// which no useful segmentation reaches, saturate).
pub(super) fn labels_png(labels: &Image<u32>) -> Image<u16> {
    labels.map(|&l| l.min(u32::from(u16::MAX)) as u16)
}

#[cfg(test)]
mod tests {
    use super::super::parg::{PargParams, segment};
    use super::*;
    use sfp_core::Mask;

    #[test]
    fn previews_of_degenerate_segmentations() {
        // NaN inputs: every pixel still labelled, so previews of full size.
        let nan = Image::new(5, 4, f32::NAN);
        let (dop, aop) = (Image::new(5, 4, 0.1f32), Image::new(5, 4, 0.3f32));
        let full = Mask::new(5, 4, true);
        let seg = segment(&nan, &aop, &full, &PargParams::default()).unwrap();
        assert_eq!(labels_png(&seg.labels).size(), (5, 4));
        assert_eq!(segments_preview(&seg.labels, &dop).size(), (5, 4));
        // A mismatched intensity falls back to grey instead of panicking.
        assert_eq!(
            segments_preview(&seg.labels, &Image::new(2, 2, 1.0)).size(),
            (5, 4)
        );
    }

    #[test]
    fn the_key_of_a_small_view_is_not_cut() {
        // A 32² view's key strip is at its narrowest: every name fits, so
        // no text reaches the strip's right edge (cut text would).
        let labels = Image::from_fn(32, 32, |x, _| u32::from(x > 4));
        let pic = keyed(
            segments_preview(&labels, &Image::new(32, 32, 1.0)),
            &labels,
            ("region solved", "regions solved"),
        );
        let lit = |x: usize| (32..pic.height()).any(|y| *pic.get(x, y) == [235, 235, 235]);
        assert!((0..pic.width() - 8).any(lit), "no key text");
        assert!(
            !(pic.width() - 8..pic.width()).any(lit),
            "key text cut at the edge"
        );
    }

    #[test]
    fn previews_mark_regions_and_background() {
        let labels = Image::from_fn(6, 4, |x, y| {
            if y == 0 {
                0
            } else if x < 3 {
                1
            } else {
                70000
            }
        });
        let png = labels_png(&labels);
        assert_eq!(png.size(), (6, 4));
        assert_eq!(
            (*png.get(0, 0), *png.get(0, 1), *png.get(5, 1)),
            (0, 1, u16::MAX)
        );
        let rgb = segments_preview(&labels, &Image::new(6, 4, 1.0));
        assert_eq!(*rgb.get(0, 0), colormap::BACKGROUND);
        let (inner, edge) = (*rgb.get(0, 2), *rgb.get(2, 2));
        assert!(
            edge.iter().zip(inner).all(|(&e, i)| e < i),
            "{edge:?} {inner:?}"
        );
    }
}
