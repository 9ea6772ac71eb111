//! A faceted stone's proportions measured from its solid (not from its parameters): length,
//! width, depth, crown height, pavilion depth and girdle thickness as percentages of the width,
//! the facets present by group, and the volume. `lapidary info` prints them.

use crate::geometry::Hull;
use crate::geometry::shape::Facets;
use glam::DVec3;

/// Proportions of a faceted stone (lengths in object units, `*_pct` of the girdle width).
#[derive(Clone, Debug, PartialEq)]
pub struct Proportions {
    /// Extent along x.
    pub length: f64,
    /// Extent along z.
    pub width: f64,
    /// Total depth, % of the width.
    pub depth_pct: f64,
    /// From the girdle's top (its highest point) to the table, % of the width (`None`: no girdle
    /// facets).
    pub crown_pct: Option<f64>,
    /// From the girdle's bottom (its lowest point) to the culet, % of the width.
    pub pavilion_pct: Option<f64>,
    /// Girdle thickness at its thinnest and thickest facet, % of the width.
    pub girdle_pct: Option<(f64, f64)>,
    /// Table width (its extent along z) over the width, %, when there is a table facet.
    pub table_pct: Option<f64>,
    /// Facets present, by group (the name without its number), in design order.
    pub groups: Vec<(String, usize)>,
    /// Facets present in all.
    pub facets: usize,
    /// Volume, object units³.
    pub volume: f64,
}

/// The group of a facet name: `"pavilion main 3"` → `"pavilion main"`, `"P1 @ 12"` → `"P1"`,
/// `"crown 2 (+x)"` → `"crown 2"`.
pub fn group(name: &str) -> &str {
    if let Some((g, _)) = name.split_once(" @ ") {
        return g;
    }
    // A step cut's side: `"crown 2 (+x)"` → `"crown 2"`.
    if let Some((g, _)) = name.split_once(" (") {
        return g;
    }
    match name.rsplit_once(' ') {
        Some((g, n)) if n.chars().all(|c| c.is_ascii_digit()) => g,
        _ => name,
    }
}

/// Measures `f`.
pub fn proportions(f: &Facets) -> Proportions {
    let extent = f.planes.iter().map(|p| p.d.abs()).fold(1.0f64, f64::max) * 1e3;
    let hull = Hull::new(&f.planes, extent).ok();
    let faces = hull.as_ref().map_or(&[][..], |h| &h.faces[..]);
    let lo = f.vertices.iter().fold(DVec3::INFINITY, |a, v| a.min(*v));
    let hi = f
        .vertices
        .iter()
        .fold(DVec3::NEG_INFINITY, |a, v| a.max(*v));
    let (length, width) = (hi.x - lo.x, hi.z - lo.z);
    let pct = |x: f64| 100.0 * x / width;
    let normal = |i: usize| f.planes[i].normal;
    let girdle: Vec<&crate::geometry::clip::Face> = faces
        .iter()
        .filter(|face| face.plane.is_some_and(|i| normal(i).y.abs() < 1e-9))
        .collect();
    // The girdle's thickness along each of its vertical edges: points of girdle faces at the
    // same (x, z).
    let (mut top, mut bottom) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut columns: Vec<(f64, f64, f64, f64)> = vec![]; // x, z, lowest y, highest y
    let tol = 1e-9 * width.max(length);
    for p in girdle.iter().flat_map(|face| &face.points) {
        top = top.max(p.y);
        bottom = bottom.min(p.y);
        match columns
            .iter_mut()
            .find(|c| (c.0 - p.x).abs() <= tol && (c.1 - p.z).abs() <= tol)
        {
            Some(c) => (c.2, c.3) = (c.2.min(p.y), c.3.max(p.y)),
            None => columns.push((p.x, p.z, p.y, p.y)),
        }
    }
    let thin = columns
        .iter()
        .map(|c| c.3 - c.2)
        .fold(f64::INFINITY, f64::min);
    let thick = columns.iter().map(|c| c.3 - c.2).fold(0.0, f64::max);
    let has_girdle = !girdle.is_empty();
    let table = faces
        .iter()
        .find(|face| face.plane.is_some_and(|i| normal(i).y > 1.0 - 1e-12));
    let table_pct = table.map(|t| {
        let zs = t.points.iter().map(|p| p.z);
        pct(ys_span(zs))
    });
    let mut groups: Vec<(String, usize)> = vec![];
    let mut present: Vec<u32> = faces
        .iter()
        .filter_map(|face| face.plane.map(|i| f.planes[i].facet))
        .collect();
    present.sort_unstable();
    present.dedup();
    for &k in &present {
        let g = group(&f.names[k as usize]);
        match groups.iter_mut().find(|(n, _)| n == g) {
            Some((_, c)) => *c += 1,
            None => groups.push((g.to_string(), 1)),
        }
    }
    Proportions {
        length,
        width,
        depth_pct: pct(hi.y - lo.y),
        crown_pct: has_girdle.then(|| pct(hi.y - top)),
        pavilion_pct: has_girdle.then(|| pct(bottom - lo.y)),
        girdle_pct: has_girdle.then(|| (pct(thin), pct(thick))),
        table_pct,
        groups,
        facets: present.len(),
        volume: f.volume,
    }
}

