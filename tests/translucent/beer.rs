//! Claim 2, Beer–Lambert through an absorbing slab, and claim 8, the free-flight estimator end
//! to end.
//!
//! The scene: a slab 4 × `D` × 4 (`D` = 0.5 thick along y, resting on y = 0) with a smooth
//! boundary, under a sky that is 1 straight up and 0 at and below the horizon
//! (`Gradient(zenith: 1, horizon: 0, nadir: 0)`: radiance `max(y, 0)`). Camera rays go straight up
//! through the slab at four points far from its sides, so every path stays on the normal: light
//! reflected back down sees black, light leaving the top sees exactly 1, and a pixel is the
//! slab's normal-incidence transmittance
//!
//! `T = (1 − R)² τ / (1 − R² τ²)`,  `R = ((η − 1)/(η + 1))²`,  `τ = exp(−σ D)`
//!
//! (the geometric series of internal reflections; e.g. Born & Wolf §1.6 for incoherent plates).
//! Paths differ only in the Fresnel branch taken (and Russian roulette), so the mean of many is
//! tested per ray and channel with its standard error.

use super::{Acc, build, gem, ray, trace_ray, z_limit};
use glam::Vec3;
use lapidary::medium::Medium;
use lapidary::render::{Strategy, World};

/// Slab thickness, object units.
const D: f64 = 0.5;
/// Absorption per object unit per channel.
const SIGMA_A: [f64; 3] = [0.2, 1.0, 3.0];
/// Paths per camera ray.
const N: u32 = 50_000;
/// Overall significance of each family.
const ALPHA: f64 = 0.01;
/// Points `(x, z)` the camera rays pass through.
const POINTS: [(f32, f32); 4] = [(0.0, 0.0), (0.3, -0.2), (-0.7, 0.5), (1.1, 1.3)];

fn stage(extra: &str) -> String {
    format!(
        "(shape: Slab(size: (4.0, {D:?}, 4.0)), ground: Off, lights: [],
          environment: Gradient(zenith: Gray(1.0), horizon: Gray(0.0), nadir: Gray(0.0)),
          camera: Orthographic(from: (0.0, -5.0, 0.0), to: (0.0, 0.0, 0.0), up: (0.0, 0.0, 1.0),
                               height: 1.0),
          {extra})"
    )
}

/// Normal-incidence Fresnel reflectance.
fn r0(eta: f64) -> f64 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// The slab's transmittance for `τ` (module docs).
fn slab(eta: f64, tau: f64) -> f64 {
    let r = r0(eta);
    (1.0 - r).powi(2) * tau / (1.0 - r * r * tau * tau)
}

/// Paths along the upward rays through `POINTS` scaled by `scale`, per ray.
fn rays_up(world: &World, scale: f32, key: u64) -> Vec<Acc> {
    POINTS
        .iter()
        .enumerate()
        .map(|(i, &(x, z))| {
            let o = Vec3::new(x * scale, -5.0 * scale, z * scale);
            trace_ray(
                world,
                ray(o, Vec3::Y),
                N,
                &[key, i as u64],
                1024,
                Strategy::Mis,
            )
        })
        .collect()
}

fn pooled(v: &[Acc]) -> Acc {
    let mut a = Acc::default();
    v.iter().for_each(|x| a.merge(x));
    a
}

/// Per ray and channel `|z| ≤` the family's limit against `expected`; returns the worst |z| and
/// the failures.
fn z_test(what: &str, per_ray: &[Acc], expected: [f64; 3], limit: f64) -> (f64, Vec<String>) {
    let mut worst = 0.0f64;
    let mut failures = Vec::new();
    for (i, a) in per_ray.iter().enumerate() {
        for (c, &e) in expected.iter().enumerate() {
            let z = a.z(c, e);
            worst = worst.max(z.abs());
            if z.abs() > limit {
                failures.push(format!(
                    "{what}: ray {i} channel {c}: {:.6} ± {:.6}, expected {e:.6} (z {z:.2})",
                    a.mean(c),
                    a.se(c)
                ));
            }
        }
    }
    (worst, failures)
}

