//! The plot of `lapidary tradeoff`: error against render time on log-log axes, one series per
//! setting (relMSE left, HDR-FLIP right), with the reference's own noise floor dashed. A biased
//! setting's curve flattens at its bias; an unbiased one keeps falling with slope −1 (relMSE)
//! until it meets the floor.

use super::plot::{register_font, save_png};
use super::tradeoff::row::Row;
use anyhow::{Result, anyhow};
use plotters::prelude::*;
use std::path::Path;

const W: u32 = 1400;
const H: u32 = 640;

/// Sixteen distinguishable colours (Tableau 10 and six more), cycled.
const COLOURS: [RGBColor; 16] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(120, 60, 0),
    RGBColor(0, 90, 50),
    RGBColor(90, 0, 140),
    RGBColor(255, 200, 0),
    RGBColor(0, 50, 160),
];

/// Log-axis range around the positive finite values of `v`, padded a little.
fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    if lo > hi {
        (1e-3, 1.0)
    } else {
        (lo / 1.5, hi * 1.5)
    }
}

/// Two significant digits, without trailing zeros (`0.23`, `5e-4`, `12`).
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if !(1e-2..1e4).contains(&v.abs()) {
        return format!("{v:.1e}").replace(".0e", "e");
    }
    let digits = (1 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Draws the two panels for `rows` to `path` (PNG, written atomically).
pub fn plot(name: &str, rows: &[Row], floor: f64, path: &Path) -> Result<()> {
    register_font();
    let mut buf = vec![255u8; (W * H * 3) as usize];
    {
        let e = |e: DrawingAreaErrorKind<_>| anyhow!("plot: {e:?}");
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let root = root
            .titled(
                &format!("{name}: error against render time (log-log)"),
                ("sans-serif", 24),
            )
            .map_err(e)?;
        let (left, right) = root.split_horizontally(W / 2);
        let floor_label = "reference noise (subtracted)";
        let times = range(rows.iter().flat_map(|r| r.curve.iter().map(|c| c.1)));
        for (panel, metric) in [(left, 0usize), (right, 1)] {
            let value = |c: &(u32, f64, crate::render::study::Errors)| {
                if metric == 0 { c.2.rel_mse } else { c.2.flip }
            };
            let mut ys = rows
                .iter()
                .flat_map(|r| r.curve.iter().map(value))
                .collect::<Vec<_>>();
            if metric == 0 {
                ys.push(floor);
            }
            let ys = range(ys.into_iter());
            let mut chart = ChartBuilder::on(&panel)
                .margin(16)
                .x_label_area_size(44)
                .y_label_area_size(70)
                .build_cartesian_2d((times.0..times.1).log_scale(), (ys.0..ys.1).log_scale())
                .map_err(e)?;
            chart
                .configure_mesh()
                .x_desc("render time (s)")
                .y_desc(if metric == 0 {
                    "relMSE"
                } else {
                    "mean HDR-FLIP"
                })
                .x_labels(8)
                .y_labels(8)
                .y_label_formatter(&|v| short(*v))
                .x_label_formatter(&|v| short(*v))
                .draw()
                .map_err(e)?;
            if metric == 0 && floor > 0.0 {
                let dashes: Vec<_> = (0..40)
                    .map(|k| {
                        let t = |k: f64| times.0 * (times.1 / times.0).powf(k / 40.0);
                        PathElement::new(
                            vec![(t(k as f64), floor), (t(k as f64 + 0.5), floor)],
                            BLACK.mix(0.5),
                        )
                    })
                    .collect();
                chart
                    .draw_series(dashes)
                    .map_err(e)?
                    .label(floor_label)
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.mix(0.5)));
            }
            for (i, r) in rows.iter().enumerate() {
                let colour = COLOURS[i % COLOURS.len()];
                let pts: Vec<(f64, f64)> = r
                    .curve
                    .iter()
                    .map(|c| (c.1, value(c)))
                    .filter(|p| p.0 > 0.0 && p.1 > 0.0 && p.1.is_finite())
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                    .map_err(e)?
                    .label(r.label.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
                    });
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                    .map_err(e)?;
            }
            if metric == 1 {
                chart
                    .configure_series_labels()
                    .border_style(BLACK)
                    .background_style(WHITE.mix(0.85))
                    .position(SeriesLabelPosition::LowerLeft)
                    .label_font(("sans-serif", 13))
                    .draw()
                    .map_err(e)?;
            }
        }
        root.present().map_err(e)?;
    }
    save_png(buf, W, H, path)
}
