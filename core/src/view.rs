//! A view on disk (conventions.md §5): what one polarization camera saw
//! (`input/`), ground truth when it was rendered (`gt/`), pictures for people
//! (`preview/`) and `meta.json`.
//!
//! `meta.json` is written **last**: a folder with it is a complete view, which
//! is what resumable dataset generation checks. Reading is strict: every
//! inconsistency is an error naming the file (mixed bit depths, size
//! mismatches, non-finite values, an empty mask, DoP far above 1).

use crate::colormap;
use crate::colour::{self, CHANNELS};
use crate::folder::{self, Kind};
use crate::io::{self, PolarizerPng, read_normals, write_normals};
use crate::labelling::SpecularScores;
use crate::legend::{Legend, with_legend};
use crate::percentile::percentile;
use crate::result_folder::ResultFolder;
use crate::stokes::{Polarimetry, Stokes};
use crate::{Error, Image, Mask, NormalMap, Result, SOFTWARE_VERSION};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the `meta.json` schema this code writes and understands.
pub const SCHEMA_VERSION: u32 = 1;

/// The ground-truth normals in `gt/`: what a reconstruction is scored against.
const GT_NORMALS: &str = "normals.exr";

/// The per-channel ground-truth Stokes vectors of a colour view in `gt/`.
const STOKES_RGB: &str = "stokes_rgb.exr";

/// The channels of `stokes_rgb.exr`, `S0.R, S0.G, S0.B, S1.R, …`, each with
/// its colour channel and Stokes component.
fn stokes_rgb_names() -> Vec<(String, usize, usize)> {
    (0..3)
        .flat_map(|k| (0..3).map(move |c| (format!("S{k}.{}", CHANNELS[c]), c, k)))
        .collect()
}

/// File names of the polarizer images, in the order of `STANDARD_ANGLES`.
pub const POL_FILES: [&str; 4] = ["pol_000.png", "pol_045.png", "pol_090.png", "pol_135.png"];

/// One file to write, run beside the others.
pub type Job<'a> = Box<dyn FnOnce() -> Result<()> + Send + 'a>;

/// `meta.json`. Every field a method may use is optional, so real captures and
/// views written by other tools work; generators keep their full settings
/// (scene, render, sensor) in `extra`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    #[serde(default)]
    pub schema_version: u32,
    #[serde(default)]
    pub generator: String,
    #[serde(default)]
    pub software_version: String,
    /// Refractive index of the (single) material, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta: Option<f64>,
    /// Albedo of the (single) material, when uniform and known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo: Option<f64>,
    /// Direction towards the dominant directional light (camera frame), scaled
    /// by its irradiance, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light: Option<[f64; 3]>,
    /// Everything else the generator needs to reproduce the view.
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl Meta {
    /// A meta record stamped with this software's version.
    pub fn new(generator: &str) -> Self {
        Meta {
            schema_version: SCHEMA_VERSION,
            generator: generator.to_string(),
            software_version: SOFTWARE_VERSION.to_string(),
            ..Meta::default()
        }
    }

    /// Parses the content of a `meta.json` (`path` names errors); a schema
    /// newer than [`SCHEMA_VERSION`] is refused.
    pub fn from_json(bytes: &[u8], path: &Path) -> Result<Meta> {
        let meta: Meta = serde_json::from_slice(bytes)
            .map_err(|e| Error::file(path, format!("invalid meta.json: {e}")))?;
        if meta.schema_version > SCHEMA_VERSION {
            return Err(Error::file(
                path,
                format!(
                    "schema_version {} is newer than this software understands ({SCHEMA_VERSION})",
                    meta.schema_version
                ),
            ));
        }
        Ok(meta)
    }

    /// Reads `dir/meta.json`, the one reader of a view's record.
    pub fn read(dir: &Path) -> Result<Meta> {
        let path = dir.join("meta.json");
        let bytes = std::fs::read(&path).map_err(|e| Error::read(&path, e))?;
        Meta::from_json(&bytes, &path)
    }
}

