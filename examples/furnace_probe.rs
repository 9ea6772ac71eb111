use lapidary::bsdf::measure::*;
use lapidary::bsdf::*;
use lapidary::color::Spectrum;
fn main() {
    let clear = |ior, m| Coat {
        ior,
        roughness: m,
        absorption: Spectrum::ZERO,
        thickness: 0.0,
    };
    let stacks = [
        (
            "white lambert / clear 1.5 5deg",
            StackDesc::new(
                vec![clear(1.5, 5.0)],
                Base::Lambert {
                    albedo: Spectrum::ONE,
                },
            ),
        ),
        (
            "perfect cond 10deg / clear 1.7 7deg",
            StackDesc::new(
                vec![clear(1.7, 7.0)],
                Base::Conductor {
                    ior: ConductorIor::Perfect,
                    roughness: 10.0,
                },
            ),
        ),
    ];
    for (name, d) in stacks {
        let s = LayeredBsdf::new(&d).unwrap();
        for model in [
            Model::Course,
            Model::Corrected,
            Model::Reference(ReferenceParams::default()),
        ] {
            let b = s.with_model(model);
            let mut line = format!("{name} {model:?}:");
            for th in [0.0, 30.0, 45.0, 60.0, 75.0, 85.0] {
                let wo = direction_deg(th, 0.0);
                let a = albedo_by_sampling(&b, wo, 200_000, 1);
                let e = albedo_by_eval(&b, &s, wo, 100_000, 2);
                line += &format!(" {th}:{:.4}/{:.4}", a.mean[0], e.mean[0]);
            }
            println!("{line}");
        }
    }
}
