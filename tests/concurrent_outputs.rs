//! Two runs writing the same outputs at once leave the pair of one run: the EXR and the PNG on
//! disk always come from the same render. Each try starts renders of different seeds to the
//! same `-o` at the same moment (three runs, seeds 1, 2, 3); afterwards the PNG must be exactly
//! the tone-mapped colour of the EXR beside it. Without the lock around the renames
//! (src/image/atomic/lock.rs) 3 of 40 such tries mixed two runs on this machine.

use lapidary::image::{ToneMap, read_exr, tone_map_pixel};
use std::process::{Command, Stdio};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};

const RECIPE: &str = r#"(
    materials: { "a": (coats: [(ior: 1.5, roughness: 8.0)], base: Lambert(albedo: Gray(0.5))) },
    surface: Material("a"),
    stage: (ground: Off),
)"#;

/// Tries of three concurrent renders.
const TRIES: usize = 40;

#[test]
fn concurrent_runs_never_mix_their_outputs() {
    let s = Scratch::new("concurrent", "pairs");
    std::fs::write(s.path("gem.ron"), RECIPE).unwrap();
    let mut mixed = vec![];
    for t in 0..TRIES {
        let children: Vec<_> = ["1", "2", "3"]
            .iter()
            .map(|seed| {
                Command::new(env!("CARGO_BIN_EXE_lapidary"))
                    .args([
                        "render", "gem.ron", "-o", "out.exr", "--size", "24x16", "--spp", "2",
                    ])
                    .args(["--quiet", "--seed", seed])
                    .current_dir(&s.0)
                    .stdin(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let out = c.wait_with_output().unwrap();
            assert!(out.status.success(), "{}", text(&out.stderr));
        }
        let exr = read_exr(&s.path("out.exr")).unwrap();
        let (r, g, b) = (
            exr.channel("R").unwrap(),
            exr.channel("G").unwrap(),
            exr.channel("B").unwrap(),
        );
        let want: Vec<u8> = (0..r.len())
            .flat_map(|i| tone_map_pixel([r[i], g[i], b[i]], &ToneMap::default()))
            .collect();
        let png = image::open(s.path("out.png")).unwrap().to_rgb8();
        if png.as_raw() != &want {
            mixed.push(t);
        }
    }
    assert!(
        mixed.is_empty(),
        "tries {mixed:?} of {TRIES} left the EXR of one run and the PNG of the other"
    );
}
