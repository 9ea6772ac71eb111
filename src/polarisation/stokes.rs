//! The Stokes AOVs (`lapidary render --stokes`): the full Stokes vector `(S0, S1, S2, S3)` of the
//! light reaching the camera, measured in one pass beside the sensor's own row.
//!
//! A camera path carries the row of the one component the sensor measures
//! ([`super::transport`]); the Stokes vector needs four. They ride on the same path as four more
//! rows `R₀ = (1, 0, 0, 0)`, `R₁ = (1, 1, 0, 0)`, `R₂ = (1, 0, 1, 0)`, `R₃ = (1, 0, 0, 1)` in the
//! image's frame — physical rows (`|(w₁, w₂, w₃)| ≤ 1`), so every correction stays in `[0, 2]` —
//! and `S₀ = R₀ · S`, `Sⱼ = Rⱼ · S − R₀ · S`. Every sampling decision of a polarised path is
//! independent of its row (the crystal's choice uses the adjoint problem's unpolarised shares,
//! a smooth interface the scalar Fresnel factor), so one path serves all five rows: each extra
//! row keeps its throughput as a factor `f` of the path's `β` (the sensor row's), updated by
//! `k_row / k_sensor` wherever the sensor's row is corrected by `k_sensor`.
//!
//! After the first depolarising vertex every row is `(w₀, 0, 0, 0)` and all rows evolve alike,
//! so their factors stop changing: the rows are **settled** and cost nothing more. Only the
//! specular chain from the camera to the first rough vertex (or a polarised light) is tracked
//! per row.
//!
//! The frame: `x` is the image's right, `y` its up (for light travelling toward the camera,
//! `y = d × x`, [`super`]); so `S1 = I(horizontal) − I(vertical)`, `S2 = I(+45°) − I(−45°)` with
//! +45° from right toward up, `S3 = I(right) − I(left)` circular — as a polarimeter looking into
//! the scene reads them. Mitsuba 3's `stokes` integrator reports the same four components per
//! pixel (Jakob et al., "Mitsuba 3", 2022; its frame is its sensor's).
//!
//! A path whose sensor row is extinguished mid-chain (correction 0: a pure row crossed by a
//! Brewster reflection) ends with its rows: the scalar loop stops a path of zero throughput. The
//! emission of a polarised light, where a crossed analyser reads zero while the Stokes vector
//! does not, is measured per row ([`StokesRows::polarised_emission`]).

use super::transport::{InterfaceEvent, MAX_CHANNELS, PathPolarisation, turn};
use glam::Vec3;

/// Rows carried: `R₀ … R₃` (module docs).
pub const ROWS: usize = 4;

/// The Stokes rows of a camera path (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StokesRows {
    /// The rows' frames and ratios.
    pub rows: [PathPolarisation; ROWS],
    /// Per row and channel, the row's throughput over the path's `β`.
    pub f: [[f32; MAX_CHANNELS]; ROWS],
    /// Whether every row has been depolarised (then they follow the sensor's row exactly).
    pub settled: bool,
}

impl StokesRows {
    /// The rows of a camera ray along `dir` (unit), in the frame whose `x` is the image's
    /// `right` (unit) made orthogonal to the ray. `scale` is `1 / w₀` of the sensor's row: 1 for
    /// an intensity sensor, 2 behind an analyser, which halves `β` but not the Stokes vector
    /// that reaches it.
    pub fn new(right: Vec3, dir: Vec3, scale: f32) -> StokesRows {
        let x = (right - dir * right.dot(dir))
            .try_normalize()
            .unwrap_or_else(|| dir.any_orthonormal_vector());
        let row = |w: [f32; 3]| PathPolarisation {
            x,
            w: [w; MAX_CHANNELS],
            mode: None,
            normal: Vec3::ZERO,
        };
        StokesRows {
            rows: [
                row([0.0; 3]),
                row([1.0, 0.0, 0.0]),
                row([0.0, 1.0, 0.0]),
                row([0.0, 0.0, 1.0]),
            ],
            f: [[scale; MAX_CHANNELS]; ROWS],
            settled: false,
        }
    }

    /// A depolarising vertex: every row becomes `(w₀, 0, 0, 0)` and the rows settle.
    #[inline]
    pub fn depolarise(&mut self) {
        if !self.settled {
            for r in &mut self.rows {
                r.depolarise();
            }
            self.settled = true;
        }
    }

