//! The lane path loop (docs/design.md §13) traces exactly the scalar integrator's paths: for every
//! scene it applies to — every opaque gem, the analytic test scenes, the peer scenes — its film
//! equals the scalar loop's film in every field of every pixel, bit for bit, under every
//! direct-light strategy, both samplers, a width that leaves a partial packet at the right edge
//! and a sample range; and the scenes it does not apply to are named with the reason.

use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Strategy, World, lanes, render_scene};
use lapidary::scene::Scene;
use lapidary::scene::stage::SamplerKind;
use std::path::Path;

fn scene(path: &Path) -> Scene {
    let text = std::fs::read_to_string(path).unwrap();
    GemRecipe::parse(path.to_str().unwrap(), &text)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every field of every pixel's sums, as bits.
fn fingerprint(world: &World, scene: &Scene, control: &Control) -> Vec<String> {
    let r = render_scene(world, scene, control);
    r.film.pixels.iter().map(|p| format!("{p:?}")).collect()
}

fn same_both_ways(name: &str, scene: &Scene, control: Control) {
    let world = World::new(scene).unwrap();
    assert_eq!(
        lanes::unsupported(&world),
        None,
        "{name}: expected the lane loop to apply"
    );
    let scalar = fingerprint(&world, scene, &control);
    let lanes = fingerprint(
        &world,
        scene,
        &Control {
            lanes: true,
            ..control
        },
    );
    let differ = lanes.iter().zip(&scalar).filter(|(a, b)| a != b).count();
    assert_eq!(
        differ, 0,
        "{name}: {differ} pixels differ between lanes and scalar"
    );
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_opaque_gem_is_the_scalar_render_bit_for_bit() {
    let mut tried = 0;
    for entry in std::fs::read_dir(root().join("gems")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let mut s = scene(&path);
        let world = World::new(&s).unwrap();
        if lanes::unsupported(&world).is_some() {
            continue;
        }
        // 37 × 13 pixels: a partial packet at every row's end.
        s.stage.render.width = 37;
        s.stage.render.height = 13;
        s.stage.render.spp = 3;
        same_both_ways(&path.display().to_string(), &s, Control::default());
        tried += 1;
    }
    assert!(tried >= 4, "only {tried} opaque gems");
}

#[test]
fn strategies_samplers_and_ranges_agree_too() {
    let mut s = scene(&root().join("gems/lepidolite.ron"));
    s.stage.render.width = 21;
    s.stage.render.height = 9;
    s.stage.render.spp = 6;
    for sampler in [SamplerKind::Sobol, SamplerKind::Independent] {
        s.stage.render.sampler = sampler;
        for strategy in [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly] {
            let control = Control {
                strategy,
                samples: Some(2..5),
                ..Control::default()
            };
            same_both_ways(&format!("lepidolite {sampler:?} {strategy:?}"), &s, control);
        }
    }
}

#[test]
fn peer_and_analytic_scenes_agree() {
    let mut paths: Vec<_> = [
        "sky-diffuse",
        "rect-rough-plastic",
        "sky-au-beckmann",
        "rect-smooth-plastic",
    ]
    .iter()
    .map(|n| root().join(format!("scripts/parity/{n}.ron")))
    .collect();
    for n in ["furnace", "mirror", "disc-light"] {
        paths.push(root().join(format!("tests/scenes/{n}.ron")));
    }
    for path in paths {
        let mut s = scene(&path);
        s.stage.render.width = 24;
        s.stage.render.height = 16;
        s.stage.render.spp = 4;
        same_both_ways(&path.display().to_string(), &s, Control::default());
    }
}

#[test]
fn scenes_the_lanes_do_not_trace_say_why() {
    for (gem, why) in [
        ("sunstone-pink", "translucent body"),
        ("oregon-sunstone", "spectral"),
        ("milky-stone", "translucent body"),
        ("brilliant-diamond", "spectral"),
    ] {
        let s = scene(&root().join(format!("gems/{gem}.ron")));
        let world = World::new(&s).unwrap();
        let said = lanes::unsupported(&world).unwrap_or("(none)");
        assert!(said.contains(why), "{gem}: {said}");
    }
}

#[test]
fn info_and_the_world_agree_on_the_loop() {
    for entry in std::fs::read_dir(root().join("gems")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let s = scene(&path);
        let world = World::new(&s).unwrap();
        assert_eq!(
            lanes::scalar_because(&s.effects).is_none(),
            lanes::unsupported(&world).is_none(),
            "{}",
            path.display()
        );
    }
}
