//! Camera paths in SIMD lanes (docs/design.md §13): a packet of eight horizontally adjacent
//! pixels at one sample index traced together, bounce by bounce, in phases whose data lie in
//! structure-of-arrays form ([`simd`]), so the compiler vectorises them across the lanes; the
//! kernel is compiled for the machine's widest instruction set at run time ([`dispatch`]).
//!
//! Each lane executes exactly the scalar integrator's operations on its own numbers, so a lane
//! render is bit for bit the scalar render of the same scene (tests/lanes.rs): lanes change the
//! speed of a render, never its image. They run the opaque RGB path loop ([`unsupported`] says
//! why a scene needs the scalar loop instead).

pub mod simd;
pub mod trace;

pub use trace::trace_packet;

use super::world::World;
use crate::geometry::MediumId;

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
    } else {
        None
    }
}

/// Runs `f` compiled for the widest instruction set this machine has (AVX-512, AVX2 + FMA, or
/// the x86-64 baseline), chosen at run time. `f` and everything it calls must be
/// `#[inline(always)]` to be compiled that way.
#[inline(always)]
pub fn dispatch<R>(f: impl FnOnce() -> R) -> R {
    struct Kernel<F>(F);
    impl<R, F: FnOnce() -> R> pulp::WithSimd for Kernel<F> {
        type Output = R;
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _: S) -> R {
            (self.0)()
        }
    }
    pulp::Arch::new().dispatch(Kernel(f))
}
