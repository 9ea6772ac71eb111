//! Light from infinitely far away: a constant sky, a sky gradient, or a lat-long radiance map.
//!
//! # Direction convention of maps
//! A map is an equirectangular (lat-long) image, row 0 at the zenith. The point `(u, v) ∈ [0, 1)²`
//! of the image (`u` across, `v` down) has polar angle `θ = π v` from +y and azimuth
//! `φ = 2π (u − ½)`, and looks along
//!
//! `m = (sin θ · sin φ, cos θ, −sin θ · cos φ)`
//!
//! so the image centre looks along −z, its right quarter (`u = ¾`) along +x and its left and right
//! edges along +z: seen from inside, the image is not mirrored. A map rotated by `rotate = α`
//! shows what the unrotated map shows along `m` in the world direction `R_y(α) m`, where `R_y` is
//! the right-handed rotation about +y (counter-clockwise seen from above): `α = π/2` moves what was
//! at −z to −x.
//!
//! # Sampling
//! Constant skies are sampled uniformly over the sphere. Gradients are sampled with a density
//! linear in `y` on each hemisphere, proportional to the luminance plus a floor of 10 % of its mean
//! (so every direction keeps a positive density). Maps are sampled from a piecewise-constant 2-D
//! distribution over `(u, v)` with weights `luminance × sin θ` per pixel (Pharr, Jakob & Humphreys,
//! *Physically Based Rendering*, 3rd ed., §14.2.4), so the solid-angle density is
//! `p(u, v) / (2π² sin θ)`; radiance is looked up from the nearest pixel, so the density is
//! proportional to the luminance that is returned.

use super::distribution::Distribution2D;
use super::{LightSample, positive_or_zero};
use crate::color::Spectrum;
use crate::image::input_kind::NotAFile;
use crate::image::{ImageError, RgbImage, read_rgb};
use crate::scene::stage::Environment;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::ops::{Add, Mul};

/// Fraction of the mean luminance added to a gradient's sampling density everywhere.
const GRADIENT_FLOOR: f32 = 0.1;

/// A lat-long map ready for lookup and sampling.
#[derive(Clone, Debug, PartialEq)]
struct Map {
    width: usize,
    height: usize,
    /// Radiance per pixel, intensity applied, invalid values zeroed; row-major, top row first.
    pixels: Vec<Spectrum>,
    distribution: Distribution2D,
    /// `cos α`, `sin α` of the rotation about +y.
    rotation: Vec2,
    /// Sample by `distribution` (else uniformly over the sphere: the importance effect off).
    importance: bool,
}

/// A gradient with its sampling density `∝ f(y)`, both linear on each hemisphere.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Gradient {
    /// Radiance at y = 1, 0, −1.
    colors: [Spectrum; 3],
    /// `f` at y = 1, 0, −1.
    f: [f32; 3],
    /// `∫₋₁¹ f(y) dy`.
    total: f32,
}

#[derive(Clone, Debug, PartialEq)]
enum Kind {
    Constant(Spectrum),
    Gradient(Gradient),
    Map(Box<Map>),
}

/// Light arriving from infinitely far away, by direction.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLight {
    kind: Kind,
    /// `∫ Y(L(ω)) dω` over the sphere.
    luminance_integral: f32,
    /// Pixels that were negative or not finite and were set to black.
    invalid_pixels: usize,
}

/// Largest value of a map pixel's channel: far above any real sky or sun stored relative to the
/// scene, and low enough that the sampling sums over the largest map (2²⁷ pixels, times an
/// `intensity` of up to 1e6) stay finite in `f32`.
pub const MAX_MAP_VALUE: f32 = 1e12;

