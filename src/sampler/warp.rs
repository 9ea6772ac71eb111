//! Warps of uniform numbers onto other domains, shared by the camera lens, disc lights and
//! cosine-weighted BSDF sampling.

use glam::Vec2;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

/// Shirley & Chiu's concentric map of the unit square onto the unit disc ("A Low Distortion Map
/// Between Disk and Square", JGT 2(3), 1997): uniform by area, continuous, low distortion. The
/// centre `(½, ½)` maps to the origin.
#[inline]
pub fn concentric_disc(u: Vec2) -> Vec2 {
    let (a, b) = (2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
    if a == 0.0 && b == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    };
    Vec2::new(r * phi.cos(), r * phi.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concentric_disc_stays_in_the_disc_covers_it_and_keeps_area() {
        let mut max_r = 0.0f32;
        let n = 64;
        let mut inner = 0;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let d = concentric_disc(u);
                assert!(d.length() <= 1.0 + 1e-6);
                max_r = max_r.max(d.length());
                inner += usize::from(d.length() < 0.5);
            }
        }
        assert!(max_r > 0.98);
        // Uniform by area: a quarter of the points fall inside radius ½ (exactly, by the map's
        // construction on this grid).
        assert_eq!(inner, n * n / 4);
        assert_eq!(concentric_disc(Vec2::splat(0.5)), Vec2::ZERO);
    }
}
