//! Measured spectra a recipe gives as `(wavelength nm, value)` points (issue 19): projected once
//! onto a fixed 10 nm grid over 360–830 nm, read by linear interpolation at a path's wavelengths,
//! and projected to a linear Rec.709 triple for RGB renders.
//!
//! **Resampling.** The points define a piecewise-linear function `f` (constant beyond the first
//! and last point). [`Measured::at`] reads the grid back as `g(λ) = Σⱼ vⱼ φⱼ(λ)`, where `φⱼ` is the
//! hat (tent) function of grid node `λⱼ` (1 at `λⱼ`, falling linearly to 0 at the neighbouring
//! nodes; only its inner half at 360 and 830 nm). Each grid value is `f` averaged with that node's
//! own hat as the weight,
//!
//! `vⱼ = ∫ f φⱼ dλ / ∫ φⱼ dλ` over 360–830 nm (`∫ φⱼ` = 10 nm inside, 5 nm at the two ends),
//!
//! integrated exactly: on each interval between `f`'s points and the hat's corners the integrand
//! is a quadratic, which Simpson's rule integrates without error; the sums are in `f64`.
//!
//! *Why the hat.* The hats sum to 1 everywhere on 360–830 nm, so `∫ g = Σ vⱼ ∫ φⱼ = ∫ f Σ φⱼ =
//! ∫ f`: the reconstruction keeps the spectrum's area over the range *exactly*, for a line of any
//! width wherever it falls (0.2 nm at 555.0 nm or at the range's ends: tested to 1e-4). A box mean
//! over each node's 10 nm cell keeps the area only inside: at 360 and 830 nm the reconstruction
//! weighs the end values by 5 nm while the box mean sums 10 nm of `f` (half of it outside the
//! range, or a constant continuation). Boxes clipped to the range (5 nm cells at the ends) would
//! keep the area too, and smooth less (rms width 2.9 nm against the hat's 4.1 nm), but a line's
//! share would jump from one node to the next as it crosses a cell boundary, and its luminance
//! with it (by a factor 1.5 between 504.9 and 505.1 nm); with the hats the share moves linearly
//! between the two nodes and the luminance is continuous in the line's position (tested).
//!
//! *Properties.* The grid values are weighted means of `f`, so they stay within `f`'s range on
//! each node's support (a reflectance ≤ 1 stays ≤ 1, nothing turns negative). Where `f` is
//! constant over a node's support its value is that constant bit for bit (the `f64` sum is within
//! a few `f64` ulps of an `f32` value, which rounds back to it): a flat spectrum stays exactly
//! flat. The price: a feature narrower than the grid is spread over ±10 nm, a slope reaching an
//! end reads there as its mean over the end's half hat (`f` 3.3 nm inside the range), and against
//! the ten 1 nm midpoint samples per cell this replaced, grid values of the shipped spectra moved
//! by up to 1.6 % of their maximum (rhodamine 6G's emission band, slightly more smoothed).
//! 48 values (`Copy`, no allocation on the hot path).
//!
//! **RGB.** A coefficient spectrum (absorption, scattering) projects as a reflectance does: the
//! D65-weighted, white-balanced linear sRGB of the spectrum ([`super::rgb2spec::reflectance_to_rgb`]),
//! so a flat spectrum `c` is exactly the grey `c`. Negative channels (a narrow spectrum outside
//! the sRGB gamut) are clamped to 0 for the RGB render, which cannot represent them.

use super::rgb2spec::reflectance_to_rgb;
use super::wavelengths::LAMBDA_MIN;
use crate::color::Rgb;
use std::fmt;

/// Grid spacing, nm.
pub const STEP: f32 = 10.0;
/// Grid values: 360, 370, …, 830 nm.
pub const SAMPLES: usize = 48;
/// Most points a recipe spectrum may have.
pub const MAX_POINTS: usize = 4096;
/// The `max` of [`Measured::from_points`] for a spectrum whose values have no upper bound (an
/// emission shape): any finite value ≥ 0.
pub const UNBOUNDED: f32 = f32::INFINITY;

