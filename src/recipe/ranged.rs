//! Range-checked deserializers: a number outside its range is refused while it is read, naming
//! the field and the allowed range. The refusal does not stop the parser ([`refuse`]: the error is
//! recorded, located at the number itself (`file:line:col`) and replaced by a stand-in), so one
//! check reports every such number; [`parse`] returns them all.

pub(crate) use super::source::recover::refuse;

/// Declares a deserializer for an `f32` field that refuses values outside `lo ..= hi` (or, with
/// `open`, `lo <.. hi`), naming the field and the range. The stand-in for a refused value
/// ([`refuse`]) is the nearest allowed one (below an open bound: `lo + 1` within the range; NaN:
/// as if below), or the one given after `else` (a field whose nearest value could raise errors of
/// its own, such as a `fill` below 1 making a surface transparent).
macro_rules! ranged {
    ($fn:ident, $name:literal, $lo:expr, $hi:expr) => {
        ranged!($fn, $name, $lo, $hi, else |v: f32| if v > $hi { $hi } else { $lo });
    };
    ($fn:ident, $name:literal, $lo:expr, $hi:expr, else $stand_in:expr) => {
        fn $fn<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
            let v = f32::deserialize(d)?;
            if (($lo)..=($hi)).contains(&v) {
                Ok(v)
            } else {
                $crate::recipe::ranged::refuse(
                    format!(
                        "{} = {v} is out of range: allowed {} ..= {}",
                        $name, $lo, $hi
                    ),
                    ($stand_in)(v),
                )
            }
        }
    };
    ($fn:ident, $name:literal, open $lo:expr, $hi:expr) => {
        fn $fn<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
            let v = f32::deserialize(d)?;
            if v > $lo && v <= $hi {
                Ok(v)
            } else {
                $crate::recipe::ranged::refuse(
                    format!(
                        "{} = {v} is out of range: allowed {} <.. {}",
                        $name, $lo, $hi
                    ),
                    if v > $hi {
                        $hi
                    } else {
                        f32::min($lo + 1.0, $hi)
                    },
                )
            }
        }
    };
}

/// A finite `f32` (stand-in 0).
pub(crate) fn finite<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = <f32 as serde::Deserialize>::deserialize(d)?;
    if v.is_finite() {
        Ok(v)
    } else {
        refuse(format!("{v} must be a finite number"), 0.0)
    }
}

/// Largest size (of a light, a cabochon, a slab), object units.
const MAX_SIZE: f32 = 1e4;

/// Sizes (each `0 <.. 1e4`), given as a tuple's components (`shown`, for the message); a refused
/// size is replaced by the nearest allowed one (1 for one at or below 0).
pub(crate) fn sizes_ok<E: serde::de::Error>(
    v: &mut [f32],
    shown: impl std::fmt::Debug,
) -> Result<(), E> {
    if v.iter().all(|x| *x > 0.0 && *x <= MAX_SIZE) {
        return Ok(());
    }
    refuse(
        format!("{shown:?} is out of range: each size allowed 0 <.. 1e4"),
        (),
    )?;
    for x in v {
        *x = if *x > MAX_SIZE {
            MAX_SIZE
        } else if *x > 0.0 {
            *x
        } else {
            1.0
        };
    }
    Ok(())
}

/// A whole-number bound as written in messages: the largest `u64` and `u32` as powers of two.
pub(crate) fn whole_bound(v: u64) -> String {
    match v {
        u64::MAX => "2⁶⁴ − 1".into(),
        0xffff_ffff => "2³² − 1".into(),
        v => v.to_string(),
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
        /// Refuses `v` (shown as given); the stand-in is the nearest bound (`above` it or not).
        fn out<E: serde::de::Error>(
            &self,
            v: impl std::fmt::Display,
            above: bool,
        ) -> Result<u64, E> {
            refuse(
                format!(
                    "{} = {v} is out of range: allowed {} ..= {} (a whole number)",
                    self.name,
                    whole_bound(self.lo),
                    whole_bound(self.hi)
                ),
                if above { self.hi } else { self.lo },
            )
        }
    }
    impl<'de> serde::de::Visitor<'de> for Visit {
        type Value = u64;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(
                f,
                "a whole number {} ..= {}",
                whole_bound(self.lo),
                whole_bound(self.hi)
            )
        }
        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<u64, E> {
            if (self.lo..=self.hi).contains(&v) {
                Ok(v)
            } else {
                self.out(v, v > self.hi)
            }
        }
        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<u64, E> {
            match u64::try_from(v) {
                Ok(u) => self.visit_u64(u),
                Err(_) => self.out(v, false),
            }
        }
        fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<u64, E> {
            let above = v > self.hi as f64;
            if v.fract() == 0.0 && v >= self.lo as f64 && !above {
                refuse(
                    format!(
                        "{} = {v:?}: write a whole number, without a decimal point or exponent",
                        self.name
                    ),
                    v as u64,
                )
            } else if v.abs() >= 9e15 {
                // Beyond 2⁵³ the parser's float is not the literal's exact value.
                self.out(format!("{v:e}"), above)
            } else {
                self.out(v, above)
            }
        }
    }
    d.deserialize_any(Visit { name, lo, hi })
}

