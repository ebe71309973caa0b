//! A contact sheet of datasets' previews: one column per view, rows
//! intensity, DoP, AoP and ground-truth normals; with several datasets, their
//! views interleaved. Made `scenes/builtin_sheet.png` and `scenes/b_svbrdf_sheet.png`:
//!
//! `cargo run --release -p sfp-cli --example dataset_sheet -- DATASET_DIR... OUT.png`

use sfp_benchmarks::sheet::contact_sheet;
use sfp_core::{Image, io};
use sfp_renderer::dataset_index::DatasetIndex;
use std::path::{Path, PathBuf};

const ROWS: [&str; 4] = ["intensity.png", "dop.png", "aop.png", "normals.png"];

fn read_rgb(path: &Path) -> Result<Image<[u8; 3]>, Box<dyn std::error::Error>> {
    let img = image::open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .to_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let pixels = img.pixels().map(|p| p.0).collect();
    Ok(Image::from_vec(w, h, pixels)?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [dirs @ .., out] = args.as_slice() else {
        return Err("usage: dataset_sheet DATASET_DIR... OUT.png".into());
    };
    if dirs.is_empty() {
        return Err("usage: dataset_sheet DATASET_DIR... OUT.png".into());
    }
    // Several datasets (e.g. one preset with and without `--svbrdf`): view
    // `k` of each side by side.
    let mut lists = Vec::new();
    for dir in dirs {
        let folders: Vec<PathBuf> = DatasetIndex::read(dir)?
            .views
            .iter()
            .map(|v| dir.join(&v.folder))
            .collect();
        lists.push(folders);
    }
    let count = lists.iter().map(Vec::len).max().unwrap_or(0);
    let views: Vec<&PathBuf> = (0..count)
        .flat_map(|k| lists.iter().filter_map(move |l| l.get(k)))
        .collect();
    let mut rows = Vec::new();
    for file in ROWS {
        let row = views
            .iter()
            .map(|v| read_rgb(&v.join("preview").join(file)))
            .collect::<Result<Vec<_>, _>>()?;
        rows.push(row);
    }
    io::write_png_rgb(out, &contact_sheet(&rows))?;
    println!("wrote {} ({} views)", out.display(), views.len());
    Ok(())
}