/// Refuses a map no light can be made of: an infinite or absurd pixel (its radiance, and the
/// sampling weight of every other pixel beside it, would be meaningless) or every pixel NaN.
fn refuse_unusable(path: &std::path::Path, img: &RgbImage) -> Result<(), ImageError> {
    let invalid = |reason: String| ImageError::Invalid {
        path: path.into(),
        reason,
    };
    let w = img.width.max(1) as usize;
    let infinite = |p: &[f32; 3]| p.iter().any(|c| c.is_infinite());
    if let Some(i) = img.pixels.iter().position(infinite) {
        return Err(invalid(format!(
            "pixel ({}, {}) is infinite: an environment map must hold finite radiance",
            i % w,
            i / w
        )));
    }
    let absurd = |p: &[f32; 3]| p.iter().any(|&c| c > MAX_MAP_VALUE);
    if let Some(i) = img.pixels.iter().position(absurd) {
        return Err(invalid(format!(
            "pixel ({}, {}) = {:?} is out of range: each channel allowed up to {MAX_MAP_VALUE:e}",
            i % w,
            i / w,
            img.pixels[i]
        )));
    }
    if !img.pixels.is_empty() && img.pixels.iter().all(|p| p.iter().any(|c| c.is_nan())) {
        return Err(invalid(
            "every pixel is NaN (not a number): the map holds no radiance".into(),
        ));
    }
    Ok(())
}

/// `c` with negative or non-finite channels set to 0.
fn sanitize(c: Spectrum) -> Spectrum {
    c.map(positive_or_zero)
}

impl EnvironmentLight {
    /// Builds the light of a stage environment; for a map, reads the image with
    /// [`read_rgb`] and builds its sampling distribution. Negative or non-finite colours count as
    /// zero.
    pub fn new(env: &Environment) -> Result<EnvironmentLight, ImageError> {
        Ok(match env {
            Environment::Constant(c) => {
                let c = sanitize(*c);
                EnvironmentLight {
                    kind: Kind::Constant(c),
                    luminance_integral: 4.0 * PI * c.luminance(),
                    invalid_pixels: 0,
                }
            }
            Environment::Gradient {
                zenith,
                horizon,
                nadir,
            } => Self::gradient([*zenith, *horizon, *nadir].map(sanitize)),
            Environment::Map {
                path,
                intensity,
                rotate,
            } => {
                // The file type first, without opening: a FIFO would block the reader.
                crate::image::input_kind::regular_file(path).map_err(|e| match e {
                    NotAFile::Missing => ImageError::NotFound { path: path.clone() },
                    e => ImageError::Unreadable {
                        path: path.clone(),
                        reason: e.to_string(),
                    },
                })?;
                let img = read_rgb(path)?;
                refuse_unusable(path, &img)?;
                Self::from_rgb(img, *intensity, *rotate)
            }
        })
    }

    /// A gradient through `colors` at y = 1, 0, −1.
    fn gradient(colors: [Spectrum; 3]) -> EnvironmentLight {
        let y = colors.map(Spectrum::luminance);
        // Mean over the sphere of a function linear in y on each hemisphere (dω = dy dφ).
        let mean = (y[0] + 2.0 * y[1] + y[2]) / 4.0;
        let f = y.map(|y| y + GRADIENT_FLOOR * mean);
        let total = 0.5 * (f[0] + f[1]) + 0.5 * (f[2] + f[1]);
        EnvironmentLight {
            kind: Kind::Gradient(Gradient { colors, f, total }),
            luminance_integral: 4.0 * PI * mean,
            invalid_pixels: 0,
        }
    }

    /// A map light from an image in memory (row-major, top row first, zenith on top; see the
    /// module docs for the direction convention).
    ///
    /// # Arguments
    /// * `img` – linear RGB radiance; pixels with a negative or non-finite channel are set to black
    ///   and counted ([`invalid_pixels`](Self::invalid_pixels)); missing pixels are black.
    /// * `intensity` – radiance multiplier (a negative or non-finite value gives a black light).
    /// * `rotate` – rotation of the map about +y in radians (right-handed).
    pub fn from_image(img: &RgbImage, intensity: f32, rotate: f32) -> EnvironmentLight {
        Self::from_rgb(img.clone(), intensity, rotate)
    }

