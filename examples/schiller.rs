//! Schiller, measured (issue 18): render platelet gems over a sweep of stone tilts and plot the
//! stone's mean luminance against the tilt.
//!
//! ```text
//! cargo build --release && cargo run --release --example schiller -- \
//!     [--bin target/release/lapidary] [--size 64x48] [--spp 64] [--from -20] [--to 60] [--step 5] \
//!     [--out docs/images/schiller.png] [GEM.ron ...]
//! ```
//!
//! Default gems: `gems/oregon-sunstone.ron` and `gems/aventurine-glass.ron`. Each gem is copied
//! into a temporary folder with its `stage` replaced by a measuring stage — no ground, a dark
//! constant sky, one small disc light 40° from the vertical in the y–z plane, an orthographic
//! camera looking straight down — and the stone rotated about the x axis by the tilt
//! (`stage.transform.rotate`). The inputs are never written. Each copy is rendered with the release
//! binary (EXR only); the stone's pixels are those whose `depth.Z` is positive (a camera ray hit
//! something: with no ground, the stone), and their mean luminance (Rec. 709 Y) is the curve.
//!
//! The mirror configuration of a platelet normal tilted by θ about x, `(0, cos θ, sin θ)`, is the
//! bisector of the view direction (+y) and the light direction (40° from +y towards +z): θ = 20°.
//! Platelets parallel to the cabochon's base are, at that tilt, parallel to the dome's surface
//! where it faces the bisector; there refraction bends the view and light rays symmetrically and
//! the mirror condition inside the stone is the one in air.
//!
//! Prints a table and a CSV (`tilt,gem,mean_y,stone_pixels`) and writes the plot.

use lapidary::image::exr::read_exr;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Light elevation from the vertical, degrees (the mirror tilt is half of it).
const LIGHT_FROM_VERTICAL: f64 = 40.0;

struct Args {
    bin: PathBuf,
    size: String,
    spp: u32,
    from: i32,
    to: i32,
    step: i32,
    out: PathBuf,
    gems: Vec<PathBuf>,
}

fn parse_args() -> Args {
    let mut a = Args {
        bin: PathBuf::from("target/release/lapidary"),
        size: "64x48".into(),
        spp: 64,
        from: -20,
        to: 60,
        step: 5,
        out: PathBuf::from("docs/images/schiller.png"),
        gems: Vec::new(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut val = || it.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        match arg.as_str() {
            "--bin" => a.bin = val().into(),
            "--size" => a.size = val(),
            "--spp" => a.spp = val().parse().expect("--spp: a number"),
            "--from" => a.from = val().parse().expect("--from: degrees"),
            "--to" => a.to = val().parse().expect("--to: degrees"),
            "--step" => a.step = val().parse().expect("--step: degrees"),
            "--out" => a.out = val().into(),
            _ => a.gems.push(arg.into()),
        }
    }
    if a.gems.is_empty() {
        a.gems = vec![
            "gems/oregon-sunstone.ron".into(),
            "gems/aventurine-glass.ron".into(),
        ];
    }
    assert!(a.step > 0 && a.to >= a.from, "bad sweep");
    a
}

/// Byte range of the top-level `stage: ( … )` field of a recipe, skipping comments and strings.
fn stage_span(text: &str) -> Option<(usize, usize)> {
    let b = text.as_bytes();
    let (mut i, mut depth) = (0, 0i32);
    let mut start = None;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'(' | b'[' | b'{' => {
                depth += 1;
                if depth == 2 && start.is_some_and(|(_, open)| open == 0) {
                    start = start.map(|(s, _)| (s, i));
                }
            }
            b')' | b']' | b'}' => {
                if depth == 2
                    && let Some((s, open)) = start
                    && open != 0
                {
                    return Some((s, i + 1));
                }
                depth -= 1;
            }
            b's' if depth == 1 && text[i..].starts_with("stage") => {
                let rest = text[i + 5..].trim_start();
                if rest.starts_with(':') {
                    start = Some((i, 0));
                }
            }
            _ => {}
        }
        i += 1;
    }
    None
}

fn measuring_stage(tilt: i32, size: &str, spp: u32) -> String {
    let (w, h) = size.split_once('x').expect("--size WxH");
    let t = LIGHT_FROM_VERTICAL.to_radians();
    format!(
        "stage: (\n\
         transform: (rotate: ({tilt}.0, 0.0, 0.0)),\n\
         ground: Off,\n\
         environment: Constant(Gray(0.02)),\n\
         lights: [Disc(center: (0.0, {:.4}, {:.4}), target: (0.0, 0.0, 0.0), radius: 0.25, radiance: Gray(2000.0))],\n\
         camera: Orthographic(from: (0.0, 10.0, 0.0), to: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), height: 2.4),\n\
         render: (width: {w}, height: {h}, spp: {spp}, max_depth: 16),\n\
         )",
        10.0 * t.cos(),
        10.0 * t.sin()
    )
}

