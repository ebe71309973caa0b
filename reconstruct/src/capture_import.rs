//! A capture imported as `sfp import` imports it: core's pipeline
//! (`sfp_core::capture::import`), then the checks only the reconstruction's
//! reading of the data can make (how much of the mask the diffuse model
//! cannot explain, `specular::beyond_diffuse`, and which way the occluding
//! contour is polarized, `specular::limb`, and whether the deepest tenth of
//! the mask shows a reflected compact light, `specular::reflected_light`),
//! recorded in `meta.json` and warned of. The CLI and Python run this one function, so their view
//! folders are the same file for file.

use crate::input::Input;
use crate::noise::stokes_noise;
use crate::prior::{DEFAULT_EXPONENT, convexity_prior};
use crate::specular::beyond_diffuse::BeyondDiffuse;
use crate::specular::fit::TYPICAL_ETA;
use crate::specular::limb::Limb;
use crate::specular::reflected_light::CorePolarization;
use sfp_core::Result;
use sfp_core::capture::import::{self, ImportOptions, Imported, Source};
use std::path::Path;

/// Imports `source` as `options` say and, when `out` is given, writes the
/// view there; each warning goes to `warn` as it arises (the share beyond
/// the diffuse ceiling named by the folder written, and last whether the
/// labels fit the data).
pub fn import(
    source: &Source,
    options: &ImportOptions,
    out: Option<&Path>,
    warn: &mut dyn FnMut(String),
) -> Result<Imported> {
    let mut imported = import::import(source, options, warn)?;
    // A layout is read back as it was written (its mask, its ground truth).
    let layout = imported.from_layout();
    let view = &mut imported.view;
    let checks = (view.input.mask.is_some() && !layout)
        .then(|| {
            // `Input::new`: an import is not refused for what a method cannot use.
            let input = Input::new(view.input.polarimetry(), view.input.mask.clone())?;
            // One prior and one noise estimate for every check.
            let prior = convexity_prior(&input.mask, DEFAULT_EXPONENT);
            let noise = stokes_noise(&input);
            Ok::<_, sfp_core::Error>((
                BeyondDiffuse::with_prior(&input, &prior, &noise),
                Limb::of(&input, &prior),
                CorePolarization::of(&input, &prior, &noise, TYPICAL_ETA),
            ))
        })
        .transpose()?;
    let (beyond, limb, core) = checks.map_or((None, None, None), |(b, l, c)| (Some(b), l, c));
    if let Some(meta) = view.meta.as_mut() {
        if let Some(beyond) = beyond {
            let figures = serde_json::to_value(beyond).expect("two numbers serialise");
            meta.extra.insert("beyond_diffuse".into(), figures);
        }
        if let Some(limb) = limb {
            let figures = serde_json::to_value(limb).expect("four numbers serialise");
            meta.extra.insert("limb".into(), figures);
        }
        if let Some(core) = core {
            let figures = serde_json::to_value(core).expect("four numbers serialise");
            meta.extra.insert("core_polarization".into(), figures);
        }
    }
    if let Some(out) = out {
        view.write(out)?;
    }
    let warnings = beyond
        .and_then(|b| b.warning())
        .into_iter()
        .chain(limb.filter(Limb::is_specular).map(|l| l.warning()))
        .chain(
            core.filter(CorePolarization::is_reflected_light)
                .map(|c| c.warning()),
        );
    for warning in warnings {
        warn(match out {
            Some(out) => format!("{}: {warning}", out.display()),
            None => warning,
        });
    }
    if let Some(warning) = imported.misfit_warning() {
        warn(warning);
    }
    Ok(imported)
}
