//! Claim 7b, modulated density, statistical form: with a modulation the flakes' collision rate
//! along a ray is `σ(d) · m(p)`, sampled by delta tracking against the unmodulated rate. The
//! free-flight distances (and which population a collision belongs to) must follow
//! `p(t, k) = σ_k(d) m_k(t) exp(−Λ(t))` with `Λ(t) = ∫₀ᵗ Σ σ_k m_k`, known in closed form for a
//! sine modulation; the null-collision bound must act as documented. Chi-square and z-tests at an
//! overall significance of 0.01 per family ([`ALPHA`], Šidák); sample counts in each doc comment.

use super::common::{chi_square_pooled, sidak_alpha};
use super::{build, gem, scene, z_limit};
use glam::{Affine3A, Quat, Vec2, Vec3};
use lapidary::platelet::statistical::{FlakeMedium, MAX_NULL_COLLISIONS};
use lapidary::platelet::{Modulation, Orientation, Population};
use lapidary::sampler::Rng;
use std::f64::consts::TAU;

/// Overall significance of each family.
const ALPHA: f64 = 0.01;
/// The sine's period along object x (object units).
const PERIOD: f64 = 0.5;

/// Two populations, through the recipe: `A`, 2000 per unit³ of copper discs (radius 0.02, uniform
/// normals) whose density is `½ + ½ sin(2π x / 0.5)`; `B`, 500 per unit³ of mirror discs (radius
/// 0.02, aligned to y within 30°), unmodulated.
fn populations() -> Vec<Population> {
    let s = scene(&gem(
        "(ior: 1.5, platelets: [
            (density: 2000.0, radius: (0.02, 0.02), orientation: Uniform, entries: [(1.0, \"copper\")],
             modulation: Some(Marble(scale: 0.5, axis: (1.0, 0.0, 0.0), turbulence: 0.0))),
            (density: 500.0, radius: (0.02, 0.02), orientation: Aligned(axis: (0.0, 1.0, 0.0), spread: 30.0),
             entries: [(1.0, \"mirror\")]),
        ])",
        "",
    ));
    let pops = s.surface.body.expect("a body").platelets;
    assert!(pops[0].modulation.is_some() && pops[1].modulation.is_none());
    assert_ne!(pops[0].entries[0].1, pops[1].entries[0].1);
    pops
}

/// The object-to-world map of the tests: scale 1.5, a turn about z, a shift.
fn to_world() -> Affine3A {
    Affine3A::from_scale_rotation_translation(
        Vec3::splat(1.5),
        Quat::from_rotation_z(0.3),
        Vec3::new(0.2, -0.1, 0.4),
    )
}

/// Simpson's rule of `f` over `[a, b]` on `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

/// Probabilities of `(bin, population)` for `bins` equal bins of `[0, t_max)` (index
/// `2·bin + k`) and of no collision (last), for the rates `rate(t) = (σ_A(t), σ_B(t))` and their
/// integral `lambda(t)`.
fn cell_probabilities(
    bins: usize,
    t_max: f64,
    rate: impl Fn(f64) -> [f64; 2],
    lambda: impl Fn(f64) -> f64,
) -> Vec<f64> {
    let w = t_max / bins as f64;
    let mut p = vec![];
    for i in 0..bins {
        let (a, b) = (i as f64 * w, (i + 1) as f64 * w);
        for k in 0..2 {
            p.push(simpson(|t| rate(t)[k] * (-lambda(t)).exp(), a, b, 64));
        }
    }
    p.push((-lambda(t_max)).exp());
    p
}

/// Free flights follow the modulated rate. Two rays through the medium of [`populations`] under
/// [`to_world`] (object x advances 0.66 and 0.58 per world unit along them, so `m` runs through
/// 4.0 and 3.5 periods before `t_max` = 3), 200 000 flights each; each flight is binned by its
/// distance (40 bins of 0.075) and population (by the face material), plus one cell for no
/// collision before `t_max`: 81 cells against `σ_k m_k(t) exp(−Λ(t))` with
/// `Λ(t) = σ_B t + σ_A (t/2 + P (cos 2πa/P − cos 2π(a + bt)/P) / (4πb))` (`a`, `b`: object x at the
/// origin and its rate along the ray; `P` the period), integrated per bin by Simpson's rule. Two
/// chi-square tests at overall 0.01 (Šidák: 5.0e-3 each). Negative controls, each rejected: the
/// unmodulated exponential flight at the majorant, and the rate frozen at the ray's origin.
#[test]
fn free_flights_follow_the_modulated_rate() {
    let pops = populations();
    let to_world = to_world();
    let medium = FlakeMedium::new(&pops, to_world);
    assert!(medium.is_modulated());
    let a_alone = FlakeMedium::new(&pops[..1], to_world);
    let b_alone = FlakeMedium::new(&pops[1..], to_world);
    let to_object = to_world.inverse();
    let (mat_a, mat_b) = (pops[0].entries[0].1, pops[1].entries[0].1);
    let a = sidak_alpha(ALPHA, 2);
    let (n, bins, t_max) = (200_000usize, 40usize, 3.0f32);
    let rays = [
        (
            Vec3::new(0.1, 0.2, 0.0),
            Vec3::new(1.0, 0.2, 0.1).normalize(),
        ),
        (
            Vec3::new(-0.3, 0.1, 0.4),
            Vec3::new(0.7, 0.6, -0.3).normalize(),
        ),
    ];
    for (r, (o, d)) in rays.into_iter().enumerate() {
        let (sa, sb) = (f64::from(a_alone.sigma(d)), f64::from(b_alone.sigma(d)));
        assert!((f64::from(medium.sigma(d)) - sa - sb).abs() < 1e-5 * (sa + sb));
        let x0 = f64::from(to_object.transform_point3(o).x);
        let bx = f64::from(to_object.transform_vector3(d).x);
        assert!(bx.abs() > 0.1, "ray {r}: m must vary along it ({bx})");
        let m = |t: f64| 0.5 + 0.5 * (TAU * (x0 + bx * t) / PERIOD).sin();
        let integral_m = |t: f64| {
            t / 2.0
                + PERIOD * ((TAU * x0 / PERIOD).cos() - (TAU * (x0 + bx * t) / PERIOD).cos())
                    / (2.0 * TAU * bx)
        };
        // The closed form and the field agree along the ray.
        for t in [0.0f32, 0.7, 2.9] {
            let got = f64::from(medium.sigma_at(o + d * t, d));
            let want = sa * m(f64::from(t)) + sb;
            assert!(
                (got - want).abs() < 1e-4 * want,
                "ray {r} t {t}: {got} vs {want}"
            );
        }
        let tm = f64::from(t_max);
        let expected = |p: Vec<f64>| -> Vec<f64> {
            let total: f64 = p.iter().sum();
            assert!((total - 1.0).abs() < 1e-6, "probabilities sum to {total}");
            p.iter().map(|q| q * n as f64).collect()
        };
        let want = expected(cell_probabilities(
            bins,
            tm,
            |t| [sa * m(t), sb],
            |t| sb * t + sa * integral_m(t),
        ));
        let mut observed = vec![0u64; 2 * bins + 1];
        let mut rng = Rng::new(0xf1 + r as u64);
        for _ in 0..n {
            let u = Vec2::new(rng.uniform(), rng.uniform());
            match medium.collide(o, d, t_max, u) {
                None => observed[2 * bins] += 1,
                Some(c) => {
                    assert!(c.t >= 0.0 && c.t < t_max && c.normal.dot(d) < 0.0, "{c:?}");
                    let k = if c.material == mat_a {
                        0
                    } else {
                        assert_eq!(c.material, mat_b);
                        1
                    };
                    let bin = ((f64::from(c.t) / tm * bins as f64) as usize).min(bins - 1);
                    observed[2 * bin + k] += 1;
                }
            }
        }
        let chi = chi_square_pooled(&observed, &want, 5.0);
        eprintln!(
            "ray {r}: object x {bx:.3} per unit; σ_A {sa:.3}, σ_B {sb:.3} per unit; none {} \
             (expected {:.0}); chi² {:.1} / {} dof (p {:.3})",
            observed[2 * bins],
            want[2 * bins],
            chi.chi2,
            chi.dof,
            chi.p_value
        );
        assert!(chi.passes(a), "ray {r}: {chi:?}");
        let majorant = expected(cell_probabilities(
            bins,
            tm,
            |_| [sa, sb],
            |t| (sa + sb) * t,
        ));
        let frozen = expected(cell_probabilities(
            bins,
            tm,
            |_| [sa * m(0.0), sb],
            |t| (sa * m(0.0) + sb) * t,
        ));
        for (name, wrong) in [("majorant", majorant), ("frozen at the origin", frozen)] {
            let chi = chi_square_pooled(&observed, &wrong, 5.0);
            assert!(
                !chi.passes(a),
                "ray {r}: the {name} rate is not rejected: {chi:?}"
            );
        }
    }
}

/// The null-collision bound: where the modulation is a constant `m`, every tentative collision is
/// null with probability `1 − m`, so with no end to the segment a flight gives up (no collision)
/// with probability exactly `(1 − m)^MAX_NULL_COLLISIONS`: 0.664 for `m` = 1e-4 (20 000 flights,
/// z-test at 0.01). With `m` = 0 no flight ever collides, and every call returns (1 000 flights
/// of 4 096 null collisions each).
#[test]
fn null_collisions_are_bounded() {
    let base = Population::new(
        3000.0,
        (0.01, 0.03),
        Orientation::Uniform,
        vec![(1.0, 0)],
        1,
    )
    .expect("a population");
    let d = Vec3::new(0.3, -0.4, 0.5).normalize();
    let mut rng = Rng::new(17);
    let medium = |m: f32| {
        FlakeMedium::new(
            &[base.clone().with_modulation(Some(Modulation::constant(m)))],
            Affine3A::IDENTITY,
        )
    };
    let never = medium(0.0);
    for _ in 0..1000 {
        let u = Vec2::new(rng.uniform(), rng.uniform());
        assert!(never.collide(Vec3::ZERO, d, f32::INFINITY, u).is_none());
    }
    let rare = medium(1e-4);
    let n = 20_000;
    let mut none = 0u32;
    for _ in 0..n {
        let u = Vec2::new(rng.uniform(), rng.uniform());
        none += u32::from(rare.collide(Vec3::ZERO, d, f32::INFINITY, u).is_none());
    }
    let p = (1.0f64 - 1e-4).powi(MAX_NULL_COLLISIONS as i32);
    let z = (f64::from(none) - p * f64::from(n)) / (p * (1.0 - p) * f64::from(n)).sqrt();
    eprintln!(
        "bound: {none} of {n} flights gave up (expected {:.0}), z {z:.2}",
        p * f64::from(n)
    );
    assert!(z.abs() <= z_limit(ALPHA, 1), "z {z:.2}");
}

/// The world's flake medium evaluates the modulation in object space: for a stone scaled by 2
/// and moved, `σ_at(p)` is `σ(d) · m(to_object(p))` at world points inside it.
#[test]
fn the_world_medium_reads_the_modulation_in_object_space() {
    let text = gem(
        "(ior: 1.5, platelets: [(density: 2000.0, radius: (0.02, 0.02), orientation: Uniform,
            entries: [(1.0, \"copper\")], modulation: Marble(scale: 0.5, turbulence: 0.0))])",
        "(transform: (scale: 2.0, translate: (0.3, 0.0, -0.2)), render: (platelets: Statistical))",
    );
    let (s, w) = build(&text);
    let flakes = w.flakes.as_ref().expect("the statistical form");
    let m = s.surface.body.as_ref().expect("a body").platelets[0]
        .modulation
        .clone()
        .expect("modulated");
    let to_object = s.stage.to_world.inverse();
    let d = Vec3::new(0.2, 0.3, 0.9).normalize();
    for x in [-0.8f32, -0.3, 0.1, 0.45, 0.9] {
        let p = Vec3::new(x, 0.2, 0.1);
        let want = flakes.sigma(d) * m.at(to_object.transform_point3(p));
        let got = flakes.sigma_at(p, d);
        assert!(
            (got - want).abs() <= 1e-5 * flakes.sigma(d),
            "{p}: {got} vs {want}"
        );
    }
}
