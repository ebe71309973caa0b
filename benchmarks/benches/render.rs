//! Renderer speed: a 512×512 orthographic sphere and a
//! ~100k-triangle tessellated sphere, one directional light, 64 spp,
//! `max_depth = 4`, specular off, with 1 and 2 rayon threads. Throughput is
//! reported in rays per second (camera, bounce and shadow rays).
//!
//! `cargo bench -p sfp-benchmarks --bench render`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sfp_renderer::render::{RenderOptions, render};
use sfp_renderer::scene::Scene;
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;
use std::time::Duration;

fn scene_text(object: &str) -> String {
    format!(
        r#"
[camera]
type = "orthographic"
width = 512
height = 512
extent = 2.2
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]

[render]
spp = 64
max_depth = 4
seed = 1

[[light]]
type = "directional"
direction = [0.4, 0.3, 1.0]
irradiance = 3.0

[[object]]
{object}
material = {{ type = "diffuse_polarized", albedo = 0.8, eta = 1.5, specular = 0.0 }}

[sensor]
noise = true
"#
    )
}

/// A UV sphere of radius 1 with `2·rings·segments − 2·segments` triangles
/// and exact vertex normals.
fn write_uv_sphere(path: &Path, rings: usize, segments: usize) {
    let mut s = String::new();
    for i in 0..=rings {
        let th = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let ph = 2.0 * PI * j as f64 / segments as f64;
            let (x, y, z) = (th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            writeln!(s, "v {x} {y} {z}\nvn {x} {y} {z}").unwrap();
        }
    }
    let idx = |i: usize, j: usize| i * segments + (j % segments) + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            if i != 0 {
                writeln!(s, "f {a}//{a} {b}//{b} {d}//{d}").unwrap();
            }
            if i != rings - 1 {
                writeln!(s, "f {b}//{b} {c}//{c} {d}//{d}").unwrap();
            }
        }
    }
    std::fs::write(path, s).unwrap();
}

fn bench(c: &mut Criterion, name: &str, scene: &Scene) {
    let probe = render(scene, &RenderOptions::default()).unwrap();
    println!(
        "{name}: {} triangles, {} samples, {} rays",
        probe.stats.triangles, probe.stats.samples, probe.stats.rays
    );
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.throughput(Throughput::Elements(probe.stats.rays));
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        group.bench_function(format!("{threads}_threads"), |b| {
            b.iter(|| pool.install(|| render(scene, &RenderOptions::default()).unwrap()))
        });
    }
    group.finish();
}

fn renderer(c: &mut Criterion) {
    let sphere = Scene::from_toml(
        &scene_text("shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0"),
        Path::new("sphere.toml"),
    )
    .unwrap();
    bench(c, "render_sphere_512_64spp", &sphere);

    let dir = tempfile::tempdir().unwrap();
    write_uv_sphere(&dir.path().join("sphere.obj"), 224, 224);
    let mesh = Scene::from_toml(
        &scene_text("mesh = \"sphere.obj\""),
        &dir.path().join("mesh.toml"),
    )
    .unwrap();
    bench(c, "render_mesh100k_512_64spp", &mesh);
}

criterion_group!(benches, renderer);
criterion_main!(benches);
