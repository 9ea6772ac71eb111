//! The drivers of items 3 (hemispherical transmittance) and 4 (the smooth interface and the rough
//! one's limit) of `tests/dielectric.rs`; the constants and helpers are the parent's.

use super::*;

/// `2 ∫₀¹ (1 − F(±μ)) μ dμ` by the midpoint rule in f64 (10⁶ points; the kink at the critical
/// angle costs < 1e-6).
fn smooth_hemispherical_exact(eta: f32, below: bool) -> f64 {
    let k = 1_000_000;
    let sign = if below { -1.0 } else { 1.0 };
    (0..k)
        .map(|i| {
            let mu = (i as f64 + 0.5) / k as f64;
            let f = f64::from(lapidary::bsdf::fresnel::dielectric(sign * mu as f32, eta));
            2.0 * (1.0 - f) * mu
        })
        .sum::<f64>()
        / k as f64
}

fn run_hemispherical(n: u64) {
    #[derive(Clone)]
    enum Subject {
        Rough(RoughDielectric),
        Smooth(SmoothDielectric),
    }
    let mut cases: Vec<(String, Subject, f32)> = Vec::new();
    for &eta in &chi::ETAS {
        for &(k, m) in &chi::SURFACES {
            cases.push((
                format!("{k:?} m={m}"),
                Subject::Rough(glass(k, m, eta)),
                eta,
            ));
        }
        cases.push((
            "smooth".into(),
            Subject::Smooth(SmoothDielectric::new(eta)),
            eta,
        ));
    }
    let jobs: Vec<(usize, bool)> = (0..cases.len())
        .flat_map(|i| [(i, false), (i, true)])
        .collect();
    let results = par_map(&jobs, |&(i, below)| {
        let (name, subject, eta) = &cases[i];
        let mut words: Vec<u64> = name.bytes().map(u64::from).collect();
        words.extend([u64::from(eta.to_bits()), u64::from(below), n]);
        match subject {
            Subject::Rough(d) => energy::hemispherical(d, Some(d), *eta, below, n, seed(&words)),
            Subject::Smooth(g) => energy::hemispherical(g, None, *eta, below, n, seed(&words)),
        }
    });
    println!(
        "\nhemispherical transmittance t̄ = (1/π)∫T|cos| over {n} cosine-distributed wo per side \
         (importance; reciprocity: t̄_above = eta²·t̄_below)"
    );
    println!(
        "{:<20} {:>7} {:>9} {:>9} {:>11} {:>8} {:>9} {:>9} {:>9}",
        "interface",
        "eta",
        "t̄_above",
        "t̄_below",
        "eta²·t̄_bel",
        "z",
        "t̄_rad_ab",
        "t̄_rad_bel",
        "exact"
    );
    let mut failures = Vec::new();
    for (i, (name, subject, eta)) in cases.iter().enumerate() {
        let (a, b) = (&results[2 * i], &results[2 * i + 1]);
        let e2 = f64::from(*eta) * f64::from(*eta);
        let se = (a.se_t * a.se_t + e2 * e2 * b.se_t * b.se_t).sqrt();
        let z = (a.t_imp - e2 * b.t_imp) / se;
        let exact = matches!(subject, Subject::Smooth(_)).then(|| {
            (
                smooth_hemispherical_exact(*eta, false),
                smooth_hemispherical_exact(*eta, true),
            )
        });
        println!(
            "{name:<20} {eta:>7.4} {:>9.5} {:>9.5} {:>11.5} {z:>8.2} {:>9.5} {:>9.5} {:>9}",
            a.t_imp,
            b.t_imp,
            e2 * b.t_imp,
            a.t_rad,
            b.t_rad,
            exact.map_or(String::new(), |(x, y)| format!("{x:.5}/{y:.5}"))
        );
        if z.abs() > Z {
            failures.push(format!(
                "{name} eta {eta}: t̄_above {} != eta²·t̄_below {} ({z:.1} standard errors)",
                a.t_imp,
                e2 * b.t_imp
            ));
        }
        // Radiance mode leaving the dense side: T_rad = η²·T_imp per sample, so the radiance
        // transmittance from below equals the importance transmittance from above (in the mean).
        let zr = (b.t_rad - a.t_imp) / se;
        if zr.abs() > Z {
            failures.push(format!(
                "{name} eta {eta}: t̄_rad(below) {} != t̄(above) {}",
                b.t_rad, a.t_imp
            ));
        }
        if let Some((x, y)) = exact {
            // The analytic identity itself (Fresnel from both sides), then the sampler against it.
            if (x - e2 * y).abs() > 1e-5 {
                failures.push(format!(
                    "eta {eta}: 2∫(1−F)μ above {x} != eta² · below {}",
                    e2 * y
                ));
            }
            for (est, want, side) in [(a, x, "above"), (b, y, "below")] {
                if (est.t_imp - want).abs() > Z * est.se_t + 1e-6 {
                    failures.push(format!(
                        "smooth eta {eta} {side}: t̄ {} != exact {want}",
                        est.t_imp
                    ));
                }
            }
        }
        for r in [a, b] {
            if r.stats.bad > 0 {
                failures.push(format!(
                    "{name}: {}",
                    r.stats.first_bad.as_deref().unwrap_or("")
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn hemispherical_transmittance_obeys_eta_squared() {
    run_hemispherical(N_HEMI);
}

/// Full version: `cargo test --release --test dielectric -- --ignored --nocapture`.
#[test]
#[ignore = "slow: cargo test --release --test dielectric -- --ignored --nocapture"]
fn hemispherical_transmittance_obeys_eta_squared_full() {
    run_hemispherical(N_HEMI * FULL);
}

// ------------------------------------------------------------------------------------------------
// 4. The smooth dielectric, and the rough one's limit
// ------------------------------------------------------------------------------------------------

/// The binomial configurations: every IOR × angle × side that is not under total internal
/// reflection.
fn split_cases() -> Vec<(f32, f32, bool)> {
    let mut v = Vec::new();
    for eta in [1.5f32, 2.4, 1.0 / 1.5] {
        for below in [false, true] {
            for theta in [0.0f32, 25.0, 50.0, 70.0, 85.0] {
                if smooth::fresnel_at(view(theta, 10.0, below), eta) < 1.0 {
                    v.push((eta, theta, below));
                }
            }
        }
    }
    v
}

/// Number of binomial configurations (checked against [`split_cases`]).
const SPLIT_COUNT: usize = 20;

fn run_split(n: u64) {
    let cases = split_cases();
    assert_eq!(cases.len(), SPLIT_COUNT);
    let alpha = sidak_alpha(ALPHA, SPLIT_COUNT);
    let results = par_map(&cases, |&(eta, theta, below)| {
        let g = SmoothDielectric::new(eta);
        let wo = view(theta, 10.0, below);
        let deg = (if below { 180.0 - theta } else { theta }, 10.0);
        let s = seed(&[
            0x5b1e,
            u64::from(eta.to_bits()),
            u64::from(theta.to_bits()),
            u64::from(below),
        ]);
        (
            smooth::split(&g, eta, wo, deg, n, s),
            smooth::delta_is_invisible(&g, wo),
        )
    });
    println!(
        "\nsmooth dielectric: reflections in {n} draws vs Binomial(n, F) (per-test α = {alpha:.2e})"
    );
    println!(
        "{:<20} {:>6} {:>10} {:>9} {:>9} {:>8} {:>9} {:>9}",
        "interface", "θo", "reflected", "share", "F", "chi²", "p", "Snell"
    );
    let mut failures = Vec::new();
    let mut worst_p = 1.0f64;
    for (r, invisible) in &results {
        worst_p = worst_p.min(r.p);
        println!(
            "{:<20} {:>6.0} {:>10} {:>9.6} {:>9.6} {:>8.2} {:>9.3e} {:>9.1e}",
            r.label,
            r.wo_deg.0,
            r.reflected,
            r.reflected as f64 / r.n as f64,
            r.f,
            r.chi2,
            r.p,
            r.worst_snell
        );
        let at = format!("{} θo {}", r.label, r.wo_deg.0);
        if r.p < alpha {
            failures.push(format!("{at}: p = {:e} < {alpha:e}", r.p));
        }
        if r.stats.bad > 0 || !r.geometry_failures.is_empty() {
            failures.push(format!(
                "{at}: {} bad samples, {:?}; {}",
                r.stats.bad,
                r.geometry_failures,
                r.stats.first_bad.as_deref().unwrap_or("")
            ));
        }
        if r.stats.returned != r.n {
            failures.push(format!(
                "{at}: {} of {} draws failed",
                r.n - r.stats.returned,
                r.n
            ));
        }
        if !invisible {
            failures.push(format!("{at}: eval or pdf of a delta is not 0"));
        }
    }
    println!("worst p = {worst_p:.3e}");
    // A wrong IOR is rejected: the counts at eta 1.5, θo 60° against F(η = 1.55).
    let g = SmoothDielectric::new(1.5);
    let wrong = smooth::split(&g, 1.55, view(60.0, 10.0, false), (60.0, 10.0), n, 0x0bad);
    println!(
        "self-test: eta 1.5 counted against F(1.55): chi² {:.1}, p {:.2e}",
        wrong.chi2, wrong.p
    );
    if wrong.p >= alpha {
        failures.push(format!("F of the wrong IOR accepted: p = {}", wrong.p));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn smooth_fresnel_split_is_binomial() {
    run_split(N_SPLIT);
}

/// Full version: `cargo test --release --test dielectric -- --ignored --nocapture`.
#[test]
#[ignore = "slow: cargo test --release --test dielectric -- --ignored --nocapture"]
fn smooth_fresnel_split_is_binomial_full() {
    run_split(N_SPLIT * FULL);
}

#[test]
fn smooth_total_internal_reflection_beyond_the_critical_angle() {
    // (eta, side of the dense medium): inside glass and diamond, and glass above the surface.
    for (eta, dense_below) in [(1.5f32, true), (2.4, true), (1.0 / 1.5, false)] {
        let g = SmoothDielectric::new(eta);
        let n_dense = if dense_below { eta } else { 1.0 / eta };
        let critical = (1.0 / n_dense).asin().to_degrees();
        let ucs = [0.0f32, 0.25, 0.5, 0.999_999, 1.0];
        // Beyond the critical angle: every uc reflects, weight 1 in both modes, pdf 1.
        let mut theta = critical + 0.05;
        while theta < 90.0 {
            let wo = view(theta, 77.0, dense_below);
            for uc in ucs {
                let mut st = SampleStats::default();
                let (sr, si) = checks::check_smooth(&g, wo, uc, glam::Vec2::splat(0.5), &mut st)
                    .unwrap_or_else(|| panic!("eta {eta} θ {theta} uc {uc}: {:?}", st.first_bad));
                assert!(
                    !sr.flags.is_transmission(),
                    "eta {eta} θ {theta} uc {uc}: {sr:?}"
                );
                assert_eq!((sr.pdf, sr.eta), (1.0, 1.0), "eta {eta} θ {theta}: {sr:?}");
                smooth::check_geometry(wo, eta, &sr, &si).unwrap();
            }
            theta += 0.5;
        }
        // Just inside the critical angle some light still leaves: uc near 1 transmits, with
        // the weights of the modes and Snell's law (sin θi = η_dense sin θo → near grazing).
        for theta in [critical - 0.5, critical - 5.0, 10.0] {
            let wo = view(theta, 77.0, dense_below);
            let mut st = SampleStats::default();
            let (sr, si) = checks::check_smooth(&g, wo, 0.999_999, glam::Vec2::ZERO, &mut st)
                .unwrap_or_else(|| panic!("{:?}", st.first_bad));
            assert!(sr.flags.is_transmission(), "eta {eta} θ {theta}: {sr:?}");
            assert!((sr.eta - 1.0 / n_dense).abs() < 1e-6, "{sr:?}");
            smooth::check_geometry(wo, eta, &sr, &si).unwrap();
        }
    }
}

fn run_convergence(n: u64) {
    let mut cases = Vec::new();
    for kind in [Distribution::Blinn, Distribution::Beckmann] {
        for eta in [1.5f32, 2.4] {
            let critical = (1.0 / eta).asin().to_degrees();
            for (theta, below) in [
                (0.0, false),
                (30.0, false),
                (60.0, false),
                (10.0, true),
                (critical - 8.0, true),
                (critical + 8.0, true),
            ] {
                cases.push((kind, eta, theta, below));
            }
        }
    }
    let results = par_map(&cases, |&(kind, eta, theta, below)| {
        let d = glass(kind, 0.5, eta);
        let wo = view(theta, 20.0, below);
        let s = seed(&[
            0xc0de,
            kind as u64,
            u64::from(eta.to_bits()),
            u64::from(theta.to_bits()),
            u64::from(below),
        ]);
        let target = move |wo: Vec3, wi: Vec3| {
            let (r, t) = smooth::smooth_dirs(wo, eta);
            if wi.z * wo.z > 0.0 { Some(r) } else { t }
        };
        energy::means(&d, Some(&d), eta, n, s, &|_| Some(wo), Some(&target))
    });
    println!(
        "\nrough m = 0.5° against smooth over {n} draws (differences as fractions of the flux)"
    );
    println!(
        "{:<16} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "interface", "θo", "1−F", "share_t", "T_imp", "T_rad", "(1−F)/η'²", "R", "F", "angle°"
    );
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    for (&(kind, eta, theta, below), r) in cases.iter().zip(&results) {
        let wo = view(theta, 20.0, below);
        let f = f64::from(smooth::fresnel_at(wo, eta));
        let etap = if below {
            1.0 / f64::from(eta)
        } else {
            f64::from(eta)
        };
        let name = format!("{kind:?} eta={eta}");
        let theta_o = if below { 180.0 - theta } else { theta };
        println!(
            "{name:<16} {theta_o:>6.1} {:>9.5} {:>9.5} {:>9.5} {:>9.5} {:>9.5} {:>9.5} {f:>9.5} {:>9.3}",
            1.0 - f,
            r.share_t,
            r.t_imp,
            r.t_rad,
            (1.0 - f) / (etap * etap),
            r.r,
            r.mean_angle_deg
        );
        let diffs = [
            ("transmission share", r.share_t, 1.0 - f, 1.0),
            ("mean importance transmission", r.t_imp, 1.0 - f, 1.0),
            ("mean reflection", r.r, f, 1.0),
            // Radiance: measured in units of the smooth interface's own scale 1/η'².
            (
                "mean radiance transmission",
                r.t_rad,
                (1.0 - f) / (etap * etap),
                etap * etap,
            ),
        ];
        for (what, got, want, scale) in diffs {
            let d = (got - want).abs() * scale;
            worst = worst.max(d);
            if d > CONVERGENCE_TOL {
                failures.push(format!(
                    "{name} θo {theta_o}: {what} {got} vs smooth {want}"
                ));
            }
        }
        if r.mean_angle_deg > CONVERGENCE_ANGLE_DEG {
            failures.push(format!(
                "{name} θo {theta_o}: mean deviation {}°",
                r.mean_angle_deg
            ));
        }
        if r.stats.bad > 0 {
            failures.push(format!(
                "{name}: {}",
                r.stats.first_bad.as_deref().unwrap_or("")
            ));
        }
    }
    println!("worst difference {worst:.2e} of the flux (tolerance {CONVERGENCE_TOL})");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn rough_converges_to_smooth_at_tiny_roughness() {
    run_convergence(N_MEAN);
}

/// Full version: `cargo test --release --test dielectric -- --ignored --nocapture`.
#[test]
#[ignore = "slow: cargo test --release --test dielectric -- --ignored --nocapture"]
fn rough_converges_to_smooth_at_tiny_roughness_full() {
    run_convergence(N_MEAN * FULL);
}
