//! Claim 8 (continued), manifold next-event estimation through the stone (`manifold-caustics`,
//! src/render/manifold/): from a point on the floor, a refraction into a smooth body and one out
//! of it to a light — the caustic a small light throws through a polished stone. (a) The walk's
//! measure `|dω0/dA2|` integrated over the light equals the solid angle of the directions at the
//! floor point whose twice-refracted rays reach the light *and* that the walk returns for the
//! light point they reach (shooting uniform directions, which uses no Newton step and no
//! Jacobian): this is the density the walk's estimate and its MIS weight use, and it stays right
//! where a lens has several connections for one light point. (b) Whole paths: MIS with the walk,
//! the walk alone and the renderer without it converge to the same image of the floor around a
//! glass sphere, and the walk lowers the variance. (c) The effect is called only for a smooth
//! body over a floor under an area light.

use super::manifold::{Lower, converge, with_walk};
use super::{build, gem, z_limit};
use glam::Vec3;
use lapidary::render::manifold::{Chain, exit, solve};
use lapidary::render::{Strategy, World};
use lapidary::sampler::Rng;
use lapidary::scene::Effect;
use std::f64::consts::PI;

/// Overall significance of the family.
const ALPHA: f64 = 0.01;
/// Largest `|dω0/dA2| · A` (sr) a connection of the measure test may have. Near a fold of the
/// lens map (where two connections of one light point merge) the measure grows without bound and
/// its variance over random light points is infinite (one point at the floor point (0.1, −1.01,
/// 0) moved the mean by 25 %): both sides of the test leave out the connections above the cap,
/// which keeps the identity exact and the variance finite.
const CAP: f32 = 5.0;
/// Height of the floor (just under the unit sphere).
const FLOOR: f32 = -1.002;

/// A unit sphere over a grey floor, one disc light of radius `r` centred at `(x, 4, 0)` aimed at
/// the origin, a black sky, and an orthographic camera looking down at the floor around the
/// sphere, `size`² pixels at `spp`.
fn floor_stage(x: f32, r: f32, size: u32, spp: u32) -> String {
    shaped_floor_stage("Sphere(radius: 1.0)", x, r, size, spp)
}

/// [`floor_stage`] with another stone `shape`.
fn shaped_floor_stage(shape: &str, x: f32, r: f32, size: u32, spp: u32) -> String {
    format!(
        "(shape: {shape}, ground: Plane(height: {FLOOR}, albedo: Gray(0.6)),
          environment: Constant(Gray(0.0)),
          lights: [Disc(center: ({x}, 4.0, 0.0), target: (0.0, 0.0, 0.0), radius: {r},
                        radiance: Gray(20.0))],
          camera: Orthographic(from: (-1.0, 5.0, 3.0), to: (-0.8, -1.0, 0.0), height: 3.2),
          render: (width: {size}, height: {size}, spp: {spp}, max_depth: 24, seed: 7))"
    )
}

/// Where the ray of direction `d` from `x0` on the floor meets the light's disc (centre `c`,
/// unit normal `n`, radius `r`) after entering and leaving the sphere, if it does.
fn through_hit(w: &World, x0: Vec3, d: Vec3, eta: f32, c: Vec3, n: Vec3, r: f32) -> Option<Vec3> {
    let e = exit(w, x0, d, eta, Chain::Through)?;
    let denom = e.out.dot(n);
    if denom >= 0.0 {
        return None;
    }
    let t = (c - e.p).dot(n) / denom;
    let q = e.p + e.out * t;
    (t > 0.0 && (q - c).length() < r).then_some(q)
}

/// (a): `∫ |dω0/dA2| dA2` over the light (100 000 uniform random points) against the solid angle
/// of the shot directions (2 M uniform over the upper hemisphere) that reach the light through
/// the sphere and that the walk returns for that light point (within 4.5 mrad), both without the
/// connections whose measure exceeds [`CAP`]: equal within a
/// z-test at α = 0.01 (Šidák over the four floor points). CI's run reads |z| 0.1, 2.6, 2.7, 0.3;
/// the same streams extended to 800 000 / 8 M kept the second and third near 2.5 (the extension
/// shares the first samples), and an independent 800 000 / 8 M run read 1.8, 0.1, 0.6, 0.3. Also reported: the share of the shot
/// directions the walk returns (the rest belong to a second connection of the same light point,
/// which only BSDF sampling produces) and the walks that found no connection.
#[test]
fn through_measure_integrates_to_the_solid_angle_the_walk_covers() {
    through_measure("Sphere(radius: 1.0)");
}

