//! Cameras: orthographic (the paper's setting, `v = [0, 0, 1]` at every pixel)
//! and pinhole perspective. Both define the camera frame of conventions.md §1:
//! `+x` right, `+y` up, `+z` towards the viewer (the camera looks along `−z`).

use glam::Vec3A;

/// Projection of a camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// `extent` = world width the image spans.
    Orthographic { extent: f32 },
    /// `fov` = horizontal field of view in radians.
    Perspective { fov: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub width: usize,
    pub height: usize,
    pub position: Vec3A,
    /// Camera `+x`, `+y` and `+z` in world coordinates (orthonormal).
    pub right: Vec3A,
    pub up: Vec3A,
    pub back: Vec3A,
    pub projection: Projection,
    /// Half-widths of the image plane at unit distance (perspective) or in
    /// world units (orthographic), along camera `x` and `y`: set once, as
    /// every camera ray needs them.
    half_size: (f32, f32),
}

/// A primary ray: origin and unit direction in world space.
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub origin: Vec3A,
    pub dir: Vec3A,
}

impl Camera {
    /// Builds the camera frame from `position`, `look_at` and `up`; `None` when
    /// they are degenerate (coincident points, `up` parallel to the view).
    pub fn look_at(
        width: usize,
        height: usize,
        position: Vec3A,
        look_at: Vec3A,
        up: Vec3A,
        projection: Projection,
    ) -> Option<Camera> {
        let forward = (look_at - position).try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let up = right.cross(forward);
        let half_w = match projection {
            Projection::Orthographic { extent } => 0.5 * extent,
            Projection::Perspective { fov } => (0.5 * fov).tan(),
        };
        Some(Camera {
            width,
            height,
            position,
            right,
            up,
            back: -forward,
            projection,
            half_size: (half_w, half_w * height as f32 / width as f32),
        })
    }

    /// Ray through image position `(px, py)` in pixels (`(col + 0.5, row + 0.5)`
    /// is a pixel centre; row 0 is the top).
    #[inline]
    pub fn ray(&self, px: f32, py: f32) -> CameraRay {
        let (hw, hh) = self.half_size;
        let x = (2.0 * px / self.width as f32 - 1.0) * hw;
        let y = (1.0 - 2.0 * py / self.height as f32) * hh;
        match self.projection {
            Projection::Orthographic { .. } => CameraRay {
                origin: self.position + self.right * x + self.up * y,
                dir: -self.back,
            },
            Projection::Perspective { .. } => CameraRay {
                origin: self.position,
                dir: (self.right * x + self.up * y - self.back).normalize(),
            },
        }
    }

    /// The Stokes frame x axis in which the camera records light arriving
    /// against `dir`: camera `+x`, made perpendicular to the ray.
    #[inline]
    pub fn stokes_axis(&self, dir: Vec3A) -> Vec3A {
        (self.right - dir * self.right.dot(dir)).normalize()
    }

    /// World vector → camera frame.
    #[inline]
    pub fn to_camera(&self, v: Vec3A) -> Vec3A {
        Vec3A::new(v.dot(self.right), v.dot(self.up), v.dot(self.back))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_and_pixel_mapping() {
        let cam = Camera::look_at(
            4,
            2,
            Vec3A::new(0.0, 0.0, 5.0),
            Vec3A::ZERO,
            Vec3A::Y,
            Projection::Orthographic { extent: 2.0 },
        )
        .unwrap();
        assert_eq!(
            (cam.right, cam.up, cam.back),
            (Vec3A::X, Vec3A::Y, Vec3A::Z)
        );
        // Top-left pixel centre: x = −0.75, y = +0.25 (height spans 1.0).
        let r = cam.ray(0.5, 0.5);
        assert!((r.origin - Vec3A::new(-0.75, 0.25, 5.0)).length() < 1e-6);
        assert_eq!(r.dir, -Vec3A::Z);
        let fov = 90f32.to_radians();
        let p = Camera::look_at(
            4,
            2,
            cam.position,
            Vec3A::ZERO,
            Vec3A::Y,
            Projection::Perspective { fov },
        )
        .unwrap();
        let d = p.ray(4.0, 1.0).dir; // right edge, middle row: 45° to the right
        assert!((d - Vec3A::new(1.0, 0.0, -1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn degenerate_setup_is_rejected() {
        let o = Projection::Orthographic { extent: 1.0 };
        assert!(Camera::look_at(2, 2, Vec3A::Z, Vec3A::Z, Vec3A::Y, o).is_none());
        assert!(Camera::look_at(2, 2, Vec3A::Z, Vec3A::ZERO, Vec3A::Z, o).is_none());
    }
}
