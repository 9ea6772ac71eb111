//! The brilliant: 57 facets (58 with a culet) and a faceted girdle, on a round or fancy outline.
//!
//! The round design is the one `scripts/brilliant-mesh.py` writes as `assets/brilliant.obj`, made
//! of planes instead of triangles (so the two agree): girdle radius 1, `y` up, azimuths
//! counter-clockwise seen from above from `+x`, a point at radius `r` and azimuth `a` being
//! `(r cos a, y, −r sin a)`. The table is a regular octagon whose corners (at `45° k`) lie at the
//! table's radius (table % measured corner to corner); each bezel (crown main) is the kite through
//! a table corner and the girdle junction below it at the crown angle; each star facet is the
//! triangle of two table corners and the star point (on the ridge between two bezels, the star
//! length of the way from the table edge to the girdle, in projection); each upper-girdle facet
//! the triangle of a star point and two neighbouring girdle junctions (every 22.5°). The pavilion
//! mirrors it: mains at the pavilion angle meeting in the culet, lower-girdle facets through the
//! lower points (the lower-girdle length of the way from girdle to culet, as GIA measures it).
//! The upper- and lower-girdle facets cut into the girdle between junctions, as on a real stone;
//! the girdle thickness parameter is its thickness there, halfway between junctions (its
//! thinnest). Sources for the proportions: Tolkowsky, "Diamond Design" (1919) for the angles;
//! GIA's cut grading terms (table corner to corner over the girdle diameter, star and lower-girdle
//! lengths as fractions of those spans).
//!
//! Fancy outlines take the round design's points onto the outline ([`Outline::map`]) and put each
//! facet's plane through three of its mapped corners.

use super::outline::Outline;
use super::{Builder, CutError};
use crate::geometry::FacetPlane;
use glam::DVec3;

/// A brilliant's proportions (fractions of the girdle width, angles in degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Brilliant {
    /// The girdle outline.
    pub outline: Outline,
    /// Table width (corner to corner) over the girdle width.
    pub table: f64,
    /// Bezel angle to the girdle plane, degrees.
    pub crown: f64,
    /// Pavilion main angle to the girdle plane, degrees.
    pub pavilion: f64,
    /// Girdle thickness (at its thinnest, between facet junctions) over the girdle width.
    pub girdle: f64,
    /// Star length: how far from the table edge toward the girdle the star points reach.
    pub star: f64,
    /// Lower-girdle length: how far from the girdle toward the culet the lower points reach.
    pub lower_girdle: f64,
    /// Culet width over the girdle width (0: pointed).
    pub culet: f64,
    /// Number of girdle facets (a multiple of 16).
    pub girdle_facets: u32,
}

impl Default for Brilliant {
    /// Tolkowsky's angles with the 56 % table of modern practice, star 50 %, lower girdle 77 %,
    /// a 2.5 % girdle, pointed culet, 64 girdle facets (`assets/brilliant.obj` has 64 too).
    fn default() -> Self {
        Brilliant {
            outline: Outline::Round,
            table: 0.56,
            crown: 34.5,
            pavilion: 40.75,
            girdle: 0.025,
            star: 0.5,
            lower_girdle: 0.77,
            culet: 0.0,
            girdle_facets: 64,
        }
    }
}

/// A brilliant's heights (girdle radius 1, the girdle's middle at `y = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Heights {
    /// The table's height.
    pub table: f64,
    /// The girdle's top at the bezel junctions.
    pub girdle_top: f64,
    /// The pavilion's point (below a culet facet, where there is one).
    pub culet: f64,
}

fn polar(r: f64, degrees: f64, y: f64) -> DVec3 {
    let a = degrees.to_radians();
    DVec3::new(r * a.cos(), y, -r * a.sin())
}

/// Height at radius 1, azimuth `degrees`, of the plane through `a` and the girdle junctions at
/// `22.5° · sector` and `22.5° · (sector + 1)`, height `y0`.
fn girdle_cut(a: DVec3, sector: f64, y0: f64, degrees: f64) -> f64 {
    let at = polar(1.0, degrees, 0.0);
    let b = polar(1.0, sector * 22.5, y0);
    let c = polar(1.0, (sector + 1.0) * 22.5, y0);
    let n = (b - a).cross(c - a);
    a.y - (n.x * (at.x - a.x) + n.z * (at.z - a.z)) / n.y
}

