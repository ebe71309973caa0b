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
