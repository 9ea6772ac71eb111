//! Unidirectional path tracing with next-event estimation and multiple importance sampling
//! (Veach & Guibas, "Optimally Combining Sampling Techniques for Monte Carlo Rendering",
//! SIGGRAPH 1995: power heuristic, β = 2), Russian roulette, and the map tree choosing the layered
//! BSDF and facet normal at every hit on the stone.
//!
//! **Depth.** `max_depth` counts scattering events: 1 is direct lighting only (light seen by the
//! camera, plus one bounce to a light), as in pbrt.
//!
//! **Facets.** Where the map gives a facet normal, the BSDF is evaluated in the facet's frame
//! ([`facet_frame`]); directions below the *unbumped* shading surface or the geometric surface
//! are dropped (the rule of [`crate::texture::bump`]), so a facet never gains energy.
//!
//! **Transmission.** A BSDF with a transmission lobe (a dielectric interface) sends the path
//! through the surface: the ray continues on the far side in the medium behind it
//! ([`PathState::scatter`]), and Russian roulette divides out the `η²` of the crossing. An opaque
//! scene never samples one, and its renders are bit-identical to the loop before transmission
//! existed.
//!
//! **Media** (issue 17). A translucent body's interior is a homogeneous medium
//! ([`crate::medium`]). On every segment through it the free flight is sampled (chromatic
//! coefficients by the one-sample MIS over channels); a scattering event picks a new direction
//! from the phase function and counts towards `medium-depth`, not `max-depth`. There is no
//! next-event estimation at medium points nor at opaque cells seen from inside: the medium is
//! enclosed by the stone, whose boundary always refracts or is opaque, so no shadow ray from
//! inside reaches a light; light behind a refracting boundary is found by BSDF and phase
//! sampling, as in pbrt-v4 and Mitsuba 3. A rough boundary hit from inside does get next-event
//! estimation through its transmission lobe (the shadow ray starts on the boundary, outside).
//! A scattering point within rounding of the boundary ahead is moved back by at most the spawn
//! offset (`keep_off_the_boundary`), or its next ray could miss the boundary and leave the stone.
//! Scenes without a body never run this code (the `transmission` and `medium` effects).
//!
//! **Platelets** (issue 18). Inside the body the nearest of the boundary and a platelet is the
//! surface, and the free flight runs up to it; platelets are walked only up to the boundary (a
//! ray that meets none is outside the stone by rounding). A ray leaving a platelet skips it (`path.platelet`)
//! instead of being offset from the disc, and starts at least the spawn offset inside the boundary
//! ahead (`keep_off_the_boundary`): a disc the boundary cuts is hit arbitrarily close to it, and an
//! offset along the disc's normal put the next ray outside the stone, where it met no boundary and
//! bounced among the population's discs beyond the stone until `max_depth` (tests/platelets.rs).
//!
//! **Light through the boundary** (issue 18). At a platelet hit or a medium scattering point
//! inside a smooth boundary, and at a floor hit under a smooth stone, a manifold walk samples a
//! light through the boundary ([`super::manifold`]); `PathState::manifold` keeps the vertex while
//! the BSDF-sampled continuation follows the walk's chain, so a light it reaches is weighted
//! against the walk (`direct::manifold_weight`).
//!
//! **Fluorescence** (issue 20). At a hit on a fluorescent base ([`crate::bsdf::layered::fluorescent`])
//! the path picks, before next-event estimation, the fluorescent lobe with probability
//! [`FLUORESCENT_SHARE`] or the elastic stack otherwise, and divides by the probability (a
//! one-sample estimate of their sum). Taking the fluorescent lobe, the throughput takes the
//! re-radiation ([`Spectral::fluoresce`]): in spectral transport each carried wavelength `λo`
//! draws the excitation wavelength `λi ≤ λo` that fed it, weighted by `K/p`, and the path carries
//! `λi` from there (`path.lambda`) while the film keeps `λo` (`path.film`) — the hero-wavelength
//! fluorescence of Mojzík, Fichet & Wilkie, EGSR 2018, with one excitation sample per carried
//! wavelength; in RGB the matrix moves throughput between channels. The vertex's next-event
//! estimation and BSDF sample then use that lobe alone. Scenes without a fluorescent base never
//! enter this code (`world.fluorescence`, the `fluorescence` effect), and `film == lambda` on
//! every path that does not fluoresce, so their renders are unchanged bit for bit.
//!
//! **Variants.** [`trace`] is generic over the transported light `S` and monomorphised per variant
//! ([`crate::spectrum`]); the film receives the path's radiance as a stored colour.
//!
//! **Sample dimensions.** The slot layout is [`crate::sampler`]'s (written once there).

