//! The scene prepared for rendering: camera, lights, analytic shapes, one
//! triangle BVH over all meshes, and a material per object.

use crate::bsdf::Material;
use crate::builtin::builtin_mesh;
use crate::bundle::{Bundle, Frustum};
use crate::bvh::{InputTriangle, TriangleBvh};
use crate::camera::{Camera, Projection};
use crate::lights::{Area, Built, Environment, Light};
use crate::materials::{SurfaceMaps, SurfacePoint};
use crate::mesh::{Mesh, Placement};
use crate::scene::{CameraKind, ObjectDesc, Scene, ShapeKind};
use crate::scene_file::Table;
use crate::shapes::{Plane, Sphere};
use glam::{Affine3A, DVec3, Vec2, Vec3, Vec3A};
use sfp_core::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Sphere(Sphere),
    Plane(Plane),
}

/// A ray–surface intersection.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub p: Vec3A,
    /// Unit geometric normal (as defined by the surface, not face-forwarded).
    pub ng: Vec3A,
    /// Unit shading normal, on the same side as `ng`.
    pub ns: Vec3A,
    /// Texture coordinates (origin top-left); zero on untextured analytic
    /// shapes.
    pub uv: Vec2,
    pub object: u32,
    /// Triangle index in the BVH (`u32::MAX` on analytic shapes).
    pub prim: u32,
}

impl Hit {
    /// Geometric and shading normals facing the viewer at `wo` (surfaces are
    /// two-sided). At silhouettes of tessellated surfaces the interpolated
    /// normal can turn away from the viewer while the visible facet cannot:
    /// there the facet normal shades (and is the ground truth), instead of a
    /// black pixel.
    #[inline]
    pub fn facing(&self, wo: Vec3A) -> (Vec3A, Vec3A) {
        let (ng, ns) = if self.ng.dot(wo) < 0.0 {
            (-self.ng, -self.ns)
        } else {
            (self.ng, self.ns)
        };
        (ng, if ns.dot(wo) > 0.0 { ns } else { ng })
    }
}

pub struct World {
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub environment: Option<Environment>,
    /// Area lights again, for rays that hit them.
    pub area_lights: Vec<Area>,
    pub materials: Vec<Material>,
    /// Maps of each object whose material varies over its surface.
    surfaces: Vec<Option<SurfaceMaps>>,
    shapes: Vec<(Shape, u32)>,
    triangles: Option<TriangleBvh>,
}

/// Tessellation of built-in objects in scenes: fine enough that flat
/// facets stay well below a pixel at 1024² (20–60k triangles each).
const BUILTIN_DETAIL: f32 = 1.0;

fn v3(a: [f64; 3]) -> Vec3A {
    DVec3::from(a).as_vec3a()
}

/// An object's surface: an analytic shape, or a placed mesh.
enum Geometry {
    Shape(Shape),
    Mesh(Mesh),
}

impl World {
    /// Builds the camera, each light and each object's material (by their
    /// kinds, which load their files), loads meshes and builds the
    /// acceleration structure.
    pub fn build(scene: &Scene) -> Result<World> {
        let d = &scene.desc;
        let camera = camera(scene)?;
        let mut lights = Vec::new();
        let mut environment = None;
        for (i, l) in d.lights.iter().enumerate() {
            match l.build(&Table::new(&scene.source, format!("light[{i}]")))? {
                Built::Light(light) => lights.push(light),
                Built::Environment(e) => environment = Some(e),
            }
        }
        let area_lights = lights.iter().filter_map(Light::area).collect();
        let mut materials = Vec::new();
        let mut surfaces = Vec::new();
        let mut shapes = Vec::new();
        let mut tris = Vec::new();
        for (i, o) in d.objects.iter().enumerate() {
            let id = i as u32;
            let t = Table::new(&scene.source, format!("object[{i}].material"));
            let (material, maps) = o.material.build(&t, object_to_world(o))?;
            materials.push(material);
            surfaces.push(maps);
            match geometry(scene, i, o)? {
                Geometry::Shape(shape) => shapes.push((shape, id)),
                Geometry::Mesh(mesh) => add_triangles(&mut tris, &mesh, id),
            }
        }
        Ok(World {
            camera,
            lights,
            environment,
            area_lights,
            materials,
            surfaces,
            shapes,
            triangles: TriangleBvh::build(&tris),
        })
    }

    /// Whether some surface reflects with a specular lobe (a material's own
    /// weight or a spatially varying map), so views record the mixture.
    pub fn has_specular_lobe(&self) -> bool {
        self.materials.iter().any(|m| m.specular > 0.0)
            || self
                .surfaces
                .iter()
                .flatten()
                .any(SurfaceMaps::has_specular)
    }

    /// Whether BSDF-sampled rays can reach light (and must be traced even
    /// at the last vertex).
    pub fn has_hittable_lights(&self) -> bool {
        self.environment.is_some() || !self.area_lights.is_empty()
    }

