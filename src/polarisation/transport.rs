//! Polarisation carried by a camera path: the sensor's measurement as a Stokes **covector** per
//! channel, updated at every vertex, so that a path costs four numbers more per wavelength rather
//! than a 4 × 4 Mueller matrix.
//!
//! A camera that measures intensity through an optional analyser reads `w · M₁ M₂ ⋯ Mₖ · S_light`,
//! where `w` is the sensor's row (`(1, 0, 0, 0)` for intensity; `½ (1, cos 2θ, sin 2θ, 0)` behind
//! a linear analyser at `θ`, the first row of its Mueller matrix) and `Mᵢ` the Mueller matrices
//! of the path's vertices from the camera outward. A camera path multiplies from the left, so it
//! only ever needs the row `w · M₁ ⋯ Mᵢ` — Mitsuba 3 carries the whole matrix (Jakob et al.,
//! "Mitsuba 3", 2022; its polarised variants), which a single measured component does not need.
//!
//! The row is kept as the path's scalar throughput `β` (its first entry, which every unpolarised
//! code path already computes) times the ratios `(w₁, w₂, w₃) / w₀` stored here. At a vertex with
//! Mueller matrix `M = M₀₀ N` (`N₀₀ = 1`), the scalar code multiplies `β` by `M₀₀ / p` (the
//! scalar Fresnel factor over the sampling probability); this module returns the correction
//! `k = ((1, w₁, w₂, w₃) · N)₀` and the new ratios. Where polarisation cannot matter the
//! correction is exactly 1: a path whose ratios are zero (unpolarised so far) has `k = N₀₀ = 1`.
//! A depolarising vertex (`M = f · diag(1, 0, 0, 0)`: Lambert, the layered materials as the
//! course models them, media, platelets) zeroes the ratios.
//!
//! For a physical row `|(w₁, w₂, w₃)| ≤ 1` (an analyser followed by physical elements stays one),
//! so `k ∈ [0, 2]`: the correction never turns a throughput negative.
//!
//! Frames follow [`super`]: the Stokes vector of the light on a path segment is measured about the
//! light's propagation direction `d` (opposite to the camera path's ray), with the reference axis
//! `x` kept here; at an interface `x` is turned to `s`, the normal of the plane of incidence.

use super::Mueller;
pub use super::event::{Interface, InterfaceEvent, MAX_CHANNELS};
use glam::Vec3;

/// The polarisation state of a camera path (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPolarisation {
    /// Reference axis of the current segment's frame: unit, orthogonal to the segment.
    pub x: Vec3,
    /// Per channel, `(w₁, w₂, w₃) / w₀` of the sensor's row in frame `x`.
    pub w: [[f32; 3]; MAX_CHANNELS],
    /// Inside a doubly refractive crystal, the wave the segment's light travels in (its row is
    /// then that wave's pure polarisation, [`super::crystal`]); `None` elsewhere, and inside
    /// after a depolarising vertex.
    pub mode: Option<super::boundary::Mode>,
    /// With `mode`, that wave's unit wave normal, oriented along the camera path, where the
    /// boundary that made it knew it (zero otherwise): a biaxial crystal's ray does not always
    /// name one wave (near an optic axis two normals of a sheet share a ray).
    pub normal: Vec3,
}

impl PathPolarisation {
    /// The row of an unpolarised intensity measurement.
    pub const UNPOLARISED: PathPolarisation = PathPolarisation {
        x: Vec3::X,
        w: [[0.0; 3]; MAX_CHANNELS],
        mode: None,
        normal: Vec3::ZERO,
    };

    /// The row of a camera behind an ideal linear analyser whose transmission axis is `axis`
    /// (world, unit), for a camera ray of direction `dir` (unit; the light propagates along
    /// `−dir`). The analyser also halves the intensity: the caller multiplies `β` by
    /// [`ANALYSER_TRANSMITTANCE`]. An axis along the ray (impossible for an axis in the image
    /// plane) gives the unpolarised row.
    pub fn analyser(axis: Vec3, dir: Vec3) -> PathPolarisation {
        let x = (axis - dir * axis.dot(dir)).try_normalize();
        match x {
            Some(x) => PathPolarisation {
                x,
                w: [[1.0, 0.0, 0.0]; MAX_CHANNELS],
                mode: None,
                normal: Vec3::ZERO,
            },
            None => PathPolarisation::UNPOLARISED,
        }
    }

