//! Chi-square tests of the samplers issue 20 added: the excitation wavelength mixed with the
//! scene's laser lines, camera wavelengths drawn partly from the lines, and next-event
//! estimation's sampling of a beam's footprint. Each histogram is compared with the density the
//! renderer divides by (integrated per bin), 200 000 independent samples per configuration;
//! significance 0.01 over the whole file (Šidák over its 8 tests: α ≈ 0.0013 each); a sample
//! where the density is 0 fails outright. The densities are piecewise constant per bin by
//! construction of the bins (1 nm excitation cells, the lines' supports, equal-area polar cells),
//! so the expected counts are exact.

use super::common::{chi_square_pooled, sidak_alpha};
use glam::{Vec2, Vec3};
use lapidary::color::Rgb;
use lapidary::light::Area;
use lapidary::sampler::Rng;
use lapidary::scene::stage::{AreaLight, LightShape};
use lapidary::spectrum::fluorescence::Fluorescence;
use lapidary::spectrum::line::Line;
use lapidary::spectrum::measured::Measured;
use lapidary::spectrum::wavelengths::{HeroWavelengths, line_mixture_pdf, visible_pdf};

const N: usize = 200_000;
const TESTS: usize = 8;

fn alpha() -> f64 {
    sidak_alpha(0.01, TESTS)
}

/// The day-glo-like colorant of the unit tests: excitation a Gaussian at 530 nm, emission at
/// 590 nm.
fn dye() -> Fluorescence {
    let gauss = |mu: f32, sigma: f32, peak: f32| {
        let pts: Vec<(f32, f32)> = (0..=470)
            .step_by(2)
            .map(|i| {
                let l = 360.0 + i as f32;
                (l, peak * (-0.5 * ((l - mu) / sigma).powi(2)).exp())
            })
            .collect();
        Measured::from_points(&pts, 1.0).unwrap()
    };
    Fluorescence::new(&gauss(530.0, 25.0, 0.9), &gauss(590.0, 20.0, 1.0), 0.8).unwrap()
}

/// Bin edges over `[lo, hi]`: every whole nm plus the given extra edges, sorted.
fn edges(lo: f32, hi: f32, extra: &[f32]) -> Vec<f32> {
    let mut e: Vec<f32> = (lo.ceil() as i32..=hi.floor() as i32)
        .map(|x| x as f32)
        .collect();
    e.push(lo);
    e.push(hi);
    e.extend(extra.iter().copied().filter(|x| *x > lo && *x < hi));
    e.sort_by(f32::total_cmp);
    e.dedup();
    e
}

/// Pearson's test of `samples` against a density constant on each bin of `edges` (read at the
/// bin's midpoint), asserting at the file's significance.
fn check(what: &str, samples: &[f32], edges: &[f32], pdf: impl Fn(f32) -> f64) {
    let bins = edges.len() - 1;
    let mut observed = vec![0u64; bins];
    for &x in samples {
        let b = edges
            .partition_point(|&e| e <= x)
            .saturating_sub(1)
            .min(bins - 1);
        observed[b] += 1;
    }
    let expected: Vec<f64> = (0..bins)
        .map(|b| {
            let (a, c) = (edges[b], edges[b + 1]);
            N as f64 * pdf(0.5 * (a + c)) * f64::from(c - a)
        })
        .collect();
    let total: f64 = expected.iter().sum::<f64>() / N as f64;
    assert!(
        (total - 1.0).abs() < 1e-3,
        "{what}: the density integrates to {total}"
    );
    let r = chi_square_pooled(&observed, &expected, 5.0);
    eprintln!(
        "{what}: χ² {:.1}, dof {}, p {:.3}",
        r.chi2, r.dof, r.p_value
    );
    assert!(r.zero_expectation_hits.is_empty(), "{what}: {r:?}");
    assert!(r.p_value > alpha(), "{what}: p {} ≤ {}", r.p_value, alpha());
}

