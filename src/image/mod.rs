//! Image input and output: OpenEXR with arbitrary channels (AOVs) and text metadata, tone-mapped
//! 8-bit sRGB PNG, and atomic file replacement.
//!
//! Pixel values are linear radiometric quantities (whatever the renderer stores, typically
//! radiance in W·sr⁻¹·m⁻² per channel, or dimensionless AOVs such as albedo); images are stored
//! row-major, top row first. Every writer goes through [`write_atomically`], so a failed write
//! never replaces an existing file.
//!
//! ```no_run
//! use lapidary::image::{Channel, ExrImage, read_rgb, write_exr};
//! let img = ExrImage {
//!     width: 2,
//!     height: 1,
//!     channels: ["R", "G", "B"]
//!         .map(|n| Channel::new(n, vec![0.5, 1.0]))
//!         .into(),
//!     attributes: vec![("lapidary.spp".into(), "64".into())],
//! };
//! write_exr("out.exr".as_ref(), &img)?;
//! assert_eq!(read_rgb("out.exr".as_ref())?.pixels[1], [1.0; 3]);
//! # Ok::<(), lapidary::image::ImageError>(())
//! ```

pub mod atomic;
pub mod compare;
pub mod exr;
pub mod flip;
pub mod heatmap;
pub mod input_kind;
pub mod outputs;
pub mod png;
pub mod stats;

pub use self::atomic::write_atomically;
pub use self::compare::{CompareError, Comparison, ZTest, compare};
pub use self::exr::{RgbImage, read_exr, read_exr_raw, read_rgb, write_exr, write_exr_raw};
pub use self::heatmap::write_heatmap;
pub use self::png::{Curve, ToneMap, tone_map_pixel, write_png};

use std::path::PathBuf;

/// One named channel of an [`ExrImage`]: one value per pixel, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Full channel name, layer prefix included (`"R"`, `"albedo.G"`, `"samples.Y"`).
    pub name: String,
    /// `width × height` samples, in the channel's own unit (radiance for colour channels).
    pub data: Vec<f32>,
}

/// A flat (non-deep) single-part image with any set of `f32` channels and text attributes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The channels; each holds `width × height` values.
    pub channels: Vec<Channel>,
    /// Text metadata as `(key, value)` pairs, e.g. `("lapidary.spp", "64")`.
    pub attributes: Vec<(String, String)>,
}

/// A channel of exact 32-bit unsigned integers (OpenEXR's `UINT` type), for data that must
/// round-trip bit for bit, such as a part render's fixed-point sums.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RawChannel {
    /// Full channel name (`"raw.sum.R.0"`).
    pub name: String,
    /// `width × height` words, row-major, top row first.
    pub data: Vec<u32>,
}

impl Channel {
    /// A channel named `name` holding `data`.
    pub fn new(name: impl Into<String>, data: Vec<f32>) -> Self {
        Channel {
            name: name.into(),
            data,
        }
    }
}

impl ExrImage {
    /// The samples of the channel with exactly this name, if present.
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.data.as_slice())
    }

    /// The value of the attribute with exactly this key, if present.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The channel names, in stored order.
    pub fn channel_names(&self) -> Vec<&str> {
        self.channels.iter().map(|c| c.name.as_str()).collect()
    }
}

/// Everything that can go wrong reading or writing an image; every message names the file.
#[derive(thiserror::Error, Debug)]
pub enum ImageError {
    /// The file does not exist.
    #[error("{}: no such file", .path.display())]
    NotFound {
        /// The file asked for.
        path: PathBuf,
    },
    /// The file exists but could not be read or parsed as OpenEXR (garbage, truncated, corrupt).
    #[error("{}: not a readable OpenEXR file: {reason}", .path.display())]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// What the decoder reported.
        reason: String,
    },
    /// A valid EXR that this module cannot represent (deep data only, subsampled channels, …).
    #[error("{}: unsupported OpenEXR content: {reason}", .path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What is unsupported.
        reason: String,
    },
    /// The colour channels asked for are missing.
    #[error("{}: no {wanted} channels; the file has: {}", .path.display(), list(.found))]
    MissingChannels {
        /// The file.
        path: PathBuf,
        /// The channels that were looked for, e.g. `"R, G, B (or Y)"`.
        wanted: String,
        /// The channel names the file does have.
        found: Vec<String>,
    },
    /// A buffer does not hold `width × height` values.
    #[error("{}: {what} has {len} values, expected {width}×{height} = {}",
        .path.display(), (*.width as u64) * (*.height as u64))]
    SizeMismatch {
        /// The file being written.
        path: PathBuf,
        /// Which buffer (e.g. "channel `albedo.R`", "pixel slice").
        what: String,
        /// Its length.
        len: usize,
        /// Image width in pixels.
        width: u32,
        /// Image height in pixels.
        height: u32,
    },
    /// Image data that cannot be written as given (zero size, bad or duplicate names, …).
    #[error("{}: invalid image: {reason}", .path.display())]
    Invalid {
        /// The file being written.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Encoding or the file system failed while writing; an existing file was left untouched.
    #[error("{}: cannot write: {reason}", .path.display())]
    Write {
        /// The file being written.
        path: PathBuf,
        /// What failed.
        reason: String,
    },
}

impl ImageError {
    /// A [`ImageError::Write`] for a file-system failure of an atomic write (see
    /// [`atomic::replace_with`]): `what` is "write" or "replace".
    pub(crate) fn io(path: &std::path::Path, what: &str, e: std::io::Error) -> Self {
        let reason = match what {
            "write" => format!("{e}; the old file, if any, is unchanged"),
            _ => format!("cannot {what} it: {e}"),
        };
        ImageError::Write {
            path: path.into(),
            reason,
        }
    }

    /// A [`ImageError::Write`] about `path`.
    pub(crate) fn write(path: &std::path::Path, reason: impl std::fmt::Display) -> Self {
        ImageError::Write {
            path: path.into(),
            reason: reason.to_string(),
        }
    }
}

/// Formats a channel list for error messages.
fn list(names: &[String]) -> String {
    if names.is_empty() {
        "no channels".into()
    } else {
        names.join(", ")
    }
}
