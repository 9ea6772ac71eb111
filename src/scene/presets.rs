//! The built-in stages ([`Stage::studio`], [`Stage::jeweller`] and the gemmologist's instruments
//! [`Stage::polariscope`] and [`Stage::dichroscope`]): what a recipe's stage starts from before its
//! own fields apply ([`crate::recipe`]).

use super::stage::{
    AreaLight, Camera, DEFAULT_MANIFOLD_HALVINGS, DEFAULT_MEDIUM_DEPTH, Environment, Filter,
    Ground, LightShape, Projection, RenderSettings, SamplerKind, Shape, Stage, rect_light,
};
use crate::color::Rgb;
use glam::{Affine3A, Vec3};

impl Stage {
    /// The jeweller's stage: a close-up light tent for sparkle at depth — bright
    /// tent walls (a bright gradient sky), a white floor, two large soft boxes left and right and
    /// one small, hard disc light above and behind the camera, and a macro camera close to the
    /// studio cabochon (22° field of view). What a jeweller's loupe photograph shows: glitter
    /// beneath the surface catches the small light; the soft boxes show the body colour.
    pub fn jeweller() -> Stage {
        let studio = Stage::studio();
        let target = Vec3::new(0.0, 0.25, 0.0);
        let camera = Camera::look_at(
            Vec3::new(0.0, 1.9, 2.6),
            target,
            Vec3::Y,
            Projection::Perspective {
                fov: 22f32.to_radians(),
                aperture: 0.0,
                focus_distance: (Vec3::new(0.0, 1.9, 2.6) - target).length(),
            },
        )
        .expect("the jeweller's camera is well defined");
        let small = Vec3::new(0.8, 4.5, 3.0);
        Stage {
            ground: Some(Ground {
                height: 0.0,
                albedo: Rgb::splat(0.7),
            }),
            environment: Environment::Gradient {
                zenith: Rgb::splat(0.9),
                horizon: Rgb::splat(0.6),
                nadir: Rgb::splat(0.3),
            },
            lights: vec![
                rect_light(
                    Vec3::new(-3.0, 2.5, 0.5),
                    target,
                    (3.0, 3.0),
                    Rgb::splat(2.5),
                ),
                rect_light(
                    Vec3::new(3.0, 2.5, 0.5),
                    target,
                    (3.0, 3.0),
                    Rgb::splat(2.0),
                ),
                AreaLight {
                    center: small,
                    normal: (target - small).normalize(),
                    shape: LightShape::Disc { radius: 0.06 },
                    radiance: Rgb::splat(2500.0),
                    two_sided: false,
                    spectrum: None,
                    line: None,
                    divergence: None,
                    polariser: None,
                },
            ],
            camera,
            ..studio
        }
    }

    /// The built-in studio: an elliptical cabochon (2 × 1.6 units, 0.55 high) on a grey floor,
    /// three soft boxes (key upper left, fill right, rim behind), a dim sky gradient and a camera
    /// looking down at 30°.
    pub fn studio() -> Stage {
        let camera = Camera::look_at(
            Vec3::new(0.0, 2.6, 4.2),
            Vec3::new(0.0, 0.15, 0.0),
            Vec3::Y,
            Projection::Perspective {
                fov: 30f32.to_radians(),
                aperture: 0.0,
                focus_distance: Vec3::new(0.0, 2.45, 4.2).length(),
            },
        )
        .expect("the studio camera is well defined");
        let origin = Vec3::new(0.0, 0.3, 0.0);
        Stage {
            shape: Shape::Cabochon {
                radius: (1.0, 0.8),
                height: 0.55,
                base: 0.0,
            },
            to_world: Affine3A::IDENTITY,
            ground: Some(Ground {
                height: 0.0,
                albedo: Rgb::splat(0.3),
            }),
            environment: Environment::Gradient {
                zenith: Rgb::splat(0.08),
                horizon: Rgb::splat(0.05),
                nadir: Rgb::splat(0.02),
            },
            lights: vec![
                rect_light(
                    Vec3::new(-2.5, 4.0, 2.0),
                    origin,
                    (3.0, 2.0),
                    Rgb::splat(4.0),
                ),
                rect_light(
                    Vec3::new(3.5, 2.5, 1.5),
                    origin,
                    (2.0, 2.0),
                    Rgb::splat(1.5),
                ),
                rect_light(
                    Vec3::new(0.0, 3.0, -3.5),
                    origin,
                    (4.0, 1.0),
                    Rgb::splat(3.0),
                ),
            ],
            camera,
            render: RenderSettings {
                width: 640,
                height: 480,
                spp: 64,
                max_depth: 8,
                medium_depth: DEFAULT_MEDIUM_DEPTH,
                medium_scattering: true,
                manifold_continuation: false,
                manifold_halvings: DEFAULT_MANIFOLD_HALVINGS,
                platelets_explicit: true,
                sampler: SamplerKind::Sobol,
                filter: Filter::Gaussian { radius: 1.5 },
                exposure: 0.0,
                seed: 0,
            },
            analyser: None,
            stokes: false,
            dichroscope: false,
        }
    }

    /// The polariscope: a dark room, a light box under the stone whose polariser's axis is the
    /// world `x` axis, and an orthographic camera looking straight down through an analyser,
    /// crossed with the polariser (axis along `z`) or parallel to it. The stone rests on the box
    /// (turned about the vertical by the recipe's preset, [`crate::recipe`]). A singly refractive
    /// stone between crossed polars stays dark but where its facets reflect and refract at
    /// oblique angles; a doubly refractive one blinks four times per turn.
    pub fn polariscope(crossed: bool) -> Stage {
        let camera = Camera::look_at(
            Vec3::new(0.0, 6.0, 0.0),
            Vec3::ZERO,
            Vec3::NEG_Z,
            Projection::Orthographic { height: 3.2 },
        )
        .expect("the polariscope's camera is well defined");
        let mut light = rect_light(
            Vec3::new(0.0, -0.05, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            (8.0, 8.0),
            Rgb::splat(2.0),
        );
        light.polariser = Some(Vec3::X);
        Stage {
            ground: None,
            environment: Environment::Constant(Rgb::ZERO),
            lights: vec![light],
            camera,
            analyser: Some(if crossed {
                std::f32::consts::FRAC_PI_2
            } else {
                0.0
            }),
            ..Stage::studio()
        }
    }

    /// The dichroscope: the polariscope's dark room, camera and light box with the light box's
    /// polariser taken away (the stone is lit by unpolarised light), and the camera's image split
    /// in two ([`Stage::dichroscope`]): the left half through an analyser along the image's right
    /// (the world `x` axis), the right half through one along its up. A pleochroic stone shows
    /// a different colour in each half wherever its two waves absorb differently; an isotropic
    /// one the same in both. The image is twice as wide as it is high, each half square.
    pub fn dichroscope() -> Stage {
        let mut stage = Stage::polariscope(false);
        for l in &mut stage.lights {
            l.polariser = None;
        }
        stage.analyser = Some(0.0);
        stage.dichroscope = true;
        stage.render.width = 640;
        stage.render.height = 320;
        stage
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn studio_camera_is_orthonormal() {
        let c = Stage::studio().camera;
        assert!(c.forward.dot(c.up).abs() < 1e-6 && c.forward.dot(c.right).abs() < 1e-6);
        assert!(c.up.y > 0.0);
        assert!(Camera::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y, c.projection).is_none());
    }
}
