//! Procedural solid textures: scalar fields over object space with values in
//! `[0, 1]`, seeded, so presets need no texture files and a pattern sticks to
//! the object whatever its orientation. Being 3-D, they need no texture
//! coordinates, and their gradient gives bump-mapped normals (`normal_map`).
//!
//! Every pattern is a pure function of `(seed, point)`: lattice values come
//! from a hash of the integer cell and the seed, never from a random stream.

use glam::Vec3A;
use serde::{Deserialize, Serialize};

/// The shapes of pattern (scene key `pattern`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PatternKind {
    /// Fractal Perlin gradient noise (four octaves): blotchy variation.
    Noise,
    /// Worley cells: distance to the nearest of random feature points.
    Cells,
    /// `½ + ½ sin(2π x)` along object-space `x`: a closed form for tests.
    Stripes,
    /// Thin random curves (the zero set of stretched noise): scratches.
    Scratches,
    /// Smooth-edged blobs of low-frequency noise: stains.
    Stains,
}

/// A pattern with its seed and `frequency` (features per unit length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pattern {
    pub kind: PatternKind,
    pub seed: u64,
    pub frequency: f32,
}

/// SplitMix64 finaliser of a lattice cell and the seed.
#[inline]
fn hash(seed: u64, x: i32, y: i32, z: i32) -> u64 {
    let mut h = seed ^ 0x9e37_79b9_7f4a_7c15;
    for c in [x, y, z] {
        h = (h ^ (c as u32 as u64)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h ^= h >> 31;
    }
    h = (h ^ (h >> 30)).wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^ (h >> 31)
}

/// A value in `[0, 1)` from 24 bits of `h` starting at bit `shift`.
#[inline]
fn unit(h: u64, shift: u32) -> f32 {
    ((h >> shift) & 0xff_ffff) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Quintic fade of improved Perlin noise (C² continuous, so bump normals are
/// smooth).
#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Perlin gradient noise in about `[−1, 1]`, zero at lattice points.
fn perlin(seed: u64, p: Vec3A) -> f32 {
    let cell = p.floor();
    let f = p - cell;
    let [ix, iy, iz] = [cell.x as i32, cell.y as i32, cell.z as i32];
    let grad = |dx: i32, dy: i32, dz: i32| {
        // One of the 12 cube-edge directions (Perlin 2002).
        let h = hash(seed, ix + dx, iy + dy, iz + dz) % 12;
        let (x, y, z) = (f.x - dx as f32, f.y - dy as f32, f.z - dz as f32);
        let (a, b) = match h / 4 {
            0 => (x, y),
            1 => (x, z),
            _ => (y, z),
        };
        let sa = if h & 1 == 0 { a } else { -a };
        let sb = if h & 2 == 0 { b } else { -b };
        sa + sb
    };
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(grad(0, 0, 0), grad(1, 0, 0), u);
    let x10 = lerp(grad(0, 1, 0), grad(1, 1, 0), u);
    let x01 = lerp(grad(0, 0, 1), grad(1, 0, 1), u);
    let x11 = lerp(grad(0, 1, 1), grad(1, 1, 1), u);
    lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
}

/// Four octaves of Perlin noise (weights ½, ¼, ⅛, 1/16), each with its own
/// seed: mean 0, standard deviation about 0.13.
fn fbm(seed: u64, p: Vec3A) -> f32 {
    let (mut sum, mut amp, mut freq) = (0.0, 0.5, 1.0);
    for octave in 0..4u64 {
        sum += amp * perlin(seed.wrapping_add(octave), p * freq);
        amp *= 0.5;
        freq *= 2.0;
    }
    sum
}

/// Distance to the nearest feature point (one per unit cell).
fn cells(seed: u64, p: Vec3A) -> f32 {
    let cell = p.floor();
    let mut best = f32::INFINITY;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let c = cell + Vec3A::new(dx as f32, dy as f32, dz as f32);
                let h = hash(seed, c.x as i32, c.y as i32, c.z as i32);
                let q = c + Vec3A::new(unit(h, 0), unit(h, 20), unit(h, 40));
                best = best.min(q.distance_squared(p));
            }
        }
    }
    best.sqrt()
}

