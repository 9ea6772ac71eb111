//! The pixel inspector: what the camera ray through one pixel meets — the material and the map
//! path that chose it (each Voronoi map's cell and entry, each overlay's and switch's branch),
//! the BSDF model and its knobs, the facet normal — and, for a translucent body, what the refracted
//! ray meets inside (a platelet, the medium, the far side), with the pixel's radiance ± σ.

use super::state::Image;
use crate::bsdf::{StackDesc, refract};
use crate::geometry::{Ray, StoneHit, offset_origin};
use crate::medium::Medium;
use crate::render::CameraRays;
use crate::render::world::Hit;
use crate::texture::{MapDecision, MapStep};
use glam::{Vec2, Vec3};
use serde_json::{Value, json};

/// The camera ray through the centre of film pixel `(x, y)` of `image`: what it hits first and
/// its (unit) direction.
pub(super) fn primary_hit(image: &Image, x: u32, y: u32) -> (Option<Hit>, Vec3) {
    primary_hit_with(image, &camera_rays(image), x, y)
}

/// The camera rays of `image`'s film (made once for a whole frame of [`primary_hit_with`]).
pub(super) fn camera_rays(image: &Image) -> CameraRays {
    let (w, h) = (image.film.width, image.film.height);
    CameraRays::new(&image.scene.stage.camera, w, h, false)
}

/// [`primary_hit`] with the film's camera rays made already.
pub(super) fn primary_hit_with(
    image: &Image,
    rays: &CameraRays,
    x: u32,
    y: u32,
) -> (Option<Hit>, Vec3) {
    let ray = rays.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
    (image.world.intersect(&ray, f32::INFINITY), ray.dir)
}

/// The switch number the inspector looks the map up with. Inside a stochastic blend band the
/// stop is drawn per sample; the inspector shows the draw for `u = ½` and says the point is in a
/// band.
const INSPECT_U: f32 = 0.5;

/// The inspector's JSON for requested-image pixel `(x, y)`; `None` outside the image.
pub fn inspect(image: &Image, x: u32, y: u32) -> Option<Value> {
    let s = image.scale.max(1);
    let (fx, fy) = (x / s, y / s);
    if fx >= image.film.width || fy >= image.film.height {
        return None;
    }
    let p = &image.film.pixels[(fy * image.film.width + fx) as usize];
    let sigma = p.variance_of_mean().map(f32::sqrt);
    let (hit, dir) = primary_hit(image, fx, fy);
    let mut out = json!({
        "x": x, "y": y,
        "radiance": p.mean().0, "sigma": sigma, "spp": p.n,
        "albedo": p.mean_albedo(),
        "depth": (p.depth_n > 0).then(|| p.mean_depth()),
        "hit": "sky", "point": null, "normal": null, "facet_normal": null,
        "material": null, "map": [], "cells": [], "glitter_cell": null, "inside": null,
        "facet": null,
        // The mean Stokes vector per colour channel (S0…S3, each R, G, B) with `--stokes`.
        "stokes": image
            .film
            .stokes
            .get((fy * image.film.width + fx) as usize)
            .map(|st| st.mean(p.n)),
    });
    let surface = &image.scene.surface;
    match hit {
        Some(Hit::Stone(h)) => {
            let look = image.world.map.explain(h.p_object, INSPECT_U);
            let m = look.hit.material;
            out["hit"] = json!("stone");
            out["point"] = json!(h.p.to_array());
            out["normal"] = json!(h.ns.to_array());
            out["facet_normal"] = json!(look.hit.facet.map(|f| f.to_array()));
            // A faceted stone's facet, by name.
            if let (Some(k), crate::geometry::Shape::Faceted(f)) =
                (h.facet, &image.scene.stage.shape)
            {
                out["facet"] = json!(f.names.get(k as usize));
            }
            out["material"] = json!({
                "index": m,
                "name": surface.name(m),
                "model": surface.stacks.get(m as usize).map_or_else(
                    || json!({ "summary": "the translucent body's bare boundary" }),
                    stack_json,
                ),
            });
            out["map"] = Value::Array(look.steps.iter().map(|s| step_json(image, s)).collect());
            out["cells"] = json!(look.hit.trail.ids().iter().map(hex).collect::<Vec<_>>());
            out["glitter_cell"] = json!(look.hit.trail.glitter_cell().as_ref().map(hex));
            if m == surface.body_index() {
                out["inside"] = inside(image, &h, dir);
            }
        }
        Some(Hit::Ground { p, .. }) => {
            out["hit"] = json!("ground");
            out["point"] = json!(p.to_array());
            let up = if dir.y <= 0.0 { 1.0 } else { -1.0 };
            out["normal"] = json!([0.0, up, 0.0]);
        }
        Some(Hit::Light { index, .. }) => {
            out["hit"] = json!(format!("light {index}"));
        }
        Some(Hit::Platelet { p, material, .. }) => {
            // Only a camera inside the body meets a platelet first.
            out["hit"] = json!("platelet");
            out["point"] = json!(p.to_array());
            out["material"] = json!({ "index": material, "name": surface.name(material) });
        }
        None => {}
    }
    Some(out)
}

