//! Pleochroism given as spectra is read per wavelength by spectral transport: a crystal's
//! ordinary and extraordinary colours given as a measured transmittance `T(λ)` absorb
//! `−ln T(λ) / distance` at each carried wavelength (and turn spectral transport on), as a body's
//! measured absorption spectrum does.
//!
//! A slab over a lamp, seen at 30°: a crystal of equal indices (its axis along the slab's normal,
//! so that its waves are the s and p of every vertex and it refracts as glass) whose two waves keep
//! `T(λ)` after one unit — 0.9, but 0.05 from 500 to 560 nm (a notch no RGB colour's smooth
//! spectrum resembles) — against glass of the same index whose `medium` absorbs the spectrum
//! `−ln T(λ)`. Spectral renders, 32 × 32 at 256 spp: each colour channel's mean within 5
//! combined standard errors plus 0.5 %. Read through the RGB projection of the coefficient
//! spectrum (the earlier rule: the smooth spectrum of that colour, which clamps the notch's
//! out-of-gamut red to 0) the red channel read 1.517 against 2.172 (checked).

use super::compile;
use lapidary::render::{Control, World, render_scene};

/// The notch: (nm, share kept after one unit).
const T: [(f64, f64); 6] = [
    (360.0, 0.9),
    (495.0, 0.9),
    (500.0, 0.05),
    (560.0, 0.05),
    (565.0, 0.9),
    (830.0, 0.9),
];

/// Mean and standard error of each colour channel over the image.
fn channels(body: &str) -> [(f64, f64); 3] {
    let t = 30f64.to_radians();
    let (y, z) = (5.0 * t.cos(), 5.0 * t.sin());
    let scene = compile(&format!(
        r#"(materials: {{}}, body: (ior: 1.5, {body}), surface: Body,
            stage: (shape: Slab(size: (40.0, 1.0, 40.0)), transform: (translate: (0.0, -0.5, 0.0)),
                    ground: Off, environment: Constant(Gray(0.0)),
                    lights: [Rect(center: (0.0, {ly}, {lz}), target: (0.0, -1.0, 0.0),
                                  size: (8.0, 8.0), radiance: Gray(2.0))],
                    camera: Orthographic(from: (0.0, {y}, {z}), to: (0.0, 0.0, 0.0), height: 0.5),
                    render: (width: 32, height: 32, spp: 256, max_depth: 12, seed: 3)))"#,
        ly = -1.0 - 3.0 * t.cos(),
        lz = -3.0 * t.sin(),
    ));
    assert!(
        scene.effects.on(lapidary::scene::Effect::Spectral),
        "a spectrum turns spectral transport on"
    );
    let world = World::new(&scene).expect("world");
    let film = render_scene(&world, &scene, &Control::default()).film.rgb();
    std::array::from_fn(|c| {
        let v: Vec<f64> = film.iter().map(|p| f64::from(p[c])).collect();
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, (var / n).sqrt())
    })
}

#[test]
fn measured_pleochroism_absorbs_per_wavelength() {
    let list = |f: &dyn Fn(f64) -> f64| {
        T.iter()
            .map(|(l, t)| format!("({l}, {})", f(*t)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let kept = list(&|t| t);
    let crystal = format!(
        "crystal: Uniaxial(ne: 1.5, axis: (0.0, 1.0, 0.0), pleochroism: (ordinary: \
         Spectrum([{kept}]), extraordinary: Spectrum([{kept}]), distance: 1.0))"
    );
    let glass = format!("medium: (absorption_spectrum: [{}])", list(&|t| -t.ln()));
    let (a, b) = (channels(&crystal), channels(&glass));
    for c in 0..3 {
        let ((x, sx), (g, sg)) = (a[c], b[c]);
        eprintln!("channel {c}: crystal {x:.5} ± {sx:.5}, glass with the medium {g:.5} ± {sg:.5}");
        assert!(
            (x - g).abs() <= 5.0 * sx.hypot(sg) + 5e-3 * g,
            "channel {c}: {x} ± {sx} vs {g} ± {sg}"
        );
    }
}
