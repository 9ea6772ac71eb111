//! The `light-prefilter` effect in [`super::World`]: an RGB render of a stage whose lights have a
//! spectrum reduces its materials under that light ([`crate::spectrum::prefilter`]; Ward &
//! Eydelberg-Vileshin, EGWR 2002). Here: which emitters make the scene's light and how much each
//! brings, and which parts of a material description change.
//!
//! **The scene's light.** Every emitter is weighted by the irradiance it would bring to the
//! stone's centre `p` without occlusion: a light by its luminance times the solid angle it
//! subtends, `A |cos θ_light| / d²` (at most 2π), the sky by its mean luminance times 4π. A beam
//! (`divergence`) counts like the disc it leaves, as if `p` were in it: a laser is aimed at the
//! stone. In the day-glo scenes the laser brings about 10⁵ times the dark room's sky.
//!
//! **The second tier** takes the colorants of the used materials (a fluorescent base's).
//!
//! **What changes.** The RGB albedo of every Lambert and Oren–Nayar base (from its measured
//! spectrum, a fluorescent base's elastic reflectance, or the upsampled RGB colour that spectral
//! renders use; a grey albedo is flat and stays as it is), the floor's albedo likewise, and a
//! fluorescent colorant's matrix. Conductor bases and coat tints keep their D65 values (their RGB
//! tables are per channel; documented in docs/fluorescence.md).

use crate::bsdf::layered::{Base, StackDesc};
use crate::color::Rgb;
use crate::light::{Area, EnvironmentLight};
use crate::scene::stage::AreaLight;
use crate::spectrum::fluorescence::Fluorescence;
use crate::spectrum::prefilter::{Prefilter, Source};
use crate::spectrum::rgb2spec;
use glam::Vec3;
use std::f32::consts::PI;
use std::sync::Arc;

/// The prefilter for `lights` and `environment` seen from `p`, with what the scene's fluorescent
/// `colorants` re-emit under them as its second tier (module docs); `None` when the scene's light
/// needs none (only grey lights and sky).
pub(super) fn scene_light<'a>(
    lights: &[AreaLight],
    environment: &EnvironmentLight,
    p: Vec3,
    colorants: impl IntoIterator<Item = &'a Fluorescence>,
) -> Option<Prefilter> {
    let mut sources = vec![];
    for l in lights {
        let omega = solid_angle(l, p);
        let weight = l.radiance.luminance() * omega;
        let source = match (&l.line, &l.spectrum) {
            (Some(line), _) => Source::line(line, weight),
            (None, Some(m)) => Source::measured(m, weight),
            (None, None) => Source::rgb(l.radiance, weight),
        };
        sources.extend(source);
    }
    if !environment.is_black() {
        let sky = mean_radiance(environment);
        sources.extend(Source::rgb(sky, sky.luminance() * 4.0 * PI));
    }
    let mut p = Prefilter::new(sources)?;
    // Each distinct colorant once: materials sharing a dye re-emit one light, not several.
    let mut seen: Vec<&Fluorescence> = vec![];
    for f in colorants {
        if !seen.contains(&f) {
            p.add_reemission(f);
            seen.push(f);
        }
    }
    Some(p)
}

/// The solid angle the light subtends from `p`, sr: `A |cos θ_light| / d²`, at most 2π (area
/// and normal as the renderer's [`Area`] has them; 0 for a degenerate light).
fn solid_angle(l: &AreaLight, p: Vec3) -> f32 {
    let light = Area::new(l);
    let d = l.center - p;
    let d2 = d.length_squared();
    let cos = if d2 > 0.0 {
        light.normal().dot(d / d2.sqrt()).abs()
    } else {
        1.0
    };
    let omega = light.area() * cos / d2;
    if omega.is_finite() {
        omega.min(2.0 * PI)
    } else {
        2.0 * PI
    }
}