/// (a) for the walk with the exact Jacobian (src/render/manifold/exact.rs): the unit sphere as a
/// cabochon (two hemispherical domes), whose walks differentiate the entry refraction and the
/// exit in closed form.
#[test]
fn exact_through_measure_integrates_to_the_solid_angle_the_walk_covers() {
    through_measure("Cabochon(radius: (1.0, 1.0), height: 1.0, base: 1.0)");
}

/// (a) for the stone `shape` (the unit sphere, however it is described).
fn through_measure(shape: &str) {
    let eta = 1.5;
    let (_, w) = build(&gem(
        "(ior: 1.5)",
        &shaped_floor_stage(shape, 1.2, 0.6, 8, 1),
    ));
    let light = &w.areas[0];
    let (n, area) = (light.normal(), light.area());
    let c = Vec3::new(1.2, 4.0, 0.0);
    let r = 0.6;
    let frame = lapidary::geometry::Frame::from_normal(n);
    let vertices = [
        Vec3::new(-0.4, FLOOR, 0.0),
        Vec3::new(-0.2, FLOOR, 0.3),
        Vec3::new(-0.55, FLOOR, -0.1),
        Vec3::new(0.1, FLOOR, 0.0),
    ];
    let limit = z_limit(ALPHA, vertices.len());
    for (k, &x0) in vertices.iter().enumerate() {
        // The walk: light points uniform on the disc (random: the set of points the walk
        // reaches has an edge, where a midpoint rule would be biased).
        let m = 100_000u32;
        let mut rng = Rng::new(0x11 + k as u64);
        let (mut sum, mut sq, mut none, mut capped) = (0.0f64, 0.0f64, 0, 0);
        for _ in 0..m {
            let rr = r * rng.uniform().sqrt();
            let phi = 2.0 * std::f32::consts::PI * rng.uniform();
            let x2 = c + (frame.s * phi.cos() + frame.t * phi.sin()) * rr;
            match solve(&w, x0, x2, n, eta, Chain::Through) {
                Some(conn) if conn.jacobian * area <= CAP => {
                    let j = f64::from(conn.jacobian) * f64::from(area);
                    sum += j;
                    sq += j * j;
                }
                Some(_) => capped += 1,
                None => none += 1,
            }
        }
        let walk_se = ((sq / f64::from(m) - (sum / f64::from(m)).powi(2)) / f64::from(m)).sqrt();
        let walk = sum / f64::from(m);
        let shots = 2_000_000u32;
        let mut rng = Rng::new(0xca05 + k as u64);
        let (mut reach, mut covered) = (0u32, 0u32);
        for _ in 0..shots {
            let z = rng.uniform();
            let phi = 2.0 * std::f32::consts::PI * rng.uniform();
            let s = (1.0 - z * z).max(0.0).sqrt();
            let d = Vec3::new(s * phi.cos(), z, s * phi.sin());
            if let Some(q) = through_hit(&w, x0, d, eta, c, n, r) {
                reach += 1;
                if solve(&w, x0, q, n, eta, Chain::Through)
                    .is_some_and(|conn| conn.d.dot(d) > 1.0 - 1e-5 && conn.jacobian * area <= CAP)
                {
                    covered += 1;
                }
            }
        }
        let p = f64::from(covered) / f64::from(shots);
        let shot = 2.0 * PI * p;
        let se = 2.0 * PI * (p * (1.0 - p) / f64::from(shots)).sqrt();
        let z = (walk - shot) / (se * se + walk_se * walk_se).sqrt();
        println!(
            "floor point {x0}: walk {walk:.6} ± {walk_se:.6} sr, shooting {shot:.6} ± {se:.6} sr; the walk \
             returns {covered} of {reach} shot directions; {none} of {m} light points unreached, {capped} capped"
        );
        assert!(reach > 1000, "{x0}: the light is seen through the sphere");
        assert!(
            covered > 0,
            "{x0}: the walk returns none of the shot directions"
        );
        assert!(z.abs() < limit, "{x0}: |z| {z:.2} ≥ {limit:.2}");
    }
}

