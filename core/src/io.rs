//! File formats of views and results (conventions.md §5): 8/16-bit PNG
//! through `image`, float EXR through `exr` (normal maps as RGB EXR), and
//! atomic writes.
//!
//! Every write goes to a temporary file in the target folder and is renamed
//! into place, so an interrupted run never leaves a half-written file under
//! its final name.

use crate::colour;
use crate::{Error, Image, Mask, NormalMap, Result};
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically (temp file in the same folder + rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let tmp = temp_path(path);
    std::fs::write(&tmp, bytes).map_err(|e| Error::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

fn temp_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{}.tmp", std::process::id()));
    path.with_file_name(name)
}

/// The content of the file `path` (an image, an array). Only a regular file is read: a
/// FIFO would block the command for ever and a device (`/dev/zero`) would
/// be read until memory runs out.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    let meta = std::fs::metadata(path).map_err(|e| Error::read(path, e))?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a folder"
        } else {
            "not a regular file (a pipe or a device)"
        };
        return Err(Error::file(path, format!("is {what}, not an image file")));
    }
    std::fs::read(path).map_err(|e| Error::read(path, e))
}

/// A grayscale PNG as read from disk, keeping its bit depth.
#[derive(Clone, Debug, PartialEq)]
pub enum GrayPng {
    Bits8(Image<u8>),
    Bits16(Image<u16>),
}

impl GrayPng {
    pub fn size(&self) -> (usize, usize) {
        match self {
            GrayPng::Bits8(i) => i.size(),
            GrayPng::Bits16(i) => i.size(),
        }
    }

    pub fn bits(&self) -> u8 {
        match self {
            GrayPng::Bits8(_) => 8,
            GrayPng::Bits16(_) => 16,
        }
    }

    /// Sensor codes widened to 16 bits (values unchanged).
    pub fn into_u16(self) -> Image<u16> {
        match self {
            GrayPng::Bits8(i) => i.map(|&v| u16::from(v)),
            GrayPng::Bits16(i) => i,
        }
    }
}

fn decode_png(bytes: &[u8], path: &Path) -> Result<image::DynamicImage> {
    image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .map_err(|e| Error::file(path, format!("not a readable PNG: {e}")))
}

/// Reads an 8- or 16-bit single-channel PNG; colour PNGs are an error.
pub fn read_gray_png(path: &Path) -> Result<GrayPng> {
    gray_png_from_bytes(&read_bytes(path)?, path)
}

/// [`read_gray_png`] on the file's content (`path` names errors).
pub fn gray_png_from_bytes(bytes: &[u8], path: &Path) -> Result<GrayPng> {
    let img = decode_png(bytes, path)?;
    if !matches!(img.color(), image::ColorType::L8 | image::ColorType::L16) {
        return Err(Error::file(
            path,
            format!(
                "expected a single-channel (grayscale) PNG, found {:?}",
                img.color()
            ),
        ));
    }
    monochrome(img, path)
}

/// Reads a monochrome sensor image (a raw mosaic frame, a polarizer image,
/// a dark frame or a flat field): a grayscale PNG as [`read_gray_png`], or
/// a colour PNG whose colour channels are equal at every pixel (mono frames
/// exported as RGB; alpha is ignored), read exactly. One rule for every
/// sensor image: a colour PNG whose channels differ anywhere is an RGB
/// picture, refused by name before any check of its content (a sensor
/// frame has one value per pixel; averaging the colours would pass a
/// photograph as polarization data, or fail later as a DoP above 1).
pub fn read_mono_png(path: &Path) -> Result<GrayPng> {
    mono_png_from_bytes(&read_bytes(path)?, path)
}

/// A polarizer image as stored: grey codes, or the codes of its three
/// colour channels (R, G, B; alpha is ignored), at the file's bit depth.
#[derive(Clone, Debug, PartialEq)]
pub enum PolarizerPng {
    Grey(GrayPng),
    Colour { bits: u8, rgb: Image<[u16; 3]> },
}

