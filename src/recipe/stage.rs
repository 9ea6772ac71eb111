//! Serde description of a recipe's `stage`: the stone's shape and placement, the ground, the
//! environment, the lights, the camera and the render settings. Every part is optional and
//! replaces the same part of the built-in studio stage ([`crate::scene::Stage::studio`]); `render`
//! overrides the studio's settings field by field.
//!
//! World space is right-handed with **y up**; lengths are in object units (the studio cabochon is
//! about 2 units across); angles are in degrees; radiance is linear Rec.709 RGB, relative.
//!
//! ```ron
//! stage: (
//!     shape: Cabochon(radius: (1.0, 0.8), height: 0.55),
//!     transform: (rotate: (0.0, 30.0, 0.0)),
//!     ground: Plane(albedo: Gray(0.3)),
//!     environment: Gradient(zenith: Gray(0.08), horizon: Gray(0.05), nadir: Gray(0.02)),
//!     lights: [Rect(center: (-2.5, 4.0, 2.0), size: (3.0, 2.0), radiance: Gray(4.0))],
//!     camera: Perspective(from: (0.0, 2.6, 4.2), to: (0.0, 0.15, 0.0), fov: 30.0),
//!     render: (width: 640, height: 480, spp: 64),
//! )
//! ```

use super::color::ColorDesc;
use super::ranged::{finite, positive2, refuse};
pub use super::render_desc::{AccuracyDesc, FilterDesc, PlateletForm, RenderDesc, SamplerDesc};
pub use super::shape::ShapeDesc;
use serde::{Deserialize, Deserializer, Serialize};

ranged!(length_range, "length", open 0.0, 1e4);

ranged!(fov_range, "fov", 1.0, 170.0);
ranged!(aperture_range, "aperture", 0.0, 1e3);
ranged!(intensity_range, "intensity", 0.0, 1e6);
ranged!(factor_range, "scale", open 0.0, 1e4);
ranged!(line_wavelength_range, "wavelength", 360.0, 830.0);
ranged!(line_fwhm_range, "fwhm", 0.1, 100.0);
ranged!(divergence_value, "divergence", open 0.0, 45.0);

/// `divergence`, degrees, `0 <.. 45`.
fn divergence_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    divergence_value(d).map(Some)
}

/// A narrow emission line: a laser's or a monochromatic lamp's ([`crate::spectrum::line`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineDesc {
    /// Centre, nm, 360 ..= 830.
    #[serde(deserialize_with = "line_wavelength_range")]
    pub wavelength: f32,
    /// Full width at half maximum, nm, 0.1 ..= 100 (default 1). Narrower lines are noisier in
    /// spectral renders: a path's wavelengths land in the line less often.
    #[serde(default = "one", deserialize_with = "line_fwhm_range")]
    pub fwhm: f32,
}

type V3 = (f32, f32, f32);

fn finite3<'de, D: Deserializer<'de>>(d: D) -> Result<V3, D::Error> {
    let v = V3::deserialize(d)?;
    if v.0.is_finite() && v.1.is_finite() && v.2.is_finite() {
        Ok(v)
    } else {
        let f = |c: f32| if c.is_finite() { c } else { 0.0 };
        refuse(
            format!("{v:?}: every coordinate must be a finite number"),
            (f(v.0), f(v.1), f(v.2)),
        )
    }
}

/// Largest radiance per channel a light or environment colour may have (relative units; the
/// studio's key light is 4). With `intensity` (≤ 1e6) the product stays far from `f32`
/// overflow, even squared for variance estimates, so an absurd value (1e30) is refused at parse.
pub const MAX_RADIANCE: f32 = 1e6;

/// A colour that is emitted light: within 0 ..= [`MAX_RADIANCE`] in every channel.
fn radiance<'de, D: Deserializer<'de>>(d: D) -> Result<ColorDesc, D::Error> {
    let c = ColorDesc::deserialize(d)?;
    // The stand-in for a refused colour.
    let white = ColorDesc::Gray(1.0);
    if let ColorDesc::Spectrum(_) = c {
        return refuse(
            "an emitted colour cannot be a `Spectrum(…)` (a reflectance's projection): give an \
             RGB colour, and for a light its measured emission as `spectrum: [(nm, value), …]`"
                .into(),
            white,
        );
    }
    match c.to_rgb() {
        Ok(s) if s.0.iter().all(|v| (0.0..=MAX_RADIANCE).contains(v)) => Ok(c),
        Ok(s) => refuse(
            format!(
                "radiance {:?} is out of range: each channel allowed 0 ..= {MAX_RADIANCE:e}",
                s.0
            ),
            white,
        ),
        Err(e) => refuse(e, white),
    }
}