    /// The interface event the sensor's row took ([`PathPolarisation::take`]) with corrections
    /// `k_sensor`: each row takes it too and its factor changes by `k_row / k_sensor` (0 where
    /// the sensor's channel was extinguished).
    pub fn take(&mut self, event: &InterfaceEvent, k_sensor: [f32; MAX_CHANNELS]) {
        if self.settled {
            return;
        }
        // The rows share one frame (they start in it and take the same events): one turn.
        let t = turn(self.rows[0].x, event.s, event.wo);
        for j in 0..ROWS {
            let k = self.rows[j].take_turned(event, t);
            self.rescale(j, k, k_sensor);
        }
    }

    /// What each row reads of light reaching the path through `event` (a light sample off a
    /// polarising vertex), times its factor, as [`StokesRows::polarised_emission`] gives it:
    /// per row and channel the event's correction `((1, w)·N)₀`, and for a light behind a
    /// polariser (`(axis, d)`: its axis and the light's propagation, world, unit) the row's
    /// reading of that polarisation after the event (the rows themselves unchanged). Rows that
    /// have settled read as the sensor does (the caller's [`StokesRows::settled`] case).
    pub fn read_light(
        &self,
        event: &InterfaceEvent,
        polariser: Option<(Vec3, Vec3)>,
    ) -> [[f32; MAX_CHANNELS]; ROWS] {
        let t = turn(self.rows[0].x, event.s, event.wo);
        std::array::from_fn(|j| {
            let mut row = self.rows[j];
            let k = row.take_turned(event, t);
            let p = polariser.map_or([1.0; MAX_CHANNELS], |(axis, d)| {
                row.polarised_emission(axis, d)
            });
            std::array::from_fn(|c| k[c] * p[c] * self.f[j][c])
        })
    }

    /// Multiplies row `j`'s factors by `k_row / k_sensor` per channel.
    #[inline]
    pub fn rescale(&mut self, j: usize, k_row: [f32; MAX_CHANNELS], k_sensor: [f32; MAX_CHANNELS]) {
        for c in 0..MAX_CHANNELS {
            self.f[j][c] = if k_sensor[c] > 0.0 {
                self.f[j][c] * (k_row[c] / k_sensor[c])
            } else {
                0.0
            };
        }
    }

    /// Every row takes the sensor row's state (inside a crystal every row is its wave's pure
    /// state, [`super::crystal`]), factors unchanged.
    #[inline]
    pub fn follow(&mut self, sensor: &PathPolarisation) {
        if !self.settled {
            self.rows = [*sensor; ROWS];
        }
    }

    /// Each row's correction of a polarised light's emission ([`PathPolarisation::
    /// polarised_emission`]) reaching the current segment, times its factor: what multiplies
    /// the emission's contribution `β · Le · w` (before the sensor's own correction) for row `j`.
    pub fn polarised_emission(&self, axis: Vec3, d: Vec3) -> [[f32; MAX_CHANNELS]; ROWS] {
        let Some(x_light) = (axis - d * axis.dot(d)).try_normalize() else {
            return [[0.0; MAX_CHANNELS]; ROWS];
        };
        let t = turn(self.rows[0].x, x_light, d);
        std::array::from_fn(|j| {
            let k = self.rows[j].polarised_emission_turned(t);
            std::array::from_fn(|c| k[c] * self.f[j][c])
        })
    }

    /// The Stokes vector from the rows' measurements `m` (any linear quantity per row):
    /// `S₀ = m₀`, `Sⱼ = mⱼ − m₀`.
    pub fn components<T: Copy + std::ops::Sub<Output = T>>(m: [T; ROWS]) -> [T; ROWS] {
        [m[0], m[1] - m[0], m[2] - m[0], m[3] - m[0]]
    }
}

#[cfg(test)]
mod tests {
    use super::super::transport::Interface;
    use super::super::{Mueller, Stokes, fresnel};
    use super::*;

