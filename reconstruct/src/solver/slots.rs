//! The layout of a normal matrix row: each unknown keeps its diagonal and
//! its couplings to the 12 pixels at most two rows later in raster order
//! (every stencil of `operators` fits a 3×3 window, so `CᵀC` couples pixels
//! at most two apart). The normal equations (`lsq`) are accumulated in it and
//! the factorisations (`cholesky`, `substructure`) read their lower triangle
//! from it.

use crate::solver::domain::Domain;

/// Pixel offsets `(dx, dy)` (rows down) of the 13 upper slots, in raster order.
pub(crate) const SLOTS: [(isize, isize); 13] = [
    (0, 0),
    (1, 0),
    (2, 0),
    (-2, 1),
    (-1, 1),
    (0, 1),
    (1, 1),
    (2, 1),
    (-2, 2),
    (-1, 2),
    (0, 2),
    (1, 2),
    (2, 2),
];

/// Slots of the 8-neighbour pairs (pixels later in raster order).
pub(crate) const NEIGHBOUR_SLOTS: [usize; 4] = [1, 4, 5, 6];

/// Slot of the coupling from a pixel to one `(dx, dy)` later in raster order.
#[inline]
pub(crate) fn slot(dx: isize, dy: isize) -> usize {
    match dy {
        0 => dx as usize,
        1 => (3 + dx + 2) as usize,
        2 => (8 + dx + 2) as usize,
        _ => panic!("rows may couple pixels at most 2 rows apart"),
    }
}

/// Unknown at slot `s` of unknown `k`, if that pixel is in `domain`.
#[inline]
pub(crate) fn slot_pixel(domain: &Domain, k: usize, s: usize) -> Option<usize> {
    let (x, y) = domain.pixel(k);
    let (dx, dy) = SLOTS[s];
    domain.at(x as isize + dx, y as isize + dy)
}

/// Unknown whose slot `s` is unknown `k`, if that pixel is in `domain`.
#[inline]
pub(crate) fn slot_source(domain: &Domain, k: usize, s: usize) -> Option<usize> {
    let (x, y) = domain.pixel(k);
    let (dx, dy) = SLOTS[s];
    domain.at(x as isize - dx, y as isize - dy)
}

/// Entry `v` at slot `s` of unknown `k` with `epsilon Σ (z_i − z_j)²` over
/// the 8-neighbour pairs of `domain` added: `epsilon` on the diagonal once
/// per pair `k` belongs to (the later pixel of the pair at one of
/// [`NEIGHBOUR_SLOTS`], or `k` at such a slot of the earlier one; added one
/// at a time, as summing over the pairs adds it), `−epsilon` on a
/// neighbour's slot.
#[inline]
fn with_membrane(v: f64, domain: &Domain, k: usize, s: usize, epsilon: f64) -> f64 {
    if s == 0 {
        NEIGHBOUR_SLOTS
            .iter()
            .flat_map(|&s| [slot_pixel(domain, k, s), slot_source(domain, k, s)])
            .flatten()
            .fold(v, |v, _| v + epsilon)
    } else if NEIGHBOUR_SLOTS.contains(&s) && slot_pixel(domain, k, s).is_some() {
        v - epsilon
    } else {
        v
    }
}

/// A normal matrix in the 13-slot layout as the solvers read it: `CᵀC`
/// with up to two membranes added in turn (`lsq`'s, and a floor for a
/// preconditioner, `plan`), entry by entry, so that neither needs a copy of
/// the matrix (104 bytes per pixel of the domain each).
#[derive(Clone, Copy)]
pub(crate) struct Entries<'a> {
    matrix: &'a [[f64; 13]],
    domain: &'a Domain,
    membranes: [Option<f64>; 2],
}

impl<'a> Entries<'a> {
    /// `matrix` on `domain` as it is.
    pub fn new(matrix: &'a [[f64; 13]], domain: &'a Domain) -> Self {
        Entries {
            matrix,
            domain,
            membranes: [None; 2],
        }
    }

    /// These entries plus `epsilon` times the membrane (at most twice).
    pub fn with_membrane(mut self, epsilon: f64) -> Self {
        let free = self
            .membranes
            .iter_mut()
            .find(|m| m.is_none())
            .expect("at most two membranes");
        *free = Some(epsilon);
        self
    }

    /// Slot `s` of unknown `k`.
    #[inline]
    pub fn get(&self, k: usize, s: usize) -> f64 {
        self.membranes
            .iter()
            .flatten()
            .fold(self.matrix[k][s], |v, &e| {
                with_membrane(v, self.domain, k, s, e)
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::Mask;

    /// The membrane summed over the pairs, as the matrix once was built.
    fn add_membrane(domain: &Domain, matrix: &mut [[f64; 13]], epsilon: f64) {
        for k in 0..matrix.len() {
            for s in NEIGHBOUR_SLOTS {
                if let Some(j) = slot_pixel(domain, k, s) {
                    matrix[k][0] += epsilon;
                    matrix[j][0] += epsilon;
                    matrix[k][s] -= epsilon;
                }
            }
        }
    }

    #[test]
    fn membranes_are_added_bit_for_bit_as_over_the_pairs() {
        // An irregular mask (holes, a ragged edge) and arbitrary entries.
        let mask = Mask::from_fn(9, 7, |x, y| (x * 3 + y * 5) % 7 != 0 && x + y < 13);
        let domain = Domain::new(&mask);
        let matrix: Vec<[f64; 13]> = (0..domain.len())
            .map(|k| std::array::from_fn(|s| ((k * 13 + s) as f64 * 0.37).sin()))
            .collect();
        // Two membranes in turn, as `lsq` and a floor add them.
        let (first, second) = (1.3e-4, 2.9e-2);
        let mut added = matrix.clone();
        add_membrane(&domain, &mut added, first);
        add_membrane(&domain, &mut added, second);
        let entries = Entries::new(&matrix, &domain)
            .with_membrane(first)
            .with_membrane(second);
        for (k, row) in added.iter().enumerate() {
            for (s, &v) in row.iter().enumerate() {
                assert_eq!(
                    entries.get(k, s).to_bits(),
                    v.to_bits(),
                    "unknown {k}, slot {s}"
                );
                assert_eq!(Entries::new(&matrix, &domain).get(k, s), matrix[k][s]);
            }
        }
        // The membrane itself: the centre of a 3×3 block gets 8 ε, its
        // right neighbour's slot −ε.
        let block = Domain::new(&Mask::from_fn(3, 3, |_, _| true));
        let zero = vec![[0.0; 13]; 9];
        let membrane = Entries::new(&zero, &block).with_membrane(1.0);
        assert_eq!((membrane.get(4, 0), membrane.get(4, 1)), (8.0, -1.0));
    }
}