/// What a method may read: the polarizer images and, optionally, a mask.
/// A colour view keeps its channels in `colour` and their Rec. 709
/// luminance in `pol` ([`ViewInput::of_colour`]), so every method, which
/// reads `pol`, reads a colour view as grey by one rule.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewInput {
    /// Linear sensor codes behind the polarizer at 0°, 45°, 90°, 135° (of
    /// a colour view: the rounded luminance of `colour`).
    pub pol: [Image<u16>; 4],
    /// Bit depth of the codes (8 or 16 as stored; the full scale is `2^bits − 1`).
    pub bits: u8,
    /// Object mask; absent for some real captures.
    pub mask: Option<Mask>,
    /// Codes of the R, G, B channels behind each polarizer (0°, 45°, 90°,
    /// 135°) of a colour view; `None` for a grey one.
    pub colour: Option<[Image<[u16; 3]>; 4]>,
}

impl ViewInput {
    /// A grey view's input.
    pub fn grey(pol: [Image<u16>; 4], bits: u8, mask: Option<Mask>) -> ViewInput {
        ViewInput {
            pol,
            bits,
            mask,
            colour: None,
        }
    }

    /// A colour view's input: `pol` is the rounded Rec. 709 luminance of
    /// each polarizer's channels ([`colour::luminance_code`]).
    pub fn of_colour(colour: [Image<[u16; 3]>; 4], bits: u8, mask: Option<Mask>) -> ViewInput {
        ViewInput {
            pol: colour
                .each_ref()
                .map(|img| img.map(|&p| colour::luminance_code(p))),
            bits,
            mask,
            colour: Some(colour),
        }
    }

    /// The grey view of the same input (the colour dropped).
    pub fn to_grey(&self) -> ViewInput {
        ViewInput::grey(self.pol.clone(), self.bits, self.mask.clone())
    }

    pub fn size(&self) -> (usize, usize) {
        self.pol[0].size()
    }

    /// The largest code: `2^bits − 1`.
    pub fn full_scale(&self) -> f32 {
        ((1u32 << self.bits) - 1) as f32
    }

    /// Pixels with a polarizer image at the full-scale code: clipped, so
    /// their Stokes vector is wrong (an import leaves them out of the mask;
    /// a rendered view keeps them in).
    /// Of a colour view, a pixel with any channel at full scale.
    pub fn saturated(&self) -> Mask {
        let full = ((1u32 << self.bits) - 1) as u16;
        let (w, h) = self.size();
        match &self.colour {
            None => Image::from_fn(w, h, |x, y| self.pol.iter().any(|p| *p.get(x, y) >= full)),
            Some(rgb) => Image::from_fn(w, h, |x, y| {
                rgb.iter().any(|p| p.get(x, y).iter().any(|&c| c >= full))
            }),
        }
    }

    /// Writes `dir/input/` alone: what a method may read, without ground
    /// truth, previews or `meta.json` (the view another tool is given, so
    /// that it cannot read the answer).
    pub fn write(&self, dir: &Path) -> Result<()> {
        self.jobs(&dir.join("input"))
            .into_par_iter()
            .try_for_each(|job| job())
    }

