//! What one interface does to the light at a vertex, computed once for every Stokes row that
//! takes it ([`super::transport::PathPolarisation::take`]): the frame (the s axis, the normal of
//! the plane of incidence) and Fresnel's Mueller matrix per channel — at a smooth dielectric
//! boundary, a bare conductor's micro-facet and a rough dielectric's micro-facet.

use super::Mueller;
use super::fresnel;
use glam::Vec3;

/// Most channels a transported value has (four hero wavelengths; three RGB channels).
pub const MAX_CHANNELS: usize = 4;

/// An interface event's kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    /// Specular reflection.
    Reflection,
    /// Specular refraction.
    Refraction,
}

/// An interface event's frame and Fresnel matrices per channel, computed once for every row that
/// takes it ([`super::transport::PathPolarisation::take`]).
#[derive(Clone, Copy, Debug)]
pub struct InterfaceEvent {
    /// The s axis (normal of the plane of incidence), the frame's axis after the event.
    pub(super) s: Vec3,
    /// The direction the light leaves along.
    pub(super) wo: Vec3,
    /// Per channel: `None` for a channel the path no longer carries, `Some(None)` where nothing
    /// passes (total internal reflection for a refraction), else the Mueller matrix.
    pub(super) m: [Option<Option<Mueller>>; MAX_CHANNELS],
}

impl InterfaceEvent {
    /// The event of [`super::transport::PathPolarisation::interface`] (same arguments); `x` is a row's current axis,
    /// which fixes the s axis at normal incidence (where every axis is one).
    pub fn new(
        n: Vec3,
        wo: Vec3,
        wi: Vec3,
        eta: [Option<f32>; MAX_CHANNELS],
        kind: Interface,
        x: Vec3,
    ) -> InterfaceEvent {
        let s = s_axis(n, wo, x);
        let cos_i = f64::from(wi.dot(n).abs()).min(1.0);
        let m = eta.map(|e| {
            e.map(|e| match kind {
                Interface::Reflection => Some(fresnel::dielectric_reflection(cos_i, f64::from(e))),
                Interface::Refraction => fresnel::dielectric_transmission(cos_i, f64::from(e)),
            })
        });
        InterfaceEvent { s, wo, m }
    }
}

impl InterfaceEvent {
    /// Reflection off a conductor's micro-facet with unit normal `h` (the half vector of `wo` and
    /// `wi`; the surface normal for a mirror): the light leaves along `wo`, arrived from `wi`,
    /// and `nk[c]` is the conductor's relative complex IOR per channel (`None`: a channel the
    /// path no longer carries). The facet's plane of incidence sets the frame, as for a rough
    /// conductor in Mitsuba 3's polarised variants (Jakob et al. 2022): a rough conductor is a
    /// mixture of mirrors, each polarising by its own Fresnel matrix.
    pub fn conductor(
        h: Vec3,
        wo: Vec3,
        wi: Vec3,
        nk: [Option<(f32, f32)>; MAX_CHANNELS],
        x: Vec3,
    ) -> InterfaceEvent {
        let s = s_axis(h, wo, x);
        let cos_i = f64::from(wi.dot(h).abs()).min(1.0);
        let m = nk.map(|v| {
            v.map(|(n, k)| {
                Some(fresnel::conductor_reflection(
                    cos_i,
                    f64::from(n),
                    f64::from(k),
                ))
            })
        });
        InterfaceEvent { s, wo, m }
    }
}

