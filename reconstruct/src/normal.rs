//! The unit normal of a zenith and an azimuth (conventions.md §1): the one
//! formula every method turns its polarization angles into normals with
//! (the SMSfP paper's Eq. 14 for MFCP's implicit azimuth; each of the two
//! candidates `ψ`, `ψ + π` of the baselines).

use std::f64::consts::FRAC_PI_2;

/// Normal with zenith `theta` and azimuth `phi`:
/// `[sin θ cos φ, sin θ sin φ, cos θ]`. `theta` is clamped to `[0, π/2]`:
/// an f32 zenith of 90° (DoP clamped to the model maximum) exceeds π/2 and
/// would give a normal facing away.
pub fn zenith_azimuth_normal(theta: f64, phi: f64) -> [f64; 3] {
    let theta = theta.clamp(0.0, FRAC_PI_2);
    let s = theta.sin();
    [s * phi.cos(), s * phi.sin(), theta.cos()]
}

/// Azimuth `φ` of a normal (camera frame), the inverse of
/// [`zenith_azimuth_normal`]'s `φ`.
pub fn normal_azimuth(n: [f32; 3]) -> f64 {
    f64::from(n[1]).atan2(f64::from(n[0]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_normal_is_eq_14() {
        let (theta, phi) = (30f64.to_radians(), 120f64.to_radians());
        let n = zenith_azimuth_normal(theta, phi);
        // sin 30° = ½, cos 120° = −½, sin 120° = √3/2, cos 30° = √3/2.
        let want = [-0.25, 3f64.sqrt() / 4.0, 3f64.sqrt() / 2.0];
        for k in 0..3 {
            assert!((n[k] - want[k]).abs() < 1e-12, "{n:?}");
        }
        for (t, p) in [(0.0, 2.0), (1.2, -3.0), (1.5, 3.1)] {
            let v = zenith_azimuth_normal(t, p);
            assert!((v.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_zenith_past_grazing_stays_facing_the_camera() {
        let n = zenith_azimuth_normal(FRAC_PI_2 + 1e-6, 0.3);
        assert!(n[2] >= 0.0 && n[2] < 1e-12, "{n:?}");
        assert_eq!(zenith_azimuth_normal(-0.1, 0.3), [0.0, 0.0, 1.0]);
    }
}
