//! A view: how `lapidary preview` moves a recipe's stage without editing it — the camera orbited
//! and zoomed about the stone, the stone tilted, the lights turned about the vertical. The same
//! view given to `lapidary render --view …` renders the preview's image bit for bit, so a view
//! found interactively becomes a batch render or a farm job.
//!
//! Conventions: world `+y` is up (docs/design.md §4). Angles are in degrees. The pivot of every
//! motion is the centre of the stone's bounding box in world space (its object origin for a mesh).
//! Yaw turns about the vertical through the pivot (positive: counter-clockwise seen from above),
//! pitch raises the camera above (positive) or below its recipe position, zoom scales the
//! camera's distance to the pivot (below 1: closer). The stone's tilt turns it about the world
//! `x` then `z` axes through the pivot and lifts it so that its lowest point stays as high as it
//! was (it rests on the floor as before; a mesh is not lifted); `light_yaw` turns every area light
//! about the vertical through the pivot and an environment map with them.

use super::stage::{Camera, Environment, LightShape, Stage};
use glam::{Affine3A, Quat, Vec3};

/// Largest |pitch| in degrees (the camera never passes over the pole, where its `up` flips).
pub const MAX_PITCH: f32 = 85.0;
/// Largest |tilt| of the stone about either axis, degrees.
pub const MAX_TILT: f32 = 60.0;
/// Zoom range (a factor on the camera's distance to the pivot).
pub const ZOOM: std::ops::RangeInclusive<f32> = 0.1..=10.0;

/// Moves of the stage relative to the recipe's (all zero / one: the recipe's own view).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct View {
    /// Camera turn about the vertical through the pivot, degrees.
    pub yaw: f32,
    /// Camera elevation change, degrees in ±[`MAX_PITCH`].
    pub pitch: f32,
    /// Factor on the camera's distance to the pivot, in [`ZOOM`].
    pub zoom: f32,
    /// Stone tilt about the world `x` axis, degrees in ±[`MAX_TILT`].
    pub tilt_x: f32,
    /// Stone tilt about the world `z` axis, degrees in ±[`MAX_TILT`].
    pub tilt_z: f32,
    /// Turn of the area lights about the vertical through the pivot, degrees.
    pub light_yaw: f32,
}

impl Default for View {
    fn default() -> Self {
        View {
            yaw: 0.0,
            pitch: 0.0,
            zoom: 1.0,
            tilt_x: 0.0,
            tilt_z: 0.0,
            light_yaw: 0.0,
        }
    }
}

/// A view value out of its range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("view `{field}` = {value}: {allowed}")]
pub struct ViewError {
    /// The field.
    pub field: &'static str,
    /// The value given.
    pub value: String,
    /// The allowed range.
    pub allowed: String,
}

impl View {
    /// Whether this is the recipe's own view.
    pub fn is_identity(&self) -> bool {
        *self == View::default()
    }

    /// `Ok` when every field is finite and in its range; yaw and light yaw are wrapped to
    /// (−180, 180] by [`View::normalised`].
    pub fn check(&self) -> Result<(), ViewError> {
        let bad = |field, value: f32, allowed: String| ViewError {
            field,
            value: value.to_string(),
            allowed,
        };
        for (field, v) in [("yaw", self.yaw), ("light_yaw", self.light_yaw)] {
            if !v.is_finite() {
                return Err(bad(field, v, "expected a finite angle in degrees".into()));
            }
        }
        if !(self.pitch.abs() <= MAX_PITCH) {
            return Err(bad(
                "pitch",
                self.pitch,
                format!("expected degrees in -{MAX_PITCH}..={MAX_PITCH}"),
            ));
        }
        if !ZOOM.contains(&self.zoom) {
            return Err(bad(
                "zoom",
                self.zoom,
                format!("expected a factor in {}..={}", ZOOM.start(), ZOOM.end()),
            ));
        }
        for (field, v) in [("tilt_x", self.tilt_x), ("tilt_z", self.tilt_z)] {
            if !(v.abs() <= MAX_TILT) {
                return Err(bad(
                    field,
                    v,
                    format!("expected degrees in -{MAX_TILT}..={MAX_TILT}"),
                ));
            }
        }
        Ok(())
    }

