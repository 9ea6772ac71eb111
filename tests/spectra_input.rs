//! Spectra as a user gives them, through the binary: CSV files whose first row is data, trailing
//! comments, errors that name the CSV file and line of the offending row, readable ranges, and
//! narrow lines that keep their area wherever they fall on the 10 nm grid.

#[path = "common/scratch.rs"]
mod scratch;

use lapidary::image::read_rgb;
use scratch::{Scratch, text};
use std::process::{Command, Output, Stdio};

/// Runs `lapidary ARGS…` in `dir`.
fn lapidary(dir: &Scratch, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(&dir.0)
        .stdin(Stdio::null())
        .output()
        .expect("binary runs")
}

/// Asserts exit status 1 and returns stderr.
fn refused(out: &Output) -> String {
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr:\n{err}");
    err
}

/// Asserts exit status 0.
fn ok(out: &Output) {
    assert_eq!(out.status.code(), Some(0), "stderr:\n{}", text(&out.stderr));
}

/// A recipe of one Lambert material whose albedo is `albedo`.
fn albedo_recipe(albedo: &str) -> String {
    format!(
        "(\n    materials: {{ \"a\": (base: Lambert(albedo: {albedo})) }},\n    \
         surface: Material(\"a\"),\n)\n"
    )
}

#[test]
fn a_first_row_of_data_is_refused_at_its_csv_line_not_taken_as_a_header() {
    let dir = Scratch::new("spectra-input", "first-row");
    std::fs::create_dir_all(dir.path("gems")).unwrap();
    std::fs::create_dir_all(dir.path("spectra")).unwrap();
    std::fs::write(
        dir.path("gems/r.ron"),
        albedo_recipe("Spectrum(\"../spectra/x.csv\")"),
    )
    .unwrap();
    for (csv, at, found) in [
        (
            "0x190,0.1\n500,0.2\n600,0.3\n",
            1,
            "wavelength `0x190` is not a decimal number",
        ),
        (
            "4_00,0.1\n500,0.2\n600,0.3\n",
            1,
            "wavelength `4_00` is not a decimal number",
        ),
        (
            "# R of a card\n\n400,0.1\n500,0x2\n",
            4,
            "value `0x2` is not a decimal number",
        ),
    ] {
        std::fs::write(dir.path("spectra/x.csv"), csv).unwrap();
        let err = refused(&lapidary(&dir, &["check", "gems/r.ron"]));
        // The path as the user finds it from where they ran the command, and the row's line.
        let want = format!("gems/../spectra/x.csv:{at}: {found}");
        assert!(err.contains(&want), "{csv:?}: wanted `{want}` in:\n{err}");
        assert!(err.contains("expected `wavelength_nm,value`"), "{err}");
    }
}

#[test]
fn trailing_comments_are_read_as_comments() {
    let dir = Scratch::new("spectra-input", "comments");
    std::fs::write(
        dir.path("x.csv"),
        "  # a card, measured\n400,0.1 # blue\n550, 0.4   # green\n700,0.6#red\n",
    )
    .unwrap();
    std::fs::write(dir.path("file.ron"), albedo_recipe("Spectrum(\"x.csv\")")).unwrap();
    std::fs::write(
        dir.path("inline.ron"),
        albedo_recipe("Spectrum([(400, 0.1), (550, 0.4), (700, 0.6)])"),
    )
    .unwrap();
    let materials = |name: &str| {
        let out = lapidary(&dir, &["info", name]);
        ok(&out);
        text(&out.stdout)
            .lines()
            .find(|l| l.contains("Lambert ["))
            .unwrap_or_else(|| panic!("no material row in {}", text(&out.stdout)))
            .to_string()
    };
    assert_eq!(materials("file.ron"), materials("inline.ron"));
}

#[test]
fn errors_in_the_points_name_the_csv_file_and_line() {
    let dir = Scratch::new("spectra-input", "point-lines");
    std::fs::write(dir.path("r.ron"), albedo_recipe("Spectrum(\"x.csv\")")).unwrap();
    for (csv, want) in [
        (
            "wavelength_nm,value\n400,0.1\n# a note\n510,0.2\n500,0.3\n",
            "x.csv:5: wavelength 500 nm does not increase (after 510 nm)",
        ),
        (
            "400,0.1\n500,1.5\n",
            "x.csv:2: value 1.5 at 500 nm is out of range: allowed 0 ..= 1",
        ),
        (
            "400,0.1\n\n\n500,0.2\n2500,0.2\n",
            "x.csv:5: wavelength 2500 nm is out of range: allowed 200 ..= 2000",
        ),
    ] {
        std::fs::write(dir.path("x.csv"), csv).unwrap();
        let err = refused(&lapidary(&dir, &["check", "r.ron"]));
        assert!(err.contains(want), "{csv:?}: wanted `{want}` in:\n{err}");
    }
}

