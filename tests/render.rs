//! Analytic scenes for the path tracer (issue 5): white furnace, mirror sphere, area light over a
//! Lambertian floor, the three direct-light strategies, determinism across thread counts, and no
//! dropped samples over the gem catalogue.
//!
//! Statistics: a pixel is tested with `z = (mean − expected) / √(variance of the mean)`; with
//! `N` pixels tested at family-wise significance α = 0.001 the Šidák bound per pixel is
//! `α_i = 1 − (1 − α)^(1/N)`, and the test allows `|z|` up to the matching normal quantile
//! (`z_crit`, computed below). Image-wide means are tested the same way with the summed variance.
//! The analytic scenes use the independent sampler: its sample variance is an honest estimate of
//! the error of the mean, where Sobol' stratification would make the z-tests conservative.

use glam::{Vec2, Vec3};
use lapidary::image::stats::{normal_quantile_two_sided, sidak};
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Rendered, Strategy, World, render};
use lapidary::scene::{Effect, Scene};
use std::path::Path;

/// Compiles recipe text.
fn scene(text: &str) -> Scene {
    GemRecipe::parse("test.ron", text)
        .unwrap_or_else(|e| panic!("{e}"))
        .compile()
        .unwrap_or_else(|e| panic!("{e}"))
}

fn run(scene: &Scene, control: &Control) -> Rendered {
    let world = World::new(scene).expect("world");
    render(
        &world,
        &scene.stage.camera,
        scene.effects.on(Effect::DepthOfField),
        &scene.stage.render,
        control,
    )
}

/// The per-pixel critical |z| for `n` tests at family-wise α = 0.001 (Šidák).
fn z_crit(n: usize) -> f64 {
    normal_quantile_two_sided(sidak(0.001, n))
}

/// Per-pixel z-test of channel means against `expected(x, y)` (None: pixel not tested). Returns
/// the number of pixels tested.
fn z_test(r: &Rendered, expected: impl Fn(u32, u32) -> Option<[f64; 3]>, what: &str) -> usize {
    let w = r.film.width;
    let cells: Vec<(u32, u32, [f64; 3])> = (0..r.film.height)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter_map(|(x, y)| expected(x, y).map(|e| (x, y, e)))
        .collect();
    let zc = z_crit(cells.len() * 3);
    let (mut max_z, mut sum_e, mut sum_m) = (0.0f64, 0.0f64, 0.0f64);
    for &(x, y, e) in &cells {
        let p = &r.film.pixels[(y * w + x) as usize];
        let m = p.mean();
        let v = p.variance_of_mean();
        for c in 0..3 {
            let sd = f64::from(v[c]).sqrt();
            let diff = f64::from(m[c]) - e[c];
            if sd > 0.0 {
                max_z = max_z.max(diff.abs() / sd);
            }
            sum_e += e[c];
            sum_m += f64::from(m[c]);
            // A zero-variance pixel must be exact to rounding.
            assert!(
                diff.abs() <= zc * sd + 2e-5 * e[c].abs().max(1.0),
                "{what}: pixel ({x}, {y}) channel {c}: {} vs expected {} (sd {sd:.2e}, |z| limit \
                 {zc:.2})",
                m[c],
                e[c]
            );
        }
    }
    eprintln!(
        "{what}: {} pixels, mean rendered {:.5} vs expected {:.5}, max |z| {max_z:.2} (limit \
         {zc:.2})",
        cells.len(),
        sum_m / (3 * cells.len()) as f64,
        sum_e / (3 * cells.len()) as f64
    );
    cells.len()
}

fn threads(n: usize) -> Control<'static> {
    Control {
        threads: Some(n),
        ..Control::default()
    }
}

fn furnace(albedo: f32) -> Scene {
    scene(&format!(
        r#"(materials: {{ "white": (base: Lambert(albedo: Gray({albedo}))) }},
            surface: Material("white"),
            stage: (shape: Sphere(radius: 1.0), ground: Off, lights: [], environment: Constant(Gray(1.0)),
                    camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0), height: 2.4),
                    render: (sampler: Independent, width: 32, height: 32, spp: 64, max_depth: 8)))"#
    ))
}

