//! Normal mapping: the shading normal of fine surface detail that the mesh
//! does not model.
//!
//! Two sources, each with the tangent frame it needs:
//! - **Bump mapping** of a procedural height field `h(p)` over object space:
//!   no texture coordinates needed, the frame is the height field's own 3-D
//!   gradient. Displacing the surface by `h` along `n` tilts the normal by the
//!   surface gradient `∇h − (∇h·n) n` (Mikkelsen, "Surface gradient based bump
//!   mapping", 2020): `n' = normalize(n − ∇_s h)`.
//! - **Tangent-space normal textures** (PNG/EXR, glTF `normalTexture`): RGB
//!   `(t, b, n)` components in `[0, 1]` mapped to `[−1, 1]`, in the frame of
//!   the mesh's texture coordinates (`t = ∂p/∂u`, `b` completes it with `n`).
//!
//! A mapped normal may turn away from the viewer, where the macro-surface is
//! still visible: [`face_viewer`] tilts it back towards `ω_o` (the usual fix;
//! the light side is guarded by the geometric normal in the integrator).

use glam::Vec3A;

/// Smallest `n'·ω_o` a mapped normal keeps.
const MIN_COS_VIEW: f32 = 0.01;

/// `n` bumped by the world-space gradient `g` of a height field.
#[inline]
pub fn bump(n: Vec3A, g: Vec3A) -> Vec3A {
    let surface_gradient = g - n * g.dot(n);
    (n - surface_gradient).normalize_or(n)
}

/// A tangent-space normal `c` (components in `[−1, 1]`: along `t`, along
/// `b = n × t`, along `n`) expressed in the world frame of unit normal `n` and
/// tangent direction `t` (made orthogonal to `n` here).
#[inline]
pub fn from_tangent_space(n: Vec3A, t: Vec3A, c: Vec3A) -> Vec3A {
    let t = (t - n * t.dot(n)).normalize_or(n.any_orthonormal_vector());
    let b = n.cross(t);
    (t * c.x + b * c.y + n * c.z.max(0.0)).normalize_or(n)
}

/// `n` tilted just enough towards `wo` that `n·ω_o ≥ MIN_COS_VIEW`.
#[inline]
pub fn face_viewer(n: Vec3A, wo: Vec3A) -> Vec3A {
    let c = n.dot(wo);
    if c >= MIN_COS_VIEW {
        n
    } else {
        (n + wo * (2.0 * MIN_COS_VIEW - c)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bump_of_a_height_field_is_the_displaced_surface_normal() {
        // Plane z = h(x, y) with ∇h = (a, b): normal ∝ (−a, −b, 1), whatever
        // the gradient's component along the normal.
        let (a, b) = (0.3f32, -0.7f32);
        for gz in [0.0f32, 5.0] {
            let n = bump(Vec3A::Z, Vec3A::new(a, b, gz));
            let expect = Vec3A::new(-a, -b, 1.0).normalize();
            assert!((n - expect).length() < 1e-6, "{n} vs {expect}");
        }
    }

    #[test]
    fn tangent_space_axes_map_to_the_frame() {
        let n = Vec3A::new(0.0, 0.0, 1.0);
        let t = Vec3A::new(1.0, 0.0, 0.3); // not orthogonal: projected
        let flat = from_tangent_space(n, t, Vec3A::Z);
        assert!((flat - n).length() < 1e-6);
        let tilted = from_tangent_space(n, t, Vec3A::new(0.6, 0.0, 0.8));
        assert!((tilted - Vec3A::new(0.6, 0.0, 0.8)).length() < 1e-6);
        let along_b = from_tangent_space(n, t, Vec3A::new(0.0, 0.6, 0.8));
        assert!((along_b - Vec3A::new(0.0, 0.6, 0.8)).length() < 1e-6);
    }

    #[test]
    fn normals_facing_away_are_tilted_back() {
        let wo = Vec3A::new(0.0, 0.0, 1.0);
        let kept = Vec3A::new(0.6, 0.0, 0.8);
        assert_eq!(face_viewer(kept, wo), kept);
        let away = Vec3A::new(0.8, 0.0, -0.6);
        let fixed = face_viewer(away, wo);
        assert!(fixed.dot(wo) >= MIN_COS_VIEW && (fixed.length() - 1.0).abs() < 1e-6);
        assert!(fixed.x > 0.9, "keeps its azimuth: {fixed}");
    }
}
