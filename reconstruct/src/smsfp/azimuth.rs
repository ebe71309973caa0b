//! The AoP's π ambiguity resolved by a sense from elsewhere: a prior's
//! azimuth (step 6, `region`), a solved normal's projection (steps 8 and 9,
//! `refine`, `sense`).

/// `(cos φ, sin φ)` of the azimuth `φ ∈ {ψ, ψ + π}` on the side of the
/// image-plane direction `d`: the AoP resolved by a sense from elsewhere
/// (a solved normal's projection, a prior's azimuth).
pub(super) fn azimuth_toward(psi: f64, d: [f64; 2]) -> (f64, f64) {
    let (sp, cp) = psi.sin_cos();
    if d[0] * cp + d[1] * sp >= 0.0 {
        (cp, sp)
    } else {
        (-cp, -sp)
    }
}

/// The AoP in the sense of the normal `n`'s projection.
pub(super) fn azimuth_in_sense(psi: f64, n: &[f32; 3]) -> (f64, f64) {
    azimuth_toward(psi, [f64::from(n[0]), f64::from(n[1])])
}
