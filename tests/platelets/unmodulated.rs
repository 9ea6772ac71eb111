//! Claim 7c, nothing changes without a modulation: a population without one generates the same
//! platelets, bit for bit, as before density modulation existed, and its statistical form draws
//! the same collisions (both pinned by hashes recorded on the code before the change, commit
//! bf16d09); a modulation that is 1 everywhere (or more, clamped) changes nothing either — the
//! same platelets, the same collisions, the same renders in both forms.
//!
//! The hashes fold the bit patterns of every generated value; they depend on `f32` `sin`, `cos`
//! and `ln` of the platform's libm (x86-64 Linux here, as in CI).

use super::{differences, gem, render_on, scene};
use glam::{Affine3A, Quat, Vec2, Vec3};
use lapidary::platelet::statistical::FlakeMedium;
use lapidary::platelet::{Modulation, Orientation, Population};
use lapidary::render::{Strategy, World};
use lapidary::sampler::{Rng, hash_words};

/// Hash of the platelets of [`populations`] over 12³ cells, recorded before modulation existed.
const PLATELETS_HASH: u64 = 0x3df6_7092_18c0_6730;
/// Words hashed into [`PLATELETS_HASH`].
const PLATELETS_WORDS: usize = 58_744;
/// Hash of 20 000 flake collisions of [`populations`], recorded before modulation existed.
const COLLISIONS_HASH: u64 = 0xcd3c_efd5_2ff6_bb0f;
/// Collisions among them.
const COLLISIONS: usize = 14_519;

/// A uniform population (3000 per unit³, two per cell) and an aligned one with two entries.
fn populations() -> Vec<Population> {
    vec![
        Population::new(
            3000.0,
            (0.01, 0.03),
            Orientation::Uniform,
            vec![(1.0, 0)],
            11,
        )
        .expect("allowed"),
        Population::new(
            800.0,
            (0.015, 0.04),
            Orientation::Aligned {
                axis: Vec3::new(0.2, 1.0, 0.1).normalize(),
                spread: 0.07,
            },
            vec![(0.3, 2), (1.0, 5)],
            0x1234_5678_9abc,
        )
        .expect("allowed"),
    ]
}

/// Every platelet of the 12³ cells around the origin, as the words of the hash.
fn platelet_words(pops: &[Population]) -> Vec<u64> {
    let mut words = vec![];
    let mut buf = vec![];
    for pop in pops {
        for z in -6..6 {
            for y in -6..6 {
                for x in -6..6 {
                    pop.cell_platelets([x, y, z], &mut buf);
                    words.push(buf.len() as u64);
                    for p in &buf {
                        let v = [
                            p.center.x, p.center.y, p.center.z, p.normal.x, p.normal.y, p.normal.z,
                            p.radius,
                        ];
                        words.extend(v.iter().map(|v| u64::from(v.to_bits())));
                        words.push(u64::from(p.material));
                    }
                }
            }
        }
    }
    words
}

/// 20 000 collisions (random directions, `t_max` and numbers; origins that do not matter without
/// a modulation) as the words of the hash, and the number of collisions.
fn collision_words(medium: &FlakeMedium) -> (Vec<u64>, usize) {
    let mut rng = Rng::new(99);
    let (mut words, mut hits) = (vec![], 0);
    for i in 0..20_000 {
        let d = Vec3::new(
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
        )
        .normalize();
        let t_max = 2.0 * rng.uniform();
        let u = Vec2::new(rng.uniform(), rng.uniform());
        let o = Vec3::new(i as f32 * 0.01, -0.3, 0.7);
        match medium.collide(o, d, t_max, u) {
            None => words.push(u64::MAX),
            Some(c) => {
                hits += 1;
                let v = [c.t, c.normal.x, c.normal.y, c.normal.z];
                words.extend(v.iter().map(|v| u64::from(v.to_bits())));
                words.push(u64::from(c.material));
            }
        }
    }
    (words, hits)
}

fn to_world() -> Affine3A {
    Affine3A::from_scale_rotation_translation(
        Vec3::splat(1.7),
        Quat::from_rotation_x(0.4),
        Vec3::new(0.1, 0.2, 0.3),
    )
}

/// Unmodulated populations generate exactly what they generated before (2 × 12³ cells hashed,
/// 6 911 platelets), and their statistical form draws exactly the same 20 000 flights.
#[test]
fn unmodulated_populations_are_as_before() {
    let pops = populations();
    let words = platelet_words(&pops);
    assert_eq!(
        (hash_words(&words), words.len()),
        (PLATELETS_HASH, PLATELETS_WORDS)
    );
    let medium = FlakeMedium::new(&pops, to_world());
    assert!(!medium.is_modulated());
    let (words, hits) = collision_words(&medium);
    assert_eq!((hash_words(&words), hits), (COLLISIONS_HASH, COLLISIONS));
}

/// A modulation of 1 everywhere (`Constant(1)`, and `Constant(2.5)` clamped to 1) keeps every
/// platelet and every flight: the same hashes through the modulated code paths.
#[test]
fn a_modulation_of_one_changes_nothing() {
    for c in [1.0, 2.5] {
        let pops: Vec<Population> = populations()
            .into_iter()
            .map(|p| p.with_modulation(Some(Modulation::constant(c))))
            .collect();
        let words = platelet_words(&pops);
        assert_eq!(hash_words(&words), PLATELETS_HASH, "Constant({c})");
        let medium = FlakeMedium::new(&pops, to_world());
        assert!(medium.is_modulated());
        let (words, hits) = collision_words(&medium);
        assert_eq!(
            (hash_words(&words), hits),
            (COLLISIONS_HASH, COLLISIONS),
            "Constant({c})"
        );
    }
}

/// Renders agree bit for bit (40 × 30, 8 spp, 2 threads, the studio stage) between a body whose
/// platelets have no modulation and the same with `modulation: Some(Constant(1.0))`, explicit and
/// statistical. The boundary is rough (2°), which keeps manifold next-event estimation off: its
/// shadow segments through a modulated statistical form integrate the rate by a quadrature, which
/// a constant modulation of 1 reproduces only to rounding.
#[test]
fn renders_with_a_modulation_of_one_are_bit_identical() {
    for form in ["Explicit", "Statistical"] {
        let film = |modulation: &str| {
            let text = gem(
                &format!(
                    "(ior: 1.52, roughness: 2.0, platelets: [(density: 3000.0, radius: (0.01, 0.04), \
                     orientation: Uniform, entries: [(1.0, \"copper\")]{modulation})])"
                ),
                &format!("(render: (platelets: {form}, max_depth: 8))"),
            );
            let mut s = scene(&text);
            let r = &mut s.stage.render;
            r.width = 40;
            r.height = 30;
            r.spp = 8;
            let w = World::new(&s).expect("world");
            assert_eq!(form == "Explicit", !w.platelets.is_empty());
            render_on(&w, &s, 2, Strategy::Mis).film
        };
        let (a, b) = (film(""), film(", modulation: Some(Constant(1.0))"));
        let (count, first) = differences(&a, &b);
        assert_eq!(count, 0, "{form}: {count} pixels differ; {first:?}");
    }
}
