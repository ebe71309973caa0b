//! Built-in objects: procedural triangle meshes that need no files, for the
//! demo, the tests and any fresh clone. Each is tessellated from an
//! analytic surface with analytic (smooth) normals and sized to the unit
//! bounding sphere around its bounding-box centre.
//!
//! `y` is each object's up axis (a cup stands on `y = min`, opening up);
//! the camera of the presets looks along `−z`.

use crate::mesh::Mesh;
use glam::Vec3;
use sfp_core::{Error, Result};
use std::f32::consts::{PI, TAU};

/// Names accepted by [`builtin_mesh`].
pub const BUILTIN_NAMES: [&str; 7] = [
    "sphere",
    "ellipsoid",
    "torus",
    "rounded_box",
    "cup",
    "bumps",
    "snowman",
];

/// The built-in object `name`; `detail` scales the tessellation (1 ≈ 20–60k
/// triangles per object).
pub fn builtin_mesh(name: &str, detail: f32) -> Result<Mesh> {
    let n = |k: f32| ((k * detail).round() as usize).max(4);
    let mut mesh = Mesh::default();
    match name {
        "sphere" => add_grid(&mut mesh, n(160.0), n(80.0), |u, v| {
            ellipsoid(u, v, Vec3::ONE)
        }),
        "ellipsoid" => add_grid(&mut mesh, n(160.0), n(80.0), |u, v| {
            ellipsoid(u, v, Vec3::new(1.0, 0.62, 0.45))
        }),
        "torus" => add_grid(&mut mesh, n(200.0), n(80.0), |u, v| {
            torus(u, v, Vec3::ZERO, 0.65, 0.3, (0.0, TAU))
        }),
        "rounded_box" => add_grid(&mut mesh, n(160.0), n(80.0), |u, v| {
            superellipsoid(u, v, 0.25)
        }),
        "cup" => {
            add_grid(&mut mesh, n(160.0), n(120.0), cup_body);
            let (r, h) = (CUP_RADIUS, CUP_HEIGHT);
            add_grid(&mut mesh, n(40.0), n(100.0), |u, v| {
                let angle = (-105f32).to_radians()..=105f32.to_radians();
                let (p, nn) = torus(
                    v,
                    u,
                    Vec3::ZERO,
                    0.32,
                    0.055,
                    (*angle.start(), *angle.end()),
                );
                // Torus in the x–y plane around (r + 0.02, h/2): swap to stand upright.
                let place = |q: Vec3| Vec3::new(q.x, q.z, q.y);
                (place(p) + Vec3::new(r + 0.02, 0.5 * h, 0.0), place(nn))
            });
        }
        "bumps" => add_grid(&mut mesh, n(200.0), n(200.0), bumps),
        "snowman" => {
            for (c, r) in [(-0.55f32, 0.5f32), (0.2, 0.36), (0.72, 0.24)] {
                add_grid(&mut mesh, n(120.0), n(60.0), |u, v| {
                    let (p, nn) = ellipsoid(u, v, Vec3::ONE);
                    (p * r + Vec3::new(0.0, c, 0.0), nn)
                });
            }
            for side in [-1.0f32, 1.0] {
                let a = Vec3::new(0.3 * side, 0.25, 0.05);
                let b = Vec3::new(0.75 * side, 0.5, 0.2);
                add_grid(&mut mesh, n(60.0), n(60.0), |u, v| {
                    capsule(u, v, a, b, 0.07)
                });
            }
        }
        other => {
            return Err(Error::invalid(format!(
                "unknown built-in object {other:?} (known: {})",
                BUILTIN_NAMES.join(", ")
            )));
        }
    }
    normalize_to_unit_sphere(&mut mesh);
    Ok(mesh)
}

