//! Item 5 of tests/smooth_coat.rs: a white Lambert sphere under a smooth clear coat in a white
//! furnace, rendered through the library API, must render 1 (see the module docs there).

use glam::Vec2;
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Strategy, World, render};
use lapidary::scene::Effect;

/// Renders the furnace at `size`² pixels and `spp` under `strategy` with the material's `model`
/// (RON), and asserts the mean over the sphere's pixels is 1 within 3σ + 0.5 % and no pixel
/// exceeds 1 by more than 5σ.
pub fn furnace(size: u32, spp: u32, strategy: Strategy, model: &str) {
    let text = format!(
        r#"(materials: {{ "coated": (coats: [(ior: 1.5, roughness: 0.0)], base: Lambert(albedo: Gray(1.0)), model: {model}) }},
            surface: Material("coated"),
            stage: (shape: Sphere(radius: 1.0), ground: Off, lights: [], environment: Constant(Gray(1.0)),
                    camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0), height: 2.4),
                    render: (sampler: Independent, width: {size}, height: {size}, spp: {spp}, max_depth: 8)))"#
    );
    let scene = GemRecipe::parse("furnace.ron", &text)
        .and_then(|r| r.compile())
        .expect("compiles");
    let world = World::new(&scene).expect("world");
    let control = Control {
        strategy,
        ..Control::default()
    };
    let dof = scene.effects.on(Effect::DepthOfField);
    let r = render(
        &world,
        &scene.stage.camera,
        dof,
        &scene.stage.render,
        &control,
    );
    assert_eq!(r.stats.dropped, 0);
    // Pixels whose whole filter footprint lies on the sphere (as tests/render.rs).
    let px = 2.4 / size as f32;
    let pixels: Vec<(u32, u32, [f32; 3], [f32; 3])> = (0..size * size)
        .map(|i| (i % size, i / size))
        .filter(|&(x, y)| {
            let p = Vec2::new((x as f32 + 0.5) * px - 1.2, 1.2 - (y as f32 + 0.5) * px);
            p.length() < 1.0 - 2.2 * px
        })
        .map(|(x, y)| {
            let pixel = &r.film.pixels[(y * size + x) as usize];
            (x, y, pixel.mean().0, pixel.variance_of_mean())
        })
        .collect();
    let n = pixels.len() as f64;
    let mut worst_z = f64::MIN;
    for c in 0..3 {
        let sum: f64 = pixels.iter().map(|p| f64::from(p.2[c])).sum();
        let var: f64 = pixels.iter().map(|p| f64::from(p.3[c])).sum();
        let (mean, se) = (sum / n, var.sqrt() / n);
        if c == 0 {
            println!("furnace {strategy:?} {model}: {n} pixels, mean {mean:.5} ± {se:.5}");
        }
        assert!(
            (mean - 1.0).abs() <= 3.0 * se + 0.005,
            "{strategy:?} {model}: mean {mean} ± {se}"
        );
        // A path's value is skewed (mostly just above 1, a tail below), so a pixel that drew
        // few tail samples has a high mean *and* a low variance estimate: each pixel's σ is the
        // larger of its own and the sphere's mean variance.
        for &(x, y, m, v) in &pixels {
            let sd = f64::from(v[c]).max(var / n).sqrt();
            worst_z = worst_z.max((f64::from(m[c]) - 1.0) / sd);
            let msg = format!(
                "{strategy:?} {model}: pixel ({x}, {y}) channel {c} = {} ± {sd:.4}",
                m[c]
            );
            assert!(f64::from(m[c]) - 1.0 <= 5.0 * sd + 1e-5, "{msg}");
        }
    }
    println!("  largest pixel (m − 1)/σ {worst_z:.2}");
}
