//! The false-colour heatmap of a comparison's per-pixel error (`lapidary compare --heatmap`).

use super::ImageError;
use super::compare::Comparison;
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
/// are drawn white.
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
    let bytes: Vec<u8> = c
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
    super::png::write_rgb8(path, c.width, c.height, bytes)
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
}
