//! Camera rays: perspective with a thin lens, and orthographic.
//!
//! Film coordinates are continuous pixels: `x ∈ [0, width)` to the right, `y ∈ [0, height)`
//! downwards, pixel `(i, j)` covering `[i, i+1) × [j, j+1)`.

use crate::geometry::Ray;
use crate::sampler::concentric_disc;
use crate::scene::stage::{Camera, Projection};
use glam::{Vec2, Vec3};

/// A camera bound to an image size.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    camera: Camera,
    width: f32,
    height: f32,
    /// Half-extent of the image plane at distance 1 (perspective) or in world units
    /// (orthographic), vertically.
    half_h: f32,
    /// Lens radius (0: pinhole or orthographic).
    lens_radius: f32,
    focus_distance: f32,
}

impl CameraRays {
    /// Binds `camera` to a `width × height` image. `depth_of_field: false` forces a pinhole (the
    /// effect is off when the scene's aperture is 0 anyway).
    pub fn new(camera: &Camera, width: u32, height: u32, depth_of_field: bool) -> Self {
        let (half_h, lens_radius, focus_distance) = match camera.projection {
            Projection::Perspective {
                fov,
                aperture,
                focus_distance,
            } => (
                (0.5 * fov).tan(),
                if depth_of_field { aperture } else { 0.0 },
                focus_distance,
            ),
            Projection::Orthographic { height } => (0.5 * height, 0.0, 1.0),
        };
        CameraRays {
            camera: *camera,
            width: width as f32,
            height: height as f32,
            half_h,
            lens_radius,
            focus_distance,
        }
    }

    /// The ray through film point `film` (continuous pixels), lens sample `lens ∈ [0,1)²`. The
    /// direction is unit length.
    pub fn ray(&self, film: Vec2, lens: Vec2) -> Ray {
        let c = &self.camera;
        let aspect = self.width / self.height;
        let sx = (2.0 * film.x / self.width - 1.0) * aspect * self.half_h;
        let sy = (1.0 - 2.0 * film.y / self.height) * self.half_h;
        match c.projection {
            Projection::Orthographic { .. } => {
                Ray::new(c.from + c.right * sx + c.up * sy, c.forward)
            }
            Projection::Perspective { .. } => {
                let dir = (c.forward + c.right * sx + c.up * sy).normalize();
                if self.lens_radius <= 0.0 {
                    return Ray::new(c.from, dir);
                }
                // Thin lens: every ray through the film point meets the pinhole ray on the plane
                // of focus, a distance `focus_distance` along `forward`.
                let focus = c.from + dir * (self.focus_distance / dir.dot(c.forward));
                let d = concentric_disc(lens) * self.lens_radius;
                let origin = c.from + c.right * d.x + c.up * d.y;
                Ray::new(origin, (focus - origin).normalize())
            }
        }
    }

    /// The film point (continuous pixels) a world point projects to through the lens centre, if
    /// it is in front of the camera (for tests and light-tracing tools).
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let c = &self.camera;
        let d = p - c.from;
        let z = d.dot(c.forward);
        let (x, y) = match c.projection {
            Projection::Orthographic { .. } => (d.dot(c.right), d.dot(c.up)),
            Projection::Perspective { .. } => {
                if z <= 0.0 {
                    return None;
                }
                (d.dot(c.right) / z, d.dot(c.up) / z)
            }
        };
        let aspect = self.width / self.height;
        Some(Vec2::new(
            (x / (aspect * self.half_h) + 1.0) * 0.5 * self.width,
            (1.0 - y / self.half_h) * 0.5 * self.height,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(projection: Projection) -> Camera {
        Camera::look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, projection).unwrap()
    }

    #[test]
    fn centre_ray_looks_along_forward_and_projection_inverts_rays() {
        let cam = camera(Projection::Perspective {
            fov: 0.6,
            aperture: 0.0,
            focus_distance: 5.0,
        });
        let rays = CameraRays::new(&cam, 64, 48, true);
        let r = rays.ray(Vec2::new(32.0, 24.0), Vec2::splat(0.5));
        assert!((r.dir - cam.forward).length() < 1e-6);
        for film in [Vec2::new(3.5, 40.25), Vec2::new(60.0, 1.0)] {
            let r = rays.ray(film, Vec2::ZERO);
            let back = rays.project(r.at(7.0)).unwrap();
            assert!((back - film).length() < 1e-3, "{film} -> {back}");
        }
        // The top edge of the image is half the field of view above the axis.
        let top = rays.ray(Vec2::new(32.0, 0.0), Vec2::ZERO);
        assert!((top.dir.angle_between(cam.forward) - 0.3).abs() < 1e-5);
    }

    #[test]
    fn thin_lens_rays_meet_on_the_focus_plane() {
        let cam = camera(Projection::Perspective {
            fov: 0.6,
            aperture: 0.2,
            focus_distance: 4.0,
        });
        let rays = CameraRays::new(&cam, 64, 48, true);
        let film = Vec2::new(10.0, 30.0);
        let pin = rays.ray(film, Vec2::splat(0.5));
        let t = 4.0 / pin.dir.dot(cam.forward);
        let focus = pin.at(t);
        for lens in [Vec2::new(0.1, 0.9), Vec2::new(0.8, 0.3)] {
            let r = rays.ray(film, lens);
            assert!((r.origin - cam.from).length() > 1e-3);
            let t = (focus - r.origin).dot(r.dir);
            assert!((r.at(t) - focus).length() < 1e-4);
        }
        // With depth of field off the same camera is a pinhole.
        let pinhole = CameraRays::new(&cam, 64, 48, false).ray(film, Vec2::new(0.1, 0.9));
        assert_eq!(pinhole.origin, cam.from);
    }

    #[test]
    fn orthographic_rays_are_parallel_and_span_the_height() {
        let cam = camera(Projection::Orthographic { height: 2.0 });
        let rays = CameraRays::new(&cam, 20, 10, true);
        let top = rays.ray(Vec2::new(10.0, 0.0), Vec2::ZERO);
        let bottom = rays.ray(Vec2::new(10.0, 10.0), Vec2::ZERO);
        assert_eq!(top.dir, cam.forward);
        assert!(((top.origin - bottom.origin).length() - 2.0).abs() < 1e-5);
    }
}
