//! Comparing a test render with a reference render (docs/design.md §10): error metrics, a per-pixel
//! z-test, an aggregate (bias) test over tiles, a mean ratio, a verdict, and a false-colour
//! error map.
//!
//! **Metrics** are taken over the `R`, `G`, `B` values of every pixel where both images are
//! finite (a `Y`-only image counts as grey in all three): RMSE, relative MSE
//! `mean((t − r)² / (r² + ε))` with [`REL_MSE_EPSILON`] `ε = 10⁻²`, MAE, and PSNR
//! `10 log₁₀(peak² / MSE)` with `peak` the reference's largest channel value (1 if that is not
//! positive); PSNR is `+∞` when the images agree exactly. All are in the images' own unit
//! (radiance), squared for the MSEs; relMSE is dimensionless. The **mean ratio** is each
//! channel's mean over those pixels, test over reference.
//!
//! **The per-pixel z-test** follows the practice of Mitsuba's render regression tests: each
//! pixel channel gives `z = (t − r) / √(var_t + var_r)`, where `var_r` is the reference's
//! `variance.R/G/B` (variance of the pixel's mean) and `var_t` the test's own, or — if the test
//! has none — `var_r · n_ref / n_test` from the sample counts (`samples.Y` per pixel, else the
//! `lapidary.spp` attribute), which assumes both renders have the same per-sample variance.
//! With `N` pixel channels tested at family-wise significance α = 0.01, each is tested at
//! Šidák's `α_i = 1 − (1 − α)^(1/N)` (Z. Šidák, "Rectangular confidence regions for the means
//! of multivariate normal distributions", JASA 1967), i.e. against the two-sided normal
//! quantile `z_crit`. A pixel passes when all its channels do; where both variances are 0 it
//! passes iff `|t − r| ≤ 10⁻⁶ · max(1, |r|)`. A pixel with a NaN or infinite value, or unusable
//! sample counts, fails. This part passes when at least 99.75 % of the pixels pass.
//!
//! **The aggregate test** sees what single pixels cannot: a shift of a few per cent is far below
//! the 10–30 % noise of a 256-spp pixel, but not below the noise of a sum of many pixels. The
//! image is cut into square tiles of [`TILE_BLOCKS`] = 32², 16² and 8² pixels from the top left
//! (edge tiles partial, with their actual pixels), plus the whole image as one tile; a block
//! size that would give a single tile is left out. A bias of one material is spread over the
//! image (the cells of an aventurine): when the reference (else the test) has a `material.Y`
//! channel, each of its values is one more group, [`Scale::Material`]. Per group and channel
//! `z = Σ(t − r) / √Σ(var_t + var_r)` over its pixels with variance (failed pixels and
//! zero-variance channels, judged per pixel, are left out). The scales share the family-wise
//! [`AGGREGATE_ALPHA`] = 0.01 by Šidák (`α_s = 1 − (1 − α)^(1/S)` for `S` scales), and each scale
//! splits its `α_s` over its tested tile channels by Šidák again, so for Gaussian errors the
//! aggregate test fails two independent renders of one scene with probability ≤ 0.01. (The pixel
//! test adds little: with `α_i` per channel it expects 0.01 failing pixels in all, and needs more
//! than 0.25 % of the pixels to fail — two or more from 400 pixels on, a chance below 10⁻⁴;
//! below 400 pixels one failing pixel fails the image, up to 0.01 more.) The sums assume that
//! pixel errors are independent, as they are for the independent sampler; the repository's
//! Sobol' references (whose sample variance overstates their error) pass every scale against
//! independent 256-spp renders (largest |z| 0.87 of its limit, the furnace's 32² tiles; over the
//! whole image at most 0.5 of it).
//! Images with a NaN, infinite or negative variance anywhere cannot be tested:
//! [`CompareError::BadVariance`].
//!
//! **The verdict** of the z-tests, when they ran, is pass iff the per-pixel test and every scale
//! pass. Otherwise (no reference variance, or no test variance nor sample counts) the image
//! passes iff relMSE ≤ [`REL_MSE_THRESHOLD`], no pixel is non-finite and every channel's mean
//! ratio is within `1 ±` [`Options::mean_tolerance`] (default [`MEAN_TOLERANCE`] = 0.5 %), since
//! relMSE alone passes a whole image 1–2 % too bright.

mod error;
mod metrics;
mod pixel;
mod planes;
mod tiles;
mod verdict;

pub use error::CompareError;
pub use tiles::scales_of;
pub use verdict::{compare, compare_with};