/// What is wrong with a spectrum's points: the point to blame (its index in the list given), if
/// one is, and what is wrong, without the point's name (so a caller that knows where the point
/// came from — a CSV file's line — can name that instead).
#[derive(Clone, Debug, PartialEq)]
pub struct PointsError {
    /// The offending point's index, `None` when the list as a whole is wrong (its length).
    pub point: Option<usize>,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl fmt::Display for PointsError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self.point {
            Some(i) => write!(f, "spectrum point {i}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

/// The allowed values `0 ..= max`, readable: `max` at or above `f32::MAX` is "any finite value
/// ≥ 0", a large one is written in exponent form.
pub fn value_range(max: f32) -> String {
    if max >= f32::MAX {
        "any finite value ≥ 0".to_string()
    } else if max >= 1e6 {
        format!("0 ..= {max:e}")
    } else {
        format!("0 ..= {max}")
    }
}

/// A spectrum on the 10 nm grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    values: [f32; SAMPLES],
}

/// The piecewise-linear function through `points` at `x`, constant beyond the first and last.
fn eval(points: &[(f64, f64)], x: f64) -> f64 {
    let k = points.partition_point(|p| p.0 <= x);
    if k == 0 {
        points[0].1
    } else if k == points.len() {
        points[k - 1].1
    } else {
        let (a, b) = (points[k - 1], points[k]);
        a.1 + (x - a.0) / (b.0 - a.0) * (b.1 - a.1)
    }
}

/// `∫ f φ / ∫ φ` over the support of the hat `φ` of the grid node at `centre` nm (module docs):
/// Simpson's rule, exact for the quadratic integrand, between consecutive corners of `f` and `φ`.
fn hat_mean(points: &[(f64, f64)], centre: f64) -> f64 {
    let step = f64::from(STEP);
    let lo = f64::from(LAMBDA_MIN);
    let hi = lo + step * (SAMPLES - 1) as f64;
    let (a, b) = ((centre - step).max(lo), (centre + step).min(hi));
    let hat = |x: f64| 1.0 - (x - centre).abs() / step;
    // The corners: the support's ends, `f`'s points inside it and the hat's apex, in order.
    let inner = points.partition_point(|p| p.0 <= a)..points.partition_point(|p| p.0 < b);
    let mut xs: Vec<f64> = Vec::with_capacity(inner.len() + 3);
    xs.push(a);
    xs.extend(points[inner].iter().map(|p| p.0));
    if centre > a && centre < b {
        xs.insert(xs.partition_point(|&x| x < centre), centre);
    }
    xs.push(b);
    let term = |x: f64| eval(points, x) * hat(x);
    let sum: f64 = xs
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| (w[1] - w[0]) / 6.0 * (term(w[0]) + 4.0 * term(0.5 * (w[0] + w[1])) + term(w[1])))
        .sum();
    // ∫ φ: 5 nm per half hat inside the range.
    sum / (0.5 * (b - a))
}

impl Measured {
    /// The spectrum through `points` (`(nm, value)`, wavelengths strictly increasing in
    /// 200 ..= 2000 nm, values finite in `0 ..= max` — `max` = [`UNBOUNDED`]: any finite value —,
    /// 2 ..= [`MAX_POINTS`] points), or what is wrong with them, naming the point by its index.
    pub fn from_points(points: &[(f32, f32)], max: f32) -> Result<Measured, String> {
        Measured::try_from_points(points, max).map_err(|e| e.to_string())
    }

