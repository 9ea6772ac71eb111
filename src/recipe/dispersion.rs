//! A translucent body's dispersion: how its index changes with the wavelength (Abbe number,
//! Cauchy or Sellmeier law), checked over the visible range.

use crate::bsdf::dispersion::{Ior, LAMBDA_D};
use serde::{Deserialize, Serialize};

/// A body's dispersion law (the index at the d line, 587.56 nm, is the body's `ior`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum DispersionDesc {
    /// Abbe number `V_d = (n_d − 1)/(n_F − n_C)`, 5 ..= 200 (a two-term Cauchy law through `ior`).
    Abbe(f32),
    /// `n(λ) = A + B/λ² + C/λ⁴` (λ in µm) with `A` chosen so that `n(587.56 nm) = ior`.
    Cauchy {
        /// `B`, µm², 0 ..= 0.1.
        b: f32,
        /// `C`, µm⁴, 0 ..= 0.01 (default 0).
        #[serde(default)]
        c: f32,
    },
    /// `n² = 1 + Σ Bᵢ λ²/(λ² − Cᵢ)` (λ in µm; `Cᵢ` in µm²): its index at 587.56 nm must equal
    /// `ior` within 0.001.
    Sellmeier {
        /// `B₁, B₂, B₃`, each 0 ..= 10.
        b: (f32, f32, f32),
        /// `C₁, C₂, C₃`, µm², each 0 ..= 1000.
        c: (f32, f32, f32),
    },
}

impl DispersionDesc {
    /// The index as a function of the wavelength of a body whose index at the d line is `ior`,
    /// or what is wrong with the law (every visible wavelength must see an index in
    /// `1 <.. n_max`).
    pub fn law(self, ior: f32, n_max: f32) -> Result<Ior, String> {
        self.law_of("body.dispersion", ior, n_max)
    }

    /// [`DispersionDesc::law`] of the index the recipe names `what` (its errors begin with it:
    /// `body.dispersion`, `body.crystal.ne_dispersion`, …), whose value at the d line is `ior`.
    pub fn law_of(self, what: &str, ior: f32, n_max: f32) -> Result<Ior, String> {
        let law = match self {
            DispersionDesc::Abbe(v) => {
                if !(5.0..=200.0).contains(&v) {
                    return Err(format!(
                        "{what}: Abbe number {v} is out of range: allowed 5 ..= 200"
                    ));
                }
                Ior::from_abbe(ior, v).ok_or_else(|| format!("{what}: Abbe needs an index > 1"))?
            }
            DispersionDesc::Cauchy { b, c } => {
                if !(0.0..=0.1).contains(&b) || !(0.0..=0.01).contains(&c) {
                    return Err(format!(
                        "{what}: Cauchy b {b} µm², c {c} µm⁴ out of range: allowed \
                         b 0 ..= 0.1, c 0 ..= 0.01"
                    ));
                }
                let l2 = (LAMBDA_D * 1e-3).powi(2);
                Ior::Cauchy {
                    a: ior - b / l2 - c / (l2 * l2),
                    b,
                    c,
                }
            }
            DispersionDesc::Sellmeier { b, c } => {
                let (b, c) = ([b.0, b.1, b.2], [c.0, c.1, c.2]);
                if b.iter().any(|v| !(0.0..=10.0).contains(v))
                    || c.iter().any(|v| !(0.0..=1000.0).contains(v))
                {
                    return Err(format!(
                        "{what}: Sellmeier b {b:?}, c {c:?} out of range: allowed \
                         each B 0 ..= 10, each C 0 ..= 1000 µm²"
                    ));
                }
                let law = Ior::Sellmeier { b, c };
                let n_d = law.at(LAMBDA_D);
                if (n_d - ior).abs() > 1e-3 {
                    return Err(format!(
                        "{what}: the Sellmeier law gives {n_d:.5} at 587.56 nm but the index \
                         it describes is {ior} there: they must agree within 0.001"
                    ));
                }
                law
            }
        };
        // Every visible wavelength must see a proper index (no resonance, 1 < n ≤ 4). The law's
        // own n² is reported where its index would be clamped (`Ior::at` gives 1 there).
        let allowed = format!("allowed 1 <.. {n_max} over 360 ..= 830 nm");
        for l in (360..=830).step_by(5) {
            let n2 = law.n_squared(l as f32);
            if !n2.is_finite() {
                return Err(format!(
                    "{what}: the law has a resonance at {l} nm (n² is not finite): \
                     {allowed}"
                ));
            }
            if n2 < 0.0 {
                return Err(format!(
                    "{what}: the law gives n² = {n2:.4} < 0 at {l} nm: it has no real \
                     index there; {allowed}"
                ));
            }
            if n2 < 1.0 {
                return Err(format!(
                    "{what}: the law gives n² = {n2:.4} < 1 (n = {:.4}) at {l} nm: \
                     {allowed}",
                    n2.sqrt()
                ));
            }
            let n = law.at(l as f32);
            if !(n > 1.0 && n <= n_max) {
                return Err(format!(
                    "{what}: the law gives n = {n} at {l} nm: {allowed}"
                ));
            }
        }
        Ok(law)
    }
}
