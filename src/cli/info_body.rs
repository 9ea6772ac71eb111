//! `lapidary info`'s line for the stone's body: its indices (a crystal's principal ones, at the
//! d line and where they disperse at Fraunhofer's F and C lines), its boundary and its interior.

use crate::scene::Body;

/// `IOR …, … boundary; interior …` of `b`.
pub(super) fn summary(b: &Body) -> String {
    let boundary = if b.alpha == 0.0 {
        "smooth".to_string()
    } else {
        format!("{:?} α {:.4}, {:?}", b.distribution, b.alpha, b.masking)
    };
    let interior = match &b.medium {
        Some(m) if b.has_medium() => format!(
            "σa {:.4?}, σs {:.4?} per object unit, g {}{}",
            m.sigma_a.0,
            m.sigma_s.0,
            m.g,
            if b.has_measured_medium() {
                " (measured spectra; RGB shows their projection)"
            } else {
                ""
            }
        ),
        _ => "clear".into(),
    };
    let ior = match b.dispersion {
        None => format!("{}", b.ior),
        Some(law) => format!(
            "{} (dispersive: n(486 nm) {:.4}, n(656 nm) {:.4}, Abbe {:.1})",
            b.ior,
            law.at(486.13),
            law.at(656.27),
            law.abbe()
        ),
    };
    // A doubly refractive body: `ior` is ω or n_α.
    let ior = match &b.crystal {
        None => ior,
        Some(c) => {
            let absorbs = |names: &[&str]| {
                if !c.pleochroic() {
                    return String::new();
                }
                let parts: Vec<String> = names
                    .iter()
                    .zip(c.sigma.iter().zip(&c.sigma_measured))
                    .map(|(n, (s, m))| match m {
                        None => format!("σ{n} {:.3?}", s.0),
                        Some(m) => format!(
                            "σ{n} measured, {:.3}–{:.3} (RGB {:.3?})",
                            (360..=830)
                                .step_by(10)
                                .map(|l| m.at(l as f32))
                                .fold(f32::MAX, f32::min),
                            m.max(),
                            s.0
                        ),
                    })
                    .collect();
                format!("; pleochroic {} per object unit", parts.join(", "))
            };
            let absorbs = |names: &[&str]| match c.thin_nm {
                None => absorbs(names),
                Some(nm) => format!(
                    "{}; thin section, {nm} nm per object unit: coherent, interference colours",
                    absorbs(names)
                ),
            };
            // With a dispersive body or own laws, the principal indices at Fraunhofer's F
            // and C lines too: the body's index from its law, each other index from its own
            // law or at its d-line difference from the body's (as the renderer takes them).
            let (names, beyond): (&[&str], [f32; 2]) = match c.indices {
                crate::scene::body::Indices::Uniaxial { ne, .. } => (&["ω", "ε"], [ne, 0.0]),
                crate::scene::body::Indices::Biaxial { beta, gamma, .. } => {
                    (&["α", "β", "γ"], [beta, gamma])
                }
            };
            let lines = if b.dispersion.is_some() || c.laws.iter().any(Option::is_some) {
                let at = |nm: f32| {
                    let n = b.dispersion.map_or(b.ior, |law| law.at(nm));
                    let values = std::iter::once(n).chain(
                        (0..names.len() - 1)
                            .map(|k| c.laws[k].map_or(n + beyond[k] - b.ior, |l| l.at(nm))),
                    );
                    let parts: Vec<String> = names
                        .iter()
                        .zip(values)
                        .map(|(name, v)| format!("{name} {v:.4}"))
                        .collect();
                    parts.join(", ")
                };
                format!("; F 486 nm: {}; C 656 nm: {}", at(486.13), at(656.27))
            } else {
                String::new()
            };
            match c.indices {
                crate::scene::body::Indices::Uniaxial { ne, axis } => format!(
                    "ω {ior}, ε {ne} (uniaxial, axis {:.3?}{lines}{})",
                    axis.to_array(),
                    absorbs(&["ω", "ε"])
                ),
                crate::scene::body::Indices::Biaxial { beta, gamma, axes } => format!(
                    "α {ior}, β {beta}, γ {gamma} (biaxial, X {:.3?}, Z {:.3?}{lines}{})",
                    axes[0].to_array(),
                    axes[2].to_array(),
                    absorbs(&["α", "β", "γ"])
                ),
            }
        }
    };
    format!("IOR {ior}, {boundary} boundary; interior {interior}")
}

#[cfg(test)]
mod tests {
    use crate::recipe::GemRecipe;

    /// A crystal's line gives its principal indices at F and C where they disperse — each
    /// pair `n_F − n_C = (n_d − 1)/V` of its Abbe law (the definition of the Abbe number) —
    /// and nothing more where they do not.
    #[test]
    fn a_dispersive_crystal_prints_its_indices_at_f_and_c() {
        let line = |body: &str| {
            let text = format!("(materials: {{}}, body: {body}, surface: Body)");
            let recipe = GemRecipe::parse("calcite.ron", &text).unwrap();
            let scene = recipe.compile().unwrap();
            let out = super::super::info::describe(&recipe, &scene, 200);
            out.lines()
                .find(|l| l.contains("body:"))
                .unwrap()
                .to_string()
        };
        let l = line(
            "(ior: 1.6584, dispersion: Abbe(50.0),
              crystal: Uniaxial(ne: 1.4864, ne_dispersion: Abbe(78.0), axis: (1.0, 1.0, 0.0)))",
        );
        let value = |after: &str, name: &str| -> f64 {
            let rest = &l[l.find(after).unwrap()..];
            let rest = &rest[rest.find(&format!("{name} ")).unwrap() + name.len() + 1..];
            rest[..6].parse().unwrap()
        };
        for (name, nd, v) in [("ω", 1.6584, 50.0), ("ε", 1.4864, 78.0)] {
            let spread = value("F 486 nm:", name) - value("C 656 nm:", name);
            assert!(
                (spread - (nd - 1.0) / v).abs() < 2e-4,
                "{name}: {spread} in {l}"
            );
        }
        let plain = line("(ior: 1.6584, crystal: Uniaxial(ne: 1.4864, axis: (1.0, 1.0, 0.0)))");
        assert!(!plain.contains("486 nm"), "{plain}");
    }
}
