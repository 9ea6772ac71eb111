//! The four complex roots of a real quartic, for the biaxial boundary ([`super::biaxial`]), whose
//! waves' normal components solve one.
//!
//! [`factored`] splits it into two real quadratics by Bairstow's method from the boundary's
//! estimates (the usual case); [`roots`] is the general solver and the fallback:
//! Weierstrass's simultaneous iteration (Durand–Kerner; Kerner, "Ein Gesamtschrittverfahren zur
//! Berechnung der Nullstellen von Polynomen", Numer. Math. 8, 1966), then two Newton steps per
//! root on the polynomial itself. Written here rather than taken from a crate: the crates that
//! find polynomial roots either return only the real ones (`roots`) or pull in a linear-algebra
//! library for a companion matrix (`nalgebra`), and four roots of a fixed degree need neither.
//! Simple roots converge quadratically; a double root (a wave along an optic axis) converges
//! linearly to about `√ε` of the root's size, which the boundary treats as one degenerate wave.

use num_complex::Complex64 as C;

/// Most iterations of the simultaneous step (from the boundary's starting points the usual case
/// takes 3–6; from a circle, 10–20).
const MAX_ITERATIONS: usize = 100;

/// `p(z)` of the monic quartic with lower coefficients `c = [c0, c1, c2, c3]`.
fn eval(c: &[f64; 4], z: C) -> C {
    (((z + c[3]) * z + c[2]) * z + c[1]) * z + c[0]
}

/// `p'(z)` of the same quartic.
fn derivative(c: &[f64; 4], z: C) -> C {
    ((4.0 * z + 3.0 * c[3]) * z + 2.0 * c[2]) * z + c[1]
}

/// The roots of `z⁴ + c3 z³ + c2 z² + c1 z + c0` (any order), or `None` if a coefficient is not
/// finite. `start`: estimates of the four roots, distinct (the iteration keeps them apart); by
/// default points on a circle as large as Cauchy's bound on the roots.
pub fn roots(c: [f64; 4], start: Option<[C; 4]>) -> Option<[C; 4]> {
    if !c.iter().all(|v| v.is_finite()) {
        return None;
    }
    let radius = 1.0 + c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // At angles that are no root's symmetry (a real polynomial's roots are symmetric about the
    // real axis).
    let mut z: [C; 4] = start.unwrap_or_else(|| {
        std::array::from_fn(|i| {
            C::from_polar(radius * (0.5 + 0.125 * i as f64), 0.8 + 1.5 * i as f64)
        })
    });
    for _ in 0..MAX_ITERATIONS {
        let mut done = true;
        for i in 0..4 {
            let mut den = C::from(1.0);
            for (j, &zj) in z.iter().enumerate() {
                if j != i {
                    den *= z[i] - zj;
                }
            }
            if den.norm_sqr() == 0.0 {
                // Two estimates met: nudge one off (never at a root of a well-posed problem).
                z[i] += C::new(1e-9 * radius, 1e-9 * radius);
                done = false;
                continue;
            }
            let p = eval(&c, z[i]);
            // Converged where |p(z)| is at the rounding error of its evaluation (Horner's
            // bound, Higham, *Accuracy and Stability of Numerical Algorithms*, §5.1):
            // iterating further only moves the estimate through noise.
            let r = z[i].norm_sqr().sqrt();
            let bound = (((r + c[3].abs()) * r + c[2].abs()) * r + c[1].abs()) * r + c[0].abs();
            if p.norm_sqr() <= (16.0 * f64::EPSILON * bound).powi(2) {
                continue;
            }
            done = false;
            z[i] -= p / den;
        }
        if done {
            break;
        }
    }
    for zi in &mut z {
        for _ in 0..2 {
            let d = derivative(&c, *zi);
            if d.norm_sqr() > 0.0 {
                let step = eval(&c, *zi) / d;
                if step.is_finite() && step.norm_sqr() < 1e-6 * (1.0 + zi.norm_sqr()) {
                    *zi -= step;
                }
            }
        }
    }
    z.iter().all(|v| v.is_finite()).then_some(z)
}

/// Most Newton steps of [`factored`] (from the boundary's estimates it takes 3–5).
const MAX_FACTOR_STEPS: usize = 24;

