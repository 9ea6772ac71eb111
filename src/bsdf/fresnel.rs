//! Fresnel reflectance: exact dielectric and conductor equations, the approximations studied by the
//! course (§3.4.1: Schlick, Lazányi–Szirmay-Kalos, a 1024-entry per-material table), and measured
//! metal presets.
//!
//! Every evaluation takes the **signed** cosine between the incident direction and the (micro-)normal
//! of the interface: positive when the light arrives from the side the normal points into (outside,
//! IOR 1 relative), negative when it arrives from inside (relative IOR inverted; total internal
//! reflection returns 1). Conductors ignore the sign.

use crate::color::Rgb;
use crate::spectrum::RgbSample;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Exact unpolarised Fresnel reflectance of a dielectric interface (Born & Wolf, §1.5.2).
///
/// # Arguments
/// * `cos_i` – signed cosine of the incident angle with the interface normal (see module docs).
/// * `eta` – relative IOR, inside / outside.
#[inline]
pub fn dielectric(cos_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (r_par * r_par + r_perp * r_perp)).clamp(0.0, 1.0)
}

/// Exact unpolarised Fresnel reflectance of a conductor with complex relative IOR `n + i k`, for one
/// channel. Computed in `f64` complex arithmetic, stable for `k ≫ n` and at grazing incidence
/// (at `cos_i = 0` both amplitude ratios have modulus exactly 1).
#[inline]
pub fn conductor(cos_i: f32, n: f32, k: f32) -> f32 {
    let c = f64::from(cos_i.abs().min(1.0));
    let (n, k) = (f64::from(n), f64::from(k));
    // η² = (n² − k²) + i 2nk ; sin²θt·η² = sin²θi, so η cosθt = sqrt(η² − sin²θi).
    let s2 = 1.0 - c * c;
    let (er, ei) = (n * n - k * k - s2, 2.0 * n * k);
    let m = (er * er + ei * ei).sqrt();
    let a = (0.5 * (m + er)).max(0.0).sqrt(); // Re sqrt(η² − sin²θ)
    let b = (0.5 * (m - er)).max(0.0).sqrt(); // Im sqrt(η² − sin²θ)
    // r⊥ = (cosθ − (a+ib)) / (cosθ + (a+ib))
    // At grazing incidence with a real, index-matched medium both denominators vanish; the limit
    // of either ratio is 1 there, as for every interface at grazing.
    let den_s = (c + a).powi(2) + b * b;
    let rs = if den_s > 0.0 {
        ((c - a).powi(2) + b * b) / den_s
    } else {
        1.0
    };
    // r∥ = (η² cosθ − (a+ib)) / (η² cosθ + (a+ib)), with η² = (n²−k²) + i 2nk
    let (pr, pi) = ((n * n - k * k) * c, 2.0 * n * k * c);
    let num = (pr - a).powi(2) + (pi - b).powi(2);
    let den = (pr + a).powi(2) + (pi + b).powi(2);
    let rp = if den > 0.0 { num / den } else { 1.0 };
    let f = 0.5 * (rs + rp);
    if f.is_finite() {
        f.clamp(0.0, 1.0) as f32
    } else {
        1.0
    }
}

/// Schlick's approximation `R0 + (1 − R0)(1 − cos)^5` (Schlick 1994, "An inexpensive BRDF model for
/// physically-based rendering"), with the transmitted cosine used from the denser side so that total
/// internal reflection is kept.
#[inline]
pub fn schlick_dielectric(cos_i: f32, eta: f32) -> f32 {
    let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let c = if cos_i >= 0.0 {
        cos_i.min(1.0)
    } else {
        // From inside: use the outside angle, or TIR.
        let sin2_t = (1.0 - cos_i * cos_i) * eta * eta;
        if sin2_t >= 1.0 {
            return 1.0;
        }
        (1.0 - sin2_t).sqrt()
    };
    r0 + (1.0 - r0) * (1.0 - c).powi(5)
}

