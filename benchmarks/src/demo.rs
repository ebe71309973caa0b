//! The main job (`sfp demo`): exact analytic views, the path-traced reference
//! sphere and one view of every built-in object (the `builtin` dataset
//! preset) → every method → metrics, with `summary.md` (a Table-1-style comparison), `sheet.png`
//! (intensity, ground truth and each method's normals and error maps) and
//! `index.html`, the same report a sweep gets (its rows in `results.jsonl`,
//! [`crate::report`]) — the end-to-end path a new user runs first. Needs no
//! files outside the repository.

use crate::report::{self, html, methods, ranking, summary};
use crate::row::{Estimates, Row, Timing};
use crate::sheet::{Cell, figures_caption, labelled_sheet};
use crate::sweep::provenance;
use crate::sweep::results::write_all;
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::collection::{self, Collection};
use sfp_core::legend::picture_part;
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::View;
use sfp_core::{Error, Result, colormap, io, metrics};
use sfp_reconstruct::input::Input;
use sfp_reconstruct::method::Picture;
use sfp_reconstruct::methods::MethodConfig;
use sfp_reconstruct::registry;
use sfp_renderer::dataset::Dataset;
use sfp_renderer::render::{RenderOptions, render};
use sfp_renderer::scene::Scene;
use std::path::Path;

/// The template of `summary.md`.
const DEMO: &str = include_str!("../templates/demo.md");

/// The reference sphere scene, rendered by the path tracer.
const SPHERE_SCENE: &str = include_str!("../../scenes/examples/sphere.toml");

/// How a demo view is made.
enum Source {
    Analytic(AnalyticScene),
    Rendered(Box<Scene>, u64),
}

fn sources(size: usize) -> Result<Vec<(String, Source)>> {
    let analytic = |shape, light| {
        Source::Analytic(AnalyticScene {
            shape,
            size,
            light,
            ..AnalyticScene::default()
        })
    };
    let mut sphere = Scene::from_toml(SPHERE_SCENE, Path::new("scenes/examples/sphere.toml"))?;
    sphere.override_settings(None, None, Some((size, size)))?;
    let mut all = vec![
        (
            "analytic_sphere".to_string(),
            analytic(Shape::Sphere, [0.3, 0.2, 1.0]),
        ),
        (
            "analytic_blobs".to_string(),
            analytic(Shape::Blobs, [-0.2, 0.3, 1.0]),
        ),
        (
            "rendered_sphere".to_string(),
            Source::Rendered(Box::new(sphere), 0),
        ),
    ];
    let mut builtin = Dataset::preset("builtin")?;
    builtin.override_settings(Some(1), Some(size), None, None)?;
    for v in builtin.plan()? {
        all.push((
            format!("builtin_{}", v.object),
            Source::Rendered(Box::new(v.scene), v.view_index),
        ));
    }
    Ok(all)
}

fn make_view(source: &Source) -> Result<View> {
    match source {
        Source::Analytic(scene) => scene.render(),
        Source::Rendered(scene, view_index) => {
            let options = RenderOptions {
                view_index: *view_index,
            };
            Ok(render(scene, &options)?.view)
        }
    }
}