impl PolarizerPng {
    pub fn bits(&self) -> u8 {
        match self {
            PolarizerPng::Grey(g) => g.bits(),
            PolarizerPng::Colour { bits, .. } => *bits,
        }
    }

    pub fn size(&self) -> (usize, usize) {
        match self {
            PolarizerPng::Grey(g) => g.size(),
            PolarizerPng::Colour { rgb, .. } => rgb.size(),
        }
    }

    /// The grey codes: as stored, or the rounded Rec. 709 luminance of the
    /// channels ([`colour::luminance_code`]).
    pub fn luminance(&self) -> Image<u16> {
        match self {
            PolarizerPng::Grey(g) => g.clone().into_u16(),
            PolarizerPng::Colour { rgb, .. } => rgb.map(|&p| colour::luminance_code(p)),
        }
    }

    /// The colour channels' codes; `None` for a grey image.
    pub fn into_colour(self) -> Option<Image<[u16; 3]>> {
        match self {
            PolarizerPng::Grey(_) => None,
            PolarizerPng::Colour { rgb, .. } => Some(rgb),
        }
    }
}

/// Reads one polarizer image, grey or colour, 8 or 16 bits: a view's
/// `input/pol_*.png` or a per-angle layout's (SfPUEL stores RGB PNGs).
/// Colour codes are kept as they are (linear, as those datasets store
/// them); any other pixel format is an error naming the file.
pub fn read_polarizer_png(path: &Path) -> Result<PolarizerPng> {
    let img = decode_png(&read_bytes(path)?, path)?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    use image::DynamicImage as D;
    let bits = match img {
        D::ImageRgb8(_) | D::ImageRgba8(_) => 8,
        D::ImageRgb16(_) | D::ImageRgba16(_) => 16,
        grey => return Ok(PolarizerPng::Grey(monochrome(grey, path)?)),
    };
    let raw = if bits == 8 {
        img.into_rgb8()
            .into_raw()
            .into_iter()
            .map(u16::from)
            .collect()
    } else {
        img.into_rgb16().into_raw()
    };
    let data = raw.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Ok(PolarizerPng::Colour {
        bits,
        rgb: Image::from_vec(w, h, data)?,
    })
}

/// Reads one polarizer image as grey: a grey PNG as it is, a colour one as
/// the Rec. 709 luminance of its codes ([`colour::luminance`]), rounded, at
/// its own bit depth.
pub fn read_luminance_png(path: &Path) -> Result<GrayPng> {
    let png = read_polarizer_png(path)?;
    let grey = png.luminance();
    Ok(if png.bits() == 8 {
        GrayPng::Bits8(grey.map(|&v| v as u8))
    } else {
        GrayPng::Bits16(grey)
    })
}

/// Reads a mask image: the pixels with a non-zero value, in a grey or a
/// colour PNG (any non-zero colour channel; alpha is ignored), so a mask
/// drawn in colour in an editor works.
pub fn read_mask_png(path: &Path) -> Result<Mask> {
    let img = decode_png(&read_bytes(path)?, path)?.into_rgb16();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let nonzero = img.pixels().map(|p| p.0 != [0; 3]).collect();
    Image::from_vec(w, h, nonzero)
}

/// [`read_mono_png`] on the file's content (`path` names errors).
pub fn mono_png_from_bytes(bytes: &[u8], path: &Path) -> Result<GrayPng> {
    monochrome(decode_png(bytes, path)?, path)
}