/// Deepest inline nesting of map-tree nodes (the leaf counts): the runtime tree's own limit,
/// [`crate::texture::map::MAX_DEPTH`], which the compiler also applies through named maps.
pub const MAX_MAP_DEPTH: usize = crate::texture::map::MAX_DEPTH;
/// Deepest nesting of fields (`Sum`, `Product`, `Remap` inside one another; the leaf counts).
pub const MAX_FIELD_DEPTH: usize = 16;
/// Deepest nesting of brackets of any kind in a description file: room for the deepest map tree
/// (three brackets a level, as in `Switch(stops: [(0, …)])`) holding the deepest field.
pub const MAX_BRACKETS: usize = 3 * MAX_MAP_DEPTH + 2 * MAX_FIELD_DEPTH + 32;
/// The RON parser's own recursion limit: above anything [`MAX_BRACKETS`] admits (RON counts
/// more than one level for some brackets), so the file's nesting is always reported in this
/// project's words, before the parser runs.
pub const RON_RECURSION_LIMIT: usize = 4 * MAX_BRACKETS;
/// Stack of the thread description files are parsed on: deep enough for [`MAX_BRACKETS`] levels
/// of serde's recursion in a debug build (reserved address space; pages are touched only as used).
const PARSE_STACK_BYTES: usize = 256 << 20;

/// Refuses text nested deeper than the documented limits, at the first place that goes too deep:
/// map-tree nodes ([`MAX_MAP_DEPTH`]), fields ([`MAX_FIELD_DEPTH`]), then brackets of any kind
/// ([`MAX_BRACKETS`]).
pub(crate) fn check_nesting(source: &super::Source) -> Result<(), super::RecipeError> {
    let n = source.nesting();
    for (depth, max, what) in [
        (&n.maps, MAX_MAP_DEPTH, "map tree"),
        (&n.fields, MAX_FIELD_DEPTH, "field"),
        (&n.brackets, MAX_BRACKETS, "brackets"),
    ] {
        if depth.deepest > max {
            return Err(source.error(
                depth.first_at(max + 1),
                format!("{what} nested {} deep; at most {max}", depth.deepest),
            ));
        }
    }
    Ok(())
}

/// Parses description text with the project's RON options, after the text's own checks
/// ([`super::Source::check_text`]) and [`check_nesting`], on a thread with a stack deep enough
/// for every nesting the checks admit, recovering from value errors
/// ([`super::Source::recovering`]): the value when the parser got to the end, and every error
/// found (a value may come with value errors).
pub(crate) fn parse<T>(source: &super::Source) -> (Option<T>, Vec<super::RecipeError>)
where
    T: serde::de::DeserializeOwned + Send,
{
    if let Err(e) = source.check_text().and_then(|()| check_nesting(source)) {
        return (None, vec![e]);
    }
    // Spectrum files are read relative to the description's folder.
    let base = std::path::Path::new(&source.file).parent();
    let run = || {
        super::spectrum::with_base(base, || {
            source.recovering(|text| {
                super::ron_options()
                    .with_recursion_limit(RON_RECURSION_LIMIT)
                    .from_str::<T>(text)
            })
        })
    };
    std::thread::scope(|s| {
        match std::thread::Builder::new()
            .name("parse".into())
            .stack_size(PARSE_STACK_BYTES)
            .spawn_scoped(s, run)
        {
            Ok(handle) => handle
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p)),
            // No thread to be had: parse here, within the current stack.
            Err(_) => run(),
        }
    })
}

