//! Error metrics (RMSE, relMSE, MAE, PSNR), the per-channel mean ratio and the relative-error
//! map, over the pixels where both images are finite.

use super::planes::Planes;
use super::{MeanRatio, REL_ERROR_OFFSET, REL_MSE_EPSILON};

/// The scalar error metrics of a comparison.
pub(super) struct Metrics {
    /// Root-mean-square error (radiance).
    pub rmse: f64,
    /// Mean of `(t − r)²/(r² + ε)`.
    pub rel_mse: f64,
    /// Mean absolute error (radiance).
    pub mae: f64,
    /// `10 log₁₀(peak²/MSE)` in dB.
    pub psnr: f64,
    /// PSNR's peak: the reference's largest finite channel value, 1 if not positive.
    pub peak: f64,
}

/// The metrics over the R, G, B of the `finite` pixels.
pub(super) fn metrics(t: &Planes, r: &Planes, finite: &[bool]) -> Metrics {
    let (mut se, mut rel, mut ae, mut peak, mut count) = (0.0, 0.0, 0.0, f64::MIN, 0usize);
    for i in (0..finite.len()).filter(|&i| finite[i]) {
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
    Metrics {
        rmse: mse.sqrt(),
        rel_mse,
        mae,
        psnr,
        peak,
    }
}

/// Each channel's mean over the `finite` pixels of both images, their ratio, and whether every
/// ratio is within `1 ± tolerance` (`0/0` counts as 1, `x/0` as ±∞).
pub(super) fn mean_ratio(t: &Planes, r: &Planes, finite: &[bool], tolerance: f64) -> MeanRatio {
    let n = finite.iter().filter(|&&f| f).count().max(1) as f64;
    let mean = |p: &Planes, c: usize| -> f64 {
        (0..finite.len())
            .filter(|&i| finite[i])
            .map(|i| f64::from(p.rgb[c][i]))
            .sum::<f64>()
            / n
    };
    let test: [f64; 3] = std::array::from_fn(|c| mean(t, c));
    let reference: [f64; 3] = std::array::from_fn(|c| mean(r, c));
    let ratio: [f64; 3] = std::array::from_fn(|c| {
        if test[c] == reference[c] {
            1.0
        } else {
            test[c] / reference[c]
        }
    });
    MeanRatio {
        test,
        reference,
        ratio,
        tolerance,
        passed: ratio.iter().all(|q| (q - 1.0).abs() <= tolerance),
    }
}

/// Per pixel, the mean over channels of `|t − r|/(|r| + 10⁻²)`; +∞ where a value is not finite.
pub(super) fn relative_error_map(t: &Planes, r: &Planes, finite: &[bool]) -> Vec<f32> {
    (0..finite.len())
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
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn planes(rgb: &[Vec<f32>; 3]) -> Planes<'_> {
        Planes {
            rgb: [&rgb[0], &rgb[1], &rgb[2]],
            variance: None,
            samples: None,
            material: None,
        }
    }

    #[test]
    fn mean_ratio_per_channel_against_the_tolerance() {
        let r = [vec![1.0, 3.0], vec![0.0, 0.0], vec![2.0, 2.0]];
        let t = [vec![1.02, 3.02], vec![0.0, 0.0], vec![2.0, 1.98]];
        let finite = [true, true];
        let m = mean_ratio(&planes(&t), &planes(&r), &finite, 0.005);
        assert!((m.ratio[0] - 1.01).abs() < 1e-6, "{:?}", m.ratio);
        assert_eq!(m.ratio[1], 1.0); // 0/0
        assert!((m.ratio[2] - 0.995).abs() < 1e-6);
        assert!((m.reference[0] - 2.0).abs() < 1e-12 && (m.test[2] - 1.99).abs() < 1e-6);
        assert!(!m.passed);
        assert!(mean_ratio(&planes(&t), &planes(&r), &finite, 0.011).passed);
        // Non-finite pixels are left out; a mean against a zero reference is infinitely off.
        let t = [vec![1.0, f32::NAN], vec![1e-3, 0.0], vec![2.0, 2.0]];
        let m = mean_ratio(&planes(&t), &planes(&r), &[true, false], 1.0);
        assert_eq!((m.ratio[0], m.ratio[1]), (1.0, f64::INFINITY));
        assert!(!m.passed);
    }
}