/// Beer–Lambert at η 1.5 and 2.4: 4 rays × 50 000 paths per slab, each ray and channel tested
/// (24 tests at overall significance 0.01, Šidák). Negative controls on the pooled 200 000 paths
/// (6 tests at 0.01): ignoring the Fresnel factors (`T = τ`) fails at both IORs, ignoring the
/// internal reflections (`(1 − R)² τ`, 2.4 % off in red at η 2.4) fails at η 2.4.
#[test]
fn beer_lambert_slab_matches_the_closed_form() {
    let limit = z_limit(ALPHA, 2 * POINTS.len() * 3);
    let pooled_limit = z_limit(ALPHA, 6);
    let tau = SIGMA_A.map(|s| (-s * D).exp());
    let mut failures = Vec::new();
    for eta in [1.5f64, 2.4] {
        let body = format!(
            "(ior: {eta:?}, medium: (absorption: ({:?}, {:?}, {:?})))",
            SIGMA_A[0], SIGMA_A[1], SIGMA_A[2]
        );
        let (_, world) = build(&gem(&body, &stage("")));
        let per_ray = rays_up(&world, 1.0, eta.to_bits());
        let expected = tau.map(|t| slab(eta, t));
        let (worst, f) = z_test(&format!("η {eta}"), &per_ray, expected, limit);
        failures.extend(f);
        let all = pooled(&per_ray);
        println!(
            "η {eta}: R {:.5}; T expected {expected:.6?}; measured {:.6?} ± {:.6?}; worst ray |z| \
             {worst:.2} (limit {limit:.2})",
            r0(eta),
            [all.mean(0), all.mean(1), all.mean(2)],
            [all.se(0), all.se(1), all.se(2)]
        );
        // Negative controls: the measurement tells these wrong models apart.
        let no_fresnel = tau;
        let single_pass = tau.map(|t| (1.0 - r0(eta)).powi(2) * t);
        for (name, wrong, must_fail) in [
            ("T = τ", no_fresnel, true),
            ("T = (1−R)² τ", single_pass, eta > 2.0),
        ] {
            let z: Vec<f64> = (0..3).map(|c| all.z(c, wrong[c])).collect();
            println!("  control {name}: z {z:.1?}");
            if must_fail && z.iter().all(|z| z.abs() <= pooled_limit) {
                failures.push(format!(
                    "η {eta}: the wrong model {name} is accepted: z {z:?}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `colour: c, distance: D` is `absorption: −ln(c)/D` (the same medium to 1e-6 and the same
/// pixel values to 1e-5 on the same random numbers), and a stone scaled ×2 by the stage keeps its
/// look: coefficients are per object unit (the ×2 slab, twice as thick in world units, transmits
/// the same T; 24 tests at 0.01).
#[test]
fn colour_form_and_stage_scale_keep_the_transmittance() {
    let eta = 1.5f64;
    let tau = SIGMA_A.map(|s| (-s * D).exp());
    let coeffs = format!(
        "(ior: 1.5, medium: (absorption: ({:?}, {:?}, {:?})))",
        SIGMA_A[0], SIGMA_A[1], SIGMA_A[2]
    );
    let colour = format!(
        "(ior: 1.5, medium: (colour: Rgb({:?}, {:?}, {:?}), distance: {D:?}))",
        tau[0] as f32, tau[1] as f32, tau[2] as f32
    );
    let (_, a) = build(&gem(&coeffs, &stage("")));
    let (_, b) = build(&gem(&colour, &stage("")));
    let (Medium::Homogeneous(ma), Medium::Homogeneous(mb)) = (a.media[1], b.media[1]) else {
        panic!("absorbing bodies have homogeneous interiors: {:?}", a.media)
    };
    for c in 0..3 {
        let (x, y) = (ma.sigma_a.0[c], mb.sigma_a.0[c]);
        assert!(
            (x - y).abs() <= 1e-6 * x.max(1.0),
            "channel {c}: {x} vs {y}"
        );
    }
    let (ra, rb) = (rays_up(&a, 1.0, 9), rays_up(&b, 1.0, 9));
    for (x, y) in ra.iter().zip(&rb) {
        for c in 0..3 {
            let (p, q) = (x.mean(c), y.mean(c));
            assert!((p - q).abs() <= 1e-5 * p, "channel {c}: {p} vs {q}");
        }
    }
    // Scaled ×2 about the origin: the slab spans y ∈ [0, 2D]; σ per world unit halves.
    let (_, s) = build(&gem(
        &coeffs,
        &stage("transform: (scale: 2.0), render: (max_depth: 1024)"),
    ));
    let per_ray = rays_up(&s, 2.0, 10);
    let expected = tau.map(|t| slab(eta, t));
    let limit = z_limit(ALPHA, 2 * POINTS.len() * 3);
    let (worst, mut failures) = z_test("scaled ×2", &per_ray, expected, limit);
    let (worst_a, f) = z_test("coefficients", &ra, expected, limit);
    failures.extend(f);
    println!("scaled ×2: worst |z| {worst:.2}; unscaled {worst_a:.2} (limit {limit:.2})");
    // Negative control: had the scale not been divided out, T would be τ².
    let wrong = tau.map(|t| slab(eta, t * t));
    let all = pooled(&per_ray);
    assert!(
        (0..3).any(|c| all.z(c, wrong[c]).abs() > limit),
        "the unscaled coefficients are accepted"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The free-flight estimator end to end (path-level spectral MIS over a hero channel,
/// `src/medium/mod.rs`): through an index-matched slab (η 1.0001, `R` ≈ 2.5e-9) of chromatic
/// `σa = (0.3, 0, 1)`, `σs = (0.5, 2, 6)` with `medium_depth: 0`, a scattered path ends, so the
/// mean is the probability of passing unscattered, `exp(−σt D)` = (0.670, 0.368, 0.030) per
/// channel — although every distance is sampled from one channel's `σt`. 4 rays × 50 000 paths,
/// 12 tests at 0.01. Controls: the pooled mean rejects `exp(−σs D)` and `exp(−σa D)`;
/// `medium_depth: 1` adds single scattering (the pooled mean rises by > 10 SE); with
/// `medium_scattering: false` nothing is sampled and every path is `exp(−σa D)` (to 1e-4).
#[test]
fn free_flight_passes_unscattered_with_exp_minus_sigma_t() {
    let sa = [0.3f64, 0.0, 1.0];
    let ss = [0.5f64, 2.0, 6.0];
    let medium = format!(
        "medium: (absorption: ({:?}, {:?}, {:?}), scattering: ({:?}, {:?}, {:?}))",
        sa[0], sa[1], sa[2], ss[0], ss[1], ss[2]
    );
    let body = format!("(ior: 1.0001, {medium})");
    let r = r0(1.0001);
    let boundary = |t: f64| (1.0 - r).powi(2) * t / (1.0 - r * r * t * t);
    let expected: [f64; 3] = std::array::from_fn(|c| boundary((-(sa[c] + ss[c]) * D).exp()));
    let limit = z_limit(ALPHA, POINTS.len() * 3);
    let run = |render: &str, key| {
        let (_, w) = build(&gem(&body, &stage(&format!("render: ({render})"))));
        rays_up(&w, 1.0, key)
    };
    let per_ray = run("medium_depth: 0", 21);
    let (worst, mut failures) = z_test("medium_depth 0", &per_ray, expected, limit);
    let all = pooled(&per_ray);
    println!(
        "unscattered: expected {expected:.5?}, measured {:.5?} ± {:.6?}, worst |z| {worst:.2} \
         (limit {limit:.2})",
        [all.mean(0), all.mean(1), all.mean(2)],
        [all.se(0), all.se(1), all.se(2)]
    );
    for (name, sigma) in [("exp(−σs D)", ss), ("exp(−σa D)", sa)] {
        let wrong: [f64; 3] = std::array::from_fn(|c| boundary((-sigma[c] * D).exp()));
        let z: Vec<f64> = (0..3).map(|c| all.z(c, wrong[c])).collect();
        println!("  control {name}: z {z:.1?}");
        if z.iter().all(|z| z.abs() <= limit) {
            failures.push(format!("the wrong model {name} is accepted: z {z:?}"));
        }
    }
    let one = pooled(&run("medium_depth: 1", 22));
    let rise: Vec<f64> = (0..3)
        .map(|c| (one.mean(c) - all.mean(c)) / one.se(c).hypot(all.se(c)))
        .collect();
    println!("  medium_depth 1 adds single scattering: rise {rise:.1?} SE");
    if !rise.iter().any(|&z| z > 10.0) {
        failures.push(format!("medium_depth 1 adds nothing: {rise:?}"));
    }
    let off = pooled(&run("medium_depth: 0, medium_scattering: false", 23));
    for (c, &s) in sa.iter().enumerate() {
        let e = boundary((-s * D).exp());
        // To 1e-4: each spawned ray starts 2e-5 units off the surface (`OFFSET_SCALE`), so the
        // segment inside is that much shorter (measured 2.1e-5 relative at σ 1).
        if (off.mean(c) - e).abs() > 1e-4 * e.max(1e-3) || off.se(c) > 1e-6 {
            failures.push(format!(
                "medium_scattering false, channel {c}: {:.7} ± {:.1e}, expected exactly {e:.7}",
                off.mean(c),
                off.se(c)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
