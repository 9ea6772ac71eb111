//! Light sampling at a vertex and the multiple-importance weights of the techniques that reach a
//! light (Veach & Guibas, "Optimally Combining Sampling Techniques for Monte Carlo Rendering",
//! SIGGRAPH 1995: power heuristic, β = 2): next-event estimation against BSDF sampling, and the
//! manifold walks against BSDF sampling of the same chains ([`super::manifold`]).

use super::facet::{NeePolarisation, facet_nee};
use super::path::{PathSample, PathState};
use super::shading::SurfaceBsdf;
use super::world::{LightRef, World};
use crate::bsdf::{Bsdf, Scatter, power_heuristic};
use crate::geometry::{Ray, offset_origin};
use crate::polarisation::stokes::ROWS;
use crate::polarisation::transport::MAX_CHANNELS;
use crate::spectrum::Spectral;
use glam::Vec3;

/// Which estimators of direct light are used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Strategy {
    /// Light sampling and BSDF sampling, combined by the power heuristic.
    #[default]
    Mis,
    /// Light sampling only: light reached by a BSDF-sampled ray is ignored (except from the
    /// camera).
    LightOnly,
    /// BSDF sampling only: no shadow rays.
    BsdfOnly,
}

/// What the Stokes AOVs' rows read of a light sample at a polarising vertex: the contribution
/// before any row's correction and each row's reading
/// ([`super::polarised::StokesAov::add_read`]).
pub(super) type RowsRead<S> = Option<(S, [[f32; MAX_CHANNELS]; ROWS])>;

/// Next-event estimation at `sb`: one light sample, weighted against BSDF sampling by `strategy`.
/// Returns what it added to the path's radiance (zero when nothing). With `POL` (polarised
/// transport), `polar` is the camera path's polarisation, which a bare conductor's Fresnel
/// matrix changes the sample's contribution by, and `rows` receives what the Stokes AOVs' rows
/// read of it there; without, both are untouched and the conductor's code is not compiled in.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn direct_light<S: Spectral, const POL: bool>(
    world: &World,
    strategy: Strategy,
    sb: &SurfaceBsdf,
    wo_local: Vec3,
    (u_light, u_point): (f32, glam::Vec2),
    path: &mut PathState<S>,
    out: &mut PathSample,
    polar: Option<&NeePolarisation<'_>>,
    rows: &mut RowsRead<S>,
) -> S
where
    Bsdf: Scatter<S>,
{
    let Some((light, p_pick)) = world.pick_light(u_light) else {
        return S::ZERO;
    };
    let sample = match light {
        LightRef::Area(i) => world.areas[i].sample(sb.p, u_point),
        LightRef::Environment => world.environment.sample(u_point),
    };
    let Some(ls) = sample else {
        return S::ZERO;
    };
    if !sb.admits(ls.wi) || (world.transmission_off && ls.wi.dot(sb.ng) < 0.0) {
        return S::ZERO;
    }
    // With MIS the BSDF's density toward the light is needed too (unless the light is hidden):
    // found with the value, which shares most of its work.
    let (wi_local, f, bsdf_pdf) = if strategy == Strategy::Mis {
        sb.eval_pdf::<S>(wo_local, ls.wi, &path.lambda)
    } else {
        let (wi_local, f) = sb.eval::<S>(wo_local, ls.wi, &path.lambda);
        (wi_local, f, 0.0)
    };
    if f.is_black() {
        return S::ZERO;
    }
    let origin = offset_origin(sb.p, sb.ng, ls.wi);
    let t_max = if ls.dist.is_finite() {
        (ls.dist - (origin - sb.p).length()) * (1.0 - 1e-4)
    } else {
        f32::INFINITY
    };
    out.rays += 1;
    if world.occluded(&Ray::new(origin, ls.wi), t_max) {
        return S::ZERO;
    }
    let p_light = p_pick * ls.pdf;
    let w = match strategy {
        Strategy::Mis => power_heuristic(p_light, bsdf_pdf),
        _ => 1.0,
    };
    let radiance = match light {
        LightRef::Area(i) => world.areas[i].emission::<S>(ls.radiance, &path.lambda),
        LightRef::Environment => S::from_illuminant(ls.radiance, &path.lambda),
    };
    let c = path.throughput() * f * radiance * (wi_local.z.abs() * w / p_light);
    if !c.is_valid() {
        return S::ZERO;
    }
    if POL
        && let Some(p) = polar
        && let Some(r) = {
            let polariser = match light {
                LightRef::Area(i) => world.areas[i].polariser(),
                LightRef::Environment => None,
            };
            let dirs = (sb.frame.to_world(wo_local), ls.wi);
            facet_nee::<S>(p, sb, dirs, polariser, &path.lambda)
        }
    {
        *rows = r.rows.map(|kf| (path.gathered(c), kf));
        return path.gather(c * S::from_channels(|ch| r.k[ch]));
    }
    path.gather(c)
}

/// Weight of one of the two ways to a light through the boundary (module [`manifold`]):
/// `p_walk` and `p_bsdf` are the densities of the direction at the vertex by the walk and by BSDF
/// sampling; `walk` says which technique produced the contribution. Light sampling only keeps the
/// walk's contributions (and BSDF sampling's where the walk cannot produce the path); BSDF
/// sampling only never runs the walk.
#[inline]
pub(super) fn manifold_weight(strategy: Strategy, p_walk: f32, p_bsdf: f32, walk: bool) -> f32 {
    match (strategy, walk) {
        (Strategy::Mis, true) => power_heuristic(p_walk, p_bsdf),
        (Strategy::Mis, false) => power_heuristic(p_bsdf, p_walk),
        (Strategy::LightOnly, true) => 1.0,
        (Strategy::LightOnly, false) => {
            if p_walk > 0.0 {
                0.0
            } else {
                1.0
            }
        }
        (Strategy::BsdfOnly, _) => 1.0,
    }
}

/// [`emission_weight`] of area light `index` met at distance `t` along `ray`.
#[inline]
pub(super) fn area_emission_weight<S: Spectral>(
    world: &World,
    strategy: Strategy,
    path: &PathState<S>,
    ray: &Ray,
    (index, t): (usize, f32),
) -> f32 {
    emission_weight(world, strategy, path, || {
        let origin = path.prev.map_or(ray.origin, |v| v.p);
        (
            LightRef::Area(index),
            world.areas[index].pdf(origin, ray.dir, t),
        )
    })
}

/// MIS weight of emission reached by the path's current ray (weight 1 for a camera ray, after a
/// specular event, which light sampling cannot reproduce, and after a vertex where no light was
/// sampled — a medium point or a reflecting surface inside the stone). `light_pdf` gives the
/// light and its solid-angle density for the direction.
#[inline]
pub(super) fn emission_weight<S: Spectral>(
    world: &World,
    strategy: Strategy,
    path: &PathState<S>,
    light_pdf: impl FnOnce() -> (LightRef, f32),
) -> f32 {
    let Some(prev) = path.prev else {
        return 1.0;
    };
    if prev.flags.is_specular() || !prev.nee {
        return 1.0;
    }
    match strategy {
        Strategy::BsdfOnly => 1.0,
        Strategy::LightOnly => 0.0,
        Strategy::Mis => {
            let (light, pdf) = light_pdf();
            let p_light = world.light_probability(light) * pdf;
            power_heuristic(prev.pdf, p_light)
        }
    }
}
