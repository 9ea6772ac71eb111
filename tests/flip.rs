//! Our HDR-FLIP (`src/image/flip.rs`) against NVIDIA's reference implementation: the values
//! below were computed with `flip-evaluator` 1.7 (PyPI; `flip_evaluator.evaluate(REF, TEST,
//! "HDR")`, default 67 ppd, ACES) on the RGB images in `tests/data/flip/` (copies of three of
//! our reference renders, 96×96). Regenerate the numbers with
//!
//! ```sh
//! pip install flip-evaluator numpy
//! python3 -c "import flip_evaluator as f; print(f.evaluate('tests/data/flip/sunstone.exr', \
//!     'tests/data/flip/sunstone-pink.exr', 'HDR', applyMagma=False)[1:])"
//! ```

use lapidary::image::flip::{DEFAULT_PPD, hdr_flip};
use lapidary::image::read_rgb;
use std::path::Path;

/// (reference, test, mean FLIP, exposures, start exposure, stop exposure) from flip-evaluator.
const OFFICIAL: [(&str, &str, f64, u32, f32, f32); 3] = [
    ("sunstone", "sunstone-pink", 0.145039, 2, 2.4860, 4.2184),
    (
        "lepidolite",
        "green-aventurine",
        0.222606,
        3,
        1.5209,
        4.2021,
    ),
    ("sunstone", "lepidolite", 0.224789, 2, 2.4860, 4.2184),
];

#[test]
fn hdr_flip_matches_the_reference_implementation() {
    let load = |n: &str| read_rgb(&Path::new("tests/data/flip").join(format!("{n}.exr"))).unwrap();
    for (r, t, mean, exposures, start, stop) in OFFICIAL {
        let (rr, tt) = (load(r), load(t));
        let f = hdr_flip(&tt.pixels, &rr.pixels, rr.width, rr.height, DEFAULT_PPD);
        eprintln!(
            "{t} vs {r}: ours {:.6} ({} exposures {:.4}..{:.4}), flip-evaluator {mean:.6}",
            f.flip.mean, f.exposures, f.start_exposure, f.stop_exposure
        );
        assert!(
            (f64::from(f.flip.mean) - mean).abs() < 2e-5,
            "{t} vs {r}: {} vs {mean}",
            f.flip.mean
        );
        assert_eq!(f.exposures, exposures);
        assert!((f.start_exposure - start).abs() < 1e-3 && (f.stop_exposure - stop).abs() < 1e-3);
    }
}
