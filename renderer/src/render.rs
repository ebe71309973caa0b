//! The top level: scene → view (conventions.md §5).

use crate::bundle::Frustum;
use crate::camera::CameraRay;
use crate::integrator::{PathSettings, trace};
use crate::pixel_bundles::{FirstVertex, PixelBundles};
use crate::sampler::{Sampler, SamplerKey, Stream};
use crate::scene::Scene;
use crate::sensor::{expose, expose_colour};
use crate::view_meta;
use crate::world::World;
use rayon::prelude::*;
use sfp_core::capture::mosaic::{Bayer, Pattern, mosaic, mosaic_colour};
use sfp_core::folder::{self, Kind};
use sfp_core::view::{GroundTruth, View, ViewInput};
use sfp_core::{Error, Image, Result, colour, io};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::time::Instant;

/// Fewest samples per pixel at which a pixel's camera rays are traced as a
/// bundle (`pixel_bundles.rs`).
const BUNDLE_MIN_SPP: u32 = 8;

/// Settings that are not part of the scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderOptions {
    /// Index of the view in a dataset: a separate random stream per view.
    pub view_index: u64,
}

/// Figures of one render (not written to `meta.json`: they vary run to run).
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    pub seconds: f64,
    /// Camera samples (pixels × spp).
    pub samples: u64,
    /// Rays traced: camera, bounce and shadow rays.
    pub rays: u64,
    pub triangles: usize,
}

/// A rendered view, the optional raw mosaic and the render figures.
pub struct Rendered {
    pub view: View,
    /// `input/raw.png` when the sensor asks for a mosaic.
    pub raw: Option<Image<u16>>,
    pub stats: RenderStats,
}

impl Rendered {
    /// Writes the view folder and `input/raw.png`, replacing a previous
    /// view at `dir` as a whole.
    pub fn write(&self, dir: &Path) -> Result<()> {
        folder::replace(dir, Kind::View, |d| {
            let (raw, view) = rayon::join(
                || match &self.raw {
                    Some(raw) => io::write_png16(&d.join("input").join("raw.png"), raw),
                    None => Ok(()),
                },
                || self.view.write_files(d),
            );
            raw.and(view)
        })
    }
}

/// Renders `scene`. See [`render_with_progress`].
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<Rendered> {
    render_with_progress(scene, options, &|_, _| {})
}

/// Per-pixel results of the path tracer (per channel: 1 grey, 3 colour)
/// and the primary-hit ground truth.
struct Pixel<const N: usize> {
    stokes: [[f32; 3]; N],
    /// The specular part of `stokes` (first interaction).
    specular_stokes: [[f32; 3]; N],
    normal: [f32; 3],
    geometric_normal: [f32; 3],
    depth: f32,
    albedo: f32,
    specular: f32,
    covered: bool,
}

