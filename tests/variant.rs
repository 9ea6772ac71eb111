//! The transport code is generic over the transported light (issue 15, docs/design.md §12): a
//! second variant, defined here outside the crate, runs through the same `trace`.
//!
//! `Grey4` carries four "hero wavelengths" (drawn from the sampler's reserved wavelength slot with
//! the rotation of Wilkie et al., EGSR 2014) and a grey value at each; its BSDF is the RGB model's
//! luminance. On a grey scene (a Lambert sphere of albedo 0.5 in a white furnace, and the glass
//! sphere of `tests/transmission.rs`) every path must give the RGB variant's radiance, path by
//! path, to rounding: the integrator, path state and shading context do not depend on RGB.

use glam::{Vec2, Vec3};
use lapidary::bsdf::{Bsdf, BsdfSample, Bxdf, Scatter, SmoothDielectric, TransportMode};
use lapidary::color::Rgb;
use lapidary::geometry::Ray;
use lapidary::recipe::GemRecipe;
use lapidary::render::{Strategy, World, trace};
use lapidary::sampler::{PixelSampler, SamplerKind, slots};
use lapidary::spectrum::{RgbSample, Spectral};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Grey4([f32; 4]);

impl Grey4 {
    fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        Grey4(std::array::from_fn(|i| f(self.0[i], o.0[i])))
    }
    fn grey(c: RgbSample) -> Self {
        Grey4([c.luminance(); 4])
    }
}
impl Add for Grey4 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        self.zip(o, |a, b| a + b)
    }
}
impl AddAssign for Grey4 {
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl Sub for Grey4 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self.zip(o, |a, b| a - b)
    }
}
impl Mul for Grey4 {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        self.zip(o, |a, b| a * b)
    }
}
impl MulAssign for Grey4 {
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}
impl Mul<f32> for Grey4 {
    type Output = Self;
    fn mul(self, s: f32) -> Self {
        Grey4(self.0.map(|a| a * s))
    }
}
impl MulAssign<f32> for Grey4 {
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}
impl Div<f32> for Grey4 {
    type Output = Self;
    fn div(self, s: f32) -> Self {
        Grey4(self.0.map(|a| a / s))
    }
}

impl Spectral for Grey4 {
    /// A grey variant cannot move light between wavelengths: no re-radiation reaches it.
    fn fluoresce(
        &mut self,
        _lambda: &mut Self::Wavelengths,
        _colorant: &lapidary::spectrum::fluorescence::Fluorescence,
        _lines: &[lapidary::spectrum::line::Line],
        _u: glam::Vec2,
    ) -> Option<[[f32; 3]; 3]> {
        *self = Self::ZERO;
        None
    }
    fn remix(self, _m: &[[f32; 3]; 3]) -> Self {
        self
    }
    /// Wavelengths in nm.
    type Wavelengths = [f32; 4];
    const WAVELENGTH_DIMENSIONS: u32 = 1;
    const ZERO: Self = Grey4([0.0; 4]);
    const ONE: Self = Grey4([1.0; 4]);
    const CHANNELS: usize = 4;
    fn channel(self, i: usize) -> f32 {
        self.0[i]
    }
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Grey4(self.0.map(f))
    }
    fn splat(v: f32) -> Self {
        Grey4([v; 4])
    }
    fn from_channels(f: impl Fn(usize) -> f32) -> Self {
        Grey4(std::array::from_fn(f))
    }
    fn sample_wavelengths(u: f32) -> [f32; 4] {
        std::array::from_fn(|k| 360.0 + 470.0 * (u + k as f32 / 4.0).fract())
    }
    fn from_reflectance(c: Rgb, _: &[f32; 4]) -> Self {
        Grey4([c.luminance(); 4])
    }
    fn from_unbounded(c: Rgb, _: &[f32; 4]) -> Self {
        Grey4([c.luminance(); 4])
    }
    fn to_rgb(self, lambda: &[f32; 4]) -> Rgb {
        assert!(
            lambda.iter().all(|l| (360.0..830.0).contains(l)),
            "{lambda:?}"
        );
        Rgb::splat(self.average())
    }
    fn max_channel(self) -> f32 {
        self.0.into_iter().fold(f32::MIN, f32::max)
    }
    fn average(self) -> f32 {
        self.0.iter().sum::<f32>() / 4.0
    }
    fn is_black(self) -> bool {
        self.0.iter().all(|&c| c == 0.0)
    }
    fn is_valid(self) -> bool {
        self.0.iter().all(|&c| c.is_finite() && c >= 0.0)
    }
}

