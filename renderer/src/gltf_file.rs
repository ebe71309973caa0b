//! A glTF file read without trusting it: the validated document, its
//! buffers, and the files its URIs name, only inside the model's folder.
//! The mesh loader and the texture loader both read models through it.

use sfp_core::{Error, Result};
use std::path::Path;

/// A validated glTF document and the GLB binary chunk, if any. gltf's
/// validation reads the accessor a primitive's `POSITION` names before it
/// checks that the accessor exists (a panic for a missing one), so that
/// reference is checked here first.
pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<(gltf::Document, Option<Vec<u8>>)> {
    use gltf::json::{mesh::Semantic, validation::Checked};
    let unreadable = |e: gltf::Error| Error::file(path, format!("cannot read glTF: {e}"));
    // gltf subtracts the 12-byte header from the GLB length field unchecked.
    if let Some(length) = bytes.strip_prefix(b"glTF").and_then(|b| b.get(4..8)) {
        let length = u32::from_le_bytes(length.try_into().expect("4 bytes"));
        if length < 12 {
            return Err(Error::file(
                path,
                format!("GLB length {length} is shorter than its 12-byte header"),
            ));
        }
    }
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(unreadable)?;
    let json = document.into_json();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let position = prim.attributes.get(&Checked::Valid(Semantic::Positions));
            if let Some(a) = position.filter(|a| a.value() >= json.accessors.len()) {
                return Err(Error::file(
                    path,
                    format!(
                        "meshes[{m}].primitives[{p}]: POSITION names accessor {}, but the file has {}",
                        a.value(),
                        json.accessors.len()
                    ),
                ));
            }
        }
    }
    let document = gltf::Document::from_json(json).map_err(unreadable)?;
    Ok((document, blob))
}

/// The data of a glTF model's buffers: the GLB binary chunk, `data:` URIs,
/// or files inside the model's folder. Other URIs (absolute paths, `..`,
/// `file:` and other schemes) are refused, so a model cannot make the loader
/// read files elsewhere (`gltf::import` follows them). Texture images are
/// read the same way, and only the one a map asks for (`texture.rs`).
pub(crate) fn buffers(
    doc: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    path: &Path,
) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                Error::file(
                    path,
                    format!("buffer {i} refers to a missing GLB binary chunk"),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => {
                read_uri(uri, path).map_err(|e| Error::file(path, format!("buffer {i}: {e}")))?
            }
        };
        if data.len() < buffer.length() {
            return Err(Error::file(
                path,
                format!(
                    "buffer {i} holds {} bytes, less than its byteLength {}",
                    data.len(),
                    buffer.length()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// The bytes a glTF URI names: a `data:` URI's, or a file's inside the
/// model's folder (`path`'s); any other URI is refused.
pub(crate) fn read_uri(uri: &str, path: &Path) -> std::result::Result<Vec<u8>, String> {
    if uri.starts_with("data:") {
        return gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), None)
            .map(|d| d.0)
            .map_err(|e| e.to_string());
    }
    let file = inside_folder(uri)
        .ok_or_else(|| format!("URI {uri:?} is not a relative path inside the model's folder"))?;
    let file = path.parent().unwrap_or(Path::new(".")).join(file);
    std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))
}

/// A percent-encoded relative URI as a path that stays inside its folder.
fn inside_folder(uri: &str) -> Option<std::path::PathBuf> {
    if uri.contains(':') {
        return None;
    }
    let decoded = urlencoding::decode(uri).ok()?;
    let rel = Path::new(&*decoded);
    let plain = rel
        .components()
        .all(|c| matches!(c, std::path::Component::Normal(_)));
    (plain && rel.components().next().is_some()).then(|| rel.to_path_buf())
}
