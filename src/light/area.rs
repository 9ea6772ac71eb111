//! Planar area lights (rectangles and discs) with uniform radiance.
//!
//! Rectangles are sampled uniformly in the solid angle they subtend (Ureña, Fajardo & King, "An
//! Area-Preserving Parametrization for Spherical Rectangles", EGSR 2013), which keeps the variance
//! low for lights close to the shading point; where that solid angle is too small for the
//! construction to be accurate (below 10⁻⁶ sr) they fall back to uniform area
//! sampling. Discs are sampled uniformly by area through the concentric map (Shirley & Chiu, "A
//! Low Distortion Map Between Disk and Square", JGT 2(3), 1997). Area densities are turned into
//! solid-angle densities by `pdf_ω = d² / (A |cos θ_light|)`.
//!
//! The choice between the two rectangle strategies depends only on the shading point, so
//! [`Area::pdf`] always reproduces the density [`Area::sample`] used.

use super::outline::{Beam, Outline};
use super::spherical_rect::SphericalRect;
use super::{LightSample, positive_or_zero};
use crate::color::Rgb;
use crate::geometry::{Frame, Ray};
use crate::sampler::concentric_disc;
use crate::scene::stage::{AreaLight, LightShape};
use crate::spectrum::Spectral;
use crate::spectrum::line::Line;
use crate::spectrum::measured::Measured;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Relative slack on the outline when [`Area::pdf`] re-intersects a direction, so a sample on the
/// very edge still finds the light after rounding.
const EDGE_SLACK: f32 = 1e-4;

/// A planar emitter with uniform radiance, built from a stage [`AreaLight`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Area {
    center: Vec3,
    /// `n` is the unit normal of the emitting face; for rectangles `s`, `t` follow the edges.
    frame: Frame,
    outline: Outline,
    radiance: Rgb,
    two_sided: bool,
    area: f32,
    spectrum: Option<&'static Measured>,
    /// A narrow emission line (a laser's), exclusive with `spectrum`.
    line: Option<Line>,
    /// A beam's cone (`divergence`), `None` for a light that fills its hemisphere.
    beam: Option<Beam>,
    /// The polariser's transmission axis, if any ([`Area::polariser`]).
    polariser: Option<Vec3>,
}

/// How directions toward a light are drawn from a given point.
#[derive(Clone, Copy, Debug)]
enum Strategy {
    Spherical(SphericalRect),
    Area,
    /// A beam's footprint: the points of the light's plane within `radius` of `foot` (the
    /// projection of the shading point) — exactly those whose direction to the point lies inside
    /// the beam's cone — sampled uniformly by area.
    Beam {
        foot: Vec3,
        radius: f32,
    },
}

impl Area {
    /// Precomputes the frame and area. A rectangle's `v` loses its component along `u` (stage
    /// rectangles have perpendicular edges); the emitting face is the side of `light.normal`. A
    /// degenerate light (zero area, zero normal, non-finite data) gets area 0 and never emits.
    pub fn new(light: &AreaLight) -> Area {
        let normal = light.normal.try_normalize().unwrap_or(Vec3::Y);
        let (frame, outline) = match light.shape {
            LightShape::Rect { u, v } => {
                let v = v - u * (u.dot(v) / u.length_squared().max(f32::MIN_POSITIVE));
                match (u.try_normalize(), v.try_normalize()) {
                    (Some(s), Some(t)) => {
                        // Orient the edges so that s × t is the emitting normal.
                        let t = if s.cross(t).dot(normal) < 0.0 { -t } else { t };
                        let (hx, hy) = (u.length(), v.length());
                        let n = s.cross(t);
                        (Frame { s, t, n }, Outline::Rect { hx, hy })
                    }
                    _ => (
                        Frame::from_normal(normal),
                        Outline::Rect { hx: 0.0, hy: 0.0 },
                    ),
                }
            }
            LightShape::Disc { radius } => (Frame::from_normal(normal), Outline::Disc { radius }),
        };
        let area = match outline {
            Outline::Rect { hx, hy } => 4.0 * hx * hy,
            Outline::Disc { radius } => PI * radius * radius,
        };
        let ok = area.is_finite() && area > 0.0 && light.center.is_finite() && frame.n.is_finite();
        let radiance = light.radiance.map(positive_or_zero);
        // An ideal polariser passes half of the unpolarised light behind it.
        let radiance = match light.polariser {
            Some(_) => radiance * crate::polarisation::transport::ANALYSER_TRANSMITTANCE,
            None => radiance,
        };
        Area {
            center: light.center,
            frame,
            outline,
            radiance,
            two_sided: light.two_sided,
            area: if ok { area } else { 0.0 },
            spectrum: light.spectrum.map(Measured::intern),
            line: light.line,
            beam: light.divergence.map(Beam::new),
            polariser: light.polariser.and_then(|a| a.try_normalize()),
        }
    }

