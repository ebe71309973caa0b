//! The outward-normal prior's rows (spec §3.2 block 3): at every layer
//! pixel (`layers`) with weight `c·ω`, the azimuth's unit vector against
//! the target's, `(cos α − cos α*, sin α − sin α*)`, and the zenith against
//! 90°, `(θ − π/2)/1000`.

use super::level::Level;
use super::levenberg::Row;
use super::model::Angles;
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_2;

/// Rows per layer pixel.
pub const ROWS: usize = 3;

/// The prior's rows at heights `z` with global weight `c`, three per target.
pub fn outward_rows(level: &Level, z: &[f64], c: f64, rows: &mut [Row]) {
    rows.par_chunks_mut(ROWS)
        .zip(&level.targets)
        .for_each(|(out, t)| {
            let k = t.unknown;
            let (p, q) = level.gradients.at(k, z);
            let a = Angles::of(p, q);
            let w = c * t.weight;
            let (s, co) = a.alpha.sin_cos();
            let (ts, tc) = t.azimuth.sin_cos();
            let da = |f: f64| level.gradients.combine(k, f * a.dalpha[0], f * a.dalpha[1]);
            out[0] = Row::weighted(w, co - tc, da(-s));
            out[1] = Row::weighted(w, s - ts, da(co));
            let dt = level
                .gradients
                .combine(k, a.dtheta[0] / 1000.0, a.dtheta[1] / 1000.0);
            out[2] = Row::weighted(w, (a.theta - FRAC_PI_2) / 1000.0, dt);
        });
}
