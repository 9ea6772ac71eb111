//! Complex 3-vectors with bilinear products (the fields of plane waves, possibly evanescent) and
//! a small complex linear solve, shared by the crystal boundary ([`super::boundary`]) and the
//! biaxial crystal ([`super::biaxial`]).

use glam::DVec3;
use num_complex::Complex64 as C;

/// A complex 3-vector.
pub type CVec = [C; 3];

/// A real vector as a complex one.
pub fn cv(v: DVec3) -> CVec {
    [C::from(v.x), C::from(v.y), C::from(v.z)]
}

/// `a + b`.
pub fn add(a: CVec, b: CVec) -> CVec {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `s a`.
pub fn scale(a: CVec, s: C) -> CVec {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// The bilinear (not Hermitian) dot product.
pub fn dot(a: CVec, b: CVec) -> C {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The bilinear cross product.
pub fn cross(a: CVec, b: CVec) -> CVec {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The Hermitian length `√(Σ |aᵢ|²)`.
pub fn norm(a: CVec) -> f64 {
    a.iter().map(|c| c.norm_sqr()).sum::<f64>().sqrt()
}

/// Whether every imaginary part is zero.
pub fn is_real(a: CVec) -> bool {
    a.iter().all(|c| c.im == 0.0)
}

/// The real part.
pub fn real(a: CVec) -> DVec3 {
    DVec3::new(a[0].re, a[1].re, a[2].re)
}

/// Gaussian elimination with partial pivoting of the 4 × 4 system `a` with `R` right-hand sides
/// (the columns of `b`), then back substitution; the solutions, one per column. The pivot is the
/// entry of largest `|z|²` (no `hypot`: the order is the same but for ties within rounding), and
/// each column's numbers depend on that column alone. `None` if a pivot is below 10⁻¹⁴ in
/// magnitude or a solution is not finite.
pub fn solve4<const R: usize>(mut a: [[C; 4]; 4], mut b: [[C; R]; 4]) -> Option<[[C; 4]; R]> {
    let real = |z: &C| z.im == 0.0;
    if a.iter().flatten().all(real) && b.iter().flatten().all(real) {
        let x = solve4_real(a.map(|r| r.map(|z| z.re)), b.map(|r| r.map(|z| z.re)))?;
        return Some(x.map(|xk| xk.map(C::from)));
    }
    for col in 0..4 {
        let p = (col..4).max_by(|&i, &j| a[i][col].norm_sqr().total_cmp(&a[j][col].norm_sqr()))?;
        if !(a[p][col].norm_sqr() > 1e-28) {
            return None;
        }
        a.swap(col, p);
        b.swap(col, p);
        let (pivot, pb) = (a[col], b[col]);
        for row in col + 1..4 {
            let f = a[row][col] / pivot[col];
            for k in col + 1..4 {
                a[row][k] -= f * pivot[k];
            }
            for k in 0..R {
                b[row][k] -= f * pb[k];
            }
        }
    }
    let mut x = [[C::from(0.0); 4]; R];
    for (k, xk) in x.iter_mut().enumerate() {
        for i in (0..4).rev() {
            let mut s = b[i][k];
            for j in i + 1..4 {
                s -= a[i][j] * xk[j];
            }
            xk[i] = s / a[i][i];
        }
    }
    x.iter().flatten().all(|c| c.is_finite()).then_some(x)
}

/// [`solve4`] of a real system (every wave propagating, none evanescent: the common case), in
/// real arithmetic with the complex path's operations on numbers whose imaginary parts are zero:
/// a quotient `a / c` as `(a c) / (c c)`, as the complex division forms it, so the solution is
/// the complex path's bit for bit (tested).
pub fn solve4_real<const R: usize>(
    mut a: [[f64; 4]; 4],
    mut b: [[f64; R]; 4],
) -> Option<[[f64; 4]; R]> {
    let div = |x: f64, c: f64| (x * c) / (c * c);
    for col in 0..4 {
        let p = (col..4)
            .max_by(|&i, &j| (a[i][col] * a[i][col]).total_cmp(&(a[j][col] * a[j][col])))?;
        if !(a[p][col] * a[p][col] > 1e-28) {
            return None;
        }
        a.swap(col, p);
        b.swap(col, p);
        let (pivot, pb) = (a[col], b[col]);
        for row in col + 1..4 {
            let f = div(a[row][col], pivot[col]);
            for k in col + 1..4 {
                a[row][k] -= f * pivot[k];
            }
            for k in 0..R {
                b[row][k] -= f * pb[k];
            }
        }
    }
    let mut x = [[0.0; 4]; R];
    for (k, xk) in x.iter_mut().enumerate() {
        for i in (0..4).rev() {
            let mut s = b[i][k];
            for j in i + 1..4 {
                s -= a[i][j] * xk[j];
            }
            xk[i] = div(s, a[i][i]);
        }
    }
    x.iter().flatten().all(|c| c.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    /// Random complex 4 × 4 systems with two right-hand sides: `A x = b` to 10⁻¹² of the
    /// system's size, each column the same as when solved alone (bit for bit), a singular
    /// system refused.
    #[test]
    fn solves_random_systems_and_refuses_singular_ones() {
        let mut rng = Rng::new(9);
        let mut z = || {
            C::new(
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.5,
            )
        };
        for _ in 0..2000 {
            let a: [[C; 4]; 4] = std::array::from_fn(|_| std::array::from_fn(|_| z()));
            let b: [[C; 2]; 4] = std::array::from_fn(|_| [z(), z()]);
            let x = solve4(a, b).expect("a random system is regular");
            for (k, xk) in x.iter().enumerate() {
                for i in 0..4 {
                    let ax: C = (0..4).map(|j| a[i][j] * xk[j]).sum();
                    let scale = 1.0 + xk.iter().map(|v| v.norm()).sum::<f64>();
                    assert!((ax - b[i][k]).norm() < 1e-12 * scale, "{ax} vs {}", b[i][k]);
                }
                let alone = solve4(a, std::array::from_fn(|i| [b[i][k]])).unwrap();
                let bits = |v: &[C; 4]| v.map(|c| (c.re.to_bits(), c.im.to_bits()));
                assert_eq!(bits(&alone[0]), bits(xk));
            }
        }
        // Real systems take the real path: the complex path's numbers bit for bit.
        let mut r = || f64::from(rng.uniform()) - 0.5;
        for _ in 0..2000 {
            let a: [[C; 4]; 4] = std::array::from_fn(|_| std::array::from_fn(|_| C::from(r())));
            let b: [[C; 2]; 4] = std::array::from_fn(|_| [C::from(r()), C::from(r())]);
            let fast = solve4(a, b).expect("regular");
            // The complex path, forced by an imaginary part that is zero but not exactly.
            let mut tiny = a;
            tiny[0][0].im = 1e-300;
            let slow = solve4(tiny, b).expect("regular");
            let bits = |v: &[C; 4]| v.map(|c| c.re.to_bits());
            for k in 0..2 {
                assert_eq!(bits(&fast[k]), bits(&slow[k]));
                assert!(fast[k].iter().all(|c| c.im == 0.0));
            }
        }
        let mut singular = [[C::from(1.0); 4]; 4];
        singular[0][0] = C::from(2.0);
        assert!(solve4(singular, [[C::from(1.0)]; 4]).is_none());
    }
}
