//! Comparing a test render with a reference render (DESIGN §8): error metrics, a per-pixel
//! z-test, a verdict, and a false-colour error map.
//!
//! **Metrics** are taken over the `R`, `G`, `B` values of every pixel where both images are
//! finite (a `Y`-only image counts as grey in all three): RMSE, relative MSE
//! `mean((t − r)² / (r² + ε))` with [`REL_MSE_EPSILON`] `ε = 10⁻²`, MAE, and PSNR
//! `10 log₁₀(peak² / MSE)` with `peak` the reference's largest channel value (1 if that is not
//! positive); PSNR is `+∞` when the images agree exactly. All are in the images' own unit
//! (radiance), squared for the MSEs; relMSE is dimensionless.
//!
//! **The z-test** follows the practice of Mitsuba's render regression tests: each pixel channel
//! gives `z = (t − r) / √(var_t + var_r)`, where `var_r` is the reference's `variance.R/G/B`
//! (variance of the pixel's mean) and `var_t` the test's own, or — if the test has none —
//! `var_r · n_ref / n_test` from the sample counts (`samples.Y` per pixel, else the
//! `lapidary.spp` attribute), which assumes both renders have the same per-sample variance.
//! With `N` pixel channels tested at family-wise significance α = 0.01, each is tested at
//! Šidák's `α_i = 1 − (1 − α)^(1/N)` (Z. Šidák, "Rectangular confidence regions for the means
//! of multivariate normal distributions", JASA 1967), i.e. against the two-sided normal
//! quantile `z_crit`. A pixel passes when all its channels do; where both variances are 0 it
//! passes iff `|t − r| ≤ 10⁻⁶ · max(1, |r|)`. A pixel with a NaN or infinite value, or an unusable
//! variance or sample count, fails. The image passes when at least 99.75 % of its pixels pass.
//!
//! **The verdict** is the z-test's when it ran; otherwise (no reference variance) the image
//! passes iff relMSE ≤ [`REL_MSE_THRESHOLD`] and no pixel is non-finite.

use super::stats::{normal_quantile_two_sided, sidak};
use super::{ExrImage, ImageError};

/// `ε` in relMSE's denominator `r² + ε` (radiance²), so that black pixels do not dominate.
pub const REL_MSE_EPSILON: f64 = 1e-2;
/// Largest relMSE that passes when the z-test cannot run.
pub const REL_MSE_THRESHOLD: f64 = 1e-3;
/// Family-wise significance of the z-test (before the Šidák split over pixel channels).
pub const Z_ALPHA: f64 = 0.01;
/// Fraction of pixels that must pass the z-test for the image to pass.
pub const Z_REQUIRED_FRACTION: f64 = 0.9975;
/// The offset in the relative error `|t − r| / (|r| + offset)` of the error map (radiance).
pub const REL_ERROR_OFFSET: f64 = 1e-2;
/// Relative error drawn at the top of the heatmap's colour scale when the z-test did not run.
pub const REL_ERROR_SCALE: f32 = 0.1;

/// Which of the two images something refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The image under test.
    Test,
    /// The reference image.
    Reference,
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Role::Test => "test",
            Role::Reference => "reference",
        })
    }
}

/// Why two images cannot be compared ("unusable input").
#[derive(thiserror::Error, Debug)]
pub enum CompareError {
    /// The images differ in size.
    #[error("sizes differ: test is {}x{}, reference is {}x{}", .test.0, .test.1, .reference.0, .reference.1)]
    SizeMismatch {
        /// Test image width and height in pixels.
        test: (u32, u32),
        /// Reference image width and height in pixels.
        reference: (u32, u32),
    },
    /// A colour channel is missing (or does not hold one value per pixel).
    #[error("the {which} image has no usable channel `{channel}` (it has: {})", list(.found))]
    MissingChannel {
        /// The image lacking the channel.
        which: Role,
        /// The channel looked for.
        channel: String,
        /// The channels the image does have.
        found: Vec<String>,
    },
    /// The images have no pixels.
    #[error("the images are empty (0 pixels)")]
    Empty,
    /// An image could not be read.
    #[error(transparent)]
    Image(#[from] ImageError),
}

impl CompareError {
    /// The image the error is about, if it is about one of them.
    pub fn role(&self) -> Option<Role> {
        match self {
            CompareError::MissingChannel { which, .. } => Some(*which),
            _ => None,
        }
    }
}

fn list(names: &[String]) -> String {
    if names.is_empty() {
        "no channels".into()
    } else {
        names.join(", ")
    }
}

/// Where the test image's variance came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestVariance {
    /// The test image's own `variance.*` channels.
    Own,
    /// The reference's variance scaled by `n_ref / n_test` (same per-sample variance assumed).
    ScaledFromReference,
}

