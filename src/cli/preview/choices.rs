//! The knobs the page offers: every knob `lapidary tradeoff` knows, with its values.

use serde_json::{Value, json};

/// Most fields one `POST /knobs` may carry (every knob once, and `reset`).
pub const MAX_KNOB_FIELDS: usize = 40;

/// The page's knob controls: each knob `tradeoff` knows with its values (`platelets` only on or
/// off: `render` has no flag for explicit or statistical); `null` for a number (its range is in
/// the knob's error message).
pub fn knob_choices() -> Value {
    use crate::bsdf::{Distribution, Masking};
    let onoff = json!(["on", "off"]);
    let mut v = json!({
        "model": ["course", "corrected", "reference"],
        "fresnel": ["exact", "schlick", "lazanyi", "table"],
        "distribution": Distribution::NAMES,
        "masking": Masking::NAMES,
        "compensation": onoff,
        "calibration": onoff,
        "sampler": ["sobol", "independent"],
        "max-depth": null,
        "medium-depth": null,
        "medium-scattering": onoff,
        "manifold-continuation": onoff,
        "manifold-halvings": null,
    });
    for e in crate::scene::Effect::ALL {
        v[e.name()] = onoff.clone();
    }
    v
}
