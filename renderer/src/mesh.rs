//! Triangle meshes from OBJ (`tobj`) and glTF/GLB (`gltf`), with per-vertex
//! shading normals (from the file, else area-weighted) and object transforms.
//!
//! Validation: non-finite coordinates, out-of-range indices and files without
//! triangles are errors naming the file. Zero-area triangles are dropped
//! (they cannot be hit and have no normal); non-triangle glTF primitives
//! (points, lines) are skipped.

use crate::{gltf_file, scene_file};
use glam::{Mat3, Mat4, Vec2, Vec3};
use sfp_core::{Error, Result};
use std::path::Path;

/// An indexed triangle mesh; `normals[i]` and `uvs[i]` belong to
/// `positions[i]`. Texture coordinates have their origin at the image's
/// top-left corner (glTF convention; OBJ's `v` is flipped on load) and are
/// `(0, 0)` when the file has none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub triangles: Vec<[u32; 3]>,
}

/// Object placement: optional fit into `[−1, 1]³`, then uniform scale,
/// rotation (XYZ Euler angles in degrees, applied x first) and translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub fit_unit_box: bool,
    pub scale: f32,
    pub rotate_deg: [f32; 3],
    pub translate: [f32; 3],
}

impl Default for Placement {
    fn default() -> Self {
        Placement {
            fit_unit_box: false,
            scale: 1.0,
            rotate_deg: [0.0; 3],
            translate: [0.0; 3],
        }
    }
}

impl Placement {
    /// The similarity transform (the fit part needs the mesh's bounds).
    pub fn matrix(&self) -> Mat4 {
        let [rx, ry, rz] = self.rotate_deg.map(f32::to_radians);
        let rotation = glam::Quat::from_euler(glam::EulerRot::ZYX, rz, ry, rx);
        Mat4::from_scale_rotation_translation(
            Vec3::splat(self.scale),
            rotation,
            Vec3::from(self.translate),
        )
    }
}

impl Mesh {
    /// Loads `.obj`, `.gltf` or `.glb` by extension.
    pub fn load(path: &Path) -> Result<Mesh> {
        if path.is_dir() {
            return Err(Error::file(
                path,
                "is a folder, not a mesh file (name the .obj, .gltf or .glb inside it)",
            ));
        }
        if !scene_file::is_file(path) {
            return Err(Error::file(path, "mesh file not found"));
        }
        Mesh::from_bytes(&scene_file::read(path)?, path)
    }

    /// Parses the content of the mesh file `path` (its extension picks the
    /// format; it names errors, and its folder holds a glTF's external buffers).
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Mesh> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let mesh = match ext.as_deref() {
            Some("obj") => load_obj(bytes, path)?,
            Some("gltf" | "glb") => load_gltf(bytes, path)?,
            _ => {
                return Err(Error::file(
                    path,
                    "unsupported mesh format (expected .obj, .gltf or .glb)",
                ));
            }
        };
        mesh.validated(path)
    }

    /// Appends `other`, renumbering its indices.
    fn append(&mut self, other: Mesh) {
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        self.uvs.extend(other.uvs);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }

    /// Rejects broken data, drops zero-area triangles and fills in missing or
    /// unusable normals.
    fn validated(mut self, path: &Path) -> Result<Mesh> {
        let n = self.positions.len();
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::file(
                path,
                format!("vertex {i} is not finite ({})", self.positions[i]),
            ));
        }
        if let Some(t) = self
            .triangles
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(Error::file(
                path,
                format!("triangle {t:?} indexes past the {n} vertices"),
            ));
        }
        let positions = &self.positions;
        self.triangles.retain(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a).length_squared() > 0.0
        });
        if self.triangles.is_empty() {
            return Err(Error::file(
                path,
                "the mesh has no triangles of non-zero area",
            ));
        }
        if self.normals.len() != n || self.normals.iter().any(|v| !v.is_finite()) {
            self.normals = area_weighted_normals(&self.positions, &self.triangles);
        }
        if self.uvs.len() != n || self.uvs.iter().any(|v| !v.is_finite()) {
            self.uvs = vec![Vec2::ZERO; n];
        }
        Ok(self)
    }

    /// Applies `placement` (and the fit to `[−1, 1]³` when asked).
    pub fn place(&mut self, placement: &Placement) {
        let mut m = placement.matrix();
        if placement.fit_unit_box {
            let (lo, hi) = self.positions.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            );
            let side = (hi - lo).max_element().max(f32::MIN_POSITIVE);
            m *= Mat4::from_scale(Vec3::splat(2.0 / side))
                * Mat4::from_translation(-0.5 * (lo + hi));
        }
        self.transform(&m);
    }

    /// Applies an affine transform; normals use the inverse transpose.
    pub fn transform(&mut self, m: &Mat4) {
        let nm = Mat3::from_mat4(*m).inverse().transpose();
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        for n in &mut self.normals {
            *n = (nm * *n).normalize_or_zero();
        }
    }
}

