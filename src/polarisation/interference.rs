//! A birefringent plate between polarisers — the polariscope's measurement — and the interference
//! colours of the Michel-Lévy chart: white light through a polariser, a plate of retardation
//! `R = d Δn` whose axis lies at `θ` to the polariser, and an analyser crossed with it keeps
//! `½ sin² 2θ · sin²(π R / λ)` of each wavelength (Born & Wolf, *Principles of Optics*, 7th ed.,
//! §15.4.4; the chart: Michel-Lévy, *Les minéraux des roches*, 1888; Sørensen, "A revised
//! Michel-Lévy interference colour chart based on first-principles calculations", European
//! Journal of Mineralogy 25, 2013, computes it the same way).

use super::{Mueller, Stokes};
use crate::spectrum::cie;
use glam::Vec3;

/// The share of unpolarised light of wavelength `lambda_nm` that a polariser at 0, a plate of
/// retardation `retardation_nm` with its slow axis at `axis` radians, and an analyser at
/// `analyser` radians let through, by the Mueller matrices.
pub fn transmittance(retardation_nm: f64, lambda_nm: f64, axis: f64, analyser: f64) -> f64 {
    let delta = std::f64::consts::TAU * retardation_nm / lambda_nm;
    Mueller::linear_polariser(analyser)
        .then_after(&Mueller::linear_retarder(delta, axis))
        .then_after(&Mueller::linear_polariser(0.0))
        .apply(Stokes::unpolarised(1.0))
        .intensity()
}

/// CIE XYZ of daylight (D65) through crossed polars with a plate of retardation `retardation_nm`
/// at 45° (constant `Δn` across the spectrum, as the chart assumes), relative to the daylight
/// seen through the polariser alone (`Y = 1` would be a plate that passes every wavelength).
pub fn michel_levy_xyz(retardation_nm: f64) -> Vec3 {
    let white = cie::spectrum_to_xyz(cie::d65).y;
    let through = cie::spectrum_to_xyz(|l| {
        let t = transmittance(
            retardation_nm,
            f64::from(l),
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::FRAC_PI_2,
        );
        cie::d65(l) * (2.0 * t) as f32
    });
    through / white
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// The Mueller chain equals the closed form at every axis and retardation, and parallel polars
    /// pass what crossed ones stop.
    #[test]
    fn a_plate_between_polars_follows_its_closed_form() {
        for i in 0..=48 {
            let axis = PI * f64::from(i) / 48.0;
            for r in [0.0, 80.0, 275.0, 550.0, 1234.0] {
                for lambda in [400.0, 550.0, 700.0] {
                    let crossed = transmittance(r, lambda, axis, FRAC_PI_2);
                    let want = 0.5 * (2.0 * axis).sin().powi(2) * (PI * r / lambda).sin().powi(2);
                    assert!((crossed - want).abs() < 1e-12, "θ {axis} R {r} λ {lambda}");
                    let parallel = transmittance(r, lambda, axis, 0.0);
                    assert!((crossed + parallel - 0.5).abs() < 1e-12);
                }
            }
        }
    }

    /// Turned once between crossed polars a doubly refractive plate goes dark four times — when
    /// its axes line up with the polars — and is brightest halfway between; an isotropic one (no
    /// retardation) stays dark.
    #[test]
    fn a_doubly_refractive_stone_blinks_four_times_per_turn() {
        let turn: Vec<f64> = (0..360)
            .map(|deg| transmittance(300.0, 550.0, f64::from(deg).to_radians(), FRAC_PI_2))
            .collect();
        let dark: Vec<usize> = (0..360).filter(|&d| turn[d] < 1e-12).collect();
        assert_eq!(dark, vec![0, 90, 180, 270]);
        let peak = turn.iter().cloned().fold(0.0, f64::max);
        for d in [45, 135, 225, 315] {
            assert!((turn[d] - peak).abs() < 1e-12);
        }
        assert!(
            (0..360)
                .all(|d| transmittance(0.0, 550.0, f64::from(d).to_radians(), FRAC_PI_2) < 1e-15)
        );
    }

    /// The chart's orders: black at no retardation; first-order lavender grey at 100 nm (short
    /// wavelengths pass first) and a brighter, near-neutral white at 250 nm; first-order yellow at 400 nm (blue lowest); the sensitive tint's magenta at 550 nm
    /// (green lowest: the plate extinguishes green); second-order blue at 650 nm (blue highest).
    #[test]
    fn michel_levy_colours_run_through_their_orders() {
        let rgb = |r: f64| cie::xyz_to_linear_srgb(michel_levy_xyz(r));
        assert!(michel_levy_xyz(0.0).length() < 1e-9);
        // Lavender grey, then the brighter, more neutral first-order white.
        let grey = rgb(100.0);
        assert!(grey.z > grey.y && grey.y > grey.x, "{grey}");
        let white = rgb(250.0);
        assert!(michel_levy_xyz(250.0).y > michel_levy_xyz(100.0).y);
        assert!(
            white.max_element() - white.min_element() < 0.35 * white.max_element(),
            "{white}"
        );
        let yellow = rgb(400.0);
        assert!(yellow.z < yellow.x && yellow.z < yellow.y, "{yellow}");
        let tint = rgb(550.0);
        assert!(tint.y < tint.x && tint.y < tint.z, "{tint}");
        let blue = rgb(650.0);
        assert!(blue.z > blue.x && blue.z > blue.y, "{blue}");
    }
}