    /// The transmission axis of the polariser over the light (world, unit), if it has one: its
    /// light is linearly polarised along it ([`crate::polarisation::transport`]).
    #[inline]
    pub fn polariser(&self) -> Option<Vec3> {
        self.polariser
    }

    /// The light's measured emission spectrum, if the recipe gave one (its RGB colour is what
    /// [`Area::emitted`] returns).
    pub fn spectrum(&self) -> Option<&Measured> {
        self.spectrum
    }

    /// Emitted radiance `rgb` (what [`Area::emitted`] or a light sample returned) at the path's
    /// wavelengths: the measured spectrum where the light has one and `rgb` is not zero (a face
    /// that does not emit), else the colour's illuminant spectrum.
    #[inline]
    pub fn emission<S: Spectral>(&self, rgb: Rgb, lambda: &S::Wavelengths) -> S {
        match (self.spectrum, self.line) {
            _ if rgb == Rgb::ZERO => S::ZERO,
            (Some(m), _) => S::from_measured(m, rgb, lambda),
            (None, Some(line)) => S::from_emission_fn(|l| line.eval(l), rgb, lambda),
            (None, None) => S::from_illuminant(rgb, lambda),
        }
    }

    /// Surface area in squared world units.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Unit normal of the emitting face.
    pub fn normal(&self) -> Vec3 {
        self.frame.n
    }

    /// Total emitted flux, `π · A · Y(L)`, doubled for two-sided lights (W for radiance in
    /// W·sr⁻¹·m⁻²); used to choose among lights.
    pub fn power(&self) -> f32 {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        // A beam of half-angle θ emits π sin²θ per unit radiance and area instead of π.
        let cone = self.beam.map_or(1.0, |b| b.sin2);
        (PI * cone * self.area * self.radiance.luminance() * sides).max(0.0)
    }

    /// Emitted radiance toward direction `w` (unit, leaving the light): the light's radiance when
    /// `w` leaves an emitting face, else zero.
    pub fn emitted(&self, w: Vec3) -> Rgb {
        let c = w.dot(self.frame.n);
        if self.area > 0.0
            && (c > 0.0 || (self.two_sided && c < 0.0))
            && self.beam.is_none_or(|b| b.admits(w, self.frame.n))
        {
            self.radiance
        } else {
            Rgb::ZERO
        }
    }

