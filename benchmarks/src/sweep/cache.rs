//! Noise-free renders, made once per distinct configuration and kept in
//! `DIR/views/<dataset>/<view>/<hash>/` (a view folder, conventions.md §5,
//! with `gt/stokes.exr` for the exposures and `preview/` for people). The
//! hash covers everything that affects the render ([`super::plan`]), so a
//! resumed or repeated sweep reuses what is there and a changed scene is
//! rendered anew.

use super::plan::{Group, Origin, PlanView};
use sfp_core::view::View;
use sfp_core::{Error, Result};
use sfp_renderer::render::{RenderOptions, render};
use std::path::Path;
use std::time::Instant;

/// A group's noise-free view, loaded.
pub struct Cached {
    pub view: View,
    /// `Row::view_dir`: relative to the output folder for cached renders,
    /// the absolute folder of a stored view.
    pub view_dir: String,
    /// Seconds spent rendering, when it was not in the cache yet.
    pub rendered: Option<f64>,
}

/// The noise-free view of `group`, rendered into the cache under `out`
/// when missing. Always read back from disk, so a fresh render and a cached
/// one give the methods identical data.
pub fn noise_free(view: &PlanView, group: &Group, out: &Path) -> Result<Cached> {
    let key = match (&group.origin, &group.cache_key) {
        (Origin::Stored(dir), _) => {
            return Ok(Cached {
                view: View::read(dir)?,
                view_dir: dir.display().to_string(),
                rendered: None,
            });
        }
        (_, Some(key)) => key,
        (_, None) => unreachable!("renders have a cache key"),
    };
    let relative = format!("views/{}/{}/{key}", view.dataset, view.view);
    let dir = out.join(&relative);
    let mut rendered = None;
    if !View::is_complete(&dir) {
        let start = Instant::now();
        if dir.exists() {
            // An interrupted write: meta.json, written last, is missing.
            std::fs::remove_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        }
        match &group.origin {
            Origin::Rendered { scene, view_index } => render(
                scene,
                &RenderOptions {
                    view_index: *view_index,
                },
            )?
            .write(&dir)?,
            Origin::Analytic(a) => a.render()?.write(&dir)?,
            Origin::Stored(_) => unreachable!("stored views returned above"),
        }
        rendered = Some(start.elapsed().as_secs_f64());
    }
    Ok(Cached {
        view: View::read(&dir)?,
        view_dir: relative,
        rendered,
    })
}
