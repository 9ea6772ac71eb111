//! OpenEXR reading and writing through the `exr` crate.
//!
//! Writing: one flat scanline part, every channel 32-bit float, ZIP compression (lossless, 16
//! scanlines per block), each attribute a `string` attribute of the header. Keys that are text
//! attributes standardised by OpenEXR (`owner`, `comments`, `capDate`, `software`, `view`,
//! `wrapmodes`, `renderingTransform`, `lookModTransform`) are written as those; the other
//! standard names (`channels`, `compression`, …) are reserved and rejected. Names and values
//! are stored as their UTF-8 bytes.
//!
//! Reading: the first flat part of any scanline or tiled file (largest mip level), channels in
//! f16, f32 or u32 converted to `f32`, names kept whole (`"albedo.R"`). Attributes returned are
//! the string ones, plus `float`, `double`, `int` and string-vector ones formatted as text;
//! they come back sorted by key. Bytes that are not UTF-8 are read as Latin-1.

use super::{Channel, ExrImage, ImageError, RawChannel};
use ::exr::meta::header::standard_names;
use ::exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, Error as ExrError, FlatSamples, Image,
    Layer, LayerAttributes, MetaData, ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
    read,
};
use std::collections::HashSet;
use std::path::Path;

/// Linear RGB pixels read from an EXR, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` linear RGB values (radiance for a render or environment map).
    pub pixels: Vec<[f32; 3]>,
}

impl RgbImage {
    /// The pixel at column `x`, row `y` (0 = top); coordinates past the edge are clamped to it,
    /// and an empty image gives black.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        let x = x.min(self.width.saturating_sub(1)) as usize;
        let y = y.min(self.height.saturating_sub(1)) as usize;
        let i = y * self.width as usize + x;
        self.pixels.get(i).copied().unwrap_or_default()
    }
}

impl ExrImage {
    /// The `R`, `G`, `B` channels as pixels, or grey from a lone luminance channel `Y`; `None` if
    /// neither set is present with `width × height` values.
    pub fn to_rgb(&self) -> Option<RgbImage> {
        let n = self.width as usize * self.height as usize;
        let get = |name| self.channel(name).filter(|d| d.len() == n);
        let pixels = match (get("R"), get("G"), get("B"), get("Y")) {
            (Some(r), Some(g), Some(b), _) => (0..n).map(|i| [r[i], g[i], b[i]]).collect(),
            (_, _, _, Some(y)) => y.iter().map(|&v| [v; 3]).collect(),
            _ => return None,
        };
        Some(RgbImage {
            width: self.width,
            height: self.height,
            pixels,
        })
    }
}

/// Standard OpenEXR attributes of type `string`, with the field the `exr` crate parses them into.
type TextField = fn(&mut LayerAttributes) -> &mut Option<Text>;
const STANDARD_TEXT: [(&str, TextField); 8] = [
    ("owner", |a| &mut a.owner),
    ("comments", |a| &mut a.comments),
    ("capDate", |a| &mut a.capture_date),
    ("software", |a| &mut a.software_name),
    ("view", |a| &mut a.view_name),
    ("wrapmodes", |a| &mut a.wrap_mode_name),
    ("renderingTransform", |a| &mut a.rendering_transform_name),
    ("lookModTransform", |a| {
        &mut a.look_modification_transform_name
    }),
];

/// Writes `img` as a single-part, all-`f32`, ZIP-compressed EXR, atomically (see
/// [`super::write_atomically`]): on error an existing file at `path` is left as it was.
pub fn write_exr(path: &Path, img: &ExrImage) -> Result<(), ImageError> {
    write_exr_raw(path, img, &[])
}

