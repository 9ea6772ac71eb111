//! The written names of [`Model`] and [`FresnelMode`]: how the command line, `tradeoff` settings,
//! render metadata and `lapidary info` spell them. Each type parses itself ([`FromStr`], any
//! letter case) and prints itself ([`fmt::Display`]):
//!
//! | value | `{}` (knob spelling) | `{:#}` (recipe spelling, as in RON) |
//! |---|---|---|
//! | `Model::Course` | `course` | `Course` |
//! | `Model::Corrected` | `corrected` | `Corrected` |
//! | `Model::Reference(_)` | `reference` | `Reference` |
//! | `FresnelMode::Exact` … `Table` | `exact`, `schlick`, `lazanyi`, `table` | `Exact` … `Table` |
//!
//! | `Distribution::Blinn`, `Beckmann`, `Ggx` | `blinn`, `beckmann`, `ggx` | `Blinn`, `Beckmann`, `Ggx` |
//! | `Masking::VCavity`, `Smith`, `SmithSeparable` | `v-cavity`, `smith`, `smith-separable` | `VCavity`, `Smith`, `SmithSeparable` |
//!
//! A name carries no [`ReferenceParams`]: `reference` parses to the default walk (4 walks per
//! evaluation, depth 256), and the walk's own parameters are set in a recipe
//! (`Reference(samples: …, max_depth: …)`) or by `lapidary brdf --walks`.

use super::{Distribution, FresnelMode, Masking, Model, ReferenceParams};
use std::fmt;
use std::str::FromStr;

/// A name that is not one of the allowed values; the message lists them (e.g. ``model `fast` is
/// not one of: course, corrected, reference``).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{what} `{value}` is not one of: {}", allowed.join(", "))]
pub struct UnknownName {
    /// What was being named (`model`, `fresnel`).
    pub what: &'static str,
    /// The name as written.
    pub value: String,
    /// Every name accepted.
    pub allowed: &'static [&'static str],
}

impl Model {
    /// Every model name, in the order printed by error messages.
    pub const NAMES: [&'static str; 3] = ["course", "corrected", "reference"];

    /// The knob spelling (`course`, `corrected`, `reference`).
    pub fn name(self) -> &'static str {
        match self {
            Model::Course => Self::NAMES[0],
            Model::Corrected => Self::NAMES[1],
            Model::Reference(_) => Self::NAMES[2],
        }
    }
}

impl FresnelMode {
    /// Every Fresnel mode name, in the order printed by error messages.
    pub const NAMES: [&'static str; 4] = ["exact", "schlick", "lazanyi", "table"];
    /// Every mode, in the order of [`FresnelMode::NAMES`].
    pub const ALL: [FresnelMode; 4] = [
        FresnelMode::Exact,
        FresnelMode::Schlick,
        FresnelMode::Lazanyi,
        FresnelMode::Table,
    ];

    /// The knob spelling (`exact`, `schlick`, `lazanyi`, `table`).
    pub fn name(self) -> &'static str {
        match self {
            FresnelMode::Exact => Self::NAMES[0],
            FresnelMode::Schlick => Self::NAMES[1],
            FresnelMode::Lazanyi => Self::NAMES[2],
            FresnelMode::Table => Self::NAMES[3],
        }
    }
}

impl Distribution {
    /// Every distribution, in the order of [`Distribution::NAMES`].
    pub const ALL: [Distribution; 3] = [
        Distribution::Blinn,
        Distribution::Beckmann,
        Distribution::Ggx,
    ];
    /// Every distribution name.
    pub const NAMES: [&'static str; 3] = ["blinn", "beckmann", "ggx"];

    /// The knob spelling.
    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|d| *d == self).unwrap_or(0)]
    }
}

impl Masking {
    /// Every masking term, in the order of [`Masking::NAMES`].
    pub const ALL: [Masking; 3] = [Masking::VCavity, Masking::Smith, Masking::SmithSeparable];
    /// Every masking name.
    pub const NAMES: [&'static str; 3] = ["v-cavity", "smith", "smith-separable"];
    /// The recipe spellings, in the same order.
    const RECIPE: [&'static str; 3] = ["VCavity", "Smith", "SmithSeparable"];

    /// The knob spelling.
    pub fn name(self) -> &'static str {
        Self::NAMES[self.index()]
    }

    fn index(self) -> usize {
        Self::ALL.iter().position(|m| *m == self).unwrap_or(0)
    }
}

impl fmt::Display for Distribution {
    /// `blinn`, `beckmann` or `ggx`; with `{:#}` capitalised.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_name(f, self.name())
    }
}

impl fmt::Display for Masking {
    /// `v-cavity`, `smith` or `smith-separable`; with `{:#}` the recipe spelling.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if f.alternate() {
            f.pad(Self::RECIPE[self.index()])
        } else {
            f.pad(self.name())
        }
    }
}

impl FromStr for Distribution {
    type Err = UnknownName;

    /// `blinn`, `beckmann` or `ggx` (also `trowbridge-reitz`), in any letter case.
    fn from_str(s: &str) -> Result<Distribution, UnknownName> {
        let lower = s.to_ascii_lowercase();
        if lower == "trowbridge-reitz" {
            return Ok(Distribution::Ggx);
        }
        Distribution::ALL
            .into_iter()
            .find(|d| d.name() == lower)
            .ok_or_else(|| UnknownName {
                what: "distribution",
                value: s.to_string(),
                allowed: &Distribution::NAMES,
            })
    }
}