/// Lazányi & Szirmay-Kalos's approximation for metals (course ref. \[23\], WSCG 2005, eq. 6 without
/// the fitted correction term): `((n−1)² + 4n(1−cos)^5 + k²) / ((n+1)² + k²)`.
#[inline]
pub fn lazanyi(cos_i: f32, n: f32, k: f32) -> f32 {
    let c = cos_i.abs().min(1.0);
    (((n - 1.0).powi(2) + 4.0 * n * (1.0 - c).powi(5) + k * k) / ((n + 1.0).powi(2) + k * k))
        .clamp(0.0, 1.0)
}

/// How a material evaluates Fresnel reflectance (course §3.4.1). Never chosen silently: the default
/// is `Exact`, the rest exist for the accuracy-versus-time study.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FresnelMode {
    /// The exact equations.
    #[default]
    Exact,
    /// Schlick's approximation (dielectrics and, with `R0` from `n, k`, conductors).
    Schlick,
    /// Lazányi–Szirmay-Kalos (conductors; for dielectrics the same formula with `k = 0`).
    Lazanyi,
    /// A 1024-entry table over `cos θ` per side, built once per material from the exact equations
    /// and linearly interpolated.
    Table,
}

/// Entries per side of a [`FresnelTable`].
pub const TABLE_SIZE: usize = 1024;

/// The course's per-material 1-D Fresnel table (§3.4.1), indexed by `|cos θ|` uniformly; dielectrics
/// keep one row for light from outside and one from inside (total internal reflection).
#[derive(Debug, PartialEq)]
pub struct FresnelTable {
    outside: Vec<RgbSample>,
    inside: Vec<RgbSample>,
}

impl FresnelTable {
    fn build(exact: &Fresnel) -> Self {
        let row = |sign: f32| {
            (0..TABLE_SIZE)
                .map(|i| exact.eval(sign * i as f32 / (TABLE_SIZE - 1) as f32))
                .collect::<Vec<_>>()
        };
        FresnelTable {
            outside: row(1.0),
            inside: row(-1.0),
        }
    }

    #[inline]
    fn lookup(&self, cos_i: f32) -> RgbSample {
        let row = if cos_i >= 0.0 {
            &self.outside
        } else {
            &self.inside
        };
        let x = (cos_i.abs().min(1.0)) * (TABLE_SIZE - 1) as f32;
        let i = (x as usize).min(TABLE_SIZE - 2);
        let t = x - i as f32;
        row[i] * (1.0 - t) + row[i + 1] * t
    }
}

/// A Fresnel evaluator bound to one interface, with its approximation chosen.
#[derive(Clone, Debug, PartialEq)]
pub enum Fresnel {
    /// Exact dielectric with relative IOR `eta` (inside / outside).
    Dielectric {
        /// Relative IOR.
        eta: f32,
    },
    /// Exact conductor, complex relative IOR per channel.
    Conductor {
        /// Real part per channel.
        n: RgbSample,
        /// Imaginary part (extinction) per channel.
        k: RgbSample,
    },
    /// A perfect mirror: reflectance 1 at every angle.
    Perfect,
    /// Schlick's approximation for a dielectric.
    SchlickDielectric {
        /// Relative IOR.
        eta: f32,
    },
    /// Schlick's approximation for a conductor, `R0` from `n, k`.
    SchlickConductor {
        /// Normal-incidence reflectance per channel.
        r0: RgbSample,
    },
    /// Lazányi–Szirmay-Kalos.
    Lazanyi {
        /// Real part per channel.
        n: RgbSample,
        /// Imaginary part per channel.
        k: RgbSample,
    },
    /// A precomputed table of one of the exact forms.
    Table(Arc<FresnelTable>),
}

impl Fresnel {
    /// The relative complex IOR `n + i k` of channel `c` of a conductor whose form keeps it (the
    /// exact equations and Lazányi–Szirmay-Kalos); `None` for a dielectric, the perfect mirror,
    /// Schlick's `R₀` and a table, which keep only reflectances. Polarised transport reads it
    /// (Fresnel's Mueller matrix needs the amplitudes).
    pub fn complex_ior(&self, c: usize) -> Option<(f32, f32)> {
        match self {
            Fresnel::Conductor { n, k } | Fresnel::Lazanyi { n, k } => Some((n[c], k[c])),
            _ => None,
        }
    }