    /// [`Measured::from_points`] with the offending point apart from the message.
    pub fn try_from_points(points: &[(f32, f32)], max: f32) -> Result<Measured, PointsError> {
        if points.len() < 2 || points.len() > MAX_POINTS {
            return Err(PointsError {
                point: None,
                message: format!(
                    "a spectrum has {} points: allowed 2 ..= {MAX_POINTS}",
                    points.len()
                ),
            });
        }
        for (i, &(l, v)) in points.iter().enumerate() {
            let wrong = |message: String| {
                Err(PointsError {
                    point: Some(i),
                    message,
                })
            };
            if !(200.0..=2000.0).contains(&l) {
                return wrong(format!(
                    "wavelength {l} nm is out of range: allowed 200 ..= 2000"
                ));
            }
            if !(v.is_finite() && v >= 0.0 && v <= max) {
                return wrong(format!(
                    "value {v} at {l} nm is out of range: allowed {}",
                    value_range(max)
                ));
            }
            if i > 0 && !(l > points[i - 1].0) {
                return wrong(format!(
                    "wavelength {l} nm does not increase (after {} nm)",
                    points[i - 1].0
                ));
            }
        }
        let points: Vec<(f64, f64)> = points
            .iter()
            .map(|&(l, v)| (f64::from(l), f64::from(v)))
            .collect();
        let values = std::array::from_fn(|i| {
            hat_mean(&points, f64::from(LAMBDA_MIN) + i as f64 * f64::from(STEP)) as f32
        });
        Ok(Measured { values })
    }

    /// `f` applied to every grid value.
    pub fn map(&self, f: impl Fn(f32) -> f32) -> Measured {
        Measured {
            values: self.values.map(f),
        }
    }

    /// The same spectrum times `s` (a unit change).
    pub fn scaled(&self, s: f32) -> Measured {
        Measured {
            values: self.values.map(|v| v * s),
        }
    }

    /// The value at `lambda_nm` (clamped to 360–830 nm), linear between grid values.
    #[inline]
    pub fn at(&self, lambda_nm: f32) -> f32 {
        let x = ((lambda_nm - LAMBDA_MIN) / STEP).clamp(0.0, (SAMPLES - 1) as f32);
        let i = (x as usize).min(SAMPLES - 2);
        let t = x - i as f32;
        self.values[i] + t * (self.values[i + 1] - self.values[i])
    }

    /// The largest grid value.
    pub fn max(&self) -> f32 {
        self.values.iter().copied().fold(0.0, f32::max)
    }

    /// CIE 1931 Y of this spectrum as emitted radiance (`∫ L ȳ / ∫ ȳ`, so a flat 1 has Y = 1).
    pub fn luminance(&self) -> f32 {
        super::cie::spectrum_to_xyz(|l| self.at(l)).y
    }

    /// The linear Rec.709 colour of this spectrum as emitted radiance: its CIE XYZ
    /// (`∫ L (x̄, ȳ, z̄) / ∫ ȳ`) through the sRGB matrix, negative channels clamped to 0 (a
    /// D65-shaped spectrum of luminance `c` is the grey `c`, to 2.4e-4).
    pub fn to_rgb_emission(&self) -> Rgb {
        let xyz = super::cie::spectrum_to_xyz(|l| self.at(l));
        let c = super::cie::xyz_to_linear_srgb(xyz);
        Rgb::new(c.x.max(0.0), c.y.max(0.0), c.z.max(0.0))
    }

    /// This spectrum with a `'static` lifetime, for runtime records that stay `Copy` (a stack's
    /// measured albedo). Equal spectra share one allocation, so memory grows with the number of
    /// distinct spectra a process loads, not with how often they are loaded.
    pub fn intern(self) -> &'static Measured {
        use std::sync::Mutex;
        static INTERNED: Mutex<Vec<&'static Measured>> = Mutex::new(Vec::new());
        let mut list = INTERNED.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(m) = list.iter().find(|m| ***m == self) {
            return m;
        }
        let m: &'static Measured = Box::leak(Box::new(self));
        list.push(m);
        m
    }

