//! Why two images cannot be compared: "unusable input" (exit status 2 of `lapidary compare`).

use super::Role;
use crate::image::ImageError;

/// Why two images cannot be compared ("unusable input").
#[derive(thiserror::Error, Debug)]
pub enum CompareError {
    /// The images differ in size.
    #[error("sizes differ: test is {}x{}, reference is {}x{}", .test.0, .test.1, .reference.0, .reference.1)]
    SizeMismatch {
        /// Test image width and height in pixels.
        test: (u32, u32),
        /// Reference image width and height in pixels.
        reference: (u32, u32),
    },
    /// A colour channel is missing (or does not hold one value per pixel).
    #[error("the {which} image has no usable channel `{channel}` (it has: {})", list(.found))]
    MissingChannel {
        /// The image lacking the channel.
        which: Role,
        /// The channel looked for.
        channel: String,
        /// The channels the image does have.
        found: Vec<String>,
    },
    /// A variance channel holds a value that no variance can have (NaN, infinite or negative):
    /// the image's error estimate cannot be trusted anywhere, so nothing is tested.
    #[error(
        "the {which} image's `{channel}` is {value} at pixel ({x}, {y}); a variance must be \
         finite and ≥ 0 ({count} such values in the channel)"
    )]
    BadVariance {
        /// The image with the bad variance.
        which: Role,
        /// The variance channel (`variance.R`, `variance.G`, `variance.B` or `variance.Y`).
        channel: String,
        /// Column of the first bad value (pixels from the left).
        x: u32,
        /// Row of the first bad value (pixels from the top).
        y: u32,
        /// The first bad value.
        value: f32,
        /// How many values of the channel are bad.
        count: usize,
    },
    /// The mean-ratio tolerance is not a fraction in `[0, 1]`.
    #[error("mean tolerance {0} is not a fraction in [0, 1]")]
    BadTolerance(f64),
    /// The images have no pixels.
    #[error("the images are empty (0 pixels)")]
    Empty,
    /// An image could not be read.
    #[error(transparent)]
    Image(#[from] ImageError),
}

impl CompareError {
    /// The image the error is about, if it is about one of them.
    pub fn role(&self) -> Option<Role> {
        match self {
            CompareError::MissingChannel { which, .. }
            | CompareError::BadVariance { which, .. } => Some(*which),
            _ => None,
        }
    }
}

/// Channel names for a message.
fn list(names: &[String]) -> String {
    if names.is_empty() {
        "no channels".into()
    } else {
        names.join(", ")
    }
}
