//! The two CSV files of `lapidary tradeoff`: a row per setting (`tradeoff.csv`) and a row per
//! capture (`tradeoff-curves.csv`).

use super::row::{Row, at_spp};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

pub(super) fn summary_csv(spp: u32, budget: f64, rows: &[Row]) -> String {
    let mut o = String::from(
        "setting,setup_s,paths_per_s,equal_spp,equal_spp_time_s,equal_spp_relmse,\
         equal_spp_relmse_raw,equal_spp_flip,equal_spp_energy,equal_time_budget_s,equal_time_spp,\
         equal_time_s,equal_time_relmse,equal_time_relmse_raw,equal_time_flip,equal_time_energy,\
         bias_relmse\n",
    );
    let num = |v: Option<f64>| {
        v.filter(|v| v.is_finite())
            .map_or(String::new(), |v| format!("{v:.6e}"))
    };
    for r in rows {
        let eq = at_spp(r, spp);
        let _ = writeln!(
            o,
            "\"{}\",{:.4},{:.0},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.label,
            r.setup,
            r.paths_per_second,
            spp,
            num(eq.map(|e| e.0)),
            num(eq.map(|e| e.1.rel_mse)),
            num(eq.map(|e| e.1.rel_mse_raw)),
            num(eq.map(|e| e.1.flip)),
            num(eq.map(|e| e.1.stone_ratio)),
            budget,
            r.last.map_or(String::new(), |l| l.0.to_string()),
            num(r.last.map(|l| l.1)),
            num(r.last.map(|l| l.2.rel_mse)),
            num(r.last.map(|l| l.2.rel_mse_raw)),
            num(r.last.map(|l| l.2.flip)),
            num(r.last.map(|l| l.2.stone_ratio)),
            num(r.bias),
        );
    }
    o
}

pub(super) fn curves_csv(rows: &[Row]) -> String {
    let mut o = String::from("setting,spp,time_s,relmse,relmse_raw,flip,energy\n");
    for r in rows {
        for (spp, t, e) in &r.curve {
            let _ = writeln!(
                o,
                "\"{}\",{spp},{t:.6},{:.6e},{:.6e},{:.6e},{:.6}",
                r.label, e.rel_mse, e.rel_mse_raw, e.flip, e.stone_ratio
            );
        }
    }
    o
}

pub(super) fn write_csv(path: &Path, text: &str) -> Result<()> {
    crate::image::write_atomically(path, |sink| {
        use std::io::Write as _;
        sink.write_all(text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
    })
}
