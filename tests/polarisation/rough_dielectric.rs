//! Rough dielectric boundaries (a `body` with `roughness`) in polarised renders: each facet
//! reflects and refracts by Fresnel's Mueller matrices, in BSDF sampling and in light sampling
//! alike.

use super::{compile, forced, mean, mean_by};
use lapidary::render::Strategy;
use lapidary::scene::Scene;

/// The slab's index.
const ETA: f64 = 1.5;

/// Fresnel's power reflectances `(R_s, R_p)` of a dielectric of index `eta` from air at `cos_i`
/// (Born & Wolf §1.5.2), written here from the amplitude formulas.
fn dielectric_sp(cos_i: f64, eta: f64) -> (f64, f64) {
    let sin2 = 1.0 - cos_i * cos_i;
    let ct = (eta * eta - sin2).sqrt(); // η cos θ_t
    let rs = (cos_i - ct) / (cos_i + ct);
    let rp = (eta * eta * cos_i - ct) / (eta * eta * cos_i + ct);
    (rs * rs, rp * rp)
}

/// A slab of index 1.5, one unit thick, its top at `y = 0` (boundary RMS slope `roughness`
/// degrees, no energy compensation; `medium` its interior), seen at `theta` degrees from its
/// normal through an analyser at `analyser` degrees from the image's right (across the plane of
/// incidence), lit by `light`.
fn slab(theta: f64, roughness: f64, medium: &str, analyser: Option<f64>, light: &str) -> Scene {
    slab_spp(theta, roughness, medium, analyser, light, 32)
}

/// [`slab`] at `spp` samples per pixel.
fn slab_spp(
    theta: f64,
    roughness: f64,
    medium: &str,
    analyser: Option<f64>,
    light: &str,
    spp: u32,
) -> Scene {
    let t = theta.to_radians();
    let (y, z) = (5.0 * t.cos(), 5.0 * t.sin());
    let analyser = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
    compile(&format!(
        r#"(materials: {{}},
            body: (ior: {ETA}, roughness: {roughness}, compensation: false {medium}),
            surface: Body,
            stage: (shape: Slab(size: (40.0, 1.0, 40.0)), transform: (translate: (0.0, -0.5, 0.0)),
                    ground: Off, {light},
                    camera: Orthographic(from: (0.0, {y}, {z}), to: (0.0, 0.0, 0.0), height: 0.5),
                    {analyser}
                    render: (width: 32, height: 32, spp: {spp}, max_depth: 12, seed: 5)))"#
    ))
}

/// A near-mirror boundary over a black interior (all that enters is absorbed) in a white sky
/// through an analyser passes `½ R_s` across the plane of incidence, `½ R_p` in it,
/// `¼ (R_s + R_p)` at 45° and `½ (R_s + R_p)` without one (5 standard errors plus 0.3 % for the
/// 0.1° facets' spread) — near Brewster's angle (56.3°) the p reflection all but vanishes.
#[test]
fn a_rough_dielectric_reflects_by_its_facets_fresnel_matrix() {
    let sky = "environment: Constant(Gray(1.0)), lights: []";
    let black = ", medium: (absorption: (1000.0, 1000.0, 1000.0))";
    for theta in [30.0f64, 56.0, 70.0] {
        let (rs, rp) = dielectric_sp(theta.to_radians().cos(), ETA);
        for (analyser, want, what) in [
            (None, 0.5 * (rs + rp), "no analyser"),
            (Some(0.0), 0.5 * rs, "analyser across the plane (s)"),
            (Some(90.0), 0.5 * rp, "analyser in the plane (p)"),
            (Some(45.0), 0.25 * (rs + rp), "analyser at 45°"),
        ] {
            let (got, se) = mean(&slab(theta, 0.1, black, analyser, sky));
            eprintln!("θ {theta}°, {what}: {got:.5} ± {se:.5} (closed form {want:.5})");
            assert!(
                (got - want).abs() <= 5.0 * se + 3e-3 * want + 1e-5,
                "θ {theta}°, {what}: {got} ± {se} vs {want}"
            );
        }
    }
}