/// The excitation wavelength drawn from the colorant's absorption mixed with a 532 nm laser line
/// (FWHM 1 nm) and a broad 450 nm lamp line, for λo above both lines, between them and below
/// both; every sample's weight is `K / pdf` with the mixture's density.
#[test]
fn excitation_mixed_with_lines_matches_its_density() {
    let f = dye();
    let lines = [Line::new(532.0, 1.0), Line::new(450.0, 8.0)];
    for lambda_o in [600.0f32, 500.0, 440.0] {
        let mut rng = Rng::new(0x5eed ^ lambda_o.to_bits() as u64);
        let mut samples = Vec::with_capacity(N);
        let mut pdf_at = vec![];
        for _ in 0..N {
            let (us, u) = (rng.uniform(), rng.uniform());
            let s = f
                .sample_excitation_mixed(lambda_o, &lines, us, u)
                .expect("excited below λo");
            assert!(s.lambda <= lambda_o && s.lambda >= 360.0);
            let want = f.kernel(s.lambda, lambda_o) / s.pdf;
            assert!((s.weight - want).abs() <= 1e-4 * want, "{s:?}");
            samples.push(s.lambda);
            if pdf_at.len() < 100 {
                pdf_at.push((s.lambda, s.pdf));
            }
        }
        // The density: (1 − c) a/A + (c/m) Σ boxes, boxes clipped at λo.
        let cells: Vec<f64> = (0..(lambda_o - 360.0) as usize)
            .map(|j| f64::from(f.excitation(360.5 + j as f32)))
            .collect();
        let total: f64 = cells.iter().sum();
        let boxes: Vec<(f32, f32)> = lines
            .iter()
            .map(|l| l.support())
            .map(|(lo, hi)| (lo, hi.min(lambda_o)))
            .filter(|(lo, hi)| hi > lo)
            .collect();
        let c = if total > 0.0 { 0.5 } else { 1.0 };
        let density = |x: f32| {
            let a = if total > 0.0 {
                f64::from(f.excitation(x)) / total
            } else {
                0.0
            };
            let b: f64 = boxes
                .iter()
                .filter(|(lo, hi)| x >= *lo && x <= *hi)
                .map(|(lo, hi)| 1.0 / f64::from(hi - lo))
                .sum();
            (1.0 - c) * a + c * b / boxes.len() as f64
        };
        for (x, p) in pdf_at {
            assert!((f64::from(p) / density(x) - 1.0).abs() < 1e-4, "{x}: {p}");
        }
        let extra: Vec<f32> = boxes.iter().flat_map(|(a, b)| [*a, *b]).collect();
        check(
            &format!("excitation with lines, λo {lambda_o}"),
            &samples,
            &edges(360.0, lambda_o, &extra),
            density,
        );
    }
}

/// The hero wavelength of a camera path in a scene with lines is distributed as
/// [`line_mixture_pdf`], the density the film divides by (one line, two lines).
#[test]
fn wavelengths_with_lines_match_their_density() {
    for lines in [
        vec![Line::new(532.0, 1.0)],
        vec![Line::new(532.0, 1.0), Line::new(633.0, 2.0)],
    ] {
        let mut rng = Rng::new(0xfeed + lines.len() as u64);
        let samples: Vec<f32> = (0..N)
            .map(|_| {
                let w = HeroWavelengths::sample_with_lines(rng.uniform(), rng.uniform(), &lines);
                for i in 0..4 {
                    let want = line_mixture_pdf(w.lambda[i], &lines);
                    assert!((w.pdf[i] - want).abs() <= 1e-6 * want, "{w:?}");
                }
                w.lambda[0]
            })
            .collect();
        let extra: Vec<f32> = lines
            .iter()
            .flat_map(|l| [l.support().0, l.support().1])
            .collect();
        // The visible density varies within a 1 nm bin: integrate it per bin by the midpoint
        // rule at 64 points (its curvature makes that exact to ~1e-7 of a bin's probability).
        let e = edges(360.0, 830.0, &extra);
        let bins = e.len() - 1;
        let mut observed = vec![0u64; bins];
        for &x in &samples {
            let b = e
                .partition_point(|&v| v <= x)
                .saturating_sub(1)
                .min(bins - 1);
            observed[b] += 1;
        }
        let expected: Vec<f64> = (0..bins)
            .map(|b| {
                let (a, c) = (e[b], e[b + 1]);
                let h = (c - a) / 64.0;
                (0..64)
                    .map(|k| f64::from(line_mixture_pdf(a + (k as f32 + 0.5) * h, &lines) * h))
                    .sum::<f64>()
                    * N as f64
            })
            .collect();
        let total: f64 = expected.iter().sum::<f64>() / N as f64;
        assert!((total - 1.0).abs() < 1e-3, "{total}");
        let r = chi_square_pooled(&observed, &expected, 5.0);
        eprintln!(
            "wavelengths, {} lines: χ² {:.1}, dof {}, p {:.3}",
            lines.len(),
            r.chi2,
            r.dof,
            r.p_value
        );
        assert!(r.zero_expectation_hits.is_empty(), "{r:?}");
        assert!(r.p_value > alpha(), "p {} ≤ {}", r.p_value, alpha());
        // Negative control: the film dividing by the visible density alone (the lines ignored)
        // is rejected by the same test.
        let visible: Vec<f64> = (0..bins)
            .map(|b| {
                let (a, c) = (e[b], e[b + 1]);
                let h = (c - a) / 64.0;
                (0..64)
                    .map(|k| f64::from(visible_pdf(a + (k as f32 + 0.5) * h) * h))
                    .sum::<f64>()
                    * N as f64
            })
            .collect();
        let bad = chi_square_pooled(&observed, &visible, 5.0);
        assert!(
            bad.p_value < alpha(),
            "visible-only density passed: {bad:?}"
        );
    }
}