use super::crystal_segment::{pleochroic_segment, pleochroic_transmittance};
use super::direct::{
    Strategy, area_emission_weight, direct_light, emission_weight, manifold_weight,
};
use super::facet::NeePolarisation;
use super::manifold;
use super::manifold::{Chain, WalkNumbers, WalkVertex};
use super::path::{ManifoldVertex, PathSample, PathState, keep_off_the_boundary};
use super::polarised::{StokesAov, crystal_boundary, crystal_sample, polarise, stokes_add};
use super::segment::{Meeting, medium_vertex_light, meet};
use super::shading::shade;
use super::world::{Hit, LightRef, World};
use crate::bsdf::{Bsdf, Scatter};
use crate::color::Rgb;
use crate::geometry::{MediumId, Ray, offset_origin};
use crate::medium::FreeFlight;
use crate::polarisation::transport::{ANALYSER_TRANSMITTANCE, PathPolarisation};
use crate::sampler::{PixelSampler, slots};
use crate::spectrum::Spectral;
use glam::Vec3;

/// Bounces after which Russian roulette may end a path (the lane loop's too).
pub(crate) const RR_DEPTH: u32 = 3;

/// The probability that a path at a fluorescent base takes the fluorescent lobe (module docs).
const FLUORESCENT_SHARE: f32 = 0.5;

