//! Display output: exposure, a tone curve, the sRGB transfer function, and 8-bit PNG encoding.
//!
//! The pipeline per channel is: scale the linear value by `2^exposure`; map it to `[0, 1]` by the
//! [`Curve`]; encode with the sRGB opto-electronic transfer function (IEC 61966-2-1:1999, §5.2);
//! quantise to 8 bits by rounding. NaN and negative values display as 0, +∞ as 255.

use super::ImageError;
use std::path::Path;

/// The curve mapping exposed linear values (≥ 0, unbounded) to display-linear `[0, 1]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Curve {
    /// K. Narkowicz's fit of the ACES reference rendering and output transforms ("ACES Filmic
    /// Tone Mapping Curve", 2016): `x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`, clamped to 1.
    /// Increasing for `x ≥ 0`, with a toe, a shoulder, and white (1.0) reached near `x = 7.24`.
    #[default]
    Filmic,
    /// Plain clamp to `[0, 1]`: values above 1 clip.
    Clamp,
}

impl Curve {
    /// Maps one exposed linear value to `[0, 1]`; NaN and negatives give 0, +∞ gives 1.
    pub fn apply(self, x: f32) -> f32 {
        // `!(x > 0)` also catches NaN; the cap keeps the rational fit away from ∞/∞.
        let x = if !(x > 0.0) { 0.0 } else { x.min(1.0e6) };
        let y = match self {
            Curve::Filmic => x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14),
            Curve::Clamp => x,
        };
        y.clamp(0.0, 1.0)
    }
}

/// How linear radiance becomes display values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneMap {
    /// Exposure adjustment in stops: values are multiplied by `2^exposure` before the curve.
    pub exposure: f32,
    /// The tone curve.
    pub curve: Curve,
}

impl Default for ToneMap {
    /// 0 stops, [`Curve::Filmic`].
    fn default() -> Self {
        ToneMap {
            exposure: 0.0,
            curve: Curve::Filmic,
        }
    }
}

/// The sRGB OETF (IEC 61966-2-1:1999): display-linear `[0, 1]` to the non-linear sRGB value,
/// `12.92 v` up to `v = 0.0031308`, `1.055 v^(1/2.4) − 0.055` above. Input is clamped to `[0, 1]`
/// and NaN gives 0.
pub fn srgb_encode(v: f32) -> f32 {
    let v = if v > 0.0 { v.min(1.0) } else { 0.0 };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// One linear RGB pixel to 8-bit sRGB: exposure, curve, OETF, rounding. Total: any input,
/// including NaN and ±∞, gives a defined output.
pub fn tone_map_pixel(rgb: [f32; 3], tm: &ToneMap) -> [u8; 3] {
    let scale = tm.exposure.exp2();
    rgb.map(|c| {
        let v = srgb_encode(tm.curve.apply(c * scale));
        // v ∈ [0, 1], so the float-to-int cast cannot saturate.
        (v * 255.0).round() as u8
    })
}

/// Writes linear RGB pixels (row-major, top row first) as an 8-bit sRGB PNG through `tm`,
/// atomically: on error an existing file at `path` is left as it was.
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    tm: &ToneMap,
) -> Result<(), ImageError> {
    if width == 0 || height == 0 {
        return Err(ImageError::Invalid {
            path: path.into(),
            reason: format!("size {width}×{height}"),
        });
    }
    if rgb.len() as u64 != width as u64 * height as u64 {
        return Err(ImageError::SizeMismatch {
            path: path.into(),
            what: "pixel slice".into(),
            len: rgb.len(),
            width,
            height,
        });
    }
    let bytes: Vec<u8> = rgb.iter().flat_map(|&p| tone_map_pixel(p, tm)).collect();
    write_rgb8(path, width, height, bytes)
}

/// Writes 8-bit RGB bytes (row-major, top row first) as a PNG, atomically (every write checked:
/// see [`super::atomic`]).
pub fn write_rgb8(path: &Path, width: u32, height: u32, bytes: Vec<u8>) -> Result<(), ImageError> {
    if bytes.len() as u64 != 3 * u64::from(width) * u64::from(height) || width == 0 || height == 0 {
        return Err(ImageError::write(path, "pixel buffer size"));
    }
    super::atomic::replace_with(
        path,
        |sink| encode_rgb8(sink, width, height, &bytes).map_err(|e| ImageError::write(path, e)),
        ImageError::io,
    )
}