/// Vertex normals as the sum of adjacent face normals weighted by face area.
fn area_weighted_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let face = (b - a).cross(c - a); // length = 2 · area
        for &i in t {
            normals[i as usize] += face;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// Materials (`mtllib`) are not read: the scene gives the material, and a
/// library path could name any file.
fn load_obj(bytes: &[u8], path: &Path) -> Result<Mesh> {
    check_obj_indices(bytes, path)?;
    let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &tobj::GPU_LOAD_OPTIONS, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| Error::file(path, format!("cannot read OBJ: {e}")))?;
    let mut mesh = Mesh::default();
    for model in models {
        let m = model.mesh;
        let vec3s = |v: &[f32]| -> Vec<Vec3> { v.chunks_exact(3).map(Vec3::from_slice).collect() };
        let positions = vec3s(&m.positions);
        let normals = vec3s(&m.normals);
        let uvs: Vec<Vec2> = m
            .texcoords
            .chunks_exact(2)
            .map(|t| Vec2::new(t[0], 1.0 - t[1]))
            .collect();
        let part = Mesh {
            uvs: if uvs.len() == positions.len() {
                uvs
            } else {
                vec![Vec2::NAN; positions.len()]
            },
            normals: if normals.len() == positions.len() {
                normals
            } else {
                vec![Vec3::NAN; positions.len()]
            },
            positions,
            triangles: m
                .indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        };
        mesh.append(part);
    }
    Ok(mesh)
}

