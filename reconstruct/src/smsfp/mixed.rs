//! Step 11: the surface fit under the mixed reflection model
//! (`specular::fit`), from each start `fit_start` names, and the choice
//! between the fitted surfaces (and, with `fit_keeps_own`, SMSfP's own).
//!
//! Between starts of different sense the fit's cost cannot choose: the
//! specular share is free per window, so a surface with wrong zeniths fits
//! the polarization about as well as the right one (glossy preset: picking
//! the lower cost gives 21.33° mean MAE, the better start per view 15.43°).
//! The intensity can: under a smooth light, `I = a + n · L` with the albedo
//! folded in, the right normals explain the shading and a surface with
//! turned azimuths does not (`light::shading_residual`). It needs no
//! labelling of the highlights: the worst-explained tenth of the pixels is
//! left out. The two convex starts (`FitStart::Convex`) share every pixel's
//! sense, so between them alone the cost chooses.

use super::Smsfp;
use crate::dome::{dome, membrane};
use crate::input::Input;
use crate::light::shading_residual;
use crate::noise::StokesNoise;
use crate::specular::fit::{self, Candidate, FitStart, SurfaceFit};
use sfp_core::{Image, NormalMap, Result};

/// What step 11 keeps: a fitted surface, or `None` for SMSfP's own (the
/// record says why).
pub(super) struct Kept {
    pub fit: Option<SurfaceFit>,
    pub record: fit::FitRecord,
}