    /// The view with yaw and light yaw wrapped to (−180, 180].
    pub fn normalised(mut self) -> View {
        let wrap = |a: f32| {
            let w = a.rem_euclid(360.0);
            if w > 180.0 { w - 360.0 } else { w }
        };
        self.yaw = wrap(self.yaw);
        self.light_yaw = wrap(self.light_yaw);
        self
    }

    /// Parses `--view` text: comma-separated `name=value` pairs of the fields above (e.g.
    /// `yaw=30,pitch=-10,zoom=0.8`); unnamed fields keep their default.
    pub fn parse(s: &str) -> Result<View, String> {
        let mut v = View::default();
        for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (name, value) = part
                .split_once('=')
                .ok_or_else(|| format!("`{part}`: expected name=value"))?;
            let x: f32 = value
                .trim()
                .parse()
                .map_err(|_| format!("`{part}`: `{}` is not a number", value.trim()))?;
            let slot = match name.trim() {
                "yaw" => &mut v.yaw,
                "pitch" => &mut v.pitch,
                "zoom" => &mut v.zoom,
                "tilt_x" => &mut v.tilt_x,
                "tilt_z" => &mut v.tilt_z,
                "light_yaw" => &mut v.light_yaw,
                other => {
                    return Err(format!(
                        "`{other}`: unknown view field (expected yaw, pitch, zoom, tilt_x, \
                         tilt_z or light_yaw)"
                    ));
                }
            };
            *slot = x;
        }
        v.check().map_err(|e| e.to_string())?;
        Ok(v.normalised())
    }

    /// The `--view` text of this view (the fields that differ from the default), or `None` for
    /// the recipe's own view. [`View::parse`] reads it back exactly (shortest round-trip
    /// decimal forms).
    pub fn to_arg(&self) -> Option<String> {
        let d = View::default();
        let fields = [
            ("yaw", self.yaw, d.yaw),
            ("pitch", self.pitch, d.pitch),
            ("zoom", self.zoom, d.zoom),
            ("tilt_x", self.tilt_x, d.tilt_x),
            ("tilt_z", self.tilt_z, d.tilt_z),
            ("light_yaw", self.light_yaw, d.light_yaw),
        ];
        let parts: Vec<String> = fields
            .iter()
            .filter(|(_, v, d)| v != d)
            .map(|(n, v, _)| format!("{n}={v}"))
            .collect();
        (!parts.is_empty()).then(|| parts.join(","))
    }

    /// Applies the view to `stage` (the recipe's): camera, stone placement and area lights. The
    /// recipe's own view (all defaults) leaves `stage` exactly as it was.
    pub fn apply(&self, stage: &mut Stage) {
        if self.is_identity() {
            return;
        }
        let pivot = pivot(stage);
        stage.camera = self.camera(&stage.camera, pivot);
        if self.tilt_x != 0.0 || self.tilt_z != 0.0 {
            let r = Quat::from_rotation_z(self.tilt_z.to_radians())
                * Quat::from_rotation_x(self.tilt_x.to_radians());
            let about = Affine3A::from_translation(pivot)
                * Affine3A::from_quat(r)
                * Affine3A::from_translation(-pivot);
            let before = lowest(stage, stage.to_world);
            let tilted = about * stage.to_world;
            // The tilted stone rests where it rested: lifted so that its lowest point is as high
            // as before (a cabochon's rim does not dip through the floor).
            let lift = match (before, lowest(stage, tilted)) {
                (Some(b), Some(a)) if b > a => b - a,
                _ => 0.0,
            };
            stage.to_world = Affine3A::from_translation(Vec3::Y * lift) * tilted;
        }
        if self.light_yaw != 0.0 {
            let r = Quat::from_rotation_y(self.light_yaw.to_radians());
            for l in &mut stage.lights {
                l.center = pivot + r * (l.center - pivot);
                l.normal = (r * l.normal).normalize_or(l.normal);
                if let LightShape::Rect { u, v } = &mut l.shape {
                    *u = r * *u;
                    *v = r * *v;
                }
            }
            // An environment map turns with the lights (the same right-handed turn about +y);
            // constant and gradient skies look the same turned.
            if let Environment::Map { rotate, .. } = &mut stage.environment {
                *rotate = (*rotate + self.light_yaw.to_radians()).rem_euclid(std::f32::consts::TAU);
            }
        }
    }

    /// The recipe's camera orbited and zoomed about `pivot`.
    fn camera(&self, base: &Camera, pivot: Vec3) -> Camera {
        if self.yaw == 0.0 && self.pitch == 0.0 && self.zoom == 1.0 {
            return *base;
        }
        let offset = base.from - pivot;
        let dist = offset.length();
        if dist <= 0.0 || !dist.is_finite() {
            return *base;
        }
        // Elevation of the recipe's camera, then the pitched one (kept inside ±MAX_PITCH of the
        // horizon so that `up` never flips).
        let dir = offset / dist;
        let elevation = dir.y.clamp(-1.0, 1.0).asin().to_degrees();
        let target = (elevation + self.pitch).clamp(-MAX_PITCH, MAX_PITCH);
        let horizontal = Vec3::new(dir.x, 0.0, dir.z)
            .try_normalize()
            .unwrap_or(Vec3::Z);
        let yaw = Quat::from_rotation_y(self.yaw.to_radians());
        let h = yaw * horizontal;
        let e = target.to_radians();
        let new_dir = h * e.cos() + Vec3::Y * e.sin();
        let from = pivot + new_dir * (dist * self.zoom);
        // Keep where the recipe's camera looked relative to the pivot: its forward turned by the
        // same yaw and pitch.
        let aim = base.from + base.forward * dist;
        let aim = pivot + yaw * (aim - pivot);
        let to = if (aim - from).length() > 1e-6 * dist {
            aim
        } else {
            pivot
        };
        Camera::look_at(from, to, Vec3::Y, base.projection).unwrap_or(*base)
    }
}

