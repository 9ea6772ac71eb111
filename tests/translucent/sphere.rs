//! Claim 3, a clear glass sphere under a gradient sky, per camera ray against an independent
//! branch sum; claim 4, the camera inside the stone.
//!
//! A smooth dielectric turns each camera ray into a random walk over a binary tree of Fresnel
//! branches: the renderer takes reflection with probability `F` and transmission with `1 − F`, and
//! its weights (1, and `1/η²` in, `η²` out, which cancel over a closed path) make the mean over
//! paths of one fixed ray equal to the deterministic sum over branches of
//! `Π F or (1 − F)` × the sky's radiance where the branch leaves. That sum is computed here in
//! f64 with its own ray–sphere intersection, Snell refraction and Fresnel equations: the external
//! reflection leaves the convex sphere at once; the refracted ray meets the far side at the same
//! internal angle again and again (sphere symmetry), each time leaving with `1 − F` and reflecting
//! with `F`, until the remaining weight is below 1e-15.

use super::{Acc, build, fresnel, gem, ray, trace_ray, z_limit};
use glam::{DVec3, Vec3};
use lapidary::geometry::MediumId;
use lapidary::render::{Control, Strategy, render};

/// Overall significance of each family.
const ALPHA: f64 = 0.01;
/// The sky: radiance at y = 1, 0, −1, linear in y on each hemisphere.
const ZENITH: [f64; 3] = [0.1, 0.3, 0.9];
const HORIZON: [f64; 3] = [0.9, 0.8, 0.6];
const NADIR: [f64; 3] = [0.25, 0.15, 0.05];
/// Paths per camera ray.
const N: u32 = 20_000;
/// Camera ray positions `(x, y)` on the plane z = 5 (rays along −z; the last misses the sphere).
const POINTS: [(f64, f64); 9] = [
    (0.0, 0.0),
    (0.3, 0.1),
    (-0.5, 0.4),
    (0.2, -0.7),
    (0.85, 0.1),
    (-0.1, 0.93),
    (0.6, -0.6),
    (0.05, -0.97),
    (1.2, 0.3),
];

fn sky(d: DVec3) -> [f64; 3] {
    let y = d.y.clamp(-1.0, 1.0);
    let end = if y >= 0.0 { ZENITH } else { NADIR };
    std::array::from_fn(|c| HORIZON[c] * (1.0 - y.abs()) + end[c] * y.abs())
}

/// Refraction of unit `d` through a surface with unit normal `n` facing against `d`, relative index
/// `e` = incident / transmitted; `None` under total internal reflection.
fn refract(d: DVec3, n: DVec3, e: f64) -> Option<DVec3> {
    let cos_i = -d.dot(n);
    let k = 1.0 - e * e * (1.0 - cos_i * cos_i);
    (k >= 0.0).then(|| (e * d + (e * cos_i - k.sqrt()) * n).normalize())
}

fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - 2.0 * d.dot(n) * n
}

/// Which branches [`branch_sum`] follows (the full sum, or a wrong model for the controls).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Branches {
    All,
    /// No internal reflections: the first exit only.
    FirstExit,
}

/// The mean radiance along the camera ray from `o` along unit `d` outside a unit sphere at the
/// origin of relative index `eta` (module docs).
fn branch_sum(o: DVec3, d: DVec3, eta: f64, which: Branches) -> [f64; 3] {
    let b = o.dot(d);
    let disc = b * b - (o.dot(o) - 1.0);
    if disc <= 0.0 || -b - disc.sqrt() <= 0.0 {
        return sky(d);
    }
    let p = o + (-b - disc.sqrt()) * d;
    let n = p.normalize();
    let f = fresnel(-d.dot(n), eta);
    let mut l = sky(reflect(d, n)).map(|v| f * v);
    let Some(mut dir) = refract(d, n, 1.0 / eta) else {
        return l;
    };
    // Radiance weights: 1/η² entering, η² leaving (kept explicit; they cancel).
    let mut w = (1.0 - f) / (eta * eta);
    let mut p = p;
    while w > 1e-15 {
        // The far side of the chord from the surface point p: t = −2 p·dir.
        p = (p - 2.0 * p.dot(dir) * dir).normalize();
        let inward = -p;
        let fi = fresnel(dir.dot(p), 1.0 / eta);
        if let Some(out) = refract(dir, inward, eta) {
            let s = sky(out);
            for c in 0..3 {
                l[c] += w * (1.0 - fi) * eta * eta * s[c];
            }
        }
        if which == Branches::FirstExit {
            break;
        }
        w *= fi;
        dir = reflect(dir, inward);
    }
    l
}

