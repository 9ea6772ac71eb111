//! The aggregate (bias) test: the z-score of the summed difference over groups of pixels at
//! several scales, `z = Σ(t − r)/√Σ(var_t + var_r)` per group and channel, which sees a shift far
//! below the noise of single pixels. The groups are square tiles, the whole image, and the
//! pixels of each material.

use super::planes::Pixel;
use super::{AGGREGATE_ALPHA, Region, Rgb, Scale, ScaleTest, TILE_BLOCKS, TileZ};
use crate::image::stats::{normal_quantile_two_sided, sidak};
use std::collections::BTreeMap;

/// The geometric scales tested on a `width × height` image: the whole image and each of
/// [`TILE_BLOCKS`] that splits it into more than one tile.
pub fn scales_of(width: u32, height: u32) -> Vec<Scale> {
    std::iter::once(Scale::Image)
        .chain(
            TILE_BLOCKS
                .iter()
                .filter(|&&b| b < width || b < height)
                .map(|&b| Scale::Block(b)),
        )
        .collect()
}

/// The aggregate tests of `px` (row-major, `width × height`) at every scale of [`scales_of`], and
/// per material when `materials` (a `material.Y` channel, one finite value per pixel) is given;
/// the family-wise [`AGGREGATE_ALPHA`] is split over the scales by Šidák.
pub(super) fn tile_tests(
    px: &[Pixel],
    width: u32,
    height: u32,
    materials: Option<&[f32]>,
) -> Vec<ScaleTest> {
    let materials = materials.filter(|m| m.len() == px.len() && m.iter().all(|v| v.is_finite()));
    let mut scales = scales_of(width, height);
    if materials.is_some() {
        scales.push(Scale::Material);
    }
    let alpha = sidak(AGGREGATE_ALPHA, scales.len());
    let w = width.max(1) as usize;
    scales
        .into_iter()
        .map(|scale| match (scale, materials) {
            (Scale::Material, Some(m)) => {
                let ids: BTreeMap<i32, usize> = m
                    .iter()
                    .map(|&v| v.round() as i32)
                    .collect::<std::collections::BTreeSet<_>>()
                    .into_iter()
                    .enumerate()
                    .map(|(k, id)| (id, k))
                    .collect();
                let by_index: Vec<i32> = ids.keys().copied().collect();
                group_test(
                    px,
                    scale,
                    alpha,
                    ids.len(),
                    |i| ids[&(m[i].round() as i32)],
                    |k| Region::Material(by_index[k]),
                )
            }
            _ => {
                let (bw, bh) = match scale {
                    Scale::Block(b) => (b.max(1), b.max(1)),
                    _ => (width.max(1), height.max(1)),
                };
                let nx = width.div_ceil(bw) as usize;
                let ny = height.div_ceil(bh) as usize;
                group_test(
                    px,
                    scale,
                    alpha,
                    nx * ny,
                    |i| ((i / w) as u32 / bh) as usize * nx + ((i % w) as u32 / bw) as usize,
                    |k| {
                        let (x, y) = ((k % nx) as u32 * bw, (k / nx) as u32 * bh);
                        Region::Rect {
                            x,
                            y,
                            width: bw.min(width - x),
                            height: bh.min(height - y),
                        }
                    },
                )
            }
        })
        .collect()
}

