//! Resolves a recipe's `stage` over the studio stage: replaced parts converted to runtime form,
//! files (meshes, environment maps) checked to exist relative to the recipe, geometry checked
//! (a light facing its own centre, a camera looking along its up vector), and the stage's effects
//! (depth of field, environment importance sampling) turned on with their reasons.

use super::RecipeError;
use super::gem::GemRecipe;
use super::stage::{
    CameraDesc, EnvironmentDesc, FilterDesc, GroundDesc, LightDesc, SamplerDesc, ShapeDesc,
};
use crate::color::Rgb;
use crate::scene::stage::{
    AreaLight, Camera, Environment, Filter, Ground, LightShape, Projection, SamplerKind, Shape,
    Stage, light_axis, placement, rect_light,
};
use crate::scene::{Effect, Effects};
use glam::Vec3;
use std::path::PathBuf;

fn v3(v: (f32, f32, f32)) -> Vec3 {
    Vec3::new(v.0, v.1, v.2)
}

/// The resolved stage, or `None` after pushing errors.
pub(crate) fn stage(
    r: &GemRecipe,
    effects: &mut Effects,
    errors: &mut Vec<RecipeError>,
) -> Option<Stage> {
    let preset = r.content.stage.as_ref().and_then(|s| s.preset);
    let mut stage = match preset {
        Some(super::stage::StagePreset::Jeweller) => Stage::jeweller(),
        Some(super::stage::StagePreset::Polariscope { crossed, .. }) => Stage::polariscope(crossed),
        Some(super::stage::StagePreset::Dichroscope { .. }) => Stage::dichroscope(),
        _ => Stage::studio(),
    };
    let n_errors = errors.len();
    let src = &r.source;
    let stage_at = src.find(&["stage", ":"]);
    let part_at = |name: &str| {
        stage_at
            .and_then(|s| src.find_from(s, &[name, ":"]))
            .or(stage_at)
    };
    // A referenced file relative to the recipe: must be a regular file with the right extension.
    let mut file = |name: &str, ext: &str, what: &str| -> Option<PathBuf> {
        let at = src.find(&[&format!("{name:?}")]).or(stage_at);
        let path = r.base_dir().join(name);
        let ok_ext = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext));
        if !ok_ext {
            errors.push(src.error(at, format!("{what} \"{name}\": expected a .{ext} file")));
            None
        } else if let Err(e) = crate::image::input_kind::regular_file(&path) {
            // Says "is a directory", "is a FIFO", … rather than "no such file".
            errors.push(src.error(
                at,
                format!(
                    "{what} \"{name}\": {e} ({} relative to the recipe)",
                    path.display()
                ),
            ));
            None
        } else {
            Some(path)
        }
    };
    let colour = |c: &super::color::ColorDesc| c.to_rgb().unwrap_or(Rgb::ZERO);

    let Some(desc) = &r.content.stage else {
        return Some(stage);
    };
    // A faceted shape's errors (pushed once `file` no longer holds `errors`).
    let mut shape_errors = vec![];
    if let Some(shape) = &desc.shape {
        stage.shape = match shape {
            ShapeDesc::Sphere { radius } => Shape::Sphere { radius: *radius },
            ShapeDesc::Cabochon {
                radius,
                height,
                base,
            } => Shape::Cabochon {
                radius: *radius,
                height: *height,
                base: *base,
            },
            ShapeDesc::Slab { size } => Shape::Slab { size: v3(*size) },
            ShapeDesc::Cut(c) => {
                super::faceted::cut(r, c, &mut shape_errors).unwrap_or(stage.shape.clone())
            }
            ShapeDesc::Design { file: name, width } => file(name, "asc", "design")
                .and_then(|p| super::faceted::design(r, &p, name, *width, &mut shape_errors))
                .unwrap_or(stage.shape.clone()),
            ShapeDesc::Mesh { file: name, scale } => Shape::Mesh {
                path: file(name, "obj", "mesh").unwrap_or_default(),
                scale: *scale,
            },
        };
    }
    if let Some(t) = &desc.transform {
        stage.to_world = placement(t.scale, v3(t.rotate), v3(t.translate));
    }
    if let Some(g) = &desc.ground {
        stage.ground = match g {
            GroundDesc::Off => None,
            GroundDesc::Plane { height, albedo } => Some(Ground {
                height: *height,
                albedo: colour(albedo),
            }),
        };
    }
    if let Some(env) = &desc.environment {
        stage.environment = match env {
            EnvironmentDesc::Constant(c) => Environment::Constant(colour(c)),
            EnvironmentDesc::Gradient {
                zenith,
                horizon,
                nadir,
            } => Environment::Gradient {
                zenith: colour(zenith),
                horizon: colour(horizon),
                nadir: colour(nadir),
            },
            EnvironmentDesc::Map {
                file: name,
                intensity,
                rotate,
            } => Environment::Map {
                path: file(name, "exr", "environment map").unwrap_or_default(),
                intensity: *intensity,
                rotate: rotate.to_radians(),
            },
        };
    }
    errors.append(&mut shape_errors);
    if let Some(lights) = &desc.lights {
        let lights_at = part_at("lights");
        stage.lights.clear();
        for (i, l) in lights.iter().enumerate() {
            let (center, target) = match l {
                LightDesc::Rect { center, target, .. } | LightDesc::Disc { center, target, .. } => {
                    (v3(*center), v3(*target))
                }
            };
            if (target - center).length() <= 1e-6 * center.length().max(1.0) {
                errors.push(src.error(
                    lights_at.and_then(|l| src.nth_element(l, i)).or(lights_at),
                    format!("stage.lights[{i}]: `target` equals `center`; a light must face a point away from itself"),
                ));
                continue;
            }
            let (radiance, spectrum, line, divergence, two_sided, polariser) = match l {
                LightDesc::Rect {
                    radiance,
                    intensity,
                    spectrum,
                    line,
                    divergence,
                    two_sided,
                    polariser,
                    ..
                }
                | LightDesc::Disc {
                    radiance,
                    intensity,
                    spectrum,
                    line,
                    divergence,
                    two_sided,
                    polariser,
                    ..
                } => (
                    colour(radiance) * *intensity,
                    spectrum,
                    line,
                    *divergence,
                    *two_sided,
                    *polariser,
                ),
            };
            let polariser = polariser.map(|a| light_axis((target - center).normalize(), a));
            let light_error = |key: &str, m: &str| {
                let at = lights_at.and_then(|l| src.nth_element(l, i)).or(lights_at);
                let at = at.and_then(|a| src.find_from(a, &[key, ":"])).or(at);
                src.error(at, format!("stage.lights[{i}].{key}: {m}"))
            };
            if line.is_some() && spectrum.is_some() {
                errors.push(light_error(
                    "line",
                    "give either `spectrum` or `line`, not both",
                ));
                continue;
            }
            if divergence.is_some() && two_sided {
                errors.push(light_error(
                    "divergence",
                    "a beam is one-sided: remove `two_sided` or `divergence`",
                ));
                continue;
            }
            let divergence = divergence.map(f32::to_radians);
            let line = line.as_ref().map(|d| {
                crate::spectrum::line::Line::new(d.wavelength, d.fwhm)
                    .with_luminance(radiance.luminance())
            });
            // A line gives the light its colour and keeps its luminance.
            let radiance = line.map_or(radiance, |l| {
                keep_luminance(l.to_rgb_emission(), radiance.luminance())
            });
            // A measured spectrum keeps the light's luminance and gives it its colour.
            let (radiance, spectrum) = match spectrum {
                None => (radiance, None),
                Some(points) => {
                    let fail = |m: String| {
                        let at = lights_at.and_then(|l| src.nth_element(l, i)).or(lights_at);
                        let at = at.and_then(|a| src.find_from(a, &["spectrum", ":"])).or(at);
                        src.error(at, format!("stage.lights[{i}].spectrum: {m}"))
                    };
                    match points.measured(1e9) {
                        Err(m) => {
                            errors.push(fail(m));
                            continue;
                        }
                        Ok(m) if !(m.luminance() > 0.0) => {
                            errors.push(fail(
                                "the spectrum has no luminance (it is zero over 360 ..= 830 nm)"
                                    .into(),
                            ));
                            continue;
                        }
                        Ok(m) => {
                            let m = m.scaled(radiance.luminance() / m.luminance());
                            (
                                keep_luminance(m.to_rgb_emission(), radiance.luminance()),
                                Some(m),
                            )
                        }
                    }
                }
            };
            stage.lights.push(match l {
                LightDesc::Rect {
                    size, two_sided, ..
                } => AreaLight {
                    two_sided: *two_sided,
                    spectrum,
                    line,
                    divergence,
                    polariser,
                    ..rect_light(center, target, *size, radiance)
                },
                LightDesc::Disc {
                    radius, two_sided, ..
                } => AreaLight {
                    center,
                    normal: (target - center).normalize(),
                    shape: LightShape::Disc { radius: *radius },
                    radiance,
                    two_sided: *two_sided,
                    spectrum,
                    line,
                    divergence,
                    polariser,
                },
            });
        }
    }
    if let Some(cam) = &desc.camera {
        let (from, to, up, projection) = match cam {
            CameraDesc::Perspective {
                from,
                to,
                up,
                fov,
                aperture,
                focus_distance,
            } => (
                v3(*from),
                v3(*to),
                v3(*up),
                Projection::Perspective {
                    fov: fov.to_radians(),
                    aperture: *aperture,
                    focus_distance: focus_distance.unwrap_or((v3(*to) - v3(*from)).length()),
                },
            ),
            CameraDesc::Orthographic {
                from,
                to,
                up,
                height,
            } => (
                v3(*from),
                v3(*to),
                v3(*up),
                Projection::Orthographic { height: *height },
            ),
        };
        match Camera::look_at(from, to, up, projection) {
            Some(c) => stage.camera = c,
            None => errors.push(src.error(
                part_at("camera"),
                if (to - from).length() <= 1e-6 * from.length().max(1.0) {
                    format!("stage.camera: `to` = {to} equals `from`; the camera must look at a point away from itself")
                } else {
                    format!("stage.camera: `up` = {up} is parallel to the view direction {}; give an up vector across it", (to - from).normalize())
                },
            )),
        }
    }
    let rd = &desc.render;
    let rs = &mut stage.render;
    rs.width = rd.width.unwrap_or(rs.width);
    rs.height = rd.height.unwrap_or(rs.height);
    let pixels = u64::from(rs.width) * u64::from(rs.height);
    if pixels > crate::scene::stage::MAX_PIXELS {
        errors.push(src.error(
            part_at("render"),
            format!(
                "stage.render: {}x{} is {pixels} pixels; at most {} (8192x8192, about 25 GiB of \
                 film) — each side 1 ..= {}",
                rs.width,
                rs.height,
                crate::scene::stage::MAX_PIXELS,
                crate::scene::stage::MAX_SIDE
            ),
        ));
    }
    rs.spp = rd.spp.unwrap_or(rs.spp);
    rs.max_depth = rd.max_depth.unwrap_or(rs.max_depth);
    rs.medium_depth = rd.medium_depth.unwrap_or(rs.medium_depth);
    rs.medium_scattering = rd.medium_scattering.unwrap_or(rs.medium_scattering);
    rs.manifold_continuation = rd.manifold_continuation.unwrap_or(rs.manifold_continuation);
    rs.manifold_halvings = rd.manifold_halvings.unwrap_or(rs.manifold_halvings);
    if let Some(f) = rd.platelets {
        rs.platelets_explicit = f == super::stage::PlateletForm::Explicit;
    }
    rs.exposure = rd.exposure.unwrap_or(rs.exposure);
    rs.seed = rd.seed.unwrap_or(rs.seed);
    if let Some(s) = rd.sampler {
        rs.sampler = match s {
            SamplerDesc::Independent => SamplerKind::Independent,
            SamplerDesc::Sobol => SamplerKind::Sobol,
        };
    }
    if let Some(f) = rd.filter {
        rs.filter = match f {
            FilterDesc::Box => Filter::Box,
            FilterDesc::Gaussian { radius } => Filter::Gaussian { radius },
        };
    }
    if let Some(a) = desc.analyser {
        stage.analyser = Some(a.to_radians());
    }
    if let Some(
        super::stage::StagePreset::Polariscope { rotation, .. }
        | super::stage::StagePreset::Dichroscope { rotation },
    ) = preset
    {
        stage.to_world = glam::Affine3A::from_rotation_y(rotation.to_radians()) * stage.to_world;
    }
    stage_effects(&stage, effects);
    (errors.len() == n_errors).then_some(stage)
}

