//! The runtime world the integrator traces: the placed stone, the floor, the lights and the
//! material table, built once from a compiled [`Scene`].

mod inside;
mod lights;
mod materials;

pub use super::setup::{MaterialCache, PROGRESS_AFTER, Setup, WorldError};
use crate::bsdf::{Bsdf, Lambert};
use crate::color::Rgb;
use crate::geometry::{MediumId, Ray, Stone, StoneHit};
use crate::light::{Area, EnvironmentLight};
use crate::medium::Medium;
use crate::scene::body::Indices;
use crate::scene::{Effect, Scene};
use crate::texture::{Map, MapEffects};
use glam::Vec3;

/// What a ray hit first.
#[derive(Clone, Copy, Debug)]
pub enum Hit {
    /// The stone.
    Stone(StoneHit),
    /// The floor at distance `t`, point `p`.
    Ground {
        /// Distance along the ray.
        t: f32,
        /// World point.
        p: Vec3,
    },
    /// A platelet inside the body at distance `t`.
    Platelet {
        /// Distance along the ray.
        t: f32,
        /// World point.
        p: Vec3,
        /// Unit world normal of the disc (not oriented toward the ray).
        n: Vec3,
        /// Material index of its face.
        material: u32,
        /// Which platelet (a ray leaving it skips it).
        id: crate::platelet::PlateletId,
    },
    /// Area light `index` at distance `t`.
    Light {
        /// Index into [`World::areas`].
        index: usize,
        /// Distance along the ray.
        t: f32,
    },
}

impl Hit {
    /// Distance along the ray.
    pub fn t(&self) -> f32 {
        match *self {
            Hit::Stone(h) => h.t,
            Hit::Ground { t, .. } | Hit::Light { t, .. } | Hit::Platelet { t, .. } => t,
        }
    }
}

/// A light chosen for next-event estimation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightRef {
    /// Area light `i`.
    Area(usize),
    /// The environment.
    Environment,
}

/// The traced world.
#[derive(Debug)]
pub struct World {
    /// The placed stone.
    pub stone: Stone,
    /// The floor height and its Lambertian BSDF, if there is a floor.
    pub ground: Option<(f32, Bsdf)>,
    /// Area lights.
    pub areas: Vec<Area>,
    /// The environment.
    pub environment: EnvironmentLight,
    /// Selection probabilities for next-event estimation: areas in order, then the environment.
    pub light_prob: Vec<f32>,
    /// Runtime BSDFs by material index (`None`: the map tree never uses it).
    pub materials: Vec<Option<Bsdf>>,
    /// Directional albedo at normal incidence by material index (for the albedo AOV).
    pub albedo: Vec<Rgb>,
    /// The medium inside the stone: what a transmission through its surface enters
    /// ([`MediumId::OUTSIDE`] for an opaque stone, `MediumId(1)` for a translucent body).
    pub interior: MediumId,
    /// The media by [`MediumId`]: 0 is the outside (a vacuum), 1 a body's interior.
    pub media: Vec<Medium>,
    /// The medium camera rays start in (the interior when the camera is inside the stone).
    pub camera_medium: MediumId,
    /// Most scattering events in a medium per path.
    pub medium_depth: u32,
    /// `transmission=off`: a body's boundary only reflects (a path ends where it would refract,
    /// and next-event estimation skips directions through the surface).
    pub transmission_off: bool,
    /// Platelet populations inside the body (object space), walked on every segment inside it
    /// when the `platelets` effect is on.
    pub platelets: Vec<crate::platelet::Population>,
    /// The platelets' statistical form (`platelets: statistical`): a medium of flakes instead of
    /// [`World::platelets`].
    pub flakes: Option<crate::platelet::statistical::FlakeMedium>,
    /// Manifold next-event estimation through the smooth boundary (the `manifold-nee` effect).
    pub manifold: Option<super::manifold::ManifoldSetup>,
    /// Whether the free-flight code runs on every segment (the `medium` effect): a body with an
    /// absorbing or scattering interior, or the effect forced on.
    pub medium: bool,
    /// The map tree.
    pub map: Map,
    /// Whether facet bumps apply.
    pub facet_bump: bool,
    /// Whether paths carry wavelengths (the `spectral` effect): [`super::render`] then traces
    /// [`crate::spectrum::HeroSample`] instead of RGB.
    pub spectral: bool,
    /// Whether fluorescent bases re-radiate (the `fluorescence` effect): at a hit on one a path
    /// picks the fluorescent or the elastic lobe ([`super::integrator`]). Off: only the elastic
    /// reflectance (the colorant still absorbs).
    pub fluorescence: bool,
    /// The lights' narrow emission lines (issue 20): spectral paths draw their wavelengths, and
    /// fluorescent excitations, partly from them ([`crate::spectrum::line`]). Empty in most
    /// scenes, which then sample exactly as before.
    pub lines: Vec<crate::spectrum::line::Line>,
    /// Centre and radius of a sphere bounding the stone, the floor patch under it and the lights.
    pub bounds: (Vec3, f32),
    /// Polarised transport (the `polarisation` effect): paths carry their sensor's Stokes row
    /// ([`crate::polarisation::transport`]); off, they carry intensity only.
    pub polarised: bool,
    /// The camera's analyser, an ideal linear polariser: its transmission axis (world, unit, in
    /// the image plane). It passes half of unpolarised light, polarised transport or not.
    pub analyser: Option<Vec3>,
    /// The image's right (world, unit) when the render measures the Stokes AOVs (polarised
    /// transport only; [`crate::polarisation::stokes`]).
    pub stokes: Option<Vec3>,
    /// A dichroscope's right window ([`crate::scene::Stage::dichroscope`]): the analyser axis of
    /// the image's right half (world, unit), 90° from [`World::analyser`], which the left half
    /// keeps. Each half shows the whole view.
    pub dichroscope: Option<Vec3>,
    /// A doubly refractive body's optics, in polarised transport (otherwise the body is
    /// isotropic with its ordinary index).
    pub crystal: Option<CrystalOptics>,
}