    /// The four rows measure a Stokes vector through a chain of interfaces as the Mueller
    /// matrices of the chain (written independently, [`Mueller`]) predict, including after the
    /// rows' frames have turned with the planes of incidence.
    #[test]
    fn rows_measure_the_stokes_vector_of_a_chain() {
        let dir = Vec3::new(0.2, -0.3, -1.0).normalize();
        let mut rows = StokesRows::new(Vec3::X, dir, 1.0);
        let x_camera = rows.rows[0].x;
        let mut sensor = PathPolarisation::UNPOLARISED;
        sensor.x = x_camera;
        // Two reflections and a refraction, in different planes: (s, M, wo, wi) per event.
        let normals = [
            Vec3::new(0.3, 1.0, 0.2).normalize(),
            Vec3::new(-1.0, 0.2, 0.4).normalize(),
            Vec3::new(0.1, 0.3, 1.0).normalize(),
        ];
        let mut wo = -dir;
        let mut beta = 1.0f64;
        let mut events = vec![];
        for (i, n) in normals.iter().enumerate() {
            let n = if n.dot(wo) < 0.0 { -*n } else { *n };
            let refract = i == 2;
            let eta = 1.6f32;
            let (wi, kind, e) = if refract {
                let wi = crate::bsdf::refract(wo, n, eta).unwrap();
                (wi, Interface::Refraction, 1.0 / eta)
            } else {
                (2.0 * n * n.dot(wo) - wo, Interface::Reflection, eta)
            };
            let event = InterfaceEvent::new(n, wo, wi, [Some(e); 4], kind, sensor.x);
            let k = sensor.take(&event);
            rows.take(&event, k);
            beta *= f64::from(k[0]);
            let cos = f64::from(wi.dot(n).abs());
            let m = if refract {
                fresnel::dielectric_transmission(cos, f64::from(e)).unwrap()
            } else {
                fresnel::dielectric_reflection(cos, f64::from(e))
            };
            // The scalar code's own factor: the unpolarised Fresnel power M₀₀.
            beta *= m.0[0][0];
            events.push((n.cross(wo).normalize(), m, wo, wi));
            wo = -wi;
        }
        // A light along the last segment, in an arbitrary frame, carried to the camera.
        let light = Stokes([1.0, 0.3, -0.4, 0.5]);
        let d_last = -events.last().unwrap().3;
        let x_light = d_last.any_orthonormal_vector();
        let (mut s_now, mut x_now) = (light, x_light);
        for &(s, m, wo, wi) in events.iter().rev() {
            let r = Mueller::frame_change(x_now.as_dvec3(), s.as_dvec3(), (-wi).as_dvec3());
            s_now = m.apply(r.apply(s_now));
            x_now = s;
            let _ = wo;
        }
        let seen = Mueller::frame_change(x_now.as_dvec3(), x_camera.as_dvec3(), (-dir).as_dvec3())
            .apply(s_now);
        // The rows' readings, β · f · (row · light) in each row's frame.
        let reading = |j: usize| {
            let r = &rows.rows[j];
            let w = r.w[0];
            let sl = Mueller::frame_change(x_light.as_dvec3(), r.x.as_dvec3(), d_last.as_dvec3())
                .apply(light)
                .0;
            let m =
                sl[0] + f64::from(w[0]) * sl[1] + f64::from(w[1]) * sl[2] + f64::from(w[2]) * sl[3];
            beta * f64::from(rows.f[j][0]) * m
        };
        let s = StokesRows::components([reading(0), reading(1), reading(2), reading(3)]);
        for (c, (got, want)) in s.iter().zip(seen.0).enumerate() {
            assert!((got - want).abs() < 1e-4, "S{c}: {got} vs {want}");
        }
        // The sensor's own row is R₀: its factor stays 1.
        assert_eq!(rows.f[0][0], 1.0);
    }

    /// Settled rows no longer change: their factors are what they were at the depolarising
    /// vertex.
    #[test]
    fn settled_rows_keep_their_factors() {
        let mut rows = StokesRows::new(Vec3::X, Vec3::NEG_Z, 2.0);
        rows.depolarise();
        let before = rows;
        let event = InterfaceEvent::new(
            Vec3::Z,
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(-0.6, 0.0, 0.8),
            [Some(1.5); 4],
            Interface::Reflection,
            Vec3::X,
        );
        rows.take(&event, [0.7; 4]);
        assert_eq!(rows, before);
        assert!(rows.rows.iter().all(PathPolarisation::is_unpolarised));
        assert_eq!(rows.f, [[2.0; MAX_CHANNELS]; ROWS]);
    }
}
