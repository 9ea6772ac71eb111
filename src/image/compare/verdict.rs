//! [`compare_with`]: every part of a comparison put together into a verdict.

use super::planes::{self, Planes, planes};
use super::{
    CompareError, Comparison, Options, REL_ERROR_SCALE, REL_MSE_THRESHOLD, Role, metrics, pixel,
    tiles,
};
use crate::image::ExrImage;

/// Compares `test` against `reference` with the default [`Options`].
pub fn compare(test: &ExrImage, reference: &ExrImage) -> Result<Comparison, CompareError> {
    compare_with(test, reference, &Options::default())
}

/// Compares `test` against `reference`: metrics, mean ratio, z-tests (when the variances are
/// known), error map and verdict, as described in the [module documentation](self).
pub fn compare_with(
    test: &ExrImage,
    reference: &ExrImage,
    options: &Options,
) -> Result<Comparison, CompareError> {
    let tol = options.mean_tolerance;
    if !(0.0..=1.0).contains(&tol) {
        return Err(CompareError::BadTolerance(tol));
    }
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(CompareError::SizeMismatch {
            test: (test.width, test.height),
            reference: (reference.width, reference.height),
        });
    }
    let n = test.width as usize * test.height as usize;
    if n == 0 {
        return Err(CompareError::Empty);
    }
    let t = planes(test, Role::Test)?;
    let r = planes(reference, Role::Reference)?;
    let finite: Vec<bool> = (0..n)
        .map(|i| (0..3).all(|c| t.rgb[c][i].is_finite() && r.rgb[c][i].is_finite()))
        .collect();
    let non_finite_pixels = finite.iter().filter(|&&f| !f).count();
    let m = metrics::metrics(&t, &r, &finite);
    let mean_ratio = metrics::mean_ratio(&t, &r, &finite, tol);

    let (ztest, ztest_skipped, error_map, error_scale) = match planes::pixels(&t, &r, &finite) {
        Ok((px, source)) => {
            let (mut z, map) = pixel::pixel_test(&px, source);
            let materials = r.material.or(t.material);
            z.scales = tiles::tile_tests(&px, test.width, test.height, materials);
            z.passed = z.pixels_passed && z.scales.iter().all(|s| s.passed);
            let scale = z.z_crit as f32;
            (Some(z), None, map, scale)
        }
        Err(why) => {
            let map = metrics::relative_error_map(&t, &r, &finite);
            (None, Some(why), map, REL_ERROR_SCALE)
        }
    };
    let passed = match &ztest {
        Some(z) => z.passed,
        None => m.rel_mse <= REL_MSE_THRESHOLD && non_finite_pixels == 0 && mean_ratio.passed,
    };
    let rgb = |p: &Planes| -> Vec<[f32; 3]> {
        (0..n)
            .map(|i| [p.rgb[0][i], p.rgb[1][i], p.rgb[2][i]])
            .collect()
    };
    let flip = f64::from(
        crate::image::flip::hdr_flip(
            &rgb(&t),
            &rgb(&r),
            test.width,
            test.height,
            crate::image::flip::DEFAULT_PPD,
        )
        .flip
        .mean,
    );
    Ok(Comparison {
        width: test.width,
        height: test.height,
        rmse: m.rmse,
        rel_mse: m.rel_mse,
        mae: m.mae,
        psnr: m.psnr,
        peak: m.peak,
        flip,
        non_finite_pixels,
        mean_ratio,
        ztest,
        ztest_skipped,
        error_map,
        error_scale,
        passed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Channel;
    use crate::image::compare::{MEAN_TOLERANCE, TestVariance};

    /// A `w × h` image with the given channels (name, values).
    fn image(w: u32, h: u32, channels: &[(&str, Vec<f32>)]) -> ExrImage {
        ExrImage {
            width: w,
            height: h,
            channels: channels
                .iter()
                .map(|(n, d)| Channel::new(*n, d.clone()))
                .collect(),
            attributes: vec![],
        }
    }

    /// R, G, B all `rgb`, plus `variance.R/G/B` all `var` if given.
    fn grey(rgb: Vec<f32>, var: Option<Vec<f32>>) -> ExrImage {
        let mut ch: Vec<(&str, Vec<f32>)> = ["R", "G", "B"].map(|n| (n, rgb.clone())).into();
        if let Some(v) = var {
            ch.extend(["variance.R", "variance.G", "variance.B"].map(|n| (n, v.clone())));
        }
        image(rgb.len() as u32, 1, &ch)
    }

    #[test]
    fn identical_images_have_zero_error_and_pass() {
        let img = grey(vec![0.1, 0.5, 2.0, 0.0], Some(vec![1e-4, 0.0, 1e-3, 0.0]));
        let c = compare(&img, &img).unwrap();
        assert_eq!((c.rmse, c.rel_mse, c.mae), (0.0, 0.0, 0.0));
        assert_eq!(c.psnr, f64::INFINITY);
        assert_eq!(c.flip, 0.0);
        assert_eq!(c.peak, 2.0);
        let z = c.ztest.as_ref().unwrap();
        assert_eq!((z.failed_pixels, z.pixels, z.tested_channels), (0, 4, 6));
        assert_eq!((z.max_abs_z, z.pass_fraction), (0.0, 1.0));
        assert!(z.passed && c.passed && c.ztest_skipped.is_none());
        assert_eq!(z.test_variance, TestVariance::Own);
        assert_eq!(c.error_map, vec![0.0; 4]);
    }

    #[test]
    fn metrics_of_a_hand_computed_example() {
        // Two pixels; only R differs: pixel 0 by +0.1 (r = 1), pixel 1 by −0.2 (r = 0.5).
        let r = image(
            2,
            1,
            &[
                ("R", vec![1.0, 0.5]),
                ("G", vec![0.0; 2]),
                ("B", vec![0.0; 2]),
            ],
        );
        let t = image(
            2,
            1,
            &[
                ("R", vec![1.1, 0.3]),
                ("G", vec![0.0; 2]),
                ("B", vec![0.0; 2]),
            ],
        );
        let c = compare(&t, &r).unwrap();
        // MSE = (0.1² + 0.2²)/6, MAE = 0.3/6, relMSE = (0.01/1.01 + 0.04/0.26)/6, peak 1.
        assert!((c.rmse - (0.05f64 / 6.0).sqrt()).abs() < 1e-7, "{}", c.rmse);
        assert!((c.mae - 0.05).abs() < 1e-7, "{}", c.mae);
        assert!((c.rel_mse - 0.027_291_190).abs() < 1e-7, "{}", c.rel_mse);
        assert!((c.psnr - 20.791_812).abs() < 1e-5, "{}", c.psnr);
        // relMSE 2.7e-2 > 1e-3, and no variance: the z-test is skipped.
        assert!(c.ztest.is_none() && c.ztest_skipped.unwrap().contains("variance"));
        assert!(!c.passed);
        // Error map: mean over channels of |t − r| / (|r| + 0.01).
        assert!((c.error_map[0] - 0.1 / 1.01 / 3.0).abs() < 1e-6);
        assert!((c.error_map[1] - 0.2 / 0.51 / 3.0).abs() < 1e-6);
        assert_eq!(c.error_scale, REL_ERROR_SCALE);
    }

    #[test]
    fn test_variance_is_scaled_by_sample_counts() {
        // Reference: 4× the test's samples, variance 1e-4 ⇒ the test's is 4e-4, σ² sum 5e-4.
        let mut r = grey(vec![1.0; 3], Some(vec![1e-4; 3]));
        r.channels.push(Channel::new("samples.Y", vec![256.0; 3]));
        let mut t = grey(vec![1.0, 1.0 + 0.05, 1.0 - 0.2], None);
        t.attributes.push(("lapidary.spp".into(), "64".into()));
        let c = compare(&t, &r).unwrap();
        let z = c.ztest.as_ref().unwrap();
        assert_eq!(z.test_variance, TestVariance::ScaledFromReference);
        let sigma = 5e-4f64.sqrt();
        let want = (f64::from(1.0f32 - 0.2) - 1.0).abs() / sigma;
        assert!((z.max_abs_z - want).abs() < 1e-6, "{}", z.max_abs_z);
        assert!((f64::from(c.error_map[1]) - 0.05 / sigma).abs() < 1e-3);
        // |z| ≈ 8.9 fails, ≈ 2.2 passes: one pixel of three fails.
        assert_eq!(z.failed_pixels, 1);
        assert!(!c.passed);
        // Without the test's sample count the test cannot be scaled: skipped, said why.
        t.attributes.clear();
        let c = compare(&t, &r).unwrap();
        assert!(c.ztest.is_none());
        assert!(c.ztest_skipped.unwrap().contains("sample counts"));
    }

    #[test]
    fn non_finite_and_zero_variance_pixels() {
        let r = grey(vec![1.0, 1.0, 1.0, 1.0], Some(vec![0.0, 0.0, 1e-4, 1e-4]));
        let t = grey(
            vec![1.0, 1.0 + 1e-3, f32::NAN, 1.0],
            Some(vec![0.0, 0.0, 1e-4, 1e-4]),
        );
        let c = compare(&t, &r).unwrap();
        assert_eq!(c.non_finite_pixels, 1);
        let z = c.ztest.as_ref().unwrap();
        // Pixel 0: exact match; 1: zero variance but differs; 2: NaN; 3: tested, z = 0.
        assert_eq!((z.failed_pixels, z.tested_channels), (2, 3));
        assert_eq!(c.error_map[0], 0.0);
        assert_eq!(&c.error_map[1..3], &[f32::INFINITY; 2]);
        assert!(!c.passed && c.rmse.is_finite());
        // Infinite values in the reference fail too, and never panic without variance.
        let r = grey(vec![f32::INFINITY, 1.0], None);
        let c = compare(&grey(vec![1.0, 1.0], None), &r).unwrap();
        assert_eq!((c.non_finite_pixels, c.rmse), (1, 0.0));
        assert!(!c.passed);
    }

    #[test]
    fn unusable_inputs_are_errors() {
        let a = grey(vec![1.0; 2], None);
        let b = grey(vec![1.0; 3], None);
        let e = compare(&a, &b).unwrap_err();
        assert!(matches!(e, CompareError::SizeMismatch { .. }), "{e}");
        let no_b = image(2, 1, &[("R", vec![0.0; 2]), ("G", vec![0.0; 2])]);
        let e = compare(&a, &no_b).unwrap_err();
        assert_eq!(e.role(), Some(Role::Reference));
        assert!(e.to_string().contains("`B` (it has: R, G)"), "{e}");
        let short = image(2, 1, &[("R", vec![0.0]), ("G", vec![0.0; 2])]);
        let e = compare(&short, &a).unwrap_err();
        assert!(
            e.to_string()
                .contains("test image has no usable channel `R`")
        );
        let empty = image(0, 0, &[]);
        assert!(matches!(compare(&empty, &empty), Err(CompareError::Empty)));
        // A luminance-only image is grey.
        let y = image(2, 1, &[("Y", vec![1.0; 2]), ("A", vec![0.0; 2])]);
        assert_eq!(compare(&y, &a).unwrap().rmse, 0.0);
    }

    #[test]
    fn bad_variance_anywhere_is_unusable_input() {
        let good = grey(vec![1.0; 4], Some(vec![1e-4; 4]));
        for bad in [f32::NAN, f32::INFINITY, -1e-6] {
            let img = grey(vec![1.0; 4], Some(vec![1e-4, 1e-4, bad, bad]));
            let e = compare(&img, &good).unwrap_err();
            assert_eq!(e.role(), Some(Role::Test));
            let msg = e.to_string();
            assert!(
                msg.contains("`variance.R` is") && msg.contains("at pixel (2, 0)"),
                "{msg}"
            );
            assert!(msg.contains("finite and ≥ 0 (2 such values"), "{msg}");
            let e = compare(&good, &img).unwrap_err();
            assert_eq!(e.role(), Some(Role::Reference));
            // Even identical images: the variance cannot be trusted.
            assert!(matches!(
                compare(&img, &img),
                Err(CompareError::BadVariance { .. })
            ));
        }
        let y = image(
            2,
            1,
            &[("Y", vec![1.0; 2]), ("variance.Y", vec![0.0, -1.0])],
        );
        let e = compare(&y, &good_y()).unwrap_err();
        assert!(
            e.to_string().contains("`variance.Y` is -1 at pixel (1, 0)"),
            "{e}"
        );
    }

    fn good_y() -> ExrImage {
        image(2, 1, &[("Y", vec![1.0; 2]), ("variance.Y", vec![1e-4; 2])])
    }

    #[test]
    fn a_shift_below_the_pixel_noise_fails_the_aggregate_test() {
        // 64 × 64, σ = 0.1 per pixel in both images: a +0.05 shift is z ≈ 0.35 per pixel (the
        // pixel test passes) but √4096 · 0.35 ≈ 22.6 over the whole image.
        let n = 64 * 64;
        let var = vec![0.01f32; n];
        let ch = |v: f32| -> ExrImage {
            let mut img = grey(vec![v; n], Some(var.clone()));
            img.width = 64;
            img.height = 64;
            img
        };
        let (r, t) = (ch(1.0), ch(1.05));
        let c = compare(&t, &r).unwrap();
        let z = c.ztest.as_ref().unwrap();
        assert!(z.pixels_passed && z.failed_pixels == 0, "{z:?}");
        let labels: Vec<String> = z.scales.iter().map(|s| s.label()).collect();
        assert_eq!(labels, ["image", "32x32", "16x16", "8x8"]);
        let whole = &z.scales[0];
        let want = f64::from(1.05f32 - 1.0) / 0.02f64.sqrt() * 64.0;
        assert!((whole.max_abs_z - want).abs() < 1e-3, "{}", whole.max_abs_z);
        // 5.7 over a 16² tile fails too; 2.8 over an 8² tile does not.
        let failed: Vec<String> = z.failed_scales().map(|s| s.label()).collect();
        assert_eq!(failed, ["image", "32x32", "16x16"]);
        assert!(!z.passed && !c.passed);
        // The same images unshifted pass at every scale.
        let c = compare(&r, &ch(1.0)).unwrap();
        assert!(c.passed && c.ztest.unwrap().scales.iter().all(|s| s.max_abs_z == 0.0));
    }

    #[test]
    fn without_variance_the_mean_ratio_is_part_of_the_verdict() {
        // A 1 % brighter image: relMSE ≈ 1e-4 passes, the mean ratio 1.01 does not.
        let r = grey(vec![1.0, 0.5, 2.0, 0.25], None);
        let t = grey(vec![1.01, 0.505, 2.02, 0.2525], None);
        let c = compare(&t, &r).unwrap();
        assert!(c.ztest.is_none() && c.rel_mse < REL_MSE_THRESHOLD);
        assert!((c.mean_ratio.ratio[1] - 1.01).abs() < 1e-6);
        assert_eq!(c.mean_ratio.tolerance, MEAN_TOLERANCE);
        assert!(!c.mean_ratio.passed && !c.passed);
        let loose = Options {
            mean_tolerance: 0.02,
        };
        assert!(compare_with(&t, &r, &loose).unwrap().passed);
        for bad in [-0.1, 1.5, f64::NAN] {
            let e = compare_with(
                &t,
                &r,
                &Options {
                    mean_tolerance: bad,
                },
            )
            .unwrap_err();
            assert!(matches!(e, CompareError::BadTolerance(_)), "{e}");
        }
        // With the z-tests run, the mean ratio is reported but not part of the verdict.
        let r = grey(vec![1.0; 4], Some(vec![1.0; 4]));
        let t = grey(vec![1.01; 4], Some(vec![1.0; 4]));
        let c = compare(&t, &r).unwrap();
        assert!(!c.mean_ratio.passed && c.passed);
    }
}
