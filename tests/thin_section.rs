//! Thin sections (`crystal: …(thin_section: (unit_nm: …))`): a crystal plate whose two waves
//! leave together and interfere, rendered between crossed polars — the polariscope's interference
//! colours — against Born & Wolf's closed form (§15.4.4): a plate of retardation `R` with its
//! axis at 45° between crossed polars passes `½ sin²(π R / λ)` of each wavelength, and white
//! light the Michel-Lévy colour of `R` (`lapidary::polarisation::interference`).

use lapidary::polarisation::interference::michel_levy_xyz;
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, World, render_scene};
use lapidary::scene::{Effect, Scene};

fn compile(text: &str) -> Scene {
    GemRecipe::parse("thin_section.ron", text)
        .unwrap_or_else(|e| panic!("{e}"))
        .compile()
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Quartz (n_o 1.544, n_e 1.553: Δn 0.009) 0.5 units thick, its axis in the plate at 45° to the
/// polars, on a light box behind a polariser along −z, seen straight down through an analyser
/// along +x (crossed) or −z (`parallel`); `unit_nm` sets the retardation `R = 0.5 · unit_nm · Δn`;
/// `line`: a 0.5 nm line at that wavelength instead of white light; `crystal: false` a glass
/// plate of index n_o.
fn plate(retardation_nm: f64, line: Option<f64>, parallel: bool, crystal: bool) -> Scene {
    let unit_nm = retardation_nm / (0.5 * 0.009);
    let optics = if crystal {
        format!(
            "ior: 1.544, crystal: Uniaxial(ne: 1.553, axis: (1.0, 0.0, 1.0), \
             thin_section: (unit_nm: {unit_nm}))"
        )
    } else {
        "ior: 1.544".to_string()
    };
    let line = line.map_or(String::new(), |l| {
        format!("line: (wavelength: {l}, fwhm: 0.5),")
    });
    let analyser = if parallel { 90.0 } else { 0.0 };
    compile(&format!(
        r#"(materials: {{}}, surface: Body, body: ({optics}),
            stage: (shape: Slab(size: (0.6, 0.5, 0.6)), transform: (translate: (0.0, 0.3, 0.0)),
                    ground: Off, environment: Constant(Gray(0.0)),
                    lights: [Rect(center: (0.0, -1.0, 0.0), target: (0.0, 0.0, 0.0),
                                  size: (20.0, 20.0), radiance: Gray(1.0), polariser: 0.0, {line})],
                    camera: Orthographic(from: (0.0, 5.0, 0.0), to: (0.0, 0.0, 0.0),
                                         up: (0.0, 0.0, -1.0), height: 1.0),
                    analyser: {analyser},
                    render: (width: 24, height: 24, spp: 256, max_depth: 16)))"#
    ))
}

