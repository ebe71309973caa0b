//! Image textures, looked up bilinearly with repeat wrapping. The renderer
//! is monochrome: albedo images are decoded as sRGB (the usual encoding of
//! colour and albedo textures, 8 or 16 bit, gray or RGB(A)) and reduced to
//! Rec. 709 luminance; data maps (roughness, specular weight, normals) are
//! linear and read one channel at a time. EXR files are always linear.

use crate::{gltf_file, scene_file};
use glam::Vec2;
use sfp_core::{Error, Result, io};
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<f32>,
}

/// Which of a glTF/GLB model's own textures a map takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelTexture {
    /// `baseColorTexture` (albedo).
    BaseColour,
    /// `metallicRoughnessTexture` (roughness in its green channel).
    MetallicRoughness,
    /// `normalTexture` (tangent-space normals).
    Normal,
}

impl ModelTexture {
    fn name(self) -> &'static str {
        match self {
            ModelTexture::BaseColour => "base-colour",
            ModelTexture::MetallicRoughness => "metallic-roughness",
            ModelTexture::Normal => "normal",
        }
    }
}

/// sRGB transfer function → linear.
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_lowercase)
}

/// Whether `path` names a glTF/GLB model (whose own textures are read).
pub fn is_model(path: &Path) -> bool {
    matches!(extension(path).as_deref(), Some("gltf" | "glb"))
}

/// Largest side of a texture image: its decoded float copy (12 bytes a
/// texel, 0.8 GB at 8192²) is checked before it is made, since a 16384²
/// texture aborted the program under a 4 GB memory limit.
pub const MAX_TEXTURE_SIDE: u32 = 8192;

/// A decoder of `reader`'s image that refuses, from its header, an image
/// with a side beyond [`MAX_TEXTURE_SIDE`].
fn limited<R: std::io::BufRead + std::io::Seek>(
    mut reader: image::ImageReader<R>,
) -> image::ImageReader<R> {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    reader.limits(limits);
    reader
}

/// An 8/16-bit image file, or the `which` texture of a glTF/GLB model.
fn open_image(path: &Path, which: ModelTexture) -> Result<image::Rgb32FImage> {
    let img = if is_model(path) {
        gltf_texture(path, which)?
    } else {
        let bytes = scene_file::read(path)?;
        let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| Error::read(path, e))?;
        limited(reader).decode().map_err(|e| {
            Error::file(
                path,
                format!("cannot read texture: {e} (sides up to {MAX_TEXTURE_SIDE} are read)"),
            )
        })?
    };
    let img = img.to_rgb32f();
    if img.width() == 0 || img.height() == 0 {
        return Err(Error::file(path, "texture is empty"));
    }
    Ok(img)
}

impl Texture {
    /// An albedo texture: an image file, or the base-colour texture of a
    /// glTF/GLB model (its single one: models with one texture per part are
    /// refused, since an object has one albedo texture).
    pub fn load(path: &Path) -> Result<Texture> {
        if extension(path).as_deref() == Some("exr") {
            return Texture::load_linear(path, ModelTexture::BaseColour, 0);
        }
        let img = open_image(path, ModelTexture::BaseColour)?;
        let texels = img
            .pixels()
            .map(|p| {
                let [r, g, b] = p.0.map(srgb_to_linear);
                0.2126 * r + 0.7152 * g + 0.0722 * b
            })
            .collect();
        Ok(Texture::from_linear(
            img.width() as usize,
            img.height() as usize,
            texels,
        ))
    }

    /// Channel `channel` (0 = R, 1 = G, 2 = B; gray images have R = G = B)
    /// of an image read as linear data, or of a glTF/GLB model's `which`
    /// texture. EXR files give `R, G, B` or, for channel 0, a single `Y`.
    pub fn load_linear(path: &Path, which: ModelTexture, channel: usize) -> Result<Texture> {
        if extension(path).as_deref() == Some("exr") {
            let name = ["R", "G", "B"][channel];
            let img = io::read_exr(path, &[name])
                .or_else(|e| match channel {
                    0 => io::read_exr(path, &["Y"]),
                    _ => Err(e),
                })?
                .remove(0);
            let (w, h) = img.size();
            if w == 0 || h == 0 {
                return Err(Error::file(path, "texture is empty"));
            }
            if img.data().iter().any(|v| !v.is_finite()) {
                return Err(Error::file(path, "texture has non-finite values"));
            }
            return Ok(Texture::from_linear(w, h, img.data().to_vec()));
        }
        let img = open_image(path, which)?;
        let texels = img.pixels().map(|p| p.0[channel]).collect();
        Ok(Texture::from_linear(
            img.width() as usize,
            img.height() as usize,
            texels,
        ))
    }