fn load_gltf(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let (doc, blob) = gltf_file::parse(bytes, path)?;
    let buffers = gltf_file::buffers(&doc, blob, path)?;
    let mut mesh = Mesh::default();
    let scenes: Vec<gltf::Scene> = match doc.default_scene() {
        Some(s) => vec![s],
        None => doc.scenes().collect(),
    };
    let mut stack: Vec<(gltf::Node, Mat4)> = scenes
        .iter()
        .flat_map(|s| s.nodes().map(|n| (n, Mat4::IDENTITY)))
        .collect();
    // glTF node hierarchies are disjoint trees; a file whose nodes form a
    // cycle (or share a child) would otherwise be walked forever.
    let mut visited = vec![false; doc.nodes().len()];
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(Error::file(
                path,
                format!(
                    "node {} is reached twice: the node hierarchy has a cycle or a shared child (glTF requires disjoint trees)",
                    node.index()
                ),
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(m) = node.mesh() {
            for prim in m.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    continue;
                }
                check_accessors(&prim, &buffers, path)?;
                let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
                let Some(positions) = reader.read_positions() else {
                    continue;
                };
                let positions: Vec<Vec3> = positions.map(Vec3::from).collect();
                let normals: Vec<Vec3> = match reader.read_normals() {
                    Some(n) => n.map(Vec3::from).collect(),
                    None => vec![Vec3::NAN; positions.len()],
                };
                let uvs: Vec<Vec2> = match reader.read_tex_coords(0) {
                    Some(t) => t.into_f32().map(Vec2::from).collect(),
                    None => vec![Vec2::NAN; positions.len()],
                };
                let indices: Vec<u32> = match reader.read_indices() {
                    Some(i) => i.into_u32().collect(),
                    None => (0..positions.len() as u32).collect(),
                };
                let mut part = Mesh {
                    positions,
                    normals,
                    uvs,
                    triangles: indices
                        .chunks_exact(3)
                        .map(|t| [t[0], t[1], t[2]])
                        .collect(),
                };
                part.transform(&world);
                mesh.append(part);
            }
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    Ok(mesh)
}

/// Checks every index of the OBJ's faces and lines (`v/vt/vn`) against the
/// elements it can refer to: from 1 to the file's count, or a relative index
/// from −1 back to the first element defined before the line. tobj turns an
/// out-of-range relative index into a huge one and multiplies it unchecked
/// (an overflow panic in builds with overflow checks).
fn check_obj_indices(bytes: &[u8], path: &Path) -> Result<()> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| Error::file(path, format!("not UTF-8 text: {e}")))?;
    const KINDS: [&str; 3] = ["v", "vt", "vn"];
    let kind_of = |line: &str| {
        let first = line.split_whitespace().next();
        KINDS.iter().position(|k| first == Some(k))
    };
    let mut total = [0i64; 3];
    for k in text.lines().filter_map(kind_of) {
        total[k] += 1;
    }
    let mut seen = [0i64; 3];
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some(k) if KINDS.contains(&k) => seen[KINDS.iter().position(|x| *x == k).unwrap()] += 1,
            Some("f" | "l") => {
                for word in words {
                    for (k, index) in word.split('/').enumerate().take(3) {
                        let Ok(i) = index.parse::<i64>() else {
                            continue; // empty, or a syntax error tobj reports
                        };
                        if i == 0 || i > total[k] || seen[k] + i < 0 {
                            return Err(Error::file(
                                path,
                                format!(
                                    "line {}: {} index {i} is out of range ({} defined, {} before this line)",
                                    n + 1,
                                    KINDS[k],
                                    total[k],
                                    seen[k]
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Checks the accessors of a primitive that the mesh reads against what
/// gltf's reader assumes without checking (or only in debug assertions): the
/// type of each attribute, at least one element, no sparse storage, and every
/// element inside its buffer view and the view inside its buffer. Otherwise
/// the reader panics, runs out of memory or quietly reads nothing.
fn check_accessors(prim: &gltf::Primitive, buffers: &[Vec<u8>], path: &Path) -> Result<()> {
    use gltf::accessor::{DataType as T, Dimensions as D};
    use gltf::mesh::Semantic;
    let attributes = prim.attributes().filter_map(|(semantic, a)| {
        let (dims, types): (D, &[T]) = match semantic {
            Semantic::Positions | Semantic::Normals => (D::Vec3, &[T::F32]),
            Semantic::TexCoords(0) => (D::Vec2, &[T::F32, T::U8, T::U16]),
            _ => return None,
        };
        Some((format!("{semantic:?}"), a, dims, types))
    });
    let indices = prim.indices().map(|a| {
        (
            "indices".to_string(),
            a,
            D::Scalar,
            &[T::U8, T::U16, T::U32][..],
        )
    });
    for (what, a, dims, types) in attributes.chain(indices) {
        let bad = |m: String| Error::file(path, format!("accessor {} ({what}): {m}", a.index()));
        if a.dimensions() != dims || !types.contains(&a.data_type()) {
            return Err(bad(format!(
                "is {:?} of {:?}, expected {dims:?} of one of {types:?}",
                a.dimensions(),
                a.data_type()
            )));
        }
        if a.count() == 0 {
            return Err(bad("has no elements".into()));
        }
        if a.sparse().is_some() {
            return Err(bad("sparse accessors are not supported".into()));
        }
        let Some(view) = a.view() else {
            return Err(bad("has no buffer view".into()));
        };
        let stride = view.stride().unwrap_or(a.size());
        if stride < a.size() {
            return Err(bad(format!(
                "buffer view {} has a stride of {stride} bytes, less than an element ({})",
                view.index(),
                a.size()
            )));
        }
        let end = (a.count() - 1)
            .checked_mul(stride)
            .and_then(|n| n.checked_add(a.size()))
            .and_then(|n| n.checked_add(a.offset()));
        if end.is_none_or(|end| end > view.length()) {
            return Err(bad(format!(
                "{} elements from byte {} run past the end of buffer view {} ({} bytes)",
                a.count(),
                a.offset(),
                view.index(),
                view.length()
            )));
        }
        let buffer = buffers.get(view.buffer().index()).map_or(0, Vec::len);
        if view
            .offset()
            .checked_add(view.length())
            .is_none_or(|end| end > buffer)
        {
            return Err(bad(format!(
                "buffer view {} (bytes {} + {}) runs past the end of buffer {} ({buffer} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shipped_meshes;

    fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn every_shipped_mesh_loads_whole() {
        for name in shipped_meshes::names().filter(|n| !n.ends_with(".png")) {
            let path = shipped_meshes::path(name).unwrap();
            let mesh = Mesh::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(
                mesh.triangles.len() > 2000,
                "{name}: {}",
                mesh.triangles.len()
            );
            assert!(mesh.normals.iter().all(|n| n.is_finite()), "{name}");
        }
    }

    #[test]
    fn obj_with_computed_normals_and_fit() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "quad.obj",
            "v 0 0 0\nv 4 0 0\nv 4 2 0\nv 0 2 0\nv 1 1 1\nf 1 2 3 4\nf 1 2 5\nf 1 1 2\n",
        );
        let mut m = Mesh::load(&p).unwrap();
        // The quad is split in two, the repeated-vertex face is dropped.
        assert_eq!(m.triangles.len(), 3);
        assert!((m.normals[3] - Vec3::Z).length() < 1e-6);
        m.place(&Placement {
            fit_unit_box: true,
            ..Placement::default()
        });
        let max = m.positions.iter().fold(Vec3::splat(-9.0), |a, &p| a.max(p));
        let min = m.positions.iter().fold(Vec3::splat(9.0), |a, &p| a.min(p));
        assert!((max.x - 1.0).abs() < 1e-6 && (min.x + 1.0).abs() < 1e-6);
        assert!((max.y - 0.5).abs() < 1e-6);
    }

    #[test]
    fn a_folder_given_as_a_mesh_is_named_as_such() {
        let dir = tempfile::tempdir().unwrap();
        let e = Mesh::load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("is a folder, not a mesh file"), "{e}");
    }

    #[test]
    fn a_gltf_node_cycle_is_an_error_not_a_hang() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "cycle.gltf",
            r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                "nodes": [{"children": [1]}, {"children": [0]}]}"#,
        );
        let e = Mesh::load(&p).unwrap_err().to_string();
        assert!(
            e.contains("cycle.gltf") && e.contains("reached twice"),
            "{e}"
        );
    }

    #[test]
    #[cfg(unix)]
    fn obj_material_libraries_are_not_read() {
        // Reading `/dev/zero` as a material library never ends.
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "lib.obj",
            "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        );
        assert_eq!(Mesh::load(&p).unwrap().triangles.len(), 1);
    }

    /// A one-triangle glTF whose buffer is the file `uri` names.
    fn triangle_gltf(uri: &str) -> String {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
                "nodes": [{{"mesh": 0}}], "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
                "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                                "min": [0, 0, 0], "max": [1, 1, 0]}}],
                "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
                "buffers": [{{"uri": "{uri}", "byteLength": 36}}]}}"#
        )
    }

    #[test]
    fn gltf_buffers_are_read_only_from_inside_the_model_folder() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("model");
        std::fs::create_dir_all(model.join("data")).unwrap();
        let floats = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let bytes: Vec<u8> = floats.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(model.join("data/tri a.bin"), &bytes).unwrap();
        std::fs::write(dir.path().join("outside.bin"), &bytes).unwrap();
        let p = write(&model, "ok.gltf", &triangle_gltf("data/tri%20a.bin"));
        assert_eq!(Mesh::load(&p).unwrap().triangles, vec![[0, 1, 2]]);
        let outside = dir.path().join("outside.bin");
        let outside = outside.to_str().unwrap();
        for uri in [
            "../outside.bin".to_string(),
            "data/../../outside.bin".to_string(),
            "%2e%2e/outside.bin".to_string(),
            outside.to_string(),
            format!("file://{outside}"),
            "https://example.com/tri.bin".to_string(),
            "%ff".to_string(),
        ] {
            let p = write(&model, "escape.gltf", &triangle_gltf(&uri));
            let e = Mesh::load(&p).unwrap_err().to_string();
            assert!(
                e.contains("escape.gltf") && e.contains("not a relative path inside"),
                "{uri}: {e}"
            );
        }
    }

    #[test]
    fn gltf_position_naming_a_missing_accessor_is_an_error_not_a_panic() {
        // Found by the `gltf` fuzz target (fuzz/README.md), minimized.
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "missing.gltf",
            r#"{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]}"#,
        );
        let e = Mesh::load(&p).unwrap_err().to_string();
        assert!(
            e.contains("missing.gltf") && e.contains("POSITION names accessor 0"),
            "{e}"
        );
    }

    #[test]
    fn glb_length_shorter_than_its_header_is_an_error_not_a_panic() {
        // Found by the `gltf` fuzz target: magic, version 2, length 0.
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("short.glb");
        std::fs::write(&p, b"glTF\x02\0\0\0\0\0\0\0\0\0\0\0JSON{}").unwrap();
        let e = Mesh::load(&p).unwrap_err().to_string();
        assert!(e.contains("short.glb") && e.contains("GLB length 0"), "{e}");
    }

    #[test]
    fn gltf_accessors_that_do_not_fit_are_errors_naming_them() {
        let dir = tempfile::tempdir().unwrap();
        let base = triangle_gltf(
            "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA",
        );
        assert!(Mesh::from_bytes(base.as_bytes(), &dir.path().join("ok.gltf")).is_ok());
        for (from, to, expected) in [
            (
                r#""count": 3"#,
                r#""count": 4"#,
                "run past the end of buffer view 0",
            ),
            (r#""count": 3"#, r#""count": 0"#, "has no elements"),
            (r#""type": "VEC3""#, r#""type": "VEC2""#, "expected Vec3"),
            (
                r#""byteLength": 36}]"#,
                r#""byteLength": 36, "byteOffset": 4}]"#,
                "runs past the end of buffer 0",
            ),
            (
                r#""byteLength": 36}]"#,
                r#""byteLength": 36, "byteStride": 4}]"#,
                "stride of 4 bytes",
            ),
        ] {
            let text = base.replacen(from, to, 1);
            assert_ne!(text, base, "{from}");
            let e = Mesh::from_bytes(text.as_bytes(), &dir.path().join("bad.gltf"))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("bad.gltf")
                    && e.contains("accessor 0 (Positions)")
                    && e.contains(expected),
                "{to}: {e}"
            );
        }
    }

    #[test]
    fn obj_indices_out_of_range_are_errors_not_panics() {
        // Found by the `obj` fuzz target (minimized): a relative texture index
        // before the first `vt` overflowed inside tobj.
        for (text, expected) in [
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/-55\n",
                "line 5: vt index -55",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//4611686018427387905 2 3\n",
                "vn index 4611686018427387905",
            ),
            (
                "v 0 0 0\nv 1 0 0\nf 1 2 -3\nv 0 1 0\n",
                "line 3: v index -3",
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "v index 0"),
        ] {
            let e = Mesh::from_bytes(text.as_bytes(), Path::new("idx.obj"))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("idx.obj") && e.contains(expected),
                "{text:?}: {e}"
            );
        }
        // A vertex defined after the face that names it is fine (absolute index).
        let late = "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n";
        assert_eq!(
            Mesh::from_bytes(late.as_bytes(), Path::new("late.obj"))
                .unwrap()
                .triangles
                .len(),
            1
        );
    }

    #[test]
    fn bad_meshes_are_errors_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            ("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"),
            ("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
            ("garbage.obj", "v 0 0\nf x y z\n"),
            ("bad.gltf", "{ not json"),
            ("mesh.ply", "ply\n"),
        ];
        for (name, text) in cases {
            let p = write(dir.path(), name, text);
            let err = Mesh::load(&p).expect_err(name).to_string();
            assert!(err.contains(name), "{err}");
        }
        let missing = Mesh::load(&dir.path().join("none.obj")).unwrap_err();
        assert!(missing.to_string().contains("none.obj"));
    }
}
