//! Ray bundles: rays traced against the BVH together. A bundle's rays lie
//! in a frustum: the thin prism (orthographic) or pyramid (pinhole) spanned
//! by the rays through a pixel's four corners, or the prism of parallel
//! shadow rays leaving a small box. One traversal with that frustum collects
//! every leaf any of the rays can reach; each ray then tests only those
//! leaves, nearest first, instead of walking the tree from the root. The
//! hits are those of single-ray traversal: the same box and triangle tests
//! decide them, on leaves the frustum test keeps conservatively. Which rays
//! form a bundle is `pixel_bundles`'s choice.

use crate::camera::{Camera, Projection};
use crate::ray_offset::max_offset;
use glam::{Vec3A, Vec4};
use obvhs::aabb::Aabb;

/// The volume swept by a pixel's camera rays: points `p` with
/// `n·p ≥ c` for every plane `(n, c)`.
#[derive(Clone, Copy, Debug)]
pub struct Frustum {
    /// Inward normal in `xyz`, offset `c` in `w`.
    planes: [Vec4; 5],
    count: usize,
    /// Parallel rays: their direction `d` and the largest `d·origin`
    /// (orthographic camera rays: the same for all, whose origins lie in the
    /// image plane); pinhole: `None`, the rays start at `eye`.
    parallel: Option<(Vec3A, f32)>,
    eye: Vec3A,
    /// A pixel's frustum: the cone around it, for balls.
    cone: Option<Cone>,
}

/// A cone holding a pixel's rays: about the centre ray from `apex` along
/// unit `axis`, of radius `radius + slope·t` at `t` along it (a cylinder
/// for an orthographic camera, `radius = 0` for a pinhole).
#[derive(Clone, Copy, Debug)]
struct Cone {
    apex: Vec3A,
    axis: Vec3A,
    radius: f32,
    slope: f32,
}

/// Relative slack of the plane tests: a box is dropped only when it is
/// outside a plane by more than rounding can explain.
const SLACK: f32 = 1e-5;