    /// Whether every channel's ratios are zero (an unpolarised measurement so far).
    #[inline]
    pub fn is_unpolarised(&self) -> bool {
        self.w.iter().flatten().all(|&v| v == 0.0)
    }

    /// A depolarising vertex: the row becomes `(w₀, 0, 0, 0)` (its `w₀` is the scalar code's).
    #[inline]
    pub fn depolarise(&mut self) {
        self.w = [[0.0; 3]; MAX_CHANNELS];
        self.mode = None;
        self.normal = Vec3::ZERO;
    }

    /// Re-expresses the row in the frame with axis `x_new` (unit, orthogonal to the light's
    /// propagation `d`). A row transforms as a Stokes vector does under the rotation (the rotator
    /// is orthogonal), by twice the angle from the old axis to the new one.
    pub fn rotate_to(&mut self, x_new: Vec3, d: Vec3) {
        if !self.is_unpolarised() {
            self.rotate_by(turn(self.x, x_new, d));
        }
        self.x = x_new;
    }

    /// Turns the ratios by a [`turn`] (the frame's axis is the caller's to set).
    #[inline]
    fn rotate_by(&mut self, [c, s]: [f32; 2]) {
        for w in &mut self.w {
            let (a, b) = (w[0], w[1]);
            w[0] = c * a + s * b;
            w[1] = -s * a + c * b;
        }
    }

    /// A specular event at an interface with unit normal `n` (either sign): the light leaves along
    /// `wo` and arrived from `wi` (so propagated along `−wi`), both unit and world space, and
    /// `eta[c]` is the relative index far side over the side the light arrived from, per channel
    /// (`None`: a channel the path no longer carries). Returns the correction of each channel's
    /// throughput (module docs) and leaves the row in the frame of the segment toward `wi`.
    pub fn interface(
        &mut self,
        n: Vec3,
        wo: Vec3,
        wi: Vec3,
        eta: [Option<f32>; MAX_CHANNELS],
        kind: Interface,
    ) -> [f32; MAX_CHANNELS] {
        let event = InterfaceEvent::new(n, wo, wi, eta, kind, self.x);
        self.take(&event)
    }

    /// The row's update by an interface event computed once ([`InterfaceEvent::new`]): what
    /// [`PathPolarisation::interface`] does, for rows that share an event (the Stokes AOVs').
    pub fn take(&mut self, e: &InterfaceEvent) -> [f32; MAX_CHANNELS] {
        self.rotate_to(e.s, e.wo);
        self.take_in_frame(e)
    }

    /// [`PathPolarisation::take`] for a row already turned by `t`, the [`turn`] from its axis to
    /// the event's (rows sharing a frame compute the turn once).
    pub fn take_turned(&mut self, e: &InterfaceEvent, t: [f32; 2]) -> [f32; MAX_CHANNELS] {
        if !self.is_unpolarised() {
            self.rotate_by(t);
        }
        self.x = e.s;
        self.take_in_frame(e)
    }

    /// The event's matrices applied to a row in the event's frame.
    fn take_in_frame(&mut self, e: &InterfaceEvent) -> [f32; MAX_CHANNELS] {
        let mut k = [0.0; MAX_CHANNELS];
        for (c, m) in e.m.iter().enumerate() {
            match m {
                None => self.w[c] = [0.0; 3],
                Some(m) => k[c] = self.apply(c, m.as_ref()),
            }
        }
        self.x = e.s;
        k
    }

    /// An element of Mueller matrix `m[c]` per channel (frame axis `x`, unit, across the light's
    /// propagation `d`) on the segment: the row turned to `x` and multiplied; returns each
    /// channel's correction `k` (the throughput takes `m₀₀ k`).
    pub fn element(
        &mut self,
        x: Vec3,
        d: Vec3,
        m: &[Mueller; MAX_CHANNELS],
    ) -> [f32; MAX_CHANNELS] {
        self.rotate_to(x, d);
        std::array::from_fn(|c| self.apply(c, Some(&m[c])))
    }

