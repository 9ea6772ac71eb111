//! Faceted stones (issue 39): the exact convex-polytope intersector against independent geometry.
//!
//! - The parametric round brilliant (`Cut(Brilliant(girdle: 1.25, girdle_facets: 32))`) is the stone
//!   `scripts/brilliant-mesh.py` writes as `assets/brilliant.obj`: 200 000 random rays hit both at
//!   the same distance with the same normal (except within 10⁻³ of an edge, where the two may name
//!   neighbouring facets).
//! - Watertight: 1.5 million rays aimed at points of every edge and every vertex of the brilliant,
//!   each continuing into the interior, all hit at the aimed point.
//! - A GemCad cube (`.asc`: table, culet and four girdle facets) is the slab: the same hits.
//! - A GemCad prism's minimum deviation per wavelength, found by scanning the incidence through the
//!   renderer's own refraction, is Snell's closed form `δ = 2 asin(n sin(A/2)) − A` with the
//!   recipe's Sellmeier law.

use glam::{DVec3, Vec2, Vec3};
use lapidary::cut::{Brilliant, Cut};
use lapidary::geometry::shape::Shape;
use lapidary::geometry::{Polytope, Ray, Solid};
use lapidary::sampler::Rng;
use std::path::Path;
use std::sync::Arc;

/// The brilliant of `assets/brilliant.obj`: the default proportions with its 1.25 % girdle and 32
/// girdle sides.
fn brilliant() -> Polytope {
    let b = Brilliant {
        girdle: 0.0125,
        girdle_facets: 32,
        ..Brilliant::default()
    };
    let f = Cut::Brilliant(b).facets(2.0).unwrap();
    Polytope::new(&f.planes, "brilliant").unwrap()
}

/// A ray from a random point around the stone aimed at a random point inside its bounds.
fn random_ray(rng: &mut Rng) -> Ray {
    let u = |rng: &mut Rng| rng.uniform() * 2.0 - 1.0;
    let o = Vec3::new(u(rng), u(rng), u(rng)) * 3.0;
    let aim = Vec3::new(u(rng), u(rng) * 0.8, u(rng));
    Ray::new(o, (aim - o).normalize())
}

