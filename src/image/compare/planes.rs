//! The channels a comparison reads from each image, checked, and the per-pixel differences and
//! variances that the pixel test and the tile tests share.

use super::{CompareError, Role, TestVariance};
use crate::image::ExrImage;

/// An image's colour (and matching variance) channels.
pub(super) struct Planes<'a> {
    /// `R`, `G`, `B` (or `Y` three times).
    pub rgb: [&'a [f32]; 3],
    /// `variance.R/G/B` (or `variance.Y` three times): variance of each pixel's mean.
    pub variance: Option<[&'a [f32]; 3]>,
    /// Samples per pixel, if known.
    pub samples: Option<Samples<'a>>,
    /// `material.Y`, if present.
    pub material: Option<&'a [f32]>,
}

/// An image's sample counts.
pub(super) enum Samples<'a> {
    /// `samples.Y`.
    PerPixel(&'a [f32]),
    /// The `lapidary.spp` attribute.
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

/// Reads `img`'s channels; a variance channel with a NaN, infinite or negative value is an error.
pub(super) fn planes(img: &ExrImage, which: Role) -> Result<Planes<'_>, CompareError> {
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
    let names = ["variance.R", "variance.G", "variance.B"];
    let (variance, used): (_, &[&str]) = match names.map(get) {
        [Some(r), Some(g), Some(b)] => (Some([r, g, b]), &names),
        _ => match get("variance.Y") {
            Some(y) => (Some([y; 3]), &["variance.Y"]),
            None => (None, &[]),
        },
    };
    for name in used {
        check_variance(img, which, name, get(name).unwrap_or_default())?;
    }
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
        material: get("material.Y"),
    })
}

/// A variance channel must be finite and non-negative everywhere.
fn check_variance(
    img: &ExrImage,
    which: Role,
    channel: &str,
    data: &[f32],
) -> Result<(), CompareError> {
    let bad = |v: &f32| !(*v >= 0.0 && v.is_finite());
    let Some(first) = data.iter().position(bad) else {
        return Ok(());
    };
    let w = img.width.max(1) as usize;
    Err(CompareError::BadVariance {
        which,
        channel: channel.into(),
        x: (first % w) as u32,
        y: (first / w) as u32,
        value: data[first],
        count: data.iter().filter(|v| bad(v)).count(),
    })
}

/// One pixel as the z-tests see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Pixel {
    /// Finite values: per channel `t − r` and `var_t + var_r` (radiance, radiance²).
    Usable {
        /// `t − r` per channel.
        diff: [f64; 3],
        /// `var_t + var_r` per channel (0 where both images have no variance).
        var: [f64; 3],
        /// The channels with zero variance in both images where `t` and `r` differ by more
        /// than `10⁻⁶ · max(1, |r|)`.
        exact_mismatch: bool,
    },
    /// NaN or infinite values, or sample counts that cannot scale the variance: a failure.
    Failed,
}

/// The pixels of `t` against `r`, and where the test's variance came from; an error message
/// when the z-tests cannot run (no reference variance, or no way to get the test's).
pub(super) fn pixels(
    t: &Planes,
    r: &Planes,
    finite: &[bool],
) -> Result<(Vec<Pixel>, TestVariance), String> {
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
    let px = (0..finite.len())
        .map(|i| {
            if !finite[i] {
                return Pixel::Failed;
            }
            // The test's variance: its own, or the reference's times n_ref / n_test.
            let ratio = match var_t {
                Ok(_) => 1.0,
                Err((nt, nr)) => {
                    let (nt, nr) = (nt.at(i), nr.at(i));
                    if !(nt > 0.0 && nr > 0.0 && nt.is_finite() && nr.is_finite()) {
                        return Pixel::Failed;
                    }
                    nr / nt
                }
            };
            let (mut diff, mut var, mut exact_mismatch) = ([0.0; 3], [0.0; 3], false);
            for c in 0..3 {
                let vr = f64::from(var_r[c][i]);
                let vt = match var_t {
                    Ok(v) => f64::from(v[c][i]),
                    Err(_) => vr * ratio,
                };
                if !(vt + vr).is_finite() {
                    return Pixel::Failed;
                }
                let (tv, rv) = (f64::from(t.rgb[c][i]), f64::from(r.rgb[c][i]));
                diff[c] = tv - rv;
                var[c] = vt + vr;
                if var[c] == 0.0 && diff[c].abs() > 1e-6 * rv.abs().max(1.0) {
                    exact_mismatch = true;
                }
            }
            Pixel::Usable {
                diff,
                var,
                exact_mismatch,
            }
        })
        .collect();
    let source = match var_t {
        Ok(_) => TestVariance::Own,
        Err(_) => TestVariance::ScaledFromReference,
    };
    Ok((px, source))
}