/// (b): the floor around a clear glass sphere (the caustic of a light of radius 0.6 lands beside
/// it): 16×16 pixels × 512 paths, paired z-tests as for the walk from inside; the walk lowers the
/// standard error in the block the caustic falls in (most of the floor is lit directly, where
/// ordinary next-event estimation already does the work).
#[test]
fn walk_through_and_bsdf_sampling_agree_on_the_floor() {
    converge(
        "caustic",
        "(ior: 1.5)",
        &floor_stage(1.6, 0.6, 16, 512),
        Effect::ManifoldCaustics,
        512,
        Lower::InABlock,
    );
}

/// (b) for the jeweller's arrangement: a cabochon whose flat base floats 0.002 above the floor
/// (the film of air the gems keep), seen from above, so most of the image is floor seen through
/// the stone. Finding (fixed): the occlusion ray from the floor to the entry point left from the
/// floor point offset along its normal (2e-5) but along the walk's direction, so across the 0.002
/// film it met the base 2.5e-5 before the entry point — inside the margin it stopped short by —
/// and the base occluded the walk for most floor directions while the walk's density still
/// claimed those paths: this test read −0.147 ± 0.005 (|z| 30) between MIS and BSDF sampling, and
/// the stone rendered 3.5 % dark on the jeweller's stage. The ray is now aimed at the entry point.
#[test]
fn walk_through_a_cabochon_on_a_film_of_air() {
    let stage = "(shape: Cabochon(radius: (1.0, 0.8), height: 0.55),
                  transform: (translate: (0.0, 0.002, 0.0)),
                  ground: Plane(height: 0.0, albedo: Gray(0.6)), environment: Constant(Gray(0.0)),
                  lights: [Disc(center: (1.2, 4.0, 0.0), target: (0.0, 0.0, 0.0), radius: 0.6,
                                radiance: Gray(20.0))],
                  camera: Orthographic(from: (-0.6, 5.0, 1.0), to: (0.0, 0.0, 0.0), height: 2.0),
                  render: (width: 16, height: 16, spp: 512, max_depth: 24, seed: 7))";
    converge(
        "cabochon caustic",
        "(ior: 1.565)",
        stage,
        Effect::ManifoldCaustics,
        512,
        Lower::InABlock,
    );
}

/// (b) with an absorbing interior: the walk's segment inside takes the medium's transmittance.
#[test]
fn walk_through_takes_the_interior_transmittance() {
    converge(
        "tinted caustic",
        "(ior: 1.6, medium: (absorption: (0.2, 0.6, 1.2)))",
        &floor_stage(1.6, 0.6, 16, 512),
        Effect::ManifoldCaustics,
        512,
        Lower::InABlock,
    );
}

/// (c): on for a smooth body over a lit floor; off without a floor, under a black floor, with a
/// rough boundary, or without an area light; forcing it on without a floor changes nothing.
#[test]
fn caustic_walk_is_called_only_over_a_lit_floor() {
    let called = |body: &str, stage: &str| {
        let (s, w) = build(&gem(body, stage));
        assert_eq!(
            w.manifold.as_ref().is_some_and(|m| m.through),
            s.effects.called(Effect::ManifoldCaustics)
        );
        s.effects.called(Effect::ManifoldCaustics)
    };
    let lit = floor_stage(1.6, 0.5, 8, 1);
    assert!(called("(ior: 1.5)", &lit));
    assert!(!called("(ior: 1.5, roughness: 2.0)", &lit));
    let black = lit.replace("albedo: Gray(0.6)", "albedo: Gray(0.0)");
    let no_floor = lit.replace(
        "ground: Plane(height: -1.002, albedo: Gray(0.6))",
        "ground: Off",
    );
    let dark = lit.replace("radiance: Gray(20.0)", "radiance: Gray(0.0)");
    for stage in [&black, &no_floor, &dark] {
        assert_ne!(stage, &lit);
        assert!(!called("(ior: 1.5)", stage));
    }
    // Forced on where there is no floor: no walk can start, and the image keeps every bit.
    let (scene, _) = build(&gem("(ior: 1.5)", &no_floor));
    let on = with_walk(&scene, Effect::ManifoldCaustics, true);
    let off = with_walk(&scene, Effect::ManifoldCaustics, false);
    let a = super::energy::trace_image(&scene, &[&on], 4, Strategy::Mis);
    let b = super::energy::trace_image(&scene, &[&off], 4, Strategy::Mis);
    for ((_, _, p), (_, _, q)) in a.iter().zip(&b) {
        assert_eq!(p[0].radiance.0, q[0].radiance.0);
    }
}
