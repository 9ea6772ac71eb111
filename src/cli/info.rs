//! `lapidary info RECIPE`: what a compiled recipe holds — its materials (which file defines each,
//! model, coats, base, share of the stone's surface), map statistics (nodes, nesting depth, cells
//! visited per lookup, and per Voronoi map its cell size, cells per unit length and volume,
//! entries, fill and bump), the stage, and every effect with the recipe element that turned it on.

use crate::bsdf::{Base, ConductorIor, StackDesc};
use crate::recipe::GemRecipe;
use crate::sampler::{Rng, hash_words};
use crate::scene::stage::{Environment, LightShape, Projection, Shape};
use crate::scene::{Effect, Scene};
use crate::texture::{MapNode, NodeId};
use anyhow::Result;
use clap::Args;
use glam::Vec3;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `lapidary info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Gem recipe (RON).
    pub recipe: PathBuf,
    /// Points sampled on the stone's surface for the material shares.
    #[arg(long, default_value_t = 20_000, value_parser = clap::value_parser!(u32).range(100..=10_000_000))]
    pub points: u32,
    /// Accuracy knobs (show what they switch).
    #[command(flatten)]
    pub knobs: super::knobs::KnobArgs,
}

/// Runs `lapidary info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let loaded = super::load::load_scene(
        &args.recipe,
        &args.knobs.accuracy().map_err(anyhow::Error::msg)?,
        None,
    )?;
    out!("{}", describe(&loaded.recipe, &loaded.scene, args.points));
    Ok(())
}

/// A stack's coats (top first) and base in one line each, as `info` and the preview's
/// inspector print them.
pub(crate) fn stack_summary(s: &StackDesc) -> (String, String) {
    let coats = if s.coats.is_empty() {
        "none".to_string()
    } else {
        s.coats
            .iter()
            .map(|c| {
                let mut t = format!("n {} m {}°", c.ior, c.roughness);
                if c.thickness > 0.0 && c.absorption.max_channel() > 0.0 {
                    t += &format!(" d {}", c.thickness);
                }
                t
            })
            .collect::<Vec<_>>()
            .join(" / ")
    };
    let base = match &s.base {
        Base::Lambert { albedo } => format!("Lambert {:.2?}", albedo.0),
        Base::OrenNayar { albedo, sigma } => format!("Oren–Nayar σ {sigma} {:.2?}", albedo.0),
        Base::Conductor { ior, roughness } => match ior {
            ConductorIor::Complex { n, k } => {
                format!("conductor m {roughness}° n {:.2?} k {:.2?}", n.0, k.0)
            }
            ConductorIor::Measured(m) => {
                let (n, k) = m.nk();
                format!(
                    "conductor m {roughness}° n {:.2?} k {:.2?} ({m:?}, measured n, k)",
                    n.0, k.0
                )
            }
            ConductorIor::Perfect => format!("perfect mirror m {roughness}°"),
        },
    };
    (coats, base)
}

/// Object-space points spread over the stone's upper surface (for material shares).
fn surface_points(shape: &Shape, n: u32, seed: u64) -> Vec<Vec3> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            // A uniform direction on the upper hemisphere, mapped onto the shape.
            let z = rng.uniform();
            let phi = std::f32::consts::TAU * rng.uniform();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let d = Vec3::new(r * phi.cos(), z, r * phi.sin());
            match *shape {
                Shape::Sphere { radius } => d * radius,
                Shape::Cabochon { radius, height, .. } => {
                    Vec3::new(d.x * radius.0, d.y * height, d.z * radius.1)
                }
                Shape::Slab { size } => Vec3::new(
                    (rng.uniform() - 0.5) * size.x,
                    size.y,
                    (rng.uniform() - 0.5) * size.z,
                ),
                Shape::Faceted(ref f) => {
                    // Where the ray from the origin along `d` leaves the solid.
                    let d64 = d.as_dvec3();
                    let t = f
                        .planes
                        .iter()
                        .filter(|p| p.normal.dot(d64) > 0.0)
                        .map(|p| p.d / p.normal.dot(d64))
                        .fold(f64::INFINITY, f64::min);
                    (d64 * t).as_vec3()
                }
                Shape::Mesh { scale, .. } => d * scale,
            }
        })
        .collect()
}

