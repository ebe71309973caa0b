//! Contact sheets: pictures laid out in a grid, for people to compare methods
//! at a glance.

use sfp_core::Image;
use sfp_core::colormap::BACKGROUND;

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
}
