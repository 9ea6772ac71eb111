//! A refractive index that depends on the wavelength (issue 19): the laws a recipe may give a
//! body's IOR by, for the spectral variant's dispersive refraction. Not yet read by any recipe or
//! BSDF (docs/spectral.md).
//!
//! - **Cauchy** (A. L. Cauchy, 1836): `n(λ) = A + B/λ² + C/λ⁴`, λ in µm.
//! - **Sellmeier** (W. Sellmeier, 1871; the form of glass catalogues such as Schott's):
//!   `n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ)`, λ in µm, `Cᵢ` in µm².
//! - **Abbe number**: a glass is often specified by `n_d` and `V_d = (n_d − 1)/(n_F − n_C)` at the
//!   Fraunhofer lines d (587.56 nm, helium), F (486.13 nm, hydrogen) and C (656.27 nm, hydrogen);
//!   [`Ior::from_abbe`] turns them into the two-term Cauchy law through `n_d` with that
//!   dispersion: `B = (n_d − 1) / (V_d (λ_F⁻² − λ_C⁻²))`, `A = n_d − B/λ_d²`.

/// Fraunhofer d line (helium), nm.
pub const LAMBDA_D: f32 = 587.56;
/// Fraunhofer F line (hydrogen), nm.
pub const LAMBDA_F: f32 = 486.13;
/// Fraunhofer C line (hydrogen), nm.
pub const LAMBDA_C: f32 = 656.27;

/// A refractive index as a function of the wavelength (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ior {
    /// The same index at every wavelength.
    Constant(f32),
    /// `A + B/λ² + C/λ⁴` (λ in µm; `b` in µm², `c` in µm⁴).
    Cauchy {
        /// `A`.
        a: f32,
        /// `B`, µm².
        b: f32,
        /// `C`, µm⁴.
        c: f32,
    },
    /// `n² = 1 + Σ Bᵢ λ²/(λ² − Cᵢ)` (λ in µm; `c` in µm²).
    Sellmeier {
        /// `B₁ … B₃`.
        b: [f32; 3],
        /// `C₁ … C₃`, µm².
        c: [f32; 3],
    },
}

/// A dispersive interface between a body and the medium outside it: the relative index
/// `η(λ) = n_inside(λ) / n_outside` a spectral path refracts with (the RGB variant keeps the
/// interface's `eta` at the d line).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dispersion {
    /// The body's index as a function of the wavelength.
    pub inside: Ior,
    /// The (non-dispersive) index of the medium outside.
    pub outside: f32,
}

impl Dispersion {
    /// The relative index inside / outside at `lambda_nm`.
    #[inline]
    pub fn eta_at(&self, lambda_nm: f32) -> f32 {
        self.inside.at(lambda_nm) / self.outside
    }
}

impl Ior {
    /// The two-term Cauchy law with index `n_d` at the d line and Abbe number `v_d` (module docs);
    /// `None` unless `n_d > 1` and `v_d > 0` are finite.
    pub fn from_abbe(n_d: f32, v_d: f32) -> Option<Ior> {
        if !(n_d > 1.0 && n_d.is_finite() && v_d > 0.0 && v_d.is_finite()) {
            return None;
        }
        let um = |l: f32| f64::from(l) * 1e-3;
        let inv2 = |l: f32| 1.0 / (um(l) * um(l));
        let b = (f64::from(n_d) - 1.0) / (f64::from(v_d) * (inv2(LAMBDA_F) - inv2(LAMBDA_C)));
        let a = f64::from(n_d) - b * inv2(LAMBDA_D);
        Some(Ior::Cauchy {
            a: a as f32,
            b: b as f32,
            c: 0.0,
        })
    }

    /// The index at `lambda_nm` (nm). A Sellmeier law evaluated at a resonance or where `n² < 1`
    /// gives 1 (no refraction) rather than a non-finite index; so does any law below 1.
    pub fn at(&self, lambda_nm: f32) -> f32 {
        let n = match *self {
            Ior::Sellmeier { .. } => {
                let n2 = self.n_squared(lambda_nm);
                if n2 >= 1.0 { n2.sqrt() } else { 1.0 }
            }
            _ => self.unclamped(lambda_nm),
        };
        if n.is_finite() && n >= 1.0 {
            n as f32
        } else {
            1.0
        }
    }

    /// `n²` at `lambda_nm` (nm) as the law gives it, without [`Ior::at`]'s clamping: for a
    /// Sellmeier law `1 + Σ Bᵢ λ²/(λ² − Cᵢ)` itself, which is below 1 (even below 0: no real
    /// index) short of a resonance and not finite at one (`λ² = Cᵢ`); for the others the square
    /// of their index.
    pub fn n_squared(&self, lambda_nm: f32) -> f64 {
        match *self {
            Ior::Sellmeier { b, c } => {
                let l = f64::from(lambda_nm) * 1e-3;
                let l2 = l * l;
                1.0 + (0..3)
                    .map(|i| f64::from(b[i]) * l2 / (l2 - f64::from(c[i])))
                    .sum::<f64>()
            }
            _ => self.unclamped(lambda_nm).powi(2),
        }
    }

