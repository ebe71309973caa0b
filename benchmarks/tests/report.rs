//! The report of a small sweep: every file written, every image the HTML
//! shows present, rows without figures shown, identical on re-run, missing
//! pictures and missing sweep files reported.

use sfp_benchmarks::report;
use sfp_benchmarks::row::Row;
use sfp_benchmarks::sweep::{self, file::Sweep, shard::Shard};
use std::path::Path;

/// One exact analytic view, two η, two noise seeds, three methods and an
/// ablation.
const SWEEP: &str = "# A small sweep of an exact analytic view.
seeds = 2

[[views]]
analytic = \"sphere\"
size = 40

[axes]
eta = [1.3, 1.5]

[[methods]]
method = \"atkinson\"

[[methods]]
method = \"smith\"

[[methods]]
method = \"smsfp\"

[[methods]]
label = \"smsfp-no-parg\"
method = \"smsfp\"
parg = false
";

/// The `src` of every `<img>` in `html`, entities decoded.
fn image_sources(html: &str) -> Vec<String> {
    html.split("<img ")
        .skip(1)
        .filter_map(|tag| {
            let start = tag.find("src=\"")? + 5;
            let end = start + tag[start..].find('"')?;
            Some(tag[start..end].replace("&#x2f;", "/").replace("&amp;", "&"))
        })
        .collect()
}

fn read(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"))
}

#[test]
fn report_of_a_small_sweep() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let file = dir.join("small.toml");
    let sweep = Sweep::from_toml(SWEEP, &file).unwrap();
    sweep::run(&sweep, dir, Shard::ALL, &|_| {}).unwrap();
    let (rows, _) = sweep::results::read_rows(&dir.join("results.jsonl"), true).unwrap();
    // 1 view × 2 η × 2 seeds × 4 labels.
    assert_eq!(rows.len(), 16);
    assert!(rows.iter().all(|r| r.metrics.is_some()), "{rows:?}");

    // A failed row and a row of a view without ground truth.
    let mut failed: Row = rows[0].clone();
    failed.key = "failed".into();
    failed.seed = 7;
    failed.metrics = None;
    failed.error = Some("boom: the solver diverged".into());
    failed.pictures = None;
    let mut real = rows[1].clone();
    real.key = "real".into();
    real.dataset = "real".into();
    real.view = "capture".into();
    real.object = "capture".into();
    real.metrics = None;
    real.pictures = None;
    let mut jsonl = read(dir, "results.jsonl");
    for r in [&failed, &real] {
        jsonl.push_str(&serde_json::to_string(r).unwrap());
        jsonl.push('\n');
    }
    std::fs::write(dir.join("results.jsonl"), jsonl).unwrap();

    let w = report::write(dir).unwrap();
    assert_eq!((w.rows, w.rows_with_figures), (18, 16));
    // η takes two values (six plots).
    assert_eq!(w.plots.len(), 6, "{:?}", w.plots);
    assert!(w.plots.iter().all(|p| p.contains("-vs-eta")));
    // Pictures of seed 0 at the first η (the sweep's picture rule): a
    // normals and an errors grid.
    assert_eq!(w.grids.len(), 2, "{:?}", w.grids);
    assert!(w.missing_pictures.is_empty(), "{:?}", w.missing_pictures);
    assert!(w.notes.is_empty(), "{:?}", w.notes);

    let html = read(dir, "index.html");
    let md = read(dir, "report.md");
    let sources = image_sources(&html);
    assert_eq!(sources.len(), 6 + 2);
    for src in &sources {
        assert!(
            dir.join(src).is_file(),
            "index.html shows {src}, which does not exist"
        );
    }
    // Every picture opens at full size: each <img> in a link to its file.
    for tag in html
        .split("<img ")
        .skip(1)
        .map(|t| t.split('>').next().unwrap())
    {
        let src = tag
            .split("src=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        assert!(
            html.contains(&format!("<a href=\"{src}\"><img src=\"{src}\"")),
            "{src} is not a link"
        );
    }
    assert_eq!(md.matches("[![").count(), 6 + 2, "{md}");
    // The grids say their one scale and colour range.
    assert!(html.contains("one grey scale for the row") && html.contains("% of full scale"));
    assert!(html.contains("one colour range for every tile"));
    for text in [&html, &md] {
        assert!(text.contains("(the paper") && text.contains("Table 1)"));
        assert!(text.contains("Table 2)"));
        // 4 pairs per comparison: too few for an interval, so no paired
        // table; the ranking says who won.
        assert!(!text.contains("Paired comparisons"));
        assert!(text.contains("Who won") && text.contains("Ranking per view"));
        assert!(text.contains("failed: boom: the solver diverged"));
        assert!(text.contains("no ground truth"));
        assert!(text.contains("A small sweep of an exact analytic view"));
        assert!(text.contains("Time per view"));
    }
    assert!(md.contains("| Dataset analytic · MAE (°) |"), "{md}");
    // The view without ground truth has a cell, counted but not averaged.
    assert!(read(dir, "stats.csv").contains("real,"));

    // Identical on re-run (the plots and grids included).
    let first: Vec<(String, Vec<u8>)> = ["index.html", "report.md", "stats.csv"]
        .iter()
        .map(|f| f.to_string())
        .chain(w.plots.iter().cloned())
        .chain(w.grids.iter().cloned())
        .map(|f| {
            let bytes = std::fs::read(dir.join(&f)).unwrap();
            (f, bytes)
        })
        .collect();
    let again = report::write(dir).unwrap();
    assert_eq!(again, w);
    for (f, bytes) in &first {
        assert!(
            std::fs::read(dir.join(f)).unwrap() == *bytes,
            "{f} differs on re-run"
        );
    }

    // A picture gone: drawn as missing and listed, not an error.
    let kept = rows
        .iter()
        .find(|r| r.method == "smith" && r.pictures.is_some())
        .unwrap();
    let gone = dir
        .join(kept.pictures.as_ref().unwrap())
        .join("normals.exr");
    std::fs::remove_file(&gone).unwrap();
    // Optional files gone: said so.
    std::fs::remove_file(dir.join("provenance.json")).unwrap();
    std::fs::remove_file(dir.join("timings.csv")).unwrap();
    let w = report::write(dir).unwrap();
    assert_eq!(w.missing_pictures, [gone.display().to_string()]);
    assert_eq!(w.notes.len(), 2, "{:?}", w.notes);
    let html = read(dir, "index.html");
    assert!(
        html.contains("could not be read"),
        "missing picture not listed"
    );
    assert!(html.contains("provenance.json is missing"));
    assert!(!html.contains("Time per view"));
}