/// Writes `img` plus `raw` as 32-bit unsigned integer channels (exact), like [`write_exr`].
pub fn write_exr_raw(path: &Path, img: &ExrImage, raw: &[RawChannel]) -> Result<(), ImageError> {
    let invalid = |reason: String| ImageError::Invalid {
        path: path.into(),
        reason,
    };
    if img.width == 0 || img.height == 0 || img.width.max(img.height) > i32::MAX as u32 {
        return Err(invalid(format!("size {}×{}", img.width, img.height)));
    }
    if img.channels.is_empty() {
        return Err(invalid("no channels".into()));
    }
    let n = img.width as usize * img.height as usize;
    let mut seen = HashSet::new();
    let mut list = SmallVec::new();
    let all = img
        .channels
        .iter()
        .map(|c| (&c.name, c.data.len(), FlatSamples::F32(c.data.clone())))
        .chain(
            raw.iter()
                .map(|c| (&c.name, c.data.len(), FlatSamples::U32(c.data.clone()))),
        );
    for (cname, len, samples) in all {
        if len != n {
            return Err(ImageError::SizeMismatch {
                path: path.into(),
                what: format!("channel `{cname}`"),
                len,
                width: img.width,
                height: img.height,
            });
        }
        let name = name_text(cname).ok_or_else(|| invalid(bad_name("channel", cname)))?;
        if !seen.insert(cname.as_str()) {
            return Err(invalid(format!("duplicate channel `{cname}`")));
        }
        list.push(AnyChannel::new(name, samples));
    }
    let mut attrs = LayerAttributes::default();
    seen.clear();
    for (key, value) in &img.attributes {
        let name = name_text(key).ok_or_else(|| invalid(bad_name("attribute", key)))?;
        if !seen.insert(key.as_str()) {
            return Err(invalid(format!("duplicate attribute `{key}`")));
        }
        let value = utf8_text(value);
        if let Some((_, field)) = STANDARD_TEXT.iter().find(|(k, _)| k == key) {
            *field(&mut attrs) = Some(value);
        } else if standard_names::ALL.contains(&key.as_bytes()) {
            return Err(invalid(format!(
                "attribute name `{key}` is reserved by OpenEXR"
            )));
        } else {
            attrs.other.insert(name, AttributeValue::Text(value));
        }
    }
    let size = (img.width as usize, img.height as usize);
    let layer = Layer::new(
        size,
        attrs,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    super::atomic::replace_with(
        path,
        |sink| {
            Image::from_layer(layer)
                .write()
                .to_buffered(sink)
                .map_err(|e| ImageError::write(path, e))
        },
        ImageError::io,
    )
}

/// Reads the first flat layer of an EXR: all channels as `f32`, text attributes sorted by key.
pub fn read_exr(path: &Path) -> Result<ExrImage, ImageError> {
    read_exr_raw(path).map(|(img, _)| img)
}

/// Reads like [`read_exr`], and also returns the `UINT` channels exactly (they are in the image
/// too, converted to `f32`).
pub fn read_exr_raw(path: &Path) -> Result<(ExrImage, Vec<RawChannel>), ImageError> {
    // The header alone first: clear errors for missing, foreign and deep-only files.
    let meta = MetaData::read_from_file(path, false).map_err(|e| decode_error(path, e))?;
    if !meta.headers.is_empty() && meta.headers.iter().all(|h| h.deep) {
        return Err(ImageError::Unsupported {
            path: path.into(),
            reason: "the file holds only deep data".into(),
        });
    }
    let file_len = std::fs::metadata(path).map_or(0, |m| m.len());
    check_plausible(&meta.headers, file_len).map_err(|reason| ImageError::Unreadable {
        path: path.into(),
        reason,
    })?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| decode_error(path, e))?;
    let mut layer = image.layer_data;
    let (w, h) = (layer.size.0, layer.size.1);
    let (Ok(width), Ok(height)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(ImageError::Unsupported {
            path: path.into(),
            reason: format!("size {w}×{h}"),
        });
    };
    let mut channels = Vec::with_capacity(layer.channel_data.list.len());
    let mut raw = Vec::new();
    for c in layer.channel_data.list {
        let name = decode_text(&c.name);
        let data: Vec<f32> = match c.sample_data {
            FlatSamples::F32(v) => v,
            FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
            FlatSamples::U32(v) => {
                let f = v.iter().map(|&x| x as f32).collect();
                raw.push(RawChannel {
                    name: name.clone(),
                    data: v,
                });
                f
            }
        };
        if data.len() != w * h {
            return Err(ImageError::Unsupported {
                path: path.into(),
                reason: format!("channel `{name}` is subsampled"),
            });
        }
        channels.push(Channel { name, data });
    }
    let mut attributes: Vec<(String, String)> = STANDARD_TEXT
        .iter()
        .filter_map(|(k, field)| {
            Some((
                k.to_string(),
                decode_text(&field(&mut layer.attributes).take()?),
            ))
        })
        .collect();
    let other = layer.attributes.other.iter().chain(&image.attributes.other);
    attributes.extend(other.filter_map(|(k, v)| Some((decode_text(k), attribute_text(v)?))));
    attributes.sort();
    let img = ExrImage {
        width,
        height,
        channels,
        attributes,
    };
    Ok((img, raw))
}