/// The whole report as text.
pub fn describe(recipe: &GemRecipe, scene: &Scene, points: u32) -> String {
    let mut o = String::new();
    let s = &scene.surface;
    let _ = writeln!(o, "{}  (recipe hash {:016x})", recipe.file(), scene.hash);

    // Shares over the surface.
    let pts = surface_points(&scene.stage.shape, points, hash_words(&[scene.hash, 7]));
    let mut counts = vec![0u32; s.leaf_names().len()];
    let mut rng = Rng::new(hash_words(&[scene.hash, 8]));
    for p in &pts {
        counts[s.map.lookup(*p, rng.uniform()).material as usize] += 1;
    }

    let _ = writeln!(
        o,
        "\nmaterials ({}, {} used):",
        s.names.len(),
        s.names.len() - s.unused().count()
    );
    let width = s.names.iter().map(|n| n.len()).max().unwrap_or(4).max(4);
    let _ = writeln!(
        o,
        "  {:>3}  {:<width$}  {:>7}  {:<10}  {:<28}  base  [file]",
        "id", "name", "share", "model", "coats"
    );
    for (i, name) in s.names.iter().enumerate() {
        let (coats, base) = stack_summary(&s.stacks[i]);
        let file = recipe.library.file_of(name).unwrap_or("?");
        let own = if file == recipe.file() {
            String::new()
        } else {
            format!("  [{file}]")
        };
        let _ = writeln!(
            o,
            "  {i:>3}  {name:<width$}  {:>6.2}%  {:<10}  {coats:<28}  {base}{own}{}",
            100.0 * f64::from(counts[i]) / f64::from(points),
            format!("{:#}", s.stacks[i].model),
            if s.used[i] {
                ""
            } else if s.unused().any(|n| n == name) {
                "  (unused)"
            } else {
                "  (platelets)"
            }
        );
    }
    if let Some(b) = &s.body {
        let i = s.body_index() as usize;
        let _ = writeln!(
            o,
            "  {i:>3}  {:<width$}  {:>6.2}%  body: {}",
            "Body",
            100.0 * f64::from(counts[i]) / f64::from(points),
            super::info_body::summary(b),
        );
        for (k, p) in b.platelets.iter().enumerate() {
            let orient = match p.orientation {
                crate::platelet::Orientation::Uniform => "random orientation".to_string(),
                crate::platelet::Orientation::Aligned { axis, spread } => format!(
                    "aligned to {:.3?} within {:.1}°",
                    axis.to_array(),
                    spread.to_degrees()
                ),
            };
            let names: Vec<&str> = p.entries.iter().map(|e| s.name(e.1)).collect();
            let _ = writeln!(
                o,
                "       platelets[{k}]: {} per unit³, radius {} … {}, {orient}; cells {:.4} \
                 ({:.2} per cell); faces {}",
                p.density,
                p.radius.0,
                p.radius.1,
                p.cell,
                p.mean_per_cell,
                names.join(", ")
            );
        }
    }

    // Map statistics.
    let map = &s.map;
    let kinds = map.nodes.iter().fold([0usize; 4], |mut k, n| {
        k[match n {
            MapNode::Material(_) => 0,
            MapNode::Voronoi(_) => 1,
            MapNode::Overlay { .. } => 2,
            MapNode::Switch { .. } => 3,
        }] += 1;
        k
    });
    let _ = writeln!(
        o,
        "\nmap: {} nodes (Voronoi {}, Overlay {}, Switch {}, Material {}), {} fields, {} entries, {} stops",
        map.nodes.len(),
        kinds[1],
        kinds[2],
        kinds[3],
        kinds[0],
        map.fields.len(),
        map.entries.len(),
        map.stops.len()
    );
    let _ = writeln!(
        o,
        "  nesting depth {} nodes; a lookup visits at most {} Voronoi cells",
        map.depth(map.root),
        map.max_trail(map.root)
    );
    let _ = writeln!(
        o,
        "  {:<44} {:>8} {:>10} {:>12} {:>7} {:>6}  bump",
        "Voronoi map (tree path)", "scale", "cells/unit", "cells/unit³", "entries", "fill"
    );
    let mut seen = vec![false; map.nodes.len()];
    let mut stack: Vec<(NodeId, String)> = vec![(map.root, "surface".into())];
    let mut rows = vec![];
    while let Some((id, path)) = stack.pop() {
        if std::mem::replace(&mut seen[id as usize], true) {
            continue;
        }
        match map.nodes[id as usize] {
            MapNode::Material(_) => {}
            MapNode::Voronoi(v) => {
                rows.push((path.clone(), v));
                for k in (0..v.count).rev() {
                    let e = map.entries[(v.first + k) as usize];
                    stack.push((e.node, format!("{path}.entries[{k}]")));
                }
            }
            MapNode::Overlay { under, over } => {
                stack.push((under, format!("{path}.under")));
                stack.push((over, format!("{path}.over")));
            }
            MapNode::Switch { first, count, .. } => {
                for k in (0..count).rev() {
                    let st = map.stops[(first + k) as usize];
                    stack.push((st.node, format!("{path}.stops[{k}]")));
                }
            }
        }
    }
    for (path, v) in rows {
        let scale = 1.0 / v.inv_scale;
        let _ = writeln!(
            o,
            "  {:<44} {:>8.4} {:>10.1} {:>12.3e} {:>7} {:>6.3}  {}",
            path,
            scale,
            v.inv_scale,
            v.inv_scale.powi(3),
            v.count,
            v.fill,
            v.bump.map_or("-".to_string(), |b| format!("{:?}", b.tilt))
        );
    }

    // Stage.
    let st = &scene.stage;
    let _ = writeln!(o, "\nstage:");
    match &st.shape {
        Shape::Faceted(f) => {
            let _ = writeln!(o, "  shape        {} (faceted)", f.label);
            let p = crate::cut::metrics::proportions(f);
            let _ = writeln!(o, "{}", p.describe("               "));
        }
        shape => {
            let _ = writeln!(o, "  shape        {shape:?}");
        }
    }
    let _ = writeln!(
        o,
        "  ground       {}",
        st.ground.map_or("off".to_string(), |g| format!(
            "plane y = {}, albedo {:.2?}",
            g.height, g.albedo.0
        ))
    );
    let env = match &st.environment {
        Environment::Constant(c) => format!("constant {:.3?}", c.0),
        Environment::Gradient {
            zenith,
            horizon,
            nadir,
        } => format!(
            "gradient zenith {:.3?} horizon {:.3?} nadir {:.3?}",
            zenith.0, horizon.0, nadir.0
        ),
        Environment::Map {
            path, intensity, ..
        } => format!("map {} × {intensity}", path.display()),
    };
    let _ = writeln!(o, "  environment  {env}");
    for (i, l) in st.lights.iter().enumerate() {
        let shape = match l.shape {
            LightShape::Rect { u, v } => {
                format!("rect {:.2} × {:.2}", 2.0 * v.length(), 2.0 * u.length())
            }
            LightShape::Disc { radius } => format!("disc r {radius:.2}"),
        };
        let _ = writeln!(
            o,
            "  light {i}      {shape} at {:.2?}, radiance {:.2?}{}{}",
            l.center.to_array(),
            l.radiance.0,
            if l.two_sided { ", two-sided" } else { "" },
            l.polariser.map_or(String::new(), |a| format!(
                ", behind a linear polariser (axis {:.3?}: passes half, polarised)",
                a.to_array()
            ))
        );
    }
    let cam = &st.camera;
    let proj = match cam.projection {
        Projection::Perspective {
            fov,
            aperture,
            focus_distance,
        } => format!(
            "perspective fov {:.1}°, aperture {aperture}, focus {focus_distance:.3}",
            fov.to_degrees()
        ),
        Projection::Orthographic { height } => format!("orthographic height {height}"),
    };
    let _ = writeln!(
        o,
        "  camera       {proj}, from {:.2?} looking {:.3?}{}",
        cam.from.to_array(),
        cam.forward.to_array(),
        st.analyser.map_or(String::new(), |a| if st.dichroscope {
            format!(
                ", a dichroscope: the left half through a linear analyser at {:.1}° from the \
                 image's right, the right half (the same view) through one at {:.1}°",
                a.to_degrees(),
                a.to_degrees() + 90.0
            )
        } else {
            format!(
                ", through a linear analyser at {:.1}° from the image's right",
                a.to_degrees()
            )
        })
    );
    let r = &st.render;
    let _ = writeln!(
        o,
        "  render       {}×{}, {} spp, max depth {}, {:?} sampler, {:?} filter, exposure {}, seed {}",
        r.width, r.height, r.spp, r.max_depth, r.sampler, r.filter, r.exposure, r.seed
    );
    if scene.surface.body.is_some() {
        let _ = writeln!(
            o,
            "  medium       depth {}, scattering {}; manifold walks: halvings per step {}, continuation {}",
            r.medium_depth,
            if r.medium_scattering {
                "on"
            } else {
                "off (absorption only)"
            },
            r.manifold_halvings,
            if r.manifold_continuation { "on" } else { "off" }
        );
    }

    // The path loop (docs/design.md §13).
    let _ = writeln!(
        o,
        "\npath loop: {}",
        match crate::render::lanes::scalar_because(&scene.effects) {
            None => format!(
                "scalar (`--lanes on`: {} paths per packet in SIMD registers, the same image; \
                 not yet faster)",
                crate::render::lanes::simd::L
            ),
            Some(why) => format!("scalar ({why} is not in the lane loop)"),
        }
    );

    // Where the material tables come from (crate::bsdf::store).
    let _ = writeln!(
        o,
        "material tables: {}",
        match crate::bsdf::store::global() {
            Some(store) => format!(
                "kept between runs in {} ({} files{}; {}=off measures them every run)",
                store.dir().display(),
                std::fs::read_dir(store.dir()).map_or(0, |d| d.count()),
                if store.full() {
                    format!(
                        ", at its bound of {}: the next table stored first removes the oldest \
                         of the store's own files",
                        crate::bsdf::store::MAX_FILES
                    )
                } else {
                    String::new()
                },
                crate::bsdf::store::ENV
            ),
            None => format!(
                "measured every run (no table cache: {} is off or no cache folder is known)",
                crate::bsdf::store::ENV
            ),
        }
    );

    // Effects.
    let _ = writeln!(o, "\neffects:");
    for e in Effect::ALL {
        let called = scene.effects.reason(e).map(|(why, n)| {
            let more = if n > 1 {
                format!(" (+{} more)", n - 1)
            } else {
                String::new()
            };
            format!("{why}{more}")
        });
        let state = if scene.effects.on(e) { "on " } else { "off" };
        let line = match (scene.effects.forced(e), scene.effects.forced_by(e), called) {
            (Some(on), Some(by), called) => format!(
                "forced {} by {by}; {}",
                if on { "on" } else { "off" },
                called.map_or_else(
                    || "the scene does not call for it".to_string(),
                    |c| format!("called for by {c}")
                )
            ),
            (_, _, Some(c)) => c,
            _ => format!("needs {}", e.trigger()),
        };
        let _ = writeln!(o, "  {state}  {:<24} {line}", e.name());
    }
    if !scene.accuracy.is_default() {
        let _ = writeln!(o, "\naccuracy knobs: {}", scene.accuracy);
    }
    o
}
