//! Datasets: every view of a tiny built-in dataset is consistent
//! (mask, normals, DoP against the Fresnel formula), generation resumes,
//! orientations are deterministic and correctly distributed, errors name the
//! file, and the mesh presets render when `SFP_MESH_DIR` is set.

use glam::{DVec3, Vec3};
use sfp_core::fresnel::diffuse_dop;
use sfp_core::view::View;
use sfp_renderer::dataset::Dataset;
use sfp_renderer::dataset::{euler_to_quat, quat_to_euler, random_orientation};
use sfp_renderer::mesh::Placement;
use std::path::Path;

/// Checks one view on disk; returns (directly lit pixels, of which DoP is
/// within 0.01 of ρ_d(θ_gt, η)).
fn check_view(dir: &Path) -> (usize, usize) {
    let view = View::read(dir).unwrap();
    let name = dir.display();
    let mask = view.input.mask.as_ref().expect("mask");
    let gt = view.gt.as_ref().expect("gt");
    let meta = view.meta.as_ref().expect("meta");
    let eta = meta.eta.expect("eta");
    let l = DVec3::from(meta.light.expect("light")).normalize();
    assert!(mask.count() > 0, "{name}: empty mask");
    let (mut lit, mut close) = (0, 0);
    for i in 0..mask.len() {
        let n = gt.normals.data()[i];
        let has_normal = n.iter().all(|v| v.is_finite()) && n != [0.0; 3];
        assert_eq!(
            mask.data()[i],
            has_normal,
            "{name}: pixel {i} mask vs normal"
        );
        if !has_normal {
            continue;
        }
        let n = DVec3::from(n.map(f64::from));
        assert!(
            (n.length() - 1.0).abs() < 1e-3,
            "{name}: |n| = {}",
            n.length()
        );
        assert!(n.z > 0.0, "{name}: pixel {i} n_z = {}", n.z);
        let [s0, s1, s2] = gt
            .stokes
            .as_ref()
            .unwrap()
            .each_ref()
            .map(|s| f64::from(s.data()[i]));
        if n.dot(l) > 0.2 && s0 > 0.0 {
            lit += 1;
            let dop = s1.hypot(s2) / s0;
            if (dop - diffuse_dop(n.z.acos(), eta)).abs() < 0.01 {
                close += 1;
            }
        }
    }
    (lit, close)
}

#[test]
fn every_builtin_view_is_consistent() {
    let out = tempfile::tempdir().unwrap();
    let mut d = Dataset::preset("builtin").unwrap();
    d.override_settings(Some(2), Some(64), Some(16), None)
        .unwrap();
    let plan = d.plan().unwrap();
    assert_eq!(plan.len(), 14);
    let done = d.generate(&plan, out.path(), &|_, _| {}).unwrap();
    assert_eq!((done.rendered, done.skipped), (14, 0));
    let (mut lit, mut close) = (0, 0);
    for v in &plan {
        let (l, c) = check_view(&out.path().join(&v.folder));
        println!("{}: {c}/{l} lit pixels with DoP within 0.01", v.folder);
        lit += l;
        close += c;
    }
    let fraction = close as f64 / lit as f64;
    println!("DoP within 0.01 of rho_d(theta_gt, 1.5): {close}/{lit} = {fraction:.3}");
    assert!(fraction > 0.9, "fraction {fraction}");
    let index: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("dataset.json")).unwrap()).unwrap();
    assert_eq!(index["views"].as_array().unwrap().len(), 14);
    assert_eq!(index["settings"]["camera"]["width"], 64);
    assert_eq!(index["views"][2]["folder"], "ellipsoid_0");
}

const TINY: &str = r#"
[dataset]
name = "tiny"
views_per_object = 2

[camera]
type = "orthographic"
width = 16
height = 16
extent = 2.2
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]

[render]
spp = 1
seed = 3

[[light]]
type = "directional"
direction = [0.2, 0.3, 1.0]
irradiance = 3.0

[material]
type = "diffuse_polarized"
albedo = 0.8
eta = 1.5

[[object]]
name = "ball"
builtin = "sphere"

[[object]]
name = "patch"
builtin = "bumps"
max_tilt = 15.0
"#;