/// Tessellates `surface(u, v)` → (position, unit normal) over `[0,1]²` with
/// `nu × nv` quads; zero-area triangles (poles) are skipped and each
/// triangle's winding follows the analytic normal.
fn add_grid(mesh: &mut Mesh, nu: usize, nv: usize, surface: impl Fn(f32, f32) -> (Vec3, Vec3)) {
    let base = mesh.positions.len() as u32;
    for j in 0..=nv {
        for i in 0..=nu {
            let (p, n) = surface(i as f32 / nu as f32, j as f32 / nv as f32);
            mesh.positions.push(p);
            mesh.normals.push(n.normalize_or_zero());
        }
    }
    let id = |i: usize, j: usize| base + (j * (nu + 1) + i) as u32;
    for j in 0..nv {
        for i in 0..nu {
            for t in [
                [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
            ] {
                let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
                let face = (b - a).cross(c - a);
                if face.length_squared() <= 1e-14 {
                    continue;
                }
                let avg: Vec3 = t.iter().map(|&k| mesh.normals[k as usize]).sum();
                mesh.triangles.push(if face.dot(avg) >= 0.0 {
                    t
                } else {
                    [t[0], t[2], t[1]]
                });
            }
        }
    }
}

fn normalize_to_unit_sphere(mesh: &mut Mesh) {
    let (lo, hi) = mesh.positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let c = 0.5 * (lo + hi);
    let r = mesh
        .positions
        .iter()
        .map(|p| (*p - c).length())
        .fold(0.0f32, f32::max);
    for p in &mut mesh.positions {
        *p = (*p - c) / r;
    }
}

/// Axis-aligned ellipsoid with semi-axes `radii` (u: longitude, v: pole to pole).
fn ellipsoid(u: f32, v: f32, radii: Vec3) -> (Vec3, Vec3) {
    let (su, cu) = (TAU * u).sin_cos();
    let (sv, cv) = (PI * v).sin_cos();
    let unit = Vec3::new(sv * cu, cv, sv * su);
    (unit * radii, unit / radii)
}

/// Torus around the `y` axis through `center`, major radius `big`, tube
/// radius `small`; `u` sweeps the major angle over `range`.
fn torus(u: f32, v: f32, center: Vec3, big: f32, small: f32, range: (f32, f32)) -> (Vec3, Vec3) {
    let a = range.0 + (range.1 - range.0) * u;
    let (sa, ca) = a.sin_cos();
    let (sb, cb) = (TAU * v).sin_cos();
    let n = Vec3::new(cb * ca, sb, cb * sa);
    (center + Vec3::new(big * ca, 0.0, big * sa) + small * n, n)
}

/// Superellipsoid `|x|^p + |y|^p + |z|^p = 1` with `p = 2/e` (a rounded box for small `e`).
fn superellipsoid(u: f32, v: f32, e: f32) -> (Vec3, Vec3) {
    let spow = |x: f32, k: f32| x.signum() * x.abs().powf(k);
    let (su, cu) = (TAU * u).sin_cos();
    let (sv, cv) = (PI * v).sin_cos();
    let p = Vec3::new(
        spow(sv, e) * spow(cu, e),
        spow(cv, e),
        spow(sv, e) * spow(su, e),
    );
    let q = 2.0 / e - 1.0;
    let n = Vec3::new(spow(p.x, q), spow(p.y, q), spow(p.z, q));
    (p, n)
}

const CUP_RADIUS: f32 = 0.6;
const CUP_HEIGHT: f32 = 1.4;

/// A point of a 2D profile `(r, y)` and its outward normal.
type ProfilePoint = ((f32, f32), (f32, f32));

/// Solid of revolution of the cup's closed profile: bottom, bottom fillet,
/// outer wall, rounded rim, inner wall, inner fillet, inner bottom.
fn cup_body(u: f32, v: f32) -> (Vec3, Vec3) {
    let (r0, h, t, b, f, fi) = (CUP_RADIUS, CUP_HEIGHT, 0.06, 0.08, 0.1, 0.08);
    let arc = |c: (f32, f32), rad: f32, a: f32, outward: f32| {
        let (s, co) = a.sin_cos();
        ((c.0 + rad * co, c.1 + rad * s), (outward * co, outward * s))
    };
    // Profile pieces with their lengths, walked in order; v picks a point by arc length.
    let pieces: [(f32, &dyn Fn(f32) -> ProfilePoint); 7] = [
        (r0 - f, &|s| ((s * (r0 - f), 0.0), (0.0, -1.0))),
        (0.5 * PI * f, &|s| {
            arc((r0 - f, f), f, -0.5 * PI + 0.5 * PI * s, 1.0)
        }),
        (h - f, &|s| ((r0, f + s * (h - f)), (1.0, 0.0))),
        (0.5 * PI * t, &|s| {
            arc((r0 - 0.5 * t, h), 0.5 * t, PI * s, 1.0)
        }),
        (h - b - fi, &|s| {
            ((r0 - t, h - s * (h - b - fi)), (-1.0, 0.0))
        }),
        (0.5 * PI * fi, &|s| {
            arc((r0 - t - fi, b + fi), fi, -0.5 * PI * s, -1.0)
        }),
        (r0 - t - fi, &|s| {
            (((1.0 - s) * (r0 - t - fi), b), (0.0, 1.0))
        }),
    ];
    let total: f32 = pieces.iter().map(|p| p.0).sum();
    let mut along = v * total;
    let mut point = pieces[6].1(1.0);
    for (len, piece) in pieces.iter() {
        if along <= *len {
            point = piece(along / len);
            break;
        }
        along -= len;
    }
    let ((r, y), (nr, ny)) = point;
    let (su, cu) = (TAU * u).sin_cos();
    (
        Vec3::new(r * cu, y, r * su),
        Vec3::new(nr * cu, ny, nr * su),
    )
}

/// Height-field patch over `[−1, 1]²` (facing `+z`): Gaussian bumps whose
/// lobes meet in concave creases, plus one dimple.
fn bumps(u: f32, v: f32) -> (Vec3, Vec3) {
    const TERMS: [(f32, f32, f32, f32); 6] = [
        (0.0, 0.0, 0.28, 0.45),
        (0.55, 0.35, 0.22, 0.35),
        (-0.5, 0.45, 0.25, 0.38),
        (-0.4, -0.5, 0.2, 0.3),
        (0.5, -0.45, 0.22, 0.33),
        (0.0, 0.7, 0.12, -0.12),
    ];
    let (x, y) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    let (mut z, mut zx, mut zy) = (0.0, 0.0, 0.0);
    for (cx, cy, s, a) in TERMS {
        let (dx, dy) = (x - cx, y - cy);
        let g = a * (-(dx * dx + dy * dy) / (2.0 * s * s)).exp();
        z += g;
        zx -= g * dx / (s * s);
        zy -= g * dy / (s * s);
    }
    (Vec3::new(x, y, z), Vec3::new(-zx, -zy, 1.0))
}

/// Capsule of radius `r` around the segment `a–b`: hemisphere, cylinder, hemisphere.
fn capsule(u: f32, v: f32, a: Vec3, b: Vec3, r: f32) -> (Vec3, Vec3) {
    let axis = (b - a).normalize();
    let (e1, e2) = axis.any_orthonormal_pair();
    let (su, cu) = (TAU * u).sin_cos();
    let ring = e1 * cu + e2 * su;
    let len = (b - a).length();
    let total = PI * r + len;
    let s = v * total;
    let (center, n) = if s < 0.5 * PI * r {
        let t = s / r; // 0..π/2 from the pole at a
        (a, -axis * t.cos() + ring * t.sin())
    } else if s < 0.5 * PI * r + len {
        (a + axis * (s - 0.5 * PI * r), ring)
    } else {
        let t = (s - 0.5 * PI * r - len) / r; // 0..π/2 towards the pole at b
        (b, ring * t.cos() + axis * t.sin())
    };
    (center + r * n, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_is_a_unit_sized_smooth_mesh() {
        for name in BUILTIN_NAMES {
            let m = builtin_mesh(name, 0.5).unwrap();
            assert!(
                m.triangles.len() > 1000,
                "{name}: {} triangles",
                m.triangles.len()
            );
            let rmax = m
                .positions
                .iter()
                .map(|p| p.length())
                .fold(0.0f32, f32::max);
            assert!(rmax <= 1.0 + 1e-4 && rmax > 0.5, "{name}: radius {rmax}");
            for n in &m.normals {
                assert!((n.length() - 1.0).abs() < 1e-4, "{name}: normal {n}");
            }
            // Windings agree with the analytic normals.
            let agree = m
                .triangles
                .iter()
                .filter(|t| {
                    let [a, b, c] = t.map(|k| m.positions[k as usize]);
                    let avg: Vec3 = t.iter().map(|&k| m.normals[k as usize]).sum();
                    (b - a).cross(c - a).dot(avg) > 0.0
                })
                .count();
            assert_eq!(agree, m.triangles.len(), "{name}");
        }
    }

    #[test]
    fn sphere_vertices_lie_on_the_sphere_with_radial_normals() {
        let m = builtin_mesh("sphere", 0.25).unwrap();
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((p.length() - 1.0).abs() < 1e-5);
            assert!((p.normalize() - *n).length() < 1e-4);
        }
    }

    #[test]
    fn analytic_normals_match_the_tessellated_surface() {
        // Face normals of a fine tessellation agree with the vertex normals.
        for name in ["ellipsoid", "torus", "rounded_box", "cup", "bumps"] {
            let m = builtin_mesh(name, 1.0).unwrap();
            let mut worst_sum = 0.0f32;
            for t in &m.triangles {
                let [a, b, c] = t.map(|k| m.positions[k as usize]);
                let face = (b - a).cross(c - a).normalize();
                let avg: Vec3 = t
                    .iter()
                    .map(|&k| m.normals[k as usize])
                    .sum::<Vec3>()
                    .normalize();
                worst_sum += face.dot(avg).clamp(-1.0, 1.0).acos().to_degrees();
            }
            let mean = worst_sum / m.triangles.len() as f32;
            assert!(mean < 3.0, "{name}: mean face/vertex normal angle {mean}°");
        }
    }

    #[test]
    fn unknown_name_lists_the_known_ones() {
        let e = builtin_mesh("teapot", 1.0).unwrap_err().to_string();
        assert!(e.contains("cup") && e.contains("teapot"), "{e}");
    }
}
