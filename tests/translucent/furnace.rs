//! Claim 1, white furnace. A body that neither absorbs nor emits only redirects light, so under a constant
//! sky of radiance 1 (no floor, no lights) every pixel is 1, whatever the boundary and the
//! scattering inside — provided refraction switches media and undoes its `1/η²`, the rough
//! boundary's multiple-scattering lobe returns exactly what single scattering loses, next-event
//! estimation through the rough boundary is weighted right against BSDF sampling, free flights
//! with chromatic `σs` keep each channel unbiased (path-level spectral MIS), and neither
//! `max_depth` nor `medium_depth` cuts paths that matter.
//!
//! The scene: a unit sphere seen orthographically (view height 2, so it fills the frame's disc),
//! 32 × 32 pixels, box filter, the independent sampler, `max_depth` 1024, `medium_depth` 4096.
//! Bodies (every one at η 1.3, 1.55 and 2.4, all with MIS): smooth and clear; rough (GGX, Smith)
//! m 10° and α 0.5, clear; smooth with isotropic scattering `σs = (1, 3, 10)` per unit; rough
//! m 10° with Henyey–Greenstein g 0.7 and the same `σs`. At η 1.55 the m 10° body is also
//! rendered with BSDF sampling only. 16 configurations.
//!
//! CI: 64 spp (65 536 paths per configuration, ≈ 4 s on two cores). Each of the 16 blocks of
//! 8 × 8 pixels (4 096 paths) and each channel is tested against 1 (16 · 16 · 3 = 768 tests,
//! overall significance 0.01, Šidák: |z| ≤ 4.36), and so is each configuration's total per channel
//! (48 tests, 0.01: |z| ≤ 3.71). Zero-variance means must be 1 to 1e-5: smooth clear bodies
//! (every path exactly 1), and the channel mean of every pixel of the smooth scattering bodies
//! (every path's, see [`Config::channel_mean_exact`]). Negative control: the same sphere with the
//! uncompensated boundary (`RoughDielectric` without energy tables) fails (0.504 ± 0.003 at
//! η 2.4, α 0.5).
//!
//! Blocks are 8 × 8 pixels, not smaller, because the compensated rough boundary's path weights
//! are heavy-tailed: at η 2.4, α 0.5, 0.6 % of the paths weigh more than 10 (up to ~1 000) and
//! carry 12 % of the mean (kurtosis ≈ 5 000), so a block of a few hundred paths is skewed low
//! with an underestimated SE (16 spp, 4 × 4-pixel blocks: a silhouette block at 0.930 ± 0.016).
//! Light sampling alone through the m 10° lobe is worse (0.2 % of the paths above 100 carry half
//! the mean) and is not in the family; MIS and BSDF sampling are.
//!
//! **Finding 1 (fixed): a medium leak.** The channel-mean check caught one path of 65 536 (η 1.55,
//! smooth, isotropic σs; pixel (17, 17), sample 34) with radiance 0 after 4 106 rays: a scattering
//! point sampled within rounding of the sphere started a ray that missed the sphere (its exit
//! root rounds to ≤ 0), so the path left the stone without crossing the boundary and scattered on
//! in the interior medium, outside, until `medium_depth`. About one path in 10⁴–10⁵ at σs 10–100
//! per unit (3 of 100 000 at σs 100). Fixed in src/render/integrator.rs (`keep_off_the_boundary`:
//! a scattering point closer than the spawn offset to the tangent plane of the surface ahead is
//! moved back to that offset, 0 leaks in the same 100 000 paths);
//! [`a_scattering_point_on_the_boundary_does_not_leak`] pins the path.
//!
//! **Finding 2 (fixed): compensation-table noise.** The compensated boundary's lobe returns
//! `1 − E(μ)` of single-scattering albedos tabulated by stratified Monte Carlo; with the coats'
//! 64 entries of 4 096 samples (`RoughDielectric::with_energy_tables`) each entry's noise (the
//! albedo `R + T` of the compensated interface off 1 by up to ±0.2 %, e.g. +0.0020 ± 0.0002 at
//! μ 0.6 from below, η 1.55, m 10°) showed in a furnace, since light meets a stone's boundary
//! many times: over 1 048 576 paths per configuration 1.000 56 ± 0.000 36 (η 1.3, m 10°),
//! 1.000 64 ± 0.000 47 (η 1.55) and 1.003 54 ± 0.000 94 (η 2.4, z 3.8: failed). A body's
//! boundary now uses 16 384 samples per entry (`scene::body::BOUNDARY_GRID` = 64): the same run
//! gives 0.999 83 ± 0.000 36, 0.999 54 ± 0.000 47 and 1.002 10 ± 0.000 93 (α 0.5: 0.999 51,
//! 0.998 83, 0.998 54), and passes ([`furnace_default_tables_full`], ≈ 20 s). With 128² · 4
//! samples per entry ([`furnace_full`]) the bodies give 0.999 87 ± 0.000 36, 0.999 47 ± 0.000 47
//! and 1.001 40 ± 0.000 92. (Those precise tables still leave ≤ 0.06 % deficits, e.g.
//! −0.000 33 ± 0.000 04 at μ 0.95 from above: linear interpolation between the 64 entries.)

