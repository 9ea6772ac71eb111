//! End-to-end tests of `lapidary compare` through the built binary: renders of a small coated
//! scene against a high-spp reference (pass, and fail on a changed IOR or a 10 % gain), exit
//! status 2 with a message for unusable input, the relMSE verdict without variance, the heatmap;
//! the aggregate (bias) test per scale, bad variances as unusable input, the mean ratio.

use lapidary::image::{Channel, ExrImage, read_exr, write_exr};
use std::process::{Command, Output, Stdio};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};

/// A coated grey Lambertian filling a 32×24 image; the independent sampler keeps the per-pixel
/// sample variances honest for the z-test.
fn recipe(ior: f32) -> String {
    format!(
        "(materials: {{ \"a\": (coats: [(ior: {ior:?}, roughness: 8.0)], \
         base: Lambert(albedo: Gray(0.5))) }}, surface: Material(\"a\"), \
         stage: (render: (width: 32, height: 24, sampler: Independent)))"
    )
}

impl Scratch {
    /// Renders the scene with coat `ior` at `spp` and `seed` to `name`.
    fn render(&self, name: &str, ior: f32, spp: u32, seed: u64) {
        let ron = self.path(&format!("{name}.ron"));
        std::fs::write(&ron, recipe(ior)).unwrap();
        let (spp, seed) = (spp.to_string(), seed.to_string());
        let out = Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .args([
                "render", "--quiet", "--no-png", "--spp", &spp, "--seed", &seed,
            ])
            .arg(&ron)
            .arg("-o")
            .arg(self.path(name))
            .stdin(Stdio::null())
            .output()
            .expect("binary runs");
        assert!(out.status.success(), "render: {}", text(&out.stderr));
    }

    /// Runs `lapidary compare TEST REF EXTRA…` (file names in the scratch directory).
    fn compare(&self, test: &str, reference: &str, extra: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .arg("compare")
            .arg(self.path(test))
            .arg(self.path(reference))
            .args(extra)
            .current_dir(&self.0)
            .stdin(Stdio::null())
            .output()
            .expect("binary runs")
    }
}

/// Asserts the exit code and returns stdout.
fn status(out: &Output, code: i32) -> String {
    assert_eq!(
        out.status.code(),
        Some(code),
        "stdout:\n{}\nstderr:\n{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    text(&out.stdout)
}

/// The value after `label` on its report line.
fn field<'a>(report: &'a str, label: &str) -> &'a str {
    report
        .lines()
        .find_map(|l| l.trim_start().strip_prefix(label))
        .unwrap_or_else(|| panic!("no {label} line in\n{report}"))
        .trim()
}