    /// The nearest hit `t ∈ (0, t_max)` of `ray` with the light's surface, from either face.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        self.hit(ray, t_max, 0.0)
    }

    #[inline(always)] // on every ray's light search; LLVM declined it in the spectral variant
    fn hit(&self, ray: &Ray, t_max: f32, slack: f32) -> Option<f32> {
        if !(self.area > 0.0) {
            return None;
        }
        let n = self.frame.n;
        let denom = ray.dir.dot(n);
        if denom == 0.0 {
            return None;
        }
        let t = (self.center - ray.origin).dot(n) / denom;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let q = ray.at(t) - self.center;
        let (a, b) = (q.dot(self.frame.s), q.dot(self.frame.t));
        self.outline.contains(a, b, slack).then_some(t)
    }

    /// How `sample` draws directions from `p` (a function of `p` alone, so `pdf` can repeat the
    /// choice); `None` when `p` cannot see an emitting face.
    fn strategy(&self, p: Vec3) -> Option<Strategy> {
        if !(self.area > 0.0) || !p.is_finite() {
            return None;
        }
        let side = (p - self.center).dot(self.frame.n);
        if !(side > 0.0 || (self.two_sided && side < 0.0)) {
            return None;
        }
        if let Some(beam) = self.beam {
            // A beam (a laser's divergence, docs/fluorescence.md): only the light's points within the cone's footprint reach `p`;
            // sampling the footprint instead of the whole light finds them every time. Where the
            // footprint is larger than the light, area sampling wastes less.
            let radius = side * beam.tan;
            if PI * radius * radius < self.area && radius > 0.0 && radius.is_finite() {
                let foot = p - self.frame.n * side;
                return Some(Strategy::Beam { foot, radius });
            }
        }
        let spherical = match self.outline {
            Outline::Rect { hx, hy } => SphericalRect::new(self.center, self.frame, (hx, hy), p),
            Outline::Disc { .. } => None,
        };
        Some(spherical.map_or(Strategy::Area, Strategy::Spherical))
    }

    /// A direction from `p` toward the light for next-event estimation, from `u ∈ [0, 1)²`.
    /// `None` if `p` is behind a one-sided light (or in its plane), or the sample's density is not
    /// finite.
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        match self.strategy(p)? {
            Strategy::Spherical(sr) => {
                let (d, dist2) = sr.sample_offset(u);
                let dist = dist2.sqrt();
                let wi = (d / dist).as_vec3();
                let pdf = (1.0 / sr.solid_angle) as f32;
                self.record(wi, dist as f32, pdf)
            }
            Strategy::Area => self.sample_area(p, u),
            Strategy::Beam { foot, radius } => {
                let d = concentric_disc(u) * radius;
                let q = foot + self.frame.s * d.x + self.frame.t * d.y;
                let local = q - self.center;
                let (a, b) = (local.dot(self.frame.s), local.dot(self.frame.t));
                if !self.outline.contains(a, b, 0.0) {
                    return None;
                }
                let d = q - p;
                let dist = d.length();
                let wi = d / dist;
                let pdf = dist * dist / (PI * radius * radius * wi.dot(self.frame.n).abs());
                self.record(wi, dist, pdf)
            }
        }
    }

    /// A point uniformly distributed over the light's area (density `1 / area` per world unit²),
    /// from `u ∈ [0, 1)²`; manifold next-event estimation samples lights this way.
    pub fn sample_point(&self, u: Vec2) -> Vec3 {
        let local = match self.outline {
            Outline::Rect { hx, hy } => Vec2::new((2.0 * u.x - 1.0) * hx, (2.0 * u.y - 1.0) * hy),
            Outline::Disc { radius } => concentric_disc(u) * radius,
        };
        self.center + self.frame.s * local.x + self.frame.t * local.y
    }

    /// Uniform area sampling converted to solid angle.
    fn sample_area(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let q = self.sample_point(u);
        let d = q - p;
        let dist = d.length();
        let wi = d / dist;
        let pdf = dist * dist / (self.area * wi.dot(self.frame.n).abs());
        self.record(wi, dist, pdf)
    }

    fn record(&self, wi: Vec3, dist: f32, pdf: f32) -> Option<LightSample> {
        let ok = wi.is_finite() && dist > 0.0 && dist.is_finite() && pdf > 0.0 && pdf.is_finite();
        ok.then(|| LightSample {
            wi,
            dist,
            radiance: self.emitted(-wi),
            pdf,
        })
    }

    /// Solid-angle density (sr⁻¹) with which [`sample`](Self::sample) from `p` produces the unit
    /// direction `wi`; 0 when `wi` misses the light or `p` cannot see an emitting face.
    ///
    /// # Arguments
    /// * `p` – the shading point.
    /// * `wi` – unit direction from `p` toward the light.
    /// * `t` – distance of the hit along `wi`, as the caller found it; the density is computed
    ///   from the light's own intersection of `(p, wi)`, and a non-positive or non-finite `t`
    ///   gives 0.
    pub fn pdf(&self, p: Vec3, wi: Vec3, t: f32) -> f32 {
        if !(t > 0.0 && t.is_finite()) {
            return 0.0;
        }
        let Some(strategy) = self.strategy(p) else {
            return 0.0;
        };
        let Some(hit) = self.hit(&Ray::new(p, wi), f32::INFINITY, EDGE_SLACK) else {
            return 0.0;
        };
        let pdf = match strategy {
            Strategy::Spherical(sr) => (1.0 / sr.solid_angle) as f32,
            Strategy::Area => hit * hit / (self.area * wi.dot(self.frame.n).abs()),
            Strategy::Beam { foot, radius } => {
                if (p + wi * hit - foot).length() > radius * (1.0 + EDGE_SLACK) {
                    return 0.0;
                }
                hit * hit / (PI * radius * radius * wi.dot(self.frame.n).abs())
            }
        };
        positive_or_zero(pdf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::distribution::testing::*;
    use crate::sampler::Rng;

    fn light(center: Vec3, normal: Vec3, shape: LightShape, two_sided: bool) -> Area {
        let radiance = Rgb::splat(2.0);
        Area::new(&AreaLight {
            center,
            normal,
            shape,
            radiance,
            two_sided,
            spectrum: None,
            line: None,
            divergence: None,
            polariser: None,
        })
    }

    /// A rectangle with half-edges `hx` along x and `hz` along z, facing −y.
    fn rect(center: Vec3, hx: f32, hz: f32, two_sided: bool) -> Area {
        let (u, v) = (Vec3::X * hx, Vec3::Z * hz);
        light(center, Vec3::NEG_Y, LightShape::Rect { u, v }, two_sided)
    }

    fn disc(center: Vec3, normal: Vec3, radius: f32) -> Area {
        light(center, normal, LightShape::Disc { radius }, false)
    }

    /// A 1 × 0.5 rectangle 0.5 above the origin (Ureña), a 10⁻³-sized one 10 away (area
    /// fallback), a tilted disc, a two-sided rectangle seen from its back; all seen from `p`.
    fn cases() -> [(&'static str, Area, Vec3); 4] {
        let n = Vec3::new(0.1, -1.0, 0.2).normalize();
        let p = Vec3::new(0.1, 0.0, 0.2);
        let o = Vec3::ZERO;
        let (near, far) = (Vec3::new(0.3, 0.5, 0.1), Vec3::new(1.0, 10.0, 0.0));
        [
            ("near", rect(near, 0.5, 0.25, false), o),
            ("far", rect(far, 5e-4, 5e-4, false), o),
            ("disc", disc(Vec3::new(0.2, 0.4, -0.3), n, 0.5), o),
            ("back", rect(Vec3::NEG_Y * 0.6, 0.4, 0.7, true), p),
        ]
    }

    #[test]
    fn pdf_matches_sample_and_integrates_to_one() {
        let c = cases();
        let spherical = c[0].1.strategy(c[0].2);
        assert!(matches!(spherical, Some(Strategy::Spherical(_))));
        assert!(matches!(c[1].1.strategy(c[1].2), Some(Strategy::Area)));
        for (name, light, p) in c {
            let mut rng = Rng::new(7);
            for _ in 0..2000 {
                let s = light.sample(p, rng.uniform2()).expect(name);
                assert!((s.wi.length() - 1.0).abs() < 1e-5 && s.radiance == Rgb::splat(2.0));
                let pdf = light.pdf(p, s.wi, s.dist);
                assert!((pdf - s.pdf).abs() <= 1e-4 * s.pdf, "{name}: {pdf}");
                let t = light.intersect(&Ray::new(p, s.wi), f32::INFINITY).unwrap();
                assert!((t - s.dist).abs() <= 1e-4 * s.dist, "{name}: {t}");
            }
            if name == "far" {
                continue; // 10⁻⁸ sr: uniform directions would never find it.
            }
            // 200 000 uniform directions, accepted within 4 standard errors.
            let (m, se) = sphere_integral(|w| {
                let t = light.intersect(&Ray::new(p, w), f32::INFINITY);
                light.pdf(p, w, t.unwrap_or(0.0))
            });
            assert!((m - 1.0).abs() < 4.0 * se, "{name}: ∫pdf = {m} ± {se}");
        }
    }

    /// Irradiance at the origin (normal +y) by next-event estimation with 20 000 samples,
    /// accepted within 4 standard errors of `exact`.
    fn check_irradiance(name: &str, exact: f64, f: impl Fn(Vec2) -> Option<LightSample>) {
        let e = |s: LightSample| f64::from(s.radiance[0] * s.wi.y / s.pdf);
        let (m, se) = estimate(20_000, 3, |u| f(u).map_or(0.0, e));
        let tol = (4.0 * se).max(1e-5 * exact);
        assert!(
            (m - exact).abs() < tol,
            "{name}: E = {m} ± {se}, exact {exact}"
        );
    }

    #[test]
    fn irradiance_matches_closed_forms() {
        use std::f64::consts::PI;
        // Disc of radius r facing down at height h on the axis: E = π L r² / (r² + h²).
        let (r, h) = (0.7f32, 0.5f32);
        let d = disc(Vec3::Y * h, Vec3::NEG_Y, r);
        let exact = PI * 2.0 * f64::from(r * r / (r * r + h * h));
        check_irradiance("disc", exact, |u| d.sample(Vec3::ZERO, u));
        // Under the corner of a parallel a × b rectangle at height h: E = π L F with
        // F = 1/(2π) [X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))], X = a/h, Y = b/h.
        for (a, b, h) in [(1.0f32, 0.6f32, 0.3f32), (2e-3, 1e-3, 10.0)] {
            let (x, y) = (f64::from(a / h), f64::from(b / h));
            let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
            let f = (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI);
            let l = rect(Vec3::new(a / 2.0, h, b / 2.0), a / 2.0, b / 2.0, false);
            assert_eq!(l.normal(), Vec3::NEG_Y);
            check_irradiance("rect", PI * 2.0 * f, |u| l.sample(Vec3::ZERO, u));
            check_irradiance("by area", PI * 2.0 * f, |u| l.sample_area(Vec3::ZERO, u));
        }
    }

    #[test]
    fn solid_angle_matches_the_closed_form() {
        // The rectangle [x0, x1] × [y0, y1] in the plane at distance z: Ω = Σ ± atan(x y / (z d))
        // over its corners (d the corner's distance); well conditioned where the light is not
        // seen edge-on. Near, far and off to the side.
        let mut rng = Rng::new(11);
        for _ in 0..20_000 {
            let half = Vec2::new(0.05 + rng.uniform(), 0.05 + rng.uniform());
            let height = 0.05 + 5.0 * rng.uniform();
            let shift = (rng.uniform2() - 0.5) * 8.0;
            let l = rect(Vec3::new(shift.x, height, shift.y), half.x, half.y, false);
            let Some(Strategy::Spherical(sr)) = l.strategy(Vec3::ZERO) else {
                panic!("{half:?} at {height}, {shift:?}: no spherical rectangle");
            };
            // The corners as the construction sees them (the frame's axes are unit to f32
            // precision, so the corner's coordinates are formed the same way).
            let (s, t) = (l.frame.s.as_dvec3(), l.frame.t.as_dvec3());
            let (hx, hy) = (f64::from(half.x), f64::from(half.y));
            let corner = l.center.as_dvec3() - s * hx - t * hy;
            let z = corner.dot(s.cross(t)).abs();
            let (x0, y0) = (corner.dot(s), corner.dot(t));
            let (x1, y1) = (x0 + 2.0 * hx, y0 + 2.0 * hy);
            let f = |x: f64, y: f64| (x * y / (z * (x * x + y * y + z * z).sqrt())).atan();
            let exact = f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0);
            let rel = (sr.solid_angle - exact).abs() / exact;
            assert!(
                rel < 1e-10,
                "{half:?} at {height}, {shift:?}: {} vs {exact}",
                sr.solid_angle
            );
        }
        // Nearly edge-on (1 mm above the plane, 2.3 units off to the side): the closed form in
        // f64 is off by 4·10⁻⁸ here, the construction's four `acos` (of values near ±1) by
        // 9·10⁻⁹ — far below what an f32 density resolves (summing the angles in pairs through
        // `atan2` is exact to 10⁻¹², but glibc's `atan2` costs 3.6 `acos`: +2 % of Lepidolite's
        // instructions); the reference is the closed form in 50-digit arithmetic (mpmath) at this
        // light's corners, x ∈
        // [−2.3712419122457504, −2.1929060369729996], y ∈ [1.0127581686756224, 2.1415453285953614],
        // z = 0.0009999999878928037.
        let l = rect(
            Vec3::new(-2.282074, 0.001, 1.5771518),
            0.08916794,
            0.5643936,
            false,
        );
        let Some(Strategy::Spherical(sr)) = l.strategy(Vec3::ZERO) else {
            panic!("edge-on: no spherical rectangle");
        };
        let reference = 9.555_223_079_427_055e-6;
        let rel = (sr.solid_angle - reference).abs() / reference;
        assert!(
            rel < 2e-8,
            "edge-on: {} vs {reference} ({rel:e})",
            sr.solid_angle
        );
    }

    #[test]
    fn one_sided_light_is_dark_behind() {
        let l = rect(Vec3::Y, 1.0, 1.0, false); // faces −y
        let above = Vec3::new(0.2, 2.0, 0.1);
        assert!(l.sample(above, Vec2::splat(0.3)).is_none());
        assert_eq!(l.pdf(above, Vec3::NEG_Y, 1.0), 0.0);
        let in_plane = Vec3::new(3.0, 1.0, 0.0);
        assert!(
            l.sample(in_plane, Vec2::splat(0.3)).is_none(),
            "in its plane"
        );
        assert!(l.sample(Vec3::ZERO, Vec2::splat(0.3)).is_some());
        assert_eq!(l.emitted(Vec3::Y), Rgb::ZERO);
        assert_eq!(l.emitted(Vec3::NEG_Y), Rgb::splat(2.0));
        let two = rect(Vec3::Y, 1.0, 1.0, true);
        assert!(two.sample(above, Vec2::splat(0.3)).is_some());
        assert_eq!(two.emitted(Vec3::Y), Rgb::splat(2.0));
        assert!((two.power() - 2.0 * l.power()).abs() < 1e-4);
        assert!((l.power() - PI * 4.0 * 2.0).abs() < 1e-4 && (l.area() - 4.0).abs() < 1e-6);
    }

    #[test]
    fn intersection_finds_the_surface_only() {
        let l = rect(Vec3::Y, 0.5, 0.25, false);
        let up = |x: f32, z: f32| Ray::new(Vec3::new(x, 0.0, z), Vec3::Y);
        assert!((l.intersect(&up(0.4, -0.2), 10.0).unwrap() - 1.0).abs() < 1e-6);
        assert!(
            l.intersect(&up(0.6, 0.0), 10.0).is_none() && l.intersect(&up(0.0, 0.3), 9.0).is_none()
        );
        assert!(l.intersect(&up(0.0, 0.0), 0.9).is_none(), "beyond t_max");
        let ray = |o: Vec3, d: Vec3| l.intersect(&Ray::new(o, d), 10.0);
        assert!(ray(Vec3::ZERO, Vec3::NEG_Y).is_none(), "away");
        assert!(ray(Vec3::Y * 2.0, Vec3::NEG_Y).is_some(), "back face");
        assert!(ray(Vec3::Y, Vec3::X).is_none(), "parallel");
        let d = disc(Vec3::Y, Vec3::NEG_Y, 0.5);
        assert!(
            d.intersect(&up(0.3, 0.3), 9.0).is_some() && d.intersect(&up(0.4, 0.4), 9.0).is_none()
        );
        // Degenerate lights never emit.
        let z = rect(Vec3::Y, 1.0, 0.0, false);
        assert_eq!((z.area(), z.power()), (0.0, 0.0));
        assert!(z.sample(Vec3::ZERO, Vec2::splat(0.5)).is_none());
    }

    #[test]
    fn sample_histogram_matches_pdf() {
        // Where 100 000 samples land on a 1 × 0.5 rectangle seen from close off-centre, in an
        // 8 × 8 grid, against ∫ pdf dω per cell (16 × 16 midpoint rule); χ² at significance 0.01.
        let l = rect(Vec3::new(0.3, 0.3, 0.1), 0.5, 0.25, false);
        let (g, sub, n) = (8usize, 16usize, 100_000);
        let mut observed = vec![0.0f64; g * g];
        let mut rng = Rng::new(5);
        for _ in 0..n {
            let s = l.sample(Vec3::ZERO, rng.uniform2()).expect("visible");
            let q = s.wi * s.dist - l.center;
            let i = ((q.dot(l.frame.s) + 0.5) * g as f32) as usize;
            let j = ((q.dot(l.frame.t) * 2.0 + 0.5) * g as f32) as usize;
            observed[j.min(g - 1) * g + i.min(g - 1)] += 1.0;
        }
        let m = g * sub;
        let mut expected = vec![0.0f64; g * g];
        for k in 0..m * m {
            let a = ((k % m) as f32 + 0.5) / m as f32 - 0.5;
            let b = ((k / m) as f32 + 0.5) / m as f32 * 0.5 - 0.25;
            let q = l.center + l.frame.s * a + l.frame.t * b;
            let (wi, dist) = (q.normalize(), q.length());
            let dw = 0.5 / (m * m) as f32 * wi.dot(l.frame.n).abs() / (dist * dist);
            expected[(k / m / sub) * g + (k % m) / sub] +=
                f64::from(l.pdf(Vec3::ZERO, wi, dist) * dw * n as f32);
        }
        assert_chi2(&observed, &expected);
    }
}
