use crate::{random_point, random_unit};
use glam::Vec3;
use lapidary::sampler::Rng;
use lapidary::texture::Voronoi;

// ------------------------------------------------------------------------------------------------
// 4. Geometry of the cellular basis
// ------------------------------------------------------------------------------------------------

/// For jitter 0, ½ and 1, at 20 000 random points each: finite values, `F1 ≤ F2`,
/// `edge ≥ (F2 − F1)/2 ≥ 0` (every other point `pj` has `|x − pj| ≥ F2`, so its bisector is at
/// least `(F2 − F1)/2` away), `F1 = |x − feature|`, `nearest` equal to `sample`; points with
/// `edge > 1e-3` keep their id (in `sample` and `nearest`) when moved by 1e-5 in four random
/// directions. Deterministic bounds, no significance involved.
#[test]
fn voronoi_basis_is_consistent_and_stable_inside_cells() {
    let mut rng = Rng::new(0x44);
    for (jitter, seed) in [(0.0f32, 31u64), (0.5, 32), (1.0, 33)] {
        let v = Voronoi::new(seed, jitter);
        let (mut inside, mut total) = (0usize, 0usize);
        for _ in 0..20_000 {
            let p = random_point(&mut rng, -60.0, 60.0);
            let s = v.sample(p);
            total += 1;
            assert!(
                s.f1.is_finite() && s.f2.is_finite() && s.edge.is_finite() && s.feature.is_finite(),
                "{p:?}: {s:?}"
            );
            assert!(s.f1 <= s.f2 && s.edge >= 0.0, "{p:?}: {s:?}");
            assert!(s.edge >= 0.5 * (s.f2 - s.f1) - 1e-5, "{p:?}: {s:?}");
            assert!(
                ((p - s.feature).length() - s.f1).abs() < 1e-4,
                "{p:?}: {s:?}"
            );
            assert_eq!(v.cell_id(s.cell), s.id);
            let n = v.nearest(p);
            assert_eq!((n.f1, n.cell, n.id), (s.f1, s.cell, s.id), "{p:?}");
            if s.edge > 1e-3 {
                inside += 1;
                for _ in 0..4 {
                    let q = p + random_unit(&mut rng) * 1e-5;
                    assert_eq!(v.sample(q).id, s.id, "{p:?} → {q:?}, edge {}", s.edge);
                    assert_eq!(v.nearest(q).id, s.id, "{p:?} → {q:?}, edge {}", s.edge);
                }
            }
        }
        // Not vacuous: most points are farther than 1e-3 from a border.
        assert!(
            inside * 10 > total * 9,
            "jitter {jitter}: {inside} of {total}"
        );
    }
}