/// Step 11 for `input` (AoPs as measured) from SMSfP's own surface
/// (`normals`, `height`), modelling a reflected compact light or not
/// (`reflected_light`, decided from `params.reflected_light`).
pub(super) fn mixed_fit(
    params: &Smsfp,
    input: &Input,
    normals: &NormalMap,
    height: &Image<f32>,
    noise: &StokesNoise,
    reflected_light: bool,
) -> Result<Kept> {
    let shaded = input.shaded();
    let residual =
        |n: &NormalMap| shading_residual(n.data(), input.intensity.data(), shaded.data());
    let own_residual = residual(normals);
    let model = fit::Model {
        eta: fit::reading_eta(params.refine, params.shared.eta),
        reflected_light,
        shading: own_residual.filter(|_| params.fit_shading),
    };
    let starts: Vec<(&str, Image<f32>)> = match params.fit_start {
        FitStart::Dome => vec![("dome", dome(&input.mask))],
        FitStart::Convex => vec![
            ("dome", dome(&input.mask)),
            ("membrane", membrane(&input.mask)?),
        ],
        FitStart::Stitched => vec![("stitched", height.clone())],
        FitStart::Both => vec![("dome", dome(&input.mask)), ("stitched", height.clone())],
    };
    let mut fits = Vec::new();
    for (name, start) in &starts {
        fits.push((*name, fit::fit(input, start, model, noise)?));
    }
    // The convex starts alone are told apart by their cost; anything else
    // by the shading.
    let by_cost = params.fit_start == FitStart::Convex && !params.fit_keeps_own;
    let choosing = fits.len() > 1 || params.fit_keeps_own;
    if !choosing {
        let (_, only) = fits.pop().expect("one start");
        let record = only.record.clone();
        return Ok(Kept {
            fit: Some(only),
            record,
        });
    }
    let mut candidates: Vec<Candidate> = fits
        .iter()
        .map(|(name, f)| Candidate {
            surface: name.to_string(),
            shading_residual: if by_cost { None } else { residual(&f.normals) },
            cost: Some(f.record.cost_end),
        })
        .collect();
    if params.fit_keeps_own {
        candidates.push(Candidate {
            surface: "own".to_string(),
            shading_residual: own_residual,
            cost: fits
                .iter()
                .find(|(n, _)| *n == "stitched")
                .map(|(_, f)| f.record.cost_start),
        });
    }
    // The lowest cost or residual; a surface without one (too few lit
    // pixels) is kept only when no surface has one.
    let score = |c: &Candidate| {
        let figure = if by_cost { c.cost } else { c.shading_residual };
        figure.unwrap_or(f64::INFINITY)
    };
    let best = (0..candidates.len())
        .min_by(|&a, &b| score(&candidates[a]).total_cmp(&score(&candidates[b])))
        .expect("at least one candidate");
    let kept_name = candidates[best].surface.clone();
    let kept_fit = (best < fits.len()).then(|| fits.swap_remove(best).1);
    let mut record = match &kept_fit {
        Some(f) => f.record.clone(),
        None => fits[0].1.record.clone(),
    };
    record.candidates = candidates;
    record.kept = Some(kept_name);
    Ok(Kept {
        fit: kept_fit,
        record,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::method::Method;
    use crate::specular::fit::MixedFit;
    use crate::specular::reflected_light::ReflectedLight;
    use crate::test_support::{analytic, glossy_sphere, mae, with_reflected_light};
    use sfp_core::analytic::Shape;

    /// `method`'s error on `input` and the record of its fit.
    fn fitted(method: &Smsfp, input: &Input, gt: &NormalMap) -> (f64, fit::FitRecord) {
        let (error, rec) = mae(method, input, gt);
        let record = serde_json::from_value(rec.run.own["fit"].clone()).unwrap();
        (error, record)
    }

    /// The surfaces the fit's choice weighed, in order.
    fn names(record: &fit::FitRecord) -> Vec<&str> {
        record
            .candidates
            .iter()
            .map(|c| c.surface.as_str())
            .collect()
    }

    #[test]
    fn the_surface_a_smooth_light_explains_best_is_kept() {
        let (input, gt) = analytic(Shape::Sphere, 64, 1.5);
        let method = Smsfp {
            mixed_fit: MixedFit::On,
            fit_start: FitStart::Both,
            fit_keeps_own: true,
            ..Smsfp::default()
        };
        let (error, record) = fitted(&method, &input, &gt);
        assert_eq!(names(&record), ["dome", "stitched", "own"]);
        let best = record
            .candidates
            .iter()
            .min_by(|a, b| {
                a.shading_residual
                    .unwrap()
                    .total_cmp(&b.shading_residual.unwrap())
            })
            .unwrap();
        assert_eq!(record.kept.as_deref(), Some(best.surface.as_str()));
        // The fit from SMSfP's surface only lowers the cost it started at.
        let cost = |i: usize| record.candidates[i].cost.unwrap();
        assert!(cost(1) <= cost(2), "{:?}", record.candidates);
        // Every candidate is the sphere here, so whichever is kept is.
        assert!(error < 3.0, "{error}° kept {:?}", record.kept);
    }

    #[test]
    fn the_convex_starts_keep_the_fit_of_lower_cost() {
        let (input, _) = glossy_sphere(64, 1.0);
        let (_, gt) = analytic(Shape::Sphere, 64, 1.5);
        let method = Smsfp {
            mixed_fit: MixedFit::On,
            ..Smsfp::default()
        };
        let (error, record) = fitted(&method, &input, &gt);
        assert_eq!(names(&record), ["dome", "membrane"]);
        let cheapest = record
            .candidates
            .iter()
            .min_by(|a, b| a.cost.unwrap().total_cmp(&b.cost.unwrap()))
            .unwrap();
        assert_eq!(record.kept.as_deref(), Some(cheapest.surface.as_str()));
        assert_eq!(record.cost_end, cheapest.cost.unwrap());
        // And the kept fit reads the glossy sphere better than the diffuse
        // model does.
        let diffuse = Smsfp {
            mixed_fit: MixedFit::Off,
            ..Smsfp::default()
        };
        let (as_diffuse, _) = mae(&diffuse, &input, &gt);
        assert!(
            error < as_diffuse,
            "{error}° against {as_diffuse}° as diffuse"
        );
    }

    #[test]
    fn a_light_reflected_by_rough_facets_is_modelled_where_the_core_shows_it() {
        // Polarization in one direction everywhere, stronger than reflection
        // by the sphere gives at its centre.
        let (input, gt) = analytic(Shape::Sphere, 64, 1.5);
        let input = with_reflected_light(input, 0.25, 15f64.to_radians(), |_, _| true);
        let read = |method: &Smsfp| {
            let (error, rec) = mae(method, &input, &gt);
            (error, rec.run.own["model"].clone())
        };
        let (auto, model) = read(&Smsfp::default());
        assert_eq!(model["model"], "mixed", "{model}");
        assert_eq!(model["reflected_light"], true, "{model}");
        let off = Smsfp {
            reflected_light: ReflectedLight::Off,
            ..Smsfp::default()
        };
        let (ignored, model) = read(&off);
        assert_eq!(model["reflected_light"], false, "{model}");
        println!("reflected light modelled {auto:.2}°, ignored {ignored:.2}°");
        assert!(auto < 0.5 * ignored, "{auto}° against {ignored}° without");
        // The plain sphere keeps it off; written as a flag, it parses.
        let (plain, _) = analytic(Shape::Sphere, 64, 1.5);
        let rec = Smsfp::default().reconstruct(&plain).unwrap();
        assert_eq!(rec.run.own["model"]["reflected_light"], false);
        let on: Smsfp =
            serde_json::from_value(serde_json::json!({ "reflected_light": true })).unwrap();
        assert_eq!(on.reflected_light, ReflectedLight::On);
    }

    #[test]
    fn by_default_the_mixed_model_reads_only_what_the_diffuse_one_cannot() {
        let model = |input: &Input| {
            let rec = Smsfp::default().reconstruct(input).unwrap();
            let model = &rec.run.own["model"];
            println!("{model}, eta {}", rec.run.own["eta"]["initial"]);
            model["model"].as_str().unwrap().to_string()
        };
        let (diffuse, _) = analytic(Shape::Sphere, 64, 1.5);
        assert_eq!(model(&diffuse), "diffuse");
        // Bright surroundings reflected: read as diffuse, an index beyond 2.5.
        let (glossy, _) = glossy_sphere(64, 3.0);
        assert_eq!(model(&glossy), "mixed");
        // Written either way, the option parses.
        let on: Smsfp = serde_json::from_value(serde_json::json!({ "mixed_fit": true })).unwrap();
        let auto: Smsfp =
            serde_json::from_value(serde_json::json!({ "mixed_fit": "auto" })).unwrap();
        assert_eq!(
            (on.mixed_fit, auto.mixed_fit),
            (MixedFit::On, MixedFit::Auto)
        );
    }
}