#[test]
fn generation_resumes_and_redoes_half_written_views() {
    let out = tempfile::tempdir().unwrap();
    let d = Dataset::from_toml(TINY, Path::new("tiny.toml")).unwrap();
    let plan = d.plan().unwrap();
    let first = d.generate(&plan, out.path(), &|_, _| {}).unwrap();
    assert_eq!((first.rendered, first.skipped), (4, 0));
    let pol = |folder: &str| std::fs::read(out.path().join(folder).join("input/pol_045.png"));
    let before = pol("patch_1").unwrap();

    let second = d.generate(&plan, out.path(), &|_, _| {}).unwrap();
    assert_eq!((second.rendered, second.skipped), (0, 4));

    // An interrupted render: files but no meta.json, and a stray file.
    let half = out.path().join("patch_1");
    std::fs::remove_file(half.join("meta.json")).unwrap();
    std::fs::remove_file(half.join("input/pol_045.png")).unwrap();
    std::fs::write(half.join("stray.txt"), "partial").unwrap();
    let skipped = std::cell::Cell::new(Vec::new());
    let third = d
        .generate(&plan, out.path(), &|v, s| {
            let mut list = skipped.take();
            list.push((v.folder.clone(), s));
            skipped.set(list);
        })
        .unwrap();
    assert_eq!((third.rendered, third.skipped), (1, 3));
    assert!(skipped.take().contains(&("patch_1".to_string(), false)));
    assert!(!half.join("stray.txt").exists());
    assert_eq!(
        pol("patch_1").unwrap(),
        before,
        "re-render is bit-identical"
    );
}

#[test]
fn orientations_are_deterministic_and_stable() {
    let d = Dataset::from_toml(TINY, Path::new("tiny.toml")).unwrap();
    let rotations = |d: &Dataset| -> Vec<[f64; 3]> {
        d.plan()
            .unwrap()
            .iter()
            .map(|v| v.scene.desc.objects[0].rotate)
            .collect()
    };
    let a = rotations(&d);
    assert_eq!(a, rotations(&d));
    assert_ne!(a[0], a[1]);
    // More views per object keep the existing views' orientations.
    let mut more = d.clone();
    more.override_settings(Some(3), None, None, None).unwrap();
    let b = rotations(&more);
    assert_eq!((b[0], b[1], b[3], b[4]), (a[0], a[1], a[2], a[3]));
    // Another seed, other orientations.
    let mut other = d.clone();
    other.override_settings(None, None, None, Some(4)).unwrap();
    assert_ne!(rotations(&other)[0], a[0]);
}

#[test]
fn orientations_follow_the_cap_distribution() {
    // The image of +z is uniform on the cap within max_tilt: its mean z is
    // (1 + cos max_tilt) / 2 and its mean x, y vanish.
    for max_tilt in [15.0f64, 60.0, 180.0] {
        let n = 20000;
        let mut mean = DVec3::ZERO;
        for i in 0..n {
            let z = random_orientation(11, i, max_tilt) * DVec3::Z;
            assert!(
                z.z >= max_tilt.to_radians().cos() - 1e-9,
                "tilt beyond {max_tilt}"
            );
            mean += z / n as f64;
        }
        let expected = (1.0 + max_tilt.to_radians().cos()) / 2.0;
        assert!((mean.z - expected).abs() < 0.01, "{max_tilt}: {mean}");
        assert!(
            mean.x.abs() < 0.01 && mean.y.abs() < 0.01,
            "{max_tilt}: {mean}"
        );
    }
}

#[test]
fn euler_angles_reproduce_the_rotation_in_mesh_placement() {
    for i in 0..100 {
        let q = random_orientation(5, i, 180.0);
        let rotate = quat_to_euler(q);
        let m = Placement {
            rotate_deg: rotate.map(|x| x as f32),
            ..Placement::default()
        }
        .matrix();
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let placed = m.transform_vector3(axis).as_dvec3();
            assert!((placed - q * axis.as_dvec3()).length() < 1e-5, "{rotate:?}");
        }
        assert!(euler_to_quat(rotate).dot(q).abs() > 1.0 - 1e-9);
    }
}

