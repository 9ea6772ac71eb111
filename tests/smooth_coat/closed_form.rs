//! The closed form of a smooth coat over a Lambert base, in f64, copied from
//! tests/adding/closed_form.rs (derivation and self-consistency tests in
//! tests/reference_closed_form.rs):
//!
//! ```text
//!   A(μo) = F(μo) + (1 − F(μo)) · τ(μ'o) · ρ · E_out / (1 − ρ · E_back)
//!   E_out  = ∫₀¹ 2μ τ(μ) (1 − F_in(μ)) dμ,   E_back = ∫₀¹ 2μ τ(μ)² F_in(μ) dμ,   τ(μ) = exp(−od/μ)
//! ```
//!
//! The integrals use composite 32-point Gauss–Legendre on 8 panels, split at the critical cosine
//! (converged to 1e-13, tests/reference_closed_form.rs).

use std::sync::OnceLock;

/// Exact unpolarised Fresnel reflectance, signed cosine (negative: from inside).
pub fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let (c, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    let c = c.min(1.0);
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - sin2_t).sqrt();
    let rp = (eta * c - ct) / (eta * c + ct);
    let rs = (c - eta * ct) / (c + eta * ct);
    0.5 * (rp * rp + rs * rs)
}

/// Nodes and weights of `n`-point Gauss–Legendre on [−1, 1] (Newton on the Legendre recurrence).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// `∫ₐᵇ f` by composite 32-point Gauss–Legendre on 8 equal panels.
fn integrate(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    static NODES: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    let nodes = NODES.get_or_init(|| gauss_legendre(32));
    let panels = 8;
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for &(x, w) in nodes {
            sum += w * 0.5 * h * f(mid + 0.5 * h * x);
        }
    }
    sum
}

/// One leg through the varnish at inner cosine `mu`.
fn tau(od: f64, mu: f64) -> f64 {
    if od == 0.0 {
        1.0
    } else if mu <= 0.0 {
        0.0
    } else {
        (-od / mu).exp()
    }
}

/// `(E_out, E_back)`: up through the varnish and out; up, reflected, down again. Split at the
/// critical cosine, with `μ = μc + (1 − μc) t²` above it (smooth in `t`).
fn inner_integrals(eta: f64, od: f64) -> (f64, f64) {
    let mu_c = (1.0 - 1.0 / (eta * eta)).sqrt();
    let f_in = |mu: f64| fresnel(-mu, eta);
    let mut e_back = integrate(0.0, mu_c, |mu| 2.0 * mu * tau(od, mu).powi(2) * f_in(mu));
    let mut e_out = integrate(0.0, mu_c, |mu| 2.0 * mu * tau(od, mu) * (1.0 - f_in(mu)));
    let span = 1.0 - mu_c;
    e_back += integrate(0.0, 1.0, |t| {
        let mu = mu_c + span * t * t;
        2.0 * mu * tau(od, mu).powi(2) * f_in(mu) * 2.0 * span * t
    });
    e_out += integrate(0.0, 1.0, |t| {
        let mu = mu_c + span * t * t;
        2.0 * mu * tau(od, mu) * (1.0 - f_in(mu)) * 2.0 * span * t
    });
    (e_out, e_back)
}

/// `F(μo) + (1 − F(μo)) τ(μ'o) ρ E_out / (1 − ρ E_back)`.
pub fn closed_form(eta: f64, od: f64, rho: f64, mu_o: f64) -> f64 {
    let f = fresnel(mu_o, eta);
    let mu_t = (1.0 - (1.0 - mu_o * mu_o) / (eta * eta)).max(0.0).sqrt();
    let (e_out, e_back) = inner_integrals(eta, od);
    f + (1.0 - f) * tau(od, mu_t) * rho * e_out / (1.0 - rho * e_back)
}
