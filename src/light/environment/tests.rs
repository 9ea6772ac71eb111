//! Unit tests of the environment light (a file of their own to keep `environment.rs` short).

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
    let (zenith, horizon) = (Rgb::new(0.2, 0.4, 1.0), Rgb::splat(0.8));
    EnvironmentLight::new(&Environment::Gradient {
        zenith,
        horizon,
        nadir: Rgb::ZERO,
    })
    .expect("no file")
}

#[test]
fn pdf_matches_sample_and_integrates_to_one() {
    let constant = EnvironmentLight::new(&Environment::Constant(Rgb::splat(0.3)));
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
        (Rgb::new(0.2, 0.4, 1.0), Rgb::splat(0.8))
    );
    assert_eq!(l.radiance(Vec3::NEG_Y), Rgb::ZERO);
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
        assert_eq!(s.radiance, Rgb::splat(2.0), "never an invalid pixel");
    }
    assert_eq!(l.radiance(Vec3::new(-0.1, 0.9, 0.0).normalize()), Rgb::ZERO);
    for l in [
        EnvironmentLight::from_image(&spot(4, 2, 0..0, 0..0, 1.0), 1.0, 0.0),
        EnvironmentLight::from_image(&img, 0.0, 0.0),
        EnvironmentLight::from_image(&spot(0, 0, 0..1, 0..1, 1.0), 1.0, 0.0),
        EnvironmentLight::new(&Environment::Constant(Rgb::ZERO)).unwrap(),
    ] {
        assert!(l.is_black() && l.sample(Vec2::splat(0.5)).is_none());
        assert_eq!((l.pdf(Vec3::X), l.power(1.0)), (0.0, 0.0));
        assert_eq!(l.radiance(Vec3::X), Rgb::ZERO);
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