    /// The linear Rec.709 triple an RGB render uses for this coefficient spectrum (module docs).
    pub fn to_rgb(&self) -> Rgb {
        if self.values.iter().all(|&v| v == self.values[0]) {
            // Flat: exactly the grey (the projection's white balance leaves 2e-4).
            return Rgb::splat(self.values[0]);
        }
        let c = reflectance_to_rgb(|l| self.at(l));
        Rgb::new(c[0].max(0.0), c[1].max(0.0), c[2].max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_spectra_are_greys_and_lines_are_interpolated() {
        let flat = Measured::from_points(&[(300.0, 0.5), (900.0, 0.5)], 1e4).unwrap();
        assert_eq!(flat.at(555.0), 0.5);
        assert_eq!(flat.to_rgb(), Rgb::splat(0.5));
        // A reddish absorption projects to a triple with red largest.
        let red = Measured::from_points(&[(360.0, 0.1), (560.0, 0.1), (700.0, 2.0)], 1e4).unwrap();
        let c = red.to_rgb();
        assert!(c[0] > c[1] && c[1] >= c[2] && c[2] > 0.0, "{c:?}");
        let ramp = Measured::from_points(&[(360.0, 0.0), (830.0, 4.7)], 1e4).unwrap();
        assert!((ramp.at(595.0) - 2.35).abs() < 1e-4);
        assert!((ramp.scaled(2.0).at(595.0) - 4.7).abs() < 2e-4);
        // Constant beyond the ends, and exact where the spectrum is constant around a node.
        let short = Measured::from_points(&[(500.0, 1.0), (600.0, 3.0)], 1e4).unwrap();
        assert_eq!(short.at(400.0), 1.0);
        assert_eq!(short.at(800.0), 3.0);
        // Flat spectra stay flat bit for bit, however their points are laid out.
        for c in [0.0, 0.1, 1.0 / 3.0, 0.999_999_9, 1.0, 7.3e-30, 1e-40, 1e4] {
            for pts in [
                vec![(360.0, c), (830.0, c)],
                vec![(300.0, c), (555.5, c), (559.9, c), (2000.0, c)],
                vec![(700.0, c), (700.1, c)],
            ] {
                let m = Measured::from_points(&pts, 1e4).unwrap();
                assert!(m.values.iter().all(|&v| v == c), "{pts:?}: {:?}", m.values);
                assert_eq!(m.to_rgb(), Rgb::splat(c));
            }
        }
    }

    /// `∫ at(λ) dλ` over 360–830 nm (`at` is linear between the 10 nm nodes, so 0.1 nm
    /// trapezoids are exact but for rounding).
    fn area_of(m: &Measured) -> f64 {
        let at = |i: usize| f64::from(m.at(360.0 + i as f32 * 0.1));
        (1..=4700).map(|i| 0.05 * (at(i - 1) + at(i))).sum()
    }

    /// `∫ f dλ` over 360–830 nm of the piecewise-linear `f` through `pts` (constant beyond
    /// the ends), by clipping each piece: the reference the grid must keep.
    fn exact_area(pts: &[(f32, f32)]) -> f64 {
        let p: Vec<(f64, f64)> = pts
            .iter()
            .map(|&(l, v)| (f64::from(l), f64::from(v)))
            .collect();
        let (lo, hi) = (360.0f64, 830.0f64);
        let mut ext = vec![(lo.min(p[0].0), p[0].1)];
        ext.extend(&p);
        ext.push((hi.max(p[p.len() - 1].0), p[p.len() - 1].1));
        let mut area = 0.0;
        for w in ext.windows(2) {
            let ((x0, y0), (x1, y1)) = (w[0], w[1]);
            let (a, b) = (x0.max(lo), x1.min(hi));
            if b > a {
                let y = |x: f64| y0 + (x - x0) / (x1 - x0) * (y1 - y0);
                area += 0.5 * (b - a) * (y(a) + y(b));
            }
        }
        area
    }

    #[test]
    fn narrow_lines_and_dips_keep_their_area_wherever_they_fall() {
        for centre in [555.0f32, 555.5, 555.3, 360.0, 829.9, 365.05, 700.0] {
            for height in [1e-3f32, 1.0, 250.0, 1e9] {
                // A 0.2 nm wide triangle on a zero background.
                let line = [(centre - 0.1, 0.0), (centre, height), (centre + 0.1, 0.0)];
                let m = Measured::from_points(&line, UNBOUNDED).unwrap();
                let (got, want) = (area_of(&m), exact_area(&line));
                assert!(want > 0.0);
                assert!(
                    ((got - want) / want).abs() < 1e-4,
                    "line at {centre} nm, height {height}: area {got}, want {want}"
                );
                assert!(m.luminance() > 0.0 || centre > 800.0);
            }
            // The same line as a dip in a flat 1 (to 0, and halfway): the missing area is kept.
            // (A shallower dip's missing area is below what f32 grid values near 1 resolve.)
            for depth in [1.0f32, 0.5] {
                let dip = [
                    (300.0, 1.0),
                    (centre - 0.1, 1.0),
                    (centre, 1.0 - depth),
                    (centre + 0.1, 1.0),
                    (900.0, 1.0),
                ];
                let m = Measured::from_points(&dip, 1.0).unwrap();
                let (got, want) = (470.0 - area_of(&m), 470.0 - exact_area(&dip));
                assert!(
                    ((got - want) / want).abs() < 1e-4,
                    "dip at {centre} nm, depth {depth}: missing {got}, want {want}"
                );
            }
        }
        // Where a 0.2 nm line falls within a cell hardly changes its luminance (0.2 nm at
        // 555.0 nm was lost between the old midpoint samples).
        let y = |c: f32| {
            Measured::from_points(&[(c - 0.1, 0.0), (c, 100.0), (c + 0.1, 0.0)], UNBOUNDED)
                .unwrap()
                .luminance()
        };
        let (a, b) = (y(555.0), y(555.5));
        assert!(a > 0.0 && ((a - b) / b).abs() < 1e-3, "{a} vs {b}");
        // Nor does crossing the middle between two nodes on ȳ's steep flank (0.8 %; a box per
        // node would change it by a factor 1.5).
        let (a, b) = (y(504.9), y(505.1));
        assert!(a > 0.0 && ((a - b) / b).abs() < 1e-2, "{a} vs {b}");
    }

    #[test]
    fn a_narrow_line_keeps_its_area() {
        // A 2 nm wide triangle of height 10 between grid points: area 10 nm.
        let line = Measured::from_points(
            &[(400.0, 0.0), (524.0, 0.0), (525.0, 10.0), (526.0, 0.0)],
            1e4,
        )
        .unwrap();
        let area: f32 = (0..=470).map(|i| line.at(360.0 + i as f32)).sum();
        assert!((area - 10.0).abs() < 0.5, "area {area}");
    }

    #[test]
    fn bad_points_are_refused() {
        for (pts, expect) in [
            (vec![(500.0, 1.0)], "2 ..= 4096"),
            (vec![(500.0, 1.0), (500.0, 2.0)], "does not increase"),
            (vec![(100.0, 1.0), (500.0, 2.0)], "200 ..= 2000"),
            (vec![(400.0, -1.0), (500.0, 2.0)], "0 ..= 10000"),
            (vec![(400.0, f32::NAN), (500.0, 2.0)], "out of range"),
        ] {
            let e = Measured::from_points(&pts, 1e4).unwrap_err();
            assert!(e.contains(expect), "{pts:?}: {e}");
        }
    }

    #[test]
    fn errors_name_the_point_apart_and_unbounded_values_read_as_words() {
        let pts = [(400.0, 1.0), (500.0, -2.0)];
        for max in [UNBOUNDED, f32::MAX] {
            let e = Measured::try_from_points(&pts, max).unwrap_err();
            assert_eq!(e.point, Some(1));
            assert_eq!(
                e.message,
                "value -2 at 500 nm is out of range: allowed any finite value ≥ 0"
            );
            assert!(
                e.to_string().starts_with("spectrum point 1: value -2"),
                "{e}"
            );
        }
        let e = Measured::try_from_points(&[(400.0, 1.0), (500.0, 2e9)], 1e9).unwrap_err();
        assert!(e.message.ends_with("allowed 0 ..= 1e9"), "{e}");
        let e = Measured::try_from_points(&[(510.0, 1.0), (500.0, 0.5)], 1.0).unwrap_err();
        assert_eq!(
            e.message,
            "wavelength 500 nm does not increase (after 510 nm)"
        );
        assert_eq!(
            Measured::try_from_points(&[(510.0, 1.0)], 1.0)
                .unwrap_err()
                .point,
            None
        );
        // Infinity is not a finite value, bounded or not.
        assert!(Measured::from_points(&[(400.0, f32::INFINITY), (500.0, 1.0)], UNBOUNDED).is_err());
    }
}