    /// [`from_image`](Self::from_image) taking the image: its pixels become the light's in place,
    /// and the sampling tables add about 4 bytes per pixel ([`table_bytes`](Self::table_bytes)),
    /// so a map costs about 16 bytes per pixel in all (12 of them its own `f32` RGB).
    pub fn from_rgb(img: RgbImage, intensity: f32, rotate: f32) -> EnvironmentLight {
        use rayon::prelude::*;
        let (width, height) = (img.width as usize, img.height as usize);
        let scale = positive_or_zero(intensity);
        let mut texels = img.pixels;
        let invalid: usize = texels
            .par_iter_mut()
            .map(|c| {
                if c.iter().all(|x| x.is_finite() && *x >= 0.0) {
                    *c = c.map(|x| x * scale);
                    0
                } else {
                    *c = [0.0; 3];
                    1
                }
            })
            .sum();
        // The same allocation, viewed as spectra.
        let mut pixels: Vec<Spectrum> = texels.into_iter().map(Spectrum).collect();
        pixels.resize(width * height, Spectrum::ZERO);
        let rows = |row: usize| {
            let (t0, t1) = (row as f32 / height as f32, (row + 1) as f32 / height as f32);
            let sin_mid = (PI * 0.5 * (t0 + t1)).sin();
            let solid = 2.0 * PI / width as f32 * ((PI * t0).cos() - (PI * t1).cos());
            (&pixels[row * width..(row + 1) * width], sin_mid, solid)
        };
        let distribution = Distribution2D::from_rows(width, height, |row, buf| {
            let (texels, sin_mid, _) = rows(row);
            buf.extend(texels.iter().map(|c| c.luminance() * sin_mid));
        });
        // Row sums in parallel, added in row order (the same total for any thread count).
        let row_sums: Vec<f64> = (0..height)
            .into_par_iter()
            .map(|row| {
                let (texels, _, solid) = rows(row);
                texels
                    .iter()
                    .map(|c| f64::from(c.luminance() * solid))
                    .sum::<f64>()
            })
            .collect();
        let integral: f64 = row_sums.iter().sum();
        let rotation = Vec2::from_angle(if rotate.is_finite() { rotate } else { 0.0 });
        EnvironmentLight {
            kind: Kind::Map(Box::new(Map {
                width,
                height,
                pixels,
                distribution,
                rotation,
                importance: true,
            })),
            luminance_integral: integral as f32,
            invalid_pixels: invalid,
        }
    }

    /// Bytes of heap the sampling tables of a map take (0 for other environments).
    pub fn table_bytes(&self) -> usize {
        match &self.kind {
            Kind::Map(m) => m.distribution.heap_bytes(),
            _ => 0,
        }
    }

    /// Samples a map by its luminance (`true`, the default) or uniformly over the sphere (the
    /// environment-importance effect forced off); other environments keep their own sampling.
    pub fn set_importance(&mut self, on: bool) {
        if let Kind::Map(m) = &mut self.kind {
            m.importance = on;
        }
    }

    /// Number of map pixels that were negative or not finite and were treated as black (0 for
    /// other environments).
    pub fn invalid_pixels(&self) -> usize {
        self.invalid_pixels
    }

    /// What a user should hear about a map light that loaded but may not be what was meant: a map
    /// that is black everywhere (it lights nothing, the background renders black), and pixels
    /// that were NaN or negative and count as black. Empty for other environments.
    pub fn warnings(&self) -> Vec<String> {
        let Kind::Map(m) = &self.kind else {
            return vec![];
        };
        let mut out = vec![];
        if self.invalid_pixels > 0 {
            out.push(format!(
                "environment map: {} of {} pixels are NaN or negative and count as black",
                self.invalid_pixels,
                m.width * m.height
            ));
        }
        if !(self.luminance_integral > 0.0) {
            out.push(
                "environment map: every pixel is black (after `intensity`): the environment \
                 lights nothing and renders black"
                    .into(),
            );
        }
        out
    }

    /// True when the environment emits nothing.
    pub fn is_black(&self) -> bool {
        match &self.kind {
            Kind::Constant(c) => c.is_black(),
            Kind::Gradient(g) => g.colors.iter().all(|c| c.is_black()),
            Kind::Map(m) => m.distribution.is_black(),
        }
    }

