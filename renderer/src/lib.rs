//! A polarized path tracer for shape-from-polarization data.
//!
//! `scene` (TOML) → `world` (meshes, BVH, lights) → `integrator` (polarized
//! path tracing with Mueller matrices, `mueller`, `bsdf`) → `sensor` →
//! a view on disk (conventions.md §5). Entry points: [`scene::Scene::load`],
//! [`render::render`] / [`render::render_with_progress`], [`render::Rendered::write`].
//!
//! A kind of light or material is one file of `lights/` or `materials/`:
//! its TOML keys (and their table), validation, build and behaviour; the
//! scene, the world and the sweeps reach it only through
//! [`lights::LightDesc`] and [`materials::MaterialDesc`].

pub mod appearance;
pub mod bsdf;
pub mod builtin;
pub mod bundle;
pub mod bvh;
pub mod camera;
pub mod dataset;
pub mod dataset_index;
mod gltf_file;
pub mod integrator;
pub mod lights;
pub mod materials;
pub mod mesh;
pub mod mueller;
pub mod normal_map;
pub mod pixel_bundles;
pub mod procedural;
pub mod ray_offset;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod scene_file;
pub mod sensor;
pub mod shapes;
pub mod shipped_meshes;
pub mod texture;
pub mod variates;
pub mod view_meta;
pub mod world;
