//! Where a ray leaving a surface starts: the hit point lifted along the
//! normal, against self-intersection. The path tracer offsets its shadow and
//! bounce rays with `offset`; a shadow bundle's prism is widened by
//! `max_offset` so it holds every ray the path tracer sends.

use glam::Vec3A;

/// Offset of a ray origin off a surface against self-intersection: ~1000×
/// the `f32` rounding of the hit point. (Larger offsets bias lighting: a
/// point lifted by δ towards a light at distance d sees ~2δ/d more of it.)
#[inline]
pub(crate) fn offset(p: Vec3A, n: Vec3A) -> Vec3A {
    p + n * offset_distance(p)
}

#[inline]
fn offset_distance(p: Vec3A) -> f32 {
    1e-4 * p.abs().max_element().max(1.0)
}

/// The largest [`offset`] of a point in the box `[lo, hi]`.
pub(crate) fn max_offset(lo: Vec3A, hi: Vec3A) -> f32 {
    offset_distance(lo.abs().max(hi.abs()))
}