    /// The writing of each polarizer image and the mask into `input`.
    fn jobs<'a>(&'a self, input: &Path) -> Vec<Job<'a>> {
        let mut jobs: Vec<Job<'a>> = Vec::new();
        for (k, file) in POL_FILES.iter().enumerate() {
            let path = input.join(file);
            jobs.push(Box::new(move || match &self.colour {
                Some(rgb) => io::write_png_rgb_codes(&path, &rgb[k], self.bits),
                None if self.bits <= 8 => {
                    io::write_png8(&path, &self.pol[k].map(|&v| v.min(255) as u8))
                }
                None => io::write_png16(&path, &self.pol[k]),
            }));
        }
        if let Some(mask) = &self.mask {
            let path = input.join("mask.png");
            jobs.push(Box::new(move || {
                io::write_png8(&path, &mask.map(|&m| if m { 255 } else { 0 }))
            }));
        }
        jobs
    }

    /// `I_un`, DoP and AoP, from the Stokes vector of the four codes in
    /// units of the full scale (stored as `f32`, as `gt/stokes.exr` is).
    pub fn polarimetry(&self) -> Polarimetry {
        Self::polarimetry_of(&self.pol, self.full_scale())
    }

    /// [`ViewInput::polarimetry`] of each colour channel (R, G, B); `None`
    /// for a grey view.
    pub fn channel_polarimetry(&self) -> Option<[Polarimetry; 3]> {
        let rgb = self.colour.as_ref()?;
        Some(std::array::from_fn(|c| {
            let pol = rgb.each_ref().map(|img| img.map(|p| p[c]));
            Self::polarimetry_of(&pol, self.full_scale())
        }))
    }

    fn polarimetry_of(pol: &[Image<u16>; 4], full_scale: f32) -> Polarimetry {
        let k = 1.0 / full_scale;
        let (w, h) = pol[0].size();
        Polarimetry::from_fn(w, h, |i| {
            let v = |c: usize| f64::from(f32::from(pol[c].data()[i]) * k);
            let st = Stokes::from_four(v(0), v(1), v(2), v(3));
            Stokes::new(
                f64::from(st.s0 as f32),
                f64::from(st.s1 as f32),
                f64::from(st.s2 as f32),
            )
        })
    }
}

/// Ground truth of a view. Only the normals are needed to evaluate a
/// reconstruction; views from other tools often have nothing else, so the
/// other layers are optional.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundTruth {
    /// Unit normals in the camera frame, `[0, 0, 0]` outside the mask: the
    /// normal the light sees (after any normal map).
    pub normals: NormalMap,
    /// Distance along `−z` from the camera; NaN outside the mask.
    pub depth: Option<Image<f32>>,
    /// Noise-free `s0, s1, s2` (same units as the renderer's radiance); of
    /// a colour view, the Rec. 709 luminance of `channel_stokes`.
    pub stokes: Option<[Image<f32>; 3]>,
    /// Noise-free `s0, s1, s2` of each colour channel (R, G, B) of a
    /// colour view, `gt/stokes_rgb.exr`.
    pub channel_stokes: Option<[[Image<f32>; 3]; 3]>,
    /// Diffuse albedo per pixel.
    pub albedo: Option<Image<f32>>,
    /// The surface's own normal where `normals` holds a normal-mapped
    /// shading normal (same frame and layout as `normals`).
    pub geometric_normals: Option<NormalMap>,
    /// Specular-lobe weight per pixel.
    pub specular: Option<Image<f32>>,
    /// Noise-free `s0, s1, s2` of the light whose first surface interaction
    /// was specular reflection (the rest of `stokes` is diffuse): the
    /// mixture's ground truth, for scenes with a specular lobe.
    pub specular_stokes: Option<[Image<f32>; 3]>,
}

impl GroundTruth {
    /// Ground truth of normals alone (another tool's view, arrays).
    pub fn of_normals(normals: NormalMap) -> GroundTruth {
        GroundTruth {
            normals,
            depth: None,
            stokes: None,
            channel_stokes: None,
            albedo: None,
            geometric_normals: None,
            specular: None,
            specular_stokes: None,
        }
    }

    /// A method's specular labelling (`found`: AoPs turned; `highlights`:
    /// mostly specular in `s0`) scored over `mask` against the mixture;
    /// `None` without it.
    pub fn specular_scores(
        &self,
        found: &Mask,
        highlights: &Mask,
        mask: &Mask,
    ) -> Option<SpecularScores> {
        SpecularScores::of(
            found,
            highlights,
            self.stokes.as_ref(),
            self.specular_stokes.as_ref(),
            mask,
        )
    }

    /// The specular share of `s0` per pixel (0 where `s0` is 0), written as
    /// `gt/specular_fraction.exr`.
    pub fn specular_fraction(&self) -> Option<Image<f32>> {
        let [s0, ..] = self.stokes.as_ref()?;
        let [p0, ..] = self.specular_stokes.as_ref()?;
        let data = s0
            .data()
            .iter()
            .zip(p0.data())
            .map(|(&s, &p)| {
                if s > 0.0 {
                    (p / s).clamp(0.0, 1.0)
                } else {
                    0.0
                }
            })
            .collect();
        Image::from_vec(s0.width(), s0.height(), data).ok()
    }
}