impl InterfaceEvent {
    /// Reflection or refraction at a rough dielectric's micro-facet (Walter et al. 2007): the
    /// light leaves along `wo` and arrived from `wi` (world, unit), `n` is the surface's normal
    /// (unit, the side `eta` calls above) and `eta[c]` the relative IOR below over above per
    /// channel (`None`: a channel the path no longer carries). Each channel's facet is the
    /// generalised half vector of its own index (Walter eq. 16) and polarises by its Fresnel
    /// matrix: a rough interface is a mixture of smooth ones, as a rough conductor is a mixture
    /// of mirrors in Mitsuba 3's polarised variants (Jakob et al. 2022; its polarised
    /// `roughdielectric` itself depolarises). The half vectors of every index lie in the plane
    /// of `wo` and `wi`, so the channels share one s axis (that plane's normal) and differ only
    /// in their angles. `None` when `wo` or `wi` lies in the surface.
    pub fn rough_dielectric(
        n: Vec3,
        wo: Vec3,
        wi: Vec3,
        eta: [Option<f32>; MAX_CHANNELS],
        x: Vec3,
    ) -> Option<InterfaceEvent> {
        let (co, ci) = (wo.dot(n), wi.dot(n));
        if co == 0.0 || ci == 0.0 || !(co.is_finite() && ci.is_finite()) {
            return None;
        }
        let reflect = co * ci > 0.0;
        // The facet's normal for relative index `e` (below over above).
        let half = |e: f32| {
            let etap = match (reflect, co > 0.0) {
                (true, _) => 1.0,
                (false, true) => e,
                (false, false) => 1.0 / e,
            };
            (wi * etap + wo).try_normalize()
        };
        let first = eta.iter().flatten().next().copied()?;
        let s = s_axis(half(first)?, wo, x);
        let m = eta.map(|e| {
            e.map(|e| {
                let h = half(e)?;
                let cos_i = f64::from(wi.dot(h).abs()).min(1.0);
                // The light arrives from `wi`'s side: the other side's index over its own.
                let rel = f64::from(if ci > 0.0 { e } else { 1.0 / e });
                if reflect {
                    Some(fresnel::dielectric_reflection(cos_i, rel))
                } else {
                    fresnel::dielectric_transmission(cos_i, rel)
                }
            })
        });
        Some(InterfaceEvent { s, wo, m })
    }
}

