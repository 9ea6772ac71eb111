//! The BSDF at a hit, built from a shading context: the hit's position, normals and facet and the
//! path's wavelengths go in, a [`SurfaceBsdf`] — a material's scattering model in the hit's
//! shading frame — comes out. This is the one place a spectral variant builds per-wavelength
//! BSDF values (docs/design.md §12); the RGB variant borrows the material's prebuilt model.

use super::path::PathSample;
use super::world::{Hit, World};
use crate::bsdf::layered::lobes::WeightsMemo;
use crate::bsdf::{
    Bsdf, BsdfSample, Bxdf, LayeredBsdf, Lobe, LobeFlags, LobeKind, Scatter, TransportMode,
};
use crate::geometry::{Frame, MediumId};
use crate::spectrum::Spectral;
use crate::spectrum::fluorescence::Fluorescence;
use crate::texture::bump::facet_frame;
use crate::texture::map::MapQuery;
use glam::{Vec2, Vec3};

/// What is known about a surface hit before its BSDF is built.
#[derive(Clone, Copy, Debug)]
pub struct ShadingContext<W> {
    /// Hit point, world space.
    pub p: Vec3,
    /// Geometric normal, facing the incoming direction `wo`.
    pub ng: Vec3,
    /// Unbumped shading normal, facing `wo`.
    pub ns: Vec3,
    /// Facet normal the map chose (world space), if any.
    pub facet: Option<Vec3>,
    /// Material index of the stone's map, `None` for the floor.
    pub material: Option<u32>,
    /// True when `wo` is on the side the surface's own normal points to (the outside of a closed,
    /// consistently wound stone); `ng` and `ns` are flipped to face `wo` either way.
    pub front: bool,
    /// The path's wavelengths.
    pub lambda: W,
}

/// A material's scattering model placed at a hit: local-frame BSDF plus the frame and normals
/// that decide which world directions it may scatter into.
#[derive(Clone, Debug)]
pub struct SurfaceBsdf<'a> {
    /// Hit point, world space.
    pub p: Vec3,
    /// Geometric normal, facing `wo`.
    pub ng: Vec3,
    /// Unbumped shading normal, facing `wo`.
    pub ns: Vec3,
    /// The shading frame (the facet's frame on a faceted cell).
    pub frame: Frame,
    /// The medium behind the surface (what a transmission from outside enters).
    pub inside: MediumId,
    /// Whether the frame is a facet's (a tilted crystal facet of the map), not the surface's.
    pub faceted: bool,
    bxdf: &'a Bsdf,
    flags: LobeFlags,
    /// Set by [`SurfaceBsdf::fluoresce`]: the path took the fluorescent lobe of the base
    /// ([`crate::bsdf::layered::fluorescent`]), which `eval`, `pdf` and `sample` then describe.
    fluorescent: Option<&'a LayeredBsdf>,
    /// What the vertex's light sample and continuation sample share (a layer stack's lobe
    /// weights for `wo`).
    memo: WeightsMemo,
}

impl<'a> SurfaceBsdf<'a> {
    /// The lobes of the model.
    #[inline]
    pub fn flags(&self) -> LobeFlags {
        self.flags
    }