/// A reflectance: finite and within 0 ..= 1 in every channel.
fn albedo<'de, D: Deserializer<'de>>(d: D) -> Result<ColorDesc, D::Error> {
    let c = ColorDesc::deserialize(d)?;
    if let ColorDesc::Spectrum(_) = c {
        return refuse(
            "the floor's albedo cannot be a `Spectrum(…)`: give an RGB colour (measured albedos \
             belong to a material's base)"
                .into(),
            grey_half(),
        );
    }
    match c.to_rgb() {
        Ok(s) if s.0.iter().all(|v| (0.0..=1.0).contains(v)) => Ok(c),
        Ok(s) => refuse(
            format!(
                "albedo {:?} is out of range: each channel allowed 0 ..= 1",
                s.0
            ),
            grey_half(),
        ),
        Err(e) => refuse(e, grey_half()),
    }
}

/// Most area lights of a stage (every shading point tests each of them).
pub const MAX_LIGHTS: usize = 64;

fn light_list<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<LightDesc>>, D::Error> {
    super::ranged::bounded_list(d, "lights", MAX_LIGHTS, false).map(Some)
}

fn zero3() -> V3 {
    (0.0, 0.0, 0.0)
}
fn y_up() -> V3 {
    (0.0, 1.0, 0.0)
}
fn one() -> f32 {
    1.0
}
fn thirty() -> f32 {
    30.0
}
fn grey_half() -> ColorDesc {
    ColorDesc::Gray(0.5)
}

/// The parts of the studio stage a recipe replaces.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageDesc {
    /// The built-in stage the recipe's parts replace parts of: `Studio` (default) or `Jeweller`
    /// (a close-up light tent with one small hard light, for sparkle at depth).
    #[serde(default)]
    pub preset: Option<StagePreset>,
    /// The stone's shape (object space; the surface maps are evaluated there).
    #[serde(default)]
    pub shape: Option<ShapeDesc>,
    /// Object-to-world placement of the stone.
    #[serde(default)]
    pub transform: Option<TransformDesc>,
    /// The floor under the stone.
    #[serde(default)]
    pub ground: Option<GroundDesc>,
    /// Light from infinitely far away.
    #[serde(default)]
    pub environment: Option<EnvironmentDesc>,
    /// Area lights (the list replaces the studio's soft boxes; `[]` removes them; at most 64).
    #[serde(default, deserialize_with = "light_list")]
    pub lights: Option<Vec<LightDesc>>,
    /// The camera.
    #[serde(default)]
    pub camera: Option<CameraDesc>,
    /// Render settings, each overriding the studio's.
    #[serde(default)]
    pub render: RenderDesc,
    /// An ideal linear polariser in front of the camera: its transmission axis in degrees from
    /// the image's right toward its up, −360 ..= 360. Turns polarised transport on.
    #[serde(default, deserialize_with = "analyser_range")]
    pub analyser: Option<f32>,
}

/// Object-to-world placement: scale, then rotations about x, y, z (degrees), then translation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDesc {
    /// Translation.
    #[serde(default = "zero3", deserialize_with = "finite3")]
    pub translate: V3,
    /// Rotation angles about x, y and z in degrees, applied in that order.
    #[serde(default = "zero3", deserialize_with = "finite3")]
    pub rotate: V3,
    /// Uniform scale, 0 <.. 1e4 (default 1).
    #[serde(default = "one", deserialize_with = "factor_range")]
    pub scale: f32,
}

