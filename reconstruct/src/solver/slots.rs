//! The layout of a normal matrix row: each unknown keeps its diagonal and
//! its couplings to the 12 pixels at most two rows later in raster order
//! (every stencil of `operators` fits a 3×3 window, so `CᵀC` couples pixels
//! at most two apart). The normal equations (`lsq`) are accumulated in it and
//! the factorisations (`cholesky`, `substructure`) read their lower triangle
//! from it.

use crate::domain::Domain;

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

/// Adds `epsilon Σ (z_i − z_j)²` over the 8-neighbour pairs of `domain` to
/// `matrix` (13-slot layout).
pub(crate) fn add_membrane(domain: &Domain, matrix: &mut [[f64; 13]], epsilon: f64) {
    for (k, row) in matrix.iter_mut().enumerate() {
        for (s, v) in row.iter_mut().enumerate() {
            *v = with_membrane(*v, domain, k, s, epsilon);
        }
    }
}

/// Entry `v` at slot `s` of unknown `k` with the membrane of
/// [`add_membrane`] added: `epsilon` once per 8-neighbour on the diagonal
/// (added one at a time, as the pairs would add it), `−epsilon` on a
/// neighbour's slot.
#[inline]
fn with_membrane(v: f64, domain: &Domain, k: usize, s: usize, epsilon: f64) -> f64 {
    if s == 0 {
        let (x, y) = domain.pixel(k);
        let (x, y) = (x as isize, y as isize);
        (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
            .filter(|&(dx, dy)| (dx, dy) != (0, 0) && domain.at(x + dx, y + dy).is_some())
            .fold(v, |v, _| v + epsilon)
    } else if NEIGHBOUR_SLOTS.contains(&s) && slot_pixel(domain, k, s).is_some() {
        v - epsilon
    } else {
        v
    }
}

/// A normal matrix in the 13-slot layout as the factorisations read it,
/// optionally with a membrane added entry by entry ([`Self::floored`]), so
/// that a modified matrix needs no copy of the whole.
#[derive(Clone, Copy)]
pub(crate) struct Entries<'a> {
    matrix: &'a [[f64; 13]],
    membrane: Option<(&'a Domain, f64)>,
}

impl<'a> Entries<'a> {
    pub fn new(matrix: &'a [[f64; 13]]) -> Self {
        Entries {
            matrix,
            membrane: None,
        }
    }

    /// The matrix plus `epsilon` times the membrane of `domain`.
    pub fn floored(matrix: &'a [[f64; 13]], domain: &'a Domain, epsilon: f64) -> Self {
        Entries {
            matrix,
            membrane: Some((domain, epsilon)),
        }
    }

    /// Slot `s` of unknown `k`.
    #[inline]
    pub fn get(&self, k: usize, s: usize) -> f64 {
        let v = self.matrix[k][s];
        match self.membrane {
            Some((domain, epsilon)) => with_membrane(v, domain, k, s, epsilon),
            None => v,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::Mask;

    #[test]
    fn floored_entries_are_the_membrane_added_bit_for_bit() {
        // An irregular mask (holes, a ragged edge) and arbitrary entries.
        let mask = Mask::from_fn(9, 7, |x, y| (x * 3 + y * 5) % 7 != 0 && x + y < 13);
        let domain = Domain::new(&mask);
        let matrix: Vec<[f64; 13]> = (0..domain.len())
            .map(|k| std::array::from_fn(|s| ((k * 13 + s) as f64 * 0.37).sin()))
            .collect();
        let epsilon = 1.3e-4;
        let mut added = matrix.clone();
        add_membrane(&domain, &mut added, epsilon);
        let floored = Entries::floored(&matrix, &domain, epsilon);
        for (k, row) in added.iter().enumerate() {
            for (s, &v) in row.iter().enumerate() {
                assert_eq!(
                    floored.get(k, s).to_bits(),
                    v.to_bits(),
                    "unknown {k}, slot {s}"
                );
                assert_eq!(Entries::new(&matrix).get(k, s), matrix[k][s]);
            }
        }
        // The membrane itself: the centre of a 3×3 block gets 8 ε, its
        // right neighbour's slot −ε.
        let block = Domain::new(&Mask::from_fn(3, 3, |_, _| true));
        let zero = vec![[0.0; 13]; 9];
        let eight = Entries::floored(&zero, &block, 1.0).get(4, 0);
        assert_eq!(Entries::floored(&zero, &block, 1.0).get(4, 1), -1.0);
        assert_eq!(eight, 8.0);
    }
}
