//! Bundles per pixel: all the camera rays of one pixel are traced against
//! the BVH as one bundle (`bundle`). A pixel's samples are jittered inside
//! its footprint, so they lie in the frustum of its four corners. The shadow
//! rays those hits send to a distant light are parallel too, and start in a
//! small box: they are traced as a second bundle, one per such light.

use crate::bundle::{Bundle, Frustum};
use crate::camera::CameraRay;
use crate::sampler::Sampler;
use crate::world::{Hit, World};
use glam::Vec3A;

/// The first vertex of a path whose camera ray was traced in a bundle: its
/// hit, and the shadow bundles of the distant lights there.
#[derive(Clone, Copy)]
pub struct FirstVertex<'a> {
    pub hit: Option<Hit>,
    pub shadows: &'a [ShadowBundle],
}

/// The shadow rays of a pixel's first hits towards one delta distant light.
pub struct ShadowBundle {
    /// Index of the light in [`World::lights`].
    pub light: usize,
    dir: Vec3A,
    pub bundle: Bundle,
}

/// A pixel's bundles and camera samples, reused from pixel to pixel (one per
/// row a rendering thread renders, so nothing is allocated per pixel).
pub struct PixelBundles {
    camera: Bundle,
    shadows: Vec<ShadowBundle>,
    samples: Vec<(Sampler, CameraRay, Option<Hit>)>,
}

impl PixelBundles {
    pub fn new(world: &World, spp: u32) -> PixelBundles {
        let shadows = (world.lights.iter().enumerate())
            .filter_map(|(light, l)| {
                let dir = l.parallel_direction()?;
                Some(ShadowBundle {
                    light,
                    dir,
                    bundle: Bundle::default(),
                })
            })
            .collect();
        PixelBundles {
            camera: Bundle::default(),
            shadows,
            samples: Vec::with_capacity(spp as usize),
        }
    }

    /// Traces the `spp` samples of a pixel, whose rays lie in `frustum`
    /// ([`Frustum::of_pixel`]): `sample(s)` gives sample
    /// `s`'s sampler (after its camera draws) and camera ray; the camera
    /// rays are intersected as one bundle, the shadow bundles gathered at
    /// their hits, and then `path` traces each sample from its first vertex.
    pub fn trace_pixel(
        &mut self,
        world: &World,
        frustum: &Frustum,
        spp: u32,
        sample: impl Fn(u32) -> (Sampler, CameraRay),
        mut path: impl FnMut(Sampler, CameraRay, Option<FirstVertex>),
    ) {
        world.gather(frustum, &mut self.camera);
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        self.samples.clear();
        for s in 0..spp {
            let (sampler, ray) = sample(s);
            let hit = world.intersect(Some(&self.camera), ray.origin, ray.dir, 0.0, f32::INFINITY);
            if let Some(h) = hit {
                (lo, hi) = (lo.min(h.p), hi.max(h.p));
            }
            self.samples.push((sampler, ray, hit));
        }
        for shadow in &mut self.shadows {
            if lo.x <= hi.x {
                world.gather(&Frustum::of_shadows(lo, hi, shadow.dir), &mut shadow.bundle);
            } else {
                shadow.bundle.leaves.clear();
            }
        }
        let shadows = &self.shadows;
        for (sampler, ray, hit) in self.samples.drain(..) {
            path(sampler, ray, Some(FirstVertex { hit, shadows }));
        }
    }
}
