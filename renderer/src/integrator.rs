//! Polarized path tracing with next-event estimation.
//!
//! Paths start at the camera, so each carries the Mueller matrix `T` that maps
//! a Stokes vector arriving at its current vertex (in the frame with x axis
//! `frame`, light travelling back along the path) to the Stokes vector the
//! camera records (camera frame, conventions.md §1). Every interaction first
//! rotates into the material's standard frames (see `bsdf`), then multiplies
//! by the BSDF's Mueller matrix. Emission is unpolarized, so a light of
//! radiance `L` adds `L · T · f · (1, 0, 0, 0)`.
//!
//! `max_depth` counts surface interactions: 1 = direct lighting only.
//! Environment and area light are combined from light and BSDF sampling by
//! the power heuristic; delta lights (directional, point) only by light
//! sampling.
//!
//! With `split_specular`, a path also returns the part of its Stokes vector
//! that went through the specular lobe at its first surface interaction
//! (the ground truth of the diffuse/specular mixture, conventions.md §5): a
//! second Mueller product `T_s` follows the path from the first bounce on,
//! and at the first vertex the specular lobe is evaluated apart. The random
//! draws are the same either way.
//!
//! **Channels.** A path carries `N` Mueller products, one per colour
//! channel (`N = 1`: grey, `N = 3`: R, G, B), which differ only through
//! the albedo of each channel: the three channels share every ray, light
//! sample and BSDF sample (drawn from the material's grey albedo), so a
//! colour render traces the rays of a grey one. With `N = 1` every
//! operation is the grey tracer's, in the same order.

use crate::bsdf::Bsdf;
use crate::bundle::Bundle;
use crate::lights::LightSample;
use crate::mueller::{Mueller, Stokes4, s_axis};
use crate::pixel_bundles::FirstVertex;
use crate::ray_offset::offset;
use crate::sampler::Sampler;
use crate::world::World;
use glam::Vec3A;

/// Path settings.
#[derive(Clone, Copy, Debug)]
pub struct PathSettings {
    pub max_depth: u32,
    pub rr_depth: u32,
    /// Also return the specular part of the first interaction.
    pub split_specular: bool,
}

/// What one path returned per channel, and how many rays it cost.
#[derive(Clone, Copy, Debug)]
pub struct PathResult<const N: usize> {
    pub stokes: [Stokes4; N],
    /// The part of `stokes` whose first surface interaction took the
    /// specular lobe (zero unless `split_specular`).
    pub specular: [Stokes4; N],
    pub rays: u32,
}

impl<const N: usize> Default for PathResult<N> {
    fn default() -> Self {
        PathResult {
            stokes: [[0.0; 4]; N],
            specular: [[0.0; 4]; N],
            rays: 0,
        }
    }
}

#[inline]
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 == 0.0 { 0.0 } else { a2 / (a2 + b2) }
}

#[inline]
fn add_scaled(acc: &mut Stokes4, s: Stokes4, k: f32) {
    for (a, v) in acc.iter_mut().zip(s) {
        *a += v * k;
    }
}

/// A path vertex seen from the lights: its BSDF, the path's Mueller product
/// up to it, the offset shading point `p`, the geometric normal `ng` and
/// how its light counts towards the specular part.
struct Vertex<'a, const N: usize> {
    bsdf: &'a Bsdf,
    t: &'a [Mueller; N],
    p: Vec3A,
    ng: Vec3A,
    specular: SpecularPart<'a, N>,
}

/// Which share of a vertex's light belongs to the first interaction's
/// specular lobe.
#[derive(Clone, Copy)]
enum SpecularPart<'a, const N: usize> {
    /// Not tracked, or the first interaction was diffuse only.
    None,
    /// This is the first interaction: its specular lobe's share.
    Lobe,
    /// A later vertex: all of its light, through `T_s`.
    Through(&'a [Mueller; N]),
}

