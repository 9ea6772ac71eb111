//! Dispersion through the renderer (issue 19): a 60° prism of a strongly dispersive glass bends
//! each wavelength by Snell's law with its own index. Chosen rays (the camera rays of chosen
//! pixels of a view through the prism's principal section) are followed through the world as
//! the integrator follows them — intersection, the hit's BSDF in its shading frame, a sampled
//! refraction in and out — at wavelengths held fixed, and the exit direction is compared with
//! the prism formula (Born & Wolf, *Principles of Optics*, §4.7.2): with apex angle `A`,
//! `sin θ1 = n sin θ1'`, `θ2' = A − θ1'`, `sin θ2 = n sin θ2'`, deviation `δ = θ1 + θ2 − A`,
//! `n = n(λ)` from the recipe's Cauchy law. Deterministic: no tolerance beyond rounding
//! (2e-4 rad); the refraction keeps only the hero wavelength.

use glam::{Vec2, Vec3};
use lapidary::bsdf::LobeFlags;
use lapidary::geometry::{Ray, offset_origin};
use lapidary::recipe::GemRecipe;
use lapidary::render::shading::shade;
use lapidary::render::world::Hit;
use lapidary::render::{PathSample, World};
use lapidary::spectrum::HeroSample;
use lapidary::spectrum::rgb2spec::d65_normalised;
use lapidary::spectrum::wavelengths::HeroWavelengths;

/// Cauchy law of the test glass: `n(λ) = A + B/λ²` with `n_d = 1.62` and a large `B` so that
/// the spread is degrees.
const N_D: f32 = 1.62;
const B: f32 = 0.03;

fn n_of(lambda: f32) -> f32 {
    let l_d = 0.58756f32;
    let a = N_D - B / (l_d * l_d);
    let l = lambda * 1e-3;
    a + B / (l * l)
}

/// An equilateral prism (apex angle 60°) with its section in the x–y plane, base on y = 0 from
/// x = −1 to 1, apex at (0, √3), extruded over z ∈ [−2, 2]; triangles wound outward.
fn prism_obj() -> String {
    let h = 3f32.sqrt();
    let v = [
        Vec3::new(-1.0, 0.0, -2.0),
        Vec3::new(1.0, 0.0, -2.0),
        Vec3::new(0.0, h, -2.0),
        Vec3::new(-1.0, 0.0, 2.0),
        Vec3::new(1.0, 0.0, 2.0),
        Vec3::new(0.0, h, 2.0),
    ];
    let tris = [
        [0, 1, 2],
        [3, 4, 5],
        [0, 1, 4],
        [0, 4, 3],
        [1, 2, 5],
        [1, 5, 4],
        [2, 0, 3],
        [2, 3, 5],
    ];
    let centre = Vec3::new(0.0, h / 3.0, 0.0);
    let mut s = String::new();
    for p in v {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for t in tris {
        let (a, b, c) = (v[t[0]], v[t[1]], v[t[2]]);
        let n = (b - a).cross(c - a);
        let out = n.dot((a + b + c) / 3.0 - centre) > 0.0;
        let t = if out { t } else { [t[0], t[2], t[1]] };
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

fn world() -> World {
    let dir = std::env::temp_dir().join(format!("lapidary-prism-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("prism.obj"), prism_obj()).unwrap();
    let recipe = format!(
        "(materials: {{}}, surface: Body,\n body: (ior: {N_D}, dispersion: Cauchy(b: {B})),\n \
         stage: (shape: Mesh(file: \"prism.obj\"), ground: Off, lights: [],\n \
         environment: Constant(Gray(1.0)),\n \
         camera: Orthographic(from: (0.0, 1.0, 6.0), to: (0.0, 1.0, 0.0), height: 3.0)))"
    );
    let path = dir.join("prism.ron");
    let scene = GemRecipe::parse(path.to_str().unwrap(), &recipe)
        .and_then(|r| r.compile())
        .expect("the prism compiles");
    let w = World::new(&scene).expect("the prism world builds");
    std::fs::remove_dir_all(&dir).ok();
    assert!(w.spectral, "a dispersive body turns spectral transport on");
    w
}

/// One wavelength in all four slots.
fn at(lambda: f32) -> HeroWavelengths {
    HeroWavelengths {
        lambda: [lambda; 4],
        pdf: [1.0; 4],
        illuminant: [d65_normalised(lambda); 4],
    }
}

/// Follows `ray` through two refractions at `lambda`; the exit direction.
fn through(world: &World, ray: Ray, lambda: f32) -> Vec3 {
    let l = at(lambda);
    let mut ray = ray;
    for crossing in 0..2 {
        let hit = world
            .intersect(&ray, f32::INFINITY)
            .expect("the ray meets the prism");
        assert!(matches!(hit, Hit::Stone(_)), "crossing {crossing}: {hit:?}");
        let mut out = PathSample::default();
        let sb = shade(world, &hit, -ray.dir, 0.5, l, false, &mut out).expect("a BSDF");
        let wo = sb.frame.to_local(-ray.dir);
        // uc near 1: past the Fresnel reflectance, the refraction.
        let s = sb
            .sample::<HeroSample>(wo, 0.9999, Vec2::splat(0.5), &l)
            .expect("a refraction");
        assert!(
            s.flags.contains(LobeFlags::TRANSMISSION),
            "crossing {crossing}"
        );
        assert!(
            s.terminate_secondary,
            "a dispersive refraction keeps the hero only"
        );
        ray = Ray::new(offset_origin(sb.p, sb.ng, s.wi), s.wi);
    }
    ray.dir
}

#[test]
fn a_prism_deviates_each_wavelength_by_snells_law() {
    let world = world();
    let apex = 60f32.to_radians();
    // Rays in the principal section aimed at the left face's middle, 15°–30° above +x (the
    // left face's inward normal points 30° below +x, so θ1 = φ + 30°).
    let mid = Vec3::new(-0.5, 3f32.sqrt() / 2.0, 0.3);
    let mut previous: Option<f32> = None;
    for phi_deg in [15.0f32, 20.0, 30.0] {
        let phi = phi_deg.to_radians();
        let d = Vec3::new(phi.cos(), phi.sin(), 0.0);
        let ray = Ray::new(mid - 3.0 * d, d);
        for lambda in [420.0f32, 486.13, 587.56, 656.27, 760.0] {
            let out = through(&world, ray, lambda);
            let n = n_of(lambda);
            let t1 = phi + 30f32.to_radians();
            let t1p = (t1.sin() / n).asin();
            let t2 = (n * (apex - t1p).sin()).asin();
            let delta = t1 + t2 - apex;
            let expected = phi - delta;
            let got = out.y.atan2(out.x);
            println!(
                "φ {phi_deg}°, λ {lambda} nm: n {n:.5}, deviation {:.4}°, exit {:.4}° (expected {:.4}°)",
                delta.to_degrees(),
                got.to_degrees(),
                expected.to_degrees()
            );
            assert!(
                out.z.abs() < 1e-4,
                "the ray left the principal section: {out:?}"
            );
            assert!(
                (got - expected).abs() < 2e-4,
                "φ {phi_deg}°, λ {lambda}: exit {got} rad, Snell {expected} rad"
            );
            if phi_deg == 20.0 {
                // Shorter wavelengths bend more (normal dispersion).
                if let Some(p) = previous {
                    assert!(got > p, "λ {lambda}: {got} not above {p}");
                }
                previous = Some(got);
            }
        }
    }
}
