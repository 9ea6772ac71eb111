//! Plots for `lapidary brdf --plot`: polar in-plane slices of `f·cos θi` at a few viewing angles and
//! the directional albedo curve, one colour per model. Uses plotters' bitmap backend with a bundled
//! font (DejaVu Sans, assets/), so no system font stack is needed.

use crate::bsdf::measure::{albedo_by_sampling, direction_deg};
use crate::bsdf::{Bxdf, LayeredBsdf, Model};
use anyhow::{Result, anyhow};
use glam::Vec3;
use plotters::prelude::*;
use rayon::prelude::*;
use std::path::Path;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Registers the bundled font as plotters' "sans-serif" (once per process).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bundled file is a valid TrueType font; a failure would only lose the labels.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

const SLICE_THETAS: [f32; 4] = [0.0, 30.0, 60.0, 80.0];
const COLOURS: [RGBColor; 3] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
];

fn model_label(m: Model) -> String {
    match m {
        Model::Reference(p) => format!("{m:#} ({} walks)", p.samples),
        _ => format!("{m:#}"),
    }
}

/// Draws the slices and albedo curves of `stacks` (one per model) to `path` (PNG, written
/// atomically).
pub fn plot_stack(
    name: &str,
    stacks: &[LayeredBsdf],
    samples: u64,
    seed: u64,
    path: &Path,
) -> Result<()> {
    register_font();
    // In-plane slices: wo at azimuth 0, wi over the plane φ ∈ {0, 180°}, signed θi.
    let slices: Vec<Vec<Vec<(f64, f64)>>> = SLICE_THETAS
        .iter()
        .map(|&to| {
            let wo = direction_deg(to, 0.0);
            stacks
                .par_iter()
                .map(|b| {
                    (-90..=90)
                        .map(|d| {
                            let t = (d as f32).to_radians();
                            let wi = Vec3::new(t.sin(), 0.0, t.cos().max(1e-4)).normalize();
                            let r = f64::from(b.eval(wo, wi).luminance() * wi.z).max(0.0);
                            (f64::from(t.sin()), r)
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let thetas: Vec<u32> = (0..90).step_by(3).collect();
    let albedos: Vec<Vec<(f64, f64)>> = stacks
        .iter()
        .map(|b| {
            thetas
                .par_iter()
                .map(|&t| {
                    let e = albedo_by_sampling(b, direction_deg(t as f32, 0.0), samples, seed);
                    (f64::from(t), f64::from(e.mean.luminance()))
                })
                .collect()
        })
        .collect();

    const W: u32 = 1600;
    const H: u32 = 960;
    let mut buf = vec![255u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| anyhow!("plot: {e:?}");
        root.fill(&WHITE).map_err(e)?;
        let root = root
            .titled(
                &format!("{name}: f·cos θi in the plane of incidence, and directional albedo"),
                ("sans-serif", 28),
            )
            .map_err(e)?;
        let (upper, lower) = root.split_vertically(470);
        let panels = upper.split_evenly((1, SLICE_THETAS.len()));
        for ((panel, &to), raw) in panels.iter().zip(SLICE_THETAS.iter()).zip(&slices) {
            // Near-mirror lobes span many decades: switch to a log radius from a tenth of the median.
            let peak = raw.iter().flatten().map(|p| p.1).fold(1e-12, f64::max);
            let mut positive: Vec<f64> = raw
                .iter()
                .flatten()
                .map(|p| p.1)
                .filter(|&v| v > 0.0)
                .collect();
            positive.sort_by(f64::total_cmp);
            let median = positive.get(positive.len() / 2).copied().unwrap_or(peak);
            let log = peak > 30.0 * median;
            let floor = (peak * 1e-4).min(median * 0.1).max(peak * 1e-9);
            let radius = |v: f64| if log { (v / floor).max(1.0).log10() } else { v };
            let curves: Vec<Vec<(f64, f64)>> = raw
                .iter()
                .map(|c| {
                    c.iter()
                        .map(|&(s, v)| (radius(v) * s, radius(v) * (1.0 - s * s).max(0.0).sqrt()))
                        .collect()
                })
                .collect();
            let rmax = curves
                .iter()
                .flatten()
                .map(|&(x, y)| x.hypot(y))
                .fold(1e-9, f64::max)
                * 1.05;
            let caption = if log {
                format!("θo = {to}°  log10 radius, peak {peak:.3e}")
            } else {
                format!("θo = {to}°  (max {peak:.3})")
            };
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, ("sans-serif", 20))
                .margin(12)
                .x_label_area_size(28)
                .y_label_area_size(48)
                .build_cartesian_2d(-rmax..rmax, 0.0..rmax)
                .map_err(e)?;
            chart
                .configure_mesh()
                .x_labels(5)
                .y_labels(5)
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(e)?;
            let (s, c) = (
                f64::from(to.to_radians().sin()),
                f64::from(to.to_radians().cos()),
            );
            chart
                .draw_series(LineSeries::new(
                    vec![(0.0, 0.0), (s * rmax, c * rmax)],
                    BLACK.mix(0.35).stroke_width(1),
                ))
                .map_err(e)?;
            for (i, curve) in curves.iter().enumerate().rev() {
                // Width 1: plotters joins wide polylines with mitres, which shoot off at a spike's 180° turn.
                chart
                    .draw_series(LineSeries::new(
                        curve.clone(),
                        COLOURS[i % 3].stroke_width(1),
                    ))
                    .map_err(e)?;
            }
        }
        let ymax = albedos.iter().flatten().map(|p| p.1).fold(1.05, f64::max) * 1.05;
        let mut chart = ChartBuilder::on(&lower)
            .caption(
                "directional albedo (luminance) against θo",
                ("sans-serif", 22),
            )
            .margin(16)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..90.0, 0.0..ymax)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("θo (degrees)")
            .y_desc("albedo")
            .draw()
            .map_err(e)?;
        chart
            .draw_series(LineSeries::new(
                vec![(0.0, 1.0), (90.0, 1.0)],
                BLACK.mix(0.3),
            ))
            .map_err(e)?;
        for (i, (curve, b)) in albedos.iter().zip(stacks).enumerate() {
            let colour = COLOURS[i % 3];
            chart
                .draw_series(LineSeries::new(curve.clone(), colour.stroke_width(2)))
                .map_err(e)?
                .label(model_label(b.model()))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
                });
        }
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.9))
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(e)?;
        root.present().map_err(e)?;
    }
    save_png(buf, W, H, path)
}

/// Encodes a plot's RGB8 buffer (`w × h`) as a PNG at `path`, written atomically: plotters draws
/// into the buffer, the `image` crate (PNG only) encodes it.
pub fn save_png(buf: Vec<u8>, w: u32, h: u32, path: &Path) -> Result<()> {
    Ok(crate::image::png::write_rgb8(path, w, h, buf)?)
}