    /// A dielectric interface with the given relative IOR, evaluated in `mode`.
    pub fn dielectric(eta: f32, mode: FresnelMode) -> Self {
        let exact = Fresnel::Dielectric { eta };
        match mode {
            FresnelMode::Exact => exact,
            FresnelMode::Schlick => Fresnel::SchlickDielectric { eta },
            FresnelMode::Lazanyi => Fresnel::Lazanyi {
                n: RgbSample::splat(eta),
                k: RgbSample::ZERO,
            },
            FresnelMode::Table => Fresnel::Table(Arc::new(FresnelTable::build(&exact))),
        }
    }

    /// A conductor with complex relative IOR `n + i k`, evaluated in `mode`.
    pub fn conductor(n: RgbSample, k: RgbSample, mode: FresnelMode) -> Self {
        let exact = Fresnel::Conductor { n, k };
        match mode {
            FresnelMode::Exact => exact,
            FresnelMode::Schlick => Fresnel::SchlickConductor {
                r0: n.zip(k, |n, k| {
                    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
                }),
            },
            FresnelMode::Lazanyi => Fresnel::Lazanyi { n, k },
            FresnelMode::Table => Fresnel::Table(Arc::new(FresnelTable::build(&exact))),
        }
    }

    /// Reflectance for the signed cosine `cos_i` (see the module docs).
    #[inline]
    pub fn eval(&self, cos_i: f32) -> RgbSample {
        match self {
            Fresnel::Dielectric { eta } => RgbSample::splat(dielectric(cos_i, *eta)),
            Fresnel::Conductor { n, k } => RgbSample([
                conductor(cos_i, n[0], k[0]),
                conductor(cos_i, n[1], k[1]),
                conductor(cos_i, n[2], k[2]),
            ]),
            Fresnel::Perfect => RgbSample::ONE,
            Fresnel::SchlickDielectric { eta } => RgbSample::splat(schlick_dielectric(cos_i, *eta)),
            Fresnel::SchlickConductor { r0 } => {
                let w = (1.0 - cos_i.abs().min(1.0)).powi(5);
                *r0 + (RgbSample::ONE - *r0) * w
            }
            Fresnel::Lazanyi { n, k } => {
                if cos_i < 0.0 && k.is_black() {
                    // A dielectric seen from inside: same formula at the outside angle, or TIR.
                    RgbSample::splat(schlick_like_inside(cos_i, n[0]))
                } else {
                    RgbSample([
                        lazanyi(cos_i, n[0], k[0]),
                        lazanyi(cos_i, n[1], k[1]),
                        lazanyi(cos_i, n[2], k[2]),
                    ])
                }
            }
            Fresnel::Table(t) => t.lookup(cos_i),
        }
    }
}

fn schlick_like_inside(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = (1.0 - cos_i * cos_i) * eta * eta;
    if sin2_t >= 1.0 {
        return 1.0;
    }
    lazanyi((1.0 - sin2_t).sqrt(), eta, 0.0)
}

/// Metal presets: measured complex IOR `n + i k`, integrated from spectral tables to RGB
/// (see [`Metal::nk`] and docs/metals.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Metal {
    /// Gold (Au).
    Gold,
    /// Silver (Ag).
    Silver,
    /// Copper (Cu).
    Copper,
    /// Aluminium (Al).
    Aluminium,
    /// Brass (Cu-Zn).
    Brass,
}

impl Metal {
    /// Every preset, for listings and tests.
    pub const ALL: [Metal; 5] = [
        Metal::Gold,
        Metal::Silver,
        Metal::Copper,
        Metal::Aluminium,
        Metal::Brass,
    ];

