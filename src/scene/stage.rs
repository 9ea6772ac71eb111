//! The runtime stage: the stone's shape and placement, the ground, environment, lights, camera and
//! render settings, resolved (studio defaults filled in, directions normalised, colours linear).
//!
//! World space is right-handed, y up; lengths in object units; angles stored in radians.

use crate::color::Rgb;
use glam::{Affine3A, EulerRot, Quat, Vec3};
use std::path::PathBuf;

pub use crate::geometry::shape::Shape;

/// The floor, an infinite Lambertian plane y = `height`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// Height of the plane.
    pub height: f32,
    /// Reflectance.
    pub albedo: Rgb,
}

/// Light from infinitely far away.
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// The same radiance everywhere.
    Constant(Rgb),
    /// Linear in the direction's y between zenith, horizon and nadir.
    Gradient {
        /// At +y.
        zenith: Rgb,
        /// At y = 0.
        horizon: Rgb,
        /// At −y.
        nadir: Rgb,
    },
    /// A lat-long EXR map.
    Map {
        /// Resolved path of the file.
        path: PathBuf,
        /// Radiance multiplier.
        intensity: f32,
        /// Rotation about +y in radians.
        rotate: f32,
    },
}

impl Environment {
    /// Whether the environment emits nothing.
    pub fn is_black(&self) -> bool {
        match self {
            Environment::Constant(c) => c.is_black(),
            Environment::Gradient {
                zenith,
                horizon,
                nadir,
            } => zenith.is_black() && horizon.is_black() && nadir.is_black(),
            Environment::Map { intensity, .. } => *intensity == 0.0,
        }
    }
}

/// The shape of an area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightShape {
    /// A rectangle with half-edge vectors `u` and `v` (`u × v` is the facing normal).
    Rect {
        /// Half of the first edge.
        u: Vec3,
        /// Half of the second edge.
        v: Vec3,
    },
    /// A disc.
    Disc {
        /// Radius.
        radius: f32,
    },
}

/// An area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaLight {
    /// Centre.
    pub center: Vec3,
    /// Unit normal of the emitting face (towards the target).
    pub normal: Vec3,
    /// Its outline.
    pub shape: LightShape,
    /// Emitted radiance (colour × intensity).
    pub radiance: Rgb,
    /// Emits from both faces.
    pub two_sided: bool,
    /// A measured emission spectrum (`radiance` is then its RGB colour): spectral paths read it
    /// at their wavelengths.
    pub spectrum: Option<crate::spectrum::measured::Measured>,
    /// A narrow emission line instead (a laser's, a monochromatic lamp's), scaled to the
    /// luminance of `radiance` (which is then its colour); exclusive with `spectrum`.
    pub line: Option<crate::spectrum::line::Line>,
    /// Half-angle of the cone about `normal` the light emits into, radians (a beam: a laser's
    /// divergence); `None` for the whole hemisphere. One-sided.
    pub divergence: Option<f32>,
    /// An ideal linear polariser over the emitting face: its transmission axis (world, unit, in
    /// the light's plane). It passes half of the light (`radiance` is the light's without it),
    /// linearly polarised along the axis ([`crate::polarisation::transport`]).
    pub polariser: Option<Vec3>,
}

/// The camera projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective with a thin lens.
    Perspective {
        /// Vertical field of view in radians.
        fov: f32,
        /// Lens radius (0: pinhole).
        aperture: f32,
        /// Distance of the plane in focus.
        focus_distance: f32,
    },
    /// Parallel projection.
    Orthographic {
        /// View height in object units.
        height: f32,
    },
}

/// The camera: an orthonormal frame at `from` looking along `forward`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub from: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up direction, orthogonal to `forward`.
    pub up: Vec3,
    /// Unit right direction (`forward × up`).
    pub right: Vec3,
    /// The projection.
    pub projection: Projection,
}

impl Camera {
    /// A camera at `from` looking at `to`; `None` if `to = from` or `up` is parallel to the view.
    pub fn look_at(from: Vec3, to: Vec3, up: Vec3, projection: Projection) -> Option<Camera> {
        let forward = (to - from).try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let up = right.cross(forward);
        Some(Camera {
            from,
            forward,
            up,
            right,
            projection,
        })
    }
}

pub use crate::sampler::SamplerKind;

/// Pixel reconstruction filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// The pixel's own square.
    Box,
    /// Truncated Gaussian, σ = radius / 3 pixels.
    Gaussian {
        /// Support radius in pixels.
        radius: f32,
    },
}

/// Most pixels of an image (8192² = 2²⁶). Each side may be up to [`MAX_SIDE`], but the film
/// takes 400 bytes per pixel (exact fixed-point sums; see `render::memory`), so the largest
/// accepted image needs about 25 GiB: on the project's 24 GiB machines the memory check refuses
/// it before rendering, and about 7500² fits; 16384² would need 100 GiB.
pub const MAX_PIXELS: u64 = 1 << 26;
/// Longest side of an image in pixels.
pub const MAX_SIDE: u32 = 16384;

