//! A coat level's tables for the Corrected model: `E_top` (shared by every material with the same
//! coat at the same level), the body's `A` and `Q` measured over the layers below, and the
//! constants of the multiple-reflection lobe (see [`super::corrected`] for the model).

use super::LayeredBsdf;
use super::absorption;
use super::corrected::sample;
use crate::bsdf::memo::Memo;
use crate::bsdf::refract_macro;
use crate::bsdf::table::{Table, for_strata};
use crate::sampler::hash_words;
use crate::spectrum::RgbSample;
use glam::Vec3;
use std::f32::consts::PI;
use std::sync::Arc;

/// Key of a coat's top-lobe albedo table: distribution, masking, `α` bits; relative IOR bits and
/// Fresnel mode; level and sampling grid (the level seeds the table's numbers).
type ETopKey = (
    (crate::bsdf::Distribution, crate::bsdf::Masking, u32),
    (u32, crate::bsdf::FresnelMode),
    (usize, usize),
);

/// Top-lobe albedo tables shared by the materials of a process (see [`crate::bsdf::memo`]).
static E_TOP: Memo<ETopKey, Arc<Table>> = Memo::new(4096);

/// Builds the tables of level `l` (the levels below must be built already): `E_top`, then `A` and
/// `Q` by stratified Monte Carlo over the Corrected sampling of the layers below, then `ρ̄`, `r_int`
/// and the multiple lobe's constants.
pub(super) fn build_tables(stack: &mut LayeredBsdf, l: usize, grid: usize) {
    let top = stack.levels[l].top.clone();
    stack.levels[l].e_top = if stack.levels[l].smooth {
        // A delta reflection's albedo is the Fresnel factor itself.
        let fresnel = stack.levels[l].fresnel.clone();
        Table::build(|mu| RgbSample::splat(fresnel.eval(mu)[0])).map(|e| e.min(1.0))
    } else {
        // Shared by every material with this coat at this level (a gem's materials often repeat
        // their varnish): the table depends on nothing else.
        let d = top.distribution;
        let key = (
            (d.kind(), d.masking(), d.alpha().to_bits()),
            (stack.levels[l].eta.to_bits(), stack.fresnel),
            (l, grid),
        );
        let table = E_TOP.get_or_build(key, || {
            Arc::new(crate::bsdf::store::table("e_top", &key, || {
                Table::by_sampling(grid, hash_words(&[l as u64, 1]), |wo, uc, u| {
                    top.sample_weight(wo, uc, u).map(|w| w.min(1e3))
                })
                .map(|e| e.min(1.0))
            }))
        });
        Table::clone(&table)
    };

    let eta = stack.levels[l].eta;
    let this = &*stack;
    // The stack's Debug text holds every input (this level's coat, the levels below it).
    let [albedo_rest, trapped] =
        crate::bsdf::store::tables("albedo_rest", &(l, grid, this), || {
            measure_rest(this, l, grid)
        });

    let lv = &stack.levels[l];
    let t_table = Table::build(|mu| RgbSample::splat(lv.t(mu)));
    let r_int = (1.0 - t_table.hemispherical(|_| 1.0)[0] / (eta * eta)).clamp(0.0, 1.0);
    let rho_bar = albedo_rest
        .hemispherical(|_| 1.0)
        .map(|x| x.clamp(0.0, 1.0));
    let denom = (RgbSample::ONE - rho_bar * r_int).map(|d| d.max(1e-6));
    let multi_albedo = rho_bar.zip(denom, |r, d| r * (1.0 - r_int) / d);
    // N = ∫ q(w) cos θ dω = 2π ∫₀¹ T(μ) Q(μ'(μ)) μ dμ, by the midpoint rule.
    let steps = 2048;
    let mut q_norm = RgbSample::ZERO;
    for i in 0..steps {
        let mu = (i as f32 + 0.5) / steps as f32;
        let mu_in = (1.0 - (1.0 - mu * mu) / (eta * eta)).max(0.0).sqrt();
        if mu_in > 0.0 && (1.0 - mu * mu) < eta * eta {
            q_norm += trapped.at(mu_in) * (lv.t(mu) * mu);
        }
    }
    q_norm *= 2.0 * PI / steps as f32;
    let multi_scale = multi_albedo.zip(q_norm, |m, n| if n > 1e-12 { m / n } else { 0.0 });
    let lv = &mut stack.levels[l];
    lv.albedo_rest = albedo_rest;
    lv.trapped = trapped;
    lv.multi_scale = multi_scale;
    lv.multi_albedo = multi_albedo;
}

/// `A` and `Q` of level `l` (the albedo of the layers below seen through its coat's absorption,
/// and the part of it trapped by internal reflection), by stratified Monte Carlo over the Corrected
/// sampling of the layers below (`grid² · UC_STRATA` samples per entry).
fn measure_rest(this: &LayeredBsdf, l: usize, grid: usize) -> [Table; 2] {
    let n2 = (grid * grid * crate::bsdf::table::UC_STRATA) as f32;
    let (eta, od) = (this.levels[l].eta, this.levels[l].od);
    let (a, q) = Table::build_pair_par(|mu| {
        let wo_in = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        let (mut a, mut q) = (RgbSample::ZERO, RgbSample::ZERO);
        for_strata(
            grid,
            hash_words(&[l as u64, 2, u64::from(mu.to_bits())]),
            |uc, u| {
                if let Some(s) = sample(this, l + 1, wo_in, uc, u, true) {
                    let wa = s.weight * absorption(od, mu, s.wi.z);
                    let t_out =
                        refract_macro(s.wi, 1.0 / eta).map_or(0.0, |wi| this.levels[l].t(wi.z));
                    a += wa;
                    q += wa * (1.0 - t_out);
                }
            },
        );
        (a / n2, q / n2)
    });
    [a, q]
}