/// A complete view.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub input: ViewInput,
    pub gt: Option<GroundTruth>,
    pub meta: Option<Meta>,
    /// Ground-truth files found unusable when reading (each message names
    /// its file): a reconstruction needs only `input/`, so these are
    /// reported, not fatal.
    pub problems: Vec<String>,
    /// Folder the view was read from (recorded in `run.json`).
    pub source: Option<PathBuf>,
}

impl View {
    /// The pixels a reconstruction of this view is scored over: its mask, or
    /// the ground truth's non-zero normals; `None` without ground truth.
    pub fn scored_mask(&self) -> Option<Mask> {
        self.gt.as_ref().map(|gt| {
            self.input
                .mask
                .clone()
                .unwrap_or_else(|| gt.normals.map(|n| *n != [0.0; 3]))
        })
    }

    /// Where the view folder `dir` keeps its ground-truth normals.
    pub fn gt_normals_path(dir: &Path) -> PathBuf {
        dir.join("gt").join(GT_NORMALS)
    }

    /// True when `dir` holds a completely written view: a view whose
    /// `meta.json`, written last, exists.
    pub fn is_complete(dir: &Path) -> bool {
        folder::is_view(dir) && dir.join("meta.json").is_file()
    }

    /// Writes the view as the folder `dir`, replacing a previous view there
    /// as a whole ([`folder::replace`]).
    pub fn write(&self, dir: &Path) -> Result<()> {
        folder::replace(dir, Kind::View, |d| self.write_files(d))
    }

    /// Writes the view's files into the existing folder `dir`, `meta.json`
    /// last (for callers that add files of their own before the folder is
    /// put in place).
    pub fn write_files(&self, dir: &Path) -> Result<()> {
        let input = dir.join("input");
        let g = dir.join("gt");
        let preview = dir.join("preview");
        // The files are independent: they are encoded concurrently, which
        // takes PNG and EXR compression off the single thread that used to
        // write them one after another.
        let mut jobs: Vec<Job> = self.input.jobs(&input);
        if let Some(gt) = &self.gt {
            let path = g.join(GT_NORMALS);
            jobs.push(Box::new(move || write_normals(&path, &gt.normals)));
            if let Some(depth) = &gt.depth {
                let path = g.join("depth.exr");
                jobs.push(Box::new(move || io::write_exr(&path, &[("Z", depth)])));
            }
            if let Some([s0, s1, s2]) = &gt.stokes {
                let path = g.join("stokes.exr");
                jobs.push(Box::new(move || {
                    io::write_exr(&path, &[("S0", s0), ("S1", s1), ("S2", s2)])
                }));
            }
            if let Some(channels) = &gt.channel_stokes {
                let path = g.join(STOKES_RGB);
                jobs.push(Box::new(move || {
                    let names = stokes_rgb_names();
                    let layers: Vec<(&str, &Image<f32>)> = names
                        .iter()
                        .map(|(name, c, k)| (name.as_str(), &channels[*c][*k]))
                        .collect();
                    io::write_exr(&path, &layers)
                }));
            }
            if let Some(albedo) = &gt.albedo {
                let path = g.join("albedo.exr");
                jobs.push(Box::new(move || io::write_exr(&path, &[("Y", albedo)])));
            }
            if let Some(n) = &gt.geometric_normals {
                let path = g.join("geometric_normals.exr");
                jobs.push(Box::new(move || write_normals(&path, n)));
            }
            if let Some(specular) = &gt.specular {
                let path = g.join("specular.exr");
                jobs.push(Box::new(move || io::write_exr(&path, &[("Y", specular)])));
            }
            if let Some([s0, s1, s2]) = &gt.specular_stokes {
                let path = g.join("specular_stokes.exr");
                jobs.push(Box::new(move || {
                    io::write_exr(&path, &[("S0", s0), ("S1", s1), ("S2", s2)])
                }));
                if let Some(fraction) = gt.specular_fraction() {
                    let path = g.join("specular_fraction.exr");
                    jobs.push(Box::new(move || io::write_exr(&path, &[("Y", &fraction)])));
                }
            }
        }
        jobs.extend(self.preview_jobs(&preview));
        jobs.into_par_iter().try_for_each(|job| job())?;
        let meta = self.meta.clone().unwrap_or_else(|| Meta::new("unknown"));
        let json = serde_json::to_vec_pretty(&meta).expect("meta serialises");
        io::write_atomic(&dir.join("meta.json"), &json)
    }

