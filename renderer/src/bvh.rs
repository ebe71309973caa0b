//! Triangle BVH: a thin wrapper over obvhs' binary BVH, with the triangles
//! stored in BVH leaf order so traversal needs no index indirection.
//!
//! Measured on the 100k-triangle sphere bench (1 thread, 16 spp, CPU time
//! including the build): BVH2 with `slow_build` (spatial splits) 2.55 s,
//! BVH2 `medium_build` 2.70 s, CWBVH `medium_build` 2.9 s. The spatial
//! splits may list a triangle in several leaves; the reordering copies it.
//!
//! Also tried on the 100k-triangle bench scene (512², 16 spp, CPU time,
//! alternating runs), none faster: CWBVH 4.0 s vs 3.35 s; leaves of at
//! most 1, 2, 4, 8 triangles 3.5–3.3 s; a four-wide SIMD traversal of the
//! same tree (every second level folded into its parent) 3.18 s vs 3.05 s;
//! obvhs' 32-byte `small_bvh2_node` 3.31 s vs 3.16 s. Traversal time goes
//! to loading nodes, not to the box tests. What pays is walking the tree
//! less often: a pixel's camera rays and their shadow rays towards a
//! distant light are traced as bundles against the leaves one traversal
//! gathers ([`gather`](TriangleBvh::gather), `bundle.rs`): 10.56 s → 6.65 s
//! at 64 spp (1 thread), with bit-identical images.

use crate::bundle::{Bundle, Frustum, Leaf};
use glam::{Vec2, Vec3A};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, builder::build_bvh2_from_tris},
    ray::{Ray, RayHit},
    rt_triangle::RtTriangle,
    triangle::Triangle,
};
use std::time::Duration;

/// Per-triangle shading data, in BVH order.
#[derive(Clone, Copy, Debug)]
pub struct TriangleShading {
    /// Vertex normals at `v0`, `v1`, `v2`.
    pub normals: [Vec3A; 3],
    /// Texture coordinates at `v0`, `v1`, `v2`.
    pub uvs: [Vec2; 3],
    /// Index of the object the triangle belongs to.
    pub object: u32,
}

/// Input triangle: vertices, vertex normals and object index.
#[derive(Clone, Copy, Debug)]
pub struct InputTriangle {
    pub vertices: [Vec3A; 3],
    pub normals: [Vec3A; 3],
    pub uvs: [Vec2; 3],
    pub object: u32,
}

pub struct TriangleBvh {
    bvh: Bvh2,
    /// Input triangles (leaves may repeat some after spatial splits).
    count: usize,
    tris: Vec<RtTriangle>,
    shading: Vec<TriangleShading>,
}

/// Surface data at a triangle hit.
#[derive(Clone, Copy, Debug)]
pub struct TriangleSurface {
    /// Unit geometric normal (winding order `v0, v1, v2`, counter-clockwise).
    pub geometric: Vec3A,
    /// Unit interpolated shading normal.
    pub shading: Vec3A,
    pub uv: Vec2,
    pub object: u32,
}

impl TriangleBvh {
    /// `None` for an empty list.
    pub fn build(input: &[InputTriangle]) -> Option<TriangleBvh> {
        if input.is_empty() {
            return None;
        }
        let tris: Vec<Triangle> = input
            .iter()
            .map(|t| Triangle {
                v0: t.vertices[0],
                v1: t.vertices[1],
                v2: t.vertices[2],
            })
            .collect();
        let bvh = build_bvh2_from_tris(
            &tris,
            BvhBuildParams::slow_build(),
            &mut Duration::default(),
        );
        let order = &bvh.primitive_indices;
        Some(TriangleBvh {
            tris: order
                .iter()
                .map(|&i| RtTriangle::from(&tris[i as usize]))
                .collect(),
            shading: order
                .iter()
                .map(|&i| {
                    let t = &input[i as usize];
                    TriangleShading {
                        normals: t.normals,
                        uvs: t.uvs,
                        object: t.object,
                    }
                })
                .collect(),
            bvh,
            count: input.len(),
        })
    }

