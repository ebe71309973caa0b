//! `sfp eval` of another tool's normals: files in the formats and frames
//! learned methods write, scored with the protocol printed.

use crate::common::*;
use sfp_core::export::write_npy_f32;
use sfp_core::view::View;

#[test]
fn files_in_every_format_and_frame_are_scored() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    sfp_ok(&["analytic", "--shape", "sphere", "--size", "32", "--out", v]);
    let gt = View::read(&view).unwrap().gt.unwrap().normals;
    let (w, h) = gt.size();
    // The ground truth in OpenCV's frame (y down, z into the scene).
    let opencv: Vec<f32> = gt
        .data()
        .iter()
        .flat_map(|n| [n[0], -n[1], -n[2]])
        .collect();
    let npy = dir.path().join("mine/pred.npy");
    std::fs::create_dir_all(npy.parent().unwrap()).unwrap();
    write_npy_f32(&npy, &[h as u64, w as u64, 3], opencv).unwrap();
    let score = |args: &[&str]| {
        let o = sfp(args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        let m = read_json(&npy.with_file_name("metrics.json"));
        (String::from_utf8_lossy(&o.stdout).into_owned(), m)
    };
    let p = npy.to_str().unwrap();
    let (text, m) = score(&["eval", v, p, "--axes", "opencv"]);
    assert!(m["mae_deg"].as_f64().unwrap() < 1e-3, "{m}");
    assert!(
        text.contains("protocol") && text.contains("uncapped"),
        "{text}"
    );
    assert!(
        text.contains("| MAE |") && text.contains("OpenCV"),
        "{text}"
    );
    assert!(npy.with_file_name("error.png").is_file());
    // Read in the wrong frame, the same file is far off.
    let (_, m) = score(&["eval", v, p]);
    assert!(m["mae_deg"].as_f64().unwrap() > 60.0, "{m}");

    // An 8-bit PNG in the image frame (y down, z towards the camera), in a
    // folder of its own with nothing else.
    let png = dir.path().join("png/normals.png");
    std::fs::create_dir_all(png.parent().unwrap()).unwrap();
    let img = gt.map(|n| [n[0], -n[1], n[2]].map(|c| ((c + 1.0) / 2.0 * 255.0).round() as u8));
    sfp_core::io::write_png_rgb(&png, &img).unwrap();
    let folder = png.parent().unwrap().to_str().unwrap();
    let o = sfp_ok(&["eval", v, folder, "--axes", "image", "--json"]);
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let mae = m["mae_deg"].as_f64().unwrap();
    assert!(mae < 0.5 && m["missing"] == 0, "{m}");

    // Wrong shapes and unknown frames are refused by name.
    let flat = dir.path().join("flat.npy");
    write_npy_f32(&flat, &[(w * h) as u64, 3], vec![0.0; w * h * 3]).unwrap();
    assert_clean_failure(&sfp(&["eval", v, flat.to_str().unwrap()]), "flat.npy");
    assert_clean_failure(&sfp(&["eval", v, p, "--axes", "dx"]), "opencv");
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    assert_clean_failure(&sfp(&["eval", v, empty.to_str().unwrap()]), "normals.npy");
}