/// Encodes 8-bit RGB bytes as a PNG into `out`.
pub fn encode_rgb8(
    out: &mut impl std::io::Write,
    width: u32,
    height: u32,
    bytes: &[u8],
) -> ::image::ImageResult<()> {
    use ::image::ImageEncoder;
    ::image::codecs::png::PngEncoder::new(out).write_image(
        bytes,
        width,
        height,
        ::image::ExtendedColorType::Rgb8,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clamp_tm(exposure: f32) -> ToneMap {
        ToneMap {
            exposure,
            curve: Curve::Clamp,
        }
    }

    #[test]
    fn default_is_filmic_at_zero_stops() {
        let tm = ToneMap::default();
        assert_eq!((tm.exposure, tm.curve), (0.0, Curve::Filmic));
    }

    #[test]
    fn monotone_and_endpoints() {
        for tm in [ToneMap::default(), clamp_tm(0.0), clamp_tm(-3.0)] {
            assert_eq!(tone_map_pixel([0.0; 3], &tm), [0; 3]);
            assert_eq!(tone_map_pixel([1.0e4; 3], &tm), [255; 3]);
            let mut prev = 0u8;
            for i in 0..=4000 {
                let x = i as f32 * 0.0025; // 0 … 10
                let v = tone_map_pixel([x, 0.0, 0.0], &tm)[0];
                assert!(v >= prev, "{tm:?}: not monotone at {x}");
                prev = v;
            }
        }
        // The filmic curve itself is strictly increasing below its shoulder.
        let f = |x: f32| Curve::Filmic.apply(x);
        assert!((1..700).all(|i| f(i as f32 * 0.01) > f((i - 1) as f32 * 0.01)));
        assert_eq!(f(8.0), 1.0);
        assert!((f(1.0) - 2.54 / 3.16).abs() < 1e-6);
    }

    #[test]
    fn exposure_is_doubling() {
        for x in [0.001f32, 0.01, 0.05, 0.13, 0.3, 0.45, 1.7, 3.0] {
            for tm in [ToneMap::default(), clamp_tm(0.0)] {
                let up = ToneMap {
                    exposure: 1.0,
                    ..tm
                };
                assert_eq!(
                    tone_map_pixel([x; 3], &up),
                    tone_map_pixel([2.0 * x; 3], &tm)
                );
            }
        }
    }

    #[test]
    fn srgb_known_points() {
        // Linear segment below the threshold, power segment above, continuous across it.
        assert!((srgb_encode(0.002) - 0.025_84).abs() < 1e-6);
        let t = 0.003_130_8f32;
        assert!((srgb_encode(t) - 12.92 * t).abs() < 1e-7);
        assert!((srgb_encode(t * 1.0001) - srgb_encode(t)).abs() < 1e-5);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.18) - 0.461_356).abs() < 1e-5);
        assert_eq!(tone_map_pixel([0.5; 3], &clamp_tm(0.0)), [188; 3]);
        assert_eq!(
            tone_map_pixel([1.0, 0.0, 0.25], &clamp_tm(0.0)),
            [255, 0, 137]
        );
    }

    #[test]
    fn non_finite_inputs_are_defined() {
        let tm = ToneMap::default();
        assert_eq!(
            tone_map_pixel([f32::NAN, -1.0, f32::NEG_INFINITY], &tm),
            [0; 3]
        );
        assert_eq!(tone_map_pixel([f32::INFINITY; 3], &tm), [255; 3]);
        assert_eq!(tone_map_pixel([f32::INFINITY; 3], &clamp_tm(0.0)), [255; 3]);
        let nan_exposure = ToneMap {
            exposure: f32::NAN,
            ..tm
        };
        assert_eq!(tone_map_pixel([1.0; 3], &nan_exposure), [0; 3]);
        let inf_exposure = clamp_tm(f32::INFINITY);
        assert_eq!(
            tone_map_pixel([0.0, 1.0, f32::NAN], &inf_exposure),
            [0, 255, 0]
        );
    }

    #[test]
    fn png_round_trip_and_errors() {
        let dir = std::env::temp_dir().join(format!("lapidary-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.png");
        let (w, h) = (7u32, 3u32);
        let px: Vec<[f32; 3]> = (0..w * h).map(|i| [i as f32 / 20.0, 0.5, 0.0]).collect();
        write_png(&path, w, h, &px, &clamp_tm(0.0)).unwrap();
        let back = ::image::open(&path).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (w, h));
        assert_eq!(back.get_pixel(0, 0).0, [0, 188, 0]);
        assert_eq!(back.get_pixel(6, 2).0, [255, 188, 0]);
        // A wrong slice length is an error naming the file, and the old PNG survives.
        let err = write_png(&path, w + 1, h, &px, &ToneMap::default()).unwrap_err();
        assert!(matches!(err, ImageError::SizeMismatch { len: 21, .. }));
        assert!(err.to_string().contains("out.png"), "{err}");
        assert!(write_png(&path, 0, 0, &[], &ToneMap::default()).is_err());
        assert_eq!(::image::open(&path).unwrap().to_rgb8(), back);
        let missing_dir = dir.join("no/such/dir/x.png");
        assert!(matches!(
            write_png(&missing_dir, 1, 1, &[[0.0; 3]], &ToneMap::default()),
            Err(ImageError::Write { .. })
        ));
    }
}
