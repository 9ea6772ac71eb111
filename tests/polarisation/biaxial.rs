//! Biaxial crystals (`crystal: Biaxial(…)`) in polarised renders: the white furnace, the
//! polariscope's blinking and a trichroic plate's three colours in the dichroscope.

use super::{compile, dichroscope_plate, furnace_sphere, mean};
use lapidary::render::{Control, World, render_scene};
use lapidary::scene::Effect;

/// Lossless biaxial spheres in a white unpolarised furnace read 1 like the calcite sphere, within
/// 5 standard errors and the same 0.1 % for trapped light: iolite (n 1.542, 1.548, 1.551) and a
/// strongly biaxial crystal (1.5, 1.65, 1.72) with its axes turned off the view, whose paths
/// cross the optic axes and meet total internal reflection of either wave.
#[test]
fn biaxial_spheres_in_a_white_furnace() {
    for (ior, beta, gamma, x_axis, z_axis) in [
        (1.542, 1.548, 1.551, "(0.0, 1.0, 0.0)", "(1.0, 0.0, 0.0)"),
        (1.5, 1.65, 1.72, "(1.0, 1.0, 0.3)", "(-0.2, 0.4, 1.0)"),
    ] {
        let (got, se) = furnace_sphere(&format!(
            "(ior: {ior}, crystal: Biaxial(beta: {beta}, gamma: {gamma},
                                          x_axis: {x_axis}, z_axis: {z_axis}))"
        ));
        eprintln!("biaxial sphere {ior}/{beta}/{gamma}: {got:.5} ± {se:.5}");
        assert!(
            (got - 1.0).abs() < 1e-3 + 5.0 * se,
            "{ior}/{beta}/{gamma}: {got} ± {se}"
        );
    }
}

/// Between crossed polars a biaxial plate seen across two of its principal axes (X and Z in the
/// plate, n 1.542 / 1.551) blinks like a uniaxial one: dark with a principal axis along a polar,
/// brightest at 45°, following `sin² 2φ` (5 standard errors).
#[test]
fn a_biaxial_plate_blinks_between_crossed_polars() {
    let plate = |rotation: f64| {
        compile(&format!(
            r#"(materials: {{}}, surface: Body,
                body: (ior: 1.542, crystal: Biaxial(beta: 1.548, gamma: 1.551,
                       x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0))),
                stage: (preset: Polariscope(crossed: true, rotation: {rotation}),
                        shape: Slab(size: (2.0, 0.5, 2.0)), transform: (translate: (0.0, 0.3, 0.0)),
                        render: (width: 40, height: 40, spp: 16, max_depth: 16, seed: 5)))"#
        ))
    };
    let (bright, se45) = mean(&plate(45.0));
    assert!(bright > 0.05, "{bright}");
    for phi in [0.0f64, 30.0, 90.0] {
        let (got, se) = mean(&plate(phi));
        let want = bright * (2.0 * phi.to_radians()).sin().powi(2);
        let tol = 5.0 * (se * se + (se45 * want / bright).powi(2)).sqrt() + 1e-6;
        eprintln!("φ {phi}°: {got:.5} ± {se:.5} (sin² 2φ × the 45° image: {want:.5})");
        assert!(
            (got - want).abs() <= tol,
            "φ {phi}°: {got} vs {want} ± {tol}"
        );
    }
}

/// A trichroic biaxial plate in the dichroscope shows the colour of each vibration direction: seen
/// along its Z axis the two windows show α (X along the image's right) and β, seen along X they
/// show γ and β. Each window's mean over the plate matches the closed form of the dichroic test,
/// `½ τ T² (1 + τ² R²)` with each wave's own index (n_α 1.620, n_β 1.621, n_γ 1.622: at normal
/// incidence the waves vibrate along the principal axes), within 1e-3 relative plus 5 standard
/// errors (480 pixels × 16 spp per window).
#[test]
fn the_dichroscope_shows_a_trichroic_crystals_three_colours() {
    let (w, h) = (48usize, 24usize);
    // (x_axis, z_axis, [left, right] as (τ, n)).
    let views = [
        (
            "(1.0, 0.0, 0.0)",
            "(0.0, 1.0, 0.0)",
            [(0.8f64, 1.620f64), (0.5, 1.621)],
        ),
        (
            "(0.0, 1.0, 0.0)",
            "(1.0, 0.0, 0.0)",
            [(0.2, 1.622), (0.5, 1.621)],
        ),
    ];
    for (x_axis, z_axis, windows) in views {
        let s = compile(&format!(
            r#"(materials: {{}}, surface: Body,
                body: (ior: 1.620, crystal: Biaxial(beta: 1.621, gamma: 1.622,
                       x_axis: {x_axis}, z_axis: {z_axis},
                       pleochroism: (alpha: Gray(0.8), beta: Gray(0.5), gamma: Gray(0.2),
                                     distance: 0.5))),
                stage: {})"#,
            dichroscope_plate(w, h)
        ));
        assert!(s.stage.dichroscope && s.effects.on(Effect::Polarisation));
        let world = World::new(&s).expect("world");
        let img = render_scene(&world, &s, &Control::default()).film.rgb();
        let inside = |x: usize, y: usize| (7..17).contains(&(x % (w / 2))) && (7..17).contains(&y);
        for (half, (tau, n)) in windows.into_iter().enumerate() {
            let r = ((n - 1.0f64) / (n + 1.0)).powi(2);
            let t2 = (1.0 - r).powi(2);
            let v: Vec<f64> = (0..h)
                .flat_map(|y| (0..w / 2).map(move |x| (x + half * w / 2, y)))
                .filter(|&(x, y)| inside(x, y))
                .map(|(x, y)| f64::from(img[y * w + x][0]))
                .collect();
            let count = v.len() as f64;
            let m = v.iter().sum::<f64>() / count;
            let se =
                (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (count - 1.0) / count).sqrt();
            let want = 0.5 * t2 * (tau + tau.powi(3) * r * r);
            eprintln!("{x_axis} half {half}: {m:.5} ± {se:.5} (closed form {want:.5})");
            assert!(
                (m - want).abs() < 1e-3 * want + 5.0 * se,
                "{x_axis} half {half}: {m} vs {want}"
            );
        }
    }
}