/// Gray images as they are, colour ones with equal channels as their one
/// value; colour ones with unequal channels refused (see [`read_mono_png`]).
fn monochrome(img: image::DynamicImage, path: &Path) -> Result<GrayPng> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let grey = |raw: Vec<u16>, stride: usize| -> Result<Vec<u16>> {
        let differ = raw
            .chunks_exact(stride)
            .filter(|p| p[0] != p[1] || p[1] != p[2])
            .count();
        if differ > 0 {
            return Err(Error::file(
                path,
                format!(
                    "an RGB picture (its colour channels differ at {differ} of {} pixels), \
                     not a sensor frame, which has one value per pixel: give the camera's raw \
                     frame or polarizer images as grayscale PNGs (a grey image saved as RGB, \
                     with three equal channels, is read as grey)",
                    w * h
                ),
            ));
        }
        Ok(raw.chunks_exact(stride).map(|p| p[0]).collect())
    };
    let narrow = |v: Vec<u16>| v.into_iter().map(|c| c as u8).collect::<Vec<u8>>();
    let wide = |raw: Vec<u8>| raw.into_iter().map(u16::from).collect::<Vec<u16>>();
    use image::DynamicImage as D;
    Ok(match img {
        D::ImageLuma8(b) => GrayPng::Bits8(Image::from_vec(w, h, b.into_raw())?),
        D::ImageLuma16(b) => GrayPng::Bits16(Image::from_vec(w, h, b.into_raw())?),
        D::ImageRgb8(b) => {
            GrayPng::Bits8(Image::from_vec(w, h, narrow(grey(wide(b.into_raw()), 3)?))?)
        }
        D::ImageRgba8(b) => {
            GrayPng::Bits8(Image::from_vec(w, h, narrow(grey(wide(b.into_raw()), 4)?))?)
        }
        D::ImageRgb16(b) => GrayPng::Bits16(Image::from_vec(w, h, grey(b.into_raw(), 3)?)?),
        D::ImageRgba16(b) => GrayPng::Bits16(Image::from_vec(w, h, grey(b.into_raw(), 4)?)?),
        other => {
            return Err(Error::file(
                path,
                format!("unsupported PNG pixel format {:?}", other.color()),
            ));
        }
    })
}

fn encode_png(img: image::DynamicImage, path: &Path) -> Result<()> {
    let mut buf = Cursor::new(Vec::new());
    img.write_to(&mut buf, image::ImageFormat::Png)
        .map_err(|e| Error::file(path, format!("PNG encoding failed: {e}")))?;
    write_atomic(path, buf.get_ref())
}