/// Renders `scene`, calling `progress(rows_done, rows_total)` after each row
/// (from worker threads, in any order). Output is bit-identical for any number
/// of threads: every random draw is keyed by (seed, view, pixel, sample).
pub fn render_with_progress(
    scene: &Scene,
    options: &RenderOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Rendered> {
    render_until(scene, options, progress, &AtomicBool::new(false))
}

/// [`render_with_progress`] that ends early, with an error, once `stop` is
/// set (checked before each row): how a caller that cannot kill the
/// process, such as the Python module on Ctrl-C, stops a long render.
pub fn render_until(
    scene: &Scene,
    options: &RenderOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    stop: &AtomicBool,
) -> Result<Rendered> {
    let start = Instant::now();
    let world = World::build(scene)?;
    if scene.desc.render.colour {
        finish::<3>(scene, options, &world, start, progress, stop)
    } else {
        finish::<1>(scene, options, &world, start, progress, stop)
    }
}

/// The traced pixels of every row, `None` when `stop` was set.
fn trace_rows<const N: usize>(
    scene: &Scene,
    options: &RenderOptions,
    world: &World,
    settings: PathSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
    stop: &AtomicBool,
    rays: &AtomicU64,
) -> Option<Vec<Pixel<N>>> {
    let r = &scene.desc.render;
    let (w, h) = (world.camera.width, world.camera.height);
    // A pixel's camera rays are traced as one bundle when there are
    // triangles and enough samples to repay gathering its leaves (the
    // gather costs about as much as tracing a few single rays).
    let bundled = world.triangle_count() > 0 && r.spp >= BUNDLE_MIN_SPP;
    let rows_done = AtomicUsize::new(0);
    let view_key = SamplerKey::new(r.seed, Stream::Path, options.view_index);
    let rows: Option<Vec<Vec<Pixel<N>>>> = (0..h)
        .into_par_iter()
        .map(|y| {
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            let mut row_rays = 0u64;
            let mut bundles = bundled.then(|| PixelBundles::new(world, r.spp));
            let row = (0..w)
                .map(|x| {
                    let pixel = (y * w + x) as u64;
                    let mut acc = [[0.0f64; 3]; N];
                    let mut acc_specular = [[0.0f64; 3]; N];
                    let key = view_key.pixel(pixel);
                    // Sample s's sampler after its jitter draw, and its camera ray.
                    let camera_sample = |s: u32| {
                        let mut sampler = key.sampler(u64::from(s));
                        let (px, py) = if r.jitter {
                            let [u, v] = sampler.next_2d();
                            (x as f32 + u, y as f32 + v)
                        } else {
                            (x as f32 + 0.5, y as f32 + 0.5)
                        };
                        (sampler, world.camera.ray(px, py))
                    };
                    // Traces one camera sample's path and adds it to the pixel.
                    let mut path =
                        |mut sampler: Sampler, ray: CameraRay, first: Option<FirstVertex>| {
                            let frame = world.camera.stokes_axis(ray.dir);
                            let res = trace::<N>(
                                world,
                                settings,
                                ray.origin,
                                ray.dir,
                                frame,
                                &mut sampler,
                                first,
                            );
                            row_rays += u64::from(res.rays);
                            for c in 0..N {
                                for (a, v) in acc[c].iter_mut().zip(res.stokes[c]) {
                                    *a += f64::from(v);
                                }
                                for (a, v) in acc_specular[c].iter_mut().zip(res.specular[c]) {
                                    *a += f64::from(v);
                                }
                            }
                        };
                    let frustum = Frustum::of_pixel(&world.camera, x, y);
                    match &mut bundles {
                        // Nothing to see: every camera ray misses, and adds
                        // nothing. The rays still count, resolved by the
                        // frustum test as a bundle's are by its leaves.
                        _ if !world.may_see(&frustum) => row_rays += u64::from(r.spp),
                        Some(b) => b.trace_pixel(world, &frustum, r.spp, camera_sample, path),
                        None => {
                            for s in 0..r.spp {
                                let (sampler, ray) = camera_sample(s);
                                path(sampler, ray, None);
                            }
                        }
                    }
                    let mut px = ground_truth::<N>(world, x, y);
                    let mean = |a: [f64; 3]| a.map(|a| (a / f64::from(r.spp)) as f32);
                    px.stokes = acc.map(mean);
                    px.specular_stokes = acc_specular.map(mean);
                    px
                })
                .collect();
            rays.fetch_add(row_rays, Ordering::Relaxed);
            progress(rows_done.fetch_add(1, Ordering::Relaxed) + 1, h);
            Some(row)
        })
        .collect();
    rows.map(|rows| rows.into_iter().flatten().collect())
}

/// Traces `N` channels (1: grey, 3: colour) and makes the view: exposure,
/// the optional mosaic, the ground truth.
fn finish<const N: usize>(
    scene: &Scene,
    options: &RenderOptions,
    world: &World,
    start: Instant,
    progress: &(dyn Fn(usize, usize) + Sync),
    stop: &AtomicBool,
) -> Result<Rendered> {
    let d = &scene.desc;
    let r = &d.render;
    let (w, h) = (world.camera.width, world.camera.height);
    let settings = PathSettings {
        max_depth: r.max_depth,
        rr_depth: r.rr_depth,
        split_specular: world.has_specular_lobe(),
    };
    let rays = AtomicU64::new(0);
    let Some(pixels) = trace_rows::<N>(scene, options, world, settings, progress, stop, &rays)
    else {
        return Err(Error::invalid("the render was stopped before it ended"));
    };
    let img = |f: &dyn Fn(&Pixel<N>) -> f32| {
        Image::from_vec(w, h, pixels.iter().map(f).collect()).expect("size matches")
    };
    // Per channel `s0, s1, s2`, and the grey (one channel, or the Rec. 709
    // luminance of three).
    let channel =
        |f: &dyn Fn(&Pixel<N>) -> [[f32; 3]; N], c: usize| [0, 1, 2].map(|k| img(&|p| f(p)[c][k]));
    let grey = |f: &dyn Fn(&Pixel<N>) -> [[f32; 3]; N]| {
        [0, 1, 2].map(|k| {
            img(&|p| {
                let v = f(p);
                if N == 3 {
                    colour::luminance([0, 1, 2].map(|c| f64::from(v[c][k]))) as f32
                } else {
                    v[0][k]
                }
            })
        })
    };
    let stokes = grey(&|p| p.stokes);
    let channel_stokes: Option<[[Image<f32>; 3]; 3]> =
        (N == 3).then(|| [0, 1, 2].map(|c| channel(&|p| p.stokes, c)));
    let mask =
        Image::from_vec(w, h, pixels.iter().map(|p| p.covered).collect()).expect("size matches");
    if mask.count() == 0 {
        return Err(Error::file(
            &scene.source,
            "no object is visible from the camera (check camera position, look_at and extent/fov)",
        ));
    }
    let (input, scale) = match &channel_stokes {
        None => {
            let exposed = expose(&d.sensor, &stokes, &mask, r.seed, options.view_index);
            let input = ViewInput::grey(exposed.pol, d.sensor.bits, Some(mask.clone()));
            (input, exposed.scale)
        }
        Some(channels) => {
            let exposed = expose_colour(&d.sensor, channels, &mask, r.seed, options.view_index);
            let input = ViewInput::of_colour(exposed.rgb, d.sensor.bits, Some(mask.clone()));
            (input, exposed.scale)
        }
    };
    // A colour view's mosaic is a colour sensor's (IMX250MYR: RGGB cells).
    let raw = d.sensor.mosaic.then(|| match &input.colour {
        Some(rgb) => mosaic_colour(rgb, Pattern::SONY, Bayer::Rggb),
        None => mosaic(&input.pol, Pattern::SONY),
    });
    let normals = |f: &dyn Fn(&Pixel<N>) -> [f32; 3]| {
        Image::from_vec(w, h, pixels.iter().map(f).collect()).expect("size matches")
    };
    // Spatially varying materials: the per-pixel specular weight, and the
    // geometric normals under the normal-mapped ones.
    let svbrdf = d
        .objects
        .iter()
        .any(|o| o.material.records_svbrdf_ground_truth());
    let gt = GroundTruth {
        normals: normals(&|p| p.normal),
        depth: Some(img(&|p| p.depth)),
        stokes: Some(stokes),
        channel_stokes,
        albedo: Some(img(&|p| p.albedo)),
        geometric_normals: svbrdf.then(|| normals(&|p| p.geometric_normal)),
        specular: svbrdf.then(|| img(&|p| p.specular)),
        specular_stokes: settings
            .split_specular
            .then(|| grey(&|p| p.specular_stokes)),
    };
    let meta = view_meta::record(scene, world, options.view_index, scale)?;
    let stats = RenderStats {
        seconds: start.elapsed().as_secs_f64(),
        samples: (w * h) as u64 * u64::from(r.spp),
        rays: rays.into_inner(),
        triangles: world.triangle_count(),
    };
    Ok(Rendered {
        view: View {
            input,
            gt: Some(gt),
            meta: Some(meta),
            problems: Vec::new(),
            source: None,
        },
        raw,
        stats,
    })
}

/// Normals (camera frame, facing the camera: the shading normal after normal
/// mapping and the geometric one), depth, albedo and specular weight at the
/// primary hit through the pixel centre.
fn ground_truth<const N: usize>(world: &World, x: usize, y: usize) -> Pixel<N> {
    let cam = &world.camera;
    let ray = cam.ray(x as f32 + 0.5, y as f32 + 0.5);
    let mut px = Pixel {
        stokes: [[0.0; 3]; N],
        specular_stokes: [[0.0; 3]; N],
        normal: [0.0; 3],
        geometric_normal: [0.0; 3],
        depth: f32::NAN,
        albedo: 0.0,
        specular: 0.0,
        covered: false,
    };
    if let Some(hit) = world.intersect(None, ray.origin, ray.dir, 0.0, f32::INFINITY) {
        let (m, ng, n) = world.shade(&hit, -ray.dir);
        px.normal = cam.to_camera(n).to_array();
        px.geometric_normal = cam.to_camera(ng).to_array();
        px.depth = hit.t * ray.dir.dot(-cam.back);
        px.albedo = m.albedo;
        px.specular = m.specular;
        px.covered = true;
    }
    px
}