/// The optics of a doubly refractive body in world space ([`crate::polarisation::crystal`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrystalOptics {
    /// The body's index at the d line: ordinary (ω) or n_α.
    pub no: f32,
    /// Uniaxial: `n_e − n_o` at the d line, kept at every wavelength (biaxial: 0).
    pub birefringence: f32,
    /// Unit optic axis, world space (biaxial: its X axis).
    pub axis: Vec3,
    /// A biaxial crystal: `n_β − n_α`, `n_γ − n_α` at the d line (kept at every wavelength) and
    /// its orthonormal principal axes X, Y, Z in world space.
    pub biaxial: Option<([f32; 2], [Vec3; 3])>,
    /// Dichroic absorption per world unit: uniaxial, of the ordinary wave and of the
    /// extraordinary wave across the axis; biaxial, of light vibrating along X, Y, Z (zero: not
    /// pleochroic).
    pub sigma: [Rgb; 3],
    /// `sigma`'s spectra per world unit where the recipe gave spectra (read per wavelength by
    /// spectral transport; `sigma` is their colours' coefficient).
    pub sigma_measured: [Option<&'static crate::spectrum::measured::Measured>; 3],
    /// A thin section: nanometres of crystal per world unit (its two waves add coherently, its
    /// boundary refracts as an isotropic one of index `no`); `None`: a gem.
    pub thin_nm: Option<f32>,
    /// Own dispersion laws of the indices beyond the body's (uniaxial `[ε, —]`, biaxial
    /// `[n_β, n_γ]`; `None`: the d line's difference is kept).
    pub laws: [Option<crate::bsdf::dispersion::Ior>; 2],
    /// The body's own law (`None`: not dispersive), for a thin section's retardation at each
    /// wavelength when an index has its own law.
    pub body_law: Option<crate::bsdf::dispersion::Ior>,
}

impl CrystalOptics {
    /// Whether the absorption depends on the wave.
    pub fn pleochroic(&self) -> bool {
        !self.sigma.iter().all(|s| s.is_black())
    }