    /// True for maps, whose sampling follows the image.
    pub fn importance_sampled(&self) -> bool {
        matches!(self.kind, Kind::Map(_))
    }

    /// Estimated flux into a scene bounded by a sphere of `scene_radius` (world units):
    /// `π r² ∫ Y(L(ω)) dω`, for choosing between the environment and other lights.
    pub fn power(&self, scene_radius: f32) -> f32 {
        PI * scene_radius * scene_radius * self.luminance_integral
    }

    /// Radiance arriving from direction `dir` (unit, world space, pointing from the scene toward
    /// the sky).
    pub fn radiance(&self, dir: Vec3) -> Spectrum {
        match &self.kind {
            Kind::Constant(c) => *c,
            Kind::Gradient(g) => piecewise_linear(dir.y, g.colors),
            Kind::Map(m) if m.pixels.is_empty() => Spectrum::ZERO,
            Kind::Map(m) => {
                let uv = m.uv(m.to_map(dir));
                uv.map_or(Spectrum::ZERO, |uv| m.pixels[m.cell(uv)])
            }
        }
    }

    /// A direction toward the sky from `u ∈ [0, 1)²`, with `dist = ∞`; `None` when black.
    pub fn sample(&self, u: Vec2) -> Option<LightSample> {
        if self.is_black() {
            return None;
        }
        let (wi, pdf, radiance) = match &self.kind {
            Kind::Constant(c) => (sphere_direction(1.0 - 2.0 * u.x, u.y), 0.25 / PI, *c),
            Kind::Gradient(g) => {
                let p_up = 0.5 * (g.f[0] + g.f[1]) / g.total;
                let y = if u.x < p_up {
                    sample_linear(u.x / p_up, g.f[1], g.f[0])
                } else {
                    -sample_linear((u.x - p_up) / (1.0 - p_up), g.f[1], g.f[2])
                };
                let wi = sphere_direction(y, u.y);
                (wi, self.pdf(wi), self.radiance(wi))
            }
            Kind::Map(m) if !m.importance => {
                let wi = sphere_direction(1.0 - 2.0 * u.x, u.y);
                (wi, 0.25 / PI, self.radiance(wi))
            }
            Kind::Map(m) => {
                let s = m.distribution.sample(u)?;
                let theta = PI * s.uv.y;
                let (sin_t, cos_t) = theta.sin_cos();
                let phi = 2.0 * PI * (s.uv.x - 0.5);
                let local = Vec3::new(sin_t * phi.sin(), cos_t, -sin_t * phi.cos());
                let (c, r) = s.cell;
                let pdf = s.pdf / (2.0 * PI * PI * sin_t);
                (m.to_world(local), pdf, m.pixels[r * m.width + c])
            }
        };
        (pdf > 0.0 && pdf.is_finite() && wi.is_finite()).then_some(LightSample {
            wi,
            dist: f32::INFINITY,
            radiance,
            pdf,
        })
    }

    /// Solid-angle density (sr⁻¹) with which [`sample`](Self::sample) produces the unit direction
    /// `dir`; 0 when black or where the map has no weight.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        if self.is_black() {
            return 0.0;
        }
        let pdf = match &self.kind {
            Kind::Constant(_) => 0.25 / PI,
            Kind::Map(m) if !m.importance => 0.25 / PI,
            Kind::Gradient(g) => piecewise_linear(dir.y, g.f) / (g.total * 2.0 * PI),
            Kind::Map(m) => {
                let local = m.to_map(dir);
                let sin_t = (local.x * local.x + local.z * local.z).sqrt();
                m.uv(local)
                    .map_or(0.0, |uv| m.distribution.pdf(uv) / (2.0 * PI * PI * sin_t))
            }
        };
        positive_or_zero(pdf)
    }
}

impl Map {
    /// World direction → map direction: `R_y(−α)`.
    fn to_map(&self, w: Vec3) -> Vec3 {
        let (c, s) = (self.rotation.x, self.rotation.y);
        Vec3::new(w.x * c - w.z * s, w.y, w.x * s + w.z * c)
    }