use super::{Acc, build, gem, z_limit};
use lapidary::bsdf::{Bsdf, RoughDielectric};
use lapidary::render::{Control, Strategy, World, render};
use std::time::Instant;

/// Overall significance of each family (blocks, totals).
const ALPHA: f64 = 0.01;
/// Image size and block size in pixels.
const SIZE: u32 = 32;
const BLOCK: u32 = 8;
/// Samples per pixel in CI and in the full runs.
const SPP: u32 = 64;
const SPP_FULL: u32 = 1024;
/// Samples per entry of the precise compensation tables: `GRID² · 4`.
const PRECISE_GRID: usize = 128;

/// One furnace configuration.
#[derive(Clone, Debug)]
struct Config {
    label: String,
    body: String,
    strategy: Strategy,
    /// Whether the interior scatters (the path must then trace many rays).
    scatters: bool,
    /// Whether the boundary is rough.
    rough: bool,
}

impl Config {
    /// A smooth boundary around a non-absorbing scattering interior: every free flight has
    /// `value = pdf` per channel and the boundary's weights are colourless and cancel over a path,
    /// so each path's radiance is `r_c / mean(r)` and its channel mean is exactly 1.
    fn channel_mean_exact(&self) -> bool {
        self.scatters && !self.rough
    }
}

fn configs() -> Vec<Config> {
    let sigma = "scattering: (1.0, 3.0, 10.0)";
    let mut v = Vec::new();
    for eta in [1.3f32, 1.55, 2.4] {
        let mut add = |label: &str, body: String, strategy, scatters, rough| {
            v.push(Config {
                label: format!("η {eta} {label} {strategy:?}"),
                body,
                strategy,
                scatters,
                rough,
            })
        };
        let mis = Strategy::Mis;
        add("smooth clear", format!("(ior: {eta})"), mis, false, false);
        let m10 = format!("(ior: {eta}, roughness: 10.0)");
        add("rough m 10° clear", m10.clone(), mis, false, true);
        if eta == 1.55 {
            add("rough m 10° clear", m10, Strategy::BsdfOnly, false, true);
        }
        let a05 = format!("(ior: {eta}, alpha: 0.5)");
        add("rough α 0.5 clear", a05, mis, false, true);
        let iso = format!("(ior: {eta}, medium: ({sigma}))");
        add("smooth σs (1,3,10) isotropic", iso, mis, true, false);
        let hg = format!(
            "(ior: {eta}, roughness: 10.0, medium: ({sigma}, phase: HenyeyGreenstein(g: 0.7)))"
        );
        add("rough m 10° σs (1,3,10) HG 0.7", hg, mis, true, true);
    }
    v
}

