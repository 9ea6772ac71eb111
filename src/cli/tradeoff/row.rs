//! One studied setting of `lapidary tradeoff` and its measurements: what the table, the CSV
//! files and the plot are made from.

use crate::render::study::Errors;

/// One studied setting and its measurements.
#[derive(Clone, Debug)]
pub struct Row {
    /// The setting as written.
    pub label: String,
    /// Seconds to build the world (material tables).
    pub setup: f64,
    /// Paths per second over the whole render.
    pub paths_per_second: f64,
    /// Each capture's spp, seconds and errors.
    pub curve: Vec<(u32, f64, Errors)>,
    /// The equal-time capture.
    pub last: Option<(u32, f64, Errors)>,
    /// The relMSE left with infinitely many samples: the intercept `b` of a least-squares fit
    /// `relMSE ≈ a / spp + b` over the captures from 16 spp (the bias of an approximation; ≈ 0
    /// for an unbiased setting).
    pub bias: Option<f64>,
}

/// The capture at `spp` samples per pixel: its seconds and errors.
pub(super) fn at_spp(row: &Row, spp: u32) -> Option<(f64, Errors)> {
    row.curve
        .iter()
        .find(|(s, _, _)| *s == spp)
        .map(|&(_, t, e)| (t, e))
}