/// Pixels whose whole filter footprint (±1.5 px Gaussian, ±0.5 box) lies on the unit sphere seen
/// by the orthographic camera of height 2.4 over `n` pixels: the centre is within `1 − margin`.
fn inside_sphere(x: u32, y: u32, n: u32, margin_px: f32) -> bool {
    let px = 2.4 / n as f32;
    let p = Vec2::new((x as f32 + 0.5) * px - 1.2, 1.2 - (y as f32 + 0.5) * px);
    p.length() < 1.0 - margin_px * px
}

#[test]
fn white_furnace_lambert_sphere_renders_its_albedo() {
    for albedo in [1.0f32, 0.5] {
        let s = furnace(albedo);
        let r = run(&s, &Control::default());
        assert_eq!(r.stats.dropped, 0);
        let tested = z_test(
            &r,
            |x, y| inside_sphere(x, y, 32, 2.2).then_some([f64::from(albedo); 3]),
            &format!("furnace albedo {albedo}"),
        );
        assert!(tested > 350, "{tested} pixels tested");
        // The image-wide mean over the tested pixels, against its standard error.
        let (mut m, mut v, mut n) = (0.0f64, 0.0f64, 0.0f64);
        for y in 0..32 {
            for x in 0..32 {
                if inside_sphere(x, y, 32, 2.2) {
                    let p = &r.film.pixels[(y * 32 + x) as usize];
                    m += f64::from(p.mean()[0]);
                    v += f64::from(p.variance_of_mean()[0]);
                    n += 1.0;
                }
            }
        }
        let z = (m / n - f64::from(albedo)) / (v.sqrt() / n);
        eprintln!("furnace albedo {albedo}: mean {:.5}, z {z:.2}", m / n);
        assert!(z.abs() < z_crit(2), "furnace mean {} (z {z})", m / n);
        // Outside the sphere the camera sees the environment: exactly 1.
        let corner = r.film.pixels[0].mean();
        assert_eq!(corner.0, [1.0; 3]);
    }
}

#[test]
fn mirror_sphere_shows_the_environment() {
    // A perfect conductor at 0.01° roughness in a gradient sky: each pixel must equal the
    // environment in the mirror direction, averaged over the pixel's box footprint.
    let s = scene(
        r#"(materials: { "mirror": (base: Conductor(metal: Perfect, roughness: 0.01)) },
            surface: Material("mirror"),
            stage: (shape: Sphere(radius: 1.0), ground: Off, lights: [],
                    environment: Gradient(zenith: Rgb(0.2, 0.4, 1.0), horizon: Gray(1.0),
                                          nadir: Rgb(0.5, 0.3, 0.1)),
                    camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0), height: 2.4),
                    render: (sampler: Independent, width: 48, height: 48, spp: 64, filter: Box)))"#,
    );
    let r = run(&s, &Control::default());
    let env = |d: Vec3| -> [f64; 3] {
        let (zen, hor, nad) = ([0.2, 0.4, 1.0], [1.0; 3], [0.5, 0.3, 0.1]);
        std::array::from_fn(|c| {
            let y = f64::from(d.y);
            if y >= 0.0 {
                hor[c] + (zen[c] - hor[c]) * y
            } else {
                hor[c] + (nad[c] - hor[c]) * -y
            }
        })
    };
    let n = 48u32;
    let expected = |x: u32, y: u32| -> Option<[f64; 3]> {
        if !inside_sphere(x, y, n, 1.0) {
            return None;
        }
        // Average of the mirror direction's radiance over a 8×8 grid in the pixel.
        let px = 2.4 / n as f32;
        let mut acc = [0.0f64; 3];
        for i in 0..8 {
            for j in 0..8 {
                let fx = (x as f32 + (i as f32 + 0.5) / 8.0) * px - 1.2;
                let fy = 1.2 - (y as f32 + (j as f32 + 0.5) / 8.0) * px;
                let nrm = Vec3::new(fx, fy, (1.0 - fx * fx - fy * fy).max(0.0).sqrt());
                let d = Vec3::NEG_Z - 2.0 * Vec3::NEG_Z.dot(nrm) * nrm;
                let e = env(d);
                for c in 0..3 {
                    acc[c] += e[c] / 64.0;
                }
            }
        }
        Some(acc)
    };
    let tested = z_test(&r, expected, "mirror sphere");
    assert!(tested > 1000);
    // And closely: the mean relative error over the tested pixels is below 0.5 %, the worst 5 %
    // (the pixel noise here is the environment varying across the pixel footprint).
    let (mut sum, mut worst) = (0.0f64, 0.0f64);
    for y in 0..n {
        for x in 0..n {
            if let Some(e) = expected(x, y) {
                let m = r.film.pixels[(y * n + x) as usize].mean();
                for c in 0..3 {
                    let rel = (f64::from(m[c]) - e[c]).abs() / e[c];
                    sum += rel / (3 * tested) as f64;
                    worst = worst.max(rel);
                }
            }
        }
    }
    assert!(
        sum < 0.005 && worst < 0.05,
        "mean relative error {sum}, worst {worst}"
    );
}

