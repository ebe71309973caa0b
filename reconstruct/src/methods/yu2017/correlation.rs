//! The shape-correlation prior of the full stage (spec §4.3 block 2): in
//! every 3×3 block of at least [`MIN_BLOCK`] mask pixels, the Pearson
//! correlation between the heights and the ratio stage's heights should be
//! 1, so the full stage may change the surface's local shape only as far
//! as the intensities demand, and never its local scale or offset.
//!
//! A block whose ratio-stage heights are flat has no correlation; the
//! authors' code turns its 0/0 into a residual of 1 with a Jacobian of 1
//! (Q6); the port gives it no row.

use super::level::Level;
use super::levenberg::Row;
use crate::solver::operators::Stencil;
use rayon::prelude::*;

/// Blocks with fewer mask pixels (centre included) carry no row.
pub const MIN_BLOCK: usize = 4;

/// Unknowns of each block: the centre's in-mask 3×3 neighbourhood.
#[derive(Clone, Debug)]
pub struct Blocks {
    members: Vec<([u32; 9], usize)>,
}

impl Blocks {
    pub fn new(level: &Level) -> Blocks {
        let d = &level.domain;
        let members = (0..d.len())
            .filter_map(|k| {
                let (x, y) = d.pixel(k);
                let mut ids = [0u32; 9];
                let mut len = 0;
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        if let Some(j) = d.at(x as isize + dx, y as isize + dy) {
                            ids[len] = j as u32;
                            len += 1;
                        }
                    }
                }
                (len >= MIN_BLOCK).then_some((ids, len))
            })
            .collect();
        Blocks { members }
    }

    pub fn len(&self) -> usize {
        self.members.len()
    }

    /// One row per block, weight `w`: `w (corr(z, kernel) − 1)`.
    pub fn rows(&self, z: &[f64], kernel: &[f64], w: f64, rows: &mut [Row]) {
        rows.par_iter_mut()
            .zip(&self.members)
            .for_each(|(row, (ids, len))| {
                let ids = &ids[..*len];
                let centred = |v: &[f64]| {
                    let mean = ids.iter().map(|&i| v[i as usize]).sum::<f64>() / *len as f64;
                    let mut c = [0.0; 9];
                    ids.iter().zip(&mut c).for_each(|(&i, c)| *c = v[i as usize] - mean);
                    let norm = c.iter().map(|x| x * x).sum::<f64>().sqrt();
                    (c, norm)
                };
                let (k, kn) = centred(kernel);
                let (c, cn) = centred(z);
                if kn <= f64::EPSILON * (1.0 + kernel[ids[0] as usize].abs()) || cn == 0.0 {
                    *row = Row::default();
                    return;
                }
                let dot: f64 = (0..*len).map(|i| c[i] * k[i]).sum::<f64>() / kn;
                let corr = dot / cn;
                // ∂corr/∂c = k̂/‖c‖ − c (c·k̂)/‖c‖³, then centred (the
                // centring's Jacobian is the symmetric projector).
                let mut g = [0.0; 9];
                for i in 0..*len {
                    g[i] = k[i] / (kn * cn) - c[i] * dot / (cn * cn * cn);
                }
                let mean = g[..*len].iter().sum::<f64>() / *len as f64;
                let mut s = Stencil::default();
                for i in 0..*len {
                    s.push(ids[i] as usize, g[i] - mean);
                }
                *row = Row::weighted(w, corr - 1.0, s);
            });
    }
}
