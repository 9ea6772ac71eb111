//! `lapidary cut` (issue 39): the cut report against what gemmology knows independently — a
//! brilliant cut to diamond's angles keeps the light in diamond (n 2.42) but leaks it through the
//! pavilion in glass (n 1.5: the pavilion mains at 40.75° lie inside glass's critical angle of
//! 41.8°, so light from the table passes through them — the "windowing" of a shallow-for-its-index
//! stone); the Oregon sunstone cut with its platelets parallel to the table shows the schiller
//! face-up and the one cut 30° off does not until tilted; the report is deterministic for any thread
//! count; bad tilts are refused with the range.

use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "common/csv_rows.rs"]
mod csv_rows;
use csv_rows::rows;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lapidary-cli-cut-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn stone(dir: &Path, name: &str, ior: f32) -> PathBuf {
    let p = dir.join(format!("{name}.ron"));
    std::fs::write(
        &p,
        format!(
            "(materials: {{}}, body: (ior: {ior}), surface: Body,\n \
             stage: (shape: Cut(Brilliant(width: 1.6)), render: (max_depth: 16)))"
        ),
    )
    .unwrap();
    p
}

fn cut(recipe: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("cut")
        .arg(recipe)
        .args(["--size", "64", "--spp", "16", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn a_diamond_cut_keeps_light_in_diamond_and_leaks_it_in_glass() {
    let dir = scratch("window");
    let diamond = stone(&dir, "diamond", 2.4175);
    let glass = stone(&dir, "glass", 1.5);
    for r in [&diamond, &glass] {
        let o = cut(r, &dir, &["--tilts", "0,20"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(
            stdout.contains("light return (ISO)") && stdout.contains("leakage"),
            "{stdout}"
        );
    }
    let d = rows(&dir.join("diamond-cut.csv"));
    let g = rows(&dir.join("glass-cut.csv"));
    assert_eq!((d.len(), g.len()), (2, 2));
    for r in d.iter().chain(&g) {
        let shares: f64 = ["aset_red", "aset_green", "aset_blue", "leakage"]
            .iter()
            .map(|k| r[*k])
            .sum();
        assert!((shares - 1.0).abs() < 1e-5, "{r:?}");
        assert!((0.0..=1.0).contains(&r["light_return_iso"]), "{r:?}");
    }
    let (d0, g0) = (&d[0], &g[0]);
    println!("face-up: diamond {d0:?}\n         glass   {g0:?}");
    // Leakage: significantly more in glass (5 standard errors of the difference).
    let diff = g0["leakage"] - d0["leakage"];
    let se = (g0["leakage_se"].powi(2) + d0["leakage_se"].powi(2)).sqrt();
    assert!(
        diff > 0.05 && diff > 5.0 * se,
        "leakage diamond {d0:?} glass {g0:?}"
    );
    let diff = d0["light_return_iso"] - g0["light_return_iso"];
    let se = (g0["light_return_iso_se"].powi(2) + d0["light_return_iso_se"].powi(2)).sqrt();
    assert!(
        diff > 0.1 && diff > 5.0 * se,
        "light return diamond {d0:?} glass {g0:?}"
    );
    assert!(dir.join("diamond-cut.png").is_file());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_report_is_the_same_for_any_thread_count() {
    let dir = scratch("threads");
    let r = stone(&dir, "stone", 1.76);
    let (a, b) = (dir.join("one"), dir.join("two"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    assert!(
        cut(&r, &a, &["--tilts", "0,15", "--threads", "1"])
            .status
            .success()
    );
    assert!(
        cut(&r, &b, &["--tilts", "0,15", "--threads", "2"])
            .status
            .success()
    );
    for f in ["stone-cut.csv", "stone-cut.png"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_tilts_are_refused_with_the_range() {
    let dir = scratch("bad");
    let r = stone(&dir, "stone", 1.5);
    for (tilts, want) in [
        ("70", "−60 ..= 60"),
        ("a", "−60 ..= 60"),
        ("0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16", "1 ..= 16"),
    ] {
        let o = cut(&r, &dir, &["--tilts", tilts]);
        assert!(!o.status.success());
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(want), "{tilts}: {e}");
    }
    assert!(!dir.join("stone-cut.csv").exists(), "nothing written");
    std::fs::remove_dir_all(&dir).ok();
}

/// The schiller share: the Oregon sunstone cut with its platelets parallel to the table flashes
/// face-up and less when tilted; the same stone cut 30° off (its platelets' normal leaning toward
/// +z) shows no flash face-up and one when tilted back toward its platelets, by −40° (each
/// comparison at 5 binomial standard errors).
#[test]
fn the_schiller_faces_up_only_in_the_stone_cut_for_it() {
    let dir = scratch("schiller");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut shares = vec![];
    for gem in ["oregon-sunstone-faceted", "oregon-sunstone-off-axis"] {
        let o = Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .arg("cut")
            .arg(root.join("gems").join(format!("{gem}.ron")))
            .args(["--size", "96", "--spp", "1", "--tilts=0,-40", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r = rows(&dir.join(format!("{gem}-cut.csv")));
        shares.push([
            (r[0]["schiller"], r[0]["schiller_se"]),
            (r[1]["schiller"], r[1]["schiller_se"]),
        ]);
    }
    println!(
        "schiller (0°, −40°): face-up cut {:?}, cut 30° off {:?}",
        shares[0], shares[1]
    );
    let more = |a: (f64, f64), b: (f64, f64)| a.0 - b.0 > 5.0 * (a.1 * a.1 + b.1 * b.1).sqrt();
    let ([up0, up40], [off0, off40]) = (shares[0], shares[1]);
    assert!(more(up0, off0), "face-up at 0°: {up0:?} vs {off0:?}");
    assert!(
        more(up0, up40),
        "the face-up cut tilted: {up0:?} vs {up40:?}"
    );
    assert!(
        more(off40, off0),
        "the off-axis cut tilted: {off40:?} vs {off0:?}"
    );
    // A stone without platelets has no schiller column value.
    let plain = stone(&dir, "plain", 1.5);
    assert!(cut(&plain, &dir, &["--tilts", "0"]).status.success());
    let text = std::fs::read_to_string(dir.join("plain-cut.csv")).unwrap();
    assert!(text.lines().nth(1).unwrap().ends_with(",,"), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}