    /// Intensity, DoP, AoP and (with ground truth) normal pictures.
    pub fn write_previews(&self, dir: &Path) -> Result<()> {
        self.preview_jobs(dir)
            .into_par_iter()
            .try_for_each(|job| job())
    }

    /// The writing of each preview picture as a separate job.
    fn preview_jobs<'a>(&'a self, dir: &Path) -> Vec<Job<'a>> {
        let mut jobs: Vec<Job<'a>> = Vec::new();
        let path = |name: &str| dir.join(name);
        let (intensity, dop, aop) = (path("intensity.png"), path("dop.png"), path("aop.png"));
        jobs.push(Box::new(move || {
            let pm = self.input.polarimetry();
            let mask = self.input.mask.as_ref();
            let inside = |img: &Image<f32>| -> Vec<f32> {
                img.data()
                    .iter()
                    .zip(0..)
                    .filter(|&(_, i)| mask.is_none_or(|m| m.data()[i]))
                    .map(|(&v, _)| v)
                    .collect()
            };
            let i_hi = percentile(&inside(&pm.intensity), 0.99).max(1e-6);
            let dop_hi = percentile(&inside(&pm.dop), 0.99).max(1e-3);
            // A colour view's intensity in colour: each channel's `I_un` on
            // the luminance's scale.
            let intensity_picture = match self.input.channel_polarimetry() {
                Some(channels) => {
                    let (w, h) = pm.intensity.size();
                    Image::from_fn(w, h, |x, y| {
                        if mask.is_some_and(|m| !m.get(x, y)) {
                            colormap::BACKGROUND
                        } else {
                            channels
                                .each_ref()
                                .map(|c| colormap::gray(c.intensity.get(x, y) / i_hi)[0])
                        }
                    })
                }
                None => colormap::scalar_preview(&pm.intensity, mask, 0.0, i_hi, colormap::gray),
            };
            let pictures = [
                (
                    &intensity,
                    intensity_picture,
                    // In percent of the sensor's full scale.
                    Legend::Bar {
                        name: "I_un",
                        lo: 0.0,
                        hi: 100.0 * f64::from(i_hi),
                        unit: "%",
                        map: colormap::gray,
                    },
                ),
                (
                    &dop,
                    colormap::scalar_preview(&pm.dop, mask, 0.0, dop_hi, colormap::viridis),
                    Legend::Bar {
                        name: "DoP",
                        lo: 0.0,
                        hi: f64::from(dop_hi),
                        unit: "",
                        map: colormap::viridis,
                    },
                ),
                (
                    &aop,
                    colormap::aop_preview(&pm.aop, &pm.dop, mask),
                    Legend::AopWheel {
                        unpolarized_below: f64::from(colormap::UNPOLARIZED_DOP),
                    },
                ),
            ];
            // Saturated pixels (in or out of the mask: an import leaves them
            // out) in a colour of their own, named under the map's legend.
            let saturated = self.input.saturated();
            let marked = saturated.count() > 0;
            let key = [(colormap::SATURATED, "saturated (clipped)")];
            pictures
                .into_par_iter()
                .try_for_each(|(path, mut img, legend)| {
                    let picture = if marked {
                        colormap::mark(&mut img, &saturated, colormap::SATURATED);
                        with_legend(&with_legend(&img, &legend), &Legend::Swatches(&key))
                    } else {
                        with_legend(&img, &legend)
                    };
                    io::write_png_rgb(path, &picture)
                })
        }));
        if let Some(gt) = &self.gt {
            let path = path("normals.png");
            jobs.push(Box::new(move || {
                let picture = gt.normals.map(|&n| colormap::normal_rgb(n));
                io::write_png_rgb(&path, &with_legend(&picture, &Legend::NormalKey))
            }));
        }
        jobs
    }

    /// Reads and checks the view in `dir`. Only `input/pol_*.png` are required.
    pub fn read(dir: &Path) -> Result<View> {
        if !dir.is_dir() {
            return Err(Error::file(
                dir,
                "not a folder (expected a view folder with input/pol_000.png, …)",
            ));
        }
        if !folder::is_view(dir) {
            let what = if ResultFolder::is_result(dir) {
                "is a reconstruction folder, not a view (were VIEW and RESULT given in the other order?)"
            } else if dir.join("dataset.json").is_file() {
                "is a dataset folder, not a view (give one of its view folders)"
            } else {
                "is not a view: it has no input/ folder with pol_000.png … pol_135.png"
            };
            return Err(Error::file(dir, what));
        }
        let input = read_input(&dir.join("input"))?;
        let meta_path = dir.join("meta.json");
        let meta = if meta_path.exists() {
            Some(Meta::read(dir)?)
        } else {
            None
        };
        let mut problems = Vec::new();
        let gt = read_gt(&dir.join("gt"), input.size(), &mut problems);
        Ok(View {
            input,
            gt,
            meta,
            problems,
            source: Some(dir.to_path_buf()),
        })
    }
}