    /// The smallest and largest texel.
    pub fn range(&self) -> (f32, f32) {
        self.texels
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    }

    /// From linear values, row-major with row 0 at `v = 0` (top).
    pub fn from_linear(width: usize, height: usize, texels: Vec<f32>) -> Texture {
        debug_assert_eq!(texels.len(), width * height);
        Texture {
            width,
            height,
            texels,
        }
    }

    /// Bilinear lookup at `uv` (origin top-left, repeating).
    #[inline]
    pub fn lookup(&self, uv: Vec2) -> f32 {
        let x = uv.x.rem_euclid(1.0) * self.width as f32 - 0.5;
        let y = uv.y.rem_euclid(1.0) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |i: f32, n: usize| (i as isize).rem_euclid(n as isize) as usize;
        let at =
            |i: f32, j: f32| self.texels[wrap(j, self.height) * self.width + wrap(i, self.width)];
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
        let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// The one `which` texture image of a glTF model (read with `TEXCOORD_0`,
/// as the mesh loader does; factors such as the base colour are left to the
/// scene's values). Its bytes come from the model's own buffers, a `data:`
/// URI or a file inside the model's folder, as the mesh's do
/// ([`gltf_file::buffers`]); no other image of the model is decoded.
fn gltf_texture(path: &Path, which: ModelTexture) -> Result<image::DynamicImage> {
    let bytes = scene_file::read(path)?;
    model_image_from_bytes(&bytes, path, which)
}

/// [`gltf_texture`] of a model's bytes read from `path` (whose folder holds
/// its external files); public for the fuzz targets.
pub fn model_image_from_bytes(
    bytes: &[u8],
    path: &Path,
    which: ModelTexture,
) -> Result<image::DynamicImage> {
    let (doc, blob) = gltf_file::parse(bytes, path)?;
    let name = which.name();
    let mut sources: Vec<usize> = Vec::new();
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let material = prim.material();
            let pbr = material.pbr_metallic_roughness();
            let found = match which {
                ModelTexture::BaseColour => pbr
                    .base_color_texture()
                    .map(|i| (i.tex_coord(), i.texture())),
                ModelTexture::MetallicRoughness => pbr
                    .metallic_roughness_texture()
                    .map(|i| (i.tex_coord(), i.texture())),
                ModelTexture::Normal => material
                    .normal_texture()
                    .map(|i| (i.tex_coord(), i.texture())),
            };
            let Some((tex_coord, texture)) = found else {
                continue;
            };
            if tex_coord != 0 {
                return Err(Error::file(
                    path,
                    format!("{name} texture uses TEXCOORD_{tex_coord}; only TEXCOORD_0 is read"),
                ));
            }
            let source = texture.source().index();
            if !sources.contains(&source) {
                sources.push(source);
            }
        }
    }
    let source = match sources[..] {
        [one] => one,
        [] => {
            return Err(Error::file(
                path,
                format!("the model has no {name} texture"),
            ));
        }
        _ => {
            return Err(Error::file(
                path,
                format!(
                    "the model has {} {name} textures (one per part); an object takes one",
                    sources.len()
                ),
            ));
        }
    };
    let image = doc
        .images()
        .nth(source)
        .ok_or_else(|| Error::file(path, format!("{name} texture names a missing image")))?;
    // gltf's `source()` unwraps what the format requires but its validation
    // does not check: a URI or a buffer view, and a MIME type with the view.
    let json = &doc.as_json().images[source];
    match (&json.buffer_view, &json.uri, &json.mime_type) {
        (None, None, _) => {
            return Err(Error::file(
                path,
                format!("{name} texture: image {source} has neither a uri nor a bufferView"),
            ));
        }
        (Some(_), _, None) => {
            return Err(Error::file(
                path,
                format!("{name} texture: image {source} has a bufferView but no mimeType"),
            ));
        }
        _ => {}
    }
    let encoded = match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buffers = gltf_file::buffers(&doc, blob, path)?;
            let (start, len) = (view.offset(), view.length());
            buffers[view.buffer().index()]
                .get(start..start.saturating_add(len))
                .ok_or_else(|| {
                    Error::file(
                        path,
                        format!("{name} texture's buffer view runs past its buffer"),
                    )
                })?
                .to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => gltf_file::read_uri(uri, path)
            .map_err(|e| Error::file(path, format!("{name} texture: {e}")))?,
    };
    let reader = image::ImageReader::new(std::io::Cursor::new(encoded))
        .with_guessed_format()
        .map_err(|e| Error::file(path, format!("{name} texture: {e}")))?;
    limited(reader)
        .decode()
        .map_err(|e| Error::file(path, format!("cannot read {name} texture: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_hits_texel_centres_and_wraps() {
        let t = Texture::from_linear(2, 2, vec![0.0, 1.0, 2.0, 3.0]);
        assert_eq!(t.lookup(Vec2::new(0.25, 0.25)), 0.0);
        assert_eq!(t.lookup(Vec2::new(0.75, 0.75)), 3.0);
        assert_eq!(t.lookup(Vec2::new(1.25, -0.75)), 0.0);
        assert!((t.lookup(Vec2::new(0.5, 0.25)) - 0.5).abs() < 1e-6);
    }

    /// A glTF model of `parts` triangles, part `i` with material `i` whose
    /// base-colour texture is image `i` (`tex{i}.png`), or untextured.
    fn write_gltf(dir: &Path, name: &str, parts: usize, textured: bool) -> std::path::PathBuf {
        let mut bytes = Vec::new();
        for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bytes.extend(v.to_le_bytes());
        }
        for v in [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0] {
            bytes.extend(v.to_le_bytes());
        }
        std::fs::write(dir.join("buf.bin"), &bytes).unwrap();
        let prims: Vec<String> = (0..parts)
            .map(|i| format!(r#"{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"material":{i}}}"#))
            .collect();
        let materials: Vec<String> = (0..parts)
            .map(|i| {
                if textured {
                    format!(r#"{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":{i}}}}}}}"#)
                } else {
                    "{}".to_string()
                }
            })
            .collect();
        let textures: Vec<String> = (0..parts).map(|i| format!(r#"{{"source":{i}}}"#)).collect();
        let images: Vec<String> = (0..parts)
            .map(|i| format!(r#"{{"uri":"tex{i}.png"}}"#))
            .collect();
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{}]}}],
            "accessors":[
              {{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
              {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":24}}],
            "buffers":[{{"uri":"buf.bin","byteLength":60}}],
            "materials":[{}],"textures":[{}],"images":[{}]}}"#,
            prims.join(","),
            materials.join(","),
            if textured {
                textures.join(",")
            } else {
                String::new()
            },
            if textured {
                images.join(",")
            } else {
                String::new()
            },
        );
        let path = dir.join(name);
        std::fs::write(&path, json).unwrap();
        path
    }

    #[test]
    fn gltf_base_colour_texture_is_the_albedo_texture() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..2 {
            image::GrayImage::from_raw(2, 1, vec![255, 188 - 100 * i as u8])
                .unwrap()
                .save(dir.path().join(format!("tex{i}.png")))
                .unwrap();
        }
        let one = write_gltf(dir.path(), "one.gltf", 1, true);
        let from_model = Texture::load(&one).unwrap();
        assert_eq!(
            from_model,
            Texture::load(&dir.path().join("tex0.png")).unwrap()
        );
        let two = write_gltf(dir.path(), "two.gltf", 2, true);
        let err = Texture::load(&two).unwrap_err().to_string();
        assert!(
            err.contains("two.gltf") && err.contains("2 base-colour textures"),
            "{err}"
        );
        let plain = write_gltf(dir.path(), "plain.gltf", 1, false);
        let err = Texture::load(&plain).unwrap_err().to_string();
        assert!(
            err.contains("plain.gltf") && err.contains("no base-colour texture"),
            "{err}"
        );
    }

    /// A texture image is read from a `data:` URI or a file inside the
    /// model's folder, never from elsewhere (the mesh's buffer rule).
    #[test]
    fn gltf_texture_images_are_read_only_from_inside_the_model() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("model");
        std::fs::create_dir(&model).unwrap();
        let png = model.join("tex0.png");
        image::GrayImage::from_raw(2, 1, vec![255, 88])
            .unwrap()
            .save(&png)
            .unwrap();
        let path = write_gltf(&model, "one.gltf", 1, true);
        let json = std::fs::read_to_string(&path).unwrap();
        let with_image = |name: &str, uri: &str| {
            let p = model.join(name);
            std::fs::write(
                &p,
                json.replace(r#""uri":"tex0.png""#, &format!(r#""uri":"{uri}""#)),
            )
            .unwrap();
            Texture::load(&p)
        };
        let expected = Texture::load(&png).unwrap();
        let encoded = base64::encode(std::fs::read(&png).unwrap());
        let data_uri = format!("data:image/png;base64,{encoded}");
        assert_eq!(with_image("data.gltf", &data_uri).unwrap(), expected);
        std::fs::copy(&png, dir.path().join("outside.png")).unwrap();
        let outside = dir.path().join("outside.png").display().to_string();
        for uri in ["../outside.png", &outside, "file:///etc/hostname"] {
            let e = with_image("escape.gltf", uri).unwrap_err().to_string();
            assert!(
                e.contains("escape.gltf") && e.contains("not a relative path inside"),
                "{uri}: {e}"
            );
        }
        let e = with_image("missing.gltf", "nothing.png")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("missing.gltf") && e.contains("nothing.png"),
            "{e}"
        );
    }

    /// Found by the `gltf` fuzz target: an image with a buffer view and no
    /// MIME type (or with neither a URI nor a view) panicked in gltf.
    #[test]
    fn gltf_images_without_a_source_are_errors_not_panics() {
        let dir = tempfile::tempdir().unwrap();
        let path = write_gltf(dir.path(), "one.gltf", 1, true);
        let json = std::fs::read_to_string(&path).unwrap();
        for (image, needle) in [
            (r#"{"bufferView":0}"#, "has a bufferView but no mimeType"),
            ("{}", "has neither a uri nor a bufferView"),
        ] {
            let text = json.replace(r#"{"uri":"tex0.png"}"#, image);
            let bytes = text.as_bytes();
            let e = model_image_from_bytes(bytes, &path, ModelTexture::BaseColour)
                .unwrap_err()
                .to_string();
            assert!(e.contains("one.gltf") && e.contains(needle), "{e}");
        }
    }

    #[test]
    fn png_is_decoded_as_srgb_luminance() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.png");
        image::GrayImage::from_raw(2, 1, vec![255, 188])
            .unwrap()
            .save(&p)
            .unwrap();
        let t = Texture::load(&p).unwrap();
        assert!((t.texels[0] - 1.0).abs() < 1e-6);
        // sRGB 188/255 ≈ 0.5 linear.
        assert!((t.texels[1] - 0.5029).abs() < 1e-3, "{}", t.texels[1]);
        let err = Texture::load(&dir.path().join("none.png"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("none.png"));
    }

    #[test]
    fn a_texture_beyond_the_size_budget_is_refused_before_decoding() {
        let dir = tempfile::tempdir().unwrap();
        let wide = dir.path().join("wide.png");
        let side = MAX_TEXTURE_SIDE as usize + 1;
        sfp_core::io::write_png8(&wide, &sfp_core::Image::new(side, 1, 7u8)).unwrap();
        let err = Texture::load(&wide).unwrap_err().to_string();
        assert!(err.contains("wide.png") && err.contains("8192"), "{err}");
        let fits = dir.path().join("fits.png");
        sfp_core::io::write_png8(&fits, &sfp_core::Image::new(side - 1, 1, 7u8)).unwrap();
        assert!(Texture::load(&fits).is_ok());
    }
}