/// Runs the demo into `out`, calling `progress(done, total, what)`.
pub fn run(out: &Path, size: usize, progress: &dyn Fn(usize, usize, &str)) -> Result<()> {
    if !(16..=2048).contains(&size) {
        return Err(Error::invalid(format!(
            "demo size {size} must be within 16..=2048"
        )));
    }
    let _claim = collection::claim(out, Collection::Demo)?;
    let sources = sources(size)?;
    let methods = MethodConfig::defaults();
    let total = sources.len() * (1 + methods.len());
    let mut done = 0;
    let mut rows = Vec::new();
    let (mut report_rows, mut timings) = (Vec::new(), Vec::new());
    for (name, source) in &sources {
        progress(done, total, name);
        let view = make_view(source)?;
        let view_dir = out.join("views").join(name);
        view.write(&view_dir)?;
        done += 1;
        let gt = view.gt.as_ref().expect("demo views have ground truth");
        let gt_mask = view.input.mask.clone().expect("demo views have a mask");
        let input = Input::from_view(&view.input)?;
        let pm = &input.intensity;
        let hi = sfp_core::percentile::percentile(pm.data(), 0.99).max(1e-6);
        let cell = |image, caption: &str| Cell {
            image: Some(image),
            caption: caption.to_string(),
        };
        let mut row = vec![
            cell(
                colormap::scalar_preview(pm, Some(&gt_mask), 0.0, hi, colormap::gray),
                "",
            ),
            cell(gt.normals.map(|&n| colormap::normal_rgb(n)), ""),
        ];
        let mut errors = Vec::new();
        let mut extra = Vec::new();
        for method in &methods {
            progress(done, total, &format!("{name}: {}", method.name()));
            let dir = out.join("results").join(name).join(method.name());
            let outcome = registry::run_with_input(&view, &input, method, &dir)?;
            let m = outcome
                .metrics
                .clone()
                .expect("demo views have ground truth");
            let key = format!("{name}/{}", method.name());
            report_rows.push(Row {
                key: key.clone(),
                dataset: name.split('_').next().unwrap_or(name).to_string(),
                view: name.clone(),
                object: name
                    .split_once('_')
                    .map_or(name.as_str(), |(_, o)| o)
                    .to_string(),
                axes: Default::default(),
                method: method.name().to_string(),
                config: method.to_value(),
                seed: 0,
                metrics: Some(m.clone()),
                estimates: Estimates::of(&outcome.reconstruction.run, view.meta.as_ref()),
                exit_status: None,
                stderr_tail: None,
                error: None,
                view_dir: format!("views/{name}"),
                pictures: Some(format!("results/{name}/{}", method.name())),
            });
            timings.push(Timing {
                key,
                method: method.name().to_string(),
                pixels: outcome.pixels,
                noise_seconds: 0.0,
                reconstruct_seconds: outcome.seconds,
                overhead_seconds: 0.0,
            });
            let rec = &outcome.reconstruction;
            let figures = figures_caption(&m);
            row.push(cell(
                rec.normals.map(|&n| colormap::normal_rgb(n)),
                &figures,
            ));
            // SMSfP's segmentation goes at the end of the row.
            extra.extend(rec.pictures.iter().filter_map(|p| match p {
                Picture::Rgb(name, image) if *name == ResultFolder::SEGMENTS => {
                    Some(cell(picture_part(image, rec.normals.size()), ""))
                }
                _ => None,
            }));
            let err = metrics::error_map(&rec.normals, &gt.normals, &gt_mask)?;
            errors.push(cell(
                colormap::scalar_preview(&err, Some(&gt_mask), 0.0, 90.0, colormap::viridis),
                &figures,
            ));
            done += 1;
        }
        row.extend(errors);
        row.extend(extra);
        rows.push((name.clone(), row));
    }
    progress(done, total, "writing summary");
    let names: Vec<&str> = methods.iter().map(|m| m.name()).collect();
    let columns: Vec<String> = ["intensity".to_string(), "ground truth".to_string()]
        .into_iter()
        .chain(names.iter().map(|n| format!("{n}\nnormals")))
        .chain(names.iter().map(|n| format!("{n}\nerror")))
        .chain(std::iter::once("PARG\nsegments".to_string()))
        .collect();
    io::write_png_rgb(
        &out.join(report::SHEET),
        &labelled_sheet(&columns, &rows, true),
    )?;
    let catalog = methods::catalog(&report_rows);
    let views = ranking::per_view(&report_rows, &catalog);
    let standings = ranking::standings(&views);
    let md = html::document(
        "demo.md",
        DEMO,
        &serde_json::json!({
            "size": size,
            "runs": summary::run_table(&report_rows, &timings),
            "methods": names.join(", "),
            "winner": ranking::verdict(&standings, views.len(), &catalog),
            "standings": ranking::standing_table(&standings, views.len(), &catalog)
                .map(|t| t.markdown()),
        }),
    )?;
    io::write_atomic(&out.join("summary.md"), md.as_bytes())?;
    // The same report a sweep gets: index.html, report.md, picture grids.
    write_all(out, &[], &report_rows, &timings)?;
    let record = serde_json::to_vec_pretty(&provenance::record("demo")).expect("serialises");
    io::write_atomic(&out.join(provenance::PROVENANCE_JSON), &record)?;
    let description = format!(
        "# `sfp demo --size {size}` (not a sweep file): the views of summary.md, each\n\
         # reconstructed once by every method with its defaults.\n"
    );
    io::write_atomic(&out.join("sweep.toml"), description.as_bytes())?;
    report::write(out)?;
    progress(total, total, "done");
    Ok(())
}