/// The pivot of every motion: the centre of the stone's bounding box in world space (the object
/// origin for a mesh, whose bounds are known only once it is loaded).
fn pivot(stage: &Stage) -> Vec3 {
    let centre = stage.shape.centre().unwrap_or(Vec3::ZERO);
    stage.to_world.transform_point3(centre)
}

/// The world height of the lowest point of the stone placed by `to_world`, from its shape's
/// support function (`None` for a mesh): `min y = t_y − h(−Mᵀ e_y)` for `x ↦ M x + t`.
fn lowest(stage: &Stage, to_world: Affine3A) -> Option<f32> {
    let m = glam::Mat3::from(to_world.matrix3);
    let down = -(m.transpose() * Vec3::Y);
    Some(to_world.translation.y - stage.shape.support(down)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::stage::Projection;

    fn camera() -> Camera {
        Camera::look_at(
            Vec3::new(0.0, 1.0, 4.0),
            Vec3::ZERO,
            Vec3::Y,
            Projection::Perspective {
                fov: 0.5,
                aperture: 0.0,
                focus_distance: 1.0,
            },
        )
        .unwrap()
    }

    #[test]
    fn parse_and_print_round_trip() {
        let v = View::parse("yaw=30, pitch=-10,zoom=0.8,light_yaw=370").unwrap();
        assert_eq!(v.yaw, 30.0);
        assert_eq!(v.light_yaw, 10.0);
        let back = View::parse(&v.to_arg().unwrap()).unwrap();
        assert_eq!(back, v);
        assert_eq!(View::default().to_arg(), None);
        assert!(View::parse("zoom=0").unwrap_err().contains("0.1..=10"));
        assert!(View::parse("pitch=90").unwrap_err().contains("-85..=85"));
        assert!(
            View::parse("tilt=3")
                .unwrap_err()
                .contains("unknown view field")
        );
        assert!(View::parse("yaw=nan").unwrap_err().contains("finite"));
        assert!(View::parse("yaw").unwrap_err().contains("name=value"));
    }

    #[test]
    fn the_default_view_changes_nothing_and_orbits_keep_the_distance() {
        let base = camera();
        let v = View::default();
        assert_eq!(v.camera(&base, Vec3::ZERO), base);
        let turned = View {
            yaw: 90.0,
            ..View::default()
        }
        .camera(&base, Vec3::ZERO);
        assert!((turned.from.length() - base.from.length()).abs() < 1e-5);
        assert!(
            (turned.from.y - base.from.y).abs() < 1e-5,
            "{:?}",
            turned.from
        );
        // A quarter turn counter-clockwise seen from above takes +z to +x.
        assert!(turned.from.x > 3.9, "{:?}", turned.from);
        let closer = View {
            zoom: 0.5,
            ..View::default()
        }
        .camera(&base, Vec3::ZERO);
        assert!((closer.from.length() - 0.5 * base.from.length()).abs() < 1e-5);
        // Pitch is clamped short of the pole: `up` stays defined.
        let high = View {
            pitch: 85.0,
            ..View::default()
        }
        .camera(&base, Vec3::ZERO);
        assert!(high.up.is_finite() && high.from.y > 0.0);
        assert!((high.from.y / high.from.length() - 85f32.to_radians().sin()).abs() < 1e-4);
    }

    /// A tilted studio cabochon keeps its lowest point on the floor (checked over points of its
    /// rim, independently of the support function), turns about its centre, and an environment
    /// map turns with the lights.
    #[test]
    fn a_tilted_stone_rests_on_the_floor_and_the_environment_turns_with_the_lights() {
        let base = Stage::studio();
        let rim_low = |st: &Stage| {
            (0..3600)
                .map(|k| {
                    let a = k as f32 * std::f32::consts::TAU / 3600.0;
                    let p = Vec3::new(a.cos(), 0.0, 0.8 * a.sin());
                    st.to_world.transform_point3(p).y
                })
                .fold(f32::MAX, f32::min)
        };
        assert!(rim_low(&base).abs() < 1e-6);
        for (tilt_x, tilt_z) in [
            (20.0, 0.0),
            (-20.0, 0.0),
            (0.0, 35.0),
            (-15.0, 25.0),
            (60.0, -60.0),
        ] {
            let mut st = base.clone();
            View {
                tilt_x,
                tilt_z,
                ..View::default()
            }
            .apply(&mut st);
            let low = rim_low(&st);
            assert!(low.abs() < 2e-4, "{tilt_x} {tilt_z}: rim reaches y = {low}");
            // The dome's top moved off the vertical: the stone did turn.
            let top = st.to_world.transform_point3(Vec3::new(0.0, 0.55, 0.0));
            assert!(top.x.abs() + top.z.abs() > 0.05, "{top}");
        }
        let mut st = base.clone();
        st.environment = Environment::Map {
            path: "sky.exr".into(),
            intensity: 1.0,
            rotate: 0.25,
        };
        let light = st.lights[0].center;
        View {
            light_yaw: 90.0,
            ..View::default()
        }
        .apply(&mut st);
        let Environment::Map { rotate, .. } = st.environment else {
            unreachable!()
        };
        assert!((rotate - (0.25 + std::f32::consts::FRAC_PI_2)).abs() < 1e-6);
        // The light turned the same way: a quarter turn counter-clockwise seen from above takes
        // its offset (x, z) to (z, −x) about the pivot.
        let p = pivot(&base);
        let (a, b) = (light - p, st.lights[0].center - p);
        assert!(
            (b.x - a.z).abs() < 1e-5 && (b.z + a.x).abs() < 1e-5,
            "{a} → {b}"
        );
    }
}