/// A built-in stage.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum StagePreset {
    /// Three soft boxes, a dim sky, a grey floor, a camera 30° down.
    Studio,
    /// A light tent: bright walls, two soft boxes, one small hard light, a macro camera.
    Jeweller,
    /// The gemmologist's polariscope ([`crate::scene::Stage::polariscope`]): a dark room, a
    /// polarised light box under the stone, an orthographic camera looking down through an
    /// analyser. Turns polarised transport on.
    Polariscope {
        /// Analyser crossed with the polariser (default true; false: parallel).
        #[serde(default = "yes")]
        crossed: bool,
        /// The stone turned about the vertical, degrees, −360 ..= 360 (default 0), after the
        /// recipe's own `transform`.
        #[serde(default, deserialize_with = "turn_range")]
        rotation: f32,
    },
    /// The gemmologist's dichroscope ([`crate::scene::Stage::dichroscope`]): the polariscope's
    /// room lit by unpolarised light, the image split into two views of the stone through
    /// analysers 90° apart (the stage's `analyser` turns both; default along the image's right).
    /// Turns polarised transport on.
    Dichroscope {
        /// The stone turned about the vertical, degrees, −360 ..= 360 (default 0), after the
        /// recipe's own `transform`.
        #[serde(default, deserialize_with = "turn_range")]
        rotation: f32,
    },
}

fn yes() -> bool {
    true
}

ranged!(turn_range, "rotation", -360.0, 360.0);
ranged!(analyser_value, "analyser", -360.0, 360.0);
ranged!(polariser_value, "polariser", -360.0, 360.0);

/// An analyser's axis, degrees, −360 ..= 360.
fn analyser_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    analyser_value(d).map(Some)
}

/// A light's polariser axis, degrees, −360 ..= 360.
fn polariser_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    polariser_value(d).map(Some)
}

/// The floor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum GroundDesc {
    /// No floor.
    Off,
    /// An infinite Lambertian plane y = `height`.
    Plane {
        /// Height of the plane (default 0: the stone rests on it).
        #[serde(default, deserialize_with = "finite")]
        height: f32,
        /// Reflectance, 0 ..= 1 per channel (default Gray(0.5)).
        #[serde(default = "grey_half", deserialize_with = "albedo")]
        albedo: ColorDesc,
    },
}

/// Light arriving from infinitely far away.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum EnvironmentDesc {
    /// The same radiance from every direction.
    Constant(#[serde(deserialize_with = "radiance")] ColorDesc),
    /// Radiance blending zenith → horizon above, horizon → nadir below (linear in the cosine).
    Gradient {
        /// Straight up.
        #[serde(deserialize_with = "radiance")]
        zenith: ColorDesc,
        /// At the horizon.
        #[serde(deserialize_with = "radiance")]
        horizon: ColorDesc,
        /// Straight down.
        #[serde(deserialize_with = "radiance")]
        nadir: ColorDesc,
    },
    /// A latitude–longitude (equirectangular) EXR image, y up, importance sampled.
    Map {
        /// The EXR file (relative to the recipe).
        file: String,
        /// Radiance multiplier, 0 ..= 1e6 (default 1).
        #[serde(default = "one", deserialize_with = "intensity_range")]
        intensity: f32,
        /// Rotation about y in degrees (default 0).
        #[serde(default, deserialize_with = "finite")]
        rotate: f32,
    },
}

