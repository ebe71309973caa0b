//! Summed-area tables: any window's sum in four look-ups, whatever its size
//! (the guided filter's window statistics, the automatic mask's window
//! majority).

use rayon::prelude::*;

/// Summed-area table of `K` channels: `(w+1)×(h+1)` entries with a zero first
/// row and column, so that any window sum is four look-ups.
pub struct Integral<const K: usize> {
    w: usize,
    h: usize,
    sums: Vec<[f64; K]>,
}

impl<const K: usize> Integral<K> {
    /// The table of `value(i)` over the row-major pixels `i` of a `w × h` image.
    pub fn new(w: usize, h: usize, value: impl Fn(usize) -> [f64; K] + Sync) -> Self {
        let stride = w + 1;
        let mut sums = vec![[0.0; K]; stride * (h + 1)];
        // Prefix sums along each row, rows in parallel ...
        sums[stride..]
            .par_chunks_mut(stride)
            .enumerate()
            .for_each(|(y, row)| {
                let mut acc = [0.0; K];
                for x in 0..w {
                    let v = value(y * w + x);
                    for k in 0..K {
                        acc[k] += v[k];
                    }
                    row[x + 1] = acc;
                }
            });
        // ... then down the columns: each row adds the finished row above
        // (sequential in y, contiguous and memory-bound in x).
        for y in 2..=h {
            let (above, below) = sums.split_at_mut(y * stride);
            for (s, a) in below[..stride].iter_mut().zip(&above[(y - 1) * stride..]) {
                for k in 0..K {
                    s[k] += a[k];
                }
            }
        }
        Integral { w, h, sums }
    }

    /// Sum over the `(2r+1)²` window centred on `(x, y)`, clipped to the image.
    #[inline]
    pub fn window(&self, x: usize, y: usize, r: usize) -> [f64; K] {
        let stride = self.w + 1;
        let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(self.w));
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(self.h));
        let s = |x: usize, y: usize| &self.sums[y * stride + x];
        let (a, b, c, d) = (s(x1, y1), s(x0, y1), s(x1, y0), s(x0, y0));
        std::array::from_fn(|k| a[k] - b[k] - c[k] + d[k])
    }
}