    /// The optics at wavelength `lambda_nm` (`None`: the d line, the RGB variant), where the
    /// body's index is `n`: an index with its own law takes the law's value there, the others
    /// keep their differences from `n` at the d line.
    pub fn at(&self, n: f64, lambda_nm: Option<f32>) -> crate::polarisation::optics::Optics {
        use crate::polarisation::{biaxial::Biaxial, optics::Optics, uniaxial::Uniaxial};
        let index = |k: usize, offset: f32| match (self.laws[k], lambda_nm) {
            (Some(law), Some(l)) => f64::from(law.at(l)),
            _ => n + f64::from(offset),
        };
        match self.biaxial {
            None => Optics::Uniaxial(Uniaxial {
                no: n,
                ne: index(0, self.birefringence),
                axis: self.axis.as_dvec3(),
            }),
            Some(([b, g], axes)) => Optics::Biaxial(Biaxial {
                n: [n, index(0, b), index(1, g)],
                axes: axes.map(|a| a.as_dvec3()),
            }),
        }
    }
}

/// The axis of the camera's analyser (world, unit) from its angle, radians from the image's right
/// toward its up.
fn analyser_axis(camera: &crate::scene::stage::Camera, angle: f32) -> Vec3 {
    let (s, c) = angle.sin_cos();
    (camera.right * c + camera.up * s).normalize()
}

impl World {
    /// Builds the world for `scene` (loads the mesh and environment map, builds BSDF tables).
    pub fn new(scene: &Scene) -> Result<World, WorldError> {
        Self::build(scene, &Setup::default())
    }

