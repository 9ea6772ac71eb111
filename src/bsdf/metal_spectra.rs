//! The metal presets' measured complex refractive index as a function of wavelength (issue 19):
//! the tables in `data/metals/` that [`Metal::nk`]'s RGB values are integrated from, read for the
//! spectral variant. Sources, per table header and [`Metal::nk`]'s docs: gold, silver, copper —
//! P. B. Johnson & R. W. Christy, Phys. Rev. B 6, 4370 (1972); aluminium — A. D. Rakić, Appl. Opt.
//! 34, 4755 (1995); brass (70 % Cu, 30 % Zn) — M. R. Querry, CRDC-CR-85034 (1985); digits from the
//! refractiveindex.info database (Polyanskiy, Sci. Data 11, 94, 2024).
//!
//! Between tabulated wavelengths `n` and `k` are interpolated linearly in wavelength (as
//! `scripts/metal-presets.py` does when it derives the RGB presets); every table spans 360–830 nm.

use super::fresnel::Metal;
use std::sync::OnceLock;

/// One metal's table: wavelengths (nm, increasing), `n`, `k`.
#[derive(Debug)]
struct Table {
    lambda: Vec<f32>,
    n: Vec<f32>,
    k: Vec<f32>,
}

impl Table {
    /// Parses `wavelength_nm,n,k` rows (`#` comments and the header skipped). The files are part
    /// of the crate (`include_str!`) and checked by the tests, so a malformed row is a build bug.
    fn parse(text: &str) -> Table {
        let mut t = Table {
            lambda: vec![],
            n: vec![],
            k: vec![],
        };
        for line in text.lines() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with("wavelength") {
                continue;
            }
            let v: Vec<f32> = line
                .split(',')
                .map(|x| x.trim().parse().expect("data/metals: a number"))
                .collect();
            assert_eq!(v.len(), 3, "data/metals: three columns");
            t.lambda.push(v[0]);
            t.n.push(v[1]);
            t.k.push(v[2]);
        }
        t
    }

    /// `(n, k)` at `lambda` nm, linear in wavelength, clamped to the table's ends.
    fn at(&self, lambda: f32) -> (f32, f32) {
        let l = &self.lambda;
        let last = l.len() - 1;
        if !(lambda > l[0]) {
            return (self.n[0], self.k[0]);
        }
        if lambda >= l[last] {
            return (self.n[last], self.k[last]);
        }
        let i = l.partition_point(|&x| x <= lambda) - 1;
        let t = (lambda - l[i]) / (l[i + 1] - l[i]);
        (
            self.n[i] + t * (self.n[i + 1] - self.n[i]),
            self.k[i] + t * (self.k[i + 1] - self.k[i]),
        )
    }
}

fn tables() -> &'static [Table; 5] {
    static TABLES: OnceLock<[Table; 5]> = OnceLock::new();
    TABLES.get_or_init(|| {
        Metal::ALL.map(|m| {
            Table::parse(match m {
                Metal::Gold => include_str!("../../data/metals/gold.csv"),
                Metal::Silver => include_str!("../../data/metals/silver.csv"),
                Metal::Copper => include_str!("../../data/metals/copper.csv"),
                Metal::Aluminium => include_str!("../../data/metals/aluminium.csv"),
                Metal::Brass => include_str!("../../data/metals/brass.csv"),
            })
        })
    })
}

impl Metal {
    /// The measured `(n, k)` relative to vacuum at wavelength `lambda_nm` (module docs; clamped
    /// to the table's range, NaN gives its first row).
    pub fn nk_at(self, lambda_nm: f32) -> (f32, f32) {
        let i = Metal::ALL.iter().position(|&m| m == self).unwrap_or(0);
        tables()[i].at(lambda_nm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::fresnel::conductor;
    use crate::spectrum::cie;

    #[test]
    fn tables_cover_the_visible_range_and_return_their_rows() {
        for (m, t) in Metal::ALL.iter().zip(tables()) {
            assert!(t.lambda.len() > 10, "{m:?}");
            assert!(
                t.lambda[0] <= 360.0 && *t.lambda.last().unwrap() >= 830.0,
                "{m:?}"
            );
            assert!(
                t.lambda.windows(2).all(|w| w[0] < w[1]),
                "{m:?}: increasing"
            );
            for i in 0..t.lambda.len() {
                assert_eq!(m.nk_at(t.lambda[i]), (t.n[i], t.k[i]));
                assert!(t.n[i] > 0.0 && t.k[i] > 0.0);
            }
        }
        // Johnson & Christy's copper at 1.76 eV (704.5 nm) is n = 0.21, k = 4.205 (their Table I).
        let (n, k) = Metal::Copper.nk_at(704.5);
        assert!(
            (n - 0.21).abs() < 1e-4 && (k - 4.205).abs() < 1e-4,
            "{n} {k}"
        );
        assert_eq!(Metal::Gold.nk_at(f32::NAN), Metal::Gold.nk_at(0.0));
    }

    /// The RGB presets are these tables integrated (`Metal::nk`'s docs): integrating `n(λ)` and
    /// `k(λ)` with the CIE functions, without an illuminant, gives them back to the four decimals
    /// they are rounded to (measured: 4.8e-5 at most).
    #[test]
    fn rgb_presets_are_the_integrated_tables() {
        let mut worst = 0.0f32;
        for m in Metal::ALL {
            let (n_rgb, k_rgb) = m.nk();
            for (part, rgb) in [(0, n_rgb), (1, k_rgb)] {
                let xyz = cie::spectrum_to_xyz(|l| {
                    let (n, k) = m.nk_at(l);
                    if part == 0 { n } else { k }
                });
                let got = cie::xyz_to_linear_srgb(xyz).to_array();
                for (c, (a, b)) in got.into_iter().zip(rgb.0).enumerate() {
                    worst = worst.max((a - b).abs());
                    assert!(
                        (a - b).abs() < 1e-4,
                        "{m:?} part {part} channel {c}: {a} vs preset {b}"
                    );
                }
            }
        }
        println!("largest difference from the presets: {worst:.1e}");
    }

    /// Spectral Fresnel at normal incidence against the closed form `((n−1)² + k²)/((n+1)² + k²)`
    /// from the table's own rows, every metal, every tabulated wavelength in 360–830 nm.
    #[test]
    fn spectral_fresnel_matches_the_tables_at_normal_incidence() {
        for (m, t) in Metal::ALL.iter().zip(tables()) {
            for i in 0..t.lambda.len() {
                if !(360.0..=830.0).contains(&t.lambda[i]) {
                    continue;
                }
                let (n, k) = m.nk_at(t.lambda[i]);
                let (tn, tk) = (f64::from(t.n[i]), f64::from(t.k[i]));
                let r0 = ((tn - 1.0).powi(2) + tk * tk) / ((tn + 1.0).powi(2) + tk * tk);
                let f = f64::from(conductor(1.0, n, k));
                assert!(
                    (f - r0).abs() < 1e-5,
                    "{m:?} at {} nm: {f} vs {r0}",
                    t.lambda[i]
                );
            }
        }
        // Copper reflects red far more than blue (its colour), silver is flat and bright.
        let r = |m: Metal, l: f32| {
            let (n, k) = m.nk_at(l);
            conductor(1.0, n, k)
        };
        assert!(r(Metal::Copper, 650.0) > r(Metal::Copper, 450.0) + 0.3);
        assert!(r(Metal::Silver, 450.0) > 0.9 && r(Metal::Silver, 650.0) > 0.9);
    }
}