/// Mean RGB over the plate's middle (rows and columns 6..18 of 24: the plate covers 0.6 of the
/// unit view) and the standard error of each channel.
fn plate_mean(scene: &Scene) -> ([f64; 3], [f64; 3]) {
    let world = World::new(scene).expect("world");
    let img = render_scene(&world, scene, &Control::default()).film.rgb();
    let px: Vec<[f32; 3]> = (7..17)
        .flat_map(|y| (7..17).map(move |x| (x, y)))
        .map(|(x, y)| img[y * 24 + x])
        .collect();
    let n = px.len() as f64;
    let mut mean = [0.0; 3];
    let mut se = [0.0; 3];
    for c in 0..3 {
        let m = px.iter().map(|p| f64::from(p[c])).sum::<f64>() / n;
        let var = px
            .iter()
            .map(|p| (f64::from(p[c]) - m).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        mean[c] = m;
        se[c] = (var / n).sqrt();
    }
    (mean, se)
}

/// Under a 550 nm line the plate passes `sin²(π R / λ)` of what a half-wave plate passes, for
/// retardations from a sixth of a wave to a wave and a quarter (the multiply reflected light,
/// `R² ≈ 0.2 %` of it, crossing the plate three times, bounds the tolerance at 0.006 beyond five
/// standard errors; 100 pixels × 256 spp each).
#[test]
fn a_thin_plate_under_a_line_follows_sin_squared() {
    let s = plate(275.0, Some(550.0), false, true);
    assert!(s.effects.on(Effect::Polarisation) && s.effects.on(Effect::Spectral));
    let luminance = |m: [f64; 3]| m[0] + m[1] + m[2];
    let (half, half_se) = plate_mean(&s);
    let (half, half_se) = (luminance(half), luminance(half_se));
    assert!(half > 0.05, "{half}");
    for r in [91.67, 137.5, 206.25, 412.5, 550.0, 687.5] {
        let (m, se) = plate_mean(&plate(r, Some(550.0), false, true));
        let (m, se) = (luminance(m), luminance(se));
        let want = (std::f64::consts::PI * r / 550.0).sin().powi(2);
        let got = m / half;
        let tol = 0.006 + 5.0 * (se / half + want * half_se / half);
        eprintln!("R {r} nm: {got:.4} (sin² πR/λ {want:.4}, ± {tol:.4})");
        assert!((got - want).abs() <= tol, "R {r}: {got} vs {want}");
    }
}

/// Under white light the plate shows the Michel-Lévy colour of its retardation: each channel of
/// the plate between crossed polars, over a glass plate of the same index between parallel polars
/// (which passes the white light the polariser leaves, with the same reflection losses), equals
/// the linear sRGB of `michel_levy_xyz(R)` (D65 through crossed polars relative to D65 through the
/// polariser alone) within 0.015 plus five standard errors — first-order grey and yellow, the
/// first-order red's sensitive tint and second-order blue and green.
#[test]
fn a_thin_plate_in_white_light_shows_the_michel_levy_colours() {
    let (white, white_se) = plate_mean(&plate(0.0, None, true, false));
    assert!(white.iter().all(|v| *v > 0.1), "{white:?}");
    for r in [150.0, 400.0, 550.0, 700.0, 900.0] {
        let (m, se) = plate_mean(&plate(r, None, false, true));
        let xyz = michel_levy_xyz(r);
        let want = lapidary::spectrum::cie::XYZ_TO_LINEAR_SRGB * xyz;
        for c in 0..3 {
            let got = m[c] / white[c];
            let tol = 0.015 + 5.0 * (se[c] + got * white_se[c]) / white[c];
            eprintln!(
                "R {r} nm channel {c}: {got:.4} (Michel-Lévy {:.4}, ± {tol:.4})",
                want[c]
            );
            assert!(
                (got - f64::from(want[c])).abs() <= tol,
                "R {r} channel {c}: {got} vs {}",
                want[c]
            );
        }
    }
}

/// Each index its own dispersion law (`ne_dispersion`): under a 450 nm line a plate's
/// retardation is `d (n_e(λ) − n_o(λ))` at that wavelength, not the d line's birefringence.
/// The plate of `plate` with ε = 1.600 of Abbe number 20 (a two-term Cauchy law through ε at
/// 587.56 nm, computed here from the Abbe definition) and ω = 1.544 constant: 100 nm of
/// retardation at the d line become 157 nm at 450 nm, which passes `sin²(π R/λ)` = 0.79 of a
/// half-wave plate's light (without the law, 0.41: the second scene). Tolerance as in the line
/// test.
#[test]
fn an_index_with_its_own_law_sets_the_retardation_at_each_wavelength() {
    let (lambda, v_e, n_e, n_o, r_d) = (450.0f64, 20.0f64, 1.600f64, 1.544f64, 100.0f64);
    let unit_nm = r_d / (0.5 * (n_e - n_o));
    let um = |l: f64| l * 1e-3;
    let (f, c, d) = (486.13, 656.27, 587.56);
    let b = (n_e - 1.0) / (v_e * (1.0 / um(f).powi(2) - 1.0 / um(c).powi(2)));
    let n_e_at = n_e + b * (1.0 / um(lambda).powi(2) - 1.0 / um(d).powi(2));
    let r = 0.5 * unit_nm * (n_e_at - n_o);
    let want = (std::f64::consts::PI * r / lambda).sin().powi(2);
    assert!(want > 0.5, "{r} nm: {want}");
    let half = plate(lambda / 2.0, Some(lambda), false, true);
    let text = |law: &str| {
        format!(
            r#"(materials: {{}}, surface: Body,
                body: (ior: {n_o}, crystal: Uniaxial(ne: {n_e}, axis: (1.0, 0.0, 1.0), {law}
                       thin_section: (unit_nm: {unit_nm}))),
                stage: (shape: Slab(size: (0.6, 0.5, 0.6)), transform: (translate: (0.0, 0.3, 0.0)),
                        ground: Off, environment: Constant(Gray(0.0)),
                        lights: [Rect(center: (0.0, -1.0, 0.0), target: (0.0, 0.0, 0.0),
                                      size: (20.0, 20.0), radiance: Gray(1.0), polariser: 0.0,
                                      line: (wavelength: {lambda}, fwhm: 0.5))],
                        camera: Orthographic(from: (0.0, 5.0, 0.0), to: (0.0, 0.0, 0.0),
                                             up: (0.0, 0.0, -1.0), height: 1.0),
                        analyser: 0.0,
                        render: (width: 24, height: 24, spp: 256, max_depth: 16)))"#
        )
    };
    let own = compile(&text("ne_dispersion: Abbe(20.0),"));
    assert!(own.effects.on(Effect::Spectral));
    // An own law alone turns spectral transport on, and `lapidary info` names it.
    let gem = compile(
        r#"(materials: {}, surface: Body,
            body: (ior: 1.544, crystal: Uniaxial(ne: 1.553, axis: (0.0, 1.0, 0.0),
                                                 ne_dispersion: Abbe(68.5))),
            stage: (shape: Sphere(radius: 1.0)))"#,
    );
    let (why, _) = gem
        .effects
        .reason(Effect::Spectral)
        .expect("spectral is on");
    assert!(
        why.starts_with("body.crystal.ne_dispersion (thin_section.ron:3"),
        "{why}"
    );
    let luminance = |m: [f64; 3]| m[0] + m[1] + m[2];
    let (h, h_se) = plate_mean(&half);
    let (h, h_se) = (luminance(h), luminance(h_se));
    for (scene, want) in [
        (own, want),
        (
            compile(&text("")),
            (std::f64::consts::PI * r_d / lambda).sin().powi(2),
        ),
    ] {
        let (m, se) = plate_mean(&scene);
        let (m, se) = (luminance(m), luminance(se));
        let got = m / h;
        let tol = 0.006 + 5.0 * (se / h + want * h_se / h);
        eprintln!("{got:.4} (sin² πR/λ {want:.4}, ± {tol:.4})");
        assert!((got - want).abs() <= tol, "{got} vs {want}");
    }
}
