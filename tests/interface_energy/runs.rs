//! The drivers of items 3 and 4 of tests/interface_energy.rs; the constants and helpers are the
//! parent's.

use super::*;

/// Importance-mode `R + T` at θo = 0, 30, 60, 80, 89° on both sides: `(label, wo, means)`.
pub fn energy_means(d: &RoughDielectric, index: usize, n: u64) -> Vec<(f32, energy::Means)> {
    let mut out = Vec::new();
    for below in [false, true] {
        for t in [0.0f32, 30.0, 60.0, 80.0, 89.0] {
            let s = hash_words(&[
                0xe6e7,
                index as u64,
                u64::from(below),
                u64::from(t.to_bits()),
                n,
            ]);
            let theta = if below { 180.0 - t } else { t };
            out.push((
                theta,
                energy::at_wo(d, Some(d), d.eta, view(t, 30.0, below), n, s),
            ));
        }
    }
    out
}

pub fn run_energy(n: u64) {
    let means = par_map(&(0..interfaces().len()).collect::<Vec<_>>(), |&i| {
        energy_means(&interfaces()[i].1, i, n)
    });
    println!("\ncompensated interface: importance-mode mean weight over {n} draws");
    let mut failures = Vec::new();
    let mut failing = Vec::new();
    let mut worst = (0.0f64, String::new());
    for (i, rows) in means.iter().enumerate() {
        let name = &interfaces()[i].0;
        for (theta, m) in rows {
            let total = m.r + m.t_imp;
            let ok = (total - 1.0).abs() <= ENERGY_TOL + 3.0 * m.se;
            println!(
                "{name:<26} θo {theta:>5.0}: R {:.5} T {:.5} R+T {total:.5} ± {:.5}{}",
                m.r,
                m.t_imp,
                m.se,
                if ok { "" } else { "  FAIL" }
            );
            if (total - 1.0).abs() > worst.0 {
                worst = ((total - 1.0).abs(), format!("{name} θo {theta}"));
            }
            if !ok {
                failures.push(format!(
                    "{name} θo {theta}: R + T = {total:.5} ± {:.5}",
                    m.se
                ));
                if !failing.contains(&i) {
                    failing.push(i);
                }
            }
            if m.stats.bad > 0 {
                failures.push(format!("{name} θo {theta}: {:?}", m.stats.first_bad));
            }
        }
    }
    println!("worst |R + T − 1| = {:.2e} ({})", worst.0, worst.1);
    if failing.is_empty() {
        return;
    }
    // Diagnosis: the same interfaces with single-scattering tables of 64² · 4 samples per entry
    // instead of with_energy_tables' 16² · 4.
    let fine = par_map(&failing, |&i| {
        let d = measure::with_tables(&interfaces()[i].2, 64);
        energy_means(&d, i, n)
    });
    for (&i, rows) in failing.iter().zip(&fine) {
        let w = rows
            .iter()
            .map(|(_, m)| (m.r + m.t_imp - 1.0).abs())
            .fold(0.0, f64::max);
        failures.push(format!(
            "{}: with tables of 64² · 4 samples per entry the worst |R + T − 1| is {w:.4}",
            interfaces()[i].0
        ));
    }
    panic!(
        "R + T ≠ 1 beyond {ENERGY_TOL} + 3σ: the lobe returns 1 − E_s(μ) of a table measured \
         with 1 024 samples per entry, whose noise reaches it (see the report):\n{}",
        failures.join("\n")
    );
}

pub fn run_hemispherical(n: u64) {
    let jobs: Vec<(usize, bool)> = (0..interfaces().len())
        .flat_map(|i| [(i, false), (i, true)])
        .collect();
    let hemi = par_map(&jobs, |&(i, below)| {
        let d = &interfaces()[i].1;
        let seed = hash_words(&[0x4e41, i as u64, u64::from(below), n]);
        energy::hemispherical(d, Some(d), d.eta, below, n, seed)
    });
    println!(
        "\nhemispherical transmittance over {n} cosine-distributed wo per side \
         (t̄_above = η² t̄_below); the old 1/E(wo) rule by quadrature of the same tables"
    );
    let mut failures = Vec::new();
    for (i, (name, d, _)) in interfaces().iter().enumerate() {
        let (a, b) = (&hemi[2 * i], &hemi[2 * i + 1]);
        let e2 = f64::from(d.eta).powi(2);
        let se = (a.se_t.powi(2) + e2 * e2 * b.se_t.powi(2)).sqrt();
        let z = (a.t_imp - e2 * b.t_imp) / se;
        let (qa, qb) = hemispherical_by_tables(d.energy.as_deref().expect("lobe"), Rule::Old);
        println!(
            "{name:<26} t̄_above {:.5} η²·t̄_below {:.5} z {z:>6.2} | old: {qa:.4} vs {:.4}",
            a.t_imp,
            e2 * b.t_imp,
            e2 * qb
        );
        if z.abs() > 3.0 || a.stats.bad + b.stats.bad > 0 {
            failures.push(format!(
                "{name}: t̄_above {} vs η² t̄_below {} (z {z:.2})",
                a.t_imp,
                e2 * b.t_imp
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

pub fn run_lobes(n: u64) {
    let mut jobs = Vec::new();
    for i in 0..interfaces().len() {
        for below in [false, true] {
            for t in [0.0f32, 60.0, 80.0] {
                for mode in [TransportMode::Importance, TransportMode::Radiance] {
                    jobs.push((i, below, t, mode));
                }
            }
        }
    }
    let rows = par_map(&jobs, |&(i, below, t, mode)| {
        let d = &interfaces()[i].1;
        let wo = view(t, 120.0, below);
        let key = |k: u64| {
            hash_words(&[
                0x10be,
                i as u64,
                u64::from(below),
                u64::from(t.to_bits()),
                mode as u64,
                k,
                n,
            ])
        };
        (
            lobe_sums(d, wo, Lobes::All, mode, n, key(0)),
            lobe_sums(d, wo, Lobes::Reflection, mode, n, key(1)),
            lobe_sums(d, wo, Lobes::Transmission, mode, n, key(2)),
        )
    });
    let nf = n as f64;
    let mean_se = |(s, s2): (f64, f64)| {
        let m = s / nf;
        (m, ((s2 / nf - m * m).max(0.0) / nf).sqrt())
    };
    let mut failures = Vec::new();
    let mut worst_z = 0.0f64;
    println!("\nrestricted lobes vs the split of the all-lobe mean ({n} draws each; z = Δ/σ)");
    for (&(i, below, t, mode), (all, r, tr)) in jobs.iter().zip(&rows) {
        let theta = if below { 180.0 - t } else { t };
        let mut line = format!("{:<26} θo {theta:>5.0} {mode:?}:", interfaces()[i].0);
        for (what, part, restricted) in [("R", all[0], r[0]), ("T", all[1], tr[1])] {
            let ((a, sa), (b, sb)) = (mean_se(part), mean_se(restricted));
            let z = (a - b) / (sa * sa + sb * sb).sqrt().max(1e-12);
            worst_z = worst_z.max(z.abs());
            line += &format!(" {what} all {a:.5} restricted {b:.5} z {z:>5.2};");
            if z.abs() > 4.0 {
                failures.push(format!("{line} ← {what}"));
            }
        }
        // A restricted call never leaves its lobe.
        if r[1].0 != 0.0 || tr[0].0 != 0.0 {
            failures.push(format!(
                "{line}: a restricted sample crossed to the other lobe"
            ));
        }
        println!("{line}");
    }
    println!(
        "worst |z| = {worst_z:.2} over {} comparisons",
        2 * jobs.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