/// The s axis of an event at normal `n` with the light leaving along `wo`: the normal of the
/// plane of incidence, or a row's axis `x` (made across `wo`) at normal incidence, where every
/// axis is one.
fn s_axis(n: Vec3, wo: Vec3, x: Vec3) -> Vec3 {
    n.cross(wo).try_normalize().unwrap_or_else(|| {
        (x - wo * x.dot(wo))
            .try_normalize()
            .unwrap_or_else(|| wo.any_orthonormal_vector())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    /// Where the surface is smooth — `wo` the mirror image or the Snell refraction of `wi` —
    /// the rough interface's facet is the surface itself: its event is the smooth event's (the
    /// same plane of incidence, the matrices to the rounding of the f32 half vector), from
    /// either side, total internal reflection included; and a dispersive channel's own half
    /// vector gives it its own angle in the shared frame.
    #[test]
    fn a_facet_along_the_normal_is_the_smooth_interface() {
        let mut rng = Rng::new(7);
        let n = Vec3::Z;
        let mut checked = [0; 3];
        for _ in 0..2000 {
            let phi = std::f32::consts::TAU * rng.uniform();
            let c = 0.02 + 0.97 * rng.uniform();
            let s = (1.0 - c * c).sqrt();
            let below = rng.uniform() < 0.5;
            let z = if below { -c } else { c };
            let wi = Vec3::new(s * phi.cos(), s * phi.sin(), z);
            let eta = 1.5f32;
            let x = wi.any_orthonormal_vector();
            // The relative index the light meets: the far side's over its own.
            let rel = if below { 1.0 / eta } else { eta };
            let reflected = Vec3::new(-wi.x, -wi.y, wi.z);
            let sin_t2 = (1.0 - c * c) / (rel * rel);
            let refracted = (sin_t2 < 1.0).then(|| {
                let ct = (1.0 - sin_t2).sqrt();
                let t = -wi / rel + (c / rel - ct) * Vec3::new(0.0, 0.0, wi.z.signum());
                t.normalize()
            });
            let etas = [Some(eta), Some(1.52), None, None];
            let rough = |wo: Vec3| InterfaceEvent::rough_dielectric(n, wo, wi, etas, x).unwrap();
            let smooth_eta = [Some(if below { 1.0 / eta } else { eta }), None, None, None];
            let mut cases = vec![(reflected, Interface::Reflection)];
            if let Some(t) = refracted {
                cases.push((t, Interface::Refraction));
            }
            for (wo, kind) in cases {
                let r = rough(wo);
                let sm = InterfaceEvent::new(n, wo, wi, smooth_eta, kind, x);
                assert!(r.s.dot(sm.s).abs() > 1.0 - 1e-5, "{wi} {wo}");
                match (r.m[0].unwrap(), sm.m[0].unwrap()) {
                    (Some(a), Some(b)) => {
                        for i in 0..4 {
                            for j in 0..4 {
                                assert!(
                                    (a.0[i][j] - b.0[i][j]).abs() < 2e-4,
                                    "{kind:?} {wi} {i}{j}: {} vs {}",
                                    a.0[i][j],
                                    b.0[i][j]
                                );
                            }
                        }
                        checked[usize::from(kind == Interface::Refraction)] += 1;
                    }
                    (None, None) => unreachable!("a refraction that exists passes light"),
                    (a, b) => panic!("{kind:?} {wi}: {a:?} vs {b:?}"),
                }
                // The second channel (n 1.52) refracts with its own facet: another angle.
                if kind == Interface::Refraction
                    && let (Some(Some(a)), Some(Some(b))) = (r.m[0], r.m[1])
                    && (a.0[0][0] - b.0[0][0]).abs() > 1e-6
                {
                    checked[2] += 1;
                }
                assert!(r.m[2].is_none() && r.m[3].is_none());
            }
        }
        assert!(checked.iter().all(|&c| c > 300), "{checked:?}");
    }

    /// Hard cases: over chains of random rough-facet events — any two directions, on one side or
    /// on both, down to 10⁻⁶ of grazing, indices 1.0001–4 from either side — every correction is
    /// finite and within `[0, 2]`, every row physical, the frame across the light's new
    /// direction; where no facet exists (a direction in the surface) there is no event.
    #[test]
    fn random_rough_chains_stay_physical() {
        let mut rng = Rng::new(11);
        let mut p = crate::polarisation::transport::PathPolarisation::analyser(Vec3::X, -Vec3::Z);
        let mut wo = Vec3::Z;
        let mut events = 0;
        for i in 0..20_000 {
            let n = Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            )
            .normalize_or(Vec3::Y);
            // Mostly random, sometimes grazing to `n` within 10⁻⁶ … 10⁻².
            let mut wi = Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            )
            .normalize_or(Vec3::X);
            if i % 4 == 0 {
                let g = 10f32.powf(-6.0 + 4.0 * rng.uniform()) * (rng.uniform() - 0.5).signum();
                wi = (wi - n * wi.dot(n) + n * g).normalize();
            }
            let eta = 1.0001 + 2.9999 * rng.uniform();
            let etas = [Some(eta), Some(eta * 1.01), None, None];
            let Some(e) = InterfaceEvent::rough_dielectric(n, wo, wi, etas, p.x) else {
                assert!(wo.dot(n) == 0.0 || wi.dot(n) == 0.0, "{wo} {wi} {n}");
                continue;
            };
            let k = p.take(&e);
            for c in 0..2 {
                assert!(
                    k[c].is_finite() && (0.0..=2.0 + 1e-4).contains(&k[c]),
                    "{k:?}"
                );
                let w = p.w[c];
                assert!(w.iter().all(|v| v.is_finite()));
                assert!(
                    w[0] * w[0] + w[1] * w[1] + w[2] * w[2] <= 1.0 + 1e-3,
                    "{w:?}"
                );
            }
            assert!(
                p.x.dot(wo).abs() < 1e-3 && p.x.dot(wi).abs() < 1e-3,
                "{} {wo}",
                p.x
            );
            events += 1;
            // The light's previous segment: it arrived along −wi.
            wo = -wi;
            if p.w[0] == [0.0; 3] {
                p = crate::polarisation::transport::PathPolarisation::analyser(
                    wo.any_orthonormal_vector(),
                    -wo,
                );
            }
        }
        assert!(events > 19_000, "{events}");
    }
}