/// The form factor from a differential area to a parallel coaxial-offset disc of radius `r` at
/// height `h`, the point `rho` off the axis (Siegel & Howell, Thermal Radiation Heat Transfer,
/// configuration factor catalogue): F = ½(1 − (h² + ρ² − r²)/√((h² + ρ² + r²)² − 4r²ρ²)).
fn disc_form_factor(h: f64, r: f64, rho: f64) -> f64 {
    let a = h * h + rho * rho;
    0.5 * (1.0 - (a - r * r) / ((a + r * r).powi(2) - 4.0 * r * r * rho * rho).sqrt())
}

fn disc_over_floor(strategy_spp: u32) -> Scene {
    // A disc light of radius 0.8 at height 1.5 facing down over a floor of albedo 0.5; the
    // stone is hidden under the floor; the sky is black. An orthographic camera at height 1
    // looks straight down on a 3 × 3 patch.
    scene(&format!(
        r#"(materials: {{ "a": (base: Lambert(albedo: Gray(0.5))) }}, surface: Material("a"),
            stage: (shape: Sphere(radius: 1.0), transform: (translate: (0.0, -10.0, 0.0)),
                    ground: Plane(height: 0.0, albedo: Gray(0.5)),
                    environment: Constant(Gray(0.0)),
                    lights: [Disc(center: (0.0, 1.5, 0.0), target: (0.0, 0.0, 0.0), radius: 0.8,
                                  radiance: Gray(2.0))],
                    camera: Orthographic(from: (0.0, 1.0, 0.0), to: (0.0, 0.0, 0.0),
                                         up: (0.0, 0.0, -1.0), height: 3.0),
                    render: (sampler: Independent, width: 24, height: 24, spp: {strategy_spp}, filter: Box)))"#
    ))
}

#[test]
fn area_light_over_lambert_floor_matches_closed_form_irradiance() {
    let s = disc_over_floor(64);
    let r = run(&s, &Control::default());
    let n = 24u32;
    let tested = z_test(
        &r,
        |x, y| {
            // Average the closed form over a 4×4 grid of the pixel's box footprint.
            let px = 3.0 / f64::from(n);
            let mut acc = 0.0;
            for i in 0..4 {
                for j in 0..4 {
                    let wx = (f64::from(x) + (f64::from(i) + 0.5) / 4.0) * px - 1.5;
                    let wz = (f64::from(y) + (f64::from(j) + 0.5) / 4.0) * px - 1.5;
                    let rho = (wx * wx + wz * wz).sqrt();
                    // Radiance = albedo/π · E = albedo · L · F.
                    acc += 0.5 * 2.0 * disc_form_factor(1.5, 0.8, rho) / 16.0;
                }
            }
            Some([acc; 3])
        },
        "disc light over a floor",
    );
    assert_eq!(tested, (n * n) as usize);
    // The centre pixel region is bright: F(1.5, 0.8, 0) = 0.8²/(0.8² + 1.5²) = 0.2215.
    let c = r.film.pixels[(12 * n + 12) as usize].mean()[0];
    assert!((c - 0.2215).abs() < 0.02, "{c}");
}