fn dims_u32(w: usize, h: usize, path: &Path) -> Result<(u32, u32)> {
    match (u32::try_from(w), u32::try_from(h)) {
        (Ok(w), Ok(h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => Err(Error::file(path, format!("cannot write a {w}×{h} image"))),
    }
}

/// Writes a 16-bit grayscale PNG.
pub fn write_png16(path: &Path, img: &Image<u16>) -> Result<()> {
    let (w, h) = dims_u32(img.width(), img.height(), path)?;
    let buf = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, img.data().to_vec())
        .expect("buffer size matches");
    encode_png(image::DynamicImage::ImageLuma16(buf), path)
}

/// Writes an 8-bit grayscale PNG.
pub fn write_png8(path: &Path, img: &Image<u8>) -> Result<()> {
    let (w, h) = dims_u32(img.width(), img.height(), path)?;
    let buf = image::ImageBuffer::<image::Luma<u8>, _>::from_raw(w, h, img.data().to_vec())
        .expect("buffer size matches");
    encode_png(image::DynamicImage::ImageLuma8(buf), path)
}

/// Writes an 8-bit RGB PNG (previews).
pub fn write_png_rgb(path: &Path, img: &Image<[u8; 3]>) -> Result<()> {
    let (w, h) = dims_u32(img.width(), img.height(), path)?;
    let raw: Vec<u8> = img.data().iter().flatten().copied().collect();
    let buf = image::RgbImage::from_raw(w, h, raw).expect("buffer size matches");
    encode_png(image::DynamicImage::ImageRgb8(buf), path)
}

/// Writes a 16-bit RGB PNG (normal maps exported at full precision).
pub fn write_png_rgb16(path: &Path, img: &Image<[u16; 3]>) -> Result<()> {
    let (w, h) = dims_u32(img.width(), img.height(), path)?;
    let raw: Vec<u16> = img.data().iter().flatten().copied().collect();
    let buf =
        image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(w, h, raw).expect("buffer size matches");
    encode_png(image::DynamicImage::ImageRgb16(buf), path)
}

/// Writes colour codes as an RGB PNG of `bits` (8 or 16) bits per channel.
pub fn write_png_rgb_codes(path: &Path, img: &Image<[u16; 3]>, bits: u8) -> Result<()> {
    if bits <= 8 {
        write_png_rgb(path, &img.map(|p| p.map(|c| c.min(255) as u8)))
    } else {
        write_png_rgb16(path, img)
    }
}

/// Reads a PNG picture as 16-bit RGB (8-bit values are scaled to 16 bits).
pub fn read_png_rgb16(path: &Path) -> Result<Image<[u16; 3]>> {
    let img = decode_png(&read_bytes(path)?, path)?.into_rgb16();
    rgb_image(img.width(), img.height(), img.into_raw())
}

/// Reads a PNG picture as 8-bit RGB (grayscale is repeated, alpha dropped,
/// 16-bit narrowed): previews, normal and error maps.
pub fn read_png_rgb(path: &Path) -> Result<Image<[u8; 3]>> {
    let img = decode_png(&read_bytes(path)?, path)?.into_rgb8();
    rgb_image(img.width(), img.height(), img.into_raw())
}

/// Interleaved RGB samples as an image of pixels.
fn rgb_image<T: Copy>(w: u32, h: u32, raw: Vec<T>) -> Result<Image<[T; 3]>> {
    let data = raw.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Image::from_vec(w as usize, h as usize, data)
}

/// Writes one EXR layer of named 32-bit float channels of equal size.
pub fn write_exr(path: &Path, channels: &[(&str, &Image<f32>)]) -> Result<()> {
    use exr::prelude::{
        AnyChannel, AnyChannels, Encoding, FlatSamples, Layer, LayerAttributes, WritableImage,
    };
    let Some((_, first)) = channels.first() else {
        return Err(Error::file(path, "no channels to write"));
    };
    let size = first.size();
    if channels.iter().any(|(_, c)| c.size() != size) {
        return Err(Error::file(path, "EXR channels differ in size"));
    }
    dims_u32(size.0, size.1, path)?;
    let list = channels
        .iter()
        .map(|(name, c)| AnyChannel::new(*name, FlatSamples::F32(c.data().to_vec())))
        .collect();
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let mut buf = Cursor::new(Vec::new());
    exr::image::Image::from_layer(layer)
        .write()
        .to_buffered(&mut buf)
        .map_err(|e| Error::file(path, format!("EXR encoding failed: {e}")))?;
    write_atomic(path, buf.get_ref())
}

/// Most samples (pixels × channels) an EXR may declare: 128 MiB of 32-bit
/// floats, e.g. three channels of 3300² pixels or a 4096 × 2048 RGB
/// environment map. Reading holds the decoded channels and their copies, so
/// the peak stays far below 1 GB.
pub const EXR_MAX_SAMPLES: usize = 1 << 25;

/// Reads the named channels of the first layer of an EXR file as 32-bit
/// floats; a missing channel is an error naming the channels present.
pub fn read_exr(path: &Path, names: &[&str]) -> Result<Vec<Image<f32>>> {
    exr_from_bytes(&read_bytes(path)?, path, names)
}

/// [`read_exr`] on the file's content (`path` names errors).
pub fn exr_from_bytes(bytes: &[u8], path: &Path, names: &[&str]) -> Result<Vec<Image<f32>>> {
    use exr::prelude::{ReadChannels, ReadLayers};
    let unreadable = |e: exr::error::Error| Error::file(path, format!("not a readable EXR: {e}"));
    // exr allocates every channel of the declared size before reading any
    // pixel, so a header of a few bytes could ask for any amount of memory.
    let meta =
        exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(unreadable)?;
    for header in &meta.headers {
        let (size, channels) = (header.layer_size, header.channels.list.len());
        let samples = size
            .0
            .checked_mul(size.1)
            .and_then(|a| a.checked_mul(channels));
        if samples.is_none_or(|n| n > EXR_MAX_SAMPLES) {
            return Err(Error::file(
                path,
                format!(
                    "declares {}×{} pixels × {channels} channels, more than the {EXR_MAX_SAMPLES} samples this reader accepts",
                    size.0, size.1
                ),
            ));
        }
    }
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(unreadable)?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    names
        .iter()
        .map(|name| {
            let ch = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name.to_string() == *name)
                .ok_or_else(|| {
                    let present: Vec<String> = layer
                        .channel_data
                        .list
                        .iter()
                        .map(|c| c.name.to_string())
                        .collect();
                    Error::file(
                        path,
                        format!("missing channel {name:?} (channels present: {present:?})"),
                    )
                })?;
            Image::from_vec(w, h, ch.sample_data.values_as_f32().collect())
        })
        .collect()
}

