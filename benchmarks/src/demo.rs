//! The main job (`sfp demo`): builds the default scenes, writes their views,
//! and summarises them in `summary.md` — the end-to-end path a new user runs
//! first.

use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::inspect::summarize;
use sfp_core::{Result, io};
use std::fmt::Write as _;
use std::path::Path;

/// One default scene of the demo.
struct DemoScene {
    name: &'static str,
    scene: AnalyticScene,
}

fn scenes(size: usize) -> Vec<DemoScene> {
    let base = AnalyticScene {
        size,
        ..AnalyticScene::default()
    };
    vec![
        DemoScene {
            name: "analytic_sphere",
            scene: AnalyticScene {
                shape: Shape::Sphere,
                light: [0.3, 0.2, 1.0],
                ..base.clone()
            },
        },
        DemoScene {
            name: "analytic_blobs",
            scene: AnalyticScene {
                shape: Shape::Blobs,
                light: [-0.2, 0.3, 1.0],
                ..base
            },
        },
    ]
}

/// Runs the demo into `out`, calling `progress(done, total, name)` per scene.
pub fn run(out: &Path, size: usize, progress: &dyn Fn(usize, usize, &str)) -> Result<()> {
    let scenes = scenes(size);
    let mut md = String::from("# polar-sfp demo\n\n");
    md.push_str(
        "| view | size | mask pixels | I_un median | DoP median | DoP p99 | above diffuse max |\n",
    );
    md.push_str("|---|---|---|---|---|---|---|\n");
    for (k, s) in scenes.iter().enumerate() {
        progress(k, scenes.len(), s.name);
        let dir = out.join("views").join(s.name);
        let view = s.scene.render()?;
        view.write(&dir)?;
        let sum = summarize(&view);
        let _ = writeln!(
            md,
            "| {} | {}×{} | {} | {:.3} | {:.3} | {:.3} | {:.1}% |",
            s.name,
            sum.width,
            sum.height,
            sum.pixels,
            sum.intensity.median,
            sum.dop.median,
            sum.dop.p99,
            100.0 * sum.dop_above_diffuse_max
        );
    }
    progress(scenes.len(), scenes.len(), "done");
    md.push_str("\nPreview pictures of each view are in `views/<name>/preview/`.\n");
    io::write_atomic(&out.join("summary.md"), md.as_bytes())
}