    /// The colorant of a fluorescent base under this surface, if any.
    #[inline]
    pub fn fluorescence(&self) -> Option<&'a Fluorescence> {
        match self.bxdf {
            Bsdf::Layered(l) => l.fluorescence(),
            _ => None,
        }
    }

    /// Makes `eval`, `pdf` and `sample` describe the fluorescent lobe `D(wo, wi)` (achromatic:
    /// the path's throughput has taken the re-radiation, [`Spectral::fluoresce`]). Does nothing
    /// on a surface without a fluorescent base.
    #[inline]
    pub fn fluoresce(&mut self) {
        if let Bsdf::Layered(l) = self.bxdf
            && l.fluorescence().is_some()
        {
            self.fluorescent = Some(l);
            self.flags = l.fluorescent_flags();
        }
    }

    /// Whether world direction `wi` may carry light to or from `wo` (facing `ng`): on the front of
    /// both the geometric and the unbumped shading surface for reflection, on the back of both for
    /// transmission (the rule of [`crate::texture::bump`], so a facet never gains energy).
    #[inline]
    pub fn admits(&self, wi: Vec3) -> bool {
        let (g, s) = (wi.dot(self.ng), wi.dot(self.ns));
        (g > 0.0 && s > 0.0) || (self.flags.is_transmission() && g < 0.0 && s < 0.0)
    }

    /// `f(wo, wi)` for world directions, sr⁻¹.
    #[inline]
    pub fn eval<S: Spectral>(&self, wo_local: Vec3, wi: Vec3, lambda: &S::Wavelengths) -> (Vec3, S)
    where
        Bsdf: Scatter<S>,
    {
        let wi_local = self.frame.to_local(wi);
        if let Some(l) = self.fluorescent {
            return (wi_local, S::splat(l.fluorescent_value(wo_local, wi_local)));
        }
        (
            wi_local,
            self.bxdf
                .eval_at(wo_local, wi_local, TransportMode::Radiance, lambda),
        )
    }

    /// [`SurfaceBsdf::eval`] and the density [`SurfaceBsdf::pdf`] of the same pair, bit for bit
    /// the two calls' results, computed together (next-event estimation with MIS needs both).
    #[inline]
    pub fn eval_pdf<S: Spectral>(
        &self,
        wo_local: Vec3,
        wi: Vec3,
        lambda: &S::Wavelengths,
    ) -> (Vec3, S, f32)
    where
        Bsdf: Scatter<S>,
    {
        let wi_local = self.frame.to_local(wi);
        if let Some(l) = self.fluorescent {
            return (
                wi_local,
                S::splat(l.fluorescent_value(wo_local, wi_local)),
                l.fluorescent_pdf(wo_local, wi_local),
            );
        }
        let (f, pdf) = self.bxdf.eval_pdf_memo(
            wo_local,
            wi_local,
            TransportMode::Radiance,
            lambda,
            &self.memo,
        );
        (wi_local, f, pdf)
    }

    /// The relative IOR (below over above the frame's `z`) of a smooth dielectric interface at
    /// the wavelength of `channel` ([`Scatter::interface_eta`]); `None` for any other model.
    #[inline]
    pub fn interface_eta<S: Spectral>(&self, channel: usize, lambda: &S::Wavelengths) -> Option<f32>
    where
        Bsdf: Scatter<S>,
    {
        if self.fluorescent.is_some() {
            return None;
        }
        <Bsdf as Scatter<S>>::interface_eta(self.bxdf, channel, lambda)
    }

    /// A bare conductor's relative complex IOR at the wavelength of `channel`
    /// ([`Scatter::conductor_ior`]); `None` for any other model.
    #[inline]
    pub fn conductor_ior<S: Spectral>(
        &self,
        channel: usize,
        lambda: &S::Wavelengths,
    ) -> Option<(f32, f32)>
    where
        Bsdf: Scatter<S>,
    {
        if self.fluorescent.is_some() {
            return None;
        }
        <Bsdf as Scatter<S>>::conductor_ior(self.bxdf, channel, lambda)
    }

    /// A bare rough dielectric interface's relative IOR (below over above the frame's `z`) at
    /// the wavelength of `channel` ([`Scatter::rough_interface_eta`]); `None` for any other model.
    #[inline]
    pub fn rough_interface_eta<S: Spectral>(
        &self,
        channel: usize,
        lambda: &S::Wavelengths,
    ) -> Option<f32>
    where
        Bsdf: Scatter<S>,
    {
        if self.fluorescent.is_some() {
            return None;
        }
        <Bsdf as Scatter<S>>::rough_interface_eta(self.bxdf, channel, lambda)
    }

    /// Density of `wi_local` (local frame) from `wo_local`.
    #[inline]
    pub fn pdf<S: Spectral>(&self, wo_local: Vec3, wi_local: Vec3, lambda: &S::Wavelengths) -> f32
    where
        Bsdf: Scatter<S>,
    {
        if let Some(l) = self.fluorescent {
            return l.fluorescent_pdf(wo_local, wi_local);
        }
        <Bsdf as Scatter<S>>::pdf_at(self.bxdf, wo_local, wi_local, lambda)
    }

    /// Samples a direction in radiance mode; the sample's `wi` is returned in world space (unit
    /// length) and `None` unless the surface admits it.
    #[inline]
    pub fn sample<S: Spectral>(
        &self,
        wo_local: Vec3,
        uc: f32,
        u: Vec2,
        lambda: &S::Wavelengths,
    ) -> Option<BsdfSample<S>>
    where
        Bsdf: Scatter<S>,
    {
        let mut bs = match self.fluorescent {
            Some(l) => {
                let fs = l.fluorescent_sample(wo_local, u)?;
                let lobe = Lobe {
                    kind: LobeKind::Diffuse,
                    layer: l.coats() as u8,
                };
                BsdfSample::from_eval(fs.wi, S::splat(fs.value), fs.pdf, lobe)?
            }
            None => self.bxdf.sample_memo(
                wo_local,
                uc,
                u,
                TransportMode::Radiance,
                lambda,
                &self.memo,
            )?,
        };
        bs.wi = self.frame.to_world(bs.wi).normalize();
        self.admits(bs.wi).then_some(bs)
    }
}