/// The roots of `z² + b z + c`, the larger one from the sum with `b`'s sign (no cancellation) and
/// the other from the product. A negative discriminant at the rounding level of its terms is a
/// double root (a wave along an optic axis must stay real, not acquire a `√ε` imaginary part).
fn quadratic(b: f64, c: f64) -> [C; 2] {
    let disc = b * b - 4.0 * c;
    if disc >= -64.0 * f64::EPSILON * (b * b + 4.0 * c.abs()) {
        let q = -0.5 * (b + disc.max(0.0).sqrt().copysign(b));
        if q == 0.0 {
            return [C::from(0.0); 2];
        }
        [C::from(q), C::from(c / q)]
    } else {
        let (re, im) = (-0.5 * b, 0.5 * (-disc).sqrt());
        [C::new(re, im), C::new(re, -im)]
    }
}

/// The roots of `z⁴ + c3 z³ + c2 z² + c1 z + c0` from a real quadratic factor `z² + r z + s`
/// found by Newton's method on the remainder of the division (Bairstow's method; Bairstow 1914,
/// as in Press et al., *Numerical Recipes*, 3rd ed., §9.5.6), started from `(r, s)`; each factor's
/// two roots then in closed form. Real arithmetic throughout, and two close roots in one factor
/// (the two waves near an optic axis) cost nothing: the factor is well conditioned while its
/// roots are apart from the other factor's. `None` if Newton's method does not settle within
/// [`MAX_FACTOR_STEPS`] (then [`roots`] is the fallback).
pub fn factored(c: [f64; 4], r: f64, s: f64) -> Option<[C; 4]> {
    let (mut r, mut s) = (r, s);
    if !(c.iter().all(|v| v.is_finite()) && r.is_finite() && s.is_finite()) {
        return None;
    }
    for _ in 0..MAX_FACTOR_STEPS {
        // p = (z² + r z + s)(z² + q1 z + q0) + r1 z + r0.
        let q1 = c[3] - r;
        let q0 = c[2] - r * q1 - s;
        let r1 = c[1] - r * q0 - s * q1;
        let r0 = c[0] - s * q0;
        // ∂(r1, r0)/∂s = −(q mod D), ∂(r1, r0)/∂r = −(z q mod D), D = z² + r z + s.
        let (j11, j12) = (-(r * r - s - q1 * r + q0), -(q1 - r));
        let (j21, j22) = (-(r * s - q1 * s), -(q0 - s));
        let det = j11 * j22 - j12 * j21;
        let dr = (r0 * j12 - r1 * j22) / det;
        let ds = (r1 * j21 - r0 * j11) / det;
        if !(dr.is_finite() && ds.is_finite()) {
            return None;
        }
        r += dr;
        s += ds;
        // Quadratic convergence: after a step this small the error is below rounding.
        if dr.abs() <= 1e-9 * (1.0 + r.abs()) && ds.abs() <= 1e-9 * (1.0 + s.abs()) {
            let q1 = c[3] - r;
            let q0 = c[2] - r * q1 - s;
            let [a, b] = quadratic(r, s);
            let [e, f] = quadratic(q1, q0);
            return Some([a, b, e, f]);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    /// The monic quartic with the given roots, as lower coefficients (its roots come in conjugate
    /// pairs or are real, so the coefficients are real).
    fn from_roots(r: [C; 4]) -> [f64; 4] {
        // Expand (z − r0)(z − r1)(z − r2)(z − r3).
        let mut p = [
            C::from(1.0),
            C::from(0.0),
            C::from(0.0),
            C::from(0.0),
            C::from(0.0),
        ];
        for (k, ri) in r.iter().enumerate() {
            for j in (1..=k + 1).rev() {
                p[j] -= *ri * p[j - 1];
            }
        }
        [p[4].re, p[3].re, p[2].re, p[1].re]
    }

    fn matched(found: [C; 4], want: [C; 4], tol: f64) -> bool {
        let mut used = [false; 4];
        want.iter().all(|w| {
            let best = (0..4)
                .filter(|&i| !used[i])
                .min_by(|&a, &b| (found[a] - w).norm().total_cmp(&(found[b] - w).norm()));
            match best {
                Some(i) if (found[i] - w).norm() <= tol * (1.0 + w.norm()) => {
                    used[i] = true;
                    true
                }
                _ => false,
            }
        })
    }

    /// Random quartics with four real roots, two real and a conjugate pair, or two pairs (the
    /// boundary's three cases): every root found to 1e-10.
    #[test]
    fn finds_every_root_of_random_quartics() {
        let mut rng = Rng::new(11);
        let mut u = || 4.0 * f64::from(rng.uniform()) - 2.0;
        for case in 0..3000 {
            let want = match case % 3 {
                0 => [C::from(u()), C::from(u()), C::from(u()), C::from(u())],
                1 => {
                    let (a, b) = (u(), u().abs() + 0.01);
                    [C::from(u()), C::from(u()), C::new(a, b), C::new(a, -b)]
                }
                _ => {
                    let (a, b, c, d) = (u(), u().abs() + 0.01, u(), u().abs() + 0.01);
                    [C::new(a, b), C::new(a, -b), C::new(c, d), C::new(c, -d)]
                }
            };
            // Well separated roots only: a near-double root is found to √ε, tested below.
            let separated = (0..4).all(|i| (0..i).all(|j| (want[i] - want[j]).norm() > 1e-3));
            if !separated {
                continue;
            }
            let got = roots(from_roots(want), None).unwrap();
            assert!(matched(got, want, 1e-9), "{want:?} → {got:?}");
        }
    }

    /// A double root (a wave along an optic axis) is found to about √ε, and the simple ones
    /// exactly.
    #[test]
    fn a_double_root_is_found_to_the_square_root_of_epsilon() {
        let want = [C::from(1.5), C::from(1.5), C::from(-1.6), C::from(-1.4)];
        let got = roots(from_roots(want), None).unwrap();
        assert!(matched(got, want, 1e-7), "{got:?}");
    }

    /// Bairstow's factor from estimates of its coefficients within 2 %: every root to
    /// 1e-12 in the three cases, and a double root in one factor stays a real double root.
    #[test]
    fn the_factored_roots_are_the_roots() {
        let mut rng = Rng::new(12);
        let mut u = || 4.0 * f64::from(rng.uniform()) - 2.0;
        let mut found = 0;
        for case in 0..3000 {
            let want = match case % 3 {
                0 => [C::from(u()), C::from(u()), C::from(u()), C::from(u())],
                1 => {
                    let (a, b) = (u(), u().abs() + 0.01);
                    [C::new(a, b), C::new(a, -b), C::from(u()), C::from(u())]
                }
                _ => {
                    let (a, b, c, d) = (u(), u().abs() + 0.01, u(), u().abs() + 0.01);
                    [C::new(a, b), C::new(a, -b), C::new(c, d), C::new(c, -d)]
                }
            };
            // The pairs apart, as the boundary's up and down waves are but near grazing (there the
            // fallback takes over: within 0.1 Newton can wander between pairings).
            // (within a pair 1e-3: closer roots are found to ε over their distance).
            let apart = (0..2).all(|i| (2..4).all(|j| (want[i] - want[j]).norm() > 0.5))
                && (want[0] - want[1]).norm() > 1e-3
                && (want[2] - want[3]).norm() > 1e-3;
            if !apart {
                continue;
            }
            let off = 1.0 + 0.02 * u() / 2.0;
            let (r, s) = (-(want[0] + want[1]).re * off, (want[0] * want[1]).re / off);
            let Some(got) = factored(from_roots(want), r, s) else {
                panic!("{want:?} from {r} {s}")
            };
            assert!(matched(got, want, 1e-12), "{want:?} → {got:?}");
            found += 1;
        }
        assert!(found > 500, "{found}");
        let want = [C::from(1.5), C::from(1.5), C::from(-1.6), C::from(-1.4)];
        let got = factored(from_roots(want), -2.9, 2.2).unwrap();
        assert!(matched(got, want, 1e-7), "{got:?}");
        assert!(got.iter().all(|z| z.im == 0.0), "{got:?}");
    }

    #[test]
    fn refuses_a_non_finite_coefficient() {
        assert!(roots([1.0, f64::NAN, 0.0, 0.0], None).is_none());
        assert!(roots([f64::INFINITY, 0.0, 0.0, 0.0], None).is_none());
    }
}