impl Brilliant {
    /// The heights of the round design.
    pub fn heights(&self) -> Heights {
        let (tc, tp) = (
            self.crown.to_radians().tan(),
            self.pavilion.to_radians().tan(),
        );
        let c = 22.5f64.to_radians().cos();
        let (rs, rl) = self.point_radii();
        let on_bezel = |r: f64, yt: f64| yt + (1.0 - r * c) * tc;
        let on_main = |r: f64, yb: f64| yb - tp + r * c * tp;
        // The girdle is `girdle` thick (of the width 2) halfway between junctions.
        let drop = -girdle_cut(polar(rs, 22.5, on_bezel(rs, 0.0)), 0.0, 0.0, 11.25);
        let rise = girdle_cut(polar(rl, 22.5, on_main(rl, 0.0)), 0.0, 0.0, 11.25);
        let yt = (2.0 * self.girdle + drop + rise) / 2.0;
        Heights {
            table: yt + (1.0 - self.table) * tc,
            girdle_top: yt,
            culet: -yt - tp,
        }
    }

    /// Radii of the star points and of the lower points (girdle radius 1).
    fn point_radii(&self) -> (f64, f64) {
        let c = 22.5f64.to_radians().cos();
        (
            self.table * c + self.star * (1.0 - self.table * c),
            1.0 - self.lower_girdle,
        )
    }