/// Mean Rec. 709 luminance over the pixels whose `depth.Z` is positive, and their count.
fn stone_mean(exr: &Path) -> (f64, usize) {
    let img = read_exr(exr).unwrap_or_else(|e| panic!("{}: {e}", exr.display()));
    let ch = |n: &str| img.channel(n).unwrap_or_else(|| panic!("no {n} channel"));
    let (r, g, b, z) = (ch("R"), ch("G"), ch("B"), ch("depth.Z"));
    let (mut sum, mut n) = (0.0f64, 0usize);
    for i in 0..z.len() {
        if z[i] > 0.0 {
            sum += 0.2126 * r[i] as f64 + 0.7152 * g[i] as f64 + 0.0722 * b[i] as f64;
            n += 1;
        }
    }
    (if n > 0 { sum / n as f64 } else { 0.0 }, n)
}

fn main() {
    let a = parse_args();
    let tmp = std::env::temp_dir().join(format!("lapidary-schiller-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).expect("temp dir");
    let tilts: Vec<i32> = (a.from..=a.to).step_by(a.step as usize).collect();
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    println!("tilt,gem,mean_y,stone_pixels");
    for gem in &a.gems {
        let name = gem.file_stem().unwrap().to_string_lossy().to_string();
        let text = std::fs::read_to_string(gem).expect("read the gem");
        let mut curve = Vec::new();
        for &t in &tilts {
            let stage = measuring_stage(t, &a.size, a.spp);
            let copy = match stage_span(&text) {
                Some((s, e)) => format!("{}{}{}", &text[..s], stage, &text[e..]),
                None => {
                    let close = text.rfind(')').expect("a recipe ends with `)`");
                    format!("{}    {stage},\n{}", &text[..close], &text[close..])
                }
            };
            let recipe = tmp.join(format!("{name}_{t}.ron"));
            std::fs::write(&recipe, copy).expect("write the copy");
            let exr = tmp.join(format!("{name}_{t}.exr"));
            let status = Command::new(&a.bin)
                .arg("render")
                .arg(&recipe)
                .arg("-o")
                .arg(&exr)
                .args(["--no-png", "-q"])
                .status()
                .expect("run lapidary");
            assert!(status.success(), "render of {} failed", recipe.display());
            let (m, n) = stone_mean(&exr);
            println!("{t},{name},{m:.6},{n}");
            curve.push((t as f64, m));
        }
        curves.push((name, curve));
    }
    println!(
        "\nmirror configuration: tilt {:.1}°",
        LIGHT_FROM_VERTICAL / 2.0
    );
    for (name, c) in &curves {
        let (pt, pm) = c
            .iter()
            .copied()
            .fold((0.0, f64::MIN), |b, p| if p.1 > b.1 { p } else { b });
        let mut ys: Vec<f64> = c.iter().map(|p| p.1).collect();
        ys.sort_by(|x, y| x.total_cmp(y));
        let median = ys[ys.len() / 2];
        let far: Vec<f64> = c
            .iter()
            .filter(|p| (p.0 - pt).abs() >= 15.0)
            .map(|p| p.1)
            .collect();
        let far_mean = far.iter().sum::<f64>() / far.len().max(1) as f64;
        println!(
            "{name}: peak at tilt {pt}° (Y {pm:.4}); peak / median {:.2}; peak / mean of tilts ≥ 15° from the peak {:.2}; min {:.4}",
            pm / median,
            pm / far_mean,
            ys[0]
        );
    }
    plot(&curves, &a.out, LIGHT_FROM_VERTICAL / 2.0);
    println!("wrote {}", a.out.display());
    let _ = std::fs::remove_dir_all(&tmp);
}

fn plot(curves: &[(String, Vec<(f64, f64)>)], out: &Path, mirror: f64) {
    static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let xs = curves.iter().flat_map(|c| c.1.iter().map(|p| p.0));
    let (x0, x1) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    let y1 = curves
        .iter()
        .flat_map(|c| c.1.iter().map(|p| p.1))
        .fold(0.0f64, f64::max)
        * 1.1;
    const W: u32 = 800;
    const H: u32 = 500;
    let mut buf = vec![0u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        root.fill(&WHITE).unwrap();
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "Schiller: stone mean luminance vs tilt (light 40° from vertical, camera overhead)",
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, 0.0..y1.max(1e-6))
            .unwrap();
        chart
            .configure_mesh()
            .x_desc("stone tilt about x (degrees)")
            .y_desc("mean luminance of the stone's pixels")
            .draw()
            .unwrap();
        chart
            .draw_series(LineSeries::new(
                vec![(mirror, 0.0), (mirror, y1)],
                BLACK.mix(0.4).stroke_width(1),
            ))
            .unwrap()
            .label(format!("platelets' mirror tilt ({mirror}°)"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.4)));
        let colours = [
            RGBColor(214, 39, 40),
            RGBColor(31, 119, 180),
            RGBColor(44, 160, 44),
        ];
        for (i, (name, c)) in curves.iter().enumerate() {
            let col = colours[i % colours.len()];
            chart
                .draw_series(LineSeries::new(c.clone(), col.stroke_width(2)))
                .unwrap()
                .label(name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                });
            chart
                .draw_series(c.iter().map(|&p| Circle::new(p, 3, col.filled())))
                .unwrap();
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .unwrap();
        root.present().unwrap();
    }
    lapidary::cli::plot::save_png(buf, W, H, out).expect("write the plot");
}
