//! Polarized diffuse reflection of a dielectric (conventions.md §3; Mitsuba's
//! `pplastic` diffuse part, Baek et al. 2018).
//!
//! Light is transmitted into the material (Fresnel transmission at `θ_i`), is
//! depolarized by subsurface scattering, scatters like Lambert, and is
//! transmitted out (Fresnel transmission at `θ_o`):
//!
//! `M = albedo/π · cosθ_i · T_out(θ_o) · D · T_in(θ_i)`, `D = diag(1, 0, 0, 0)`.
//!
//! For unpolarized light this gives `s0 = albedo/π · E cosθ_i T(θ_i) T(θ_o)`
//! with `T = (T_s + T_p)/2` and DoP `(T_p − T_s)/(T_p + T_s) = ρ_d(θ_o, η)`,
//! polarized in the plane of exit (AoP ∥ normal azimuth). Polarized incident
//! light is weighted by the first row of `T_in`, so its polarization matters.

use super::fresnel::transmission_terms;
use crate::mueller::Mueller;

/// `T_out · D · T_in` (without `albedo/π · cosθ_i`), in the exit s/p frame
/// (output) and incidence s/p frame (input). Rank one: column 0 of `T_out`
/// times row 0 of `T_in`.
#[inline]
pub fn transfer(cos_i: f32, cos_o: f32, eta: f32) -> Mueller {
    transfer_with_exit(cos_i, transmission_terms(cos_o, eta), eta)
}

/// [`transfer`] with the exit terms `((T_s+T_p)/2, (T_s−T_p)/2)` at `θ_o`
/// precomputed (they are shared by every light and BSDF sample at a vertex).
#[inline]
pub fn transfer_with_exit(cos_i: f32, (ao, bo): (f32, f32), eta: f32) -> Mueller {
    let (ai, bi) = transmission_terms(cos_i, eta);
    Mueller([
        [ao * ai, ao * bi, 0.0, 0.0],
        [bo * ai, bo * bi, 0.0, 0.0],
        [0.0; 4],
        [0.0; 4],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::fresnel::{diffuse_dop, transmittance};

    #[test]
    fn unpolarized_light_gives_paper_dop_and_fresnel_weighted_intensity() {
        let eta = 1.5f32;
        for (deg_i, deg_o) in [(0.0f32, 0.0f32), (30.0, 60.0), (75.0, 20.0), (10.0, 85.0)] {
            let (ci, co) = (deg_i.to_radians().cos(), deg_o.to_radians().cos());
            let s = transfer(ci, co, eta).apply([1.0, 0.0, 0.0, 0.0]);
            let (tsi, tpi) = transmittance(f64::from(ci), 1.5);
            let (tso, tpo) = transmittance(f64::from(co), 1.5);
            let s0 = 0.25 * (tsi + tpi) * (tso + tpo);
            assert!((f64::from(s[0]) - s0).abs() < 1e-6);
            let dop = f64::from(-s[1] / s[0]);
            let expect = diffuse_dop(f64::from(deg_o).to_radians(), 1.5);
            assert!((dop - expect).abs() < 1e-6, "{dop} vs {expect}");
            assert_eq!((s[2], s[3]), (0.0, 0.0));
        }
    }

    #[test]
    fn polarized_input_is_weighted_by_entry_transmission() {
        // s-polarized light enters less than p-polarized light.
        let m = transfer(0.3, 0.9, 1.5);
        let s_in = m.apply([1.0, 1.0, 0.0, 0.0])[0];
        let p_in = m.apply([1.0, -1.0, 0.0, 0.0])[0];
        let (ts, tp) = transmittance(0.3, 1.5);
        let (to_s, to_p) = transmittance(0.9, 1.5);
        let t_out = 0.5 * (to_s + to_p);
        assert!((f64::from(s_in) - ts * t_out).abs() < 1e-6);
        assert!((f64::from(p_in) - tp * t_out).abs() < 1e-6);
    }
}
