//! Fill-reducing orderings for the normal equations of `lsq`.
//!
//! The normal matrix of a masked image problem is a discretised elliptic
//! operator on a planar grid. Approximate minimum degree (AMD, faer's default)
//! is generic; geometric nested dissection uses the pixel coordinates
//! directly: split the pixel set by a straight separator across its longer
//! side, order both halves recursively and the separator last. On planar
//! grids this bounds the Cholesky fill to O(n log n) and leaves large dense
//! separator blocks that faer's supernodal factorisation handles well.
//!
//! The separator is 2 pixels thick because `CᵀC` couples pixels up to 2
//! apart (rows span a 3×3 neighbourhood).

use crate::solver::domain::Domain;

/// Which fill-reducing ordering the Cholesky factorisation uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ordering {
    /// faer's approximate minimum degree.
    Amd,
    /// Geometric nested dissection on pixel coordinates.
    #[default]
    NestedDissection,
}

impl Ordering {
    pub fn name(self) -> &'static str {
        match self {
            Ordering::Amd => "amd",
            Ordering::NestedDissection => "nested_dissection",
        }
    }
}

/// Sets at most this large are ordered as they come (raster order).
const LEAF: usize = 64;

/// Separator thickness in pixels (the reach of `CᵀC`'s couplings).
const SEPARATOR: u32 = 2;

/// The elimination order for the unknowns `members` (positions 0.. in the
/// system, `order[new] = old`), or `None` to let faer compute AMD.
pub fn fill_reducing(ordering: Ordering, domain: &Domain, members: &[usize]) -> Option<Vec<usize>> {
    match ordering {
        Ordering::Amd => None,
        Ordering::NestedDissection => Some(nested_dissection(domain, members)),
    }
}

/// The nested-dissection elimination order of the unknowns `members`
/// (positions into it, `order[new] = old`).
pub fn nested_dissection(domain: &Domain, members: &[usize]) -> Vec<usize> {
    let mut points = points(domain, members.iter().copied().enumerate());
    let mut order = Vec::with_capacity(points.len());
    dissect(&mut points, &mut order);
    order
}

/// The first nested-dissection cut of the domain unknowns `members`:
/// `[low, high, separator]` (domain unknowns), where no unknown of `low` is
/// within reach of one of `high`. `None` when the set is too small or too
/// thin to cut, or a side would be empty.
pub fn bisect(domain: &Domain, members: &[usize]) -> Option<[Vec<usize>; 3]> {
    let mut points = points(domain, members.iter().map(|&k| (k, k)));
    let (before, after) = cut(&mut points)?;
    if before == 0 || after == 0 {
        return None;
    }
    let ids = |p: &[(u32, u32, usize)]| p.iter().map(|p| p.2).collect::<Vec<_>>();
    let (low, rest) = points.split_at(before);
    let (high, separator) = rest.split_at(after);
    Some([ids(low), ids(high), ids(separator)])
}

/// `(x, y, tag)` of each `(unknown, tag)`.
fn points(domain: &Domain, tagged: impl Iterator<Item = (usize, usize)>) -> Vec<(u32, u32, usize)> {
    tagged
        .map(|(tag, k)| {
            let (x, y) = domain.pixel(k);
            (x as u32, y as u32, tag)
        })
        .collect()
}

/// Appends the nested-dissection order of `points` (`(x, y, position)`) to `order`.
fn dissect(points: &mut [(u32, u32, usize)], order: &mut Vec<usize>) {
    let Some((before, after)) = cut(points) else {
        order.extend(points.iter().map(|p| p.2));
        return;
    };
    let (low, rest) = points.split_at_mut(before);
    let (high, separator) = rest.split_at_mut(after);
    dissect(low, order);
    dissect(high, order);
    order.extend(separator.iter().map(|p| p.2));
}

/// Rearranges `points` into `before the separator | after it | separator`
/// by a straight cut across the longer side at the median, and returns the
/// lengths of the first two parts; `None` (points untouched) for a leaf.
fn cut(points: &mut [(u32, u32, usize)]) -> Option<(usize, usize)> {
    if points.len() <= LEAF {
        return None;
    }
    let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
    for &(x, y, _) in points.iter() {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let along_x = x1 - x0 >= y1 - y0;
    let coord = |p: &(u32, u32, usize)| if along_x { p.0 } else { p.1 };
    if (if along_x { x1 - x0 } else { y1 - y0 }) < 2 * SEPARATOR + 2 {
        return None;
    }
    // Median coordinate, so both halves hold about as many pixels.
    let mid = points.len() / 2;
    points.select_nth_unstable_by_key(mid, coord);
    let cut = coord(&points[mid]);
    let before = partition(points, |p| coord(p) < cut);
    let after = partition(&mut points[before..], |p| coord(p) >= cut + SEPARATOR);
    Some((before, after))
}

/// Moves the elements satisfying `pred` to the front (order not kept);
/// returns how many there are.
fn partition<T>(items: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut front = 0;
    for i in 0..items.len() {
        if pred(&items[i]) {
            items.swap(front, i);
            front += 1;
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::Mask;

    #[test]
    fn nested_dissection_is_a_permutation_with_separators_last() {
        let mask = Mask::from_fn(90, 70, |x, y| (x * 7 + y * 3) % 11 != 0 && x + y > 10);
        let domain = Domain::new(&mask);
        let members: Vec<usize> = (0..domain.len()).collect();
        let forward = fill_reducing(Ordering::NestedDissection, &domain, &members).unwrap();
        let mut seen = vec![false; members.len()];
        for &old in &forward {
            assert!(!seen[old]);
            seen[old] = true;
        }
        assert!(seen.iter().all(|&s| s));
        // The top-level separator is a 2-column band eliminated last: the
        // last pixels ordered share one x (or y) range of width 2.
        let tail: Vec<(usize, usize)> = forward[forward.len() - 40..]
            .iter()
            .map(|&k| domain.pixel(k))
            .collect();
        let (xmin, xmax) = tail
            .iter()
            .fold((usize::MAX, 0), |(a, b), p| (a.min(p.0), b.max(p.0)));
        assert!(
            xmax - xmin < SEPARATOR as usize,
            "tail spans x {xmin}..={xmax}"
        );
        assert!(fill_reducing(Ordering::Amd, &domain, &members).is_none());
    }
}