/// A recipe with a fluorescent base whose colorant's emission spectrum is `emission`.
fn fluorescent_recipe(emission: &str) -> String {
    format!(
        "(\n    materials: {{ \"a\": (base: Lambert(albedo: Gray(0.8), fluorescence: (\n        \
         excitation: [(400, 0.0), (450, 0.8), (500, 0.0)],\n        emission: {emission},\n        \
         quantum_yield: 0.9,\n    ))) }},\n    surface: Material(\"a\"),\n)\n"
    )
}

#[test]
fn an_emission_spectrum_without_an_upper_bound_says_so_in_words() {
    let dir = Scratch::new("spectra-input", "emission-range");
    std::fs::write(dir.path("e.csv"), "500,0\n550,2e6\n600,-1\n").unwrap();
    std::fs::write(dir.path("r.ron"), fluorescent_recipe("\"e.csv\"")).unwrap();
    let err = refused(&lapidary(&dir, &["check", "r.ron"]));
    assert!(
        err.contains(
            "base.fluorescence.emission: e.csv:3: value -1 at 600 nm is out of range: allowed \
             any finite value ≥ 0"
        ),
        "{err}"
    );
    assert!(!err.contains("340282"), "{err}");
}

/// Mean luminance (Rec.709) of a small spectral render of a grey floor lit only by a light whose
/// spectrum is a 0.2 nm line at `centre` nm (256 spp: the two lines' renders differ by 1e-5 ..
/// 8e-5 over seeds, at 16 spp by 1.2e-3 of sampling noise).
fn floor_under_a_line(dir: &Scratch, centre: f32) -> f64 {
    let name = format!("line-{centre}");
    let recipe = format!(
        "(\n    materials: {{ \"a\": (base: Lambert(albedo: Gray(0.5))) }},\n    \
         surface: Material(\"a\"),\n    stage: (\n        shape: Sphere(radius: 0.2),\n        \
         ground: Plane(height: -1.0, albedo: Gray(0.5)),\n        \
         environment: Constant(Gray(0.0)),\n        \
         lights: [Rect(center: (0, 3, 0), target: (0, 0, 0), size: (2, 2), radiance: Gray(3), \
         spectrum: [({}, 0), ({centre}, 40), ({}, 0)])],\n        \
         camera: Orthographic(from: (0, 5, 0), to: (0, 0, 0), up: (0, 0, -1), height: 3.0),\n    \
         ),\n)\n",
        centre - 0.1,
        centre + 0.1
    );
    std::fs::write(dir.path(&format!("{name}.ron")), recipe).unwrap();
    let out = lapidary(
        dir,
        &[
            "render",
            &format!("{name}.ron"),
            "--size",
            "48x48",
            "--spp",
            "256",
            "--seed",
            "3",
            "--no-png",
            "--quiet",
            "-o",
            &format!("{name}.exr"),
        ],
    );
    ok(&out);
    let img = read_rgb(&dir.path(&format!("{name}.exr"))).unwrap();
    let sum: f64 = img
        .pixels
        .iter()
        .map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
        .sum();
    sum / img.pixels.len() as f64
}

#[test]
fn a_narrow_line_is_kept_wherever_it_falls() {
    let dir = Scratch::new("spectra-input", "narrow-line");
    // As a light's spectrum: 0.2 nm at 555.0 nm (between the old resampling's midpoint samples)
    // lights the floor as the same line at 555.5 nm does.
    let (a, b) = (
        floor_under_a_line(&dir, 555.0),
        floor_under_a_line(&dir, 555.5),
    );
    assert!(
        a > 0.0 && ((a - b) / b).abs() < 1e-3,
        "555.0 nm: {a}, 555.5 nm: {b}"
    );
    // As a fluorescent colorant's emission: a lone narrow line is a shape, not "zero".
    for centre in [555.0, 700.0] {
        let line = format!(
            "[({}, 0), ({centre}, 1), ({}, 0)]",
            centre - 0.1,
            centre + 0.1
        );
        std::fs::write(dir.path("f.ron"), fluorescent_recipe(&line)).unwrap();
        ok(&lapidary(&dir, &["check", "f.ron"]));
    }
}
