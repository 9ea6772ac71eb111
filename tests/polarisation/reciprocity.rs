//! The crystal events (`polarisation::crystal`) solve one boundary problem — the adjoint's — and
//! read the physical problem's amplitudes from it by reciprocity: a lossless, reciprocal
//! boundary's scattering matrix between power-normalised waves is symmetric, and on the
//! isotropic side a reversed wave keeps its p field and flips its s field, so the physical
//! Jones amplitudes are the adjoint's transposed with a sign on each s index. Checked here
//! against the second solve the events no longer make, for calcite and a strongly biaxial
//! crystal (n 1.5, 1.65, 1.72), random axes, directions from grazing (cos 0.02) to normal, and a
//! tilted boundary, in all four relations the events use:
//!
//! 1. out of a crystal wave (reversed) into s and p: the Stokes vector and the power;
//! 2. reflection from outside: the Jones matrix of the mirrored direction;
//! 3. inside, the power reflected from one wave into another;
//! 4. into a crystal wave from outside: the Stokes vector of its Jones row and its powers.
//!
//! Each to 10⁻⁹ (the solves agree to about 10⁻¹¹); with the sign on the s index left out, the
//! Stokes vectors' S2 and S3 change sign and relations 1, 2 and 4 fail.

use glam::DVec3;
use lapidary::polarisation::biaxial::Biaxial;
use lapidary::polarisation::boundary::{Boundary, Incident, Outgoing};
use lapidary::polarisation::optics::Optics;
use lapidary::polarisation::uniaxial::Uniaxial;
use lapidary::sampler::Rng;
use num_complex::Complex64 as C;

fn unit(rng: &mut Rng) -> DVec3 {
    let z = 2.0 * f64::from(rng.uniform()) - 1.0;
    let phi = std::f64::consts::TAU * f64::from(rng.uniform());
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The normalised Stokes vector of Jones components `(a, b)`.
fn stokes(a: C, b: C) -> [f64; 4] {
    let i = a.norm_sqr() + b.norm_sqr();
    let z = a * b.conj();
    [
        1.0,
        (a.norm_sqr() - b.norm_sqr()) / i,
        2.0 * z.re / i,
        -2.0 * z.im / i,
    ]
}

fn max_diff(a: [f64; 4], b: [f64; 4]) -> f64 {
    (0..4).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
}

/// `solve` for the reversed crystal wave of `o`.
fn reversed(b: &Boundary, o: &Outgoing, reference: DVec3) -> [Outgoing; 4] {
    b.solve(
        Incident::Inside {
            dir: -o.wave.direction(),
            mode: o.wave.mode,
        },
        reference,
    )
    .expect("the reversed wave's problem is regular")
}

#[test]
fn one_solve_gives_the_physical_problem() {
    const TOL: f64 = 1e-9;
    let mut rng = Rng::new(2026);
    let normal = DVec3::new(0.2, -0.1, 1.0).normalize();
    let (tangent, bitangent) = normal.any_orthonormal_pair();
    let mut checked = [0u32; 4];
    for case in 0..3000 {
        let axis = unit(&mut rng);
        let crystal = if case % 2 == 0 {
            Optics::Uniaxial(Uniaxial {
                no: 1.6584,
                ne: 1.4864,
                axis,
            })
        } else {
            let y = axis.any_orthonormal_vector();
            Optics::Biaxial(Biaxial {
                n: [1.5, 1.65, 1.72],
                axes: [axis, y, axis.cross(y)],
            })
        };
        let b = Boundary {
            crystal,
            n1: 1.0,
            normal,
        };
        let z = 0.02 + 0.98 * f64::from(rng.uniform());
        let phi = std::f64::consts::TAU * f64::from(rng.uniform());
        let r = (1.0 - z * z).sqrt();
        let wo = r * phi.cos() * tangent + r * phi.sin() * bitangent + z * normal;
        let reference = unit(&mut rng);
        let Some([s_in, p_in]) = b.solve_sp(-wo, reference) else {
            continue;
        };
        // 2. Reflection: the mirrored direction's Jones matrix is D Jᵀ D.
        let wi = 2.0 * normal * normal.dot(wo) - wo;
        let [rs, rp] = b.solve_sp(-wi, reference).unwrap();
        let want = [
            [s_in[0].amplitude, -s_in[1].amplitude],
            [-p_in[0].amplitude, p_in[1].amplitude],
        ];
        let got = [
            [rs[0].amplitude, rp[0].amplitude],
            [rs[1].amplitude, rp[1].amplitude],
        ];
        for (g, w) in got.iter().flatten().zip(want.iter().flatten()) {
            assert!((g - w).norm() < TOL, "case {case}: {got:?} vs {want:?}");
        }
        checked[1] += 1;
        for j in [2, 3] {
            let wave = s_in[j].wave;
            if !wave.propagating() || s_in[j].power + p_in[j].power < 1e-9 {
                continue;
            }
            // 1. Out of the crystal wave, reversed.
            let out = reversed(&b, &s_in[j], reference);
            let got = stokes(out[0].amplitude, out[1].amplitude);
            let want = stokes(-s_in[j].amplitude, p_in[j].amplitude);
            assert!(
                max_diff(got, want) < TOL,
                "case {case}: {got:?} vs {want:?}"
            );
            let power = out[0].power + out[1].power;
            assert!((power - s_in[j].power - p_in[j].power).abs() < TOL);
            checked[0] += 1;
            // The crystal wave going up toward the boundary, as a camera path inside meets it.
            let up = b
                .solve(
                    Incident::Inside {
                        dir: -wave.direction(),
                        mode: wave.mode,
                    },
                    reference,
                )
                .unwrap();
            // 3. Reflected into another wave and back.
            for o in &up[2..] {
                if o.wave.propagating() && o.power > 1e-9 {
                    let back = reversed(&b, o, reference);
                    let r = back[b.crystal.slot(wave.mode)].power;
                    assert!((r - o.power).abs() < TOL, "case {case}: {r} vs {}", o.power);
                    checked[2] += 1;
                }
            }
            // 4. Into this wave from outside, against the light leaving it.
            if up[0].power + up[1].power > 1e-9 {
                let wi = up[0].wave.direction();
                let [s2, p2] = b.solve_sp(-wi, reference).unwrap();
                let k = b.crystal.slot(wave.mode);
                let got = stokes(s2[k].amplitude, p2[k].amplitude);
                let want = stokes(-up[0].amplitude, up[1].amplitude);
                assert!(
                    max_diff(got, want) < TOL,
                    "case {case}: {got:?} vs {want:?}"
                );
                assert!((s2[k].power - up[0].power).abs() < TOL);
                assert!((p2[k].power - up[1].power).abs() < TOL);
                checked[3] += 1;
            }
        }
    }
    assert!(checked.iter().all(|&c| c > 2000), "{checked:?}");
}
