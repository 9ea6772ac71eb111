//! Faceted stones: parametric cuts and GemCad designs as half-spaces (docs/cuts.md).
//!
//! A cut is a list of planes with names; the stone is the intersection of their half-spaces
//! ([`crate::geometry::Polytope`]). Conventions: object space, `y` up, the table toward `+y`, the
//! girdle's middle at `y = 0` and its centre on the `y` axis; the girdle width (the outline's
//! extent along `z`) is `width`, its length along `x` is `width · ratio`. A recipe gives the
//! crystal's directions (a platelet population's axis, later an optic axis) in this same frame, so
//! a stone's orientation in the rough is chosen relative to its cut: platelets aligned with `y`
//! lie parallel to the table and flash face-up.
//!
//! - [`outline`]: girdle outlines (round, oval, marquise, pear, cushion).
//! - [`brilliant`]: the 57/58-facet brilliant on any of them.
//! - [`step`]: step cuts (emerald, square/Asscher) and the princess.
//! - [`asc`]: GemCad `.asc` designs, read and written.
//! - [`metrics`]: proportions measured from the solid.

pub mod asc;
pub mod brilliant;
pub mod metrics;
pub mod outline;
pub mod step;

pub use brilliant::Brilliant;
pub use outline::Outline;
pub use step::Step;

use crate::geometry::FacetPlane;
use crate::geometry::shape::Facets;
use glam::DVec3;

/// A parametric cut.
#[derive(Clone, Debug, PartialEq)]
pub enum Cut {
    /// The brilliant family.
    Brilliant(Brilliant),
    /// Step cuts and the princess.
    Step(Step),
}

/// Why a cut cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct CutError(pub String);

impl Cut {
    /// The stone's facets at girdle width `width` (object units).
    pub fn facets(&self, width: f64) -> Result<Facets, CutError> {
        let (planes, names, label) = match self {
            Cut::Brilliant(b) => {
                let (p, n) = b.planes()?;
                (p, n, format!("{} brilliant", b.outline.name()))
            }
            Cut::Step(s) => {
                let (p, n) = s.planes()?;
                (p, n, s.label())
            }
        };
        // The designs are made at girdle width 2.
        let s = 0.5 * width;
        let planes = planes
            .into_iter()
            .map(|p| FacetPlane { d: p.d * s, ..p })
            .collect();
        let f = Facets::new(planes, names, label).map_err(|e| CutError(e.to_string()))?;
        // Girdle facets may vanish where the girdle thins to a knife edge; any other facet cut
        // away means the proportions contradict each other.
        let missing: Vec<u32> = f
            .missing()
            .into_iter()
            .filter(|&k| !f.names[k as usize].starts_with("girdle"))
            .collect();
        if let Some(&first) = missing.first() {
            return Err(CutError(format!(
                "the proportions cut away {} facet{} ({}{}): change the angles or lengths",
                missing.len(),
                if missing.len() == 1 { "" } else { "s" },
                f.names[first as usize],
                if missing.len() > 1 { ", …" } else { "" }
            )));
        }
        Ok(f)
    }
}

/// The facets of a GemCad design, scaled so that its girdle width — the smaller of its extents
/// along `x` and `z` — is `width` (object units). The design's centre stays at the origin.
pub fn design_facets(d: &asc::Design, width: f64, label: String) -> Result<Facets, CutError> {
    let b = d.builder().map_err(|e| CutError(e.to_string()))?;
    let unscaled = Facets::new(b.planes.clone(), b.names.clone(), label.clone())
        .map_err(|e| CutError(e.to_string()))?;
    let lo = unscaled
        .vertices
        .iter()
        .fold(DVec3::INFINITY, |a, v| a.min(*v));
    let hi = unscaled
        .vertices
        .iter()
        .fold(DVec3::NEG_INFINITY, |a, v| a.max(*v));
    let w = (hi.x - lo.x).min(hi.z - lo.z);
    if !(w > 0.0 && w.is_finite()) {
        return Err(CutError("the design has no girdle width".into()));
    }
    let s = width / w;
    let planes = b
        .planes
        .into_iter()
        .map(|p| FacetPlane { d: p.d * s, ..p })
        .collect();
    Facets::new(planes, b.names, label).map_err(|e| CutError(e.to_string()))
}

/// Collects named planes, each oriented away from a point inside the stone.
pub(crate) struct Builder {
    inside: DVec3,
    /// The planes so far.
    pub planes: Vec<FacetPlane>,
    /// Their names.
    pub names: Vec<String>,
}

impl Builder {
    /// An empty list; `inside` is a point strictly inside the stone.
    pub fn new(inside: DVec3) -> Builder {
        Builder {
            inside,
            planes: vec![],
            names: vec![],
        }
    }

    /// The facet through `a`, `b`, `c`.
    pub fn through(&mut self, a: DVec3, b: DVec3, c: DVec3, name: String) -> Result<(), CutError> {
        let p = FacetPlane::through(a, b, c, self.inside, self.names.len() as u32)
            .ok_or_else(|| CutError(format!("the {name} facet degenerates")))?;
        self.planes.push(p);
        self.names.push(name);
        Ok(())
    }

    /// The facet through `p` with normal `±n`, the sign that faces away from the inside point.
    pub fn facing_out(&mut self, n: DVec3, p: DVec3, name: String) -> Result<(), CutError> {
        let n = if n.dot(self.inside - p) > 0.0 { -n } else { n };
        self.with_normal(n, p, name)
    }

    /// The facet with outward normal `n` through `p`.
    pub fn with_normal(&mut self, n: DVec3, p: DVec3, name: String) -> Result<(), CutError> {
        let plane = FacetPlane::with_normal(n, p, self.names.len() as u32)
            .ok_or_else(|| CutError(format!("the {name} facet degenerates")))?;
        self.planes.push(plane);
        self.names.push(name);
        Ok(())
    }
}
