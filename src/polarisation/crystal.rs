//! A camera path meeting the smooth boundary of a uniaxial or biaxial crystal ([`super::boundary`]): which
//! wave the light came from, chosen with its probability, and the path's Stokes row and
//! throughput after it.
//!
//! Inside the crystal light travels as two waves whose energy follows different rays (the
//! ordinary and the extraordinary, or a biaxial crystal's fast and slow); along one ray direction the path carries one of them, in a
//! pure linear polarisation — its electric field — so inside the crystal the row is
//! `(1, 1, 0, 0)` in the frame whose axis is that field and the path remembers the wave
//! ([`super::transport::PathPolarisation::mode`]). Waves are added incoherently, as ray optics
//! does: for a stone much thicker than the light's coherence length (a gem, not a thin section)
//! the interference between the two waves averages to the "high-order white" this gives.
//!
//! The camera path runs against the light, so the choice is made from the *adjoint* problem —
//! the boundary solved for a wave sent back along the path — whose power shares sum to one and,
//! by reciprocity (tested in [`super::boundary`]), equal the physical shares of light arriving
//! from each wave; the weights then use the physical problem's Jones amplitudes and powers, so
//! the estimate stays unbiased whatever the sampling. The physical problem needs no solve of its
//! own: a lossless, reciprocal boundary's scattering matrix between power-normalised waves is
//! symmetric (Lorentz reciprocity; Potton, "Reciprocity in optics", *Rep. Prog. Phys.* 67,
//! 2004), so what a wave sends into another is what that one, reversed, sends into the first,
//! reversed. On the isotropic side
//! a reversed wave keeps its p field and flips its s field (the s axis `normal × t` turns with
//! the tangential wave vector `t`), so the physical Jones amplitudes are the adjoint's
//! transposed with a sign on each s index, `J = D Jₐᵀ D`, `D = diag(−1, 1)` — one solve per event
//! instead of two (checked against the second solve to 10⁻⁹ in the tests).
//!
//! Radiance changes by `n_to² / n_from²` across a refraction (Veach 1997, eq. 5.12), where a
//! crystal wave's `n²` is its radiance index [`etendue::index2`] — the inverse Gaussian
//! curvature of its wave-vector surface, the exact invariant of an anisotropic medium — rather
//! than its phase index's square.

use super::boundary::{Boundary, Incident, Mode, Outgoing};
use super::etendue;
use super::optics::Optics;
use super::transport::PathPolarisation;
use glam::DVec3;
use num_complex::Complex64 as C;

/// What the boundary did to a camera path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrystalStep {
    /// The path's new direction (unit): against the light's ray.
    pub wi: DVec3,
    /// Factor of the path's throughput (Fresnel powers and Jones amplitudes measured by the
    /// row, radiance scaling, over the choice's probability).
    pub weight: f64,
    /// The choice's probability.
    pub prob: f64,
    /// Radiance index ([`etendue::index2`]'s square root) of the new segment's wave over the old
    /// one's (1 for a reflection on the outside): Russian roulette divides the radiance scaling
    /// out by its square.
    pub eta: f64,
    /// Whether the path crossed the boundary.
    pub crossed: bool,
}

/// The Stokes vector (intensity 1) of a field with Jones components `(a, b)` in an s/p frame
/// (the convention of [`super`]: `S3 = −2 Im(a b*)`).
fn stokes(a: C, b: C) -> [f64; 4] {
    let (x, y) = (a.norm_sqr(), b.norm_sqr());
    let z = a * b.conj();
    let i = (x + y).max(f64::MIN_POSITIVE);
    [1.0, (x - y) / i, 2.0 * z.re / i, -2.0 * z.im / i]
}

/// The row `(1, w)` of channel 0 as `f64`.
fn row(p: &PathPolarisation) -> [f64; 4] {
    let w = p.w[0];
    [1.0, f64::from(w[0]), f64::from(w[1]), f64::from(w[2])]
}

fn dot4(a: [f64; 4], b: [f64; 4]) -> f64 {
    a.iter().zip(&b).map(|(x, y)| x * y).sum()
}