impl Frustum {
    /// The frustum of pixel `(x, y)` (column, row), widened by 1% of a pixel
    /// on each side so that rays through its edges are inside despite
    /// rounding.
    pub fn of_pixel(camera: &Camera, x: usize, y: usize) -> Frustum {
        let (x0, x1) = (x as f32 - 0.01, x as f32 + 1.01);
        let (y0, y1) = (y as f32 - 0.01, y as f32 + 1.01);
        // Corners counter-clockwise as seen from the camera (image rows go down).
        let corners = [(x0, y1), (x1, y1), (x1, y0), (x0, y0)].map(|(px, py)| camera.ray(px, py));
        let centre = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
        let inside = centre.origin + centre.dir;
        let mut planes = [Vec4::ZERO; 5];
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let n = match camera.projection {
                Projection::Orthographic { .. } => (b.origin - a.origin).cross(a.dir),
                Projection::Perspective { .. } => a.dir.cross(b.dir),
            }
            .normalize();
            let n = if n.dot(inside - a.origin) < 0.0 {
                -n
            } else {
                n
            };
            planes[k] = n.extend(n.dot(a.origin));
        }
        let (count, parallel) = match camera.projection {
            // A prism extends behind the image plane too: cut it there.
            Projection::Orthographic { .. } => {
                let d = centre.dir;
                planes[4] = d.extend(d.dot(centre.origin));
                (5, Some((d, d.dot(centre.origin))))
            }
            Projection::Perspective { .. } => (4, None),
        };
        // Distance of a corner ray's origin from the axis, and the tangent
        // of its angle to it: the cone's rays are all inside.
        let axis = centre.dir;
        let (mut radius, mut slope) = (0.0f32, 0.0f32);
        for c in corners {
            let o = c.origin - centre.origin;
            radius = radius.max((o - axis * o.dot(axis)).length());
            let along = c.dir.dot(axis);
            slope = slope.max((c.dir - axis * along).length() / along);
        }
        Frustum {
            planes,
            count,
            parallel,
            eye: centre.origin,
            cone: Some(Cone {
                apex: centre.origin,
                axis,
                radius: radius * (1.0 + SLACK),
                slope: slope * (1.0 + SLACK),
            }),
        }
    }

    /// The prism swept by rays along unit `dir` from any point of the box
    /// `[lo, hi]`.
    fn sweep(lo: Vec3A, hi: Vec3A, dir: Vec3A) -> Frustum {
        let (u, v) = dir.any_orthonormal_pair();
        let corners = (0..8).map(|k| {
            Vec3A::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        });
        let mut range = [(f32::INFINITY, f32::NEG_INFINITY); 3];
        for c in corners {
            for (r, axis) in range.iter_mut().zip([u, v, dir]) {
                let x = axis.dot(c);
                *r = (r.0.min(x), r.1.max(x));
            }
        }
        let [ru, rv, rd] = range;
        Frustum {
            planes: [
                u.extend(ru.0),
                (-u).extend(-ru.1),
                v.extend(rv.0),
                (-v).extend(-rv.1),
                dir.extend(rd.0),
            ],
            count: 5,
            parallel: Some((dir, rd.1)),
            eye: Vec3A::ZERO,
            cone: None,
        }
    }

    /// The prism of the shadow rays towards a distant light along `dir`
    /// that leave hit points in `[lo, hi]`, each lifted off its surface by
    /// at most [`max_offset`] (doubled against rounding).
    pub fn of_shadows(lo: Vec3A, hi: Vec3A, dir: Vec3A) -> Frustum {
        let margin = 2.0 * max_offset(lo, hi);
        Frustum::sweep(lo - margin, hi + margin, dir)
    }

    /// Whether some point of `b` may lie inside (conservative).
    #[inline]
    pub fn may_overlap(&self, b: &Aabb) -> bool {
        self.planes[..self.count].iter().all(|p| {
            let n = Vec3A::from(p.truncate());
            // The corner farthest along n.
            let far = Vec3A::select(n.cmpge(Vec3A::ZERO), b.max, b.min);
            let slack = SLACK * (p.w.abs() + n.abs().dot(far.abs()));
            n.dot(far) >= p.w - slack
        })
    }

    /// Whether some point of the ball of radius `r` about `c` may lie
    /// inside (conservative): the ball is not wholly outside any plane, nor
    /// outside a pixel's cone (which the planes alone miss for a ball
    /// beside a corner of the pixel).
    pub fn may_overlap_ball(&self, c: Vec3A, r: f32) -> bool {
        let planes = self.planes[..self.count].iter().all(|p| {
            let n = Vec3A::from(p.truncate());
            let slack = SLACK * (p.w.abs() + n.abs().dot(c.abs()) + r);
            n.dot(c) + r >= p.w - slack
        });
        planes
            && self.cone.is_none_or(|k| {
                let v = c - k.apex;
                let t = v.dot(k.axis);
                // Near or behind the apex: kept.
                if t <= r {
                    return true;
                }
                // The ball reaches the cone's surface when its centre is
                // within r / cos(half-angle) of it, measured across the axis.
                let d = (v - k.axis * t).length();
                let reach = k.radius + k.slope * t + r * (1.0 + k.slope * k.slope).sqrt();
                d <= reach + SLACK * (v.length() + r + k.apex.abs().max_element())
            })
    }

    /// A lower bound on the distance `t` at which any ray of the bundle can
    /// reach a point of `b`.
    #[inline]
    pub fn near(&self, b: &Aabb) -> f32 {
        let t = match self.parallel {
            Some((d, c)) => {
                let close = Vec3A::select(d.cmpge(Vec3A::ZERO), b.min, b.max);
                let dc = d.dot(close);
                dc - c - SLACK * (dc.abs() + c.abs())
            }
            None => {
                let closest = self.eye.clamp(b.min, b.max);
                let dist = (closest - self.eye).length();
                dist - SLACK * (dist + self.eye.abs().max_element())
            }
        };
        t.max(0.0)
    }
}

/// A leaf a bundle can reach: its box, its triangles (`first..first +
/// count` in BVH order) and the bundle's lower bound on reaching it.
#[derive(Clone, Copy, Debug)]
pub struct Leaf {
    pub aabb: Aabb,
    pub first: u32,
    pub count: u32,
    pub near: f32,
}

/// Reusable storage of a bundle traversal.
#[derive(Default)]
pub struct Bundle {
    /// Leaves sorted by `near`.
    pub leaves: Vec<Leaf>,
    pub stack: Vec<u32>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray_offset::offset;
    use crate::sampler::{Sampler, Stream};
    use crate::scene::Scene;
    use crate::world::World;
    use std::path::Path;

    /// A snowman (self-occluding spheres and arms) and a cup over a ground
    /// plane, seen by `camera`, lit from `light`.
    fn world(camera: &str) -> World {
        let text = format!(
            r#"
[camera]
{camera}
width = 24
height = 24
position = [0.3, 0.4, 4.0]
look_at = [0.0, 0.0, 0.0]
[[light]]
type = "directional"
direction = [0.5, 0.7, 0.6]
irradiance = 3.0
[[object]]
builtin = "snowman"
material = {{ type = "diffuse_polarized", albedo = 0.8, eta = 1.5 }}
[[object]]
builtin = "cup"
translate = [0.6, -0.3, 0.5]
scale = 0.5
material = {{ type = "diffuse_polarized", albedo = 0.8, eta = 1.5 }}
"#
        );
        World::build(&Scene::from_toml(&text, Path::new("bundle.toml")).unwrap()).unwrap()
    }