/// `ε` in relMSE's denominator `r² + ε` (radiance²), so that black pixels do not dominate.
pub const REL_MSE_EPSILON: f64 = 1e-2;
/// Largest relMSE that passes when the z-test cannot run.
pub const REL_MSE_THRESHOLD: f64 = 1e-3;
/// Family-wise significance of the per-pixel z-test (before the Šidák split over pixel channels).
pub const Z_ALPHA: f64 = 0.01;
/// Fraction of pixels that must pass the per-pixel z-test.
pub const Z_REQUIRED_FRACTION: f64 = 0.9975;
/// Family-wise significance of the aggregate test, shared by its scales (Šidák).
pub const AGGREGATE_ALPHA: f64 = 0.01;
/// Sides in pixels of the square tiles of the aggregate test (besides the whole image).
pub const TILE_BLOCKS: [u32; 3] = [32, 16, 8];
/// Default largest `|mean_t / mean_r − 1|` of any channel when the z-tests cannot run (0.5 %).
pub const MEAN_TOLERANCE: f64 = 0.005;
/// The offset in the relative error `|t − r| / (|r| + offset)` of the error map (radiance).
pub const REL_ERROR_OFFSET: f64 = 1e-2;
/// Relative error drawn at the top of the heatmap's colour scale when the z-test did not run.
pub const REL_ERROR_SCALE: f32 = 0.1;

/// Which of the two images something refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The image under test.
    Test,
    /// The reference image.
    Reference,
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Role::Test => "test",
            Role::Reference => "reference",
        })
    }
}

/// A colour channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rgb {
    /// Red (`R`).
    R,
    /// Green (`G`).
    G,
    /// Blue (`B`).
    B,
}

impl Rgb {
    /// R, G, B in channel order.
    pub const ALL: [Rgb; 3] = [Rgb::R, Rgb::G, Rgb::B];
}

impl std::fmt::Display for Rgb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Rgb::R => "R",
            Rgb::G => "G",
            Rgb::B => "B",
        })
    }
}

/// Where the test image's variance came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestVariance {
    /// The test image's own `variance.*` channels.
    Own,
    /// The reference's variance scaled by `n_ref / n_test` (same per-sample variance assumed).
    ScaledFromReference,
}

/// Settings of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Largest `|mean_t / mean_r − 1|` of a channel that passes when the z-tests cannot run, as
    /// a fraction in `[0, 1]` (default [`MEAN_TOLERANCE`], 0.5 %).
    pub mean_tolerance: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            mean_tolerance: MEAN_TOLERANCE,
        }
    }
}

/// How the aggregate test groups the pixels at one scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// The whole image as one group.
    Image,
    /// Square tiles of this side in pixels from the top left (edge tiles partial).
    Block(u32),
    /// One group per value of the reference's `material.Y` (the material of each pixel's first
    /// sample; −1 floor, −2 nothing), wherever its pixels are.
    Material,
}

impl Scale {
    /// `image`, `32x32` etc., or `material`.
    pub fn label(&self) -> String {
        match self {
            Scale::Image => "image".into(),
            Scale::Block(b) => format!("{b}x{b}"),
            Scale::Material => "material".into(),
        }
    }
}

/// Where a group of the aggregate test is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// A rectangle of pixels.
    Rect {
        /// Left column (pixels from the left).
        x: u32,
        /// Top row (pixels from the top).
        y: u32,
        /// Width in pixels (smaller than the block at the right edge).
        width: u32,
        /// Height in pixels (smaller than the block at the bottom edge).
        height: u32,
    },
    /// The pixels of one `material.Y` value.
    Material(i32),
}

impl std::fmt::Display for Region {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Region::Rect {
                x,
                y,
                width,
                height,
            } => write!(f, "the {width}x{height} tile at ({x}, {y})"),
            Region::Material(m) => write!(f, "the pixels of material {m}"),
        }
    }
}

/// One group and channel of the aggregate test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileZ {
    /// The group.
    pub region: Region,
    /// The channel.
    pub channel: Rgb,
    /// `Σ(t − r) / √Σ(var_t + var_r)` over the group; positive when the test is brighter.
    pub z: f64,
}

/// The aggregate test at one scale.
#[derive(Clone, Debug, PartialEq)]
pub struct ScaleTest {
    /// How the pixels are grouped.
    pub scale: Scale,
    /// Groups (tiles, partial edge tiles included, or materials) at this scale.
    pub tiles: usize,
    /// Group channels tested (those with variance): the `N` of this scale's Šidák correction.
    pub tested: usize,
    /// This scale's family-wise significance, [`AGGREGATE_ALPHA`] split over the scales.
    pub alpha: f64,
    /// Critical |z| of each group channel (two-sided, after the Šidák split over `tested`).
    pub z_crit: f64,
    /// Largest |z| over the tested group channels (0 if none).
    pub max_abs_z: f64,
    /// The group channel of the largest |z|.
    pub worst: Option<TileZ>,
    /// Group channels beyond `z_crit`.
    pub failed: usize,
    /// Whether no group channel is beyond `z_crit`.
    pub passed: bool,
}