/// The outcome of the per-pixel z-test.
#[derive(Clone, Debug, PartialEq)]
pub struct ZTest {
    /// Family-wise significance ([`Z_ALPHA`], 0.01).
    pub alpha: f64,
    /// Critical |z| of each pixel channel after the Šidák correction (two-sided).
    pub z_crit: f64,
    /// Pixels in the image.
    pub pixels: usize,
    /// Pixels that failed (a channel beyond `z_crit`, non-finite values, unusable variance).
    pub failed_pixels: usize,
    /// Fraction of the pixels that passed, in `[0, 1]`.
    pub pass_fraction: f64,
    /// Fraction required to pass ([`Z_REQUIRED_FRACTION`], 0.9975).
    pub required_fraction: f64,
    /// Largest |z| over all tested pixel channels (0 if none).
    pub max_abs_z: f64,
    /// Pixel channels tested with a z-score (the `N` of the Šidák correction).
    pub tested_channels: usize,
    /// Where the test's variance came from.
    pub test_variance: TestVariance,
    /// Whether `pass_fraction ≥ required_fraction`.
    pub passed: bool,
}

/// Everything [`compare`] finds.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Root-mean-square error over R, G, B of the finite pixels (radiance).
    pub rmse: f64,
    /// Mean of `(t − r)² / (r² + ε)`, ε = [`REL_MSE_EPSILON`] (dimensionless).
    pub rel_mse: f64,
    /// Mean absolute error (radiance).
    pub mae: f64,
    /// `10 log₁₀(peak² / MSE)` in dB, peak = the reference's largest channel value; `+∞` if equal.
    pub psnr: f64,
    /// The reference's largest finite channel value used as PSNR's peak (1 if not positive).
    pub peak: f64,
    /// Mean HDR-FLIP error in [0, 1] at 67 pixels per degree ([`super::flip::hdr_flip`];
    /// Andersson et al. 2020, 2021): a perceptual difference, reported, not part of the verdict.
    pub flip: f64,
    /// Pixels with a NaN or infinite R, G or B in either image (always failures).
    pub non_finite_pixels: usize,
    /// The z-test, `None` when it could not run (see `ztest_skipped`).
    pub ztest: Option<ZTest>,
    /// Why the z-test did not run.
    pub ztest_skipped: Option<String>,
    /// Per-pixel error, row-major: the largest |z| over the pixel's channels when the z-test ran
    /// (0 or +∞ for zero-variance pixels by their exact check), else the mean over channels of
    /// `|t − r| / (|r| + 10⁻²)`; +∞ for failed non-finite pixels.
    pub error_map: Vec<f32>,
    /// The error drawn at the top of the heatmap's scale: `z_crit`, or [`REL_ERROR_SCALE`].
    pub error_scale: f32,
    /// The verdict: the z-test's if it ran, else relMSE ≤ [`REL_MSE_THRESHOLD`] and no
    /// non-finite pixel.
    pub passed: bool,
}

/// An image's colour (and matching variance) channels.
struct Planes<'a> {
    rgb: [&'a [f32]; 3],
    variance: Option<[&'a [f32]; 3]>,
    samples: Option<Samples<'a>>,
}

/// An image's sample counts.
enum Samples<'a> {
    PerPixel(&'a [f32]),
    Uniform(f64),
}

impl Samples<'_> {
    fn at(&self, i: usize) -> f64 {
        match self {
            Samples::PerPixel(s) => f64::from(s[i]),
            Samples::Uniform(n) => *n,
        }
    }
}