impl FromStr for Masking {
    type Err = UnknownName;

    /// `v-cavity`, `smith` or `smith-separable` (or the recipe spellings), in any letter case.
    fn from_str(s: &str) -> Result<Masking, UnknownName> {
        let lower = s.to_ascii_lowercase();
        Masking::ALL
            .into_iter()
            .find(|m| m.name() == lower || Masking::RECIPE[m.index()].to_ascii_lowercase() == lower)
            .ok_or_else(|| UnknownName {
                what: "masking",
                value: s.to_string(),
                allowed: &Masking::NAMES,
            })
    }
}

/// Writes `name`, capitalised under the alternate flag (`{:#}`).
fn write_name(f: &mut fmt::Formatter<'_>, name: &str) -> fmt::Result {
    if !f.alternate() {
        return f.pad(name);
    }
    let mut chars = name.chars();
    let capital: String = chars
        .next()
        .map(|c| c.to_ascii_uppercase())
        .into_iter()
        .chain(chars)
        .collect();
    f.pad(&capital)
}

impl fmt::Display for Model {
    /// `course`, `corrected` or `reference`; with `{:#}` `Course`, `Corrected` or `Reference`.
    /// Width and alignment are honoured (`{:<10}`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_name(f, self.name())
    }
}

impl fmt::Display for FresnelMode {
    /// `exact`, `schlick`, `lazanyi` or `table`; with `{:#}` capitalised.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_name(f, self.name())
    }
}

impl FromStr for Model {
    type Err = UnknownName;

    /// `course`, `corrected` or `reference` (the default walk: 4 walks per evaluation, depth
    /// 256), in any letter case.
    fn from_str(s: &str) -> Result<Model, UnknownName> {
        match s.to_ascii_lowercase().as_str() {
            "course" => Ok(Model::Course),
            "corrected" => Ok(Model::Corrected),
            "reference" => Ok(Model::Reference(ReferenceParams::default())),
            _ => Err(UnknownName {
                what: "model",
                value: s.to_string(),
                allowed: &Model::NAMES,
            }),
        }
    }
}

impl FromStr for FresnelMode {
    type Err = UnknownName;

    /// `exact`, `schlick`, `lazanyi` or `table`, in any letter case.
    fn from_str(s: &str) -> Result<FresnelMode, UnknownName> {
        let lower = s.to_ascii_lowercase();
        FresnelMode::ALL
            .into_iter()
            .find(|m| m.name() == lower)
            .ok_or_else(|| UnknownName {
                what: "fresnel",
                value: s.to_string(),
                allowed: &FresnelMode::NAMES,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distributions_and_maskings_round_trip() {
        for d in Distribution::ALL {
            assert_eq!(d.to_string().parse::<Distribution>(), Ok(d));
            assert_eq!(format!("{d:#}").parse::<Distribution>(), Ok(d));
        }
        for m in Masking::ALL {
            assert_eq!(m.to_string().parse::<Masking>(), Ok(m));
            assert_eq!(format!("{m:#}").parse::<Masking>(), Ok(m));
        }
        assert_eq!("GGX".parse::<Distribution>(), Ok(Distribution::Ggx));
        let e = "phong".parse::<Distribution>().unwrap_err().to_string();
        assert!(e.contains("blinn, beckmann, ggx"), "{e}");
        let e = "torrance".parse::<Masking>().unwrap_err().to_string();
        assert!(e.contains("v-cavity, smith, smith-separable"), "{e}");
    }

    #[test]
    fn models_round_trip() {
        let models = [
            Model::Course,
            Model::Corrected,
            Model::Reference(ReferenceParams::default()),
        ];
        for (m, name) in models.into_iter().zip(Model::NAMES) {
            assert_eq!(m.to_string(), name);
            assert_eq!(m.to_string().parse::<Model>(), Ok(m));
            assert_eq!(format!("{m:#}").parse::<Model>(), Ok(m));
            assert_eq!(name.to_ascii_uppercase().parse::<Model>(), Ok(m));
        }
        assert_eq!(format!("{:#}", Model::Course), "Course");
        assert_eq!(format!("{:#}", Model::Corrected), "Corrected");
        // The walk's parameters are not part of the name.
        let deep = Model::Reference(ReferenceParams {
            samples: 64,
            max_depth: 16,
        });
        assert_eq!(format!("{deep} {deep:#}"), "reference Reference");
        assert_eq!(format!("[{:<10}]", Model::Course), "[course    ]");
        assert_eq!(format!("[{:>10.3}]", Model::Course), "[       cou]");
    }

    #[test]
    fn fresnel_modes_round_trip() {
        for (m, name) in FresnelMode::ALL.into_iter().zip(FresnelMode::NAMES) {
            assert_eq!(m.to_string(), name);
            assert_eq!(m.to_string().parse::<FresnelMode>(), Ok(m));
            assert_eq!(format!("{m:#}").parse::<FresnelMode>(), Ok(m));
            assert_eq!(format!("{m:#}"), format!("{m:?}"));
        }
    }

    #[test]
    fn unknown_names_list_the_allowed_ones() {
        let e = "fast".parse::<Model>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "model `fast` is not one of: course, corrected, reference"
        );
        let e = "Fast".parse::<FresnelMode>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "fresnel `Fast` is not one of: exact, schlick, lazanyi, table"
        );
    }
}