    /// Map direction → world direction: `R_y(α)`.
    fn to_world(&self, m: Vec3) -> Vec3 {
        let (c, s) = (self.rotation.x, self.rotation.y);
        Vec3::new(m.x * c + m.z * s, m.y, -m.x * s + m.z * c)
    }

    /// Image coordinates `(u, v) ∈ [0, 1)²` of a direction in map space; `None` if not finite.
    fn uv(&self, m: Vec3) -> Option<Vec2> {
        let v = m.y.clamp(-1.0, 1.0).acos() / PI;
        let mut u = m.x.atan2(-m.z) / (2.0 * PI) + 0.5;
        if u >= 1.0 {
            u -= 1.0;
        }
        let below_one = 1.0 - f32::EPSILON / 2.0;
        let uv = Vec2::new(u.clamp(0.0, below_one), v.clamp(0.0, below_one));
        uv.is_finite().then_some(uv)
    }

    /// Pixel index of image coordinates.
    fn cell(&self, uv: Vec2) -> usize {
        let c = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let r = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        r * self.width + c
    }
}

/// The function of `y ∈ [−1, 1]` linear on each hemisphere through `v` at y = 1, 0, −1.
fn piecewise_linear<T: Copy + Add<Output = T> + Mul<f32, Output = T>>(y: f32, v: [T; 3]) -> T {
    let y = y.clamp(-1.0, 1.0);
    let end = if y >= 0.0 { v[0] } else { v[2] };
    v[1] * (1.0 - y.abs()) + end * y.abs()
}

/// The unit direction with height `y ∈ [−1, 1]` and azimuth `2π·u` about +y.
fn sphere_direction(y: f32, u: f32) -> Vec3 {
    let y = y.clamp(-1.0, 1.0);
    let r = (1.0 - y * y).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u).sin_cos();
    Vec3::new(r * c, y, r * s)
}