/// A clear near-smooth slab over a lamp (a black sky): the light seen through it has crossed two
/// boundaries and any number of inner reflection pairs, so through an analyser across the
/// plane it is `½ L T_s² Σ R_s²ᵏ = ½ L (1 − R_s)/(1 + R_s)`, in the plane the same of p, and
/// the mean of the two without one (the slab's two faces parallel: each crossing at the same
/// angle; an unpolarised render would read `L (1 − R)² / (1 − R²)` of the mean `R`, 2 % lower
/// at 65°). 5 standard errors plus 0.3 %.
#[test]
fn a_rough_dielectric_refracts_by_its_facets_fresnel_matrix() {
    let radiance = 2.0;
    for theta in [40.0f64, 65.0] {
        let t = theta.to_radians();
        // The lamp faces the camera across the slab, large enough for the refracted offset.
        let lamp = format!(
            "environment: Constant(Gray(0.0)),
             lights: [Rect(center: (0.0, {}, {}), target: (0.0, -1.0, 0.0),
                           size: (8.0, 8.0), radiance: Gray({radiance}))]",
            -1.0 - 3.0 * t.cos(),
            -3.0 * t.sin()
        );
        let (rs, rp) = dielectric_sp(t.cos(), ETA);
        let (ts, tp) = ((1.0 - rs) / (1.0 + rs), (1.0 - rp) / (1.0 + rp));
        for (analyser, want, what) in [
            (None, 0.5 * radiance * (ts + tp), "no analyser"),
            (
                Some(0.0),
                0.5 * radiance * ts,
                "analyser across the plane (s)",
            ),
            (Some(90.0), 0.5 * radiance * tp, "analyser in the plane (p)"),
        ] {
            // Without an analyser nothing turns polarisation on here: force it.
            let (got, se) = mean(&forced(&slab(theta, 0.1, "", analyser, &lamp), true));
            eprintln!("θ {theta}°, {what}: {got:.5} ± {se:.5} (closed form {want:.5})");
            assert!(
                (got - want).abs() <= 5.0 * se + 3e-3 * want,
                "θ {theta}°, {what}: {got} ± {se} vs {want}"
            );
        }
    }
}

/// A rough (25°) clear slab seen at 70° over a lamp, through analysers across and in the plane:
/// the light reaches the camera refracted at the slab's bottom, where light sampling alone
/// (through the boundary) and BSDF sampling alone estimate the same image (their means within 5
/// combined standard errors, 512 spp on 32 × 32 pixels), so the light samples take the facets'
/// transmission matrices as the sampled directions do; across and in the plane differ by far
/// more than that. Also with the lamp behind a polariser (its polarisation read after the
/// facet), and seen at 45° in reflection off the top of a black slab.
#[test]
fn light_sampling_reads_the_facets_polarisation() {
    let behind = |polariser: Option<f64>| {
        let t = 70f64.to_radians();
        format!(
            "environment: Constant(Gray(0.0)),
             lights: [Rect(center: (0.0, {}, {}), target: (0.0, -1.0, 0.0),
                           size: (3.0, 3.0), radiance: Gray(2.0) {})]",
            -1.0 - 3.0 * t.cos(),
            -3.0 * t.sin(),
            polariser.map_or(String::new(), |p| format!(", polariser: {p}"))
        )
    };
    let above = "environment: Constant(Gray(0.0)),
                 lights: [Rect(center: (0.0, 3.0, -3.0), target: (0.0, 0.0, 0.0),
                               size: (3.0, 3.0), radiance: Gray(4.0))]";
    let black = ", medium: (absorption: (1000.0, 1000.0, 1000.0))";
    for (theta, light, medium, what) in [
        (70.0, behind(None), "", "through"),
        (70.0, behind(Some(30.0)), "", "through, polarised lamp"),
        (45.0, above.to_string(), black, "reflected"),
    ] {
        light_against_bsdf_sampling(theta, &light, medium, what);
    }
}

fn light_against_bsdf_sampling(theta: f64, light: &str, medium: &str, what: &str) {
    let image = |analyser: f64, strategy: Strategy| {
        let s = slab_spp(theta, 25.0, medium, Some(analyser), light, 512);
        mean_by(&s, strategy)
    };
    let mut means = Vec::new();
    for analyser in [0.0, 90.0] {
        let (light, sl) = image(analyser, Strategy::LightOnly);
        let (bsdf, sb) = image(analyser, Strategy::BsdfOnly);
        eprintln!(
            "{what}, analyser {analyser}°: light {light:.5} ± {sl:.5}, BSDF {bsdf:.5} ± {sb:.5}"
        );
        let se = (sl * sl + sb * sb).sqrt();
        assert!(
            (light - bsdf).abs() <= 5.0 * se,
            "{what}, analyser {analyser}°: light sampling {light} against BSDF sampling {bsdf} ± {se}"
        );
        assert!(light > 0.0 && bsdf > 0.0);
        means.push((light, se));
    }
    // s and p part: the two analysers read apart by far more than the noise.
    let ((s, es), (p, ep)) = (means[0], means[1]);
    assert!(
        (s - p).abs() > 10.0 * (es * es + ep * ep).sqrt(),
        "{what}: s {s} p {p}"
    );
}