#[test]
fn bad_presets_name_the_file_and_key() {
    let cases = [
        (
            TINY.replace("max_tilt = 15.0", "max_tilt = 15.0\ntilt = 3"),
            "tilt",
        ),
        (TINY.replace("\"bumps\"", "\"teapot\""), "builtin"),
        (TINY.replace("name = \"patch\"", "name = \"ball\""), "name"),
        (TINY.replace("name = \"patch\"", "name = \"a/b\""), "name"),
        (
            TINY.replace("views_per_object = 2", "views_per_object = 0"),
            "views_per_object",
        ),
        (
            TINY.replace("max_tilt = 15.0", "max_tilt = 0.0"),
            "max_tilt",
        ),
        (TINY.replace("eta = 1.5", "eta = 9.0"), "eta"),
        (
            TINY.replace(
                "builtin = \"sphere\"",
                "builtin = \"sphere\"\nmesh = \"x.obj\"",
            ),
            "builtin",
        ),
    ];
    for (text, key) in cases {
        let err = Dataset::from_toml(&text, Path::new("/p/bad.toml"))
            .expect_err(key)
            .to_string();
        assert!(
            err.contains("bad.toml") && err.contains(key),
            "{key}: {err}"
        );
    }
    let err = Dataset::preset("c").unwrap_err().to_string();
    assert!(err.contains("builtin") && err.contains("\"c\""), "{err}");
}

#[test]
fn a_missing_mesh_names_the_file_and_the_variable() {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("p.toml");
    let relative = TINY.replace("builtin = \"sphere\"", "mesh = \"absent.obj\"");
    let err = Dataset::from_toml(&relative, &source)
        .unwrap()
        .plan()
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("absent.obj") && err.contains("p.toml"),
        "{err}"
    );

    let shared = TINY.replace("builtin = \"sphere\"", "mesh = \"@nowhere/absent.obj\"");
    let err = Dataset::from_toml(&shared, &source)
        .unwrap()
        .plan()
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("absent.obj") && err.contains("SFP_MESH_DIR"),
        "{err}"
    );
}

/// With `SFP_MESH_DIR` set the originals there are read, else the shipped
/// meshes (cli/tests/cli/meshes.rs renders the shipped ones explicitly).
#[test]
fn mesh_presets_render_one_tiny_view_of_each_object() {
    for preset in ["a", "b"] {
        let out = tempfile::tempdir().unwrap();
        let mut d = Dataset::preset(preset).unwrap();
        d.desc.dataset.textured = true;
        d.override_settings(Some(1), Some(32), Some(2), None)
            .unwrap();
        let plan = d.plan().unwrap();
        assert_eq!(plan.len(), 4);
        d.generate(&plan, out.path(), &|_, _| {}).unwrap();
        for v in &plan {
            let (lit, _) = check_view(&out.path().join(&v.folder));
            assert!(lit > 0, "{preset}/{}: nothing directly lit", v.folder);
        }
        // Textured objects (the mug's PNG, the duck's embedded GLB texture)
        // vary their albedo; untextured ones keep 0.8.
        let albedo = |folder: &str| {
            let view = View::read(&out.path().join(folder)).unwrap();
            let mask = view.input.mask.unwrap();
            let gt = view.gt.unwrap();
            let inside: Vec<f32> = (0..mask.len())
                .filter(|&i| mask.data()[i])
                .map(|i| gt.albedo.as_ref().unwrap().data()[i])
                .collect();
            let lo = inside.iter().copied().fold(f32::INFINITY, f32::min);
            let hi = inside.iter().copied().fold(0.0f32, f32::max);
            (lo, hi)
        };
        let (textured, plain) = if preset == "a" {
            ("duck_0", "teapot_0")
        } else {
            ("mug_0", "cat_0")
        };
        let (lo, hi) = albedo(textured);
        assert!(hi - lo > 0.05, "{textured} albedo {lo}..{hi}");
        assert_eq!(albedo(plain), (0.8, 0.8));
        // The SVBRDF variant: every object loads its maps and renders.
        let svbrdf = tempfile::tempdir().unwrap();
        d.desc.dataset.svbrdf = true;
        let plan = d.plan().unwrap();
        d.generate(&plan, svbrdf.path(), &|_, _| {}).unwrap();
        for v in &plan {
            let view = View::read(&svbrdf.path().join(&v.folder)).unwrap();
            assert!(view.gt.unwrap().geometric_normals.is_some(), "{}", v.folder);
        }
    }
}