/// Next-event estimation: adds light sample `ls` seen from vertex `v`
/// unless something blocks it (`bundle`: the gathered leaves of the shadow
/// rays the sample belongs to, if any).
#[inline]
fn direct<const N: usize>(
    world: &World,
    v: &Vertex<N>,
    ls: LightSample,
    bundle: Option<&Bundle>,
    out: &mut PathResult<N>,
) {
    let Vertex {
        bsdf,
        t,
        p,
        ng,
        specular,
    } = *v;
    if ng.dot(ls.wi) <= 0.0 || ls.value <= 0.0 {
        return;
    }
    let (f, lobe) = match specular {
        SpecularPart::Lobe => {
            let (diffuse, spec) = bsdf.eval_lobes::<N>(ls.wi);
            match spec {
                Some(spec) => (diffuse.map(|d| d.add(&spec)), Some(spec)),
                None => (diffuse, None),
            }
        }
        _ => (bsdf.eval::<N>(ls.wi), None),
    };
    if f.iter().all(|f| f.0[0][0] <= 0.0) {
        return;
    }
    out.rays += 1;
    if world.occluded(bundle, p, ls.wi, 0.0, ls.dist * (1.0 - 1e-4)) {
        return;
    }
    let w = if ls.pdf > 0.0 {
        power_heuristic(ls.pdf, bsdf.pdf(ls.wi))
    } else {
        1.0
    };
    for c in 0..N {
        add_scaled(&mut out.stokes[c], t[c].apply(f[c].column0()), ls.value * w);
        match (specular, lobe) {
            (SpecularPart::Lobe, Some(spec)) => {
                add_scaled(
                    &mut out.specular[c],
                    t[c].apply(spec.column0()),
                    ls.value * w,
                );
            }
            (SpecularPart::Through(ts), _) => {
                add_scaled(
                    &mut out.specular[c],
                    ts[c].apply(f[c].column0()),
                    ls.value * w,
                );
            }
            _ => {}
        }
    }
}

/// A sampled bounce whose Mueller weight is applied to the path only once
/// the ray it starts finds something that can contribute: a ray that
/// escapes a scene without environment or area light ends the path, and
/// skips the 4×4 product and the new frame.
struct Bounce<const N: usize> {
    bsdf: Bsdf,
    pdf: f32,
    /// The weight of each channel, when the roulette already needed it.
    weight: Option<[Mueller; N]>,
    /// Shading normal at the vertex the ray leaves.
    ns: Vec3A,
    /// Russian-roulette survival probability, when the roulette was played.
    survival: Option<f32>,
    /// The bounce leaves the first vertex and its specular lobe starts `T_s`.
    starts_specular: bool,
}

