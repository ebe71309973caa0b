//! Fixtures the tests share: analytic views and the error
//! of a method on them.

use crate::input::Input;
use crate::method::{Method, Reconstruction};
use sfp_core::NormalMap;
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::metrics::evaluate;

/// The analytic views' light.
pub(crate) const LIGHT: [f64; 3] = [0.35, 0.25, 0.9];

/// An analytic `shape` of `size²` pixels and refractive index `eta` under
/// [`LIGHT`]: its input and its true normals.
pub(crate) fn analytic(shape: Shape, size: usize, eta: f64) -> (Input, NormalMap) {
    let view = AnalyticScene {
        shape,
        size,
        eta,
        albedo: 0.8,
        light: LIGHT,
    }
    .render()
    .unwrap();
    let input = Input::from_view(&view.input).unwrap();
    (input, view.gt.unwrap().normals)
}

/// `method`'s mean angular error (degrees) on `input` against `gt`, and its
/// reconstruction; every mask pixel must have a normal.
pub(crate) fn mae(method: &dyn Method, input: &Input, gt: &NormalMap) -> (f64, Reconstruction) {
    let rec = method.reconstruct(input).unwrap();
    let m = evaluate(&rec.normals, gt, &input.mask).unwrap();
    assert_eq!(m.missing, 0);
    (m.mae_deg, rec)
}