/// The path loop; with `POL` the path carries its sensor's Stokes row
/// ([`crate::polarisation::transport`]): a camera analyser starts it, smooth dielectric
/// boundaries act by Fresnel's Mueller matrices, every other vertex depolarises, and a polarised
/// light's emission is measured by the row. `analyser` is the camera's (the world's, or a
/// dichroscope's right window's). With `STOKES` (polarised only) the path also measures the
/// Stokes vector of its light ([`crate::polarisation::stokes`]) into `stokes`.
#[allow(clippy::too_many_arguments)]
pub(super) fn trace_path<S: Spectral, const POL: bool, const STOKES: bool>(
    world: &World,
    mut ray: Ray,
    sampler: &mut PixelSampler,
    max_depth: u32,
    strategy: Strategy,
    lambda: S::Wavelengths,
    analyser: Option<Vec3>,
    stokes: &mut [Rgb; 4],
) -> (PathSample, S)
where
    Bsdf: Scatter<S>,
{
    let mut out = PathSample {
        material: -2,
        ..PathSample::default()
    };
    if world.camera_medium != MediumId::OUTSIDE {
        ray.medium = world.camera_medium;
    }
    let mut path = PathState::<S>::new(lambda, ray.medium);
    let mut pol = PathPolarisation::UNPOLARISED;
    // The Stokes AOVs' rows (polarised transport with `--stokes`).
    let mut aov: Option<StokesAov<S>> = None;
    if POL && STOKES {
        aov = StokesAov::new(world, ray.dir);
    }
    if let Some(axis) = analyser {
        if POL {
            pol = PathPolarisation::analyser(axis, ray.dir);
        }
        path.beta *= ANALYSER_TRANSMITTANCE;
    }
    loop {
        sampler.skip_to(slots::bounce(path.depth));
        out.rays += 1;
        let mut found = world.intersect(&ray, f32::INFINITY);
        let Meeting { hidden, flight } = meet(world, &ray, &mut path, sampler, &mut found);
        // A pleochroic crystal absorbs by the wave the segment carries (polarised transport).
        let pleochroic = POL
            .then(|| pleochroic_segment(world, path.medium, sampler))
            .flatten();
        if let Some((u, hero)) = flight {
            let medium = &world.media[usize::from(path.medium.0)];
            let t_hit = found.as_ref().map_or(f32::INFINITY, Hit::t);
            match medium.free_flight::<S>(t_hit, hero, u.y, &path.lambda) {
                FreeFlight::Pass { value, pdf } => path.take_flight(hero, value, pdf),
                FreeFlight::Scatter { t, value, pdf } => {
                    path.take_flight(hero, value, pdf);
                    if let Some((c, u)) = pleochroic {
                        let rows = aov.as_mut().filter(|_| STOKES).map(|a| &mut a.rows);
                        path.beta *= pleochroic_transmittance::<S>(
                            c,
                            &mut pol,
                            rows,
                            ray.dir,
                            t,
                            u,
                            &path.lambda,
                        );
                    }
                    if path.medium_events >= world.medium_depth || !path.alive() {
                        break;
                    }
                    let Some(phase) = medium.phase() else { break };
                    let ahead = hidden.as_ref().or(found.as_ref());
                    let p = keep_off_the_boundary(ray.at(t), &ray, ahead);
                    let Some(ps) = phase.sample(-ray.dir, sampler.get2d()) else {
                        break;
                    };
                    path.manifold = None;
                    if let Some(setup) = &world.manifold
                        && setup.inside
                        && strategy != Strategy::BsdfOnly
                    {
                        let at = (p, ray.dir);
                        let v = medium_vertex_light::<S, STOKES>(
                            world, setup, strategy, sampler, at, &phase, &ps, &mut path, &mut aov,
                        );
                        path.manifold = Some(v);
                    }
                    path.scatter_in_medium(ps.pdf, p);
                    if POL {
                        pol.depolarise();
                        if STOKES && let Some(a) = &mut aov {
                            a.rows.depolarise();
                        }
                    }
                    path.platelet = None;
                    if path.depth >= RR_DEPTH {
                        let q = path.survival();
                        if !(sampler.get1d() < q) {
                            break;
                        }
                        path.beta *= 1.0 / q;
                    }
                    ray = Ray::in_medium(p, ps.wi, path.medium);
                    continue;
                }
            }
        }
        if let Some((c, u)) = pleochroic
            && let Some(h) = &found
        {
            let rows = aov.as_mut().filter(|_| STOKES).map(|a| &mut a.rows);
            path.beta *=
                pleochroic_transmittance::<S>(c, &mut pol, rows, ray.dir, h.t(), u, &path.lambda);
        }
        let hit = match found {
            None => {
                let le = S::from_illuminant(world.environment.radiance(ray.dir), &path.lambda);
                let w = emission_weight(world, strategy, &path, || {
                    (LightRef::Environment, world.environment.pdf(ray.dir))
                });
                let added = path.add_emission(le, w);
                if STOKES {
                    stokes_add(&mut aov, added);
                }
                break;
            }
            Some(Hit::Light { index, t }) => {
                let le_unpolarised = world.areas[index]
                    .emission::<S>(world.areas[index].emitted(-ray.dir), &path.lambda);
                let mut le = le_unpolarised;
                // The Stokes rows' own readings of a polarised light (before they settle).
                let mut read = None;
                if POL && let Some(axis) = world.areas[index].polariser() {
                    let k = pol.polarised_emission(axis, -ray.dir);
                    le *= S::from_channels(|c| k[c]);
                    read = aov
                        .as_ref()
                        .filter(|_| STOKES)
                        .filter(|a| !a.rows.settled)
                        .map(|a| a.rows.polarised_emission(axis, -ray.dir));
                }
                let w = match (path.manifold, &world.manifold) {
                    // The walk's chain of refractions since a vertex where the walk ran.
                    (Some(v), Some(setup)) if v.crossings == v.chain.crossings() => {
                        let p_walk =
                            manifold::density(world, setup, v.p, v.d, ray.at(t), index, v.chain);
                        manifold_weight(strategy, p_walk, v.pdf, false)
                    }
                    _ => area_emission_weight(world, strategy, &path, &ray, (index, t)),
                };
                let added = path.add_emission(le, w);
                if STOKES && let Some(a) = &mut aov {
                    match read {
                        Some(kf) => {
                            a.add_read(path.gathered(path.throughput() * le_unpolarised * w), kf)
                        }
                        None => a.add(added),
                    }
                }
                if path.depth == 0 {
                    out.depth = Some(t);
                }
                break;
            }
            Some(h) => h,
        };
        let wo = -ray.dir;
        let u_switch = sampler.get1d();
        let Some(mut sb) = shade(
            world,
            &hit,
            wo,
            u_switch,
            path.lambda,
            path.depth == 0,
            &mut out,
        ) else {
            break;
        };
        if path.bounces() >= max_depth {
            break;
        }
        // A fluorescent base (module docs): the fluorescent lobe with probability
        // FLUORESCENT_SHARE — the throughput takes the re-radiation and the path carries the
        // excitation wavelengths from here — else the elastic stack.
        if world.fluorescence
            && let Some(colorant) = sb.fluorescence()
        {
            let u = sampler.get2d_at(slots::fluorescence(path.depth));
            if u.x < FLUORESCENT_SHARE {
                let u = glam::Vec2::new(u.x / FLUORESCENT_SHARE, u.y);
                if let Some(m) = path
                    .beta
                    .fluoresce(&mut path.lambda, colorant, &world.lines, u)
                {
                    path.take_remap(&m);
                }
                path.beta *= 1.0 / FLUORESCENT_SHARE;
                sb.fluoresce();
            } else {
                path.beta *= 1.0 / (1.0 - FLUORESCENT_SHARE);
            }
            if !path.alive() {
                break;
            }
        }
        let wo_local = sb.frame.to_local(wo);
        let u_light = sampler.get1d();
        let u_point = sampler.get2d();
        // Inside the stone only a transmitting boundary can see a light (module docs).
        let sees_out = path.medium == MediumId::OUTSIDE || sb.flags().is_transmission();
        let nee = strategy != Strategy::BsdfOnly && !sb.flags().is_specular_only() && sees_out;
        // Inside a crystal the path carries a wave: light samples there read no facet's matrix
        // (only a transmitting vertex sees a light from inside, and a crystal's boundary is
        // sampled by its own rule). A platelet's conductor polarises (below); the path then
        // carries no wave until it takes one by its row (`crystal_segment::take_wave`).
        let in_crystal = POL && world.crystal.is_some() && path.medium != MediumId::OUTSIDE;
        if nee {
            let polar = (POL && !in_crystal).then(|| NeePolarisation {
                pol: &pol,
                rows: aov.as_ref().filter(|_| STOKES).map(|a| &a.rows),
            });
            let mut read = None;
            let added = direct_light::<S, POL>(
                world,
                strategy,
                &sb,
                wo_local,
                (u_light, u_point),
                &mut path,
                &mut out,
                polar.as_ref(),
                &mut read,
            );
            if STOKES {
                match (read, aov.as_mut()) {
                    (Some((c, kf)), Some(a)) => a.add_read(c, kf),
                    _ => stokes_add(&mut aov, added),
                }
            }
        }
        // Manifold next-event estimation from a platelet (the light it sees through the
        // boundary) or from the floor (the light focused on it through the stone).
        let start = match (&world.manifold, hit) {
            _ if strategy == Strategy::BsdfOnly || sb.flags().is_specular_only() => None,
            (Some(setup), Hit::Platelet { id, .. }) if setup.inside => {
                let v = WalkVertex {
                    p: keep_off_the_boundary(sb.p, &ray, hidden.as_ref()),
                    chain: Chain::Out,
                    skip: (id.population != u32::MAX).then_some(id),
                    ng: Vec3::ZERO,
                };
                let walk = sampler.get1d();
                let u = WalkNumbers {
                    light: u_light,
                    point: u_point,
                    map: [u_switch; 2],
                    walk,
                };
                Some((setup, v, u))
            }
            (Some(setup), Hit::Ground { .. })
                if setup.through && path.medium == MediumId::OUTSIDE =>
            {
                let v = WalkVertex {
                    p: sb.p,
                    chain: Chain::Through,
                    skip: None,
                    ng: sb.ng,
                };
                let (light, point, map, walk) = (
                    sampler.get1d(),
                    sampler.get2d(),
                    sampler.get2d(),
                    sampler.get1d(),
                );
                let u = WalkNumbers {
                    light,
                    point,
                    map: map.into(),
                    walk,
                };
                Some((setup, v, u))
            }
            _ => None,
        };
        if let Some((setup, v, u)) = &start
            && let Some(ml) = manifold::sample_light::<S>(world, setup, v, u, &path.lambda)
            && sb.admits(ml.d)
        {
            let (wi_local, f) = sb.eval::<S>(wo_local, ml.d, &path.lambda);
            let p_bsdf = sb.pdf::<S>(wo_local, wi_local, &path.lambda) * ml.cross;
            let w = manifold_weight(strategy, ml.pdf, p_bsdf, true);
            let c = path.throughput() * f * ml.value * (wi_local.z.abs() * w);
            if c.is_valid() {
                let added = path.gather(c);
                if STOKES {
                    stokes_add(&mut aov, added);
                }
            }
        }
        let walk = start.map(|(_, v, _)| v);

        // Continue the path by sampling the BSDF.
        let uc = sampler.get1d();
        let u = sampler.get2d();
        // A doubly refractive body's boundary (polarised transport only): its own sampling.
        let crystal = POL
            .then(|| crystal_boundary::<S>(world, &hit, &sb, &path.lambda))
            .flatten();
        let sampled = match crystal {
            Some(c) => {
                let outside = path.medium == MediumId::OUTSIDE;
                let rows = aov.as_mut().filter(|_| STOKES).map(|a| &mut a.rows);
                crystal_sample::<S>(c, &mut pol, rows, &sb, wo, outside, &path.lambda, (uc, u.x))
            }
            None => sb.sample::<S>(wo_local, uc, u, &path.lambda),
        };
        let Some(bs) = sampled else {
            break;
        };
        if world.transmission_off && bs.flags.is_transmission() {
            // `transmission=off`: the boundary only reflects.
            break;
        }
        path.manifold = match (walk, path.manifold) {
            // A delta lobe at the vertex is not a direction the walk can produce.
            (Some(_), _) if bs.flags.is_specular() => None,
            (Some(v), _) => Some(ManifoldVertex {
                p: v.p,
                d: bs.wi,
                pdf: bs.pdf,
                chain: v.chain,
                crossings: 0,
            }),
            (None, Some(v))
                if v.crossings < v.chain.crossings()
                    && matches!(hit, Hit::Stone(_))
                    && bs.flags.is_specular()
                    && bs.flags.is_transmission()
                    && !sb.faceted =>
            {
                Some(ManifoldVertex {
                    pdf: v.pdf * bs.pdf,
                    crossings: v.crossings + 1,
                    ..v
                })
            }
            _ => None,
        };
        if bs.terminate_secondary {
            // A dispersive refraction sent each wavelength its own way: only the hero goes on.
            S::terminate_secondary(&mut path.lambda);
            S::terminate_secondary(&mut path.film);
        }
        path.scatter(&bs, sb.p, sb.inside);
        if POL && crystal.is_none() {
            let rows = aov.as_mut().filter(|_| STOKES).map(|a| &mut a.rows);
            let above = wo_local.z > 0.0;
            let facets = !in_crystal || matches!(hit, Hit::Platelet { .. });
            polarise(&mut pol, rows, &mut path, &sb, &bs, wo, above, facets);
        }
        path.platelet = match hit {
            Hit::Platelet { id, .. } => Some(id),
            _ => None,
        };
        if !nee && let Some(v) = path.prev.as_mut() {
            v.nee = false;
        }
        if path.depth >= RR_DEPTH {
            let q = path.survival();
            if !(sampler.get1d() < q) {
                break;
            }
            path.beta *= 1.0 / q;
        }
        if !path.alive() {
            break;
        }
        let origin = match hit {
            // The platelet is skipped by the next ray, so it needs no offset from the disc; the
            // hit is kept off the boundary ahead like a scattering point (a hit on a disc the
            // boundary cuts can lie within rounding of it; the move, at most the spawn offset,
            // may put the origin behind the disc it leaves, which the ray then passes).
            // (Already computed where the walk ran from the platelet.)
            Hit::Platelet { p, .. } => walk
                .map(|v| v.p)
                .unwrap_or_else(|| keep_off_the_boundary(p, &ray, hidden.as_ref())),
            _ => offset_origin(sb.p, sb.ng, bs.wi),
        };
        ray = Ray::in_medium(origin, bs.wi, path.medium);
    }
    if S::WAVELENGTH_DIMENSIONS > 0 {
        // Spectral: XYZ is a non-negative combination of the wavelengths' values, Rec.709 a
        // linear map of it that may leave the gamut (crate::spectrum::hero).
        out.signed = true;
        out.radiance = if path.l.is_valid() {
            path.l.to_rgb(&path.film)
        } else {
            Rgb::splat(f32::NAN)
        };
    } else {
        out.radiance = path.l.to_rgb(&path.film);
    }
    if STOKES && let Some(a) = &aov {
        *stokes = a.finish(&path.film);
    }
    (out, path.l)
}