    /// [`World::new`] that gives up with [`WorldError::Stopped`] when `setup`'s deadline passes
    /// or its cancel flag is set (checked before each material's tables and between the stages of
    /// the build), and shows the tables' progress when they take long.
    pub fn build(scene: &Scene, setup: &Setup) -> Result<World, WorldError> {
        let stage = &scene.stage;
        setup.check()?;
        let stone = Stone::new(&stage.shape, stage.to_world)?;
        setup.check()?;
        let mut environment = EnvironmentLight::new(&stage.environment)?;
        setup.check()?;
        // An RGB render under lights with a spectrum: materials reduced under that light.
        let prefilter = if scene.effects.on(Effect::LightPrefilter)
            && !scene.effects.on(Effect::Spectral)
        {
            let (lo, hi) = stone.bounds();
            let colorants = (scene.surface.stacks.iter().zip(&scene.surface.used))
                .filter(|(_, used)| **used)
                .filter_map(|(d, _)| d.fluorescence.as_deref());
            super::prefilter::scene_light(&stage.lights, &environment, 0.5 * (lo + hi), colorants)
        } else {
            None
        };
        let prefiltered: Option<Vec<_>> = prefilter.as_ref().map(|p| {
            scene
                .surface
                .stacks
                .iter()
                .map(|d| super::prefilter::stack(p, d))
                .collect()
        });
        let stacks = prefiltered.as_deref().unwrap_or(&scene.surface.stacks);
        let (materials, albedo) = materials::build(scene, stacks, prefilter.as_ref(), setup)?;
        let body = scene.surface.body.as_ref();
        let shows_body = scene.effects.on(Effect::Transmission) && body.is_some();
        // A translucent stone resting on the floor: light leaving through its base starts within
        // the spawn offset below the plane and would pass under the floor to the sky's nadir. The
        // floor is lowered by 10⁻⁴ of the stone's size there, so that light meets it and the
        // floor's light enters the base again (opaque stones keep the floor where it is).
        let (stone_lo, stone_hi) = stone.bounds();
        let size = (stone_hi - stone_lo).max_element().max(1e-6);
        let ground = stage.ground.map(|mut g| {
            if let Some(p) = &prefilter {
                g.albedo = super::prefilter::albedo(p, g.albedo, None);
            }
            // Only where the map shows the body (forcing `transmission` on for a stone that
            // stays opaque must not move its floor).
            let resting = shows_body
                && scene.effects.called(Effect::Transmission)
                && (stone_lo.y - g.height).abs() <= 1e-3 * size;
            (
                if resting {
                    g.height.min(stone_lo.y) - 1e-4 * size
                } else {
                    g.height
                },
                Bsdf::Lambert(Lambert {
                    albedo: g.albedo.into(),
                }),
            )
        });
        let areas: Vec<Area> = stage.lights.iter().map(Area::new).collect();
        setup.check()?;
        if !scene.effects.on(Effect::EnvironmentImportance) {
            environment.set_importance(false);
        }

        let (light_prob, bounds) = lights::selection(&stone, &stage.lights, &areas, &environment);
        let mut inside = inside::build(scene, &stone, &areas)?;
        // Polarised transport: the manifold walks carry a scalar through the boundary, which is
        // exact only for a single crossing toward unpolarised light (module docs of
        // `crate::polarisation::transport`); otherwise BSDF sampling alone finds those lights.
        let polarised = scene.effects.on(Effect::Polarisation);
        let crystal = (polarised && shows_body)
            .then(|| body.and_then(|b| b.crystal.map(|c| (b.ior, b.dispersion, c))))
            .flatten()
            .map(|(ior, body_law, c)| {
                // Coefficients per object unit become per world unit (the stage's scale).
                let scale = stage
                    .to_world
                    .matrix3
                    .x_axis
                    .length()
                    .max(f32::MIN_POSITIVE);
                let to_world = |v: Vec3| stage.to_world.transform_vector3(v).normalize();
                let (birefringence, axis, biaxial) = match c.indices {
                    Indices::Uniaxial { ne, axis } => (ne - ior, to_world(axis), None),
                    Indices::Biaxial { beta, gamma, axes } => {
                        // Orthonormal again in world space (Gram–Schmidt, X kept).
                        let x = to_world(axes[0]);
                        let z = to_world(axes[2]);
                        let z = (z - x * z.dot(x)).normalize();
                        let principal = Some(([beta - ior, gamma - ior], [x, z.cross(x), z]));
                        (0.0, x, principal)
                    }
                };
                CrystalOptics {
                    no: ior,
                    birefringence,
                    axis,
                    biaxial,
                    sigma: c.sigma.map(|s| s * (1.0 / scale)),
                    sigma_measured: (c.sigma_measured)
                        .map(|m| m.map(|m| m.scaled(1.0 / scale).intern())),
                    thin_nm: c.thin_nm.map(|nm| nm / scale),
                    laws: c.laws,
                    body_law,
                }
            });
        if polarised && let Some(m) = inside.manifold.as_mut() {
            m.through = false;
            m.inside &= areas.iter().all(|a| a.polariser().is_none()) && crystal.is_none();
            if !m.inside {
                inside.manifold = None;
            }
        }

        Ok(World {
            stone,
            ground,
            areas,
            environment,
            light_prob,
            materials,
            albedo,
            interior: inside.interior,
            media: inside.media,
            camera_medium: inside.camera_medium,
            medium_depth: stage.render.medium_depth,
            transmission_off: scene.effects.forced(Effect::Transmission) == Some(false),
            platelets: inside.platelets,
            flakes: inside.flakes,
            manifold: inside.manifold,
            medium: scene.effects.on(Effect::Medium),
            map: scene.surface.map.with_effects(MapEffects {
                overlay: scene.effects.forced(Effect::GlitterOverlay) != Some(false),
                blend: scene.effects.forced(Effect::StochasticSwitch) != Some(false),
                bump: scene.effects.forced(Effect::FacetBump) != Some(false),
            }),
            facet_bump: scene.effects.on(Effect::FacetBump),
            spectral: scene.effects.on(Effect::Spectral),
            fluorescence: scene.effects.on(Effect::Fluorescence),
            lines: stage.lights.iter().filter_map(|l| l.line).collect(),
            bounds,
            polarised,
            analyser: stage.analyser.map(|a| analyser_axis(&stage.camera, a)),
            stokes: (polarised && stage.stokes).then_some(stage.camera.right),
            dichroscope: stage
                .analyser
                .filter(|_| stage.dichroscope)
                .map(|a| analyser_axis(&stage.camera, a + std::f32::consts::FRAC_PI_2)),
            crystal,
        })
    }