fn gradient_stage() -> String {
    let c = |v: [f64; 3]| format!("Rgb({:?}, {:?}, {:?})", v[0], v[1], v[2]);
    format!(
        "(shape: Sphere(radius: 1.0), ground: Off, lights: [],
          environment: Gradient(zenith: {}, horizon: {}, nadir: {}),
          camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0), height: 2.4))",
        c(ZENITH),
        c(HORIZON),
        c(NADIR)
    )
}

/// Smooth glass (η 1.5) and diamond (η 2.4) spheres: 9 camera rays × 20 000 paths each, every ray
/// and channel against the branch sum (54 tests at overall significance 0.01, Šidák). Controls
/// (each must be rejected somewhere in the family): the branch sum at η + 0.05, and without the
/// internal reflections.
#[test]
fn glass_sphere_under_a_gradient_sky_matches_the_branch_sum() {
    let limit = z_limit(ALPHA, 2 * POINTS.len() * 3);
    let mut failures = Vec::new();
    for eta in [1.5f64, 2.4] {
        let (_, world) = build(&gem(&format!("(ior: {eta:?})"), &gradient_stage()));
        let dir = DVec3::NEG_Z;
        let measured: Vec<Acc> = POINTS
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| {
                let o = Vec3::new(x as f32, y as f32, 5.0);
                trace_ray(
                    &world,
                    ray(o, dir.as_vec3()),
                    N,
                    &[eta.to_bits(), i as u64],
                    1024,
                    Strategy::Mis,
                )
            })
            .collect();
        let mut worst = 0.0f64;
        let mut control_worst = [0.0f64; 2];
        for (i, (&(x, y), a)) in POINTS.iter().zip(&measured).enumerate() {
            let o = DVec3::new(x, y, 5.0);
            let want = branch_sum(o, dir, eta, Branches::All);
            let wrong = [
                branch_sum(o, dir, eta + 0.05, Branches::All),
                branch_sum(o, dir, eta, Branches::FirstExit),
            ];
            println!(
                "η {eta} ray {i} ({x}, {y}): expected {want:.5?}, measured {:.5?} ± {:.5?}",
                [a.mean(0), a.mean(1), a.mean(2)],
                [a.se(0), a.se(1), a.se(2)]
            );
            for c in 0..3 {
                let z = a.z(c, want[c]);
                worst = worst.max(z.abs());
                if z.abs() > limit {
                    failures.push(format!(
                        "η {eta} ray {i} channel {c}: {:.6} ± {:.6} vs {:.6} (z {z:.2})",
                        a.mean(c),
                        a.se(c),
                        want[c]
                    ));
                }
                for (k, w) in wrong.iter().enumerate() {
                    control_worst[k] = control_worst[k].max(a.z(c, w[c]).abs());
                }
            }
        }
        println!(
            "η {eta}: worst |z| {worst:.2} (limit {limit:.2}); controls: η + 0.05 worst |z| \
             {:.1}, first exit only {:.1}",
            control_worst[0], control_worst[1]
        );
        for (k, name) in ["η + 0.05", "no internal reflections"].iter().enumerate() {
            if control_worst[k] <= limit {
                failures.push(format!("η {eta}: the wrong model '{name}' is accepted"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Unit directions spread over the sphere (a Fibonacci lattice).
fn directions(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).sqrt();
            let phi = i as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
            Vec3::new((r * phi.cos()) as f32, y as f32, (r * phi.sin()) as f32)
        })
        .collect()
}

/// A camera inside a clear smooth sphere under a constant sky of 1. Radiance inside a medium of
/// index η in equilibrium with that sky is η² (the basic radiance `L/n²` is what refraction
/// keeps), and a smooth sphere never changes a ray's internal angle: rays from the eye at
/// distance `b` from the centre's line with `b < 1/η` leave with weight exactly η² (every path,
/// 1e-5), rays with `b > 1/η` are trapped by total internal reflection for ever and carry 0 at
/// `max_depth` (directions within 5 % of `b = 1/η`, where
/// internal reflections near the critical angle may outlast `max_depth` 64, are left out). 200
/// directions × 16 paths at η 1.5 and 2.4, both classes present. The
/// camera starts in the body's medium, and a render from inside (16 × 16, 4 spp) drops nothing.
#[test]
fn camera_inside_a_clear_sphere_sees_eta_squared() {
    let eye = Vec3::new(0.75, 0.3, -0.2);
    for eta in [1.5f32, 2.4] {
        let stage = format!(
            "(shape: Sphere(radius: 1.0), ground: Off, lights: [], environment: Constant(Gray(1.0)),
              camera: Perspective(from: ({:?}, {:?}, {:?}), to: (0.0, 0.3, -0.2), fov: 90.0),
              render: (width: 16, height: 16, spp: 4, max_depth: 64))",
            eye.x, eye.y, eye.z
        );
        let (scene, world) = build(&gem(&format!("(ior: {eta:?})"), &stage));
        assert!(
            world.camera_medium == world.interior && world.interior != MediumId::OUTSIDE,
            "the camera starts inside the body"
        );
        let (mut out, mut trapped) = (0, 0);
        let e2 = eta * eta;
        for (i, d) in directions(200).into_iter().enumerate() {
            let b = eye.cross(d).length();
            let a = trace_ray(&world, ray(eye, d), 16, &[7, i as u64], 64, Strategy::Mis);
            let want = if b < 0.95 / eta {
                out += 1;
                e2
            } else if b > 1.05 / eta {
                trapped += 1;
                0.0
            } else {
                continue;
            };
            for c in 0..3 {
                let (m, se) = (a.mean(c), a.se(c));
                assert!(
                    (m - f64::from(want)).abs() <= 1e-5 * f64::from(e2) && se < 1e-6,
                    "η {eta}, direction {d} (b {b:.4}): {m} ± {se}, expected {want} for every path"
                );
            }
        }
        println!("η {eta}: {out} directions leave with η² = {e2}, {trapped} are trapped");
        assert!(out > 20 && trapped > 20, "{out} {trapped}");
        let r = render(
            &world,
            &scene.stage.camera,
            false,
            &scene.stage.render,
            &Control::default(),
        );
        assert_eq!(r.stats.dropped, 0, "η {eta}: samples dropped");
        assert!(r.film.rgb().iter().flatten().all(|v| v.is_finite()));
    }
}

/// The camera at the centre of an absorbing sphere (η 2.4, `σa = (0.5, 1, 2)`, radius 1) looks
/// along radii, so every event is at normal incidence: the ray leaves with `1 − F₀` after
/// `τ = e^{−σa}`, or reflects with `F₀` back through the centre (`τ²` more), so
/// `L = η² (1 − F₀) τ / (1 − F₀ τ²)` per channel under a sky of 1. 8 rays × 20 000 paths, 24 tests
/// at 0.01. Controls on the pooled paths: without the η² (the value a camera outside would see),
/// and without the internal reflections, both rejected.
#[test]
fn camera_at_the_centre_of_an_absorbing_sphere() {
    let eta = 2.4f64;
    let sigma = [0.5f64, 1.0, 2.0];
    let stage = "(shape: Sphere(radius: 1.0), ground: Off, lights: [], \
                 environment: Constant(Gray(1.0)), \
                 camera: Perspective(from: (0.0, 0.0, 0.0), to: (0.0, 0.0, -1.0), fov: 60.0))";
    let body = format!(
        "(ior: {eta:?}, medium: (absorption: ({:?}, {:?}, {:?})))",
        sigma[0], sigma[1], sigma[2]
    );
    let (_, world) = build(&gem(&body, stage));
    assert_eq!(world.camera_medium, world.interior);
    let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let tau = sigma.map(|s| (-s).exp());
    let want = tau.map(|t| eta * eta * (1.0 - f0) * t / (1.0 - f0 * t * t));
    let limit = z_limit(ALPHA, 8 * 3);
    let dirs = [
        Vec3::X,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(-1.0, 0.5, 0.2),
        Vec3::new(0.3, -0.8, -0.5),
        Vec3::new(-0.2, -0.1, 0.9),
        Vec3::new(0.7, 0.0, -0.7),
    ];
    let mut all = Acc::default();
    for (i, d) in dirs.into_iter().enumerate() {
        let a = trace_ray(
            &world,
            ray(Vec3::ZERO, d),
            N,
            &[11, i as u64],
            1024,
            Strategy::Mis,
        );
        for (c, &w) in want.iter().enumerate() {
            let z = a.z(c, w);
            assert!(
                z.abs() <= limit,
                "direction {d}: channel {c}: {:.5} ± {:.5}, expected {w:.5} (z {z:.2})",
                a.mean(c),
                a.se(c)
            );
        }
        all.merge(&a);
    }
    println!(
        "centre of an absorbing sphere: expected {want:.5?}, measured {:.5?} ± {:.5?}",
        [all.mean(0), all.mean(1), all.mean(2)],
        [all.se(0), all.se(1), all.se(2)]
    );
    let no_eta2 = want.map(|w| w / (eta * eta));
    let no_reflections: [f64; 3] = std::array::from_fn(|c| eta * eta * (1.0 - f0) * tau[c]);
    for (name, wrong) in [
        ("no η²", no_eta2),
        ("no internal reflections", no_reflections),
    ] {
        let z: Vec<f64> = (0..3).map(|c| all.z(c, wrong[c])).collect();
        println!("  control {name}: z {z:.1?}");
        assert!(
            z.iter().any(|z| z.abs() > limit),
            "the wrong model {name} is accepted"
        );
    }
}