    /// Number of input triangles.
    pub fn len(&self) -> usize {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The box around every triangle (the root node's).
    pub fn bounds(&self) -> &Aabb {
        self.bvh.nodes[0].aabb()
    }

    /// Closest hit in `(tmin, tmax)`: distance and triangle id.
    #[inline]
    pub fn intersect(&self, origin: Vec3A, dir: Vec3A, tmin: f32, tmax: f32) -> Option<(f32, u32)> {
        let mut hit = RayHit::none();
        let ray = Ray::new(origin, dir, tmin, tmax);
        self.bvh
            .ray_traverse(ray, &mut hit, |r, id| self.tris[id].intersect(r))
            .then_some((hit.t, hit.primitive_id))
    }

    /// Collects into `bundle.leaves` every leaf whose box may overlap
    /// `frustum`, sorted by the frustum's lower bound on reaching it.
    pub fn gather(&self, frustum: &Frustum, bundle: &mut Bundle) {
        bundle.leaves.clear();
        bundle.stack.clear();
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return;
        }
        bundle.stack.push(0);
        while let Some(i) = bundle.stack.pop() {
            let node = &nodes[i as usize];
            if !frustum.may_overlap(node.aabb()) {
                continue;
            }
            if node.is_leaf() {
                bundle.leaves.push(Leaf {
                    aabb: *node.aabb(),
                    first: node.first_index,
                    count: node.prim_count,
                    near: frustum.near(node.aabb()),
                });
            } else {
                bundle.stack.push(node.first_index + 1);
                bundle.stack.push(node.first_index);
            }
        }
        bundle
            .leaves
            .sort_unstable_by(|a, b| a.near.total_cmp(&b.near));
    }

    /// [`Self::intersect`] for a ray of the bundle `gather` collected: the
    /// same box and triangle tests on the gathered leaves only, stopping at
    /// the first leaf no nearer than the closest hit so far.
    #[inline]
    pub fn intersect_gathered(
        &self,
        bundle: &Bundle,
        origin: Vec3A,
        dir: Vec3A,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, u32)> {
        let mut ray = Ray::new(origin, dir, tmin, tmax);
        let mut best = None;
        for leaf in &bundle.leaves {
            if leaf.near >= ray.tmax {
                break;
            }
            if leaf.aabb.intersect_ray(&ray) >= ray.tmax {
                continue;
            }
            for id in leaf.first..leaf.first + leaf.count {
                let t = self.tris[id as usize].intersect(&ray);
                if t < ray.tmax {
                    ray.tmax = t;
                    best = Some((t, id));
                }
            }
        }
        best
    }

    /// [`Self::occluded`] for a ray of a gathered bundle.
    #[inline]
    pub fn occluded_gathered(
        &self,
        bundle: &Bundle,
        origin: Vec3A,
        dir: Vec3A,
        tmin: f32,
        tmax: f32,
    ) -> bool {
        let ray = Ray::new(origin, dir, tmin, tmax);
        bundle
            .leaves
            .iter()
            .take_while(|leaf| leaf.near < tmax)
            .any(|leaf| {
                leaf.aabb.intersect_ray(&ray) < tmax
                    && (leaf.first..leaf.first + leaf.count)
                        .any(|id| self.tris[id as usize].intersect(&ray) < tmax)
            })
    }

    /// Whether anything blocks the segment `(tmin, tmax)`.
    #[inline]
    pub fn occluded(&self, origin: Vec3A, dir: Vec3A, tmin: f32, tmax: f32) -> bool {
        let ray = Ray::new(origin, dir, tmin, tmax);
        !self
            .bvh
            .ray_traverse_miss(ray, |r, id| self.tris[id].intersect(r))
    }

    /// Normals and texture coordinates at point `p` on triangle `id`
    /// (barycentric interpolation).
    #[inline]
    pub fn surface(&self, id: u32, p: Vec3A) -> TriangleSurface {
        let tri = &self.tris[id as usize];
        let sh = &self.shading[id as usize];
        // RtTriangle stores e1 = v0 − v1, e2 = v2 − v0, ng = e1 × e2.
        let (v0, v1, v2) = (tri.v0, tri.v0 - tri.e1, tri.v0 + tri.e2);
        let n = (v1 - v0).cross(v2 - v0);
        let area2 = n.length_squared();
        let b1 = (p - v0).cross(v2 - v0).dot(n) / area2;
        let b2 = (v1 - v0).cross(p - v0).dot(n) / area2;
        let b0 = 1.0 - b1 - b2;
        let geometric = n.normalize();
        let shading = (sh.normals[0] * b0 + sh.normals[1] * b1 + sh.normals[2] * b2)
            .try_normalize()
            .unwrap_or(geometric);
        TriangleSurface {
            geometric,
            shading,
            uv: sh.uvs[0] * b0 + sh.uvs[1] * b1 + sh.uvs[2] * b2,
            object: sh.object,
        }
    }

    /// `∂p/∂u` of triangle `id` from its edges and texture coordinates (the
    /// tangent of normal textures); zero when its `uv`s are degenerate.
    pub fn tangent(&self, id: u32) -> Vec3A {
        let tri = &self.tris[id as usize];
        let uv = self.shading[id as usize].uvs;
        // [v1 − v0, v2 − v0] = [∂p/∂u, ∂p/∂v] · [Δuv1, Δuv2], solved for ∂p/∂u.
        let (e1, e2) = (-tri.e1, tri.e2);
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-12 {
            return Vec3A::ZERO;
        }
        (e1 * d2.y - e2 * d1.y) / det
    }
}