/// An emission colour clamped into the sRGB gamut ([`crate::spectrum::line::Line::to_rgb_emission`])
/// scaled back to its spectrum's luminance `y`: clamping a 532 nm laser's negative red and blue
/// raises its luminance by 19 %, which an RGB render would otherwise add to everything it lights.
fn keep_luminance(rgb: Rgb, y: f32) -> Rgb {
    let have = rgb.luminance();
    if have > 0.0 && y.is_finite() {
        rgb * (y / have)
    } else {
        rgb
    }
}

/// Effects the stage calls for.
pub(crate) fn stage_effects(stage: &Stage, effects: &mut Effects) {
    if let Projection::Perspective { aperture, .. } = stage.camera.projection
        && aperture > 0.0
    {
        effects.turn_on(
            Effect::DepthOfField,
            format!("stage.camera aperture = {aperture}"),
        );
    }
    if let Environment::Map { path, .. } = &stage.environment {
        effects.turn_on(
            Effect::EnvironmentImportance,
            format!("stage.environment Map(\"{}\")", path.display()),
        );
    }
    // The analyser first: its reason is what tells the lane loop's check that one is there.
    if let Some(a) = stage.analyser {
        let reason = if stage.dichroscope {
            format!(
                "the Dichroscope's analysers at {:.1}° (left) and {:.1}° (right)",
                a.to_degrees(),
                a.to_degrees() + 90.0
            )
        } else {
            format!("stage.analyser = {:.1}°", a.to_degrees())
        };
        effects.turn_on(Effect::Polarisation, reason);
    }
    for (i, l) in stage.lights.iter().enumerate() {
        if l.spectrum.is_some() {
            effects.turn_on(Effect::Spectral, format!("stage.lights[{i}].spectrum"));
        }
        if l.line.is_some() {
            effects.turn_on(Effect::Spectral, format!("stage.lights[{i}].line"));
        }
        if l.polariser.is_some() {
            effects.turn_on(Effect::Polarisation, format!("stage.lights[{i}].polariser"));
        }
    }
}