    /// Multiplies channel `c`'s row by `m / m₀₀` and renormalises it; returns the correction `k`
    /// (0, and the channel's ratios zeroed, where `m` passes nothing).
    fn apply(&mut self, c: usize, m: Option<&Mueller>) -> f32 {
        let Some(m) = m.filter(|m| m.0[0][0] > 0.0 && m.0[0][0].is_finite()) else {
            self.w[c] = [0.0; 3];
            return 0.0;
        };
        let row = [
            1.0,
            f64::from(self.w[c][0]),
            f64::from(self.w[c][1]),
            f64::from(self.w[c][2]),
        ];
        let out: [f64; 4] =
            std::array::from_fn(|j| (0..4).map(|i| row[i] * m.0[i][j]).sum::<f64>() / m.0[0][0]);
        if out[0] > 0.0 && out.iter().all(|v| v.is_finite()) {
            self.w[c] = [
                (out[1] / out[0]) as f32,
                (out[2] / out[0]) as f32,
                (out[3] / out[0]) as f32,
            ];
            out[0] as f32
        } else {
            self.w[c] = [0.0; 3];
            0.0
        }
    }

    /// The correction of each channel's emission for light linearly polarised along `axis`
    /// (world, unit; a light behind an ideal polariser) reaching the current segment, whose
    /// light propagates along `d` (unit): `(1, w₁, w₂, w₃) · (1, 1, 0, 0)` in the polariser's
    /// frame. The light's intensity (already halved by its polariser) is the scalar code's.
    pub fn polarised_emission(&self, axis: Vec3, d: Vec3) -> [f32; MAX_CHANNELS] {
        if self.is_unpolarised() {
            return [1.0; MAX_CHANNELS];
        }
        let Some(x_light) = (axis - d * axis.dot(d)).try_normalize() else {
            // Light propagating along the polariser's axis: no transverse component passes.
            return [0.0; MAX_CHANNELS];
        };
        let mut row = *self;
        row.rotate_to(x_light, d);
        row.w.map(|w| (1.0 + w[0]).max(0.0))
    }

    /// [`PathPolarisation::polarised_emission`] for a row whose frame has already been related to
    /// the light's by `t`, the [`turn`] to the polariser's axis.
    pub fn polarised_emission_turned(&self, [c, s]: [f32; 2]) -> [f32; MAX_CHANNELS] {
        self.w.map(|w| (1.0 + (c * w[0] + s * w[1])).max(0.0))
    }
}

/// `(cos 2φ, sin 2φ)` of the angle `φ` from frame axis `from` to `to`, both unit and orthogonal
/// to the propagation direction `d` (the rotator a row or Stokes vector takes between them).
#[inline]
pub fn turn(from: Vec3, to: Vec3, d: Vec3) -> [f32; 2] {
    let phi = from.cross(to).dot(d).atan2(from.dot(to));
    let (s, c) = (2.0 * phi).sin_cos();
    [c, s]
}

/// The intensity an ideal linear polariser passes of unpolarised light.
pub const ANALYSER_TRANSMITTANCE: f32 = 0.5;

#[cfg(test)]
mod tests {
    use super::super::Stokes;
    use super::super::fresnel;
    use super::*;
    use std::f64::consts::PI;

    /// The measurement `w · S` of Stokes vector `s` by a channel-0 row.
    fn measure(p: &PathPolarisation, s: Stokes) -> f64 {
        let w = p.w[0];
        s.0[0] + f64::from(w[0]) * s.0[1] + f64::from(w[1]) * s.0[2] + f64::from(w[2]) * s.0[3]
    }

    /// A measurement does not depend on the frame it is written in: rotating the row and
    /// re-expressing the Stokes vector with [`Mueller::frame_change`] (written independently)
    /// give the same number.
    #[test]
    fn rotation_keeps_measurements() {
        let d = Vec3::new(0.3, -0.5, 0.8).normalize();
        let x0 = d.any_orthonormal_vector();
        let mut p = PathPolarisation {
            x: x0,
            w: [[0.6, -0.3, 0.5]; MAX_CHANNELS],
            mode: None,
            normal: Vec3::ZERO,
        };
        let s = Stokes([1.0, 0.2, -0.7, 0.4]);
        let before = measure(&p, s);
        for k in 0..12 {
            let a = 0.37 * k as f32;
            let x1 = (x0 * a.cos() + d.cross(x0) * a.sin()).normalize();
            let mut q = p;
            q.rotate_to(x1, d);
            let s1 = Mueller::frame_change(x0.as_dvec3(), x1.as_dvec3(), d.as_dvec3()).apply(s);
            assert!((measure(&q, s1) - before).abs() < 1e-5, "{k}");
        }
        p.depolarise();
        assert!(p.is_unpolarised());
    }