/// Traces one path from the camera along `(origin, dir)`; `frame` is the
/// camera's Stokes x axis for this ray. `first` is the camera ray's hit and
/// the shadow bundles at it when the caller traced the pixel's rays as
/// bundles (`pixel_bundles.rs`), `None` to trace them here.
///
/// Always inlined into the pixel loop: called for every sample, it spent
/// ~100 instructions per call loading and spilling the scene's
/// loop-invariant values, which inlined are set up once per pixel.
#[inline(always)]
pub fn trace<const N: usize>(
    world: &World,
    settings: PathSettings,
    mut origin: Vec3A,
    mut dir: Vec3A,
    mut frame: Vec3A,
    sampler: &mut Sampler,
    mut first: Option<FirstVertex>,
) -> PathResult<N> {
    let shadows = first.map_or(&[][..], |f| f.shadows);
    let mut out = PathResult::default();
    let mut t = [Mueller::IDENTITY; N];
    // `T_s`: the product along the path for the first vertex's specular
    // lobe alone, once the path has left that vertex.
    let mut t_spec: Option<[Mueller; N]> = None;
    // BSDF density of the last bounce (0 = camera ray: no MIS).
    let mut bsdf_pdf = 0.0f32;
    let mut depth = 0;
    let mut bounce: Option<Bounce<N>> = None;
    loop {
        out.rays += 1;
        let hit = match first.take() {
            Some(f) => f.hit,
            None => world.intersect(None, origin, dir, 0.0, f32::INFINITY),
        };
        let t_hit = hit.map_or(f32::INFINITY, |h| h.t);
        let emitted = world.emitter_hit(origin, dir, t_hit);
        if hit.is_none() && emitted.is_none() && world.environment.is_none() {
            break;
        }
        if let Some(b) = bounce.take() {
            let survival = b.survival.map_or(1.0, f32::recip);
            let weight = if b.starts_specular {
                // Both lobes once: their sum is the weight, the specular
                // one starts `T_s`.
                let (diffuse, spec) = b.bsdf.eval_lobes::<N>(dir);
                let full = diffuse.map(|d| spec.map_or(d, |s| d.add(&s)));
                if let Some(spec) = spec {
                    t_spec = Some(t.map(|t| t.mul_matrix(&spec).scale(survival / b.pdf)));
                }
                b.weight
                    .unwrap_or_else(|| full.map(|f| f.scale(b.pdf.recip())))
            } else {
                let weight = b.weight.unwrap_or_else(|| b.bsdf.weight::<N>(dir, b.pdf));
                if let Some(ts) = &mut t_spec {
                    for c in 0..N {
                        ts[c] = ts[c].mul_matrix(&weight[c]).scale(survival);
                    }
                }
                weight
            };
            for c in 0..N {
                t[c] = t[c].mul_matrix(&weight[c]);
                if b.survival.is_some() {
                    t[c] = t[c].scale(survival);
                }
            }
            frame = s_axis(-dir, b.ns);
        }
        if let Some((radiance, light_pdf)) = emitted {
            let w = if bsdf_pdf > 0.0 {
                power_heuristic(bsdf_pdf, light_pdf)
            } else {
                1.0
            };
            for c in 0..N {
                add_scaled(&mut out.stokes[c], t[c].column0(), radiance * w);
                if let Some(ts) = &t_spec {
                    add_scaled(&mut out.specular[c], ts[c].column0(), radiance * w);
                }
            }
            break;
        }
        let Some(hit) = hit else {
            if let Some(env) = &world.environment {
                let w = if bsdf_pdf > 0.0 {
                    power_heuristic(bsdf_pdf, env.pdf(dir))
                } else {
                    1.0
                };
                let radiance = env.radiance(dir);
                for c in 0..N {
                    add_scaled(&mut out.stokes[c], t[c].column0(), radiance * w);
                    if let Some(ts) = &t_spec {
                        add_scaled(&mut out.specular[c], ts[c].column0(), radiance * w);
                    }
                }
            }
            break;
        };
        if depth == settings.max_depth {
            break; // this ray only looked for the environment
        }
        depth += 1;
        let wo = -dir;
        let (material, ng, ns) = world.shade(&hit, wo);
        let Some(bsdf) = material.at(ns, wo) else {
            break;
        };
        // Re-express T's input in the exit frame of this vertex.
        let exit_axis = s_axis(wo, ns);
        for c in 0..N {
            t[c] = t[c].then_rotated_input(wo, exit_axis, frame);
            if let Some(ts) = &mut t_spec {
                ts[c] = ts[c].then_rotated_input(wo, exit_axis, frame);
            }
        }
        let p = offset(hit.p, ng);
        let starts_specular = settings.split_specular && depth == 1 && bsdf.has_specular();

        let vertex = Vertex {
            bsdf: &bsdf,
            t: &t,
            p,
            ng,
            specular: match &t_spec {
                Some(ts) => SpecularPart::Through(ts),
                None if starts_specular => SpecularPart::Lobe,
                None => SpecularPart::None,
            },
        };
        for (i, light) in world.lights.iter().enumerate() {
            let ls = light.sample(p, sampler.next_2d());
            let bundle = match depth {
                1 => shadows.iter().find(|s| s.light == i).map(|s| &s.bundle),
                _ => None,
            };
            direct(world, &vertex, ls, bundle, &mut out);
        }
        if let Some(env) = &world.environment {
            let ls = env.sample(sampler.next_2d());
            direct(world, &vertex, ls, None, &mut out);
        }

        if depth == settings.max_depth && !world.has_hittable_lights() {
            break;
        }
        let Some((wi, pdf)) = bsdf.sample_direction(sampler.next_f32(), sampler.next_2d()) else {
            break;
        };
        if wi.dot(ng) <= 0.0 {
            break;
        }
        bsdf_pdf = pdf;
        origin = p;
        dir = wi;
        // The roulette is played before the ray is traced, on the (0, 0)
        // entry of the product alone (its largest over the channels).
        let (mut weight, mut survival) = (None, None);
        if depth >= settings.rr_depth {
            let w = bsdf.weight::<N>(wi, pdf);
            let q = (0..N)
                .map(|c| t[c].product_entry(&w[c], 0, 0))
                .fold(f32::NEG_INFINITY, f32::max)
                .min(0.95);
            if q <= 0.0 || sampler.next_f32() >= q {
                break;
            }
            (weight, survival) = (Some(w), Some(q));
        }
        bounce = Some(Bounce {
            bsdf,
            pdf,
            weight,
            ns,
            survival,
            starts_specular,
        });
    }
    out
}
