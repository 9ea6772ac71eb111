//! Camera paths in SIMD lanes (docs/design.md §13): a packet of eight horizontally adjacent
//! pixels at one sample index traced together, bounce by bounce, in phases whose data lie in
//! structure-of-arrays form ([`simd`]), so the compiler vectorises them across the lanes; the
//! kernel is compiled for the machine's widest instruction set at run time ([`dispatch`]).
//!
//! Each lane executes exactly the scalar integrator's operations on its own numbers, so a lane
//! render is bit for bit the scalar render of the same scene (tests/lanes.rs): lanes change the
//! speed of a render, never its image. They run the opaque RGB path loop ([`unsupported`] says
//! why a scene needs the scalar loop instead).

mod draws;
pub mod simd;
mod stone;
pub mod trace;

pub use trace::trace_packet;

use super::path::PathSample;
use super::world::World;
use crate::geometry::MediumId;
use crate::sampler::PixelSampler;
use simd::L;

/// Why `world` cannot be traced in lanes (`None`: it can): the scalar integrator's media,
/// platelets, manifold walks, fluorescent lobes and wavelengths are not in the lane loop.
pub fn unsupported(world: &World) -> Option<&'static str> {
    if world.spectral {
        Some("spectral transport")
    } else if world.interior != MediumId::OUTSIDE || world.camera_medium != MediumId::OUTSIDE {
        Some("a translucent body (transmission)")
    } else if world.medium {
        Some("a participating medium")
    } else if !world.platelets.is_empty() || world.flakes.is_some() {
        Some("platelets")
    } else if world.manifold.is_some() {
        Some("manifold next-event estimation")
    } else if world.fluorescence {
        Some("fluorescence")
    } else if world.polarised {
        Some("polarised transport")
    } else if world.analyser.is_some() {
        Some("a camera analyser")
    } else {
        None
    }
}

/// Why a scene whose effects are `effects` is traced by the scalar loop (`None`: by lanes), from
/// the effects alone (what `lapidary info` prints before any world is built; it agrees with
/// [`unsupported`] on the built world).
pub fn scalar_because(effects: &crate::scene::Effects) -> Option<&'static str> {
    use crate::scene::Effect;
    [
        (Effect::Spectral, "spectral transport"),
        (Effect::Transmission, "a translucent body (transmission)"),
        (Effect::Medium, "a participating medium"),
        (Effect::Platelets, "platelets"),
        (Effect::ManifoldNee, "manifold next-event estimation"),
        (Effect::ManifoldCaustics, "manifold next-event estimation"),
        (Effect::Fluorescence, "fluorescence"),
        (Effect::Polarisation, "polarised transport"),
    ]
    .into_iter()
    .find(|(e, _)| effects.on(*e))
    .map(|(_, why)| why)
    .or_else(|| {
        // The analyser still halves the light with polarisation forced off.
        effects
            .reason(Effect::Polarisation)
            .is_some_and(|(r, _)| r.contains("analyser"))
            .then_some("a camera analyser")
    })
}

/// Traces `packet` with the kernel compiled for the widest instruction set this machine has
/// (AVX-512, AVX2 + FMA, or the x86-64 baseline), chosen at run time by `pulp`. Everything the
/// kernel calls is `#[inline(always)]` down to the lane operations ([`simd`]), so it is compiled
/// for that instruction set too. (A closure handed to the dispatcher is not inlined into it:
/// the kernel is this named type's method.)
#[inline]
pub fn dispatch(
    world: &World,
    setup: &trace::Setup,
    packet: trace::Packet,
    samplers: &mut [PixelSampler; L],
) -> [PathSample; L] {
    struct Kernel<'a> {
        world: &'a World,
        setup: &'a trace::Setup<'a>,
        packet: trace::Packet,
        samplers: &'a mut [PixelSampler; L],
    }
    impl pulp::WithSimd for Kernel<'_> {
        type Output = [PathSample; L];
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _: S) -> [PathSample; L] {
            trace_packet(self.world, self.setup, self.packet, self.samplers)
        }
    }
    pulp::Arch::new().dispatch(Kernel {
        world,
        setup,
        packet,
        samplers,
    })
}