impl Proportions {
    /// The proportions as `lapidary info` prints them, one item per line, indented by `indent`.
    pub fn describe(&self, indent: &str) -> String {
        let mut s = format!(
            "{indent}length × width {:.4} × {:.4} (ratio {:.3}), total depth {:.2} %",
            self.length,
            self.width,
            self.length / self.width,
            self.depth_pct
        );
        if let Some(t) = self.table_pct {
            s += &format!("\n{indent}table {t:.2} % (across z)");
        }
        if let (Some(c), Some(p), Some((thin, thick))) =
            (self.crown_pct, self.pavilion_pct, self.girdle_pct)
        {
            s += &format!(
                "\n{indent}crown height {c:.2} %, pavilion depth {p:.2} %, girdle {thin:.2} % to \
                 {thick:.2} %"
            );
        }
        let groups: Vec<String> = self
            .groups
            .iter()
            .map(|(g, n)| format!("{g} {n}"))
            .collect();
        s += &format!(
            "\n{indent}{} facets ({}); volume {:.4} units³",
            self.facets,
            groups.join(", "),
            self.volume
        );
        s
    }
}

fn ys_span(v: impl Iterator<Item = f64> + Clone) -> f64 {
    v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::{Brilliant, Cut};

    /// Against `assets/brilliant.obj`'s header (generated by `scripts/brilliant-mesh.py`, an
    /// independent construction): crown 15.12 %, pavilion 43.08 %, total depth 61.15 %, girdle
    /// 1.25 % to 2.95 % of the diameter; 57 facets and 32 girdle sides.
    #[test]
    fn the_brilliants_measured_proportions() {
        let b = Brilliant {
            girdle: 0.0125,
            girdle_facets: 32,
            ..Brilliant::default()
        };
        let f = Cut::Brilliant(b).facets(2.0).unwrap();
        let p = proportions(&f);
        assert!((p.width - 2.0).abs() < 1e-9 && (p.length - 2.0).abs() < 1e-9);
        assert!((p.depth_pct - 61.15).abs() < 0.006, "{p:?}");
        let (thin, thick) = p.girdle_pct.unwrap();
        assert!(
            (thin - 1.25).abs() < 0.006 && (thick - 2.95).abs() < 0.006,
            "{p:?}"
        );
        assert!((p.crown_pct.unwrap() - 15.12).abs() < 0.006, "{p:?}");
        assert!((p.pavilion_pct.unwrap() - 43.08).abs() < 0.006, "{p:?}");
        // The octagon's corners at 0 and 90°: 56 % across, as its parameter.
        assert!((p.table_pct.unwrap() - 56.0).abs() < 1e-6, "{p:?}");
        assert_eq!(p.facets, 57 + 32);
        let count = |g: &str| p.groups.iter().find(|(n, _)| n == g).map(|x| x.1);
        assert_eq!(count("star"), Some(8));
        assert_eq!(count("upper girdle"), Some(16));
        assert_eq!(count("girdle"), Some(32));
        assert_eq!(group("P1 @ 12"), "P1");
    }
}