    /// The half-spaces (girdle width 2) and the facet names.
    pub fn planes(&self) -> Result<(Vec<FacetPlane>, Vec<String>), CutError> {
        if self.girdle_facets == 0 || !self.girdle_facets.is_multiple_of(16) {
            return Err(CutError(format!(
                "girdle_facets = {}: a multiple of 16 (16 ..= 256)",
                self.girdle_facets
            )));
        }
        let (tc, tp) = (
            self.crown.to_radians().tan(),
            self.pavilion.to_radians().tan(),
        );
        let c = 22.5f64.to_radians().cos();
        // The star points lie below the table only if `r_star cos 22.5° > table`: a large table
        // needs long stars.
        let t = self.table;
        let min_star = t * (1.0 - c * c) / (c * (1.0 - t * c));
        if self.star <= min_star {
            return Err(CutError(format!(
                "star = {:.1} % with table = {:.1} %: the star facets would rise above the table; \
                 this table needs star > {:.1} %",
                100.0 * self.star,
                100.0 * t,
                100.0 * min_star
            )));
        }
        let h = self.heights();
        let (yt, yb) = (h.girdle_top, -h.girdle_top);
        let (rs, rl) = self.point_radii();
        let o = &self.outline;
        let m = |p: DVec3| o.map(p);
        let table: Vec<DVec3> = (0..8)
            .map(|k| m(polar(self.table, 45.0 * k as f64, h.table)))
            .collect();
        let culet = DVec3::new(0.0, h.culet, 0.0);
        let top = |s: usize| m(polar(1.0, 22.5 * s as f64, yt));
        let bot = |s: usize| m(polar(1.0, 22.5 * s as f64, yb));
        // The outline's horizontal tangent at the junction at `22.5° · s` (a central difference:
        // at a marquise's or pear's point it bisects the corner).
        let tangent = |s: usize| {
            let e = 1e-4;
            let a = 22.5 * s as f64;
            m(polar(1.0, a + e, 0.0)) - m(polar(1.0, a - e, 0.0))
        };
        // Each bezel (pavilion main) is the plane through its table corner (the culet) and its
        // girdle junction that contains the outline's tangent there: on the round the kite of
        // the round design; on any outline a plane that meets the girdle at the junction only.
        let main = |apex: DVec3, junction: DVec3, s: usize| {
            let n = (junction - apex).cross(tangent(s)).normalize_or_zero();
            (n, junction)
        };
        let bezels: Vec<(DVec3, DVec3)> =
            (0..8).map(|k| main(table[k], top(2 * k), 2 * k)).collect();
        let mains: Vec<(DVec3, DVec3)> = (0..8).map(|k| main(culet, bot(2 * k), 2 * k)).collect();
        // Star (lower) points: on the ridge of two neighbouring bezels (mains), at the round
        // design's height.
        let ridge = |a: (DVec3, DVec3), b: (DVec3, DVec3), y: f64| -> Result<DVec3, CutError> {
            let (na, nb) = (a.0, b.0);
            let (da, db) = (na.dot(a.1) - na.y * y, nb.dot(b.1) - nb.y * y);
            let det = na.x * nb.z - na.z * nb.x;
            if det.abs() < 1e-12 {
                return Err(CutError("two neighbouring main facets are parallel".into()));
            }
            Ok(DVec3::new(
                (da * nb.z - db * na.z) / det,
                y,
                (na.x * db - nb.x * da) / det,
            ))
        };
        let star: Vec<DVec3> = (0..8)
            .map(|k| ridge(bezels[k], bezels[(k + 1) % 8], yt + (1.0 - rs * c) * tc))
            .collect::<Result<_, _>>()?;
        let lower: Vec<DVec3> = (0..8)
            .map(|k| ridge(mains[k], mains[(k + 1) % 8], yb - tp + rl * c * tp))
            .collect::<Result<_, _>>()?;
        let mut f = Builder::new(DVec3::new(0.0, 0.5 * (h.table + h.culet), 0.0));
        f.with_normal(DVec3::Y, table[0], "table".into())?;
        for k in 0..8 {
            f.through(
                table[k],
                star[k],
                table[(k + 1) % 8],
                format!("star {}", k + 1),
            )?;
        }
        for (k, &(n, at)) in bezels.iter().enumerate() {
            f.facing_out(n, at, format!("bezel {}", k + 1))?;
        }
        for s in 0..16 {
            f.through(
                star[s / 2],
                top(s),
                top(s + 1),
                format!("upper girdle {}", s + 1),
            )?;
        }
        for (k, &(n, at)) in mains.iter().enumerate() {
            f.facing_out(n, at, format!("pavilion main {}", k + 1))?;
        }
        for s in 0..16 {
            f.through(
                lower[s / 2],
                bot(s),
                bot(s + 1),
                format!("lower girdle {}", s + 1),
            )?;
        }
        if self.culet > 0.0 {
            // The culet facet: horizontal, as wide as `culet` of the width across the mains.
            let y = h.culet + self.culet * tp;
            f.with_normal(DVec3::NEG_Y, DVec3::new(0.0, y, 0.0), "culet".into())?;
        }
        let n = self.girdle_facets as usize;
        let step = 360.0 / n as f64;
        for i in 0..n {
            let a = m(polar(1.0, step * i as f64, 0.0));
            let b = m(polar(1.0, step * (i + 1) as f64, 0.0));
            f.through(a, b, a + DVec3::Y, format!("girdle {}", i + 1))?;
        }
        Ok((f.planes, f.names))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Hull;

    /// The round brilliant's proportions against those `scripts/brilliant-mesh.py` writes into
    /// `assets/brilliant.obj`'s header (its girdle: 1.25 % of the diameter between junctions).
    #[test]
    fn the_round_brilliant_has_the_meshs_proportions() {
        let b = Brilliant {
            girdle: 0.0125,
            ..Brilliant::default()
        };
        let h = b.heights();
        let crown = (h.table - h.girdle_top) / 2.0;
        let pavilion = (-h.girdle_top - h.culet) / 2.0;
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/brilliant.obj"),
        )
        .unwrap();
        let pct = |key: &str| -> f64 {
            let at = text.find(key).unwrap() + key.len();
            let rest = text[at..].trim_start();
            rest[..rest.find('%').unwrap()].parse().unwrap()
        };
        assert!(
            (100.0 * crown - pct("Crown height")).abs() < 0.006,
            "{crown}"
        );
        assert!(
            (100.0 * pavilion - pct("pavilion depth")).abs() < 0.006,
            "{pavilion}"
        );
        let depth = (h.table - h.culet) / 2.0;
        assert!(
            (100.0 * depth - pct("total depth")).abs() < 0.006,
            "{depth}"
        );
        let (planes, names) = b.planes().unwrap();
        assert_eq!(names.len(), 57 + 64);
        let hull = Hull::new(&planes, 100.0).unwrap();
        // Every facet appears.
        assert_eq!(hull.faces.len(), 57 + 64);
        // The table is the regular octagon of 56 % corner to corner.
        let table = hull.faces.iter().find(|f| f.plane == Some(0)).unwrap();
        assert_eq!(table.points.len(), 8);
        for p in &table.points {
            assert!(((p.x * p.x + p.z * p.z).sqrt() - 0.56).abs() < 1e-9);
        }
    }
}
