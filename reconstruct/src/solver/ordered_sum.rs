//! Sums over many terms, in parallel and in a fixed order.
//!
//! Rayon's own `sum` splits the work where threads steal it, so the order
//! of the additions, and the last bits of the result, depend on the
//! scheduling. A cost compared with `<` between steps then turns a step
//! down on one run and not on the next (the Levenberg–Marquardt loops of
//! `specular::fit` and `methods/yu2017`), and the same view gives other
//! normals through the CLI and through Python. Here the terms are summed
//! in chunks of a fixed size, in parallel, and the chunks' sums in order.

use rayon::prelude::*;

/// Terms per chunk.
pub(crate) const CHUNK: usize = 1 << 14;

/// `Σ term(i)` for `i` in `0..n`, the same to the last bit on every run.
pub fn ordered_sum(n: usize, term: impl Fn(usize) -> f64 + Sync) -> f64 {
    let partial: Vec<f64> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(n))
                .map(&term)
                .sum::<f64>()
        })
        .collect();
    partial.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sum_is_the_sequential_sum_of_the_chunks() {
        // Terms whose sum depends on the order of the additions.
        let term =
            |i: usize| if i.is_multiple_of(3) { 1e16 } else { 1.0 } * if i.is_multiple_of(2) { 1.0 } else { -1.0 };
        let n = 3 * CHUNK + 17;
        let expected: f64 = (0..n.div_ceil(CHUNK))
            .map(|c| (c * CHUNK..((c + 1) * CHUNK).min(n)).map(term).sum::<f64>())
            .sum();
        for _ in 0..20 {
            assert_eq!(ordered_sum(n, term).to_bits(), expected.to_bits());
        }
        assert_eq!(ordered_sum(0, term), 0.0);
    }
}