/// The unit ray direction of a crystal wave (its energy), from its wave vector.
fn ray_of(b: &Boundary, o: &Outgoing) -> DVec3 {
    b.crystal.ray(o.wave.direction(), o.wave.mode)
}

/// The row of the pure state of the crystal's wave of `mode` along the unit `ray`: `(1, 1, 0, 0)`
/// in the frame whose axis is the wave's electric field (across the ray) — for a uniaxial crystal
/// across the plane of ray and axis for the ordinary wave, in it for the extraordinary (Born &
/// Wolf §15.3).
pub fn pure_state(crystal: &Optics, ray: DVec3, mode: Mode) -> PathPolarisation {
    let x = crystal.field(ray, mode);
    PathPolarisation {
        x: x.as_vec3(),
        w: [[1.0, 0.0, 0.0]; super::transport::MAX_CHANNELS],
        mode: Some(mode),
        // A biaxial wave's normal as the field took it (the ray alone may not name one).
        normal: match crystal {
            Optics::Biaxial(_) => crystal.wave_of_ray(ray, mode).as_vec3(),
            Optics::Uniaxial(_) => glam::Vec3::ZERO,
        },
    }
}

/// Puts the row in the pure state of a crystal wave (its field, real part, across `ray`).
fn enter_wave(p: &mut PathPolarisation, o: &Outgoing, ray: DVec3) {
    let e = DVec3::new(o.wave.e[0].re, o.wave.e[1].re, o.wave.e[2].re);
    let x = (e - ray * e.dot(ray))
        .try_normalize()
        .unwrap_or_else(|| ray.any_orthonormal_vector());
    p.x = x.as_vec3();
    p.w = [[1.0, 0.0, 0.0]; super::transport::MAX_CHANNELS];
    p.mode = Some(o.wave.mode);
    p.normal = o.wave.direction().as_vec3();
}

/// Picks index `i` of `shares` (summing to about 1) with `u ∈ [0, 1)`.
fn pick(shares: &[f64], u: f64) -> Option<usize> {
    let total: f64 = shares.iter().sum();
    let mut acc = 0.0;
    for (i, &s) in shares.iter().enumerate() {
        acc += s;
        if u * total < acc && s > 0.0 {
            return Some(i);
        }
    }
    shares.iter().rposition(|&s| s > 0.0)
}

/// A camera path outside the crystal meets it: the light leaving toward the camera along `wo`
/// (unit, `wo · b.normal > 0`) was reflected there or came out of one of the crystal's waves.
/// Updates the row `p` (channel 0; its frame about `wo`).
pub fn from_outside(
    b: &Boundary,
    wo: DVec3,
    p: &mut PathPolarisation,
    u: f64,
) -> Option<CrystalStep> {
    let n = b.normal;
    let reference = p.x.as_dvec3();
    let dir = -wo;
    // Adjoint: unpolarised light sent in along the path.
    let [s_in, p_in] = b.solve_sp(dir, reference)?;
    let share = |j: usize| 0.5 * (s_in[j].power + p_in[j].power);
    let shares = [share(0) + share(1), share(2), share(3)];
    let choice = pick(&shares, u)?;
    let prob = shares[choice] / shares.iter().sum::<f64>();
    let t = wo - n * wo.dot(n);
    let s = b.s_axis(t, reference);
    p.rotate_to(s.as_vec3(), wo.as_vec3());
    let w = row(p);
    if choice == 0 {
        // Reflection: the physical light arrived along −wi (mirror of wo); its Jones matrix
        // (columns incident s, p; the s axis is this one) is the adjoint's, transposed, in the
        // reversed waves' fields.
        let wi = 2.0 * n * n.dot(wo) - wo;
        let jones = [
            [s_in[0].amplitude, -s_in[1].amplitude],
            [-p_in[0].amplitude, p_in[1].amplitude],
        ];
        let m = super::Mueller::from_jones(jones);
        let out: [f64; 4] = std::array::from_fn(|j| (0..4).map(|i| w[i] * m.0[i][j]).sum());
        if !(out[0] > 0.0) {
            return None;
        }
        p.w[0] = [
            (out[1] / out[0]) as f32,
            (out[2] / out[0]) as f32,
            (out[3] / out[0]) as f32,
        ];
        p.x = s.as_vec3();
        p.mode = None;
        p.normal = glam::Vec3::ZERO;
        return Some(CrystalStep {
            wi,
            weight: out[0] / prob,
            prob,
            eta: 1.0,
            crossed: false,
        });
    }
    // Out of crystal wave j: the adjoint's transmitted wave, reversed.
    let j = choice + 1;
    let adj = if s_in[j].power >= p_in[j].power {
        s_in[j]
    } else {
        p_in[j]
    };
    let ray_down = ray_of(b, &adj);
    // The crystal wave, reversed, leaves as the s and p amplitudes the adjoint sent into it,
    // with the power the two sent (reciprocity, module docs).
    let t_exit = s_in[j].power + p_in[j].power;
    let st = stokes(-s_in[j].amplitude, p_in[j].amplitude);
    let measured = dot4(w, st);
    let k = DVec3::new(adj.wave.k[0].re, adj.wave.k[1].re, adj.wave.k[2].re);
    let index2 = etendue::index2(&b.crystal, k, adj.wave.mode);
    let scale = b.n1 * b.n1 / index2;
    enter_wave(p, &adj, ray_down);
    Some(CrystalStep {
        wi: ray_down,
        weight: t_exit * measured * 0.5 * scale / prob,
        prob,
        eta: index2.sqrt() / b.n1,
        crossed: true,
    })
    .filter(|c| c.weight.is_finite() && c.weight >= 0.0)
}

