//! How a world picks a light for next-event estimation: each area light and the environment in
//! proportion to its power, and the sphere bounding the stone and the lights.

use crate::geometry::Stone;
use crate::light::{Area, EnvironmentLight};
use crate::scene::stage::AreaLight;
use glam::Vec3;

/// The probability of picking each area light (in order) and the environment (last), and the
/// centre and radius of the sphere bounding the stone and the lights' centres.
pub(super) fn selection(
    stone: &Stone,
    lights: &[AreaLight],
    areas: &[Area],
    environment: &EnvironmentLight,
) -> (Vec<f32>, (Vec3, f32)) {
    let (lo, hi) = stone.bounds();
    let mut lo = lo;
    let mut hi = hi;
    for l in lights {
        lo = lo.min(l.center);
        hi = hi.max(l.center);
    }
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);

    let mut power: Vec<f32> = areas.iter().map(Area::power).collect();
    power.push(if environment.is_black() {
        0.0
    } else {
        environment.power(radius)
    });
    let total: f32 = power.iter().filter(|p| p.is_finite()).sum();
    let light_prob = power
        .iter()
        .map(|&p| {
            if total > 0.0 && p.is_finite() {
                p / total
            } else {
                0.0
            }
        })
        .collect();

    (light_prob, (centre, radius))
}
