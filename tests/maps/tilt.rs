use crate::common::{ChiSquare, Grid2, chi_square_pooled, par_map};
use crate::{alpha_i, block_ids};
use glam::Vec3;
use lapidary::texture::{FacetBump, Tilt, Voronoi};

// ------------------------------------------------------------------------------------------------
// 3. Tilt distributions against their pdf
// ------------------------------------------------------------------------------------------------

/// Normals drawn in the default tilt test.
const N_TILT: usize = 200_000;

/// The result of one tilt histogram test.
struct TiltRun {
    chi: ChiSquare,
    /// Normals that were not finite unit vectors, or fell outside the `φ` range.
    invalid: u64,
    /// `∫_grid pdf dω` of the claimed distribution.
    integral: f64,
}

impl TiltRun {
    fn passes(&self, alpha: f64) -> bool {
        self.invalid == 0 && self.integral <= 1.0 + 1e-6 && self.chi.passes(alpha)
    }
}

/// The `(cos θ, φ)` grid of a tilt distribution: the cone's grid puts `cos θmax` on a bin edge
/// and keeps four rows of bins outside the cone (zero expectation), Beckmann's covers
/// `cos θ ∈ [0.75, 1]` (all but 2e-5 of the mass). 16 bins in `φ`.
fn tilt_grid(tilt: Tilt) -> Grid2 {
    let tau = std::f64::consts::TAU;
    match tilt {
        Tilt::Cone { half_angle } => {
            // The support's edge as the implementation computes it (in f32, 3e-8 below the f64
            // cosine at 25°), so that no correct sample can fall into a zero-expectation bin.
            let c = f64::from(half_angle.to_radians().cos());
            let step = (1.0 - c) / 16.0;
            Grid2 {
                nu: 20,
                nv: 16,
                u: (c - 4.0 * step, 1.0),
                v: (0.0, tau),
            }
        }
        Tilt::Beckmann { .. } => Grid2 {
            nu: 50,
            nv: 16,
            u: (0.75, 1.0),
            v: (0.0, tau),
        },
    }
}

/// Draws `n` facet normals `sampled.normal(id)` over distinct cell ids, bins them by
/// `(cos θ, φ)` and compares with `n ∫_bin claimed.pdf dω` (`dω = d(cos θ) dφ`; adaptive 3 × 3
/// Gauss–Legendre, 4 × 4 cells per bin refined to 1e-10). One extra cell holds the normals below
/// the grid, expecting `n (1 − ∫_grid pdf)` (zero when that is below 1e-9).
fn tilt_test(sampled: FacetBump, claimed: FacetBump, grid: Grid2, n: usize, seed: u64) -> TiltRun {
    let basis = Voronoi::new(seed, 1.0);
    let cells = grid.len();
    let mut observed = vec![0u64; cells + 1];
    let mut invalid = 0u64;
    for id in block_ids(&basis, n) {
        let m = sampled.normal(id);
        if !m.is_finite() || (m.length() - 1.0).abs() > 1e-5 {
            invalid += 1;
            continue;
        }
        let mut phi = f64::from(m.y).atan2(f64::from(m.x));
        if phi < 0.0 {
            phi += std::f64::consts::TAU;
        }
        let cos_t = f64::from(m.z);
        if cos_t < grid.u.0 {
            observed[cells] += 1;
            continue;
        }
        match grid.bin(cos_t, phi) {
            Some(b) => observed[b] += 1,
            None => invalid += 1,
        }
    }
    let mass = grid.integrate_adaptive(4, 1e-10, 6, |u, phi| {
        let s = (1.0 - u * u).max(0.0).sqrt();
        let m = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, u as f32);
        f64::from(claimed.pdf(m))
    });
    let integral: f64 = mass.iter().sum();
    let mut expected: Vec<f64> = mass.iter().map(|m| m * n as f64).collect();
    let rest = 1.0 - integral;
    expected.push(if rest < 1e-9 { 0.0 } else { rest * n as f64 });
    TiltRun {
        chi: chi_square_pooled(&observed, &expected, 5.0),
        invalid,
        integral,
    }
}

fn print_tilt(label: &str, n: usize, r: &TiltRun) {
    println!(
        "{label:<44} n {n:>7} ∫pdf {:.7} bins {:>4} pooled {:>4} dof {:>4} chi² {:>10.1} \
         p {:.3e} invalid {} zero-pdf hits {}",
        r.integral,
        r.chi.own_bins,
        r.chi.pooled_cells,
        r.chi.dof,
        r.chi.chi2,
        r.chi.p_value,
        r.invalid,
        r.chi.zero_expectation_hits.len()
    );
}

/// The cone (25°) and Beckmann (15° RMS) tilts against their pdfs (passing, `α_i` each), and the
/// negative controls — the same normals against a cone of 26° and a Beckmann of 16.5° — which
/// must be rejected at `α_i`.
fn tilt_distributions(n: usize) {
    let cone = FacetBump {
        tilt: Tilt::Cone { half_angle: 25.0 },
    };
    let beckmann = FacetBump {
        tilt: Tilt::Beckmann { rms: 15.0 },
    };
    let wrong_cone = FacetBump {
        tilt: Tilt::Cone { half_angle: 26.0 },
    };
    let wrong_beckmann = FacetBump {
        tilt: Tilt::Beckmann { rms: 16.5 },
    };
    let cases = [
        ("cone 25°", cone, cone, true),
        ("beckmann 15°", beckmann, beckmann, true),
        (
            "control: cone 25° sampled, pdf of 26°",
            cone,
            wrong_cone,
            false,
        ),
        (
            "control: beckmann 15° sampled, pdf of 16.5°",
            beckmann,
            wrong_beckmann,
            false,
        ),
    ];
    let runs = par_map(&cases, |&(_, sampled, claimed, _)| {
        tilt_test(sampled, claimed, tilt_grid(sampled.tilt), n, 0x3c)
    });
    let alpha = alpha_i();
    println!("tilt distributions (α_i {alpha:.2e})");
    for ((label, _, _, should_pass), r) in cases.iter().zip(&runs) {
        print_tilt(label, n, r);
        if *should_pass {
            assert!(
                r.passes(alpha),
                "{label}: p = {:e}, invalid {}, ∫ {}",
                r.chi.p_value,
                r.invalid,
                r.integral
            );
            assert!(r.chi.dof > 200, "{label}: the histogram is too coarse");
        } else {
            assert!(
                r.chi.p_value < alpha,
                "{label}: the wrong pdf was accepted, p = {:e}",
                r.chi.p_value
            );
        }
    }
}

/// 200 000 normals per distribution (cells of a 64 × 64 × 49 block); significance `α_i`.
#[test]
fn tilt_distributions_match_their_pdf() {
    tilt_distributions(N_TILT);
}

/// Full strength, 2 000 000 normals: `cargo test --release --test maps -- --ignored`.
#[test]
#[ignore = "slow: cargo test --release --test maps -- --ignored"]
fn tilt_distributions_match_their_pdf_full() {
    tilt_distributions(10 * N_TILT);
}
