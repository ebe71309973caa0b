//! The height map as a triangle mesh in PLY (`mesh.ply` of a result
//! folder, written by `ResultFolder::write_mesh`).

use crate::{Error, Image, Mask, Result};
use std::io::Write;
use std::path::Path;

/// The mask's pixels numbered in row-major order: the mesh's vertices.
struct Vertices {
    width: usize,
    height: usize,
    /// Vertex of each pixel, `None` outside the mask.
    index: Vec<Option<u32>>,
    pixels: Vec<(usize, usize)>,
}

impl Vertices {
    fn new(mask: &Mask) -> Vertices {
        let (width, height) = mask.size();
        let mut index = vec![None; width * height];
        let mut pixels = Vec::with_capacity(mask.count());
        for y in 0..height {
            for x in 0..width {
                if *mask.get(x, y) {
                    index[y * width + x] = Some(pixels.len() as u32);
                    pixels.push((x, y));
                }
            }
        }
        Vertices {
            width,
            height,
            index,
            pixels,
        }
    }

    fn len(&self) -> usize {
        self.pixels.len()
    }

    fn at(&self, x: isize, y: isize) -> Option<usize> {
        if x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height {
            return None;
        }
        self.index[y as usize * self.width + x as usize].map(|k| k as usize)
    }

    fn pixel(&self, k: usize) -> (usize, usize) {
        self.pixels[k]
    }
}

/// Writes the height map over `mask` as a binary little-endian PLY mesh.
///
/// Vertices are pixel centres in the camera frame, in pixel units:
/// `X = col + 0.5`, `Y = rows − (row + 0.5)` (y up), `Z = height`. Each 2×2
/// block of mask pixels gives two triangles (one if only three are inside),
/// wound counter-clockwise as seen from the camera (+z).
pub fn write_height_mesh(path: &Path, height: &Image<f32>, mask: &Mask) -> Result<()> {
    if !height.same_size(mask) {
        return Err(Error::file(path, "height map and mask differ in size"));
    }
    let vertices = Vertices::new(mask);
    let (w, h) = mask.size();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    for y in 0..h.saturating_sub(1) as isize {
        for x in 0..w.saturating_sub(1) as isize {
            // Corners as seen on screen: top-left, top-right, bottom-left, bottom-right.
            let tl = vertices.at(x, y);
            let tr = vertices.at(x + 1, y);
            let bl = vertices.at(x, y + 1);
            let br = vertices.at(x + 1, y + 1);
            // Counter-clockwise on screen with y up: bl → br → tr, bl → tr → tl.
            let tris = match (tl, tr, bl, br) {
                (Some(a), Some(b), Some(c), Some(d)) => vec![[c, d, b], [c, b, a]],
                (None, Some(b), Some(c), Some(d)) => vec![[c, d, b]],
                (Some(a), None, Some(c), Some(d)) => vec![[c, d, a]],
                (Some(a), Some(b), None, Some(d)) => vec![[d, b, a]],
                (Some(a), Some(b), Some(c), None) => vec![[c, b, a]],
                _ => vec![],
            };
            faces.extend(tris.into_iter().map(|t| t.map(|v| v as u32)));
        }
    }
    let mut out = Vec::with_capacity(vertices.len() * 12 + faces.len() * 13 + 256);
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment polar-sfp height map, pixel units, camera frame (y up)\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    )
    .expect("writing to memory");
    for k in 0..vertices.len() {
        let (x, y) = vertices.pixel(k);
        let v = [
            x as f32 + 0.5,
            h as f32 - (y as f32 + 0.5),
            *height.get(x, y),
        ];
        for c in v {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in &faces {
        out.push(3);
        for v in f {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, out).map_err(|e| Error::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ply_has_expected_counts() {
        let mask = Mask::from_fn(4, 3, |x, y| !(x == 3 && y == 2));
        let height = Image::new(4, 3, 1.0f32);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("mesh.ply");
        write_height_mesh(&path, &height, &mask).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        // 11 vertices; 2×3 blocks: 5 full (10 triangles) + 1 with three corners.
        assert!(text.contains("element vertex 11\n"));
        assert!(text.contains("element face 11\n"));
        let header = text.find("end_header\n").unwrap() + "end_header\n".len();
        assert_eq!(bytes.len(), header + 11 * 12 + 11 * 13);
    }
}
