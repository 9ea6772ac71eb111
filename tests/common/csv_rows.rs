//! A CSV with a header line read as one map from column to value per row (`#[path]`-included by
//! `cli_cut` and `cut_report`); a cell that is not a number (an empty one) reads as NaN.

use std::collections::HashMap;
use std::path::Path;

/// The rows of the CSV file at `csv`.
pub fn rows(csv: &Path) -> Vec<HashMap<String, f64>> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            head.iter()
                .zip(l.split(','))
                .map(|(k, v)| (k.to_string(), v.parse().unwrap_or(f64::NAN)))
                .collect()
        })
        .collect()
}
