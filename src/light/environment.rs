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
use crate::color::Rgb;
use crate::image::input_kind::NotAFile;
use crate::image::{ImageError, RgbImage, read_rgb};
use crate::scene::stage::Environment;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::ops::{Add, Mul};

mod map;
pub use map::MAX_MAP_VALUE;
use map::{Map, refuse_unusable};

/// Fraction of the mean luminance added to a gradient's sampling density everywhere.
const GRADIENT_FLOOR: f32 = 0.1;

/// A gradient with its sampling density `∝ f(y)`, both linear on each hemisphere.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Gradient {
    /// Radiance at y = 1, 0, −1.
    colors: [Rgb; 3],
    /// `f` at y = 1, 0, −1.
    f: [f32; 3],
    /// `∫₋₁¹ f(y) dy`.
    total: f32,
}

#[derive(Clone, Debug, PartialEq)]
enum Kind {
    Constant(Rgb),
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

/// `c` with negative or non-finite channels set to 0.
fn sanitize(c: Rgb) -> Rgb {
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
    fn gradient(colors: [Rgb; 3]) -> EnvironmentLight {
        let y = colors.map(Rgb::luminance);
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
        let mut pixels: Vec<Rgb> = texels.into_iter().map(Rgb).collect();
        pixels.resize(width * height, Rgb::ZERO);
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
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        match &self.kind {
            Kind::Constant(c) => *c,
            Kind::Gradient(g) => piecewise_linear(dir.y, g.colors),
            Kind::Map(m) if m.pixels.is_empty() => Rgb::ZERO,
            Kind::Map(m) => {
                let uv = m.uv(m.to_map(dir));
                uv.map_or(Rgb::ZERO, |uv| m.pixels[m.cell(uv)])
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
mod tests;
