//! The false-colour heatmap of a comparison's per-pixel error (`lapidary compare --heatmap`).

use super::ImageError;
use super::compare::{Comparison, Region};
use std::path::Path;

/// Control points of matplotlib's *viridis* colour map (van der Walt & Smith, 2015, CC0), evenly
/// spaced from 0 to 1, as 8-bit sRGB; perceptually uniform and readable in greyscale.
const VIRIDIS: [[u8; 3]; 9] = [
    [0x44, 0x01, 0x54],
    [0x47, 0x2d, 0x7b],
    [0x3b, 0x52, 0x8b],
    [0x2c, 0x72, 0x8e],
    [0x21, 0x91, 0x8c],
    [0x28, 0xae, 0x80],
    [0x5e, 0xc9, 0x62],
    [0xad, 0xdc, 0x30],
    [0xfd, 0xe7, 0x25],
];

/// The viridis colour of `v ∈ [0, 1]` (clamped; NaN gives the bottom), interpolated linearly in
/// sRGB between the control points.
pub fn viridis(v: f32) -> [u8; 3] {
    let v = if v > 0.0 { v.min(1.0) } else { 0.0 };
    let x = v * (VIRIDIS.len() - 1) as f32;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f32;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    [0, 1, 2].map(|c| (f32::from(a[c]) * (1.0 - f) + f32::from(b[c]) * f).round() as u8)
}

/// Writes the error map of `c` as an 8-bit sRGB PNG, atomically: each pixel's error divided by
/// `c.error_scale` (z_crit, or a relative error of 0.1) through [`viridis`], so the top colour
/// (yellow) marks failing pixels; non-finite values and failed pixels with an infinite error
/// are drawn white. The worst tile of each scale of the aggregate test that failed is outlined
/// in magenta ([`OUTLINE`]), so a bias no single pixel shows is still located.
pub fn write_heatmap(path: &Path, c: &Comparison) -> Result<(), ImageError> {
    if c.width == 0 || c.height == 0 {
        return Err(ImageError::Invalid {
            path: path.into(),
            reason: format!("size {}×{}", c.width, c.height),
        });
    }
    if c.error_map.len() as u64 != u64::from(c.width) * u64::from(c.height) {
        return Err(ImageError::SizeMismatch {
            path: path.into(),
            what: "error map".into(),
            len: c.error_map.len(),
            width: c.width,
            height: c.height,
        });
    }
    let scale = if c.error_scale > 0.0 {
        c.error_scale
    } else {
        1.0
    };
    let mut bytes: Vec<u8> = c
        .error_map
        .iter()
        .flat_map(|&e| {
            if e.is_finite() {
                viridis(e / scale)
            } else {
                [255; 3]
            }
        })
        .collect();
    for region in failed_tiles(c) {
        outline(&mut bytes, c.width, region);
    }
    super::png::write_rgb8(path, c.width, c.height, bytes)
}

/// The colour of a failing tile's outline (sRGB magenta).
pub const OUTLINE: [u8; 3] = [255, 0, 255];

/// The worst tile of every failed scale of the aggregate test (materials have no outline).
fn failed_tiles(c: &Comparison) -> Vec<Region> {
    c.ztest
        .iter()
        .flat_map(|z| z.failed_scales())
        .filter_map(|s| s.worst.map(|w| w.region))
        .filter(|r| matches!(r, Region::Rect { .. }))
        .collect()
}

/// Draws the one-pixel border of `region` into the RGB bytes of a `width`-wide image.
fn outline(bytes: &mut [u8], width: u32, region: Region) {
    let Region::Rect {
        x,
        y,
        width: w,
        height: h,
    } = region
    else {
        return;
    };
    if w == 0 || h == 0 {
        return;
    }
    for py in y..y + h {
        for px in x..x + w {
            if px == x || py == y || px == x + w - 1 || py == y + h - 1 {
                let i = 3 * (py as usize * width as usize + px as usize);
                if let Some(p) = bytes.get_mut(i..i + 3) {
                    p.copy_from_slice(&OUTLINE);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::compare::compare;
    use crate::image::{Channel, ExrImage};

    fn grey(rgb: Vec<f32>) -> ExrImage {
        ExrImage {
            width: rgb.len() as u32,
            height: 1,
            channels: ["R", "G", "B"].map(|n| Channel::new(n, rgb.clone())).into(),
            attributes: vec![],
        }
    }

    #[test]
    fn heatmap_is_a_png_of_the_image_size() {
        let dir = std::env::temp_dir().join(format!("lapidary-compare-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("heat.png");
        let t = grey(vec![1.0, 2.0, f32::NAN]);
        let c = compare(&t, &grey(vec![1.0; 3])).unwrap();
        write_heatmap(&path, &c).unwrap();
        let png = ::image::open(&path).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), (3, 1));
        assert_eq!(png.get_pixel(0, 0).0, VIRIDIS[0]);
        assert_eq!(png.get_pixel(1, 0).0, VIRIDIS[8]);
        assert_eq!(png.get_pixel(2, 0).0, [255; 3]);
        assert_eq!(viridis(0.5), VIRIDIS[4]);
        assert_eq!(viridis(f32::NAN), VIRIDIS[0]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_worst_tile_of_a_failed_scale_is_outlined() {
        let dir = std::env::temp_dir().join(format!("lapidary-outline-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("heat.png");
        // 24 × 24 with σ = 0.1 per image: the 8 × 8 block at (8, 16) is +0.05, z = 0.5 per
        // pixel but 0.5 · √64 = 4 over its 8² tile (limit ≈ 3.7), 2.8 over the 16² tile and 1.3
        // over the image (both pass).
        let (w, h) = (24u32, 24u32);
        let img = |shift: bool| {
            let rgb: Vec<f32> = (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    let lit = shift && (8..16).contains(&x) && (16..24).contains(&y);
                    if lit { 1.05 } else { 1.0 }
                })
                .collect();
            let mut e = ExrImage {
                width: w,
                height: h,
                channels: ["R", "G", "B"].map(|n| Channel::new(n, rgb.clone())).into(),
                attributes: vec![],
            };
            for n in ["variance.R", "variance.G", "variance.B"] {
                e.channels
                    .push(Channel::new(n, vec![0.005; (w * h) as usize]));
            }
            e
        };
        let c = compare(&img(true), &img(false)).unwrap();
        let z = c.ztest.as_ref().unwrap();
        assert!(z.pixels_passed && !z.passed, "{z:?}");
        write_heatmap(&path, &c).unwrap();
        let png = ::image::open(&path).unwrap().to_rgb8();
        // The 8² tile's border is magenta; its inside and the rest keep their colours.
        let failed: Vec<String> = z.failed_scales().map(|s| s.label()).collect();
        assert_eq!(failed, ["8x8"]);
        for (x, y) in [(8, 16), (15, 16), (8, 23), (15, 20)] {
            assert_eq!(png.get_pixel(x, y).0, OUTLINE, "({x}, {y})");
        }
        assert_ne!(png.get_pixel(11, 19).0, OUTLINE);
        assert_ne!(png.get_pixel(0, 0).0, OUTLINE);
        assert_ne!(png.get_pixel(7, 16).0, OUTLINE);
        // Nothing outlined when every scale passes.
        let c = compare(&img(false), &img(false)).unwrap();
        write_heatmap(&path, &c).unwrap();
        let png = ::image::open(&path).unwrap().to_rgb8();
        assert!(png.pixels().all(|p| p.0 != OUTLINE));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