fn read_input(dir: &Path) -> Result<ViewInput> {
    let mut pngs: Vec<(PathBuf, PolarizerPng)> = Vec::with_capacity(4);
    for file in POL_FILES {
        let path = dir.join(file);
        let png = io::read_polarizer_png(&path)?;
        if let Some((first_path, first)) = pngs.first() {
            let kind = |p: &PolarizerPng| match p {
                PolarizerPng::Grey(_) => "grey",
                PolarizerPng::Colour { .. } => "colour",
            };
            let differs = if png.bits() != first.bits() {
                Some((
                    "bit depth",
                    format!("{}-bit", png.bits()),
                    format!("{}-bit", first.bits()),
                ))
            } else if png.size() != first.size() {
                Some((
                    "size",
                    format!("{:?} pixels", png.size()),
                    format!("{:?}", first.size()),
                ))
            } else if kind(&png) != kind(first) {
                Some((
                    "kind (all grey or all colour)",
                    kind(&png).into(),
                    kind(first).into(),
                ))
            } else {
                None
            };
            if let Some((what, this, other)) = differs {
                return Err(Error::file(
                    &path,
                    format!(
                        "is {this} but {} is {other}: polarizer images must share one {what}",
                        first_path.display(),
                    ),
                ));
            }
        }
        pngs.push((path, png));
    }
    let bits = pngs[0].1.bits();
    let size = pngs[0].1.size();
    let colour = matches!(pngs[0].1, PolarizerPng::Colour { .. });
    let mut it = pngs.into_iter().map(|(_, png)| png);
    let pngs = [(); 4].map(|_| it.next().expect("four images"));
    let mask_path = dir.join("mask.png");
    let mask = if mask_path.exists() {
        let m = io::read_gray_png(&mask_path)?;
        if m.size() != size {
            return Err(Error::file(
                &mask_path,
                format!(
                    "is {:?} pixels but the polarizer images are {size:?}",
                    m.size()
                ),
            ));
        }
        let half = if m.bits() == 8 { 128 } else { 32768 };
        let mask = m.into_u16().map(|&v| v >= half);
        if mask.count() == 0 {
            return Err(Error::file(
                &mask_path,
                "mask is empty: no pixel is marked as object (255)",
            ));
        }
        Some(mask)
    } else {
        None
    };
    let input = if colour {
        ViewInput::of_colour(
            pngs.map(|png| png.into_colour().expect("colour images")),
            bits,
            mask,
        )
    } else {
        ViewInput::grey(pngs.map(|png| png.luminance()), bits, mask)
    };
    check_dop(&input, dir)?;
    Ok(input)
}

