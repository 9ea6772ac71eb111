//! Range-checked deserializers: a number outside its range is rejected while it is read, so the
//! RON parser reports the error at the number itself (`file:line:col`), naming the field and the
//! allowed range.

/// Declares a deserializer for an `f32` field that rejects values outside `lo ..= hi` (or, with
/// `open`, `lo <.. hi`), naming the field and the range.
macro_rules! ranged {
    ($fn:ident, $name:literal, $lo:expr, $hi:expr) => {
        fn $fn<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
            let v = f32::deserialize(d)?;
            if (($lo)..=($hi)).contains(&v) {
                Ok(v)
            } else {
                Err(serde::de::Error::custom(format!(
                    "{} = {v} is out of range: allowed {} ..= {}",
                    $name, $lo, $hi
                )))
            }
        }
    };
    ($fn:ident, $name:literal, open $lo:expr, $hi:expr) => {
        fn $fn<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
            let v = f32::deserialize(d)?;
            if v > $lo && v <= $hi {
                Ok(v)
            } else {
                Err(serde::de::Error::custom(format!(
                    "{} = {v} is out of range: allowed {} <.. {}",
                    $name, $lo, $hi
                )))
            }
        }
    };
}

