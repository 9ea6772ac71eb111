//! The aggregate (bias) test: the z-score of the summed difference over tiles at several scales,
//! `z = Σ(t − r)/√Σ(var_t + var_r)` per tile and channel, which sees a shift far below the noise
//! of single pixels.

use super::planes::Pixel;
use super::{AGGREGATE_ALPHA, Rgb, ScaleTest, TILE_BLOCKS, TileZ};
use crate::image::stats::{normal_quantile_two_sided, sidak};

/// The tile sides tested on a `width × height` image: the whole image (`None`) and each of
/// [`TILE_BLOCKS`] that splits it into more than one tile.
pub fn scales_of(width: u32, height: u32) -> Vec<Option<u32>> {
    std::iter::once(None)
        .chain(
            TILE_BLOCKS
                .iter()
                .filter(|&&b| b < width || b < height)
                .map(|&b| Some(b)),
        )
        .collect()
}

/// The tile tests of `px` (row-major, `width × height`) at every scale of [`scales_of`], the
/// family-wise [`AGGREGATE_ALPHA`] split over the scales by Šidák.
pub(super) fn tile_tests(px: &[Pixel], width: u32, height: u32) -> Vec<ScaleTest> {
    let scales = scales_of(width, height);
    let alpha = sidak(AGGREGATE_ALPHA, scales.len());
    scales
        .into_iter()
        .map(|block| scale_test(px, width, height, block, alpha))
        .collect()
}