/// Rejects inputs whose DoP exceeds 1 well beyond quantization and noise on
/// more than 1% of the (masked) pixels: the usual cause is polarizer images in
/// the wrong order or at other angles.
fn check_dop(input: &ViewInput, dir: &Path) -> Result<()> {
    let k = 1.0 / f64::from(input.full_scale());
    let (w, h) = input.size();
    let (mut considered, mut bad, mut example) = (0usize, 0usize, None);
    for y in 0..h {
        for x in 0..w {
            if input.mask.as_ref().is_some_and(|m| !m.get(x, y)) {
                continue;
            }
            let v = |i: usize| f64::from(*input.pol[i].get(x, y)) * k;
            let s = Stokes::from_four(v(0), v(1), v(2), v(3));
            if s.s0 < 0.02 {
                continue;
            }
            considered += 1;
            let dop = s.dop_unclamped();
            if dop > 1.1 {
                bad += 1;
                example.get_or_insert((x, y, dop));
            }
        }
    }
    if bad > 0 && bad * 100 > considered {
        let (x, y, dop) = example.expect("bad > 0");
        return Err(Error::file(
            dir,
            format!(
                "DoP exceeds 1 at {bad} of {considered} pixels (e.g. {dop:.2} at column {x}, row {y}): \
                 are pol_000/045/090/135 in the right order and at those angles?"
            ),
        ));
    }
    Ok(())
}

/// `gt/` of a view: `None` without a usable `normals.exr`; the other layers
/// where present. Unusable files are listed in `problems`.
fn read_gt(dir: &Path, size: (usize, usize), problems: &mut Vec<String>) -> Option<GroundTruth> {
    let sized = |path: &Path, imgs: Vec<Image<f32>>| -> Result<Vec<Image<f32>>> {
        if imgs[0].size() != size {
            return Err(Error::file(
                path,
                format!(
                    "is {:?} pixels but the input images are {size:?}",
                    imgs[0].size()
                ),
            ));
        }
        Ok(imgs)
    };
    let mut normal_layer = |file: &str| -> Option<NormalMap> {
        let path = dir.join(file);
        if !path.exists() {
            return None;
        }
        read_normals(&path)
            .and_then(|n| sized(&path, vec![n.map(|_| 0.0)]).map(|_| n))
            .map_err(|e| problems.push(e.to_string()))
            .ok()
    };
    let normals = normal_layer(GT_NORMALS)?;
    let geometric_normals = normal_layer("geometric_normals.exr");
    let mut layer = |file: &str, names: &[&str]| -> Option<Vec<Image<f32>>> {
        let path = dir.join(file);
        if !path.exists() {
            return None;
        }
        io::read_exr(&path, names)
            .and_then(|imgs| sized(&path, imgs))
            .map_err(|e| problems.push(e.to_string()))
            .ok()
    };
    let depth = layer("depth.exr", &["Z"]).map(|mut v| v.remove(0));
    let channel_stokes = layer(
        STOKES_RGB,
        &stokes_rgb_names()
            .iter()
            .map(|(name, ..)| name.as_str())
            .collect::<Vec<_>>(),
    )
    .map(|v| {
        let mut s = v.into_iter();
        let by_component: [[Image<f32>; 3]; 3] =
            [(); 3].map(|_| [(); 3].map(|_| s.next().expect("nine channels")));
        let [s0, s1, s2] = by_component;
        let mut per = [s0, s1, s2].map(|c| c.into_iter());
        [(); 3].map(|_| per.each_mut().map(|c| c.next().expect("three channels")))
    });
    let mut stokes_layer = |file: &str| {
        layer(file, &["S0", "S1", "S2"]).map(|v| {
            let mut s = v.into_iter();
            [(); 3].map(|_| s.next().expect("three channels"))
        })
    };
    let stokes = stokes_layer("stokes.exr");
    let specular_stokes = stokes_layer("specular_stokes.exr");
    let albedo = layer("albedo.exr", &["Y"]).map(|mut v| v.remove(0));
    let specular = layer("specular.exr", &["Y"]).map(|mut v| v.remove(0));
    Some(GroundTruth {
        normals,
        depth,
        stokes,
        channel_stokes,
        albedo,
        geometric_normals,
        specular,
        specular_stokes,
    })
}