    /// `(n, k)` per channel, relative to vacuum.
    ///
    /// Each channel is the spectral `n(λ)` or `k(λ)` integrated as Mitsuba 3's RGB variants
    /// integrate an unbounded spectrum: over 360–830 nm against the CIE 1931 2° colour-matching
    /// functions (CIE 015:2018), divided by `∫ȳ`, with no illuminant, then XYZ → linear Rec.709.
    /// Derived by `scripts/metal-presets.py` (which prints these arms with `--rust`) from the
    /// tables in `data/metals/`, rounded to four decimals:
    ///
    /// * gold, silver, copper — P. B. Johnson & R. W. Christy, "Optical constants of the noble
    ///   metals", Phys. Rev. B 6, 4370 (1972);
    /// * aluminium — A. D. Rakić, "Algorithm for the determination of intrinsic optical constants
    ///   of metal films: application to aluminum", Appl. Opt. 34, 4755 (1995);
    /// * brass (70 % Cu, 30 % Zn) — M. R. Querry, "Optical constants", Contractor Report
    ///   CRDC-CR-85034 (1985).
    ///
    /// The method, the tables' provenance and the old point-sampled presets are compared in
    /// docs/metals.md; the normal-incidence reflectance of each preset is pinned in the tests.
    pub fn nk(self) -> (Rgb, Rgb) {
        match self {
            Metal::Gold => (
                Rgb::new(0.1263, 0.4660, 1.3429),
                Rgb::new(4.2406, 2.2091, 1.6454),
            ),
            Metal::Silver => (
                Rgb::new(0.0666, 0.0519, 0.0388),
                Rgb::new(5.1845, 3.3534, 2.3041),
            ),
            Metal::Copper => (
                Rgb::new(0.2810, 0.9871, 1.1795),
                Rgb::new(3.9229, 2.4598, 2.1389),
            ),
            Metal::Aluminium => (
                Rgb::new(1.7449, 0.9330, 0.5324),
                Rgb::new(9.1212, 6.2184, 4.8235),
            ),
            Metal::Brass => (
                Rgb::new(0.5198, 0.4885, 1.0417),
                Rgb::new(4.3312, 2.5481, 1.5914),
            ),
        }
    }