/// Sum over pixels of the variance of the pixel mean in channel `c` (a noise figure).
fn total_variance(r: &Rendered, c: usize) -> f64 {
    r.film
        .pixels
        .iter()
        .map(|p| f64::from(p.variance_of_mean()[c]))
        .sum()
}

/// Image mean and its standard error, per channel.
fn image_mean(r: &Rendered) -> ([f64; 3], [f64; 3]) {
    let n = r.film.pixels.len() as f64;
    let mut m = [0.0; 3];
    let mut v = [0.0; 3];
    for p in &r.film.pixels {
        let (pm, pv) = (p.mean(), p.variance_of_mean());
        for c in 0..3 {
            m[c] += f64::from(pm[c]) / n;
            v[c] += f64::from(pv[c]) / (n * n);
        }
    }
    (m, v.map(f64::sqrt))
}

#[test]
fn light_only_bsdf_only_and_mis_agree() {
    // The studio's three soft boxes and sky over a coated glossy stone: every estimator is
    // unbiased, so per-pixel means agree within their noise, and so do image means. The z-test
    // needs each estimator's sample variance to be a fair estimate of its error. That fails where
    // a strategy meets the light only a few times per pixel: a pixel short of rare hits looks both
    // dim and quiet. It happens at silhouettes, where a few samples of the pixel graze the stone
    // (BSDF-only on the soft boxes, light-only on the glossy reflection of the sky: |z| up to 5
    // at 4096 spp there, ≤ 2 inside), so per-pixel tests skip pixels whose 5 × 5 neighbourhood
    // sees more than one thing, and use 2048 spp so that hits are not rare elsewhere. The floor is off: with it, light
    // reaches the floor through the stone (floor → stone → soft box), paths BSDF sampling alone
    // finds so rarely that its sample variance underestimates its error (at 4096 spp under the
    // test sky below: BSDF-only 20 % low on some floor pixels, |z| up to 6.8, while light-only
    // and MIS agree to |z| ≤ 1.4), so the z-test would not be valid for it.
    let text = r#"(materials: { "glossy": (coats: [(ior: 1.5, roughness: 8.0, thickness: 0.5,
                                                    absorption: Rgb(0.1, 0.4, 0.8))],
                                          base: Lambert(albedo: Gray(0.6))) },
                   surface: Material("glossy"),
                   stage: (ground: Off,
                           render: (sampler: Independent, width: 24, height: 18, spp: 2048, max_depth: 4)))"#;
    let s = scene(text);
    let renders: Vec<(Strategy, Rendered)> =
        [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly]
            .into_iter()
            .map(|strategy| {
                let c = Control {
                    strategy,
                    ..Control::default()
                };
                (strategy, run(&s, &c))
            })
            .collect();
    let (mis_m, mis_s) = image_mean(&renders[0].1);
    for (strategy, r) in &renders[1..] {
        let (m, sd) = image_mean(r);
        for c in 0..3 {
            let z = (m[c] - mis_m[c]) / (sd[c].powi(2) + mis_s[c].powi(2)).sqrt();
            // Family of 6 comparisons at α = 0.001.
            assert!(
                z.abs() < z_crit(6),
                "{strategy:?} channel {c}: {} vs MIS {} (z {z:.2})",
                m[c],
                mis_m[c]
            );
        }
        // Per pixel: the difference of two independent estimates, z-tested.
        let mis = &renders[0].1;
        let n = compare_pixels(
            r,
            mis,
            |k| interior(mis, k),
            &format!("{strategy:?} vs MIS"),
        );
        assert!(n > 100, "{n} interior pixels");
    }
    // MIS is the least noisy of the three over the image.
    let noise = |r: &Rendered| total_variance(r, 1);
    for (strategy, r) in &renders {
        let (m, sd) = image_mean(r);
        eprintln!(
            "studio, {strategy:?}: image mean G {:.5} ± {:.5}, summed pixel variance {:.3e}",
            m[1],
            sd[1],
            noise(r)
        );
    }
    assert!(noise(&renders[0].1) < noise(&renders[1].1));
    assert!(noise(&renders[0].1) < noise(&renders[2].1));
}