/// Builds the BSDF of a stone or floor hit for the incoming direction `wo` (world, toward the
/// viewer); records the first-hit AOVs when `first`. `None` for a light or an unused material.
///
/// # Arguments
/// * `map` – the bounce's map-switch number (stochastic blends of the map tree), or a
///   [`MapQuery`] that also holds a field's value at the hit already evaluated (the lane loop's).
/// * `lambda` – the path's wavelengths.
pub fn shade<'a, W: Copy>(
    world: &'a World,
    hit: &Hit,
    wo: Vec3,
    map: impl Into<MapQuery>,
    lambda: W,
    first: bool,
    out: &mut PathSample,
) -> Option<SurfaceBsdf<'a>> {
    let t_hit;
    let ctx = match *hit {
        Hit::Stone(h) => {
            // Meshes may be open or wound inconsistently: face the normals toward the viewer.
            let front = wo.dot(h.ng) >= 0.0;
            let (ng, ns) = if !front { (-h.ng, -h.ns) } else { (h.ng, h.ns) };
            let ns = if wo.dot(ns) > 0.0 { ns } else { ng };
            let look = world.map.lookup_knowing(h.p_object, map.into());
            t_hit = h.t;
            ShadingContext {
                p: h.p,
                ng,
                ns,
                facet: look.facet,
                material: Some(look.material),
                front,
                lambda,
            }
        }
        Hit::Ground { t, p } => {
            let n = if wo.y >= 0.0 { Vec3::Y } else { Vec3::NEG_Y };
            t_hit = t;
            ShadingContext {
                p,
                ng: n,
                ns: n,
                facet: None,
                material: None,
                front: true,
                lambda,
            }
        }
        Hit::Platelet {
            t, p, n, material, ..
        } => {
            // A disc is two-sided: its faces look toward whichever side the path comes from.
            let n = if wo.dot(n) >= 0.0 { n } else { -n };
            t_hit = t;
            ShadingContext {
                p,
                ng: n,
                ns: n,
                facet: None,
                material: Some(material),
                front: true,
                lambda,
            }
        }
        Hit::Light { .. } => return None,
    };
    let sb = world.bsdf_at(&ctx, wo)?;
    if first {
        out.depth = Some(t_hit);
        match ctx.material {
            Some(m) => {
                out.albedo = world.albedo[m as usize];
                out.material = m as i32;
            }
            None => {
                if let Bsdf::Lambert(b) = sb.bxdf {
                    out.albedo = b.albedo.into();
                }
                out.material = -1;
            }
        }
        out.normal = sb.frame.n;
    }
    Some(sb)
}

impl World {
    /// The BSDF at a hit described by `ctx`, for the incoming direction `wo` (world, toward the
    /// viewer); `None` when the material is unused or there is no floor.
    #[inline]
    pub fn bsdf_at<W>(&self, ctx: &ShadingContext<W>, wo: Vec3) -> Option<SurfaceBsdf<'_>> {
        let (bxdf, frame, inside, faceted) = match ctx.material {
            Some(m) => {
                let bxdf = self.materials.get(m as usize)?.as_ref()?;
                // A reflecting model is symmetric: its frame faces the viewer. An interface that
                // transmits has an outside and an inside (its `eta` is inside over outside), so its
                // frame keeps the surface's own orientation and `wo` lies below it when the path
                // arrives from within the stone.
                let n = if ctx.front || !bxdf.flags().is_transmission() {
                    ctx.ns
                } else {
                    -ctx.ns
                };
                let base = Frame::from_normal(n);
                let (frame, faceted) = match ctx.facet {
                    Some(facet) if self.facet_bump => (facet_frame(&base, facet, wo), true),
                    _ => (base, false),
                };
                (bxdf, frame, self.interior, faceted)
            }
            None => {
                let (_, bxdf) = self.ground.as_ref()?;
                (bxdf, Frame::from_normal(ctx.ns), MediumId::OUTSIDE, false)
            }
        };
        Some(SurfaceBsdf {
            p: ctx.p,
            ng: ctx.ng,
            ns: ctx.ns,
            frame,
            inside,
            faceted,
            bxdf,
            flags: bxdf.flags(),
            fluorescent: None,
            memo: WeightsMemo::default(),
        })
    }
}
