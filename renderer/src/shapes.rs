//! Procedural shapes intersected analytically (no tessellation error).

use glam::{Vec2, Vec3A};
use obvhs::aabb::Aabb;

/// A sphere; its normal points outwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3A,
    pub radius: f32,
}

/// A plane through `center` with normal `normal`, infinite or a square of
/// side `size` whose edges follow `u` and `normal × u`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub center: Vec3A,
    pub normal: Vec3A,
    pub u: Vec3A,
    pub half_size: Option<f32>,
}

impl Sphere {
    /// Nearest intersection distance in `(tmin, tmax)` along unit `dir`.
    ///
    /// Uses the perpendicular distance from the centre (Ray Tracing Gems,
    /// ch. 7) instead of `b² − c`, which cancels catastrophically in `f32` when
    /// the ray starts far away: this keeps normals accurate to ~1e-6.
    #[inline]
    pub fn intersect(&self, origin: Vec3A, dir: Vec3A, tmin: f32, tmax: f32) -> Option<f32> {
        let oc = self.center - origin;
        let tca = oc.dot(dir);
        let perp = oc - dir * tca;
        let h2 = self.radius * self.radius - perp.length_squared();
        if h2 < 0.0 {
            return None;
        }
        let h = h2.sqrt();
        [tca - h, tca + h]
            .into_iter()
            .find(|&t| t > tmin && t < tmax)
    }

    #[inline]
    pub fn normal(&self, p: Vec3A) -> Vec3A {
        (p - self.center).normalize()
    }

    /// Equirectangular coordinates: `u` the azimuth `atan2(x, −z)/2π`, `v` the
    /// polar angle from `+y` over `π` (the environment map's layout).
    #[inline]
    pub fn uv(&self, p: Vec3A) -> Vec2 {
        let n = self.normal(p);
        let u = n.x.atan2(-n.z) / std::f32::consts::TAU;
        Vec2::new(
            u.rem_euclid(1.0),
            n.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI,
        )
    }
}

impl Plane {
    /// `normal` must be non-zero; `u` is any direction not parallel to it.
    pub fn new(center: Vec3A, normal: Vec3A, size: Option<f32>) -> Plane {
        let normal = normal.normalize();
        Plane {
            center,
            normal,
            u: normal.any_orthonormal_vector(),
            half_size: size.map(|s| 0.5 * s),
        }
    }

    /// The box around the square; `None` for an infinite plane.
    pub fn bounds(&self) -> Option<Aabb> {
        let h = self.half_size?;
        let reach = (self.u.abs() + self.normal.cross(self.u).abs()) * h;
        Some(Aabb::new(self.center - reach, self.center + reach))
    }

    /// World-unit coordinates along `u` and `normal × u` from the centre
    /// (a texture repeats once per unit length).
    #[inline]
    pub fn uv(&self, p: Vec3A) -> Vec2 {
        let q = p - self.center;
        Vec2::new(q.dot(self.u), q.dot(self.normal.cross(self.u)))
    }

    #[inline]
    pub fn intersect(&self, origin: Vec3A, dir: Vec3A, tmin: f32, tmax: f32) -> Option<f32> {
        let denom = self.normal.dot(dir);
        if denom == 0.0 {
            return None;
        }
        let t = self.normal.dot(self.center - origin) / denom;
        if !(t > tmin && t < tmax) {
            return None;
        }
        if let Some(h) = self.half_size {
            let q = origin + dir * t - self.center;
            let v = self.normal.cross(self.u);
            if q.dot(self.u).abs() > h || q.dot(v).abs() > h {
                return None;
            }
        }
        Some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_hits_near_side_and_exits() {
        let s = Sphere {
            center: Vec3A::ZERO,
            radius: 1.0,
        };
        let t = s.intersect(Vec3A::new(0.6, 0.0, 5.0), -Vec3A::Z, 0.0, f32::INFINITY);
        assert!((t.unwrap() - (5.0 - 0.8)).abs() < 1e-6);
        // From inside: the far wall.
        let t = s.intersect(Vec3A::ZERO, Vec3A::X, 0.0, f32::INFINITY);
        assert!((t.unwrap() - 1.0).abs() < 1e-6);
        assert!(
            s.intersect(Vec3A::new(1.1, 0.0, 5.0), -Vec3A::Z, 0.0, 100.0)
                .is_none()
        );
        assert!(
            s.intersect(Vec3A::new(0.0, 0.0, 5.0), Vec3A::Z, 0.0, 100.0)
                .is_none()
        );
    }

    #[test]
    fn plane_square_bounds() {
        let p = Plane::new(Vec3A::ZERO, Vec3A::Z, Some(2.0));
        assert!(
            p.intersect(Vec3A::new(0.3, 0.3, 1.0), -Vec3A::Z, 0.0, 10.0)
                .is_some()
        );
        assert!(
            p.intersect(Vec3A::new(1.5, 1.5, 1.0), -Vec3A::Z, 0.0, 10.0)
                .is_none()
        );
        let inf = Plane::new(Vec3A::ZERO, Vec3A::Z, None);
        assert!(
            inf.intersect(Vec3A::new(50.0, 0.0, 1.0), -Vec3A::Z, 0.0, 10.0)
                .is_some()
        );
    }
}