    /// The nearest area light hit before `tmax`: its radiance and the
    /// solid-angle density light sampling would have had.
    #[inline]
    pub fn emitter_hit(&self, origin: Vec3A, dir: Vec3A, tmax: f32) -> Option<(f32, f32)> {
        let mut best: Option<(f32, f32, f32)> = None;
        for a in &self.area_lights {
            let limit = best.map_or(tmax, |b| b.0);
            if let Some((t, pdf)) = a.hit(origin, dir, limit) {
                best = Some((t, a.radiance, pdf));
            }
        }
        best.map(|(_, radiance, pdf)| (radiance, pdf))
    }

    /// The material at a hit seen from `wo`, with its maps applied, and the
    /// geometric and shading normals facing the viewer ([`Hit::facing`],
    /// then normal-mapped).
    #[inline]
    pub fn shade(&self, hit: &Hit, wo: Vec3A) -> (Material, Vec3A, Vec3A) {
        let i = hit.object as usize;
        let (ng, ns) = hit.facing(wo);
        match &self.surfaces[i] {
            None => (self.materials[i], ng, ns),
            Some(maps) => {
                let (m, n) = self.mapped(maps, hit, ns, wo);
                (m, ng, n)
            }
        }
    }

    /// The maps' material and shading normal at a hit. Kept out of line:
    /// inlined into the path tracer's loop it cost renders of constant
    /// materials ~4% more instructions.
    #[inline(never)]
    fn mapped(&self, maps: &SurfaceMaps, hit: &Hit, ns: Vec3A, wo: Vec3A) -> (Material, Vec3A) {
        let point = SurfacePoint {
            p: hit.p,
            uv: hit.uv,
            dpdu: self.tangent(maps, hit),
        };
        maps.at(self.materials[hit.object as usize], &point, ns, wo)
    }

