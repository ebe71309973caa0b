//! Colour: the one rule by which a reader of grey reads a colour image or a
//! colour view (conventions.md §5, §6). Rec. 709 luminance of linear
//! channels; being a weighted sum, it keeps each polarizer's sinusoid, so
//! the Stokes vector of the luminance is the same sum of the channels' own.

/// Weights of R, G, B in the luminance (Rec. 709).
pub const REC709: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Names of the channels, in the order every colour array keeps them.
pub const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// `0.2126 R + 0.7152 G + 0.0722 B` of linear values.
#[inline]
pub fn luminance(rgb: [f64; 3]) -> f64 {
    REC709[0] * rgb[0] + REC709[1] * rgb[1] + REC709[2] * rgb[2]
}

/// The luminance of linear codes, rounded to the nearest code.
#[inline]
pub fn luminance_code(rgb: [u16; 3]) -> u16 {
    luminance(rgb.map(f64::from)).round() as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_is_its_own_luminance() {
        assert!((REC709.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        for v in [0u16, 1, 255, 40000, 65535] {
            assert_eq!(luminance_code([v; 3]), v);
        }
        assert_eq!(luminance_code([1000, 0, 0]), 213);
    }
}