/// Distance from `p` to the nearest edge of the polytope.
fn edge_distance(edges: &[(DVec3, DVec3)], p: Vec3) -> f64 {
    let p = p.as_dvec3();
    edges
        .iter()
        .map(|&(a, b)| {
            let ab = b - a;
            let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
            (a + ab * t - p).length()
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn the_parametric_brilliant_is_the_obj_brilliant() {
    let poly = brilliant();
    let mesh = Solid::new(&Shape::Mesh {
        path: Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/brilliant.obj"),
        scale: 1.0,
    })
    .unwrap();
    let edges = poly.hull().edges();
    let mut rng = Rng::new(39);
    let (mut hits, mut near_edges) = (0, 0);
    for _ in 0..200_000 {
        let ray = random_ray(&mut rng);
        let (a, b) = (poly.intersect(&ray, 1e9), mesh.intersect(&ray, 1e9));
        match (a, b) {
            (Some(a), Some(b)) => {
                hits += 1;
                assert!((a.t - b.t).abs() < 2e-4, "{ray:?}: {a:?} vs {b:?}");
                if edge_distance(&edges, a.p) > 1e-3 {
                    assert!(a.ng.dot(b.ng) > 0.99999, "{ray:?}: {a:?} vs {b:?}");
                } else {
                    near_edges += 1;
                }
            }
            (None, None) => {}
            (a, b) => {
                // Only a ray grazing the silhouette may differ.
                let p = a.or(b).unwrap().p;
                assert!(
                    edge_distance(&edges, p) < 1e-4,
                    "{ray:?}: polytope {a:?}, mesh {b:?}"
                );
            }
        }
    }
    assert!(hits > 50_000, "{hits} hits");
    println!("{hits} hits, {near_edges} within 1e-3 of an edge");
    // The same facet count as the mesh's header: 57 facets and 32 girdle sides.
    assert_eq!(poly.planes(), 57 + 32);
}

#[test]
fn rays_at_every_edge_and_vertex_of_the_brilliant_hit() {
    let poly = brilliant();
    let hull = poly.hull();
    let vertices = hull.vertices();
    let centre = vertices.iter().sum::<DVec3>() / vertices.len() as f64;
    let mut rng = Rng::new(7);
    let mut targets: Vec<DVec3> = vertices.clone();
    for (a, b) in hull.edges() {
        for _ in 0..60 {
            targets.push(a + (b - a) * f64::from(rng.uniform()));
        }
    }
    let per_target = 1_500_000 / targets.len() + 1;
    let mut count = 0usize;
    for &x in &targets {
        for _ in 0..per_target {
            // Into the interior: toward a random point near the centre.
            let jitter = DVec3::new(
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.5,
            ) * 0.6;
            let dir = (centre + jitter - x).normalize();
            let origin = x - dir * (3.0 + f64::from(rng.uniform()));
            let ray = Ray::new(origin.as_vec3(), dir.as_vec3());
            let h = poly
                .intersect(&ray, f32::INFINITY)
                .unwrap_or_else(|| panic!("a ray at {x} slipped through"));
            assert!((h.p.as_dvec3() - x).length() < 2e-5, "{x}: {h:?}");
            count += 1;
        }
    }
    assert!(count >= 1_500_000, "{count}");
    println!(
        "{count} rays at {} edges and {} vertices: all hit",
        hull.edges().len(),
        vertices.len()
    );
}

const CUBE: &str = "GemCad 5.0\ng 96 0\ny 4 y\nI 1.5\nH A cube: lapidary's test design\n\
                    a 0 1 n Table\na -0 1 n Culet\na 90 1 0 24 48 72 n Girdle\n";

/// Writes `text` to a scratch `.asc` and reads it as a recipe's shape.
fn design_shape(name: &str, text: &str, width: f32) -> Shape {
    let dir = std::env::temp_dir().join(format!("lapidary-faceted-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(format!("{name}.asc")), text).unwrap();
    let recipe = format!(
        "(materials: {{\"m\": (base: Lambert(albedo: Gray(0.5)))}}, surface: Material(\"m\"),\n\
         stage: (shape: Design(file: \"{name}.asc\", width: {width})))"
    );
    let path = dir.join("gem.ron");
    let scene = lapidary::recipe::GemRecipe::parse(path.to_str().unwrap(), &recipe)
        .and_then(|r| r.compile())
        .expect("the design compiles");
    std::fs::remove_dir_all(&dir).ok();
    scene.stage.shape.clone()
}

#[test]
fn a_gemcad_cube_is_the_slab() {
    let shape = design_shape("cube", CUBE, 2.0);
    let Shape::Faceted(f) = &shape else {
        panic!("{shape:?}")
    };
    assert_eq!(f.names.len(), 6);
    assert!((f.volume - 8.0).abs() < 1e-9);
    let cube = Solid::new(&shape).unwrap();
    // The slab rests on y = 0; the design is centred: compare with the slab lifted by 1.
    let slab = Solid::new(&Shape::Slab {
        size: Vec3::splat(2.0),
    })
    .unwrap();
    let mut rng = Rng::new(3);
    let mut hits = 0;
    for _ in 0..100_000 {
        let ray = random_ray(&mut rng);
        let lifted = Ray::new(ray.origin + Vec3::Y, ray.dir);
        match (cube.intersect(&ray, 1e9), slab.intersect(&lifted, 1e9)) {
            (Some(a), Some(b)) => {
                hits += 1;
                assert!((a.t - b.t).abs() < 1e-5, "{a:?} {b:?}");
                assert!((a.p + Vec3::Y - b.p).length() < 1e-5, "{a:?} {b:?}");
            }
            (None, None) => {}
            (a, b) => panic!("{ray:?}: design {a:?}, slab {b:?}"),
        }
    }
    assert!(hits > 20_000, "{hits}");
}

/// The SCHOTT N-BK7 Sellmeier coefficients (SCHOTT optical glass data sheet, N-BK7):
/// `n² − 1 = Σ Bᵢ λ² / (λ² − Cᵢ)`, λ in µm.
const BK7_B: [f64; 3] = [1.039_612_12, 0.231_792_344, 1.010_469_45];
const BK7_C: [f64; 3] = [0.006_000_698_67, 0.020_017_914_4, 103.560_653];

fn bk7(lambda_nm: f64) -> f64 {
    let l2 = (lambda_nm * 1e-3).powi(2);
    (1.0 + (0..3).map(|i| BK7_B[i] * l2 / (l2 - BK7_C[i])).sum::<f64>()).sqrt()
}

const PRISM: &str = "GemCad 5.0\ng 96 0\ny 1 n\nI 1.5168\nH A 60-degree prism: lapidary's test design\n\
                     a 60 0.5 24 72 n Faces\na -0 0.5 n Base\na 90 2 0 48 n Ends\n";

#[test]
fn a_gemcad_prism_has_snells_minimum_deviation_at_every_wavelength() {
    use lapidary::bsdf::LobeFlags;
    use lapidary::geometry::offset_origin;
    use lapidary::render::World;
    use lapidary::render::shading::shade;
    use lapidary::render::world::Hit;
    use lapidary::spectrum::HeroSample;
    use lapidary::spectrum::rgb2spec::d65_normalised;
    use lapidary::spectrum::wavelengths::HeroWavelengths;

    let dir = std::env::temp_dir().join(format!("lapidary-faceted-prism-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("prism.asc"), PRISM).unwrap();
    let recipe = format!(
        "(materials: {{}}, surface: Body,\n body: (ior: {}, dispersion: Sellmeier(b: ({}, {}, {}), \
         c: ({}, {}, {}))),\n stage: (shape: Design(file: \"prism.asc\", width: 4.0), ground: Off, \
         lights: [], environment: Constant(Gray(1.0))))",
        bk7(587.56),
        BK7_B[0],
        BK7_B[1],
        BK7_B[2],
        BK7_C[0],
        BK7_C[1],
        BK7_C[2]
    );
    let scene = lapidary::recipe::GemRecipe::parse(dir.join("p.ron").to_str().unwrap(), &recipe)
        .and_then(|r| r.compile())
        .expect("the prism compiles");
    let world = World::new(&scene).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    // The prism's faces: normals (±sin 60°, cos 60°, 0), apex on the y axis, A = 60°.
    let Shape::Faceted(f) = &scene.stage.shape else {
        panic!()
    };
    let apex_y = f.vertices.iter().map(|v| v.y).fold(f64::MIN, f64::max);
    let base_y = f.vertices.iter().map(|v| v.y).fold(f64::MAX, f64::min);
    let mid_left = Vec3::new(
        (-0.5 * (apex_y - base_y) / 3f64.sqrt()) as f32,
        (0.5 * (apex_y + base_y)) as f32,
        0.1,
    );
    let through = |phi: f64, lambda: f32| -> Option<f64> {
        let l = HeroWavelengths {
            lambda: [lambda; 4],
            pdf: [1.0; 4],
            illuminant: [d65_normalised(lambda); 4],
        };
        let d = Vec3::new(phi.cos() as f32, phi.sin() as f32, 0.0);
        let mut ray = Ray::new(mid_left - 3.0 * d, d);
        for _ in 0..2 {
            let hit = world.intersect(&ray, f32::INFINITY)?;
            assert!(matches!(hit, Hit::Stone(_)));
            let mut out = lapidary::render::PathSample::default();
            let sb = shade(&world, &hit, -ray.dir, 0.5, l, false, &mut out)?;
            let wo = sb.frame.to_local(-ray.dir);
            let s = sb.sample::<HeroSample>(wo, 0.9999, Vec2::splat(0.5), &l)?;
            if !s.flags.contains(LobeFlags::TRANSMISSION) {
                return None;
            }
            ray = Ray::new(offset_origin(sb.p, sb.ng, s.wi), s.wi);
        }
        let out = ray.dir.as_dvec3();
        Some(phi - out.y.atan2(out.x))
    };
    let apex = 60f64.to_radians();
    for lambda in [404.66f32, 486.13, 587.56, 656.27, 852.11] {
        let n = bk7(f64::from(lambda));
        let want = 2.0 * (n * (apex / 2.0).sin()).asin() - apex;
        // Scan the incidence (its minimum is flat: a 0.02° grid finds it to ~1e-7 rad).
        let best = (0..3000)
            .filter_map(|k| {
                let phi = (-10.0 + 0.02 * f64::from(k)).to_radians();
                through(phi, lambda)
            })
            .fold(f64::INFINITY, f64::min);
        println!(
            "λ {lambda} nm: n {n:.5}, minimum deviation {:.4}° (Snell {:.4}°)",
            best.to_degrees(),
            want.to_degrees()
        );
        assert!((best - want).abs() < 2e-4, "λ {lambda}: {best} vs {want}");
    }
}

#[test]
fn shapes_are_shared_not_copied() {
    // A faceted shape is behind an `Arc`: cloning a stage does not copy its planes.
    let shape = design_shape("shared", CUBE, 2.0);
    let Shape::Faceted(f) = &shape else { panic!() };
    let copy = shape.clone();
    let Shape::Faceted(g) = &copy else { panic!() };
    assert!(Arc::ptr_eq(f, g));
}

/// Every corner of the brilliant's parameter box on every outline, and 2 000 random points in it:
/// each cut is either made with every facet present (girdle facets may vanish at a knife-edge
/// girdle) and the stone closed, or refused with a message (never a panic).
#[test]
fn the_whole_parameter_range_cuts_or_is_refused() {
    use lapidary::cut::Outline;
    let outlines = [
        Outline::Round,
        Outline::Oval { ratio: 3.0 },
        Outline::Marquise { ratio: 3.0 },
        Outline::Pear { ratio: 1.0 },
        Outline::Pear { ratio: 3.0 },
        Outline::Cushion { ratio: 2.0 },
    ];
    // Ranges as `recipe::cut` allows them.
    let ranges = [
        (0.40, 0.80),
        (20.0, 45.0),
        (35.0, 50.0),
        (0.0, 0.10),
        (0.30, 0.70),
        (0.50, 0.95),
        (0.0, 0.10),
    ];
    let make = |x: [f64; 7], outline: Outline| Brilliant {
        outline,
        table: x[0],
        crown: x[1],
        pavilion: x[2],
        girdle: x[3],
        star: x[4],
        lower_girdle: x[5],
        culet: x[6],
        girdle_facets: 64,
    };
    let (mut made, mut refused) = (0, 0);
    let mut check = |b: Brilliant| match Cut::Brilliant(b).facets(2.0) {
        Ok(f) => {
            made += 1;
            // Only girdle facets may vanish (where the girdle thins to a knife edge).
            let lost = f
                .missing()
                .into_iter()
                .filter(|&k| !f.names[k as usize].starts_with("girdle"));
            assert!(f.volume > 0.0 && lost.count() == 0, "{b:?}");
            Polytope::new(&f.planes, "sweep").unwrap();
        }
        Err(e) => {
            refused += 1;
            assert!(e.0.contains("facet"), "{b:?}: {e}");
        }
    };
    for outline in outlines {
        for corner in 0..128u32 {
            let x: [f64; 7] = std::array::from_fn(|k| {
                let (lo, hi) = ranges[k];
                if corner & (1 << k) != 0 { hi } else { lo }
            });
            check(make(x, outline));
        }
    }
    let mut rng = Rng::new(2024);
    for k in 0..2000 {
        let x: [f64; 7] = std::array::from_fn(|i| {
            let (lo, hi) = ranges[i];
            lo + (hi - lo) * f64::from(rng.uniform())
        });
        check(make(x, outlines[k % outlines.len()]));
    }
    println!("{made} cut, {refused} refused");
    assert!(made > refused, "{made} cut, {refused} refused");
}

/// Bad cuts are refused where they are written: a number out of range at the number, a
/// contradiction at the `Cut`, a broken `.asc` at its own line and column.
#[test]
fn bad_cuts_and_designs_are_refused_at_their_position() {
    let dir = std::env::temp_dir().join(format!("lapidary-faceted-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let head =
        "(materials: {\"m\": (base: Lambert(albedo: Gray(0.5)))}, surface: Material(\"m\"),\n";
    let error = |shape: &str| -> String {
        let text = format!("{head} stage: (shape: {shape}))");
        let path = dir.join("gem.ron");
        match lapidary::recipe::GemRecipe::parse(path.to_str().unwrap(), &text)
            .and_then(|r| r.compile())
        {
            Ok(_) => panic!("{shape} was accepted"),
            Err(e) => e.to_string(),
        }
    };
    // `line:col` of `needle` in the recipe's second line.
    let at = |shape: &str, needle: &str| {
        let line = format!(" stage: (shape: {shape}))");
        format!("gem.ron:2:{}:", line.find(needle).unwrap() + 1)
    };
    let shape = "Cut(Brilliant(crown: 60.0))";
    let e = error(shape);
    let want = format!(
        "{} crown = 60 is out of range: allowed 20 ..= 45",
        at(shape, "60.0")
    );
    assert!(e.ends_with(&want), "{e}");
    let shape = "Cut(Brilliant(outline: Pear(ratio: 0.5)))";
    let e = error(shape);
    let want = format!(
        "{} ratio = 0.5 is out of range: allowed 1 ..= 3",
        at(shape, "0.5")
    );
    assert!(e.ends_with(&want), "{e}");
    let e = error("Cut(Brilliant(girdle_facets: 40))");
    assert!(e.contains("a multiple of 16 in 16 ..= 256"), "{e}");
    let shape = "Cut(Brilliant(table: 80.0, star: 30.0))";
    let e = error(shape);
    let want = format!(
        "{} shape: Cut: star = 30.0 % with table = 80.0 %",
        at(shape, "Cut")
    );
    assert!(e.contains(&want), "{e}");
    assert!(e.contains("needs star > 48.6 %"), "{e}");
    let e = error("Cut(Emerald(pavilion: [40.0, 50.0]))");
    assert!(e.contains("flatter than the one before"), "{e}");
    std::fs::write(
        dir.join("broken.asc"),
        "GemCad 5.0\r\ng 96 0\r\na 40 1.0 0 24\r\na 91 1 0\r\n",
    )
    .unwrap();
    let e = error("Design(file: \"broken.asc\")");
    assert!(
        e.contains("broken.asc:4:3: angle = 91: allowed −90 ..= 90 degrees"),
        "{e}"
    );
    let e = error("Design(file: \"missing.asc\")");
    assert!(e.contains("design \"missing.asc\""), "{e}");
    let e = error("Design(file: \"gem.ron\")");
    assert!(e.contains("expected a .asc file"), "{e}");
    // An open design: no table, so nothing closes it upward.
    std::fs::write(
        dir.join("open.asc"),
        "GemCad 5.0\ng 96 0\na -40 1.0 0 24 48 72\n",
    )
    .unwrap();
    let e = error("Design(file: \"open.asc\")");
    assert!(e.contains("do not close the stone"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Tolkowsky's ideal brilliant (*Diamond Design*, 1919, as tabulated in gemmology texts since):
/// table 53 %, crown angle 34.5°, pavilion angle 40.75°, knife-edge girdle — for which he
/// published crown height 16.2 %, pavilion depth 43.1 % and total depth 59.3 % of the girdle
/// diameter (his total has no girdle). The cut measured from its solid (`lapidary info`'s
/// figures, `cut::metrics`) gives his figures to their printed digits; its girdle is a knife edge
/// only halfway between the junctions, where a faceted girdle is thinnest, so the solid's total
/// depth adds the girdle's thickness at the junctions.
#[test]
fn tolkowskys_brilliant_has_his_published_proportions() {
    let b = Brilliant {
        table: 0.53,
        girdle: 0.0,
        ..Brilliant::default()
    };
    let f = Cut::Brilliant(b).facets(2.0).unwrap();
    let p = lapidary::cut::metrics::proportions(&f);
    let (crown, pavilion) = (p.crown_pct.unwrap(), p.pavilion_pct.unwrap());
    let (thinnest, thickest) = p.girdle_pct.unwrap();
    let rounded = |x: f64| (10.0 * x).round() / 10.0;
    assert_eq!(rounded(crown), 16.2, "crown height {crown}");
    assert_eq!(rounded(pavilion), 43.1, "pavilion depth {pavilion}");
    // His total is the sum of his rounded parts (16.15 + 43.08 = 59.23 unrounded).
    assert!(
        (crown + pavilion - 59.3).abs() < 0.1,
        "crown + pavilion {}",
        crown + pavilion
    );
    assert!((p.table_pct.unwrap() - 53.0).abs() < 1e-6);
    assert!(thinnest.abs() < 1e-6, "knife edge {thinnest}");
    assert!((p.depth_pct - (crown + pavilion + thickest)).abs() < 1e-6);
}
