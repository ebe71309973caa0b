//! A noise seed → a noisy input in memory: the renderer's sensor model
//! applied to a cached noise-free render's Stokes (`gt/stokes.exr`), not a
//! re-render. Draws are keyed by (seed, view, pixel, channel), so an
//! exposure is the same in any run or shard. Noise is drawn inside the
//! object mask only (`sensor::expose_inside`; the methods read nothing
//! else), which makes a realisation several times cheaper than the full
//! frame's and identical to it on the object.

use sfp_core::view::{View, ViewInput};
use sfp_core::{Error, Result};
use sfp_reconstruct::input::Input;
use sfp_renderer::scene::SensorDesc;
use sfp_renderer::sensor::expose_inside;

/// The polarizer images `sensor` records of `view`'s noise-free Stokes with
/// noise `seed` (`view_index` keeps views' draws apart), validated for the
/// methods.
pub fn noisy_input(view: &View, sensor: &SensorDesc, seed: u64, view_index: u64) -> Result<Input> {
    Input::from_view(&noisy_view_input(view, sensor, seed, view_index)?)
}

/// The polarizer images of [`noisy_input`] as codes, before the methods'
/// reading: what a command method is given as its view's `input/`.
pub fn noisy_view_input(
    view: &View,
    sensor: &SensorDesc,
    seed: u64,
    view_index: u64,
) -> Result<ViewInput> {
    let stokes = view.gt.as_ref().and_then(|gt| gt.stokes.as_ref());
    let (Some(stokes), Some(mask)) = (stokes, &view.input.mask) else {
        return Err(Error::invalid(
            "a noise exposure needs the view's noise-free Stokes (gt/stokes.exr) and mask",
        ));
    };
    let exposed = expose_inside(sensor, stokes, mask, seed, view_index);
    Ok(ViewInput::grey(
        exposed.pol,
        sensor.bits,
        Some(mask.clone()),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::analytic::AnalyticScene;

    #[test]
    fn seeds_differ_and_repeat() {
        let view = AnalyticScene {
            size: 32,
            ..AnalyticScene::default()
        }
        .render()
        .unwrap();
        let sensor = SensorDesc {
            full_well: 2000.0,
            ..SensorDesc::default()
        };
        let a = noisy_input(&view, &sensor, 1, 0).unwrap();
        let b = noisy_input(&view, &sensor, 1, 0).unwrap();
        let c = noisy_input(&view, &sensor, 2, 0).unwrap();
        assert_eq!(a.intensity, b.intensity);
        assert_ne!(a.intensity, c.intensity);
        let quiet = SensorDesc {
            noise: false,
            ..sensor
        };
        let q1 = noisy_input(&view, &quiet, 1, 0).unwrap();
        let q2 = noisy_input(&view, &quiet, 2, 0).unwrap();
        assert_eq!(q1.intensity, q2.intensity);
    }
}