/// Most materials a recipe may have, its own and included together (and most in one file).
pub const MAX_MATERIALS: usize = 100_000;
/// Most named maps in a recipe's `maps`.
pub const MAX_NAMED_MAPS: usize = 100_000;
/// Most entries of one Voronoi, and most stops of one Switch.
pub const MAX_CHOICES: usize = 100_000;
/// Most nodes a compiled map tree may have (named maps count once, however often used).
pub const MAX_MAP_NODES: usize = 1_000_000;
/// Most inputs of one `Sum` or `Product`.
pub const MAX_FIELD_INPUTS: usize = 64;
/// Most coats of one material.
pub const MAX_COATS: usize = 16;
/// Most files one `include` list names.
pub const MAX_INCLUDES: usize = 256;
/// Most walks per evaluation of the Reference model (`samples`).
pub const MAX_REFERENCE_SAMPLES: u64 = 256;
/// Most bounces of one Reference walk (`max_depth`).
pub const MAX_REFERENCE_DEPTH: u64 = 4096;

/// A list of at most `max` elements (and at least one when `non_empty`) for the field `name`;
/// the error is raised at the first element too many, so it points into the file there.
pub(crate) fn bounded_list<'de, D, T>(
    d: D,
    name: &'static str,
    max: usize,
    non_empty: bool,
) -> Result<Vec<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: serde::Deserialize<'de>,
{
    struct Visit<T> {
        name: &'static str,
        max: usize,
        non_empty: bool,
        item: std::marker::PhantomData<T>,
    }
    impl<'de, T: serde::Deserialize<'de>> serde::de::Visitor<'de> for Visit<T> {
        type Value = Vec<T>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(f, "a list of at most {} elements", self.max)
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
            let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(self.max));
            while let Some(v) = seq.next_element()? {
                if out.len() == self.max {
                    return Err(serde::de::Error::custom(format!(
                        "{}: more than {} elements; at most {}",
                        self.name, self.max, self.max
                    )));
                }
                out.push(v);
            }
            if self.non_empty && out.is_empty() {
                return Err(serde::de::Error::custom(
                    "the list is empty; give at least one element",
                ));
            }
            Ok(out)
        }
    }
    d.deserialize_seq(Visit {
        name,
        max,
        non_empty,
        item: std::marker::PhantomData,
    })
}

/// `include`: at most [`MAX_INCLUDES`] files.
pub(crate) fn includes<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<String>, D::Error> {
    bounded_list(d, "include", MAX_INCLUDES, false)
}

/// `materials`: unique names, at most [`MAX_MATERIALS`].
pub(crate) fn materials<'de, D, V>(d: D) -> Result<indexmap::IndexMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    bounded_keys(d, "materials", MAX_MATERIALS)
}

/// `maps`: unique names, at most [`MAX_NAMED_MAPS`].
pub(crate) fn named_maps<'de, D, V>(d: D) -> Result<indexmap::IndexMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    bounded_keys(d, "maps", MAX_NAMED_MAPS)
}

/// A name → value map, rejecting a name given twice (a plain map would keep the later one
/// silently) and more than `max` names (the error at the first name too many).
fn bounded_keys<'de, D, V>(
    d: D,
    name: &'static str,
    max: usize,
) -> Result<indexmap::IndexMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    struct Bounded<V>(indexmap::IndexMap<String, V>);
    struct Visit<V> {
        name: &'static str,
        max: usize,
        value: std::marker::PhantomData<V>,
    }
    impl<'de, V: serde::Deserialize<'de>> serde::de::Visitor<'de> for Visit<V> {
        type Value = Bounded<V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(f, "a map from names to definitions")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> Result<Bounded<V>, A::Error> {
            let mut out = indexmap::IndexMap::new();
            while let Some(key) = m.next_key::<String>()? {
                if out.contains_key(&key) {
                    // The second definition is read (its own errors are reported) and dropped.
                    refuse(
                        format!("\"{key}\" is defined twice; names must be unique"),
                        (),
                    )?;
                    m.next_value::<V>()?;
                    continue;
                }
                if out.len() == self.max {
                    return Err(serde::de::Error::custom(format!(
                        "{}: more than {} definitions; at most {}",
                        self.name, self.max, self.max
                    )));
                }
                let value = m.next_value()?;
                out.insert(key, value);
            }
            Ok(Bounded(out))
        }
    }
    d.deserialize_map(Visit {
        name,
        max,
        value: std::marker::PhantomData,
    })
    .map(|b| b.0)
}