#[test]
fn renders_are_bit_identical_for_one_and_two_threads() {
    let gem = GemRecipe::load(Path::new("gems/lepidolite.ron")).unwrap();
    let mut s = gem.compile().unwrap();
    s.stage.render.width = 40;
    s.stage.render.height = 30;
    s.stage.render.spp = 6;
    let one = run(&s, &threads(1));
    let two = run(&s, &threads(2));
    assert_eq!(one.film, two.film);
    assert!(one.film.samples() == 40 * 30 * 6);
    // A different seed gives a different image.
    s.stage.render.seed = 1;
    let other = run(&s, &threads(2));
    assert_ne!(one.film, other.film);
}

#[test]
fn translucent_renders_are_bit_identical_for_one_and_two_threads() {
    // Issue 17: paths through a body (free flights, phase sampling, a hero channel per path) draw
    // only from their own pixel's sample slots, so the film does not depend on the threads.
    for name in ["sunstone-pink", "milky-stone", "tinted-glass-sphere"] {
        let gem = GemRecipe::load(Path::new(&format!("gems/{name}.ron"))).unwrap();
        let mut s = gem.compile().unwrap();
        assert!(s.effects.on(Effect::Transmission) && s.effects.on(Effect::Medium));
        s.stage.render.width = 40;
        s.stage.render.height = 30;
        s.stage.render.spp = 6;
        let one = run(&s, &threads(1));
        let two = run(&s, &threads(2));
        assert_eq!(one.stats.dropped, 0, "{name}");
        assert!(one.film == two.film, "{name}: 1 and 2 threads differ");
        s.stage.render.seed = 1;
        assert!(
            run(&s, &threads(2)).film != one.film,
            "{name}: the seed changes nothing"
        );
    }
}

#[test]
fn stopping_early_returns_a_partial_film() {
    let s = furnace(0.5);
    let stop = std::sync::atomic::AtomicBool::new(true);
    let r = run(
        &s,
        &Control {
            cancel: Some(&stop),
            ..Control::default()
        },
    );
    assert!(r.stats.partial);
    assert_eq!(r.stats.spp_complete, 0);
    let past = std::time::Instant::now();
    let r = run(
        &s,
        &Control {
            deadline: Some(past),
            ..Control::default()
        },
    );
    assert!(r.stats.partial && r.film.samples() == 0);
}

#[test]
fn no_dropped_samples_over_the_catalogue() {
    let mut gems: Vec<_> = std::fs::read_dir("gems")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    gems.sort();
    assert!(gems.len() >= 7);
    for path in gems {
        let mut s = GemRecipe::load(&path).unwrap().compile().unwrap();
        s.stage.render.width = 64;
        s.stage.render.height = 48;
        s.stage.render.spp = 16;
        let r = run(&s, &Control::default());
        assert_eq!(r.stats.dropped, 0, "{}", path.display());
        assert_eq!(r.film.samples(), 64 * 48 * 16);
        let (m, _) = image_mean(&r);
        assert!(
            m.iter().all(|v| v.is_finite() && *v > 0.0),
            "{}: {m:?}",
            path.display()
        );
    }
}

/// Per-pixel z-test of the difference of two independent renders of the same scene.
fn assert_same_within_noise(a: &Rendered, b: &Rendered, what: &str) {
    compare_pixels(a, b, |_| true, what);
}

/// Whether every pixel within two pixels of pixel `k` saw the same thing first (material id):
/// the pixel's filter footprint (Gaussian, radius 1.5) does not straddle a silhouette.
fn interior(r: &Rendered, k: usize) -> bool {
    let (w, h) = (r.film.width as i64, r.film.height as i64);
    let (x, y) = (k as i64 % w, k as i64 / w);
    let m = r.film.pixels[k].material;
    (-2..=2).all(|dy| {
        (-2..=2).all(|dx| {
            let (u, v) = (x + dx, y + dy);
            (0..w).contains(&u)
                && (0..h).contains(&v)
                && r.film.pixels[(v * w + u) as usize].material == m
        })
    })
}

