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

/// A whole number within `lo ..= hi` for the field `name`. Read from any RON number, so that a
/// literal outside the field's type (`-1` or `99999999999999999999` for a `u64`, `5e9` for a
/// `u32`) is reported at the number with the field's name and range, instead of as the parser's
/// bare "Integer is out of bounds".
pub(crate) fn whole<'de, D: serde::Deserializer<'de>>(
    d: D,
    name: &'static str,
    lo: u64,
    hi: u64,
) -> Result<u64, D::Error> {
    struct Visit {
        name: &'static str,
        lo: u64,
        hi: u64,
    }
    impl Visit {
        fn out<E: serde::de::Error>(&self, v: impl std::fmt::Display) -> E {
            E::custom(format!(
                "{} = {v} is out of range: allowed {} ..= {} (a whole number)",
                self.name, self.lo, self.hi
            ))
        }
    }
    impl<'de> serde::de::Visitor<'de> for Visit {
        type Value = u64;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(f, "a whole number {} ..= {}", self.lo, self.hi)
        }
        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<u64, E> {
            if (self.lo..=self.hi).contains(&v) {
                Ok(v)
            } else {
                Err(self.out(v))
            }
        }
        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<u64, E> {
            match u64::try_from(v) {
                Ok(u) => self.visit_u64(u),
                Err(_) => Err(self.out(v)),
            }
        }
        fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<u64, E> {
            if v.fract() == 0.0 && v >= self.lo as f64 && v <= self.hi as f64 {
                Err(E::custom(format!(
                    "{} = {v:?}: write a whole number, without a decimal point or exponent",
                    self.name
                )))
            } else if v.abs() >= 9e15 {
                // Beyond 2⁵³ the parser's float is not the literal's exact value.
                Err(self.out(format!("{v:e}")))
            } else {
                Err(self.out(v))
            }
        }
    }
    d.deserialize_any(Visit { name, lo, hi })
}
