//! Serde description of a faceted stone's cut (`shape: Cut(…)`), range-checked as it is read;
//! [`CutDesc::to_cut`] gives the runtime [`crate::cut::Cut`]. Percentages are of the girdle
//! width; angles are degrees to the girdle plane.
//!
//! ```ron
//! shape: Cut(Brilliant(outline: Oval(ratio: 1.35), width: 2.0, table: 57.0, crown: 34.0)),
//! shape: Cut(Emerald(ratio: 1.4, corner: 15.0, crown: [50.0, 40.0, 30.0], pavilion: [60.0, 50.0, 42.0])),
//! ```

use super::ranged::refuse;
use crate::cut::step::StepKind;
use crate::cut::{Brilliant, Cut, Outline, Step};
use serde::{Deserialize, Deserializer, Serialize};

ranged!(width_range, "width", open 0.0, 1e4);
ranged!(ratio_range, "ratio", 1.0, 3.0);
ranged!(table_range, "table", 40.0, 80.0);
ranged!(crown_range, "crown", 20.0, 45.0);
ranged!(pavilion_range, "pavilion", 35.0, 50.0);
ranged!(girdle_range, "girdle", 0.0, 10.0);
ranged!(star_range, "star", 30.0, 70.0);
ranged!(lower_range, "lower_girdle", 50.0, 95.0);
ranged!(culet_range, "culet", 0.0, 10.0);
ranged!(corner_range, "corner", 0.0, 35.0);
ranged!(step_table_range, "table", 20.0, 90.0);

/// The girdle outline of a brilliant.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum OutlineDesc {
    /// A circle.
    Round,
    /// An ellipse (the round design stretched).
    Oval {
        /// Length over width, 1 ..= 3.
        #[serde(deserialize_with = "ratio_range")]
        ratio: f32,
    },
    /// A navette.
    Marquise {
        /// Length over width, 1 ..= 3.
        #[serde(deserialize_with = "ratio_range")]
        ratio: f32,
    },
    /// A half circle and a point.
    Pear {
        /// Length over width, 1 ..= 3.
        #[serde(deserialize_with = "ratio_range")]
        ratio: f32,
    },
    /// A rounded rectangle.
    Cushion {
        /// Length over width, 1 ..= 3.
        #[serde(deserialize_with = "ratio_range")]
        ratio: f32,
    },
}

fn round() -> OutlineDesc {
    OutlineDesc::Round
}
fn two() -> f32 {
    2.0
}
fn table() -> f32 {
    56.0
}
fn crown() -> f32 {
    34.5
}
fn pavilion() -> f32 {
    40.75
}
fn girdle() -> f32 {
    2.5
}
fn star() -> f32 {
    50.0
}
fn lower() -> f32 {
    77.0
}
fn girdle_facets() -> u32 {
    64
}

/// A brilliant (defaults: Tolkowsky's angles with a 56 % table, as `assets/brilliant.obj`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrilliantDesc {
    /// Girdle outline (default `Round`).
    #[serde(default = "round")]
    pub outline: OutlineDesc,
    /// Girdle width in object units (default 2).
    #[serde(default = "two", deserialize_with = "width_range")]
    pub width: f32,
    /// Table, % of the width corner to corner, 40 ..= 80 (default 56).
    #[serde(default = "table", deserialize_with = "table_range")]
    pub table: f32,
    /// Crown (bezel) angle, 20 ..= 45° (default 34.5).
    #[serde(default = "crown", deserialize_with = "crown_range")]
    pub crown: f32,
    /// Pavilion angle, 35 ..= 50° (default 40.75).
    #[serde(default = "pavilion", deserialize_with = "pavilion_range")]
    pub pavilion: f32,
    /// Girdle thickness at its thinnest, % of the width, 0 ..= 10 (default 2.5).
    #[serde(default = "girdle", deserialize_with = "girdle_range")]
    pub girdle: f32,
    /// Star length, %, 30 ..= 70 (default 50).
    #[serde(default = "star", deserialize_with = "star_range")]
    pub star: f32,
    /// Lower-girdle length, %, 50 ..= 95 (default 77).
    #[serde(default = "lower", deserialize_with = "lower_range")]
    pub lower_girdle: f32,
    /// Culet, % of the width, 0 ..= 10 (default 0: pointed).
    #[serde(default, deserialize_with = "culet_range")]
    pub culet: f32,
    /// Girdle facets, a multiple of 16 in 16 ..= 256 (default 64).
    #[serde(default = "girdle_facets", deserialize_with = "girdle_facet_count")]
    pub girdle_facets: u32,
}

fn girdle_facet_count<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = u32::deserialize(d)?;
    if (16..=256).contains(&v) && v % 16 == 0 {
        Ok(v)
    } else {
        refuse(
            format!("girdle_facets = {v} is out of range: a multiple of 16 in 16 ..= 256"),
            64,
        )
    }
}

