//! Step cuts: rows of facets parallel to the girdle's sides — the emerald cut (a rectangle with
//! cut corners), the square step cut (the Asscher, with larger corners) and the princess (a
//! square without corners whose pavilion rows close in a point; real princess pavilions split
//! each row into chevrons along the diagonals, which this one does not).
//!
//! At girdle width 2: the outline has half-length `ratio` along x and half-width 1 along z; each
//! corner cut is a 45° side whose legs are `corner · 2` long. Each row of the crown (girdle to
//! table) and of the pavilion (girdle down) is one facet per side, tilted by the row's angle
//! toward that side; the rows divide the inset from the girdle to the table (crown) or to the keel
//! (pavilion) into equal horizontal widths, so each row's height follows from its angle. Angles
//! fall row by row from the girdle inward (a convex stone).

use super::{Builder, CutError};
use crate::geometry::FacetPlane;
use glam::DVec3;

/// Which step cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepKind {
    /// A rectangle with cut corners.
    Emerald,
    /// A square with cut corners (the Asscher).
    Square,
    /// A square without corners, the pavilion closing in a point.
    Princess,
}

/// A step cut's proportions (fractions of the girdle width, angles in degrees).
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Which cut.
    pub kind: StepKind,
    /// Length over width (1 for the square cuts).
    pub ratio: f64,
    /// Corner legs over the width (0 for the princess).
    pub corner: f64,
    /// Table width over the girdle width.
    pub table: f64,
    /// Crown rows' angles from the girdle toward the table, falling.
    pub crown: Vec<f64>,
    /// Pavilion rows' angles from the girdle toward the keel, falling.
    pub pavilion: Vec<f64>,
    /// Girdle thickness over the width.
    pub girdle: f64,
}

impl Step {
    /// The cut's name.
    pub fn label(&self) -> String {
        match self.kind {
            StepKind::Emerald => "emerald cut".into(),
            StepKind::Square => "square step cut".into(),
            StepKind::Princess => "princess cut".into(),
        }
    }

    /// The outline's sides: outward normal, distance from the centre and name.
    fn sides(&self) -> Vec<(DVec3, f64, &'static str)> {
        let (a, b) = (self.ratio, 1.0);
        let mut v = vec![
            (DVec3::X, a, "+x"),
            (DVec3::NEG_X, a, "−x"),
            (DVec3::Z, b, "+z"),
            (DVec3::NEG_Z, b, "−z"),
        ];
        let leg = 2.0 * self.corner;
        if leg > 0.0 {
            let e = (a + b - leg) / 2f64.sqrt();
            for (sx, sz, name) in [
                (1.0, 1.0, "+x+z"),
                (-1.0, 1.0, "−x+z"),
                (1.0, -1.0, "+x−z"),
                (-1.0, -1.0, "−x−z"),
            ] {
                v.push((DVec3::new(sx, 0.0, sz).normalize(), e, name));
            }
        }
        v
    }

    /// Whether side `side` still has a facet in a row starting `inset` in from the girdle: the
    /// sides of an outline inset evenly keep their length but its corner sides shorten, by
    /// `2 tan 22.5°` per unit of inset, and vanish at `inset = leg √2 / (2 tan 22.5°)`.
    fn corner_at(&self, side: &str, inset: f64) -> bool {
        let is_corner = side.chars().count() > 2;
        !is_corner
            || 2.0 * self.corner * 2f64.sqrt() - 2.0 * inset * 22.5f64.to_radians().tan() > 1e-9
    }

