//! The per-pixel z-test: each pixel channel's `z = (t − r)/√(var_t + var_r)` against Šidák's
//! critical value over all pixel channels, and the error map of the largest |z| per pixel.

use super::planes::Pixel;
use super::{TestVariance, Z_ALPHA, Z_REQUIRED_FRACTION, ZTest};
use crate::image::stats::{normal_quantile_two_sided, sidak};

/// The per-pixel test of `px` and its error map (max |z| per pixel, +∞ for failed pixels). The
/// result's `scales` is empty and `passed` is the pixel verdict alone.
pub(super) fn pixel_test(px: &[Pixel], test_variance: TestVariance) -> (ZTest, Vec<f32>) {
    let tested: usize = px
        .iter()
        .map(|p| match p {
            Pixel::Usable { var, .. } => var.iter().filter(|&&v| v > 0.0).count(),
            Pixel::Failed => 0,
        })
        .sum();
    let z_crit = normal_quantile_two_sided(sidak(Z_ALPHA, tested));
    let (mut failed, mut max_abs_z) = (0usize, 0.0f64);
    let map = px
        .iter()
        .map(|p| match *p {
            Pixel::Usable {
                diff,
                var,
                exact_mismatch,
            } => {
                let max_z = (0..3)
                    .filter(|&c| var[c] > 0.0)
                    .map(|c| diff[c].abs() / var[c].sqrt())
                    .fold(0.0f64, f64::max);
                max_abs_z = max_abs_z.max(max_z);
                if exact_mismatch || max_z > z_crit {
                    failed += 1;
                }
                if exact_mismatch {
                    f32::INFINITY
                } else {
                    max_z as f32
                }
            }
            Pixel::Failed => {
                failed += 1;
                f32::INFINITY
            }
        })
        .collect();
    let n = px.len().max(1);
    let pass_fraction = (n - failed.min(n)) as f64 / n as f64;
    let pixels_passed = pass_fraction >= Z_REQUIRED_FRACTION;
    let z = ZTest {
        alpha: Z_ALPHA,
        z_crit,
        pixels: px.len(),
        failed_pixels: failed,
        pass_fraction,
        required_fraction: Z_REQUIRED_FRACTION,
        max_abs_z,
        tested_channels: tested,
        test_variance,
        pixels_passed,
        scales: Vec::new(),
        passed: pixels_passed,
    };
    (z, map)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn usable(d: f64, v: f64) -> Pixel {
        Pixel::Usable {
            diff: [d, 0.0, 0.0],
            var: [v, v, 0.0],
            exact_mismatch: false,
        }
    }

    #[test]
    fn counts_tested_channels_and_fails_beyond_the_sidak_limit() {
        // 400 pixels with 2 tested channels each (798 with the failed pixel out): z_crit =
        // q(1 − 0.99^(1/798)) ≈ 4.37, so |z| 4 passes and 4.5 fails.
        let mut px = vec![usable(0.0, 1.0); 400];
        px[0] = usable(4.0, 1.0);
        px[1] = usable(-4.5, 1.0);
        px[2] = Pixel::Failed;
        let (z, map) = pixel_test(&px, TestVariance::Own);
        assert_eq!(z.tested_channels, 798);
        assert!((z.z_crit - 4.367).abs() < 0.001, "{}", z.z_crit);
        assert_eq!(z.failed_pixels, 2);
        assert_eq!((map[0], map[1], map[2]), (4.0, 4.5, f32::INFINITY));
        assert_eq!(z.max_abs_z, 4.5);
        // 2 of 400 failed: 99.5 % < 99.75 %.
        assert!(!z.pixels_passed && !z.passed && z.scales.is_empty());
        px[1] = usable(0.0, 1.0);
        assert!(pixel_test(&px, TestVariance::Own).0.passed);
    }
}