fn stage(spp: u32) -> String {
    format!(
        "(shape: Sphere(radius: 1.0), ground: Off, lights: [], environment: Constant(Gray(1.0)),
          camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0), height: 2.0),
          render: (width: {SIZE}, height: {SIZE}, spp: {spp}, max_depth: 1024, medium_depth: 4096,
                   sampler: Independent, filter: Box, seed: 17))"
    )
}

/// What a configuration rendered.
struct Outcome {
    label: String,
    total: Acc,
    blocks: Vec<Acc>,
    rays_per_path: f64,
    dropped: u64,
    /// Largest `|Σ_c sum_c / (3 n) − 1|` over the pixels.
    channel_mean_error: f64,
    secs: f64,
}

/// Which boundary replaces the recipe's for a run.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Boundary {
    /// As the recipe builds it (`with_energy_tables_at(BOUNDARY_GRID)`).
    Recipe,
    /// Rough boundaries with compensation tables of `PRECISE_GRID² · 4` samples per entry.
    Precise,
    /// Rough boundaries without compensation (the negative control).
    Uncompensated,
}

/// The plain (uncompensated) rough interface of the world's body, if it is rough.
fn plain_boundary(world: &World) -> Option<RoughDielectric> {
    match world.materials.last()?.as_ref()? {
        Bsdf::Dielectric(d) => Some(RoughDielectric {
            energy: None,
            ..d.clone()
        }),
        _ => None,
    }
}

fn run(c: &Config, spp: u32, boundary: Boundary) -> Outcome {
    let (scene, mut world) = build(&gem(&c.body, &stage(spp)));
    assert_eq!(
        world.media.len(),
        2,
        "{}: the body has an interior",
        c.label
    );
    if let Some(plain) = plain_boundary(&world) {
        let replace = match boundary {
            Boundary::Recipe => None,
            Boundary::Precise => Some(super::measure::with_tables(&plain, PRECISE_GRID)),
            Boundary::Uncompensated => Some(plain),
        };
        if let Some(b) = replace {
            *world.materials.last_mut().expect("body") = Some(Bsdf::Dielectric(b));
        }
    }
    let start = Instant::now();
    let r = render(
        &world,
        &scene.stage.camera,
        false,
        &scene.stage.render,
        &Control {
            threads: Some(2),
            strategy: c.strategy,
            ..Control::default()
        },
    );
    let secs = start.elapsed().as_secs_f64();
    let nb = SIZE / BLOCK;
    let mut blocks = vec![Acc::default(); (nb * nb) as usize];
    let mut total = Acc::default();
    let mut channel_mean_error = 0.0f64;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let p = &r.film.pixels[(y * SIZE + x) as usize];
            let avg = p.radiance_sum().iter().sum::<f64>() / (3.0 * f64::from(p.n.max(1)));
            channel_mean_error = channel_mean_error.max((avg - 1.0).abs());
            blocks[((y / BLOCK) * nb + x / BLOCK) as usize].add_pixel(p);
            total.add_pixel(p);
        }
    }
    Outcome {
        label: c.label.clone(),
        total,
        blocks,
        rays_per_path: r.stats.rays as f64 / r.stats.paths.max(1) as f64,
        dropped: r.stats.dropped,
        channel_mean_error,
        secs,
    }
}