/// A laser: a disc of radius 0.08 at (0, 3, 0) aimed down with a 0.3° divergence.
fn beam(radius: f32) -> Area {
    Area::new(&AreaLight {
        center: Vec3::new(0.0, 3.0, 0.0),
        normal: Vec3::NEG_Y,
        shape: LightShape::Disc { radius },
        radiance: Rgb::splat(1.0),
        two_sided: false,
        spectrum: None,
        line: None,
        divergence: Some(0.3f32.to_radians()),
        polariser: None,
    })
}

/// Next-event estimation toward a beam samples the footprint of the shading point's cone on the
/// light uniformly: the sampled points, in equal-area polar cells of the footprint, are uniform
/// (footprint inside the disc: the beam's axis, and off axis), and each sample's density equals
/// `Area::pdf` of its direction; a point whose footprint leaves the disc loses exactly the
/// samples outside it, and every sampled direction carries the beam's radiance.
#[test]
fn beam_sampling_is_uniform_over_the_footprint() {
    let light = beam(0.08);
    let h = 3.0f32;
    let foot = h * 0.3f32.to_radians().tan();
    for (x, inside) in [(0.0f32, true), (0.03, true), (0.075, false)] {
        let p = Vec3::new(x, 0.0, 0.0);
        let mut rng = Rng::new(0xbea + x.to_bits() as u64);
        let (rings, sectors) = (10usize, 16usize);
        let mut observed = vec![0u64; rings * sectors + 1];
        for _ in 0..N {
            let u = Vec2::new(rng.uniform(), rng.uniform());
            let Some(s) = light.sample(p, u) else {
                observed[rings * sectors] += 1;
                continue;
            };
            assert!(s.radiance.0.iter().all(|&c| c == 1.0), "{s:?}");
            let pdf = light.pdf(p, s.wi, s.dist);
            assert!((pdf / s.pdf - 1.0).abs() < 1e-3, "{pdf} vs {}", s.pdf);
            let q = p + s.wi * s.dist;
            let d = Vec2::new(q.x - x, q.z) / foot;
            let r2 = d.length_squared().min(0.999_999);
            let ring = (r2 * rings as f32) as usize;
            let phi = d.y.atan2(d.x) + std::f32::consts::PI;
            let sector = ((phi / std::f32::consts::TAU * sectors as f32) as usize).min(sectors - 1);
            observed[ring * sectors + sector] += 1;
        }
        let expected: Vec<f64> = if inside {
            let mut e = vec![N as f64 / (rings * sectors) as f64; rings * sectors];
            e.push(0.0);
            e
        } else {
            // The fraction of each cell inside the disc (4096 sub-points per cell).
            let mut e = vec![];
            let mut lost = 0.0;
            for ring in 0..rings {
                for sector in 0..sectors {
                    let mut hit = 0usize;
                    for k in 0..64 {
                        for m in 0..64 {
                            let r2 = (ring as f32 + (k as f32 + 0.5) / 64.0) / rings as f32;
                            let phi = (sector as f32 + (m as f32 + 0.5) / 64.0) / sectors as f32
                                * std::f32::consts::TAU
                                - std::f32::consts::PI;
                            let q = Vec2::new(x, 0.0)
                                + Vec2::new(phi.cos(), phi.sin()) * r2.sqrt() * foot;
                            hit += usize::from(q.length() <= 0.08);
                        }
                    }
                    let share = hit as f64 / 4096.0;
                    e.push(N as f64 / (rings * sectors) as f64 * share);
                    lost += N as f64 / (rings * sectors) as f64 * (1.0 - share);
                }
            }
            e.push(lost);
            e
        };
        let r = chi_square_pooled(&observed, &expected, 5.0);
        eprintln!(
            "beam footprint at x {x}: χ² {:.1}, dof {}, p {:.3}",
            r.chi2, r.dof, r.p_value
        );
        assert!(r.zero_expectation_hits.is_empty(), "{r:?}");
        assert!(r.p_value > alpha(), "x {x}: p {} ≤ {}", r.p_value, alpha());
    }
}