    /// Lower-case name as used in recipes.
    pub fn name(self) -> &'static str {
        match self {
            Metal::Gold => "gold",
            Metal::Silver => "silver",
            Metal::Copper => "copper",
            Metal::Aluminium => "aluminium",
            Metal::Brass => "brass",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_known_values() {
        // Normal incidence: ((η−1)/(η+1))².
        assert!((dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        // Brewster angle: parallel component vanishes, F = r⊥²/2.
        let tb = 1.5f32.atan();
        let f = dielectric(tb.cos(), 1.5);
        let ct = (1.0 - tb.sin().powi(2) / 2.25).sqrt();
        let rs = (tb.cos() - 1.5 * ct) / (tb.cos() + 1.5 * ct);
        assert!((f - 0.5 * rs * rs).abs() < 1e-5);
        // Grazing → 1, TIR from inside → 1, index-matched → 0.
        assert!((dielectric(1e-7, 1.5) - 1.0).abs() < 1e-5);
        assert_eq!(dielectric(-0.3, 1.5), 1.0);
        assert!(dielectric(0.7, 1.0).abs() < 1e-7);
    }

    #[test]
    fn dielectric_reciprocal_across_interface() {
        // F from outside at θi equals F from inside at θt (Stokes relations).
        for i in 1..89 {
            let ci = (i as f32).to_radians().cos();
            let st = (1.0 - ci * ci).sqrt() / 1.7;
            let ct = (1.0 - st * st).sqrt();
            assert!((dielectric(ci, 1.7) - dielectric(-ct, 1.7)).abs() < 1e-5);
        }
    }

    #[test]
    fn conductor_limits() {
        // k = 0 reduces to the dielectric equations.
        for i in 0..90 {
            let c = (i as f32).to_radians().cos();
            assert!(
                (conductor(c, 1.5, 0.0) - dielectric(c, 1.5)).abs() < 1e-5,
                "{i}"
            );
        }
        // Normal incidence closed form.
        let (n, k) = (0.2f32, 3.0f32);
        let r0 = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!((conductor(1.0, n, k) - r0).abs() < 1e-6);
        // Grazing and k ≫ n stay finite and in [0, 1].
        for &(n, k) in &[(0.05, 10.0), (4.0, 10.0), (0.01, 0.0)] {
            for &c in &[0.0, 1e-7, 0.5, 1.0] {
                let f = conductor(c, n, k);
                assert!((0.0..=1.0).contains(&f) && f.is_finite());
            }
            assert!((conductor(0.0, n, k) - 1.0).abs() < 1e-6);
        }
        // Index-matched and real (n = 1, k = 0): finite everywhere, 1 at grazing.
        assert_eq!(conductor(0.0, 1.0, 0.0), 1.0);
        assert_eq!(conductor(-0.0, 1.0, 0.0), 1.0);
        assert!(conductor(0.5, 1.0, 0.0).abs() < 1e-7);
    }

    #[test]
    fn presets_reflect_like_metals() {
        // Normal-incidence reflectance of each preset as docs/metals.md tabulates it
        // (`scripts/metal-presets.py`, column "new"); gold's blue (0.345) is the darkest channel.
        let expected = [
            (Metal::Gold, [0.974, 0.735, 0.345]),
            (Metal::Silver, [0.990, 0.983, 0.976]),
            (Metal::Copper, [0.934, 0.605, 0.494]),
            (Metal::Aluminium, [0.923, 0.912, 0.917]),
            (Metal::Brass, [0.901, 0.776, 0.378]),
        ];
        assert_eq!(expected.map(|(m, _)| m), Metal::ALL);
        for (m, r0) in expected {
            let (n, k) = m.nk();
            let f = Fresnel::conductor(n.into(), k.into(), FresnelMode::Exact).eval(1.0);
            assert!(
                f.min_channel() > 0.3 && f.max_channel() < 1.0,
                "{m:?} {f:?}"
            );
            for c in 0..3 {
                assert!(
                    (f[c] - r0[c]).abs() < 6e-4,
                    "{m:?} channel {c}: {f:?} vs {r0:?}"
                );
            }
        }
        let gold = Fresnel::conductor(
            Metal::Gold.nk().0.into(),
            Metal::Gold.nk().1.into(),
            FresnelMode::Exact,
        )
        .eval(1.0);
        assert!(
            gold[0] > gold[1] && gold[1] > gold[2],
            "gold is yellow: {gold:?}"
        );
        let silver = Fresnel::conductor(
            Metal::Silver.nk().0.into(),
            Metal::Silver.nk().1.into(),
            FresnelMode::Exact,
        )
        .eval(1.0);
        assert!(silver.min_channel() > 0.95);
    }

    #[test]
    fn approximations_track_exact() {
        let (n, k) = Metal::Gold.nk();
        let exact = Fresnel::conductor(n.into(), k.into(), FresnelMode::Exact);
        for mode in [
            FresnelMode::Schlick,
            FresnelMode::Lazanyi,
            FresnelMode::Table,
        ] {
            let approx = Fresnel::conductor(n.into(), k.into(), mode);
            let mut worst = 0.0f32;
            for i in 0..=1000 {
                let c = i as f32 / 1000.0;
                let d = (approx.eval(c) - exact.eval(c)).map(f32::abs).max_channel();
                worst = worst.max(d);
            }
            let bound = if mode == FresnelMode::Table {
                1e-4
            } else {
                0.12
            };
            assert!(worst < bound, "{mode:?}: {worst}");
        }
        let exact = Fresnel::dielectric(1.5, FresnelMode::Exact);
        for mode in [
            FresnelMode::Schlick,
            FresnelMode::Lazanyi,
            FresnelMode::Table,
        ] {
            let approx = Fresnel::dielectric(1.5, mode);
            for i in -1000..=1000 {
                let c = i as f32 / 1000.0;
                let d = (approx.eval(c)[0] - exact.eval(c)[0]).abs();
                // The table's linear interpolation rounds the total-internal-reflection knee
                // (cos = −0.745 for η 1.5) over one entry.
                let knee = (c + (1.0f32 - 1.0 / 2.25).sqrt()).abs() < 2.0 / 1023.0;
                let bound = match mode {
                    FresnelMode::Table if knee => 0.05,
                    FresnelMode::Table => 2e-3,
                    _ => 0.15,
                };
                assert!(d < bound, "{mode:?} cos {c}: {d}");
            }
        }
    }
}