    /// Every jittered camera ray of every pixel finds the same hit (distance
    /// and triangle) among its pixel's gathered leaves as by single-ray
    /// traversal, and every shadow ray from those hits towards the light is
    /// blocked exactly when single-ray traversal says so.
    #[test]
    fn bundles_find_the_hits_of_single_rays() {
        for camera in [
            "type = \"orthographic\"\nextent = 2.6",
            "type = \"perspective\"\nfov = 40.0",
        ] {
            let w = world(camera);
            let light = w.lights[0].parallel_direction().unwrap();
            let mut s = Sampler::new(1, Stream::Path, 0, 0, 0);
            let (mut bundle, mut shadow) = (Bundle::default(), Bundle::default());
            let (mut hits, mut shadow_rays, mut blocked) = (0, 0, 0);
            for y in 0..w.camera.height {
                for x in 0..w.camera.width {
                    w.gather(&Frustum::of_pixel(&w.camera, x, y), &mut bundle);
                    let rays: Vec<_> = (0..16)
                        .map(|_| {
                            let [u, v] = s.next_2d();
                            w.camera.ray(x as f32 + u, y as f32 + v)
                        })
                        .collect();
                    let found: Vec<_> = rays
                        .iter()
                        .filter_map(|r| {
                            let one = w.intersect(None, r.origin, r.dir, 0.0, f32::INFINITY);
                            let all =
                                w.intersect(Some(&bundle), r.origin, r.dir, 0.0, f32::INFINITY);
                            assert_eq!(
                                one.map(|h| (h.t, h.prim)),
                                all.map(|h| (h.t, h.prim)),
                                "{camera}, pixel ({x}, {y})"
                            );
                            one.map(|h| (h, r.dir))
                        })
                        .collect();
                    let Some(first) = found.first() else { continue };
                    hits += found.len();
                    let (lo, hi) = found
                        .iter()
                        .fold((first.0.p, first.0.p), |(lo, hi), (h, _)| {
                            (lo.min(h.p), hi.max(h.p))
                        });
                    w.gather(&Frustum::of_shadows(lo, hi, light), &mut shadow);
                    // As the integrator does: the normal faces the viewer,
                    // and only points facing the light send a shadow ray.
                    for (h, dir) in &found {
                        let ng = h.facing(-*dir).0;
                        if ng.dot(light) <= 0.0 {
                            continue;
                        }
                        let p = offset(h.p, ng);
                        let one = w.occluded(None, p, light, 0.0, f32::INFINITY);
                        let all = w.occluded(Some(&shadow), p, light, 0.0, f32::INFINITY);
                        assert_eq!(one, all, "{camera}, pixel ({x}, {y})");
                        shadow_rays += 1;
                        blocked += usize::from(one);
                    }
                }
            }
            // The scene exercises both outcomes.
            assert!(
                hits > 2000 && blocked > 100 && blocked + 100 < shadow_rays,
                "{hits} hits, {shadow_rays} shadow rays, {blocked} blocked"
            );
        }
    }

    /// A pixel whose frustum misses every sphere and square sends no ray
    /// that hits one (off-centre spheres, near and far, and a square seen
    /// at an angle), and the test leaves out most empty pixels.
    #[test]
    fn pixels_that_see_nothing_hit_nothing() {
        for camera in [
            "type = \"orthographic\"\nextent = 2.6",
            "type = \"perspective\"\nfov = 40.0",
        ] {
            let text = format!(
                r#"
[camera]
{camera}
width = 32
height = 32
position = [0.3, 0.4, 4.0]
look_at = [0.0, 0.0, 0.0]
[[light]]
type = "directional"
direction = [0.5, 0.7, 0.6]
irradiance = 3.0
[[object]]
shape = "sphere"
center = [-0.5, 0.3, 0.0]
radius = 0.45
material = {{ type = "diffuse_polarized", albedo = 0.8, eta = 1.5 }}
[[object]]
shape = "sphere"
center = [0.6, -0.5, 1.5]
radius = 0.2
material = {{ type = "diffuse_polarized", albedo = 0.8, eta = 1.5 }}
[[object]]
shape = "plane"
center = [0.5, 0.6, -0.5]
normal = [0.3, 0.2, 1.0]
size = 0.5
material = {{ type = "diffuse_polarized", albedo = 0.8, eta = 1.5 }}
"#
            );
            let w =
                World::build(&Scene::from_toml(&text, Path::new("empty.toml")).unwrap()).unwrap();
            let mut s = Sampler::new(1, Stream::Path, 0, 0, 0);
            let (mut empty, mut culled) = (0, 0);
            for y in 0..w.camera.height {
                for x in 0..w.camera.width {
                    let sees = w.may_see(&Frustum::of_pixel(&w.camera, x, y));
                    let hits = (0..64).any(|_| {
                        let [u, v] = s.next_2d();
                        let r = w.camera.ray(x as f32 + u, y as f32 + v);
                        w.intersect(None, r.origin, r.dir, 0.0, f32::INFINITY)
                            .is_some()
                    });
                    assert!(sees || !hits, "{camera}, pixel ({x}, {y})");
                    empty += usize::from(!hits);
                    culled += usize::from(!sees);
                }
            }
            assert!(
                culled * 10 > empty * 9,
                "{camera}: {culled} of {empty} culled"
            );
        }
    }
}
