//! The cut report's schiller measure for a stone with platelets: the share of the stone's pixels
//! where the eye sees a platelet mirroring light from near the zenith.
//!
//! Geometric optics, traced from the eye: the camera ray through each pixel's centre enters the
//! body by Snell's law (smooth boundary), meets the first platelet on its way (or none), is
//! mirrored by it, and leaves the stone by Snell's law after at most [`MAX_INTERNAL`] total
//! internal reflections. Where it leaves within [`CONE`] of the zenith — the direction a lamp held
//! near the observer's head lights from — that pixel shows the schiller flash. Platelets parallel
//! to the table of a stone seen face-up mirror the eye's ray straight back up: a cutter who orients
//! the rough that way shows the flash face-up (`gems/oregon-sunstone-faceted.ron`); cut 30° off
//! (`gems/oregon-sunstone-off-axis.ron`) the flash needs a tilt.

use super::report::Estimate;
use crate::bsdf::{reflect, refract};
use crate::geometry::{Ray, offset_origin};
use crate::render::world::Hit;
use crate::render::{CameraRays, World};
use crate::scene::Scene;
use crate::scene::stage::Camera;
use glam::{Vec2, Vec3};

/// Half-angle around the zenith from which the flash's light comes, degrees.
pub const CONE: f32 = 20.0;

/// Most total internal reflections followed on the way out.
pub const MAX_INTERNAL: usize = 8;

/// The share of stone pixels showing a platelet's flash, with its binomial standard error; `None`
/// for a stone without a body or platelets, or one that covers no pixel.
pub fn share(world: &World, scene: &Scene, camera: &Camera, size: u32) -> Option<Estimate> {
    let body = scene.surface.body.as_ref()?;
    if world.platelets.is_empty() {
        return None;
    }
    let rays = CameraRays::new(camera, size, size, false);
    let cos_cone = CONE.to_radians().cos();
    let (mut stone, mut flash) = (0usize, 0usize);
    for y in 0..size {
        for x in 0..size {
            let ray = rays.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
            let Some(Hit::Stone(h)) = world.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            stone += 1;
            if let Some(out) = flash_direction(world, body.ior, h.p, h.ng, ray.dir) {
                flash += usize::from(out.y >= cos_cone);
            }
        }
    }
    (stone > 0).then(|| {
        let p = flash as f64 / stone as f64;
        Estimate {
            value: p,
            se: (p * (1.0 - p) / stone as f64).sqrt(),
        }
    })
}

/// Where the eye ray `dir` hitting the stone at `p` (outward normal `n`) leaves after entering,
/// meeting a platelet and being mirrored by it; `None` when it meets no platelet or stays in.
fn flash_direction(world: &World, ior: f32, p: Vec3, n: Vec3, dir: Vec3) -> Option<Vec3> {
    let mut d = refract(-dir, n, ior)?;
    let mut ray = Ray::in_medium(offset_origin(p, n, d), d, world.interior);
    let exit = world.stone.intersect(&ray, f32::INFINITY)?;
    let Some(Hit::Platelet { t, n: pn, .. }) = world.platelet_hit(&ray, exit.t, None) else {
        return None;
    };
    d = reflect(-d, pn);
    let at = ray.at(t);
    ray = Ray::in_medium(
        at + d * 1e-5 * at.abs().max_element().max(1.0),
        d,
        world.interior,
    );
    for _ in 0..=MAX_INTERNAL {
        let h = world.stone.intersect(&ray, f32::INFINITY)?;
        // Leaving: from inside (index `ior`) to air through the outward normal.
        match refract(-ray.dir, -h.ng, 1.0 / ior) {
            Some(out) => return Some(out),
            None => {
                let r = reflect(-ray.dir, h.ng);
                ray = Ray::in_medium(offset_origin(h.p, h.ng, r), r, world.interior);
            }
        }
    }
    None
}