/// Inverts the CDF of the density on `[0, 1]` proportional to `(1 − x)·a + x·b` (`a, b ≥ 0`, not
/// both 0): the root of `(b − a) x² + 2a x = u (a + b)` written as
/// `x = u (a + b) / (a + √((1 − u) a² + u b²))`, which does not cancel when `a ≈ b`.
fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + ((1.0 - u) * a * a + u * b * b).sqrt());
    x.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::distribution::testing::*;
    use crate::sampler::Rng;
    use std::ops::Range;

    /// A `w × h` image, black but for value `v` in columns `cols` of rows `rows`.
    fn spot(w: u32, h: u32, cols: Range<u32>, rows: Range<u32>, v: f32) -> RgbImage {
        let lit = |i: u32| cols.contains(&(i % w)) && rows.contains(&(i / w));
        let pixels = (0..w * h).map(|i| [v * f32::from(u8::from(lit(i))); 3]);
        let pixels = pixels.collect();
        RgbImage {
            width: w,
            height: h,
            pixels,
        }
    }

    /// 32 × 16 map: smooth colours, a black row and one bright pixel.
    fn textured(rotate: f32) -> EnvironmentLight {
        let mut img = spot(32, 16, 0..0, 0..0, 0.0);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            let (c, r) = ((i % 32) as f32, (i / 32) as f32);
            *p = [1.0 + 0.8 * (c * 0.3).sin(), 0.5 + r / 16.0, 0.2];
        }
        img.pixels[11 * 32..12 * 32].fill([0.0; 3]);
        img.pixels[5 * 32 + 20] = [50.0, 40.0, 30.0];
        EnvironmentLight::from_image(&img, 2.0, rotate)
    }

    fn gradient() -> EnvironmentLight {
        let (zenith, horizon) = (Spectrum::rgb(0.2, 0.4, 1.0), Spectrum::splat(0.8));
        EnvironmentLight::new(&Environment::Gradient {
            zenith,
            horizon,
            nadir: Spectrum::ZERO,
        })
        .expect("no file")
    }

    #[test]
    fn pdf_matches_sample_and_integrates_to_one() {
        let constant = EnvironmentLight::new(&Environment::Constant(Spectrum::splat(0.3)));
        let lights = [constant.expect("no file"), gradient(), textured(0.7)];
        for (name, l) in ["constant", "gradient", "map"].into_iter().zip(lights) {
            let mut rng = Rng::new(9);
            for _ in 0..2000 {
                let s = l.sample(rng.uniform2()).expect(name);
                assert!(s.dist == f32::INFINITY && (s.wi.length() - 1.0).abs() < 1e-5);
                let pdf = l.pdf(s.wi);
                assert!(
                    (pdf - s.pdf).abs() <= 1e-4 * s.pdf,
                    "{name}: {pdf}, {}",
                    s.pdf
                );
                assert_eq!(s.radiance, l.radiance(s.wi), "{name}");
            }
            // 200 000 uniform directions, accepted within 4 standard errors.
            let (m, se) = sphere_integral(|w| l.pdf(w));
            assert!((m - 1.0).abs() < (4.0 * se).max(1e-6), "{name}: {m} ± {se}");
        }
    }

    /// Estimate of `∫ L dω` (channel `ch`) from 20 000 samples: (mean, standard error).
    fn integral(l: &EnvironmentLight, ch: usize) -> (f64, f64) {
        let f = |s: LightSample| f64::from(s.radiance[ch] / s.pdf);
        estimate(20_000, 4, |u| l.sample(u).map_or(0.0, f))
    }

    #[test]
    fn gradient_is_linear_in_height_and_estimates_its_integral() {
        let l = gradient();
        let (zenith, horizon) = (l.radiance(Vec3::Y), l.radiance(Vec3::X));
        assert_eq!(
            (zenith, horizon),
            (Spectrum::rgb(0.2, 0.4, 1.0), Spectrum::splat(0.8))
        );
        assert_eq!(l.radiance(Vec3::NEG_Y), Spectrum::ZERO);
        assert!((l.radiance(Vec3::new(0.0, -0.5, 0.866))[0] - 0.4).abs() < 1e-6);
        // ∫ L dω = π (zenith + 2 horizon + nadir) per channel, within 4 standard errors.
        for ch in 0..3 {
            let (m, se) = integral(&l, ch);
            let exact = f64::from(PI * (zenith[ch] + 2.0 * horizon[ch]));
            assert!(
                (m - exact).abs() < 4.0 * se,
                "channel {ch}: {m} ± {se} vs {exact}"
            );
        }
        let y = PI * (zenith.luminance() + 2.0 * horizon.luminance());
        assert!((l.power(2.0) - PI * 4.0 * y).abs() < 1e-4);
    }

    #[test]
    fn one_bright_pixel_concentrates_the_samples() {
        let l = EnvironmentLight::from_image(&spot(16, 8, 5..6, 2..3, 10.0), 1.0, 0.0);
        let Kind::Map(m) = &l.kind else {
            unreachable!()
        };
        let mut rng = Rng::new(6);
        for _ in 0..20_000 {
            let s = l.sample(rng.uniform2()).expect("not black");
            assert_eq!(m.cell(m.uv(s.wi).unwrap()), 2 * 16 + 5, "{:?}", s.wi); // rotate = 0
        }
        // ∫ L dω = 10 × the pixel's solid angle, within 4 standard errors.
        let (mean, se) = integral(&l, 0);
        let t = |r: f32| f64::from((PI * r / 8.0).cos());
        let exact = 10.0 * std::f64::consts::TAU / 16.0 * (t(2.0) - t(3.0));
        assert!((mean - exact).abs() < 4.0 * se, "{mean} ± {se} vs {exact}");
        assert_eq!(l.pdf(Vec3::Y), 0.0);
        assert!((f64::from(l.power(1.0)) - std::f64::consts::PI * exact).abs() < 1e-3);
    }

    #[test]
    fn sampled_directions_follow_the_pdf() {
        // 100 000 samples each, χ² at significance 0.01 on a 16 × 8 lat-long grid. The map is
        // rotated by 5 pixel widths so that pdf·sin θ stays constant inside each cell of the
        // midpoint rule, which is then exact.
        for l in [textured(std::f32::consts::TAU * 5.0 / 32.0), gradient()] {
            assert_latlong_chi2(
                100_000,
                |u| l.sample(u).expect("not black").wi,
                |w| l.pdf(w),
            );
        }
    }

    #[test]
    fn rotation_turns_the_map_about_y() {
        // A bright 2 × 2 patch at the image centre, on the horizon: it looks along −z.
        let img = spot(32, 16, 15..17, 7..9, 5.0);
        let mean_dir = |l: &EnvironmentLight| {
            let mut rng = Rng::new(2);
            let sum: Vec3 = (0..2000)
                .map(|_| l.sample(rng.uniform2()).unwrap().wi)
                .sum();
            sum.normalize()
        };
        let l0 = EnvironmentLight::from_image(&img, 1.0, 0.0);
        let l90 = EnvironmentLight::from_image(&img, 1.0, PI / 2.0);
        assert!(l0.radiance(Vec3::NEG_Z)[0] == 5.0 && l0.radiance(Vec3::NEG_X)[0] == 0.0);
        assert!(l90.radiance(Vec3::NEG_X)[0] == 5.0 && l90.radiance(Vec3::NEG_Z)[0] == 0.0);
        let (a, b) = (mean_dir(&l0), mean_dir(&l90));
        assert!(
            a.dot(Vec3::NEG_Z) > 0.99 && b.dot(Vec3::NEG_X) > 0.99,
            "{a} {b}"
        );
        let turn = a.cross(b).y.atan2(a.dot(b)).to_degrees();
        assert!((turn - 90.0).abs() < 0.5, "turned by {turn}°");
    }

    #[test]
    fn invalid_and_black_maps_are_handled() {
        let mut img = spot(4, 2, 0..4, 0..2, 2.0);
        img.pixels[..3].copy_from_slice(&[[f32::NAN, 1.0, 1.0], [-1.0; 3], [f32::INFINITY; 3]]);
        let l = EnvironmentLight::from_image(&img, 1.0, 0.0);
        assert_eq!(l.invalid_pixels(), 3);
        assert!(l.importance_sampled() && !l.is_black());
        let mut rng = Rng::new(1);
        for _ in 0..500 {
            let s = l.sample(rng.uniform2()).unwrap();
            assert_eq!(s.radiance, Spectrum::splat(2.0), "never an invalid pixel");
        }
        assert_eq!(
            l.radiance(Vec3::new(-0.1, 0.9, 0.0).normalize()),
            Spectrum::ZERO
        );
        for l in [
            EnvironmentLight::from_image(&spot(4, 2, 0..0, 0..0, 1.0), 1.0, 0.0),
            EnvironmentLight::from_image(&img, 0.0, 0.0),
            EnvironmentLight::from_image(&spot(0, 0, 0..1, 0..1, 1.0), 1.0, 0.0),
            EnvironmentLight::new(&Environment::Constant(Spectrum::ZERO)).unwrap(),
        ] {
            assert!(l.is_black() && l.sample(Vec2::splat(0.5)).is_none());
            assert_eq!((l.pdf(Vec3::X), l.power(1.0)), (0.0, 0.0));
            assert_eq!(l.radiance(Vec3::X), Spectrum::ZERO);
        }
    }

    #[test]
    fn maps_are_read_from_exr_files() {
        use crate::image::{Channel, ExrImage, write_exr};
        let dir = std::env::temp_dir().join(format!("lapidary-env-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let img = spot(8, 4, 2..5, 1..3, 7.0);
        let data = img.pixels.iter().map(|p| p[0]).collect();
        let (width, height, channels) = (
            8,
            4,
            vec![Channel {
                name: "Y".into(),
                data,
            }],
        );
        let exr = ExrImage {
            width,
            height,
            channels,
            attributes: vec![],
        };
        let path = dir.join("sky.exr");
        write_exr(&path, &exr).unwrap();
        let (intensity, rotate) = (3.0, 0.4);
        let env = Environment::Map {
            path,
            intensity,
            rotate,
        };
        let from_file = EnvironmentLight::new(&env).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(from_file, EnvironmentLight::from_image(&img, 3.0, 0.4));
        assert!(EnvironmentLight::new(&env).is_err(), "file removed");
    }
}
