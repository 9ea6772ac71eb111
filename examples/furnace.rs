//! White-furnace check of two key stacks under the three evaluation models:
//! a white Lambert base under a clear coat (η 1.5, m 5°) and a perfect conductor (m 10°) under a
//! clear coat (η 1.7, m 7°). Prints the directional albedo (sample mean) at several viewing angles.
//!
//! `cargo run --release --example furnace`

use lapidary::bsdf::measure::{albedo_by_sampling, direction_deg};
use lapidary::bsdf::{Base, Coat, ConductorIor, LayeredBsdf, Model, ReferenceParams, StackDesc};
use lapidary::color::Rgb;

/// One row: stack name, model name, `(θo, albedo)` pairs.
type Row = (String, String, Vec<(f32, f32)>);

/// Albedo rows with `n` samples per angle.
fn furnace(n: u64) -> Vec<Row> {
    let clear = |ior, roughness| Coat {
        ior,
        roughness,
        absorption: Rgb::ZERO,
        thickness: 0.0,
    };
    let stacks = [
        (
            "white Lambert / clear coat η1.5 m5°",
            StackDesc::new(vec![clear(1.5, 5.0)], Base::Lambert { albedo: Rgb::ONE }),
        ),
        (
            "perfect conductor m10° / clear coat η1.7 m7°",
            StackDesc::new(
                vec![clear(1.7, 7.0)],
                Base::Conductor {
                    ior: ConductorIor::Perfect,
                    roughness: 10.0,
                },
            ),
        ),
    ];
    let mut rows = Vec::new();
    for (name, desc) in stacks {
        let stack = LayeredBsdf::new(&desc).expect("valid stack");
        for model in [
            Model::Course,
            Model::Corrected,
            Model::Reference(ReferenceParams::default()),
        ] {
            let b = stack.with_model(model);
            let values = [0.0f32, 30.0, 60.0, 75.0, 85.0]
                .iter()
                .map(|&t| {
                    (
                        t,
                        albedo_by_sampling(&b, direction_deg(t, 0.0), n, 7).mean[0],
                    )
                })
                .collect();
            let label = format!("{model:?}")
                .split('(')
                .next()
                .unwrap_or("")
                .to_string();
            rows.push((name.to_string(), label, values));
        }
    }
    rows
}

fn main() {
    for (stack, model, values) in furnace(200_000) {
        let cells: Vec<String> = values
            .iter()
            .map(|(t, a)| format!("{t:>2}°: {a:.4}"))
            .collect();
        println!("{stack:<46} {model:<10} {}", cells.join("  "));
    }
}

#[test]
fn furnace_runs_and_corrected_conserves_energy() {
    for (stack, model, values) in furnace(20_000) {
        for (t, a) in values {
            assert!(a.is_finite() && a > 0.5, "{stack} {model} {t}: {a}");
            if model != "Course" {
                assert!((a - 1.0).abs() < 0.03, "{stack} {model} {t}: {a}");
            }
        }
    }
}
