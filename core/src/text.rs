//! Text drawn into pictures (labels, tick values, units) with an 8×8 bitmap
//! font (`font8x8`): no font files, identical pixels on every machine.

use crate::Image;

/// The 8×8 bitmap of `c` (one byte per row, bit 0 leftmost): ASCII, Latin-1
/// (`°`), Greek (`η`, `σ`); minus-like signs as `-`, anything else as `?`.
pub fn glyph(c: char) -> [u8; 8] {
    use font8x8::legacy::{BASIC_LEGACY, GREEK_LEGACY, LATIN_LEGACY};
    let c = match c {
        '−' | '⁻' | '–' | '—' => '-',
        other => other,
    };
    let code = c as usize;
    match code {
        0x20..=0x7e => BASIC_LEGACY[code],
        0xa0..=0xff => LATIN_LEGACY[code - 0xa0],
        0x390..=0x3c9 => GREEK_LEGACY[code - 0x390],
        _ => BASIC_LEGACY['?' as usize],
    }
}

/// Width in pixels of `text` drawn at `scale` (8 × scale per character).
pub fn text_width(text: &str, scale: usize) -> usize {
    text.chars().count() * 8 * scale
}

/// Draws `text` with its top-left corner at `(x, y)`, each font pixel a
/// `scale × scale` square of `colour`; what falls outside is clipped.
pub fn draw_text(
    img: &mut Image<[u8; 3]>,
    x: usize,
    y: usize,
    text: &str,
    scale: usize,
    colour: [u8; 3],
) {
    for (i, c) in text.chars().enumerate() {
        let g = glyph(c);
        for (row, bits) in g.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let px = x + (i * 8 + col) * scale + dx;
                        let py = y + row * scale + dy;
                        if px < img.width() && py < img.height() {
                            *img.get_mut(px, py) = colour;
                        }
                    }
                }
            }
        }
    }
}

/// The largest scale (at most `max_scale`, at least 1) at which `text`
/// fits in `width` pixels.
pub fn fitting_scale(text: &str, width: usize, max_scale: usize) -> usize {
    (1..=max_scale.max(1))
        .rev()
        .find(|&s| text_width(text, s) <= width)
        .unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_lands_where_asked_and_clips() {
        let mut img = Image::new(20, 10, [0u8; 3]);
        draw_text(&mut img, 2, 1, "I", 1, [255; 3]);
        let lit: usize = img.data().iter().filter(|p| **p == [255; 3]).count();
        let bits: usize = glyph('I').iter().map(|b| b.count_ones() as usize).sum();
        assert_eq!(lit, bits);
        assert!((0..2).all(|x| (0..10).all(|y| *img.get(x, y) == [0; 3])));
        // Clipped at the border, no panic; scale 2 lights four pixels per bit.
        let mut big = Image::new(40, 40, [0u8; 3]);
        draw_text(&mut big, 0, 0, "°", 2, [1; 3]);
        let deg: usize = glyph('°').iter().map(|b| b.count_ones() as usize).sum();
        assert!(deg > 0);
        assert_eq!(big.data().iter().filter(|p| **p == [1; 3]).count(), 4 * deg);
        draw_text(&mut img, 18, 8, "WW", 3, [9; 3]);
        assert_eq!(glyph('η'), font8x8::legacy::GREEK_LEGACY[0x3b7 - 0x390]);
        assert_eq!(glyph('−'), glyph('-'));
        assert_eq!(fitting_scale("abcd", 64, 3), 2);
        assert_eq!(fitting_scale("abcdefghijk", 8, 3), 1);
    }
}