/// One scale: `groups` groups, pixel `i` in group `group_of(i)`, group `k` at `region_of(k)`.
fn group_test(
    px: &[Pixel],
    scale: Scale,
    alpha: f64,
    groups: usize,
    group_of: impl Fn(usize) -> usize,
    region_of: impl Fn(usize) -> Region,
) -> ScaleTest {
    // Per group and channel: Σ(t − r) and Σ(var_t + var_r) over the usable pixel channels with
    // variance (zero-variance channels are checked exactly per pixel; failed pixels fail there).
    let mut sums = vec![[(0.0f64, 0.0f64); 3]; groups];
    for (i, p) in px.iter().enumerate() {
        let Pixel::Usable { diff, var, .. } = p else {
            continue;
        };
        let g = &mut sums[group_of(i)];
        for c in 0..3 {
            if var[c] > 0.0 {
                g[c].0 += diff[c];
                g[c].1 += var[c];
            }
        }
    }
    let tested = sums.iter().flatten().filter(|(_, v)| *v > 0.0).count();
    let z_crit = normal_quantile_two_sided(sidak(alpha, tested));
    let (mut worst, mut failed) = (None::<TileZ>, 0usize);
    for (k, g) in sums.iter().enumerate() {
        for (c, &(d, v)) in g.iter().enumerate() {
            if v <= 0.0 {
                continue;
            }
            let z = d / v.sqrt();
            if z.abs() > z_crit {
                failed += 1;
            }
            if worst.as_ref().is_none_or(|w| z.abs() > w.z.abs()) {
                worst = Some(TileZ {
                    region: region_of(k),
                    channel: Rgb::ALL[c],
                    z,
                });
            }
        }
    }
    ScaleTest {
        scale,
        tiles: groups,
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
        use Scale::{Block, Image};
        assert_eq!(scales_of(96, 96), [Image, Block(32), Block(16), Block(8)]);
        assert_eq!(scales_of(20, 12), [Image, Block(16), Block(8)]);
        assert_eq!(scales_of(8, 8), [Image]);
        assert_eq!(scales_of(40, 1), [Image, Block(32), Block(16), Block(8)]);
    }

    #[test]
    fn tiles_sum_differences_and_variances_with_partial_edges() {
        // 20 × 12 with a difference of 0.01 and variance 1e-4 everywhere: a whole-image
        // z = 240 · 0.01 / √(240 · 1e-4) = √240 ≈ 15.5 in R; G has variance but no difference,
        // B no variance (not tested).
        let px = image(20, 12, |_, _| (0.01, 1e-4));
        let s = tile_tests(&px, 20, 12, None);
        assert_eq!(s.len(), 3);
        let alpha = sidak(AGGREGATE_ALPHA, 3);
        let whole = &s[0];
        assert_eq!(
            (whole.tiles, whole.tested, whole.scale),
            (1, 2, Scale::Image)
        );
        assert!((whole.max_abs_z - 240f64.sqrt()).abs() < 1e-9);
        assert!((whole.alpha - alpha).abs() < 1e-15);
        assert_eq!(whole.z_crit, normal_quantile_two_sided(sidak(alpha, 2)));
        assert!(!whole.passed);
        // 16²: tiles 16×12 and a partial 4×12 (z = √48 ≈ 6.9); both in R fail.
        let w16 = &s[1];
        assert_eq!((w16.tiles, w16.tested, w16.failed), (2, 4, 2));
        let worst = w16.worst.unwrap();
        let rect = Region::Rect {
            x: 0,
            y: 0,
            width: 16,
            height: 12,
        };
        assert_eq!(worst.region, rect);
        assert_eq!(worst.channel, Rgb::R);
        assert!((worst.z - 192f64.sqrt()).abs() < 1e-9);
        // 8²: 3 × 2 tiles, the corner one 4 × 4.
        assert_eq!(s[2].tiles, 6);
    }

    #[test]
    fn noise_passes_and_a_local_shift_fails_only_where_it_is_seen() {
        // ±1σ alternating noise passes everywhere; a +0.75σ shift of one 8×8 block (z = 6 there,
        // 3 over its 16² tile, 0.75 over the image) fails at 8² only.
        let noise = |x: u32, y: u32| {
            if (x + y).is_multiple_of(2) {
                0.01
            } else {
                -0.01
            }
        };
        let px = image(64, 64, |x, y| (noise(x, y), 1e-4));
        assert!(
            tile_tests(&px, 64, 64, None)
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
        let s = tile_tests(&px, 64, 64, None);
        let failed: Vec<Scale> = s.iter().filter(|s| !s.passed).map(|s| s.scale).collect();
        assert_eq!(failed, vec![Scale::Block(8)]);
        let worst = s[3].worst.unwrap();
        assert!(matches!(worst.region, Region::Rect { x: 8, y: 40, .. }));
        assert!((worst.z - 6.0).abs() < 1e-9, "{}", worst.z);
        // Failed pixels and zero-variance channels are left out of the sums.
        let mut px = image(16, 16, |_, _| (0.0, 1e-4));
        px[0] = Pixel::Failed;
        px[1] = Pixel::Usable {
            diff: [1.0; 3],
            var: [0.0; 3],
            exact_mismatch: true,
        };
        let s = tile_tests(&px, 16, 16, None);
        assert!(s.iter().all(|s| s.passed && s.max_abs_z == 0.0));
    }

    #[test]
    fn materials_are_one_more_scale_wherever_their_pixels_are() {
        // Material 3 on every fourth pixel of a 96 × 96 image (2304 pixels, scattered): +0.1σ
        // there is z = 0.1 · √2304 = 4.8 over the material, but 2.4 over the whole image and
        // 0.8 over a 32² tile (the ±1σ noise cancels over each of these groups).
        let m: Vec<f32> = (0..96 * 96)
            .map(|i| if i % 4 == 0 { 3.0 } else { -1.0 })
            .collect();
        let noise = |x: u32, y: u32| {
            if (x + y).is_multiple_of(2) {
                0.01
            } else {
                -0.01
            }
        };
        let px = image(96, 96, |x, y| {
            let shift = if x % 4 == 0 { 0.001 } else { 0.0 };
            (noise(x, y) + shift, 1e-4)
        });
        let s = tile_tests(&px, 96, 96, Some(&m));
        assert_eq!(s.len(), 5);
        assert!((s[0].alpha - sidak(AGGREGATE_ALPHA, 5)).abs() < 1e-15);
        let by_material = &s[4];
        assert_eq!((by_material.scale, by_material.tiles), (Scale::Material, 2));
        assert!(!by_material.passed);
        let worst = by_material.worst.unwrap();
        assert_eq!((worst.region, worst.channel), (Region::Material(3), Rgb::R));
        assert!((worst.z - 4.8).abs() < 1e-9, "{}", worst.z);
        assert!((s[0].max_abs_z - 2.4).abs() < 1e-9, "{}", s[0].max_abs_z);
        assert!(s[..4].iter().all(|s| s.passed), "{s:?}");
        // Without a usable material channel the scale is left out.
        assert_eq!(tile_tests(&px, 96, 96, None).len(), 4);
        let mut bad = m.clone();
        bad[5] = f32::NAN;
        assert_eq!(tile_tests(&px, 96, 96, Some(&bad)).len(), 4);
    }
}
