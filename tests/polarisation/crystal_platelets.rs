//! Platelets inside a crystal polarise: a platelet's conductor reflects the camera row by its
//! Fresnel matrix, and the path then takes one of the crystal's waves by the row it carries
//! (`render::polarised::take_wave`) instead of either with probability ½.
//!
//! A crystal whose two indices are equal refracts as glass, and where every vertex's plane of
//! incidence holds the optic axis its two waves are the s and p polarisations themselves; then
//! the crystal's incoherent sum of its two waves is exact, and a render through it must equal
//! the render of an isotropic body of the same index, where platelets already reflect by the
//! conductor's matrix. (With the axis tilted out of the planes of incidence the two differ: glass
//! keeps the coherence between s and p that the crystal's waves, added incoherently as in a thick
//! stone, drop — docs/polarisation.md.) The scene: a slab of index 1.55 full of near-mirror copper
//! discs parallel to its faces (most rays meet one), a lamp in the mirror direction, seen at 70°
//! through an analyser across and in the plane of incidence — light refracted in (s weakened),
//! reflected by a disc (copper: `R_s > R_p`) and refracted out. Clear, and absorbing: the glass
//! through a medium, the crystal through equal ordinary and extraordinary colours (a pleochroic
//! crystal's segment, which then takes the wave).
//!
//! Per pixel and colour channel, the crystal's image minus the glass's (the same discs: the
//! difference's spread is noise, not the discs' pattern), 32 × 32 pixels at 1 024 spp: the mean
//! within 5 standard errors plus 0.5 %. With the platelets depolarising inside the crystal (the
//! earlier rule) the clear slab's means moved by 13–16 standard errors, 2 % of the image.

use super::compile;
use lapidary::render::{Control, World, render_scene};

/// The slab, `body` the body's optics beyond its index, through an analyser at `analyser`
/// degrees from the image's right (0: across the plane of incidence).
fn slab(body: &str, analyser: f64) -> Vec<[f32; 3]> {
    let t = 70f64.to_radians();
    let (y, z) = (5.0 * t.cos(), 5.0 * t.sin());
    let mz = -z;
    let scene = compile(&format!(
        r#"(materials: {{ "mirror": (base: Conductor(metal: Copper, roughness: 0.01)) }},
            body: (ior: 1.55, {body}
                   platelets: [(radius: (0.05, 0.05), density: 200.0,
                                orientation: Aligned(axis: (0.0, 1.0, 0.0), spread: 0.0),
                                entries: [(1.0, "mirror")])]),
            surface: Body,
            stage: (shape: Slab(size: (6.0, 1.0, 6.0)), transform: (translate: (0.0, -0.5, 0.0)),
                    ground: Off, environment: Constant(Gray(0.0)),
                    lights: [Rect(center: (0.0, {y}, {mz}), target: (0.0, 0.0, 0.0),
                                  size: (3.0, 3.0), radiance: Gray(1.0))],
                    camera: Orthographic(from: (0.0, {y}, {z}), to: (0.0, 0.0, 0.0), height: 0.5),
                    analyser: {analyser},
                    render: (width: 32, height: 32, spp: 1024, max_depth: 12, seed: 9)))"#
    ));
    let world = World::new(&scene).expect("world");
    render_scene(&world, &scene, &Control::default()).film.rgb()
}

#[test]
fn platelets_in_an_index_matched_crystal_polarise_as_in_glass() {
    let crystal = "crystal: Uniaxial(ne: 1.55, axis: (0.0, 1.0, 0.0)";
    // Half the light kept per unit either way.
    let k = std::f64::consts::LN_2;
    let cases = [
        ("clear", String::new(), format!("{crystal}),")),
        (
            "absorbing",
            format!("medium: (absorption: ({k}, {k}, {k})),"),
            format!(
                "{crystal}, pleochroism: (ordinary: Gray(0.5), extraordinary: Gray(0.5), \
                 distance: 1.0)),"
            ),
        ),
    ];
    for (what, glass_body, crystal_body) in &cases {
        let mut means = vec![];
        for analyser in [0.0, 90.0] {
            let glass = slab(glass_body, analyser);
            let xtal = slab(crystal_body, analyser);
            for c in 0..3 {
                let d: Vec<f64> = xtal
                    .iter()
                    .zip(&glass)
                    .map(|(x, g)| f64::from(x[c]) - f64::from(g[c]))
                    .collect();
                let n = d.len() as f64;
                let m = d.iter().sum::<f64>() / n;
                let se = (d.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
                let level = glass.iter().map(|g| f64::from(g[c])).sum::<f64>() / n;
                eprintln!(
                    "{what}, analyser {analyser}°, channel {c}: glass {level:.5}, crystal − glass \
                     {m:+.5} ± {se:.5}"
                );
                assert!(
                    m.abs() <= 5.0 * se + 5e-3 * level,
                    "{what}, analyser {analyser}°, channel {c}: {m} ± {se} (glass {level})"
                );
                if c == 0 {
                    means.push(level);
                }
            }
        }
        // The two analysers see different images: polarisation matters here.
        assert!(means[0] > 1.1 * means[1], "{what}: {means:?}");
    }
}