    /// The half-spaces (girdle width 2) and the facet names.
    pub fn planes(&self) -> Result<(Vec<FacetPlane>, Vec<String>), CutError> {
        for (what, rows) in [("crown", &self.crown), ("pavilion", &self.pavilion)] {
            if rows.is_empty() || rows.len() > 8 {
                return Err(CutError(format!(
                    "{what}: 1 ..= 8 rows, got {}",
                    rows.len()
                )));
            }
            if rows.windows(2).any(|w| w[1] >= w[0]) {
                return Err(CutError(format!(
                    "{what} angles {rows:?}: each row must be flatter than the one before it \
                     (angles falling from the girdle inward)"
                )));
            }
        }
        let g = self.girdle;
        let crown_width = (1.0 - self.table) / self.crown.len() as f64;
        let pavilion_width = 1.0 / self.pavilion.len() as f64;
        let crown_heights = heights(g, crown_width, &self.crown);
        let pavilion_heights = heights(g, pavilion_width, &self.pavilion);
        let top = *crown_heights.last().unwrap_or(&g);
        let bottom = -*pavilion_heights.last().unwrap_or(&g);
        let mut f = Builder::new(DVec3::new(0.0, 0.5 * (top + bottom), 0.0));
        let sides = self.sides();
        f.with_normal(DVec3::Y, DVec3::new(0.0, top, 0.0), "table".into())?;
        for (i, &angle) in self.crown.iter().enumerate() {
            let (s, c) = angle.to_radians().sin_cos();
            let inset = i as f64 * crown_width;
            for &(m, e, side) in sides.iter().filter(|s| self.corner_at(s.2, inset)) {
                let at = m * (e - inset) + DVec3::Y * crown_heights[i];
                f.with_normal(
                    m * s + DVec3::Y * c,
                    at,
                    format!("crown {} ({side})", i + 1),
                )?;
            }
        }
        for &(m, e, side) in &sides {
            f.with_normal(m, m * e, format!("girdle ({side})"))?;
        }
        for (i, &angle) in self.pavilion.iter().enumerate() {
            let (s, c) = angle.to_radians().sin_cos();
            let inset = i as f64 * pavilion_width;
            for &(m, e, side) in sides.iter().filter(|s| self.corner_at(s.2, inset)) {
                let at = m * (e - inset) - DVec3::Y * pavilion_heights[i];
                f.with_normal(
                    m * s - DVec3::Y * c,
                    at,
                    format!("pavilion {} ({side})", i + 1),
                )?;
            }
        }
        Ok((f.planes, f.names))
    }
}

/// The heights (from the girdle's middle, upward for the crown and downward for the pavilion)
/// at the start of each row and after the last: `g` at the girdle, then rising by `width · tan a`
/// per row.
fn heights(g: f64, width: f64, angles: &[f64]) -> Vec<f64> {
    let mut h = vec![g];
    for a in angles {
        let last = *h.last().unwrap_or(&g);
        h.push(last + width * a.to_radians().tan());
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Hull;

    fn emerald() -> Step {
        Step {
            kind: StepKind::Emerald,
            ratio: 1.4,
            corner: 0.15,
            table: 0.6,
            crown: vec![50.0, 40.0, 30.0],
            pavilion: vec![60.0, 50.0, 40.0],
            girdle: 0.02,
        }
    }

    #[test]
    fn the_emerald_cut_has_every_facet_and_its_table() {
        let s = emerald();
        let (planes, names) = s.planes().unwrap();
        // Table, 3 crown rows of 8 sides, 8 girdle sides, 3 pavilion rows of which the last
        // (starting 2/3 of the half-width in, past 0.3 √2 / (2 tan 22.5°) = 0.51) has no corners.
        assert_eq!(names.len(), 1 + 3 * 8 + 8 + 2 * 8 + 4);
        let hull = Hull::new(&planes, 100.0).unwrap();
        let present: std::collections::HashSet<usize> =
            hull.faces.iter().filter_map(|f| f.plane).collect();
        // The last pavilion row's ends on the long sides close against the keel: every facet
        // but possibly those bounds a face.
        let missing: Vec<&String> = (0..names.len())
            .filter(|i| !present.contains(i))
            .map(|i| &names[i])
            .collect();
        assert!(missing.is_empty(), "{missing:?}");
        let table = hull.faces.iter().find(|f| f.plane == Some(0)).unwrap();
        let z = table.points.iter().map(|p| p.z).fold(0.0, f64::max);
        assert!((z - 0.6).abs() < 1e-9, "table half-width {z}");
    }

    #[test]
    fn rows_must_flatten_inward() {
        let mut s = emerald();
        s.crown = vec![30.0, 40.0];
        assert!(s.planes().unwrap_err().0.contains("flatter"));
        s.crown = vec![];
        assert!(s.planes().unwrap_err().0.contains("1 ..= 8"));
    }
}