/// A camera path inside the crystal, travelling along the unit `dir` (`dir · b.normal > 0`),
/// meets the boundary: the light that then went down the path in its wave (the row's `mode`; a
/// path that lost its wave at a depolarising vertex picks one, each with probability ½) came in
/// from outside or was reflected from one of the two waves. `u` picks the wave (`u.0`, when
/// needed) and the event (`u.1`).
pub fn from_inside(
    b: &Boundary,
    dir: DVec3,
    p: &mut PathPolarisation,
    u: (f64, f64),
) -> Option<CrystalStep> {
    let reference = p.x.as_dvec3();
    let modes = b.crystal.modes();
    let mode = match p.mode {
        Some(m) => m,
        // (1, 0, 0, 0) = ½ (1, m_o) + ½ (1, m_e): the two waves along a ray are orthogonal.
        None if u.0 < 0.5 => modes[0],
        None => modes[1],
    };
    // The light's wave travels down along −dir; the adjoint sends it back up along dir. A
    // biaxial wave's normal is the one its boundary made, where the path knows it.
    let k_up = match b.crystal {
        Optics::Biaxial(_) if p.mode == Some(mode) && p.normal.as_dvec3().dot(dir) > 0.0 => {
            p.normal.as_dvec3().normalize()
        }
        _ => b.crystal.wave_of_ray(dir, mode),
    };
    let adj = b.solve(Incident::Inside { dir: k_up, mode }, reference)?;
    let shares = [adj[0].power + adj[1].power, adj[2].power, adj[3].power];
    let choice = pick(&shares, u.1)?;
    let prob = shares[choice] / shares.iter().sum::<f64>();
    let index_own = b.crystal.index(k_up, mode);
    let index2_own = etendue::index2(&b.crystal, index_own * k_up, mode);
    if choice == 0 {
        // In from outside along −wi: the Jones row into this wave, per unit incident power.
        let wi = if adj[0].power >= adj[1].power {
            adj[0].wave.direction()
        } else {
            adj[1].wave.direction()
        };
        // The s and p waves from outside along −wi send into this wave the amplitudes and
        // powers this wave, reversed, sends into them.
        let (a, pa) = (-adj[0].amplitude, adj[0].power);
        let (bb, pb) = (adj[1].amplitude, adj[1].power);
        // A common flux factor turns amplitudes into power-normalised ones (s and p carry the
        // same incident flux).
        let f = if a.norm_sqr() > 0.0 {
            pa / a.norm_sqr()
        } else if bb.norm_sqr() > 0.0 {
            pb / bb.norm_sqr()
        } else {
            return None;
        };
        let (ja, jb) = (a * f.sqrt(), bb * f.sqrt());
        let z = ja * jb.conj();
        let analyser = [
            0.5 * (ja.norm_sqr() + jb.norm_sqr()),
            0.5 * (ja.norm_sqr() - jb.norm_sqr()),
            z.re,
            z.im,
        ];
        if !(analyser[0] > 0.0) {
            return None;
        }
        let t = wi - b.normal * wi.dot(b.normal);
        let s = b.s_axis(t, reference);
        p.x = s.as_vec3();
        p.w[0] = [
            (analyser[1] / analyser[0]) as f32,
            (analyser[2] / analyser[0]) as f32,
            (analyser[3] / analyser[0]) as f32,
        ];
        p.mode = None;
        p.normal = glam::Vec3::ZERO;
        return Some(CrystalStep {
            wi,
            weight: 2.0 * analyser[0] * index2_own / (b.n1 * b.n1) / prob,
            prob,
            eta: b.n1 / index2_own.sqrt(),
            crossed: true,
        })
        .filter(|c| c.weight.is_finite());
    }
    // Reflected from wave k: the adjoint's reflected wave, reversed, is the light's, and it
    // reflects into this wave the power this wave reflected into it.
    let o = adj[choice + 1];
    let ray = ray_of(b, &o);
    let r = o.power;
    let k = DVec3::new(o.wave.k[0].re, o.wave.k[1].re, o.wave.k[2].re);
    let index2_k = etendue::index2(&b.crystal, k, o.wave.mode);
    enter_wave(p, &o, -ray);
    Some(CrystalStep {
        wi: ray,
        weight: r * index2_own / index2_k / prob,
        prob,
        eta: (index2_k / index2_own).sqrt(),
        crossed: false,
    })
    .filter(|c| c.weight.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polarisation::uniaxial::Uniaxial;
    use crate::sampler::Rng;

    fn calcite(axis: DVec3) -> Boundary {
        Boundary {
            crystal: Optics::Uniaxial(Uniaxial {
                no: 1.6584,
                ne: 1.4864,
                axis: axis.normalize(),
            }),
            n1: 1.0,
            normal: DVec3::Z,
        }
    }

    /// A strongly biaxial crystal (n 1.5, 1.65, 1.72) whose X axis is `axis`.
    fn strong_biaxial(axis: DVec3) -> Boundary {
        let x = axis.normalize();
        let y = x.any_orthonormal_vector();
        Boundary {
            crystal: Optics::Biaxial(crate::polarisation::biaxial::Biaxial {
                n: [1.5, 1.65, 1.72],
                axes: [x, y, x.cross(y)],
            }),
            n1: 1.0,
            normal: DVec3::Z,
        }
    }

    /// An index-matched crystal behaves as glass: from outside with an unpolarised row the
    /// expected throughput of the step is Fresnel's `R + T/η²`, summed over its choices.
    #[test]
    fn isotropic_limit_matches_the_scalar_boundary() {
        let b = Boundary {
            crystal: Optics::Uniaxial(Uniaxial {
                no: 1.5,
                ne: 1.5,
                axis: DVec3::new(0.3, 0.5, 0.8).normalize(),
            }),
            n1: 1.0,
            normal: DVec3::Z,
        };
        let cos = 0.6f64;
        let wo = DVec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
        let f = crate::bsdf::fresnel::dielectric(cos as f32, 1.5) as f64;
        let n = 20_000;
        let mut sum = 0.0;
        for i in 0..n {
            let mut p = PathPolarisation::UNPOLARISED;
            let u = (i as f64 + 0.5) / n as f64;
            if let Some(step) = from_outside(&b, wo, &mut p, u) {
                sum += step.weight;
            }
        }
        let want = f + (1.0 - f) / 2.25;
        assert!(
            (sum / n as f64 - want).abs() < 2e-3,
            "{} vs {want}",
            sum / n as f64
        );
    }

    /// The boundary's choices are drawn with the probabilities the steps report: over 12
    /// configurations (calcite and a strongly biaxial crystal in turn, random axes and
    /// directions, from outside, and from inside in each of the crystal's two waves), 30 000
    /// uniform draws each, Pearson's chi-square of the three outcomes' counts against
    /// `prob × draws` stays below its critical value at α 0.01 for the family, Šidák-adjusted
    /// over the 36 tests (2.79e-4 each: 16.37 for two degrees of freedom, 13.21 for one).
    #[test]
    fn choices_follow_their_probabilities() {
        let mut rng = Rng::new(77);
        let mut tests = 0;
        for config in 0..12 {
            let axis = DVec3::new(
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.3,
                f64::from(rng.uniform()) - 0.5,
            );
            let b = if config % 2 == 0 {
                calcite(axis)
            } else {
                strong_biaxial(axis)
            };
            let z = 0.1 + 0.85 * f64::from(rng.uniform());
            let dir = DVec3::new((1.0 - z * z).sqrt(), 0.0, z);
            for (inside, wave) in [(false, 0), (true, 0), (true, 1)] {
                // Outcome key: crossed, and the new segment's wave (None outside).
                let mut counts: Vec<((bool, Option<Mode>), f64, usize)> = vec![];
                let n = 30_000;
                for _ in 0..n {
                    let mut p = PathPolarisation::UNPOLARISED;
                    let step = if inside {
                        p.mode = Some(b.crystal.modes()[wave]);
                        from_inside(&b, dir, &mut p, (0.0, f64::from(rng.uniform())))
                    } else {
                        from_outside(&b, dir, &mut p, f64::from(rng.uniform()))
                    };
                    let Some(step) = step else { continue };
                    let key = (step.crossed, p.mode);
                    match counts.iter_mut().find(|(k, _, _)| *k == key) {
                        Some(c) => c.2 += 1,
                        None => counts.push((key, step.prob, 1)),
                    }
                }
                let total: usize = counts.iter().map(|c| c.2).sum();
                let chi2: f64 = counts
                    .iter()
                    .map(|(_, p, k)| {
                        let e = p * total as f64;
                        (*k as f64 - e).powi(2) / e
                    })
                    .sum();
                let dof = counts.len().saturating_sub(1);
                let critical = [0.0, 13.21, 16.37][dof];
                assert!(
                    chi2 < critical || dof == 0,
                    "{counts:?}: χ² {chi2} ({dof} dof)"
                );
                tests += 1;
            }
        }
        assert_eq!(tests, 36);
    }

    /// Rays come out where they should: from outside the chosen wave's ray goes into the crystal,
    /// and from inside a reflection stays inside while a crossing leaves; weights finite and ≥ 0.
    #[test]
    fn steps_go_where_their_waves_go() {
        let mut rng = Rng::new(3);
        for _ in 0..2000 {
            let axis = DVec3::new(
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.5,
            );
            let b = if rng.uniform() < 0.5 {
                calcite(axis)
            } else {
                strong_biaxial(axis)
            };
            let z = 0.05 + 0.95 * f64::from(rng.uniform());
            let phi = std::f64::consts::TAU * f64::from(rng.uniform());
            let r = (1.0 - z * z).sqrt();
            let wo = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let mut p = PathPolarisation::analyser(glam::Vec3::X, (-wo).as_vec3());
            if let Some(s) = from_outside(&b, wo, &mut p, f64::from(rng.uniform())) {
                assert!(s.weight >= 0.0 && s.weight.is_finite());
                if s.crossed {
                    assert!(s.wi.z < 0.0 && p.mode.is_some(), "{s:?}");
                    // A biaxial path carries its wave's normal, whose ray is the path's.
                    if let (Optics::Biaxial(_), Some(mode)) = (b.crystal, p.mode) {
                        let ray = b.crystal.ray(p.normal.as_dvec3().normalize(), mode);
                        assert!((ray - s.wi).length() < 1e-6, "{ray} vs {}", s.wi);
                    }
                    let mut q = p;
                    let u = (f64::from(rng.uniform()), f64::from(rng.uniform()));
                    if let Some(t) = from_inside(&b, -s.wi, &mut q, u) {
                        assert!(t.weight >= 0.0 && t.weight.is_finite());
                        assert_eq!(t.wi.z > 0.0, t.crossed, "{t:?}");
                    }
                } else {
                    assert!(s.wi.z > 0.0);
                }
            }
        }
    }
}