fn hex(c: &u64) -> String {
    format!("{c:016x}")
}

/// A layered stack's model, its knobs and its layers.
fn stack_json(d: &StackDesc) -> Value {
    let (coats, base) = crate::cli::info::stack_summary(d);
    json!({
        "summary": format!("{:#}; coats {coats}; base {base}", d.model),
        "model": d.model.to_string(),
        "fresnel": d.fresnel.to_string(),
        "distribution": d.distribution.to_string(),
        "masking": d.masking.to_string(),
        "compensation": d.compensation,
        "calibration": d.calibration,
        "coats": coats,
        "base": base,
    })
}

/// One node of the map walk: its path, the name of the named map it is (`defined`), and what it
/// decided.
fn step_json(image: &Image, s: &MapStep) -> Value {
    let defined = image
        .scene
        .surface
        .map_labels
        .get(s.node as usize)
        // Only a named map's own node: the nodes inside it are known by their path.
        .filter(|l| l.starts_with("maps.\"") && l.ends_with('"') && **l != s.path)
        .cloned();
    // A switched-off overlay (`--effect glitter-overlay=off`) is a copy of its lower map.
    let replaced = matches!(
        image.scene.surface.map.nodes.get(s.node as usize),
        Some(crate::texture::MapNode::Overlay { .. })
    ) && !matches!(s.decision, MapDecision::Overlay { .. });
    let mut v = match s.decision {
        MapDecision::Voronoi {
            cell,
            filled,
            fill,
            entry,
            entries,
            bump,
        } => json!({
            "kind": if fill < 1.0 { "Voronoi (sparse)" } else { "Voronoi" },
            "cell": hex(&cell), "filled": filled, "fill": fill,
            "entry": entry, "entries": entries, "bump": bump,
        }),
        MapDecision::Overlay { over } => json!({
            "kind": "Overlay",
            "shows": if over { "over" } else { "under (over is transparent here)" },
        }),
        MapDecision::Switch {
            value,
            stop,
            stops,
            in_band,
        } => json!({
            "kind": "Switch", "value": value, "stop": stop, "stops": stops, "in_band": in_band,
        }),
        MapDecision::Material { index } => json!({
            "kind": "Material", "index": index, "name": image.scene.surface.name(index),
        }),
    };
    v["path"] = json!(s.path);
    v["level"] = json!(s.level);
    v["defined"] = json!(defined);
    if replaced {
        v["note"] = json!("overlay switched off: its lower map");
    }
    v
}

/// What the camera ray refracted into a translucent body meets: the first platelet, or the far
/// side, with the interior's transmittance along the way. The refraction is the smooth one at the
/// body's index (for a rough boundary, the mean direction).
fn inside(image: &Image, h: &StoneHit, dir: Vec3) -> Value {
    let world = &image.world;
    let Some(body) = image.scene.surface.body.as_ref() else {
        return Value::Null;
    };
    let Some(wi) = refract(-dir, h.ns, body.ior) else {
        return json!({ "ior": body.ior, "refracted": null });
    };
    let ray = Ray::in_medium(offset_origin(h.p, h.ng, wi), wi, world.interior);
    let exit = world
        .stone
        .intersect(&ray, f32::INFINITY)
        .map(|e| e.t)
        .unwrap_or(f32::INFINITY);
    let platelet = (!world.platelets.is_empty())
        .then(|| world.platelet_hit(&ray, exit, None))
        .flatten();
    let reach = platelet.map_or(exit, |p| p.t());
    let medium = world.media.get(usize::from(world.interior.0));
    let (coefficients, transmittance) = match medium {
        Some(Medium::Homogeneous(m)) => {
            let t = |a: f32, s: f32| (-(a + s) * reach).exp();
            let (a, s) = (m.sigma_a.0, m.sigma_s.0);
            (
                json!({ "sigma_a": a, "sigma_s": s, "g": m.phase.g }),
                json!([t(a[0], s[0]), t(a[1], s[1]), t(a[2], s[2])]),
            )
        }
        _ => (json!("clear"), json!([1.0, 1.0, 1.0])),
    };
    let platelet = match platelet {
        Some(Hit::Platelet {
            t, p, n, material, ..
        }) => json!({
            "distance": t,
            "point": p.to_array(),
            "normal": n.to_array(),
            "incidence_deg": wi.dot(n).abs().clamp(0.0, 1.0).acos().to_degrees(),
            "material": { "index": material, "name": image.scene.surface.name(material) },
        }),
        _ => Value::Null,
    };
    let angle = |w: Vec3| w.dot(h.ns).abs().clamp(0.0, 1.0).acos().to_degrees();
    json!({
        "ior": body.ior,
        "rough_boundary": body.alpha > 0.0,
        "incidence_deg": angle(-dir),
        "refraction_deg": angle(wi),
        "refracted": wi.to_array(),
        "exit_distance": exit.is_finite().then_some(exit),
        "platelet": platelet,
        "flakes": world.flakes.is_some(),
        "medium": coefficients,
        "transmittance": transmittance,
    })
}