fn exr(s: &Scratch, name: &str) -> ExrImage {
    read_exr(&s.path(name)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn identical_images_pass_with_zero_error() {
    let s = Scratch::new("cli-compare", "identical");
    s.render("ref.exr", 1.5, 16, 0);
    let report = status(&s.compare("ref.exr", "ref.exr", &[]), 0);
    assert!(report.starts_with(&format!(
        "{} vs {} (32x24)\n",
        s.path("ref.exr").display(),
        s.path("ref.exr").display()
    )));
    for label in ["RMSE", "relMSE", "MAE"] {
        assert_eq!(field(&report, label).parse::<f64>(), Ok(0.0), "{report}");
    }
    assert!(field(&report, "PSNR").starts_with("inf"), "{report}");
    assert!(field(&report, "FLIP").starts_with("0.0000 "), "{report}");
    assert!(field(&report, "z-test").starts_with("100.00% of 768 pixels pass"));
    assert_eq!(field(&report, "verdict"), "PASS");
}

#[test]
fn low_spp_render_passes_against_a_high_spp_reference_and_writes_a_heatmap() {
    let s = Scratch::new("cli-compare", "pass");
    s.render("ref.exr", 1.5, 1024, 0);
    s.render("test.exr", 1.5, 64, 3);
    let report = status(
        &s.compare("test.exr", "ref.exr", &["--heatmap", "diff.png"]),
        0,
    );
    assert!(field(&report, "RMSE").parse::<f64>().unwrap() > 0.0);
    let z = field(&report, "z-test");
    assert!(
        z.contains("(need 99.75%)") && z.contains("Šidák"),
        "{report}"
    );
    assert_eq!(field(&report, "verdict"), "PASS");
    let png = image::open(s.path("diff.png")).unwrap();
    assert_eq!((png.width(), png.height()), (32, 24));
    assert!(field(&report, "heatmap").contains("diff.png"), "{report}");
}

#[test]
fn changed_ior_fails() {
    let s = Scratch::new("cli-compare", "ior");
    s.render("ref.exr", 1.5, 1024, 0);
    s.render("test.exr", 1.8, 256, 3);
    let report = status(&s.compare("test.exr", "ref.exr", &[]), 1);
    assert!(field(&report, "verdict").starts_with("FAIL ("), "{report}");
}

#[test]
fn ten_percent_brighter_fails_and_still_writes_the_heatmap() {
    let s = Scratch::new("cli-compare", "gain");
    s.render("ref.exr", 1.5, 1024, 0);
    let mut img = exr(&s, "ref.exr");
    for c in img
        .channels
        .iter_mut()
        .filter(|c| ["R", "G", "B"].contains(&&*c.name))
    {
        c.data.iter_mut().for_each(|v| *v *= 1.1);
    }
    write_exr(&s.path("bright.exr"), &img).unwrap();
    let out = s.compare("bright.exr", "ref.exr", &["--heatmap", "diff.png"]);
    let report = status(&out, 1);
    assert!(
        field(&report, "verdict").contains("fail the z-test"),
        "{report}"
    );
    let png = image::open(s.path("diff.png")).unwrap();
    assert_eq!((png.width(), png.height()), (32, 24));
    // FLIP sees a 10 % brighter image as a small but clear perceptual difference.
    let flip: f64 = field(&report, "FLIP")
        .split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .expect("a FLIP value");
    assert!(flip > 0.005 && flip < 0.2, "FLIP {flip}");
}

#[test]
fn unusable_inputs_exit_2_naming_the_file() {
    let s = Scratch::new("cli-compare", "unusable");
    let rgb = |w: u32, h: u32, names: &[&str]| ExrImage {
        width: w,
        height: h,
        channels: names
            .iter()
            .map(|n| Channel::new(*n, vec![0.5; (w * h) as usize]))
            .collect(),
        attributes: vec![],
    };
    write_exr(&s.path("a.exr"), &rgb(4, 3, &["R", "G", "B"])).unwrap();
    write_exr(&s.path("small.exr"), &rgb(3, 3, &["R", "G", "B"])).unwrap();
    write_exr(&s.path("nob.exr"), &rgb(4, 3, &["R", "G", "A"])).unwrap();
    std::fs::write(s.path("text.exr"), "not an image").unwrap();
    let cases = [
        ("small.exr", "a.exr", "sizes differ"),
        ("missing.exr", "a.exr", "missing.exr: no such file"),
        ("a.exr", "missing.exr", "missing.exr: no such file"),
        ("text.exr", "a.exr", "text.exr: not a readable OpenEXR file"),
        ("a.exr", "nob.exr", "nob.exr: no channel `B`"),
    ];
    for (test, reference, message) in cases {
        let out = s.compare(test, reference, &["--heatmap", "diff.png"]);
        assert_eq!(status(&out, 2), "", "{test} vs {reference}");
        let err = text(&out.stderr);
        assert!(err.starts_with("error: ") && err.contains(message), "{err}");
    }
    assert!(!s.path("diff.png").exists());
    let out = s.compare("small.exr", "a.exr", &[]);
    let err = text(&out.stderr);
    assert!(
        err.contains("is 3x3 but") && err.contains("a.exr is 4x3"),
        "{err}"
    );
}

#[test]
fn without_variance_the_verdict_comes_from_rel_mse() {
    use exr::prelude::{f16, write_rgb_file};
    let s = Scratch::new("cli-compare", "novariance");
    let value = |x: usize, y: usize, gain: f32| f16::from_f32(gain * (0.1 + 0.01 * (x + y) as f32));
    for (name, gain) in [("ref.exr", 1.0), ("same.exr", 1.0), ("bright.exr", 1.1)] {
        write_rgb_file(s.path(name), 8, 4, |x, y| {
            (value(x, y, gain), value(x, y, gain), value(y, x, gain))
        })
        .unwrap();
    }
    let report = status(&s.compare("same.exr", "ref.exr", &[]), 0);
    let z = field(&report, "z-test");
    assert!(
        z.starts_with("skipped: the reference has no variance"),
        "{report}"
    );
    assert!(z.contains("verdict from relMSE ≤ 1e-3"), "{report}");
    assert_eq!(field(&report, "verdict"), "PASS");
    let report = status(&s.compare("bright.exr", "ref.exr", &[]), 1);
    assert!(
        field(&report, "verdict").starts_with("FAIL (relMSE"),
        "{report}"
    );
}

/// `img` with R, G, B multiplied by `gain`.
fn brightened(mut img: ExrImage, gain: f32) -> ExrImage {
    for c in img
        .channels
        .iter_mut()
        .filter(|c| ["R", "G", "B"].contains(&&*c.name))
    {
        c.data.iter_mut().for_each(|v| *v *= gain);
    }
    img
}

#[test]
fn a_bias_within_every_pixels_noise_fails_the_aggregate_test() {
    // A 256-spp render 10 % brighter, against itself: no pixel's z reaches the limit (each
    // has about 15 % noise), but the mean over tiles and the whole image moves far beyond it.
    let s = Scratch::new("cli-compare", "bias");
    s.render("ref.exr", 1.5, 256, 0);
    write_exr(&s.path("bright.exr"), &brightened(exr(&s, "ref.exr"), 1.1)).unwrap();
    let out = s.compare("bright.exr", "ref.exr", &["--heatmap", "bias.png"]);
    let report = status(&out, 1);
    // No pixel is yellow, but the worst failing tiles are outlined in magenta.
    let png = image::open(s.path("bias.png")).unwrap().to_rgb8();
    let magenta = png.pixels().filter(|p| p.0 == [255, 0, 255]).count();
    assert!(magenta >= 2 * 32 + 2 * 22, "{magenta} outline pixels");
    assert!(
        field(&report, "heatmap").contains("magenta = worst failing tile"),
        "{report}"
    );
    assert!(
        field(&report, "z-test").starts_with("100.00% of 768 pixels pass"),
        "{report}"
    );
    assert!(
        field(&report, "bias").contains("α 0.01 shared by 4 scales (Šidák)"),
        "{report}"
    );
    // The 16² and 8² tiles (partial at the bottom: 32 × 24) and the materials (stone, floor).
    let material = field(&report, "material");
    assert!(
        material.starts_with("2 materials ") && material.contains("of the pixels of material "),
        "{material}"
    );
    for (label, tiles) in [
        ("image", "1 tile "),
        ("16x16", "4 tiles "),
        ("8x8", "12 tiles "),
    ] {
        let line = field(&report, label);
        assert!(line.starts_with(tiles), "{line}");
        assert!(
            line.contains("|z| max ") && line.contains("limit "),
            "{line}"
        );
        assert!(
            line.contains("FAIL (") && line.contains("tile at ("),
            "{line}"
        );
    }
    assert!(
        field(&report, "verdict").starts_with("FAIL (bias at image: |z| "),
        "{report}"
    );
    // The same file against itself passes every scale.
    let report = status(&s.compare("ref.exr", "ref.exr", &[]), 0);
    for label in ["image", "16x16", "8x8", "material"] {
        assert!(field(&report, label).ends_with("pass"), "{report}");
    }
}

#[test]
fn a_nan_infinite_or_negative_variance_is_unusable_input() {
    let s = Scratch::new("cli-compare", "badvar");
    s.render("ref.exr", 1.5, 16, 0);
    for (k, bad) in [f32::NAN, f32::INFINITY, -1e-3].into_iter().enumerate() {
        let mut img = exr(&s, "ref.exr");
        let var = img
            .channels
            .iter_mut()
            .find(|c| c.name == "variance.G")
            .unwrap();
        var.data[32 * 5 + 7] = bad;
        let name = format!("bad{k}.exr");
        write_exr(&s.path(&name), &img).unwrap();
        // As the test, as the reference, and against itself: exit 2, never a verdict.
        for (t, r) in [(&*name, "ref.exr"), ("ref.exr", &*name), (&*name, &*name)] {
            let out = s.compare(t, r, &[]);
            assert_eq!(status(&out, 2), "", "{t} vs {r}");
            let err = text(&out.stderr);
            assert!(
                err.contains(&format!("{name}: `variance.G` is {bad} at pixel (7, 5)")),
                "{err}"
            );
            assert!(err.contains("must be finite and ≥ 0"), "{err}");
        }
    }
}

#[test]
fn without_variance_a_one_percent_bias_fails_on_the_mean_ratio() {
    let s = Scratch::new("cli-compare", "meanratio");
    s.render("ref.exr", 1.5, 64, 0);
    let strip = |img: ExrImage| ExrImage {
        channels: img
            .channels
            .into_iter()
            .filter(|c| ["R", "G", "B"].contains(&&*c.name))
            .collect(),
        ..img
    };
    let reference = strip(exr(&s, "ref.exr"));
    write_exr(&s.path("plain.exr"), &reference).unwrap();
    write_exr(&s.path("bright.exr"), &brightened(reference, 1.01)).unwrap();
    // relMSE of a 1 % gain is 1e-4, below its 1e-3 threshold; the mean ratio 1.01 is not.
    let report = status(&s.compare("bright.exr", "plain.exr", &[]), 1);
    assert!(
        field(&report, "relMSE").parse::<f64>().unwrap() < 1e-3,
        "{report}"
    );
    let mean = field(&report, "mean");
    assert!(
        mean.starts_with("test/reference R 1.0100  G 1.0100  B 1.0100 (tolerance ±0.5 %, FAIL)"),
        "{report}"
    );
    assert!(
        field(&report, "verdict").starts_with("FAIL (mean ratio R 1.0100 outside 1 ± 0.005"),
        "{report}"
    );
    let report = status(
        &s.compare("bright.exr", "plain.exr", &["--mean-tolerance", "0.02"]),
        0,
    );
    assert!(
        field(&report, "mean").ends_with("(tolerance ±2 %, pass)"),
        "{report}"
    );
    for bad in ["1.5", "-0.01", "inf", "0.5%"] {
        let out = s.compare(
            "bright.exr",
            "plain.exr",
            &[&format!("--mean-tolerance={bad}")],
        );
        assert_eq!(status(&out, 2), "");
        assert!(text(&out.stderr).contains("is not a fraction in [0, 1]"));
    }
}