#[inline]
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Pattern {
    /// The pattern's value in `[0, 1]` at object-space point `p`.
    pub fn value(&self, p: Vec3A) -> f32 {
        let q = p * self.frequency;
        let v = match self.kind {
            // Spread to a standard deviation of about ¼ (tails clamped).
            PatternKind::Noise => 0.5 + 2.0 * fbm(self.seed, q),
            // Nearest-point distances rarely exceed 0.8.
            PatternKind::Cells => 1.25 * cells(self.seed, q),
            PatternKind::Stripes => 0.5 + 0.5 * (std::f32::consts::TAU * q.x).sin(),
            PatternKind::Scratches => {
                // Noise squeezed 8× across a seeded direction: its zero set is
                // a family of long thin curves, kept where |n| < width.
                let h = hash(self.seed, 0x5c, 0x7a, 0x11);
                let (phi, z) = (std::f32::consts::TAU * unit(h, 0), 2.0 * unit(h, 24) - 1.0);
                let r = (1.0 - z * z).sqrt();
                let d = Vec3A::new(r * phi.cos(), r * phi.sin(), z);
                let stretched = q + d * (7.0 * q.dot(d));
                1.0 - smoothstep(0.0, 0.06, perlin(self.seed, stretched).abs())
            }
            PatternKind::Stains => smoothstep(0.05, 0.2, fbm(self.seed, q * 0.5)),
        };
        v.clamp(0.0, 1.0)
    }

    /// Gradient of [`Pattern::value`] by central differences (step small
    /// against a feature: 1/1000 of the pattern's period).
    pub fn gradient(&self, p: Vec3A) -> Vec3A {
        let h = 1e-3 / self.frequency;
        let d = |e: Vec3A| (self.value(p + e * h) - self.value(p - e * h)) / (2.0 * h);
        Vec3A::new(d(Vec3A::X), d(Vec3A::Y), d(Vec3A::Z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points() -> impl Iterator<Item = Vec3A> {
        (0..500).map(|i| {
            let t = i as f32;
            Vec3A::new(
                (t * 0.7371).sin() * 3.0,
                (t * 1.313).cos() * 2.0,
                t * 0.0123 - 3.0,
            )
        })
    }

    #[test]
    fn values_are_in_unit_range_seeded_and_varied() {
        for kind in [
            PatternKind::Noise,
            PatternKind::Cells,
            PatternKind::Stripes,
            PatternKind::Scratches,
            PatternKind::Stains,
        ] {
            let a = Pattern {
                kind,
                seed: 1,
                frequency: 2.0,
            };
            let b = Pattern { seed: 2, ..a };
            let va: Vec<f32> = points().map(|p| a.value(p)).collect();
            assert!(va.iter().all(|v| (0.0..=1.0).contains(v)), "{kind:?}");
            let (lo, hi) = va
                .iter()
                .fold((1.0f32, 0.0f32), |(l, h), &v| (l.min(v), h.max(v)));
            assert!(hi - lo > 0.3, "{kind:?}: range {lo}..{hi}");
            assert_eq!(va, points().map(|p| a.value(p)).collect::<Vec<_>>());
            let same_for_other_seed = points().all(|p| a.value(p) == b.value(p));
            assert_eq!(
                same_for_other_seed,
                kind == PatternKind::Stripes,
                "{kind:?}"
            );
        }
    }

    #[test]
    fn perlin_vanishes_on_the_lattice_and_is_continuous() {
        for p in [Vec3A::ZERO, Vec3A::new(3.0, -2.0, 5.0)] {
            assert_eq!(perlin(9, p), 0.0);
        }
        for p in points() {
            let e = Vec3A::splat(1e-4);
            assert!((perlin(9, p + e) - perlin(9, p)).abs() < 1e-3);
        }
    }

    #[test]
    fn stripes_gradient_matches_closed_form() {
        let s = Pattern {
            kind: PatternKind::Stripes,
            seed: 0,
            frequency: 3.0,
        };
        for p in points() {
            let g = s.gradient(p);
            let tau = std::f32::consts::TAU;
            let expect = 0.5 * tau * 3.0 * (tau * 3.0 * p.x).cos();
            assert!(
                (g.x - expect).abs() < 2e-3 * tau * 3.0,
                "{} vs {expect}",
                g.x
            );
            assert!(g.y.abs() < 1e-3 && g.z.abs() < 1e-3);
        }
    }

    #[test]
    fn cells_are_zero_at_feature_points() {
        let c = Pattern {
            kind: PatternKind::Cells,
            seed: 4,
            frequency: 1.0,
        };
        let h = hash(4, 2, -1, 0);
        let q = Vec3A::new(2.0 + unit(h, 0), -1.0 + unit(h, 20), unit(h, 40));
        assert!(c.value(q) < 1e-6);
    }
}
