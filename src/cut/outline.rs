//! Girdle outlines of the brilliant family: where the girdle lies in each direction.
//!
//! Units: the girdle's width (its extent along `z`) is 2, its length along `x` is `2 · ratio`
//! (`ratio ≥ 1`, length over width). Directions are azimuths in the girdle plane `y = 0`.

use glam::DVec3;

/// The outline of a brilliant-family stone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outline {
    /// A circle.
    Round,
    /// An ellipse of semi-axes `ratio` (x) and 1 (z): the round design stretched along x
    /// (exactly: an affine stretch keeps every facet planar).
    Oval {
        /// Length over width.
        ratio: f64,
    },
    /// A navette: two circular arcs meeting in points at `x = ±ratio`.
    Marquise {
        /// Length over width.
        ratio: f64,
    },
    /// A half-circle (x ≤ 0) joined to a marquise point (x > 0); the length is
    /// `2 · ratio` with the circle's centre at the origin.
    Pear {
        /// Length over width.
        ratio: f64,
    },
    /// A superellipse `|x/ratio|⁴ + |z|⁴ = 1`: a rounded rectangle.
    Cushion {
        /// Length over width.
        ratio: f64,
    },
}

impl Outline {
    /// Length over width.
    pub fn ratio(&self) -> f64 {
        match *self {
            Outline::Round => 1.0,
            Outline::Oval { ratio }
            | Outline::Marquise { ratio }
            | Outline::Pear { ratio }
            | Outline::Cushion { ratio } => ratio,
        }
    }

    /// The name, as recipes write it.
    pub fn name(&self) -> &'static str {
        match self {
            Outline::Round => "round",
            Outline::Oval { .. } => "oval",
            Outline::Marquise { .. } => "marquise",
            Outline::Pear { .. } => "pear",
            Outline::Cushion { .. } => "cushion",
        }
    }

    /// Carries a point of the round design (girdle radius 1) onto this outline: the oval by an
    /// affine stretch along x, the others radially — a point at azimuth `φ` and radius `r` moves
    /// to radius `r · ρ(φ)`, `ρ` being the outline's distance from the centre along `φ`. Heights
    /// are kept.
    pub fn map(&self, p: DVec3) -> DVec3 {
        match *self {
            Outline::Round => p,
            Outline::Oval { ratio } => DVec3::new(p.x * ratio, p.y, p.z),
            _ => {
                let h = DVec3::new(p.x, 0.0, p.z);
                let r = h.length();
                if r == 0.0 {
                    return p;
                }
                let u = h / r;
                let s = self.radius(u.x, u.z);
                DVec3::new(p.x * s, p.y, p.z * s)
            }
        }
    }

    /// The distance from the centre to the outline along the unit direction `(ux, uz)`.
    pub fn radius(&self, ux: f64, uz: f64) -> f64 {
        match *self {
            Outline::Round => 1.0,
            Outline::Oval { ratio } => 1.0 / ((ux / ratio).powi(2) + uz * uz).sqrt(),
            Outline::Marquise { ratio } => arc(ratio, uz),
            Outline::Pear { ratio } => {
                if ux <= 0.0 {
                    1.0
                } else {
                    // The pointed half: the marquise of tip distance 2·ratio − 1.
                    arc(2.0 * ratio - 1.0, uz)
                }
            }
            Outline::Cushion { ratio } => ((ux / ratio).powi(4) + uz.powi(4)).powf(-0.25),
        }
    }
}

/// Distance along the unit direction `(ux, uz)` (only `uz` matters) to the arc through `(0, ±1)` and `(±tip, 0)`: the circle on the far
/// side of the x axis, centre `(0, ∓c)` with `c = (tip² − 1)/2` and radius `R = c + 1` (so it
/// meets the round girdle at `z = ±1` with the same tangent).
fn arc(tip: f64, uz: f64) -> f64 {
    let c = 0.5 * (tip * tip - 1.0);
    let radius = c + 1.0;
    // Centre below the x axis for directions above it.
    let cz = if uz >= 0.0 { -c } else { c };
    // |r u − C|² = R²: r² − 2 r (u·C) + |C|² − R² = 0.
    let b = uz * cz;
    b + (b * b - cz * cz + radius * radius).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outlines_have_their_length_and_width() {
        for o in [
            Outline::Round,
            Outline::Oval { ratio: 1.4 },
            Outline::Marquise { ratio: 2.0 },
            Outline::Cushion { ratio: 1.2 },
        ] {
            let r = o.ratio();
            assert!((o.radius(1.0, 0.0) - r).abs() < 1e-12, "{o:?}");
            assert!((o.radius(-1.0, 0.0) - r).abs() < 1e-12, "{o:?}");
            assert!((o.radius(0.0, 1.0) - 1.0).abs() < 1e-12, "{o:?}");
            assert!((o.radius(0.0, -1.0) - 1.0).abs() < 1e-12, "{o:?}");
        }
        let pear = Outline::Pear { ratio: 1.5 };
        assert!((pear.radius(1.0, 0.0) - 2.0).abs() < 1e-12);
        assert!((pear.radius(-1.0, 0.0) - 1.0).abs() < 1e-12);
        // Convex: the outline's points, taken around, always turn the same way.
        for o in [
            Outline::Marquise { ratio: 2.0 },
            Outline::Pear { ratio: 1.6 },
            Outline::Cushion { ratio: 1.0 },
        ] {
            let pts: Vec<(f64, f64)> = (0..720)
                .map(|k| {
                    let a = k as f64 * std::f64::consts::TAU / 720.0;
                    let r = o.radius(a.cos(), a.sin());
                    (r * a.cos(), r * a.sin())
                })
                .collect();
            for k in 0..720 {
                let (a, b, c) = (pts[k], pts[(k + 1) % 720], pts[(k + 2) % 720]);
                let cross = (b.0 - a.0) * (c.1 - b.1) - (b.1 - a.1) * (c.0 - b.0);
                assert!(cross > -1e-9, "{o:?} turns back at {k}");
            }
        }
    }
}
