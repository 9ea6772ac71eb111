//! The manifold tests' scene (tests only).

/// The tests' scene: a stone `shape` with the body `body` (recipe text), its surface the bare
/// boundary, under a disc light of radius 0.5 at height 4.
pub(super) fn test_world(shape: &str, body: &str) -> crate::render::World {
    let text = format!(
        "(materials: {{ \"m\": (coats: [], base: Lambert(albedo: Gray(0.5))) }},
          body: {body}, surface: Body,
          stage: (shape: {shape},
                  lights: [Disc(center: (0.0, 4.0, 0.0), target: (0.0, 0.0, 0.0),
                                radius: 0.5, radiance: Gray(20.0))]))"
    );
    let scene = crate::recipe::GemRecipe::parse("t.ron", &text)
        .unwrap()
        .compile()
        .unwrap();
    crate::render::World::new(&scene).unwrap()
}
