//! The four complex roots of a real quartic, for the biaxial boundary ([`super::biaxial`]), whose
//! waves' normal components solve one.
//!
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

    #[test]
    fn refuses_a_non_finite_coefficient() {
        assert!(roots([1.0, f64::NAN, 0.0, 0.0], None).is_none());
        assert!(roots([f64::INFINITY, 0.0, 0.0, 0.0], None).is_none());
    }
}