/// Walks from a cell's feature point `a` in a random direction until the id changes, bisects to
/// the border (40 halvings), and checks both sides: the ids differ, the border point is on the
/// bisector of `a` and the far side's feature `b` (`||x − a| − |x − b|| < 2e-4`), `edge < 1e-4`
/// and `F2 − F1 < 2e-4` there. At the midpoint `m` of `a` and `b`, when `a` and `b` are its two
/// nearest points (`m` lies on their shared face), `edge(m) < 1e-4`. 1000 walks per jitter.
/// Deterministic bounds.
#[test]
fn voronoi_id_changes_across_borders_where_edge_vanishes() {
    let mut rng = Rng::new(0x45);
    for (jitter, seed) in [(0.0f32, 41u64), (0.5, 42), (1.0, 43)] {
        let v = Voronoi::new(seed, jitter);
        let (mut walks, mut midpoints) = (0usize, 0usize);
        for _ in 0..1000 {
            let s = v.sample(random_point(&mut rng, -30.0, 30.0));
            let a = s.feature;
            let d = random_unit(&mut rng);
            let Some(t_hi) = (1..=80)
                .map(|i| i as f32 * 0.05)
                .find(|&t| v.sample(a + d * t).id != s.id)
            else {
                panic!("jitter {jitter}: no border within 4 cells of {a:?} along {d:?}");
            };
            let (mut lo, mut hi) = (0.0f32, t_hi);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if v.sample(a + d * mid).id == s.id {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let (x_lo, x_hi) = (a + d * lo, a + d * hi);
            let (near, far) = (v.sample(x_lo), v.sample(x_hi));
            assert_eq!(near.id, s.id);
            assert_ne!(far.id, s.id);
            let b = far.feature;
            for (x, at) in [(x_lo, near), (x_hi, far)] {
                assert!(at.edge < 1e-4, "edge at the border {x:?}: {at:?}");
                assert!(at.f2 - at.f1 < 2e-4, "{x:?}: {at:?}");
                assert!(
                    ((x - a).length() - (x - b).length()).abs() < 2e-4,
                    "{x:?} is not on the bisector of {a:?} and {b:?}"
                );
            }
            walks += 1;
            let m = 0.5 * (a + b);
            let at = v.sample(m);
            let (da, db) = ((m - a).length(), (m - b).length());
            if (at.f1 - da).abs() < 1e-5 && (at.f2 - db).abs() < 1e-5 {
                midpoints += 1;
                assert!(at.edge < 1e-4, "midpoint {m:?} of {a:?}, {b:?}: {at:?}");
            }
        }
        // Not vacuous: many midpoints lie on the shared face.
        assert!(
            midpoints * 4 > walks,
            "jitter {jitter}: {midpoints} of {walks}"
        );
    }
}

/// Jitter 0 puts every feature point at its cell's centre, so the bisectors are the planes of
/// integer coordinates: on them `F1 = F2` and `edge = 0`, at lattice points 8 points tie at
/// `√3/2`; `nearest` breaks the ties like `sample`. Deterministic bounds.
#[test]
fn voronoi_edge_vanishes_on_known_bisectors() {
    let v = Voronoi::new(51, 0.0);
    let mut rng = Rng::new(0x46);
    for _ in 0..5000 {
        let k = (rng.uniform() * 200.0 - 100.0).floor();
        let mut p = random_point(&mut rng, -100.0, 100.0);
        let axis = (rng.uniform() * 3.0) as usize % 3;
        // Keep the other coordinates away from their bisectors.
        for i in 0..3 {
            p[i] = p[i].floor() + 0.2 + 0.6 * (p[i] - p[i].floor());
        }
        p[axis] = k;
        let s = v.sample(p);
        assert!(
            (s.f2 - s.f1).abs() < 1e-5 && s.edge < 1e-5,
            "{p:?} on a bisector: {s:?}"
        );
        let mut lower = s.cell;
        lower[axis] = k as i32 - 1;
        let mut upper = s.cell;
        upper[axis] = k as i32;
        assert!(s.cell == lower || s.cell == upper, "{p:?}: {s:?}");
        let n = v.nearest(p);
        assert_eq!((n.f1, n.cell, n.id), (s.f1, s.cell, s.id), "{p:?}");
        // Half a cell off the bisector: inside, edge ½ minus the other axes' margins.
        let mut q = p;
        q[axis] += 0.5;
        assert!(v.sample(q).edge >= 0.2 - 1e-4, "{q:?}: {:?}", v.sample(q));
    }
    for p in [
        Vec3::ZERO,
        Vec3::new(3.0, -7.0, 12.0),
        Vec3::splat(-1.0),
        Vec3::new(-0.0, 0.0, -0.0),
    ] {
        let s = v.sample(p);
        let half_diag = 0.75f32.sqrt();
        assert!(
            (s.f1 - half_diag).abs() < 1e-6 && (s.f2 - half_diag).abs() < 1e-6 && s.edge < 1e-6,
            "{p:?}: {s:?}"
        );
        let n = v.nearest(p);
        assert_eq!((n.f1, n.cell, n.id), (s.f1, s.cell, s.id), "{p:?}");
    }
}
