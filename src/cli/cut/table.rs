//! The cut report's table on stdout and its CSV.

use super::Row;
use super::report::Estimate;
use std::fmt::Write as _;

/// A value and its standard error, to a digit more where the error would print as 0.000.
fn pm(e: &Estimate) -> String {
    if e.se > 0.0 && e.se < 5e-4 {
        format!("{:.4} ± {:.4}", e.value, e.se)
    } else {
        format!("{:.3} ± {:.3}", e.value, e.se)
    }
}

/// Two tables: the light under the diffuse lightings, then the pattern, fire, scintillation and
/// schiller.
pub(super) fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "tilt   light return (ISO)   COS              ASET red        green           blue            leakage\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:>4}°  {:<20} {:<16} {:<15} {:<15} {:<15} {}",
            r.tilt,
            pm(&r.light_return),
            pm(&r.cos),
            pm(&r.aset[0]),
            pm(&r.aset[1]),
            pm(&r.aset[2]),
            pm(&r.aset[3]),
        );
    }
    s += "\ntilt   extinction      contrast        fire            sparkles    scintillation /°   schiller\n";
    for r in rows {
        let _ = writeln!(
            s,
            "{:>4}°  {:<15} {:<15} {:<15} {:<11} {:<18} {}",
            r.tilt,
            pm(&r.extinction),
            pm(&r.contrast),
            pm(&r.fire),
            format!("{:.0} ± {:.0}", r.sparkles.value, r.sparkles.se),
            pm(&r.scintillation),
            r.schiller.as_ref().map_or("–".to_string(), pm)
        );
    }
    s
}

/// One line per tilt; a value and its standard error in neighbouring columns.
pub(super) fn csv_text(rows: &[Row]) -> String {
    let mut s = String::from(
        "tilt_deg,light_return_iso,light_return_iso_se,cos,cos_se,aset_red,aset_red_se,\
         aset_green,aset_green_se,aset_blue,aset_blue_se,leakage,leakage_se,extinction,\
         extinction_se,contrast,contrast_se,fire,fire_se,sparkles,sparkles_se,sparkling,sparkling_se,\
         scintillation_per_deg,scintillation_per_deg_se,schiller,schiller_se\n",
    );
    for r in rows {
        let mut cells = vec![r.tilt.to_string()];
        let mut push = |e: &Estimate| {
            cells.push(format!("{:.6}", e.value));
            cells.push(format!("{:.6}", e.se));
        };
        for e in [&r.light_return, &r.cos].into_iter().chain(r.aset.iter()) {
            push(e);
        }
        for e in [&r.extinction, &r.contrast, &r.fire] {
            push(e);
        }
        cells.push(format!("{:.0}", r.sparkles.value));
        cells.push(format!("{:.1}", r.sparkles.se));
        let mut push = |e: &Estimate| {
            cells.push(format!("{:.6}", e.value));
            cells.push(format!("{:.6}", e.se));
        };
        push(&r.sparkling);
        push(&r.scintillation);
        // Empty cells for a stone without platelets.
        match &r.schiller {
            Some(e) => push(e),
            None => cells.extend([String::new(), String::new()]),
        }
        s += &cells.join(",");
        s.push('\n');
    }
    s
}
