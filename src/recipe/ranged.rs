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

/// Deserializes a name → value map, rejecting a name given twice (a plain map would keep the
/// later one silently).
pub(crate) fn unique_keys<'de, D, V>(d: D) -> Result<indexmap::IndexMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    struct Visit<V>(std::marker::PhantomData<V>);
    impl<'de, V: serde::Deserialize<'de>> serde::de::Visitor<'de> for Visit<V> {
        type Value = indexmap::IndexMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map from names to definitions")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut m: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = indexmap::IndexMap::new();
            while let Some(key) = m.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "\"{key}\" is defined twice; names must be unique"
                    )));
                }
                let value = m.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Visit(std::marker::PhantomData))
}

/// A finite `f32`.
pub(crate) fn finite<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = <f32 as serde::Deserialize>::deserialize(d)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(serde::de::Error::custom(format!(
            "{v} must be a finite number"
        )))
    }
}

/// Sizes (each `0 <.. 1e4`), given as a tuple's components.
pub(crate) fn sizes_ok<E: serde::de::Error>(
    v: &[f32],
    shown: impl std::fmt::Debug,
) -> Result<(), E> {
    if v.iter().all(|x| *x > 0.0 && *x <= 1e4) {
        Ok(())
    } else {
        Err(E::custom(format!(
            "{shown:?} is out of range: each size allowed 0 <.. 1e4"
        )))
    }
}