    /// The closest hit along `ray` (unit direction) before `t_max`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut best = self.stone.intersect(ray, t_max).map(Hit::Stone);
        let mut t_best = best.map_or(t_max, |h| h.t());
        if let Some((h, _)) = self.ground {
            let t = (h - ray.origin.y) / ray.dir.y;
            if t > 0.0 && t < t_best {
                t_best = t;
                best = Some(Hit::Ground { t, p: ray.at(t) });
            }
        }
        for (index, a) in self.areas.iter().enumerate() {
            if let Some(t) = a.intersect(ray, t_best) {
                t_best = t;
                best = Some(Hit::Light { index, t });
            }
        }
        best
    }

    /// The nearest platelet along `ray` before `t_max` (a ray inside the body), skipping the
    /// platelet `skip` it leaves from.
    pub fn platelet_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        skip: Option<crate::platelet::PlateletId>,
    ) -> Option<Hit> {
        let to_object = self.stone.to_object();
        // An affine map keeps the ray parameter: `t` is the same in both spaces.
        let o = to_object.transform_point3(ray.origin);
        let d = to_object.transform_vector3(ray.dir);
        let h = crate::platelet::grid::intersect(&self.platelets, o, d, 0.0, t_max, skip)?;
        let n = self
            .stone
            .to_world()
            .transform_vector3(h.normal)
            .try_normalize()?;
        Some(Hit::Platelet {
            t: h.t,
            p: ray.at(h.t),
            n,
            material: h.material,
            id: h.id,
        })
    }

    /// Whether anything blocks `ray` before `t_max`.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        if let Some((h, _)) = self.ground {
            let t = (h - ray.origin.y) / ray.dir.y;
            if t > 0.0 && t < t_max {
                return true;
            }
        }
        self.areas.iter().any(|a| a.intersect(ray, t_max).is_some())
            || self.stone.occluded(ray, t_max)
    }

    /// Picks a light for next-event estimation with `u ∈ [0, 1)`; returns it and its probability.
    pub fn pick_light(&self, u: f32) -> Option<(LightRef, f32)> {
        let mut acc = 0.0;
        let mut last = None;
        for (i, &p) in self.light_prob.iter().enumerate() {
            if p <= 0.0 {
                continue;
            }
            acc += p;
            last = Some((i, p));
            if u < acc {
                break;
            }
        }
        let (i, p) = last?;
        let light = if i < self.areas.len() {
            LightRef::Area(i)
        } else {
            LightRef::Environment
        };
        Some((light, p))
    }

    /// Probability that [`World::pick_light`] picks `light`.
    pub fn light_probability(&self, light: LightRef) -> f32 {
        match light {
            LightRef::Area(i) => self.light_prob[i],
            LightRef::Environment => self.light_prob[self.areas.len()],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bxdf;
    use crate::recipe::GemRecipe;

    #[test]
    fn identical_stacks_share_one_build_and_unused_ones_are_skipped() {
        let coat = |ior: f32| {
            format!(
                "(coats: [(ior: {ior:?}, roughness: 5.0, thickness: 0.5)], base: Lambert(albedo: Gray(0.5)))"
            )
        };
        let text = format!(
            "(materials: {{ \"a\": {}, \"b\": {}, \"c\": {}, \"d\": {} }},\n surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"a\")), (1.0, Material(\"b\")), (1.0, Material(\"c\"))]))",
            coat(1.5),
            coat(1.7),
            coat(1.5),
            coat(1.5)
        );
        let scene = GemRecipe::parse("t.ron", &text).unwrap().compile().unwrap();
        let world = World::new(&scene).unwrap();
        let (wo, wi) = (
            Vec3::new(0.3, 0.1, 0.9).normalize(),
            Vec3::new(-0.2, 0.4, 0.8).normalize(),
        );
        let f = |k: usize| world.materials[k].as_ref().map(|b| b.eval(wo, wi));
        assert_eq!(f(0), f(2), "a and its twin c");
        assert_ne!(f(0), f(1));
        assert!(f(0).is_some() && f(3).is_none(), "d is unused");
        assert_eq!(world.albedo[0], world.albedo[2]);
    }
}