/// A step cut or princess.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepDesc {
    /// Girdle width in object units (default 2).
    #[serde(default = "two", deserialize_with = "width_range")]
    pub width: f32,
    /// Length over width, 1 ..= 3 (default: 1.4 for the emerald, 1 for the others; the square
    /// cuts take 1 whatever is given).
    #[serde(default, deserialize_with = "optional_ratio")]
    pub ratio: Option<f32>,
    /// Corner legs, % of the width, 0 ..= 35 (default: 15 emerald, 25 square, 0 princess).
    #[serde(default, deserialize_with = "optional_corner")]
    pub corner: Option<f32>,
    /// Table, % of the width, 20 ..= 90 (default 60).
    #[serde(default = "step_table", deserialize_with = "step_table_range")]
    pub table: f32,
    /// Crown rows' angles from the girdle in, falling, each 5 ..= 80° (1 ..= 8 rows).
    #[serde(default, deserialize_with = "angles")]
    pub crown: Option<Vec<f32>>,
    /// Pavilion rows' angles from the girdle in, falling, each 5 ..= 80° (1 ..= 8 rows).
    #[serde(default, deserialize_with = "angles")]
    pub pavilion: Option<Vec<f32>>,
    /// Girdle thickness, % of the width, 0 ..= 10 (default 2).
    #[serde(default = "step_girdle", deserialize_with = "girdle_range")]
    pub girdle: f32,
}

fn step_table() -> f32 {
    60.0
}
fn step_girdle() -> f32 {
    2.0
}

fn optional_ratio<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    ratio_range(d).map(Some)
}
fn optional_corner<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    corner_range(d).map(Some)
}

fn angles<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<f32>>, D::Error> {
    let v = Vec::<f32>::deserialize(d)?;
    if v.is_empty() || v.len() > 8 {
        return refuse(
            format!("{} rows: allowed 1 ..= 8", v.len()),
            Some(vec![45.0]),
        );
    }
    if let Some(a) = v.iter().find(|a| !(5.0..=80.0).contains(*a)) {
        return refuse(
            format!("row angle {a} is out of range: allowed 5 ..= 80"),
            Some(vec![45.0]),
        );
    }
    if v.windows(2).any(|w| w[1] >= w[0]) {
        return refuse(
            format!(
                "row angles {v:?}: each row must be flatter than the one before it (falling from \
                 the girdle inward)"
            ),
            Some(vec![45.0]),
        );
    }
    Ok(Some(v))
}

/// A parametric cut.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CutDesc {
    /// The brilliant family.
    Brilliant(BrilliantDesc),
    /// A rectangular step cut with cut corners.
    Emerald(StepDesc),
    /// A square step cut with cut corners (Asscher).
    Square(StepDesc),
    /// A square brilliant-like step cut whose pavilion closes in a point.
    Princess(StepDesc),
}

impl CutDesc {
    /// The runtime cut and its girdle width.
    pub fn to_cut(&self) -> (Cut, f64) {
        let f = |x: f32| f64::from(x);
        match self {
            CutDesc::Brilliant(b) => {
                let outline = match b.outline {
                    OutlineDesc::Round => Outline::Round,
                    OutlineDesc::Oval { ratio } => Outline::Oval { ratio: f(ratio) },
                    OutlineDesc::Marquise { ratio } => Outline::Marquise { ratio: f(ratio) },
                    OutlineDesc::Pear { ratio } => Outline::Pear { ratio: f(ratio) },
                    OutlineDesc::Cushion { ratio } => Outline::Cushion { ratio: f(ratio) },
                };
                let cut = Cut::Brilliant(Brilliant {
                    outline,
                    table: f(b.table) / 100.0,
                    crown: f(b.crown),
                    pavilion: f(b.pavilion),
                    girdle: f(b.girdle) / 100.0,
                    star: f(b.star) / 100.0,
                    lower_girdle: f(b.lower_girdle) / 100.0,
                    culet: f(b.culet) / 100.0,
                    girdle_facets: b.girdle_facets,
                });
                (cut, f(b.width))
            }
            CutDesc::Emerald(s) | CutDesc::Square(s) | CutDesc::Princess(s) => {
                let (kind, ratio, corner, crown, pavilion) = match self {
                    CutDesc::Emerald(_) => (
                        StepKind::Emerald,
                        s.ratio.unwrap_or(1.4),
                        s.corner.unwrap_or(15.0),
                        vec![50.0, 40.0, 30.0],
                        vec![55.0, 45.0, 38.0],
                    ),
                    CutDesc::Square(_) => (
                        StepKind::Square,
                        1.0,
                        s.corner.unwrap_or(25.0),
                        vec![50.0, 40.0, 30.0],
                        vec![55.0, 45.0, 38.0],
                    ),
                    _ => (
                        StepKind::Princess,
                        1.0,
                        s.corner.unwrap_or(0.0),
                        vec![45.0, 32.0],
                        vec![62.0, 52.0, 42.0],
                    ),
                };
                let list = |v: &Option<Vec<f32>>, d: Vec<f64>| {
                    v.as_ref()
                        .map_or(d, |v| v.iter().map(|&a| f64::from(a)).collect())
                };
                let cut = Cut::Step(Step {
                    kind,
                    ratio: f(ratio),
                    corner: f(corner) / 100.0,
                    table: f(s.table) / 100.0,
                    crown: list(&s.crown, crown),
                    pavilion: list(&s.pavilion, pavilion),
                    girdle: f(s.girdle) / 100.0,
                });
                (cut, f(s.width))
            }
        }
    }
}