    /// `∂p/∂u` at a hit of a surface with `maps` (only maps looked up by
    /// texture coordinates need it).
    fn tangent(&self, maps: &SurfaceMaps, hit: &Hit) -> Vec3A {
        if !maps.uses_uv() {
            return Vec3A::ZERO;
        }
        if let Some(bvh) = &self.triangles
            && hit.prim != u32::MAX
        {
            return bvh.tangent(hit.prim);
        }
        match self.shapes.iter().find(|s| s.1 == hit.object).map(|s| s.0) {
            // u is the azimuth atan2(x, −z)/2π.
            Some(Shape::Sphere(s)) => {
                let n = s.normal(hit.p);
                Vec3A::new(-n.z, 0.0, n.x) * (std::f32::consts::TAU * s.radius)
            }
            Some(Shape::Plane(pl)) => pl.u,
            None => Vec3A::ZERO,
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.as_ref().map_or(0, TriangleBvh::len)
    }

    /// Closest hit along unit `dir` within `(tmin, tmax)`; `bundle`, when
    /// given, holds the gathered leaves of a bundle the ray belongs to.
    #[inline]
    pub fn intersect(
        &self,
        bundle: Option<&Bundle>,
        origin: Vec3A,
        dir: Vec3A,
        tmin: f32,
        tmax: f32,
    ) -> Option<Hit> {
        let mut best: Option<(f32, Shape, u32)> = None;
        let mut tmax = tmax;
        for &(shape, id) in &self.shapes {
            let t = match shape {
                Shape::Sphere(s) => s.intersect(origin, dir, tmin, tmax),
                Shape::Plane(p) => p.intersect(origin, dir, tmin, tmax),
            };
            if let Some(t) = t {
                tmax = t;
                best = Some((t, shape, id));
            }
        }
        if let Some(bvh) = &self.triangles
            && let Some((t, prim)) = match bundle {
                Some(bundle) => bvh.intersect_gathered(bundle, origin, dir, tmin, tmax),
                None => bvh.intersect(origin, dir, tmin, tmax),
            }
        {
            let p = origin + dir * t;
            let s = bvh.surface(prim, p);
            return Some(Hit {
                t,
                p,
                ng: s.geometric,
                ns: s.shading,
                uv: s.uv,
                object: s.object,
                prim,
            });
        }
        best.map(|(t, shape, object)| {
            let p = origin + dir * t;
            // Texture coordinates only for textured objects: the sphere's
            // (atan2, acos) cost ~9% of an untextured render.
            let textured = self.surfaces[object as usize]
                .as_ref()
                .is_some_and(SurfaceMaps::uses_uv);
            let (n, uv) = match shape {
                Shape::Sphere(s) => (s.normal(p), if textured { s.uv(p) } else { Vec2::ZERO }),
                Shape::Plane(pl) => (pl.normal, if textured { pl.uv(p) } else { Vec2::ZERO }),
            };
            Hit {
                t,
                p,
                ng: n,
                ns: n,
                uv,
                object,
                prim: u32::MAX,
            }
        })
    }

    /// Whether a ray in `frustum` may find anything: an environment or
    /// area light (which rays can see), a sphere, or the box of a square
    /// or of the triangles.
    pub fn may_see(&self, frustum: &Frustum) -> bool {
        self.has_hittable_lights()
            || (self.triangles.as_ref()).is_some_and(|b| frustum.may_overlap(b.bounds()))
            || self.shapes.iter().any(|&(shape, _)| match shape {
                Shape::Sphere(s) => frustum.may_overlap_ball(s.center, s.radius),
                Shape::Plane(p) => p.bounds().is_none_or(|b| frustum.may_overlap(&b)),
            })
    }

    /// Collects the triangle leaves the rays in `frustum` can reach (nothing
    /// in a scene without meshes).
    pub fn gather(&self, frustum: &Frustum, bundle: &mut Bundle) {
        match &self.triangles {
            Some(bvh) => bvh.gather(frustum, bundle),
            None => bundle.leaves.clear(),
        }
    }

    /// Whether anything blocks `(tmin, tmax)` along `dir`; `bundle`, when
    /// given, holds the gathered leaves of a bundle the ray belongs to.
    #[inline]
    pub fn occluded(
        &self,
        bundle: Option<&Bundle>,
        origin: Vec3A,
        dir: Vec3A,
        tmin: f32,
        tmax: f32,
    ) -> bool {
        self.shapes.iter().any(|&(shape, _)| match shape {
            Shape::Sphere(s) => s.intersect(origin, dir, tmin, tmax).is_some(),
            Shape::Plane(p) => p.intersect(origin, dir, tmin, tmax).is_some(),
        }) || self.triangles.as_ref().is_some_and(|b| match bundle {
            Some(bundle) => b.occluded_gathered(bundle, origin, dir, tmin, tmax),
            None => b.occluded(origin, dir, tmin, tmax),
        })
    }
}

/// The scene's camera.
fn camera(scene: &Scene) -> Result<Camera> {
    let c = &scene.desc.camera;
    let projection = match c.kind {
        CameraKind::Orthographic => Projection::Orthographic {
            extent: c.extent.unwrap_or(1.0) as f32,
        },
        CameraKind::Perspective => Projection::Perspective {
            fov: (c.fov.unwrap_or(45.0) as f32).to_radians(),
        },
    };
    Camera::look_at(
        c.width,
        c.height,
        v3(c.position),
        v3(c.look_at),
        v3(c.up),
        projection,
    )
    .ok_or_else(|| {
        Error::file(
            &scene.source,
            "`camera`: position equals look_at, or up is parallel to the view direction",
        )
    })
}

/// The placement of object `o`'s material maps: object space is the world
/// with its rotation and translation undone (procedural maps).
fn object_to_world(o: &ObjectDesc) -> Affine3A {
    if o.shape.is_some() {
        Affine3A::from_translation(v3(o.center.unwrap_or([0.0; 3])).into())
    } else {
        Affine3A::from_mat4(
            Placement {
                fit_unit_box: false,
                scale: 1.0,
                ..placement(o)
            }
            .matrix(),
        )
    }
}

/// How a mesh or built-in object is placed.
fn placement(o: &ObjectDesc) -> Placement {
    Placement {
        fit_unit_box: o.fit_unit_box,
        scale: o.scale as f32,
        rotate_deg: o.rotate.map(|x| x as f32),
        translate: o.translate.map(|x| x as f32),
    }
}

/// Object `i`'s surface: its shape, or its mesh (loaded or generated) placed
/// in the world.
fn geometry(scene: &Scene, i: usize, o: &ObjectDesc) -> Result<Geometry> {
    let center = v3(o.center.unwrap_or([0.0; 3]));
    let mut mesh = match (o.shape, &o.mesh, &o.builtin) {
        (Some(ShapeKind::Sphere), _, _) => {
            let radius = o.radius.unwrap_or(1.0) as f32;
            return Ok(Geometry::Shape(Shape::Sphere(Sphere { center, radius })));
        }
        (Some(ShapeKind::Plane), _, _) => {
            let size = o.size.map(|s| s as f32);
            let normal = v3(o.normal.unwrap_or([0.0, 0.0, 1.0]));
            return Ok(Geometry::Shape(Shape::Plane(Plane::new(
                center, normal, size,
            ))));
        }
        (None, Some(m), _) => Mesh::load(&scene.file_path(m)?)?,
        (None, None, Some(name)) => builtin_mesh(name, BUILTIN_DETAIL)
            .map_err(|e| Error::file(&scene.source, format!("`object[{i}]`: {e}")))?,
        (None, None, None) => {
            return Err(Error::file(
                &scene.source,
                format!("`object[{i}]`: give `shape`, `mesh` or `builtin`"),
            ));
        }
    };
    mesh.place(&placement(o));
    Ok(Geometry::Mesh(mesh))
}

/// Appends the triangles of object `object`'s placed mesh to the BVH's input.
fn add_triangles(tris: &mut Vec<InputTriangle>, mesh: &Mesh, object: u32) {
    let a = |p: Vec3| Vec3A::from(p);
    for t in &mesh.triangles {
        let [i0, i1, i2] = t.map(|k| k as usize);
        let vertices = [i0, i1, i2].map(|k| a(mesh.positions[k]));
        tris.push(InputTriangle {
            vertices,
            normals: [i0, i1, i2].map(|k| a(mesh.normals[k])),
            // Built-in objects have no texture coordinates.
            uvs: [i0, i1, i2].map(|k| mesh.uvs.get(k).copied().unwrap_or(Vec2::ZERO)),
            object,
        });
    }
}
