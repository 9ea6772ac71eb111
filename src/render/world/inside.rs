//! What lies inside a translucent stone: the media (the outside's and the body's interior), the
//! medium the camera starts in, manifold next-event estimation through the boundary, and the
//! platelets (explicit populations or their statistical form). An opaque stone has none of it.

use super::WorldError;
use crate::color::Rgb;
use crate::geometry::{MediumId, Stone};
use crate::light::Area;
use crate::medium::Medium;
use crate::render::manifold::{ManifoldSetup, WalkEffort};
use crate::scene::{Effect, Scene};

/// The inside of the stone, as the world holds it.
pub(super) struct Inside {
    /// Media by [`MediumId`]: the outside's, then the body's interior.
    pub media: Vec<Medium>,
    /// The body's interior medium (`OUTSIDE` for an opaque stone).
    pub interior: MediumId,
    /// The medium camera rays start in.
    pub camera_medium: MediumId,
    /// Manifold next-event estimation through a smooth boundary.
    pub manifold: Option<ManifoldSetup>,
    /// Explicit platelet populations.
    pub platelets: Vec<crate::platelet::Population>,
    /// The platelets' statistical form.
    pub flakes: Option<crate::platelet::statistical::FlakeMedium>,
}

/// The inside of `scene`'s stone; refuses a translucent body on a mesh that does not bound a
/// solid the right way round, and platelets a walk cannot cover.
pub(super) fn build(scene: &Scene, stone: &Stone, areas: &[Area]) -> Result<Inside, WorldError> {
    let stage = &scene.stage;
    let body = scene.surface.body.as_ref();
    let shows_body = scene.effects.on(Effect::Transmission) && body.is_some();
    let scale = stage.to_world.matrix3.x_axis.length();
    let medium_on = scene.effects.on(Effect::Medium);
    let mut media = vec![if scene.effects.forced(Effect::Medium) == Some(true) {
        // Forced on: the free-flight code runs on every segment, through a medium that
        // neither absorbs nor scatters (its weight is exactly 1).
        Medium::Homogeneous(crate::medium::Homogeneous {
            sigma_a: Rgb::ZERO,
            sigma_s: Rgb::ZERO,
            phase: crate::medium::HenyeyGreenstein::new(0.0),
            sigma_a_measured: None,
            sigma_s_measured: None,
        })
    } else {
        Medium::Vacuum
    }];
    if shows_body && let crate::geometry::Solid::Mesh(m) = stone.solid() {
        let open = m.open_edges();
        if open > 0 {
            return Err(WorldError::OpenBody(open));
        }
        let volume = m.signed_volume();
        if volume <= 0.0 {
            return Err(WorldError::InsideOutBody(volume));
        }
    }
    let interior = match body {
        Some(b) if shows_body => {
            media.push(if medium_on {
                b.medium(scale, stage.render.medium_scattering)
            } else {
                Medium::Vacuum
            });
            MediumId(1)
        }
        _ => MediumId::OUTSIDE,
    };
    let transmission = scene.effects.on(Effect::Transmission);
    let camera_medium = if transmission && interior != MediumId::OUTSIDE {
        if stone.contains(stage.camera.from) {
            interior
        } else {
            MediumId::OUTSIDE
        }
    } else {
        MediumId::OUTSIDE
    };
    // The walks solve Snell's law with one index: a dispersive body in a spectral render
    // refracts each wavelength its own way, so there light is found by BSDF sampling alone.
    let dispersive =
        scene.effects.on(Effect::Spectral) && body.is_some_and(|b| b.dispersion.is_some());
    let manifold = match body {
        Some(b) if shows_body && b.alpha == 0.0 && !dispersive => ManifoldSetup::new(
            b.ior,
            scene.surface.body_index(),
            areas,
            (
                scene.effects.on(Effect::ManifoldNee),
                scene.effects.on(Effect::ManifoldCaustics),
            ),
            WalkEffort {
                halvings: stage.render.manifold_halvings,
                continuation: stage.render.manifold_continuation,
            },
        ),
        _ => None,
    };
    let mut platelets = match body {
        Some(b)
            if shows_body
                && scene.effects.on(Effect::Platelets)
                && stage.render.platelets_explicit =>
        {
            b.platelets.clone()
        }
        _ => vec![],
    };
    // Every walk inside the stone must fit the walk's cell budget.
    let (object_lo, object_hi) = stone.solid().bounds();
    crate::platelet::grid::check_span(&platelets, object_lo, object_hi)?;
    // The cells around the stone drawn once for the walks (no result changes; bounded).
    for p in &mut platelets {
        p.prepare(object_lo, object_hi);
    }

    let flakes = match body {
        Some(b)
            if shows_body
                && scene.effects.on(Effect::Platelets)
                && !stage.render.platelets_explicit
                && !b.platelets.is_empty() =>
        {
            Some(crate::platelet::statistical::FlakeMedium::new(
                &b.platelets,
                stage.to_world,
            ))
        }
        _ => None,
    };
    // The walks' probability is 1 everywhere in a clear enough interior (no line traced for it).
    let manifold = manifold.map(|m| {
        let sigma = if medium_on {
            media[usize::from(interior.0)].min_extinction()
        } else {
            0.0
        } + flakes.as_ref().map_or(0.0, |f| f.sigma_max());
        let (lo, hi) = stone.bounds();
        m.with_clear_interior(sigma, (hi - lo).length())
    });
    Ok(Inside {
        media,
        interior,
        camera_medium,
        manifold,
        platelets,
        flakes,
    })
}
