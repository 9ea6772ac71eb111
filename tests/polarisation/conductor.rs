//! Bare conductors (a `Conductor` base without coats) in polarised renders: each facet reflects
//! by Fresnel's Mueller matrix for the conductor's complex index, in BSDF sampling and in light
//! sampling alike.

use super::{compile, mean, mean_by};
use lapidary::render::Strategy;
use lapidary::scene::Scene;
use num_complex::Complex64 as C;

/// Channel 0's complex index `n + i k` of the test conductor: a weak absorber, so that s and p
/// part widely (gold's `R_s` and `R_p` both stay near 1).
const N: f64 = 1.5;
const K: f64 = 0.5;

/// Fresnel's power reflectances `(R_s, R_p)` of a conductor `n + i k` from air at `cos_i` (Born &
/// Wolf §14.2), written here from the amplitude formulas.
fn conductor_sp(cos_i: f64, n: f64, k: f64) -> (f64, f64) {
    let eta = C::new(n, k);
    let sin2 = 1.0 - cos_i * cos_i;
    let ct = (eta * eta - sin2).sqrt(); // η cos θ_t
    let rs = (cos_i - ct) / (cos_i + ct);
    let rp = (eta * eta * cos_i - ct) / (eta * eta * cos_i + ct);
    (rs.norm_sqr(), rp.norm_sqr())
}

/// A slab of the test conductor (RMS slope `roughness` degrees) seen at `theta` degrees from its
/// normal through an analyser at `analyser` degrees from the image's right (across the plane of
/// incidence), lit by `light`.
fn slab(theta: f64, roughness: f64, analyser: Option<f64>, light: &str) -> Scene {
    let t = theta.to_radians();
    let (y, z) = (5.0 * t.cos(), 5.0 * t.sin());
    let analyser = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
    compile(&format!(
        r#"(materials: {{ "metal": (base: Conductor(metal: Complex(n: ({N}, 0.4, 0.4),
                                                              k: ({K}, 2.0, 2.0)),
                                                 roughness: {roughness}),
                                  compensation: false) }},
            surface: Material("metal"),
            stage: (shape: Slab(size: (40.0, 1.0, 40.0)), transform: (translate: (0.0, -0.5, 0.0)),
                    ground: Off, {light},
                    camera: Orthographic(from: (0.0, {y}, {z}), to: (0.0, 0.0, 0.0), height: 0.5),
                    {analyser}
                    render: (width: 32, height: 32, spp: 32, max_depth: 4, seed: 3)))"#
    ))
}

/// A near-mirror conductor in a white sky through an analyser passes `½ R_s` across the plane of
/// incidence, `½ R_p` in it, `¼ (R_s + R_p)` at 45° and `½ (R_s + R_p)` without one (5 standard
/// errors plus 0.2 % for the 0.1° facets' spread).
#[test]
fn a_mirror_conductor_polarises_by_its_fresnel_matrix() {
    let sky = "environment: Constant(Gray(1.0)), lights: []";
    for theta in [30.0f64, 65.0] {
        let (rs, rp) = conductor_sp(theta.to_radians().cos(), N, K);
        for (analyser, want, what) in [
            (None, 0.5 * (rs + rp), "no analyser"),
            (Some(0.0), 0.5 * rs, "analyser across the plane (s)"),
            (Some(90.0), 0.5 * rp, "analyser in the plane (p)"),
            (Some(45.0), 0.25 * (rs + rp), "analyser at 45°"),
        ] {
            let (got, se) = mean(&slab(theta, 0.1, analyser, sky));
            eprintln!("θ {theta}°, {what}: {got:.5} ± {se:.5} (closed form {want:.5})");
            assert!(
                (got - want).abs() <= 5.0 * se + 2e-3 * want,
                "θ {theta}°, {what}: {got} ± {se} vs {want}"
            );
        }
    }
}

/// A rough conductor under a lamp through an analyser: light sampling alone and BSDF sampling
/// alone estimate the same image (their means within 5 combined standard errors), so the light
/// samples take the facets' Fresnel matrices as the sampled directions do; across and in the
/// plane of incidence differ by far more than that. The same behind a polarising lamp (its
/// polarisation read after the facet).
#[test]
fn light_sampling_reads_the_facets_polarisation() {
    for polariser in [None, Some(30.0)] {
        light_against_bsdf_sampling(polariser);
    }
}

fn light_against_bsdf_sampling(polariser: Option<f64>) {
    let lamp = format!(
        "environment: Constant(Gray(0.0)),
         lights: [Rect(center: (0.0, 3.0, -4.0), target: (0.0, 0.0, 0.0),
                       size: (3.0, 3.0), radiance: Gray(4.0) {})]",
        polariser.map_or(String::new(), |p| format!(", polariser: {p}"))
    );
    let image = |analyser: f64, strategy: Strategy| {
        let s = slab(50.0, 8.0, Some(analyser), &lamp);
        mean_by(&s, strategy)
    };
    let mut means = Vec::new();
    for analyser in [0.0, 90.0] {
        let (light, sl) = image(analyser, Strategy::LightOnly);
        let (bsdf, sb) = image(analyser, Strategy::BsdfOnly);
        let (mis, _) = image(analyser, Strategy::Mis);
        eprintln!(
            "polariser {polariser:?}, analyser {analyser}°: light {light:.5} ± {sl:.5}, \
             BSDF {bsdf:.5} ± {sb:.5}, MIS {mis:.5}"
        );
        let se = (sl * sl + sb * sb).sqrt();
        assert!(
            (light - bsdf).abs() <= 5.0 * se,
            "analyser {analyser}°: light sampling {light} against BSDF sampling {bsdf} ± {se}"
        );
        assert!(light > 0.0 && bsdf > 0.0);
        means.push((light, se));
    }
    // s and p part: the analyser across the plane passes several times what the other does.
    let ((s, es), (p, ep)) = (means[0], means[1]);
    assert!(s - p > 10.0 * (es * es + ep * ep).sqrt(), "s {s} p {p}");
}
