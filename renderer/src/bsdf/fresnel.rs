//! Fresnel amplitude coefficients in `f32` for the hot path; the `f64`
//! reference is `sfp_core::fresnel`, against which this is tested.

/// Amplitude coefficients `(r_s, r_p)` for light arriving from outside at
/// incidence cosine `cos_i` on a dielectric of relative index `eta ≥ 1`, with
/// signs for the s/p frames `(s, d × s)` of the incident and reflected rays.
/// Power reflectances are their squares, transmittances `1 − r²`.
#[inline]
pub fn amplitudes(cos_i: f32, eta: f32) -> (f32, f32) {
    if eta == 1.0 {
        return (0.0, 0.0); // no interface (and no 0/0 at grazing incidence)
    }
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (rs, rp)
}

/// `((T_s + T_p)/2, (T_s − T_p)/2)`: the first column of the transmission
/// Mueller matrix in the s/p frame (also, by reciprocity, for exit at `cos`).
#[inline]
pub fn transmission_terms(cos: f32, eta: f32) -> (f32, f32) {
    let (rs, rp) = amplitudes(cos, eta);
    let (ts, tp) = (1.0 - rs * rs, 1.0 - rp * rp);
    (0.5 * (ts + tp), 0.5 * (ts - tp))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::fresnel::{reflectance, transmittance};

    #[test]
    fn grazing_incidence_is_finite() {
        assert_eq!(amplitudes(0.0, 1.0), (0.0, 0.0));
        assert_eq!(amplitudes(0.0, 1.5), (-1.0, -1.0));
    }

    #[test]
    fn matches_core_reference() {
        for eta in [1.0f32, 1.3, 1.5, 2.2] {
            for k in 1..=100 {
                let c = k as f32 / 100.0;
                let (rs, rp) = amplitudes(c, eta);
                let (rs2, rp2) = reflectance(f64::from(c), f64::from(eta));
                assert!(
                    (f64::from(rs * rs) - rs2).abs() < 1e-6
                        && (f64::from(rp * rp) - rp2).abs() < 1e-6
                );
                let (a, b) = transmission_terms(c, eta);
                let (ts, tp) = transmittance(f64::from(c), f64::from(eta));
                assert!((f64::from(a) - 0.5 * (ts + tp)).abs() < 1e-6);
                assert!((f64::from(b) - 0.5 * (ts - tp)).abs() < 1e-6);
            }
        }
    }
}