/// Renders every configuration, prints the table and returns the failures.
fn furnace(configs: &[Config], spp: u32, boundary: Boundary) -> Vec<String> {
    let z_block = z_limit(ALPHA, configs.len() * (SIZE / BLOCK).pow(2) as usize * 3);
    let z_total = z_limit(ALPHA, configs.len() * 3);
    println!(
        "\nfurnace, {} paths per configuration (|z| limits: block {z_block:.2}, total {z_total:.2})",
        spp * SIZE * SIZE
    );
    println!(
        "{:<52} {:>18} {:>18} {:>18} {:>8} {:>7} {:>6} {:>6}",
        "configuration",
        "R mean ± SE",
        "G mean ± SE",
        "B mean ± SE",
        "worst z",
        "rays/p",
        "s",
        "block"
    );
    let mut failures = Vec::new();
    for c in configs {
        let o = run(c, spp, boundary);
        let cell = |c: usize| format!("{:.5}±{:.5}", o.total.mean(c), o.total.se(c));
        let (mut worst, mut worst_at) = (0.0f64, 0usize);
        for (b, acc) in o.blocks.iter().enumerate() {
            for ch in 0..3 {
                let z = acc.z(ch, 1.0);
                if z.abs() > worst.abs() {
                    (worst, worst_at) = (z, b);
                }
                if z.abs() > z_block {
                    failures.push(format!(
                        "{}: block {b} channel {ch}: {:.5} ± {:.5} (z {z:.2})",
                        o.label,
                        acc.mean(ch),
                        acc.se(ch)
                    ));
                }
            }
        }
        println!(
            "{:<52} {:>18} {:>18} {:>18} {:>8.2} {:>7.1} {:>6.2} {:>6}",
            o.label,
            cell(0),
            cell(1),
            cell(2),
            worst,
            o.rays_per_path,
            o.secs,
            worst_at
        );
        for ch in 0..3 {
            let z = o.total.z(ch, 1.0);
            if z.abs() > z_total {
                failures.push(format!(
                    "{}: total channel {ch}: {:.5} ± {:.5} (z {z:.2})",
                    o.label,
                    o.total.mean(ch),
                    o.total.se(ch)
                ));
            }
        }
        if o.dropped > 0 {
            failures.push(format!("{}: {} samples dropped", o.label, o.dropped));
        }
        // Not vacuous: rough boundaries spread the paths, media scatter them many times.
        if c.rough && o.total.se(0) == 0.0 {
            failures.push(format!(
                "{}: no variance: the boundary is not rough",
                o.label
            ));
        }
        if c.channel_mean_exact() && o.channel_mean_error > 1e-5 {
            failures.push(format!(
                "{}: a pixel's channel mean is off 1 by {:.2e}",
                o.label, o.channel_mean_error
            ));
        }
        if c.scatters && o.rays_per_path < 10.0 {
            failures.push(format!(
                "{}: {:.1} rays per path: the medium does not scatter",
                o.label, o.rays_per_path
            ));
        }
    }
    failures
}

