//! The Corrected (and Course) stack's lobe selection: the weights with which a sample picks the
//! top interface's lobe, the layers below or the multiple-reflection lobe for one `wo`, the escape
//! cone the layers below are sampled in over a diffuse base, and a path vertex's memo of the
//! weights ([`WeightsMemo`]). Shared by sampling ([`super::corrected`]) and by the joint value
//! and density ([`super::joint`]).

use super::LayeredBsdf;
use crate::bsdf::{Bsdf, refract_macro};
use glam::Vec3;
use std::cell::Cell;
use std::f32::consts::FRAC_1_PI;

/// Lobe-selection weights `[top, rest, multiple]` at a level for one `wo`, and the refracted
/// `wo'` ([`lobe_weights`]).
pub type LobeWeights = ([f32; 3], Option<Vec3>);

/// Smallest selection weight of a lobe that can contribute.
const LOBE_FLOOR: f32 = 1e-5;

/// Lobe-selection weights `[top, rest, multiple]` at level `l` for `wo` (sum 1, or all 0 when the
/// level reflects nothing), and the refracted `wo'`.
#[inline]
pub fn lobe_weights(stack: &LayeredBsdf, l: usize, wo: Vec3, corrected: bool) -> LobeWeights {
    let lv = &stack.levels[l];
    let e = lv.e_top.at(wo.z)[0].max(0.0);
    let wo_in = refract_macro(wo, lv.eta);
    let mut w = [e, 0.0, 0.0];
    if let Some(wi) = wo_in {
        let t = 1.0 - e;
        let a = lv.albedo_rest.at(wi.z);
        let q = lv.trapped.at(wi.z);
        if corrected {
            // The calibration scales the body's albedo by about c(μo)².
            let c2 = match (&stack.calibration, l) {
                (Some(c), 0) => {
                    let c = c.at(wo.z);
                    (c * c).luminance().max(0.0)
                }
                _ => 1.0,
            };
            w[1] = t * c2 * (a - q).luminance().max(0.0);
            // The cosine lobe also carries the top interface's multiple-scattering reflection.
            let ms = lv.top_energy.as_ref().map_or(0.0, |e| e.split(wo).0);
            w[2] = t * c2 * (q * lv.multi_albedo).luminance().max(0.0) + ms;
        } else {
            w[1] = t * a.luminance().max(0.0);
        }
    }
    // Floors keep every lobe that can be non-zero sampleable (pdf > 0 wherever f > 0), also where
    // a table rounds a tiny albedo to 0 (e.g. m → 90°, where D·cos sampling almost always fails).
    w[0] = w[0].max(LOBE_FLOOR);
    if wo_in.is_some() {
        w[1] = w[1].max(LOBE_FLOOR);
        if corrected {
            w[2] = w[2].max(LOBE_FLOOR);
        }
    }
    let sum = w[0] + w[1] + w[2];
    if sum > 0.0 && sum.is_finite() {
        (w.map(|x| x / sum), wo_in)
    } else {
        ([0.0; 3], wo_in)
    }
}

/// When the layer below level `l` is a diffuse base (Lambert or Oren–Nayar, sampled by cosine),
/// the rest lobe samples only the **escape cone** `sin θ' < 1/η` — the inner directions that can
/// leave — instead of the whole hemisphere, so no sample is spent on a direction that must fail.
/// Returns the cone's squared disk radius `1/η²`, or `None` (glossy base, deeper coat, `η ≤ 1`).
/// The tables still integrate the base over the whole hemisphere.
#[inline]
pub(super) fn escape_cone(stack: &LayeredBsdf, l: usize) -> Option<f32> {
    let eta = stack.levels[l].eta;
    let diffuse = matches!(stack.base, Bsdf::Lambert(_) | Bsdf::OrenNayar(_));
    (l + 1 == stack.levels.len() && diffuse && eta > 1.0).then(|| 1.0 / (eta * eta))
}

/// Density of [`sample_cone_cosine`] for a direction known to lie in the cone.
#[inline]
pub(super) fn cone_cosine_pdf(w: Vec3, r2: f32) -> f32 {
    if w.z <= 0.0 {
        0.0
    } else {
        w.z * FRAC_1_PI / r2
    }
}

/// The Corrected stack's lobe weights for one `wo` ([`lobe_weights`]), kept by a path vertex
/// (`render::SurfaceBsdf`) between its next-event estimation, which needs them for the density
/// toward the light, and its continuation sample, which picks its lobe with them: three table
/// lookups, a refraction and the calibration's lookup done once per vertex instead of twice. Keyed
/// by the bits of `wo`, so a query for another direction finds them afresh.
#[derive(Clone, Debug, Default)]
pub struct WeightsMemo(Cell<Option<([u32; 3], LobeWeights)>>);

impl WeightsMemo {
    /// The top level's weights for `wo` under the Corrected model.
    #[inline]
    pub(super) fn get(&self, stack: &LayeredBsdf, wo: Vec3) -> LobeWeights {
        let key = wo.to_array().map(f32::to_bits);
        if let Some((k, w)) = self.0.get()
            && k == key
        {
            return w;
        }
        let w = lobe_weights(stack, 0, wo, true);
        self.0.set(Some((key, w)));
        w
    }
}