/// The sky's mean radiance over the sphere: a 32 × 64 midpoint grid in `(cos θ, φ)` (equal solid
/// angles).
fn mean_radiance(environment: &EnvironmentLight) -> Rgb {
    let (nz, nphi) = (32, 64);
    let mut sum = [0.0f64; 3];
    for i in 0..nz {
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / nz as f32;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * PI * (j as f32 + 0.5) / nphi as f32;
            let c = environment.radiance(Vec3::new(r * phi.cos(), z, r * phi.sin()));
            for (s, v) in sum.iter_mut().zip(c.0) {
                *s += f64::from(v);
            }
        }
    }
    Rgb(sum.map(|s| (s / f64::from(nz * nphi)) as f32))
}

/// `albedo` (a base's RGB, the D65 projection of `spectrum` when it has one) under the scene's
/// light; a grey albedo without a spectrum is flat and unchanged.
pub(super) fn albedo(
    p: &Prefilter,
    albedo: Rgb,
    spectrum: Option<&crate::spectrum::measured::Measured>,
) -> Rgb {
    match spectrum {
        Some(m) => p.reflectance(|l| m.at(l), albedo),
        None if albedo.0[0] == albedo.0[1] && albedo.0[1] == albedo.0[2] => albedo,
        None => {
            let s = rgb2spec::reflectance(albedo.0);
            p.reflectance(|l| s.eval(l), albedo)
        }
    }
}

/// `desc` with its base albedo and fluorescent colorant reduced under the scene's light.
pub(super) fn stack(p: &Prefilter, desc: &StackDesc) -> StackDesc {
    let mut out = desc.clone();
    let spectrum = desc.base_spectrum;
    match &mut out.base {
        Base::Lambert { albedo: a } | Base::OrenNayar { albedo: a, .. } => {
            *a = albedo(p, *a, spectrum);
        }
        Base::Conductor { .. } => {}
    }
    if let Some(f) = &desc.fluorescence {
        out.fluorescence = Some(Arc::new(f.with_rgb_matrix(p.fluorescence(f))));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::stage::LightShape;
    use crate::spectrum::line::Line;

    fn disc(center: Vec3, normal: Vec3, radius: f32) -> AreaLight {
        AreaLight {
            center,
            normal,
            shape: LightShape::Disc { radius },
            radiance: Rgb::splat(1.0),
            two_sided: false,
            spectrum: None,
            line: None,
            divergence: None,
            polariser: None,
        }
    }

    #[test]
    fn solid_angles_are_small_discs_and_capped() {
        let l = disc(Vec3::new(0.0, 10.0, 0.0), Vec3::NEG_Y, 0.5);
        let omega = solid_angle(&l, Vec3::ZERO);
        assert!((omega - PI * 0.25 / 100.0).abs() < 1e-6, "{omega}");
        let edge_on = disc(Vec3::new(0.0, 10.0, 0.0), Vec3::X, 0.5);
        assert!(solid_angle(&edge_on, Vec3::ZERO) < 1e-6);
        assert_eq!(solid_angle(&l, l.center), 2.0 * PI);
    }

    #[test]
    fn grey_stages_need_no_prefilter_and_a_laser_does() {
        let sky =
            EnvironmentLight::new(&crate::scene::stage::Environment::Constant(Rgb::splat(0.5)))
                .unwrap();
        let grey = disc(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y, 1.0);
        assert!(scene_light(std::slice::from_ref(&grey), &sky, Vec3::ZERO, []).is_none());
        let mut laser = grey;
        laser.line = Some(Line::new(532.0, 1.0));
        laser.radiance = Line::new(532.0, 1.0).to_rgb_emission();
        let p = scene_light(&[grey, laser], &sky, Vec3::ZERO, []).unwrap();
        let e = p.light();
        assert!(e[1] > e[0] && e[1] > e[2], "{e:?}");
        // Grey albedos stay exactly as they are.
        assert_eq!(albedo(&p, Rgb::splat(0.3), None), Rgb::splat(0.3));
    }
}