/// Reads `R`, `G`, `B` (alpha and other channels ignored; a lone `Y` gives grey) from the first
/// flat layer of an EXR. Missing colour channels are an error that lists the channels present.
pub fn read_rgb(path: &Path) -> Result<RgbImage, ImageError> {
    let img = read_exr(path)?;
    img.to_rgb().ok_or_else(|| ImageError::MissingChannels {
        path: path.into(),
        wanted: "R, G, B (or Y)".into(),
        found: img.channels.into_iter().map(|c| c.name).collect(),
    })
}

/// An `exr` crate error as an [`ImageError`] about `path`.
fn decode_error(path: &Path, e: ExrError) -> ImageError {
    let path = path.into();
    match e {
        ExrError::Io(e) if e.kind() == std::io::ErrorKind::NotFound => {
            ImageError::NotFound { path }
        }
        ExrError::NotSupported(r) => ImageError::Unsupported {
            path,
            reason: r.into_owned(),
        },
        e => ImageError::Unreadable {
            path,
            reason: e.to_string(),
        },
    }
}

/// Decoded bytes a file may promise per byte it holds: well above DEFLATE's 1032:1 limit (RFC
/// 1951: a match yields at most 258 bytes and costs at least 2 bits), with room for PIZ.
const MAX_EXPANSION: u64 = 4096;
/// Files may always promise this much, however small they are (2 GiB).
const MIN_BUDGET: u64 = 2 << 30;

/// Rejects headers promising far more pixels than a file of `file_len` bytes can hold. A corrupt
/// size field would otherwise make the decoder attempt an allocation that aborts the process.
fn check_plausible(headers: &[::exr::meta::header::Header], file_len: u64) -> Result<(), String> {
    // Each chunk has an 8-byte entry in the offset table.
    let chunks: u64 = headers.iter().map(|h| h.chunk_count as u64).sum();
    if chunks.saturating_mul(8) > file_len {
        return Err(format!(
            "header promises {chunks} blocks, too many for {file_len} bytes"
        ));
    }
    if let Some(h) = headers.iter().find(|h| !h.deep) {
        let (w, ht, c) = (h.layer_size.0, h.layer_size.1, h.channels.list.len());
        let bytes = (w as u64)
            .saturating_mul(ht as u64)
            .saturating_mul(4 * c as u64);
        if bytes > MIN_BUDGET.max(file_len.saturating_mul(MAX_EXPANSION)) {
            return Err(format!(
                "header promises {w}×{ht} pixels × {c} channels, implausible for {file_len} bytes"
            ));
        }
    }
    Ok(())
}

/// A non-empty name of at most 255 bytes without NUL, as EXR text; `None` if not storable.
fn name_text(s: &str) -> Option<Text> {
    (!s.is_empty() && s.len() <= 255 && !s.contains('\0')).then(|| utf8_text(s))
}

fn bad_name(kind: &str, name: &str) -> String {
    format!("{kind} name `{name}` must be 1 to 255 bytes without NUL")
}

/// The UTF-8 bytes of `s` as EXR text (which is a byte string).
fn utf8_text(s: &str) -> Text {
    Text::from_bytes_unchecked(SmallVec::from_slice(s.as_bytes()))
}

/// EXR text as a string: UTF-8 if valid, otherwise Latin-1.
fn decode_text(t: &Text) -> String {
    String::from_utf8(t.bytes().to_vec()).unwrap_or_else(|_| t.chars().collect())
}