/// One scale: tiles of `block × block` pixels from the top left (the last row and column
/// partial), or the whole image for `None`.
fn scale_test(px: &[Pixel], width: u32, height: u32, block: Option<u32>, alpha: f64) -> ScaleTest {
    let (bw, bh) = match block {
        Some(b) => (b.max(1), b.max(1)),
        None => (width.max(1), height.max(1)),
    };
    let (nx, ny) = (width.div_ceil(bw) as usize, height.div_ceil(bh) as usize);
    // Per tile and channel: Σ(t − r) and Σ(var_t + var_r) over the usable pixel channels with
    // variance (zero-variance channels are checked exactly per pixel; failed pixels fail there).
    let mut sums = vec![[(0.0f64, 0.0f64); 3]; nx * ny];
    for (i, p) in px.iter().enumerate() {
        let Pixel::Usable { diff, var, .. } = p else {
            continue;
        };
        let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
        let tile = &mut sums[(y / bh) as usize * nx + (x / bw) as usize];
        for c in 0..3 {
            if var[c] > 0.0 {
                tile[c].0 += diff[c];
                tile[c].1 += var[c];
            }
        }
    }
    let tested = sums.iter().flatten().filter(|(_, v)| *v > 0.0).count();
    let z_crit = normal_quantile_two_sided(sidak(alpha, tested));
    let (mut worst, mut failed) = (None::<TileZ>, 0usize);
    for (k, tile) in sums.iter().enumerate() {
        for (c, &(d, v)) in tile.iter().enumerate() {
            if v <= 0.0 {
                continue;
            }
            let z = d / v.sqrt();
            if z.abs() > z_crit {
                failed += 1;
            }
            if worst.as_ref().is_none_or(|w| z.abs() > w.z.abs()) {
                let (x, y) = ((k % nx) as u32 * bw, (k / nx) as u32 * bh);
                worst = Some(TileZ {
                    x,
                    y,
                    width: bw.min(width - x),
                    height: bh.min(height - y),
                    channel: Rgb::ALL[c],
                    z,
                });
            }
        }
    }
    ScaleTest {
        block,
        tiles: nx * ny,
        tested,
        alpha,
        z_crit,
        max_abs_z: worst.as_ref().map_or(0.0, |w| w.z.abs()),
        worst,
        failed,
        passed: failed == 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> (f64, f64)) -> Vec<Pixel> {
        (0..w * h)
            .map(|i| {
                let (d, v) = f(i % w, i / w);
                Pixel::Usable {
                    diff: [d, 0.0, d],
                    var: [v, v, 0.0],
                    exact_mismatch: false,
                }
            })
            .collect()
    }

    #[test]
    fn scales_drop_blocks_that_cover_the_image() {
        assert_eq!(scales_of(96, 96), vec![None, Some(32), Some(16), Some(8)]);
        assert_eq!(scales_of(20, 12), vec![None, Some(16), Some(8)]);
        assert_eq!(scales_of(8, 8), vec![None]);
        assert_eq!(scales_of(40, 1), vec![None, Some(32), Some(16), Some(8)]);
    }

    #[test]
    fn tiles_sum_differences_and_variances_with_partial_edges() {
        // 20 × 12 with a difference of 0.01 and variance 1e-4 everywhere: a whole-image
        // z = 240 · 0.01 / √(240 · 1e-4) = √240 ≈ 15.5 in R; G has variance but no difference,
        // B no variance (not tested).
        let px = image(20, 12, |_, _| (0.01, 1e-4));
        let s = tile_tests(&px, 20, 12);
        assert_eq!(s.len(), 3);
        let alpha = sidak(AGGREGATE_ALPHA, 3);
        let whole = &s[0];
        assert_eq!((whole.tiles, whole.tested, whole.block), (1, 2, None));
        assert!((whole.max_abs_z - 240f64.sqrt()).abs() < 1e-9);
        assert!((whole.alpha - alpha).abs() < 1e-15);
        assert_eq!(whole.z_crit, normal_quantile_two_sided(sidak(alpha, 2)));
        assert!(!whole.passed);
        // 16²: tiles 16×12 and a partial 4×12 (z = √48 ≈ 6.9); both in R fail.
        let w16 = &s[1];
        assert_eq!((w16.tiles, w16.tested, w16.failed), (2, 4, 2));
        let worst = w16.worst.unwrap();
        assert_eq!(
            (worst.x, worst.y, worst.width, worst.height),
            (0, 0, 16, 12)
        );
        assert_eq!(worst.channel, Rgb::R);
        assert!((worst.z - 192f64.sqrt()).abs() < 1e-9);
        // 8²: 3 × 2 tiles, the corner one 4 × 4.
        assert_eq!(s[2].tiles, 6);
    }

    #[test]
    fn noise_passes_and_a_local_shift_fails_only_where_it_is_seen() {
        // ±1σ alternating noise passes everywhere; a +0.75σ shift of one 8×8 block (z = 6 there,
        // 3 over its 16² tile, 0.75 over the image) fails at 8² only.
        let noise = |x: u32, y: u32| if (x + y) % 2 == 0 { 0.01 } else { -0.01 };
        let px = image(64, 64, |x, y| (noise(x, y), 1e-4));
        assert!(
            tile_tests(&px, 64, 64)
                .iter()
                .all(|s| s.passed && s.max_abs_z < 1.0)
        );
        let px = image(64, 64, |x, y| {
            let shift = if (8..16).contains(&x) && (40..48).contains(&y) {
                0.0075
            } else {
                0.0
            };
            (noise(x, y) + shift, 1e-4)
        });
        let s = tile_tests(&px, 64, 64);
        let failed: Vec<Option<u32>> = s.iter().filter(|s| !s.passed).map(|s| s.block).collect();
        assert_eq!(failed, vec![Some(8)]);
        let worst = s[3].worst.unwrap();
        assert_eq!((worst.x, worst.y), (8, 40));
        assert!((worst.z - 6.0).abs() < 1e-9, "{}", worst.z);
        // Failed pixels and zero-variance channels are left out of the sums.
        let mut px = image(16, 16, |_, _| (0.0, 1e-4));
        px[0] = Pixel::Failed;
        px[1] = Pixel::Usable {
            diff: [1.0; 3],
            var: [0.0; 3],
            exact_mismatch: true,
        };
        let s = tile_tests(&px, 16, 16);
        assert!(s.iter().all(|s| s.passed && s.max_abs_z == 0.0));
    }
}