fn planes(img: &ExrImage, which: Role) -> Result<Planes<'_>, CompareError> {
    let n = img.width as usize * img.height as usize;
    let get = |name: &str| img.channel(name).filter(|d| d.len() == n);
    let rgb = match (get("R"), get("G"), get("B"), get("Y")) {
        (Some(r), Some(g), Some(b), _) => [r, g, b],
        (_, _, _, Some(y)) => [y; 3],
        (r, g, _, _) => {
            let channel = if r.is_none() {
                "R"
            } else if g.is_none() {
                "G"
            } else {
                "B"
            };
            return Err(CompareError::MissingChannel {
                which,
                channel: channel.into(),
                found: img.channel_names().iter().map(|s| s.to_string()).collect(),
            });
        }
    };
    let variance = match (get("variance.R"), get("variance.G"), get("variance.B")) {
        (Some(r), Some(g), Some(b)) => Some([r, g, b]),
        _ => get("variance.Y").map(|y| [y; 3]),
    };
    let samples = match get("samples.Y") {
        Some(s) => Some(Samples::PerPixel(s)),
        None => img
            .attribute("lapidary.spp")
            .and_then(|s| s.trim().parse::<f64>().ok())
            .filter(|&n| n > 0.0 && n.is_finite())
            .map(Samples::Uniform),
    };
    Ok(Planes {
        rgb,
        variance,
        samples,
    })
}

/// A pixel's z-test outcome before `z_crit` is known.
#[derive(Clone, Copy)]
enum PixelZ {
    /// Largest |z| over the tested channels, and whether the zero-variance channels matched.
    Tested { max_z: f64, exact_ok: bool },
    /// Non-finite values or unusable variance / sample counts.
    Failed,
}

/// Compares `test` against `reference`: metrics, z-test (when the reference has variance), error
/// map and verdict, as described in the [module documentation](self).
pub fn compare(test: &ExrImage, reference: &ExrImage) -> Result<Comparison, CompareError> {
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

    // Metrics over the finite pixels.
    let (mut se, mut rel, mut ae, mut peak, mut count) = (0.0, 0.0, 0.0, f64::MIN, 0usize);
    for i in (0..n).filter(|&i| finite[i]) {
        for c in 0..3 {
            let (tv, rv) = (f64::from(t.rgb[c][i]), f64::from(r.rgb[c][i]));
            let d = tv - rv;
            se += d * d;
            rel += d * d / (rv * rv + REL_MSE_EPSILON);
            ae += d.abs();
            peak = peak.max(rv);
            count += 1;
        }
    }
    let peak = if peak > 0.0 { peak } else { 1.0 };
    let (mse, rel_mse, mae) = if count == 0 {
        (f64::NAN, f64::NAN, f64::NAN)
    } else {
        let k = count as f64;
        (se / k, rel / k, ae / k)
    };
    let psnr = if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (peak * peak / mse).log10()
    };

    let (ztest, ztest_skipped, error_map, error_scale) = match z_test(&t, &r, &finite) {
        Ok((z, map)) => (Some(z.clone()), None, map, z.z_crit as f32),
        Err(why) => {
            let map = (0..n)
                .map(|i| {
                    if !finite[i] {
                        return f32::INFINITY;
                    }
                    let e: f64 = (0..3)
                        .map(|c| {
                            let (tv, rv) = (f64::from(t.rgb[c][i]), f64::from(r.rgb[c][i]));
                            (tv - rv).abs() / (rv.abs() + REL_ERROR_OFFSET)
                        })
                        .sum();
                    (e / 3.0) as f32
                })
                .collect();
            (None, Some(why), map, REL_ERROR_SCALE)
        }
    };
    let passed = match &ztest {
        Some(z) => z.passed,
        None => rel_mse <= REL_MSE_THRESHOLD && non_finite_pixels == 0,
    };
    let rgb = |p: &Planes| -> Vec<[f32; 3]> {
        (0..n)
            .map(|i| [p.rgb[0][i], p.rgb[1][i], p.rgb[2][i]])
            .collect()
    };
    let flip = f64::from(
        super::flip::hdr_flip(
            &rgb(&t),
            &rgb(&r),
            test.width,
            test.height,
            super::flip::DEFAULT_PPD,
        )
        .flip
        .mean,
    );
    Ok(Comparison {
        width: test.width,
        height: test.height,
        rmse: mse.sqrt(),
        rel_mse,
        mae,
        psnr,
        peak,
        flip,
        non_finite_pixels,
        ztest,
        ztest_skipped,
        error_map,
        error_scale,
        passed,
    })
}