    /// The index of a constant or Cauchy law at `lambda_nm`, unclamped (a Sellmeier law: the
    /// root of its `n²`, NaN below 0).
    fn unclamped(&self, lambda_nm: f32) -> f64 {
        let l = f64::from(lambda_nm) * 1e-3;
        let l2 = l * l;
        match *self {
            Ior::Constant(n) => f64::from(n),
            Ior::Cauchy { a, b, c } => f64::from(a) + f64::from(b) / l2 + f64::from(c) / (l2 * l2),
            Ior::Sellmeier { .. } => self.n_squared(lambda_nm).sqrt(),
        }
    }

    /// The Abbe number `(n_d − 1)/(n_F − n_C)`; infinite for a constant index.
    pub fn abbe(&self) -> f32 {
        let spread = self.at(LAMBDA_F) - self.at(LAMBDA_C);
        (self.at(LAMBDA_D) - 1.0) / spread
    }

    /// Whether the index changes with the wavelength.
    pub fn is_dispersive(&self) -> bool {
        match *self {
            Ior::Constant(_) => false,
            Ior::Cauchy { b, c, .. } => b != 0.0 || c != 0.0,
            Ior::Sellmeier { .. } => self.at(LAMBDA_F) != self.at(LAMBDA_C),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Schott N-BK7, Sellmeier coefficients and catalogue values n_d = 1.51680, V_d = 64.17
    /// (SCHOTT optical glass data sheet N-BK7, 2014).
    const BK7: Ior = Ior::Sellmeier {
        b: [1.039_612, 0.231_792_34, 1.010_469_5],
        c: [0.006_000_699, 0.020_017_914, 103.560_65],
    };

    #[test]
    fn sellmeier_gives_the_catalogue_index_and_abbe_number() {
        assert!(
            (BK7.at(LAMBDA_D) - 1.5168).abs() < 5e-5,
            "{}",
            BK7.at(LAMBDA_D)
        );
        assert!((BK7.abbe() - 64.17).abs() < 0.05, "{}", BK7.abbe());
        // Normal dispersion: blue bends more than red.
        assert!(BK7.at(450.0) > BK7.at(550.0) && BK7.at(550.0) > BK7.at(700.0));
        assert!(BK7.is_dispersive());
    }

    #[test]
    fn abbe_number_round_trips_through_cauchy() {
        for (n_d, v_d) in [(1.5168f32, 64.17f32), (2.417, 55.3), (1.7, 20.0)] {
            let ior = Ior::from_abbe(n_d, v_d).expect("valid");
            assert!((ior.at(LAMBDA_D) - n_d).abs() < 1e-5, "{n_d}");
            assert!(
                (ior.abbe() - v_d).abs() < 1e-2 * v_d,
                "{v_d}: {}",
                ior.abbe()
            );
            assert!(ior.is_dispersive());
        }
        for (n_d, v_d) in [
            (1.0f32, 50.0f32),
            (1.5, 0.0),
            (f32::NAN, 50.0),
            (1.5, f32::INFINITY),
        ] {
            assert_eq!(Ior::from_abbe(n_d, v_d), None, "{n_d} {v_d}");
        }
    }

    #[test]
    fn constant_and_degenerate_laws_stay_finite() {
        assert_eq!(Ior::Constant(1.55).at(400.0), 1.55);
        assert!(!Ior::Constant(1.55).is_dispersive());
        assert!(Ior::Constant(1.55).abbe().is_infinite());
        // At a Sellmeier resonance (λ² = C) or below it where n² < 1: 1, not NaN or infinity.
        let resonant = Ior::Sellmeier {
            b: [1.0, 0.0, 0.0],
            c: [0.25, 0.0, 0.0],
        };
        for l in [500.0f32, 499.9, 400.0, 0.0, f32::NAN] {
            let n = resonant.at(l);
            assert!(n.is_finite() && n >= 1.0, "{l}: {n}");
        }
    }

    #[test]
    fn n_squared_is_the_law_itself_where_the_index_is_clamped() {
        // BK7 at the d line: the square of its index.
        let n = f64::from(BK7.at(LAMBDA_D));
        assert!((BK7.n_squared(LAMBDA_D) - n * n).abs() < 1e-5);
        // B = 1, C = 0.25 µm² at 400 nm: 1 + 0.16/(0.16 − 0.25) = −7/9, below 0; at the
        // resonance (500 nm) not finite; at 360 nm with B = 0.5: 1 − 0.0648/0.1204 ≈ 0.462.
        let resonant = |b: f32| Ior::Sellmeier {
            b: [b, 0.0, 0.0],
            c: [0.25, 0.0, 0.0],
        };
        assert!((resonant(1.0).n_squared(400.0) + 7.0 / 9.0).abs() < 1e-6);
        assert!(!resonant(1.0).n_squared(500.0).is_finite());
        let n2 = resonant(0.5).n_squared(360.0);
        assert!((n2 - (1.0 - 0.5 * 0.1296 / 0.1204)).abs() < 1e-6, "{n2}");
        assert_eq!(resonant(0.5).at(360.0), 1.0);
        let cauchy = Ior::Cauchy {
            a: 0.5,
            b: 0.1,
            c: 0.0,
        };
        assert!((cauchy.n_squared(1000.0) - 0.36).abs() < 1e-6);
    }
}