/// An area light facing `target`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// A rectangle (a soft box).
    Rect {
        /// Centre.
        #[serde(deserialize_with = "finite3")]
        center: V3,
        /// The point it faces (default the origin).
        #[serde(default = "zero3", deserialize_with = "finite3")]
        target: V3,
        /// Full width and height.
        #[serde(deserialize_with = "positive2")]
        size: (f32, f32),
        /// Emitted radiance.
        #[serde(deserialize_with = "radiance")]
        radiance: ColorDesc,
        /// Radiance multiplier, 0 ..= 1e6 (default 1).
        #[serde(default = "one", deserialize_with = "intensity_range")]
        intensity: f32,
        /// Emit from both faces (default false: only towards `target`).
        #[serde(default)]
        two_sided: bool,
        /// A measured relative spectral power distribution, `[(nm, power), …]` or a CSV file
        /// ([`super::spectrum`]): the light emits this spectrum scaled to the luminance of
        /// `radiance × intensity` (its colour replaces `radiance`'s). Turns spectral transport on.
        #[serde(default)]
        spectrum: Option<super::spectrum::SpectrumDesc>,
        /// A narrow emission line instead of `spectrum`, `(wavelength: 532, fwhm: 1)`: a
        /// monochromatic lamp or, with `divergence`, a laser. Turns spectral transport on.
        #[serde(default)]
        line: Option<LineDesc>,
        /// Emit only within this half-angle (degrees, 0 <.. 45) of the direction to `target`:
        /// a beam (a laser's divergence). One-sided.
        #[serde(default, deserialize_with = "divergence_range")]
        divergence: Option<f32>,
        /// An ideal linear polariser over the face: its transmission axis in degrees, −360 ..=
        /// 360, from the light's horizontal in-plane direction (a rectangle's `size.0` edge)
        /// toward the normal × that direction. It passes half the light, linearly polarised.
        /// Turns polarised transport on.
        #[serde(default, deserialize_with = "polariser_range")]
        polariser: Option<f32>,
    },
    /// A disc.
    Disc {
        /// Centre.
        #[serde(deserialize_with = "finite3")]
        center: V3,
        /// The point it faces (default the origin).
        #[serde(default = "zero3", deserialize_with = "finite3")]
        target: V3,
        /// Radius.
        #[serde(deserialize_with = "length_range")]
        radius: f32,
        /// Emitted radiance.
        #[serde(deserialize_with = "radiance")]
        radiance: ColorDesc,
        /// Radiance multiplier, 0 ..= 1e6 (default 1).
        #[serde(default = "one", deserialize_with = "intensity_range")]
        intensity: f32,
        /// Emit from both faces (default false).
        #[serde(default)]
        two_sided: bool,
        /// A measured relative spectral power distribution (as for `Rect`).
        #[serde(default)]
        spectrum: Option<super::spectrum::SpectrumDesc>,
        /// A narrow emission line (as for `Rect`).
        #[serde(default)]
        line: Option<LineDesc>,
        /// A beam's half-angle, degrees (as for `Rect`): a laser is a `Disc` of the beam's radius
        /// with a `line` and a `divergence`.
        #[serde(default, deserialize_with = "divergence_range")]
        divergence: Option<f32>,
        /// An ideal linear polariser over the face: its transmission axis in degrees, −360 ..=
        /// 360, from the light's horizontal in-plane direction (a rectangle's `size.0` edge)
        /// toward the normal × that direction. It passes half the light, linearly polarised.
        /// Turns polarised transport on.
        #[serde(default, deserialize_with = "polariser_range")]
        polariser: Option<f32>,
    },
}

/// The camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CameraDesc {
    /// A perspective camera with an optional thin lens.
    Perspective {
        /// Eye position.
        #[serde(deserialize_with = "finite3")]
        from: V3,
        /// The point looked at.
        #[serde(deserialize_with = "finite3")]
        to: V3,
        /// Up direction (default +y).
        #[serde(default = "y_up", deserialize_with = "finite3")]
        up: V3,
        /// Vertical field of view in degrees, 1 ..= 170 (default 30).
        #[serde(default = "thirty", deserialize_with = "fov_range")]
        fov: f32,
        /// Lens radius in object units, 0 ..= 1e3 (default 0: a pinhole, everything sharp).
        #[serde(default, deserialize_with = "aperture_range")]
        aperture: f32,
        /// Distance to the plane in focus (default: `|to − from|`).
        #[serde(default, deserialize_with = "focus_range")]
        focus_distance: Option<f32>,
    },
    /// An orthographic camera.
    Orthographic {
        /// Eye position.
        #[serde(deserialize_with = "finite3")]
        from: V3,
        /// The point looked at.
        #[serde(deserialize_with = "finite3")]
        to: V3,
        /// Up direction (default +y).
        #[serde(default = "y_up", deserialize_with = "finite3")]
        up: V3,
        /// Height of the view in object units.
        #[serde(deserialize_with = "length_range")]
        height: f32,
    },
}

fn focus_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    let v = f32::deserialize(d)?;
    if v > 0.0 && v <= 1e6 {
        Ok(Some(v))
    } else {
        // Stand-in: the default (the distance to `to`).
        refuse(
            format!("focus_distance = {v} is out of range: allowed 0 <.. 1e6"),
            None,
        )
    }
}