/// The per-pixel z-test and its error map (max |z| per pixel), or why it cannot run.
fn z_test(t: &Planes, r: &Planes, finite: &[bool]) -> Result<(ZTest, Vec<f32>), String> {
    let var_r = r
        .variance
        .ok_or("the reference has no variance.R/G/B channels")?;
    let var_t = match (t.variance, &t.samples, &r.samples) {
        (Some(v), _, _) => Ok(v),
        (None, Some(nt), Some(nr)) => Err((nt, nr)),
        (None, _, _) => {
            return Err("the test has no variance channels and the sample counts \
                        (samples.Y or lapidary.spp) of both images are not known"
                .into());
        }
    };
    let n = finite.len();
    let mut tested = 0usize;
    let per_pixel: Vec<PixelZ> = (0..n)
        .map(|i| {
            if !finite[i] {
                return PixelZ::Failed;
            }
            // The test's variance: its own, or the reference's times n_ref / n_test.
            let ratio = match var_t {
                Ok(_) => 1.0,
                Err((nt, nr)) => {
                    let (nt, nr) = (nt.at(i), nr.at(i));
                    if !(nt > 0.0 && nr > 0.0 && nt.is_finite() && nr.is_finite()) {
                        return PixelZ::Failed;
                    }
                    nr / nt
                }
            };
            let (mut max_z, mut exact_ok) = (0.0f64, true);
            for c in 0..3 {
                let vr = f64::from(var_r[c][i]);
                let vt = match var_t {
                    Ok(v) => f64::from(v[c][i]),
                    Err(_) => vr * ratio,
                };
                if !(vr >= 0.0 && vt >= 0.0 && vr.is_finite() && vt.is_finite()) {
                    return PixelZ::Failed;
                }
                let (tv, rv) = (f64::from(t.rgb[c][i]), f64::from(r.rgb[c][i]));
                let var = vt + vr;
                if var > 0.0 {
                    max_z = max_z.max((tv - rv).abs() / var.sqrt());
                    tested += 1;
                } else if (tv - rv).abs() > 1e-6 * rv.abs().max(1.0) {
                    exact_ok = false;
                }
            }
            PixelZ::Tested { max_z, exact_ok }
        })
        .collect();
    let z_crit = normal_quantile_two_sided(sidak(Z_ALPHA, tested));
    let mut failed = 0usize;
    let mut max_abs_z = 0.0f64;
    let map = per_pixel
        .iter()
        .map(|p| match *p {
            PixelZ::Tested { max_z, exact_ok } => {
                max_abs_z = max_abs_z.max(max_z);
                if !exact_ok || max_z > z_crit {
                    failed += 1;
                }
                if exact_ok {
                    max_z as f32
                } else {
                    f32::INFINITY
                }
            }
            PixelZ::Failed => {
                failed += 1;
                f32::INFINITY
            }
        })
        .collect();
    let pass_fraction = (n - failed) as f64 / n as f64;
    let z = ZTest {
        alpha: Z_ALPHA,
        z_crit,
        pixels: n,
        failed_pixels: failed,
        pass_fraction,
        required_fraction: Z_REQUIRED_FRACTION,
        max_abs_z,
        tested_channels: tested,
        test_variance: match var_t {
            Ok(_) => TestVariance::Own,
            Err(_) => TestVariance::ScaledFromReference,
        },
        passed: pass_fraction >= Z_REQUIRED_FRACTION,
    };
    Ok((z, map))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Channel;

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
}
