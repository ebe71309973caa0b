//! The mask the method solves on (spec §1): every pixel keeps at least one
//! horizontal and one vertical 4-neighbour, so both derivatives of every
//! pixel exist, and no 4-connected piece is smaller than [`MIN_PIECE`].
//! The rule removes pixels until nothing changes, as the authors' code does
//! by recursion.

use sfp_core::Mask;

/// 4-connected pieces smaller than this are removed.
pub const MIN_PIECE: usize = 5;

/// The refined mask (module doc).
pub fn refine(mask: &Mask) -> Mask {
    let mut mask = mask.clone();
    loop {
        for piece in pieces4(&mask) {
            if piece.len() < MIN_PIECE {
                piece.iter().for_each(|&i| mask.data_mut()[i] = false);
            }
        }
        let lone: Vec<usize> = (0..mask.len())
            .filter(|&i| {
                let (w, _) = mask.size();
                let (x, y) = (i % w, i / w);
                let at = |dx: isize, dy: isize| inside(&mask, x as isize + dx, y as isize + dy);
                *mask.get(x, y) && (!(at(-1, 0) || at(1, 0)) || !(at(0, -1) || at(0, 1)))
            })
            .collect();
        if lone.is_empty() {
            return mask;
        }
        lone.iter().for_each(|&i| mask.data_mut()[i] = false);
    }
}

/// Whether `(x, y)` is inside the image and the mask.
pub fn inside(mask: &Mask, x: isize, y: isize) -> bool {
    let (w, h) = mask.size();
    x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h && *mask.get(x as usize, y as usize)
}

/// The 4-connected pieces of `mask` as raster indices, ordered by their
/// first pixel in column-major order (the order the authors' labelling
/// gives, which the layer tracing follows).
pub fn pieces4(mask: &Mask) -> Vec<Vec<usize>> {
    let (w, h) = mask.size();
    let mut seen = vec![false; mask.len()];
    let mut pieces = Vec::new();
    let mut stack = Vec::new();
    for x in 0..w {
        for y in 0..h {
            let start = y * w + x;
            if !mask.data()[start] || seen[start] {
                continue;
            }
            seen[start] = true;
            stack.push(start);
            let mut piece = Vec::new();
            while let Some(i) = stack.pop() {
                piece.push(i);
                let (px, py) = ((i % w) as isize, (i / w) as isize);
                for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                    let (nx, ny) = (px + dx, py + dy);
                    if inside(mask, nx, ny) {
                        let j = ny as usize * w + nx as usize;
                        if !seen[j] {
                            seen[j] = true;
                            stack.push(j);
                        }
                    }
                }
            }
            pieces.push(piece);
        }
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::mask_of as mask;

    #[test]
    fn spurs_and_small_pieces_are_peeled_until_stable() {
        // A 3×3 block with a two-pixel spur to the right (no vertical
        // neighbour: removed) and a 5-pixel piece whose lower-left pixel has
        // no vertical neighbour: once it goes, 4 pixels are too few.
        let m = mask(&[
            "...........",
            ".###.......",
            ".#####..##.",
            ".###...###.",
            "...........",
        ]);
        let refined = refine(&m);
        let expected = mask(&[
            "...........",
            ".###.......",
            ".###.......",
            ".###.......",
            "...........",
        ]);
        assert_eq!(refined.data(), expected.data());
        assert_eq!(refine(&refined).data(), refined.data());
    }

    #[test]
    fn pieces_come_in_column_major_order() {
        let m = mask(&["..#", "#..", "..#"]);
        let pieces = pieces4(&m);
        assert_eq!(pieces, vec![vec![3], vec![2], vec![8]]);
    }
}