/// Per-pixel z-test of the difference of two independent estimates over the pixels `keep`
/// selects; returns how many were tested.
fn compare_pixels(a: &Rendered, b: &Rendered, keep: impl Fn(usize) -> bool, what: &str) -> usize {
    let tested: Vec<usize> = (0..a.film.pixels.len()).filter(|&k| keep(k)).collect();
    let zc = z_crit(tested.len() * 3);
    let mut max_z = 0.0f64;
    for &k in &tested {
        let (p, q) = (&a.film.pixels[k], &b.film.pixels[k]);
        let (vp, vq) = (p.variance_of_mean(), q.variance_of_mean());
        for c in 0..3 {
            let d = f64::from(p.mean()[c]) - f64::from(q.mean()[c]);
            let sd = (f64::from(vp[c]) + f64::from(vq[c])).sqrt();
            if sd > 0.0 {
                max_z = max_z.max(d.abs() / sd);
            }
            assert!(
                d.abs() <= zc * sd + 1e-5,
                "{what}: pixel {k} channel {c} differs by {d} (sd {sd})"
            );
        }
    }
    eprintln!(
        "{what}: {} pixels, max |z| {max_z:.2} (limit {zc:.2})",
        tested.len()
    );
    tested.len()
}

#[test]
fn a_cube_mesh_renders_like_the_slab_of_the_same_size() {
    let stage = |shape: &str, seed: u32| {
        format!(
            r#"(materials: {{ "m": (coats: [(ior: 1.5, roughness: 6.0)], base: Lambert(albedo: Gray(0.4))) }},
                surface: Material("m"),
                stage: (shape: {shape}, transform: (rotate: (0.0, 30.0, 0.0), scale: 0.5),
                        render: (sampler: Independent, width: 32, height: 24, spp: 64, seed: {seed})))"#
        )
    };
    let mesh = run(
        &scene(&stage(
            r#"Mesh(file: "tests/data/cube.obj", scale: 1.0)"#,
            1,
        )),
        &Control::default(),
    );
    let slab = run(
        &scene(&stage("Slab(size: (2.0, 2.0, 2.0))", 2)),
        &Control::default(),
    );
    assert_same_within_noise(&mesh, &slab, "cube mesh vs slab");
    // The stone covers a good part of the image (material id ≥ 0).
    let on_stone = mesh.film.pixels.iter().filter(|p| p.material >= 0).count();
    assert!(on_stone > 100, "{on_stone} pixels on the stone");
}

