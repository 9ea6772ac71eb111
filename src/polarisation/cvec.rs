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

/// The real part.
pub fn real(a: CVec) -> DVec3 {
    DVec3::new(a[0].re, a[1].re, a[2].re)
}

/// Gaussian elimination with partial pivoting of the 4 × 4 system `a` with `R` right-hand sides
/// (the columns of `b`); the solutions, one per column.
pub fn solve4<const R: usize>(mut a: [[C; 4]; 4], mut b: [[C; R]; 4]) -> Option<[[C; 4]; R]> {
    for col in 0..4 {
        let p = (col..4).max_by(|&i, &j| a[i][col].norm().total_cmp(&a[j][col].norm()))?;
        if !(a[p][col].norm() > 1e-14) {
            return None;
        }
        a.swap(col, p);
        b.swap(col, p);
        let (pivot, pb) = (a[col], b[col]);
        for (row, rb) in a
            .iter_mut()
            .zip(b.iter_mut())
            .enumerate()
            .filter(|(r, _)| *r != col)
            .map(|(_, x)| x)
        {
            let f = row[col] / pivot[col];
            for (x, v) in row.iter_mut().zip(pivot).skip(col) {
                *x -= f * v;
            }
            for (x, v) in rb.iter_mut().zip(pb) {
                *x -= f * v;
            }
        }
    }
    let x: [[C; 4]; R] = std::array::from_fn(|k| std::array::from_fn(|i| b[i][k] / a[i][i]));
    x.iter().flatten().all(|c| c.is_finite()).then_some(x)
}