#[test]
fn svbrdf_variant_gives_every_builtin_object_its_maps() {
    let mut d = Dataset::preset("builtin").unwrap();
    d.override_settings(Some(1), Some(48), Some(4), None)
        .unwrap();
    let plain = d.plan().unwrap();
    d.desc.dataset.svbrdf = true;
    let svbrdf = d.plan().unwrap();
    assert_eq!(plain.len(), 7);
    for (a, b) in plain.iter().zip(&svbrdf) {
        let material = |v: &sfp_renderer::dataset::PlannedView| {
            v.scene.desc.objects[0]
                .material
                .records_svbrdf_ground_truth()
        };
        assert!(!material(a) && material(b), "{}", a.folder);
        // Only the material changes: the same orientation, light and noise.
        let mut same = b.scene.desc.clone();
        same.objects[0].material = a.scene.desc.objects[0].material.clone();
        assert!(same == a.scene.desc, "{}", a.folder);
    }
    let out = tempfile::tempdir().unwrap();
    let sphere: Vec<_> = svbrdf
        .into_iter()
        .filter(|v| v.object == "sphere")
        .collect();
    d.generate(&sphere, out.path(), &|_, _| {}).unwrap();
    let view = View::read(&out.path().join("sphere_0")).unwrap();
    let mask = view.input.mask.unwrap();
    let gt = view.gt.unwrap();
    let geometric = gt.geometric_normals.unwrap();
    let (specular, albedo) = (gt.specular.unwrap(), gt.albedo.unwrap());
    let inside: Vec<usize> = (0..mask.len()).filter(|&i| mask.data()[i]).collect();
    let spread = |img: &sfp_core::Image<f32>| {
        let v = inside.iter().map(|&i| img.data()[i]);
        v.clone().fold(f32::MIN, f32::max) - v.fold(f32::MAX, f32::min)
    };
    assert!(spread(&albedo) > 0.2 && spread(&specular) > 0.2);
    // Bumps tilt the shading normal away from the sphere's own normal.
    let tilt: Vec<f32> = inside
        .iter()
        .map(|&i| {
            let (n, g) = (gt.normals.data()[i], geometric.data()[i]);
            (n[0] * g[0] + n[1] * g[1] + n[2] * g[2])
                .clamp(-1.0, 1.0)
                .acos()
        })
        .collect();
    let mean = tilt.iter().sum::<f32>() / tilt.len() as f32;
    println!("mean bump tilt {:.1}°", mean.to_degrees());
    assert!(mean.to_degrees() > 2.0 && mean.to_degrees() < 30.0);
}

/// The glossy preset needs no files: every view gets its own material from
/// the ranges and one of the four lightings, recorded in `dataset.json`;
/// another seed draws others.
#[test]
fn the_glossy_preset_draws_materials_and_lightings_per_view() {
    let out = tempfile::tempdir().unwrap();
    let mut d = Dataset::preset("glossy").unwrap();
    d.override_settings(Some(2), Some(16), Some(2), None)
        .unwrap();
    let plan = d.plan().unwrap();
    assert_eq!(plan.len(), 22);
    let look = |v: &sfp_renderer::dataset::PlannedView| {
        let m = serde_json::to_value(&v.scene.desc.objects[0].material).unwrap();
        (
            m["roughness"].as_f64().unwrap(),
            v.lighting.clone().unwrap(),
        )
    };
    let mut names: Vec<String> = plan.iter().map(|v| look(v).1).collect();
    names.sort();
    names.dedup();
    assert_eq!(names, ["overcast", "room", "room+key", "sky"]);
    for v in &plan {
        let (roughness, _) = look(v);
        assert!((0.05..=0.5).contains(&roughness), "{roughness}");
    }
    d.generate(&plan[..3], out.path(), &|_, _| {}).unwrap();
    let index: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("dataset.json")).unwrap()).unwrap();
    assert_eq!(
        index["views"][0]["lighting"],
        plan[0].lighting.clone().unwrap()
    );
    for v in &plan[..3] {
        let view = View::read(&out.path().join(&v.folder)).unwrap();
        assert!(view.input.mask.unwrap().count() > 20, "{}", v.folder);
        assert!(view.gt.unwrap().specular_stokes.is_some(), "{}", v.folder);
    }
    d.override_settings(None, None, None, Some(2)).unwrap();
    let other = d.plan().unwrap();
    assert_ne!(look(&other[0]).0, look(&plan[0]).0);
}