    /// Malus's law through the row: an analyser at `θ` to a polarised light passes `cos² θ` of
    /// it (times the analyser's ½ of unpolarised light, applied by the caller).
    #[test]
    fn analyser_against_a_polarised_light_is_malus() {
        let dir = Vec3::new(0.0, 0.0, -1.0);
        let d = -dir;
        let right = Vec3::X;
        let p = PathPolarisation::analyser(right, dir);
        for k in 0..=18 {
            let theta = PI as f32 * k as f32 / 18.0;
            let axis = Vec3::new(theta.cos(), theta.sin(), 0.0);
            // The light's intensity behind its polariser is ½ L: the row corrects it by 2 cos² θ,
            // so the camera (with its own ½) reads ½ L cos² θ as Malus says.
            let k0 = p.polarised_emission(axis, d)[0];
            let want = 2.0 * theta.cos().powi(2);
            assert!((k0 - want).abs() < 1e-5, "θ {theta}: {k0} vs {want}");
        }
        assert_eq!(
            PathPolarisation::UNPOLARISED.polarised_emission(Vec3::Y, d),
            [1.0; MAX_CHANNELS]
        );
    }

    /// An unpolarised row meets an interface with correction exactly 1 (the scalar Fresnel factor
    /// is the whole story), and leaves with the interface's polarising row: at Brewster's angle a
    /// reflection passes only s light, so the row becomes `(1, 1, 0, 0)` in the s frame.
    #[test]
    fn unpolarised_rows_are_corrected_by_one_and_brewster_polarises() {
        let n = Vec3::Y;
        let eta = 1.5f32;
        let theta_b = eta.atan();
        let wo = Vec3::new(theta_b.sin(), theta_b.cos(), 0.0);
        let wi = Vec3::new(-wo.x, wo.y, 0.0);
        let mut p = PathPolarisation::UNPOLARISED;
        let k = p.interface(
            n,
            wo,
            wi,
            [Some(eta), Some(1.3), None, None],
            Interface::Reflection,
        );
        assert_eq!(k[0], 1.0);
        assert_eq!(k[1], 1.0);
        assert_eq!(k[2], 0.0);
        assert!((p.w[0][0] - 1.0).abs() < 1e-5, "{:?}", p.w[0]);
        assert!(p.w[1][0] > 0.0 && p.w[1][0] < 1.0, "{:?}", p.w[1]);
        // The frame's axis is s: normal to the plane of incidence and to the new segment.
        assert!(p.x.dot(wi).abs() < 1e-6 && p.x.dot(n).abs() < 1e-6);
        // A second reflection in the same plane sees s light: its correction is Rs/R.
        let mut q = p;
        let cos = 0.6f32;
        let wo2 = Vec3::new((1.0 - cos * cos).sqrt(), cos, 0.0);
        let wi2 = Vec3::new(-wo2.x, cos, 0.0);
        let k2 = q.interface(n, wo2, wi2, [Some(eta); 4], Interface::Reflection)[0];
        let m = fresnel::dielectric_reflection(f64::from(cos), f64::from(eta));
        let want = (m.0[0][0] + m.0[1][0]) / m.0[0][0];
        assert!((f64::from(k2) - want).abs() < 1e-5, "{k2} vs {want}");
    }

    /// Corrections stay within `[0, 2]` and rows physical over random chains of interfaces.
    #[test]
    fn random_chains_stay_physical() {
        let mut state = 12345u64;
        let mut u = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        let mut p = PathPolarisation::analyser(Vec3::X, Vec3::NEG_Z);
        let mut wo = Vec3::Z;
        for _ in 0..2000 {
            let n = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5).normalize_or(Vec3::Y);
            let n = if n.dot(wo) < 0.0 { -n } else { n };
            let refl = u() < 0.5;
            let eta = 1.0 + 1.5 * u();
            let wi = if refl {
                2.0 * n * n.dot(wo) - wo
            } else {
                match crate::bsdf::refract(wo, n, eta) {
                    Some(v) => v,
                    None => continue,
                }
            };
            let kind = if refl {
                Interface::Reflection
            } else {
                Interface::Refraction
            };
            let e = if refl { eta } else { 1.0 / eta };
            let k = p.interface(n, wo, wi, [Some(e); 4], kind);
            assert!((0.0..=2.0 + 1e-4).contains(&k[0]), "{k:?}");
            let w = p.w[0];
            assert!(
                w[0] * w[0] + w[1] * w[1] + w[2] * w[2] <= 1.0 + 1e-3,
                "{w:?}"
            );
            assert!(p.x.dot(wi).abs() < 1e-4);
            wo = -wi;
        }
    }
}