#[test]
fn environment_map_is_importance_sampled_without_bias() {
    // A 64 × 32 lat-long sky: dim blue with a warm "sun" of 16 × 8 pixels (≈ 1.2 sr) 15–60 times
    // brighter. It is large and not too bright so that BSDF sampling alone meets it often enough
    // for its sample variance to be a fair error estimate: with an 8 × 4-pixel sun 100× the sky,
    // points that see a sliver of it just above their horizon get about one BSDF hit in 2048
    // samples, and a pixel with none is both dim and quiet (|z| up to 15 against MIS, while
    // MIS and light-only agree to |z| 2.5; checked against brute-force integration of the map).
    let dir = std::env::temp_dir().join(format!("lapidary-envmap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sky.exr");
    let (w, h) = (64u32, 32u32);
    let mut chans = vec![vec![0.0f32; (w * h) as usize]; 3];
    for y in 0..h {
        for x in 0..w {
            let k = (y * w + x) as usize;
            let sun = (16..32).contains(&x) && (6..14).contains(&y);
            let v = if sun {
                [6.0, 4.5, 3.0]
            } else {
                [0.1, 0.2, 0.4]
            };
            for c in 0..3 {
                chans[c][k] = v[c];
            }
        }
    }
    let img = lapidary::image::ExrImage {
        width: w,
        height: h,
        channels: ["R", "G", "B"]
            .iter()
            .zip(chans)
            .map(|(n, data)| lapidary::image::Channel {
                name: n.to_string(),
                data,
            })
            .collect(),
        attributes: vec![],
    };
    lapidary::image::write_exr(&path, &img).unwrap();
    let text = format!(
        r#"(materials: {{ "m": (coats: [(ior: 1.5, roughness: 10.0)], base: Lambert(albedo: Gray(0.5))) }},
            surface: Material("m"),
            stage: (shape: Sphere(radius: 1.0), lights: [], ground: Off,
                    environment: Map(file: {:?}, intensity: 1.0, rotate: 40.0),
                    render: (sampler: Independent, width: 24, height: 18, spp: 2048, max_depth: 3)))"#,
        path.display().to_string()
    );
    let s = scene(&text);
    assert!(s.effects.on(Effect::EnvironmentImportance));
    let mis = run(&s, &Control::default());
    let bsdf = run(
        &s,
        &Control {
            strategy: Strategy::BsdfOnly,
            ..Control::default()
        },
    );
    let light = run(
        &s,
        &Control {
            strategy: Strategy::LightOnly,
            ..Control::default()
        },
    );
    let inside = |k| interior(&mis, k);
    assert!(compare_pixels(&mis, &bsdf, inside, "env map: MIS vs BSDF only") > 80);
    assert!(compare_pixels(&mis, &light, inside, "env map: MIS vs light only") > 80);
    // Importance sampling the sun pays: MIS has far less noise than BSDF sampling alone.
    let noise = |r: &Rendered| total_variance(r, 0);
    eprintln!(
        "env map: summed pixel variance MIS {:.3e}, light only {:.3e}, BSDF only {:.3e}",
        noise(&mis),
        noise(&light),
        noise(&bsdf)
    );
    assert!(
        noise(&mis) * 4.0 < noise(&bsdf),
        "{} vs {}",
        noise(&mis),
        noise(&bsdf)
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn depth_of_field_code_changes_nothing_when_the_aperture_is_zero() {
    // The lens numbers are drawn whether or not the lens is used, so forcing the effect's code on
    // for a pinhole camera renders bit-identically; with an aperture the image changes.
    let text = |aperture: f32| {
        format!(
            r#"(materials: {{ "a": (coats: [(ior: 1.5, roughness: 3.0)], base: Lambert(albedo: Gray(0.5))) }},
                surface: Material("a"),
                stage: (camera: Perspective(from: (0.0, 2.6, 4.2), to: (0.0, 0.15, 0.0), fov: 30.0,
                                            aperture: {aperture}, focus_distance: 2.0),
                        render: (width: 24, height: 18, spp: 8)))"#
        )
    };
    let pinhole = scene(&text(0.0));
    assert!(!pinhole.effects.on(Effect::DepthOfField));
    let world = World::new(&pinhole).unwrap();
    let r = |dof: bool, s: &Scene| {
        render(
            &world,
            &s.stage.camera,
            dof,
            &s.stage.render,
            &Control::default(),
        )
        .film
    };
    assert_eq!(r(false, &pinhole), r(true, &pinhole));
    let lens = scene(&text(0.2));
    assert!(lens.effects.on(Effect::DepthOfField));
    assert_ne!(r(true, &lens), r(false, &lens));
}

#[test]
fn reference_model_is_unbiased_under_every_strategy() {
    // The Reference model's `eval` is a random-walk estimate and its `pdf` only an approximation
    // of the walk's density; the integrator must still be unbiased with either strategy (the MIS
    // weights use the same approximate pdf on both sides, so they sum to one). 2048 spp: at 256
    // BSDF-only met the lights too rarely on a few pixels for a valid z-test (|z| 5.4 there; 3.7
    // at most at 2048 over 306 pixels).
    let s = scene(
        r#"(materials: { "r": (coats: [(ior: 1.5, roughness: 12.0, thickness: 1.0,
                                         absorption: Rgb(0.2, 0.5, 0.9))],
                               base: Conductor(metal: Gold, roughness: 15.0),
                               model: Reference(samples: 2, max_depth: 64)) },
            surface: Material("r"),
            stage: (ground: Off,
                    render: (sampler: Independent, width: 32, height: 24, spp: 2048, max_depth: 3)))"#,
    );
    let mis = run(&s, &Control::default());
    assert_eq!(mis.stats.dropped, 0);
    for strategy in [Strategy::LightOnly, Strategy::BsdfOnly] {
        let other = run(
            &s,
            &Control {
                strategy,
                ..Control::default()
            },
        );
        let what = format!("Reference model, {strategy:?} vs MIS");
        assert!(compare_pixels(&other, &mis, |k| interior(&mis, k), &what) > 30);
    }
}