/// The attribute kinds returned by [`read_exr`], formatted as text.
fn attribute_text(v: &AttributeValue) -> Option<String> {
    Some(match v {
        AttributeValue::Text(t) => decode_text(t),
        AttributeValue::TextVector(ts) => ts.iter().map(decode_text).collect::<Vec<_>>().join("\n"),
        AttributeValue::F32(x) => x.to_string(),
        AttributeValue::F64(x) => x.to_string(),
        AttributeValue::I32(x) => x.to_string(),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ::exr::prelude::{Compression, SampleType, f16, write_rgba_file};
    use std::path::PathBuf;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lapidary-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn image(width: u32, height: u32, channels: &[(&str, Vec<f32>)]) -> ExrImage {
        let channels = channels.iter().cloned();
        ExrImage {
            width,
            height,
            channels: channels.map(|(n, d)| Channel::new(n, d)).collect(),
            attributes: vec![],
        }
    }

    /// NaN-free values including ±0, a subnormal, extremes and ∞, distinct per channel and pixel.
    fn values(seed: u32, n: usize) -> Vec<f32> {
        let inf = f32::INFINITY;
        let special = [0.0, -0.0, 1.0e-40, f32::MAX, -1.0e-38, inf];
        let hash = |i: usize| ((i as u32).wrapping_mul(2654435761) ^ seed) as f32;
        let value = |i: usize| match i % 9 {
            k @ 0..6 if seed.is_multiple_of(2) => special[k],
            _ => hash(i).sin() * 1.0e3 / (1 + i) as f32,
        };
        (0..n).map(value).collect()
    }

    fn sample_image(width: u32, height: u32) -> ExrImage {
        let names = "R G B albedo.R albedo.G samples.Y material.Y".split(' ');
        let n = (width * height) as usize;
        let channels: Vec<_> = (0..).zip(names).map(|(i, c)| (c, values(i, n))).collect();
        let mut img = image(width, height, &channels);
        img.attributes = [
            ("lapidary.version", "0.1.0".to_string()),
            ("lapidary.spp", "64".into()),
            ("lapidary.key.longer.than.31.bytes", "x".repeat(600)),
            ("lapidary.note", "γ ≈ 2.4, tab\tand newline\n".into()),
            ("comments", "standard text attribute".into()),
            ("software", "lapidary".into()),
        ]
        .map(|(k, v)| (k.to_string(), v))
        .into();
        img
    }

    #[test]
    fn round_trip_is_bit_exact() {
        for (w, h) in [(1, 1), (37, 19)] {
            let path = scratch(&format!("rt{w}x{h}.exr"));
            let img = sample_image(w, h);
            write_exr(&path, &img).unwrap();
            let back = read_exr(&path).unwrap();
            assert_eq!((back.width, back.height, back.channels.len()), (w, h, 7));
            let bits = |d: &[f32]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            for c in &img.channels {
                let data = back.channel(&c.name).expect("channel kept");
                assert_eq!(bits(&c.data), bits(data), "channel {}", c.name);
            }
            let mut attrs = img.attributes.clone();
            attrs.sort();
            assert_eq!(attrs, back.attributes);
            assert_eq!(back.attribute("lapidary.spp"), Some("64"));
            // The file is what the docs say: one part, f32 channels, ZIP.
            let meta = MetaData::read_from_file(&path, true).unwrap();
            assert_eq!(meta.headers.len(), 1);
            assert_eq!(meta.headers[0].compression, Compression::ZIP16);
            let mut types = meta.headers[0].channels.list.iter().map(|c| c.sample_type);
            assert!(types.all(|t| t == SampleType::F32));
        }
    }

    #[test]
    fn reads_f16_u32_tiled_file_from_exr_crate() {
        let path = scratch("f16.exr");
        let (w, h) = (70usize, 3usize); // wider than one 64-pixel tile
        let f = |i: usize| i as f32 * 0.25 - 3.0; // exact in f16
        let half = |v: f32| f16::from_f32(v);
        let (r, id) = ((0..w * h).map(|i| half(f(i))), (0..w * h).map(|i| i as u32));
        let list = SmallVec::from_vec(vec![
            AnyChannel::new("R", FlatSamples::F16(r.collect())),
            AnyChannel::new("G", FlatSamples::F16(vec![half(0.5); w * h])),
            AnyChannel::new("B", FlatSamples::F32(vec![2.0; w * h])),
            AnyChannel::new("diffuse.R", FlatSamples::F32(vec![0.125; w * h])),
            AnyChannel::new("id", FlatSamples::U32(id.collect())),
        ]);
        let mut attrs = LayerAttributes::default();
        attrs.other.insert("gain".into(), AttributeValue::F32(2.5));
        attrs
            .other
            .insert("label".into(), AttributeValue::Text("latlong".into()));
        attrs.owner = Some("someone".into());
        let tiled = Encoding::FAST_LOSSLESS;
        let layer = Layer::new((w, h), attrs, tiled, AnyChannels::sort(list));
        Image::from_layer(layer).write().to_file(&path).unwrap();

        let img = read_exr(&path).unwrap();
        assert_eq!((img.width, img.height), (70, 3));
        assert_eq!(img.channel("R").unwrap()[137], f(137));
        assert_eq!(img.channel("diffuse.R").unwrap()[5], 0.125);
        assert_eq!(img.channel("id").unwrap()[209], 209.0);
        assert_eq!(img.attribute("gain"), Some("2.5"));
        assert_eq!(img.attribute("label"), Some("latlong"));
        assert_eq!(img.attribute("owner"), Some("someone"));
        let rgb = read_rgb(&path).unwrap();
        assert_eq!(rgb.pixel(67, 1), [f(137), 0.5, 2.0]);
        assert_eq!(rgb.pixel(500, 500), rgb.pixels[w * h - 1]);
    }

    #[test]
    fn read_rgb_ignores_alpha_and_accepts_luminance() {
        let path = scratch("rgba.exr");
        write_rgba_file(&path, 4, 2, |x, y| (x as f32, y as f32, 0.5f32, 0.25f32)).unwrap();
        let rgb = read_rgb(&path).unwrap();
        assert_eq!((rgb.width, rgb.height, rgb.pixels.len()), (4, 2, 8));
        assert_eq!(rgb.pixels[7], [3.0, 1.0, 0.5]);

        let grey = scratch("grey.exr");
        write_exr(&grey, &image(2, 1, &[("Y", vec![0.0, 0.75])])).unwrap();
        assert_eq!(read_rgb(&grey).unwrap().pixels, vec![[0.0; 3], [0.75; 3]]);
    }

    #[test]
    fn missing_channels_are_listed() {
        let path = scratch("nocolour.exr");
        let chans = ["R", "depth.Z", "A"].map(|n| (n, vec![1.0; 6]));
        write_exr(&path, &image(3, 2, &chans)).unwrap();
        let err = read_rgb(&path).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, ImageError::MissingChannels { .. }));
        assert!(
            msg.contains("nocolour.exr: no R, G, B (or Y) channels"),
            "{msg}"
        );
        assert!(msg.ends_with("the file has: A, R, depth.Z"), "{msg}");
    }

    #[test]
    fn bad_files_are_errors_not_panics() {
        let missing = scratch("does-not-exist.exr");
        let err = read_exr(&missing).unwrap_err();
        assert!(matches!(err, ImageError::NotFound { .. }), "{err}");
        assert!(err.to_string().contains("does-not-exist.exr"));

        let garbage = scratch("garbage.exr");
        std::fs::write(&garbage, b"this is not an OpenEXR file at all").unwrap();
        let err = read_rgb(&garbage).unwrap_err();
        assert!(matches!(err, ImageError::Unreadable { .. }), "{err}");

        let good = scratch("whole.exr");
        write_exr(&good, &sample_image(37, 19)).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let cut = scratch("truncated.exr");
        for len in (0..bytes.len() - 1).step_by(97).chain([bytes.len() - 1]) {
            std::fs::write(&cut, &bytes[..len]).unwrap();
            assert!(read_exr(&cut).is_err(), "{len} bytes read fine");
        }
        // Corrupt sizes are refused before any allocation: `dataWindow` is name, `box2i`, size,
        // then xMin, yMin, xMax, yMax as i32.
        let name = bytes.windows(11).position(|b| b == b"dataWindow\0");
        let at = name.unwrap() + 11 + 6 + 4;
        for (offset, expect) in [(8, "implausible"), (12, "too many")] {
            let mut corrupt = bytes.clone();
            corrupt[at + offset..at + offset + 4].copy_from_slice(&(1i32 << 29).to_le_bytes());
            std::fs::write(&cut, &corrupt).unwrap();
            let err = read_exr(&cut).unwrap_err().to_string();
            assert!(err.contains(expect), "{err}");
        }
        // A directory is not a file either.
        assert!(read_exr(&std::env::temp_dir()).is_err());
    }

    #[test]
    fn invalid_images_are_rejected_and_old_file_kept() {
        let path = scratch("keep.exr");
        let good = sample_image(2, 2);
        write_exr(&path, &good).unwrap();
        let before = std::fs::read(&path).unwrap();

        let mut short = good.clone();
        short.channels[3].data.pop();
        let err = write_exr(&path, &short).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, ImageError::SizeMismatch { len: 3, .. }));
        assert!(
            msg.contains("`albedo.R` has 3 values, expected 2×2 = 4"),
            "{msg}"
        );

        let mut dup = good.clone();
        dup.channels[1].name = "R".into();
        let mut reserved = good.clone();
        reserved.attributes.push(("channels".into(), "x".into()));
        let mut unnamed = good.clone();
        unnamed.channels[0].name.clear();
        let mut twice = good.clone();
        twice.attributes.push(("lapidary.spp".into(), "1".into()));
        for bad in [dup, reserved, unnamed, twice, ExrImage::default()] {
            let err = write_exr(&path, &bad).unwrap_err();
            assert!(matches!(err, ImageError::Invalid { .. }), "{err}");
        }
        assert_eq!(std::fs::read(&path).unwrap(), before);

        let err = write_exr(&scratch("no/such/dir.exr"), &good).unwrap_err();
        assert!(matches!(err, ImageError::Write { .. }), "{err}");
    }
}