/// Two sizes, each `0 <.. 1e4` ([`sizes_ok`]).
pub(crate) fn positive2<'de, D: serde::Deserializer<'de>>(d: D) -> Result<(f32, f32), D::Error> {
    let v = <(f32, f32) as serde::Deserialize>::deserialize(d)?;
    let mut s = [v.0, v.1];
    sizes_ok(&mut s, v).map(|()| (s[0], s[1]))
}

/// A `u32` count in `lo ..= hi`; any number is read, so an overflowing literal still gets the
/// field's name and range.
pub(crate) fn count<'de, D: serde::Deserializer<'de>>(
    d: D,
    name: &'static str,
    lo: u32,
    hi: u32,
) -> Result<Option<u32>, D::Error> {
    let v = whole(d, name, lo.into(), hi.into())?;
    Ok(Some(v as u32)) // within `hi`, a u32
}

/// A seed field (`Option`): any `u64`, with the field's name and range when the literal is not
/// one.
pub(crate) fn seed_range<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<u64>, D::Error> {
    any_seed(d).map(Some)
}
/// A seed: any `u64`, with the field's name and range when the literal is not one.
pub(crate) fn any_seed<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    whole(d, "seed", 0, u64::MAX)
}

#[cfg(test)]
mod tests {
    use super::super::surface::{FieldDesc, MapDesc, SwitchDesc};
    use super::super::{Source, ron_options};

    /// Parses a map node recovering from value errors: the node and the errors' messages.
    fn recover(text: &str) -> (Option<MapDesc>, Vec<String>) {
        let (map, errors) =
            Source::new("m.ron", text).recovering(|t| ron_options().from_str::<MapDesc>(t));
        (map, errors.into_iter().map(|e| e.message).collect())
    }

    #[test]
    fn refused_values_are_replaced_by_allowed_stand_ins() {
        let (map, errors) = recover(
            "Voronoi(scale: 0.0, jitter: 2.0, fill: -0.5, seed: -1, \
             entries: [(0.0, Material(\"a\")), (1e9, Material(\"b\"))])",
        );
        assert_eq!(errors.len(), 6, "{errors:#?}");
        let Some(MapDesc::Voronoi {
            scale,
            jitter,
            fill,
            seed,
            entries,
            ..
        }) = map
        else {
            panic!("a Voronoi: {map:?}");
        };
        // The nearest allowed value; `fill` its default (a lower one makes cells transparent).
        assert_eq!((scale, jitter, fill, seed), (1e-4, 1.0, 1.0, Some(0)));
        assert_eq!((entries[0].0.0, entries[1].0.0), (1.0, 1.0));

        let (map, errors) = recover(
            "Switch(by: Perlin(scale: 1.0, octaves: 40, lacunarity: 1.0), \
             stops: [(0.5, Material(\"a\")), (0.2, Material(\"b\"))], blend: 3.0)",
        );
        assert_eq!(errors.len(), 3, "{errors:#?}");
        assert!(errors[2].contains("strictly ascending"), "{errors:#?}");
        let Some(MapDesc::Switch(SwitchDesc(s))) = map else {
            panic!("a Switch: {map:?}");
        };
        let FieldDesc::Perlin {
            octaves,
            lacunarity,
            ..
        } = s.by
        else {
            panic!("Perlin: {:?}", s.by);
        };
        // Below an open bound: one above it.
        assert_eq!((octaves, lacunarity), (16, 2.0));
        let t: Vec<f32> = s.stops.iter().map(|(t, _)| *t).collect();
        assert_eq!((t, s.blend), (vec![0.0, 1.0], 0.0));
        assert!(SwitchDesc::try_from(s).is_ok());
    }

    #[test]
    fn shape_errors_still_stop_the_parser() {
        // An empty `stops` and an unknown field: the value errors before them are kept.
        for (text, last) in [
            ("Switch(by: Constant(inf), stops: [])", "`stops` is empty"),
            ("Voronoi(scale: 0.0, size: 1.0, entries: [])", "`size`"),
        ] {
            let (map, errors) = recover(text);
            assert!(map.is_none() && errors.len() == 2, "{text}: {errors:#?}");
            assert!(errors[1].contains(last), "{text}: {errors:#?}");
        }
    }
}