/// 65 536 paths per configuration, blocks and totals (module docs).
#[test]
fn furnace_sphere_is_one_on_every_block() {
    let failures = furnace(&configs(), SPP, Boundary::Recipe);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Negative control: without the multiple-scattering lobe a rough boundary loses energy at every
/// event (most at α 0.5 and η 2.4, where paths meet the boundary many times), and the furnace
/// sees it in the total. 16 spp (16 384 paths).
#[test]
fn furnace_rejects_an_uncompensated_boundary() {
    let c: Vec<Config> = configs()
        .into_iter()
        .filter(|c| c.label.starts_with("η 2.4 rough α 0.5"))
        .collect();
    assert_eq!(c.len(), 1);
    let wrong = furnace(&c, 16, Boundary::Uncompensated);
    assert!(
        wrong.iter().any(|f| f.contains("total")),
        "an uncompensated boundary passes the furnace"
    );
}

/// The recipe's `compensation: false` (and the `compensation=off` knob) is the plain interface
/// of the negative control above — the peers' rough dielectric —, bit for bit: the same image
/// as replacing the boundary by hand, which loses energy in the furnace; the default keeps the
/// compensated boundary.
#[test]
fn the_compensation_switch_gives_the_plain_interface() {
    let body = "(ior: 2.4, alpha: 0.5, compensation: false)";
    let c = Config {
        label: "η 2.4 rough α 0.5 compensation: false".into(),
        body: body.into(),
        strategy: Strategy::Mis,
        scatters: false,
        rough: true,
    };
    let (_, world) = build(&gem(body, &stage(16)));
    match world.materials.last() {
        Some(Some(Bsdf::Dielectric(d))) => assert!(d.energy.is_none(), "still compensated"),
        other => panic!("not a rough boundary: {other:?}"),
    }
    let switched = run(&c, 16, Boundary::Recipe);
    let by_hand = run(
        &Config {
            body: "(ior: 2.4, alpha: 0.5)".into(),
            ..c.clone()
        },
        16,
        Boundary::Uncompensated,
    );
    assert_eq!(
        switched.total.sum, by_hand.total.sum,
        "not the plain interface"
    );
    let mean = switched.total.sum.iter().sum::<f64>() / (3.0 * switched.total.n as f64);
    assert!(mean < 0.9, "the plain interface keeps its energy: {mean}");
    // The knob, over a recipe that asks for compensation.
    let (mut scene, _) = build(&gem("(ior: 2.4, alpha: 0.5)", &stage(16)));
    let knobs: lapidary::scene::Knobs = "compensation=off".parse().unwrap();
    knobs.apply(&mut scene, "test").unwrap();
    let world = World::new(&scene).unwrap();
    match world.materials.last() {
        Some(Some(Bsdf::Dielectric(d))) => assert!(d.energy.is_none(), "the knob did not reach it"),
        other => panic!("not a rough boundary: {other:?}"),
    }
}

/// 1 048 576 paths per configuration; rough boundaries get compensation tables of 128² · 4
/// samples per entry, so the furnace tests the integrator and the media rather than the noise of
/// the default tables (module docs). ≈ 30 s on two cores.
#[test]
#[ignore = "slow: cargo test --release --test translucent furnace_full -- --ignored --nocapture"]
fn furnace_full() {
    let failures = furnace(&configs(), SPP_FULL, Boundary::Precise);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The rough clear bodies at 1 048 576 paths with the boundary exactly as a recipe builds it
/// (`BOUNDARY_GRID` tables; module docs, finding 2).
#[test]
#[ignore = "slow: cargo test --release --test translucent -- --ignored furnace_default_tables_full"]
fn furnace_default_tables_full() {
    let c: Vec<Config> = configs()
        .into_iter()
        .filter(|c| c.rough && !c.scatters && c.strategy == Strategy::Mis)
        .collect();
    let failures = furnace(&c, SPP_FULL, Boundary::Recipe);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The path the furnace caught leaking (before the fix in `keep_off_the_boundary`,
/// src/render/integrator.rs): η 1.55, smooth, isotropic `σs = (1, 3, 10)`; pixel (17, 17),
/// sample 34 of the CI render. Its 48th scattering event fell within rounding of the sphere, the
/// next ray started there missed the sphere, and the path scattered on in the interior medium
/// outside the stone until `medium_depth` (4 106 rays, radiance 0). Its channel mean must be
/// exactly 1 like every other path of this body (see [`Config::channel_mean_exact`]).
#[test]
fn a_scattering_point_on_the_boundary_does_not_leak() {
    use glam::Vec2;
    use lapidary::render::{CameraRays, FilterSampler, trace};
    use lapidary::sampler::PixelSampler;
    use lapidary::spectrum::RgbSample;
    let c = configs()
        .into_iter()
        .find(|c| c.label.starts_with("η 1.55 smooth σs"))
        .expect("config");
    let (scene, world) = build(&gem(&c.body, &stage(SPP)));
    let st = &scene.stage.render;
    let (x, y, s) = (17u32, 17u32, 34u32);
    let mut sampler = PixelSampler::new(st.sampler, st.seed, u64::from(y * SIZE + x), s);
    let offset = FilterSampler::new(st.filter).sample(sampler.get2d());
    let lens = sampler.get2d();
    let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + offset;
    let ray = CameraRays::new(&scene.stage.camera, SIZE, SIZE, false).ray(film, lens);
    let p = trace::<RgbSample>(&world, ray, &mut sampler, st.max_depth, Strategy::Mis);
    let mean = p.radiance.0.iter().sum::<f32>() / 3.0;
    println!("radiance {:?}, {} rays", p.radiance, p.rays);
    assert!(
        (mean - 1.0).abs() < 1e-5 && p.rays < 1000,
        "radiance {:?} after {} rays: the path left the stone without crossing its boundary",
        p.radiance,
        p.rays
    );
}