/// Writes a normal map as float RGB EXR (`R, G, B = n_x, n_y, n_z`).
pub fn write_normals(path: &Path, normals: &NormalMap) -> Result<()> {
    let ch = |k: usize| normals.map(|n| n[k]);
    write_exr(path, &[("R", &ch(0)), ("G", &ch(1)), ("B", &ch(2))])
}

/// Reads a normal map written by [`write_normals`]; non-finite values are an
/// error (a method that has no normal writes `[0, 0, 0]`).
pub fn read_normals(path: &Path) -> Result<NormalMap> {
    let normals = read_rgb_exr(path)?;
    let w = normals.width();
    if let Some(i) = normals
        .data()
        .iter()
        .position(|n| n.iter().any(|v| !v.is_finite()))
    {
        return Err(Error::file(
            path,
            format!("non-finite normal at column {}, row {}", i % w, i / w),
        ));
    }
    Ok(normals)
}

/// The `R, G, B` channels of an EXR file as one vector a pixel, whatever
/// their values (another tool's normals may hold NaN where it has none).
pub fn read_rgb_exr(path: &Path) -> Result<Image<[f32; 3]>> {
    let c = read_exr(path, &["R", "G", "B"])?;
    let (w, h) = c[0].size();
    Image::from_vec(
        w,
        h,
        (0..w * h)
            .map(|i| [c[0].data()[i], c[1].data()[i], c[2].data()[i]])
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_png_round_trip_and_gray_as_rgb() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.png");
        let img = Image::from_fn(3, 2, |x, y| [x as u8 * 80, y as u8 * 200, 7]);
        write_png_rgb(&p, &img).unwrap();
        assert_eq!(read_png_rgb(&p).unwrap(), img);
        let g = dir.path().join("g.png");
        write_png8(&g, &Image::new(2, 2, 9u8)).unwrap();
        assert_eq!(read_png_rgb(&g).unwrap(), Image::new(2, 2, [9u8; 3]));
    }

    #[test]
    fn sensor_images_are_grey_or_rgb_with_equal_channels() {
        let dir = tempfile::tempdir().unwrap();
        let grey = dir.path().join("grey.png");
        let img = Image::from_fn(3, 2, |x, y| [x as u16 * 9000 + y as u16; 3]);
        write_png_rgb16(&grey, &img).unwrap();
        let back = read_mono_png(&grey).unwrap();
        assert_eq!(back, GrayPng::Bits16(img.map(|p| p[0])));
        let colour = dir.path().join("colour.png");
        write_png_rgb(
            &colour,
            &Image::from_fn(3, 2, |x, _| [200, 100 + x as u8, 50]),
        )
        .unwrap();
        let e = read_mono_png(&colour).unwrap_err().to_string();
        assert!(
            e.contains("colour.png") && e.contains("an RGB picture"),
            "{e}"
        );
        assert!(
            e.contains("differ at 6 of 6 pixels") && e.contains("grayscale"),
            "{e}"
        );
    }

    #[test]
    fn png16_round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.png");
        let img = Image::from_fn(7, 5, |x, y| (x * 9000 + y * 1111) as u16);
        write_png16(&p, &img).unwrap();
        assert_eq!(read_gray_png(&p).unwrap(), GrayPng::Bits16(img));
    }

    #[test]
    fn exr_round_trip_is_bit_exact_including_nan() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.exr");
        let a = Image::from_fn(6, 4, |x, y| (x as f32 * 0.1 - y as f32).sin() * 1e-3);
        let mut b = Image::from_fn(6, 4, |x, y| x as f32 / (y as f32 + 1.0));
        *b.get_mut(2, 1) = f32::NAN;
        write_exr(&p, &[("Y", &a), ("Z", &b)]).unwrap();
        let back = read_exr(&p, &["Z", "Y"]).unwrap();
        let bits = |i: &Image<f32>| i.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back[0]), bits(&b));
        assert_eq!(bits(&back[1]), bits(&a));
    }

    #[test]
    fn exr_declaring_a_huge_image_is_refused_before_allocating() {
        // Found by the `exr` fuzz target: a data window of 2^26 × 8 pixels ×
        // 3 channels in a file of a few hundred bytes (2 GB allocated).
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("huge.exr");
        let one = Image::new(1, 1, 0.0f32);
        write_exr(&p, &[("R", &one), ("G", &one), ("B", &one)]).unwrap();
        let mut bytes = std::fs::read(&p).unwrap();
        // The data window (box2i: x_min, y_min, x_max, y_max) of the 1×1 image.
        let window = [0i32, 0, 0, 0].map(i32::to_le_bytes).concat();
        let name = b"dataWindow\0box2i\0";
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
        assert_eq!(bytes[at..at + 16], window);
        bytes[at + 8..at + 12].copy_from_slice(&((1i32 << 26) - 1).to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&7i32.to_le_bytes());
        let e = exr_from_bytes(&bytes, Path::new("huge.exr"), &["R"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("huge.exr") && e.contains("67108864×8 pixels × 3 channels"),
            "{e}"
        );
    }

    #[test]
    fn missing_channel_and_corruption_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.exr");
        write_exr(&p, &[("Y", &Image::new(3, 3, 1.0f32))]).unwrap();
        let e = read_exr(&p, &["R"]).unwrap_err().to_string();
        assert!(e.contains("a.exr") && e.contains("\"R\""), "{e}");
        let bytes = std::fs::read(&p).unwrap();
        std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
        let e = read_exr(&p, &["Y"]).unwrap_err().to_string();
        assert!(e.contains("a.exr"), "{e}");
        let q = dir.path().join("b.png");
        write_png16(&q, &Image::new(8, 8, 7u16)).unwrap();
        let bytes = std::fs::read(&q).unwrap();
        std::fs::write(&q, &bytes[..bytes.len() - 20]).unwrap();
        let e = read_gray_png(&q).unwrap_err().to_string();
        assert!(e.contains("b.png"), "{e}");
    }

    #[test]
    fn a_pipe_a_device_or_a_folder_is_refused_without_reading() {
        // A FIFO would block a read for ever, /dev/zero fill the memory.
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("mask.png");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        let mut refused = vec![
            Path::new("/dev/zero").to_path_buf(),
            dir.path().to_path_buf(),
        ];
        if made.is_ok_and(|s| s.success()) {
            refused.push(fifo);
        }
        for path in refused {
            let err = read_gray_png(&path).unwrap_err().to_string();
            assert!(
                err.contains(&path.display().to_string()) && err.contains("not an image file"),
                "{err}"
            );
        }
    }
}