/// The RGB models seen through `Grey4`.
impl Scatter<Grey4> for Bsdf {
    fn eval_at(&self, wo: Vec3, wi: Vec3, mode: TransportMode, _: &[f32; 4]) -> Grey4 {
        Grey4::grey(Bxdf::<RgbSample>::eval_mode(self, wo, wi, mode))
    }
    fn sample_at(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        _: &[f32; 4],
    ) -> Option<BsdfSample<Grey4>> {
        let s = Bxdf::<RgbSample>::sample_mode(self, wo, uc, u, mode)?;
        Some(BsdfSample {
            wi: s.wi,
            f: Grey4::grey(s.f),
            pdf: s.pdf,
            weight: Grey4::grey(s.weight),
            lobe: s.lobe,
            flags: s.flags,
            eta: s.eta,
            pdf_is_proportional: s.pdf_is_proportional,
            terminate_secondary: false,
        })
    }
    fn pdf_at(&self, wo: Vec3, wi: Vec3, _: &[f32; 4]) -> f32 {
        Bxdf::<RgbSample>::pdf(self, wo, wi)
    }
    fn interface_eta(&self, _channel: usize, _: &[f32; 4]) -> Option<f32> {
        match self {
            Bsdf::SmoothDielectric(b) => Some(b.eta),
            _ => None,
        }
    }
}

fn world(replace: Option<Bsdf>) -> World {
    let scene = GemRecipe::parse("furnace.ron", include_str!("scenes/furnace.ron"))
        .and_then(|r| r.compile())
        .expect("the furnace scene compiles");
    let mut world = World::new(&scene).expect("the furnace world builds");
    if let Some(b) = replace {
        for m in world.materials.iter_mut().flatten() {
            *m = b.clone();
        }
    }
    world
}

#[test]
fn a_second_variant_traces_the_same_paths() {
    for (name, world) in [
        ("lambert 0.5", world(None)),
        (
            "glass 1.5",
            world(Some(Bsdf::SmoothDielectric(SmoothDielectric::new(1.5)))),
        ),
    ] {
        let mut worst = 0.0f32;
        for i in 0..4000u32 {
            let ray = |s: &mut PixelSampler| {
                let u = s.get2d();
                s.skip_to(slots::bounce(0));
                let (r, phi) = (1.2 * u.x.sqrt(), std::f32::consts::TAU * u.y);
                Ray::new(Vec3::new(r * phi.cos(), r * phi.sin(), 5.0), Vec3::NEG_Z)
            };
            let mut s = PixelSampler::new(SamplerKind::Sobol, 3, u64::from(i), i);
            let rgb = trace::<RgbSample>(&world, ray(&mut s), &mut s, 16, Strategy::Mis);
            let mut s = PixelSampler::new(SamplerKind::Sobol, 3, u64::from(i), i);
            let grey = trace::<Grey4>(&world, ray(&mut s), &mut s, 16, Strategy::Mis);
            assert_eq!(
                (rgb.rays, rgb.material),
                (grey.rays, grey.material),
                "{name} path {i}"
            );
            let (a, b) = (rgb.radiance.luminance(), grey.radiance[0]);
            worst = worst.max((a - b).abs() / a.max(1e-3));
        }
        println!("{name}: worst relative difference {worst:.2e}");
        assert!(worst < 1e-4, "{name}: {worst}");
    }
}