impl ScaleTest {
    /// The scale's [label](Scale::label).
    pub fn label(&self) -> String {
        self.scale.label()
    }
}

/// The outcome of the z-tests: per pixel, and aggregated over tiles.
#[derive(Clone, Debug, PartialEq)]
pub struct ZTest {
    /// Family-wise significance of the per-pixel test ([`Z_ALPHA`], 0.01).
    pub alpha: f64,
    /// Critical |z| of each pixel channel after the Šidák correction (two-sided).
    pub z_crit: f64,
    /// Pixels in the image.
    pub pixels: usize,
    /// Pixels that failed (a channel beyond `z_crit`, non-finite values, unusable sample counts).
    pub failed_pixels: usize,
    /// Fraction of the pixels that passed, in `[0, 1]`.
    pub pass_fraction: f64,
    /// Fraction required to pass ([`Z_REQUIRED_FRACTION`], 0.9975).
    pub required_fraction: f64,
    /// Largest |z| over all tested pixel channels (0 if none).
    pub max_abs_z: f64,
    /// Pixel channels tested with a z-score (the `N` of the Šidák correction).
    pub tested_channels: usize,
    /// Where the test's variance came from.
    pub test_variance: TestVariance,
    /// Whether `pass_fraction ≥ required_fraction`.
    pub pixels_passed: bool,
    /// The aggregate test: whole image, tiles from the largest to the smallest, materials.
    pub scales: Vec<ScaleTest>,
    /// Whether the pixel test and every scale passed.
    pub passed: bool,
}

impl ZTest {
    /// The aggregate scales that failed, largest first.
    pub fn failed_scales(&self) -> impl Iterator<Item = &ScaleTest> {
        self.scales.iter().filter(|s| !s.passed)
    }
}

/// Each channel's mean over the pixels finite in both images, and their ratio.
#[derive(Clone, Debug, PartialEq)]
pub struct MeanRatio {
    /// The test's mean R, G, B (radiance).
    pub test: [f64; 3],
    /// The reference's mean R, G, B (radiance).
    pub reference: [f64; 3],
    /// `test / reference` per channel (1 for `0/0`, ±∞ for `x/0`).
    pub ratio: [f64; 3],
    /// The tolerance it was held to ([`Options::mean_tolerance`]).
    pub tolerance: f64,
    /// Whether every `|ratio − 1| ≤ tolerance`.
    pub passed: bool,
}

/// Everything [`compare`] finds.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Root-mean-square error over R, G, B of the finite pixels (radiance).
    pub rmse: f64,
    /// Mean of `(t − r)² / (r² + ε)`, ε = [`REL_MSE_EPSILON`] (dimensionless).
    pub rel_mse: f64,
    /// Mean absolute error (radiance).
    pub mae: f64,
    /// `10 log₁₀(peak² / MSE)` in dB, peak = the reference's largest channel value; `+∞` if equal.
    pub psnr: f64,
    /// The reference's largest finite channel value used as PSNR's peak (1 if not positive).
    pub peak: f64,
    /// Mean HDR-FLIP error in [0, 1] at 67 pixels per degree ([`super::flip::hdr_flip`];
    /// Andersson et al. 2020, 2021): a perceptual difference, reported, not part of the verdict.
    pub flip: f64,
    /// Pixels with a NaN or infinite R, G or B in either image (always failures).
    pub non_finite_pixels: usize,
    /// The per-channel mean ratio (part of the verdict only when the z-tests did not run).
    pub mean_ratio: MeanRatio,
    /// The z-tests, `None` when they could not run (see `ztest_skipped`).
    pub ztest: Option<ZTest>,
    /// Why the z-tests did not run.
    pub ztest_skipped: Option<String>,
    /// Per-pixel error, row-major: the largest |z| over the pixel's channels when the z-test ran
    /// (0 or +∞ for zero-variance pixels by their exact check), else the mean over channels of
    /// `|t − r| / (|r| + 10⁻²)`; +∞ for failed non-finite pixels.
    pub error_map: Vec<f32>,
    /// The error drawn at the top of the heatmap's scale: `z_crit`, or [`REL_ERROR_SCALE`].
    pub error_scale: f32,
    /// The verdict: the z-tests' if they ran, else relMSE ≤ [`REL_MSE_THRESHOLD`], no
    /// non-finite pixel and the mean ratio within its tolerance.
    pub passed: bool,
}