/// Render settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Longest path in bounces (surface scattering events).
    pub max_depth: u32,
    /// Most scattering events inside a medium per path (`medium-depth`), 0 ..= 4096; the
    /// medium's events do not count towards `max_depth`.
    pub medium_depth: u32,
    /// Whether media scatter (`medium-scattering=off`: the absorption-only approximation, where
    /// light that would scatter goes straight on).
    pub medium_scattering: bool,
    /// Whether a manifold walk that fails from the straight line retries by the continuation in
    /// the index (`manifold-continuation`; default off: measured, the retries find few
    /// connections for their cost, and BSDF sampling keeps what the walk misses).
    pub manifold_continuation: bool,
    /// Most halvings of a manifold walk's Newton step that does not lower the residual
    /// (`manifold-halvings`), 0 ..= [`MAX_MANIFOLD_HALVINGS`] (default 1: measured, further
    /// halvings cost many ray casts and find next to no connections).
    pub manifold_halvings: u32,
    /// Platelets traced one by one (`false`: their statistical form, a medium of flakes).
    pub platelets_explicit: bool,
    /// The sampler.
    pub sampler: SamplerKind,
    /// The pixel filter.
    pub filter: Filter,
    /// PNG exposure in stops.
    pub exposure: f32,
    /// Seed of the pixel samples.
    pub seed: u64,
}

/// The default of [`RenderSettings::medium_depth`].
pub const DEFAULT_MEDIUM_DEPTH: u32 = 256;
/// The largest [`RenderSettings::medium_depth`] a user may give.
pub const MAX_MEDIUM_DEPTH: u32 = 4096;
/// The default of [`RenderSettings::manifold_halvings`].
pub const DEFAULT_MANIFOLD_HALVINGS: u32 = 1;
/// The largest [`RenderSettings::manifold_halvings`] a user may give (a step shortened 256
/// times: beyond it a walk only creeps).
pub const MAX_MANIFOLD_HALVINGS: u32 = 8;

/// A resolved stage.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    /// The stone's shape in object space.
    pub shape: Shape,
    /// Object to world.
    pub to_world: Affine3A,
    /// The floor, if any.
    pub ground: Option<Ground>,
    /// The environment.
    pub environment: Environment,
    /// Area lights.
    pub lights: Vec<AreaLight>,
    /// The camera.
    pub camera: Camera,
    /// Render settings.
    pub render: RenderSettings,
    /// An ideal linear polariser in front of the camera (an analyser): its transmission axis in
    /// radians from the image's right toward its up; `None` for none.
    pub analyser: Option<f32>,
    /// Whether the render also measures the Stokes vector of the light reaching the camera (the
    /// `S0`–`S3` AOVs, `--stokes`; [`crate::polarisation::stokes`]). Needs polarised transport.
    pub stokes: bool,
    /// The dichroscope's split image (the `Dichroscope` preset): the left half of the image sees
    /// the whole view through [`Stage::analyser`], the right half the same view through an
    /// analyser turned 90° from it — the two polarisations side by side, as a calcite
    /// dichroscope's two windows show them.
    pub dichroscope: bool,
}

/// A rectangular soft box at `center` facing `target`, `w × h`, its `w` edge horizontal.
pub fn rect_light(center: Vec3, target: Vec3, size: (f32, f32), radiance: Rgb) -> AreaLight {
    let normal = (target - center).try_normalize().unwrap_or(Vec3::NEG_Y);
    let side = normal
        .cross(Vec3::Y)
        .try_normalize()
        .unwrap_or_else(|| normal.cross(Vec3::X).normalize());
    let other = side.cross(normal);
    // u × v must be the facing normal: side × other = −normal, so swap.
    let (u, v) = (other * (0.5 * size.1), side * (0.5 * size.0));
    AreaLight {
        center,
        normal,
        shape: LightShape::Rect { u, v },
        radiance,
        two_sided: false,
        spectrum: None,
        line: None,
        divergence: None,
        polariser: None,
    }
}

/// Object-to-world from a scale, x-y-z rotation angles in degrees and a translation.
pub fn placement(scale: f32, rotate_deg: Vec3, translate: Vec3) -> Affine3A {
    let r = rotate_deg * (std::f32::consts::PI / 180.0);
    Affine3A::from_scale_rotation_translation(
        Vec3::splat(scale),
        Quat::from_euler(EulerRot::ZYX, r.z, r.y, r.x),
        translate,
    )
}

/// The world direction at `degrees` in the plane of a light facing `normal` (unit), measured
/// from the edge [`rect_light`] makes horizontal (a rectangle's width edge) toward
/// `normal × edge`: where a light's `polariser` axis points.
pub fn light_axis(normal: Vec3, degrees: f32) -> Vec3 {
    let side = normal
        .cross(Vec3::Y)
        .try_normalize()
        .unwrap_or_else(|| normal.cross(Vec3::X).normalize());
    let (s, c) = degrees.to_radians().sin_cos();
    side * c + normal.cross(side) * s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rect_lights_face_their_target_and_span_their_size() {
        let l = rect_light(Vec3::new(1.0, 3.0, 2.0), Vec3::ZERO, (3.0, 2.0), Rgb::ONE);
        let LightShape::Rect { u, v } = l.shape else {
            panic!()
        };
        assert!((u.cross(v).normalize() - l.normal).length() < 1e-5);
        assert!((2.0 * v.length() - 3.0).abs() < 1e-5 && (2.0 * u.length() - 2.0).abs() < 1e-5);
        assert!(l.normal.dot(-l.center) > 0.0);
        // Straight down: no NaN from the parallel up vector.
        let d = rect_light(Vec3::Y, Vec3::ZERO, (1.0, 1.0), Rgb::ONE);
        let LightShape::Rect { u, v } = d.shape else {
            panic!()
        };
        assert!(u.is_finite() && v.is_finite() && u.cross(v).dot(Vec3::NEG_Y) > 0.0);
    }
}
